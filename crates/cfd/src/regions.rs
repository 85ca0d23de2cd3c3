//! Connected fluid regions and the mass balance they must satisfy.
//!
//! Incompressible fluid cannot accumulate: a region of connected fluid cells that touches no pressure
//! pressure side (outlet or total-pressure side) must receive exactly as much volume through its inlets as it loses through them, at every time,
//! and its pressure is defined only up to a constant. The pressure solver handles one such closed region
//! (a lid-driven cavity) by working on zero-mean fields. Anything else is a set-up error, refused before
//! the first step instead of being hidden by removing the mean of the pressure equation's right-hand side:
//!
//! * an inlet feeding a closed region at a net rate (no outlet on the grid, or solids cutting the inlet off
//!   from every outlet);
//! * a fluid pocket sealed off by solids from every outlet (its pressure would float freely), or two
//!   closed regions on one grid.
//!
//! Regions are found by a flood fill over fluid cells through the faces they share; each is described to
//! the user by its cell count, its bounding box and one cell index.

use crate::bc::{Boundary, SIDES};
use crate::grid::{Grid, Mode, GHOST};

/// One connected region of fluid cells.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// Number of fluid cells.
    pub cells: usize,
    /// Interior index of the first cell found (lowest padded index).
    pub first: [usize; 3],
    /// Bounding box of the cells \[m\].
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    /// Sides that hold the pressure (outlets, total-pressure sides) with a face on this region.
    pub outlets: Vec<usize>,
    /// Sides with an inlet face on this region, with the inlet's face area on it \[m²\] (per radian when
    /// axisymmetric).
    pub inlets: Vec<(usize, f64)>,
}

impl Region {
    /// How the region is named in messages.
    pub fn describe(&self, index: usize) -> String {
        format!(
            "fluid region {} ({} cells, x {:.4}..{:.4} m, y {:.4}..{:.4} m, z {:.4}..{:.4} m, containing cell ({}, {}, {}))",
            index + 1,
            self.cells,
            self.lo[0],
            self.hi[0],
            self.lo[1],
            self.hi[1],
            self.lo[2],
            self.hi[2],
            self.first[0],
            self.first[1],
            self.first[2]
        )
    }
}

/// The fluid regions of a grid: the region label of every padded cell (`u32::MAX` for blocked and ghost
/// cells) and the regions.
#[derive(Clone, Debug)]
pub struct Regions {
    pub label: Vec<u32>,
    pub regions: Vec<Region>,
}

/// Labels the connected fluid regions of `grid` (cells not `blocked`) and records the inlet and outlet
/// sides each touches.
pub fn find(grid: &Grid, bc: &[Boundary; 6], blocked: &[bool]) -> Regions {
    let l = grid.layout;
    let mut label = vec![u32::MAX; l.len()];
    let mut regions = Vec::new();
    let mut stack = Vec::new();
    let dims = if grid.mode == Mode::Axisymmetric { 2 } else { 3 };
    for start in 0..l.len() {
        let q0 = l.coords(start);
        if label[start] != u32::MAX || !l.interior(q0) || blocked[start] {
            continue;
        }
        let id = regions.len() as u32;
        let mut reg = Region {
            cells: 0,
            first: [q0[0] - GHOST, q0[1] - GHOST, q0[2] - GHOST],
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
            outlets: Vec::new(),
            inlets: Vec::new(),
        };
        label[start] = id;
        stack.push(start);
        while let Some(c) = stack.pop() {
            let q = l.coords(c);
            reg.cells += 1;
            for a in 0..3 {
                let m = &grid.metric[a];
                reg.lo[a] = reg.lo[a].min(m.xf[q[a] - 1]);
                reg.hi[a] = reg.hi[a].max(m.xf[q[a]]);
            }
            for a in 0..dims {
                for plus in [false, true] {
                    let at_side = if plus { q[a] == GHOST + l.n[a] - 1 } else { q[a] == GHOST };
                    if at_side {
                        let side = 2 * a + usize::from(plus);
                        match &bc[side] {
                            b if b.holds_pressure() && !reg.outlets.contains(&side) => reg.outlets.push(side),
                            Boundary::Inlet { .. } => {
                                let mut qf = q;
                                if !plus {
                                    qf[a] -= 1;
                                }
                                let area = grid.face_area(a, qf);
                                match reg.inlets.iter_mut().find(|(s, _)| *s == side) {
                                    Some((_, total)) => *total += area,
                                    None => reg.inlets.push((side, area)),
                                }
                            }
                            _ => {}
                        }
                        continue;
                    }
                    let n = if plus { c + l.s[a] } else { c - l.s[a] };
                    if label[n] == u32::MAX && !blocked[n] {
                        label[n] = id;
                        stack.push(n);
                    }
                }
            }
        }
        reg.outlets.sort_unstable();
        reg.inlets.sort_by_key(|(s, _)| *s);
        regions.push(reg);
    }
    Regions { label, regions }
}

/// Volume flow \[m³/s\] an inlet on `side` with face area `area` pushes into the domain at time `t`.
fn inflow(bc: &Boundary, side: usize, area: f64, t: f64) -> f64 {
    let a = side / 2;
    let sign = if side % 2 == 0 { 1.0 } else { -1.0 };
    bc.velocity(t).map_or(0.0, |v| sign * v[a] * area)
}

/// Checks that every fluid region can satisfy continuity: see the module documentation. The error names
/// the region (cells, extent) and the inlet side involved.
pub fn check_mass_balance(grid: &Grid, bc: &[Boundary; 6], regions: &Regions) -> Result<(), String> {
    let closed: Vec<usize> =
        (0..regions.regions.len()).filter(|&r| regions.regions[r].outlets.is_empty()).collect();
    let any_outlet = regions.regions.iter().any(|r| !r.outlets.is_empty());
    for &r in &closed {
        let reg = &regions.regions[r];
        // The inflow is piecewise linear between the table times, so its net value vanishes everywhere if
        // it vanishes at every breakpoint (and at t = 0).
        let mut times = vec![0.0];
        for &(side, _) in &reg.inlets {
            if let Boundary::Inlet { table, .. } = &bc[side] {
                times.extend(table.t_s.iter().copied());
            }
        }
        for &t in &times {
            let flows: Vec<(usize, f64)> =
                reg.inlets.iter().map(|&(side, area)| (side, inflow(&bc[side], side, area, t))).collect();
            let net: f64 = flows.iter().map(|f| f.1).sum();
            let scale: f64 = flows.iter().map(|f| f.1.abs()).sum();
            if net.abs() > 1e-9 * scale.max(f64::MIN_POSITIVE) && scale > 0.0 {
                let names: Vec<String> = flows
                    .iter()
                    .filter(|f| f.1 != 0.0)
                    .map(|(s, q)| format!("{} ({:.4e} m³/s)", SIDES[*s], q))
                    .collect();
                let why = if any_outlet {
                    "solids cut it off from every outlet"
                } else {
                    "no side of the grid is an outlet"
                };
                let unit = if grid.mode == Mode::Axisymmetric { " per radian" } else { "" };
                return Err(format!(
                    "inlet {} feeds {} at a net {:.4e} m³/s{unit} at t = {t} s, but {why}: incompressible fluid \
                     cannot enter a closed region. Make one side an outlet (type = \"outlet\" or \
                     \"total_pressure\") reachable from the inlet, or balance the inflow",
                    names.join(" + "),
                    reg.describe(r),
                    net
                ));
            }
        }
    }
    if any_outlet {
        if let Some(&r) = closed.first() {
            return Err(format!(
                "{} is sealed off from every outlet by solids, so its pressure is undefined. Open it to an \
                 outlet or fill it with a solid",
                regions.regions[r].describe(r)
            ));
        }
    } else if closed.len() > 1 {
        return Err(format!(
            "the solids split the fluid into {} regions and no side is an outlet, so each region's pressure \
             level is undefined; {} is separate from {}. Connect them, fill the smaller ones with solids, or \
             add an outlet to each",
            closed.len(),
            regions.regions[closed[1]].describe(closed[1]),
            regions.regions[closed[0]].describe(closed[0])
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::TimeTable;
    use crate::grid::Grid;
    use crate::solid::{blocked_cells, Solid};

    fn wall() -> Boundary {
        Boundary::Wall { velocity_m_s: [0.0; 3] }
    }

    fn inlet(u: f64) -> Boundary {
        Boundary::Inlet { velocity_m_s: [u, 0.0, 0.0], table: TimeTable::default() }
    }

    fn grid() -> Grid {
        Grid::uniform_box([0.0; 3], [4.0, 2.0, 1.0], [8, 4, 2]).unwrap()
    }

    #[test]
    fn a_wall_across_the_channel_makes_two_regions_with_their_sides() {
        let g = grid();
        let plate = Solid::Box { min_m: [1.9, 0.0, 0.0], max_m: [2.1, 2.0, 1.0] };
        let blocked = blocked_cells(&g, &[plate]).unwrap();
        let bc = [inlet(1.0), Boundary::Outlet { pressure_pa: 0.0 }, wall(), wall(), wall(), wall()];
        let r = find(&g, &bc, &blocked);
        assert_eq!(r.regions.len(), 2);
        // The plate is thinner than a cell: it blocks the layer holding its mid-plane x = 2, cell 4.
        let (a, b) = (&r.regions[0], &r.regions[1]);
        assert_eq!(a.cells, 4 * 4 * 2);
        assert_eq!(b.cells, 3 * 4 * 2);
        assert_eq!(a.inlets, vec![(0, 2.0)], "inlet area 2 × 1 m²");
        assert!(a.outlets.is_empty());
        assert_eq!(b.outlets, vec![1]);
        let e = check_mass_balance(&g, &bc, &r).unwrap_err();
        assert!(e.contains("inlet x_min") && e.contains("fluid region 1") && e.contains("cut it off"), "{e}");
        assert!(e.contains("x 0.0000..2.0000 m"), "{e}");
    }

    #[test]
    fn inlet_without_outlet_is_refused_but_balanced_or_closed_boxes_pass() {
        let g = grid();
        let open = vec![false; g.layout.len()];
        let bc = [inlet(1.0), wall(), wall(), wall(), wall(), wall()];
        let e = check_mass_balance(&g, &bc, &find(&g, &bc, &open)).unwrap_err();
        assert!(e.contains("no side of the grid is an outlet") && e.contains("2.0000e0 m³/s"), "{e}");
        // In at x_min and out at x_max at the same speed: balanced, allowed.
        let bc = [inlet(1.0), inlet(1.0), wall(), wall(), wall(), wall()];
        check_mass_balance(&g, &bc, &find(&g, &bc, &open)).unwrap();
        // A ramped inlet balanced at t = 0 (factor 0) but not later is caught at the table's later time.
        let ramp = Boundary::Inlet { velocity_m_s: [1.0, 0.0, 0.0], table: TimeTable::ramp(0.5) };
        let bc = [ramp, wall(), wall(), wall(), wall(), wall()];
        let e = check_mass_balance(&g, &bc, &find(&g, &bc, &open)).unwrap_err();
        assert!(e.contains("t = 0.5 s"), "{e}");
        // A closed cavity with a moving lid.
        let bc = [wall(), wall(), wall(), Boundary::Wall { velocity_m_s: [1.0, 0.0, 0.0] }, wall(), wall()];
        check_mass_balance(&g, &bc, &find(&g, &bc, &open)).unwrap();
        // A total-pressure side takes up the inflow like an outlet.
        let tp = Boundary::TotalPressure { total_pressure_pa: 0.0, table: TimeTable::default() };
        let bc = [inlet(1.0), tp, wall(), wall(), wall(), wall()];
        check_mass_balance(&g, &bc, &find(&g, &bc, &open)).unwrap();
        // The solver refuses to start on an unbalanced set-up.
        let bc = [inlet(1.0), wall(), wall(), wall(), wall(), wall()];
        let fluid = crate::Fluid { density: 1.0, viscosity: 1e-3 };
        let e = crate::Flow::new(g, fluid, bc, open, crate::Numerics::default()).err().unwrap();
        assert!(matches!(e, crate::FlowError::MassBalance(_)), "{e}");
    }

    #[test]
    fn sealed_pockets_are_named() {
        let g = grid();
        // A wall across a closed box leaves two closed regions.
        let plate = Solid::Box { min_m: [1.9, 0.0, 0.0], max_m: [2.1, 2.0, 1.0] };
        let blocked = blocked_cells(&g, &[plate]).unwrap();
        let bc = [wall(), wall(), wall(), wall(), wall(), wall()];
        let e = check_mass_balance(&g, &bc, &find(&g, &bc, &blocked)).unwrap_err();
        assert!(e.contains("split the fluid into 2 regions") && e.contains("fluid region 2"), "{e}");
        // With an outlet on x_max, the left part is a sealed pocket.
        let bc = [wall(), Boundary::Outlet { pressure_pa: 0.0 }, wall(), wall(), wall(), wall()];
        let e = check_mass_balance(&g, &bc, &find(&g, &bc, &blocked)).unwrap_err();
        assert!(e.contains("fluid region 1") && e.contains("sealed off"), "{e}");
    }
}
