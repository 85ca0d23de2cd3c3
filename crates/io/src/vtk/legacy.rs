//! Legacy VTK files (`.vtk`), ASCII or BINARY (big-endian), versions 2.0 to 5.1.
//!
//! Layout per the VTK file-format specification ("VTK File Formats", Kitware, legacy section):
//! header line, title, `ASCII`/`BINARY`, `DATASET <type>`, geometry, then `POINT_DATA n` / `CELL_DATA n`
//! sections of `SCALARS`, `VECTORS`, `NORMALS`, `TENSORS` and `FIELD` arrays. Version 5.1 stores cells as
//! `OFFSETS` and `CONNECTIVITY` arrays; older versions as one `n id…` row per cell. `METADATA` blocks are
//! skipped.

use super::{cell_type, lattice, DataArray, VtkDataset, VtkError};
use spatter_core::Vec3;
use std::path::Path;

struct Cursor<'a> {
    b: &'a [u8],
    pos: usize,
    binary: bool,
    path: &'a Path,
}

fn type_size(t: &str) -> Option<usize> {
    Some(match t {
        "bit" => return None,
        "unsigned_char" | "char" | "vtktypeint8" | "vtktypeuint8" => 1,
        "unsigned_short" | "short" | "vtktypeint16" | "vtktypeuint16" => 2,
        "unsigned_int" | "int" | "float" | "vtktypeint32" | "vtktypeuint32" => 4,
        "unsigned_long" | "long" | "double" | "vtktypeint64" | "vtktypeuint64" | "vtkidtype" => 8,
        _ => return None,
    })
}

impl<'a> Cursor<'a> {
    fn err(&self, msg: impl Into<String>) -> VtkError {
        let line = 1 + self.b[..self.pos.min(self.b.len())].iter().filter(|&&c| c == b'\n').count();
        VtkError::format(self.path, format!("line {line}: {}", msg.into()))
    }

    fn skip_ws(&mut self) {
        while self.pos < self.b.len() && self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    /// Next whitespace-separated word, or None at the end.
    fn word(&mut self) -> Option<&'a str> {
        self.skip_ws();
        let start = self.pos;
        while self.pos < self.b.len() && !self.b[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if start == self.pos {
            None
        } else {
            std::str::from_utf8(&self.b[start..self.pos]).ok()
        }
    }

    fn expect_word(&mut self, what: &str) -> Result<&'a str, VtkError> {
        self.word().ok_or_else(|| self.err(format!("unexpected end of file; expected {what}")))
    }

    fn usize(&mut self, what: &str) -> Result<usize, VtkError> {
        let w = self.expect_word(what)?;
        w.parse().map_err(|_| self.err(format!("`{w}` is not a count ({what})")))
    }

    /// Rest of the current line (without the newline).
    fn rest_of_line(&mut self) -> &'a str {
        let start = self.pos;
        while self.pos < self.b.len() && self.b[self.pos] != b'\n' {
            self.pos += 1;
        }
        let s = std::str::from_utf8(&self.b[start..self.pos]).unwrap_or("");
        if self.pos < self.b.len() {
            self.pos += 1;
        }
        s.trim_end_matches('\r')
    }

    /// Reads `n` numbers of VTK type `ty` as f64.
    fn numbers(&mut self, n: usize, ty: &str) -> Result<Vec<f64>, VtkError> {
        if self.binary {
            let size = type_size(ty).ok_or_else(|| self.err(format!("data type `{ty}` is not supported")))?;
            // Binary data start after the newline that ends the header line.
            self.rest_of_line();
            let end = self.pos + n * size;
            if end > self.b.len() {
                return Err(
                    self.err(format!("binary block of {n} `{ty}` values runs past the end of the file"))
                );
            }
            let chunk = &self.b[self.pos..end];
            self.pos = end;
            let mut out = Vec::with_capacity(n);
            for c in chunk.chunks_exact(size) {
                out.push(decode_be(c, ty));
            }
            Ok(out)
        } else {
            if type_size(ty).is_none() {
                return Err(self.err(format!("data type `{ty}` is not supported")));
            }
            let mut out = Vec::with_capacity(n);
            for _ in 0..n {
                let w = self.expect_word("a number")?;
                out.push(w.parse::<f64>().map_err(|_| self.err(format!("`{w}` is not a number")))?);
            }
            Ok(out)
        }
    }

    /// Numbers written as text even in BINARY files (ORIGIN, SPACING).
    fn text_numbers(&mut self, n: usize) -> Result<Vec<f64>, VtkError> {
        let mut out = Vec::with_capacity(n);
        for _ in 0..n {
            let w = self.expect_word("a number")?;
            out.push(w.parse::<f64>().map_err(|_| self.err(format!("`{w}` is not a number")))?);
        }
        Ok(out)
    }

    fn ids(&mut self, n: usize, ty: &str) -> Result<Vec<u32>, VtkError> {
        let v = self.numbers(n, ty)?;
        v.into_iter()
            .map(|x| {
                if x >= 0.0 && x <= u32::MAX as f64 && x.fract() == 0.0 {
                    Ok(x as u32)
                } else {
                    Err(self.err(format!("`{x}` is not a valid index")))
                }
            })
            .collect()
    }

    /// Skips a `METADATA` block (ends at an empty line) if the next word is METADATA.
    fn skip_metadata(&mut self) {
        let save = self.pos;
        if self.word() == Some("METADATA") {
            self.rest_of_line();
            loop {
                let l = self.rest_of_line();
                if l.trim().is_empty() || self.pos >= self.b.len() {
                    break;
                }
            }
        } else {
            self.pos = save;
        }
    }
}

fn decode_be(c: &[u8], ty: &str) -> f64 {
    match (ty, c.len()) {
        ("float", 4) => f32::from_be_bytes([c[0], c[1], c[2], c[3]]) as f64,
        ("double", 8) => f64::from_be_bytes(c.try_into().unwrap_or([0; 8])),
        (t, 1) if t.starts_with('u') || t == "vtktypeuint8" => c[0] as f64,
        (_, 1) => c[0] as i8 as f64,
        (t, 2) if t.starts_with('u') || t == "vtktypeuint16" => u16::from_be_bytes([c[0], c[1]]) as f64,
        (_, 2) => i16::from_be_bytes([c[0], c[1]]) as f64,
        (t, 4) if t.starts_with('u') || t == "vtktypeuint32" => {
            u32::from_be_bytes([c[0], c[1], c[2], c[3]]) as f64
        }
        (_, 4) => i32::from_be_bytes([c[0], c[1], c[2], c[3]]) as f64,
        (t, 8) if t.starts_with('u') || t == "vtktypeuint64" => {
            u64::from_be_bytes(c.try_into().unwrap_or([0; 8])) as f64
        }
        (_, 8) => i64::from_be_bytes(c.try_into().unwrap_or([0; 8])) as f64,
        _ => f64::NAN,
    }
}

/// Parses a legacy VTK file.
pub fn parse(bytes: &[u8], path: &Path) -> Result<VtkDataset, VtkError> {
    let mut c = Cursor { b: bytes, pos: 0, binary: false, path };
    let header = c.rest_of_line();
    if !header.starts_with("# vtk DataFile Version") {
        return Err(VtkError::format(
            path,
            "not a legacy VTK file (first line is not `# vtk DataFile Version …`)",
        ));
    }
    let version: f64 = header.rsplit(' ').next().and_then(|v| v.trim().parse().ok()).unwrap_or(2.0);
    let _title = c.rest_of_line();
    match c.rest_of_line().trim() {
        "ASCII" => c.binary = false,
        "BINARY" => c.binary = true,
        other => return Err(c.err(format!("expected ASCII or BINARY, found `{other}`"))),
    }
    if c.word() != Some("DATASET") {
        return Err(c.err("expected `DATASET <type>`"));
    }
    let kind = c.expect_word("a dataset type")?.to_owned();
    let mut ds = VtkDataset::default();
    let mut dims = [0usize; 3];
    let mut origin = Vec3::ZERO;
    let mut spacing = Vec3::ONE;
    let mut coords: [Vec<f64>; 3] = Default::default();
    let mut cells_raw: Option<(usize, Vec<u32>)> = None;
    let mut offsets_51: Option<Vec<u32>> = None;
    // Geometry section: read keywords until POINT_DATA / CELL_DATA / end.
    let mut pending: Option<String> = None;
    loop {
        let save = c.pos;
        let Some(w) = c.word() else { break };
        match w {
            "POINTS" => {
                let n = c.usize("point count")?;
                let ty = c.expect_word("point data type")?;
                let v = c.numbers(3 * n, ty)?;
                ds.points = v.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
                c.skip_metadata();
            }
            "DIMENSIONS" => {
                for d in &mut dims {
                    *d = c.usize("dimension")?;
                }
            }
            "ORIGIN" => {
                let v = c.text_numbers(3)?;
                origin = Vec3::new(v[0], v[1], v[2]);
            }
            "SPACING" | "ASPECT_RATIO" => {
                let v = c.text_numbers(3)?;
                spacing = Vec3::new(v[0], v[1], v[2]);
            }
            "X_COORDINATES" | "Y_COORDINATES" | "Z_COORDINATES" => {
                let k = (w.as_bytes()[0] - b'X') as usize;
                let n = c.usize("coordinate count")?;
                let ty = c.expect_word("coordinate type")?;
                coords[k] = c.numbers(n, ty)?;
                c.skip_metadata();
            }
            "CELLS" => {
                let n = c.usize("cell count")?;
                let size = c.usize("cell list size")?;
                if version >= 5.0 {
                    // 5.1: OFFSETS <type> (n values) then CONNECTIVITY <type> (size values).
                    if c.word() != Some("OFFSETS") {
                        return Err(c.err("expected OFFSETS after CELLS in a version 5 file"));
                    }
                    let ty = c.expect_word("offset type")?;
                    let off = c.ids(n, ty)?;
                    c.skip_metadata();
                    if c.word() != Some("CONNECTIVITY") {
                        return Err(c.err("expected CONNECTIVITY after OFFSETS"));
                    }
                    let ty = c.expect_word("connectivity type")?;
                    let conn = c.ids(size, ty)?;
                    c.skip_metadata();
                    offsets_51 = Some(off);
                    cells_raw = Some((n.saturating_sub(1), conn));
                } else {
                    let conn = c.ids(size, "int")?;
                    cells_raw = Some((n, conn));
                }
            }
            "CELL_TYPES" => {
                let n = c.usize("cell type count")?;
                let t = c.ids(n, "int")?;
                ds.cell_types = t.into_iter().map(|x| x as u8).collect();
            }
            "POINT_DATA" | "CELL_DATA" => {
                pending = Some(w.to_owned());
                break;
            }
            "METADATA" => {
                c.pos = save;
                c.skip_metadata();
            }
            "FIELD" => {
                // Dataset-level field data (e.g. TIME): read and drop.
                let _name = c.expect_word("field name")?;
                let k = c.usize("array count")?;
                for _ in 0..k {
                    read_field_array(&mut c)?;
                }
            }
            other => return Err(c.err(format!("unexpected keyword `{other}` in the {kind} geometry"))),
        }
    }
    // Assemble cells.
    match kind.as_str() {
        "UNSTRUCTURED_GRID" => {
            let (n, conn) = cells_raw.ok_or_else(|| VtkError::format(path, "UNSTRUCTURED_GRID without CELLS"))?;
            if ds.cell_types.len() != n {
                return Err(VtkError::format(path, format!("{n} cells but {} cell types", ds.cell_types.len())));
            }
            if let Some(off) = offsets_51 {
                let offsets: Vec<usize> = off.iter().map(|&o| o as usize).collect();
                if offsets.last().copied() != Some(conn.len()) || offsets.windows(2).any(|w| w[1] < w[0]) {
                    return Err(VtkError::format(path, "cell offsets are not increasing or do not end at the connectivity size"));
                }
                if ds.cell_types.contains(&cell_type::POLYHEDRON) {
                    // VTK 9 writes a polyhedron's connectivity as its face stream [n_faces, n_0, ids…, …].
                    ds.cell_offsets = vec![0];
                    ds.poly_faces = vec![Vec::new(); n];
                    for i in 0..n {
                        let row = &conn[offsets[i]..offsets[i + 1]];
                        if ds.cell_types[i] == cell_type::POLYHEDRON {
                            let (ids, stream) = super::xml::polyhedron_points(row).ok_or_else(|| {
                                VtkError::format(path, format!("cell {i}: malformed polyhedron face stream"))
                            })?;
                            ds.connectivity.extend_from_slice(&ids);
                            ds.poly_faces[i] = stream;
                        } else {
                            ds.connectivity.extend_from_slice(row);
                        }
                        ds.cell_offsets.push(ds.connectivity.len());
                    }
                } else {
                    ds.cell_offsets = offsets;
                    ds.connectivity = conn;
                }
            } else {
                split_legacy_cells(&mut ds, n, &conn, path)?;
            }
        }
        "STRUCTURED_GRID" => {
            let (t, o, conn) = VtkDataset::structured_cells(dims);
            (ds.cell_types, ds.cell_offsets, ds.connectivity) = (t, o, conn);
        }
        "RECTILINEAR_GRID" => {
            for k in 0..3 {
                if coords[k].len() != dims[k] {
                    return Err(VtkError::format(path, "coordinate arrays do not match DIMENSIONS"));
                }
            }
            ds.points = lattice(dims, |i, j, k| Vec3::new(coords[0][i], coords[1][j], coords[2][k]));
            let (t, o, conn) = VtkDataset::structured_cells(dims);
            (ds.cell_types, ds.cell_offsets, ds.connectivity) = (t, o, conn);
        }
        "STRUCTURED_POINTS" => {
            ds.points = lattice(dims, |i, j, k| origin + spacing * Vec3::new(i as f64, j as f64, k as f64));
            let (t, o, conn) = VtkDataset::structured_cells(dims);
            (ds.cell_types, ds.cell_offsets, ds.connectivity) = (t, o, conn);
        }
        other => {
            return Err(VtkError::unsupported(
                path,
                format!("DATASET {other}; a flow field needs UNSTRUCTURED_GRID, STRUCTURED_GRID, RECTILINEAR_GRID or STRUCTURED_POINTS"),
            ))
        }
    }
    if kind == "STRUCTURED_GRID" && ds.points.len() != dims[0] * dims[1] * dims[2] {
        return Err(VtkError::format(path, "STRUCTURED_GRID point count does not match DIMENSIONS"));
    }
    // Attribute sections.
    let mut section = pending;
    while let Some(sec) = section.take() {
        let n = c.usize("tuple count")?;
        let on_points = sec == "POINT_DATA";
        loop {
            let save = c.pos;
            let Some(w) = c.word() else { break };
            let arr = match w {
                "SCALARS" => {
                    let name = c.expect_word("array name")?.to_owned();
                    let ty = c.expect_word("data type")?.to_owned();
                    // Optional component count on the same line, then LOOKUP_TABLE (optional in practice).
                    let rest = c.rest_of_line();
                    let comps = rest.split_whitespace().next().and_then(|s| s.parse().ok()).unwrap_or(1usize);
                    let save = c.pos;
                    if c.word() == Some("LOOKUP_TABLE") {
                        let _ = c.expect_word("table name")?;
                    } else {
                        c.pos = save;
                    }
                    let values = c.numbers(n * comps, &ty)?;
                    Some(DataArray { name, components: comps, values })
                }
                "VECTORS" | "NORMALS" => {
                    let name = c.expect_word("array name")?.to_owned();
                    let ty = c.expect_word("data type")?.to_owned();
                    Some(DataArray { name, components: 3, values: c.numbers(3 * n, &ty)? })
                }
                "TENSORS" => {
                    let name = c.expect_word("array name")?.to_owned();
                    let ty = c.expect_word("data type")?.to_owned();
                    Some(DataArray { name, components: 9, values: c.numbers(9 * n, &ty)? })
                }
                "FIELD" => {
                    let _ = c.expect_word("field name")?;
                    let k = c.usize("array count")?;
                    for _ in 0..k {
                        let a = read_field_array(&mut c)?;
                        if a.len() == n {
                            push(&mut ds, on_points, a);
                        }
                    }
                    None
                }
                "LOOKUP_TABLE" => {
                    let _ = c.expect_word("table name")?;
                    let m = c.usize("table size")?;
                    let _ = c.numbers(4 * m, "float")?;
                    None
                }
                "METADATA" => {
                    c.pos = save;
                    c.skip_metadata();
                    None
                }
                "POINT_DATA" | "CELL_DATA" => {
                    section = Some(w.to_owned());
                    break;
                }
                other => return Err(c.err(format!("unexpected keyword `{other}` in {sec}"))),
            };
            if let Some(a) = arr {
                push(&mut ds, on_points, a);
                c.skip_metadata();
            }
        }
    }
    Ok(ds)
}

fn push(ds: &mut VtkDataset, on_points: bool, a: DataArray) {
    if on_points {
        ds.point_data.push(a);
    } else {
        ds.cell_data.push(a);
    }
}

fn read_field_array(c: &mut Cursor) -> Result<DataArray, VtkError> {
    c.skip_metadata();
    let name = c.expect_word("array name")?.to_owned();
    let comps = c.usize("component count")?;
    let tuples = c.usize("tuple count")?;
    let ty = c.expect_word("data type")?.to_owned();
    let values = c.numbers(comps * tuples, &ty)?;
    c.skip_metadata();
    Ok(DataArray { name, components: comps, values })
}

/// Splits pre-5.0 `CELLS` rows (`n id…`, or `n n_faces (n_i id…)…` for polyhedra).
fn split_legacy_cells(ds: &mut VtkDataset, n: usize, raw: &[u32], path: &Path) -> Result<(), VtkError> {
    let mut pos = 0;
    ds.cell_offsets = Vec::with_capacity(n + 1);
    ds.cell_offsets.push(0);
    let has_poly = ds.cell_types.contains(&cell_type::POLYHEDRON);
    for i in 0..n {
        let cnt = *raw.get(pos).ok_or_else(|| VtkError::format(path, "CELLS list ends early"))? as usize;
        let row =
            raw.get(pos + 1..pos + 1 + cnt).ok_or_else(|| VtkError::format(path, "CELLS list ends early"))?;
        pos += 1 + cnt;
        if ds.cell_types[i] == cell_type::POLYHEDRON {
            let (ids, stream) = super::xml::polyhedron_points(row).ok_or_else(|| {
                VtkError::format(path, format!("cell {i}: malformed polyhedron face stream"))
            })?;
            ds.connectivity.extend_from_slice(&ids);
            if ds.poly_faces.is_empty() {
                ds.poly_faces = vec![Vec::new(); n];
            }
            ds.poly_faces[i] = stream;
        } else {
            ds.connectivity.extend_from_slice(row);
        }
        ds.cell_offsets.push(ds.connectivity.len());
    }
    if has_poly && ds.poly_faces.len() != n {
        ds.poly_faces.resize(n, Vec::new());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const TET_ASCII: &str = "# vtk DataFile Version 3.0
two tets
ASCII
DATASET UNSTRUCTURED_GRID
POINTS 5 float
0 0 0  1 0 0  0 1 0  0 0 1  1 1 1
CELLS 2 10
4 0 1 2 3
4 1 2 3 4
CELL_TYPES 2
10 10
CELL_DATA 2
SCALARS p float 1
LOOKUP_TABLE default
1.5 2.5
POINT_DATA 5
VECTORS U double
0 0 0 1 0 0 0 1 0 0 0 1 1 1 1
FIELD attributes 1
k 1 5 float
0.1 0.2 0.3 0.4 0.5
";

    #[test]
    fn ascii_unstructured_grid_with_attributes() {
        let ds = parse(TET_ASCII.as_bytes(), Path::new("t.vtk")).unwrap();
        ds.check(Path::new("t.vtk")).unwrap();
        assert_eq!(ds.points.len(), 5);
        assert_eq!(ds.cell_types, vec![10, 10]);
        assert_eq!(ds.cell(1), &[1, 2, 3, 4]);
        assert_eq!(ds.cell_array("p").unwrap().values, vec![1.5, 2.5]);
        assert_eq!(ds.point_array("U").unwrap().vec3(4), Vec3::ONE);
        assert_eq!(ds.point_array("k").unwrap().values[2], 0.3);
    }

    #[test]
    fn binary_big_endian_and_version_5_1() {
        // The same two tets, BINARY, version 5.1 with OFFSETS/CONNECTIVITY.
        let mut b: Vec<u8> =
            b"# vtk DataFile Version 5.1\nbin\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 5 double\n".to_vec();
        for p in [0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 1., 1., 1.] {
            b.extend_from_slice(&f64::to_be_bytes(p));
        }
        b.extend_from_slice(b"\nCELLS 3 8\nOFFSETS vtktypeint64\n");
        for o in [0i64, 4, 8] {
            b.extend_from_slice(&o.to_be_bytes());
        }
        b.extend_from_slice(b"\nCONNECTIVITY vtktypeint64\n");
        for o in [0i64, 1, 2, 3, 1, 2, 3, 4] {
            b.extend_from_slice(&o.to_be_bytes());
        }
        b.extend_from_slice(b"\nCELL_TYPES 2\n");
        for t in [10i32, 10] {
            b.extend_from_slice(&t.to_be_bytes());
        }
        b.extend_from_slice(b"\nPOINT_DATA 5\nFIELD attributes 1\nU 3 5 float\n");
        for i in 0..15 {
            b.extend_from_slice(&(i as f32).to_be_bytes());
        }
        b.extend_from_slice(b"\nMETADATA\nINFORMATION 0\n\n");
        let ds = parse(&b, Path::new("b.vtk")).unwrap();
        ds.check(Path::new("b.vtk")).unwrap();
        assert_eq!(ds.cell(0), &[0, 1, 2, 3]);
        assert_eq!(ds.cell(1), &[1, 2, 3, 4]);
        assert_eq!(ds.points[4], Vec3::ONE);
        assert_eq!(ds.point_array("U").unwrap().vec3(4), Vec3::new(12.0, 13.0, 14.0));
    }

    #[test]
    fn structured_points_become_hexahedra() {
        let s = "# vtk DataFile Version 2.0\nbox\nASCII\nDATASET STRUCTURED_POINTS\nDIMENSIONS 3 2 2\nORIGIN 0 0 0\nSPACING 0.5 1 1\nPOINT_DATA 12\nSCALARS f float\nLOOKUP_TABLE default\n0 1 2 3 4 5 6 7 8 9 10 11\n";
        let ds = parse(s.as_bytes(), Path::new("s.vtk")).unwrap();
        assert_eq!(ds.n_cells(), 2);
        assert_eq!(ds.cell(1), &[1, 2, 5, 4, 7, 8, 11, 10]);
        assert_eq!(ds.points[11], Vec3::new(1.0, 1.0, 1.0));
    }

    #[test]
    fn errors_name_the_line() {
        let s = "# vtk DataFile Version 2.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 2 float\n0 0 zero\n";
        let e = parse(s.as_bytes(), Path::new("bad.vtk")).unwrap_err().to_string();
        assert!(e.contains("bad.vtk") && e.contains("line 6") && e.contains("`zero`"), "{e}");
        let e = parse(b"hello", Path::new("x.vtk")).unwrap_err().to_string();
        assert!(e.contains("not a legacy VTK file"), "{e}");
    }
}
