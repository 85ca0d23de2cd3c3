//! Snow adhesion: stick/bounce regime maps of dry snow grains hitting car plastics.

pub mod bed;
pub mod bed_index;
pub mod bisection;
pub mod cases;
pub mod checks;
pub mod config;
pub mod dt_guard;
pub mod error;
pub mod fit;
pub mod impact;
pub mod material;
pub mod model;
pub mod output;
pub mod regime;
pub mod runner;
pub mod samples;

pub use config::SnowConfig;
pub use error::SnowError;
pub use runner::run;
pub mod bench;
pub mod validation;

pub use bench::bench;
pub use validation::validation_cases;

#[cfg(test)]
mod tests;
