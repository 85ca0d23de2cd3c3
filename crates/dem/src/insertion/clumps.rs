//! Insertion of rigid multi-sphere bodies (clumps): random positions and orientations, mixes of
//! templates with number ratios, never overlapping anything present.
//!
//! A body is placed at a uniformly random centre of mass in the region's bounding box with a uniformly
//! random orientation (Shoemake 1992, "Uniform random rotations", Graphics Gems III, pp. 124–132: the unit
//! quaternion from three uniform numbers). It is accepted only if **every member sphere** lies inside the
//! region and overlaps neither a sphere present (free spheres and members of other bodies, through the
//! same [`OverlapIndex`] as sphere insertion) nor a wall at the placement time ([`WallClearance`]). The
//! random fill draws the templates first, places the bodies with the largest bounding radius first, and
//! stops at the first body that finds no place (the caller reports it); the injector shares the rate
//! logic of sphere injection ([`super::Injector::place_clumps`]).

use super::{FillTarget, OverlapIndex, Region, WallClearance};
use serde::{Deserialize, Serialize};
use spatter_core::rng::{Rng, RngExt};
use spatter_core::{Quat, Vec3};
use std::f64::consts::TAU;

/// One template of a mix as insertion sees it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClumpShape {
    /// Index of the template in the simulation ([`crate::Simulation::add_template`]).
    pub template: usize,
    /// Member spheres in the body's principal frame: centre relative to the centre of mass \[m\], radius
    /// \[m\].
    pub members: Vec<(Vec3, f64)>,
    /// Mass of one body \[kg\].
    pub mass: f64,
    /// Volume of one body for volume-fraction fills, mass / density \[m³\].
    pub volume: f64,
}

impl ClumpShape {
    /// Largest distance from the centre of mass to a member surface \[m\].
    pub fn bounding_radius(&self) -> f64 {
        self.members.iter().map(|(c, r)| c.length() + r).fold(0.0, f64::max)
    }
}

/// Templates with their probabilities per drawn body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClumpMix {
    pub shapes: Vec<ClumpShape>,
    /// Cumulative probabilities (last = 1).
    cumulative: Vec<f64>,
}

impl ClumpMix {
    /// A mix drawing `shapes[k]` with probability `weights[k] / Σ weights` per body. Weights must be
    /// non-negative with a positive sum (checked by the scene) and as many as shapes.
    pub fn new(shapes: Vec<ClumpShape>, weights: &[f64]) -> Self {
        let total: f64 = weights.iter().sum();
        let mut acc = 0.0;
        let mut cumulative: Vec<f64> = weights
            .iter()
            .map(|w| {
                acc += w / total;
                acc
            })
            .collect();
        if let Some(last) = cumulative.last_mut() {
            *last = 1.0;
        }
        ClumpMix { shapes, cumulative }
    }

    /// Draws a template slot.
    pub fn sample(&self, rng: &mut Rng) -> usize {
        if self.shapes.len() == 1 {
            return 0;
        }
        let u: f64 = rng.random();
        self.cumulative.iter().position(|&c| u < c).unwrap_or(self.shapes.len() - 1)
    }

    /// Largest member radius of any template \[m\].
    pub fn max_member_radius(&self) -> f64 {
        self.shapes.iter().flat_map(|s| s.members.iter().map(|m| m.1)).fold(0.0, f64::max)
    }
}

/// A body placed by insertion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClumpPlacement {
    /// Slot of the template in the mix.
    pub slot: usize,
    /// Centre of mass \[m\].
    pub pos: Vec3,
    /// Orientation of the template's principal frame.
    pub quat: Quat,
}

/// A uniformly distributed random orientation (Shoemake 1992).
pub fn random_orientation(rng: &mut Rng) -> Quat {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    let (s2, c2) = (TAU * u2).sin_cos();
    let (s3, c3) = (TAU * u3).sin_cos();
    Quat::from_xyzw(a * s2, a * c2, b * s3, b * c3).normalize()
}

/// An overlap index for members of `mix` placed in `region`, holding the `existing` spheres that can
/// reach into it.
pub(crate) fn index_for_mix(region: &Region, mix: &ClumpMix, existing: &[(Vec3, f64)]) -> OverlapIndex {
    let d = 2.0 * mix.max_member_radius();
    let r_exist = existing.iter().map(|e| e.1).fold(0.0, f64::max);
    let mut index = OverlapIndex::new((0.5 * d + r_exist).max(d));
    let b = region.bounds().inflated(r_exist);
    for &(x, r) in existing {
        if b.contains(x) {
            index.insert(x, r);
        }
    }
    index
}

/// Tries up to `attempts` random positions and orientations for a body of `mix.shapes[slot]`; the first
/// whose members all lie inside `region` and clear of `index` and `walls` is inserted into `index` and
/// returned.
pub(crate) fn try_place_clump(
    region: &Region,
    mix: &ClumpMix,
    slot: usize,
    index: &mut OverlapIndex,
    walls: &WallClearance,
    attempts: u64,
    rng: &mut Rng,
) -> Option<ClumpPlacement> {
    let shape = &mix.shapes[slot];
    for _ in 0..attempts {
        let x = region.sample(rng);
        let q = random_orientation(rng);
        let fits = shape.members.iter().all(|&(c, r)| {
            let y = x + q * c;
            region.contains_sphere(y, r) && !index.overlaps(y, r) && walls.overlapping(y, r).is_none()
        });
        if fits {
            for &(c, r) in &shape.members {
                index.insert(x + q * c, r);
            }
            return Some(ClumpPlacement { slot, pos: x, quat: q });
        }
    }
    None
}

/// What a random clump fill placed.
#[derive(Clone, Debug, PartialEq)]
pub struct ClumpFill {
    /// The bodies, largest bounding radius first.
    pub bodies: Vec<ClumpPlacement>,
    /// Body volume placed (Σ [`ClumpShape::volume`]) \[m³\].
    pub volume: f64,
    /// `None` when the target was met; otherwise the template slot of the body that found no place.
    pub stuck_at: Option<usize>,
}

/// Random sequential addition of bodies of `mix`: the templates are drawn first (`count` bodies, or until
/// their volume reaches the fraction of the region), then placed largest first, each at the first of up
/// to `max_attempts` random positions and orientations that fits (module docs). Stops at the first body
/// that finds no place and reports it in [`ClumpFill::stuck_at`].
pub fn random_clump_fill(
    region: &Region,
    mix: &ClumpMix,
    target: FillTarget,
    existing: &[(Vec3, f64)],
    walls: &WallClearance,
    max_attempts: u64,
    rng: &mut Rng,
) -> ClumpFill {
    let mut draws: Vec<usize> = Vec::new();
    match target {
        FillTarget::Count(n) => draws.extend((0..n).map(|_| mix.sample(rng))),
        FillTarget::VolumeFraction(f) => {
            let goal = f * region.volume();
            let mut v = 0.0;
            while v < goal {
                let s = mix.sample(rng);
                v += mix.shapes[s].volume;
                draws.push(s);
            }
        }
    }
    let radius: Vec<f64> = mix.shapes.iter().map(ClumpShape::bounding_radius).collect();
    draws.sort_by(|&a, &b| radius[b].total_cmp(&radius[a]).then(a.cmp(&b)));
    let mut index = index_for_mix(region, mix, existing);
    let mut out = ClumpFill { bodies: Vec::with_capacity(draws.len()), volume: 0.0, stuck_at: None };
    for slot in draws {
        match try_place_clump(region, mix, slot, &mut index, walls, max_attempts, rng) {
            Some(p) => {
                out.volume += mix.shapes[slot].volume;
                out.bodies.push(p);
            }
            None => {
                out.stuck_at = Some(slot);
                break;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::insertion::{InjectionRate, Injector, InjectorState};
    use crate::walls::{Plane, Wall, WallShape};
    use spatter_core::distribution::SizeDistribution;
    use spatter_core::motion::Motion;
    use spatter_core::rng::seeded;
    use spatter_core::Aabb;

    fn rod(r: f64) -> Vec<(Vec3, f64)> {
        (0..3).map(|k| (Vec3::new((k as f64 - 1.0) * 1.5 * r, 0.0, 0.0), r)).collect()
    }

    fn mix() -> ClumpMix {
        let r = 1e-3;
        let shapes = vec![
            ClumpShape { template: 0, members: rod(r), mass: 3e-5, volume: 1.2e-8 },
            ClumpShape { template: 1, members: vec![(Vec3::ZERO, 1.5e-3)], mass: 3.5e-5, volume: 1.4e-8 },
        ];
        ClumpMix::new(shapes, &[3.0, 1.0])
    }

    fn members_of(m: &ClumpMix, p: &ClumpPlacement) -> Vec<(Vec3, f64)> {
        m.shapes[p.slot].members.iter().map(|&(c, r)| (p.pos + p.quat * c, r)).collect()
    }

    /// Random orientations are uniform: the body x axis has mean 0 and ⟨x_k²⟩ = 1/3 (uniform on the
    /// sphere), within 5 standard errors over 20 000 draws.
    #[test]
    fn random_orientations_are_uniform() {
        let mut rng = seeded(1, 0);
        let n = 20_000;
        let (mut mean, mut sq) = (Vec3::ZERO, Vec3::ZERO);
        for _ in 0..n {
            let q = random_orientation(&mut rng);
            assert!((q.length() - 1.0).abs() < 1e-12);
            let x = q * Vec3::X;
            mean += x;
            sq += x * x;
        }
        let (mean, sq) = (mean / n as f64, sq / n as f64);
        // σ of a component: 1/√3 → standard error 0.0041; of its square: √(1/5 − 1/9) → 0.0021.
        assert!(mean.abs().max_element() < 5.0 * 0.0041, "{mean:?}");
        assert!((sq - Vec3::splat(1.0 / 3.0)).abs().max_element() < 5.0 * 0.0021, "{sq:?}");
    }

    /// A fill of a mix: every member inside the region and above the floor, no two members of different
    /// bodies overlapping, none overlapping the existing sphere; the template ratio 3 : 1 holds within
    /// 5 binomial standard errors.
    #[test]
    fn a_clump_fill_never_overlaps_and_follows_the_ratio() {
        let m = mix();
        let region = Region::Box(Aabb::new(Vec3::ZERO, Vec3::splat(0.03)));
        let walls = vec![Wall {
            name: "floor".into(),
            shape: WallShape::Plane(Plane::new(Vec3::new(0.0, 0.0, 0.01), Vec3::Z)),
            material: 0,
            motion: Motion::Fixed,
        }];
        let existing = [(Vec3::splat(0.02), 3e-3)];
        let mut rng = seeded(4, 0);
        let n = 200;
        let f = random_clump_fill(
            &region,
            &m,
            FillTarget::Count(n),
            &existing,
            &WallClearance::new(&walls, 0.0),
            10_000,
            &mut rng,
        );
        assert_eq!(f.stuck_at, None);
        assert_eq!(f.bodies.len(), n as usize);
        let mut all: Vec<(usize, Vec3, f64)> = vec![(usize::MAX, existing[0].0, existing[0].1)];
        for (b, p) in f.bodies.iter().enumerate() {
            for (x, r) in members_of(&m, p) {
                assert!(region.contains_sphere(x, r));
                assert!(x.z - r >= 0.01 - 1e-15, "member below the floor");
                all.push((b, x, r));
            }
        }
        for (k, a) in all.iter().enumerate() {
            for b in &all[k + 1..] {
                if a.0 != b.0 {
                    assert!(
                        (a.1 - b.1).length() >= a.2 + b.2,
                        "members of bodies {} and {} overlap",
                        a.0,
                        b.0
                    );
                }
            }
        }
        let rods = f.bodies.iter().filter(|p| p.slot == 0).count() as f64;
        let se = (n as f64 * 0.75 * 0.25).sqrt();
        assert!((rods - 0.75 * n as f64).abs() < 5.0 * se, "{rods} rods of {n}");
        // Largest bounding radius first: the rods (2.5 mm), then the balls (1.5 mm).
        assert!(f
            .bodies
            .windows(2)
            .all(|w| m.shapes[w[0].slot].bounding_radius() >= m.shapes[w[1].slot].bounding_radius()));
    }

    #[test]
    fn a_region_too_small_for_the_body_reports_it() {
        let m = mix();
        let region = Region::Box(Aabb::new(Vec3::ZERO, Vec3::splat(0.004)));
        let mut rng = seeded(4, 0);
        let f = random_clump_fill(
            &region,
            &ClumpMix::new(vec![m.shapes[0].clone()], &[1.0]),
            FillTarget::Count(1),
            &[],
            &WallClearance::none(),
            1000,
            &mut rng,
        );
        assert_eq!(f.stuck_at, Some(0));
        assert!(f.bodies.is_empty());
    }

    /// A mass-rate clump injector stays within half a body mass of ṁ t at every placement, with two
    /// templates of different mass.
    #[test]
    fn mass_rate_clump_injection_is_exact_in_mass() {
        let m = mix();
        let mut inj = Injector {
            dist: SizeDistribution::Mono { diameter: 1.0 },
            clumps: Some(m.clone()),
            rate: InjectionRate::KgPerSecond(3e-3),
            density: 2500.0,
            start: 0.0,
            end: 1.0,
            velocity: Vec3::ZERO,
            material: 0,
            attempts: 1000,
            state: InjectorState::new(seeded(9, 1)),
        };
        let region = Region::Box(Aabb::new(Vec3::ZERO, Vec3::splat(0.2)));
        let mut existing: Vec<(Vec3, f64)> = Vec::new();
        let mut placed = 0;
        for k in 1..=100 {
            let t = k as f64 * 0.01;
            let new = inj.place_clumps(&region, t, &existing, &WallClearance::none());
            for p in &new {
                existing.extend(members_of(&m, p));
            }
            placed += new.len();
            let target = 3e-3 * t;
            assert!(
                (inj.state.mass - target).abs() <= 0.5 * 3.5e-5 + 1e-15,
                "t = {t}: {} vs {target}",
                inj.state.mass
            );
        }
        assert_eq!(placed as u64, inj.state.inserted);
        assert!(placed > 80);
    }
}
