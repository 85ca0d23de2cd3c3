//! The ten time-integration schemes of the DEM integrator study (Jasion 2013, *Toward a Physics Based
//! Entrainment Model for Simulation of Helicopter Brownout*, PhD thesis, University of Southampton,
//! Appendix A, Table A.1; the schemes in their textbook forms as in Tuley, Danby, Shrimpton & Palmer
//! 2010, "On the optimal numerical time integration for DEM using soft sphere contact models", Powder
//! Technology 203), for a system of ordinary differential equations y′ = f(t, y) whose state is
//! positions followed by velocities, y = (q, v).
//!
//! | scheme | force evaluations per step | history |
//! |---|---|---|
//! | FE forward Euler | 1 | – |
//! | SE symplectic Euler (v first, then q with the new v) | 1 | – |
//! | RK2 explicit midpoint | 2 | – |
//! | RK4 classical Runge–Kutta | 4 | – |
//! | AB2, AB4 Adams–Bashforth | 1 | 1, 3 past derivatives |
//! | ABM4 AB4 predictor + 3-step Adams–Moulton corrector (PECE) | 2 | 3 past derivatives |
//! | BD1, BD2, BD4 backward differentiation, implicit | `iterations` | 0, 1, 3 past states |
//!
//! The multi-step schemes start themselves: while their history is short they take RK4 steps (fourth
//! order, so the start never limits the order), recording the derivative at each step start. The
//! implicit schemes solve their equation by a fixed number of fixed-point iterations from y_n, each
//! costing one evaluation; k iterations give a local error O(Δt^{k+1}) of the iteration, so BD-p needs at
//! least p iterations to keep its order.

use serde::{Deserialize, Serialize};

/// A time-integration scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scheme {
    Fe,
    Se,
    Rk2,
    Rk4,
    Ab2,
    Ab4,
    Abm4,
    Bd1,
    Bd2,
    Bd4,
}

impl Scheme {
    /// All ten, in the order of Jasion (2013), Table A.1.
    pub const ALL: [Scheme; 10] = [
        Scheme::Fe,
        Scheme::Se,
        Scheme::Rk2,
        Scheme::Rk4,
        Scheme::Ab2,
        Scheme::Ab4,
        Scheme::Abm4,
        Scheme::Bd1,
        Scheme::Bd2,
        Scheme::Bd4,
    ];

    /// Short upper-case name (FE, SE, …).
    pub fn label(self) -> &'static str {
        match self {
            Scheme::Fe => "FE",
            Scheme::Se => "SE",
            Scheme::Rk2 => "RK2",
            Scheme::Rk4 => "RK4",
            Scheme::Ab2 => "AB2",
            Scheme::Ab4 => "AB4",
            Scheme::Abm4 => "ABM4",
            Scheme::Bd1 => "BD1",
            Scheme::Bd2 => "BD2",
            Scheme::Bd4 => "BD4",
        }
    }

    /// Parses a label or snake-case name (`"RK4"`, `"rk4"`).
    pub fn parse(s: &str) -> Option<Scheme> {
        Scheme::ALL.into_iter().find(|k| k.label().eq_ignore_ascii_case(s))
    }

    /// Global order of accuracy on a smooth problem. SE is first order in general but second order in
    /// the position when the motion starts with zero acceleration (a particle entering a contact), the
    /// case of the study.
    pub fn nominal_order(self) -> u32 {
        match self {
            Scheme::Fe | Scheme::Bd1 => 1,
            Scheme::Se | Scheme::Rk2 | Scheme::Ab2 | Scheme::Bd2 => 2,
            Scheme::Rk4 | Scheme::Ab4 | Scheme::Abm4 | Scheme::Bd4 => 4,
        }
    }

    /// Whether the scheme is implicit (needs an iteration count).
    pub fn is_implicit(self) -> bool {
        matches!(self, Scheme::Bd1 | Scheme::Bd2 | Scheme::Bd4)
    }

    /// Force (derivative) evaluations per step once started; `iterations` for the implicit ones.
    pub fn evaluations_per_step(self, iterations: u32) -> u32 {
        match self {
            Scheme::Fe | Scheme::Se | Scheme::Ab2 | Scheme::Ab4 => 1,
            Scheme::Rk2 | Scheme::Abm4 => 2,
            Scheme::Rk4 => 4,
            Scheme::Bd1 | Scheme::Bd2 | Scheme::Bd4 => iterations,
        }
    }

    /// Past derivatives (AB, ABM) or states (BD) kept besides the current ones.
    pub(crate) fn history(self) -> usize {
        match self {
            Scheme::Ab2 | Scheme::Bd2 => 1,
            Scheme::Ab4 | Scheme::Abm4 | Scheme::Bd4 => 3,
            _ => 0,
        }
    }
}

/// y′ = f(t, y) with y = (q, v) of `N` = 2 × degrees of freedom entries.
pub trait System<const N: usize> {
    /// The derivative (v, a(t, q, v)) at `t` \[s\] and state `y`.
    fn derivative(&mut self, t: f64, y: &[f64; N]) -> [f64; N];
}

/// Steps one state with one scheme, keeping the multi-step history.
#[derive(Clone, Debug)]
pub struct Stepper<const N: usize> {
    pub scheme: Scheme,
    /// Fixed-point iterations per step of the implicit schemes (≥ 1).
    pub iterations: u32,
    /// Past derivatives f_{n−1}, f_{n−2}, … (newest first).
    f_past: Vec<[f64; N]>,
    /// Past states y_{n−1}, y_{n−2}, … (newest first).
    y_past: Vec<[f64; N]>,
    /// Derivative evaluations so far.
    pub evaluations: u64,
}

fn axpy<const N: usize>(y: &[f64; N], h: f64, f: &[f64; N]) -> [f64; N] {
    std::array::from_fn(|i| y[i] + h * f[i])
}

impl<const N: usize> Stepper<N> {
    /// A stepper with an empty history. Implicit schemes need `iterations` ≥ 1.
    pub fn new(scheme: Scheme, iterations: u32) -> Result<Self, String> {
        if scheme.is_implicit() && iterations == 0 {
            return Err(format!(
                "the implicit scheme {} needs an iteration count ≥ 1 (e.g. {})",
                scheme.label(),
                scheme.nominal_order() + 1
            ));
        }
        Ok(Stepper { scheme, iterations, f_past: Vec::new(), y_past: Vec::new(), evaluations: 0 })
    }

    fn eval(&mut self, sys: &mut impl System<N>, t: f64, y: &[f64; N]) -> [f64; N] {
        self.evaluations += 1;
        sys.derivative(t, y)
    }

    /// Advances `y` from `t` by `dt`.
    pub fn step(&mut self, sys: &mut impl System<N>, t: f64, y: &mut [f64; N], dt: f64) {
        let need = self.scheme.history();
        let started = self.f_past.len().max(self.y_past.len()) >= need;
        let y0 = *y;
        match self.scheme {
            Scheme::Fe => {
                let f = self.eval(sys, t, y);
                *y = axpy(y, dt, &f);
            }
            Scheme::Se => {
                let f = self.eval(sys, t, y);
                let d = N / 2;
                for i in 0..d {
                    y[d + i] += dt * f[d + i];
                }
                for i in 0..d {
                    y[i] += dt * y[d + i];
                }
            }
            Scheme::Rk2 => {
                let k1 = self.eval(sys, t, y);
                let k2 = self.eval(sys, t + 0.5 * dt, &axpy(y, 0.5 * dt, &k1));
                *y = axpy(y, dt, &k2);
            }
            Scheme::Rk4 => {
                let f0 = self.eval(sys, t, y);
                *y = self.rk4_from(sys, t, y, dt, &f0);
            }
            Scheme::Ab2 | Scheme::Ab4 | Scheme::Abm4 => {
                let f0 = self.eval(sys, t, y);
                if !started {
                    *y = self.rk4_from(sys, t, y, dt, &f0);
                } else {
                    let p = &self.f_past;
                    *y = match self.scheme {
                        Scheme::Ab2 => std::array::from_fn(|i| y[i] + dt * (1.5 * f0[i] - 0.5 * p[0][i])),
                        _ => {
                            let pred: [f64; N] = std::array::from_fn(|i| {
                                y[i] + dt / 24.0
                                    * (55.0 * f0[i] - 59.0 * p[0][i] + 37.0 * p[1][i] - 9.0 * p[2][i])
                            });
                            if self.scheme == Scheme::Ab4 {
                                pred
                            } else {
                                let f1 = self.eval(sys, t + dt, &pred);
                                let p = &self.f_past;
                                std::array::from_fn(|i| {
                                    y[i] + dt / 24.0 * (9.0 * f1[i] + 19.0 * f0[i] - 5.0 * p[0][i] + p[1][i])
                                })
                            }
                        }
                    };
                }
                self.f_past.insert(0, f0);
                self.f_past.truncate(need);
            }
            Scheme::Bd1 | Scheme::Bd2 | Scheme::Bd4 => {
                if !started {
                    let f0 = self.eval(sys, t, y);
                    *y = self.rk4_from(sys, t, y, dt, &f0);
                } else {
                    // y_{n+1} = Σ αₖ y_{n−k} + β Δt f(t_{n+1}, y_{n+1}).
                    let p = &self.y_past;
                    let (base, beta): ([f64; N], f64) = match self.scheme {
                        Scheme::Bd1 => (y0, 1.0),
                        Scheme::Bd2 => (std::array::from_fn(|i| (4.0 * y0[i] - p[0][i]) / 3.0), 2.0 / 3.0),
                        _ => (
                            std::array::from_fn(|i| {
                                (48.0 * y0[i] - 36.0 * p[0][i] + 16.0 * p[1][i] - 3.0 * p[2][i]) / 25.0
                            }),
                            12.0 / 25.0,
                        ),
                    };
                    let mut guess = y0;
                    for _ in 0..self.iterations {
                        let f = self.eval(sys, t + dt, &guess);
                        guess = axpy(&base, beta * dt, &f);
                    }
                    *y = guess;
                }
                if need > 0 {
                    self.y_past.insert(0, y0);
                    self.y_past.truncate(need);
                }
            }
        }
    }

    /// One RK4 step whose first stage `f0` is known.
    fn rk4_from(
        &mut self,
        sys: &mut impl System<N>,
        t: f64,
        y: &[f64; N],
        dt: f64,
        f0: &[f64; N],
    ) -> [f64; N] {
        let h = 0.5 * dt;
        let k2 = self.eval(sys, t + h, &axpy(y, h, f0));
        let k3 = self.eval(sys, t + h, &axpy(y, h, &k2));
        let k4 = self.eval(sys, t + dt, &axpy(y, dt, &k3));
        std::array::from_fn(|i| y[i] + dt / 6.0 * (f0[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]))
    }
}
