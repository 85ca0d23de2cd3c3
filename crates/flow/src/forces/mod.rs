//! The particle–fluid force library.
//!
//! Every force is returned **per unit particle mass** (an acceleration, m/s²) and every torque per unit
//! moment of inertia (an angular acceleration, rad/s²), the convention of Jasion (2013), eq. 3.4–3.8.
//! The relative velocity is written `w = u_f − v_p` (fluid minus
//! particle) throughout, so that drag is `+w/τ`.
//!
//! * [`drag`] — Stokes, Schiller–Naumann, Di Felice (with and without the voidage factor) and
//!   Haider–Levenspiel (non-spherical) drag laws, terminal velocity;
//! * [`lift`] — Saffman shear lift with Mei's correction, Magnus lift (Oesterle & Bui-Dinh) and the
//!   rotational (Magnus) torque (Rubinow–Keller / Dennis);
//! * [`wall_lift`] — wall-bounded lift F⁺ = p (a⁺)^q (Table 3.1 regimes) with Zeng's wall-distance factor;
//! * [`history`] — the Basset history force: a window integrated exactly (singular kernel included)
//!   and an exponential tail for older history, Odar–Hamilton and Reeks–McKee corrections;
//! * [`inertial`] — added mass, pressure gradient (fluid acceleration), gravity and buoyancy;
//! * [`model`] — a switchable set of all of them as used by the tracker;
//! * [`ranking`] — nondimensional reference magnitudes (Jasion Table 6.4) and the asperity constants;
//! * [`contact`] — pull-off forces (JKR, DMT) and their inverse, damping ratio from restitution.

pub mod contact;
pub mod drag;
pub mod history;
pub mod inertial;
pub mod lift;
pub mod model;
pub mod ranking;
pub mod wall_lift;

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};

/// Properties of the carrier fluid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    /// Density ρ_f \[kg/m³\].
    #[serde(rename = "density_kg_m3", default = "default_air_density")]
    pub density: f64,
    /// Dynamic viscosity μ \[Pa s\].
    #[serde(rename = "viscosity_pa_s", default = "default_air_viscosity")]
    pub viscosity: f64,
}

fn default_air_density() -> f64 {
    1.225
}
fn default_air_viscosity() -> f64 {
    1.81e-5
}

impl Default for Fluid {
    /// Air at 15 °C, 1 atm.
    fn default() -> Self {
        Fluid { density: default_air_density(), viscosity: default_air_viscosity() }
    }
}

impl Fluid {
    /// Kinematic viscosity ν = μ/ρ \[m²/s\].
    pub fn nu(&self) -> f64 {
        self.viscosity / self.density
    }
}

impl Validate for Fluid {
    fn validate(&self, c: &mut Checker) {
        c.positive("density_kg_m3", self.density);
        c.positive("viscosity_pa_s", self.viscosity);
    }
}

/// Particle Reynolds number Re_p = ρ_f d |w| / μ (Jasion eq. 3.28).
#[inline]
pub fn reynolds(fluid: &Fluid, d: f64, slip: f64) -> f64 {
    fluid.density * d * slip / fluid.viscosity
}

/// Stokes relaxation time τ_p = ρ_p d² / (18 μ) \[s\] (Jasion eq. 3.30).
#[inline]
pub fn stokes_time(fluid: &Fluid, d: f64, rho_p: f64) -> f64 {
    rho_p * d * d / (18.0 * fluid.viscosity)
}

/// Mass of a sphere of diameter `d` and density `rho` \[kg\].
#[inline]
pub fn sphere_mass(d: f64, rho: f64) -> f64 {
    std::f64::consts::PI / 6.0 * rho * d * d * d
}
