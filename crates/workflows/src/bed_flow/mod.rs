//! A DEM particle bed under a ground-adjacent flow (one-way coupling).
//!
//! * [`near_ground`] — the flow over the patch: friction velocity and direction from a uniform shear
//!   flow or from any `FlowField` (rotor wall jet, imported or solved field);
//! * [`exposure`] — which grains feel the flow (not covered from above, not in the lee of a protruding
//!   upwind grain);
//! * [`forces`] — drag, wall lift (and optionally Saffman and Magnus) from the force library on the
//!   exposed grains at their real centre height, installed as the DEM engine's external-force hook;
//! * [`bed`] — building the bed (bed file or pour), stepping it, taking out the grains that leave it.
//!
//! The brownout workflow hands the grains that leave the bed to the dust cloud's tracker.

pub mod bed;
pub mod exposure;
pub mod forces;
pub mod near_ground;

#[cfg(test)]
mod tests;

pub use bed::BedFlowState;
pub use bed::{BedFlow, DemBedConfig, Released};
pub use near_ground::{FieldShear, GroundFlow, TabulatedShear, UniformShear};
