//! A flow field imported from CFD results (VTK files), steady or a time series.
//!
//! **Interpolation modes** ([`Interpolation`]):
//!
//! * `point` — linear interpolation of point data on the tetrahedral decomposition. Cells other than
//!   tetrahedra get a centre point at their vertex mean, valued at the mean of their vertex values (so a
//!   field linear in space is reproduced exactly). This is the default whenever the file has point data
//!   (OpenFOAM's `foamToVTK` writes both; its point values honour the boundary conditions, e.g. zero
//!   velocity on no-slip walls).
//! * `cell_point` — OpenFOAM's `cellPoint` idea: the centre point sits at the cell's volume centroid and
//!   carries the cell value; the vertices carry point data, or, when the file has only cell data,
//!   values reconstructed by a weighted least-squares linear fit over the cells around each vertex
//!   (exact for linear fields).
//! * `cell` — the cell value, constant in each cell (zero gradient), as Fluent's DPM does by default.
//!
//! k and ε (or ω, converted with ε = β* k ω, β* = 0.09; Wilcox 2006) are read when present.

use super::decompose::{decompose, CentreRule};
use super::tetmesh::TetMesh;
use super::{FieldError, FlowField, Sample};
use serde::{Deserialize, Serialize};
use spatter_core::{Aabb, Mat3, Vec3};
use spatter_io::vtk::{self, DataArray, VtkDataset};
use std::path::{Path, PathBuf};

/// How values between mesh points are obtained.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Interpolation {
    /// `point` when the velocity is given as point data, else `cell_point`.
    #[default]
    Auto,
    Point,
    CellPoint,
    Cell,
}

/// Names of the arrays to read.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ArrayNames {
    #[serde(default = "name_u")]
    pub velocity: String,
    #[serde(default = "name_k")]
    pub k: String,
    #[serde(default = "name_eps")]
    pub epsilon: String,
    #[serde(default = "name_omega")]
    pub omega: String,
}

fn name_u() -> String {
    "U".into()
}
fn name_k() -> String {
    "k".into()
}
fn name_eps() -> String {
    "epsilon".into()
}
fn name_omega() -> String {
    "omega".into()
}

impl Default for ArrayNames {
    fn default() -> Self {
        ArrayNames { velocity: name_u(), k: name_k(), epsilon: name_eps(), omega: name_omega() }
    }
}

/// One time level: values at the tetrahedral mesh points (or per cell in `cell` mode).
#[derive(Clone, Debug, Default)]
struct Frame {
    time: f64,
    u: Vec<Vec3>,
    k: Vec<f64>,
    eps: Vec<f64>,
}

/// Weighted least-squares reconstruction of point values from cell values (sparse rows, one per
/// dataset point).
#[derive(Clone, Debug, Default)]
struct Recon {
    start: Vec<u32>,
    cells: Vec<u32>,
    w: Vec<f64>,
}

impl Recon {
    fn apply(&self, cell_values: &[f64], comps: usize) -> Vec<f64> {
        let n = self.start.len() - 1;
        let mut out = vec![0.0; n * comps];
        for p in 0..n {
            for e in self.start[p] as usize..self.start[p + 1] as usize {
                let c = self.cells[e] as usize;
                for k in 0..comps {
                    out[p * comps + k] += self.w[e] * cell_values[c * comps + k];
                }
            }
        }
        out
    }
}

/// An imported flow field.
#[derive(Clone, Debug)]
pub struct ImportedField {
    pub mesh: TetMesh,
    /// The interpolation in use (never `Auto`).
    pub mode: Interpolation,
    frames: Vec<Frame>,
    turbulence: bool,
    /// Period \[s\] of a cyclic time series (e.g. one rotor revolution); `None` holds the last frame.
    pub period: Option<f64>,
    /// Centre point id of each dataset cell (`u32::MAX` if not split).
    cell_centre: Vec<u32>,
    n_dataset_points: usize,
    recon: Option<Recon>,
}

/// Options of [`ImportedField::load`].
#[derive(Clone, Debug, Default)]
pub struct ImportOptions {
    pub interpolation: Interpolation,
    pub names: ArrayNames,
    /// Multiply coordinates by this (e.g. 1e-3 for a mesh in millimetres); 0 means 1.
    pub length_scale: f64,
    /// Period of a cyclic time series \[s\].
    pub period: Option<f64>,
}

impl ImportedField {
    /// Loads one file (steady) or several `(time, file)` pairs sharing one mesh (time series).
    pub fn load(files: &[(f64, PathBuf)], opts: &ImportOptions) -> Result<Self, FieldError> {
        let first = files.first().ok_or_else(|| FieldError::Config("no flow-field files given".into()))?;
        let ds0 = scaled(vtk::read(&first.1)?, opts);
        let mut f = Self::build(&ds0, first.0, opts, &first.1)?;
        for (t, path) in &files[1..] {
            let ds = scaled(vtk::read(path)?, opts);
            if ds.points.len() != ds0.points.len() || ds.n_cells() != ds0.n_cells() {
                return Err(FieldError::Data {
                    path: path.clone(),
                    message: format!(
                        "time series files must share one mesh: {} points / {} cells here, {} / {} in {}",
                        ds.points.len(),
                        ds.n_cells(),
                        ds0.points.len(),
                        ds0.n_cells(),
                        first.1.display()
                    ),
                });
            }
            let frame = f.frame_from(&ds0, &ds, *t, opts, path)?;
            f.frames.push(frame);
        }
        f.frames.sort_by(|a, b| a.time.total_cmp(&b.time));
        if let Some(p) = f.period {
            let span = f.frames.last().map(|l| l.time).unwrap_or(0.0) - f.frames[0].time;
            if p <= span {
                return Err(FieldError::Config(format!(
                    "period_s = {p} must exceed the span of the time series ({span} s)"
                )));
            }
        }
        Ok(f)
    }

    /// Builds a steady field from a dataset already in memory.
    pub fn from_dataset(ds: &VtkDataset, opts: &ImportOptions) -> Result<Self, FieldError> {
        Self::build(&scaled(ds.clone(), opts), 0.0, opts, Path::new("(memory)"))
    }

    fn build(ds: &VtkDataset, time: f64, opts: &ImportOptions, path: &Path) -> Result<Self, FieldError> {
        let data_err = |m: String| FieldError::Data { path: path.to_owned(), message: m };
        let name = &opts.names.velocity;
        let has_point_u = ds.point_array(name).is_some_and(|a| a.components >= 3);
        let has_cell_u = ds.cell_array(name).is_some_and(|a| a.components >= 3);
        if !has_point_u && !has_cell_u {
            let names: Vec<&str> =
                ds.point_data.iter().chain(&ds.cell_data).map(|a| a.name.as_str()).collect();
            return Err(data_err(format!(
                "no 3-component velocity array `{name}` (arrays in the file: {})",
                names.join(", ")
            )));
        }
        let mode = match opts.interpolation {
            Interpolation::Auto if has_point_u => Interpolation::Point,
            Interpolation::Auto => Interpolation::CellPoint,
            Interpolation::Cell if !has_cell_u => {
                return Err(data_err(format!("interpolation = \"cell\" needs `{name}` as cell data")))
            }
            m => m,
        };
        let (keep_tets, rule) = match mode {
            Interpolation::Point => (true, CentreRule::VertexMean),
            _ => (false, CentreRule::Centroid),
        };
        let d = decompose(ds, keep_tets, rule);
        if d.tets.is_empty() {
            return Err(data_err(
                "the file holds no volume cells (tetrahedra, hexahedra, wedges, pyramids or polyhedra)"
                    .into(),
            ));
        }
        let centres: Vec<Vec3> = d
            .cell_centre
            .iter()
            .enumerate()
            .map(|(c, &id)| if id == u32::MAX { cell_mean(ds, c) } else { d.points[id as usize] })
            .collect();
        let needs_recon = mode != Interpolation::Cell && !has_point_u;
        let recon = needs_recon.then(|| build_recon(ds, &centres));
        let mesh = TetMesh::new(d.points, d.tets, d.tet_cell);
        let mut f = ImportedField {
            mesh,
            mode,
            frames: Vec::new(),
            turbulence: false,
            period: opts.period,
            cell_centre: d.cell_centre,
            n_dataset_points: ds.points.len(),
            recon,
        };
        let frame = f.frame_from(ds, ds, time, opts, path)?;
        f.turbulence = !frame.k.is_empty() && !frame.eps.is_empty();
        f.frames.push(frame);
        Ok(f)
    }

    /// Values of array `name` (`comps` components) at the mesh points, or per cell in `cell` mode.
    fn values(&self, geo: &VtkDataset, ds: &VtkDataset, name: &str, comps: usize) -> Option<Vec<f64>> {
        let pa = ds.point_array(name).filter(|a| a.components >= comps);
        let ca = ds.cell_array(name).filter(|a| a.components >= comps);
        let take = |a: &DataArray| -> Vec<f64> {
            (0..a.len()).flat_map(|i| a.values[i * a.components..i * a.components + comps].to_vec()).collect()
        };
        if self.mode == Interpolation::Cell {
            return ca.map(take);
        }
        let mut pv = match (pa, ca, &self.recon) {
            (Some(a), _, _) => take(a),
            (None, Some(a), Some(r)) => r.apply(&take(a), comps),
            (None, Some(a), None) => build_recon(geo, &cell_means(geo)).apply(&take(a), comps),
            (None, None, _) => return None,
        };
        let cell_vals = ca.map(take);
        pv.resize(self.mesh.points.len() * comps, 0.0);
        let _ = self.n_dataset_points;
        for (c, &cid) in self.cell_centre.iter().enumerate() {
            if cid == u32::MAX {
                continue;
            }
            let dst = cid as usize * comps;
            match (&cell_vals, self.mode) {
                (Some(cv), Interpolation::CellPoint) => {
                    pv[dst..dst + comps].copy_from_slice(&cv[c * comps..c * comps + comps]);
                }
                _ => {
                    let mut ids: Vec<u32> = geo.cell(c).to_vec();
                    ids.sort_unstable();
                    ids.dedup();
                    for k in 0..comps {
                        let s: f64 = ids.iter().map(|&i| pv[i as usize * comps + k]).sum();
                        pv[dst + k] = s / ids.len() as f64;
                    }
                }
            }
        }
        Some(pv)
    }

    fn frame_from(
        &self,
        geo: &VtkDataset,
        ds: &VtkDataset,
        time: f64,
        opts: &ImportOptions,
        path: &Path,
    ) -> Result<Frame, FieldError> {
        let n = &opts.names;
        let u = self.values(geo, ds, &n.velocity, 3).ok_or_else(|| FieldError::Data {
            path: path.to_owned(),
            message: format!("no velocity array `{}` usable with interpolation {:?}", n.velocity, self.mode),
        })?;
        let u: Vec<Vec3> = u.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
        if let Some(i) = u.iter().position(|v| !spatter_core::math::is_finite(*v)) {
            return Err(FieldError::Data {
                path: path.to_owned(),
                message: format!("velocity value {i} is not finite"),
            });
        }
        let k = self.values(geo, ds, &n.k, 1).unwrap_or_default();
        let mut eps = self.values(geo, ds, &n.epsilon, 1).unwrap_or_default();
        if eps.is_empty() && !k.is_empty() {
            if let Some(om) = self.values(geo, ds, &n.omega, 1) {
                eps = k.iter().zip(&om).map(|(k, w)| 0.09 * k * w).collect();
            }
        }
        let k = if eps.is_empty() { Vec::new() } else { k };
        if self.mode == Interpolation::Cell {
            return Ok(Frame { time, u, k, eps });
        }
        // Point values follow the mesh's own (Morton) point order.
        let m = &self.mesh;
        Ok(Frame { time, u: m.permute_points(&u), k: m.permute_points(&k), eps: m.permute_points(&eps) })
    }

    /// Number of time levels.
    pub fn n_frames(&self) -> usize {
        self.frames.len()
    }

    /// Times of the frames \[s\].
    pub fn times(&self) -> Vec<f64> {
        self.frames.iter().map(|f| f.time).collect()
    }

    /// Two frames and the weight of the second at time `t`, and 1/Δt between them (0 if steady).
    #[inline]
    fn bracket(&self, t: f64) -> (usize, usize, f64, f64) {
        let n = self.frames.len();
        if n == 1 {
            return (0, 0, 0.0, 0.0);
        }
        let t0 = self.frames[0].time;
        let tl = self.frames[n - 1].time;
        let t = match self.period {
            Some(p) => t0 + (t - t0).rem_euclid(p),
            // Held before the first frame: the field does not change there (zero ∂u/∂t).
            None if t < t0 => return (0, 0, 0.0, 0.0),
            None => t.clamp(t0, tl),
        };
        if t >= tl {
            // Only reachable with a period: between the last frame and the first one a period later.
            let p = self.period.unwrap_or(0.0);
            let dt = t0 + p - tl;
            if dt <= 0.0 {
                return (n - 1, n - 1, 0.0, 0.0);
            }
            return (n - 1, 0, (t - tl) / dt, 1.0 / dt);
        }
        let i = self.frames.partition_point(|f| f.time <= t).clamp(1, n - 1) - 1;
        let dt = self.frames[i + 1].time - self.frames[i].time;
        (i, i + 1, (t - self.frames[i].time) / dt, 1.0 / dt)
    }
}

fn scaled(mut ds: VtkDataset, opts: &ImportOptions) -> VtkDataset {
    if opts.length_scale > 0.0 && opts.length_scale != 1.0 {
        ds.points.iter_mut().for_each(|p| *p *= opts.length_scale);
    }
    ds
}

fn cell_mean(ds: &VtkDataset, c: usize) -> Vec3 {
    let ids = ds.cell(c);
    ids.iter().map(|&i| ds.points[i as usize]).sum::<Vec3>() / ids.len().max(1) as f64
}

fn cell_means(ds: &VtkDataset) -> Vec<Vec3> {
    (0..ds.n_cells()).map(|c| cell_mean(ds, c)).collect()
}

/// Weighted least-squares linear reconstruction weights at every dataset point from the cells around
/// it (weights 1/r²): φ(x_p) = a of the fit φ ≈ a + g·(x − x_p). Exact for linear fields. When the
/// cells around a point do not span 3-D (corners, edges, faces of a structured block) the stencil grows
/// to the cells around those cells; failing that, inverse-distance weights are used.
fn build_recon(ds: &VtkDataset, centres: &[Vec3]) -> Recon {
    let np = ds.points.len();
    let nc = ds.n_cells();
    // Point → cells (CSR).
    let mut count = vec![0u32; np + 1];
    let is_volume = |c: usize| super::decompose::cell_faces(ds, c).is_some();
    let vol: Vec<bool> = (0..nc).map(is_volume).collect();
    for c in 0..nc {
        if vol[c] {
            for &p in ds.cell(c) {
                count[p as usize + 1] += 1;
            }
        }
    }
    for p in 0..np {
        count[p + 1] += count[p];
    }
    let mut fill = count.clone();
    let mut p2c = vec![0u32; count[np] as usize];
    for c in 0..nc {
        if vol[c] {
            for &p in ds.cell(c) {
                p2c[fill[p as usize] as usize] = c as u32;
                fill[p as usize] += 1;
            }
        }
    }
    let cells_of = |p: usize| &p2c[count[p] as usize..count[p + 1] as usize];
    let mut r = Recon { start: vec![0], cells: Vec::new(), w: Vec::new() };
    let mut stencil: Vec<u32> = Vec::new();
    for p in 0..np {
        let xp = ds.points[p];
        stencil.clear();
        stencil.extend_from_slice(cells_of(p));
        stencil.sort_unstable();
        stencil.dedup();
        let mut weights = ls_weights(xp, &stencil, centres);
        if weights.is_none() && !stencil.is_empty() {
            let ring: Vec<u32> = stencil.clone();
            for &c in &ring {
                for &q in ds.cell(c as usize) {
                    stencil.extend_from_slice(cells_of(q as usize));
                }
            }
            stencil.sort_unstable();
            stencil.dedup();
            weights = ls_weights(xp, &stencil, centres);
        }
        let w = weights.unwrap_or_else(|| {
            let w: Vec<f64> =
                stencil.iter().map(|&c| 1.0 / (centres[c as usize] - xp).length().max(1e-300)).collect();
            let s: f64 = w.iter().sum();
            w.iter().map(|x| x / s).collect()
        });
        r.cells.extend_from_slice(&stencil);
        r.w.extend(w);
        r.start.push(r.cells.len() as u32);
    }
    r
}

/// Least-squares weights for the value at `xp`, or `None` when the stencil does not span 3-D.
fn ls_weights(xp: Vec3, stencil: &[u32], centres: &[Vec3]) -> Option<Vec<f64>> {
    if stencil.len() < 4 {
        return None;
    }
    let h = stencil.iter().map(|&c| (centres[c as usize] - xp).length()).fold(0.0, f64::max);
    if h <= 0.0 {
        return None;
    }
    // Normal equations AᵀWA with rows [1, r/h].
    let mut m = [[0.0f64; 4]; 4];
    let rows: Vec<([f64; 4], f64)> = stencil
        .iter()
        .map(|&c| {
            let d = (centres[c as usize] - xp) / h;
            ([1.0, d.x, d.y, d.z], 1.0 / d.length_squared().max(1e-12))
        })
        .collect();
    for (a, w) in &rows {
        for i in 0..4 {
            for j in 0..4 {
                m[i][j] += w * a[i] * a[j];
            }
        }
    }
    // Column 0 of the inverse: solve M z = e0.
    let z = solve4(m, [1.0, 0.0, 0.0, 0.0])?;
    Some(rows.iter().map(|(a, w)| w * (a[0] * z[0] + a[1] * z[1] + a[2] * z[2] + a[3] * z[3])).collect())
}

impl ImportedField {
    /// Point or cell-point interpolation in a steady field.
    #[inline]
    fn sample_steady(&self, loc: &super::tetmesh::Location, want_grad: bool) -> Sample {
        let f = &self.frames[0];
        let v = self.mesh.tets[loc.tet as usize];
        let mut s = Sample::default();
        for k in 0..4 {
            s.u += loc.bary[k] * f.u[v[k] as usize];
        }
        if self.turbulence {
            for k in 0..4 {
                let p = v[k] as usize;
                s.k += loc.bary[k] * f.k[p];
                s.eps += loc.bary[k] * f.eps[p];
            }
        }
        if want_grad {
            let g = self.mesh.bary_gradients(loc.tet);
            let mut m = Mat3::ZERO;
            for k in 0..4 {
                let uk = f.u[v[k] as usize];
                m.x_axis += uk * g[k].x;
                m.y_axis += uk * g[k].y;
                m.z_axis += uk * g[k].z;
            }
            s.grad = m;
        }
        s
    }
}

/// Gaussian elimination with partial pivoting; `None` when (nearly) singular.
fn solve4(mut m: [[f64; 4]; 4], mut b: [f64; 4]) -> Option<[f64; 4]> {
    let scale = (0..4).map(|i| m[i][i].abs()).fold(0.0, f64::max);
    for col in 0..4 {
        let piv = (col..4).max_by(|&a, &b| m[a][col].abs().total_cmp(&m[b][col].abs()))?;
        if m[piv][col].abs() <= 1e-9 * scale {
            return None;
        }
        m.swap(col, piv);
        b.swap(col, piv);
        for r in col + 1..4 {
            let f = m[r][col] / m[col][col];
            for c in col..4 {
                m[r][c] -= f * m[col][c];
            }
            b[r] -= f * b[col];
        }
    }
    let mut x = [0.0; 4];
    for r in (0..4).rev() {
        let s: f64 = (r + 1..4).map(|c| m[r][c] * x[c]).sum();
        x[r] = (b[r] - s) / m[r][r];
    }
    Some(x)
}

impl FlowField for ImportedField {
    #[inline]
    fn sample(&self, x: Vec3, t: f64, hint: &mut u32, want_grad: bool) -> Option<Sample> {
        let loc = match self.mesh.locate(x, hint) {
            Some(l) => l,
            None => self.mesh.extrapolate(x, *hint)?,
        };
        if self.frames.len() == 1 && self.mode != Interpolation::Cell {
            return Some(self.sample_steady(&loc, want_grad));
        }
        let (i0, i1, w1, inv_dt) = self.bracket(t);
        let w0 = 1.0 - w1;
        let (f0, f1) = (&self.frames[i0], &self.frames[i1]);
        let mut s = Sample::default();
        if self.mode == Interpolation::Cell {
            let c = self.mesh.tet_cell[loc.tet as usize] as usize;
            s.u = w0 * f0.u[c] + w1 * f1.u[c];
            s.du_dt = (f1.u[c] - f0.u[c]) * inv_dt;
            if self.turbulence {
                s.k = w0 * f0.k[c] + w1 * f1.k[c];
                s.eps = w0 * f0.eps[c] + w1 * f1.eps[c];
            }
            return Some(s);
        }
        let v = self.mesh.tets[loc.tet as usize];
        let mut u0 = Vec3::ZERO;
        let mut u1 = Vec3::ZERO;
        for k in 0..4 {
            u0 += loc.bary[k] * f0.u[v[k] as usize];
            u1 += loc.bary[k] * f1.u[v[k] as usize];
        }
        s.u = w0 * u0 + w1 * u1;
        s.du_dt = (u1 - u0) * inv_dt;
        if self.turbulence {
            for k in 0..4 {
                let p = v[k] as usize;
                s.k += loc.bary[k] * (w0 * f0.k[p] + w1 * f1.k[p]);
                s.eps += loc.bary[k] * (w0 * f0.eps[p] + w1 * f1.eps[p]);
            }
        }
        if want_grad {
            let g = self.mesh.bary_gradients(loc.tet);
            let mut m = Mat3::ZERO;
            for k in 0..4 {
                let p = v[k] as usize;
                let uk = w0 * f0.u[p] + w1 * f1.u[p];
                // Column j of the gradient: Σ_k u_k ∂λ_k/∂x_j.
                m.x_axis += uk * g[k].x;
                m.y_axis += uk * g[k].y;
                m.z_axis += uk * g[k].z;
            }
            s.grad = m;
        }
        Some(s)
    }

    fn bounds(&self) -> Option<Aabb> {
        Some(self.mesh.bounds())
    }

    fn has_turbulence(&self) -> bool {
        self.turbulence
    }

    fn tet_hint_count(&self) -> usize {
        self.mesh.tets.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::tetmesh::{kuhn_box, NONE};
    use spatter_io::vtk::cell_type as ct;

    fn lin(p: Vec3) -> Vec3 {
        Vec3::new(1.0 + 2.0 * p.x - p.y + 0.5 * p.z, -3.0 * p.x + 0.25 * p.y, 0.7 - p.z + 4.0 * p.y)
    }

    fn grad_lin() -> Mat3 {
        Mat3::from_cols(Vec3::new(2.0, -3.0, 0.0), Vec3::new(-1.0, 0.25, 4.0), Vec3::new(0.5, 0.0, -1.0))
    }

    fn tet_dataset(n: usize) -> VtkDataset {
        let (points, tets) = kuhn_box(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(2.0, 1.0, 1.5), [n, n, n], 0.3);
        let mut ds = VtkDataset { points, ..Default::default() };
        ds.cell_offsets.push(0);
        for t in tets {
            ds.connectivity.extend(t);
            ds.cell_types.push(ct::TETRA);
            ds.cell_offsets.push(ds.connectivity.len());
        }
        ds
    }

    fn hex_dataset(n: usize) -> VtkDataset {
        // A sheared structured block of hexahedra.
        let dims = [n + 1, n + 1, n + 1];
        let (cell_types, cell_offsets, connectivity) = VtkDataset::structured_cells(dims);
        let mut points = Vec::new();
        for k in 0..=n {
            for j in 0..=n {
                for i in 0..=n {
                    let (x, y, z) = (i as f64 / n as f64, j as f64 / n as f64, k as f64 / n as f64);
                    points.push(Vec3::new(x + 0.2 * y, y + 0.1 * z * z, z + 0.05 * x));
                }
            }
        }
        VtkDataset { points, cell_types, cell_offsets, connectivity, ..Default::default() }
    }

    fn random_points_inside(f: &ImportedField, n: usize) -> Vec<Vec3> {
        let b = f.mesh.bounds();
        let mut s = 99u64;
        let mut rnd = move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut out = Vec::new();
        let mut hint = NONE;
        while out.len() < n {
            let x = b.min + b.extent() * Vec3::new(rnd(), rnd(), rnd());
            if f.mesh.locate(x, &mut hint).is_some() {
                out.push(x);
            }
        }
        out
    }

    fn assert_linear_exact(f: &ImportedField) {
        let mut hint = NONE;
        for x in random_points_inside(f, 500) {
            let s = f.sample(x, 0.0, &mut hint, true).unwrap();
            assert!((s.u - lin(x)).length() < 1e-11 * (1.0 + lin(x).length()), "{x}: {} vs {}", s.u, lin(x));
            let dg = s.grad - grad_lin();
            assert!(dg.x_axis.length() + dg.y_axis.length() + dg.z_axis.length() < 1e-9, "{dg}");
        }
    }

    #[test]
    fn linear_point_data_on_tets_is_exact() {
        let mut ds = tet_dataset(5);
        let u: Vec<f64> = ds.points.iter().flat_map(|p| lin(*p).to_array()).collect();
        ds.point_data.push(DataArray { name: "U".into(), components: 3, values: u });
        let f = ImportedField::from_dataset(&ds, &ImportOptions::default()).unwrap();
        assert_eq!(f.mode, Interpolation::Point);
        assert_linear_exact(&f);
    }

    #[test]
    fn linear_cell_data_on_hexes_is_exact_with_cell_point() {
        // Cell values = field at the volume centroid (what a finite-volume code stores for a linear field);
        // vertex values reconstructed by least squares.
        let mut ds = hex_dataset(4);
        let d = decompose(&ds, false, CentreRule::Centroid);
        let u: Vec<f64> =
            (0..ds.n_cells()).flat_map(|c| lin(d.points[d.cell_centre[c] as usize]).to_array()).collect();
        ds.cell_data.push(DataArray { name: "U".into(), components: 3, values: u });
        let f = ImportedField::from_dataset(&ds, &ImportOptions::default()).unwrap();
        assert_eq!(f.mode, Interpolation::CellPoint);
        assert_linear_exact(&f);
    }

    #[test]
    fn linear_point_data_on_hexes_is_exact_and_cell_mode_is_constant() {
        let mut ds = hex_dataset(3);
        let u: Vec<f64> = ds.points.iter().flat_map(|p| lin(*p).to_array()).collect();
        ds.point_data.push(DataArray { name: "U".into(), components: 3, values: u });
        let f = ImportedField::from_dataset(&ds, &ImportOptions::default()).unwrap();
        assert_linear_exact(&f);
        // Cell mode: the value of the containing cell.
        let cv: Vec<f64> = (0..ds.n_cells()).flat_map(|c| [c as f64, 0.0, 0.0]).collect();
        ds.cell_data.push(DataArray { name: "U".into(), components: 3, values: cv });
        let opts = ImportOptions { interpolation: Interpolation::Cell, ..Default::default() };
        let f = ImportedField::from_dataset(&ds, &opts).unwrap();
        let mut h = NONE;
        let s = f.sample(Vec3::new(0.1, 0.1, 0.1), 0.0, &mut h, true).unwrap();
        assert_eq!(s.u, Vec3::ZERO);
        assert_eq!(s.grad, Mat3::ZERO);
    }

    #[test]
    fn time_series_interpolates_holds_and_cycles() {
        let dir = tempfile::tempdir().unwrap();
        let write = |name: &str, ux: f64| {
            let text = format!(
                "# vtk DataFile Version 2.0\nframe\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 float\n0 0 0 1 0 0 0 1 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\nPOINT_DATA 4\nVECTORS U float\n{ux} 0 0 {ux} 0 0 {ux} 0 0 {ux} 0 0\n"
            );
            let p = dir.path().join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        let files = vec![(1.0, write("b.vtk", 3.0)), (0.0, write("a.vtk", 1.0))];
        let x = Vec3::new(0.1, 0.1, 0.1);
        let f = ImportedField::load(&files, &ImportOptions::default()).unwrap();
        assert_eq!(f.times(), vec![0.0, 1.0], "sorted by time");
        let mut h = NONE;
        let s = f.sample(x, 0.25, &mut h, false).unwrap();
        assert!((s.u.x - 1.5).abs() < 1e-12 && (s.du_dt.x - 2.0).abs() < 1e-12);
        let after = f.sample(x, 5.0, &mut h, false).unwrap();
        assert_eq!((after.u.x, after.du_dt.x), (3.0, 0.0), "held after the last frame");
        let before = f.sample(x, -1.0, &mut h, false).unwrap();
        assert_eq!((before.u.x, before.du_dt.x), (1.0, 0.0), "held before the first, without a slope");
        // Cyclic with period 2: t = 1.5 lies halfway from the last frame back to the first (at t = 2).
        let opts = ImportOptions { period: Some(2.0), ..Default::default() };
        let f = ImportedField::load(&files, &opts).unwrap();
        assert!((f.sample(x, 1.5, &mut h, false).unwrap().u.x - 2.0).abs() < 1e-12);
        assert!((f.sample(x, 4.25, &mut h, false).unwrap().u.x - 1.5).abs() < 1e-12);
        // A period shorter than the series is refused.
        let opts = ImportOptions { period: Some(0.5), ..Default::default() };
        assert!(ImportedField::load(&files, &opts).unwrap_err().to_string().contains("period_s"));
    }

    /// Writes `text` as `name` in a fresh folder and loads it as a steady field.
    fn load_text(name: &str, text: &[u8]) -> ImportedField {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        ImportedField::load(&[(0.0, p)], &ImportOptions::default()).unwrap_or_else(|e| panic!("{e}"))
    }

    /// Two cells of a sheared structured grid (3 × 2 × 2 points, i fastest), written by hand; U = lin(x)
    /// at every point (values worked out by hand from `lin`).
    const STRUCTURED_GRID: &str = "# vtk DataFile Version 3.0
sheared block, hand-made
ASCII
DATASET STRUCTURED_GRID
DIMENSIONS 3 2 2
POINTS 12 double
0 0 0   0.5 0.02 0.03   1 0.04 0.06
0.1 0.4 0   0.6 0.42 0.03   1.1 0.44 0.06
0 0.05 0.7   0.5 0.07 0.73   1 0.09 0.76
0.1 0.45 0.7   0.6 0.47 0.73   1.1 0.49 0.76
POINT_DATA 12
VECTORS U double
1 0 0.7   1.995 -1.495 0.75   2.99 -2.99 0.8
0.8 -0.2 2.3   1.795 -1.695 2.35   2.79 -3.19 2.4
1.3 0.0125 0.2   2.295 -1.4825 0.25   3.29 -2.9775 0.3
1.1 -0.1875 1.8   2.095 -1.6825 1.85   3.09 -3.1775 1.9
CELL_DATA 2
SCALARS p float 1
LOOKUP_TABLE default
10 20
";

    /// A rectilinear grid with uneven spacing: x ∈ {0, 0.3, 1}, y ∈ {−1, 0.5}, z ∈ {2, 2.4}; U = lin(x).
    const RECTILINEAR_GRID: &str = "# vtk DataFile Version 2.0
uneven box, hand-made
ASCII
DATASET RECTILINEAR_GRID
DIMENSIONS 3 2 2
X_COORDINATES 3 float
0 0.3 1.0
Y_COORDINATES 2 float
-1 0.5
Z_COORDINATES 2 float
2 2.4
POINT_DATA 12
VECTORS U double
3 -0.25 -5.3   3.6 -1.15 -5.3   5 -3.25 -5.3
1.5 0.125 0.7   2.1 -0.775 0.7   3.5 -2.875 0.7
3.2 -0.25 -5.7   3.8 -1.15 -5.7   5.2 -3.25 -5.7
1.7 0.125 0.3   2.3 -0.775 0.3   3.7 -2.875 0.3
";

    #[test]
    fn legacy_structured_grid_is_read_and_a_linear_field_reproduced_exactly() {
        let ds = spatter_io::vtk::legacy::parse(STRUCTURED_GRID.as_bytes(), Path::new("s.vtk")).unwrap();
        ds.check(Path::new("s.vtk")).unwrap();
        // Points in file order (i fastest), two hexahedra in VTK's vertex order, cell data kept.
        assert_eq!(ds.points.len(), 12);
        assert_eq!(ds.points[4], Vec3::new(0.6, 0.42, 0.03));
        assert_eq!(ds.points[11], Vec3::new(1.1, 0.49, 0.76));
        assert_eq!(ds.cell_types, vec![ct::HEXAHEDRON; 2]);
        assert_eq!(ds.cell(0), &[0, 1, 4, 3, 6, 7, 10, 9]);
        assert_eq!(ds.cell(1), &[1, 2, 5, 4, 7, 8, 11, 10]);
        assert_eq!(ds.cell_array("p").unwrap().values, vec![10.0, 20.0]);
        // The hand values are lin(x) at the points (to the rounding of their decimal digits).
        for (i, p) in ds.points.iter().enumerate() {
            assert!((ds.point_array("U").unwrap().vec3(i) - lin(*p)).length() < 1e-14, "point {i}");
        }
        // Point interpolation on the tetrahedral split reproduces the linear field and its gradient
        // (1e-11 at 500 random points).
        let f = load_text("s.vtk", STRUCTURED_GRID.as_bytes());
        assert_eq!(f.mode, Interpolation::Point);
        assert_linear_exact(&f);
    }

    #[test]
    fn legacy_rectilinear_grid_ascii_and_binary_reproduce_a_linear_field_exactly() {
        let ds = spatter_io::vtk::legacy::parse(RECTILINEAR_GRID.as_bytes(), Path::new("r.vtk")).unwrap();
        assert_eq!(ds.points.len(), 12);
        assert_eq!(ds.points[1], Vec3::new(0.3, -1.0, 2.0));
        assert_eq!(ds.points[5], Vec3::new(1.0, 0.5, 2.0));
        assert_eq!(ds.points[10], Vec3::new(0.3, 0.5, 2.4));
        assert_eq!(ds.cell(1), &[1, 2, 5, 4, 7, 8, 11, 10]);
        for (i, p) in ds.points.iter().enumerate() {
            assert!((ds.point_array("U").unwrap().vec3(i) - lin(*p)).length() < 1e-14, "point {i}");
        }
        let f = load_text("r.vtk", RECTILINEAR_GRID.as_bytes());
        assert_linear_exact(&f);
        // The same grid as big-endian BINARY (float coordinates, double vectors): the same points (the
        // coordinates rounded to f32, as the file stores them) and again the linear field.
        let mut b: Vec<u8> =
            b"# vtk DataFile Version 2.0\nuneven box\nBINARY\nDATASET RECTILINEAR_GRID\nDIMENSIONS 3 2 2\n"
                .to_vec();
        let axes: [(&str, &[f64]); 3] = [("X", &[0.0, 0.3, 1.0]), ("Y", &[-1.0, 0.5]), ("Z", &[2.0, 2.4])];
        for (name, v) in axes {
            b.extend_from_slice(format!("{name}_COORDINATES {} float\n", v.len()).as_bytes());
            for x in v {
                b.extend_from_slice(&(*x as f32).to_be_bytes());
            }
            b.push(b'\n');
        }
        b.extend_from_slice(b"POINT_DATA 12\nVECTORS U double\n");
        let pts = ds.points.iter().map(|p| p.as_vec3().as_dvec3());
        for p in pts.clone() {
            for c in lin(p).to_array() {
                b.extend_from_slice(&c.to_be_bytes());
            }
        }
        let bin = spatter_io::vtk::legacy::parse(&b, Path::new("rb.vtk")).unwrap();
        assert_eq!(bin.points, pts.collect::<Vec<_>>());
        let f = load_text("rb.vtk", &b);
        assert_linear_exact(&f);
    }

    #[test]
    fn k_omega_fields_are_converted_to_epsilon() {
        // ε = β* k ω with β* = 0.09 (Wilcox 2006, k–ω model; OpenFOAM's kOmega/kOmegaSST betaStar),
        // converted at the mesh points, then interpolated linearly like every point value. Two tetrahedra
        // written by hand with k and ω varying per point: at each vertex ε = 0.09 k ω, at the centroid of
        // the first tetrahedron the mean of its four vertex values (1e-12 relative).
        let k = [0.5, 0.8, 1.2, 0.3, 2.0];
        let omega = [100.0, 250.0, 40.0, 900.0, 10.0];
        let text = |with_eps: bool| {
            let mut t = String::from(
                "# vtk DataFile Version 3.0\nk-omega, hand-made\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n0 0 0  1 0 0  0 1 0  0 0 1  1 1 1\nCELLS 2 10\n4 0 1 2 3\n4 1 2 3 4\nCELL_TYPES 2\n10 10\nPOINT_DATA 5\nVECTORS U double\n1 0 0 1 0 0 1 0 0 1 0 0 1 0 0\nSCALARS k double 1\nLOOKUP_TABLE default\n0.5 0.8 1.2 0.3 2.0\nSCALARS omega double 1\nLOOKUP_TABLE default\n100 250 40 900 10\n",
            );
            if with_eps {
                t.push_str("SCALARS epsilon double 1\nLOOKUP_TABLE default\n7 7 7 7 7\n");
            }
            t
        };
        let f = load_text("kw.vtk", text(false).as_bytes());
        assert!(f.has_turbulence());
        let pts = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z, Vec3::ONE];
        let eps: Vec<f64> = (0..5).map(|i| 0.09 * k[i] * omega[i]).collect();
        let mut h = NONE;
        for i in 0..5 {
            let s = f.sample(pts[i], 0.0, &mut h, false).unwrap();
            assert!((s.eps - eps[i]).abs() <= 1e-12 * eps[i], "vertex {i}: {} vs {}", s.eps, eps[i]);
            assert!((s.k - k[i]).abs() <= 1e-12 * k[i]);
        }
        let s = f.sample(Vec3::splat(0.25), 0.0, &mut h, false).unwrap();
        let mean = 0.25 * (eps[0] + eps[1] + eps[2] + eps[3]);
        assert!((s.eps - mean).abs() <= 1e-12 * mean, "centroid: {} vs {mean}", s.eps);
        // An ε array wins over ω.
        let f = load_text("ke.vtk", text(true).as_bytes());
        assert!((f.sample(Vec3::splat(0.25), 0.0, &mut h, false).unwrap().eps - 7.0).abs() < 1e-12);
    }

    #[test]
    fn missing_velocity_is_named() {
        let ds = tet_dataset(1);
        let e = ImportedField::from_dataset(&ds, &ImportOptions::default()).unwrap_err().to_string();
        assert!(e.contains("`U`"), "{e}");
    }
}
