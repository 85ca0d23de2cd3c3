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
}

impl<N, D, T, R> Composed<N, D, T, R> {
    pub fn new(normal: N, damping: D, tangential: T, rolling: R) -> Self {
        Composed { normal, damping, tangential, rolling, energy: true }
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
        let mut dissipated = if self.energy { -(f_n - nf.force) * vn * c.dt } else { 0.0 };
        let f_coulomb = nf.coulomb_force.unwrap_or(f_n.max(0.0));
        let v_t = c.v_rel - vn * n;
        let t = self.tangential.force(
            &p.tangential,
            &mut s.tangential,
            k_t,
            gamma_t,
            f_coulomb,
            v_t,
            c,
            self.energy,
        );
        let (rolling_torque, roll_diss) = self.rolling.torque(&p.rolling, &mut s.rolling, f_coulomb, c);
        if self.energy {
            dissipated += t.dissipated + roll_diss * c.dt;
        }
        Some(ContactOutput {
            force: f_n * n + t.force,
            normal_force: f_n,
            rolling_torque,
            dissipated,
            energy: if self.energy { nf.energy + t.energy } else { 0.0 },
        })
    }
}
