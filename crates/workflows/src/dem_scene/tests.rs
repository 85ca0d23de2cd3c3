//! Scene tests: parsing and validation messages, an interrupted and resumed run equals an uninterrupted
//! one bit for bit, and the shipped example is valid.

use super::*;
use spatter_core::check::Checker;
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_core::Vec3;
use spatter_io::run::{RunContext, RunDir};
use std::path::Path;

/// A small pour: a box of planes, an STL floor, a lattice fill and an injector, with rolling resistance.
fn pour_toml(stl: &Path) -> String {
    format!(
        r#"
dt_s = 5e-5
duration_s = 0.04
output_interval_s = 0.01
seed = 7

[contact]
rolling = "constant_torque"

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
rolling_friction = 0.02

[[pairs]]
materials = ["grain", "steel"]
friction = 0.3

[[walls]]
name = "floor"
material = "steel"
shape = {{ type = "mesh", file = "{}" }}

[[walls]]
name = "xlo"
material = "steel"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [1, 0, 0] }}

[[walls]]
name = "xhi"
material = "steel"
shape = {{ type = "plane", point_m = [0.06, 0, 0], normal = [-1, 0, 0] }}

[[walls]]
name = "ylo"
material = "steel"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [0, 1, 0] }}

[[walls]]
name = "yhi"
material = "steel"
shape = {{ type = "plane", point_m = [0, 0.06, 0], normal = [0, -1, 0] }}

[[fill]]
material = "grain"
method = "lattice"
region = {{ type = "box", min_m = [0, 0, 0], max_m = [0.06, 0.06, 0.03] }}
size = {{ kind = "uniform", min = 0.005, max = 0.006 }}

[[inject]]
material = "grain"
region = {{ type = "box", min_m = [0, 0, 0.04], max_m = [0.06, 0.06, 0.06] }}
size = {{ kind = "mono", diameter = 0.005 }}
particles_per_s = 2000
velocity_m_s = [0, 0, -0.5]
interval_s = 0.005
"#,
        stl.display()
    )
}

fn floor_stl(dir: &Path) -> std::path::PathBuf {
    let mut m = spatter_core::mesh::TriMesh::rectangle(0.08, 0.08, 0.0, 4, 4);
    m.map_vertices(|v| v - spatter_core::Vec3::new(0.01, 0.01, 0.0));
    let p = dir.join("floor.stl");
    std::fs::write(&p, m.to_binary_stl()).unwrap();
    p
}

fn parse(text: &str) -> SceneConfig {
    toml::from_str(text).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn interrupted_and_resumed_run_equals_uninterrupted_run_bit_for_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = parse(&pour_toml(&floor_stl(tmp.path())));
    let full = RunDir::create(&tmp.path().join("full")).unwrap();
    let s = run(&cfg, &RunContext::new(&full, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    let part = RunDir::create(&tmp.path().join("part")).unwrap();
    // Stop after 333 polls (one per step), in the middle of an output interval and after injections.
    let stop = StopAfterPolls::new(333);
    let s = run(&cfg, &RunContext::new(&part, &stop, false)).unwrap();
    assert_eq!(s.finished, Finished::Interrupted);
    assert!(part.checkpoint_path().is_file());
    let s = run(&cfg, &RunContext::new(&part, &Unattended, true)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    assert!(!part.checkpoint_path().is_file(), "checkpoint removed after completion");
    for rel in [
        "energy.csv",
        "particles.pvd",
        "particles/particles_00004.vtu",
        "walls/floor_00004.vtu",
        "floor_wall.pvd",
    ] {
        let a = std::fs::read(full.root().join(rel)).unwrap();
        let b = std::fs::read(part.root().join(rel)).unwrap();
        assert!(a == b, "{rel} differs between the uninterrupted and the resumed run");
    }
    // The run did something: particles were injected and touch the STL floor.
    let csv = std::fs::read_to_string(full.root().join("energy.csv")).unwrap();
    let last: Vec<f64> = csv.lines().last().unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    let first: Vec<f64> = csv.lines().nth(1).unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    assert!(last[2] > first[2], "injection added particles: {} → {}", first[2], last[2]);
    let mesh = spatter_io::vtk::read(&full.root().join("walls/floor_00004.vtu")).unwrap();
    let impacts = &mesh.cell_array("impacts").unwrap().values;
    assert!(impacts.iter().sum::<f64>() > 0.0, "impacts recorded on the STL floor");
}

#[test]
fn a_multi_step_integrator_resumes_bit_for_bit_in_a_scene() {
    // engine.integrator = "abm4": the checkpoint carries the past derivatives (and "bd2" its past states
    // with engine.iterations), so an interrupted run ends identical to an uninterrupted one.
    for engine in ["integrator = \"abm4\"", "integrator = \"bd2\"\niterations = 2"] {
        let tmp = tempfile::tempdir().unwrap();
        let text = pour_toml(&floor_stl(tmp.path())).replacen(
            "seed = 7\n",
            &format!("seed = 7\n\n[engine]\n{engine}\n"),
            1,
        );
        let cfg = parse(&text);
        assert_ne!(cfg.engine.integrator, spatter_dem::sim::Integrator::VelocityVerlet, "{engine}");
        let full = RunDir::create(&tmp.path().join("full")).unwrap();
        let s = run(&cfg, &RunContext::new(&full, &Unattended, false)).unwrap();
        assert_eq!(s.finished, Finished::Completed);
        let part = RunDir::create(&tmp.path().join("part")).unwrap();
        let s = run(&cfg, &RunContext::new(&part, &StopAfterPolls::new(333), false)).unwrap();
        assert_eq!(s.finished, Finished::Interrupted);
        let s = run(&cfg, &RunContext::new(&part, &Unattended, true)).unwrap();
        assert_eq!(s.finished, Finished::Completed);
        for rel in ["energy.csv", "particles/particles_00004.vtu", "walls/floor_00004.vtu"] {
            let a = std::fs::read(full.root().join(rel)).unwrap();
            let b = std::fs::read(part.root().join(rel)).unwrap();
            assert!(a == b, "{engine}: {rel} differs between the uninterrupted and the resumed run");
        }
    }
}

#[test]
fn resuming_with_another_scene_is_refused_by_the_checkpoint_header() {
    // The job driver stamps checkpoints with the resolved input's hash; the DEM run loads its checkpoint
    // through the context, so another scene's hash is refused (here 21 and 22 stand for two inputs).
    let tmp = tempfile::tempdir().unwrap();
    let cfg = parse(&pour_toml(&floor_stl(tmp.path())));
    let dir = RunDir::create(&tmp.path().join("run")).unwrap();
    let stop = StopAfterPolls::new(50);
    let first = RunContext { input_hash: 21, ..RunContext::new(&dir, &stop, false) };
    assert_eq!(run(&cfg, &first).unwrap().finished, Finished::Interrupted);
    let mut other = cfg.clone();
    other.duration_s *= 2.0;
    let e = run(&other, &RunContext { input_hash: 22, ..RunContext::new(&dir, &Unattended, true) })
        .unwrap_err()
        .to_string();
    assert!(e.contains("different scenario"), "{e}");
    assert!(dir.checkpoint_path().is_file(), "the checkpoint is kept for its own scene");
}

#[test]
fn validation_names_the_bad_keys() {
    let tmp = tempfile::tempdir().unwrap();
    let mut cfg = parse(&pour_toml(&floor_stl(tmp.path())));
    cfg.dt_s = -1.0;
    cfg.pairs[0].materials[1] = "unobtainium".into();
    cfg.pair_defaults.restitution = 1.5;
    cfg.walls[0].material = "wood".into();
    cfg.fill[0].size = Some(spatter_core::distribution::SizeDistribution::Mono { diameter: -1.0 });
    cfg.engine.rebalance_imbalance = Some(0.9);
    let errs = Checker::run(&cfg, None).unwrap_err();
    let find =
        |k: &str| errs.iter().find(|e| e.key == k).unwrap_or_else(|| panic!("no error for {k}: {errs:?}"));
    assert!(find("dt_s").message.contains("positive"));
    assert!(find("pairs[0].materials[1]").message.contains("unobtainium"));
    assert_eq!(find("pair_defaults.restitution").message, "restitution = 1.5 is outside (0, 1]");
    assert!(find("walls[0].material").message.contains("wood"));
    assert!(find("fill[0].size").message.contains("diameter = -1"));
    assert_eq!(find("engine.rebalance_imbalance").message, "rebalance_imbalance = 0.9 is outside [1, inf]");
    let bad = "dt_s = 1e-5\nduration_s = 1\n[materials.a]\nyoungs_modulus_pa = 1e9\npoisson_ratio = 0.3\ndensity_kg_m3 = 1000\nunknown_key = 3\n";
    assert!(toml::from_str::<SceneConfig>(bad).is_err(), "unknown keys are rejected");
}

#[test]
fn shipped_examples_are_valid() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut n = 0;
    for entry in std::fs::read_dir(&root).unwrap() {
        let p = entry.unwrap().path();
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        // DEM scenes: `dem_*.toml`, and the bed laboratory's pour.
        if !((name.starts_with("dem_") && name.ends_with(".toml")) || name == "bed_pour.toml") {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap();
        // Scenario files start with `kind = "dem"`, which the scenario loader consumes.
        let body: String =
            text.lines().filter(|l| !l.trim_start().starts_with("kind")).collect::<Vec<_>>().join("\n");
        let cfg: SceneConfig = toml::from_str(&body).unwrap_or_else(|e| panic!("{name}: {e}"));
        Checker::run(&cfg, Some(&root)).unwrap_or_else(|e| panic!("{name}: {e:?}"));
        n += 1;
    }
    assert!(n >= 2, "examples/dem_*.toml and bed_pour.toml: {n} found");
}

#[test]
fn tangential_history_rule_is_selectable_from_the_scene() {
    use spatter_dem::contact::MindlinHistory as H;
    for (key, rule) in [
        ("mindlin", Some(H::Displacement)),
        ("mindlin_rescale", Some(H::DisplacementRescaled)),
        ("mindlin_force", Some(H::Force)),
        ("mindlin_rescale_force", Some(H::ForceRescaled)),
        ("linear", None),
    ] {
        let c: ContactConfig = toml::from_str(&format!("tangential = \"{key}\"")).unwrap();
        assert_eq!(c.tangential.mindlin_history(), rule, "{key}");
    }
    assert!(toml::from_str::<ContactConfig>("tangential = \"deresiewicz\"").is_err());
    // The choice reaches the engine: the same pour with the incremental rescaled rule gives another
    // energy history than the default (the particles stick and slide on the floor and on each other).
    assert_pour_differs(
        "the tangential rule",
        [&|c| c.contact.tangential = TangentialKind::Mindlin, &|c| {
            c.contact.tangential = TangentialKind::MindlinRescaleForce
        }],
    );
}

/// Runs the pour on the STL floor once with each setting and asserts that the two energy histories
/// (`energy.csv`) differ: the option named `what` reaches the engine.
fn assert_pour_differs(what: &str, settings: [&dyn Fn(&mut SceneConfig); 2]) {
    let tmp = tempfile::tempdir().unwrap();
    let mut csv = Vec::new();
    for (k, set) in settings.iter().enumerate() {
        let mut cfg = parse(&pour_toml(&floor_stl(tmp.path())));
        set(&mut cfg);
        let dir = RunDir::create(&tmp.path().join(format!("run{k}"))).unwrap();
        let s = run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap();
        assert_eq!(s.finished, Finished::Completed);
        csv.push(std::fs::read_to_string(dir.root().join("energy.csv")).unwrap());
    }
    assert_ne!(csv[0], csv[1], "{what} changed nothing");
}

#[test]
fn coulomb_load_is_selectable_from_the_scene_and_refused_for_adhesive_laws() {
    use spatter_dem::contact::CoulombLoad;
    for (key, load) in [("total", CoulombLoad::Total), ("elastic", CoulombLoad::Elastic)] {
        let c: ContactConfig = toml::from_str(&format!("coulomb_load = \"{key}\"")).unwrap();
        assert_eq!(c.coulomb_load, load, "{key}");
    }
    assert_eq!(ContactConfig::default().coulomb_load, CoulombLoad::Total);
    assert!(toml::from_str::<ContactConfig>("coulomb_load = \"normal\"").is_err());
    // The choice reaches the engine: damped contacts sliding on the floor and on each other feel another
    // friction cap, so the energy history differs.
    assert_pour_differs(
        "the Coulomb load",
        [&|c| c.contact.coulomb_load = CoulombLoad::Total, &|c| {
            c.contact.coulomb_load = CoulombLoad::Elastic
        }],
    );
    // Adhesive laws choose their own Coulomb force: the key is an error there, naming it.
    let tmp = tempfile::tempdir().unwrap();
    let mut cfg = parse(&pour_toml(&floor_stl(tmp.path())));
    cfg.contact.coulomb_load = CoulombLoad::Elastic;
    cfg.contact.normal = NormalKind::Jkr;
    let errs = Checker::run(&cfg, None).unwrap_err();
    let e = errs.iter().find(|e| e.key == "contact.coulomb_load").unwrap_or_else(|| panic!("{errs:?}"));
    assert!(e.message.contains("adhesive_coulomb"), "{}", e.message);
}

/// The mixed scene of the insertion audit: a tube, a post standing through the fill and injection
/// regions, a horizontal mesh plate across the fill region, a rotating paddle; a random log-normal fill,
/// a lattice fill and a mass-rate injector.
fn walls_in_the_way_toml(dir: &Path) -> String {
    let plate = dir.join("plate.obj");
    std::fs::write(
        &plate,
        "v -0.05 -0.05 0.125\nv 0.05 -0.05 0.125\nv 0.05 0.05 0.125\nv -0.05 0.05 0.125\nf 1 2 3\nf 1 3 4\n",
    )
    .unwrap();
    format!(
        r#"
dt_s = 4e-6
duration_s = 0.004
output_interval_s = 0.002

[materials.grain]
youngs_modulus_pa = 5e7
poisson_ratio = 0.3
density_kg_m3 = 2500

[pair_defaults]
friction = 0.4
restitution = 0.5

[[walls]]
name = "tube"
material = "grain"
shape = {{ type = "cylinder", point_m = [0, 0, 0], axis = [0, 0, 1], radius_m = 0.08, inside = true }}

[[walls]]
name = "post"
material = "grain"
shape = {{ type = "cylinder", point_m = [0, 0, 0], axis = [0, 0, 1], radius_m = 0.01, inside = false, axial_min_m = 0.0, axial_max_m = 0.2 }}

[[walls]]
name = "paddle"
material = "grain"
shape = {{ type = "rectangle", center_m = [0.04, 0, 0.06], half_u_m = [0.02, 0, 0], half_v_m = [0, 0.01, 0] }}
motion = "spin"

[[motions]]
name = "spin"
type = "rotation"
center_m = [0, 0, 0.06]
axis = [0, 0, 1]
angular_speed_rad_s = 5

[[walls]]
name = "plate"
material = "grain"
shape = {{ type = "mesh", file = "{}" }}

[[fill]]
material = "grain"
region = {{ type = "cylinder", base_m = [0, 0, 0.1], axis = [0, 0, 1], radius_m = 0.07, height_m = 0.05 }}
size = {{ kind = "log_normal", median = 0.004, geometric_std = 1.3 }}
count = 200

[[fill]]
material = "grain"
method = "lattice"
region = {{ type = "box", min_m = [-0.03, -0.03, 0.155], max_m = [0.03, 0.03, 0.17] }}
size = {{ kind = "mono", diameter = 0.004 }}

[[inject]]
material = "grain"
region = {{ type = "box", min_m = [-0.04, -0.04, 0.17], max_m = [0.04, 0.04, 0.2] }}
size = {{ kind = "tabulated", diameters = [0.003, 0.004, 0.006], cumulative = [0, 0.5, 1], basis = "mass" }}
kg_per_s = 0.05
velocity_m_s = [0, 0, -0.5]
"#,
        plate.display()
    )
}

#[test]
fn fills_and_injections_cut_by_walls_create_no_overlaps_and_run() {
    // Before, the random fill put spheres into the post and the run stopped at step 0 ("overlap with a
    // wall is 5.792 of its radius"). Every initial sphere must now keep its radius from the post's
    // surface (r ≥ 0.01 + radius within its axial range) and from the plate (|z − 0.125| ≥ radius over
    // the plate's square), exact geometry to 1e-12 m, and the run must complete.
    let tmp = tempfile::tempdir().unwrap();
    let cfg = parse(&walls_in_the_way_toml(tmp.path()));
    Checker::run(&cfg, None).unwrap();
    let built = setup::build(&cfg).unwrap();
    let ps = setup::initial_particles(&cfg, &built.walls, &built.templates).unwrap().spheres;
    let lattice = ps.len() - 200;
    assert!(lattice > 20, "{lattice} lattice particles");
    let clear_of_walls = |x: spatter_core::Vec3, r: f64| {
        let post = x.truncate().length() - 0.01;
        let on_plate = x.x.abs() <= 0.05 && x.y.abs() <= 0.05;
        let plate = if on_plate { (x.z - 0.125).abs() } else { f64::INFINITY };
        let tube = 0.08 - x.truncate().length();
        post >= r - 1e-12 && plate >= r - 1e-12 && tube >= r - 1e-12
    };
    for p in &ps {
        assert!(clear_of_walls(p.pos, p.radius), "{:?} r = {}", p.pos, p.radius);
    }
    // Some spheres sit right next to the post and the plate (the walls did cut the regions).
    assert!(ps.iter().any(|p| p.pos.truncate().length() < 0.01 + 2.0 * p.radius));
    assert!(ps.iter().any(|p| (p.pos.z - 0.125).abs() < 2.0 * p.radius));
    let dir = RunDir::create(&tmp.path().join("run")).unwrap();
    let s = run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.finished, Finished::Completed);
    // 0.05 kg/s for 4 ms: 2e-4 kg, within half a particle (≤ 2.83e-7 kg for 6 mm) of the target.
    let line = s.headline.iter().find(|l| l.starts_with("inject[0]")).expect("injector line");
    let placed: f64 = line.split(", ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    assert!((placed - 2e-4).abs() <= 0.5 * 2500.0 * std::f64::consts::PI / 6.0 * 0.006f64.powi(3), "{line}");
}

#[test]
fn a_fill_that_does_not_fit_is_an_error_naming_the_key() {
    let tmp = tempfile::tempdir().unwrap();
    let mut cfg = parse(&walls_in_the_way_toml(tmp.path()));
    cfg.fill[0].count = Some(20_000);
    cfg.fill[0].max_attempts = 2000;
    let built = setup::build(&cfg).unwrap();
    let err = setup::initial_particles(&cfg, &built.walls, &built.templates).unwrap_err().to_string();
    assert!(err.starts_with("fill[0].count: the region is full: placed "), "{err}");
    assert!(err.contains("of 20000 particles") && err.contains("max_attempts = 2000"), "{err}");
    cfg.fill[0].count = None;
    cfg.fill[0].volume_fraction = Some(0.6);
    let err = setup::initial_particles(&cfg, &built.walls, &built.templates).unwrap_err().to_string();
    assert!(
        err.starts_with("fill[0].volume_fraction: the region is full: reached a solid fraction"),
        "{err}"
    );
}

/// One sphere of `d` (m) at `centre` moving at `v` (m/s), as a one-site cubic lattice fill.
fn one_sphere(centre: [f64; 3], d: f64, v: [f64; 3]) -> String {
    let r = 0.5 * d;
    let lo = [centre[0] - r, centre[1] - r, centre[2] - r];
    let hi = [centre[0] + r + 1e-9, centre[1] + r + 1e-9, centre[2] + r + 1e-9];
    format!(
        r#"
[[fill]]
material = "grain"
method = "lattice"
lattice = "cubic"
spacing_m = {d}
region = {{ type = "box", min_m = [{}, {}, {}], max_m = [{}, {}, {}] }}
size = {{ kind = "mono", diameter = {d} }}
velocity_m_s = [{}, {}, {}]
"#,
        lo[0], lo[1], lo[2], hi[0], hi[1], hi[2], v[0], v[1], v[2]
    )
}

#[test]
fn the_restitution_model_is_chosen_per_pair() {
    // Two 10 mm grains (E = 50 MPa, ν = 0.3, ρ = 2500) fall at 2 m/s, without gravity, onto two steel
    // plates of different materials: grain–plate_a uses Thornton's e(V) with σ_y = 1 MPa, grain–plate_b
    // the constant e = 0.5. Reference for plate_a: Thornton (1997) with the pair yield velocity (thesis
    // Eq. 31) V_y = 3.194 √(p_y⁵R*³/(E*⁴m*)), p_y = 2.5 σ_y, R* = r, m* = m (a wall), E* from the two
    // materials; e = thornton_full(V, V_y) (checked against Thornton's closed form in
    // restitution_models). Realised e: exact calibration (table, 1e-6 in e) and velocity Verlet at
    // ~2000 steps per contact, whose error is O(Δt²) (2e-5 here): 2e-4 absolute.
    let tmp = tempfile::tempdir().unwrap();
    let d = 0.01;
    let r = 0.5 * d;
    let v0 = 2.0;
    let mut text = String::from(
        r#"
dt_s = 2e-7
duration_s = 6e-4
output_interval_s = 6e-4
gravity_m_s2 = [0, 0, 0]

[materials.grain]
youngs_modulus_pa = 5e7
poisson_ratio = 0.3
density_kg_m3 = 2500

[materials.plate_a]
youngs_modulus_pa = 2e11
poisson_ratio = 0.3
density_kg_m3 = 7800

[materials.plate_b]
youngs_modulus_pa = 2e11
poisson_ratio = 0.3
density_kg_m3 = 7800

[pair_defaults]
friction = 0.3
restitution = 0.5

[[pairs]]
materials = ["grain", "plate_a"]
restitution_model = "thornton"
yield_stress_pa = 1e6

[[walls]]
name = "a"
material = "plate_a"
shape = { type = "rectangle", center_m = [-0.05, 0, 0], half_u_m = [0.03, 0, 0], half_v_m = [0, 0.03, 0] }

[[walls]]
name = "b"
material = "plate_b"
shape = { type = "rectangle", center_m = [0.05, 0, 0], half_u_m = [0.03, 0, 0], half_v_m = [0, 0.03, 0] }
"#,
    );
    text.push_str(&one_sphere([-0.05, 0.0, r + 1e-4], d, [0.0, 0.0, -v0]));
    text.push_str(&one_sphere([0.05, 0.0, r + 1e-4], d, [0.0, 0.0, -v0]));
    let cfg = parse(&text);
    Checker::run(&cfg, None).unwrap();
    let dir = RunDir::create(&tmp.path().join("run")).unwrap();
    let s = run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    let vtu = spatter_io::vtk::read(&dir.root().join("particles/particles_00001.vtu")).unwrap();
    let (ids, vel) =
        (&vtu.point_array("id").unwrap().values, &vtu.point_array("velocity_m_s").unwrap().values);
    let x = &vtu.points;
    let mut e = [0.0; 2];
    for k in 0..ids.len() {
        assert!(x[k].z > r + 1e-4, "rebounded and left the plate");
        e[if x[k].x < 0.0 { 0 } else { 1 }] = vel[3 * k + 2] / v0;
    }
    let e_star: f64 = 1.0 / ((1.0 - 0.09) / 5e7 + (1.0 - 0.09) / 2e11);

    let m = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let p_y: f64 = 2.5e6;
    let v_y = 3.194 * (p_y.powi(5) * r.powi(3) / (e_star.powi(4) * m)).sqrt();
    let e_a = spatter_dem::restitution_models::thornton_full(v0, v_y);
    assert!((v_y - 0.1022).abs() < 1e-3 && (e_a - 0.5).abs() > 0.05, "V_y = {v_y}, e = {e_a}");
    assert!((e[0] - e_a).abs() < 2e-4, "Thornton pair: e = {} vs {e_a}", e[0]);
    assert!((e[1] - 0.5).abs() < 2e-4, "constant pair: e = {} vs 0.5", e[1]);
}

#[test]
fn restitution_model_keys_are_checked() {
    let tmp = tempfile::tempdir().unwrap();
    let mut cfg = parse(&pour_toml(&floor_stl(tmp.path())));
    cfg.pair_defaults.restitution_model = RestitutionKind::Thornton;
    cfg.pairs[0].yield_stress_pa = Some(-3.0);
    cfg.pairs[0].restitution_model = Some(RestitutionKind::Thornton);
    let errs = Checker::run(&cfg, None).unwrap_err();
    let find =
        |k: &str| errs.iter().find(|e| e.key == k).unwrap_or_else(|| panic!("no error for {k}: {errs:?}"));
    assert!(find("pair_defaults.yield_stress_pa").message.contains("needs yield_stress_pa"));
    assert!(find("pairs[0].yield_stress_pa").message.contains("positive"));
    cfg.pair_defaults = PairValues::default();
    cfg.pairs[0].restitution_model = None;
    cfg.pairs[0].yield_stress_pa = Some(1e6);
    let errs = Checker::run(&cfg, None).unwrap_err();
    assert_eq!(
        errs[0].message, "yield_stress_pa = 1000000 is used only with restitution_model = \"thornton\"",
        "{errs:?}"
    );
    assert!(toml::from_str::<PairValues>("restitution_model = \"walton\"").is_err());
    let v: PairValues = toml::from_str(
        "restitution_model = \"thornton\"\nyield_stress_pa = 2e6\nthornton_form = \"power_law\"",
    )
    .unwrap();
    assert_eq!(v.thornton_form, spatter_dem::restitution_models::ThorntonForm::PowerLaw);
}

#[test]
fn the_time_step_check_sees_the_smallest_diameter_a_distribution_can_draw() {
    // setup::min_diameter sizes the time-step warning for injected particles; for every bounded
    // distribution no draw may be smaller (exact: the bound is the sampler's own). The wide normal
    // (σ = 0.5 mean) is the case that used to break it: truncated at f64::MIN_POSITIVE, it drew
    // Φ(−1.8) − Φ(−2) = 1.3 % of its particles below the assumed floor mean/10 (Abramowitz & Stegun
    // table 26.1), about 1300 of the 10⁵ draws here.
    use spatter_core::distribution::{PsdBasis, SizeDistribution};
    let dists = [
        SizeDistribution::Mono { diameter: 1e-3 },
        SizeDistribution::Uniform { min: 1e-3, max: 2e-3 },
        SizeDistribution::Normal { mean: 1e-3, std_dev: 0.2e-3 },
        SizeDistribution::Normal { mean: 1e-3, std_dev: 0.5e-3 },
        SizeDistribution::Tabulated {
            diameters: vec![1e-3, 2e-3, 4e-3],
            cumulative: vec![0.0, 0.5, 1.0],
            basis: PsdBasis::Mass,
        },
    ];
    for (k, d) in dists.iter().enumerate() {
        let floor = setup::min_diameter(d);
        let mut rng = spatter_core::rng::seeded(3, k as u64);
        let below = (0..100_000).filter(|_| d.sample(&mut rng) < floor).count();
        assert_eq!(below, 0, "{d:?}: {below} draws below {floor:e}");
    }
    // The normal's floor is max(mean − 3σ, mean/10): 0.4 mm and 0.1 mm here.
    assert_eq!(setup::min_diameter(&dists[2]), 1e-3 - 3.0 * 0.2e-3);
    assert_eq!(setup::min_diameter(&dists[3]), 0.1 * 1e-3);
}

/// Stones on the STL floor of [`pour_toml`]'s box: an ellipsoid template and a three-sphere template from
/// an `x y z r` file, a clump fill and a mass-rate clump injection (ratios by mass), Finnie wear on the
/// floor.
fn stones_toml(dir: &Path) -> String {
    let stl = floor_stl(dir);
    let spheres = dir.join("rod.xyzr");
    std::fs::write(&spheres, "x y z r\n-0.003 0 0 0.002\n0 0 0 0.002\n0.003 0 0 0.002\n").unwrap();
    let mut text = pour_toml(&stl);
    // Keep the box and the floor; the spheres give way to stones.
    text.truncate(text.find("[[fill]]").unwrap());
    text.push_str(&format!(
        r#"
[templates.pebble]
shape = {{ type = "ellipsoid", semi_axes_m = [0.004, 0.003, 0.0025] }}
packing = {{ type = "equal", sphere_diameter_m = 0.0016 }}

[templates.rod]
shape = {{ type = "spheres", file = "{}" }}

[[fill]]
material = "grain"
region = {{ type = "box", min_m = [0, 0, 0.001], max_m = [0.06, 0.06, 0.03] }}
clumps = {{ templates = ["pebble", "rod"], ratios = [1, 1] }}
count = 20
velocity_m_s = [0, 0, -0.5]

[[inject]]
material = "grain"
region = {{ type = "box", min_m = [0, 0, 0.035], max_m = [0.06, 0.06, 0.06] }}
clumps = {{ templates = ["pebble", "rod"], ratios = [3, 1], basis = "mass" }}
kg_per_s = 0.05
velocity_m_s = [0, 0, -0.5]
interval_s = 0.005

[[wear]]
particle_material = "grain"
wall_material = "steel"
model = "finnie"
k_s2_m2 = 1.0
"#,
        spheres.display()
    ));
    text
}

fn scalar(s: &spatter_io::run::RunSummary, name: &str) -> Option<f64> {
    s.scalars.iter().find(|(k, _)| k == name).map(|(_, v)| *v)
}

#[test]
fn a_stone_scene_runs_resumes_bit_for_bit_and_reports_its_wear() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = parse(&stones_toml(tmp.path()));
    Checker::run(&cfg, None).unwrap();
    let full = RunDir::create(&tmp.path().join("full")).unwrap();
    let s = run(&cfg, &RunContext::new(&full, &Unattended, false)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.finished, Finished::Completed);
    let part = RunDir::create(&tmp.path().join("part")).unwrap();
    let stop = StopAfterPolls::new(333);
    let p = run(&cfg, &RunContext::new(&part, &stop, false)).unwrap();
    assert_eq!(p.finished, Finished::Interrupted);
    let p = run(&cfg, &RunContext::new(&part, &Unattended, true)).unwrap();
    assert_eq!(p.finished, Finished::Completed);
    for rel in
        ["energy.csv", "bodies.csv", "wear.csv", "particles/particles_00004.vtu", "walls/floor_00004.vtu"]
    {
        let a = std::fs::read(full.root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let b = std::fs::read(part.root().join(rel)).unwrap();
        assert!(a == b, "{rel} differs between the uninterrupted and the resumed run");
    }
    // The 20 filled bodies plus the injected ones. Placements every 5 ms from t = 0, the last at 35 ms
    // (the run ends at 40 ms): 0.05 kg/s × 0.035 s within half a pebble (the heavier template:
    // ρ 4/3 π abc = 2500 × 1.257e-7 m³ = 3.14e-4 kg, envelope mass).
    let bodies = scalar(&s, "bodies").unwrap();
    let injected_bodies = scalar(&s, "injected_count").unwrap();
    assert!(injected_bodies >= 4.0, "{injected_bodies} bodies injected");
    assert_eq!(bodies, 20.0 + injected_bodies, "no body left the domain");
    let injected = scalar(&s, "injected_mass_kg").unwrap();
    assert!((injected - 0.05 * 0.035).abs() <= 0.5 * 3.15e-4, "injected {injected} kg");
    // Every member sphere in the particle VTU carries its body id; bodies.csv has one row per body.
    let vtu = spatter_io::vtk::read(&full.root().join("particles/particles_00004.vtu")).unwrap();
    let ids = &vtu.point_array("body_id").unwrap().values;
    assert!(ids.iter().all(|&b| b >= 0.0), "only members, no free spheres");
    let mut distinct: Vec<i64> = ids.iter().map(|&b| b as i64).collect();
    distinct.sort();
    distinct.dedup();
    assert_eq!(distinct.len() as f64, bodies);
    let csv = std::fs::read_to_string(full.root().join("bodies.csv")).unwrap();
    let t_end = csv.lines().last().unwrap().split(',').next().unwrap().to_owned();
    let last_rows = csv.lines().filter(|l| l.split(',').next() == Some(t_end.as_str())).count();
    assert_eq!(last_rows as f64, bodies);
    // Wear: the falling stones erode the floor; the summary total equals the wear CSV's last row and the
    // sum over the floor's triangles in the last wall VTU (the only mesh wall).
    let total = scalar(&s, "eroded_mass_kg").unwrap();
    assert!(total > 0.0, "eroded mass {total}");
    let wear = std::fs::read_to_string(full.root().join("wear.csv")).unwrap();
    assert!(wear.starts_with("t_s,floor_eroded_mass_kg,floor_impacts"), "{wear}");
    let last: Vec<f64> = wear.lines().last().unwrap().split(',').map(|x| x.parse().unwrap()).collect();
    assert_eq!(last[1], total);
    let mesh = spatter_io::vtk::read(&full.root().join("walls/floor_00004.vtu")).unwrap();
    let per_triangle: f64 = mesh.cell_array("eroded_mass_kg").unwrap().values.iter().sum();
    assert!((per_triangle - total).abs() <= 1e-12 * total, "{per_triangle} vs {total}");
    assert!(full.root().join("wear/floor_eroded_mass.png").is_file());
    // The map is recorded for a study's gallery: its VTU holds the same per-triangle values.
    let map = s.maps.iter().find(|m| m.label == "floor eroded mass").expect("wear map recorded");
    let recorded = spatter_io::vtk::read(&map.vtu).unwrap();
    let values = &recorded.cell_array(&map.array).unwrap().values;
    assert_eq!(values, &mesh.cell_array("eroded_mass_kg").unwrap().values);
    assert!(full.root().join("templates/pebble.vtu").is_file());
}

/// A sphere thrown at 1 m/s along x and 1 m/s down onto an STL floor, a pebble thrown down beside it; events
/// with the impact angle also seen in the x–z plane and the crossing of the plane x = 0.03 m;
/// trajectories of the first body and sphere.
fn events_toml(dir: &Path) -> String {
    format!(
        r#"
dt_s = 1e-5
duration_s = 0.03
output_interval_s = 0.01
gravity_m_s2 = [0, 0, -9.81]

[materials.grain]
youngs_modulus_pa = 5e7
poisson_ratio = 0.3
density_kg_m3 = 2500

[pair_defaults]
friction = 0.3
restitution = 0.5

[[walls]]
name = "floor"
material = "grain"
shape = {{ type = "mesh", file = "{}" }}

[templates.pebble]
shape = {{ type = "ellipsoid", semi_axes_m = [0.004, 0.003, 0.0025] }}
packing = {{ type = "equal", sphere_diameter_m = 0.0016 }}

[[fill]]
material = "grain"
region = {{ type = "box", min_m = [0.0178, 0.0178, 0.0078], max_m = [0.0222, 0.0222, 0.0122] }}
size = {{ kind = "mono", diameter = 0.004 }}
count = 1
velocity_m_s = [1, 0, -1]

[[fill]]
material = "grain"
region = {{ type = "box", min_m = [0.04, 0.045, 0.006], max_m = [0.06, 0.065, 0.02] }}
clumps = {{ templates = ["pebble"] }}
count = 1
velocity_m_s = [0, 0, -1]

[output.events]
angle_plane_normal = [0, 1, 0]
crossing_plane = {{ point_m = [0.03, 0, 0], normal = [1, 0, 0] }}

[output.trajectories]
every_steps = 100
first = 1
"#,
        floor_stl(dir).display()
    )
}

/// Header and rows of a CSV the scene wrote; an empty cell (an event that did not happen) reads as NaN.
fn csv_rows(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    spatter_io::csv::read_series(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn the_event_log_records_first_impacts_and_plane_crossings_and_resumes() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = parse(&events_toml(tmp.path()));
    Checker::run(&cfg, None).unwrap();
    let full = RunDir::create(&tmp.path().join("full")).unwrap();
    let s = run(&cfg, &RunContext::new(&full, &Unattended, false)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.finished, Finished::Completed);
    let part = RunDir::create(&tmp.path().join("part")).unwrap();
    assert_eq!(
        run(&cfg, &RunContext::new(&part, &StopAfterPolls::new(1234), false)).unwrap().finished,
        Finished::Interrupted
    );
    assert_eq!(run(&cfg, &RunContext::new(&part, &Unattended, true)).unwrap().finished, Finished::Completed);
    for rel in ["events.csv", "trajectories.csv"] {
        let a = std::fs::read(full.root().join(rel)).unwrap();
        let b = std::fs::read(part.root().join(rel)).unwrap();
        assert!(a == b, "{rel} differs between the uninterrupted and the resumed run");
    }
    let (head, rows) = csv_rows(&full.root().join("events.csv"));
    let col = |k: &str| head.iter().position(|h| h == k).unwrap_or_else(|| panic!("no column {k}: {head:?}"));
    // Bodies first: the pebble (body 0, template 0), then the sphere (particle id 0, filled first).
    assert_eq!(rows.len(), 2, "{rows:?}");
    let (body, sphere) = (&rows[0], &rows[1]);
    assert_eq!((body[col("body")], body[col("id")], body[col("template")]), (1.0, 0.0, 0.0));
    assert_eq!((sphere[col("body")], sphere[col("id")], sphere[col("template")]), (0.0, 0.0, -1.0));
    // The sphere falls from its start height h = z0 − r (from the first particle VTU) to touch at 1 m/s
    // along x: v_z² = 1 + 2 g h, so the impact angle is atan(|v_z|/1) ≈ 54° (to 0.02°: the event takes
    // the half-step velocity, g Δt/2 = 5e-5 m/s, of the step in which the contact formed); in the x–z
    // plane the same angle (the velocity lies in it).
    let first = spatter_io::vtk::read(&full.root().join("particles/particles_00000.vtu")).unwrap();
    let free = first.point_array("body_id").unwrap().values.iter().position(|&b| b < 0.0).unwrap();
    let h = first.points[free].z - 0.002;
    let vz = (1.0 + 2.0 * 9.81 * h).sqrt();
    let angle = vz.atan().to_degrees();
    assert!(
        (sphere[col("first_impact_angle_deg")] - angle).abs() < 0.02,
        "{} vs {angle}",
        sphere[col("first_impact_angle_deg")]
    );
    assert!(
        (sphere[col("first_impact_plane_angle_deg")] - sphere[col("first_impact_angle_deg")]).abs() < 1e-9
    );
    assert!((sphere[col("first_impact_speed_m_s")] - vz.hypot(1.0)).abs() < 1e-3);
    assert!((sphere[col("first_impact_normal_speed_m_s")] - vz).abs() < 1e-3);
    // Touch after t = (vz − 1)/g ≈ 7 ms, within a step.
    let t_touch = (vz - 1.0) / 9.81;
    assert!((sphere[col("first_impact_t_s")] - t_touch).abs() < 2e-5, "{}", sphere[col("first_impact_t_s")]);
    assert_eq!(sphere[col("first_impact_wall")], 0.0);
    assert!(sphere[col("first_impact_triangle")] >= 0.0);
    assert!(sphere[col("collisions_floor")] >= 1.0);
    // The pebble, thrown down at 1 m/s from at most 2 cm, lands within 20 ms.
    assert!(body[col("first_impact_t_s")] < 0.02, "{body:?}");
    assert!(body[col("collisions_floor")] >= 1.0);
    assert!(body[col("first_impact_angle_deg")] > 80.0, "{body:?}");
    // The sphere crosses x = 0.03 m moving along +x after ~10 ms (1 m/s from x ≈ 0.02 m, slowed by
    // friction at the bounce); the pebble never does.
    let t_cross = sphere[col("crossing_t_s")];
    assert!(t_cross > 0.0097 && t_cross < 0.02, "{t_cross}");
    assert!(sphere[col("crossing_dir_x")] > 0.5);
    assert!((sphere[col("crossing_x_m")] - 0.03).abs() < 2e-5);
    assert!(body[col("crossing_t_s")].is_nan());
    // Trajectories: body 0 and sphere 0 every 100 steps (3000 steps: 30 rows each).
    let (thead, trows) = csv_rows(&full.root().join("trajectories.csv"));
    assert_eq!(thead[..3], ["t_s", "body", "id"]);
    assert_eq!(trows.len(), 60);
    assert!(trows.iter().all(|r| r[2] == 0.0));
    assert_eq!(trows.iter().filter(|r| r[1] == 1.0).count(), 30);
    assert_eq!(scalar(&s, "objects_hit_wall"), Some(2.0));
    assert_eq!(scalar(&s, "objects_crossed_plane"), Some(1.0));
}

/// A scene of free spheres only (no clump templates: the particles carry no body index at all) with a
/// crossing plane and trajectories: the event log and the trajectories are written (the sphere crosses
/// x = 0.03 m moving along +x, one trajectory row every 100 steps) — reading the missing body index
/// panicked before.
#[test]
fn events_and_trajectories_of_a_scene_without_clumps() {
    let tmp = tempfile::tempdir().unwrap();
    let text = events_toml(tmp.path());
    let start = text.find("[templates.pebble]").unwrap();
    let end = text.find("[output.events]").unwrap();
    let fill = text[start..end].find("[[fill]]").unwrap();
    // Keep the first fill (the free sphere), drop the template and the clump fill.
    let second = text[start + fill + 8..end].find("[[fill]]").unwrap() + start + fill + 8;
    let text = format!("{}{}{}", &text[..start], &text[start + fill..second], &text[end..]);
    assert!(!text.contains("pebble"), "{text}");
    let cfg = parse(&text);
    Checker::run(&cfg, None).unwrap();
    let dir = RunDir::create(&tmp.path().join("run")).unwrap();
    let s = run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.finished, Finished::Completed);
    let (head, rows) = csv_rows(&dir.root().join("events.csv"));
    let col = |k: &str| head.iter().position(|h| h == k).unwrap_or_else(|| panic!("no column {k}: {head:?}"));
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!((rows[0][col("body")], rows[0][col("template")]), (0.0, -1.0));
    assert!((rows[0][col("crossing_x_m")] - 0.03).abs() < 2e-5);
    assert!(rows[0][col("crossing_dir_x")] > 0.5);
    let (_, trows) = csv_rows(&dir.root().join("trajectories.csv"));
    assert_eq!(trows.len(), 30);
    assert_eq!(scalar(&s, "objects_crossed_plane"), Some(1.0));
}

/// A tyre wall on a wheel node (ω = 5 rad/s about y through (0, 0, 0.4)) whose parent chassis drives at
/// 2 m/s along x: rolling without slip (v = ωR with R = 0.4 m). Analytic: the wall point at the origin at
/// t = 0 is at (2t − 0.4 sin 5t, 0, 0.4 − 0.4 cos 5t), the contact point is at rest, the top moves at 4 m/s.
#[test]
fn a_wall_on_a_child_motion_rolls_with_its_chassis() {
    let cfg = parse(
        r#"
dt_s = 1e-5
duration_s = 0.001
output_interval_s = 0.001
[materials.rubber]
youngs_modulus_pa = 1e7
poisson_ratio = 0.45
density_kg_m3 = 1100
[pair_defaults]
friction = 0.5
restitution = 0.5
[[motions]]
name = "chassis"
type = "translation"
velocity_m_s = [2, 0, 0]
[[motions]]
name = "wheel"
parent = "chassis"
type = "rotation"
center_m = [0, 0, 0.4]
axis = [0, 1, 0]
angular_speed_rad_s = 5
[[walls]]
name = "tyre"
material = "rubber"
shape = { type = "cylinder", point_m = [0, 0, 0.4], axis = [0, 1, 0], radius_m = 0.4, inside = false }
motion = "wheel"
[[walls]]
name = "road"
material = "rubber"
shape = { type = "plane", point_m = [0, 0, 0], normal = [0, 0, 1] }
"#,
    );
    let built = setup::build(&cfg).unwrap_or_else(|e| panic!("{e}"));
    let (tyre, road) = (&built.walls[0].motion, &built.walls[1].motion);
    assert!(matches!(road, spatter_core::motion::Motion::Fixed));
    for t in [0.0, 0.1, 0.77] {
        let p = tyre.pose(t).apply(Vec3::ZERO);
        let th: f64 = 5.0 * t;
        let want = Vec3::new(2.0 * t - 0.4 * th.sin(), 0.0, 0.4 - 0.4 * th.cos());
        assert!((p - want).length() < 1e-12, "t = {t}: {p} vs {want}");
        let centre = Vec3::new(2.0 * t, 0.0, 0.4);
        let bottom = centre - Vec3::new(0.0, 0.0, 0.4);
        assert!(tyre.velocity_at(t, bottom).length() < 1e-12, "the contact point is at rest");
        let top = tyre.velocity_at(t, centre + Vec3::new(0.0, 0.0, 0.4));
        assert!((top - Vec3::new(4.0, 0.0, 0.0)).length() < 1e-12, "{top}");
    }
    // A wall naming no node of [[motions]] is refused with the key.
    let mut bad = cfg.clone();
    bad.walls[1].motion = Some("spin".into());
    let e = Checker::run(&bad, None).unwrap_err();
    assert!(
        e.iter().any(|i| i.key == "walls[1].motion" && i.message.contains("\"spin\" is not defined")),
        "{e:?}"
    );
}
