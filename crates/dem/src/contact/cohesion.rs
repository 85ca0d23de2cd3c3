//! Linear cohesion: a Hooke spring plus an attractive linear spring that acts over a cohesion radius
//! larger than the particle radius.
//!
//! Reference: Jasion (2013), *Toward a Physics Based Entrainment Model for Simulation of Helicopter
//! Brownout*, PhD thesis, University of Southampton, Eq. 3.60–3.61 (linear normal force) and Eq. 3.68
//! (cohesion, F_coh = −k_coh δ_coh n̂ with δ_coh the overlap of the cohesion radii r_coh > r). The thesis
//! writes the attractive case with a negative k_coh (its Table C.2); here k_coh ≥ 0 is the strength of the
//! attraction.

use super::normal::{Hooke, HookeParams, HookeStiffness, NormalForce, NormalLaw};
use super::{ContactInput, PairProps};
use serde::{Deserialize, Serialize};

/// Hooke normal force with linear cohesion. With overlap δ (of the particle radii) and the cohesion
/// overlap δ_coh = δ + (λ − 1)(rᵢ + rⱼ) (λ = r_coh/r; for a wall δ_coh = δ + (λ − 1) rᵢ), the elastic
/// normal force is
///
/// F_ne = k_n max(δ, 0) − k_coh δ_coh  for δ_coh > 0, no contact otherwise.
///
/// The attraction is largest, k_coh (λ − 1)(rᵢ + rⱼ), when the particle surfaces just touch; a pair held
/// together by this law therefore separates only under a pull larger than that force (with k_coh < k_n the
/// net tension falls again in compression). The dashpot acts only while δ > 0 (damping stiffness k_n,
/// restitution-calibrated as for Hooke); the tangential spring sees the same stiffness. The stored energy
/// ½ k_n max(δ, 0)² − ½ k_coh δ_coh² is zero where the cohesion radii just touch, so the energy budget of
/// a cohesive assembly closes like that of any other conservative law.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearCohesion {
    /// The repulsive spring (a pair's own [`PairProps::stiffness`] wins, as for [`Hooke`]).
    pub hooke: Hooke,
    /// λ = r_coh / r ≥ 1, the cohesion radius over the particle radius (Jasion 2013, Table C.2: 1.1).
    pub radius_ratio: f64,
}

/// Per-pair parameters of [`LinearCohesion`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LinearCohesionParams {
    pub hooke: HookeParams,
    /// k_coh \[N/m\].
    pub cohesion: f64,
    /// λ − 1 (0 when the pair has no cohesion, so that its contacts end at touching).
    pub extra: f64,
}

impl LinearCohesion {
    /// The law with constant stiffness `k_n` \[N/m\] and cohesion radius ratio `radius_ratio`.
    pub fn new(k_n: f64, radius_ratio: f64) -> Self {
        LinearCohesion { hooke: Hooke { stiffness: HookeStiffness::Constant(k_n) }, radius_ratio }
    }

    /// The largest attractive force \[N\] of a contact with radius sum `radius_sum` (rᵢ + rⱼ, or rᵢ for a
    /// wall): k_coh (λ − 1)(rᵢ + rⱼ), reached when the surfaces just touch. A steady pull above it
    /// separates the pair.
    pub fn pull_off_force(p: &LinearCohesionParams, radius_sum: f64) -> f64 {
        p.cohesion * p.extra * radius_sum
    }
}

impl NormalLaw for LinearCohesion {
    type Params = LinearCohesionParams;
    type State = ();

    fn params(&self, pair_index: usize, props: &PairProps) -> LinearCohesionParams {
        let cohesion = props.cohesion_stiffness;
        LinearCohesionParams {
            hooke: self.hooke.params(pair_index, props),
            cohesion,
            extra: if cohesion > 0.0 { (self.radius_ratio - 1.0).max(0.0) } else { 0.0 },
        }
    }

    /// (λ − 1)(rᵢ + rⱼ) with rᵢ + rⱼ ≤ 4 R* for a pair; for a wall (R* = rᵢ) this over-estimates the reach
    /// (λ − 1) rᵢ, which only widens the candidate search.
    fn range(&self, p: &LinearCohesionParams, r_eff: f64) -> f64 {
        p.extra * 4.0 * r_eff
    }

    #[inline(always)]
    fn evaluate(&self, p: &LinearCohesionParams, c: &ContactInput, _s: &mut ()) -> Option<NormalForce> {
        let d = c.overlap;
        let d_coh = d + p.extra * c.radius_sum;
        if d_coh <= 0.0 || (d <= 0.0 && p.extra == 0.0) {
            return None;
        }
        let k = Hooke::stiffness(&p.hooke, c.r_eff, c.m_eff);
        let dp = d.max(0.0);
        let attraction = p.cohesion * d_coh;
        Some(NormalForce {
            force: k * dp - attraction,
            damping_stiffness: if d > 0.0 { k } else { 0.0 },
            contact_radius: (c.r_eff * dp).sqrt(),
            coulomb_force: None,
            energy: 0.5 * k * dp * dp - 0.5 * attraction * d_coh,
        })
    }

    fn damping_exponent(&self) -> f64 {
        1.0
    }
}
