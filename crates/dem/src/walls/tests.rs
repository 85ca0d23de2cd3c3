//! Analytic plane versus the same plane as a two-triangle STL, impacts on a face, the shared edge and a
//! shared vertex; mesh contact rules on convex and concave corners.

use super::*;
use crate::contact::HertzMindlin;
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
