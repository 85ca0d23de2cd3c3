//! v_crit(d) by bisection: the normal speed below which a particle of diameter d sticks.
//!
//! Assumes one transition (stick below, bounce above), which the grid maps of the thesis baseline show;
//! the bracket is widened by factors of 4 when it does not contain the transition and the search then
//! halves it geometrically until its relative width is below the tolerance.

use super::impact::Outcome;
use super::model::{ImpactModel, Surface};
use serde::{Deserialize, Serialize};

/// Whether the bracket contained the transition.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum BracketStatus {
    /// v_crit lies inside the final bracket.
    Found,
    /// Even the lowest speed tried bounced: v_crit is below `low`.
    BelowRange,
    /// Even the highest speed tried stuck: v_crit is above `high`.
    AboveRange,
}

/// The critical speed of one diameter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CriticalSpeed {
    /// Diameter \[m\].
    pub diameter: f64,
    /// Geometric mean of the final bracket \[m/s\] (NaN unless found).
    pub v_crit: f64,
    /// Highest speed that stuck \[m/s\].
    pub low: f64,
    /// Lowest speed that bounced \[m/s\].
    pub high: f64,
    pub status: BracketStatus,
    /// Impacts simulated.
    pub impacts: u32,
    /// Impacts of the search that created energy ([`ImpactResult::created_energy`]): a numerical
    /// failure that makes the result untrustworthy.
    ///
    /// [`ImpactResult::created_energy`]: super::impact::ImpactResult::created_energy
    pub energy_created: u32,
}

/// Finds v_crit for diameter `d` \[m\] starting from the bracket [`low`, `high`] \[m/s\].
pub fn critical_speed(
    model: &ImpactModel,
    d: f64,
    low: f64,
    high: f64,
    rel_tol: f64,
    max_expansions: u32,
) -> CriticalSpeed {
    let mut impacts = 0u32;
    let mut energy_created = 0u32;
    let mut sticks = |v: f64| {
        impacts += 1;
        let r = model.simulate(d, v, 0.0, [0.0, 0.0], Surface::Configured).0;
        energy_created += u32::from(r.created_energy());
        r.outcome == Outcome::Stick
    };
    let (mut lo, mut hi) = (low.min(high), low.max(high));
    let mut k = 0;
    while !sticks(lo) {
        if k == max_expansions {
            return CriticalSpeed {
                diameter: d,
                v_crit: f64::NAN,
                low: 0.0,
                high: lo,
                status: BracketStatus::BelowRange,
                impacts,
                energy_created,
            };
        }
        hi = lo;
        lo /= 4.0;
        k += 1;
    }
    let mut k = 0;
    while sticks(hi) {
        if k == max_expansions {
            return CriticalSpeed {
                diameter: d,
                v_crit: f64::NAN,
                low: hi,
                high: f64::INFINITY,
                status: BracketStatus::AboveRange,
                impacts,
                energy_created,
            };
        }
        lo = hi;
        hi *= 4.0;
        k += 1;
    }
    while hi / lo - 1.0 > rel_tol {
        let mid = (lo * hi).sqrt();
        if sticks(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    CriticalSpeed {
        diameter: d,
        v_crit: (lo * hi).sqrt(),
        low: lo,
        high: hi,
        status: BracketStatus::Found,
        impacts,
        energy_created,
    }
}
