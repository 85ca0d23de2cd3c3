//! The Basset (history) force.
//!
//! Boussinesq–Basset term of the Maxey–Riley equation (Jasion 2013 eq. 3.35, 3.37;
//! `digests/seed_003_brownout.md` §2.3), per unit mass, with w = u_f − v_p:
//!
//! F_B/m = K_B C_H/6 · [ ∫₀ᵗ (dw/dτ) / √(t − τ) dτ + w(0)/√t ],    K_B = 9 √(ρ_f μ) / (√π ρ_p d),
//!
//! (K_B = 6 r² √(π ρ_f μ)/m_p). The second term is Reeks & McKee's (1984) correction for a particle
//! injected with a slip w(0). C_H is Odar & Hamilton's (1964) acceleration correction
//! C_H = 2.88 + 3.12/(1 + A_c)³ (C_H = 6 in creeping flow, hence the C_H/6).
//!
//! Jasion prints C_B = 2.88 + 3.12/(0.12 + A_c)³ (eq. 3.36): that mixes in the 0.12 of Odar–Hamilton's
//! added-mass coefficient and gives C_B(0) = 1808, i.e. a force 300× Basset's. [`odar_hamilton_as_printed`]
//! reproduces it for the closed-form checks; the force uses the original form.
//!
//! **Discretisation.** With w piecewise linear between step times t_j, the integral over each interval is
//! exact: (w_{j+1} − w_j)/Δt · 2(√(t − t_j) − √(t − t_{j+1})). The singular last interval gives
//! 2 (w_{n+1} − w_n)/√Δt, which is treated implicitly as an extra inertia (the tracker adds
//! `2 K_B C_H/6 √Δt` to the effective mass). Intervals older than the window are dropped (Dorgan & Loth
//! 2007 show a window of a few τ_p loses little); the memory is `window` vectors per particle.

use serde::{Deserialize, Serialize};
use spatter_core::Vec3;

/// Odar & Hamilton (1964) history coefficient C_H = 2.88 + 3.12/(1 + A_c)³.
#[inline]
pub fn odar_hamilton(a_c: f64) -> f64 {
    2.88 + 3.12 / (1.0 + a_c).powi(3)
}

/// Jasion eq. 3.36 as printed: C_B = 2.88 + 3.12/(0.12 + A_c)³ (see the module notes).
#[inline]
pub fn odar_hamilton_as_printed(a_c: f64) -> f64 {
    2.88 + 3.12 / (0.12 + a_c).powi(3)
}

/// Acceleration number A_c = |w|² / (d · |d|w|/dt|) (Jasion eq. 3.36); ∞ when the slip does not change.
#[inline]
pub fn acceleration_number(slip: f64, d: f64, dslip_dt: f64) -> f64 {
    let den = d * dslip_dt.abs();
    if den > 0.0 {
        slip * slip / den
    } else {
        f64::INFINITY
    }
}

/// K_B = 9 √(ρ_f μ) / (√π ρ_p d) \[s^(-1/2)\]: the history force per unit mass is K_B times an integral
/// with units of m/s^(1/2).
#[inline]
pub fn basset_coefficient(rho_f: f64, mu: f64, rho_p: f64, d: f64) -> f64 {
    9.0 * (rho_f * mu).sqrt() / (std::f64::consts::PI.sqrt() * rho_p * d)
}

/// Settings of the history force.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BassetSettings {
    /// Number of past intervals kept (window length = window × dt).
    #[serde(default = "default_window")]
    pub window: usize,
    /// Apply the Odar–Hamilton acceleration correction C_H/6 (otherwise C_H/6 = 1, the creeping-flow
    /// Basset force).
    #[serde(default)]
    pub odar_hamilton: bool,
    /// Include the Reeks–McKee initial-slip term w(0)/√t.
    #[serde(default = "yes")]
    pub reeks_mckee: bool,
}

fn default_window() -> usize {
    64
}
fn yes() -> bool {
    true
}

impl Default for BassetSettings {
    fn default() -> Self {
        BassetSettings { window: default_window(), odar_hamilton: false, reeks_mckee: true }
    }
}

/// The slip history of one particle: a ring buffer of w at the last `window + 1` step times.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct History {
    w: Vec<Vec3>,
    /// Index of the newest sample in `w`.
    head: usize,
    /// Number of valid samples.
    len: usize,
    /// Slip at the start of the particle's life (Reeks–McKee).
    pub w0: Vec3,
    /// Time since the particle's life started \[s\].
    pub age: f64,
    /// Fluid velocity seen at the previous step (estimates the fluid's change over the coming step).
    pub u_last: Vec3,
}

impl History {
    /// An empty history for a window of `window` intervals, starting with slip `w0`.
    pub fn new(window: usize, w0: Vec3) -> Self {
        let mut w = vec![Vec3::ZERO; window + 1];
        w[0] = w0;
        History { w, head: 0, len: 1, w0, age: 0.0, u_last: Vec3::ZERO }
    }

    /// Records the slip at the end of a step of length `dt`.
    pub fn push(&mut self, w: Vec3, dt: f64) {
        let cap = self.w.len();
        self.head = (self.head + 1) % cap;
        self.w[self.head] = w;
        self.len = (self.len + 1).min(cap);
        self.age += dt;
    }

    /// The newest recorded slip.
    pub fn last(&self) -> Vec3 {
        self.w[self.head]
    }

    /// The explicit part of the history integral at time t_n + dt (the end of the coming step), i.e.
    /// Σ over every completed interval inside the window of (Δw_j/dt)·2(√(t − t_j) − √(t − t_{j+1})),
    /// with constant step `dt`, plus the Reeks–McKee term when requested. The coming interval's own
    /// contribution 2(w_{n+1} − w_n)/√dt is left to the caller (it is implicit).
    pub fn explicit_integral(&self, dt: f64, reeks_mckee: bool) -> Vec3 {
        let cap = self.w.len();
        let mut sum = Vec3::ZERO;
        // Interval k steps back (k = 1 is the newest completed one) spans [t − (k+1)dt, t − k dt].
        for k in 1..self.len {
            let newer = self.w[(self.head + cap - (k - 1)) % cap];
            let older = self.w[(self.head + cap - k) % cap];
            let weight = 2.0 * (((k + 1) as f64).sqrt() - (k as f64).sqrt()) / dt.sqrt();
            sum += (newer - older) * weight;
        }
        if reeks_mckee {
            sum += self.w0 / (self.age + dt).sqrt();
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn odar_hamilton_values() {
        // digests/seed_003_brownout.md §6.1 item 2 (printed form): C_B(0) = 1808.44, C_B(1) = 5.1008,
        // C_B(∞) = 2.88 (5 significant figures).
        assert!((odar_hamilton_as_printed(0.0) - 1808.44).abs() < 0.01);
        assert!((odar_hamilton_as_printed(1.0) - 5.1008).abs() < 1e-4);
        assert_eq!(odar_hamilton_as_printed(f64::INFINITY), 2.88);
        // Original form: 6 in creeping flow (Basset), 2.88 for large A_c.
        assert!((odar_hamilton(0.0) - 6.0).abs() < 1e-15);
        assert_eq!(odar_hamilton(f64::INFINITY), 2.88);
    }

    #[test]
    fn history_integral_of_linear_ramp_is_exact() {
        // w(t) = a t from t = 0: ∫₀ᵗ a/√(t−τ) dτ = 2a√t exactly (every interval integrated exactly).
        let a = Vec3::new(2.0, -1.0, 0.5);
        let dt = 1e-3;
        let n = 50;
        let mut h = History::new(1000, Vec3::ZERO);
        for i in 1..=n {
            h.push(a * (i as f64 * dt), dt);
        }
        // Integral at t = (n+1) dt: explicit part + the coming interval's 2 Δw/√dt with Δw = a dt.
        let t = (n + 1) as f64 * dt;
        let total = h.explicit_integral(dt, false) + 2.0 * a * dt / dt.sqrt();
        let expect = 2.0 * a * t.sqrt();
        assert!((total - expect).length() < 1e-12 * expect.length(), "{total} vs {expect}");
    }

    #[test]
    fn window_truncates_old_intervals() {
        let dt = 1e-3;
        let mut h = History::new(4, Vec3::ZERO);
        // A step in w long ago falls out of a window of 4 intervals.
        h.push(Vec3::X, dt);
        for _ in 0..10 {
            h.push(Vec3::X, dt);
        }
        assert_eq!(h.explicit_integral(dt, false), Vec3::ZERO);
        // Reeks–McKee: w0/√(age + dt).
        let h = History::new(4, Vec3::Y);
        assert!((h.explicit_integral(0.25, true) - Vec3::Y * 2.0).length() < 1e-15);
    }
}
