//! `spatter-cfd`: an incompressible finite-volume flow solver on structured staggered grids.
//!
//! * [`grid`] — axes (uniform, geometric, tanh-clustered), the padded layout, metric factors, and the
//!   3D Cartesian and 2D axisymmetric (r, z) modes;
//! * [`solid`] — blocked cells from analytic shapes (box, plate, cylinder, pipe wall) and closed STL/OBJ;
//! * [`regions`] — connected fluid regions and the mass balance each must satisfy;
//! * [`bc`] — walls (moving, slip), symmetry and axis, velocity inlets with time tables, pressure outlets,
//!   total-pressure sides;
//! * [`momentum`] — TVD (van Leer) convection and viscous diffusion on the staggered control volumes;
//! * [`sources`] — momentum sources: actuator disks and point forces from particles;
//! * [`turbulence`] — the standard and realizable k–ε models with wall functions;
//! * [`wall_shear`] — wall shear stress and friction velocity along the no-slip sides;
//! * [`solver`] — the projection method: Adams–Bashforth predictor, pressure correction, checks;
//! * [`mg`] — geometric multigrid V-cycle for the pressure operator;
//! * [`pcg`] — conjugate gradients preconditioned by that V-cycle;
//! * [`reduce`] — parallel plane loops and thread-count-independent sums;
//! * [`output`] — cell fields as `.vtr`, probes and slices for pictures;
//! * [`cavity`] — the lid-driven cavity and the tables of Ghia, Ghia & Shin (1982).
//!
//! Everything is SI. The solver works in kinematic pressure p/ρ internally and reports pascals.

// Stencil code indexes several arrays by the same grid coordinate; iterators would hide the geometry.
#![allow(clippy::needless_range_loop)]

pub mod bc;
pub mod bench;
pub mod cavity;
pub mod grid;
pub mod mg;
pub mod momentum;
pub mod output;
pub mod pcg;
pub mod reduce;
pub mod regions;
pub mod solid;
pub mod solver;
pub mod sources;
pub mod turbulence;
pub mod validation;
pub mod wall_shear;

#[cfg(test)]
mod pressure_sides_tests;

pub use bc::{Boundary, TimeTable};
pub use grid::{Axis, Grid, Mode};
pub use solid::Solid;
pub use solver::{Flow, FlowError, Fluid, Numerics, State};
