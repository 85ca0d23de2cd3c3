//! Soft-sphere discrete element engine.

pub mod adhesion;
pub mod restitution_models;

pub mod bench;
pub mod clump;
pub mod contact;
pub mod error;
pub mod insertion;
pub mod integrators;
pub mod output;
pub mod packing;
pub mod par;
pub mod particles;
pub mod sim;
pub mod timestep;
pub mod validation;
pub mod walls;
pub mod wear;

pub use error::DemError;
pub use particles::{NewParticle, Particles};
pub use sim::{EnergyMethod, EnergyReport, Integrator, Settings, Simulation};
pub use validation::validation_cases;
