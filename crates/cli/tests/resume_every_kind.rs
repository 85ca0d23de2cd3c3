//! The job driver's promise, kind by kind, through the real binary: a run stopped part-way (a
//! deterministic stop, or a real SIGTERM) and resumed with `--resume` leaves the same files, byte for byte,
//! as an uninterrupted run — also when periodic checkpoints were written along the way.

mod common;
use common::*;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Output, Stdio};

fn run(scenario: &Path, out: &Path, extra: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut c = spatter();
    c.arg("run").arg(scenario).arg("--out").arg(out).args(extra).env("SPATTER_NO_PROGRESS", "1");
    for (k, v) in envs {
        c.env(k, v);
    }
    c.output().unwrap()
}

fn text(o: &Output) -> String {
    format!(
        "stdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// Whole run, then a run stopped after `polls` polls with a checkpoint at every poll, then `--resume`.
fn stop_and_resume(scenario: &Path, polls: u64, what: &str) {
    let dir = scenario.parent().unwrap();
    let whole = dir.join("whole");
    let parts = dir.join("parts");
    let o = run(scenario, &whole, &[], &[]);
    assert!(o.status.success(), "{what}: {}", text(&o));
    let o = run(
        scenario,
        &parts,
        &["--checkpoint-interval-s", "1e-9"],
        &[("SPATTER_STOP_AFTER_POLLS", &polls.to_string())],
    );
    assert_eq!(o.status.code(), Some(130), "{what}: the stopped run exits 130: {}", text(&o));
    assert!(parts.join("checkpoint.bin").is_file(), "{what}: a stopped run leaves its checkpoint");
    let summary = std::fs::read_to_string(parts.join("summary.json")).unwrap();
    assert!(summary.contains("\"interrupted\""), "{what}: {summary}");
    let o = run(scenario, &parts, &["--resume"], &[]);
    assert!(o.status.success(), "{what}: resume: {}", text(&o));
    assert!(!parts.join("checkpoint.bin").exists(), "{what}: a finished run removes its checkpoint");
    let summary = std::fs::read_to_string(parts.join("summary.json")).unwrap();
    assert!(summary.contains("\"completed\""), "{what}: {summary}");
    assert_same_files(&whole, &parts, what);
}

/// A small 2D dam break with probes and height sensors (as in the `sph` scene tests).
fn sph_scenario(end_time_s: f64) -> String {
    format!(
        r#"kind = "sph"
title = "resume test"
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
end_time_s = {end_time_s}
vtu_interval_s = 0.01
sample_interval_s = 0.002
[[sensors.probes]]
name = "p1"
position_m = [0.05, 0.0, 0.05]
[sensors.height]
base_z_m = 0.0
bin_m = 0.02
bins = 10
window_s = [0.01, 0.05]
"#
    )
}

#[test]
fn sph_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let s = write(dir.path(), "sph.toml", sph_scenario(0.05).as_bytes());
    stop_and_resume(&s, 60, "sph");
}

#[test]
fn dem_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let mut floor = spatter_core::mesh::TriMesh::rectangle(0.08, 0.08, 0.0, 4, 4);
    floor.map_vertices(|v| v - spatter_core::Vec3::new(0.01, 0.01, 0.0));
    write(dir.path(), "floor.stl", &floor.to_binary_stl());
    let scene = r#"kind = "dem"
dt_s = 5e-5
duration_s = 0.03
output_interval_s = 0.01
seed = 7
[materials.grain]
youngs_modulus_pa = 5e7
poisson_ratio = 0.3
density_kg_m3 = 2500
[materials.steel]
youngs_modulus_pa = 2e11
poisson_ratio = 0.3
density_kg_m3 = 7800
[pair_defaults]
friction = 0.5
restitution = 0.4
[[walls]]
name = "floor"
material = "steel"
shape = { type = "mesh", file = "floor.stl" }
[[walls]]
name = "xlo"
material = "steel"
shape = { type = "plane", point_m = [0, 0, 0], normal = [1, 0, 0] }
[[walls]]
name = "xhi"
material = "steel"
shape = { type = "plane", point_m = [0.06, 0, 0], normal = [-1, 0, 0] }
[[walls]]
name = "ylo"
material = "steel"
shape = { type = "plane", point_m = [0, 0, 0], normal = [0, 1, 0] }
[[walls]]
name = "yhi"
material = "steel"
shape = { type = "plane", point_m = [0, 0.06, 0], normal = [0, -1, 0] }
[[fill]]
material = "grain"
method = "lattice"
region = { type = "box", min_m = [0, 0, 0], max_m = [0.06, 0.06, 0.02] }
size = { kind = "uniform", min = 0.005, max = 0.006 }
[[inject]]
material = "grain"
region = { type = "box", min_m = [0, 0, 0.04], max_m = [0.06, 0.06, 0.06] }
size = { kind = "mono", diameter = 0.005 }
particles_per_s = 2000
velocity_m_s = [0, 0, -0.5]
interval_s = 0.005
"#;
    let s = write(dir.path(), "dem.toml", scene.as_bytes());
    stop_and_resume(&s, 250, "dem");
}

#[test]
fn snow_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let text = include_str!("../../../examples/snow_regime_map.toml")
        .replace("diameters = 46", "diameters = 6")
        .replace("normal_speeds = 50", "normal_speeds = 8");
    let s = write(dir.path(), "snow.toml", text.as_bytes());
    stop_and_resume(&s, 3, "snow_regime_map");
}

#[test]
fn deposition_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for f in ["deposition_plate.stl", "deposition_regime_map.json"] {
        std::fs::copy(examples.join(f), dir.path().join(f)).unwrap();
    }
    let text = std::fs::read_to_string(examples.join("deposition_stagnation_plate.toml"))
        .unwrap()
        .replace("parcels = 100000", "parcels = 1500")
        .replace("duration_s = 1.0", "duration_s = 0.2");
    let s = write(dir.path(), "deposition.toml", text.as_bytes());
    stop_and_resume(&s, 150, "deposition");
}

#[test]
fn wading_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for f in ["wading_truck_body.stl", "wading_truck_wheels.stl", "wading_truck_sensors.stl"] {
        std::fs::copy(examples.join(f), dir.path().join(f)).unwrap();
    }
    let text = std::fs::read_to_string(examples.join("wading_truck.toml"))
        .unwrap()
        .replace("spacing_m = 0.05", "spacing_m = 0.12")
        .replace("wetting_cap = 0.48", "wetting_cap = 0.48\nend_time_s = 0.006\nvtu_interval_s = 0.003");
    let s = write(dir.path(), "wading.toml", text.as_bytes());
    stop_and_resume(&s, 5, "wading");
}

#[test]
fn flow_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    // The cavity example on a 16² grid for 1 s, without the early steady stop.
    let text = std::fs::read_to_string(examples.join("flow_cavity.toml"))
        .unwrap()
        .replace("cells = 48, cluster = 0.5", "cells = 16")
        .replace("end_time_s = 40.0", "end_time_s = 1.0")
        .replace("steady_rate_m_s2 = 1e-4", "")
        .replace("field_interval_s = 5.0", "field_interval_s = 0.25")
        .replace("sample_interval_s = 0.5", "sample_interval_s = 0.05");
    assert!(text.contains("cells = 16") && text.contains("end_time_s = 1.0"));
    let s = write(dir.path(), "flow.toml", text.as_bytes());
    stop_and_resume(&s, 40, "flow");
}

#[test]
fn cfd_dem_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    // The fluidised-bed example with 150 beads for 30 coupling steps, snapshots and samples inside.
    let text = std::fs::read_to_string(examples.join("cfd_dem_fluidised_bed.toml"))
        .unwrap()
        .replace("count = 3000", "count = 150")
        .replace("duration_s = 0.6", "duration_s = 0.0012")
        .replace("field_interval_s = 0.025", "field_interval_s = 0.0004")
        .replace("sample_interval_s = 0.005", "sample_interval_s = 0.0001");
    assert!(text.contains("count = 150") && text.contains("duration_s = 0.0012"));
    let s = write(dir.path(), "cfd_dem.toml", text.as_bytes());
    stop_and_resume(&s, 17, "cfd_dem");
}

/// A real SIGTERM (what a batch scheduler sends) to a child `spatter run`: it finishes the step, writes
/// a checkpoint, exits 130, and `--resume` completes the run with the same files as an uninterrupted one.
#[cfg(unix)]
#[test]
fn sigterm_writes_a_checkpoint_and_resume_completes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let s = write(dir.path(), "sph.toml", sph_scenario(0.25).as_bytes());
    let whole = dir.path().join("whole");
    let parts = dir.path().join("parts");
    let o = run(&s, &whole, &[], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let mut child = spatter()
        .arg("run")
        .arg(&s)
        .arg("--out")
        .arg(&parts)
        .env("SPATTER_PROGRESS_INTERVAL_S", "0")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Progress lines on stderr (not a terminal) show the time loop has started.
    let stderr = child.stderr.take().unwrap();
    let mut lines = BufReader::new(stderr).lines();
    let mut seen = Vec::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        let started = line.starts_with("progress: ") && !line.starts_with("progress: 0/");
        seen.push(line);
        if started {
            break;
        }
    }
    assert!(seen.last().is_some_and(|l| l.starts_with("progress: ")), "no progress lines: {seen:?}");
    let kill = std::process::Command::new("kill").arg("-TERM").arg(child.id().to_string()).status().unwrap();
    assert!(kill.success());
    let rest: Vec<String> = lines.map_while(Result::ok).collect();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "SIGTERM exits 130 after a checkpoint; stderr: {seen:?} {rest:?}");
    assert!(parts.join("checkpoint.bin").is_file(), "SIGTERM leaves a checkpoint");
    let o = run(&s, &parts, &["--resume"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    assert_same_files(&whole, &parts, "sph after SIGTERM");
}

#[test]
fn resume_refuses_another_scenario_a_damaged_checkpoint_and_a_missing_one() {
    let dir = tempfile::tempdir().unwrap();
    let s = write(dir.path(), "sph.toml", sph_scenario(0.05).as_bytes());
    let out = dir.path().join("out");
    let o = run(&s, &out, &[], &[("SPATTER_STOP_AFTER_POLLS", "5")]);
    assert_eq!(o.status.code(), Some(130), "{}", text(&o));
    let ckpt = out.join("checkpoint.bin");
    let good = std::fs::read(&ckpt).unwrap();
    // Another scenario.
    let other = write(dir.path(), "other.toml", sph_scenario(0.06).as_bytes());
    let o = run(&other, &out, &["--resume"], &[]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("different scenario") && !t.contains("panicked"), "{t}");
    // Truncated, then a flipped byte.
    std::fs::write(&ckpt, &good[..good.len() / 2]).unwrap();
    let o = run(&s, &out, &["--resume"], &[]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("damaged") && !t.contains("panicked"), "{t}");
    let mut flipped = good.clone();
    let i = flipped.len() - 7;
    flipped[i] ^= 0x10;
    std::fs::write(&ckpt, &flipped).unwrap();
    let o = run(&s, &out, &["--resume"], &[]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("damaged") && t.contains("checksum"), "{t}");
    // The good checkpoint resumes.
    std::fs::write(&ckpt, &good).unwrap();
    let o = run(&s, &out, &["--resume"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    // Nothing left to resume.
    let o = run(&s, &out, &["--resume"], &[]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("holds no checkpoint.bin"), "{t}");
}

#[test]
fn an_output_folder_of_another_run_is_refused_unless_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let s = write(dir.path(), "sph.toml", sph_scenario(0.01).as_bytes());
    let out = dir.path().join("out");
    let o = run(&s, &out, &[], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let o = run(&s, &out, &[], &[]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("--overwrite") && t.contains("earlier run"), "{t}");
    std::fs::write(out.join("stale.csv"), "t_s\n1\n").unwrap();
    let o = run(&s, &out, &["--overwrite"], &[]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(!out.join("stale.csv").exists(), "--overwrite removes the earlier run's files");
    // A folder that is not a run folder is never emptied.
    let foreign = dir.path().join("home");
    std::fs::create_dir(&foreign).unwrap();
    std::fs::write(foreign.join("thesis.tex"), "precious").unwrap();
    let o = run(&s, &foreign, &["--overwrite"], &[]);
    let t = text(&o);
    assert_eq!(o.status.code(), Some(2), "{t}");
    assert!(t.contains("not from a spatter run"), "{t}");
    assert!(foreign.join("thesis.tex").is_file());
}

#[test]
fn summary_json_carries_kind_scalars_and_artifacts() {
    let dir = tempfile::tempdir().unwrap();
    let s = write(dir.path(), "sph.toml", sph_scenario(0.01).as_bytes());
    let out = dir.path().join("out");
    let o = run(&s, &out, &[], &[]);
    assert!(o.status.success(), "{}", text(&o));
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(v["finished"], "completed");
    assert_eq!(v["kind"], "sph");
    let scalars = v["scalars"].as_array().expect("scalars as [name, value] pairs");
    assert!(!scalars.is_empty(), "{v}");
    assert!(scalars.iter().any(|p| p[0] == "tank_mean_wet_fraction"), "{v}");
    assert!(v["wall_time_s"].as_f64().is_some_and(|w| w > 0.0), "{v}");
    let artifacts = v["artifacts"].as_array().unwrap();
    assert!(!artifacts.is_empty());
    for a in artifacts {
        let rel = a[1].as_str().unwrap();
        assert!(Path::new(rel).is_relative() && out.join(rel).exists(), "artifact {a}");
    }
    let log = std::fs::read_to_string(out.join("log.txt")).unwrap();
    assert!(log.contains("run cost:") && log.contains("sph resume test"), "one log path:\n{log}");
    assert_eq!(log.matches("run cost:").count(), 1, "no line twice:\n{log}");
}

#[test]
fn absurd_thread_counts_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let s = write(dir.path(), "sph.toml", sph_scenario(0.01).as_bytes());
    for n in ["0", "100000"] {
        let o = run(&s, &dir.path().join(format!("out{n}")), &["--threads", n], &[]);
        let t = text(&o);
        assert_eq!(o.status.code(), Some(1), "{t}");
        assert!(t.contains(&format!("--threads {n}")) && !t.contains("panicked"), "{t}");
    }
}

#[test]
fn brownout_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let text = include_str!("../../../examples/brownout_bell47.toml")
        .replace("duration_s = 6.0", "duration_s = 0.06")
        .replace("interval_s = 0.25", "interval_s = 0.02")
        .replace("grid_cells = [48, 48, 16]", "grid_cells = [8, 8, 4]")
        .replace("classes = 10", "classes = 4")
        .replace("[liftoff]", "[liftoff]\npoints = 8");
    let s = write(dir.path(), "brownout.toml", text.as_bytes());
    stop_and_resume(&s, 12, "brownout");
}

#[test]
fn brownout_dem_bed_resumes_bit_for_bit() {
    // The DEM bed patch under the rotor feeding the cloud: a 6 × 4 × 2 grain patch, 15 cloud steps.
    let dir = tempfile::tempdir().unwrap();
    let text = include_str!("../../../examples/brownout_bell47_dem_bed.toml")
        .replace("tip_vortices = true", "tip_vortices = false")
        .replace("duration_s = 1.0", "duration_s = 0.03")
        .replace("duration_s = 0.05", "duration_s = 0.03")
        .replace("patch_size_m = [2e-3, 1e-3]", "patch_size_m = [0.74e-3, 0.5e-3]")
        .replace("layers = 3", "layers = 2\nimpact_speed_m_s = 0.5\nsettle_s = 0.002")
        .replace("release_height_over_diameter = 3.0", "release_height_over_diameter = 0.5")
        .replace("interval_s = 0.02", "interval_s = 0.004")
        .replace("grid_cells = [48, 48, 16]", "grid_cells = [8, 8, 4]")
        .replace("classes = 10", "classes = 4")
        .replace("[liftoff]", "[liftoff]\npoints = 8");
    let s = write(dir.path(), "brownout_dem_bed.toml", text.as_bytes());
    stop_and_resume(&s, 12, "brownout_dem_bed");
}

#[test]
fn gravelometer_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    // Four one-sphere stones through a short pipe onto the DIN panel.
    let text = r#"kind = "gravelometer"
standard = "din_55996_1"
duration_s = 0.012
[pipe]
length_m = 0.05
[panel]
distance_m = 0.06
triangle_size_m = 0.02
[stones]
count = 4
feed_time_s = 0.002
youngs_modulus_pa = 1e9
[stones.templates.ball]
shape = { type = "ball", radius_m = 2.5e-3 }
packing = { type = "count", sphere_count = 1 }
[launch]
speed_m_s = 12.0
[output]
particles_vtu = true
output_interval_s = 0.002
"#;
    let s = write(dir.path(), "gravelometer.toml", text.as_bytes());
    stop_and_resume(&s, 12, "gravelometer");
}

#[test]
fn gravelometer_with_coupled_air_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    // Two one-sphere stones through a short pipe in solved air (k–ε, two cells across the pipe): the
    // checkpoint carries the flow, the coupling's record and the fluid files.
    let text = r#"kind = "gravelometer"
standard = "din_55996_1"
air = "coupled"
duration_s = 0.006
[pipe]
length_m = 0.05
[panel]
width_m = 0.03
length_m = 0.04
distance_m = 0.05
triangle_size_m = 0.01
strips = 4
[protection_box]
margin_m = 0.02
[stones]
count = 2
feed_time_s = 0.002
youngs_modulus_pa = 1e9
[stones.templates.ball]
shape = { type = "ball", radius_m = 2.5e-3 }
packing = { type = "count", sphere_count = 1 }
[launch]
speed_m_s = 12.0
[coupled_air]
cell_size_m = 0.01
[output]
particles_vtu = true
output_interval_s = 0.001
"#;
    let s = write(dir.path(), "gravelometer_coupled.toml", text.as_bytes());
    stop_and_resume(&s, 12, "gravelometer with coupled air");
}

#[test]
fn integrator_study_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let text = include_str!("../../../examples/integrator_orders.toml")
        .replace("max_steps = 10000", "max_steps = 300");
    let s = write(dir.path(), "integrators.toml", text.as_bytes());
    stop_and_resume(&s, 4, "integrator_study");
}
