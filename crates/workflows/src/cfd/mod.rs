//! The `flow` scenario kind: an incompressible flow solved by `spatter-cfd` on a structured grid, with
//! fields, series, probes and pictures in the run folder (`docs/cfd.md`).

pub mod config;
pub mod field;
pub mod run;

pub use config::FlowConfig;
pub use field::{AxisFrame, SolvedField};
pub use run::{build, build_domain, run, FlowDomain, FlowRunError};
