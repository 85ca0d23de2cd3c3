//! Sessile-drop calibration: the static contact angle that a given Akinci adhesion coefficient produces,
//! so users can choose the adhesion of a wall from a measured contact angle (the calibration the truck wading
//! thesis, Arjun & Michael 2022, lists as future work).
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
    /// Height of the lowest particle's centre above the plate at the end \[m\]: dp/2 for liquid resting
    /// on the wall as water filled against it does.
    pub standoff: f64,
}

impl SessileResult {
    /// The drop came to rest in one piece: no particle removed and a kinetic energy at the end below 0.1
    /// of the surface-energy scale (settled drops end at 10⁻⁵–10⁻², a drop still spreading as a film at
    /// about 10⁻²; unstable ones at 1–10). Only settled drops give a contact angle to calibrate with.
    pub fn settled(&self) -> bool {
        self.removed == 0 && self.residual_motion < 0.1
    }
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
    // The cohesion compresses the liquid by its virial pressure and an adhesive wall the liquid near it
    // by about the adhesion factor times that: the sound speed must keep both compressions small
    // (c₀ ≥ 10 √(p/ρ)).
    p.sound_speed = p.sound_speed.max(p.capillary_sound_speed(d.adhesion));
    // Viscous damping lets the drop come to rest within the run (the static angle does not depend on it).
    p.artificial_viscosity = 0.1;
    p.kinematic_viscosity = 1e-5;
    let mut sim = Simulation::new(p);
    // Wide enough for the whole drop spread as a film: a wall of adhesion above about 1
    // wets completely and the drop keeps spreading. On a narrower plate (3R until 2026-11-25) the film
    // reached the edge and was drawn round it onto the plate's sides and underside, the cap height was
    // measured from there, and the angle rose again with the factor (2D, R/8: 10.5° at 2, 37° at 5 and 10).
    let film = match d.dim {
        Dim::Two => std::f64::consts::PI * r * r / (4.0 * dp),
        Dim::Three => (2.0 * r * r * r / (3.0 * dp)).sqrt(),
    };
    // The film is thinner than a spacing where the wall pulls it (measured in 3D at R/6, adhesion 2: base
    // radius 5.9 mm against 4.0 mm for a film one spacing thick), so twice that extent.
    let half = (3.0 * r).max(2.0 * film + 4.0 * dp);
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
    let reach = half + 4.0 * r;
    sim.set_domain(Aabb::new(Vec3::splat(-reach), Vec3::splat(reach)));
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
        standoff: zmin,
    })
}

/// Where a contact angle falls in a table of angles against adhesion factors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FactorFit {
    /// The factor that gives the angle (interpolated linearly between the table's rows).
    Within(f64),
    /// The angle is larger than the table's largest: even the smallest factor wets more. Holds that
    /// factor and its angle \[deg\].
    LessWetting { factor: f64, angle_deg: f64 },
    /// The angle is smaller than the table's smallest (complete wetting at this spacing): holds the
    /// smallest factor that reaches the table's smallest angle, and that angle \[deg\].
    MoreWetting { factor: f64, angle_deg: f64 },
}

/// The adhesion factor that gives contact angle `target_deg`, from `rows` of (factor, angle \[deg\]) with
/// increasing factors (settled drops only, [`SessileResult::settled`]). The angle falls with the factor;
/// where a measured angle rises again (noise of a drop that has spread to a film), the table is read
/// through its running minimum, so the answer is the smallest factor that reaches the target.
pub fn factor_for_angle(rows: &[(f64, f64)], target_deg: f64) -> Option<FactorFit> {
    let first = *rows.first()?;
    let mut env: Vec<(f64, f64)> = Vec::with_capacity(rows.len());
    for &(f, a) in rows {
        let a = env.last().map_or(a, |l: &(f64, f64)| a.min(l.1));
        env.push((f, a));
    }
    if target_deg > first.1 {
        return Some(FactorFit::LessWetting { factor: first.0, angle_deg: first.1 });
    }
    for w in env.windows(2) {
        let ((f0, a0), (f1, a1)) = (w[0], w[1]);
        if target_deg <= a0 && target_deg >= a1 && a0 > a1 {
            return Some(FactorFit::Within(f0 + (f1 - f0) * (a0 - target_deg) / (a0 - a1)));
        }
    }
    let smallest = env[env.len() - 1].1;
    let f = env.iter().find(|r| r.1 == smallest).map_or(first.0, |r| r.0);
    if target_deg == smallest {
        Some(FactorFit::Within(f))
    } else {
        Some(FactorFit::MoreWetting { factor: f, angle_deg: smallest })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factors_are_read_from_the_falling_angle() {
        // The 2D table of docs/sph.md (R/8, 8 capillary times), with the film-limited rise at 10.
        let rows = [(0.5, 100.1), (1.0, 20.5), (2.0, 6.7), (5.0, 5.3), (10.0, 5.5)]; // an earlier measurement
        let Some(FactorFit::Within(f)) = factor_for_angle(&rows, 60.0) else { panic!("60° within") };
        assert!((f - (0.5 + 0.5 * (100.1 - 60.0) / (100.1 - 20.5))).abs() < 1e-12);
        let Some(FactorFit::Within(f)) = factor_for_angle(&rows, 100.1) else { panic!("end point") };
        assert_eq!(f, 0.5);
        assert_eq!(
            factor_for_angle(&rows, 120.0),
            Some(FactorFit::LessWetting { factor: 0.5, angle_deg: 100.1 })
        );
        // Below the smallest angle: the first factor that reached it (5, not 10).
        assert_eq!(
            factor_for_angle(&rows, 2.0),
            Some(FactorFit::MoreWetting { factor: 5.0, angle_deg: 5.3 })
        );
        let Some(FactorFit::Within(f)) = factor_for_angle(&rows, 5.3) else { panic!("smallest angle") };
        assert_eq!(f, 5.0);
        assert_eq!(factor_for_angle(&[], 30.0), None);
    }
}
