//! Incipient motion of a grain resting on a bed: rocking out of its seat (the moment balance about the
//! downwind asperity) and lifting off (the wall lift against weight and cohesion).
//!
//! **Rocking.**
//! A sand grain of radius r_p rests on two grains of the bed, touching them at the asperities A
//! (downwind) and B (upwind), a distance a apart (Ziskind, Fichman & Gutfinger 1997; Ibrahim, Dunn &
//! Brach 2003; Jasion 2013 §6.4.2). Taking moments about A (Jasion eq. 6.5, written here with consistent
//! dimensions):
//!
//! * the horizontal fluid force F_H (drag) acts 0.74 r_p above the centre (Ibrahim et al.: the shear
//!   flow's torque on the grain), arm 0.74 r_p + √(r_p² − a²/4) above the contact line;
//! * the wall-bounded lift F_L and the weight F_g act at the centre, arm a/2;
//! * cohesion acts at the contacts: the pull-off force F_P at B, arm a.
//!
//! The grain rocks out of its seat when the driving moment F_H (0.74 r_p + √(r_p² − a²/4)) + F_L a/2
//! exceeds the resisting moment a F_P + F_g a/2, i.e. when F_H exceeds
//!
//! F_H,crit = [a F_P + (F_g − F_L) a/2] / (0.74 r_p + √(r_p² − a²/4))      (Jasion eq. 6.6).
//!
//! **Lifting off.** Once free, a grain leaves the bed only if the wall lift exceeds its weight and
//! cohesion, F_L ≥ F_g + F_P (Jasion §6.4.2: "it is still reliant on the lift forces to overcome
//! gravity"; his Fig. 6.8 normalises the lift by F_g + F_P). With F_L ∝ D^q (q = 2.31 for Hall's law,
//! 1.87 for Mollinger's), F_P ∝ D and F_g ∝ D³, the ratio F_L/(F_g + F_P) peaks where
//! D² = (q − 1) F_P D⁻¹/((3 − q) F_g D⁻³) — 265 µm for sand with σ = 2 × 10⁻⁴ J/m² under Hall's law,
//! independent of u_*: small grains are held by cohesion, large ones by their weight, medium grains
//! lift off first, the thesis's conclusion. With the regime choice of Table 3.1 (Mollinger's stronger
//! lift below Re_p* = 5) the smallest lift-off friction velocity moves to about 115 µm; among the
//! thesis's sizes 10, 300 and 500 µm the 300 µm grains still go first.
//!
//! The forces on the resting grain come from the friction velocity u_* of the flow over the bed:
//! * drag F_D = 3π μ D u_c f_d(Re) f_w at the centre speed u_c = u_* u⁺(D u_*/(2ν)) of the law of the
//!   wall ([`super::wall_law`]), with Schiller & Naumann's f_d and the wall factor f_w = 1.7009 of a
//!   sphere touching a wall in shear flow (O'Neill 1968; 1 switches it off);
//! * wall lift F_L = p (a⁺)^q ρ ν² (Table 3.1 of the thesis; regime choice by Re_p* = D u_*/ν, see
//!   [`crate::forces::wall_lift`]);
//! * pull-off F_P = f_p π σ r_p, f_p = 3/2 (JKR) or 2 (DMT), the grain treated as a sphere on a flat
//!   (Jasion eq. 3.54–3.55);
//! * weight F_g = (ρ_p − ρ_f) g π D³/6 (buoyancy optional).
//!
//! Rocking alone favours large grains (drag grows like D² f_d(Re) with the centre speed, faster than the
//! cohesion moment, and the weight moment only catches up beyond ≈ 0.5 mm for the Bell 47 numbers); the
//! thesis notes the same ("larger particles ... will be easier to rock") before concluding from the lift
//! that medium grains are entrained first.

use crate::forces::contact::{pull_off_force, PullOffTheory};
use crate::forces::drag::schiller_naumann_fd;
use crate::forces::wall_lift::{wall_lift_force, WallLiftLaw, ZengAlpha};
use crate::forces::{sphere_mass, Fluid};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use std::f64::consts::PI;

/// O'Neill's (1968) drag factor for a sphere touching a plane wall in linear shear flow.
pub const ONEILL_WALL_FACTOR: f64 = 1.7009;

/// The bed and adhesion model of the moment balance. Scenario table `[liftoff]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RockingSettings {
    /// Work of adhesion σ \[J/m²\] (Jasion Table 6.1: 2 × 10⁻⁴ for glass/sand).
    #[serde(rename = "surface_energy_j_m2", default = "default_sigma")]
    pub surface_energy: f64,
    /// Pull-off theory: `jkr` (F = 1.5πσr, default) or `dmt` (F = 2πσr).
    #[serde(default)]
    pub pull_off: PullOff,
    /// Asperity spacing a/D (0.5: a grain on two touching grains of its size, the π/6 asperity angle
    /// of Jasion eq. 5.3).
    #[serde(default = "default_asperity")]
    pub asperity_ratio: f64,
    /// Height of the horizontal force above the centre / r_p (Ibrahim et al.: 0.74).
    #[serde(default = "default_arm")]
    pub force_arm: f64,
    /// Drag factor of the wall (O'Neill: 1.7009; 1 = free-stream drag).
    #[serde(default = "default_wall_factor")]
    pub wall_drag_factor: f64,
    /// Wall-bounded lift law (default: the regimes of Table 3.1).
    #[serde(default = "default_lift")]
    pub wall_lift: WallLiftLaw,
    /// Whether the wall-bounded lift acts.
    #[serde(default = "yes")]
    pub wall_lift_enabled: bool,
    /// Gravitational acceleration \[m/s²\].
    #[serde(rename = "gravity_m_s2", default = "default_g")]
    pub gravity: f64,
    /// Buoyancy on the weight.
    #[serde(default = "yes")]
    pub buoyancy: bool,
}

/// Pull-off theory (scenario spelling).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PullOff {
    #[default]
    Jkr,
    Dmt,
}

impl From<PullOff> for PullOffTheory {
    fn from(p: PullOff) -> Self {
        match p {
            PullOff::Jkr => PullOffTheory::Jkr,
            PullOff::Dmt => PullOffTheory::Dmt,
        }
    }
}

fn default_sigma() -> f64 {
    2e-4
}
fn default_asperity() -> f64 {
    0.5
}
fn default_arm() -> f64 {
    0.74
}
fn default_wall_factor() -> f64 {
    ONEILL_WALL_FACTOR
}
fn default_lift() -> WallLiftLaw {
    WallLiftLaw::Regimes
}
fn default_g() -> f64 {
    9.81
}
fn yes() -> bool {
    true
}

impl Default for RockingSettings {
    fn default() -> Self {
        RockingSettings {
            surface_energy: default_sigma(),
            pull_off: PullOff::Jkr,
            asperity_ratio: default_asperity(),
            force_arm: default_arm(),
            wall_drag_factor: default_wall_factor(),
            wall_lift: default_lift(),
            wall_lift_enabled: true,
            gravity: default_g(),
            buoyancy: true,
        }
    }
}

impl Validate for RockingSettings {
    fn validate(&self, c: &mut Checker) {
        c.non_negative("surface_energy_j_m2", self.surface_energy);
        c.in_range("asperity_ratio", self.asperity_ratio, 0.0, false, 2.0, false);
        c.non_negative("force_arm", self.force_arm);
        c.positive("wall_drag_factor", self.wall_drag_factor);
        c.positive("gravity_m_s2", self.gravity);
    }
}

/// What a grain does: lift off, rock (roll out of its seat but stay on the ground), or stay held.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum State {
    /// The wall lift exceeds weight and cohesion.
    LiftsOff,
    /// The driving moment exceeds the resisting one (but the lift does not lift the grain).
    Rocks,
    /// Held, and cohesion F_P is larger than the weight.
    HeldByCohesion,
    /// Held, and the weight is larger than cohesion.
    HeldByWeight,
}

/// The forces \[N\] on a resting grain and the outcome of the two balances.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Incipient {
    pub drag: f64,
    pub lift: f64,
    pub pull_off: f64,
    pub weight: f64,
    /// Speed at the grain's centre \[m/s\].
    pub centre_speed: f64,
    /// Critical horizontal force F_H,crit \[N\] (eq. 6.6).
    pub critical_force: f64,
    /// Driving over resisting moment (≥ 1: the grain rocks).
    pub ratio: f64,
    /// F_L/(F_g + F_P) (≥ 1: the grain lifts off).
    pub lift_ratio: f64,
    pub state: State,
}

/// The moment and lift balances for a grain of diameter `d` and density `rho_p` under friction velocity
/// `u_star`.
pub fn incipient(d: f64, rho_p: f64, u_star: f64, fluid: &Fluid, s: &RockingSettings) -> Incipient {
    let nu = fluid.nu();
    let r = 0.5 * d;
    let a = s.asperity_ratio * d;
    let u_c = super::wall_law::speed_at(r, u_star, nu);
    let re = fluid.density * d * u_c / fluid.viscosity;
    let drag = 3.0 * PI * fluid.viscosity * d * u_c * schiller_naumann_fd(re) * s.wall_drag_factor;
    let lift = if s.wall_lift_enabled {
        wall_lift_force(s.wall_lift, Some(ZengAlpha::Zeng), d, r, u_star, fluid.density, nu)
    } else {
        0.0
    };
    let pull_off = pull_off_force(s.pull_off.into(), s.surface_energy, r);
    let buoy = if s.buoyancy { 1.0 - fluid.density / rho_p } else { 1.0 };
    let weight = sphere_mass(d, rho_p) * s.gravity * buoy;
    let arm = s.force_arm * r + (r * r - 0.25 * a * a).max(0.0).sqrt();
    let (cohesion_moment, weight_moment) = (a * pull_off, 0.5 * a * weight);
    let driving = drag * arm + 0.5 * a * lift;
    let resisting = cohesion_moment + weight_moment;
    let ratio = if resisting > 0.0 { driving / resisting } else { f64::INFINITY };
    let held = pull_off + weight;
    let lift_ratio = if held > 0.0 { lift / held } else { f64::INFINITY };
    let state = if lift_ratio >= 1.0 {
        State::LiftsOff
    } else if ratio >= 1.0 {
        State::Rocks
    } else if pull_off >= weight {
        State::HeldByCohesion
    } else {
        State::HeldByWeight
    };
    Incipient {
        drag,
        lift,
        pull_off,
        weight,
        centre_speed: u_c,
        critical_force: (cohesion_moment + weight_moment - 0.5 * a * lift) / arm,
        ratio,
        lift_ratio,
        state,
    }
}

/// The smallest u_* ∈ \[10⁻⁵, 100\] m/s at which `measure` (increasing in u_*) reaches 1, by bisection
/// in log u_*; `None` when it stays below 1.
fn critical_u_star(measure: impl Fn(f64) -> f64) -> Option<f64> {
    let (mut lo, mut hi) = (1e-5, 100.0);
    if measure(lo) >= 1.0 {
        return Some(lo);
    }
    if measure(hi) < 1.0 {
        return None;
    }
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if measure(mid) < 1.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi / lo - 1.0 < 1e-12 {
            break;
        }
    }
    Some(0.5 * (lo + hi))
}

/// The friction velocity \[m/s\] at which a grain of diameter `d` starts to rock (moment ratio 1);
/// `None` above 100 m/s.
pub fn critical_friction_velocity(d: f64, rho_p: f64, fluid: &Fluid, s: &RockingSettings) -> Option<f64> {
    critical_u_star(|u| incipient(d, rho_p, u, fluid, s).ratio)
}

/// The friction velocity \[m/s\] at which the wall lift on a grain of diameter `d` equals its weight and
/// cohesion; `None` above 100 m/s or without wall lift.
pub fn lift_off_friction_velocity(d: f64, rho_p: f64, fluid: &Fluid, s: &RockingSettings) -> Option<f64> {
    critical_u_star(|u| incipient(d, rho_p, u, fluid, s).lift_ratio)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn thesis_air() -> Fluid {
        // Jasion Table 6.1: air 1.19 kg/m³, 1.82e-5 Pa s.
        Fluid { density: 1.19, viscosity: 1.82e-5 }
    }

    #[test]
    fn moment_balance_by_hand() {
        // 300 µm sand, u* = 0.3 m/s, no lift, free drag: every term by hand.
        let s = RockingSettings { wall_lift_enabled: false, wall_drag_factor: 1.0, ..Default::default() };
        let f = thesis_air();
        let (d, rho) = (300e-6, 2480.0);
        let out = incipient(d, rho, 0.3, &f, &s);
        let r = 150e-6;
        let u_c = super::super::wall_law::speed_at(r, 0.3, f.nu());
        let re = 1.19 * d * u_c / 1.82e-5;
        let drag = 3.0 * PI * 1.82e-5 * d * u_c * (1.0 + 0.15 * re.powf(0.687));
        let w = PI / 6.0 * d.powi(3) * (rho - 1.19) * 9.81;
        let fp = 1.5 * PI * 2e-4 * r;
        let a = 0.5 * d;
        let arm = 0.74 * r + (r * r - a * a / 4.0).sqrt();
        assert!((out.drag / drag - 1.0).abs() < 1e-12 && (out.weight / w - 1.0).abs() < 1e-12);
        assert!((out.pull_off / fp - 1.0).abs() < 1e-12);
        assert!((out.ratio - drag * arm / (a * fp + w * a / 2.0)).abs() < 1e-12);
        assert!((out.critical_force - (a * fp + w * a / 2.0) / arm).abs() < 1e-20);
        // At the critical friction velocity the drag equals the critical force.
        let uc = critical_friction_velocity(d, rho, &f, &s).unwrap();
        let at = incipient(d, rho, uc, &f, &s);
        assert!((at.drag / at.critical_force - 1.0).abs() < 1e-9);
    }

    #[test]
    fn medium_grains_lift_off_first() {
        // Jasion (2013) Ch. 6: cohesion holds the small grains, weight the large ones, the medium ones
        // (≈ 300 µm) are entrained first. Table 6.1 properties, σ = 2e-4 J/m², JKR pull-off.
        let (f, s) = (thesis_air(), RockingSettings::default());
        let crit = |d: f64| lift_off_friction_velocity(d, 2480.0, &f, &s).unwrap();
        let (u10, u300, u500) = (crit(10e-6), crit(300e-6), crit(500e-6));
        assert!(u300 < u500 && u300 < u10, "{u10} {u300} {u500}");
        // Under Hall's law alone the lift ratio peaks at D = √(8.543 σ/((ρ_p − ρ_f) g)) = 265.1 µm
        // (module docs), whatever u*: the smallest lift-off u* on a 1 µm grid lies there.
        let hall = RockingSettings { wall_lift: WallLiftLaw::Hall, ..RockingSettings::default() };
        let best = (100..=600)
            .map(|k| k as f64 * 1e-6)
            .map(|d| (lift_off_friction_velocity(d, 2480.0, &f, &hall).unwrap(), d))
            .fold((f64::INFINITY, 0.0), |a, b| if b.0 < a.0 { b } else { a });
        assert!((best.1 - 265.1e-6).abs() <= 1.01e-6, "minimum at {} µm", best.1 * 1e6);
        // Just below their own thresholds: 10 µm held by cohesion, 500 µm by weight.
        assert_eq!(incipient(10e-6, 2480.0, 0.5 * u10, &f, &s).state, State::HeldByCohesion);
        let big = incipient(500e-6, 2480.0, 0.2, &f, &s);
        assert_eq!(big.state, State::HeldByWeight, "{big:?}");
    }
}
