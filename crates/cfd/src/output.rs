//! What a flow leaves on disk: cell fields as a VTK rectilinear grid (`.vtr`), values at points (probes)
//! and 2D slices of the speed for pictures.
//!
//! Cell values are the averages of the two staggered face values per component; blocked cells carry zero
//! velocity and pressure and are marked by the `solid` array (1 = blocked).

use crate::grid::Mode;
use crate::solver::Flow;
use spatter_io::vtr::Vtr;

/// Cell-centred velocity \[m/s\], static pressure \[Pa\] and solid flags of every interior cell, x fastest.
pub struct CellFields {
    pub velocity: Vec<[f64; 3]>,
    pub pressure: Vec<f64>,
    pub solid: Vec<i64>,
}

/// The cell fields of `flow`.
pub fn cell_fields(flow: &Flow) -> CellFields {
    let l = flow.grid.layout;
    let n = l.cells();
    let mut out = CellFields {
        velocity: Vec::with_capacity(n),
        pressure: Vec::with_capacity(n),
        solid: Vec::with_capacity(n),
    };
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            for i in 0..l.n[0] {
                let c = l.cell(i, j, k);
                if flow.blocked[c] {
                    out.velocity.push([0.0; 3]);
                    out.pressure.push(0.0);
                    out.solid.push(1);
                } else {
                    out.velocity.push(flow.cell_velocity(i, j, k));
                    out.pressure.push(flow.cell_pressure(i, j, k));
                    out.solid.push(0);
                }
            }
        }
    }
    out
}

/// The flow as a `.vtr` builder with cell arrays `velocity_m_s`, `pressure_Pa` and `solid`, and
/// `k_m2_s2`, `epsilon_m2_s3`, `nu_t_m2_s` when the k–ε model runs; more arrays can be chained by the
/// caller. Coordinates are the grid's faces; an axisymmetric
/// grid is written as its (r, z) plane with the one-radian third axis as given.
pub fn to_vtr(flow: &Flow) -> std::io::Result<Vtr> {
    let f = cell_fields(flow);
    let ax = &flow.grid.axes;
    let mut v = Vtr::new(ax[0].faces(), ax[1].faces(), ax[2].faces())?
        .cell_vector("velocity_m_s", &f.velocity)
        .cell_scalar("pressure_Pa", &f.pressure)
        .cell_int("solid", &f.solid);
    if let (Some(ts), Some(t)) = (&flow.state.turbulence, &flow.turbulence) {
        let l = flow.grid.layout;
        let cells = |val: &dyn Fn(usize) -> f64| -> Vec<f64> {
            let mut out = Vec::with_capacity(l.cells());
            for k in 0..l.n[2] {
                for j in 0..l.n[1] {
                    for i in 0..l.n[0] {
                        let c = l.cell(i, j, k);
                        out.push(if flow.blocked[c] { 0.0 } else { val(c) });
                    }
                }
            }
            out
        };
        let nu = flow.fluid.viscosity;
        v = v
            .cell_scalar("k_m2_s2", &cells(&|c| ts.k[c]))
            .cell_scalar("epsilon_m2_s3", &cells(&|c| ts.eps[c]))
            .cell_scalar("nu_t_m2_s", &cells(&|c| t.nu_eff[c] - nu));
    }
    Ok(v)
}

/// k \[m²/s²\] and ε \[m²/s³\] of the cell holding `x`, when a turbulence model runs; `None` outside the
/// grid, in a solid or for laminar flows.
pub fn turbulence_at(flow: &Flow, x: [f64; 3]) -> Option<(f64, f64)> {
    let ts = flow.state.turbulence.as_ref()?;
    let g = &flow.grid;
    for a in 0..3 {
        if !(x[a] >= g.axes[a].lo() && x[a] <= g.axes[a].hi()) {
            return None;
        }
    }
    let q = [0, 1, 2].map(|a| g.axes[a].locate(x[a]));
    let c = g.layout.cell(q[0], q[1], q[2]);
    (!flow.blocked[c]).then(|| (ts.k[c], ts.eps[c]))
}

/// A planar cut of the grid normal to axis `normal` through the cell layer holding coordinate `at`:
/// the face coordinates of the two in-plane axes (in increasing axis order) and the speed |u| per cell,
/// NaN in solids.
pub struct Slice {
    /// The in-plane axes (e.g. [0, 1] for a cut normal to z).
    pub axes: [usize; 2],
    pub h_faces: Vec<f64>,
    pub v_faces: Vec<f64>,
    /// |u| \[m/s\] per cell, horizontal index fastest.
    pub speed: Vec<f64>,
    /// The layer cut (interior index along `normal`).
    pub layer: usize,
}

/// The speed on the cut normal to `normal` (0, 1 or 2) at coordinate `at` \[m\] (clamped to the grid).
pub fn speed_slice(flow: &Flow, normal: usize, at: f64) -> Slice {
    let g = &flow.grid;
    let axes = match normal {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    };
    let layer = g.axes[normal].locate(at);
    let (nh, nv) = (g.layout.n[axes[0]], g.layout.n[axes[1]]);
    let mut speed = Vec::with_capacity(nh * nv);
    for b in 0..nv {
        for a in 0..nh {
            let mut q = [0; 3];
            q[normal] = layer;
            q[axes[0]] = a;
            q[axes[1]] = b;
            let c = g.layout.cell(q[0], q[1], q[2]);
            speed.push(if flow.blocked[c] {
                f64::NAN
            } else {
                let u = flow.cell_velocity(q[0], q[1], q[2]);
                (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt()
            });
        }
    }
    Slice {
        axes,
        h_faces: g.axes[axes[0]].faces().to_vec(),
        v_faces: g.axes[axes[1]].faces().to_vec(),
        speed,
        layer,
    }
}

/// Velocity \[m/s\] and static pressure \[Pa\] at point `x`: velocity interpolated trilinearly from the
/// staggered nodes ([`Flow::velocity_at`]), pressure of the cell holding the point. `None` outside the
/// grid or inside a solid.
pub fn probe(flow: &Flow, x: [f64; 3]) -> Option<([f64; 3], f64)> {
    let g = &flow.grid;
    let u = flow.velocity_at(x)?;
    let q = [0, 1, 2].map(|a| g.axes[a].locate(x[a]));
    let c = g.layout.cell(q[0], q[1], q[2]);
    if flow.blocked[c] {
        return None;
    }
    Some((u, flow.cell_pressure(q[0], q[1], q[2])))
}

/// Names of the coordinate axes of a grid mode, for labels.
pub fn axis_names(mode: Mode) -> [&'static str; 3] {
    match mode {
        Mode::Cartesian => ["x", "y", "z"],
        Mode::Axisymmetric => ["r", "z", "θ"],
    }
}

/// Kinetic energy of the fluid per unit density, ½ Σ |u|² V over fluid cells \[m⁵/s²\] (per radian when
/// axisymmetric), from the cell-centred velocity.
pub fn kinetic_energy(flow: &Flow) -> f64 {
    let l = flow.grid.layout;
    let mut e = 0.0;
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            for i in 0..l.n[0] {
                let c = l.cell(i, j, k);
                if !flow.blocked[c] {
                    let u = flow.cell_velocity(i, j, k);
                    let q = l.coords(c);
                    e += 0.5 * (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) * flow.grid.volume(q);
                }
            }
        }
    }
    e
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::Boundary;
    use crate::grid::{Axis, Grid};
    use crate::solver::{Fluid, Numerics};

    /// A closed box with a prescribed velocity field written straight into the state.
    fn flow_with_field() -> Flow {
        let g = Grid::new(
            [
                Axis::geometric(0.0, 2.0, 8, 1.1).unwrap(),
                Axis::uniform(0.0, 1.0, 4).unwrap(),
                Axis::uniform(0.0, 0.5, 2).unwrap(),
            ],
            Mode::Cartesian,
        )
        .unwrap();
        let solid = crate::solid::Solid::Box { min_m: [1.5, 0.0, 0.0], max_m: [2.0, 0.25, 0.5] };
        let blocked = crate::solid::blocked_cells(&g, &[solid]).unwrap();
        let wall = Boundary::Wall { velocity_m_s: [0.0; 3] };
        let bc = std::array::from_fn(|_| wall.clone());
        let mut f =
            Flow::new(g, Fluid { density: 2.0, viscosity: 1e-3 }, bc, blocked, Numerics::default()).unwrap();
        // u = x at the u-nodes (x faces), v = 0, w = 0; p/ρ = y at the centres.
        let l = f.grid.layout;
        for c in 0..l.len() {
            let q = l.coords(c);
            f.state.u[0][c] = f.grid.metric[0].xf[q[0]];
            f.state.p[c] = f.grid.metric[1].xc[q[1]];
        }
        f
    }

    #[test]
    fn cell_fields_average_faces_and_mark_solids() {
        let f = flow_with_field();
        let cf = cell_fields(&f);
        let l = f.grid.layout;
        assert_eq!(cf.velocity.len(), l.cells());
        let ax = &f.grid.axes;
        // Cell (2, 1, 0): u = mean of its face coordinates = its centre x; p = ρ y_c.
        let c = 2 + 8; // i + nx·j with j = 1
        assert!((cf.velocity[c][0] - ax[0].centre(2)).abs() < 1e-14);
        assert!((cf.pressure[c] - 2.0 * ax[1].centre(1)).abs() < 1e-14);
        let solids = cf.solid.iter().filter(|&&s| s == 1).count();
        let expect = (0..8).filter(|&i| ax[0].centre(i) >= 1.5).count() * 2;
        assert_eq!(solids, expect, "cells with centres in the box: x ≥ 1.5, y < 0.25, both z layers");
        let v = to_vtr(&f).unwrap();
        assert_eq!(v.cells_per_axis(), [8, 4, 2]);
    }

    #[test]
    fn slices_and_probes_read_the_right_cells() {
        let f = flow_with_field();
        let s = speed_slice(&f, 2, 0.4);
        assert_eq!((s.axes, s.layer), ([0, 1], 1));
        assert_eq!(s.speed.len(), 32);
        let ax = &f.grid.axes;
        assert!((s.speed[3 + 8 * 2] - ax[0].centre(3)).abs() < 1e-14);
        assert!(s.speed[7].is_nan(), "solid corner cell (7, 0)");
        // Probe between nodes: u linear in x, so trilinear interpolation is exact; p of the cell.
        let (u, p) = probe(&f, [0.7, 0.6, 0.1]).unwrap();
        assert!((u[0] - 0.7).abs() < 1e-12, "{u:?}");
        assert!((p - 2.0 * ax[1].centre(2)).abs() < 1e-14);
        assert!(probe(&f, [1.9, 0.1, 0.1]).is_none(), "inside the solid");
        assert!(probe(&f, [2.5, 0.1, 0.1]).is_none(), "outside the grid");
    }
}
