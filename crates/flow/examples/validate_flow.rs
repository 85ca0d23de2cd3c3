//! Prints the flow engine's validation table without the CLI:
//! `cargo run --release -p spatter-flow --example validate_flow [--quick]`.

fn main() {
    let quick = std::env::args().any(|a| a == "--quick");
    let mut failed = 0;
    for case in spatter_flow::validation::validation_cases() {
        for c in (case.run)(quick) {
            let ok = c.passed();
            failed += usize::from(!ok);
            println!(
                "{:<24} {:<52} ref {:>14.6e} ours {:>14.6e} err {:>9.2e} tol {:?} {}",
                c.case,
                c.quantity,
                c.reference,
                c.ours,
                c.error(),
                c.tolerance,
                if ok { "pass" } else { "FAIL" }
            );
        }
    }
    if failed > 0 {
        eprintln!("{failed} checks failed");
        std::process::exit(1);
    }
}
