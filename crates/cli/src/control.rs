//! The CLI's side of [`RunControl`]: a stop flag raised by SIGINT (Ctrl-C) and SIGTERM (a scheduler
//! ending the job), and progress — a bar with ETA on a terminal, periodic lines on stderr otherwise
//! (piped, CI, `nohup`, batch jobs).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use spatter_core::control::{RunControl, StopAfterPolls};
use std::io::IsTerminal;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

/// Raised by the first SIGINT/SIGTERM; a second one ends the program at once.
static STOP: OnceLock<Arc<AtomicBool>> = OnceLock::new();

/// Seconds between progress lines when stderr is not a terminal (`SPATTER_PROGRESS_INTERVAL_S`
/// overrides it).
const PROGRESS_LINE_INTERVAL_S: f64 = 10.0;

fn stop_flag() -> Arc<AtomicBool> {
    STOP.get_or_init(|| Arc::new(AtomicBool::new(false))).clone()
}

/// Installs the SIGINT + SIGTERM handler (once per process).
pub fn install_signal_handler() {
    let flag = stop_flag();
    let _ = ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::SeqCst) {
            eprintln!(
                "\nsecond stop signal: ending immediately (outputs since the last checkpoint are lost)"
            );
            std::process::exit(130);
        }
        eprintln!("\nstop signal: finishing the current step, writing a checkpoint and flushing outputs…");
    });
}

/// How progress is shown.
enum Display {
    /// An indicatif bar (stderr is a terminal).
    Bar,
    /// A line every `every` (stderr is not a terminal).
    Lines { every: Duration, last: Mutex<Option<Instant>> },
    /// Nothing (`SPATTER_NO_PROGRESS` or `-q`).
    Off,
}

/// Progress display + stop flag.
///
/// For tests and scripted checks, the environment variable `SPATTER_STOP_AFTER_POLLS=N` makes the run
/// behave as if Ctrl-C were pressed just before its (N+1)-th poll — a deterministic interruption point.
pub struct CliControl {
    bar: ProgressBar,
    display: Display,
    started: Instant,
    flag: Arc<AtomicBool>,
    stop_after: Option<StopAfterPolls>,
}

impl CliControl {
    /// `quiet`: no progress at all.
    pub fn new(quiet: bool) -> Self {
        let stop_after = std::env::var("SPATTER_STOP_AFTER_POLLS")
            .ok()
            .and_then(|v| v.parse().ok())
            .map(StopAfterPolls::new);
        let display = if quiet || std::env::var_os("SPATTER_NO_PROGRESS").is_some() {
            Display::Off
        } else if std::io::stderr().is_terminal() {
            Display::Bar
        } else {
            let s = std::env::var("SPATTER_PROGRESS_INTERVAL_S")
                .ok()
                .and_then(|v| v.parse::<f64>().ok())
                .filter(|s| s.is_finite() && *s >= 0.0)
                .unwrap_or(PROGRESS_LINE_INTERVAL_S);
            Display::Lines { every: Duration::from_secs_f64(s), last: Mutex::new(None) }
        };
        let bar = match display {
            Display::Bar => {
                let bar = ProgressBar::with_draw_target(Some(0), ProgressDrawTarget::stderr_with_hz(4));
                bar.set_style(
                    ProgressStyle::with_template(
                        "{spinner} [{elapsed_precise}] {bar:40.cyan/blue} {pos}/{len} ({percent}%) ETA {eta} {msg}",
                    )
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
                );
                bar
            }
            _ => ProgressBar::hidden(),
        };
        CliControl { bar, display, started: Instant::now(), flag: stop_flag(), stop_after }
    }

    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }

    fn line(&self, done: u64, total: u64) {
        let Display::Lines { every, last } = &self.display else { return };
        let Ok(mut last) = last.lock() else { return };
        let now = Instant::now();
        if last.is_some_and(|l| now.duration_since(l) < *every) && done < total {
            return;
        }
        *last = Some(now);
        let elapsed = self.started.elapsed().as_secs_f64();
        let frac = if total > 0 { done as f64 / total as f64 } else { 0.0 };
        let eta = if frac > 0.0 && frac < 1.0 {
            format!(", ETA {:.0} s", elapsed * (1.0 - frac) / frac)
        } else {
            String::new()
        };
        eprintln!("progress: {done}/{total} ({:.1} %), {elapsed:.0} s elapsed{eta}", 100.0 * frac);
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
        match self.display {
            Display::Bar => {
                if self.bar.length() != Some(total) {
                    self.bar.set_length(total);
                }
                self.bar.set_position(done);
            }
            Display::Lines { .. } => self.line(done, total),
            Display::Off => {}
        }
    }

    fn status(&self, message: &str) {
        match self.display {
            Display::Bar => self.bar.set_message(message.to_owned()),
            Display::Lines { .. } => eprintln!("status: {message}"),
            Display::Off => {}
        }
    }
}
