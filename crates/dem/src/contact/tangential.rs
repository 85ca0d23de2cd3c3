//! Tangential laws: spring with history, dashpot and Coulomb cap.

use super::{ContactInput, NormalForce, PairProps};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use spatter_core::Vec3;
use std::fmt::Debug;

/// The tangential force of one contact in one step.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TangentialForce {
    /// Force on particle i \[N\], perpendicular to the normal.
    pub force: Vec3,
    /// Energy dissipated in this step \[J\] (dashpot and Coulomb slip).
    pub dissipated: f64,
    /// Elastic energy of the tangential spring \[J\].
    pub energy: f64,
}

/// A tangential contact law.
pub trait TangentialLaw: Clone + Debug + Send + Sync + 'static {
    type Params: Clone + Debug + Send + Sync;
    type State: Copy + Default + PartialEq + Debug + Send + Sync + Serialize + DeserializeOwned;

    fn params(&self, pair_index: usize, props: &PairProps) -> Self::Params;

    /// Tangential stiffness k_t \[N/m\] (the damping law builds γ_t from it).
    fn stiffness(&self, p: &Self::Params, nf: &NormalForce, c: &ContactInput) -> f64;

    /// k_t/S_n when it is a constant of the pair type, given S_n/a \[Pa\] of the normal law if that is one
    /// ([`super::NormalLaw::damping_stiffness_per_radius`]); else `None` (the default). The damping law
    /// may then derive γ_t from the square root it takes for γ_n ([`super::DampingLaw::coefficients`]).
    fn stiffness_ratio(&self, _p: &Self::Params, _sn_per_radius: Option<f64>) -> Option<f64> {
        None
    }

    /// The tangential force for tangential relative velocity `v_t` \[m/s\], dashpot `gamma_t` \[N s/m\] and
    /// Coulomb normal force `f_coulomb` ≥ 0 \[N\]; updates the history in `state`. With `energy` false the
    /// returned energy and dissipation may be left zero.
    #[allow(clippy::too_many_arguments)]
    fn force(
        &self,
        p: &Self::Params,
        state: &mut Self::State,
        k_t: f64,
        gamma_t: f64,
        f_coulomb: f64,
        v_t: Vec3,
        c: &ContactInput,
        energy: bool,
    ) -> TangentialForce;
}

/// Tangential spring with history ξ (the accumulated tangential displacement while in contact),
/// Coulomb-capped:
///
/// 1. ξ is rotated into the current tangent plane keeping its length (the contact frame turns with the
///    pair; projecting without rescaling would silently lose stored energy, rescaling keeps ½k_t|ξ|²);
/// 2. ξ ← s ξ + v_t Δt with the law's history scale s, trial force F = −k_t ξ − γ_t v_t;
/// 3. if |F| > μ F_c: F ← μ F_c F/|F| and ξ ← −F/k_t (the spring carries the capped force, no dashpot
///    while sliding, as LIGGGHTS), so a sliding contact stores exactly (μF_c)²/(2k_t) and can never push
///    along the sliding direction afterwards.
///
/// The scale s says how the stored force follows a stiffness change k_prev → k_t (contact radius
/// a_prev → a for Mindlin): with s = 1 the force is k_t ξ, i.e. it follows the stiffness both ways; with
/// s = k_prev/k_t the force is kept and only the increment k_t Δξ is added (incremental form). See
/// [`MindlinHistory`] for the four combinations. Shared by [`Mindlin`], [`MindlinVariant`] and
/// [`LinearHistory`].
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn spring_history(
    xi: &mut Vec3,
    k_prev: &mut f64,
    scale: f64,
    k_t: f64,
    gamma_t: f64,
    mu: f64,
    f_coulomb: f64,
    v_t: Vec3,
    n: Vec3,
    dt: f64,
    track_energy: bool,
) -> TangentialForce {
    let len2 = xi.length_squared();
    let mut x = *xi;
    let proj = x.dot(n);
    // Rescaling changes the length by a factor 1/√(1 − proj²/len2), which is 1 to double precision when
    // proj² ≤ 1e-16 len2 (the usual case in slow, dense flow): skip the square root and division then.
    if proj * proj > 1e-16 * len2 {
        x -= proj * n;
        let l2 = x.length_squared();
        // A history (almost) parallel to the new normal has no tangential meaning: drop it.
        x = if l2 > 1e-24 * len2 { x * (len2 / l2).sqrt() } else { Vec3::ZERO };
    } else {
        x -= proj * n;
    }
    x = x * scale + v_t * dt;
    let mut f = -k_t * x - gamma_t * v_t;
    let cap = mu * f_coulomb;
    let f2 = f.length_squared();
    if f2 > cap * cap {
        // F ← μF_c F/|F|, ξ ← −F/k_t, with one square root and one division.
        let len = f2.sqrt();
        if k_t > 0.0 {
            let t = 1.0 / (len * k_t);
            x = f * (-cap * t);
            f *= cap * k_t * t;
        } else {
            f *= cap / len;
            x = Vec3::ZERO;
        }
    }
    *xi = x;
    // Energy stored at the end of the previous step (with the stiffness of then; the rotation keeps |ξ|).
    let u_old = 0.5 * std::mem::replace(k_prev, k_t) * len2;
    if !track_energy {
        return TangentialForce { force: f, dissipated: 0.0, energy: 0.0 };
    }
    let energy = 0.5 * k_t * x.length_squared();
    // Energy absorbed by the contact in this step minus the change of stored spring energy. A spring whose
    // stiffness changes with the normal load (Mindlin) changes its stored energy without work; that change
    // is counted here too, so mechanical + dissipated energy is conserved exactly by the bookkeeping.
    let dissipated = -f.dot(v_t) * dt - (energy - u_old);
    TangentialForce { force: f, dissipated, energy }
}

/// Implements [`TangentialLaw`] for a spring-with-history law from its stiffness k_t(params, normal force),
/// its constant k_t/S_n if any (given S_n/a, see [`TangentialLaw::stiffness_ratio`]) and its history
/// scale s(k_t/k_t,prev) (see [`spring_history`]): the laws differ only in these three.
macro_rules! spring_law {
    (
        $law:ty,
        |$l:ident, $p:ident, $nf:ident| $stiffness:expr,
        |$l3:ident, $p3:ident, $sn_per_radius:ident| $stiffness_ratio:expr,
        |$l2:ident, $ratio:ident| $scale:expr
    ) => {
        impl TangentialLaw for $law {
            type Params = MindlinParams;
            type State = SpringHistory;

            fn params(&self, _pair_index: usize, props: &PairProps) -> MindlinParams {
                MindlinParams::new(props.g_star, props.friction)
            }

            #[inline(always)]
            fn stiffness(&self, $p: &MindlinParams, $nf: &NormalForce, _c: &ContactInput) -> f64 {
                let $l = self;
                $stiffness
            }

            fn stiffness_ratio(&self, $p3: &MindlinParams, $sn_per_radius: Option<f64>) -> Option<f64> {
                let $l3 = self;
                $stiffness_ratio
            }

            #[inline(always)]
            fn force(
                &self,
                p: &MindlinParams,
                s: &mut SpringHistory,
                k_t: f64,
                gamma_t: f64,
                f_coulomb: f64,
                v_t: Vec3,
                c: &ContactInput,
                energy: bool,
            ) -> TangentialForce {
                let $l2 = self;
                // k_t/k_t,prev = a/a_prev for Mindlin (1 at first touch and when either is zero).
                let $ratio = if s.k_prev > 0.0 && k_t > 0.0 { k_t / s.k_prev } else { 1.0 };
                let scale = $scale;
                spring_history(
                    &mut s.xi,
                    &mut s.k_prev,
                    scale,
                    k_t,
                    gamma_t,
                    p.mu,
                    f_coulomb,
                    v_t,
                    c.normal,
                    c.dt,
                    energy,
                )
            }
        }
    };
}

/// Mindlin (no-slip) tangential stiffness k_t = 8 G* a with history and Coulomb cap μ.
///
/// Reference: Mindlin (1949) J. Appl. Mech. 16:259; Chung & Ooi (2011) §2; LAMMPS `tangential mindlin`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Mindlin;

/// Per-pair parameters of [`Mindlin`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MindlinParams {
    /// G* \[Pa\].
    pub g_star: f64,
    /// Sliding friction coefficient μ.
    pub mu: f64,
    /// 8 G* \[Pa\], the Mindlin stiffness per contact radius (k_t = 8 G* a), formed once per pair type.
    pub stiffness_per_radius: f64,
}

impl MindlinParams {
    /// The parameters for effective shear modulus G* = `g_star` \[Pa\] and friction coefficient `mu`.
    pub fn new(g_star: f64, mu: f64) -> Self {
        MindlinParams { g_star, mu, stiffness_per_radius: 8.0 * g_star }
    }
}

/// Tangential history state: the spring displacement ξ \[m\] and the stiffness of the last step \[N/m\]
/// (for the energy bookkeeping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SpringHistory {
    pub xi: Vec3,
    pub k_prev: f64,
}

spring_law!(
    Mindlin,
    |_law, p, nf| p.stiffness_per_radius * nf.contact_radius,
    |_law, p, sn_per_radius| mindlin_stiffness_ratio(p, sn_per_radius),
    |_law, _ratio| 1.0
);

/// k_t/S_n = 8G*a/(S_n/a · a) of a Mindlin spring when S_n/a is a constant (4G*/E* with Hertz).
fn mindlin_stiffness_ratio(p: &MindlinParams, sn_per_radius: Option<f64>) -> Option<f64> {
    sn_per_radius.filter(|&s| s > 0.0).map(|s| 8.0 * p.g_star / s)
}

/// Linear tangential spring k_t = `stiffness_ratio` × S_n (S_n = k_n for Hooke) with history and Coulomb
/// cap. LIGGGHTS `hooke` uses ratio 1 (or 2/7 with `ktToKnUser`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinearHistory {
    pub stiffness_ratio: f64,
}

impl Default for LinearHistory {
    fn default() -> Self {
        LinearHistory { stiffness_ratio: 2.0 / 7.0 }
    }
}

spring_law!(
    LinearHistory,
    |law, _p, nf| law.stiffness_ratio * nf.damping_stiffness,
    |law, _p, _sn_per_radius| Some(law.stiffness_ratio),
    |_law, _ratio| 1.0
);

/// No tangential force.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Frictionless;

impl TangentialLaw for Frictionless {
    type Params = ();
    type State = ();

    fn params(&self, _pair_index: usize, _props: &PairProps) {}

    #[inline(always)]
    fn stiffness(&self, _p: &(), _nf: &NormalForce, _c: &ContactInput) -> f64 {
        0.0
    }

    fn stiffness_ratio(&self, _p: &(), _sn_per_radius: Option<f64>) -> Option<f64> {
        Some(0.0)
    }

    #[inline(always)]
    fn force(
        &self,
        _p: &(),
        _s: &mut (),
        _k_t: f64,
        _gamma_t: f64,
        _f_coulomb: f64,
        _v_t: Vec3,
        _c: &ContactInput,
        _energy: bool,
    ) -> TangentialForce {
        TangentialForce::default()
    }
}

/// How a Mindlin spring's history follows a changing contact radius a (k_t = 8G*a). The four choices of
/// LAMMPS `pair granular` (`mindlin`, `mindlin_rescale`, `mindlin/force`, `mindlin_rescale/force`).
///
/// With the stored elastic force F_e, stiffness k = 8G*a and a_prev the radius of the previous step:
///
/// | choice | F_e when a changes (before adding k Δξ) | energy over a closed load cycle |
/// |---|---|---|
/// | `Displacement` | F_e a/a_prev (both ways) | can be created: displace at small a, load normally, return |
/// | `DisplacementRescaled` | F_e a/a_prev loading, F_e (a/a_prev)² unloading | can be created (same cycle) |
/// | `Force` | kept | can be created: displace at large a, unload normally, return |
/// | `ForceRescaled` | kept loading, F_e a/a_prev unloading | never created |
///
/// `ForceRescaled` is the no-slip limit (θ = 1) of the incremental Mindlin–Deresiewicz law as written by
/// Thornton, Cummins & Cleary (2013) Powder Technol. 233:30, eq. 18 (ΔT = 8G*a Δδ_t; T scaled by a/a_prev
/// when the normal load decreases); `DisplacementRescaled` follows Walton (personal communication cited
/// by the LAMMPS documentation of `pair granular`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MindlinHistory {
    /// F = k_t ξ with the total displacement ξ (LAMMPS `mindlin`, LIGGGHTS `tangential history`).
    #[default]
    Displacement,
    /// ξ ← ξ a/a_prev when a shrinks (LAMMPS `mindlin_rescale`).
    DisplacementRescaled,
    /// Incremental force: F ← F + k_t Δξ (LAMMPS `mindlin/force`).
    Force,
    /// Incremental force, F ← F a/a_prev when a shrinks (LAMMPS `mindlin_rescale/force`).
    ForceRescaled,
}

impl MindlinHistory {
    /// The scale s of [`spring_history`] for the stiffness ratio r = k_t/k_prev = a/a_prev.
    #[inline(always)]
    pub fn scale(self, ratio: f64) -> f64 {
        match self {
            MindlinHistory::Displacement => 1.0,
            MindlinHistory::DisplacementRescaled => ratio.min(1.0),
            MindlinHistory::Force => 1.0 / ratio,
            MindlinHistory::ForceRescaled => (1.0 / ratio).min(1.0),
        }
    }
}

/// Mindlin no-slip stiffness k_t = 8 G* a with a chosen [`MindlinHistory`] and Coulomb cap μ.
/// `MindlinVariant { history: MindlinHistory::Displacement }` is [`Mindlin`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MindlinVariant {
    pub history: MindlinHistory,
}

spring_law!(
    MindlinVariant,
    |_law, p, nf| p.stiffness_per_radius * nf.contact_radius,
    |_law, p, sn_per_radius| mindlin_stiffness_ratio(p, sn_per_radius),
    |law, ratio| law.history.scale(ratio)
);
