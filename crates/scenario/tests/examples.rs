//! Every example scenario under `examples/` is valid (study files, `*_study.toml`, are checked by the
//! study crate), and its fully resolved input (what a run writes as
//! `run.toml`) is itself a valid scenario when placed in an unrelated folder: file paths in it are absolute.

use std::path::{Path, PathBuf};

fn examples() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter(|p| !p.to_string_lossy().ends_with("_study.toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn every_example_and_its_resolved_input_are_valid() {
    let list = examples();
    assert!(list.len() >= 8, "examples found: {list:?}");
    let elsewhere = tempfile::tempdir().unwrap();
    for path in list {
        let loaded = spatter_scenario::load(&path).unwrap_or_else(|e| {
            panic!("{}: {}", path.display(), e.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("\n"))
        });
        let resolved = loaded.scenario.resolved_toml().unwrap();
        let again = elsewhere.path().join(path.file_name().unwrap());
        std::fs::write(&again, &resolved).unwrap();
        let reloaded = spatter_scenario::load(&again).unwrap_or_else(|e| {
            panic!(
                "run.toml of {} does not load from another folder:\n{}",
                path.display(),
                e.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("\n")
            )
        });
        assert_eq!(reloaded.scenario.kind(), loaded.scenario.kind());
        assert_eq!(
            reloaded.scenario.resolved_toml().unwrap(),
            resolved,
            "{}: resolving is idempotent",
            path.display()
        );
    }
}
