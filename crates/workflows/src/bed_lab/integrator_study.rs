//! The `integrator_study` scenario kind: the ten schemes of `spatter_dem::integrators` on the analytic
//! single-contact problems of Jasion (2013), Appendices A and B (see
//! `spatter_dem::validation::integrator_study`), swept from 10 steps up to `max_steps`, with the
//! observed orders beside the thesis's. Every key is documented in `docs/bed.md`.

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Invalid, Validate};
use spatter_core::control::Finished;
use spatter_dem::integrators::Scheme;
use spatter_dem::validation::integrator_study::{
    placements, study_row, sweep_steps, thesis_order, StudyCase, StudyRow,
};
use spatter_io::plot::{bar_chart_png, Bars, Chart};
use spatter_io::run::{RunContext, RunSummary, Smoke};

/// An integrator study.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IntegratorStudyConfig {
    /// Schemes to compare (default all ten).
    #[serde(default = "all_schemes")]
    pub schemes: Vec<Scheme>,
    /// Test problems (default all six).
    #[serde(default = "all_cases")]
    pub cases: Vec<StudyCase>,
    /// Impact placements N_FM ∈ [0, 1) as a fraction of a step (default [0, 0.5]).
    #[serde(default = "default_n_fm")]
    pub n_fm: Vec<f64>,
    /// Largest step count of the sweep (from 10, four runs per decade; default 10⁴).
    #[serde(default = "default_max_steps")]
    pub max_steps: u32,
    /// Fixed-point iterations per step of the implicit schemes BD1, BD2, BD4 (default 5).
    #[serde(default)]
    pub iterations: Option<u32>,
}

fn all_schemes() -> Vec<Scheme> {
    Scheme::ALL.to_vec()
}
fn all_cases() -> Vec<StudyCase> {
    StudyCase::ALL.to_vec()
}
fn default_n_fm() -> Vec<f64> {
    vec![0.0, 0.5]
}
fn default_max_steps() -> u32 {
    10_000
}

impl Default for IntegratorStudyConfig {
    fn default() -> Self {
        IntegratorStudyConfig {
            schemes: all_schemes(),
            cases: all_cases(),
            n_fm: default_n_fm(),
            max_steps: default_max_steps(),
            iterations: Some(5),
        }
    }
}

impl IntegratorStudyConfig {
    fn iterations(&self) -> u32 {
        self.iterations.unwrap_or(5)
    }
}

impl Validate for IntegratorStudyConfig {
    fn validate(&self, c: &mut Checker) {
        if self.schemes.is_empty() {
            c.fail("schemes", "give at least one scheme, e.g. schemes = [\"se\", \"rk4\"]");
        }
        if self.cases.is_empty() {
            c.fail("cases", "give at least one case, e.g. cases = [\"normal_damped\"]");
        }
        if self.n_fm.is_empty() {
            c.fail("n_fm", "give at least one impact placement, e.g. n_fm = [0.0, 0.5]");
        }
        for (i, v) in self.n_fm.iter().enumerate() {
            c.element("n_fm", i, |c| c.in_range("value", *v, 0.0, true, 1.0, false));
        }
        if !(100..=1_000_000).contains(&self.max_steps) {
            c.fail(
                "max_steps",
                format!(
                    "max_steps = {} must lie in 100 … 1000000 (the order fit uses runs of ≥ 100 steps)",
                    self.max_steps
                ),
            );
        }
        if let Some(0) = self.iterations {
            c.fail(
                "iterations",
                "iterations = 0: the implicit schemes BD1, BD2, BD4 need ≥ 1 fixed-point iteration per \
                 step (BD-p keeps its order with ≥ p)",
            );
        }
    }
}

impl Smoke for IntegratorStudyConfig {
    /// Sweeps to 300 steps only.
    fn smoke(&mut self) {
        self.max_steps = self.max_steps.min(300);
    }
}

/// Why an integrator study failed.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error("invalid integrator study: {}", .0.iter().map(|e| format!("{} ({})", e.message, e.key)).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Invalid>),
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("checkpoint: {0}")]
    Checkpoint(#[from] spatter_io::checkpoint::CheckpointError),
}

fn fmt_order(o: Option<f64>) -> String {
    o.map_or("round-off".to_owned(), |v| format!("{v:.2}"))
}

/// Runs the study into `ctx.dir`: `errors.csv` (every run), `orders.csv` and `orders.md` (observed
/// against nominal and thesis orders), `error_<case>_nfm<N_FM>.png` per case and placement,
/// `orders_nfm<N_FM>.png`. Checkpoints after every (case, placement) block.
pub fn run(cfg: &IntegratorStudyConfig, ctx: &RunContext) -> Result<RunSummary, StudyError> {
    Checker::run(cfg, None).map_err(StudyError::Invalid)?;
    let steps = sweep_steps(cfg.max_steps);
    let blocks: Vec<(StudyCase, f64)> =
        cfg.cases.iter().flat_map(|&c| placements(c, &cfg.n_fm).into_iter().map(move |f| (c, f))).collect();
    let mut rows: Vec<StudyRow> = if ctx.resume { ctx.load_checkpoint()? } else { Vec::new() };
    let per_block = cfg.schemes.len();
    let mut done = rows.len() / per_block.max(1);
    while done < blocks.len() {
        if ctx.control.stop_requested() {
            ctx.save_checkpoint(&rows)?;
            return Ok(RunSummary::new(Finished::Interrupted));
        }
        let (case, n_fm) = blocks[done];
        for &s in &cfg.schemes {
            rows.push(study_row(case, s, n_fm, &steps, cfg.iterations()));
        }
        done += 1;
        if ctx.checkpoint_due() {
            ctx.save_checkpoint(&rows)?;
        }
    }
    let summary = write_outputs(cfg, &rows, ctx)?;
    // A finished run leaves no checkpoint behind.
    let ckpt = ctx.dir.checkpoint_path();
    if ckpt.exists() {
        std::fs::remove_file(&ckpt)?;
    }
    Ok(summary)
}

fn write_outputs(
    cfg: &IntegratorStudyConfig,
    rows: &[StudyRow],
    ctx: &RunContext,
) -> Result<RunSummary, StudyError> {
    let f = spatter_io::fmt_f64;
    let mut err_rows = Vec::new();
    for r in rows {
        for &(dt, e) in &r.points {
            err_rows.push(vec![
                r.case.name().to_owned(),
                r.scheme.label().to_owned(),
                f(r.n_fm),
                f(dt),
                f(e),
            ]);
        }
    }
    let errors = ctx.dir.path("errors.csv");
    spatter_io::csv::write_table(&errors, &["case", "scheme", "n_fm", "dt", "error"], &err_rows)?;
    let mut order_rows = Vec::new();
    let mut md = String::from(
        "| case | N_FM | scheme | nominal | observed (ours) | thesis |\n|---|---|---|---|---|---|\n",
    );
    for r in rows {
        let thesis = thesis_order(r.case, r.scheme, r.n_fm).unwrap_or("–");
        order_rows.push(vec![
            r.case.name().to_owned(),
            f(r.n_fm),
            r.scheme.label().to_owned(),
            r.scheme.nominal_order().to_string(),
            r.observed_order.map_or("round-off".to_owned(), f),
            thesis.to_owned(),
        ]);
        md += &format!(
            "| {} | {} | {} | {} | {} | {} |\n",
            r.case.name(),
            r.n_fm,
            r.scheme.label(),
            r.scheme.nominal_order(),
            fmt_order(r.observed_order),
            thesis
        );
    }
    let orders = ctx.dir.path("orders.csv");
    spatter_io::csv::write_table(
        &orders,
        &["case", "n_fm", "scheme", "nominal_order", "observed_order", "thesis_order"],
        &order_rows,
    )?;
    let table = ctx.dir.write_text("orders.md", &md)?;
    let mut s = RunSummary::new(Finished::Completed);
    s.artifacts.push(("observed orders (table)".into(), table));
    s.artifacts.push(("observed orders".into(), orders));
    s.artifacts.push(("error of every run".into(), errors));
    // Error against step count, one picture per case and placement.
    let palette = |k: usize| spatter_io::plot::viridis(k as f64 / (cfg.schemes.len().max(2) - 1) as f64);
    let mut blocks: Vec<(StudyCase, f64)> = Vec::new();
    for r in rows {
        if !blocks.contains(&(r.case, r.n_fm)) {
            blocks.push((r.case, r.n_fm));
        }
    }
    for &(case, n_fm) in &blocks {
        let mut chart =
            Chart::new(&format!("{} — N_FM = {n_fm}", case.name()), "time step Δt (k = m = u₀ = 1)", "error")
                .log_x()
                .log_y()
                .legend_right();
        for (k, r) in rows.iter().filter(|r| r.case == case && r.n_fm == n_fm).enumerate() {
            let pts: Vec<(f64, f64)> =
                r.points.iter().filter(|p| p.1 > 0.0).map(|&(dt, e)| (dt, e.max(1e-16))).collect();
            let label = format!("{} ({})", r.scheme.label(), fmt_order(r.observed_order));
            chart = chart.line_colored(&label, &pts, palette(k));
        }
        let path = ctx.dir.path(&format!("error_{}_nfm{}.png", case.name(), n_fm));
        chart.save_png(&path)?;
        s.artifacts.push((format!("error, {} at N_FM = {n_fm}", case.name()), path));
    }
    // Observed orders per scheme, one bar group per scheme and a bar per case, for each placement.
    let mut fms: Vec<f64> = Vec::new();
    for &(_, f) in &blocks {
        if !fms.contains(&f) {
            fms.push(f);
        }
    }
    let categories: Vec<String> = cfg.schemes.iter().map(|s| s.label().to_owned()).collect();
    for &n_fm in &fms {
        let cases: Vec<StudyCase> =
            cfg.cases.iter().copied().filter(|c| placements(*c, &cfg.n_fm).contains(&n_fm)).collect();
        let values: Vec<Vec<f64>> = cases
            .iter()
            .map(|&c| {
                cfg.schemes
                    .iter()
                    .map(|&sch| {
                        rows.iter()
                            .find(|r| r.case == c && r.scheme == sch && r.n_fm == n_fm)
                            .and_then(|r| r.observed_order)
                            .unwrap_or(f64::NAN)
                    })
                    .collect()
            })
            .collect();
        let nominal: Vec<f64> = cfg.schemes.iter().map(|s| s.nominal_order() as f64).collect();
        let mut series: Vec<Bars> = vec![Bars { label: "nominal", values: &nominal, intervals: &[] }];
        for (c, v) in cases.iter().zip(&values) {
            series.push(Bars { label: c.name(), values: v, intervals: &[] });
        }
        let path = ctx.dir.path(&format!("orders_nfm{n_fm}.png"));
        bar_chart_png(
            &path,
            &format!("Observed order per scheme, N_FM = {n_fm} (missing bar: error at round-off)"),
            "observed order",
            &categories,
            &series,
        )?;
        s.artifacts.push((format!("observed orders at N_FM = {n_fm}"), path));
    }
    s.headline.push(format!(
        "{} runs of {} schemes × {} cases",
        rows.len(),
        cfg.schemes.len(),
        cfg.cases.len()
    ));
    for r in rows {
        s.scalar(
            &format!("order_{}_{}_nfm{}", r.case.name(), r.scheme.label(), r.n_fm),
            r.observed_order.unwrap_or(-1.0),
        );
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn study_writes_tables_and_pictures_and_reaches_nominal_orders() {
        // The smooth control (Jasion 2013, Appendix A: every scheme at its nominal order) through the
        // whole kind, to 10³ steps; ±0.25 (a shorter sweep than the validate case's 10⁴).
        let dir = tempfile::tempdir().unwrap();
        let rd = spatter_io::run::RunDir::create(dir.path()).unwrap();
        let ctx = RunContext::new(&rd, &spatter_core::control::Unattended, false);
        let cfg = IntegratorStudyConfig {
            cases: vec![StudyCase::Smooth, StudyCase::TangentialElastic],
            max_steps: 1000,
            ..Default::default()
        };
        let s = run(&cfg, &ctx).unwrap();
        for f in ["errors.csv", "orders.csv", "orders.md", "orders_nfm0.png", "error_smooth_nfm0.png"] {
            assert!(dir.path().join(f).is_file(), "{f} missing");
        }
        for sch in Scheme::ALL {
            let name = format!("order_smooth_{}_nfm0", sch.label());
            let v = s.scalars.iter().find(|(n, _)| *n == name).unwrap().1;
            assert!((v - sch.nominal_order() as f64).abs() < 0.25, "{name} = {v}");
        }
    }

    #[test]
    fn zero_iterations_and_bad_placements_are_refused() {
        let cfg = IntegratorStudyConfig { iterations: Some(0), n_fm: vec![1.0], ..Default::default() };
        let e = Checker::run(&cfg, None).unwrap_err();
        let text = format!("{e:?}");
        assert!(text.contains("iterations") && text.contains("n_fm"), "{text}");
    }
}
