//! Drag laws.
//!
//! The drag acceleration on a particle of diameter d and density ρ_p is written
//!
//! a_D = f(Re) · (u_f − v_p) / τ_p,    τ_p = ρ_p d² / (18 μ),    f = C_D Re / 24,
//!
//! so that f = 1 is Stokes drag and every other law is a correction factor (Jasion 2013, eq. 3.32–3.34
//! and L1466, with the sign of the printed expression corrected so that drag resists slip). For non-spherical particles d is the volume-equivalent diameter.

use super::{reynolds, stokes_time, Fluid};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};

/// A drag coefficient law C_D(Re).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "snake_case", deny_unknown_fields)]
pub enum DragLaw {
    /// C_D = 24/Re (Stokes 1851; Jasion eq. 3.33).
    Stokes,
    /// C_D = 24/Re (1 + 0.15 Re^0.687) for Re < 1000, 0.44 above (Schiller & Naumann 1933; Jasion eq.
    /// 3.34 quotes validity to Re < 800; the constant Newton branch above 1000 is the usual
    /// continuation, e.g. Crowe et al., *Multiphase Flows with Droplets and Particles*, 2nd ed., §4.2).
    #[default]
    SchillerNaumann,
    /// C_D = (0.63 + 4.8/√Re)² (Dallavalle), multiplied in a suspension of fluid volume fraction ε by the
    /// Di Felice (1994) voidage factor ε^(2−χ), χ = 3.7 − 0.65 exp(−(1.5 − log₁₀ Re_ε)²/2) with
    /// Re_ε = ε Re (Di Felice, Int. J. Multiphase Flow 20:153–159, 1994). `voidage = None` (or 1) gives
    /// the single-particle law without the voidage factor.
    DiFelice {
        #[serde(default)]
        voidage: Option<f64>,
    },
    /// Haider & Levenspiel (1989), Powder Technol. 58:63–70, eq. 10: non-spherical particles of
    /// sphericity φ ∈ (0, 1] (φ = 1 for a sphere).
    HaiderLevenspiel { sphericity: f64 },
}

impl Validate for DragLaw {
    fn validate(&self, c: &mut Checker) {
        match self {
            DragLaw::DiFelice { voidage: Some(e) } => c.in_range("voidage", *e, 0.0, false, 1.0, true),
            DragLaw::HaiderLevenspiel { sphericity } => {
                c.in_range("sphericity", *sphericity, 0.0, false, 1.0, true)
            }
            _ => {}
        }
    }
}

/// Schiller–Naumann correction f_d = 1 + 0.15 Re^0.687 (Jasion eq. 3.84), without the Newton cap.
#[inline]
pub fn schiller_naumann_fd(re: f64) -> f64 {
    1.0 + 0.15 * re.powf(0.687)
}

/// Dallavalle / Di Felice single-particle drag coefficient C_D = (0.63 + 4.8/√Re)².
#[inline]
pub fn di_felice_cd(re: f64) -> f64 {
    let s = 0.63 + 4.8 / re.sqrt();
    s * s
}

/// Di Felice exponent χ(Re) = 3.7 − 0.65 exp(−(1.5 − log₁₀ Re)²/2).
#[inline]
pub fn di_felice_chi(re: f64) -> f64 {
    let l = 1.5 - re.log10();
    3.7 - 0.65 * (-0.5 * l * l).exp()
}

/// Haider–Levenspiel drag coefficient for sphericity `phi`.
pub fn haider_levenspiel_cd(re: f64, phi: f64) -> f64 {
    let (a, b, c, d) = haider_levenspiel_coefficients(phi);
    24.0 / re * (1.0 + a * re.powf(b)) + c / (1.0 + d / re)
}

/// The coefficients A, B, C, D of Haider & Levenspiel (1989), eq. 11–14.
pub fn haider_levenspiel_coefficients(phi: f64) -> (f64, f64, f64, f64) {
    let p2 = phi * phi;
    let p3 = p2 * phi;
    let a = (2.3288 - 6.4581 * phi + 2.4486 * p2).exp();
    let b = 0.0964 + 0.5565 * phi;
    let c = (4.905 - 13.8944 * phi + 18.4222 * p2 - 10.2599 * p3).exp();
    let d = (1.4681 + 12.2584 * phi - 20.7322 * p2 + 15.8855 * p3).exp();
    (a, b, c, d)
}

impl DragLaw {
    /// Drag coefficient C_D at particle Reynolds number `re` (> 0).
    pub fn cd(&self, re: f64) -> f64 {
        24.0 / re * self.factor(re)
    }

    /// The correction f = C_D Re / 24 relative to Stokes drag at Reynolds number `re` ≥ 0; finite and
    /// continuous as Re → 0.
    #[inline]
    pub fn factor(&self, re: f64) -> f64 {
        match *self {
            DragLaw::Stokes => 1.0,
            DragLaw::SchillerNaumann => {
                if re < 1000.0 {
                    schiller_naumann_fd(re)
                } else {
                    0.44 * re / 24.0
                }
            }
            DragLaw::DiFelice { voidage } => {
                let eps = voidage.unwrap_or(1.0);
                let re_e = eps * re;
                // (0.63 + 4.8/√Re)² Re/24 written to stay finite at Re = 0.
                let s = 0.63 * re_e.sqrt() + 4.8;
                let f_single = s * s / 24.0;
                if eps == 1.0 {
                    f_single
                } else {
                    // F = ½ C_D(Re_ε) ρ A ε² w² ε^(−χ): relative to Stokes drag at the interstitial slip,
                    // f = C_D(Re_ε) Re_ε/24 · ε^(1−χ)  (one ε goes into Re_ε).
                    let chi = if re_e > 0.0 { di_felice_chi(re_e) } else { 3.7 };
                    f_single * eps.powf(1.0 - chi)
                }
            }
            DragLaw::HaiderLevenspiel { sphericity } => {
                let (a, b, c, d) = haider_levenspiel_coefficients(sphericity);
                1.0 + a * re.powf(b) + c * re * re / (24.0 * (re + d))
            }
        }
    }

    /// Drag relaxation time τ = τ_p / f(Re) \[s\] of a particle with slip speed `slip`, so that
    /// a_D = (u_f − v_p)/τ.
    #[inline]
    pub fn relaxation_time(&self, fluid: &Fluid, d: f64, rho_p: f64, slip: f64) -> f64 {
        stokes_time(fluid, d, rho_p) / self.factor(reynolds(fluid, d, slip))
    }

    /// Terminal settling speed \[m/s\] of a particle of diameter `d` and density `rho_p` under gravity
    /// `g` \[m/s²\] with buoyancy, solving (ρ_p − ρ_f) g V = ½ C_D ρ_f A v² for v by bisection on
    /// Re (monotone for every law here). Returns 0 for a neutrally buoyant particle.
    pub fn terminal_speed(&self, fluid: &Fluid, d: f64, rho_p: f64, g: f64) -> f64 {
        let tau = stokes_time(fluid, d, rho_p);
        let a = (1.0 - fluid.density / rho_p) * g;
        if a <= 0.0 {
            return 0.0;
        }
        // Balance: f(Re(v)) v = a τ.  g(v) = f v − a τ is increasing in v.
        let target = a * tau;
        let resid = |v: f64| self.factor(reynolds(fluid, d, v)) * v - target;
        let mut lo = 0.0;
        let mut hi = target.max(1e-30);
        while resid(hi) < 0.0 {
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if resid(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-15 * hi {
                break;
            }
        }
        0.5 * (lo + hi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn schiller_naumann_closed_form_values() {
        // Schiller & Naumann (1933), f = 1 + 0.15 Re^0.687 (Jasion 2013 eq. 3.84): f(1) = 1.15, f(100) = 4.5489, f(800) = 15.8086.
        assert!(rel(schiller_naumann_fd(1.0), 1.15) < 1e-12);
        assert!(rel(schiller_naumann_fd(100.0), 4.5489) < 5e-5);
        assert!(rel(schiller_naumann_fd(800.0), 15.8086) < 5e-5);
        assert!(rel(DragLaw::SchillerNaumann.cd(1e4), 0.44) < 1e-12);
    }

    #[test]
    fn di_felice_verification_values() {
        // Di Felice (1994), C_d = (0.63 + 4.8/√Re)²: C_d(Re=1) = 29.4849, C_d(1000) = 0.61119, χ(10^1.5) = 3.05 (5 significant
        // figures as quoted).
        let law = DragLaw::DiFelice { voidage: None };
        assert!(rel(law.cd(1.0), 29.4849) < 2e-6);
        assert!(rel(law.cd(1000.0), 0.61119) < 1e-5);
        assert!(rel(di_felice_chi(10f64.powf(1.5)), 3.05) < 1e-12);
        assert!(rel(di_felice_cd(1.0), 29.4849) < 2e-6);
    }

    #[test]
    fn di_felice_tables_of_cd_and_chi() {
        // Di Felice (1994), Int. J. Multiphase Flow 20:153–159: C_d = (0.63 + 4.8/√Re)² and
        // χ = 3.7 − 0.65 exp(−(1.5 − log₁₀ Re)²/2) over 1 ≤ Re ≤ 1e5. The paper gives the formulas; the
        // values (4 or 5 decimals) are the stone-chip verification set's, computed from them by hand:
        // tolerance half a unit of their last digit.
        let law = DragLaw::DiFelice { voidage: None };
        let half_digit = |decimals: i32| 0.5 * 10f64.powi(-decimals);
        for (re, cd, dec) in [
            (1.0, 29.4849, 4),
            (10.0, 4.61345, 5),
            (100.0, 1.2321, 4),
            (1e3, 0.61119, 5),
            (1e4, 0.45968, 5),
            (1e5, 0.41626, 5),
        ] {
            assert!((di_felice_cd(re) - cd).abs() < half_digit(dec), "C_d({re}) = {}", di_felice_cd(re));
            // The engine's law (written as the factor C_d Re/24 to stay finite at Re = 0) is the same.
            assert!((law.cd(re) - cd).abs() < half_digit(dec), "DragLaw C_d({re}) = {}", law.cd(re));
        }
        for (re, chi) in [
            (1.0, 3.48898),
            (10.0, 3.12638),
            (100.0, 3.12638),
            (1e3, 3.48898),
            (1e4, 3.67144),
            (1e5, 3.69858),
        ] {
            assert!((di_felice_chi(re) - chi).abs() < half_digit(5), "χ({re}) = {}", di_felice_chi(re));
        }
        // The minimum 3.05 at Re = 10^1.5, symmetric in log₁₀ Re about it.
        let min = 10f64.powf(1.5);
        assert!((di_felice_chi(min) - 3.05).abs() < 1e-12);
        for k in 1..100 {
            let x = 0.05 * k as f64;
            let (lo, hi) = (di_felice_chi(min / 10f64.powf(x)), di_felice_chi(min * 10f64.powf(x)));
            assert!(lo > 3.05 && hi > 3.05 && (lo - hi).abs() < 1e-12, "log Re ±{x}: {lo} {hi}");
        }
    }

    #[test]
    fn di_felice_voidage_factor_raises_drag() {
        // ε = 0.6 at Re = 10: factor relative to the single particle = ε^(1−χ(6)) · C_D(6)·6/(C_D(10)·10).
        let single = DragLaw::DiFelice { voidage: None };
        let dense = DragLaw::DiFelice { voidage: Some(0.6) };
        let re = 10.0;
        let chi = di_felice_chi(6.0);
        let expect = di_felice_cd(6.0) * 6.0 / 24.0 * 0.6f64.powf(1.0 - chi);
        assert!(rel(dense.factor(re), expect) < 1e-12);
        assert!(dense.factor(re) > 2.0 * single.factor(re), "dense suspensions drag much harder");
        // ε = 1 is exactly the single-particle law.
        assert_eq!(DragLaw::DiFelice { voidage: Some(1.0) }.factor(re), single.factor(re));
    }

    /// Clift & Gauvin (1970) standard drag curve for spheres (Clift, Grace & Weber, *Bubbles, Drops and
    /// Particles*, 1978, Table 5.2), used as an independent reference.
    fn clift_gauvin(re: f64) -> f64 {
        24.0 / re * (1.0 + 0.15 * re.powf(0.687)) + 0.42 / (1.0 + 42500.0 * re.powf(-1.16))
    }

    #[test]
    fn haider_levenspiel_reduces_to_the_sphere_curve() {
        // At φ = 1 Haider–Levenspiel eq. 10–14 is a fit of the standard sphere curve; their paper states
        // an rms deviation of a few percent. Tolerance 7 % against Clift–Gauvin over 0.1 ≤ Re ≤ 10⁵.
        for re in [0.1, 1.0, 10.0, 100.0, 1000.0, 1e4, 1e5] {
            let hl = DragLaw::HaiderLevenspiel { sphericity: 1.0 }.cd(re);
            assert!(rel(hl, clift_gauvin(re)) < 0.07, "Re {re}: HL {hl} vs {}", clift_gauvin(re));
        }
        // Less spherical particles drag more at every Re (Haider & Levenspiel 1989, Fig. 4).
        for re in [1.0, 100.0, 1e4] {
            let sphere = DragLaw::HaiderLevenspiel { sphericity: 1.0 }.cd(re);
            assert!(DragLaw::HaiderLevenspiel { sphericity: 0.6 }.cd(re) > 1.2 * sphere);
        }
        // The correction factor stays finite as Re → 0.
        assert!(DragLaw::HaiderLevenspiel { sphericity: 0.8 }.factor(0.0).is_finite());
    }

    #[test]
    fn terminal_speed_stokes_and_schiller_naumann() {
        let air = Fluid { density: 1.19, viscosity: 1.82e-5 };
        // Stokes: v = (ρ_p − ρ_f) g d²/(18μ). 10 µm sand.
        let d = 10e-6;
        let v = DragLaw::Stokes.terminal_speed(&air, d, 2480.0, 9.81);
        let expect = (2480.0 - 1.19) * 9.81 * d * d / (18.0 * 1.82e-5);
        assert!(rel(v, expect) < 1e-12);
        // Stokes settling of Jasion's (2013) sand: r_p = 5 µm → 7.43 mm/s (≈ v_ind/800 = 7.5 mm/s).
        assert!((v - 7.43e-3).abs() < 0.01e-3, "{v}");
        // Schiller–Naumann: the returned speed satisfies the force balance.
        let d = 300e-6;
        let v = DragLaw::SchillerNaumann.terminal_speed(&air, d, 2480.0, 9.81);
        let re = reynolds(&air, d, v);
        let cd = DragLaw::SchillerNaumann.cd(re);
        let weight = (2480.0 - 1.19) * 9.81 * std::f64::consts::PI / 6.0 * d.powi(3);
        let drag = 0.5 * cd * 1.19 * std::f64::consts::PI / 4.0 * d * d * v * v;
        assert!(rel(drag, weight) < 1e-10);
        assert!(re > 1.0 && re < 800.0, "inside the Schiller–Naumann range: {re}");
    }
}
