//! Errors of the DEM engine.

use std::path::PathBuf;
use thiserror::Error;

/// Why a DEM run could not start or had to stop.
#[derive(Debug, Error)]
pub enum DemError {
    /// The run became unstable. Names the particle, the step, the time and the likely cause.
    #[error(
        "DEM blow-up at step {step} (t = {time_s:e} s), particle id {particle}: {what}. Likely cause: {cause}"
    )]
    BlowUp { particle: u32, step: u64, time_s: f64, what: String, cause: String },
    /// A configuration value is unusable (key path and message as in `spatter_core::check`).
    #[error("{key}: {message}")]
    Config { key: String, message: String },
    /// Several configuration problems at once.
    #[error("invalid DEM scene:\n{}", .0.iter().map(|i| format!("  {}: {}", i.key, i.message)).collect::<Vec<_>>().join("\n"))]
    Invalid(Vec<spatter_core::check::Invalid>),
    #[error(transparent)]
    Mesh(#[from] spatter_core::mesh::MeshError),
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error(transparent)]
    Checkpoint(#[from] spatter_io::checkpoint::CheckpointError),
    /// Resuming needs a checkpoint that matches the scene.
    #[error("cannot resume: {0}")]
    Resume(String),
}
