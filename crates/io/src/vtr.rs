//! VTK XML rectilinear grids (`.vtr`): structured fields on a grid given by its face coordinates per axis
//! (uniform or stretched), with cell and point data, as ParaView reads them; and a strict reader for the
//! files written here.
//!
//! Cell (i, j, k) of an `nx × ny × nz` grid is entry `i + nx·(j + ny·k)` of every cell array (x fastest,
//! VTK's order); point arrays have `(nx + 1)(ny + 1)(nz + 1)` entries in the same order. Arrays are
//! stored inline in VTK's `binary` format like the `.vtu` files.

use crate::vtk_xml::{bad, decode, push, write_array, write_section, Array, Values};
use quick_xml::events::Event;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io;
use std::path::Path;

/// Builder for one `.vtr` file.
#[derive(Clone, Debug)]
pub struct Vtr {
    coords: [Vec<f64>; 3],
    point_data: Vec<Array>,
    cell_data: Vec<Array>,
}

/// Checks that `c` holds at least two finite, strictly increasing face coordinates.
fn check_axis(name: &str, c: &[f64]) -> Result<(), String> {
    if c.len() < 2 {
        return Err(format!("axis {name} needs at least 2 face coordinates, got {}", c.len()));
    }
    if c.windows(2).any(|w| w[1] <= w[0] || !w[0].is_finite() || !w[1].is_finite()) {
        return Err(format!("axis {name}: face coordinates must be finite and increase strictly"));
    }
    Ok(())
}

impl Vtr {
    /// A grid with face coordinates `x`, `y`, `z` \[m\] (each strictly increasing, at least two values).
    pub fn new(x: &[f64], y: &[f64], z: &[f64]) -> io::Result<Self> {
        for (name, c) in [("x", x), ("y", y), ("z", z)] {
            check_axis(name, c).map_err(|e| io::Error::new(io::ErrorKind::InvalidInput, e))?;
        }
        Ok(Vtr {
            coords: [x.to_vec(), y.to_vec(), z.to_vec()],
            point_data: Vec::new(),
            cell_data: Vec::new(),
        })
    }

    /// Cells per axis.
    pub fn cells_per_axis(&self) -> [usize; 3] {
        [0, 1, 2].map(|a| self.coords[a].len() - 1)
    }

    fn n_cells(&self) -> usize {
        self.cells_per_axis().iter().product()
    }

    fn n_points(&self) -> usize {
        self.coords.iter().map(Vec::len).product()
    }

    /// Adds a scalar per cell. Panics if the length is not the number of cells (a programming error).
    pub fn cell_scalar(mut self, name: &str, v: &[f64]) -> Self {
        let n = self.n_cells();
        push(&mut self.cell_data, n, name, 1, Values::F64(v.to_vec()));
        self
    }

    /// Adds a vector per cell.
    pub fn cell_vector(mut self, name: &str, v: &[[f64; 3]]) -> Self {
        let n = self.n_cells();
        push(&mut self.cell_data, n, name, 3, Values::F64(v.iter().flatten().copied().collect()));
        self
    }

    /// Adds an integer per cell.
    pub fn cell_int(mut self, name: &str, v: &[i64]) -> Self {
        let n = self.n_cells();
        push(&mut self.cell_data, n, name, 1, Values::I64(v.to_vec()));
        self
    }

    /// Adds a scalar per grid point.
    pub fn point_scalar(mut self, name: &str, v: &[f64]) -> Self {
        let n = self.n_points();
        push(&mut self.point_data, n, name, 1, Values::F64(v.to_vec()));
        self
    }

    /// The file's text.
    pub fn to_xml(&self) -> String {
        let [nx, ny, nz] = self.cells_per_axis();
        let extent = format!("0 {nx} 0 {ny} 0 {nz}");
        let mut s = String::with_capacity(256 + self.n_cells() * 40);
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str(
            "<VTKFile type=\"RectilinearGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n",
        );
        let _ = writeln!(s, "  <RectilinearGrid WholeExtent=\"{extent}\">");
        let _ = writeln!(s, "    <Piece Extent=\"{extent}\">");
        write_section(&mut s, "PointData", &self.point_data);
        write_section(&mut s, "CellData", &self.cell_data);
        s.push_str("      <Coordinates>\n");
        for (name, c) in ["x", "y", "z"].iter().zip(&self.coords) {
            write_array(&mut s, name, 1, &Values::F64(c.clone()));
        }
        s.push_str("      </Coordinates>\n    </Piece>\n  </RectilinearGrid>\n</VTKFile>\n");
        s
    }

    /// Writes the file.
    pub fn write(&self, path: &Path) -> io::Result<()> {
        std::fs::write(path, self.to_xml())
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))
    }
}

/// Contents of a `.vtr` file read back by [`read`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct VtrData {
    /// Face coordinates per axis.
    pub coords: [Vec<f64>; 3],
    /// Name → (components, values as f64).
    pub point_data: BTreeMap<String, (usize, Vec<f64>)>,
    pub cell_data: BTreeMap<String, (usize, Vec<f64>)>,
}

fn parse_extent(path: &Path, text: Option<String>) -> io::Result<[usize; 3]> {
    let text = text.ok_or_else(|| bad(path, "Piece lacks Extent"))?;
    let v: Vec<i64> = text.split_whitespace().filter_map(|t| t.parse().ok()).collect();
    if v.len() != 6 || (0..3).any(|a| v[2 * a] != 0 || v[2 * a + 1] < 1) {
        return Err(bad(path, format!("Extent `{text}` is not `0 nx 0 ny 0 nz` with n ≥ 1")));
    }
    Ok([v[1] as usize, v[3] as usize, v[5] as usize])
}

/// Reads a `.vtr` written by [`Vtr::write`], checking the XML is well formed and every array's length
/// agrees with the extent.
pub fn read(path: &Path) -> io::Result<VtrData> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
    let mut reader = quick_xml::Reader::from_str(&text);
    reader.config_mut().check_end_names = true;
    let mut data = VtrData::default();
    let mut extent = None;
    let mut section = String::new();
    let mut current: Option<(String, String, usize, String)> = None;
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
                        if attr("type").as_deref() != Some("RectilinearGrid") {
                            return Err(bad(path, "not a RectilinearGrid VTKFile"));
                        }
                        if attr("header_type").as_deref() != Some("UInt64") {
                            return Err(bad(path, "only header_type=\"UInt64\" is read"));
                        }
                    }
                    "Piece" => extent = Some(parse_extent(path, attr("Extent"))?),
                    "PointData" | "CellData" | "Coordinates" => section = tag.clone(),
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
                        "Coordinates" => match name.as_str() {
                            "x" => data.coords[0] = values,
                            "y" => data.coords[1] = values,
                            "z" => data.coords[2] = values,
                            other => return Err(bad(path, format!("unknown coordinate array `{other}`"))),
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
    let n = extent.ok_or_else(|| bad(path, "no Piece element"))?;
    for (a, name) in ["x", "y", "z"].iter().enumerate() {
        if data.coords[a].len() != n[a] + 1 {
            return Err(bad(
                path,
                format!("coordinate `{name}` has {} values for {} cells", data.coords[a].len(), n[a]),
            ));
        }
        check_axis(name, &data.coords[a]).map_err(|e| bad(path, e))?;
    }
    let nc: usize = n.iter().product();
    let np: usize = n.iter().map(|v| v + 1).product();
    for (name, (c, v)) in &data.cell_data {
        if v.len() != c * nc {
            return Err(bad(path, format!("cell array `{name}` has {} values for {nc} cells", v.len())));
        }
    }
    for (name, (c, v)) in &data.point_data {
        if v.len() != c * np {
            return Err(bad(path, format!("point array `{name}` has {} values for {np} points", v.len())));
        }
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stretched_grid_round_trips_exactly_and_corruption_is_detected() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.vtr");
        let (x, y, z) = (vec![0.0, 0.1, 0.3, 0.7], vec![-1.0, 1.0 / 3.0], vec![0.0, 1e-9, 2.0]);
        let nc = 3 * 2;
        let s: Vec<f64> = (0..nc).map(|c| c as f64 * 0.5 - 1.0).collect();
        let v: Vec<[f64; 3]> = (0..nc).map(|c| [c as f64, -(c as f64), 1.0 / (c as f64 + 1.0)]).collect();
        let pts: Vec<f64> = (0..4 * 2 * 3).map(|c| c as f64).collect();
        Vtr::new(&x, &y, &z)
            .unwrap()
            .cell_scalar("p_Pa", &s)
            .cell_vector("U_m_s", &v)
            .cell_int("blocked", &[0, 1, 0, 0, 1, 1])
            .point_scalar("n", &pts)
            .write(&p)
            .unwrap();
        let d = read(&p).unwrap();
        assert_eq!(d.coords, [x.clone(), y.clone(), z.clone()]);
        assert_eq!(d.cell_data["p_Pa"], (1, s));
        assert_eq!(d.cell_data["U_m_s"].1[3..6], [1.0, -1.0, 0.5]);
        assert_eq!(d.cell_data["blocked"].1, vec![0.0, 1.0, 0.0, 0.0, 1.0, 1.0]);
        assert_eq!(d.point_data["n"].1.len(), 24);
        let text = std::fs::read_to_string(&p)
            .unwrap()
            .replace("0 3 0 1 0 2\">\n      <Point", "0 4 0 1 0 2\">\n      <Point");
        std::fs::write(&p, text).unwrap();
        let e = read(&p).unwrap_err().to_string();
        assert!(e.contains("coordinate `x` has 4 values for 4 cells"), "{e}");
        assert!(Vtr::new(&[0.0, 0.0], &y, &z).is_err(), "faces must increase");
    }
}
