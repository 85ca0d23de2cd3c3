//! The gravelometer stone-chip test (DIN 55996-1, SAE J400) as a scenario kind: stones fed into an
//! accelerating pipe fly at an inclined coated panel; the result is the eroded mass on the panel, its
//! share per horizontal strip, and the impact statistics a test engineer compares with the standard's
//! photographs and high-speed films.
//!
//! The workflow composes the DEM scene: it generates the geometry (pipe, protection box, panel with its
//! strips, clamp) as triangle meshes, builds a `dem` scene with the stones as rigid multi-sphere
//! templates, an injector at the pipe inlet and Finnie wear on the panel, runs it through
//! [`crate::dem_scene::run_collect`] (checkpoints, resume and outputs as for any DEM scene) and reads the
//! results from the scene's records. Keys and outputs: `docs/gravelometer.md`.

pub mod air;
pub mod config;
pub mod coupled;
pub mod geometry;
mod results;
pub mod scene;

pub use config::{AirMode, GravelometerConfig, GravelometerInput, Standard, StoneShape};
pub use results::{Accounting, Statistics};

use spatter_core::control::Finished;
use spatter_dem::error::DemError;
use spatter_io::run::{RunContext, RunSummary};
use std::path::PathBuf;
use thiserror::Error;

/// Why a gravelometer run failed.
#[derive(Debug, Error)]
pub enum GravelometerError {
    /// A value that only shows as wrong once the stones are built (size against the pipe, feed rate).
    #[error("{key}: {message}")]
    Config { key: String, message: String },
    #[error(transparent)]
    Dem(#[from] DemError),
    #[error("{path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    /// The coupled air failed (a fluid step beyond its stability limit, a fluid file).
    #[error(transparent)]
    Coupled(#[from] crate::cfd_dem::partner::PartnerError),
}

/// Runs the scenario in `ctx`: the DEM scene's files plus the gravelometer results (see
/// `docs/gravelometer.md`).
pub fn run(cfg: &GravelometerConfig, ctx: &RunContext) -> Result<RunSummary, GravelometerError> {
    let plan = scene::plan(cfg)?;
    let comm = ctx.comm;
    if comm.size() > 1 && cfg.air() == AirMode::Coupled {
        return Err(GravelometerError::Config {
            key: "air".into(),
            message: format!(
                "\"coupled\" runs in one process in this version, and this run has {} ranks: use \"prescribed\" \
                 or \"none\" on ranks, or start the coupled run without mpirun",
                comm.size()
            ),
        });
    }
    let geo = ctx.dir.path("geometry");
    // On several ranks rank 0 writes the geometry and every rank reads it: all wait until it is written,
    // and a rank 0 that failed to write ends every rank.
    let strips = if comm.is_root() { scene::write_geometry(&plan, &geo) } else { Ok(scene::strips(&plan)) };
    if comm.size() > 1 {
        let mut failed = [u64::from(strips.is_err())];
        comm.all_sum_u64(&mut failed);
        if failed[0] > 0 && strips.is_ok() {
            return Err(GravelometerError::Config {
                key: "geometry".into(),
                message: "rank 0 could not write the geometry files (its error ends the run)".into(),
            });
        }
    }
    let strips = strips?;
    let scfg = scene::scene(cfg, &plan, &geo);
    tracing::info!(
        "gravelometer {}: {} stone template(s), mean diameter {:.2} mm, launch velocity ({:.2}, {:.2}, {:.2}) m/s, \
         feed {:.4} kg/s for {} s, dt = {:.3e} s",
        cfg.input.standard.label(),
        plan.stones.len(),
        plan.mean_diameter * 1e3,
        plan.launch.x,
        plan.launch.y,
        plan.launch.z,
        plan.kg_per_s,
        plan.feed_time,
        plan.dt
    );
    let hook = scene::air_forces(cfg, &plan);
    if let Some(a) = &plan.air {
        tracing::info!(
            "prescribed air: bulk {:.2} m/s, centreline {:.2} m/s, profile exponent {}, ramp {} s, outside the pipe: {:?}",
            a.bulk,
            a.centreline(),
            a.exponent,
            a.ramp,
            a.outside
        );
    }
    let (mut summary, results) = if cfg.air() == AirMode::Coupled {
        let dom = coupled::domain(cfg, &plan, &geo)?;
        let fluid = coupled::coupled_fluid(cfg, &dom)?;
        let x = &dom.grid.x;
        let (y, z) = (&dom.grid.y, dom.grid.z_axis());
        tracing::info!(
            "coupled air: grid {} × {} × {} cells of {} m over x [{}, {}] m, y [{}, {}] m, z [{}, {}] m; \
             turbulence {:?}; {} DEM steps per fluid step (Δt_f = {:.3e} s)",
            x.cells,
            y.cells,
            z.cells,
            config::get(cfg.input.coupled_air.cell_size_m),
            x.min_m,
            x.max_m,
            y.min_m,
            y.max_m,
            z.min_m,
            z.max_m,
            dom.turbulence,
            dom.substeps,
            dom.substeps as f64 * plan.dt
        );
        crate::dem_scene::run_collect_partnered(&scfg, ctx, None, fluid)?
    } else {
        crate::dem_scene::run_collect_with(&scfg, ctx, hook)?
    };
    // Rank 0 holds the whole records (mesh walls, events, bodies of every rank) and writes the results.
    let Some(r) = results else { return Ok(summary) };
    if summary.finished != Finished::Completed || !comm.is_root() {
        return Ok(summary);
    }
    results::report(cfg, &plan, &strips, &r, ctx, &mut summary)?;
    Ok(summary)
}

#[cfg(test)]
mod tests;
