//! Sample impacts of a regime map as ParaView time series: the two grid impacts on either side of the
//! stick/bounce boundary at the smallest diameter, traced step by step and written as particle VTU files
//! with a `.pvd` collection each, beside a VTU patch of the wall (the plane z = 0).

use super::impact::TracePoint;
use super::model::{ImpactModel, Surface};
use super::runner::SnowError;
use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;
use spatter_io::pvd::PvdSeries;
use spatter_io::run::RunDir;
use spatter_io::vtu::Vtu;
use std::path::PathBuf;

/// Largest number of frames written per sample impact (the trace is thinned evenly to this).
const MAX_FRAMES: usize = 120;

/// Traces the impacts `(diameter, normal speed, label)` and writes `samples/<label>_NNNN.vtu`,
/// `samples/<label>.pvd` and `samples/wall.vtu`. Returns the artifacts to show the user.
pub fn write_sample_impacts(
    model: &ImpactModel,
    impacts: &[(f64, f64, &str)],
    dir: &RunDir,
) -> Result<Vec<(String, PathBuf)>, SnowError> {
    let mut artifacts = Vec::new();
    let mut largest = 0.0f64;
    for &(d, v_n, label) in impacts {
        largest = largest.max(d);
        let mut trace: Vec<TracePoint> = Vec::new();
        let (result, _) =
            model.simulate_traced(d, v_n, 0.0, [0.0, 0.0], Surface::Configured, Some(&mut trace));
        let stride = trace.len().div_ceil(MAX_FRAMES).max(1);
        let pvd_path = dir.path(&format!("samples/{label}.pvd"));
        let mut pvd = PvdSeries::new(&pvd_path);
        for (k, p) in trace.iter().step_by(stride).enumerate() {
            let name = format!("{label}_{k:04}.vtu");
            Vtu::point_cloud(&[Vec3::from_array(p.position)])
                .point_scalar("radius_m", &[0.5 * d])
                .point_vector("velocity_m_s", &[Vec3::from_array(p.velocity)])
                .point_scalar("normal_force_N", &[p.normal_force])
                .point_scalar("overlap_m", &[if p.overlap.is_finite() { p.overlap } else { 0.0 }])
                .write(&dir.path(&format!("samples/{name}")))?;
            pvd.push(p.t, &name)?;
        }
        artifacts.push((
            format!("sample impact d = {d:.3e} m at {v_n:.4} m/s ({:?}), ParaView series", result.outcome),
            pvd_path,
        ));
    }
    // A wall patch a few diameters wide under the impact point.
    let half = 3.0 * largest;
    let mut wall = TriMesh::rectangle(2.0 * half, 2.0 * half, 0.0, 4, 4);
    wall.map_vertices(|v| v - Vec3::new(half, half, 0.0));
    let wpath = dir.path("samples/wall.vtu");
    Vtu::triangles(&wall.vertices, &wall.triangles).write(&wpath)?;
    artifacts.push(("wall patch for the sample impacts (VTU)".into(), wpath));
    Ok(artifacts)
}
