//! Hertz plus a constant attraction while the surfaces touch: DMT and simplified JKR, one law with the
//! size of the attraction as its parameter.
//!
//! F(δ) = (4/3)E*√R* δ^{3/2} − F_po for δ ≥ 0, no force for δ < 0. There is no neck and no hysteresis: the
//! contact exists exactly while δ ≥ 0.
//!
//! * **DMT** (Derjaguin, Muller & Toporov 1975), [`PullOff::Dmt`]: F_po = 2πΓR*, the DMT pull-off force.
//!   DMT describes stiff, weakly adhesive, small contacts (Tabor parameter λ_T ≲ 0.1); it is provided for
//!   comparison with full JKR.
//! * **Simplified JKR**, [`PullOff::SimplifiedJkr`]: F_po = F_c = (3/2)πΓR*, the JKR pull-off force — the
//!   additive "Hertz + cohesion" idea of LIGGGHTS' `cohesion sjkr`, reduced to a constant attraction of the
//!   JKR pull-off size. The snow thesis calls the additive approach inaccurate (L394): it has no neck, no
//!   hysteresis and a different force at first touch (−F_c instead of JKR's −(8/9)F_c). Provided to show
//!   the difference against [`super::jkr`].

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Which constant attraction is added to Hertz.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PullOff {
    /// DMT: 2πΓR*.
    Dmt,
    /// Simplified JKR: (3/2)πΓR*.
    SimplifiedJkr,
}

impl PullOff {
    /// F_po/(ΓR*) \[-\]: 2π (DMT) or 3π/2 (simplified JKR).
    pub fn factor(self) -> f64 {
        match self {
            PullOff::Dmt => 2.0 * PI,
            PullOff::SimplifiedJkr => 1.5 * PI,
        }
    }
}

/// Hertz plus a constant attraction for one pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ConstantPullOff {
    /// Hertz stiffness (4/3)E*√R* \[N/m^{3/2}\].
    pub hertz_stiffness: f64,
    /// Constant attraction F_po \[N\] (the pull-off force of the law).
    pub pull_off_force: f64,
}

impl ConstantPullOff {
    /// The law `kind` for E* \[Pa\], R* \[m\], Γ \[J/m²\].
    pub fn new(kind: PullOff, e_star: f64, r_star: f64, work_of_adhesion: f64) -> Self {
        ConstantPullOff {
            hertz_stiffness: 4.0 / 3.0 * e_star * r_star.sqrt(),
            pull_off_force: kind.factor() * work_of_adhesion * r_star,
        }
    }

    /// Elastic force \[N\] (positive repulsive) at overlap `delta` \[m\]; `None` for δ < 0.
    pub fn force(&self, delta: f64) -> Option<f64> {
        (delta >= 0.0).then(|| self.hertz_stiffness * delta * delta.sqrt() - self.pull_off_force)
    }

    /// Stored energy ∫₀^δ F dδ′ = (2/5)k δ^{5/2} − F_po δ \[J\]; `None` for δ < 0.
    pub fn energy(&self, delta: f64) -> Option<f64> {
        (delta >= 0.0)
            .then(|| 0.4 * self.hertz_stiffness * delta * delta * delta.sqrt() - self.pull_off_force * delta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dmt_pull_off_and_zero_force_overlap() {
        // DMT pull-off 2πΓR* (Derjaguin, Muller & Toporov 1975); F = 0 where (4/3)E*√R δ^{3/2} = 2πΓR*.
        let (e, r, g) = (1.88329e9, 5e-6, 0.2);
        let d = ConstantPullOff::new(PullOff::Dmt, e, r, g);
        assert!((d.force(0.0).unwrap() + 2.0 * PI * g * r).abs() < 1e-18);
        let d0 = (2.0 * PI * g * r / (4.0 / 3.0 * e * r.sqrt())).powf(2.0 / 3.0);
        assert!(d.force(d0).unwrap().abs() < 1e-12 * d.pull_off_force);
        assert!(d.force(-1e-12).is_none());
        // Energy is the integral of the force (Simpson, 1e-9).
        let n = 1000;
        let h = 2.0 * d0 / n as f64;
        let mut s = 0.0;
        for i in 0..n {
            let a = i as f64 * h;
            s += h / 6.0
                * (d.force(a).unwrap() + 4.0 * d.force(a + 0.5 * h).unwrap() + d.force(a + h).unwrap());
        }
        assert!((s - d.energy(2.0 * d0).unwrap()).abs() < 1e-6 * d.pull_off_force * d0);
    }

    #[test]
    fn simplified_jkr_is_hertz_minus_the_jkr_pull_off() {
        // F = Hertz − (3/2)πΓR*: at δ = 0 the force is −F_c (not JKR's −8/9 F_c).
        let s = ConstantPullOff::new(PullOff::SimplifiedJkr, 1.88329e9, 5e-6, 0.2);
        let fc = 1.5 * PI * 0.2 * 5e-6;
        assert!((s.force(0.0).unwrap() + fc).abs() < 1e-18);
        let d: f64 = 1e-8;
        let hertz = 4.0 / 3.0 * 1.88329e9 * (5e-6f64).sqrt() * d.powf(1.5);
        assert!((s.force(d).unwrap() - (hertz - fc)).abs() < 1e-12 * hertz);
        assert!(s.force(-1e-15).is_none());
        // The two differ only in the attraction: ratio 2π / (3π/2) = 4/3.
        let dmt = ConstantPullOff::new(PullOff::Dmt, 1.88329e9, 5e-6, 0.2);
        assert!((dmt.pull_off_force / s.pull_off_force - 4.0 / 3.0).abs() < 1e-15);
        assert_eq!(dmt.hertz_stiffness, s.hertz_stiffness);
    }
}
