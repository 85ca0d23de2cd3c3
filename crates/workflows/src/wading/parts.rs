//! The vehicle as named parts: mesh files whose solids become parts, wheels found by part name and
//! checked against their declared axle and radius.

use spatter_core::mesh::{MeshError, TriMesh};
use spatter_core::{Aabb, Vec3};
use std::path::Path;

/// One named part of the vehicle.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedPart {
    pub name: String,
    pub mesh: TriMesh,
}

/// The parts in a mesh file: every `solid NAME … endsolid` of an ASCII STL becomes a part called NAME (a
/// solid without a name, or a name used twice, gets the file's stem and its number); a binary STL or an
/// OBJ file is one part named after the file's stem. Coordinates are multiplied by `scale`. A file with
/// no solid, or a solid without triangles, is an error naming the file (and the solid).
pub fn read_parts(path: &Path, scale: f64) -> Result<Vec<NamedPart>, MeshError> {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("part").to_owned();
    let bytes = std::fs::read(path).map_err(|source| MeshError::Io { path: path.to_owned(), source })?;
    let is_stl = path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("stl"));
    let binary = bytes.len() >= 84 && {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        bytes.len() == 84 + 50 * n
    };
    if !is_stl || binary {
        let mesh = TriMesh::load(path, scale)?;
        return Ok(vec![NamedPart { name: stem, mesh }]);
    }
    let text = std::str::from_utf8(&bytes).map_err(|_| MeshError::Invalid {
        path: path.to_owned(),
        message: "is neither binary STL nor text".into(),
    })?;
    // Solids as (name, first line number, text).
    let mut solids: Vec<(String, usize, String)> = Vec::new();
    let mut current: Option<(String, usize, String)> = None;
    for (i, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("solid") => {
                if let Some(s) = current.take() {
                    solids.push(s);
                }
                let name = words.collect::<Vec<_>>().join(" ");
                current = Some((name, i, format!("{line}\n")));
            }
            Some("endsolid") => {
                if let Some(mut s) = current.take() {
                    s.2.push_str(line);
                    s.2.push('\n');
                    solids.push(s);
                }
            }
            _ => {
                if let Some(s) = current.as_mut() {
                    s.2.push_str(line);
                    s.2.push('\n');
                } else if !line.trim().is_empty() {
                    return Err(MeshError::Parse {
                        path: path.to_owned(),
                        line: i + 1,
                        message: format!("`{}` outside any `solid … endsolid`", line.trim()),
                    });
                }
            }
        }
    }
    if let Some(s) = current.take() {
        solids.push(s);
    }
    if solids.is_empty() {
        return Err(MeshError::Invalid {
            path: path.to_owned(),
            message: "holds no solid (expected `solid NAME … endsolid NAME` blocks of facets)".into(),
        });
    }
    let mut parts: Vec<NamedPart> = Vec::with_capacity(solids.len());
    for (k, (name, first, body)) in solids.into_iter().enumerate() {
        let mut mesh = TriMesh::parse_stl(body.as_bytes(), path).map_err(|e| match e {
            MeshError::Parse { path, line, message } => {
                MeshError::Parse { path, line: line + first, message }
            }
            other => other,
        })?;
        let label = if name.is_empty() { format!("solid {}", k + 1) } else { format!("solid `{name}`") };
        if mesh.triangles.is_empty() {
            return Err(MeshError::Invalid {
                path: path.to_owned(),
                message: format!("{label} (line {}) holds no triangles", first + 1),
            });
        }
        // The checks of a mesh read whole (non-finite or far coordinates, zero-area triangles), naming the
        // solid.
        mesh.validate(path).map_err(|e| match e {
            MeshError::Invalid { path, message } => {
                MeshError::Invalid { path, message: format!("{label} (line {}): {message}", first + 1) }
            }
            other => other,
        })?;
        if scale != 1.0 {
            mesh.vertices.iter_mut().for_each(|v| *v *= scale);
        }
        let taken = |n: &str| parts.iter().any(|p| p.name == n);
        let name = if name.is_empty() || taken(&name) { format!("{stem}_{}", k + 1) } else { name };
        parts.push(NamedPart { name, mesh });
    }
    Ok(parts)
}

/// How far the mesh of a wheel reaches from its axle: the largest distance of a vertex from the axle line
/// through `axle` along `axis` (unit) \[m\].
pub fn wheel_reach(mesh: &TriMesh, axle: Vec3, axis: Vec3) -> f64 {
    mesh.vertices
        .iter()
        .map(|&v| {
            let d = v - axle;
            (d - axis * d.dot(axis)).length()
        })
        .fold(0.0, f64::max)
}

/// Bounding box of several parts.
pub fn bounds(parts: &[NamedPart]) -> Aabb {
    parts.iter().fold(Aabb::EMPTY, |b, p| b.union(p.mesh.bounds()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facet(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> String {
        format!(
            "facet normal 0 0 1\n outer loop\n  vertex {} {} {}\n  vertex {} {} {}\n  vertex {} {} {}\n endloop\nendfacet\n",
            a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]
        )
    }

    #[test]
    fn every_solid_of_a_multi_solid_stl_is_a_part() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("truck.stl");
        let t1 = facet([0., 0., 0.], [1., 0., 0.], [0., 1., 0.]);
        let t2 = facet([0., 0., 1.], [2., 0., 1.], [0., 2., 1.]);
        let text = format!(
            "solid cab\n{t1}{t2}endsolid cab\nsolid wheel_fl\n{t1}endsolid wheel_fl\nsolid\n{t2}endsolid\nsolid cab\n{t1}endsolid cab\n"
        );
        std::fs::write(&path, text).unwrap();
        let parts = read_parts(&path, 0.001).unwrap();
        let names: Vec<&str> = parts.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["cab", "wheel_fl", "truck_3", "truck_4"]);
        assert_eq!(parts[0].mesh.triangles.len(), 2);
        assert!((parts[0].mesh.bounds().max.x - 0.002).abs() < 1e-15, "scaled from mm");
    }

    #[test]
    fn files_without_solids_or_triangles_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let empty = dir.path().join("empty.stl");
        std::fs::write(&empty, "\n\n").unwrap();
        let e = read_parts(&empty, 1.0).unwrap_err().to_string();
        assert!(e.contains("empty.stl") && e.contains("holds no solid"), "{e}");
        let hollow = dir.path().join("hollow.stl");
        let t = facet([0., 0., 0.], [1., 0., 0.], [0., 1., 0.]);
        std::fs::write(&hollow, format!("solid a\n{t}endsolid a\nsolid mirror\nendsolid mirror\n")).unwrap();
        let e = read_parts(&hollow, 1.0).unwrap_err().to_string();
        assert!(e.contains("solid `mirror` (line 10) holds no triangles"), "{e}");
        let stray = dir.path().join("stray.stl");
        std::fs::write(&stray, format!("vertex 0 0 0\nsolid a\n{t}endsolid a\n")).unwrap();
        let e = read_parts(&stray, 1.0).unwrap_err().to_string();
        assert!(e.contains("line 1") && e.contains("outside any"), "{e}");
    }

    #[test]
    fn wheel_reach_is_the_radius_of_a_cylinder_mesh() {
        // A 24-gon prism of radius 0.5 about the y axis through (1, 0, 0.5).
        let n = 24;
        let mut soup = Vec::new();
        for k in 0..n {
            let a0 = k as f64 / n as f64 * std::f64::consts::TAU;
            let a1 = (k + 1) as f64 / n as f64 * std::f64::consts::TAU;
            let p = |a: f64, y: f64| Vec3::new(1.0 + 0.5 * a.cos(), y, 0.5 + 0.5 * a.sin());
            soup.extend([p(a0, 0.0), p(a1, 0.0), p(a1, 0.3)]);
            soup.extend([p(a0, 0.0), p(a1, 0.3), p(a0, 0.3)]);
        }
        let mesh = TriMesh::from_triangle_soup(&soup);
        let r = wheel_reach(&mesh, Vec3::new(1.0, 0.15, 0.5), Vec3::Y);
        assert!((r - 0.5).abs() < 1e-12, "{r}");
    }
}
