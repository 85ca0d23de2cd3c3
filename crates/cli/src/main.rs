//! `spatter`: particles that hit, stick to, wet and wear surfaces.
//!
//! The binary only parses arguments and dispatches; every physical model lives in the library crates.

mod commands;
mod control;
mod logging;
mod registry;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

const EXAMPLES: &str = "\
Examples:
  spatter demo                                   # snow regime map on the built-in scenario, no files needed
  spatter run examples/snow_regime_map.toml      # run a scenario; results in runs/snow_regime_map/
  spatter run study.toml --out runs/a --threads 2
  spatter run study.toml --out runs/a --resume   # continue after Ctrl-C, SIGTERM or a kill
  spatter run study.toml --out runs/a --overwrite # replace an earlier run's files
  mpirun -n 4 spatter run dam.toml --out runs/d --resume --repartition # continue on another rank count
  spatter check study.toml                       # validate and print the resolved input
  spatter validate --quick                       # reference cases, table of errors, non-zero exit on failure
  spatter bench dem                              # throughput of an engine
  spatter sweep examples/snow_sobol_study.toml   # parameter study: results table, Sobol indices, report
  spatter forces examples/forces_table_6_4.toml  # which particle-fluid forces matter, as a table and CSV
  spatter sessile --adhesion 0.6,0.8,1.0         # SPH contact angle per wall adhesion factor (calibration)
  spatter sessile --contact-angle glass=25       # adhesion factor that gives a measured contact angle";

#[derive(Parser, Debug)]
#[command(name = "spatter", version, about = "Particles that hit, stick to, wet and wear surfaces.", after_help = EXAMPLES)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a scenario file; its `kind` key says which workflow or engine runs it.
    #[command(
        after_help = "Example:\n  spatter run examples/snow_regime_map.toml --out runs/snow --threads 2"
    )]
    Run {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Output folder [default: runs/<scenario file name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Worker threads [default: all cores].
        #[arg(long)]
        threads: Option<usize>,
        /// Continue from the checkpoint in the output folder.
        #[arg(long, conflicts_with = "overwrite")]
        resume: bool,
        /// Delete the files of an earlier run in the output folder before starting.
        #[arg(long)]
        overwrite: bool,
        /// With --resume: continue a checkpoint written on another number of MPI ranks, splitting it
        /// afresh over the ranks of this run (results then differ from an uninterrupted run at round-off).
        #[arg(long)]
        repartition: bool,
        /// Wall-clock seconds between periodic checkpoints (a kill loses at most this much work).
        #[arg(long, default_value_t = spatter_scenario::job::DEFAULT_CHECKPOINT_INTERVAL_S)]
        checkpoint_interval_s: f64,
        /// More messages on the terminal (-v information, -vv debug); `RUST_LOG` filters the log file.
        #[arg(short, long, action = clap::ArgAction::Count, conflicts_with = "quiet")]
        verbose: u8,
        /// Errors only on the terminal, no progress.
        #[arg(short, long)]
        quiet: bool,
        /// A reduced run (a few steps, parcels or impacts) that exercises every output in seconds.
        #[arg(long)]
        smoke: bool,
    },
    /// Validate a scenario and print the fully resolved input (defaults filled in).
    #[command(after_help = "Example:\n  spatter check examples/snow_regime_map.toml")]
    Check {
        /// Scenario file (TOML).
        scenario: PathBuf,
    },
    /// Run the main job on the built-in default scenario.
    #[command(after_help = "Example:\n  spatter demo --out runs/demo")]
    Demo {
        /// Output folder.
        #[arg(long, default_value = "runs/demo")]
        out: PathBuf,
        /// Worker threads [default: all cores].
        #[arg(long)]
        threads: Option<usize>,
    },
    /// Run the registered reference cases and print a table of errors; non-zero exit on any failure.
    #[command(
        after_help = "Examples:\n  spatter validate --quick\n  spatter validate --case chung_ooi\n  spatter validate --csv validation.csv"
    )]
    Validate {
        /// Reduced variants (the ones CI runs).
        #[arg(long)]
        quick: bool,
        /// Only cases whose name contains this text.
        #[arg(long)]
        case: Option<String>,
        /// Also write the table with every check's source to this CSV file.
        #[arg(long)]
        csv: Option<PathBuf>,
    },
    /// Rank the particle–fluid forces of a `forces` scenario: table on screen, CSV in the output folder.
    #[command(after_help = "Example:\n  spatter forces examples/forces_table_6_4.toml --out runs/forces")]
    Forces {
        /// Scenario file of kind `forces`.
        scenario: PathBuf,
        /// Output folder for the CSV tables [default: runs/<scenario file name>].
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// SPH sessile drops: the static contact angle each wall adhesion factor gives, to calibrate `adhesion`
    /// against a measured contact angle (docs/sph.md, "Sessile-drop calibration").
    #[command(
        after_help = "Examples:\n  spatter sessile --adhesion 0.6,0.8,1.0\n  spatter sessile --adhesion 0.9 --dimensions 3 --resolution 8 --csv angles.csv\n  spatter sessile --contact-angle glass=25,paint=80,rubber=100 --dimensions 3 --resolution 6"
    )]
    Sessile {
        /// Wall adhesion factors (multiples of the liquid's cohesion), comma-separated, each in [0, 10].
        #[arg(
            long,
            value_delimiter = ',',
            allow_hyphen_values = true,
            required_unless_present = "contact_angle"
        )]
        adhesion: Vec<f64>,
        /// Measured contact angles `material=degrees`, comma-separated (e.g. glass=25,paint=80): prints the
        /// adhesion factor of each, from a table of drops over the factors 0.25–3 and one check per material.
        #[arg(long, value_delimiter = ',', conflicts_with = "adhesion")]
        contact_angle: Vec<String>,
        /// 2 (half-disc drop, the validated setting) or 3 (hemisphere).
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u8).range(2..=3))]
        dimensions: u8,
        /// Particles across the drop radius, 4 to 40; use the particle spacing of your run (R/dp).
        #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u32).range(4..=40))]
        resolution: u32,
        /// Drop radius [m], in (0, 0.1].
        #[arg(long, default_value_t = 2e-3, allow_negative_numbers = true)]
        radius_m: f64,
        /// Surface tension of the liquid [N/m], in (0, 1].
        #[arg(long, default_value_t = 0.072)]
        surface_tension_n_m: f64,
        /// Simulated time in capillary times √(ρR³/σ), 1 to 100.
        #[arg(long, default_value_t = 12.0)]
        capillary_times: f64,
        /// Also write the table to this CSV file.
        #[arg(long)]
        csv: Option<PathBuf>,
    },
    /// Run a parameter study: every case of a study file (a base scenario and the keys to vary), then a
    /// results table, plots, Sobol indices for sampled designs and report.html (docs/studies.md).
    #[command(
        args_conflicts_with_subcommands = true,
        after_help = "Examples:\n  spatter sweep examples/snow_sobol_study.toml\n  spatter sweep study.toml --out runs/s --shard 3/8   # one task of a batch job array\n  spatter sweep collect study.toml --out runs/s        # table and report once every shard is done"
    )]
    Sweep {
        #[command(subcommand)]
        action: Option<SweepAction>,
        /// Study file (TOML).
        study: Option<PathBuf>,
        /// Study folder [default: runs/<study file name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Run only shard i of n (every n-th case, starting at case i - 1), e.g. 2/8.
        #[arg(long, value_parser = commands::sweep::parse_shard)]
        shard: Option<(usize, usize)>,
        /// Worker threads per case [default: all cores].
        #[arg(long)]
        threads: Option<usize>,
        /// Delete another study's cases found in the folder, and cases whose scenario changed since they
        /// ran (an edited base), instead of refusing; the changed cases then run afresh.
        #[arg(long)]
        overwrite: bool,
    },
    /// Run a named benchmark and print its throughput.
    #[command(after_help = "Example:\n  spatter bench dem\n  spatter bench snow --quick")]
    Bench {
        /// Engine or workflow to benchmark.
        #[arg(value_parser = clap::builder::PossibleValuesParser::new(registry::BENCHES))]
        engine: String,
        /// A smaller case that finishes in seconds.
        #[arg(long)]
        quick: bool,
    },
}

#[derive(Subcommand, Debug)]
enum SweepAction {
    /// Build the results table, plots and report of a study whose shards have all finished.
    Collect {
        /// Study file (TOML).
        study: PathBuf,
        /// Study folder [default: runs/<study file name>].
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    // Before anything else: under mpirun every rank starts here, and MPI must be up before the first
    // collective; `launch` lives until `main` returns (dropping it finalises MPI).
    let launch = match spatter_mpi::init() {
        Ok(l) => l,
        Err(e) => {
            if e.rank == 0 {
                eprintln!("error: {e}");
            }
            return ExitCode::from(commands::EXIT_BAD_INPUT);
        }
    };
    let comm = launch.comm();
    let cli = Cli::parse();
    if comm.size() > 1 && !matches!(cli.command, Command::Run { .. }) {
        if comm.is_root() {
            eprintln!(
                "error: under mpirun ({} ranks) only `spatter run` can be started; run the other commands \
                 without mpirun",
                comm.size()
            );
        }
        return ExitCode::from(commands::EXIT_BAD_INPUT);
    }
    let result = match cli.command {
        Command::Run {
            scenario,
            out,
            threads,
            resume,
            overwrite,
            repartition,
            checkpoint_interval_s,
            verbose,
            quiet,
            smoke,
        } => {
            let args = commands::run::RunArgs {
                out,
                threads,
                resume,
                overwrite,
                repartition,
                checkpoint_interval_s,
                verbose,
                quiet,
                smoke,
            };
            commands::run::run_file_on(&scenario, &args, comm)
        }
        Command::Check { scenario } => commands::check(&scenario),
        Command::Demo { out, threads } => commands::run::demo(&out, threads),
        Command::Validate { quick, case, csv } => commands::validate(quick, case.as_deref(), csv.as_deref()),
        Command::Bench { engine, quick } => commands::bench(&engine, quick),
        Command::Sweep { action: Some(SweepAction::Collect { study, out }), .. } => {
            commands::sweep::collect(&study, out.as_deref())
        }
        Command::Sweep { action: None, study: Some(study), out, shard, threads, overwrite } => {
            commands::sweep::sweep(&study, out.as_deref(), shard, threads, overwrite)
        }
        Command::Sweep { action: None, study: None, .. } => {
            Err(anyhow::anyhow!("spatter sweep needs a study file: spatter sweep STUDY.toml (see --help)"))
        }
        Command::Forces { scenario, out } => commands::forces(&scenario, out.as_deref()),
        Command::Sessile {
            adhesion,
            contact_angle,
            dimensions,
            resolution,
            radius_m,
            surface_tension_n_m,
            capillary_times,
            csv,
        } => commands::sessile::run(
            &commands::sessile::Request {
                adhesion,
                contact_angles: contact_angle,
                dimensions,
                resolution: resolution as usize,
                radius_m,
                surface_tension_n_m,
                capillary_times,
            },
            csv.as_deref(),
        ),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
