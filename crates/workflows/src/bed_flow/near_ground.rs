//! The flow just above the bed: a friction velocity and a flow direction over the patch.
//!
//! A DEM patch is small (millimetres to centimetres) against the scales of the flow over it (a rotor
//! wall jet of metres), so the flow is described by its friction velocity u_* and the direction ê of the
//! ground-parallel flow at the patch centre. Within the bed's roughness layer the speed follows the
//! smooth-wall law of the wall u(y) = u_* u⁺(y u_*/ν) (Spalding's single formula: linear in the viscous
//! sublayer, u_*/κ ln(y u_*/ν) + B u_* above, κ = 0.41, B = 5.0; see `spatter_flow::liftoff::wall_law`),
//! the profile the lift-off analysis uses. Over the log layer this is the uniform shear flow
//! u(y) = (u_*/κ) ln(y/y₀) with the smooth-wall roughness length y₀ = (ν/u_*) e^(−κB).

use spatter_core::Vec3;
use spatter_flow::field::FlowField;
use spatter_flow::forces::Fluid;
use spatter_flow::liftoff::ground_shear::{ground_shear, GroundProbe, ShearMethod};

/// A flow over the patch: friction velocity \[m/s\] and unit ground-parallel direction at time `t` \[s\].
/// Must be a pure function of `t` (results are then the same for any thread count and across resumes).
pub trait GroundFlow: Send + Sync {
    fn shear(&self, t: f64) -> (f64, Vec3);
}

/// A steady uniform shear flow: friction velocity `u_star` \[m/s\] along `direction` (horizontal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UniformShear {
    pub u_star: f64,
    pub direction: Vec3,
}

impl GroundFlow for UniformShear {
    fn shear(&self, _t: f64) -> (f64, Vec3) {
        (self.u_star, Vec3::new(self.direction.x, self.direction.y, 0.0).normalize_or(Vec3::X))
    }
}

/// A tabulated flow: (u_*, ê) at the times k·`interval_s`, held constant until the next entry (the last
/// entry holds on). One entry is a steady flow.
#[derive(Clone, Debug, PartialEq)]
pub struct TabulatedShear {
    pub interval_s: f64,
    pub values: Vec<(f64, Vec3)>,
}

impl GroundFlow for TabulatedShear {
    fn shear(&self, t: f64) -> (f64, Vec3) {
        if self.values.is_empty() {
            return (0.0, Vec3::X);
        }
        let k = if self.interval_s > 0.0 { (t / self.interval_s).floor().max(0.0) as usize } else { 0 };
        self.values[k.min(self.values.len() - 1)]
    }
}

/// Any [`FlowField`] at a ground point: u_* from the log law at the wall-jet peak below `max_height`
/// (the ground-shear estimate of the lift-off analysis, times a gust factor), the direction from the
/// ground-parallel velocity at that peak.
pub struct FieldShear<'a, F: FlowField> {
    pub field: &'a F,
    /// Ground point under the patch centre \[m\] (ground plane z = `centre.z`, normal +z).
    pub centre: Vec3,
    pub max_height: f64,
    pub gust: f64,
    pub fluid: Fluid,
}

impl<F: FlowField> FieldShear<'_, F> {
    /// Friction velocity \[m/s\] and unit ground-parallel direction at time `t`.
    pub fn at(&self, t: f64) -> (f64, Vec3) {
        let probe = GroundProbe {
            origin: self.centre,
            direction: Vec3::X,
            distances: vec![0.0],
            method: ShearMethod::JetPeak { max_height: self.max_height, samples: 96 },
            gust: self.gust,
        };
        let g = ground_shear(self.field, &probe, t, &self.fluid);
        let (u_star, height) = g.first().map_or((0.0, self.max_height), |g| (g.u_star, g.height));
        let mut hint = spatter_flow::field::tetmesh::NONE;
        let dir = self
            .field
            .sample(self.centre + height * Vec3::Z, t, &mut hint, false)
            .map_or(Vec3::X, |s| Vec3::new(s.u.x, s.u.y, 0.0).normalize_or(Vec3::X));
        (u_star, dir)
    }

    /// The flow tabulated every `interval_s` over `duration_s` (one entry when `steady`).
    pub fn tabulate(&self, duration_s: f64, interval_s: f64, steady: bool) -> TabulatedShear {
        let n = if steady { 1 } else { (duration_s / interval_s).ceil() as usize + 1 };
        TabulatedShear { interval_s, values: (0..n).map(|k| self.at(k as f64 * interval_s)).collect() }
    }
}
