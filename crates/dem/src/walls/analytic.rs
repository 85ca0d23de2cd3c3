//! Analytic wall shapes. Each `hit(x, reach)` returns the closest surface point, the unit normal from the
//! wall to `x`, and the distance, when the surface is closer than `reach`.

use serde::{Deserialize, Serialize};
use spatter_core::Vec3;

/// Infinite plane through `point` with unit `normal`; one-sided: the wall is the half-space behind it, so
/// a centre that crosses the plane reports a large overlap (and trips blow-up detection) instead of
/// passing through.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    pub point: Vec3,
    pub normal: Vec3,
}

impl Plane {
    /// A plane with the normal normalised.
    pub fn new(point: Vec3, normal: Vec3) -> Self {
        Plane { point, normal: normal.normalize() }
    }

    #[inline]
    pub fn hit(&self, x: Vec3, reach: f64) -> Option<(Vec3, Vec3, f64)> {
        let s = (x - self.point).dot(self.normal);
        (s < reach).then(|| (x - s * self.normal, self.normal, s))
    }
}

/// Finite rectangle `center ± a·half_u ± b·half_v`, |a|, |b| ≤ 1 (`half_u` ⟂ `half_v`); two-sided, with
/// edge and corner contacts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rectangle {
    pub center: Vec3,
    pub half_u: Vec3,
    pub half_v: Vec3,
}

impl Rectangle {
    #[inline]
    pub fn hit(&self, x: Vec3, reach: f64) -> Option<(Vec3, Vec3, f64)> {
        let d = x - self.center;
        let (lu, lv) = (self.half_u.length(), self.half_v.length());
        let (u, v) = (self.half_u / lu, self.half_v / lv);
        let a = d.dot(u).clamp(-lu, lu);
        let b = d.dot(v).clamp(-lv, lv);
        let q = self.center + a * u + b * v;
        let r = x - q;
        let dist = r.length();
        if dist >= reach {
            return None;
        }
        let n = if dist > 0.0 {
            r / dist
        } else {
            let n = u.cross(v);
            if d.dot(n) < 0.0 {
                -n
            } else {
                n
            }
        };
        Some((q, n, dist))
    }
}

/// Circular cylinder of `radius` about the axis through `point` along unit `axis`, between axial
/// coordinates `axial_min` and `axial_max` measured from `point` (±∞ for an infinite tube). With `inside`
/// the particles move inside the tube, otherwise outside a post. The ends are open.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cylinder {
    pub point: Vec3,
    pub axis: Vec3,
    pub radius: f64,
    pub inside: bool,
    pub axial_min: f64,
    pub axial_max: f64,
}

impl Cylinder {
    #[inline]
    pub fn hit(&self, x: Vec3, reach: f64) -> Option<(Vec3, Vec3, f64)> {
        let d = x - self.point;
        let h = d.dot(self.axis);
        if h < self.axial_min || h > self.axial_max {
            return None;
        }
        let rho = d - h * self.axis;
        let l = rho.length();
        let radial = if l > 0.0 {
            rho / l
        } else {
            // On the axis: any radial direction is as good.
            spatter_core::math::orthonormal_basis(self.axis).0
        };
        let q = self.point + h * self.axis + self.radius * radial;
        let (dist, n) = if self.inside { (self.radius - l, -radial) } else { (l - self.radius, radial) };
        (dist < reach).then_some((q, n, dist))
    }
}

/// Solid ball of `radius` about `center`; the particles move outside it (a spherical probe or
/// obstacle). Contact curvature is ignored as for every analytic wall (R* = particle radius).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ball {
    pub center: Vec3,
    pub radius: f64,
}

impl Ball {
    #[inline]
    pub fn hit(&self, x: Vec3, reach: f64) -> Option<(Vec3, Vec3, f64)> {
        let d = x - self.center;
        let l = d.length();
        // At the centre any direction is as good; +z keeps the choice deterministic.
        let n = if l > 0.0 { d / l } else { Vec3::Z };
        let dist = l - self.radius;
        (dist < reach).then_some((self.center + self.radius * n, n, dist))
    }
}

/// Solid circular cylinder with flat ends (a rod): the disc of `radius` about `base` perpendicular to
/// the unit `axis`, swept a `length` along the axis. The particles move outside it; its faces, rim
/// edges and side all make contact. A centre inside the rod reports a negative distance to the nearest
/// face (and so a large overlap that blow-up detection catches).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rod {
    pub base: Vec3,
    pub axis: Vec3,
    pub radius: f64,
    pub length: f64,
}

impl Rod {
    #[inline]
    pub fn hit(&self, x: Vec3, reach: f64) -> Option<(Vec3, Vec3, f64)> {
        let d = x - self.base;
        let h = d.dot(self.axis);
        let rho = d - h * self.axis;
        let l = rho.length();
        let radial = if l > 0.0 { rho / l } else { spatter_core::math::orthonormal_basis(self.axis).0 };
        let inside = h >= 0.0 && h <= self.length && l <= self.radius;
        if !inside {
            // Closest point of the solid: clamp the axial and radial coordinates.
            let q = self.base + h.clamp(0.0, self.length) * self.axis + l.min(self.radius) * radial;
            let r = x - q;
            let dist = r.length();
            if dist >= reach {
                return None;
            }
            return Some((q, r / dist, dist));
        }
        // Inside: leave through the nearest face.
        let (to_base, to_top, to_side) = (h, self.length - h, self.radius - l);
        let (q, n, depth) = if to_base <= to_top && to_base <= to_side {
            (x - h * self.axis, -self.axis, to_base)
        } else if to_top <= to_side {
            (x + to_top * self.axis, self.axis, to_top)
        } else {
            (self.base + h * self.axis + self.radius * radial, radial, to_side)
        };
        Some((q, n, -depth))
    }
}
