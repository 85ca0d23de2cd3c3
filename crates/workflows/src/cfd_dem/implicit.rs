//! The semi-implicit momentum exchange (`coupling.exchange = "semi_implicit"`).
//!
//! Each sphere's exchanged force is linearised at the start of the coupling step as
//! e = β̃ (u − ṽ) + r: a coefficient β̃ \[kg/s\] (the drag law's β at the current slip, over α in model
//! B), the velocity ṽ the drag pulls the fluid towards, and the rest r (the pressure-gradient force of
//! model A, the K-correction's change of the drag), both held for the step. The fluid takes the drag
//! implicitly: minus e is spread onto the velocity nodes with the same weights as the explicit
//! exchange, as k = β̃/(α ρ V) on the diagonal and s = (β̃ ṽ − r)/(ρ V) explicit
//! ([`spatter_cfd::sources::ImplicitSource`]; the `Ksl`/`Us` fields of CFDEM's implicit drag), so a
//! heavily loaded cell relaxes towards the particles' velocity without overshoot. After the fluid step
//! each sphere gets e with the predictor velocity u* the fluid's source used (the node values
//! interpolated with those weights, over α; the share on boundary faces with the fluid velocity at the
//! start of the step): the fluid gains exactly −Σ e Δt, the spheres Σ e Δt.
//!
//! The spheres keep e for the N DEM steps of the coupling step. So that a step long against a sphere's
//! drag relaxation time τ = m/β does not overshoot either, β̃ and ṽ are the step averages of a sphere
//! relaxing in a steady fluid under its other known forces G (gravity, buoyancy, r; contacts not
//! included): m dv/dt = β (u − v) + G has the mean drag over Δt
//! β φ (u − v) + (φ − 1) G, φ = (1 − e^(−x))/x, x = β Δt/m, i.e. β̃ = φ β and ṽ = v + (1 − φ) G/(φ β).
//! The sphere's velocity then moves by (1 − e^(−x)) of its slip per step, never past the fluid, and a
//! sphere at its terminal velocity (β (u − v) = −G) keeps exactly that drag. Frozen spheres and clump
//! members (whose body's mass is not the sphere's) take φ = 1. The force of the DEM's last evaluation
//! is given the new fluid force too, so that velocity Verlet's first half step of the coupling step
//! kicks with it rather than with the previous step's (which would hand the spheres
//! Δt_DEM/2 (F_old − F_new) more than they take from the fluid, and overshoot in stiff cells).

use super::exchange::GridFluid;
use super::{Coupling, ExchangeReport, MomentumModel};
use crate::fluid_forces::FluidSampler;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::Vec3;
use spatter_dem::contact::ContactLaw;
use spatter_dem::Simulation;
use std::time::Instant;

/// How the fluid–particle force is exchanged.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Exchange {
    /// Forces on spheres and fluid from the state at the start of the coupling step, held constant
    /// (the default).
    #[default]
    Explicit,
    /// The drag implicit in the fluid velocity and step-averaged for the spheres (module docs).
    SemiImplicit,
}

/// One sphere's linearised exchange over a coupling step.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Linear {
    /// β̃ \[kg/s\].
    beta: f64,
    /// Void fraction of the sphere's cell.
    alpha: f64,
    /// ṽ \[m/s\].
    v_eff: Vec3,
    /// The explicit rest r \[N\].
    rest: Vec3,
    /// Interstitial fluid velocity at the sphere at the start of the step \[m/s\].
    u_old: Vec3,
    /// Archimedes' −ρ_f V g \[N\] (not exchanged).
    buoyancy: Vec3,
}

/// φ(x) = (1 − e^(−x))/x, the mean of e^(−t β/m) over a step, x = β Δt/m ≥ 0.
fn step_mean(x: f64) -> f64 {
    if x > 1e-12 {
        -(-x).exp_m1() / x
    } else {
        1.0
    }
}

impl Coupling {
    /// Void fraction, the linearised exchange of every sphere of `dem` over a fluid step `dt`, and the
    /// fluid's implicit source from it.
    pub(super) fn prepare_implicit<L: ContactLaw>(&mut self, dem: &Simulation<L>, dt: f64) {
        let t1 = self.sample_fields(&dem.particles.pos, &dem.particles.radius);
        let p = &dem.particles;
        let n = p.len();
        self.linear.resize(n, Linear::default());
        let sampler =
            GridFluid { flow: &self.flow, void_fraction: &self.void_fraction, grad_p: &self.grad_p };
        let opts = &self.options;
        let rho_f = self.flow.fluid.density;
        let g = dem.gravity;
        let t = self.flow.state.t;
        const CHUNK: usize = 1024;
        self.linear
            .par_chunks_mut(CHUNK)
            .zip(self.inside.par_chunks_mut(CHUNK))
            .zip(self.shares.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(ch, ((lin, ins), sh))| {
                for k in 0..lin.len() {
                    let i = ch * CHUNK + k;
                    let Some(f) = sampler.fluid_at(p.pos[i], t, &mut 0) else {
                        ins[k] = false;
                        sh[k] = None;
                        continue;
                    };
                    let r = p.radius[i];
                    let v = p.vel[i];
                    let (drag, pforce) = opts.forces.parts(r, v, &f);
                    let w = f.u - v;
                    let beta = opts.forces.drag.beta(&opts.forces.fluid, 2.0 * r, f.alpha, w.length());
                    // drag − β w is the K-correction's change (exactly 0 without it).
                    let (be, rest) = match opts.model {
                        MomentumModel::A => (beta, drag - beta * w + pforce),
                        MomentumModel::B => (beta / f.alpha, (drag - beta * w) / f.alpha),
                    };
                    let buoyancy = if opts.forces.pressure_force {
                        -(4.0 / 3.0 * std::f64::consts::PI * r * r * r) * rho_f * g
                    } else {
                        Vec3::ZERO
                    };
                    let inv_m = p.inv_mass[i];
                    let phi = if inv_m > 0.0 && !p.is_member(i) { step_mean(be * dt * inv_m) } else { 1.0 };
                    let v_eff = if phi < 1.0 {
                        v + (1.0 - phi) / (phi * be) * (g / inv_m + buoyancy + rest)
                    } else {
                        v
                    };
                    lin[k] = Linear { beta: phi * be, alpha: f.alpha, v_eff, rest, u_old: f.u, buoyancy };
                    ins[k] = true;
                    // Unit force: the shares are the node weights over ρ V, and the boundary fractions.
                    sh[k] = sampler.flow.point_force_shares(p.pos[i].to_array(), [1.0; 3]);
                }
            });
        // The node coefficients, in particle order (the same sums on any thread count).
        if let Some(force) = self.flow.force.as_mut() {
            force.iter_mut().for_each(|a| a.iter_mut().for_each(|v| *v = 0.0));
        }
        let src = self.flow.implicit_source();
        for i in 0..n {
            let (true, Some(sh)) = (self.inside[i], &self.shares[i]) else { continue };
            let lin = &self.linear[i];
            let (v_eff, rest) = (lin.v_eff.to_array(), lin.rest.to_array());
            for &(comp, c, a) in sh.nodes() {
                let comp = comp as usize;
                src.k[comp][c] += a * lin.beta / lin.alpha;
                src.s[comp][c] += a * (lin.beta * v_eff[comp] - rest[comp]);
            }
        }
        self.times.forces += t1.elapsed().as_secs_f64();
    }

    /// After the fluid step: every sphere's force from the predictor velocity the fluid's source used,
    /// written into `dem`'s persistent external forces, and the momentum balance of the step.
    pub(super) fn finish_implicit<L: ContactLaw>(&mut self, dem: &mut Simulation<L>) -> ExchangeReport {
        let t0 = Instant::now();
        let flow = &self.flow;
        let n = self.linear.len();
        self.exchanged.resize(n, Vec3::ZERO);
        self.on_particles.resize(n, Vec3::ZERO);
        self.carried.resize(n, (Vec3::ZERO, 0.0));
        let empty: [Vec<f64>; 3] = Default::default();
        let u_star = flow.implicit.as_ref().map_or(&empty, |s| &s.u_star);
        let rho = flow.fluid.density;
        let l = flow.grid.layout;
        let (lin, inside, shares) = (&self.linear, &self.inside, &self.shares);
        const CHUNK: usize = 1024;
        self.exchanged
            .par_chunks_mut(CHUNK)
            .zip(self.on_particles.par_chunks_mut(CHUNK))
            .zip(self.carried.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(ch, ((ex, on), car))| {
                for k in 0..ex.len() {
                    let i = ch * CHUNK + k;
                    let (true, Some(sh)) = (inside[i], &shares[i]) else {
                        ex[k] = Vec3::ZERO;
                        on[k] = Vec3::ZERO;
                        car[k] = (Vec3::ZERO, 0.0);
                        continue;
                    };
                    let lin = &lin[i];
                    let b = Vec3::from(sh.on_boundaries());
                    let mut u = [0.0; 3];
                    for &(comp, c, a) in sh.nodes() {
                        let comp = comp as usize;
                        u[comp] += a * rho * flow.grid.node_volume(comp, l.coords(c)) * u_star[comp][c];
                    }
                    // The velocity the sphere sees: the fluid nodes' u*/α, the boundary share at the start.
                    let u_seen = Vec3::from(u) / lin.alpha + b * lin.u_old;
                    let e = lin.beta * (u_seen - lin.v_eff) + lin.rest;
                    ex[k] = e;
                    on[k] = e + lin.buoyancy;
                    // The boundaries carry their fraction of minus the force at the start-of-step fluid.
                    let carried = -(b * (lin.beta * (lin.u_old - lin.v_eff) + lin.rest));
                    let scale = lin.beta * (u_seen.length() + lin.v_eff.length()) + lin.rest.length();
                    car[k] = (carried, scale);
                }
            });
        let mut from = Vec3::ZERO;
        let mut on_boundaries = Vec3::ZERO;
        let mut scale = 0.0;
        let mut outside = 0;
        for i in 0..n {
            if !self.inside[i] || self.shares[i].is_none() {
                outside += 1;
                continue;
            }
            from += self.exchanged[i];
            on_boundaries += self.carried[i].0;
            scale += self.carried[i].1;
        }
        // Velocity Verlet's first half step of the next DEM steps kicks with the force of the last
        // evaluation, which holds the previous coupling step's fluid force: it gets the new one, so that
        // the spheres take exactly Σ e Δt_f.
        dem.replace_external_forces(&self.on_particles);
        let to = Vec3::from(flow.total_implicit_force());
        let alpha_min = self.void_fraction.alpha.iter().copied().fold(1.0, f64::min);
        // Near equilibrium both sides are small differences of large terms (s − k u*, β̃ (ũ − ṽ)), so the
        // balance is measured against the size of those terms.
        let rel = (to + on_boundaries + from).length() / from.length().max(scale).max(1e-300);
        self.last = ExchangeReport {
            from_particles: from,
            to_fluid: to,
            to_boundaries: on_boundaries,
            relative_mismatch: rel,
            outside,
            alpha_min,
        };
        self.times.forces += t0.elapsed().as_secs_f64();
        self.last
    }
}
