//! `spatter-flow`: particles in air.
//!
//! * [`forces`] — the particle–fluid force library (drag laws, lift, torque, history, added mass, pressure
//!   gradient, gravity/buoyancy, wall-bounded lift) and the nondimensional force ranking;
//! * [`field`] — flow fields: analytic (uniform, stagnation point, vortices, wall jet, rotor downwash) and
//!   imported from VTK files (`spatter_io::vtk`), with point location and interpolation, and turbulent dispersion;
//! * [`cloud`] — the dust cloud: size classes, a ground source of parcels, concentration and optical
//!   depth on a grid;
//! * [`liftoff`] — wall shear along the ground, Shields exceedance, the asperity moment balance and the
//!   lift-off map;
//! * [`tracker`] — parcels, injection, the integrator, wall rules on STL bodies, deposition statistics
//!   and the exact mass balance;
//! * [`validation`] — reference cases for `spatter validate`; [`bench`] — `spatter bench track`.
//!
//! Every quantity is SI. Forces are per unit particle mass (accelerations) unless a function says
//! otherwise.

// Index loops over small fixed arrays (barycentric weights, 4×4 systems) read like the formulas.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod cloud;
pub mod field;
pub mod forces;
pub mod liftoff;
pub mod tracker;
pub mod validation;
