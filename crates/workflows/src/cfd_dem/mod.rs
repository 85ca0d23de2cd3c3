//! Volume-averaged (unresolved) two-way CFD–DEM coupling: a `spatter-cfd` flow on a Cartesian grid and a
//! DEM simulation exchanging momentum through the void fraction and the fluid forces on the spheres.
//!
//! One coupling step (fluid step Δt_f = N Δt_DEM):
//!
//! 1. **void fraction** α per cell from the spheres ([`void_fraction`]);
//! 2. **forces**: at each sphere the interstitial velocity u = U/α (U the solver's superficial
//!    velocity), ∇p interpolated from the face gradients, α of its cell; the fluid force of
//!    [`FluidForceOptions`] (drag law, K-correction) by the [`MomentumModel`]; the forces are written
//!    into the DEM's persistent external forces and held constant for the N DEM steps;
//! 3. **exchange**: minus the exchanged force of every sphere is spread onto the velocity nodes around
//!    it (the same trilinear stencil the velocity is sampled with) as a body force; the momentum the
//!    fluid receives, Σ ρ V a over the nodes, is compared with the momentum taken from the spheres
//!    ([`ExchangeReport`]);
//! 4. **fluid** step Δt_f (explicit source; with [`Exchange::SemiImplicit`] the drag is implicit in the
//!    fluid velocity and the spheres' forces follow the fluid step, see [`implicit`]);
//! 5. **DEM**: N steps.
//!
//! The fluid solver advances the superficial velocity U = α u with ∇·U = 0 and
//! ρ (∂U/∂t + ∇·(U U)) = −∇p + μ ∇²U − f, f the exchanged force per unit volume: the steady balances of
//! both momentum models are exact (a fixed bed gives Ergun's pressure drop), while the α in the time
//! derivative, in convection (U U/α) and in the continuity equation (∂α/∂t) is neglected — a
//! quasi-static bed approximation, good for fixed and slowly expanding beds, not for fast dense
//! transients (see docs/cfd.md, "CFD–DEM coupling").
//!
//! The solver's pressure p excludes the hydrostatic part ρ_f g·x; its force on a sphere, Archimedes'
//! −ρ_f V g, is added to every sphere and balanced by the hydrostatic pressure, so it is not exchanged.

pub mod config;
pub mod exchange;
pub mod implicit;
pub mod partner;
pub mod run;
#[cfg(test)]
mod tests;
pub mod validation;
pub mod void_fraction;

use crate::fluid_forces::{FluidForceOptions, FluidSampler};
pub use config::CfdDemConfig;
use exchange::{pressure_gradient_nodes, GridFluid};
pub use implicit::Exchange;
use rayon::prelude::*;
pub use run::{run, CfdDemError};
use serde::{Deserialize, Serialize};
use spatter_cfd::reduce::in_pool;
use spatter_cfd::{Flow, FlowError, Mode};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;
use spatter_dem::contact::ContactLaw;
use spatter_dem::{DemError, Simulation};
use std::time::Instant;
pub use void_fraction::{VoidFraction, VoidFractionMethod};

/// Which terms of the fluid–particle force go where (Zhou, Kuang, Chu & Yu 2010, J. Fluid Mech.
/// 661:482–510, "set I" = model A, "set II" = model B; the two of CFDEM®coupling).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MomentumModel {
    /// A sphere feels drag + the dynamic pressure-gradient force −V∇p + buoyancy; the fluid receives
    /// minus drag and pressure-gradient force (at steady state −α∇p balances the drag, the form of the
    /// model-A fluid equation). The default.
    #[default]
    A,
    /// A sphere feels drag/α + buoyancy (no dynamic pressure-gradient force); the fluid receives minus
    /// drag/α (the fluid equation of model B, where −∇p balances the drag/α).
    B,
}

/// Coupling options.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingOptions {
    /// Drag law and K-correction; the fluid's density and viscosity are the flow's.
    #[serde(flatten)]
    pub forces: FluidForceOptions,
    #[serde(default)]
    pub model: MomentumModel,
    /// Explicit (default) or semi-implicit exchange ([`implicit`]).
    #[serde(default)]
    pub exchange: Exchange,
    #[serde(default)]
    pub void_fraction: VoidFractionMethod,
    /// Lower clamp of the void fraction (default 0.3).
    #[serde(default = "default_alpha_min")]
    pub alpha_min: f64,
    /// DEM steps per fluid step (default 10).
    #[serde(default = "default_substeps")]
    pub dem_steps_per_fluid_step: u32,
}

fn default_alpha_min() -> f64 {
    0.3
}
fn default_substeps() -> u32 {
    10
}

impl Default for CouplingOptions {
    fn default() -> Self {
        CouplingOptions {
            forces: FluidForceOptions::default(),
            model: MomentumModel::A,
            exchange: Exchange::Explicit,
            void_fraction: VoidFractionMethod::Divided,
            alpha_min: default_alpha_min(),
            dem_steps_per_fluid_step: default_substeps(),
        }
    }
}

impl Validate for CouplingOptions {
    fn validate(&self, c: &mut Checker) {
        c.nested("k_correction", |c| self.forces.k_correction.validate(c));
        c.in_range("alpha_min", self.alpha_min, 0.0, false, 1.0, false);
        if self.dem_steps_per_fluid_step == 0 {
            c.fail("dem_steps_per_fluid_step", "= 0: give at least 1 DEM step per fluid step");
        }
    }
}

/// The momentum balance of one coupling step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ExchangeReport {
    /// Σ of the exchanged fluid forces on the spheres inside the grid \[N\].
    pub from_particles: Vec3,
    /// Σ ρ V a of the body force the fluid received \[N\].
    pub to_fluid: Vec3,
    /// The part of the spheres' reaction that boundary faces carry (spheres within half a cell of an inlet,
    /// outlet, wall or solid face; [`spatter_cfd::sources::PointForce::on_boundaries`]) \[N\].
    #[serde(default)]
    pub to_boundaries: Vec3,
    /// |to_fluid + to_boundaries + from_particles| / max(|from_particles|, 1e-300).
    pub relative_mismatch: f64,
    /// Spheres outside the grid (no fluid force).
    pub outside: u64,
    /// Smallest void fraction of a fluid cell.
    pub alpha_min: f64,
}

/// Wall time spent in each part of the coupling \[s\].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CouplingTimes {
    pub fluid: f64,
    pub void_fraction: f64,
    pub forces: f64,
    pub dem: f64,
}

impl CouplingTimes {
    /// What a coupled run reports of its cost after `coupling_steps` steps that took `pressure_iterations`
    /// pressure iterations in all: the headline "time per coupling step [ms]: …" and the per-step scalars
    /// (pressure iterations, then seconds of fluid, void fraction, forces and DEM).
    pub fn cost_report(
        &self,
        coupling_steps: u64,
        pressure_iterations: u64,
    ) -> (String, [(&'static str, f64); 5]) {
        let steps = coupling_steps.max(1) as f64;
        let per = |v: f64| 1e3 * v / steps;
        let line = format!(
            "time per coupling step [ms]: fluid {:.3}, void fraction {:.3}, forces {:.3}, DEM {:.3} (total {:.3})",
            per(self.fluid),
            per(self.void_fraction),
            per(self.forces),
            per(self.dem),
            per(self.fluid + self.void_fraction + self.forces + self.dem)
        );
        let scalars = [
            ("pressure_iterations_per_step", pressure_iterations as f64 / steps),
            ("time_fluid_s_per_step", self.fluid / steps),
            ("time_void_fraction_s_per_step", self.void_fraction / steps),
            ("time_forces_s_per_step", self.forces / steps),
            ("time_dem_s_per_step", self.dem / steps),
        ];
        (line, scalars)
    }
}

/// Why a coupled step failed.
#[derive(Debug, thiserror::Error)]
pub enum CouplingError {
    #[error("CFD–DEM coupling needs a Cartesian grid (the axisymmetric mode has no 3D particle cells)")]
    NotCartesian,
    #[error(
        "the fluid step Δt_f = dem_steps_per_fluid_step × DEM step = {dt:e} s exceeds the explicit \
         diffusion limit {limit:e} s of the flow solver (1/(4 ν Σ 1/Δx²), second-order Adams–Bashforth) \
         at t = {t} s; lower dem_steps_per_fluid_step or the DEM time step"
    )]
    FluidStep { dt: f64, limit: f64, t: f64 },
    #[error("fluid: {0}")]
    Flow(#[from] FlowError),
    #[error("DEM: {0}")]
    Dem(#[from] DemError),
}

/// The fluid side of a two-way coupling: the flow, the void fraction and the exchange buffers. It
/// couples to any DEM simulation passed to [`Coupling::exchange`]; [`Coupled`] pairs it with one, and
/// the gravelometer's coupled air steps it inside the DEM scene's own loop
/// ([`partner::CoupledFluid`]), so both run the same coupling step.
pub struct Coupling {
    pub flow: Flow,
    pub options: CouplingOptions,
    void_fraction: VoidFraction,
    grad_p: [Vec<f64>; 3],
    /// Exchanged force per sphere of the current coupling step \[N\].
    exchanged: Vec<Vec3>,
    /// The spheres' forces of the current step \[N\] (exchanged + buoyancy).
    on_particles: Vec<Vec3>,
    inside: Vec<bool>,
    /// The node shares of each sphere's exchanged force (`None`: outside the grid); of a unit force
    /// in the semi-implicit exchange.
    shares: Vec<Option<spatter_cfd::sources::PointForce>>,
    /// Semi-implicit exchange: each sphere's linearised force of the current step.
    linear: Vec<implicit::Linear>,
    /// Semi-implicit exchange: each sphere's force carried by boundary faces \[N\] and the size of its
    /// terms \[N\] (the scale of its momentum balance).
    carried: Vec<(Vec3, f64)>,
    pub times: CouplingTimes,
    pub last: ExchangeReport,
}

/// A flow and a DEM simulation coupled two-way. Dereferences to its [`Coupling`] (`c.flow`, `c.last`).
pub struct Coupled<L: ContactLaw> {
    pub coupling: Coupling,
    pub dem: Simulation<L>,
}

impl<L: ContactLaw> std::ops::Deref for Coupled<L> {
    type Target = Coupling;
    fn deref(&self) -> &Coupling {
        &self.coupling
    }
}

impl<L: ContactLaw> std::ops::DerefMut for Coupled<L> {
    fn deref_mut(&mut self) -> &mut Coupling {
        &mut self.coupling
    }
}

impl Coupling {
    /// The fluid side of a coupling on `flow`; the DEM's gravity is the coupling's (buoyancy −ρ_f V g).
    pub fn new(flow: Flow, mut options: CouplingOptions) -> Result<Self, CouplingError> {
        if flow.grid.mode != Mode::Cartesian {
            return Err(CouplingError::NotCartesian);
        }
        // The flow carries the kinematic viscosity ν, the force laws the dynamic one μ = ρ ν.
        options.forces.fluid = spatter_flow::forces::Fluid {
            density: flow.fluid.density,
            viscosity: flow.fluid.density * flow.fluid.viscosity,
        };
        let void_fraction = VoidFraction::new(&flow.grid, options.void_fraction, options.alpha_min);
        Ok(Coupling {
            flow,
            options,
            void_fraction,
            grad_p: Default::default(),
            exchanged: Vec::new(),
            on_particles: Vec::new(),
            inside: Vec::new(),
            shares: Vec::new(),
            linear: Vec::new(),
            carried: Vec::new(),
            times: CouplingTimes::default(),
            last: ExchangeReport::default(),
        })
    }

    /// The void fraction of the last coupling step.
    pub fn void_fraction(&self) -> &VoidFraction {
        &self.void_fraction
    }

    /// The fluid time step Δt_f = N Δt_DEM \[s\] for a DEM step `dem_dt`.
    pub fn fluid_dt_for(&self, dem_dt: f64) -> f64 {
        self.options.dem_steps_per_fluid_step as f64 * dem_dt
    }

    /// DEM steps of `dem_dt` the next fluid step may span: `dem_steps_per_fluid_step`, or fewer when the
    /// flow's convective limit at Courant number `courant` or its diffusion limit (which moves with the
    /// eddy viscosity of k–ε) is shorter; at least 1.
    pub fn adaptive_substeps(&self, dem_dt: f64, courant: f64) -> u32 {
        let stable = self.flow.stable_dt(courant, f64::INFINITY);
        let n = (stable / dem_dt).floor();
        (n.min(self.options.dem_steps_per_fluid_step as f64).max(1.0)) as u32
    }

    /// Void fraction, forces and exchange at the current state of `dem` (steps 1–3 of a coupling step),
    /// without stepping; the forces on the spheres become `dem`'s persistent external forces. Returns
    /// the momentum balance. This is the explicit exchange; with `exchange = semi_implicit` a coupling
    /// step recomputes every force around its fluid step, so this serves for outputs only.
    pub fn exchange<L: ContactLaw>(&mut self, dem: &mut Simulation<L>) -> ExchangeReport {
        let rep = self.compute_exchange(dem);
        let t1 = Instant::now();
        // The new forces act from the next DEM step's first half-kick on (see
        // `Simulation::replace_external_forces`).
        dem.replace_external_forces(&self.on_particles);
        self.times.forces += t1.elapsed().as_secs_f64();
        rep
    }

    /// [`Coupling::exchange`] without handing the forces to `dem`: the void fraction, the forces on the
    /// spheres (`on_particles`), the fluid's body force and the momentum balance of the current state,
    /// for outputs. A resumed run computes its first outputs this way, so the DEM's forces stay those of
    /// the checkpoint and the run continues bit for bit.
    pub fn compute_exchange<L: ContactLaw>(&mut self, dem: &Simulation<L>) -> ExchangeReport {
        let t1 = self.sample_fields(&dem.particles.pos, &dem.particles.radius);
        let p = &dem.particles;
        let n = p.len();
        self.exchanged.resize(n, Vec3::ZERO);
        self.on_particles.resize(n, Vec3::ZERO);
        let sampler =
            GridFluid { flow: &self.flow, void_fraction: &self.void_fraction, grad_p: &self.grad_p };
        let opts = &self.options;
        let rho_f = self.flow.fluid.density;
        let g = dem.gravity;
        let t = self.flow.state.t;
        const CHUNK: usize = 1024;
        self.exchanged
            .par_chunks_mut(CHUNK)
            .zip(self.on_particles.par_chunks_mut(CHUNK))
            .zip(self.inside.par_chunks_mut(CHUNK))
            .zip(self.shares.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(ch, (((ex, on), ins), sh))| {
                for k in 0..ex.len() {
                    let i = ch * CHUNK + k;
                    let Some(f) = sampler.fluid_at(p.pos[i], t, &mut 0) else {
                        ex[k] = Vec3::ZERO;
                        on[k] = Vec3::ZERO;
                        ins[k] = false;
                        sh[k] = None;
                        continue;
                    };
                    let r = p.radius[i];
                    let (drag, pforce) = opts.forces.parts(r, p.vel[i], &f);
                    let e = match opts.model {
                        MomentumModel::A => drag + pforce,
                        MomentumModel::B => drag / f.alpha,
                    };
                    let buoyancy = if opts.forces.pressure_force {
                        -(4.0 / 3.0 * std::f64::consts::PI * r * r * r) * rho_f * g
                    } else {
                        Vec3::ZERO
                    };
                    ex[k] = e;
                    on[k] = e + buoyancy;
                    ins[k] = true;
                    sh[k] = sampler.flow.point_force_shares(p.pos[i].to_array(), (-e).to_array());
                }
            });
        // Spread onto the fluid in particle order (the shares are computed in parallel above, the
        // scatter is sequential: the same sums on any thread count).
        if let Some(force) = self.flow.force.as_mut() {
            force.iter_mut().for_each(|a| a.iter_mut().for_each(|v| *v = 0.0));
        }
        let mut from = Vec3::ZERO;
        let mut on_boundaries = Vec3::ZERO;
        let mut outside = 0;
        for i in 0..n {
            if !self.inside[i] {
                outside += 1;
                continue;
            }
            match &self.shares[i] {
                Some(sh) => {
                    self.flow.apply_point_force(sh);
                    from += self.exchanged[i];
                    on_boundaries += Vec3::from(sh.on_boundaries());
                }
                None => outside += 1,
            }
        }
        let to = Vec3::from(self.flow.total_body_force());
        let alpha_min = self.void_fraction.alpha.iter().copied().fold(1.0, f64::min);
        let rel = (to + on_boundaries + from).length() / from.length().max(1e-300);
        self.last = ExchangeReport {
            from_particles: from,
            to_fluid: to,
            to_boundaries: on_boundaries,
            relative_mismatch: rel,
            outside,
            alpha_min,
        };
        self.times.forces += t1.elapsed().as_secs_f64();
        self.last
    }

    /// The start of both exchanges: the void fraction of the spheres at `pos` with radii `radius` (its
    /// time added to `times.void_fraction`), the pressure gradient at the velocity nodes, and the
    /// per-sphere buffers sized for them. Returns when the forces' clock starts.
    fn sample_fields(&mut self, pos: &[Vec3], radius: &[f64]) -> Instant {
        let t0 = Instant::now();
        self.void_fraction.update(&self.flow.grid, &self.flow.blocked, pos, radius);
        let t1 = Instant::now();
        self.times.void_fraction += (t1 - t0).as_secs_f64();
        pressure_gradient_nodes(&self.flow, &mut self.grad_p);
        self.inside.resize(pos.len(), false);
        self.shares.resize(pos.len(), None);
        t1
    }

    /// The fluid part of a coupling step spanning `substeps` DEM steps: exchange with `dem`, then one
    /// fluid step of Δt_f = `substeps` × the DEM step (the caller then advances the DEM by as many
    /// steps).
    pub fn exchange_and_advance<L: ContactLaw>(
        &mut self,
        dem: &mut Simulation<L>,
        substeps: u32,
    ) -> Result<(ExchangeReport, spatter_cfd::solver::StepReport), CouplingError> {
        // On a worker thread of the pool: its many short parallel loops then start without a round trip
        // through the scheduler each (spatter_cfd::reduce::in_pool).
        in_pool(|| self.exchange_and_advance_here(dem, substeps))
    }

    fn exchange_and_advance_here<L: ContactLaw>(
        &mut self,
        dem: &mut Simulation<L>,
        substeps: u32,
    ) -> Result<(ExchangeReport, spatter_cfd::solver::StepReport), CouplingError> {
        let dt = substeps as f64 * dem.dt;
        // The fixed fluid step must respect the explicit diffusion limit (with k–ε it moves with ν_t).
        // stable_dt returns 0.9 of the limit.
        let limit = self.flow.stable_dt(f64::INFINITY, f64::INFINITY) / 0.9;
        if dt > limit {
            return Err(CouplingError::FluidStep { dt, limit, t: self.flow.state.t });
        }
        match self.options.exchange {
            Exchange::Explicit => {
                let rep = self.exchange(dem);
                let t0 = Instant::now();
                let frep = self.flow.step(dt)?;
                self.times.fluid += t0.elapsed().as_secs_f64();
                Ok((rep, frep))
            }
            Exchange::SemiImplicit => {
                self.prepare_implicit(dem, dt);
                let t0 = Instant::now();
                let frep = self.flow.step(dt)?;
                self.times.fluid += t0.elapsed().as_secs_f64();
                Ok((self.finish_implicit(dem), frep))
            }
        }
    }

    /// The acceleration \[m/s²\] the spheres put into the fluid at each velocity node at the last
    /// exchange: the explicit body force, or the applied implicit source s − k u* of the last
    /// semi-implicit step (`None` before any exchange).
    pub fn momentum_source(&self) -> Option<&[Vec<f64>; 3]> {
        match (&self.flow.implicit, self.options.exchange) {
            (Some(src), Exchange::SemiImplicit) => Some(&src.applied),
            _ => self.flow.force.as_ref(),
        }
    }
}

impl<L: ContactLaw> Coupled<L> {
    /// Couples `flow` and `dem`; the DEM's gravity is the coupling's (buoyancy −ρ_f V g).
    pub fn new(flow: Flow, dem: Simulation<L>, options: CouplingOptions) -> Result<Self, CouplingError> {
        Ok(Coupled { coupling: Coupling::new(flow, options)?, dem })
    }

    /// The fluid time step Δt_f = N Δt_DEM \[s\].
    pub fn fluid_dt(&self) -> f64 {
        self.coupling.fluid_dt_for(self.dem.dt)
    }

    /// Void fraction, forces and exchange at the current state (steps 1–3 of a coupling step), without
    /// stepping; returns the momentum balance.
    pub fn exchange(&mut self) -> ExchangeReport {
        self.coupling.exchange(&mut self.dem)
    }

    /// The same for outputs only: the DEM's forces are left as they are ([`Coupling::compute_exchange`]).
    pub fn compute_exchange(&mut self) -> ExchangeReport {
        self.coupling.compute_exchange(&self.dem)
    }

    /// One coupling step: exchange, one fluid step of Δt_f, N DEM steps.
    pub fn step(&mut self) -> Result<ExchangeReport, CouplingError> {
        self.step_reporting().map(|(rep, _)| rep)
    }

    /// Like [`Coupled::step`], also returning the fluid step's report (Courant number, pressure solve).
    pub fn step_reporting(
        &mut self,
    ) -> Result<(ExchangeReport, spatter_cfd::solver::StepReport), CouplingError> {
        self.step_observed(|_| Ok(()))
    }

    /// Like [`Coupled::step_reporting`], calling `after_dem_step` with the DEM after each of the N DEM
    /// steps (the scene's event log and trajectories read it there). The steps are the same as without
    /// the observer.
    pub fn step_observed<E: From<CouplingError> + Send>(
        &mut self,
        mut after_dem_step: impl FnMut(&Simulation<L>) -> Result<(), E> + Send,
    ) -> Result<(ExchangeReport, spatter_cfd::solver::StepReport), E> {
        in_pool(|| {
            let n = self.coupling.options.dem_steps_per_fluid_step;
            let out = self.coupling.exchange_and_advance(&mut self.dem, n)?;
            let t1 = Instant::now();
            for _ in 0..n {
                self.dem.step().map_err(CouplingError::from)?;
                after_dem_step(&self.dem)?;
            }
            self.coupling.times.dem += t1.elapsed().as_secs_f64();
            Ok(out)
        })
    }
}
