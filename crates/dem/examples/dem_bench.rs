//! The DEM benchmark outside the CLI, with the LAMMPS data file export used by `bench/dem/compare.sh`:
//!
//! `cargo run --release -p spatter-dem --example dem_bench -- [--quick] [--clumps] [--lammps-data box.data]
//!  [--steps N] [--threads-only 1] [--per-contact | --no-energy] [--chunks N [--chunk-steps K]]`
//!
//! `--dump state.txt [--steps N] [--settle N] [--threads-only T]` writes the settled box and the box after
//! N more steps (default 100) as the bits of every position, velocity, spin and energy account
//! (`bench::state_bits`): compare the files of two builds to see whether a change kept the motion bit for
//! bit. `--save-settled FILE` keeps the settled box (a checkpoint) and `--settled FILE` starts from it
//! instead of settling, with `--dump` and `--lammps-data`: a profile (valgrind) then simulates only the
//! steps it counts.
//! With `--chunks`, prints the fastest and the median chunk; `DEM_BENCH_TRACE=1` lists every chunk time
//! on stderr (bursts of slow steps are the shared host, not the code).

use spatter_dem::bench::{
    dense_box, run_state_bits, settle, state_bits, time_run, write_lammps_data, BoxCase,
};
use spatter_dem::contact::HertzMindlin;
use spatter_dem::Simulation;

/// The settled box: loaded from `--settled FILE` (a state saved by `--save-settled FILE`, so that a profile
/// under valgrind need not simulate the settling), else settled here for `settle_steps` steps.
fn settled_box(
    case: &BoxCase,
    settle_steps: u64,
    flag: &dyn Fn(&str) -> Option<String>,
) -> Simulation<HertzMindlin> {
    let mut sim = dense_box(case);
    if let Some(path) = flag("--settled") {
        let state = spatter_io::checkpoint::load(std::path::Path::new(&path), 0).expect("--settled FILE");
        sim.restore(state).expect("restoring the settled state");
        return sim;
    }
    settle(&mut sim, settle_steps).expect("settling");
    if let Some(path) = flag("--save-settled") {
        spatter_io::checkpoint::save(std::path::Path::new(&path), 0, &sim.state())
            .expect("--save-settled FILE");
    }
    sim
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let flag = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let quick = args.iter().any(|a| a == "--quick");
    // Energy budget: residual (the scene default), `--per-contact`, or none (`--no-energy`).
    let energy = if args.iter().any(|a| a == "--no-energy") {
        None
    } else if args.iter().any(|a| a == "--per-contact") {
        Some(spatter_dem::EnergyMethod::PerContact)
    } else {
        Some(spatter_dem::EnergyMethod::Residual)
    };
    if args.iter().any(|a| a == "--clumps") {
        // The sphere box and the clump box with the same number of member spheres, 1 and 2 threads.
        let case = if quick { BoxCase::quick() } else { BoxCase::full() };
        let steps: u64 =
            flag("--steps").map(|s| s.parse().expect("--steps N")).unwrap_or(if quick { 200 } else { 400 });
        let settle_steps: u64 = flag("--settle")
            .map(|s| s.parse().expect("--settle N"))
            .unwrap_or(if quick { 2000 } else { 4000 });
        let mut sim = dense_box(&case);
        settle(&mut sim, settle_steps).expect("settling");
        let state = sim.state();
        let one = time_run(&case, &state, 1, steps, true, energy).expect("1 thread");
        let two = time_run(&case, &state, 2, steps, true, energy).expect("2 threads");
        println!(
            "spheres: {} ; 1 thread {:.3e}, 2 threads {:.3e} particle-steps/s",
            sim.particles.len(),
            one.rate(),
            two.rate()
        );
        let clump_settle: u64 = flag("--clump-settle")
            .map(|s| s.parse().expect("--clump-settle N"))
            .unwrap_or(spatter_dem::bench::CLUMP_SETTLE_STEPS);
        for line in spatter_dem::bench::bench_clumps(&case, clump_settle, steps, one.rate(), two.rate())
            .expect("clumps")
        {
            println!("{line}");
        }
        return;
    }
    if let Some(path) = flag("--dump") {
        // Byte-identity check: the settled box and the box after `--steps` more steps, as bits.
        let case = if quick { BoxCase::quick() } else { BoxCase::full() };
        let steps: u64 = flag("--steps").map(|s| s.parse().expect("--steps N")).unwrap_or(100);
        let settle_steps: u64 = flag("--settle")
            .map(|s| s.parse().expect("--settle N"))
            .unwrap_or(if quick { 2000 } else { 4000 });
        let threads: usize =
            flag("--threads-only").map(|s| s.parse().expect("--threads-only N")).unwrap_or(1);
        let sim = settled_box(&case, settle_steps, &flag);
        let mut text = state_bits(&sim);
        text.push_str(&run_state_bits(&case, &sim.state(), threads, steps, energy).expect("run"));
        std::fs::write(&path, text).expect("writing the dump");
        return;
    }
    if let Some(path) = flag("--lammps-data") {
        // Settle, export for LAMMPS, and time the same state here.
        let case = if quick { BoxCase::quick() } else { BoxCase::full() };
        let steps: u64 = flag("--steps").map(|s| s.parse().expect("--steps N")).unwrap_or(1000);
        let settle_steps: u64 = flag("--settle")
            .map(|s| s.parse().expect("--settle N"))
            .unwrap_or(if quick { 2000 } else { 4000 });
        let sim = settled_box(&case, settle_steps, &flag);
        write_lammps_data(&sim, case.extent(), std::path::Path::new(&path)).expect("data file");
        let e = case.extent();
        println!("box_x {:.10e}", e.x);
        println!("box_y {:.10e}", e.y);
        println!("box_z {:.10e}", e.z);
        println!("particles {}", sim.particles.len());
        println!("dt {:e}", case.dt);
        println!("pair_contacts {}", sim.last_evaluation().pair_contacts);
        let e = sim.energy();
        println!("kinetic_over_elastic {:.3e}", (e.kinetic + e.rotational) / e.elastic.max(1e-300));
        println!("bytes_per_particle {:.0}", sim.bytes_per_particle());
        let state = sim.state();
        if let Some(chunks) = flag("--chunks") {
            // Noisy machines: the fastest of many short chunks approximates the uncontended speed.
            let chunks: usize = chunks.parse().expect("--chunks N");
            let chunk_steps: u64 =
                flag("--chunk-steps").map(|s| s.parse().expect("--chunk-steps N")).unwrap_or(10);
            let t: usize = flag("--threads-only").map(|s| s.parse().expect("--threads-only N")).unwrap_or(1);
            let mut run = dense_box(&case);
            run.restore(state).expect("restore");
            run.law.energy = energy.is_some();
            run.energy_method = energy.unwrap_or_default();
            let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build().expect("pool");
            let mut times = Vec::with_capacity(chunks);
            pool.install(|| {
                for _ in 0..chunks {
                    let t0 = std::time::Instant::now();
                    run.run_steps(chunk_steps).expect("steps");
                    times.push(t0.elapsed().as_secs_f64() / chunk_steps as f64);
                }
            });
            if std::env::var_os("DEM_BENCH_TRACE").is_some() {
                for (k, t) in times.iter().enumerate() {
                    eprintln!("chunk {k} {t:.6}");
                }
            }
            let mut sorted = times.clone();
            sorted.sort_by(f64::total_cmp);
            let best = sorted[0];
            let median = sorted[sorted.len() / 2];
            println!(
                "spatter_threads_{t}_best_chunk {:.6e} particle-steps/s",
                run.particles.len() as f64 / best
            );
            println!(
                "spatter_threads_{t}_median_chunk {:.6e} particle-steps/s",
                run.particles.len() as f64 / median
            );
            return;
        }
        let threads: Vec<usize> = match flag("--threads-only") {
            Some(t) => vec![t.parse().expect("--threads-only N")],
            None => vec![1, 2],
        };
        for t in threads {
            let r = time_run(&case, &state, t, steps, true, energy).expect("timed run");
            println!(
                "spatter_threads_{t} {:.6e} particle-steps/s ({} steps, {:.3} s, {} rebuilds)",
                r.rate(),
                r.steps,
                r.seconds,
                r.rebuilds
            );
        }
        return;
    }
    match spatter_dem::bench::bench(quick) {
        Ok(lines) => lines.iter().for_each(|l| println!("{l}")),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
