//! `spatter forces`: the force ranking of the brownout thesis (Jasion 2013, Table 6.4) on screen and as CSV.

mod common;
use common::*;

#[test]
fn forces_prints_the_ranking_and_writes_csv() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = write(dir.path(), "f.toml", include_bytes!("../../../examples/forces_table_6_4.toml"));
    let out = dir.path().join("out");
    let o = spatter()
        .arg("forces")
        .arg(&scenario)
        .arg("--out")
        .arg(&out)
        .env("SPATTER_NO_PROGRESS", "1")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&o.stderr));
    // Critical drag coefficient A_H/F_D0 = 9.90 for every diameter (Jasion 2013, eq. 6.7–6.10).
    let line = stdout.lines().find(|l| l.starts_with("A_H/F_D0")).expect("A_H/F_D0 row");
    assert_eq!(line.matches("9.9000e0").count(), 3, "{line}");
    assert!(out.join("force_ranking.csv").is_file() && out.join("force_magnitudes.csv").is_file());
}

#[test]
fn forces_refuses_other_kinds() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = write(dir.path(), "s.toml", include_bytes!("../../../examples/snow_regime_map.toml"));
    let o = spatter().arg("forces").arg(&scenario).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("needs a scenario of kind \"forces\""));
}
