//! Sessile-drop calibration: the static contact angle that a given Akinci adhesion coefficient produces,
//! so users can choose the adhesion of a wall from a measured contact angle (digest §2.10.5, future-work
//! item L1428).
//!
//! A half-disc (2D) or hemisphere (3D) of water is placed on a flat wall without gravity and relaxes
//! under surface tension and adhesion until it is at rest. The angle is read from the spherical-cap
//! geometry of the relaxed drop, `tan(θ/2) = H / b`, with the base half-width (radius) `b` of the
//! particles touching the wall and the height `H` of the cap, both extended by half a spacing to the
//! particle surface.

use crate::error::SphError;
use crate::kernel::Dim;
use crate::params::SphParams;
use crate::sim::{Simulation, WallOptions};
use spatter_core::{Aabb, Vec3};

/// Inputs of a sessile-drop run.
#[derive(Clone, Debug, PartialEq)]
pub struct SessileDrop {
    pub dim: Dim,
    /// Radius of the initial half-disc/hemisphere \[m\].
    pub radius: f64,
    /// Particles across the initial radius.
    pub resolution: usize,
    /// Surface tension σ \[N/m\].
    pub surface_tension: f64,
    /// Akinci adhesion β of the wall as a multiple of the cohesion γ.
    pub adhesion: f64,
    /// Simulated time in capillary times `√(ρR³/σ)`.
    pub capillary_times: f64,
}

impl SessileDrop {
    /// A 2 mm water drop at 10 particles per radius, relaxed over 12 capillary times.
    pub fn water(dim: Dim, adhesion: f64) -> Self {
        SessileDrop {
            dim,
            radius: 2e-3,
            resolution: 10,
            surface_tension: 0.072,
            adhesion,
            capillary_times: 12.0,
        }
    }
}

/// The relaxed drop.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SessileResult {
    /// Static contact angle \[deg\].
    pub contact_angle_deg: f64,
    /// Base half-width (2D) or radius (3D) \[m\].
    pub base: f64,
    /// Cap height \[m\].
    pub height: f64,
    /// Kinetic energy at the end over the surface energy scale σR (σR² in 3D).
    pub residual_motion: f64,
    /// Particles removed during the run (the drop left the plate or broke up).
    pub removed: u64,
}

/// Runs the sessile drop and measures its contact angle.
pub fn sessile_drop(d: &SessileDrop) -> Result<SessileResult, SphError> {
    let r = d.radius;
    let dp = r / d.resolution as f64;
    let rho = 1000.0;
    let sigma = d.surface_tension;
    // Capillary velocity scale √(σ/(ρR)); c₀ ten times a generous multiple of it.
    let u = (sigma / (rho * r)).sqrt();
    let mut p = SphParams::water(d.dim, dp, 10.0 * 3.0 * u);
    p.gravity = Vec3::ZERO;
    p.surface_tension = sigma;
    // Viscous damping lets the drop come to rest within the run (the static angle does not depend on it).
    p.artificial_viscosity = 0.1;
    p.kinematic_viscosity = 1e-5;
    let mut sim = Simulation::new(p);
    let half = 3.0 * r;
    let three = d.dim == Dim::Three;
    let wall = Aabb::new(
        Vec3::new(-half, if three { -half } else { 0.0 }, -4.0 * dp),
        Vec3::new(half, if three { half } else { 0.0 }, 0.0),
    );
    sim.add_block("plate", wall, None, None, WallOptions { adhesion: d.adhesion, slip: Default::default() });
    // Lattice points of the half-disc / hemisphere above the plate.
    let n = (r / dp).ceil() as i64;
    let mut pts = Vec::new();
    let ny = if three { n } else { 0 };
    for k in 0..n {
        for j in -ny..ny.max(1) {
            for i in -n..n {
                let x = Vec3::new(
                    (i as f64 + 0.5) * dp,
                    if three { (j as f64 + 0.5) * dp } else { 0.0 },
                    (k as f64 + 0.5) * dp,
                );
                if x.length() < r {
                    pts.push(x);
                }
            }
        }
    }
    sim.add_particles(&pts, Vec3::ZERO);
    // Start at the density the cohesion compresses the liquid to, so that the drop is not thrown off the
    // wall by the compression transient.
    let rho_c = sim.params.eos().density(sim.params.cohesive_pressure());
    sim.fluid.rho.iter_mut().for_each(|r| *r = rho_c);
    sim.set_domain(Aabb::new(Vec3::splat(-4.0 * r), Vec3::splat(4.0 * r)));
    let tc = (rho * r * r * r / sigma).sqrt();
    sim.initialize()?;
    while sim.time < d.capillary_times * tc {
        sim.step()?;
    }
    // Base: particles in the first layer above the wall; height: the highest particle.
    let zmin = sim.fluid.pos.iter().map(|x| x.z).fold(f64::INFINITY, f64::min);
    let base = sim
        .fluid
        .pos
        .iter()
        .filter(|x| x.z < zmin + 0.5 * dp)
        .map(|x| if three { (x.x * x.x + x.y * x.y).sqrt() } else { x.x.abs() })
        .fold(0.0, f64::max)
        + 0.5 * dp;
    let top = sim.fluid.pos.iter().map(|x| x.z).fold(f64::NEG_INFINITY, f64::max) + 0.5 * dp;
    let height = top - (zmin - 0.5 * dp);
    // A drop that no longer touches the wall (it does not wet it at all) has an angle of 180°.
    let theta = if zmin > 1.5 * dp { std::f64::consts::PI } else { 2.0 * (height / base).atan() };
    let energy_scale = if three { sigma * r * r } else { sigma * r };
    Ok(SessileResult {
        contact_angle_deg: theta.to_degrees(),
        base,
        height,
        residual_motion: sim.kinetic_energy() / energy_scale,
        removed: sim.removed.outside_domain + sim.removed.density_window,
    })
}
