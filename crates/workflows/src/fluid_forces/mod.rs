//! Fluid forces on DEM spheres from a flow field: drag and the pressure-gradient (buoyancy) force, as the
//! DEM's [`ExternalForces`] hook.
//!
//! Each sphere i (a free sphere or a member of a rigid clump) feels
//!
//! F_i = K[β_i (u(x_i) − v_i)] − V_i ∇p(x_i),
//!
//! * u — the fluid velocity at the sphere's centre (interstitial velocity in a suspension);
//! * v_i — the sphere's own velocity; for a clump member the DEM already stores v + ω × r (r the arm
//!   from the body's centre of mass), so the drag on a turning body resists the turning;
//! * β_i — the exchange coefficient of the chosen [`DragModel`] \[kg/s\];
//! * K — the drag correction of [`KCorrection`] (default 1);
//! * ∇p — the pressure gradient at the sphere, from the [`FluidSampler`]: for a prescribed field either
//!   hydrostatic (∇p = ρ_f g: Archimedes buoyancy) or from the field's Euler equation
//!   (∇p = ρ_f (g − Du/Dt)), see [`PressureGradient`].
//!
//! Forces act at the sphere centres; a clump member's force reaches its body's centre of mass through
//! the DEM's member reduction (force, and torque r × F). The hook writes no torque of its own.
//!
//! The evaluation is parallel over fixed blocks of particles and each sphere's force depends only on
//! that sphere, so results are bit-identical for any thread count. It allocates only when the number of
//! particles grows (the per-particle location hints of imported fields).

mod drag;
mod sampler;
#[cfg(test)]
mod tests;

pub use drag::DragModel;
pub use sampler::{FluidSampler, LocalFluid, PrescribedFlow, PressureGradient};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;
use spatter_dem::sim::{ExternalForces, ParticleView};
use spatter_flow::forces::Fluid;

/// Particles per parallel task.
const CHUNK: usize = 1024;

/// A correction of the drag on the spheres of porous multi-sphere bodies (the "K-correction" of
/// stone-chip CFD–DEM studies, whose published calibration is not available): the drag components
/// transverse to the local fluid velocity are multiplied by K, the component along it is kept.
/// `None` (K = 1) is the default and leaves every force unchanged.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum KCorrection {
    /// K = 1.
    #[default]
    None,
    /// The transverse drag components times `k` (dimensionless, > 0), calibrated by the user against
    /// single-body trajectories.
    Transverse { k: f64 },
}

impl KCorrection {
    /// The corrected drag of a sphere in fluid moving with velocity `u` (the background direction).
    #[inline]
    pub fn apply(&self, drag: Vec3, u: Vec3) -> Vec3 {
        match *self {
            KCorrection::None => drag,
            KCorrection::Transverse { k } => {
                let n = u.normalize_or_zero();
                let along = drag.dot(n) * n;
                along + k * (drag - along)
            }
        }
    }
}

impl Validate for KCorrection {
    fn validate(&self, c: &mut Checker) {
        if let KCorrection::Transverse { k } = self {
            c.positive("k", *k);
        }
    }
}

/// Options of the fluid forces.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidForceOptions {
    /// Carrier fluid (density \[kg/m³\], viscosity \[Pa s\]).
    #[serde(default)]
    pub fluid: Fluid,
    /// Drag law.
    #[serde(default)]
    pub drag: DragModel,
    /// Drag correction for multi-sphere bodies (default none, K = 1).
    #[serde(default)]
    pub k_correction: KCorrection,
    /// Apply the pressure-gradient force −V∇p (default true).
    #[serde(default = "yes")]
    pub pressure_force: bool,
}

fn yes() -> bool {
    true
}

impl Default for FluidForceOptions {
    /// Air, Di Felice drag, K = 1, with the pressure-gradient force.
    fn default() -> Self {
        FluidForceOptions {
            fluid: Fluid::default(),
            drag: DragModel::default(),
            k_correction: KCorrection::None,
            pressure_force: true,
        }
    }
}

impl Validate for FluidForceOptions {
    fn validate(&self, c: &mut Checker) {
        c.nested("fluid", |c| self.fluid.validate(c));
        c.nested("k_correction", |c| self.k_correction.validate(c));
    }
}

impl FluidForceOptions {
    /// The fluid force on one sphere of radius `r` \[m\] moving with velocity `v` \[m/s\] in the local fluid
    /// `f` \[N\]: the drag K[β (u − v)] plus, if enabled, −V ∇p.
    #[inline]
    pub fn force_on_sphere(&self, r: f64, v: Vec3, f: &LocalFluid) -> Vec3 {
        let (drag, vol_grad_p) = self.parts(r, v, f);
        drag + vol_grad_p
    }

    /// The drag \[N\] and the pressure-gradient force \[N\] on one sphere, separately.
    #[inline]
    pub fn parts(&self, r: f64, v: Vec3, f: &LocalFluid) -> (Vec3, Vec3) {
        let w = f.u - v;
        let beta = self.drag.beta(&self.fluid, 2.0 * r, f.alpha, w.length());
        let drag = self.k_correction.apply(beta * w, f.u);
        let p = if self.pressure_force {
            -(4.0 / 3.0 * std::f64::consts::PI * r * r * r) * f.grad_p
        } else {
            Vec3::ZERO
        };
        (drag, p)
    }
}

/// Adds the fluid force of every free sphere and clump member in `p` to `force`; returns the number of
/// spheres outside the sampler's domain (they get no fluid force). `hints` holds one location hint per
/// particle (resized when the count changes). Parallel over fixed blocks, bit-identical for any thread
/// count.
pub fn add_fluid_forces<S: FluidSampler + ?Sized>(
    sampler: &S,
    options: &FluidForceOptions,
    time: f64,
    p: &ParticleView,
    hints: &mut Vec<u32>,
    force: &mut [Vec3],
) -> u64 {
    let n = p.pos.len();
    if hints.len() != n {
        hints.resize(n, spatter_flow::field::tetmesh::NONE);
    }
    force[..n]
        .par_chunks_mut(CHUNK)
        .zip(hints.par_chunks_mut(CHUNK))
        .enumerate()
        .map(|(c, (fs, hs))| {
            let mut outside = 0u64;
            for (k, (f, h)) in fs.iter_mut().zip(hs.iter_mut()).enumerate() {
                let i = c * CHUNK + k;
                if p.inv_mass[i] <= 0.0 {
                    continue;
                }
                match sampler.fluid_at(p.pos[i], time, h) {
                    Some(local) => *f += options.force_on_sphere(p.radius[i], p.vel[i], &local),
                    None => outside += 1,
                }
            }
            outside
        })
        .sum()
}

/// The DEM hook: fluid forces from a [`FluidSampler`] at every force evaluation.
pub struct FluidForces<S: FluidSampler> {
    pub sampler: S,
    pub options: FluidForceOptions,
    hints: Vec<u32>,
    outside: u64,
}

impl<S: FluidSampler> FluidForces<S> {
    pub fn new(sampler: S, options: FluidForceOptions) -> Self {
        FluidForces { sampler, options, hints: Vec::new(), outside: 0 }
    }

    /// Spheres outside the field's domain in the last evaluation (they felt no fluid force).
    pub fn outside_last(&self) -> u64 {
        self.outside
    }
}

impl<S: FluidSampler> ExternalForces for FluidForces<S> {
    fn add(&mut self, time: f64, particles: &ParticleView, force: &mut [Vec3], _torque: &mut [Vec3]) {
        self.outside =
            add_fluid_forces(&self.sampler, &self.options, time, particles, &mut self.hints, force);
    }

    /// The drag on a sphere is sampled at its own centre from its own velocity (the hints only speed up
    /// the search of an imported mesh).
    fn per_particle(&self) -> bool {
        true
    }
}
