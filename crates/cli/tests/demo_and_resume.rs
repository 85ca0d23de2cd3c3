//! The README's main job and the interrupt/resume promise, through the real binary.

mod common;
use common::*;
use std::path::Path;

fn files(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn demo_writes_a_complete_run_folder() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("demo");
    let o = spatter().args(["demo", "--out"]).arg(&out).env("SPATTER_NO_PROGRESS", "1").output().unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "demo failed:\n{stdout}\n{}", String::from_utf8_lossy(&o.stderr));
    assert!(stdout.contains("regime_map.png"), "the demo says where the picture is:\n{stdout}");
    let names = files(&out);
    for must in ["run.toml", "log.txt", "impacts.csv", "regime_map.png", "regime_map.json"] {
        assert!(names.iter().any(|n| n == must), "{must} missing from {names:?}");
    }
    // ParaView series of the sample impacts: a .pvd whose every file exists and reads back.
    let pvd = std::fs::read_to_string(out.join("samples/bounce.pvd")).unwrap();
    let frames: Vec<&str> =
        pvd.lines().filter_map(|l| l.split("file=\"").nth(1)?.split('"').next()).collect();
    assert!(frames.len() > 10, "{pvd}");
    for f in &frames {
        let d = spatter_io::vtu::read(&out.join("samples").join(f)).unwrap();
        assert_eq!(d.points.len(), 1);
    }
    spatter_io::vtu::read(&out.join("samples/wall.vtu")).unwrap();
    // The resolved input is itself a valid scenario.
    let (code, err) = check(&out.join("run.toml"));
    assert_eq!(code, 0, "run.toml does not check: {err}");
    // CSV header carries units.
    let csv = std::fs::read_to_string(out.join("impacts.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains("normal_speed_m_s"));
}

#[test]
fn interrupted_and_resumed_run_equals_uninterrupted_run() {
    let dir = tempfile::tempdir().unwrap();
    let scenario =
        write(dir.path(), "map.toml", include_str!("../../../examples/snow_regime_map.toml").as_bytes());
    let whole = dir.path().join("whole");
    let parts = dir.path().join("parts");
    let run = |out: &Path, extra: &[&str], stop_after: Option<&str>| {
        let mut c = spatter();
        c.arg("run").arg(&scenario).arg("--out").arg(out).args(extra).env("SPATTER_NO_PROGRESS", "1");
        if let Some(n) = stop_after {
            c.env("SPATTER_STOP_AFTER_POLLS", n);
        }
        c.output().unwrap()
    };
    let o = run(&whole, &[], None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(&parts, &[], Some("3"));
    assert_eq!(
        o.status.code(),
        Some(130),
        "interrupted run exits 130: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    assert!(parts.join("checkpoint.bin").is_file(), "interruption leaves a checkpoint");
    assert!(String::from_utf8_lossy(&o.stdout).contains("--resume"), "tells how to continue");
    let o = run(&parts, &["--resume"], None);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!parts.join("checkpoint.bin").exists(), "a finished run removes its checkpoint");
    for f in ["impacts.csv", "interface.csv", "regime_map.json"] {
        let a = std::fs::read(whole.join(f)).unwrap();
        let b = std::fs::read(parts.join(f)).unwrap();
        assert!(a == b, "{f} differs between the uninterrupted and the resumed run");
    }
}
