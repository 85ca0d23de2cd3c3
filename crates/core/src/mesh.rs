//! Triangle meshes: STL (ASCII and binary) and OBJ readers, vertex welding, edge topology, and the closest
//! point on a triangle with the region (face, edge, vertex) it lies in.
//!
//! Coordinates are in metres. Readers take a `scale` so that a CAD file in millimetres can be read with
//! `scale = 1e-3`.

use crate::{Aabb, Vec3};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Largest coordinate magnitude a mesh file may hold, in its own units (a billion kilometres in metres).
pub const MAX_COORDINATE: f64 = 1e12;
/// An indexed triangle mesh. Triangles are counter-clockwise seen from the side their normal points to.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TriMesh {
    pub vertices: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// Why a mesh file could not be read. Every variant names the file.
#[derive(Debug, Error)]
pub enum MeshError {
    #[error("mesh file {path}: cannot read it: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("mesh file {path}: unknown extension; expected .stl or .obj")]
    UnknownFormat { path: PathBuf },
    #[error("mesh file {path}, line {line}: {message}")]
    Parse { path: PathBuf, line: usize, message: String },
    #[error("mesh file {path}: {message}")]
    Invalid { path: PathBuf, message: String },
}

/// Where on a triangle the closest point lies. Edge `k` joins local vertices `k` and `(k+1) % 3`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum TriRegion {
    Face,
    Edge(u8),
    Vertex(u8),
}

/// Closest point on triangle `(a, b, c)` to `p`, and the region it lies in.
///
/// Voronoi-region walk of Ericson, *Real-Time Collision Detection* (2005), §5.1.5, extended to report the
/// region so that contacts on a shared edge or vertex can be counted once.
pub fn closest_point_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, TriRegion) {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, TriRegion::Vertex(0));
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, TriRegion::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, TriRegion::Edge(0));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, TriRegion::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, TriRegion::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), TriRegion::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (a + ab * v + ac * w, TriRegion::Face)
}

/// Shared-edge topology: a global id for every undirected edge, so contacts found through two triangles
/// that share an edge (or a vertex) can be recognised as one.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeshTopology {
    /// Global edge id of each triangle's local edges 0, 1, 2.
    pub triangle_edges: Vec<[u32; 3]>,
    /// Number of triangles using each edge (1 = boundary edge, 2 = interior edge of a manifold).
    pub edge_use_count: Vec<u32>,
}

impl TriMesh {
    /// Reads `.stl` (ASCII or binary) or `.obj` by extension, multiplying coordinates by `scale`.
    /// Coincident vertices are welded so that neighbouring triangles share their edges.
    pub fn load(path: &Path, scale: f64) -> Result<Self, MeshError> {
        let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
        let bytes = std::fs::read(path).map_err(|source| MeshError::Io { path: path.to_owned(), source })?;
        let mut mesh = match ext.as_deref() {
            Some("stl") => Self::parse_stl(&bytes, path)?,
            Some("obj") => Self::parse_obj(&bytes, path)?,
            _ => return Err(MeshError::UnknownFormat { path: path.to_owned() }),
        };
        if mesh.triangles.is_empty() {
            return Err(MeshError::Invalid { path: path.to_owned(), message: "holds no triangles".into() });
        }
        mesh.validate(path)?;
        if scale != 1.0 {
            mesh.vertices.iter_mut().for_each(|v| *v *= scale);
        }
        Ok(mesh)
    }

    /// The checks [`Self::load`] makes on a mesh read from `path` (named in the error): every coordinate
    /// finite and within ±[`MAX_COORDINATE`], no zero-area triangle. For meshes read otherwise (the solids
    /// of a multi-solid STL).
    pub fn validate(&self, path: &Path) -> Result<(), MeshError> {
        if let Some(i) = self.vertices.iter().position(|v| !crate::math::is_finite(*v)) {
            return Err(MeshError::Invalid {
                path: path.to_owned(),
                message: format!("vertex {i} has a non-finite coordinate"),
            });
        }
        // Areas are products of coordinates: beyond about 1e150 they overflow and every triangle would read
        // as degenerate. No geometry of this code reaches a billion kilometres in any unit.
        let far = |v: &Vec3| v.x.abs().max(v.y.abs()).max(v.z.abs()) > MAX_COORDINATE;
        if let Some(i) = self.vertices.iter().position(far) {
            let v = self.vertices[i];
            return Err(MeshError::Invalid {
                path: path.to_owned(),
                message: format!(
                    "vertex {i} at [{:e}, {:e}, {:e}] lies beyond ±{MAX_COORDINATE:e} (in the file's units); check the \
                     file's coordinates and units",
                    v.x, v.y, v.z
                ),
            });
        }
        if let Some(message) = self.zero_area_report() {
            return Err(MeshError::Invalid { path: path.to_owned(), message });
        }
        Ok(())
    }

    /// Names the first zero-area triangle (corners on one line, area below 1e-12 of the squared bounding
    /// box diagonal) and how many there are, or `None`. Such triangles have no normal: contacts with them
    /// would be lost or undefined, so a mesh that holds any is refused rather than silently thinned.
    pub fn zero_area_report(&self) -> Option<String> {
        let diag2 = self.bounds().extent().length_squared();
        let tol = 1e-12 * diag2;
        let bad: Vec<usize> =
            (0..self.triangles.len()).filter(|&t| self.area(t).is_nan() || self.area(t) <= tol).collect();
        let first = *bad.first()?;
        let [a, b, c] = self.corners(first);
        Some(format!(
            "{} of its {} triangles have zero area, the first is triangle {first} (0-based, in file order after \
             dropping triangles with two equal corners) with corners [{}, {}, {}], [{}, {}, {}], [{}, {}, {}]; \
             repair the mesh (remove zero-area faces) and export it again",
            bad.len(),
            self.triangles.len(),
            a.x,
            a.y,
            a.z,
            b.x,
            b.y,
            b.z,
            c.x,
            c.y,
            c.z
        ))
    }

    /// Parses STL bytes. A file whose size is exactly 84 + 50·n for the count n in its header is binary,
    /// whatever its first bytes say (many binary STL writers start the header with "solid").
    pub fn parse_stl(bytes: &[u8], path: &Path) -> Result<Self, MeshError> {
        if bytes.len() >= 84 {
            let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
            if bytes.len() == 84 + 50 * n {
                return Ok(Self::parse_binary_stl(bytes, n));
            }
        }
        let text = std::str::from_utf8(bytes).map_err(|_| MeshError::Invalid {
            path: path.to_owned(),
            message: "neither a binary STL (size does not match its triangle count) nor ASCII text".into(),
        })?;
        Self::parse_ascii_stl(text, path)
    }

    fn parse_binary_stl(bytes: &[u8], n: usize) -> Self {
        let mut soup = Vec::with_capacity(3 * n);
        for t in 0..n {
            let rec = &bytes[84 + 50 * t..84 + 50 * (t + 1)];
            for k in 0..3 {
                let off = 12 + 12 * k;
                let f = |i: usize| {
                    let o = off + 4 * i;
                    f32::from_le_bytes([rec[o], rec[o + 1], rec[o + 2], rec[o + 3]]) as f64
                };
                soup.push(Vec3::new(f(0), f(1), f(2)));
            }
        }
        Self::from_triangle_soup(&soup)
    }

    fn parse_ascii_stl(text: &str, path: &Path) -> Result<Self, MeshError> {
        let mut soup = Vec::new();
        let mut in_loop = 0usize;
        let err = |line: usize, message: String| MeshError::Parse { path: path.to_owned(), line, message };
        let mut saw_solid = false;
        for (i, raw) in text.lines().enumerate() {
            let line_no = i + 1;
            let mut words = raw.split_whitespace();
            match words.next() {
                Some("solid") => saw_solid = true,
                Some("vertex") => {
                    let mut xyz = [0.0; 3];
                    for c in &mut xyz {
                        let w = words
                            .next()
                            .ok_or_else(|| err(line_no, "vertex needs three coordinates".into()))?;
                        *c = w.parse().map_err(|_| err(line_no, format!("`{w}` is not a number")))?;
                    }
                    soup.push(Vec3::from_array(xyz));
                    in_loop += 1;
                }
                Some("endloop") => {
                    if in_loop != 3 {
                        return Err(err(line_no, format!("a facet has {in_loop} vertices; expected 3")));
                    }
                    in_loop = 0;
                }
                Some("facet" | "outer" | "endfacet" | "endsolid") | None => {}
                Some(w) => return Err(err(line_no, format!("unexpected keyword `{w}` in ASCII STL"))),
            }
        }
        if !saw_solid {
            return Err(MeshError::Invalid {
                path: path.to_owned(),
                message: "not an STL file (no `solid`)".into(),
            });
        }
        Ok(Self::from_triangle_soup(&soup))
    }

    /// Parses Wavefront OBJ: `v x y z` and `f i j k …` (1-based, negative = relative, `i/t/n` forms);
    /// polygons are fan-triangulated. Other statements are ignored.
    pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<Self, MeshError> {
        let text = std::str::from_utf8(bytes).map_err(|_| MeshError::Invalid {
            path: path.to_owned(),
            message: "OBJ file is not UTF-8 text".into(),
        })?;
        let err = |line: usize, message: String| MeshError::Parse { path: path.to_owned(), line, message };
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line_no = i + 1;
            let mut words = raw.split_whitespace();
            match words.next() {
                Some("v") => {
                    let mut xyz = [0.0; 3];
                    for c in &mut xyz {
                        let w =
                            words.next().ok_or_else(|| err(line_no, "`v` needs three coordinates".into()))?;
                        *c = w.parse().map_err(|_| err(line_no, format!("`{w}` is not a number")))?;
                    }
                    vertices.push(Vec3::from_array(xyz));
                }
                Some("f") => {
                    let mut idx = Vec::with_capacity(4);
                    for w in words {
                        let first = w.split('/').next().unwrap_or("");
                        let k: i64 = first
                            .parse()
                            .map_err(|_| err(line_no, format!("`{w}` is not a vertex index")))?;
                        let n = vertices.len() as i64;
                        let k0 = if k > 0 { k - 1 } else { n + k };
                        if k == 0 || k0 < 0 || k0 >= n {
                            return Err(err(line_no, format!("vertex index {k} is outside 1..={n}")));
                        }
                        idx.push(k0 as u32);
                    }
                    if idx.len() < 3 {
                        return Err(err(line_no, "a face needs at least 3 vertices".into()));
                    }
                    for k in 1..idx.len() - 1 {
                        triangles.push([idx[0], idx[k], idx[k + 1]]);
                    }
                }
                _ => {}
            }
        }
        Ok(TriMesh { vertices, triangles })
    }

    /// Builds an indexed mesh from three points per triangle, welding bit-identical points.
    pub fn from_triangle_soup(points: &[Vec3]) -> Self {
        let mut map: HashMap<[u64; 3], u32> = HashMap::with_capacity(points.len() / 2);
        let mut vertices = Vec::new();
        let mut triangles = Vec::with_capacity(points.len() / 3);
        for tri in points.chunks_exact(3) {
            let mut t = [0u32; 3];
            for (k, p) in tri.iter().enumerate() {
                // `+ 0.0` turns −0.0 into +0.0, so the two spellings of zero weld into one vertex.
                let key = [(p.x + 0.0).to_bits(), (p.y + 0.0).to_bits(), (p.z + 0.0).to_bits()];
                t[k] = *map.entry(key).or_insert_with(|| {
                    vertices.push(*p);
                    (vertices.len() - 1) as u32
                });
            }
            // Degenerate triangles (two equal corners) carry no area and no contact: drop them.
            if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                triangles.push(t);
            }
        }
        TriMesh { vertices, triangles }
    }

    /// Writes a binary STL (single precision, as the format requires).
    pub fn to_binary_stl(&self) -> Vec<u8> {
        let mut out = vec![0u8; 80];
        out[..16].copy_from_slice(b"spatter mesh    ");
        out.extend_from_slice(&(self.triangles.len() as u32).to_le_bytes());
        for t in 0..self.triangles.len() {
            let n = self.normal(t);
            for v in std::iter::once(n).chain(self.corners(t)) {
                for c in v.to_array() {
                    out.extend_from_slice(&(c as f32).to_le_bytes());
                }
            }
            out.extend_from_slice(&[0, 0]);
        }
        out
    }

    /// The three corner positions of triangle `t`.
    #[inline]
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        let [a, b, c] = self.triangles[t];
        [self.vertices[a as usize], self.vertices[b as usize], self.vertices[c as usize]]
    }

    /// Unit normal of triangle `t` (right-hand rule on its corner order).
    pub fn normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.corners(t);
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Area of triangle `t` \[m²\].
    pub fn area(&self, t: usize) -> f64 {
        let [a, b, c] = self.corners(t);
        0.5 * (b - a).cross(c - a).length()
    }

    /// Centroid of triangle `t`.
    pub fn centroid(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.corners(t);
        (a + b + c) / 3.0
    }

    /// Total surface area \[m²\].
    pub fn total_area(&self) -> f64 {
        (0..self.triangles.len()).map(|t| self.area(t)).sum()
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(&self.vertices)
    }

    /// Edge topology (global edge ids and how many triangles use each edge).
    pub fn topology(&self) -> MeshTopology {
        let mut ids: HashMap<(u32, u32), u32> = HashMap::with_capacity(self.triangles.len() * 3 / 2);
        let mut edge_use_count = Vec::new();
        let triangle_edges = self
            .triangles
            .iter()
            .map(|t| {
                let mut e = [0u32; 3];
                for k in 0..3 {
                    let (a, b) = (t[k], t[(k + 1) % 3]);
                    let key = (a.min(b), a.max(b));
                    let next = edge_use_count.len() as u32;
                    let id = *ids.entry(key).or_insert(next);
                    if id == next {
                        edge_use_count.push(0);
                    }
                    edge_use_count[id as usize] += 1;
                    e[k] = id;
                }
                e
            })
            .collect();
        MeshTopology { triangle_edges, edge_use_count }
    }

    /// Signed volume enclosed (positive for a closed mesh with outward normals) \[m³\].
    pub fn signed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Whether `p` lies inside a closed mesh (parity of crossings of a ray along a slightly skewed axis).
    pub fn contains_point(&self, p: Vec3) -> bool {
        let dir = Vec3::new(0.577_350_269_189_625_8, 0.577_350_269_189_625_7, 0.577_350_269_189_626)
            + Vec3::new(1.3e-7, -2.9e-7, 0.0);
        let mut crossings = 0u32;
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.corners(t);
            if ray_hits_triangle(p, dir, a, b, c).is_some() {
                crossings += 1;
            }
        }
        crossings % 2 == 1
    }

    /// An axis-aligned rectangle `[0,lx]×[0,ly]` at height `z`, normal +z, split into `nx × ny` squares
    /// of two triangles each. Handy for tests and analytic-vs-mesh comparisons.
    pub fn rectangle(lx: f64, ly: f64, z: f64, nx: usize, ny: usize) -> Self {
        let mut vertices = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                vertices.push(Vec3::new(lx * i as f64 / nx as f64, ly * j as f64 / ny as f64, z));
            }
        }
        let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
        let mut triangles = Vec::with_capacity(2 * nx * ny);
        for j in 0..ny {
            for i in 0..nx {
                triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        TriMesh { vertices, triangles }
    }

    /// Applies `f` to every vertex (e.g. a rigid transform).
    pub fn map_vertices(&mut self, f: impl Fn(Vec3) -> Vec3) {
        self.vertices.iter_mut().for_each(|v| *v = f(*v));
    }
}

/// Möller–Trumbore ray/triangle intersection; returns the ray parameter `s > 0` of the hit.
pub fn ray_hits_triangle(origin: Vec3, dir: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<f64> {
    let e1 = b - a;
    let e2 = c - a;
    let pv = dir.cross(e2);
    let det = e1.dot(pv);
    if det.abs() < 1e-300 {
        return None;
    }
    let inv = 1.0 / det;
    let tv = origin - a;
    let u = tv.dot(pv) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qv = tv.cross(e1);
    let v = dir.dot(qv) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let s = e2.dot(qv) * inv;
    (s > 0.0).then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    const A: Vec3 = Vec3::new(0.0, 0.0, 0.0);
    const B: Vec3 = Vec3::new(1.0, 0.0, 0.0);
    const C: Vec3 = Vec3::new(0.0, 1.0, 0.0);

    #[test]
    fn closest_point_regions() {
        let cases = [
            (Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.2, 0.2, 0.0), TriRegion::Face),
            (Vec3::new(-1.0, -1.0, 0.5), A, TriRegion::Vertex(0)),
            (Vec3::new(2.0, -0.5, 0.0), B, TriRegion::Vertex(1)),
            (Vec3::new(-0.1, 3.0, 0.0), C, TriRegion::Vertex(2)),
            (Vec3::new(0.5, -1.0, 0.3), Vec3::new(0.5, 0.0, 0.0), TriRegion::Edge(0)),
            (Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.5, 0.5, 0.0), TriRegion::Edge(1)),
            (Vec3::new(-2.0, 0.25, -1.0), Vec3::new(0.0, 0.25, 0.0), TriRegion::Edge(2)),
        ];
        for (p, q, r) in cases {
            let (got, region) = closest_point_on_triangle(p, A, B, C);
            assert!((got - q).length() < 1e-14, "{p} → {got}, expected {q}");
            assert_eq!(region, r, "{p}");
        }
    }

    #[test]
    fn closest_point_is_never_farther_than_brute_force_samples() {
        let (a, b, c) = (Vec3::new(0.1, -0.3, 0.2), Vec3::new(1.2, 0.4, -0.1), Vec3::new(-0.2, 0.9, 0.5));
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..200 {
            let p = Vec3::new(rnd(), rnd(), rnd());
            let (q, _) = closest_point_on_triangle(p, a, b, c);
            let d = (p - q).length();
            for i in 0..=40 {
                for j in 0..=(40 - i) {
                    let s = a + (b - a) * (i as f64 / 40.0) + (c - a) * (j as f64 / 40.0);
                    assert!(d <= (p - s).length() + 1e-12);
                }
            }
        }
    }

    /// A triangle with three distinct but collinear corners survives welding and has no normal: loading
    /// refuses the mesh, naming the triangle; a clean mesh loads.
    #[test]
    fn zero_area_triangles_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("good.stl");
        std::fs::write(&good, TriMesh::rectangle(1.0, 1.0, 0.0, 2, 2).to_binary_stl()).unwrap();
        assert!(TriMesh::load(&good, 1.0).is_ok());
        let mut m = TriMesh::rectangle(1.0, 1.0, 0.0, 2, 2);
        m.vertices.push(Vec3::new(2.0, 0.0, 0.0));
        m.vertices.push(Vec3::new(3.0, 0.0, 0.0));
        m.vertices.push(Vec3::new(4.0, 0.0, 0.0));
        let n = m.vertices.len() as u32;
        m.triangles.push([n - 3, n - 2, n - 1]);
        let bad = dir.path().join("bad.stl");
        std::fs::write(&bad, m.to_binary_stl()).unwrap();
        let e = TriMesh::load(&bad, 1.0).unwrap_err().to_string();
        assert!(e.contains("bad.stl") && e.contains("1 of its 9 triangles have zero area"), "{e}");
        assert!(e.contains("triangle 8"), "{e}");
    }

    /// A vertex at 1e300 (a corrupted or mistyped file) is refused for its coordinate, not reported as a
    /// mesh of zero-area triangles (its areas overflowed).
    #[test]
    fn huge_coordinates_are_refused_for_what_they_are() {
        let dir = tempfile::tempdir().unwrap();
        // ASCII STL holds doubles (binary STL's single precision would read 1e300 as infinity).
        let path = dir.path().join("far.stl");
        let facet = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
            format!(
                "facet normal 0 0 1\nouter loop\nvertex {} {} {}\nvertex {} {} {}\nvertex {} {} {}\nendloop\nendfacet\n",
                a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]
            )
        };
        let text = format!(
            "solid far\n{}{}endsolid far\n",
            facet([0.0, 0.0, 0.0], [1e300, 0.0, 0.0], [0.0, 1.0, 0.0]),
            facet([0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [0.0, 1.0, 1.0])
        );
        std::fs::write(&path, text).unwrap();
        let e = TriMesh::load(&path, 1.0).unwrap_err().to_string();
        assert!(e.contains("far.stl") && e.contains("beyond ±1e12") && !e.contains("zero area"), "{e}");
        // A mesh in millimetres a kilometre across is fine.
        let big = TriMesh::rectangle(1e6, 1e6, 0.0, 2, 2);
        let path = dir.path().join("big.stl");
        std::fs::write(&path, big.to_binary_stl()).unwrap();
        assert!(TriMesh::load(&path, 1e-3).is_ok());
    }

    #[test]
    fn stl_round_trip_and_welding() {
        let mesh = TriMesh::rectangle(2.0, 1.0, 0.5, 2, 1);
        let bytes = mesh.to_binary_stl();
        let back = TriMesh::parse_stl(&bytes, Path::new("x.stl")).unwrap();
        assert_eq!(back.triangles.len(), 4);
        assert_eq!(back.vertices.len(), 6, "shared corners welded");
        assert!((back.total_area() - 2.0).abs() < 1e-6);
        let topo = back.topology();
        assert_eq!(topo.edge_use_count.iter().filter(|&&c| c == 2).count(), 3, "three interior edges");
    }

    #[test]
    fn negative_zero_welds_with_zero() {
        let soup = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(-0.0, 0.0, -0.0),
            Vec3::new(0.0, -1.0, 0.0),
            Vec3::new(1.0, -0.0, 0.0),
        ];
        let m = TriMesh::from_triangle_soup(&soup);
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.topology().edge_use_count.iter().filter(|&&c| c == 2).count(), 1, "shared edge found");
    }

    #[test]
    fn ascii_stl_and_obj() {
        let stl = "solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\nendfacet\nendsolid t\n";
        let m = TriMesh::parse_stl(stl.as_bytes(), Path::new("a.stl")).unwrap();
        assert_eq!(m.triangles.len(), 1);
        assert!((m.normal(0) - Vec3::Z).length() < 1e-15);
        let obj = "# square\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1/1/1 2/2/2 3/3/3 4/4/4\n";
        let m = TriMesh::parse_obj(obj.as_bytes(), Path::new("a.obj")).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let bad = "v 0 0 0\nf 1 2 3\n";
        let e = TriMesh::parse_obj(bad.as_bytes(), Path::new("bad.obj")).unwrap_err().to_string();
        assert!(e.contains("bad.obj, line 2") && e.contains("outside 1..=1"), "{e}");
        let e =
            TriMesh::parse_stl(b"solid x\n vertex 0 0 zero\n", Path::new("s.stl")).unwrap_err().to_string();
        assert!(e.contains("line 2") && e.contains("`zero` is not a number"), "{e}");
    }

    #[test]
    fn inside_test_on_a_cube() {
        let mut soup = Vec::new();
        // A unit cube as 12 triangles with outward normals.
        let v = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
        let quads = [
            [v(0., 0., 0.), v(0., 1., 0.), v(1., 1., 0.), v(1., 0., 0.)],
            [v(0., 0., 1.), v(1., 0., 1.), v(1., 1., 1.), v(0., 1., 1.)],
            [v(0., 0., 0.), v(1., 0., 0.), v(1., 0., 1.), v(0., 0., 1.)],
            [v(0., 1., 0.), v(0., 1., 1.), v(1., 1., 1.), v(1., 1., 0.)],
            [v(0., 0., 0.), v(0., 0., 1.), v(0., 1., 1.), v(0., 1., 0.)],
            [v(1., 0., 0.), v(1., 1., 0.), v(1., 1., 1.), v(1., 0., 1.)],
        ];
        for q in quads {
            soup.extend_from_slice(&[q[0], q[1], q[2], q[0], q[2], q[3]]);
        }
        let cube = TriMesh::from_triangle_soup(&soup);
        assert!((cube.signed_volume() - 1.0).abs() < 1e-14);
        assert!(cube.contains_point(Vec3::splat(0.5)));
        assert!(!cube.contains_point(Vec3::new(1.5, 0.5, 0.5)));
    }
}
