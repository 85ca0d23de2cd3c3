//! Adhesive normal contact laws: full hysteretic JKR, DMT and simplified JKR, with the Tabor parameter
//! that says which one applies.
//!
//! * [`jkr`] — full JKR mechanics (contact radius by Newton on the normalised quartic, neck hysteresis,
//!   break criteria, stored energy);
//! * [`dmt`] — Hertz plus a constant 2πΓR* attraction while touching;
//! * [`sjkr`] — Hertz plus a constant (3/2)πΓR* attraction while touching ("simplified JKR");
//! * [`tabor`] — the Tabor parameter.
//!
//! The pure mechanics here know nothing of the engine; the normal-law implementations that plug them into
//! the composable contact kernel live beside them.

pub mod dmt;
pub mod jkr;
pub mod laws;
pub mod sjkr;
pub mod tabor;

pub use dmt::Dmt;
pub use jkr::{BreakCriterion, Jkr, JkrEval, JkrState};
pub use laws::{AdhesiveCoulomb, DmtLaw, JkrDamping, JkrLaw, SjkrLaw};
pub use sjkr::SimplifiedJkr;
pub use tabor::tabor_parameter;
