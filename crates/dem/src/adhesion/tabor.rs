//! Tabor parameter: whether an adhesive contact is JKR-like (soft, large, strongly adhesive) or DMT-like.

/// Tabor parameter λ_T = (R* Γ² / (E*² z₀³))^{1/3} \[-\] for R* \[m\], Γ \[J/m²\], E* \[Pa\] and the
/// equilibrium separation z₀ \[m\] (0.2–0.4 nm). JKR applies for λ_T > 5 (Krijt et al. 2013; snow thesis
/// Eq. 15; the thesis's Eq. 23 misprints E* without the square).
pub fn tabor_parameter(r_star: f64, work_of_adhesion: f64, e_star: f64, z0: f64) -> f64 {
    (r_star * work_of_adhesion * work_of_adhesion / (e_star * e_star * z0 * z0 * z0)).cbrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn snow_thesis_tabor_range() {
        // Thesis L398–400: 9.6 ≤ λ_T ≤ 41.3; the formula gives 9.587 (R = 5 µm, z₀ = 0.4 nm) and
        // 41.308 (R = 50 µm, z₀ = 0.2 nm) with ice–ABS E* = 1.88329e9 Pa. Tolerance: 4 printed digits.
        let e = 1.88329e9;
        assert!((tabor_parameter(5e-6, 0.2, e, 0.4e-9) - 9.587).abs() < 1e-3);
        assert!((tabor_parameter(50e-6, 0.2, e, 0.2e-9) - 41.308).abs() < 1e-3);
        assert!((tabor_parameter(5e-6, 0.2, e, 0.2e-9) - 19.173).abs() < 1e-3);
    }
}
