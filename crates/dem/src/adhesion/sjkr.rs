//! Simplified JKR: the Hertz force minus a constant pull-off force F_c = (3/2)πΓR* while the surfaces
//! touch.
//!
//! F(δ) = (4/3)E*√R* δ^{3/2} − F_c for δ ≥ 0, no force for δ < 0: the additive "Hertz + cohesion" idea of
//! LIGGGHTS' `cohesion sjkr`, reduced to a constant attraction of the JKR pull-off size. The snow thesis
//! calls the additive approach inaccurate (L394): it has no neck, no hysteresis and a different force at
//! first touch. Provided to show the difference against [`super::jkr`].

use serde::{Deserialize, Serialize};

/// Simplified-JKR contact of one pair.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimplifiedJkr {
    /// Hertz stiffness (4/3)E*√R* \[N/m^{3/2}\].
    pub hertz_stiffness: f64,
    /// Constant attraction F_c = (3/2)πΓR* \[N\].
    pub pull_off_force: f64,
}

impl SimplifiedJkr {
    /// Simplified JKR for E* \[Pa\], R* \[m\], Γ \[J/m²\].
    pub fn new(e_star: f64, r_star: f64, work_of_adhesion: f64) -> Self {
        SimplifiedJkr {
            hertz_stiffness: 4.0 / 3.0 * e_star * r_star.sqrt(),
            pull_off_force: 1.5 * std::f64::consts::PI * work_of_adhesion * r_star,
        }
    }

    /// Elastic force \[N\] (positive repulsive) at overlap `delta` \[m\]; `None` for δ < 0.
    pub fn force(&self, delta: f64) -> Option<f64> {
        (delta >= 0.0).then(|| self.hertz_stiffness * delta * delta.sqrt() - self.pull_off_force)
    }

    /// Stored energy ∫₀^δ F dδ′ \[J\]; `None` for δ < 0.
    pub fn energy(&self, delta: f64) -> Option<f64> {
        (delta >= 0.0)
            .then(|| 0.4 * self.hertz_stiffness * delta * delta * delta.sqrt() - self.pull_off_force * delta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_pull_off_on_hertz() {
        // F = Hertz − (3/2)πΓR*: at δ = 0 the force is −F_c (not JKR's −8/9 F_c).
        let s = SimplifiedJkr::new(1.88329e9, 5e-6, 0.2);
        let fc = 1.5 * std::f64::consts::PI * 0.2 * 5e-6;
        assert!((s.force(0.0).unwrap() + fc).abs() < 1e-18);
        let d: f64 = 1e-8;
        let hertz = 4.0 / 3.0 * 1.88329e9 * (5e-6f64).sqrt() * d.powf(1.5);
        assert!((s.force(d).unwrap() - (hertz - fc)).abs() < 1e-12 * hertz);
        assert!(s.force(-1e-15).is_none());
    }
}
