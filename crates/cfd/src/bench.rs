//! `spatter bench flow`: cell-steps per second of the 3D lid-driven cube cavity.
//!
//! Unit cube, n³ uniform cells (n = 100: 10⁶ cells), lid y = 1 moving at 1 m/s in +x, ν = 10⁻³ m²/s
//! (Re = 1000), Δt = 0.5 h (Courant number 0.5 at the lid speed), pressure solved to a relative residual of
//! 10⁻⁶. The flow starts from rest; two steps run before the clock starts. The same case for OpenFOAM's
//! icoFoam is written by `bench/flow/compare.sh`.

use crate::bc::Boundary;
use crate::grid::Grid;
use crate::pcg::PcgSettings;
use crate::solver::{Flow, FlowError, Fluid, Numerics};
use std::time::Instant;

/// The benchmark flow with n³ cells.
pub fn cube_cavity(n: usize) -> Result<Flow, FlowError> {
    let grid =
        Grid::uniform_box([0.0; 3], [1.0; 3], [n, n, n]).map_err(|e| FlowError::Setup(e.to_string()))?;
    let wall = Boundary::Wall { velocity_m_s: [0.0; 3] };
    let lid = Boundary::Wall { velocity_m_s: [1.0, 0.0, 0.0] };
    let bc = [wall.clone(), wall.clone(), wall.clone(), lid, wall.clone(), wall];
    let len = grid.layout.len();
    let numerics =
        Numerics { pressure: PcgSettings { rtol: 1e-6, ..Default::default() }, ..Default::default() };
    Flow::new(grid, Fluid { density: 1.0, viscosity: 1e-3 }, bc, vec![false; len], numerics)
}

/// Measured speed of one run.
#[derive(Clone, Copy, Debug)]
pub struct BenchResult {
    pub cells: usize,
    pub steps: usize,
    pub threads: usize,
    pub seconds: f64,
    pub cell_steps_per_s: f64,
    /// CPU seconds of all the process's threads over the timed steps (Linux; 0 when unknown). On a
    /// loaded machine cell-steps per CPU-second on one thread is what an idle core would do.
    pub cpu_seconds: f64,
    pub mean_pressure_iterations: f64,
}

/// CPU time of all threads of this process \[s\] from `/proc/self/task/*/schedstat` (Linux).
pub fn process_cpu_seconds() -> Option<f64> {
    let mut ns = 0u64;
    for entry in std::fs::read_dir("/proc/self/task").ok()? {
        let p = entry.ok()?.path().join("schedstat");
        let s = std::fs::read_to_string(p).ok()?;
        ns += s.split_whitespace().next()?.parse::<u64>().ok()?;
    }
    Some(ns as f64 * 1e-9)
}

/// Runs `steps` timed steps of the n³ cavity on `threads` threads.
pub fn run_case(n: usize, steps: usize, threads: usize) -> Result<BenchResult, FlowError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| FlowError::Setup(format!("cannot start {threads} threads: {e}")))?;
    pool.install(|| {
        let mut f = cube_cavity(n)?;
        let dt = 0.5 / n as f64;
        for _ in 0..2 {
            f.step(dt)?;
        }
        let t0 = Instant::now();
        let c0 = process_cpu_seconds();
        let mut its = 0usize;
        for _ in 0..steps {
            its += f.step(dt)?.pressure.iterations;
        }
        let seconds = t0.elapsed().as_secs_f64();
        let cpu_seconds = match (c0, process_cpu_seconds()) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        };
        let cells = n * n * n;
        Ok(BenchResult {
            cells,
            steps,
            threads,
            seconds,
            cell_steps_per_s: (cells * steps) as f64 / seconds,
            cpu_seconds,
            mean_pressure_iterations: its as f64 / steps as f64,
        })
    })
}

/// One printable line.
pub fn describe(r: &BenchResult) -> String {
    format!(
        "cfd cavity {} cells, {} steps, {} thread(s): {:.3} s wall ({:.3} s CPU), {:.3e} cell-steps/s, {:.1} pressure iterations/step",
        r.cells, r.steps, r.threads, r.seconds, r.cpu_seconds, r.cell_steps_per_s, r.mean_pressure_iterations
    )
}

/// Runs the benchmark on 1 and 2 threads. `quick`: 40³ cells.
pub fn bench(quick: bool) -> Result<Vec<String>, FlowError> {
    let (n, steps) = if quick { (40, 5) } else { (100, 10) };
    let mut out = Vec::new();
    let mut rates = Vec::new();
    for threads in [1, 2] {
        let r = run_case(n, steps, threads)?;
        rates.push(r.cell_steps_per_s);
        out.push(describe(&r));
    }
    out.push(format!("speed-up on 2 threads: {:.2}", rates[1] / rates[0]));
    Ok(out)
}
