use super::config::*;
use super::run;
use spatter_core::control::{StopAfterPolls, Unattended};
use spatter_core::distribution::SizeDistribution;
use spatter_core::mesh::TriMesh;
use spatter_core::regime::{PolyFit, RegimeMap};
use spatter_core::Vec3;
use spatter_flow::field::analytic::{AnalyticField, ConstantTurbulence};
use spatter_flow::tracker::inject::{InjectorSpec, Region};
use spatter_flow::tracker::walls::{Restitution, WallRuleSpec};
use spatter_io::run::{RunContext, RunDir};
use std::path::Path;

/// A plate at z = 0 under a slanted flow, a regime map with v_crit = 1.5 m/s, a box injector.
fn scenario(dir: &Path) -> DepositionConfig {
    let mut plate = TriMesh::rectangle(1.0, 1.0, 0.0, 8, 8);
    plate.map_vertices(|v| v - Vec3::new(0.5, 0.5, 0.0));
    std::fs::write(dir.join("plate.stl"), plate.to_binary_stl()).unwrap();
    let fit = PolyFit {
        x: "diameter_m".into(),
        y: "critical_normal_speed_m_s".into(),
        log10: true,
        coefficients: vec![1.5f64.log10()],
        x_range: [1e-6, 1e-3],
        rms_relative_error: 0.0,
    };
    let map = RegimeMap {
        schema: RegimeMap::SCHEMA.into(),
        description: "test".into(),
        v_crit_of_d: fit.clone(),
        d_crit_of_vn: fit,
        interface: vec![],
    };
    std::fs::write(dir.join("map.json"), serde_json::to_string(&map).unwrap()).unwrap();
    DepositionConfig {
        fluid: Default::default(),
        flow: FlowSpec {
            analytic: vec![AnalyticField::Uniform { velocity: Vec3::new(3.0, 0.0, -2.0) }],
            turbulence: Some(ConstantTurbulence { k: 0.3, epsilon: 1.0 }),
            length_scale: 1.0,
            ..Default::default()
        },
        forces: Default::default(),
        dispersion: Some(Default::default()),
        bodies: vec![BodySpec {
            name: "plate".into(),
            file: dir.join("plate.stl"),
            scale: 1.0,
            translate_m: Vec3::ZERO,
            wall: WallRuleSpec::RegimeMap {
                file: dir.join("map.json"),
                bounce: Restitution { normal: 0.4, tangential: 0.9 },
                max_tangential_speed_m_s: None,
                max_wall_shear_pa: None,
            },
            shear_probe_distance_m: 1e-3,
            view_direction: Vec3::new(0.0, 0.0, -1.0),
            view_up: Vec3::Y,
        }],
        injectors: vec![InjectorSpec {
            name: "cloud".into(),
            region: Region::Box { min_m: Vec3::new(-0.45, -0.3, 0.1), max_m: Vec3::new(-0.3, 0.3, 0.4) },
            size: SizeDistribution::LogNormal { median: 40e-6, geometric_std: 1.5 },
            density: 917.0,
            velocity: Vec3::new(3.0, 0.0, -2.0),
            normal_speed: 0.0,
            velocity_spread: 0.0,
            parcels: 3000,
            start_s: 0.0,
            end_s: 0.05,
            particles_per_parcel: None,
            mass_per_parcel_kg: None,
            mass_flow_kg_s: Some(1e-5),
            seed: 4,
        }],
        time: TimeSpec { dt_s: 5e-4, duration_s: 0.4, stop_when_settled: true },
        domain: Some(DomainBox { min_m: Vec3::new(-0.6, -0.6, -0.1), max_m: Vec3::new(0.6, 0.6, 0.6) }),
        output: OutputSpec {
            interval_s: 0.02,
            parcels: true,
            picture_quantity: PictureQuantity::MassPerArea,
        },
    }
}

fn run_in(
    cfg: &DepositionConfig,
    out: &Path,
    control: &dyn spatter_core::control::RunControl,
    resume: bool,
) -> spatter_io::run::RunSummary {
    let rd = RunDir::create(out).unwrap();
    let ctx = RunContext::new(&rd, control, resume);
    run(cfg, &ctx).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn interrupted_and_resumed_run_equals_an_uninterrupted_one() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = scenario(dir.path());
    let a = dir.path().join("a");
    let s = run_in(&cfg, &a, &Unattended, false);
    assert_eq!(s.finished, spatter_core::control::Finished::Completed);
    assert!(s.headline[0].contains("residual 0e0 kg"), "{}", s.headline[0]);
    let b = dir.path().join("b");
    let s = run_in(&cfg, &b, &StopAfterPolls::new(137), false);
    assert_eq!(s.finished, spatter_core::control::Finished::Interrupted);
    assert!(b.join("checkpoint.bin").is_file());
    // The interrupted run wrote the body outputs from the deposits so far, and says they are partial.
    // Their content is the checkpoint's: the VTU's per-triangle masses add up to the exactly summed
    // deposited mass of the balance (1e-12 relative) and its impacts to the deposit's impact count.
    assert!(b.join("plate_deposit.png").is_file() && b.join("deposit_summary.csv").is_file());
    assert!(s.headline.iter().any(|l| l.contains("PARTIAL") && l.contains("--resume")), "{:?}", s.headline);
    let ck: super::run::Checkpoint = spatter_io::checkpoint::load(&b.join("checkpoint.bin"), 0).unwrap();
    let vtu = spatter_io::vtk::read(&b.join("bodies/plate.vtu")).unwrap();
    let partial_mass: f64 = vtu.cell_array("deposited_mass_kg").unwrap().values.iter().sum();
    let exact = ck.state.balance.deposited.value();
    assert!(exact > 0.0, "nothing deposited before the interrupt: pick a later one");
    assert!((partial_mass - exact).abs() <= 1e-12 * exact, "{partial_mass} vs {exact}");
    let partial_impacts: f64 = vtu.cell_array("impacts").unwrap().values.iter().sum();
    assert_eq!(partial_impacts, ck.state.deposits[0].impacts.iter().sum::<u64>() as f64);
    let s = run_in(&cfg, &b, &StopAfterPolls::new(100), true);
    assert_eq!(s.finished, spatter_core::control::Finished::Interrupted, "stopped twice");
    let s = run_in(&cfg, &b, &Unattended, true);
    assert_eq!(s.finished, spatter_core::control::Finished::Completed);
    for f in [
        "balance.csv",
        "bodies/plate.vtu",
        "deposit_summary.csv",
        "plate_deposit.png",
        "parcels.pvd",
        "parcels/parcels_00005.vtu",
    ] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f} differs after resume"
        );
    }
    assert!(!b.join("checkpoint.bin").exists());
    // Something stuck and something bounced: the plate saw more impacts than parcels stuck to it.
    let vtu = spatter_io::vtk::read(&a.join("bodies/plate.vtu")).unwrap();
    let impacts: f64 = vtu.cell_array("impacts").unwrap().values.iter().sum();
    let deposited_mass: f64 = vtu.cell_array("deposited_mass_kg").unwrap().values.iter().sum();
    let balance = std::fs::read_to_string(a.join("balance.csv")).unwrap();
    let last: Vec<f64> = balance.lines().last().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    let stuck_parcels = last[2];
    assert!(stuck_parcels > 0.0 && deposited_mass > 0.0, "nothing stuck");
    assert!(impacts > stuck_parcels, "nothing bounced: {impacts} impacts, {stuck_parcels} parcels stuck");
    // The body file and the summary agree on the deposited mass.
    let summary = std::fs::read_to_string(a.join("deposit_summary.csv")).unwrap();
    let row: Vec<&str> = summary.lines().nth(1).unwrap().split(',').collect();
    let deposited: f64 = row[1].parse().unwrap();
    assert!((deposited - deposited_mass).abs() <= 1e-12 * deposited, "{deposited} vs {deposited_mass}");
    assert_eq!(row[3].parse::<f64>().unwrap(), impacts);
    assert!(a.join("plate_deposit.png").is_file());
}

#[test]
fn resuming_with_another_configuration_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = scenario(dir.path());
    let out = dir.path().join("run");
    let s = run_in(&cfg, &out, &StopAfterPolls::new(20), false);
    assert_eq!(s.finished, spatter_core::control::Finished::Interrupted);
    let mut other = cfg.clone();
    other.time.dt_s = 2.5e-4;
    let rd = RunDir::create(&out).unwrap();
    // The checkpoint carries the hash of the input that wrote it (the job driver stamps the resolved
    // input's hash; `run_in` stamps 0), and the run loads it through the context.
    let ctx = RunContext { input_hash: 12, ..RunContext::new(&rd, &Unattended, true) };
    let e = run(&other, &ctx).unwrap_err().to_string();
    assert!(e.contains("checkpoint.bin") && e.contains("different scenario"), "{e}");
    // The checkpoint is left for the right configuration.
    assert!(out.join("checkpoint.bin").is_file());
    let s = run_in(&cfg, &out, &Unattended, true);
    assert_eq!(s.finished, spatter_core::control::Finished::Completed);
}

#[test]
fn a_rust_caller_gets_the_validation_too() {
    // dt_s = 0 used to give duration/dt = ∞ → u64::MAX steps: an endless run.
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = scenario(dir.path());
    cfg.time.dt_s = 0.0;
    let rd = RunDir::create(&dir.path().join("run")).unwrap();
    let ctx = RunContext::new(&rd, &Unattended, false);
    let e = run(&cfg, &ctx).unwrap_err();
    assert!(matches!(e, super::DepositionError::Invalid(_)), "{e}");
    assert!(e.to_string().contains("dt_s = 0 must be a positive number (time.dt_s)"), "{e}");
}

#[test]
fn body_names_cannot_leave_the_run_folder() {
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = scenario(dir.path());
    for bad in ["../../x", "a/b", "..", "plate one", ""] {
        cfg.bodies[0].name = bad.into();
        let errs = spatter_core::check::Checker::run(&cfg, Some(dir.path())).unwrap_err();
        assert!(errs.iter().any(|e| e.key == "bodies[0].name"), "{bad}: {errs:?}");
    }
    for good in ["plate", "wedge_v2.stl-body", "A.1"] {
        cfg.bodies[0].name = good.into();
        assert!(spatter_core::check::Checker::run(&cfg, Some(dir.path())).is_ok(), "{good}");
    }
}

#[test]
fn bad_inputs_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = scenario(dir.path());
    cfg.flow.vtk = Some("nowhere.vtu".into());
    cfg.injectors[0].end_s = -1.0;
    cfg.time.dt_s = 0.0;
    let errs = spatter_core::check::Checker::run(&cfg, Some(dir.path())).unwrap_err();
    let keys: Vec<&str> = errs.iter().map(|e| e.key.as_str()).collect();
    assert!(keys.contains(&"flow"), "{errs:?}");
    assert!(keys.contains(&"flow.vtk"), "{errs:?}");
    assert!(keys.contains(&"injectors[0].end_s"), "{errs:?}");
    assert!(keys.contains(&"time.dt_s"), "{errs:?}");
    let e = errs.iter().find(|e| e.key == "time.dt_s").unwrap();
    assert_eq!(e.message, "dt_s = 0 must be a positive number");
}

#[test]
fn wall_lift_key_uses_the_wall_shear_estimate_and_changes_the_run_only_when_on() {
    use spatter_flow::forces::wall_lift::WallLiftSettings;
    // The test scenario with a planar stagnation flow added to its uniform stream: u = (3 + a x, 0, −2 − a z)
    // with a = 2 s⁻¹. With `[forces] wall_lift` on (u_* from the estimate) the plate's wall shear is
    // estimated at h = 0.1 mm: τ_w = μ|u_t(h)|/h = μ|3 + a x_c|/h per triangle (x_c the centroid), checked
    // to 1e-12 relative in the body VTU. Without the key nothing is estimated (zeros) and the run differs.
    let dir = tempfile::tempdir().unwrap();
    let mut cfg = scenario(dir.path());
    let (a, h) = (2.0, 1e-4);
    cfg.flow.analytic.push(AnalyticField::StagnationPoint {
        strain_rate: a,
        centre: Vec3::ZERO,
        normal: Vec3::Z,
        axisymmetric: false,
    });
    cfg.bodies[0].shear_probe_distance_m = h;
    cfg.output.parcels = false;
    let mut on = cfg.clone();
    on.forces.wall_lift = Some(WallLiftSettings::default());
    let (out_off, out_on) = (dir.path().join("off"), dir.path().join("on"));
    run_in(&cfg, &out_off, &Unattended, false);
    run_in(&on, &out_on, &Unattended, false);
    let vtu = spatter_io::vtk::read(&out_on.join("bodies/plate.vtu")).unwrap();
    let tau = &vtu.cell_array("wall_shear_estimate_pa").unwrap().values;
    let mut plate = TriMesh::rectangle(1.0, 1.0, 0.0, 8, 8);
    plate.map_vertices(|v| v - Vec3::new(0.5, 0.5, 0.0));
    assert_eq!(tau.len(), plate.triangles.len());
    let mu = cfg.fluid.viscosity;
    for (t, got) in tau.iter().enumerate() {
        let expect = mu * (3.0 + a * plate.centroid(t).x).abs() / h;
        assert!((got - expect).abs() <= 1e-12 * expect, "triangle {t}: {got} vs {expect}");
    }
    let vtu_off = spatter_io::vtk::read(&out_off.join("bodies/plate.vtu")).unwrap();
    assert!(vtu_off.cell_array("wall_shear_estimate_pa").unwrap().values.iter().all(|&v| v == 0.0));
    let balance = |d: &Path| std::fs::read_to_string(d.join("balance.csv")).unwrap();
    assert_ne!(balance(&out_off), balance(&out_on), "the lift changed no trajectory");
    // The same run without the key again gives the same file: the switch is the only difference.
    let again = dir.path().join("off_again");
    run_in(&cfg, &again, &Unattended, false);
    assert_eq!(balance(&out_off), balance(&again));
}
