//! The lid-driven cavity: the reference tables of Ghia, Ghia & Shin (1982) and a driver that runs the
//! square cavity to steady state and samples its centrelines.
//!
//! Reference: U. Ghia, K. N. Ghia, C. T. Shin, "High-Re solutions for incompressible flow using the
//! Navier–Stokes equations and a multigrid method", J. Comput. Phys. 48 (1982) 387–411, Table I (u on the
//! vertical centreline x = 0.5) and Table II (v on the horizontal centreline y = 0.5), unit cavity, lid
//! speed 1 in +x at y = 1.

use crate::bc::Boundary;
use crate::grid::{Axis, Grid, Mode};
use crate::solver::{Flow, FlowError, Fluid, Numerics};

/// y of Ghia Table I.
pub const GHIA_Y: [f64; 17] = [
    1.0000, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5000, 0.4531, 0.2813, 0.1719, 0.1016,
    0.0703, 0.0625, 0.0547, 0.0000,
];
/// u(0.5, y) at Re = 100 and 1000 (Table I).
pub const GHIA_U_100: [f64; 17] = [
    1.00000, 0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581, -0.21090, -0.15662,
    -0.10150, -0.06434, -0.04775, -0.04192, -0.03717, 0.00000,
];
pub const GHIA_U_1000: [f64; 17] = [
    1.00000, 0.65928, 0.57492, 0.51117, 0.46604, 0.33304, 0.18719, 0.05702, -0.06080, -0.10648, -0.27805,
    -0.38289, -0.29730, -0.22220, -0.20196, -0.18109, 0.00000,
];
/// x of Ghia Table II.
pub const GHIA_X: [f64; 17] = [
    1.0000, 0.9688, 0.9609, 0.9531, 0.9453, 0.9063, 0.8594, 0.8047, 0.5000, 0.2344, 0.2266, 0.1563, 0.0938,
    0.0781, 0.0703, 0.0625, 0.0000,
];
/// v(x, 0.5) at Re = 100 and 1000 (Table II).
pub const GHIA_V_100: [f64; 17] = [
    0.00000, -0.05906, -0.07391, -0.08864, -0.10313, -0.16914, -0.22445, -0.24533, 0.05454, 0.17527, 0.17507,
    0.16077, 0.12317, 0.10890, 0.10091, 0.09233, 0.00000,
];
pub const GHIA_V_1000: [f64; 17] = [
    0.00000, -0.21388, -0.27669, -0.33714, -0.39188, -0.51550, -0.42665, -0.31966, 0.02526, 0.32235, 0.33075,
    0.37095, 0.32627, 0.30353, 0.29012, 0.27485, 0.00000,
];

/// Points (coordinate, velocity) of a centreline profile.
pub type Profile = Vec<(f64, f64)>;

/// Ghia's tables for `re` (100 or 1000): (y, u) and (x, v) pairs.
pub fn ghia(re: u32) -> Option<(Profile, Profile)> {
    let (u, v) = match re {
        100 => (&GHIA_U_100, &GHIA_V_100),
        1000 => (&GHIA_U_1000, &GHIA_V_1000),
        _ => return None,
    };
    Some((
        GHIA_Y.iter().copied().zip(u.iter().copied()).collect(),
        GHIA_X.iter().copied().zip(v.iter().copied()).collect(),
    ))
}

/// A unit square cavity (2D: one cell across z with slip sides) with `n × n` cells, lid speed 1 at y = 1,
/// ν = 1/Re. `beta` > 0 clusters the cells towards the walls (tanh map).
pub fn square_cavity(n: usize, re: f64, beta: f64, numerics: Numerics) -> Result<Flow, FlowError> {
    let ax = Axis::clustered(0.0, 1.0, n, beta).map_err(|e| FlowError::Setup(e.to_string()))?;
    let grid = Grid::new(
        [ax.clone(), ax, Axis::uniform(0.0, 1.0 / n as f64, 1).expect("one cell")],
        Mode::Cartesian,
    )
    .map_err(|e| FlowError::Setup(e.to_string()))?;
    let wall = Boundary::Wall { velocity_m_s: [0.0; 3] };
    let lid = Boundary::Wall { velocity_m_s: [1.0, 0.0, 0.0] };
    let bc = [wall.clone(), wall.clone(), wall, lid, Boundary::Slip, Boundary::Slip];
    let blocked = vec![false; grid.layout.len()];
    Flow::new(grid, Fluid { density: 1.0, viscosity: 1.0 / re }, bc, blocked, numerics)
}

/// Runs `flow` until the largest change of any velocity over one time unit falls below `tol` (or
/// `t_max`), with the largest stable step at Courant number 0.5. Returns the final time.
pub fn run_to_steady(flow: &mut Flow, tol: f64, t_max: f64) -> Result<f64, FlowError> {
    let mut last = flow.state.u.clone();
    let mut t_check = flow.state.t + 1.0;
    while flow.state.t < t_max {
        let dt = flow.stable_dt(0.5, 0.05);
        flow.step(dt)?;
        if flow.state.t >= t_check {
            let change = (0..3)
                .flat_map(|a| flow.state.u[a].iter().zip(&last[a]).map(|(x, y)| (x - y).abs()))
                .fold(0.0, f64::max);
            if change < tol {
                break;
            }
            last = flow.state.u.clone();
            t_check = flow.state.t + 1.0;
        }
    }
    Ok(flow.state.t)
}

/// Centreline samples of a cavity at Ghia's points: (u at x = ½ for each y, v at y = ½ for each x).
pub fn centrelines(flow: &Flow) -> (Vec<f64>, Vec<f64>) {
    let zc = 0.5 * (flow.grid.axes[2].lo() + flow.grid.axes[2].hi());
    let clampi = |s: f64| s.clamp(0.0, 1.0);
    let u =
        GHIA_Y.iter().map(|&y| flow.velocity_at([0.5, clampi(y), zc]).map_or(f64::NAN, |v| v[0])).collect();
    let v =
        GHIA_X.iter().map(|&x| flow.velocity_at([clampi(x), 0.5, zc]).map_or(f64::NAN, |v| v[1])).collect();
    (u, v)
}

/// Largest |ours − Ghia| over Table I and Table II at Reynolds number `re`.
pub fn ghia_max_error(flow: &Flow, re: u32) -> Option<(f64, f64)> {
    let (tu, tv) = ghia(re)?;
    let (u, v) = centrelines(flow);
    let eu = tu.iter().zip(&u).map(|((_, r), o)| (r - o).abs()).fold(0.0, f64::max);
    let ev = tv.iter().zip(&v).map(|((_, r), o)| (r - o).abs()).fold(0.0, f64::max);
    Some((eu, ev))
}
