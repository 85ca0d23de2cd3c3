//! Rigid bodies made of spheres ("clumps", multi-sphere particles): the body set, rotation, mass
//! properties and templates.
//!
//! How a clump moves (per step of velocity Verlet, `crate::sim`):
//!
//! 1. member spheres are ordinary particles: their wall and pair contacts are found and computed by the
//!    sphere loops (members of one body are never listed as a pair);
//! 2. after each force evaluation the member forces are reduced onto the body, in member order, so the
//!    sums do not depend on the thread count: F = Σ fᵢ + M g, T = Σ (rᵢ × fᵢ + τᵢ), rᵢ = xᵢ − X;
//! 3. the body is kicked and drifted: V += ½Δt F/M, π += ½Δt qᵀTq, X += V Δt, the free rotor
//!    ([`rotation`]) turns q and π, a second half kick after the next evaluation;
//! 4. members are placed rigidly, xᵢ = X + q rᵢ, vᵢ = V + ω × (q rᵢ), ωᵢ = ω.

pub mod bodies;
pub mod fill;
pub mod mass;
pub mod rotation;
pub mod shapes;
pub mod template;

pub(crate) use bodies::BodyRecord;
pub use bodies::{Bodies, NewBody, NO_BODY};
pub use mass::MassProperties;
pub use template::{ClumpTemplate, MassBasis};
