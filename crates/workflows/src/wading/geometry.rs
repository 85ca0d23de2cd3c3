//! Surfaces generated for a wading run: the channel's road and side walls as triangle meshes, and an
//! ASCII STL writer for them and for the placed vehicle parts (written to the run folder, where they are
//! both the engine's input and a picture of the set-up for ParaView).

use super::channel::ChannelSpec;
use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;
use std::io::Write;
use std::path::Path;

/// The road surface: one strip across the channel per segment of the profile, normals up.
pub fn road_mesh(c: &ChannelSpec) -> TriMesh {
    let w = 0.5 * c.width_m;
    let mut soup = Vec::new();
    for s in c.profile().windows(2) {
        let ((x0, z0), (x1, z1)) = (s[0], s[1]);
        if x1 <= x0 {
            continue;
        }
        let a = Vec3::new(x0, -w, z0);
        let b = Vec3::new(x1, -w, z1);
        let cc = Vec3::new(x1, w, z1);
        let d = Vec3::new(x0, w, z0);
        soup.extend([a, b, cc, a, cc, d]);
    }
    TriMesh::from_triangle_soup(&soup)
}

/// The two side walls, from the road up to `wall_height_m` above the road level (z = 0), normals facing
/// into the channel.
pub fn side_walls_mesh(c: &ChannelSpec) -> TriMesh {
    let w = 0.5 * c.width_m;
    let top = c.wall_height_m;
    let mut soup = Vec::new();
    for s in c.profile().windows(2) {
        let ((x0, z0), (x1, z1)) = (s[0], s[1]);
        if x1 <= x0 {
            continue;
        }
        // +y wall, normal −y.
        let (a, b, cc, d) =
            (Vec3::new(x0, w, z0), Vec3::new(x1, w, z1), Vec3::new(x1, w, top), Vec3::new(x0, w, top));
        soup.extend([a, b, cc, a, cc, d]);
        // −y wall, normal +y (reversed winding).
        let (a, b, cc, d) =
            (Vec3::new(x0, -w, z0), Vec3::new(x1, -w, z1), Vec3::new(x1, -w, top), Vec3::new(x0, -w, top));
        soup.extend([a, cc, b, a, d, cc]);
    }
    TriMesh::from_triangle_soup(&soup)
}

/// Writes `mesh` as an ASCII STL solid called `name`. Coordinates are written with Rust's shortest
/// round-trip formatting, so reading the file back gives the same numbers.
pub fn write_stl(path: &Path, name: &str, mesh: &TriMesh) -> std::io::Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(out, "solid {name}")?;
    for t in 0..mesh.triangles.len() {
        let [a, b, c] = mesh.corners(t);
        let n = (b - a).cross(c - a).normalize_or_zero();
        writeln!(out, "facet normal {} {} {}\n outer loop", n.x, n.y, n.z)?;
        for v in [a, b, c] {
            writeln!(out, "  vertex {} {} {}", v.x, v.y, v.z)?;
        }
        writeln!(out, " endloop\nendfacet")?;
    }
    writeln!(out, "endsolid {name}")?;
    out.flush()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wading::channel::tests::channel;

    /// The road's area is the width times the profile's length; its normals point up; the walls' normals
    /// point into the channel and their area is twice ∫ (top − road) dx.
    #[test]
    fn channel_surfaces_face_the_water() {
        let c = channel();
        let road = road_mesh(&c);
        let ramp = (3.0f64 * 3.0 + 0.25).sqrt();
        let area: f64 = (0..road.triangles.len()).map(|t| road.area(t)).sum();
        assert!((area - 4.0 * (4.0 + 6.0 + 2.0 + 2.0 * ramp)).abs() < 1e-9, "{area}");
        for t in 0..road.triangles.len() {
            assert!(road.normal(t).z > 0.9, "road triangle {t} faces down");
        }
        let walls = side_walls_mesh(&c);
        let area: f64 = (0..walls.triangles.len()).map(|t| walls.area(t)).sum();
        // ∫ (1 − road) dx = 18 + 0.5 · (6 + 3) (the pool floor and half of each ramp).
        assert!((area - 2.0 * (18.0 + 0.5 * 9.0)).abs() < 1e-9, "{area}");
        for t in 0..walls.triangles.len() {
            let n = walls.normal(t);
            let y = walls.centroid(t).y;
            assert!(n.y * y < 0.0 && n.y.abs() > 0.99, "wall triangle {t} at y = {y} faces {n}");
        }
    }

    #[test]
    fn an_stl_written_reads_back_the_same() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("road.stl");
        let road = road_mesh(&channel());
        write_stl(&p, "road", &road).unwrap();
        let back = TriMesh::load(&p, 1.0).unwrap();
        assert_eq!(back.triangles.len(), road.triangles.len());
        for t in 0..road.triangles.len() {
            assert_eq!(back.corners(t), road.corners(t));
        }
    }
}
