//! Sample impacts of a regime map as ParaView time series: the two grid impacts on either side of the
//! stick/bounce boundary at the smallest diameter, traced step by step and written as particle VTU files
//! with a `.pvd` collection each, beside a VTU of the target they hit: a patch of the plane z = 0
//! (`wall.vtu`), the triangulated surface of the target sphere (`target_sphere.vtu`, frozen wall sphere or
//! free partner particle — the traces are relative to the partner, which therefore stays at the origin),
//! or the bed spheres as points with `radius_m` (`bed.vtu`).

use super::config::TargetKind;
use super::error::SnowError;
use super::impact::TracePoint;
use super::model::{ImpactModel, Surface};
use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;
use spatter_io::pvd::PvdSeries;
use spatter_io::run::RunDir;
use spatter_io::vtu::Vtu;
use std::path::PathBuf;

/// Largest number of frames written per sample impact (the trace is thinned evenly to this).
const MAX_FRAMES: usize = 120;

/// Traces the impacts `(diameter, normal speed, label)` on `surface` and writes `samples/<label>_NNNN.vtu`,
/// `samples/<label>.pvd` and the target geometry (see the module docs). Returns the artifacts to show the
/// user.
pub fn write_sample_impacts(
    model: &ImpactModel,
    surface: Surface<'_>,
    impacts: &[(f64, f64, &str)],
    dir: &RunDir,
) -> Result<Vec<(String, PathBuf)>, SnowError> {
    let mut artifacts = Vec::new();
    let mut largest = 0.0f64;
    for &(d, v_n, label) in impacts {
        largest = largest.max(d);
        let mut trace: Vec<TracePoint> = Vec::new();
        let (result, _) = model.simulate_traced(d, v_n, 0.0, [0.0, 0.0], surface, Some(&mut trace));
        let stride = trace.len().div_ceil(MAX_FRAMES).max(1);
        let pvd_path = dir.path(&format!("samples/{label}.pvd"));
        let mut pvd = PvdSeries::new(&pvd_path);
        for (k, p) in trace.iter().step_by(stride).enumerate() {
            let name = format!("{label}_{k:04}.vtu");
            Vtu::point_cloud(&[Vec3::from_array(p.position)])
                .point_scalar("radius_m", &[0.5 * d])
                .point_vector("velocity_m_s", &[Vec3::from_array(p.velocity)])
                .point_scalar("normal_force_N", &[p.normal_force])
                .point_scalar("overlap_m", &[p.overlap.unwrap_or(0.0)])
                .write(&dir.path(&format!("samples/{name}")))?;
            pvd.push(p.t, &name)?;
        }
        artifacts.push((
            format!("sample impact d = {d:.3e} m at {v_n:.4} m/s ({:?}), ParaView series", result.outcome),
            pvd_path,
        ));
    }
    artifacts.push(write_target(model, surface, largest, dir)?);
    Ok(artifacts)
}

/// Latitude and longitude divisions of the triangulated target sphere.
const SPHERE_RINGS: usize = 24;
const SPHERE_SEGMENTS: usize = 48;

/// A UV sphere of radius `radius` \[m\] centred at the origin: two poles and `rings − 1` latitude circles
/// of `segments` vertices, closed, outward-wound triangles.
pub fn uv_sphere(radius: f64, rings: usize, segments: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    use std::f64::consts::PI;
    let mut v = vec![Vec3::new(0.0, 0.0, radius)];
    for i in 1..rings {
        let th = PI * i as f64 / rings as f64;
        for j in 0..segments {
            let ph = 2.0 * PI * j as f64 / segments as f64;
            v.push(radius * Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
        }
    }
    v.push(Vec3::new(0.0, 0.0, -radius));
    let south = (v.len() - 1) as u32;
    let at = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
    let mut t = Vec::new();
    for j in 0..segments {
        t.push([0, at(1, j), at(1, j + 1)]);
        t.push([south, at(rings - 1, j + 1), at(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            t.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
            t.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
        }
    }
    (v, t)
}

/// Writes the geometry of what the sample impacts hit.
fn write_target(
    model: &ImpactModel,
    surface: Surface<'_>,
    largest: f64,
    dir: &RunDir,
) -> Result<(String, PathBuf), SnowError> {
    if let Surface::Bed { spheres, .. } = surface {
        let centres: Vec<Vec3> = spheres.iter().map(|q| Vec3::from(q.centre)).collect();
        let radii: Vec<f64> = spheres.iter().map(|q| q.radius).collect();
        let path = dir.path("samples/bed.vtu");
        Vtu::point_cloud(&centres).point_scalar("radius_m", &radii).write(&path)?;
        return Ok(("rough-wall bed of the sample impacts, points with radius_m (VTU)".into(), path));
    }
    match model.target {
        TargetKind::Wall => {
            // A wall patch a few diameters wide under the impact point.
            let half = 3.0 * largest;
            let mut wall = TriMesh::rectangle(2.0 * half, 2.0 * half, 0.0, 4, 4);
            wall.map_vertices(|v| v - Vec3::new(half, half, 0.0));
            let path = dir.path("samples/wall.vtu");
            Vtu::triangles(&wall.vertices, &wall.triangles).write(&path)?;
            Ok(("wall patch for the sample impacts (VTU)".into(), path))
        }
        TargetKind::WallSphere | TargetKind::Particle => {
            let radius = 0.5 * model.partner_diameter(largest);
            let (v, t) = uv_sphere(radius, SPHERE_RINGS, SPHERE_SEGMENTS);
            let path = dir.path("samples/target_sphere.vtu");
            Vtu::triangles(&v, &t).write(&path)?;
            let what = if model.target == TargetKind::Particle {
                "partner particle (at the origin of the relative traces)"
            } else {
                "frozen wall sphere"
            };
            Ok((format!("{what} of radius {radius:.3e} m for the sample impacts (VTU)"), path))
        }
    }
}
