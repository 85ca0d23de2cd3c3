//! Wall-bounded lift on a particle in a turbulent boundary layer.
//!
//! Mollinger & Nieuwstadt (1996) form, Jasion (2013) eq. 3.49 and Table 3.1:
//!
//! F_L⁺ = p (a⁺)^q,   F_L = F_L⁺ ρ_f ν²,   a⁺ = a u_*/ν = ½ Re_p*,   Re_p* = d u_*/ν,
//!
//! with a the particle radius and u_* the friction velocity. The force points away from the wall. For a
//! particle whose centre is not touching the wall, Zeng et al. (2009) give the distance factor
//!
//! C_L/C_L,w = exp(−0.5 δ (Re/250)^(4/3)) [exp(α δ^β) − λ],   δ = y/d − 0.5,
//! α = −exp(−0.3 + 0.025 Re),  β = 0.8 + 0.01 Re,  λ = (1 − e^(−δ)) (Re/250)^(5/2),
//!
//! applied for y ≤ 4 d (y = centre-to-wall distance) and zero beyond. Jasion prints α with 0.05·2a⁺
//! = 0.05 Re (β and λ converted back give Zeng's 0.01 Re and (Re/250)^(5/2)); we follow Zeng's
//! 0.025 Re and offer the printed form as [`ZengAlpha::AsPrinted`].

use super::{sphere_mass, Fluid};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};

/// One row of Jasion Table 3.1: F⁺ = p (a⁺)^q.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WallLiftLaw {
    /// Saffman: p = 6.46, q = 3 (Re_p* ≪ 1).
    Saffman,
    /// Leighton & Acrivos (1985): p = 9.22, q = 4 (Re_p* ≪ 1).
    LeightonAcrivos,
    /// Hall (1988): p = 20.9, q = 2.31 (Re_p* > 6).
    Hall,
    /// Mollinger & Nieuwstadt (1996): p = 56.9, q = 1.87 (0.6 < Re_p* < 4).
    Mollinger,
    /// The regime choice of Jasion L1184–1186: Leighton–Acrivos below Re_p* = 0.6, Mollinger from 0.6
    /// up to [`REGIME_SWITCH_MOLLINGER_HALL`], Hall above. Table 3.1 leaves 4 < Re_p* < 6 open; we switch
    /// in the middle of the gap. The law is discontinuous at both switches (the fits disagree there).
    Regimes,
}

/// Re_p* at which [`WallLiftLaw::Regimes`] changes from Mollinger to Hall (the middle of Table 3.1's
/// 4–6 gap).
pub const REGIME_SWITCH_MOLLINGER_HALL: f64 = 5.0;

/// Re_p* below which [`WallLiftLaw::Regimes`] uses Leighton & Acrivos (Jasion L1184).
pub const REGIME_SWITCH_LA_MOLLINGER: f64 = 0.6;

impl WallLiftLaw {
    /// The (p, q) pair of a single law; for [`WallLiftLaw::Regimes`] the pair in force at `re_star`.
    pub fn coefficients(&self, re_star: f64) -> (f64, f64) {
        match self {
            WallLiftLaw::Saffman => (6.46, 3.0),
            WallLiftLaw::LeightonAcrivos => (9.22, 4.0),
            WallLiftLaw::Hall => (20.9, 2.31),
            WallLiftLaw::Mollinger => (56.9, 1.87),
            WallLiftLaw::Regimes => {
                if re_star < REGIME_SWITCH_LA_MOLLINGER {
                    WallLiftLaw::LeightonAcrivos.coefficients(re_star)
                } else if re_star < REGIME_SWITCH_MOLLINGER_HALL {
                    WallLiftLaw::Mollinger.coefficients(re_star)
                } else {
                    WallLiftLaw::Hall.coefficients(re_star)
                }
            }
        }
    }

    /// Nondimensional lift F⁺ = p (a⁺)^q.
    pub fn f_plus(&self, a_plus: f64) -> f64 {
        let (p, q) = self.coefficients(2.0 * a_plus);
        p * a_plus.powf(q)
    }
}

/// Which α Zeng's factor uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ZengAlpha {
    /// α = −exp(−0.3 + 0.025 Re) (Zeng, Najjar, Balachandar & Fischer 2009, Phys. Fluids 21:033302).
    #[default]
    Zeng,
    /// α = −exp(−0.3 + 0.05 · 2a⁺) as printed by Jasion (2013) eq. 3.50.
    AsPrinted,
}

/// Zeng's wall-distance factor C_L/C_L,w for a particle whose centre is `y` above the wall, diameter
/// `d`, at shear Reynolds number `re` = Re_p*. Equals 1 at contact (y = d/2); zero for y > 4d.
pub fn zeng_factor(y: f64, d: f64, re: f64, alpha_form: ZengAlpha) -> f64 {
    if y > WALL_LIFT_RANGE_DIAMETERS * d {
        return 0.0;
    }
    let delta = (y / d - 0.5).max(0.0);
    let alpha = match alpha_form {
        ZengAlpha::Zeng => -(-0.3 + 0.025 * re).exp(),
        ZengAlpha::AsPrinted => -(-0.3 + 0.05 * re).exp(),
    };
    let beta = 0.8 + 0.01 * re;
    let lambda = (1.0 - (-delta).exp()) * (re / 250.0).powf(2.5);
    (-0.5 * delta * (re / 250.0).powf(4.0 / 3.0)).exp() * ((alpha * delta.powf(beta)).exp() - lambda)
}

/// Wall-bounded lift force \[N\] on a particle of diameter `d` whose centre is `y` above the wall, in a
/// boundary layer of friction velocity `u_star` \[m/s\], fluid density `rho_f` and kinematic viscosity
/// `nu`. Positive = away from the wall.
pub fn wall_lift_force(
    law: WallLiftLaw,
    zeng: Option<ZengAlpha>,
    d: f64,
    y: f64,
    u_star: f64,
    rho_f: f64,
    nu: f64,
) -> f64 {
    let a_plus = 0.5 * d * u_star / nu;
    let f = law.f_plus(a_plus) * rho_f * nu * nu;
    match zeng {
        Some(form) => f * zeng_factor(y, d, 2.0 * a_plus, form),
        None => f,
    }
}

/// Ratio of wall distance to diameter beyond which [`zeng_factor`] (and therefore the tracker's wall lift)
/// is zero: Zeng et al.'s fit covers centre distances y ≤ 4d.
pub const WALL_LIFT_RANGE_DIAMETERS: f64 = 4.0;

/// The wall-bounded lift as a switchable term of the tracker (scenario key `[forces] wall_lift`).
///
/// Each step a parcel within [`WALL_LIFT_RANGE_DIAMETERS`] diameters of a body surface (centre to the
/// closest surface point, distance y) gets the acceleration [`wall_lift_acceleration`] along the unit
/// vector from that surface point to its centre (away from the wall). The friction velocity is
/// `friction_velocity_m_s` when given, else u_* = √(τ_w/ρ_f) from the wall-shear estimate of the closest
/// triangle (`tracker::walls::Body::estimate_wall_shear`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallLiftSettings {
    /// Which row(s) of Table 3.1 (default: the regime choice, [`WallLiftLaw::Regimes`]).
    #[serde(default = "default_law")]
    pub law: WallLiftLaw,
    /// The α of Zeng's distance factor (default: Zeng et al. 2009).
    #[serde(default)]
    pub zeng_alpha: ZengAlpha,
    /// A fixed friction velocity u_* \[m/s\] for every wall; absent = from the wall-shear estimate.
    #[serde(rename = "friction_velocity_m_s", default, skip_serializing_if = "Option::is_none")]
    pub friction_velocity: Option<f64>,
}

fn default_law() -> WallLiftLaw {
    WallLiftLaw::Regimes
}

impl Default for WallLiftSettings {
    fn default() -> Self {
        WallLiftSettings { law: default_law(), zeng_alpha: ZengAlpha::Zeng, friction_velocity: None }
    }
}

impl Validate for WallLiftSettings {
    fn validate(&self, c: &mut Checker) {
        if let Some(u) = self.friction_velocity {
            c.positive("friction_velocity_m_s", u);
        }
    }
}

/// Wall-bounded lift per unit particle mass \[m/s²\] on a sphere of diameter `d` and density `rho_p`
/// whose centre is `y` from the wall, with friction velocity `u_star`: [`wall_lift_force`] with Zeng's
/// factor divided by the particle mass. Positive = away from the wall; zero beyond y = 4d.
#[inline]
pub fn wall_lift_acceleration(
    s: &WallLiftSettings,
    fluid: &Fluid,
    d: f64,
    rho_p: f64,
    y: f64,
    u_star: f64,
) -> f64 {
    if y > WALL_LIFT_RANGE_DIAMETERS * d || u_star <= 0.0 {
        return 0.0;
    }
    wall_lift_force(s.law, Some(s.zeng_alpha), d, y, u_star, fluid.density, fluid.nu())
        / sphere_mass(d, rho_p)
}

/// Friction velocity u_* = √(τ_w/ρ_f) \[m/s\] (Jasion eq. 3.21).
pub fn friction_velocity(tau_w: f64, rho_f: f64) -> f64 {
    (tau_w.abs() / rho_f).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_3_1_at_unit_a_plus_is_p() {
        // Jasion (2013) Table 3.1: at a⁺ = 1 every law gives F⁺ = p.
        for (law, p) in [
            (WallLiftLaw::Saffman, 6.46),
            (WallLiftLaw::LeightonAcrivos, 9.22),
            (WallLiftLaw::Hall, 20.9),
            (WallLiftLaw::Mollinger, 56.9),
        ] {
            assert_eq!(law.f_plus(1.0), p);
        }
        // Regime selection by Re_p* = 2a⁺.
        assert_eq!(WallLiftLaw::Regimes.coefficients(0.3), (9.22, 4.0));
        assert_eq!(WallLiftLaw::Regimes.coefficients(2.0), (56.9, 1.87));
        assert_eq!(WallLiftLaw::Regimes.coefficients(10.0), (20.9, 2.31));
        // Power law: doubling a⁺ multiplies Hall's F⁺ by 2^2.31.
        assert!(
            (WallLiftLaw::Hall.f_plus(8.0) / WallLiftLaw::Hall.f_plus(4.0) - 2f64.powf(2.31)).abs() < 1e-12
        );
    }

    #[test]
    fn zeng_factor_is_one_at_contact_and_decays() {
        for re in [1.0, 10.0, 100.0] {
            assert!((zeng_factor(0.5, 1.0, re, ZengAlpha::Zeng) - 1.0).abs() < 1e-15);
            let near = zeng_factor(0.75, 1.0, re, ZengAlpha::Zeng);
            let far = zeng_factor(2.0, 1.0, re, ZengAlpha::Zeng);
            assert!(near < 1.0 && far < near, "Re {re}: {near} {far}");
        }
        assert_eq!(zeng_factor(4.01, 1.0, 10.0, ZengAlpha::Zeng), 0.0);
        // Hand value at δ = 1, Re = 10: exp(−0.5·0.04^(4/3))·[exp(−exp(−0.05)) − (1 − e⁻¹)·0.04^2.5].
        let expect = (-0.5 * 0.04f64.powf(4.0 / 3.0)).exp()
            * ((-(-0.05f64).exp()).exp() - (1.0 - (-1.0f64).exp()) * 0.04f64.powf(2.5));
        assert!((zeng_factor(1.5, 1.0, 10.0, ZengAlpha::Zeng) - expect).abs() < 1e-15);
        // The printed α decays faster.
        assert!(
            zeng_factor(1.5, 1.0, 10.0, ZengAlpha::AsPrinted) < zeng_factor(1.5, 1.0, 10.0, ZengAlpha::Zeng)
        );
    }

    #[test]
    fn dimensional_force() {
        // F = p (a⁺)^q ρ ν²: 300 µm grain, u_* = 0.5 m/s in air → a⁺ = 0.5·300e-6·0.5/1.53e-5.
        let (rho, nu) = (1.19, 1.53e-5);
        let a_plus = 0.5 * 300e-6 * 0.5 / nu;
        let f = wall_lift_force(WallLiftLaw::Hall, None, 300e-6, 150e-6, 0.5, rho, nu);
        assert!((f - 20.9 * a_plus.powf(2.31) * rho * nu * nu).abs() < 1e-18);
        let fz = wall_lift_force(WallLiftLaw::Hall, Some(ZengAlpha::Zeng), 300e-6, 150e-6, 0.5, rho, nu);
        assert!((fz - f).abs() < 1e-15 * f, "contact: factor 1");
    }
}
