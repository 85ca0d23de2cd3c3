//! The deposition scenario's `[forces] wall_lift` key: accepted with every documented choice, and every
//! bad value refused with file:line:column, the key path, the value and the expected form.

use std::path::{Path, PathBuf};

const BASE: &str = include_str!("../../../examples/deposition_stagnation_plate.toml");

/// The stagnation-plate example with a `[forces]` table holding `wall_lift = <value>`, read as if it lay
/// in `examples/` (so its body and regime-map paths resolve).
fn load(value: &str) -> Result<spatter_scenario::Loaded, Vec<spatter_scenario::ScenarioError>> {
    let path: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/wall_lift_check.toml");
    let text = format!("{BASE}\n[forces]\nwall_lift = {value}\n");
    spatter_scenario::load_str(&path, &text)
}

fn refused(value: &str, must: &[&str]) {
    let errs = match load(value) {
        Ok(_) => panic!("`wall_lift = {value}` was accepted"),
        Err(e) => e,
    };
    let text = errs.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("\n");
    for m in must {
        assert!(text.contains(m), "`{m}` missing from:\n{text}");
    }
}

#[test]
fn documented_choices_load() {
    for v in [
        "{}",
        "{ law = \"regimes\" }",
        "{ law = \"hall\", zeng_alpha = \"as_printed\" }",
        "{ law = \"mollinger\", friction_velocity_m_s = 0.4 }",
        "{ law = \"saffman\" }",
        "{ law = \"leighton_acrivos\", zeng_alpha = \"zeng\" }",
    ] {
        let loaded = load(v).unwrap_or_else(|e| panic!("{v}: {}", e[0]));
        let resolved = loaded.scenario.resolved_toml().unwrap();
        assert!(resolved.contains("[forces.wall_lift]"), "{resolved}");
    }
}

#[test]
fn bad_values_are_located_and_explained() {
    // The appended `wall_lift = …` line is the last line of the file.
    let line = BASE.lines().count() + 3;
    refused(
        "{ law = \"hal\" }",
        &[
            &format!("wall_lift_check.toml:{line}:"),
            "key `forces.wall_lift.law`",
            "unknown variant `hal`",
            "`regimes`",
        ],
    );
    refused(
        "{ friction_velocity_m_s = -0.4 }",
        &[
            &format!("wall_lift_check.toml:{line}:"),
            "key `forces.wall_lift.friction_velocity_m_s`",
            "friction_velocity_m_s = -0.4 must be a positive number",
        ],
    );
    refused(
        "{ friction_velocity_m_s = \"fast\" }",
        &[
            "key `forces.wall_lift.friction_velocity_m_s`",
            "invalid type: string \"fast\"",
            "expected a number",
        ],
    );
    refused(
        "{ zeng_alpha = \"printed\" }",
        &["key `forces.wall_lift.zeng_alpha`", "unknown variant `printed`", "`as_printed`"],
    );
    refused("{ lwa = \"hall\" }", &["key `forces.wall_lift.lwa`", "unknown field `lwa`"]);
    refused("true", &["key `forces.wall_lift`", "invalid type: boolean `true`"]);
}
