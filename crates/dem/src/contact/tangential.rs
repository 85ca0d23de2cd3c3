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
/// 2. ξ ← ξ + v_t Δt, trial force F = −k_t ξ − γ_t v_t;
/// 3. if |F| > μ F_c: F ← μ F_c F/|F| and ξ ← −F/k_t (the spring carries the capped force, no dashpot
///    while sliding, as LIGGGHTS), so a sliding contact stores exactly (μF_c)²/(2k_t) and can never push
///    along the sliding direction afterwards.
///
/// Shared by [`Mindlin`] (k_t = 8 G* a) and [`LinearHistory`] (k_t ∝ k_n).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn spring_history(
    xi: &mut Vec3,
    k_prev: &mut f64,
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
    // Energy stored at the end of the previous step (with the stiffness of then; the rotation keeps |ξ|).
    let u_old = 0.5 * *k_prev * len2;
    x += v_t * dt;
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
    *k_prev = k_t;
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
}

/// Tangential history state: the spring displacement ξ \[m\] and the stiffness of the last step \[N/m\]
/// (for the energy bookkeeping).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SpringHistory {
    pub xi: Vec3,
    pub k_prev: f64,
}

impl TangentialLaw for Mindlin {
    type Params = MindlinParams;
    type State = SpringHistory;

    fn params(&self, _pair_index: usize, props: &PairProps) -> MindlinParams {
        MindlinParams { g_star: props.g_star, mu: props.friction }
    }

    #[inline(always)]
    fn stiffness(&self, p: &MindlinParams, nf: &NormalForce, _c: &ContactInput) -> f64 {
        8.0 * p.g_star * nf.contact_radius
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
        spring_history(&mut s.xi, &mut s.k_prev, k_t, gamma_t, p.mu, f_coulomb, v_t, c.normal, c.dt, energy)
    }
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

impl TangentialLaw for LinearHistory {
    type Params = MindlinParams;
    type State = SpringHistory;

    fn params(&self, _pair_index: usize, props: &PairProps) -> MindlinParams {
        MindlinParams { g_star: props.g_star, mu: props.friction }
    }

    #[inline(always)]
    fn stiffness(&self, _p: &MindlinParams, nf: &NormalForce, _c: &ContactInput) -> f64 {
        self.stiffness_ratio * nf.damping_stiffness
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
        spring_history(&mut s.xi, &mut s.k_prev, k_t, gamma_t, p.mu, f_coulomb, v_t, c.normal, c.dt, energy)
    }
}

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
