//! Ground shear and grain lift-off under a flow: the first half of the brownout question "which grains
//! leave the ground, where, and when".
//!
//! * [`wall_law`] — friction velocity, y⁺, D_p⁺ and the smooth-wall law of the wall (Spalding's formula);
//! * [`ground_shear`] — wall shear stress along the ground of any [`crate::field::FlowField`] by a wall
//!   function, and the fraction of time the Shields parameter exceeds its threshold;
//! * [`shields`] — the Shields parameter and its critical values;
//! * [`incipient`] — the moment balance of a grain on two bed grains about the downwind asperity (drag,
//!   wall lift, cohesion, weight) and the lift-off balance, with their critical friction velocities;
//! * [`map`] — the lift-off map (ground distance × grain size) as CSV and PNG;
//! * [`entrainment`] — the empirical entrainment models (Bagnold / Shao–Lu thresholds, Haehnel,
//!   Wachspress, White / Phillips–Brown) and the mass lifted per ground annulus.

pub mod entrainment;
pub mod ground_shear;
pub mod incipient;
pub mod map;
pub mod shields;
pub mod wall_law;
