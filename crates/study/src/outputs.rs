//! What a finished study writes: the results and cost tables, a plot of every analysed output against
//! every varied key, Sobol indices (table and chart) for a Sobol design, the maps, curves and tables of
//! scalars every case recorded side by side, and `report.html`.

use crate::curves::{case_tables, overlay, CaseTable, Overlay};
use crate::gallery::{file_safe, redraw, Gallery};
use crate::plan::{case_dir_name, Plan};
use crate::sensitivity::{indices, Indices};
use crate::spec::{design_name, DesignKind, Scale, StudyFile};
use crate::sweep::StudyError;
use crate::table::Table;
use spatter_io::plot::{bar_chart_png, Bars, Chart};
use spatter_io::report::Report;
use spatter_io::summary::SummaryFile;
use std::path::{Path, PathBuf};

/// At most this many outputs are plotted when the study does not name them.
const DEFAULT_PLOTTED: usize = 8;
/// Rows of the results table shown in the report (the CSV has all).
const REPORT_ROWS: usize = 200;
/// Cases whose maps (or first picture) the report shows side by side.
const GALLERY_CASES: usize = 36;

/// Writes every output of a finished study into `out`; returns what it wrote, labelled.
pub fn write_all(
    study: &StudyFile,
    plan: &Plan,
    table: &Table,
    out: &Path,
) -> Result<Vec<(String, PathBuf)>, StudyError> {
    let write = |name: &str, text: String| -> Result<PathBuf, StudyError> {
        let p = out.join(name);
        std::fs::write(&p, text).map_err(|source| StudyError::Io { path: p.clone(), source })?;
        Ok(p)
    };
    let mut written = vec![
        ("results table".to_owned(), write("results.csv", table.results_csv())?),
        ("cost per case".to_owned(), write("cost.csv", table.cost_csv())?),
    ];
    let outputs = analysed_outputs(study, table)?;
    let plots_dir = out.join("plots");
    std::fs::create_dir_all(&plots_dir)
        .map_err(|source| StudyError::Io { path: plots_dir.clone(), source })?;
    let mut plots = Vec::new();
    for o in &outputs {
        for (i, key) in plan.keys.iter().enumerate() {
            let p = plots_dir.join(format!("{}__{}.png", file_safe(o), file_safe(key)));
            plot_output(study, plan, table, o, i, &p)?;
            plots.push((format!("{o} against {key}"), p));
        }
    }
    let mut sobol = Vec::new();
    if let (DesignKind::Sobol, Some(d)) = (study.spec.design, plan.saltelli) {
        let mut csv = String::from(
            "output,key,first_order,first_order_low,first_order_high,total,total_low,total_high\n",
        );
        for o in &outputs {
            let f = table.column(o);
            let idx = indices(&d, &f, study.spec.bootstrap, study.spec.seed)
                .map_err(|e| StudyError::Analysis(format!("Sobol indices of `{o}`: {e}")))?;
            for (k, ix) in plan.keys.iter().zip(&idx) {
                csv.push_str(&format!(
                    "{o},{k},{},{},{},{},{},{}\n",
                    ix.first, ix.first_ci.0, ix.first_ci.1, ix.total, ix.total_ci.0, ix.total_ci.1
                ));
            }
            let p = out.join(format!("sobol_{}.png", file_safe(o)));
            sobol_chart(&p, o, &plan.keys, &idx, d.n)?;
            sobol.push((o.clone(), idx, p));
        }
        written.push(("Sobol indices".into(), write("sobol.csv", csv)?));
        for (o, _, p) in &sobol {
            written.push((format!("Sobol indices of {o}"), p.clone()));
        }
    }
    written.extend(plots.iter().cloned());
    let galleries = redraw(plan, out, GALLERY_CASES);
    for g in &galleries {
        written.push((format!("{} of every case on one colour scale", g.label), out.join("gallery")));
    }
    let overlays = overlay(plan, out, GALLERY_CASES);
    for o in &overlays {
        written.push((format!("{} of every case", o.label), o.picture.clone()));
    }
    let tables = case_tables(plan, table, out);
    for t in &tables {
        written.push((format!("{} per case", t.label), t.csv.clone()));
    }
    let report = out.join("report.html");
    let figures =
        Figures { plots: &plots, sobol: &sobol, galleries: &galleries, overlays: &overlays, tables: &tables };
    study_report(study, plan, table, &outputs, &figures, out)
        .write(&report)
        .map_err(|source| StudyError::Io { path: report.clone(), source })?;
    written.push(("study report".into(), report));
    Ok(written)
}

/// The outputs the study names, or the first scalars every case reported.
fn analysed_outputs(study: &StudyFile, table: &Table) -> Result<Vec<String>, StudyError> {
    if study.spec.outputs.is_empty() {
        return Ok(table.scalar_names.iter().take(DEFAULT_PLOTTED).cloned().collect());
    }
    for o in &study.spec.outputs {
        if !table.scalar_names.contains(o) {
            return Err(StudyError::Analysis(format!(
                "{}: outputs names \"{o}\", which no case reported; the cases report: {}",
                study.source.path.display(),
                table.scalar_names.join(", ")
            )));
        }
    }
    Ok(study.spec.outputs.clone())
}

/// `output` against varied key `i`: one line per combination of the other keys' values for a small grid,
/// points otherwise.
fn plot_output(
    study: &StudyFile,
    plan: &Plan,
    table: &Table,
    output: &str,
    i: usize,
    path: &Path,
) -> Result<(), StudyError> {
    let y = table.column(output);
    let x: Vec<f64> = plan.cases.iter().map(|c| number(&c.values[i])).collect();
    let key = &plan.keys[i];
    // The legend beside the plot: inside it would hide the points of the top right corner.
    let mut chart = Chart::new(&format!("{output} against {key}"), key, output).legend_right();
    if study.spec.vary[i].scale == Scale::Log && x.iter().all(|v| *v > 0.0) {
        chart = chart.log_x();
    }
    let mut groups: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for (c, (&xv, &yv)) in plan.cases.iter().zip(x.iter().zip(&y)) {
        let label = plan
            .keys
            .iter()
            .zip(&c.values)
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, (k, v))| format!("{} = {}", short(k), crate::plan::table_text(v)))
            .collect::<Vec<_>>()
            .join(", ");
        match groups.iter_mut().find(|(l, _)| *l == label) {
            Some((_, pts)) => pts.push((xv, yv)),
            None => groups.push((label, vec![(xv, yv)])),
        }
    }
    let lines = study.spec.design == DesignKind::Grid && groups.len() <= 7 && x.iter().all(|v| v.is_finite());
    if lines {
        for (label, mut pts) in groups {
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart = chart.line(&label, &pts);
        }
    } else {
        let pts: Vec<(f64, f64)> = x.iter().copied().zip(y.iter().copied()).collect();
        chart = chart.markers(&format!("{} cases", pts.len()), &pts, (0, 114, 178));
    }
    chart.save_png(path).map_err(|source| StudyError::Io { path: path.to_owned(), source })
}

/// The last part of a dotted key (its own name), for legends.
fn short(key: &str) -> &str {
    key.rsplit('.').next().unwrap_or(key)
}

/// A varied value as a number for plotting (booleans 0/1; strings and others NaN).
fn number(v: &toml::Value) -> f64 {
    match v {
        toml::Value::Float(x) => *x,
        toml::Value::Integer(n) => *n as f64,
        toml::Value::Boolean(b) => f64::from(u8::from(*b)),
        _ => f64::NAN,
    }
}

fn sobol_chart(
    path: &Path,
    output: &str,
    keys: &[String],
    idx: &[Indices],
    n: usize,
) -> Result<(), StudyError> {
    let first: Vec<f64> = idx.iter().map(|i| i.first).collect();
    let total: Vec<f64> = idx.iter().map(|i| i.total).collect();
    let first_ci: Vec<(f64, f64)> = idx.iter().map(|i| i.first_ci).collect();
    let total_ci: Vec<(f64, f64)> = idx.iter().map(|i| i.total_ci).collect();
    let names: Vec<String> = keys.iter().map(|k| short(k).to_owned()).collect();
    bar_chart_png(
        path,
        &format!("Sobol indices of {output} (N = {n}, 95 % bootstrap intervals)"),
        "share of the output variance",
        &names,
        &[
            Bars { label: "first order S_i", values: &first, intervals: &first_ci },
            Bars { label: "total S_Ti", values: &total, intervals: &total_ci },
        ],
    )
    .map_err(|source| StudyError::Io { path: path.to_owned(), source })
}

type SobolResult = (String, Vec<Indices>, PathBuf);

/// The pictures a study report shows.
struct Figures<'a> {
    /// Each output against each varied key.
    plots: &'a [(String, PathBuf)],
    /// Sobol indices per output (Sobol designs).
    sobol: &'a [SobolResult],
    /// Maps of every case redrawn on one colour scale.
    galleries: &'a [Gallery],
    /// Curves of every case overlaid.
    overlays: &'a [Overlay],
    /// Tables of scalars with a column per case.
    tables: &'a [CaseTable],
}

fn study_report(
    study: &StudyFile,
    plan: &Plan,
    table: &Table,
    outputs: &[String],
    figures: &Figures,
    out: &Path,
) -> Report {
    let Figures { plots, sobol, galleries, overlays, tables } = *figures;
    let title = study.spec.title.clone().unwrap_or_else(|| format!("Study {}", study.source.path.display()));
    let mut r = Report::new(&title);
    r.text(&format!(
        "{} cases of the `{}` scenario {} ({} design over {}), {:.1} s of wall time in all ({:.2} core-hours at most).",
        plan.cases.len(),
        plan.kind,
        plan.base.display(),
        design_name(study.spec.design),
        plan.keys.join(", "),
        table.total_wall_time_s(),
        table.total_wall_time_s() / 3600.0 * threads_used(plan, out) as f64,
    ));
    let warnings: Vec<String> = plan
        .cases
        .iter()
        .filter_map(|c| {
            SummaryFile::read(&out.join("cases").join(case_dir_name(c.index))).ok().flatten().map(|s| (c, s))
        })
        .flat_map(|(c, s)| {
            s.headline
                .iter()
                .filter_map(|l| l.strip_prefix("warning: "))
                .map(|w| format!("case {}: {w}", c.index))
                .collect::<Vec<_>>()
        })
        .take(50)
        .collect();
    r.warnings(warnings);
    for (o, idx, p) in sobol {
        r.heading(&format!("Sensitivity of {o}"));
        r.table(
            vec![
                "key".into(),
                "first order S_i".into(),
                "95 % interval".into(),
                "total S_Ti".into(),
                "95 % interval".into(),
            ],
            plan.keys
                .iter()
                .zip(idx)
                .map(|(k, i)| {
                    vec![
                        k.clone(),
                        format!("{:.3}", i.first),
                        format!("{:.3} … {:.3}", i.first_ci.0, i.first_ci.1),
                        format!("{:.3}", i.total),
                        format!("{:.3} … {:.3}", i.total_ci.0, i.total_ci.1),
                    ]
                })
                .collect(),
        );
        if let Err(e) = r.picture(&format!("Sobol indices of {o}"), p) {
            tracing::warn!("report: {e}");
        }
    }
    for g in galleries {
        r.heading(&format!("{}: every case on one colour scale", g.label));
        let whose = if g.fixed {
            "the scale every case fixed (values above it show in the top colour)"
        } else {
            "the range of every case's values; each case's own pictures, on its own scale, are in its folder"
        };
        r.text(&format!(
            "Colour scale {} to {} ({}) for every case: {whose}.",
            spatter_io::plot::tick_label(g.scale.0),
            spatter_io::plot::tick_label(g.scale.1),
            g.colorbar_label
        ));
        let refs: Vec<(String, &Path)> = g.pictures.iter().map(|(l, p)| (l.clone(), p.as_path())).collect();
        if let Err(e) = r.gallery(&refs) {
            tracing::warn!("report: {e}");
        }
    }
    for o in overlays {
        r.heading(&format!("{}: every case", o.label));
        if let Err(e) = r.picture(&format!("{} of {} cases", o.label, o.cases.len()), &o.picture) {
            tracing::warn!("report: {e}");
        }
    }
    for t in tables {
        r.heading(&format!("{}: every case", t.label));
        let mut header = vec![String::new()];
        header.extend(t.cases.iter().cloned());
        let rows = t
            .rows
            .iter()
            .zip(&t.values)
            .map(|(row, v)| {
                let mut cells = vec![row.clone()];
                cells.extend(v.iter().map(|x| if x.is_finite() { short_number(*x) } else { String::new() }));
                cells
            })
            .collect();
        r.table(header, rows);
    }
    cost_table(&mut r, plan, table);
    if !plots.is_empty() {
        r.heading("Outputs against the varied keys");
        for (label, p) in plots {
            if let Err(e) = r.picture(label, p) {
                tracing::warn!("report: {e}");
            }
        }
    }
    r.heading("Results");
    let mut header = vec!["case".to_owned()];
    header.extend(plan.keys.iter().cloned());
    header.extend(outputs.iter().cloned());
    let rows = table
        .rows
        .iter()
        .take(REPORT_ROWS)
        .map(|row| {
            let mut v = vec![row.case.to_string()];
            v.extend(row.values.iter().cloned());
            for o in outputs {
                let x = row.scalars.iter().find(|(k, _)| k == o).map(|(_, x)| *x);
                v.push(x.map(|x| format!("{x:.5e}")).unwrap_or_default());
            }
            v
        })
        .collect();
    r.table(header, rows);
    if table.rows.len() > REPORT_ROWS {
        r.text(&format!("First {REPORT_ROWS} of {} cases; all are in results.csv.", table.rows.len()));
    }
    let gallery: Vec<(String, PathBuf)> = plan
        .cases
        .iter()
        .take(GALLERY_CASES)
        .filter(|_| galleries.is_empty())
        .filter_map(|c| {
            let dir = out.join("cases").join(case_dir_name(c.index));
            let s = SummaryFile::read(&dir).ok().flatten()?;
            let (_, p) = s.artifacts.iter().find(|(_, p)| p.extension().is_some_and(|e| e == "png"))?;
            let p = if p.is_absolute() { p.clone() } else { dir.join(p) };
            p.is_file().then(|| (plan.caption(c), p))
        })
        .collect();
    if !gallery.is_empty() {
        r.heading("The first picture of each case");
        let refs: Vec<(String, &Path)> = gallery.iter().map(|(l, p)| (l.clone(), p.as_path())).collect();
        if let Err(e) = r.gallery(&refs) {
            tracing::warn!("report: {e}");
        }
    }
    r.heading("Input");
    r.pre("the study file", &study.source.text);
    r
}

/// The cost of every case (particles, steps, wall time, threads, core-hours) and the total.
fn cost_table(r: &mut Report, plan: &Plan, table: &Table) {
    let costs = table.costs();
    r.heading("Cost per case");
    let cell = |v: Option<f64>| v.map(|x| format!("{x:.0}")).unwrap_or_default();
    let mut rows: Vec<Vec<String>> = costs
        .iter()
        .map(|c| {
            let caption = plan.cases.iter().find(|k| k.index == c.case).map(|k| plan.caption(k));
            vec![
                caption.unwrap_or_else(|| format!("case {}", c.case)),
                cell(c.particles),
                cell(c.wall_particles),
                cell(c.steps),
                format!("{:.1}", c.wall_time_s),
                c.threads.to_string(),
                format!("{:.4}", c.core_hours()),
                c.particle_steps_per_s().map(|x| format!("{x:.3e}")).unwrap_or_default(),
            ]
        })
        .collect();
    rows.push(vec![
        "all cases".into(),
        String::new(),
        String::new(),
        String::new(),
        format!("{:.1}", costs.iter().map(|c| c.wall_time_s).sum::<f64>()),
        String::new(),
        format!("{:.4}", costs.iter().map(|c| c.core_hours()).sum::<f64>()),
        String::new(),
    ]);
    r.table(
        [
            "case",
            "particles",
            "wall particles",
            "steps",
            "wall time [s]",
            "threads",
            "core-hours",
            "particle-steps/s",
        ]
        .map(String::from)
        .to_vec(),
        rows,
    );
}

/// A number with four significant digits, in plain notation between 10⁻³ and 10⁴ (and for 0).
fn short_number(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 {
        "0".to_owned()
    } else if (1e-3..1e4).contains(&a) {
        let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        format!("{x:.digits$}")
    } else {
        format!("{x:.3e}")
    }
}

/// Threads the first case ran with (for the core-hours estimate).
fn threads_used(plan: &Plan, out: &Path) -> usize {
    plan.cases
        .first()
        .and_then(|c| SummaryFile::read(&out.join("cases").join(case_dir_name(c.index))).ok().flatten())
        .map(|s| s.threads.max(1))
        .unwrap_or(1)
}

#[cfg(test)]
mod tests {
    use super::short_number;

    #[test]
    fn short_numbers_keep_four_significant_digits() {
        assert_eq!(short_number(0.0), "0");
        assert_eq!(short_number(0.091234), "0.09123");
        assert_eq!(short_number(1.0), "1.000");
        assert_eq!(short_number(1234.56), "1235");
        assert_eq!(short_number(2.5e-5), "2.500e-5");
        assert_eq!(short_number(-3.0e6), "-3.000e6");
    }
}
