//! The adhesive laws as normal laws of the composable contact kernel ([`crate::contact::NormalLaw`]).
//!
//! * [`JkrLaw`] — full hysteretic JKR ([`super::jkr`]); acts down to the break overlap, so its
//!   [`NormalLaw::range`] is δ_c (or 0.48 δ_c under load control);
//! * [`DmtLaw`] — Hertz minus 2πΓR* while touching ([`super::dmt`]);
//! * [`SjkrLaw`] — Hertz minus (3/2)πΓR* while touching ([`super::sjkr`]).
//!
//! Every law reads Γ from [`PairProps::work_of_adhesion`] and E* from [`PairProps::e_star`]; R* comes with
//! each contact, so polydisperse systems need no per-radius tables.
//!
//! # Choices the snow thesis leaves open (documented in `docs/snow.md`)
//!
//! * **Damping stiffness** ([`JkrDamping`]): S_n = 2E*√(R*·max(δ, 0)), the Hertz stiffness of the overlap
//!   with no damping inside the neck (default; what both public LIGGGHTS JKR implementations do), or
//!   S_n = 2E*a with the JKR contact radius a, which also damps the neck.
//! * **Coulomb normal force** ([`AdhesiveCoulomb`]): the friction cap μ·F uses F = F_ne + 2F_po, the
//!   load that the adhesive contact can carry in sliding (default; Thornton & Yin 1991, Marshall 2009
//!   Eq. 25), or the Hertz force of the overlap (LIGGGHTS-PFM JKR), or the total normal force after
//!   damping clamped at zero (the kernel's non-adhesive default).

use super::jkr::{BreakCriterion, Jkr, JkrState};
use super::pull_off::{ConstantPullOff, PullOff};
use crate::contact::{ContactInput, NormalForce, NormalLaw, PairProps};
use serde::{Deserialize, Serialize};

/// Which stiffness sets the normal dashpot of an adhesive contact, γ_n = c·√(m* S_n).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JkrDamping {
    /// S_n = 2E*√(R*·max(δ, 0)): the Hertz stiffness of the overlap, zero in the neck (δ < 0). LIGGGHTS
    /// JKR convention (default).
    #[default]
    Overlap,
    /// S_n = 2E*a with the adhesive contact radius a: the dashpot also acts in the neck.
    ContactRadius,
}

/// Which normal force caps Coulomb friction in an adhesive contact.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AdhesiveCoulomb {
    /// F_ne + 2F_po (≥ 0 along the JKR curve): Thornton & Yin (1991), Marshall (2009). Default.
    #[default]
    PlusTwicePullOff,
    /// The Hertz force (4/3)E*√R* max(δ, 0)^{3/2} of the overlap (LIGGGHTS-PFM JKR).
    Hertz,
    /// The total normal force after damping, clamped at zero (zero whenever the contact pulls).
    Total,
}

impl AdhesiveCoulomb {
    #[inline]
    fn force(self, f_elastic: f64, pull_off: f64, e_star: f64, c: &ContactInput) -> Option<f64> {
        match self {
            AdhesiveCoulomb::PlusTwicePullOff => Some((f_elastic + 2.0 * pull_off).max(0.0)),
            AdhesiveCoulomb::Hertz => {
                let d = c.overlap.max(0.0);
                Some(4.0 / 3.0 * e_star * (c.r_eff * d).sqrt() * d)
            }
            AdhesiveCoulomb::Total => None,
        }
    }
}

/// Per-pair parameters of the adhesive laws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdhesionParams {
    /// E* \[Pa\].
    pub e_star: f64,
    /// Γ \[J/m²\].
    pub work_of_adhesion: f64,
}

fn adhesion_params(props: &PairProps) -> AdhesionParams {
    AdhesionParams { e_star: props.e_star, work_of_adhesion: props.work_of_adhesion }
}

/// Overlap-based damping stiffness 2E*√(R* max(δ,0)) \[N/m\].
#[inline]
fn overlap_stiffness(e_star: f64, c: &ContactInput) -> f64 {
    2.0 * e_star * (c.r_eff * c.overlap.max(0.0)).sqrt()
}

/// Per-contact state of [`JkrLaw`]: the hysteresis state and the zero-load contact radius a₀ of this
/// contact, computed once when the contact forms. R* is fixed for a contact between two given spheres (or
/// a sphere and a wall), so the JKR scales need no cube root per force evaluation: F_c and δ_c follow from
/// a₀ with a few multiplications ([`Jkr::with_a0`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JkrContact {
    /// Formed flag and Newton warm start.
    pub hysteresis: JkrState,
    /// a₀ \[m\] of this contact (0 until formed).
    pub a0: f64,
}

/// Full hysteretic JKR normal law. With Γ = 0 in a pair it reduces to Hertz.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JkrLaw {
    /// Where the neck breaks (default −δ_c).
    pub break_criterion: BreakCriterion,
    /// Damping stiffness convention (default overlap, no neck damping).
    pub damping: JkrDamping,
    /// Coulomb normal force (default F_ne + 2F_c).
    pub coulomb: AdhesiveCoulomb,
}

impl NormalLaw for JkrLaw {
    type Params = AdhesionParams;
    type State = JkrContact;

    fn params(&self, _pair_index: usize, props: &PairProps) -> AdhesionParams {
        adhesion_params(props)
    }

    fn range(&self, p: &AdhesionParams, r_eff: f64) -> f64 {
        if p.work_of_adhesion > 0.0 {
            -Jkr::new(p.e_star, r_eff, p.work_of_adhesion).break_overlap(self.break_criterion)
        } else {
            0.0
        }
    }

    #[inline]
    fn evaluate(&self, p: &AdhesionParams, c: &ContactInput, state: &mut JkrContact) -> Option<NormalForce> {
        if p.work_of_adhesion <= 0.0 {
            // Hertz limit (Γ → 0: a₀, δ_c → 0).
            let d = c.overlap;
            if d <= 0.0 {
                return None;
            }
            let a = (c.r_eff * d).sqrt();
            let force = 4.0 / 3.0 * p.e_star * a * d;
            return Some(NormalForce {
                force,
                damping_stiffness: 2.0 * p.e_star * a,
                contact_radius: a,
                coulomb_force: None,
                energy: 0.4 * force * d,
            });
        }
        if !state.hysteresis.formed && c.overlap < 0.0 {
            return None;
        }
        let jkr = if state.a0 > 0.0 {
            Jkr::with_a0(p.e_star, c.r_eff, p.work_of_adhesion, state.a0)
        } else {
            let j = Jkr::new(p.e_star, c.r_eff, p.work_of_adhesion);
            state.a0 = j.a0;
            j
        };
        let Some(ev) = jkr.evaluate(c.overlap, self.break_criterion, &mut state.hysteresis) else {
            *state = JkrContact::default();
            return None;
        };
        let damping_stiffness = match self.damping {
            JkrDamping::Overlap => overlap_stiffness(p.e_star, c),
            JkrDamping::ContactRadius => 2.0 * p.e_star * ev.contact_radius,
        };
        Some(NormalForce {
            force: ev.force,
            damping_stiffness,
            contact_radius: ev.contact_radius,
            coulomb_force: self.coulomb.force(ev.force, jkr.pull_off_force, p.e_star, c),
            energy: ev.energy,
        })
    }

    fn damping_exponent(&self) -> f64 {
        1.5
    }
}

/// DMT normal law: Hertz minus 2πΓR* while the surfaces touch ([`PullOff::Dmt`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct DmtLaw {
    /// Coulomb normal force (default F_ne + 2·2πΓR*).
    pub coulomb: AdhesiveCoulomb,
}

/// Simplified JKR normal law: Hertz minus (3/2)πΓR* while the surfaces touch ([`PullOff::SimplifiedJkr`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SjkrLaw {
    /// Coulomb normal force (default F_ne + 2F_c).
    pub coulomb: AdhesiveCoulomb,
}

/// The force of a [`ConstantPullOff`] law of kind `kind` for one contact.
#[inline]
fn pull_off_force(
    kind: PullOff,
    coulomb: AdhesiveCoulomb,
    p: &AdhesionParams,
    c: &ContactInput,
) -> Option<NormalForce> {
    let law = ConstantPullOff::new(kind, p.e_star, c.r_eff, p.work_of_adhesion);
    let force = law.force(c.overlap)?;
    Some(NormalForce {
        force,
        damping_stiffness: overlap_stiffness(p.e_star, c),
        contact_radius: (c.r_eff * c.overlap).sqrt(),
        coulomb_force: coulomb.force(force, law.pull_off_force, p.e_star, c),
        energy: law.energy(c.overlap).unwrap_or(0.0),
    })
}

/// [`NormalLaw`] for a constant-pull-off law struct with a `coulomb` field.
macro_rules! constant_pull_off_law {
    ($law:ty, $kind:expr) => {
        impl NormalLaw for $law {
            type Params = AdhesionParams;
            type State = ();

            fn params(&self, _pair_index: usize, props: &PairProps) -> AdhesionParams {
                adhesion_params(props)
            }

            #[inline]
            fn evaluate(&self, p: &AdhesionParams, c: &ContactInput, _s: &mut ()) -> Option<NormalForce> {
                pull_off_force($kind, self.coulomb, p, c)
            }

            fn damping_exponent(&self) -> f64 {
                1.5
            }
        }
    };
}

constant_pull_off_law!(DmtLaw, PullOff::Dmt);
constant_pull_off_law!(SjkrLaw, PullOff::SimplifiedJkr);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{Composed, ContactLaw, Mindlin, NoDamping, NoRolling};
    use spatter_core::material::Material;
    use spatter_core::Vec3;

    fn ice_abs_props(gamma: f64) -> PairProps {
        let ice = Material::new(9.8e9, 0.31, 920.0).unwrap();
        let abs = Material::new(2.0e9, 0.35, 1100.0).unwrap();
        let mut p = PairProps::new(&ice, &abs, 0.0, 1.0);
        p.work_of_adhesion = gamma;
        p
    }

    fn input(overlap: f64, r: f64) -> ContactInput {
        ContactInput {
            normal: Vec3::Z,
            overlap,
            r_eff: r,
            radius_sum: r,
            m_eff: 1e-12,
            i_eff: 1e-24,
            v_rel: Vec3::ZERO,
            w_rel: Vec3::ZERO,
            dt: 1e-9,
        }
    }

    #[test]
    fn jkr_law_follows_the_mechanics_through_the_kernel() {
        // The composed kernel with the JKR normal law reproduces F(0) = −8/9 F_c on first touch, keeps the
        // neck at negative overlap and breaks below −δ_c (JKR theory).
        let props = ice_abs_props(0.2);
        let law = Composed::new(JkrLaw::default(), NoDamping, Mindlin, NoRolling);
        let p = law.params(0, &props);
        let r = 5e-6;
        let jkr = Jkr::new(props.e_star, r, 0.2);
        assert!((law.range(&p, r) - jkr.critical_overlap).abs() < 1e-20);
        let mut s = Default::default();
        assert!(law.compute(&p, &input(-1e-10, r), &mut s).is_none());
        let out = law.compute(&p, &input(0.0, r), &mut s).unwrap();
        assert!((out.normal_force / jkr.pull_off_force + 8.0 / 9.0).abs() < 1e-10);
        let neck = law.compute(&p, &input(-0.9 * jkr.critical_overlap, r), &mut s).unwrap();
        assert!(neck.normal_force < 0.0);
        assert!(law.compute(&p, &input(-1.01 * jkr.critical_overlap, r), &mut s).is_none());
    }

    #[test]
    fn damping_stiffness_and_coulomb_choices() {
        let props = ice_abs_props(0.2);
        let r = 5e-6;
        let jkr = Jkr::new(props.e_star, r, 0.2);
        let c_neck = input(-0.5 * jkr.critical_overlap, r);
        let mut s = JkrContact { hysteresis: JkrState { formed: true, y: 0.0 }, a0: 0.0 };
        let law = JkrLaw::default();
        let p = law.params(0, &props);
        let nf = law.evaluate(&p, &c_neck, &mut s).unwrap();
        assert_eq!(nf.damping_stiffness, 0.0, "no damping in the neck by default");
        let f_expected = nf.force + 2.0 * jkr.pull_off_force;
        assert!((nf.coulomb_force.unwrap() - f_expected).abs() < 1e-15);
        let law = JkrLaw {
            damping: JkrDamping::ContactRadius,
            coulomb: AdhesiveCoulomb::Hertz,
            ..Default::default()
        };
        let nf = law.evaluate(&p, &c_neck, &mut s).unwrap();
        assert!((nf.damping_stiffness - 2.0 * props.e_star * nf.contact_radius).abs() < 1e-6);
        assert_eq!(nf.coulomb_force, Some(0.0));
        // DMT and simplified JKR: constant attraction at first touch, nothing below δ = 0.
        let dmt = DmtLaw::default();
        let mut u = ();
        let f = dmt.evaluate(&p, &input(0.0, r), &mut u).unwrap().force;
        assert!((f + 2.0 * std::f64::consts::PI * 0.2 * r).abs() < 1e-18);
        assert!(dmt.evaluate(&p, &input(-1e-12, r), &mut u).is_none());
        let sjkr = SjkrLaw::default();
        let f = sjkr.evaluate(&p, &input(0.0, r), &mut u).unwrap().force;
        assert!((f + jkr.pull_off_force).abs() < 1e-18);
    }

    #[test]
    fn zero_work_of_adhesion_is_hertz() {
        let props = ice_abs_props(0.0);
        let law = JkrLaw::default();
        let p = law.params(0, &props);
        assert_eq!(law.range(&p, 5e-6), 0.0);
        let d: f64 = 1e-8;
        let nf = law.evaluate(&p, &input(d, 5e-6), &mut JkrContact::default()).unwrap();
        let hertz = 4.0 / 3.0 * props.e_star * (5e-6f64).sqrt() * d.powf(1.5);
        assert!((nf.force - hertz).abs() < 1e-12 * hertz);
    }

    #[test]
    fn cached_scales_give_the_same_forces_bit_for_bit() {
        // JkrContact keeps a₀ from the first evaluation; every later force must equal the one from JKR
        // scales recomputed at each call (Jkr::new + Jkr::evaluate), exactly, through loading, the neck and
        // the break (the JKR curve's points are covered by the mechanics tests).
        let props = ice_abs_props(0.2);
        let law = JkrLaw::default();
        let p = law.params(0, &props);
        let r = 5e-6;
        let jkr = Jkr::new(props.e_star, r, 0.2);
        let (mut cached, mut fresh) = (JkrContact::default(), JkrState::default());
        let mut broke = false;
        for k in 0..400 {
            let x = k as f64 / 100.0;
            let delta = jkr.critical_overlap * (3.0 - (x - 2.0).abs() * 2.1);
            let a = law.evaluate(&p, &input(delta, r), &mut cached);
            let b = Jkr::new(props.e_star, r, 0.2).evaluate(delta, law.break_criterion, &mut fresh);
            assert_eq!(a.map(|n| n.force), b.map(|e| e.force), "step {k}, δ = {delta}");
            assert_eq!(a.map(|n| n.energy), b.map(|e| e.energy));
            match a {
                Some(_) => assert_eq!(cached.a0, jkr.a0),
                None => {
                    assert_eq!(cached, JkrContact::default(), "no state without contact");
                    broke |= k > 200;
                }
            }
        }
        assert!(broke, "the path reaches below −δ_c");
    }
}
