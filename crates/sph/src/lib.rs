//! Weakly compressible SPH engine for free-surface water with moving rigid bodies, surface tension,
//! adhesion, air drag, wetting and splash sensors.
//!
//! * [`bench`] — the `spatter bench sph` dam break; [`bench_dsph`] — DualSPHysics's 01_DamBreak, timed to a
//!   physical end time for the side-by-side run;
//! * [`kernel`], [`eos`], [`params`] — kernels (Wendland C2, cubic spline, Akinci splines), Tait equation
//!   of state, physical and numerical parameters;
//! * [`fluid`], [`boundary`] — particle storage; walls sampled from boxes and meshes, moving by
//!   [`spatter_core::motion::KinematicTree`];
//! * [`neighbours`], `pass` — cell-list neighbour loops (wall extrapolation, forces, continuity);
//! * [`guard`] — no particle crosses a wall, however thin;
//! * [`fill`] — fluid initialisation on a lattice (box minus solids, flood fill);
//! * [`drag`] — air drag;
//! * [`wetting`] — wetting maps and wet areas at wall-particle resolution;
//! * [`sessile`] — contact angle of a sessile drop for a given adhesion (calibration);
//! * [`validation`] — reference cases for `spatter validate`; [`wheel_wading`] — the wheel rolling through
//!   still water among them, with [`wheel_loads`], the hydrostatic loads it is held against;
//! * [`sim`] — the [`Simulation`] and its time step (velocity Verlet with one force evaluation per step).
//!
//! See `docs/sph.md` for the equations, defaults and references.

pub mod bench;
pub mod bench_dsph;
pub mod boundary;
mod candidates;
pub mod drag;
pub mod eos;
pub mod error;
pub mod fill;
pub mod fluid;
pub mod guard;
pub mod kernel;
mod local_walls;
pub mod neighbours;
pub mod params;
mod pass;
pub mod sessile;
pub mod sim;
pub mod validation;
pub mod wetting;
pub mod wheel_loads;
pub mod wheel_wading;

pub use error::SphError;
pub use kernel::{Dim, KernelKind};
pub use params::SphParams;
pub use sim::Simulation;
