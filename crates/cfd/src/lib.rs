//! `spatter-cfd`: an incompressible finite-volume flow solver on structured staggered grids.
//!
//! * [`grid`] — axes (uniform, geometric, tanh-clustered), the padded layout, metric factors, and the
//!   3D Cartesian and 2D axisymmetric (r, z) modes;
//! * [`mg`] — geometric multigrid V-cycle for the pressure operator;
//! * [`pcg`] — conjugate gradients preconditioned by that V-cycle;
//! * [`reduce`] — parallel plane loops and thread-count-independent sums.

pub mod grid;
pub mod mg;
pub mod pcg;
pub mod reduce;
