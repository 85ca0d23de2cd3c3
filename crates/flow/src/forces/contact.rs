//! Closed forms of the particle–surface contact that set the entrainment scales: the pull-off force of an
//! adhering sphere and the damping of a linear spring–dashpot contact from a restitution coefficient.
//!
//! * **Pull-off** (Jasion 2013 eq. 3.54–3.55): a sphere of radius r
//!   (the smaller body, treated as adhering to a flat surface) with work of adhesion σ comes off at
//!   F = (3/2)πσr (Johnson–Kendall–Roberts) or F = 2πσr (Derjaguin–Muller–Toporov). The thesis inverts
//!   measured pull-off forces (Jones et al.: 20–40 nN at 6 µm, 10–20 nN at 35 µm; Ibrahim et al.: 34 nN at
//!   72 µm) with the JKR form to get σ, hence σ = 2·10⁻⁴ J/m² of its Table 6.1 and of the force ranking.
//! * **Damping from restitution** (Jasion eq. 3.64): the linear contact
//!   m δ̈ + c δ̇ + k δ = 0 rebounds, after half a damped period π/ω_d, with
//!   e = exp(−πξ/√(1 − ξ²)), ξ = c/(2√(k m)); inverted, ξ = −ln e/√(π² + ln²e) and
//!   c = 2ξ√(k m_eff) (the thesis prints c with the sign of ln e, which would make it negative).

use std::f64::consts::PI;

/// Which adhesion theory gives the pull-off force.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PullOffTheory {
    /// Johnson, Kendall & Roberts (1971): F = (3/2)πσr.
    Jkr,
    /// Derjaguin, Muller & Toporov (1975): F = 2πσr.
    Dmt,
}

impl PullOffTheory {
    /// F/(σ r) \[-\].
    pub fn factor(self) -> f64 {
        match self {
            PullOffTheory::Jkr => 1.5 * PI,
            PullOffTheory::Dmt => 2.0 * PI,
        }
    }
}

/// Pull-off force \[N\] of a sphere of radius `r` \[m\] with work of adhesion `sigma` \[J/m²\].
pub fn pull_off_force(theory: PullOffTheory, sigma: f64, r: f64) -> f64 {
    theory.factor() * sigma * r
}

/// The work of adhesion \[J/m²\] that a measured pull-off `force` \[N\] of a sphere of radius `r` \[m\]
/// implies (the inverse of [`pull_off_force`]).
pub fn surface_energy_from_pull_off(theory: PullOffTheory, force: f64, r: f64) -> f64 {
    force / (theory.factor() * r)
}

/// Damping ratio ξ = −ln e/√(π² + ln²e) of the linear spring–dashpot contact with restitution `e` ∈ (0, 1]
/// (0 at e = 1, → 1 as e → 0).
pub use spatter_core::material::restitution_damping_ratio as damping_ratio;

/// Dashpot coefficient |c| = 2ξ√(k m_eff) \[N s/m\] that gives restitution `e` to a linear contact of
/// stiffness `k` \[N/m\] between bodies of effective mass `m_eff` \[kg\] (Jasion eq. 3.64–3.65).
pub fn linear_damping_coefficient(e: f64, k: f64, m_eff: f64) -> f64 {
    2.0 * damping_ratio(e) * (k * m_eff).sqrt()
}

/// Restitution of the linear contact m δ̈ + c δ̇ + k δ = 0 (under-damped, c < 2√(k m)): the analytic
/// solution δ = (u₀/ω_d) e^{−ξω_n t} sin ω_d t returns to δ = 0 at t = π/ω_d with speed u₀ e^{−ξω_nπ/ω_d}.
pub fn linear_contact_restitution(c: f64, k: f64, m: f64) -> f64 {
    let xi = c / (2.0 * (k * m).sqrt());
    (-PI * xi / (1.0 - xi * xi).sqrt()).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pull_off_and_its_inverse() {
        // Ibrahim et al. (Jasion L1253): σ = 2e-4 J/m² gives (3/2)π·2e-4·36e-6 = 3.393e-8 N ≈ 34 nN at 72 µm.
        let f = pull_off_force(PullOffTheory::Jkr, 2e-4, 36e-6);
        assert!((f - 1.5 * PI * 2e-4 * 36e-6).abs() < 1e-22);
        assert!((surface_energy_from_pull_off(PullOffTheory::Jkr, f, 36e-6) - 2e-4).abs() < 1e-18);
        // DMT is 4/3 of JKR for the same σ and r.
        let ratio = pull_off_force(PullOffTheory::Dmt, 2e-4, 36e-6) / f;
        assert!((ratio - 4.0 / 3.0).abs() < 1e-15);
    }

    #[test]
    fn damping_ratio_limits_and_round_trip() {
        // e = 1: no damping; the linear contact with c = 2ξ√(km) rebounds with the e it was built for
        // (e = 0.5 reproduced), to 1e-14.
        assert_eq!(damping_ratio(1.0), 0.0);
        for e in [0.9, 0.5, 0.2, 1e-4] {
            let (k, m) = (2.0e3, 3.0e-6);
            let c = linear_damping_coefficient(e, k, m);
            assert!((linear_contact_restitution(c, k, m) - e).abs() < 1e-14 * e.max(1e-2), "e = {e}");
        }
    }
}
