//! `run(cfg, ctx)`: the four modes of the `snow_regime_map` scenario, parallel over impacts, stoppable
//! and resumable.
//!
//! Work is a list of independent jobs (impacts, or one bisection per diameter) done in chunks with rayon.
//! Between chunks the run polls [`RunControl::stop_requested`]; on a stop it saves the finished results in
//! `checkpoint.bin` and returns [`Finished::Interrupted`]. On resume it reloads them and continues with
//! the next job. Every job is deterministic and independent of the thread count, so a resumed run writes
//! the same files as an uninterrupted one.

use super::bed::{random_insertion, settled, wilson_interval, Bed};
use super::bed_index::BedIndex;
use super::bisection::{critical_speed, CriticalSpeed};
use super::cases::{case_config, model_of};
use super::config::{Mode, Packing, SnowConfig};
use super::error::SnowError;
use super::material::TimeStepReport;
use super::model::{ImpactModel, Surface};
use super::output::{self, Axes, INTERFACE_RGB};
use super::regime::{self, grid_jobs, run_job, ImpactRecord};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::check::Checker;
use spatter_core::control::Finished;
use spatter_core::rng::{seeded, RngExt};
use spatter_core::Vec3;
use spatter_dem::adhesion::tabor_parameter;
use spatter_dem::restitution_models::RestitutionModel;
use spatter_io::plot::Chart;
use spatter_io::run::{RunContext, RunSummary};

/// What `checkpoint.bin` holds (its header names the input it belongs to: a resume with another
/// configuration is refused when it is loaded).
#[derive(Serialize, Deserialize)]
struct Progress {
    records: Vec<ImpactRecord>,
    critical: Vec<CriticalSpeed>,
}

/// Does the jobs not yet in `done(p)` in chunks, polling between chunks for a stop (returns
/// [`Finished::Interrupted`]) and for a periodic checkpoint (saves `p` and carries on).
fn run_chunks<J: Sync, R: Send>(
    jobs: &[J],
    p: &mut Progress,
    done: fn(&mut Progress) -> &mut Vec<R>,
    chunk: usize,
    ctx: &RunContext<'_>,
    f: impl Fn(&J) -> R + Sync,
) -> Result<Finished, SnowError> {
    while done(p).len() < jobs.len() {
        if ctx.control.stop_requested() {
            return Ok(Finished::Interrupted);
        }
        if ctx.checkpoint_due() {
            save_progress(p, ctx)?;
        }
        let start = done(p).len();
        let end = (start + chunk).min(jobs.len());
        let new: Vec<R> = jobs[start..end].par_iter().map(&f).collect();
        done(p).extend(new);
        ctx.control.progress(end as u64, jobs.len() as u64);
    }
    Ok(Finished::Completed)
}

fn load_progress(ctx: &RunContext<'_>) -> Result<Progress, SnowError> {
    let fresh = Progress { records: Vec::new(), critical: Vec::new() };
    if !ctx.resume || !ctx.dir.checkpoint_path().exists() {
        return Ok(fresh);
    }
    ctx.load_checkpoint().map_err(|e| SnowError::Checkpoint(e.to_string()))
}

fn save_progress(p: &Progress, ctx: &RunContext<'_>) -> Result<(), SnowError> {
    ctx.save_checkpoint(p).map_err(|e| SnowError::Checkpoint(e.to_string()))
}

fn interrupted(p: &Progress, ctx: &RunContext<'_>, total: usize) -> Result<RunSummary, SnowError> {
    let path = ctx.dir.checkpoint_path();
    save_progress(p, ctx)?;
    let mut s = RunSummary::new(Finished::Interrupted);
    s.headline.push(format!(
        "stopped after {} of {total} jobs; checkpoint written to {}",
        p.records.len().max(p.critical.len()),
        path.display()
    ));
    Ok(s)
}

fn completed(ctx: &RunContext<'_>) {
    let _ = std::fs::remove_file(ctx.dir.checkpoint_path());
}

/// Runs the `snow_regime_map` scenario `cfg` into `ctx.dir`.
pub fn run(cfg: &SnowConfig, ctx: &RunContext<'_>) -> Result<RunSummary, SnowError> {
    Checker::run(cfg, None).map_err(SnowError::Invalid)?;
    let cfg = &cfg.resolved();
    let dt_warning = super::dt_guard::warning(cfg);
    if let Some(w) = &dt_warning {
        tracing::warn!("{w}");
    }
    let mut summary = match cfg.mode {
        Mode::Grid => run_grid(cfg, ctx)?,
        Mode::Bisection => run_bisection(cfg, ctx)?,
        Mode::Sensitivity => run_sensitivity(cfg, ctx)?,
        Mode::RoughWall => run_rough_wall(cfg, ctx)?,
        Mode::Single => run_single(cfg, ctx)?,
    };
    if summary.finished == Finished::Completed {
        let mut lines = material_report(cfg);
        if let Some(w) = dt_warning {
            lines.push(format!("warning: {w}"));
        }
        lines.append(&mut summary.headline);
        summary.headline = lines;
        let log = summary.headline.join("\n") + "\n";
        summary.artifacts.push(("summary".into(), ctx.dir.write_text("snow_summary.txt", &log)?));
        completed(ctx);
    }
    Ok(summary)
}

/// The contact numbers printed for one diameter of a run: the effective quantities of the particle and the
/// target it actually hits, and what follows from them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactReport {
    /// Particle diameter \[m\].
    pub diameter: f64,
    /// Speed the Hertz time is quoted at \[m/s\] (the run's highest normal speed).
    pub speed: f64,
    /// E* of the particle–target pair \[Pa\].
    pub e_star: f64,
    /// R* = R₁R₂/(R₁ + R₂) \[m\] (R for the flat wall).
    pub r_star: f64,
    /// m* = m₁m₂/(m₁ + m₂) \[kg\] (m for a frozen target).
    pub m_star: f64,
    /// Tabor parameter at z₀ = 0.4 nm and 0.2 nm \[-\].
    pub tabor: (f64, f64),
    /// Thesis Eq. 24, Rayleigh and Hertz (at `speed`, with E*, R*, m*) time estimates \[s\].
    pub times: TimeStepReport,
    /// Time step the run uses \[s\].
    pub dt: f64,
}

/// The target the run's impacts hit: the bed spheres in rough-wall mode, else the configured target.
fn report_points(cfg: &SnowConfig) -> (Vec<f64>, f64, Option<f64>) {
    match cfg.mode {
        Mode::RoughWall => {
            let v = cfg.rough_wall.speed_axis(cfg.grid.velocity_scale_m_s);
            (
                vec![cfg.rough_wall.particle_diameter_m],
                v.last().copied().unwrap_or(1.0),
                Some(0.5 * cfg.rough_wall.bed_sphere_diameter_m),
            )
        }
        Mode::Single => (vec![cfg.single.diameter_m], cfg.single.normal_speed_m_s, None),
        _ => {
            let d = cfg.grid.diameter_axis();
            let mut ds = vec![d[0]];
            if d[d.len() - 1] != d[0] {
                ds.push(d[d.len() - 1]);
            }
            (ds, cfg.grid.speed_range().1, None)
        }
    }
}

/// Contact numbers at the smallest and largest diameter of the run, for the target the impacts hit (flat
/// wall, frozen wall sphere, free particle or rough-wall bed sphere). E*, R* and m* come from
/// [`ImpactModel::setup`], the numbers the impacts use.
pub fn contact_reports(cfg: &SnowConfig) -> Vec<ContactReport> {
    let (ds, speed, bed_radius) = report_points(cfg);
    let model = model_of(cfg);
    let empty = BedIndex::default();
    let surface = match bed_radius {
        Some(rp) => Surface::Bed { spheres: &[], top: 0.0, sphere_radius: rp, index: &empty },
        None => Surface::Configured,
    };
    let g = cfg.contact.work_of_adhesion_j_m2;
    ds.iter()
        .map(|&d| {
            let (_, s) = model.setup(d, speed, surface);
            ContactReport {
                diameter: d,
                speed,
                e_star: s.e_star,
                r_star: s.r_star,
                m_star: s.m_star,
                tabor: (
                    tabor_parameter(s.r_star, g, s.e_star, 0.4e-9),
                    tabor_parameter(s.r_star, g, s.e_star, 0.2e-9),
                ),
                times: TimeStepReport::new(d, &cfg.particle, s.e_star, s.r_star, s.m_star, speed),
                dt: s.dt,
            }
        })
        .collect()
}

/// Effective contact quantities, Tabor parameter and time-step estimates at the smallest and largest
/// diameter (printed for every run).
pub fn material_report(cfg: &SnowConfig) -> Vec<String> {
    let target = match (cfg.mode, cfg.target) {
        (Mode::RoughWall, _) => "a rough-wall bed sphere",
        (_, super::config::TargetKind::Wall) => "the flat wall",
        (_, super::config::TargetKind::WallSphere) => "a frozen wall sphere",
        (_, super::config::TargetKind::Particle) => "a free partner particle",
    };
    let mut out = Vec::new();
    if let Some(t) = cfg.ice_temperature_c {
        out.push(format!(
            "particle Young's modulus from ice_temperature_c = {t} °C (thesis Eq. 20): {:.5e} Pa",
            super::material::ice_youngs_modulus(t)
        ));
    }
    for c in contact_reports(cfg) {
        out.push(format!(
            "contact at d = {:.3e} m with {target}: E* = {:.5e} Pa, R* = {:.5e} m, m* = {:.5e} kg; Tabor parameter (z0 = 0.4 / 0.2 nm) {:.3} / {:.3} (JKR valid above 5)",
            c.diameter, c.e_star, c.r_star, c.m_star, c.tabor.0, c.tabor.1
        ));
        out.push(format!(
            "time steps at d = {:.3e} m: thesis Eq. 24 {:.4e} s, Rayleigh {:.4e} s, Hertz time at {:.3} m/s {:.4e} s; used {:.4e} s",
            c.diameter, c.times.thesis_eq24, c.times.rayleigh, c.speed, c.times.hertz, c.dt
        ));
    }
    out
}

/// Largest relative difference of the critical speeds of `points` from those of `base` at the diameters
/// both have (`[d, v_crit]` pairs); `None` when they share none or a diameter is missing from `base`.
fn boundary_deviation(points: &[[f64; 2]], base: &[[f64; 2]]) -> Option<f64> {
    if points.is_empty() {
        return None;
    }
    let mut dev: f64 = 0.0;
    for p in points {
        let b = base.iter().find(|b| b[0] == p[0])?;
        dev = dev.max((p[1] / b[1] - 1.0).abs());
    }
    Some(dev)
}

/// Adds the energy check of `impacts` simulated impacts, `created` of which left with more kinetic energy
/// than they came with (a numerical failure), to the summary; warns when there are any. `marked` names
/// the file and column where they are flagged.
/// Study scalars of a set of impacts: how many, the fraction that stuck, how many created energy.
fn impact_scalars(s: &mut RunSummary, prefix: &str, records: &[ImpactRecord]) {
    let n = records.len();
    let stuck = records.iter().filter(|r| r.result.outcome == super::impact::Outcome::Stick).count();
    s.scalar(&format!("{prefix}impacts"), n as f64);
    s.scalar(&format!("{prefix}stick_fraction"), if n > 0 { stuck as f64 / n as f64 } else { 0.0 });
    let created = records.iter().filter(|r| r.result.created_energy()).count();
    s.scalar(&format!("{prefix}energy_created_impacts"), created as f64);
}

fn energy_check(s: &mut RunSummary, created: usize, impacts: usize, marked: &str) {
    if created == 0 && impacts == 1 {
        s.headline
            .push("energy check: the impact did not leave with more kinetic energy than it came with".into());
    } else if created == 0 {
        s.headline.push(format!(
            "energy check: none of {impacts} impacts left with more kinetic energy than it came with"
        ));
    } else {
        let msg = format!(
            "warning: {created} of {impacts} impacts left with more kinetic energy than they came with (by more \
             than 0.1 %): energy created by the time integration, a numerical failure, so their outcomes are \
             not to be trusted ({marked}); reduce the time step (docs/snow.md §3)"
        );
        tracing::warn!("{msg}");
        s.headline.push(msg);
    }
}

fn description(cfg: &SnowConfig, extra: &str) -> String {
    format!(
        "snow_regime_map {extra}: particle E = {} Pa, nu = {}, rho = {} kg/m3 on {:?} (wall E = {} Pa, nu = {}); \
         {:?} normal law, work of adhesion {} J/m2, break {:?}, damping {:?}/{:?}, restitution {:?}",
        cfg.particle.youngs_modulus,
        cfg.particle.poisson_ratio,
        cfg.particle.density,
        cfg.target,
        cfg.wall.youngs_modulus,
        cfg.wall.poisson_ratio,
        cfg.contact.normal_law,
        cfg.contact.work_of_adhesion_j_m2,
        cfg.contact.break_criterion,
        cfg.contact.damping_stiffness,
        cfg.contact.damping_calibration,
        cfg.contact.restitution
    )
}

/// Chunk size for `jobs` jobs: enough work per chunk for every thread, at least eight chunks per run so a
/// stop request is answered promptly.
fn chunk_size(jobs: usize) -> usize {
    (jobs / 8).clamp(1, 64 * rayon::current_num_threads().max(1))
}

fn run_grid(cfg: &SnowConfig, ctx: &RunContext<'_>) -> Result<RunSummary, SnowError> {
    let jobs = grid_jobs(&cfg.grid);
    let model = model_of(cfg);
    let mut p = load_progress(ctx)?;
    ctx.control.status("snow regime map: grid");
    if run_chunks(&jobs, &mut p, |p| &mut p.records, chunk_size(jobs.len()), ctx, |j| run_job(&model, j))?
        == Finished::Interrupted
    {
        return interrupted(&p, ctx, jobs.len());
    }
    let axes = Axes::of(&cfg.grid);
    let mut s = RunSummary::new(Finished::Completed);
    let impacts = ctx.dir.path("impacts.csv");
    output::write_impacts(&impacts, &[(0, &p.records)])?;
    s.artifacts.push(("every impact".into(), impacts));
    let created = p.records.iter().filter(|r| r.result.created_energy()).count();
    energy_check(&mut s, created, p.records.len(), "energy_created = 1 in impacts.csv");
    s.scalar("energy_created_impacts", created as f64);
    let n_d = cfg.grid.diameters;
    let n_v = cfg.grid.normal_speeds;
    for (ai, angle) in cfg.grid.angles_deg.iter().enumerate() {
        let recs = &p.records[ai * n_d * n_v..(ai + 1) * n_d * n_v];
        let iface = regime::interface(&p.records, n_d, n_v, ai);
        let suffix = if cfg.grid.angles_deg.len() > 1 { format!("_angle{ai}") } else { String::new() };
        // Refinement bisects normal impacts, so it applies to the normal-impact angle only.
        let points = if cfg.grid.refine_interface && *angle == 0.0 {
            regime::refine(&model, &iface.brackets, cfg.bisection.relative_tolerance)
        } else {
            iface.points.clone()
        };
        let ipath = ctx.dir.path(&format!("interface{suffix}.csv"));
        output::write_interface(&ipath, &iface.brackets, &points, &axes)?;
        s.artifacts.push((format!("interface points at {angle} deg"), ipath));
        let map =
            regime::regime_map(&points, &cfg.fit, description(cfg, &format!("grid, angle {angle} deg")));
        if ai == 0 {
            if let Some(m) = &map {
                let jpath = ctx.dir.path("regime_map.json");
                output::write_regime_map(&jpath, m)?;
                s.artifacts.push(("wall rule (regime_map.json)".into(), jpath));
                s.headline.push(fit_line("v_crit(d)", &m.v_crit_of_d));
                s.headline.push(fit_line("d_crit(v_n)", &m.d_crit_of_vn));
            } else {
                s.headline
                    .push("no stick/bounce interface inside the grid: no regime_map.json written".into());
            }
        }
        if ai == 0 && *angle == 0.0 {
            // The two impacts either side of the boundary at the smallest diameter, for ParaView.
            if let Some(b) = iface.brackets.first() {
                let picks = [(b[0], b[1], "stick"), (b[0], b[2], "bounce")];
                s.artifacts.extend(super::samples::write_sample_impacts(
                    &model,
                    Surface::Configured,
                    &picks,
                    ctx.dir,
                )?);
            }
        }
        if ai == 0 {
            s.scalar("stick_count", regime::stick_count(recs) as f64);
            s.scalar("impacts", recs.len() as f64);
            s.scalar("stick_fraction", regime::stick_count(recs) as f64 / recs.len().max(1) as f64);
            s.scalar("interface_diameters", iface.points.len() as f64);
        }
        let title = format!("Regime map, {} impacts at {angle} deg", recs.len());
        let chart = output::regime_chart(&title, recs, &points, map.as_ref().map(|m| &m.v_crit_of_d), &axes);
        let png = output::save_chart(&chart, ctx.dir, &format!("regime_map{suffix}"), cfg.svg)?;
        s.artifacts.push((format!("regime map picture at {angle} deg"), png));
        s.headline.push(format!(
            "angle {angle} deg: {} of {} impacts stick; interface at {} diameters, {} stick at every speed, {} bounce at every speed{}",
            regime::stick_count(recs),
            recs.len(),
            iface.points.len(),
            iface.all_stick.len(),
            iface.all_bounce.len(),
            if iface.non_monotone.is_empty() {
                String::new()
            } else {
                format!(", {} with more than one transition", iface.non_monotone.len())
            }
        ));
    }
    Ok(s)
}

fn fit_line(name: &str, f: &spatter_core::regime::PolyFit) -> String {
    format!(
        "fit {name} ({}log10 polynomial, degree {}): coefficients {:?} on [{:.4e}, {:.4e}], rms relative error {:.3} %",
        if f.log10 { "" } else { "non-" },
        f.coefficients.len() - 1,
        f.coefficients,
        f.x_range[0],
        f.x_range[1],
        100.0 * f.rms_relative_error
    )
}

fn run_bisection(cfg: &SnowConfig, ctx: &RunContext<'_>) -> Result<RunSummary, SnowError> {
    let ds = cfg.grid.diameter_axis();
    let (v_lo, v_hi) = cfg.grid.speed_range();
    let lo = cfg.bisection.speed_low_m_s.unwrap_or(v_lo);
    let hi = cfg.bisection.speed_high_m_s.unwrap_or(v_hi);
    let model = model_of(cfg);
    let mut p = load_progress(ctx)?;
    ctx.control.status("snow regime map: bisection");
    let tol = cfg.bisection.relative_tolerance;
    let exp = cfg.bisection.max_expansions;
    if run_chunks(
        &ds,
        &mut p,
        |p| &mut p.critical,
        chunk_size(ds.len()).min(4 * rayon::current_num_threads().max(1)),
        ctx,
        |&d| critical_speed(&model, d, lo, hi, tol, exp),
    )? == Finished::Interrupted
    {
        return interrupted(&p, ctx, ds.len());
    }
    let axes = Axes::of(&cfg.grid);
    let mut s = RunSummary::new(Finished::Completed);
    let cpath = ctx.dir.path("critical_speeds.csv");
    output::write_critical_speeds(&cpath, &p.critical)?;
    s.artifacts.push(("critical speed per diameter".into(), cpath));
    let points = regime::interface_from_bisection(&p.critical);
    let map = regime::regime_map(&points, &cfg.fit, description(cfg, "bisection"));
    if let Some(m) = &map {
        let jpath = ctx.dir.path("regime_map.json");
        output::write_regime_map(&jpath, m)?;
        s.artifacts.push(("wall rule (regime_map.json)".into(), jpath));
        s.headline.push(fit_line("v_crit(d)", &m.v_crit_of_d));
        s.headline.push(fit_line("d_crit(v_n)", &m.d_crit_of_vn));
    }
    let pts: Vec<(f64, f64)> = points.iter().map(|q| (axes.v(q[1]), axes.d(q[0]))).collect();
    let mut chart = Chart::new("Critical normal speed by bisection", &axes.v_label(), &axes.d_label())
        .markers("v_crit (bisection)", &pts, output::STICK_RGB);
    if let Some(m) = &map {
        chart =
            chart.line_colored("fitted boundary", &output::fit_curve(&m.v_crit_of_d, &axes), INTERFACE_RGB);
    }
    let png = output::save_chart(&chart, ctx.dir, "critical_speed", cfg.svg)?;
    s.artifacts.push(("critical speed picture".into(), png));
    let impacts: u32 = p.critical.iter().map(|c| c.impacts).sum();
    let created: u32 = p.critical.iter().map(|c| c.energy_created).sum();
    energy_check(
        &mut s,
        created as usize,
        impacts as usize,
        "counted per diameter in the energy_created column of critical_speeds.csv",
    );
    let found = points.len();
    s.headline.push(format!(
        "bisection: v_crit found for {found} of {} diameters with {impacts} impacts (relative tolerance {tol})",
        ds.len()
    ));
    if let (Some(a), Some(b)) = (points.first(), points.last()) {
        s.headline.push(format!(
            "v_crit = {:.4} m/s at d = {:.3e} m, {:.4} m/s at d = {:.3e} m",
            a[1], a[0], b[1], b[0]
        ));
    }
    // The stick count an equivalent grid would give (speeds k·Δv, one transition per diameter).
    let vs = cfg.grid.speed_axis();
    // Speeds at or below the highest sticking speed of each diameter stick.
    let grid_count: usize = p.critical.iter().map(|c| vs.iter().filter(|&&v| v <= c.low).count()).sum();
    s.headline.push(format!("equivalent grid stick count ({} speeds): {grid_count}", vs.len()));
    if let (Some(a), Some(b)) = (points.first(), points.last()) {
        s.scalar("v_crit_smallest_d_m_s", a[1]);
        s.scalar("v_crit_largest_d_m_s", b[1]);
        let mean_log = points.iter().map(|q| q[1].ln()).sum::<f64>() / points.len() as f64;
        s.scalar("v_crit_geometric_mean_m_s", mean_log.exp());
    }
    s.scalar("diameters_with_v_crit", found as f64);
    s.scalar("grid_stick_count", grid_count as f64);
    s.scalar("impacts", f64::from(impacts));
    s.scalar("energy_created_impacts", created as f64);
    // The critical speed at each diameter where the bisection found one, named by the diameter in µm
    // (rounded to 1e-6 µm so that a grid diameter such as 70 µm reads `70`, not `70.00000000000001`).
    for c in p.critical.iter().filter(|c| c.v_crit.is_finite()) {
        let um = (c.diameter * 1e12).round() / 1e6;
        s.scalar(&format!("v_crit_m_s_at_{}um", spatter_io::fmt_f64(um)), c.v_crit);
    }
    Ok(s)
}

/// A labelled boundary of the sensitivity picture: label, points, colour.
type BoundaryLine = (String, Vec<(f64, f64)>, (u8, u8, u8));

fn run_sensitivity(cfg: &SnowConfig, ctx: &RunContext<'_>) -> Result<RunSummary, SnowError> {
    let cases = &cfg.sensitivity.cases;
    let base_jobs = grid_jobs(&cfg.grid);
    let models: Vec<ImpactModel> = cases.iter().map(|c| model_of(&case_config(cfg, c))).collect();
    let jobs: Vec<(usize, usize)> =
        (0..cases.len()).flat_map(|c| (0..base_jobs.len()).map(move |j| (c, j))).collect();
    let mut p = load_progress(ctx)?;
    ctx.control.status("snow regime map: sensitivity study");
    if run_chunks(
        &jobs,
        &mut p,
        |p| &mut p.records,
        chunk_size(jobs.len()),
        ctx,
        |&(c, j)| run_job(&models[c], &base_jobs[j]),
    )? == Finished::Interrupted
    {
        return interrupted(&p, ctx, jobs.len());
    }
    let axes = Axes::of(&cfg.grid);
    let mut s = RunSummary::new(Finished::Completed);
    let n = base_jobs.len();
    let sets: Vec<(usize, &[ImpactRecord])> =
        (0..cases.len()).map(|c| (c, &p.records[c * n..(c + 1) * n])).collect();
    let ipath = ctx.dir.path("sensitivity_impacts.csv");
    output::write_impacts(&ipath, &sets)?;
    s.artifacts.push(("every impact of every case".into(), ipath));
    let created = p.records.iter().filter(|r| r.result.created_energy()).count();
    energy_check(&mut s, created, p.records.len(), "energy_created = 1 in sensitivity_impacts.csv");
    for (c, recs) in &sets {
        impact_scalars(&mut s, &format!("case{c}_"), recs);
    }
    let (n_d, n_v) = (cfg.grid.diameters, cfg.grid.normal_speeds);
    let mut rows = Vec::new();
    let mut chart = Chart::new(
        "Sensitivity study: stick/bounce boundaries (stick left of each line)",
        &axes.v_label(),
        &axes.d_label(),
    );
    s.headline.push(format!("{:<20} {:>8} {:>8}", "case", "sticks", "thesis"));
    let mut lines: Vec<BoundaryLine> = Vec::new();
    // Each boundary is refined by bisection as in grid mode, so the lines show the boundary rather than
    // the grid's steps, and the baseline's regime_map.json is the one grid mode writes.
    let refine = cfg.grid.refine_interface && cfg.grid.angles_deg.first() == Some(&0.0);
    let mut base_points: Vec<[f64; 2]> = Vec::new();
    for (c, case) in cases.iter().enumerate() {
        let recs = sets[c].1;
        let count = regime::stick_count(recs);
        let iface = regime::interface(recs, n_d, n_v, 0);
        let points = if refine {
            regime::refine(&models[c], &iface.brackets, cfg.bisection.relative_tolerance)
        } else {
            iface.points.clone()
        };
        let pts: Vec<(f64, f64)> = points.iter().map(|q| (axes.v(q[1]), axes.d(q[0]))).collect();
        // A boundary within 2 % of the baseline's lies under it in the picture: the label says so.
        let label = match boundary_deviation(&points, &base_points) {
            Some(dev) if c > 0 && dev <= 0.02 => {
                format!("{} ({count}; within {:.1} % of baseline)", case.name, 100.0 * dev)
            }
            _ => format!("{} ({count})", case.name),
        };
        if c == 0 {
            base_points = points.clone();
        }
        // The baseline is drawn last so that cases on top of it do not hide it.
        lines.push((label, pts, output::case_colour(c)));
        let cc = case_config(cfg, case);
        // The yield stress is undefined for a constant restitution: an empty cell.
        let sy = match cc.contact.restitution {
            RestitutionModel::Thornton { yield_stress_pa, .. } => format!("{yield_stress_pa}"),
            RestitutionModel::Constant { .. } => String::new(),
        };
        rows.push(vec![
            case.name.clone(),
            format!("{}", cc.particle.youngs_modulus),
            format!("{}", cc.particle.poisson_ratio),
            format!("{}", cc.contact.work_of_adhesion_j_m2),
            sy,
            format!("{count}"),
            case.thesis_sticks.map_or(String::new(), |t| t.to_string()),
            format!("{}", recs.len()),
        ]);
        s.headline.push(format!(
            "{:<20} {:>8} {:>8}",
            case.name,
            count,
            case.thesis_sticks.map_or("-".to_string(), |t| t.to_string())
        ));
        let map_chart =
            output::regime_chart(&format!("Regime map: {}", case.name), recs, &points, None, &axes);
        output::save_chart(&map_chart, ctx.dir, &format!("maps/case{c}"), false)?;
        if c == 0 {
            if let Some(m) = regime::regime_map(&points, &cfg.fit, description(cfg, "sensitivity baseline")) {
                let jpath = ctx.dir.path("regime_map.json");
                output::write_regime_map(&jpath, &m)?;
                s.artifacts.push(("baseline wall rule (regime_map.json)".into(), jpath));
            }
        }
    }
    if !lines.is_empty() {
        lines.rotate_left(1);
    }
    for (label, pts, rgb) in &lines {
        chart = chart.line_colored(label, pts, *rgb);
    }
    let tpath = ctx.dir.path("sensitivity.csv");
    spatter_io::csv::write_table(
        &tpath,
        &[
            "case",
            "particle_youngs_modulus_pa",
            "particle_poisson_ratio",
            "work_of_adhesion_j_m2",
            "yield_stress_pa",
            "sticks",
            "thesis_sticks",
            "impacts",
        ],
        &rows,
    )?;
    s.artifacts.push(("stick counts beside the thesis".into(), tpath));
    let png = output::save_chart(&chart, ctx.dir, "sensitivity_boundaries", cfg.svg)?;
    s.artifacts.push(("boundaries of every case".into(), png));
    s.headline.push(format!(
        "velocity scale {} m/s: grid speeds {:.4}..{:.4} m/s (normalised {:.3}..{:.3})",
        cfg.grid.velocity_scale_m_s,
        cfg.grid.speed_range().0,
        cfg.grid.speed_range().1,
        cfg.grid.speed_range().0 / cfg.grid.velocity_scale_m_s,
        cfg.grid.speed_range().1 / cfg.grid.velocity_scale_m_s
    ));
    Ok(s)
}

/// The rough-wall bed of `cfg`.
pub fn make_bed(cfg: &SnowConfig) -> Bed {
    let rw = &cfg.rough_wall;
    let mut rng = seeded(rw.seed, u64::MAX);
    match rw.packing {
        Packing::RandomInsertion => random_insertion(
            rw.bed_width(),
            rw.bed_thickness(),
            rw.bed_sphere_diameter_m,
            rw.volume_fraction,
            &mut rng,
        ),
        Packing::Settled => settled(
            rw.bed_width(),
            rw.bed_thickness(),
            rw.bed_sphere_diameter_m,
            rw.volume_fraction,
            &mut rng,
        ),
    }
}

/// Lateral aim point of rough-wall impact `k`: uniform in the central square of half the bed width.
pub fn aim_point(cfg: &SnowConfig, k: u64) -> [f64; 2] {
    let mut rng = seeded(cfg.rough_wall.seed, k);
    let half = 0.25 * cfg.rough_wall.bed_width();
    [(rng.random::<f64>() * 2.0 - 1.0) * half, (rng.random::<f64>() * 2.0 - 1.0) * half]
}

fn run_rough_wall(cfg: &SnowConfig, ctx: &RunContext<'_>) -> Result<RunSummary, SnowError> {
    let rw = &cfg.rough_wall;
    let bed = make_bed(cfg);
    let speeds = rw.speed_axis(cfg.grid.velocity_scale_m_s);
    let d = rw.particle_diameter_m;
    let model = model_of(cfg);
    let index = BedIndex::new(&bed.spheres);
    let surface = Surface::bed(&bed, &index);
    let jobs: Vec<(usize, usize)> =
        (0..speeds.len()).flat_map(|i| (0..rw.impacts_per_speed).map(move |k| (i, k))).collect();
    let mut p = load_progress(ctx)?;
    ctx.control.status("snow regime map: rough wall");
    let run_one = |&(i, k): &(usize, usize)| {
        let aim = aim_point(cfg, (i * rw.impacts_per_speed + k) as u64);
        let (result, setup) = model.simulate(d, speeds[i], 0.0, aim, surface);
        ImpactRecord {
            diameter: d,
            normal_speed: speeds[i],
            tangential_speed: 0.0,
            angle_deg: 0.0,
            aim,
            result,
            restitution_input: setup.restitution_input,
            dt: setup.dt,
            hertz_time: setup.hertz_time,
        }
    };
    if run_chunks(&jobs, &mut p, |p| &mut p.records, chunk_size(jobs.len()), ctx, run_one)?
        == Finished::Interrupted
    {
        return interrupted(&p, ctx, jobs.len());
    }
    let mut s = RunSummary::new(Finished::Completed);
    let ipath = ctx.dir.path("rough_impacts.csv");
    output::write_impacts(&ipath, &[(0, &p.records)])?;
    s.artifacts.push(("every rough-wall impact".into(), ipath));
    let created = p.records.iter().filter(|r| r.result.created_energy()).count();
    energy_check(&mut s, created, p.records.len(), "energy_created = 1 in rough_impacts.csv");
    impact_scalars(&mut s, "", &p.records);
    // The bed for ParaView.
    let centres: Vec<Vec3> = bed.spheres.iter().map(|q| Vec3::from(q.centre)).collect();
    let radii: Vec<f64> = bed.spheres.iter().map(|q| q.radius).collect();
    let vtu = ctx.dir.path("bed.vtu");
    spatter_io::vtu::Vtu::point_cloud(&centres).point_scalar("radius_m", &radii).write(&vtu)?;
    s.artifacts.push(("rough-wall bed (VTU)".into(), vtu));
    // Flat-wall reference for the same particle.
    let mut flat = model.clone();
    flat.target = super::config::TargetKind::Wall;
    let v_flat = critical_speed(&flat, d, speeds[0], speeds[speeds.len() - 1], 1e-3, 6);
    let n = rw.impacts_per_speed;
    let mut csv = spatter_io::csv::CsvSeries::create(
        &ctx.dir.path("stick_probability.csv"),
        &[
            "normal_speed_m_s",
            "normal_speed_norm",
            "impacts",
            "sticks",
            "stick_probability",
            "wilson_low",
            "wilson_high",
            "at_rest",
            "at_rest_probability",
            "moving_in_contact",
        ],
    )?;
    let (mut est, mut lo_pts, mut hi_pts, mut rest_pts) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let ratio = cfg.integration.static_slip_ratio;
    // A stuck particle is "at rest" when its energy proved it bound or it no longer moves tangentially; on
    // a rough wall many grains that keep a contact at the check time still roll or slide across the bed.
    let at_rest = |r: &ImpactRecord| {
        r.sticks()
            && (r.result.decision == super::impact::Decision::Bound
                || r.result.tangential_speed <= ratio * r.normal_speed)
    };
    let v_scale = cfg.grid.velocity_scale_m_s;
    let mut any_stick_max: Option<f64> = None;
    for (i, &v) in speeds.iter().enumerate() {
        let recs = &p.records[i * n..(i + 1) * n];
        let k = recs.iter().filter(|r| r.sticks()).count();
        let rest = recs.iter().filter(|r| at_rest(r)).count();
        let (ph, lo, hi) = wilson_interval(k, n, rw.confidence);
        let p_rest = rest as f64 / n as f64;
        csv.row(&[v, v / v_scale, n as f64, k as f64, ph, lo, hi, rest as f64, p_rest, (k - rest) as f64])?;
        est.push((v, ph));
        rest_pts.push((v, p_rest));
        lo_pts.push((v, lo));
        hi_pts.push((v, hi));
        if k > 0 {
            any_stick_max = Some(v);
        }
    }
    csv.flush()?;
    s.artifacts
        .push(("stick probability with Wilson intervals".into(), ctx.dir.path("stick_probability.csv")));
    // Diameters in µm, to the nm.
    let um = |x: f64| (x * 1e9).round() / 1e3;
    let (y0, y1) = output::y_range_with_legend(0.0, 1.0, 4);
    let mut chart = Chart::new(
        &format!(
            "Stick probability of a {} µm grain on a bed of {} µm spheres",
            um(d),
            um(rw.bed_sphere_diameter_m)
        ),
        "normal impact speed [m/s]",
        "stick probability",
    )
    .log_x()
    .y_range(y0.max(-0.02), y1)
    .line_colored("stick probability (contact at check time)", &est, output::STICK_RGB)
    .markers("", &est, output::STICK_RGB)
    .dashed(&format!("Wilson {} % interval", 100.0 * rw.confidence), &lo_pts, (120, 120, 120))
    .dashed("", &hi_pts, (120, 120, 120))
    .line_colored("stuck and at rest", &rest_pts, (120, 0, 160));
    if v_flat.v_crit.is_finite() {
        chart = chart.dashed(
            "flat-wall v_crit",
            &[(v_flat.v_crit, 0.0), (v_flat.v_crit, 1.0)],
            output::BOUNCE_RGB,
        );
    }
    let png = output::save_chart(&chart, ctx.dir, "stick_probability", cfg.svg)?;
    s.artifacts.push(("stick probability picture".into(), png));
    s.headline.push(format!(
        "rough wall: {} spheres of {:.3e} m ({:?}, nominal volume fraction {:.3}), bed top {:.3e} m, width {:.3e} m",
        bed.spheres.len(),
        rw.bed_sphere_diameter_m,
        rw.packing,
        bed.nominal_fraction,
        bed.top,
        bed.width
    ));
    let moving: usize = p.records.iter().filter(|r| r.sticks() && !at_rest(r)).count();
    s.headline.push(format!(
        "{moving} of {} stuck impacts were still rolling or sliding across the bed at the check time",
        p.records.iter().filter(|r| r.sticks()).count()
    ));
    s.headline.push(format!(
        "{} impacts per speed at {} speeds; highest speed with a stick: {}; flat-wall v_crit for the same particle {:.4} m/s",
        n,
        speeds.len(),
        any_stick_max.map_or("none".into(), |v| format!("{v:.4} m/s ({:.4} normalised)", v / v_scale)),
        v_flat.v_crit
    ));
    Ok(s)
}

fn run_single(cfg: &SnowConfig, ctx: &RunContext<'_>) -> Result<RunSummary, SnowError> {
    use super::config::NormalLawKind;
    let sc = &cfg.single;
    let model = model_of(cfg);
    let mut trace = Vec::new();
    let (r, setup) = model.simulate_traced(
        sc.diameter_m,
        sc.normal_speed_m_s,
        sc.tangential_speed_m_s,
        [0.0, 0.0],
        Surface::Configured,
        Some(&mut trace),
    );
    let mut s = RunSummary::new(Finished::Completed);
    let tpath = ctx.dir.path("trace.csv");
    let mut csv = spatter_io::csv::CsvSeries::create(
        &tpath,
        &["t_s", "overlap_m", "normal_force_N", "x_m", "z_m", "vx_m_s", "vz_m_s", "contacts"],
    )?;
    for p in &trace {
        // Without contact the overlap is undefined: an empty cell.
        csv.row_with_gaps(&[
            Some(p.t),
            p.overlap,
            Some(p.normal_force),
            Some(p.position[0]),
            Some(p.position[2]),
            Some(p.velocity[0]),
            Some(p.velocity[2]),
            Some(p.contacts as f64),
        ])?;
    }
    csv.flush()?;
    s.artifacts.push(("every time step".into(), tpath));
    // Force–overlap loop, normalised by the JKR scales when the law is JKR (thesis Fig. 6).
    let jkr = (cfg.contact.normal_law == NormalLawKind::Jkr && cfg.contact.work_of_adhesion_j_m2 > 0.0).then(
        || spatter_dem::adhesion::Jkr::new(setup.e_star, setup.r_star, cfg.contact.work_of_adhesion_j_m2),
    );
    let (fs, ds, xl, yl) = match &jkr {
        Some(j) => (j.pull_off_force, j.critical_overlap, "overlap / δ_c", "normal force / F_c"),
        None => (1.0, 1.0, "overlap [m]", "normal force [N]"),
    };
    let pts: Vec<(f64, f64)> =
        trace.iter().filter_map(|p| p.overlap.map(|o| (o / ds, p.normal_force / fs))).collect();
    let mut chart = Chart::new(
        &format!(
            "Force–overlap history: {} µm grain at {} m/s ({:?})",
            (sc.diameter_m * 1e9).round() / 1e3,
            sc.normal_speed_m_s,
            r.outcome
        ),
        xl,
        yl,
    )
    .line_colored("simulated (elastic + damping)", &pts, output::STICK_RGB);
    let mut curve: Vec<(f64, f64)> = Vec::new();
    if let Some(j) = &jkr {
        let d_max = pts.iter().map(|p| p.0).fold(0.0, f64::max).max(1.0);
        curve = (0..=400)
            .filter_map(|i| {
                let x = -1.0 + (d_max + 1.0) * i as f64 / 400.0;
                j.force(x * j.critical_overlap).map(|f| (x, f / j.pull_off_force))
            })
            .collect();
        chart = chart.dashed("JKR curve (elastic)", &curve, output::BOUNCE_RGB);
    }
    let (lo, hi) = pts
        .iter()
        .chain(&curve)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| (a.min(p.1), b.max(p.1)));
    if lo.is_finite() && hi.is_finite() {
        // Room for the legend above the loop, whose turning point (deepest overlap) is at the top right.
        let (y0, y1) = output::y_range_with_legend(lo, hi, if jkr.is_some() { 2 } else { 1 });
        chart = chart.y_range(y0, y1);
    }
    let png = output::save_chart(&chart, ctx.dir, "force_overlap", cfg.svg)?;
    s.artifacts.push(("force–overlap loop".into(), png));
    s.headline.push(format!(
        "single impact d = {:.3e} m, v_n = {} m/s, v_t = {} m/s: {:?} ({:?}), restitution input {:.4}, realised {:.4}, rebound/impact kinetic energy {:.4}, max overlap {:.4e} m, contact {:.4e} s, {} steps of {:.4e} s",
        sc.diameter_m,
        sc.normal_speed_m_s,
        sc.tangential_speed_m_s,
        r.outcome,
        r.decision,
        setup.restitution_input,
        r.restitution,
        r.energy_ratio,
        r.max_overlap,
        r.contact_duration,
        r.steps,
        setup.dt
    ));
    energy_check(&mut s, usize::from(r.created_energy()), 1, "see the kinetic energy ratio above");
    s.scalar("stuck", if r.outcome == super::impact::Outcome::Stick { 1.0 } else { 0.0 });
    s.scalar("restitution", r.restitution);
    s.scalar("energy_ratio", r.energy_ratio);
    s.scalar("max_overlap_m", r.max_overlap);
    s.scalar("contact_duration_s", r.contact_duration);
    Ok(s)
}
