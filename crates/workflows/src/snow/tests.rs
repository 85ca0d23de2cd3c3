//! Whole-workflow tests of the snow module (fast variants; the full cases run in `spatter validate`).

use super::config::{Mode, SnowConfig, TargetKind};
use super::impact::{Decision, Outcome, StickCriterion};
use super::model::Surface;
use super::runner::{model_of, run};
use spatter_core::check::Checker;
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_dem::restitution_models::RestitutionModel;
use spatter_io::run::{RunContext, RunDir};

#[test]
fn quick_validation_cases_pass() {
    for case in super::validation::validation_cases() {
        for check in (case.run)(true) {
            assert!(
                check.passed(),
                "{} / {}: reference {} ours {} ({:?}, {})",
                check.case,
                check.quantity,
                check.reference,
                check.ours,
                check.tolerance,
                check.source
            );
        }
    }
}

#[test]
fn hertz_restitution_and_energy_through_the_driver() {
    // Without adhesion and with the LIGGGHTS damping (no tensile clamp) the realised restitution equals
    // the input for Hertz (the linearised coefficient is exact there, contact::restitution_fit); e = 1
    // conserves energy. Tolerance 2e-3: time discretisation at 200 steps per contact.
    let mut cfg = SnowConfig::default();
    cfg.contact.normal_law = super::config::NormalLawKind::Hertz;
    for e in [1.0, 0.8, 0.5, 0.2] {
        cfg.contact.restitution = RestitutionModel::Constant { restitution: e };
        let (r, _) = model_of(&cfg).simulate(20e-6, 1.0, 0.0, [0.0, 0.0], Surface::Configured);
        assert_eq!(r.outcome, Outcome::Bounce);
        assert_eq!(r.decision, Decision::Separated);
        assert!((r.restitution - e).abs() < 2e-3, "e_in {e}: e_out {}", r.restitution);
    }
}

#[test]
fn chung_ooi_glass_spheres_particle_particle() {
    // VERIFICATION.md, Chung & Ooi test 1: glass spheres R = 0.01 m at ±10 m/s, elastic, δ_max = 274.1 µm
    // (1 %). Here one sphere at rest is hit at 20 m/s (same relative motion); momentum is conserved and
    // the relative rebound speed equals the approach speed.
    let glass = spatter_core::material::Material::new(48e9, 0.2, 2800.0).unwrap();
    let mut cfg = SnowConfig {
        particle: glass.clone(),
        wall: glass,
        target: TargetKind::Particle,
        ..Default::default()
    };
    cfg.contact.normal_law = super::config::NormalLawKind::Hertz;
    cfg.contact.restitution = RestitutionModel::Constant { restitution: 1.0 };
    cfg.contact.work_of_adhesion_j_m2 = 0.0;
    let (r, _) = model_of(&cfg).simulate(0.02, 20.0, 0.0, [0.0, 0.0], Surface::Configured);
    assert!((r.max_overlap / 274.1e-6 - 1.0).abs() < 0.01, "{}", r.max_overlap);
    assert!((r.restitution - 1.0).abs() < 1e-3, "{}", r.restitution);
}

#[test]
fn outcome_depends_on_the_normal_speed_only() {
    // Thesis §4.2 / Fig. 14: on a flat wall the normal force does not see the tangential motion, so under
    // the overlap criterion stick/bounce is the same at every impact angle.
    let cfg = SnowConfig::default();
    let model = model_of(&cfg);
    for v_n in [2.0, 6.0, 8.0, 8.3, 12.0] {
        let (a, _) = model.simulate(10e-6, v_n, 0.0, [0.0, 0.0], Surface::Configured);
        for angle in [30.0f64, 60.0, 80.0] {
            let v_t = v_n * angle.to_radians().tan();
            let (b, _) = model.simulate(10e-6, v_n, v_t, [0.0, 0.0], Surface::Configured);
            assert_eq!(a.outcome, b.outcome, "v_n {v_n}, angle {angle}");
        }
    }
}

#[test]
fn static_tangential_criterion_rejects_sliding_particles() {
    // A 10 µm grain that sticks in the normal direction but still slides at the check time counts as a
    // stick under the thesis criterion and as a bounce under the static criterion.
    let mut cfg = SnowConfig::default();
    let (r, _) = model_of(&cfg).simulate(10e-6, 1.0, 5.0, [0.0, 0.0], Surface::Configured);
    assert_eq!(r.outcome, Outcome::Stick);
    cfg.integration.stick_criterion = StickCriterion::StaticTangential;
    let (r, _) = model_of(&cfg).simulate(10e-6, 1.0, 5.0, [0.0, 0.0], Surface::Configured);
    assert_eq!(r.outcome, Outcome::Bounce);
    // The grain rolls without slipping (v = 5/7 v_t) but does not stay where it landed.
    assert!(r.slip_speed < 1e-3 && (r.tangential_speed / 5.0 - 5.0 / 7.0).abs() < 1e-3, "{r:?}");
    // Without tangential motion the static criterion agrees with the overlap criterion.
    let (r, _) = model_of(&cfg).simulate(10e-6, 1.0, 0.0, [0.0, 0.0], Surface::Configured);
    assert_eq!(r.outcome, Outcome::Stick);
}

#[test]
fn rough_wall_start_touches_one_bed_sphere() {
    let cfg = SnowConfig::default();
    let bed = super::runner::make_bed(&cfg);
    let model = model_of(&cfg);
    let surface = Surface::Bed { spheres: &bed.spheres, top: bed.top, sphere_radius: bed.sphere_radius };
    // Slow impacts on a 1 µm bed stick (single-asperity v_crit ≈ 0.95 m/s, digest §4.4), fast ones mostly
    // bounce; every run ends decided.
    let mut fast_bounces = 0;
    for k in 0..8 {
        let aim = super::runner::aim_point(&cfg, k);
        let (slow, _) = model.simulate(10e-6, 0.1, 0.0, aim, surface);
        assert_eq!(slow.outcome, Outcome::Stick, "aim {aim:?}");
        assert!(slow.max_overlap > 0.0);
        let (fast, _) = model.simulate(10e-6, 4.0, 0.0, aim, surface);
        if fast.outcome == Outcome::Bounce {
            fast_bounces += 1;
        }
    }
    assert!(fast_bounces >= 3, "{fast_bounces}");
}

fn small(mode: Mode) -> SnowConfig {
    let mut cfg = SnowConfig { mode, svg: false, ..Default::default() };
    cfg.grid.diameters = 6;
    cfg.grid.normal_speeds = 8;
    cfg.sensitivity.cases.truncate(3);
    cfg.rough_wall.normal_speeds = 3;
    cfg.rough_wall.impacts_per_speed = 4;
    cfg.rough_wall.bed_width_m = Some(20e-6);
    cfg
}

#[test]
fn interrupted_and_resumed_runs_equal_uninterrupted_ones() {
    let root = tempfile::tempdir().unwrap();
    for mode in [Mode::Grid, Mode::Bisection, Mode::Sensitivity, Mode::RoughWall] {
        let cfg = small(mode);
        let a = RunDir::create(&root.path().join(format!("{mode:?}_a"))).unwrap();
        let s = run(&cfg, &RunContext { dir: &a, control: &Unattended, resume: false }).unwrap();
        assert_eq!(s.finished, Finished::Completed);
        let b = RunDir::create(&root.path().join(format!("{mode:?}_b"))).unwrap();
        let stop = StopAfterPolls::new(1);
        let s = run(&cfg, &RunContext { dir: &b, control: &stop, resume: false }).unwrap();
        assert_eq!(s.finished, Finished::Interrupted, "{mode:?}");
        assert!(b.checkpoint_path().exists());
        let s = run(&cfg, &RunContext { dir: &b, control: &Unattended, resume: true }).unwrap();
        assert_eq!(s.finished, Finished::Completed);
        assert!(!b.checkpoint_path().exists());
        let mut compared = 0;
        for entry in std::fs::read_dir(a.root()).unwrap() {
            let name = entry.unwrap().file_name();
            let n = name.to_string_lossy();
            if n.ends_with(".csv") || n.ends_with(".json") {
                let fa = std::fs::read(a.root().join(&name)).unwrap();
                let fb = std::fs::read(b.root().join(&name)).unwrap();
                assert!(fa == fb, "{mode:?}: {n} differs after resume");
                compared += 1;
            }
        }
        assert!(compared >= 2, "{mode:?}: {compared} files compared");
        assert!(a
            .root()
            .join(match mode {
                Mode::Grid => "regime_map.png",
                Mode::Bisection => "critical_speed.png",
                Mode::Sensitivity => "sensitivity_boundaries.png",
                Mode::RoughWall => "stick_probability.png",
                Mode::Single => "force_overlap.png",
            })
            .exists());
    }
}

#[test]
fn resume_refuses_a_different_configuration() {
    let root = tempfile::tempdir().unwrap();
    let cfg = small(Mode::Grid);
    let d = RunDir::create(root.path()).unwrap();
    let stop = StopAfterPolls::new(0);
    assert_eq!(
        run(&cfg, &RunContext { dir: &d, control: &stop, resume: false }).unwrap().finished,
        Finished::Interrupted
    );
    let mut other = cfg.clone();
    other.grid.normal_speeds = 9;
    let e = run(&other, &RunContext { dir: &d, control: &Unattended, resume: true }).unwrap_err();
    assert!(e.to_string().contains("different configuration"), "{e}");
}

#[test]
fn grid_results_do_not_depend_on_the_thread_count() {
    let cfg = small(Mode::Grid);
    let model = model_of(&cfg);
    let jobs = super::regime::grid_jobs(&cfg.grid);
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    use rayon::prelude::*;
    let a: Vec<_> = one.install(|| jobs.par_iter().map(|j| super::regime::run_job(&model, j)).collect());
    let b: Vec<_> = two.install(|| jobs.par_iter().map(|j| super::regime::run_job(&model, j)).collect());
    assert_eq!(a, b);
}

#[test]
fn configuration_round_trip_and_messages() {
    let cfg = SnowConfig::default();
    let text = serde_json::to_string(&cfg).unwrap();
    let back: SnowConfig = serde_json::from_str(&text).unwrap();
    assert_eq!(back, cfg);
    let bad: Result<SnowConfig, _> = serde_json::from_str(r#"{"mode": "grid", "speed": 3}"#);
    assert!(bad.is_err(), "unknown keys are rejected");
    let mut cfg = SnowConfig::default();
    cfg.particle.poisson_ratio = 0.6;
    cfg.grid.diameter_max_m = 1e-6;
    cfg.contact.restitution = RestitutionModel::Constant { restitution: 0.0 };
    let e = Checker::run(&cfg, None).unwrap_err();
    let keys: Vec<&str> = e.iter().map(|i| i.key.as_str()).collect();
    assert!(keys.contains(&"particle.poisson_ratio"), "{keys:?}");
    assert!(keys.contains(&"grid.diameter_max_m"), "{keys:?}");
    assert!(keys.contains(&"contact.restitution.restitution"), "{keys:?}");
}

#[test]
fn driver_matches_the_dem_engine() {
    // The lean driver and the full DEM engine call the same contact law; with the engine's plain
    // velocity Verlet (half-step velocities in the dashpot, `predict_velocity = false`) and the same Δt
    // they must produce the same trajectory: same outcome and, for bounces, the same rebound speed to
    // round-off (1e-9 relative).
    use spatter_core::motion::Motion;
    use spatter_core::Vec3;
    use spatter_dem::adhesion::JkrLaw;
    use spatter_dem::contact::{
        Composed, Mindlin, NoRolling, PairProps, PairTable, RestitutionCalibration, RestitutionDamping,
    };
    use spatter_dem::walls::{Plane, Wall, WallShape};
    use spatter_dem::{NewParticle, Settings, Simulation};
    let mut cfg = SnowConfig::default();
    cfg.integration.predict_velocity = false;
    let model = model_of(&cfg);
    for (d, v) in [(10e-6, 4.0), (10e-6, 12.0), (50e-6, 1.0), (50e-6, 3.0)] {
        let (r, setup) = model.simulate(d, v, 0.0, [0.0, 0.0], Surface::Configured);
        let (props, _) = model.setup(d, v, Surface::Configured);
        let mats = vec![cfg.particle.clone(), cfg.wall.clone()];
        let pairs = PairTable::build(2, |a, b| {
            if a != b {
                props.clone()
            } else {
                PairProps::new(&mats[a], &mats[b], 0.05, 0.5)
            }
        });
        let damping = RestitutionDamping {
            tensile_clamp: false,
            calibration: RestitutionCalibration::Linearised,
            tangential: true,
        };
        let law = Composed::new(JkrLaw::default(), damping, Mindlin, NoRolling);
        let mut sim = Simulation::new(law, mats, pairs, setup.dt, Settings::default());
        sim.add_wall(Wall {
            name: "wall".into(),
            shape: WallShape::Plane(Plane::new(Vec3::ZERO, Vec3::Z)),
            material: 1,
            motion: Motion::Fixed,
        });
        sim.add_particle(NewParticle {
            pos: Vec3::new(0.0, 0.0, 0.5 * d),
            vel: Vec3::new(0.0, 0.0, -v),
            omega: Vec3::ZERO,
            radius: 0.5 * d,
            material: 0,
            frozen: false,
        });
        sim.run_steps(r.steps).unwrap();
        let (z, vz) = (sim.particles.pos[0].z, sim.particles.vel[0].z);
        match r.outcome {
            Outcome::Bounce => {
                assert!(
                    (vz / v - r.restitution).abs() < 1e-9 * r.restitution.max(1e-3),
                    "d {d} v {v}: {vz} vs {}",
                    r.restitution * v
                );
            }
            Outcome::Stick => {
                // Still within the neck after the same number of steps.
                let jkr = spatter_dem::adhesion::Jkr::new(props.e_star, 0.5 * d, props.work_of_adhesion);
                assert!(0.5 * d - z > -jkr.critical_overlap, "d {d} v {v}: engine separated");
            }
        }
    }
}

#[test]
fn sensitivity_checks_fail_on_doctored_counts() {
    // Every check of `snow_sensitivity_stick_counts` must be able to fail. Reference: the thesis counts of
    // Table 3 (L503–531) and our full-grid counts at 16 m/s (docs/snow.md §4.3), which pass.
    use super::config::SensitivityCase;
    use super::validation::sensitivity_checks;
    let cases = SensitivityCase::thesis_table();
    let thesis: Vec<usize> = cases.iter().map(|k| k.thesis_sticks.unwrap() as usize).collect();
    let failed = |counts: &[usize]| -> Vec<String> {
        sensitivity_checks(&cases, counts).into_iter().filter(|c| !c.passed()).map(|c| c.quantity).collect()
    };
    let ours = [249, 247, 249, 249, 249, 102, 1270, 469, 165];
    assert!(failed(&ours).is_empty(), "{:?}", failed(&ours));
    assert!(failed(&thesis).is_empty(), "{:?}", failed(&thesis));
    // A model that never sticks fails every count (ln 0) and both trends; the E/ν ratios are 0/0 (NaN).
    let never = failed(&[0; 9]);
    assert_eq!(never.len(), 9 + 2 + 4, "{never:?}");
    // A true factor of 2: the thesis counts ×1.95 pass, ×2.05 and ÷2.05 fail every count check.
    let scaled = |f: f64| -> Vec<usize> { thesis.iter().map(|&t| (t as f64 * f).round() as usize).collect() };
    assert!(failed(&scaled(1.95)).is_empty(), "{:?}", failed(&scaled(1.95)));
    for f in [2.05, 1.0 / 2.05] {
        let fails = failed(&scaled(f));
        assert_eq!(fails.len(), 9, "×{f}: {fails:?}");
        assert!(fails.iter().all(|q| q.starts_with("|ln(sticks/thesis)|")), "{fails:?}");
    }
    // Trends are strict: equal counts (Γ or σ_y without effect) fail, one trend check each (the count of
    // the changed case may fail its factor-2 check as well).
    let trend_fails = |counts: &[usize]| -> Vec<String> {
        failed(counts).into_iter().filter(|q| !q.starts_with("|ln(sticks/thesis)|")).collect()
    };
    for (i, word) in [(6, "Γ=1"), (5, "Γ=1"), (7, "σ_y=0.5"), (8, "σ_y=0.5")] {
        let mut k = ours;
        k[i] = k[0];
        let fails = trend_fails(&k);
        assert_eq!(fails.len(), 1, "case {i}: {fails:?}");
        assert!(fails[0].contains(word) && fails[0].contains("[1 = holds]"), "{fails:?}");
    }
    // Reversed trends fail too.
    let mut k = ours;
    k.swap(5, 6);
    assert_eq!(trend_fails(&k).len(), 1);
    let mut k = ours;
    k.swap(7, 8);
    assert_eq!(trend_fails(&k).len(), 1);
    // E and ν: 6 % and 3 % changes fail (limits 5 % and 2 %), 4 % and 1.6 % pass.
    for (i, n, fails) in [(1, 264, 1), (2, 234, 1), (1, 259, 0), (3, 257, 1), (4, 241, 1), (4, 253, 0)] {
        let mut k = ours;
        k[i] = n;
        assert_eq!(failed(&k).len(), fails, "case {i} with {n} sticks: {:?}", failed(&k));
    }
}
