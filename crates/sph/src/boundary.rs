//! Boundary particles: walls and bodies sampled at the fluid spacing, grouped in parts that move with
//! prescribed kinematics.
//!
//! * **Lattice parts** (analytic boxes): `layers` lattice layers continue the fluid lattice behind each
//!   closed face (first layer dp/2 behind the face), each particle with volume dp^d.
//! * **Solid mesh parts** (closed STL/OBJ surfaces and generated solids such as wheels): the surface
//!   samples of [`spatter_core::surface_sample`] moved inside, in `layers` layers at (k + ½)·dp behind the
//!   surface like the lattice layers of a block, each particle with volume (sample area)·dp. The fluid
//!   then rests half a spacing off the surface, as at lattice walls, so that the fluid particles' volumes
//!   tile the space up to the body (loads and wetting refer to the true surface).
//! * **Shell mesh parts** (open surfaces: plates, panels, thin shells with water on both sides): one layer
//!   on the surface, optional further layers offset by dp against the normal, each particle with the
//!   Akinci et al. (2012) volume `V_b = 1 / Σ_k W_bk` (same-part neighbours), so that irregular or thin
//!   samplings still fill the kernel support. A one-layer shell holds the fluid about 1.2–1.6 dp off
//!   its surface.
//!
//! Wall pressure, velocity and density are extrapolated from the fluid every step (Adami, Hu & Adams
//! 2012, J. Comput. Phys. 231:7057), see [`crate::pass`]. Every part also keeps its surface as triangles
//! in its reference frame: the crossing guard ([`crate::guard`]) stops any fluid particle that would pass
//! through it, so even a shell one particle thick cannot leak.

use crate::kernel::{Dim, Kernel};
use crate::neighbours::NeighbourGrid;
use serde::{Deserialize, Serialize};
use spatter_core::mesh::TriMesh;
use spatter_core::motion::KinematicTree;
use spatter_core::surface_sample::{sample_surface, TriangleCoverage};
use spatter_core::tri_bvh::TriBvh;
use spatter_core::{Aabb, Mat3, Vec3};

/// Tangential condition of a wall for the laminar viscous term.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Slip {
    /// Dummy velocity `2 v_wall − ṽ` (Adami et al. 2012): the fluid sticks to the wall.
    #[default]
    NoSlip,
    /// Dummy velocity `ṽ`: no viscous shear from the wall.
    FreeSlip,
}

/// How a part was sampled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Sampling {
    /// Lattice layers of an analytic box.
    Lattice,
    /// Surface samples of an open mesh (a shell), with the coverage of every triangle by the first-layer
    /// samples (sample indices relative to the part's first particle).
    Mesh(TriangleCoverage),
    /// Samples of a closed mesh moved inside the solid (first layer dp/2 behind the surface), with the
    /// coverage of every triangle by the first-layer samples.
    Solid(TriangleCoverage),
}

impl Sampling {
    /// Triangle coverage of a mesh part (shell or solid).
    pub fn coverage(&self) -> Option<&TriangleCoverage> {
        match self {
            Sampling::Lattice => None,
            Sampling::Mesh(c) | Sampling::Solid(c) => Some(c),
        }
    }

    /// Distance \[m\] from a first-layer particle to the surface point it stands for, along its normal:
    /// dp/2 for lattice and solid parts (first layer behind the surface), 0 for shells (on it).
    pub fn surface_offset(&self, dp: f64) -> f64 {
        match self {
            Sampling::Lattice | Sampling::Solid(_) => 0.5 * dp,
            Sampling::Mesh(_) => 0.0,
        }
    }

    /// Distance \[m\] from a particle's wet point to the surface the fluid actually rests on, added to the
    /// wet distance: 0 for lattice and solid parts (the fluid rests dp/2 off their true surface); dp for
    /// shells. A one-layer shell carries Akinci volumes that stand for a full-thickness wall, so it holds
    /// the fluid about 1.5 dp off its particles on either side — dp/2 off a surface dp in front of the sheet
    /// (measured: 1.46–1.61 dp under 10 cm of still water and after a 5 cm drop, `tests/engine.rs`).
    pub fn wet_reach(&self, dp: f64) -> f64 {
        match self {
            Sampling::Lattice | Sampling::Solid(_) => 0.0,
            Sampling::Mesh(_) => dp,
        }
    }
}

/// A rigid wall or body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Part {
    pub name: String,
    /// Node of the kinematic tree it moves with (None: fixed in the world).
    pub node: Option<usize>,
    /// Surface in the reference frame (world coordinates at t = 0).
    pub surface: TriMesh,
    pub bvh: TriBvh,
    pub sampling: Sampling,
    /// Its particles are `start..end` of the boundary arrays.
    pub start: usize,
    pub end: usize,
    /// Akinci adhesion coefficient β as a multiple of the cohesion coefficient γ.
    pub adhesion: f64,
    pub slip: Slip,
    /// Point (reference frame) about which the fluid torque is reported.
    pub torque_point: Vec3,
    /// Surface is closed: the inside is solid and never filled with fluid.
    pub closed: bool,
}

/// Rigid placement and motion of a part at one instant.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    pub rot: Mat3,
    /// World position of the reference-frame origin.
    pub origin: Vec3,
    /// Velocity of that point \[m/s\].
    pub vel: Vec3,
    pub omega: Vec3,
    /// Acceleration of that point \[m/s²\].
    pub acc: Vec3,
    pub alpha: Vec3,
}

impl Frame {
    pub const IDENTITY: Frame = Frame {
        rot: Mat3::IDENTITY,
        origin: Vec3::ZERO,
        vel: Vec3::ZERO,
        omega: Vec3::ZERO,
        acc: Vec3::ZERO,
        alpha: Vec3::ZERO,
    };

    /// Frame of `node` at time `t`; accelerations by central differences over ±1 µs.
    pub fn of(tree: &KinematicTree, node: Option<usize>, t: f64) -> Frame {
        let Some(i) = node else { return Frame::IDENTITY };
        let at = |t: f64| {
            let o = tree.world_point(i, t, Vec3::ZERO);
            (o, tree.velocity_at(i, t, o), tree.angular_velocity(i, t))
        };
        let (origin, vel, omega) = at(t);
        let eps = 1e-6;
        let (_, vp, wp) = at(t + eps);
        let (_, vm, wm) = at(t - eps);
        Frame {
            rot: Mat3::from_quat(tree.rotation(i, t)),
            origin,
            vel,
            omega,
            acc: (vp - vm) / (2.0 * eps),
            alpha: (wp - wm) / (2.0 * eps),
        }
    }

    #[inline]
    pub fn to_world(&self, x: Vec3) -> Vec3 {
        self.rot * x + self.origin
    }

    #[inline]
    pub fn to_reference(&self, x: Vec3) -> Vec3 {
        self.rot.transpose() * (x - self.origin)
    }

    #[inline]
    pub fn velocity(&self, x: Vec3) -> Vec3 {
        self.vel + self.omega.cross(x - self.origin)
    }

    #[inline]
    pub fn acceleration(&self, x: Vec3) -> Vec3 {
        let r = x - self.origin;
        self.acc + self.alpha.cross(r) + self.omega.cross(self.omega.cross(r))
    }

    pub fn is_static(&self) -> bool {
        *self == Frame::IDENTITY
    }
}

/// Points of a boundary sampling before they become particles.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Samples {
    pub pos: Vec<Vec3>,
    /// Unit normal pointing into the fluid side (lattice parts) or the mesh's own normal (mesh parts).
    pub normal: Vec<Vec3>,
    /// Wall area the particle stands for \[m², or m per metre of depth in 2D\]; 0 behind the first layer.
    pub area: Vec<f64>,
    /// Particle volumes \[m³\] when the sampling fixes them (solid mesh parts); empty otherwise (computed
    /// by [`Boundary::compute_volumes`]).
    pub volume: Vec<f64>,
}

/// Face flags of a box in the order −x, +x, −y, +y, −z, +z.
pub type Faces = [bool; 6];

/// Lattice coordinates along one axis: outside layers below `lo`, the interior lattice, outside above `hi`.
/// Each entry is (coordinate, outside side: −1 below, +1 above, 0 inside, layer index).
fn axis_coords(lo: f64, hi: f64, dp: f64, below: usize, above: usize) -> Vec<(f64, i8, usize)> {
    let mut c = Vec::new();
    for k in (0..below).rev() {
        c.push((lo - (k as f64 + 0.5) * dp, -1, k));
    }
    let mut i = 0;
    loop {
        let x = lo + (i as f64 + 0.5) * dp;
        if x >= hi {
            break;
        }
        c.push((x, 0, 0));
        i += 1;
    }
    for k in 0..above {
        c.push((hi + (k as f64 + 0.5) * dp, 1, k));
    }
    c
}

/// A container: fluid inside `inner`, `layers` lattice layers outside every closed face. In 2D the y faces
/// are ignored and all particles have y = 0.
pub fn tank_lattice(inner: Aabb, closed: Faces, layers: usize, dp: f64, dim: Dim) -> Samples {
    let ax = |a: usize| {
        axis_coords(
            inner.min[a],
            inner.max[a],
            dp,
            if closed[2 * a] { layers } else { 0 },
            if closed[2 * a + 1] { layers } else { 0 },
        )
    };
    let xs = ax(0);
    let ys = if dim == Dim::Two { vec![(0.0, 0, 0)] } else { ax(1) };
    let zs = ax(2);
    let face_area = if dim == Dim::Two { dp } else { dp * dp };
    let mut s = Samples::default();
    for &(z, sz, kz) in &zs {
        for &(y, sy, ky) in &ys {
            for &(x, sx, kx) in &xs {
                let sides = [(sx, kx), (sy, ky), (sz, kz)];
                let outside = sides.iter().filter(|s| s.0 != 0).count();
                if outside == 0 {
                    continue;
                }
                // Normal: into the fluid along the axis where the particle is farthest outside.
                let mut best = (0usize, -1.0);
                for (a, &(side, k)) in sides.iter().enumerate() {
                    if side != 0 && k as f64 > best.1 {
                        best = (a, k as f64);
                    }
                }
                let a = best.0;
                let mut n = Vec3::ZERO;
                n[a] = -(sides[a].0 as f64);
                let area = if outside == 1 && sides[a].1 == 0 { face_area } else { 0.0 };
                s.pos.push(Vec3::new(x, y, z));
                s.normal.push(n);
                s.area.push(area);
            }
        }
    }
    s
}

/// A solid box (fluid outside): lattice points inside `block` within `layers` spacings of its faces.
pub fn block_lattice(block: Aabb, layers: usize, dp: f64, dim: Dim) -> Samples {
    let ax = |a: usize| axis_coords(block.min[a], block.max[a], dp, 0, 0);
    let xs = ax(0);
    let ys = if dim == Dim::Two { vec![(0.0, 0, 0)] } else { ax(1) };
    let zs = ax(2);
    let axes: &[usize] = if dim == Dim::Two { &[0, 2] } else { &[0, 1, 2] };
    let face_area = if dim == Dim::Two { dp } else { dp * dp };
    let depth = layers as f64 * dp;
    let mut s = Samples::default();
    for &(z, _, _) in &zs {
        for &(y, _, _) in &ys {
            for &(x, _, _) in &xs {
                let p = Vec3::new(x, y, z);
                let mut dmin = f64::INFINITY;
                let mut n = Vec3::ZERO;
                let mut first = 0;
                for &a in axes {
                    for (d, sign) in [(p[a] - block.min[a], -1.0), (block.max[a] - p[a], 1.0)] {
                        dmin = dmin.min(d);
                        if d < dp {
                            let mut e = Vec3::ZERO;
                            e[a] = sign;
                            n += e;
                            first += 1;
                        }
                    }
                }
                if dmin >= depth {
                    continue;
                }
                if n == Vec3::ZERO {
                    // Deeper layer: point along the nearest face.
                    for &a in axes {
                        if p[a] - block.min[a] <= dmin + 1e-12 {
                            n[a] = -1.0;
                            break;
                        }
                        if block.max[a] - p[a] <= dmin + 1e-12 {
                            n[a] = 1.0;
                            break;
                        }
                    }
                }
                s.pos.push(p);
                s.normal.push(n.normalize_or_zero());
                s.area.push(first as f64 * face_area);
            }
        }
    }
    s
}

/// Triangles of the faces of `b` flagged in `faces`, normals pointing inwards (`inward`) or outwards.
/// In 2D the y faces are skipped and the x and z faces span y ∈ [−1, 1] m (particles live at y = 0).
pub fn box_surface(b: Aabb, faces: Faces, inward: bool, dim: Dim) -> TriMesh {
    let (mut lo, mut hi) = (b.min, b.max);
    if dim == Dim::Two {
        lo.y = -1.0;
        hi.y = 1.0;
    }
    let c = |i: usize| {
        Vec3::new(
            if i & 1 == 0 { lo.x } else { hi.x },
            if i & 2 == 0 { lo.y } else { hi.y },
            if i & 4 == 0 { lo.z } else { hi.z },
        )
    };
    // Corners of each face in counter-clockwise order seen from outside.
    let quads: [[usize; 4]; 6] =
        [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];
    let mut soup = Vec::new();
    for (f, q) in quads.iter().enumerate() {
        if !faces[f] || (dim == Dim::Two && (f == 2 || f == 3)) {
            continue;
        }
        let [a, b2, cc, d] = q.map(c);
        if inward {
            soup.extend([a, cc, b2, a, d, cc]);
        } else {
            soup.extend([a, b2, cc, a, cc, d]);
        }
    }
    TriMesh::from_triangle_soup(&soup)
}

/// Samples an open mesh surface (a shell): one layer on it and `layers − 1` more offset by k·dp against
/// the normals.
pub fn mesh_samples(mesh: &TriMesh, dp: f64, layers: usize, seed: u64) -> (Samples, TriangleCoverage) {
    let ss = sample_surface(mesh, dp, seed);
    let mut s = Samples {
        pos: ss.points.clone(),
        normal: ss.normals.clone(),
        area: ss.areas.clone(),
        volume: vec![],
    };
    for k in 1..layers.max(1) {
        for i in 0..ss.points.len() {
            s.pos.push(ss.points[i] - ss.normals[i] * (k as f64 * dp));
            s.normal.push(ss.normals[i]);
            s.area.push(0.0);
        }
    }
    (s, ss.coverage)
}

/// Samples the solid enclosed by a closed mesh: the surface samples moved inside along the outward
/// normals, in `layers` layers at depths (k + ½)·dp, each with the outward normal (into the fluid). The
/// mesh may be oriented either way (the sign of its enclosed volume tells). A sample of a deeper layer is
/// kept only inside the solid and no nearer to another part of the surface than half a spacing less than
/// its depth: where faces meet at an edge, or the solid is thinner than the layers, the nearest face's
/// samples fill the space and no particle ends up outside. Volumes: see [`solid_volumes`].
pub fn solid_samples(mesh: &TriMesh, dp: f64, layers: usize, seed: u64) -> (Samples, TriangleCoverage) {
    let ss = sample_surface(mesh, dp, seed);
    let outward = if mesh.signed_volume() < 0.0 { -1.0 } else { 1.0 };
    let bvh = TriBvh::build(mesh);
    let mut s = Samples::default();
    let mut layer = Vec::new();
    for k in 0..layers.max(1) {
        let depth = (k as f64 + 0.5) * dp;
        for i in 0..ss.points.len() {
            let n = ss.normals[i] * outward;
            let p = ss.points[i] - n * depth;
            if k > 0 {
                let inside = bvh.contains_point(mesh, p);
                let crowded = bvh.closest_point(mesh, p, depth - 0.5 * dp).is_some();
                if !inside || crowded {
                    continue;
                }
            }
            s.pos.push(p);
            s.normal.push(n);
            s.area.push(if k == 0 { ss.areas[i] } else { 0.0 });
            s.volume.push(0.0);
            layer.push(k);
        }
    }
    solid_volumes(mesh, &bvh, &mut s, &layer, dp);
    (s, ss.coverage)
}

/// Probe lattice spacing of [`solid_volumes`] as a fraction of dp.
const VOLUME_PROBE: f64 = 0.25;

/// Volumes of solid samples by a probe lattice of spacing dp/4: every probe inside the solid and within
/// the depth of the layers goes to its nearest sample, and a sample's volume is its probe count times the
/// probe volume. The volumes therefore add up to the volume of the sampled shell (to the probe
/// resolution), overlapping slabs at edges are counted once, and irregular (gap-filled) samplings get
/// the volumes of their Voronoi cells. `layer[j]` is the layer of sample j (0 = first, dp/2 deep).
fn solid_volumes(mesh: &TriMesh, bvh: &TriBvh, s: &mut Samples, layer: &[usize], dp: f64) {
    let last = layer.iter().copied().max().unwrap_or(0);
    let mut grid = NeighbourGrid::new();
    grid.rebuild(&s.pos, dp);
    let step = VOLUME_PROBE * dp;
    let cell = step * step * step;
    // Probes are visited from every sample whose box (±reach) holds them and counted only for their
    // nearest sample, so each probe counts once.
    let reach = 0.75 * dp;
    let index = |x: f64| (x / step).floor() as i64;
    for (j, ((&x, &n), vol)) in s.pos.iter().zip(&s.normal).zip(s.volume.iter_mut()).enumerate() {
        let lo = [index(x.x - reach), index(x.y - reach), index(x.z - reach)];
        let hi = [index(x.x + reach), index(x.y + reach), index(x.z + reach)];
        let mut count = 0usize;
        for i in lo[0]..=hi[0] {
            for k in lo[1]..=hi[1] {
                for l in lo[2]..=hi[2] {
                    let q =
                        Vec3::new((i as f64 + 0.5) * step, (k as f64 + 0.5) * step, (l as f64 + 0.5) * step);
                    let d2 = (q - x).length_squared();
                    if d2 > reach * reach {
                        continue;
                    }
                    let mut nearest = true;
                    grid.for_each_run(q, |run| {
                        for &m in &grid.entries()[run] {
                            let m = m as usize;
                            let dm = (s.pos[m] - q).length_squared();
                            if m != j && (dm < d2 || (dm == d2 && m < j)) {
                                nearest = false;
                            }
                        }
                    });
                    if !nearest {
                        continue;
                    }
                    // Beyond the innermost layer: not part of the sampled shell.
                    if layer[j] == last && (q - x).dot(n) < -0.5 * dp {
                        continue;
                    }
                    // Only probes near the first layer can lie outside the solid.
                    if layer[j] == 0 && !bvh.contains_point(mesh, q) {
                        continue;
                    }
                    count += 1;
                }
            }
        }
        *vol = count as f64 * cell;
    }
}

/// All boundary particles, in canonical order (grouped by part).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Boundary {
    pub parts: Vec<Part>,
    /// Position in the part's reference frame.
    pub ref_pos: Vec<Vec3>,
    pub ref_normal: Vec<Vec3>,
    /// Particle volume \[m³, m² in 2D\].
    pub volume: Vec<f64>,
    /// Wall area represented \[m², m in 2D\].
    pub area: Vec<f64>,
    pub part: Vec<u16>,
    /// Current frame of every part (world position, velocity and so on of particle i follow from
    /// `frames[part[i]]` and its reference position).
    pub frames: Vec<Frame>,
    /// Wet at the last step.
    pub wet: Vec<bool>,
    /// Accumulated wet time \[s\].
    pub wet_time: Vec<f64>,
}

impl Boundary {
    pub fn len(&self) -> usize {
        self.ref_pos.len()
    }

    pub fn is_empty(&self) -> bool {
        self.ref_pos.is_empty()
    }

    /// Adds a part from samples given in its reference frame. Returns its index.
    #[allow(clippy::too_many_arguments)]
    pub fn add_part(
        &mut self,
        name: &str,
        node: Option<usize>,
        samples: Samples,
        surface: TriMesh,
        sampling: Sampling,
        adhesion: f64,
        slip: Slip,
        closed: bool,
    ) -> usize {
        let start = self.ref_pos.len();
        let idx = self.parts.len();
        let n = samples.pos.len();
        let centroid = if n > 0 { samples.pos.iter().copied().sum::<Vec3>() / n as f64 } else { Vec3::ZERO };
        self.ref_pos.extend(&samples.pos);
        self.ref_normal.extend(&samples.normal);
        self.area.extend(&samples.area);
        if samples.volume.len() == n {
            self.volume.extend(&samples.volume);
        } else {
            self.volume.extend(std::iter::repeat_n(0.0, n));
        }
        self.part.extend(std::iter::repeat_n(idx as u16, n));
        self.wet.extend(std::iter::repeat_n(false, n));
        self.wet_time.extend(std::iter::repeat_n(0.0, n));
        let bvh = TriBvh::build(&surface);
        self.parts.push(Part {
            name: name.to_owned(),
            node,
            surface,
            bvh,
            sampling,
            start,
            end: start + n,
            adhesion,
            slip,
            torque_point: centroid,
            closed,
        });
        self.frames.push(Frame::IDENTITY);
        idx
    }

    /// Particle volumes: dp^d for lattice parts, Akinci et al. (2012) `1/Σ_k W_bk` for shell mesh parts;
    /// solid mesh parts keep the volumes their sampling gave.
    pub fn compute_volumes(&mut self, kernel: &Kernel, dp: f64) {
        let v_lattice = dp.powi(kernel.dim.count());
        for p in &self.parts {
            let r = p.start..p.end;
            match p.sampling {
                Sampling::Lattice => self.volume[r].iter_mut().for_each(|v| *v = v_lattice),
                Sampling::Solid(_) => {}
                Sampling::Mesh(_) => {
                    let pts = &self.ref_pos[r.clone()];
                    let mut g = NeighbourGrid::new();
                    g.rebuild(pts, kernel.support());
                    let support2 = kernel.support() * kernel.support();
                    for (k, x) in pts.iter().enumerate() {
                        let mut s = 0.0;
                        g.for_each_run(*x, |run| {
                            for &j in &g.entries()[run] {
                                let d2 = (pts[j as usize] - *x).length_squared();
                                if d2 < support2 {
                                    s += kernel.w(d2.sqrt());
                                }
                            }
                        });
                        self.volume[p.start + k] = 1.0 / s;
                    }
                }
            }
        }
    }

    /// Moves every part to its placement at time `t`.
    pub fn update_kinematics(&mut self, tree: &KinematicTree, t: f64) {
        for (k, p) in self.parts.iter().enumerate() {
            self.frames[k] = Frame::of(tree, p.node, t);
        }
    }

    /// Current world position of particle `i`.
    #[inline]
    pub fn position(&self, i: usize) -> Vec3 {
        self.frames[self.part[i] as usize].to_world(self.ref_pos[i])
    }

    /// Current velocity of particle `i` \[m/s\].
    #[inline]
    pub fn velocity(&self, i: usize) -> Vec3 {
        let f = &self.frames[self.part[i] as usize];
        f.velocity(f.to_world(self.ref_pos[i]))
    }

    /// Current acceleration of particle `i` \[m/s²\].
    #[inline]
    pub fn acceleration(&self, i: usize) -> Vec3 {
        let f = &self.frames[self.part[i] as usize];
        f.acceleration(f.to_world(self.ref_pos[i]))
    }

    /// Current unit normal of particle `i`.
    #[inline]
    pub fn normal(&self, i: usize) -> Vec3 {
        self.frames[self.part[i] as usize].rot * self.ref_normal[i]
    }

    /// True when some part moves at time of the last kinematics update.
    pub fn any_moving(&self) -> bool {
        self.parts.iter().any(|p| p.node.is_some())
    }

    /// Largest boundary speed \[m/s\].
    pub fn max_speed(&self) -> f64 {
        let mut m: f64 = 0.0;
        for (k, p) in self.parts.iter().enumerate() {
            if p.node.is_none() {
                continue;
            }
            let f = &self.frames[k];
            for i in p.start..p.end {
                m = m.max(f.velocity(f.to_world(self.ref_pos[i])).length_squared());
            }
        }
        m.sqrt()
    }

    /// Bytes held per wall particle (capacities).
    pub fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.ref_pos.capacity() * size_of::<Vec3>()
            + self.ref_normal.capacity() * size_of::<Vec3>()
            + self.volume.capacity() * 8
            + self.area.capacity() * 8
            + self.part.capacity() * 2
            + self.wet.capacity()
            + self.wet_time.capacity() * 8
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_core::motion::Motion;

    #[test]
    fn tank_lattice_continues_the_fluid_lattice() {
        let dp = 0.1;
        let inner = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 0.5, 0.8));
        let s = tank_lattice(inner, [true, true, true, true, true, false], 3, dp, Dim::Three);
        // Expanded box (1.6 × 1.1 × 1.1 with open top) minus the inner 10 × 5 × 8 block.
        assert_eq!(s.pos.len(), 16 * 11 * 11 - 10 * 5 * 8);
        // Wetted area = floor + four walls.
        let a: f64 = s.area.iter().sum();
        assert!((a - (1.0 * 0.5 + 2.0 * 1.0 * 0.8 + 2.0 * 0.5 * 0.8)).abs() < 1e-9, "{a}");
        // The first layer below the floor sits dp/2 under it and faces up.
        let k = s
            .pos
            .iter()
            .position(|p| (p.z + 0.05).abs() < 1e-12 && p.x > 0.0 && p.x < 1.0 && p.y > 0.0 && p.y < 0.5)
            .unwrap();
        assert_eq!(s.normal[k], Vec3::Z);
        assert!(s.pos.iter().all(|p| !(p.x > 0.0
            && p.x < 1.0
            && p.y > 0.0
            && p.y < 0.5
            && p.z > 0.0
            && p.z < 0.8)));
        // 2D: x–z plane only.
        let s2 = tank_lattice(inner, [true; 6], 2, dp, Dim::Two);
        assert_eq!(s2.pos.len(), 14 * 12 - 10 * 8);
        assert!(s2.pos.iter().all(|p| p.y == 0.0));
    }

    #[test]
    fn block_lattice_area_is_the_block_surface() {
        let dp = 0.05;
        let b = Aabb::new(Vec3::ZERO, Vec3::new(0.5, 0.3, 0.2));
        let s = block_lattice(b, 2, dp, Dim::Three);
        let a: f64 = s.area.iter().sum();
        assert!((a - 2.0 * (0.15 + 0.1 + 0.06)).abs() < 1e-9, "{a}");
        // Every lattice point of the 10 × 6 × 4 block is within two spacings of a face.
        assert_eq!(s.pos.len(), 240);
    }

    #[test]
    fn frames_of_a_wheel_on_a_chassis() {
        let mut tree = KinematicTree::new();
        let chassis = tree.add(Motion::Translation { velocity: Vec3::new(2.0, 0.0, 0.0) }, None);
        let wheel = tree.add(Motion::rotation(Vec3::new(0.0, 0.0, 0.5), Vec3::Y, 4.0), Some(chassis));
        let f = Frame::of(&tree, Some(wheel), 0.25);
        let centre = f.to_world(Vec3::new(0.0, 0.0, 0.5));
        assert!((centre - Vec3::new(0.5, 0.0, 0.5)).length() < 1e-12);
        // Bottom point at rest, centripetal acceleration ω²R towards the centre.
        let bottom = centre - Vec3::new(0.0, 0.0, 0.5);
        assert!(f.velocity(bottom).length() < 1e-9);
        let a = f.acceleration(bottom);
        assert!((a - Vec3::new(0.0, 0.0, 8.0)).length() < 1e-6, "{a}");
        assert!(
            (f.to_reference(f.to_world(Vec3::new(0.3, 0.1, 0.2))) - Vec3::new(0.3, 0.1, 0.2)).length()
                < 1e-12
        );
    }

    #[test]
    fn box_surface_normals_point_the_requested_way() {
        let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let out = box_surface(b, [true; 6], false, Dim::Three);
        assert_eq!(out.triangles.len(), 12);
        assert!((out.signed_volume() - 1.0).abs() < 1e-12);
        let inward = box_surface(b, [true; 6], true, Dim::Three);
        assert!((inward.signed_volume() + 1.0).abs() < 1e-12);
    }

    /// Volume of the part of a box `[0, l]³` within `depth` of its surface.
    fn shell_volume(l: f64, depth: f64) -> f64 {
        let inner = (l - 2.0 * depth).max(0.0);
        l.powi(3) - inner.powi(3)
    }

    #[test]
    fn solid_samples_fill_the_shell_of_a_cube_once_whatever_its_orientation() {
        // The particle volumes of a solid must add up to the volume of the layers they sample (exact
        // geometry; tolerance 2 %, the resolution of the dp/4 volume probes at the 12 edges), every particle
        // lies inside, and the first layer lies dp/2 behind the faces. Outward and inward oriented
        // meshes give the same sampling.
        let dp = 0.01;
        for (cells, layers) in [(6.0, 3), (10.0, 3), (9.0, 2)] {
            let l = cells * dp;
            let b = Aabb::new(Vec3::ZERO, Vec3::splat(l));
            for inward in [false, true] {
                let mesh = box_surface(b, [true; 6], inward, Dim::Three);
                let (s, _) = solid_samples(&mesh, dp, layers, 7);
                let total: f64 = s.volume.iter().sum();
                let want = shell_volume(l, layers as f64 * dp);
                assert!(
                    (total - want).abs() < 0.02 * want,
                    "{cells} dp cube, {layers} layers, inward {inward}: {total} vs {want}"
                );
                for (k, p) in s.pos.iter().enumerate() {
                    let depth =
                        [p.x, p.y, p.z, l - p.x, l - p.y, l - p.z].into_iter().fold(f64::INFINITY, f64::min);
                    assert!(depth > 0.0, "particle {k} at {p} is outside");
                    if s.area[k] > 0.0 {
                        assert!((depth - 0.5 * dp).abs() < 1e-9, "first-layer particle {k} at depth {depth}");
                        assert!(
                            s.normal[k].dot(*p - Vec3::splat(0.5 * l)) > 0.0,
                            "normal of {k} points inward"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_solid_thinner_than_its_layers_has_no_particle_outside() {
        // A plate 1.5 dp thick sampled with 3 layers: deeper layers from both faces would cross; they
        // are dropped, and the volumes still add up to the plate's volume (2 %, as above).
        let dp = 0.01;
        let b = Aabb::new(Vec3::ZERO, Vec3::new(0.1, 0.1, 1.5 * dp));
        let mesh = box_surface(b, [true; 6], false, Dim::Three);
        let (s, _) = solid_samples(&mesh, dp, 3, 3);
        for p in &s.pos {
            assert!(b.contains(*p), "{p} outside the plate");
        }
        let total: f64 = s.volume.iter().sum();
        let want = 0.1 * 0.1 * 1.5 * dp;
        assert!((total - want).abs() < 0.02 * want, "{total} vs {want}");
    }
}
