//! Empirical entrainment models: threshold friction velocities and the mass of dust a flow lifts per
//! unit ground area and time (Jasion 2013 §2.4, §2.6, eq. 2.1–2.8).
//!
//! * **Threshold** (Bagnold 1941; Shao & Lu 2000, eq. 2.4): u_*t = B √((ρ_p − ρ_f) g D/ρ_f + C/(ρ_f D)),
//!   equivalently the critical stress τ_c = ρ_f u_*t² = B² (Δρ g D + C/D) (Haehnel's eq. 2.2). Presets:
//!   Bagnold's fluid threshold B = 0.1, C = 0; Shao & Lu's B = 0.1109 (B² = A_N = 0.0123),
//!   C = 3 × 10⁻⁴ N/m — the aeolian constants Haehnel uses. The cohesion term C/D makes fine grains
//!   harder to lift: the threshold has a minimum near 100 µm.
//! * **Haehnel** jet erosion (eq. 2.1): q = (C_q/g)(τ_w − τ_c) for τ_w > τ_c. The thesis gives C_q "in
//!   m⁻¹"; with C_q in s⁻¹ q is a mass flux per unit area \[kg/(m² s)\], which is how it is used here.
//! * **Wachspress** et al. (eq. 2.3, 2.6): the friction velocity from a rough-wall log profile
//!   u(y) = 5.75 u_* log₁₀(y/k_r) at y = 0.3 m, k_r = D/30; the injected flux Q = C_w (v_ref − u_*t)³ with
//!   the speed v_ref at the reference height, as printed, C_w fitted to rotor wash.
//! * **White** horizontal saltation flux (eq. 2.8, used by Phillips & Brown): Q = E c (ρ_f/g) u_*³
//!   (1 − u_*t/u_*)(1 + u_*t²/u_*²) \[kg/(m s)\] with c = 0.261 and E the erodible fraction of the surface,
//!   and the vertical dust source S = Q e^(13.4 f − 6.0) \[kg/(m² s)\] with the clay fraction f (0.1), the
//!   form the thesis prints (Marticorena & Bergametti 1995 write the ratio as 10^(13.4f − 6) cm⁻¹).

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};

/// Constants B, C of the threshold friction velocity u_*t = B √(Δρ g D/ρ_f + C/(ρ_f D)).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Threshold {
    /// B \[-\].
    pub b: f64,
    /// C \[N/m\].
    #[serde(rename = "c_n_m")]
    pub c: f64,
}

impl Threshold {
    /// Bagnold's (1941) fluid threshold: B = 0.1, no cohesion term.
    pub const BAGNOLD: Threshold = Threshold { b: 0.1, c: 0.0 };
    /// Shao & Lu (2000), as used by Haehnel: B = 0.1109, C = 3 × 10⁻⁴ N/m.
    pub const SHAO_LU: Threshold = Threshold { b: 0.1109, c: 3e-4 };

    /// Critical wall shear stress τ_c = B² (Δρ g D + C/D) \[Pa\] (Haehnel, eq. 2.2).
    pub fn critical_stress(&self, d: f64, rho_p: f64, rho_f: f64, g: f64) -> f64 {
        self.b * self.b * ((rho_p - rho_f) * g * d + self.c / d)
    }

    /// Threshold friction velocity u_*t = √(τ_c/ρ_f) \[m/s\] (eq. 2.4).
    pub fn friction_velocity(&self, d: f64, rho_p: f64, rho_f: f64, g: f64) -> f64 {
        (self.critical_stress(d, rho_p, rho_f, g) / rho_f).sqrt()
    }
}

impl Validate for Threshold {
    fn validate(&self, c: &mut Checker) {
        c.positive("b", self.b);
        c.non_negative("c_n_m", self.c);
    }
}

/// Friction velocity \[m/s\] from a speed `u` at height `y` over a rough wall of roughness `k_r`, by the
/// log profile u = 5.75 u_* log₁₀(y/k_r) of Wachspress et al. (eq. 2.3); 0 where y ≤ k_r.
pub fn rough_wall_friction_velocity(u: f64, y: f64, k_r: f64) -> f64 {
    let l = (y / k_r).log10();
    if l <= 0.0 {
        0.0
    } else {
        u.abs() / (5.75 * l)
    }
}

/// An entrainment model: the vertical dust flux per unit ground area.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum EntrainmentModel {
    /// Haehnel: q = (C_q/g)(τ_w − τ_c).
    Haehnel {
        /// C_q \[1/s\].
        #[serde(rename = "coefficient_1_s")]
        coefficient: f64,
    },
    /// Wachspress et al.: Q = C_w (v_ref − u_*t)³, v_ref the speed at the reference height.
    Wachspress {
        /// C_w \[kg s²/m⁵\].
        #[serde(rename = "coefficient_kg_s2_m5")]
        coefficient: f64,
    },
    /// White's horizontal flux with the Phillips–Brown source S = Q e^(13.4 f − 6.0).
    White {
        /// Erodible fraction E of the surface \[-\].
        #[serde(default = "one")]
        erodible_fraction: f64,
        /// Clay fraction f \[-\].
        #[serde(default = "default_clay")]
        clay_fraction: f64,
    },
}

fn one() -> f64 {
    1.0
}
fn default_clay() -> f64 {
    0.1
}

/// White's constant c (eq. 2.8).
pub const WHITE_C: f64 = 0.261;

/// White's horizontal saltation flux \[kg/(m s)\] at friction velocity `u_star` over threshold `u_t`.
pub fn white_horizontal_flux(u_star: f64, u_t: f64, erodible: f64, rho_f: f64, g: f64) -> f64 {
    if u_star <= u_t {
        return 0.0;
    }
    let r = u_t / u_star;
    erodible * WHITE_C * rho_f / g * u_star.powi(3) * (1.0 - r) * (1.0 + r * r)
}

/// Phillips & Brown's vertical source per unit horizontal flux e^(13.4 f − 6.0) \[1/m\].
pub fn phillips_brown_ratio(clay_fraction: f64) -> f64 {
    (13.4 * clay_fraction - 6.0).exp()
}

/// What the ground sees at one point: friction velocity, wall shear and the speed at the reference
/// height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundState {
    pub u_star: f64,
    pub tau_w: f64,
    pub reference_speed: f64,
}

impl EntrainmentModel {
    /// Vertical dust mass flux \[kg/(m² s)\] for grains with threshold `u_t` (critical stress
    /// ρ_f u_t²), air density `rho_f`, gravity `g`.
    pub fn flux(&self, ground: &GroundState, u_t: f64, rho_f: f64, g: f64) -> f64 {
        match *self {
            EntrainmentModel::Haehnel { coefficient } => {
                let tau_c = rho_f * u_t * u_t;
                (coefficient / g * (ground.tau_w - tau_c)).max(0.0)
            }
            EntrainmentModel::Wachspress { coefficient } => {
                let excess = ground.reference_speed - u_t;
                if excess > 0.0 {
                    coefficient * excess.powi(3)
                } else {
                    0.0
                }
            }
            EntrainmentModel::White { erodible_fraction, clay_fraction } => {
                white_horizontal_flux(ground.u_star, u_t, erodible_fraction, rho_f, g)
                    * phillips_brown_ratio(clay_fraction)
            }
        }
    }
}

impl Validate for EntrainmentModel {
    fn validate(&self, c: &mut Checker) {
        match self {
            EntrainmentModel::Haehnel { coefficient } => c.non_negative("coefficient_1_s", *coefficient),
            EntrainmentModel::Wachspress { coefficient } => {
                c.non_negative("coefficient_kg_s2_m5", *coefficient)
            }
            EntrainmentModel::White { erodible_fraction, clay_fraction } => {
                c.in_range("erodible_fraction", *erodible_fraction, 0.0, true, 1.0, true);
                c.in_range("clay_fraction", *clay_fraction, 0.0, true, 1.0, true);
            }
        }
    }
}

/// Mass rate \[kg/s\] lifted from each annulus between consecutive `edges` (radii \[m\], increasing) of
/// an axisymmetric ground, the flux \[kg/(m² s)\] taken at the annulus mid-radius by `flux_at(r)`.
pub fn annulus_rates(edges: &[f64], flux_at: impl Fn(f64) -> f64) -> Vec<f64> {
    edges
        .windows(2)
        .map(|w| std::f64::consts::PI * (w[1] * w[1] - w[0] * w[0]) * flux_at(0.5 * (w[0] + w[1])))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn haehnel_thresholds() {
        // From Haehnel's constants (B = 0.1109, C = 3e-4 N/m), sand 2480 kg/m³ in air 1.19 kg/m³,
        // g = 9.81, from Jasion (2013) eq. 2.2 (reference values to 3 significant figures):
        // (D, τ_c, u*_t) = (10 µm, 0.372 Pa, 0.559 m/s), (100 µm, 0.0668, 0.237),
        // (300 µm, 0.102, 0.293), (500 µm, 0.157, 0.363).
        let t = Threshold::SHAO_LU;
        for (d, tau, u) in
            [(10e-6, 0.372, 0.559), (100e-6, 0.0668, 0.237), (300e-6, 0.102, 0.293), (500e-6, 0.157, 0.363)]
        {
            let tc = t.critical_stress(d, 2480.0, 1.19, 9.81);
            let ut = t.friction_velocity(d, 2480.0, 1.19, 9.81);
            assert!((tc / tau - 1.0).abs() < 0.005, "{d}: τ_c {tc}");
            assert!((ut / u - 1.0).abs() < 0.005, "{d}: u*t {ut}");
        }
        // Bagnold: u*t = 0.1 √(Δρ g D/ρ_f): 300 µm → 0.1 √(2478.81·9.81·3e-4/1.19) = 0.24760 m/s.
        let ub = Threshold::BAGNOLD.friction_velocity(300e-6, 2480.0, 1.19, 9.81);
        assert!((ub - 0.24760).abs() < 5e-5, "{ub}");
        // The Shao–Lu threshold has its minimum near 100 µm: D* = √(C/(Δρ g)) = 110 µm.
        let f = |d: f64| t.friction_velocity(d, 2480.0, 1.19, 9.81);
        assert!(f(110e-6) < f(90e-6) && f(110e-6) < f(130e-6));
    }

    #[test]
    fn fluxes_by_hand() {
        let (rho, g) = (1.19, 9.81);
        // White: u* = 0.6, u*t = 0.3 → Q = 0.261 (1.19/9.81) 0.216 (0.5)(1.25) = 4.2746e-3 kg/(m s).
        let q = white_horizontal_flux(0.6, 0.3, 1.0, rho, g);
        assert!((q - 0.261 * rho / g * 0.216 * 0.5 * 1.25).abs() < 1e-15 && (q - 4.2746e-3).abs() < 1e-6);
        assert_eq!(white_horizontal_flux(0.2, 0.3, 1.0, rho, g), 0.0);
        // Phillips–Brown source at f = 0.1: e^(−4.66) = 9.4665e-3 per metre.
        assert!((phillips_brown_ratio(0.1) - 9.4665e-3).abs() < 1e-7);
        let ground = GroundState { u_star: 0.6, tau_w: rho * 0.36, reference_speed: 8.0 };
        let m = EntrainmentModel::White { erodible_fraction: 0.5, clay_fraction: 0.1 };
        assert!((m.flux(&ground, 0.3, rho, g) - 0.5 * q * phillips_brown_ratio(0.1)).abs() < 1e-15);
        // Haehnel: C_q = 2 s⁻¹, τ_w = 0.4284 Pa, u*t = 0.3 (τ_c = 0.1071) → (2/9.81)(0.3213) kg/(m² s).
        let h = EntrainmentModel::Haehnel { coefficient: 2.0 };
        assert!((h.flux(&ground, 0.3, rho, g) - 2.0 / g * (rho * 0.36 - rho * 0.09)).abs() < 1e-15);
        // Wachspress: C_w (8 − 0.3)³.
        let w = EntrainmentModel::Wachspress { coefficient: 1e-6 };
        assert!((w.flux(&ground, 0.3, rho, g) - 1e-6 * 7.7f64.powi(3)).abs() < 1e-18);
        // Rough-wall log profile: u = 5.75 u* log10(y/k): 0.3 m over k = 10 µm: u* = u/(5.75·4.4771).
        let us = rough_wall_friction_velocity(10.0, 0.3, 1e-5);
        assert!((us - 10.0 / (5.75 * 30000f64.log10())).abs() < 1e-12);
    }

    #[test]
    fn annuli_integrate_a_uniform_flux() {
        // A uniform 1e-3 kg/(m² s) over 0..10 m in 5 annuli: total π 10² 1e-3.
        let edges: Vec<f64> = (0..=5).map(|k| 2.0 * k as f64).collect();
        let rates = annulus_rates(&edges, |_| 1e-3);
        let total: f64 = rates.iter().sum();
        assert!((total - std::f64::consts::PI * 100.0 * 1e-3).abs() < 1e-15);
        assert!((rates[0] - std::f64::consts::PI * 4.0 * 1e-3).abs() < 1e-15);
    }
}
