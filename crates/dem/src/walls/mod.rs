//! Walls: geometry + material + prescribed motion.
//!
//! * [`Plane`] — infinite, one-sided (particles live on the side its normal points to);
//! * [`Rectangle`] — a finite flat plate, two-sided, with edges and corners;
//! * [`Cylinder`] — particles inside a tube or outside a post, optionally bounded along the axis (open
//!   ends);
//! * [`Ball`] and [`Rod`] — solid bodies the particles stay outside of (a sphere; a cylinder with flat
//!   ends): probes and obstacles;
//! * [`MeshWall`] — a triangle mesh (STL/OBJ) with face/edge/vertex contacts counted once
//!   ([`mesh`]) and per-triangle impact records.
//!
//! Each wall is defined in its *reference frame* (its position at t = 0) and moves by a
//! [`Motion`](spatter_core::motion::Motion): the engine maps a particle into the reference frame with the
//! wall's current pose, finds the contact there, and maps point and normal back. The wall velocity at the
//! contact point, v_c + ω × (q − c), enters the relative velocity. Contact curvature of analytic walls is
//! ignored (R* = particle radius, as in LIGGGHTS `fix wall/gran`).

mod analytic;
pub mod mesh;

pub use analytic::{Ball, Cylinder, Plane, Rectangle, Rod};
pub use mesh::{MeshRecords, MeshWall};

use spatter_core::motion::{Motion, Pose};
use spatter_core::Vec3;

/// Geometry of a wall in its reference frame.
#[derive(Clone, Debug)]
pub enum WallShape {
    Plane(Plane),
    Rectangle(Rectangle),
    Cylinder(Cylinder),
    Ball(Ball),
    Rod(Rod),
    Mesh(Box<MeshWall>),
}

/// A wall: geometry, material index and motion.
#[derive(Clone, Debug)]
pub struct Wall {
    /// Name used in outputs (mesh VTU file names).
    pub name: String,
    pub shape: WallShape,
    /// Material index into the simulation's material list.
    pub material: u16,
    pub motion: Motion,
}

/// A contact point found on a wall, in world coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallHit {
    /// Contact point on the wall surface \[m\].
    pub point: Vec3,
    /// Unit normal from the wall to the particle centre.
    pub normal: Vec3,
    /// Distance from the particle centre to the wall surface \[m\] (overlap δ = r − distance).
    pub distance: f64,
}

/// A wall's placement and velocity at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallKinematics {
    pub pose: Pose,
    /// Velocity of the pose's reference point \[m/s\].
    pub v_center: Vec3,
    /// Angular velocity \[rad/s\].
    pub omega: Vec3,
    /// The wall never moves (identity pose, zero velocity): the transforms are skipped.
    pub fixed: bool,
}

impl WallKinematics {
    pub const FIXED: WallKinematics =
        WallKinematics { pose: Pose::IDENTITY, v_center: Vec3::ZERO, omega: Vec3::ZERO, fixed: true };

    /// Kinematics of `motion` at time `t` \[s\].
    pub fn of(motion: &Motion, t: f64) -> Self {
        if let Motion::Fixed = motion {
            return Self::FIXED;
        }
        let pose = motion.pose(t);
        WallKinematics {
            pose,
            v_center: motion.velocity_at(t, pose.center()),
            omega: motion.angular_velocity(t),
            fixed: false,
        }
    }

    /// Velocity of the wall's material point at world position `x` \[m/s\].
    #[inline]
    pub fn velocity_at(&self, x: Vec3) -> Vec3 {
        if self.fixed {
            return Vec3::ZERO;
        }
        self.v_center + self.omega.cross(x - self.pose.center())
    }

    /// Maps a world point into the wall's reference frame.
    #[inline]
    pub fn to_reference(&self, x: Vec3) -> Vec3 {
        if self.fixed {
            return x;
        }
        self.pose.inverse_apply(x)
    }

    /// Maps a reference-frame hit to world coordinates.
    #[inline]
    pub fn hit_to_world(&self, point_ref: Vec3, normal_ref: Vec3, distance: f64) -> WallHit {
        if self.fixed {
            return WallHit { point: point_ref, normal: normal_ref, distance };
        }
        WallHit { point: self.pose.apply(point_ref), normal: self.pose.rotation * normal_ref, distance }
    }

    /// Upper bound of the speed of any wall point within `extent` \[m\] of the reference point.
    pub fn max_speed(&self, extent: f64) -> f64 {
        self.v_center.length() + self.omega.length() * extent
    }
}

impl Wall {
    /// Largest distance of the wall's (bounded) geometry from its motion's reference point, used to bound
    /// wall speeds; infinite walls report the distance to their defining point plus `fallback`.
    pub fn extent(&self, fallback: f64) -> f64 {
        let center = self.motion.pose(0.0).center();
        match &self.shape {
            WallShape::Plane(p) => (p.point - center).length() + fallback,
            WallShape::Rectangle(r) => (r.center - center).length() + r.half_u.length() + r.half_v.length(),
            WallShape::Cylinder(c) => (c.point - center).length() + c.radius + fallback,
            WallShape::Ball(b) => (b.center - center).length() + b.radius,
            WallShape::Rod(r) => (r.base - center).length() + r.length + r.radius,
            WallShape::Mesh(m) => m.mesh.vertices.iter().map(|v| (*v - center).length()).fold(0.0, f64::max),
        }
    }

    /// Distance from world position `x` to the wall surface with the wall placed by `kin`, if it is less
    /// than `reach` \[m\] (a sphere of radius r centred at `x` overlaps the wall by r − distance when
    /// the distance is below r). Behind a one-sided plane, outside a containing cylinder or inside a post
    /// the distance is negative. Used by insertion and diagnostics, not by the force loop.
    pub fn surface_distance(&self, kin: &WallKinematics, x: Vec3, reach: f64) -> Option<f64> {
        let x_ref = kin.to_reference(x);
        match &self.shape {
            WallShape::Mesh(m) => {
                m.bvh.closest_point(&m.mesh, x_ref, reach).map(|h| h.distance).filter(|d| *d < reach)
            }
            _ => self.analytic_hit(x_ref, reach).map(|h| h.2),
        }
    }

    /// The contact of a sphere at reference-frame position `x` with an analytic wall, if the surface is
    /// closer than `reach` \[m\] (meshes are handled by [`MeshWall::resolve`]).
    #[inline(always)]
    pub fn analytic_hit(&self, x: Vec3, reach: f64) -> Option<(Vec3, Vec3, f64)> {
        match &self.shape {
            WallShape::Plane(p) => p.hit(x, reach),
            WallShape::Rectangle(r) => r.hit(x, reach),
            WallShape::Cylinder(c) => c.hit(x, reach),
            WallShape::Ball(b) => b.hit(x, reach),
            WallShape::Rod(r) => r.hit(x, reach),
            WallShape::Mesh(_) => None,
        }
    }
}

#[cfg(test)]
mod tests;
