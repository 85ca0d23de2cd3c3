//! A conforming tetrahedral decomposition of an imported volume mesh, with point location by
//! neighbour walking and a background bin grid.
//!
//! **Decomposition.** Every cell that is not kept as a tetrahedron is split into tetrahedra joining an
//! interior *centre point* to the triangles of its faces. A polygonal face is fan-triangulated from its
//! vertex with the smallest global id, so the two cells sharing a face triangulate it identically and
//! the tetrahedral mesh is conforming (every interior triangle is shared by exactly two tetrahedra).
//! Polyhedra, hexahedra, wedges and pyramids are handled alike; a hexahedron gives 12 tetrahedra.
//! This follows the face-diagonal/cell-centre idea OpenFOAM's own particle tracking uses (tets of
//! cell centre, face base point and face edge), made conforming by the minimum-id rule.
//!
//! **Location.** A particle keeps the index of its last tetrahedron. Barycentric coordinates are
//! computed there; if one is negative the walk moves to the neighbour across the face opposite the most
//! negative coordinate (Lawson's visibility walk), which takes O(1) steps for particles that move less
//! than a cell per step. Failing walks (boundaries of non-convex domains, lost hints) fall back to a
//! uniform grid of bins holding the tetrahedra that overlap each bin.

use spatter_core::{Aabb, Vec3};

/// No tetrahedron / no neighbour.
pub const NONE: u32 = u32::MAX;

/// Barycentric tolerance: a point is inside when every coordinate ≥ −`INSIDE_TOL`.
pub const INSIDE_TOL: f64 = 1e-10;

/// How far outside its last tetrahedron (in barycentric units) a point may be and still get values
/// extrapolated from it ([`TetMesh::extrapolate`]).
pub const EXTRAPOLATION_LIMIT: f64 = 0.25;

/// Maximum number of walk steps before the bin grid is asked.
const MAX_WALK: usize = 48;

/// Tetrahedral mesh.
#[derive(Clone, Debug, Default)]
pub struct TetMesh {
    /// Mesh points followed by the added cell centres.
    pub points: Vec<Vec3>,
    /// Vertex ids, positively oriented ((p1−p0)·((p2−p0)×(p3−p0)) > 0).
    pub tets: Vec<[u32; 4]>,
    /// Neighbour across the face opposite vertex k, or [`NONE`] on the boundary.
    pub neighbours: Vec<[u32; 4]>,
    /// Source cell of each tetrahedron.
    pub tet_cell: Vec<u32>,
    /// `points[i]` is point `point_order[i]` of the list given to [`TetMesh::new`] (points are stored in
    /// Morton order too); per-point data must be permuted the same way.
    pub point_order: Vec<u32>,
    grid: BinGrid,
}

/// Uniform bins over the mesh bounds; bin b holds `items[start[b]..start[b+1]]`.
#[derive(Clone, Debug)]
struct BinGrid {
    bounds: Aabb,
    dims: [usize; 3],
    inv_cell: Vec3,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Default for BinGrid {
    fn default() -> Self {
        BinGrid { bounds: Aabb::EMPTY, dims: [1; 3], inv_cell: Vec3::ZERO, start: vec![0, 0], items: vec![] }
    }
}

impl BinGrid {
    fn bin_coords(&self, p: Vec3) -> [usize; 3] {
        let r = (p - self.bounds.min) * self.inv_cell;
        [
            (r.x.max(0.0) as usize).min(self.dims[0] - 1),
            (r.y.max(0.0) as usize).min(self.dims[1] - 1),
            (r.z.max(0.0) as usize).min(self.dims[2] - 1),
        ]
    }

    fn bin_index(&self, c: [usize; 3]) -> usize {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }
}

/// Result of a successful location.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Location {
    pub tet: u32,
    /// Barycentric coordinates (λ₀..λ₃), summing to 1.
    pub bary: [f64; 4],
}

impl TetMesh {
    /// Builds the mesh from points and positively or negatively oriented tetrahedra (each with its
    /// source cell). Degenerate tetrahedra must already be removed.
    pub fn new(points: Vec<Vec3>, mut tets: Vec<[u32; 4]>, mut tet_cell: Vec<u32>) -> Self {
        for t in &mut tets {
            let [a, b, c, d] = t.map(|i| points[i as usize]);
            if (b - a).dot((c - a).cross(d - a)) < 0.0 {
                t.swap(2, 3);
            }
        }
        // Morton order of tetrahedron centroids: neighbours in space become neighbours in memory.
        let bounds = Aabb::from_points(&points);
        let ext = bounds.extent().max(Vec3::splat(1e-300));
        let key = |t: &[u32; 4]| {
            let c = t.iter().map(|&i| points[i as usize]).sum::<Vec3>() * 0.25;
            let r = ((c - bounds.min) / ext).clamp(Vec3::ZERO, Vec3::ONE) * 1_048_575.0;
            morton3(r.x as u64, r.y as u64, r.z as u64)
        };
        let mut order: Vec<(u64, u32)> = tets.iter().enumerate().map(|(i, t)| (key(t), i as u32)).collect();
        order.sort_unstable();
        tets = order.iter().map(|&(_, i)| tets[i as usize]).collect();
        tet_cell = order.iter().map(|&(_, i)| tet_cell[i as usize]).collect();
        // Points in Morton order as well, so a tetrahedron's corners lie close in memory.
        let pkey = |p: &Vec3| {
            let r = ((*p - bounds.min) / ext).clamp(Vec3::ZERO, Vec3::ONE) * 1_048_575.0;
            morton3(r.x as u64, r.y as u64, r.z as u64)
        };
        let mut porder: Vec<(u64, u32)> =
            points.iter().enumerate().map(|(i, p)| (pkey(p), i as u32)).collect();
        porder.sort_unstable();
        let point_order: Vec<u32> = porder.iter().map(|&(_, i)| i).collect();
        let mut new_index = vec![0u32; points.len()];
        for (new, &old) in point_order.iter().enumerate() {
            new_index[old as usize] = new as u32;
        }
        let points: Vec<Vec3> = point_order.iter().map(|&i| points[i as usize]).collect();
        tets.iter_mut().for_each(|t| *t = t.map(|i| new_index[i as usize]));
        let neighbours = build_neighbours(&tets);
        let mut m = TetMesh { points, tets, neighbours, tet_cell, point_order, grid: BinGrid::default() };
        m.grid = m.build_grid();
        m
    }

    /// Reorders per-point values given in the order of the points passed to [`TetMesh::new`] (an empty
    /// list stays empty).
    pub fn permute_points<T: Copy>(&self, values: &[T]) -> Vec<T> {
        if values.is_empty() {
            return Vec::new();
        }
        self.point_order.iter().map(|&i| values[i as usize]).collect()
    }

    pub fn bounds(&self) -> Aabb {
        self.grid.bounds
    }

    fn build_grid(&self) -> BinGrid {
        let bounds = Aabb::from_points(&self.points);
        let n = self.tets.len().max(1);
        let ext = bounds.extent().max(Vec3::splat(1e-12 * bounds.extent().max_element().max(1e-300)));
        // About two tetrahedra per bin on average.
        let target = (n as f64 / 2.0).max(1.0);
        let h = (ext.x * ext.y * ext.z / target).cbrt();
        let dims = [
            ((ext.x / h).ceil() as usize).clamp(1, 1024),
            ((ext.y / h).ceil() as usize).clamp(1, 1024),
            ((ext.z / h).ceil() as usize).clamp(1, 1024),
        ];
        let inv_cell = Vec3::new(dims[0] as f64 / ext.x, dims[1] as f64 / ext.y, dims[2] as f64 / ext.z);
        let mut g = BinGrid { bounds, dims, inv_cell, start: vec![], items: vec![] };
        let nb = dims[0] * dims[1] * dims[2];
        let mut count = vec![0u32; nb + 1];
        let range = |t: &[u32; 4]| {
            let bb = Aabb::from_points(t.iter().map(|&i| &self.points[i as usize]));
            (g.bin_coords(bb.min), g.bin_coords(bb.max))
        };
        for t in &self.tets {
            let (lo, hi) = range(t);
            for k in lo[2]..=hi[2] {
                for j in lo[1]..=hi[1] {
                    for i in lo[0]..=hi[0] {
                        count[g.bin_index([i, j, k]) + 1] += 1;
                    }
                }
            }
        }
        for b in 0..nb {
            count[b + 1] += count[b];
        }
        let mut fill = count.clone();
        let mut items = vec![0u32; count[nb] as usize];
        for (ti, t) in self.tets.iter().enumerate() {
            let (lo, hi) = range(t);
            for k in lo[2]..=hi[2] {
                for j in lo[1]..=hi[1] {
                    for i in lo[0]..=hi[0] {
                        let b = g.bin_index([i, j, k]);
                        items[fill[b] as usize] = ti as u32;
                        fill[b] += 1;
                    }
                }
            }
        }
        g.start = count;
        g.items = items;
        g
    }

    /// Barycentric coordinates of `x` in tetrahedron `t`.
    #[inline]
    pub fn barycentric(&self, t: u32, x: Vec3) -> [f64; 4] {
        let [a, b, c, d] = self.tets[t as usize];
        let p0 = self.points[a as usize];
        let e1 = self.points[b as usize] - p0;
        let e2 = self.points[c as usize] - p0;
        let e3 = self.points[d as usize] - p0;
        let r = x - p0;
        let c23 = e2.cross(e3);
        let inv = 1.0 / e1.dot(c23);
        let l1 = r.dot(c23) * inv;
        let l2 = e1.dot(r.cross(e3)) * inv;
        let l3 = e1.dot(e2.cross(r)) * inv;
        [1.0 - l1 - l2 - l3, l1, l2, l3]
    }

    /// Gradients of the four barycentric coordinates of tetrahedron `t` \[1/m\].
    #[inline]
    pub fn bary_gradients(&self, t: u32) -> [Vec3; 4] {
        let [a, b, c, d] = self.tets[t as usize];
        let p0 = self.points[a as usize];
        let e1 = self.points[b as usize] - p0;
        let e2 = self.points[c as usize] - p0;
        let e3 = self.points[d as usize] - p0;
        let inv = 1.0 / e1.dot(e2.cross(e3));
        let g1 = e2.cross(e3) * inv;
        let g2 = e3.cross(e1) * inv;
        let g3 = e1.cross(e2) * inv;
        [-(g1 + g2 + g3), g1, g2, g3]
    }

    /// Locates `x`, starting from the tetrahedron `hint` (updated on success; [`NONE`] = no hint).
    /// `None` when `x` lies outside the mesh.
    #[inline]
    pub fn locate(&self, x: Vec3, hint: &mut u32) -> Option<Location> {
        if (*hint as usize) < self.tets.len() {
            let mut t = *hint;
            for _ in 0..MAX_WALK {
                let l = self.barycentric(t, x);
                let (mut kmin, mut vmin) = (0, l[0]);
                for (k, &v) in l.iter().enumerate().skip(1) {
                    if v < vmin {
                        kmin = k;
                        vmin = v;
                    }
                }
                if vmin >= -INSIDE_TOL {
                    *hint = t;
                    return Some(Location { tet: t, bary: l });
                }
                let n = self.neighbours[t as usize][kmin];
                if n == NONE {
                    break;
                }
                t = n;
            }
        }
        let loc = self.locate_in_bins(x)?;
        *hint = loc.tet;
        Some(loc)
    }

    /// For a point just outside the mesh (a particle sliding along a wall whose CFD surface and STL
    /// differ slightly, or leaving through an outlet): the location in tetrahedron `hint` with negative
    /// barycentric coordinates clipped to zero (the nearest point of that tetrahedron's face, roughly),
    /// provided no coordinate is below −[`EXTRAPOLATION_LIMIT`]; `None` otherwise.
    #[inline]
    pub fn extrapolate(&self, x: Vec3, hint: u32) -> Option<Location> {
        if hint as usize >= self.tets.len() {
            return None;
        }
        let mut l = self.barycentric(hint, x);
        if l.iter().any(|&v| v < -EXTRAPOLATION_LIMIT) {
            return None;
        }
        l.iter_mut().for_each(|v| *v = v.max(0.0));
        let sum: f64 = l.iter().sum();
        l.iter_mut().for_each(|v| *v /= sum);
        Some(Location { tet: hint, bary: l })
    }

    /// Location through the bin grid only.
    pub fn locate_in_bins(&self, x: Vec3) -> Option<Location> {
        let g = &self.grid;
        if !g.bounds.inflated(1e-9 * g.bounds.extent().max_element()).contains(x) || self.tets.is_empty() {
            return None;
        }
        let b = g.bin_index(g.bin_coords(x));
        let mut best: Option<Location> = None;
        let mut best_min = f64::NEG_INFINITY;
        for &t in &g.items[g.start[b] as usize..g.start[b + 1] as usize] {
            let l = self.barycentric(t, x);
            let m = l.iter().copied().fold(f64::INFINITY, f64::min);
            if m >= 0.0 {
                return Some(Location { tet: t, bary: l });
            }
            if m > best_min {
                best_min = m;
                best = Some(Location { tet: t, bary: l });
            }
        }
        // Points on shared faces may be outside every candidate by round-off only.
        best.filter(|_| best_min >= -INSIDE_TOL)
    }

    /// Volume of tetrahedron `t` \[m³\].
    pub fn volume(&self, t: usize) -> f64 {
        let [a, b, c, d] = self.tets[t].map(|i| self.points[i as usize]);
        (b - a).dot((c - a).cross(d - a)) / 6.0
    }

    /// Number of boundary faces (faces with no neighbour).
    pub fn boundary_faces(&self) -> usize {
        self.neighbours.iter().flatten().filter(|&&n| n == NONE).count()
    }
}

fn morton3(x: u64, y: u64, z: u64) -> u64 {
    fn spread(mut v: u64) -> u64 {
        v &= 0x1f_ffff;
        v = (v | v << 32) & 0x1f00000000ffff;
        v = (v | v << 16) & 0x1f0000ff0000ff;
        v = (v | v << 8) & 0x100f00f00f00f00f;
        v = (v | v << 4) & 0x10c30c30c30c30c3;
        v = (v | v << 2) & 0x1249249249249249;
        v
    }
    spread(x) | spread(y) << 1 | spread(z) << 2
}

/// Face adjacency by sorting the faces' sorted vertex triples.
fn build_neighbours(tets: &[[u32; 4]]) -> Vec<[u32; 4]> {
    let mut faces: Vec<([u32; 3], u32)> = Vec::with_capacity(4 * tets.len());
    for (t, v) in tets.iter().enumerate() {
        for k in 0..4 {
            let mut f = [v[(k + 1) % 4], v[(k + 2) % 4], v[(k + 3) % 4]];
            f.sort_unstable();
            faces.push((f, (4 * t + k) as u32));
        }
    }
    faces.sort_unstable();
    let mut nb = vec![[NONE; 4]; tets.len()];
    let mut i = 0;
    while i < faces.len() {
        let mut j = i + 1;
        while j < faces.len() && faces[j].0 == faces[i].0 {
            j += 1;
        }
        if j - i == 2 {
            let (a, b) = (faces[i].1, faces[i + 1].1);
            nb[(a / 4) as usize][(a % 4) as usize] = b / 4;
            nb[(b / 4) as usize][(b % 4) as usize] = a / 4;
        }
        i = j;
    }
    nb
}

/// A structured box `[0,1]³·size + origin` of `n³` cubes, each split into six tetrahedra around its main
/// diagonal (Kuhn/Freudenthal; conforming), with interior points displaced by up to `jitter` of the
/// spacing (deterministic), for tests and benchmarks.
pub fn kuhn_box(origin: Vec3, size: Vec3, n: [usize; 3], jitter: f64) -> (Vec<Vec3>, Vec<[u32; 4]>) {
    let [nx, ny, nz] = n;
    let id = |i: usize, j: usize, k: usize| (i + (nx + 1) * (j + (ny + 1) * k)) as u32;
    let h = size / Vec3::new(nx as f64, ny as f64, nz as f64);
    let mut points = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
    let mut s = 0x2545_f491_4f6c_dd1du64;
    let mut rnd = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let mut p = origin + h * Vec3::new(i as f64, j as f64, k as f64);
                let interior = i > 0 && i < nx && j > 0 && j < ny && k > 0 && k < nz;
                let d = Vec3::new(rnd(), rnd(), rnd());
                if interior {
                    p += jitter * h * d;
                }
                points.push(p);
            }
        }
    }
    // The six tetrahedra of a cube sharing the diagonal 0–7 (corner c = i + 2j + 4k).
    const PATHS: [[usize; 4]; 6] =
        [[0, 1, 3, 7], [0, 1, 5, 7], [0, 2, 3, 7], [0, 2, 6, 7], [0, 4, 5, 7], [0, 4, 6, 7]];
    let mut tets = Vec::with_capacity(6 * nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let corner = |c: usize| id(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                for p in PATHS {
                    tets.push(p.map(corner));
                }
            }
        }
    }
    (points, tets)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn box_mesh(n: usize, jitter: f64) -> TetMesh {
        let (p, t) = kuhn_box(Vec3::ZERO, Vec3::ONE, [n, n, n], jitter);
        let cells = (0..t.len() as u32).collect();
        TetMesh::new(p, t, cells)
    }

    #[test]
    fn kuhn_box_is_conforming_and_fills_the_volume() {
        let m = box_mesh(4, 0.3);
        let vol: f64 = (0..m.tets.len()).map(|t| m.volume(t)).sum();
        assert!((vol - 1.0).abs() < 1e-12, "{vol}");
        assert!((0..m.tets.len()).all(|t| m.volume(t) > 0.0));
        // Boundary faces: 6 sides × 16 squares × 2 triangles.
        assert_eq!(m.boundary_faces(), 6 * 16 * 2);
    }

    #[test]
    fn walking_and_bins_find_the_same_tet() {
        let m = box_mesh(6, 0.3);
        let mut s = 7u64;
        let mut rnd = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut hint = 0;
        for _ in 0..2000 {
            let x = Vec3::new(rnd(), rnd(), rnd());
            let a = m.locate(x, &mut hint).expect("inside");
            let b = m.locate_in_bins(x).expect("inside");
            assert!(a.bary.iter().all(|&l| l >= -INSIDE_TOL));
            // Reconstruct x from the barycentric coordinates.
            let y: Vec3 = (0..4).map(|k| a.bary[k] * m.points[m.tets[a.tet as usize][k] as usize]).sum();
            assert!((x - y).length() < 1e-12);
            if a.tet != b.tet {
                // Only possible on a shared face.
                assert!(a.bary.iter().any(|&l| l.abs() < 1e-9));
            }
        }
        assert!(m.locate(Vec3::new(1.5, 0.5, 0.5), &mut hint).is_none());
        assert!(m.locate(Vec3::new(-0.1, 0.5, 0.5), &mut NONE.clone()).is_none());
    }

    #[test]
    fn gradients_of_a_linear_function_are_exact() {
        let m = box_mesh(3, 0.35);
        let f = |p: Vec3| 2.0 * p.x - 3.0 * p.y + 0.5 * p.z + 1.0;
        for t in 0..m.tets.len() as u32 {
            let g = m.bary_gradients(t);
            let grad: Vec3 = (0..4).map(|k| f(m.points[m.tets[t as usize][k] as usize]) * g[k]).sum();
            assert!((grad - Vec3::new(2.0, -3.0, 0.5)).length() < 1e-10);
        }
    }
}
