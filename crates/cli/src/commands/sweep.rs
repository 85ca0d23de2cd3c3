//! `spatter sweep STUDY` and `spatter sweep collect STUDY`: parameter studies (crate `spatter-study`).

use super::{report_errors, EXIT_BAD_INPUT};
use crate::control::{install_signal_handler, CliControl};
use anyhow::{Context, Result};
use spatter_core::control::RunControl;
use spatter_study::{CaseRunner, Plan, StudyFile, SweepOptions};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Parses `--shard i/n`.
pub fn parse_shard(text: &str) -> Result<(usize, usize), String> {
    let bad = || format!("--shard {text}: expected i/n with whole numbers 1 ≤ i ≤ n, e.g. 2/8");
    let (i, n) = text.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (i.trim().parse().map_err(|_| bad())?, n.trim().parse().map_err(|_| bad())?);
    if i == 0 || n == 0 || i > n {
        return Err(bad());
    }
    Ok((i, n))
}

fn default_out(study: &Path) -> PathBuf {
    let stem = study.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "study".into());
    PathBuf::from("runs").join(stem)
}

/// Reads the study and plans its cases; `Err(code)` after printing the errors.
fn plan(study_path: &Path, out: &Path) -> Result<(StudyFile, Plan), ExitCode> {
    let study = StudyFile::read(study_path).map_err(|e| {
        report_errors(&e);
        ExitCode::from(EXIT_BAD_INPUT)
    })?;
    let plan = Plan::new(&study, &out.join("cases")).map_err(|e| {
        report_errors(&e);
        ExitCode::from(EXIT_BAD_INPUT)
    })?;
    Ok((study, plan))
}

/// Runs every case in-process, one after another, each through the job driver in its folder with its
/// own log (the study's log is open again between cases).
struct InProcess<'a> {
    control: &'a CliControl,
}

impl CaseRunner for InProcess<'_> {
    fn run_case(&self, scenario: &Path, dir: &Path, resume: bool) -> Result<(), String> {
        let loaded = spatter_scenario::load(scenario)
            .map_err(|errors| errors.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("\n"))?;
        // A case without a checkpoint starts afresh: the files of an earlier, failed attempt go; the
        // study's case.toml stays.
        let opts = spatter_scenario::job::JobOptions {
            resume,
            overwrite: !resume,
            keep: vec!["case.toml".into()],
            ..spatter_scenario::job::JobOptions::new(dir)
        };
        spatter_scenario::job::run(&loaded, &opts, self.control).map(|_| ()).map_err(|e| e.to_string())
    }

    fn stop_requested(&self) -> bool {
        self.control.stop_requested()
    }
}

/// `spatter sweep STUDY`.
pub fn sweep(
    study_path: &Path,
    out: Option<&Path>,
    shard: Option<(usize, usize)>,
    threads: Option<usize>,
    overwrite: bool,
) -> Result<ExitCode> {
    let out = out.map(Path::to_owned).unwrap_or_else(|| default_out(study_path));
    let (study, plan) = match plan(study_path, &out) {
        Ok(p) => p,
        Err(code) => return Ok(code),
    };
    super::run::set_threads(threads)?;
    install_signal_handler();
    let control = CliControl::new(false);
    if let Some(note) = crate::logging::init(control.bar(), 0, false) {
        eprintln!("note: {note}");
    }
    let log = out_log(&out)?;
    spatter_io::runlog::open(&log, log.is_file())
        .with_context(|| format!("cannot open {}", log.display()))?;
    let cases = match shard {
        Some((i, n)) => plan.shard(i, n).count(),
        None => plan.cases.len(),
    };
    println!(
        "study {}: {} cases of `{}` ({}){}, into {}",
        study_path.display(),
        plan.cases.len(),
        plan.kind,
        plan.keys.join(", "),
        shard.map(|(i, n)| format!(", shard {i}/{n} runs {cases} of them")).unwrap_or_default(),
        out.display()
    );
    let opts = SweepOptions { out: out.clone(), shard, overwrite };
    let runner = InProcess { control: &control };
    let result = super::run::on_worker(&spatter_core::comm::SERIAL, || {
        spatter_study::run_study(&study, &plan, &opts, &runner, &control)
    });
    control.finish();
    let outcome = result?;
    println!(
        "{} cases run, {} already finished{}",
        outcome.ran,
        outcome.skipped,
        if outcome.failed.is_empty() { String::new() } else { format!(", {} failed", outcome.failed.len()) }
    );
    for i in &outcome.failed {
        eprintln!(
            "error: case {i} failed; see {}",
            out.join("cases").join(spatter_study::plan::case_dir_name(*i)).join("error.txt").display()
        );
    }
    if outcome.interrupted {
        println!(
            "stopped; finished cases are kept. Continue with:\n  spatter sweep {} --out {}{}",
            study_path.display(),
            out.display(),
            shard.map(|(i, n)| format!(" --shard {i}/{n}")).unwrap_or_default()
        );
        return Ok(ExitCode::from(130));
    }
    for (label, path) in &outcome.written {
        println!("  {label}: {}", path.display());
    }
    if let Some((i, n)) = shard {
        println!(
            "shard {i}/{n} done. When every shard has finished:\n  spatter sweep collect {} --out {}",
            study_path.display(),
            out.display()
        );
    }
    Ok(if outcome.failed.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// The study's own log file (cases log into it too while one logger serves the process).
fn out_log(out: &Path) -> Result<PathBuf> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    Ok(out.join(spatter_study::sweep::LOG_FILE))
}

/// `spatter sweep collect STUDY`.
pub fn collect(study_path: &Path, out: Option<&Path>) -> Result<ExitCode> {
    let out = out.map(Path::to_owned).unwrap_or_else(|| default_out(study_path));
    let (study, plan) = match plan(study_path, &out) {
        Ok(p) => p,
        Err(code) => return Ok(code),
    };
    let written = spatter_study::collect(&study, &plan, &out)?;
    println!("study {}: {} cases collected", study_path.display(), plan.cases.len());
    for (label, path) in &written {
        println!("  {label}: {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::parse_shard;

    #[test]
    fn shards_parse_and_bad_ones_are_refused() {
        assert_eq!(parse_shard("2/8"), Ok((2, 8)));
        for bad in ["3/2", "0/2", "1/0", "a/b", "2", "-1/2"] {
            assert!(parse_shard(bad).unwrap_err().contains(bad), "{bad}");
        }
    }
}
