//! What the CLI can validate, benchmark and demonstrate: the lists collected from the engine crates.

use spatter_core::validation::Case;

/// Scenario that `spatter demo` runs: the snow regime map of `examples/snow_regime_map.toml` (the same
/// text, built into the binary so the demo needs no files).
pub const DEMO_SCENARIO: (&str, &str) =
    ("examples/snow_regime_map.toml", include_str!("../../../examples/snow_regime_map.toml"));

/// Names accepted by `spatter bench`.
pub const BENCHES: &[&str] = &["dem", "sph", "snow", "track", "flow"];

/// Every registered validation case, engine by engine.
pub fn validation_cases() -> Vec<Case> {
    let mut cases = spatter_dem::validation_cases();
    cases.extend(spatter_workflows::snow::validation_cases());
    cases.extend(spatter_flow::validation::validation_cases());
    cases.extend(spatter_sph::validation::validation_cases());
    cases.extend(spatter_cfd::validation::validation_cases());
    cases.extend(spatter_workflows::cfd_dem::validation::validation_cases());
    cases
}

/// Runs benchmark `name` and returns the lines to print.
pub fn run_bench(name: &str, quick: bool) -> anyhow::Result<Vec<String>> {
    match name {
        "dem" => Ok(spatter_dem::bench::bench(quick)?),
        "sph" => Ok(spatter_sph::bench::bench(quick)?),
        "snow" => Ok(spatter_workflows::snow::bench(quick)?),
        "track" => Ok(spatter_flow::bench::bench(quick)?),
        "flow" => Ok(spatter_cfd::bench::bench(quick)?),
        _ => anyhow::bail!("no benchmark named `{name}`; expected one of: {}", BENCHES.join(", ")),
    }
}
