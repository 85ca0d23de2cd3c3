//! Simple closed triangle meshes for tests, examples and analytic bodies (normals point outwards).

use crate::math::orthonormal_basis;
use crate::mesh::TriMesh;
use crate::{Aabb, Vec3};

/// A closed cylinder (wheel, roller) of `radius` and `length` \[m\] centred at `center` with its axis
/// along `axis`, the mantle split into `segments` facets and `rings` bands along the axis.
pub fn cylinder(
    center: Vec3,
    axis: Vec3,
    radius: f64,
    length: f64,
    segments: usize,
    rings: usize,
) -> TriMesh {
    let a = axis.normalize_or_zero();
    let (u, v) = orthonormal_basis(a);
    let segments = segments.max(3);
    let rings = rings.max(1);
    let rim = |k: usize, s: f64| {
        let phi = std::f64::consts::TAU * (k % segments) as f64 / segments as f64;
        center + a * (s * length) + (u * phi.cos() + v * phi.sin()) * radius
    };
    let mut soup = Vec::with_capacity(segments * (6 * rings + 6));
    for k in 0..segments {
        for r in 0..rings {
            let s0 = -0.5 + r as f64 / rings as f64;
            let s1 = -0.5 + (r + 1) as f64 / rings as f64;
            let (p00, p10, p11, p01) = (rim(k, s0), rim(k + 1, s0), rim(k + 1, s1), rim(k, s1));
            soup.extend([p00, p10, p11, p00, p11, p01]);
        }
        // Caps: fans around the end centres.
        let (c0, c1) = (center - a * (0.5 * length), center + a * (0.5 * length));
        soup.extend([c0, rim(k + 1, -0.5), rim(k, -0.5)]);
        soup.extend([c1, rim(k, 0.5), rim(k + 1, 0.5)]);
    }
    TriMesh::from_triangle_soup(&soup)
}

/// The closed surface of an axis-aligned box, each face split into two triangles.
pub fn box_mesh(b: Aabb) -> TriMesh {
    let (lo, hi) = (b.min, b.max);
    let c = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    let quads: [[usize; 4]; 6] =
        [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
    let mut soup = Vec::with_capacity(36);
    for q in quads {
        let [p, r, s, t] = q.map(c);
        soup.extend([p, r, s, p, s, t]);
    }
    TriMesh::from_triangle_soup(&soup)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closed_with_outward_normals_and_the_right_volume() {
        let c = cylinder(Vec3::new(1.0, 2.0, 3.0), Vec3::Y, 0.5, 0.2, 256, 2);
        let exact = std::f64::consts::PI * 0.25 * 0.2;
        // A 256-gon has area (n/2) sin(2π/n) r², 0.01 % below the circle.
        assert!((c.signed_volume() - exact).abs() < 2e-4 * exact, "{}", c.signed_volume());
        assert!(c.topology().edge_use_count.iter().all(|&n| n == 2), "watertight");
        assert!(c.contains_point(Vec3::new(1.0, 2.05, 3.3)) && !c.contains_point(Vec3::new(1.0, 2.2, 3.0)));
        let b = box_mesh(Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0)));
        assert!((b.signed_volume() - 6.0).abs() < 1e-12);
        assert!(b.topology().edge_use_count.iter().all(|&n| n == 2));
    }
}
