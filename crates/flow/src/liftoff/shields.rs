//! The Shields criterion for the onset of grain motion and its exceedance in unsteady flows.
//!
//! Jasion (2013) eq. 4.30 writes the Shields parameter with the grain density (not the submerged
//! density ρ_p − ρ_f, which differs by 0.05 % for sand in air): θ = τ_w/(ρ_p g D_p), with the critical
//! value θ* = 0.06 for uniform grains and 0.03 for mixed sizes (the thesis's reference stress
//! τ_ref = 0.03 ρ_p g D_p). In an unsteady flow the fraction of time with θ > θ* tells how often a
//! location can entrain (Jasion §4.5, Fig. 4.20).

/// Critical Shields parameter for uniform grains.
pub const SHIELDS_UNIFORM: f64 = 0.06;
/// Critical Shields parameter for mixed grain sizes (Jasion's τ_ref).
pub const SHIELDS_MIXED: f64 = 0.03;

/// Shields parameter θ = τ_w/(ρ_p g D_p) \[-\].
#[inline]
pub fn shields_parameter(tau_w: f64, rho_p: f64, g: f64, d: f64) -> f64 {
    tau_w / (rho_p * g * d)
}

/// Critical wall shear stress θ* ρ_p g D_p \[Pa\].
#[inline]
pub fn shields_stress(theta_c: f64, rho_p: f64, g: f64, d: f64) -> f64 {
    theta_c * rho_p * g * d
}

/// Fraction of the samples of `series` strictly above `threshold` (equally spaced samples of a time
/// series, or of one period of a periodic one); 0 for an empty series.
pub fn fraction_above(series: &[f64], threshold: f64) -> f64 {
    if series.is_empty() {
        return 0.0;
    }
    series.iter().filter(|&&v| v > threshold).count() as f64 / series.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_stress_of_the_thesis() {
        // τ_ref = 0.03 ρ_p g D_p: 7.30e-3 Pa for 10 µm and 0.219 Pa for 300 µm sand (2480 kg/m³, g = 9.81).
        assert!((shields_stress(SHIELDS_MIXED, 2480.0, 9.81, 10e-6) - 7.299e-3).abs() < 1e-6);
        assert!((shields_stress(SHIELDS_MIXED, 2480.0, 9.81, 300e-6) - 0.21896).abs() < 1e-5);
        assert!((shields_parameter(0.21896, 2480.0, 9.81, 300e-6) - 0.03).abs() < 1e-6);
        // A sine passing above the threshold for a third of its period: sin > 0.5 on (π/6, 5π/6).
        let s: Vec<f64> = (0..6000).map(|k| (k as f64 / 6000.0 * std::f64::consts::TAU).sin()).collect();
        assert!((fraction_above(&s, 0.5) - 1.0 / 3.0).abs() < 1e-3);
        assert_eq!(fraction_above(&[], 1.0), 0.0);
    }
}
