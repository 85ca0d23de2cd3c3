//! Snow and ice material helpers: ice Young's modulus against temperature and the time-step estimates the
//! snow thesis prints for its runs.

use spatter_core::material::Material;
use std::f64::consts::PI;

/// Young's modulus of polycrystalline ice \[Pa\] at temperature `t_celsius` \[°C\], thesis Eq. 20 as
/// printed (after Higa et al. 1998): E \[GPa\] = 100 / (10.40 (1 + 1.070×10⁻³ T + 1.87×10⁻⁶ T³)).
///
/// The cubic term is kept as printed: it gives 9.7724 GPa at −12 °C, the 9.8 GPa of the thesis tables
/// (Lind 2017; a T² reading would give 9.738 GPa).
pub fn ice_youngs_modulus(t_celsius: f64) -> f64 {
    let t = t_celsius;
    100.0 / (10.40 * (1.0 + 1.070e-3 * t + 1.87e-6 * t * t * t)) * 1e9
}

/// Normal Hertz stiffness of two identical spheres as the thesis prints it (Eq. 12, read with E outside
/// the root, a misprint of the thesis): k_n = √(2R)·E / (3(1 − ν²)) \[N/m^{3/2}\].
pub fn thesis_hertz_stiffness(radius: f64, youngs_modulus: f64, poisson_ratio: f64) -> f64 {
    (2.0 * radius).sqrt() * youngs_modulus / (3.0 * (1.0 - poisson_ratio * poisson_ratio))
}

/// Thesis Eq. 24: Δt = (1/10)·2π√(m/k_n) with k_n from Eq. 12 and m = ρ(π/6)d³ \[s\] for a sphere of
/// diameter `diameter` \[m\] of material `m`. Dimensionally inconsistent (k_n is in N/m^{3/2}) but it is
/// the number the thesis quotes: 0.129 ns at d = 10 µm and 2.294 ns at 100 µm for ice (Lind 2017).
pub fn thesis_time_step(diameter: f64, m: &Material) -> f64 {
    let mass = m.density * PI / 6.0 * diameter.powi(3);
    let k = thesis_hertz_stiffness(0.5 * diameter, m.youngs_modulus, m.poisson_ratio);
    0.2 * PI * (mass / k).sqrt()
}

/// The three time-step estimates of the thesis for one impact, all in seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeStepReport {
    /// Thesis Eq. 24 (one tenth of the "oscillation period" 2π√(m/k_n)).
    pub thesis_eq24: f64,
    /// Rayleigh time (thesis Eq. 25) of the particle.
    pub rayleigh: f64,
    /// Hertz contact time (thesis Eq. 26) at the impact speed.
    pub hertz: f64,
}

impl TimeStepReport {
    /// Estimates for a particle of diameter `diameter` \[m\] and material `particle` hitting a partner with
    /// effective modulus `e_star` \[Pa\], effective radius `r_star` \[m\] and effective mass `m_star` \[kg\]
    /// at `speed` \[m/s\].
    pub fn new(
        diameter: f64,
        particle: &Material,
        e_star: f64,
        r_star: f64,
        m_star: f64,
        speed: f64,
    ) -> Self {
        TimeStepReport {
            thesis_eq24: thesis_time_step(diameter, particle),
            rayleigh: spatter_core::timestep::rayleigh_time(
                0.5 * diameter,
                particle.density,
                particle.shear_modulus(),
                particle.poisson_ratio,
            ),
            hertz: spatter_core::timestep::hertz_time(m_star, r_star, e_star, speed),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ice_modulus_at_minus_twelve() {
        // Lind (2017): E(−12 °C) = 9.7724 GPa, E(−5) = 9.669, E(−20) = 9.978 GPa (printed digits).
        assert!((ice_youngs_modulus(-12.0) / 1e9 - 9.7724).abs() < 1e-4);
        assert!((ice_youngs_modulus(-5.0) / 1e9 - 9.669).abs() < 1e-3);
        assert!((ice_youngs_modulus(-20.0) / 1e9 - 9.978).abs() < 1e-3);
    }

    #[test]
    fn thesis_time_step_range() {
        // Lind (2017): 0.129 ns (d = 10 µm) and 2.294 ns (d = 100 µm); thesis prints 0.13–2.3 ns.
        let ice = Material::new(9.8e9, 0.31, 920.0).unwrap();
        assert!((thesis_time_step(10e-6, &ice) / 0.129e-9 - 1.0).abs() < 4e-3);
        assert!((thesis_time_step(100e-6, &ice) / 2.294e-9 - 1.0).abs() < 5e-4);
    }

    #[test]
    fn time_step_report_values() {
        // Lind (2017): Rayleigh 8.402 ns at d = 10 µm; Hertz (ice–ABS E*) 76.0 ns at 1 m/s for 10 µm.
        let ice = Material::new(9.8e9, 0.31, 920.0).unwrap();
        let m = 920.0 * PI / 6.0 * 1e-15;
        let r = TimeStepReport::new(10e-6, &ice, 1.88329e9, 5e-6, m, 1.0);
        assert!((r.rayleigh / 8.402e-9 - 1.0).abs() < 1e-3);
        assert!((r.hertz / 76.0e-9 - 1.0).abs() < 2e-3);
    }
}
