//! A dust source on an axisymmetric ground: annuli × size classes with mass rates, released as parcels.
//!
//! Each (annulus, size class) accumulates the mass it has emitted (rate × Δt). Whenever the accumulated
//! mass reaches one parcel's mass a parcel is released — at a uniformly random point of the annulus
//! (uniform in area) at `release_height` above the ground, with the fluid velocity there — and its mass
//! is taken off the account. The remainder carries over, so the mass handed to the tracker never exceeds
//! what the source has emitted by more than one parcel per account, and what has not yet been released
//! is reported ([`DustSource::pending_mass`]). The random stream is the source's own (seeded), so the
//! cloud is reproducible.

use super::classes::SizeClasses;
use crate::forces::sphere_mass;
use crate::liftoff::entrainment::{EntrainmentModel, GroundState, Threshold};
use crate::liftoff::ground_shear::GroundShear;
use crate::tracker::inject::NewParcel;
use serde::{Deserialize, Serialize};
use spatter_core::rng::{seeded, Rng, RngExt};
use spatter_core::Vec3;

/// The source.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DustSource {
    /// Ground point on the axis \[m\] (the ground is the horizontal plane through it).
    pub centre: Vec3,
    /// Annulus edges \[m\], increasing from the axis.
    pub edges: Vec<f64>,
    /// Grain diameters \[m\] of the classes and their density \[kg/m³\].
    pub diameters: Vec<f64>,
    pub density: f64,
    /// `rates[a][c]`: mass rate of annulus a, class c \[kg/s\].
    pub rates: Vec<Vec<f64>>,
    /// Mass of one parcel \[kg\].
    pub parcel_mass: f64,
    /// Release height above the ground \[m\].
    pub release_height: f64,
    /// Emitted but not yet released mass per account \[kg\].
    pending: Vec<Vec<f64>>,
    /// Mass released as parcels so far \[kg\].
    pub released: f64,
    rng: Rng,
}

/// Mass rates \[kg/s\] per annulus (between consecutive `edges`) and size class from an entrainment
/// model: the flux of each class at the ground state of the annulus (`ground[a]`, at its mid-radius)
/// with that class's threshold friction velocity, times the class's mass fraction of the bed, times the
/// annulus area.
#[allow(clippy::too_many_arguments)]
pub fn entrainment_rates(
    edges: &[f64],
    ground: &[GroundShear],
    reference_speed: &[f64],
    classes: &SizeClasses,
    model: &EntrainmentModel,
    threshold: &Threshold,
    (rho_p, rho_f, g): (f64, f64, f64),
) -> Vec<Vec<f64>> {
    edges
        .windows(2)
        .zip(ground.iter().zip(reference_speed))
        .map(|(w, (gs, &v))| {
            let area = std::f64::consts::PI * (w[1] * w[1] - w[0] * w[0]);
            let state = GroundState { u_star: gs.u_star, tau_w: gs.tau_w, reference_speed: v };
            classes
                .diameters
                .iter()
                .zip(&classes.mass_fractions)
                .map(|(&d, &frac)| {
                    let u_t = threshold.friction_velocity(d, rho_p, rho_f, g);
                    model.flux(&state, u_t, rho_f, g) * frac * area
                })
                .collect()
        })
        .collect()
}

impl DustSource {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        centre: Vec3,
        edges: Vec<f64>,
        diameters: Vec<f64>,
        density: f64,
        rates: Vec<Vec<f64>>,
        parcel_mass: f64,
        release_height: f64,
        seed: u64,
    ) -> Self {
        let pending = rates.iter().map(|r| vec![0.0; r.len()]).collect();
        DustSource {
            centre,
            edges,
            diameters,
            density,
            rates,
            parcel_mass,
            release_height,
            pending,
            released: 0.0,
            rng: seeded(seed, 0),
        }
    }

    /// Total mass rate \[kg/s\].
    pub fn total_rate(&self) -> f64 {
        self.rates.iter().flatten().sum()
    }

    /// Emitted mass not yet released as parcels \[kg\].
    pub fn pending_mass(&self) -> f64 {
        self.pending.iter().flatten().sum()
    }

    /// Emits `rate · dt` on every account and releases the parcels that became due; `fluid_velocity`
    /// gives the initial parcel velocity at a point.
    pub fn release(
        &mut self,
        dt: f64,
        fluid_velocity: impl Fn(Vec3) -> Vec3,
        mut out: impl FnMut(NewParcel),
    ) {
        for (a, rates) in self.rates.iter().enumerate() {
            let (r0, r1) = (self.edges[a], self.edges[a + 1]);
            for (c, &rate) in rates.iter().enumerate() {
                self.pending[a][c] += rate * dt;
                let d = self.diameters[c];
                let count = self.parcel_mass / sphere_mass(d, self.density);
                while self.pending[a][c] >= self.parcel_mass {
                    self.pending[a][c] -= self.parcel_mass;
                    let u: f64 = self.rng.random();
                    let r = (r0 * r0 + u * (r1 * r1 - r0 * r0)).sqrt();
                    let th = std::f64::consts::TAU * self.rng.random::<f64>();
                    let pos = self.centre + Vec3::new(r * th.cos(), r * th.sin(), self.release_height);
                    self.released += self.parcel_mass;
                    out(NewParcel {
                        pos,
                        vel: fluid_velocity(pos),
                        diameter: d,
                        density: self.density,
                        count,
                    });
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn released_mass_follows_the_rates() {
        // Two annuli, two classes; 1 s in 100 steps: released + pending = emitted exactly (to rounding).
        let rates = vec![vec![1e-3, 2e-3], vec![0.0, 5e-4]];
        let mut s = DustSource::new(
            Vec3::ZERO,
            vec![0.0, 1.0, 3.0],
            vec![50e-6, 200e-6],
            2480.0,
            rates,
            1e-6,
            0.01,
            3,
        );
        let mut n = 0;
        let mut inside = true;
        for _ in 0..100 {
            s.release(
                0.01,
                |_| Vec3::ZERO,
                |p| {
                    n += 1;
                    let r = p.pos.x.hypot(p.pos.y);
                    inside &= r <= 3.0 && (p.pos.z - 0.01).abs() < 1e-15;
                    assert!((p.count * sphere_mass(p.diameter, 2480.0) - 1e-6).abs() < 1e-18);
                },
            );
        }
        let emitted = 3.5e-3;
        assert!(
            (s.released + s.pending_mass() - emitted).abs() < 1e-15,
            "{} {}",
            s.released,
            s.pending_mass()
        );
        assert!(s.pending_mass() < 3.0 * 1e-6 && inside);
        assert!((n as f64 * 1e-6 - s.released).abs() < 1e-15);
    }
}
