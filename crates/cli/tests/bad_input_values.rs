//! Malformed or out-of-range values in a real scenario (the snow regime-map example). Each test edits one
//! line of `examples/snow_regime_map.toml` and asserts the located message: file:line:column, the key path,
//! the bad value and the expected form.

mod common;
use common::*;

const BASE: &str = include_str!("../../../examples/snow_regime_map.toml");

/// The example with the first occurrence of `from` replaced by `to`; panics if `from` is absent so the
/// test cannot silently check the unedited file.
fn edited(from: &str, to: &str) -> String {
    assert!(BASE.contains(from), "example no longer contains `{from}`");
    BASE.replacen(from, to, 1)
}

/// 1-based line of the first line containing `needle` in `text`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).expect("needle present") + 1
}

#[test]
fn the_unedited_example_is_valid() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "ok.toml", BASE.as_bytes());
    let (code, err) = check(&f);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn unknown_key() {
    let text = edited("diameters = 46", "diameterz = 46");
    let l = line_of(&text, "diameterz");
    rejects(
        "unknown.toml",
        text.as_bytes(),
        &[&format!("unknown.toml:{l}:1"), "key `grid.diameterz`", "unknown field `diameterz`", "`diameters`"],
    );
}

#[test]
fn wrong_type() {
    let text = edited("diameters = 46", "diameters = \"many\"");
    let l = line_of(&text, "\"many\"");
    rejects(
        "type.toml",
        text.as_bytes(),
        &[
            &format!("type.toml:{l}:13"),
            "key `grid.diameters`",
            "invalid type: string \"many\"",
            "(found `\"many\"`)",
        ],
    );
}

#[test]
fn missing_key() {
    let text = edited("density_kg_m3 = 920.0\n", "");
    // Located at the table that lacks the key.
    let l = line_of(&text, "[particle]");
    rejects(
        "missing.toml",
        text.as_bytes(),
        &[&format!("missing.toml:{l}:1"), "key `particle`", "missing field `density_kg_m3`"],
    );
}

#[test]
fn unknown_choice() {
    let text = edited("mode = \"grid\"", "mode = \"gird\"");
    rejects(
        "choice.toml",
        text.as_bytes(),
        &["choice.toml:6:8", "key `mode`", "unknown variant `gird`", "`bisection`"],
    );
}

#[test]
fn negative_size() {
    let text = edited("diameter_min_m = 10e-6", "diameter_min_m = -10e-6");
    let l = line_of(&text, "diameter_min_m = -10e-6");
    rejects(
        "neg.toml",
        text.as_bytes(),
        &[
            &format!("neg.toml:{l}:18"),
            "key `grid.diameter_min_m`",
            "diameter_min_m = -0.00001 must be a positive number",
        ],
    );
}

#[test]
fn poisson_ratio_at_or_above_one_half() {
    let text = edited("poisson_ratio = 0.31", "poisson_ratio = 0.6");
    let l = line_of(&text, "poisson_ratio = 0.6");
    rejects(
        "nu.toml",
        text.as_bytes(),
        &[
            &format!("nu.toml:{l}:17"),
            "key `particle.poisson_ratio`",
            "poisson_ratio = 0.6 is outside [0, 0.5)",
        ],
    );
    let text = edited("poisson_ratio = 0.35", "poisson_ratio = 0.5");
    rejects(
        "nu_half.toml",
        text.as_bytes(),
        &["key `wall.poisson_ratio`", "poisson_ratio = 0.5 is outside [0, 0.5)"],
    );
}

#[test]
fn restitution_above_one() {
    let text = edited(
        "model = \"thornton\"\nyield_stress_pa = 1.0e6               # σ_y (thesis Table 3)\nform = \"full\"                         # full formula, e ≤ 1 (or \"power_law\": thesis Eq. 34, clamped)\nyield_geometry = \"wall\"               # thesis Eq. 32",
        "model = \"constant\"\nrestitution = 1.5",
    );
    let l = line_of(&text, "restitution = 1.5");
    rejects(
        "e.toml",
        text.as_bytes(),
        &[
            &format!("e.toml:{l}:15"),
            "key `contact.restitution.restitution`",
            "restitution = 1.5 is outside (0, 1]",
        ],
    );
}

#[test]
fn time_step_not_positive() {
    let text = edited("[integration]\n", "[integration]\ndt_s = 0.0\n");
    let l = line_of(&text, "dt_s = 0.0");
    rejects(
        "dt.toml",
        text.as_bytes(),
        &[&format!("dt.toml:{l}:8"), "key `integration.dt_s`", "dt_s = 0 must be a positive number"],
    );
    let text = edited("[integration]\n", "[integration]\ndt_s = -1e-9\n");
    rejects(
        "dtneg.toml",
        text.as_bytes(),
        &["key `integration.dt_s`", "dt_s = -0.000000001 must be a positive number"],
    );
}

#[test]
fn several_problems_are_listed_together() {
    let text = edited("poisson_ratio = 0.31", "poisson_ratio = 0.7").replacen(
        "diameter_min_m = 10e-6",
        "diameter_min_m = -1.0",
        1,
    );
    rejects(
        "two.toml",
        text.as_bytes(),
        &[
            "poisson_ratio = 0.7 is outside",
            "diameter_min_m = -1 must be a positive",
            "2 problems found; nothing was run.",
        ],
    );
}

#[test]
fn ice_temperature_above_melting() {
    let text = edited("# ice_temperature_c = -12.0", "ice_temperature_c = 5.0");
    let l = line_of(&text, "ice_temperature_c = 5.0");
    rejects(
        "ice.toml",
        text.as_bytes(),
        &[
            &format!("ice.toml:{l}:21"),
            "key `ice_temperature_c`",
            "ice_temperature_c = 5 is outside [-40, 0]",
        ],
    );
}
