//! Full JKR (Johnson–Kendall–Roberts 1971) adhesive elastic contact with necking hysteresis.
//!
//! # Mechanics
//!
//! For an elastic contact of effective modulus E* \[Pa\], effective radius R* \[m\] and work of adhesion
//! Γ \[J/m²\] (Γ = 2γ for two surfaces of energy γ; the snow thesis uses Γ directly):
//!
//! * zero-load contact radius a₀ = (9πΓR*²/(2E*))^{1/3} (thesis Eq. 17),
//! * pull-off force F_c = (3/2)πΓR* (thesis Eq. 18),
//! * critical overlap δ_c = a₀²/(2·6^{1/3}R*) (the minimum of δ(a); thesis Eq. 19 read as an overlap; its
//!   printed form is garbled),
//! * overlap and force along the JKR curve: δ(a) = a²/R* − √(2πΓa/E*), F(a) = 4E*a³/(3R*) − √(8πΓE*a³),
//!   positive F repulsive.
//!
//! In the normalised variables of Marshall (2009, J. Comput. Phys. 228:1541) with x = a/a₀:
//! δ/δ_c = 6^{1/3}(2x² − (4/3)x^{1/2}) and F/F_c = 4x³ − 4x^{3/2}. Given δ, the contact radius is the
//! largest root of the quartic 2y⁴ − (4/3)y − (δ/δ_c)/6^{1/3} = 0 with y = √x, solved here by Newton's
//! method (closed-form roots lose precision near the break point).
//!
//! # Hysteresis
//!
//! A contact forms when the surfaces touch (δ ≥ 0); the force then jumps to F(0) = −(8/9)F_c. While formed,
//! the JKR force acts for δ down to the break overlap — −δ_c under displacement control (default, thesis
//! and Thornton & Ning 1998), or −0.48075 δ_c where F = −F_c under load control (LAMMPS `granular jkr`).
//! Below it the contact breaks and the surface energy of the neck is lost. The energy stored in the
//! formed contact, U(δ) = ∫₀^δ F dδ′ (zero at formation), is available in closed form; the neck work
//! W_neck = U(−δ_c) = 0.935503 F_c δ_c gives the undamped sticking velocity 1.367847 √(F_c δ_c/m*).

use serde::{Deserialize, Serialize};

/// 6^{1/3}.
pub const CBRT_6: f64 = 1.817_120_592_832_139_6;

/// δ/δ_c at the load-controlled pull-off point x = 4^{-1/3}, where F = −F_c: −0.480749856769136.
pub const LOAD_CONTROLLED_BREAK_RATIO: f64 = -0.480_749_856_769_136_2;

/// Normalised contact radius x = a/a₀ at first touch (δ = 0): (2/3)^{2/3}.
pub fn touch_radius_ratio() -> f64 {
    TOUCH_RATIO
}

/// W_neck/(F_c δ_c) under displacement control: U at x = 6^{-2/3}.
const NECK_WORK_CRITICAL: f64 = 0.935_502_783_271_927_7;

/// W_neck/(F_c δ_c) under load control: U at x = 4^{-1/3}.
const NECK_WORK_PULL_OFF: f64 = 0.462_014_008_967_729_9;

/// (2/3)^{2/3}.
const TOUCH_RATIO: f64 = 0.763_142_828_368_887_9;

/// [`normalised_energy`] at the touch radius (2/3)^{2/3}: −0.8466138943830397.
const TOUCH_ENERGY: f64 = -0.846_613_894_383_039_7;

/// Where a formed JKR contact breaks.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BreakCriterion {
    /// Displacement control: the neck breaks at δ = −δ_c, where the JKR curve ends (default; snow thesis
    /// Eq. 19, Thornton & Ning 1998, LIGGGHTS JKR implementations).
    #[default]
    CriticalOverlap,
    /// Load control: the neck breaks where the attraction peaks, F = −F_c at δ = −0.48075 δ_c (LAMMPS
    /// `pair granular jkr`). Dissipates less than [`BreakCriterion::CriticalOverlap`].
    PullOffForce,
}

impl BreakCriterion {
    /// Break overlap as a multiple of δ_c (negative).
    pub fn ratio(self) -> f64 {
        match self {
            BreakCriterion::CriticalOverlap => -1.0,
            BreakCriterion::PullOffForce => LOAD_CONTROLLED_BREAK_RATIO,
        }
    }
}

/// Newton iteration limit of [`normalised_root`]. Away from the break point convergence takes 2–5
/// iterations; at δ = −δ_c the root is double and convergence is linear.
const MAX_NEWTON: usize = 80;

/// Largest real root y of 2y⁴ − (4/3)y − s = 0 for s = (δ/δ_c)/6^{1/3} ≥ −6^{-1/3}, by Newton's method.
///
/// `start` is an optional previous root (warm start). Returns `None` for s below the minimum −6^{-1/3}
/// (no contact possible: δ < −δ_c). The returned y satisfies y ≥ 6^{-1/3} (stable branch).
pub fn normalised_root(s: f64, start: Option<f64>) -> Option<f64> {
    const Y_MIN: f64 = 0.550_321_208_149_104_3; // 6^{-1/3}: minimum of the quartic
    const S_MIN: f64 = -Y_MIN; // f(Y_MIN) = −6^{-1/3}
    if s.is_nan() || s < S_MIN {
        // Allow a rounding-level excursion below the minimum: return the double root.
        return if s >= S_MIN - 1e-12 { Some(Y_MIN) } else { None };
    }
    let f = |y: f64| 2.0 * y * y * y * y - (4.0 / 3.0) * y - s;
    let df = |y: f64| 8.0 * y * y * y - 4.0 / 3.0;
    // Upper bound of the root: for y ≥ 1, y⁴ = s/2 + (2/3)y ≤ s/2 + (2/3)y⁴ ⇒ y ≤ (1.5 s)^{1/4}; for
    // s ≤ 2/3 the root is ≤ 1 because f(1) = 2/3 − s ≥ 0 and f increases beyond Y_MIN.
    let upper = if s > 2.0 / 3.0 { (1.5 * s).sqrt().sqrt() } else { 1.0 };
    // Newton on the convex, increasing branch converges monotonically from above. A warm start below the
    // root is first moved above it by one Newton step (convexity), if the slope there is safe.
    let mut y = match start {
        Some(y0) if y0.is_finite() && y0 > Y_MIN => {
            let f0 = f(y0);
            if f0 >= 0.0 {
                y0.min(upper)
            } else {
                let d0 = df(y0);
                if d0 > 0.5 {
                    (y0 - f0 / d0).min(upper)
                } else {
                    upper
                }
            }
        }
        _ => upper,
    };
    for _ in 0..MAX_NEWTON {
        let d = df(y);
        if d <= 0.0 {
            return Some(Y_MIN);
        }
        let step = f(y) / d;
        let next = (y - step).max(Y_MIN);
        if (y - next).abs() <= 4.0 * f64::EPSILON * y {
            return Some(next);
        }
        y = next;
    }
    Some(y)
}

/// JKR contact of one pair: E*, R*, Γ and the derived scales a₀, F_c, δ_c.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Jkr {
    /// Effective Young's modulus E* \[Pa\].
    pub e_star: f64,
    /// Effective radius R* \[m\].
    pub r_star: f64,
    /// Work of adhesion Γ \[J/m²\].
    pub work_of_adhesion: f64,
    /// Zero-load contact radius a₀ \[m\].
    pub a0: f64,
    /// Pull-off force F_c \[N\].
    pub pull_off_force: f64,
    /// Critical overlap δ_c > 0 \[m\]; the neck breaks at −δ_c under displacement control.
    pub critical_overlap: f64,
}

impl Jkr {
    /// Derived JKR scales for E* \[Pa\], R* \[m\], Γ \[J/m²\] (all > 0).
    pub fn new(e_star: f64, r_star: f64, work_of_adhesion: f64) -> Self {
        let a0 = (9.0 * std::f64::consts::PI * work_of_adhesion * r_star * r_star / (2.0 * e_star)).cbrt();
        Self::with_a0(e_star, r_star, work_of_adhesion, a0)
    }

    /// [`Jkr::new`] with the zero-load contact radius a₀ \[m\] already known (from an earlier `new` of the
    /// same E*, R*, Γ): no cube root, the same numbers bit for bit.
    #[inline]
    pub fn with_a0(e_star: f64, r_star: f64, work_of_adhesion: f64, a0: f64) -> Self {
        Jkr {
            e_star,
            r_star,
            work_of_adhesion,
            a0,
            pull_off_force: 1.5 * std::f64::consts::PI * work_of_adhesion * r_star,
            critical_overlap: a0 * a0 / (2.0 * CBRT_6 * r_star),
        }
    }

    /// Overlap δ(a) \[m\] on the JKR curve for contact radius `a` \[m\]: a²/R* − √(2πΓa/E*).
    pub fn overlap_of_radius(&self, a: f64) -> f64 {
        a * a / self.r_star - (2.0 * std::f64::consts::PI * self.work_of_adhesion * a / self.e_star).sqrt()
    }

    /// Elastic normal force F(a) \[N\] (positive repulsive) for contact radius `a` \[m\]:
    /// 4E*a³/(3R*) − √(8πΓE*a³).
    pub fn force_of_radius(&self, a: f64) -> f64 {
        let a3 = a * a * a;
        4.0 * self.e_star * a3 / (3.0 * self.r_star)
            - (8.0 * std::f64::consts::PI * self.work_of_adhesion * self.e_star * a3).sqrt()
    }

    /// Overlap at which F = 0 (x = 1): δ₀ = a₀²/(3R*) \[m\].
    pub fn zero_force_overlap(&self) -> f64 {
        self.a0 * self.a0 / (3.0 * self.r_star)
    }

    /// Overlap \[m\] at which a formed contact breaks under `criterion` (negative).
    pub fn break_overlap(&self, criterion: BreakCriterion) -> f64 {
        criterion.ratio() * self.critical_overlap
    }

    /// Normalised root y = √(a/a₀) for overlap `delta` \[m\] (see [`normalised_root`]); `None` below −δ_c.
    pub fn root(&self, delta: f64, start: Option<f64>) -> Option<f64> {
        normalised_root(delta / (self.critical_overlap * CBRT_6), start)
    }

    /// Contact radius a \[m\] of a formed contact at overlap `delta` \[m\]; `None` below −δ_c.
    pub fn contact_radius(&self, delta: f64) -> Option<f64> {
        self.root(delta, None).map(|y| self.a0 * y * y)
    }

    /// Elastic force \[N\] of a formed contact at overlap `delta` \[m\]; `None` below −δ_c.
    pub fn force(&self, delta: f64) -> Option<f64> {
        self.root(delta, None).map(|y| self.force_of_root(y))
    }

    /// Force \[N\] for normalised root y: F_c(4y⁶ − 4y³).
    #[inline]
    pub fn force_of_root(&self, y: f64) -> f64 {
        let y3 = y * y * y;
        4.0 * self.pull_off_force * y3 * (y3 - 1.0)
    }

    /// Energy \[J\] stored in a formed contact, U = ∫₀^δ F dδ′ (zero when the contact forms at δ = 0),
    /// for normalised root y. In x = y²: U = F_cδ_c 6^{1/3}[(16/5)x⁵ − (16/3)x^{7/2} + (4/3)x²] − U(x_touch).
    pub fn energy_of_root(&self, y: f64) -> f64 {
        self.pull_off_force * self.critical_overlap * (normalised_energy(y * y) - TOUCH_ENERGY)
    }

    /// Energy \[J\] stored in a formed contact at overlap `delta` (see [`Jkr::energy_of_root`]).
    pub fn energy(&self, delta: f64) -> Option<f64> {
        self.root(delta, None).map(|y| self.energy_of_root(y))
    }

    /// Work \[J\] needed to pull a formed contact from δ = 0 to its break point: U(δ_break) =
    /// 0.935503 F_c δ_c under displacement control, 0.462014 F_c δ_c under load control (closed form of
    /// [`Jkr::energy_of_root`] at the break radius; checked against it in the tests).
    pub fn neck_work(&self, criterion: BreakCriterion) -> f64 {
        let k = match criterion {
            BreakCriterion::CriticalOverlap => NECK_WORK_CRITICAL,
            BreakCriterion::PullOffForce => NECK_WORK_PULL_OFF,
        };
        k * self.pull_off_force * self.critical_overlap
    }

    /// Largest impact speed \[m/s\] at which an undamped, purely elastic JKR impact of effective mass
    /// `m_eff` \[kg\] sticks: √(2 W_neck/m*) (1.367847 √(F_cδ_c/m*) under displacement control).
    pub fn elastic_sticking_speed(&self, m_eff: f64, criterion: BreakCriterion) -> f64 {
        (2.0 * self.neck_work(criterion) / m_eff).sqrt()
    }
}

/// 6^{1/3}[(16/5)x⁵ − (16/3)x^{7/2} + (4/3)x²]: ∫ (F/F_c) d(δ/δ_c) along the JKR curve.
fn normalised_energy(x: f64) -> f64 {
    CBRT_6 * (3.2 * x.powi(5) - (16.0 / 3.0) * x.powi(3) * x.sqrt() + (4.0 / 3.0) * x * x)
}

/// Per-contact hysteresis state of a JKR contact.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JkrState {
    /// True once the surfaces have touched and until the neck breaks.
    pub formed: bool,
    /// Last normalised root y = √(a/a₀), the Newton start value of the next step (0 = none).
    pub y: f64,
}

/// One evaluation of a JKR contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JkrEval {
    /// Elastic force \[N\], positive repulsive.
    pub force: f64,
    /// Contact radius a \[m\].
    pub contact_radius: f64,
    /// Stored energy U(δ) \[J\] (zero at formation).
    pub energy: f64,
}

impl Jkr {
    /// Advances the hysteresis state to overlap `delta` \[m\] and returns the force, or `None` when there is
    /// no contact (not yet formed and δ < 0, or broken below the break overlap; `state` is then reset).
    pub fn evaluate(&self, delta: f64, criterion: BreakCriterion, state: &mut JkrState) -> Option<JkrEval> {
        if !state.formed {
            if delta < 0.0 {
                return None;
            }
            state.formed = true;
            state.y = 0.0;
        } else if delta < self.break_overlap(criterion) {
            *state = JkrState::default();
            return None;
        }
        let start = if state.y > 0.0 { Some(state.y) } else { None };
        let Some(y) = self.root(delta, start) else {
            *state = JkrState::default();
            return None;
        };
        state.y = y;
        Some(JkrEval {
            force: self.force_of_root(y),
            contact_radius: self.a0 * y * y,
            energy: self.energy_of_root(y),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rel(a: f64, b: f64) -> f64 {
        ((a - b) / b).abs()
    }

    /// Ice on ABS (Lind 2017 Table 2): E* = 1.88329e9 Pa.
    fn ice_abs(d: f64) -> Jkr {
        let ice = spatter_core::material::Material::new(9.8e9, 0.31, 920.0).unwrap();
        let abs = spatter_core::material::Material::new(2.0e9, 0.35, 1100.0).unwrap();
        Jkr::new(spatter_core::material::effective_modulus(&ice, &abs), d / 2.0, 0.2)
    }

    #[test]
    fn scales_match_snow_table() {
        // Ice on a flat ABS wall, Γ = 0.2 (inputs of Lind 2017 Table 2): a₀, F_c, δ_c, δ₀, F(0) per diameter.
        // The table prints 5 significant digits: tolerance 1e-4 relative.
        let rows = [
            (10e-6, 3.3481e-07, 4.7124e-06, 6.1692e-09, 7.4734e-09, -4.1888e-06),
            (20e-6, 5.3149e-07, 9.4248e-06, 7.7727e-09, 9.4159e-09, -8.3776e-06),
            (50e-6, 9.7900e-07, 2.3562e-05, 1.0549e-08, 1.2779e-08, -2.0944e-05),
            (100e-6, 1.5541e-06, 4.7124e-05, 1.3291e-08, 1.6101e-08, -4.1888e-05),
        ];
        for (d, a0, fc, dc, d0, f0) in rows {
            let j = ice_abs(d);
            assert!(rel(j.a0, a0) < 1e-4, "a0 {d}");
            assert!(rel(j.pull_off_force, fc) < 1e-4, "Fc {d}");
            assert!(rel(j.critical_overlap, dc) < 1e-4, "dc {d}");
            assert!(rel(j.zero_force_overlap(), d0) < 1e-4, "d0 {d}");
            assert!(rel(j.force(0.0).unwrap(), f0) < 1e-4, "F(0) {d}");
        }
    }

    #[test]
    fn forces_at_the_marked_points() {
        // JKR theory (Johnson, Kendall & Roberts 1971): F(0) = −8/9 F_c; F = 0 at δ = a₀²/(3R*); F_min = −F_c at
        // δ = −0.48075 δ_c; at δ = −δ_c the contact radius is x = 6^{-2/3} and F = −5/9 F_c.
        // Newton converges to machine precision: tolerance 1e-10 (1e-6 at the double root −δ_c).
        let j = ice_abs(20e-6);
        let fc = j.pull_off_force;
        assert!(rel(j.force(0.0).unwrap(), -8.0 / 9.0 * fc) < 1e-10);
        assert!(rel(j.contact_radius(0.0).unwrap(), touch_radius_ratio() * j.a0) < 1e-10);
        assert!(j.force(j.zero_force_overlap()).unwrap().abs() < 1e-10 * fc);
        assert!(rel(j.contact_radius(j.zero_force_overlap()).unwrap(), j.a0) < 1e-12);
        let d_lc = LOAD_CONTROLLED_BREAK_RATIO * j.critical_overlap;
        assert!(rel(j.force(d_lc).unwrap(), -fc) < 1e-10);
        // The load-controlled break ratio 0.48075 to its 5 digits.
        assert!((LOAD_CONTROLLED_BREAK_RATIO + 0.48075).abs() < 5e-6);
        let ds = -j.critical_overlap;
        assert!(rel(j.force(ds).unwrap(), -5.0 / 9.0 * fc) < 1e-6);
        assert!(rel(j.contact_radius(ds).unwrap(), 6f64.powf(-2.0 / 3.0) * j.a0) < 1e-6);
        assert!(j.force(ds * (1.0 + 1e-9)).is_none(), "no contact below −δ_c");
        // The JKR force is the minimum of the force curve at the load-controlled point.
        for k in 0..200 {
            let d = -j.critical_overlap + k as f64 * 0.01 * j.critical_overlap;
            assert!(j.force(d).unwrap() >= -fc * (1.0 + 1e-12));
        }
    }

    #[test]
    fn newton_root_lies_on_the_curve_for_any_start() {
        // Round trip δ → a → δ(a) over eight decades of overlap, cold and warm started.
        let j = ice_abs(50e-6);
        let mut prev: Option<f64> = None;
        for k in 0..400 {
            let ratio = -1.0 + 1e-9 + (k as f64 / 40.0).powi(4);
            let d = ratio * j.critical_overlap;
            let cold = j.root(d, None).unwrap();
            let warm = j.root(d, prev).unwrap();
            assert!(rel(warm, cold) < 1e-12, "warm start at {ratio}");
            let a = j.a0 * cold * cold;
            let back = j.overlap_of_radius(a);
            assert!((back - d).abs() < 1e-10 * j.critical_overlap.max(d.abs()), "{ratio}: {back} vs {d}");
            assert!(
                rel(j.force_of_radius(a), j.force_of_root(cold)) < 1e-9
                    || j.force_of_root(cold).abs() < 1e-12
            );
            prev = Some(cold);
        }
        // Starting far from the root (e.g. after a large jump) still converges to the largest root.
        for s in [-0.55, -0.3, 0.0, 1.0, 1e3, 1e8] {
            for st in [0.5503212081491043, 0.6, 1.0, 10.0, 1e3] {
                let y = normalised_root(s, Some(st)).unwrap();
                assert!((2.0 * y.powi(4) - 4.0 / 3.0 * y - s).abs() < 1e-12 * s.abs().max(1.0));
                assert!(y >= 0.5503212081491043);
            }
        }
    }

    #[test]
    fn neck_work_and_elastic_sticking_speed() {
        // Closed forms of the JKR curve: W_neck = 0.935503 F_c δ_c; V_s = 1.367847 √(F_c δ_c/m).
        // With Lind's (2017) ice–ABS inputs: W_neck = 2.7196e-14 J and V_s = 0.3360 m/s at d = 10 µm (4 digits).
        let j = ice_abs(10e-6);
        let w = j.neck_work(BreakCriterion::CriticalOverlap);
        assert!(rel(w, 0.935503 * j.pull_off_force * j.critical_overlap) < 1e-6);
        assert!(rel(w, 2.7196e-14) < 1e-4);
        let m = 920.0 * std::f64::consts::PI / 6.0 * 1e-15;
        let v = j.elastic_sticking_speed(m, BreakCriterion::CriticalOverlap);
        assert!(rel(v, 1.367847 * (j.pull_off_force * j.critical_overlap / m).sqrt()) < 1e-6);
        assert!(rel(v, 0.3360) < 2e-4);
        // Energy is the integral of the force: compare with a fine trapezoid rule (1e-6).
        let n = 20000;
        let (a, b) = (-j.critical_overlap * 0.9, j.critical_overlap * 3.0);
        let h = (b - a) / n as f64;
        let mut integral = 0.0;
        for i in 0..n {
            let x0 = a + i as f64 * h;
            integral += 0.5 * h * (j.force(x0).unwrap() + j.force(x0 + h).unwrap());
        }
        let exact = j.energy(b).unwrap() - j.energy(a).unwrap();
        assert!(rel(integral, exact) < 1e-6, "{integral} vs {exact}");
        assert!(j.energy(0.0).unwrap().abs() < 1e-12 * w);
        assert!((normalised_energy(TOUCH_RATIO) - TOUCH_ENERGY).abs() < 1e-15);
        assert!((TOUCH_RATIO - (2.0f64 / 3.0).powf(2.0 / 3.0)).abs() < 1e-15);
        // The closed-form neck works equal the stored energy at the break radius.
        for crit in [BreakCriterion::CriticalOverlap, BreakCriterion::PullOffForce] {
            let y = j.root(j.break_overlap(crit), None).unwrap();
            assert!(rel(j.neck_work(crit), j.energy_of_root(y)) < 1e-7, "{crit:?}");
        }
    }

    #[test]
    fn hysteresis_state_machine() {
        let j = ice_abs(10e-6);
        let dc = j.critical_overlap;
        for crit in [BreakCriterion::CriticalOverlap, BreakCriterion::PullOffForce] {
            let mut s = JkrState::default();
            assert!(j.evaluate(-0.5 * dc, crit, &mut s).is_none(), "no force on approach");
            assert!(!s.formed);
            let e = j.evaluate(0.0, crit, &mut s).unwrap();
            assert!(rel(e.force, -8.0 / 9.0 * j.pull_off_force) < 1e-10);
            assert!(s.formed);
            assert!(j.evaluate(-0.4 * dc, crit, &mut s).is_some(), "the neck persists");
            let inside = j.evaluate(0.999 * j.break_overlap(crit), crit, &mut s);
            assert!(inside.is_some());
            assert!(j.evaluate(1.001 * j.break_overlap(crit), crit, &mut s).is_none(), "breaks");
            assert_eq!(s, JkrState::default());
            assert!(j.evaluate(-0.1 * dc, crit, &mut s).is_none(), "no re-forming before touch");
        }
    }
}
