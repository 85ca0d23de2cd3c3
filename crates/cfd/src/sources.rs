//! Momentum sources: body forces on the fluid from an actuator disk (a rotor of uniform loading with a
//! tip taper) and from particles (point forces spread over the nearest velocity nodes).
//!
//! Both write accelerations \[m/s²\] into [`Flow::force`] at the staggered velocity nodes, where the
//! momentum equation adds them to its explicit terms. A force F \[N\] placed at a node with control
//! volume V is the acceleration F/(ρV), so Σ ρ V a over the nodes equals the total force exactly.

use crate::grid::{Mode, GHOST};
use crate::solver::Flow;
use serde::{Deserialize, Serialize};

/// An actuator disk on the axis of an axisymmetric grid: thrust `thrust_n` \[N\] over the disk of
/// `radius_m` at axial position `axial_m`, pushing the fluid along `direction` (+1: towards +axial,
/// −1: towards −axial, the downwash of a rotor thrusting upwards). The pressure jump is uniform out to
/// (1 − `tip_taper`)·R and falls linearly to 0 at the tip.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActuatorDisk {
    pub thrust_n: f64,
    pub radius_m: f64,
    pub axial_m: f64,
    #[serde(default = "minus_one")]
    pub direction: f64,
    #[serde(default)]
    pub tip_taper: f64,
}

fn minus_one() -> f64 {
    -1.0
}

impl spatter_core::check::Validate for ActuatorDisk {
    fn validate(&self, c: &mut spatter_core::check::Checker) {
        c.positive("thrust_n", self.thrust_n);
        c.positive("radius_m", self.radius_m);
        c.finite("axial_m", self.axial_m);
        if self.direction != 1.0 && self.direction != -1.0 {
            c.fail(
                "direction",
                format!("= {}: give +1 (push towards +axial) or -1 (towards -axial)", self.direction),
            );
        }
        c.in_range("tip_taper", self.tip_taper, 0.0, true, 1.0, false);
    }
}

impl ActuatorDisk {
    /// Loading shape at radius r (1 inside, linear taper to 0 at the tip).
    fn shape(&self, r: f64) -> f64 {
        let r0 = (1.0 - self.tip_taper) * self.radius_m;
        if r <= r0 {
            1.0
        } else if r < self.radius_m {
            (self.radius_m - r) / (self.radius_m - r0)
        } else {
            0.0
        }
    }

    /// Ideal induced velocity in hover from momentum theory, v_i = √(T / (2ρA)) \[m/s\] (Rankine 1865,
    /// Froude 1889).
    pub fn hover_induced_velocity(&self, density: f64) -> f64 {
        (self.thrust_n / (2.0 * density * std::f64::consts::PI * self.radius_m.powi(2))).sqrt()
    }
}

/// A linear momentum source per unit mass, a = s − k u \[m/s²\], at the velocity nodes, which the
/// predictor takes implicitly in u (backward Euler, outside the Adams–Bashforth terms):
/// u* ← (u* + Δt s)/(1 + Δt k). It is the particles' drag of a semi-implicit coupling, −β (u − v)/(ρV)
/// with k = β/(ρV) on the diagonal and s = β v/(ρV) explicit (the `Ksl`/`Us` form of CFDEM's implicit
/// drag); a large k Δt relaxes u towards s/k without overshoot, where an explicit source would
/// oscillate. The fluid receives ρ V (s − k u*) Δt per node over a step, which [`ImplicitSource::applied`]
/// holds after it. The source stays until it is changed ([`Flow::implicit_source`] clears it).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImplicitSource {
    /// Coefficient k ≥ 0 per velocity node \[1/s\].
    pub k: [Vec<f64>; 3],
    /// Explicit part s per velocity node \[m/s²\].
    pub s: [Vec<f64>; 3],
    /// After a step: the predictor velocity u* the source was evaluated with \[m/s\] (active nodes with
    /// a source; 0 elsewhere).
    pub u_star: [Vec<f64>; 3],
    /// After a step: the acceleration applied, s − k u* \[m/s²\] (active nodes with a source; 0
    /// elsewhere).
    pub applied: [Vec<f64>; 3],
}

impl ImplicitSource {
    fn zeros(n: usize) -> [Vec<f64>; 3] {
        [vec![0.0; n], vec![0.0; n], vec![0.0; n]]
    }

    /// Takes the source implicitly at the active nodes of component `a` of `u` (the predictor velocity
    /// before the outlet nodes copy their neighbours), recording u* and the applied acceleration.
    pub(crate) fn advance(
        &mut self,
        a: usize,
        l: &crate::grid::Layout,
        active: &[u8],
        dt: f64,
        u: &mut [f64],
    ) {
        let (k, s) = (&self.k[a], &self.s[a]);
        let (us, ap) = (&mut self.u_star[a], &mut self.applied[a]);
        // Sequential over the padded nodes: one formula per node, so the order does not matter.
        for c in 0..l.len() {
            if active[c] != crate::solver::ACTIVE || (k[c] == 0.0 && s[c] == 0.0) {
                us[c] = 0.0;
                ap[c] = 0.0;
                continue;
            }
            let v = (u[c] + dt * s[c]) / (1.0 + dt * k[c]);
            u[c] = v;
            us[c] = v;
            ap[c] = s[c] - k[c] * v;
        }
    }
}

/// Why a source could not be placed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SourceError {
    #[error("an actuator disk needs an axisymmetric grid")]
    NotAxisymmetric,
    #[error("actuator disk at axial position {0} m lies outside the grid")]
    Outside(f64),
    #[error("actuator disk radius {0} m covers no cell centre; refine the radial axis")]
    NoCells(f64),
}

/// The accelerations one point force adds to the velocity nodes around it: at most 8 nodes for each of
/// the 3 components, as (component, padded node index, acceleration \[m/s²\]).
#[derive(Clone, Copy, Debug)]
pub struct PointForce {
    adds: [(u8, usize, f64); 24],
    len: usize,
    boundary: [f64; 3],
}

impl PointForce {
    /// The (component, node, acceleration) shares.
    pub fn nodes(&self) -> &[(u8, usize, f64)] {
        &self.adds[..self.len]
    }

    /// The part of the force \[N\] that boundary faces carry (see [`Flow::point_force_shares`]): the fluid
    /// receives the force less this.
    pub fn on_boundaries(&self) -> [f64; 3] {
        self.boundary
    }
}

impl Flow {
    fn force_arrays(&mut self) -> &mut [Vec<f64>; 3] {
        let n = self.grid.layout.len();
        self.force.get_or_insert_with(|| [vec![0.0; n], vec![0.0; n], vec![0.0; n]])
    }

    /// Adds the disk's body force on the axial velocity nodes of the face nearest `axial_m`. The pressure
    /// jump is scaled so that the discrete thrust, Σ Δp(r) 2πr Δr over the covered cells, is `thrust_n`.
    pub fn add_actuator_disk(&mut self, disk: &ActuatorDisk) -> Result<(), SourceError> {
        if self.grid.mode != Mode::Axisymmetric {
            return Err(SourceError::NotAxisymmetric);
        }
        let ax = &self.grid.axes;
        if !(disk.axial_m > ax[1].lo() && disk.axial_m < ax[1].hi()) {
            return Err(SourceError::Outside(disk.axial_m));
        }
        // The interior face nearest the disk plane: face f lies between cells f and f + 1.
        let faces = ax[1].faces();
        let f = (1..faces.len() - 1)
            .min_by(|&a, &b| (faces[a] - disk.axial_m).abs().total_cmp(&(faces[b] - disk.axial_m).abs()))
            .ok_or(SourceError::Outside(disk.axial_m))?;
        let j = f - 1; // the cell whose +face it is
        let nr = ax[0].n();
        let loads: Vec<f64> = (0..nr).map(|i| disk.shape(ax[0].centre(i))).collect();
        let two_pi = 2.0 * std::f64::consts::PI;
        let area: f64 = (0..nr).map(|i| loads[i] * two_pi * ax[0].centre(i) * ax[0].width(i)).sum();
        if area <= 0.0 {
            return Err(SourceError::NoCells(disk.radius_m));
        }
        let dp = disk.thrust_n / area;
        let rho = self.fluid.density;
        let l = self.grid.layout;
        let dc = self.grid.metric[1].dc[j + GHOST];
        let sign = disk.direction.signum();
        let force = self.force_arrays();
        for (i, &w) in loads.iter().enumerate() {
            if w > 0.0 {
                // Δp over the node's axial extent gives the force per volume; per mass, divide by ρ.
                force[1][l.cell(i, j, 0)] += sign * w * dp / (rho * dc);
            }
        }
        Ok(())
    }

    /// Spreads the force `f` \[N\] acting on the fluid at point `x` over the velocity nodes around it with
    /// the trilinear weights of [`Flow::velocity_at`] (the same stencil the particles sample), as
    /// accelerations f w/(ρ V_node).
    ///
    /// Two kinds of stencil node are not updated by the momentum equation, and they are treated apart:
    /// * a **boundary face** (the normal velocity on a face between a fluid cell and a side of the domain
    ///   or a blocked cell: inlet, wall, slip, symmetry, outlet or solid face) carries its share: that
    ///   force acts on the fluid between the node and the first pressure point, where the boundary's
    ///   pressure balances it (a bed resting on an inlet pushes on the inlet, a stone beside a pipe wall on
    ///   the wall). Moving it onto the next interior face instead would put the force of the half cell
    ///   beside the boundary onto one face, whose pressure jump the particles then sample (the model A
    ///   pressure-gradient force feeds back on itself there): a fluidised bed resting on the inlet showed
    ///   2.4 times Ergun's pressure drop that way (docs/cfd.md, minimum fluidisation);
    /// * other nodes (tangential ghost nodes outside the domain, nodes inside solids) take no share and the
    ///   weights of the updated nodes are renormalised.
    ///
    /// When no node of a component's stencil is updated or a boundary face, that component goes whole to the
    /// nearest updated node. In axisymmetric mode `f` is per radian (r, axial, 0). Returns `None` when `x`
    /// lies outside the grid or no updated node lies near it.
    pub fn add_point_force(&mut self, x: [f64; 3], f: [f64; 3]) -> bool {
        match self.point_force_shares(x, f) {
            Some(shares) => {
                self.apply_point_force(&shares);
                true
            }
            None => false,
        }
    }

    /// The node accelerations [`Flow::add_point_force`] would add for the force `f` at `x`, without
    /// adding them (`None` outside the grid). Computing the shares reads the flow only, so many point
    /// forces can be prepared in parallel and applied in a fixed order with [`Flow::apply_point_force`]
    /// (the sums are then the same on any thread count).
    pub fn point_force_shares(&self, x: [f64; 3], f: [f64; 3]) -> Option<PointForce> {
        let g = &self.grid;
        let l = g.layout;
        for a in 0..3 {
            if !(x[a] >= g.axes[a].lo() && x[a] <= g.axes[a].hi()) {
                return None;
            }
        }
        let rho = self.fluid.density;
        let mut out = PointForce { adds: [(0, 0, 0.0); 24], len: 0, boundary: [0.0; 3] };
        for comp in 0..3 {
            if f[comp] == 0.0 {
                continue;
            }
            let (base, w) = crate::solver::trilinear_stencil(g, comp, x);
            // Only nodes the momentum equation updates take a share; the weights are renormalised.
            let mut nodes = [(0usize, 0.0f64); 8];
            let (mut count, mut total, mut on_boundary) = (0, 0.0, 0.0);
            for dk in 0..2 {
                for dj in 0..2 {
                    for di in 0..2 {
                        let c = l.at(base[0] + di, base[1] + dj, base[2] + dk);
                        let wt = (if di == 1 { w[0] } else { 1.0 - w[0] })
                            * (if dj == 1 { w[1] } else { 1.0 - w[1] })
                            * (if dk == 1 { w[2] } else { 1.0 - w[2] });
                        if wt <= 0.0 {
                            continue;
                        }
                        if self.is_active_node(comp, c) {
                            nodes[count] = (c, wt);
                            count += 1;
                            total += wt;
                        } else if self.is_boundary_face(comp, c) {
                            on_boundary += wt;
                        }
                    }
                }
            }
            total += on_boundary;
            out.boundary[comp] = if total > 0.0 { f[comp] * on_boundary / total } else { 0.0 };
            if count == 0 && on_boundary == 0.0 {
                // No node of the stencil is updated (a point next to or inside blocked cells, or on a
                // closed side): the whole component goes to the nearest node that is, so that the fluid
                // still receives exactly the force.
                match self.nearest_active_node(comp, base, x) {
                    Some(c) => {
                        nodes[0] = (c, 1.0);
                        count = 1;
                        total = 1.0;
                    }
                    None => return None,
                }
            }
            for &(c, wt) in &nodes[..count] {
                let v = g.node_volume(comp, l.coords(c));
                out.adds[out.len] = (comp as u8, c, f[comp] * wt / total / (rho * v));
                out.len += 1;
            }
        }
        Some(out)
    }

    /// Whether velocity node `c` of component `comp` lies on a boundary face: the face between cell `c`
    /// and its +`comp` neighbour, with exactly one of the two a fluid cell.
    fn is_boundary_face(&self, comp: usize, c: usize) -> bool {
        let l = self.grid.layout;
        let q = l.coords(c);
        if q[comp] + 1 >= l.p[comp] {
            return false;
        }
        self.is_fluid(c) != self.is_fluid(c + l.s[comp])
    }

    /// The updated (active) velocity node of component `comp` nearest to `x` among the 4 × 4 × 4 nodes
    /// around the trilinear stencil with lowest node `base`; the first in index order on ties.
    fn nearest_active_node(&self, comp: usize, base: [usize; 3], x: [f64; 3]) -> Option<usize> {
        let g = &self.grid;
        let l = g.layout;
        let pos = |a: usize, q: usize| if a == comp { g.metric[a].xf[q] } else { g.metric[a].xc[q] };
        let range = |a: usize| base[a].saturating_sub(1)..(base[a] + 3).min(l.p[a]);
        let mut best: Option<(f64, usize)> = None;
        for k in range(2) {
            for j in range(1) {
                for i in range(0) {
                    let c = l.at(i, j, k);
                    if !self.is_active_node(comp, c) {
                        continue;
                    }
                    let d2: f64 =
                        [i, j, k].iter().enumerate().map(|(a, &q)| (pos(a, q) - x[a]).powi(2)).sum();
                    if best.is_none_or(|(b, _)| d2 < b) {
                        best = Some((d2, c));
                    }
                }
            }
        }
        best.map(|(_, c)| c)
    }

    /// Adds the node accelerations of one point force (see [`Flow::point_force_shares`]).
    pub fn apply_point_force(&mut self, shares: &PointForce) {
        let force = self.force_arrays();
        for &(comp, c, acc) in shares.nodes() {
            force[comp as usize][c] += acc;
        }
    }

    /// The implicit source, created (zero) on first use and cleared: k, s, u* and the applied
    /// acceleration all 0, ready to be filled for the next step.
    pub fn implicit_source(&mut self) -> &mut ImplicitSource {
        let n = self.grid.layout.len();
        let src = self.implicit.get_or_insert_with(|| ImplicitSource {
            k: ImplicitSource::zeros(n),
            s: ImplicitSource::zeros(n),
            u_star: ImplicitSource::zeros(n),
            applied: ImplicitSource::zeros(n),
        });
        for v in [&mut src.k, &mut src.s, &mut src.u_star, &mut src.applied] {
            v.iter_mut().for_each(|a| a.iter_mut().for_each(|x| *x = 0.0));
        }
        src
    }

    /// Total force the body-force field exerts on the fluid, Σ ρ V a over the active nodes \[N\] (per
    /// radian when axisymmetric).
    pub fn total_body_force(&self) -> [f64; 3] {
        self.total_of(self.force.as_ref())
    }

    /// Total force the implicit source applied in the last step, Σ ρ V (s − k u*) over the active nodes
    /// \[N\] (per radian when axisymmetric); the fluid gained this times Δt of momentum from it.
    pub fn total_implicit_force(&self) -> [f64; 3] {
        self.total_of(self.implicit.as_ref().map(|i| &i.applied))
    }

    fn total_of(&self, force: Option<&[Vec<f64>; 3]>) -> [f64; 3] {
        let Some(force) = force else { return [0.0; 3] };
        let l = self.grid.layout;
        let rho = self.fluid.density;
        // Active nodes are interior cells' +faces: a sum over interior cells, plane by plane in order.
        [0, 1, 2].map(|a| {
            crate::reduce::sum_interior(&l, |c| {
                if force[a][c] != 0.0 && self.is_active_node(a, c) {
                    rho * self.grid.node_volume(a, l.coords(c)) * force[a][c]
                } else {
                    0.0
                }
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bc::Boundary;
    use crate::grid::{Axis, Grid};
    use crate::solver::{Fluid, Numerics};

    fn wall() -> Boundary {
        Boundary::Wall { velocity_m_s: [0.0; 3] }
    }

    /// A sphere beside a blocked wall (its stencil partly in the solid) and one whose centre lies inside
    /// the first layer of blocked cells (every node of some components' stencils in the solid, the case
    /// that lost momentum in the coupled gravelometer pipe): the fluid and the solid's faces together
    /// receive exactly the forces (Σ ρ V a + Σ boundary shares = Σ f to round-off, 1e-12), the fluid's
    /// part all on updated nodes.
    #[test]
    fn point_forces_next_to_and_inside_blocked_cells_keep_their_whole_force() {
        let g = Grid::uniform_box([0.0; 3], [8.0; 3], [8, 8, 8]).unwrap();
        let l = g.layout;
        // The cells with x > 4 m are solid.
        let blocked: Vec<bool> =
            (0..l.len()).map(|c| l.interior(l.coords(c)) && l.coords(c)[0] >= GHOST + 4).collect();
        let mut f = Flow::new(
            g,
            Fluid { density: 1.2, viscosity: 1e-3 },
            std::array::from_fn(|_| wall()),
            blocked,
            Numerics::default(),
        )
        .unwrap();
        let forces = [([3.9, 4.3, 4.3], [1.0, -2.0, 0.5]), ([4.6, 2.2, 5.7], [-3.0, 0.25, 2.0])];
        let mut want = [0.0; 3];
        for (x, force) in forces {
            let shares = f.point_force_shares(x, force).unwrap();
            assert!(shares.nodes().iter().all(|&(a, c, _)| f.is_active_node(a as usize, c)));
            f.apply_point_force(&shares);
            for a in 0..3 {
                want[a] += force[a] - shares.on_boundaries()[a];
            }
        }
        // The sphere inside the solid (x = 4.6 m, solid from 4 m): its x stencil has the solid face at
        // x = 4 m (weight 0.4) and a node inside the solid (no share), so the wall carries all of f_x.
        let inside = f.point_force_shares([4.6, 2.2, 5.7], [-3.0, 0.25, 2.0]).unwrap();
        assert!((inside.on_boundaries()[0] + 3.0).abs() < 1e-12, "{:?}", inside.on_boundaries());
        let t = f.total_body_force();
        for a in 0..3 {
            assert!((t[a] - want[a]).abs() < 1e-12, "{t:?} vs {want:?}");
        }
    }

    #[test]
    fn point_forces_put_exactly_their_force_into_the_fluid() {
        let g = Grid::new(
            [
                Axis::geometric(0.0, 1.0, 9, 1.2).unwrap(),
                Axis::uniform(0.0, 1.0, 7).unwrap(),
                Axis::uniform(0.0, 0.5, 5).unwrap(),
            ],
            Mode::Cartesian,
        )
        .unwrap();
        let n = g.layout.len();
        let mut f = Flow::new(
            g,
            Fluid { density: 1.3, viscosity: 1e-3 },
            std::array::from_fn(|_| wall()),
            vec![false; n],
            Numerics::default(),
        )
        .unwrap();
        let inner = f.point_force_shares([0.31, 0.52, 0.17], [2.0, -1.0, 0.5]).unwrap();
        assert_eq!(inner.on_boundaries(), [0.0; 3], "away from the walls nothing goes to them");
        f.apply_point_force(&inner);
        // Next to the wall y = 1 (7 cells of 1/7 m): the y nodes around y = 0.99 m are the face at
        // 6/7 m (weight (1 − 0.99)·7 = 0.07, updated) and the wall face at 1 m (weight 0.93), so the
        // wall carries 0.93 of f_y (the x and z stencils have tangential ghost nodes: renormalised).
        let edge = f.point_force_shares([0.01, 0.99, 0.02], [0.0, 3.0, 0.0]).unwrap();
        assert!((edge.on_boundaries()[1] - 0.93 * 3.0).abs() < 1e-12, "{:?}", edge.on_boundaries());
        f.apply_point_force(&edge);
        assert!(!f.add_point_force([1.5, 0.5, 0.2], [1.0, 0.0, 0.0]), "outside");
        let t = f.total_body_force();
        for (a, want) in [2.0, -1.0 + 3.0 * 0.07, 0.5].iter().enumerate() {
            assert!((t[a] - want).abs() < 1e-12, "{t:?}");
        }
    }

    /// A disk of R = 1 m and T = π N in ρ = 1 (v_h = √(T/2ρA) = 0.7071 m/s) at mid-height of a 4R × 12R
    /// axisymmetric domain, 40 × 120 cells, pushing the fluid towards −axial; the top brings a climb
    /// inflow `vc` (an outlet in hover, `vc` = 0), the side and the bottom are outlets. Runs 30 s (the
    /// starting vortex has left the domain) and returns the induced velocity v_i (mean axial speed
    /// through the disk over t = 20–30 s minus `vc`) and momentum theory's value (Rankine–Froude; e.g.
    /// Leishman, *Principles of Helicopter Aerodynamics*, §2.4 and §2.13):
    /// v_i = −V_c/2 + √((V_c/2)² + v_h²), which is v_h = √(T/(2ρA)) in hover.
    fn disk_in_climb(vc: f64) -> (f64, f64) {
        let disk = ActuatorDisk {
            thrust_n: std::f64::consts::PI,
            radius_m: 1.0,
            axial_m: 6.0,
            direction: -1.0,
            tip_taper: 0.0,
        };
        let (nr, nz) = (40, 120);
        let g = Grid::new(
            [
                Axis::uniform(0.0, 4.0, nr).unwrap(),
                Axis::uniform(0.0, 12.0, nz).unwrap(),
                Axis::uniform(0.0, 1.0, 1).unwrap(),
            ],
            Mode::Axisymmetric,
        )
        .unwrap();
        let n = g.layout.len();
        let top = if vc > 0.0 {
            Boundary::Inlet { velocity_m_s: [0.0, -vc, 0.0], table: Default::default() }
        } else {
            Boundary::Outlet { pressure_pa: 0.0 }
        };
        let bc = [
            Boundary::Axis,
            Boundary::Outlet { pressure_pa: 0.0 },
            Boundary::Outlet { pressure_pa: 0.0 },
            top,
            Boundary::Slip,
            Boundary::Slip,
        ];
        let mut f =
            Flow::new(g, Fluid { density: 1.0, viscosity: 2e-3 }, bc, vec![false; n], Numerics::default())
                .unwrap();
        f.add_actuator_disk(&disk).unwrap();
        let t = f.total_body_force();
        // Per radian: T/2π along −axial, exactly.
        assert!((t[1] + 0.5).abs() < 1e-12, "{t:?}");
        let vh = disk.hover_induced_velocity(1.0);
        assert!((vh - 0.5f64.sqrt()).abs() < 1e-12);
        let vi_theory = -vc / 2.0 + ((vc / 2.0).powi(2) + vh * vh).sqrt();
        let (mut sum, mut time) = (0.0, 0.0);
        while f.state.t < 30.0 {
            let dt = f.stable_dt(0.5, 0.05);
            f.step(dt).unwrap();
            if f.state.t > 20.0 {
                let (mut q, mut a) = (0.0, 0.0);
                for i in 0..nr {
                    let r = f.grid.axes[0].centre(i);
                    if r < 1.0 {
                        let dr = f.grid.axes[0].width(i);
                        let v = f.velocity_at([r, 6.0, 0.5]).unwrap()[1];
                        q += v * r * dr;
                        a += r * dr;
                    }
                }
                sum += -q / a * dt;
                time += dt;
            }
        }
        (sum / time - vc, vi_theory)
    }

    #[test]
    fn actuator_disk_in_climb_induces_the_momentum_theory_velocity() {
        let (vi, theory) = disk_in_climb(0.2);
        eprintln!("climb: v_i = {vi:.4} m/s, theory {theory:.4} m/s");
        // Measured −0.2 % (40 × 120 cells, lateral outlet at 4 R); 3 % allows for the finite domain.
        assert!((vi / theory - 1.0).abs() < 0.03, "v_i = {vi}, theory {theory}");
    }

    #[test]
    fn a_tapered_disk_carries_its_thrust_with_the_loading_falling_to_zero_at_the_tip() {
        let g = Grid::new(
            [
                Axis::uniform(0.0, 2.0, 20).unwrap(),
                Axis::uniform(0.0, 2.0, 10).unwrap(),
                Axis::uniform(0.0, 1.0, 1).unwrap(),
            ],
            Mode::Axisymmetric,
        )
        .unwrap();
        let n = g.layout.len();
        let bc = [
            Boundary::Axis,
            Boundary::Outlet { pressure_pa: 0.0 },
            Boundary::Outlet { pressure_pa: 0.0 },
            Boundary::Outlet { pressure_pa: 0.0 },
            Boundary::Slip,
            Boundary::Slip,
        ];
        let mut f =
            Flow::new(g, Fluid { density: 1.2, viscosity: 1e-3 }, bc, vec![false; n], Numerics::default())
                .unwrap();
        let disk =
            ActuatorDisk { thrust_n: 40.0, radius_m: 1.0, axial_m: 1.02, direction: 1.0, tip_taper: 0.4 };
        f.add_actuator_disk(&disk).unwrap();
        // Σ ρ V a over the nodes is the thrust per radian, along +axial.
        let t = f.total_body_force();
        assert!((t[1] - 40.0 / (2.0 * std::f64::consts::PI)).abs() < 1e-12, "{t:?}");
        assert!(t[0] == 0.0 && t[2] == 0.0);
        // The face nearest 1.02 m is the one at 1.0 m (the +face of cell 4); uniform pressure jump out
        // to r = 0.6 m, a linear fall to 0 at r = 1 m, nothing beyond.
        let l = f.grid.layout;
        let force = f.force.as_ref().unwrap();
        let a = |i: usize| force[1][l.cell(i, 4, 0)];
        let inner = a(0);
        assert!(inner > 0.0);
        for i in 0..6 {
            assert!((a(i) / inner - 1.0).abs() < 1e-12, "uniform out to 0.6 m: cell {i}");
        }
        for i in 6..10 {
            let r = f.grid.axes[0].centre(i);
            assert!((a(i) / inner - (1.0 - r) / 0.4).abs() < 1e-12, "taper at r = {r}");
        }
        for i in 10..20 {
            assert_eq!(a(i), 0.0, "outside the disk: cell {i}");
        }
        for j in (0..10).filter(|&j| j != 4) {
            assert_eq!(force[1][l.cell(0, j, 0)], 0.0, "only one face carries the disk");
        }
        // Misplaced disks are refused.
        let outside = ActuatorDisk { axial_m: 3.0, ..disk };
        assert_eq!(f.add_actuator_disk(&outside), Err(SourceError::Outside(3.0)));
        let tiny = ActuatorDisk { radius_m: 0.01, ..disk };
        assert_eq!(f.add_actuator_disk(&tiny), Err(SourceError::NoCells(0.01)));
    }

    /// A stiff uniform drag on a channel open at both ends (static-pressure outlets, slip sides): with
    /// the same s and k at every x-node the flow stays uniform and pressure-free, so each step is exactly
    /// the backward-Euler recursion u ← (u + Δt s)/(1 + Δt k), which approaches s/k monotonically even at
    /// k Δt = 50, where an explicit source (u ← u + Δt (s − k u)) would multiply the distance by −49 per
    /// step. The momentum the fluid receives is Σ ρ V (s − k u*) (exact to round-off, 1e-12).
    #[test]
    fn an_implicit_linear_source_relaxes_a_uniform_flow_by_backward_euler() {
        let g = Grid::uniform_box([0.0; 3], [4.0, 1.0, 1.0], [8, 2, 2]).unwrap();
        let out = || Boundary::Outlet { pressure_pa: 0.0 };
        let bc = [out(), out(), Boundary::Slip, Boundary::Slip, Boundary::Slip, Boundary::Slip];
        let blocked = vec![false; g.layout.len()];
        let mut f =
            Flow::new(g, Fluid { density: 2.0, viscosity: 1e-3 }, bc, blocked, Numerics::default()).unwrap();
        let (k, s, dt) = (500.0, 1000.0, 0.1);
        let mut want = 0.0f64;
        for step in 0..6 {
            let l = f.grid.layout;
            let active: Vec<usize> = (0..l.len()).filter(|&c| f.is_active_node(0, c)).collect();
            assert_eq!(active.len(), 7 * 2 * 2);
            let src = f.implicit_source();
            for &c in &active {
                src.k[0][c] = k;
                src.s[0][c] = s;
            }
            f.step(dt).unwrap();
            let before = want;
            want = (want + dt * s) / (1.0 + dt * k);
            for &c in &active {
                assert!(
                    (f.state.u[0][c] / want - 1.0).abs() < 1e-12,
                    "step {step}: {} vs {want}",
                    f.state.u[0][c]
                );
            }
            // Monotone: every step closes part of the gap to s/k = 2 m/s, never crossing it.
            assert!(want > before && want < s / k, "step {step}: {want}");
            let got = f.total_implicit_force()[0];
            let expect = 2.0 * 28.0 * 0.125 * (s - k * want); // ρ × 28 nodes × 0.5³ m³
            assert!((got / expect - 1.0).abs() < 1e-12, "{got} vs {expect}");
        }
        assert!((want - s / k).abs() < 1e-6 * s / k, "{want}");
    }
}
