//! `spatter sessile`: the static contact angle of an SPH drop on a wall of each given adhesion factor,
//! or the adhesion factor that gives each measured contact angle (one per material: glass, paint,
//! rubber, …), so that users can set the `adhesion` of a wall from a measured angle
//! (`spatter_sph::sessile`, docs/sph.md "Sessile-drop calibration").

use anyhow::{bail, Result};
use spatter_sph::params::ADHESION_CALIBRATED;
use spatter_sph::sessile::{factor_for_angle, sessile_drop, FactorFit, SessileDrop, SessileResult};
use spatter_sph::{Dim, SphParams};
use std::path::Path;
use std::process::ExitCode;

/// Adhesion factors of the table the contact-angle mode interpolates in: the calibrated range and a
/// little beyond on each side.
const TABLE_FACTORS: [f64; 8] = [0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 3.0];

/// What to compute; every value is checked by [`Request::check`] before anything runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    /// Wall adhesion factors (multiples of the cohesion), each in [0, 10].
    pub adhesion: Vec<f64>,
    /// Measured contact angles `name=degrees`, each in (0, 180): the factor that gives each is sought.
    pub contact_angles: Vec<String>,
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

/// A measured contact angle of a named material.
#[derive(Clone, Debug, PartialEq)]
struct Material {
    name: String,
    angle_deg: f64,
}

fn parse_material(text: &str) -> Result<Material, String> {
    let Some((name, deg)) = text.split_once('=') else {
        return Err(format!("--contact-angle `{text}` is not `name=degrees` (e.g. glass=25)"));
    };
    let name = name.trim();
    if name.is_empty() {
        return Err(format!("--contact-angle `{text}` has no material name before `=`"));
    }
    match deg.trim().parse::<f64>() {
        Ok(a) if a > 0.0 && a < 180.0 => Ok(Material { name: name.to_owned(), angle_deg: a }),
        _ => Err(format!("--contact-angle {name}={} is not an angle in (0, 180) degrees", deg.trim())),
    }
}

impl Request {
    /// Every out-of-range value, one message each, naming the option, the value and the allowed range.
    pub fn check(&self) -> Vec<String> {
        let mut e = Vec::new();
        if self.adhesion.is_empty() == self.contact_angles.is_empty() {
            e.push("give either --adhesion (angles per factor) or --contact-angle (factor per angle)".into());
        }
        for &f in &self.adhesion {
            if !(0.0..=10.0).contains(&f) {
                e.push(format!("--adhesion {f} is outside [0, 10] (a multiple of the liquid's cohesion)"));
            }
        }
        for m in &self.contact_angles {
            if let Err(msg) = parse_material(m) {
                e.push(msg);
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

    fn drop(&self, adhesion: f64) -> SessileDrop {
        SessileDrop {
            dim: if self.dimensions == 3 { Dim::Three } else { Dim::Two },
            radius: self.radius_m,
            resolution: self.resolution,
            surface_tension: self.surface_tension_n_m,
            adhesion,
            capillary_times: self.capillary_times,
        }
    }
}

/// One sessile drop, printed as a table row.
fn run_one(req: &Request, f: f64) -> Result<SessileResult> {
    let r = match sessile_drop(&req.drop(f)) {
        Ok(r) => r,
        Err(e) => bail!("sessile drop at adhesion {f}: {e}"),
    };
    println!(
        "{:>9} {:>18.1} {:>12.4e} {:>12.4e} {:>16.3e} {:>8}",
        f, r.contact_angle_deg, r.base, r.height, r.residual_motion, r.removed
    );
    if let Some(note) = SphParams::adhesion_note(f) {
        println!("          note: {note}");
    }
    if !r.settled() {
        println!("          not settled (particles removed or still moving): this angle is not used");
    }
    Ok(r)
}

fn row(f: f64, r: &SessileResult) -> Vec<String> {
    vec![
        spatter_io::fmt_f64(f),
        spatter_io::fmt_f64(r.contact_angle_deg),
        spatter_io::fmt_f64(r.base),
        spatter_io::fmt_f64(r.height),
        spatter_io::fmt_f64(r.residual_motion),
        r.removed.to_string(),
    ]
}

fn write_csv(path: &Path, head: &[&str], rows: &[Vec<String>]) -> Result<()> {
    spatter_io::csv::write_table(path, head, rows).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    println!("table: {}", path.display());
    Ok(())
}

/// Runs one drop per adhesion factor (or the table and one check per material), prints the results and
/// optionally writes them as CSV.
pub fn run(req: &Request, csv: Option<&Path>) -> Result<ExitCode> {
    let problems = req.check();
    if !problems.is_empty() {
        for p in &problems {
            eprintln!("error: {p}");
        }
        return Ok(ExitCode::from(super::EXIT_BAD_INPUT));
    }
    println!(
        "sessile drops: {}D, radius {} m, {} particles per radius, σ = {} N/m, {} capillary times",
        req.dimensions, req.radius_m, req.resolution, req.surface_tension_n_m, req.capillary_times
    );
    let head =
        ["adhesion", "contact_angle_deg", "base_m", "height_m", "residual_motion", "removed_particles"];
    let title = || {
        println!(
            "{:>9} {:>18} {:>12} {:>12} {:>16} {:>8}",
            "adhesion", "contact angle/deg", "base/m", "height/m", "residual motion", "removed"
        )
    };
    if req.contact_angles.is_empty() {
        title();
        let mut rows = Vec::new();
        for &f in &req.adhesion {
            let r = run_one(req, f)?;
            rows.push(row(f, &r));
        }
        println!(
            "180° means the drop left the plate. The angle depends on the spacing: calibrate with the R/dp of your run."
        );
        if let Some(path) = csv {
            write_csv(path, &head, &rows)?;
        }
        return Ok(ExitCode::SUCCESS);
    }
    let materials: Vec<Material> = req.contact_angles.iter().filter_map(|m| parse_material(m).ok()).collect();
    println!("table of angles over the adhesion factors {TABLE_FACTORS:?}:");
    title();
    let mut table = Vec::new();
    for &f in &TABLE_FACTORS {
        let r = run_one(req, f)?;
        if r.settled() {
            table.push((f, r.contact_angle_deg));
        }
    }
    println!("\nadhesion per material (interpolated in the table, then checked with one drop):");
    title();
    let mut rows = Vec::new();
    for m in &materials {
        let fit = factor_for_angle(&table, m.angle_deg);
        let (f, remark) = match fit {
            Some(FactorFit::Within(f)) => (f, String::new()),
            Some(FactorFit::LessWetting { factor, angle_deg }) => (
                factor,
                format!(
                    "{}° is above the table's largest angle {angle_deg:.1}° (adhesion {factor}): use adhesion 0 or \
                     {factor}; the drop wets no less",
                    m.angle_deg
                ),
            ),
            Some(FactorFit::MoreWetting { factor, angle_deg }) => (
                factor,
                format!(
                    "{}° is below the smallest angle this spacing resolves ({angle_deg:.1}°, complete wetting from \
                     adhesion {factor})",
                    m.angle_deg
                ),
            ),
            None => bail!("no drop of the table settled: try a coarser --resolution or more --capillary-times"),
        };
        let f = (f * 1000.0).round() / 1000.0;
        let r = run_one(req, f)?;
        println!(
            "          {}: measured {}°, adhesion {f}, SPH angle {:.1}°",
            m.name, m.angle_deg, r.contact_angle_deg
        );
        if !remark.is_empty() {
            println!("          {remark}");
        }
        let mut cells = vec![m.name.clone(), spatter_io::fmt_f64(m.angle_deg)];
        cells.extend(row(f, &r));
        rows.push(cells);
    }
    println!(
        "\nSet `adhesion` of each wall to its material's factor. Calibrated range {}–{}; the angle depends on the \
         spacing: calibrate with the R/dp of your run.",
        ADHESION_CALIBRATED[0], ADHESION_CALIBRATED[1]
    );
    if let Some(path) = csv {
        let mut h = vec!["material", "measured_angle_deg"];
        h.extend_from_slice(&head);
        write_csv(path, &h, &rows)?;
    }
    Ok(ExitCode::SUCCESS)
}
