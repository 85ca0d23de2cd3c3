//! The tracker benchmark without the CLI: `cargo run --release -p spatter-flow --example track_bench [--quick]`.

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    match spatter_flow::bench::bench(quick) {
        Ok(lines) => lines.iter().for_each(|l| println!("{l}")),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
