//! Running a `cfd_dem` scenario: build the flow and the DEM scene, step them together with
//! [`Coupled`], write fields, particles, series, probes and pictures; checkpoint on a stop request and
//! resume bit for bit.
//!
//! Outputs in the run folder:
//!
//! * `fields.pvd` + `fields/fields_NNNNN.vtr` — the fluid (superficial velocity, pressure, solid flags,
//!   void fraction, momentum source from the particles) and `particles.pvd` + `particles/*.vtu` — the
//!   spheres, both every `output.field_interval_s` and at the end, at the same times;
//! * `series.csv` — every `output.sample_interval_s`: pressure drop, bed height, particle and fluid
//!   momentum, the exchanged force and the momentum balance of the last coupling step;
//! * `probes.csv` — fluid velocity and pressure at each probe, at the same times;
//! * with the DEM scene's `[dem.output]`: `events.csv` and `trajectories.csv` (read after every DEM
//!   step, through the `dem` kind's writers) and `<wall>_wall.pvd` + `walls/<wall>_NNNNN.vtu` for the
//!   mesh walls at the field snapshots;
//! * `speed.png`, `void_fraction.png` — the fluid speed and the void fraction on a planar cut at the end;
//!   `pressure_drop.png` — the pressure drop and the bed height over time;
//! * `log.txt`: set-up, a line per snapshot with the momentum balance, the time split at the end.

use super::config::CfdDemConfig;
use super::{Coupled, CouplingError, CouplingTimes};
use crate::cfd::run::{cut_png, io_at, max_speed};
use crate::cfd::{build_domain, FlowDomain, FlowRunError};
use crate::dem_scene::events::EventLog;
use crate::dem_scene::{
    inject, mesh_artifacts, mesh_series, record_step, setup, summarize_records, time_step_warnings,
    trajectory_series, with_law, write_events, write_mesh_snapshots, WithLaw,
};
use serde::{Deserialize, Serialize};
use spatter_cfd::output::{probe, speed_slice, to_vtr};
use spatter_cfd::Flow;
use spatter_core::check::{Checker, Invalid};
use spatter_core::control::Finished;
use spatter_core::Vec3;
use spatter_dem::contact::ContactLaw;
use spatter_dem::error::DemError;
use spatter_dem::insertion::InjectorState;
use spatter_dem::output::write_particles;
use spatter_dem::sim::{SimState, Simulation};
use spatter_io::csv::CsvSeries;
use spatter_io::plot::Chart;
use spatter_io::pvd::PvdSeries;
use spatter_io::run::{RunContext, RunSummary};
use std::path::Path;
use std::time::Instant;

/// Why a coupled run failed.
#[derive(Debug, thiserror::Error)]
pub enum CfdDemError {
    #[error("invalid cfd_dem scenario: {}", .0.iter().map(|e| format!("{}: {}", e.key, e.message)).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Invalid>),
    #[error("{0}")]
    Setup(String),
    #[error("fluid: {0}")]
    Flow(#[from] FlowRunError),
    #[error("dem: {0}")]
    Dem(#[from] DemError),
    #[error(transparent)]
    Coupling(#[from] CouplingError),
    #[error(transparent)]
    Checkpoint(#[from] spatter_io::checkpoint::CheckpointError),
}

impl From<spatter_cfd::FlowError> for CfdDemError {
    fn from(e: spatter_cfd::FlowError) -> Self {
        CfdDemError::Flow(FlowRunError::Flow(e))
    }
}

/// Runs the scenario in `ctx` (see the module documentation for the files written).
pub fn run(cfg: &CfdDemConfig, ctx: &RunContext) -> Result<RunSummary, CfdDemError> {
    Checker::run(cfg, None).map_err(CfdDemError::Invalid)?;
    let flow = build_domain(&FlowDomain {
        fluid: &cfg.fluid,
        grid: &cfg.grid,
        boundaries: &cfg.boundaries,
        solids: &cfg.solids,
        turbulence: &cfg.turbulence,
        numerics: &cfg.numerics,
    })?;
    for (i, p) in cfg.output.probes.iter().enumerate() {
        if probe(&flow, p.at_m).is_none() {
            return Err(CfdDemError::Setup(format!(
                "output.probes[{i}] `{}` at {:?} m lies outside the grid or inside a solid",
                p.name, p.at_m
            )));
        }
    }
    with_law(&cfg.dem, Driver { cfg, ctx, flow })?
}

struct Driver<'a> {
    cfg: &'a CfdDemConfig,
    ctx: &'a RunContext<'a>,
    flow: Flow,
}

impl WithLaw for Driver<'_> {
    type Output = Result<RunSummary, CfdDemError>;
    fn with<L: ContactLaw>(self, law: L, built: setup::Built) -> Result<Self::Output, DemError> {
        Ok(drive(self.cfg, self.ctx, self.flow, law, built))
    }
}

/// Everything a resumed run needs besides the configuration.
#[derive(Serialize, Deserialize)]
struct RunState<S> {
    sim: SimState<S>,
    flow: spatter_cfd::State,
    injectors: Vec<InjectorState>,
    next_field: f64,
    field_count: u32,
    next_sample: f64,
    series_bytes: u64,
    probes_bytes: u64,
    coupling_steps: u64,
    /// Largest relative momentum mismatch of any coupling step so far.
    max_mismatch: f64,
    /// The last coupling step's report (for the series rows).
    last: super::ExchangeReport,
    last_courant: f64,
    last_iterations: usize,
    max_courant: f64,
    pressure_iterations: u64,
    times: CouplingTimes,
    wall_seconds: f64,
    warnings: Vec<String>,
    /// The DEM scene's event log (empty without `[dem.output.events]`).
    events: EventLog,
    /// Bytes written to `trajectories.csv` (0 when not written).
    trajectories_bytes: u64,
}

const SERIES: [&str; 20] = [
    "t_s",
    "coupling_step",
    "particles",
    "pressure_drop_Pa",
    "bed_height_m",
    "particle_momentum_x_kg_m_s",
    "particle_momentum_y_kg_m_s",
    "particle_momentum_z_kg_m_s",
    "fluid_momentum_x_kg_m_s",
    "fluid_momentum_y_kg_m_s",
    "fluid_momentum_z_kg_m_s",
    "force_on_fluid_x_N",
    "force_on_fluid_y_N",
    "force_on_fluid_z_N",
    "momentum_mismatch",
    "alpha_min",
    "particle_kinetic_energy_J",
    "max_fluid_speed_m_s",
    "courant",
    "pressure_iterations",
];

/// The axis gravity acts along (largest |g| component; z without gravity) and whether it points to the
/// axis's lower end.
fn gravity_axis(g: Vec3) -> (usize, bool) {
    let a = g.to_array();
    if g.length() == 0.0 {
        return (2, true);
    }
    let k = (0..3).max_by(|&i, &j| a[i].abs().total_cmp(&a[j].abs())).unwrap_or(2);
    (k, a[k] <= 0.0)
}

/// Area-weighted mean pressure of the fluid cells of interior layer `layer` normal to axis `a` \[Pa\].
fn layer_pressure(flow: &Flow, a: usize, layer: usize) -> f64 {
    let l = flow.grid.layout;
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let (mut sum, mut area) = (0.0, 0.0);
    for j in 0..l.n[c] {
        for i in 0..l.n[b] {
            let mut q = [0; 3];
            q[a] = layer;
            q[b] = i;
            q[c] = j;
            if flow.blocked[l.cell(q[0], q[1], q[2])] {
                continue;
            }
            let w = flow.grid.axes[b].width(i) * flow.grid.axes[c].width(j);
            sum += w * flow.cell_pressure(q[0], q[1], q[2]);
            area += w;
        }
    }
    if area > 0.0 {
        sum / area
    } else {
        0.0
    }
}

/// The pressure drop across the grid along gravity \[Pa\]: mean pressure of the bottom cell layer (the
/// end gravity points to) minus that of the top layer, plus the spheres' force that boundary faces carry
/// (`on_boundaries`, \[N\], from the last exchange) along gravity per cross-section area — the force on
/// the fluid between the bottom face and the first layer's centre, so that the sum is the drop from face to
/// face. The solver's pressure excludes the hydrostatic part, so for a fluidised bed this is the bed's
/// weight less buoyancy per unit area.
pub(super) fn pressure_drop(flow: &Flow, g: Vec3, on_boundaries: Vec3) -> f64 {
    let (a, down_is_low) = gravity_axis(g);
    let n = flow.grid.layout.n[a];
    let (lo, hi) = (layer_pressure(flow, a, 0), layer_pressure(flow, a, n - 1));
    let (b, c) = ((a + 1) % 3, (a + 2) % 3);
    let ax = &flow.grid.axes;
    let section = (ax[b].hi() - ax[b].lo()) * (ax[c].hi() - ax[c].lo());
    let down = if down_is_low { -1.0 } else { 1.0 };
    let carried = down * on_boundaries.to_array()[a] / section;
    carried + if down_is_low { lo - hi } else { hi - lo }
}

/// Twice the volume-weighted mean height of the sphere centres above the grid's bottom along gravity
/// \[m\] (the height of a uniform bed); 0 without spheres.
fn bed_height<L: ContactLaw>(sim: &Simulation<L>, flow: &Flow) -> f64 {
    let (a, down_is_low) = gravity_axis(sim.gravity);
    let ax = &flow.grid.axes[a];
    let p = &sim.particles;
    let (mut sum, mut vol) = (0.0, 0.0);
    for i in 0..p.len() {
        let v = p.radius[i].powi(3);
        let x = p.pos[i].to_array()[a];
        let h = if down_is_low { x - ax.lo() } else { ax.hi() - x };
        sum += v * h;
        vol += v;
    }
    if vol > 0.0 {
        2.0 * sum / vol
    } else {
        0.0
    }
}

/// Momentum of the moving spheres \[kg m/s\] and their kinetic energy \[J\] (frozen ones left out).
fn particle_momentum<L: ContactLaw>(sim: &Simulation<L>) -> (Vec3, f64) {
    let p = &sim.particles;
    let (mut m, mut e) = (Vec3::ZERO, 0.0);
    for i in 0..p.len() {
        if p.inv_mass[i] > 0.0 {
            let mass = 1.0 / p.inv_mass[i];
            m += mass * p.vel[i];
            e += 0.5 * mass * p.vel[i].length_squared();
        }
    }
    (m, e)
}

/// Momentum of the fluid, Σ ρ U V over the fluid cells with the cell-centred superficial velocity
/// \[kg m/s\].
fn fluid_momentum(flow: &Flow) -> Vec3 {
    let l = flow.grid.layout;
    let mut m = Vec3::ZERO;
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            for i in 0..l.n[0] {
                if !flow.blocked[l.cell(i, j, k)] {
                    m += flow.grid.volume([
                        i + spatter_cfd::grid::GHOST,
                        j + spatter_cfd::grid::GHOST,
                        k + spatter_cfd::grid::GHOST,
                    ]) * Vec3::from(flow.cell_velocity(i, j, k));
                }
            }
        }
    }
    flow.fluid.density * m
}

fn probe_columns(cfg: &CfdDemConfig) -> Vec<String> {
    let mut c = vec!["t_s".to_owned()];
    for p in &cfg.output.probes {
        for q in ["ux_m_s", "uy_m_s", "uz_m_s", "p_Pa"] {
            c.push(format!("{}_{q}", p.name));
        }
    }
    c
}

fn probe_row(cfg: &CfdDemConfig, flow: &Flow) -> Vec<Option<f64>> {
    let mut row = vec![Some(flow.state.t)];
    for p in &cfg.output.probes {
        match probe(flow, p.at_m) {
            Some((u, pr)) => row.extend([u[0], u[1], u[2], pr].map(Some)),
            None => row.extend([None; 4]),
        }
    }
    row
}

fn dem_io(path: &Path) -> impl Fn(std::io::Error) -> CfdDemError + '_ {
    move |e| CfdDemError::Flow(FlowRunError::Io(format!("{}: {e}", path.display())))
}

fn drive<L: ContactLaw>(
    cfg: &CfdDemConfig,
    ctx: &RunContext,
    flow: Flow,
    law: L,
    built: setup::Built,
) -> Result<RunSummary, CfdDemError> {
    let dir = ctx.dir;
    let ckpt = dir.checkpoint_path();
    let series_path = dir.path("series.csv");
    let probes_path = dir.path("probes.csv");
    let fields_pvd = dir.path("fields.pvd");
    let particles_pvd = dir.path("particles.pvd");
    let session = Instant::now();
    let pcols = probe_columns(cfg);
    let pcols: Vec<&str> = pcols.iter().map(String::as_str).collect();
    let dem_cfg = &cfg.dem;
    let mut sim = crate::dem_scene::simulation(law, built, dem_cfg);
    sim.set_impact_recording(dem_cfg.output.events.is_some());
    let mut injectors = setup::injectors(dem_cfg, sim.templates())?;
    let resumed: Option<RunState<L::State>> =
        if ctx.resume && ckpt.exists() { Some(ctx.load_checkpoint()?) } else { None };
    let mut flow = flow;
    let (mut st, mut series, mut probes, mut fields, mut particles, mut trajectories, mut meshes) =
        match resumed {
            Some(mut st) => {
                sim.restore(std::mem::replace(&mut st.sim, sim.state()))
                    .map_err(|e| CfdDemError::Dem(DemError::Resume(e)))?;
                flow.restore(st.flow.clone())?;
                if st.injectors.len() != injectors.len() {
                    return Err(CfdDemError::Dem(DemError::Resume("the number of injectors changed".into())));
                }
                for (slot, state) in injectors.iter_mut().zip(&st.injectors) {
                    slot.0.state = state.clone();
                }
                let series =
                    CsvSeries::resume(&series_path, &SERIES, st.series_bytes).map_err(io_at(&series_path))?;
                let probes =
                    CsvSeries::resume(&probes_path, &pcols, st.probes_bytes).map_err(io_at(&probes_path))?;
                let t = st.flow.t;
                let mut fields = PvdSeries::load_or_new(&fields_pvd).map_err(io_at(&fields_pvd))?;
                fields.truncate_after(t).map_err(io_at(&fields_pvd))?;
                let mut particles = PvdSeries::load_or_new(&particles_pvd).map_err(io_at(&particles_pvd))?;
                particles.truncate_after(t).map_err(io_at(&particles_pvd))?;
                let trajectories = trajectory_series(dem_cfg, dir, Some(st.trajectories_bytes))?;
                let meshes = mesh_series(&sim, dir, Some(t), dem_cfg.output.mesh_vtu)?;
                tracing::info!("resumed at t = {t:.6} s, coupling step {}", st.coupling_steps);
                (st, series, probes, fields, particles, trajectories, meshes)
            }
            None => {
                let initial = setup::initial_particles(dem_cfg, &sim.walls, sim.templates())?;
                for p in initial.spheres {
                    sim.add_particle(p);
                }
                for (template, material, body) in initial.bodies {
                    sim.add_clump(template, material, body)?;
                }
                let warnings = time_step_warnings(dem_cfg, &sim);
                for w in &warnings {
                    tracing::warn!("{w}");
                }
                let l = flow.grid.layout;
                tracing::info!(
                "cfd_dem {}: grid {} × {} × {}, ρ_f = {} kg/m³, ν = {:.4e} m²/s; {} spheres; DEM step {:e} s, \
                 {} DEM steps per fluid step; drag {:?}, model {:?}, void fraction {:?}; {} thread(s)",
                cfg.title,
                l.n[0],
                l.n[1],
                l.n[2],
                cfg.fluid.density_kg_m3,
                cfg.fluid.kinematic_viscosity_m2_s,
                sim.particles.len(),
                dem_cfg.dt_s,
                cfg.coupling.dem_steps_per_fluid_step,
                cfg.coupling.forces.drag,
                cfg.coupling.model,
                cfg.coupling.void_fraction,
                rayon::current_num_threads()
            );
                let st = RunState {
                    sim: sim.state(),
                    flow: flow.state.clone(),
                    injectors: Vec::new(),
                    next_field: 0.0,
                    field_count: 0,
                    next_sample: 0.0,
                    series_bytes: 0,
                    probes_bytes: 0,
                    coupling_steps: 0,
                    max_mismatch: 0.0,
                    last: Default::default(),
                    last_courant: 0.0,
                    last_iterations: 0,
                    max_courant: 0.0,
                    pressure_iterations: 0,
                    times: CouplingTimes::default(),
                    wall_seconds: 0.0,
                    warnings,
                    events: EventLog::default(),
                    trajectories_bytes: 0,
                };
                let series = CsvSeries::create(&series_path, &SERIES).map_err(io_at(&series_path))?;
                let probes = CsvSeries::create(&probes_path, &pcols).map_err(io_at(&probes_path))?;
                let trajectories = trajectory_series(dem_cfg, dir, None)?;
                let meshes = mesh_series(&sim, dir, None, dem_cfg.output.mesh_vtu)?;
                (
                    st,
                    series,
                    probes,
                    PvdSeries::new(&fields_pvd),
                    PvdSeries::new(&particles_pvd),
                    trajectories,
                    meshes,
                )
            }
        };
    let mut c = Coupled::new(flow, sim, cfg.coupling)?;
    c.times = st.times;
    // The void fraction and the exchanged forces of the current state, for the first outputs; the DEM's
    // forces are not touched (a coupling step recomputes the exchange from the same state, and a resumed
    // run must find the forces of its checkpoint, whichever exchange it uses).
    c.compute_exchange();
    c.times = st.times;
    let end = dem_cfg.duration_s;
    let total_steps = (end / c.fluid_dt()).round().max(1.0) as u64;
    let eps = 1e-9 * c.fluid_dt();
    let field_dt = cfg.output.field_interval(dem_cfg);
    let sample_dt = cfg.output.sample_interval(dem_cfg);
    let gravity = c.dem.gravity;
    let inject_every: Vec<u64> =
        dem_cfg.inject.iter().map(|j| ((j.interval_s / c.fluid_dt()).round() as u64).max(1)).collect();
    loop {
        let t = c.flow.state.t;
        let done = st.coupling_steps >= total_steps;
        if t >= st.next_sample - eps || done {
            let (pm, ke) = particle_momentum(&c.dem);
            let fm = fluid_momentum(&c.flow);
            let to = st.last.to_fluid;
            let row = [
                t,
                st.coupling_steps as f64,
                c.dem.particles.len() as f64,
                pressure_drop(&c.flow, gravity, st.last.to_boundaries),
                bed_height(&c.dem, &c.flow),
                pm.x,
                pm.y,
                pm.z,
                fm.x,
                fm.y,
                fm.z,
                to.x,
                to.y,
                to.z,
                st.last.relative_mismatch,
                if st.coupling_steps == 0 { c.last.alpha_min } else { st.last.alpha_min },
                ke,
                max_speed(&c.flow),
                st.last_courant,
                st.last_iterations as f64,
            ];
            series.row(&row).map_err(io_at(&series_path))?;
            probes.row_with_gaps(&probe_row(cfg, &c.flow)).map_err(io_at(&probes_path))?;
            while st.next_sample <= t + eps {
                st.next_sample += sample_dt;
            }
        }
        if t >= st.next_field - eps || done {
            write_snapshot(ctx, &mut fields, &mut particles, &c, st.field_count)?;
            if dem_cfg.output.mesh_vtu {
                // Stamped with the fluid's time, as the fields and particles (the DEM's clock, a sum of
                // N Δt_DEM per step, differs from it by round-off).
                write_mesh_snapshots(&c.dem, ctx, &mut meshes, u64::from(st.field_count), t)?;
            }
            st.field_count += 1;
            tracing::info!(
                "t = {t:.6} s, coupling step {}: {} spheres, pressure drop {:.4e} Pa, bed height {:.4e} m, \
                 momentum mismatch {:.2e} (largest so far {:.2e}), smallest α {:.4}",
                st.coupling_steps,
                c.dem.particles.len(),
                pressure_drop(&c.flow, gravity, st.last.to_boundaries),
                bed_height(&c.dem, &c.flow),
                st.last.relative_mismatch,
                st.max_mismatch,
                c.last.alpha_min
            );
            while st.next_field <= t + eps {
                st.next_field += field_dt;
            }
        }
        if done {
            break;
        }
        let stop = ctx.control.stop_requested();
        if stop || ctx.checkpoint_due() {
            series.flush().map_err(io_at(&series_path))?;
            probes.flush().map_err(io_at(&probes_path))?;
            st.series_bytes = series.bytes_written();
            st.probes_bytes = probes.bytes_written();
            if let Some(tr) = trajectories.as_mut() {
                tr.flush().map_err(io_at(&dir.path("trajectories.csv")))?;
                st.trajectories_bytes = tr.bytes_written();
            }
            st.flow = c.flow.state.clone();
            st.sim = c.dem.state();
            st.injectors = injectors.iter().map(|(i, _)| i.state.clone()).collect();
            st.times = c.times;
            let wall_before = st.wall_seconds;
            st.wall_seconds += session.elapsed().as_secs_f64();
            ctx.save_checkpoint(&st)?;
            st.wall_seconds = wall_before;
            write_events(dem_cfg, &c.dem, &st.events, ctx)?;
        }
        if stop {
            tracing::info!(
                "stopped at t = {t:.6} s, coupling step {}; checkpoint written",
                st.coupling_steps
            );
            let mut s = RunSummary::new(Finished::Interrupted);
            s.headline.push(format!("stopped at t = {t:.6} s of {end} s; resume to continue"));
            s.artifacts.push(("checkpoint".into(), ckpt));
            return Ok(s);
        }
        for (k, (inj, region)) in injectors.iter_mut().enumerate() {
            if st.coupling_steps % inject_every[k] == 0 {
                inject(&mut c.dem, inj, region, k);
            }
        }
        let events = &mut st.events;
        let (rep, frep) = c.step_observed(|dem| {
            record_step(dem_cfg, dem, events, trajectories.as_mut(), &spatter_core::comm::SERIAL)
                .map_err(CfdDemError::Dem)
        })?;
        st.coupling_steps += 1;
        st.last = rep;
        st.max_mismatch = st.max_mismatch.max(rep.relative_mismatch);
        st.last_courant = frep.courant;
        st.last_iterations = frep.pressure.iterations;
        st.max_courant = st.max_courant.max(frep.courant);
        st.pressure_iterations += frep.pressure.iterations as u64;
        ctx.control.progress(st.coupling_steps, total_steps);
    }
    series.flush().map_err(io_at(&series_path))?;
    probes.flush().map_err(io_at(&probes_path))?;
    if let Some(tr) = trajectories.as_mut() {
        tr.flush().map_err(io_at(&dir.path("trajectories.csv")))?;
    }
    write_events(dem_cfg, &c.dem, &st.events, ctx)?;
    if ckpt.exists() {
        let _ = std::fs::remove_file(&ckpt);
    }
    st.times = c.times;
    let wall = st.wall_seconds + session.elapsed().as_secs_f64();
    finish(cfg, ctx, &c, &st, wall)
}

/// Cell arrays of the coupling: the void fraction and the momentum source the spheres put into the
/// fluid, ρ a at the cell centre \[N/m³\] (the average of the two face values per component).
pub(super) fn coupling_cells(c: &super::Coupling) -> (Vec<f64>, Vec<[f64; 3]>) {
    let flow = &c.flow;
    let l = flow.grid.layout;
    let rho = flow.fluid.density;
    let mut alpha = Vec::with_capacity(l.cells());
    let mut src = Vec::with_capacity(l.cells());
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            for i in 0..l.n[0] {
                let cell = l.cell(i, j, k);
                alpha.push(c.void_fraction().alpha[cell]);
                src.push(match c.momentum_source() {
                    Some(f) if !flow.blocked[cell] => {
                        [0, 1, 2].map(|a| 0.5 * rho * (f[a][cell] + f[a][cell - l.s[a]]))
                    }
                    _ => [0.0; 3],
                });
            }
        }
    }
    (alpha, src)
}

fn write_snapshot<L: ContactLaw>(
    ctx: &RunContext,
    fields: &mut PvdSeries,
    particles: &mut PvdSeries,
    c: &Coupled<L>,
    n: u32,
) -> Result<(), CfdDemError> {
    let t = c.flow.state.t;
    let rel = format!("fields/fields_{n:05}.vtr");
    let path = ctx.dir.path(&rel);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(io_at(parent))?;
    }
    let (alpha, src) = coupling_cells(&c.coupling);
    to_vtr(&c.flow)
        .map(|v| v.cell_scalar("void_fraction", &alpha).cell_vector("momentum_source_N_m3", &src))
        .and_then(|v| v.write(&path))
        .map_err(io_at(&path))?;
    fields.push(t, &rel).map_err(io_at(&ctx.dir.path("fields.pvd")))?;
    let rel = format!("particles/particles_{n:05}.vtu");
    let path = ctx.dir.path(&rel);
    write_particles(&c.dem, &path).map_err(dem_io(&path))?;
    particles.push(t, &rel).map_err(dem_io(&ctx.dir.path("particles.pvd")))?;
    Ok(())
}

fn finish<L: ContactLaw>(
    cfg: &CfdDemConfig,
    ctx: &RunContext,
    c: &Coupled<L>,
    st: &RunState<L::State>,
    wall: f64,
) -> Result<RunSummary, CfdDemError> {
    let dir = ctx.dir;
    let mut s = RunSummary::new(Finished::Completed);
    let flow = &c.flow;
    let g = &flow.grid;
    let (normal, at) = cfg.output.cut(&cfg.grid);
    let slice = speed_slice(flow, normal, at);
    let names = ["x", "y", "z"];
    let cut = format!("{} = {:.4} m", names[normal], g.axes[normal].centre(slice.layer));
    let prefix = if cfg.title.is_empty() { String::new() } else { format!("{}: ", cfg.title) };
    let (xl, yl) = (format!("{} [m]", names[slice.axes[0]]), format!("{} [m]", names[slice.axes[1]]));
    let png = dir.path("speed.png");
    let title = format!("{prefix}superficial fluid speed at t = {:.4} s, {cut}", flow.state.t);
    cut_png(&png, &slice, &slice.speed, &title, (&xl, &yl), "speed |U| [m/s]")?;
    s.artifacts.push(("fluid speed on the cut".into(), png));
    // The void fraction on the same cut (NaN in solids, drawn grey).
    let l = g.layout;
    let mut alpha = Vec::with_capacity(slice.speed.len());
    for v in 0..l.n[slice.axes[1]] {
        for h in 0..l.n[slice.axes[0]] {
            let mut q = [0; 3];
            q[normal] = slice.layer;
            q[slice.axes[0]] = h;
            q[slice.axes[1]] = v;
            let cell = l.cell(q[0], q[1], q[2]);
            alpha.push(if flow.blocked[cell] { f64::NAN } else { c.void_fraction().alpha[cell] });
        }
    }
    let png = dir.path("void_fraction.png");
    let title = format!("{prefix}void fraction at t = {:.4} s, {cut}", flow.state.t);
    cut_png(&png, &slice, &alpha, &title, (&xl, &yl), "void fraction α [-]")?;
    s.artifacts.push(("void fraction on the cut".into(), png));
    // Pressure drop and bed height over time, read back from the series.
    let series_path = dir.path("series.csv");
    let text = std::fs::read_to_string(&series_path).map_err(io_at(&series_path))?;
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|line| line.split(',').map(|v| v.trim().parse().unwrap_or(f64::NAN)).collect())
        .collect();
    let col = |k: usize| -> Vec<(f64, f64)> {
        rows.iter().filter(|r| r.len() > k).map(|r| (r[0], r[k])).filter(|p| p.1.is_finite()).collect()
    };
    let png = dir.path("pressure_drop.png");
    Chart::new(&format!("{prefix}pressure drop across the grid"), "t [s]", "Δp [Pa]")
        .line("pressure drop (bottom − top)", &col(3))
        .save_png(&png)
        .map_err(io_at(&png))?;
    s.artifacts.push(("pressure drop over time".into(), png));
    let png = dir.path("bed_height.png");
    Chart::new(&format!("{prefix}bed height (twice the mean sphere height)"), "t [s]", "H [m]")
        .line("bed height", &col(4))
        .save_png(&png)
        .map_err(io_at(&png))?;
    s.artifacts.push(("bed height over time".into(), png));
    s.artifacts.push(("fluid fields (ParaView)".into(), dir.path("fields.pvd")));
    s.artifacts.push(("particles (ParaView)".into(), dir.path("particles.pvd")));
    s.artifacts.push(("series".into(), series_path));
    summarize_records(&cfg.dem, &st.events, ctx, &mut s);
    mesh_artifacts(&cfg.dem, &c.dem, ctx, &mut s);
    let dp = pressure_drop(flow, c.dem.gravity, st.last.to_boundaries);
    let h = bed_height(&c.dem, flow);
    let (pm, ke) = particle_momentum(&c.dem);
    let (cost_line, cost_scalars) = st.times.cost_report(st.coupling_steps, st.pressure_iterations);
    s.headline.push(format!(
        "t = {:.6} s after {} coupling steps ({} DEM steps each); {} spheres; pressure drop {dp:.4e} Pa; \
         bed height {h:.4e} m; {wall:.1} s wall time",
        flow.state.t,
        st.coupling_steps,
        cfg.coupling.dem_steps_per_fluid_step,
        c.dem.particles.len()
    ));
    s.headline.push(format!(
        "momentum balance of the exchange: largest relative mismatch {:.2e} over all coupling steps",
        st.max_mismatch
    ));
    s.headline.push(cost_line);
    tracing::info!("{}", s.headline[2]);
    for w in &st.warnings {
        s.headline.push(format!("warning: {w}"));
    }
    let results = [
        ("t_end_s", flow.state.t),
        ("coupling_steps", st.coupling_steps as f64),
        ("particles", c.dem.particles.len() as f64),
        ("pressure_drop_Pa", dp),
        ("bed_height_m", h),
        ("particle_momentum_z_kg_m_s", pm.z),
        ("particle_kinetic_energy_J", ke),
        ("max_momentum_mismatch", st.max_mismatch),
        ("alpha_min", c.last.alpha_min),
        ("max_courant", st.max_courant),
    ];
    for (name, v) in results.into_iter().chain(cost_scalars) {
        s.scalar(name, v);
    }
    for p in &cfg.output.probes {
        if let Some((u, pr)) = probe(flow, p.at_m) {
            for (k, q) in ["ux_m_s", "uy_m_s", "uz_m_s"].iter().enumerate() {
                s.scalar(&format!("probe_{}_{q}", p.name), u[k]);
            }
            s.scalar(&format!("probe_{}_p_Pa", p.name), pr);
        }
    }
    Ok(s)
}
