//! Regime maps: the (diameter, normal speed[, angle]) grid, its stick/bounce interface and the fitted
//! wall rule.

use super::bisection::{BracketStatus, CriticalSpeed};
use super::config::{FitConfig, GridConfig};
use super::fit::fit_polynomial;
use super::impact::{ImpactResult, Outcome};
use super::model::{ImpactModel, Surface};
use serde::{Deserialize, Serialize};
use spatter_core::regime::RegimeMap;

/// One grid point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridJob {
    /// Diameter \[m\].
    pub diameter: f64,
    /// Normal speed \[m/s\].
    pub normal_speed: f64,
    /// Impact angle from the normal \[deg\].
    pub angle_deg: f64,
}

/// One simulated impact with the numbers that set it up.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImpactRecord {
    /// Diameter \[m\].
    pub diameter: f64,
    /// Normal impact speed \[m/s\].
    pub normal_speed: f64,
    /// Tangential impact speed \[m/s\].
    pub tangential_speed: f64,
    /// Impact angle from the normal \[deg\].
    pub angle_deg: f64,
    /// Lateral aim point \[m\].
    pub aim: [f64; 2],
    pub result: ImpactResult,
    /// Restitution given to the damping \[-\].
    pub restitution_input: f64,
    /// Time step \[s\].
    pub dt: f64,
    /// Hertz contact time at the reference speed \[s\].
    pub hertz_time: f64,
}

impl ImpactRecord {
    pub fn sticks(&self) -> bool {
        self.result.outcome == Outcome::Stick
    }
}

/// The grid points in the order angle, diameter, speed (speed fastest).
pub fn grid_jobs(grid: &GridConfig) -> Vec<GridJob> {
    let ds = grid.diameter_axis();
    let vs = grid.speed_axis();
    let mut jobs = Vec::with_capacity(grid.angles_deg.len() * ds.len() * vs.len());
    for &a in &grid.angles_deg {
        for &d in &ds {
            for &v in &vs {
                jobs.push(GridJob { diameter: d, normal_speed: v, angle_deg: a });
            }
        }
    }
    jobs
}

/// Simulates one impact of the configured target.
pub fn run_job(model: &ImpactModel, job: &GridJob) -> ImpactRecord {
    let v_t = job.normal_speed * job.angle_deg.to_radians().tan();
    let (result, setup) =
        model.simulate(job.diameter, job.normal_speed, v_t, [0.0, 0.0], Surface::Configured);
    ImpactRecord {
        diameter: job.diameter,
        normal_speed: job.normal_speed,
        tangential_speed: v_t,
        angle_deg: job.angle_deg,
        aim: [0.0, 0.0],
        result,
        restitution_input: setup.restitution_input,
        dt: setup.dt,
        hertz_time: setup.hertz_time,
    }
}

/// The stick/bounce interface of a grid at one angle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Interface {
    /// `[diameter_m, critical_normal_speed_m_s]`: midpoint between the highest speed that stuck below
    /// the lowest bouncing speed and that bouncing speed.
    pub points: Vec<[f64; 2]>,
    /// `[diameter_m, highest_stick_m_s, lowest_bounce_m_s]` of every interface point.
    pub brackets: Vec<[f64; 3]>,
    /// Diameters that bounced at every speed (v_crit below the grid).
    pub all_bounce: Vec<f64>,
    /// Diameters that stuck at every speed (v_crit above the grid).
    pub all_stick: Vec<f64>,
    /// Diameters with a stick above their lowest bouncing speed (more than one transition).
    pub non_monotone: Vec<f64>,
}

/// Extracts the interface of `records` laid out as [`grid_jobs`] (`n_d` diameters × `n_v` speeds per
/// angle) for angle number `angle_index`.
pub fn interface(records: &[ImpactRecord], n_d: usize, n_v: usize, angle_index: usize) -> Interface {
    let mut out = Interface::default();
    for i in 0..n_d {
        let row = &records[(angle_index * n_d + i) * n_v..(angle_index * n_d + i + 1) * n_v];
        let d = row[0].diameter;
        match row.iter().position(|r| !r.sticks()) {
            None => out.all_stick.push(d),
            Some(0) => {
                out.all_bounce.push(d);
                if row.iter().any(|r| r.sticks()) {
                    out.non_monotone.push(d);
                }
            }
            Some(k) => {
                out.points.push([d, 0.5 * (row[k - 1].normal_speed + row[k].normal_speed)]);
                out.brackets.push([d, row[k - 1].normal_speed, row[k].normal_speed]);
                if row[k..].iter().any(|r| r.sticks()) {
                    out.non_monotone.push(d);
                }
            }
        }
    }
    out
}

/// Refines grid brackets `[d, v_stick, v_bounce]` by bisection to relative width `rel_tol`, in parallel;
/// returns `[d, v_crit]` (brackets whose ends no longer reproduce are kept at their midpoint).
pub fn refine(model: &ImpactModel, brackets: &[[f64; 3]], rel_tol: f64) -> Vec<[f64; 2]> {
    use rayon::prelude::*;
    brackets
        .par_iter()
        .map(|b| {
            let c = super::bisection::critical_speed(model, b[0], b[1], b[2], rel_tol, 0);
            if c.status == BracketStatus::Found {
                [b[0], c.v_crit]
            } else {
                [b[0], 0.5 * (b[1] + b[2])]
            }
        })
        .collect()
}

/// Interface points of a bisection run.
pub fn interface_from_bisection(speeds: &[CriticalSpeed]) -> Vec<[f64; 2]> {
    speeds.iter().filter(|c| c.status == BracketStatus::Found).map(|c| [c.diameter, c.v_crit]).collect()
}

/// Fits both forms of the boundary to the interface points; `None` with fewer than two points.
pub fn regime_map(points: &[[f64; 2]], fit: &FitConfig, description: String) -> Option<RegimeMap> {
    if points.len() < 2 {
        return None;
    }
    let vd: Vec<(f64, f64)> = points.iter().map(|p| (p[0], p[1])).collect();
    let dv: Vec<(f64, f64)> = points.iter().map(|p| (p[1], p[0])).collect();
    Some(RegimeMap {
        schema: RegimeMap::SCHEMA.into(),
        description,
        v_crit_of_d: fit_polynomial(&vd, fit.degree, fit.log10, "diameter_m", "critical_normal_speed_m_s")?,
        d_crit_of_vn: fit_polynomial(&dv, fit.degree, fit.log10, "normal_speed_m_s", "critical_diameter_m")?,
        interface: points.to_vec(),
    })
}

/// Number of sticking impacts.
pub fn stick_count(records: &[ImpactRecord]) -> usize {
    records.iter().filter(|r| r.sticks()).count()
}
