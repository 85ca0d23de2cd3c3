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
  spatter run study.toml --out runs/a --resume   # continue after Ctrl-C
  spatter check study.toml                       # validate and print the resolved input
  spatter validate --quick                       # reference cases, table of errors, non-zero exit on failure
  spatter bench dem                              # throughput of an engine
  spatter forces examples/forces_table_6_4.toml  # which particle-fluid forces matter, as a table and CSV";

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
        #[arg(long)]
        resume: bool,
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Run { scenario, out, threads, resume } => {
            commands::run::run_file(&scenario, out.as_deref(), threads, resume)
        }
        Command::Check { scenario } => commands::check(&scenario),
        Command::Demo { out, threads } => commands::run::demo(&out, threads),
        Command::Validate { quick, case, csv } => commands::validate(quick, case.as_deref(), csv.as_deref()),
        Command::Bench { engine, quick } => commands::bench(&engine, quick),
        Command::Forces { scenario, out } => commands::forces(&scenario, out.as_deref()),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}
