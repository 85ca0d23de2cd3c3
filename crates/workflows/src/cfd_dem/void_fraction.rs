//! The fluid volume fraction α of each cell of a Cartesian CFD grid, from the DEM spheres in it.
//!
//! * **cell centre** (the "particle centroid method"): a sphere's whole volume goes to the cell holding
//!   its centre. Cheap; α jumps when a sphere crosses a face.
//! * **divided**: the sphere's volume is split equally over the points of a 6 × 6 × 6 lattice of its
//!   bounding cube that lie inside it (136 points; the lattice spacing is 2r/6, the points sit at the
//!   centres of the sub-cubes), and each point's share goes to the cell holding the point. α then varies
//!   smoothly as a sphere crosses a face (the idea of the divided void-fraction model of CFDEM®coupling;
//!   the point set here is our own).
//!
//! Either way the solid volume of every sphere inside the grid is booked exactly once, so Σ (1 − α) V
//! over the cells equals the spheres' volume (before clamping). α is clamped to \[α_min, 1\]; blocked
//! (solid) cells keep α = 1 (no fluid equation is solved there).
//!
//! The accumulation runs over the particles in their storage order on one thread, so α is the same for
//! any thread count (it costs ~0.1 µs per lattice point; a scatter over a few hundred thousand spheres
//! is still well under the cost of the fluid step).

use serde::{Deserialize, Serialize};
use spatter_cfd::grid::{Grid, GHOST};
use spatter_core::Vec3;

/// How a sphere's volume is distributed over the cells.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum VoidFractionMethod {
    /// The whole volume to the cell of the centre.
    CellCentre,
    /// Split over sub-volume points (default).
    #[default]
    Divided,
}

/// Lattice points per axis of the divided method.
const LATTICE: usize = 6;

/// The divided method's points inside the unit sphere: lattice indices (i, j, k) along x, y, z, in the
/// order their shares are booked. A point sits at (−1 + (i + ½)·2/6, …) radii from the centre.
fn divided_points() -> Vec<[u8; 3]> {
    let mut out = Vec::new();
    for k in 0..LATTICE {
        for j in 0..LATTICE {
            for i in 0..LATTICE {
                if lattice_offset(i).powi(2) + lattice_offset(j).powi(2) + lattice_offset(k).powi(2) <= 1.0 {
                    out.push([i as u8, j as u8, k as u8]);
                }
            }
        }
    }
    out
}

/// Offset of lattice coordinate `i` from the centre, in radii.
fn lattice_offset(i: usize) -> f64 {
    -1.0 + 2.0 / LATTICE as f64 * (i as f64 + 0.5)
}

/// The void-fraction field and its workspace.
#[derive(Clone, Debug)]
pub struct VoidFraction {
    pub method: VoidFractionMethod,
    /// Lower clamp α_min ∈ (0, 1).
    pub alpha_min: f64,
    /// α per padded cell (1 in ghost and blocked cells).
    pub alpha: Vec<f64>,
    /// Solid volume booked per padded cell in the last update \[m³\].
    pub solid: Vec<f64>,
    points: Vec<[u8; 3]>,
}

impl VoidFraction {
    /// A field of α = 1 on `grid`.
    pub fn new(grid: &Grid, method: VoidFractionMethod, alpha_min: f64) -> Self {
        let n = grid.layout.len();
        VoidFraction { method, alpha_min, alpha: vec![1.0; n], solid: vec![0.0; n], points: divided_points() }
    }

    /// Index of the padded cell holding `x`, `None` outside the grid.
    pub fn cell_of(grid: &Grid, x: Vec3) -> Option<usize> {
        let x = x.to_array();
        let mut q = [0usize; 3];
        for a in 0..3 {
            let ax = &grid.axes[a];
            if !(x[a] >= ax.lo() && x[a] <= ax.hi()) {
                return None;
            }
            q[a] = ax.locate(x[a]) + GHOST;
        }
        Some(grid.layout.at(q[0], q[1], q[2]))
    }

    /// Recomputes α from spheres at `pos` with radii `radius` (all of them, frozen ones included: a
    /// fixed bed takes fluid volume too). Returns the solid volume that fell outside the grid \[m³\].
    pub fn update(&mut self, grid: &Grid, blocked: &[bool], pos: &[Vec3], radius: &[f64]) -> f64 {
        self.solid.iter_mut().for_each(|v| *v = 0.0);
        let mut outside = 0.0;
        let share = 1.0 / self.points.len() as f64;
        for (&x, &r) in pos.iter().zip(radius) {
            let v = 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
            match self.method {
                VoidFractionMethod::CellCentre => match Self::cell_of(grid, x) {
                    Some(c) => self.solid[c] += v,
                    None => outside += v,
                },
                VoidFractionMethod::Divided => {
                    // The points share their coordinates along each axis with a lattice plane, so the
                    // cell index along an axis is located once per plane (6 per axis instead of once per
                    // point); the shares are booked in the same point order as before.
                    let dv = v * share;
                    let xa = x.to_array();
                    let mut offset = [[None::<usize>; LATTICE]; 3];
                    for (a, row) in offset.iter_mut().enumerate() {
                        let ax = &grid.axes[a];
                        for (i, o) in row.iter_mut().enumerate() {
                            let y = xa[a] + r * lattice_offset(i);
                            if y >= ax.lo() && y <= ax.hi() {
                                *o = Some(grid.layout.s[a] * (ax.locate(y) + GHOST));
                            }
                        }
                    }
                    for &[i, j, k] in &self.points {
                        match (offset[0][i as usize], offset[1][j as usize], offset[2][k as usize]) {
                            (Some(a), Some(b), Some(c)) => self.solid[a + b + c] += dv,
                            _ => outside += dv,
                        }
                    }
                }
            }
        }
        let l = grid.layout;
        for (c, (a, (&solid, &b))) in self.alpha.iter_mut().zip(self.solid.iter().zip(blocked)).enumerate() {
            let q = l.coords(c);
            *a = if l.interior(q) && !b {
                (1.0 - solid / grid.volume(q)).clamp(self.alpha_min, 1.0)
            } else {
                1.0
            };
        }
        outside
    }

    /// α of the cell holding `x` (1 outside the grid).
    pub fn at(&self, grid: &Grid, x: Vec3) -> f64 {
        Self::cell_of(grid, x).map_or(1.0, |c| self.alpha[c])
    }

    /// The mean of α over the interior fluid cells whose centres lie in the box \[lo, hi\] (volume
    /// weighted); `None` if no cell centre does.
    pub fn mean_in_box(&self, grid: &Grid, blocked: &[bool], lo: Vec3, hi: Vec3) -> Option<f64> {
        let l = grid.layout;
        let (mut sum, mut vol) = (0.0, 0.0);
        for (c, &b) in blocked.iter().enumerate().take(l.len()) {
            let q = l.coords(c);
            if !l.interior(q) || b {
                continue;
            }
            let x = Vec3::from(grid.centre(q));
            if x.cmpge(lo).all() && x.cmple(hi).all() {
                let v = grid.volume(q);
                sum += self.alpha[c] * v;
                vol += v;
            }
        }
        (vol > 0.0).then(|| sum / vol)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_cfd::grid::{Axis, Mode};

    fn grid() -> Grid {
        Grid::new(
            [
                Axis::uniform(0.0, 0.01, 5).unwrap(),
                Axis::uniform(0.0, 0.01, 5).unwrap(),
                Axis::geometric(0.0, 0.02, 8, 1.1).unwrap(),
            ],
            Mode::Cartesian,
        )
        .unwrap()
    }

    #[test]
    fn both_methods_book_every_sphere_volume_exactly_once() {
        // Σ (1 − α) V over the cells = Σ 4/3 π r³ (nothing clamped: the spheres are small), to round-off
        // (1e-12 relative).
        let g = grid();
        let blocked = vec![false; g.layout.len()];
        let pos: Vec<Vec3> = (0..40)
            .map(|k| {
                Vec3::new(
                    0.001 + 0.0002 * k as f64,
                    0.0017 * (k % 5) as f64 + 0.001,
                    0.0004 * k as f64 + 0.001,
                )
            })
            .collect();
        let radius: Vec<f64> = (0..40).map(|k| 2e-4 + 1e-5 * k as f64).collect();
        let want: f64 = radius.iter().map(|r| 4.0 / 3.0 * std::f64::consts::PI * r * r * r).sum();
        for method in [VoidFractionMethod::CellCentre, VoidFractionMethod::Divided] {
            let mut vf = VoidFraction::new(&g, method, 0.3);
            let outside = vf.update(&g, &blocked, &pos, &radius);
            let l = g.layout;
            let got: f64 = (0..l.len())
                .filter(|&c| l.interior(l.coords(c)))
                .map(|c| (1.0 - vf.alpha[c]) * g.volume(l.coords(c)))
                .sum();
            assert_eq!(outside, 0.0);
            assert!((got / want - 1.0).abs() < 1e-12, "{method:?}: {got} vs {want}");
        }
    }

    #[test]
    fn divided_splits_a_sphere_on_a_face_evenly_and_alpha_is_clamped() {
        // A sphere centred on the face x = 4 mm between two cells of a uniform grid: the divided method
        // books half of its volume on each side (the lattice is symmetric about the centre); the cell
        // centre method books it all on one side. A sphere larger than its cell is clamped to α_min.
        let g = grid();
        let blocked = vec![false; g.layout.len()];
        let x = Vec3::new(0.004, 0.005, 0.001);
        let r = 5e-4;
        let mut vf = VoidFraction::new(&g, VoidFractionMethod::Divided, 0.3);
        vf.update(&g, &blocked, &[x], &[r]);
        let a = VoidFraction::cell_of(&g, x - Vec3::new(1e-4, 0.0, 0.0)).unwrap();
        let b = VoidFraction::cell_of(&g, x + Vec3::new(1e-4, 0.0, 0.0)).unwrap();
        assert_ne!(a, b);
        assert!((vf.solid[a] / vf.solid[b] - 1.0).abs() < 1e-12, "{} vs {}", vf.solid[a], vf.solid[b]);
        vf.update(&g, &blocked, &[x], &[3e-3]);
        assert_eq!(vf.at(&g, x), 0.3);
    }
}
