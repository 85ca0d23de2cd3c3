//! The composed kernel: normal + damping + tangential + rolling, monomorphised.

use super::{
    ContactInput, ContactLaw, ContactOutput, DampingLaw, NormalLaw, PairProps, RollingLaw, TangentialLaw,
};
use serde::{Deserialize, Serialize};

/// One law of each kind, combined into a [`ContactLaw`]. The laws themselves hold only global options
/// (per-pair numbers live in [`ComposedParams`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Composed<N, D, T, R> {
    pub normal: N,
    pub damping: D,
    pub tangential: T,
    pub rolling: R,
    /// Book stored and dissipated energy per contact (default true). Switching it off saves about 10 %
    /// of the contact time; [`ContactOutput::energy`] and [`ContactOutput::dissipated`] are then zero.
    pub energy: bool,
    /// Which normal force caps Coulomb friction when the normal law leaves the choice open
    /// ([`super::NormalForce::coulomb_force`] = `None`: Hooke, Hertz).
    #[serde(default)]
    pub coulomb_load: CoulombLoad,
}

/// The normal force F_c of the Coulomb cap |F_t| ≤ μ F_c for normal laws that leave the choice open.
///
/// The two conventions differ while the normal dashpot works: on loading the total force exceeds the
/// elastic one, on unloading it is smaller and (with the tensile clamp) reaches zero before the overlap
/// does, so with `Total` a contact always slides at its end and with `Elastic` it may leave sticking.
/// LAMMPS `pair granular` and LIGGGHTS cap with the total force; Chung & Ooi's (2011) test 6 reference
/// curve is reproduced only with the elastic force (docs/dem.md §4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoulombLoad {
    /// The total normal force after damping, clamped at zero (default).
    #[default]
    Total,
    /// The elastic normal force F_ne of the normal law, clamped at zero.
    Elastic,
}

impl<N, D, T, R> Composed<N, D, T, R> {
    pub fn new(normal: N, damping: D, tangential: T, rolling: R) -> Self {
        Composed { normal, damping, tangential, rolling, energy: true, coulomb_load: CoulombLoad::Total }
    }

    /// The same law with Coulomb friction capped by `load`.
    pub fn with_coulomb_load(self, load: CoulombLoad) -> Self {
        Composed { coulomb_load: load, ..self }
    }
}

impl<N: Default, D: Default, T: Default, R: Default> Default for Composed<N, D, T, R> {
    fn default() -> Self {
        Composed::new(N::default(), D::default(), T::default(), R::default())
    }
}

/// Per-pair parameters of a [`Composed`] law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ComposedParams<NP, DP, TP, RP> {
    pub normal: NP,
    pub damping: DP,
    pub tangential: TP,
    pub rolling: RP,
    /// √(k_t/S_n) when the tangential stiffness is a constant multiple of the damping stiffness for this
    /// pair type (Hertz with Mindlin: √(8G*a/(2E*a)) = √(4G*/E*)), else `None`; passed to
    /// [`DampingLaw::coefficients`].
    pub stiffness_ratio_sqrt: Option<f64>,
}

/// Per-contact state of a [`Composed`] law: the states of its parts and nothing else (with Hertz,
/// restitution damping and Mindlin only the tangential history, 32 bytes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ComposedState<NS, DS, TS, RS> {
    pub normal: NS,
    pub damping: DS,
    pub tangential: TS,
    pub rolling: RS,
}

impl<N, D, T, R> ContactLaw for Composed<N, D, T, R>
where
    N: NormalLaw,
    D: DampingLaw,
    T: TangentialLaw,
    R: RollingLaw,
{
    type Params = ComposedParams<N::Params, D::Params, T::Params, R::Params>;
    type State = ComposedState<N::State, D::State, T::State, R::State>;
    const USES_ROTATION: bool = R::USES_ROTATION;

    fn params(&self, pair_index: usize, props: &PairProps) -> Self::Params {
        let normal = self.normal.params(pair_index, props);
        let tangential = self.tangential.params(pair_index, props);
        let ratio =
            self.tangential.stiffness_ratio(&tangential, self.normal.damping_stiffness_per_radius(&normal));
        ComposedParams {
            damping: self.damping.params(pair_index, props, self.normal.damping_exponent()),
            rolling: self.rolling.params(pair_index, props),
            stiffness_ratio_sqrt: ratio.filter(|r| *r >= 0.0 && r.is_finite()).map(f64::sqrt),
            normal,
            tangential,
        }
    }

    fn without_energy(&self) -> Self {
        Composed { energy: false, ..self.clone() }
    }

    #[inline(always)]
    fn range(&self, p: &Self::Params, r_eff: f64) -> f64 {
        self.normal.range(&p.normal, r_eff)
    }

    #[inline(always)]
    fn compute(&self, p: &Self::Params, c: &ContactInput, s: &mut Self::State) -> Option<ContactOutput> {
        // One copy of the kernel per combination of the run-time options: they are tested once per contact
        // instead of at every use (the same arithmetic either way).
        match (self.energy, self.coulomb_load) {
            (true, CoulombLoad::Total) => self.kernel::<true, false>(p, c, s),
            (true, CoulombLoad::Elastic) => self.kernel::<true, true>(p, c, s),
            (false, CoulombLoad::Total) => self.kernel::<false, false>(p, c, s),
            (false, CoulombLoad::Elastic) => self.kernel::<false, true>(p, c, s),
        }
    }
}

impl<N, D, T, R> Composed<N, D, T, R>
where
    N: NormalLaw,
    D: DampingLaw,
    T: TangentialLaw,
    R: RollingLaw,
{
    /// [`ContactLaw::compute`] with the options as constants: `ENERGY` = [`Composed::energy`],
    /// `ELASTIC_LOAD` = ([`Composed::coulomb_load`] is [`CoulombLoad::Elastic`]).
    #[inline(always)]
    fn kernel<const ENERGY: bool, const ELASTIC_LOAD: bool>(
        &self,
        p: &<Self as ContactLaw>::Params,
        c: &ContactInput,
        s: &mut <Self as ContactLaw>::State,
    ) -> Option<ContactOutput> {
        let nf = self.normal.evaluate(&p.normal, c, &mut s.normal)?;
        self.damping.in_contact(&p.damping, c, &mut s.damping);
        let n = c.normal;
        let vn = c.v_rel.dot(n);
        let k_t = self.tangential.stiffness(&p.tangential, &nf, c);
        let (gamma_n, gamma_t) =
            self.damping.coefficients(&p.damping, &s.damping, &nf, k_t, p.stiffness_ratio_sqrt, c);
        let mut f_n = nf.force - gamma_n * vn;
        if self.damping.tensile_clamp(&p.damping) {
            let floor = nf.force.min(0.0);
            if f_n < floor {
                f_n = floor;
            }
        }
        // Work absorbed by the normal dashpot in this step: −F_d·v_n Δt ≥ 0.
        let mut dissipated = if ENERGY { -(f_n - nf.force) * vn * c.dt } else { 0.0 };
        let f_coulomb = nf.coulomb_force.unwrap_or(if ELASTIC_LOAD { nf.force } else { f_n }.max(0.0));
        let v_t = c.v_rel - vn * n;
        let t =
            self.tangential.force(&p.tangential, &mut s.tangential, k_t, gamma_t, f_coulomb, v_t, c, ENERGY);
        let (rolling_torque, roll_diss) = self.rolling.torque(&p.rolling, &mut s.rolling, f_coulomb, c);
        if ENERGY {
            dissipated += t.dissipated + roll_diss * c.dt;
        }
        Some(ContactOutput {
            force: f_n * n + t.force,
            normal_force: f_n,
            rolling_torque,
            dissipated,
            energy: if ENERGY { nf.energy + t.energy } else { 0.0 },
        })
    }
}
