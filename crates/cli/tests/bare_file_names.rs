//! A scenario named without a folder (`spatter check scenario.toml` run inside its folder) resolves its
//! relative file paths against the working directory, and a run folder's `run.toml` can be checked from
//! inside that folder.

mod common;
use common::spatter;
use std::path::PathBuf;

fn examples() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../examples").canonicalize().unwrap()
}

#[test]
fn a_bare_scenario_name_is_checked_in_the_working_directory() {
    let out = spatter().current_dir(examples()).args(["check", "snow_regime_map.toml"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "stderr:\n{err}");
}

#[test]
fn relative_file_keys_of_a_bare_scenario_name_become_absolute() {
    // The wedge deposition example names its OpenFOAM field and body relative to its folder.
    let out = spatter().current_dir(examples()).args(["check", "deposition_wedge.toml"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "stderr:\n{err}");
    let resolved = String::from_utf8_lossy(&out.stdout);
    let base = examples().to_string_lossy().into_owned();
    assert!(resolved.contains(&base), "no absolute path under {base} in:\n{resolved}");
}

#[test]
fn run_toml_is_checked_from_inside_its_run_folder() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("demo");
    let out = spatter().args(["demo", "--out"]).arg(&run).output().unwrap();
    assert!(out.status.success(), "demo failed:\n{}", String::from_utf8_lossy(&out.stderr));
    let out = spatter().current_dir(&run).args(["check", "run.toml"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "stderr:\n{err}");
}
