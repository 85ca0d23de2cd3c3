//! `spatter bench track`: parcel-steps per second of the tracker in an unstructured field.
//!
//! The field is a jittered Kuhn tetrahedral mesh of the unit cube (6 n³ tetrahedra: about 10⁶ for
//! n = 55) carrying a cellular flow u = U₀ (sin πx cos πz, 0.3 sin 2πy, −cos πx sin πz) at its points,
//! built through the import path (`ImportedField::from_dataset`). 10⁶ parcels of 50 µm ice start at
//! uniformly random points; forces are Schiller–Naumann drag and gravity; Δt = 1 ms (a parcel moves
//! about a quarter of a cell per step). The benchmark runs with 1 and 2 threads and also times the
//! point location alone (the same positions and hints the next step starts from).
//!
//! The rotor case ([`rotor_bench`]) tracks sand parcels in the analytic rotor downwash of the Bell 47 at
//! z_d/R = 0.68 (Jasion 2013 Ch. 6) with the mean flow alone, with the tabulated tip vortices and with
//! the directly summed tip vortices, one worker thread, and prints parcel-steps per CPU-second of each
//! on its own row with its cost relative to the mean flow (the tabulated vortices aim at ≤ 2×).

use crate::field::analytic::{AnalyticField, AnalyticSet};
use crate::field::rotor::RotorDownwash;
use crate::field::tetmesh::{kuhn_box, TetMesh};
use crate::field::{FieldError, ImportOptions, ImportedField};
use crate::forces::model::{ForceModel, ForceSwitches};
use crate::forces::Fluid;
use crate::tracker::inject::NewParcel;
use crate::tracker::{Parcel, TrackSettings, Tracker, CHUNK};
use rayon::prelude::*;
use spatter_core::rng::{seeded, RngExt};
use spatter_core::{Aabb, Vec3};
use spatter_io::vtk::{cell_type, DataArray, VtkDataset};
use std::time::Instant;

fn cellular(p: Vec3) -> Vec3 {
    use std::f64::consts::PI;
    5.0 * Vec3::new(
        (PI * p.x).sin() * (PI * p.z).cos(),
        0.3 * (2.0 * PI * p.y).sin(),
        -(PI * p.x).cos() * (PI * p.z).sin(),
    )
}

/// The benchmark field with about 6 n³ tetrahedra.
pub fn bench_field(n: usize) -> Result<ImportedField, FieldError> {
    let (points, tets) = kuhn_box(Vec3::ZERO, Vec3::ONE, [n, n, n], 0.3);
    let mut ds = VtkDataset { cell_offsets: Vec::with_capacity(tets.len() + 1), ..Default::default() };
    ds.cell_offsets.push(0);
    for t in &tets {
        ds.connectivity.extend_from_slice(t);
        ds.cell_types.push(cell_type::TETRA);
        ds.cell_offsets.push(ds.connectivity.len());
    }
    let u: Vec<f64> = points.iter().flat_map(|p| cellular(*p).to_array()).collect();
    ds.points = points;
    ds.point_data.push(DataArray { name: "U".into(), components: 3, values: u });
    ImportedField::from_dataset(&ds, &ImportOptions::default())
}

/// CPU time of the calling thread \[ns\] (Linux `/proc/thread-self/schedstat`), to tell a loaded machine
/// from a slow tracker: with one worker thread, parcel-steps per CPU-second is what an idle core does.
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

fn mesh_bytes(m: &TetMesh) -> usize {
    m.points.len() * 24 + m.tets.len() * (16 + 16 + 4)
}

/// Runs the unstructured-field benchmark and returns the printable lines. `quick`: 10⁵ parcels in about
/// 10⁵ tetrahedra.
pub fn unstructured_bench(quick: bool) -> Result<Vec<String>, FieldError> {
    let (n_mesh, n_parcels, steps) = if quick { (25, 100_000, 3) } else { (55, 1_000_000, 5) };
    let t0 = Instant::now();
    let field = bench_field(n_mesh)?;
    let setup = t0.elapsed().as_secs_f64();
    let mut lines = vec![format!(
        "track: field {} tetrahedra ({} points) from an unstructured import, built in {:.2} s; {} parcels of 50 µm ice, Schiller–Naumann drag + gravity, dt = 1 ms",
        field.mesh.tets.len(),
        field.mesh.points.len(),
        setup,
        n_parcels
    )];
    let mut rng = seeded(2024, 0);
    let starts: Vec<Vec3> = (0..n_parcels)
        .map(|_| {
            Vec3::new(
                0.02 + 0.96 * rng.random::<f64>(),
                0.02 + 0.96 * rng.random::<f64>(),
                0.02 + 0.96 * rng.random::<f64>(),
            )
        })
        .collect();
    let mut per_thread = Vec::new();
    for threads in [1usize, 2] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .map_err(|e| FieldError::Config(e.to_string()))?;
        let (rate, step_ms, loc_ms, cpu_rate, sort_ms) = pool.install(|| {
            let model = ForceModel::new(Fluid::default(), ForceSwitches::default());
            let settings = TrackSettings {
                dt: 1e-3,
                domain: None,
                dispersion: None,
                max_bounces: 8,
                resort_interval: 20,
            };
            let mut tr = Tracker::new(&field, model, settings, vec![]);
            for &x in &starts {
                tr.add(
                    NewParcel { pos: x, vel: cellular(x), diameter: 50e-6, density: 917.0, count: 1.0 },
                    0,
                );
            }
            // Warm-up: the first step finds every parcel through the bins; then the periodic re-sort by
            // cell that the tracker does every `resort_interval` steps (timed separately).
            let _ = tr.step();
            let t = Instant::now();
            tr.sort_parcels();
            let sort_s = t.elapsed().as_secs_f64();
            let t = Instant::now();
            let cpu0 = thread_cpu_ns();
            for _ in 0..steps {
                let _ = tr.step();
            }
            let step_s = t.elapsed().as_secs_f64() / steps as f64;
            let cpu_s = match (cpu0, thread_cpu_ns()) {
                (Some(a), Some(b)) if threads == 1 => Some((b - a) as f64 * 1e-9 / steps as f64),
                _ => None,
            };
            // Location alone, from the state the next step starts in.
            let snapshot: Vec<(Vec3, u32)> =
                tr.state.parcels.iter().map(|p: &Parcel| (p.pos, p.hint)).collect();
            let mut hints: Vec<u32> = snapshot.iter().map(|s| s.1).collect();
            let t = Instant::now();
            let found: usize = hints
                .par_chunks_mut(CHUNK)
                .zip(snapshot.par_chunks(CHUNK))
                .map(|(h, s)| {
                    let mut n = 0;
                    for (hint, (x, _)) in h.iter_mut().zip(s) {
                        n += usize::from(field.mesh.locate(*x, hint).is_some());
                    }
                    n
                })
                .sum();
            let loc_s = t.elapsed().as_secs_f64();
            let airborne = tr.airborne();
            let rate = airborne as f64 / step_s;
            let _ = found;
            (rate, step_s * 1e3, loc_s * 1e3, cpu_s.map(|c| airborne as f64 / c), sort_s * 1e3)
        });
        let (rate, step_ms, loc_ms, cpu_rate, sort_ms) = (rate, step_ms, loc_ms, cpu_rate, sort_ms);
        lines.push(format!(
            "track: {threads} thread{}: {:.3e} parcel-steps/s ({:.1} ms per step; point location {:.1} ms = {:.0} % of it; re-sort {:.1} ms every 20 steps){}",
            if threads == 1 { "" } else { "s" },
            rate,
            step_ms,
            loc_ms,
            100.0 * loc_ms / step_ms,
            sort_ms,
            cpu_rate.map(|r| format!("; {r:.3e} parcel-steps per CPU-second")).unwrap_or_default()
        ));
        per_thread.push(rate);
    }
    lines.push(format!(
        "track: speed-up 1 → 2 threads {:.2}×; memory {} B per parcel, {:.0} B per tetrahedron",
        per_thread[1] / per_thread[0],
        std::mem::size_of::<Parcel>(),
        mesh_bytes(&field.mesh) as f64 / field.mesh.tets.len() as f64
    ));
    Ok(lines)
}

/// [`unstructured_bench`] followed by [`rotor_bench`] (`spatter bench track`).
pub fn bench(quick: bool) -> Result<Vec<String>, FieldError> {
    let mut lines = unstructured_bench(quick)?;
    lines.extend(rotor_bench(quick)?);
    Ok(lines)
}

/// Parcel-steps per CPU-second (one worker thread) of `steps` steps of the parcels `starts` in `rotor`,
/// and the wall time of the first step (which builds the tip-vortex table when there is one).
fn rotor_rate(rotor: &RotorDownwash, starts: &[Vec3], steps: usize) -> Result<(f64, f64), FieldError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .map_err(|e| FieldError::Config(e.to_string()))?;
    let field = AnalyticSet { parts: vec![AnalyticField::Rotor(rotor.clone())], turbulence: None };
    Ok(pool.install(|| {
        let model = ForceModel::new(
            crate::forces::Fluid { density: rotor.air_density_kg_m3, viscosity: 1.82e-5 },
            ForceSwitches::default(),
        );
        let r = rotor.radius_m;
        let domain =
            Aabb::new(Vec3::new(-6.0 * r, -6.0 * r, rotor.ground_z_m), Vec3::new(6.0 * r, 6.0 * r, 3.0 * r));
        let settings = TrackSettings {
            dt: 1e-3,
            domain: Some(domain),
            dispersion: None,
            max_bounces: 8,
            resort_interval: 0,
        };
        let t = Instant::now();
        let _ = rotor.tabulated_vortices();
        let setup = t.elapsed().as_secs_f64();
        let mut tr = Tracker::new(&field, model, settings, vec![]);
        for &x in starts {
            tr.add(
                NewParcel {
                    pos: x,
                    vel: field.velocity(x, 0.0),
                    diameter: 20e-6,
                    density: 2480.0,
                    count: 1.0,
                },
                0,
            );
        }
        let cpu0 = thread_cpu_ns();
        let t = Instant::now();
        let mut parcel_steps = 0usize;
        for _ in 0..steps {
            parcel_steps += tr.airborne();
            let _ = tr.step();
        }
        let wall = t.elapsed().as_secs_f64();
        let secs = match (cpu0, thread_cpu_ns()) {
            (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
            _ => wall,
        };
        (parcel_steps as f64 / secs.max(1e-12), setup)
    }))
}

/// The rotor benchmark: 20 µm sand parcels (2480 kg/m³) spread over 0.3 < r/R < 2.5 and 0 < z < z_hub
/// under the Bell 47 at z_d/R = 0.68 (T = 8.8 kN, R = 5.66 m, Ω = 35.6 rad/s, 10 revolutions of tip
/// vortices), Schiller–Naumann drag and gravity, Δt = 1 ms, one thread. The mean flow and the tabulated
/// vortices are timed alternately, [`ROTOR_ROUNDS`] times each, and the fastest round of each is kept (a
/// busy machine only ever slows a round down). `quick`: fewer steps.
pub fn rotor_bench(quick: bool) -> Result<Vec<String>, FieldError> {
    // The quick run keeps the parcel count: with a tenth of the parcels their state fits in the core's
    // cache and the mean flow alone runs faster, which is not the regime of a brownout cloud.
    let (n, steps, n_direct, steps_direct) = if quick { (20_000, 5, 200, 2) } else { (20_000, 20, 1000, 3) };
    let mut rotor = RotorDownwash::bell47(0.68);
    let mut rng = seeded(2025, 1);
    let r0 = rotor.radius_m;
    let starts: Vec<Vec3> = (0..n)
        .map(|_| {
            let r = r0 * (0.3 + 2.2 * rng.random::<f64>());
            let a = std::f64::consts::TAU * rng.random::<f64>();
            Vec3::new(r * a.cos(), r * a.sin(), 0.01 + (rotor.hub_m.z - 0.01) * rng.random::<f64>())
        })
        .collect();
    let mut vortices = rotor.clone();
    vortices.tip_vortices = true;
    let (mut mean, mut table, mut build) = (0.0f64, 0.0f64, None);
    for _ in 0..ROTOR_ROUNDS {
        mean = mean.max(rotor_rate(&rotor, &starts, steps)?.0);
        let (rate, setup) = rotor_rate(&vortices, &starts, steps)?;
        table = table.max(rate);
        // The first round builds the table; later rounds find it built.
        build.get_or_insert(setup);
    }
    let build = build.unwrap_or(0.0);
    let nodes = vortices.tabulated_vortices().map(|t| (t.nodes(), t.bytes())).unwrap_or((0, 0));
    rotor = vortices;
    rotor.vortex_table = false;
    let (direct, _) = rotor_rate(&rotor, &starts[..n_direct], steps_direct)?;
    Ok(vec![
        format!(
            "track rotor: Bell 47 at z_d/R = 0.68, {n} parcels of 20 µm sand, dt = 1 ms, {steps} steps, 1 thread, parcel-steps per CPU-second (fastest of {ROTOR_ROUNDS} alternating rounds):"
        ),
        format!("track rotor: mean flow                         {mean:.3e} parcel-steps per CPU-second"),
        format!(
            "track rotor: mean flow + tabulated tip vortices  {table:.3e} parcel-steps per CPU-second ({:.2}× the cost of the mean flow; target ≤ 2×; table {} nodes, {:.1} MB, built in {build:.2} s)",
            mean / table,
            nodes.0,
            nodes.1 as f64 / 1e6,
        ),
        format!(
            "track rotor: mean flow + tip vortices summed     {direct:.3e} parcel-steps per CPU-second ({:.0}× the cost of the mean flow; {n_direct} parcels)",
            mean / direct
        ),
    ])
}

/// Alternating timing rounds of the rotor benchmark's mean flow and tabulated vortices.
const ROTOR_ROUNDS: usize = 3;

#[cfg(test)]
mod tests {
    #[test]
    fn quick_bench_runs() {
        let lines = super::unstructured_bench(true).unwrap();
        assert_eq!(lines.len(), 4, "{lines:?}");
        assert!(lines[1].contains("parcel-steps/s"));
    }

    #[test]
    fn quick_rotor_bench_runs() {
        let lines = super::rotor_bench(true).unwrap();
        assert_eq!(lines.len(), 4, "{lines:?}");
        assert!(
            lines[1].contains("mean flow ") && lines[2].contains("tabulated") && lines[3].contains("summed")
        );
    }
}
