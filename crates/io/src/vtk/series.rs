//! Time series of VTK files: ParaView `.pvd` collections and `.series` JSON files.
//!
//! * `.pvd`: `<VTKFile type="Collection"><Collection><DataSet timestep="t" file="f.vtu"/>…`;
//! * `.series` (ParaView ≥ 5.5, written by `foamToVTK`): `{"file-series-version": "1.0", "files":
//!   [{"name": "f.vtu", "time": t}, …]}`.
//!
//! File names are resolved relative to the series file.

use super::VtkError;
use std::path::{Path, PathBuf};

/// `(time, file)` pairs sorted by time.
pub fn read_series(path: &Path) -> Result<Vec<(f64, PathBuf)>, VtkError> {
    let text =
        std::fs::read_to_string(path).map_err(|source| VtkError::Io { path: path.to_owned(), source })?;
    let dir = path.parent().unwrap_or(Path::new("."));
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
    let mut out = if name.ends_with(".series") {
        let v: serde_json::Value =
            serde_json::from_str(&text).map_err(|e| VtkError::format(path, format!("JSON: {e}")))?;
        let files = v
            .get("files")
            .and_then(|f| f.as_array())
            .ok_or_else(|| VtkError::format(path, "no `files` array"))?;
        let mut out = Vec::new();
        for (i, f) in files.iter().enumerate() {
            let n = f.get("name").and_then(|n| n.as_str());
            let t = f.get("time").and_then(|t| t.as_f64());
            match (n, t) {
                (Some(n), Some(t)) => out.push((t, dir.join(n))),
                _ => return Err(VtkError::format(path, format!("files[{i}] needs `name` and `time`"))),
            }
        }
        out
    } else {
        // .pvd: scan DataSet elements for timestep and file attributes.
        let mut out = Vec::new();
        for tag in text.split("<DataSet").skip(1) {
            let end = tag.find('>').unwrap_or(tag.len());
            let tag = &tag[..end];
            let attr = |k: &str| {
                let key = format!("{k}=\"");
                tag.find(&key).map(|p| {
                    let rest = &tag[p + key.len()..];
                    rest[..rest.find('"').unwrap_or(rest.len())].to_owned()
                })
            };
            let t = attr("timestep").and_then(|t| t.trim().parse::<f64>().ok()).unwrap_or(0.0);
            let f =
                attr("file").ok_or_else(|| VtkError::format(path, "a <DataSet> without a file attribute"))?;
            out.push((t, dir.join(f)));
        }
        out
    };
    if out.is_empty() {
        return Err(VtkError::format(path, "the series lists no files"));
    }
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pvd_and_series() {
        let dir = tempfile::tempdir().unwrap();
        let pvd = dir.path().join("a.pvd");
        std::fs::write(&pvd, "<VTKFile type=\"Collection\"><Collection><DataSet timestep=\"2\" file=\"b.vtu\"/><DataSet timestep=\"1\" part=\"0\" file=\"a.vtu\"/></Collection></VTKFile>").unwrap();
        let s = read_series(&pvd).unwrap();
        assert_eq!(s[0], (1.0, dir.path().join("a.vtu")));
        assert_eq!(s[1].0, 2.0);
        let ser = dir.path().join("internal.vtu.series");
        std::fs::write(&ser, r#"{"file-series-version":"1.0","files":[{"name":"x_0.vtu","time":0},{"name":"x_1.vtu","time":0.5}]}"#).unwrap();
        let s = read_series(&ser).unwrap();
        assert_eq!(s[1], (0.5, dir.path().join("x_1.vtu")));
    }
}
