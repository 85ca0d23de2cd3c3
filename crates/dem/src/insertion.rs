//! Particle insertion: regions, lattice and random non-overlapping fills, timed injection.
//!
//! * [`Region`]: an axis-aligned box, a cylinder, or the inside of a closed triangle mesh. A sphere is
//!   accepted only if it lies entirely inside.
//! * [`lattice_fill`]: centres on a simple-cubic or face-centred-cubic lattice of a given spacing.
//! * [`random_fill`]: random sequential addition of spheres with diameters from a
//!   [`SizeDistribution`](spatter_core::distribution::SizeDistribution), never overlapping each other or
//!   the particles already present, until a count or a solid volume fraction is reached.
//! * [`Injector`]: the same random placement repeated over time at a number or mass rate.

use serde::{Deserialize, Serialize};
use spatter_core::distribution::SizeDistribution;
use spatter_core::mesh::TriMesh;
use spatter_core::rng::{Rng, RngExt};
use spatter_core::tri_bvh::TriBvh;
use spatter_core::{Aabb, Vec3};
use std::collections::HashMap;
use std::f64::consts::PI;

/// A region particles are placed in.
#[derive(Clone, Debug)]
pub enum Region {
    Box(Aabb),
    /// Cylinder from `base` along unit `axis` over `height`, of `radius`.
    Cylinder {
        base: Vec3,
        axis: Vec3,
        radius: f64,
        height: f64,
    },
    /// The inside of a closed mesh.
    Mesh {
        mesh: TriMesh,
        bvh: TriBvh,
    },
}

impl Region {
    /// A mesh region (builds the hierarchy).
    pub fn mesh(mesh: TriMesh) -> Self {
        let bvh = TriBvh::build(&mesh);
        Region::Mesh { mesh, bvh }
    }

    /// Bounding box.
    pub fn bounds(&self) -> Aabb {
        match self {
            Region::Box(b) => *b,
            Region::Cylinder { base, axis, radius, height } => {
                let top = *base + *axis * *height;
                // Extent of a disc of radius r with normal a along each axis: r √(1 − a_k²).
                let e = Vec3::new(
                    (1.0 - axis.x * axis.x).max(0.0).sqrt(),
                    (1.0 - axis.y * axis.y).max(0.0).sqrt(),
                    (1.0 - axis.z * axis.z).max(0.0).sqrt(),
                ) * *radius;
                Aabb::new(base.min(top) - e, base.max(top) + e)
            }
            Region::Mesh { bvh, .. } => bvh.bounds(),
        }
    }

    /// Volume \[m³\] (mesh: enclosed volume).
    pub fn volume(&self) -> f64 {
        match self {
            Region::Box(b) => b.volume(),
            Region::Cylinder { radius, height, .. } => PI * radius * radius * height,
            Region::Mesh { mesh, .. } => mesh.signed_volume().abs(),
        }
    }

    /// Whether a sphere of radius `r` at `x` lies entirely inside.
    pub fn contains_sphere(&self, x: Vec3, r: f64) -> bool {
        match self {
            Region::Box(b) => x.cmpge(b.min + Vec3::splat(r)).all() && x.cmple(b.max - Vec3::splat(r)).all(),
            Region::Cylinder { base, axis, radius, height } => {
                let d = x - *base;
                let h = d.dot(*axis);
                h >= r && h <= height - r && (d - h * *axis).length() <= radius - r
            }
            Region::Mesh { mesh, bvh } => {
                bvh.contains_point(mesh, x) && bvh.closest_point(mesh, x, r).is_none()
            }
        }
    }

    /// A uniformly random point of the bounding box.
    fn sample(&self, rng: &mut Rng) -> Vec3 {
        let b = self.bounds();
        let u = Vec3::new(rng.random(), rng.random(), rng.random());
        b.min + u * b.extent()
    }
}

/// Lattice type of [`lattice_fill`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Lattice {
    /// Simple cubic.
    Cubic,
    /// Face-centred cubic (close packed): nearest-neighbour distance = spacing.
    #[default]
    Fcc,
}

/// Centres on a lattice of nearest-neighbour distance `spacing` \[m\] where a sphere of radius `r` fits
/// inside `region`, in lattice order (x fastest, then y, then z).
pub fn lattice_fill(region: &Region, spacing: f64, r: f64, lattice: Lattice) -> Vec<Vec3> {
    let b = region.bounds();
    let (a, basis): (f64, &[Vec3]) = match lattice {
        Lattice::Cubic => (spacing, &[Vec3::ZERO]),
        Lattice::Fcc => (
            spacing * std::f64::consts::SQRT_2,
            &[Vec3::ZERO, Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.5, 0.0, 0.5), Vec3::new(0.0, 0.5, 0.5)],
        ),
    };
    let origin = b.min + Vec3::splat(r);
    let n = ((b.extent() - Vec3::splat(2.0 * r)) / a).max(Vec3::ZERO);
    let (nx, ny, nz) = (n.x as usize + 1, n.y as usize + 1, n.z as usize + 1);
    let mut out = Vec::new();
    for k in 0..nz {
        for bz in basis.iter().filter(|q| q.z == 0.0).chain(basis.iter().filter(|q| q.z != 0.0)) {
            for j in 0..ny {
                for i in 0..nx {
                    let x = origin + (Vec3::new(i as f64, j as f64, k as f64) + *bz) * a;
                    if region.contains_sphere(x, r) {
                        out.push(x);
                    }
                }
            }
        }
    }
    out
}

/// A spatial hash of spheres for overlap checks during random placement.
#[derive(Debug)]
pub struct OverlapIndex {
    cell: f64,
    map: HashMap<[i64; 3], Vec<(Vec3, f64)>>,
}

impl OverlapIndex {
    /// Index with cells of `cell` \[m\] (≥ the largest diameter for exact queries).
    pub fn new(cell: f64) -> Self {
        OverlapIndex { cell, map: HashMap::new() }
    }

    fn key(&self, x: Vec3) -> [i64; 3] {
        let q = x / self.cell;
        [q.x.floor() as i64, q.y.floor() as i64, q.z.floor() as i64]
    }

    pub fn insert(&mut self, x: Vec3, r: f64) {
        let k = self.key(x);
        self.map.entry(k).or_default().push((x, r));
    }

    /// Whether a sphere at `x` of radius `r` overlaps any indexed sphere (exact when r plus any indexed
    /// radius is at most the cell size).
    pub fn overlaps(&self, x: Vec3, r: f64) -> bool {
        let k = self.key(x);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = self.map.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        if list.iter().any(|(y, ry)| (*y - x).length_squared() < (r + ry) * (r + ry)) {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }
}

/// When a random fill stops.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FillTarget {
    Count(u64),
    /// Solid volume fraction of the region.
    VolumeFraction(f64),
}

/// Random sequential addition: draws diameters from `dist` and random centres in `region` until the
/// target is met or `max_attempts` consecutive placements failed. `existing` spheres (centre, radius) are
/// avoided. Returns (centre, radius) of the new spheres.
pub fn random_fill(
    region: &Region,
    dist: &SizeDistribution,
    target: FillTarget,
    existing: &[(Vec3, f64)],
    max_attempts: u64,
    rng: &mut Rng,
) -> Vec<(Vec3, f64)> {
    // The largest diameter for the hash cell: sample the distribution's upper tail.
    let d_max = (0..256).map(|_| dist.sample(rng)).fold(0.0, f64::max) * 1.5;
    // Cells must be at least as large as the largest sum of two radii that can meet.
    let r_exist = existing.iter().map(|e| e.1).fold(0.0, f64::max);
    let mut index = OverlapIndex::new((0.5 * d_max + r_exist).max(d_max).max(1e-300));
    let b = region.bounds().inflated(d_max);
    for &(x, r) in existing {
        if b.contains(x) {
            index.insert(x, r);
        }
    }
    let vol = region.volume();
    let mut out = Vec::new();
    let mut solid = 0.0;
    let mut fails = 0u64;
    let done = |n: usize, solid: f64| match target {
        FillTarget::Count(c) => n as u64 >= c,
        FillTarget::VolumeFraction(f) => solid >= f * vol,
    };
    while !done(out.len(), solid) && fails < max_attempts {
        let r = 0.5 * dist.sample(rng);
        let x = region.sample(rng);
        if 2.0 * r > d_max || !region.contains_sphere(x, r) || index.overlaps(x, r) {
            fails += 1;
            continue;
        }
        fails = 0;
        index.insert(x, r);
        solid += 4.0 / 3.0 * PI * r * r * r;
        out.push((x, r));
    }
    out
}

/// Rate of a timed injection.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InjectionRate {
    /// Particles per second.
    ParticlesPerSecond(f64),
    /// Kilograms per second (converted with the distribution's mean volume and the density).
    KgPerSecond(f64),
}

/// Inserts particles over time: at each call of [`Injector::due`] the number inserted so far catches up
/// with rate × elapsed time (placements that do not fit are retried at the next call).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Injector {
    pub dist: SizeDistribution,
    /// Particles per second.
    pub number_rate: f64,
    pub start: f64,
    pub end: f64,
    /// Initial velocity of injected particles \[m/s\].
    pub velocity: Vec3,
    pub material: u16,
    /// Placement attempts per particle before giving up for this call.
    pub attempts: u64,
    pub inserted: u64,
    pub rng: Rng,
}

impl Injector {
    /// Converts a rate to particles per second for density `rho` \[kg/m³\].
    pub fn number_rate(rate: InjectionRate, dist: &SizeDistribution, rho: f64) -> f64 {
        match rate {
            InjectionRate::ParticlesPerSecond(n) => n,
            InjectionRate::KgPerSecond(m) => m / (rho * dist.mean_volume()),
        }
    }

    /// Particles that should have been inserted by time `t` minus those inserted.
    pub fn due(&self, t: f64) -> u64 {
        if t < self.start {
            return 0;
        }
        let target = (self.number_rate * (t.min(self.end) - self.start)).floor() as u64;
        target.saturating_sub(self.inserted)
    }

    /// Places up to `n` new spheres in `region` avoiding `existing`; returns (centre, radius).
    pub fn place(&mut self, region: &Region, n: u64, existing: &[(Vec3, f64)]) -> Vec<(Vec3, f64)> {
        let out = random_fill(
            region,
            &self.dist,
            FillTarget::Count(n),
            existing,
            self.attempts.max(1) * n.max(1),
            &mut self.rng,
        );
        self.inserted += out.len() as u64;
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_core::rng::seeded;

    #[test]
    fn fcc_lattice_fills_a_box_at_close_packing() {
        // FCC packing fraction π/(3√2) = 0.7405 in the bulk; a finite box loses some at the faces.
        let region = Region::Box(Aabb::new(Vec3::ZERO, Vec3::splat(0.1)));
        let r = 0.002;
        let pts = lattice_fill(&region, 2.0 * r, r, Lattice::Fcc);
        for (k, a) in pts.iter().enumerate() {
            assert!(region.contains_sphere(*a, r));
            for b in &pts[k + 1..] {
                assert!((*a - *b).length() >= 2.0 * r * (1.0 - 1e-12), "overlap");
            }
        }
        let phi = pts.len() as f64 * 4.0 / 3.0 * PI * r.powi(3) / region.volume();
        assert!(phi > 0.6 && phi < 0.7405, "{phi}");
    }

    #[test]
    fn random_fill_in_a_cylinder_never_overlaps_and_hits_its_target() {
        let region = Region::Cylinder { base: Vec3::ZERO, axis: Vec3::Z, radius: 0.05, height: 0.1 };
        let dist = SizeDistribution::Uniform { min: 0.004, max: 0.008 };
        let mut rng = seeded(3, 0);
        let existing = [(Vec3::new(0.0, 0.0, 0.05), 0.01)];
        let got = random_fill(&region, &dist, FillTarget::VolumeFraction(0.2), &existing, 10_000, &mut rng);
        let solid: f64 = got.iter().map(|(_, r)| 4.0 / 3.0 * PI * r.powi(3)).sum();
        assert!(solid >= 0.2 * region.volume());
        let all: Vec<_> = got.iter().chain(existing.iter()).collect();
        for (k, a) in all.iter().enumerate() {
            for b in &all[k + 1..] {
                assert!((a.0 - b.0).length() >= a.1 + b.1, "overlap");
            }
        }
        for (x, r) in &got {
            assert!(region.contains_sphere(*x, *r));
        }
    }

    #[test]
    fn injector_catches_up_with_its_rate() {
        let mut inj = Injector {
            dist: SizeDistribution::Mono { diameter: 0.002 },
            number_rate: 1000.0,
            start: 0.0,
            end: 1.0,
            velocity: Vec3::ZERO,
            material: 0,
            attempts: 100,
            inserted: 0,
            rng: seeded(1, 1),
        };
        let region = Region::Box(Aabb::new(Vec3::ZERO, Vec3::splat(0.1)));
        assert_eq!(inj.due(0.0105), 10);
        let got = inj.place(&region, inj.due(0.0105), &[]);
        assert_eq!(got.len(), 10);
        assert_eq!(inj.due(0.0105), 0);
        assert_eq!(inj.due(5.0), 990, "stops at the end time");
        // Mass rate: 1 g/s of 2 mm spheres of density 2500 → 95.49 particles/s.
        let nr = Injector::number_rate(InjectionRate::KgPerSecond(1e-3), &inj.dist, 2500.0);
        assert!((nr - 1e-3 / (2500.0 * PI / 6.0 * 8e-9)).abs() < 1e-9);
    }

    #[test]
    fn random_fill_inside_a_closed_mesh() {
        // A closed box mesh [0, 0.1]³ made of 12 triangles: every sphere lies inside, none overlaps.
        let v = |x: f64, y: f64, z: f64| Vec3::new(x, y, z) * 0.1;
        let quads = [
            [v(0., 0., 0.), v(0., 1., 0.), v(1., 1., 0.), v(1., 0., 0.)],
            [v(0., 0., 1.), v(1., 0., 1.), v(1., 1., 1.), v(0., 1., 1.)],
            [v(0., 0., 0.), v(1., 0., 0.), v(1., 0., 1.), v(0., 0., 1.)],
            [v(0., 1., 0.), v(0., 1., 1.), v(1., 1., 1.), v(1., 1., 0.)],
            [v(0., 0., 0.), v(0., 0., 1.), v(0., 1., 1.), v(0., 1., 0.)],
            [v(1., 0., 0.), v(1., 1., 0.), v(1., 1., 1.), v(1., 0., 1.)],
        ];
        let mut soup = Vec::new();
        for q in quads {
            soup.extend_from_slice(&[q[0], q[1], q[2], q[0], q[2], q[3]]);
        }
        let region = Region::mesh(TriMesh::from_triangle_soup(&soup));
        assert!((region.volume() - 1e-3).abs() < 1e-12);
        let dist = SizeDistribution::Mono { diameter: 0.01 };
        let got = random_fill(&region, &dist, FillTarget::Count(200), &[], 100_000, &mut seeded(5, 5));
        assert_eq!(got.len(), 200);
        for (k, (x, r)) in got.iter().enumerate() {
            assert!(x.cmpge(Vec3::splat(*r - 1e-12)).all() && x.cmple(Vec3::splat(0.1 - r + 1e-12)).all());
            for (y, s) in &got[k + 1..] {
                assert!((*x - *y).length() >= r + s);
            }
        }
    }
}
