//! Logging: one `tracing` subscriber for the whole program. Every event goes to the current run's
//! `log.txt` (through [`spatter_io::runlog`], which the job driver points at the run folder); events at or
//! above the terminal level also go to stderr (printed above the progress bar).
//!
//! Terminal level: warnings by default, errors only with `-q`, information with `-v`, debug with `-vv`,
//! everything with `-vvv`. The log file gets information and above (debug with `-vv`). `RUST_LOG`
//! (`warn`, `debug`, `spatter_sph=debug,info`, …) replaces the file's filter when set.

use indicatif::ProgressBar;
use std::io::{self, Write};
use tracing::{Level, Metadata};
use tracing_subscriber::filter::{LevelFilter, Targets};
use tracing_subscriber::fmt::MakeWriter;
use tracing_subscriber::layer::SubscriberExt;
use tracing_subscriber::util::SubscriberInitExt;
use tracing_subscriber::Layer;

#[derive(Clone)]
struct Tee {
    bar: ProgressBar,
    terminal: Level,
}

struct TeeWriter {
    bar: Option<ProgressBar>,
    buf: Vec<u8>,
}

impl Write for TeeWriter {
    fn write(&mut self, b: &[u8]) -> io::Result<usize> {
        self.buf.extend_from_slice(b);
        Ok(b.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Drop for TeeWriter {
    fn drop(&mut self) {
        spatter_io::runlog::append(&self.buf);
        if let Some(bar) = &self.bar {
            let text = String::from_utf8_lossy(&self.buf).into_owned();
            bar.suspend(|| eprint!("{text}"));
        }
    }
}

impl<'a> MakeWriter<'a> for Tee {
    type Writer = TeeWriter;

    fn make_writer(&'a self) -> TeeWriter {
        TeeWriter { bar: Some(self.bar.clone()), buf: Vec::new() }
    }

    fn make_writer_for(&'a self, meta: &Metadata<'_>) -> TeeWriter {
        let to_terminal = *meta.level() <= self.terminal;
        TeeWriter { bar: to_terminal.then(|| self.bar.clone()), buf: Vec::new() }
    }
}

/// Terminal level for `-v` count `verbose` and `-q`.
fn terminal_level(verbose: u8, quiet: bool) -> Level {
    match (quiet, verbose) {
        (true, _) => Level::ERROR,
        (false, 0) => Level::WARN,
        (false, 1) => Level::INFO,
        (false, 2) => Level::DEBUG,
        _ => Level::TRACE,
    }
}

/// Installs the subscriber (once per process). Returns a note when `RUST_LOG` could not be read.
pub fn init(bar: &ProgressBar, verbose: u8, quiet: bool) -> Option<String> {
    let terminal = terminal_level(verbose, quiet);
    let file_level = if verbose >= 2 { terminal } else { Level::INFO };
    let mut note = None;
    let filter = match std::env::var("RUST_LOG") {
        Ok(spec) if !spec.trim().is_empty() => match spec.parse::<Targets>() {
            Ok(t) => t,
            Err(e) => {
                note = Some(format!(
                    "RUST_LOG={spec:?} ignored ({e}); expected e.g. `debug` or `spatter_sph=debug,info`"
                ));
                Targets::new().with_default(LevelFilter::from_level(file_level))
            }
        },
        _ => Targets::new().with_default(LevelFilter::from_level(file_level.max(terminal))),
    };
    let tee = Tee { bar: bar.clone(), terminal };
    let layer = tracing_subscriber::fmt::layer()
        .with_writer(tee)
        .with_ansi(false)
        .with_target(false)
        .with_filter(filter);
    let _ = tracing_subscriber::registry().with(layer).try_init();
    note
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verbosity_flags_map_to_levels() {
        assert_eq!(terminal_level(0, false), Level::WARN);
        assert_eq!(terminal_level(1, false), Level::INFO);
        assert_eq!(terminal_level(2, false), Level::DEBUG);
        assert_eq!(terminal_level(5, false), Level::TRACE);
        assert_eq!(terminal_level(3, true), Level::ERROR);
    }
}
