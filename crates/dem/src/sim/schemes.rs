//! The integrators of the study library ([`crate::integrators`]: Jasion 2013, *Toward a Physics Based
//! Entrainment Model for Simulation of Helicopter Brownout*, PhD thesis, University of Southampton,
//! Appendix A, Table A.1) on particle assemblies: forward Euler, RK2, RK4, AB2, AB4, ABM4, BD1, BD2 and
//! BD4 (symplectic Euler and velocity Verlet have their own, faster passes in `integrate.rs`).
//!
//! The state of particle i is yᵢ = (xᵢ, vᵢ, ωᵢ), its derivative (vᵢ, Fᵢ/mᵢ, τᵢ/Iᵢ). The update formulas,
//! the self-start (RK4 steps while the history is short) and the fixed-point iterations of the implicit
//! schemes are those of [`crate::integrators::Stepper`], applied to every particle at once.
//!
//! **Contact history.** Every step starts with one *committed* evaluation at (tₙ, yₙ): it advances the
//! incremental contact springs by Δt with the velocities of yₙ (as symplectic Euler does), books energy,
//! impacts and mesh records and decides which contacts form. The other evaluations of the step (RK
//! stages, the ABM corrector, further fixed-point iterations) are *trial* evaluations: each starts from
//! the contact states the committed evaluation left, advances the springs by the stage's own time
//! c·Δt, and its states are discarded afterwards. So a contact's history advances exactly once per
//! step whatever the number of stages.
//!
//! **Multi-step history.** The past derivatives (AB, ABM) or states (BD) are kept per particle id in
//! [`SchemeHistory`], which is part of the checkpointed state; a rebuild that re-sorts the particles
//! reorders it, a removed particle drops out of it, and a particle added during the run restarts it
//! (the next steps are RK4 steps again, the self-start).
//!
//! **Neighbour lists** are rebuilt only between steps. Each step adds twice the largest displacement of
//! any of its stage states from xₙ to the displacement bound, so the stages of the following step stay
//! inside the skin as long as the motion does not speed up more than twofold from one step to the next.

use super::forces::SlotOut;
use super::Simulation;
use crate::contact::ContactLaw;
use crate::error::DemError;
use crate::integrators::Scheme;
use crate::particles::Particles;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::Vec3;

/// One particle's state (x \[m\], v \[m/s\], ω \[rad/s\]) or its time derivative (v, a, α).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Y {
    pub x: Vec3,
    pub v: Vec3,
    pub w: Vec3,
}

/// The per-particle history of the multi-step schemes (checkpointed with the rest of the state).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SchemeHistory {
    /// Ids of the particles the entries belong to, in the order of the entries.
    pub ids: Vec<u32>,
    /// Past derivatives (AB2, AB4, ABM4) or past states (BD2, BD4), newest first.
    pub past: Vec<Vec<Y>>,
}

impl SchemeHistory {
    /// Puts the entries in the order of `ids` (the current particle order). Entries of particles that are
    /// gone are dropped; if a particle has no entry (it was added), the history restarts empty.
    fn align(&mut self, ids: &[u32]) {
        if self.ids == ids {
            return;
        }
        let mut order: Vec<(u32, u32)> = self.ids.iter().enumerate().map(|(k, &id)| (id, k as u32)).collect();
        order.sort_unstable();
        let mut from = Vec::with_capacity(ids.len());
        for id in ids {
            match order.binary_search_by_key(id, |e| e.0) {
                Ok(k) => from.push(order[k].1 as usize),
                Err(_) => {
                    self.past.clear();
                    break;
                }
            }
        }
        if !self.past.is_empty() {
            for p in &mut self.past {
                let old = std::mem::take(p);
                *p = from.iter().map(|&k| old[k]).collect();
            }
        }
        self.ids.clear();
        self.ids.extend_from_slice(ids);
    }

    /// Makes `latest` the newest entry, keeping at most `keep`.
    fn push(&mut self, latest: &[Y], keep: usize) {
        if self.past.len() < keep {
            self.past.insert(0, latest.to_vec());
        } else {
            self.past.rotate_right(1);
            self.past[0].clear();
            self.past[0].extend_from_slice(latest);
        }
    }
}

/// Buffers of one step (allocated once, not part of the state).
pub(crate) struct StageBuffers<S> {
    /// yₙ.
    y0: Vec<Y>,
    /// f(tₙ, yₙ), the committed evaluation.
    f0: Vec<Y>,
    /// Stage derivatives.
    k: [Vec<Y>; 3],
    /// A combination (stage state, BD base).
    tmp: Vec<Y>,
    /// Contact states after the committed evaluation.
    pairs: Vec<S>,
    walls: Vec<S>,
    outs: Vec<SlotOut>,
}

impl<S> Default for StageBuffers<S> {
    fn default() -> Self {
        StageBuffers {
            y0: Vec::new(),
            f0: Vec::new(),
            k: [Vec::new(), Vec::new(), Vec::new()],
            tmp: Vec::new(),
            pairs: Vec::new(),
            walls: Vec::new(),
            outs: Vec::new(),
        }
    }
}

/// out = Σ cₖ termₖ, particle by particle (the order of the sum is fixed: results do not depend on the
/// thread count).
fn lincomb(out: &mut Vec<Y>, n: usize, terms: &[(f64, &[Y])]) {
    out.resize(n, Y::default());
    out.par_iter_mut().enumerate().with_min_len(1024).for_each(|(i, o)| {
        let mut y = Y::default();
        for (c, t) in terms {
            let e = t[i];
            y.x += *c * e.x;
            y.v += *c * e.v;
            y.w += *c * e.w;
        }
        *o = y;
    });
}

/// Writes states `ys` into the particle arrays; returns the largest distance of a new position from
/// `x0` \[m\] and whether every component is finite.
fn write_state(p: &mut Particles, ys: &[Y], x0: &[Y]) -> (f64, bool) {
    let (d2, check) = p
        .pos
        .par_iter_mut()
        .zip(p.vel.par_iter_mut().zip(p.omega.par_iter_mut()))
        .enumerate()
        .with_min_len(1024)
        .map(|(i, (x, (v, w)))| {
            let y = ys[i];
            *x = y.x;
            *v = y.v;
            *w = y.w;
            ((y.x - x0[i].x).length_squared(), (y.x + y.v + y.w).element_sum())
        })
        .reduce(|| (0.0, 0.0), |a, b| (a.0.max(b.0), a.1 + b.1));
    (d2.sqrt(), check.is_finite())
}

fn read_state(p: &Particles, out: &mut Vec<Y>) {
    out.clear();
    out.extend(p.pos.iter().zip(p.vel.iter().zip(&p.omega)).map(|(&x, (&v, &w))| Y { x, v, w }));
}

impl<L: ContactLaw> Simulation<L> {
    /// The derivative (v, F/m, τ/I) of every particle from the forces of the last evaluation (α = 0 with
    /// rotation off; frozen particles keep their velocity).
    fn derivative_into(&self, out: &mut Vec<Y>) {
        let p = &self.particles;
        let rotation = self.settings.rotation;
        out.resize(p.len(), Y::default());
        out.par_iter_mut().enumerate().with_min_len(1024).for_each(|(i, o)| {
            let im = p.inv_mass[i];
            let r = p.radius[i];
            *o = Y {
                x: p.vel[i],
                v: im * p.force[i],
                // 1/I = 2.5/(m r²).
                w: if rotation { (2.5 * im / (r * r)) * p.torque[i] } else { Vec3::ZERO },
            };
        });
    }

    /// Writes states `ys` into the particle arrays (flagging a non-finite one for the blow-up check);
    /// returns the largest distance of a new position from `x0` \[m\].
    fn put_state(&mut self, ys: &[Y], x0: &[Y]) -> f64 {
        let (d, finite) = write_state(&mut self.particles, ys, x0);
        self.state_maybe_nonfinite |= !finite;
        d
    }

    /// A trial evaluation at time tₙ + `c`·Δt of the state now in the particle arrays: derivative into
    /// `out`, contact states back to those of the committed evaluation.
    fn trial(&mut self, b: &mut StageBuffers<L::State>, t0: f64, c: f64, out: usize) -> Result<(), DemError> {
        self.st.time = t0 + c * self.dt;
        self.trial_dt = Some(c * self.dt);
        let r = self.evaluate();
        self.trial_dt = None;
        self.st.time = t0;
        r?;
        self.derivative_into(&mut b.k[out]);
        self.st.list.state.copy_from_slice(&b.pairs);
        self.st.wall_list.state.copy_from_slice(&b.walls);
        self.st.wall_list.out.copy_from_slice(&b.outs);
        Ok(())
    }

    /// One step of `scheme` (any but symplectic Euler, which has its own pass).
    pub(crate) fn scheme_step(&mut self, scheme: Scheme) -> Result<(), DemError> {
        if !self.st.bodies.is_empty() {
            return Err(DemError::Config {
                key: "integrator".into(),
                message: format!(
                    "the integrator {} runs single spheres only; clumps need velocity_verlet or symplectic_euler",
                    scheme.label()
                ),
            });
        }
        let iterations = self.settings.iterations.unwrap_or(0);
        if scheme.is_implicit() && iterations == 0 {
            return Err(DemError::Config {
                key: "iterations".into(),
                message: format!(
                    "the implicit integrator {} needs an iteration count ≥ 1 (BD-p keeps its order with ≥ p)",
                    scheme.label()
                ),
            });
        }
        self.maybe_rebuild();
        let need = scheme.history();
        if need > 0 {
            self.st.history.align(&self.particles.id);
        } else if !self.st.history.past.is_empty() {
            self.st.history = SchemeHistory::default();
        }
        let started = self.st.history.past.len() >= need;
        let n = self.particles.len();
        let (t0, dt) = (self.st.time, self.dt);
        let mut b = std::mem::take(&mut self.stage);
        read_state(&self.particles, &mut b.y0);

        // The committed evaluation at (tₙ, yₙ).
        self.evaluate()?;
        self.derivative_into(&mut b.f0);
        b.pairs.clone_from(&self.st.list.state);
        b.walls.clone_from(&self.st.wall_list.state);
        b.outs.clone_from(&self.st.wall_list.out);

        let mut reach: f64 = 0.0;
        macro_rules! stage {
            ($terms:expr, $c:expr, $out:expr) => {{
                lincomb(&mut b.tmp, n, $terms);
                reach = reach.max(self.put_state(&b.tmp, &b.y0));
                self.trial(&mut b, t0, $c, $out)?;
            }};
        }
        // The history is taken out for the step (the stages borrow the simulation mutably).
        let p = std::mem::take(&mut self.st.history.past);
        let h = 0.5 * dt;
        let rk4 = scheme == Scheme::Rk4 || (need > 0 && !started);
        if rk4 {
            stage!(&[(1.0, &b.y0), (h, &b.f0)], 0.5, 0);
            stage!(&[(1.0, &b.y0), (h, &b.k[0])], 0.5, 1);
            stage!(&[(1.0, &b.y0), (dt, &b.k[1])], 1.0, 2);
            let s = dt / 6.0;
            lincomb(
                &mut b.tmp,
                n,
                &[(1.0, &b.y0), (s, &b.f0), (2.0 * s, &b.k[0]), (2.0 * s, &b.k[1]), (s, &b.k[2])],
            );
        } else {
            let s = dt / 24.0;
            match scheme {
                Scheme::Fe => lincomb(&mut b.tmp, n, &[(1.0, &b.y0), (dt, &b.f0)]),
                Scheme::Rk2 => {
                    stage!(&[(1.0, &b.y0), (h, &b.f0)], 0.5, 0);
                    lincomb(&mut b.tmp, n, &[(1.0, &b.y0), (dt, &b.k[0])]);
                }
                Scheme::Ab2 => lincomb(&mut b.tmp, n, &[(1.0, &b.y0), (1.5 * dt, &b.f0), (-0.5 * dt, &p[0])]),
                Scheme::Ab4 | Scheme::Abm4 => {
                    let pred: [(f64, &[Y]); 5] = [
                        (1.0, &b.y0),
                        (55.0 * s, &b.f0),
                        (-59.0 * s, &p[0]),
                        (37.0 * s, &p[1]),
                        (-9.0 * s, &p[2]),
                    ];
                    if scheme == Scheme::Ab4 {
                        lincomb(&mut b.tmp, n, &pred);
                    } else {
                        stage!(&pred, 1.0, 0);
                        lincomb(
                            &mut b.tmp,
                            n,
                            &[
                                (1.0, &b.y0),
                                (9.0 * s, &b.k[0]),
                                (19.0 * s, &b.f0),
                                (-5.0 * s, &p[0]),
                                (s, &p[1]),
                            ],
                        );
                    }
                }
                Scheme::Bd1 | Scheme::Bd2 | Scheme::Bd4 => {
                    // y_{n+1} = base + β Δt f(y_{n+1}), iterated from yₙ (whose derivative is f0).
                    let (base, beta): (&[(f64, &[Y])], f64) = match scheme {
                        Scheme::Bd1 => (&[(1.0, &b.y0)], 1.0),
                        Scheme::Bd2 => (&[(4.0 / 3.0, &b.y0), (-1.0 / 3.0, &p[0])], 2.0 / 3.0),
                        _ => (
                            &[
                                (48.0 / 25.0, &b.y0),
                                (-36.0 / 25.0, &p[0]),
                                (16.0 / 25.0, &p[1]),
                                (-3.0 / 25.0, &p[2]),
                            ],
                            12.0 / 25.0,
                        ),
                    };
                    // k[1] holds the base, k[2] the current guess.
                    let mut base_buf = std::mem::take(&mut b.k[1]);
                    lincomb(&mut base_buf, n, base);
                    b.k[1] = base_buf;
                    let mut guess = std::mem::take(&mut b.k[2]);
                    lincomb(&mut guess, n, &[(1.0, &b.k[1]), (beta * dt, &b.f0)]);
                    for _ in 1..iterations {
                        reach = reach.max(self.put_state(&guess, &b.y0));
                        self.trial(&mut b, t0, 1.0, 0)?;
                        lincomb(&mut guess, n, &[(1.0, &b.k[1]), (beta * dt, &b.k[0])]);
                    }
                    std::mem::swap(&mut b.tmp, &mut guess);
                    b.k[2] = guess;
                }
                Scheme::Se | Scheme::Rk4 => unreachable!("handled above"),
            }
        }
        reach = reach.max(self.put_state(&b.tmp, &b.y0));
        self.st.history.past = p;
        match scheme {
            Scheme::Ab2 | Scheme::Ab4 | Scheme::Abm4 => self.st.history.push(&b.f0, need),
            Scheme::Bd2 | Scheme::Bd4 => self.st.history.push(&b.y0, need),
            _ => {}
        }
        self.stage = b;
        self.st.forces_valid = false;
        self.advance_time(0.0);
        self.st.disp_particles += 2.0 * reach;
        Ok(())
    }
}
