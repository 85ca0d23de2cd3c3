//! Wall impacts of the last force evaluation, for event logs: every particle–wall contact that formed in
//! it (the same event that counts `impacts` on a mesh triangle and triggers wear), with the contact
//! point, the wall normal and the particle's velocity relative to the wall at first touch.
//!
//! Recording is off by default ([`super::Simulation::set_impact_recording`]); when on, the events are
//! collected in the sequential pass over the wall contacts that also keeps the mesh records, in particle
//! order, so they are the same for any thread count. They describe one evaluation and are not
//! checkpointed: a caller that keeps a log reads them after every step.

use crate::walls::{Wall, WallKinematics, WallShape};
use spatter_core::mesh::closest_point_on_triangle;
use spatter_core::Vec3;

/// One particle–wall contact that formed in the last force evaluation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallImpact {
    /// Stable id of the particle (for a clump, the member sphere that touched).
    pub particle: u32,
    /// Stable id of the particle's rigid body, `None` for a free sphere.
    pub body: Option<u32>,
    /// Index of the wall.
    pub wall: usize,
    /// Triangle of a mesh wall, `None` for an analytic wall.
    pub triangle: Option<u32>,
    /// Time of the evaluation \[s\].
    pub time: f64,
    /// Unit wall normal at the contact, pointing towards the particle.
    pub normal: Vec3,
    /// Velocity of the particle centre relative to the wall's material point at the contact \[m/s\] —
    /// under velocity Verlet the half-step velocity the contact force saw, before any deceleration.
    pub velocity: Vec3,
}

impl WallImpact {
    /// Impact speed |v| \[m/s\].
    pub fn speed(&self) -> f64 {
        self.velocity.length()
    }

    /// Angle between the velocity and the wall plane \[deg\] (90° for a normal impact).
    pub fn angle_deg(&self) -> f64 {
        let v_n = -self.velocity.dot(self.normal);
        let v_t = (self.velocity + v_n * self.normal).length();
        v_n.max(0.0).atan2(v_t).to_degrees()
    }

    /// The impact angle seen in the plane with unit normal `m` \[deg\]: the angle between the velocity
    /// projected onto that plane and the trace of the wall in it (the projected wall normal gives the
    /// direction across the trace). NaN when the velocity or the wall normal is perpendicular to the
    /// plane (no angle in it).
    pub fn angle_in_plane_deg(&self, m: Vec3) -> f64 {
        let v = self.velocity - self.velocity.dot(m) * m;
        let n = self.normal - self.normal.dot(m) * m;
        let (lv, ln) = (v.length(), n.length());
        if lv < 1e-12 * self.velocity.length().max(f64::MIN_POSITIVE) || ln < 1e-12 {
            return f64::NAN;
        }
        (-v.dot(n) / (lv * ln)).clamp(-1.0, 1.0).asin().to_degrees()
    }
}

/// The normal and the wall velocity at the contact of a sphere centred at `x` with wall `wall` (triangle
/// `tri` of a mesh) placed by `kin`, computed as the contact detection does.
pub(crate) fn contact_frame(wall: &Wall, kin: &WallKinematics, tri: u32, x: Vec3) -> (Vec3, Vec3) {
    let x_ref = kin.to_reference(x);
    let (point_ref, normal_ref) = match &wall.shape {
        WallShape::Mesh(m) => {
            let [a, b, c] = m.mesh.corners(tri as usize);
            let (q, _) = closest_point_on_triangle(x_ref, a, b, c);
            let d = x_ref - q;
            let n = if d.length_squared() > 0.0 { d.normalize() } else { m.mesh.normal(tri as usize) };
            (q, n)
        }
        _ => match wall.analytic_hit(x_ref, f64::INFINITY) {
            Some((p, n, _)) => (p, n),
            None => (x_ref, Vec3::ZERO),
        },
    };
    let hit = kin.hit_to_world(point_ref, normal_ref, 0.0);
    (hit.normal, kin.velocity_at(hit.point))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn impact(velocity: Vec3, normal: Vec3) -> WallImpact {
        WallImpact { particle: 0, body: None, wall: 0, triangle: None, time: 0.0, normal, velocity }
    }

    /// Angles of impacts on the floor z = 0: normal 90°, 45° downwards at 45°, grazing 0°. The impact
    /// v = (0.5, 0.5, −0.5) is atan(0.5/√0.5) = 35.26° to the floor in space, and 45° when seen in the
    /// x–z plane (normal y) or the y–z plane (normal x); in the floor's own plane it has no angle.
    #[test]
    fn impact_angles_in_space_and_in_a_plane() {
        let z = Vec3::Z;
        assert!((impact(Vec3::new(0.0, 0.0, -2.0), z).angle_deg() - 90.0).abs() < 1e-12);
        assert!((impact(Vec3::new(1.0, 0.0, -1.0), z).angle_deg() - 45.0).abs() < 1e-12);
        assert!(impact(Vec3::new(1.0, 0.0, 0.0), z).angle_deg().abs() < 1e-12);
        let v = Vec3::new(0.5, 0.5, -0.5);
        let i = impact(v, z);
        assert!((i.angle_deg() - (0.5f64 / 0.5f64.hypot(0.5)).atan().to_degrees()).abs() < 1e-12);
        assert!((i.angle_deg() - 35.264389682754654).abs() < 1e-9);
        assert!((i.angle_in_plane_deg(Vec3::Y) - 45.0).abs() < 1e-12);
        // Seen in the y–z plane the same impact is also 45°; in the x–y plane (the wall's own plane
        // contains no normal component) there is no angle.
        assert!((i.angle_in_plane_deg(Vec3::X) - 45.0).abs() < 1e-12);
        assert!(i.angle_in_plane_deg(Vec3::Z).is_nan());
        // Leaving the wall gives a negative angle.
        assert!(impact(Vec3::new(1.0, 0.0, 1.0), z).angle_in_plane_deg(Vec3::Y) < 0.0);
    }
}
