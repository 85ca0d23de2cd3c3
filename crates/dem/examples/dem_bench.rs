//! The DEM benchmark outside the CLI, with the LAMMPS data file export used by `bench/dem/compare.sh`:
//!
//! `cargo run --release -p spatter-dem --example dem_bench -- [--quick] [--lammps-data box.data]
//!  [--steps N] [--threads-only 1]`

use spatter_dem::bench::{dense_box, settle, time_run, write_lammps_data, BoxCase};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let flag = |name: &str| args.iter().position(|a| a == name).and_then(|i| args.get(i + 1)).cloned();
    let quick = args.iter().any(|a| a == "--quick");
    if let Some(path) = flag("--lammps-data") {
        // Settle, export for LAMMPS, and time the same state here.
        let case = if quick { BoxCase::quick() } else { BoxCase::full() };
        let steps: u64 = flag("--steps").map(|s| s.parse().expect("--steps N")).unwrap_or(1000);
        let settle_steps: u64 = flag("--settle").map(|s| s.parse().expect("--settle N")).unwrap_or(600);
        let mut sim = dense_box(&case);
        settle(&mut sim, settle_steps).expect("settling");
        write_lammps_data(&sim, case.extent(), std::path::Path::new(&path)).expect("data file");
        let e = case.extent();
        println!("box_x {:.10e}", e.x);
        println!("box_y {:.10e}", e.y);
        println!("box_z {:.10e}", e.z);
        println!("particles {}", sim.particles.len());
        println!("dt {:e}", case.dt);
        println!("pair_contacts {}", sim.last_evaluation().pair_contacts);
        println!("bytes_per_particle {:.0}", sim.bytes_per_particle());
        let state = sim.state();
        let threads: Vec<usize> = match flag("--threads-only") {
            Some(t) => vec![t.parse().expect("--threads-only N")],
            None => vec![1, 2],
        };
        for t in threads {
            let r = time_run(&case, &state, t, steps, true).expect("timed run");
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
