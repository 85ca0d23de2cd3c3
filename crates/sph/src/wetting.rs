//! Wetting maps at wall-particle resolution, independent of the surface mesh (marking a whole triangle wet
//! when any particle touches it blurs the map and makes it change with the mesh size).
//!
//! Every first-layer wall particle carries its wet flag and accumulated wet time. A mesh part's triangles
//! get the area-weighted mean of the particles covering them (see [`spatter_core::surface_sample`]): a
//! coarse triangle touched by one droplet is only partly wet, so the wet area does not grow with the
//! triangle size. Lattice parts (boxes) are drawn as one square of side dp per wall particle.

use crate::boundary::Sampling;
use crate::sim::Simulation;
use rayon::prelude::*;
use spatter_core::math::orthonormal_basis;
use spatter_core::mesh::TriMesh;
use spatter_core::{Aabb, Vec3};
use std::collections::HashMap;

/// A wall's wetting map in world coordinates.
#[derive(Clone, Debug)]
pub struct WettingMap {
    pub mesh: TriMesh,
    /// Wet fraction of each triangle now \[0–1\].
    pub wet_now: Vec<f64>,
    /// Fraction of the elapsed time each triangle was wet \[0–1\].
    pub wet_time_fraction: Vec<f64>,
}

/// Wetted areas of one wall.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WetArea {
    /// Wall area \[m², m per metre of depth in 2D\].
    pub area: f64,
    /// Area wet now.
    pub wet_now: f64,
    /// Time-averaged wet area (Σ area · wet time / elapsed).
    pub wet_mean: f64,
}

/// Wetted areas of part `k` after `elapsed` seconds.
pub fn wet_area(sim: &Simulation, k: usize, elapsed: f64) -> WetArea {
    let part = &sim.boundary.parts[k];
    let b = &sim.boundary;
    let mut w = WetArea::default();
    for i in part.start..part.end {
        let a = b.area[i];
        w.area += a;
        if b.wet[i] {
            w.wet_now += a;
        }
        if elapsed > 0.0 {
            w.wet_mean += a * b.wet_time[i] / elapsed;
        }
    }
    w
}

/// The water at one wall now.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PartWater {
    /// Volume of the water within the part's wet reach \[m³; m² per metre of depth in 2D\].
    pub volume: f64,
    /// Rate at which that water arrives at the surface \[m³/s; m²/s in 2D\].
    pub arrival: f64,
}

/// The water at part `k` now. `volume`: the fluid within the part's wet reach `d` of its surface, Σ m/ρ —
/// the reach of the wet flag (`wet_distance` plus the part's [`Sampling::wet_reach`]), measured from the
/// surface points its first-layer particles stand for ([`Sampling::surface_offset`] along the normal).
/// `arrival`: the rate at which water reaches the surface, Σ (m/ρ) · max(0, −(v − v_w)·n) / d over the
/// same particles, with the normal n and the velocity v_w of the nearest surface point — a layer d thick
/// approaching at u_n delivers (m/ρ) u_n / d per second. Summed in particle order (the result does not
/// depend on the thread count).
pub fn part_water(sim: &Simulation, k: usize) -> PartWater {
    let b = &sim.boundary;
    let part = &b.parts[k];
    let p = &sim.params;
    let d = p.wet_distance + part.sampling.wet_reach(p.spacing);
    let surface: Vec<usize> = (part.start..part.end).filter(|&i| b.area[i] > 0.0).collect();
    if surface.is_empty() || d.is_nan() || d <= 0.0 {
        return PartWater::default();
    }
    let offset = part.sampling.surface_offset(p.spacing);
    let pos: Vec<Vec3> = surface.iter().map(|&i| b.position(i) + b.normal(i) * offset).collect();
    let reach = Aabb::from_points(&pos).inflated(d);
    let cell = |x: Vec3| ((x.x / d).floor() as i64, (x.y / d).floor() as i64, (x.z / d).floor() as i64);
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::new();
    for (j, &x) in pos.iter().enumerate() {
        grid.entry(cell(x)).or_default().push(j as u32);
    }
    let f = &sim.fluid;
    let near: Vec<usize> = (0..f.len()).into_par_iter().filter(|&i| reach.contains(f.pos[i])).collect();
    let mut w = PartWater::default();
    let m = p.mass();
    for i in near {
        let x = f.pos[i];
        let (cx, cy, cz) = cell(x);
        let mut best: Option<(f64, usize)> = None;
        for (dx, dy, dz) in
            (-1..=1).flat_map(|a| (-1..=1).flat_map(move |b| (-1..=1).map(move |c| (a, b, c))))
        {
            for &j in grid.get(&(cx + dx, cy + dy, cz + dz)).map_or(&[][..], |v| v) {
                let r2 = (pos[j as usize] - x).length_squared();
                if r2 < d * d && best.is_none_or(|(b2, _)| r2 < b2) {
                    best = Some((r2, j as usize));
                }
            }
        }
        let Some((_, j)) = best else { continue };
        let s = surface[j];
        let vol = m / f.rho[i];
        w.volume += vol;
        let un = -(f.vel[i] - b.velocity(s)).dot(b.normal(s));
        if un > 0.0 {
            w.arrival += vol * un / d;
        }
    }
    w
}

/// Wetting map of part `k` after `elapsed` seconds.
pub fn wetting_map(sim: &Simulation, k: usize, elapsed: f64) -> WettingMap {
    let part = &sim.boundary.parts[k];
    let b = &sim.boundary;
    let frame = b.frames[k];
    let t = elapsed.max(f64::MIN_POSITIVE);
    match &part.sampling {
        Sampling::Mesh(cov) | Sampling::Solid(cov) => {
            let n = part.end - part.start;
            let now: Vec<f64> = (0..n).map(|s| if b.wet[part.start + s] { 1.0 } else { 0.0 }).collect();
            let frac: Vec<f64> = (0..n).map(|s| (b.wet_time[part.start + s] / t).min(1.0)).collect();
            let mut mesh = part.surface.clone();
            mesh.map_vertices(|v| frame.to_world(v));
            WettingMap {
                mesh,
                wet_now: cov.triangle_means(&now),
                wet_time_fraction: cov.triangle_means(&frac),
            }
        }
        Sampling::Lattice => {
            let dp = sim.params.spacing;
            let mut soup = Vec::new();
            let (mut now, mut frac) = (Vec::new(), Vec::new());
            for i in part.start..part.end {
                if b.area[i] <= 0.0 {
                    continue;
                }
                let n = b.normal(i);
                // First-layer lattice particles sit dp/2 behind the face they stand for.
                let c = b.position(i) + n * (0.5 * dp);
                let (u, v) = orthonormal_basis(n);
                let (u, v) = (u * (0.5 * dp), v * (0.5 * dp));
                let (p0, p1, p2, p3) = (c - u - v, c + u - v, c + u + v, c - u + v);
                soup.extend([p0, p1, p2, p0, p2, p3]);
                let wet = if b.wet[i] { 1.0 } else { 0.0 };
                let f = (b.wet_time[i] / t).min(1.0);
                now.extend([wet, wet]);
                frac.extend([f, f]);
            }
            // Keep the squares separate (no welding across shared corners changes nothing visible).
            let mesh = TriMesh {
                vertices: soup.clone(),
                triangles: (0..soup.len() / 3)
                    .map(|k| [3 * k as u32, 3 * k as u32 + 1, 3 * k as u32 + 2])
                    .collect(),
            };
            WettingMap { mesh, wet_now: now, wet_time_fraction: frac }
        }
    }
}

/// Wetting of part `k` at wall-particle resolution: one square per first-layer wall particle, centred on
/// the wall surface, with the area the particle stands for (used for the pictures: sharp whatever the
/// triangulation). Returns the squares and, per triangle, the wet-time fraction.
pub fn particle_map(sim: &Simulation, k: usize, elapsed: f64) -> (TriMesh, Vec<f64>) {
    let t = elapsed.max(f64::MIN_POSITIVE);
    let wet_time = &sim.boundary.wet_time;
    particle_squares(sim, k, |i| (wet_time[i] / t).min(1.0))
}

/// The squares of [`particle_map`] (one per first-layer wall particle of part `k`, where the particles
/// are now) with `value(i)` of boundary particle `i` on both triangles of its square; e.g. the wet flag
/// for a map of the wetting at one moment.
pub fn particle_squares(sim: &Simulation, k: usize, value: impl Fn(usize) -> f64) -> (TriMesh, Vec<f64>) {
    let part = &sim.boundary.parts[k];
    let b = &sim.boundary;
    let dp = sim.params.spacing;
    let offset = part.sampling.surface_offset(dp);
    let mut soup = Vec::new();
    let mut values = Vec::new();
    for i in part.start..part.end {
        let a = b.area[i];
        if a <= 0.0 {
            continue;
        }
        let n = b.normal(i);
        // Lattice and solid particles sit dp/2 behind the face they stand for; shell samples lie on it.
        let c = b.position(i) + n * offset;
        let side = if sim.params.dim == crate::kernel::Dim::Two { dp } else { a.sqrt() };
        let (u, v) = orthonormal_basis(n);
        let (u, v) = (u * (0.5 * side), v * (0.5 * side));
        let (p0, p1, p2, p3) = (c - u - v, c + u - v, c + u + v, c - u + v);
        soup.extend([p0, p1, p2, p0, p2, p3]);
        let f = value(i);
        values.extend([f, f]);
    }
    let mesh = TriMesh {
        vertices: soup.clone(),
        triangles: (0..soup.len() / 3).map(|q| [3 * q as u32, 3 * q as u32 + 1, 3 * q as u32 + 2]).collect(),
    };
    (mesh, values)
}

/// A view direction and up vector that look at the part's main face.
pub fn default_view(sim: &Simulation, k: usize) -> (Vec3, Vec3) {
    let part = &sim.boundary.parts[k];
    let b = &sim.boundary;
    let mut n = Vec3::ZERO;
    for i in part.start..part.end {
        n += b.normal(i) * b.area[i];
    }
    let total: f64 = b.area[part.start..part.end].iter().sum();
    let mean = if total > 0.0 { n / total } else { Vec3::ZERO };
    // Containers (normals pointing inwards, open top) are seen from above; other walls face the viewer
    // with their mean normal.
    let view = if mean.length() > 0.3 {
        -mean.normalize()
    } else if mean.z > 0.0 {
        -Vec3::Z
    } else {
        Vec3::new(0.3, 1.0, -0.4).normalize()
    };
    let up = if view.z.abs() > 0.9 { Vec3::Y } else { Vec3::Z };
    (view, up)
}
