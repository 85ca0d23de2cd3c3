//! The SPH validation cases of `spatter validate` without the CLI:
//! `cargo run --release -p spatter-sph --example sph_validate -- [--quick] [case-name-part]`.

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let filter = args.iter().find(|a| !a.starts_with("--"));
    let mut failed = 0;
    for case in spatter_sph::validation::validation_cases() {
        if filter.is_some_and(|f| !case.name.contains(f.as_str())) {
            continue;
        }
        let t0 = std::time::Instant::now();
        for c in (case.run)(quick) {
            let ok = c.passed();
            failed += usize::from(!ok);
            println!(
                "{:<28} {:<56} ref {:>12.5e} ours {:>12.5e} err {:>9.2e} tol {:?} {}",
                c.case,
                c.quantity,
                c.reference,
                c.ours,
                c.error(),
                c.tolerance,
                if ok { "pass" } else { "FAIL" }
            );
        }
        eprintln!("{}: {:.1} s", case.name, t0.elapsed().as_secs_f64());
    }
    std::process::exit(i32::from(failed > 0));
}
