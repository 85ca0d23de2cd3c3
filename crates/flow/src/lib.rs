//! `spatter-flow`: particles in air.
//!
//! * [`forces`] — the particle–fluid force library (drag laws, lift, torque, history, added mass, pressure
//!   gradient, gravity/buoyancy, wall-bounded lift) and the nondimensional force ranking;
//!
//! Every quantity is SI. Forces are per unit particle mass (accelerations) unless a function says
//! otherwise.

// Index loops over small fixed arrays (barycentric weights, 4×4 systems) read like the formulas.
#![allow(clippy::needless_range_loop)]

pub mod field;
pub mod forces;
pub mod tracker;
pub mod vtk;
