//! `spatter sweep`: a 2 × 3 study run whole, as two shards collected, and interrupted and rerun must give
//! the same results table byte for byte; bad studies fail with located messages; reports load in a real
//! browser.

mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::Output;

/// The study's base scenario: a small snow bisection over `diameters` grain diameters.
fn write_base(dir: &Path, diameters: u32) {
    let text = format!(
        "kind = \"snow_regime_map\"\nmode = \"bisection\"\nsvg = false\n[grid]\ndiameters = {diameters}\n"
    );
    write(dir, "base.toml", text.as_bytes());
}

/// A small snow bisection (4 diameters) and a 2 × 3 grid study over it.
fn study_files(dir: &Path) -> PathBuf {
    write_base(dir, 4);
    write(
        dir,
        "study.toml",
        b"base = \"base.toml\"\n\
          [[vary]]\nkey = \"contact.work_of_adhesion_j_m2\"\nvalues = [0.1, 0.3]\n\
          [[vary]]\nkey = \"particle.poisson_ratio\"\nfrom = 0.29\nto = 0.33\nsteps = 3\n",
    )
}

fn sweep(args: &[&str], study: &Path, out: &Path, stop_after: Option<&str>) -> Output {
    let mut c = spatter();
    c.arg("sweep").args(args).arg(study).arg("--out").arg(out).env("SPATTER_NO_PROGRESS", "1");
    if let Some(n) = stop_after {
        c.env("SPATTER_STOP_AFTER_POLLS", n);
    }
    c.output().unwrap()
}

fn ok(o: &Output) -> String {
    let text = format!("{}\n{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "sweep failed ({:?}):\n{text}", o.status.code());
    text
}

fn table(out: &Path) -> String {
    std::fs::read_to_string(out.join("results.csv")).unwrap()
}

#[test]
fn whole_sharded_and_interrupted_studies_give_the_same_table() {
    let dir = tempfile::tempdir().unwrap();
    let study = study_files(dir.path());

    let whole = dir.path().join("whole");
    ok(&sweep(&[], &study, &whole, None));
    let reference = table(&whole);
    let rows: Vec<&str> = reference.lines().collect();
    assert_eq!(rows.len(), 7, "header + 6 cases:\n{reference}");
    assert!(
        rows[0].starts_with("case,contact.work_of_adhesion_j_m2,particle.poisson_ratio,status,"),
        "{}",
        rows[0]
    );
    assert!(rows[0].contains("v_crit_smallest_d_m_s"), "{}", rows[0]);
    // The last key varies fastest; ends of the range are exact.
    assert!(rows[1].starts_with("0,0.1,0.29,completed,"), "{}", rows[1]);
    assert!(rows[3].starts_with("2,0.1,0.33,completed,"), "{}", rows[3]);
    assert!(rows[4].starts_with("3,0.3,0.29,completed,"), "{}", rows[4]);
    // More adhesion, higher critical speed (the physics the table must show).
    let vcrit = |row: &str| row.split(',').nth(4).unwrap().parse::<f64>().unwrap();
    assert!(vcrit(rows[4]) > vcrit(rows[1]), "{reference}");
    for name in ["report.html", "cost.csv", "plan.csv"] {
        assert!(whole.join(name).is_file(), "{name} missing");
    }

    // Two shards into one folder, then collect.
    let sharded = dir.path().join("sharded");
    let first = ok(&sweep(&["--shard", "1/2"], &study, &sharded, None));
    assert!(first.contains("spatter sweep collect"), "{first}");
    assert!(!sharded.join("results.csv").exists(), "a shard does not write the table");
    let early = spatter().args(["sweep", "collect"]).arg(&study).arg("--out").arg(&sharded).output().unwrap();
    assert_eq!(early.status.code(), Some(1), "collect before every shard has run must fail");
    assert!(
        String::from_utf8_lossy(&early.stderr).contains("not run"),
        "{}",
        String::from_utf8_lossy(&early.stderr)
    );
    ok(&sweep(&["--shard", "2/2"], &study, &sharded, None));
    let c = spatter().args(["sweep", "collect"]).arg(&study).arg("--out").arg(&sharded).output().unwrap();
    ok(&c);
    assert_eq!(table(&sharded), reference, "two shards + collect differ from one run");

    // Stopped part-way (inside a case), then run again: finished cases are skipped, the stopped one resumes.
    let killed = dir.path().join("killed");
    let o = sweep(&[], &study, &killed, Some("25"));
    assert_eq!(o.status.code(), Some(130), "{}", String::from_utf8_lossy(&o.stdout));
    assert!(!killed.join("results.csv").exists());
    let again = ok(&sweep(&[], &study, &killed, None));
    assert!(again.contains("already finished"), "{again}");
    assert_eq!(table(&killed), reference, "a stopped and rerun study differs from one run");

    // A rerun of a finished study runs nothing and rewrites the same table.
    let rerun = ok(&sweep(&[], &study, &whole, None));
    assert!(rerun.contains("0 cases run, 6 already finished"), "{rerun}");
    assert_eq!(table(&whole), reference);
}

#[test]
fn bad_studies_name_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    study_files(dir.path());
    let cases: &[(&str, &str, &[&str])] = &[
        ("absent key", "base = \"base.toml\"\n[[vary]]\nkey = \"particle.radius_m\"\nvalues = [1.0]\n", &["study.toml:3:", "vary[0].key", "no key \"particle.radius_m\""]),
        ("wrong type", "base = \"base.toml\"\n[[vary]]\nkey = \"particle.poisson_ratio\"\nvalues = [true]\n", &["vary[0].values", "a number"]),
        ("empty range", "base = \"base.toml\"\n[[vary]]\nkey = \"particle.poisson_ratio\"\nfrom = 0.2\nto = 0.3\nsteps = 0\n", &["study.toml:6:", "empty range"]),
        ("out of range", "base = \"base.toml\"\n[[vary]]\nkey = \"particle.poisson_ratio\"\nvalues = [0.3, 0.6]\n", &["case 1", "poisson_ratio = 0.6"]),
        ("missing base", "base = \"nope.toml\"\n[[vary]]\nkey = \"a\"\nvalues = [1]\n", &["study.toml:1:", "no scenario file"]),
        ("not toml", "base = \n", &["study.toml:1:"]),
    ];
    for (what, text, expect) in cases {
        let study = write(dir.path(), "study.toml", text.as_bytes());
        let o = sweep(&[], &study, &dir.path().join("out"), None);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        assert!(!err.contains("panicked"), "{what}: {err}");
        for e in *expect {
            assert!(err.contains(e), "{what}: expected `{e}` in\n{err}");
        }
    }
    let study = study_files(dir.path());
    let o = spatter().args(["sweep"]).arg(&study).args(["--shard", "3/2"]).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "clap refuses a bad shard");
    assert!(String::from_utf8_lossy(&o.stderr).contains("--shard 3/2"));
}

#[test]
fn a_folder_of_another_study_is_refused_unless_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let study = study_files(dir.path());
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("plan.csv"), "case,x\n0,1\n").unwrap();
    let o = sweep(&[], &study, &out, None);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--overwrite"));
    ok(&sweep(&["--overwrite"], &study, &out, None));
    assert!(table(&out).lines().count() == 7);
}

/// A base scenario edited after the study ran: its finished cases are stale. The rerun and `collect`
/// refuse and say so, before running anything; with `--overwrite` the rerun deletes the changed cases and
/// the collected results and runs every changed case afresh from the new base.
#[test]
fn a_changed_base_is_refused_and_rerun_afresh_with_overwrite() {
    let dir = tempfile::tempdir().unwrap();
    let study = study_files(dir.path());
    let out = dir.path().join("out");
    ok(&sweep(&[], &study, &out, None));
    let before = table(&out);
    write_base(dir.path(), 5);
    let o = sweep(&[], &study, &out, None);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("base scenario changed") && err.contains("--overwrite"), "{err}");
    assert!(err.contains("case 0, case 1, case 2, case 3, case 4, case 5"), "{err}");
    assert_eq!(table(&out), before, "nothing rewritten on refusal");
    let c = spatter().args(["sweep", "collect"]).arg(&study).arg("--out").arg(&out).output().unwrap();
    let err = String::from_utf8_lossy(&c.stderr);
    assert_eq!(c.status.code(), Some(1), "collect of stale cases must fail: {err}");
    assert!(err.contains("base scenario changed"), "{err}");
    let again = ok(&sweep(&["--overwrite"], &study, &out, None));
    assert!(again.contains("6 cases run, 0 already finished"), "{again}");
    let case = std::fs::read_to_string(out.join("cases/case_00000/case.toml")).unwrap();
    assert!(case.contains("diameters = 5"), "{case}");
}

/// Headless Chromium opens the study report and a run report: every picture decodes, no script error.
/// Skipped (with a note) where Chromium is not installed, unless `SPATTER_REQUIRE_CHROMIUM=1` (CI).
#[test]
fn reports_open_in_a_browser_with_every_picture() {
    let Some(chromium) = find_chromium() else { return };
    let dir = tempfile::tempdir().unwrap();
    let study = study_files(dir.path());
    let out = dir.path().join("s");
    ok(&sweep(&[], &study, &out, None));
    for report in [out.join("report.html"), out.join("cases/case_00000/report.html")] {
        opens_in_browser(chromium, &report);
    }
}

/// Chromium, when installed; `None` (with a note) otherwise, unless `SPATTER_REQUIRE_CHROMIUM` is set (CI),
/// where a missing browser fails the test.
fn find_chromium() -> Option<&'static str> {
    let chromium = ["chromium", "chromium-browser", "google-chrome"]
        .into_iter()
        .find(|c| std::process::Command::new(c).arg("--version").output().is_ok_and(|o| o.status.success()));
    if chromium.is_none() {
        assert!(
            std::env::var("SPATTER_REQUIRE_CHROMIUM").is_err(),
            "SPATTER_REQUIRE_CHROMIUM is set but no chromium"
        );
        eprintln!("note: chromium not installed; report browser check skipped");
    }
    chromium
}

/// Headless `chromium` opens `report`: every picture decodes and no script error occurs.
fn opens_in_browser(chromium: &str, report: &Path) {
    let profile = tempfile::tempdir().unwrap();
    let o = std::process::Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--virtual-time-budget=10000",
            "--dump-dom",
        ])
        .arg(format!("--user-data-dir={}", profile.path().display()))
        .arg(format!("file://{}", report.display()))
        .output()
        .unwrap();
    let dom = String::from_utf8_lossy(&o.stdout);
    let body = dom.split("<body").nth(1).and_then(|b| b.split('>').next()).unwrap_or("");
    let images = body.split("data-images=\"").nth(1).and_then(|s| s.split('"').next()).unwrap_or("?");
    let (loaded, total) = images.split_once('/').unwrap_or(("?", "?"));
    assert!(total != "0" && loaded == total, "{}: {images} pictures loaded; body: {body}", report.display());
    assert!(body.contains("data-script-errors=\"0\""), "{}: script errors; body: {body}", report.display());
}

/// A deposition study whose two cases differ only in the mass each parcel carries (same seeds, so the same
/// impacts): the study redraws both plate maps on one colour scale, whose top is the heavier case's peak
/// mass per area — four times the lighter case's.
#[test]
fn maps_of_every_case_are_redrawn_on_one_colour_scale() {
    let dir = tempfile::tempdir().unwrap();
    let ex = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").canonicalize().unwrap();
    let base = std::fs::read_to_string(ex.join("deposition_stagnation_plate.toml"))
        .unwrap()
        .replace("\"deposition_plate.stl\"", &format!("{:?}", ex.join("deposition_plate.stl")))
        .replace("\"deposition_regime_map.json\"", &format!("{:?}", ex.join("deposition_regime_map.json")))
        .replace("parcels = 100000", "parcels = 3000")
        .replace("duration_s = 1.0", "duration_s = 0.3");
    write(dir.path(), "base.toml", base.as_bytes());
    let study = write(
        dir.path(),
        "study.toml",
        b"base = \"base.toml\"\n[[vary]]\nkey = \"injectors[0].mass_per_parcel_kg\"\nvalues = [1e-9, 4e-9]\n",
    );
    let out = dir.path().join("s");
    ok(&sweep(&[], &study, &out, None));
    let peak = |case: &str| {
        let vtu = spatter_io::vtk::read(&out.join("cases").join(case).join("bodies/plate.vtu")).unwrap();
        vtu.cell_array("mass_per_area_kg_m2").unwrap().values.iter().copied().fold(0.0, f64::max)
    };
    let (light, heavy) = (peak("case_00000"), peak("case_00001"));
    assert!(light > 0.0, "the plate must receive snow");
    assert!((heavy / light - 4.0).abs() < 1e-9, "same impacts, four times the mass: {light} {heavy}");
    for case in ["case_00000", "case_00001"] {
        assert!(
            out.join("gallery/plate_deposit").join(format!("{case}.png")).is_file(),
            "{case} map missing"
        );
    }
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(report.contains("plate deposit: every case on one colour scale"), "gallery heading missing");
    let scale = format!("Colour scale 0 to {}", spatter_io::plot::tick_label(heavy));
    assert!(report.contains(&scale), "expected `{scale}` in the report");
}

/// A reduced wading study (the shipped truck at a coarse spacing for 6 ms, three variants) writes one
/// comparison page: every variant named with its values, the wetting maps of every part side by side on
/// the runs' fixed 0–48 % scale, the splash-height curves and the sensor curves overlaid, the wet fractions
/// per part and per group with a column per variant, and the cost table; the page opens in a browser.
#[test]
fn a_wading_study_writes_one_comparison_page() {
    let dir = tempfile::tempdir().unwrap();
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for f in ["wading_truck_body.stl", "wading_truck_wheels.stl", "wading_truck_sensors.stl"] {
        std::fs::copy(examples.join(f), dir.path().join(f)).unwrap();
    }
    let base = std::fs::read_to_string(examples.join("wading_truck.toml"))
        .unwrap()
        .replace("spacing_m = 0.05", "spacing_m = 0.12")
        .replace("wetting_cap = 0.48", "wetting_cap = 0.48\nend_time_s = 0.006\nvtu_interval_s = 0.003");
    write(dir.path(), "base.toml", base.as_bytes());
    let study = write(
        dir.path(),
        "study.toml",
        b"title = \"wading variants\"\nbase = \"base.toml\"\ndesign = \"list\"\n\
          [[vary]]\nkey = \"fluid.spacing_m\"\nvalues = [0.12, 0.12, 0.14]\n\
          [[vary]]\nkey = \"vehicle.adhesion\"\nvalues = [1.0, 10.0, 1.0]\n\
          [[vary]]\nkey = \"drag.enabled\"\nvalues = [true, true, false]\n",
    );
    let out = dir.path().join("s");
    ok(&sweep(&[], &study, &out, None));
    let report = std::fs::read_to_string(out.join("report.html")).unwrap();
    let captions = [
        "case 0: spacing_m = 0.12, adhesion = 1, enabled = true",
        "case 1: spacing_m = 0.12, adhesion = 10, enabled = true",
        "case 2: spacing_m = 0.14, adhesion = 1, enabled = false",
    ];
    for c in captions {
        assert!(report.contains(c), "the page must name `{c}`");
    }
    for part in ["cab", "chassis", "wheel_fl", "camera_front", "channel_walls"] {
        for case in 0..3 {
            let png = out.join(format!("gallery/{part}_wetting/case_{case:05}.png"));
            assert!(png.is_file(), "{} missing", png.display());
        }
        assert!(report.contains(&format!("{part} wetting: every case on one colour scale")), "{part}");
    }
    assert!(
        report.contains(
            "Colour scale 0 to 0.48 (time wet / elapsed) for every case: the scale every case fixed"
        ),
        "the maps keep the runs' fixed wetting cap"
    );
    for curve in ["splash_height_distribution", "camera_front_wet_fraction_over_time"] {
        assert!(out.join(format!("plots/curve_{curve}.png")).is_file(), "{curve} overlay missing");
    }
    assert!(report.contains("splash height distribution: every case"));
    let parts = std::fs::read_to_string(
        out.join("tables/mean_wet_fraction_per_part__area_fraction__averaged_over_the_run_.csv"),
    )
    .unwrap();
    assert!(parts.starts_with("row,case_0,case_1,case_2\n"), "{parts}");
    assert!(parts.lines().any(|l| l.starts_with("wheel_fl,")), "{parts}");
    assert!(report.contains("mean wet fraction per report group (area-weighted): every case"));
    let cost = std::fs::read_to_string(out.join("cost.csv")).unwrap();
    let rows: Vec<Vec<&str>> = cost.lines().map(|l| l.split(',').collect()).collect();
    assert_eq!(
        rows[0].join(","),
        "case,particles,wall_particles,steps,wall_time_s,threads,core_hours,particle_steps_per_s"
    );
    for r in &rows[1..] {
        let n: f64 = r[1].parse().unwrap();
        let steps: f64 = r[3].parse().unwrap();
        assert!(n > 1000.0 && steps >= 1.0, "{cost}");
    }
    // The coarser case has fewer water particles.
    assert!(rows[3][1].parse::<f64>().unwrap() < rows[1][1].parse::<f64>().unwrap(), "{cost}");
    assert!(report.contains("Cost per case"));
    if let Some(chromium) = find_chromium() {
        opens_in_browser(chromium, &out.join("report.html"));
    }
}
