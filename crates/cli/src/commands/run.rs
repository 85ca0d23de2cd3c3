//! `spatter run` and `spatter demo`.

use super::{report_errors, EXIT_BAD_INPUT};
use crate::control::{install_ctrlc, CliControl};
use anyhow::{Context, Result};
use spatter_core::control::Finished;
use spatter_io::run::{RunContext, RunDir};
use spatter_io::summary::SummaryFile;
use spatter_scenario::Loaded;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The built-in scenario `spatter demo` runs (the same text as the example file).
pub const DEMO_SCENARIO: (&str, &str) = crate::registry::DEMO_SCENARIO;

/// `spatter run <scenario>`.
pub fn run_file(path: &Path, out: Option<&Path>, threads: Option<usize>, resume: bool) -> Result<ExitCode> {
    let loaded = match spatter_scenario::load(path) {
        Ok(l) => l,
        Err(errors) => {
            report_errors(&errors);
            return Ok(ExitCode::from(EXIT_BAD_INPUT));
        }
    };
    let out = out.map(Path::to_owned).unwrap_or_else(|| default_out(path));
    let again = format!("spatter run {} --out {} --resume", path.display(), out.display());
    execute(loaded, &out, threads, resume, &again)
}

/// `spatter demo`.
pub fn demo(out: &Path, threads: Option<usize>) -> Result<ExitCode> {
    let (name, text) = DEMO_SCENARIO;
    let loaded = spatter_scenario::load_str(Path::new(name), text).map_err(|errors| {
        anyhow::anyhow!(
            "the built-in scenario is invalid: {}",
            errors.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("; ")
        )
    })?;
    println!("spatter demo: running the built-in scenario `{name}` ({})", loaded.scenario.kind());
    execute(loaded, out, threads, false, &format!("spatter run {name} --out {} --resume", out.display()))
}

/// Runs `loaded` in `dir` (whose `run.toml` is written), then writes `summary.json` and `report.html`
/// there; returns the summary and the wall time \[s\].
pub fn run_in_dir(
    loaded: &Loaded,
    dir: &RunDir,
    control: &dyn spatter_core::control::RunControl,
    resume: bool,
) -> Result<(spatter_io::run::RunSummary, f64)> {
    let ctx = RunContext { dir, control, resume };
    let started = Instant::now();
    let summary = loaded.scenario.run(&ctx).map_err(|e| anyhow::anyhow!("{e}"))?;
    let secs = started.elapsed().as_secs_f64();
    let kind = loaded.scenario.kind();
    SummaryFile::of(&summary, kind, dir.root(), secs, rayon::current_num_threads())
        .write(dir.root())
        .with_context(|| format!("cannot write the summary in {}", dir.root().display()))?;
    let title = format!("{} — {kind}", loaded.source.path.display());
    if let Err(e) = spatter_io::report::write_run_report(dir.root(), &title) {
        tracing::warn!("no report.html: {e}");
    }
    Ok((summary, secs))
}

/// Sizes the global worker pool (`--threads`); all cores when `None`.
pub fn set_threads(threads: Option<usize>) -> Result<()> {
    if let Some(n) = threads {
        anyhow::ensure!(n >= 1, "--threads must be at least 1");
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global()
            .context("cannot set up worker threads")?;
    }
    Ok(())
}

fn default_out(scenario: &Path) -> PathBuf {
    let stem = scenario.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "run".into());
    PathBuf::from("runs").join(stem)
}

fn execute(
    loaded: Loaded,
    out: &Path,
    threads: Option<usize>,
    resume: bool,
    resume_hint: &str,
) -> Result<ExitCode> {
    set_threads(threads)?;
    let dir = RunDir::create(out)?;
    let checkpoint = dir.checkpoint_path();
    if resume && !checkpoint.is_file() {
        anyhow::bail!(
            "--resume: {} holds no checkpoint.bin; run without --resume to start afresh",
            out.display()
        );
    }
    if !resume && checkpoint.is_file() {
        eprintln!(
            "note: {} holds a checkpoint of an unfinished run; starting afresh (use --resume to continue it)",
            out.display()
        );
        std::fs::remove_file(&checkpoint).ok();
    }
    let resolved = loaded.scenario.resolved_toml().map_err(anyhow::Error::msg)?;
    if !resume {
        std::fs::remove_file(dir.root().join("log.txt")).ok();
    }
    dir.write_text("run.toml", &resolved)?;

    install_ctrlc();
    let control = CliControl::new();
    crate::logging::init(Some(&dir.root().join("log.txt")), control.bar())?;
    tracing::info!(
        "spatter {} {} scenario {} → {}{}",
        env!("CARGO_PKG_VERSION"),
        loaded.scenario.kind(),
        loaded.source.path.display(),
        out.display(),
        if resume { " (resumed)" } else { "" }
    );
    tracing::info!("threads: {}", rayon::current_num_threads());
    let result = run_in_dir(&loaded, &dir, &control, resume);
    control.finish();
    let (summary, secs) = result?;
    for line in &summary.headline {
        println!("{line}");
        tracing::info!("{line}");
    }
    for (label, path) in &summary.artifacts {
        println!("  {label}: {}", path.display());
    }
    match summary.finished {
        Finished::Completed => {
            println!("done in {secs:.1} s; results in {}", out.display());
            tracing::info!("completed in {secs:.3} s");
            Ok(ExitCode::SUCCESS)
        }
        Finished::Interrupted => {
            println!(
                "stopped after {secs:.1} s; outputs so far are in {}. Continue with:\n  {resume_hint}",
                out.display()
            );
            tracing::info!("interrupted after {secs:.3} s; checkpoint written");
            Ok(ExitCode::from(130))
        }
    }
}
