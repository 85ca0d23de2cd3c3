//! Sampling a triangle-mesh surface with points at a target spacing (SPH boundary particles, wetting
//! sensors), with the surface area each point stands for and, for every triangle, which points cover it.
//!
//! Method:
//! 1. **Plane lattices.** Every triangle proposes the points of a square lattice of edge `spacing` laid in
//!    its plane with an origin and axes that depend only on the plane (the plane's foot point from the
//!    world origin and [`orthonormal_basis`] of the sign-normalised normal), offset by half a spacing. All
//!    triangles of one plane therefore propose points of one lattice: a flat part is sampled as a regular
//!    grid whatever its triangulation.
//! 2. **Gap filling.** Random points (about three per `spacing²`) are proposed on every triangle.
//! 3. **Poisson-disk acceptance.** Lattice proposals in triangle order, then the random ones in shuffled
//!    order, are accepted when no accepted point lies within `0.7·spacing`. Seams between non-coplanar
//!    triangles get no duplicates, and every surface point stays within one spacing of a sample.
//! 4. **Areas.** Area probes (the plane lattice of edge `spacing/2`, or the centroid of a triangle too small
//!    to hold one; each carries an equal share of its triangle's area) are given to the nearest accepted point. A point's area is the sum of its
//!    probes; a triangle's coverage lists the points its probes went to with their shares. Areas therefore
//!    add up exactly to the mesh area, and a quantity known per point (wet or dry) maps onto any triangle
//!    as an area fraction, independent of how finely the surface is triangulated.
//!
//! Deterministic for a given `seed`.

use crate::grid::CellGrid;
use crate::math::orthonormal_basis;
use crate::mesh::TriMesh;
use crate::rng::{seeded, RngExt};
use crate::Vec3;
use serde::{Deserialize, Serialize};

/// Acceptance radius as a fraction of the spacing.
const MIN_DISTANCE: f64 = 0.7;
/// Random gap-filling proposals per `spacing²` of area.
const FILL_PER_CELL: f64 = 3.0;
/// Area probes lie on the plane lattice of edge `spacing / PROBES_PER_SIDE`.
const PROBES_PER_SIDE: f64 = 2.0;

/// Which sample points cover each triangle, and with how much of its area (compressed rows).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TriangleCoverage {
    /// Entries of triangle `t` are `start[t]..start[t + 1]`.
    pub start: Vec<u32>,
    /// Sample index of each entry.
    pub sample: Vec<u32>,
    /// Area of the triangle represented by that sample \[m²\]; a triangle's weights sum to its area.
    pub weight: Vec<f64>,
}

impl TriangleCoverage {
    /// Area-weighted mean over each triangle of a per-sample quantity (NaN for a zero-area triangle).
    pub fn triangle_means(&self, per_sample: &[f64]) -> Vec<f64> {
        (0..self.start.len().saturating_sub(1))
            .map(|t| {
                let r = self.start[t] as usize..self.start[t + 1] as usize;
                let area: f64 = self.weight[r.clone()].iter().sum();
                if area <= 0.0 {
                    return f64::NAN;
                }
                let s: f64 = r.map(|k| self.weight[k] * per_sample[self.sample[k] as usize]).sum();
                s / area
            })
            .collect()
    }
}

/// Sample points on a mesh surface.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SurfaceSamples {
    pub points: Vec<Vec3>,
    /// Unit normal of the triangle each point was proposed on (the mesh's own orientation).
    pub normals: Vec<Vec3>,
    /// Triangle each point was proposed on.
    pub triangles: Vec<u32>,
    /// Surface area each point stands for \[m²\].
    pub areas: Vec<f64>,
    pub coverage: TriangleCoverage,
}

struct Proposal {
    p: Vec3,
    tri: u32,
}

/// Lattice points of the plane of triangle `(a, b, c)` that lie inside it.
fn lattice_points(a: Vec3, b: Vec3, c: Vec3, s: f64, out: &mut Vec<Vec3>) {
    let n = (b - a).cross(c - a);
    let len = n.length();
    if len <= 0.0 || !len.is_finite() {
        return;
    }
    let mut n = n / len;
    // Sign-normalise so that both orientations of one plane share a lattice.
    let k = if n.x.abs() >= n.y.abs() && n.x.abs() >= n.z.abs() {
        0
    } else if n.y.abs() >= n.z.abs() {
        1
    } else {
        2
    };
    if n[k] < 0.0 {
        n = -n;
    }
    let (t1, t2) = orthonormal_basis(n);
    let o = n * n.dot(a);
    let uv = |p: Vec3| ((p - o).dot(t1), (p - o).dot(t2));
    let corners = [uv(a), uv(b), uv(c)];
    let vmin = corners.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
    let vmax = corners.iter().map(|c| c.1).fold(f64::NEG_INFINITY, f64::max);
    let j0 = (vmin / s - 0.5).ceil() as i64;
    let j1 = (vmax / s - 0.5).floor() as i64;
    for j in j0..=j1 {
        let v = (j as f64 + 0.5) * s;
        // Interval of u where the horizontal line v meets the triangle.
        let (mut ulo, mut uhi) = (f64::INFINITY, f64::NEG_INFINITY);
        for e in 0..3 {
            let (p, q) = (corners[e], corners[(e + 1) % 3]);
            let (lo, hi) = (p.1.min(q.1), p.1.max(q.1));
            if v < lo || v > hi {
                continue;
            }
            if hi == lo {
                ulo = ulo.min(p.0.min(q.0));
                uhi = uhi.max(p.0.max(q.0));
            } else {
                let u = p.0 + (q.0 - p.0) * (v - p.1) / (q.1 - p.1);
                ulo = ulo.min(u);
                uhi = uhi.max(u);
            }
        }
        if ulo > uhi {
            continue;
        }
        let i0 = (ulo / s - 0.5).ceil() as i64;
        let i1 = (uhi / s - 0.5).floor() as i64;
        for i in i0..=i1 {
            let u = (i as f64 + 0.5) * s;
            out.push(o + t1 * u + t2 * v);
        }
    }
}

/// Uniform random point on triangle `(a, b, c)`.
fn random_point(a: Vec3, b: Vec3, c: Vec3, rng: &mut crate::rng::Rng) -> Vec3 {
    let r1: f64 = rng.random();
    let r2: f64 = rng.random();
    let s = r1.sqrt();
    a * (1.0 - s) + b * (s * (1.0 - r2)) + c * (s * r2)
}

/// Samples the surface of `mesh` at `spacing` \[m\] (see the module documentation).
pub fn sample_surface(mesh: &TriMesh, spacing: f64, seed: u64) -> SurfaceSamples {
    assert!(spacing > 0.0 && spacing.is_finite(), "sampling spacing must be positive, got {spacing}");
    let ntri = mesh.triangles.len();
    let cell_area = spacing * spacing;
    // 1. Lattice proposals.
    let mut proposals: Vec<Proposal> = Vec::new();
    let mut buf = Vec::new();
    for t in 0..ntri {
        let [a, b, c] = mesh.corners(t);
        buf.clear();
        lattice_points(a, b, c, spacing, &mut buf);
        proposals.extend(buf.iter().map(|&p| Proposal { p, tri: t as u32 }));
    }
    let n_lattice = proposals.len();
    // 2. Random gap-filling proposals.
    let mut rng = seeded(seed, 0x5350_4831);
    for t in 0..ntri {
        let area = mesh.area(t);
        if area <= 0.0 {
            continue;
        }
        let n = (FILL_PER_CELL * area / cell_area).ceil().max(1.0) as usize;
        let [a, b, c] = mesh.corners(t);
        for _ in 0..n {
            proposals.push(Proposal { p: random_point(a, b, c, &mut rng), tri: t as u32 });
        }
    }
    // Shuffle the random proposals (Fisher–Yates) so gaps fill evenly.
    for i in (n_lattice + 1..proposals.len()).rev() {
        let j = n_lattice + rng.random_range(0..=(i - n_lattice));
        proposals.swap(i, j);
    }
    // 3. Poisson-disk acceptance against a grid of all proposals.
    let rmin = MIN_DISTANCE * spacing;
    let pts: Vec<Vec3> = proposals.iter().map(|p| p.p).collect();
    let mut grid = CellGrid::new();
    grid.rebuild(&pts, rmin);
    let mut accepted = vec![false; pts.len()];
    let rmin2 = rmin * rmin;
    let mut samples: Vec<u32> = Vec::new();
    for i in 0..pts.len() {
        let p = pts[i];
        let mut free = true;
        grid.for_each_candidate_run(p, |r| {
            if free {
                for &j in &grid.entries()[r] {
                    if accepted[j as usize] && (pts[j as usize] - p).length_squared() < rmin2 {
                        free = false;
                        break;
                    }
                }
            }
        });
        if free {
            accepted[i] = true;
            samples.push(i as u32);
        }
    }
    let points: Vec<Vec3> = samples.iter().map(|&i| pts[i as usize]).collect();
    let triangles: Vec<u32> = samples.iter().map(|&i| proposals[i as usize].tri).collect();
    let normals: Vec<Vec3> = triangles.iter().map(|&t| mesh.normal(t as usize)).collect();
    // 4. Area probes to the nearest sample.
    let mut sgrid = CellGrid::new();
    let reach = 2.0 * spacing;
    sgrid.rebuild(&points, reach);
    let mut areas = vec![0.0; points.len()];
    let mut start = Vec::with_capacity(ntri + 1);
    let mut cov_sample = Vec::new();
    let mut cov_weight = Vec::new();
    let mut probes: Vec<Vec3> = Vec::new();
    let mut row: Vec<(u32, f64)> = Vec::new();
    start.push(0u32);
    for t in 0..ntri {
        let area = mesh.area(t);
        row.clear();
        if area > 0.0 && !points.is_empty() {
            let [a, b, c] = mesh.corners(t);
            probes.clear();
            lattice_points(a, b, c, spacing / PROBES_PER_SIDE, &mut probes);
            if probes.is_empty() {
                // A triangle smaller than a probe cell is represented by its centroid.
                probes.push((a + b + c) / 3.0);
            }
            let w = area / probes.len() as f64;
            for &q in &probes {
                let mut best = (f64::INFINITY, u32::MAX);
                sgrid.for_each_candidate(q, |j| {
                    let d2 = (points[j as usize] - q).length_squared();
                    if d2 < best.0 || (d2 == best.0 && j < best.1) {
                        best = (d2, j);
                    }
                });
                if best.1 == u32::MAX || best.0 > reach * reach {
                    // A hole wider than the search reach cannot occur after gap filling; stay exact anyway.
                    for (j, p) in points.iter().enumerate() {
                        let d2 = (*p - q).length_squared();
                        if d2 < best.0 {
                            best = (d2, j as u32);
                        }
                    }
                }
                areas[best.1 as usize] += w;
                row.push((best.1, w));
            }
            row.sort_unstable_by_key(|e| e.0);
            let mut k = 0;
            while k < row.len() {
                let (j, mut w) = row[k];
                k += 1;
                while k < row.len() && row[k].0 == j {
                    w += row[k].1;
                    k += 1;
                }
                cov_sample.push(j);
                cov_weight.push(w);
            }
        }
        start.push(cov_sample.len() as u32);
    }
    SurfaceSamples {
        points,
        normals,
        triangles,
        areas,
        coverage: TriangleCoverage { start, sample: cov_sample, weight: cov_weight },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn min_pair_distance(p: &[Vec3]) -> f64 {
        let mut g = CellGrid::new();
        g.rebuild(p, 0.1);
        let mut m = f64::INFINITY;
        for (i, a) in p.iter().enumerate() {
            g.for_each_candidate(*a, |j| {
                if j as usize != i {
                    m = m.min((p[j as usize] - *a).length());
                }
            });
        }
        m
    }

    #[test]
    fn a_flat_rectangle_is_a_regular_grid_whatever_its_triangulation() {
        // 0.3 × 0.2 m at spacing 0.01 → exactly 30 × 20 lattice points, each standing for 1 cm².
        for (nx, ny) in [(1, 1), (7, 5), (30, 20)] {
            let m = TriMesh::rectangle(0.3, 0.2, 0.05, nx, ny);
            let s = sample_surface(&m, 0.01, 3);
            assert_eq!(s.points.len(), 600, "mesh {nx}×{ny}");
            let total: f64 = s.areas.iter().sum();
            assert!((total - 0.06).abs() < 1e-12, "areas add up to the mesh area: {total}");
            for a in &s.areas {
                // Triangles cutting through a point's probes shift a little area between neighbours.
                assert!(*a > 0.5e-4 && *a < 1.5e-4, "area {a}");
            }
            assert!((min_pair_distance(&s.points) - 0.01).abs() < 1e-9);
        }
    }

    #[test]
    fn a_sphere_is_covered_without_duplicates_or_holes() {
        // Icosphere-like tessellation of a unit sphere by latitude/longitude quads.
        let (nu, nv) = (24, 12);
        let pt = |i: usize, j: usize| {
            let th = std::f64::consts::PI * j as f64 / nv as f64;
            let ph = 2.0 * std::f64::consts::PI * i as f64 / nu as f64;
            Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
        };
        let mut soup = Vec::new();
        for i in 0..nu {
            for j in 0..nv {
                let (a, b, c, d) = (pt(i, j), pt(i + 1, j), pt(i + 1, j + 1), pt(i, j + 1));
                soup.extend([a, c, b, a, d, c]);
            }
        }
        let m = TriMesh::from_triangle_soup(&soup);
        let sp = 0.1;
        let s = sample_surface(&m, sp, 9);
        assert!(min_pair_distance(&s.points) >= MIN_DISTANCE * sp - 1e-12);
        // No hole: every surface point lies within one spacing of a sample.
        let mut g = CellGrid::new();
        g.rebuild(&s.points, 2.0 * sp);
        let mut rng = seeded(1, 1);
        for _ in 0..2000 {
            let t = rng.random_range(0..m.triangles.len());
            let [a, b, c] = m.corners(t);
            let q = random_point(a, b, c, &mut rng);
            let mut best = f64::INFINITY;
            g.for_each_candidate(q, |j| best = best.min((s.points[j as usize] - q).length()));
            assert!(best < sp, "hole of radius {best} at {q}");
        }
        // Density about one point per spacing² (the acceptance radius sets it only approximately).
        let per_cell = s.points.len() as f64 * sp * sp / m.total_area();
        assert!(per_cell > 0.8 && per_cell < 1.6, "{per_cell} points per spacing²");
        let total: f64 = s.areas.iter().sum();
        assert!((total - m.total_area()).abs() < 1e-9 * m.total_area());
    }

    #[test]
    fn coverage_maps_per_sample_values_to_area_fractions() {
        // Coarse (2 triangles) and fine (40×40×2) meshes of one plate; mark samples with x < 0.13 as wet.
        for (nx, ny) in [(1, 1), (40, 40)] {
            let m = TriMesh::rectangle(0.4, 0.4, 0.0, nx, ny);
            let s = sample_surface(&m, 0.01, 5);
            let wet: Vec<f64> = s.points.iter().map(|p| if p.x < 0.13 { 1.0 } else { 0.0 }).collect();
            let frac = s.coverage.triangle_means(&wet);
            let wet_area: f64 = frac.iter().enumerate().map(|(t, f)| f * m.area(t)).sum();
            // 13 of 40 lattice columns are wet: 0.13 × 0.4 m². Probes on the diagonals of the coarse mesh are
            // shared by two triangles, which shifts a little area; 0.5 % covers it.
            assert!((wet_area - 0.052).abs() < 0.005 * 0.052, "mesh {nx}: wet area {wet_area}");
            // Triangles are either fully wet, fully dry, or cut by the wet edge with a fractional value.
            assert!(frac.iter().all(|f| (0.0..=1.0).contains(f)));
        }
    }
}
