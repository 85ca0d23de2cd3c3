//! Tests of the sides that hold the pressure: fixed-pressure outlets and total-pressure sides.

use crate::bc::{Boundary, TimeTable};
use crate::grid::{Axis, Grid, Mode};
use crate::{Flow, Fluid, Numerics};

fn wall() -> Boundary {
    Boundary::Wall { velocity_m_s: [0.0; 3] }
}

fn flow(len: [f64; 3], n: [usize; 3], fluid: Fluid, bc: [Boundary; 6]) -> Flow {
    let ax = |a: usize| Axis::uniform(0.0, len[a], n[a]).unwrap();
    let grid = Grid::new([ax(0), ax(1), ax(2)], Mode::Cartesian).unwrap();
    let blocked = vec![false; grid.layout.len()];
    Flow::new(grid, fluid, bc, blocked, Numerics::default()).unwrap()
}

/// Mean normal velocity over the fluid faces of interior x-layer face `i` (between cells i − 1 and i).
fn mean_u(f: &Flow, i: usize) -> f64 {
    let l = f.grid.layout;
    let (mut sum, mut area) = (0.0, 0.0);
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            let c = l.cell(i, j, k) - 1;
            let q = l.coords(c);
            let w = f.grid.face_area(0, q);
            sum += w * f.state.u[0][c];
            area += w;
        }
    }
    sum / area
}

#[test]
fn outlet_pressure_shifts_the_pressure_field_and_nothing_else() {
    // A channel with a ramped, slanted inlet and two outlets, run with outlet pressure 0 and P: the
    // velocities agree to round-off and the pressure (cells, probes, VTK field) is shifted by P.
    let p_out = 2.5e4;
    let run = |p: f64| {
        let out = Boundary::Outlet { pressure_pa: p };
        let inlet = Boundary::Inlet { velocity_m_s: [1.0, 0.1, 0.0], table: TimeTable::ramp(0.3) };
        let bc = [inlet, out.clone(), wall(), out, Boundary::Slip, wall()];
        let mut f = flow([4.0, 1.0, 0.5], [32, 8, 3], Fluid { density: 1.2, viscosity: 0.05 }, bc);
        for _ in 0..60 {
            f.step(0.01).unwrap();
        }
        f
    };
    let (a, b) = (run(0.0), run(p_out));
    let mut du = 0.0f64;
    for c in 0..3 {
        for (x, y) in a.state.u[c].iter().zip(&b.state.u[c]) {
            du = du.max((x - y).abs());
        }
    }
    // Round-off: the velocity is of order 1 m/s; differences of p/ρ ≈ 2·10⁴ m²/s² lose about
    // 2·10⁴ ε ≈ 4·10⁻¹² of absolute precision per step.
    assert!(du < 1e-9, "velocity changed by {du:e} m/s");
    let l = a.grid.layout;
    let mut dp = 0.0f64;
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            for i in 0..l.n[0] {
                dp = dp.max((b.cell_pressure(i, j, k) - a.cell_pressure(i, j, k) - p_out).abs());
            }
        }
    }
    assert!(dp < 1e-6, "pressure shift differs from {p_out} Pa by {dp:e} Pa");
    let x = [2.1, 0.4, 0.2];
    let (pa, pb) = (crate::output::probe(&a, x).unwrap().1, crate::output::probe(&b, x).unwrap().1);
    assert!((pb - pa - p_out).abs() < 1e-6, "probe: {pa} and {pb} Pa");
    let (fa, fb) = (crate::output::cell_fields(&a), crate::output::cell_fields(&b));
    for (x, y) in fa.pressure.iter().zip(&fb.pressure) {
        assert!((y - x - p_out).abs() < 1e-6, "VTK pressure {x} and {y} Pa");
    }
}

/// A duct with slip walls between a total-pressure side p₀ on x_min and an outlet at p_out on x_max.
fn bernoulli_duct(rho: f64, p_out: f64, dp: f64, length: f64) -> Flow {
    let tp = Boundary::TotalPressure { total_pressure_pa: p_out + dp, table: TimeTable::default() };
    let bc = [
        tp,
        Boundary::Outlet { pressure_pa: p_out },
        Boundary::Slip,
        Boundary::Slip,
        Boundary::Slip,
        Boundary::Slip,
    ];
    flow([length, 0.2, 0.2], [20, 4, 4], Fluid { density: rho, viscosity: 1e-3 }, bc)
}

#[test]
fn frictionless_duct_starts_up_along_the_plug_equation_and_reaches_the_bernoulli_speed() {
    // Without friction the fluid moves as a plug of length L: L dU/dt = (p_in − p_out)/ρ with the face
    // pressure p_in = p₀ − ½ρU² (Bernoulli from rest to the inlet face), so
    // U(t) = U∞ tanh(U∞ t / (2L)) with U∞ = √(2(p₀ − p_out)/ρ) (Bernoulli's equation along a streamline,
    // e.g. White, Fluid Mechanics, 7th ed., §3.5). The face pressure follows the velocity of the previous
    // step, so the discrete start-up is the forward-Euler solution of that equation: its error is O(Δt),
    // 1.2·10⁻³ at most with Δt = 0.005 s (U∞Δt/2L = 0.005). Tolerances: 0.5 % on the start-up, 0.1 % on the
    // speed at t = 6 s (tanh 6 = 1 − 1.2·10⁻⁵).
    let (rho, p_out, dp, length): (f64, f64, f64, f64) = (1.2, 50.0, 2.4, 1.0);
    let u_inf = (2.0 * dp / rho).sqrt();
    let mut f = bernoulli_duct(rho, p_out, dp, length);
    let dt = 0.005;
    let mut worst: f64 = 0.0;
    for n in 1..=1200 {
        f.step(dt).unwrap();
        let t = n as f64 * dt;
        if n % 50 == 0 && t <= 2.0 {
            let exact = u_inf * (u_inf * t / (2.0 * length)).tanh();
            worst = worst.max((mean_u(&f, 10) / exact - 1.0).abs());
        }
    }
    assert!(worst < 0.005, "start-up off the plug equation by {worst}");
    let u = mean_u(&f, 10);
    assert!((u / u_inf - 1.0).abs() < 1e-3, "U = {u} m/s, Bernoulli {u_inf} m/s");
    // Plug flow: every x face carries the same speed, and the outlet holds its pressure.
    for i in 0..=20 {
        assert!((mean_u(&f, i) - u).abs() < 1e-9 * u_inf, "face {i}");
    }
    let p_last = f.cell_pressure(19, 1, 1);
    assert!((p_last - p_out).abs() < 1e-3 * dp, "last cell {p_last} Pa, outlet {p_out} Pa");
}

/// Mean speed \[m/s\] of the steady laminar channel of height h = 1 m and length L = 4 m (ν = 0.1 m²/s,
/// ρ = 1 kg/m³, no-slip walls at y = 0 and h, slip in z) driven by a total-pressure side p₀ = p_out + Δp on
/// x_min against an outlet at p_out = 10 Pa on x_max, on `ny` cells across (8 ny along).
fn channel_speed(dp: f64, ny: usize) -> (f64, f64) {
    let p_out = 10.0;
    let tp = Boundary::TotalPressure { total_pressure_pa: p_out + dp, table: TimeTable::default() };
    let bc = [tp, Boundary::Outlet { pressure_pa: p_out }, wall(), wall(), Boundary::Slip, Boundary::Slip];
    let mut f = flow([4.0, 1.0, 0.1], [2 * ny, ny, 1], Fluid { density: 1.0, viscosity: 0.1 }, bc);
    crate::cavity::run_to_steady(&mut f, 1e-7, 200.0).unwrap();
    (mean_u(&f, 0), mean_u(&f, ny))
}

#[test]
fn laminar_channel_between_total_and_static_pressure_carries_the_poiseuille_flow() {
    // Mean-pressure balance from the still reservoir behind the total-pressure side to the outlet
    // (kinematic):
    //   (p₀ − p_out)/ρ = ½βU² + 12νUL/h² + ½K U²,
    // with 12νUL/h² the plane-Poiseuille drop (White, Viscous Fluid Flow §3-3), β = 6/5 the mean of
    // u²/U² over the parabolic profile the zero-gradient inflow carries in at this Reynolds number (the
    // face pressure is p₀ − ½u² face by face), and K the excess loss of a developing entrance, at most
    // Shah & London's K(∞) ≈ 0.69 for parallel plates entered by a uniform profile (Shah & London 1978,
    // Laminar Flow Forced Convection in Ducts, ch. VI). Δp = 0.5 Pa gives U ≈ 0.103 m/s, Re = Uh/ν ≈ 1:
    // the viscous drop is 0.49 m²/s², ½βU² = 0.0064 and ½K U² ≤ 0.0037, so leaving K out moves U by at
    // most 0.8 %. The grid's own error: 16 cells across the channel give a Poiseuille drop 0.8 % low
    // (section 5 of docs/cfd.md), U that much high. Tolerance 2 %.
    let dp: f64 = 0.5;
    let (u_in, u) = channel_speed(dp, 16);
    let (a, b, c) = (0.5 * 1.2, 12.0 * 0.1 * 4.0, -dp);
    let u_pred = (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
    assert!((u_in / u - 1.0).abs() < 1e-6, "mass: inflow {u_in}, mid-channel {u} m/s");
    assert!((u / u_pred - 1.0).abs() < 0.02, "U = {u} m/s, predicted {u_pred} m/s");
}

#[test]
fn the_step_from_rest_between_pressure_sides_is_bounded_by_their_bernoulli_speed() {
    // Fluid at rest between p₀ = 2.4 Pa and an outlet at 0 (ρ = 1.2) is about to move at up to
    // U∞ = √(2Δp/ρ) = 2 m/s (Bernoulli); its zero velocity alone would allow any step.
    let mut f = bernoulli_duct(1.2, 0.0, 2.4, 1.0);
    assert!((f.pressure_speed(0.0) - 2.0).abs() < 1e-12);
    // Courant 0.5 over the smallest width 0.05 m at 2 m/s (the diffusion limit, 0.19 s, is larger).
    let dt = f.stable_dt(0.5, 1.0);
    assert!((dt - 0.0125).abs() < 1e-12, "dt = {dt} s");
    f.step(dt).unwrap();
    // Outlets that agree leave the step to the velocity.
    let same = Boundary::Outlet { pressure_pa: 3.0 };
    let bc = [same.clone(), same, Boundary::Slip, Boundary::Slip, Boundary::Slip, Boundary::Slip];
    let g = flow([1.0, 0.2, 0.2], [20, 4, 4], Fluid { density: 1.2, viscosity: 1e-3 }, bc);
    assert_eq!(g.pressure_speed(0.0), 0.0);
}
