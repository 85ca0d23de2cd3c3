//! Running a study: every case (or one shard of them) in its own folder, finished cases skipped and
//! interrupted ones resumed on a rerun, then the results table, plots and report.
//!
//! Layout of a study folder:
//!
//! ```text
//! OUT/plan.csv                 every case and its values (written first; identifies the study)
//! OUT/cases/case_00007/        one run folder per case: case.toml (its scenario), run.toml,
//!                              summary.json, the kind's outputs; error.txt when the case failed
//! OUT/results.csv              one row per case: varied keys, status, every scalar output
//! OUT/cost.csv                 wall time per case
//! OUT/sobol.csv, *.png         sensitivity indices and plots
//! OUT/report.html              everything above on one self-contained page
//! ```
//!
//! Shards (`--shard i/n`) share one folder (a cluster's shared file system): each runs every n-th case,
//! starting at case i − 1, and [`collect`] builds the table once all have finished. Because the table is
//! built from the case folders alone, one run, several shards, or a run killed and repeated all give the
//! same table byte for byte.

use crate::plan::{case_dir_name, table_text, Case, Plan};
use crate::spec::StudyFile;
use crate::table::Table;
use spatter_core::control::RunControl;
use spatter_io::summary::SummaryFile;
use std::path::{Path, PathBuf};

/// Runs one case; the program that starts a study provides it (the CLI runs cases in-process through the
/// job driver).
pub trait CaseRunner {
    /// Runs the scenario file `scenario` with `dir` as its run folder, continuing from the checkpoint in
    /// `dir` when `resume`. On `Ok`, `dir/summary.json` says whether the case completed.
    fn run_case(&self, scenario: &Path, dir: &Path, resume: bool) -> Result<(), String>;
    /// True once the study should stop (Ctrl-C, SIGTERM).
    fn stop_requested(&self) -> bool;
}

/// How to run a study.
#[derive(Clone, Debug)]
pub struct SweepOptions {
    /// The study folder.
    pub out: PathBuf,
    /// `Some((i, n))`: run shard i of n (1-based) and leave the table to [`collect`].
    pub shard: Option<(usize, usize)>,
    /// Delete the cases of a different study found in `out`, and cases whose scenario changed since they
    /// ran, instead of refusing.
    pub overwrite: bool,
}

/// What a study run did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SweepOutcome {
    /// Cases run to completion now.
    pub ran: usize,
    /// Cases skipped because an earlier run finished them.
    pub skipped: usize,
    /// Cases that failed (their folder holds `error.txt`).
    pub failed: Vec<usize>,
    /// The study stopped on request before its last case.
    pub interrupted: bool,
    /// Files written by [`collect`] (empty for a shard or an interrupted run).
    pub written: Vec<(String, PathBuf)>,
}

/// A study that cannot run or be collected.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    #[error("{0}")]
    Folder(String),
    #[error("cannot write {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("{0}")]
    Incomplete(String),
    #[error("{0}")]
    Analysis(String),
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> StudyError + '_ {
    move |source| StudyError::Io { path: path.to_owned(), source }
}

/// The study's own log, which may exist before the plan is written.
pub const LOG_FILE: &str = "study_log.txt";

/// The text of `plan.csv`: the case index and every varied value.
pub fn plan_csv(plan: &Plan) -> String {
    let mut s = String::from("case");
    for k in &plan.keys {
        s.push(',');
        s.push_str(k);
    }
    s.push('\n');
    for c in &plan.cases {
        s.push_str(&c.index.to_string());
        for v in &c.values {
            s.push(',');
            s.push_str(&table_text(v));
        }
        s.push('\n');
    }
    s
}

/// Prepares `opts.out` for `plan`: refuses (or with `overwrite` clears) a folder that holds another
/// study's cases or another run's files, and writes `plan.csv`.
fn prepare(plan: &Plan, opts: &SweepOptions) -> Result<(), StudyError> {
    let out = &opts.out;
    std::fs::create_dir_all(out).map_err(io_err(out))?;
    let plan_path = out.join("plan.csv");
    let ours = plan_csv(plan);
    let theirs = std::fs::read_to_string(&plan_path).ok();
    let foreign = match &theirs {
        Some(t) => t != &ours,
        // No plan: the folder must not hold anything else of substance.
        None => std::fs::read_dir(out).map_err(io_err(out))?.flatten().any(|e| e.file_name() != LOG_FILE),
    };
    if foreign {
        if !opts.overwrite {
            let what = if theirs.is_some() {
                "the cases of a different study (its plan.csv differs)"
            } else {
                "files that are not a study's"
            };
            return Err(StudyError::Folder(format!(
                "{} holds {what}; choose another --out folder or pass --overwrite to delete them",
                out.display()
            )));
        }
        for sub in ["cases", "plots"] {
            let p = out.join(sub);
            if p.exists() {
                std::fs::remove_dir_all(&p).map_err(io_err(&p))?;
            }
        }
        for entry in std::fs::read_dir(out).map_err(io_err(out))?.flatten() {
            if entry.path().is_file() && entry.file_name() != LOG_FILE {
                std::fs::remove_file(entry.path()).map_err(io_err(&entry.path()))?;
            }
        }
    }
    if theirs.as_deref() != Some(ours.as_str()) {
        std::fs::write(&plan_path, ours).map_err(io_err(&plan_path))?;
    }
    Ok(())
}

/// The cases among `cases` whose folder in `out` holds a `case.toml` other than the scenario the study now
/// gives them: the base scenario (or a default) changed since they ran, so their results are stale.
fn stale<'a>(cases: impl IntoIterator<Item = &'a Case>, out: &Path) -> Vec<usize> {
    cases
        .into_iter()
        .filter(|c| {
            let input = out.join("cases").join(case_dir_name(c.index)).join("case.toml");
            std::fs::read_to_string(input).is_ok_and(|existing| existing != c.text)
        })
        .map(|c| c.index)
        .collect()
}

/// "case 3, case 7, … (and N more)" for messages.
fn case_list(indices: &[usize]) -> String {
    let mut list: Vec<String> = indices.iter().take(12).map(|i| format!("case {i}")).collect();
    if indices.len() > 12 {
        list.push(format!("and {} more", indices.len() - 12));
    }
    list.join(", ")
}

/// Before any case runs: refuses stale cases (see [`stale`]), or with `overwrite` deletes their folders
/// (checkpoints included: they belong to the old scenario) and the study's collected results, which
/// describe them.
fn clear_stale(cases: &[&Case], out: &Path, overwrite: bool) -> Result<(), StudyError> {
    let changed = stale(cases.iter().copied(), out);
    if changed.is_empty() {
        return Ok(());
    }
    if !overwrite {
        return Err(StudyError::Folder(format!(
            "{}: the scenario of {} differs from what this study now gives them (the base scenario changed \
             since they ran), so their results are stale; pass --overwrite to run them afresh",
            out.display(),
            case_list(&changed)
        )));
    }
    for &i in &changed {
        let dir = out.join("cases").join(case_dir_name(i));
        std::fs::remove_dir_all(&dir).map_err(io_err(&dir))?;
    }
    for entry in std::fs::read_dir(out).map_err(io_err(out))?.flatten() {
        let (path, name) = (entry.path(), entry.file_name());
        if name == "cases" || name == "plan.csv" || name == LOG_FILE {
            continue;
        }
        if path.is_dir() {
            std::fs::remove_dir_all(&path).map_err(io_err(&path))?;
        } else {
            std::fs::remove_file(&path).map_err(io_err(&path))?;
        }
    }
    Ok(())
}

/// Runs the cases of `plan` (those of the shard, if one is given) and, for a whole study, collects the
/// results. Finished cases are skipped, interrupted cases resume from their checkpoint.
pub fn run_study(
    study: &StudyFile,
    plan: &Plan,
    opts: &SweepOptions,
    runner: &dyn CaseRunner,
    progress: &dyn RunControl,
) -> Result<SweepOutcome, StudyError> {
    if let Some((i, n)) = opts.shard {
        if n == 0 || i == 0 || i > n {
            return Err(StudyError::Folder(format!(
                "--shard {i}/{n}: a shard is i/n with 1 ≤ i ≤ n (for example 1/4 … 4/4)"
            )));
        }
    }
    prepare(plan, opts)?;
    let cases: Vec<_> = match opts.shard {
        Some((i, n)) => plan.shard(i, n).collect(),
        None => plan.cases.iter().collect(),
    };
    clear_stale(&cases, &opts.out, opts.overwrite)?;
    let mut outcome =
        SweepOutcome { ran: 0, skipped: 0, failed: Vec::new(), interrupted: false, written: Vec::new() };
    for (done, case) in cases.iter().enumerate() {
        progress.progress(done as u64, cases.len() as u64);
        if runner.stop_requested() {
            outcome.interrupted = true;
            return Ok(outcome);
        }
        let dir = opts.out.join("cases").join(case_dir_name(case.index));
        let input = dir.join("case.toml");
        let summary = SummaryFile::read(&dir).map_err(StudyError::Folder)?;
        if summary.as_ref().is_some_and(SummaryFile::completed) {
            outcome.skipped += 1;
            continue;
        }
        std::fs::create_dir_all(&dir).map_err(io_err(&dir))?;
        if !input.is_file() {
            std::fs::write(&input, &case.text).map_err(io_err(&input))?;
        }
        std::fs::remove_file(dir.join("error.txt")).ok();
        let resume = dir.join("checkpoint.bin").is_file();
        progress.status(&format!("case {} of {}", case.index, plan.cases.len()));
        tracing::info!(
            "study case {} → {}{}",
            case.index,
            dir.display(),
            if resume { " (resumed)" } else { "" }
        );
        match runner.run_case(&input, &dir, resume) {
            Ok(()) => match SummaryFile::read(&dir).map_err(StudyError::Folder)? {
                Some(s) if s.completed() => outcome.ran += 1,
                Some(_) => {
                    outcome.interrupted = true;
                    return Ok(outcome);
                }
                None => {
                    let msg = "the case ended without writing summary.json";
                    std::fs::write(dir.join("error.txt"), msg).ok();
                    outcome.failed.push(case.index);
                }
            },
            Err(msg) => {
                tracing::warn!("study case {} failed: {msg}", case.index);
                std::fs::write(dir.join("error.txt"), format!("{msg}\n")).map_err(io_err(&dir))?;
                outcome.failed.push(case.index);
            }
        }
    }
    progress.progress(cases.len() as u64, cases.len() as u64);
    if opts.shard.is_none() && outcome.failed.is_empty() {
        outcome.written = collect(study, plan, &opts.out)?;
    }
    Ok(outcome)
}

/// Builds the results table, plots, sensitivity indices and report of a study from its case folders;
/// refuses, naming them, when cases have not finished (a shard still running, or failed cases).
pub fn collect(study: &StudyFile, plan: &Plan, out: &Path) -> Result<Vec<(String, PathBuf)>, StudyError> {
    let plan_path = out.join("plan.csv");
    match std::fs::read_to_string(&plan_path) {
        Ok(t) if t == plan_csv(plan) => {}
        Ok(_) => {
            return Err(StudyError::Folder(format!(
                "{} belongs to a different study (plan.csv differs from this study's cases)",
                out.display()
            )))
        }
        Err(_) => {
            return Err(StudyError::Folder(format!(
                "{} holds no plan.csv: run the study (or its shards) with this --out folder first",
                out.display()
            )))
        }
    }
    let changed = stale(&plan.cases, out);
    if !changed.is_empty() {
        return Err(StudyError::Folder(format!(
            "{}: {} ran with another scenario than this study now gives them (the base scenario changed \
             since); rerun the study (or its shards) with --overwrite and collect again",
            out.display(),
            case_list(&changed)
        )));
    }
    let table = Table::read(plan, out);
    let missing = table.unfinished();
    if !missing.is_empty() {
        let list: Vec<String> = missing.iter().take(12).map(|(i, why)| format!("case {i} ({why})")).collect();
        return Err(StudyError::Incomplete(format!(
            "{} of {} cases have not finished: {}{}; run the missing shards (or rerun the study) and collect again",
            missing.len(),
            plan.cases.len(),
            list.join(", "),
            if missing.len() > 12 { ", …" } else { "" }
        )));
    }
    crate::outputs::write_all(study, plan, &table, out)
}
