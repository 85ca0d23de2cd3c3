//! The `sph` scenario: configuration checks, outputs, and checkpoint/resume that continues bit for bit.

use spatter_core::check::Checker;
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_io::run::{RunContext, RunDir};
use spatter_sph::scene::{run, SphConfig};
use std::path::Path;

/// A small 2D dam break with a probe, a wall probe and height sensors.
const SMALL: &str = r#"
title = "test"
[fluid]
dimensions = 2
spacing_m = 0.01
[[walls]]
name = "tank"
type = "tank"
min_m = [0.0, 0.0, 0.0]
max_m = [0.4, 0.0, 0.3]
[[fill]]
type = "box"
min_m = [0.0, 0.0, 0.0]
max_m = [0.1, 0.0, 0.2]
[output]
end_time_s = 0.05
vtu_interval_s = 0.01
sample_interval_s = 0.002
[[sensors.probes]]
name = "p1"
position_m = [0.05, 0.0, 0.05]
[[sensors.wall_probes]]
name = "far"
position_m = [0.405, 0.0, 0.02]
radius_m = 0.02
[sensors.height]
base_z_m = 0.0
bin_m = 0.02
bins = 10
window_s = [0.01, 0.05]
"#;

fn config(text: &str) -> SphConfig {
    let cfg: SphConfig = toml::from_str(text).expect("parses");
    Checker::run(&cfg, None).expect("valid");
    cfg
}

fn run_to_end(cfg: &SphConfig, dir: &Path) {
    let d = RunDir::create(dir).unwrap();
    let s = run(cfg, &RunContext { dir: &d, control: &Unattended, resume: false }).unwrap();
    assert_eq!(s.finished, Finished::Completed);
}

#[test]
fn a_run_writes_every_output() {
    let cfg = config(SMALL);
    let tmp = tempfile::tempdir().unwrap();
    run_to_end(&cfg, tmp.path());
    for f in [
        "series.csv",
        "particles.pvd",
        "particles/particles_00000.vtu",
        "particles/particles_00005.vtu",
        "log.txt",
        "wetting.csv",
        "wetting/tank.vtu",
        "wetting/tank.png",
        "splash_height.csv",
        "splash_height.png",
    ] {
        assert!(tmp.path().join(f).is_file(), "{f} missing");
    }
    let (cols, rows) = spatter_io::csv::read_series(&tmp.path().join("series.csv")).unwrap();
    assert!(cols.iter().any(|c| c == "far_p_Pa") && cols.iter().any(|c| c == "tank_Fz_N"));
    assert!(rows.len() >= 25, "a row every 2 ms: {}", rows.len());
    let vtu = spatter_io::vtu::read(&tmp.path().join("particles/particles_00005.vtu")).unwrap();
    assert_eq!(vtu.points.len(), 10 * 20);
    let log = std::fs::read_to_string(tmp.path().join("log.txt")).unwrap();
    assert!(log.contains("run cost:") && log.contains("core-hours") && log.contains("dt = "), "{log}");
    assert!(!tmp.path().join("checkpoint.bin").exists(), "a finished run leaves no checkpoint");
}

#[test]
fn an_interrupted_run_resumes_bit_for_bit() {
    let cfg = config(SMALL);
    let full = tempfile::tempdir().unwrap();
    run_to_end(&cfg, full.path());
    let split = tempfile::tempdir().unwrap();
    let d = RunDir::create(split.path()).unwrap();
    let stop = StopAfterPolls::new(60);
    let s = run(&cfg, &RunContext { dir: &d, control: &stop, resume: false }).unwrap();
    assert_eq!(s.finished, Finished::Interrupted);
    assert!(split.path().join("checkpoint.bin").is_file());
    let s = run(&cfg, &RunContext { dir: &d, control: &Unattended, resume: true }).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    for f in
        ["series.csv", "particles.pvd", "particles/particles_00005.vtu", "wetting.csv", "splash_height.csv"]
    {
        let a = std::fs::read(full.path().join(f)).unwrap();
        let b = std::fs::read(split.path().join(f)).unwrap();
        assert!(a == b, "{f} differs after resume");
    }
}

#[test]
fn bad_values_are_named_with_their_key() {
    let bad = SMALL.replace("spacing_m = 0.01", "spacing_m = -0.01\nsound_speed_factor = 5.0");
    let cfg: SphConfig = toml::from_str(&bad).unwrap();
    let errs = Checker::run(&cfg, None).unwrap_err();
    let keys: Vec<&str> = errs.iter().map(|e| e.key.as_str()).collect();
    assert!(keys.contains(&"fluid.spacing_m") && keys.contains(&"fluid.sound_speed_factor"), "{errs:?}");
    let bad = SMALL.replace("type = \"tank\"", "type = \"tank\"\nmotion = \"nowhere\"");
    let cfg: SphConfig = toml::from_str(&bad).unwrap();
    let errs = Checker::run(&cfg, None).unwrap_err();
    assert_eq!(errs[0].key, "walls[0].motion", "{errs:?}");
    assert!(toml::from_str::<SphConfig>(&SMALL.replace("[output]", "[output]\nunknown_key = 1")).is_err());
}

#[test]
fn shipped_examples_are_valid() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for name in ["sph_dam_break.toml", "sph_wheel.toml", "sph_baffle.toml"] {
        let text = std::fs::read_to_string(root.join(name)).unwrap();
        let body: String =
            text.lines().filter(|l| !l.trim_start().starts_with("kind")).collect::<Vec<_>>().join("\n");
        let cfg: SphConfig = toml::from_str(&body).unwrap_or_else(|e| panic!("{name}: {e}"));
        Checker::run(&cfg, Some(&root)).unwrap_or_else(|e| panic!("{name}: {e:?}"));
    }
}

#[test]
fn the_resolved_configuration_round_trips_through_toml() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(root.join("sph_wheel.toml")).unwrap();
    let body: String =
        text.lines().filter(|l| !l.trim_start().starts_with("kind")).collect::<Vec<_>>().join("\n");
    let cfg: SphConfig = toml::from_str(&body).unwrap();
    let resolved = toml::to_string(&cfg).expect("serialises");
    let back: SphConfig = toml::from_str(&resolved).expect("parses back");
    assert_eq!(back, cfg);
    assert!(resolved.contains("artificial_viscosity = 0.02"), "defaults are written out:\n{resolved}");
}
