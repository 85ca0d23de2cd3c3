//! The tracker benchmarks (unstructured field, rotor downwash) without the CLI:
//! `cargo run --release -p spatter-flow --example track_bench [--quick] [--rotor]` (`--rotor`: only the
//! rotor case).

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let run = if std::env::args().any(|a| a == "--rotor") {
        spatter_flow::bench::rotor_bench(quick)
    } else {
        spatter_flow::bench::bench(quick)
    };
    match run {
        Ok(lines) => lines.iter().for_each(|l| println!("{l}")),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
