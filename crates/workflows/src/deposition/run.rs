//! Running a `deposition` scenario: build the field, bodies and injectors, track, write the deposit maps.
//!
//! Outputs in the run folder:
//!
//! * `balance.csv` — every `output.interval_s`: parcels and mass airborne, deposited, escaped, injected;
//! * `parcels.pvd` + `parcels/parcels_NNNNN.vtu` — parcel snapshots (position, velocity, diameter, count,
//!   status, id);
//! * `bodies/<name>.vtu` — each body's triangles with the per-triangle deposit and impact statistics;
//! * `<name>_deposit.png` — the chosen statistic on the body, seen from the body's view direction;
//! * `deposit_summary.csv` — one row per body.
//!
//! Stopping (Ctrl-C) writes `checkpoint.bin` after a whole step and the body outputs (VTU, picture,
//! summary) from the deposits so far, marked partial in the log and the picture title; resuming continues
//! from the checkpoint and gives the same files as an uninterrupted run.

use super::config::{DepositionConfig, PictureQuantity};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Invalid};
use spatter_core::control::Finished;
use spatter_core::mesh::TriMesh;
use spatter_core::{Aabb, Vec3};
use spatter_flow::field::analytic::AnalyticSet;
use spatter_flow::field::imported::{ImportOptions, ImportedField};
use spatter_flow::field::tetmesh::NONE;
use spatter_flow::field::{Field, FieldError, FlowField};
use spatter_flow::forces::model::ForceModel;
use spatter_flow::tracker::inject::{InjectError, Injector, InjectorState};
use spatter_flow::tracker::walls::{Body, WallRule, WallRuleError, WallRuleSpec};
use spatter_flow::tracker::{Status, TrackError, TrackSettings, Tracker, TrackerState};
use spatter_io::csv::CsvSeries;
use spatter_io::pvd::PvdSeries;
use spatter_io::run::{MeshMapRecord, RunContext, RunSummary};
use spatter_io::vtu::Vtu;
use std::path::PathBuf;

/// Why a deposition run failed.
#[derive(Debug, thiserror::Error)]
pub enum DepositionError {
    #[error(transparent)]
    Field(#[from] FieldError),
    #[error("body `{name}`: {message}")]
    Body { name: String, message: String },
    #[error(transparent)]
    Wall(#[from] WallRuleError),
    #[error(transparent)]
    Inject(#[from] InjectError),
    #[error(transparent)]
    Track(#[from] TrackError),
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("checkpoint: {0}")]
    Checkpoint(String),
    #[error("invalid deposition configuration: {}", .0.iter().map(|e| format!("{} ({})", e.message, e.key)).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Invalid>),
}

/// What `checkpoint.bin` holds (its header names the input it belongs to: a resume with another
/// configuration is refused when it is loaded).
#[derive(Serialize, Deserialize)]
pub(super) struct Checkpoint {
    pub(super) state: TrackerState,
    pub(super) injectors: Vec<InjectorState>,
    pub(super) next_output: u64,
    pub(super) csv_bytes: u64,
}

const BALANCE_COLUMNS: [&str; 9] = [
    "time_s",
    "airborne_parcels",
    "deposited_parcels",
    "escaped_parcels",
    "injected_kg",
    "airborne_kg",
    "deposited_kg",
    "escaped_kg",
    "balance_residual_kg",
];

/// Builds the flow field of `cfg`.
pub fn build_field(cfg: &DepositionConfig) -> Result<Field, DepositionError> {
    let f = &cfg.flow;
    if !f.analytic.is_empty() {
        return Ok(Field::Analytic(AnalyticSet { parts: f.analytic.clone(), turbulence: f.turbulence }));
    }
    let files: Vec<(f64, PathBuf)> = if let Some(v) = &f.vtk {
        vec![(0.0, v.clone())]
    } else if let Some(s) = &f.series {
        spatter_io::vtk::series::read_series(s).map_err(FieldError::from)?
    } else {
        f.files.iter().map(|t| (t.time_s, t.file.clone())).collect()
    };
    let opts = ImportOptions {
        interpolation: f.interpolation,
        names: f.arrays.clone(),
        length_scale: f.length_scale,
        period: f.period_s,
    };
    Ok(Field::Imported(Box::new(ImportedField::load(&files, &opts)?)))
}

/// Loads the bodies of `cfg`; wall shear is estimated from `field` where a rule needs it or where the
/// wall lift takes its friction velocity from it.
pub fn build_bodies(cfg: &DepositionConfig, field: &Field) -> Result<Vec<Body>, DepositionError> {
    let mut out = Vec::new();
    for b in &cfg.bodies {
        let mut mesh = TriMesh::load(&b.file, b.scale)
            .map_err(|e| DepositionError::Body { name: b.name.clone(), message: e.to_string() })?;
        if b.translate_m != Vec3::ZERO {
            let t = b.translate_m;
            mesh.map_vertices(|v| v + t);
        }
        let rule = WallRule::from_spec(&b.wall)?;
        let mut body = Body::new(b.name.clone(), mesh, rule);
        let lift_needs_shear = cfg.forces.wall_lift.is_some_and(|w| w.friction_velocity.is_none());
        if lift_needs_shear || matches!(b.wall, WallRuleSpec::RegimeMap { max_wall_shear_pa: Some(_), .. }) {
            let mut hint = NONE;
            body.estimate_wall_shear(cfg.fluid.viscosity, b.shear_probe_distance_m, |p| {
                field.sample(p, 0.0, &mut hint, false).map(|s| s.u)
            });
        }
        out.push(body);
    }
    Ok(out)
}

fn balance_row(tr: &Tracker<Field>) -> [f64; 9] {
    let count = |s: Status| tr.state.parcels.iter().filter(|p| p.status == s).count() as f64;
    let b = &tr.state.balance;
    let air = tr.airborne_mass().value();
    let (inj, rhs) = tr.mass_balance();
    [
        tr.state.time,
        count(Status::Airborne),
        count(Status::Deposited),
        count(Status::Escaped),
        b.injected.value(),
        air,
        b.deposited.value(),
        b.escaped.value(),
        inj - rhs,
    ]
}

fn write_parcels(tr: &Tracker<Field>, ctx: &RunContext, k: u64, pvd: &mut PvdSeries) -> std::io::Result<()> {
    let ps: Vec<_> = tr.state.parcels.iter().filter(|p| p.status != Status::Escaped).collect();
    let pos: Vec<Vec3> = ps.iter().map(|p| p.pos).collect();
    let rel = format!("parcels/parcels_{k:05}.vtu");
    Vtu::point_cloud(&pos)
        .point_vector("velocity_m_s", &ps.iter().map(|p| p.vel).collect::<Vec<_>>())
        .point_scalar("diameter_m", &ps.iter().map(|p| p.diameter).collect::<Vec<_>>())
        .point_scalar("particles", &ps.iter().map(|p| p.count).collect::<Vec<_>>())
        .point_int(
            "status",
            &ps.iter().map(|p| if p.status == Status::Airborne { 0 } else { 1 }).collect::<Vec<_>>(),
        )
        .point_int("id", &ps.iter().map(|p| p.id as i64).collect::<Vec<_>>())
        .write(&ctx.dir.path(&rel))?;
    pvd.push(tr.state.time, &rel)
}

/// Runs a deposition scenario.
pub fn run(cfg: &DepositionConfig, ctx: &RunContext) -> Result<RunSummary, DepositionError> {
    // Scenario files are validated by the loader; a configuration built in Rust is checked here (a zero
    // dt_s would otherwise mean u64::MAX steps).
    Checker::run(cfg, None).map_err(DepositionError::Invalid)?;
    let field = build_field(cfg)?;
    let bodies = build_bodies(cfg, &field)?;
    let settings = TrackSettings {
        dt: cfg.time.dt_s,
        domain: cfg.domain.map(|d| Aabb::new(d.min_m, d.max_m)),
        dispersion: cfg.dispersion,
        max_bounces: 8,
        resort_interval: 20,
    };
    if cfg.dispersion.is_some() && !field.has_turbulence() {
        tracing::warn!("dispersion is on but the flow field has no k and ε: the random walk does nothing");
    }
    if cfg.forces.wall_lift.is_some() && cfg.bodies.is_empty() {
        tracing::warn!("forces.wall_lift is on but there are no [[bodies]]: the wall lift does nothing");
    }
    let model = ForceModel::new(cfg.fluid, cfg.forces.clone());
    let mut tr = Tracker::new(field, model, settings, bodies);
    let mut injectors: Vec<Injector> = cfg
        .injectors
        .iter()
        .enumerate()
        .map(|(i, s)| Injector::new(s.clone(), i as u64))
        .collect::<Result<_, _>>()?;
    let csv_path = ctx.dir.path("balance.csv");
    let pvd_path = ctx.dir.path("parcels.pvd");
    let ckpt = ctx.dir.checkpoint_path();
    let mut next_output = 0u64;
    let (mut csv, mut pvd) = if ctx.resume && ckpt.is_file() {
        let c: Checkpoint = ctx.load_checkpoint().map_err(|e| DepositionError::Checkpoint(e.to_string()))?;
        tr.state = c.state;
        for (inj, st) in injectors.iter_mut().zip(&c.injectors) {
            inj.restore(st);
        }
        next_output = c.next_output;
        let mut pvd = PvdSeries::load_or_new(&pvd_path)?;
        pvd.truncate_after(tr.state.time)?;
        (CsvSeries::resume(&csv_path, &BALANCE_COLUMNS, c.csv_bytes)?, pvd)
    } else {
        (CsvSeries::create(&csv_path, &BALANCE_COLUMNS)?, PvdSeries::new(&pvd_path))
    };
    let dt = cfg.time.dt_s;
    let n_steps = (cfg.time.duration_s / dt).round() as u64;
    let interval = cfg.output.interval_s;
    let injection_end = cfg.injectors.iter().map(|i| i.end_s).fold(0.0, f64::max);
    let output_due = |t: f64, k: u64| t >= k as f64 * interval - 1e-9 * dt;
    let write_outputs =
        |tr: &Tracker<Field>, k: &mut u64, csv: &mut CsvSeries, pvd: &mut PvdSeries| -> std::io::Result<()> {
            csv.row(&balance_row(tr))?;
            if cfg.output.parcels {
                write_parcels(tr, ctx, *k, pvd)?;
            }
            *k += 1;
            Ok(())
        };
    if tr.state.step == 0 && next_output == 0 {
        write_outputs(&tr, &mut next_output, &mut csv, &mut pvd)?;
    }
    let mut finished = Finished::Completed;
    let mut last_written_step = u64::MAX;
    while tr.state.step < n_steps {
        let stop = ctx.control.stop_requested();
        if stop || ctx.checkpoint_due() {
            csv.flush()?;
            let c = Checkpoint {
                state: tr.state.clone(),
                injectors: injectors.iter().map(Injector::state).collect(),
                next_output,
                csv_bytes: csv.bytes_written(),
            };
            ctx.save_checkpoint(&c).map_err(|e| DepositionError::Checkpoint(e.to_string()))?;
            if stop {
                finished = Finished::Interrupted;
                break;
            }
        }
        let t_end = tr.state.time + dt;
        for (i, inj) in injectors.iter_mut().enumerate() {
            inj.release(t_end, |p| tr.add(p, i as u16));
        }
        tr.step()?;
        if output_due(tr.state.time, next_output) {
            write_outputs(&tr, &mut next_output, &mut csv, &mut pvd)?;
            last_written_step = tr.state.step;
        }
        ctx.control.progress(tr.state.step, n_steps);
        let all_released = injectors.iter().all(|i| i.released == i.total());
        if cfg.time.stop_when_settled && all_released && tr.state.time >= injection_end && tr.airborne() == 0
        {
            break;
        }
    }
    if finished == Finished::Interrupted {
        let mut s = RunSummary::new(Finished::Interrupted);
        s.headline.push(format!(
            "stopped at t = {:.6} s (step {} of {n_steps}); checkpoint written to {}",
            tr.state.time,
            tr.state.step,
            ckpt.display()
        ));
        // The deposit so far, so an interrupted run still shows where things landed; a resumed run
        // rewrites these files when it ends (identical to an uninterrupted run).
        if !cfg.bodies.is_empty() {
            write_bodies(cfg, &tr, ctx, &mut s, Some(tr.state.time))?;
            let note = format!(
                "PARTIAL deposit outputs (bodies/*.vtu, *_deposit.png, deposit_summary.csv) written from the \
                 deposits up to t = {:.6} s; `--resume` continues the run and replaces them at its end",
                tr.state.time
            );
            // The summary lines go to the log (and the screen) through the runner.
            s.headline.push(note);
        }
        return Ok(s);
    }
    if last_written_step != tr.state.step {
        write_outputs(&tr, &mut next_output, &mut csv, &mut pvd)?;
    }
    csv.flush()?;
    let mut summary = RunSummary::new(Finished::Completed);
    summary.artifacts.push(("mass balance".into(), csv_path.clone()));
    if cfg.output.parcels {
        summary.artifacts.push(("parcel snapshots".into(), pvd_path.clone()));
    }
    write_bodies(cfg, &tr, ctx, &mut summary, None)?;
    let b = &tr.state.balance;
    let (inj, rhs) = tr.mass_balance();
    let line = format!(
        "t = {:.6} s: injected {} parcels ({:.6e} kg) = deposited {} ({:.6e} kg) + escaped {} ({:.6e} kg) + airborne {} ({:.6e} kg); residual {:e} kg",
        tr.state.time,
        b.n_injected,
        inj,
        b.n_deposited,
        b.deposited.value(),
        b.n_escaped,
        b.escaped.value(),
        tr.airborne(),
        tr.airborne_mass().value(),
        inj - rhs
    );
    summary.headline.insert(0, line);
    for (name, value) in [
        ("t_end_s", tr.state.time),
        ("injected_parcels", b.n_injected as f64),
        ("injected_kg", inj),
        ("deposited_parcels", b.n_deposited as f64),
        ("deposited_kg", b.deposited.value()),
        ("escaped_parcels", b.n_escaped as f64),
        ("escaped_kg", b.escaped.value()),
        ("airborne_parcels", tr.airborne() as f64),
        ("airborne_kg", tr.airborne_mass().value()),
        ("mass_balance_residual_kg", inj - rhs),
    ] {
        summary.scalar(name, value);
    }
    let _ = std::fs::remove_file(&ckpt);
    Ok(summary)
}

/// Writes every body's VTU and picture and `deposit_summary.csv` from the deposits so far; `partial` is
/// the time of an interrupted run (named in the picture titles and the summary lines).
fn write_bodies(
    cfg: &DepositionConfig,
    tr: &Tracker<Field>,
    ctx: &RunContext,
    summary: &mut RunSummary,
    partial: Option<f64>,
) -> Result<(), DepositionError> {
    let partial_note = partial.map(|t| format!(" (partial, t = {t:.6} s)")).unwrap_or_default();
    let mut rows = Vec::new();
    for (k, (body, spec)) in tr.bodies.iter().zip(&cfg.bodies).enumerate() {
        let d = &tr.state.deposits[k];
        let m = &body.mesh;
        let areas: Vec<f64> = (0..m.triangles.len()).map(|t| m.area(t)).collect();
        let mpa = d.mass_per_area(&areas);
        let rel = format!("bodies/{}.vtu", body.name);
        Vtu::triangles(&m.vertices, &m.triangles)
            .cell_scalar("deposited_mass_kg", &d.mass)
            .cell_scalar("mass_per_area_kg_m2", &mpa)
            .cell_scalar("deposited_particles", &d.particles)
            .cell_int("impacts", &d.impacts.iter().map(|&i| i as i64).collect::<Vec<_>>())
            .cell_scalar("impact_particles", &d.impact_particles)
            .cell_scalar("mean_normal_speed_m_s", &d.mean_vn())
            .cell_scalar("mean_tangential_speed_m_s", &d.mean_vt())
            .cell_scalar("mean_impact_angle_deg", &d.mean_angle_deg())
            .cell_scalar("wall_shear_estimate_pa", &body.wall_shear)
            .write(&ctx.dir.path(&rel))?;
        summary.artifacts.push((format!("{} deposit (VTU)", body.name), ctx.dir.path(&rel)));
        // The picture's values and the VTU array that holds them (a study redraws it from there).
        let (values, label, array) = match cfg.output.picture_quantity {
            PictureQuantity::MassPerArea => {
                (mpa.clone(), "deposited mass per area [kg/m²]", "mass_per_area_kg_m2")
            }
            PictureQuantity::Impacts => {
                (d.impacts.iter().map(|&i| i as f64).collect(), "impacts [parcels]", "impacts")
            }
            PictureQuantity::MeanNormalSpeed => {
                (d.mean_vn(), "mean normal impact speed [m/s]", "mean_normal_speed_m_s")
            }
        };
        let png = ctx.dir.path(&format!("{}_deposit.png", body.name));
        let title = format!("{}: {}{partial_note}", body.name, label.split(" [").next().unwrap_or(label));
        spatter_io::plot::mesh_map_png(&png, m, &values, spec.view_direction, spec.view_up, &title, label)?;
        summary.artifacts.push((format!("{} deposit (PNG)", body.name), png));
        summary.maps.push(MeshMapRecord {
            label: format!("{} deposit", body.name),
            vtu: ctx.dir.path(&rel),
            array: array.to_owned(),
            view_dir: spec.view_direction.to_array(),
            up: spec.view_up.to_array(),
            title,
            colorbar_label: label.to_owned(),
            scale: None,
        });
        let mass: f64 = d.mass.iter().sum();
        let area: f64 = areas.iter().sum();
        let impacts: u64 = d.impacts.iter().sum();
        let peak = mpa.iter().copied().fold(0.0, f64::max);
        summary.headline.push(format!(
            "{}: deposited {:.4e} kg on {:.4e} m² ({} impacts), peak {:.4e} kg/m²{partial_note}",
            body.name, mass, area, impacts, peak
        ));
        summary.scalar(&format!("{}_deposited_kg", body.name), mass);
        summary.scalar(&format!("{}_impacts", body.name), impacts as f64);
        summary.scalar(&format!("{}_mean_mass_per_area_kg_m2", body.name), mass / area);
        summary.scalar(&format!("{}_peak_mass_per_area_kg_m2", body.name), peak);
        rows.push(vec![
            body.name.clone(),
            spatter_io::fmt_f64(mass),
            spatter_io::fmt_f64(d.particles.iter().sum()),
            impacts.to_string(),
            spatter_io::fmt_f64(area),
            spatter_io::fmt_f64(mass / area),
            spatter_io::fmt_f64(peak),
        ]);
    }
    if !rows.is_empty() {
        let p = ctx.dir.path("deposit_summary.csv");
        spatter_io::csv::write_table(
            &p,
            &[
                "body",
                "deposited_kg",
                "deposited_particles",
                "impacts",
                "area_m2",
                "mean_mass_per_area_kg_m2",
                "peak_mass_per_area_kg_m2",
            ],
            &rows,
        )?;
        summary.artifacts.push(("deposit summary".into(), p));
    }
    Ok(())
}
