//! Time-step estimates for contact mechanics.

use std::f64::consts::PI;

/// Rayleigh-wave time Δt_R = π R √(ρ/G) / (0.1631 ν + 0.8766) \[s\] for a sphere of radius `radius` \[m\],
/// density \[kg/m³\], shear modulus \[Pa\] and Poisson ratio.
///
/// Reference: LIGGGHTS `fix check/timestep/gran` documentation; snow thesis (Lind 2017)
/// Eq. 25.
pub fn rayleigh_time(radius: f64, density: f64, shear_modulus: f64, poisson_ratio: f64) -> f64 {
    PI * radius * (density / shear_modulus).sqrt() / (0.1631 * poisson_ratio + 0.8766)
}

/// Hertz contact duration t_c = 2.868 (m*² / (R* E*² v))^{1/5} \[s\] of an elastic impact at approach
/// speed `speed` \[m/s\].
///
/// Reference: Chung & Ooi (2011) (coefficient 2.868; the snow thesis Eq. 26 rounds it
/// to 2.87).
pub fn hertz_time(effective_mass: f64, effective_radius: f64, effective_modulus: f64, speed: f64) -> f64 {
    2.868
        * (effective_mass * effective_mass
            / (effective_radius * effective_modulus * effective_modulus * speed))
            .powf(0.2)
}

/// Period-based estimate for a linear spring of stiffness `k` \[N/m\] and mass `m` \[kg\]:
/// Δt = 2π √(m/k) / 10 — one tenth of the oscillation period (snow thesis Eq. 14).
pub fn spring_period_step(mass: f64, stiffness: f64) -> f64 {
    0.2 * PI * (mass / stiffness).sqrt()
}

/// Time step of a linear contact resolved by `a_res` steps: Δt = √(m/k_n) / a_res \[s\] for a particle
/// of mass `mass` \[kg\] on a spring of stiffness `stiffness` \[N/m\]. The undamped contact lasts
/// π√(m*/k_n) (m* = m/2 for two equal particles), so a_res = 10 gives about 22 steps per
/// particle–particle contact.
///
/// Reference: Jasion (2013), PhD thesis, University of Southampton, Eq. 3.69.
pub fn linear_contact_step(mass: f64, stiffness: f64, a_res: f64) -> f64 {
    (mass / stiffness).sqrt() / a_res
}

/// Linear stiffness k_n = (4/15) E/(1 − ν²) √(2 r δ_max) \[N/m\] that matches the Hertz force of two
/// equal spheres of radius `radius` \[m\] (Young's modulus \[Pa\], Poisson ratio) at the expected
/// largest overlap `max_overlap` \[m\].
///
/// Reference: Jasion (2013), PhD thesis, University of Southampton, Eq. 3.70.
pub fn linear_stiffness_from_modulus(
    youngs_modulus: f64,
    poisson_ratio: f64,
    radius: f64,
    max_overlap: f64,
) -> f64 {
    4.0 / 15.0 * youngs_modulus / (1.0 - poisson_ratio * poisson_ratio) * (2.0 * radius * max_overlap).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_contact_step_resolves_the_contact() {
        // Jasion (2013) Eq. 3.69: m = 4 kg, k = 1 N/m, a_res = 20 → Δt = 0.1 s (exact arithmetic).
        assert!((linear_contact_step(4.0, 1.0, 20.0) - 0.1).abs() < 1e-15);
    }

    #[test]
    fn linear_stiffness_matches_hertz_work_to_the_overlap() {
        // Jasion (2013) Eq. 3.70 is the stiffness whose spring stores, at δ_max, the same energy as the
        // Hertz contact of two equal spheres: ½ k δ² = (8/15) E* √R* δ^{5/2} with E* = E/(2(1 − ν²)),
        // R* = r/2 (Johnson 1985 §4.2). Checked to round-off (1e-12 relative).
        let (e, nu, r, d) = (70e9, 0.3, 2e-3, 2e-5);
        let k = linear_stiffness_from_modulus(e, nu, r, d);
        let e_star = e / (2.0 * (1.0 - nu * nu));
        let hertz_work = 8.0 / 15.0 * e_star * (0.5 * r).sqrt() * d.powf(2.5);
        assert!((0.5 * k * d * d / hertz_work - 1.0).abs() < 1e-12, "{k}");
    }

    #[test]
    fn rayleigh_time_matches_snow_thesis() {
        // Lind (2017): ice, G = 3.7405 GPa, ν = 0.31, ρ = 920:
        // Δt_R = 8.402 ns at d = 10 µm. Tolerance 1e-3 relative (4 printed digits).
        let g = 9.8e9 / (2.0 * 1.31);
        let t = rayleigh_time(5e-6, 920.0, g, 0.31);
        assert!((t / 8.402e-9 - 1.0).abs() < 1e-3, "{t}");
    }

    #[test]
    fn hertz_time_matches_chung_ooi_glass() {
        // Chung & Ooi (2011) test 1, glass: t_c = 40.34 µs (1 %).
        // Two spheres R = 0.01, v = ±10 → approach speed 20 m/s, R* = 0.005, m* = m/2.
        let e_star = 48e9 / (2.0 * (1.0 - 0.04));
        let m = 2800.0 * 4.0 / 3.0 * PI * 1e-6;
        let t = hertz_time(m / 2.0, 0.005, e_star, 20.0);
        assert!((t / 40.34e-6 - 1.0).abs() < 0.01, "{t}");
    }
}
