//! VTK XML unstructured grids (`.vtu`) for particles (one vertex cell per particle) and triangle meshes,
//! with point and cell data, as ParaView reads them. [`crate::vtk::read`] reads them back.
//!
//! Arrays are stored inline in VTK's `binary` format ([`crate::vtk_xml`]).

use crate::vtk_xml::{push, write_array, write_section, write_u8_array, xml_escape, Array, Values};
use spatter_core::Vec3;
use std::fmt::Write as _;
use std::io;
use std::path::Path;

use crate::vtk::cell_type::{TRIANGLE as VTK_TRIANGLE, VERTEX as VTK_VERTEX};

/// Builder for one `.vtu` file.
#[derive(Clone, Debug)]
pub struct Vtu {
    points: Vec<f64>,
    connectivity: Vec<i64>,
    offsets: Vec<i64>,
    types: Vec<u8>,
    point_data: Vec<Array>,
    cell_data: Vec<Array>,
}

fn flatten(v: &[Vec3]) -> Vec<f64> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

impl Vtu {
    /// Particles: one vertex cell per point.
    pub fn point_cloud(positions: &[Vec3]) -> Self {
        let n = positions.len() as i64;
        Vtu {
            points: flatten(positions),
            connectivity: (0..n).collect(),
            offsets: (1..=n).collect(),
            types: vec![VTK_VERTEX; n as usize],
            point_data: Vec::new(),
            cell_data: Vec::new(),
        }
    }

    /// A triangle mesh.
    pub fn triangles(vertices: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        Vtu {
            points: flatten(vertices),
            connectivity: triangles.iter().flat_map(|t| t.map(i64::from)).collect(),
            offsets: (1..=triangles.len() as i64).map(|k| 3 * k).collect(),
            types: vec![VTK_TRIANGLE; triangles.len()],
            point_data: Vec::new(),
            cell_data: Vec::new(),
        }
    }

    /// A box of `dims` = \[n_x, n_y, n_z\] hexahedral cells of size `spacing` from the corner `origin`
    /// (a uniform grid written as an unstructured one). Cells are numbered x fastest, then y, then z, so
    /// cell data index i + n_x (j + n_y k).
    pub fn hexahedral_grid(origin: Vec3, spacing: Vec3, dims: [usize; 3]) -> Self {
        let [nx, ny, nz] = dims;
        let mut points = Vec::with_capacity(3 * (nx + 1) * (ny + 1) * (nz + 1));
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    let p = origin + spacing * Vec3::new(i as f64, j as f64, k as f64);
                    points.extend_from_slice(&p.to_array());
                }
            }
        }
        // The same hexahedra the VTK reader builds for a structured block of (n + 1)³ points.
        let (types, offsets, connectivity) =
            crate::vtk::VtkDataset::structured_cells([nx + 1, ny + 1, nz + 1]);
        Vtu {
            points,
            connectivity: connectivity.into_iter().map(i64::from).collect(),
            offsets: offsets[1..].iter().map(|&o| o as i64).collect(),
            types,
            point_data: Vec::new(),
            cell_data: Vec::new(),
        }
    }

    fn n_points(&self) -> usize {
        self.points.len() / 3
    }

    fn n_cells(&self) -> usize {
        self.types.len()
    }

    /// Adds a scalar per point. Panics if the length differs from the number of points (a programming error).
    pub fn point_scalar(mut self, name: &str, v: &[f64]) -> Self {
        let n = self.n_points();
        push(&mut self.point_data, n, name, 1, Values::F64(v.to_vec()));
        self
    }

    pub fn point_vector(mut self, name: &str, v: &[Vec3]) -> Self {
        let n = self.n_points();
        push(&mut self.point_data, n, name, 3, Values::F64(flatten(v)));
        self
    }

    pub fn point_int(mut self, name: &str, v: &[i64]) -> Self {
        let n = self.n_points();
        push(&mut self.point_data, n, name, 1, Values::I64(v.to_vec()));
        self
    }

    pub fn cell_scalar(mut self, name: &str, v: &[f64]) -> Self {
        let n = self.n_cells();
        push(&mut self.cell_data, n, name, 1, Values::F64(v.to_vec()));
        self
    }

    pub fn cell_vector(mut self, name: &str, v: &[Vec3]) -> Self {
        let n = self.n_cells();
        push(&mut self.cell_data, n, name, 3, Values::F64(flatten(v)));
        self
    }

    pub fn cell_int(mut self, name: &str, v: &[i64]) -> Self {
        let n = self.n_cells();
        push(&mut self.cell_data, n, name, 1, Values::I64(v.to_vec()));
        self
    }

    /// The file's text.
    pub fn to_xml(&self) -> String {
        let mut s = String::with_capacity(64 + self.points.len() * 12);
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str(
            "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        );
        s.push_str("  <UnstructuredGrid>\n");
        let _ = writeln!(
            s,
            "    <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
            self.n_points(),
            self.n_cells()
        );
        write_section(&mut s, "PointData", &self.point_data);
        write_section(&mut s, "CellData", &self.cell_data);
        s.push_str("      <Points>\n");
        write_array(&mut s, "Points", 3, &Values::F64(self.points.clone()));
        s.push_str("      </Points>\n      <Cells>\n");
        write_array(&mut s, "connectivity", 1, &Values::I64(self.connectivity.clone()));
        write_array(&mut s, "offsets", 1, &Values::I64(self.offsets.clone()));
        write_u8_array(&mut s, "types", &self.types);
        s.push_str("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n");
        s
    }

    /// Writes the file.
    pub fn write(&self, path: &Path) -> io::Result<()> {
        std::fs::write(path, self.to_xml())
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))
    }

    /// The text of a parallel file (`.pvtu`) joining `pieces` (paths relative to the `.pvtu`), each a
    /// `.vtu` with the arrays of this builder (names, types and components are taken from it; its own
    /// points are not written). ParaView reads the pieces as one data set.
    pub fn pvtu_xml(&self, pieces: &[String]) -> String {
        let mut s = String::with_capacity(512 + 64 * pieces.len());
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str(
            "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        );
        s.push_str("  <PUnstructuredGrid GhostLevel=\"0\">\n");
        for (tag, arrays) in [("PPointData", &self.point_data), ("PCellData", &self.cell_data)] {
            let _ = writeln!(s, "    <{tag}>");
            for a in arrays {
                let _ = writeln!(
                    s,
                    "      <PDataArray type=\"{}\" Name=\"{}\" NumberOfComponents=\"{}\"/>",
                    a.values.type_name(),
                    xml_escape(&a.name),
                    a.components
                );
            }
            let _ = writeln!(s, "    </{tag}>");
        }
        s.push_str(
            "    <PPoints>\n      <PDataArray type=\"Float64\" NumberOfComponents=\"3\"/>\n    </PPoints>\n",
        );
        for p in pieces {
            let _ = writeln!(s, "    <Piece Source=\"{}\"/>", xml_escape(p));
        }
        s.push_str("  </PUnstructuredGrid>\n</VTKFile>\n");
        s
    }

    /// Writes [`Self::pvtu_xml`] to `path`.
    pub fn write_pvtu(&self, path: &Path, pieces: &[String]) -> io::Result<()> {
        std::fs::write(path, self.pvtu_xml(pieces))
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vtk::read;

    #[test]
    fn hexahedral_grid_round_trips() {
        let g = Vtu::hexahedral_grid(Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.5, 1.0, 2.0), [2, 3, 1])
            .cell_scalar("c", &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.vtu");
        g.write(&path).unwrap();
        let back = read(&path).unwrap();
        assert_eq!(back.points.len(), 3 * 4 * 2);
        assert_eq!(back.points[back.points.len() - 1], Vec3::new(2.0, 5.0, 5.0));
        assert_eq!(back.connectivity.len(), 6 * 8);
        // Cell 1 (i = 1, j = 0, k = 0) starts at point 1 and its top face at point 1 + 12.
        assert_eq!(back.cell(1), &[1, 2, 5, 4, 13, 14, 17, 16]);
        assert_eq!(back.cell_array("c").unwrap().values, vec![0.0, 1.0, 2.0, 3.0, 4.0, 5.0]);
    }

    #[test]
    fn particles_round_trip_exactly() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("p.vtu");
        let pos = vec![Vec3::new(0.1, 0.2, 0.3), Vec3::new(-1.0, 1.0 / 3.0, 1e-9)];
        Vtu::point_cloud(&pos)
            .point_scalar("radius_m", &[0.01, 0.02])
            .point_vector("velocity_m_s", &[Vec3::X, Vec3::new(0.0, -2.5, 0.0)])
            .point_int("id", &[7, 9])
            .write(&p)
            .unwrap();
        let d = read(&p).unwrap();
        assert_eq!(d.points, pos);
        assert_eq!(d.cell_types, vec![1, 1]);
        let radius = d.point_array("radius_m").unwrap();
        assert_eq!((radius.components, &radius.values), (1, &vec![0.01, 0.02]));
        assert_eq!(d.point_array("velocity_m_s").unwrap().values, vec![1.0, 0.0, 0.0, 0.0, -2.5, 0.0]);
        assert_eq!(d.point_array("id").unwrap().values, vec![7.0, 9.0]);
    }

    /// A `.pvtu` names every piece and declares the pieces' arrays with their types and components (VTK's
    /// own reader joins them in `tests/vtk_reader.rs`).
    #[test]
    fn pvtu_joins_pieces() {
        let dir = tempfile::tempdir().unwrap();
        let piece = |pos: &[Vec3], ids: &[i64]| {
            Vtu::point_cloud(pos).point_scalar("rho", &vec![1000.0; pos.len()]).point_int("id", ids)
        };
        let a = piece(&[Vec3::ZERO, Vec3::X], &[0, 1]);
        let b = piece(&[Vec3::Y], &[2]);
        a.write(&dir.path().join("p_r0000.vtu")).unwrap();
        b.write(&dir.path().join("p_r0001.vtu")).unwrap();
        let pieces = vec!["p_r0000.vtu".to_string(), "p_r0001.vtu".to_string()];
        let path = dir.path().join("p.pvtu");
        a.write_pvtu(&path, &pieces).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("<PDataArray type=\"Float64\" Name=\"rho\" NumberOfComponents=\"1\"/>"));
        assert!(text.contains("<PDataArray type=\"Int64\" Name=\"id\" NumberOfComponents=\"1\"/>"));
        assert_eq!(text.matches("<Piece Source=").count(), 2);
    }

    #[test]
    fn mesh_round_trip_and_corruption_is_detected() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.vtu");
        let m = spatter_core::mesh::TriMesh::rectangle(1.0, 1.0, 0.0, 1, 1);
        Vtu::triangles(&m.vertices, &m.triangles).cell_scalar("impacts", &[3.0, 4.0]).write(&p).unwrap();
        let d = read(&p).unwrap();
        assert_eq!(d.connectivity, vec![0, 1, 3, 0, 3, 2]);
        assert_eq!(d.cell_offsets, vec![0, 3, 6]);
        assert_eq!(d.cell_array("impacts").unwrap().values, vec![3.0, 4.0]);
        let text =
            std::fs::read_to_string(&p).unwrap().replace("NumberOfPoints=\"4\"", "NumberOfPoints=\"5\"");
        std::fs::write(&p, text).unwrap();
        assert!(read(&p).is_err());
        std::fs::write(&p, "<VTKFile type=\"UnstructuredGrid\" header_type=\"UInt64\"><Piece></VTKFile>")
            .unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("m.vtu"), "{e}");
    }
}
