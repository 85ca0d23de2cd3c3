//! Mass properties of a union of spheres: volume, centre of mass, inertia tensor, principal axes.
//!
//! * **No two members overlap** (tight fills of equal spheres, most generated templates): exact sums of
//!   the sphere volumes and of their inertia about the common centre of mass (parallel-axis theorem).
//! * **Overlapping members**: the union is integrated along lines parallel to x, exactly along each line
//!   (the union of the sphere chords), and by the midpoint rule over a (y, z) grid of the lines. The
//!   spacing is `radius_min / 32` (at most [`MAX_POINTS`] lines; the spacing grows if needed), and the
//!   integral is repeated at twice the spacing; the relative difference of the two (volume and trace of
//!   the inertia, the larger) is reported as [`MassProperties::error_estimate`]. The error falls at
//!   least as h^{3/2} (the chord length has a square-root edge at the silhouette), so the estimate bounds
//!   the error of the finer integral in practice (tested against the exact union of two overlapping
//!   spheres: error 2.8·10⁻⁴, estimate 3.1·10⁻³).
//!
//! The tensor is diagonalised by cyclic Jacobi rotations (Golub & Van Loan, *Matrix Computations*, §8.5)
//! — hand-written because a 3 × 3 symmetric matrix is all the engine needs and a linear-algebra crate for
//! it would be a large dependency. Principal moments are sorted ascending, axes form a right-handed frame.

use spatter_core::math::sphere_volume;
use spatter_core::{Mat3, Quat, Vec3};

/// Largest number of grid points of one voxel integration.
pub const MAX_POINTS: usize = 8_000_000;

/// Mass properties per unit density of a set of spheres (multiply by ρ for kg).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// Volume of the union \[m³\].
    pub volume: f64,
    /// Centre of volume (= centre of mass for uniform density) \[m\].
    pub center: Vec3,
    /// Inertia tensor per unit density about `center` \[m⁵\].
    pub tensor: Mat3,
    /// Principal moments per unit density, ascending \[m⁵\].
    pub principal: Vec3,
    /// Rotation from the principal frame to the input frame (columns = principal axes).
    pub axes: Quat,
    /// Relative error estimate of the integration (0 when exact).
    pub error_estimate: f64,
}

/// Whether any two spheres overlap (touching is not overlapping).
pub fn any_overlap(spheres: &[(Vec3, f64)]) -> bool {
    for (a, &(ca, ra)) in spheres.iter().enumerate() {
        for &(cb, rb) in &spheres[a + 1..] {
            let s = ra + rb;
            if (ca - cb).length_squared() < s * s * (1.0 - 1e-12) {
                return true;
            }
        }
    }
    false
}

/// Mass properties per unit density of the union of `spheres` (centre \[m\], radius \[m\]); exact when no
/// two overlap, else by voxel integration (module docs). `spheres` must not be empty.
pub fn of_spheres(spheres: &[(Vec3, f64)]) -> MassProperties {
    assert!(!spheres.is_empty(), "mass properties of an empty sphere set");
    let (volume, center, tensor, error) = if any_overlap(spheres) {
        let r_min = spheres.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
        let fine = voxel(spheres, r_min / 32.0);
        let coarse = voxel(spheres, 2.0 * fine.3);
        let dv = ((fine.0 - coarse.0) / fine.0).abs();
        let tr = |m: &Mat3| m.x_axis.x + m.y_axis.y + m.z_axis.z;
        let di = ((tr(&fine.2) - tr(&coarse.2)) / tr(&fine.2)).abs();
        (fine.0, fine.1, fine.2, dv.max(di))
    } else {
        let (v, c, t) = exact_disjoint(spheres);
        (v, c, t, 0.0)
    };
    let (principal, axes) = principal_axes(&tensor);
    MassProperties { volume, center, tensor, principal, axes, error_estimate: error }
}

/// Exact volume, centre and inertia tensor per unit density of disjoint spheres.
fn exact_disjoint(spheres: &[(Vec3, f64)]) -> (f64, Vec3, Mat3) {
    let volume: f64 = spheres.iter().map(|s| sphere_volume(s.1)).sum();
    let center = spheres.iter().map(|s| sphere_volume(s.1) * s.0).sum::<Vec3>() / volume;
    let mut t = Mat3::ZERO;
    for &(c, r) in spheres {
        let v = sphere_volume(r);
        let d = c - center;
        // Own inertia (2/5) V r² plus the parallel-axis term V (|d|² 1 − d dᵀ).
        t += Mat3::from_diagonal(Vec3::splat(0.4 * v * r * r + v * d.length_squared())) - v * outer(d, d);
    }
    (volume, center, t)
}

fn outer(a: Vec3, b: Vec3) -> Mat3 {
    Mat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Integration of the union on lines along x through the centres of a (y, z) grid of spacing `h`
/// (enlarged so that at most [`MAX_POINTS`] lines are used): along each line the union of the sphere
/// chords is integrated exactly, across the lines by the midpoint rule (each line stands for an h × h
/// cell, whose own second moment h²/12 about y and z is added). Returns volume, centre, tensor and the
/// spacing used.
fn voxel(spheres: &[(Vec3, f64)], h: f64) -> (f64, Vec3, Mat3, f64) {
    let mut lo = Vec3::splat(f64::INFINITY);
    let mut hi = Vec3::splat(f64::NEG_INFINITY);
    for &(c, r) in spheres {
        lo = lo.min(c - Vec3::splat(r));
        hi = hi.max(c + Vec3::splat(r));
    }
    let ext = hi - lo;
    let mut h = h;
    while (ext.y / h).ceil() * (ext.z / h).ceil() > MAX_POINTS as f64 {
        h *= 1.25;
    }
    let (ny, nz) = ((ext.y / h).ceil() as usize, (ext.z / h).ceil() as usize);
    let mid = 0.5 * (lo + hi);
    let (y0, z0) = (mid.y - 0.5 * h * ny as f64, mid.z - 0.5 * h * nz as f64);
    let da = h * h;
    // Raw moments about the box centre: Σ 1, Σ x, Σ x xᵀ.
    let mut m0 = 0.0;
    let mut m1 = Vec3::ZERO;
    let mut m2 = Mat3::ZERO;
    let mut chords: Vec<(f64, f64)> = Vec::with_capacity(spheres.len());
    for k in 0..nz {
        let z = z0 + (k as f64 + 0.5) * h;
        for j in 0..ny {
            let y = y0 + (j as f64 + 0.5) * h;
            chords.clear();
            for &(c, r) in spheres {
                let s2 = r * r - (y - c.y).powi(2) - (z - c.z).powi(2);
                if s2 > 0.0 {
                    let s = s2.sqrt();
                    chords.push((c.x - s - mid.x, c.x + s - mid.x));
                }
            }
            if chords.is_empty() {
                continue;
            }
            chords.sort_by(|a, b| a.0.total_cmp(&b.0));
            // ∫ 1, ∫ x, ∫ x² over the union of the chords.
            let (mut l0, mut l1, mut l2) = (0.0, 0.0, 0.0);
            let (mut a, mut b) = chords[0];
            let mut add = |a: f64, b: f64| {
                l0 += b - a;
                l1 += 0.5 * (b * b - a * a);
                l2 += (b * b * b - a * a * a) / 3.0;
            };
            for &(ca, cb) in &chords[1..] {
                if ca > b {
                    add(a, b);
                    (a, b) = (ca, cb);
                } else {
                    b = b.max(cb);
                }
            }
            add(a, b);
            let (dy, dz) = (y - mid.y, z - mid.z);
            m0 += l0;
            m1 += Vec3::new(l1, dy * l0, dz * l0);
            let c = h * h / 12.0;
            m2 += Mat3::from_cols(
                Vec3::new(l2, dy * l1, dz * l1),
                Vec3::new(dy * l1, (dy * dy + c) * l0, dy * dz * l0),
                Vec3::new(dz * l1, dy * dz * l0, (dz * dz + c) * l0),
            );
        }
    }
    let volume = m0 * da;
    let cm = m1 / m0;
    let cov = (m2 - m0 * outer(cm, cm)) * da;
    let tr = cov.x_axis.x + cov.y_axis.y + cov.z_axis.z;
    let tensor = Mat3::from_diagonal(Vec3::splat(tr)) - cov;
    (volume, mid + cm, tensor, h)
}

/// Eigen-decomposition of a symmetric 3 × 3 matrix: eigenvalues ascending and the rotation whose columns
/// are the eigenvectors (right-handed).
pub fn principal_axes(t: &Mat3) -> (Vec3, Quat) {
    let mut a = [[0.0; 3]; 3];
    for (r, row) in a.iter_mut().enumerate() {
        for (c, v) in row.iter_mut().enumerate() {
            *v = 0.5 * (t.col(c)[r] + t.col(r)[c]);
        }
    }
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let scale = (0..3).map(|k| a[k][k].abs()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    for _sweep in 0..64 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        if off <= 1e-17 * scale {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() <= 1e-300 {
                continue;
            }
            // Rotation that zeroes a[p][q] (Golub & Van Loan, Algorithm 8.5.1).
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let tt = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let tt = if theta == 0.0 { 1.0 } else { tt };
            let c = 1.0 / (tt * tt + 1.0).sqrt();
            let s = tt * c;
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (rp, rq) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * rp[k] - s * rq[k];
                a[q][k] = s * rp[k] + c * rq[k];
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let mut order = [0usize, 1, 2];
    order.sort_by(|&x, &y| a[x][x].total_cmp(&a[y][y]));
    let col = |k: usize| Vec3::new(v[0][k], v[1][k], v[2][k]);
    let (e0, e1) = (col(order[0]).normalize(), col(order[1]).normalize());
    let e2 = e0.cross(e1).normalize();
    let e1 = e2.cross(e0);
    let values = Vec3::new(a[order[0]][order[0]], a[order[1]][order[1]], a[order[2]][order[2]]);
    (values, Quat::from_mat3(&Mat3::from_cols(e0, e1, e2)).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn one_sphere_is_exact() {
        let p = of_spheres(&[(Vec3::new(1.0, 2.0, 3.0), 0.5)]);
        assert_eq!(p.error_estimate, 0.0);
        assert!((p.volume - 4.0 / 3.0 * PI * 0.125).abs() < 1e-15);
        assert!((p.center - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-15);
        // I = (2/5) V r² per unit density.
        let i = 0.4 * p.volume * 0.25;
        assert!((p.principal - Vec3::splat(i)).abs().max_element() < 1e-15);
    }

    /// Two touching spheres (a dumbbell): I about the axis = 2 (2/5) V r², about a perpendicular axis
    /// through the centre = 2 ((2/5) V r² + V r²).
    #[test]
    fn touching_dumbbell_is_exact_with_the_axis_as_smallest_moment() {
        let r = 0.1;
        let p = of_spheres(&[(Vec3::new(0.0, -r, 0.0), r), (Vec3::new(0.0, r, 0.0), r)]);
        assert_eq!(p.error_estimate, 0.0);
        let v = sphere_volume(r);
        let ia = 2.0 * 0.4 * v * r * r;
        let ip = 2.0 * (0.4 * v * r * r + v * r * r);
        assert!((p.principal - Vec3::new(ia, ip, ip)).abs().max_element() < 1e-14 * ip);
        // The smallest axis is y.
        let e0 = p.axes * Vec3::X;
        assert!(e0.y.abs() > 1.0 - 1e-12);
    }

    /// Two overlapping spheres of radius r at distance d: the union volume is 2V − lens, lens =
    /// π (4r + d)(2r − d)²/12 (sphere–sphere intersection, e.g. Weisstein, MathWorld "Sphere-Sphere
    /// Intersection"). The voxel integral must agree within its stated error estimate.
    #[test]
    fn overlapping_spheres_voxel_volume_within_the_stated_error() {
        let (r, d) = (1.0, 1.0);
        let p = of_spheres(&[(Vec3::ZERO, r), (Vec3::new(d, 0.0, 0.0), r)]);
        let lens = PI * (4.0 * r + d) * (2.0 * r - d).powi(2) / 12.0;
        let exact = 2.0 * sphere_volume(r) - lens;
        let err = ((p.volume - exact) / exact).abs();
        assert!(p.error_estimate > 0.0);
        assert!(err < p.error_estimate.max(1e-4), "error {err:e}, estimate {:e}", p.error_estimate);
        // Measured 2.8e-4 at r/32 (estimate 3.1e-3).
        assert!(err < 5e-4, "error {err:e}");
        assert!((p.center.x - 0.5).abs() < 1e-9, "symmetric: {:?}", p.center);
    }

    #[test]
    fn jacobi_diagonalises_a_rotated_diagonal_tensor() {
        let rot = Quat::from_rotation_z(0.7) * Quat::from_rotation_x(-0.4);
        let m = Mat3::from_quat(rot);
        let d = Mat3::from_diagonal(Vec3::new(3.0, 1.0, 2.0));
        let t = m * d * m.transpose();
        let (vals, axes) = principal_axes(&t);
        assert!((vals - Vec3::new(1.0, 2.0, 3.0)).abs().max_element() < 1e-13);
        let back = Mat3::from_quat(axes).transpose() * t * Mat3::from_quat(axes);
        assert!((back - Mat3::from_diagonal(vals)).abs().to_cols_array().iter().all(|x| *x < 1e-13));
        assert!((Mat3::from_quat(axes).determinant() - 1.0).abs() < 1e-13);
    }
}
