//! A bounding-volume hierarchy over the triangles of a [`TriMesh`]: first hit of a segment, closest
//! point within a radius, ray-parity inside tests and box queries in O(log N) per query.
//!
//! Built top-down by splitting the centroids at the median of the longest axis (leaves of at most four
//! triangles). The tree stores triangle indices only; every query takes the mesh it was built from.

use crate::mesh::{closest_point_on_triangle, ray_hits_triangle, TriMesh, TriRegion};
use crate::{Aabb, Vec3};
use serde::{Deserialize, Serialize};

const LEAF_SIZE: usize = 4;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
struct Node {
    bounds: Aabb,
    /// Leaf: first index into `order`. Inner node: index of the left child (the right child follows it).
    first: u32,
    /// Number of triangles of a leaf; 0 for an inner node.
    count: u32,
}

/// Triangle hierarchy of one mesh.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TriBvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

/// Result of [`TriBvh::closest_point`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestHit {
    pub point: Vec3,
    pub triangle: u32,
    pub distance: f64,
    pub region: TriRegion,
}

fn tri_bounds(mesh: &TriMesh, t: usize) -> Aabb {
    let [a, b, c] = mesh.corners(t);
    Aabb::new(a.min(b).min(c), a.max(b).max(c))
}

/// Squared distance from `p` to the box (0 inside).
fn box_dist2(b: &Aabb, p: Vec3) -> f64 {
    let d = (b.min - p).max(Vec3::ZERO).max(p - b.max);
    d.length_squared()
}

/// Whether the segment `origin + s·dir`, `s ∈ [0, s_max]`, meets the box (slab test).
fn segment_meets_box(b: &Aabb, origin: Vec3, inv_dir: Vec3, s_max: f64) -> bool {
    let mut lo = 0.0_f64;
    let mut hi = s_max;
    for k in 0..3 {
        let (o, inv, mn, mx) = (origin[k], inv_dir[k], b.min[k], b.max[k]);
        if inv.is_infinite() {
            // Parallel to this slab: inside it or never.
            if o < mn || o > mx {
                return false;
            }
            continue;
        }
        let (mut t0, mut t1) = ((mn - o) * inv, (mx - o) * inv);
        if t0 > t1 {
            std::mem::swap(&mut t0, &mut t1);
        }
        lo = lo.max(t0);
        hi = hi.min(t1);
        if lo > hi {
            return false;
        }
    }
    true
}

impl TriBvh {
    /// Builds the hierarchy over every triangle of `mesh` (degenerate triangles included; they are never hit).
    pub fn build(mesh: &TriMesh) -> Self {
        let n = mesh.triangles.len();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let bounds: Vec<Aabb> = (0..n).map(|t| tri_bounds(mesh, t)).collect();
        let centroids: Vec<Vec3> = bounds.iter().map(|b| b.center()).collect();
        let mut nodes = Vec::with_capacity(2 * n / LEAF_SIZE + 1);
        if n > 0 {
            nodes.push(Node { bounds: Aabb::EMPTY, first: 0, count: 0 });
            // Explicit stack of (node index, range in `order`).
            let mut stack = vec![(0usize, 0usize, n)];
            while let Some((node, lo, hi)) = stack.pop() {
                let nb = order[lo..hi].iter().fold(Aabb::EMPTY, |b, &t| b.union(bounds[t as usize]));
                let cb = order[lo..hi].iter().fold(Aabb::EMPTY, |b, &t| b.grown_to(centroids[t as usize]));
                let ext = cb.extent();
                let axis = if ext.x >= ext.y && ext.x >= ext.z {
                    0
                } else if ext.y >= ext.z {
                    1
                } else {
                    2
                };
                if hi - lo <= LEAF_SIZE || ext[axis] <= 0.0 {
                    nodes[node] = Node { bounds: nb, first: lo as u32, count: (hi - lo) as u32 };
                    continue;
                }
                let mid = lo + (hi - lo) / 2;
                order[lo..hi].select_nth_unstable_by(mid - lo, |&a, &b| {
                    centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis]).then(a.cmp(&b))
                });
                let left = nodes.len();
                nodes.push(Node { bounds: Aabb::EMPTY, first: 0, count: 0 });
                nodes.push(Node { bounds: Aabb::EMPTY, first: 0, count: 0 });
                nodes[node] = Node { bounds: nb, first: left as u32, count: 0 };
                stack.push((left + 1, mid, hi));
                stack.push((left, lo, mid));
            }
        }
        TriBvh { nodes, order }
    }

    /// Bounds of the whole mesh (empty for a mesh without triangles).
    pub fn bounds(&self) -> Aabb {
        self.nodes.first().map(|n| n.bounds).unwrap_or(Aabb::EMPTY)
    }

    /// Visits the leaves whose boxes pass `visit_node`, calling `f` with each of their triangles.
    #[inline]
    fn walk(&self, mut visit_node: impl FnMut(&Aabb) -> bool, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        let mut stack = [0u32; 64];
        let mut top = 1usize;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top] as usize];
            if !visit_node(&node.bounds) {
                continue;
            }
            if node.count > 0 {
                let s = node.first as usize;
                for &t in &self.order[s..s + node.count as usize] {
                    f(t);
                }
            } else if top + 2 <= stack.len() {
                stack[top] = node.first + 1;
                stack[top + 1] = node.first;
                top += 2;
            } else {
                // Deeper than 64 levels cannot happen with median splits of < 2^60 triangles; stay correct anyway.
                let s = node.first as usize;
                for child in [s, s + 1] {
                    self.walk_from(child, &mut visit_node, &mut f);
                }
            }
        }
    }

    fn walk_from(&self, i: usize, visit_node: &mut dyn FnMut(&Aabb) -> bool, f: &mut dyn FnMut(u32)) {
        let node = &self.nodes[i];
        if !visit_node(&node.bounds) {
            return;
        }
        if node.count > 0 {
            let s = node.first as usize;
            for &t in &self.order[s..s + node.count as usize] {
                f(t);
            }
        } else {
            self.walk_from(node.first as usize, visit_node, f);
            self.walk_from(node.first as usize + 1, visit_node, f);
        }
    }

    /// Calls `f` for every triangle whose bounding box overlaps `query`.
    pub fn for_each_overlapping(&self, mesh: &TriMesh, query: &Aabb, mut f: impl FnMut(u32)) {
        let overlaps = |b: &Aabb| b.min.cmple(query.max).all() && b.max.cmpge(query.min).all();
        self.walk(overlaps, |t| {
            if overlaps(&tri_bounds(mesh, t as usize)) {
                f(t)
            }
        });
    }

    /// First crossing of the segment from `a` to `b` with a triangle of `mesh`: the fraction `s ∈ (0, 1]`
    /// along the segment and the triangle index. Hits on shared edges and vertices count for every
    /// triangle that owns them, so a segment cannot slip between two triangles.
    pub fn segment_first_hit(&self, mesh: &TriMesh, a: Vec3, b: Vec3) -> Option<(f64, u32)> {
        let dir = b - a;
        if dir == Vec3::ZERO {
            return None;
        }
        let inv = Vec3::ONE / dir;
        let mut best: Option<(f64, u32)> = None;
        let s_max = std::cell::Cell::new(1.0);
        self.walk(
            |bx| segment_meets_box(bx, a, inv, s_max.get()),
            |t| {
                let [p, q, r] = mesh.corners(t as usize);
                if let Some(s) = ray_hits_triangle(a, dir, p, q, r) {
                    let better = match best {
                        None => true,
                        Some((bs, bt)) => s < bs || (s == bs && t < bt),
                    };
                    if s <= 1.0 && better {
                        best = Some((s, t));
                        s_max.set(s);
                    }
                }
            },
        );
        best
    }

    /// Closest point of `mesh` to `p` among points within `max_dist` (None when nothing is that close).
    pub fn closest_point(&self, mesh: &TriMesh, p: Vec3, max_dist: f64) -> Option<ClosestHit> {
        let mut best: Option<ClosestHit> = None;
        let mut r2 = max_dist * max_dist;
        // The visitor cannot see `best` change, so it reads the shrinking radius through a cell.
        let radius2 = std::cell::Cell::new(r2);
        self.walk(
            |bx| box_dist2(bx, p) <= radius2.get(),
            |t| {
                let [a, b, c] = mesh.corners(t as usize);
                let (q, region) = closest_point_on_triangle(p, a, b, c);
                let d2 = (q - p).length_squared();
                let better = match best {
                    None => d2 <= r2,
                    Some(h) => d2 < r2 || (d2 == r2 && t < h.triangle),
                };
                if better {
                    r2 = d2;
                    radius2.set(d2);
                    best = Some(ClosestHit { point: q, triangle: t, distance: d2.sqrt(), region });
                }
            },
        );
        best
    }

    /// Number of triangles crossed by the infinite ray `origin + s·dir`, `s > 0`.
    pub fn ray_crossings(&self, mesh: &TriMesh, origin: Vec3, dir: Vec3) -> u32 {
        let inv = Vec3::ONE / dir;
        let mut n = 0;
        self.walk(
            |bx| segment_meets_box(bx, origin, inv, f64::INFINITY),
            |t| {
                let [a, b, c] = mesh.corners(t as usize);
                if ray_hits_triangle(origin, dir, a, b, c).is_some() {
                    n += 1;
                }
            },
        );
        n
    }

    /// Whether `p` lies inside the closed `mesh` (parity of crossings along the same slightly skewed
    /// direction as [`TriMesh::contains_point`], so both agree).
    pub fn contains_point(&self, mesh: &TriMesh, p: Vec3) -> bool {
        let dir = Vec3::new(0.5773502691896258, 0.5773502691896257, 0.577_350_269_189_626)
            + Vec3::new(1.3e-7, -2.9e-7, 0.0);
        self.ray_crossings(mesh, p, dir) % 2 == 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed unit cube [0,1]³ with outward normals, each face split into `n×n` squares.
    fn cube(n: usize) -> TriMesh {
        let mut soup = Vec::new();
        let face = |soup: &mut Vec<Vec3>, o: Vec3, u: Vec3, v: Vec3| {
            for i in 0..n {
                for j in 0..n {
                    let (fi, fj, d) = (i as f64 / n as f64, j as f64 / n as f64, 1.0 / n as f64);
                    let p00 = o + u * fi + v * fj;
                    let p10 = p00 + u * d;
                    let p11 = p10 + v * d;
                    let p01 = p00 + v * d;
                    soup.extend([p00, p10, p11, p00, p11, p01]);
                }
            }
        };
        // Each face's (u × v) points outward.
        face(&mut soup, Vec3::ZERO, Vec3::Y, Vec3::X); // z = 0, normal −z
        face(&mut soup, Vec3::Z, Vec3::X, Vec3::Y); // z = 1
        face(&mut soup, Vec3::ZERO, Vec3::X, Vec3::Z); // y = 0, normal −y
        face(&mut soup, Vec3::Y, Vec3::Z, Vec3::X); // y = 1
        face(&mut soup, Vec3::ZERO, Vec3::Z, Vec3::Y); // x = 0, normal −x
        face(&mut soup, Vec3::X, Vec3::Y, Vec3::Z); // x = 1
        TriMesh::from_triangle_soup(&soup)
    }

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn inside_tests_agree_with_the_brute_force_mesh_test() {
        let m = cube(5);
        assert!(m.signed_volume() > 0.99 && m.signed_volume() < 1.01);
        let bvh = TriBvh::build(&m);
        let mut s = 11;
        for _ in 0..300 {
            let p = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 1.6 - Vec3::splat(0.3);
            assert_eq!(bvh.contains_point(&m, p), m.contains_point(p), "{p}");
        }
    }

    #[test]
    fn closest_point_matches_brute_force() {
        let m = cube(4);
        let bvh = TriBvh::build(&m);
        let mut s = 5;
        for _ in 0..200 {
            let p = Vec3::new(lcg(&mut s), lcg(&mut s), lcg(&mut s)) * 2.0 - Vec3::splat(0.5);
            let brute = (0..m.triangles.len())
                .map(|t| {
                    let [a, b, c] = m.corners(t);
                    (closest_point_on_triangle(p, a, b, c).0 - p).length()
                })
                .fold(f64::INFINITY, f64::min);
            let hit = bvh.closest_point(&m, p, 10.0).expect("within 10 m");
            assert!((hit.distance - brute).abs() < 1e-12, "{p}: {} vs {brute}", hit.distance);
            assert!(bvh.closest_point(&m, p, 0.999 * brute).is_none());
        }
    }

    #[test]
    fn segments_through_faces_edges_and_vertices_are_caught() {
        let m = cube(3); // shared edges at x, y = 1/3, 2/3 on every face
        let bvh = TriBvh::build(&m);
        // Through a face interior, a shared edge, a shared vertex, and a cube corner-adjacent edge.
        for (a, b) in [
            (Vec3::new(0.5, 0.5, 0.9), Vec3::new(0.5, 0.5, 1.1)),
            (Vec3::new(1.0 / 3.0, 0.5, 0.95), Vec3::new(1.0 / 3.0, 0.5, 1.05)),
            (Vec3::new(1.0 / 3.0, 2.0 / 3.0, 0.95), Vec3::new(1.0 / 3.0, 2.0 / 3.0, 1.05)),
            (Vec3::new(0.999, 0.5, 0.999), Vec3::new(1.001, 0.5, 1.001)),
        ] {
            let (s, _) =
                bvh.segment_first_hit(&m, a, b).unwrap_or_else(|| panic!("{a} → {b} slipped through"));
            let hit = a + (b - a) * s;
            assert!(hit.z > 0.999 || hit.x > 0.999, "{hit}");
        }
        // A short segment inside and one outside meet nothing.
        assert!(bvh.segment_first_hit(&m, Vec3::splat(0.4), Vec3::splat(0.6)).is_none());
        assert!(bvh.segment_first_hit(&m, Vec3::splat(1.4), Vec3::splat(1.6)).is_none());
        // Through the whole cube: the first hit is the entry face.
        let (s, _) = bvh.segment_first_hit(&m, Vec3::new(0.5, 0.5, -1.0), Vec3::new(0.5, 0.5, 2.0)).unwrap();
        assert!((s - 1.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn box_query_finds_every_overlapping_triangle() {
        let m = cube(6);
        let bvh = TriBvh::build(&m);
        let q = Aabb::new(Vec3::new(0.2, 0.2, 0.9), Vec3::new(0.45, 0.3, 1.2));
        let mut found = Vec::new();
        bvh.for_each_overlapping(&m, &q, |t| found.push(t));
        found.sort_unstable();
        let brute: Vec<u32> = (0..m.triangles.len() as u32)
            .filter(|&t| {
                let b = tri_bounds(&m, t as usize);
                b.min.cmple(q.max).all() && b.max.cmpge(q.min).all()
            })
            .collect();
        assert_eq!(found, brute);
        assert!(!found.is_empty());
    }

    #[test]
    fn empty_mesh_is_harmless() {
        let m = TriMesh::default();
        let bvh = TriBvh::build(&m);
        assert!(bvh.bounds().is_empty());
        assert!(!bvh.contains_point(&m, Vec3::ZERO));
        assert!(bvh.closest_point(&m, Vec3::ZERO, 1.0).is_none());
        assert!(bvh.segment_first_hit(&m, Vec3::ZERO, Vec3::ONE).is_none());
    }
}
