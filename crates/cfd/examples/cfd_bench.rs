//! `cfd_bench N STEPS THREADS`: one run of the cube-cavity benchmark (see `spatter_cfd::bench`), printing
//! a `RESULT` line for scripts.
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let num = |i: usize, default: usize, name: &str| -> usize {
        match args.get(i) {
            None => default,
            Some(s) => match s.parse::<usize>() {
                Ok(v) if v > 0 => v,
                _ => {
                    eprintln!("cfd_bench: {name} = {s:?} must be a positive integer (usage: cfd_bench N STEPS THREADS)");
                    std::process::exit(2);
                }
            },
        }
    };
    let n = num(1, 100, "N");
    let steps = num(2, 10, "STEPS");
    let threads = num(3, 1, "THREADS");
    match spatter_cfd::bench::run_case(n, steps, threads) {
        Ok(r) => {
            println!("{}", spatter_cfd::bench::describe(&r));
            println!(
                "RESULT cells={} steps={} threads={} seconds={:.4} cpu_seconds={:.4} cell_steps_per_s={:.6e}",
                r.cells, r.steps, r.threads, r.seconds, r.cpu_seconds, r.cell_steps_per_s
            );
        }
        Err(e) => {
            eprintln!("cfd_bench: {e}");
            std::process::exit(1);
        }
    }
}
