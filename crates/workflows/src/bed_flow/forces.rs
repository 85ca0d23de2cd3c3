//! The fluid forces on the exposed grains of a DEM bed: the hook [`BedFlowForces`] the DEM engine calls
//! once per force evaluation.
//!
//! For an exposed grain (see [`super::exposure`]) of diameter d, mass m and velocity v whose centre is
//! y = z − z_ground above the flow's ground plane, with (u_*, ê) = the [`GroundFlow`] at time t:
//!
//! * fluid velocity u = u_* u⁺(y u_*/ν) ê (law of the wall, [`super::near_ground`]);
//! * **drag** F_D = f_w m (u − v)/τ, τ = τ_p/f(Re) from the force library's drag law (Schiller–Naumann
//!   by default) at the slip Reynolds number, times O'Neill's (1968) wall factor f_w = 1.7009 for a
//!   sphere touching a wall in shear flow while y < 2r (the grain rests on the bed), 1 above;
//! * **wall lift** F_L = p (a⁺)^q ρ_f ν² × Zeng's distance factor (Jasion 2013, Table 3.1, eq. 3.49;
//!   Zeng et al. 2009), upwards, zero beyond y = 4d;
//! * optionally **Saffman** (Mei's correction) and **Magnus** lift in the shear du/dy of the wall law
//!   (off by default: next to the wall the wall-lift law is the measured form of the shear lift, and
//!   both together would count it twice);
//! * **buoyancy** ρ_f V g upwards.
//!
//! Gravity and the contacts (with their cohesion) are the DEM's. The fluid torque on the grains is not
//! modelled (the rocking torque arises from the drag at the centre and the contact forces).

use super::exposure::{exposure, ExposureScratch};
use super::near_ground::GroundFlow;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::{Mat3, Vec3};
use spatter_dem::sim::{ExternalForces, ParticleView};
use spatter_flow::forces::drag::DragLaw;
use spatter_flow::forces::lift;
use spatter_flow::forces::wall_lift::{wall_lift_force, WallLiftLaw, ZengAlpha};
use spatter_flow::forces::Fluid;
use spatter_flow::liftoff::incipient::ONEILL_WALL_FACTOR;
use spatter_flow::liftoff::wall_law::speed_at;
use std::sync::{Arc, Mutex};

/// Which fluid forces act on the exposed grains.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BedForceSettings {
    /// Drag law (default Schiller–Naumann).
    #[serde(default)]
    pub drag: DragLaw,
    /// Drag factor of a grain resting on the bed (y < 2r; default O'Neill's 1.7009; 1 switches it off).
    #[serde(default = "oneill")]
    pub wall_drag_factor: f64,
    /// Wall-lift law of Jasion's Table 3.1 (default: the regime choice).
    #[serde(default = "regimes")]
    pub wall_lift: WallLiftLaw,
    /// Saffman shear lift with Mei's correction (default off).
    #[serde(default)]
    pub saffman: bool,
    /// Magnus lift of the grain's spin relative to the fluid rotation (default off).
    #[serde(default)]
    pub magnus: bool,
}

fn oneill() -> f64 {
    ONEILL_WALL_FACTOR
}
fn regimes() -> WallLiftLaw {
    WallLiftLaw::Regimes
}

impl Default for BedForceSettings {
    fn default() -> Self {
        BedForceSettings {
            drag: DragLaw::default(),
            wall_drag_factor: oneill(),
            wall_lift: regimes(),
            saffman: false,
            magnus: false,
        }
    }
}

/// What the last evaluation saw (shared with the workflow for its outputs).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BedFlowProbe {
    pub time: f64,
    pub u_star: f64,
    pub exposed: usize,
}

/// The DEM hook: fluid forces on the exposed grains.
pub struct BedFlowForces<G: GroundFlow> {
    pub flow: Arc<G>,
    pub fluid: Fluid,
    /// Grain density \[kg/m³\] (the drag law's relaxation time needs it with the diameter).
    pub density: f64,
    /// The flow's ground plane \[m\].
    pub z_ground: f64,
    /// The DEM time at which the flow starts (the flow's time is the DEM's minus this) \[s\].
    pub t0: f64,
    pub settings: BedForceSettings,
    /// Last evaluation's friction velocity and exposed count.
    pub probe: Arc<Mutex<BedFlowProbe>>,
    scratch: ExposureScratch,
    exposed: Vec<bool>,
    active: Vec<bool>,
}

impl<G: GroundFlow> BedFlowForces<G> {
    pub fn new(flow: Arc<G>, fluid: Fluid, density: f64, z_ground: f64, settings: BedForceSettings) -> Self {
        BedFlowForces {
            flow,
            fluid,
            density,
            z_ground,
            t0: 0.0,
            settings,
            probe: Arc::default(),
            scratch: ExposureScratch::default(),
            exposed: Vec::new(),
            active: Vec::new(),
        }
    }

    /// The fluid force \[N\] on one exposed grain of radius `r`, mass `m`, at centre height `y` above the
    /// ground plane, velocity `v`, spin `w`, under friction velocity `u_star` along `dir`.
    #[allow(clippy::too_many_arguments)]
    pub fn grain_force(&self, r: f64, m: f64, y: f64, v: Vec3, w: Vec3, u_star: f64, dir: Vec3) -> Vec3 {
        let s = &self.settings;
        let fl = &self.fluid;
        let nu = fl.nu();
        let d = 2.0 * r;
        let y = y.max(1e-3 * r);
        let u = speed_at(y, u_star, nu) * dir;
        let slip = u - v;
        let tau = s.drag.relaxation_time(fl, d, self.density, slip.length());
        let f_w = if y < 2.0 * r { s.wall_drag_factor } else { 1.0 };
        let mut f = f_w * m * slip / tau;
        f.z += wall_lift_force(s.wall_lift, Some(ZengAlpha::Zeng), d, y, u_star, fl.density, nu);
        f.z += fl.density * m / self.density * 9.81;
        if s.saffman || s.magnus {
            // dU/dy of the wall law by a central difference. The gradient of u = U(y) ê has one non-zero
            // column, ∂u/∂z = (dU/dy) ê (column j is ∂u/∂x_j); the library takes the vorticity from it.
            let h = 1e-3 * y;
            let dudy = (speed_at(y + h, u_star, nu) - speed_at(y - h, u_star, nu)) / (2.0 * h);
            let grad = Mat3::from_cols(Vec3::ZERO, Vec3::ZERO, dudy * dir);
            let omega_f = spatter_flow::forces::model::vorticity(&grad);
            if s.saffman {
                f += m * lift::saffman_mei(fl, d, self.density, slip, omega_f);
            }
            if s.magnus {
                f += m * lift::magnus(fl, d, self.density, slip, w - 0.5 * omega_f);
            }
        }
        f
    }
}

impl<G: GroundFlow> BedFlowForces<G> {
    /// The flow's friction velocity and direction at DEM time `time`; finds the exposed grains (kept for
    /// the force evaluation) and records both in the probe.
    pub fn observe(&mut self, time: f64, pos: &[Vec3], radius: &[f64], inv_mass: &[f64]) -> (f64, Vec3) {
        let (u_star, dir) = self.flow.shear(time - self.t0);
        self.active.clear();
        self.active.extend(inv_mass.iter().map(|&im| im > 0.0));
        let mut exposed = std::mem::take(&mut self.exposed);
        exposure(pos, radius, &self.active, dir, self.z_ground, &mut self.scratch, &mut exposed);
        let count = exposed.iter().filter(|&&e| e).count();
        self.exposed = exposed;
        if let Ok(mut probe) = self.probe.lock() {
            *probe = BedFlowProbe { time: time - self.t0, u_star, exposed: count };
        }
        (u_star, dir)
    }
}

impl<G: GroundFlow> ExternalForces for BedFlowForces<G> {
    fn add(&mut self, time: f64, p: &ParticleView, force: &mut [Vec3], _torque: &mut [Vec3]) {
        let (u_star, dir) = self.observe(time, p.pos, p.radius, p.inv_mass);
        let this = &*self;
        force.par_iter_mut().enumerate().for_each(|(i, f)| {
            if this.exposed[i] {
                let m = 1.0 / p.inv_mass[i];
                *f += this.grain_force(
                    p.radius[i],
                    m,
                    p.pos[i].z - this.z_ground,
                    p.vel[i],
                    p.omega[i],
                    u_star,
                    dir,
                );
            }
        });
    }
}
