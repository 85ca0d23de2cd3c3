//! Rotation of a rigid body: the free-rotor step of the symmetric splitting of Dullweber, Leimkuhler &
//! McLachlan (1997), "Symplectic splitting methods for rigid body molecular dynamics", J. Chem. Phys.
//! 107:5840 (the scheme LAMMPS calls NO_SQUISH, Miller et al. 2002, J. Chem. Phys. 116:8649).
//!
//! State: the orientation quaternion q (body frame → space frame, x_space = X + q r_body) and the angular
//! momentum in the body's principal frame π. The Hamiltonian of free rotation is split into the three
//! principal parts π_k²/(2 I_k); each part is a rotation about one principal axis by the angle
//! φ = Δt π_k/I_k, which turns the other two components of π by −φ and the body by +φ:
//!
//! ```text
//!   R_k(Δt):  q ← q ⊗ (cos φ/2, sin φ/2 e_k),   (π_i, π_j) ← rotation by −φ,   φ = Δt π_k / I_k
//!   free step over Δt = R_1(Δt/2) R_2(Δt/2) R_3(Δt) R_2(Δt/2) R_1(Δt/2)
//! ```
//!
//! Why this scheme: every sub-step is an exact rotation, so |π| and the space-frame angular momentum
//! L = q π q* are conserved to round-off in a torque-free motion (not just to the truncation error), the
//! composition is symplectic and time-reversible, so the kinetic energy error stays bounded (it oscillates
//! at O((ωΔt)²) without drift over any number of steps), and it fits the kick–drift–kick structure of
//! velocity Verlet: torques kick π by ½Δt at each end of the step, the free rotor is the rotational
//! "drift". With an isotropic inertia (sphere-like bodies) the gyroscopic term vanishes identically and
//! the engine kicks ω directly (see [`crate::clump::Bodies`]).
//!
//! The quaternion is renormalised after every step (|q| = 1 to round-off).

use spatter_core::{Quat, Vec3};

/// One exact sub-rotation about principal axis `axis` (0, 1, 2) for time `h` \[s\].
#[inline]
fn rotate_about(axis: usize, h: f64, q: &mut Quat, pi: &mut Vec3, inv_i: Vec3) {
    let phi = h * pi[axis] * inv_i[axis];
    let (s, c) = phi.sin_cos();
    // π rotated by −φ about e_axis: components (j, k) cyclic after `axis`.
    let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
    let (pj, pk) = (pi[j], pi[k]);
    pi[j] = c * pj + s * pk;
    pi[k] = -s * pj + c * pk;
    // q ← q ⊗ (cos φ/2, sin φ/2 e_axis).
    let (sh, ch) = (0.5 * phi).sin_cos();
    let mut v = [0.0; 3];
    v[axis] = sh;
    *q *= Quat::from_xyzw(v[0], v[1], v[2], ch);
}

/// Advances the torque-free rotation of a body with principal inverse inertia `inv_i` \[1/(kg m²)\] by `dt`
/// \[s\]: orientation `q` and body-frame angular momentum `pi` \[kg m²/s\] (symmetric splitting, module
/// docs). The quaternion is renormalised.
pub fn free_rotation(q: &mut Quat, pi: &mut Vec3, inv_i: Vec3, dt: f64) {
    let h = 0.5 * dt;
    rotate_about(0, h, q, pi, inv_i);
    rotate_about(1, h, q, pi, inv_i);
    rotate_about(2, dt, q, pi, inv_i);
    rotate_about(1, h, q, pi, inv_i);
    rotate_about(0, h, q, pi, inv_i);
    *q = q.normalize();
}

/// Rotation of an isotropic body (I the same about every axis) with space-frame angular velocity `omega`
/// \[rad/s\] over `dt` \[s\]: q ← exp(½ ω Δt) ⊗ q, exact for a constant ω, renormalised.
pub fn spin_isotropic(q: &mut Quat, omega: Vec3, dt: f64) {
    let a = omega * dt;
    if a == Vec3::ZERO {
        return;
    }
    *q = (Quat::from_scaled_axis(a) * *q).normalize();
}

/// Space-frame angular velocity of a body with orientation `q`, body-frame angular momentum `pi` and
/// principal inverse inertia `inv_i`: ω = q (π ∘ I⁻¹) q* \[rad/s\].
#[inline]
pub fn omega_space(q: Quat, pi: Vec3, inv_i: Vec3) -> Vec3 {
    q * (pi * inv_i)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Torque-free asymmetric top (principal moments 1, 2, 3): the space-frame angular momentum, the
    /// rotational energy and |q| are invariants of the exact motion (Landau & Lifshitz, Mechanics §37).
    #[test]
    fn torque_free_rotation_conserves_l_energy_and_unit_quaternion() {
        let inertia = Vec3::new(1.0, 2.0, 3.0);
        let inv_i = inertia.recip();
        let mut q = Quat::from_rotation_y(0.3) * Quat::from_rotation_x(0.2);
        let mut pi = Vec3::new(0.4, 0.2, 1.0);
        let l0 = q * pi;
        let e0 = 0.5 * pi.dot(pi * inv_i);
        let dt = 1e-3;
        let (mut max_dl, mut max_de, mut max_dq): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for _ in 0..100_000 {
            free_rotation(&mut q, &mut pi, inv_i, dt);
            max_dl = max_dl.max((q * pi - l0).length() / l0.length());
            max_de = max_de.max((0.5 * pi.dot(pi * inv_i) - e0).abs() / e0);
            max_dq = max_dq.max((q.length() - 1.0).abs());
        }
        // Tolerances of the verification plan for rigid multi-sphere bodies: L to 1e-10, energy to 1e-8
        // (ω Δt ≈ 5e-4 here), |q| = 1 to 1e-12.
        assert!(max_dl < 1e-10, "|ΔL|/|L| = {max_dl:e}");
        assert!(max_de < 1e-8, "ΔE/E = {max_de:e}");
        assert!(max_dq < 1e-12, "||q| − 1| = {max_dq:e}");
    }

    /// Rotation about the intermediate principal axis is unstable (tennis-racket or Dzhanibekov effect):
    /// started close to it, the body flips periodically; about the largest and the smallest axes it
    /// stays (Landau & Lifshitz, Mechanics §37).
    #[test]
    fn rotation_about_the_intermediate_axis_flips_and_about_the_others_is_stable() {
        let inertia = Vec3::new(1.0, 2.0, 3.0);
        let inv_i = inertia.recip();
        let run = |axis: usize| {
            let mut q = Quat::IDENTITY;
            let mut pi = Vec3::splat(1e-3);
            pi[axis] = 2.0;
            let mut flips = 0;
            let mut min_along = f64::INFINITY;
            let mut sign = 1.0;
            for _ in 0..200_000 {
                free_rotation(&mut q, &mut pi, inv_i, 1e-3);
                let along = pi[axis] / pi.length();
                min_along = min_along.min(along.abs());
                if along * sign < -0.5 {
                    flips += 1;
                    sign = -sign;
                }
            }
            (flips, min_along)
        };
        let (f1, m1) = run(1);
        assert!(f1 >= 2, "intermediate axis: {f1} flips");
        assert!(m1 < 0.01);
        for axis in [0, 2] {
            let (f, m) = run(axis);
            assert_eq!(f, 0, "axis {axis} must be stable");
            assert!(m > 0.999, "axis {axis}: the rotation axis wandered to {m}");
        }
    }

    #[test]
    fn isotropic_spin_turns_by_omega_dt() {
        let mut q = Quat::IDENTITY;
        spin_isotropic(&mut q, Vec3::new(0.0, 0.0, 2.0), 0.25);
        let x = q * Vec3::X;
        assert!((x - Vec3::new(0.5f64.cos(), 0.5f64.sin(), 0.0)).length() < 1e-15);
    }
}
