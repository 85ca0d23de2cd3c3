//! Tests of the sides that hold the pressure: fixed-pressure outlets.

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
