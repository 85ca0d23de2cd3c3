//! Uniform cell-list neighbour search, shared by the DEM and SPH engines.
//!
//! [`CellGrid::rebuild`] bins points into cubic cells of edge `cell_size` over their bounding box with a
//! counting sort (O(N)). After a rebuild, [`CellGrid::entries`] lists point indices in cell order
//! (x fastest, then y, then z); engines use it as the permutation that re-sorts their particle arrays for
//! cache locality. Any two points closer than `cell_size` lie in the same or adjacent cells.
//!
//! The grid covers the points' bounding box; if a stray point would make the grid too large (more than
//! `4 N + 4096` cells) the cell size is enlarged, which keeps every query correct and only costs speed.

use crate::{Aabb, Vec3};
use rayon::prelude::*;
use std::ops::Range;

/// Cell list over a set of points.
#[derive(Clone, Debug, Default)]
pub struct CellGrid {
    origin: Vec3,
    cell_size: f64,
    inv_cell: f64,
    dims: [usize; 3],
    cell_start: Vec<u32>,
    entries: Vec<u32>,
    point_cell: Vec<u32>,
    /// Scratch: next free slot of each cell during the scatter (kept to reuse its allocation).
    cursor: Vec<u32>,
}

impl CellGrid {
    pub fn new() -> Self {
        Self::default()
    }

    /// Bins `points` into cells of edge at least `cell_size` \[m\] (> 0). Reuses its allocations.
    pub fn rebuild(&mut self, points: &[Vec3], cell_size: f64) {
        assert!(cell_size > 0.0 && cell_size.is_finite(), "cell size must be positive, got {cell_size}");
        let n = points.len();
        let bounds = if n > 50_000 {
            points.par_chunks(8192).map(Aabb::from_points).reduce(|| Aabb::EMPTY, Aabb::union)
        } else {
            Aabb::from_points(points)
        };
        // A non-finite corner (a point at infinity or NaN, which the engines report as a blow-up after
        // the step) leaves one cell: every query still sees every point.
        let finite = |v: Vec3| v.x.is_finite() && v.y.is_finite() && v.z.is_finite();
        let bounds =
            if bounds.is_empty() || !finite(bounds.min) || !finite(bounds.max) || !finite(bounds.extent()) {
                Aabb::new(Vec3::ZERO, Vec3::ZERO)
            } else {
                bounds
            };
        let max_cells = 4 * n + 4096;
        let mut size = cell_size;
        let dims = loop {
            let e = bounds.extent() / size;
            // Saturating: a stray point 1e300 m away must enlarge the cells, never overflow the count.
            let cells = |x: f64| if x < 1e15 { x as usize + 1 } else { 1_000_000_000_000_000 };
            let d = [cells(e.x), cells(e.y), cells(e.z)];
            let total = (d[0] as f64) * (d[1] as f64) * (d[2] as f64);
            if total <= max_cells as f64 {
                break d;
            }
            size *= (total / max_cells as f64).cbrt() * 1.01;
            if !size.is_finite() {
                // Points near ±1.8e308 m apart: one cell holds them all.
                size = f64::MAX;
                break [1, 1, 1];
            }
        };
        self.origin = bounds.min;
        self.cell_size = size;
        self.inv_cell = 1.0 / size;
        self.dims = dims;
        let ncells = dims[0] * dims[1] * dims[2];

        self.point_cell.resize(n, 0);
        {
            let (origin, inv, dims) = (self.origin, self.inv_cell, self.dims);
            let cell = |p: &Vec3| Self::cell_index_with(origin, inv, dims, *p) as u32;
            if n > 50_000 {
                self.point_cell.par_iter_mut().zip(points.par_iter()).for_each(|(c, p)| *c = cell(p));
            } else {
                self.point_cell.iter_mut().zip(points).for_each(|(c, p)| *c = cell(p));
            }
        }
        self.cell_start.clear();
        self.cell_start.resize(ncells + 1, 0);
        for &c in &self.point_cell {
            self.cell_start[c as usize + 1] += 1;
        }
        for c in 0..ncells {
            self.cell_start[c + 1] += self.cell_start[c];
        }
        self.entries.resize(n, 0);
        // Scatter with a running cursor per cell; point order within a cell stays ascending (stable).
        self.cursor.clear();
        self.cursor.extend_from_slice(&self.cell_start[..ncells]);
        for (i, &c) in self.point_cell.iter().enumerate() {
            let slot = &mut self.cursor[c as usize];
            self.entries[*slot as usize] = i as u32;
            *slot += 1;
        }
    }

    #[inline]
    fn cell_coord(origin: Vec3, inv: f64, dims: [usize; 3], p: Vec3) -> [usize; 3] {
        let q = (p - origin) * inv;
        let clamp = |x: f64, d: usize| {
            if x.is_nan() || x <= 0.0 {
                0
            } else {
                (x as usize).min(d - 1)
            }
        };
        [clamp(q.x, dims[0]), clamp(q.y, dims[1]), clamp(q.z, dims[2])]
    }

    #[inline]
    fn cell_index_with(origin: Vec3, inv: f64, dims: [usize; 3], p: Vec3) -> usize {
        let c = Self::cell_coord(origin, inv, dims, p);
        (c[2] * dims[1] + c[1]) * dims[0] + c[0]
    }

    /// Lower corner of cell (0, 0, 0) \[m\]: cell `(i, j, k)` spans `origin + [i, i+1)·cell_size` etc.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// The cell edge actually used \[m\] (≥ the requested one).
    pub fn cell_size(&self) -> f64 {
        self.cell_size
    }

    /// Number of cells along x, y, z.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Point indices in cell order: the permutation that sorts points by cell.
    pub fn entries(&self) -> &[u32] {
        &self.entries
    }

    /// Cell of point `i` as binned by the last rebuild.
    pub fn cell_of_point(&self, i: usize) -> usize {
        self.point_cell[i] as usize
    }

    /// Range of [`entries`](Self::entries) that holds cell `c`.
    pub fn cell_range(&self, c: usize) -> Range<usize> {
        self.cell_start[c] as usize..self.cell_start[c + 1] as usize
    }

    /// Calls `f` with ranges of [`entries`](Self::entries) that together hold every point in the 3×3×3
    /// cells around `p` (each x-row of three cells is one contiguous range, so at most nine calls).
    #[inline]
    pub fn for_each_candidate_run(&self, p: Vec3, mut f: impl FnMut(Range<usize>)) {
        if self.entries.is_empty() {
            return;
        }
        let c = Self::cell_coord(self.origin, self.inv_cell, self.dims, p);
        let [nx, ny, nz] = self.dims;
        let x0 = c[0].saturating_sub(1);
        let x1 = (c[0] + 1).min(nx - 1);
        for z in c[2].saturating_sub(1)..=(c[2] + 1).min(nz - 1) {
            for y in c[1].saturating_sub(1)..=(c[1] + 1).min(ny - 1) {
                let row = (z * ny + y) * nx;
                let start = self.cell_start[row + x0] as usize;
                let end = self.cell_start[row + x1 + 1] as usize;
                if start < end {
                    f(start..end);
                }
            }
        }
    }

    /// Calls `f(j)` for every point `j` in the 3×3×3 cells around `p` (a superset of the points within
    /// `cell_size` of `p`).
    #[inline]
    pub fn for_each_candidate(&self, p: Vec3, mut f: impl FnMut(u32)) {
        self.for_each_candidate_run(p, |r| self.entries[r].iter().for_each(|&j| f(j)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(n: usize, seed: u64) -> Vec<Vec3> {
        let mut s = seed;
        let mut r = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        (0..n).map(|_| Vec3::new(r(), 0.5 * r(), 2.0 * r())).collect()
    }

    /// The grid's entries are a permutation of the points, and the candidates of every `step`-th of the
    /// first `queries` points within `h` are exactly the points a brute-force search finds.
    fn assert_brute_force_neighbours(g: &CellGrid, pts: &[Vec3], h: f64, queries: usize, step: usize) {
        let mut perm = g.entries().to_vec();
        perm.sort_unstable();
        assert_eq!(perm, (0..pts.len() as u32).collect::<Vec<_>>(), "entries is a permutation");
        for (i, p) in pts.iter().enumerate().take(queries).step_by(step) {
            let mut found = Vec::new();
            g.for_each_candidate(*p, |j| {
                if (pts[j as usize] - *p).length() < h {
                    found.push(j)
                }
            });
            found.sort_unstable();
            let brute: Vec<u32> =
                (0..pts.len() as u32).filter(|&j| (pts[j as usize] - *p).length() < h).collect();
            assert_eq!(found, brute, "point {i}");
        }
    }

    #[test]
    fn finds_exactly_the_brute_force_neighbours() {
        let pts = cloud(2000, 7);
        let h = 0.07;
        let mut g = CellGrid::new();
        g.rebuild(&pts, h);
        assert_brute_force_neighbours(&g, &pts, h, pts.len(), 37);
    }

    #[test]
    fn a_stray_point_enlarges_cells_instead_of_exhausting_memory() {
        let mut pts = cloud(100, 3);
        pts.push(Vec3::new(1e9, -1e9, 1e9));
        let mut g = CellGrid::new();
        g.rebuild(&pts, 1e-3);
        let d = g.dims();
        assert!(d[0] * d[1] * d[2] <= 4 * pts.len() + 4096);
        let mut n = 0;
        g.for_each_candidate(pts[100], |_| n += 1);
        assert!(n >= 1);
    }

    /// Points 1e300 m away or at infinity (a scene with a bed row at x = 1e300 m or a gravity of
    /// 1e300 m/s² sent the engines here, where the cell count overflowed and the binning indexed out of
    /// bounds): the grid stays within its cell budget and every query still finds its true neighbours.
    #[test]
    fn points_at_huge_or_infinite_distances_are_binned_and_found() {
        let h = 0.07;
        for far in
            [Vec3::new(1e300, 0.0, 0.0), Vec3::new(-1e308, 1e308, 1e308), Vec3::new(f64::INFINITY, 0.0, 0.0)]
        {
            let mut pts = cloud(300, 5);
            pts.push(far);
            let mut g = CellGrid::new();
            g.rebuild(&pts, h);
            let d = g.dims();
            assert!(
                d.iter().all(|&k| k >= 1) && d[0] * d[1] * d[2] <= 4 * pts.len() + 4096,
                "{far:?}: {d:?}"
            );
            assert_brute_force_neighbours(&g, &pts, h, 300, 23);
        }
    }

    #[test]
    fn empty_and_nan_inputs_do_not_panic() {
        let mut g = CellGrid::new();
        g.rebuild(&[], 0.1);
        g.for_each_candidate(Vec3::ZERO, |_| panic!("no points"));
        g.rebuild(&[Vec3::new(f64::NAN, 0.0, 0.0), Vec3::ONE], 0.1);
        assert_eq!(g.entries().len(), 2);
    }
}
