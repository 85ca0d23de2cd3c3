//! One function per subcommand.

pub mod run;
pub mod sessile;
pub mod sweep;

use crate::registry;
use anyhow::Result;
use spatter_core::validation::Tolerance;
use std::path::Path;
use std::process::ExitCode;

/// Exit code for a scenario file with errors.
pub const EXIT_BAD_INPUT: u8 = 2;

/// Prints every scenario error, one per line, and how many there were.
pub fn report_errors(errors: &[spatter_scenario::ScenarioError]) {
    for e in errors {
        eprintln!("error: {e}");
    }
    if errors.len() > 1 {
        eprintln!("{} problems found; nothing was run.", errors.len());
    }
}

/// `spatter check`: validate and print the resolved input.
pub fn check(path: &Path) -> Result<ExitCode> {
    match spatter_scenario::load(path) {
        Ok(loaded) => {
            let text = loaded.scenario.resolved_toml().map_err(anyhow::Error::msg)?;
            print!("{text}");
            eprintln!("{}: valid `{}` scenario", path.display(), loaded.scenario.kind());
            Ok(ExitCode::SUCCESS)
        }
        Err(errors) => {
            report_errors(&errors);
            Ok(ExitCode::from(EXIT_BAD_INPUT))
        }
    }
}

/// `spatter validate`: run the registered cases and print one line per compared quantity; with `csv`,
/// also write the table (with each check's source) to that file.
pub fn validate(quick: bool, filter: Option<&str>, csv: Option<&Path>) -> Result<ExitCode> {
    let cases: Vec<_> = registry::validation_cases()
        .into_iter()
        .filter(|c| filter.is_none_or(|f| c.name.contains(f)))
        .collect();
    if cases.is_empty() {
        anyhow::bail!("no validation case matches {:?}", filter.unwrap_or(""));
    }
    println!(
        "{:<34} {:<46} {:>13} {:>13} {:>10} {:>10}  result",
        "case", "quantity", "reference", "ours", "rel.error", "tolerance"
    );
    let (mut passed, mut failed) = (0, 0);
    let mut rows = Vec::new();
    for case in cases {
        for c in (case.run)(quick) {
            let tol = match c.tolerance {
                Tolerance::Relative(t) => format!("{:.1e}", t),
                Tolerance::Absolute(t) => format!("±{:.1e}", t),
            };
            let ok = c.passed();
            let (kind, t) = match c.tolerance {
                Tolerance::Relative(t) => ("relative", t),
                Tolerance::Absolute(t) => ("absolute", t),
            };
            rows.push(vec![
                c.case.clone(),
                c.quantity.clone(),
                format!("{:e}", c.reference),
                format!("{:e}", c.ours),
                format!("{:e}", c.error()),
                kind.to_owned(),
                format!("{t:e}"),
                if ok { "pass" } else { "fail" }.to_owned(),
                c.source.clone(),
            ]);
            if ok {
                passed += 1
            } else {
                failed += 1
            }
            println!(
                "{:<34} {:<46} {:>13.6e} {:>13.6e} {:>10.2e} {:>10}  {}",
                c.case,
                c.quantity,
                c.reference,
                c.ours,
                c.error(),
                tol,
                if ok { "pass" } else { "FAIL" }
            );
        }
    }
    println!("\n{passed} passed, {failed} failed{}", if quick { " (quick variants)" } else { "" });
    if let Some(path) = csv {
        let header = [
            "case",
            "quantity",
            "reference",
            "ours",
            "error",
            "tolerance_kind",
            "tolerance",
            "result",
            "source",
        ];
        spatter_io::csv::write_table(path, &header, &rows)
            .map_err(|e| anyhow::anyhow!("cannot write {}: {e}", path.display()))?;
        println!("table with sources: {}", path.display());
    }
    Ok(if failed == 0 { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// `spatter forces <scenario>`: a `forces` run, which prints the ranking table and writes it as CSV.
pub fn forces(path: &Path, out: Option<&Path>) -> Result<ExitCode> {
    let loaded = match spatter_scenario::load(path) {
        Ok(l) => l,
        Err(errors) => {
            report_errors(&errors);
            return Ok(ExitCode::from(EXIT_BAD_INPUT));
        }
    };
    let spatter_scenario::Scenario::Forces(_) = &loaded.scenario else {
        eprintln!(
            "error: {}: `spatter forces` needs a scenario of kind \"forces\", this one is \"{}\" (use `spatter run`)",
            path.display(),
            loaded.scenario.kind()
        );
        return Ok(ExitCode::from(EXIT_BAD_INPUT));
    };
    // The run prints the ranking table (its headline) and writes the CSV tables.
    run::run_file(path, &run::RunArgs { out: out.map(Path::to_owned), ..run::RunArgs::default() })
}

/// `spatter bench <engine>`.
pub fn bench(engine: &str, quick: bool) -> Result<ExitCode> {
    for line in registry::run_bench(engine, quick)? {
        println!("{line}");
    }
    Ok(ExitCode::SUCCESS)
}
