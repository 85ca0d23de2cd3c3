//! The CLI's side of [`RunControl`]: a Ctrl-C flag and a progress bar with ETA.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use spatter_core::control::{RunControl, StopAfterPolls};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

/// Raised by the first Ctrl-C; a second Ctrl-C ends the program at once.
static STOP: OnceLock<Arc<AtomicBool>> = OnceLock::new();

fn stop_flag() -> Arc<AtomicBool> {
    STOP.get_or_init(|| Arc::new(AtomicBool::new(false))).clone()
}

/// Installs the Ctrl-C handler (once per process).
pub fn install_ctrlc() {
    let flag = stop_flag();
    let _ = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            eprintln!("\nsecond Ctrl-C: stopping immediately (outputs since the last checkpoint are lost)");
            std::process::exit(130);
        }
        eprintln!("\nCtrl-C: finishing the current step, writing a checkpoint and flushing outputs…");
    });
}

/// Progress bar + stop flag.
///
/// For tests and scripted checks, the environment variable `SPATTER_STOP_AFTER_POLLS=N` makes the run
/// behave as if Ctrl-C were pressed just before its (N+1)-th poll — a deterministic interruption point.
pub struct CliControl {
    bar: ProgressBar,
    flag: Arc<AtomicBool>,
    stop_after: Option<StopAfterPolls>,
}

impl CliControl {
    pub fn new() -> Self {
        let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr_with_hz(4));
        bar.set_style(
            ProgressStyle::with_template(
                "{spinner} [{elapsed_precise}] {bar:40.cyan/blue} {pos}/{len} ({percent}%) ETA {eta} {msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        let stop_after = std::env::var("SPATTER_STOP_AFTER_POLLS")
            .ok()
            .and_then(|v| v.parse().ok())
            .map(StopAfterPolls::new);
        if std::env::var("SPATTER_NO_PROGRESS").is_ok() {
            bar.set_draw_target(ProgressDrawTarget::hidden());
        }
        CliControl { bar, flag: stop_flag(), stop_after }
    }

    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl RunControl for CliControl {
    fn stop_requested(&self) -> bool {
        if let Some(s) = &self.stop_after {
            if s.stop_requested() {
                self.flag.store(true, Ordering::SeqCst);
            }
        }
        self.flag.load(Ordering::SeqCst)
    }

    fn progress(&self, done: u64, total: u64) {
        if self.bar.length() != Some(total) {
            self.bar.set_length(total);
        }
        self.bar.set_position(done);
    }

    fn status(&self, message: &str) {
        self.bar.set_message(message.to_owned());
    }
}
