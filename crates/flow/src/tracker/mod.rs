//! The Lagrangian parcel tracker.
//!
//! **Integrator.** Over a step of length Δt the fluid velocity u (mean + turbulent fluctuation), the drag
//! relaxation time τ (from the drag law at the slip at the start of the step), the inertia factor M
//! (added mass, implicit Basset part) and every other force a are held fixed and the equation
//! M dv/dt = (u − v)/τ + a is integrated exactly (the "analytic" scheme of OpenFOAM's particle
//! integration and Fluent's analytic drag update):
//!
//! τ′ = Mτ, v_∞ = u + a τ′/M,  v(Δt) = v_∞ + (v − v_∞) e^(−Δt/τ′),
//! x(Δt) = x + v_∞ Δt + (v − v_∞) τ′ (1 − e^(−Δt/τ′)).
//!
//! It is unconditionally stable and exact in uniform flow with constant forces; for τ ≪ Δt a parcel
//! moves at its local equilibrium velocity u + aτ (e.g. terminal settling), which is the right answer.
//! Its error is first order in Δt through the variation of u, τ and a along the path. The spin decays
//! exponentially with the rate of the fluid torque.
//!
//! **Walls.** The segment x → x(Δt) is tested against every body (BVH); at the first hit the body's
//! rule applies (stick, bounce with restitution for the rest of the step, or escape), up to
//! `max_bounces` times per step. With the wall-bounded lift switched on ([`ForceSwitches::wall_lift`])
//! the closest body surface point within 4 d of the parcel (BVH query) gives the wall distance and the
//! direction of the lift, which joins the other forces of the step ([`wall_lift`]).
//!
//! [`ForceSwitches::wall_lift`]: crate::forces::model::ForceSwitches::wall_lift
//!
//! **Parallelism.** Parcels are processed in fixed chunks of [`CHUNK`] with rayon; each parcel depends
//! only on its own state (its random stream is `seeded(seed, parcel id)`), impacts are collected per
//! chunk and reduced in chunk order, so results are bit-identical for any thread count. The per-parcel
//! loop does not allocate.

pub mod deposit;
pub mod exact_sum;
pub mod inject;
pub mod walls;

use crate::field::dispersion::{DispersionSettings, Eddy};
use crate::field::tetmesh::NONE;
use crate::field::FlowField;
use crate::forces::history::{acceleration_number, basset_coefficient, odar_hamilton, History};
use crate::forces::model::{FluidLocal, ForceModel};
use crate::forces::wall_lift::{
    friction_velocity, wall_lift_acceleration, WallLiftSettings, WALL_LIFT_RANGE_DIAMETERS,
};
use crate::forces::{sphere_mass, Fluid};
use deposit::{Deposit, Impact, ImpactOutcome};
use exact_sum::ExactSum;
use inject::NewParcel;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::rng::{seeded, Rng};
use spatter_core::{Aabb, Vec3};
use walls::{reflect, Body, Outcome};

/// Parcels per parallel work item (fixed, so the reduction order never depends on the thread count).
pub const CHUNK: usize = 1024;

/// Where a parcel is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Status {
    Airborne,
    Deposited,
    Escaped,
}

/// One parcel: `count` identical particles moving together. The state every step reads; what only
/// some force models need lives in [`ParcelExtra`] and [`History`] side arrays.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Parcel {
    pub pos: Vec3,
    pub vel: Vec3,
    pub diameter: f64,
    pub density: f64,
    pub count: f64,
    /// Stable id (release order).
    pub id: u64,
    /// Location cache of the flow field.
    pub hint: u32,
    pub status: Status,
    /// Injector that released it.
    pub injector: u16,
}

/// Per-parcel state kept only when the random walk or the particle spin is in use.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParcelExtra {
    /// Angular velocity \[rad/s\].
    pub spin: Vec3,
    /// Current eddy of the random walk.
    pub eddy: Eddy,
    /// The parcel's own random stream (`seeded(seed, id)`).
    pub rng: Rng,
}

impl Parcel {
    /// Mass of the parcel (all its particles) \[kg\].
    pub fn mass(&self) -> f64 {
        self.count * sphere_mass(self.diameter, self.density)
    }
}

/// Settings of the tracker.
#[derive(Clone, Debug, PartialEq)]
pub struct TrackSettings {
    /// Time step \[s\].
    pub dt: f64,
    /// Parcels leaving this box escape (in addition to leaving an imported field's mesh).
    pub domain: Option<Aabb>,
    pub dispersion: Option<DispersionSettings>,
    /// Maximum wall bounces handled within one step.
    pub max_bounces: u32,
    /// Every this many steps the parcels are reordered by their location (cell order, which follows a
    /// Morton curve), so that neighbouring parcels in memory read neighbouring mesh data; 0 = never.
    pub resort_interval: u32,
}

impl Default for TrackSettings {
    fn default() -> Self {
        TrackSettings { dt: 1e-4, domain: None, dispersion: None, max_bounces: 8, resort_interval: 20 }
    }
}

/// Exact mass balance of a run.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Balance {
    pub injected: ExactSum,
    pub deposited: ExactSum,
    pub escaped: ExactSum,
    pub n_injected: u64,
    pub n_deposited: u64,
    pub n_escaped: u64,
}

/// The serialisable state of a run (checkpoints).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct TrackerState {
    pub time: f64,
    pub step: u64,
    pub parcels: Vec<Parcel>,
    /// Spin and random-walk state, one per parcel when dispersion, Magnus lift or the fluid torque is on.
    pub extras: Vec<ParcelExtra>,
    /// Slip histories (Basset), one per parcel when the force is on.
    pub histories: Vec<History>,
    /// One per body.
    pub deposits: Vec<Deposit>,
    pub balance: Balance,
    pub next_id: u64,
    /// Parcels at this index and beyond are not airborne (set by [`Tracker::sort_parcels`], which puts the
    /// airborne ones first, and by [`Tracker::add`]); the step loop stops here, so deposited and escaped
    /// parcels cost nothing once sorted out.
    pub live_end: usize,
}

/// A run that cannot continue.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    #[error("parcel {id} blew up at step {step}, t = {time} s: {cause}")]
    BlowUp { id: u64, step: u64, time: f64, cause: String },
}

/// Something that happened to a parcel during a step.
#[derive(Clone, Copy, Debug)]
enum Event {
    Impact(Impact),
    /// Left the domain or the mesh with this mass.
    Exit(f64),
}

/// Everything a parcel update reads.
struct Ctx<'a, F: FlowField> {
    field: &'a F,
    model: &'a ForceModel,
    bodies: &'a [Body],
    s: &'a TrackSettings,
    t: f64,
    dt: f64,
    need_grad: bool,
}

/// The tracker.
pub struct Tracker<F: FlowField> {
    pub field: F,
    pub model: ForceModel,
    pub settings: TrackSettings,
    pub bodies: Vec<Body>,
    pub state: TrackerState,
    events: Vec<Vec<Event>>,
    errors: Vec<Option<TrackError>>,
}

/// The exponential (analytic drag) update of position and velocity over `dt` with fluid velocity `u`,
/// relaxation time `tau` (∞ = no drag) and constant acceleration `a` (both already divided by the
/// inertia factor).
#[inline]
pub fn exponential_update(x: Vec3, v: Vec3, u: Vec3, tau: f64, a: Vec3, dt: f64) -> (Vec3, Vec3) {
    if tau.is_finite() && tau > 0.0 {
        let v_inf = u + a * tau;
        let r = dt / tau;
        // 1 − e^(−r) without cancellation for small r.
        let one_minus_e = -(-r).exp_m1();
        let e = 1.0 - one_minus_e;
        (x + v_inf * dt + (v - v_inf) * (tau * one_minus_e), v_inf + (v - v_inf) * e)
    } else {
        let v1 = v + a * dt;
        (x + 0.5 * (v + v1) * dt, v1)
    }
}

impl<F: FlowField> Tracker<F> {
    pub fn new(field: F, model: ForceModel, settings: TrackSettings, bodies: Vec<Body>) -> Self {
        let deposits = bodies.iter().map(|b| Deposit::new(b.mesh.triangles.len())).collect();
        Tracker {
            field,
            model,
            settings,
            bodies,
            state: TrackerState { deposits, ..Default::default() },
            events: Vec::new(),
            errors: Vec::new(),
        }
    }

    /// Adds a parcel (released at the current time). A parcel released outside the domain escapes at once.
    pub fn add(&mut self, p: NewParcel, injector: u16) {
        let id = self.state.next_id;
        self.state.next_id += 1;
        let seed = self.settings.dispersion.map(|d| d.seed).unwrap_or(0);
        let mut parcel = Parcel {
            pos: p.pos,
            vel: p.vel,
            diameter: p.diameter,
            density: p.density,
            count: p.count,
            id,
            hint: NONE,
            status: Status::Airborne,
            injector,
        };
        if self.needs_extras() {
            self.state.extras.push(ParcelExtra {
                spin: Vec3::ZERO,
                eddy: Eddy::default(),
                rng: seeded(seed, id),
            });
        }
        let m = parcel.mass();
        let b = &mut self.state.balance;
        b.injected.add(m);
        b.n_injected += 1;
        let inside = self.settings.domain.is_none_or(|d| d.contains(p.pos))
            && self.field.sample(p.pos, self.state.time, &mut parcel.hint, false).is_some();
        if !inside {
            parcel.status = Status::Escaped;
            b.escaped.add(m);
            b.n_escaped += 1;
        }
        if let Some(bs) = self.model.switches.basset {
            let w0 = self
                .field
                .sample(p.pos, self.state.time, &mut parcel.hint, false)
                .map(|s| s.u - p.vel)
                .unwrap_or(Vec3::ZERO);
            let tau_p = crate::forces::stokes_time(&self.model.fluid, p.diameter, p.density);
            let mut h = History::new(bs.window_steps(tau_p, self.settings.dt), bs.tail, w0);
            h.u_last = w0 + p.vel;
            self.state.histories.push(h);
        }
        self.state.parcels.push(parcel);
        self.state.live_end = self.state.parcels.len();
    }

    /// Whether parcels carry a [`ParcelExtra`].
    fn needs_extras(&self) -> bool {
        let s = &self.model.switches;
        self.settings.dispersion.is_some() || s.magnus || s.rotational_torque.is_some()
    }

    /// Reorders the parcels: airborne ones first, by location cell, then by id (deterministic); the
    /// step loop then ends at the last airborne parcel.
    pub fn sort_parcels(&mut self) {
        let ps = &self.state.parcels;
        // Keys are unique (ids are), so the parallel unstable sort gives one order for any thread count.
        let mut keys: Vec<(bool, u32, u64, u32)> = ps
            .par_iter()
            .enumerate()
            .map(|(i, p)| (p.status != Status::Airborne, p.hint, p.id, i as u32))
            .collect();
        keys.par_sort_unstable();
        let order = keys;
        self.state.parcels = order.par_iter().map(|k| ps[k.3 as usize].clone()).collect();
        if !self.state.histories.is_empty() {
            let h = &self.state.histories;
            self.state.histories = order.par_iter().map(|k| h[k.3 as usize].clone()).collect();
        }
        if !self.state.extras.is_empty() {
            let e = &self.state.extras;
            self.state.extras = order.par_iter().map(|k| e[k.3 as usize].clone()).collect();
        }
        self.state.live_end = self.state.parcels.iter().take_while(|p| p.status == Status::Airborne).count();
    }

    /// Advances every airborne parcel by one step.
    pub fn step(&mut self) -> Result<(), TrackError> {
        let every = self.settings.resort_interval as u64;
        if every > 0 && self.state.step % every == 0 {
            self.sort_parcels();
        }
        let live = self.state.live_end.min(self.state.parcels.len());
        let n_chunks = live.div_ceil(CHUNK);
        if self.events.len() < n_chunks {
            self.events.resize_with(n_chunks, Vec::new);
            self.errors.resize_with(n_chunks, || None);
        }
        let ctx = Ctx {
            field: &self.field,
            model: &self.model,
            bodies: &self.bodies,
            s: &self.settings,
            t: self.state.time,
            dt: self.settings.dt,
            need_grad: self.model.needs_gradient(),
        };
        let step = self.state.step;
        let events = &mut self.events[..n_chunks];
        let errors = &mut self.errors[..n_chunks];
        let st = &mut self.state;
        // One loop per combination of side arrays (rayon's zip needs them all present).
        macro_rules! chunks {
            ($extras:expr, $hist:expr, $body:expr) => {
                st.parcels[..live]
                    .par_chunks_mut(CHUNK)
                    .zip($extras)
                    .zip($hist)
                    .zip(events.par_iter_mut())
                    .zip(errors.par_iter_mut())
                    .for_each(|((((chunk, ex), hi), ev), err)| {
                        ev.clear();
                        *err = None;
                        #[allow(clippy::redundant_closure_call)]
                        ($body)(chunk, ex, hi, ev, err);
                    })
            };
        }
        fn run<F: FlowField>(
            chunk: &mut [Parcel],
            mut ex: Option<&mut [ParcelExtra]>,
            mut hi: Option<&mut [History]>,
            ev: &mut Vec<Event>,
            err: &mut Option<TrackError>,
            ctx: &Ctx<F>,
            step: u64,
        ) {
            for (i, p) in chunk.iter_mut().enumerate() {
                let e = ex.as_deref_mut().map(|x| &mut x[i]);
                let h = hi.as_deref_mut().map(|x| &mut x[i]);
                if let Some(x) = advance(p, e, h, ctx, ev, step) {
                    err.get_or_insert(x);
                }
            }
        }
        let none_e = || (0..n_chunks).into_par_iter().map(|_| None::<&mut [ParcelExtra]>);
        let none_h = || (0..n_chunks).into_par_iter().map(|_| None::<&mut [History]>);
        match (st.extras.is_empty(), st.histories.is_empty()) {
            (true, true) => chunks!(none_e(), none_h(), |c, e, h, v, r| run(c, e, h, v, r, &ctx, step)),
            (false, true) => {
                chunks!(st.extras[..live].par_chunks_mut(CHUNK).map(Some), none_h(), |c, e, h, v, r| run(
                    c, e, h, v, r, &ctx, step
                ))
            }
            (true, false) => {
                chunks!(none_e(), st.histories[..live].par_chunks_mut(CHUNK).map(Some), |c, e, h, v, r| run(
                    c, e, h, v, r, &ctx, step
                ))
            }
            (false, false) => chunks!(
                st.extras[..live].par_chunks_mut(CHUNK).map(Some),
                st.histories[..live].par_chunks_mut(CHUNK).map(Some),
                |c, e, h, v, r| run(c, e, h, v, r, &ctx, step)
            ),
        }
        if let Some(e) = self.errors[..n_chunks].iter_mut().find_map(|e| e.take()) {
            return Err(e);
        }
        for ev in &self.events[..n_chunks] {
            for e in ev {
                let b = &mut self.state.balance;
                match e {
                    Event::Exit(m) => {
                        b.escaped.add(*m);
                        b.n_escaped += 1;
                    }
                    Event::Impact(i) => {
                        self.state.deposits[i.body as usize].record(i);
                        match i.outcome {
                            ImpactOutcome::Stuck => {
                                b.deposited.add(i.mass);
                                b.n_deposited += 1;
                            }
                            ImpactOutcome::Escaped => {
                                b.escaped.add(i.mass);
                                b.n_escaped += 1;
                            }
                            ImpactOutcome::Bounced => {}
                        }
                    }
                }
            }
        }
        self.state.step += 1;
        self.state.time = self.state.step as f64 * self.settings.dt;
        Ok(())
    }

    /// Number of airborne parcels.
    pub fn airborne(&self) -> usize {
        self.state.parcels.iter().filter(|p| p.status == Status::Airborne).count()
    }

    /// Exact airborne mass \[kg\].
    pub fn airborne_mass(&self) -> ExactSum {
        let mut s = ExactSum::new();
        for p in &self.state.parcels {
            if p.status == Status::Airborne {
                s.add(p.mass());
            }
        }
        s
    }

    /// (injected, deposited + escaped + airborne) as exactly rounded sums; equal bit for bit when the
    /// balance closes.
    pub fn mass_balance(&self) -> (f64, f64) {
        let b = &self.state.balance;
        let mut rhs = b.deposited.clone();
        rhs.merge(&b.escaped);
        rhs.merge(&self.airborne_mass());
        (b.injected.value(), rhs.value())
    }
}

/// First hit of the segment a → b with any body: (fraction, body, triangle).
#[inline]
fn first_hit(bodies: &[Body], a: Vec3, b: Vec3) -> Option<(f64, usize, u32)> {
    let mut best: Option<(f64, usize, u32)> = None;
    for (k, body) in bodies.iter().enumerate() {
        if let Some((s, t)) = body.bvh.segment_first_hit(&body.mesh, a, b) {
            if best.is_none_or(|(bs, _, _)| s < bs) {
                best = Some((s, k, t));
            }
        }
    }
    best
}

/// Wall-bounded lift per unit mass on a parcel at `x` (zero farther than 4 d from every body, where the
/// BVH query ends at the root box of each body).
#[inline]
pub fn wall_lift(bodies: &[Body], s: &WallLiftSettings, fluid: &Fluid, x: Vec3, d: f64, rho_p: f64) -> Vec3 {
    let Some(w) = walls::nearest_wall(bodies, x, WALL_LIFT_RANGE_DIAMETERS * d) else {
        return Vec3::ZERO;
    };
    let u_star = match s.friction_velocity {
        Some(u) => u,
        None => friction_velocity(bodies[w.body].wall_shear[w.triangle as usize], fluid.density),
    };
    wall_lift_acceleration(s, fluid, d, rho_p, w.distance, u_star) * w.away
}

/// Advances one parcel by one step. Returns an error for a non-finite state.
#[inline]
fn advance<F: FlowField>(
    p: &mut Parcel,
    mut extra: Option<&mut ParcelExtra>,
    hist: Option<&mut History>,
    ctx: &Ctx<F>,
    events: &mut Vec<Event>,
    step: u64,
) -> Option<TrackError> {
    if p.status != Status::Airborne {
        return None;
    }
    let dt = ctx.dt;
    let Some(s) = ctx.field.sample(p.pos, ctx.t, &mut p.hint, ctx.need_grad) else {
        p.status = Status::Escaped;
        events.push(Event::Exit(p.mass()));
        return None;
    };
    let model = ctx.model;
    let (d, rho) = (p.diameter, p.density);
    let mut u = s.u;
    if let (Some(disp), Some(x)) = (&ctx.s.dispersion, extra.as_deref_mut()) {
        let slip = (s.u - p.vel).length();
        let tau = model.switches.drag.relaxation_time(&model.fluid, d, rho, slip);
        u += disp.fluctuation(&mut x.eddy, &mut x.rng, s.k, s.eps, tau, slip, dt);
    }
    let fl = FluidLocal { u, grad: s.grad, du_dt: s.du_dt };
    let spin = extra.as_deref().map(|x| x.spin).unwrap_or(Vec3::ZERO);
    let f = model.evaluate(d, rho, p.vel, spin, &fl);
    let mut inertia = f.inertia;
    let mut a = f.accel;
    if let Some(wl) = &model.switches.wall_lift {
        a += wall_lift(ctx.bodies, wl, &model.fluid, p.pos, d, rho);
    }
    if let (Some(h), Some(bs)) = (hist, model.switches.basset) {
        let w = u - p.vel;
        let kb0 = basset_coefficient(model.fluid.density, model.fluid.viscosity, rho, d);
        let ch6 = if bs.odar_hamilton {
            let dslip = (w.length() - h.last().length()) / dt;
            odar_hamilton(acceleration_number(w.length(), d, dslip)) / 6.0
        } else {
            1.0
        };
        let kb = kb0 * ch6;
        let du = u - h.u_last;
        a += kb * (h.explicit_integral(dt, bs.reeks_mckee) + 2.0 * du / dt.sqrt());
        inertia += 2.0 * kb * dt.sqrt();
        let tau = f.tau * inertia;
        let (x1, v1) = exponential_update(p.pos, p.vel, u, tau, a / inertia, dt);
        h.push(u - v1, dt);
        h.u_last = u;
        return finish(p, extra, x1, v1, f.spin_accel, &fl, ctx, events, step);
    }
    let (x1, v1) = exponential_update(p.pos, p.vel, u, f.tau * inertia, a / inertia, dt);
    finish(p, extra, x1, v1, f.spin_accel, &fl, ctx, events, step)
}

/// Spin update, wall hits and domain exit after the free-flight update to (x1, v1).
#[allow(clippy::too_many_arguments)]
#[inline]
fn finish<F: FlowField>(
    p: &mut Parcel,
    extra: Option<&mut ParcelExtra>,
    x1: Vec3,
    v1: Vec3,
    spin_accel: Vec3,
    fl: &FluidLocal,
    ctx: &Ctx<F>,
    events: &mut Vec<Event>,
    step: u64,
) -> Option<TrackError> {
    let dt = ctx.dt;
    if let (Some(_), Some(x)) = (ctx.model.switches.rotational_torque, extra) {
        let half_omega = 0.5 * fl.vorticity();
        let rel = x.spin - half_omega;
        let r = rel.length();
        if r > 0.0 {
            let rate = spin_accel.length() / r;
            x.spin = half_omega + rel * (-rate * dt).exp();
        }
    }
    let (x0, v0) = (p.pos, p.vel);
    let (mut start, mut end, mut vel) = (x0, x1, v1);
    let mut remaining = 1.0;
    let mut bounces = 0;
    while !ctx.bodies.is_empty() {
        let Some((sf, bk, tri)) = first_hit(ctx.bodies, start, end) else { break };
        let body = &ctx.bodies[bk];
        let hit = start + sf * (end - start);
        let mut n = body.mesh.normal(tri as usize);
        if (end - start).dot(n) > 0.0 {
            n = -n;
        }
        // Velocity at the impact: linear between the step's end points (free flight after a bounce).
        let v_imp = if bounces == 0 { v0 + sf * (v1 - v0) } else { vel };
        let v_n = (-v_imp.dot(n)).max(0.0);
        let v_t = (v_imp - v_imp.dot(n) * n).length();
        let outcome = body.rule.outcome(p.diameter, v_n, v_t, body.wall_shear[tri as usize]);
        let mut impact = Impact {
            body: bk as u16,
            triangle: tri,
            v_n,
            v_t,
            count: p.count,
            mass: p.mass(),
            outcome: ImpactOutcome::Bounced,
        };
        match outcome {
            Outcome::Stick => {
                impact.outcome = ImpactOutcome::Stuck;
                events.push(Event::Impact(impact));
                p.pos = hit;
                p.vel = Vec3::ZERO;
                p.status = Status::Deposited;
                return None;
            }
            Outcome::Escape => {
                impact.outcome = ImpactOutcome::Escaped;
                events.push(Event::Impact(impact));
                p.pos = hit;
                p.status = Status::Escaped;
                return None;
            }
            Outcome::Bounce(r) => {
                events.push(Event::Impact(impact));
                vel = reflect(v_imp, n, r);
                remaining *= 1.0 - sf;
                let eps = 1e-9 * (1.0 + hit.abs().max_element());
                start = hit + eps * n;
                end = start + vel * (remaining * dt);
                bounces += 1;
                if bounces >= ctx.s.max_bounces {
                    end = start;
                    break;
                }
            }
        }
    }
    p.pos = end;
    p.vel = vel;
    if !(spatter_core::math::is_finite(p.pos) && spatter_core::math::is_finite(p.vel)) {
        return Some(TrackError::BlowUp {
            id: p.id,
            step,
            time: ctx.t,
            cause: format!(
                "non-finite position or velocity (from x = {x0}, v = {v0}); check dt against the particle \
                 relaxation time and the flow field values"
            ),
        });
    }
    if ctx.s.domain.is_some_and(|d| !d.contains(p.pos)) {
        p.status = Status::Escaped;
        events.push(Event::Exit(p.mass()));
    }
    None
}

#[cfg(test)]
mod tests;
