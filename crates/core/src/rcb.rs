//! Recursive coordinate bisection: which rank owns which part of space.
//!
//! A decomposed run gives every rank a box; a particle belongs to the rank whose box holds it. The boxes
//! come from the particles: the ranks are split in two groups (⌊n/2⌋ and ⌈n/2⌉), the particles in two sets
//! of proportional size along the longest extent of their bounding box, and each half is split again
//! until every group has one rank (Berger & Bokhari, "A partitioning strategy for nonuniform problems on
//! multiprocessors", IEEE Trans. Computers 36, 1987). A cut lies midway between two neighbouring particle
//! coordinates, so particles on one lattice plane never straddle a cut. The tree is built from the same
//! points on every rank and is deterministic, so every rank holds the same tree without a message.
//!
//! Boxes are half-open (`x < cut` goes low). Their outer faces are the domain's on periodic axes and
//! ±∞ on the others, so a particle that leaves the domain still has an owner.

use crate::comm::{Comm, WireReader, WireWriter};
use crate::{Aabb, Vec3};
use serde::{Deserialize, Serialize};

/// Largest number of points a rebalanced split is built from ([`Rcb::rebalanced`]).
pub const REBALANCE_SAMPLE: u64 = 1 << 20;

/// Default load imbalance (most particles on one rank over the mean) above which the engines rebuild
/// their split ([`Rcb::improved`]).
pub const DEFAULT_REBALANCE: f64 = 1.2;

/// The imbalance limit of a scenario's `rebalance_imbalance` key: the default when it is absent, `None`
/// (never rebalance) for `inf`.
pub fn rebalance_limit(key: Option<f64>) -> Option<f64> {
    let v = key.unwrap_or(DEFAULT_REBALANCE);
    v.is_finite().then_some(v)
}

/// One node of the tree: a leaf names its rank; a split sends `x[axis] < at` to `lo`, the rest to `hi`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
enum Node {
    Leaf { rank: usize },
    Split { axis: usize, at: f64, lo: usize, hi: usize },
}

/// A decomposition of space into one box per rank.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rcb {
    nodes: Vec<Node>,
    ranks: usize,
    domain: Aabb,
    periodic: [bool; 3],
}

/// A rank whose box, shifted by `shift` (a periodic image), lies within the halo width of this rank's box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Peer {
    pub rank: usize,
    /// Add to a position on `rank` to bring it next to this rank's box \[m\].
    pub shift: Vec3,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RcbError {
    #[error("{ranks} ranks for {points} particles: every rank needs at least one particle; use at most {points} ranks")]
    TooManyRanks { ranks: usize, points: usize },
    #[error("no particles to split over {ranks} ranks: start the run without mpirun")]
    NoParticles { ranks: usize },
    #[error("a run needs at least one rank")]
    NoRanks,
    #[error("{points} particles on {ranks} ranks cannot be split: they share one position along every axis")]
    Unsplittable { ranks: usize, points: usize },
    #[error("a periodic axis needs a domain of positive, finite length (axis {axis})")]
    BadPeriodicDomain { axis: usize },
}

impl Rcb {
    /// Builds the tree over `points` for `ranks` ranks. `domain` gives the outer faces on `periodic` axes
    /// (elsewhere they are infinite); points are expected inside it on those axes.
    pub fn from_points(
        points: &[Vec3],
        ranks: usize,
        domain: Aabb,
        periodic: [bool; 3],
    ) -> Result<Self, RcbError> {
        if ranks == 0 {
            return Err(RcbError::NoRanks);
        }
        if points.is_empty() && ranks > 1 {
            return Err(RcbError::NoParticles { ranks });
        }
        if points.len() < ranks {
            return Err(RcbError::TooManyRanks { ranks, points: points.len() });
        }
        for (axis, &is_periodic) in periodic.iter().enumerate() {
            let len = domain.max[axis] - domain.min[axis];
            if is_periodic && !(len.is_finite() && len > 0.0) {
                return Err(RcbError::BadPeriodicDomain { axis });
            }
        }
        let mut rcb = Rcb { nodes: Vec::with_capacity(2 * ranks), ranks, domain, periodic };
        let mut order: Vec<usize> = (0..points.len()).collect();
        rcb.split(points, &mut order, 0, ranks)?;
        Ok(rcb)
    }

    /// Adds the subtree for ranks `first..first + n` over the points `idx`; returns its node index.
    fn split(
        &mut self,
        points: &[Vec3],
        idx: &mut [usize],
        first: usize,
        n: usize,
    ) -> Result<usize, RcbError> {
        let me = self.nodes.len();
        if n == 1 {
            self.nodes.push(Node::Leaf { rank: first });
            return Ok(me);
        }
        let n_lo = n / 2;
        let bounds = Aabb::from_points(idx.iter().map(|&i| &points[i]));
        let extent = bounds.extent();
        let mut axes = [0usize, 1, 2];
        // Longest extent first; ties keep the lower axis (a stable sort), so the order is deterministic.
        axes.sort_by(|&a, &b| extent[b].total_cmp(&extent[a]));
        let target = (idx.len() as u128 * n_lo as u128 / n as u128) as usize;
        let mut chosen = None;
        for axis in axes {
            idx.sort_by(|&a, &b| points[a][axis].total_cmp(&points[b][axis]).then(a.cmp(&b)));
            let coord = |k: usize| points[idx[k]][axis];
            // Admissible split positions k: both sides keep at least one point per rank, and the points
            // either side of the cut differ in this coordinate. Take the one nearest the balanced target.
            let lo_min = n_lo;
            let lo_max = idx.len() - (n - n_lo);
            let best = (lo_min..=lo_max)
                .filter(|&k| coord(k - 1) < coord(k))
                .min_by_key(|&k| (k.abs_diff(target), k));
            if let Some(k) = best {
                chosen = Some((axis, k, 0.5 * (coord(k - 1) + coord(k))));
                break;
            }
        }
        let Some((axis, k, at)) = chosen else {
            return Err(RcbError::Unsplittable { ranks: n, points: idx.len() });
        };
        // The last sort was along the chosen axis (the loop breaks right after it).
        self.nodes.push(Node::Split { axis, at, lo: 0, hi: 0 });
        let (lo_idx, hi_idx) = idx.split_at_mut(k);
        let lo = self.split(points, lo_idx, first, n_lo)?;
        let hi = self.split(points, hi_idx, first + n_lo, n - n_lo)?;
        if let Node::Split { lo: l, hi: h, .. } = &mut self.nodes[me] {
            *l = lo;
            *h = hi;
        }
        Ok(me)
    }

    /// The load imbalance of a split now: the largest number of particles on one rank over the mean
    /// number (1 is perfect balance), from every rank's count `local` of the particles it owns.
    /// Collective; every rank gets the same value. With no particles at all it is 1.
    pub fn imbalance(comm: &dyn Comm, local: usize) -> f64 {
        let mut most = [local as f64];
        comm.all_max_f64(&mut most);
        let mut total = [local as u64];
        comm.all_sum_u64(&mut total);
        if total[0] == 0 {
            return 1.0;
        }
        most[0] * comm.size() as f64 / total[0] as f64
    }

    /// A split of the particles where they are now, for dynamic load balancing: every rank passes the
    /// ids and positions of the particles it owns, and every rank gets the same tree, built by
    /// [`Self::from_points`] over the gathered points ordered by id. Above [`REBALANCE_SAMPLE`]
    /// particles only those whose id is a multiple of the stride ⌈N / REBALANCE_SAMPLE⌉ are gathered
    /// (ids are unique). With m sample points per rank the counts then balance to within about 1/√m
    /// (1 % at 100 ranks, 3 % at 1000) and the gather stays at 30 MB whatever the run's size; below
    /// that size every particle counts and the balance is [`Self::from_points`]'s. The result depends on the set of
    /// particles only, not on which rank holds which, nor in which order. Also returns the imbalance of
    /// the new split over the gathered points (exact below the sample size), so that a caller can keep
    /// the old split when the new one would be no better (particles sharing a coordinate on a lattice
    /// cannot always be balanced). Collective.
    pub fn rebalanced(
        comm: &dyn Comm,
        ids: &[u32],
        pos: &[Vec3],
        domain: Aabb,
        periodic: [bool; 3],
    ) -> Result<(Self, f64), RcbError> {
        let mut total = [pos.len() as u64];
        comm.all_sum_u64(&mut total);
        let stride = total[0].div_ceil(REBALANCE_SAMPLE).max(1);
        let mut w = WireWriter::with_capacity(28 * (pos.len() / stride as usize + 1));
        for (&id, &x) in ids.iter().zip(pos) {
            if u64::from(id) % stride == 0 {
                w.u32(id).vec3(x);
            }
        }
        let mut sample = Vec::new();
        for buf in comm.all_gather_bytes(&w.finish()) {
            let mut r = WireReader::new(&buf);
            while !r.is_done() {
                // Written just above by the same code on every rank.
                let bad = "load-balance sample from another rank of this run";
                sample.push((r.u32().expect(bad), r.vec3().expect(bad)));
            }
        }
        sample.sort_by_key(|e| e.0);
        let points: Vec<Vec3> = sample.into_iter().map(|e| e.1).collect();
        let rcb = Self::from_points(&points, comm.size(), domain, periodic)?;
        let mut counts = vec![0usize; comm.size()];
        for &x in &points {
            counts[rcb.owner(x)] += 1;
        }
        let most = counts.iter().copied().max().unwrap_or(0);
        let imbalance = most as f64 * comm.size() as f64 / points.len() as f64;
        Ok((rcb, imbalance))
    }

    /// The domain the split was built for (its faces bound the boxes on periodic axes only).
    pub fn domain(&self) -> Aabb {
        self.domain
    }

    /// Dynamic load balancing: when the imbalance of the particles each rank owns now
    /// ([`Self::imbalance`]) exceeds `limit`, the split [`Self::rebalanced`] builds over them, unless it
    /// would be no better (particles sharing coordinates on a lattice) or cannot be built (fewer
    /// particles than ranks); otherwise `None`, keep the split in force. Depends on the particles only,
    /// so every rank gets the same answer. Collective.
    pub fn improved(
        comm: &dyn Comm,
        limit: f64,
        ids: &[u32],
        pos: &[Vec3],
        domain: Aabb,
        periodic: [bool; 3],
    ) -> Option<Self> {
        let now = Self::imbalance(comm, pos.len());
        if now <= limit {
            return None;
        }
        let (rcb, after) = Self::rebalanced(comm, ids, pos, domain, periodic).ok()?;
        (after < now).then_some(rcb)
    }

    /// Number of ranks.
    pub fn ranks(&self) -> usize {
        self.ranks
    }

    /// The rank whose box holds `p`.
    pub fn owner(&self, p: Vec3) -> usize {
        let mut node = 0;
        loop {
            match self.nodes[node] {
                Node::Leaf { rank } => return rank,
                Node::Split { axis, at, lo, hi } => node = if p[axis] < at { lo } else { hi },
            }
        }
    }

    /// Every rank's box, in rank order (half-open: the upper faces belong to the next box).
    pub fn boxes(&self) -> Vec<Aabb> {
        let mut outer = Aabb::new(Vec3::splat(f64::NEG_INFINITY), Vec3::splat(f64::INFINITY));
        for axis in 0..3 {
            if self.periodic[axis] {
                outer.min[axis] = self.domain.min[axis];
                outer.max[axis] = self.domain.max[axis];
            }
        }
        let mut boxes = vec![outer; self.ranks];
        self.collect_boxes(0, outer, &mut boxes);
        boxes
    }

    fn collect_boxes(&self, node: usize, b: Aabb, out: &mut [Aabb]) {
        match self.nodes[node] {
            Node::Leaf { rank } => out[rank] = b,
            Node::Split { axis, at, lo, hi } => {
                let (mut lo_box, mut hi_box) = (b, b);
                lo_box.max[axis] = at;
                hi_box.min[axis] = at;
                self.collect_boxes(lo, lo_box, out);
                self.collect_boxes(hi, hi_box, out);
            }
        }
    }

    /// The ranks (with the periodic shift of their image) whose box comes within `width` of rank `me`'s
    /// box, sorted by rank then shift; `me` itself appears only through a periodic image. The relation is
    /// symmetric: if `b` is a peer of `a` with shift `s`, then `a` is a peer of `b` with shift `−s`.
    pub fn peers(&self, me: usize, width: f64) -> Vec<Peer> {
        let boxes = self.boxes();
        let mine = boxes[me];
        let len = self.domain.extent();
        let steps = |axis: usize| -> &'static [f64] {
            if self.periodic[axis] {
                &[-1.0, 0.0, 1.0]
            } else {
                &[0.0]
            }
        };
        // The shift along a non-periodic axis is exactly 0, never `0 × length`: the domain may be
        // unbounded there, and 0 × ∞ is NaN.
        let component = |axis: usize, step: f64| if self.periodic[axis] { step * len[axis] } else { 0.0 };
        let mut out = Vec::new();
        for (rank, other) in boxes.iter().enumerate() {
            for &sx in steps(0) {
                for &sy in steps(1) {
                    for &sz in steps(2) {
                        let shift = Vec3::new(component(0, sx), component(1, sy), component(2, sz));
                        if rank == me && shift == Vec3::ZERO {
                            continue;
                        }
                        if mine.gap(&Aabb::new(other.min + shift, other.max + shift)) <= width {
                            out.push(Peer { rank, shift });
                        }
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A dam-break water column as a lattice of spacing 1: 20 × 10 × 6 points.
    fn lattice() -> Vec<Vec3> {
        let mut p = Vec::new();
        for i in 0..20 {
            for j in 0..10 {
                for k in 0..6 {
                    p.push(Vec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5));
                }
            }
        }
        p
    }

    fn domain() -> Aabb {
        Aabb::new(Vec3::ZERO, Vec3::new(20.0, 10.0, 6.0))
    }

    /// The lattice dealt out over 3 ranks unevenly and in scrambled order (every point to rank
    /// `(7 i) mod 11 mod 3`, each rank's list reversed): the rebalanced split is the one built from all
    /// points on one rank, whatever rank holds which point; the imbalance is the largest count over the
    /// mean, computed by hand here.
    #[test]
    fn a_rebalanced_split_depends_only_on_the_particles() {
        use crate::comm::ThreadComm;
        let pts = lattice();
        let expected = Rcb::from_points(&pts, 3, domain(), [false; 3]).unwrap();
        let holder = |i: usize| (7 * i) % 11 % 3;
        let counts: Vec<usize> = (0..3).map(|r| (0..pts.len()).filter(|&i| holder(i) == r).count()).collect();
        let most = *counts.iter().max().unwrap() as f64;
        let out = ThreadComm::run(3, |comm| {
            let (mut ids, mut pos) = (Vec::new(), Vec::new());
            for (i, &p) in pts.iter().enumerate().rev() {
                if holder(i) == comm.rank() {
                    ids.push(i as u32);
                    pos.push(p);
                }
            }
            let imbalance = Rcb::imbalance(comm, pos.len());
            (Rcb::rebalanced(comm, &ids, &pos, domain(), [false; 3]).unwrap(), imbalance)
        });
        // The new split's imbalance: its largest count over the mean (whole planes of 60 points move, so
        // 1200 points split 420 / 360 / 420 over 3 ranks: 1.05).
        let mut split = [0usize; 3];
        pts.iter().for_each(|&x| split[expected.owner(x)] += 1);
        let after_expected = *split.iter().max().unwrap() as f64 * 3.0 / pts.len() as f64;
        for ((rcb, after), imbalance) in out {
            assert_eq!(rcb, expected);
            assert_eq!(imbalance, most * 3.0 / pts.len() as f64, "counts {counts:?}");
            assert_eq!(after, after_expected, "split {split:?}");
            assert!(after < imbalance);
        }
        assert!(counts.iter().any(|&c| c as f64 > 1.05 * pts.len() as f64 / 3.0), "{counts:?} is uneven");
    }

    /// Above the sample size only every stride-th id is gathered: 3·2²⁰ + 5 points on a line (ids in
    /// order) split over 2 ranks put the cut at the sample's median, within one stride of the true
    /// median; with no particles the imbalance is 1.
    #[test]
    fn a_large_run_is_rebalanced_from_a_sample() {
        use crate::comm::ThreadComm;
        let n = 3 * REBALANCE_SAMPLE as usize + 5;
        let out = ThreadComm::run(2, |comm| {
            // Rank 0 holds the first 90 %.
            let range = if comm.rank() == 0 { 0..n * 9 / 10 } else { n * 9 / 10..n };
            let ids: Vec<u32> = range.clone().map(|i| i as u32).collect();
            let pos: Vec<Vec3> = range.map(|i| Vec3::new(i as f64, 0.0, 0.0)).collect();
            let (rcb, _) = Rcb::rebalanced(comm, &ids, &pos, Aabb::EMPTY, [false; 3]).unwrap();
            (rcb.boxes()[0].max.x, Rcb::imbalance(comm, 0))
        });
        // Stride ⌈n / 2²⁰⌉ = 4: the ids 0, 4, 8, … are gathered, so the cut lies midway between two
        // sampled points (at 4k + 2; from every point it would lie at m + 0.5).
        let stride = 4.0;
        for (cut, empty) in out {
            assert!((cut - 0.5 * n as f64).abs() <= stride, "cut at {cut}, median {}", 0.5 * n as f64);
            assert_eq!(cut % stride, 2.0, "cut at {cut}: between two sampled ids");
            assert_eq!(empty, 1.0);
        }
    }

    /// Counts are balanced to within one lattice plane of the largest group (the cut never splits a
    /// plane), every point lies in its owner's box, and cuts fall midway between planes.
    #[test]
    fn lattice_is_balanced_and_owners_match_boxes() {
        let pts = lattice();
        for ranks in 1..=7 {
            let rcb = Rcb::from_points(&pts, ranks, domain(), [false; 3]).unwrap();
            let boxes = rcb.boxes();
            let mut count = vec![0usize; ranks];
            for p in &pts {
                let r = rcb.owner(*p);
                count[r] += 1;
                let b = boxes[r];
                assert!(p.cmpge(b.min).all() && p.cmplt(b.max).all(), "{p} outside box {r} {b:?}");
            }
            let ideal = pts.len() as f64 / ranks as f64;
            // The largest plane of this lattice holds 10 × 6 = 60 points; two nested cuts can each be off
            // by half a plane.
            for (r, &c) in count.iter().enumerate() {
                assert!((c as f64 - ideal).abs() <= 60.0, "{ranks} ranks: rank {r} has {c}, ideal {ideal}");
                assert!(c > 0);
            }
            for node in &rcb.nodes {
                if let Node::Split { at, .. } = node {
                    assert_eq!(at.fract(), 0.0, "cut {at} between planes at half-integers");
                }
            }
        }
    }

    /// Two ranks on the 20-long column cut it in the middle, exactly as a hand count says.
    #[test]
    fn two_ranks_cut_the_long_axis_in_half() {
        let rcb = Rcb::from_points(&lattice(), 2, domain(), [false; 3]).unwrap();
        assert_eq!(rcb.nodes[0], Node::Split { axis: 0, at: 10.0, lo: 1, hi: 2 });
        assert_eq!(rcb.owner(Vec3::new(9.99, 0.0, 0.0)), 0);
        assert_eq!(rcb.owner(Vec3::new(10.0, 0.0, 0.0)), 1);
        // Outside the domain a point still has an owner.
        assert_eq!(rcb.owner(Vec3::new(-5.0, 100.0, 0.0)), 0);
        assert_eq!(rcb.owner(Vec3::new(50.0, -100.0, 0.0)), 1);
    }

    /// The peer relation is symmetric with opposite shifts, and periodic images appear.
    #[test]
    fn peers_are_symmetric_with_periodic_images() {
        let pts = lattice();
        for periodic in [[false; 3], [true, false, false], [true, true, true]] {
            for ranks in 1..=5 {
                let rcb = Rcb::from_points(&pts, ranks, domain(), periodic).unwrap();
                for me in 0..ranks {
                    for p in rcb.peers(me, 1.5) {
                        let back = rcb.peers(p.rank, 1.5);
                        assert!(
                            back.iter().any(|q| q.rank == me && q.shift == -p.shift),
                            "{ranks} ranks {periodic:?}: {me} sees {p:?} but not back"
                        );
                    }
                }
            }
        }
        // One rank periodic in x sees itself across the periodic boundary, and nothing when not periodic.
        let one = Rcb::from_points(&pts, 1, domain(), [true, false, false]).unwrap();
        let peers = one.peers(0, 1.0);
        assert_eq!(peers.len(), 2);
        assert_eq!(peers[0].shift, Vec3::new(-20.0, 0.0, 0.0));
        assert!(Rcb::from_points(&pts, 1, domain(), [false; 3]).unwrap().peers(0, 1.0).is_empty());
        // Two ranks cut at x = 10 with a width below the gap of a far-away 4-rank layout.
        let four = Rcb::from_points(&pts, 4, domain(), [false; 3]).unwrap();
        let boxes = four.boxes();
        for me in 0..4 {
            for p in four.peers(me, 0.5) {
                assert!(boxes[me].gap(&boxes[p.rank]) <= 0.5);
            }
        }
    }

    /// A domain unbounded along a non-periodic axis (a DEM scene without `domain_min_m`/`domain_max_m`
    /// along it): no rank lists itself as its own peer, every shift is finite, and two ranks far apart
    /// along the cut axis are not peers. Before the non-periodic shift was made exactly 0, its component
    /// was 0 × ∞ = NaN, so every rank saw itself with a NaN shift and every other rank at gap 0.
    #[test]
    fn peers_of_an_unbounded_domain_have_finite_shifts() {
        let pts = lattice();
        let open = Aabb::new(Vec3::splat(f64::NEG_INFINITY), Vec3::splat(f64::INFINITY));
        let half_open =
            Aabb::new(Vec3::new(0.0, f64::NEG_INFINITY, 0.0), Vec3::new(20.0, f64::INFINITY, 6.0));
        for (domain, periodic) in [(open, [false; 3]), (half_open, [true, false, false])] {
            for ranks in 1..=4 {
                let rcb = Rcb::from_points(&pts, ranks, domain, periodic).unwrap();
                for me in 0..ranks {
                    for p in rcb.peers(me, 1.5) {
                        assert!(p.shift.is_finite(), "{ranks} ranks {periodic:?}: {me} sees {p:?}");
                        assert!(p.rank != me || p.shift != Vec3::ZERO, "{me} is its own peer");
                        assert!(p.rank != me || periodic[0], "{me} sees itself without a periodic axis");
                    }
                }
            }
        }
        // Four ranks on the 20-long lattice cut x at 10 first, then the halves along x again (at 5 and
        // 15): ranks 0 (x < 5) and 3 (x ≥ 15) are 10 apart and no peers for a width of 1.5.
        let four = Rcb::from_points(&pts, 4, open, [false; 3]).unwrap();
        let boxes = four.boxes();
        assert_eq!((boxes[0].max.x, boxes[3].min.x), (5.0, 15.0));
        assert!(four.peers(0, 1.5).iter().all(|p| p.rank != 3));
        assert_eq!(four.peers(0, 1.5), vec![Peer { rank: 1, shift: Vec3::ZERO }]);
    }

    #[test]
    fn bad_requests_are_refused_with_a_sentence() {
        let pts = lattice();
        let five = &pts[..5];
        let e = Rcb::from_points(five, 8, domain(), [false; 3]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "8 ranks for 5 particles: every rank needs at least one particle; use at most 5 ranks"
        );
        assert_eq!(Rcb::from_points(&pts, 0, domain(), [false; 3]), Err(RcbError::NoRanks));
        let e = Rcb::from_points(&[], 2, domain(), [false; 3]).unwrap_err();
        assert_eq!(e.to_string(), "no particles to split over 2 ranks: start the run without mpirun");
        let same = vec![Vec3::ONE; 4];
        assert!(matches!(
            Rcb::from_points(&same, 2, domain(), [false; 3]),
            Err(RcbError::Unsplittable { .. })
        ));
        let flat = Aabb::new(Vec3::ZERO, Vec3::new(0.0, 10.0, 6.0));
        assert_eq!(
            Rcb::from_points(&pts, 2, flat, [true, false, false]),
            Err(RcbError::BadPeriodicDomain { axis: 0 })
        );
    }

    /// The tree depends only on the points' set and order-independent tie-breaks: the same points in
    /// another order give the same boxes (every rank builds it alone and must agree).
    #[test]
    fn order_of_the_points_does_not_matter_for_the_boxes() {
        let pts = lattice();
        let mut rev = pts.clone();
        rev.reverse();
        for ranks in 2..=6 {
            let a = Rcb::from_points(&pts, ranks, domain(), [false; 3]).unwrap();
            let b = Rcb::from_points(&rev, ranks, domain(), [false; 3]).unwrap();
            assert_eq!(a.boxes(), b.boxes(), "{ranks} ranks");
        }
    }
}
