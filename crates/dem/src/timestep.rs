//! Time-step helpers: the Rayleigh and Hertz estimates for a set of particles and the warning rule.
//!
//! A DEM step must resolve both the elastic waves in a particle and the fastest contact:
//!
//! * Rayleigh time t_R = π R √(ρ/G) / (0.1631 ν + 0.8766) of the smallest, stiffest particle; LIGGGHTS
//!   and the snow thesis recommend Δt ≤ 20 % of t_R;
//! * Hertz contact duration t_c = 2.868 (m*²/(R* E*² v))^{1/5} at the highest expected impact speed v;
//!   resolving a contact needs Δt ≤ t_c / 20 (about 20 steps per contact; 50 or more for accurate
//!   restitution);
//! * for a linear (Hooke) spring k_n the contact lasts half an undamped period, t_c = π √(m*/k_n)
//!   (damping lengthens it, so this is the conservative bound); the same 20 steps per contact apply and the
//!   Rayleigh time is not used, since a soft spring, not the material's elastic waves, sets the step.
//!
//! [`check_dt`] returns a warning when Δt exceeds either bound.

use spatter_core::material::{effective_modulus, Material};
use spatter_core::math::sphere_volume;
use spatter_core::timestep::{hertz_time, rayleigh_time};

/// Largest recommended fraction of the Rayleigh time.
pub const RAYLEIGH_FRACTION: f64 = 0.2;
/// Smallest recommended number of steps per Hertz contact.
pub const STEPS_PER_CONTACT: f64 = 20.0;

/// Rayleigh time \[s\] of a sphere of `radius` \[m\] of `material` (∞ for a rigid material).
pub fn rayleigh(material: &Material, radius: f64) -> f64 {
    if material.youngs_modulus.is_infinite() {
        return f64::INFINITY;
    }
    rayleigh_time(radius, material.density, material.shear_modulus(), material.poisson_ratio)
}

/// Hertz contact time \[s\] of a sphere of `radius` of material `a` hitting a flat wall of material `b`
/// (pass the particle material twice for particle–particle) at `speed` \[m/s\].
pub fn hertz(a: &Material, b: &Material, radius: f64, speed: f64, particle_pair: bool) -> f64 {
    let m = a.density * sphere_volume(radius);
    let (m_eff, r_eff) = if particle_pair { (0.5 * m, 0.5 * radius) } else { (m, radius) };
    hertz_time(m_eff, r_eff, effective_modulus(a, b), speed.max(1e-9))
}

/// Undamped linear-spring contact duration t_c = π √(m*/k_n) \[s\] of effective mass `m_eff` \[kg\] on a
/// spring `k_n` \[N/m\] (half the period of m* on k_n).
pub fn linear_contact_time(m_eff: f64, k_n: f64) -> f64 {
    std::f64::consts::PI * (m_eff / k_n).sqrt()
}

/// Which contact duration a time-step check compares with (named in the warning).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContactKind {
    /// Hertz contact duration ([`hertz`]).
    Hertz,
    /// Linear spring contact duration ([`linear_contact_time`]).
    Linear,
}

/// A warning when `dt` exceeds [`RAYLEIGH_FRACTION`] of `t_rayleigh` or `t_hertz` / [`STEPS_PER_CONTACT`].
/// `t_contact` is the shortest contact duration of `kind`.
pub fn check_dt(dt: f64, t_rayleigh: f64, t_contact: f64, kind: ContactKind) -> Option<String> {
    let mut parts = Vec::new();
    if dt > RAYLEIGH_FRACTION * t_rayleigh {
        parts.push(format!(
            "dt_s = {dt:e} is {:.0} % of the Rayleigh time {t_rayleigh:e} s (recommended ≤ {:.0} %)",
            100.0 * dt / t_rayleigh,
            100.0 * RAYLEIGH_FRACTION
        ));
    }
    if dt > t_contact / STEPS_PER_CONTACT {
        let name = match kind {
            ContactKind::Hertz => "fastest Hertz contact",
            ContactKind::Linear => "shortest linear-spring contact",
        };
        parts.push(format!(
            "dt_s = {dt:e} resolves the {name} ({t_contact:e} s) with only {:.1} steps \
             (recommended ≥ {STEPS_PER_CONTACT})",
            t_contact / dt
        ));
    }
    (!parts.is_empty()).then(|| parts.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warning_rules() {
        let glass = Material::new(48e9, 0.2, 2800.0).unwrap();
        let tr = rayleigh(&glass, 0.001);
        // Rayleigh time of a 2 mm glass bead: π·1e-3·√(2800/20e9)/(0.1631·0.2 + 0.8766) = 1.2928e-6 s.
        assert!((tr / 1.292843e-6 - 1.0).abs() < 1e-5, "{tr}");
        let tc = hertz(&glass, &glass, 0.001, 1.0, true);
        assert!(check_dt(0.1 * tr, tr, tc, ContactKind::Hertz).is_none());
        let w = check_dt(0.5 * tr, tr, tc, ContactKind::Hertz).unwrap();
        assert!(w.contains("Rayleigh"), "{w}");
        assert!(check_dt(tc / 5.0, f64::INFINITY, tc, ContactKind::Hertz).unwrap().contains("Hertz"));
        assert!(check_dt(tc / 5.0, f64::INFINITY, tc, ContactKind::Linear).unwrap().contains("linear"));
    }

    #[test]
    fn linear_contact_time_is_half_the_spring_period() {
        // m* = 1 g on k = 1e4 N/m: ω = √(k/m) = 3162.3 rad/s, half period π/ω = 9.9346e-4 s (a free
        // harmonic oscillator).
        let t = linear_contact_time(1e-3, 1e4);
        assert!((t / 9.934_588e-4 - 1.0).abs() < 1e-6, "{t}");
    }
}
