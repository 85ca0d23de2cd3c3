//! A precomputed tip-vortex field: smooth tables plus the exact rings near the point.
//!
//! The rotor's tip vortices enter the flow as a fluctuation about the mean (the mean flow already carries
//! their time average, the slipstream's shear layer):
//!
//! u′(x, t) = Σ_j u_j(x; r_c,j) − ⟨Σ_j u_j⟩,   ⟨Σ_j u_j⟩ = (1/P) ∫₀^τ_max u(x; τ) dτ,
//!
//! a sum over the rings alive (ages φ + jP, φ the phase in the shedding period P) minus its time average.
//! Summing directly costs one elliptic-integral evaluation per ring and point, and the average a few
//! hundred more. The table splits every ring into a widened ring (core s_j = max(r_c,j, R_s)) and the
//! difference to it:
//!
//! u′ = [W(φ) − ⟨W⟩]  +  Σ_j [u_j(r_c,j) − u_j(s_j)]  −  ⟨Σ_j [u_j(r_c,j) − u_j(s_j)]⟩,   W = Σ_j u_j(s_j).
//!
//! * W(φ) − ⟨W⟩ varies on the scale R_s in space and is periodic in the phase: it is tabulated once on a
//!   uniform (r, z) grid of spacing R_s/6 at about 16 phases per period (per phase segment, see below) and
//!   read back with 4-point Lagrange interpolation in r and z and linear interpolation in phase. ⟨W⟩ comes
//!   from the same samples (every phase node of every ring is one age; Simpson's rule over the ages);
//! * each difference u_j(r_c,j) − u_j(s_j) comes from ψ_thin's core terms and falls off like e^(−αQ/s²)
//!   with the squared distance Q to the core line: it is evaluated exactly for the rings within `reach` =
//!   3.5 R_s (e^(−α·3.5²) = 2 × 10⁻⁷) and dropped beyond; those rings come from the point's arc-length
//!   windows along the two legs of the path (an index range, no scan over the rings);
//! * its time average is phase-independent and, like the differences, lives within `reach` of the path:
//!   a second (r, z) table of spacing r_c,min/6 holds it, by Gauss–Legendre quadrature over the ages.
//!
//! R_s = max(ℓ, 1.5 r_c0) with ℓ = v_c P the spacing of the rings along the path: a few rings fall within
//! reach. The number of rings alive changes at the phase where the oldest ring is dropped; the phase axis
//! is split there into segments, each with a fixed ring count and end nodes computed as one-sided limits,
//! so no interpolation straddles a ring's birth or death.
//!
//! Outside the tables' box the direct sum is used. The test `table_equals_direct_sum_*` bounds the
//! difference to the direct sum (see [`TABLE_TOLERANCE`]).

use super::rings::{ring_core_difference, Ring, VortexPath};
use super::RotorDownwash;
use rayon::prelude::*;
use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

/// Grid spacing of the smooth table in units of the smoothing radius R_s.
const SPACING_PER_SMOOTHING: f64 = 1.0 / 6.0;
/// Grid spacing of the core table in units of the smallest core radius.
const SPACING_PER_CORE: f64 = 1.0 / 6.0;
/// Phase nodes per shedding period.
const PHASES_PER_PERIOD: f64 = 16.0;
/// Near rings are evaluated exactly within this many smoothing radii of their core line.
const REACH_PER_SMOOTHING: f64 = 3.5;
/// Tables beyond this many nodes are not built (the direct sum is used; about 64 MB).
const MAX_NODES: usize = 8_000_000;

/// The bound the tests put on |u_table − u_direct| relative to the peak swirl 0.7153 Γ_v/(2π r_c0) of a
/// newly shed vortex, over points on and off the vortex path.
pub const TABLE_TOLERANCE: f64 = 2e-3;

/// One phase segment: the ring count is fixed within it.
#[derive(Clone, Debug)]
struct Segment {
    phi0: f64,
    phi1: f64,
    /// Rings alive (j = 0..count).
    count: usize,
    /// Phase nodes (odd, ≥ 3), the first at `phi0`, the last at `phi1`.
    nodes: usize,
    /// Index of the first node plane.
    first_plane: usize,
}

/// A uniform (r, z) grid from the axis and `z0` with `spacing`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub spacing: f64,
    pub nr: usize,
    pub nz: usize,
    pub z0: f64,
}

impl Grid {
    fn new(spacing: f64, r_max: f64, z0: f64, z1: f64) -> Self {
        Grid {
            spacing,
            nr: (r_max / spacing).ceil() as usize + 1,
            nz: ((z1 - z0) / spacing).ceil() as usize + 1,
            z0,
        }
    }

    fn contains(&self, r: f64, z: f64) -> bool {
        let h = self.spacing;
        r <= (self.nr - 1) as f64 * h && z >= self.z0 && z <= self.z0 + (self.nz - 1) as f64 * h
    }

    /// First stencil nodes (r, z) and the Lagrange weights of a point inside.
    #[inline]
    fn stencil(&self, r: f64, z: f64) -> (usize, usize, [f64; 4], [f64; 4]) {
        let (i0, tr) = stencil(r / self.spacing, self.nr);
        let (j0, tz) = stencil((z - self.z0) / self.spacing, self.nz);
        (i0, j0, lagrange4(tr), lagrange4(tz))
    }
}

/// The tabulated tip-vortex fluctuation of one rotor.
#[derive(Clone, Debug)]
pub struct VortexTable {
    /// Identifies the table (and its clones) in the per-thread ring cache.
    id: u64,
    /// The rotor the table was built for (compared against the rotor in use).
    pub source: RotorDownwash,
    pub path: VortexPath,
    /// Smoothing radius R_s \[m\].
    pub smoothing: f64,
    /// Exact-ring reach \[m\].
    pub reach: f64,
    /// Grid of the smooth table and of the core table.
    pub smooth_grid: Grid,
    pub core_grid: Grid,
    segments: Vec<Segment>,
    /// W(φ) − ⟨W⟩ as (u_r, u_z): plane-major, then z, then r.
    smooth: Vec<[f32; 2]>,
    /// ⟨Σ_j [u_j(r_c,j) − u_j(s_j)]⟩: z-major, then r.
    core_mean: Vec<[f32; 2]>,
}

/// 4-point Lagrange weights at t for nodes −1, 0, 1, 2.
#[inline]
fn lagrange4(t: f64) -> [f64; 4] {
    let (a, b, c, d) = (t + 1.0, t, t - 1.0, t - 2.0);
    [-b * c * d / 6.0, a * c * d / 2.0, -a * b * d / 2.0, a * b * c / 6.0]
}

/// First stencil node and the local coordinate for a point at grid coordinate `f` on `n` nodes.
#[inline]
fn stencil(f: f64, n: usize) -> (usize, f64) {
    // Truncation instead of `floor` (a library call on the baseline x86-64 target): they differ only for
    // negative non-integral f, where both are clamped to 1.
    let i = (f as isize).clamp(1, n as isize - 3) as usize;
    (i - 1, f - i as f64)
}

/// Simpson weights (h/3)(1, 4, 2, 4, …, 4, 1) of node `k` of `n` (odd) nodes, without the h/3.
#[inline]
fn simpson(k: usize, n: usize) -> f64 {
    if k == 0 || k == n - 1 {
        1.0
    } else if k % 2 == 1 {
        4.0
    } else {
        2.0
    }
}

impl VortexTable {
    /// Builds the tables of `rotor`'s tip vortices, or `None` when they would exceed the node limit.
    pub fn build(rotor: &RotorDownwash) -> Option<Self> {
        let path = VortexPath::new(rotor);
        let rc0 = rotor.core_radius_fraction * rotor.radius_m;
        let smoothing = (path.speed * path.period).max(1.5 * rc0);
        let reach = REACH_PER_SMOOTHING * smoothing;
        let rc_min = path.min_core();
        // Box: every ring's radius plus 1.5 R, from the ground (or 1 R below the lowest ring out of
        // ground effect) to R above the disk.
        let (mut r_far, mut z_low) = (rotor.radius_m, rotor.hub_m.z);
        for k in 0..=256 {
            let (r, z) = path.position(path.max_age * k as f64 / 256.0);
            r_far = r_far.max(r);
            z_low = z_low.min(z);
        }
        let z0 = path.ground_z.unwrap_or(z_low - rotor.radius_m);
        let z1 = rotor.hub_m.z + rotor.radius_m;
        let r_max = r_far + 1.5 * rotor.radius_m;
        let smooth_grid = Grid::new(smoothing * SPACING_PER_SMOOTHING, r_max, z0, z1);
        let core_grid = Grid::new(rc_min * SPACING_PER_CORE, r_max, z0, z1);
        // Phase segments split where the oldest ring is dropped.
        let p = path.period;
        let a = path.max_age;
        let death = a - (a / p).floor() * p;
        let mut segments = Vec::new();
        let mut planes = 0;
        for (phi0, phi1) in [(0.0, death), (death, p)] {
            if phi1 - phi0 < 1e-9 * p {
                continue;
            }
            let count = path.count(0.5 * (phi0 + phi1));
            let mut nodes = (PHASES_PER_PERIOD * (phi1 - phi0) / p).ceil() as usize + 1;
            nodes = nodes.max(3) | 1;
            segments.push(Segment { phi0, phi1, count, nodes, first_plane: planes });
            planes += nodes;
        }
        let smooth_nodes = planes * smooth_grid.nr * smooth_grid.nz;
        let core_nodes = core_grid.nr * core_grid.nz;
        if smooth_nodes + core_nodes > MAX_NODES || smooth_grid.nr.min(smooth_grid.nz) < 4 {
            tracing::warn!(
                "tip-vortex tables of {smooth_nodes} + {core_nodes} nodes exceed {MAX_NODES}: summing the rings directly"
            );
            return None;
        }
        let smooth = Self::build_smooth(&path, &segments, planes, smooth_grid, smoothing);
        let core_mean = Self::build_core_mean(&path, core_grid, smoothing, reach, rc_min);
        static NEXT_ID: AtomicU64 = AtomicU64::new(0);
        Some(VortexTable {
            id: NEXT_ID.fetch_add(1, Ordering::Relaxed),
            source: rotor.clone(),
            path,
            smoothing,
            reach,
            smooth_grid,
            core_grid,
            segments,
            smooth,
            core_mean,
        })
    }

    /// W(φ) − ⟨W⟩ at every node: W at each phase plane and, from the same ring samples, ⟨W⟩ =
    /// (1/P) Σ over segments and rings of Simpson's rule over that ring's ages in the segment.
    fn build_smooth(
        path: &VortexPath,
        segments: &[Segment],
        planes: usize,
        grid: Grid,
        smoothing: f64,
    ) -> Vec<[f32; 2]> {
        // The rings of every phase plane with their widened cores and Simpson weights.
        let mut rings: Vec<Vec<(Ring, f64)>> = vec![Vec::new(); planes];
        for s in segments {
            let dphi = (s.phi1 - s.phi0) / (s.nodes - 1) as f64;
            for k in 0..s.nodes {
                let phi = s.phi0 + dphi * k as f64;
                let weight = simpson(k, s.nodes) * dphi / 3.0;
                rings[s.first_plane + k] = (0..s.count)
                    .map(|j| {
                        let mut ring = path.ring(phi + j as f64 * path.period);
                        ring.rc = ring.rc.max(smoothing);
                        (ring, weight)
                    })
                    .collect();
            }
        }
        // One row of z at a time (all r and planes), then scattered plane-major.
        let rows: Vec<Vec<[f32; 2]>> = (0..grid.nz)
            .into_par_iter()
            .map(|iz| {
                let z = grid.z0 + iz as f64 * grid.spacing;
                let mut row = vec![[0.0f32; 2]; planes * grid.nr];
                let mut w = vec![(0.0f64, 0.0f64); planes];
                for ir in 0..grid.nr {
                    let r = ir as f64 * grid.spacing;
                    w.iter_mut().for_each(|x| *x = (0.0, 0.0));
                    let mut mean = (0.0, 0.0);
                    for (slot, plane) in w.iter_mut().zip(&rings) {
                        for (ring, weight) in plane {
                            let (a, b) = path.ring_and_image(ring.r, ring.z, ring.rc, r, z);
                            slot.0 += a;
                            slot.1 += b;
                            mean.0 += weight * a;
                            mean.1 += weight * b;
                        }
                    }
                    let (m0, m1) = (mean.0 / path.period, mean.1 / path.period);
                    for (k, v) in w.iter().enumerate() {
                        row[k * grid.nr + ir] = [(v.0 - m0) as f32, (v.1 - m1) as f32];
                    }
                }
                row
            })
            .collect();
        let plane_len = grid.nr * grid.nz;
        let mut data = vec![[0.0f32; 2]; planes * plane_len];
        for (iz, row) in rows.iter().enumerate() {
            for k in 0..planes {
                let dst = k * plane_len + iz * grid.nr;
                data[dst..dst + grid.nr].copy_from_slice(&row[k * grid.nr..(k + 1) * grid.nr]);
            }
        }
        data
    }

    /// ⟨Σ_j [u_j(r_c,j) − u_j(s_j)]⟩ at every node within reach of the path (zero elsewhere), by
    /// Gauss–Legendre over the ages of the arc-length windows on panels of a quarter of the smallest core.
    fn build_core_mean(
        path: &VortexPath,
        grid: Grid,
        smoothing: f64,
        reach: f64,
        rc_min: f64,
    ) -> Vec<[f32; 2]> {
        let mut data = vec![[0.0f32; 2]; grid.nr * grid.nz];
        let panel = 0.25 * rc_min;
        data.par_chunks_mut(grid.nr).enumerate().for_each(|(iz, row)| {
            let z = grid.z0 + iz as f64 * grid.spacing;
            for (ir, o) in row.iter_mut().enumerate() {
                let r = ir as f64 * grid.spacing;
                let mut acc = (0.0, 0.0);
                let mut add = |gamma: f64, zq: f64, image_of: Option<f64>| {
                    for (s0, s1) in path.arc_windows(r, zq, reach) {
                        let (a, b) = path.integrate_arc(s0, s1, panel, |age| {
                            let ring = path.ring(age);
                            if ring.rc >= smoothing {
                                return (0.0, 0.0);
                            }
                            let zv = image_of.map_or(ring.z, |zg| 2.0 * zg - ring.z);
                            ring_core_difference(gamma, ring.r, zv, ring.rc, smoothing, r, z)
                        });
                        acc.0 += a;
                        acc.1 += b;
                    }
                };
                add(-path.gamma, z, None);
                if let Some(zg) = path.ground_z {
                    add(path.gamma, 2.0 * zg - z, Some(zg));
                }
                *o = [(acc.0 / path.period) as f32, (acc.1 / path.period) as f32];
            }
        });
        data
    }

    /// Memory of the tables \[bytes\].
    pub fn bytes(&self) -> usize {
        (self.smooth.len() + self.core_mean.len()) * std::mem::size_of::<[f32; 2]>()
    }

    /// Number of table nodes.
    pub fn nodes(&self) -> usize {
        self.smooth.len() + self.core_mean.len()
    }

    /// Whether (r, z) lies inside the tabulated box.
    #[inline]
    pub fn contains(&self, r: f64, z: f64) -> bool {
        self.smooth_grid.contains(r, z) && self.core_grid.contains(r, z)
    }

    /// W(φ) − ⟨W⟩ at (r, z) and phase `phi` of segment `s`.
    #[inline]
    fn smooth_part(&self, s: &Segment, phi: f64, r: f64, z: f64) -> (f64, f64) {
        let g = &self.smooth_grid;
        let fp = (phi - s.phi0) / (s.phi1 - s.phi0) * (s.nodes - 1) as f64;
        // Truncation equals `floor` for fp ≥ 0; negative fp gives 0 either way.
        let k = (fp.max(0.0) as usize).min(s.nodes - 2);
        let wp = (fp - k as f64).clamp(0.0, 1.0);
        let (i0, j0, wr, wz) = g.stencil(r, z);
        let plane_len = g.nr * g.nz;
        let mut acc = [0.0f64; 2];
        for (dp, w_phase) in [(0, 1.0 - wp), (1, wp)] {
            let plane = (s.first_plane + k + dp) * plane_len;
            let mut sum = [0.0f64; 2];
            for (dj, wzj) in wz.iter().enumerate() {
                let row = plane + (j0 + dj) * g.nr + i0;
                let mut line = [0.0f64; 2];
                for (c, wri) in self.smooth[row..row + 4].iter().zip(wr.iter()) {
                    line[0] += wri * c[0] as f64;
                    line[1] += wri * c[1] as f64;
                }
                sum[0] += wzj * line[0];
                sum[1] += wzj * line[1];
            }
            acc[0] += w_phase * sum[0];
            acc[1] += w_phase * sum[1];
        }
        (acc[0], acc[1])
    }

    /// The core table at (r, z).
    #[inline]
    fn core_part(&self, r: f64, z: f64) -> (f64, f64) {
        let g = &self.core_grid;
        let (i0, j0, wr, wz) = g.stencil(r, z);
        let mut acc = [0.0f64; 2];
        for (dj, wzj) in wz.iter().enumerate() {
            let row = (j0 + dj) * g.nr + i0;
            let mut line = [0.0f64; 2];
            for (c, wri) in self.core_mean[row..row + 4].iter().zip(wr.iter()) {
                line[0] += wri * c[0] as f64;
                line[1] += wri * c[1] as f64;
            }
            acc[0] += wzj * line[0];
            acc[1] += wzj * line[1];
        }
        (acc[0], acc[1])
    }

    /// Tip-vortex fluctuation (u_r, u_z) at (r, z), time `t`: the tables with the exact near rings, or
    /// the direct sum outside the tables.
    pub fn velocity(&self, r: f64, z: f64, t: f64) -> (f64, f64) {
        let path = &self.path;
        if !self.contains(r, z) {
            return path.velocity_direct(r, z, t);
        }
        let phi = path.phase(t);
        let Some(seg) = self.segments.iter().find(|s| phi <= s.phi1).or(self.segments.last()) else {
            return (0.0, 0.0);
        };
        let count = path.count(phi);
        let (a, b) = self.smooth_part(seg, phi, r, z);
        let (c, d) = self.core_part(r, z);
        let (mut ur, mut uz) = (a - c, b - d);
        let reach2 = self.reach * self.reach;
        with_phase_rings(self.id, path, phi, count, |rings| {
            // Physical rings (−Γ at z_v) near (r, z); ground images (+Γ at 2z_g − z_v) are near (r, z)
            // when the ring is near the mirrored point (r, 2z_g − z).
            let mut add = |gamma: f64, zq: f64, image_of: Option<f64>| {
                for (lo, hi) in path.candidates(phi, count, r, zq, self.reach) {
                    for ring in rings.get(lo..=hi).unwrap_or_default() {
                        if ring.rc >= self.smoothing {
                            continue;
                        }
                        let q = (r - ring.r) * (r - ring.r) + (zq - ring.z) * (zq - ring.z);
                        if q > reach2 {
                            continue;
                        }
                        let zv = image_of.map_or(ring.z, |zg| 2.0 * zg - ring.z);
                        let (a, b) = ring_core_difference(gamma, ring.r, zv, ring.rc, self.smoothing, r, z);
                        ur += a;
                        uz += b;
                    }
                }
            };
            add(-path.gamma, z, None);
            if let Some(zg) = path.ground_z {
                add(path.gamma, 2.0 * zg - z, Some(zg));
            }
        });
        (ur, uz)
    }
}

/// The rings alive at one phase of one table.
struct PhaseRings {
    table: u64,
    phi_bits: u64,
    rings: Vec<Ring>,
}

/// Phases remembered per thread: a tracker step samples the field at one time, and its time derivative
/// at two more.
const CACHED_PHASES: usize = 4;

thread_local! {
    /// The last [`CACHED_PHASES`] ring sets of this thread and the slot to replace next.
    static PHASE_RINGS: RefCell<(Vec<PhaseRings>, usize)> = const { RefCell::new((Vec::new(), 0)) };
}

/// Calls `f` with the rings j = 0..`count` (ages φ + jP) of `path` at phase `phi`. Every parcel of a
/// tracker step is evaluated at the same time, so the rings' positions and cores (three square roots
/// each) are computed once per thread and phase instead of once per candidate ring and point; the
/// values are the same as [`VortexPath::ring`]'s, so results do not depend on the cache.
fn with_phase_rings<R>(
    table: u64,
    path: &VortexPath,
    phi: f64,
    count: usize,
    f: impl FnOnce(&[Ring]) -> R,
) -> R {
    PHASE_RINGS.with(|cell| {
        let mut guard = cell.borrow_mut();
        let (entries, next) = &mut *guard;
        let phi_bits = phi.to_bits();
        let slot = match entries.iter().position(|e| e.table == table && e.phi_bits == phi_bits) {
            Some(k) => k,
            None => {
                let rings = (0..count).map(|j| path.ring(phi + j as f64 * path.period)).collect();
                let entry = PhaseRings { table, phi_bits, rings };
                if entries.len() < CACHED_PHASES {
                    entries.push(entry);
                    entries.len() - 1
                } else {
                    let k = *next;
                    *next = (k + 1) % CACHED_PHASES;
                    entries[k] = entry;
                    k
                }
            }
        };
        f(&entries[slot].rings)
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::analytic::LAMB_OSEEN_ALPHA;
    use spatter_core::rng::{seeded, RngExt};
    use std::f64::consts::PI;

    /// Largest |u_table − u_direct| over random points of the table box and points on the vortex path at
    /// random times, relative to the peak swirl of a new vortex 0.7153 Γ/(2π r_c0) (Jasion eq. 6.14).
    fn worst_error(rotor: &RotorDownwash, samples: usize) -> (f64, f64) {
        let table = VortexTable::build(rotor).expect("table");
        let path = &table.path;
        let rc0 = rotor.core_radius_fraction * rotor.radius_m;
        let peak = (1.0 - (-LAMB_OSEEN_ALPHA).exp()) * path.gamma / (2.0 * PI * rc0);
        let mut rng = seeded(7, 0);
        let g = table.core_grid;
        let (r_max, z1) = ((g.nr - 1) as f64 * g.spacing, g.z0 + (g.nz - 1) as f64 * g.spacing);
        let z0 = g.z0;
        let mut worst: f64 = 0.0;
        let mut worst_near: f64 = 0.0;
        for k in 0..samples {
            let t = 100.0 * rng.random::<f64>();
            let (r, z) = if k % 2 == 0 {
                (r_max * rng.random::<f64>(), z0 + (z1 - z0) * rng.random::<f64>())
            } else {
                // Within two core radii of a random live ring.
                let phi = path.phase(t);
                let j = (rng.random::<f64>() * path.count(phi) as f64) as usize;
                let ring = path.ring(phi + j as f64 * path.period);
                let a = 2.0 * PI * rng.random::<f64>();
                let d = 2.0 * ring.rc * rng.random::<f64>();
                (ring.r + d * a.cos(), (ring.z + d * a.sin()).max(z0))
            };
            let (a, b) = table.velocity(r, z, t);
            let (c, d) = path.velocity_direct(r, z, t);
            let e = (a - c).hypot(b - d) / peak;
            if k % 2 == 0 {
                worst = worst.max(e);
            } else {
                worst_near = worst_near.max(e);
            }
        }
        (worst, worst_near)
    }

    #[test]
    fn table_equals_direct_sum_in_ground_effect() {
        // Bell 47 at z_d/R = 0.68 with 10 revolutions of vortices (Jasion 2013 Ch. 6).
        let mut rotor = RotorDownwash::bell47(0.68);
        rotor.tip_vortices = true;
        let (far, near) = worst_error(&rotor, 4000);
        eprintln!("IGE: worst error / peak swirl: box {far:.2e}, near cores {near:.2e}");
        assert!(far < TABLE_TOLERANCE && near < TABLE_TOLERANCE, "{far} {near}");
    }

    #[test]
    fn table_equals_direct_sum_out_of_ground_effect() {
        let mut rotor = RotorDownwash::bell47(4.0);
        rotor.ground = false;
        rotor.tip_vortices = true;
        rotor.vortex_max_age_revs = 3.3;
        rotor.blades = 3;
        let (far, near) = worst_error(&rotor, 2000);
        eprintln!("OGE: worst error / peak swirl: box {far:.2e}, near cores {near:.2e}");
        assert!(far < TABLE_TOLERANCE && near < TABLE_TOLERANCE, "{far} {near}");
    }

    #[test]
    fn rotor_uses_the_table_and_rebuilds_for_a_changed_rotor() {
        let mut rotor = RotorDownwash::bell47(0.68);
        rotor.tip_vortices = true;
        rotor.vortex_max_age_revs = 2.0;
        assert!(rotor.tabulated_vortices().is_some());
        let clone = rotor.clone();
        assert!(std::ptr::eq(clone.tabulated_vortices().unwrap(), rotor.tabulated_vortices().unwrap()));
        // A changed rotor must not use the stale table.
        let mut changed = rotor.clone();
        changed.thrust_n *= 2.0;
        assert!(changed.tabulated_vortices().is_none());
        let x = (6.0, 1.5, 0.3);
        let direct = changed.vortex_path().velocity_direct(x.0, x.1, x.2);
        assert_eq!(changed.vortex_velocity_rz(x.0, x.1, x.2), direct);
    }
}
