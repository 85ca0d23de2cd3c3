//! Neighbour queries over a rough-wall bed: a cell list of the bed-sphere centres
//! ([`spatter_core::grid::CellGrid`], cells one bed-sphere diameter wide) answering box queries and
//! first-hit queries along a straight path, so that the impact driver's work per step depends on the
//! spheres near the particle, not on the size of the bed.

use super::impact::BedSphere;
use spatter_core::grid::CellGrid;
use spatter_core::Vec3;

/// Cell list over the centres of a bed's spheres.
#[derive(Clone, Debug, Default)]
pub struct BedIndex {
    grid: CellGrid,
    /// Bounding box of the centres \[m\].
    lo: Vec3,
    hi: Vec3,
    /// Largest sphere radius \[m\].
    max_radius: f64,
    /// Number of spheres indexed.
    len: usize,
}

impl BedIndex {
    /// Indexes `spheres` (cells of one largest-sphere diameter).
    pub fn new(spheres: &[BedSphere]) -> Self {
        let centres: Vec<Vec3> = spheres.iter().map(|q| Vec3::from(q.centre)).collect();
        let max_radius = spheres.iter().map(|q| q.radius).fold(0.0, f64::max);
        let mut grid = CellGrid::new();
        let (mut lo, mut hi) = (Vec3::splat(f64::INFINITY), Vec3::splat(f64::NEG_INFINITY));
        for c in &centres {
            lo = lo.min(*c);
            hi = hi.max(*c);
        }
        if !centres.is_empty() {
            grid.rebuild(&centres, (2.0 * max_radius).max(f64::MIN_POSITIVE.sqrt()));
        }
        BedIndex { grid, lo, hi, max_radius, len: centres.len() }
    }

    /// Largest sphere radius \[m\] (0 for an empty bed).
    pub fn max_radius(&self) -> f64 {
        self.max_radius
    }

    /// Number of spheres indexed.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the bed has no spheres.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Calls `f(i)` for every sphere whose centre may lie in the box `[lo, hi]` (a superset: every sphere
    /// of the cells the box touches). Work is proportional to the spheres in those cells.
    pub fn for_each_in_box(&self, lo: Vec3, hi: Vec3, mut f: impl FnMut(usize)) {
        if self.len == 0 || lo.cmpgt(self.hi).any() || hi.cmplt(self.lo).any() {
            return;
        }
        let origin = self.grid.origin();
        let inv = 1.0 / self.grid.cell_size();
        let dims = self.grid.dims();
        let index = |x: f64, o: f64, n: usize| -> usize {
            let q = ((x - o) * inv).floor();
            if q <= 0.0 {
                0
            } else {
                (q as usize).min(n - 1)
            }
        };
        let (x0, x1) = (index(lo.x, origin.x, dims[0]), index(hi.x, origin.x, dims[0]));
        let (y0, y1) = (index(lo.y, origin.y, dims[1]), index(hi.y, origin.y, dims[1]));
        let (z0, z1) = (index(lo.z, origin.z, dims[2]), index(hi.z, origin.z, dims[2]));
        let entries = self.grid.entries();
        for z in z0..=z1 {
            for y in y0..=y1 {
                let row = (z * dims[1] + y) * dims[0];
                let start = self.grid.cell_range(row + x0).start;
                let end = self.grid.cell_range(row + x1).end;
                for &j in &entries[start..end] {
                    f(j as usize);
                }
            }
        }
    }

    /// First point along the path `o + s·u` (unit `u`, s ≥ 0) at which the centre comes within
    /// `extra + radius` of a sphere centre: `(s, sphere index)`, or `None` if the path never does.
    ///
    /// The path is walked in pieces one cell long, each querying the box around it inflated by the reach;
    /// the walk stops once the nearest hit found lies within the pieces already searched, or where the
    /// path leaves the reach of the bed.
    pub fn first_hit(&self, spheres: &[BedSphere], o: Vec3, u: Vec3, extra: f64) -> Option<(f64, usize)> {
        if self.len == 0 {
            return None;
        }
        let reach = extra + self.max_radius;
        let (s_in, s_out) = ray_box(o, u, self.lo - Vec3::splat(reach), self.hi + Vec3::splat(reach))?;
        let piece = self.grid.cell_size();
        let mut best: Option<(f64, usize)> = None;
        let mut s0 = s_in.max(0.0);
        while s0 <= s_out {
            let s1 = (s0 + piece).min(s_out);
            let (a, b) = (o + u * s0, o + u * s1);
            let lo = a.min(b) - Vec3::splat(reach);
            let hi = a.max(b) + Vec3::splat(reach);
            self.for_each_in_box(lo, hi, |i| {
                let q = spheres[i];
                if let Some(s) = sweep_hit(o, u, Vec3::from(q.centre), extra + q.radius) {
                    if best.is_none_or(|(bs, bi)| s < bs || (s == bs && i < bi)) {
                        best = Some((s, i));
                    }
                }
            });
            if best.is_some_and(|(bs, _)| bs <= s1) || s1 >= s_out {
                break;
            }
            s0 = s1;
        }
        best
    }
}

/// Entry and exit distances of the ray `o + s·u` through the box `[lo, hi]`, `None` if it misses.
fn ray_box(o: Vec3, u: Vec3, lo: Vec3, hi: Vec3) -> Option<(f64, f64)> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for k in 0..3 {
        if u[k] == 0.0 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return None;
            }
        } else {
            let (a, b) = ((lo[k] - o[k]) / u[k], (hi[k] - o[k]) / u[k]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t1 >= t0.max(0.0)).then_some((t0, t1))
}

/// Distance s ≥ 0 along unit direction `u` from `o` at which a point comes within `rr` of `c` (0 if it
/// already is; `None` if it never does or moves away).
pub fn sweep_hit(o: Vec3, u: Vec3, c: Vec3, rr: f64) -> Option<f64> {
    let oc = o - c;
    let bq = u.dot(oc);
    let cq = oc.length_squared() - rr * rr;
    if cq <= 0.0 {
        return Some(0.0);
    }
    if bq >= 0.0 {
        return None;
    }
    let disc = bq * bq - cq;
    (disc >= 0.0).then(|| -bq - disc.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_core::rng::{seeded, RngExt};

    fn brute_first_hit(spheres: &[BedSphere], o: Vec3, u: Vec3, extra: f64) -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        for (i, q) in spheres.iter().enumerate() {
            if let Some(s) = sweep_hit(o, u, Vec3::from(q.centre), extra + q.radius) {
                if best.is_none_or(|(bs, bi)| s < bs || (s == bs && i < bi)) {
                    best = Some((s, i));
                }
            }
        }
        best
    }

    #[test]
    fn queries_equal_brute_force() {
        // The indexed box and first-hit queries must find exactly what a loop over every sphere finds
        // (the superset of the box query filtered by distance; identical first hits).
        let bed = super::super::bed::random_insertion(30e-6, 4e-6, 1e-6, 0.64, &mut seeded(5, 0));
        let s = &bed.spheres;
        let index = BedIndex::new(s);
        assert_eq!(index.len(), s.len());
        let mut rng = seeded(5, 1);
        for k in 0..200 {
            let p = Vec3::new(
                (rng.random::<f64>() - 0.5) * 36e-6,
                (rng.random::<f64>() - 0.5) * 36e-6,
                rng.random::<f64>() * 14e-6 - 2e-6,
            );
            let reach = 6.5e-6;
            let mut found = Vec::new();
            index.for_each_in_box(p - Vec3::splat(reach), p + Vec3::splat(reach), |i| found.push(i));
            found.sort_unstable();
            found.dedup();
            let near: Vec<usize> =
                found.into_iter().filter(|&i| (Vec3::from(s[i].centre) - p).length() < reach).collect();
            let brute: Vec<usize> =
                (0..s.len()).filter(|&i| (Vec3::from(s[i].centre) - p).length() < reach).collect();
            assert_eq!(near, brute, "box query {k}");
            // Paths in every direction, from above, inside and beside the bed.
            let dir =
                Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5)
                    .normalize();
            let extra = 5e-6 * rng.random::<f64>();
            assert_eq!(index.first_hit(s, p, dir, extra), brute_first_hit(s, p, dir, extra), "path {k}");
        }
        // An empty bed answers nothing.
        let empty = BedIndex::new(&[]);
        assert!(empty.is_empty() && empty.first_hit(&[], Vec3::ZERO, Vec3::Z, 1.0).is_none());
    }
}
