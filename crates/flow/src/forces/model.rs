//! A switchable set of particle–fluid forces, evaluated once per particle and step.
//!
//! The tracker integrates
//!
//! M dv/dt = (u − v)/τ + a,        M = 1 + C_A ρ_f/ρ_p (+ the implicit Basset inertia),
//!
//! where the drag relaxation time τ = τ_p/f(Re) comes from the drag law at the current slip and `a`
//! collects every other force per unit mass (explicit over the step). [`ForceModel::evaluate`] returns
//! (τ, a, M) and the fluid angular acceleration of the particle's spin.

use super::wall_lift::WallLiftSettings;
use super::{drag::DragLaw, history::BassetSettings, inertial, lift, lift::TorqueLaw, Fluid};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::{Mat3, Vec3};

/// Which forces act. Scenario key: `[forces]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceSwitches {
    /// Drag law (`{ law = "schiller_naumann" }` by default); `drag_enabled = false` switches drag off.
    #[serde(default)]
    pub drag: DragLaw,
    #[serde(default = "yes")]
    pub drag_enabled: bool,
    /// Gravitational acceleration \[m/s²\]; `[0, 0, 0]` switches gravity off.
    #[serde(rename = "gravity_m_s2", default = "default_gravity")]
    pub gravity: Vec3,
    /// Buoyancy (1 − ρ_f/ρ_p) on gravity.
    #[serde(default = "yes")]
    pub buoyancy: bool,
    /// Saffman shear lift with Mei's correction (needs the velocity gradient).
    #[serde(default)]
    pub saffman_mei: bool,
    /// Magnus lift from the particle spin relative to the fluid rotation (Oesterle–Bui-Dinh).
    #[serde(default)]
    pub magnus: bool,
    /// Fluid torque on the particle spin; `None` = spin is not integrated (stays at its initial value).
    #[serde(default)]
    pub rotational_torque: Option<TorqueLaw>,
    /// Added-mass coefficient C_A (0.5 for a sphere); 0 switches the force off.
    #[serde(default)]
    pub added_mass_coefficient: f64,
    /// Pressure-gradient (fluid-acceleration) force (ρ_f/ρ_p) Du/Dt.
    #[serde(default)]
    pub pressure_gradient: bool,
    /// Basset history force; absent = off. Memory per parcel: (window + 1) + 12 vectors, window =
    /// ⌈window_tau_p · τ_p/Δt⌉ steps up to `max_window_steps` (see [`BassetSettings`]).
    #[serde(default)]
    pub basset: Option<BassetSettings>,
    /// Wall-bounded lift (Table 3.1 with Zeng's distance factor) near the tracker's bodies; absent = off.
    /// Evaluated by the tracker, which knows the wall distance, not by [`ForceModel::evaluate`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_lift: Option<WallLiftSettings>,
}

fn yes() -> bool {
    true
}
fn default_gravity() -> Vec3 {
    Vec3::new(0.0, 0.0, -9.81)
}

impl Default for ForceSwitches {
    /// Schiller–Naumann drag, gravity −9.81 ẑ with buoyancy; everything else off.
    fn default() -> Self {
        ForceSwitches {
            drag: DragLaw::default(),
            drag_enabled: true,
            gravity: default_gravity(),
            buoyancy: true,
            saffman_mei: false,
            magnus: false,
            rotational_torque: None,
            added_mass_coefficient: 0.0,
            pressure_gradient: false,
            basset: None,
            wall_lift: None,
        }
    }
}

impl Validate for ForceSwitches {
    fn validate(&self, c: &mut Checker) {
        c.item("drag", &self.drag);
        c.finite_vec("gravity_m_s2", self.gravity);
        c.in_range("added_mass_coefficient", self.added_mass_coefficient, 0.0, true, 10.0, true);
        if let Some(b) = &self.basset {
            c.item("basset", b);
        }
        if let Some(w) = &self.wall_lift {
            c.item("wall_lift", w);
        }
    }
}

/// The fluid as seen by one particle at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FluidLocal {
    /// Fluid velocity (including any turbulent fluctuation) \[m/s\].
    pub u: Vec3,
    /// Velocity gradient, column j = ∂u/∂x_j \[1/s\] (zero when unknown).
    pub grad: Mat3,
    /// Local time derivative ∂u/∂t \[m/s²\].
    pub du_dt: Vec3,
}

impl Default for FluidLocal {
    fn default() -> Self {
        FluidLocal { u: Vec3::ZERO, grad: Mat3::ZERO, du_dt: Vec3::ZERO }
    }
}

impl FluidLocal {
    /// Vorticity ∇×u \[1/s\].
    #[inline]
    pub fn vorticity(&self) -> Vec3 {
        vorticity(&self.grad)
    }

    /// Fluid acceleration Du/Dt = ∂u/∂t + (u·∇)u \[m/s²\].
    #[inline]
    pub fn material_derivative(&self) -> Vec3 {
        self.du_dt + self.grad * self.u
    }
}

/// Vorticity ∇×u of a gradient whose column j is ∂u/∂x_j.
#[inline]
pub fn vorticity(g: &Mat3) -> Vec3 {
    Vec3::new(g.y_axis.z - g.z_axis.y, g.z_axis.x - g.x_axis.z, g.x_axis.y - g.y_axis.x)
}

/// Result of one force evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepForces {
    /// Drag relaxation time τ = τ_p/f(Re) \[s\]; ∞ without drag.
    pub tau: f64,
    /// Every non-drag force per unit mass \[m/s²\] (before division by the inertia factor).
    pub accel: Vec3,
    /// Inertia factor M ≥ 1 (added mass).
    pub inertia: f64,
    /// Angular acceleration of the spin \[rad/s²\].
    pub spin_accel: Vec3,
}

/// The switchable force set with its fluid.
#[derive(Clone, Debug, PartialEq)]
pub struct ForceModel {
    pub fluid: Fluid,
    pub switches: ForceSwitches,
}

impl ForceModel {
    pub fn new(fluid: Fluid, switches: ForceSwitches) -> Self {
        ForceModel { fluid, switches }
    }

    /// Whether the velocity gradient is needed (lift, rotation, fluid acceleration).
    pub fn needs_gradient(&self) -> bool {
        let s = &self.switches;
        s.saffman_mei
            || s.magnus
            || s.rotational_torque.is_some()
            || s.pressure_gradient
            || s.added_mass_coefficient > 0.0
    }

    /// Evaluates every switched-on force for a particle of diameter `d`, density `rho_p`, velocity `v`
    /// and spin `spin` in the local fluid `f`.
    #[inline]
    pub fn evaluate(&self, d: f64, rho_p: f64, v: Vec3, spin: Vec3, f: &FluidLocal) -> StepForces {
        let s = &self.switches;
        let fluid = &self.fluid;
        let w = f.u - v;
        let slip = w.length();
        let tau = if s.drag_enabled { s.drag.relaxation_time(fluid, d, rho_p, slip) } else { f64::INFINITY };
        let mut a = inertial::gravity_buoyancy(s.gravity, fluid.density, rho_p, s.buoyancy);
        let mut inertia = 1.0;
        let mut spin_accel = Vec3::ZERO;
        if self.needs_gradient() {
            let omega_f = f.vorticity();
            if s.saffman_mei {
                a += lift::saffman_mei(fluid, d, rho_p, w, omega_f);
            }
            let spin_rel = spin - 0.5 * omega_f;
            if s.magnus {
                a += lift::magnus(fluid, d, rho_p, w, spin_rel);
            }
            if let Some(law) = s.rotational_torque {
                spin_accel = lift::rotational_torque(fluid, d, rho_p, spin_rel, law);
            }
            if s.pressure_gradient || s.added_mass_coefficient > 0.0 {
                let dudt = f.material_derivative();
                if s.pressure_gradient {
                    a += inertial::pressure_gradient(dudt, fluid.density, rho_p);
                }
                if s.added_mass_coefficient > 0.0 {
                    a += inertial::added_mass_explicit(dudt, s.added_mass_coefficient, fluid.density, rho_p);
                    inertia = inertial::effective_inertia(s.added_mass_coefficient, fluid.density, rho_p);
                }
            }
        }
        StepForces { tau, accel: a, inertia, spin_accel }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vorticity_of_shear_and_rotation() {
        // u = (G y, 0, 0): ∂u/∂y = G → ω_z = −G.
        let g = Mat3::from_cols(Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::ZERO);
        assert_eq!(vorticity(&g), Vec3::new(0.0, 0.0, -2.0));
        // Solid rotation u = Ω ẑ × x = (−Ω y, Ω x, 0): ω = 2Ω ẑ.
        let om = 3.0;
        let g = Mat3::from_cols(Vec3::new(0.0, om, 0.0), Vec3::new(-om, 0.0, 0.0), Vec3::ZERO);
        assert_eq!(vorticity(&g), Vec3::new(0.0, 0.0, 2.0 * om));
        // Du/Dt in solid rotation is the centripetal acceleration −Ω² r.
        let f = FluidLocal { u: Vec3::new(-om * 0.5, om * 1.0, 0.0), grad: g, du_dt: Vec3::ZERO };
        assert!((f.material_derivative() - Vec3::new(-om * om, -om * om * 0.5, 0.0)).length() < 1e-14);
    }

    #[test]
    fn default_model_is_drag_and_gravity() {
        let m = ForceModel::new(Fluid::default(), ForceSwitches::default());
        assert!(!m.needs_gradient());
        let f = FluidLocal { u: Vec3::new(1.0, 0.0, 0.0), ..Default::default() };
        let s = m.evaluate(50e-6, 917.0, Vec3::ZERO, Vec3::ZERO, &f);
        assert_eq!(s.inertia, 1.0);
        assert!((s.accel.z + 9.81 * (1.0 - 1.225 / 917.0)).abs() < 1e-12);
        let expect = DragLaw::SchillerNaumann.relaxation_time(&Fluid::default(), 50e-6, 917.0, 1.0);
        assert_eq!(s.tau, expect);
    }
}
