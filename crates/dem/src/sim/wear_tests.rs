//! Erosion wear on mesh walls through the engine: one oblique impact against the closed form, a
//! symmetric pattern on a symmetric panel, the body mass of a clump.

use super::*;
use crate::clump::{ClumpTemplate, NewBody};
use crate::contact::{HertzMindlin, PairProps, PairTable};
use crate::validation::impact::rigid;
use crate::walls::{MeshWall, Wall, WallShape};
use crate::wear::{finnie_f, WearModel, WearTable};
use spatter_core::math::sphere_volume;
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use spatter_core::Quat;

fn panel_sim(n: usize, l: f64, model: WearModel) -> Simulation<HertzMindlin> {
    let m = Material::new(1e8, 0.3, 2500.0).unwrap();
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

/// One sphere hits the panel at γ = 30° to its plane with 2 m/s (no gravity): Finnie's eroded mass is
/// k m v² f(30°) = k m v² cos²(30°)/3 with the velocity at first touch (the initial one), on one triangle,
/// with one impact at 30°.
#[test]
fn a_single_oblique_impact_erodes_the_closed_form_mass() {
    let mut sim = panel_sim(2, 0.04, WearModel::Finnie { k: 0.5 });
    let r = 2e-3;
    let g = 30f64.to_radians();
    let v = 2.0 * Vec3::new(g.cos(), 0.0, -g.sin());
    let hit = Vec3::new(0.012, 0.006, 0.0); // inside one triangle's face
    let x0 = hit + Vec3::new(0.0, 0.0, r) - v * (5e-5 / v.z.abs());
    let mut p = crate::NewParticle::at(x0, r, 0);
    p.vel = v;
    sim.add_particle(p);
    sim.run_steps(2000).unwrap();
    let mass = 2500.0 * sphere_volume(r);
    let want = 0.5 * mass * 4.0 * finnie_f(g);
    let WallShape::Mesh(m) = &sim.walls[0].shape else { unreachable!() };
    let rec = &m.records;
    assert_eq!(rec.impacts.iter().sum::<u64>(), 1);
    let t = rec.impacts.iter().position(|&k| k == 1).unwrap();
    assert!((rec.eroded_mass[t] - want).abs() < 1e-12 * want, "{} against {want}", rec.eroded_mass[t]);
    assert!((rec.impact_angle_sum[t] - 30.0).abs() < 1e-9);
    assert!((sim.eroded_mass(0) - want).abs() < 1e-12 * want);
    // Finnie f(30°) = cos²30°/3 = 0.25.
    assert!((finnie_f(g) - 0.25).abs() < 1e-15);
}

/// Spheres rain on a square panel in pairs placed point-symmetrically about its centre (the second of a
/// pair at C − (x − C) with the velocity turned by 180° about the normal). The rectangle's triangulation
/// is point-symmetric too (triangle 2k of square (i, j) ↔ triangle 2k+1 of square (n−1−i, n−1−j)), so the
/// eroded mass per triangle must be point-symmetric, for both models.
#[test]
fn a_symmetric_rain_on_a_symmetric_panel_erodes_a_symmetric_pattern() {
    for model in
        [WearModel::Finnie { k: 1.0 }, WearModel::NormalEnergy { coefficient: 1e-3, threshold: 1e-5 }]
    {
        let (n, l) = (4, 0.08);
        let mut sim = panel_sim(n, l, model);
        let c = Vec3::new(0.5 * l, 0.5 * l, 0.0);
        let r = 1.5e-3;
        let mut rng = spatter_core::rng::seeded(5, 0);
        use spatter_core::rng::RngExt;
        for k in 0..12 {
            let d = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, 0.0) * (0.8 * l);
            let ang = rng.random::<f64>() * std::f64::consts::TAU;
            let vt = 0.5 + rng.random::<f64>();
            let v = Vec3::new(vt * ang.cos(), vt * ang.sin(), -1.0 - rng.random::<f64>());
            let h = r + 0.002 + 0.002 * k as f64;
            for (x, vel) in [(c + d, v), (c - d, Vec3::new(-v.x, -v.y, v.z))] {
                let mut p = crate::NewParticle::at(Vec3::new(x.x, x.y, h), r, 0);
                p.vel = vel;
                sim.add_particle(p);
            }
        }
        sim.run_steps(40_000).unwrap();
        let WallShape::Mesh(m) = &sim.walls[0].shape else { unreachable!() };
        let e = &m.records.eroded_mass;
        let total: f64 = e.iter().sum();
        let impacts: u64 = m.records.impacts.iter().sum();
        assert!(
            total > 0.0 && impacts >= 16 && impacts % 2 == 0,
            "{}: total {total}, impacts {impacts}",
            model.name()
        );
        for j in 0..n {
            for i in 0..n {
                for s in 0..2 {
                    let a = 2 * (j * n + i) + s;
                    let b = 2 * ((n - 1 - j) * n + (n - 1 - i)) + (1 - s);
                    assert_eq!(m.records.impacts[a], m.records.impacts[b]);
                    assert!(
                        (e[a] - e[b]).abs() <= 1e-9 * total,
                        "{}: triangle {a} {} vs {b} {}",
                        model.name(),
                        e[a],
                        e[b]
                    );
                }
            }
        }
    }
}

/// A clump erodes with its whole mass: a two-sphere body hitting the panel with one member at 30°.
#[test]
fn a_clump_erodes_with_the_body_mass() {
    let mut sim = panel_sim(2, 0.04, WearModel::Finnie { k: 1.0 });
    let r = 2e-3;
    let t = sim.add_template(ClumpTemplate::from_spheres(
        "pair",
        &[(Vec3::new(-r, 0.0, 0.0), r), (Vec3::new(r, 0.0, 0.0), r)],
    ));
    let g = 30f64.to_radians();
    let v = 2.0 * Vec3::new(g.cos(), 0.0, -g.sin());
    // Body axis vertical: the lower member hits first and alone.
    let q = Quat::from_rotation_y(std::f64::consts::FRAC_PI_2);
    let hit = Vec3::new(0.012, 0.006, 0.0);
    let x0 = hit + Vec3::new(0.0, 0.0, 2.0 * r) - v * (5e-5 / v.z.abs());
    sim.add_clump(t, 0, NewBody { pos: x0, quat: q, vel: v, omega: Vec3::ZERO }).unwrap();
    sim.run_steps(300).unwrap();
    let mass = 2.0 * 2500.0 * sphere_volume(r);
    let want = mass * 4.0 * finnie_f(g);
    let got = sim.eroded_mass(0);
    assert!((got - want).abs() < 1e-9 * want, "{got} against {want}");
}
