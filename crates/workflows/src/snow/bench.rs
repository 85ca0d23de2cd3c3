//! `spatter bench snow`: impacts per second of the regime-map sweeps on 1 and 2 threads.
//!
//! Case: the thesis baseline (ice on ABS, full JKR, Thornton restitution), Δt = t_H / 200.
//! * grid: the full 46 × 50 map (2300 impacts);
//! * bisection: v_crit(d) for the 46 diameters to 10⁻³ relative;
//! * rough wall: 10 µm grains at 1 m/s on random-insertion beds of 1 µm spheres 30 µm and 120 µm wide
//!   (16× the spheres), to show that the cost of an impact does not grow with the bed.

use super::bed_index::BedIndex;
use super::bisection::critical_speed;
use super::cases::model_of;
use super::config::SnowConfig;
use super::model::Surface;
use super::regime::{grid_jobs, run_job, stick_count};
use super::runner::{aim_point, make_bed};
use rayon::prelude::*;
use std::time::Instant;

/// Runs the benchmark and returns the lines to print. `quick` shrinks the grid to 12 × 10.
pub fn bench(quick: bool) -> Result<Vec<String>, rayon::ThreadPoolBuildError> {
    let mut cfg = SnowConfig::default();
    if quick {
        cfg.grid.diameters = 12;
        cfg.grid.normal_speeds = 10;
    }
    let model = model_of(&cfg);
    let jobs = grid_jobs(&cfg.grid);
    let ds = cfg.grid.diameter_axis();
    let (lo, hi) = cfg.grid.speed_range();
    let mut lines = vec![format!(
        "snow: {} × {} grid of single impacts (ice on ABS, full JKR, dt = Hertz time / {}) and a {}-diameter bisection map",
        cfg.grid.diameters, cfg.grid.normal_speeds, cfg.integration.steps_per_contact, ds.len()
    )];
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
        let (grid_s, sticks, steps) = pool.install(|| {
            let t = Instant::now();
            let recs: Vec<_> = jobs.par_iter().map(|j| run_job(&model, j)).collect();
            let steps: u64 = recs.iter().map(|r| r.result.steps).sum();
            (t.elapsed().as_secs_f64(), stick_count(&recs), steps)
        });
        let (bis_s, impacts) = pool.install(|| {
            let t = Instant::now();
            let n: u32 = ds.par_iter().map(|&d| critical_speed(&model, d, lo, hi, 1e-3, 6).impacts).sum();
            (t.elapsed().as_secs_f64(), n)
        });
        let rough = pool.install(|| rough_wall_rates(quick));
        lines.push(format!(
            "{threads} thread(s): grid {} impacts in {:.3} s = {:.0} impacts/s ({:.2e} contact steps/s, {} sticks); bisection map {:.3} s ({} impacts, {:.0} impacts/s)",
            jobs.len(),
            grid_s,
            jobs.len() as f64 / grid_s,
            steps as f64 / grid_s,
            sticks,
            bis_s,
            impacts,
            impacts as f64 / bis_s
        ));
        lines.push(format!("{threads} thread(s): rough wall {rough}"));
    }
    Ok(lines)
}

/// Impacts per second on a narrow and a 4× wider rough-wall bed (bed building not timed).
fn rough_wall_rates(quick: bool) -> String {
    let impacts = if quick { 16 } else { 160 };
    let mut parts = Vec::new();
    for width in [30e-6, 120e-6] {
        let mut cfg = SnowConfig::default();
        cfg.rough_wall.bed_width_m = Some(width);
        let bed = make_bed(&cfg);
        let index = BedIndex::new(&bed.spheres);
        let model = model_of(&cfg);
        let surface = Surface::bed(&bed, &index);
        let d = cfg.rough_wall.particle_diameter_m;
        let t = Instant::now();
        let steps: u64 = (0..impacts as u64)
            .into_par_iter()
            .map(|k| model.simulate(d, 1.0, 0.0, aim_point(&cfg, k), surface).0.steps)
            .sum();
        let s = t.elapsed().as_secs_f64();
        parts.push(format!(
            "{} spheres: {impacts} impacts in {s:.3} s = {:.0} impacts/s ({:.2e} steps/s)",
            bed.spheres.len(),
            impacts as f64 / s,
            steps as f64 / s
        ));
    }
    parts.join("; ")
}
