//! The wall particles a rank needs: on several ranks every rank holds the whole boundary (its reference
//! positions and frames), but only the wall particles within one kernel support of its wall region
//! enter its wall set — its box cut down to the neighbourhood of the fluid it owns and receives
//! (`Decomp::wall_region`): the walls its own fluid can see and the walls in its box any fluid reaches.
//! Everything a step does per wall particle (placing it, binning it, its extrapolated state, its wet
//! flag) then scales with the rank's share of the wetted walls instead of with all of them
//! (docs/scaling.md: with every wall on every rank a 10⁸-particle wading case spends seconds per step on
//! walls whatever the number of ranks, and with the whole box a rank at the water's edge holds the dry
//! road and the vehicle beyond it).
//!
//! To avoid even placing every wall particle each step, a part's particles are grouped in chunks of
//! [`CHUNK`] consecutive indices with their bounding box in the part's reference frame; a chunk whose
//! box, carried by the part's current frame, lies farther than the reach from the rank's box is skipped
//! whole. Consecutive indices are usually near each other (lattice and surface sampling fill a part row
//! by row), which keeps the chunk boxes tight; where they are not, the chunks are only looser, never
//! wrong. The selected particles come out in increasing index order, the order of the full wall set.

use crate::boundary::Boundary;
use rayon::prelude::*;
use spatter_core::{Aabb, Vec3};

/// Wall particles per chunk.
const CHUNK: usize = 256;

/// Consecutive wall particles `start..end` of one part and their bounding box in its reference frame.
#[derive(Clone, Debug)]
struct Chunk {
    start: u32,
    end: u32,
    part: u16,
    /// Centre and half extent of the box of the reference positions \[m\].
    centre: Vec3,
    half: Vec3,
}

/// The chunks of a boundary and scratch for the selection; rebuilt when the boundary changes size.
#[derive(Clone, Debug, Default)]
pub(crate) struct LocalWalls {
    chunks: Vec<Chunk>,
    /// Per chunk: whether its box is within reach (scratch of [`Self::select`]).
    near: Vec<bool>,
    /// Boundary size the chunks were built for.
    built_for: usize,
}

impl Chunk {
    /// Whether the chunk's box, carried by its part's current frame, lies within `reach` \[m\] of
    /// `region`.
    fn within(&self, b: &Boundary, region: &Aabb, reach: f64) -> bool {
        let f = &b.frames[self.part as usize];
        let centre = f.to_world(self.centre);
        let half = f.rot.abs() * self.half;
        Aabb::new(centre - half, centre + half).gap(region) <= reach
    }
}

/// Euclidean distance from `x` to the box `b` (0 inside; infinite faces never add) \[m\].
pub(crate) fn point_gap(x: Vec3, b: &Aabb) -> f64 {
    Aabb::new(x, x).gap(b)
}

impl LocalWalls {
    fn build(&mut self, b: &Boundary) {
        self.chunks.clear();
        for (k, part) in b.parts.iter().enumerate() {
            let mut start = part.start;
            while start < part.end {
                let end = (start + CHUNK).min(part.end);
                let bx = Aabb::from_points(&b.ref_pos[start..end]);
                self.chunks.push(Chunk {
                    start: start as u32,
                    end: end as u32,
                    part: k as u16,
                    centre: 0.5 * (bx.min + bx.max),
                    half: 0.5 * (bx.max - bx.min),
                });
                start = end;
            }
        }
        self.near.resize(self.chunks.len(), false);
        self.built_for = b.len();
    }

    fn ensure_built(&mut self, b: &Boundary) {
        if self.built_for != b.len() || (self.chunks.is_empty() && !b.is_empty()) {
            self.build(b);
        }
    }

    /// Calls `f(i, x)` for every wall particle `i` of `b` whose current world position `x` lies within
    /// `radius` \[m\] of `centre` (|x − centre| ≤ radius), in increasing index order. Chunks whose boxes
    /// are farther away are skipped whole, so a query costs one box test per chunk and a distance per
    /// particle of the nearby chunks instead of a distance per wall particle (a wall-pressure sensor on
    /// several ranks looks for the wall particles outside its rank's wall set this way).
    pub(crate) fn for_each_within(
        &mut self,
        b: &Boundary,
        centre: Vec3,
        radius: f64,
        mut f: impl FnMut(usize, Vec3),
    ) {
        self.ensure_built(b);
        let point = Aabb::new(centre, centre);
        // The chunk test compares boxes whose corners are rounded differently from the particles'
        // positions; a slack of 10⁻⁹ of the scale keeps a particle at exactly `radius` from being lost
        // with its chunk (a chunk too many only costs its distance tests).
        let reach = radius + 1e-9 * (1.0 + radius + centre.abs().max_element());
        for c in self.chunks.iter().filter(|c| c.within(b, &point, reach)) {
            for i in c.start as usize..c.end as usize {
                let x = b.position(i);
                if (x - centre).length() <= radius {
                    f(i, x);
                }
            }
        }
    }

    /// Appends to `src` and `pos` the index and current world position of every wall particle of `b`
    /// within `reach` \[m\] of `region`, in increasing index order.
    pub(crate) fn select(
        &mut self,
        b: &Boundary,
        region: &Aabb,
        reach: f64,
        src: &mut Vec<u32>,
        pos: &mut Vec<Vec3>,
    ) {
        self.ensure_built(b);
        self.near
            .par_iter_mut()
            .zip(self.chunks.par_iter())
            .with_min_len(256)
            .for_each(|(near, c)| *near = c.within(b, region, reach));
        for (c, _) in self.chunks.iter().zip(&self.near).filter(|(_, &near)| near) {
            for i in c.start as usize..c.end as usize {
                let x = b.position(i);
                if point_gap(x, region) <= reach {
                    src.push(i as u32);
                    pos.push(x);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::Dim;
    use crate::params::SphParams;
    use crate::sim::{Simulation, WallOptions};

    /// The selection equals the brute-force filter of every wall particle (same indices, same order,
    /// same positions) for a tank and a rotated, moved box part, for regions inside, across and outside
    /// the walls, and a region with infinite faces (an outer rank box of an unbounded domain).
    #[test]
    fn selection_equals_the_filter_of_every_wall_particle() {
        let mut sim = Simulation::new(SphParams::water(Dim::Three, 0.02, 10.0));
        let open_top = [true, true, true, true, true, false];
        sim.add_tank(
            "tank",
            Aabb::new(Vec3::ZERO, Vec3::new(1.0, 0.4, 0.5)),
            open_top,
            None,
            None,
            WallOptions::default(),
        );
        let mut b = sim.boundary.clone();
        // A second frame: rotated 30° about z and moved, as a moving part's frame would be.
        let (s, c) = 30f64.to_radians().sin_cos();
        b.frames[0].rot = spatter_core::Mat3::from_cols(
            Vec3::new(c, s, 0.0),
            Vec3::new(-s, c, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        );
        b.frames[0].origin = Vec3::new(0.3, -0.2, 0.1);
        let inf = f64::INFINITY;
        let regions = [
            Aabb::new(Vec3::new(0.2, 0.02, 0.03), Vec3::new(0.5, 0.3, 0.3)),
            Aabb::new(Vec3::new(-0.1, -0.1, -0.1), Vec3::new(0.05, 0.5, 0.2)),
            Aabb::new(Vec3::new(5.0, 5.0, 5.0), Vec3::new(6.0, 6.0, 6.0)),
            Aabb::new(Vec3::new(-inf, -inf, -inf), Vec3::new(0.4, inf, inf)),
        ];
        for boundary in [&sim.boundary, &b] {
            for region in &regions {
                let reach = 0.06;
                let mut lw = LocalWalls::default();
                let (mut src, mut pos) = (Vec::new(), Vec::new());
                lw.select(boundary, region, reach, &mut src, &mut pos);
                let want: Vec<u32> = (0..boundary.len())
                    .filter(|&i| point_gap(boundary.position(i), region) <= reach)
                    .map(|i| i as u32)
                    .collect();
                assert_eq!(src, want, "region {region:?}");
                assert!(pos.iter().zip(&src).all(|(x, &i)| *x == boundary.position(i as usize)));
            }
        }
        // Spheres around points inside, on and outside the walls, both frames: the same particles in the
        // same order as the distance test over every wall particle.
        for boundary in [&sim.boundary, &b] {
            for (centre, radius) in [
                (Vec3::new(0.5, 0.2, 0.0), 0.07),
                (Vec3::new(0.0, 0.0, 0.0), 0.15),
                (Vec3::new(0.9, 0.35, 0.25), 0.05),
                (Vec3::new(3.0, 3.0, 3.0), 0.1),
            ] {
                let mut lw = LocalWalls::default();
                let mut got = Vec::new();
                lw.for_each_within(boundary, centre, radius, |i, x| got.push((i, x)));
                let want: Vec<(usize, Vec3)> = (0..boundary.len())
                    .map(|i| (i, boundary.position(i)))
                    .filter(|(_, x)| (*x - centre).length() <= radius)
                    .collect();
                assert_eq!(got, want, "sphere at {centre:?}, radius {radius}");
            }
        }
        let mut n = 0;
        LocalWalls::default().for_each_within(&sim.boundary, Vec3::new(0.5, 0.2, 0.0), 0.07, |_, _| n += 1);
        assert!(n > 10 && n < sim.boundary.len() / 10, "{n} of {}", sim.boundary.len());
        // The cases test something: the first region selects some walls but not all, the third none.
        let mut lw = LocalWalls::default();
        let (mut src, mut pos) = (Vec::new(), Vec::new());
        lw.select(&sim.boundary, &regions[0], 0.06, &mut src, &mut pos);
        assert!(
            !src.is_empty() && src.len() < sim.boundary.len() / 2,
            "{} of {}",
            src.len(),
            sim.boundary.len()
        );
    }
}
