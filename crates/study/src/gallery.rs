//! The same map of every case on one colour scale.
//!
//! A run records each colour map it draws on a triangle mesh (`summary.json` → `maps`: the `.vtu`, the
//! cell array, the view). Each case picks its own colour scale, so two cases' pictures cannot be compared
//! colour for colour; the study therefore reads the recorded arrays of every case, takes one scale over all
//! of them (from 0, or the lowest value if negative, to the highest finite value) and draws every case's
//! map again on it, into `gallery/<map label>/case_NNNNN.png`. When every case drew the map on the same
//! fixed scale (a run's `wetting_cap`), that scale is kept, so the study's pictures read like the runs'.

use crate::plan::{case_dir_name, Plan};
use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;
use spatter_io::plot::mesh_map_png_on_scale;
use spatter_io::run::MeshMapRecord;
use spatter_io::summary::SummaryFile;
use std::path::{Path, PathBuf};

/// One map redrawn for several cases on a common scale.
#[derive(Clone, Debug, PartialEq)]
pub struct Gallery {
    /// The map's label as the runs recorded it.
    pub label: String,
    /// The common colour scale (low, high) in the map's unit.
    pub scale: (f64, f64),
    /// True when the scale is the one every case fixed (e.g. a wetting cap), not one over their values.
    pub fixed: bool,
    /// The colour-bar label (name and unit).
    pub colorbar_label: String,
    /// (caption, picture) per case, in case order.
    pub pictures: Vec<(String, PathBuf)>,
}

/// One case's map, read back from its `.vtu`.
struct CaseMap {
    case: usize,
    record: MeshMapRecord,
    mesh: TriMesh,
    values: Vec<f64>,
}

/// Redraws the recorded maps of the first `max_cases` cases of `plan` (run under `out/cases`) on one colour
/// scale per map label, into `out/gallery`. A case without a summary or whose `.vtu` cannot be read is left
/// out with a warning in the log (its own pictures are still in its folder); a map only one case drew is
/// drawn too.
pub fn redraw(plan: &Plan, out: &Path, max_cases: usize) -> Vec<Gallery> {
    let mut labels: Vec<String> = Vec::new();
    let mut maps: Vec<CaseMap> = Vec::new();
    for c in plan.cases.iter().take(max_cases) {
        let dir = out.join("cases").join(case_dir_name(c.index));
        let Ok(Some(summary)) = SummaryFile::read(&dir) else { continue };
        for record in summary.maps {
            let vtu = if record.vtu.is_absolute() { record.vtu.clone() } else { dir.join(&record.vtu) };
            match read_map(&vtu, &record.array) {
                Ok((mesh, values)) => {
                    if !labels.contains(&record.label) {
                        labels.push(record.label.clone());
                    }
                    maps.push(CaseMap { case: c.index, record, mesh, values });
                }
                Err(e) => tracing::warn!("gallery: case {}: {e}", c.index),
            }
        }
    }
    let mut galleries = Vec::new();
    for label in labels {
        let of_label: Vec<&CaseMap> = maps.iter().filter(|m| m.record.label == label).collect();
        // A scale every case fixed alike (a wetting cap) is kept; otherwise one over every case's values.
        let fixed = of_label
            .first()
            .and_then(|m| m.record.scale)
            .filter(|s| s[1] > s[0] && of_label.iter().all(|m| m.record.scale == Some(*s)));
        let scale = match fixed {
            Some([lo, hi]) => (lo, hi),
            None => common_scale(of_label.iter().map(|m| m.values.as_slice())),
        };
        let folder = out.join("gallery").join(file_safe(&label));
        if let Err(e) = std::fs::create_dir_all(&folder) {
            tracing::warn!("gallery: cannot create {}: {e}", folder.display());
            continue;
        }
        let mut pictures = Vec::new();
        for m in &of_label {
            let png = folder.join(format!("{}.png", case_dir_name(m.case)));
            let r = &m.record;
            let title = format!("case {}: {}", m.case, r.title);
            let view = (Vec3::from_array(r.view_dir), Vec3::from_array(r.up));
            let caption = plan.cases.iter().find(|c| c.index == m.case).map(|c| plan.caption(c));
            match mesh_map_png_on_scale(&png, &m.mesh, &m.values, view, (&title, &r.colorbar_label), scale) {
                Ok(()) => pictures.push((caption.unwrap_or_else(|| format!("case {}", m.case)), png)),
                Err(e) => tracing::warn!("gallery: case {}: {e}", m.case),
            }
        }
        let colorbar_label = of_label.first().map(|m| m.record.colorbar_label.clone()).unwrap_or_default();
        galleries.push(Gallery { label, scale, fixed: fixed.is_some(), colorbar_label, pictures });
    }
    galleries
}

/// One scale over every finite value of every case: from 0 (or the lowest value, if negative) to the
/// highest; `(0, 1)` when no case has a positive range.
pub fn common_scale<'a>(cases: impl Iterator<Item = &'a [f64]>) -> (f64, f64) {
    let (mut lo, mut hi) = (0.0_f64, f64::NEG_INFINITY);
    for v in cases.flatten().filter(|v| v.is_finite()) {
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    if hi.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (0.0, 1.0)
    }
}

/// The triangles of `vtu` and its one-component cell array `array`.
fn read_map(vtu: &Path, array: &str) -> Result<(TriMesh, Vec<f64>), String> {
    let data = spatter_io::vtk::read(vtu).map_err(|e| e.to_string())?;
    // The reader has checked every index and array length; what is left is the cell shape.
    if data.cell_types.iter().any(|&t| t != spatter_io::vtk::cell_type::TRIANGLE) {
        return Err(format!("{}: not a mesh of triangles only", vtu.display()));
    }
    let triangles = data.connectivity.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let values = match data.cell_array(array) {
        Some(a) if a.components == 1 => a.values.clone(),
        Some(a) => {
            return Err(format!(
                "{}: cell array `{array}` has {} components, expected 1",
                vtu.display(),
                a.components
            ))
        }
        None => return Err(format!("{}: no cell array `{array}`", vtu.display())),
    };
    Ok((TriMesh { vertices: data.points, triangles }, values))
}

/// `s` with every character other than ASCII letters, digits, `_` and `-` replaced by `_`.
pub(crate) fn file_safe(s: &str) -> String {
    s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' || c == '-' { c } else { '_' }).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_io::vtu::Vtu;

    #[test]
    fn the_common_scale_spans_every_case_from_zero_and_ignores_non_finite_values() {
        let a = [1.0, 2.0, f64::NAN];
        let b = [0.5, 7.0, f64::INFINITY];
        assert_eq!(common_scale([&a[..], &b[..]].into_iter()), (0.0, 7.0));
        let c = [-3.0, 1.0];
        assert_eq!(common_scale([&a[..], &c[..]].into_iter()), (-3.0, 2.0));
        assert_eq!(common_scale([&[f64::NAN][..], &[0.0][..]].into_iter()), (0.0, 1.0));
    }

    #[test]
    fn a_written_map_reads_back_and_a_wrong_array_or_cell_type_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("panel.vtu");
        let v = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::ONE];
        Vtu::triangles(&v, &[[0, 1, 2], [1, 3, 2]]).cell_scalar("mass", &[1.0, 2.5]).write(&p).unwrap();
        let (mesh, values) = read_map(&p, "mass").unwrap();
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(mesh.vertices, v.to_vec());
        assert_eq!(values, vec![1.0, 2.5]);
        assert!(read_map(&p, "speed").unwrap_err().contains("no cell array `speed`"));
        let cloud = dir.path().join("cloud.vtu");
        Vtu::point_cloud(&v).write(&cloud).unwrap();
        assert!(read_map(&cloud, "mass").unwrap_err().contains("not a mesh of triangles"));
    }
}
