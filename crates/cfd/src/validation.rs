//! Verification of the flow solver against analytic solutions and published data, for `spatter validate`
//! (full variants) and the unit tests (quick variants).
//!
//! * Lid-driven cavity at Re = 100 and 1000: Ghia, Ghia & Shin (1982), J. Comput. Phys. 48:387, Tables I–II.
//! * Plane Poiseuille flow from a uniform inlet: developed profile u = 6U (y/H)(1 − y/H) and pressure
//!   gradient dp/dx = −12 μU/H² (White, Viscous Fluid Flow, 3rd ed., §3-3.2).
//! * Hagen–Poiseuille flow in the axisymmetric (r, z) mode: u = 2U(1 − r²/R²), Δp/L = 32 μU/D² (White §3-3.3).
//! * Decaying Taylor–Green vortex u = sin x cos y e^{−2νt}, v = −cos x sin y e^{−2νt} in the box [0, π]²
//!   with slip walls (an exact Navier–Stokes solution, Taylor & Green 1937): transient error and the
//!   observed order of convergence under grid refinement (expected 2).

use crate::bc::Boundary;
use crate::cavity;
use crate::grid::{Axis, Grid, Mode, GHOST};
use crate::solver::{Flow, Fluid, Numerics};
use spatter_core::validation::{Case, Check};

/// Registered cases.
pub fn validation_cases() -> Vec<Case> {
    vec![
        Case { name: "cfd_cavity_re100", run: cavity_re100 },
        Case { name: "cfd_cavity_re1000", run: cavity_re1000 },
        Case { name: "cfd_channel_poiseuille", run: channel },
        Case { name: "cfd_pipe_axisymmetric", run: pipe },
        Case { name: "cfd_taylor_green_order", run: taylor_green },
        Case { name: "cfd_pipe_k_epsilon_friction", run: turbulent_pipe },
    ]
}

const GHIA: &str = "Ghia, Ghia & Shin (1982) J. Comput. Phys. 48:387, Tables I-II";

fn cavity_case(re: u32, quick: bool) -> Vec<Check> {
    let name = format!("cfd_cavity_re{re}");
    // Quick: uniform grid; full: 128² clustered towards the walls.
    let (n, beta, tol) = match (re, quick) {
        (100, true) => (32, 0.0, 0.015),
        (100, false) => (128, 1.0, 0.005),
        (_, true) => (64, 1.0, 0.02),
        (_, false) => (128, 1.0, 0.015),
    };
    let t_max = if re == 100 { 60.0 } else { 150.0 };
    let mut out = Vec::new();
    let mut f = match cavity::square_cavity(n, re as f64, beta, Numerics::default()) {
        Ok(f) => f,
        Err(e) => {
            return vec![Check::absolute(&name, format!("setup failed: {e}"), 0.0, f64::NAN, 0.0, GHIA)]
        }
    };
    if let Err(e) = cavity::run_to_steady(&mut f, 1e-4, t_max) {
        return vec![Check::absolute(&name, format!("run failed: {e}"), 0.0, f64::NAN, 0.0, GHIA)];
    }
    let (eu, ev) = cavity::ghia_max_error(&f, re).unwrap_or((f64::NAN, f64::NAN));
    out.push(Check::absolute(&name, format!("max |u - u_Ghia| on x = 0.5, {n}x{n} [-]"), 0.0, eu, tol, GHIA));
    out.push(Check::absolute(&name, format!("max |v - v_Ghia| on y = 0.5, {n}x{n} [-]"), 0.0, ev, tol, GHIA));
    // The headline extrema.
    let (u, v) = cavity::centrelines(&f);
    let (tu, tv) = cavity::ghia(re).unwrap_or_default();
    let imin = (0..tu.len()).min_by(|&a, &b| tu[a].1.total_cmp(&tu[b].1)).unwrap_or(0);
    out.push(Check::absolute(
        &name,
        format!("u at y = {} (Ghia min u) [-]", tu[imin].0),
        tu[imin].1,
        u[imin],
        tol,
        GHIA,
    ));
    let imax = (0..tv.len()).max_by(|&a, &b| tv[a].1.total_cmp(&tv[b].1)).unwrap_or(0);
    out.push(Check::absolute(
        &name,
        format!("v at x = {} (Ghia max v) [-]", tv[imax].0),
        tv[imax].1,
        v[imax],
        tol,
        GHIA,
    ));
    out
}

fn cavity_re100(quick: bool) -> Vec<Check> {
    cavity_case(100, quick)
}

fn cavity_re1000(quick: bool) -> Vec<Check> {
    cavity_case(1000, quick)
}

/// Runs to steady state with the largest stable step, at most `t_max`.
fn settle(f: &mut Flow, t_max: f64) -> Result<(), crate::FlowError> {
    cavity::run_to_steady(f, 1e-6, t_max).map(|_| ())
}

const WHITE: &str = "White, Viscous Fluid Flow (3rd ed.) §3-3";

fn channel(quick: bool) -> Vec<Check> {
    let case = "cfd_channel_poiseuille";
    // H = 1, L = 4, U = 1, Re = U H / ν = 10; developed after about 0.6 H + 0.05 Re H ≈ 1.1 H.
    let (nx, ny) = if quick { (64, 16) } else { (128, 32) };
    let run = || -> Result<Flow, crate::FlowError> {
        let grid = Grid::new(
            [Axis::uniform(0.0, 4.0, nx)?, Axis::uniform(0.0, 1.0, ny)?, Axis::uniform(0.0, 0.1, 1)?],
            Mode::Cartesian,
        )
        .map_err(|e| crate::FlowError::Setup(e.to_string()))?;
        let wall = Boundary::Wall { velocity_m_s: [0.0; 3] };
        let bc = [
            Boundary::Inlet { velocity_m_s: [1.0, 0.0, 0.0], table: Default::default() },
            Boundary::Outlet { pressure_pa: 0.0 },
            wall.clone(),
            wall,
            Boundary::Slip,
            Boundary::Slip,
        ];
        let n = grid.layout.len();
        let mut f =
            Flow::new(grid, Fluid { density: 1.0, viscosity: 0.1 }, bc, vec![false; n], Numerics::default())?;
        settle(&mut f, 40.0)?;
        Ok(f)
    };
    let f = match run() {
        Ok(f) => f,
        Err(e) => return vec![Check::absolute(case, format!("run failed: {e}"), 0.0, f64::NAN, 0.0, WHITE)],
    };
    let zc = 0.05;
    let mut err = 0.0f64;
    for j in 0..ny {
        let y = f.grid.axes[1].centre(j);
        let u = f.velocity_at([3.0, y, zc]).map_or(f64::NAN, |v| v[0]);
        err = err.max((u - 6.0 * y * (1.0 - y)).abs());
    }
    // Pressure gradient from the centre-row pressures at x = 2.5 and 3.5.
    let p_at = |x: f64| {
        let i = f.grid.axes[0].locate(x);
        let j = ny / 2;
        (f.grid.axes[0].centre(i), 0.5 * (f.cell_pressure(i, j, 0) + f.cell_pressure(i, j - 1, 0)))
    };
    let (x1, p1) = p_at(2.5);
    let (x2, p2) = p_at(3.5);
    let dpdx = (p2 - p1) / (x2 - x1);
    vec![
        Check::absolute(
            case,
            format!("max |u - 6U y(1-y)| at x = 3H, {nx}x{ny} [m/s]"),
            0.0,
            err,
            0.015,
            WHITE,
        ),
        Check::relative(case, "dp/dx = -12 mu U / H^2 [Pa/m]", -1.2, dpdx, 0.02, WHITE),
        Check::absolute(case, "net outflow [m^3/s]", 0.0, f.net_outflow(), 1e-9, "continuity"),
    ]
}

/// Darcy friction factor of a smooth pipe from the Colebrook equation 1/√f = −2 log₁₀(2.51/(Re √f))
/// (Colebrook 1939), solved by fixed-point iteration.
pub fn colebrook_smooth(re: f64) -> f64 {
    let mut x = 8.0; // 1/√f
    for _ in 0..50 {
        x = -2.0 * (2.51 * x / re).log10();
    }
    1.0 / (x * x)
}

/// A developed turbulent pipe flow with the k–ε model and wall functions, in the axisymmetric mode:
/// D = 1 m, U = 1 m/s, Re = 5·10⁴ (quick: 2·10⁴), uniform inlet with 5 % intensity; the friction factor
/// f = (−dp/dz) D / (½ ρ U²) from the pressure drop between 30 and 40 D against Colebrook's smooth-pipe
/// value and Blasius f = 0.316 Re^(−1/4) (Blasius 1913). The first cell centre sits at y+ ≈ 30–60.
///
/// The pipe wall is the grid side r = 0.5 m, or with `wall: PipeWall::Blocked(m)` the inner faces of `m`
/// rings of blocked cells added outside r = 0.5 m (the wall functions on blocked-cell faces).
pub fn turbulent_pipe_friction(
    re: f64,
    nr: usize,
    nz: usize,
    length: f64,
    model: crate::turbulence::KEpsilon,
    wall: PipeWall,
) -> Result<(f64, f64), crate::FlowError> {
    let f = turbulent_pipe_flow(re, nr, nz, length, model, wall)?;
    Ok((pipe_friction(&f, nr, length), f.velocity_at([0.0, length - 10.0, 0.5]).map_or(f64::NAN, |v| v[1])))
}

/// The steady flow of [`turbulent_pipe_friction`].
pub fn turbulent_pipe_flow(
    re: f64,
    nr: usize,
    nz: usize,
    length: f64,
    model: crate::turbulence::KEpsilon,
    wall: PipeWall,
) -> Result<Flow, crate::FlowError> {
    let rings = match wall {
        PipeWall::Side => 0,
        PipeWall::Blocked(m) => m,
    };
    let h = 0.5 / nr as f64;
    let grid = Grid::new(
        [
            Axis::uniform(0.0, 0.5 + rings as f64 * h, nr + rings)?,
            Axis::uniform(0.0, length, nz)?,
            Axis::uniform(0.0, 1.0, 1)?,
        ],
        Mode::Axisymmetric,
    )
    .map_err(|e| crate::FlowError::Setup(e.to_string()))?;
    let bc = [
        Boundary::Axis,
        Boundary::Wall { velocity_m_s: [0.0; 3] },
        Boundary::Inlet { velocity_m_s: [0.0, 1.0, 0.0], table: Default::default() },
        Boundary::Outlet { pressure_pa: 0.0 },
        Boundary::Slip,
        Boundary::Slip,
    ];
    let l = grid.layout;
    let blocked: Vec<bool> =
        (0..l.len()).map(|c| l.interior(l.coords(c)) && l.coords(c)[0] >= GHOST + nr).collect();
    let mut f =
        Flow::new(grid, Fluid { density: 1.0, viscosity: 1.0 / re }, bc, blocked, Numerics::default())?;
    f.enable_k_epsilon(model);
    // Steady to 10⁻⁴ m/s per time unit, at most 4 flow-throughs.
    cavity::run_to_steady(&mut f, 1e-4, 4.0 * length)?;
    Ok(f)
}

/// Darcy f = (−dp/dz) D / (½ ρ U²) of the pipe flow `f` of [`turbulent_pipe_flow`] (D = 1 m, U = 1 m/s,
/// ρ = 1 kg/m³) from the section-mean pressures 20 and 10 m before the outlet.
pub fn pipe_friction(f: &Flow, nr: usize, length: f64) -> f64 {
    let p_at = |z: f64| {
        let j = f.grid.axes[1].locate(z);
        // Area-weighted mean pressure over the section.
        let (mut pa, mut a) = (0.0, 0.0);
        for i in 0..nr {
            let r = f.grid.axes[0].centre(i);
            pa += f.cell_pressure(i, j, 0) * r;
            a += r;
        }
        (f.grid.axes[1].centre(j), pa / a)
    };
    let (z1, p1) = p_at(length - 20.0);
    let (z2, p2) = p_at(length - 10.0);
    -(p2 - p1) / (z2 - z1) / 0.5
}

/// Where the wall of [`turbulent_pipe_friction`]'s pipe is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PipeWall {
    /// The grid side r = 0.5 m.
    Side,
    /// The faces of this many rings of blocked cells outside r = 0.5 m.
    Blocked(usize),
}

const COLEBROOK: &str = "Colebrook (1939) smooth pipe; Blasius (1913) f = 0.316 Re^-0.25";

fn turbulent_pipe(quick: bool) -> Vec<Check> {
    let case = "cfd_pipe_k_epsilon_friction";
    let (re, nr, nz) = if quick { (2e4, 8, 100) } else { (5e4, 12, 100) };
    match turbulent_pipe_friction(
        re,
        nr,
        nz,
        50.0,
        crate::turbulence::KEpsilon::standard(0.05, 0.07),
        PipeWall::Side,
    ) {
        Ok((f, _)) => vec![
            Check::relative(
                case,
                format!("Darcy f at Re = {re:e}, {nr}x{nz}, vs Colebrook [-]"),
                colebrook_smooth(re),
                f,
                0.10,
                COLEBROOK,
            ),
            Check::relative(
                case,
                format!("Darcy f at Re = {re:e} vs Blasius [-]"),
                0.316 * re.powf(-0.25),
                f,
                0.10,
                COLEBROOK,
            ),
        ],
        Err(e) => vec![Check::absolute(case, format!("run failed: {e}"), 0.0, f64::NAN, 0.0, COLEBROOK)],
    }
}

fn pipe(quick: bool) -> Vec<Check> {
    let case = "cfd_pipe_axisymmetric";
    // D = 1, L = 4, U = 1, ν = 0.1 (Re = 10).
    let (nr, nz) = if quick { (16, 64) } else { (32, 128) };
    let run = || -> Result<Flow, crate::FlowError> {
        let grid = Grid::new(
            [Axis::uniform(0.0, 0.5, nr)?, Axis::uniform(0.0, 4.0, nz)?, Axis::uniform(0.0, 1.0, 1)?],
            Mode::Axisymmetric,
        )
        .map_err(|e| crate::FlowError::Setup(e.to_string()))?;
        let bc = [
            Boundary::Axis,
            Boundary::Wall { velocity_m_s: [0.0; 3] },
            Boundary::Inlet { velocity_m_s: [0.0, 1.0, 0.0], table: Default::default() },
            Boundary::Outlet { pressure_pa: 0.0 },
            Boundary::Slip,
            Boundary::Slip,
        ];
        let n = grid.layout.len();
        let mut f =
            Flow::new(grid, Fluid { density: 1.0, viscosity: 0.1 }, bc, vec![false; n], Numerics::default())?;
        settle(&mut f, 40.0)?;
        Ok(f)
    };
    let f = match run() {
        Ok(f) => f,
        Err(e) => return vec![Check::absolute(case, format!("run failed: {e}"), 0.0, f64::NAN, 0.0, WHITE)],
    };
    let mut err = 0.0f64;
    for i in 0..nr {
        let r = f.grid.axes[0].centre(i);
        let u = f.velocity_at([r, 3.0, 0.5]).map_or(f64::NAN, |v| v[1]);
        err = err.max((u - 2.0 * (1.0 - r * r / 0.25)).abs());
    }
    let p_at = |z: f64| {
        let j = f.grid.axes[1].locate(z);
        (f.grid.axes[1].centre(j), f.cell_pressure(0, j, 0))
    };
    let (z1, p1) = p_at(2.5);
    let (z2, p2) = p_at(3.5);
    let dpdz = (p2 - p1) / (z2 - z1);
    vec![
        Check::absolute(
            case,
            format!("max |u - 2U(1 - r^2/R^2)| at z = 3D, {nr}x{nz} [m/s]"),
            0.0,
            err,
            0.03,
            WHITE,
        ),
        Check::relative(case, "dp/dz = -32 mu U / D^2 [Pa/m]", -3.2, dpdz, 0.02, WHITE),
        Check::absolute(case, "net outflow [m^3/s per rad]", 0.0, f.net_outflow(), 1e-9, "continuity"),
    ]
}

/// Largest velocity error of the decaying Taylor–Green vortex on an n×n grid at t = 1 (ν = 0.1).
pub fn taylor_green_error(n: usize, scheme: crate::momentum::Convection) -> Result<f64, crate::FlowError> {
    use std::f64::consts::PI;
    let grid = Grid::new(
        [Axis::uniform(0.0, PI, n)?, Axis::uniform(0.0, PI, n)?, Axis::uniform(0.0, PI / n as f64, 1)?],
        Mode::Cartesian,
    )
    .map_err(|e| crate::FlowError::Setup(e.to_string()))?;
    let bc = [Boundary::Slip, Boundary::Slip, Boundary::Slip, Boundary::Slip, Boundary::Slip, Boundary::Slip];
    let nu = 0.1;
    let len = grid.layout.len();
    let numerics = Numerics {
        convection: scheme,
        pressure: crate::pcg::PcgSettings { rtol: 1e-12, ..Default::default() },
        ..Default::default()
    };
    let mut f = Flow::new(grid, Fluid { density: 1.0, viscosity: nu }, bc, vec![false; len], numerics)?;
    let l = f.grid.layout;
    let exact = |x: f64, y: f64, t: f64| {
        let d = (-2.0 * nu * t).exp();
        [x.sin() * y.cos() * d, -x.cos() * y.sin() * d]
    };
    for c in 0..len {
        let q = l.coords(c);
        let m = &f.grid.metric;
        f.state.u[0][c] = exact(m[0].xf[q[0]], m[1].xc[q[1]], 0.0)[0];
        f.state.u[1][c] = exact(m[0].xc[q[0]], m[1].xf[q[1]], 0.0)[1];
    }
    f.fill_boundaries(0.0);
    // Δt ∝ h² (half the explicit diffusion limit): the time error falls faster than the space error, so
    // the observed order is the spatial one.
    let h = PI / n as f64;
    let steps = (1.0 / (0.5 * 0.9 * h * h / (8.0 * nu))).ceil() as usize;
    let dt = 1.0 / steps as f64;
    for _ in 0..steps {
        f.step(dt)?;
    }
    let t = f.state.t;
    let mut err = 0.0f64;
    for c in 0..len {
        let q = l.coords(c);
        if !l.interior(q) {
            continue;
        }
        let m = &f.grid.metric;
        err = err.max((f.state.u[0][c] - exact(m[0].xf[q[0]], m[1].xc[q[1]], t)[0]).abs());
        err = err.max((f.state.u[1][c] - exact(m[0].xc[q[0]], m[1].xf[q[1]], t)[1]).abs());
    }
    Ok(err)
}

fn taylor_green(quick: bool) -> Vec<Check> {
    use crate::momentum::Convection;
    let case = "cfd_taylor_green_order";
    let src = "Taylor & Green (1937), exact decaying solution";
    let (n1, n2) = if quick { (16, 32) } else { (32, 64) };
    let mut out = Vec::new();
    for sch in [Convection::Central, Convection::VanLeer] {
        match (taylor_green_error(n1, sch), taylor_green_error(n2, sch)) {
            (Ok(e1), Ok(e2)) => {
                let order = (e1 / e2).log2();
                out.push(Check::absolute(
                    case,
                    format!("{sch:?}: max velocity error at t = 1, {n2}x{n2} [m/s]"),
                    0.0,
                    e2,
                    2e-4,
                    src,
                ));
                // Linear interpolation: the scheme's formal order 2. Van Leer: clipping at extrema adds
                // errors that vanish faster than h² on coarse grids, so its observed order lies between 2
                // and 3.2 (measured 2.8, 3.1, 2.5 for 8→16→32→64) and tends to 2.
                let (reference, tol, what) = match sch {
                    Convection::VanLeer => (2.6, 0.6, "in [2, 3.2]"),
                    _ => (2.0, 0.15, "2"),
                };
                out.push(Check::absolute(
                    case,
                    format!("{sch:?}: observed order of convergence {n1} -> {n2}, expected {what} [-]"),
                    reference,
                    order,
                    tol,
                    src,
                ));
            }
            (a, b) => {
                let msg = a.err().or(b.err()).map(|e| e.to_string()).unwrap_or_default();
                out.push(Check::absolute(case, format!("run failed: {msg}"), 0.0, f64::NAN, 0.0, src));
            }
        }
    }
    out
}

impl From<crate::grid::AxisError> for crate::FlowError {
    fn from(e: crate::grid::AxisError) -> Self {
        crate::FlowError::Setup(e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_all(checks: Vec<Check>) {
        for c in &checks {
            eprintln!(
                "{} | {} | ref {} | ours {} | {:?}",
                c.case, c.quantity, c.reference, c.ours, c.tolerance
            );
        }
        for c in &checks {
            assert!(c.passed(), "{c:?}");
        }
    }

    #[test]
    fn cavity_re100_quick_case_passes() {
        assert_all(cavity_re100(true));
    }

    /// About a minute: run with `cargo test -p spatter-cfd -- --ignored`.
    #[test]
    #[ignore]
    fn cavity_re1000_quick_case_passes() {
        assert_all(cavity_re1000(true));
    }

    #[test]
    fn channel_poiseuille_profile_and_pressure_gradient() {
        assert_all(channel(true));
    }

    #[test]
    fn axisymmetric_hagen_poiseuille() {
        assert_all(pipe(true));
    }

    #[test]
    fn taylor_green_decay_converges_at_second_order() {
        assert_all(taylor_green(true));
    }
}

#[cfg(test)]
mod turbulent_tests {
    use super::*;

    #[test]
    fn colebrook_matches_the_moody_chart() {
        // Smooth-pipe values of the Moody chart (Moody 1944): f(10⁴) ≈ 0.0309, f(10⁵) ≈ 0.0180.
        assert!((colebrook_smooth(1e4) - 0.0309).abs() < 3e-4, "{}", colebrook_smooth(1e4));
        assert!((colebrook_smooth(1e5) - 0.0180).abs() < 2e-4, "{}", colebrook_smooth(1e5));
    }

    /// Re = 2·10⁴ on 8 × 100 cells (y+ ≈ 35): about 30 s in a debug build.
    #[test]
    fn k_epsilon_pipe_friction_factor_within_ten_percent_of_colebrook_and_blasius() {
        let checks = turbulent_pipe(true);
        for c in &checks {
            eprintln!("{} | {} | ref {} | ours {}", c.case, c.quantity, c.reference, c.ours);
            assert!(c.passed(), "{c:?}");
        }
    }

    /// Wall functions on the faces of blocked cells: the pipe of the quick case (standard k–ε, Re = 2·10⁴,
    /// 8 × 100 cells) once with the grid side as its wall and once with two rings of blocked cells
    /// outside r = R. The blocked wall reaches Darcy f within 10 % of Colebrook (1939) (measured −5.4 %,
    /// as the side wall) and agrees with the side wall to 10⁻⁴ in f and in every cell's velocity (the same
    /// wall law on the same cells; measured 6·10⁻⁸ in f); the developed profile 10 D before the outlet
    /// follows the 1/7 power law u/U_b = (60/49)(1 − r/R)^{1/7} (Nikuradse's smooth-pipe profiles, as
    /// given by Schlichting, Boundary-Layer Theory, ch. 20) within 4 % at every cell centre (measured:
    /// largest deviation −3.0 % in the wall cell, −2.3 % on the axis).
    #[test]
    fn k_epsilon_wall_functions_act_on_blocked_cell_faces_as_on_the_grid_sides() {
        let (re, nr, nz, len) = (2e4, 8, 100, 50.0);
        let model = crate::turbulence::KEpsilon::standard(0.05, 0.07);
        let side = turbulent_pipe_flow(re, nr, nz, len, model, PipeWall::Side).unwrap();
        let solid = turbulent_pipe_flow(re, nr, nz, len, model, PipeWall::Blocked(2)).unwrap();
        let (fs, fb) = (pipe_friction(&side, nr, len), pipe_friction(&solid, nr, len));
        let fc = colebrook_smooth(re);
        eprintln!("Darcy f: side wall {fs}, blocked wall {fb}, Colebrook {fc}");
        assert!((fb / fc - 1.0).abs() < 0.10, "blocked wall f = {fb}, Colebrook {fc}");
        assert!((fb / fs - 1.0).abs() < 1e-4, "blocked wall f = {fb}, side wall {fs}");
        let j = side.grid.axes[1].locate(len - 10.0);
        for i in 0..nr {
            let r = side.grid.axes[0].centre(i) / 0.5;
            let law = 60.0 / 49.0 * (1.0 - r).powf(1.0 / 7.0);
            let (us, ub) = (side.cell_velocity(i, j, 0)[1], solid.cell_velocity(i, j, 0)[1]);
            eprintln!("r/R = {r:.4}: u/U_b side {us:.4}, blocked {ub:.4}, 1/7 law {law:.4}");
            assert!((ub / us - 1.0).abs() < 1e-4, "r/R = {r}: blocked {ub}, side {us}");
            assert!((ub / law - 1.0).abs() < 0.04, "r/R = {r}: blocked {ub}, 1/7 law {law}");
        }
        // No k inside the solid, and the blocked cells next to the fluid carry the wall viscosity.
        let t = solid.turbulence.as_ref().unwrap();
        let l = solid.grid.layout;
        let (c_wall, c_fluid) = (l.cell(nr, j, 0), l.cell(nr - 1, j, 0));
        assert!(t.nu_eff[c_wall] < t.nu_eff[c_fluid], "{} vs {}", t.nu_eff[c_wall], t.nu_eff[c_fluid]);
    }

    /// The realizable model (Shih et al. 1995) in the pipe of the full validation case (Re = 5·10⁴,
    /// 12 × 100 cells): Darcy f within 10 % of Colebrook (1939) and Blasius (1913), the accuracy usually
    /// quoted for k–ε models with wall functions. **Fails today**: f = 0.01883, −9.9 % from Colebrook and
    /// −10.9 % from Blasius (at Re = 2·10⁴ on 8 × 100 cells −10.3 %), about 5 % below the standard model
    /// on the same grid; the cause is not found yet (docs/cfd.md §2). Run it with `--ignored`.
    #[test]
    #[ignore = "known deviation: realizable pipe friction 10-11 % low, see docs/cfd.md section 2"]
    fn realizable_k_epsilon_pipe_friction_factor_within_ten_percent_of_colebrook_and_blasius() {
        let re = 5e4;
        let model = crate::turbulence::KEpsilon::realizable(0.05, 0.07);
        let (f, uc) = turbulent_pipe_friction(re, 12, 100, 50.0, model, PipeWall::Side).unwrap();
        eprintln!("realizable: f = {f}, centreline {uc}, Colebrook {}", colebrook_smooth(re));
        assert!((f / colebrook_smooth(re) - 1.0).abs() < 0.10, "f = {f}");
        assert!((f / (0.316 * re.powf(-0.25)) - 1.0).abs() < 0.10, "f = {f}");
    }

    #[test]
    fn k_epsilon_is_thread_count_independent_and_resumes_bit_for_bit() {
        let build = || {
            let grid = Grid::new(
                [
                    Axis::uniform(0.0, 0.5, 8).unwrap(),
                    Axis::uniform(0.0, 10.0, 40).unwrap(),
                    Axis::uniform(0.0, 1.0, 1).unwrap(),
                ],
                Mode::Axisymmetric,
            )
            .unwrap();
            let bc = [
                Boundary::Axis,
                Boundary::Wall { velocity_m_s: [0.0; 3] },
                Boundary::Inlet { velocity_m_s: [0.0, 1.0, 0.0], table: Default::default() },
                Boundary::Outlet { pressure_pa: 0.0 },
                Boundary::Slip,
                Boundary::Slip,
            ];
            let n = grid.layout.len();
            let mut f = Flow::new(
                grid,
                Fluid { density: 1.0, viscosity: 5e-5 },
                bc,
                vec![false; n],
                Numerics::default(),
            )
            .unwrap();
            f.enable_k_epsilon(crate::turbulence::KEpsilon::standard(0.05, 0.07));
            f
        };
        let run = |threads: usize, split: Option<usize>| {
            rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
                let mut f = build();
                let dir = tempfile::tempdir().unwrap();
                let path = dir.path().join("checkpoint.bin");
                for s in 0..30 {
                    if Some(s) == split {
                        spatter_io::checkpoint::save(&path, 7, &f.state).unwrap();
                        f = build();
                        f.restore(spatter_io::checkpoint::load(&path, 7).unwrap()).unwrap();
                    }
                    let dt = f.stable_dt(0.5, 0.1);
                    f.step(dt).unwrap();
                }
                let t = f.state.turbulence.clone().unwrap();
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                (bits(&f.state.u[1]), bits(&f.state.p), bits(&t.k), bits(&t.eps))
            })
        };
        let straight = run(1, None);
        assert!(straight.2.iter().any(|&k| f64::from_bits(k) > 0.0));
        assert_eq!(run(2, None), straight, "2 threads give the same bits as 1");
        assert_eq!(run(1, Some(13)), straight, "resume changes nothing");
    }
}
