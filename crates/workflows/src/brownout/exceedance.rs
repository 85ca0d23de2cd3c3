//! The Shields exceedance map: along the ground, for every grain size of the lift-off map, the fraction
//! of the unsteady window (one shedding period of the analytic tip vortices, or the period or span of an
//! imported time series) during which the Shields parameter θ = τ_w/(ρ_p g D) exceeds θ*
//! (Jasion 2013 §4.5 and §5.3: how often a place can entrain; a steady field gives 0 or 1).
//!
//! Outputs: `shields_exceedance.csv` (`r_m`, `r_over_R`, `d_um`, `fraction_above`, `mean_shields`,
//! `max_shields`, `shields_critical`) and `shields_exceedance.png` (r/R × grain size, banded by the
//! fraction).

use super::config::BrownoutConfig;
use rayon::prelude::*;
use spatter_flow::field::FlowField;
use spatter_flow::liftoff::ground_shear::{exceedance_table, ground_shear, GroundProbe, GroundShear};
use spatter_io::plot::Chart;
use spatter_io::run::{RunContext, RunSummary};

/// Computes the map on `field` at `times` (the lift-off map's ground points and diameters, the gust
/// factor `liftoff.exceedance_gust_factor`) and writes its CSV and PNG.
pub fn write<F: FlowField>(
    cfg: &BrownoutConfig,
    ctx: &RunContext,
    field: &F,
    probe: &GroundProbe,
    times: Vec<f64>,
    summary: &mut RunSummary,
) -> std::io::Result<()> {
    let lo = &cfg.liftoff;
    let r0 = cfg.rotor.radius_m;
    let rho_p = cfg.ground.density_kg_m3;
    let probe = GroundProbe { gust: lo.exceedance_gust_factor, ..probe.clone() };
    // One wall-shear profile per time, computed in parallel (the order of the collected series is the
    // order of `times`, so the result does not depend on the thread count).
    let series: Vec<Vec<GroundShear>> =
        times.par_iter().map(|&t| ground_shear(field, &probe, t, &cfg.air)).collect();
    let table = exceedance_table(&series, &lo.diameters_m, rho_p, 9.81, lo.shields_critical);
    let mut rows = Vec::new();
    let mut bands: [Vec<(f64, f64)>; 5] = Default::default();
    for (i, row) in table.iter().enumerate() {
        let r = probe.distances[i];
        for (k, e) in row.iter().enumerate() {
            let d = lo.diameters_m[k];
            rows.push(
                [r, r / r0, d * 1e6, e.fraction, e.mean, e.max, lo.shields_critical]
                    .iter()
                    .map(|&v| spatter_io::fmt_f64(v))
                    .collect::<Vec<_>>(),
            );
            let band = match e.fraction {
                f if f <= 0.0 => 0,
                f if f < 0.25 => 1,
                f if f < 0.5 => 2,
                f if f < 0.75 => 3,
                _ => 4,
            };
            bands[band].push((r / r0, d * 1e6));
        }
    }
    let csv = ctx.dir.path("shields_exceedance.csv");
    spatter_io::csv::write_table(
        &csv,
        &["r_m", "r_over_R", "d_um", "fraction_above", "mean_shields", "max_shields", "shields_critical"],
        &rows,
    )?;
    let span = match (times.first(), times.last()) {
        (Some(a), Some(b)) if times.len() > 1 => (b - a) * times.len() as f64 / (times.len() - 1) as f64,
        _ => 0.0,
    };
    let png = ctx.dir.path("shields_exceedance.png");
    Chart::new(
        &format!(
            "fraction of time with Shields θ > {} ({} samples over {:.4} s)",
            lo.shields_critical,
            times.len(),
            span
        ),
        "r / R",
        "grain diameter [µm]",
    )
    .log_y()
    .size(900, 600)
    .markers("never", &bands[0], (200, 200, 200))
    .markers("< 25 % of the time", &bands[1], (31, 119, 180))
    .markers("25–50 %", &bands[2], (44, 160, 44))
    .markers("50–75 %", &bands[3], (255, 127, 14))
    .markers("≥ 75 % (always, in a steady flow)", &bands[4], (214, 39, 40))
    .save_png(&png)?;
    summary.artifacts.push(("Shields exceedance table".into(), csv));
    summary.artifacts.push(("Shields exceedance map".into(), png));
    // The largest grain that is above the threshold at least half of the time somewhere, and where.
    let largest = table
        .iter()
        .enumerate()
        .flat_map(|(i, row)| row.iter().enumerate().map(move |(k, e)| (i, k, e.fraction)))
        .filter(|&(_, _, f)| f >= 0.5)
        .max_by(|a, b| lo.diameters_m[a.1].total_cmp(&lo.diameters_m[b.1]).then(a.2.total_cmp(&b.2)));
    match largest {
        Some((i, k, f)) => {
            summary.headline.push(format!(
                "Shields exceedance (θ* = {}): the largest grain above θ* at least half of the time is {:.0} µm ({:.0} % of the time at r/R = {:.2})",
                lo.shields_critical,
                lo.diameters_m[k] * 1e6,
                100.0 * f,
                probe.distances[i] / r0
            ));
            summary.scalar("shields_exceedance_largest_diameter_um", lo.diameters_m[k] * 1e6);
        }
        None => {
            summary.headline.push(format!(
                "Shields exceedance (θ* = {}): no grain size is above θ* half of the time anywhere",
                lo.shields_critical
            ));
            summary.scalar("shields_exceedance_largest_diameter_um", 0.0);
        }
    }
    Ok(())
}
