//! The rotor's mean flow solved as a steady axisymmetric RANS flow (`flow = { kind = "rans" }`): the
//! case Jasion (2013, Ch. 6) ran in Fluent for Leese's (1964) Bell 47 measurements. An actuator disk of
//! the scenario's radius and thrust with a linear tip taper, at z_d above a smooth no-slip ground, in an
//! (r, z) domain with static-pressure boundaries at the side and top, realizable (default) or standard
//! k–ε with log-law wall functions, stepped in time from rest until the flow no longer changes.
//!
//! Steady state: every interval R/v_i (v_i = √(T/(2ρA)), the momentum-theory induced velocity) the
//! largest change of any velocity node over that interval is compared with v_i; the solve stops when it is
//! below `steady_change` · v_i, or at `max_time_over_r_v` intervals (the run log and the summary say which).

use super::config::BrownoutConfig;
use serde::{Deserialize, Serialize};
use spatter_cfd::grid::{Axis, Grid, Mode};
use spatter_cfd::sources::ActuatorDisk;
use spatter_cfd::turbulence::KEpsilon;
use spatter_cfd::{Boundary, Flow, Fluid, Numerics};
use spatter_core::check::{Checker, Validate};

/// Which mean flow the lift-off map, the source and the cloud run on.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FlowChoice {
    /// The analytic rotor downwash of `spatter-flow` (momentum theory, wall jet, optional tip vortices).
    #[default]
    Analytic,
    /// The axisymmetric RANS flow solved at the start of the run.
    Rans(RansConfig),
    /// A field imported from VTK files, optionally at model scale (scaled by R and v_ind).
    Imported(super::imported::ImportedFlowConfig),
}

/// Turbulence model of the RANS solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RansTurbulence {
    /// Realizable k–ε (Shih et al. 1995), the thesis's model.
    #[default]
    Realizable,
    /// Standard k–ε (Launder & Spalding 1974).
    Standard,
}

/// Grid and run length of the RANS solve (lengths over the rotor radius R).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RansConfig {
    /// Radial extent of the domain over R (the thesis: 9).
    #[serde(default = "nine")]
    pub domain_radius_over_radius: f64,
    /// Height of the domain over R (the thesis: 5).
    #[serde(default = "five")]
    pub domain_height_over_radius: f64,
    /// Radial cells, each `radial_growth` times wider than the one before (fine at the axis).
    #[serde(default = "radial_cells")]
    pub radial_cells: usize,
    #[serde(default = "radial_growth")]
    pub radial_growth: f64,
    /// Axial cells, each `axial_growth` times taller than the one below (fine at the ground).
    #[serde(default = "axial_cells")]
    pub axial_cells: usize,
    #[serde(default = "axial_growth")]
    pub axial_growth: f64,
    /// Fraction of the radius over which the disk loading falls linearly to 0 at the tip.
    #[serde(default = "taper")]
    pub tip_taper: f64,
    #[serde(default)]
    pub turbulence: RansTurbulence,
    /// Steady when the largest velocity change over an interval R/v_i is below this × v_i.
    #[serde(default = "steady_change")]
    pub steady_change: f64,
    /// Longest solve, in intervals R/v_i.
    #[serde(default = "max_time")]
    pub max_time_over_r_v: f64,
    /// Stop after this many time steps even if not steady (a quick look; `--smoke` sets 20).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_steps: Option<u64>,
}

fn nine() -> f64 {
    9.0
}
fn five() -> f64 {
    5.0
}
fn radial_cells() -> usize {
    48
}
fn axial_cells() -> usize {
    36
}
fn radial_growth() -> f64 {
    1.06
}
fn axial_growth() -> f64 {
    1.13
}
fn taper() -> f64 {
    0.35
}
fn steady_change() -> f64 {
    0.01
}
fn max_time() -> f64 {
    60.0
}

impl Default for RansConfig {
    fn default() -> Self {
        RansConfig {
            domain_radius_over_radius: nine(),
            domain_height_over_radius: five(),
            radial_cells: radial_cells(),
            radial_growth: radial_growth(),
            axial_cells: axial_cells(),
            axial_growth: axial_growth(),
            tip_taper: taper(),
            turbulence: RansTurbulence::Realizable,
            steady_change: steady_change(),
            max_time_over_r_v: max_time(),
            max_steps: None,
        }
    }
}

impl Validate for RansConfig {
    fn validate(&self, c: &mut Checker) {
        c.in_range("domain_radius_over_radius", self.domain_radius_over_radius, 2.0, true, 100.0, true);
        c.in_range("domain_height_over_radius", self.domain_height_over_radius, 1.0, true, 100.0, true);
        for (key, n) in [("radial_cells", self.radial_cells), ("axial_cells", self.axial_cells)] {
            if !(8..=2000).contains(&n) {
                c.fail(key, format!("{key} = {n} must be 8 to 2000"));
            }
        }
        c.in_range("radial_growth", self.radial_growth, 1.0, true, 1.3, true);
        c.in_range("axial_growth", self.axial_growth, 1.0, true, 1.3, true);
        c.in_range("tip_taper", self.tip_taper, 0.0, true, 1.0, false);
        c.in_range("steady_change", self.steady_change, 0.0, false, 1.0, true);
        c.in_range("max_time_over_r_v", self.max_time_over_r_v, 0.0, false, 1e4, true);
    }
}

impl Validate for FlowChoice {
    fn validate(&self, c: &mut Checker) {
        match self {
            FlowChoice::Analytic => {}
            FlowChoice::Rans(r) => r.validate(c),
            FlowChoice::Imported(i) => i.validate(c),
        }
    }
}

/// How a solve ended.
pub struct Solved {
    pub flow: Flow,
    /// Whether the steady criterion was met (else the time limit ended it).
    pub steady: bool,
    /// Last largest change over an interval, over v_i.
    pub change: f64,
    /// Momentum-theory induced velocity out of ground effect \[m/s\].
    pub v_hover: f64,
    /// The disk as placed in the grid.
    pub disk: ActuatorDisk,
}

/// Builds the (r, z) problem of `cfg`'s rotor.
pub fn build(cfg: &BrownoutConfig, rc: &RansConfig) -> Result<(Flow, ActuatorDisk), String> {
    let r0 = cfg.rotor.radius_m;
    let axis = |hi: f64, n: usize, ratio: f64| {
        if ratio == 1.0 { Axis::uniform(0.0, hi, n) } else { Axis::geometric(0.0, hi, n, ratio) }
            .map_err(|e| e.to_string())
    };
    let grid = Grid::new(
        [
            axis(rc.domain_radius_over_radius * r0, rc.radial_cells, rc.radial_growth)?,
            axis(rc.domain_height_over_radius * r0, rc.axial_cells, rc.axial_growth)?,
            Axis::uniform(0.0, 1.0, 1).map_err(|e| e.to_string())?,
        ],
        Mode::Axisymmetric,
    )
    .map_err(|e| e.to_string())?;
    let out = Boundary::Outlet { pressure_pa: 0.0 };
    let bc = [
        Boundary::Axis,
        out.clone(),
        Boundary::Wall { velocity_m_s: [0.0; 3] },
        out,
        Boundary::Slip,
        Boundary::Slip,
    ];
    let mut numerics = Numerics::default();
    // The ground's flat cells make the pressure operator anisotropic: the multigrid-preconditioned CG
    // needs more iterations; 10⁻⁶ is ample for a steady solution.
    numerics.pressure.rtol = 1e-6;
    numerics.pressure.max_iterations = 500;
    let n = grid.layout.len();
    let fluid = Fluid { density: cfg.air.density, viscosity: cfg.air.nu() };
    let mut flow = Flow::new(grid, fluid, bc, vec![false; n], numerics).map_err(|e| e.to_string())?;
    let disk = ActuatorDisk {
        thrust_n: cfg.rotor.thrust(cfg.air.density),
        radius_m: r0,
        axial_m: cfg.rotor.height_over_radius * r0,
        direction: -1.0,
        tip_taper: rc.tip_taper,
    };
    flow.add_actuator_disk(&disk).map_err(|e| e.to_string())?;
    // Ambient turbulence length scale (only the initial state uses it: there are no inlets).
    let ell = 0.1 * r0;
    flow.enable_k_epsilon(match rc.turbulence {
        RansTurbulence::Realizable => KEpsilon::realizable(0.05, ell),
        RansTurbulence::Standard => KEpsilon::standard(0.05, ell),
    });
    Ok((flow, disk))
}

/// Solves the rotor flow to steady state (or the time limit, or `max_steps`). `stop` is polled between
/// steps; a stop returns `Ok(None)`.
pub fn solve(
    cfg: &BrownoutConfig,
    rc: &RansConfig,
    stop: &dyn Fn() -> bool,
) -> Result<Option<Solved>, String> {
    let max_steps = rc.max_steps;
    let (mut flow, disk) = build(cfg, rc)?;
    let v_hover = disk.hover_induced_velocity(cfg.air.density);
    let interval = cfg.rotor.radius_m / v_hover;
    let end = rc.max_time_over_r_v * interval;
    let dt_max = 0.05 * interval;
    let mut previous = flow.state.u.clone();
    let mut next_check = interval;
    let mut change = f64::INFINITY;
    let mut steady = false;
    while flow.state.t < end {
        if stop() {
            return Ok(None);
        }
        if max_steps.is_some_and(|n| flow.state.step >= n) {
            break;
        }
        let dt = flow.stable_dt(0.5, dt_max.min(next_check - flow.state.t).max(1e-9));
        flow.step(dt).map_err(|e| format!("RANS rotor solve: {e}"))?;
        if flow.state.t >= next_check - 1e-9 * interval {
            let du = (0..2)
                .flat_map(|a| flow.state.u[a].iter().zip(&previous[a]).map(|(x, y)| (x - y).abs()))
                .fold(0.0, f64::max);
            change = du / v_hover;
            tracing::info!(
                "RANS rotor: t = {:.2} s (t v_i/R = {:.1}), step {}, largest velocity change over R/v_i {:.3e} v_i",
                flow.state.t,
                flow.state.t / interval,
                flow.state.step,
                change
            );
            previous.clone_from(&flow.state.u);
            next_check += interval;
            if change < rc.steady_change {
                steady = true;
                break;
            }
        }
    }
    Ok(Some(Solved { flow, steady, change, v_hover, disk }))
}
