//! Filling a region with fluid particles on a lattice of spacing dp: a box minus the solids and walls in
//! it, or a flood fill from a seed point that never crosses a wall.

use crate::boundary::Boundary;
use crate::kernel::Dim;
use crate::neighbours::NeighbourGrid;
use spatter_core::{Aabb, Vec3};
use std::collections::VecDeque;

/// Distances that keep new fluid particles off the walls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    /// Minimum distance to any boundary particle \[m\].
    pub particles: f64,
    /// Minimum distance to a mesh part's surface \[m\].
    pub surface: f64,
}

impl Clearance {
    /// Defaults: 0.75·dp from boundary particles, 0.5·dp from mesh surfaces.
    pub fn for_spacing(dp: f64) -> Self {
        Clearance { particles: 0.75 * dp, surface: 0.5 * dp }
    }
}

/// Lattice index range along one axis: points `lo + (i + 0.5)·dp` strictly inside `(lo, hi)`.
fn count(lo: f64, hi: f64, dp: f64) -> usize {
    let n = ((hi - lo) / dp + 1e-9).floor();
    if n > 0.0 {
        n as usize
    } else {
        0
    }
}

/// Tests whether a lattice site may hold fluid.
struct Admission<'a> {
    boundary: &'a Boundary,
    grid: NeighbourGrid,
    clear: Clearance,
}

impl<'a> Admission<'a> {
    fn new(boundary: &'a Boundary, clear: Clearance) -> Self {
        let mut grid = NeighbourGrid::new();
        // Query radius: twice the particle clearance covers both uses below.
        grid.rebuild(&boundary.ref_pos, 2.0 * clear.particles.max(1e-12));
        Admission { boundary, grid, clear }
    }

    /// Distance to the nearest boundary particle, if one is within `2·clearance.particles`.
    fn nearest_particle(&self, p: Vec3) -> f64 {
        let mut best = f64::INFINITY;
        self.grid.for_each_run(p, |r| {
            for &j in &self.grid.entries()[r] {
                best = best.min((self.boundary.ref_pos[j as usize] - p).length());
            }
        });
        best
    }

    fn ok(&self, p: Vec3) -> bool {
        if self.nearest_particle(p) < self.clear.particles {
            return false;
        }
        for part in &self.boundary.parts {
            // A site exactly `surface` off a face (lattice-aligned bodies) is admitted whatever the rounding.
            let near = self.clear.surface * (1.0 - 1e-9);
            if part.sampling.coverage().is_some() && part.bvh.closest_point(&part.surface, p, near).is_some()
            {
                return false;
            }
            if part.closed && part.bvh.bounds().contains(p) && part.bvh.contains_point(&part.surface, p) {
                return false;
            }
        }
        true
    }

    /// Whether the straight path between two neighbouring sites crosses a wall.
    fn blocked(&self, a: Vec3, b: Vec3) -> bool {
        // Far from every boundary particle no surface can be in between (surfaces are sampled at dp).
        if self.nearest_particle(a) > 2.0 * self.clear.particles
            && self.nearest_particle(b) > 2.0 * self.clear.particles
        {
            return false;
        }
        self.boundary.parts.iter().any(|part| part.bvh.segment_first_hit(&part.surface, a, b).is_some())
    }
}

/// Lattice points of `region` (offset dp/2 from its lower corner) that are not inside a solid and keep
/// the clearance from walls. In 2D only the x–z plane (y = 0) is filled.
pub fn fill_box(boundary: &Boundary, region: Aabb, dp: f64, dim: Dim, clear: Clearance) -> Vec<Vec3> {
    let adm = Admission::new(boundary, clear);
    let nx = count(region.min.x, region.max.x, dp);
    let ny = if dim == Dim::Two { 1 } else { count(region.min.y, region.max.y, dp) };
    let nz = count(region.min.z, region.max.z, dp);
    let mut out = Vec::with_capacity(nx * ny * nz);
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let p = site(region, dp, dim, [i as i64, j as i64, k as i64]);
                if adm.ok(p) {
                    out.push(p);
                }
            }
        }
    }
    out
}

fn site(region: Aabb, dp: f64, dim: Dim, ijk: [i64; 3]) -> Vec3 {
    let y = if dim == Dim::Two { 0.0 } else { region.min.y + (ijk[1] as f64 + 0.5) * dp };
    Vec3::new(region.min.x + (ijk[0] as f64 + 0.5) * dp, y, region.min.z + (ijk[2] as f64 + 0.5) * dp)
}

/// Flood fill of the lattice of `region` from the site nearest `seed`, through sites that keep the
/// clearance and along paths that cross no wall. Errors when the seed site itself is not admissible.
pub fn flood_fill(
    boundary: &Boundary,
    seed: Vec3,
    region: Aabb,
    dp: f64,
    dim: Dim,
    clear: Clearance,
) -> Result<Vec<Vec3>, String> {
    let adm = Admission::new(boundary, clear);
    let n = [
        count(region.min.x, region.max.x, dp),
        if dim == Dim::Two { 1 } else { count(region.min.y, region.max.y, dp) },
        count(region.min.z, region.max.z, dp),
    ];
    if n.contains(&0) {
        return Err(format!("the fill region is thinner than one spacing ({dp} m)"));
    }
    let idx = |c: f64, lo: f64, n: usize| (((c - lo) / dp - 0.5).round().max(0.0) as usize).min(n - 1);
    let start = [
        idx(seed.x, region.min.x, n[0]),
        if dim == Dim::Two { 0 } else { idx(seed.y, region.min.y, n[1]) },
        idx(seed.z, region.min.z, n[2]),
    ];
    let s0 = site(region, dp, dim, start.map(|v| v as i64));
    if !adm.ok(s0) {
        return Err(format!(
            "the seed point [{}, {}, {}] is inside a solid or closer than the clearance to a wall",
            seed.x, seed.y, seed.z
        ));
    }
    let flat = |c: [usize; 3]| (c[2] * n[1] + c[1]) * n[0] + c[0];
    let mut state = vec![0u8; n[0] * n[1] * n[2]]; // 0 unseen, 1 fluid, 2 rejected
    let mut queue = VecDeque::new();
    state[flat(start)] = 1;
    queue.push_back(start);
    let dirs: &[[i64; 3]] = if dim == Dim::Two {
        &[[1, 0, 0], [-1, 0, 0], [0, 0, 1], [0, 0, -1]]
    } else {
        &[[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
    };
    let mut out = Vec::new();
    while let Some(c) = queue.pop_front() {
        let p = site(region, dp, dim, c.map(|v| v as i64));
        out.push(p);
        for d in dirs {
            let nc = [c[0] as i64 + d[0], c[1] as i64 + d[1], c[2] as i64 + d[2]];
            if nc.iter().zip(n).any(|(&v, m)| v < 0 || v >= m as i64) {
                continue;
            }
            let nc = nc.map(|v| v as usize);
            let f = flat(nc);
            if state[f] != 0 {
                continue;
            }
            let q = site(region, dp, dim, nc.map(|v| v as i64));
            if adm.ok(q) && !adm.blocked(p, q) {
                state[f] = 1;
                queue.push_back(nc);
            } else if !adm.ok(q) {
                state[f] = 2;
            }
        }
    }
    // Breadth-first order is not spatial order; return the sites sorted like `fill_box`.
    out.sort_by(|a, b| a.z.total_cmp(&b.z).then(a.y.total_cmp(&b.y)).then(a.x.total_cmp(&b.x)));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::{box_surface, mesh_samples, tank_lattice, Sampling, Slip};
    use spatter_core::mesh::TriMesh;

    #[test]
    fn a_box_fill_stops_at_the_tank_walls_and_a_plate_splits_a_flood_fill() {
        let dp = 0.1;
        let inner = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 0.4, 1.0));
        let mut b = Boundary::default();
        let faces = [true, true, true, true, true, false];
        let s = tank_lattice(inner, faces, 2, dp, Dim::Three);
        b.add_part(
            "tank",
            None,
            s,
            box_surface(inner, faces, true, Dim::Three),
            Sampling::Lattice,
            0.0,
            Slip::NoSlip,
            false,
        );
        let all = fill_box(&b, inner, dp, Dim::Three, Clearance::for_spacing(dp));
        assert_eq!(all.len(), 10 * 4 * 10, "the fluid lattice fits exactly inside the walls");
        // A vertical plate at x = 0.5 spanning the full tank, one particle thick.
        let mut plate = TriMesh::rectangle(0.4, 1.0, 0.0, 4, 8);
        plate.map_vertices(|v| Vec3::new(0.5, v.x, v.y));
        let (ps, cov) = mesh_samples(&plate, dp, 1, 1);
        b.add_part("plate", None, ps, plate, Sampling::Mesh(cov), 0.0, Slip::NoSlip, false);
        let left =
            flood_fill(&b, Vec3::new(0.2, 0.2, 0.5), inner, dp, Dim::Three, Clearance::for_spacing(dp))
                .unwrap();
        assert!(left.iter().all(|p| p.x < 0.5), "the flood fill stays on the seed's side of the plate");
        // Sites at x = 0.45 are 0.05 m from the plate surface: too close (0.5 dp clearance ties; 0.75 dp to particles).
        assert_eq!(left.len(), 4 * 4 * 10);
        let boxed = fill_box(&b, inner, dp, Dim::Three, Clearance::for_spacing(dp));
        assert_eq!(boxed.len(), 8 * 4 * 10, "a box fill skips the sites next to the plate on both sides");
        assert!(flood_fill(&b, Vec3::new(0.5, 0.2, 0.5), inner, dp, Dim::Three, Clearance::for_spacing(dp))
            .is_err());
    }
}
