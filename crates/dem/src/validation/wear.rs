//! Erosion wear: Finnie's angle function against its table, and single impacts through the engine
//! against the closed forms of both wear models.
//!
//! The panel scene is `pub(crate)` so the engine's unit tests (`sim/wear_tests.rs`) run the same set-up.

use super::impact::rigid;
use crate::contact::{HertzMindlin, PairProps, PairTable};
use crate::sim::{Settings, Simulation};
use crate::walls::{MeshWall, Wall, WallShape};
use crate::wear::{finnie_f, WearModel, WearTable};
use spatter_core::material::Material;
use spatter_core::math::sphere_volume;
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use spatter_core::validation::Check;
use spatter_core::Vec3;

const SRC_FINNIE: &str =
    "Finnie (1960) Wear 3:87, f(g) = sin 2g - 3 sin^2 g (tan g <= 1/3), cos^2 g / 3 above";

/// Density of the particles of the panel scene \[kg/m³\].
pub(crate) const PANEL_PARTICLE_DENSITY: f64 = 2500.0;

/// A square mesh panel of side `l` in z = 0 (`n` × `n` squares, two triangles each, wall density
/// 1200 kg/m³, rigid), Hertz–Mindlin particles of E = 0.1 GPa, μ = 0.3, e = 0.6, Δt = 1 µs, no gravity,
/// with `model` for the particle–panel pair.
pub(crate) fn panel_sim(n: usize, l: f64, model: WearModel) -> Simulation<HertzMindlin> {
    let m = Material { youngs_modulus: 1e8, poisson_ratio: 0.3, density: PANEL_PARTICLE_DENSITY };
    let wall = Material { density: 1200.0, ..rigid(0.3) };
    let mats = vec![m, wall];
    let pairs = PairTable::build(2, |a, b| PairProps::new(&mats[a], &mats[b], 0.3, 0.6));
    let mut sim = Simulation::new(HertzMindlin::default(), mats, pairs, 1e-6, Settings::default());
    sim.add_wall(Wall {
        name: "panel".into(),
        shape: WallShape::Mesh(Box::new(MeshWall::new(TriMesh::rectangle(l, l, 0.0, n, n)))),
        material: 1,
        motion: Motion::Fixed,
    });
    let mut w = WearTable::new(2);
    w.set(0, 1, model);
    sim.set_wear(w);
    sim
}

/// What one impact left on the panel.
pub(crate) struct Impact {
    /// Impacting mass \[kg\].
    pub mass: f64,
    /// Impacts counted on all triangles.
    pub impacts: u64,
    /// Eroded mass of the triangle hit and of the whole panel \[kg\].
    pub triangle_mass: f64,
    pub total_mass: f64,
    /// Impact angle recorded on the triangle hit \[deg\].
    pub angle_deg: f64,
}

/// One sphere (r = 2 mm) hits a face of the panel at `gamma_deg` to its plane with `speed` (no gravity),
/// `steps` steps of 1 µs.
pub(crate) fn single_impact(model: WearModel, gamma_deg: f64, speed: f64, steps: usize) -> Option<Impact> {
    let mut sim = panel_sim(2, 0.04, model);
    let r = 2e-3;
    let g = gamma_deg.to_radians();
    let v = speed * Vec3::new(g.cos(), 0.0, -g.sin());
    let hit = Vec3::new(0.012, 0.006, 0.0); // inside one triangle's face
    let x0 = hit + Vec3::new(0.0, 0.0, r) - v * (5e-5 / v.z.abs());
    let mut p = crate::NewParticle::at(x0, r, 0);
    p.vel = v;
    sim.add_particle(p);
    sim.run_steps(steps as u64).ok()?;
    let WallShape::Mesh(m) = &sim.walls[0].shape else { return None };
    let rec = &m.records;
    let t = rec.impacts.iter().position(|&k| k > 0)?;
    Some(Impact {
        mass: PANEL_PARTICLE_DENSITY * sphere_volume(r),
        impacts: rec.impacts.iter().sum(),
        triangle_mass: rec.eroded_mass[t],
        total_mass: sim.eroded_mass(0),
        angle_deg: rec.impact_angle_sum[t] / rec.impacts[t] as f64,
    })
}

/// Finnie's f(γ) at the tabulated angles (values of the two branches to five decimals), its maximum
/// 0.30278 at ½ atan(2/3) = 16.845° and its continuity at tan γ = 1/3.
pub fn finnie_table(_quick: bool) -> Vec<Check> {
    let case = "wear_finnie_angle_function";
    let table = [
        (0.0, 0.0),
        (5.0, 0.15086),
        (10.0, 0.25156),
        (15.0, 0.29904),
        (16.845, 0.30278),
        (18.435, 0.30000),
        (20.0, 0.29434),
        (30.0, 0.25),
        (45.0, 0.16667),
        (54.0, 0.11516),
        (60.0, 0.08333),
        (72.0, 0.03183),
        (90.0, 0.0),
    ];
    let mut out: Vec<Check> = table
        .iter()
        .map(|&(deg, f)| {
            Check::absolute(
                case,
                format!("f({deg} deg) [-]"),
                f,
                finnie_f(f64::to_radians(deg)),
                5e-6,
                SRC_FINNIE,
            )
        })
        .collect();
    // The maximum: scan 0…90° in 10⁻⁴ degree steps.
    let (mut best, mut arg) = (0.0, 0.0);
    for k in 0..=900_000 {
        let deg = k as f64 * 1e-4;
        let f = finnie_f(deg.to_radians());
        if f > best {
            (best, arg) = (f, deg);
        }
    }
    let g_max = 0.5 * (2.0f64 / 3.0).atan().to_degrees();
    out.push(Check::absolute(case, "angle of the maximum [deg]", g_max, arg, 1e-3, SRC_FINNIE));
    out.push(Check::absolute(case, "maximum of f [-]", 0.302_775_637_7, best, 1e-9, SRC_FINNIE));
    let g = (1.0f64 / 3.0).atan();
    let jump = (finnie_f(g + 1e-12) - finnie_f(g - 1e-12)).abs();
    out.push(Check::absolute(case, "jump of f at tan g = 1/3 [-]", 0.0, jump, 1e-9, SRC_FINNIE));
    out
}

/// One sphere hits the panel: the eroded mass equals the model's closed form with the velocity at first
/// touch (Finnie: k m v² f(γ); normal energy: c (½ m v_n² − E_th)), on one triangle, one impact at the
/// impact angle; Finnie erodes nothing at normal incidence.
pub fn single_oblique_impact(quick: bool) -> Vec<Check> {
    let case = "wear_single_impact";
    let speed = 2.0;
    let angles: &[f64] = if quick { &[30.0] } else { &[10.0, 30.0, 60.0] };
    let k = 0.5;
    let mut out = Vec::new();
    let nan = f64::NAN;
    for &g in angles {
        let finnie = WearModel::Finnie { k };
        let i = single_impact(finnie, g, speed, 2000);
        let (want, got, n, ang, total) = match &i {
            Some(i) => {
                let want = k * i.mass * speed * speed * finnie_f(g.to_radians());
                (want, i.triangle_mass, i.impacts as f64, i.angle_deg, i.total_mass)
            }
            None => (1.0, nan, nan, nan, nan),
        };
        let label = |s: &str| format!("Finnie, {g} deg at {speed} m/s: {s}");
        out.push(Check::relative(
            case,
            label("eroded mass of the triangle hit [kg]"),
            want,
            got,
            1e-9,
            SRC_FINNIE,
        ));
        out.push(Check::relative(
            case,
            label("eroded mass of the panel [kg]"),
            want,
            total,
            1e-9,
            SRC_FINNIE,
        ));
        out.push(Check::absolute(case, label("impacts [-]"), 1.0, n, 0.0, SRC_FINNIE));
        out.push(Check::absolute(case, label("impact angle [deg]"), g, ang, 1e-6, SRC_FINNIE));
    }
    // Normal incidence: Finnie erodes nothing, the normal-energy model c (½ m v² − E_th).
    let normal = single_impact(WearModel::Finnie { k }, 90.0, speed, 2000);
    // Zero up to the round-off of the tangential speed: 10⁻¹² of k m v².
    let scale = normal.as_ref().map_or(0.0, |i| k * i.mass * speed * speed);
    out.push(Check::absolute(
        case,
        "Finnie, 90 deg: eroded mass [kg]",
        0.0,
        normal.as_ref().map_or(nan, |i| i.total_mass),
        1e-12 * scale,
        SRC_FINNIE,
    ));
    // Threshold between the normal kinetic energy at 20° and at 45° (m = 8.4e-5 kg: ½ m v_n² = 2.0e-5 J
    // and 8.4e-5 J), so the 20° impact erodes nothing.
    let (c, e_th) = (1e-4, 5e-5);
    let model = WearModel::NormalEnergy { coefficient: c, threshold: e_th };
    let src = "normal impact-energy threshold model: c max(0, m v_n^2 / 2 - E_th)";
    for g in [90.0, 45.0, 20.0] {
        let i = single_impact(model, g, speed, 2000);
        let (want, got, scale) = match &i {
            Some(i) => {
                let vn = speed * f64::to_radians(g).sin();
                (c * (0.5 * i.mass * vn * vn - e_th).max(0.0), i.total_mass, c * 0.5 * i.mass * speed * speed)
            }
            None => (0.0, nan, 0.0),
        };
        out.push(Check::absolute(
            case,
            format!("normal energy, {g} deg: eroded mass [kg]"),
            want,
            got,
            1e-9 * scale,
            src,
        ));
    }
    out
}
