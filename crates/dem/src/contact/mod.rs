//! Contact laws, composed per pair type like LAMMPS `pair granular`: a **normal** part (elastic force,
//! possibly adhesive and hysteretic), a **damping** part, a **tangential** part and a **rolling** part.
//!
//! # The pieces
//!
//! | trait | built-in laws | chooses |
//! |---|---|---|
//! | [`NormalLaw`] | [`Hooke`], [`Hertz`] | elastic normal force F_ne(δ), per-contact state, interaction range beyond touching, the damping stiffness S_n, the contact radius a, the force that caps Coulomb friction |
//! | [`DampingLaw`] | [`RestitutionDamping`], [`NoDamping`] | normal and tangential dashpot coefficients γ_n, γ_t and the tensile-clamp convention |
//! | [`TangentialLaw`] | [`Mindlin`], [`MindlinVariant`], [`LinearHistory`], [`Frictionless`] | tangential force with history, Coulomb cap |
//! | [`RollingLaw`] | [`ConstantTorque`], [`ViscousRolling`], [`NoRolling`] | rolling-resistance torque |
//!
//! [`Composed<N, D, T, R>`](Composed) glues one law of each kind into a [`ContactLaw`], the interface the
//! engine calls once per contact. The engine is generic over its `ContactLaw`, so the whole per-contact
//! computation is monomorphised and inlined: no `dyn` call per contact. Where a scenario file picks laws at
//! run time, the scene runner `match`es once on the choice and instantiates the engine for that
//! combination (see `spatter_workflows::dem_scene`).
//!
//! Each sub-law turns the pair's [`PairProps`] (E*, G*, μ, μ_r, e, Γ … of material a × material b) into its
//! own precomputed `Params` once per pair type ([`ContactLaw::params`]); the per-contact call only reads
//! them. Each sub-law also owns a per-contact `State` (tangential spring, JKR "contact formed" flag …)
//! that the engine stores with the contact, keyed by the stable ids of the two partners, and checkpoints.
//!
//! # Conventions
//!
//! * The normal `n` points from the partner (particle j or wall) to particle i. The overlap is
//!   δ = rᵢ + rⱼ − |xᵢ − xⱼ| (particle–particle) or δ = rᵢ − dist(xᵢ, wall); δ > 0 in compression.
//!   Contacts may exist at δ < 0 if the normal law says so (adhesive necks).
//! * `v_rel` is the velocity of particle i's contact point minus the partner's contact point; the normal
//!   approach speed is −v_rel·n.
//! * A positive normal force is repulsive. All forces in [`ContactOutput`] act on particle i; the partner
//!   gets the opposite force. The engine adds the torques of the tangential force, −rᵢ n × F on i and
//!   −rⱼ n × F on j (full radii as lever arms, the same arms the contact-point velocity uses, so the
//!   power balance is exact).
//! * **Tensile clamp (default on).** Damping may not make the total normal force tensile while the elastic
//!   force is repulsive, nor more tensile than an attractive elastic force:
//!   F_n = max(F_ne + F_nd, min(F_ne, 0)). The damping coefficient is calibrated for the convention in
//!   force ([`RestitutionDamping`]), so the realised coefficient of restitution equals the input e with the
//!   clamp on or off (Chung & Ooi test 3). With the clamp, the closed-form damping coefficient
//!   realises a higher restitution than asked (e_in = 0.5 → 0.55), hence the fitted option.
//! * **Coulomb force.** The tangential force is capped at μ·F_c where F_c is the normal law's choice
//!   ([`NormalForce::coulomb_force`]); for Hooke and Hertz it is, by default, the total (clamped) normal
//!   force including damping, so that tangential and normal impulses keep the ratio μ when sliding
//!   (Chung & Ooi tests 4–6), or the elastic force with [`CoulombLoad::Elastic`].
//!
//! # Adding a normal law
//!
//! Implement [`NormalLaw`] (see `normal.rs`, where [`Hertz`] is the worked example):
//!
//! 1. `type Params`: whatever you precompute per pair type from [`PairProps`] in [`NormalLaw::params`]
//!    (it receives the pair-type index too, so a law can carry its own per-pair table).
//! 2. `type State`: per-contact persistent state, `Default` = "no contact yet". For full JKR this holds the
//!    "contact formed" flag (and, e.g., the last contact radius as Newton start value). The engine resets
//!    it to `Default` when the law reports no contact.
//! 3. [`NormalLaw::range`]: the largest gap (−δ ≥ 0) at which the law may still act or keep state, e.g.
//!    δ_c for JKR. The neighbour search adds it to the contact distance. Zero for Hooke/Hertz.
//! 4. [`NormalLaw::evaluate`]: given δ, R* and the state, return `None` when there is no contact (not yet
//!    formed, or broken: for JKR, δ < 0 with the flag unset, or δ < −δ_c), else a [`NormalForce`]:
//!    * `force` — elastic normal force F_ne \[N\], may be negative (attractive);
//!    * `damping_stiffness` — S_n \[N/m\] for the dashpot γ_n = c·√(m* S_n); return 0 for no damping
//!      (e.g. in the JKR neck δ < 0, the LIGGGHTS convention), or 2E*a for the contact-radius variant;
//!    * `contact_radius` — a \[m\], used by Mindlin (k_t = 8G*a) and for outputs;
//!    * `coulomb_force` — `None` to leave the cap to [`Composed::coulomb_load`], or `Some(F)` with the
//!      law's own choice (LAMMPS JKR uses |F_ne + 2F_c|);
//!    * `energy` — elastic energy stored \[J\] for the energy budget.
//! 5. [`NormalLaw::damping_exponent`]: the exponent p of the power law F = kδᵖ whose exact
//!    restitution calibration the damping should use (1 for Hooke, 1.5 for Hertz-like laws).
//! 6. Optionally [`NormalLaw::damping_stiffness_per_radius`]: S_n/a if S_n is proportional to a in every
//!    contact (Hertz: 2E*), so that with Mindlin the damping saves a square root per contact.
//!
//! Then use it as `Composed<MyLaw, RestitutionDamping, Mindlin, NoRolling>`. The engine, walls, meshes,
//! history bookkeeping and checkpoints need no change.

mod cohesion;
mod composed;
mod damping;
mod normal;
mod pair;
pub mod restitution_fit;
mod rolling;
mod tangential;

pub use cohesion::{LinearCohesion, LinearCohesionParams};
pub use composed::{Composed, ComposedParams, ComposedState, CoulombLoad};
pub use damping::{
    DampingLaw, NoDamping, RestitutionCalibration, RestitutionDamping, RestitutionDampingParams,
};
pub use normal::{Hertz, HertzParams, Hooke, HookeParams, HookeStiffness, NormalForce, NormalLaw};
pub use pair::{PairProps, PairTable};
pub use rolling::{AnyRolling, ConstantTorque, NoRolling, RollingLaw, ViscousRolling};
pub use tangential::{
    Frictionless, LinearHistory, Mindlin, MindlinHistory, MindlinParams, MindlinVariant, SpringHistory,
    TangentialForce, TangentialLaw,
};

use serde::de::DeserializeOwned;
use serde::Serialize;
use spatter_core::Vec3;
use std::fmt::Debug;

/// Geometry and kinematics of one contact, seen from particle i.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactInput {
    /// Unit normal pointing from the partner to particle i.
    pub normal: Vec3,
    /// Overlap δ \[m\], positive in compression (negative inside an adhesive neck).
    pub overlap: f64,
    /// Effective radius R* \[m\] (R for a flat wall).
    pub r_eff: f64,
    /// Sum of the radii rᵢ + rⱼ \[m\] (rᵢ for a wall), from which range-based laws such as
    /// [`LinearCohesion`] scale their reach.
    pub radius_sum: f64,
    /// Effective mass m* \[kg\] (m for a wall or frozen partner).
    pub m_eff: f64,
    /// Effective moment of inertia 1/(1/Iᵢ + 1/Iⱼ) \[kg m²\], for rolling laws that must not overshoot.
    pub i_eff: f64,
    /// Velocity of particle i's contact point minus the partner's \[m/s\].
    pub v_rel: Vec3,
    /// Angular velocity of particle i minus the partner's \[rad/s\].
    pub w_rel: Vec3,
    /// Time step \[s\].
    pub dt: f64,
}

/// What a contact does to particle i in this step (the partner gets the opposite force and torque).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactOutput {
    /// Total contact force on particle i (normal + tangential) \[N\].
    pub force: Vec3,
    /// Signed normal part of `force` \[N\] (positive repulsive); force = normal_force·n + tangential.
    pub normal_force: f64,
    /// Rolling-resistance torque on particle i \[N m\] (not including the torque of the tangential force).
    pub rolling_torque: Vec3,
    /// Energy dissipated in this contact during this step \[J\] (dashpots, Coulomb slip, rolling, and the
    /// stored-energy change of a tangential spring whose stiffness follows the normal load).
    pub dissipated: f64,
    /// Elastic energy stored in the contact \[J\] (normal and tangential springs).
    pub energy: f64,
}

impl ContactOutput {
    /// Tangential part of the force \[N\].
    pub fn tangential_force(&self, normal: Vec3) -> Vec3 {
        self.force - self.normal_force * normal
    }
}

/// A complete contact law: what the engine calls for every particle–particle and particle–wall contact.
///
/// Usually a [`Composed`] law; implement this trait directly only for laws that do not split into the
/// four parts.
pub trait ContactLaw: Clone + Send + Sync + 'static {
    /// Parameters precomputed once per pair type.
    type Params: Clone + Debug + Send + Sync;
    /// Per-contact persistent state; `Default` means "no contact".
    type State: Copy + Default + PartialEq + Debug + Send + Sync + Serialize + DeserializeOwned;

    /// Whether the law reads [`ContactInput::w_rel`] and [`ContactInput::i_eff`] and exerts a rolling
    /// torque (rolling resistance). When false the engine may leave them zero and skip computing them, and
    /// [`ContactOutput::rolling_torque`] must be zero (the engine then does not add it).
    const USES_ROTATION: bool = true;

    /// Precomputes the parameters of pair type `pair_index` (index into the engine's pair table).
    fn params(&self, pair_index: usize, props: &PairProps) -> Self::Params;

    /// Largest gap −δ ≥ 0 \[m\] at which a contact of effective radius `r_eff` may still act or keep state.
    fn range(&self, p: &Self::Params, r_eff: f64) -> f64;

    /// Force and torque of one contact in this step; updates `state`. Returns `None` when the partners do
    /// not interact (the engine then resets `state` to `Default`).
    fn compute(&self, p: &Self::Params, c: &ContactInput, state: &mut Self::State) -> Option<ContactOutput>;

    /// The same law without energy bookkeeping ([`ContactOutput::energy`] and
    /// [`ContactOutput::dissipated`] may then be zero). Must not change forces or states: the engine uses
    /// it in steps that need no energies. The default keeps the law as it is.
    fn without_energy(&self) -> Self {
        self.clone()
    }
}

/// The standard combination: Hertz normal, restitution damping, Mindlin tangential with history, no
/// rolling resistance (LIGGGHTS `hertz` + `tangential history`, LAMMPS `hertz/material … mindlin`).
pub type HertzMindlin = Composed<Hertz, RestitutionDamping, Mindlin, NoRolling>;

/// [`HertzMindlin`] with constant-torque rolling resistance.
pub type HertzMindlinRolling = Composed<Hertz, RestitutionDamping, Mindlin, ConstantTorque>;

/// Linear spring–dashpot with a linear tangential spring (LIGGGHTS `hooke` + `tangential history`).
pub type HookeLinear = Composed<Hooke, RestitutionDamping, LinearHistory, NoRolling>;

#[cfg(test)]
mod tests;
