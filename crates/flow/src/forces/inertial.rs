//! Added mass, pressure-gradient (fluid-acceleration) force, gravity and buoyancy.
//!
//! Maxey & Riley (1983) form, per unit particle mass, with Du/Dt the fluid acceleration following the
//! fluid and dv/dt the particle acceleration:
//!
//! * pressure gradient (undisturbed flow): F_P/m = −∇p/ρ_p − (buoyancy part) = (ρ_f/ρ_p) Du/Dt, using
//!   ∇p = ρ_f (g − Du/Dt) + μ∇²u with the viscous term neglected and the hydrostatic part counted as
//!   buoyancy (Jasion 2013 eq. 3.47 writes −(1/ρ_p) ∇p);
//! * added mass: F_A/m = C_A (ρ_f/ρ_p) (Du/Dt − dv/dt), C_A = ½ for a sphere (Jasion eq. 3.46 keeps only
//!   the particle-acceleration part and prints it with a + sign; the force resists the particle's
//!   acceleration relative to the fluid). Because it contains dv/dt it is solved implicitly: the
//!   particle's inertia becomes (1 + C_A ρ_f/ρ_p), see [`effective_inertia`];
//! * gravity and buoyancy: F_g/m = (1 − ρ_f/ρ_p) g (Jasion eq. 3.48).

use spatter_core::Vec3;

/// Gravity with (or without) buoyancy, per unit mass \[m/s²\].
#[inline]
pub fn gravity_buoyancy(g: Vec3, rho_f: f64, rho_p: f64, buoyancy: bool) -> Vec3 {
    if buoyancy {
        (1.0 - rho_f / rho_p) * g
    } else {
        g
    }
}

/// Pressure-gradient force per unit mass \[m/s²\] from the fluid acceleration `du_dt` = Du/Dt.
#[inline]
pub fn pressure_gradient(du_dt: Vec3, rho_f: f64, rho_p: f64) -> Vec3 {
    rho_f / rho_p * du_dt
}

/// The explicit part of the added-mass force per unit mass, C_A (ρ_f/ρ_p) Du/Dt \[m/s²\]; the
/// −C_A (ρ_f/ρ_p) dv/dt part enters through [`effective_inertia`].
#[inline]
pub fn added_mass_explicit(du_dt: Vec3, c_a: f64, rho_f: f64, rho_p: f64) -> Vec3 {
    c_a * rho_f / rho_p * du_dt
}

/// Inertia factor 1 + C_A ρ_f/ρ_p: the particle equation with added mass is
/// (1 + C_A ρ_f/ρ_p) dv/dt = (sum of the other forces per unit mass) + C_A (ρ_f/ρ_p) Du/Dt.
#[inline]
pub fn effective_inertia(c_a: f64, rho_f: f64, rho_p: f64) -> f64 {
    1.0 + c_a * rho_f / rho_p
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn neutrally_buoyant_particle_follows_an_accelerating_fluid() {
        // ρ_p = ρ_f, no drag: (1 + C_A) dv/dt = Du/Dt + C_A Du/Dt → dv/dt = Du/Dt (Maxey & Riley 1983).
        let a = Vec3::new(3.0, -2.0, 1.0);
        let (rho, ca) = (1000.0, 0.5);
        let rhs = pressure_gradient(a, rho, rho) + added_mass_explicit(a, ca, rho, rho);
        let dvdt = rhs / effective_inertia(ca, rho, rho);
        assert!((dvdt - a).length() < 1e-14);
        // Gravity and buoyancy cancel.
        assert_eq!(gravity_buoyancy(Vec3::new(0.0, 0.0, -9.81), rho, rho, true), Vec3::ZERO);
        // A bubble (ρ_p ≪ ρ_f) accelerates 3× the fluid: (ρ_f/ρ_p)(1 + C_A)/(1 + C_A ρ_f/ρ_p) → 3.
        let (rf, rp) = (1000.0, 1e-3);
        let dvdt = (pressure_gradient(a, rf, rp) + added_mass_explicit(a, ca, rf, rp))
            / effective_inertia(ca, rf, rp);
        assert!((dvdt - 3.0 * a).length() < 1e-5 * a.length());
    }
}
