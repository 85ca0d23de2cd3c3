//! The `flow` kind end to end: `examples/flow_cavity.toml` at a reduced size runs to the end and writes its
//! files; a stopped and resumed run writes the same files byte for byte; bad input is refused with the key,
//! boundary or cell named.

use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_scenario::job::{self, JobOptions};
use std::path::Path;

const CAVITY: &str = include_str!("../../../examples/flow_cavity.toml");

/// The example on a 16² grid for 2 s, without the early steady stop.
fn small_cavity() -> String {
    let t = CAVITY
        .replace("cells = 48, cluster = 0.5", "cells = 16")
        .replace("end_time_s = 40.0", "end_time_s = 2.0")
        .replace("steady_rate_m_s2 = 1e-4", "")
        .replace("field_interval_s = 5.0", "field_interval_s = 0.5")
        .replace("sample_interval_s = 0.5", "sample_interval_s = 0.1");
    assert!(
        t.contains("cells = 16") && t.contains("end_time_s = 2.0") && t.contains("field_interval_s = 0.5")
    );
    t
}

fn load(dir: &Path, text: &str) -> Result<spatter_scenario::Loaded, String> {
    let p = dir.join("flow.toml");
    std::fs::write(&p, text).unwrap();
    spatter_scenario::load(&p).map_err(|e| e.iter().map(|x| x.to_string()).collect::<Vec<_>>().join("\n"))
}

/// The job driver points the process's one log at the running job's folder, so jobs in one process run
/// one after another (as the cases of a study do).
static ONE_JOB_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs `scenario` through the job driver (run folder, checkpoints, summary.json) into `out`.
fn run(
    scenario: &spatter_scenario::Loaded,
    out: &Path,
    control: &dyn spatter_core::control::RunControl,
    resume: bool,
) -> Result<spatter_io::run::RunSummary, String> {
    let mut opts = JobOptions::new(out);
    opts.resume = resume;
    let _one = ONE_JOB_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    job::run(scenario, &opts, control).map_err(|e| e.to_string())
}

#[test]
fn the_cavity_example_runs_and_a_resumed_run_writes_the_same_files() {
    let tmp = tempfile::tempdir().unwrap();
    let sc = load(tmp.path(), &small_cavity()).unwrap();
    assert_eq!(sc.scenario.kind(), "flow");
    let whole = tmp.path().join("whole");
    let s = run(&sc, &whole, &Unattended, false).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    let scalar = |n: &str| s.scalars.iter().find(|(k, _)| k == n).map(|(_, v)| *v).unwrap();
    assert!((scalar("t_end_s") - 2.0).abs() < 1e-12);
    // After 2 s the lid has set the fluid turning: the fastest cell centre, half a cell (1/32 m) below
    // the lid, moves at most at the lid speed, the centre much slower.
    let speed = scalar("max_speed_m_s");
    assert!(speed > 0.6 && speed < 1.0, "{speed}");
    assert!(scalar("probe_centre_ux_m_s").abs() < 0.3);
    assert!(scalar("net_outflow_m3_s").abs() < 1e-12, "closed cavity: no net flux");
    assert!(scalar("ghia_max_du").is_finite() && scalar("ghia_max_dv").is_finite());
    for f in [
        "series.csv",
        "probes.csv",
        "fields.pvd",
        "speed.png",
        "centreline_u.png",
        "centreline_v.png",
        "run.toml",
        "summary.json",
        "log.txt",
    ] {
        assert!(whole.join(f).is_file(), "{f} missing");
    }
    let vtrs = std::fs::read_dir(whole.join("fields")).unwrap().count();
    assert_eq!(vtrs, 5, "t = 0, 0.5, 1, 1.5, 2 s");
    let pvd = std::fs::read_to_string(whole.join("fields.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 5);
    let probes = std::fs::read_to_string(whole.join("probes.csv")).unwrap();
    assert!(probes.starts_with("t_s,centre_ux_m_s,centre_uy_m_s,centre_uz_m_s,centre_p_Pa,below_lid_ux_m_s"));
    assert_eq!(probes.lines().count(), 1 + 21, "header and t = 0, 0.1, …, 2 s");

    // Stop after 150 polls (between two steps, mid-run), then resume.
    let parts = tmp.path().join("parts");
    let s = run(&sc, &parts, &StopAfterPolls::new(150), false).unwrap();
    assert_eq!(s.finished, Finished::Interrupted);
    assert!(parts.join("checkpoint.bin").is_file());
    let s = run(&sc, &parts, &Unattended, true).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    assert!(!parts.join("checkpoint.bin").exists(), "a finished run removes its checkpoint");
    let mut files =
        vec!["series.csv".to_owned(), "probes.csv".into(), "fields.pvd".into(), "centrelines.csv".into()];
    files.extend((0..5).map(|k| format!("fields/fields_{k:05}.vtr")));
    for f in files {
        let (a, b) = (std::fs::read(whole.join(&f)).unwrap(), std::fs::read(parts.join(&f)).unwrap());
        assert!(a == b, "{f} differs between the uninterrupted and the resumed run");
    }
}

#[test]
fn max_steps_and_smoke_cut_the_run_short_but_write_every_output() {
    let tmp = tempfile::tempdir().unwrap();
    let text = small_cavity().replace("end_time_s = 2.0", "end_time_s = 2.0\nmax_steps = 7");
    let sc = load(tmp.path(), &text).unwrap();
    let s = run(&sc, &tmp.path().join("capped"), &Unattended, false).unwrap();
    let scalar = |n: &str| s.scalars.iter().find(|(k, _)| k == n).map(|(_, v)| *v).unwrap();
    assert_eq!(scalar("steps"), 7.0);
    assert!(scalar("t_end_s") < 2.0);
    let pvd = std::fs::read_to_string(tmp.path().join("capped/fields.pvd")).unwrap();
    assert_eq!(pvd.matches("<DataSet").count(), 2, "t = 0 and the last step: {pvd}");
    // --smoke: at most 30 steps, the whole example otherwise.
    let mut sc = load(tmp.path(), CAVITY).unwrap();
    sc.scenario.smoke();
    let s = run(&sc, &tmp.path().join("smoke"), &Unattended, false).unwrap();
    let steps = s.scalars.iter().find(|(k, _)| k == "steps").map(|(_, v)| *v).unwrap();
    assert_eq!(steps, 30.0);
    assert!(tmp.path().join("smoke/centreline_u.png").is_file());
    let e = load_error(&text.replace("max_steps = 7", "max_steps = 0"));
    assert!(e.contains("time.max_steps"), "{e}");
}

#[test]
fn the_turbulent_pipe_example_runs_and_writes_k_and_epsilon() {
    let text = include_str!("../../../examples/flow_pipe_k_epsilon.toml")
        .replace(
            "y = { min_m = 0.0, max_m = 5.0, cells = 100 }",
            "y = { min_m = 0.0, max_m = 1.0, cells = 20 }",
        )
        .replace("end_time_s = 2.0", "end_time_s = 0.1")
        .replace("at_m = [0.0, 3.0, 0.5]", "at_m = [0.0, 0.6, 0.5]")
        .replace("at_m = [0.0, 4.0, 0.5]", "at_m = [0.0, 0.8, 0.5]");
    assert!(text.contains("cells = 20") && text.contains("end_time_s = 0.1"));
    let tmp = tempfile::tempdir().unwrap();
    let sc = load(tmp.path(), &text).unwrap();
    let out = tmp.path().join("out");
    let s = run(&sc, &out, &Unattended, false).unwrap();
    let scalar = |n: &str| s.scalars.iter().find(|(k, _)| k == n).map(|(_, v)| *v).unwrap();
    // The pressure falls along the pipe and the core speeds up as the wall layers grow.
    assert!(scalar("probe_z30D_p_Pa") > scalar("probe_z40D_p_Pa"));
    assert!(scalar("probe_z40D_uy_m_s") > 10.0, "{}", scalar("probe_z40D_uy_m_s"));
    assert!(scalar("kinetic_energy_J_per_rad") > 0.0);
    let last = std::fs::read_dir(out.join("fields")).unwrap().map(|e| e.unwrap().path()).max().unwrap();
    let vtr = std::fs::read_to_string(last).unwrap();
    for name in ["k_m2_s2", "epsilon_m2_s3", "nu_t_m2_s"] {
        assert!(vtr.contains(&format!("Name=\"{name}\"")), "{name} missing");
    }
    assert!(out.join("speed.png").is_file());
}

/// The message of the first load error of `text`.
fn load_error(text: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    load(tmp.path(), text).err().unwrap_or_else(|| panic!("accepted:\n{text}"))
}

fn run_error(text: &str) -> String {
    let tmp = tempfile::tempdir().unwrap();
    let sc = load(tmp.path(), text).unwrap();
    run(&sc, &tmp.path().join("out"), &Unattended, false).err().unwrap_or_else(|| panic!("ran:\n{text}"))
}

#[test]
fn bad_flow_input_is_refused_with_the_key_boundary_or_cell_named() {
    let base = small_cavity();
    // An inlet table whose times go backwards: located at the key.
    let e = load_error(&base.replace(
        "x_min = { type = \"wall\" }",
        "x_min = { type = \"inlet\", velocity_m_s = [1.0, 0.0, 0.0], table = { t_s = [0.0, 2.0, 1.0], factor = [0.0, 1.0, 1.0] } }",
    ));
    assert!(e.contains("boundaries.x_min.table.t_s") && e.contains("increase strictly"), "{e}");
    assert!(e.contains("flow.toml:"), "located in the file: {e}");
    // A grid far beyond memory: refused before anything is allocated.
    let e = load_error(&base.replace(
        "z = { min_m = 0.0, max_m = 0.02, cells = 1 }",
        "z = { min_m = 0.0, max_m = 0.02, cells = 1 }\nmax_memory_gb = 0.0001",
    ));
    assert!(
        e.contains("grid.x.cells") && e.contains("needs about") && e.contains("grid.max_memory_gb"),
        "{e}"
    );
    let e = load_error(&base.replace("cells = 1 }", "cells = 10000000 }").replace(
        "x = { min_m = 0.0, max_m = 1.0, cells = 16 }",
        "x = { min_m = 0.0, max_m = 1.0, cells = 10000000 }",
    ));
    assert!(e.contains("grid.x.cells"), "{e}");
    // An unknown key.
    let e = load_error(&base.replace("courant = 0.5", "courant = 0.5\ncfl = 0.5"));
    assert!(e.contains("cfl"), "{e}");
    // An inlet with no outlet anywhere: the mass balance names the inlet and the region.
    let e = run_error(&base.replace(
        "x_min = { type = \"wall\" }",
        "x_min = { type = \"inlet\", velocity_m_s = [1.0, 0.0, 0.0] }",
    ));
    assert!(
        e.contains("inlet x_min")
            && e.contains("fluid region 1")
            && e.contains("no side of the grid is an outlet"),
        "{e}"
    );
    // A fixed step far above the stable one: the blow-up names the step and the cell.
    let e = run_error(&base.replace("courant = 0.5", "courant = 0.5\ndt_s = 0.2"));
    assert!(e.contains("Courant number") && e.contains("in cell ("), "{e}");
    // A probe outside the grid.
    let e = run_error(&base.replace("at_m = [0.5, 0.9, 0.01]", "at_m = [0.5, 1.9, 0.01]"));
    assert!(e.contains("output.probes[1]") && e.contains("below_lid"), "{e}");
    // An open STL solid is named with its index and file.
    let tmp = tempfile::tempdir().unwrap();
    let mut cube = spatter_core::shapes::box_mesh(spatter_core::Aabb::new(
        spatter_core::Vec3::new(0.4, 0.4, -0.1),
        spatter_core::Vec3::new(0.6, 0.6, 0.1),
    ));
    cube.triangles.pop();
    std::fs::write(tmp.path().join("open.stl"), cube.to_binary_stl()).unwrap();
    let text = format!("{base}\n[[solids]]\nshape = \"mesh\"\nfile = \"open.stl\"\n");
    let sc = load(tmp.path(), &text).unwrap();
    let e = run(&sc, &tmp.path().join("out"), &Unattended, false).err().unwrap();
    assert!(e.contains("solids[0]") && e.contains("open.stl") && e.contains("not closed"), "{e}");
}
