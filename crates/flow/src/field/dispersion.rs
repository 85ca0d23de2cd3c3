//! Turbulent dispersion: the discrete random walk (eddy interaction model) of Gosman & Ioannides (1983),
//! in the form of the Fluent DPM theory guide (§16.5 "Discrete Random Walk Tracking").
//!
//! A particle meets a sequence of eddies. Each eddy has an isotropic fluctuation u′ = ζ √(2k/3)
//! (ζ standard normal per component) that stays constant for the interaction time
//!
//! t_int = min(τ_e, t_cross),   τ_e = 2 T_L (or −T_L ln r, r uniform),   T_L = C_L k/ε,
//! t_cross = −τ ln(1 − L_e/(τ |u − v|)),   L_e = C_μ^(3/4) k^(3/2)/ε,
//!
//! with τ the particle relaxation time (no crossing when L_e ≥ τ|u − v|). C_L = 0.15 (Fluent's default
//! for k–ε models), C_μ = 0.09. A tracer (τ → 0) then diffuses with D = (2k/3) T_L, Taylor's result.
//!
//! Each particle owns its generator (`spatter_core::rng::seeded(seed, particle id)`), so the walk is
//! reproducible and independent of thread count and particle order.

use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::rng::{Rng, RngExt};
use spatter_core::Vec3;

/// Random-walk settings. Scenario table `[dispersion]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DispersionSettings {
    /// Time-scale constant C_L of T_L = C_L k/ε.
    #[serde(default = "default_cl")]
    pub time_scale_constant: f64,
    /// Draw each eddy lifetime as −T_L ln r instead of 2 T_L.
    #[serde(default)]
    pub random_eddy_lifetime: bool,
    /// Seed of the per-particle generators.
    #[serde(default)]
    pub seed: u64,
}

fn default_cl() -> f64 {
    0.15
}

impl Default for DispersionSettings {
    fn default() -> Self {
        DispersionSettings { time_scale_constant: default_cl(), random_eddy_lifetime: false, seed: 0 }
    }
}

impl Validate for DispersionSettings {
    fn validate(&self, c: &mut Checker) {
        c.positive("time_scale_constant", self.time_scale_constant);
    }
}

/// C_μ^(3/4) with C_μ = 0.09.
const CMU_34: f64 = 0.164_316_767_251_549_84;

/// The eddy a particle is currently in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Eddy {
    /// Velocity fluctuation \[m/s\].
    pub u_prime: Vec3,
    /// Remaining interaction time \[s\].
    pub remaining: f64,
}

impl DispersionSettings {
    /// The fluctuation to add to the mean fluid velocity for the coming step of length `dt`, drawing a
    /// new eddy when the current one has expired. `k`, `eps` are the local turbulence quantities, `tau`
    /// the particle relaxation time and `slip` its slip speed.
    #[allow(clippy::too_many_arguments)]
    pub fn fluctuation(
        &self,
        eddy: &mut Eddy,
        rng: &mut Rng,
        k: f64,
        eps: f64,
        tau: f64,
        slip: f64,
        dt: f64,
    ) -> Vec3 {
        if eddy.remaining <= 0.0 {
            if k <= 0.0 || eps <= 0.0 {
                *eddy = Eddy { u_prime: Vec3::ZERO, remaining: dt };
            } else {
                let sigma = (2.0 * k / 3.0).sqrt();
                let z = Vec3::new(
                    StandardNormal.sample(rng),
                    StandardNormal.sample(rng),
                    StandardNormal.sample(rng),
                );
                let tl = self.time_scale_constant * k / eps;
                let life = if self.random_eddy_lifetime {
                    let r: f64 = rng.random();
                    -tl * (1.0 - r).ln()
                } else {
                    2.0 * tl
                };
                let le = CMU_34 * k.powf(1.5) / eps;
                let cross = if tau.is_finite() && tau * slip > le {
                    -tau * (1.0 - le / (tau * slip)).ln()
                } else {
                    f64::INFINITY
                };
                *eddy = Eddy { u_prime: sigma * z, remaining: life.min(cross) };
            }
        }
        eddy.remaining -= dt;
        eddy.u_prime
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_core::rng::seeded;

    #[test]
    fn tracers_diffuse_with_taylors_coefficient() {
        // Homogeneous turbulence, zero mean flow, tracers (τ = 0): ⟨x²⟩ → 2 D t, D = (2k/3) T_L
        // (Taylor 1921). With a fixed lifetime 2T_L each eddy moves a tracer u′·2T_L, so over t = 200 T_L
        // the variance is exactly (2k/3)(2T_L)² (t/2T_L) = 2 D t in expectation. 4000 tracers × 3
        // components: relative standard error of the variance ≈ √(2/12000) = 1.3 %; tolerance 5 %.
        let s = DispersionSettings::default();
        let (k, eps) = (1.5, 3.0);
        let tl = s.time_scale_constant * k / eps;
        let dt = tl / 10.0;
        let steps = 2000;
        let mut var = 0.0;
        let n = 4000;
        for id in 0..n {
            let mut rng = seeded(1, id);
            let mut eddy = Eddy::default();
            let mut x = Vec3::ZERO;
            for _ in 0..steps {
                x += s.fluctuation(&mut eddy, &mut rng, k, eps, 0.0, 0.0, dt) * dt;
            }
            var += x.length_squared() / 3.0;
        }
        var /= n as f64;
        let t = steps as f64 * dt;
        let expect = 2.0 * (2.0 * k / 3.0) * tl * t;
        assert!((var / expect - 1.0).abs() < 0.05, "variance {var}, Taylor {expect}");
    }

    #[test]
    fn heavy_particles_cross_eddies_and_the_walk_repeats() {
        let s = DispersionSettings::default();
        let mut rng = seeded(3, 7);
        let mut eddy = Eddy::default();
        // τ|u−v| much larger than L_e: crossing time ≈ L_e/|u−v| is shorter than 2T_L.
        let (k, eps) = (1.0, 1.0);
        s.fluctuation(&mut eddy, &mut rng, k, eps, 10.0, 10.0, 0.0);
        let le = CMU_34 * k.powf(1.5) / eps;
        let expect = -10.0 * (1.0 - le / 100.0).ln();
        assert!((eddy.remaining - expect).abs() < 1e-12);
        assert!(eddy.remaining < 2.0 * 0.15);
        // Same seed and stream, same walk.
        let (mut a, mut b) = (seeded(9, 2), seeded(9, 2));
        let (mut ea, mut eb) = (Eddy::default(), Eddy::default());
        for _ in 0..100 {
            assert_eq!(
                s.fluctuation(&mut ea, &mut a, 2.0, 5.0, 1e-3, 0.1, 1e-3),
                s.fluctuation(&mut eb, &mut b, 2.0, 5.0, 1e-3, 0.1, 1e-3)
            );
        }
    }
}
