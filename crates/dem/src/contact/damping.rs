//! Damping laws: the normal and tangential dashpots and the tensile-clamp convention.

use super::restitution_fit::{damping_coefficient, linearised_coefficient};
use super::{ContactInput, NormalForce, PairProps};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::fmt::Debug;

/// A damping law. The composed kernel adds F_nd = −γ_n (v_rel·n) to the normal force and passes γ_t to
/// the tangential law.
pub trait DampingLaw: Clone + Debug + Send + Sync + 'static {
    type Params: Clone + Debug + Send + Sync;
    /// Per-contact state (e.g. a coefficient fixed at first touch from the impact speed).
    type State: Copy + Default + PartialEq + Debug + Send + Sync + Serialize + DeserializeOwned;

    /// Precomputes pair-type parameters; `normal_exponent` is [`super::NormalLaw::damping_exponent`].
    fn params(&self, pair_index: usize, props: &PairProps, normal_exponent: f64) -> Self::Params;

    /// Called in every evaluation of a contact, before the coefficients are asked for. A law that fixes
    /// something at first touch (e.g. the impact speed, −c.v_rel·c.normal) keeps its own "formed" flag in
    /// its state, so laws that need none store nothing per contact. The default does nothing.
    #[inline(always)]
    fn in_contact(&self, _p: &Self::Params, _c: &ContactInput, _state: &mut Self::State) {}

    /// Normal dashpot coefficient γ_n ≥ 0 \[N s/m\].
    fn normal_coefficient(
        &self,
        p: &Self::Params,
        s: &Self::State,
        nf: &NormalForce,
        c: &ContactInput,
    ) -> f64;

    /// Tangential dashpot coefficient γ_t ≥ 0 \[N s/m\] for tangential stiffness `k_t` \[N/m\].
    fn tangential_coefficient(&self, p: &Self::Params, s: &Self::State, k_t: f64, c: &ContactInput) -> f64;

    /// Both dashpot coefficients (γ_n, γ_t) \[N s/m\], what the composed kernel calls. `ratio_sqrt` is
    /// √(k_t/S_n) when k_t/S_n is a constant of the pair type (see [`super::TangentialLaw::stiffness_ratio`]),
    /// so that a law whose coefficients go as √(m* S) can take γ_t from the square root of γ_n. The
    /// default asks [`DampingLaw::normal_coefficient`] and [`DampingLaw::tangential_coefficient`].
    #[inline(always)]
    fn coefficients(
        &self,
        p: &Self::Params,
        s: &Self::State,
        nf: &NormalForce,
        k_t: f64,
        _ratio_sqrt: Option<f64>,
        c: &ContactInput,
    ) -> (f64, f64) {
        (self.normal_coefficient(p, s, nf, c), self.tangential_coefficient(p, s, k_t, c))
    }

    /// Whether damping may not make the normal force tensile (see [`crate::contact`] conventions).
    fn tensile_clamp(&self, p: &Self::Params) -> bool;
}

/// How the restitution coefficient e is turned into a dashpot coefficient.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RestitutionCalibration {
    /// Solve the impact equation so that the realised e equals the input under the chosen clamp
    /// convention ([`super::restitution_fit`]). Default.
    #[default]
    Exact,
    /// The closed form of LIGGGHTS/LAMMPS (β = ln e/√(ln²e+π²), c = 2√(5/6)|β| for Hertz, 2|β| for
    /// Hooke): for comparisons with those codes.
    Linearised,
}

/// Viscous damping from the pair's coefficient of restitution: γ_n = c_n √(m* S_n), γ_t = c_t √(m* k_t),
/// where S_n comes from the normal law. c_t = c_n unless tangential damping is off.
///
/// Reference for the form: Tsuji, Tanaka & Ishida (1992), Powder Technol. 71:239; LIGGGHTS `hertz`
/// (γ = −2√(5/6) β √(S m*)). The exact calibration is this crate's ([`super::restitution_fit`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RestitutionDamping {
    /// Tensile clamp (default true).
    pub tensile_clamp: bool,
    pub calibration: RestitutionCalibration,
    /// Tangential dashpot on (default true, as LIGGGHTS).
    pub tangential: bool,
}

impl Default for RestitutionDamping {
    fn default() -> Self {
        RestitutionDamping {
            tensile_clamp: true,
            calibration: RestitutionCalibration::Exact,
            tangential: true,
        }
    }
}

/// Per-pair parameters of [`RestitutionDamping`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RestitutionDampingParams {
    /// Dimensionless normal coefficient c_n.
    pub c_n: f64,
    /// Dimensionless tangential coefficient c_t.
    pub c_t: f64,
    pub clamp: bool,
}

impl RestitutionDamping {
    /// The dimensionless coefficient c for restitution `e` and force exponent `p` under this law's options.
    pub fn coefficient(&self, e: f64, p: f64) -> f64 {
        match self.calibration {
            RestitutionCalibration::Exact => damping_coefficient(e, p, self.tensile_clamp),
            RestitutionCalibration::Linearised => linearised_coefficient(e, p),
        }
    }
}

impl DampingLaw for RestitutionDamping {
    type Params = RestitutionDampingParams;
    type State = ();

    fn params(&self, _pair_index: usize, props: &PairProps, p: f64) -> RestitutionDampingParams {
        let c_n = self.coefficient(props.restitution, p);
        RestitutionDampingParams {
            c_n,
            c_t: if self.tangential { c_n } else { 0.0 },
            clamp: self.tensile_clamp,
        }
    }

    #[inline(always)]
    fn normal_coefficient(
        &self,
        p: &RestitutionDampingParams,
        _s: &(),
        nf: &NormalForce,
        c: &ContactInput,
    ) -> f64 {
        p.c_n * (c.m_eff * nf.damping_stiffness).sqrt()
    }

    #[inline(always)]
    fn tangential_coefficient(
        &self,
        p: &RestitutionDampingParams,
        _s: &(),
        k_t: f64,
        c: &ContactInput,
    ) -> f64 {
        p.c_t * (c.m_eff * k_t).sqrt()
    }

    #[inline(always)]
    fn coefficients(
        &self,
        p: &RestitutionDampingParams,
        s: &(),
        nf: &NormalForce,
        k_t: f64,
        ratio_sqrt: Option<f64>,
        c: &ContactInput,
    ) -> (f64, f64) {
        let root = (c.m_eff * nf.damping_stiffness).sqrt();
        let gamma_t = match ratio_sqrt {
            // √(m* k_t) = √(m* S_n) √(k_t/S_n): one square root less per contact.
            Some(r) => p.c_t * r * root,
            None => self.tangential_coefficient(p, s, k_t, c),
        };
        (p.c_n * root, gamma_t)
    }

    #[inline(always)]
    fn tensile_clamp(&self, p: &RestitutionDampingParams) -> bool {
        p.clamp
    }
}

/// No damping (elastic contacts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct NoDamping;

impl DampingLaw for NoDamping {
    type Params = ();
    type State = ();

    fn params(&self, _pair_index: usize, _props: &PairProps, _p: f64) {}

    #[inline(always)]
    fn normal_coefficient(&self, _p: &(), _s: &(), _nf: &NormalForce, _c: &ContactInput) -> f64 {
        0.0
    }

    #[inline(always)]
    fn tangential_coefficient(&self, _p: &(), _s: &(), _k_t: f64, _c: &ContactInput) -> f64 {
        0.0
    }

    fn tensile_clamp(&self, _p: &()) -> bool {
        true
    }
}
