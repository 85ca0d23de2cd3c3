//! Pour, bed file and packing tests: packing density of frictionless and frictional pours, bit-for-bit
//! resume of a pour, a bed file read into a scene bit for bit, and the bad-input messages.

use super::*;
use spatter_core::check::Checker;
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_io::run::{RunContext, RunDir, RunSummary};

/// A box of `cells` × `cells` diameters (d = 10 mm) with planes on four sides and a floor, poured with
/// `count` spheres; Hooke contacts stiff enough that the overlaps under the bed's weight stay below
/// 10⁻³ d (k = 10⁴ N/m, m = 1.31 g: weight of a column of ten spheres 0.13 N → 1.3·10⁻⁵ m).
fn box_pour(count: u64, cells: f64, friction: f64, duration: f64) -> String {
    let w = 0.01 * cells;
    format!(
        r#"
dt_s = 4e-5
duration_s = {duration}
output_interval_s = 0.02
seed = 11

[contact]
normal = "hooke"
hooke_stiffness_n_m = 1e4
tangential = "linear"

[engine]
track_energy = false

[materials.glass]
youngs_modulus_pa = 6e10
poisson_ratio = 0.25
density_kg_m3 = 2500

[pair_defaults]
friction = {friction}
restitution = 0.3

[[walls]]
name = "floor"
material = "glass"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [0, 0, 1] }}
[[walls]]
name = "xlo"
material = "glass"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [1, 0, 0] }}
[[walls]]
name = "xhi"
material = "glass"
shape = {{ type = "plane", point_m = [{w}, 0, 0], normal = [-1, 0, 0] }}
[[walls]]
name = "ylo"
material = "glass"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [0, 1, 0] }}
[[walls]]
name = "yhi"
material = "glass"
shape = {{ type = "plane", point_m = [0, {w}, 0], normal = [0, -1, 0] }}

[pour]
material = "glass"
size = {{ kind = "mono", diameter = 0.01 }}
region = {{ type = "box", min_m = [0, 0, 0], max_m = [{w}, {w}, 0.5] }}
count = {count}
interval_s = 0.001
"#
    )
}

fn parse(text: &str) -> SceneConfig {
    toml::from_str(text).unwrap_or_else(|e| panic!("{e}"))
}

fn scalar(s: &RunSummary, name: &str) -> f64 {
    s.scalars.iter().find(|(k, _)| k == name).map(|(_, v)| *v).unwrap_or_else(|| panic!("no scalar {name}"))
}

/// Runs a box pour and returns its summary.
fn pour(count: u64, cells: f64, friction: f64, core: &str) -> RunSummary {
    let mut cfg = parse(&format!("{}{core}", box_pour(count, cells, friction, 4.0)));
    cfg.output.particles_vtu = false;
    Checker::run(&cfg, None).unwrap_or_else(|e| panic!("{e:?}"));
    let tmp = tempfile::tempdir().unwrap();
    let dir = RunDir::create(tmp.path()).unwrap();
    let s = run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.finished, Finished::Completed);
    s
}

/// Monodisperse pours in a 10 d × 10 d box, 1000 spheres, a bed about 8 d high. The packing density is
/// measured in the core 2 d away from every wall and from the floor and 2 d below the surface (6 × 6 × 4
/// d³, about 175 spheres' volume): the wall layers are looser (the first layer at a plane is ordered)
/// and are left out.
///
/// Frictionless: random close packing, φ = 0.64 (Scott & Kilgour 1969, "The density of random close
/// packing of spheres", J. Phys. D 2, 863: 0.637 ± 0.001; Jasion 2013 Table C.3: 63–64 % for his
/// stiffest frictionless 3D beds). Tolerance ±0.025: the core holds about 175 sphere volumes, and the
/// solid fraction of a window of that size fluctuates by about 0.01 (one standard deviation) from one
/// random packing to the next; and a pour with finite damping sits slightly below the RCP limit.
///
/// Frictional (μ = 0.5): looser, as Jasion (2013, Appendix C, Table C.3) finds (friction lowers the
/// packing, FLA 82 % vs SLA 86 %, FLB 69 % vs SLB 74 %); random loose to poured packings of frictional
/// spheres lie at 0.56–0.61 (Onoda & Liniger 1990, PRL 64, 2727; Silbert 2010, Soft Matter 6, 2918). We
/// require φ(μ = 0.5) < φ(μ = 0) − 0.02 and φ(μ = 0.5) in [0.55, 0.62].
#[test]
fn frictionless_pour_packs_near_random_close_packing_and_friction_packs_looser() {
    let core = r#"
[output]
bed_file = false
[[output.packing]]
name = "core"
min_m = [0.02, 0.02, 0.02]
max_m = [0.08, 0.08, 0.06]
"#;
    let smooth = pour(1000, 10.0, 0.0, core);
    let rough = pour(1000, 10.0, 0.5, core);
    let (a, b) = (scalar(&smooth, "packing_core"), scalar(&rough, "packing_core"));
    eprintln!("core packing: frictionless {a:.4}, frictional {b:.4}");
    for s in [&smooth, &rough] {
        assert_eq!(scalar(s, "poured"), 1000.0);
        assert!(scalar(s, "settled_s") < 4.0, "settled before the end: {:?}", s.headline);
    }
    assert!((a - 0.64).abs() < 0.025, "frictionless core packing {a}");
    assert!(b < a - 0.02 && (0.55..0.62).contains(&b), "frictional core packing {b} (frictionless {a})");
}

#[test]
fn an_interrupted_pour_resumes_bit_for_bit_and_its_bed_starts_another_run() {
    let tmp = tempfile::tempdir().unwrap();
    let cfg = parse(&box_pour(60, 5.0, 0.3, 0.3));
    let full = RunDir::create(&tmp.path().join("full")).unwrap();
    let s = run(&cfg, &RunContext::new(&full, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    assert_eq!(scalar(&s, "poured"), 60.0);
    let part = RunDir::create(&tmp.path().join("part")).unwrap();
    // Stop in the middle of the pour (step 1333, t = 0.053 s: 54 of 60 spheres poured).
    let s = run(&cfg, &RunContext::new(&part, &StopAfterPolls::new(1333), false)).unwrap();
    assert_eq!(s.finished, Finished::Interrupted);
    let s = run(&cfg, &RunContext::new(&part, &Unattended, true)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    for rel in ["energy.csv", "particles.pvd", "particles/particles_00003.vtu", "bed.txt"] {
        let a = std::fs::read(full.root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let b = std::fs::read(part.root().join(rel)).unwrap();
        assert!(a == b, "{rel} differs between the uninterrupted and the resumed pour");
    }
    // The bed starts another scene: the spheres it places are those of the file bit for bit, and the
    // bed written from them is the same file.
    let bed = full.root().join("bed.txt");
    let mut next = parse(&box_pour(1, 5.0, 0.3, 0.3));
    next.pour = None;
    next.bed = Some(BedStart { file: bed.clone() });
    Checker::run(&next, None).unwrap_or_else(|e| panic!("{e:?}"));
    let built = setup::build(&next).unwrap();
    let spheres = setup::initial_particles(&next, &built.walls, &built.templates).unwrap().spheres;
    let mut p = spatter_dem::particles::Particles::new();
    for s in &spheres {
        p.push(*s, 2500.0);
    }
    let text = crate::bed_lab::bed_file::format(&crate::bed_lab::bed_file::from_particles(&p, &["glass"]));
    assert_eq!(text, std::fs::read_to_string(&bed).unwrap(), "bed file → scene → bed file");
    assert_eq!(spheres.len(), 60);
    // And runs from there.
    next.duration_s = 0.01;
    let dir = RunDir::create(&tmp.path().join("next")).unwrap();
    let s = run(&next, &RunContext::new(&dir, &Unattended, false)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scalar(&s, "particles"), 60.0);
}

#[test]
fn bad_pours_and_bed_files_are_refused_with_the_key() {
    let tmp = tempfile::tempdir().unwrap();
    let errs = |cfg: &SceneConfig| Checker::run(cfg, Some(tmp.path())).unwrap_err();
    // A pour region above the domain.
    let mut cfg = parse(&box_pour(10, 5.0, 0.0, 1.0));
    cfg.engine.domain_min_m = Some(spatter_core::Vec3::new(-0.1, -0.1, -0.1));
    cfg.engine.domain_max_m = Some(spatter_core::Vec3::new(0.2, 0.2, 0.3));
    let e = errs(&cfg);
    let m = &e.iter().find(|e| e.key == "pour.region").unwrap_or_else(|| panic!("{e:?}")).message;
    assert!(m.contains("above the domain") && m.contains("0.5"), "{m}");
    // A missing bed file, a malformed one, one with an unknown material.
    let mut cfg = parse(&box_pour(10, 5.0, 0.0, 1.0));
    cfg.bed = Some(BedStart { file: "missing.txt".into() });
    let e = errs(&cfg);
    assert!(e.iter().any(|e| e.key == "bed.file" && e.message.contains("no such file")), "{e:?}");
    let head = crate::bed_lab::bed_file::MAGIC;
    for (text, want) in [
        (format!("{head}\n0 0.005 glass 0.1 0.1 0.1 0 0 0 0 0\n"), "line 2: 11 fields, expected 12"),
        (format!("{head}\n0 0.005 steel 0.1 0.1 0.1 0 0 0 0 0 0\n"), "line 2: field `material` = \"steel\""),
        ("id radius\n".to_string(), "line 1: expected the header"),
    ] {
        std::fs::write(tmp.path().join("bad.txt"), text).unwrap();
        cfg.bed = Some(BedStart { file: "bad.txt".into() });
        let e = errs(&cfg);
        let m = &e.iter().find(|e| e.key == "bed.file").unwrap_or_else(|| panic!("{e:?}")).message;
        assert!(m.contains(want) && m.contains("bad.txt"), "{m}");
    }
    // A pour that overflows its region at run time.
    let mut cfg = parse(&box_pour(400, 3.0, 0.0, 2.0));
    if let Some(RegionConfig::Box { max_m, .. }) = cfg.pour.as_mut().map(|p| &mut p.region) {
        max_m.z = 0.1;
    }
    let dir = RunDir::create(&tmp.path().join("full")).unwrap();
    let e = run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap_err().to_string();
    assert!(e.contains("pour.region") && e.contains("region's top"), "{e}");
}

/// A pour into a vertical cylinder (radius 5.64 cm, the area of the 10 × 10 cm box above) inside a
/// cylindrical wall: every sphere ends inside the cylinder, up to its overlap with the wall — a
/// frictionless bed presses on its wall with its full hydrostatic pressure, φ ρ g h ≈ 1.3 kPa at the
/// floor, about 0.13 N on a wall sphere, 1.3·10⁻⁵ m of overlap at k = 10⁴ N/m, several times that where
/// the packing concentrates the load (we measure 4.2·10⁻⁵ m); the bound is 10⁻⁴ m = 10⁻² d, far below
/// the radius a sphere outside the wall would show — and the frictionless core — a 6 × 6 × 4
/// d box on the axis, at least 1.4 d from the wall, 2 d above the floor and below the surface — packs
/// at random close packing as in the box (0.64 ± 0.025, the tolerance and reference of
/// `frictionless_pour_packs_near_random_close_packing_and_friction_packs_looser`).
#[test]
fn a_cylinder_pour_stays_inside_its_wall_and_packs_like_the_box() {
    let radius = 0.0564;
    let text = format!(
        r#"
dt_s = 4e-5
duration_s = 4.0
output_interval_s = 0.02
seed = 5
[contact]
normal = "hooke"
hooke_stiffness_n_m = 1e4
tangential = "linear"
[engine]
track_energy = false
[materials.glass]
youngs_modulus_pa = 6e10
poisson_ratio = 0.25
density_kg_m3 = 2500
[pair_defaults]
friction = 0.0
restitution = 0.3
[[walls]]
name = "floor"
material = "glass"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [0, 0, 1] }}
[[walls]]
name = "die"
material = "glass"
shape = {{ type = "cylinder", point_m = [0, 0, 0], axis = [0, 0, 1], radius_m = {radius}, inside = true }}
[pour]
material = "glass"
size = {{ kind = "mono", diameter = 0.01 }}
region = {{ type = "cylinder", base_m = [0, 0, 0], axis = [0, 0, 1], radius_m = {radius}, height_m = 0.5 }}
count = 1000
interval_s = 0.001
[output]
particles_vtu = false
[[output.packing]]
name = "core"
min_m = [-0.03, -0.03, 0.02]
max_m = [0.03, 0.03, 0.06]
"#
    );
    let cfg = parse(&text);
    Checker::run(&cfg, None).unwrap_or_else(|e| panic!("{e:?}"));
    let tmp = tempfile::tempdir().unwrap();
    let dir = RunDir::create(tmp.path()).unwrap();
    let s = run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scalar(&s, "poured"), 1000.0);
    assert!(scalar(&s, "settled_s") < 4.0, "settled before the end: {:?}", s.headline);
    let bed = crate::bed_lab::bed_file::read(&dir.path("bed.txt"), &["glass"]).unwrap();
    assert_eq!(bed.len(), 1000);
    let worst =
        bed.iter().map(|b| b.pos.x.hypot(b.pos.y) + b.radius - radius).fold(f64::NEG_INFINITY, f64::max);
    assert!(worst < 1e-4, "a sphere reaches {worst:e} m beyond the wall");
    let phi = scalar(&s, "packing_core");
    eprintln!("cylinder pour: core packing {phi:.4}, settled at {:.3} s", scalar(&s, "settled_s"));
    assert!((phi - 0.64).abs() < 0.025, "core packing {phi}");
}

/// The time-step warning of a Hooke scene compares Δt with the linear-spring contact π√(m*/k_n) and not
/// with the Rayleigh time of the material (which the soft spring makes irrelevant). The box pour: glass
/// spheres d = 10 mm, m = 1.309 g, k_n = 10⁴ N/m → particle pair m* = 0.654 g, t_c = 8.04·10⁻⁴ s, so
/// Δt = 4·10⁻⁵ s gives 20.1 steps per contact (no warning) although it is 7 times the Rayleigh time of
/// glass (5.5·10⁻⁶ s); Δt = 10⁻⁴ s gives 8.0 steps and must warn, naming the linear contact.
#[test]
fn hooke_time_step_warning_uses_the_spring() {
    let warn = |dt: f64| {
        let mut cfg = parse(&box_pour(10, 4.0, 0.5, 1.0));
        cfg.dt_s = dt;
        struct W<'a>(&'a SceneConfig);
        impl WithLaw for W<'_> {
            type Output = Vec<String>;
            fn with<L: spatter_dem::contact::ContactLaw>(
                self,
                law: L,
                built: setup::Built,
            ) -> Result<Vec<String>, spatter_dem::error::DemError> {
                let sim = simulation(law, built, self.0);
                Ok(time_step_warnings(self.0, &sim))
            }
        }
        with_law(&cfg, W(&cfg)).unwrap()
    };
    assert!(warn(4e-5).is_empty(), "{:?}", warn(4e-5));
    let w = warn(1e-4);
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains("linear-spring contact") && w[0].contains("8.0 steps"), "{}", w[0]);
    assert!(!w[0].contains("Rayleigh"), "{}", w[0]);
}
