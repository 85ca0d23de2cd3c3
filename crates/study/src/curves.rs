//! The same curve of every case in one plot, and the same table of scalars with one column per case.
//!
//! A run records the curves it wrote as CSV columns (`summary.json` → `curves`: the file, the x and y
//! columns, the axis labels) and the tables of scalars it reported (`scalar_tables`: row label → scalar
//! name). The study overlays every case's curve of one label in `plots/curve_<label>.png` (one line per
//! case, named with its values) and lays every table out with a row per entry and a column per case, in
//! `tables/<label>.csv` and the report.

use crate::gallery::file_safe;
use crate::plan::{case_dir_name, Plan};
use crate::table::Table;
use spatter_io::plot::Chart;
use spatter_io::run::{CurveRecord, ScalarTableRecord};
use spatter_io::summary::SummaryFile;
use std::path::{Path, PathBuf};

/// One curve of several cases overlaid in one plot.
#[derive(Clone, Debug, PartialEq)]
pub struct Overlay {
    /// The curve's label as the runs recorded it.
    pub label: String,
    /// The plot.
    pub picture: PathBuf,
    /// Captions of the cases drawn, in case order.
    pub cases: Vec<String>,
}

/// A table of scalars with one column per case.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseTable {
    pub label: String,
    /// Row labels, in the order of first appearance by case.
    pub rows: Vec<String>,
    /// Case captions (the columns).
    pub cases: Vec<String>,
    /// `values[row][case]`; NaN where a case did not report the row.
    pub values: Vec<Vec<f64>>,
    /// The CSV written.
    pub csv: PathBuf,
}

/// One case's curve: its caption and its (x, y) points.
type CaseCurve = (String, Vec<(f64, f64)>);

/// One case's column of a table: its index, its (row label, scalar name) entries, its row of results.
type Column<'a> = (usize, Vec<&'a (String, String)>, Option<&'a crate::table::Row>);

/// Curves of the first `max_cases` cases overlaid per label into `out/plots/curve_<label>.png`. A case
/// whose CSV cannot be read or lacks a column is left out with a warning in the log.
pub fn overlay(plan: &Plan, out: &Path, max_cases: usize) -> Vec<Overlay> {
    let mut found: Vec<(String, Vec<CaseCurve>, CurveRecord)> = Vec::new();
    for c in plan.cases.iter().take(max_cases) {
        let dir = out.join("cases").join(case_dir_name(c.index));
        let Ok(Some(summary)) = SummaryFile::read(&dir) else { continue };
        for rec in summary.curves {
            let csv = if rec.csv.is_absolute() { rec.csv.clone() } else { dir.join(&rec.csv) };
            match read_curve(&csv, &rec.x_column, &rec.y_column) {
                Ok(points) => match found.iter_mut().find(|(l, _, _)| *l == rec.label) {
                    Some((_, lines, _)) => lines.push((plan.caption(c), points)),
                    None => found.push((rec.label.clone(), vec![(plan.caption(c), points)], rec)),
                },
                Err(e) => tracing::warn!("curves: case {}: {e}", c.index),
            }
        }
    }
    let folder = out.join("plots");
    if let Err(e) = std::fs::create_dir_all(&folder) {
        tracing::warn!("curves: cannot create {}: {e}", folder.display());
        return Vec::new();
    }
    let mut overlays = Vec::new();
    for (label, lines, rec) in found {
        let picture = folder.join(format!("curve_{}.png", file_safe(&label)));
        let mut chart =
            Chart::new(&format!("{label}: every case"), &rec.x_label, &rec.y_label).legend_right();
        for (caption, pts) in &lines {
            chart = chart.line(caption, pts);
        }
        match chart.save_png(&picture) {
            Ok(()) => {
                overlays.push(Overlay { label, picture, cases: lines.into_iter().map(|(c, _)| c).collect() })
            }
            Err(e) => tracing::warn!("curves: {}: {e}", picture.display()),
        }
    }
    overlays
}

/// The (x, y) pairs of columns `x` and `y` of a numeric CSV with a header row.
fn read_curve(csv: &Path, x: &str, y: &str) -> Result<Vec<(f64, f64)>, String> {
    let (header, rows) = spatter_io::csv::read_series(csv).map_err(|e| e.to_string())?;
    let col = |name: &str| {
        header.iter().position(|h| h.trim() == name).ok_or_else(|| {
            format!("{}: no column `{name}` (the columns are {})", csv.display(), header.join(", "))
        })
    };
    let (i, j) = (col(x)?, col(y)?);
    Ok(rows.iter().filter_map(|r| Some((*r.get(i)?, *r.get(j)?))).collect())
}

/// Every scalar table the cases recorded, with a column per case, written to `out/tables/<label>.csv`.
/// Values come from the results table, so a table reads the same as `results.csv`.
pub fn case_tables(plan: &Plan, table: &Table, out: &Path) -> Vec<CaseTable> {
    let mut records: Vec<ScalarTableRecord> = Vec::new();
    let mut per_case: Vec<(usize, Vec<ScalarTableRecord>)> = Vec::new();
    for c in &plan.cases {
        let dir = out.join("cases").join(case_dir_name(c.index));
        let Ok(Some(summary)) = SummaryFile::read(&dir) else { continue };
        for t in &summary.scalar_tables {
            if !records.iter().any(|r| r.label == t.label) {
                records.push(ScalarTableRecord { label: t.label.clone(), rows: Vec::new() });
            }
        }
        per_case.push((c.index, summary.scalar_tables));
    }
    let folder = out.join("tables");
    let mut tables = Vec::new();
    for rec in records {
        let mut rows: Vec<String> = Vec::new();
        for (_, ts) in &per_case {
            for (row, _) in ts.iter().filter(|t| t.label == rec.label).flat_map(|t| &t.rows) {
                if !rows.contains(row) {
                    rows.push(row.clone());
                }
            }
        }
        // Per case with a summary: its index, its (row, scalar) entries of this table, its row of results.
        let columns: Vec<Column> = per_case
            .iter()
            .map(|(i, ts)| {
                let entries = ts.iter().filter(|t| t.label == rec.label).flat_map(|t| &t.rows).collect();
                (*i, entries, table.rows.iter().find(|r| r.case == *i))
            })
            .collect();
        let values: Vec<Vec<f64>> = rows
            .iter()
            .map(|row| {
                columns
                    .iter()
                    .map(|(_, entries, r)| {
                        let name = entries.iter().find(|(l, _)| l == row).map(|(_, n)| n);
                        name.zip(*r)
                            .and_then(|(n, r)| r.scalars.iter().find(|(k, _)| k == n).map(|(_, v)| *v))
                            .unwrap_or(f64::NAN)
                    })
                    .collect()
            })
            .collect();
        let cases: Vec<&crate::plan::Case> =
            columns.iter().filter_map(|(i, _, _)| plan.cases.iter().find(|c| c.index == *i)).collect();
        let csv = folder.join(format!("{}.csv", file_safe(&rec.label)));
        let mut text = String::from("row");
        for c in &cases {
            text.push_str(&format!(",case_{}", c.index));
        }
        text.push('\n');
        for (row, v) in rows.iter().zip(&values) {
            text.push_str(&csv_text(row));
            for x in v {
                text.push(',');
                if x.is_finite() {
                    text.push_str(&spatter_io::fmt_f64(*x));
                }
            }
            text.push('\n');
        }
        if let Err(e) = std::fs::create_dir_all(&folder).and_then(|()| std::fs::write(&csv, text)) {
            tracing::warn!("tables: {}: {e}", csv.display());
            continue;
        }
        tables.push(CaseTable {
            label: rec.label,
            rows,
            cases: cases.iter().map(|c| plan.caption(c)).collect(),
            values,
            csv,
        });
    }
    tables
}

/// A CSV field, quoted when it holds a comma or quote.
fn csv_text(s: &str) -> String {
    if s.contains([',', '"']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_curve_reads_its_two_columns_and_a_missing_column_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("splash.csv");
        std::fs::write(&p, "bin_low_m,height_over_depth,mean_volume_m3\n0,0.125,2e-3\n0.075,0.375,1e-3\n")
            .unwrap();
        let pts = read_curve(&p, "height_over_depth", "mean_volume_m3").unwrap();
        assert_eq!(pts, vec![(0.125, 2e-3), (0.375, 1e-3)]);
        let e = read_curve(&p, "height_over_depth", "volume").unwrap_err();
        assert!(e.contains("no column `volume`") && e.contains("mean_volume_m3"), "{e}");
    }
}
