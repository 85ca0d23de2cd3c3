//! Malformed scenario files that fail before any kind-specific schema applies. Each test asserts the
//! specific message (file, position, key, expected form) and that nothing panics.

mod common;
use common::*;

#[test]
fn empty_file() {
    rejects("empty.toml", b"", &["empty.toml", "the file is empty", "kind = "]);
    rejects("blank.toml", b"  \n\n\t\n", &["blank.toml", "the file is empty"]);
}

#[test]
fn binary_garbage() {
    let garbage: Vec<u8> = (0..600u32).map(|i| (i.wrapping_mul(2654435761) >> 13) as u8).collect();
    rejects("garbage.toml", &garbage, &["garbage.toml", "binary data, not a TOML text file"]);
    rejects("nul.toml", b"kind = \"dem\"\0\0\0", &["nul.toml", "NUL byte at offset 12"]);
}

#[test]
fn toml_syntax_error_is_located() {
    rejects(
        "syntax.toml",
        b"kind = \"dem\"\n[materials\nx = 1\n",
        &["syntax.toml:2:11", "unclosed table, expected `]`"],
    );
    rejects("noval.toml", b"kind = \"dem\"\ndt_s =\n", &["noval.toml:2:"]);
}

#[test]
fn missing_kind() {
    rejects(
        "nokind.toml",
        b"dt_s = 1e-6\n",
        &["nokind.toml:1:1", "key `kind`", "missing key `kind`", "expected one of"],
    );
}

#[test]
fn a_study_file_given_as_a_scenario_points_to_sweep() {
    rejects(
        "study.toml",
        b"base = \"snow.toml\"\n[[vary]]\nkey = \"grid.diameters\"\nvalues = [4, 8]\n",
        &["study.toml:1:1", "parameter study", "spatter sweep"],
    );
}

#[test]
fn kind_of_wrong_type() {
    rejects("kind42.toml", b"kind = 42\n", &["kind42.toml:1:1", "kind = 42 must be a string"]);
}

#[test]
fn unknown_kind() {
    rejects(
        "kindx.toml",
        b"# comment\nkind = \"dme\"\n",
        &["kindx.toml:2:8", "unknown kind \"dme\"", "expected one of"],
    );
}

#[test]
fn missing_file() {
    let dir = tempfile::tempdir().unwrap();
    let (code, err) = check(&dir.path().join("nope.toml"));
    assert_eq!(code, 2);
    assert!(err.contains("nope.toml") && err.contains("cannot read the scenario file"), "{err}");
}
