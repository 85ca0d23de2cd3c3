//! Axis-aligned bounding boxes.

use crate::Vec3;
use serde::{Deserialize, Serialize};

/// An axis-aligned box `[min, max]` \[m\].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    /// The empty box: contains nothing, and growing it by a point gives that point.
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f64::INFINITY), max: Vec3::splat(f64::NEG_INFINITY) };

    pub fn new(min: Vec3, max: Vec3) -> Self {
        Aabb { min, max }
    }

    /// Smallest box holding every point (the empty box for no points).
    pub fn from_points<'a>(points: impl IntoIterator<Item = &'a Vec3>) -> Self {
        points.into_iter().fold(Self::EMPTY, |b, p| b.grown_to(*p))
    }

    pub fn grown_to(self, p: Vec3) -> Self {
        Aabb { min: self.min.min(p), max: self.max.max(p) }
    }

    pub fn union(self, o: Aabb) -> Self {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    /// The box enlarged by `margin` on every side.
    pub fn inflated(self, margin: f64) -> Self {
        Aabb { min: self.min - Vec3::splat(margin), max: self.max + Vec3::splat(margin) }
    }

    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    pub fn contains(&self, p: Vec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }

    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    pub fn volume(&self) -> f64 {
        if self.is_empty() {
            0.0
        } else {
            let e = self.extent();
            e.x * e.y * e.z
        }
    }

    /// Euclidean distance to the box `o` (0 when they touch or overlap) \[m\]. An infinite face (the
    /// outer boxes of a domain split over ranks) never adds: its gap of −∞ is clamped to 0.
    pub fn gap(&self, o: &Aabb) -> f64 {
        let mut d2 = 0.0;
        for axis in 0..3 {
            let gap = (self.min[axis] - o.max[axis]).max(o.min[axis] - self.max[axis]).max(0.0);
            if gap.is_finite() {
                d2 += gap * gap;
            }
        }
        d2.sqrt()
    }
}
