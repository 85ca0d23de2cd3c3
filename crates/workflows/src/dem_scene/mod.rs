//! Scenes: a DEM simulation described by a configuration ([`SceneConfig`], the `kind = "dem"` scenario
//! body) and run into a run folder by [`run`], with checkpoint and bit-identical resume.

mod bed_outputs;
mod clumps;
mod config;
mod event_ranks;
pub mod events;
pub mod pour;
pub mod probe;
mod run;
pub mod setup;

pub use config::*;
pub(crate) use run::{
    inject, mesh_artifacts, mesh_series, record_step, summarize_records, time_step_warnings,
    trajectory_series, write_events, write_mesh_snapshots,
};
pub use run::{
    run, run_collect, run_collect_partnered, run_collect_with, simulation, with_law, MeshWallResult,
    SceneResults, StepPartner, WithLaw,
};

#[cfg(test)]
mod pour_tests;
#[cfg(test)]
mod probe_tests;
#[cfg(test)]
mod tests;
