//! Time integration and blow-up checks.

use super::Simulation;
use crate::contact::ContactLaw;
use crate::error::DemError;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::math::is_finite;
use spatter_core::Vec3;

/// Time integration scheme.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Velocity Verlet (kick–drift–force–kick); forces see the half-step velocities. Default.
    #[default]
    VelocityVerlet,
    /// Symplectic (semi-implicit) Euler: force, kick by Δt, drift (`"se"` is accepted too).
    #[serde(alias = "se")]
    SymplecticEuler,
    /// Forward Euler (Jasion 2013, Table A.1; first order, for studies).
    Fe,
    /// Explicit midpoint Runge–Kutta (2 evaluations per step).
    Rk2,
    /// Classical fourth-order Runge–Kutta (4 evaluations per step).
    Rk4,
    /// Two-step Adams–Bashforth (self-starting with RK4 steps).
    Ab2,
    /// Four-step Adams–Bashforth (self-starting with RK4 steps).
    Ab4,
    /// Adams–Bashforth–Moulton predictor–corrector, fourth order (2 evaluations per step).
    Abm4,
    /// Backward Euler by fixed-point iteration (`Settings::iterations` evaluations per step).
    Bd1,
    /// Two-step backward differentiation by fixed-point iteration.
    Bd2,
    /// Four-step backward differentiation by fixed-point iteration.
    Bd4,
}

impl Integrator {
    /// The scheme of the integrator library this integrator runs (`None` for velocity Verlet, which is
    /// not one of the ten; symplectic Euler is the library's SE).
    pub fn scheme(self) -> Option<crate::integrators::Scheme> {
        use crate::integrators::Scheme;
        Some(match self {
            Integrator::VelocityVerlet => return None,
            Integrator::SymplecticEuler => Scheme::Se,
            Integrator::Fe => Scheme::Fe,
            Integrator::Rk2 => Scheme::Rk2,
            Integrator::Rk4 => Scheme::Rk4,
            Integrator::Ab2 => Scheme::Ab2,
            Integrator::Ab4 => Scheme::Ab4,
            Integrator::Abm4 => Scheme::Abm4,
            Integrator::Bd1 => Scheme::Bd1,
            Integrator::Bd2 => Scheme::Bd2,
            Integrator::Bd4 => Scheme::Bd4,
        })
    }

    /// The integrator that runs `scheme` in a DEM scene.
    pub fn of_scheme(scheme: crate::integrators::Scheme) -> Integrator {
        use crate::integrators::Scheme;
        match scheme {
            Scheme::Fe => Integrator::Fe,
            Scheme::Se => Integrator::SymplecticEuler,
            Scheme::Rk2 => Integrator::Rk2,
            Scheme::Rk4 => Integrator::Rk4,
            Scheme::Ab2 => Integrator::Ab2,
            Scheme::Ab4 => Integrator::Ab4,
            Scheme::Abm4 => Integrator::Abm4,
            Scheme::Bd1 => Integrator::Bd1,
            Scheme::Bd2 => Integrator::Bd2,
            Scheme::Bd4 => Integrator::Bd4,
        }
    }

    /// Short name for tables (VV, SE, FE, RK4, …).
    pub fn label(self) -> &'static str {
        self.scheme().map_or("VV", |s| s.label())
    }
}

impl<L: ContactLaw> Simulation<L> {
    /// Kicks velocities by `frac`·Δt·F/m (and ω by `frac`·Δt·τ/I); with `drift`, then moves positions by
    /// v·Δt. Frozen particles keep their velocity and move with it. Returns the largest speed after the
    /// kick (for the neighbour-list displacement bound; 0 without `drift`, where no caller needs it).
    /// With `reset`, the force and torque arrays are then set to gravity (and the persistent external
    /// forces) for the next evaluation, in the same pass.
    pub(crate) fn kick_drift(&mut self, frac: f64, drift: bool, reset: bool) -> f64 {
        match (drift, reset) {
            (true, true) => self.kick_pass::<true, true>(frac),
            (true, false) => self.kick_pass::<true, false>(frac),
            (false, true) => self.kick_pass::<false, true>(frac),
            (false, false) => self.kick_pass::<false, false>(frac),
        }
    }

    /// [`Simulation::kick_drift`] with the options as constants, so that each pass keeps only its own work
    /// in the loop (a kick without drift neither reads the positions nor tracks the largest speed).
    fn kick_pass<const DRIFT: bool, const RESET: bool>(&mut self, frac: f64) -> f64 {
        let h = frac * self.dt;
        let dt = self.dt;
        let g = self.gravity;
        let p = &mut self.particles;
        let (inv_m, radius) = (&p.inv_mass, &p.radius);
        let (ext_f, ext_t) = (&p.ext_force, &p.ext_torque);
        let has_ext = !ext_f.is_empty();
        const CHUNK: usize = 4096;
        let v2max = p
            .vel
            .par_chunks_mut(CHUNK)
            .zip(p.omega.par_chunks_mut(CHUNK))
            .zip(p.pos.par_chunks_mut(CHUNK))
            .zip(p.force.par_chunks_mut(CHUNK).zip(p.torque.par_chunks_mut(CHUNK)))
            .enumerate()
            .map(move |(c, (((vs, ws), xs), (fs, ts)))| {
                // Copies of the captured scalars and slices, so that the loops keep them in registers.
                let (h, dt, g, has_ext, ext_f, ext_t) = (h, dt, g, has_ext, ext_f, ext_t);
                let base = c * CHUNK;
                let (inv_m, radius) = (&inv_m[base..base + vs.len()], &radius[base..base + vs.len()]);
                let mut m: f64 = 0.0;
                // Sum of all components: NaN or ∞ anywhere makes it non-finite (f64::max would hide a NaN;
                // a finite sum that overflows only costs a search in `check_finite`). Without a drift the
                // positions are unchanged since the last drift checked them.
                let mut check = 0.0;
                if !DRIFT {
                    let particles = vs.iter_mut().zip(ws.iter_mut());
                    let inputs = fs.iter_mut().zip(ts.iter_mut()).zip(inv_m.iter().zip(radius));
                    for (k, ((v, w), ((f, t), (&im, &r)))) in particles.zip(inputs).enumerate() {
                        let hm = h * im;
                        *v += hm * *f;
                        *w += (2.5 * hm / (r * r)) * *t;
                        check += (*v + *w).element_sum();
                        if RESET {
                            reset_force(f, t, im, g, has_ext, ext_f, ext_t, base + k);
                        }
                    }
                    return (m, check);
                }
                let particles = vs.iter_mut().zip(ws.iter_mut()).zip(xs.iter_mut());
                let inputs = fs.iter_mut().zip(ts.iter_mut()).zip(inv_m.iter().zip(radius));
                for (k, (((v, w), x), ((f, t), (&im, &r)))) in particles.zip(inputs).enumerate() {
                    // Frozen particles have zero inverse mass and inertia: the kick vanishes.
                    let hm = h * im;
                    *v += hm * *f;
                    // 1/I = 2.5/(m r²).
                    *w += (2.5 * hm / (r * r)) * *t;
                    *x += *v * dt;
                    let v2 = v.length_squared();
                    if v2 > m {
                        m = v2;
                    }
                    check += (*v + *w + *x).element_sum();
                    if RESET {
                        reset_force(f, t, im, g, has_ext, ext_f, ext_t, base + k);
                    }
                }
                (m, check)
            })
            .reduce(|| (0.0, 0.0), |a, b| (a.0.max(b.0), a.1 + b.1));
        self.base_forces_ready = RESET;
        self.state_maybe_nonfinite |= !v2max.1.is_finite();
        v2max.0.sqrt()
    }

    /// Sets the spins of all single spheres to zero (rotation switched off; clump members take their
    /// spin from their body and keep it).
    pub(crate) fn clear_spins(&mut self) {
        let p = &mut self.particles;
        if self.st.bodies.is_empty() {
            p.omega.par_iter_mut().for_each(|w| *w = Vec3::ZERO);
        } else {
            for i in 0..p.len() {
                if !p.is_member(i) {
                    p.omega[i] = Vec3::ZERO;
                }
            }
        }
    }

    /// Fails with a blow-up error naming the first particle whose state is not finite (the kicks flag a
    /// non-finite state as they go; only then are the particles searched).
    pub(crate) fn check_finite(&mut self) -> Result<(), DemError> {
        if !std::mem::take(&mut self.state_maybe_nonfinite) {
            return Ok(());
        }
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
                cause: self.likely_cause(false),
            }),
        }
    }
}

/// Sets the force and torque of particle `i` to gravity `g` (m g = g/(1/m); none for a frozen particle) plus
/// its persistent external force and torque, if the run has any.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn reset_force(
    f: &mut Vec3,
    t: &mut Vec3,
    im: f64,
    g: Vec3,
    has_ext: bool,
    ext_f: &[Vec3],
    ext_t: &[Vec3],
    i: usize,
) {
    *f = if im > 0.0 { g / im } else { Vec3::ZERO };
    *t = Vec3::ZERO;
    if has_ext {
        *f += ext_f[i];
        *t += ext_t[i];
    }
}
