//! Running a `brownout` scenario.
//!
//! Outputs in the run folder:
//!
//! * `liftoff_map.csv`, `liftoff_map.png`, `liftoff_thresholds.png` — the lift-off analysis on the mean
//!   flow (ground distance × grain size; thresholds against size);
//! * `entrainment_source.csv` — the source's mass rate per annulus and size class;
//! * `cloud_balance.csv` — every `output.interval_s`: entrained, airborne, redeposited and left mass;
//! * `entrained_mass.png` — those curves;
//! * `cloud.pvd` + `cloud/cloud_NNNNN.vtu` — mass concentration and extinction on the grid;
//! * `optical_depth.csv`, `optical_depth.png` — optical depth of every line of sight against time.
//!
//! Stopping (Ctrl-C, SIGTERM) writes `checkpoint.bin` after a whole step; `--resume` continues and gives
//! the same files as an uninterrupted run.

use super::config::{BrownoutConfig, EntrainmentSource, FlowChoice};
use crate::bed_flow::{BedFlow, BedFlowState, FieldShear, Released};
use crate::cfd::SolvedField;
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Invalid};
use spatter_core::control::Finished;
use spatter_core::Vec3;
use spatter_flow::cloud::grid::CloudGrid;
use spatter_flow::cloud::sim::{CloudBalance, CloudSim};
use spatter_flow::cloud::source::{entrainment_rates, DustSource};
use spatter_flow::cloud::LARGE_PARTICLE_EXTINCTION;
use spatter_flow::field::analytic::{AnalyticField, AnalyticSet};
use spatter_flow::field::rotor::RotorDownwash;
use spatter_flow::field::FlowField;
use spatter_flow::forces::model::{ForceModel, ForceSwitches};
use spatter_flow::liftoff::ground_shear::{ground_shear, GroundProbe, GroundShear, ShearMethod};
use spatter_flow::liftoff::map::lift_off_map;
use spatter_flow::tracker::{TrackError, TrackSettings, TrackerState};
use spatter_io::csv::CsvSeries;
use spatter_io::plot::Chart;
use spatter_io::pvd::PvdSeries;
use spatter_io::run::{RunContext, RunSummary};

/// Why a brownout run failed.
#[derive(Debug, thiserror::Error)]
pub enum BrownoutError {
    #[error(transparent)]
    Track(#[from] TrackError),
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("checkpoint: {0}")]
    Checkpoint(String),
    #[error("invalid brownout configuration: {}", .0.iter().map(|e| format!("{} ({})", e.message, e.key)).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Invalid>),
}

/// What `checkpoint.bin` holds.
#[derive(Serialize, Deserialize)]
struct Checkpoint {
    state: TrackerState,
    source: DustSource,
    next_output: u64,
    balance_bytes: u64,
    optics_bytes: u64,
    /// The DEM bed patch and the bytes of its time series (`entrainment.source = "dem_bed"`).
    bed: Option<BedFlowState>,
    bed_bytes: u64,
}

const BED_COLUMNS: [&str; 6] =
    ["time_s", "entrained_grains", "entrained_kg", "grains_in_bed", "exposed_grains", "u_star_m_s"];

fn bed_row(b: &BedFlow) -> [f64; 6] {
    let probe = b.probe.lock().map(|p| *p).unwrap_or_default();
    [
        b.flow_time(),
        b.entrained_count as f64,
        b.entrained_mass,
        b.sim.particles.len() as f64,
        probe.exposed as f64,
        probe.u_star,
    ]
}

/// Sampling interval of an unsteady flow over the DEM bed patch \[s\].
const BED_FLOW_INTERVAL_S: f64 = 1e-3;

/// The key a bed-building error belongs to.
fn bed_key(b: &crate::bed_flow::DemBedConfig) -> &'static str {
    if b.file.is_some() {
        "dem_bed.file"
    } else {
        "dem_bed"
    }
}

/// Most parcels a run may release (about 1 GB of parcel state).
const MAX_PARCELS: f64 = 1e7;

const BALANCE_COLUMNS: [&str; 7] =
    ["time_s", "entrained_kg", "airborne_kg", "redeposited_kg", "left_kg", "pending_kg", "airborne_parcels"];

fn balance_row(t: f64, b: &CloudBalance, airborne: usize) -> [f64; 7] {
    [t, b.entrained, b.airborne, b.redeposited, b.left, b.pending, airborne as f64]
}

/// Runs a brownout scenario.
pub fn run(cfg: &BrownoutConfig, ctx: &RunContext) -> Result<RunSummary, BrownoutError> {
    Checker::run(cfg, None).map_err(BrownoutError::Invalid)?;
    let air = cfg.air;
    let rotor = cfg.rotor.downwash(&air);
    let summary = RunSummary::new(Finished::Completed);
    match &cfg.flow {
        FlowChoice::Analytic => {
            let field = AnalyticSet { parts: vec![AnalyticField::Rotor(rotor.clone())], turbulence: None };
            // The mean flow (the tip vortices are a fluctuation about it): the lift-off map's field, with
            // the gust factor standing for the fluctuations as in the thesis's mean + 2u′.
            let mean_rotor = RotorDownwash { tip_vortices: false, ..rotor.clone() };
            let mean_field = AnalyticSet { parts: vec![AnalyticField::Rotor(mean_rotor)], turbulence: None };
            // With tip vortices the flux (nonlinear in u_*) is averaged over one shedding period; the mean
            // flow is steady and needs one sample.
            let window = if rotor.tip_vortices {
                let period = std::f64::consts::TAU / (cfg.rotor.blades as f64 * cfg.rotor.omega_rad_s);
                Unsteady { start: 0.0, span: period, phases: cfg.entrainment.phases }
            } else {
                Unsteady::STEADY
            };
            run_on(cfg, ctx, field, &mean_field, window, summary)
        }
        FlowChoice::Imported(ic) => {
            let loaded = super::imported::load(cfg, ic)
                .map_err(|e| BrownoutError::Invalid(vec![Invalid { key: "flow".into(), message: e }]))?;
            let mut summary = summary;
            let s = loaded.field.scaling;
            summary.headline.push(format!(
                "imported flow: {} frame(s); scaled to the rotor by lengths × {:.6}, velocities × {:.6}, times × {:.6}{}",
                loaded.frames,
                s.length,
                s.velocity,
                s.time(),
                if loaded.frames > 1 {
                    format!("; unsteady window {:.4} s from t = {:.4} s (full scale)", loaded.window.1, loaded.window.0)
                } else {
                    String::new()
                }
            ));
            summary.scalar("flow_length_scale", s.length);
            summary.scalar("flow_velocity_scale", s.velocity);
            let field = &loaded.field;
            if loaded.frames > 1 && loaded.window.1 > 0.0 {
                let window = Unsteady {
                    start: loaded.window.0,
                    span: loaded.window.1,
                    phases: cfg.entrainment.phases,
                };
                // The lift-off map's mean flow: the field averaged over the exceedance map's times.
                let mean = super::imported::TimeMean {
                    inner: field,
                    times: window.times(cfg.liftoff.exceedance_samples),
                };
                run_on(cfg, ctx, field, &mean, window, summary)
            } else {
                run_on(cfg, ctx, field, field, Unsteady::STEADY, summary)
            }
        }
        FlowChoice::Rans(rc) => {
            let started = std::time::Instant::now();
            let stop = || ctx.control.stop_requested();
            let Some(solved) = super::rans::solve(cfg, rc, &stop)
                .map_err(|e| BrownoutError::Invalid(vec![Invalid { key: "flow".into(), message: e }]))?
            else {
                let mut s = RunSummary::new(Finished::Interrupted);
                s.headline.push("stopped during the RANS solve of the rotor flow (no checkpoint: a resumed run solves it again)".into());
                return Ok(s);
            };
            let summary = rans_outputs(cfg, ctx, &solved, started.elapsed().as_secs_f64(), summary)?;
            let field = SolvedField::new(&solved.flow);
            let mean_field = SolvedField::new(&solved.flow);
            run_on(cfg, ctx, field, &mean_field, Unsteady::STEADY, summary)
        }
    }
}

/// Writes the solved rotor flow (`rotor_flow.vtr`, `rotor_wall_shear.csv`) and its summary lines.
fn rans_outputs(
    cfg: &BrownoutConfig,
    ctx: &RunContext,
    solved: &super::rans::Solved,
    seconds: f64,
    mut summary: RunSummary,
) -> Result<RunSummary, BrownoutError> {
    let flow = &solved.flow;
    let r0 = cfg.rotor.radius_m;
    let vtr = ctx.dir.path("rotor_flow.vtr");
    spatter_cfd::output::to_vtr(flow).and_then(|v| v.write(&vtr))?;
    summary.artifacts.push(("solved rotor flow (ParaView)".into(), vtr));
    // Induced velocity: area-weighted mean axial speed through the disk plane.
    let ax = &flow.grid.axes[0];
    let (mut q, mut a) = (0.0, 0.0);
    for i in (0..ax.n()).take_while(|&i| ax.centre(i) < r0) {
        let (r, dr) = (ax.centre(i), ax.width(i));
        if let Some(u) = flow.velocity_at([r, solved.disk.axial_m, 0.5]) {
            q -= u[1] * r * dr;
            a += r * dr;
        }
    }
    let vi = if a > 0.0 { q / a } else { 0.0 };
    let wall = flow.wall_shear(2);
    let rows: Vec<Vec<String>> = wall
        .iter()
        .map(|p| {
            let near = flow.velocity_at([p.centre[0], 0.1, 0.5]).map_or(0.0, |u| u[0]);
            [
                p.centre[0],
                p.centre[0] / r0,
                p.y,
                p.speed,
                near,
                p.tau_over_rho * cfg.air.density,
                p.u_star,
                p.y_plus,
            ]
            .iter()
            .map(|&v| spatter_io::fmt_f64(v))
            .collect()
        })
        .collect();
    let csv = ctx.dir.path("rotor_wall_shear.csv");
    spatter_io::csv::write_table(
        &csv,
        &[
            "r_m",
            "r_over_R",
            "wall_distance_m",
            "wall_cell_speed_m_s",
            "radial_speed_0p1m_m_s",
            "tau_w_pa",
            "u_star_m_s",
            "y_plus",
        ],
        &rows,
    )?;
    summary.artifacts.push(("ground shear of the solved flow".into(), csv));
    let (peak, at) =
        wall.iter().map(|p| (p.u_star, p.centre[0])).fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    summary.headline.push(format!(
        "RANS rotor ({}): {} after t = {:.1} s ({} steps, {seconds:.0} s wall time; last change over R/v_i {:.2e} v_i); induced velocity through the disk {vi:.3} m/s against momentum theory out of ground effect {:.3} m/s; ground friction velocity peaks at {peak:.3} m/s at r/R = {:.2}",
        match solved.flow.turbulence.as_ref().map(|t| t.model.variant) {
            Some(spatter_cfd::turbulence::Variant::Standard) => "standard k–ε",
            _ => "realizable k–ε",
        },
        if solved.steady { "steady" } else { "not steady yet (time or step limit)" },
        flow.state.t,
        flow.state.step,
        solved.change,
        solved.v_hover,
        at / r0
    ));
    summary.scalar("rans_steady", if solved.steady { 1.0 } else { 0.0 });
    summary.scalar("rans_induced_velocity_m_s", vi);
    summary.scalar("rans_hover_induced_velocity_m_s", solved.v_hover);
    summary.scalar("rans_max_ground_friction_velocity_m_s", peak);
    summary.scalar("rans_max_ground_friction_velocity_r_over_R", at / r0);
    Ok(summary)
}

/// The time window over which an unsteady field is sampled: one shedding period of the analytic tip
/// vortices, or the period (else the span) of an imported time series.
#[derive(Clone, Copy, Debug)]
struct Unsteady {
    /// Start \[s\] and length \[s\] of the window (0: a steady field).
    start: f64,
    span: f64,
    /// Times at which the source's flux is averaged (1 for a steady field; an unsteady one may use 1 too).
    phases: usize,
}

impl Unsteady {
    const STEADY: Unsteady = Unsteady { start: 0.0, span: 0.0, phases: 1 };

    /// `n` equally spaced times over the window, from its start (one time for a steady field).
    fn times(&self, n: usize) -> Vec<f64> {
        if self.span > 0.0 {
            (0..n).map(|k| self.start + self.span * k as f64 / n as f64).collect()
        } else {
            vec![self.start]
        }
    }
}

/// The lift-off map, the source and the cloud on `field` (the lift-off map on `mean_field`).
fn run_on<F: FlowField, M: FlowField>(
    cfg: &BrownoutConfig,
    ctx: &RunContext,
    field: F,
    mean_field: &M,
    window: Unsteady,
    mut summary: RunSummary,
) -> Result<RunSummary, BrownoutError> {
    let phases = window.phases;
    let air = cfg.air;
    let r0 = cfg.rotor.radius_m;
    let g = 9.81;
    let rho_p = cfg.ground.density_kg_m3;
    let classes = cfg
        .ground
        .size
        .classes()
        .map_err(|e| BrownoutError::Invalid(vec![Invalid { key: "ground.size".into(), message: e }]))?;

    // 1. Lift-off map on the mean flow.
    let lo = &cfg.liftoff;
    let n = lo.points;
    let probe = GroundProbe {
        origin: Vec3::ZERO,
        direction: Vec3::X,
        distances: (0..n)
            .map(|i| {
                r0 * (lo.radius_min_over_radius
                    + (lo.radius_max_over_radius - lo.radius_min_over_radius) * i as f64 / (n - 1) as f64)
            })
            .collect(),
        method: ShearMethod::JetPeak { max_height: lo.shear_max_height_over_radius * r0, samples: 96 },
        gust: lo.gust_factor,
    };
    let map = lift_off_map(mean_field, &probe, r0, (&lo.diameters_m, rho_p), &air, &cfg.rocking(), 0.0);
    let title = format!(
        "lift-off map: rotor R = {r0} m at z_d/R = {}, gust factor {}",
        cfg.rotor.height_over_radius, lo.gust_factor
    );
    for (name, label) in [
        ("liftoff_map.csv", "lift-off map table"),
        ("liftoff_map.png", "lift-off map"),
        ("liftoff_thresholds.png", "lift-off thresholds"),
    ] {
        let path = ctx.dir.path(name);
        match name {
            "liftoff_map.csv" => map.write_csv(&path)?,
            "liftoff_map.png" => map.write_png(&path, &title)?,
            _ => map.write_threshold_png(&path, "friction velocity to rock and to lift off a grain")?,
        }
        summary.artifacts.push((label.into(), path));
    }
    let u_max = map.ground.iter().map(|g| g.u_star).fold(0.0, f64::max);
    summary.scalar("max_friction_velocity_m_s", u_max);
    // Which size lifts off most easily (largest lift ratio anywhere).
    let (k_best, (ratio_best, at_best)) = (0..map.diameters.len())
        .map(|k| (k, map.peak_lift(k)))
        .fold((0, (f64::NEG_INFINITY, 0.0)), |a, b| if b.1 .0 > a.1 .0 { b } else { a });
    summary.headline.push(format!(
        "lift-off: friction velocity up to {u_max:.3} m/s; the largest lift / (weight + cohesion) is {ratio_best:.3} for {:.0} µm grains at r/R = {:.2}",
        map.diameters[k_best] * 1e6,
        at_best / r0
    ));
    summary.scalar("most_liftable_diameter_um", map.diameters[k_best] * 1e6);
    super::exceedance::write(cfg, ctx, &field, &probe, window.times(lo.exceedance_samples), &mut summary)?;

    // 2. The entrainment source on annuli.
    let en = &cfg.entrainment;
    let edges: Vec<f64> = (0..=en.annuli)
        .map(|i| {
            r0 * (en.radius_min_over_radius
                + (en.radius_max_over_radius - en.radius_min_over_radius) * i as f64 / en.annuli as f64)
        })
        .collect();
    let mids: Vec<f64> = edges.windows(2).map(|w| 0.5 * (w[0] + w[1])).collect();
    let src_probe = GroundProbe { distances: mids.clone(), gust: en.gust_factor, ..probe.clone() };
    let ref_probe = GroundProbe {
        method: ShearMethod::FixedHeight { height: en.reference_height_m },
        ..src_probe.clone()
    };
    // With tip vortices the flux (nonlinear in u_*) is averaged over one shedding period, sampled at
    // `phases` equally spaced times.
    let mut ground: Vec<GroundShear> = Vec::new();
    let mut rates: Vec<Vec<f64>> = Vec::new();
    for (k, t) in window.times(phases).into_iter().enumerate() {
        let gs = ground_shear(&field, &src_probe, t, &air);
        let reference: Vec<f64> = ground_shear(&field, &ref_probe, t, &air).iter().map(|g| g.speed).collect();
        let r = entrainment_rates(
            &edges,
            &gs,
            &reference,
            &classes,
            &en.model,
            &en.threshold.threshold(),
            (rho_p, air.density, g),
        );
        if k == 0 {
            ground = gs;
            rates = r;
        } else {
            for (a, row) in rates.iter_mut().enumerate() {
                for (c, v) in row.iter_mut().enumerate() {
                    *v += r[a][c];
                }
                ground[a].u_star += gs[a].u_star;
            }
        }
    }
    for (a, row) in rates.iter_mut().enumerate() {
        for v in row.iter_mut() {
            *v /= phases as f64;
        }
        ground[a].u_star /= phases as f64;
    }
    {
        let mut rows = Vec::new();
        for (a, row) in rates.iter().enumerate() {
            for (c, rate) in row.iter().enumerate() {
                rows.push(vec![
                    spatter_io::fmt_f64(edges[a]),
                    spatter_io::fmt_f64(edges[a + 1]),
                    spatter_io::fmt_f64(classes.diameters[c] * 1e6),
                    spatter_io::fmt_f64(ground[a].u_star),
                    spatter_io::fmt_f64(*rate),
                ]);
            }
        }
        let path = ctx.dir.path("entrainment_source.csv");
        spatter_io::csv::write_table(
            &path,
            &["r_inner_m", "r_outer_m", "d_um", "mean_u_star_m_s", "rate_kg_s"],
            &rows,
        )?;
        summary.artifacts.push(("entrainment source".into(), path));
    }
    let model_rate: f64 = rates.iter().flatten().sum();
    let from_bed = cfg.entrainment.source == EntrainmentSource::DemBed;
    if from_bed {
        // The model's flux is written above for comparison; the cloud is fed by the bed patch alone.
        for v in rates.iter_mut().flatten() {
            *v = 0.0;
        }
    }
    let source = DustSource::new(
        Vec3::ZERO,
        edges,
        classes.diameters.clone(),
        rho_p,
        rates,
        cfg.cloud.parcel_mass_kg,
        cfg.cloud.release_height_m,
        cfg.cloud.seed,
    );
    let total_rate = source.total_rate();
    summary.scalar("entrainment_rate_kg_s", model_rate);
    let parcels = total_rate * cfg.cloud.duration_s / cfg.cloud.parcel_mass_kg;
    if parcels > MAX_PARCELS {
        return Err(BrownoutError::Invalid(vec![Invalid {
            key: "cloud.parcel_mass_kg".into(),
            message: format!(
                "parcel_mass_kg = {:e} kg: the source gives {total_rate:.4e} kg/s, so duration_s = {} s would release {parcels:.3e} parcels (at most {MAX_PARCELS:e}); choose a parcel mass of at least {:.3e} kg",
                cfg.cloud.parcel_mass_kg,
                cfg.cloud.duration_s,
                total_rate * cfg.cloud.duration_s / MAX_PARCELS
            ),
        }]));
    }

    // 3. The cloud.
    let dt = cfg.cloud.dt_s;
    let domain = cfg.domain();
    let settings =
        TrackSettings { dt, domain: Some(domain), dispersion: None, max_bounces: 8, resort_interval: 0 };
    let model = ForceModel::new(air, ForceSwitches::default());
    // The DEM bed patch under the flow, centred on the ground at `radius_over_radius`·R on the +x axis;
    // built (and settled) before the cloud starts.
    let patch_centre =
        cfg.dem_bed.as_ref().map_or(Vec3::ZERO, |b| Vec3::new(b.radius_over_radius * r0, 0.0, 0.0));
    let shear = cfg.dem_bed.as_ref().filter(|_| from_bed).map(|b| {
        FieldShear {
            field: &field,
            centre: patch_centre,
            max_height: lo.shear_max_height_over_radius * r0,
            gust: lo.gust_factor,
            fluid: air,
        }
        .tabulate(b.duration_s, BED_FLOW_INTERVAL_S, window.span <= 0.0)
    });
    let mut sim = CloudSim::new(field, model, settings, source);
    let mut grid = CloudGrid::new(domain, cfg.output.grid_cells);
    let lines = &cfg.output.lines_of_sight;
    let mut optics_cols = vec!["time_s".to_owned()];
    optics_cols.extend(lines.iter().map(|l| format!("tau_{}", l.name)));
    let optics_cols: Vec<&str> = optics_cols.iter().map(String::as_str).collect();
    let balance_path = ctx.dir.path("cloud_balance.csv");
    let optics_path = ctx.dir.path("optical_depth.csv");
    let pvd_path = ctx.dir.path("cloud.pvd");
    let ckpt = ctx.dir.checkpoint_path();
    let bed_path = ctx.dir.path("dem_bed_entrainment.csv");
    let mut next_output = 0u64;
    let mut bed_state: Option<BedFlowState> = None;
    let (mut bal_csv, mut opt_csv, mut pvd, mut bed_csv) = if ctx.resume && ckpt.is_file() {
        // The checkpoint's header carries the input hash: another scenario's checkpoint is refused here.
        let c: Checkpoint = ctx.load_checkpoint().map_err(|e| BrownoutError::Checkpoint(e.to_string()))?;
        sim.tracker.state = c.state;
        sim.source = c.source;
        next_output = c.next_output;
        bed_state = c.bed;
        let mut pvd = PvdSeries::load_or_new(&pvd_path)?;
        pvd.truncate_after(sim.tracker.state.time)?;
        (
            CsvSeries::resume(&balance_path, &BALANCE_COLUMNS, c.balance_bytes)?,
            CsvSeries::resume(&optics_path, &optics_cols, c.optics_bytes)?,
            pvd,
            if shear.is_some() {
                Some(CsvSeries::resume(&bed_path, &BED_COLUMNS, c.bed_bytes)?)
            } else {
                None
            },
        )
    } else {
        (
            CsvSeries::create(&balance_path, &BALANCE_COLUMNS)?,
            CsvSeries::create(&optics_path, &optics_cols)?,
            PvdSeries::new(&pvd_path),
            if shear.is_some() { Some(CsvSeries::create(&bed_path, &BED_COLUMNS)?) } else { None },
        )
    };
    let mut bed = match (&cfg.dem_bed, shear) {
        (Some(b), Some(shear)) => {
            let built = BedFlow::build(b, rho_p, air, std::sync::Arc::new(shear), bed_state)
                .map_err(|e| BrownoutError::Invalid(vec![Invalid { key: bed_key(b).into(), message: e }]))?;
            Some(built)
        }
        _ => None,
    };
    if let Some(b) = &bed {
        if sim.tracker.state.step == 0 {
            let path = ctx.dir.path("dem_bed_start.vtu");
            spatter_dem::output::write_particles(&b.sim, &path)?;
            summary.artifacts.push(("DEM bed patch at the start (ParaView)".into(), path));
        }
    }
    let bed_duration = cfg.dem_bed.as_ref().map_or(0.0, |b| b.duration_s);
    let mut released: Vec<Released> = Vec::new();
    let n_steps = (cfg.cloud.duration_s / dt).round() as u64;
    let interval = cfg.output.interval_s;
    let mut write_outputs = |sim: &CloudSim<F>,
                             k: &mut u64,
                             bal: &mut CsvSeries,
                             opt: &mut CsvSeries,
                             pvd: &mut PvdSeries|
     -> std::io::Result<()> {
        let t = sim.tracker.state.time;
        bal.row(&balance_row(t, &sim.balance(), sim.tracker.airborne()))?;
        grid.fill(&sim.tracker.state.parcels, LARGE_PARTICLE_EXTINCTION);
        let mut row = vec![t];
        row.extend(lines.iter().map(|l| grid.optical_depth(l.from_m, l.to_m)));
        opt.row(&row)?;
        let rel = format!("cloud/cloud_{k:05}.vtu");
        std::fs::create_dir_all(ctx.dir.path("cloud"))?;
        grid.write_vtu(&ctx.dir.path(&rel))?;
        pvd.push(t, &rel)?;
        *k += 1;
        Ok(())
    };
    // The bed's rows: at t = 0, at every output time while the patch runs, and once when it ends (the
    // patch may end between two output times; after its end nothing changes).
    let bed_ended = |b: &BedFlow| b.flow_time() + 0.5 * b.sim.dt >= bed_duration;
    let write_bed = |bed: &Option<BedFlow>, csv: &mut Option<CsvSeries>, last: bool| -> std::io::Result<()> {
        if let (Some(b), Some(csv)) = (bed, csv) {
            if last || !bed_ended(b) {
                csv.row(&bed_row(b))?;
            }
        }
        Ok(())
    };
    if sim.tracker.state.step == 0 && next_output == 0 {
        write_outputs(&sim, &mut next_output, &mut bal_csv, &mut opt_csv, &mut pvd)?;
        write_bed(&bed, &mut bed_csv, false)?;
    }
    let due = |t: f64, k: u64| t >= k as f64 * interval - 1e-9 * dt;
    let mut last_written = u64::MAX;
    while sim.tracker.state.step < n_steps {
        let stop = ctx.control.stop_requested();
        if stop || ctx.checkpoint_due() {
            bal_csv.flush()?;
            opt_csv.flush()?;
            if let Some(c) = &mut bed_csv {
                c.flush()?;
            }
            let c = Checkpoint {
                state: sim.tracker.state.clone(),
                source: sim.source.clone(),
                next_output,
                balance_bytes: bal_csv.bytes_written(),
                optics_bytes: opt_csv.bytes_written(),
                bed: bed.as_ref().map(BedFlow::state),
                bed_bytes: bed_csv.as_ref().map_or(0, CsvSeries::bytes_written),
            };
            ctx.save_checkpoint(&c).map_err(|e| BrownoutError::Checkpoint(e.to_string()))?;
            if stop {
                let mut s = RunSummary::new(Finished::Interrupted);
                s.headline.push(format!(
                    "stopped at t = {:.6} s (step {} of {n_steps}); checkpoint written to {}",
                    sim.tracker.state.time,
                    sim.tracker.state.step,
                    ckpt.display()
                ));
                return Ok(s);
            }
        }
        let mut bed_just_ended = false;
        if let Some(b) = &mut bed {
            let running = !bed_ended(b);
            // The bed runs over this cloud step; the grains that left it join the cloud at the step's
            // start, at their place on the ground (bed frame: ground plane at z = 0, patch centre at
            // the patch's place), with their own velocity.
            let target = ((sim.tracker.state.step + 1) as f64 * dt).min(bed_duration);
            let dtb = b.sim.dt;
            while b.flow_time() + 0.5 * dtb < target {
                b.step(&mut released).map_err(|e| BrownoutError::Checkpoint(format!("DEM bed: {e}")))?;
            }
            bed_just_ended = running && bed_ended(b);
            let [x0, x1, y0, y1] = b.footprint;
            let origin = Vec3::new(0.5 * (x0 + x1), 0.5 * (y0 + y1), b.z_ground);
            for r in released.drain(..) {
                sim.tracker.add(
                    spatter_flow::tracker::inject::NewParcel {
                        pos: patch_centre + (r.pos - origin),
                        vel: r.vel,
                        diameter: r.diameter,
                        density: rho_p,
                        count: 1.0,
                    },
                    0,
                );
            }
        }
        sim.step()?;
        let output = due(sim.tracker.state.time, next_output);
        if output {
            write_outputs(&sim, &mut next_output, &mut bal_csv, &mut opt_csv, &mut pvd)?;
            last_written = sim.tracker.state.step;
        }
        if output || bed_just_ended {
            write_bed(&bed, &mut bed_csv, bed_just_ended)?;
        }
        ctx.control.progress(sim.tracker.state.step, n_steps);
    }
    if last_written != sim.tracker.state.step {
        write_outputs(&sim, &mut next_output, &mut bal_csv, &mut opt_csv, &mut pvd)?;
        write_bed(&bed, &mut bed_csv, false)?;
    }
    bal_csv.flush()?;
    opt_csv.flush()?;
    if let Some(c) = &mut bed_csv {
        c.flush()?;
    }
    // A finished run leaves no checkpoint behind.
    if ckpt.exists() {
        std::fs::remove_file(&ckpt)?;
    }

    // 4. Pictures of the time series.
    let (_, bal_rows) = spatter_io::csv::read_series(&balance_path)?;
    let col = |k: usize| -> Vec<(f64, f64)> { bal_rows.iter().map(|r| (r[0], r[k])).collect() };
    let mass_png = ctx.dir.path("entrained_mass.png");
    Chart::new("dust mass: entrained = airborne + redeposited + left", "time [s]", "mass [kg]")
        .size(900, 600)
        .line("entrained", &col(1))
        .line("airborne", &col(2))
        .line("redeposited", &col(3))
        .line("left the domain", &col(4))
        .save_png(&mass_png)?;
    let (_, opt_rows) = spatter_io::csv::read_series(&optics_path)?;
    let tau_png = ctx.dir.path("optical_depth.png");
    let mut chart = Chart::new(
        "optical depth along the lines of sight (Q_ext = 2); transmission e^(−τ)",
        "time [s]",
        "optical depth τ",
    )
    .size(900, 600);
    for (k, l) in lines.iter().enumerate() {
        let pts: Vec<(f64, f64)> = opt_rows.iter().map(|r| (r[0], r[k + 1])).collect();
        chart = chart.line(&l.name, &pts);
    }
    chart.save_png(&tau_png)?;
    if let Some(b) = &bed {
        let path = ctx.dir.path("dem_bed_end.vtu");
        spatter_dem::output::write_particles(&b.sim, &path)?;
        summary.artifacts.push(("DEM bed patch at the end (ParaView)".into(), path));
        let (_, rows) = spatter_io::csv::read_series(&bed_path)?;
        let col = |k: usize| -> Vec<(f64, f64)> { rows.iter().map(|r| (r[0], r[k])).collect() };
        let png = ctx.dir.path("dem_bed_entrainment.png");
        Chart::new(
            "DEM bed patch: grains that left the bed, and grains exposed to the flow",
            "time [s]",
            "grains",
        )
        .size(900, 600)
        .line("entrained (left the bed)", &col(1))
        .line("exposed to the flow", &col(4))
        .save_png(&png)?;
        summary.artifacts.push(("DEM bed entrainment table".into(), bed_path.clone()));
        summary.artifacts.push(("DEM bed entrainment plot".into(), png));
        let probe = b.probe.lock().map(|p| *p).unwrap_or_default();
        summary.headline.push(format!(
            "DEM bed patch at r/R = {:.2}: {} grains ({:.3e} kg) left the bed in {:.3} s under u* = {:.3} m/s; {} grains remain, {} exposed",
            cfg.dem_bed.as_ref().map_or(0.0, |c| c.radius_over_radius),
            b.entrained_count,
            b.entrained_mass,
            b.flow_time(),
            probe.u_star,
            b.sim.particles.len(),
            probe.exposed
        ));
        summary.scalar("dem_bed_entrained_grains", b.entrained_count as f64);
        summary.scalar("dem_bed_entrained_kg", b.entrained_mass);
        summary.scalar("dem_bed_friction_velocity_m_s", probe.u_star);
    }
    for (label, path) in [
        ("cloud mass balance", balance_path),
        ("entrained mass curve", mass_png),
        ("concentration field", pvd_path),
        ("optical depth table", optics_path),
        ("optical depth plot", tau_png),
    ] {
        summary.artifacts.push((label.into(), path));
    }
    let b = sim.balance();
    let (lhs, rhs) = sim.tracker.mass_balance();
    summary.headline.push(format!(
        "cloud at t = {:.3} s: entrained {:.4e} kg = airborne {:.4e} + redeposited {:.4e} + left {:.4e} kg (residual {:e} kg); source {:.4e} kg/s",
        sim.tracker.state.time, b.entrained, b.airborne, b.redeposited, b.left, lhs - rhs, total_rate
    ));
    for (k, l) in lines.iter().enumerate() {
        let tau = opt_rows.last().map(|r| r[k + 1]).unwrap_or(0.0);
        summary.headline.push(format!(
            "line of sight `{}`: optical depth {tau:.4e} at the end (transmission {:.4})",
            l.name,
            (-tau).exp()
        ));
        summary.scalar(&format!("optical_depth_{}", l.name), tau);
    }
    for (name, v) in [
        ("entrained_kg", b.entrained),
        ("airborne_kg", b.airborne),
        ("redeposited_kg", b.redeposited),
        ("left_kg", b.left),
        ("mass_balance_residual_kg", lhs - rhs),
    ] {
        summary.scalar(name, v);
    }
    Ok(summary)
}
