//! Erosion wear on mesh walls through the engine: one oblique impact against the closed form, a
//! symmetric pattern on a symmetric panel, the body mass of a clump.

use super::*;
use crate::clump::{ClumpTemplate, NewBody};
use crate::validation::wear::{panel_sim, single_impact};
use crate::walls::WallShape;
use crate::wear::{finnie_f, WearModel};
use spatter_core::math::sphere_volume;
use spatter_core::Quat;

/// One sphere hits the panel at γ = 30° to its plane with 2 m/s (no gravity): Finnie's eroded mass is
/// k m v² f(30°) = k m v² cos²(30°)/3 with the velocity at first touch (the initial one), on one triangle,
/// with one impact at 30°.
#[test]
fn a_single_oblique_impact_erodes_the_closed_form_mass() {
    let k = 0.5;
    let i = single_impact(WearModel::Finnie { k }, 30.0, 2.0, 2000).expect("the sphere hits the panel");
    let g = 30f64.to_radians();
    let want = k * i.mass * 4.0 * finnie_f(g);
    assert_eq!(i.impacts, 1);
    assert!((i.triangle_mass - want).abs() < 1e-12 * want, "{} against {want}", i.triangle_mass);
    assert!((i.angle_deg - 30.0).abs() < 1e-9);
    assert!((i.total_mass - want).abs() < 1e-12 * want);
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
