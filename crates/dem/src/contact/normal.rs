//! Normal contact laws: the elastic (possibly adhesive) normal force and what it tells the other parts.

use super::{ContactInput, PairProps};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::fmt::Debug;

/// What a normal law reports for one contact in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NormalForce {
    /// Elastic normal force F_ne \[N\]; positive repulsive, negative attractive.
    pub force: f64,
    /// Stiffness S_n \[N/m\] from which the damping law builds γ_n = c·√(m* S_n); 0 switches damping off
    /// (e.g. inside an adhesive neck).
    pub damping_stiffness: f64,
    /// Contact radius a \[m\] (Mindlin k_t = 8 G* a).
    pub contact_radius: f64,
    /// The normal force that caps Coulomb friction, μ·F_c \[N\]: `None` = as the composed law's
    /// [`super::CoulombLoad`] says (default: the total normal force after damping, clamped at zero),
    /// `Some(F)` = the law's own choice (≥ 0).
    pub coulomb_force: Option<f64>,
    /// Elastic energy stored in the normal direction \[J\].
    pub energy: f64,
}

/// An elastic normal contact law. See the module documentation of [`crate::contact`] for a step-by-step
/// guide to writing one.
pub trait NormalLaw: Clone + Debug + Send + Sync + 'static {
    /// Parameters precomputed once per pair type.
    type Params: Clone + Debug + Send + Sync;
    /// Per-contact persistent state (`Default` = no contact yet).
    type State: Copy + Default + PartialEq + Debug + Send + Sync + Serialize + DeserializeOwned;

    /// Precomputes the parameters of pair type `pair_index`.
    fn params(&self, pair_index: usize, props: &PairProps) -> Self::Params;

    /// Largest gap −δ ≥ 0 \[m\] at which the law may still act or keep state (0 for non-adhesive laws).
    fn range(&self, _p: &Self::Params, _r_eff: f64) -> f64 {
        0.0
    }

    /// The normal force at overlap `c.overlap`, or `None` when the partners are not in contact (the
    /// engine then resets `state`).
    fn evaluate(&self, p: &Self::Params, c: &ContactInput, state: &mut Self::State) -> Option<NormalForce>;

    /// Exponent p of the power law F = k δᵖ used to calibrate restitution damping (1 Hooke, 1.5 Hertz).
    fn damping_exponent(&self) -> f64;

    /// S_n/a \[Pa\] when the damping stiffness is proportional to the contact radius in every contact of
    /// the pair type (Hertz: S_n = 2E*a), else `None` (the default). With a tangential stiffness that is
    /// proportional to a too (Mindlin), k_t/S_n is then a constant of the pair type
    /// ([`super::TangentialLaw::stiffness_ratio`]), which saves a square root per contact.
    fn damping_stiffness_per_radius(&self, _p: &Self::Params) -> Option<f64> {
        None
    }
}

/// How the Hooke spring stiffness is chosen.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HookeStiffness {
    /// A constant k_n \[N/m\] for every pair.
    Constant(f64),
    /// k_n such that a Hooke impact at this characteristic speed \[m/s\] reaches the same maximum overlap
    /// as a Hertz impact: k_n = (16/15) √R* E* (15 m* V² / (16 √R* E*))^{1/5} (LIGGGHTS `hooke`
    /// with `characteristicVelocity`).
    CharacteristicVelocity(f64),
}

/// Linear spring: F_ne = k_n δ for δ > 0.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hooke {
    pub stiffness: HookeStiffness,
}

/// Per-pair parameters of [`Hooke`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HookeParams {
    /// E* \[Pa\] (used by the characteristic-velocity stiffness).
    pub e_star: f64,
    pub stiffness: HookeStiffness,
}

impl Hooke {
    /// k_n \[N/m\] of a contact.
    #[inline(always)]
    pub fn stiffness(p: &HookeParams, r_eff: f64, m_eff: f64) -> f64 {
        match p.stiffness {
            HookeStiffness::Constant(k) => k,
            HookeStiffness::CharacteristicVelocity(v) => {
                let s = r_eff.sqrt() * p.e_star;
                16.0 / 15.0 * s * (15.0 * m_eff * v * v / (16.0 * s)).powf(0.2)
            }
        }
    }
}

impl NormalLaw for Hooke {
    type Params = HookeParams;
    type State = ();

    /// The pair's own stiffness ([`PairProps::stiffness`]) wins over the law's global choice.
    fn params(&self, _pair_index: usize, props: &PairProps) -> HookeParams {
        let stiffness = props.stiffness.map_or(self.stiffness, HookeStiffness::Constant);
        HookeParams { e_star: props.e_star, stiffness }
    }

    #[inline(always)]
    fn evaluate(&self, p: &HookeParams, c: &ContactInput, _s: &mut ()) -> Option<NormalForce> {
        let d = c.overlap;
        if d <= 0.0 {
            return None;
        }
        let k = Self::stiffness(p, c.r_eff, c.m_eff);
        Some(NormalForce {
            force: k * d,
            damping_stiffness: k,
            contact_radius: (c.r_eff * d).sqrt(),
            coulomb_force: None,
            energy: 0.5 * k * d * d,
        })
    }

    fn damping_exponent(&self) -> f64 {
        1.0
    }
}

/// Hertz: F_ne = (4/3) E* √R* δ^{3/2} for δ > 0, contact radius a = √(R*δ), damping stiffness
/// S_n = dF/dδ = 2 E* a, elastic energy (8/15) E* √R* δ^{5/2}.
///
/// Reference: Johnson, *Contact Mechanics* (1985) §4.2; Chung & Ooi (2011) Eq. 1–3.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Hertz;

/// Per-pair parameters of [`Hertz`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzParams {
    /// E* \[Pa\].
    pub e_star: f64,
    /// (4/3) E* \[Pa\], the force factor (precomputed: the same product the formula forms first).
    pub force_factor: f64,
    /// 2 E* \[Pa\], the damping stiffness per contact radius S_n/a.
    pub stiffness_per_radius: f64,
}

impl HertzParams {
    /// The parameters for effective modulus E* = `e_star` \[Pa\].
    pub fn new(e_star: f64) -> Self {
        HertzParams { e_star, force_factor: 4.0 / 3.0 * e_star, stiffness_per_radius: 2.0 * e_star }
    }
}

impl NormalLaw for Hertz {
    type Params = HertzParams;
    type State = ();

    fn params(&self, _pair_index: usize, props: &PairProps) -> HertzParams {
        HertzParams::new(props.e_star)
    }

    #[inline(always)]
    fn evaluate(&self, p: &HertzParams, c: &ContactInput, _s: &mut ()) -> Option<NormalForce> {
        let d = c.overlap;
        if d <= 0.0 {
            return None;
        }
        let a = (c.r_eff * d).sqrt();
        // (4/3 E*) a δ and (2E*) a, with the constant factors formed once per pair type.
        let force = p.force_factor * a * d;
        Some(NormalForce {
            force,
            damping_stiffness: p.stiffness_per_radius * a,
            contact_radius: a,
            coulomb_force: None,
            energy: 0.4 * force * d,
        })
    }

    fn damping_exponent(&self) -> f64 {
        1.5
    }

    fn damping_stiffness_per_radius(&self, p: &HertzParams) -> Option<f64> {
        Some(p.stiffness_per_radius)
    }
}
