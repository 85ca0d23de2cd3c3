//! Running an `sph` scenario: time loop, outputs, checkpoint and resume.
//!
//! On several ranks (`ctx.comm`, a run under `mpirun`) every rank steps its share of the fluid and joins
//! every collective sensor; rank 0 alone writes `series.csv`, the `.pvd`, the `.pvtu` of each output, the
//! walls, maps and tables; every rank writes its own piece of the particle output.
//!
//! Checkpoints: one rank writes its whole [`SceneState`] into `checkpoint.bin` (the format of one-rank
//! runs, unchanged). Several ranks write one part each ([`RankPart`]: the rank's state with its share of
//! the fluid and of the partial sums, and the split of space) and rank 0 a manifest
//! ([`spatter_io::rank_checkpoint`]). A resume on as many ranks continues bit for bit; with
//! `--repartition` the parts (or a one-rank checkpoint) are joined and split afresh over the ranks of the
//! new run, which then differs from an uninterrupted run at round-off level.

use super::build::{build_with, BuildInfo};
use super::config::SphConfig;
use serde::{Deserialize, Serialize};
use spatter_core::comm::Comm;
use spatter_core::control::Finished;
use spatter_core::rcb::Rcb;
use spatter_core::Vec3;
use spatter_io::csv::{write_table, CsvSeries};
use spatter_io::pvd::PvdSeries;
use spatter_io::rank_checkpoint::Resumed;
use spatter_io::run::{CurveRecord, MeshMapRecord, RunContext, RunSummary};
use spatter_io::vtu::Vtu;
use spatter_sph::error::SphError;
use spatter_sph::sim::Simulation;
use spatter_sph::wetting::{default_view, particle_map, particle_squares, wet_area, wetting_map};
use std::path::Path;
use std::time::Instant;

/// Everything a resumed run needs besides the configuration.
#[derive(Clone, Debug, Serialize, Deserialize)]
struct SceneState {
    sim: Simulation,
    info: BuildInfo,
    next_vtu: f64,
    vtu_count: u32,
    next_sample: f64,
    series_bytes: u64,
    /// ∫ volume per height bin dt over the averaging window \[m⁴ or m³ in 2D\], and the time covered.
    height_volume_time: Vec<f64>,
    height_time: f64,
    flux_started: bool,
    flux_up: Vec<f64>,
    flux_down: Vec<f64>,
    /// Wall-clock seconds of earlier sessions.
    wall_seconds: f64,
    /// Instantaneous wetting maps written so far (`output.wetting_map_times_s`).
    maps_written: usize,
}

/// One rank's part of a checkpoint written on several ranks: its state (its own fluid; wet times, height
/// volumes and plane fluxes as this rank's partial sums; the series and `.pvd` counters of rank 0) and the
/// split of space it steps in.
#[derive(Deserialize)]
struct RankPart {
    scene: SceneState,
    partition: Option<Rcb>,
}

/// [`RankPart`] as written (borrowing the running state; the same bytes).
#[derive(Serialize)]
struct RankPartRef<'a> {
    scene: &'a SceneState,
    partition: Option<&'a Rcb>,
}

/// The state to continue from, on the ranks of `ctx.comm` (collective; see the module docs).
fn resumed_state(ctx: &RunContext) -> Result<SceneState, SphError> {
    let comm = ctx.comm;
    Ok(match ctx.load_checkpoint_parts::<SceneState, RankPart>()? {
        Resumed::Whole(mut st) if comm.size() == 1 => {
            st.sim.refresh();
            st
        }
        Resumed::Whole(st) => rejoin(vec![(st, None)], comm)?,
        Resumed::Mine(RankPart { mut scene, partition }) => {
            let rcb = partition.ok_or_else(|| {
                SphError::Setup("the checkpoint part holds no split of space over the ranks".into())
            })?;
            scene.sim.restore_partition(rcb, comm)?;
            scene
        }
        Resumed::All(parts) => rejoin(parts.into_iter().map(|p| (p.scene, p.partition)).collect(), comm)?,
    })
}

/// Joins the states of the ranks that wrote a checkpoint (in their rank order) and splits them over the
/// ranks of `comm`: rank 0 takes the sums of the partial sums, the others start theirs from zero.
fn rejoin(parts: Vec<(SceneState, Option<Rcb>)>, comm: &dyn Comm) -> Result<SceneState, SphError> {
    let totals = comm.is_root();
    let mut sims = Vec::with_capacity(parts.len());
    let mut first: Option<SceneState> = None;
    for (st, rcb) in parts {
        let (sim, rest) = st.split_sim();
        sims.push((sim, rcb));
        match first.as_mut() {
            None => first = Some(rest),
            Some(f) => {
                for (a, b) in [
                    (&mut f.height_volume_time, &rest.height_volume_time),
                    (&mut f.flux_up, &rest.flux_up),
                    (&mut f.flux_down, &rest.flux_down),
                ] {
                    a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
                }
            }
        }
    }
    let mut st = first.ok_or_else(|| SphError::Setup("a checkpoint of no ranks".into()))?;
    if !totals {
        for v in [&mut st.height_volume_time, &mut st.flux_up, &mut st.flux_down] {
            v.fill(0.0);
        }
    }
    st.sim = Simulation::join_parts(sims, totals)?;
    st.sim.repartition(comm)?;
    Ok(st)
}

impl SceneState {
    /// Takes the simulation out (leaving an empty one) to hand it to [`Simulation::join_parts`].
    fn split_sim(mut self) -> (Simulation, SceneState) {
        let params = self.sim.params.clone();
        let sim = std::mem::replace(&mut self.sim, Simulation::new(params));
        (sim, self)
    }
}

/// Column names of `series.csv`.
fn series_columns(cfg: &SphConfig, sim: &Simulation) -> Vec<String> {
    let mut c: Vec<String> = [
        "t_s",
        "dt_s",
        "step",
        "particles",
        "removed_outside_domain",
        "removed_density_window",
        "kinetic_energy_J",
        "max_speed_m_s",
        "max_density_ratio",
        "min_density_ratio",
        "guard_stops",
        "dt_acoustic_s",
        "dt_force_s",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    for p in &sim.boundary.parts {
        for q in [
            "Fx_N",
            "Fy_N",
            "Fz_N",
            "Mx_Nm",
            "My_Nm",
            "Mz_Nm",
            "wet_area_m2",
            "water_m3",
            "water_arrival_m3_s",
        ] {
            c.push(format!("{}_{q}", p.name));
        }
    }
    for p in &cfg.sensors.probes {
        for q in ["p_Pa", "vx_m_s", "vy_m_s", "vz_m_s"] {
            c.push(format!("{}_{q}", p.name));
        }
    }
    for p in &cfg.sensors.wall_probes {
        c.push(format!("{}_p_Pa", p.name));
    }
    c
}

/// One row of `series.csv`; a probe without fluid around it is a gap (`None`). Collective: every rank
/// computes the same row.
fn series_row(cfg: &SphConfig, sim: &mut Simulation, comm: &dyn Comm) -> Vec<Option<f64>> {
    let l = sim.last;
    let mut r: Vec<Option<f64>> = [
        sim.time,
        sim.dt,
        sim.steps as f64,
        sim.fluid_count_with(comm) as f64,
        sim.removed.outside_domain as f64,
        sim.removed.density_window as f64,
        sim.kinetic_energy_with(comm),
        l.max_speed,
        l.max_density_ratio,
        l.min_density_ratio,
        l.guard_hits as f64,
        l.dt_acoustic,
        l.dt_force,
    ]
    .map(Some)
    .to_vec();
    let loads = sim.part_loads_with(comm);
    for (k, ld) in loads.iter().enumerate() {
        let wa = sim.wet_area_with(comm, k, sim.time);
        let water = sim.part_water_with(comm, k);
        r.extend(
            [
                ld.force.x,
                ld.force.y,
                ld.force.z,
                ld.torque.x,
                ld.torque.y,
                ld.torque.z,
                wa.wet_now,
                water.volume,
                water.arrival,
            ]
            .map(Some),
        );
    }
    for p in &cfg.sensors.probes {
        match sim.probe_with(comm, p.position_m) {
            Some((pr, v)) => r.extend([pr, v.x, v.y, v.z].map(Some)),
            None => r.extend([None; 4]),
        }
    }
    for p in &cfg.sensors.wall_probes {
        r.push(sim.wall_pressure_with(comm, p.position_m, p.radius_m));
    }
    r
}

fn particles_vtu(cfg: &SphConfig, sim: &Simulation) -> Vtu {
    let base = cfg.sensors.height.as_ref().map(|h| h.base_z_m).unwrap_or(0.0);
    let f = &sim.fluid;
    let height: Vec<f64> = f.pos.iter().map(|p| p.z - base).collect();
    let ids: Vec<i64> = f.id.iter().map(|&i| i as i64).collect();
    Vtu::point_cloud(&f.pos)
        .point_vector("velocity_m_s", &f.vel)
        .point_scalar("pressure_Pa", &sim.pressures())
        .point_scalar("density_kg_m3", &f.rho)
        .point_scalar("height_m", &height)
        .point_int("id", &ids)
}

/// Writes the particle output number `count`; returns its path relative to the run folder (for the
/// `.pvd`). One rank: `particles/particles_00012.vtu`. Several: every rank writes its piece
/// `particles/particles_00012_r0003.vtu` and rank 0 the `particles/particles_00012.pvtu` joining them.
fn write_particles(
    dir: &spatter_io::run::RunDir,
    count: u32,
    cfg: &SphConfig,
    sim: &Simulation,
    comm: &dyn Comm,
) -> Result<String, SphError> {
    let vtu = particles_vtu(cfg, sim);
    if comm.size() == 1 {
        let rel = format!("particles/particles_{count:05}.vtu");
        let p = dir.path(&rel);
        vtu.write(&p).map_err(io_at(&p))?;
        return Ok(rel);
    }
    let piece = |r: usize| format!("particles_{count:05}_r{r:04}.vtu");
    let p = dir.path(&format!("particles/{}", piece(comm.rank())));
    vtu.write(&p).map_err(fatal(comm, &p))?;
    let rel = format!("particles/particles_{count:05}.pvtu");
    if comm.is_root() {
        let p = dir.path(&rel);
        let pieces: Vec<String> = (0..comm.size()).map(piece).collect();
        vtu.write_pvtu(&p, &pieces).map_err(io_at(&p))?;
    }
    Ok(rel)
}

/// The wall particles with the wetting records `wet`, `wet_time` (gathered from every rank).
fn write_walls(path: &Path, sim: &Simulation, (wet, wet_time): (&[bool], &[f64])) -> std::io::Result<()> {
    let b = &sim.boundary;
    let part: Vec<i64> = b.part.iter().map(|&p| p as i64).collect();
    let wet: Vec<i64> = wet.iter().map(|&w| w as i64).collect();
    let n = b.len();
    let pos: Vec<Vec3> = (0..n).map(|i| b.position(i)).collect();
    let vel: Vec<Vec3> = (0..n).map(|i| b.velocity(i)).collect();
    let nrm: Vec<Vec3> = (0..n).map(|i| b.normal(i)).collect();
    Vtu::point_cloud(&pos)
        .point_vector("velocity_m_s", &vel)
        .point_vector("normal", &nrm)
        .point_scalar("area_m2", &b.area)
        .point_scalar("volume_m3", &b.volume)
        .point_scalar("wet_time_s", wet_time)
        .point_int("wet", &wet)
        .point_int("part", &part)
        .write(path)
}

fn io_at(path: &Path) -> impl Fn(std::io::Error) -> SphError + '_ {
    move |e| SphError::Io(std::io::Error::new(e.kind(), format!("{}: {e}", path.display())))
}

/// A write that failed on one rank of several: the others cannot be told in a collective they are not
/// in, so the whole run ends here (after printing the error); on one rank an ordinary error.
fn fatal<'a>(comm: &'a dyn Comm, path: &'a Path) -> impl Fn(std::io::Error) -> SphError + 'a {
    move |e| {
        let e = io_at(path)(e);
        if comm.size() > 1 {
            eprintln!("error on rank {} of {}: {e}; ending the run", comm.rank(), comm.size());
            comm.abort(1);
        }
        e
    }
}

/// Runs the scenario in `ctx` (see `docs/sph.md` for the files written). File paths are taken as given
/// (the scenario loader has made them absolute; see [`spatter_io::paths`]).
pub fn run(cfg: &SphConfig, ctx: &RunContext) -> Result<RunSummary, SphError> {
    let dir = ctx.dir;
    let comm = ctx.comm;
    let (root, ranks) = (comm.is_root(), comm.size() > 1);
    let ckpt = dir.checkpoint_path();
    let series_path = dir.path("series.csv");
    let pvd_path = dir.path("particles.pvd");
    let session = Instant::now();
    // Rank 0 alone writes the series and the .pvd. On several ranks the job driver has checked that the
    // checkpoint exists (every rank must take the same branch).
    let (mut st, mut series, mut pvd) = if ctx.resume && (ranks || ckpt.exists()) {
        let st = resumed_state(ctx)?;
        let (series, pvd) = if root {
            let cols = series_columns(cfg, &st.sim);
            let cols: Vec<&str> = cols.iter().map(|s| s.as_str()).collect();
            let series =
                CsvSeries::resume(&series_path, &cols, st.series_bytes).map_err(fatal(comm, &series_path))?;
            let mut pvd = PvdSeries::load_or_new(&pvd_path).map_err(fatal(comm, &pvd_path))?;
            pvd.truncate_after(st.sim.time).map_err(fatal(comm, &pvd_path))?;
            tracing::info!(
                "resumed at t = {:.6} s, step {}{}",
                st.sim.time,
                st.sim.steps,
                if ranks { format!(" on {} ranks", comm.size()) } else { String::new() }
            );
            (Some(series), Some(pvd))
        } else {
            (None, None)
        };
        (st, series, pvd)
    } else {
        let (sim, info) = build_with(cfg, comm)?;
        if root {
            tracing::info!(
                "sph {}: {} fluid and {} wall particles, dp = {} m, h = {:.4} m, U_max = {:.4} m/s, c0 = {:.4} m/s, dt0 = {:.4e} s, {} thread(s){}",
                cfg.title,
                info.fluid_particles,
                info.wall_particles,
                sim.params.spacing,
                sim.params.h(),
                info.u_max,
                info.sound_speed,
                sim.dt,
                rayon::current_num_threads(),
                if ranks { format!(" on each of {} ranks", comm.size()) } else { String::new() }
            );
            for w in &info.warnings {
                tracing::warn!("{w}");
            }
        }
        let (series, pvd) = if root {
            let cols = series_columns(cfg, &sim);
            let cols: Vec<&str> = cols.iter().map(|s| s.as_str()).collect();
            let series = CsvSeries::create(&series_path, &cols).map_err(fatal(comm, &series_path))?;
            (Some(series), Some(PvdSeries::new(&pvd_path)))
        } else {
            (None, None)
        };
        let nb = cfg.sensors.height.as_ref().map(|h| h.bins).unwrap_or(0);
        let st = SceneState {
            sim,
            info,
            next_vtu: 0.0,
            vtu_count: 0,
            next_sample: 0.0,
            series_bytes: 0,
            height_volume_time: vec![0.0; nb],
            height_time: 0.0,
            flux_started: false,
            flux_up: vec![0.0; nb + 1],
            flux_down: vec![0.0; nb + 1],
            wall_seconds: 0.0,
            maps_written: 0,
        };
        if cfg.output.wall_particles {
            let wetting = st.sim.wetting_with(comm);
            let p = dir.path("walls.vtu");
            if root {
                write_walls(&p, &st.sim, (&wetting.0, &wetting.1)).map_err(fatal(comm, &p))?;
            }
        }
        (st, series, pvd)
    };
    // Not part of a checkpoint: the scenario's value, also on a resume.
    st.sim.set_rebalance(cfg.domain.rebalance());
    let end = cfg.output.end_time_s;
    let vtu_dt = cfg.output.vtu_interval();
    let sample_dt = cfg.output.sample_interval();
    let total_steps_estimate = (end / st.sim.dt.max(1e-12)) as u64;
    loop {
        // Outputs due at the current time.
        if st.sim.time >= st.next_sample - 1e-12 * end {
            let row = series_row(cfg, &mut st.sim, comm);
            if let Some(series) = series.as_mut() {
                series.row_with_gaps(&row).map_err(fatal(comm, &series_path))?;
            }
            while st.next_sample <= st.sim.time + 1e-12 * end {
                st.next_sample += sample_dt;
            }
        }
        if st.sim.time >= st.next_vtu - 1e-12 * end {
            let rel = write_particles(dir, st.vtu_count, cfg, &st.sim, comm)?;
            if let Some(pvd) = pvd.as_mut() {
                pvd.push(st.sim.time, &rel).map_err(fatal(comm, &pvd_path))?;
            }
            if cfg.output.wall_particles {
                let wetting = st.sim.wetting_with(comm);
                let p = dir.path(&format!("walls/walls_{:05}.vtu", st.vtu_count));
                if root {
                    write_walls(&p, &st.sim, (&wetting.0, &wetting.1)).map_err(fatal(comm, &p))?;
                }
            }
            st.vtu_count += 1;
            let l = st.sim.last;
            let particles = st.sim.fluid_count_with(comm);
            if root {
                tracing::info!(
                    "t = {:.6} s, step {}, dt = {:.4e} s (acoustic {:.3e}, force {:.3e}, viscous {:.3e}), {} particles, removed {} (domain) + {} (density), max speed {:.4} m/s, density {:.4}–{:.4} ρ0, guard stops {}",
                    st.sim.time,
                    st.sim.steps,
                    st.sim.dt,
                    l.dt_acoustic,
                    l.dt_force,
                    l.dt_viscous,
                    particles,
                    st.sim.removed.outside_domain,
                    st.sim.removed.density_window,
                    l.max_speed,
                    l.min_density_ratio,
                    l.max_density_ratio,
                    l.guard_hits
                );
                if l.max_speed > 0.1 * st.sim.params.sound_speed {
                    tracing::warn!(
                        "max speed {:.4} m/s exceeds c0/10 = {:.4} m/s; density errors may exceed 1 % — raise fluid.max_velocity_m_s",
                        l.max_speed,
                        0.1 * st.sim.params.sound_speed
                    );
                }
            }
            while st.next_vtu <= st.sim.time + 1e-12 * end {
                st.next_vtu += vtu_dt;
            }
        }
        let map_times = &cfg.output.wetting_map_times_s;
        while st.maps_written < map_times.len() && st.sim.time >= map_times[st.maps_written] - 1e-12 * end {
            write_instant_maps(cfg, dir, &st.sim, st.maps_written, comm)?;
            st.maps_written += 1;
        }
        if st.sim.time >= end - 1e-12 * end {
            break;
        }
        let poll = ctx.poll();
        if poll.stop || poll.checkpoint {
            if let Some(series) = series.as_mut() {
                series.flush().map_err(fatal(comm, &series_path))?;
                st.series_bytes = series.bytes_written();
            }
            // The checkpoint holds the wall time up to now; this session's count goes on from here.
            let earlier = st.wall_seconds;
            st.wall_seconds += session.elapsed().as_secs_f64();
            if ranks {
                ctx.save_checkpoint_part(&RankPartRef { scene: &st, partition: st.sim.partition() })?;
            } else {
                ctx.save_checkpoint(&st)?;
            }
            if poll.stop {
                if root {
                    tracing::info!(
                        "stopped at t = {:.6} s, step {}; checkpoint written",
                        st.sim.time,
                        st.sim.steps
                    );
                }
                let mut s = RunSummary::new(Finished::Interrupted);
                s.headline
                    .push(format!("stopped at t = {:.6} s of {end} s; resume to continue", st.sim.time));
                s.artifacts.push(("checkpoint".into(), ckpt));
                return Ok(s);
            }
            st.wall_seconds = earlier;
        }
        st.sim.step_with(comm)?;
        accumulate_height(cfg, &mut st);
        ctx.control.progress(st.sim.steps, total_steps_estimate.max(st.sim.steps));
    }
    if let Some(series) = series.as_mut() {
        series.flush().map_err(fatal(comm, &series_path))?;
    }
    let wall = st.wall_seconds + session.elapsed().as_secs_f64();
    finish(cfg, ctx, st, wall)
}

/// Height bins and plane fluxes over the averaging window.
/// Every part's wetting at this moment (map `n` of `output.wetting_map_times_s`, written at the first step
/// at or after its time): `wetting/instant_NN/<part>.vtu` (cell array `wet_now`, 1 wet and 0 dry, on one
/// square per wall particle where the part is now) and `.png` on the scale 0–1, from the view of the
/// part's time-averaged map. A collective on several ranks (the wet flags are gathered); rank 0 writes.
fn write_instant_maps(
    cfg: &SphConfig,
    dir: &spatter_io::run::RunDir,
    sim: &Simulation,
    n: usize,
    comm: &dyn Comm,
) -> Result<(), SphError> {
    let (wet, _) = sim.wetting_with(comm);
    if !comm.is_root() {
        return Ok(());
    }
    for k in 0..sim.boundary.parts.len() {
        let name = &sim.boundary.parts[k].name;
        let wcfg = cfg.walls.iter().find(|w| w.name == *name);
        if !wcfg.map(|w| w.wetting_map).unwrap_or(true) {
            continue;
        }
        let (squares, now) = particle_squares(sim, k, |i| if wet[i] { 1.0 } else { 0.0 });
        if squares.triangles.is_empty() {
            continue;
        }
        let vtu = dir.path(&format!("wetting/instant_{n:02}/{name}.vtu"));
        Vtu::triangles(&squares.vertices, &squares.triangles)
            .cell_scalar("wet_now", &now)
            .write(&vtu)
            .map_err(fatal(comm, &vtu))?;
        let (dv, du) = default_view(sim, k);
        let view = wcfg.and_then(|w| w.view_dir).unwrap_or(dv);
        let up = wcfg.and_then(|w| w.up).unwrap_or(du);
        let png = vtu.with_extension("png");
        let title = format!("{name}: wet at t = {:.4} s", sim.time);
        spatter_io::plot::mesh_map_png_on_scale(
            &png,
            &squares,
            &now,
            (view, up),
            (&title, "wet (1) or dry (0)"),
            (0.0, 1.0),
        )
        .map_err(fatal(comm, &png))?;
    }
    Ok(())
}

fn accumulate_height(cfg: &SphConfig, st: &mut SceneState) {
    let Some(h) = &cfg.sensors.height else { return };
    let sim = &mut st.sim;
    let [t0, t1] = h.window_s;
    let t = sim.time;
    if !st.flux_started && t >= t0 {
        sim.reset_flux();
        st.flux_started = true;
    }
    if t > t0 && t - sim.last_dt() < t1 {
        // Portion of the last step inside the window.
        let lo = (t - sim.last_dt()).max(t0);
        let hi = t.min(t1);
        let w = (hi - lo).max(0.0);
        let m = sim.params.mass();
        for (x, rho) in sim.fluid.pos.iter().zip(&sim.fluid.rho) {
            let k = ((x.z - h.base_z_m) / h.bin_m).floor();
            if k >= 0.0 && (k as usize) < h.bins {
                st.height_volume_time[k as usize] += m / rho * w;
            }
        }
        st.height_time += w;
        if t >= t1 {
            st.flux_up.clone_from(&sim.flux_up);
            st.flux_down.clone_from(&sim.flux_down);
        }
    }
}

fn finish(cfg: &SphConfig, ctx: &RunContext, mut st: SceneState, wall: f64) -> Result<RunSummary, SphError> {
    let dir = ctx.dir;
    let comm = ctx.comm;
    // The collective part: every rank's share of the loads, particles, wetting, heights and fluxes.
    let loads = st.sim.part_loads_with(comm);
    let particles = st.sim.fluid_count_with(comm);
    st.sim.gather_wetting(comm);
    for v in [
        &mut st.height_volume_time,
        &mut st.flux_up,
        &mut st.flux_down,
        &mut st.sim.flux_up,
        &mut st.sim.flux_down,
    ] {
        comm.sum_f64_ordered(v);
    }
    let sim = st.sim;
    let mut summary = RunSummary::new(Finished::Completed);
    if !comm.is_root() {
        // Rank 0 writes the results and the summary.
        return Ok(summary);
    }
    let elapsed = sim.time;
    // Wetting maps and wet areas.
    let mut rows = Vec::new();
    for k in 0..sim.boundary.parts.len() {
        let name = sim.boundary.parts[k].name.clone();
        let wa = wet_area(&sim, k, elapsed);
        rows.push(vec![
            name.clone(),
            spatter_io::fmt_f64(wa.area),
            spatter_io::fmt_f64(wa.wet_now),
            spatter_io::fmt_f64(wa.wet_mean),
            spatter_io::fmt_f64(if wa.area > 0.0 { wa.wet_mean / wa.area } else { 0.0 }),
        ]);
        let wcfg = cfg.walls.iter().find(|w| w.name == name);
        if !wcfg.map(|w| w.wetting_map).unwrap_or(true) {
            continue;
        }
        let map = wetting_map(&sim, k, elapsed);
        if map.mesh.triangles.is_empty() {
            continue;
        }
        let vtu = dir.path(&format!("wetting/{name}.vtu"));
        Vtu::triangles(&map.mesh.vertices, &map.mesh.triangles)
            .cell_scalar("wet_now", &map.wet_now)
            .cell_scalar("wet_time_fraction", &map.wet_time_fraction)
            .write(&vtu)
            .map_err(io_at(&vtu))?;
        let (dv, du) = default_view(&sim, k);
        let view = wcfg.and_then(|w| w.view_dir).unwrap_or(dv);
        let up = wcfg.and_then(|w| w.up).unwrap_or(du);
        let png = dir.path(&format!("wetting/{name}.png"));
        let (squares, fraction) = particle_map(&sim, k, elapsed);
        let scale = match cfg.output.wetting_cap {
            Some(cap) => (0.0, cap),
            None => spatter_io::plot::auto_scale(&fraction),
        };
        let title = format!("{name}: fraction of time wet (0–{elapsed:.3} s)");
        let colorbar = "time wet / elapsed";
        spatter_io::plot::mesh_map_png_on_scale(
            &png,
            &squares,
            &fraction,
            (view, up),
            (&title, colorbar),
            scale,
        )
        .map_err(io_at(&png))?;
        summary.artifacts.push((format!("wetting map {name}"), png));
        // The picture's squares and values, so that a study can redraw every case's map on one scale.
        let squares_vtu = dir.path(&format!("wetting/{name}_squares.vtu"));
        Vtu::triangles(&squares.vertices, &squares.triangles)
            .cell_scalar("wet_time_fraction", &fraction)
            .write(&squares_vtu)
            .map_err(io_at(&squares_vtu))?;
        summary.maps.push(MeshMapRecord {
            label: format!("{name} wetting"),
            vtu: squares_vtu,
            array: "wet_time_fraction".into(),
            view_dir: view.to_array(),
            up: up.to_array(),
            title,
            colorbar_label: colorbar.into(),
            scale: cfg.output.wetting_cap.map(|cap| [0.0, cap]),
        });
    }
    let wet_csv = dir.path("wetting.csv");
    write_table(
        &wet_csv,
        &["wall", "area_m2", "wet_area_now_m2", "mean_wet_area_m2", "mean_wet_fraction"],
        &rows,
    )
    .map_err(io_at(&wet_csv))?;
    summary.artifacts.push(("wet areas".into(), wet_csv));
    // Splash heights.
    let mut splash_scalars: Vec<(String, f64)> = Vec::new();
    if let Some(h) = &cfg.sensors.height {
        let x = h.reference_depth_m.unwrap_or(h.bin_m);
        // The plane counters are frozen when the window closes. A run that ends inside the window (before
        // `window_s[1]`) reports what they counted up to its end, over the time it covered — as the volumes
        // are; until 2026-11-24 it reported zero flux.
        let [t0, t1] = h.window_s;
        let closed = sim.time >= t1;
        let (flux_up, flux_down, span) = if closed || !st.flux_started {
            (&st.flux_up, &st.flux_down, t1 - t0)
        } else {
            tracing::info!(
                "splash heights: the run ended at t = {:.6} s inside the window [{t0}, {t1}] s; volumes and fluxes are averaged over [{t0}, {:.6}] s",
                sim.time, sim.time
            );
            (&sim.flux_up, &sim.flux_down, st.height_time)
        };
        let mut rows = Vec::new();
        let mut vol_pts = Vec::new();
        let mut flux_pts = Vec::new();
        for k in 0..h.bins {
            let lo = k as f64 * h.bin_m;
            let vol = if st.height_time > 0.0 { st.height_volume_time[k] / st.height_time } else { 0.0 };
            // Flux through the bin's lower edge.
            let rate = |v: &Vec<f64>| if span > 0.0 { v.get(k).copied().unwrap_or(0.0) / span } else { 0.0 };
            let (up, down) = (rate(flux_up), rate(flux_down));
            rows.push(vec![
                spatter_io::fmt_f64(lo),
                spatter_io::fmt_f64(lo + h.bin_m),
                spatter_io::fmt_f64((lo + 0.5 * h.bin_m) / x),
                spatter_io::fmt_f64(vol),
                spatter_io::fmt_f64(up),
                spatter_io::fmt_f64(up - down),
            ]);
            vol_pts.push(((lo + 0.5 * h.bin_m) / x, vol));
            flux_pts.push((lo / x, up));
        }
        let p = dir.path("splash_height.csv");
        write_table(
            &p,
            &[
                "bin_low_m",
                "bin_high_m",
                "height_over_depth",
                "mean_volume_m3",
                "upward_flux_lower_edge_m3_s",
                "net_flux_lower_edge_m3_s",
            ],
            &rows,
        )
        .map_err(io_at(&p))?;
        summary.curves.push(CurveRecord {
            label: "splash height distribution".into(),
            csv: p.clone(),
            x_column: "height_over_depth".into(),
            y_column: "mean_volume_m3".into(),
            x_label: "height / depth".into(),
            y_label: "mean volume [m³]".into(),
        });
        summary.artifacts.push(("splash heights".into(), p));
        // Volume-weighted mean height of the resident water and the highest bin holding any.
        let total: f64 = vol_pts.iter().map(|(_, v)| v).sum();
        if total > 0.0 {
            let mean = vol_pts.iter().map(|(h, v)| h * v).sum::<f64>() / total;
            let top = vol_pts.iter().filter(|(_, v)| *v > 0.0).map(|(h, _)| *h).fold(0.0, f64::max);
            splash_scalars.push(("splash_mean_height_over_depth".into(), mean));
            splash_scalars.push(("splash_top_bin_height_over_depth".into(), top));
        }
        let png = dir.path("splash_height.png");
        spatter_io::plot::Chart::new("Splash height distribution", "height / depth", "mean volume [m³]")
            .line("resident volume per bin", &vol_pts)
            .save_png(&png)
            .map_err(io_at(&png))?;
        summary.artifacts.push(("splash height plot".into(), png));
    }
    // Cost.
    let threads = rayon::current_num_threads();
    let (cores, workers) = if comm.size() > 1 {
        (threads * comm.size(), format!("{} ranks × {threads} thread(s)", comm.size()))
    } else {
        (threads, format!("{threads} thread(s)"))
    };
    let cost = format!(
        "run cost: {} fluid + {} wall particles, {} steps, {:.1} s wall time, {workers}, {:.4} core-hours, {:.3e} particle-steps/s",
        particles,
        sim.boundary.len(),
        sim.steps,
        wall,
        wall * cores as f64 / 3600.0,
        st.info.fluid_particles as f64 * sim.steps as f64 / wall.max(1e-9)
    );
    summary.headline.push(format!(
        "t = {:.4} s in {} steps; {} particles left, {} removed (outside the domain) and {} (density window)",
        sim.time, sim.steps, particles, sim.removed.outside_domain, sim.removed.density_window
    ));
    for (k, p) in sim.boundary.parts.iter().enumerate() {
        let wa = wet_area(&sim, k, elapsed);
        let f: Vec3 = loads[k].force;
        summary.headline.push(format!(
            "{}: wet now {:.4e} m², mean wet {:.4e} m² of {:.4e} m²; fluid force [{:.4e}, {:.4e}, {:.4e}] N",
            p.name, wa.wet_now, wa.wet_mean, wa.area, f.x, f.y, f.z
        ));
        summary.scalar(&format!("{}_wet_area_now_m2", p.name), wa.wet_now);
        summary.scalar(&format!("{}_mean_wet_area_m2", p.name), wa.wet_mean);
        let fraction = if wa.area > 0.0 { wa.wet_mean / wa.area } else { 0.0 };
        summary.scalar(&format!("{}_mean_wet_fraction", p.name), fraction);
        summary.scalar(&format!("{}_Fz_N", p.name), f.z);
    }
    for (name, value) in [
        ("t_end_s", sim.time),
        ("steps", sim.steps as f64),
        ("fluid_particles", particles as f64),
        ("wall_particles", sim.boundary.len() as f64),
        ("removed_outside_domain", sim.removed.outside_domain as f64),
        ("removed_density_window", sim.removed.density_window as f64),
    ] {
        summary.scalar(name, value);
    }
    summary.scalars.append(&mut splash_scalars);
    summary.headline.push(cost);
    if comm.is_root() {
        if sim.ranks() > 1 {
            tracing::info!(
                "load balance: the split of space was rebuilt {} time(s) this session",
                sim.rebalances()
            );
        }
        let ph = sim.phase_times();
        tracing::info!(
            "step phases on rank 0 (s, this session): predict {:.2}, walls and guard {:.2}, sort {:.2}, wall state {:.2}, forces {:.2}, correct {:.2}",
            ph.predict,
            ph.walls_guard,
            ph.sort,
            ph.wall_state,
            ph.forces,
            ph.correct
        );
    }
    summary.artifacts.push(("particles (ParaView)".into(), dir.path("particles.pvd")));
    summary.artifacts.push(("time series".into(), dir.path("series.csv")));
    spatter_io::rank_checkpoint::remove(dir.root()).map_err(io_at(&dir.checkpoint_path()))?;
    Ok(summary)
}
