//! Deposition: snow, dust or spray carried by an air flow (analytic or imported from CFD) onto STL
//! bodies, with stick/bounce from the snow workflow's regime map; and the particle–fluid force ranking.
//!
//! * [`config`] — the `deposition` and `forces` scenario kinds;
//! * [`run`] — a deposition run (`run::run`);
//! * [`forces`] — the force ranking (`forces::run`, `forces::report` for `spatter forces`).
//!
//! The reference cases (`spatter validate`) and the tracker benchmark (`spatter bench track`) live in
//! the engine: `spatter_flow::validation::validation_cases` and `spatter_flow::bench::bench`.

pub mod config;
pub mod forces;
pub mod run;

pub use config::{DepositionConfig, ForcesConfig};
pub use run::{run, DepositionError};

#[cfg(test)]
mod tests;
