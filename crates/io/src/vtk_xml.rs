//! Pieces shared by the VTK XML writers ([`crate::vtu`], [`crate::vtr`]): inline `binary` data arrays
//! (base64 of a `UInt64` byte count followed by the little-endian values, one stream per array, no
//! compression). [`crate::vtk`] reads them back.

use base64::Engine;
use std::fmt::Write as _;

/// Values of one data array.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Values {
    F64(Vec<f64>),
    I64(Vec<i64>),
}

impl Values {
    pub(crate) fn len(&self) -> usize {
        match self {
            Values::F64(v) => v.len(),
            Values::I64(v) => v.len(),
        }
    }

    /// The VTK type name of the values.
    pub(crate) fn type_name(&self) -> &'static str {
        match self {
            Values::F64(_) => "Float64",
            Values::I64(_) => "Int64",
        }
    }
}

/// A named data array with `components` values per entity.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Array {
    pub(crate) name: String,
    pub(crate) components: usize,
    pub(crate) values: Values,
}

/// Appends `array` to `list` after checking it holds `components` values for each of `expected` entities.
/// A length mismatch is a programming error of the caller and panics with the array named.
pub(crate) fn push(list: &mut Vec<Array>, expected: usize, name: &str, components: usize, values: Values) {
    let len = values.len();
    assert_eq!(len, expected * components, "VTK array `{name}`: {len} values for {expected} entities");
    list.push(Array { name: name.to_owned(), components, values });
}

fn encode(bytes: &[u8]) -> String {
    let mut raw = Vec::with_capacity(8 + bytes.len());
    raw.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
    raw.extend_from_slice(bytes);
    base64::engine::general_purpose::STANDARD.encode(raw)
}

/// Writes one `<DataArray>` element.
pub(crate) fn write_array(s: &mut String, name: &str, components: usize, values: &Values) {
    let ty = values.type_name();
    let bytes: Vec<u8> = match values {
        Values::F64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
        Values::I64(v) => v.iter().flat_map(|x| x.to_le_bytes()).collect(),
    };
    let _ = writeln!(
        s,
        "        <DataArray type=\"{ty}\" Name=\"{}\" NumberOfComponents=\"{components}\" format=\"binary\">{}</DataArray>",
        xml_escape(name),
        encode(&bytes)
    );
}

/// Writes one `<DataArray>` element of bytes.
pub(crate) fn write_u8_array(s: &mut String, name: &str, values: &[u8]) {
    let _ = writeln!(
        s,
        "        <DataArray type=\"UInt8\" Name=\"{name}\" NumberOfComponents=\"1\" format=\"binary\">{}</DataArray>",
        encode(values)
    );
}

/// Writes every array of `list` inside `<tag>…</tag>`.
pub(crate) fn write_section(s: &mut String, tag: &str, list: &[Array]) {
    let _ = writeln!(s, "      <{tag}>");
    for a in list {
        write_array(s, &a.name, a.components, &a.values);
    }
    let _ = writeln!(s, "      </{tag}>");
}

pub(crate) fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}
