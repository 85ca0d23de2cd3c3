//! Elastic materials and the effective properties of a contacting pair.
//!
//! Definitions follow Chung & Ooi (2011), Granular Matter 13:643–656, §2:
//!
//! * E* = [(1−ν₁²)/E₁ + (1−ν₂²)/E₂]⁻¹
//! * G* = [(2−ν₁)/G₁ + (2−ν₂)/G₂]⁻¹ with G = E / (2(1+ν))  (Mindlin; identical to LIGGGHTS'
//!   1/G* = 2(2−ν₁)(1+ν₁)/E₁ + 2(2−ν₂)(1+ν₂)/E₂)
//! * R* = R₁R₂/(R₁+R₂), m* = m₁m₂/(m₁+m₂); a flat wall is R = ∞, a fixed body m = ∞.
//!
//! A rigid body is a material with `youngs_modulus = f64::INFINITY`; its compliance terms vanish.

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Isotropic elastic material.
///
/// In scenario files the keys carry their units: `youngs_modulus_pa`, `poisson_ratio`, `density_kg_m3`
/// (`youngs_modulus_pa = inf` makes a rigid body).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Young's modulus E \[Pa\]; `f64::INFINITY` for a rigid body.
    #[serde(rename = "youngs_modulus_pa")]
    pub youngs_modulus: f64,
    /// Poisson ratio ν \[-\], in \[0, 0.5).
    pub poisson_ratio: f64,
    /// Density ρ \[kg/m³\].
    #[serde(rename = "density_kg_m3")]
    pub density: f64,
}

impl crate::check::Validate for Material {
    fn validate(&self, c: &mut crate::check::Checker) {
        if self.youngs_modulus.is_nan() || self.youngs_modulus <= 0.0 {
            c.fail(
                "youngs_modulus_pa",
                format!(
                    "youngs_modulus_pa = {} must be a positive number of pascals (inf for a rigid body)",
                    self.youngs_modulus
                ),
            );
        }
        c.in_range("poisson_ratio", self.poisson_ratio, 0.0, true, 0.5, false);
        c.positive("density_kg_m3", self.density);
    }
}

/// A material value outside its physical range.
#[derive(Debug, Error, PartialEq)]
pub enum MaterialError {
    #[error("youngs_modulus = {0} is not a positive number of pascals")]
    YoungsModulus(f64),
    #[error("poisson_ratio = {0} is outside [0, 0.5)")]
    PoissonRatio(f64),
    #[error("density = {0} is not a positive number of kg/m³")]
    Density(f64),
}

impl Material {
    /// A checked material: E > 0 (∞ allowed), 0 ≤ ν < 0.5, ρ > 0 and finite.
    pub fn new(youngs_modulus: f64, poisson_ratio: f64, density: f64) -> Result<Self, MaterialError> {
        let m = Material { youngs_modulus, poisson_ratio, density };
        m.check()?;
        Ok(m)
    }

    /// Checks the physical ranges (see [`Material::new`]).
    pub fn check(&self) -> Result<(), MaterialError> {
        if self.youngs_modulus.is_nan() || self.youngs_modulus <= 0.0 {
            return Err(MaterialError::YoungsModulus(self.youngs_modulus));
        }
        if !(0.0..0.5).contains(&self.poisson_ratio) {
            return Err(MaterialError::PoissonRatio(self.poisson_ratio));
        }
        if !(self.density.is_finite() && self.density > 0.0) {
            return Err(MaterialError::Density(self.density));
        }
        Ok(())
    }

    /// Shear modulus G = E / (2(1+ν)) \[Pa\].
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }

    /// Normal compliance (1−ν²)/E \[1/Pa\]; zero for a rigid body.
    pub fn normal_compliance(&self) -> f64 {
        (1.0 - self.poisson_ratio * self.poisson_ratio) / self.youngs_modulus
    }

    /// Tangential compliance (2−ν)/G \[1/Pa\]; zero for a rigid body.
    pub fn tangential_compliance(&self) -> f64 {
        (2.0 - self.poisson_ratio) / self.shear_modulus()
    }
}

/// Effective Young's modulus E* \[Pa\] of two materials in contact.
pub fn effective_modulus(a: &Material, b: &Material) -> f64 {
    1.0 / (a.normal_compliance() + b.normal_compliance())
}

/// Effective shear modulus G* \[Pa\] (Mindlin) of two materials in contact.
pub fn effective_shear_modulus(a: &Material, b: &Material) -> f64 {
    1.0 / (a.tangential_compliance() + b.tangential_compliance())
}

/// Effective radius R* = R₁R₂/(R₁+R₂) \[m\]; pass `f64::INFINITY` for a flat wall (R* = R₁).
pub fn effective_radius(r1: f64, r2: f64) -> f64 {
    harmonic_pair(r1, r2)
}

/// Effective mass m* = m₁m₂/(m₁+m₂) \[kg\]; pass `f64::INFINITY` for a fixed body (m* = m₁).
pub fn effective_mass(m1: f64, m2: f64) -> f64 {
    harmonic_pair(m1, m2)
}

/// Damping ratio ξ = −ln e/√(ln²e + π²) ∈ \[0, 1) of the linear spring–dashpot contact that realises the
/// coefficient of restitution `e` ∈ (0, 1] (0 at e = 1, → 1 as e → 0). Its negative is the damping
/// parameter β of Tsuji, Tanaka & Ishida (1992) and Antypov & Elliott (2011, EPL 94:50004), which the
/// Hertzian dashpots of LIGGGHTS and LAMMPS use.
pub fn restitution_damping_ratio(e: f64) -> f64 {
    let l = e.ln();
    -l / (l * l + std::f64::consts::PI * std::f64::consts::PI).sqrt()
}

fn harmonic_pair(a: f64, b: f64) -> f64 {
    if a.is_infinite() {
        b
    } else if b.is_infinite() {
        a
    } else {
        a * b / (a + b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damping_ratio_of_restitution_matches_the_closed_form_and_inverts() {
        // Values of β = ln e/√(ln²e + π²) (Tsuji, Tanaka & Ishida 1992), evaluated to six digits
        // independently of this code; ξ = −β.
        for (e, xi) in [(0.3, 0.357857), (0.5, 0.215454), (0.7, 0.112808), (0.9, 0.033518)] {
            let got = restitution_damping_ratio(e);
            assert!((got - xi).abs() < 1e-6, "ξ({e}) = {got}, expected {xi}");
            // The linear oscillator's restitution e = exp(−πξ/√(1 − ξ²)) gives e back.
            let back = (-std::f64::consts::PI * got / (1.0 - got * got).sqrt()).exp();
            assert!((back - e).abs() < 1e-12, "e({got}) = {back}, expected {e}");
        }
        assert_eq!(restitution_damping_ratio(1.0), 0.0);
    }

    #[test]
    fn snow_seed_effective_moduli() {
        // Reference: computed from Lind (2017) Table 2:
        // ice–ABS E* = 1.88329e9 Pa, G* = 3.7323e8 Pa; ice–ice E* = 5.42095e9 Pa. Tolerance 1e-5 relative.
        let ice = Material::new(9.8e9, 0.31, 920.0).unwrap();
        let abs = Material::new(2.0e9, 0.35, 1100.0).unwrap();
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        assert!(rel(effective_modulus(&ice, &abs), 1.88329e9) < 1e-5);
        assert!(rel(effective_shear_modulus(&ice, &abs), 3.7323e8) < 1e-4);
        assert!(rel(effective_modulus(&ice, &ice), 5.42095e9) < 1e-5);
    }

    #[test]
    fn rigid_partner_and_flat_wall_limits() {
        let glass = Material::new(48e9, 0.2, 2800.0).unwrap();
        let rigid = Material::new(f64::INFINITY, 0.2, 2800.0).unwrap();
        assert_eq!(effective_modulus(&glass, &rigid), 48e9 / (1.0 - 0.04));
        assert_eq!(effective_radius(0.01, f64::INFINITY), 0.01);
        assert_eq!(effective_mass(2.0, f64::INFINITY), 2.0);
        assert_eq!(effective_radius(0.01, 0.01), 0.005);
    }

    #[test]
    fn out_of_range_values_are_rejected() {
        assert_eq!(Material::new(1e9, 0.6, 1000.0), Err(MaterialError::PoissonRatio(0.6)));
        assert_eq!(Material::new(1e9, 0.5, 1000.0), Err(MaterialError::PoissonRatio(0.5)));
        assert_eq!(Material::new(-1.0, 0.3, 1000.0), Err(MaterialError::YoungsModulus(-1.0)));
        assert_eq!(Material::new(1e9, 0.3, 0.0), Err(MaterialError::Density(0.0)));
        assert!(Material::new(1e9, 0.3, f64::NAN).is_err());
    }
}
