//! What can go wrong in a snow run.

use spatter_core::check::Invalid;
use std::io;
use thiserror::Error;

/// What can go wrong in a snow run.
#[derive(Debug, Error)]
pub enum SnowError {
    #[error("invalid snow_regime_map configuration: {}", .0.iter().map(|e| format!("{} ({})", e.message, e.key)).collect::<Vec<_>>().join("; "))]
    Invalid(Vec<Invalid>),
    #[error("{0}")]
    Io(#[from] io::Error),
    #[error("checkpoint: {0}")]
    Checkpoint(String),
}
