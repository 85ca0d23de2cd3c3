//! Scenario files that reference files which are not there.

mod common;
use common::*;

const HOPPER: &str = include_str!("../../../examples/dem_hopper.toml");

#[test]
fn nonexistent_mesh_file() {
    assert!(HOPPER.contains("file = \"dem_hopper.stl\""), "example changed");
    let text = HOPPER.replacen("file = \"dem_hopper.stl\"", "file = \"no_such_hopper.stl\"", 1);
    let line = text.lines().position(|l| l.contains("no_such_hopper.stl")).unwrap() + 1;
    rejects(
        "hopper.toml",
        text.as_bytes(),
        &[&format!("hopper.toml:{line}:"), "no_such_hopper.stl", "no such file"],
    );
}

#[test]
fn mesh_path_is_relative_to_the_scenario_not_the_working_directory() {
    // The example's STL sits beside it: checking it from another working directory must succeed.
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "dem_hopper.stl", include_bytes!("../../../examples/dem_hopper.stl"));
    let f = write(dir.path(), "hopper.toml", HOPPER.as_bytes());
    let out = spatter().arg("check").arg(&f).current_dir(std::env::temp_dir()).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
}
