//! `spatter-core`: the pieces every spatter engine shares.
//!
//! * [`math`] — `f64` vectors and quaternions (re-exported from `glam`) and small geometric helpers;
//! * [`material`] — elastic materials and effective pair properties (E*, G*, R*, m*);
//! * [`mesh`] — triangle meshes, STL/OBJ readers, closest point on a triangle with face/edge/vertex regions;
//! * [`grid`] — a cell-list neighbour search shared by DEM and SPH;
//! * [`tri_bvh`] — a triangle hierarchy: segment crossings, closest points, inside tests;
//! * [`shapes`] — closed cylinder and box meshes;
//! * [`surface_sample`] — boundary-particle sampling of a mesh surface at a given spacing;
//! * [`motion`] — prescribed rigid-body kinematics (constant, rotating, tabulated, hierarchical);
//! * [`distribution`] — particle size distributions;
//! * [`timestep`] — Rayleigh and Hertz time-step estimates;
//! * [`control`] — how a long run learns it should stop and reports progress;
//! * [`comm`] — the ranks of a run split over processes (MPI) or threads, and their collectives;
//! * [`rcb`] — recursive coordinate bisection: which rank owns which part of space;
//! * [`rng`] — seeded, serialisable random number generators;
//! * [`check`] — physical validation of inputs with the key path of every bad value;
//! * [`regime`] — the stick/bounce wall rule (regime-map JSON) shared by the snow workflow and trackers;
//! * [`validation`] — the case/check format of `spatter validate`.
//!
//! Everything is in SI units. The core knows nothing of the engines built on it.

pub mod aabb;
pub mod check;
pub mod comm;
pub mod control;
pub mod distribution;
pub mod grid;
pub mod material;
pub mod math;
pub mod mesh;
pub mod motion;
pub mod rcb;
pub mod regime;
pub mod rng;
pub mod shapes;
pub mod special;
pub mod surface_sample;
pub mod timestep;
pub mod tri_bvh;
pub mod validation;

pub use aabb::Aabb;
pub use math::{Mat3, Quat, Vec3};
