//! The `forces` scenario kind and `spatter forces <scenario>`: the nondimensional reference magnitude
//! of every particle–fluid force for given scales (Jasion 2013 Table 6.4, eq. 6.7–6.10), and the
//! accelerations the force library gives at the reference state.

use super::config::ForcesConfig;
use spatter_core::check::{Checker, Invalid};
use spatter_core::control::Finished;
use spatter_flow::forces::ranking::{physical_magnitudes, reference_terms, Ranking, RankingInput};
use spatter_io::run::{RunContext, RunSummary};

/// The ranking input of a `forces` scenario.
pub fn ranking_input(cfg: &ForcesConfig) -> RankingInput {
    RankingInput {
        fluid: cfg.fluid,
        particle_density: cfg.particle_density,
        velocity: cfg.velocity_scale,
        surface_energy: cfg.surface_energy,
        gravity: cfg.gravity,
        diameters: cfg.diameters.clone(),
        factors: cfg.factors,
    }
}

/// Both tables: the reference terms as printed by the thesis and the library's accelerations / g.
pub fn rankings(cfg: &ForcesConfig) -> (Ranking, Ranking) {
    let input = ranking_input(cfg);
    (reference_terms(&input), physical_magnitudes(&input))
}

/// A diameter for a column header: "10 µm", "2.5 µm", "1.5 mm".
fn fmt_d(d: f64) -> String {
    let (v, unit) = if d < 1e-3 { (d * 1e6, "µm") } else { (d * 1e3, "mm") };
    let s = format!("{v:.3}");
    format!("{} {unit}", s.trim_end_matches('0').trim_end_matches('.'))
}

/// A ranking as screen lines: one row per force, one column per diameter.
pub fn format_table(title: &str, r: &Ranking) -> Vec<String> {
    let mut out = vec![title.to_owned()];
    let mut head = format!("{:<10} {:<38} {:>3}", "symbol", "force", "dir");
    for d in &r.diameters {
        head += &format!(" {:>12}", fmt_d(*d));
    }
    out.push(head);
    let mut re = format!("{:<10} {:<38} {:>3}", "Re_0", "particle Reynolds number at u_0", "");
    for v in &r.reynolds {
        re += &format!(" {:>12.4e}", v);
    }
    out.push(re);
    for row in &r.rows {
        let mut l = format!("{:<10} {:<38} {:>3}", row.symbol, row.name, row.direction);
        for v in &row.values {
            l += &format!(" {:>12.4e}", v);
        }
        out.push(l);
    }
    out
}

/// Screen lines of `spatter forces <scenario>`.
pub fn report(cfg: &ForcesConfig) -> Vec<String> {
    let (refs, phys) = rankings(cfg);
    let mut out =
        format_table("Reference magnitudes F_φ0 (Jasion 2013 eq. 3.86–3.96 as printed; Table 6.4):", &refs);
    out.push(String::new());
    out.extend(format_table("Force library at the reference state, acceleration / g:", &phys));
    out
}

fn write_csv(path: &std::path::Path, r: &Ranking) -> std::io::Result<()> {
    let mut header = vec!["symbol".to_owned(), "force".to_owned(), "direction".to_owned()];
    header.extend(r.diameters.iter().map(|d| format!("d_{}_m", spatter_io::fmt_f64(*d))));
    let mut rows = vec![{
        let mut v = vec!["Re_0".to_owned(), "particle Reynolds number at u_0".to_owned(), String::new()];
        v.extend(r.reynolds.iter().map(|x| spatter_io::fmt_f64(*x)));
        v
    }];
    for row in &r.rows {
        let mut v = vec![row.symbol.to_owned(), row.name.to_owned(), row.direction.to_owned()];
        v.extend(row.values.iter().map(|x| spatter_io::fmt_f64(*x)));
        rows.push(v);
    }
    let h: Vec<&str> = header.iter().map(String::as_str).collect();
    spatter_io::csv::write_table(path, &h, &rows)
}

/// Why a `forces` run failed.
#[derive(Debug, thiserror::Error)]
pub enum ForcesError {
    #[error("invalid forces configuration: {}", .0.iter().map(|e| format!("{} ({})", e.message, e.key)).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Invalid>),
    #[error("{0}")]
    Io(#[from] std::io::Error),
}

/// Runs a `forces` scenario: writes `force_ranking.csv` and `force_magnitudes.csv`, returns the table.
/// The configuration is validated first (scenario files already are; a Rust caller may not have).
pub fn run(cfg: &ForcesConfig, ctx: &RunContext) -> Result<RunSummary, ForcesError> {
    Checker::run(cfg, None).map_err(ForcesError::Invalid)?;
    let (refs, phys) = rankings(cfg);
    let a = ctx.dir.path("force_ranking.csv");
    write_csv(&a, &refs)?;
    let b = ctx.dir.path("force_magnitudes.csv");
    write_csv(&b, &phys)?;
    let mut s = RunSummary::new(Finished::Completed);
    s.headline = report(cfg);
    s.artifacts.push(("reference magnitudes".into(), a));
    s.artifacts.push(("force library magnitudes / g".into(), b));
    // The ranked numbers: each reference force per diameter (nondimensional, as in the table).
    for row in &refs.rows {
        for (d, v) in refs.diameters.iter().zip(&row.values) {
            s.scalar(&format!("{}_at_{}um", row.symbol, spatter_io::fmt_f64(d * 1e6)), *v);
        }
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_flow::forces::Fluid;

    pub(crate) fn table_6_4() -> ForcesConfig {
        ForcesConfig {
            fluid: Fluid { density: 1.19, viscosity: 1.82e-5 },
            particle_density: 2480.0,
            velocity_scale: 6.0,
            surface_energy: 2e-4,
            gravity: 9.81,
            diameters: vec![10e-6, 300e-6, 500e-6],
            factors: Default::default(),
        }
    }

    #[test]
    fn forces_run_writes_the_table() {
        let dir = tempfile::tempdir().unwrap();
        let rd = spatter_io::run::RunDir::create(dir.path()).unwrap();
        let ctx = RunContext::new(&rd, &spatter_core::control::Unattended, false);
        let s = run(&table_6_4(), &ctx).unwrap();
        let text = std::fs::read_to_string(dir.path().join("force_ranking.csv")).unwrap();
        // Table 6.4 drag reference for 10 µm: 2.202e-3 (Jasion 2013).
        let drag = text.lines().find(|l| l.starts_with("F_D0")).unwrap();
        let v: f64 = drag.split(',').nth(3).unwrap().parse().unwrap();
        assert!((v - 2.202e-3).abs() < 5e-7, "{drag}");
        let crit = text.lines().find(|l| l.starts_with("A_H/F_D0")).unwrap();
        let v: f64 = crit.split(',').nth(4).unwrap().parse().unwrap();
        assert!((v - 9.90).abs() < 0.005, "{crit}");
        assert!(s.headline.iter().any(|l| l.contains("F_S0")));
    }

    #[test]
    fn forces_run_refuses_an_invalid_configuration() {
        let dir = tempfile::tempdir().unwrap();
        let rd = spatter_io::run::RunDir::create(dir.path()).unwrap();
        let ctx = RunContext::new(&rd, &spatter_core::control::Unattended, false);
        let mut cfg = table_6_4();
        cfg.velocity_scale = 0.0;
        let e = run(&cfg, &ctx).unwrap_err().to_string();
        assert!(e.contains("velocity_scale_m_s"), "{e}");
        assert!(!dir.path().join("force_ranking.csv").exists());
    }
}
