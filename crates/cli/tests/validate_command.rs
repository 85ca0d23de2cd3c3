//! `spatter validate`: the printed table, the exit code and the CSV with sources.

mod common;
use common::spatter;

#[test]
fn quick_validation_of_one_case_writes_its_table_with_sources() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("v.csv");
    let out = spatter()
        .args(["validate", "--quick", "--case", "flow_table_6_4", "--csv"])
        .arg(&csv)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains(" 0 failed (quick variants)"), "{stdout}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "case,quantity,reference,ours,error,tolerance_kind,tolerance,result,source"
    );
    let rows: Vec<&str> = lines.collect();
    // One CSV row per printed row, each naming its case, result and a non-empty source.
    let printed = stdout.lines().filter(|l| l.starts_with("flow_table_6_4")).count();
    assert!(printed > 0 && rows.len() == printed, "{} rows, {printed} printed", rows.len());
    for r in rows {
        assert!(r.starts_with("flow_table_6_4,") && r.contains(",pass,"), "{r}");
        assert!(!r.ends_with(",pass,"), "empty source: {r}");
    }
}

#[test]
fn an_unknown_case_is_an_error_not_an_empty_pass() {
    let out = spatter().args(["validate", "--quick", "--case", "no_such_case"]).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no validation case matches \"no_such_case\""));
}
