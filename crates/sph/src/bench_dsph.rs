//! The 3D dam break of DualSPHysics's example `examples/main/01_DamBreak` (`CaseDambreak_Def.xml`,
//! DualSPHysics v5.4) built in spatter, and a timed run to a physical end time, for the side-by-side
//! comparison in `bench/sph/dualsphysics.sh` (docs/sph.md §5).
//!
//! Geometry of that example (metres): a water block 0.4 × 0.67 × 0.3 (x, y, z) at the lower corner of a
//! tank 1.6 × 0.67 × 0.4 with an open top, and a square column ("building") 0.12 × 0.12 × 0.45 standing on
//! the floor at x = 0.9, y = 0.24. Water at rest, hydrostatic density. The rate compared is the wall time
//! to reach the same simulated time, so each code's own time step counts.

use crate::bench::cpu_seconds;
use crate::kernel::Dim;
use crate::params::SphParams;
use crate::sim::{Simulation, WallOptions};
use crate::SphError;
use spatter_core::{Aabb, Vec3};
use std::time::Instant;

/// Water block of the example \[m\] (x, y, z), from the origin.
pub const FLUID_BLOCK: [f64; 3] = [0.4, 0.67, 0.3];
/// Inner size of the tank \[m\]; its top is open.
pub const TANK: [f64; 3] = [1.6, 0.67, 0.4];
/// Lower corner and size of the building \[m\].
pub const BUILDING: ([f64; 3], [f64; 3]) = ([0.9, 0.24, 0.0], [0.12, 0.12, 0.45]);
/// Gravity \[m/s²\] along −z.
const G: f64 = 9.81;

/// Sound speed \[m/s\] by spatter's rule for a dam break: 10 × the front speed 2√(gH) of Ritter (1892),
/// H = the height of the water block (docs/sph.md §1). DualSPHysics's rule, `coefsound` 20 × √(g·hswl), is
/// the same formula with its own depth `hswl` (the highest fluid particle above the lowest one).
pub fn default_sound_speed() -> f64 {
    10.0 * 2.0 * (G * FLUID_BLOCK[2]).sqrt()
}

/// The example's dam break with particle spacing `dp` \[m\], smoothing length `h_over_dp` × dp and the
/// sound speed `sound_speed` \[m/s\] (default [`default_sound_speed`]); every other parameter is spatter's
/// default ([`SphParams::water`]). Walls: lattice layers filling the kernel support behind the tank's five
/// closed faces and inside the building.
pub fn dam_break(dp: f64, h_over_dp: f64, sound_speed: Option<f64>) -> Result<Simulation, SphError> {
    // The range of `h_over_dp` that scenario files accept (`scene/config.rs`).
    if !(dp.is_finite() && dp > 0.0 && dp <= 0.05) {
        return Err(SphError::Setup(format!(
            "particle spacing dp = {dp} m: expected a number in (0, 0.05] (at least 6 particles across the \
             water column's height of {} m)",
            FLUID_BLOCK[2]
        )));
    }
    if !(1.0..=4.0).contains(&h_over_dp) {
        return Err(SphError::Setup(format!(
            "smoothing length over spacing h/dp = {h_over_dp}: expected a number from 1 to 4"
        )));
    }
    let c0 = sound_speed.unwrap_or_else(default_sound_speed);
    if !(c0.is_finite() && c0 > 0.0) {
        return Err(SphError::Setup(format!("sound speed {c0} m/s: expected a positive number")));
    }
    let mut p = SphParams::water(Dim::Three, dp, c0);
    p.h_over_dp = h_over_dp;
    p.gravity = Vec3::new(0.0, 0.0, -G);
    let mut sim = Simulation::new(p);
    let v = |a: [f64; 3]| Vec3::new(a[0], a[1], a[2]);
    let open_top = [true, true, true, true, true, false];
    sim.add_tank("tank", Aabb::new(Vec3::ZERO, v(TANK)), open_top, None, None, WallOptions::default());
    let (b0, bs) = (v(BUILDING.0), v(BUILDING.1));
    sim.add_block("building", Aabb::new(b0, b0 + bs), None, None, WallOptions::default());
    sim.fill_box(Aabb::new(Vec3::ZERO, v(FLUID_BLOCK)), Vec3::ZERO, true);
    Ok(sim)
}

/// One run to a physical end time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimedRun {
    pub threads: usize,
    pub fluid_particles: usize,
    pub wall_particles: usize,
    /// Steps taken; each evaluates the forces once (velocity Verlet, docs/sph.md §1).
    pub steps: u64,
    /// Simulated time reached \[s\] (the first step end at or after the requested time).
    pub time: f64,
    /// Wall time of the steps \[s\] (set-up and initial state excluded).
    pub seconds: f64,
    /// Wall time of the set-up: building the particles and the initial state \[s\].
    pub setup_seconds: f64,
    /// CPU seconds of the steps (user + system, all threads), where the system reports them.
    pub cpu_seconds: Option<f64>,
    /// Smallest, mean and largest time step \[s\].
    pub dt_min: f64,
    pub dt_mean: f64,
    pub dt_max: f64,
}

impl TimedRun {
    /// Fluid particles × steps / wall time of the steps.
    pub fn particle_steps_per_s(&self) -> f64 {
        self.fluid_particles as f64 * self.steps as f64 / self.seconds
    }
}

/// Builds [`dam_break`]`(dp, h_over_dp, sound_speed)` and steps it on `threads` threads until the
/// simulated time reaches `t_end` \[s\] (no warm-up: the run starts at rest, as DualSPHysics's does).
pub fn run_to_time(
    dp: f64,
    h_over_dp: f64,
    sound_speed: Option<f64>,
    threads: usize,
    t_end: f64,
) -> Result<TimedRun, SphError> {
    if !(t_end.is_finite() && t_end > 0.0) {
        return Err(SphError::Setup(format!("end time {t_end} s: expected a positive number")));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| SphError::Setup(format!("cannot start {threads} threads: {e}")))?;
    pool.install(|| {
        let s0 = Instant::now();
        let mut sim = dam_break(dp, h_over_dp, sound_speed)?;
        sim.initialize()?;
        let setup_seconds = s0.elapsed().as_secs_f64();
        let (mut dt_min, mut dt_max) = (f64::INFINITY, 0.0f64);
        let c0 = cpu_seconds();
        let t0 = Instant::now();
        while sim.time < t_end {
            sim.step()?;
            let dt = sim.last_dt();
            dt_min = dt_min.min(dt);
            dt_max = dt_max.max(dt);
        }
        let seconds = t0.elapsed().as_secs_f64();
        let cpu = match (c0, cpu_seconds()) {
            (Some(a), Some(b)) => Some(b - a),
            _ => None,
        };
        Ok(TimedRun {
            threads,
            fluid_particles: sim.fluid.len(),
            wall_particles: sim.boundary.len(),
            steps: sim.steps,
            time: sim.time,
            seconds,
            setup_seconds,
            cpu_seconds: cpu,
            dt_min,
            dt_mean: sim.time / sim.steps as f64,
            dt_max,
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// DualSPHysics's GenCase (v5.0.229, the generator the script uses) reports 194 400 fluid particles in
    /// the block at dp = 7.38 mm (its case summary, "Fluid....: 194400"): 54 × 90 × 40, ⌊size/dp⌋ lattice
    /// points per axis. spatter's fill puts its points at (i + ½) dp and gives the same count, checked
    /// exactly. (At dp = 20 mm GenCase gives 9 600 against spatter's 9 900: its far tank wall at y = 0.67 m
    /// falls on the lattice row at 0.66 m and replaces that row of water.) The highest particle sits dp/2
    /// below the block's top; sound speed 20 √(g · 0.3 m) = 34.31 m/s.
    #[test]
    fn the_dualsphysics_dam_break_has_its_fluid_block_and_walls() {
        let dp = 0.00738;
        let s = dam_break(dp, 3f64.sqrt(), None).unwrap();
        assert_eq!(s.fluid.len(), 194_400);
        assert_eq!(s.params.h(), dp * 3f64.sqrt());
        assert!((s.params.sound_speed - 34.3103).abs() < 1e-3, "{}", s.params.sound_speed);
        let parts: Vec<&str> = s.boundary.parts.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(parts, ["tank", "building"]);
        let top = s.fluid.pos.iter().map(|x| x.z).fold(0.0f64, f64::max);
        assert!((top - 39.5 * dp).abs() < 1e-12, "highest fluid particle at {top} m");
    }

    /// The run stops at the first step end at or after the end time: the time reached is the sum of the
    /// steps taken (mean dt × steps), lies within one step past the end, and the steps' dt follow the CFL
    /// rule of docs/sph.md §1, dt ≤ 0.2 h / c₀ (flow speeds only lower it).
    #[test]
    fn the_run_reaches_the_end_time_in_whole_steps() {
        let (dp, r) = (0.04, 3f64.sqrt());
        let t_end = 2e-3;
        let run = run_to_time(dp, r, None, 1, t_end).unwrap();
        assert!(run.time >= t_end && run.time - run.dt_max < t_end, "{run:?}");
        assert!((run.dt_mean * run.steps as f64 - run.time).abs() < 1e-15);
        let cfl = 0.2 * r * dp / default_sound_speed();
        assert!(run.dt_max <= cfl * (1.0 + 1e-12) && run.dt_min > 0.5 * cfl, "{run:?}, CFL dt {cfl}");
        assert_eq!(run.fluid_particles, 10 * 16 * 7);
        assert!(run.particle_steps_per_s() > 0.0);
    }

    #[test]
    fn bad_input_is_refused_with_the_value() {
        let e = dam_break(-0.01, 1.5, None).unwrap_err().to_string();
        assert!(e.contains("-0.01") && e.contains("(0, 0.05]"), "{e}");
        let e = dam_break(0.02, 0.5, None).unwrap_err().to_string();
        assert!(e.contains("0.5") && e.contains("1 to 4"), "{e}");
        let e = run_to_time(0.02, 1.5, None, 1, f64::NAN).unwrap_err().to_string();
        assert!(e.contains("NaN") && e.contains("positive"), "{e}");
    }
}
