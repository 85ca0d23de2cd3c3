//! The job driver: everything `spatter run` does around a scenario, the same for every kind.
//!
//! [`run`] prepares the run folder (refusing one that holds another run's files unless told to
//! overwrite), writes the resolved input `run.toml`, points the log at `log.txt`, runs the scenario with
//! periodic checkpoints (every [`JobOptions::checkpoint_interval_s`] of wall time) and stop requests
//! (SIGINT, SIGTERM, through the caller's [`RunControl`]), checks that the results hold only finite
//! numbers, and writes `summary.json`. Argument parsing, signal handlers, the thread pool and the
//! `tracing` subscriber belong to the program (the CLI installs them once), so a study can call [`run`]
//! for case after case in one process.
//!
//! Checkpoints are stamped with [`input_hash`], the hash of the resolved input: a resume with another
//! scenario, another format version or a damaged file is refused with a sentence before the scenario
//! starts (see [`spatter_io::checkpoint`]).

use crate::kinds::{Loaded, RunError, KIND_RANKS};
use serde_json::Value;
use spatter_core::comm::{Comm, SERIAL};
use spatter_core::control::{Finished, RunControl};
use spatter_io::checkpoint::fnv1a;
use spatter_io::run::{RunContext, RunDir, RunSummary};
use spatter_io::summary::SummaryFile;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use thiserror::Error;

/// Default wall-clock time between periodic checkpoints \[s\] (five minutes): a killed run loses at most
/// this much work, and writing even a large state this rarely costs well under 1 % of the run.
pub const DEFAULT_CHECKPOINT_INTERVAL_S: f64 = 300.0;

/// Files a run folder holds that mark it as a spatter run folder.
const RUN_MARKERS: &[&str] = &["run.toml", "summary.json", "checkpoint.bin"];

/// How to run a job.
#[derive(Clone, Debug)]
pub struct JobOptions {
    /// The run folder.
    pub out: PathBuf,
    /// Continue from the checkpoint in `out`.
    pub resume: bool,
    /// Delete the files of an earlier run in `out` before starting.
    pub overwrite: bool,
    /// Wall-clock seconds between periodic checkpoints (> 0; default
    /// [`DEFAULT_CHECKPOINT_INTERVAL_S`]).
    pub checkpoint_interval_s: f64,
    /// Files in `out` that belong to the caller (a study's `case.toml`): not another run's files, and
    /// kept by `overwrite`.
    pub keep: Vec<String>,
    /// With `resume`: continue a checkpoint written on another number of ranks than this run has,
    /// splitting the state afresh (`--repartition`; kinds that run on several ranks only).
    pub repartition: bool,
}

impl JobOptions {
    /// A fresh run into `out` with the default checkpoint interval.
    pub fn new(out: &Path) -> Self {
        JobOptions {
            out: out.to_owned(),
            resume: false,
            overwrite: false,
            checkpoint_interval_s: DEFAULT_CHECKPOINT_INTERVAL_S,
            keep: Vec::new(),
            repartition: false,
        }
    }
}

/// Why a job did not run or did not finish with trustworthy results.
#[derive(Debug, Error)]
pub enum JobError {
    /// The run folder cannot be used (another run's files, not a folder, no checkpoint to resume).
    #[error("{0}")]
    Folder(String),
    /// The checkpoint cannot be resumed.
    #[error("{0}")]
    Resume(String),
    /// Reading or writing a file of the run folder failed.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The scenario itself failed.
    #[error("{0}")]
    Run(RunError),
    /// The run ended but its results hold NaN or infinity.
    #[error("{0}")]
    NonFinite(String),
    /// The scenario cannot run on the ranks it was started on (`mpirun -n N`).
    #[error("{0}")]
    Ranks(String),
}

/// Hash of a resolved input text, stamped into checkpoints.
pub fn input_hash(resolved: &str) -> u64 {
    // 0 means "not stamped"; keep real inputs away from it.
    fnv1a(resolved.as_bytes()).max(1)
}

/// Runs `loaded` into `opts.out` (see the module docs) and returns its summary.
pub fn run(loaded: &Loaded, opts: &JobOptions, control: &dyn RunControl) -> Result<RunSummary, JobError> {
    run_with_comm(loaded, opts, control, &SERIAL)
}

/// [`run`] on the ranks of `comm` (a run started by `mpirun`). Every rank calls it and every rank returns
/// an error when one does. Kinds that are not split over ranks ([`crate::Scenario::runs_on_ranks`]) are
/// refused on several ranks before the run folder is touched; one rank is the ordinary run. On several
/// ranks rank 0 alone prepares the folder, writes `run.toml`, `log.txt`, `summary.json` and the report;
/// the others learn the outcome of each of these from it. A resume needs a checkpoint written by as many
/// ranks as this run has, or [`JobOptions::repartition`] (see [`spatter_io::rank_checkpoint`]).
pub fn run_with_comm(
    loaded: &Loaded,
    opts: &JobOptions,
    control: &dyn RunControl,
    comm: &dyn Comm,
) -> Result<RunSummary, JobError> {
    if comm.size() > 1 && !loaded.scenario.runs_on_ranks() {
        let split: Vec<String> = KIND_RANKS.iter().filter(|k| k.1).map(|k| format!("`{}`", k.0)).collect();
        return Err(JobError::Ranks(format!(
            "started on {} ranks, but kind `{}` runs in one process (kinds split over MPI ranks: {}); \
             start it without mpirun, with --threads for the cores of this machine",
            comm.size(),
            loaded.scenario.kind(),
            split.join(", ")
        )));
    }
    if opts.repartition && !opts.resume {
        return Err(JobError::Folder("--repartition continues a checkpoint: it needs --resume".into()));
    }
    if opts.repartition && !loaded.scenario.runs_on_ranks() {
        return Err(JobError::Folder(format!(
            "--repartition: kind `{}` runs in one process and its checkpoints are never split over ranks; \
             resume without --repartition",
            loaded.scenario.kind()
        )));
    }
    if !(opts.checkpoint_interval_s > 0.0 && opts.checkpoint_interval_s.is_finite()) {
        return Err(JobError::Folder(format!(
            "checkpoint interval {} s: expected a positive number of seconds",
            opts.checkpoint_interval_s
        )));
    }
    let resolved = loaded.scenario.resolved_toml().map_err(|e| JobError::Folder(e.to_string()))?;
    let hash = input_hash(&resolved);
    if comm.size() > 1 {
        return run_on_ranks(loaded, opts, control, comm, &resolved, hash);
    }
    let dir = prepare_folder(opts, hash, comm.size())?;
    dir.write_text("run.toml", &resolved)?;
    let earlier_wall_s = if opts.resume { earlier_wall_time(&dir) } else { 0.0 };
    // The job's log; whatever log was open before (a study's own) is open again afterwards.
    let previous_log = spatter_io::runlog::current();
    spatter_io::runlog::open(&dir.root().join("log.txt"), opts.resume)?;
    let result = run_in(loaded, &dir, opts, control, comm, hash, earlier_wall_s);
    if let Err(e) = &result {
        tracing::error!("{e}");
    }
    spatter_io::runlog::close();
    if let Some(p) = previous_log {
        spatter_io::runlog::open(&p, true)?;
    }
    result
}

/// Rank 0's outcome of a step only it takes (`Ok` or the error text), shared with every rank: rank 0
/// returns its own error, the others a [`JobError::Folder`] (folder steps) or [`JobError::Run`] with the
/// same text.
fn shared<T>(
    comm: &dyn Comm,
    mine: Option<Result<T, JobError>>,
    other: fn(String) -> JobError,
) -> Result<Option<T>, JobError> {
    let mut text = match &mine {
        Some(Err(e)) => e.to_string().into_bytes(),
        _ => Vec::new(),
    };
    comm.broadcast_bytes(0, &mut text);
    match mine {
        Some(r) => r.map(Some),
        None if text.is_empty() => Ok(None),
        None => Err(other(String::from_utf8_lossy(&text).into_owned())),
    }
}

/// Makes a scenario's outcome the same on every rank (collective). Its errors are meant to be collective
/// already (every rank returns the same one); an error only some ranks meet (a picture that rank 0 alone
/// draws, a file only it writes) would leave the others in the job's next collective for ever. Every rank
/// learns whether another failed, and a rank that succeeded returns the lowest failing rank's message.
fn agree_on_failure(comm: &dyn Comm, mine: Result<RunSummary, JobError>) -> Result<RunSummary, JobError> {
    if comm.size() == 1 {
        return mine;
    }
    let text = match &mine {
        Err(e) => [&[1u8][..], e.to_string().as_bytes()].concat(),
        Ok(_) => vec![0u8],
    };
    let all = comm.all_gather_bytes(&text);
    match (mine, all.iter().enumerate().find(|(_, b)| b.first() == Some(&1))) {
        (Ok(_), Some((rank, b))) => {
            let message = format!("rank {rank}: {}", String::from_utf8_lossy(&b[1..]));
            Err(JobError::Run(message.into()))
        }
        (mine, _) => mine,
    }
}

/// A run on several ranks (see [`run_with_comm`]).
fn run_on_ranks(
    loaded: &Loaded,
    opts: &JobOptions,
    control: &dyn RunControl,
    comm: &dyn Comm,
    resolved: &str,
    hash: u64,
) -> Result<RunSummary, JobError> {
    let root = comm.is_root();
    let prepared = root.then(|| {
        let dir = prepare_folder(opts, hash, comm.size())?;
        dir.write_text("run.toml", resolved)?;
        Ok(dir)
    });
    let dir = match shared(comm, prepared, JobError::Folder)? {
        Some(dir) => dir,
        // Rank 0 has created the folder.
        None => RunDir::create(&opts.out)?,
    };
    let previous_log = spatter_io::runlog::current();
    let earlier_wall_s = if opts.resume && root { earlier_wall_time(&dir) } else { 0.0 };
    if !root {
        // Created by the first line only: a rank with nothing to say leaves no file.
        spatter_io::runlog::open_when_written(&dir.root().join(rank_log(comm.rank())), opts.resume);
    }
    if root {
        spatter_io::runlog::open(&dir.root().join("log.txt"), opts.resume)?;
        tracing::info!(
            "spatter {} {} scenario {} → {} on {} ranks × {} thread(s){}",
            env!("CARGO_PKG_VERSION"),
            loaded.scenario.kind(),
            loaded.source.path.display(),
            dir.root().display(),
            comm.size(),
            rayon::current_num_threads(),
            match (opts.resume, opts.repartition) {
                (true, true) => " (resumed, re-partitioned)",
                (true, false) => " (resumed)",
                _ => "",
            }
        );
    }
    let timed = Timed::new(control, Duration::from_secs_f64(opts.checkpoint_interval_s));
    let ctx = RunContext {
        dir: &dir,
        control: &timed,
        resume: opts.resume,
        input_hash: hash,
        comm,
        repartition: opts.repartition,
    };
    let started = Instant::now();
    // The scenario's errors are collective (every rank returns the same one); a failed write on one rank
    // ends the whole run there.
    let result = agree_on_failure(comm, loaded.scenario.run(&ctx).map_err(JobError::Run));
    let wall = earlier_wall_s + started.elapsed().as_secs_f64();
    let result = match result {
        Ok(summary) => {
            let written = root.then(|| {
                for line in &summary.headline {
                    tracing::info!("{line}");
                }
                check_finite(dir.root(), &summary)?;
                write_summary(&dir, loaded, &summary, wall)?;
                match summary.finished {
                    Finished::Completed => {
                        tracing::info!("completed in {wall:.3} s on {} ranks", comm.size())
                    }
                    Finished::Interrupted => {
                        tracing::info!("interrupted after {wall:.3} s; checkpoint written")
                    }
                }
                Ok(())
            });
            shared(comm, written, |t| JobError::Run(t.into())).map(|_| summary)
        }
        Err(e) => Err(e),
    };
    // How long each rank waited in the collectives (read before the gathers below add to it).
    let waited = comm.seconds_in_collectives();
    // Which ranks wrote a log of their own (every rank reaches this point: the outcomes above are
    // collective).
    let logged = comm.all_gather_bytes(&[u8::from(!root && spatter_io::runlog::written())]);
    let waits = comm.all_gather_bytes(&waited.to_le_bytes());
    if root && comm.size() > 1 {
        tracing::info!("{}", collectives_line(&waits, started.elapsed().as_secs_f64()));
    }
    if root {
        let files: Vec<String> = logged
            .iter()
            .enumerate()
            .filter(|(_, f)| f.first() == Some(&1))
            .map(|(r, _)| rank_log(r))
            .collect();
        if !files.is_empty() {
            tracing::warn!(
                "ranks other than 0 logged messages (warnings among them?): see {}",
                files.join(", ")
            );
        }
        if let Err(e) = &result {
            tracing::error!("{e}");
        }
    }
    spatter_io::runlog::close();
    if let Some(p) = previous_log {
        spatter_io::runlog::open(&p, true)?;
    }
    result
}

/// The log line of the time every rank spent in the collectives (`waits`: each rank's seconds as
/// little-endian bytes, in rank order) over `wall` seconds of this run's stretch: a rank that waits much
/// longer than the others was waiting for slower ones (load imbalance) or for messages.
fn collectives_line(waits: &[Vec<u8>], wall: f64) -> String {
    let parts: Vec<String> = waits
        .iter()
        .enumerate()
        .map(|(r, b)| {
            let s = b.as_slice().try_into().map(f64::from_le_bytes).unwrap_or(f64::NAN);
            format!("rank {r} {s:.3} s ({:.1} %)", 100.0 * s / wall.max(1e-300))
        })
        .collect();
    format!(
        "time in collectives and exchanges, waiting for the other ranks included, over {wall:.3} s: {}",
        parts.join(", ")
    )
}

/// The log of rank `rank` (> 0) of a run on several ranks, relative to the run folder.
pub fn rank_log(rank: usize) -> String {
    format!("ranks/log_r{rank:04}.txt")
}

fn run_in(
    loaded: &Loaded,
    dir: &RunDir,
    opts: &JobOptions,
    control: &dyn RunControl,
    comm: &dyn Comm,
    hash: u64,
    earlier_wall_s: f64,
) -> Result<RunSummary, JobError> {
    tracing::info!(
        "spatter {} {} scenario {} → {}{}",
        env!("CARGO_PKG_VERSION"),
        loaded.scenario.kind(),
        loaded.source.path.display(),
        dir.root().display(),
        if opts.resume { " (resumed)" } else { "" }
    );
    tracing::info!("threads: {}", rayon::current_num_threads());
    let timed = Timed::new(control, Duration::from_secs_f64(opts.checkpoint_interval_s));
    let ctx = RunContext {
        dir,
        control: &timed,
        resume: opts.resume,
        input_hash: hash,
        comm,
        repartition: opts.repartition,
    };
    let started = Instant::now();
    let summary = loaded.scenario.run(&ctx).map_err(JobError::Run)?;
    let wall = earlier_wall_s + started.elapsed().as_secs_f64();
    for line in &summary.headline {
        tracing::info!("{line}");
    }
    check_finite(dir.root(), &summary)?;
    write_summary(dir, loaded, &summary, wall)?;
    match summary.finished {
        Finished::Completed => tracing::info!("completed in {wall:.3} s"),
        Finished::Interrupted => tracing::info!("interrupted after {wall:.3} s; checkpoint written"),
    }
    Ok(summary)
}

/// Creates (or checks) the run folder of a run on `ranks` ranks. A checkpoint to resume must be intact,
/// of this input, and written by as many ranks unless `opts.repartition`.
fn prepare_folder(opts: &JobOptions, hash: u64, ranks: usize) -> Result<RunDir, JobError> {
    let (out, resume, overwrite) = (opts.out.as_path(), opts.resume, opts.overwrite);
    if out.exists() && !out.is_dir() {
        return Err(JobError::Folder(format!("output {} exists and is not a folder", out.display())));
    }
    let checkpoint = out.join("checkpoint.bin");
    if resume {
        if !checkpoint.is_file() {
            return Err(JobError::Folder(format!(
                "--resume: {} holds no checkpoint.bin (the run finished, or never started); run without \
                 --resume to start afresh",
                out.display()
            )));
        }
        let written = spatter_io::checkpoint::written_by(&checkpoint, hash)
            .map_err(|e| JobError::Resume(e.to_string()))?;
        if written != ranks && !opts.repartition {
            let e = spatter_io::checkpoint::CheckpointError::RankCount { path: checkpoint, written, ranks };
            return Err(JobError::Resume(e.to_string()));
        }
        return Ok(RunDir::create(out)?);
    }
    let entries: Vec<PathBuf> = match std::fs::read_dir(out) {
        Ok(rd) => rd
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| !p.file_name().is_some_and(|n| opts.keep.iter().any(|k| n == k.as_str())))
            .collect(),
        Err(_) => Vec::new(),
    };
    if !entries.is_empty() {
        let is_run = RUN_MARKERS.iter().any(|m| out.join(m).exists());
        if !is_run {
            return Err(JobError::Folder(format!(
                "output folder {} holds {} files that are not from a spatter run; choose a new or empty \
                 folder with --out",
                out.display(),
                entries.len()
            )));
        }
        if !overwrite {
            let what =
                if checkpoint.is_file() { "an unfinished run (checkpoint.bin)" } else { "an earlier run" };
            return Err(JobError::Folder(format!(
                "output folder {} holds the files of {what}; use --resume to continue it, --overwrite to \
                 delete its files and start afresh, or --out for another folder",
                out.display()
            )));
        }
        for p in entries {
            let removed = if p.is_dir() { std::fs::remove_dir_all(&p) } else { std::fs::remove_file(&p) };
            removed
                .map_err(|e| JobError::Folder(format!("--overwrite: cannot delete {}: {e}", p.display())))?;
        }
    }
    Ok(RunDir::create(out)?)
}

/// Wall time recorded by the interrupted session(s) before this one.
fn earlier_wall_time(dir: &RunDir) -> f64 {
    std::fs::read_to_string(dir.root().join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<Value>(&t).ok())
        .and_then(|v| v.get("wall_time_s").and_then(Value::as_f64))
        .unwrap_or(0.0)
}

/// `summary.json` (see [`spatter_io::summary`]): what the run ended with, for studies (skip finished
/// cases, results tables) and reports; then `report.html` beside it.
fn write_summary(dir: &RunDir, loaded: &Loaded, s: &RunSummary, wall_s: f64) -> Result<(), JobError> {
    let kind = loaded.scenario.kind();
    SummaryFile::of(s, kind, dir.root(), wall_s, rayon::current_num_threads()).write(dir.root())?;
    let title = format!("{} — {kind}", loaded.source.path.display());
    if let Err(e) = spatter_io::report::write_run_report(dir.root(), &title) {
        tracing::warn!("no report.html: {e}");
    }
    Ok(())
}

/// The run's results hold only finite numbers: every scalar is finite, and no CSV file of the run folder
/// holds a NaN or an infinity (a value undefined by design is an empty cell, see
/// `spatter_io::csv::CsvSeries::row_with_gaps`). The first offender is named with its file, line and
/// column.
pub fn check_finite(root: &Path, s: &RunSummary) -> Result<(), JobError> {
    for (name, v) in &s.scalars {
        if !v.is_finite() {
            return Err(JobError::NonFinite(format!(
                "the run's result `{name}` is {v}; the results are not trustworthy (see log.txt for the \
                 first warning, and check time step and inputs)"
            )));
        }
    }
    let mut csvs = Vec::new();
    collect_csv(root, &mut csvs);
    csvs.sort();
    for path in csvs {
        let Ok(text) = std::fs::read_to_string(&path) else { continue };
        let mut lines = text.lines().enumerate();
        let header: Vec<&str> = lines.next().map(|(_, h)| h.split(',').collect()).unwrap_or_default();
        for (i, line) in lines {
            for (j, cell) in line.split(',').enumerate() {
                let c = cell.trim().trim_matches('"').to_ascii_lowercase();
                // Undefined-by-design values are empty cells; NaN and infinity are failed computations.
                let bad = matches!(
                    c.as_str(),
                    "nan"
                        | "-nan"
                        | "+nan"
                        | "inf"
                        | "-inf"
                        | "+inf"
                        | "infinity"
                        | "-infinity"
                        | "+infinity"
                );
                if bad {
                    let col =
                        header.get(j).map(|h| format!("column `{h}`")).unwrap_or(format!("column {}", j + 1));
                    return Err(JobError::NonFinite(format!(
                        "{}:{}: {col} holds {cell}; the run's results are not trustworthy (see log.txt, and \
                         check time step and inputs)",
                        path.display(),
                        i + 1
                    )));
                }
            }
        }
    }
    Ok(())
}

fn collect_csv(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            collect_csv(&p, out);
        } else if p.extension().is_some_and(|x| x == "csv") {
            out.push(p);
        }
    }
}

/// The caller's control plus a wall-clock timer that asks for a checkpoint every `interval`.
struct Timed<'a> {
    inner: &'a dyn RunControl,
    interval: Duration,
    last: Mutex<Instant>,
}

impl<'a> Timed<'a> {
    fn new(inner: &'a dyn RunControl, interval: Duration) -> Self {
        Timed { inner, interval, last: Mutex::new(Instant::now()) }
    }
}

impl RunControl for Timed<'_> {
    fn stop_requested(&self) -> bool {
        self.inner.stop_requested()
    }

    fn progress(&self, done: u64, total: u64) {
        self.inner.progress(done, total)
    }

    fn status(&self, message: &str) {
        self.inner.status(message)
    }

    fn checkpoint_due(&self) -> bool {
        if self.inner.checkpoint_due() {
            return true;
        }
        let Ok(mut last) = self.last.lock() else { return false };
        if last.elapsed() >= self.interval {
            *last = Instant::now();
            true
        } else {
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_core::control::Finished;

    /// The collectives line gives every rank's seconds and their share of the run's wall time, in rank
    /// order, and says so for a malformed entry instead of failing.
    #[test]
    fn the_collectives_line_lists_every_rank_with_its_share() {
        let waits = vec![0.5f64.to_le_bytes().to_vec(), 1.25f64.to_le_bytes().to_vec(), vec![1, 2]];
        let line = collectives_line(&waits, 5.0);
        assert!(
            line.ends_with(
                "over 5.000 s: rank 0 0.500 s (10.0 %), rank 1 1.250 s (25.0 %), rank 2 NaN s (NaN %)"
            ),
            "{line}"
        );
    }

    /// The final check passes empty cells (values undefined by design) and names the file, line and
    /// column of a NaN or an infinity in any table of the run folder, and of a non-finite scalar.
    #[test]
    fn final_check_refuses_nan_and_infinity_but_not_gaps() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("probes");
        std::fs::create_dir(&sub).unwrap();
        let table = sub.join("p.csv");
        let ok = RunSummary::new(Finished::Completed);
        std::fs::write(&table, "t_s,p_Pa\n0,\n1,2.5\n").unwrap();
        assert!(check_finite(dir.path(), &ok).is_ok(), "an empty cell is a gap, not a failure");
        for bad in ["NaN", "inf", "-inf"] {
            std::fs::write(&table, format!("t_s,p_Pa\n0,1\n1,{bad}\n")).unwrap();
            let msg = check_finite(dir.path(), &ok).unwrap_err().to_string();
            assert!(msg.contains("p.csv:3") && msg.contains("column `p_Pa`") && msg.contains(bad), "{msg}");
        }
        std::fs::write(&table, "t_s,p_Pa\n0,1\n").unwrap();
        let mut s = RunSummary::new(Finished::Completed);
        s.scalar("total_J", f64::NEG_INFINITY);
        let msg = check_finite(dir.path(), &s).unwrap_err().to_string();
        assert!(msg.contains("total_J") && msg.contains("-inf"), "{msg}");
    }

    /// Started on two ranks, every rank refuses the run with the same sentence and the run folder is
    /// never created; one rank of a rank-aware world is the ordinary run.
    #[test]
    fn several_ranks_are_refused_by_every_rank_before_the_folder_is_touched() {
        use spatter_core::comm::ThreadComm;
        use spatter_core::control::Unattended;
        let dir = tempfile::tempdir().unwrap();
        let text = include_str!("../../../examples/snow_single.toml");
        let loaded = crate::load_str(Path::new("snow_single.toml"), text).unwrap();
        let out = dir.path().join("run");
        let opts = JobOptions::new(&out);
        let errors =
            ThreadComm::run(2, |c| run_with_comm(&loaded, &opts, &Unattended, c).unwrap_err().to_string());
        assert_eq!(errors[0], errors[1]);
        assert!(
            errors[0].contains("started on 2 ranks") && errors[0].contains("without mpirun"),
            "{}",
            errors[0]
        );
        assert!(!out.exists());
    }

    /// An error that only one rank meets becomes every rank's (naming the rank), so that no rank goes on
    /// to wait in a collective the failed one never joins; outcomes that agree pass unchanged.
    #[test]
    fn a_failure_on_one_rank_is_every_ranks_failure() {
        use spatter_core::comm::ThreadComm;
        for failing in [0, 1] {
            let out = ThreadComm::run(3, |c| {
                let mine = if c.rank() == failing {
                    Err(JobError::Run("cannot draw wetting/wall.png".into()))
                } else {
                    Ok(RunSummary::new(Finished::Completed))
                };
                agree_on_failure(c, mine).map(|_| ()).map_err(|e| e.to_string())
            });
            for (r, o) in out.iter().enumerate() {
                let e = o.as_ref().unwrap_err();
                let expected = if r == failing {
                    "cannot draw wetting/wall.png".to_string()
                } else {
                    format!("rank {failing}: cannot draw wetting/wall.png")
                };
                assert_eq!(e, &expected, "rank {r} of a run failing on rank {failing}");
            }
        }
        let ok =
            ThreadComm::run(2, |c| agree_on_failure(c, Ok(RunSummary::new(Finished::Completed))).is_ok());
        assert_eq!(ok, vec![true, true]);
    }
}
