//! Cell faces of the VTK cell types and the decomposition of a [`VtkDataset`] into a conforming
//! tetrahedral mesh (see [`super::tetmesh`] for the rule).

use spatter_core::Vec3;
use spatter_io::vtk::{cell_type as ct, VtkDataset};

/// Face lists (local vertex ids) of the linear VTK cells (VTK `vtkTetra`, `vtkHexahedron`, `vtkWedge`,
/// `vtkPyramid` face tables). Orientation does not matter here.
fn local_faces(t: u8) -> Option<&'static [&'static [usize]]> {
    const TET: &[&[usize]] = &[&[0, 1, 3], &[1, 2, 3], &[2, 0, 3], &[0, 2, 1]];
    const HEX: &[&[usize]] =
        &[&[0, 4, 7, 3], &[1, 2, 6, 5], &[0, 1, 5, 4], &[3, 7, 6, 2], &[0, 3, 2, 1], &[4, 5, 6, 7]];
    const WEDGE: &[&[usize]] = &[&[0, 1, 2], &[3, 5, 4], &[0, 3, 4, 1], &[1, 4, 5, 2], &[2, 5, 3, 0]];
    const PYR: &[&[usize]] = &[&[0, 3, 2, 1], &[0, 1, 4], &[1, 2, 4], &[2, 3, 4], &[3, 0, 4]];
    match t {
        ct::TETRA => Some(TET),
        ct::HEXAHEDRON | ct::VOXEL => Some(HEX),
        ct::WEDGE => Some(WEDGE),
        ct::PYRAMID => Some(PYR),
        _ => None,
    }
}

/// The faces of cell `c` as polygons of global point ids (`None` for non-volume cells).
pub fn cell_faces(ds: &VtkDataset, c: usize) -> Option<Vec<Vec<u32>>> {
    let t = ds.cell_types[c];
    let ids = ds.cell(c);
    if t == ct::POLYHEDRON {
        let s = ds.poly_faces.get(c)?;
        let nf = *s.first()? as usize;
        let mut out = Vec::with_capacity(nf);
        let mut pos = 1;
        for _ in 0..nf {
            let n = *s.get(pos)? as usize;
            out.push(s.get(pos + 1..pos + 1 + n)?.to_vec());
            pos += 1 + n;
        }
        return Some(out);
    }
    let faces = local_faces(t)?;
    // VTK_VOXEL orders its corners lexicographically; map to hexahedron order.
    let map: [usize; 8] = if t == ct::VOXEL { [0, 1, 3, 2, 4, 5, 7, 6] } else { [0, 1, 2, 3, 4, 5, 6, 7] };
    let need = faces.iter().flat_map(|f| f.iter()).copied().max().unwrap_or(0) + 1;
    if ids.len() < need {
        return None;
    }
    Some(faces.iter().map(|f| f.iter().map(|&k| ids[map[k]]).collect()).collect())
}

/// Fan triangulation of a polygon from its vertex with the smallest id, dropping collapsed triangles.
pub fn triangulate(face: &[u32], out: &mut Vec<[u32; 3]>) {
    let n = face.len();
    if n < 3 {
        return;
    }
    let s = (0..n).min_by_key(|&i| face[i]).unwrap_or(0);
    for k in 1..n - 1 {
        let (a, b, c) = (face[s], face[(s + k) % n], face[(s + k + 1) % n]);
        if a != b && b != c && a != c {
            out.push([a, b, c]);
        }
    }
}

/// Where the centre point of split cells goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CentreRule {
    /// Mean of the cell's vertices (a linear field's value there is the mean of the vertex values).
    VertexMean,
    /// Volume centroid (where a finite-volume cell value lives).
    Centroid,
}

/// Output of [`decompose`].
pub struct Decomposition {
    /// Dataset points followed by one centre point per split cell.
    pub points: Vec<Vec3>,
    pub tets: Vec<[u32; 4]>,
    pub tet_cell: Vec<u32>,
    /// Centre point id of each cell, or `u32::MAX` when the cell was kept as one tetrahedron or is not
    /// a volume cell.
    pub cell_centre: Vec<u32>,
    /// Number of volume cells used.
    pub volume_cells: usize,
}

/// Decomposes every volume cell. Tetrahedra are kept whole when `keep_tets`; every other cell (and
/// every tetrahedron otherwise) is split around a centre point placed by `rule`.
pub fn decompose(ds: &VtkDataset, keep_tets: bool, rule: CentreRule) -> Decomposition {
    let mut points = ds.points.clone();
    let mut tets = Vec::new();
    let mut tet_cell = Vec::new();
    let mut cell_centre = vec![u32::MAX; ds.n_cells()];
    let mut tris = Vec::new();
    let mut volume_cells = 0;
    for c in 0..ds.n_cells() {
        let Some(faces) = cell_faces(ds, c) else { continue };
        volume_cells += 1;
        let ids = ds.cell(c);
        if keep_tets && ds.cell_types[c] == ct::TETRA {
            let t = [ids[0], ids[1], ids[2], ids[3]];
            if tet_volume(&points, t).abs() > 0.0 {
                tets.push(t);
                tet_cell.push(c as u32);
            }
            continue;
        }
        tris.clear();
        for f in &faces {
            triangulate(f, &mut tris);
        }
        let mut uniq: Vec<u32> = faces.iter().flatten().copied().collect();
        uniq.sort_unstable();
        uniq.dedup();
        let mean = uniq.iter().map(|&i| points[i as usize]).sum::<Vec3>() / uniq.len().max(1) as f64;
        let centre = match rule {
            CentreRule::VertexMean => mean,
            CentreRule::Centroid => {
                let (mut v, mut m) = (0.0, Vec3::ZERO);
                for t in &tris {
                    let [a, b, cc] = t.map(|i| points[i as usize]);
                    let vol = ((b - a).dot((cc - a).cross(mean - a)) / 6.0).abs();
                    v += vol;
                    m += vol * (a + b + cc + mean) * 0.25;
                }
                if v > 0.0 {
                    m / v
                } else {
                    mean
                }
            }
        };
        let cid = points.len() as u32;
        points.push(centre);
        cell_centre[c] = cid;
        let scale = uniq.iter().map(|&i| (points[i as usize] - centre).length()).fold(0.0, f64::max);
        let tiny = 1e-12 * scale * scale * scale;
        for t in &tris {
            let tet = [cid, t[0], t[1], t[2]];
            if tet_volume(&points, tet).abs() > tiny {
                tets.push(tet);
                tet_cell.push(c as u32);
            }
        }
    }
    Decomposition { points, tets, tet_cell, cell_centre, volume_cells }
}

fn tet_volume(p: &[Vec3], t: [u32; 4]) -> f64 {
    let [a, b, c, d] = t.map(|i| p[i as usize]);
    (b - a).dot((c - a).cross(d - a)) / 6.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::tetmesh::TetMesh;

    /// Two hexahedra side by side plus a wedge on top of the first, as a VTK dataset.
    fn mixed() -> VtkDataset {
        let mut ds = VtkDataset::default();
        for k in 0..2 {
            for j in 0..2 {
                for i in 0..3 {
                    ds.points.push(Vec3::new(i as f64, j as f64, k as f64));
                }
            }
        }
        let id = |i: u32, j: u32, k: u32| i + 3 * (j + 2 * k);
        ds.points.push(Vec3::new(0.0, 0.0, 2.0)); // 12
        ds.points.push(Vec3::new(0.0, 1.0, 2.0)); // 13
        let hex = |i: u32| {
            [
                id(i, 0, 0),
                id(i + 1, 0, 0),
                id(i + 1, 1, 0),
                id(i, 1, 0),
                id(i, 0, 1),
                id(i + 1, 0, 1),
                id(i + 1, 1, 1),
                id(i, 1, 1),
            ]
        };
        ds.connectivity.extend(hex(0));
        ds.connectivity.extend(hex(1));
        // Wedge: bottom triangle (0,0,1),(1,0,1),(0,0,2) and top (0,1,1),(1,1,1),(0,1,2).
        ds.connectivity.extend([id(0, 0, 1), id(1, 0, 1), 12, id(0, 1, 1), id(1, 1, 1), 13]);
        ds.cell_types = vec![ct::HEXAHEDRON, ct::HEXAHEDRON, ct::WEDGE];
        ds.cell_offsets = vec![0, 8, 16, 22];
        ds
    }

    #[test]
    fn mixed_cells_decompose_conformingly() {
        let ds = mixed();
        let d = decompose(&ds, true, CentreRule::Centroid);
        assert_eq!(d.volume_cells, 3);
        assert_eq!(d.tets.len(), 12 + 12 + 8);
        let m = TetMesh::new(d.points.clone(), d.tets.clone(), d.tet_cell.clone());
        let vol: f64 = (0..m.tets.len()).map(|t| m.volume(t)).sum();
        assert!((vol - 2.5).abs() < 1e-12, "{vol}");
        // Boundary: 10 outer quads of the hex pair minus the 1 covered by the wedge's quad face → the
        // wedge adds 2 triangles + 2 quads exposed: (10 − 1)·2 + 2 + 2·2 = 24 triangles.
        assert_eq!(m.boundary_faces(), 24);
        // Centroid of the first hexahedron is its centre.
        assert!((d.points[d.cell_centre[0] as usize] - Vec3::new(0.5, 0.5, 0.5)).length() < 1e-14);
    }
}
