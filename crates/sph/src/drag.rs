//! Air drag on fluid particles.
//!
//! The truck wading thesis (Arjun & Michael 2022) gives no drag equation: the three tools only offer a switch (Preonlab force
//! field, Simcenter tick-box, LS-DYNA `*DEFINE_SPH_AMBIENT_DRAG` with air density and viscosity). We use the
//! standard drag of a sphere of the particle's volume, `F = ½ ρ_air C_D(Re) A |u_rel| u_rel` with
//! `u_rel = u_air − v`, `A = π d²/4`, `d = (6V/π)^{1/3}`, `Re = ρ_air |u_rel| d / μ_air` and the
//! Schiller & Naumann (1933) correlation `C_D = 24/Re (1 + 0.15 Re^0.687)` for `Re ≤ 1000`, 0.44 above
//! (Clift, Grace & Weber 1978, "Bubbles, Drops and Particles", Table 5.2).
//!
//! A particle inside the liquid is shielded by its neighbours, so the force is weighted by the particle's
//! exposure to air, following the idea of Gissler et al. (2017), "Approximate air-fluid interactions for
//! SPH", VRIPHYS: `e = clamp((1 − φ)/(1 − φ_self), 0, 1)`, where `φ = Σ_j V_j W_ij` is the kernel-weighted
//! volume fraction of liquid (walls count as liquid) and `φ_self = V_i W(0)` its value for an isolated
//! particle. A free droplet has `e = 1`, a particle in the bulk `e = 0`, a particle on a flat free surface
//! about ½. In 2D the particle is a cylinder per metre of depth: `d = 2 dp/√π`, frontal area `d`.

use crate::kernel::Dim;
use crate::params::DragParams;
use spatter_core::Vec3;

/// Schiller–Naumann drag coefficient of a sphere.
pub fn drag_coefficient(re: f64) -> f64 {
    if re <= 0.0 {
        return f64::INFINITY;
    }
    if re <= 1000.0 {
        24.0 / re * (1.0 + 0.15 * re.powf(0.687))
    } else {
        0.44
    }
}

/// Acceleration \[m/s²\] of a particle of mass `m`, volume `vol`, velocity `v`, liquid fraction `phi`
/// (with its own contribution `phi_self`).
pub fn acceleration(p: &DragParams, dim: Dim, v: Vec3, m: f64, vol: f64, phi: f64, phi_self: f64) -> Vec3 {
    let u = p.air_velocity - v;
    let speed = u.length();
    if speed == 0.0 || !p.enabled {
        return Vec3::ZERO;
    }
    let exposure = if phi_self < 1.0 { ((1.0 - phi) / (1.0 - phi_self)).clamp(0.0, 1.0) } else { 1.0 };
    if exposure == 0.0 {
        return Vec3::ZERO;
    }
    let (d, area) = match dim {
        Dim::Three => {
            let d = (6.0 * vol / std::f64::consts::PI).cbrt();
            (d, std::f64::consts::PI * d * d / 4.0)
        }
        Dim::Two => {
            let d = 2.0 * (vol / std::f64::consts::PI).sqrt();
            (d, d)
        }
    };
    let re = p.air_density * speed * d / p.air_viscosity;
    // ½ ρ C_D A |u| u with C_D·Re finite as Re → 0 (Stokes limit 3πμd u).
    let cd_times_speed = drag_coefficient(re) * speed;
    u * (exposure * 0.5 * p.air_density * cd_times_speed * area / m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stokes_limit_and_newton_regime() {
        let p = DragParams { enabled: true, ..DragParams::default() };
        // Stokes: F = 3πμ d u for Re ≪ 1 (within the Schiller–Naumann correction 0.15 Re^0.687).
        let d = 1e-5;
        let vol = std::f64::consts::PI * d * d * d / 6.0;
        let m = 1000.0 * vol;
        let v = Vec3::new(-1e-3, 0.0, 0.0);
        let a = acceleration(&p, Dim::Three, v, m, vol, 0.0, 0.0);
        let stokes = 3.0 * std::f64::consts::PI * p.air_viscosity * d * 1e-3 / m;
        let re: f64 = p.air_density * 1e-3 * d / p.air_viscosity;
        assert!((a.x / stokes - (1.0 + 0.15 * re.powf(0.687))).abs() < 1e-9, "{} vs {stokes}", a.x);
        // Newton regime: C_D = 0.44 for a 5 mm drop at 20 m/s (Re ≈ 6650), opposing the motion.
        let d = 5e-3;
        let vol = std::f64::consts::PI * d * d * d / 6.0;
        let a = acceleration(&p, Dim::Three, Vec3::new(0.0, 0.0, 20.0), 1000.0 * vol, vol, 0.0, 0.0);
        let want = 0.5 * 1.204 * 0.44 * std::f64::consts::PI * d * d / 4.0 * 400.0 / (1000.0 * vol);
        assert!((a.z + want).abs() < 1e-9 * want);
        // Quiescent air slows a particle whatever its direction; a shielded particle feels nothing.
        assert!(acceleration(&p, Dim::Three, Vec3::new(0.0, -3.0, 0.0), 1.0, 1e-3, 0.0, 0.0).y > 0.0);
        assert_eq!(acceleration(&p, Dim::Three, Vec3::X, 1.0, 1e-3, 1.0, 0.1), Vec3::ZERO);
        // Prescribed air velocity drives a particle at rest.
        let wind = DragParams { air_velocity: Vec3::new(5.0, 0.0, 0.0), ..p };
        assert!(acceleration(&wind, Dim::Two, Vec3::ZERO, 1.0, 1e-4, 0.0, 0.0).x > 0.0);
        // Switched off.
        assert_eq!(
            acceleration(&DragParams::default(), Dim::Three, Vec3::X, 1.0, 1e-3, 0.0, 0.0),
            Vec3::ZERO
        );
    }
}
