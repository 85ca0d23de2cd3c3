//! Soft-sphere discrete element engine.

pub mod adhesion;
pub mod restitution_models;

pub mod contact;
pub mod error;
pub mod insertion;
pub mod par;
pub mod particles;
pub mod sim;
pub mod validation;
pub mod walls;

pub use error::DemError;
pub use particles::{NewParticle, Particles};
pub use sim::{EnergyReport, Integrator, Settings, Simulation};
pub use validation::validation_cases;
