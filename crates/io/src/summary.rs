//! `summary.json`: what a finished (or stopped) run reports, in a form other programs read — the study
//! runner uses it to skip finished cases and to build its results table, the run report to show the key
//! numbers.

use crate::run::{CurveRecord, MeshMapRecord, RunSummary, ScalarTableRecord};
use serde::{Deserialize, Serialize};
use spatter_core::control::Finished;
use std::path::{Path, PathBuf};

/// File name of the summary in a run folder.
pub const FILE: &str = "summary.json";

/// The contents of `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SummaryFile {
    /// The scenario's `kind`.
    pub kind: String,
    /// `"completed"` or `"interrupted"`.
    pub finished: String,
    /// Named scalar results in the order the run reported them; `null` for a value that is not finite.
    pub scalars: Vec<(String, Option<f64>)>,
    /// Lines the run printed at its end.
    pub headline: Vec<String>,
    /// Labelled output files, relative to the run folder where they are inside it.
    pub artifacts: Vec<(String, PathBuf)>,
    /// Wall time of the run \[s\], summed over the sessions of a stopped and resumed run.
    pub wall_time_s: f64,
    /// Worker threads used.
    pub threads: usize,
    /// The warnings among the closing lines.
    #[serde(default)]
    pub warnings: Vec<String>,
    /// Colour maps on triangle meshes, with the `.vtu` paths relative to the run folder where they are
    /// inside it.
    #[serde(default)]
    pub maps: Vec<MeshMapRecord>,
    /// Curves written as CSV columns, with the CSV paths relative to the run folder where they are inside
    /// it.
    #[serde(default)]
    pub curves: Vec<CurveRecord>,
    /// Named tables of scalars (row label → scalar name).
    #[serde(default)]
    pub scalar_tables: Vec<ScalarTableRecord>,
}

impl SummaryFile {
    /// The summary of `s` for a run of `kind` in folder `root`.
    pub fn of(s: &RunSummary, kind: &str, root: &Path, wall_time_s: f64, threads: usize) -> Self {
        SummaryFile {
            kind: kind.to_owned(),
            finished: match s.finished {
                Finished::Completed => "completed",
                Finished::Interrupted => "interrupted",
            }
            .to_owned(),
            scalars: s.scalars.iter().map(|(k, v)| (k.clone(), v.is_finite().then_some(*v))).collect(),
            headline: s.headline.clone(),
            artifacts: s
                .artifacts
                .iter()
                .map(|(l, p)| {
                    (l.clone(), p.strip_prefix(root).map(Path::to_owned).unwrap_or_else(|_| p.clone()))
                })
                .collect(),
            wall_time_s,
            threads,
            warnings: s.headline.iter().filter(|l| l.starts_with("warning")).cloned().collect(),
            maps: s
                .maps
                .iter()
                .map(|m| MeshMapRecord {
                    vtu: m.vtu.strip_prefix(root).map(Path::to_owned).unwrap_or_else(|_| m.vtu.clone()),
                    ..m.clone()
                })
                .collect(),
            curves: s
                .curves
                .iter()
                .map(|c| CurveRecord {
                    csv: c.csv.strip_prefix(root).map(Path::to_owned).unwrap_or_else(|_| c.csv.clone()),
                    ..c.clone()
                })
                .collect(),
            scalar_tables: s.scalar_tables.clone(),
        }
    }

    /// True when the run went to its end.
    pub fn completed(&self) -> bool {
        self.finished == "completed"
    }

    /// The scalar `name`, if reported (NaN when it was not finite).
    pub fn scalar(&self, name: &str) -> Option<f64> {
        self.scalars.iter().find(|(k, _)| k == name).map(|(_, v)| v.unwrap_or(f64::NAN))
    }

    /// Writes `root/summary.json` atomically (temporary file, then rename).
    pub fn write(&self, root: &Path) -> std::io::Result<()> {
        let path = root.join(FILE);
        let tmp = root.join("summary.json.tmp");
        let text = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        std::fs::write(&tmp, text + "\n")?;
        std::fs::rename(&tmp, &path)
    }

    /// Reads `root/summary.json`; `Ok(None)` when there is none.
    pub fn read(root: &Path) -> Result<Option<Self>, String> {
        let path = root.join(FILE);
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(format!("cannot read {}: {e}", path.display())),
        };
        serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| format!("{} is not a run summary: {e}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summaries_round_trip_and_keep_order_and_non_finite_values() {
        let dir = tempfile::tempdir().unwrap();
        let mut s = RunSummary::new(Finished::Completed);
        s.scalar("z_m", 0.1);
        s.scalar("a_J", f64::NAN);
        s.artifacts.push(("map".into(), dir.path().join("map.png")));
        s.maps.push(MeshMapRecord {
            label: "panel".into(),
            vtu: dir.path().join("panel.vtu"),
            array: "impacts".into(),
            view_dir: [0.0, 0.0, -1.0],
            up: [0.0, 1.0, 0.0],
            title: "panel: impacts".into(),
            colorbar_label: "impacts".into(),
            scale: Some([0.0, 0.5]),
        });
        s.curves.push(CurveRecord {
            label: "profile".into(),
            csv: dir.path().join("profile.csv"),
            x_column: "x_m".into(),
            y_column: "v_m_s".into(),
            x_label: "x [m]".into(),
            y_label: "v [m/s]".into(),
        });
        s.scalar_tables.push(ScalarTableRecord {
            label: "height per part".into(),
            rows: vec![("a".into(), "z_m".into())],
        });
        let f = SummaryFile::of(&s, "dem", dir.path(), 1.5, 2);
        f.write(dir.path()).unwrap();
        let back = SummaryFile::read(dir.path()).unwrap().unwrap();
        assert_eq!(back, f);
        assert_eq!(back.scalars[0].0, "z_m");
        assert!(back.scalar("a_J").unwrap().is_nan());
        assert_eq!(back.artifacts[0].1, Path::new("map.png"));
        assert_eq!(back.maps[0].vtu, Path::new("panel.vtu"));
        assert_eq!(back.maps[0].scale, Some([0.0, 0.5]));
        assert_eq!(back.curves[0].csv, Path::new("profile.csv"));
        assert_eq!(back.scalar_tables[0].rows[0].1, "z_m");
        assert!(back.completed());
        std::fs::write(dir.path().join(FILE), "{").unwrap();
        assert!(SummaryFile::read(dir.path()).unwrap_err().contains("not a run summary"));
        assert_eq!(SummaryFile::read(&dir.path().join("none")).unwrap(), None);
    }
}
