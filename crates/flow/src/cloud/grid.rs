//! Mass concentration and extinction on a uniform grid, and the optical depth along a line of sight.
//!
//! Every airborne parcel adds its mass (count × particle mass) and its extinction cross-section
//! (count × Q_ext π D²/4) to the cell that contains it; divided by the cell volume these are the mass
//! concentration c \[kg/m³\] and the extinction coefficient β \[1/m\]. The optical depth of a segment is
//! τ = ∫ β ds, exact for the cellwise-constant β by walking the cells the segment crosses
//! (Amanatides & Woo 1987) and summing β × the length inside each.

use crate::tracker::{Parcel, Status};
use spatter_core::{Aabb, Vec3};
use spatter_io::vtu::Vtu;
use std::io;
use std::path::Path;

/// A uniform grid over a box.
#[derive(Clone, Debug, PartialEq)]
pub struct CloudGrid {
    pub bounds: Aabb,
    pub dims: [usize; 3],
    /// Mass \[kg\] and extinction cross-section \[m²\] per cell (x fastest).
    pub mass: Vec<f64>,
    pub cross_section: Vec<f64>,
}

impl CloudGrid {
    /// An empty grid of `dims` cells over `bounds` (non-empty box, every dimension ≥ 1).
    pub fn new(bounds: Aabb, dims: [usize; 3]) -> Self {
        let n = dims.iter().product();
        CloudGrid { bounds, dims, mass: vec![0.0; n], cross_section: vec![0.0; n] }
    }

    /// Cell size \[m\].
    pub fn cell(&self) -> Vec3 {
        let e = self.bounds.max - self.bounds.min;
        Vec3::new(e.x / self.dims[0] as f64, e.y / self.dims[1] as f64, e.z / self.dims[2] as f64)
    }

    fn cell_volume(&self) -> f64 {
        let c = self.cell();
        c.x * c.y * c.z
    }

    /// Index of the cell containing `x`, `None` outside.
    pub fn index(&self, x: Vec3) -> Option<usize> {
        if !self.bounds.contains(x) {
            return None;
        }
        let f = (x - self.bounds.min) / self.cell();
        let i = (f.x as usize).min(self.dims[0] - 1);
        let j = (f.y as usize).min(self.dims[1] - 1);
        let k = (f.z as usize).min(self.dims[2] - 1);
        Some(i + self.dims[0] * (j + self.dims[1] * k))
    }

    /// Clears and fills the grid from the airborne `parcels` with extinction efficiency `q_ext`.
    pub fn fill(&mut self, parcels: &[Parcel], q_ext: f64) {
        self.mass.iter_mut().for_each(|m| *m = 0.0);
        self.cross_section.iter_mut().for_each(|m| *m = 0.0);
        for p in parcels.iter().filter(|p| p.status == Status::Airborne) {
            if let Some(i) = self.index(p.pos) {
                self.mass[i] += p.mass();
                self.cross_section[i] +=
                    p.count * q_ext * 0.25 * std::f64::consts::PI * p.diameter * p.diameter;
            }
        }
    }

    /// Mass concentration per cell \[kg/m³\].
    pub fn concentration(&self) -> Vec<f64> {
        let v = self.cell_volume();
        self.mass.iter().map(|m| m / v).collect()
    }

    /// Extinction coefficient per cell \[1/m\].
    pub fn extinction(&self) -> Vec<f64> {
        let v = self.cell_volume();
        self.cross_section.iter().map(|m| m / v).collect()
    }

    /// Optical depth τ = ∫ β ds from `a` to `b` (the part of the segment inside the grid).
    pub fn optical_depth(&self, a: Vec3, b: Vec3) -> f64 {
        let d = b - a;
        let len = d.length();
        if len == 0.0 {
            return 0.0;
        }
        // Clip the segment to the box (slab method): parameters t0 < t1 in [0, 1].
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for ax in 0..3 {
            let (lo, hi, o, v) = (self.bounds.min[ax], self.bounds.max[ax], a[ax], d[ax]);
            if v == 0.0 {
                if o < lo || o > hi {
                    return 0.0;
                }
            } else {
                let (mut s0, mut s1) = ((lo - o) / v, (hi - o) / v);
                if s0 > s1 {
                    std::mem::swap(&mut s0, &mut s1);
                }
                t0 = t0.max(s0);
                t1 = t1.min(s1);
            }
        }
        if t1 <= t0 {
            return 0.0;
        }
        let cell = self.cell();
        let inv_vol = 1.0 / self.cell_volume();
        // Start cell at the entry point (nudged inside), then step cell to cell (Amanatides & Woo).
        let entry = a + d * t0;
        let mut idx = [0isize; 3];
        let mut step = [0isize; 3];
        let mut t_max = [f64::INFINITY; 3];
        let mut t_delta = [f64::INFINITY; 3];
        for ax in 0..3 {
            let f = ((entry[ax] - self.bounds.min[ax]) / cell[ax]).floor() as isize;
            // On an upper face the entry belongs to the last cell.
            let f = f.clamp(0, self.dims[ax] as isize - 1);
            idx[ax] = f;
            if d[ax] > 0.0 {
                step[ax] = 1;
                t_max[ax] = (self.bounds.min[ax] + (f + 1) as f64 * cell[ax] - a[ax]) / d[ax];
                t_delta[ax] = cell[ax] / d[ax];
            } else if d[ax] < 0.0 {
                step[ax] = -1;
                t_max[ax] = (self.bounds.min[ax] + f as f64 * cell[ax] - a[ax]) / d[ax];
                t_delta[ax] = -cell[ax] / d[ax];
            }
        }
        let mut t = t0;
        let mut tau = 0.0;
        loop {
            let ax = if t_max[0] <= t_max[1] && t_max[0] <= t_max[2] {
                0
            } else if t_max[1] <= t_max[2] {
                1
            } else {
                2
            };
            let t_next = t_max[ax].min(t1);
            let i = idx[0] as usize + self.dims[0] * (idx[1] as usize + self.dims[1] * idx[2] as usize);
            tau += self.cross_section[i] * inv_vol * (t_next - t).max(0.0) * len;
            if t_next >= t1 {
                break;
            }
            t = t_next;
            idx[ax] += step[ax];
            if idx[ax] < 0 || idx[ax] >= self.dims[ax] as isize {
                break;
            }
            t_max[ax] += t_delta[ax];
        }
        tau
    }

    /// Writes the grid as hexahedral cells with `concentration_kg_m3` and `extinction_1_m` cell data.
    pub fn write_vtu(&self, path: &Path) -> io::Result<()> {
        Vtu::hexahedral_grid(self.bounds.min, self.cell(), self.dims)
            .cell_scalar("concentration_kg_m3", &self.concentration())
            .cell_scalar("extinction_1_m", &self.extinction())
            .write(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tracker::Status;

    fn parcel(pos: Vec3, d: f64, count: f64) -> Parcel {
        Parcel {
            pos,
            vel: Vec3::ZERO,
            diameter: d,
            density: 2480.0,
            count,
            id: 0,
            hint: 0,
            status: Status::Airborne,
            injector: 0,
        }
    }

    #[test]
    fn uniform_cloud_follows_beer_lambert() {
        // One parcel of N grains per cell of a 10 × 10 × 10 grid over a 2 m cube: β = N Q π D²/4 / V_cell
        // everywhere, and τ = β L for any line through it, oblique ones included (exact traversal).
        let b = Aabb::new(Vec3::ZERO, Vec3::splat(2.0));
        let mut g = CloudGrid::new(b, [10, 10, 10]);
        let mut ps = Vec::new();
        for k in 0..10 {
            for j in 0..10 {
                for i in 0..10 {
                    ps.push(parcel(
                        Vec3::new(0.1 + 0.2 * i as f64, 0.1 + 0.2 * j as f64, 0.1 + 0.2 * k as f64),
                        50e-6,
                        1e4,
                    ));
                }
            }
        }
        g.fill(&ps, 2.0);
        let beta = 1e4 * 2.0 * 0.25 * std::f64::consts::PI * 2.5e-9 / 0.008;
        assert!(g.extinction().iter().all(|e| (e - beta).abs() < 1e-12 * beta));
        for (a, bb) in [
            (Vec3::new(-1.0, 1.0, 1.0), Vec3::new(3.0, 1.0, 1.0)),
            (Vec3::new(0.3, 0.2, 0.1), Vec3::new(1.7, 1.9, 1.3)),
            (Vec3::new(-1.0, -1.0, -1.0), Vec3::new(3.0, 3.0, 3.0)),
            (Vec3::new(0.5, 0.5, 1.9), Vec3::new(0.5, 0.5, 0.2)),
        ] {
            let seg = (bb - a).length();
            // Length inside the cube.
            let (mut t0, mut t1) = (0.0f64, 1.0f64);
            for ax in 0..3 {
                let v = bb[ax] - a[ax];
                let (mut s0, mut s1) = ((0.0 - a[ax]) / v, (2.0 - a[ax]) / v);
                if s0 > s1 {
                    std::mem::swap(&mut s0, &mut s1);
                }
                t0 = t0.max(s0);
                t1 = t1.min(s1);
            }
            let inside = (t1 - t0) * seg;
            let tau = g.optical_depth(a, bb);
            assert!(
                (tau - beta * inside).abs() < 1e-9 * beta * inside,
                "{a} → {bb}: {tau} vs {}",
                beta * inside
            );
        }
        // Outside the box: zero.
        assert_eq!(g.optical_depth(Vec3::new(3.0, 3.0, 3.0), Vec3::new(4.0, 3.0, 3.0)), 0.0);
        // Mass concentration: total mass / volume.
        let total: f64 = g.concentration().iter().sum::<f64>() * 0.008;
        let expect = 1000.0 * 1e4 * crate::forces::sphere_mass(50e-6, 2480.0);
        assert!((total - expect).abs() < 1e-12 * expect);
        let dir = tempfile::tempdir().unwrap();
        g.write_vtu(&dir.path().join("cloud.vtu")).unwrap();
    }

    #[test]
    fn a_single_cell_counts_only_its_chord() {
        let b = Aabb::new(Vec3::ZERO, Vec3::splat(1.0));
        let mut g = CloudGrid::new(b, [4, 4, 4]);
        g.fill(&[parcel(Vec3::new(0.6, 0.6, 0.6), 1e-4, 1.0)], 2.0);
        let beta = 2.0 * 0.25 * std::f64::consts::PI * 1e-8 / (0.25f64.powi(3));
        // Along x through that cell: chord 0.25 m.
        assert!(
            (g.optical_depth(Vec3::new(0.0, 0.6, 0.6), Vec3::new(1.0, 0.6, 0.6)) - 0.25 * beta).abs() < 1e-12
        );
        // A line missing the cell: zero.
        assert_eq!(g.optical_depth(Vec3::new(0.0, 0.1, 0.6), Vec3::new(1.0, 0.1, 0.6)), 0.0);
    }
}
