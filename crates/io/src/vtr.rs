//! VTK XML rectilinear grids (`.vtr`): structured fields on a grid given by its face coordinates per axis
//! (uniform or stretched), with cell and point data, as ParaView reads them. (`spatter-flow` reads them
//! back as imported flow fields.)
//!
//! Cell (i, j, k) of an `nx × ny × nz` grid is entry `i + nx·(j + ny·k)` of every cell array (x fastest,
//! VTK's order); point arrays have `(nx + 1)(ny + 1)(nz + 1)` entries in the same order. Arrays are
//! stored inline in VTK's `binary` format like the `.vtu` files.

use crate::vtk_xml::{push, write_array, write_section, Array, Values};
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extent_coordinates_and_arrays_are_written_in_vtk_order() {
        // VTK's own reader checks these files in `tests/vtk_reader.rs`; here the text itself.
        let (x, y, z) = (vec![0.0, 0.1, 0.3, 0.7], vec![-1.0, 1.0 / 3.0], vec![0.0, 1e-9, 2.0]);
        let v = Vtr::new(&x, &y, &z).unwrap().cell_scalar("p_Pa", &[0.0; 6]).cell_int("blocked", &[0; 6]);
        assert_eq!(v.cells_per_axis(), [3, 1, 2]);
        let xml = v.to_xml();
        assert!(xml.contains("<RectilinearGrid WholeExtent=\"0 3 0 1 0 2\">"), "{xml}");
        assert!(xml.contains("<Piece Extent=\"0 3 0 1 0 2\">"));
        assert!(xml.contains("Name=\"p_Pa\" NumberOfComponents=\"1\""));
        assert!(xml.contains("type=\"Int64\" Name=\"blocked\""));
        for name in ["x", "y", "z"] {
            assert!(xml.contains(&format!("Name=\"{name}\" NumberOfComponents=\"1\"")));
        }
        assert!(Vtr::new(&[0.0, 0.0], &y, &z).is_err(), "faces must increase");
        assert!(Vtr::new(&[0.0], &y, &z).is_err(), "one face is no cell");
        let wrong = std::panic::catch_unwind(|| Vtr::new(&x, &y, &z).unwrap().cell_scalar("p", &[0.0; 5]));
        assert!(wrong.is_err(), "a cell array of the wrong length is a programming error");
    }
}
