//! Solids that clump templates are filled from: sphere, ellipsoid, cut sphere, rounded tetrahedron and
//! rounded square pyramid, and any closed triangle mesh.
//!
//! A solid answers one question for the fill, its *depth* at a point: the distance to its surface,
//! positive inside (exact), negative outside (only the sign is used).

use spatter_core::mesh::{closest_point_on_triangle, TriMesh};
use spatter_core::tri_bvh::TriBvh;
use spatter_core::{Aabb, Vec3};
use std::f64::consts::PI;

/// A closed solid (module docs).
pub trait Solid: Sync {
    /// Distance from `p` to the surface, positive inside \[m\].
    fn depth(&self, p: Vec3) -> f64;
    /// Bounding box \[m\].
    fn bounds(&self) -> Aabb;
    /// Volume \[m³\].
    fn volume(&self) -> f64;
}

/// A ball of radius `radius` \[m\] at the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ball {
    pub radius: f64,
}

impl Solid for Ball {
    fn depth(&self, p: Vec3) -> f64 {
        self.radius - p.length()
    }
    fn bounds(&self) -> Aabb {
        Aabb::new(Vec3::splat(-self.radius), Vec3::splat(self.radius))
    }
    fn volume(&self) -> f64 {
        4.0 / 3.0 * PI * self.radius.powi(3)
    }
}

/// An ellipsoid with semi-axes `semi_axes` \[m\] along x, y, z, centred at the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ellipsoid {
    pub semi_axes: Vec3,
}

impl Solid for Ellipsoid {
    /// Distance to the surface by the Lagrange condition of the closest point (Eberly, "Distance from a
    /// point to an ellipse, an ellipsoid, or a hyperellipsoid", Geometric Tools, 2013): the closest point
    /// is xᵢ = aᵢ² yᵢ/(t + aᵢ²) with t the largest root of Σ (aᵢ yᵢ/(t + aᵢ²))² = 1, found by bisection.
    /// Zero coordinates are nudged by 10⁻¹² of the axis so that the root is bracketed (the closest point of
    /// the nudged point converges to the exact one).
    fn depth(&self, p: Vec3) -> f64 {
        let a = self.semi_axes;
        let y = p.abs().max(a * 1e-12);
        // In the shifted variable s = t + a_min² the root near −a_min² keeps full precision.
        let amin = a.min_element();
        let shift = a * a - Vec3::splat(amin * amin);
        let f = |s: f64| {
            let q = a * y / (Vec3::splat(s) + shift);
            q.length_squared() - 1.0
        };
        let mut lo = 0.0;
        let mut hi = (a.max_element() * y.length()).max(0.0) + amin * amin;
        while f(hi) > 0.0 {
            hi *= 2.0;
        }
        for _ in 0..2000 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if f(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let s = 0.5 * (lo + hi);
        let x = a * a * y / (Vec3::splat(s) + shift);
        let d = (x - y).length();
        let inside = (p / a).length_squared() < 1.0;
        if inside {
            d
        } else {
            -d
        }
    }
    fn bounds(&self) -> Aabb {
        Aabb::new(-self.semi_axes, self.semi_axes)
    }
    fn volume(&self) -> f64 {
        4.0 / 3.0 * PI * self.semi_axes.x * self.semi_axes.y * self.semi_axes.z
    }
}

/// A ball of radius `radius` \[m\] at the origin with the part below z = `cut_z` \[m\] removed (a
/// "one-third sphere" keeps the upper two thirds of the diameter: cut_z = −R/3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutBall {
    pub radius: f64,
    pub cut_z: f64,
}

impl Solid for CutBall {
    fn depth(&self, p: Vec3) -> f64 {
        // Inside an intersection the distance to the boundary is the smaller of the two.
        (self.radius - p.length()).min(p.z - self.cut_z)
    }
    fn bounds(&self) -> Aabb {
        let r = self.radius;
        Aabb::new(Vec3::new(-r, -r, self.cut_z.max(-r)), Vec3::splat(r))
    }
    fn volume(&self) -> f64 {
        // Spherical cap of height H = R − z_c: π H² (3R − H)/3.
        let h = self.radius - self.cut_z;
        PI * h * h * (3.0 * self.radius - h) / 3.0
    }
}

/// A convex polyhedron grown by a ball of radius `rounding` \[m\] (Minkowski sum): rounded edges and
/// corners. The core is given by its triangles (outward, counter-clockwise).
#[derive(Clone, Debug, PartialEq)]
pub struct RoundedPolyhedron {
    pub core: TriMesh,
    pub rounding: f64,
}

impl RoundedPolyhedron {
    /// A regular tetrahedron of edge `edge` \[m\] (of the core), centroid at the origin.
    pub fn tetrahedron(edge: f64, rounding: f64) -> Self {
        let s = edge / (2.0 * 2f64.sqrt());
        let v = vec![
            Vec3::new(1.0, 1.0, 1.0) * s,
            Vec3::new(1.0, -1.0, -1.0) * s,
            Vec3::new(-1.0, 1.0, -1.0) * s,
            Vec3::new(-1.0, -1.0, 1.0) * s,
        ];
        let mut t = vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
        orient_outward(&v, &mut t);
        RoundedPolyhedron { core: TriMesh { vertices: v, triangles: t }, rounding }
    }

    /// A square pyramid of base side `base` and height `height` \[m\] (of the core), base centre at the
    /// origin, apex on +z.
    pub fn square_pyramid(base: f64, height: f64, rounding: f64) -> Self {
        let h = 0.5 * base;
        let v = vec![
            Vec3::new(-h, -h, 0.0),
            Vec3::new(h, -h, 0.0),
            Vec3::new(h, h, 0.0),
            Vec3::new(-h, h, 0.0),
            Vec3::new(0.0, 0.0, height),
        ];
        let mut t = vec![[0, 2, 1], [0, 3, 2], [0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        orient_outward(&v, &mut t);
        RoundedPolyhedron { core: TriMesh { vertices: v, triangles: t }, rounding }
    }

    fn face_planes(&self) -> impl Iterator<Item = (Vec3, f64)> + '_ {
        (0..self.core.triangles.len()).map(|k| {
            let n = self.core.normal(k);
            (n, n.dot(self.core.corners(k)[0]))
        })
    }
}

/// Flips triangles whose normal points towards the centroid of the vertices (convex cores only).
fn orient_outward(v: &[Vec3], t: &mut [[u32; 3]]) {
    let c = v.iter().copied().sum::<Vec3>() / v.len() as f64;
    for tri in t.iter_mut() {
        let [a, b, d] = tri.map(|i| v[i as usize]);
        if (b - a).cross(d - a).dot(a - c) < 0.0 {
            tri.swap(1, 2);
        }
    }
}

impl Solid for RoundedPolyhedron {
    fn depth(&self, p: Vec3) -> f64 {
        // Inside the core: rounding + distance to the nearest face plane; outside: rounding − distance
        // to the core.
        let inner = self.face_planes().map(|(n, d)| d - n.dot(p)).fold(f64::INFINITY, f64::min);
        if inner >= 0.0 {
            return self.rounding + inner;
        }
        let dist = (0..self.core.triangles.len())
            .map(|k| {
                let [a, b, c] = self.core.corners(k);
                (closest_point_on_triangle(p, a, b, c).0 - p).length()
            })
            .fold(f64::INFINITY, f64::min);
        self.rounding - dist
    }
    fn bounds(&self) -> Aabb {
        let b = self.core.bounds();
        Aabb::new(b.min - Vec3::splat(self.rounding), b.max + Vec3::splat(self.rounding))
    }
    /// Steiner's formula for a convex body grown by a ball of radius ρ: V + S ρ + ρ² Σₑ Lₑ θₑ/2 + 4πρ³/3,
    /// θₑ the angle between the outward normals of the faces at edge e (Schneider, *Convex Bodies*, §4.2).
    fn volume(&self) -> f64 {
        let m = &self.core;
        let rho = self.rounding;
        let topo = m.topology();
        let mut faces_of_edge: Vec<Vec<usize>> = vec![Vec::new(); topo.edge_use_count.len()];
        let mut edge_len = vec![0.0; topo.edge_use_count.len()];
        for (k, edges) in topo.triangle_edges.iter().enumerate() {
            let c = m.corners(k);
            for (e, &id) in edges.iter().enumerate() {
                faces_of_edge[id as usize].push(k);
                edge_len[id as usize] = (c[(e + 1) % 3] - c[e]).length();
            }
        }
        let mean_curv: f64 = faces_of_edge
            .iter()
            .zip(&edge_len)
            .filter(|(f, _)| f.len() == 2)
            .map(|(f, &l)| l * m.normal(f[0]).dot(m.normal(f[1])).clamp(-1.0, 1.0).acos() / 2.0)
            .sum();
        m.signed_volume() + m.total_area() * rho + mean_curv * rho * rho + 4.0 / 3.0 * PI * rho.powi(3)
    }
}

/// A closed triangle mesh as a solid (the caller checks that it is closed, see
/// [`super::fill::check_closed`]).
pub struct MeshSolid {
    pub mesh: TriMesh,
    bvh: TriBvh,
}

impl MeshSolid {
    pub fn new(mesh: TriMesh) -> Self {
        let bvh = TriBvh::build(&mesh);
        MeshSolid { mesh, bvh }
    }
}

impl Solid for MeshSolid {
    fn depth(&self, p: Vec3) -> f64 {
        let d = self.bvh.closest_point(&self.mesh, p, f64::INFINITY).map_or(f64::INFINITY, |h| h.distance);
        if self.bvh.contains_point(&self.mesh, p) {
            d
        } else {
            -d
        }
    }
    fn bounds(&self) -> Aabb {
        self.mesh.bounds()
    }
    fn volume(&self) -> f64 {
        self.mesh.signed_volume().abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ellipsoid_depth_is_the_distance_to_the_surface() {
        let e = Ellipsoid { semi_axes: Vec3::new(3.0, 2.0, 1.0) };
        // On an axis the nearest surface point is along the smallest axis from the centre.
        assert!((e.depth(Vec3::ZERO) - 1.0).abs() < 1e-9, "{}", e.depth(Vec3::ZERO));
        // Brute force over the surface for a few points.
        for p in [Vec3::new(1.0, 0.5, 0.2), Vec3::new(-2.0, 0.3, -0.4), Vec3::new(0.1, -1.2, 0.5)] {
            let mut best = f64::INFINITY;
            let n = 400;
            for i in 0..=n {
                let th = PI * i as f64 / n as f64;
                for j in 0..2 * n {
                    let ph = PI * j as f64 / n as f64;
                    let s = Vec3::new(3.0 * th.sin() * ph.cos(), 2.0 * th.sin() * ph.sin(), th.cos());
                    best = best.min((s - p).length());
                }
            }
            let d = e.depth(p);
            assert!(d > 0.0 && d <= best + 1e-12 && best - d < 2e-4, "{p:?}: {d} vs brute force {best}");
        }
        assert!(e.depth(Vec3::new(3.5, 0.0, 0.0)) < 0.0);
    }

    #[test]
    fn rounded_tetrahedron_volume_and_depth() {
        // Without rounding: a regular tetrahedron, V = a³/(6√2); inradius a/(2√6).
        let a = 1.0;
        let t = RoundedPolyhedron::tetrahedron(a, 0.0);
        assert!((t.volume() - a.powi(3) / (6.0 * 2f64.sqrt())).abs() < 1e-12);
        assert!((t.depth(Vec3::ZERO) - a / (2.0 * 6f64.sqrt())).abs() < 1e-12);
        // A zero-size core grown by ρ is a ball.
        let b = RoundedPolyhedron::tetrahedron(1e-9, 0.5);
        assert!((b.volume() - 4.0 / 3.0 * PI * 0.125).abs() < 1e-7);
        // A square pyramid core with rounding ρ: the depth at a far point is ρ − distance.
        let p = RoundedPolyhedron::square_pyramid(1.0, 1.0, 0.1);
        assert!((p.depth(Vec3::new(0.0, 0.0, -0.3)) - (0.1 - 0.3)).abs() < 1e-12);
        // Steiner's formula against a lattice count (faces aligned with the grid make the count oscillate
        // by ±0.5 % with the spacing: 0.7332, 0.7318, 0.7370 at h = 0.02, 0.01, 0.005 for 0.7354).
        let h = 0.01;
        let bb = p.bounds();
        let n = ((bb.max - bb.min) / h).ceil();
        let mut count = 0.0;
        for i in 0..n.x as usize {
            for j in 0..n.y as usize {
                for k in 0..n.z as usize {
                    let q = bb.min + Vec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * h;
                    if p.depth(q) > 0.0 {
                        count += 1.0;
                    }
                }
            }
        }
        let v = count * h * h * h;
        assert!((v - p.volume()).abs() < 1e-2 * p.volume(), "lattice {v} against Steiner {}", p.volume());
    }

    #[test]
    fn cut_ball_volume_is_the_cap() {
        let c = CutBall { radius: 1.0, cut_z: -1.0 / 3.0 };
        // H = 4/3: π (16/9)(3 − 4/3)/3 = 80π/81.
        assert!((c.volume() - 80.0 * PI / 81.0).abs() < 1e-12);
        assert!((c.depth(Vec3::new(0.0, 0.0, 0.0)) - 1.0 / 3.0).abs() < 1e-15);
    }
}
