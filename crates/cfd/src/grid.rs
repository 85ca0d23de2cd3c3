//! Structured grids: face coordinates per axis (uniform or stretched), the padded memory layout shared by
//! every field, and the metric factors of the finite-volume operators.
//!
//! A grid is the tensor product of three [`Axis`]. In [`Mode::Cartesian`] the axes are x, y, z. In
//! [`Mode::Axisymmetric`] the first axis is the radius r (its first face must be 0, the axis), the second
//! is the axial coordinate z, and the third axis holds one cell of one radian: face areas and volumes carry
//! the factor r, so that Σ A_f u_f is the discrete form of (1/r)∂(r u_r)/∂r + ∂u_z/∂z.
//!
//! Every field is stored with [`GHOST`] ghost layers on each side so that interior stencils (second
//! neighbours for the TVD limiter) never branch; cell `(i, j, k)` of the padded array is at
//! `i + sx·j + sy·k` with `i ∈ 0..nx + 2·GHOST`. Interior cells are `GHOST..GHOST + n`.

use serde::{Deserialize, Serialize};

/// Ghost layers on each side of every field.
pub const GHOST: usize = 2;

/// Face coordinates along one axis \[m\]: `n + 1` strictly increasing values.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Axis {
    faces: Vec<f64>,
}

/// Why an axis could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AxisError {
    #[error("an axis needs at least one cell")]
    NoCells,
    #[error(
        "axis face coordinates must increase strictly and be finite; face {index} = {value} after {previous}"
    )]
    NotIncreasing { index: usize, value: f64, previous: f64 },
    #[error("stretching ratio {0} must be finite and > 0")]
    BadRatio(f64),
}

impl Axis {
    /// `n` equal cells on `[lo, hi]`.
    pub fn uniform(lo: f64, hi: f64, n: usize) -> Result<Self, AxisError> {
        if n == 0 {
            return Err(AxisError::NoCells);
        }
        let h = (hi - lo) / n as f64;
        Self::from_faces((0..=n).map(|i| if i == n { hi } else { lo + i as f64 * h }).collect())
    }

    /// `n` cells on `[lo, hi]` growing geometrically: each cell is `ratio` times the one before it
    /// (ratio < 1 clusters cells at `hi`, > 1 at `lo`).
    pub fn geometric(lo: f64, hi: f64, n: usize, ratio: f64) -> Result<Self, AxisError> {
        if !(ratio.is_finite() && ratio > 0.0) {
            return Err(AxisError::BadRatio(ratio));
        }
        if n == 0 {
            return Err(AxisError::NoCells);
        }
        if (ratio - 1.0).abs() < 1e-12 {
            return Self::uniform(lo, hi, n);
        }
        // First width h0 with h0 (ratio^n − 1)/(ratio − 1) = hi − lo.
        let h0 = (hi - lo) * (ratio - 1.0) / (ratio.powi(n as i32) - 1.0);
        let mut faces = Vec::with_capacity(n + 1);
        let mut x = lo;
        let mut h = h0;
        for _ in 0..n {
            faces.push(x);
            x += h;
            h *= ratio;
        }
        faces.push(hi);
        Self::from_faces(faces)
    }

    /// `n` cells on `[lo, hi]` clustered symmetrically towards both ends by a tanh map of strength `beta`
    /// (0 → uniform; 2 gives end cells about 4× smaller than the middle ones). Suited to walls at both ends.
    pub fn clustered(lo: f64, hi: f64, n: usize, beta: f64) -> Result<Self, AxisError> {
        if !(beta.is_finite() && beta >= 0.0) {
            return Err(AxisError::BadRatio(beta));
        }
        if beta < 1e-9 {
            return Self::uniform(lo, hi, n);
        }
        if n == 0 {
            return Err(AxisError::NoCells);
        }
        let t = beta.tanh();
        Self::from_faces(
            (0..=n)
                .map(|i| {
                    let s = 2.0 * i as f64 / n as f64 - 1.0; // −1..1
                    let m = (beta * s).tanh() / t; // −1..1, clustered at the ends
                    if i == 0 {
                        lo
                    } else if i == n {
                        hi
                    } else {
                        lo + 0.5 * (m + 1.0) * (hi - lo)
                    }
                })
                .collect(),
        )
    }

    /// An axis from explicit face coordinates.
    pub fn from_faces(faces: Vec<f64>) -> Result<Self, AxisError> {
        if faces.len() < 2 {
            return Err(AxisError::NoCells);
        }
        for i in 0..faces.len() {
            let ok = faces[i].is_finite() && (i == 0 || faces[i] > faces[i - 1]);
            if !ok {
                return Err(AxisError::NotIncreasing {
                    index: i,
                    value: faces[i],
                    previous: if i == 0 { f64::NAN } else { faces[i - 1] },
                });
            }
        }
        Ok(Axis { faces })
    }

    /// Number of cells.
    pub fn n(&self) -> usize {
        self.faces.len() - 1
    }

    /// Face coordinates \[m\].
    pub fn faces(&self) -> &[f64] {
        &self.faces
    }

    /// Width of cell `i` \[m\].
    pub fn width(&self, i: usize) -> f64 {
        self.faces[i + 1] - self.faces[i]
    }

    /// Centre of cell `i` \[m\].
    pub fn centre(&self, i: usize) -> f64 {
        0.5 * (self.faces[i] + self.faces[i + 1])
    }

    pub fn lo(&self) -> f64 {
        self.faces[0]
    }

    pub fn hi(&self) -> f64 {
        self.faces[self.faces.len() - 1]
    }

    /// Smallest cell width \[m\].
    pub fn min_width(&self) -> f64 {
        (0..self.n()).map(|i| self.width(i)).fold(f64::INFINITY, f64::min)
    }

    /// Index of the cell holding coordinate `x` (clamped to the axis).
    pub fn locate(&self, x: f64) -> usize {
        let n = self.n();
        match self.faces.binary_search_by(|f| f.total_cmp(&x)) {
            Ok(i) => i.min(n - 1),
            Err(0) => 0,
            Err(i) => (i - 1).min(n - 1),
        }
    }
}

/// Coordinate system of a grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// x, y, z.
    #[default]
    Cartesian,
    /// (r, z) with one azimuthal cell of one radian; no swirl.
    Axisymmetric,
}

/// Per-axis metric arrays over the padded index range, for nodes at cell centres (`c`) and at the +side
/// face of a cell (`f`). The weight `w` is r on the radial axis of an axisymmetric grid and 1 otherwise.
#[derive(Clone, Debug)]
pub struct AxisMetric {
    /// Cell width (ghost cells mirror the first/last interior widths) \[m\].
    pub d: Vec<f64>,
    /// Distance from centre i to centre i + 1 \[m\].
    pub dc: Vec<f64>,
    /// Cell-centre coordinate \[m\].
    pub xc: Vec<f64>,
    /// Coordinate of the +side face of cell i \[m\].
    pub xf: Vec<f64>,
    /// Weight at the centre and at the +face (r or 1).
    pub wc: Vec<f64>,
    pub wf: Vec<f64>,
    /// Centre node: area/volume factor of its + and − faces \[1/m\].
    pub cp: Vec<f64>,
    pub cm: Vec<f64>,
    /// Face node (control volume from centre i to centre i+1): factor of its + and − sides \[1/m\].
    pub fp: Vec<f64>,
    pub fm: Vec<f64>,
}

impl AxisMetric {
    fn new(axis: &Axis, radial: bool) -> Self {
        let n = axis.n();
        let np = n + 2 * GHOST;
        // Mirror widths into the ghosts.
        let width = |p: usize| -> f64 {
            let i = p as isize - GHOST as isize;
            let n = n as isize;
            let m = if i < 0 {
                -i - 1
            } else if i >= n {
                2 * n - 1 - i
            } else {
                i
            };
            axis.width(m.clamp(0, n - 1) as usize)
        };
        let d: Vec<f64> = (0..np).map(width).collect();
        let mut xf = vec![0.0; np];
        // Face GHOST − 1 (the −face of the first interior cell) is the axis start.
        xf[GHOST - 1] = axis.lo();
        for p in GHOST..np {
            xf[p] = xf[p - 1] + d[p];
        }
        for p in (0..GHOST - 1).rev() {
            xf[p] = xf[p + 1] - d[p + 1];
        }
        // Use the exact interior faces (no accumulated round-off).
        for i in 0..=n {
            xf[GHOST - 1 + i] = axis.faces()[i];
        }
        let xc: Vec<f64> = (0..np).map(|p| xf[p] - 0.5 * d[p]).collect();
        let dc: Vec<f64> = (0..np).map(|p| if p + 1 < np { xc[p + 1] - xc[p] } else { d[p] }).collect();
        let weight = |x: f64| if radial { x.abs() } else { 1.0 };
        let wc: Vec<f64> = xc.iter().map(|&x| weight(x)).collect();
        let wf: Vec<f64> = xf.iter().map(|&x| weight(x)).collect();
        let safe = |num: f64, den: f64| if den > 0.0 { num / den } else { 0.0 };
        let mut cp = vec![0.0; np];
        let mut cm = vec![0.0; np];
        let mut fp = vec![0.0; np];
        let mut fm = vec![0.0; np];
        for p in 1..np - 1 {
            cp[p] = safe(wf[p], wc[p] * d[p]);
            cm[p] = safe(wf[p - 1], wc[p] * d[p]);
            fp[p] = safe(wc[p + 1], wf[p] * dc[p]);
            fm[p] = safe(wc[p], wf[p] * dc[p]);
        }
        AxisMetric { d, dc, xc, xf, wc, wf, cp, cm, fp, fm }
    }
}

/// Index arithmetic of the padded arrays.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Interior cells per axis.
    pub n: [usize; 3],
    /// Padded size per axis (`n + 2·GHOST`).
    pub p: [usize; 3],
    /// Strides: 1, px, px·py.
    pub s: [usize; 3],
}

impl Layout {
    pub fn new(n: [usize; 3]) -> Self {
        let p = [n[0] + 2 * GHOST, n[1] + 2 * GHOST, n[2] + 2 * GHOST];
        Layout { n, p, s: [1, p[0], p[0] * p[1]] }
    }

    /// Padded array length.
    pub fn len(&self) -> usize {
        self.p[0] * self.p[1] * self.p[2]
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Length of one k-plane.
    pub fn plane(&self) -> usize {
        self.s[2]
    }

    /// Padded index of padded coordinates.
    #[inline]
    pub fn at(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.s[1] * j + self.s[2] * k
    }

    /// Padded index of interior cell `(i, j, k)` (0-based interior coordinates).
    #[inline]
    pub fn cell(&self, i: usize, j: usize, k: usize) -> usize {
        self.at(i + GHOST, j + GHOST, k + GHOST)
    }

    /// Padded coordinates of a padded index.
    #[inline]
    pub fn coords(&self, c: usize) -> [usize; 3] {
        [c % self.p[0], (c / self.s[1]) % self.p[1], c / self.s[2]]
    }

    /// Whether padded coordinates lie inside the interior.
    #[inline]
    pub fn interior(&self, q: [usize; 3]) -> bool {
        (0..3).all(|a| q[a] >= GHOST && q[a] < GHOST + self.n[a])
    }

    /// Number of interior cells.
    pub fn cells(&self) -> usize {
        self.n[0] * self.n[1] * self.n[2]
    }
}

/// A structured grid with its metric.
#[derive(Clone, Debug)]
pub struct Grid {
    pub axes: [Axis; 3],
    pub mode: Mode,
    pub layout: Layout,
    pub metric: [AxisMetric; 3],
}

/// Why a grid could not be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GridError {
    #[error("axisymmetric grids need the radial axis to start at r = 0 (found {0} m)")]
    AxisNotAtZero(f64),
    #[error("axisymmetric grids have exactly one cell along the third axis (found {0})")]
    AxisymmetricThirdAxis(usize),
}

impl Grid {
    pub fn new(axes: [Axis; 3], mode: Mode) -> Result<Self, GridError> {
        if mode == Mode::Axisymmetric {
            if axes[0].lo() != 0.0 {
                return Err(GridError::AxisNotAtZero(axes[0].lo()));
            }
            if axes[2].n() != 1 {
                return Err(GridError::AxisymmetricThirdAxis(axes[2].n()));
            }
        }
        let layout = Layout::new([axes[0].n(), axes[1].n(), axes[2].n()]);
        let radial = mode == Mode::Axisymmetric;
        let metric = [
            AxisMetric::new(&axes[0], radial),
            AxisMetric::new(&axes[1], false),
            AxisMetric::new(&axes[2], false),
        ];
        Ok(Grid { axes, mode, layout, metric })
    }

    /// A uniform Cartesian box `[lo, hi]` with `n` cells per axis.
    pub fn uniform_box(lo: [f64; 3], hi: [f64; 3], n: [usize; 3]) -> Result<Self, AxisError> {
        let ax = |a: usize| Axis::uniform(lo[a], hi[a], n[a]);
        Ok(Grid::new([ax(0)?, ax(1)?, ax(2)?], Mode::Cartesian)
            .expect("Cartesian grids have no mode constraints"))
    }

    /// Cell volume \[m³\] (per radian in axisymmetric mode) of padded cell `q`.
    pub fn volume(&self, q: [usize; 3]) -> f64 {
        let m = &self.metric;
        m[0].wc[q[0]] * m[0].d[q[0]] * m[1].d[q[1]] * m[2].d[q[2]]
    }

    /// Area \[m²\] of the +face of padded cell `q` normal to axis `a`.
    pub fn face_area(&self, a: usize, q: [usize; 3]) -> f64 {
        let m = &self.metric;
        match a {
            0 => m[0].wf[q[0]] * m[1].d[q[1]] * m[2].d[q[2]],
            1 => m[0].wc[q[0]] * m[0].d[q[0]] * m[2].d[q[2]],
            _ => m[0].wc[q[0]] * m[0].d[q[0]] * m[1].d[q[1]],
        }
    }

    /// Centre of padded cell `q` \[m\].
    pub fn centre(&self, q: [usize; 3]) -> [f64; 3] {
        [self.metric[0].xc[q[0]], self.metric[1].xc[q[1]], self.metric[2].xc[q[2]]]
    }

    /// Smallest cell width over the interior \[m\].
    pub fn min_width(&self) -> f64 {
        let lim = if self.mode == Mode::Axisymmetric { 2 } else { 3 };
        (0..lim).map(|a| self.axes[a].min_width()).fold(f64::INFINITY, f64::min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretched_axes_cover_the_interval_and_grow_as_asked() {
        let a = Axis::geometric(0.0, 1.0, 10, 1.2).unwrap();
        assert_eq!(a.n(), 10);
        assert_eq!(a.hi(), 1.0);
        for i in 1..9 {
            assert!((a.width(i) / a.width(i - 1) - 1.2).abs() < 1e-12);
        }
        let c = Axis::clustered(0.0, 2.0, 20, 2.0).unwrap();
        assert!((c.width(0) - c.width(19)).abs() < 1e-12, "symmetric");
        assert!(c.width(0) < 0.3 * c.width(10), "clustered at the ends");
        assert!(Axis::from_faces(vec![0.0, 1.0, 1.0]).is_err());
        assert_eq!(a.locate(0.0), 0);
        assert_eq!(a.locate(1.0), 9);
        assert_eq!(a.locate(a.faces()[3] + 1e-9), 3);
    }

    #[test]
    fn axisymmetric_metric_has_zero_area_on_the_axis_and_r_weighted_volumes() {
        let g = Grid::new(
            [
                Axis::uniform(0.0, 1.0, 4).unwrap(),
                Axis::uniform(0.0, 2.0, 8).unwrap(),
                Axis::uniform(0.0, 1.0, 1).unwrap(),
            ],
            Mode::Axisymmetric,
        )
        .unwrap();
        let q = [GHOST, GHOST, GHOST];
        // −face of the first radial cell is the axis.
        assert_eq!(g.metric[0].wf[GHOST - 1], 0.0);
        assert!((g.volume(q) - 0.125 * 0.25 * 0.25).abs() < 1e-15);
        // Σ volumes = ∫ r dr dz = R²/2 · L per radian.
        let mut v = 0.0;
        for i in 0..4 {
            for j in 0..8 {
                v += g.volume([GHOST + i, GHOST + j, GHOST]);
            }
        }
        assert!((v - 0.5 * 2.0).abs() < 1e-12);
    }
}
