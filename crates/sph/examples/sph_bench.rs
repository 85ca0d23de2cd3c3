//! One configuration of the SPH benchmark, for profiling:
//! `cargo run --release -p spatter-sph --example sph_bench -- [n] [threads] [steps]`
//! (n particles across the column width, default 46; 1 thread; 5 steps). Prints wall and CPU time
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
    let args: Vec<usize> = raw.iter().filter_map(|a| a.parse().ok()).collect();
    let n = args.first().copied().unwrap_or(46);
    let threads = args.get(1).copied().unwrap_or(1);
    let steps = args.get(2).copied().unwrap_or(5) as u64;
    match spatter_sph::bench::run_case(n, threads, steps) {
        Ok(r) => {
            let inter = r.interactions_per_particle * r.fluid_particles as f64 * r.steps as f64;
            let cpu = r.cpu_seconds.unwrap_or(f64::NAN);
            println!(
                "{} fluid + {} wall, {} thread(s), {} steps: {:.3} s/step wall, {:.3} CPU-s/step, {:.3e} interactions/s, {:.3e} interactions per CPU-s, {:.1} interactions per particle, {:.0} B/particle",
                r.fluid_particles,
                r.wall_particles,
                r.threads,
                r.steps,
                r.seconds / r.steps as f64,
                cpu / r.steps as f64,
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
