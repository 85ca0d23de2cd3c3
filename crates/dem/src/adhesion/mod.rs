//! Adhesive normal contact laws: full hysteretic JKR, DMT and simplified JKR, with the Tabor parameter
//! that says which one applies.
//!
//! * [`jkr`] — full JKR mechanics (contact radius by Newton on the normalised quartic, neck hysteresis,
//!   break criteria, stored energy);
//! * [`pull_off`] — Hertz plus a constant attraction while touching: 2πΓR* (DMT) or (3/2)πΓR*
//!   ("simplified JKR");
//! * [`tabor`] — the Tabor parameter.
//!
//! The pure mechanics here know nothing of the engine; the normal-law implementations that plug them into
//! the composable contact kernel live beside them.

pub mod jkr;
pub mod laws;
pub mod pull_off;
pub mod tabor;

pub use jkr::{BreakCriterion, Jkr, JkrEval, JkrState};
pub use laws::{AdhesiveCoulomb, DmtLaw, JkrContact, JkrDamping, JkrLaw, SjkrLaw};
pub use pull_off::{ConstantPullOff, PullOff};
pub use tabor::tabor_parameter;
