//! The `sph` scenario: configuration checks, outputs, and checkpoint/resume that continues bit for bit.

use spatter_core::check::Checker;
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_io::run::{RunContext, RunDir, RunSummary};
use spatter_workflows::sph_scene::{build, run, SphConfig};
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

fn run_to_end(cfg: &SphConfig, dir: &Path) -> RunSummary {
    let d = RunDir::create(dir).unwrap();
    let s = run(cfg, &RunContext::new(&d, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    s
}

#[test]
fn a_run_writes_every_output() {
    let cfg = config(SMALL);
    let tmp = tempfile::tempdir().unwrap();
    let summary = run_to_end(&cfg, tmp.path());
    for f in [
        "series.csv",
        "particles.pvd",
        "particles/particles_00000.vtu",
        "particles/particles_00005.vtu",
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
    let vtu = spatter_io::vtk::read(&tmp.path().join("particles/particles_00005.vtu")).unwrap();
    assert_eq!(vtu.points.len(), 10 * 20);
    // The log is the job driver's (one tracing path); the scene writes no log.txt of its own.
    assert!(!tmp.path().join("log.txt").exists(), "the scene writes no log.txt itself");
    let cost = summary.headline.iter().find(|l| l.contains("run cost:")).expect("a run-cost line");
    assert!(cost.contains("core-hours"), "{cost}");
    // The wetting picture is recorded for a study's gallery: its squares and values, each in [0, 1].
    let map = summary.maps.iter().find(|m| m.label == "tank wetting").expect("wetting map recorded");
    let squares = spatter_io::vtk::read(&map.vtu).unwrap();
    let fraction = &squares.cell_array(&map.array).unwrap().values;
    assert_eq!(fraction.len() * 3, squares.connectivity.len());
    assert!(fraction.iter().all(|f| (0.0..=1.0).contains(f)) && fraction.iter().any(|&f| f > 0.0));
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
    let s = run(&cfg, &RunContext::new(&d, &stop, false)).unwrap();
    assert_eq!(s.finished, Finished::Interrupted);
    assert!(split.path().join("checkpoint.bin").is_file());
    let s = run(&cfg, &RunContext::new(&d, &Unattended, true)).unwrap();
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
    for v in ["0.5", "nan"] {
        let cfg: SphConfig = toml::from_str(
            &SMALL.replace("[output]", &format!("[domain]\nrebalance_imbalance = {v}\n[output]")),
        )
        .unwrap();
        let errs = Checker::run(&cfg, None).unwrap_err();
        assert_eq!(errs[0].key, "domain.rebalance_imbalance", "{errs:?}");
        assert!(errs[0].message.contains("is outside [1, inf]"), "{errs:?}");
    }
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

/// Defaults of `[fluid]` (docs/sph.md §2): ρ₀ = 1000 kg/m³, g = 9.81 m/s², Tait γ = 7, c₀ = 10 U_max.
const RHO0: f64 = 1000.0;
const G: f64 = 9.81;

/// Water at rest, 0.2 m deep, in a 2D tank 0.4 m wide whose side walls are parts of their own (blocks 4 dp
/// thick reaching 4 dp below the floor, closing the corners), with a lid above the water that it never
/// touches.
const STILL: &str = r#"
[fluid]
dimensions = 2
spacing_m = 0.01
[[walls]]
name = "floor"
type = "tank"
min_m = [0.0, 0.0, 0.0]
max_m = [0.4, 0.0, 0.3]
open_faces = ["+z", "-x", "+x"]
[[walls]]
name = "left"
type = "block"
min_m = [-0.04, 0.0, -0.04]
max_m = [0.0, 0.0, 0.3]
[[walls]]
name = "right"
type = "block"
min_m = [0.4, 0.0, -0.04]
max_m = [0.44, 0.0, 0.3]
[[walls]]
name = "lid"
type = "block"
min_m = [0.1, 0.0, 0.26]
max_m = [0.3, 0.0, 0.3]
[[fill]]
type = "box"
min_m = [0.0, 0.0, 0.0]
max_m = [0.4, 0.0, 0.2]
[output]
end_time_s = 0.4
vtu_interval_s = 0.2
sample_interval_s = 0.005
[sensors.height]
base_z_m = 0.0
bin_m = 0.03
bins = 9
window_s = [0.2, 0.4]
"#;

/// Still water (`STILL`): the side walls carry the hydrostatic force and moment, the height bins hold the
/// water that is in them, no volume crosses a plane, the floor is wet for the whole run and the lid never.
#[test]
fn still_water_outputs_match_hydrostatics() {
    let (depth, width, dp) = (0.2, 0.4, 0.01);
    let cfg = config(STILL);
    let tmp = tempfile::tempdir().unwrap();
    run_to_end(&cfg, tmp.path());

    // Loads (series.csv), averaged over the second half of the run, after the start-up transient.
    let (cols, rows) = spatter_io::csv::read_series(&tmp.path().join("series.csv")).unwrap();
    let t = column(&cols, &rows, "t_s");
    let mean = |name: &str| {
        let v: Vec<f64> = column(&cols, &rows, name)
            .into_iter()
            .zip(&t)
            .filter(|(_, &t)| t >= 0.2)
            .map(|(v, _)| v)
            .collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    // Hydrostatics per metre of wall: force ½ρgH², moment about the wall's bottom edge ρgH³/6 (centre of
    // pressure at H/3). Tolerance 1 %: the hydrostatic validation gets the wall pressure within about 1 %
    // (measured here: force +0.22 %, moment +0.28 %).
    let f_ref = 0.5 * RHO0 * G * depth * depth;
    let m_ref = RHO0 * G * depth.powi(3) / 6.0;
    // The torque is reported about the centroid of the part's particles (docs/sph.md §1, Loads): the
    // centre of each block (its lattice is symmetric, the sides being whole multiples of dp), 2 cm outside
    // the water's edge and 0.13 m above the floor.
    for (side, sign, x_edge, x_centre) in [("left", -1.0, 0.0, -0.02), ("right", 1.0, width, width + 0.02)] {
        let (fx, fz, my) =
            (mean(&format!("{side}_Fx_N")), mean(&format!("{side}_Fz_N")), mean(&format!("{side}_My_Nm")));
        // About the bottom edge e = (x_edge, 0, 0): M_e = M_c + (c − e) × F, its y component.
        let m_edge = my + 0.13 * fx - (x_centre - x_edge) * fz;
        assert!(
            (fx - sign * f_ref).abs() < 0.01 * f_ref,
            "{side}: Fx = {fx} N/m, hydrostatics {}",
            sign * f_ref
        );
        assert!(
            (m_edge - sign * m_ref).abs() < 0.01 * m_ref,
            "{side}: moment about the bottom edge {m_edge} N m/m (about the centroid {my}), hydrostatics {}",
            sign * m_ref
        );
        // In 2D every force and lever arm lies in the x–z plane: the other components are exactly 0.
        for q in ["Fy_N", "Mx_Nm", "Mz_Nm"] {
            assert!(column(&cols, &rows, &format!("{side}_{q}")).iter().all(|&v| v == 0.0), "{side}_{q}");
        }
    }
    // The vertical loads of all parts add up to the weight of the water, within the 2 % of the hydrostatic
    // validation (each side wall carries about 1 % of it: the floor within a kernel support of a corner).
    let fz: f64 = ["floor", "left", "right", "lid"].iter().map(|p| mean(&format!("{p}_Fz_N"))).sum();
    let weight = RHO0 * G * width * depth;
    assert!((fz + weight).abs() < 0.02 * weight, "vertical load {fz} N/m, weight {weight} N/m");

    // Height bins (splash_height.csv, 3 cm over the window 0.2–0.4 s): the tank's width times the height of
    // water in the bin (2 of its 3 cm at the surface, none above), divided by the compression of the water,
    // ρ/ρ₀ = (1 + γ g d/c₀²)^(1/γ) at the mid-depth d of the water in the bin (Tait, c₀ = 10 · 2√(gH) =
    // 28 m/s: 0.23 % at the floor). Tolerance 0.1 % of a full bin: less than one particle (dp² is 0.83 % of
    // it), so no particle may change bin.
    let c0 = 10.0 * 2.0 * (G * depth).sqrt();
    let bin = 0.03;
    let (head, rows) = read_table(&tmp.path().join("splash_height.csv"));
    assert_eq!(rows.len(), 9);
    for row in &rows {
        let (lo, hi) = (field(&head, row, "bin_low_m"), field(&head, row, "bin_high_m"));
        let wet = (depth.min(hi) - lo).max(0.0);
        let d = depth - (lo + 0.5 * wet);
        let want = width * wet / (1.0 + 7.0 * G * d / (c0 * c0)).powf(1.0 / 7.0);
        let vol = field(&head, row, "mean_volume_m3");
        assert!((vol - want).abs() < 1e-3 * width * bin, "bin {lo}–{hi} m: {vol} m², expected {want} m²");
        // No volume crosses a plane: both fluxes below one particle (dp²) over the 0.2 s window.
        for q in ["upward_flux_lower_edge_m3_s", "net_flux_lower_edge_m3_s"] {
            let f = field(&head, row, q);
            assert!(f.abs() < dp * dp / 0.2, "bin {lo}–{hi} m: {q} = {f}");
        }
    }

    // Wet times (wetting.csv).
    let (head, rows) = read_table(&tmp.path().join("wetting.csv"));
    let wall = |name: &str, q: &str| {
        let row = rows.iter().find(|r| r[0] == name).unwrap_or_else(|| panic!("no row {name}"));
        field(&head, row, q)
    };
    // The floor is under water at every step: its wet time is the sum of the same step lengths as the
    // clock, so the fraction is 1 to round-off.
    let floor = wall("floor", "mean_wet_fraction");
    assert!((floor - 1.0).abs() < 1e-12, "floor wet fraction {floor}");
    assert_eq!(wall("lid", "mean_wet_fraction"), 0.0, "the lid never meets the water");
    // The side walls are wet over the water depth for the whole run, to one wall particle (dp).
    for side in ["left", "right"] {
        let a = wall(side, "mean_wet_area_m2");
        assert!((a - depth).abs() < dp, "{side}: time-averaged wet length {a} m, water depth {depth} m");
    }
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

/// Water at rest, 0.2 m deep, in a 2D tank whose right wall slides down at 0.1 m/s (a block reaching
/// 4 dp below the floor, free slip); a block is fixed under the water.
const SLIDING: &str = r#"
[fluid]
dimensions = 2
spacing_m = 0.01
[[motions]]
name = "down"
type = "translation"
velocity_m_s = [0.0, 0.0, -0.1]
[[walls]]
name = "tank"
type = "tank"
min_m = [0.0, 0.0, 0.0]
max_m = [0.4, 0.0, 0.4]
open_faces = ["+z", "+x"]
[[walls]]
name = "under"
type = "block"
min_m = [0.1, 0.0, 0.04]
max_m = [0.16, 0.0, 0.1]
[[walls]]
name = "slider"
type = "block"
min_m = [0.4, 0.0, -0.04]
max_m = [0.44, 0.0, 0.4]
motion = "down"
slip = "free_slip"
[[fill]]
type = "box"
min_m = [0.0, 0.0, 0.0]
max_m = [0.4, 0.0, 0.2]
[output]
end_time_s = 0.3
vtu_interval_s = 0.3
sample_interval_s = 0.01
wall_particles = true
"#;

/// Wet times (`SLIDING`): every particle of the sliding wall's face reads the time it spent under the
/// water — all of the run below the water line, none above it, and from the time it reached the water
/// line on for the particles that came down to it — and the fixed block reads wet for the whole run.
#[test]
fn wet_time_is_the_time_under_water() {
    let (depth, dp, v) = (0.2, 0.01, 0.1);
    let cfg = config(SLIDING);
    let tmp = tempfile::tempdir().unwrap();
    run_to_end(&cfg, tmp.path());
    // The run stops at the first step end at or after end_time_s; the last row is written there.
    let (cols, rows) = spatter_io::csv::read_series(&tmp.path().join("series.csv")).unwrap();
    let elapsed = *column(&cols, &rows, "t_s").last().unwrap();
    let (head, rows) = read_table(&tmp.path().join("wetting.csv"));
    let under = rows.iter().find(|r| r[0] == "under").unwrap();
    // Under the water at every step: the wet time is the sum of the same step lengths as the clock.
    let f = field(&head, under, "mean_wet_fraction");
    assert!((f - 1.0).abs() < 1e-12, "fixed block under water: wet fraction {f}");

    // Wall particles at the end (walls/…: position, normal, area, part, wet_time_s).
    let w = spatter_io::vtk::read(&tmp.path().join("walls/walls_00001.vtu")).unwrap();
    let get = |name: &str| &w.point_array(name).unwrap().values;
    let (part, nrm, area, wet) = (get("part"), get("normal"), get("area_m2"), get("wet_time_s"));
    let (mut submerged, mut arriving) = (0, 0);
    for (i, x) in w.points.iter().enumerate() {
        // Face particles of the slider (part 2) facing the water, still beside it (above the floor).
        if part[i] != 2.0 || area[i] <= 0.0 || nrm[3 * i] > -0.99 || x.z < 0.0 {
            continue;
        }
        let z0 = x.z + v * elapsed;
        if z0 < depth {
            // Beside the water from the start.
            assert!((wet[i] - elapsed).abs() < 1e-12, "z0 = {z0}: wet {} s of {elapsed} s", wet[i]);
            submerged += 1;
        } else {
            // Reaches the water line when the top fluid row (dp/2 below the surface, dp/2 from the wall,
            // within the normal reach 1.5 dp) comes within the lateral reach 0.75 dp along the wall.
            // Tolerance: the water line is resolved to one particle spacing, dp/v = 0.1 s of the wall's
            // travel.
            let t_reach = (z0 - (depth - 0.5 * dp) - 0.75 * dp) / v;
            let want = (elapsed - t_reach).max(0.0);
            assert!((wet[i] - want).abs() < dp / v, "z0 = {z0}: wet {} s, expected {want} s", wet[i]);
            if want > 0.0 {
                arriving += 1;
            }
        }
    }
    // 20 rows beside the water less the 3 that went below the floor; 3 rows reach the water line.
    assert_eq!((submerged, arriving), (17, 3));
}

/// A wall adhesion outside the calibrated range 0.75–3 is reported as a set-up warning (one per wall,
/// naming it; the run writes it to the log), and a wall inside it is not; without surface tension adhesion
/// has no effect and nothing is said.
#[test]
fn adhesion_outside_the_calibrated_range_is_warned_about() {
    let with = |st: f64, f: f64| {
        SMALL
            .replace("spacing_m = 0.01", &format!("spacing_m = 0.01\nsurface_tension_n_m = {st}"))
            .replace("max_m = [0.4, 0.0, 0.3]\n", &format!("max_m = [0.4, 0.0, 0.3]\nadhesion = {f}\n"))
    };
    for (st, f, warned) in [(0.072, 10.0, true), (0.072, 1.0, false), (0.0, 10.0, false)] {
        let cfg = config(&with(st, f));
        let (_, info) = build(&cfg).unwrap();
        let line = "wall `tank`: adhesion 10 is above the calibrated range 0.75–3";
        assert_eq!(
            info.warnings.iter().any(|w| w.starts_with(line)),
            warned,
            "σ = {st}, adhesion {f}: {:?}",
            info.warnings
        );
    }
}

/// The small dam break split over 2 and 3 thread-ranks against one rank: the same series, wet areas and
/// splash heights within 10⁻⁶ of each column's scale (the runs differ at the single-precision rounding of
/// the pairs across rank cuts; see `spatter-sph`'s `tests/decomposed.rs`), the same particle count in
/// every row (exact); every output holds one `.pvtu` naming one piece per rank, the pieces hold every
/// particle once, and the walls are written once.
#[test]
fn a_run_on_ranks_matches_one_rank() {
    use spatter_core::comm::ThreadComm;
    let text = SMALL.replace("sample_interval_s = 0.002", "sample_interval_s = 0.002\nwall_particles = true");
    let cfg = config(&text);
    let tmp = tempfile::tempdir().unwrap();
    let one = tmp.path().join("one");
    run_to_end(&cfg, &one);
    let (cols, rows1) = spatter_io::csv::read_series(&one.join("series.csv")).unwrap();
    for n in [2usize, 3] {
        let out = tmp.path().join(format!("ranks{n}"));
        let d = RunDir::create(&out).unwrap();
        let done = ThreadComm::run(n, |comm| {
            let ctx = RunContext { comm, ..RunContext::new(&d, &Unattended, false) };
            run(&cfg, &ctx).map(|s| s.finished).map_err(|e| e.to_string())
        });
        assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{done:?}");
        let (cols_n, rows) = spatter_io::csv::read_series(&out.join("series.csv")).unwrap();
        assert_eq!(cols_n, cols);
        assert_eq!(rows.len(), rows1.len());
        for (c, name) in cols.iter().enumerate() {
            let col = |rs: &Vec<Vec<f64>>| rs.iter().map(|r| r[c]).collect::<Vec<f64>>();
            let (a, b) = (col(&rows1), col(&rows));
            let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
            let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
            if name == "particles" || name == "step" {
                assert_eq!(worst, 0.0, "{n} ranks, column {name}");
            }
            assert!(worst <= 1e-6 * scale, "{n} ranks, column {name}: off by {worst:e} of {scale:e}");
        }
        for table in ["wetting.csv", "splash_height.csv"] {
            let t1 = std::fs::read_to_string(one.join(table)).unwrap();
            let tn = std::fs::read_to_string(out.join(table)).unwrap();
            let nums =
                |t: &str| -> Vec<f64> { t.split([',', '\n']).filter_map(|v| v.parse().ok()).collect() };
            let (a, b) = (nums(&t1), nums(&tn));
            assert_eq!(a.len(), b.len(), "{table}");
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-9), "{n} ranks, {table}: {y} vs {x}");
            }
        }
        let pvtu = std::fs::read_to_string(out.join("particles/particles_00005.pvtu")).unwrap();
        let mut total = 0;
        for r in 0..n {
            let piece = format!("particles_00005_r{r:04}.vtu");
            assert!(pvtu.contains(&format!("Source=\"{piece}\"")), "{pvtu}");
            total += spatter_io::vtk::read(&out.join("particles").join(&piece)).unwrap().points.len();
        }
        assert_eq!(total, 10 * 20, "every particle in one piece");
        let pvd = std::fs::read_to_string(out.join("particles.pvd")).unwrap();
        assert!(pvd.contains("particles/particles_00005.pvtu"), "{pvd}");
        assert!(out.join("walls.vtu").is_file() && out.join("walls/walls_00005.vtu").is_file());
        let stray: Vec<_> = std::fs::read_dir(out.join("walls")).unwrap().filter_map(|e| e.ok()).collect();
        assert_eq!(stray.len(), 6, "one walls file per output");
    }
}

/// Stops after `n` polls like [`StopAfterPolls`] and asks for a checkpoint at every poll before that, so a
/// run writes one checkpoint generation per step.
struct CheckpointEveryPoll(StopAfterPolls);

impl spatter_core::control::RunControl for CheckpointEveryPoll {
    fn stop_requested(&self) -> bool {
        self.0.stop_requested()
    }
    fn checkpoint_due(&self) -> bool {
        true
    }
}

/// Every file under `a` is in `b` with the same bytes, and `b` holds no other file.
fn same_tree(a: &Path, b: &Path, what: &str) {
    fn files(root: &Path, dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                files(root, &p, out);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_owned());
            }
        }
    }
    let (mut fa, mut fb) = (Vec::new(), Vec::new());
    files(a, a, &mut fa);
    files(b, b, &mut fb);
    fa.sort();
    fb.sort();
    assert_eq!(fa, fb, "{what}: the same files");
    for f in &fa {
        assert!(
            std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap(),
            "{what}: {f:?} differs"
        );
    }
}

/// Runs the scenario on `n` thread-ranks into `dir` with a control per rank; returns every rank's outcome.
fn run_on_ranks(
    cfg: &SphConfig,
    dir: &Path,
    n: usize,
    resume: bool,
    repartition: bool,
    control: impl Fn() -> Box<dyn spatter_core::control::RunControl> + Sync,
) -> Vec<Result<Finished, String>> {
    use spatter_core::comm::ThreadComm;
    let d = RunDir::create(dir).unwrap();
    ThreadComm::run(n, |comm| {
        let c = control();
        let ctx = RunContext { comm, repartition, ..RunContext::new(&d, c.as_ref(), resume) };
        run(cfg, &ctx).map(|s| s.finished).map_err(|e| e.to_string())
    })
}

/// A run on two thread-ranks stopped part-way (after writing a checkpoint at every step, so old
/// generations are deleted as new ones are complete) and resumed on two ranks leaves every file, byte for
/// byte, as the uninterrupted two-rank run: each rank continues from its own part with the same split.
/// The split is rebuilt at every balance check that finds the counts unequal (`rebalance_imbalance = 1`,
/// every 20 steps), so the stop falls between rebalances and the resumed run must rebuild where the
/// uninterrupted one did.
#[test]
fn a_run_on_two_ranks_resumes_bit_for_bit() {
    let text = SMALL
        .replace("sample_interval_s = 0.002", "sample_interval_s = 0.002\nwall_particles = true")
        .replace("[output]", "[domain]\nrebalance_imbalance = 1.0\n[output]");
    let cfg = config(&text);
    let tmp = tempfile::tempdir().unwrap();
    let (full, split) = (tmp.path().join("full"), tmp.path().join("split"));
    let done = run_on_ranks(&cfg, &full, 2, false, false, || Box::new(Unattended));
    assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{done:?}");
    let stopped = run_on_ranks(&cfg, &split, 2, false, false, || {
        Box::new(CheckpointEveryPoll(StopAfterPolls::new(60)))
    });
    assert!(stopped.iter().all(|f| *f == Ok(Finished::Interrupted)), "{stopped:?}");
    assert!(split.join("checkpoint.bin").is_file());
    let mut parts: Vec<String> = std::fs::read_dir(split.join("checkpoint"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    parts.sort();
    // 61 checkpoints (one per poll, the last at the stop): generations 0–60, only the last one kept.
    assert_eq!(parts, ["part_g000060_r0000.bin", "part_g000060_r0001.bin"]);
    let resumed = run_on_ranks(&cfg, &split, 2, true, false, || Box::new(Unattended));
    assert!(resumed.iter().all(|f| *f == Ok(Finished::Completed)), "{resumed:?}");
    assert!(!split.join("checkpoint.bin").exists() && !split.join("checkpoint").exists());
    same_tree(&full, &split, "two ranks, stopped and resumed on two");
}

/// The largest difference of every `series.csv` column of `dir` from the one-rank run `rows1`, within
/// 10⁻⁶ of the column's scale; particle and step counts exact.
fn series_within_round_off(dir: &Path, cols: &[String], rows1: &[Vec<f64>], what: &str) {
    let (cols_n, rows) = spatter_io::csv::read_series(&dir.join("series.csv")).unwrap();
    assert_eq!(cols_n, cols, "{what}");
    assert_eq!(rows.len(), rows1.len(), "{what}");
    for (c, name) in cols.iter().enumerate() {
        let col = |rs: &[Vec<f64>]| rs.iter().map(|r| r[c]).collect::<Vec<f64>>();
        let (a, b) = (col(rows1), col(&rows));
        let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max);
        if name == "particles" || name == "step" {
            assert_eq!(worst, 0.0, "{what}, column {name}");
        }
        assert!(worst <= 1e-6 * scale, "{what}, column {name}: off by {worst:e} of {scale:e}");
    }
}

/// A checkpoint resumed on another rank count: refused on every rank with one sentence without
/// `repartition`; with it, a two-rank checkpoint continues on one and on three ranks, and a one-rank
/// checkpoint on two. Tolerance: 10⁻⁶ of each `series.csv` column's scale against the uninterrupted
/// one-rank run, the same as for uninterrupted runs on several ranks (`a_run_on_ranks_matches_one_rank`):
/// a re-partitioned run sums forces in another order after the resume (pairs across rank cuts are
/// evaluated in double precision, the others in single precision), so it differs at that rounding;
/// particle counts, steps and times exact.
#[test]
fn a_checkpoint_resumes_on_another_rank_count_with_repartition() {
    let cfg = config(SMALL);
    let tmp = tempfile::tempdir().unwrap();
    let one = tmp.path().join("one");
    run_to_end(&cfg, &one);
    let (cols, rows1) = spatter_io::csv::read_series(&one.join("series.csv")).unwrap();
    let stop = || -> Box<dyn spatter_core::control::RunControl> { Box::new(StopAfterPolls::new(60)) };
    let go = || -> Box<dyn spatter_core::control::RunControl> { Box::new(Unattended) };
    for (from, to) in [(2usize, 1usize), (2, 3), (1, 2)] {
        let what = format!("{from} → {to} ranks");
        let dir = tmp.path().join(format!("from{from}to{to}"));
        let stopped = run_on_ranks(&cfg, &dir, from, false, false, stop);
        assert!(stopped.iter().all(|f| *f == Ok(Finished::Interrupted)), "{what}: {stopped:?}");
        let refused = run_on_ranks(&cfg, &dir, to, true, false, go);
        let sentence = format!(
            "written by {from} rank{} and this run has {to} rank{}: add --repartition",
            if from > 1 { "s" } else { "" },
            if to > 1 { "s" } else { "" }
        );
        for r in &refused {
            let e = r.as_ref().unwrap_err();
            assert!(e.contains(&sentence), "{what}: {e}");
        }
        let resumed = run_on_ranks(&cfg, &dir, to, true, true, go);
        assert!(resumed.iter().all(|f| *f == Ok(Finished::Completed)), "{what}: {resumed:?}");
        series_within_round_off(&dir, &cols, &rows1, &what);
        for table in ["wetting.csv", "splash_height.csv"] {
            let t1 = std::fs::read_to_string(one.join(table)).unwrap();
            let tn = std::fs::read_to_string(dir.join(table)).unwrap();
            let nums =
                |t: &str| -> Vec<f64> { t.split([',', '\n']).filter_map(|v| v.parse().ok()).collect() };
            let (a, b) = (nums(&t1), nums(&tn));
            assert_eq!(a.len(), b.len(), "{what}: {table}");
            for (x, y) in a.iter().zip(&b) {
                assert!((x - y).abs() <= 1e-6 * x.abs().max(1e-9), "{what}, {table}: {y} vs {x}");
            }
        }
        assert!(!dir.join("checkpoint.bin").exists() && !dir.join("checkpoint").exists(), "{what}");
    }
}

/// Instantaneous wetting maps (`output.wetting_map_times_s`): at t = 0 the tank's wet squares are the
/// water column's wetted perimeter, floor a = 0.1 m plus the left wall 2a = 0.2 m (per metre of depth,
/// within 2 dp for the corners), and at every map time the wet squares add up to the wet area the series
/// reports at that moment (the same wet flags, exactly).
#[test]
fn instantaneous_maps_show_the_wetting_of_their_moment() {
    let text = SMALL
        .replace("sample_interval_s = 0.002", "sample_interval_s = 0.002\nwetting_map_times_s = [0.0, 0.05]");
    let cfg = config(&text);
    let tmp = tempfile::tempdir().unwrap();
    let summary = run_to_end(&cfg, tmp.path());
    assert!(summary.finished == Finished::Completed);
    let (cols, rows) = spatter_io::csv::read_series(&tmp.path().join("series.csv")).unwrap();
    let wet = column(&cols, &rows, "tank_wet_area_m2");
    let dp = 0.01;
    let mut areas = Vec::new();
    for n in 0..2 {
        let dir = tmp.path().join(format!("wetting/instant_{n:02}"));
        assert!(dir.join("tank.png").is_file(), "map {n}: picture missing");
        let vtu = spatter_io::vtk::read(&dir.join("tank.vtu")).unwrap();
        let now = &vtu.cell_array("wet_now").unwrap().values;
        assert!(now.iter().all(|v| *v == 0.0 || *v == 1.0), "wet or dry only");
        // Two triangles per wall particle, each standing for dp of wall per metre of depth in 2D.
        areas.push(now.iter().sum::<f64>() / 2.0 * dp);
    }
    assert!((areas[0] - 0.3).abs() <= 2.0 * dp, "wetted perimeter at rest: {} m", areas[0]);
    assert!((areas[0] - wet[0]).abs() < 1e-12, "map 0 {} vs series {}", areas[0], wet[0]);
    let last = *wet.last().unwrap();
    assert!((areas[1] - last).abs() < 1e-12, "map 1 {} vs series {last}", areas[1]);
    assert!(areas[1] != areas[0], "the surge has moved the wet line");
    let e = toml::from_str::<SphConfig>(
        &SMALL.replace("sample_interval_s = 0.002", "wetting_map_times_s = [0.02, 0.01]"),
    )
    .unwrap();
    let errs = Checker::run(&e, None).unwrap_err();
    assert_eq!(errs[0].key, "output.wetting_map_times_s[1]", "{errs:?}");
    assert!(errs[0].message.contains("must increase"), "{errs:?}");
}
