//! The `sph` scenario kind: configuration ([`SphConfig`], serde + [`spatter_core::check::Validate`]),
//! building the simulation from it and running it with outputs, checkpoint and resume.

mod build;
pub mod config;
mod run;

pub use build::{build, BuildInfo};
pub use config::SphConfig;
pub use run::run;
