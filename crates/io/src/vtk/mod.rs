//! Reading CFD results written as VTK files.
//!
//! * legacy `.vtk` (`# vtk DataFile Version 2.0 … 5.1`, ASCII or big-endian BINARY) as written by
//!   OpenFOAM's `foamToVTK -legacy`: `UNSTRUCTURED_GRID`, `STRUCTURED_GRID`, `RECTILINEAR_GRID`,
//!   `STRUCTURED_POINTS`; attributes `SCALARS`, `VECTORS`, `NORMALS`, `TENSORS`, `FIELD`;
//! * XML `.vtu`, `.vts`, `.vtr`, `.vti` as written by ParaView and by `foamToVTK`: `ascii`, inline
//!   `binary` (base64) and `appended` (raw or base64) data, UInt32 or UInt64 headers, zlib compression,
//!   polyhedral cells (`faces`/`faceoffsets`);
//! * time series as ParaView `.pvd` collections or `.series` JSON files ([`series`]).
//!
//! Everything is converted into one [`VtkDataset`]: points, cells (structured grids become hexahedra)
//! and named point/cell arrays in `f64`.

pub mod legacy;
pub mod series;
pub mod xml;

use spatter_core::Vec3;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// VTK cell type ids (VTK `vtkCellType.h`).
pub mod cell_type {
    pub const VERTEX: u8 = 1;
    pub const LINE: u8 = 3;
    pub const TRIANGLE: u8 = 5;
    pub const POLYGON: u8 = 7;
    pub const QUAD: u8 = 9;
    pub const TETRA: u8 = 10;
    pub const VOXEL: u8 = 11;
    pub const HEXAHEDRON: u8 = 12;
    pub const WEDGE: u8 = 13;
    pub const PYRAMID: u8 = 14;
    pub const POLYHEDRON: u8 = 42;
}

/// Why a VTK file could not be used. Every variant names the file.
#[derive(Debug, Error)]
pub enum VtkError {
    #[error("VTK file {path}: cannot read it: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("VTK file {path}: {message}")]
    Format { path: PathBuf, message: String },
    #[error("VTK file {path}: unsupported: {message}")]
    Unsupported { path: PathBuf, message: String },
}

impl VtkError {
    pub(crate) fn format(path: &Path, message: impl Into<String>) -> Self {
        VtkError::Format { path: path.to_owned(), message: message.into() }
    }
    pub(crate) fn unsupported(path: &Path, message: impl Into<String>) -> Self {
        VtkError::Unsupported { path: path.to_owned(), message: message.into() }
    }
}

/// A named array with `components` values per tuple.
#[derive(Clone, Debug, PartialEq)]
pub struct DataArray {
    pub name: String,
    pub components: usize,
    pub values: Vec<f64>,
}

impl DataArray {
    /// Number of tuples.
    pub fn len(&self) -> usize {
        self.values.len() / self.components.max(1)
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Tuple `i` as a vector (the first three components; missing ones are 0).
    pub fn vec3(&self, i: usize) -> Vec3 {
        let c = self.components;
        let v = &self.values[i * c..i * c + c];
        Vec3::new(v[0], if c > 1 { v[1] } else { 0.0 }, if c > 2 { v[2] } else { 0.0 })
    }
}

/// An unstructured volume mesh with data, the common form of every supported file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VtkDataset {
    pub points: Vec<Vec3>,
    /// VTK cell type of each cell.
    pub cell_types: Vec<u8>,
    /// `cell_offsets[i]..cell_offsets[i+1]` indexes `connectivity` for cell i (length = cells + 1).
    pub cell_offsets: Vec<usize>,
    pub connectivity: Vec<u32>,
    /// For polyhedral cells: the VTK face stream `[n_faces, n_0, ids…, n_1, ids…]` of each cell (empty
    /// for other cells). Either empty or one entry per cell.
    pub poly_faces: Vec<Vec<u32>>,
    pub point_data: Vec<DataArray>,
    pub cell_data: Vec<DataArray>,
}

impl VtkDataset {
    pub fn n_cells(&self) -> usize {
        self.cell_types.len()
    }

    /// Point ids of cell `i`.
    pub fn cell(&self, i: usize) -> &[u32] {
        &self.connectivity[self.cell_offsets[i]..self.cell_offsets[i + 1]]
    }

    pub fn point_array(&self, name: &str) -> Option<&DataArray> {
        self.point_data.iter().find(|a| a.name == name)
    }

    pub fn cell_array(&self, name: &str) -> Option<&DataArray> {
        self.cell_data.iter().find(|a| a.name == name)
    }

    /// Checks sizes and indices; `path` names the file in the error.
    pub fn check(&self, path: &Path) -> Result<(), VtkError> {
        let n = self.points.len();
        if self.cell_offsets.len() != self.cell_types.len() + 1 {
            return Err(VtkError::format(path, "cell offsets and cell types disagree in length"));
        }
        if let Some(&bad) = self.connectivity.iter().find(|&&i| i as usize >= n) {
            return Err(VtkError::format(
                path,
                format!("a cell refers to point {bad}, but there are {n} points"),
            ));
        }
        if let Some(i) = self.points.iter().position(|p| !spatter_core::math::is_finite(*p)) {
            return Err(VtkError::format(path, format!("point {i} has a non-finite coordinate")));
        }
        for a in &self.point_data {
            if a.values.len() != n * a.components {
                return Err(VtkError::format(
                    path,
                    format!(
                        "point array `{}` has {} values, expected {} × {}",
                        a.name,
                        a.values.len(),
                        n,
                        a.components
                    ),
                ));
            }
        }
        let nc = self.n_cells();
        for a in &self.cell_data {
            if a.values.len() != nc * a.components {
                return Err(VtkError::format(
                    path,
                    format!(
                        "cell array `{}` has {} values, expected {} × {}",
                        a.name,
                        a.values.len(),
                        nc,
                        a.components
                    ),
                ));
            }
        }
        if !self.poly_faces.is_empty() && self.poly_faces.len() != nc {
            return Err(VtkError::format(path, "polyhedron face lists do not match the cell count"));
        }
        for c in 0..nc {
            if self.cell_types[c] == cell_type::POLYHEDRON {
                let stream = self.poly_faces.get(c).map(Vec::as_slice).unwrap_or(&[]);
                check_face_stream(stream, n).map_err(|m| VtkError::format(path, format!("cell {c}: {m}")))?;
            }
        }
        Ok(())
    }

    /// Hexahedral cells of a structured block of `dims` points (x fastest), as VTK hexahedra.
    pub fn structured_cells(dims: [usize; 3]) -> (Vec<u8>, Vec<usize>, Vec<u32>) {
        let [nx, ny, nz] = dims;
        let (cx, cy, cz) = (nx.saturating_sub(1), ny.saturating_sub(1), nz.saturating_sub(1));
        let id = |i: usize, j: usize, k: usize| (i + nx * (j + ny * k)) as u32;
        let n = cx * cy * cz;
        let mut conn = Vec::with_capacity(8 * n);
        for k in 0..cz {
            for j in 0..cy {
                for i in 0..cx {
                    conn.extend_from_slice(&[
                        id(i, j, k),
                        id(i + 1, j, k),
                        id(i + 1, j + 1, k),
                        id(i, j + 1, k),
                        id(i, j, k + 1),
                        id(i + 1, j, k + 1),
                        id(i + 1, j + 1, k + 1),
                        id(i, j + 1, k + 1),
                    ]);
                }
            }
        }
        (vec![cell_type::HEXAHEDRON; n], (0..=n).map(|c| 8 * c).collect(), conn)
    }
}

/// Checks a polyhedron's face stream `[n_faces, n_0, ids…, n_1, ids…]`: at least one face, every face
/// with at least three points, the lengths adding up to the stream's length exactly, and every point id
/// below `n_points`.
fn check_face_stream(s: &[u32], n_points: usize) -> Result<(), String> {
    let Some(&nf) = s.first() else {
        return Err("polyhedron without a face stream".into());
    };
    if nf == 0 {
        return Err("polyhedron with 0 faces".into());
    }
    let mut pos = 1;
    for f in 0..nf as usize {
        let Some(&len) = s.get(pos) else {
            return Err(format!("polyhedron face stream ends after {f} of {nf} faces ({} values)", s.len()));
        };
        let len = len as usize;
        if len < 3 {
            return Err(format!("polyhedron face {f} has {len} points; a face needs at least 3"));
        }
        let Some(ids) = s.get(pos + 1..pos + 1 + len) else {
            return Err(format!(
                "polyhedron face {f} announces {len} points but the face stream ends after {} values",
                s.len()
            ));
        };
        if let Some(&bad) = ids.iter().find(|&&i| i as usize >= n_points) {
            return Err(format!(
                "polyhedron face {f} refers to point {bad}, but there are {n_points} points"
            ));
        }
        pos += 1 + len;
    }
    if pos != s.len() {
        return Err(format!("polyhedron face stream has {} values, its {nf} faces use {pos}", s.len()));
    }
    Ok(())
}

/// Reads a VTK file by extension: `.vtk` (legacy), `.vtu`, `.vts`, `.vtr`, `.vti` (XML).
pub fn read(path: &Path) -> Result<VtkDataset, VtkError> {
    let bytes = std::fs::read(path).map_err(|source| VtkError::Io { path: path.to_owned(), source })?;
    let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    let ds = match ext.as_deref() {
        Some("vtk") => legacy::parse(&bytes, path)?,
        Some("vtu" | "vts" | "vtr" | "vti") => xml::parse(&bytes, path)?,
        _ => {
            return Err(VtkError::unsupported(
                path,
                "unknown extension; expected .vtk (legacy) or .vtu/.vts/.vtr/.vti (XML)",
            ))
        }
    };
    ds.check(path)?;
    Ok(ds)
}

/// The points of a structured lattice of `dims` points, x fastest then y then z (VTK's order), placed by `f(i, j, k)`.
pub(crate) fn lattice(dims: [usize; 3], f: impl Fn(usize, usize, usize) -> Vec3) -> Vec<Vec3> {
    let mut v = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                v.push(f(i, j, k));
            }
        }
    }
    v
}
