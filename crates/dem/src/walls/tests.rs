//! Analytic plane versus the same plane as a two-triangle STL, impacts on a face, the shared edge and a
//! shared vertex; mesh contact rules on convex and concave corners.

use super::*;
use crate::contact::{
    Composed, ContactLaw, Frictionless, Hertz, HertzMindlin, NoRolling, RestitutionDamping,
};
use crate::particles::NewParticle;
use crate::sim::{uniform_pairs, Settings, Simulation};
use spatter_core::material::Material;
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use std::path::Path;

/// The unit square at z = 0 as a binary STL of two triangles (shared diagonal from (0,0) to (1,1)),
/// read back through the STL reader.
pub(crate) fn two_triangle_square(dir: &Path) -> TriMesh {
    let m = TriMesh::rectangle(1.0, 1.0, 0.0, 1, 1);
    assert_eq!(m.triangles.len(), 2);
    let path = dir.join("square.stl");
    std::fs::write(&path, m.to_binary_stl()).unwrap();
    TriMesh::load(&path, 1.0).unwrap()
}

fn impact(wall: WallShape, x0: Vec3, v0: Vec3, w0: Vec3) -> (Vec3, Vec3, f64) {
    let al = Material::new(70e9, 0.3, 2699.0).unwrap();
    let mats = vec![al.clone(), Material::new(f64::INFINITY, 0.3, 2699.0).unwrap()];
    let pairs = uniform_pairs(&mats, 0.3, 0.8);
    let r = 0.01;
    let m = 2699.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let tc = spatter_core::timestep::hertz_time(m, r, pairs.get(0, 1).e_star, v0.z.abs());
    let mut sim = Simulation::new(HertzMindlin::default(), mats, pairs, tc / 200.0, Settings::default());
    sim.add_wall(Wall { name: "floor".into(), shape: wall, material: 1, motion: Motion::Fixed });
    let mut p = NewParticle::at(x0, r, 0);
    p.vel = v0;
    p.omega = w0;
    sim.add_particle(p);
    let mut fmax: f64 = 0.0;
    for _ in 0..600 {
        sim.step().unwrap();
        fmax = fmax.max(sim.particles.force[0].z);
    }
    (sim.particles.vel[0], sim.particles.omega[0], fmax)
}

#[test]
fn analytic_plane_and_two_triangle_stl_agree_on_face_edge_and_vertex() {
    // Reference: the analytic plane. The STL must give the same rebound (1e-9 relative: only round-off
    // differs) for a normal and an oblique impact at a face point, on the shared diagonal edge, and on the
    // shared corner vertex (moving into the plate).
    let dir = tempfile::tempdir().unwrap();
    let mesh = two_triangle_square(dir.path());
    let r = 0.01;
    let h = r + 1e-5;
    for (name, xy) in [("face", (0.7, 0.25)), ("edge", (0.5, 0.5)), ("vertex", (0.0, 0.0))] {
        for v0 in [Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.3, 0.2, -1.0)] {
            let x0 = Vec3::new(xy.0, xy.1, h);
            let w0 = Vec3::new(0.0, 3.0, 0.0);
            let plane = WallShape::Plane(Plane::new(Vec3::ZERO, Vec3::Z));
            let stl = WallShape::Mesh(Box::new(MeshWall::new(mesh.clone())));
            let (va, wa, fa) = impact(plane, x0, v0, w0);
            let (vb, wb, fb) = impact(stl, x0, v0, w0);
            assert!(va.z > 0.5, "{name}: bounced ({va})");
            let close = |a: Vec3, b: Vec3| (a - b).length() <= 1e-9 * a.length().max(1e-3);
            assert!(close(va, vb), "{name} {v0}: velocity plane {va} vs STL {vb}");
            assert!(close(wa, wb), "{name} {v0}: spin plane {wa} vs STL {wb}");
            assert!((fa - fb).abs() <= 1e-9 * fa, "{name} {v0}: F_max plane {fa} vs STL {fb}");
        }
    }
}

#[test]
fn convex_edge_gives_one_contact_and_concave_corner_two() {
    // A roof ridge: two triangles meeting at 90° along the x axis (edge y = 0, z = 0).
    let soup = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 1.0, -1.0),
        Vec3::new(1.0, 0.0, 0.0),
    ];
    let roof = MeshWall::new(TriMesh::from_triangle_soup(&soup));
    let (mut raw, mut hits) = (mesh::HitBuffer::default(), mesh::HitBuffer::default());
    // Directly above the ridge: one edge contact with normal +z.
    roof.resolve(Vec3::new(0.5, 0.0, 0.05), 0.1, &[0, 1], &mut raw, &mut hits);
    assert_eq!(hits.len(), 1);
    assert!((hits.as_slice()[0].normal - Vec3::Z).length() < 1e-12);
    // A valley (the same ridge seen from below): a sphere in the groove touches both faces.
    let valley = MeshWall::new(TriMesh::from_triangle_soup(&soup.map(|v| Vec3::new(v.x, v.y, -v.z))));
    valley.resolve(Vec3::new(0.5, 0.0, 0.1), 0.1, &[0, 1], &mut raw, &mut hits);
    assert_eq!(hits.len(), 2, "concave: one contact per face");
    // A flat fan of six triangles around a vertex: a sphere above a face near the centre gets one contact.
    let mut fan = Vec::new();
    for k in 0..6 {
        let a = k as f64 * std::f64::consts::PI / 3.0;
        let b = (k + 1) as f64 * std::f64::consts::PI / 3.0;
        fan.extend_from_slice(&[
            Vec3::ZERO,
            Vec3::new(a.cos(), a.sin(), 0.0),
            Vec3::new(b.cos(), b.sin(), 0.0),
        ]);
    }
    let fan = MeshWall::new(TriMesh::from_triangle_soup(&fan));
    for x in [Vec3::new(0.02, 0.005, 0.01), Vec3::new(0.0, 0.0, 0.01), Vec3::new(0.03, 0.0, 0.01)] {
        fan.resolve(x, 0.02, &[0, 1, 2, 3, 4, 5], &mut raw, &mut hits);
        assert_eq!(hits.len(), 1, "fan at {x}: {:?}", hits.as_slice());
        assert!((hits.as_slice()[0].distance - 0.01).abs() < 1e-15);
    }
}

#[test]
fn rectangle_contacts_inside_outside_and_at_its_edges() {
    // Closest-point geometry of a 0.2 × 0.1 m plate in z = 0 (to 1e-12, round-off of the inputs): above
    // and below its
    // face the normal is ±z; beyond its extent by more than the reach there is no contact; near an edge
    // (corner) the contact point is on the edge (corner) and the normal points from there to the centre.
    let rect =
        Rectangle { center: Vec3::ZERO, half_u: Vec3::new(0.1, 0.0, 0.0), half_v: Vec3::new(0.0, 0.05, 0.0) };
    let near = |a: Vec3, b: Vec3| (a - b).length() < 1e-12;
    let (q, n, d) = rect.hit(Vec3::new(0.03, -0.02, 0.004), 0.005).unwrap();
    assert!(near(q, Vec3::new(0.03, -0.02, 0.0)) && near(n, Vec3::Z) && (d - 0.004).abs() < 1e-12);
    let (_, n, _) = rect.hit(Vec3::new(0.03, 0.02, -0.004), 0.005).unwrap();
    assert!(near(n, -Vec3::Z), "two-sided: {n}");
    // Beyond the short edge: closest point (0.1, 0, 0), distance √(0.01² + 0.004²) = 0.01077 > reach.
    assert_eq!(rect.hit(Vec3::new(0.11, 0.0, 0.004), 0.005), None);
    // Beyond the long edge, 3 mm out and 4 mm up: a 3-4-5 triangle, distance 5 mm, normal (0.6, 0, 0.8).
    let (q, n, d) = rect.hit(Vec3::new(0.103, 0.01, 0.004), 0.006).unwrap();
    assert!(near(q, Vec3::new(0.1, 0.01, 0.0)) && near(n, Vec3::new(0.6, 0.0, 0.8)));
    assert!((d - 0.005).abs() < 1e-12);
    assert_eq!(rect.hit(Vec3::new(0.103, 0.01, 0.004), 0.0049), None, "beyond the reach");
    // In the plane, off a corner: normal (0.6, 0.8, 0).
    let (q, n, _) = rect.hit(Vec3::new(0.103, 0.054, 0.0), 0.006).unwrap();
    assert!(near(q, Vec3::new(0.1, 0.05, 0.0)) && near(n, Vec3::new(0.6, 0.8, 0.0)));
}

/// An aluminium sphere (r = 1 cm) moving at `v0` from `x0` against `wall` (rigid), elastic and
/// frictionless, for 1000 steps of 1/200 of the Hertz contact time at 1 m/s. Returns the final velocity.
fn elastic_frictionless(wall: WallShape, x0: Vec3, v0: Vec3) -> Vec3 {
    let al = Material::new(70e9, 0.3, 2699.0).unwrap();
    let mats = vec![al.clone(), Material::new(f64::INFINITY, 0.3, 2699.0).unwrap()];
    let pairs = uniform_pairs(&mats, 0.0, 1.0);
    let r = 0.01;
    let m = 2699.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let tc = spatter_core::timestep::hertz_time(m, r, pairs.get(0, 1).e_star, 1.0);
    let mut sim = Simulation::new(HertzMindlin::default(), mats, pairs, tc / 200.0, Settings::default());
    sim.add_wall(Wall { name: "plate".into(), shape: wall, material: 1, motion: Motion::Fixed });
    let mut p = NewParticle::at(x0, r, 0);
    p.vel = v0;
    sim.add_particle(p);
    sim.run_steps(1000).unwrap();
    sim.particles.vel[0]
}

#[test]
fn a_sphere_bounces_off_a_rectangle_misses_it_outside_and_is_deflected_by_its_edge() {
    // Rigid-body reflection about the contact normal, v' = v − 2(v·n)n (elastic, frictionless). On the
    // face n = z: v' = −v (1e-5 relative: the energy error of velocity Verlet at 200 steps per contact is
    // 1.1e-6 here). Outside the extent the
    // path passes 1 mm from the edge: untouched (exact). At the edge, a sphere falling at horizontal
    // offset b = 0.6 r beyond it touches the edge line with n = (sin θ, 0, cos θ), sin θ = 0.6, so
    // v' = V (sin 2θ, 0, cos 2θ) = V (0.96, 0, 0.28). The contact slides round the edge during the
    // impact (tangential speed 0.6 V for t_c = 53 µs), so the normal turns by about 0.6 V t_c/r = 3.2e-3
    // rad, which the rigid formula ignores: 5e-3 V per component.
    let r = 0.01;
    let plate = || {
        WallShape::Rectangle(Rectangle {
            center: Vec3::ZERO,
            half_u: Vec3::new(0.1, 0.0, 0.0),
            half_v: Vec3::new(0.0, 0.1, 0.0),
        })
    };
    let down = Vec3::new(0.0, 0.0, -1.0);
    let v = elastic_frictionless(plate(), Vec3::new(0.02, 0.03, r + 1e-5), down);
    assert!((v - Vec3::Z).length() < 1e-5, "face: {v}");
    let v = elastic_frictionless(plate(), Vec3::new(0.1 + r + 1e-3, 0.0, r + 1e-5), down);
    assert_eq!(v, down, "outside the plate the sphere falls past");
    let b = 0.6 * r;
    let v = elastic_frictionless(plate(), Vec3::new(0.1 + b, 0.0, 0.8 * r + 1e-5), down);
    let expect = Vec3::new(0.96, 0.0, 0.28);
    assert!((v - expect).abs().max_element() < 5e-3, "edge: {v} vs {expect}");
    assert!((v.length() - 1.0).abs() < 1e-5, "elastic: |v| = {}", v.length());
}

/// The aluminium sphere of [`impact`] (r = 1 cm, μ = 0.3, e = 0.8, Δt = t_c/200 at 1 m/s) against the
/// two-triangle STL square as floor, optionally under a rigid analytic ceiling at height `ceiling`, no
/// gravity.
fn on_stl_floor(dir: &Path, x0: Vec3, v0: Vec3, ceiling: Option<f64>) -> Simulation<HertzMindlin> {
    on_stl_floor_with(HertzMindlin::default(), dir, x0, v0, ceiling)
}

/// [`on_stl_floor`] with contact law `law`.
fn on_stl_floor_with<L: ContactLaw>(
    law: L,
    dir: &Path,
    x0: Vec3,
    v0: Vec3,
    ceiling: Option<f64>,
) -> Simulation<L> {
    let al = Material::new(70e9, 0.3, 2699.0).unwrap();
    let mats = vec![al.clone(), Material::new(f64::INFINITY, 0.3, 2699.0).unwrap()];
    let pairs = uniform_pairs(&mats, 0.3, 0.8);
    let r = 0.01;
    let m = 2699.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let tc = spatter_core::timestep::hertz_time(m, r, pairs.get(0, 1).e_star, 1.0);
    let mut sim = Simulation::new(law, mats, pairs, tc / 200.0, Settings::default());
    let floor = WallShape::Mesh(Box::new(MeshWall::new(two_triangle_square(dir))));
    sim.add_wall(Wall { name: "floor".into(), shape: floor, material: 1, motion: Motion::Fixed });
    if let Some(h) = ceiling {
        let shape = WallShape::Plane(Plane::new(Vec3::new(0.0, 0.0, h), -Vec3::Z));
        sim.add_wall(Wall { name: "ceiling".into(), shape, material: 1, motion: Motion::Fixed });
    }
    let mut p = NewParticle::at(x0, r, 0);
    p.vel = v0;
    sim.add_particle(p);
    sim
}

fn floor_records<L: ContactLaw>(sim: &Simulation<L>) -> &MeshRecords {
    match &sim.walls[0].shape {
        WallShape::Mesh(m) => &m.records,
        _ => unreachable!("wall 0 is the STL floor"),
    }
}

#[test]
fn stl_impact_records_equal_the_momentum_change_and_count_each_impact_once() {
    // No gravity, so the contact force alone changes the momentum, and under velocity Verlet
    // v_out − v_in = Σ_k F_k Δt/m exactly (the half kicks of consecutive steps add up, F = 0 before and
    // after the contact): the records Σ|F_n|Δt and Σ|F_t|Δt must equal m |Δv_n| = m (v_in + v_out) and,
    // for an impact sliding throughout (F_t keeps its direction), m |Δv_t|. Tolerance 1e-9 relative:
    // round-off only. Impacts at a face point, on the shared diagonal edge and at the shared corner
    // vertex, straight down at 1 m/s and oblique at (3, 0, −1) m/s: 3 > (7/2) μ (1 + e) = 1.89, so the
    // contact slides for its whole duration (Maw, Barber & Fawcett 1976; Chung & Ooi 2011 test 4). Each
    // is one impact on exactly one triangle, whose mean impact speed is the approach speed 1 m/s (1e-12:
    // nothing acts before the contact).
    let dir = tempfile::tempdir().unwrap();
    let r = 0.01;
    let h = r + 1e-5;
    for (name, xy) in [("face", (0.7, 0.25)), ("edge", (0.5, 0.5)), ("vertex", (0.0, 0.0))] {
        for v0 in [Vec3::new(0.0, 0.0, -1.0), Vec3::new(3.0, 0.0, -1.0)] {
            let mut sim = on_stl_floor(dir.path(), Vec3::new(xy.0, xy.1, h), v0, None);
            sim.run_steps(600).unwrap();
            assert_eq!(sim.last_evaluation().wall_contacts, 0, "{name} {v0}: the impact is over");
            let m = 1.0 / sim.particles.inv_mass[0];
            let v1 = sim.particles.vel[0];
            assert!(v1.z > 0.5, "{name} {v0}: bounced ({v1})");
            let rec = floor_records(&sim);
            let jn: f64 = rec.normal_impulse.iter().sum();
            let jt: f64 = rec.tangential_impulse.iter().sum();
            let dv_n = m * (v1.z - v0.z);
            let dv_t = m * (v1 - v0).truncate().length();
            assert!((jn / dv_n - 1.0).abs() < 1e-9, "{name} {v0}: normal impulse {jn} vs m Δv_n {dv_n}");
            if v0.x == 0.0 {
                assert!(jt <= 1e-9 * jn, "{name} {v0}: tangential impulse {jt} of a head-on impact");
            } else {
                assert!(dv_t > 0.1 * dv_n, "{name} {v0}: friction acted ({dv_t})");
                assert!(
                    (jt / dv_t - 1.0).abs() < 1e-9,
                    "{name} {v0}: tangential impulse {jt} vs m Δv_t {dv_t}"
                );
            }
            let hit: Vec<usize> = (0..rec.impacts.len()).filter(|&t| rec.impacts[t] > 0).collect();
            assert_eq!(hit.len(), 1, "{name} {v0}: impacts per triangle {:?}", rec.impacts);
            assert_eq!(rec.impacts[hit[0]], 1, "{name} {v0}: impacts per triangle {:?}", rec.impacts);
            let speed = rec.impact_speed_sum[hit[0]];
            assert!((speed - 1.0).abs() < 1e-12, "{name} {v0}: mean impact speed {speed}");
        }
    }
    // Two bounces on the shared edge, with a rigid ceiling 0.1 mm above the rebounding sphere: two
    // impacts, and the impulse is the floor's share of the momentum changes, m (u₁ − u₀ + u₃ − u₂), with
    // u₀ … u₃ the vertical free-flight velocities between the contacts (floor, ceiling, floor).
    let mut sim =
        on_stl_floor(dir.path(), Vec3::new(0.5, 0.5, h), Vec3::new(0.0, 0.0, -1.0), Some(2.0 * r + 1e-4));
    let mut free: Vec<f64> = vec![-1.0];
    let mut steps = 0;
    while free.len() < 4 && steps < 20_000 {
        sim.step().unwrap();
        steps += 1;
        let vz = sim.particles.vel[0].z;
        if sim.last_evaluation().wall_contacts == 0 && vz != *free.last().unwrap() {
            free.push(vz);
        }
    }
    assert_eq!(free.len(), 4, "floor, ceiling, floor: free-flight speeds {free:?}");
    assert!(free[1] > 0.0 && free[2] < 0.0 && free[3] > 0.0, "{free:?}");
    let m = 1.0 / sim.particles.inv_mass[0];
    let rec = floor_records(&sim);
    assert_eq!(rec.impacts.iter().sum::<u64>(), 2, "impacts per triangle {:?}", rec.impacts);
    let jn: f64 = rec.normal_impulse.iter().sum();
    let expect = m * (free[1] - free[0] + free[3] - free[2]);
    assert!((jn / expect - 1.0).abs() < 1e-9, "normal impulse {jn} vs {expect}");
    let speeds: f64 = rec.impact_speed_sum.iter().sum();
    assert!((speeds - (1.0 - free[2])).abs() < 1e-12, "impact speeds {speeds} vs 1 + {}", -free[2]);
}

/// Hertz with restitution damping and no friction: a law whose contacts keep no state at all.
type Stateless = Composed<Hertz, RestitutionDamping, Frictionless, NoRolling>;

#[test]
fn a_contact_of_a_stateless_law_is_one_impact_however_long_it_lasts() {
    // A contact forms when its wall slot was not in contact in the previous evaluation, not when the
    // law's state equals its default (which a stateless law's always does). Head-on bounces at 1 m/s
    // on the two-triangle STL (face point, shared edge, shared vertex; ~200 steps in contact) are one
    // impact each, with the approach speed 1 m/s (1e-12) and Σ|F_n|Δt = m (v_in + v_out) (1e-9, as
    // for Hertz–Mindlin above); two bounces under a ceiling are two.
    let law = Stateless::default();
    assert_eq!(<Stateless as ContactLaw>::State::default(), Default::default());
    let dir = tempfile::tempdir().unwrap();
    let r = 0.01;
    let h = r + 1e-5;
    for (name, xy) in [("face", (0.7, 0.25)), ("edge", (0.5, 0.5)), ("vertex", (0.0, 0.0))] {
        let v0 = Vec3::new(0.0, 0.0, -1.0);
        let mut sim = on_stl_floor_with(law, dir.path(), Vec3::new(xy.0, xy.1, h), v0, None);
        sim.run_steps(600).unwrap();
        let m = 1.0 / sim.particles.inv_mass[0];
        let v1 = sim.particles.vel[0];
        assert!(v1.z > 0.5 && sim.last_evaluation().wall_contacts == 0, "{name}: bounced ({v1})");
        let rec = floor_records(&sim);
        assert_eq!(rec.impacts.iter().sum::<u64>(), 1, "{name}: impacts per triangle {:?}", rec.impacts);
        let speed: f64 = rec.impact_speed_sum.iter().sum();
        assert!((speed - 1.0).abs() < 1e-12, "{name}: impact speed {speed}");
        let jn: f64 = rec.normal_impulse.iter().sum();
        assert!((jn / (m * (v1.z - v0.z)) - 1.0).abs() < 1e-9, "{name}: normal impulse {jn}");
    }
    let mut sim = on_stl_floor_with(
        law,
        dir.path(),
        Vec3::new(0.5, 0.5, h),
        Vec3::new(0.0, 0.0, -1.0),
        Some(2.0 * r + 1e-4),
    );
    let mut ups = 0;
    let mut was_up = false;
    for _ in 0..20_000 {
        sim.step().unwrap();
        let up = sim.particles.vel[0].z > 0.0 && sim.last_evaluation().wall_contacts == 0;
        ups += (up && !was_up) as u32;
        was_up = up;
        if ups == 2 {
            break;
        }
    }
    assert_eq!(ups, 2, "two floor bounces");
    assert_eq!(floor_records(&sim).impacts.iter().sum::<u64>(), 2, "{:?}", floor_records(&sim).impacts);
}

/// A soft sphere (E = 50 MPa, r = 1 cm) resting under gravity at its static Hertz overlap on the
/// two-triangle STL, at (0.45, 0.5), sliding at 1 m/s along x across the shared diagonal (x = y), Δt = 20 µs.
fn resting_slider<L: ContactLaw>(law: L, dir: &Path) -> Simulation<L> {
    let soft = Material::new(5e7, 0.3, 2500.0).unwrap();
    let mats = vec![soft];
    let pairs = uniform_pairs(&mats, 0.5, 0.5);
    let mut sim = Simulation::new(law, mats, pairs.clone(), 2e-5, Settings::default());
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    let floor = WallShape::Mesh(Box::new(MeshWall::new(two_triangle_square(dir))));
    sim.add_wall(Wall { name: "floor".into(), shape: floor, material: 0, motion: Motion::Fixed });
    let r = 0.01;
    let m = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let delta = (3.0 * m * 9.81 / (4.0 * pairs.get(0, 0).e_star * r.sqrt())).powf(2.0 / 3.0);
    let mut p = NewParticle::at(Vec3::new(0.45, 0.5, r - delta), r, 0);
    p.vel = Vec3::new(1.0, 0.0, 0.0);
    sim.add_particle(p);
    sim
}

#[test]
fn a_contact_sliding_across_a_seam_through_rebuilds_and_a_checkpoint_is_one_impact() {
    // The resting slider of [`resting_slider`] stays in contact for 7500 steps (0.15 s, to x ≈ 0.6, or
    // 0.565 for Hertz–Mindlin, whose friction soon makes it roll at 5/7 of the speed; > 0.55 checked): it
    // crosses from one triangle to the other (both carry normal impulse), the lists are rebuilt every
    // ~1 mm of travel (half the default skin of 10 % of the diameter), and the run is checkpointed
    // (written and read back) and resumed half-way. Exactly one impact is recorded, for the stateless
    // law as for Hertz–Mindlin, and the resumed run's records equal the uninterrupted run's bit for bit.
    fn check<L: ContactLaw>(law: L, name: &str) {
        let dir = tempfile::tempdir().unwrap();
        let mut sim = resting_slider(law.clone(), dir.path());
        sim.run_steps(3750).unwrap();
        let path = dir.path().join("checkpoint.bin");
        spatter_io::checkpoint::save(&path, 0, &sim.state()).unwrap();
        sim.run_steps(3750).unwrap();
        let mut resumed = resting_slider(law, dir.path());
        resumed.restore(spatter_io::checkpoint::load(&path, 0).unwrap()).unwrap();
        resumed.run_steps(3750).unwrap();
        for (run, s) in [("uninterrupted", &sim), ("resumed", &resumed)] {
            assert!(
                s.particles.pos[0].x > 0.55,
                "{name} {run}: crossed the diagonal ({})",
                s.particles.pos[0]
            );
            assert!(s.rebuild_count() > 20, "{name} {run}: lists rebuilt {} times", s.rebuild_count());
            assert_eq!(s.last_evaluation().wall_contacts, 1, "{name} {run}: still in contact");
            let rec = floor_records(s);
            assert!(rec.normal_impulse.iter().all(|&j| j > 0.0), "{name} {run}: {:?}", rec.normal_impulse);
            assert_eq!(
                rec.impacts.iter().sum::<u64>(),
                1,
                "{name} {run}: impacts per triangle {:?}",
                rec.impacts
            );
        }
        assert_eq!(floor_records(&sim), floor_records(&resumed), "{name}: resumed records differ");
    }
    check(Stateless::default(), "stateless");
    check(HertzMindlin::default(), "Hertz–Mindlin");
}

#[test]
fn ball_and_rod_contacts_on_faces_edges_and_inside() {
    // Closest-point geometry (exact up to round-off, 1e-12): a ball of radius 2 cm at the origin and a
    // rod of radius 1 cm from z = 0 to z = 5 cm along +z.
    let near = |a: Vec3, b: Vec3| (a - b).length() < 1e-12;
    let ball = Ball { center: Vec3::ZERO, radius: 0.02 };
    // 3-4-5 direction at distance 0.025 from the centre: 5 mm from the surface, normal outward.
    let (q, n, d) = ball.hit(Vec3::new(0.015, 0.0, 0.02), 0.006).unwrap();
    assert!(near(n, Vec3::new(0.6, 0.0, 0.8)) && near(q, Vec3::new(0.012, 0.0, 0.016)));
    assert!((d - 0.005).abs() < 1e-12);
    assert_eq!(ball.hit(Vec3::new(0.015, 0.0, 0.02), 0.005), None, "beyond the reach");
    let (_, _, d) = ball.hit(Vec3::new(0.0, 0.0, 0.01), 0.001).unwrap();
    assert!((d + 0.01).abs() < 1e-12, "inside the ball the distance is negative: {d}");

    let rod = Rod { base: Vec3::ZERO, axis: Vec3::Z, radius: 0.01, length: 0.05 };
    // Below the flat end: normal −z, contact point straight above.
    let (q, n, d) = rod.hit(Vec3::new(0.004, 0.003, -0.002), 0.003).unwrap();
    assert!(near(q, Vec3::new(0.004, 0.003, 0.0)) && near(n, -Vec3::Z) && (d - 0.002).abs() < 1e-12);
    // Beside the side: radial normal.
    let (q, n, d) = rod.hit(Vec3::new(0.0, 0.013, 0.02), 0.004).unwrap();
    assert!(near(q, Vec3::new(0.0, 0.01, 0.02)) && near(n, Vec3::Y) && (d - 0.003).abs() < 1e-12);
    // Off the lower rim, 3 mm out and 4 mm down: distance 5 mm, normal (0.6, 0, −0.8).
    let (q, n, d) = rod.hit(Vec3::new(0.013, 0.0, -0.004), 0.006).unwrap();
    assert!(near(q, Vec3::new(0.01, 0.0, 0.0)) && near(n, Vec3::new(0.6, 0.0, -0.8)));
    assert!((d - 0.005).abs() < 1e-12);
    // Above the top end, and inside near the bottom face (leaves through it: distance −1 mm, normal −z).
    let (_, n, _) = rod.hit(Vec3::new(0.0, 0.0, 0.052), 0.003).unwrap();
    assert!(near(n, Vec3::Z));
    let (_, n, d) = rod.hit(Vec3::new(0.002, 0.0, 0.001), 0.001).unwrap();
    assert!(near(n, -Vec3::Z) && (d + 0.001).abs() < 1e-12, "inside: {n} {d}");
    let (_, n, d) = rod.hit(Vec3::new(0.0, -0.009, 0.02), 0.001).unwrap();
    assert!(near(n, -Vec3::Y) && (d + 0.001).abs() < 1e-12, "inside near the side: {n} {d}");
}

#[test]
fn a_sphere_reflects_off_a_ball_and_off_a_rod_end_as_off_a_rigid_body() {
    // Elastic, frictionless: v' = v − 2(v·n)n with n the contact normal (tolerances as in the rectangle
    // test above). A sphere falling onto the top of a ball at a horizontal offset b from its centre line
    // touches it with n = (b/(R + r), 0, √(1 − (b/(R + r))²)); the rotation of the normal during the
    // contact is small (t_c ≈ 53 µs at 1 m/s), 5e-3 V per component. Onto a rod's flat end: v' = −v.
    let r = 0.01;
    let down = Vec3::new(0.0, 0.0, -1.0);
    let ball = WallShape::Ball(Ball { center: Vec3::ZERO, radius: 0.02 });
    let s = 0.6;
    let zc = 0.03 * (1.0f64 - s * s).sqrt();
    let v = elastic_frictionless(ball, Vec3::new(0.03 * s, 0.0, zc + 1e-5), down);
    let expect = Vec3::new(2.0 * s * 0.8, 0.0, 2.0 * 0.8 * 0.8 - 1.0);
    assert!((v - expect).abs().max_element() < 5e-3, "ball: {v} vs {expect}");
    assert!((v.length() - 1.0).abs() < 1e-5);
    let rod =
        WallShape::Rod(Rod { base: Vec3::new(0.0, 0.0, -0.05), axis: Vec3::Z, radius: 0.02, length: 0.05 });
    let v = elastic_frictionless(rod, Vec3::new(0.005, 0.0, r + 1e-5), down);
    assert!((v - Vec3::Z).length() < 1e-5, "rod end: {v}");
}
