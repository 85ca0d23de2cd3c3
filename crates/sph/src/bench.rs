//! `spatter bench sph`: a 3D dam break with at least 10⁶ fluid particles (2·10⁵ in quick mode), timed on
//! one and on two threads.
//!
//! Printed: particle-steps per second (fluid particles × steps / wall time), particle-interactions per
//! second (directed fluid–fluid pairs within the kernel support, counted once per particle that receives
//! the interaction, plus fluid–wall pairs, per wall second), the parallel efficiency, and the bytes held
//! per fluid particle by the state and every scratch buffer (walls included). Also the CPU time per step
//! and the interactions per CPU-second ([`cpu_seconds`]): on a machine shared with other work the CPU
//! time measures the work, while the wall time and the parallel efficiency need an idle machine.

use crate::kernel::Dim;
use crate::params::SphParams;
use crate::sim::{Simulation, WallOptions};
use spatter_core::{Aabb, Vec3};
use std::time::Instant;

/// One timed configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchResult {
    pub threads: usize,
    pub fluid_particles: usize,
    pub wall_particles: usize,
    pub steps: u64,
    pub seconds: f64,
    /// CPU seconds (user + system, all threads of the process) of the timed steps, when the operating
    /// system reports them (Linux `/proc/self/stat`); on a shared machine this is the fair measure of
    /// work, wall time the measure of speed.
    pub cpu_seconds: Option<f64>,
    pub particle_steps_per_s: f64,
    pub interactions_per_s: f64,
    pub interactions_per_particle: f64,
    pub bytes_per_particle: f64,
    /// Wall-clock milliseconds per step in the phases of the step.
    pub phase_ms: crate::sim::PhaseTimes,
}

/// The dam break of the benchmark: column a × 2a × a (x, z, y) with `n` particles across a, in a tank
/// 4a long and 2a high (open top).
pub fn dam_break(n: usize) -> Simulation {
    dam_break_with(n, None)
}

/// [`dam_break`] with the smoothing length `h_over_dp` × spacing instead of the default (1.5 in 3D,
/// support 3 dp). `Some(1.0)` gives a support of 2 dp, the fixed support (4 particle radii) of
/// SPlisHSPlasH, for the side-by-side comparison in `bench/sph/compare.sh`.
pub fn dam_break_with(n: usize, h_over_dp: Option<f64>) -> Simulation {
    let dp = 0.005;
    let a = n as f64 * dp;
    let g = 9.81;
    let mut p = SphParams::water(Dim::Three, dp, 10.0 * (2.0 * g * 2.0 * a).sqrt());
    if let Some(r) = h_over_dp {
        p.h_over_dp = r;
    }
    p.gravity = Vec3::new(0.0, 0.0, -g);
    let mut sim = Simulation::new(p);
    let open_top = [true, true, true, true, true, false];
    sim.add_tank(
        "tank",
        Aabb::new(Vec3::ZERO, Vec3::new(4.0 * a, a, 2.0 * a)),
        open_top,
        None,
        None,
        WallOptions::default(),
    );
    sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(a, a, 2.0 * a)), Vec3::ZERO, true);
    sim
}

/// Times `steps` steps of the dam break on `threads` threads (after two warm-up steps).
pub fn run_case(n: usize, threads: usize, steps: u64) -> Result<BenchResult, crate::SphError> {
    run_case_with(n, threads, steps, None)
}

/// [`run_case`] of [`dam_break_with`]`(n, h_over_dp)`.
pub fn run_case_with(
    n: usize,
    threads: usize,
    steps: u64,
    h_over_dp: Option<f64>,
) -> Result<BenchResult, crate::SphError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| crate::SphError::Setup(format!("cannot start {threads} threads: {e}")))?;
    pool.install(|| {
        let mut sim = dam_break_with(n, h_over_dp);
        sim.initialize()?;
        for _ in 0..2 {
            sim.step()?;
        }
        let mut interactions = 0u64;
        let p0 = sim.phase_times();
        let c0 = cpu_seconds();
        let t0 = Instant::now();
        for _ in 0..steps {
            sim.step()?;
            interactions += sim.last.interactions;
        }
        let seconds = t0.elapsed().as_secs_f64();
        let cpu = match (c0, cpu_seconds()) {
            (Some(a), Some(b)) => Some(b - a),
            _ => None,
        };
        let p1 = sim.phase_times();
        let ms = |a: f64, b: f64| (b - a) * 1e3 / steps as f64;
        let phase_ms = crate::sim::PhaseTimes {
            predict: ms(p0.predict, p1.predict),
            walls_guard: ms(p0.walls_guard, p1.walls_guard),
            sort: ms(p0.sort, p1.sort),
            wall_state: ms(p0.wall_state, p1.wall_state),
            forces: ms(p0.forces, p1.forces),
            correct: ms(p0.correct, p1.correct),
        };
        let nf = sim.fluid.len();
        Ok(BenchResult {
            threads,
            fluid_particles: nf,
            wall_particles: sim.boundary.len(),
            steps,
            seconds,
            cpu_seconds: cpu,
            particle_steps_per_s: nf as f64 * steps as f64 / seconds,
            interactions_per_s: interactions as f64 / seconds,
            interactions_per_particle: interactions as f64 / (steps as f64 * nf as f64),
            bytes_per_particle: sim.bytes_per_particle(),
            phase_ms,
        })
    })
}

/// CPU time of this process \[s\] (user + system over all threads), from `/proc/self/stat` (fields 14
/// and 15, in clock ticks of 1/100 s, the Linux `USER_HZ`). None where that file does not exist.
pub fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The command name (field 2) is in parentheses and may hold spaces: count fields after the last ')'.
    let rest = &s[s.rfind(')')? + 1..];
    let mut f = rest.split_whitespace().skip(11);
    let utime: f64 = f.next()?.parse().ok()?;
    let stime: f64 = f.next()?.parse().ok()?;
    Some((utime + stime) / 100.0)
}

/// Runs the benchmark on one and two threads and returns the lines to print.
pub fn bench(quick: bool) -> Result<Vec<String>, crate::SphError> {
    let (n, steps) = if quick { (46, 5) } else { (80, 10) };
    let r1 = run_case(n, 1, steps)?;
    let r2 = run_case(n, 2, steps)?;
    let mut lines = vec![format!(
        "sph dam break 3D: {} fluid + {} wall particles, {:.1} interactions per fluid particle and step, {} steps timed",
        r1.fluid_particles, r1.wall_particles, r1.interactions_per_particle, steps
    )];
    for r in [&r1, &r2] {
        let cpu = match r.cpu_seconds {
            Some(c) if c > 0.0 => format!(
                ", {:.3e} interactions per CPU-second ({:.2} CPU-s/step)",
                r.interactions_per_particle * r.fluid_particles as f64 * r.steps as f64 / c,
                c / r.steps as f64
            ),
            _ => String::new(),
        };
        lines.push(format!(
            "  {} thread(s): {:.3e} particle-steps/s, {:.3e} particle-interactions/s ({:.3e} per core), {:.3} s/step{}",
            r.threads,
            r.particle_steps_per_s,
            r.interactions_per_s,
            r.interactions_per_s / r.threads as f64,
            r.seconds / r.steps as f64,
            cpu
        ));
    }
    let mut eff = format!(
        "  parallel efficiency on 2 threads (wall time): {:.1} %",
        100.0 * r2.particle_steps_per_s / (2.0 * r1.particle_steps_per_s)
    );
    if let (Some(c1), Some(c2)) = (r1.cpu_seconds, r2.cpu_seconds) {
        if c2 > 0.0 {
            // 1-thread CPU time over 2-thread CPU time for the same steps: below 100 % when the parallel
            // scheme adds work or a thread spins while it waits for the other (rayon idles by spinning
            // briefly); it says nothing about waiting for a core that another process holds.
            eff.push_str(&format!("; CPU-time ratio 1/2 threads: {:.1} %", 100.0 * c1 / c2));
        }
    }
    lines.push(eff);
    lines.push(format!(
        "  memory: {:.0} bytes per fluid particle (state, scratch and walls)",
        r1.bytes_per_particle
    ));
    lines.push(format!(
        "  phases, 1 thread [ms/step]: forces {:.0}, wall state {:.0}, sort {:.0}, walls and guard {:.0}, predict {:.0}, correct {:.0}",
        r1.phase_ms.forces,
        r1.phase_ms.wall_state,
        r1.phase_ms.sort,
        r1.phase_ms.walls_guard,
        r1.phase_ms.predict,
        r1.phase_ms.correct
    ));
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With h = dp the support is 2 dp, so a particle deep in a lattice has the 26 lattice points with
    /// 0 < |k|² < 4 as neighbours (the 6 at exactly 2 dp lie on the support and are not counted), against
    /// 92 with 0 < |k|² < 9 at the default h = 1.5 dp; the small column here has surfaces and walls, so
    /// its averages (24.9 and 86.7 interactions per particle) are checked against bounds around those
    /// counts that exclude each other.
    #[test]
    fn the_smoothing_length_option_sets_the_support() {
        let s = dam_break_with(12, Some(1.0));
        assert_eq!(s.params.h(), s.params.spacing);
        let d = dam_break(12);
        assert_eq!(d.params.h(), 1.5 * d.params.spacing);
        let narrow = run_case_with(12, 1, 1, Some(1.0)).unwrap();
        let wide = run_case(12, 1, 1).unwrap();
        assert!(
            (18.0..30.0).contains(&narrow.interactions_per_particle),
            "{}",
            narrow.interactions_per_particle
        );
        assert!((60.0..95.0).contains(&wide.interactions_per_particle), "{}", wide.interactions_per_particle);
    }
}
