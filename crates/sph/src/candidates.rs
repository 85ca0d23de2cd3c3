//! Branch-free collection of the neighbours of a point from contiguous ranges of a sorted particle set,
//! testing four candidates per instruction in single precision.
//!
//! Each set keeps, next to its double-precision positions, a single-precision copy in structure-of-arrays
//! form ([`Coords32`], 12 bytes per particle), relative to an origin shared by every set of a run. The
//! cut-off test runs on that copy four lanes wide (SSE2 on baseline x86-64), and the lanes' results
//! become a bit mask, so the candidate loop has neither a branch per candidate nor a conversion. The pair
//! terms still take their distances from the double-precision positions.
//!
//! Precision: coordinates are rounded to `f32` relative to an origin fixed for the run (the domain's
//! lower corner), an error of at most 6·10⁻⁸ `L` per coordinate for points within `L` of it, so a pair
//! whose distance is within about `2·10⁻⁷ L` of the cut-off may be classified either way. Its kernel
//! gradient is zero to that order (Wendland C2 and the cubic spline vanish with their first two
//! derivatives at the support), so the forces do not change beyond rounding; the interaction count can.
//! The cut-off lies 10⁻⁴ inside the support (`Simulation::consts`), so lattice neighbours exactly at the
//! support stay out while `L` is below about 750 particle spacings (h = 1.5 dp; worst-case rounding);
//! in larger domains a few of them may be counted, with terms zero to rounding. The test is symmetric:
//! the wall pass and the fluid pass classify a pair alike, since both subtract the same two rounded
//! coordinates.

use rayon::prelude::*;
use spatter_core::Vec3;
use std::ops::Range;

/// Capacity of a neighbour list; a power of two, so that a masked index needs no bounds check.
pub(crate) const BATCH: usize = 256;
const _: () = assert!(BATCH.is_power_of_two());

/// Lanes of one test.
const LANES: usize = 4;

/// For each mask of four lanes, the set lanes packed to the front (the other slots 0).
const PACKED: [[u32; LANES]; 16] = {
    let mut t = [[0u32; LANES]; 16];
    let mut m = 0;
    while m < 16 {
        let (mut l, mut n) = (0, 0);
        while l < LANES {
            if (m >> l) & 1 == 1 {
                t[m][n] = l as u32;
                n += 1;
            }
            l += 1;
        }
        m += 1;
    }
    t
};

/// For each mask of four lanes, the number of set lanes, four bits per mask.
const COUNTS: u64 = {
    let (mut c, mut m) = (0u64, 0);
    while m < 16 {
        c |= ((m as u32).count_ones() as u64) << (4 * m);
        m += 1;
    }
    c
};

/// Single-precision coordinates of a sorted set, relative to an origin, padded by `LANES − 1` entries
/// so that a test may read past the end of the last range.
#[derive(Clone, Debug, Default)]
pub(crate) struct Coords32 {
    x: Vec<f32>,
    y: Vec<f32>,
    z: Vec<f32>,
    origin: Vec3,
}

/// Borrowed [`Coords32`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct Coords32View<'a> {
    x: &'a [f32],
    y: &'a [f32],
    z: &'a [f32],
    origin: Vec3,
}

impl Coords32 {
    /// Copies `pos` \[m\] relative to `origin` \[m\].
    pub fn fill(&mut self, pos: &[Vec3], origin: Vec3) {
        self.origin = origin;
        let n = pos.len();
        for (axis, v) in [&mut self.x, &mut self.y, &mut self.z].into_iter().enumerate() {
            v.clear();
            v.resize(n + LANES - 1, f32::INFINITY);
            v[..n].par_iter_mut().with_min_len(4096).zip(pos.par_iter()).for_each(|(c, p)| {
                *c = (p[axis] - origin[axis]) as f32;
            });
        }
    }

    /// The origin of the coordinates \[m\].
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    pub fn view(&self) -> Coords32View<'_> {
        Coords32View { x: &self.x, y: &self.y, z: &self.z, origin: self.origin }
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        (self.x.capacity() + self.y.capacity() + self.z.capacity()) * std::mem::size_of::<f32>()
    }
}

impl Coords32View<'_> {
    /// A query at `p` \[m\] with squared cut-off `r2max` \[m²\], rounded as the set's coordinates are.
    #[inline(always)]
    pub fn query(&self, p: Vec3, r2max: f64) -> Query {
        let q = p - self.origin;
        Query {
            x: glam::Vec4::splat(q.x as f32),
            y: glam::Vec4::splat(q.y as f32),
            z: glam::Vec4::splat(q.z as f32),
            r2: glam::Vec4::splat(r2max as f32),
        }
    }
}

/// A query point and squared cut-off in single precision, one value per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Query {
    x: glam::Vec4,
    y: glam::Vec4,
    z: glam::Vec4,
    r2: glam::Vec4,
}

impl Query {
    /// Bit `l` set when candidate `l` of the four at `x, y, z` lies within the cut-off.
    #[inline(always)]
    fn mask(&self, x: &[f32], y: &[f32], z: &[f32]) -> u32 {
        let dx = glam::Vec4::from_slice(x) - self.x;
        let dy = glam::Vec4::from_slice(y) - self.y;
        let dz = glam::Vec4::from_slice(z) - self.z;
        (dx * dx + dy * dy + dz * dz).cmplt(self.r2).bitmask()
    }
}

/// A neighbour list filled without branching: every candidate's index is written to the next free slot,
/// which only advances when the candidate is within the cut-off.
pub(crate) struct Candidates {
    list: [u32; BATCH],
    n: usize,
}

impl Candidates {
    pub fn new() -> Self {
        Candidates { list: [0; BATCH], n: 0 }
    }

    /// Appends the indices `k` in `range` of the points of `set` within the cut-off of `q`; whenever the
    /// list cannot take four more it is handed to `flush` and emptied.
    #[inline(always)]
    pub fn collect(
        &mut self,
        q: &Query,
        set: &Coords32View,
        range: Range<usize>,
        mut flush: impl FnMut(&[u32]),
    ) {
        let Range { mut start, end } = range;
        // Equal lengths, so that one bounds test of a range covers the three axes. Ranges come from the
        // set's own cell list, filled from the same positions, so they lie within the coordinates.
        let len = set.x.len().min(set.y.len()).min(set.z.len());
        let (xs, ys, zs) = (&set.x[..len], &set.y[..len], &set.z[..len]);
        while start < end {
            if self.n + LANES > BATCH {
                flush(&self.list[..self.n]);
                self.n = 0;
            }
            // At most as many candidates as the free slots hold in whole groups: the loops below then
            // need no capacity test (a last, partial group writes four slots too).
            let stop = end.min(start + ((BATCH - self.n) & !(LANES - 1)));
            let whole = start + (stop - start) / LANES * LANES;
            let mut n = self.n;
            let list = &mut self.list;
            let mut k = glam::UVec4::splat(start as u32);
            let mut put = |m: u32, k: glam::UVec4| {
                // The selected indices, packed to the front, fill the next four slots; their count
                // advances the list.
                (k + glam::UVec4::from_array(PACKED[m as usize])).write_to_slice(&mut list[n..n + LANES]);
                n += (COUNTS >> (4 * m)) as usize & 0xf;
            };
            let groups = xs[start..whole]
                .chunks_exact(LANES)
                .zip(ys[start..whole].chunks_exact(LANES))
                .zip(zs[start..whole].chunks_exact(LANES));
            for ((cx, cy), cz) in groups {
                put(q.mask(cx, cy, cz), k);
                k += glam::UVec4::splat(LANES as u32);
            }
            if whole < stop {
                // Lanes past the end of the range are not candidates.
                let g = whole..whole + LANES;
                put(q.mask(&xs[g.clone()], &ys[g.clone()], &zs[g]) & ((1 << (stop - whole)) - 1), k);
            }
            self.n = n;
            start = stop;
        }
    }

    /// The neighbours collected since the last flush; empties the list.
    #[inline(always)]
    pub fn take(&mut self) -> &[u32] {
        let n = std::mem::replace(&mut self.n, 0);
        &self.list[..n]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The collected lists hold exactly the points within the cut-off, in index order, for ranges of
    /// every length modulo four, lists that overflow, and points far from the origin.
    #[test]
    fn collects_exactly_the_points_within_the_cut_off() {
        use spatter_core::rng::RngExt;
        let mut rng = spatter_core::rng::seeded(7, 0);
        let mut rnd = move || rng.random::<f64>();
        let far = Vec3::new(250.0, -40.0, 3.0);
        let pts: Vec<Vec3> = (0..2000).map(|_| far + Vec3::new(rnd(), rnd(), rnd())).collect();
        let mut c32 = Coords32::default();
        c32.fill(&pts, far - Vec3::splat(0.5));
        let set = c32.view();
        let mut cand = Candidates::new();
        for t in 0..200 {
            let p = far + Vec3::new(rnd(), rnd(), rnd());
            let r = 0.05 + 0.4 * rnd();
            let (a, b) = ((t * 37) % 2000, (t * 37) % 2000 + t * 9 % 1500);
            let b = b.min(2000);
            let d2 = |k: u32| (pts[k as usize] - p).length_squared();
            // Points within 10⁻⁵ of the squared cut-off may fall either way in single precision.
            let clear = |k: u32| (d2(k) - r * r).abs() > 1e-5 * r * r;
            let want: Vec<u32> = (a as u32..b as u32).filter(|&k| clear(k) && d2(k) < r * r).collect();
            let mut got = Vec::new();
            // Two ranges, to cross the list's fills.
            let mid = a + (b - a) / 3;
            cand.collect(&set.query(p, r * r), &set, a..mid, |l| got.extend_from_slice(l));
            cand.collect(&set.query(p, r * r), &set, mid..b, |l| got.extend_from_slice(l));
            got.extend_from_slice(cand.take());
            assert!(got.windows(2).all(|w| w[0] < w[1]), "query {t}: not in index order");
            assert!(got.iter().all(|&k| (a..b).contains(&(k as usize))), "query {t}: index outside {a}..{b}");
            got.retain(|&k| clear(k));
            assert_eq!(got, want, "query {t}, range {a}..{b}");
        }
    }

    #[test]
    fn an_empty_set_yields_nothing() {
        let mut c32 = Coords32::default();
        c32.fill(&[], Vec3::ONE);
        let set = c32.view();
        let mut cand = Candidates::new();
        cand.collect(&set.query(Vec3::ZERO, 1.0), &set, 0..0, |_| panic!("flushed"));
        assert!(cand.take().is_empty());
    }
}
