//! A coupled fluid stepped inside a DEM scene's own loop ([`crate::dem_scene::StepPartner`]): every
//! `dem_steps_per_fluid_step` DEM steps — fewer when the flow's Courant number would exceed
//! [`FLUID_COURANT`] or its diffusion limit (the eddy viscosity of k–ε grows as the flow develops) is
//! shorter ([`Coupling::adaptive_substeps`]) — the coupling step of
//! [`Coupling::exchange_and_advance`] (void fraction, forces on the spheres as their persistent
//! external forces, momentum to the fluid, one fluid step), exactly as [`super::Coupled::step`] orders
//! it; the scene keeps its injection, events,
//! wear records, outputs and checkpoints, and the checkpoint carries the fluid's state. Workflows whose
//! results come from the scene's records (the gravelometer) couple their air this way.
//!
//! Files written beside the scene's: `fields.pvd` + `fields/fields_NNNNN.vtr` (superficial velocity,
//! pressure, solid flags, turbulence, void fraction, momentum source) at every scene output, and
//! `coupling.csv`, one row per scene output with the momentum balance of the last coupling step. Both
//! carry the DEM's time; the fluid is that of the last coupling step, which advanced it by one fluid
//! step ahead of the DEM (the order of [`super::Coupled::step`]).

use super::run::coupling_cells;
use super::{Coupling, CouplingError, CouplingTimes, ExchangeReport};
use crate::cfd::run::io_at;
use crate::cfd::FlowRunError;
use crate::dem_scene::StepPartner;
use serde::{Deserialize, Serialize};
use spatter_cfd::output::to_vtr;
use spatter_dem::contact::ContactLaw;
use spatter_dem::error::DemError;
use spatter_dem::Simulation;
use spatter_io::csv::CsvSeries;
use spatter_io::pvd::PvdSeries;
use spatter_io::run::{RunContext, RunSummary};
use std::time::Instant;

/// Courant number a fluid step may reach before it spans fewer DEM steps.
pub const FLUID_COURANT: f64 = 0.5;

/// Columns of `coupling.csv`.
pub const COUPLING_COLUMNS: [&str; 10] = [
    "t_s",
    "coupling_step",
    "force_on_fluid_x_N",
    "force_on_fluid_y_N",
    "force_on_fluid_z_N",
    "momentum_mismatch",
    "alpha_min",
    "spheres_outside_grid",
    "courant",
    "pressure_iterations",
];

/// What a checkpoint keeps of the coupled fluid.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct FluidState {
    pub flow: spatter_cfd::State,
    pub coupling_steps: u64,
    pub last: ExchangeReport,
    /// Largest relative momentum mismatch of any coupling step so far.
    pub max_mismatch: f64,
    pub max_courant: f64,
    pub last_courant: f64,
    pub last_iterations: usize,
    pub pressure_iterations: u64,
    pub times: CouplingTimes,
    pub field_count: u32,
    pub csv_bytes: u64,
    /// The DEM step at which the next coupling step is due.
    pub next_step: u64,
    /// Fewest DEM steps a fluid step spanned so far.
    pub min_substeps: u32,
}

/// Why a partnered run failed.
#[derive(Debug, thiserror::Error)]
pub enum PartnerError {
    #[error(transparent)]
    Dem(#[from] DemError),
    #[error(transparent)]
    Coupling(#[from] CouplingError),
    #[error("fluid: {0}")]
    Flow(#[from] FlowRunError),
}

/// The coupled fluid of a DEM scene (see the module docs).
pub struct CoupledFluid {
    pub coupling: Coupling,
    pub st: FluidState,
    fields: Option<PvdSeries>,
    csv: Option<CsvSeries>,
    /// Wall clock at the end of the last coupling step: the time until the next one is the DEM's.
    since: Option<Instant>,
}

impl CoupledFluid {
    pub fn new(coupling: Coupling) -> Self {
        let st = FluidState {
            flow: coupling.flow.state.clone(),
            coupling_steps: 0,
            last: ExchangeReport::default(),
            max_mismatch: 0.0,
            max_courant: 0.0,
            last_courant: 0.0,
            last_iterations: 0,
            pressure_iterations: 0,
            times: CouplingTimes::default(),
            field_count: 0,
            csv_bytes: 0,
            next_step: 0,
            min_substeps: u32::MAX,
        };
        CoupledFluid { coupling, st, fields: None, csv: None, since: None }
    }

    fn open(&mut self, ctx: &RunContext, resume: Option<f64>) -> Result<(), PartnerError> {
        let pvd = ctx.dir.path("fields.pvd");
        let csv = ctx.dir.path("coupling.csv");
        let flow_err = |e: FlowRunError| PartnerError::Flow(e);
        match resume {
            Some(t) => {
                let mut f = PvdSeries::load_or_new(&pvd).map_err(io_at(&pvd)).map_err(flow_err)?;
                f.truncate_after(t).map_err(io_at(&pvd)).map_err(flow_err)?;
                self.fields = Some(f);
                self.csv = Some(
                    CsvSeries::resume(&csv, &COUPLING_COLUMNS, self.st.csv_bytes)
                        .map_err(io_at(&csv))
                        .map_err(flow_err)?,
                );
            }
            None => {
                self.fields = Some(PvdSeries::new(&pvd));
                self.csv =
                    Some(CsvSeries::create(&csv, &COUPLING_COLUMNS).map_err(io_at(&csv)).map_err(flow_err)?);
            }
        }
        Ok(())
    }

    fn sync_state(&mut self) {
        self.st.flow = self.coupling.flow.state.clone();
        self.st.times = self.coupling.times;
    }
}

impl StepPartner for CoupledFluid {
    type State = FluidState;
    type Error = PartnerError;

    fn before_step<L: ContactLaw>(&mut self, sim: &mut Simulation<L>) -> Result<(), PartnerError> {
        if sim.step_count() < self.st.next_step {
            return Ok(());
        }
        if let Some(t) = self.since {
            self.coupling.times.dem += t.elapsed().as_secs_f64();
        }
        let n = self.coupling.adaptive_substeps(sim.dt, FLUID_COURANT);
        let (rep, frep) = self.coupling.exchange_and_advance(sim, n)?;
        let s = &mut self.st;
        s.next_step = sim.step_count() + n as u64;
        s.min_substeps = s.min_substeps.min(n);
        s.coupling_steps += 1;
        s.last = rep;
        s.max_mismatch = s.max_mismatch.max(rep.relative_mismatch);
        s.last_courant = frep.courant;
        s.last_iterations = frep.pressure.iterations;
        s.max_courant = s.max_courant.max(frep.courant);
        s.pressure_iterations += frep.pressure.iterations as u64;
        self.since = Some(Instant::now());
        Ok(())
    }

    fn output<L: ContactLaw>(&mut self, sim: &Simulation<L>, ctx: &RunContext) -> Result<(), PartnerError> {
        if self.fields.is_none() {
            self.open(ctx, None)?;
        }
        let c = &self.coupling;
        // Stamped with the DEM's time, as the particles: the fluid is that of its last step, at most one
        // fluid step ahead.
        let t = sim.time();
        let rel = format!("fields/fields_{:05}.vtr", self.st.field_count);
        let path = ctx.dir.path(&rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(io_at(parent))?;
        }
        let (alpha, src) = coupling_cells(c);
        to_vtr(&c.flow)
            .map(|v| v.cell_scalar("void_fraction", &alpha).cell_vector("momentum_source_N_m3", &src))
            .and_then(|v| v.write(&path))
            .map_err(io_at(&path))?;
        if let Some(f) = self.fields.as_mut() {
            f.push(t, &rel).map_err(io_at(&ctx.dir.path("fields.pvd")))?;
        }
        self.st.field_count += 1;
        let s = &self.st;
        let row = [
            t,
            s.coupling_steps as f64,
            s.last.to_fluid.x,
            s.last.to_fluid.y,
            s.last.to_fluid.z,
            s.last.relative_mismatch,
            s.last.alpha_min,
            s.last.outside as f64,
            s.last_courant,
            s.last_iterations as f64,
        ];
        if let Some(csv) = self.csv.as_mut() {
            let p = csv.path().to_owned();
            csv.row(&row).map_err(io_at(&p))?;
        }
        Ok(())
    }

    fn state(&self) -> FluidState {
        let mut st = self.st.clone();
        st.flow = self.coupling.flow.state.clone();
        st.times = self.coupling.times;
        if let Some(csv) = &self.csv {
            st.csv_bytes = csv.bytes_written();
        }
        st
    }

    fn restore(&mut self, state: FluidState, ctx: &RunContext, t: f64) -> Result<(), PartnerError> {
        self.coupling
            .flow
            .restore(state.flow.clone())
            .map_err(|e| PartnerError::Flow(FlowRunError::Flow(e)))?;
        self.coupling.times = state.times;
        self.coupling.last = state.last;
        self.st = state;
        self.open(ctx, Some(t))
    }

    fn finish<L: ContactLaw>(
        &mut self,
        _sim: &Simulation<L>,
        ctx: &RunContext,
        s: &mut RunSummary,
    ) -> Result<(), PartnerError> {
        if let Some(t) = self.since.take() {
            self.coupling.times.dem += t.elapsed().as_secs_f64();
        }
        self.sync_state();
        if let Some(csv) = self.csv.as_mut() {
            let p = csv.path().to_owned();
            csv.flush().map_err(io_at(&p))?;
        }
        let st = &self.st;
        let (cost_line, cost_scalars) = st.times.cost_report(st.coupling_steps, st.pressure_iterations);
        s.headline.push(format!(
            "coupled air: {} coupling steps (at most {} DEM steps each, at fewest {}); momentum balance of the \
             exchange: largest relative mismatch {:.2e}; largest Courant number {:.3}",
            st.coupling_steps,
            self.coupling.options.dem_steps_per_fluid_step,
            st.min_substeps,
            st.max_mismatch,
            st.max_courant
        ));
        s.headline.push(cost_line);
        let counts = [
            ("coupling_steps", st.coupling_steps as f64),
            ("max_momentum_mismatch", st.max_mismatch),
            ("max_courant", st.max_courant),
        ];
        for (name, v) in counts.into_iter().chain(cost_scalars) {
            s.scalar(name, v);
        }
        s.artifacts.push(("fluid fields (ParaView)".into(), ctx.dir.path("fields.pvd")));
        s.artifacts.push(("coupling balance".into(), ctx.dir.path("coupling.csv")));
        Ok(())
    }
}
