//! One configuration of the SPH benchmark, for profiling:
//! `cargo run --release -p spatter-sph --example sph_bench -- [n] [threads] [steps] [h/dp]`
//! (n particles across the column width, default 46; 1 thread; 5 steps; smoothing length over spacing,
//! default that of the engine, 1.5 in 3D). Prints wall and CPU time
//! (user + system of the process) per step, throughput and the wall time per phase of the step.
//! `-- all` runs `bench::bench(true)` (the quick `spatter bench sph`), `-- full` the full one.

fn main() {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    if raw.first().is_some_and(|a| a == "all" || a == "full") {
        match spatter_sph::bench::bench(raw[0] == "all") {
            Ok(lines) => lines.iter().for_each(|l| println!("{l}")),
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(1);
            }
        }
        return;
    }
    const NAMES: [&str; 4] = ["n (particles across the column)", "threads", "steps", "h/dp"];
    let int = |k: usize, default: usize| -> usize {
        raw.get(k).map_or(default, |a| match a.parse::<usize>() {
            Ok(v) if v >= 1 => v,
            _ => {
                eprintln!(
                    "error: argument {} ({}) is {a:?}, expected a whole number of at least 1",
                    k + 1,
                    NAMES[k]
                );
                std::process::exit(2)
            }
        })
    };
    let (n, threads, steps) = (int(0, 46), int(1, 1), int(2, 5) as u64);
    // The range scenario files accept for `h_over_dp` (`scene/config.rs`).
    let h_over_dp = raw.get(3).map(|a| match a.parse::<f64>() {
        Ok(r) if (1.0..=4.0).contains(&r) => r,
        _ => {
            eprintln!("error: argument 4 ({}) is {a:?}, expected a number from 1 to 4", NAMES[3]);
            std::process::exit(2)
        }
    });
    match spatter_sph::bench::run_case_with(n, threads, steps, h_over_dp) {
        Ok(r) => {
            let inter = r.interactions_per_particle * r.fluid_particles as f64 * r.steps as f64;
            // The CPU clock ticks in 10 ms: a run shorter than a tick has no rate per CPU-second.
            let cpu = r.cpu_seconds.filter(|&c| c > 0.0).unwrap_or(f64::NAN);
            println!(
                "{} fluid + {} wall, {} thread(s), {} steps: {:.3} s/step wall, {:.3} CPU-s/step, {:.4e} particle-steps/s, {:.3e} interactions/s, {:.3e} interactions per CPU-s, {:.1} interactions per particle, {:.0} B/particle",
                r.fluid_particles,
                r.wall_particles,
                r.threads,
                r.steps,
                r.seconds / r.steps as f64,
                cpu / r.steps as f64,
                r.particle_steps_per_s,
                r.interactions_per_s,
                inter / cpu,
                r.interactions_per_particle,
                r.bytes_per_particle
            );
            println!("phase ms/step: {:?}", r.phase_ms);
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
