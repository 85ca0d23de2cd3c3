//! Rolling-resistance laws: a torque opposing the relative rolling rotation.
//!
//! The rolling rotation is the part of ω_rel = ωᵢ − ωⱼ perpendicular to the normal (twisting about n is
//! excluded). Both laws below are limited so that the torque cannot reverse the relative rolling rotation
//! within one step (|M| ≤ I_eff |ω_roll| / Δt with 1/I_eff = 1/Iᵢ + 1/Iⱼ): the classic constant-torque
//! law otherwise chatters around ω_roll = 0 (Ai et al. 2011, §3.1).
//!
//! Reference: Ai, Chen, Rotter & Ooi (2011), "Assessment of rolling resistance models in discrete element
//! simulations", Powder Technol. 206:269–282 — model A (constant directional torque) and model B
//! (viscous).

use super::{ContactInput, PairProps};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use spatter_core::Vec3;
use std::fmt::Debug;

/// A rolling-resistance law.
pub trait RollingLaw: Clone + Debug + Send + Sync + 'static {
    type Params: Clone + Debug + Send + Sync;
    type State: Copy + Default + PartialEq + Debug + Send + Sync + Serialize + DeserializeOwned;

    /// Whether the law reads [`ContactInput::w_rel`] and [`ContactInput::i_eff`]; a law that does not
    /// must return a zero torque (see [`super::ContactLaw::USES_ROTATION`]).
    const USES_ROTATION: bool = true;

    fn params(&self, pair_index: usize, props: &PairProps) -> Self::Params;

    /// Torque on particle i \[N m\] and dissipation rate \[W\], for the normal force `f_n` ≥ 0 \[N\] that caps
    /// friction.
    fn torque(&self, p: &Self::Params, state: &mut Self::State, f_n: f64, c: &ContactInput) -> (Vec3, f64);
}

#[inline(always)]
fn rolling_rotation(c: &ContactInput) -> Vec3 {
    c.w_rel - c.w_rel.dot(c.normal) * c.normal
}

/// Applies the no-reversal limit and returns (torque, dissipation) for a torque of magnitude `m`
/// opposing `w_roll`.
#[inline(always)]
fn opposing(m: f64, w_roll: Vec3, c: &ContactInput) -> (Vec3, f64) {
    let w = w_roll.length();
    if w == 0.0 || m <= 0.0 {
        return (Vec3::ZERO, 0.0);
    }
    let limit = if c.dt > 0.0 { c.i_eff * w / c.dt } else { f64::INFINITY };
    let m = m.min(limit);
    (w_roll * (-m / w), m * w)
}

/// Model A: constant directional torque M = −μ_r R* F_n ω̂_roll (LIGGGHTS `rolling_friction cdt`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ConstantTorque;

impl RollingLaw for ConstantTorque {
    /// μ_r (dimensionless).
    type Params = f64;
    type State = ();

    fn params(&self, _pair_index: usize, props: &PairProps) -> f64 {
        props.rolling_friction
    }

    #[inline(always)]
    fn torque(&self, mu_r: &f64, _s: &mut (), f_n: f64, c: &ContactInput) -> (Vec3, f64) {
        opposing(mu_r * c.r_eff * f_n.max(0.0), rolling_rotation(c), c)
    }
}

/// Model B: viscous M = −μ_rv R* F_n (R* |ω_roll|) ω̂_roll, μ_rv in s/m.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ViscousRolling;

impl RollingLaw for ViscousRolling {
    /// μ_rv \[s/m\].
    type Params = f64;
    type State = ();

    fn params(&self, _pair_index: usize, props: &PairProps) -> f64 {
        props.rolling_viscous
    }

    #[inline(always)]
    fn torque(&self, mu_rv: &f64, _s: &mut (), f_n: f64, c: &ContactInput) -> (Vec3, f64) {
        let w = rolling_rotation(c);
        opposing(mu_rv * c.r_eff * c.r_eff * f_n.max(0.0) * w.length(), w, c)
    }
}

/// No rolling resistance.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NoRolling;

impl RollingLaw for NoRolling {
    type Params = ();
    type State = ();
    const USES_ROTATION: bool = false;

    fn params(&self, _pair_index: usize, _props: &PairProps) {}

    #[inline(always)]
    fn torque(&self, _p: &(), _s: &mut (), _f_n: f64, _c: &ContactInput) -> (Vec3, f64) {
        (Vec3::ZERO, 0.0)
    }
}

/// Rolling law chosen at run time (a `match` per contact, no `dyn`): none, constant torque or viscous.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AnyRolling {
    #[default]
    None,
    ConstantTorque,
    Viscous,
}

impl RollingLaw for AnyRolling {
    /// (μ_r, μ_rv).
    type Params = (f64, f64);
    type State = ();

    fn params(&self, _pair_index: usize, props: &PairProps) -> (f64, f64) {
        (props.rolling_friction, props.rolling_viscous)
    }

    #[inline(always)]
    fn torque(&self, p: &(f64, f64), s: &mut (), f_n: f64, c: &ContactInput) -> (Vec3, f64) {
        match self {
            AnyRolling::None => (Vec3::ZERO, 0.0),
            AnyRolling::ConstantTorque => ConstantTorque.torque(&p.0, s, f_n, c),
            AnyRolling::Viscous => ViscousRolling.torque(&p.1, s, f_n, c),
        }
    }
}
