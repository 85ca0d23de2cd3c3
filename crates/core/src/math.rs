//! Vector types and small geometric helpers. All quantities are `f64` in SI units.

pub use glam::{DMat3 as Mat3, DQuat as Quat, DVec3 as Vec3};

/// Two unit vectors `(t1, t2)` that complete `n` (assumed unit length) to a right-handed orthonormal basis.
///
/// Branch-free construction of Duff et al. (2017), "Building an orthonormal basis, revisited", JCGT 6(1).
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0_f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    let t1 = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
    let t2 = Vec3::new(b, sign + n.y * n.y * a, -n.y);
    (t1, t2)
}

/// Volume of a sphere of radius `r` \[m³\].
pub fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * r * r * r
}

/// True when every component of `v` is finite.
pub fn is_finite(v: Vec3) -> bool {
    v.x.is_finite() && v.y.is_finite() && v.z.is_finite()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal_for_many_normals() {
        for n in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::Z, Vec3::new(1.0, 2.0, -3.0).normalize()] {
            let (t1, t2) = orthonormal_basis(n);
            assert!((t1.length() - 1.0).abs() < 1e-14);
            assert!((t2.length() - 1.0).abs() < 1e-14);
            assert!(t1.dot(n).abs() < 1e-14 && t2.dot(n).abs() < 1e-14 && t1.dot(t2).abs() < 1e-14);
            assert!((t1.cross(t2) - n).length() < 1e-14, "right-handed");
        }
    }
}
