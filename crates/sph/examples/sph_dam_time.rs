//! DualSPHysics's 01_DamBreak ([`spatter_sph::bench_dsph`]) run to a physical end time, for
//! `bench/sph/dualsphysics.sh`:
//! `cargo run --release -p spatter-sph --example sph_dam_time -- DP THREADS T_END [H/DP] [C0]`
//! (spacing DP \[m\], end time T_END \[s\], smoothing length over spacing, default √3 (DualSPHysics's
//! `coefh` 1, support 3.46 dp), sound speed C0 \[m/s\], default 20 √(g · 0.3 m)). Prints one line starting
//! with RESULT: key–value pairs (fluid and wall particles, steps, simulated time, time steps, wall and CPU
//! seconds of the steps and of the set-up, fluid particle-steps/s).

use spatter_sph::bench_dsph::run_to_time;

const NAMES: [&str; 5] = ["DP (particle spacing, m)", "THREADS", "T_END (s)", "H/DP", "C0 (m/s)"];

fn fail(k: usize, a: &str, expected: &str) -> ! {
    eprintln!("error: argument {} ({}) is {a:?}, expected {expected}", k + 1, NAMES[k]);
    std::process::exit(2)
}

fn main() {
    let raw: Vec<String> = std::env::args().skip(1).collect();
    if raw.len() < 3 || raw.len() > 5 {
        eprintln!("usage: sph_dam_time DP THREADS T_END [H/DP] [C0]");
        std::process::exit(2);
    }
    let num = |k: usize, ok: &dyn Fn(f64) -> bool, expected: &str| -> f64 {
        match raw[k].parse::<f64>() {
            Ok(v) if ok(v) => v,
            _ => fail(k, &raw[k], expected),
        }
    };
    let positive = |v: f64| v.is_finite() && v > 0.0;
    let dp = num(0, &positive, "a positive number");
    let threads = match raw[1].parse::<usize>() {
        Ok(t) if t >= 1 => t,
        _ => fail(1, &raw[1], "a whole number of at least 1"),
    };
    let t_end = num(2, &positive, "a positive number");
    let h_over_dp = if raw.len() > 3 {
        num(3, &|v| (1.0..=4.0).contains(&v), "a number from 1 to 4")
    } else {
        3f64.sqrt()
    };
    let c0 = (raw.len() > 4).then(|| num(4, &positive, "a positive number"));
    match run_to_time(dp, h_over_dp, c0, threads, t_end) {
        Ok(r) => {
            let cpu = r.cpu_seconds.unwrap_or(f64::NAN);
            println!(
                "RESULT fluid {} wall {} threads {} h_over_dp {:.6} steps {} time_s {:.6e} dt_min {:.4e} dt_mean {:.4e} dt_max {:.4e} wall_s {:.4} cpu_s {:.3} setup_s {:.3} particle_steps_per_s {:.4e}",
                r.fluid_particles,
                r.wall_particles,
                r.threads,
                h_over_dp,
                r.steps,
                r.time,
                r.dt_min,
                r.dt_mean,
                r.dt_max,
                r.seconds,
                cpu,
                r.setup_seconds,
                r.particle_steps_per_s()
            );
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
