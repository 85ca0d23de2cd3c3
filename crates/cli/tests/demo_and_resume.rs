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
        let d = spatter_io::vtk::read(&out.join("samples").join(f)).unwrap();
        assert_eq!(d.points.len(), 1);
    }
    spatter_io::vtk::read(&out.join("samples/wall.vtu")).unwrap();
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

/// A real Ctrl-C (SIGINT sent to the process while it runs, at a moment the test does not choose
/// exactly) stops the hopper example cleanly with exit code 130 and a checkpoint; `--resume` finishes
/// it, and every output equals that of the uninterrupted run byte for byte.
#[cfg(unix)]
#[test]
fn a_real_ctrl_c_interrupts_and_the_run_resumes_to_the_same_results() {
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    let text =
        include_str!("../../../examples/dem_hopper.toml").replace("duration_s = 1.5", "duration_s = 0.2");
    assert!(text.contains("duration_s = 0.2"));
    let scenario = write(dir.path(), "hopper.toml", text.as_bytes());
    write(dir.path(), "dem_hopper.stl", include_bytes!("../../../examples/dem_hopper.stl"));
    let (whole, parts) = (dir.path().join("whole"), dir.path().join("parts"));
    let command = |out: &Path, extra: &[&str]| {
        let mut c = spatter();
        c.arg("run").arg(&scenario).arg("--out").arg(out).args(extra).env("SPATTER_NO_PROGRESS", "1");
        c
    };
    let o = command(&whole, &[]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    // Interrupt once the third particle file (t = 0.04 s of 0.2 s) is written: VTU files are written whole
    // at each output, CSV rows only reach the disk once a second.
    let mut child = command(&parts, &[]).stdout(std::process::Stdio::null()).spawn().unwrap();
    let start = Instant::now();
    loop {
        let written = std::fs::read_dir(parts.join("particles")).map(|d| d.count()).unwrap_or(0);
        if written >= 3 {
            break;
        }
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it could be interrupted");
        assert!(start.elapsed() < Duration::from_secs(600), "no particle files written");
        std::thread::sleep(Duration::from_millis(20));
    }
    let kill = std::process::Command::new("kill").arg("-INT").arg(child.id().to_string()).status().unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "a Ctrl-C'd run exits 130");
    assert!(parts.join("checkpoint.bin").is_file(), "the interruption leaves a checkpoint");

    let o = command(&parts, &["--resume"]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!parts.join("checkpoint.bin").exists(), "a finished run removes its checkpoint");
    for f in ["energy.csv", "particles.pvd", "hopper_wall.pvd"] {
        let (a, b) = (std::fs::read(whole.join(f)).unwrap(), std::fs::read(parts.join(f)).unwrap());
        assert!(a == b, "{f} differs between the uninterrupted and the resumed run");
    }
    let vtus = files(&whole.join("particles"));
    assert_eq!(vtus, files(&parts.join("particles")));
    let last = vtus.last().unwrap();
    let (a, b) = (
        std::fs::read(whole.join("particles").join(last)).unwrap(),
        std::fs::read(parts.join("particles").join(last)).unwrap(),
    );
    assert!(a == b, "the last particle file {last} differs");
}
