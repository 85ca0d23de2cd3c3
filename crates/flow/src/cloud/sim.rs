//! A dust cloud in a flow: a [`DustSource`] feeding a [`Tracker`] over a flat ground that keeps what
//! lands on it, with the mass balance entrained = airborne + redeposited + left the domain.

use super::source::DustSource;
use crate::field::FlowField;
use crate::forces::model::ForceModel;
use crate::tracker::walls::{Body, WallRule};
use crate::tracker::{TrackError, TrackSettings, Tracker};
use serde::Serialize;
use spatter_core::mesh::TriMesh;
use spatter_core::{Aabb, Vec3};

/// Where the entrained mass is \[kg\].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CloudBalance {
    /// Released by the source into the flow.
    pub entrained: f64,
    pub airborne: f64,
    /// Landed on the ground again.
    pub redeposited: f64,
    /// Left the domain.
    pub left: f64,
    /// Emitted by the source but not yet a whole parcel.
    pub pending: f64,
}

/// Source + tracker over a ground plane.
pub struct CloudSim<F: FlowField> {
    pub tracker: Tracker<F>,
    pub source: DustSource,
}

impl<F: FlowField> CloudSim<F> {
    /// The tracker over `field` with `model` and `settings` (its `domain` must be set: parcels leaving
    /// it are counted as left), and a ground body — two triangles covering the domain's footprint at the
    /// source's ground height — that keeps every parcel hitting it (redeposited).
    pub fn new(field: F, model: ForceModel, settings: TrackSettings, source: DustSource) -> Self {
        let z = source.centre.z;
        let b = settings.domain.unwrap_or(Aabb::new(Vec3::splat(-1e3), Vec3::splat(1e3)));
        let (x0, x1, y0, y1) = (b.min.x - 1.0, b.max.x + 1.0, b.min.y - 1.0, b.max.y + 1.0);
        let c = [Vec3::new(x0, y0, z), Vec3::new(x1, y0, z), Vec3::new(x1, y1, z), Vec3::new(x0, y1, z)];
        let ground = TriMesh::from_triangle_soup(&[c[0], c[1], c[2], c[0], c[2], c[3]]);
        let body = Body::new("ground", ground, WallRule::Trap);
        CloudSim { tracker: Tracker::new(field, model, settings, vec![body]), source }
    }

    /// Releases the parcels due over one step, then advances every parcel.
    pub fn step(&mut self) -> Result<(), TrackError> {
        let dt = self.tracker.settings.dt;
        let t = self.tracker.state.time;
        let field = &self.tracker.field;
        let mut new = Vec::new();
        self.source.release(
            dt,
            |x| {
                field
                    .sample(x, t, &mut crate::field::tetmesh::NONE.clone(), false)
                    .map(|s| s.u)
                    .unwrap_or(Vec3::ZERO)
            },
            |p| new.push(p),
        );
        for p in new {
            self.tracker.add(p, 0);
        }
        self.tracker.step()
    }

    /// The mass balance (the tracker's exact sums; `entrained` is the tracker's injected mass).
    pub fn balance(&self) -> CloudBalance {
        let b = &self.tracker.state.balance;
        CloudBalance {
            entrained: b.injected.value(),
            airborne: self.tracker.airborne_mass().value(),
            redeposited: b.deposited.value(),
            left: b.escaped.value(),
            pending: self.source.pending_mass(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::analytic::{AnalyticField, AnalyticSet};
    use crate::field::rotor::RotorDownwash;
    use crate::forces::model::ForceSwitches;
    use crate::forces::Fluid;

    #[test]
    fn bell47_cloud_balances_its_mass() {
        let rotor = RotorDownwash::bell47(0.68);
        let r0 = rotor.radius_m;
        let field = AnalyticSet { parts: vec![AnalyticField::Rotor(rotor)], turbulence: None };
        let fluid = Fluid { density: 1.19, viscosity: 1.82e-5 };
        let model = ForceModel::new(fluid, ForceSwitches::default());
        let domain = Aabb::new(Vec3::new(-2.0 * r0, -2.0 * r0, 0.0), Vec3::new(2.0 * r0, 2.0 * r0, r0));
        let settings = TrackSettings { dt: 2e-3, domain: Some(domain), ..Default::default() };
        // 20 and 300 µm grains from 0.5 R to 1.5 R, 1 g/s each.
        let edges = vec![0.5 * r0, r0, 1.5 * r0];
        let rates = vec![vec![5e-4, 5e-4], vec![5e-4, 5e-4]];
        let source = DustSource::new(Vec3::ZERO, edges, vec![20e-6, 300e-6], 2480.0, rates, 1e-6, 0.03, 11);
        let mut sim = CloudSim::new(field, model, settings, source);
        for _ in 0..400 {
            sim.step().unwrap();
        }
        let b = sim.balance();
        // Released by the source = handed to the tracker; emitted = released + pending (1 g/s·… for 0.8 s).
        assert!((b.entrained - sim.source.released).abs() < 1e-15);
        assert!((b.entrained + b.pending - 2e-3 * 0.8).abs() < 1e-12, "{b:?}");
        // The tracker's exact balance: entrained = airborne + redeposited + left, bit for bit.
        let (lhs, rhs) = sim.tracker.mass_balance();
        assert_eq!(lhs, rhs);
        // The heavy grains fall back, the fine ones stay up or leave: all three are non-zero.
        assert!(b.redeposited > 0.0 && b.airborne > 0.0, "{b:?}");
    }
}
