//! `spatter sessile`: the static contact angle of an SPH drop on a wall of each given adhesion factor,
//! so that users can pick the `adhesion` of a wall from a measured contact angle
//! (`spatter_sph::sessile`, docs/sph.md "Sessile-drop calibration").

use anyhow::{bail, Result};
use spatter_sph::sessile::{sessile_drop, SessileDrop};
use spatter_sph::Dim;
use std::path::Path;
use std::process::ExitCode;

/// What to compute; every value is checked by [`Request::check`] before anything runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// Wall adhesion factors (multiples of the cohesion), each in [0, 10].
    pub adhesion: Vec<f64>,
    /// 2 or 3.
    pub dimensions: u8,
    /// Particles across the drop radius, 4 to 40.
    pub resolution: usize,
    /// Drop radius \[m\], in (0, 0.1].
    pub radius_m: f64,
    /// Surface tension \[N/m\], in (0, 1].
    pub surface_tension_n_m: f64,
    /// Simulated time in capillary times √(ρR³/σ), in [1, 100].
    pub capillary_times: f64,
}

impl Request {
    /// Every out-of-range value, one message each, naming the option, the value and the allowed range.
    pub fn check(&self) -> Vec<String> {
        let mut e = Vec::new();
        for &f in &self.adhesion {
            if !(0.0..=10.0).contains(&f) {
                e.push(format!("--adhesion {f} is outside [0, 10] (a multiple of the liquid's cohesion)"));
            }
        }
        if !(self.radius_m > 0.0 && self.radius_m <= 0.1) {
            e.push(format!("--radius-m {} is outside (0, 0.1] m", self.radius_m));
        }
        if !(self.surface_tension_n_m > 0.0 && self.surface_tension_n_m <= 1.0) {
            e.push(format!("--surface-tension-n-m {} is outside (0, 1] N/m", self.surface_tension_n_m));
        }
        if !(1.0..=100.0).contains(&self.capillary_times) {
            e.push(format!("--capillary-times {} is outside [1, 100]", self.capillary_times));
        }
        if !(4..=40).contains(&self.resolution) {
            e.push(format!("--resolution {} is outside 4 to 40", self.resolution));
        }
        if !(2..=3).contains(&self.dimensions) {
            e.push(format!("--dimensions {} must be 2 or 3", self.dimensions));
        }
        e
    }
}

/// Runs one drop per adhesion factor, prints the table and optionally writes it as CSV.
pub fn run(req: &Request, csv: Option<&Path>) -> Result<ExitCode> {
    let problems = req.check();
    if !problems.is_empty() {
        for p in &problems {
            eprintln!("error: {p}");
        }
        return Ok(ExitCode::from(super::EXIT_BAD_INPUT));
    }
    let dim = if req.dimensions == 3 { Dim::Three } else { Dim::Two };
    println!(
        "sessile drops: {}D, radius {} m, {} particles per radius, σ = {} N/m, {} capillary times",
        req.dimensions, req.radius_m, req.resolution, req.surface_tension_n_m, req.capillary_times
    );
    println!(
        "{:>9} {:>18} {:>12} {:>12} {:>16} {:>8}",
        "adhesion", "contact angle/deg", "base/m", "height/m", "residual motion", "removed"
    );
    let mut rows = Vec::new();
    for &f in &req.adhesion {
        let drop = SessileDrop {
            dim,
            radius: req.radius_m,
            resolution: req.resolution,
            surface_tension: req.surface_tension_n_m,
            adhesion: f,
            capillary_times: req.capillary_times,
        };
        let r = match sessile_drop(&drop) {
            Ok(r) => r,
            Err(e) => bail!("sessile drop at --adhesion {f}: {e}"),
        };
        println!(
            "{:>9} {:>18.1} {:>12.4e} {:>12.4e} {:>16.3e} {:>8}",
            f, r.contact_angle_deg, r.base, r.height, r.residual_motion, r.removed
        );
        rows.push(vec![
            spatter_io::fmt_f64(f),
            spatter_io::fmt_f64(r.contact_angle_deg),
            spatter_io::fmt_f64(r.base),
            spatter_io::fmt_f64(r.height),
            spatter_io::fmt_f64(r.residual_motion),
            r.removed.to_string(),
        ]);
    }
    println!(
        "180° means the drop left the plate. The angle depends on the spacing: calibrate with the R/dp of your run."
    );
    if let Some(path) = csv {
        spatter_io::csv::write_table(
            path,
            &["adhesion", "contact_angle_deg", "base_m", "height_m", "residual_motion", "removed_particles"],
            &rows,
        )
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        println!("table: {}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}
