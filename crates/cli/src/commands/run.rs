//! `spatter run` and `spatter demo`: argument handling around the job driver
//! ([`spatter_scenario::job`]), which does the rest.

use super::{report_errors, EXIT_BAD_INPUT};
use crate::control::{install_signal_handler, CliControl};
use anyhow::{Context, Result};
use spatter_core::comm::{Comm, SERIAL};
use spatter_core::control::Finished;
use spatter_scenario::job::{self, JobError, JobOptions};
use spatter_scenario::Loaded;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The built-in scenario `spatter demo` runs (the same text as the example file).
pub const DEMO_SCENARIO: (&str, &str) = crate::registry::DEMO_SCENARIO;

/// Exit code of a run stopped by a signal (checkpoint written): 128 + SIGINT, as shells report it.
pub const EXIT_INTERRUPTED: u8 = 130;

/// Largest `--threads` accepted, as a multiple of the logical CPUs.
const THREADS_PER_CPU_MAX: usize = 4;

/// What `spatter run` was asked to do besides the scenario.
#[derive(Clone, Debug)]
pub struct RunArgs {
    pub out: Option<PathBuf>,
    pub threads: Option<usize>,
    pub resume: bool,
    pub overwrite: bool,
    /// With `resume`: continue on another rank count than the checkpoint's (`--repartition`).
    pub repartition: bool,
    pub checkpoint_interval_s: f64,
    pub verbose: u8,
    pub quiet: bool,
    /// Cut the scenario down to a smoke test (`--smoke`).
    pub smoke: bool,
}

impl Default for RunArgs {
    fn default() -> Self {
        RunArgs {
            out: None,
            threads: None,
            resume: false,
            overwrite: false,
            repartition: false,
            checkpoint_interval_s: job::DEFAULT_CHECKPOINT_INTERVAL_S,
            verbose: 0,
            quiet: false,
            smoke: false,
        }
    }
}

/// `spatter run <scenario>`.
pub fn run_file(path: &Path, args: &RunArgs) -> Result<ExitCode> {
    run_file_on(path, args, &SERIAL)
}

/// `spatter run <scenario>` on the ranks of `comm` (started by `mpirun`): every rank reads the scenario,
/// only rank 0 prints.
pub fn run_file_on(path: &Path, args: &RunArgs, comm: &dyn Comm) -> Result<ExitCode> {
    let mut loaded = match spatter_scenario::load(path) {
        Ok(l) => l,
        Err(errors) => {
            if comm.is_root() {
                report_errors(&errors);
            }
            return Ok(ExitCode::from(EXIT_BAD_INPUT));
        }
    };
    if args.smoke {
        loaded.scenario.smoke();
        if comm.is_root() {
            eprintln!(
                "note: --smoke: a reduced run of {} (see run.toml for the values used)",
                path.display()
            );
        }
    }
    let out = args.out.clone().unwrap_or_else(|| default_out(path));
    let again = format!("spatter run {} --out {} --resume", path.display(), out.display());
    execute(loaded, &out, args, &again, comm)
}

/// `spatter demo`: the built-in scenario; an earlier demo in the same folder is replaced.
pub fn demo(out: &Path, threads: Option<usize>) -> Result<ExitCode> {
    let (name, text) = DEMO_SCENARIO;
    let loaded = spatter_scenario::load_str(Path::new(name), text).map_err(|errors| {
        anyhow::anyhow!(
            "the built-in scenario is invalid: {}",
            errors.iter().map(|e| e.to_string()).collect::<Vec<_>>().join("; ")
        )
    })?;
    println!("spatter demo: running the built-in scenario `{name}` ({})", loaded.scenario.kind());
    let args = RunArgs { threads, overwrite: true, ..RunArgs::default() };
    execute(loaded, out, &args, &format!("spatter run {name} --out {} --resume", out.display()), &SERIAL)
}

fn default_out(scenario: &Path) -> PathBuf {
    let stem = scenario.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "run".into());
    PathBuf::from("runs").join(stem)
}

/// Sets up the global thread pool (`--threads`; all cores when `None`): refused when 0 or beyond
/// [`THREADS_PER_CPU_MAX`] per logical CPU.
pub fn set_threads(threads: Option<usize>) -> Result<()> {
    let Some(n) = threads else { return Ok(()) };
    let cpus = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    anyhow::ensure!(n >= 1, "--threads 0: expected at least 1 worker thread");
    anyhow::ensure!(
        n <= THREADS_PER_CPU_MAX * cpus,
        "--threads {n}: this machine has {cpus} logical CPUs; expected at most {} ({}× the CPUs), more \
         threads only slow the run down",
        THREADS_PER_CPU_MAX * cpus,
        THREADS_PER_CPU_MAX
    );
    rayon::ThreadPoolBuilder::new().num_threads(n).build_global().context("cannot set up worker threads")
}

/// Runs `f` on a worker of the global thread pool (when the ranks' transport allows calls from any
/// thread), so that the parallel loops of the run start on a worker. Started from the main thread
/// instead, every parallel loop hands its work to the pool and waits: with one thread a futex wake-up
/// and two context switches per loop, 15 % of a DEM step's time in the kernel (measured with `perf` on
/// the 20 000-grain pile of `bench/dem/ranks.sh`). Results do not depend on the thread a loop starts
/// on.
pub(crate) fn on_worker<R: Send>(comm: &dyn Comm, f: impl FnOnce() -> R + Send) -> R {
    if comm.calls_from_any_thread() {
        rayon::scope(|_| f())
    } else {
        f()
    }
}

fn execute(
    loaded: Loaded,
    out: &Path,
    args: &RunArgs,
    resume_hint: &str,
    comm: &dyn Comm,
) -> Result<ExitCode> {
    // Under mpirun every rank runs this; rank 0 alone talks to the user.
    let root = comm.is_root();
    let quiet = args.quiet || !root;
    set_threads(args.threads)?;
    install_signal_handler();
    let control = CliControl::new(quiet);
    if let Some(note) = crate::logging::init(control.bar(), args.verbose, quiet) {
        eprintln!("note: {note}");
    }
    let opts = JobOptions {
        out: out.to_owned(),
        resume: args.resume,
        overwrite: args.overwrite,
        checkpoint_interval_s: args.checkpoint_interval_s,
        keep: Vec::new(),
        repartition: args.repartition,
    };
    let started = Instant::now();
    let result = on_worker(comm, || job::run_with_comm(&loaded, &opts, &control, comm));
    control.finish();
    let summary = match result {
        Ok(s) => s,
        Err(e @ (JobError::Folder(_) | JobError::Resume(_) | JobError::Ranks(_))) => {
            if root {
                eprintln!("error: {e}");
            }
            return Ok(ExitCode::from(EXIT_BAD_INPUT));
        }
        Err(_) if !root => return Ok(ExitCode::FAILURE),
        Err(e) => return Err(anyhow::anyhow!("{e}")),
    };
    let secs = started.elapsed().as_secs_f64();
    if !quiet {
        for line in &summary.headline {
            println!("{line}");
        }
        for (label, path) in &summary.artifacts {
            println!("  {label}: {}", path.display());
        }
    }
    match summary.finished {
        Finished::Completed => {
            if root {
                println!("done in {secs:.1} s; results in {}", out.display());
            }
            Ok(ExitCode::SUCCESS)
        }
        Finished::Interrupted => {
            if root {
                println!(
                    "stopped after {secs:.1} s; outputs so far are in {}. Continue with:\n  {resume_hint}",
                    out.display()
                );
            }
            Ok(ExitCode::from(EXIT_INTERRUPTED))
        }
    }
}
