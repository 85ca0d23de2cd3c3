//! DMT (Derjaguin–Muller–Toporov 1975) adhesion: the Hertz force plus a constant attraction 2πΓR* while
//! the surfaces touch.
//!
//! F(δ) = (4/3)E*√R* δ^{3/2} − 2πΓR* for δ ≥ 0, no force for δ < 0. The pull-off force is 2πΓR* and
//! there is no neck and no hysteresis: the contact exists exactly while δ ≥ 0. DMT describes stiff, weakly
//! adhesive, small contacts (Tabor parameter λ_T ≲ 0.1); it is provided for comparison with full JKR.

use serde::{Deserialize, Serialize};

/// DMT contact of one pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Dmt {
    /// Hertz stiffness (4/3)E*√R* \[N/m^{3/2}\].
    pub hertz_stiffness: f64,
    /// Constant attraction 2πΓR* \[N\] (the DMT pull-off force).
    pub pull_off_force: f64,
}

impl Dmt {
    /// DMT contact for E* \[Pa\], R* \[m\], Γ \[J/m²\].
    pub fn new(e_star: f64, r_star: f64, work_of_adhesion: f64) -> Self {
        Dmt {
            hertz_stiffness: 4.0 / 3.0 * e_star * r_star.sqrt(),
            pull_off_force: 2.0 * std::f64::consts::PI * work_of_adhesion * r_star,
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
    fn pull_off_and_zero_force_overlap() {
        // DMT pull-off 2πΓR* (Derjaguin, Muller & Toporov 1975); F = 0 where (4/3)E*√R δ^{3/2} = 2πΓR*.
        let (e, r, g) = (1.88329e9, 5e-6, 0.2);
        let d = Dmt::new(e, r, g);
        assert!((d.force(0.0).unwrap() + 2.0 * std::f64::consts::PI * g * r).abs() < 1e-18);
        let d0 = (2.0 * std::f64::consts::PI * g * r / (4.0 / 3.0 * e * r.sqrt())).powf(2.0 / 3.0);
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
}
