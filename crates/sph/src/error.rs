//! Errors of the SPH engine.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum SphError {
    /// The state stopped being finite: names the particle, step, time and the likely cause.
    #[error(
        "SPH blow-up at step {step}, t = {time:.6e} s: fluid particle {id} has a non-finite {what}. \
         Likely cause: {cause}"
    )]
    BlowUp { step: u64, time: f64, id: u32, what: &'static str, cause: String },
    /// A set-up that cannot run (empty fluid, seed inside a wall, …).
    #[error("SPH set-up: {0}")]
    Setup(String),
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error(transparent)]
    Checkpoint(#[from] spatter_io::checkpoint::CheckpointError),
    #[error(transparent)]
    Mesh(#[from] spatter_core::mesh::MeshError),
    #[error(transparent)]
    Motion(#[from] spatter_core::motion::MotionError),
}
