//! The incompressible flow solver: staggered (MAC) finite volumes, second-order Adams–Bashforth for
//! convection and diffusion, and an incremental pressure-correction projection.
//!
//! Unknowns: the velocity components at the faces of their cells (u at +x faces, v at +y faces, w at +z
//! faces) and the kinematic pressure p/ρ at cell centres. The staggered layout couples pressure and
//! velocity at neighbouring points, so no checkerboard pressure can appear and no Rhie–Chow interpolation
//! is needed (Harlow & Welch 1965).
//!
//! One step from tⁿ to tⁿ⁺¹ = tⁿ + Δt (Kim & Moin 1985; Brown, Cortez & Minion 2001):
//! 1. H = −(u·∇)u + ∇·(ν∇u) + f at every interior velocity node (see [`crate::momentum`]);
//! 2. predictor u* = uⁿ + Δt [(1 + Δt/2Δt₀) Hⁿ − (Δt/2Δt₀) Hⁿ⁻¹] − Δt ∇pⁿ (variable-step AB2; Euler on the
//!    first step), boundary velocities at tⁿ⁺¹; a linear source s − k u ([`Flow::implicit`]) is then
//!    taken backward-Euler: u* ← (u* + Δt s)/(1 + Δt k);
//! 3. pressure correction φ from ∇·(∇φ) = ∇·u*/Δt, solved by multigrid-preconditioned CG;
//! 4. uⁿ⁺¹ = u* − Δt ∇φ (discretely divergence-free to the solver tolerance), pⁿ⁺¹ = pⁿ + φ.
//!
//! Sides that hold the pressure (outlets, total-pressure sides) are Dirichlet faces of the pressure:
//! the normal velocity on such a face is copied from the interior node in the predictor (zero normal
//! gradient) and then corrected by Δt times the gradient of φ across the half cell between the cell
//! centre and the face. Each face remembers the kinematic pressure p_b it holds ([`State::p_faces`]);
//! a step computes the new face value p_b⁺ from the side's condition at tⁿ⁺¹ — for a total-pressure side
//! from the face velocity uⁿ at the start of the step (explicit in time) — and solves for φ with the face
//! value φ_b = p_b⁺ − p_b, so that pⁿ⁺¹ holds p_b⁺ on the face. A side whose pressure does not change
//! has φ_b = 0, the homogeneous condition.

use crate::bc::{Boundary, SIDES};
use crate::grid::{Grid, Mode, GHOST};
use crate::mg::{Multigrid, Stencil};
use crate::momentum::{face_value, Convection, DirOps};
use crate::pcg::{Pcg, PcgReport, PcgSettings};
use crate::reduce::{for_planes, max_interior, sum_interior};
use serde::{Deserialize, Serialize};

/// Node kinds.
const FIXED: u8 = 0;
pub(crate) const ACTIVE: u8 = 1;
const OUTLET: u8 = 2;

/// Fluid properties.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fluid {
    /// Density \[kg/m³\].
    pub density: f64,
    /// Kinematic viscosity \[m²/s\].
    pub viscosity: f64,
}

/// Numerical settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Numerics {
    pub convection: Convection,
    pub pressure: PcgSettings,
    /// A step whose Courant number exceeds this is refused as unstable.
    pub max_courant: f64,
}

impl Default for Numerics {
    fn default() -> Self {
        Numerics { convection: Convection::VanLeer, pressure: PcgSettings::default(), max_courant: 1.0 }
    }
}

/// Everything that changes in time: what a checkpoint stores.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct State {
    /// Time \[s\].
    pub t: f64,
    pub step: u64,
    /// Velocity components at their faces \[m/s\] (padded layout).
    pub u: [Vec<f64>; 3],
    /// Kinematic pressure p/ρ at cell centres \[m²/s²\].
    pub p: Vec<f64>,
    /// Kinematic pressure held on each face of the sides that hold the pressure \[m²/s²\], in the order
    /// of the solver's list of those faces (x faces, then y, then z).
    pub p_faces: Vec<f64>,
    /// Explicit terms of the previous step, for Adams–Bashforth.
    h_old: [Vec<f64>; 3],
    dt_old: f64,
    /// k and ε when a turbulence model runs.
    pub turbulence: Option<crate::turbulence::TurbState>,
}

/// Why a step failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FlowError {
    #[error("flow diverged at step {step} (t = {t} s): Courant number {courant:.3} > {limit} in cell ({i}, {j}, {k}) at ({x:.4}, {y:.4}, {z:.4}) m; reduce the time step")]
    Courant {
        step: u64,
        t: f64,
        courant: f64,
        limit: f64,
        i: usize,
        j: usize,
        k: usize,
        x: f64,
        y: f64,
        z: f64,
    },
    #[error("flow diverged at step {step} (t = {t} s): the velocity became NaN in cell ({i}, {j}, {k}); reduce the time step or check the boundary conditions")]
    NotFinite { step: u64, t: f64, i: usize, j: usize, k: usize },
    #[error("{0}")]
    Setup(String),
    #[error("inconsistent boundaries: {0}")]
    Boundaries(String),
    #[error("mass balance: {0}")]
    MassBalance(String),
    #[error("the pressure solver did not converge at step {step}: relative residual {residual:.2e} after {iterations} iterations")]
    Pressure { step: u64, residual: f64, iterations: usize },
}

/// Report of one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    pub pressure: PcgReport,
    /// Largest Courant number Σ_a |u_a| Δt / Δx_a over the cells.
    pub courant: f64,
}

/// An incompressible flow on a structured grid.
pub struct Flow {
    pub grid: Grid,
    pub fluid: Fluid,
    pub bc: [Boundary; 6],
    pub numerics: Numerics,
    pub state: State,
    /// Blocked cells (padded).
    pub blocked: Vec<bool>,
    /// Body acceleration at the velocity nodes \[m/s²\] (actuator disks, particles), if any.
    pub force: Option<[Vec<f64>; 3]>,
    /// A linear source s − k u taken implicitly by the predictor (the particles' drag of a semi-implicit
    /// coupling), if any; see [`crate::sources::ImplicitSource`].
    pub implicit: Option<crate::sources::ImplicitSource>,
    /// The k–ε model, when enabled ([`Flow::enable_k_epsilon`]).
    pub turbulence: Option<crate::turbulence::Turbulence>,
    kind: [Vec<u8>; 3],
    /// Nodes set from neighbours after every update: (node, fluid neighbours to mirror).
    solid_nodes: [Vec<(usize, Vec<usize>)>; 3],
    /// Normal velocity nodes on the faces of the sides that hold the pressure: the node, the interior
    /// node it copies in the predictor and the side.
    outlet_nodes: [Vec<(usize, usize, u8)>; 3],
    centre_ops: [DirOps; 3],
    face_ops: [DirOps; 3],
    pcg: Pcg,
    phi: Vec<f64>,
    rhs: Vec<f64>,
    h_new: [Vec<f64>; 3],
}

impl Flow {
    /// A fluid at rest on `grid` with blocked cells `blocked` (see [`crate::solid::blocked_cells`]).
    pub fn new(
        grid: Grid,
        fluid: Fluid,
        bc: [Boundary; 6],
        blocked: Vec<bool>,
        numerics: Numerics,
    ) -> Result<Self, FlowError> {
        let l = grid.layout;
        if grid.mode == Mode::Axisymmetric {
            if bc[0] != Boundary::Axis {
                return Err(FlowError::Boundaries(
                    "an axisymmetric grid needs x_min = { type = \"axis\" } (r = 0)".into(),
                ));
            }
            if bc[4] != Boundary::Slip || bc[5] != Boundary::Slip {
                return Err(FlowError::Boundaries(
                    "an axisymmetric grid needs slip on z_min and z_max (the azimuthal sides)".into(),
                ));
            }
        }
        for (s, b) in bc.iter().enumerate() {
            if *b == Boundary::Axis && !(grid.mode == Mode::Axisymmetric && s == 0) {
                return Err(FlowError::Boundaries(format!(
                    "{} cannot be an axis: only x_min of an axisymmetric grid is",
                    SIDES[s]
                )));
            }
        }
        if blocked.len() != l.len() {
            return Err(FlowError::Setup(format!(
                "{} blocked flags for a grid of {} padded cells (use solid::blocked_cells)",
                blocked.len(),
                l.len()
            )));
        }
        let regions = crate::regions::find(&grid, &bc, &blocked);
        crate::regions::check_mass_balance(&grid, &bc, &regions).map_err(FlowError::MassBalance)?;
        let n = l.len();
        let fluid_cell = |q: [usize; 3]| l.interior(q) && !blocked[l.at(q[0], q[1], q[2])];
        let mut kind = [vec![FIXED; n], vec![FIXED; n], vec![FIXED; n]];
        let mut outlet_nodes: [Vec<(usize, usize, u8)>; 3] = Default::default();
        for c in 0..n {
            let q = l.coords(c);
            for a in 0..3 {
                if grid.mode == Mode::Axisymmetric && a == 2 {
                    continue;
                }
                let mut qn = q;
                qn[a] += 1;
                if qn[a] >= l.p[a] {
                    continue;
                }
                let others_inside =
                    (0..3).filter(|&b| b != a).all(|b| q[b] >= GHOST && q[b] < GHOST + l.n[b]);
                if !others_inside {
                    continue;
                }
                let (fa, fb) = (fluid_cell(q), fluid_cell(qn));
                if fa && fb {
                    kind[a][c] = ACTIVE;
                } else if q[a] == GHOST - 1 && fb && bc[2 * a].holds_pressure() {
                    kind[a][c] = OUTLET;
                    outlet_nodes[a].push((c, c + l.s[a], 2 * a as u8));
                } else if q[a] == GHOST + l.n[a] - 1 && fa && bc[2 * a + 1].holds_pressure() {
                    kind[a][c] = OUTLET;
                    outlet_nodes[a].push((c, c - l.s[a], 2 * a as u8 + 1));
                }
            }
        }
        // Nodes touching blocked cells: normal faces stay 0, tangential nodes inside solids mirror their
        // fluid neighbours (no-slip at the solid face).
        let mut solid_nodes: [Vec<(usize, Vec<usize>)>; 3] = Default::default();
        for c in 0..n {
            let q = l.coords(c);
            for a in 0..3 {
                let mut qn = q;
                qn[a] += 1;
                if qn[a] >= l.p[a] {
                    continue;
                }
                let b0 = blocked[c];
                let b1 = blocked[c + l.s[a]];
                if !(b0 || b1) {
                    continue;
                }
                let mut nbs = Vec::new();
                if b0 && b1 {
                    for b in 0..3 {
                        if b == a {
                            continue;
                        }
                        let s = l.s[b];
                        if q[b] + 1 < l.p[b] && kind[a][c + s] != FIXED {
                            nbs.push(c + s);
                        }
                        if q[b] >= 1 && kind[a][c - s] != FIXED {
                            nbs.push(c - s);
                        }
                    }
                }
                let boundary_face = (0..3).any(|b| q[b] < GHOST || qn[b] >= GHOST + l.n[b]);
                if !nbs.is_empty() || boundary_face || b0 != b1 {
                    solid_nodes[a].push((c, nbs));
                }
            }
        }
        let stencil = pressure_stencil(&grid, &kind, &outlet_nodes);
        let pcg = Pcg::new(Multigrid::new(stencil));
        let centre_ops = [0, 1, 2].map(|a| DirOps::centre(&grid.metric[a]));
        let face_ops = [0, 1, 2].map(|a| DirOps::face(&grid.metric[a]));
        let zeros = || [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
        // The fluid starts at rest at the static pressure of the first side that holds the pressure (in
        // side order; a total-pressure side's p₀ at t = 0), so that a single outlet pressure shifts the
        // pressure field and changes nothing else.
        let level =
            bc.iter().find_map(|b| b.static_pressure(0.0, 0.0, fluid.density)).unwrap_or(0.0) / fluid.density;
        let faces = outlet_nodes.iter().map(Vec::len).sum();
        let state = State {
            t: 0.0,
            step: 0,
            u: zeros(),
            p: vec![level; n],
            p_faces: vec![level; faces],
            h_old: zeros(),
            dt_old: 0.0,
            turbulence: None,
        };
        let mut f = Flow {
            grid,
            fluid,
            bc,
            numerics,
            state,
            blocked,
            force: None,
            implicit: None,
            turbulence: None,
            kind,
            solid_nodes,
            outlet_nodes,
            centre_ops,
            face_ops,
            pcg,
            phi: vec![0.0; n],
            rhs: vec![0.0; n],
            h_new: zeros(),
        };
        f.fill_boundaries(0.0);
        Ok(f)
    }

    /// Bytes a flow on a grid of `n` cells per axis will hold, computed before allocating anything: per
    /// padded cell the velocity (3), pressure, the Adams–Bashforth history (3 + 3), φ and the right-hand
    /// side, the CG vectors (4) and the body force (3, when `with_force`) as f64, three node-kind bytes and
    /// the blocked flag; with `with_turbulence` the k–ε arrays (k, ε, ν_eff, two work arrays and the two
    /// wall-function sums as f64, a wall count byte); plus [`Multigrid::F64_PER_CELL`] values per padded
    /// cell of every multigrid level.
    /// Small per-boundary lists and the dense coarsest factor (≤ 64² values) are left out; the estimate is
    /// within a few per cent of [`Flow::heap_bytes`] (tested).
    pub fn memory_estimate(n: [usize; 3], with_force: bool, with_turbulence: bool) -> u64 {
        let fine = crate::grid::Layout::new(n).len() as u64;
        let per_cell =
            8 * (16 + if with_force { 3 } else { 0 }) + 4 + if with_turbulence { 8 * 7 + 2 } else { 0 };
        let levels: u64 = Multigrid::level_layouts(n).iter().map(|l| l.len() as u64).sum();
        fine * per_cell + levels * 8 * Multigrid::F64_PER_CELL as u64
    }

    /// Bytes this flow holds on the heap in its fields, work vectors and pressure solver.
    pub fn heap_bytes(&self) -> u64 {
        let f64s = |v: &[Vec<f64>; 3]| v.iter().map(Vec::capacity).sum::<usize>();
        let st = &self.state;
        let mut n =
            f64s(&st.u) + st.p.capacity() + st.p_faces.capacity() + f64s(&st.h_old) + f64s(&self.h_new);
        n += self.phi.capacity() + self.rhs.capacity();
        n += self.force.as_ref().map_or(0, f64s);
        n += self
            .implicit
            .as_ref()
            .map_or(0, |i| f64s(&i.k) + f64s(&i.s) + f64s(&i.u_star) + f64s(&i.applied));
        if let Some(t) = &self.state.turbulence {
            n += t.k.capacity() + t.eps.capacity();
        }
        let turb = self.turbulence.as_ref().map_or(0, |t| t.heap_bytes());
        let bytes = self.kind.iter().map(Vec::capacity).sum::<usize>() + self.blocked.capacity();
        let lists: usize = (0..3)
            .map(|a| {
                self.outlet_nodes[a].capacity() * std::mem::size_of::<(usize, usize, u8)>()
                    + self.solid_nodes[a].iter().map(|(_, v)| 32 + 8 * v.capacity()).sum::<usize>()
            })
            .sum();
        (8 * n + bytes + lists) as u64 + self.pcg.heap_bytes() + turb
    }

    /// Switches on the standard k–ε model with wall functions ([`crate::turbulence`]), starting from the
    /// inlet turbulence everywhere. Call before the first step.
    pub fn enable_k_epsilon(&mut self, model: crate::turbulence::KEpsilon) {
        let mut t = crate::turbulence::Turbulence::new(model, &self.grid, &self.bc, &self.blocked);
        let st = t.initial_state(&self.grid, &self.bc);
        t.fill_nu_eff(&self.grid, &self.bc, &self.blocked, self.fluid.viscosity, &self.state.u, &st);
        self.state.turbulence = Some(st);
        self.turbulence = Some(t);
    }

    /// Number of multigrid levels of the pressure solver.
    pub fn multigrid_depth(&self) -> usize {
        self.pcg.mg.depth()
    }

    /// Whether velocity node `c` of component `a` is updated by the momentum equation.
    pub fn is_active_node(&self, a: usize, c: usize) -> bool {
        self.kind[a][c] == ACTIVE
    }

    /// Whether padded cell `c` is fluid.
    pub fn is_fluid(&self, c: usize) -> bool {
        self.grid.layout.interior(self.grid.layout.coords(c)) && !self.blocked[c]
    }

    /// Sets the ghost and boundary values of the velocity for time `t`.
    pub fn fill_boundaries(&mut self, t: f64) {
        let l = self.grid.layout;
        let g = GHOST;
        for d in 0..3 {
            let n = l.n[d];
            let (d1, d2) = ((d + 1) % 3, (d + 2) % 3);
            for plus in [false, true] {
                let bc = &self.bc[2 * d + usize::from(plus)];
                let vel = bc.velocity(t);
                for o2 in 0..l.p[d2] {
                    for o1 in 0..l.p[d1] {
                        let idx = |qd: usize| {
                            let mut q = [0; 3];
                            q[d] = qd;
                            q[d1] = o1;
                            q[d2] = o2;
                            l.at(q[0], q[1], q[2])
                        };
                        for a in 0..3 {
                            let u = &mut self.state.u[a];
                            if a == d {
                                // Normal component.
                                let (bnode, beyond, inner, beyond2) = if plus {
                                    (idx(g + n - 1), idx(g + n), idx(g + n - 2), Some(idx(g + n + 1)))
                                } else {
                                    (idx(g - 1), idx(g - 2), idx(g), None)
                                };
                                match bc {
                                    Boundary::Outlet { .. } | Boundary::TotalPressure { .. } => {}
                                    Boundary::Inlet { .. } => u[bnode] = vel.map_or(0.0, |v| v[a]),
                                    _ => u[bnode] = 0.0,
                                }
                                u[beyond] = 2.0 * u[bnode] - u[inner];
                                if let Some(b2) = beyond2 {
                                    u[b2] = u[beyond];
                                }
                            } else {
                                let pairs = if plus {
                                    [(g + n, g + n - 1), (g + n + 1, g + n - 2)]
                                } else {
                                    [(g - 1, g), (g - 2, g + 1)]
                                };
                                for (gq, mq) in pairs {
                                    let (gi, mi) = (idx(gq), idx(mq));
                                    u[gi] = match bc {
                                        Boundary::Wall { .. } | Boundary::Inlet { .. } => {
                                            2.0 * vel.map_or(0.0, |v| v[a]) - u[mi]
                                        }
                                        Boundary::Slip | Boundary::Axis => u[mi],
                                        Boundary::Outlet { .. } | Boundary::TotalPressure { .. } => {
                                            u[idx(if plus { g + n - 1 } else { g })]
                                        }
                                    };
                                }
                            }
                        }
                    }
                }
            }
        }
        for a in 0..3 {
            let u = &mut self.state.u[a];
            for (c, nbs) in &self.solid_nodes[a] {
                u[*c] = if nbs.is_empty() {
                    0.0
                } else {
                    -nbs.iter().map(|&m| u[m]).sum::<f64>() / nbs.len() as f64
                };
            }
        }
    }

    /// Explicit terms H of component `A` at its active nodes into `out`; with `TURB` the viscosity of
    /// each control-volume face is the effective viscosity of the turbulence model (the laminar path
    /// keeps its arithmetic, so laminar results are unchanged bit for bit).
    fn explicit_terms<const A: usize, const TURB: bool>(&self, out: &mut [f64]) {
        let l = self.grid.layout;
        let s = l.s;
        let u = &self.state.u;
        let phi = &u[A];
        let kind = &self.kind[A];
        let ops: [&DirOps; 3] =
            [0, 1, 2].map(|d| if d == A { &self.face_ops[d] } else { &self.centre_ops[d] });
        let nu = self.fluid.viscosity;
        let scheme = self.numerics.convection;
        let hoop = A == 0 && self.grid.mode == Mode::Axisymmetric;
        let rf = &self.grid.metric[0].xf;
        let force = self.force.as_ref().map(|f| &f[A]);
        let nu_eff: &[f64] = match (&self.turbulence, TURB) {
            (Some(t), true) => &t.nu_eff,
            _ => &[],
        };
        for_planes(&l, out, |k, plane| {
            let base = k * s[2];
            for j in GHOST..GHOST + l.n[1] {
                for i in GHOST..GHOST + l.n[0] {
                    let c = base + j * s[1] + i;
                    if kind[c] != ACTIVE {
                        plane[c - base] = 0.0;
                        continue;
                    }
                    let q = [i, j, k];
                    let pc = phi[c];
                    let mut conv = 0.0;
                    let mut diff = 0.0;
                    for d in 0..3 {
                        let sd = s[d];
                        let o = ops[d];
                        let qd = q[d];
                        let (vp, vm) = if d == A {
                            (0.5 * (pc + phi[c + sd]), 0.5 * (phi[c - sd] + pc))
                        } else {
                            let ud = &u[d];
                            (0.5 * (ud[c] + ud[c + s[A]]), 0.5 * (ud[c - sd] + ud[c - sd + s[A]]))
                        };
                        let (fp, fm) = (o.fp[qd], o.fm[qd]);
                        let (pe, pw) = (phi[c + sd], phi[c - sd]);
                        let plus = if vp >= 0.0 {
                            face_value(scheme, pw, pc, pe)
                        } else {
                            face_value(scheme, phi[c + 2 * sd], pe, pc)
                        };
                        let minus = if vm >= 0.0 {
                            face_value(scheme, phi[c - 2 * sd], pw, pc)
                        } else {
                            face_value(scheme, pe, pc, pw)
                        };
                        conv += fp * vp * (plus - pc) - fm * vm * (minus - pc);
                        if TURB {
                            // Face viscosities: cell centres along A, edge averages across.
                            let sa = s[A];
                            let (np, nm) = if d == A {
                                (nu_eff[c + sa], nu_eff[c])
                            } else {
                                (
                                    0.25 * (nu_eff[c]
                                        + nu_eff[c + sa]
                                        + nu_eff[c + sd]
                                        + nu_eff[c + sa + sd]),
                                    0.25 * (nu_eff[c]
                                        + nu_eff[c + sa]
                                        + nu_eff[c - sd]
                                        + nu_eff[c + sa - sd]),
                                )
                            };
                            diff += fp * o.hp[qd] * (pe - pc) * np - fm * o.hm[qd] * (pc - pw) * nm;
                        } else {
                            diff += fp * o.hp[qd] * (pe - pc) - fm * o.hm[qd] * (pc - pw);
                        }
                    }
                    let mut h = if TURB { diff - conv } else { nu * diff - conv };
                    if hoop {
                        let r = rf[i];
                        let nu_node = if TURB { 0.5 * (nu_eff[c] + nu_eff[c + 1]) } else { nu };
                        h -= nu_node * pc / (r * r);
                    }
                    if let Some(f) = force {
                        h += f[c];
                    }
                    plane[c - base] = h;
                }
            }
        });
    }

    /// Advances by `dt` seconds (on a worker thread of the rayon pool, see [`crate::reduce::in_pool`]).
    pub fn step(&mut self, dt: f64) -> Result<StepReport, FlowError> {
        crate::reduce::in_pool(|| self.advance(dt))
    }

    fn advance(&mut self, dt: f64) -> Result<StepReport, FlowError> {
        let l = self.grid.layout;
        let s = l.s;
        let p_targets = self.pressure_targets(self.state.t + dt);
        let mut h_new = std::mem::take(&mut self.h_new);
        if self.turbulence.is_some() {
            self.explicit_terms::<0, true>(&mut h_new[0]);
            self.explicit_terms::<1, true>(&mut h_new[1]);
            if self.grid.mode == Mode::Cartesian {
                self.explicit_terms::<2, true>(&mut h_new[2]);
            }
        } else {
            self.explicit_terms::<0, false>(&mut h_new[0]);
            self.explicit_terms::<1, false>(&mut h_new[1]);
            if self.grid.mode == Mode::Cartesian {
                self.explicit_terms::<2, false>(&mut h_new[2]);
            }
        }
        let (c1, c0) = if self.state.step == 0 || self.state.dt_old <= 0.0 {
            (1.0, 0.0)
        } else {
            let r = dt / (2.0 * self.state.dt_old);
            (1.0 + r, r)
        };
        // Predictor.
        for a in 0..3 {
            let kind = &self.kind[a];
            let (h, ho, p) = (&h_new[a], &self.state.h_old[a], &self.state.p);
            let inv_dc: Vec<f64> = self.grid.metric[a].dc.iter().map(|&x| 1.0 / x).collect();
            for_planes(&l, &mut self.state.u[a], |k, plane| {
                let base = k * s[2];
                for j in GHOST..GHOST + l.n[1] {
                    for i in GHOST..GHOST + l.n[0] {
                        let c = base + j * s[1] + i;
                        if kind[c] == ACTIVE {
                            let qa = [i, j, k][a];
                            plane[c - base] +=
                                dt * (c1 * h[c] - c0 * ho[c]) - dt * (p[c + s[a]] - p[c]) * inv_dc[qa];
                        }
                    }
                }
            });
            if let Some(src) = self.implicit.as_mut() {
                src.advance(a, &l, kind, dt, &mut self.state.u[a]);
            }
            for &(c, src, _) in &self.outlet_nodes[a] {
                self.state.u[a][c] = self.state.u[a][src];
            }
        }
        let t_new = self.state.t + dt;
        self.fill_boundaries(t_new);
        // Pressure correction: A φ = −(Σ A_f u*·n)/Δt.
        let grid = &self.grid;
        let u = &self.state.u;
        let blocked = &self.blocked;
        for_planes(&l, &mut self.rhs, |k, plane| {
            let base = k * s[2];
            let m = &grid.metric;
            for j in GHOST..GHOST + l.n[1] {
                for i in GHOST..GHOST + l.n[0] {
                    let c = base + j * s[1] + i;
                    if blocked[c] {
                        plane[c - base] = 0.0;
                        continue;
                    }
                    let flux = m[1].d[j] * m[2].d[k] * (m[0].wf[i] * u[0][c] - m[0].wf[i - 1] * u[0][c - 1])
                        + m[0].wc[i] * m[0].d[i] * m[2].d[k] * (u[1][c] - u[1][c - s[1]])
                        + m[0].wc[i] * m[0].d[i] * m[1].d[j] * (u[2][c] - u[2][c - s[2]]);
                    plane[c - base] = -flux / dt;
                }
            }
        });
        // Dirichlet faces whose pressure changes: φ_b = p_b⁺ − p_b moves to the right-hand side with the
        // face's coupling 2A/Δ (the half cell between the centre and the face; see `pressure_stencil`).
        let phi_b: Vec<f64> = p_targets.iter().zip(&self.state.p_faces).map(|(t, p)| t - p).collect();
        let mut f = 0;
        for a in 0..3 {
            for &(c, src, _) in &self.outlet_nodes[a] {
                if phi_b[f] != 0.0 {
                    let cell = if src > c { c + s[a] } else { c };
                    let coef =
                        2.0 * self.grid.face_area(a, l.coords(c)) / self.grid.metric[a].d[l.coords(cell)[a]];
                    self.rhs[cell] += coef * phi_b[f];
                }
                f += 1;
            }
        }
        self.phi.iter_mut().for_each(|v| *v = 0.0);
        let rep = self.pcg.solve(&mut self.rhs, &mut self.phi, &self.numerics.pressure);
        if !rep.converged {
            return Err(FlowError::Pressure {
                step: self.state.step,
                residual: rep.relative_residual,
                iterations: rep.iterations,
            });
        }
        // Correction.
        let mut f = 0;
        for a in 0..3 {
            let kind = &self.kind[a];
            let phi = &self.phi;
            let m = &self.grid.metric[a];
            for_planes(&l, &mut self.state.u[a], |k, plane| {
                let base = k * s[2];
                for j in GHOST..GHOST + l.n[1] {
                    for i in GHOST..GHOST + l.n[0] {
                        let c = base + j * s[1] + i;
                        if kind[c] == ACTIVE {
                            let qa = [i, j, k][a];
                            plane[c - base] -= dt * (phi[c + s[a]] - phi[c]) / m.dc[qa];
                        }
                    }
                }
            });
            for &(c, src, _) in &self.outlet_nodes[a] {
                let q = l.coords(c);
                // The face value of φ is φ_b: the gradient over the half cell is 2(φ_b − φ_P)/Δ outwards.
                let cell = if src > c { c + s[a] } else { c };
                let d = m.d[l.coords(cell)[a]];
                let sign = if q[a] < GHOST { 1.0 } else { -1.0 };
                self.state.u[a][c] -= sign * dt * 2.0 * (self.phi[cell] - phi_b[f]) / d;
                f += 1;
            }
        }
        self.state.p_faces = p_targets;
        let phi = &self.phi;
        for_planes(&l, &mut self.state.p, |k, plane| {
            let base = k * s[2];
            for (o, v) in plane.iter_mut().enumerate() {
                *v += phi[base + o];
            }
        });
        self.fill_boundaries(t_new);
        if let (Some(turb), Some(ts)) = (self.turbulence.as_mut(), self.state.turbulence.as_mut()) {
            turb.step(
                &self.grid,
                &self.bc,
                &self.blocked,
                self.fluid.viscosity,
                &self.state.u,
                t_new,
                dt,
                ts,
            );
        }
        self.h_new = std::mem::replace(&mut self.state.h_old, h_new);
        self.state.dt_old = dt;
        self.state.t = t_new;
        self.state.step += 1;
        let courant = self.check(dt)?;
        Ok(StepReport { pressure: rep, courant })
    }

    /// The kinematic pressure each Dirichlet face holds at time `t` \[m²/s²\] (see
    /// [`Boundary::static_pressure`]), from the face velocities of the current state.
    fn pressure_targets(&self, t: f64) -> Vec<f64> {
        let l = self.grid.layout;
        let rho = self.fluid.density;
        let mut out = Vec::with_capacity(self.state.p_faces.len());
        for a in 0..3 {
            for &(c, _, side) in &self.outlet_nodes[a] {
                let u = self.state.u[a][c];
                let u_in = if l.coords(c)[a] < GHOST { u } else { -u };
                let p = self.bc[side as usize].static_pressure(t, u_in, rho).unwrap_or(0.0);
                out.push(p / rho);
            }
        }
        out
    }

    /// Largest Courant number; an error for NaN or Courant numbers above the limit.
    fn check(&self, dt: f64) -> Result<f64, FlowError> {
        let l = self.grid.layout;
        let m = &self.grid.metric;
        let u = &self.state.u;
        let courant_at = |c: usize| {
            let q = l.coords(c);
            (0..3).map(|a| u[a][c].abs().max(u[a][c - l.s[a]].abs()) / m[a].d[q[a]]).sum::<f64>() * dt
        };
        let cmax = max_interior(&l, courant_at);
        if cmax.is_finite() && cmax <= self.numerics.max_courant {
            return Ok(cmax);
        }
        // Locate the offending cell (rare path, sequential).
        for c in 0..l.len() {
            let q = l.coords(c);
            if !l.interior(q) {
                continue;
            }
            let co = courant_at(c);
            let [i, j, k] = [q[0] - GHOST, q[1] - GHOST, q[2] - GHOST];
            if co.is_nan() {
                return Err(FlowError::NotFinite { step: self.state.step, t: self.state.t, i, j, k });
            }
            if co >= cmax || co > self.numerics.max_courant {
                let x = self.grid.centre(q);
                return Err(FlowError::Courant {
                    step: self.state.step,
                    t: self.state.t,
                    courant: co,
                    limit: self.numerics.max_courant,
                    i,
                    j,
                    k,
                    x: x[0],
                    y: x[1],
                    z: x[2],
                });
            }
        }
        Err(FlowError::NotFinite { step: self.state.step, t: self.state.t, i: 0, j: 0, k: 0 })
    }

    /// The largest stable time step: `courant`·min(Δx/|u|) and 0.9 of the explicit diffusion limit
    /// Δt ≤ 1/(4ν Σ 1/Δx²) of second-order Adams–Bashforth; capped at `dt_max`. Where sides that hold the
    /// pressure differ in pressure, |u| is taken at least as the Bernoulli speed of the largest difference,
    /// √(2Δp/ρ) (see [`Flow::pressure_speed`]), over the smallest cell width: fluid at rest between them is
    /// about to move that fast.
    pub fn stable_dt(&self, courant: f64, dt_max: f64) -> f64 {
        let l = self.grid.layout;
        let m = &self.grid.metric;
        let u = &self.state.u;
        let dims = if self.grid.mode == Mode::Axisymmetric { 2 } else { 3 };
        let rate = max_interior(&l, |c| {
            let q = l.coords(c);
            (0..dims).map(|a| u[a][c].abs().max(u[a][c - l.s[a]].abs()) / m[a].d[q[a]]).sum::<f64>()
        });
        let h2 = (0..dims).map(|a| 1.0 / (self.grid.axes[a].min_width().powi(2))).sum::<f64>();
        let mut diff = 0.9 / (4.0 * self.fluid.viscosity * h2);
        if let Some(t) = &self.turbulence {
            // The largest ν_eff Σ 1/Δx² over the cells (ghosts included: they hold the wall viscosity).
            let nu_rate = max_interior(&l, |c| {
                let q = l.coords(c);
                let inv: f64 = (0..dims).map(|a| 1.0 / m[a].d[q[a]].powi(2)).sum();
                let mut v = t.nu_eff[c];
                for a in 0..dims {
                    v = v
                        .max(0.5 * (t.nu_eff[c] + t.nu_eff[c + l.s[a]]))
                        .max(0.5 * (t.nu_eff[c] + t.nu_eff[c - l.s[a]]));
                }
                v * inv
            });
            diff = diff.min(0.9 / (4.0 * nu_rate));
        }
        let u_p = self.pressure_speed(self.state.t);
        let rate = if u_p > 0.0 {
            let h = (0..dims).map(|a| self.grid.axes[a].min_width()).fold(f64::INFINITY, f64::min);
            rate.max(u_p / h)
        } else {
            rate
        };
        let conv = if rate > 0.0 { courant / rate } else { f64::INFINITY };
        dt_max.min(diff).min(conv)
    }

    /// The Bernoulli speed √(2Δp/ρ) \[m/s\] of the largest difference Δp between the pressures the sides
    /// that hold the pressure have at time `t` for fluid at rest (outlets their static pressure,
    /// total-pressure sides p₀): the fastest that difference drives the fluid without losses. 0 when
    /// there are fewer than two such sides or they agree.
    pub fn pressure_speed(&self, t: f64) -> f64 {
        let rho = self.fluid.density;
        let held: Vec<f64> = self.bc.iter().filter_map(|b| b.static_pressure(t, 0.0, rho)).collect();
        let hi = held.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let lo = held.iter().copied().fold(f64::INFINITY, f64::min);
        if held.len() < 2 || hi <= lo {
            return 0.0;
        }
        (2.0 * (hi - lo) / rho).sqrt()
    }

    /// Velocity at the centre of interior cell (i, j, k) (average of the two face values per component).
    pub fn cell_velocity(&self, i: usize, j: usize, k: usize) -> [f64; 3] {
        let l = self.grid.layout;
        let c = l.cell(i, j, k);
        [0, 1, 2].map(|a| 0.5 * (self.state.u[a][c] + self.state.u[a][c - l.s[a]]))
    }

    /// Static pressure at the centre of interior cell (i, j, k) \[Pa\].
    pub fn cell_pressure(&self, i: usize, j: usize, k: usize) -> f64 {
        self.fluid.density * self.state.p[self.grid.layout.cell(i, j, k)]
    }

    /// Velocity at point x by trilinear interpolation of each staggered component \[m/s\]; `None` outside.
    pub fn velocity_at(&self, x: [f64; 3]) -> Option<[f64; 3]> {
        self.velocity_at_nodes(&self.state.u, x)
    }

    /// Like [`Flow::velocity_at`] for other velocity nodes `nodes` on this grid (an earlier state).
    pub fn velocity_at_nodes(&self, nodes: &[Vec<f64>; 3], x: [f64; 3]) -> Option<[f64; 3]> {
        let l = self.grid.layout;
        for a in 0..3 {
            if !(x[a] >= self.grid.axes[a].lo() && x[a] <= self.grid.axes[a].hi()) {
                return None;
            }
        }
        let mut out = [0.0; 3];
        for (comp, o) in out.iter_mut().enumerate() {
            let (base, w) = trilinear_stencil(&self.grid, comp, x);
            let u = &nodes[comp];
            let mut v = 0.0;
            for dk in 0..2 {
                for dj in 0..2 {
                    for di in 0..2 {
                        let c = l.at(base[0] + di, base[1] + dj, base[2] + dk);
                        let f = (if di == 1 { w[0] } else { 1.0 - w[0] })
                            * (if dj == 1 { w[1] } else { 1.0 - w[1] })
                            * (if dk == 1 { w[2] } else { 1.0 - w[2] });
                        v += f * u[c];
                    }
                }
            }
            *o = v;
        }
        Some(out)
    }

    /// Volume flux out of the domain through all boundaries \[m³/s\] (per radian when axisymmetric);
    /// ≈ 0 for a divergence-free field.
    pub fn net_outflow(&self) -> f64 {
        let l = self.grid.layout;
        let s = l.s;
        let m = &self.grid.metric;
        let u = &self.state.u;
        sum_interior(&l, |c| {
            if self.blocked[c] {
                return 0.0;
            }
            let [i, j, k] = l.coords(c);
            m[1].d[j] * m[2].d[k] * (m[0].wf[i] * u[0][c] - m[0].wf[i - 1] * u[0][c - 1])
                + m[0].wc[i] * m[0].d[i] * m[2].d[k] * (u[1][c] - u[1][c - s[1]])
                + m[0].wc[i] * m[0].d[i] * m[1].d[j] * (u[2][c] - u[2][c - s[2]])
        })
    }

    /// Restores a state saved from a flow on the same grid.
    pub fn restore(&mut self, state: State) -> Result<(), FlowError> {
        let n = self.grid.layout.len();
        let faces: usize = self.outlet_nodes.iter().map(Vec::len).sum();
        if state.p.len() != n || state.u.iter().any(|v| v.len() != n) || state.p_faces.len() != faces {
            return Err(FlowError::Boundaries(format!(
                "checkpoint holds {} values per field and {} pressure-face values but this grid needs {n} and \
                 {faces}; was it written for another grid or other boundaries?",
                state.p.len(),
                state.p_faces.len()
            )));
        }
        if self.turbulence.is_some() != state.turbulence.is_some() {
            return Err(FlowError::Setup(
                "the checkpoint was written with a different turbulence model than this flow uses".into(),
            ));
        }
        self.state = state;
        if let (Some(t), Some(ts)) = (self.turbulence.as_mut(), self.state.turbulence.as_ref()) {
            t.fill_nu_eff(&self.grid, &self.bc, &self.blocked, self.fluid.viscosity, &self.state.u, ts);
        }
        Ok(())
    }
}

/// The trilinear stencil of velocity component `comp` at point `x` (inside the grid): the padded
/// coordinates of the lowest of the eight surrounding nodes and the weights along each axis. Nodes of a
/// component sit at the faces along its own axis and at the centres along the others.
pub fn trilinear_stencil(grid: &Grid, comp: usize, x: [f64; 3]) -> ([usize; 3], [f64; 3]) {
    let l = grid.layout;
    let mut base = [0usize; 3];
    let mut w = [0.0f64; 3];
    for a in 0..3 {
        let m = &grid.metric[a];
        let nodes = if a == comp { &m.xf } else { &m.xc };
        // Largest padded index with node ≤ x (nodes are increasing).
        let p = nodes.partition_point(|&v| v <= x[a]).clamp(1, l.p[a] - 1) - 1;
        w[a] = ((x[a] - nodes[p]) / (nodes[p + 1] - nodes[p])).clamp(0.0, 1.0);
        base[a] = p;
    }
    (base, w)
}

/// The pressure-correction operator of the node kinds.
fn pressure_stencil(
    grid: &Grid,
    kind: &[Vec<u8>; 3],
    outlet_nodes: &[Vec<(usize, usize, u8)>; 3],
) -> Stencil {
    let l = grid.layout;
    let mut st = Stencil::empty(l);
    st.singular = outlet_nodes.iter().all(|v| v.is_empty());
    for c in 0..l.len() {
        let q = l.coords(c);
        for a in 0..3 {
            if kind[a][c] == ACTIVE {
                let coef = grid.face_area(a, q) / grid.metric[a].dc[q[a]];
                st.a[a][c] = coef;
                st.diag[c] += coef;
                st.diag[c + l.s[a]] += coef;
            }
        }
    }
    for (a, list) in outlet_nodes.iter().enumerate() {
        for &(c, src, _) in list {
            let cell = if src > c { c + l.s[a] } else { c };
            // Face area of the outlet face (the +face of `c` along a) over half the cell width.
            let area = grid.face_area(a, l.coords(c));
            st.diag[cell] += 2.0 * area / grid.metric[a].d[l.coords(cell)[a]];
        }
    }
    st
}

#[cfg(test)]
mod tests {
    use crate::cavity::square_cavity;
    use crate::Numerics;

    fn bits(v: &[Vec<f64>; 3]) -> Vec<u64> {
        v.iter().flat_map(|c| c.iter().map(|x| x.to_bits())).collect()
    }

    #[test]
    fn memory_estimate_matches_what_the_solver_allocates() {
        use crate::grid::{Axis, Grid, Mode};
        use crate::{Boundary, Flow, Fluid};
        for (n, mode) in [([40, 30, 20], Mode::Cartesian), ([48, 96, 1], Mode::Axisymmetric)] {
            let ax = |a: usize| Axis::uniform(0.0, 1.0, n[a]).unwrap();
            let g = Grid::new([ax(0), ax(1), ax(2)], mode).unwrap();
            let wall = Boundary::Wall { velocity_m_s: [0.0; 3] };
            let mut bc: [Boundary; 6] = std::array::from_fn(|_| wall.clone());
            if mode == Mode::Axisymmetric {
                bc[0] = Boundary::Axis;
                bc[4] = Boundary::Slip;
                bc[5] = Boundary::Slip;
            }
            let blocked = vec![false; g.layout.len()];
            let mut f =
                Flow::new(g, Fluid { density: 1.0, viscosity: 1e-3 }, bc, blocked, Numerics::default())
                    .unwrap();
            let l = f.grid.layout.len();
            f.force = Some([vec![0.0; l], vec![0.0; l], vec![0.0; l]]);
            f.enable_k_epsilon(crate::turbulence::KEpsilon::standard(0.05, 0.1));
            let (est, real) = (Flow::memory_estimate(n, true, true) as f64, f.heap_bytes() as f64);
            assert!((est / real - 1.0).abs() < 0.05, "{n:?}: estimate {est} B, allocated {real} B");
        }
    }

    #[test]
    fn resume_from_a_checkpoint_is_bit_identical_and_threads_do_not_change_results() {
        let run = |threads: usize, split: Option<usize>| {
            rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
                let mut f = square_cavity(24, 400.0, 0.5, Numerics::default()).unwrap();
                let dir = tempfile::tempdir().unwrap();
                let path = dir.path().join("checkpoint.bin");
                for s in 0..40 {
                    if Some(s) == split {
                        spatter_io::checkpoint::save(&path, 7, &f.state).unwrap();
                        f = square_cavity(24, 400.0, 0.5, Numerics::default()).unwrap();
                        f.restore(spatter_io::checkpoint::load(&path, 7).unwrap()).unwrap();
                    }
                    // A variable step exercises the AB2 step-ratio history in the checkpoint.
                    f.step(0.01 + 0.0005 * (s % 3) as f64).unwrap();
                }
                (bits(&f.state.u), f.state.p.iter().map(|x| x.to_bits()).collect::<Vec<_>>())
            })
        };
        let straight = run(1, None);
        assert_eq!(run(1, Some(17)), straight, "resume changes nothing");
        assert_eq!(run(2, None), straight, "2 threads give the same bits as 1");
    }
}
