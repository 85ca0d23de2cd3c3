//! Triangle-mesh walls: face/edge/vertex contacts counted once, and per-triangle impact records.
//!
//! # One contact per touching surface patch
//!
//! A sphere near a mesh finds the closest point on every triangle in reach. On a flat or gently curved
//! mesh several triangles report points on their shared edges or vertices, and naive summation gives a
//! double (or sixfold) force. The rule used here accepts a point only if it is a *local minimum of the
//! distance over the whole mesh*:
//!
//! * a **face** point (interior of its triangle) always is;
//! * an **edge** point on edge e is one only if every other in-reach triangle that owns e also reports
//!   its closest point on e (otherwise some neighbour has a closer point next to it, and the sphere's
//!   contact with that neighbour already accounts for the patch); among the triangles that agree, the
//!   lowest index owns the contact;
//! * a **vertex** point likewise requires every other in-reach triangle owning that vertex to report the
//!   same vertex.
//!
//! A final guard merges accepted points closer than 10⁻⁹ of the reach (two faces that both claim a point
//! on their shared edge through round-off). Convex edges and corners therefore give one contact with the
//! correct (edge- or vertex-) normal, concave corners give one contact per face, and a flat mesh acts
//! exactly like the analytic plane, also when the contact sits on a shared edge or vertex (tested).
//!
//! # History across triangles
//!
//! Contact state lives with the triangle that owns the contact. When a sliding contact passes from one
//! triangle to its neighbour, the new owner inherits the state of the nearest contact of the same mesh
//! that ended in the same step (see the engine's wall loop), so the tangential spring survives seams.

use serde::{Deserialize, Serialize};
use spatter_core::mesh::{closest_point_on_triangle, MeshTopology, TriMesh, TriRegion};
use spatter_core::tri_bvh::TriBvh;
use spatter_core::{Aabb, Vec3};

/// A mesh wall in its reference frame.
#[derive(Clone, Debug)]
pub struct MeshWall {
    pub mesh: TriMesh,
    pub topology: MeshTopology,
    pub bvh: TriBvh,
    /// Accumulated impact records per triangle.
    pub records: MeshRecords,
}

/// Per-triangle accumulated contact records, written to the mesh VTU as cell data.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeshRecords {
    /// Σ |F_n| Δt \[N s\].
    pub normal_impulse: Vec<f64>,
    /// Σ |F_t| Δt \[N s\].
    pub tangential_impulse: Vec<f64>,
    /// Number of contacts that formed on the triangle.
    pub impacts: Vec<u64>,
    /// Σ normal approach speed at formation \[m/s\] (divide by `impacts` for the mean impact speed).
    pub impact_speed_sum: Vec<f64>,
    /// Σ impact angle at formation, between the velocity relative to the wall and the wall plane
    /// \[deg\] (divide by `impacts` for the mean).
    #[serde(default)]
    pub impact_angle_sum: Vec<f64>,
    /// Eroded wall mass \[kg\] (wear models, [`crate::wear`]).
    #[serde(default)]
    pub eroded_mass: Vec<f64>,
}

impl MeshRecords {
    pub fn new(n: usize) -> Self {
        MeshRecords {
            normal_impulse: vec![0.0; n],
            tangential_impulse: vec![0.0; n],
            impacts: vec![0; n],
            impact_speed_sum: vec![0.0; n],
            impact_angle_sum: vec![0.0; n],
            eroded_mass: vec![0.0; n],
        }
    }

    /// Adds the records of `other` (of the same mesh) triangle by triangle: the records of the same
    /// wall kept by several ranks, joined.
    pub fn add(&mut self, other: &MeshRecords) {
        for (a, b) in self.impacts.iter_mut().zip(&other.impacts) {
            *a += b;
        }
        for (a, b) in [
            (&mut self.normal_impulse, &other.normal_impulse),
            (&mut self.tangential_impulse, &other.tangential_impulse),
            (&mut self.impact_speed_sum, &other.impact_speed_sum),
            (&mut self.impact_angle_sum, &other.impact_angle_sum),
            (&mut self.eroded_mass, &other.eroded_mass),
        ] {
            a.iter_mut().zip(b).for_each(|(a, b)| *a += b);
        }
    }

    /// Sizes the records added after older checkpoints were written.
    pub(crate) fn fill_missing(&mut self) {
        let n = self.impacts.len();
        self.impact_angle_sum.resize(n, 0.0);
        self.eroded_mass.resize(n, 0.0);
    }
}

/// One accepted contact of a sphere with a mesh, in the mesh's reference frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshHit {
    /// Index of the owning triangle in the caller's candidate list.
    pub slot: usize,
    pub triangle: u32,
    pub point: Vec3,
    /// Unit normal from the surface to the sphere centre.
    pub normal: Vec3,
    pub distance: f64,
    pub region: TriRegion,
}

/// Most in-reach triangles one sphere can be resolved against without heap allocation.
pub const MAX_INLINE_HITS: usize = 48;

impl MeshWall {
    /// A mesh wall; vertices closer than 10⁻⁹ of the mesh's bounding-box diagonal are welded first, so
    /// that seams of CAD exports whose copies of a vertex differ in the last bits still share their edges.
    pub fn new(mesh: TriMesh) -> Self {
        let mesh = weld(mesh, 1e-9);
        let topology = mesh.topology();
        let bvh = TriBvh::build(&mesh);
        let records = MeshRecords::new(mesh.triangles.len());
        MeshWall { mesh, topology, bvh, records }
    }

    /// Calls `f(t)` for every triangle closer than `reach` to `x` (reference frame), in ascending order of
    /// triangle index is *not* guaranteed; callers sort if they need an order.
    pub fn for_each_near(&self, x: Vec3, reach: f64, mut f: impl FnMut(u32)) {
        let q = Aabb::new(x - Vec3::splat(reach), x + Vec3::splat(reach));
        self.bvh.for_each_overlapping(&self.mesh, &q, |t| {
            let [a, b, c] = self.mesh.corners(t as usize);
            let (p, _) = closest_point_on_triangle(x, a, b, c);
            if (p - x).length_squared() < reach * reach {
                f(t)
            }
        });
    }

    /// Resolves the contacts of a sphere centred at `x` (reference frame) with the candidate triangles
    /// `candidates` (ascending), keeping surface points closer than `reach`. Accepted contacts are written
    /// to `out` (cleared first; `raw` is scratch); see the module documentation for the rule.
    pub fn resolve(&self, x: Vec3, reach: f64, candidates: &[u32], raw: &mut HitBuffer, out: &mut HitBuffer) {
        out.clear();
        raw.clear();
        for (slot, &t) in candidates.iter().enumerate() {
            let [a, b, c] = self.mesh.corners(t as usize);
            let (q, region) = closest_point_on_triangle(x, a, b, c);
            let r = x - q;
            let d2 = r.length_squared();
            if d2 >= reach * reach {
                continue;
            }
            let distance = d2.sqrt();
            let normal = if distance > 0.0 {
                r / distance
            } else {
                let n = self.mesh.normal(t as usize);
                if n == Vec3::ZERO {
                    continue;
                }
                n
            };
            raw.push(MeshHit { slot, triangle: t, point: q, normal, distance, region });
        }
        let hits = raw.as_slice();
        for (k, h) in hits.iter().enumerate() {
            let t = h.triangle as usize;
            let accepted = match h.region {
                TriRegion::Face => true,
                TriRegion::Edge(e) => {
                    let edge = self.topology.triangle_edges[t][e as usize];
                    hits.iter().enumerate().all(|(m, o)| {
                        if m == k {
                            return true;
                        }
                        let oe = &self.topology.triangle_edges[o.triangle as usize];
                        match oe.iter().position(|&x| x == edge) {
                            None => true,
                            // A neighbour owning the edge agrees only if its own closest point is on
                            // the same edge; the lowest triangle index owns the shared contact.
                            Some(local) => {
                                o.region == TriRegion::Edge(local as u8) && o.triangle > h.triangle
                            }
                        }
                    })
                }
                TriRegion::Vertex(v) => {
                    let vertex = self.mesh.triangles[t][v as usize];
                    hits.iter().enumerate().all(|(m, o)| {
                        if m == k {
                            return true;
                        }
                        let ov = &self.mesh.triangles[o.triangle as usize];
                        match ov.iter().position(|&x| x == vertex) {
                            None => true,
                            Some(local) => {
                                o.region == TriRegion::Vertex(local as u8) && o.triangle > h.triangle
                            }
                        }
                    })
                }
            };
            if !accepted {
                continue;
            }
            let tol = 1e-9 * reach;
            if out.as_slice().iter().any(|a| (a.point - h.point).length_squared() <= tol * tol) {
                continue;
            }
            out.push(*h);
        }
    }
}

/// Merges vertices closer than `rel_tol` × (bounding-box diagonal) and drops triangles that degenerate.
fn weld(mesh: TriMesh, rel_tol: f64) -> TriMesh {
    use std::collections::HashMap;
    let b = mesh.bounds();
    let tol = rel_tol * b.extent().length();
    if tol.is_nan() || tol <= 0.0 || mesh.vertices.is_empty() {
        return mesh;
    }
    let key = |v: Vec3| {
        let q = (v - b.min) / tol;
        [q.x.floor() as i64, q.y.floor() as i64, q.z.floor() as i64]
    };
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut vertices: Vec<Vec3> = Vec::with_capacity(mesh.vertices.len());
    let mut remap = Vec::with_capacity(mesh.vertices.len());
    for &v in &mesh.vertices {
        let k = key(v);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = cells.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        for &c in list {
                            if (vertices[c as usize] - v).length() <= tol {
                                found = Some(c);
                                break 'search;
                            }
                        }
                    }
                }
            }
        }
        let idx = found.unwrap_or_else(|| {
            vertices.push(v);
            let c = (vertices.len() - 1) as u32;
            cells.entry(k).or_default().push(c);
            c
        });
        remap.push(idx);
    }
    let triangles = mesh
        .triangles
        .iter()
        .map(|t| [remap[t[0] as usize], remap[t[1] as usize], remap[t[2] as usize]])
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    TriMesh { vertices, triangles }
}

/// A small vector of [`MeshHit`]s that stays on the stack up to [`MAX_INLINE_HITS`] entries.
#[derive(Clone, Debug)]
pub struct HitBuffer {
    inline: [MeshHit; MAX_INLINE_HITS],
    len: usize,
    spill: Vec<MeshHit>,
}

impl Default for HitBuffer {
    fn default() -> Self {
        const EMPTY: MeshHit = MeshHit {
            slot: 0,
            triangle: 0,
            point: Vec3::ZERO,
            normal: Vec3::ZERO,
            distance: 0.0,
            region: TriRegion::Face,
        };
        HitBuffer { inline: [EMPTY; MAX_INLINE_HITS], len: 0, spill: Vec::new() }
    }
}

impl HitBuffer {
    pub fn clear(&mut self) {
        self.len = 0;
        self.spill.clear();
    }

    pub fn push(&mut self, h: MeshHit) {
        if self.len < MAX_INLINE_HITS {
            self.inline[self.len] = h;
            self.len += 1;
        } else {
            if self.spill.is_empty() {
                self.spill.extend_from_slice(&self.inline);
            }
            self.spill.push(h);
            self.len += 1;
        }
    }

    pub fn as_slice(&self) -> &[MeshHit] {
        if self.len <= MAX_INLINE_HITS {
            &self.inline[..self.len]
        } else {
            &self.spill
        }
    }

    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}
