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

/// Reads a CSV table with a text column: the header and the rows of fields.
fn read_table(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let split = |l: &str| l.split(',').map(str::to_owned).collect::<Vec<_>>();
    let mut lines = text.lines();
    let head = split(lines.next().unwrap());
    (head, lines.map(split).collect())
}

/// Field `name` of a table row, as a number.
fn field(head: &[String], row: &[String], name: &str) -> f64 {
    let k = head.iter().position(|c| c == name).unwrap_or_else(|| panic!("no column {name}"));
    row[k].parse().unwrap_or_else(|_| panic!("{name} = {} is not a number", row[k]))
}

/// Column `name` of a numeric series.
fn column(cols: &[String], rows: &[Vec<f64>], name: &str) -> Vec<f64> {
    let k = cols.iter().position(|c| c == name).unwrap_or_else(|| panic!("no column {name}"));
    rows.iter().map(|r| r[k]).collect()
}

/// Two slabs of water in zero gravity: A, 0.2 m wide, z ∈ [0, 0.2] m at t = 0, moving up at 0.4 m/s, and B,
/// 0.1 m wide, z ∈ [0.2, 0.4] m, moving down at 0.4 m/s, 0.3 m apart. At the rest density nothing acts on
/// them: they move rigidly (exactly: every pair has zero pressure and relative velocity).
const SLABS: &str = r#"
[fluid]
dimensions = 2
spacing_m = 0.01
gravity_m_s2 = [0.0, 0.0, 0.0]
[domain]
min_m = [-0.5, -1.0, -0.5]
max_m = [1.0, 1.0, 1.0]
[[fill]]
type = "box"
min_m = [0.0, 0.0, 0.0]
max_m = [0.2, 0.0, 0.2]
velocity_m_s = [0.0, 0.0, 0.4]
[[fill]]
type = "box"
min_m = [0.5, 0.0, 0.2]
max_m = [0.6, 0.0, 0.4]
velocity_m_s = [0.0, 0.0, -0.4]
[output]
end_time_s = 0.2
vtu_interval_s = 0.2
sample_interval_s = 0.01
[sensors.height]
base_z_m = 0.0
bin_m = 0.02
bins = 25
window_s = [0.1, 0.2]
"#;

/// Length of [a, b] ∩ [lo, hi].
fn overlap(a: f64, b: f64, lo: f64, hi: f64) -> f64 {
    (b.min(hi) - a.max(lo)).max(0.0)
}

/// Moving slabs (`SLABS`): the volume crossing each plane is the slab's width times the length of slab
/// that passes it in the window, upward for A and downward for B, and the mean volume per bin is the
/// time-average of the slabs' overlap with it. Also with the run ending inside the window (end 0.15 s):
/// both are averaged over the part of the window the run covered (until 2026-11-24 such a run reported
/// zero flux).
#[test]
fn moving_slabs_give_the_volume_flux_and_mean_volume_per_bin() {
    let (wa, wb, v, dp, bin) = (0.2, 0.1, 0.4, 0.01, 0.02);
    let t0 = 0.1;
    for end in [0.2, 0.15] {
        let cfg = config(&SLABS.replace("end_time_s = 0.2", &format!("end_time_s = {end}")));
        let tmp = tempfile::tempdir().unwrap();
        run_to_end(&cfg, tmp.path());
        let (cols, rows) = spatter_io::csv::read_series(&tmp.path().join("series.csv")).unwrap();
        let dt_max = column(&cols, &rows, "dt_s").iter().copied().fold(0.0, f64::max);
        // The run stops at the first step end at or after end_time_s; the last row is written there.
        let t1 = column(&cols, &rows, "t_s").last().copied().unwrap().min(0.2);
        let span = t1 - t0;
        let (head, rows) = read_table(&tmp.path().join("splash_height.csv"));
        assert_eq!(rows.len(), 25);
        for row in &rows {
            let zp = field(&head, row, "bin_low_m");
            // Rows of A pass the plane z_p in the window if they started at z_p − v t, t in the window; rows
            // of B if they started at z_p + v t. Rows cross the planes at 0.0125 s + k 0.025 s, at least
            // 0.011 s (12 steps) from the window's ends (0.1 s; 0.15 or 0.2 s, or the step end just after
            // them), so the count is exact: tolerance round-off (1e-9 relative).
            let up = wa * overlap(zp - v * t1, zp - v * t0, 0.0, 0.2) / span;
            let down = wb * overlap(zp + v * t0, zp + v * t1, 0.2, 0.4) / span;
            let got_up = field(&head, row, "upward_flux_lower_edge_m3_s");
            let got_net = field(&head, row, "net_flux_lower_edge_m3_s");
            assert!(
                (got_up - up).abs() <= 1e-9 * wa * v,
                "end {end}, plane {zp}: up {got_up}, expected {up}"
            );
            assert!(
                (got_net - (up - down)).abs() <= 1e-9 * wa * v,
                "end {end}, plane {zp}: net {got_net}, expected {}",
                up - down
            );
            // Mean volume in [z_p, z_p + bin]: time-average of the slabs' overlap with the bin (midpoint rule,
            // 10⁴ points; the overlap is piecewise linear). The sensor samples the volume at step ends, so
            // each row entering or leaving the bin counts up to one step too long or too short: tolerance two
            // such rows of A, 2 W_A dp dt_max / span (a bin meets at most one slab edge, two rows).
            let n = 10_000;
            let mut want = 0.0;
            for i in 0..n {
                let t = t0 + (i as f64 + 0.5) / n as f64 * span;
                want += wa * overlap(zp, zp + bin, v * t, 0.2 + v * t)
                    + wb * overlap(zp, zp + bin, 0.2 - v * t, 0.4 - v * t);
            }
            want /= n as f64;
            let got = field(&head, row, "mean_volume_m3");
            let tol = 2.0 * wa * dp * dt_max / span;
            assert!((got - want).abs() <= tol, "end {end}, bin {zp}: {got} m², expected {want} ± {tol} m²");
        }
    }
}
