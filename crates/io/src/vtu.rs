//! VTK XML unstructured grids (`.vtu`) for particles (one vertex cell per particle) and triangle meshes,
//! with point and cell data, as ParaView reads them; and a strict reader for the files written here.
//!
//! Arrays are stored inline in VTK's `binary` format ([`crate::vtk_xml`]).

use crate::vtk_xml::{bad, decode, push, write_array, write_section, write_u8_array, Array, Values};
use quick_xml::events::Event;
use spatter_core::Vec3;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io;
use std::path::Path;

const VTK_VERTEX: u8 = 1;
const VTK_TRIANGLE: u8 = 5;

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
}

/// Contents of a `.vtu` file read back by [`read`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VtuData {
    pub points: Vec<Vec3>,
    pub connectivity: Vec<i64>,
    pub offsets: Vec<i64>,
    pub types: Vec<u8>,
    /// Name → (components, values as f64).
    pub point_data: BTreeMap<String, (usize, Vec<f64>)>,
    pub cell_data: BTreeMap<String, (usize, Vec<f64>)>,
}

/// Reads a `.vtu` written in the inline binary form used by [`Vtu::write`], checking the XML is well formed
/// and that every array's length agrees with the piece's point and cell counts.
pub fn read(path: &Path) -> io::Result<VtuData> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
    let mut reader = quick_xml::Reader::from_str(&text);
    reader.config_mut().check_end_names = true;
    let mut data = VtuData::default();
    let (mut n_points, mut n_cells) = (None::<usize>, None::<usize>);
    let mut section = String::new();
    let mut current: Option<(String, String, usize, String)> = None; // (type, name, components, format)
    let mut saw_root = false;
    loop {
        match reader.read_event().map_err(|e| bad(path, format!("malformed XML: {e}")))? {
            Event::Start(e) => {
                let tag = String::from_utf8_lossy(e.name().as_ref()).into_owned();
                let attr = |key: &str| -> Option<String> {
                    e.attributes()
                        .flatten()
                        .find(|a| a.key.as_ref() == key.as_bytes())
                        .map(|a| String::from_utf8_lossy(&a.value).into_owned())
                };
                match tag.as_str() {
                    "VTKFile" => {
                        saw_root = true;
                        if attr("type").as_deref() != Some("UnstructuredGrid") {
                            return Err(bad(path, "not an UnstructuredGrid VTKFile"));
                        }
                        if attr("header_type").as_deref() != Some("UInt64") {
                            return Err(bad(path, "only header_type=\"UInt64\" is read"));
                        }
                    }
                    "Piece" => {
                        n_points = attr("NumberOfPoints").and_then(|v| v.parse().ok());
                        n_cells = attr("NumberOfCells").and_then(|v| v.parse().ok());
                    }
                    "PointData" | "CellData" | "Points" | "Cells" => section = tag.clone(),
                    "DataArray" => {
                        let comps = attr("NumberOfComponents").and_then(|v| v.parse().ok()).unwrap_or(1);
                        current = Some((
                            attr("type").unwrap_or_default(),
                            attr("Name").unwrap_or_default(),
                            comps,
                            attr("format").unwrap_or_default(),
                        ));
                    }
                    _ => {}
                }
            }
            Event::Text(t) => {
                if let Some((ty, name, comps, format)) = current.take() {
                    let values = decode(path, &ty, &name, &format, t.as_ref())?;
                    match section.as_str() {
                        "Points" => {
                            data.points =
                                values.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
                        }
                        "Cells" => match name.as_str() {
                            "connectivity" => data.connectivity = values.iter().map(|&v| v as i64).collect(),
                            "offsets" => data.offsets = values.iter().map(|&v| v as i64).collect(),
                            "types" => data.types = values.iter().map(|&v| v as u8).collect(),
                            _ => {}
                        },
                        "PointData" => {
                            data.point_data.insert(name, (comps, values));
                        }
                        "CellData" => {
                            data.cell_data.insert(name, (comps, values));
                        }
                        _ => {}
                    }
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if !saw_root {
        return Err(bad(path, "no VTKFile element"));
    }
    let np = n_points.ok_or_else(|| bad(path, "Piece lacks NumberOfPoints"))?;
    let nc = n_cells.ok_or_else(|| bad(path, "Piece lacks NumberOfCells"))?;
    if data.points.len() != np || data.types.len() != nc || data.offsets.len() != nc {
        return Err(bad(path, "array lengths disagree with NumberOfPoints/NumberOfCells"));
    }
    if data.offsets.last().copied().unwrap_or(0) as usize != data.connectivity.len() {
        return Err(bad(path, "last offset does not match the connectivity length"));
    }
    if data.connectivity.iter().any(|&c| c < 0 || c as usize >= np) {
        return Err(bad(path, "connectivity refers to a point that does not exist"));
    }
    for (name, (c, v)) in &data.point_data {
        if v.len() != c * np {
            return Err(bad(path, format!("point array `{name}` has {} values for {np} points", v.len())));
        }
    }
    for (name, (c, v)) in &data.cell_data {
        if v.len() != c * nc {
            return Err(bad(path, format!("cell array `{name}` has {} values for {nc} cells", v.len())));
        }
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(d.types, vec![1, 1]);
        assert_eq!(d.point_data["radius_m"], (1, vec![0.01, 0.02]));
        assert_eq!(d.point_data["velocity_m_s"].1, vec![1.0, 0.0, 0.0, 0.0, -2.5, 0.0]);
        assert_eq!(d.point_data["id"].1, vec![7.0, 9.0]);
    }

    #[test]
    fn mesh_round_trip_and_corruption_is_detected() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.vtu");
        let m = spatter_core::mesh::TriMesh::rectangle(1.0, 1.0, 0.0, 1, 1);
        Vtu::triangles(&m.vertices, &m.triangles).cell_scalar("impacts", &[3.0, 4.0]).write(&p).unwrap();
        let d = read(&p).unwrap();
        assert_eq!(d.connectivity, vec![0, 1, 3, 0, 3, 2]);
        assert_eq!(d.offsets, vec![3, 6]);
        assert_eq!(d.cell_data["impacts"].1, vec![3.0, 4.0]);
        let text =
            std::fs::read_to_string(&p).unwrap().replace("NumberOfPoints=\"4\"", "NumberOfPoints=\"5\"");
        std::fs::write(&p, text).unwrap();
        assert!(read(&p).is_err());
        std::fs::write(&p, "<VTKFile type=\"UnstructuredGrid\" header_type=\"UInt64\"><Piece></VTKFile>")
            .unwrap();
        assert!(read(&p).unwrap_err().to_string().contains("malformed XML"));
    }
}
