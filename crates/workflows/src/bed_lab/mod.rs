//! The particle-bed laboratory (Jasion 2013, *Toward a Physics Based Entrainment Model for Simulation of
//! Helicopter Brownout*, PhD thesis, University of Southampton, Appendices A–C): the integrator study.
//! Every key is documented in `docs/bed.md`.

pub mod bed_file;
pub mod integrator_study;
pub mod probe_analysis;

pub use integrator_study::{run as run_integrator_study, IntegratorStudyConfig};
