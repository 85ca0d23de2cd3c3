//! The integrator study of Jasion (2013), *Toward a Physics Based Entrainment Model for Simulation of
//! Helicopter Brownout*, PhD thesis, University of Southampton, Appendix A (tangential contact) and
//! Appendix B (normal spring–dashpot after Tuley et al. 2010): single contacts with analytic solutions,
//! the impact placed exactly N_FM of a step after a step boundary, error against the analytic solution at a
//! comparison time that is a whole number of steps, and the observed order from a log–log fit over step
//! counts from 10 to 10⁴.
//!
//! Choices the thesis leaves open (it gives no numbers for m, k, μ, δ_y, u₀):
//! * normal cases: k = m = u₀ = 1 (Appendix B), e = 1 (elastic) or 0.5 (damped), tension allowed at the
//!   end of contact as in the analytic solution; compared at 0.8 of the contact duration π/ω_d after
//!   impact (inside the contact, after the largest overlap), error |x − x_an| / δ̂ (Eq. B.5);
//! * tangential cases: m = k_x = u₀ = 1, a solid sphere (r* = 1 + r_p²/R_g² = 3.5), Coulomb force
//!   F_f = μ k_y δ_y chosen so that the elastic phase ends at sin(ω_s t_trans) = ½ (Eq. A.15);
//!   compared at 0.8 t_trans (elastic, Eq. A.23), 2 t_trans (elastic→frictional, A.25) and, for pure
//!   sliding, at 0.8 of the time the contact-point slip stops (the thesis's "stop time" of A.24 would
//!   include a rolling phase its quadratic solution does not describe); error |x − x_an| / x_an (A.26);
//! * smooth control: x″ = −x from x = 0, v = 1 (a motion that starts with zero acceleration, as after an
//!   impact), compared at t = 2.
//!
//! Placement: the particle starts u₀(1 + N_FM)Δt before contact, so contact begins N_FM of a step after
//! t = Δt; Δt = τ_c / (N − 1 − N_FM) makes the comparison time t_i + τ_c exactly step N.

use crate::integrators::{Scheme, Stepper, System};
use serde::{Deserialize, Serialize};
use spatter_core::validation::Check;

/// A test problem of the study.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StudyCase {
    /// Harmonic oscillator without discontinuity (the control test).
    Smooth,
    /// Linear spring, no damping (Tuley "normal elastic").
    NormalElastic,
    /// Linear spring–dashpot with e = 0.5 (Tuley "normal damped").
    NormalDamped,
    /// Tangential elastic contact (Jasion Eq. A.11).
    TangentialElastic,
    /// Tangential Coulomb sliding from impact (Eq. A.13).
    TangentialFrictional,
    /// Tangential elastic, then sliding (Eq. A.16).
    TangentialElasticFrictional,
}

impl StudyCase {
    pub const ALL: [StudyCase; 6] = [
        StudyCase::Smooth,
        StudyCase::NormalElastic,
        StudyCase::NormalDamped,
        StudyCase::TangentialElastic,
        StudyCase::TangentialFrictional,
        StudyCase::TangentialElasticFrictional,
    ];

    pub fn name(self) -> &'static str {
        match self {
            StudyCase::Smooth => "smooth",
            StudyCase::NormalElastic => "normal_elastic",
            StudyCase::NormalDamped => "normal_damped",
            StudyCase::TangentialElastic => "tangential_elastic",
            StudyCase::TangentialFrictional => "tangential_frictional",
            StudyCase::TangentialElasticFrictional => "tangential_elastic_frictional",
        }
    }
}

/// Non-dimensional radius r* = 1 + r_p²/R_g² of a solid sphere (R_g² = 2/5 r_p²), Jasion Eq. A.2.
const R_STAR: f64 = 3.5;
/// sin(ω_s t_trans) of the tangential cases.
const SIN_TRANS: f64 = 0.5;

/// Damping ratio ξ = −ln e / √(π² + ln² e) of a linear spring–dashpot with restitution e.
pub use spatter_core::material::restitution_damping_ratio as damping_ratio;

/// Largest overlap of a linear spring–dashpot impact, Jasion Eq. B.6 (after Tuley et al. 2010):
/// δ̂ = A u₀ / (ω_d √(1 + A²)) · exp(−arctan(A)/A), A = ω_d/(ξ ω_n) \[m\].
pub fn max_overlap(k: f64, m: f64, u0: f64, e: f64) -> f64 {
    let xi = damping_ratio(e);
    let wn = (k / m).sqrt();
    let wd = wn * (1.0 - xi * xi).sqrt();
    if xi == 0.0 {
        return u0 / wn;
    }
    let a = wd / (xi * wn);
    a * u0 / (wd * (1.0 + a * a).sqrt()) * (-(a.atan()) / a).exp()
}

struct Problem {
    case: StudyCase,
    /// Dashpot coefficient c (normal), Coulomb force F_f (tangential).
    c: f64,
    f_lim: f64,
    /// Contact is detected at a step start with x > −ε (ε = 10⁻⁹ Δt: a contact that begins on a step
    /// boundary, N_FM = 0, is detected there despite the round-off of the free-flight steps).
    eps: f64,
    /// Contact detected (at the start of a step; every stage of that step and later ones sees it).
    detected: bool,
    /// s at detection: the tangential spring is Δs since then (history starts at detection).
    s_ref: f64,
}

impl Problem {
    fn new(case: StudyCase) -> Self {
        let xi = if case == StudyCase::NormalDamped { damping_ratio(0.5) } else { 0.0 };
        let ws = R_STAR.sqrt();
        Problem { case, c: 2.0 * xi, f_lim: SIN_TRANS / ws, eps: 0.0, detected: false, s_ref: 0.0 }
    }

    /// Contact detection at the start of a step, as a DEM code does it (Jasion 2013, Appendix A: "contact
    /// is detected when the particle overlaps the plane at the start of a step"): forces act from the
    /// first step that starts in overlap, so an impact N_FM of a step before that start goes unfelt for
    /// (1 − N_FM) Δt, and the tangential spring starts at zero there.
    fn detect(&mut self, y: &[f64; 4]) {
        if !self.detected && y[0] > -self.eps {
            self.detected = true;
            self.s_ref = y[0] + y[1];
        }
    }

    fn omega_s(&self) -> f64 {
        R_STAR.sqrt()
    }

    fn t_trans(&self) -> f64 {
        SIN_TRANS.asin() / self.omega_s()
    }

    fn omega_d(&self) -> f64 {
        let xi = self.c / 2.0;
        (1.0 - xi * xi).sqrt()
    }

    /// Time from impact (or start) to the comparison.
    fn tau_c(&self) -> f64 {
        match self.case {
            StudyCase::Smooth => 2.0,
            StudyCase::NormalElastic | StudyCase::NormalDamped => 0.8 * std::f64::consts::PI / self.omega_d(),
            StudyCase::TangentialElastic => 0.8 * self.t_trans(),
            StudyCase::TangentialElasticFrictional => 2.0 * self.t_trans(),
            StudyCase::TangentialFrictional => 0.8 / (R_STAR * self.f_lim),
        }
    }

    /// Analytic x at time τ after impact (x = 0 at impact).
    fn exact(&self, tau: f64) -> f64 {
        let ws = self.omega_s();
        let el = |t: f64| (ws * t).sin() / (R_STAR * ws) + (1.0 - 1.0 / R_STAR) * t;
        match self.case {
            StudyCase::Smooth => tau.sin(),
            StudyCase::NormalElastic | StudyCase::NormalDamped => {
                let xi = self.c / 2.0;
                let wd = self.omega_d();
                (-xi * tau).exp() * (wd * tau).sin() / wd
            }
            StudyCase::TangentialElastic => el(tau),
            StudyCase::TangentialFrictional => tau - self.f_lim * tau * tau / 2.0,
            StudyCase::TangentialElasticFrictional => {
                let t1 = self.t_trans();
                if tau <= t1 {
                    return el(tau);
                }
                let ux1 = (ws * t1).cos() / R_STAR + 1.0 - 1.0 / R_STAR;
                let d = tau - t1;
                el(t1) + ux1 * d - self.f_lim * d * d / 2.0
            }
        }
    }

    /// Error normalisation: δ̂ for the normal cases (B.5), |x_an| otherwise (A.26).
    fn scale(&self, exact: f64) -> f64 {
        match self.case {
            StudyCase::NormalElastic => max_overlap(1.0, 1.0, 1.0, 1.0),
            StudyCase::NormalDamped => max_overlap(1.0, 1.0, 1.0, 0.5),
            _ => exact.abs(),
        }
    }
}

/// State (x, r_p θ, ẋ, r_p θ̇); contact while x > 0.
impl System<4> for Problem {
    fn derivative(&mut self, _t: f64, y: &[f64; 4]) -> [f64; 4] {
        let (x, v) = (y[0], y[2]);
        let mut a = [0.0; 2];
        match self.case {
            StudyCase::Smooth => a[0] = -x,
            StudyCase::NormalElastic | StudyCase::NormalDamped if self.detected && x > -self.eps => {
                a[0] = -x - self.c * v;
            }
            StudyCase::NormalElastic | StudyCase::NormalDamped => {}
            _ if self.detected => {
                let s = y[0] + y[1] - self.s_ref;
                let us = y[2] + y[3];
                let f = match self.case {
                    StudyCase::TangentialElastic => s,
                    StudyCase::TangentialFrictional => self.f_lim * us.signum(),
                    _ => s.signum() * s.abs().min(self.f_lim),
                };
                // m ẍ = −F, r_p θ̈ = −(r_p²/R_g²) F/m = −2.5 F/m.
                a = [-f, -(R_STAR - 1.0) * f];
            }
            _ => {}
        }
        [y[2], y[3], a[0], a[1]]
    }
}

/// Fixed-point iterations of the implicit schemes in the study (enough for BD4 to keep its order).
pub const STUDY_ITERATIONS: u32 = 5;

/// Error of `scheme` on `case` with `steps` steps to the comparison time and the impact at fraction
/// `n_fm` of a step. Returns (error, Δt).
pub fn study_error(case: StudyCase, scheme: Scheme, n_fm: f64, steps: u32, iterations: u32) -> (f64, f64) {
    let mut p = Problem::new(case);
    let tau = p.tau_c();
    let (dt, mut y) = if case == StudyCase::Smooth {
        (tau / steps as f64, [0.0, 0.0, 1.0, 0.0])
    } else {
        let dt = tau / (steps as f64 - 1.0 - n_fm);
        (dt, [-(1.0 + n_fm) * dt, 0.0, 1.0, 0.0])
    };
    p.eps = 1e-9 * dt;
    let mut st = Stepper::<4>::new(scheme, iterations.max(1)).expect("iterations ≥ 1");
    for k in 0..steps {
        p.detect(&y);
        st.step(&mut p, k as f64 * dt, &mut y, dt);
    }
    let exact = p.exact(tau);
    ((y[0] - exact).abs() / p.scale(exact), dt)
}

/// Step counts of a sweep: four per decade from 10 up to `max_steps` (10⁴ in the thesis).
pub fn sweep_steps(max_steps: u32) -> Vec<u32> {
    let decades = (max_steps.max(10) as f64 / 10.0).log10();
    let n = (decades * 4.0 + 1e-9).floor() as i32;
    (0..=n).map(|i| (10f64 * 10f64.powf(i as f64 / 4.0)).round() as u32).collect()
}

/// Step count of the quick (`quick = true`) and full sweeps.
fn max_steps(quick: bool) -> u32 {
    if quick {
        1000
    } else {
        10_000
    }
}

/// Errors below this are round-off and left out of the order fit.
pub const ERROR_FLOOR: f64 = 1e-13;

/// The fit starts at this many steps (coarser runs are not yet in the asymptotic range of the
/// fourth-order schemes).
pub const FIT_MIN_STEPS: f64 = 100.0;

/// Least-squares slope of log(error) against log(Δt) over the runs of at least [`FIT_MIN_STEPS`] steps
/// whose error is above [`ERROR_FLOOR`] (the observed order); when fewer than three such runs remain
/// (a scheme that reaches round-off early), over every run above the floor; `None` when even those are
/// fewer than three (the scheme is exact to round-off on the problem). `points` are (Δt, error) with
/// Δt ≈ τ_c/N.
pub fn fit_order(points: &[(f64, f64)], tau: f64) -> Option<f64> {
    let select = |min_steps: f64| -> Vec<(f64, f64)> {
        points
            .iter()
            .filter(|(dt, e)| *e > ERROR_FLOOR && tau / dt >= min_steps - 2.0)
            .map(|(dt, e)| (dt.ln(), e.ln()))
            .collect()
    };
    let mut pts = select(FIT_MIN_STEPS);
    if pts.len() < 3 {
        pts = select(0.0);
    }
    if pts.len() < 3 {
        return None;
    }
    let n = pts.len() as f64;
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + p.1));
    let (mx, my) = (sx / n, sy / n);
    let (sxy, sxx) =
        pts.iter().fold((0.0, 0.0), |a, p| (a.0 + (p.0 - mx) * (p.1 - my), a.1 + (p.0 - mx).powi(2)));
    Some(sxy / sxx)
}

/// One row of the study: a scheme on a case at one impact placement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StudyRow {
    pub case: StudyCase,
    pub scheme: Scheme,
    pub n_fm: f64,
    /// (Δt, error) per step count.
    pub points: Vec<(f64, f64)>,
    pub observed_order: Option<f64>,
}

/// One row: `scheme` on `case` at `n_fm` over the step counts `steps`, implicit schemes with
/// `iterations` fixed-point iterations.
pub fn study_row(case: StudyCase, scheme: Scheme, n_fm: f64, steps: &[u32], iterations: u32) -> StudyRow {
    let points: Vec<(f64, f64)> = steps
        .iter()
        .map(|&n| study_error(case, scheme, n_fm, n, iterations))
        .map(|(e, dt)| (dt, e))
        .collect();
    let observed_order = fit_order(&points, Problem::new(case).tau_c());
    StudyRow { case, scheme, n_fm, points, observed_order }
}

/// The placements a case is run at: the smooth control has no impact (N_FM = 0 only).
pub fn placements(case: StudyCase, n_fms: &[f64]) -> Vec<f64> {
    if case == StudyCase::Smooth {
        vec![0.0]
    } else {
        n_fms.to_vec()
    }
}

/// The full sweep: every case × scheme × N_FM ∈ `n_fms`, 10 to 10⁴ steps (`quick`: 10³).
pub fn run_study(cases: &[StudyCase], schemes: &[Scheme], n_fms: &[f64], quick: bool) -> Vec<StudyRow> {
    let steps = sweep_steps(max_steps(quick));
    let mut rows = Vec::new();
    for &case in cases {
        for n_fm in placements(case, n_fms) {
            for &scheme in schemes {
                rows.push(study_row(case, scheme, n_fm, &steps, STUDY_ITERATIONS));
            }
        }
    }
    rows
}

/// The thesis's observed order for a case and placement, as it reports it (Jasion 2013, Appendix A
/// test 2 and Appendix B; `None` where it reports none).
pub fn thesis_order(case: StudyCase, scheme: Scheme, n_fm: f64) -> Option<&'static str> {
    use Scheme::*;
    use StudyCase::*;
    let at_zero = n_fm == 0.0;
    Some(match (case, at_zero) {
        (Smooth, _) => match scheme {
            Fe | Bd1 => "1",
            Se | Rk2 | Ab2 | Bd2 => "2",
            _ => "4",
        },
        (TangentialFrictional, true) => match scheme {
            Rk2 | Rk4 => "2",
            _ => "1",
        },
        (TangentialElastic | TangentialElasticFrictional, true) => match scheme {
            Se | Rk2 | Ab2 | Ab4 | Abm4 => "2",
            Fe | Bd1 | Bd2 | Rk4 | Bd4 => "1",
        },
        (TangentialFrictional | TangentialElastic | TangentialElasticFrictional, false) => "1",
        (NormalElastic, true) => match scheme {
            Rk2 => "3",
            Rk4 => "4",
            _ => "≥2",
        },
        (NormalElastic, false) => match scheme {
            Se => "2",
            _ => "≥2",
        },
        (NormalDamped, true) => match scheme {
            Rk2 => "2",
            _ => "1",
        },
        (NormalDamped, false) => "≤1",
    })
}

/// `spatter validate` case: every scheme reaches its nominal order on the smooth oscillator (±0.15; the
/// control test of Jasion 2013, Appendix A: "every scheme achieves its nominal order", SE second).
pub fn smooth_orders(quick: bool) -> Vec<Check> {
    run_study(&[StudyCase::Smooth], &Scheme::ALL, &[0.0], quick)
        .into_iter()
        .map(|r| {
            Check::absolute(
                format!("integrator_smooth_{}", r.scheme.label()),
                "observed order",
                r.scheme.nominal_order() as f64,
                r.observed_order.unwrap_or(f64::NAN),
                0.15,
                "Jasion (2013) Appendix A control test; textbook orders",
            )
        })
        .collect()
}

/// `spatter validate` case: the normal spring–dashpot impact of Jasion (2013) Appendix B with
/// k = m = u₀ = 1, e = 0.5: δ̂ of Eq. B.6 = 0.74181 (5 digits as printed), the same maximum from a fine
/// RK4 run (1e-6), and the rebound velocity giving e = 0.5 (1e-6).
pub fn normal_impact(_quick: bool) -> Vec<Check> {
    let src = "Jasion (2013) Eq. B.6 (after Tuley et al. 2010)";
    let d_hat = max_overlap(1.0, 1.0, 1.0, 0.5);
    let mut p = Problem::new(StudyCase::NormalDamped);
    // Start at the impact, in contact, and end exactly at the end of contact t = π/ω_d (both on step
    // boundaries, where RK4 keeps its fourth order).
    let steps = 10_000;
    let dt = std::f64::consts::PI / p.omega_d() / steps as f64;
    p.eps = 1e-9 * dt;
    let mut y = [0.0, 0.0, 1.0, 0.0];
    p.detect(&y);
    let mut st = Stepper::<4>::new(Scheme::Rk4, 0).expect("explicit");
    let mut best = 0.0f64;
    for k in 0..steps {
        st.step(&mut p, k as f64 * dt, &mut y, dt);
        best = best.max(y[0]);
    }
    vec![
        Check::absolute("integrator_normal_impact", "δ̂ (B.6) [-]", 0.74181, d_hat, 5e-6, src),
        Check::relative("integrator_normal_impact", "δ̂ fine RK4 run [-]", d_hat, best, 1e-6, src),
        Check::relative("integrator_normal_impact", "rebound e [-]", 0.5, -y[2], 1e-6, src),
    ]
}

/// `spatter validate` case, the thesis's discontinuity findings that this study reproduces (Jasion 2013,
/// Appendix A test 2 and Appendix B; ±0.2 in the order): in the tangential elastic case SE stays second
/// order with the impact on a step boundary (N_FM = 0) and every scheme falls to first order at
/// N_FM = 0.5; in the damped normal case at N_FM = 0 SE is first order and RK2 second.
pub fn discontinuity_orders(quick: bool) -> Vec<Check> {
    let src = "Jasion (2013) Appendix A test 2, Appendix B";
    let mut out = Vec::new();
    let mut push = |rows: Vec<StudyRow>, order: f64| {
        for r in rows {
            out.push(Check::absolute(
                format!("integrator_{}_{}_nfm{}", r.case.name(), r.scheme.label(), r.n_fm),
                "observed order",
                order,
                r.observed_order.unwrap_or(f64::NAN),
                0.2,
                src,
            ));
        }
    };
    push(run_study(&[StudyCase::TangentialElastic], &[Scheme::Se], &[0.0], quick), 2.0);
    push(run_study(&[StudyCase::TangentialElastic], &Scheme::ALL, &[0.5], quick), 1.0);
    push(run_study(&[StudyCase::NormalDamped], &[Scheme::Se], &[0.0], quick), 1.0);
    push(run_study(&[StudyCase::NormalDamped], &[Scheme::Rk2], &[0.0], quick), 2.0);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn max_overlap_matches_the_printed_value_and_rebound() {
        for c in normal_impact(true) {
            assert!(c.passed(), "{c:?}");
        }
    }

    #[test]
    fn every_scheme_reaches_its_nominal_order_on_a_smooth_oscillator() {
        for c in smooth_orders(false) {
            assert!(c.passed(), "{c:?}");
        }
    }

    #[test]
    fn discontinuities_reproduce_the_thesis_findings() {
        for c in discontinuity_orders(true) {
            assert!(c.passed(), "{c:?}");
        }
    }

    #[test]
    fn implicit_scheme_without_iterations_is_refused() {
        let e = Stepper::<4>::new(Scheme::Bd2, 0).unwrap_err();
        assert!(e.contains("BD2") && e.contains("iteration"), "{e}");
    }
}
