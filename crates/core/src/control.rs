//! How a long run learns that it should stop, and where it reports progress.
//!
//! Engines and workflows poll [`RunControl::stop_requested`] between steps; when it turns true they write
//! a checkpoint, flush their outputs and return [`Finished::Interrupted`]. When
//! [`RunControl::checkpoint_due`] turns true they write a checkpoint and carry on. The CLI implements the trait with
//! a Ctrl-C flag and a progress bar; tests use [`StopAfterPolls`] to interrupt a run at an exact point.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

/// Control channel between a running job and whoever started it.
pub trait RunControl: Sync {
    /// True once the job should stop at the next safe point.
    fn stop_requested(&self) -> bool;
    /// Reports progress as `done` of `total` units (steps, impacts, …).
    fn progress(&self, _done: u64, _total: u64) {}
    /// A short status line (phase names and the like).
    fn status(&self, _message: &str) {}
    /// True when the job should write a checkpoint at its next safe point and carry on (the job driver
    /// raises it every `checkpoint_interval_s` of wall time). Jobs poll it where they poll
    /// [`RunControl::stop_requested`].
    fn checkpoint_due(&self) -> bool {
        false
    }
}

/// Whether a job ran to its end or stopped early on request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Finished {
    Completed,
    Interrupted,
}

/// Never stops, reports nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct Unattended;

impl RunControl for Unattended {
    fn stop_requested(&self) -> bool {
        false
    }
}

/// Stops when a shared flag is raised (the CLI raises it from its Ctrl-C handler).
#[derive(Debug, Default)]
pub struct StopFlag(pub AtomicBool);

impl StopFlag {
    pub fn raise(&self) {
        self.0.store(true, Ordering::SeqCst);
    }
}

impl RunControl for StopFlag {
    fn stop_requested(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// Requests a stop after the job has polled `n` times: a deterministic stand-in for Ctrl-C in tests.
#[derive(Debug)]
pub struct StopAfterPolls {
    remaining: AtomicU64,
}

impl StopAfterPolls {
    pub fn new(n: u64) -> Self {
        StopAfterPolls { remaining: AtomicU64::new(n) }
    }
}

impl RunControl for StopAfterPolls {
    fn stop_requested(&self) -> bool {
        self.remaining.fetch_update(Ordering::SeqCst, Ordering::SeqCst, |r| r.checked_sub(1)).is_err()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stop_after_polls_counts_exactly() {
        let c = StopAfterPolls::new(2);
        assert!(!c.stop_requested());
        assert!(!c.stop_requested());
        assert!(c.stop_requested());
        assert!(c.stop_requested());
    }
}
