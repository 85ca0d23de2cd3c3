//! Running a `flow` scenario: build the grid, solids and boundaries, step the solver with an adaptive (or
//! fixed) time step, write fields, series, probes and pictures; checkpoint on a stop request and resume.
//!
//! Outputs in the run folder:
//!
//! * `fields.pvd` + `fields/fields_NNNNN.vtr` — cell velocity, pressure and solid flags every
//!   `output.field_interval_s` and at the end;
//! * `series.csv` — every `output.sample_interval_s`: time, step, Courant number, pressure iterations,
//!   largest speed, kinetic energy, net outflow;
//! * `probes.csv` — velocity and pressure at each probe, at the same times;
//! * `speed.png` — the speed on a planar cut at the end;
//! * with `output.ghia_re`: `centrelines.csv`, `centreline_u.png`, `centreline_v.png` against Ghia, Ghia &
//!   Shin (1982);
//! * `log.txt` (through the program's logging): set-up, a line per field snapshot, the result.
//!
//! A resumed run continues from `checkpoint.bin` and writes the same files, bit for bit, as an
//! uninterrupted one (the solver state, the output clocks and the file lengths are in the checkpoint).

use super::config::{
    BoundariesSpec, CutNormal, FlowConfig, FluidSpec, GridSpec, NumericsSpec, TurbulenceSpec,
};
use serde::{Deserialize, Serialize};
use spatter_cfd::grid::Grid;
use spatter_cfd::output::{axis_names, kinetic_energy, probe, speed_slice, to_vtr, Slice};
use spatter_cfd::pcg::PcgSettings;
use spatter_cfd::{cavity, Boundary, Flow, FlowError, Fluid, Mode, Numerics};
use spatter_core::check::{Checker, Invalid};
use spatter_core::control::Finished;
use spatter_io::csv::{write_table, CsvSeries};
use spatter_io::plot::{field_map_png, Chart, FieldMap};
use spatter_io::pvd::PvdSeries;
use spatter_io::run::{RunContext, RunSummary};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Why a flow run failed.
#[derive(Debug, thiserror::Error)]
pub enum FlowRunError {
    #[error("invalid flow scenario: {}", .0.iter().map(|e| format!("{}: {}", e.key, e.message)).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Invalid>),
    #[error("{0}")]
    Setup(String),
    #[error(transparent)]
    Flow(#[from] FlowError),
    #[error("{0}")]
    Io(String),
    #[error(transparent)]
    Checkpoint(#[from] spatter_io::checkpoint::CheckpointError),
}

pub(crate) fn io_at(path: &Path) -> impl Fn(std::io::Error) -> FlowRunError + '_ {
    move |e| FlowRunError::Io(format!("{}: {e}", path.display()))
}

/// Draws `values` (one per cell of the cut `slice`, row by row) as a colour map into `png`.
pub(crate) fn cut_png(
    png: &Path,
    slice: &Slice,
    values: &[f64],
    title: &str,
    (x_label, y_label): (&str, &str),
    colorbar_label: &str,
) -> Result<(), FlowRunError> {
    let map = FieldMap {
        x_faces: &slice.h_faces,
        y_faces: &slice.v_faces,
        values,
        title,
        x_label,
        y_label,
        colorbar_label,
    };
    field_map_png(png, &map).map_err(io_at(png))
}

/// Builds the flow of a scenario (grid, blocked cells, boundaries, numerics, turbulence, actuator disks),
/// at rest.
pub fn build(cfg: &FlowConfig) -> Result<Flow, FlowRunError> {
    let mut flow = build_domain(&FlowDomain {
        fluid: &cfg.fluid,
        grid: &cfg.grid,
        boundaries: &cfg.boundaries,
        solids: &cfg.solids,
        turbulence: &cfg.turbulence,
        numerics: &cfg.numerics,
    })?;
    for (i, d) in cfg.actuator_disks.iter().enumerate() {
        flow.add_actuator_disk(d).map_err(|e| FlowRunError::Setup(format!("actuator_disks[{i}]: {e}")))?;
    }
    Ok(flow)
}

/// The tables of a scenario that describe the fluid and its domain, shared by the `flow` and `cfd_dem`
/// kinds (same keys, same meaning).
pub struct FlowDomain<'a> {
    pub fluid: &'a FluidSpec,
    pub grid: &'a GridSpec,
    pub boundaries: &'a BoundariesSpec,
    pub solids: &'a [spatter_cfd::solid::Solid],
    pub turbulence: &'a TurbulenceSpec,
    pub numerics: &'a NumericsSpec,
}

/// Builds the flow of `d` (grid, blocked cells, boundaries, numerics, turbulence model), at rest.
pub fn build_domain(d: &FlowDomain) -> Result<Flow, FlowRunError> {
    let g = d.grid;
    let axis = |name: &str, a: &super::config::AxisSpec| {
        a.axis().map_err(|e| FlowRunError::Setup(format!("grid.{name}: {e}")))
    };
    let grid = Grid::new([axis("x", &g.x)?, axis("y", &g.y)?, axis("z", &g.z_axis())?], g.mode)
        .map_err(|e| FlowRunError::Setup(format!("grid: {e}")))?;
    let blocked =
        spatter_cfd::solid::blocked_cells(&grid, d.solids).map_err(|e| FlowRunError::Setup(e.to_string()))?;
    let n = d.numerics;
    let numerics = Numerics {
        convection: n.convection,
        pressure: PcgSettings {
            rtol: n.pressure_tolerance,
            max_iterations: n.pressure_max_iterations,
            ..PcgSettings::default()
        },
        max_courant: n.max_courant,
    };
    let fluid = Fluid { density: d.fluid.density_kg_m3, viscosity: d.fluid.kinematic_viscosity_m2_s };
    let mut flow = Flow::new(grid, fluid, d.boundaries.sides(), blocked, numerics)?;
    if let Some(model) = d.turbulence.k_epsilon() {
        flow.enable_k_epsilon(model);
    }
    Ok(flow)
}

/// Everything a resumed run needs besides the configuration.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct RunState {
    flow: spatter_cfd::State,
    next_field: f64,
    field_count: u32,
    next_sample: f64,
    series_bytes: u64,
    probes_bytes: u64,
    wall_seconds: f64,
    /// Last step: size, Courant number, pressure iterations.
    last_dt: f64,
    last_courant: f64,
    last_iterations: usize,
    /// Over the run: largest Courant number and the sum of pressure iterations.
    max_courant: f64,
    pressure_iterations: u64,
    /// Velocity at the previous sample (for the steady-state test) and its time.
    previous: Option<[Vec<f64>; 3]>,
    previous_t: f64,
    /// Largest |∂u/∂t| over the last sample interval \[m/s²\].
    rate: f64,
}

const SERIES: [&str; 8] = [
    "t_s",
    "dt_s",
    "step",
    "courant",
    "pressure_iterations",
    "max_speed_m_s",
    "kinetic_energy_J",
    "net_outflow_m3_s",
];

fn probe_columns(cfg: &FlowConfig) -> Vec<String> {
    let mut c = vec!["t_s".to_owned()];
    for p in &cfg.output.probes {
        for q in ["ux_m_s", "uy_m_s", "uz_m_s", "p_Pa"] {
            c.push(format!("{}_{q}", p.name));
        }
    }
    c
}

pub(crate) fn max_speed(flow: &Flow) -> f64 {
    let l = flow.grid.layout;
    let mut m: f64 = 0.0;
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            for i in 0..l.n[0] {
                if !flow.blocked[l.cell(i, j, k)] {
                    let u = flow.cell_velocity(i, j, k);
                    m = m.max((u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt());
                }
            }
        }
    }
    m
}

/// One row of the probe table; a probe in a blocked cell is a gap (`None`).
fn probe_row(cfg: &FlowConfig, flow: &Flow) -> Vec<Option<f64>> {
    let mut row = vec![Some(flow.state.t)];
    for p in &cfg.output.probes {
        match probe(flow, p.at_m) {
            Some((u, pr)) => row.extend([u[0], u[1], u[2], pr].map(Some)),
            None => row.extend([None; 4]),
        }
    }
    row
}

/// Runs the scenario in `ctx` (see the module documentation for the files written).
pub fn run(cfg: &FlowConfig, ctx: &RunContext) -> Result<RunSummary, FlowRunError> {
    Checker::run(cfg, None).map_err(FlowRunError::Invalid)?;
    let dir = ctx.dir;
    let root = dir.root().to_owned();
    let ckpt = dir.checkpoint_path();
    let series_path = dir.path("series.csv");
    let probes_path = dir.path("probes.csv");
    let pvd_path = dir.path("fields.pvd");
    let session = Instant::now();
    let pcols = probe_columns(cfg);
    let pcols: Vec<&str> = pcols.iter().map(String::as_str).collect();
    let mut flow = build(cfg)?;
    for (i, p) in cfg.output.probes.iter().enumerate() {
        if probe(&flow, p.at_m).is_none() {
            return Err(FlowRunError::Setup(format!(
                "output.probes[{i}] `{}` at {:?} m lies outside the grid or inside a solid",
                p.name, p.at_m
            )));
        }
    }
    let (mut st, mut series, mut probes, mut pvd) = if ctx.resume && ckpt.exists() {
        let st: RunState = ctx.load_checkpoint()?;
        flow.restore(st.flow.clone())?;
        let series =
            CsvSeries::resume(&series_path, &SERIES, st.series_bytes).map_err(io_at(&series_path))?;
        let probes = CsvSeries::resume(&probes_path, &pcols, st.probes_bytes).map_err(io_at(&probes_path))?;
        let mut pvd = PvdSeries::load_or_new(&pvd_path).map_err(io_at(&pvd_path))?;
        pvd.truncate_after(st.flow.t).map_err(io_at(&pvd_path))?;
        tracing::info!("resumed at t = {:.6} s, step {}", st.flow.t, st.flow.step);
        (st, series, probes, pvd)
    } else {
        let l = flow.grid.layout;
        let fluid_cells = (0..l.len()).filter(|&c| flow.is_fluid(c)).count();
        tracing::info!(
            "flow {}: {:?} grid {} × {} × {} ({} fluid cells), ρ = {} kg/m³, ν = {:.4e} m²/s, {} multigrid levels, {} thread(s)",
            cfg.title,
            cfg.grid.mode,
            l.n[0],
            l.n[1],
            l.n[2],
            fluid_cells,
            cfg.fluid.density_kg_m3,
            cfg.fluid.kinematic_viscosity_m2_s,
            flow.multigrid_depth(),
            rayon::current_num_threads()
        );
        let series = CsvSeries::create(&series_path, &SERIES).map_err(io_at(&series_path))?;
        let probes = CsvSeries::create(&probes_path, &pcols).map_err(io_at(&probes_path))?;
        let st = RunState {
            flow: flow.state.clone(),
            next_field: 0.0,
            field_count: 0,
            next_sample: 0.0,
            series_bytes: 0,
            probes_bytes: 0,
            wall_seconds: 0.0,
            last_dt: 0.0,
            last_courant: 0.0,
            last_iterations: 0,
            max_courant: 0.0,
            pressure_iterations: 0,
            previous: None,
            previous_t: 0.0,
            rate: f64::INFINITY,
        };
        (st, series, probes, PvdSeries::new(&pvd_path))
    };
    let end = cfg.time.end_time_s;
    let eps = 1e-12 * end;
    let field_dt = cfg.output.field_interval(end);
    let sample_dt = cfg.output.sample_interval(end);
    let mut steady = false;
    loop {
        let t = flow.state.t;
        if t >= st.next_sample - eps {
            let row = [
                t,
                st.last_dt,
                flow.state.step as f64,
                st.last_courant,
                st.last_iterations as f64,
                max_speed(&flow),
                cfg.fluid.density_kg_m3 * kinetic_energy(&flow),
                flow.net_outflow(),
            ];
            series.row(&row).map_err(io_at(&series_path))?;
            probes.row_with_gaps(&probe_row(cfg, &flow)).map_err(io_at(&probes_path))?;
            if let Some(limit) = cfg.time.steady_rate_m_s2 {
                if let Some(prev) = &st.previous {
                    let change = (0..3)
                        .flat_map(|a| flow.state.u[a].iter().zip(&prev[a]).map(|(x, y)| (x - y).abs()))
                        .fold(0.0, f64::max);
                    st.rate = change / (t - st.previous_t).max(f64::MIN_POSITIVE);
                    steady = st.rate < limit;
                }
                st.previous = Some(flow.state.u.clone());
                st.previous_t = t;
            }
            while st.next_sample <= t + eps {
                st.next_sample += sample_dt;
            }
        }
        let capped = cfg.time.max_steps.is_some_and(|n| flow.state.step >= n);
        let done = t >= end - eps || steady || capped;
        if t >= st.next_field - eps || done {
            write_field(&root, &mut pvd, &pvd_path, &flow, st.field_count)?;
            st.field_count += 1;
            tracing::info!(
                "t = {t:.6} s, step {}, dt = {:.4e} s, Courant {:.3}, {} pressure iterations, max speed {:.4e} m/s, net outflow {:.3e} m³/s",
                flow.state.step,
                st.last_dt,
                st.last_courant,
                st.last_iterations,
                max_speed(&flow),
                flow.net_outflow()
            );
            while st.next_field <= t + eps {
                st.next_field += field_dt;
            }
        }
        if done {
            if steady {
                tracing::info!(
                    "steady: largest rate of change {:.3e} m/s² < time.steady_rate_m_s2 at t = {t:.6} s",
                    st.rate
                );
            }
            if capped && !steady && t < end - eps {
                tracing::info!("stopped after time.max_steps = {} steps at t = {t:.6} s", flow.state.step);
            }
            break;
        }
        let stop = ctx.control.stop_requested();
        if stop || ctx.checkpoint_due() {
            series.flush().map_err(io_at(&series_path))?;
            probes.flush().map_err(io_at(&probes_path))?;
            st.series_bytes = series.bytes_written();
            st.probes_bytes = probes.bytes_written();
            st.flow = flow.state.clone();
            let wall_before = st.wall_seconds;
            st.wall_seconds += session.elapsed().as_secs_f64();
            ctx.save_checkpoint(&st)?;
            st.wall_seconds = wall_before;
        }
        if stop {
            tracing::info!("stopped at t = {t:.6} s, step {}; checkpoint written", flow.state.step);
            let mut s = RunSummary::new(Finished::Interrupted);
            s.headline.push(format!("stopped at t = {t:.6} s of {end} s; resume to continue"));
            s.artifacts.push(("checkpoint".into(), ckpt));
            return Ok(s);
        }
        let dt = match cfg.numerics.dt_s {
            Some(dt) => dt,
            None => flow.stable_dt(cfg.numerics.courant, cfg.numerics.dt_max_s.unwrap_or(f64::INFINITY)),
        };
        let dt = dt.min(end - t);
        let rep = flow.step(dt)?;
        st.last_dt = dt;
        st.last_courant = rep.courant;
        st.last_iterations = rep.pressure.iterations;
        st.max_courant = st.max_courant.max(rep.courant);
        st.pressure_iterations += rep.pressure.iterations as u64;
        let mut estimate = (end / dt.max(1e-300)) as u64;
        if let Some(n) = cfg.time.max_steps {
            estimate = estimate.min(n);
        }
        ctx.control.progress(flow.state.step, estimate.max(flow.state.step));
    }
    series.flush().map_err(io_at(&series_path))?;
    probes.flush().map_err(io_at(&probes_path))?;
    if ckpt.exists() {
        let _ = std::fs::remove_file(&ckpt);
    }
    let wall = st.wall_seconds + session.elapsed().as_secs_f64();
    finish(cfg, ctx, &flow, &st, wall)
}

fn write_field(
    root: &Path,
    pvd: &mut PvdSeries,
    pvd_path: &Path,
    flow: &Flow,
    n: u32,
) -> Result<(), FlowRunError> {
    let rel = format!("fields/fields_{n:05}.vtr");
    let path = root.join(&rel);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).map_err(io_at(parent))?;
    }
    to_vtr(flow).and_then(|v| v.write(&path)).map_err(io_at(&path))?;
    pvd.push(flow.state.t, &rel).map_err(io_at(pvd_path))
}

fn finish(
    cfg: &FlowConfig,
    ctx: &RunContext,
    flow: &Flow,
    st: &RunState,
    wall: f64,
) -> Result<RunSummary, FlowRunError> {
    let dir = ctx.dir;
    let mut s = RunSummary::new(Finished::Completed);
    let g = &flow.grid;
    // Speed on the cut.
    let (normal, at) = match cfg.output.slice {
        Some(sl) => (
            match sl.normal {
                CutNormal::X => 0,
                CutNormal::Y => 1,
                CutNormal::Z => 2,
            },
            sl.at_m,
        ),
        None => (2, 0.5 * (g.axes[2].lo() + g.axes[2].hi())),
    };
    let slice = speed_slice(flow, normal, at);
    let names = axis_names(g.mode);
    let cut = if g.mode == Mode::Axisymmetric {
        "(r, z) plane".to_owned()
    } else {
        format!("{} = {:.4} m", names[normal], g.axes[normal].centre(slice.layer))
    };
    let title = format!(
        "{}speed at t = {:.4} s, {cut}",
        if cfg.title.is_empty() { String::new() } else { format!("{}: ", cfg.title) },
        flow.state.t
    );
    let (xl, yl) = (format!("{} [m]", names[slice.axes[0]]), format!("{} [m]", names[slice.axes[1]]));
    let png = dir.path("speed.png");
    cut_png(&png, &slice, &slice.speed, &title, (&xl, &yl), "speed |u| [m/s]")?;
    s.artifacts.push(("speed on the cut".into(), png));
    s.artifacts.push(("fields (ParaView)".into(), dir.path("fields.pvd")));
    s.artifacts.push(("series".into(), dir.path("series.csv")));
    if let Some(re) = cfg.output.ghia_re {
        let (eu, ev) = ghia_comparison(cfg, flow, re, dir.root())?;
        s.headline.push(format!(
            "centrelines against Ghia, Ghia & Shin (1982), Re = {re}: max |Δu|/U = {eu:.4}, max |Δv|/U = {ev:.4}"
        ));
        s.scalar("ghia_max_du", eu);
        s.scalar("ghia_max_dv", ev);
        s.artifacts.push(("u on the vertical centreline".into(), dir.path("centreline_u.png")));
        s.artifacts.push(("v on the horizontal centreline".into(), dir.path("centreline_v.png")));
    }
    let steps = flow.state.step;
    let speed = max_speed(flow);
    let ke = cfg.fluid.density_kg_m3 * kinetic_energy(flow);
    let mean_iter = if steps > 0 { st.pressure_iterations as f64 / steps as f64 } else { 0.0 };
    s.headline.push(format!(
        "t = {:.6} s after {steps} steps; max speed {speed:.4e} m/s; largest Courant number {:.3}; {mean_iter:.2} pressure iterations per step; {wall:.1} s wall time",
        flow.state.t, st.max_courant
    ));
    s.scalar("t_end_s", flow.state.t);
    s.scalar("steps", steps as f64);
    s.scalar("max_speed_m_s", speed);
    s.scalar(if g.mode == Mode::Axisymmetric { "kinetic_energy_J_per_rad" } else { "kinetic_energy_J" }, ke);
    s.scalar("max_courant", st.max_courant);
    s.scalar("pressure_iterations_per_step", mean_iter);
    s.scalar("net_outflow_m3_s", flow.net_outflow());
    for (i, d) in cfg.actuator_disks.iter().enumerate() {
        let w = disk_mean_axial_speed(flow, d);
        if !w.is_finite() {
            continue; // a disk whose plane lies inside solids has no fluid to average
        }
        s.headline.push(format!(
            "actuator disk {i}: mean axial speed through the disk {w:.4} m/s; momentum theory in hover √(T/(2ρA)) = {:.4} m/s",
            d.hover_induced_velocity(cfg.fluid.density_kg_m3)
        ));
        s.scalar(&format!("disk_{i}_mean_axial_speed_m_s"), w);
    }
    if g.mode == Mode::Axisymmetric {
        for side in 0..6 {
            let w = flow.wall_shear(side);
            if w.is_empty() {
                continue;
            }
            let name = ["x_min", "x_max", "y_min", "y_max", "z_min", "z_max"][side];
            let (csv, png) = write_wall_shear(dir.root(), name, &w, &cfg.title)?;
            let (peak, at) =
                w.iter()
                    .map(|p| (p.u_star, p.centre))
                    .fold((0.0, [0.0; 3]), |a, b| if b.0 > a.0 { b } else { a });
            let along = if side / 2 == 0 { at[1] } else { at[0] };
            s.headline.push(format!(
                "wall {name}: largest friction velocity {peak:.4} m/s at {} = {along:.4} m",
                if side / 2 == 0 { "z" } else { "r" }
            ));
            s.scalar(&format!("wall_{name}_max_friction_velocity_m_s"), peak);
            s.scalar(&format!("wall_{name}_max_friction_velocity_at_m"), along);
            s.artifacts.push((format!("wall shear along {name}"), csv));
            s.artifacts.push((format!("friction velocity along {name}"), png));
        }
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

/// Writes `wall_shear_<name>.csv` (one row per wall cell along an axisymmetric wall) and
/// `wall_shear_<name>.png` (friction velocity and wall-cell speed against the coordinate along the wall).
fn write_wall_shear(
    root: &Path,
    name: &str,
    w: &[spatter_cfd::wall_shear::WallPoint],
    title: &str,
) -> Result<(PathBuf, PathBuf), FlowRunError> {
    let csv = root.join(format!("wall_shear_{name}.csv"));
    let rows: Vec<Vec<String>> = w
        .iter()
        .map(|p| {
            [p.centre[0], p.centre[1], p.y, p.speed, p.tau_over_rho, p.u_star, p.y_plus]
                .iter()
                .map(|&v| spatter_io::fmt_f64(v))
                .collect()
        })
        .collect();
    write_table(
        &csv,
        &["x_m", "y_m", "wall_distance_m", "speed_m_s", "tau_over_rho_m2_s2", "u_star_m_s", "y_plus"],
        &rows,
    )
    .map_err(io_at(&csv))?;
    let along = |p: &spatter_cfd::wall_shear::WallPoint| {
        if name.starts_with('x') {
            p.centre[1]
        } else {
            p.centre[0]
        }
    };
    let png = root.join(format!("wall_shear_{name}.png"));
    let us: Vec<(f64, f64)> = w.iter().map(|p| (along(p), p.u_star)).collect();
    let sp: Vec<(f64, f64)> = w.iter().map(|p| (along(p), 0.1 * p.speed)).collect();
    Chart::new(
        &format!(
            "{}wall {name}: friction velocity and wall-cell speed",
            if title.is_empty() { String::new() } else { format!("{title}: ") }
        ),
        if name.starts_with('x') { "axial position [m]" } else { "r [m]" },
        "u* [m/s]; speed / 10 [m/s]",
    )
    .size(900, 600)
    .line("friction velocity u*", &us)
    .line("wall-cell speed / 10", &sp)
    .save_png(&png)
    .map_err(io_at(&png))?;
    Ok((csv, png))
}

/// Area-weighted mean of the axial velocity over the disk's radius at its axial position, sampled at the
/// radial cell centres \[m/s\] (positive along the disk's `direction`).
fn disk_mean_axial_speed(flow: &Flow, d: &spatter_cfd::sources::ActuatorDisk) -> f64 {
    let ax = &flow.grid.axes[0];
    let zc = 0.5 * (flow.grid.axes[2].lo() + flow.grid.axes[2].hi());
    let (mut q, mut a) = (0.0, 0.0);
    for i in (0..ax.n()).take_while(|&i| ax.centre(i) < d.radius_m) {
        let (r, dr) = (ax.centre(i), ax.width(i));
        if let Some(u) = flow.velocity_at([r, d.axial_m, zc]) {
            q += u[1] * r * dr;
            a += r * dr;
        }
    }
    if a > 0.0 {
        d.direction * q / a
    } else {
        f64::NAN
    }
}

/// Samples the centrelines of the x–y box (taken as the unit cavity, velocities over the fastest wall
/// speed), writes `centrelines.csv` and the two pictures, and returns the largest differences from Ghia's
/// tables (u on x = ½, v on y = ½).
fn ghia_comparison(cfg: &FlowConfig, flow: &Flow, re: u32, root: &Path) -> Result<(f64, f64), FlowRunError> {
    let g = &flow.grid;
    let lid = cfg
        .boundaries
        .sides()
        .iter()
        .filter_map(|b| match b {
            Boundary::Wall { velocity_m_s } => Some(velocity_m_s.iter().map(|v| v * v).sum::<f64>().sqrt()),
            _ => None,
        })
        .fold(0.0, f64::max);
    if lid <= 0.0 {
        return Err(FlowRunError::Setup(
            "output.ghia_re compares a lid-driven cavity, but no wall moves (boundaries.*.velocity_m_s)"
                .into(),
        ));
    }
    let (tu, tv) = cavity::ghia(re).ok_or_else(|| FlowRunError::Setup(format!("output.ghia_re = {re}")))?;
    let (x0, x1, y0, y1) = (g.axes[0].lo(), g.axes[0].hi(), g.axes[1].lo(), g.axes[1].hi());
    let zc = 0.5 * (g.axes[2].lo() + g.axes[2].hi());
    let at = |xn: f64, yn: f64| -> [f64; 3] {
        flow.velocity_at([x0 + xn * (x1 - x0), y0 + yn * (y1 - y0), zc]).unwrap_or([f64::NAN; 3])
    };
    let eu = tu.iter().map(|&(y, u)| (at(0.5, y)[0] / lid - u).abs()).fold(0.0, f64::max);
    let ev = tv.iter().map(|&(x, v)| (at(x, 0.5)[1] / lid - v).abs()).fold(0.0, f64::max);
    let n = 201;
    let s: Vec<f64> = (0..n).map(|k| k as f64 / (n - 1) as f64).collect();
    let ours_u: Vec<(f64, f64)> = s.iter().map(|&y| (at(0.5, y)[0] / lid, y)).collect();
    let ours_v: Vec<(f64, f64)> = s.iter().map(|&x| (x, at(x, 0.5)[1] / lid)).collect();
    let rows: Vec<Vec<String>> = (0..n)
        .map(|k| [s[k], ours_u[k].0, ours_v[k].1].iter().map(|v| spatter_io::fmt_f64(*v)).collect())
        .collect();
    let csv = root.join("centrelines.csv");
    write_table(&csv, &["s", "u_over_U_at_x_half_y_s", "v_over_U_at_y_half_x_s"], &rows)
        .map_err(io_at(&csv))?;
    let ghia_u: Vec<(f64, f64)> = tu.iter().map(|&(y, u)| (u, y)).collect();
    let red = (200, 30, 30);
    let pu = root.join("centreline_u.png");
    Chart::new(&format!("u on the vertical centreline x = ½, Re = {re}"), "u / U [-]", "y / L [-]")
        .line("spatter", &ours_u)
        .markers("Ghia, Ghia & Shin (1982)", &ghia_u, red)
        .y_range(0.0, 1.0)
        .save_png(&pu)
        .map_err(io_at(&pu))?;
    let pv = root.join("centreline_v.png");
    Chart::new(&format!("v on the horizontal centreline y = ½, Re = {re}"), "x / L [-]", "v / U [-]")
        .line("spatter", &ours_v)
        .markers("Ghia, Ghia & Shin (1982)", &tv, red)
        .x_range(0.0, 1.0)
        .save_png(&pv)
        .map_err(io_at(&pv))?;
    Ok((eu, ev))
}
