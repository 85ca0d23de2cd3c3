use super::config::*;
use super::run;
use spatter_core::check::{Checker, Invalid};
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_core::Vec3;
use spatter_flow::liftoff::entrainment::{EntrainmentModel, Threshold};
use spatter_io::run::{RunContext, RunDir};
use std::path::Path;

/// The Bell 47 of Jasion (2013) Ch. 6 (after Leese 1964): R = 5.66 m, T = W = 8.8 kN, Ω = 35.6 rad/s,
/// z_d/R = 0.68, over Rodgers' desert sand (normal by mass, 300 ± 120 µm, 10–500 µm), a short cloud on
/// the mean flow (tip vortices off to keep the test fast).
fn bell47() -> BrownoutConfig {
    let text = r#"
[rotor]
radius_m = 5.66
thrust_n = 8800.0
omega_rad_s = 35.6
height_over_radius = 0.68
[ground]
size = { kind = "normal_by_mass", mean_m = 300e-6, std_dev_m = 120e-6, min_m = 10e-6, max_m = 500e-6, classes = 6 }
[liftoff]
points = 24
diameters_m = [10e-6, 300e-6, 500e-6]
[entrainment]
model = { model = "white" }
gust_factor = 1.3
annuli = 14
[cloud]
dt_s = 4e-3
duration_s = 0.4
parcel_mass_kg = 1e-7
[output]
interval_s = 0.1
grid_cells = [16, 16, 8]
[[output.lines_of_sight]]
name = "low"
from_m = [-12.0, 0.0, 0.1]
to_m = [12.0, 0.0, 0.1]
[[output.lines_of_sight]]
name = "high"
from_m = [-12.0, 0.0, 10.0]
to_m = [12.0, 0.0, 10.0]
"#;
    toml::from_str(text).unwrap()
}

fn keys(e: &[Invalid]) -> Vec<&str> {
    e.iter().map(|i| i.key.as_str()).collect()
}

#[test]
fn the_bell47_configuration_is_valid() {
    Checker::run(&bell47(), None).unwrap();
}

#[test]
fn bad_input_is_named_by_key() {
    let mut c = bell47();
    c.rotor.height_over_radius = -0.2;
    let e = Checker::run(&c, None).unwrap_err();
    assert_eq!(keys(&e), ["rotor.height_over_radius"]);
    assert!(e[0].message.contains("below the ground"), "{}", e[0].message);

    let mut c = bell47();
    c.rotor.thrust_n = Some(-8800.0);
    let e = Checker::run(&c, None).unwrap_err();
    assert_eq!(keys(&e), ["rotor.thrust_n"]);
    assert!(e[0].message.contains("-8800"), "{}", e[0].message);

    let mut c = bell47();
    c.rotor.thrust_coefficient = Some(0.02);
    let e = Checker::run(&c, None).unwrap_err();
    assert_eq!(keys(&e), ["rotor.thrust_n"]);
    assert!(e[0].message.contains("not both"), "{}", e[0].message);

    let mut c = bell47();
    c.ground.size = SizeConfig::Classes { diameters_m: vec![100e-6, 200e-6], mass_weights: vec![0.0, 0.0] };
    let e = Checker::run(&c, None).unwrap_err();
    assert_eq!(keys(&e), ["ground.size"]);
    assert!(e[0].message.contains("mass"), "{}", e[0].message);

    let mut c = bell47();
    c.output.lines_of_sight[1].to_m = Vec3::new(12.0, 0.0, 40.0);
    let e = Checker::run(&c, None).unwrap_err();
    assert_eq!(keys(&e), ["output.lines_of_sight[1].to_m"]);
    assert!(e[0].message.contains("outside the cloud domain"), "{}", e[0].message);
}

#[test]
fn thrust_coefficient_gives_the_thrust_of_the_british_convention() {
    // C_T = T/(½ρπR²(ΩR)²) (Jasion 2013 eq. 4.23); the Bell 47 (8.8 kN, R = 5.66 m, Ω = 35.6 rad/s) in
    // air of 1.19 kg/m³: by hand 8800/(0.5·1.19·π·5.66²·(35.6·5.66)²) = 3.6195e-3.
    let mut c = bell47();
    let rho = 1.19;
    let r = 5.66;
    let ct = 8800.0 / (0.5 * rho * std::f64::consts::PI * r * r * (35.6f64 * r).powi(2));
    c.rotor.thrust_n = None;
    c.rotor.thrust_coefficient = Some(ct);
    assert!((c.rotor.thrust(rho) - 8800.0).abs() < 1e-9);
    assert!((ct - 3.6195e-3).abs() < 1e-7, "{ct}");
}

fn csv(path: &Path) -> Vec<Vec<f64>> {
    spatter_io::csv::read_series(path).unwrap().1
}

fn scalar(s: &spatter_io::run::RunSummary, name: &str) -> f64 {
    s.scalars.iter().find(|(n, _)| n == name).map(|(_, v)| *v).unwrap()
}

#[test]
fn bell47_run_lifts_medium_grains_first_and_balances_the_cloud() {
    let cfg = bell47();
    let root = tempfile::tempdir().unwrap();
    let d = RunDir::create(root.path()).unwrap();
    let s = run(&cfg, &RunContext::new(&d, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    for (label, path) in &s.artifacts {
        assert!(path.exists(), "{label}: {}", path.display());
    }
    // Jasion (2013) Ch. 6: of 10, 300 and 500 µm grains, 300 µm lift off first (medium grains: small ones
    // held by cohesion, large ones by weight), at 0.5 < r/R < 1.5.
    assert_eq!(scalar(&s, "most_liftable_diameter_um"), 300.0);

    // The source: White's flux is non-zero exactly where the friction velocity beats the Shao–Lu
    // threshold of the class (Shao & Lu 2000 with Haehnel's constants).
    let rows = csv(&d.path("entrainment_source.csv"));
    assert_eq!(rows.len(), 14 * 6);
    let mut emitting = 0;
    for r in &rows {
        let u_t = Threshold::SHAO_LU.friction_velocity(r[2] * 1e-6, 2480.0, 1.19, 9.81);
        assert_eq!(r[4] > 0.0, r[3] > u_t, "{r:?} against u*t = {u_t}");
        emitting += usize::from(r[4] > 0.0);
    }
    assert!(emitting > 0);
    let rate: f64 = rows.iter().map(|r| r[4]).sum();
    assert!((rate - scalar(&s, "entrainment_rate_kg_s")).abs() <= 1e-12 * rate);

    // The cloud: the source emits rate × t (released + pending, to round-off), and the tracker's
    // balance entrained = airborne + redeposited + left holds bit for bit.
    let bal = csv(&d.path("cloud_balance.csv"));
    assert_eq!(bal.len(), 5, "rows at t = 0, 0.1, …, 0.4 s");
    let last = bal.last().unwrap();
    assert!((last[0] - 0.4).abs() < 1e-9);
    assert!((last[1] + last[5] - rate * 0.4).abs() < 1e-9 * rate, "{last:?}");
    assert!(last[1] > 0.0 && last[2] > 0.0, "{last:?}");
    assert_eq!(scalar(&s, "mass_balance_residual_kg"), 0.0);
    // Optical depth: the dust stays near the ground in 0.4 s; the high line sees none.
    let tau = csv(&d.path("optical_depth.csv"));
    assert_eq!(tau.len(), 5);
    assert!(tau.last().unwrap()[1] > 0.0 && tau.last().unwrap()[2] == 0.0, "{tau:?}");
    assert_eq!(tau[0][1], 0.0);
    // One concentration snapshot per row.
    let vtus = std::fs::read_dir(d.path("cloud")).unwrap().count();
    assert_eq!(vtus, 5);
}

#[test]
fn an_absurd_parcel_count_is_refused_before_tracking() {
    let mut cfg = bell47();
    cfg.cloud.parcel_mass_kg = 1e-15;
    let root = tempfile::tempdir().unwrap();
    let d = RunDir::create(root.path()).unwrap();
    let e = run(&cfg, &RunContext::new(&d, &Unattended, false)).unwrap_err();
    assert!(e.to_string().contains("cloud.parcel_mass_kg"), "{e}");
    assert!(!d.path("cloud_balance.csv").exists());
}

#[test]
fn a_stopped_and_resumed_run_writes_the_same_files() {
    let mut cfg = bell47();
    cfg.entrainment.model = EntrainmentModel::Haehnel { coefficient: 0.05 };
    let root = tempfile::tempdir().unwrap();
    let a = RunDir::create(&root.path().join("a")).unwrap();
    assert_eq!(run(&cfg, &RunContext::new(&a, &Unattended, false)).unwrap().finished, Finished::Completed);
    let b = RunDir::create(&root.path().join("b")).unwrap();
    let stop = StopAfterPolls::new(37);
    assert_eq!(run(&cfg, &RunContext::new(&b, &stop, false)).unwrap().finished, Finished::Interrupted);
    assert!(b.checkpoint_path().exists());
    assert_eq!(run(&cfg, &RunContext::new(&b, &Unattended, true)).unwrap().finished, Finished::Completed);
    assert!(!b.checkpoint_path().exists(), "a finished run removes its checkpoint");
    let mut compared = 0;
    for rel in ["cloud_balance.csv", "optical_depth.csv", "entrainment_source.csv", "cloud.pvd"] {
        assert!(std::fs::read(a.path(rel)).unwrap() == std::fs::read(b.path(rel)).unwrap(), "{rel}");
        compared += 1;
    }
    for e in std::fs::read_dir(a.path("cloud")).unwrap() {
        let name = e.unwrap().file_name();
        let rel = format!("cloud/{}", name.to_string_lossy());
        assert!(std::fs::read(a.path(&rel)).unwrap() == std::fs::read(b.path(&rel)).unwrap(), "{rel}");
        compared += 1;
    }
    assert_eq!(compared, 9);
    // Another scenario's checkpoint (another input hash) is refused.
    let c = RunDir::create(&root.path().join("c")).unwrap();
    let stop = StopAfterPolls::new(5);
    assert_eq!(run(&cfg, &RunContext::new(&c, &stop, false)).unwrap().finished, Finished::Interrupted);
    let ctx = RunContext { input_hash: 12, ..RunContext::new(&c, &Unattended, true) };
    let e = run(&cfg, &ctx).unwrap_err().to_string();
    assert!(e.contains("checkpoint.bin") && e.contains("different scenario"), "{e}");
}

/// `flow = { kind = "rans" }`: the tip vortices belong to the analytic flow and are refused; a short
/// solve on a coarse grid runs the whole chain on the solved field and writes its extra outputs, and the
/// cloud's mass balance stays exact.
#[test]
fn the_rans_flow_runs_the_chain_on_the_solved_field() {
    let mut cfg = bell47();
    cfg.flow = FlowChoice::Rans(RansConfig {
        radial_cells: 16,
        axial_cells: 12,
        max_steps: Some(30),
        ..RansConfig::default()
    });
    Checker::run(&cfg, None).unwrap();
    let mut bad = cfg.clone();
    bad.rotor.tip_vortices = true;
    let e = Checker::run(&bad, None).unwrap_err();
    assert_eq!(keys(&e), ["rotor.tip_vortices"], "{e:?}");
    cfg.cloud.duration_s = 0.04;
    let root = tempfile::tempdir().unwrap();
    let d = RunDir::create(root.path()).unwrap();
    let s = run(&cfg, &RunContext::new(&d, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    for f in ["rotor_flow.vtr", "rotor_wall_shear.csv", "liftoff_map.csv", "cloud_balance.csv"] {
        assert!(root.path().join(f).is_file(), "{f}");
    }
    assert_eq!(scalar(&s, "rans_steady"), 0.0, "30 steps are not steady");
    let vh = scalar(&s, "rans_hover_induced_velocity_m_s");
    assert!((vh - (8800.0 / (2.0 * 1.19 * std::f64::consts::PI * 5.66f64.powi(2))).sqrt()).abs() < 1e-9);
    let rows = csv(&root.path().join("rotor_wall_shear.csv"));
    assert_eq!(rows.len(), 16, "one row per ground cell");
    assert!(rows.iter().all(|r| r.iter().all(|v| v.is_finite())));
    assert_eq!(scalar(&s, "mass_balance_residual_kg"), 0.0);
}

/// The axisymmetric RANS rotor on a coarse grid (40 × 20 cells, steady after about 23 R/v_i; 7 s in the
/// test profile, against 98 s for the default 48 × 36 grid) against what is published about the Bell 47 (H-13) case of
/// Jasion (2013, Ch. 6) after Leese (1964). Leese's measured radial profile (the thesis's Fig. 6.1, "RANS
/// within 20 %") is only given as a figure without numbers, so the test checks what the text states:
/// the near-ground speed peaks at r/D ≈ 1 (r/R ≈ 2), where Leese saw the peak pick-up one diameter
/// from the hub — here the radial speed 0.1 m above the ground (Leese's measurement height) must peak
/// within 1.2 ≤ r/R ≤ 2.6; and the induced velocity through the disk must lie in the band of the
/// ground-effect momentum theories at z_d/R = 0.68 (Hayden 1976: 0.757, Cheeseman & Bennett 1955:
/// 0.865 of √(T/(2ρA)) = 6.06 m/s), widened by 5 % for the coarse grid.
#[test]
fn rans_ground_speed_peaks_one_diameter_from_the_hub() {
    let cfg = bell47();
    let rc = RansConfig {
        radial_cells: 40,
        radial_growth: 1.075,
        axial_cells: 20,
        axial_growth: 1.2,
        max_time_over_r_v: 30.0,
        ..RansConfig::default()
    };
    let solved = super::rans::solve(&cfg, &rc, &|| false).unwrap().unwrap();
    let flow = &solved.flow;
    let r0 = cfg.rotor.radius_m;
    let profile: Vec<(f64, f64)> = (1..=120)
        .map(|i| {
            let r = i as f64 * 0.05 * r0;
            (r / r0, flow.velocity_at([r, 0.1, 0.5]).map_or(0.0, |u| u[0]))
        })
        .collect();
    let (at, peak) = profile.iter().copied().fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
    // Measured: 14.4 m/s at r/R = 1.45 on this grid, 14.5 m/s at r/R = 1.80 on the default grid.
    assert!(solved.steady, "not steady after {} s", flow.state.t);
    assert!(
        (1.2..=2.6).contains(&at),
        "near-ground radial speed peaks at r/R = {at} ({peak} m/s): {profile:?}"
    );
    // Induced velocity: area-weighted mean downwash through the disk plane.
    let ax = &flow.grid.axes[0];
    let (mut q, mut a) = (0.0, 0.0);
    for i in (0..ax.n()).take_while(|&i| ax.centre(i) < r0) {
        let (r, dr) = (ax.centre(i), ax.width(i));
        let w = flow.velocity_at([r, solved.disk.axial_m, 0.5]).unwrap()[1];
        q -= w * r * dr;
        a += r * dr;
    }
    // Measured: 0.766 on this grid, 0.794 on the default grid (coarser radial grids give up to 1.03:
    // the disk's tip taper needs radial resolution).
    let ratio = q / a / solved.v_hover;
    assert!((0.757 * 0.95..=0.865 * 1.05).contains(&ratio), "v_i / v_hover = {ratio}");
    eprintln!(
        "RANS (40 × 20): peak radial speed 0.1 m above the ground {peak:.2} m/s at r/R = {at:.2}; v_i/v_h = {ratio:.3}; t = {:.1} s, steady {}",
        flow.state.t, solved.steady
    );
}

/// Writes the analytic downwash of a model rotor (Jasion 2013 Table 5.2: R = 0.5 m, weight 0.6 g N,
/// z_d/R = 0.68, air 1.19 kg/m³) on a uniform grid of 5 cm over |x|, |y| ≤ 2 R, 0 ≤ z ≤ R: a stand-in for
/// a model-scale CFD field.
fn write_model_rotor_field(path: &Path) -> spatter_flow::field::rotor::RotorDownwash {
    use spatter_flow::field::rotor::RotorDownwash;
    let mut model = RotorDownwash::new(Vec3::new(0.0, 0.0, 0.34), 0.5, 0.6 * 9.81, 47.1);
    model.air_density_kg_m3 = 1.19;
    let h = 0.05;
    let dims = [40, 40, 10];
    let origin = Vec3::new(-1.0, -1.0, 0.0);
    let mut u = Vec::new();
    for k in 0..=dims[2] {
        for j in 0..=dims[1] {
            for i in 0..=dims[0] {
                u.push(model.velocity(origin + h * Vec3::new(i as f64, j as f64, k as f64), 0.0));
            }
        }
    }
    spatter_io::vtu::Vtu::hexahedral_grid(origin, Vec3::splat(h), dims)
        .point_vector("U", &u)
        .write(path)
        .unwrap();
    model
}

/// `flow = { kind = "imported", scale = … }`: a model-scale field carried to the Bell 47 by R and v_ind.
/// The analytic mean downwash is similar in R and v_ind (it has no other scale), so at the grid's nodes
/// (where the interpolation is exact) the scaled imported field must equal the Bell 47's analytic
/// downwash to rounding; and the whole chain runs on it.
#[test]
fn a_model_scale_field_scaled_by_r_and_v_ind_is_the_full_scale_flow() {
    use spatter_flow::field::{AnalyticField, AnalyticSet, FlowField};
    let root = tempfile::tempdir().unwrap();
    let file = root.path().join("model_rotor.vtu");
    let model = write_model_rotor_field(&file);
    let mut cfg = bell47();
    cfg.flow = FlowChoice::Imported(ImportedFlowConfig {
        vtk: Some(file.clone()),
        series: None,
        interpolation: Default::default(),
        arrays: Default::default(),
        length_scale: 1.0,
        period_s: None,
        scale: Some(ModelScale {
            model_radius_m: 0.5,
            model_v_ind_m_s: None,
            model_thrust_n: Some(0.6 * 9.81),
        }),
    });
    Checker::run(&cfg, None).unwrap();
    let FlowChoice::Imported(ic) = &cfg.flow else { unreachable!() };
    let loaded = super::imported::load(&cfg, ic).unwrap();
    let full = cfg.rotor.downwash(&cfg.air);
    assert!((loaded.field.scaling.length - 5.66 / 0.5).abs() < 1e-12);
    assert!(
        (loaded.field.scaling.velocity - full.induced_velocity() / model.induced_velocity()).abs() < 1e-12
    );
    let analytic = AnalyticSet { parts: vec![AnalyticField::Rotor(full)], turbulence: None };
    let mut compared = 0;
    for (i, j, k) in [(30, 20, 1), (25, 20, 2), (20, 20, 5), (36, 24, 1), (22, 27, 8), (33, 11, 3)] {
        let node = Vec3::new(-1.0 + 0.05 * i as f64, -1.0 + 0.05 * j as f64, 0.05 * k as f64);
        let x = node * loaded.field.scaling.length;
        let a = analytic.sample(x, 0.0, &mut u32::MAX.clone(), false).unwrap().u;
        let b = loaded.field.sample(x, 0.0, &mut u32::MAX.clone(), false).unwrap().u;
        assert!((a - b).length() <= 1e-9 * a.length().max(1.0), "{x:?}: analytic {a:?}, scaled {b:?}");
        compared += 1;
    }
    assert_eq!(compared, 6);
    // Unscaled (a full-size field given as it is), the same file is the model's flow.
    let mut plain = ic.clone();
    plain.scale = None;
    let unscaled = super::imported::load(&cfg, &plain).unwrap();
    assert_eq!(unscaled.field.scaling, spatter_flow::field::scaled::RotorScaling::IDENTITY);

    cfg.cloud.duration_s = 0.04;
    let d = RunDir::create(&root.path().join("run")).unwrap();
    let s = run(&cfg, &RunContext::new(&d, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    for f in ["liftoff_map.csv", "shields_exceedance.csv", "entrainment_source.csv", "cloud_balance.csv"] {
        assert!(d.path(f).is_file(), "{f}");
    }
    assert!((scalar(&s, "flow_length_scale") - 11.32).abs() < 1e-12);
    assert_eq!(scalar(&s, "mass_balance_residual_kg"), 0.0);
    eprintln!("imported Bell 47 from the model: max u* {}", scalar(&s, "max_friction_velocity_m_s"));
}

#[test]
fn bad_model_scales_are_named_by_key() {
    let mut cfg = bell47();
    let ic = ImportedFlowConfig {
        vtk: Some("no_such_field.vtu".into()),
        series: None,
        interpolation: Default::default(),
        arrays: Default::default(),
        length_scale: 1.0,
        period_s: None,
        scale: Some(ModelScale { model_radius_m: -0.5, model_v_ind_m_s: Some(0.0), model_thrust_n: None }),
    };
    cfg.flow = FlowChoice::Imported(ic.clone());
    let e = Checker::run(&cfg, None).unwrap_err();
    assert_eq!(keys(&e), ["flow.vtk", "flow.scale.model_radius_m", "flow.scale.model_v_ind_m_s"], "{e:?}");
    assert!(e[1].message.contains("-0.5") && e[2].message.contains("positive"), "{e:?}");
    let mut both = ic.clone();
    both.scale =
        Some(ModelScale { model_radius_m: 0.5, model_v_ind_m_s: Some(1.8), model_thrust_n: Some(5.9) });
    cfg.flow = FlowChoice::Imported(both);
    let e = Checker::run(&cfg, None).unwrap_err();
    assert_eq!(keys(&e), ["flow.vtk", "flow.scale.model_v_ind_m_s"], "{e:?}");
    let mut thrust = ic;
    thrust.scale =
        Some(ModelScale { model_radius_m: 0.5, model_v_ind_m_s: None, model_thrust_n: Some(-1.0) });
    cfg.flow = FlowChoice::Imported(thrust);
    cfg.rotor.tip_vortices = true;
    let e = Checker::run(&cfg, None).unwrap_err();
    assert_eq!(keys(&e), ["flow.vtk", "flow.scale.model_thrust_n", "rotor.tip_vortices"], "{e:?}");
}

/// A patch of two layers of 300 µm grains, 7.4 × 5 grains wide, settled for 2 ms and run for 7 ms.
fn small_patch() -> DemBedConfig {
    DemBedConfig {
        grain_diameter_m: Some(300e-6),
        patch_size_m: [7.4 * 300e-6, 5.0 * 300e-6],
        layers: 2,
        settle_s: Some(2e-3),
        duration_s: 0.007,
        ..DemBedConfig::default()
    }
}

#[test]
fn the_dem_bed_feels_an_unsteady_flow_even_with_one_source_phase() {
    // The source's phase count (how many times per period its flux is averaged) must not make the bed's
    // flow steady: with tip vortices the friction velocity over the patch changes within 7 ms (a tenth of
    // the shedding period 2π/(2 · 35.6 rad/s) = 88 ms).
    let mut cfg = bell47();
    cfg.rotor.tip_vortices = true;
    cfg.entrainment.phases = 1;
    cfg.entrainment.source = EntrainmentSource::DemBed;
    cfg.dem_bed = Some(small_patch());
    cfg.cloud.dt_s = 2e-3;
    cfg.cloud.duration_s = 0.01;
    cfg.output.interval_s = 0.004;
    Checker::run(&cfg, None).unwrap();
    let root = tempfile::tempdir().unwrap();
    let d = RunDir::create(root.path()).unwrap();
    run(&cfg, &RunContext::new(&d, &Unattended, false)).unwrap();
    let rows = csv(&d.path("dem_bed_entrainment.csv"));
    let u: Vec<f64> = rows.iter().map(|r| r[5]).collect();
    assert!(u.iter().all(|&x| x > 0.0), "{u:?}");
    let spread =
        u.iter().cloned().fold(f64::NEG_INFINITY, f64::max) - u.iter().cloned().fold(f64::INFINITY, f64::min);
    // A steady table gives a spread of exactly 0; any sampling of the vortex-driven flow gives far more
    // than 10⁻⁴ of u* (a vortex passage changes the near-ground speed by tens of per cent).
    assert!(spread > 1e-4 * u[0], "the friction velocity over the patch must follow the vortices: {u:?}");
}

/// `dem_bed_entrainment.csv`: the first row already shows the flow over the patch (exposed grains and
/// friction velocity at the start, not zeros), the rows stop when the patch's time ends (one row at its
/// end, between two output times), and the times increase.
#[test]
fn the_dem_bed_table_starts_with_the_flow_and_ends_with_the_patch() {
    let mut cfg = bell47();
    cfg.entrainment.source = EntrainmentSource::DemBed;
    cfg.dem_bed = Some(small_patch());
    cfg.cloud.dt_s = 2e-3;
    cfg.cloud.duration_s = 0.02;
    cfg.output.interval_s = 0.004;
    Checker::run(&cfg, None).unwrap();
    let root = tempfile::tempdir().unwrap();
    let d = RunDir::create(root.path()).unwrap();
    let s = run(&cfg, &RunContext::new(&d, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    let rows = csv(&d.path("dem_bed_entrainment.csv"));
    let u_star = scalar(&s, "dem_bed_friction_velocity_m_s");
    assert!(rows[0][0] == 0.0 && rows[0][4] > 0.0 && rows[0][5] > 0.0, "first row {:?}", rows[0]);
    assert!((rows[0][5] - u_star).abs() < 1e-12, "a steady flow: the same u* throughout");
    assert!(rows.windows(2).all(|w| w[1][0] > w[0][0]), "times increase: {rows:?}");
    let last = rows.last().unwrap();
    assert!((last[0] - 0.007).abs() < 1e-6, "the last row is the patch's end: {rows:?}");
    // t = 0, the outputs at 0.004 s (patch running) and the patch's end at 0.007 s.
    assert_eq!(rows.len(), 3, "{rows:?}");
}
