//! The `brownout` workflow: a helicopter rotor in hover over a sand bed. Which grains lift off where
//! (lift-off map), how much dust the ground gives (an empirical entrainment model), and how thick the cloud
//! is in the pilot's line of sight (concentration and optical depth), on the analytic rotor downwash of
//! `spatter-flow` (mean flow with optional tip vortices) or on the axisymmetric RANS rotor flow solved by
//! `spatter-cfd` at the start of the run ([`rans`]). `docs/brownout.md` describes keys, models and how the
//! results compare with Jasion (2013).

pub mod config;
pub mod exceedance;
pub mod imported;
pub mod rans;
pub mod run;

pub use config::BrownoutConfig;
pub use run::{run, BrownoutError};

#[cfg(test)]
mod tests;
