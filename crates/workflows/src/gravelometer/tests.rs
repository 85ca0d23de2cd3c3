//! Tests of the gravelometer workflow: presets against the published set-ups, refusals of bad input, the
//! launch formula, a ballistic flight against Galileo's parabola, the fate of every stone, and the
//! directions of the published parametric study on reduced cases.

use super::config::{preset, GravelometerConfig, GravelometerInput, Standard};
use super::scene::{empirical_launch_speed, feeder_vertical_speed, plan};
use super::{results, run, GravelometerError};
use spatter_core::check::Checker;
use spatter_core::control::Unattended;
use spatter_io::run::{RunContext, RunDir, RunSummary};
use std::path::Path;

fn load(text: &str) -> GravelometerConfig {
    let input: GravelometerInput = toml::from_str(text).unwrap();
    GravelometerConfig::from(input)
}

fn problems(text: &str) -> String {
    let cfg = load(text);
    match Checker::run(&cfg, None) {
        Ok(()) => String::new(),
        Err(v) => v.iter().map(|i| format!("{}: {}\n", i.key, i.message)).collect(),
    }
}

fn scalar(s: &RunSummary, name: &str) -> f64 {
    s.scalars.iter().find(|(n, _)| n == name).map_or(f64::NAN, |v| v.1)
}

#[test]
fn presets_carry_the_published_set_ups_and_name_what_is_assumed() {
    // Qian et al. (2022), CMES: DIN 55996-1 — 30 mm pipe, 500 g in 10 s, 100 × 200 mm panel at 54°, five
    // strips, 1 s simulated; SAE J400 — 52 mm pipe, 31.1 m/s of air at 0.48 MPa, 100 × 300 mm upright
    // panel, six strips, 2 s simulated; K_h = 59.6; 30 stones in the statistics; 40 impacts.
    let din = load("standard = \"din_55996_1\"").input;
    assert_eq!(din.pipe.diameter_m, Some(0.03));
    assert_eq!(
        (din.panel.width_m, din.panel.length_m, din.panel.angle_deg),
        (Some(0.1), Some(0.2), Some(54.0))
    );
    assert_eq!(din.panel.strips, Some(5));
    assert_eq!((din.stones.charge_kg, din.stones.feed_time_s), (Some(0.5), Some(10.0)));
    assert_eq!(din.duration_s, Some(1.0));
    assert_eq!(din.launch.k_h, Some(59.6));
    assert_eq!((din.output.first_n, din.output.cutoff_impacts), (Some(30), Some(40)));
    let sae = load("standard = \"sae_j400\"").input;
    assert_eq!(sae.pipe.diameter_m, Some(0.052));
    assert_eq!(sae.pipe.air_velocity_m_s, Some(31.1));
    assert_eq!(
        (sae.panel.width_m, sae.panel.length_m, sae.panel.angle_deg),
        (Some(0.1), Some(0.3), Some(90.0))
    );
    assert_eq!(sae.panel.strips, Some(6));
    assert_eq!(sae.stones.feed_time_s, Some(7.0));
    assert_eq!(sae.duration_s, Some(2.0));
    assert_eq!(sae.stones.templates.as_ref().map(|t| t.len()), Some(4));
    // Air flow rate of the SAE pipe: 31.1 m/s × π (0.026 m)² = 0.06605 m³/s.
    assert!((sae.launch.air_flow_m3_s.unwrap() - 0.066_046).abs() < 1e-5);
    // Lost values are marked; a value the file sets is not.
    for key in ["pipe.length_m", "panel.distance_m", "stones.youngs_modulus_pa", "wear.k_s2_m2"] {
        assert!(sae.assumed.iter().any(|k| k == key), "{key} not marked: {:?}", sae.assumed);
    }
    assert!(!sae.assumed.iter().any(|k| k == "panel.angle_deg"));
    let set = load("standard = \"sae_j400\"\n[pipe]\nlength_m = 0.4").input;
    assert!(!set.assumed.iter().any(|k| k == "pipe.length_m"));
    assert_eq!(set.pipe.length_m, Some(0.4));
    // Every preset value is filled (and round-trips through the resolved TOML).
    let text = toml::to_string(&GravelometerConfig { input: din.clone() }).unwrap();
    let again: GravelometerConfig = toml::from_str(&text).unwrap();
    assert_eq!(again.input.panel, din.panel);
    assert!(text.contains("assumed"));
    let (_, assumed) = preset(Standard::Din55996_1);
    assert!(assumed.contains(&"pipe.air_velocity_m_s"));
}

#[test]
fn bad_values_are_refused_with_the_key_and_the_expected_form() {
    let p = problems("standard = \"din_55996_1\"\n[panel]\nangle_deg = 0.0");
    assert!(p.contains("panel.angle_deg") && p.contains("outside (0°, 90°]"), "{p}");
    let p = problems("standard = \"din_55996_1\"\n[panel]\nangle_deg = 95.0");
    assert!(p.contains("panel.angle_deg"), "{p}");
    assert!(problems("standard = \"din_55996_1\"\n[panel]\nangle_deg = 90.0").is_empty());
    let p = problems("standard = \"sae_j400\"\n[panel]\ntriangle_size_m = 0.1\nstrips = 8");
    assert!(p.contains("panel.strips") && p.contains("more than the 3 rows"), "{p}");
    assert!(problems("standard = \"sae_j400\"\nair = \"coupled\"").is_empty());
    let coupled =
        |keys: &str| problems(&format!("standard = \"sae_j400\"\nair = \"coupled\"\n[coupled_air]\n{keys}"));
    let p = coupled("cell_size_m = 0.03");
    assert!(p.contains("coupled_air.cell_size_m") && p.contains("fewer than two cells"), "{p}");
    assert!(coupled("turbulence = \"k_epsilon\"").is_empty());
    assert!(coupled("inlet_intensity = 0.0").contains("coupled_air.inlet_intensity"));
    assert!(coupled("dem_steps_per_fluid_step = 0").contains("coupled_air.dem_steps_per_fluid_step"));
    assert!(problems("standard = \"sae_j400\"\nair = \"prescribed\"").is_empty());
    let air = |keys: &str| {
        problems(&format!("standard = \"din_55996_1\"\nair = \"prescribed\"\n[air_field]\n{keys}"))
    };
    let p = air("profile_exponent = 0.5");
    assert!(p.contains("air_field.profile_exponent") && p.contains("between 1 and 20"), "{p}");
    let p = air("ramp_s = -0.1");
    assert!(p.contains("air_field.ramp_s"), "{p}");
    let p = air("viscosity_pa_s = 0.0");
    assert!(p.contains("air_field.viscosity_pa_s"), "{p}");
    let p = air("k_correction = { kind = \"transverse\", k = 0.0 }");
    assert!(p.contains("air_field.k_correction.k"), "{p}");
    // Starting from rest needs air to move the stones.
    assert!(air("[launch]\nspeed_m_s = 0.0").is_empty());
    let p = problems("standard = \"din_55996_1\"\n[launch]\nspeed_m_s = 0.0");
    assert!(p.contains("launch.speed_m_s"), "{p}");
    let p = problems("standard = \"din_55996_1\"\n[contact]\nstone_wall_restitution = 1.5");
    assert!(p.contains("contact.stone_wall_restitution"), "{p}");
}

#[test]
fn a_stone_wider_than_the_pipe_and_a_feed_the_pipe_cannot_pass_are_refused() {
    let cfg =
        load("standard = \"din_55996_1\"\n[pipe]\ndiameter_m = 0.005\n[stones]\nmember_diameter_m = 2e-3");
    match plan(&cfg) {
        Err(GravelometerError::Config { key, message }) => {
            assert_eq!(key, "stones");
            assert!(message.contains("pipe.diameter_m = 0.005"), "{message}");
        }
        other => panic!("{other:?}"),
    }
    let cfg = load("standard = \"din_55996_1\"\n[stones]\nmember_diameter_m = 2e-3\ncharge_kg = 500.0\nfeed_time_s = 1.0");
    match plan(&cfg) {
        Err(GravelometerError::Config { key, message }) => {
            assert_eq!(key, "stones.charge_kg");
            assert!(message.contains("more than the pipe passes"), "{message}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_launch_velocity_follows_the_empirical_formula_and_the_feeder_fall() {
    // v_h = K_h Q_f / (ρ^{1/3} D): 59.6 × 0.0198 / (7400^{1/3} × 4.5e-3) = 13.45 m/s (hand calculation).
    let v = empirical_launch_speed(59.6, 0.0198, 7400.0, 4.5e-3);
    assert!((v - 59.6 * 0.0198 / (7400f64.cbrt() * 4.5e-3)).abs() < 1e-12);
    assert!((v - 13.45).abs() < 0.01, "{v}");
    // Proportional to the flow, falling with density and diameter (as the study found).
    assert!(empirical_launch_speed(59.6, 0.04, 7400.0, 4.5e-3) > v);
    assert!(empirical_launch_speed(59.6, 0.0198, 2650.0, 4.5e-3) > v);
    assert!(empirical_launch_speed(59.6, 0.0198, 7400.0, 9e-3) < v);
    // Free fall of 0.2 m: √(2 g h) = 1.981 m/s, times e = 0.5, downwards.
    assert!((feeder_vertical_speed(0.2, 0.5, 9.81) + 0.5 * (2.0f64 * 9.81 * 0.2).sqrt()).abs() < 1e-12);
    // The DIN preset: the mix's volume-equivalent diameter is that of the cut ball, ρ = 7400 kg/m³.
    let cfg = load("standard = \"din_55996_1\"\n[stones]\nmember_diameter_m = 1.5e-3");
    let p = plan(&cfg).unwrap();
    // Cut ball of radius r with the lower third of the diameter removed: V = 80π r³/81, so
    // D = (480/81)^{1/3} r = 4.5238 mm for r = 2.5 mm.
    assert!((p.mean_diameter - (480.0f64 / 81.0).cbrt() * 2.5e-3).abs() < 1e-9, "{}", p.mean_diameter);
    let q = 28.0 * std::f64::consts::PI * 0.015 * 0.015;
    assert!((p.launch.x - empirical_launch_speed(59.6, q, 7400.0, p.mean_diameter)).abs() < 1e-9);
    assert!((p.launch.z - feeder_vertical_speed(0.2, 0.5, 9.81)).abs() < 1e-12);
}

/// A reduced gravelometer: one-sphere "stones" of 5 mm (a single member each), soft enough for a large
/// time step, a 0.1 m pipe and the panel 0.1 m further on; `top`, `stones` and `launch` add keys to the
/// top level and to `[stones]` and `[launch]`.
fn reduced(top: &str, stones: &str, launch: &str) -> String {
    format!(
        r#"standard = "din_55996_1"
duration_s = 0.03
{top}
[pipe]
length_m = 0.1
[panel]
distance_m = 0.1
triangle_size_m = 0.01
[stones]
youngs_modulus_pa = 1e9
{stones}
[stones.templates.ball]
shape = {{ type = "ball", radius_m = 2.5e-3 }}
packing = {{ type = "count", sphere_count = 1 }}
[launch]
fall_height_m = 0.0
{launch}
[output]
particles_vtu = false
output_interval_s = 0.001
"#
    )
}

fn run_in(dir: &Path, text: &str) -> RunSummary {
    let cfg = load(text);
    Checker::run(&cfg, None).unwrap();
    let d = RunDir::create(dir).unwrap();
    run(&cfg, &RunContext::new(&d, &Unattended, false)).unwrap()
}

fn csv(path: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().split(',').map(str::to_owned).collect();
    (head, lines.map(|l| l.split(',').map(str::to_owned).collect()).collect())
}

#[test]
fn a_stone_flies_galileos_parabola_onto_the_panel() {
    let tmp = tempfile::tempdir().unwrap();
    let s = run_in(tmp.path(), &reduced("", "count = 1\nfeed_time_s = 0.001", "speed_m_s = 12.0"));
    // The stone's state inside the pipe from trajectories.csv.
    let (head, rows) = csv(&tmp.path().join("trajectories.csv"));
    let col = |n: &str| head.iter().position(|h| h == n).unwrap();
    let row0: Vec<f64> = rows[0].iter().map(|c| c.parse().unwrap()).collect();
    let (t0, x0, z0) = (row0[col("t_s")], row0[col("x_m")], row0[col("z_m")]);
    let (vx, vz) = (row0[col("vx_m_s")], row0[col("vz_m_s")]);
    assert!((vx - 12.0).abs() < 1e-9, "{vx}");
    // Galileo: x = x0 + vx τ, z = z0 + vz τ − g τ²/2; the sphere (radius r) touches the panel plane when
    // its centre is r in front of it: (p − c)·n = r, n = (−sin 54°, 0, cos 54°), c = (0.1, 0, 0).
    // The stone's one member (the largest sphere the fill finds inside the 2.5 mm ball).
    let cfg = load(&reduced("", "count = 1\nfeed_time_s = 0.001", "speed_m_s = 12.0"));
    let r = plan(&cfg).unwrap().stones[0].template.spheres[0].1;
    assert!((r - 2.5e-3).abs() < 0.1e-3, "{r}");
    let g = 9.81;
    let th = 54f64.to_radians();
    let (nx, nz) = (-th.sin(), th.cos());
    let f = |tau: f64| (x0 + vx * tau - 0.1) * nx + (z0 + vz * tau - 0.5 * g * tau * tau) * nz - r;
    let (mut a, mut b) = (0.0, 0.1);
    for _ in 0..200 {
        let m = 0.5 * (a + b);
        if f(m) > 0.0 {
            a = m;
        } else {
            b = m;
        }
    }
    let tau = 0.5 * (a + b);
    let (head, rows) = csv(&tmp.path().join("impacts.csv"));
    let col = |n: &str| head.iter().position(|h| h == n).unwrap();
    assert_eq!(rows.len(), 1, "{rows:?}");
    assert_eq!(rows[0][col("wall")], "panel");
    let get = |n: &str| rows[0][col(n)].parse::<f64>().unwrap();
    let dt = scalar(&s, "dt_s");
    // Impact time within two steps (contact is detected at the end of the step that closes the gap).
    assert!((get("t_s") - (t0 + tau)).abs() < 2.0 * dt, "t {} vs {}", get("t_s"), t0 + tau);
    // Impact speed: |v| = √(vx² + (vz − g τ)²) within 0.1 % (the contact sees the half-step velocity).
    let vz_hit = vz - g * tau;
    let speed = vx.hypot(vz_hit);
    assert!((get("speed_m_s") - speed).abs() < 1e-3 * speed, "{} vs {speed}", get("speed_m_s"));
    // Impact angle α against the panel's up direction (cos 54°, 0, sin 54°): acos(v·u/|v|), 0.1°.
    let alpha = ((vx * th.cos() + vz_hit * th.sin()) / speed).acos().to_degrees();
    assert!((get("angle_deg") - alpha).abs() < 0.1, "{} vs {alpha}", get("angle_deg"));
    // Height of the impact on the panel from its bottom edge (0.1 m below the centre along the edge):
    // the contact point is r behind the centre along −n; the triangle centroid is within one triangle.
    let (xc, zc) = (x0 + vx * tau - r * nx, z0 + vz * tau - 0.5 * g * tau * tau - r * nz);
    let s_hit = (xc - 0.1) * th.cos() + zc * th.sin() + 0.1;
    assert!((get("height_on_panel_m") - s_hit).abs() < 0.01, "{} vs {s_hit}", get("height_on_panel_m"));
    assert_eq!(get("pipe_collisions"), 0.0);
    // The eroded mass is Finnie's: an impact at 54° erodes (f(54°) = 0.115 > 0).
    assert!(scalar(&s, "panel_eroded_mass_kg") > 0.0);
}

#[test]
fn every_injected_stone_is_accounted_for() {
    let tmp = tempfile::tempdir().unwrap();
    let text = reduced("", "count = 8\nfeed_time_s = 0.004", "");
    let s = run_in(tmp.path(), &text.replace("duration_s = 0.03", "duration_s = 0.05"));
    let injected = scalar(&s, "stones_injected");
    assert_eq!(injected, 8.0);
    let sum: f64 = ["stones_on_panel", "stones_in_box", "stones_in_pipe", "stones_out_of_domain"]
        .iter()
        .map(|k| scalar(&s, k))
        .sum();
    assert_eq!(sum, injected, "{:?}", s.scalars);
    assert!(!s.headline.iter().any(|l| l.contains("WARNING")), "{:?}", s.headline);
    let (_, rows) = csv(&tmp.path().join("stones.csv"));
    assert_eq!(rows[0], ["injected", "8"]);
    // The damage map is recorded for a study's gallery: the panel's VTU, its per-area array, seen from
    // the pipe (against the panel's front normal).
    let map = s.maps.iter().find(|m| m.label == "panel damage").expect("panel damage map recorded");
    assert!(map.vtu.ends_with("panel_damage.vtu") && map.array == "eroded_mass_per_area_kg_m2");
    let th = 54f64.to_radians();
    assert!((map.view_dir[0] - th.sin()).abs() < 1e-12 && (map.view_dir[2] + th.cos()).abs() < 1e-12);
    // The strip shares add up to 100 %.
    let (_, strips) = csv(&tmp.path().join("strips.csv"));
    assert_eq!(strips.len(), 5);
    let total: f64 = strips.iter().map(|r| r[4].parse::<f64>().unwrap()).sum();
    assert!((total - 100.0).abs() < 1e-9, "{total}");
    // ... and are recorded for a study: the curve strip → share from strips.csv (overlaid across cases)
    // and the table of the five share scalars (one column per case).
    let curve =
        s.curves.iter().find(|c| c.label == results::STRIP_SHARE_CURVE).expect("strip curve recorded");
    assert!(
        curve.csv.ends_with("strips.csv") && curve.x_column == "strip" && curve.y_column == "share_percent"
    );
    let table = s.scalar_tables.iter().find(|t| t.label == results::STRIP_SHARE_TABLE).expect("strip table");
    let named: Vec<&str> = table.rows.iter().map(|(_, n)| n.as_str()).collect();
    assert_eq!(named, (1..=5).map(|k| format!("strip_{k}_share_percent")).collect::<Vec<_>>());
    for (_, n) in &table.rows {
        assert!(s.scalars.iter().any(|(k, _)| k == n), "{n} reported");
    }
    for f in [
        "panel_damage.png",
        "panel_damage.vtu",
        "strips.png",
        "impact_speed_histogram.png",
        "impact_statistics.csv",
    ] {
        assert!(tmp.path().join(f).is_file(), "{f}");
    }
}

/// Directions of the parametric study of Qian et al. (2022), Figs. 22–25, on reduced cases (eight
/// one-sphere stones, same seed, so that the cases differ only in the varied parameter):
/// * the eroded mass grows as the impingement angle goes from 90° (upright panel, M0) over 72° (M1, the
///   value assumed for the study's lost one) to 54° (M2): EM(M0) < EM(M1) < EM(M2) — Finnie's f(90°) = 0,
///   f(72°) = 0.032, f(54°) = 0.115;
/// * the spread of impact heights grows M0 → M1 → M2: the standard deviation of the impact height along
///   the panel's long edge (the beam's height spread lands on a length 1/sin θ longer: 1.05 at 72°,
///   1.24 at 54°; the reduced case grows 1.04 and 3.7 times, so 1/sin θ alone does not explain 54°);
/// * faster stones erode more (M3 < M0 < M4).
#[test]
fn eroded_mass_and_spread_move_as_the_published_parametric_study_found() {
    let tmp = tempfile::tempdir().unwrap();
    let case = |name: &str, angle: f64, speed: f64| {
        let text = reduced("", "count = 8\nfeed_time_s = 0.004", &format!("speed_m_s = {speed}"))
            .replace("distance_m = 0.1", &format!("distance_m = 0.1\nangle_deg = {angle}"));
        let s = run_in(&tmp.path().join(name), &text.replace("duration_s = 0.03", "duration_s = 0.04"));
        (scalar(&s, "panel_eroded_mass_kg"), scalar(&s, "height_on_panel_sd_m"))
    };
    let (em_90, spread_90) = case("m0", 90.0, 12.0);
    let (em_72, spread_72) = case("m1", 72.0, 12.0);
    let (em_54, spread_54) = case("m2", 54.0, 12.0);
    let (em_slow, _) = case("m3", 54.0, 6.0);
    eprintln!(
        "eroded mass 90°/72°/54° at 12 m/s: {em_90:e} {em_72:e} {em_54:e} kg, at 54° and 6 m/s {em_slow:e} kg; \
         impact-height spread {spread_90} {spread_72} {spread_54} m"
    );
    // "As the impingement angle decreases from 90° to 54°, the eroded mass increases significantly":
    // at least twice, and M1 between.
    assert!(em_54 > 2.0 * em_90, "eroded mass at 54° {em_54:e} vs 90° {em_90:e}");
    assert!(em_90 < em_72 && em_72 < em_54, "eroded mass 90°/72°/54°: {em_90:e} {em_72:e} {em_54:e}");
    assert!(
        spread_90 < spread_72 && spread_72 < spread_54,
        "impact-height spread 90°/72°/54°: {spread_90} {spread_72} {spread_54} m"
    );
    assert!(em_54 > em_slow, "eroded mass at 12 m/s {em_54:e} vs 6 m/s {em_slow:e}");
}

/// A standard's preset set-up (pipe, panel, distance, angle, strips, feeder fall) with eight 5 mm
/// one-sphere stones, soft, launched at `speed` m/s (`None`: by the launch formula), without air.
fn preset_balls(standard: &str, speed: Option<f64>) -> String {
    let launch = speed.map_or(String::new(), |v| format!("speed_m_s = {v}"));
    format!(
        r#"standard = "{standard}"
air = "none"
duration_s = 0.06
[stones]
shape = "sphere"
sphere_diameter_m = 0.005
member_diameter_m = 0.005
youngs_modulus_pa = 1e9
count = 8
feed_time_s = 0.004
[launch]
{launch}
[output]
particles_vtu = false
output_interval_s = 0.002
"#
    )
}

/// Strip shares of a run, strip 1 (top) first.
fn shares(s: &RunSummary, strips: usize) -> Vec<f64> {
    (1..=strips).map(|k| scalar(s, &format!("strip_{k}_share_percent"))).collect()
}

/// Where the damage lands on the preset panels, as Qian et al. (2022) found it (Figs. 15 and 21):
/// * DIN 55996-1 (five strips, 54°): the middle part wears most — strip 3 takes the largest share;
/// * SAE J400 (six strips, upright): the damage concentrates in the lower middle — strip 4 or 5 takes
///   the largest share and the two together more than half;
/// * SAE J400: more stones strike the upright panel moving down (α > 90°) than up, "under the influence
///   of gravity" (Table 6). Without air this follows from the launch — every stone leaves the feeder
///   moving down and gravity adds to it — unless bounces off the pipe floor send stones up; it guards
///   the launch direction and the angle's sign convention (the coupled SAE runs give 27–28 of 30,
///   docs/gravelometer.md).
///
/// The pipe is aimed at the panel's centre and the stones reach it a little low (the feeder's fall
/// carries them towards the pipe floor), so these follow from the preset geometry and the launch;
/// eight one-sphere stones without air, DIN at the launch formula's speed for them (11.7 m/s; the
/// grit's is 13.4 m/s), SAE at the formula's 26 m/s for its gravel (the ball's own would be far
/// faster). The coupled SAE and DIN examples wear the same strips most (docs/gravelometer.md).
#[test]
fn the_preset_panels_wear_where_the_published_study_found_it() {
    let tmp = tempfile::tempdir().unwrap();
    let din = run_in(&tmp.path().join("din"), &preset_balls("din_55996_1", None));
    let sae = run_in(&tmp.path().join("sae"), &preset_balls("sae_j400", Some(26.0)));
    let (d, s) = (shares(&din, 5), shares(&sae, 6));
    let down = scalar(&sae, "impact_angle_above_90_share");
    eprintln!("DIN strip shares {d:?} %; SAE strip shares {s:?} %; SAE share of α > 90°: {down}");
    let largest = |v: &[f64]| (0..v.len()).max_by(|&a, &b| v[a].total_cmp(&v[b])).unwrap() + 1;
    assert!(d.iter().chain(&s).all(|x| x.is_finite()), "both panels are eroded");
    assert_eq!(largest(&d), 3, "DIN: the middle strip wears most, shares {d:?}");
    assert!([4, 5].contains(&largest(&s)), "SAE: the lower middle wears most, shares {s:?}");
    assert!(s[3] + s[4] > 50.0, "SAE: strips 4 and 5 take most of the damage, shares {s:?}");
    assert!(down > 0.5, "SAE: most stones strike moving down, share with α > 90° {down}");
}

/// The study's initial-velocity series (M3 < M0 < M4, Figs. 22–23) on the SAE preset: the eroded mass
/// grows with the stones' speed, as the study found. The impacts move *up* the panel as the speed
/// rises — the study saw the impacted area move down and put it down to fewer collisions with the pipe
/// wall. Here every stone leaves the feeder with the same downward speed (e √(2 g h) = 0.99 m/s,
/// docs/gravelometer.md "How it runs", 4), and over the fixed flight from the pipe inlet to the panel it descends by that speed times
/// a flight time ∝ 1/v, plus gravity's ½ g t²: faster stones strike higher. Stated as found, with the
/// cause; eight one-sphere stones at 20, 26 and 32 m/s without air, measured 124.6, 127.5 and 133.3 mm
/// (each a mean over eight triangle centroids of a 5 mm mesh). With coupled air, where the pipe
/// collisions do fall with speed (0.55 → 0.05 → 0 per stone), the damage centroid rises likewise
/// (−29.9 → −18.6 → −15.2 mm from the axis, docs/gravelometer.md).
#[test]
fn faster_stones_erode_more_and_strike_higher_on_the_sae_panel() {
    let tmp = tempfile::tempdir().unwrap();
    let runs: Vec<(f64, f64)> = [20.0, 26.0, 32.0]
        .iter()
        .map(|&v| {
            let s = run_in(&tmp.path().join(format!("v{v}")), &preset_balls("sae_j400", Some(v)));
            (scalar(&s, "panel_eroded_mass_kg"), scalar(&s, "height_on_panel_mean_m"))
        })
        .collect();
    eprintln!("SAE at 20 / 26 / 32 m/s: (eroded mass kg, mean impact height m) {runs:?}");
    for w in runs.windows(2) {
        assert!(w[1].0 > w[0].0, "eroded mass grows with the speed: {runs:?}");
        assert!(w[1].1 > w[0].1, "impacts rise with the speed: {runs:?}");
    }
}

#[test]
fn the_sphere_mode_is_the_single_particle_steel_ball() {
    // Qian et al. (2022), single-particle tests S1–S5: a 5 mm steel ball of 615 spheres of 0.5 mm (solid
    // fraction 615 · (0.5/5)³ = 0.615). The equal-sphere fill here packs at most the face-centred cubic
    // density 0.74; the ball keeps the mass of the solid steel ball, ρ π D³ / 6.
    let cfg = load(
        "standard = \"din_55996_1\"\n[stones]\nshape = \"sphere\"\nsphere_diameter_m = 0.005\n\
         member_diameter_m = 5e-4\ndensity_kg_m3 = 7850.0",
    );
    let p = plan(&cfg).unwrap();
    assert_eq!(p.stones.len(), 1);
    let ball = &p.stones[0];
    let n = ball.template.spheres.len() as f64;
    let fraction = n * (0.5f64 / 5.0).powi(3);
    assert!(fraction > 0.5 && fraction <= 0.7405, "{n} members, solid fraction {fraction}");
    let m = 7850.0 * std::f64::consts::PI * 0.005f64.powi(3) / 6.0;
    assert!((ball.mass - m).abs() < 1e-12 * m, "{} vs {m}", ball.mass);
    assert!((ball.diameter - 0.005).abs() < 1e-12);
}

/// `air = "prescribed"` on the DIN preset (reduced geometry, one-sphere grit, developed flow from t = 0):
/// the stones leave the feeder at the empirical 12 m/s into 28 m/s air (centreline 34.3 m/s), so the
/// drag speeds them up on the way to the panel and they hit it faster than without air. Size of the
/// rise, estimated with Newton drag: a 4.8e-4 kg stone of 5 mm with C_D ≈ 0.47 (Di Felice at
/// Re ≈ 7000) at a slip of ≈ 22 m/s accelerates at k w² ≈ 5.6 m/s² for the ≈ 16 ms of its 0.2 m flight,
/// about +0.09 m/s; the test accepts +0.04 to +0.15 m/s (the slip falls along the way and the stones
/// off the axis see the profile's slower air).
#[test]
fn prescribed_air_speeds_up_the_din_stones_on_their_way_to_the_panel() {
    let tmp = tempfile::tempdir().unwrap();
    let case = |name: &str, top: &str| {
        let text = reduced(top, "count = 6\nfeed_time_s = 0.004", "");
        let s = run_in(&tmp.path().join(name), &text.replace("duration_s = 0.03", "duration_s = 0.04"));
        (scalar(&s, "impact_speed_mean_m_s"), scalar(&s, "impacts_counted"))
    };
    let (none, n_none) = case("none", "");
    let (air, n_air) = case("air", "air = \"prescribed\"\n[air_field]\nramp_s = 0.0");
    assert!(n_none >= 5.0 && n_air == n_none, "impacts: {n_none} without air, {n_air} with");
    let rise = air - none;
    assert!(rise > 0.04 && rise < 0.15, "mean impact speed {air} m/s with air, {none} m/s without");
}

/// The single-particle tests S1–S5 of Qian et al. (2022): a 5 mm steel ball starting from rest in the
/// horizontal 30 mm accelerating pipe (shortened here to 0.1 m), driven by air raised step by step (the
/// study raised the reservoir pressure from 0.05 to 0.25 MPa; the air speeds it gave are not in the
/// published text, so bulk speeds of 30–50 m/s stand for them). What the study reports and this model
/// reproduces: the ball's speed at the pipe exit grows with the air (V1, "the particle horizontal
/// velocity at the outlet increases with the increase of set air pressure"), and the ball collides with
/// the pipe wall no more often when the air is stronger (V2, "the higher the air pressure … the fewer
/// collisions with the pipe wall"). The uplift the study saw comes from the turbulent, swirling pipe
/// flow; the axisymmetric prescribed profile has no lift, so the highest point is only reported.
#[test]
fn single_particle_tests_s1_to_s5_exit_faster_and_hit_the_wall_no_more_often_with_more_air() {
    let tmp = tempfile::tempdir().unwrap();
    let mut last: Option<(f64, f64)> = None;
    for (k, bulk) in [30.0, 35.0, 40.0, 45.0, 50.0].into_iter().enumerate() {
        let text = format!(
            r#"standard = "din_55996_1"
air = "prescribed"
duration_s = 0.3
[pipe]
length_m = 0.1
air_velocity_m_s = {bulk}
[panel]
distance_m = 0.1
triangle_size_m = 0.01
[stones]
shape = "sphere"
sphere_diameter_m = 0.005
member_diameter_m = 0.005
density_kg_m3 = 7850.0
youngs_modulus_pa = 1e9
count = 1
feed_time_s = 0.001
[launch]
speed_m_s = 0.0
fall_height_m = 0.0
[air_field]
ramp_s = 0.01
[output]
particles_vtu = false
output_interval_s = 0.01
"#
        );
        let s = run_in(&tmp.path().join(format!("s{}", k + 1)), &text);
        let v = scalar(&s, "first_stone_exit_speed_m_s");
        let hits = scalar(&s, "first_stone_pipe_collisions");
        let h = scalar(&s, "first_stone_max_height_in_pipe_m");
        assert!(v.is_finite() && h.is_finite(), "S{}: exit speed {v}, height {h}", k + 1);
        assert!(v > 0.0 && v < bulk, "S{}: exit speed {v} m/s in {bulk} m/s air", k + 1);
        if let Some((v0, hits0)) = last {
            assert!(v > v0, "S{}: exit speed {v} after {v0}", k + 1);
            assert!(hits <= hits0, "S{}: {hits} wall collisions after {hits0}", k + 1);
        }
        last = Some((v, hits));
    }
}

/// A small DIN set-up for the coupled air: a `pipe_m` pipe, a 30 × 40 mm panel 50 mm from the exit
/// in a box 20 mm larger all round (a few thousand flow cells), a 5 mm steel ball from rest.
fn coupled_case(air: &str, pipe_m: f64, bulk: f64, cell: f64, duration: f64) -> String {
    format!(
        r#"standard = "din_55996_1"
air = "{air}"
duration_s = {duration}
[pipe]
length_m = {pipe_m}
air_velocity_m_s = {bulk}
[panel]
width_m = 0.03
length_m = 0.04
distance_m = 0.05
triangle_size_m = 0.01
strips = 4
[protection_box]
margin_m = 0.02
[stones]
shape = "sphere"
sphere_diameter_m = 0.005
member_diameter_m = 0.005
density_kg_m3 = 7850.0
youngs_modulus_pa = 1e9
count = 1
feed_time_s = 0.001
[launch]
speed_m_s = 0.0
fall_height_m = 0.0
[air_field]
ramp_s = 0.005
[coupled_air]
cell_size_m = {cell}
[output]
particles_vtu = false
output_interval_s = 0.005
"#
    )
}

/// The air of the coupled pipe alone (no stones), stepped to `t_end`: (flow, domain).
fn empty_pipe(text: &str, t_end: f64) -> (spatter_cfd::Flow, super::coupled::AirDomain) {
    let cfg = load(text);
    Checker::run(&cfg, None).unwrap();
    let p = plan(&cfg).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    super::scene::write_geometry(&p, tmp.path()).unwrap();
    let dom = super::coupled::domain(&cfg, &p, tmp.path()).unwrap();
    let mut fluid = super::coupled::coupled_fluid(&cfg, &dom).unwrap();
    while fluid.coupling.flow.state.t < t_end {
        let n = fluid.coupling.adaptive_substeps(p.dt, crate::cfd_dem::partner::FLUID_COURANT);
        fluid.coupling.flow.step(n as f64 * p.dt).unwrap();
    }
    (fluid.coupling.flow, dom)
}

/// Axial velocity of the cells of the pipe section nearest `x`: (r, u) per open cell.
fn section(flow: &spatter_cfd::Flow, x: f64) -> Vec<(f64, f64)> {
    let g = &flow.grid;
    let l = g.layout;
    let i = (0..l.n[0])
        .min_by(|&a, &b| (g.axes[0].centre(a) - x).abs().total_cmp(&(g.axes[0].centre(b) - x).abs()));
    let i = i.unwrap();
    let mut out = Vec::new();
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            if !flow.blocked[l.cell(i, j, k)] {
                let (y, z) = (g.axes[1].centre(j), g.axes[2].centre(k));
                out.push(((y * y + z * z).sqrt(), flow.cell_velocity(i, j, k)[0]));
            }
        }
    }
    out
}

/// The empty coupled DIN pipe (30 mm, 28 m/s bulk, laminar, the preset's 7.5 mm cells) after the
/// inlet ramp: every section carries the inlet's bulk speed (continuity through the stair-stepped
/// bore, to 1e-9 relative), the no-slip pipe wall slows the wall cells below the middle ones, and the
/// pressure falls along the pipe (friction) and is finite everywhere. The turbulent friction is tested
/// with k–ε below.
#[test]
fn the_empty_coupled_pipe_carries_the_bulk_speed_through_every_section() {
    let text = coupled_case("coupled", 0.29, 28.0, 0.0075, 0.05);
    let (flow, dom) = empty_pipe(&text, 0.02);
    assert!(dom.grid.x.min_m <= -0.29 && dom.grid.x.min_m > -0.29 - 0.0075, "{:?}", dom.grid.x);
    let ub = 28.0;
    for x in [-0.25, -0.15, -0.05] {
        let s = section(&flow, x);
        // Open cells: those with centres in the bore, 12 of the 4 × 4 around the axis.
        assert_eq!(s.len(), 12, "x = {x}");
        let mean = s.iter().map(|c| c.1).sum::<f64>() / s.len() as f64;
        assert!((mean / ub - 1.0).abs() < 1e-9, "x = {x}: bulk {mean} m/s on {} cells", s.len());
    }
    let s = section(&flow, -0.05);
    let r_mid = 0.5 * 0.015;
    let mean_of = |inner: bool| {
        let v: Vec<f64> = s.iter().filter(|c| (c.0 < r_mid) == inner).map(|c| c.1).collect();
        v.iter().sum::<f64>() / v.len() as f64
    };
    let (centre, wall) = (mean_of(true), mean_of(false));
    assert!(centre > wall, "centre {centre} m/s, wall cells {wall} m/s");
    let g = &flow.grid;
    let p_at = |x: f64| {
        let l = g.layout;
        let i = (0..l.n[0])
            .min_by(|&a, &b| (g.axes[0].centre(a) - x).abs().total_cmp(&(g.axes[0].centre(b) - x).abs()))
            .unwrap();
        let (mut sum, mut n) = (0.0, 0.0);
        for k in 0..l.n[2] {
            for j in 0..l.n[1] {
                if !flow.blocked[l.cell(i, j, k)] {
                    sum += flow.cell_pressure(i, j, k);
                    n += 1.0;
                }
            }
        }
        sum / n
    };
    let (pa, pb) = (p_at(-0.25), p_at(-0.05));
    assert!(pa.is_finite() && pb.is_finite() && pa > pb, "p {pa} Pa at x = -0.25 m, {pb} Pa at -0.05 m");
}

/// The empty coupled DIN pipe with standard k–ε (wall functions on the blocked cells of the bore):
/// after 0.05 s k stays bounded near its equilibrium (the run without wall functions on blocked faces
/// reached k ≈ 5e4 m²/s²), every section still carries the bulk speed, and the pressure drop between
/// x = −0.25 and −0.05 m over ½ρU_b² (L/D) gives a Darcy friction factor within 15 % of Colebrook's
/// smooth-pipe value (Colebrook 1939) at Re = U_b D/ν = 5.6·10⁴ (10 %, the usual accuracy of k–ε with
/// wall functions, widened for the bore's staircase of 12 cells; measured +8.2 %, k at most 22 m²/s²).
#[test]
fn k_epsilon_in_the_coupled_pipe_gives_a_turbulent_pipe_friction() {
    let text = coupled_case("coupled", 0.29, 28.0, 0.0075, 0.05)
        .replace("[coupled_air]\n", "[coupled_air]\nturbulence = \"k_epsilon\"\n");
    let (flow, _) = empty_pipe(&text, 0.05);
    let ub = 28.0;
    for x in [-0.25, -0.15, -0.05] {
        let s = section(&flow, x);
        let mean = s.iter().map(|c| c.1).sum::<f64>() / s.len() as f64;
        assert!((mean / ub - 1.0).abs() < 1e-9, "x = {x}: bulk {mean} m/s");
    }
    let g = &flow.grid;
    let l = g.layout;
    let ts = flow.state.turbulence.as_ref().unwrap();
    let k_max = (0..l.len()).filter(|&c| flow.is_fluid(c)).map(|c| ts.k[c]).fold(0.0, f64::max);
    let p_at = |x: f64| {
        let i = g.axes[0].locate(x);
        let (mut sum, mut n) = (0.0, 0.0);
        for k in 0..l.n[2] {
            for j in 0..l.n[1] {
                if !flow.blocked[l.cell(i, j, k)] {
                    sum += flow.cell_pressure(i, j, k);
                    n += 1.0;
                }
            }
        }
        (g.axes[0].centre(i), sum / n)
    };
    let ((xa, pa), (xb, pb)) = (p_at(-0.25), p_at(-0.05));
    let (d, rho, nu) = (0.03, 1.204, 1.81e-5 / 1.204);
    let f = (pa - pb) / (xb - xa) * d / (0.5 * rho * ub * ub);
    let fc = spatter_cfd::validation::colebrook_smooth(ub * d / nu);
    eprintln!("k-eps coupled pipe: k_max {k_max} m2/s2, Darcy f {f}, Colebrook {fc}");
    assert!(k_max < 100.0, "k_max {k_max}");
    assert!((f / fc - 1.0).abs() < 0.15, "f {f}, Colebrook {fc}");
}

/// One 5 mm steel ball launched at 8 m/s along the axis of the coupled 0.29 m DIN pipe (28 m/s bulk)
/// gains speed from the air as in the prescribed power-law air of the same bulk speed. The gain is
/// drag × time: with Newton drag (C_D ≈ 0.44) at a slip near 28 m/s the ball speeds up at about
/// 8 m/s² over its 36 ms in the pipe, +0.3 m/s. What differs: the prescribed air on the axis is the
/// developed power law's 1.224 U_b, the coupled (laminar, four cells across) air about U_b, read by
/// the drag as U/α with the ball's own void fraction α ≈ 0.85 in its 7.5 mm cell — the slips differ by
/// about 10 %, which enters the drag squared: the gains are asked to agree within 25 %. The ball
/// flies 0.3 mm lower by the exit and never touches the wall. The coupling's momentum balance closes to
/// round-off at every step (relative mismatch below 1e-12).
#[test]
fn one_ball_in_the_coupled_pipe_leaves_it_as_fast_as_in_prescribed_air() {
    let tmp = tempfile::tempdir().unwrap();
    let run_air = |air: &str| {
        let text = coupled_case(air, 0.29, 28.0, 0.0075, 0.045).replace("speed_m_s = 0.0", "speed_m_s = 8.0");
        let s = run_in(&tmp.path().join(air), &text);
        (scalar(&s, "first_stone_exit_speed_m_s") - 8.0, s)
    };
    let (gp, sp) = run_air("prescribed");
    let (gc, s) = run_air("coupled");
    eprintln!("speed gained in the pipe: prescribed {gp} m/s, coupled {gc} m/s");
    assert!(gp > 0.15 && gp < 0.6, "prescribed gain {gp} m/s (Newton-drag estimate +0.3 m/s)");
    assert!((gc / gp - 1.0).abs() < 0.25, "gain {gc} m/s coupled, {gp} m/s prescribed");
    for r in [&sp, &s] {
        assert_eq!(scalar(r, "first_stone_pipe_collisions"), 0.0);
    }
    let mismatch = scalar(&s, "max_momentum_mismatch");
    assert!(mismatch < 1e-12, "momentum mismatch {mismatch}");
    assert!(scalar(&s, "coupling_steps") > 10.0);
    assert!(
        tmp.path().join("coupled/fields.pvd").exists() && tmp.path().join("coupled/coupling.csv").exists()
    );
}

/// The coupled air gives the same bits on 1 and 2 threads: three balls through a short coupled DIN pipe
/// (void fraction, forces, exchange and fluid steps in parallel; every sum in a fixed order). The fluid
/// fields, the coupling balance and the trajectories are compared byte for byte.
#[test]
fn the_coupled_air_is_bit_identical_on_one_and_two_threads() {
    let tmp = tempfile::tempdir().unwrap();
    // 5 mm cells: about 14 000 padded cells, above the size the flow solver's loops run in parallel.
    let text = coupled_case("coupled", 0.1, 28.0, 0.005, 0.012)
        .replace("speed_m_s = 0.0", "speed_m_s = 8.0")
        .replace("count = 1", "count = 3");
    let run_on = |threads: usize| {
        let dir = tmp.path().join(format!("t{threads}"));
        rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| run_in(&dir, &text));
        dir
    };
    let (one, two) = (run_on(1), run_on(2));
    let fields: Vec<_> =
        std::fs::read_dir(one.join("fields")).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(fields.len() >= 2, "{fields:?}");
    let mut files: Vec<std::path::PathBuf> = fields.iter().map(|f| Path::new("fields").join(f)).collect();
    files.extend(["coupling.csv", "trajectories.csv", "stones.csv"].map(std::path::PathBuf::from));
    for f in files {
        let (a, b) = (std::fs::read(one.join(&f)).unwrap(), std::fs::read(two.join(&f)).unwrap());
        assert!(a == b, "{} differs between 1 and 2 threads", f.display());
    }
}

#[test]
fn the_impact_headline_states_no_undefined_statistic() {
    // Before the first stone reaches the panel the statistics are undefined (NaN): the headline says so
    // in words instead of printing NaN; one impact has a mean but no standard deviation.
    let none = results::Statistics::of(&[]);
    let line = results::impact_headline(&none, &none);
    assert!(!line.contains("NaN"), "{line}");
    assert!(line.contains("no stone reached the panel"), "{line}");
    let one = results::impact_headline(&results::Statistics::of(&[13.4]), &results::Statistics::of(&[54.0]));
    assert!(!one.contains("NaN") && one.contains("13.40 m/s") && one.contains("54.0°"), "{one}");
    assert!(!one.contains('±'), "{one}");
    // Three impacts: mean 13, sample SD 1 (values 12, 13, 14), range 12–14.
    let speed = results::Statistics::of(&[12.0, 13.0, 14.0]);
    let angle = results::Statistics::of(&[50.0, 54.0, 58.0]);
    let three = results::impact_headline(&speed, &angle);
    assert_eq!(
        three,
        "first 3 stones on the panel: speed 13.00 ± 1.00 m/s (12.00–14.00), impact angle 54.0 ± 4.0° (50.0–58.0°)"
    );
}

/// The gravelometer on two ranks (ranks as threads) against one: twelve one-sphere stones (rigid bodies
/// of one member) through the reduced DIN pipe in prescribed air (the drag hook runs on each rank over the members
/// it owns) onto the panel. Rank 0 writes the results from every rank's records; every table of the run
/// (stones, impacts, strips, wear, bodies, energies) and every scalar of the summary agree with one rank
/// within 10⁻⁹ of each column's largest magnitude (measured: 8·10⁻¹⁵; the energy sums add the ranks' parts
/// in another order). Coupled air is refused on ranks, naming the key.
#[test]
fn the_gravelometer_on_two_ranks_matches_one() {
    use spatter_core::comm::ThreadComm;
    let tmp = tempfile::tempdir().unwrap();
    let text =
        reduced("air = \"prescribed\"\n[air_field]\nramp_s = 0.0", "count = 12\nfeed_time_s = 0.008", "")
            .replace("duration_s = 0.03", "duration_s = 0.035");
    let cfg = load(&text);
    Checker::run(&cfg, None).unwrap();
    let on = |n: usize, dir: &Path| {
        let d = RunDir::create(dir).unwrap();
        ThreadComm::run(n, |comm| {
            let ctx = RunContext { comm, ..RunContext::new(&d, &Unattended, false) };
            run(&cfg, &ctx).map_err(|e| e.to_string())
        })
    };
    let (one, two) = (tmp.path().join("one"), tmp.path().join("two"));
    let s1 = on(1, &one).pop().unwrap().unwrap();
    let mut s2 = on(2, &two);
    assert!(s2.iter().all(Result::is_ok), "{:?}", s2.iter().map(|r| r.as_ref().err()).collect::<Vec<_>>());
    let s2 = s2.remove(0).unwrap();
    assert!(scalar(&s1, "impacts_counted") >= 10.0, "stones reached the panel: {:?}", s1.scalars);
    let mut worst: f64 = 0.0;
    for f in ["stones.csv", "impacts.csv", "strips.csv", "wear.csv", "bodies.csv", "energy.csv"] {
        let ((h1, r1), (h2, r2)) = (csv(&one.join(f)), csv(&two.join(f)));
        assert_eq!(h1, h2, "{f}");
        assert_eq!(r1.len(), r2.len(), "{f}: rows");
        assert!(!r1.is_empty(), "{f} has rows");
        for c in 0..h1.len() {
            let num = |r: &[String]| r[c].trim().parse::<f64>().ok();
            let scale = r1.iter().filter_map(|r| num(r)).map(f64::abs).fold(0.0, f64::max).max(1e-300);
            for (a, b) in r1.iter().zip(&r2) {
                match (num(a), num(b)) {
                    (Some(x), Some(y)) if x.is_finite() || y.is_finite() => {
                        let d = (x - y).abs() / scale;
                        worst = worst.max(d);
                        assert!(d <= 1e-9, "{f} column {}: {y} on 2 ranks, {x} on 1", h1[c]);
                    }
                    _ => assert_eq!(a[c], b[c], "{f} column {}", h1[c]),
                }
            }
        }
    }
    for (name, v1) in &s1.scalars {
        let v2 = scalar(&s2, name);
        assert!(
            (v1 - v2).abs() <= 1e-9 * v1.abs().max(1e-300) || v1 == &v2,
            "{name}: {v2} on 2 ranks, {v1} on 1"
        );
    }
    eprintln!("gravelometer on 2 ranks: largest relative difference {worst:e}");
    // Coupled air runs in one process: refused on two ranks with the key named.
    let coupled = load(&text.replace("air = \"prescribed\"", "air = \"coupled\""));
    let d = RunDir::create(&tmp.path().join("coupled")).unwrap();
    let errs = ThreadComm::run(2, |comm| {
        let ctx = RunContext { comm, ..RunContext::new(&d, &Unattended, false) };
        run(&coupled, &ctx).err().map(|e| e.to_string())
    });
    for e in errs {
        let e = e.expect("refused");
        assert!(e.starts_with("air: ") && e.contains("2 ranks"), "{e}");
    }
}
