//! What the CLI can validate, benchmark and demonstrate: the lists collected from the engine crates.

use spatter_core::validation::Case;

/// Scenario that `spatter demo` runs: (name shown to the user, TOML text).
pub const DEMO_SCENARIO: (&str, &str) = ("(none)", "");

/// Names accepted by `spatter bench`.
pub const BENCHES: &[&str] = &[];

/// Every registered validation case.
pub fn validation_cases() -> Vec<Case> {
    Vec::new()
}

/// Runs benchmark `name` and returns the lines to print.
pub fn run_bench(name: &str, _quick: bool) -> anyhow::Result<Vec<String>> {
    anyhow::bail!("no benchmark named `{name}`")
}
