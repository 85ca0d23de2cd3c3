//! Time integration and blow-up checks.

use super::Simulation;
use crate::contact::ContactLaw;
use crate::error::DemError;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::math::is_finite;

/// Time integration scheme.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Velocity Verlet (kick–drift–force–kick); forces see the half-step velocities. Default.
    #[default]
    VelocityVerlet,
    /// Symplectic (semi-implicit) Euler: force, kick by Δt, drift.
    SymplecticEuler,
}

impl<L: ContactLaw> Simulation<L> {
    /// Kicks velocities by `frac`·Δt·F/m (and ω by `frac`·Δt·τ/I); with `drift`, then moves positions by
    /// v·Δt. Frozen particles keep their velocity and move with it. Returns the largest speed after the
    /// kick (for the neighbour-list displacement bound).
    pub(crate) fn kick_drift(&mut self, frac: f64, drift: bool) -> f64 {
        let h = frac * self.dt;
        let dt = self.dt;
        let p = &mut self.particles;
        let (force, torque, inv_m, inv_i) = (&p.force, &p.torque, &p.inv_mass, &p.inv_inertia);
        p.vel
            .par_iter_mut()
            .zip(p.omega.par_iter_mut())
            .zip(p.pos.par_iter_mut())
            .enumerate()
            .map(|(i, ((v, w), x))| {
                if inv_m[i] > 0.0 {
                    *v += h * inv_m[i] * force[i];
                    *w += h * inv_i[i] * torque[i];
                }
                if drift {
                    *x += *v * dt;
                }
                v.length()
            })
            .reduce(|| 0.0, f64::max)
    }

    /// Fails with a blow-up error naming the first particle whose state is not finite.
    pub(crate) fn check_finite(&self) -> Result<(), DemError> {
        let p = &self.particles;
        let bad = (0..p.len())
            .into_par_iter()
            .find_first(|&i| !(is_finite(p.pos[i]) && is_finite(p.vel[i]) && is_finite(p.omega[i])));
        match bad {
            None => Ok(()),
            Some(i) => Err(DemError::BlowUp {
                particle: p.id[i],
                step: self.st.step,
                time_s: self.st.time,
                what: format!(
                    "position/velocity became non-finite (x = {:?}, v = {:?}, force = {:?})",
                    p.pos[i].to_array(),
                    p.vel[i].to_array(),
                    p.force[i].to_array()
                ),
                cause: self.likely_cause(),
            }),
        }
    }
}
