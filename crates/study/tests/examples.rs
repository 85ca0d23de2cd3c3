//! Every study under `examples/` (`*_study.toml`) reads, and every one of its cases is a valid scenario.

use std::path::Path;

#[test]
fn every_example_study_plans() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut studies: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with("_study.toml"))
        .collect();
    studies.sort();
    assert!(!studies.is_empty(), "no example study in {}", dir.display());
    let cases = tempfile::tempdir().unwrap();
    for path in studies {
        let study = spatter_study::StudyFile::read(&path)
            .unwrap_or_else(|e| panic!("{}", e.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("\n")));
        let plan = spatter_study::Plan::new(&study, cases.path())
            .unwrap_or_else(|e| panic!("{}", e.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("\n")));
        assert_eq!(plan.cases.len(), study.case_count(), "{}", path.display());
    }
}
