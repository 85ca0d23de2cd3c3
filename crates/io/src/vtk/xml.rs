//! VTK XML files: `UnstructuredGrid` (.vtu), `StructuredGrid` (.vts), `RectilinearGrid` (.vtr) and
//! `ImageData` (.vti).
//!
//! Data array encodings per the VTK XML format description (Kitware, "VTK File Formats", XML section):
//! `format="ascii"` (text), `format="binary"` (base64 of a byte-count header followed by the data; the
//! header may be encoded together with the data or as its own base64 block — both are accepted) and
//! `format="appended"` (an `offset` into the `<AppendedData>` block, `encoding="raw"` or `"base64"`).
//! `header_type` UInt32 (default) or UInt64, `byte_order` Little/BigEndian, and
//! `compressor="vtkZLibDataCompressor"` (block header `[n_blocks, block_size, last_size, sizes…]`).
//! Polyhedra: the `faces`/`faceoffsets` arrays (VTK ≤ 9.3) or `face_connectivity`/`face_offsets`/
//! `polyhedron_to_faces`/`polyhedron_offsets` (VTK ≥ 9.4).

use super::{cell_type, lattice, DataArray, VtkDataset, VtkError};
use base64::Engine;
use quick_xml::events::Event;
use spatter_core::Vec3;
use std::collections::HashMap;
use std::io::Read;
use std::path::Path;

/// A parsed XML element (attributes, text and children), enough for VTK files.
#[derive(Debug, Default)]
struct Element {
    name: String,
    attrs: HashMap<String, String>,
    text: Vec<u8>,
    children: Vec<Element>,
}

impl Element {
    fn attr(&self, k: &str) -> Option<&str> {
        self.attrs.get(k).map(String::as_str)
    }
    fn child(&self, name: &str) -> Option<&Element> {
        self.children.iter().find(|c| c.name == name)
    }
    fn children_named<'a>(&'a self, name: &'a str) -> impl Iterator<Item = &'a Element> + 'a {
        self.children.iter().filter(move |c| c.name == name)
    }
}

fn parse_tree(xml: &[u8], path: &Path) -> Result<Element, VtkError> {
    let mut reader = quick_xml::Reader::from_reader(xml);
    reader.config_mut().check_end_names = false;
    let mut stack: Vec<Element> = vec![Element::default()];
    let mut buf = Vec::new();
    let element = |s: &quick_xml::events::BytesStart| {
        let mut el =
            Element { name: String::from_utf8_lossy(s.name().as_ref()).into_owned(), ..Default::default() };
        for a in s.attributes().flatten() {
            let k = String::from_utf8_lossy(a.key.as_ref()).into_owned();
            let v = String::from_utf8_lossy(&a.value).into_owned();
            el.attrs.insert(k, v);
        }
        el
    };
    let close = |stack: &mut Vec<Element>| {
        if stack.len() > 1 {
            let el = stack.pop().unwrap_or_default();
            if let Some(parent) = stack.last_mut() {
                parent.children.push(el);
            }
        }
    };
    loop {
        let ev = reader.read_event_into(&mut buf).map_err(|e| VtkError::format(path, format!("XML: {e}")))?;
        match ev {
            Event::Start(s) => stack.push(element(&s)),
            Event::Empty(s) => {
                stack.push(element(&s));
                close(&mut stack);
            }
            Event::Text(t) => {
                if let Some(top) = stack.last_mut() {
                    top.text.extend_from_slice(&t.into_inner());
                }
            }
            Event::CData(t) => {
                if let Some(top) = stack.last_mut() {
                    top.text.extend_from_slice(&t.into_inner());
                }
            }
            Event::End(_) => close(&mut stack),
            Event::Eof => break,
            _ => {}
        }
        buf.clear();
    }
    while stack.len() > 1 {
        close(&mut stack);
    }
    let root = stack.pop().unwrap_or_default();
    root.children
        .into_iter()
        .find(|e| e.name == "VTKFile")
        .ok_or_else(|| VtkError::format(path, "not a VTK XML file (no <VTKFile> element)"))
}

/// File-level encoding settings.
#[derive(Clone, Copy)]
struct Enc {
    big_endian: bool,
    header64: bool,
    zlib: bool,
}

/// The `<AppendedData>` block.
struct Appended<'a> {
    raw: bool,
    data: &'a [u8],
}

fn type_size(t: &str) -> Option<usize> {
    Some(match t {
        "Int8" | "UInt8" | "Char" => 1,
        "Int16" | "UInt16" => 2,
        "Int32" | "UInt32" | "Float32" | "Int" | "Float" => 4,
        "Int64" | "UInt64" | "Float64" | "Double" => 8,
        _ => return None,
    })
}

fn decode_value(c: &[u8], ty: &str, be: bool) -> f64 {
    macro_rules! rd {
        ($t:ty, $n:expr) => {{
            let mut a = [0u8; $n];
            a.copy_from_slice(c);
            if be {
                <$t>::from_be_bytes(a) as f64
            } else {
                <$t>::from_le_bytes(a) as f64
            }
        }};
    }
    match ty {
        "Int8" | "Char" => c[0] as i8 as f64,
        "UInt8" => c[0] as f64,
        "Int16" => rd!(i16, 2),
        "UInt16" => rd!(u16, 2),
        "Int32" | "Int" => rd!(i32, 4),
        "UInt32" => rd!(u32, 4),
        "Int64" => rd!(i64, 8),
        "UInt64" => rd!(u64, 8),
        "Float32" | "Float" => rd!(f32, 4),
        "Float64" | "Double" => rd!(f64, 8),
        _ => f64::NAN,
    }
}

fn read_header_int(b: &[u8], enc: Enc) -> Option<usize> {
    if enc.header64 {
        let a: [u8; 8] = b.get(..8)?.try_into().ok()?;
        Some((if enc.big_endian { u64::from_be_bytes(a) } else { u64::from_le_bytes(a) }) as usize)
    } else {
        let a: [u8; 4] = b.get(..4)?.try_into().ok()?;
        Some((if enc.big_endian { u32::from_be_bytes(a) } else { u32::from_le_bytes(a) }) as usize)
    }
}

fn inflate(data: &[u8], expect: usize) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(expect);
    flate2::read::ZlibDecoder::new(data).read_to_end(&mut out).ok()?;
    (out.len() == expect).then_some(out)
}

/// Decodes the byte payload of one binary block that starts at `b` (header included). Returns the data
/// bytes and the number of input bytes consumed.
fn decode_block(b: &[u8], enc: Enc) -> Option<(Vec<u8>, usize)> {
    let hs = if enc.header64 { 8 } else { 4 };
    if !enc.zlib {
        let n = read_header_int(b, enc)?;
        let data = b.get(hs..hs + n)?;
        return Some((data.to_vec(), hs + n));
    }
    let nb = read_header_int(b, enc)?;
    let bs = read_header_int(b.get(hs..)?, enc)?;
    let last = read_header_int(b.get(2 * hs..)?, enc)?;
    let head = hs * (3 + nb);
    let mut sizes = Vec::with_capacity(nb);
    for i in 0..nb {
        sizes.push(read_header_int(b.get(hs * (3 + i)..)?, enc)?);
    }
    let mut out = Vec::new();
    let mut pos = head;
    for (i, &cs) in sizes.iter().enumerate() {
        let expect = if i + 1 == nb && last != 0 { last } else { bs };
        out.extend(inflate(b.get(pos..pos + cs)?, expect)?);
        pos += cs;
    }
    Some((out, pos))
}

fn b64(text: &[u8]) -> Option<Vec<u8>> {
    let clean: Vec<u8> = text.iter().copied().filter(|c| !c.is_ascii_whitespace()).collect();
    base64::engine::general_purpose::STANDARD.decode(&clean).ok()
}

/// Decodes a base64 block whose header is encoded either together with the data or separately.
fn decode_base64_block(text: &[u8], enc: Enc) -> Option<Vec<u8>> {
    let clean: Vec<u8> = text.iter().copied().filter(|c| !c.is_ascii_whitespace()).collect();
    // Together: one base64 stream.
    if let Some(all) = b64(&clean) {
        if let Some((data, used)) = decode_block(&all, enc) {
            if used == all.len() || all.len() - used < 3 {
                return Some(data);
            }
        }
    }
    // Separately: the header is its own base64 block (VTK's writer does this).
    let hs = if enc.header64 { 8 } else { 4 };
    let enc_len = |bytes: usize| bytes.div_ceil(3) * 4;
    let head_bytes = if enc.zlib {
        let first = b64(clean.get(..enc_len(hs))?)?;
        let nb = read_header_int(&first, enc)?;
        hs * (3 + nb)
    } else {
        hs
    };
    let head = b64(clean.get(..enc_len(head_bytes))?)?;
    let body = b64(clean.get(enc_len(head_bytes)..)?)?;
    let mut joined = head[..head_bytes].to_vec();
    joined.extend_from_slice(&body);
    decode_block(&joined, enc).map(|(d, _)| d)
}

/// Reads the values of one `<DataArray>`.
fn array_values(el: &Element, enc: Enc, app: &Option<Appended>, path: &Path) -> Result<Vec<f64>, VtkError> {
    let name = el.attr("Name").unwrap_or("(unnamed)");
    let ty = el.attr("type").unwrap_or("Float32");
    let size = type_size(ty)
        .ok_or_else(|| VtkError::unsupported(path, format!("DataArray `{name}`: type `{ty}`")))?;
    let format = el.attr("format").unwrap_or("ascii");
    let bad = |m: &str| VtkError::format(path, format!("DataArray `{name}`: {m}"));
    let bytes = match format {
        "ascii" => {
            let text = std::str::from_utf8(&el.text).map_err(|_| bad("text is not UTF-8"))?;
            return text
                .split_ascii_whitespace()
                .map(|w| w.parse::<f64>().map_err(|_| bad(&format!("`{w}` is not a number"))))
                .collect();
        }
        "binary" => {
            decode_base64_block(&el.text, enc).ok_or_else(|| bad("cannot decode the base64 block"))?
        }
        "appended" => {
            let app =
                app.as_ref().ok_or_else(|| bad("format=\"appended\" but the file has no <AppendedData>"))?;
            let off: usize = el
                .attr("offset")
                .and_then(|o| o.trim().parse().ok())
                .ok_or_else(|| bad("appended array without a valid offset"))?;
            let tail = app.data.get(off..).ok_or_else(|| bad("offset beyond the appended data"))?;
            if app.raw {
                decode_block(tail, enc)
                    .map(|(d, _)| d)
                    .ok_or_else(|| bad("cannot decode the appended block"))?
            } else {
                // Base64 appended: the block runs to the next array's offset; decode greedily.
                let end = tail.iter().position(|c| *c == b'<').unwrap_or(tail.len());
                decode_base64_prefix(&tail[..end], enc)
                    .ok_or_else(|| bad("cannot decode the appended base64 block"))?
            }
        }
        other => return Err(bad(&format!("unknown format `{other}`"))),
    };
    if bytes.len() % size != 0 {
        return Err(bad("byte count is not a multiple of the value size"));
    }
    Ok(bytes.chunks_exact(size).map(|c| decode_value(c, ty, enc.big_endian)).collect())
}

/// Base64 appended data: the block for one array is a prefix of `text`; its length follows from the
/// (separately or jointly encoded) header.
fn decode_base64_prefix(text: &[u8], enc: Enc) -> Option<Vec<u8>> {
    let hs = if enc.header64 { 8 } else { 4 };
    let enc_len = |bytes: usize| bytes.div_ceil(3) * 4;
    let first = b64(text.get(..enc_len(hs).max(8))?)?;
    let (head_bytes, data_bytes_guess) = if enc.zlib {
        let nb = read_header_int(&first, enc)?;
        (hs * (3 + nb), None)
    } else {
        (hs, Some(read_header_int(&first, enc)?))
    };
    // Separate encoding: header block then data block.
    let head = b64(text.get(..enc_len(head_bytes))?)?;
    let data_len = match data_bytes_guess {
        Some(n) => n,
        None => {
            let mut s = 0;
            for i in 0..(head_bytes / hs - 3) {
                s += read_header_int(&head[hs * (3 + i)..], enc)?;
            }
            s
        }
    };
    if let Some(body) = text.get(enc_len(head_bytes)..enc_len(head_bytes) + enc_len(data_len)).and_then(b64) {
        let mut joined = head[..head_bytes].to_vec();
        joined.extend_from_slice(&body);
        if let Some((d, _)) = decode_block(&joined, enc) {
            return Some(d);
        }
    }
    // Joint encoding.
    let all = b64(text.get(..enc_len(head_bytes + data_len))?)?;
    decode_block(&all, enc).map(|(d, _)| d)
}

fn data_arrays(
    sec: Option<&Element>,
    enc: Enc,
    app: &Option<Appended>,
    path: &Path,
) -> Result<Vec<DataArray>, VtkError> {
    let mut out = Vec::new();
    if let Some(sec) = sec {
        for el in sec.children_named("DataArray") {
            let components = el.attr("NumberOfComponents").and_then(|s| s.parse().ok()).unwrap_or(1usize);
            let name = el.attr("Name").unwrap_or("").to_owned();
            let values = array_values(el, enc, app, path)?;
            out.push(DataArray { name, components: components.max(1), values });
        }
    }
    Ok(out)
}

fn find_array<'a>(sec: &'a Element, name: &str) -> Option<&'a Element> {
    sec.children_named("DataArray").find(|e| e.attr("Name") == Some(name))
}

fn ints(v: Vec<f64>, path: &Path, what: &str) -> Result<Vec<i64>, VtkError> {
    v.into_iter()
        .map(|x| {
            if x.fract() == 0.0 && x.is_finite() {
                Ok(x as i64)
            } else {
                Err(VtkError::format(path, format!("{what}: `{x}` is not an integer")))
            }
        })
        .collect()
}

/// Unique point ids and the face stream of a polyhedron given as `[n_faces, n_0, ids…, n_1, ids…]`.
pub(crate) fn polyhedron_points(stream: &[u32]) -> Option<(Vec<u32>, Vec<u32>)> {
    let nf = *stream.first()? as usize;
    let mut pos = 1;
    let mut ids = Vec::new();
    for _ in 0..nf {
        let n = *stream.get(pos)? as usize;
        let f = stream.get(pos + 1..pos + 1 + n)?;
        for &i in f {
            if !ids.contains(&i) {
                ids.push(i);
            }
        }
        pos += 1 + n;
    }
    Some((ids, stream[..pos].to_vec()))
}

fn extent(s: Option<&str>) -> Option<[i64; 6]> {
    let v: Vec<i64> = s?.split_whitespace().filter_map(|w| w.parse().ok()).collect();
    v.try_into().ok()
}

/// Parses a VTK XML file.
pub fn parse(bytes: &[u8], path: &Path) -> Result<VtkDataset, VtkError> {
    // Cut off the appended block: raw binary is not XML.
    let (xml_part, appended) = match find(bytes, b"<AppendedData") {
        Some(pos) => {
            let tag_end = bytes[pos..].iter().position(|&c| c == b'>').map(|p| pos + p + 1);
            let tag_end = tag_end.ok_or_else(|| VtkError::format(path, "unterminated <AppendedData> tag"))?;
            let tag = String::from_utf8_lossy(&bytes[pos..tag_end]);
            let raw = !tag.contains("base64");
            let us = bytes[tag_end..]
                .iter()
                .position(|&c| c == b'_')
                .ok_or_else(|| VtkError::format(path, "<AppendedData> without the `_` marker"))?;
            let start = tag_end + us + 1;
            let end = rfind(bytes, b"</AppendedData>").filter(|&e| e >= start).unwrap_or(bytes.len());
            let mut xml = bytes[..pos].to_vec();
            xml.extend_from_slice(b"</VTKFile>");
            (xml, Some(Appended { raw, data: &bytes[start..end] }))
        }
        None => (bytes.to_vec(), None),
    };
    let root = parse_tree(&xml_part, path)?;
    let enc = Enc {
        big_endian: root.attr("byte_order") == Some("BigEndian"),
        header64: root.attr("header_type") == Some("UInt64"),
        zlib: match root.attr("compressor") {
            None | Some("") => false,
            Some("vtkZLibDataCompressor") => true,
            Some(other) => {
                return Err(VtkError::unsupported(
                    path,
                    format!("compressor `{other}` (only zlib is supported)"),
                ))
            }
        },
    };
    let kind = root.attr("type").unwrap_or("").to_owned();
    let grid = root
        .child(&kind)
        .ok_or_else(|| VtkError::format(path, format!("no <{kind}> element under <VTKFile>")))?;
    let mut ds = VtkDataset { cell_offsets: vec![0], ..Default::default() };
    for piece in grid.children_named("Piece") {
        let base = ds.points.len() as u32;
        let mut part = VtkDataset::default();
        match kind.as_str() {
            "UnstructuredGrid" => {
                let pts = piece.child("Points").and_then(|p| p.children_named("DataArray").next());
                let pts = pts.ok_or_else(|| VtkError::format(path, "Piece without <Points>"))?;
                let v = array_values(pts, enc, &appended, path)?;
                if v.len() % 3 != 0 {
                    return Err(VtkError::format(path, format!("<Points> holds {} values, not a multiple of 3", v.len())));
                }
                part.points = v.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
                let cells = piece.child("Cells").ok_or_else(|| VtkError::format(path, "Piece without <Cells>"))?;
                let get = |n: &str| -> Result<Option<Vec<i64>>, VtkError> {
                    match find_array(cells, n) {
                        Some(e) => Ok(Some(ints(array_values(e, enc, &appended, path)?, path, n)?)),
                        None => Ok(None),
                    }
                };
                let conn = get("connectivity")?.ok_or_else(|| VtkError::format(path, "<Cells> without connectivity"))?;
                let offs = get("offsets")?.ok_or_else(|| VtkError::format(path, "<Cells> without offsets"))?;
                let types = get("types")?.ok_or_else(|| VtkError::format(path, "<Cells> without types"))?;
                if offs.len() != types.len() {
                    return Err(VtkError::format(path, "offsets and types differ in length"));
                }
                part.cell_types = types.iter().map(|&t| t as u8).collect();
                part.cell_offsets = std::iter::once(0usize).chain(offs.iter().map(|&o| o as usize)).collect();
                if part.cell_offsets.windows(2).any(|w| w[1] < w[0]) || part.cell_offsets.last() != Some(&conn.len()) {
                    return Err(VtkError::format(path, "cell offsets are not increasing or do not end at the connectivity size"));
                }
                part.connectivity = conn.iter().map(|&i| i as u32).collect();
                // The piece's declared sizes must agree with its arrays (a truncated or edited file).
                for (key, found) in [("NumberOfPoints", part.points.len()), ("NumberOfCells", part.cell_types.len())] {
                    if let Some(declared) = piece.attr(key) {
                        if declared.trim().parse::<usize>().ok() != Some(found) {
                            return Err(VtkError::format(path, format!("Piece says {key}=\"{declared}\" but its arrays hold {found}")));
                        }
                    }
                }
                if part.cell_types.contains(&cell_type::POLYHEDRON) {
                    part.poly_faces = polyhedra(&get("faces")?, &get("faceoffsets")?, &get("face_connectivity")?, &get("face_offsets")?, &get("polyhedron_to_faces")?, &get("polyhedron_offsets")?, &part.cell_types, path)?;
                }
            }
            "StructuredGrid" => {
                let ext = extent(piece.attr("Extent")).ok_or_else(|| VtkError::format(path, "Piece without Extent"))?;
                let dims = dims_of(ext);
                let pts = piece.child("Points").and_then(|p| p.children_named("DataArray").next());
                let pts = pts.ok_or_else(|| VtkError::format(path, "Piece without <Points>"))?;
                let v = array_values(pts, enc, &appended, path)?;
                part.points = v.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
                if part.points.len() != dims[0] * dims[1] * dims[2] {
                    return Err(VtkError::format(path, "point count does not match Extent"));
                }
                (part.cell_types, part.cell_offsets, part.connectivity) = VtkDataset::structured_cells(dims);
            }
            "RectilinearGrid" => {
                let ext = extent(piece.attr("Extent")).ok_or_else(|| VtkError::format(path, "Piece without Extent"))?;
                let dims = dims_of(ext);
                let co = piece.child("Coordinates").ok_or_else(|| VtkError::format(path, "Piece without <Coordinates>"))?;
                let c: Vec<Vec<f64>> = co
                    .children_named("DataArray")
                    .map(|e| array_values(e, enc, &appended, path))
                    .collect::<Result<_, _>>()?;
                if c.len() != 3 || (0..3).any(|k| c[k].len() != dims[k]) {
                    return Err(VtkError::format(path, "coordinate arrays do not match Extent"));
                }
                part.points = lattice(dims, |i, j, k| Vec3::new(c[0][i], c[1][j], c[2][k]));
                (part.cell_types, part.cell_offsets, part.connectivity) = VtkDataset::structured_cells(dims);
            }
            "ImageData" => {
                let ext = extent(piece.attr("Extent").or(grid.attr("WholeExtent")))
                    .ok_or_else(|| VtkError::format(path, "ImageData without Extent"))?;
                let dims = dims_of(ext);
                let v3 = |s: Option<&str>, d: f64| {
                    let v: Vec<f64> = s.unwrap_or("").split_whitespace().filter_map(|w| w.parse().ok()).collect();
                    if v.len() == 3 {
                        Vec3::new(v[0], v[1], v[2])
                    } else {
                        Vec3::splat(d)
                    }
                };
                let origin = v3(grid.attr("Origin"), 0.0);
                let spacing = v3(grid.attr("Spacing"), 1.0);
                let lo = Vec3::new(ext[0] as f64, ext[2] as f64, ext[4] as f64);
                part.points = lattice(dims, |i, j, k| origin + spacing * (lo + Vec3::new(i as f64, j as f64, k as f64)));
                (part.cell_types, part.cell_offsets, part.connectivity) = VtkDataset::structured_cells(dims);
            }
            other => {
                return Err(VtkError::unsupported(
                    path,
                    format!("VTKFile type `{other}`; expected UnstructuredGrid, StructuredGrid, RectilinearGrid or ImageData"),
                ))
            }
        }
        part.point_data = data_arrays(piece.child("PointData"), enc, &appended, path)?;
        part.cell_data = data_arrays(piece.child("CellData"), enc, &appended, path)?;
        part.check(path)?;
        merge(&mut ds, part, base);
    }
    // A file without points is valid VTK (a particle snapshot after the last particle left); whoever needs
    // cells says so (the flow-field import refuses a file without volume cells).
    Ok(ds)
}

fn dims_of(e: [i64; 6]) -> [usize; 3] {
    [(e[1] - e[0] + 1).max(0) as usize, (e[3] - e[2] + 1).max(0) as usize, (e[5] - e[4] + 1).max(0) as usize]
}

#[allow(clippy::too_many_arguments)]
fn polyhedra(
    faces: &Option<Vec<i64>>,
    faceoffsets: &Option<Vec<i64>>,
    face_conn: &Option<Vec<i64>>,
    face_offs: &Option<Vec<i64>>,
    poly_faces: &Option<Vec<i64>>,
    poly_offs: &Option<Vec<i64>>,
    types: &[u8],
    path: &Path,
) -> Result<Vec<Vec<u32>>, VtkError> {
    let n = types.len();
    let mut out = vec![Vec::new(); n];
    let bad = || VtkError::format(path, "malformed polyhedron face arrays");
    if let (Some(f), Some(fo)) = (faces, faceoffsets) {
        // faceoffsets[i] = end of cell i's stream in `faces`, −1 for non-polyhedra.
        let mut start = 0usize;
        for i in 0..n {
            let end = *fo.get(i).ok_or_else(bad)?;
            if end < 0 {
                continue;
            }
            let end = end as usize;
            if types[i] == cell_type::POLYHEDRON {
                out[i] = f.get(start..end).ok_or_else(bad)?.iter().map(|&x| x as u32).collect();
            }
            start = end;
        }
        return Ok(out);
    }
    if let (Some(fc), Some(fo), Some(pf), Some(po)) = (face_conn, face_offs, poly_faces, poly_offs) {
        // VTK ≥ 9.4: faces as a cell array, polyhedra as lists of face ids.
        let face = |k: usize| -> Option<&[i64]> {
            let s = if k == 0 { 0 } else { *fo.get(k - 1)? as usize };
            fc.get(s..*fo.get(k)? as usize)
        };
        let mut start = 0usize;
        for i in 0..n {
            let end = *po.get(i).ok_or_else(bad)? as usize;
            if types[i] == cell_type::POLYHEDRON {
                let ids = pf.get(start..end).ok_or_else(bad)?;
                let mut s = vec![ids.len() as u32];
                for &fid in ids {
                    let f = face(fid as usize).ok_or_else(bad)?;
                    s.push(f.len() as u32);
                    s.extend(f.iter().map(|&x| x as u32));
                }
                out[i] = s;
            }
            start = end;
        }
        return Ok(out);
    }
    Err(VtkError::format(path, "polyhedral cells without face arrays"))
}

fn merge(ds: &mut VtkDataset, part: VtkDataset, base: u32) {
    let had_cells = ds.n_cells();
    ds.points.extend(part.points);
    let c0 = ds.connectivity.len();
    ds.connectivity.extend(part.connectivity.iter().map(|&i| i + base));
    ds.cell_offsets.extend(part.cell_offsets[1..].iter().map(|&o| o + c0));
    ds.cell_types.extend(&part.cell_types);
    if !part.poly_faces.is_empty() || !ds.poly_faces.is_empty() {
        ds.poly_faces.resize(had_cells, Vec::new());
        let mut pf = part.poly_faces;
        pf.resize(part.cell_types.len(), Vec::new());
        for s in pf {
            // Shift point ids inside the stream.
            let mut s = s;
            if !s.is_empty() {
                let nf = s[0] as usize;
                let mut pos = 1;
                for _ in 0..nf {
                    let n = s[pos] as usize;
                    for x in &mut s[pos + 1..pos + 1 + n] {
                        *x += base;
                    }
                    pos += 1 + n;
                }
            }
            ds.poly_faces.push(s);
        }
    }
    for (dst, src) in [(&mut ds.point_data, part.point_data), (&mut ds.cell_data, part.cell_data)] {
        if dst.is_empty() && had_cells == 0 {
            *dst = src;
        } else {
            for a in src {
                if let Some(d) = dst.iter_mut().find(|d| d.name == a.name && d.components == a.components) {
                    d.values.extend(a.values);
                }
            }
        }
    }
}

fn find(h: &[u8], n: &[u8]) -> Option<usize> {
    h.windows(n.len()).position(|w| w == n)
}

fn rfind(h: &[u8], n: &[u8]) -> Option<usize> {
    h.windows(n.len()).rposition(|w| w == n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn le_block(values: &[f64], ty: &str, header64: bool) -> Vec<u8> {
        let mut data = Vec::new();
        for &v in values {
            match ty {
                "Float32" => data.extend_from_slice(&(v as f32).to_le_bytes()),
                "Float64" => data.extend_from_slice(&v.to_le_bytes()),
                "Int64" => data.extend_from_slice(&(v as i64).to_le_bytes()),
                "UInt8" => data.push(v as u8),
                "Int32" => data.extend_from_slice(&(v as i32).to_le_bytes()),
                _ => unreachable!(),
            }
        }
        let mut out = if header64 {
            (data.len() as u64).to_le_bytes().to_vec()
        } else {
            (data.len() as u32).to_le_bytes().to_vec()
        };
        out.extend(data);
        out
    }

    const PTS: [f64; 15] = [0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 1., 1., 1.];
    const CONN: [f64; 8] = [0., 1., 2., 3., 1., 2., 3., 4.];
    const OFFS: [f64; 2] = [4., 8.];
    const TYPES: [f64; 2] = [10., 10.];
    const U: [f64; 15] = [0., 1., 2., 3., 4., 5., 6., 7., 8., 9., 10., 11., 12., 13., 14.];

    fn check_two_tets(ds: &VtkDataset) {
        ds.check(Path::new("t")).unwrap();
        assert_eq!(ds.points[4], Vec3::ONE);
        assert_eq!(ds.cell(1), &[1, 2, 3, 4]);
        assert_eq!(ds.cell_types, vec![10, 10]);
        assert_eq!(ds.point_array("U").unwrap().vec3(4), Vec3::new(12.0, 13.0, 14.0));
        assert_eq!(ds.cell_array("p").unwrap().values, vec![1.5, 2.5]);
    }

    fn doc(
        header64: bool,
        zlib: bool,
        arrays: &[(&str, &str, usize, String, &str)],
        appended: Option<(&str, Vec<u8>)>,
    ) -> Vec<u8> {
        // arrays: (section, name/type, comps, payload attr+text, type)
        let mut s = format!(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"{}\"{}>\n<UnstructuredGrid>\n<Piece NumberOfPoints=\"5\" NumberOfCells=\"2\">\n",
            if header64 { "UInt64" } else { "UInt32" },
            if zlib { " compressor=\"vtkZLibDataCompressor\"" } else { "" }
        );
        for sec in ["Points", "Cells", "PointData", "CellData"] {
            s += &format!("<{sec}>\n");
            for (sect, name, comps, payload, ty) in arrays {
                if *sect == sec {
                    s += &format!("<DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{comps}\" {payload}</DataArray>\n");
                }
            }
            s += &format!("</{sec}>\n");
        }
        s += "</Piece>\n</UnstructuredGrid>\n";
        let mut out = s.into_bytes();
        if let Some((encoding, blob)) = appended {
            out.extend_from_slice(format!("<AppendedData encoding=\"{encoding}\">\n_").as_bytes());
            out.extend(blob);
            out.extend_from_slice(b"\n</AppendedData>\n");
        }
        out.extend_from_slice(b"</VTKFile>\n");
        out
    }

    fn all_arrays() -> Vec<(&'static str, &'static str, usize, Vec<f64>, &'static str)> {
        vec![
            ("Points", "Points", 3, PTS.to_vec(), "Float64"),
            ("Cells", "connectivity", 1, CONN.to_vec(), "Int64"),
            ("Cells", "offsets", 1, OFFS.to_vec(), "Int64"),
            ("Cells", "types", 1, TYPES.to_vec(), "UInt8"),
            ("PointData", "U", 3, U.to_vec(), "Float32"),
            ("CellData", "p", 1, vec![1.5, 2.5], "Float64"),
        ]
    }

    #[test]
    fn ascii_vtu() {
        let arrays: Vec<_> = all_arrays()
            .into_iter()
            .map(|(s, n, c, v, t)| {
                let text: Vec<String> = v.iter().map(|x| x.to_string()).collect();
                (s, n, c, format!("format=\"ascii\">{}", text.join(" ")), t)
            })
            .collect();
        let ds = parse(&doc(false, false, &arrays, None), Path::new("a.vtu")).unwrap();
        check_two_tets(&ds);
    }

    #[test]
    fn inline_base64_joint_and_separate_headers() {
        let e = base64::engine::general_purpose::STANDARD;
        for (header64, separate) in [(false, false), (true, false), (false, true), (true, true)] {
            let arrays: Vec<_> = all_arrays()
                .into_iter()
                .map(|(s, n, c, v, t)| {
                    let block = le_block(&v, t, header64);
                    let hs = if header64 { 8 } else { 4 };
                    let text = if separate {
                        format!("{}{}", e.encode(&block[..hs]), e.encode(&block[hs..]))
                    } else {
                        e.encode(&block)
                    };
                    (s, n, c, format!("format=\"binary\">{text}"), t)
                })
                .collect();
            let ds = parse(&doc(header64, false, &arrays, None), Path::new("b.vtu")).unwrap();
            check_two_tets(&ds);
        }
    }

    #[test]
    fn appended_raw_and_zlib() {
        for zlib in [false, true] {
            let mut blob = Vec::new();
            let arrays: Vec<_> = all_arrays()
                .into_iter()
                .map(|(s, n, c, v, t)| {
                    let off = blob.len();
                    let block = le_block(&v, t, false);
                    if zlib {
                        let data = &block[4..];
                        let mut z =
                            flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
                        z.write_all(data).unwrap();
                        let comp = z.finish().unwrap();
                        for h in [1u32, data.len() as u32, data.len() as u32, comp.len() as u32] {
                            blob.extend_from_slice(&h.to_le_bytes());
                        }
                        blob.extend(comp);
                    } else {
                        blob.extend(block);
                    }
                    (s, n, c, format!("format=\"appended\" offset=\"{off}\">"), t)
                })
                .collect();
            let ds = parse(&doc(false, zlib, &arrays, Some(("raw", blob))), Path::new("c.vtu")).unwrap();
            check_two_tets(&ds);
        }
    }

    #[test]
    fn rectilinear_and_polyhedron() {
        let vtr = "<VTKFile type=\"RectilinearGrid\" version=\"0.1\"><RectilinearGrid WholeExtent=\"0 2 0 1 0 1\"><Piece Extent=\"0 2 0 1 0 1\"><Coordinates><DataArray type=\"Float64\" format=\"ascii\">0 0.5 1</DataArray><DataArray type=\"Float64\" format=\"ascii\">0 1</DataArray><DataArray type=\"Float64\" format=\"ascii\">0 2</DataArray></Coordinates><CellData><DataArray type=\"Float32\" Name=\"c\" format=\"ascii\">7 8</DataArray></CellData></Piece></RectilinearGrid></VTKFile>";
        let ds = parse(vtr.as_bytes(), Path::new("r.vtr")).unwrap();
        assert_eq!(ds.n_cells(), 2);
        assert_eq!(ds.points.len(), 12);
        assert_eq!(ds.points[11], Vec3::new(1.0, 1.0, 2.0));
        assert_eq!(ds.cell_array("c").unwrap().values, vec![7.0, 8.0]);
        // One polyhedron: the unit tetrahedron written as a polyhedral cell.
        let vtu = "<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"4\" NumberOfCells=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points><Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">42</DataArray><DataArray type=\"Int32\" Name=\"faces\" format=\"ascii\">4 3 0 2 1 3 0 1 3 3 1 2 3 3 0 3 2</DataArray><DataArray type=\"Int32\" Name=\"faceoffsets\" format=\"ascii\">17</DataArray></Cells></Piece></UnstructuredGrid></VTKFile>";
        let ds = parse(vtu.as_bytes(), Path::new("p.vtu")).unwrap();
        assert_eq!(ds.poly_faces[0][0], 4);
        assert_eq!(ds.poly_faces[0].len(), 17);
    }

    #[test]
    fn malformed_polyhedra_are_refused_not_panicking() {
        // The unit tetrahedron of `rectilinear_and_polyhedron` as a polyhedron with a broken face stream.
        let vtu = |faces: &str, faceoffsets: &str| {
            format!("<VTKFile type=\"UnstructuredGrid\"><UnstructuredGrid><Piece NumberOfPoints=\"4\" NumberOfCells=\"1\"><Points><DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"ascii\">0 0 0 1 0 0 0 1 0 0 0 1</DataArray></Points><Cells><DataArray type=\"Int32\" Name=\"connectivity\" format=\"ascii\">0 1 2 3</DataArray><DataArray type=\"Int32\" Name=\"offsets\" format=\"ascii\">4</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">42</DataArray><DataArray type=\"Int32\" Name=\"faces\" format=\"ascii\">{faces}</DataArray><DataArray type=\"Int32\" Name=\"faceoffsets\" format=\"ascii\">{faceoffsets}</DataArray></Cells></Piece></UnstructuredGrid></VTKFile>")
        };
        let err = |faces: &str, offs: &str| {
            let e = parse(vtu(faces, offs).as_bytes(), Path::new("p.vtu")).unwrap_err().to_string();
            assert!(e.contains("p.vtu"), "{e}");
            e
        };
        // A face refers to point 9 of 4 (used to panic in the decomposition).
        let e = err("4 3 0 2 9 3 0 1 3 3 1 2 3 3 0 3 2", "17");
        assert!(e.contains("cell 0") && e.contains("point 9") && e.contains("4 points"), "{e}");
        // Five faces announced, four given.
        let e = err("5 3 0 2 1 3 0 1 3 3 1 2 3 3 0 3 2", "17");
        assert!(e.contains("ends after 4 of 5 faces"), "{e}");
        // A face announcing more points than the stream holds.
        let e = err("4 3 0 2 1 3 0 1 3 3 1 2 3 7 0 3 2", "17");
        assert!(e.contains("announces 7 points"), "{e}");
        // Trailing values after the last face.
        let e = err("3 3 0 2 1 3 0 1 3 3 1 2 3 3 0 3 2", "17");
        assert!(e.contains("has 17 values"), "{e}");
        // A two-point face, and an empty faceoffsets array (used to index out of bounds).
        let e = err("4 2 0 2 3 0 1 3 3 1 2 3 3 0 3 2", "16");
        assert!(e.contains("face 0 has 2 points"), "{e}");
        err("4 3 0 2 1 3 0 1 3 3 1 2 3 3 0 3 2", "");
    }
}
