//! What the fluid-force hook needs to know about the fluid at a sphere: velocity, pressure gradient and
//! void fraction. A prescribed [`FlowField`] provides it here; the coupled CFD–DEM solver provides it
//! from its own grid.

use serde::{Deserialize, Serialize};
use spatter_core::Vec3;
use spatter_flow::field::FlowField;

/// The fluid at one sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalFluid {
    /// Fluid velocity (interstitial) \[m/s\].
    pub u: Vec3,
    /// Pressure gradient ∇p \[Pa/m\].
    pub grad_p: Vec3,
    /// Fluid volume fraction α ∈ (0, 1].
    pub alpha: f64,
}

/// A source of [`LocalFluid`] values.
pub trait FluidSampler: Send + Sync {
    /// The fluid at `x` \[m\] and time `t` \[s\], or `None` outside the fluid domain. `hint` is a per-particle
    /// location cache (start with `spatter_flow::field::tetmesh::NONE`).
    fn fluid_at(&self, x: Vec3, t: f64, hint: &mut u32) -> Option<LocalFluid>;
}

/// How the pressure gradient of a prescribed field is obtained.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PressureGradient {
    /// ∇p = ρ_f g: the hydrostatic pressure; −V∇p is Archimedes' buoyancy −ρ_f V g. The default.
    #[default]
    Hydrostatic,
    /// ∇p = ρ_f (g − Du/Dt) with Du/Dt = ∂u/∂t + (∇u) u from the field (Euler's equation, viscous
    /// stresses neglected): buoyancy plus the fluid-acceleration force of a prescribed flow. Needs
    /// the field's gradient, so it costs a gradient sample per sphere.
    FluidAcceleration,
}

/// A prescribed flow field seen by the fluid-force hook: the field's velocity, a pressure gradient by
/// [`PressureGradient`], and a uniform void fraction (1 for single stones in air).
pub struct PrescribedFlow<F: FlowField> {
    pub field: F,
    /// Fluid density ρ_f \[kg/m³\] (the pressure gradient's scale).
    pub density: f64,
    /// Gravitational acceleration \[m/s²\].
    pub gravity: Vec3,
    pub pressure: PressureGradient,
    /// Fluid volume fraction α ∈ (0, 1] used by the drag law.
    pub alpha: f64,
}

impl<F: FlowField> PrescribedFlow<F> {
    /// A field with hydrostatic pressure and α = 1.
    pub fn new(field: F, density: f64, gravity: Vec3) -> Self {
        PrescribedFlow { field, density, gravity, pressure: PressureGradient::Hydrostatic, alpha: 1.0 }
    }
}

impl<F: FlowField> FluidSampler for PrescribedFlow<F> {
    #[inline]
    fn fluid_at(&self, x: Vec3, t: f64, hint: &mut u32) -> Option<LocalFluid> {
        let want_grad = self.pressure == PressureGradient::FluidAcceleration;
        let s = self.field.sample(x, t, hint, want_grad)?;
        let accel = if want_grad { s.du_dt + s.grad * s.u } else { Vec3::ZERO };
        Some(LocalFluid { u: s.u, grad_p: self.density * (self.gravity - accel), alpha: self.alpha })
    }
}
