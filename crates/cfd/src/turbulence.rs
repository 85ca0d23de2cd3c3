//! The k–ε models with wall functions: standard (Launder & Spalding 1974, "The numerical computation of
//! turbulent flows", Comput. Methods Appl. Mech. Eng. 3:269–289) and realizable (Shih, Liou, Shabbir,
//! Yang & Zhu 1995, "A new k–ε eddy viscosity model for high Reynolds number turbulent flows", Computers
//! & Fluids 24:227–238).
//!
//! Transport of the turbulent kinetic energy k and its dissipation rate ε at the cell centres:
//!
//!   ∂k/∂t + ∇·(u k) = ∇·((ν + ν_t/σ_k)∇k) + P_k − ε,
//!   ∂ε/∂t + ∇·(u ε) = ∇·((ν + ν_t/σ_ε)∇ε) + (ε/k)(C₁ P_k − C₂ ε),   ν_t = C_μ k²/ε,
//!
//! with P_k = ν_t · 2 S_ij S_ij (plus 2(u_r/r)² in the axisymmetric mode) and the constants C_μ = 0.09,
//! C₁ = 1.44, C₂ = 1.92, σ_k = 1.0, σ_ε = 1.3.
//!
//! **Realizable** ([`Variant::Realizable`]): the same k equation; the ε equation
//!
//!   ∂ε/∂t + ∇·(u ε) = ∇·((ν + ν_t/σ_ε)∇ε) + C₁ S ε − C₂ ε²/(k + √(ν ε)),
//!
//! with S = √(2 S_ij S_ij), C₁ = max(0.43, η/(η + 5)), η = S k/ε, C₂ = 1.9, σ_ε = 1.2, and a variable
//! C_μ = 1/(A₀ + A_s k U*/ε) in ν_t = C_μ k²/ε: A₀ = 4.04, A_s = √6 cos φ, φ = ⅓ arccos(√6 W),
//! W = S_ij S_jk S_ki / S̃³, S̃ = √(S_ij S_ij), U* = √(S_ij S_ij + Ω_ij Ω_ij) (the hoop strain u_r/r
//! included in the axisymmetric mode). C_μ falls where strain is large against k/ε (stagnation points,
//! where the standard model overproduces k, and the front of a starting jet, where it lets ν_t run away),
//! and is 0.09 in an equilibrium log layer (S k/ε = 3.33). The wall functions and the cells next to
//! walls keep C_μ = 0.09 (the log-law equilibrium the wall functions assume).
//!
//! Convection uses the face velocities of the staggered grid
//! directly with the momentum equation's TVD scheme; time stepping is forward Euler with the destruction
//! terms implicit (k ← (k + Δt R)/(1 + Δt ε/k)), which keeps k and ε positive.
//!
//! **Wall functions** (standard log law, κ = 0.41, E = 9.793) on the no-slip sides of the box and on the
//! faces of blocked cells (solids inside the grid, at rest): in a cell next to a wall at distance y_p
//! (half the cell width across the wall face), with u* = C_μ^{1/4} k^{1/2} and y* = u* y_p/ν,
//! * the wall shear stress is τ_w/ρ = ν_w u_t / y_p with the wall viscosity ν_w = ν y* κ / ln(E y*)
//!   (ν below y* = 11.06), entered in the momentum equation as the viscosity of the wall face;
//! * P_k = (τ_w/ρ) u*/(κ y_p) and ε = C_μ^{3/4} k^{3/2}/(κ y_p) (averaged over the walls of a corner cell).
//!
//! Inlets bring k = 1.5 (I |u_in|)² and ε = C_μ^{3/4} k^{3/2}/ℓ for a turbulence intensity I and length
//! scale ℓ; outlets, slip sides and the axis have zero normal gradient; no k or ε crosses a wall or the
//! face of a blocked cell.
//!
//! The wall viscosity enters the momentum equation through ν_eff of the cell across the wall face: a
//! ghost cell across a side holds 2ν_w − ν_eff(P), so that the face average is ν_w; a blocked cell holds
//! the mean of 2ν_w − ν_eff(P) over the fluid cells P sharing a face with it, which is exact for a flat
//! wall and an average at the edges and corners of a solid (a staircase of blocked cells).
//! The turbulent stress is modelled as ∇·(ν_eff ∇u); the part ∇·(ν_t (∇u)ᵀ), which vanishes for
//! developed shear flows, is left out.

use crate::bc::Boundary;
use crate::grid::{Grid, Mode, GHOST};
use crate::momentum::{face_value, Convection, DirOps};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Which k–ε model.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Variant {
    /// Launder & Spalding (1974): constant C_μ, ε production C₁ P_k ε/k.
    #[default]
    Standard,
    /// Shih et al. (1995): variable C_μ, ε production C₁ S ε, destruction C₂ ε²/(k + √(νε)).
    Realizable,
}

/// A₀ of the realizable model's C_μ (the value of Fluent's implementation, which the thesis of Jasion
/// 2013 used; Shih et al. 1995 give 4.0).
pub const A0_REALIZABLE: f64 = 4.04;

/// Model constants and inlet turbulence.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KEpsilon {
    /// Standard or realizable.
    #[serde(default)]
    pub variant: Variant,
    #[serde(default = "c_mu")]
    pub c_mu: f64,
    #[serde(default = "c1")]
    pub c1: f64,
    #[serde(default = "c2")]
    pub c2: f64,
    #[serde(default = "one")]
    pub sigma_k: f64,
    #[serde(default = "sigma_eps")]
    pub sigma_eps: f64,
    /// Turbulence intensity I of the inlets \[-\].
    #[serde(default = "intensity")]
    pub inlet_intensity: f64,
    /// Turbulence length scale ℓ of the inlets \[m\].
    pub inlet_length_scale_m: f64,
}

fn c_mu() -> f64 {
    0.09
}
fn c1() -> f64 {
    1.44
}
fn c2() -> f64 {
    1.92
}
fn one() -> f64 {
    1.0
}
fn sigma_eps() -> f64 {
    1.3
}
fn intensity() -> f64 {
    0.05
}

/// von Kármán constant and the log-law constant of smooth walls.
pub const KAPPA: f64 = 0.41;
pub const E_WALL: f64 = 9.793;
/// y* where the linear and logarithmic laws meet.
pub const Y_LAM: f64 = 11.06;

impl KEpsilon {
    /// The standard constants with inlet turbulence `intensity` and `length_scale` \[m\].
    pub fn standard(intensity: f64, length_scale: f64) -> Self {
        KEpsilon {
            variant: Variant::Standard,
            c_mu: c_mu(),
            c1: c1(),
            c2: c2(),
            sigma_k: 1.0,
            sigma_eps: sigma_eps(),
            inlet_intensity: intensity,
            inlet_length_scale_m: length_scale,
        }
    }

    /// The realizable model (Shih et al. 1995: C₂ = 1.9, σ_k = 1.0, σ_ε = 1.2; C₁ is computed) with inlet
    /// turbulence `intensity` and `length_scale` \[m\]. `c_mu` = 0.09 is kept for the wall functions and
    /// the inlet ε.
    pub fn realizable(intensity: f64, length_scale: f64) -> Self {
        KEpsilon {
            variant: Variant::Realizable,
            c_mu: c_mu(),
            c1: c1(),
            c2: 1.9,
            sigma_k: 1.0,
            sigma_eps: 1.2,
            inlet_intensity: intensity,
            inlet_length_scale_m: length_scale,
        }
    }

    /// k and ε of an inlet with speed `speed` \[m/s\].
    pub fn inlet_values(&self, speed: f64) -> (f64, f64) {
        let k = (1.5 * (self.inlet_intensity * speed).powi(2)).max(K_MIN);
        (k, self.c_mu.powf(0.75) * k.powf(1.5) / self.inlet_length_scale_m)
    }
}

/// Floors that keep k and ε positive \[m²/s², m²/s³\].
pub const K_MIN: f64 = 1e-12;
pub const EPS_MIN: f64 = 1e-14;

/// Wall viscosity ν_w (molecular plus turbulent at the wall face) for a cell centre at `y` \[m\] from the
/// wall with turbulent kinetic energy `k`, molecular viscosity `nu`.
#[inline]
pub fn wall_viscosity(c_mu: f64, k: f64, y: f64, nu: f64) -> f64 {
    let ystar = c_mu.powf(0.25) * k.max(0.0).sqrt() * y / nu;
    if ystar > Y_LAM {
        nu * ystar * KAPPA / (E_WALL * ystar).ln()
    } else {
        nu
    }
}

/// C_μ of the realizable model (Shih et al. 1995) for the velocity gradient `g` (g\[a\]\[b\] = ∂u_a/∂x_b,
/// the hoop strain u_r/r in g\[2\]\[2\] when axisymmetric), k \[m²/s²\] and ε \[m²/s³\]:
/// C_μ = 1/(A₀ + A_s k U*/ε).
pub fn realizable_c_mu(g: &[[f64; 3]; 3], k: f64, eps: f64) -> f64 {
    let mut s = [[0.0; 3]; 3];
    let (mut ss, mut oo) = (0.0, 0.0);
    for a in 0..3 {
        for b in 0..3 {
            s[a][b] = 0.5 * (g[a][b] + g[b][a]);
            let o = 0.5 * (g[a][b] - g[b][a]);
            ss += s[a][b] * s[a][b];
            oo += o * o;
        }
    }
    let mut sss = 0.0;
    for a in 0..3 {
        for b in 0..3 {
            for c in 0..3 {
                sss += s[a][b] * s[b][c] * s[c][a];
            }
        }
    }
    let st = ss.sqrt();
    let w = if st > 0.0 { sss / (st * st * st) } else { 0.0 };
    let phi = ((6f64.sqrt() * w).clamp(-1.0, 1.0)).acos() / 3.0;
    let a_s = 6f64.sqrt() * phi.cos();
    let u_star = (ss + oo).sqrt();
    1.0 / (A0_REALIZABLE + a_s * k * u_star / eps.max(EPS_MIN))
}

/// Velocity gradient at the centre of cell `c` (g\[a\]\[b\] = ∂u_a/∂x_b from the cell-centred velocities;
/// the hoop strain u_r/r in g\[2\]\[2\] when axisymmetric only if `hoop`).
fn cell_gradient(grid: &Grid, u: &[Vec<f64>; 3], c: usize, hoop: bool) -> [[f64; 3]; 3] {
    let l = grid.layout;
    let s = l.s;
    let m = &grid.metric;
    let q = l.coords(c);
    let dims = if grid.mode == Mode::Axisymmetric { 2 } else { 3 };
    let uc = |c: usize, a: usize| 0.5 * (u[a][c] + u[a][c - s[a]]);
    let mut g = [[0.0; 3]; 3];
    for a in 0..dims {
        g[a][a] = (u[a][c] - u[a][c - s[a]]) / m[a].d[q[a]];
        for b in 0..dims {
            if b != a {
                let sb = s[b];
                let span = m[b].xc[q[b] + 1] - m[b].xc[q[b] - 1];
                g[a][b] = (uc(c + sb, a) - uc(c - sb, a)) / span;
            }
        }
    }
    if hoop && grid.mode == Mode::Axisymmetric {
        g[2][2] = uc(c, 0) / m[0].xc[q[0]];
    }
    g
}

/// The turbulence state: k and ε at the cell centres (padded layout).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TurbState {
    pub k: Vec<f64>,
    pub eps: Vec<f64>,
}

/// Work arrays and the fixed wall geometry of the model.
#[derive(Clone, Debug)]
pub struct Turbulence {
    pub model: KEpsilon,
    /// ν + ν_t per padded cell, ghosts holding the wall-function values (see [`Turbulence::fill_nu_eff`]).
    pub nu_eff: Vec<f64>,
    /// The faces between fluid cells and walls (no-slip sides and blocked cells).
    walls: Vec<WallFace>,
    /// (blocked cell, fluid cell sharing a face with it, distance from the fluid cell's centre to the
    /// face \[m\]), ordered by blocked cell.
    solid_faces: Vec<(usize, usize, f64)>,
    /// Whether a cell lies next to a wall (its ν_t keeps the wall functions' C_μ).
    at_wall: Vec<bool>,
    k_new: Vec<f64>,
    eps_new: Vec<f64>,
    /// Per cell: P_k and ε summed over its walls, and the number of walls.
    wall_p: Vec<f64>,
    wall_e: Vec<f64>,
    wall_n: Vec<u8>,
    centre_ops: [DirOps; 3],
}

/// A wall face of a fluid cell.
#[derive(Clone, Copy, Debug)]
struct WallFace {
    /// The fluid cell.
    cell: usize,
    /// Direction of the wall from the cell, as a side index (2a: −a, 2a + 1: +a).
    side: usize,
    /// Distance from the cell centre to the wall \[m\].
    y: f64,
    /// The face of a blocked cell (a wall at rest) rather than a side of the grid.
    solid: bool,
}

fn mirror(l: &crate::grid::Layout, side: usize, c: usize) -> Option<usize> {
    // The ghost cell across `side` from boundary cell c.
    let a = side / 2;
    let q = l.coords(c);
    if side % 2 == 0 {
        (q[a] == GHOST).then(|| c - l.s[a])
    } else {
        (q[a] == GHOST + l.n[a] - 1).then(|| c + l.s[a])
    }
}

impl Turbulence {
    pub fn new(model: KEpsilon, grid: &Grid, bc: &[Boundary; 6], blocked: &[bool]) -> Self {
        let l = grid.layout;
        let dims = if grid.mode == Mode::Axisymmetric { 2 } else { 3 };
        let mut walls = Vec::new();
        let mut solid_faces = Vec::new();
        for c in 0..l.len() {
            let q = l.coords(c);
            if !l.interior(q) || blocked[c] {
                continue;
            }
            for (side, b) in bc.iter().enumerate() {
                if matches!(b, Boundary::Wall { .. }) && mirror(&l, side, c).is_some() {
                    let a = side / 2;
                    walls.push(WallFace { cell: c, side, y: 0.5 * grid.metric[a].d[q[a]], solid: false });
                }
            }
            for a in 0..dims {
                for (side, nb) in [(2 * a, c - l.s[a]), (2 * a + 1, c + l.s[a])] {
                    if l.interior(l.coords(nb)) && blocked[nb] {
                        let y = 0.5 * grid.metric[a].d[q[a]];
                        walls.push(WallFace { cell: c, side, y, solid: true });
                        solid_faces.push((nb, c, y));
                    }
                }
            }
        }
        solid_faces.sort_by_key(|&(b, c, _)| (b, c));
        let n = l.len();
        let mut at_wall = vec![false; n];
        for w in &walls {
            at_wall[w.cell] = true;
        }
        Turbulence {
            model,
            nu_eff: vec![0.0; n],
            walls,
            solid_faces,
            at_wall,
            k_new: vec![0.0; n],
            eps_new: vec![0.0; n],
            wall_p: vec![0.0; n],
            wall_e: vec![0.0; n],
            wall_n: vec![0; n],
            centre_ops: [0, 1, 2].map(|a| DirOps::centre(&grid.metric[a])),
        }
    }

    /// Bytes held on the heap (ν_eff, work arrays, wall lists).
    pub fn heap_bytes(&self) -> u64 {
        let f = self.nu_eff.capacity()
            + self.k_new.capacity()
            + self.eps_new.capacity()
            + self.wall_p.capacity()
            + self.wall_e.capacity();
        (8 * f
            + self.wall_n.capacity()
            + self.at_wall.capacity()
            + std::mem::size_of::<WallFace>() * self.walls.capacity()
            + 24 * self.solid_faces.capacity()) as u64
    }

    /// Initial state: the inlet values of the fastest inlet everywhere (or a small k at rest).
    pub fn initial_state(&self, grid: &Grid, bc: &[Boundary; 6]) -> TurbState {
        let speed = bc
            .iter()
            .filter_map(|b| match b {
                Boundary::Inlet { velocity_m_s, table } => {
                    let f = table.t_s.iter().map(|&t| table.at(t).abs()).fold(table.at(0.0).abs(), f64::max);
                    Some(f * velocity_m_s.iter().map(|v| v * v).sum::<f64>().sqrt())
                }
                _ => None,
            })
            .fold(0.0, f64::max);
        let (k, e) = self.model.inlet_values(speed.max(1e-3));
        let n = grid.layout.len();
        TurbState { k: vec![k; n], eps: vec![e; n] }
    }

    /// Ghost values of k and ε: inlet values at inlets, zero gradient elsewhere.
    fn fill_ghosts(&self, grid: &Grid, bc: &[Boundary; 6], t: f64, st: &mut TurbState) {
        let l = grid.layout;
        for (side, b) in bc.iter().enumerate() {
            let inlet = match b {
                Boundary::Inlet { .. } => {
                    let v = b.velocity(t).unwrap_or([0.0; 3]);
                    Some(self.model.inlet_values((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()))
                }
                _ => None,
            };
            let a = side / 2;
            for_side_cells(&l, side, |c, g| {
                let g2 = if side % 2 == 0 { g - l.s[a] } else { g + l.s[a] };
                match inlet {
                    Some((ki, ei)) => {
                        st.k[g] = (2.0 * ki - st.k[c]).max(K_MIN);
                        st.eps[g] = (2.0 * ei - st.eps[c]).max(EPS_MIN);
                    }
                    None => {
                        st.k[g] = st.k[c];
                        st.eps[g] = st.eps[c];
                    }
                }
                st.k[g2] = st.k[g];
                st.eps[g2] = st.eps[g];
            });
        }
    }

    /// ν_eff = ν + C_μ k²/ε in fluid cells (C_μ of the realizable model from the velocity `u`), ν in
    /// blocked cells; in the ghost cell across a wall the value 2ν_w − ν_eff(P), so that the average over
    /// the wall face (used by the momentum diffusion) is the wall viscosity ν_w of the log law; a copy of
    /// the neighbour across other sides.
    #[allow(clippy::too_many_arguments)]
    pub fn fill_nu_eff(
        &mut self,
        grid: &Grid,
        bc: &[Boundary; 6],
        blocked: &[bool],
        nu: f64,
        u: &[Vec<f64>; 3],
        st: &TurbState,
    ) {
        let l = grid.layout;
        let c_mu = self.model.c_mu;
        let realizable = self.model.variant == Variant::Realizable;
        for c in 0..l.len() {
            let q = l.coords(c);
            self.nu_eff[c] = if l.interior(q) && !blocked[c] {
                // Next to a wall the log law's equilibrium (C_μ = 0.09) holds by assumption of the wall
                // functions; the cell-centred gradient there (a difference across the wall's ghost) is
                // too coarse to give the realizable C_μ.
                let cm = if realizable && !self.at_wall[c] {
                    realizable_c_mu(&cell_gradient(grid, u, c, true), st.k[c], st.eps[c])
                } else {
                    c_mu
                };
                nu + (cm * st.k[c] * st.k[c] / st.eps[c].max(EPS_MIN)).min(1e5 * nu)
            } else {
                nu
            };
        }
        // Blocked cells next to fluid: the mean over their fluid neighbours of 2ν_w − ν_eff(P).
        for group in self.solid_faces.chunk_by(|x, y| x.0 == y.0) {
            let sum: f64 = group
                .iter()
                .map(|&(_, p, y)| 2.0 * wall_viscosity(c_mu, st.k[p], y, nu) - self.nu_eff[p])
                .sum();
            self.nu_eff[group[0].0] = sum / group.len() as f64;
        }
        for (side, b) in bc.iter().enumerate() {
            let a = side / 2;
            for_side_cells(&l, side, |c, g| {
                self.nu_eff[g] = match b {
                    Boundary::Wall { .. } if !blocked[c] => {
                        let y = 0.5 * grid.metric[a].d[l.coords(c)[a]];
                        2.0 * wall_viscosity(c_mu, st.k[c], y, nu) - self.nu_eff[c]
                    }
                    _ => self.nu_eff[c],
                };
            });
        }
    }

    /// Advances k and ε by `dt` with the velocity `u` (face nodes) of the new time level.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        grid: &Grid,
        bc: &[Boundary; 6],
        blocked: &[bool],
        nu: f64,
        u: &[Vec<f64>; 3],
        t: f64,
        dt: f64,
        st: &mut TurbState,
    ) {
        let l = grid.layout;
        let s = l.s;
        let m = &grid.metric;
        let md = &self.model;
        let dims = if grid.mode == Mode::Axisymmetric { 2 } else { 3 };
        self.fill_ghosts(grid, bc, t, st);
        // Cell-centred velocity and its gradient.
        let uc = |c: usize, a: usize| 0.5 * (u[a][c] + u[a][c - s[a]]);
        // Wall functions: P_k and ε of the cells next to walls (sums over the walls, then averaged).
        for w in &self.walls {
            self.wall_p[w.cell] = 0.0;
            self.wall_e[w.cell] = 0.0;
            self.wall_n[w.cell] = 0;
        }
        let cmu25 = md.c_mu.powf(0.25);
        for &WallFace { cell: c, side, y, solid } in &self.walls {
            let a = side / 2;
            let k = st.k[c].max(K_MIN);
            let vw = if solid { [0.0; 3] } else { bc[side].velocity(t).unwrap_or([0.0; 3]) };
            // Tangential speed relative to the wall at the cell centre.
            let mut ut2 = 0.0;
            for b in 0..dims {
                if b != a {
                    let d = uc(c, b) - vw[b];
                    ut2 += d * d;
                }
            }
            let ustar = cmu25 * k.sqrt();
            let tau = wall_viscosity(md.c_mu, k, y, nu) * ut2.sqrt() / y;
            self.wall_p[c] += tau * ustar / (KAPPA * y);
            self.wall_e[c] += md.c_mu.powf(0.75) * k.powf(1.5) / (KAPPA * y);
            self.wall_n[c] += 1;
        }
        let (wall_p, wall_e, wall_n) = (&self.wall_p, &self.wall_e, &self.wall_n);
        let scheme = Convection::VanLeer;
        let ops = &self.centre_ops;
        let (k, e) = (&st.k, &st.eps);
        let nu_eff = &self.nu_eff;
        let plane = l.plane();
        let cell = |c: usize| -> (f64, f64) {
            let q = l.coords(c);
            if !l.interior(q) || blocked[c] {
                return (k[c], e[c]);
            }
            // Strain rate 2 S_ij S_ij from the cell-centred velocities (the hoop strain is added below).
            let g = cell_gradient(grid, u, c, false);
            let mut s2 = 0.0;
            for a in 0..3 {
                for b in 0..3 {
                    let sij = 0.5 * (g[a][b] + g[b][a]);
                    s2 += 2.0 * sij * sij;
                }
            }
            if grid.mode == Mode::Axisymmetric {
                let r = m[0].xc[q[0]];
                let ur_r = uc(c, 0) / r;
                s2 += 2.0 * ur_r * ur_r;
            }
            let kc = k[c].max(K_MIN);
            let ec = e[c].max(EPS_MIN);
            let nut = nu_eff[c] - nu;
            let mut pk = nut * s2;
            let mut eps_wall = None;
            if wall_n[c] > 0 {
                let w = wall_n[c] as f64;
                pk = wall_p[c] / w;
                eps_wall = Some(wall_e[c] / w);
            }
            // Convection and diffusion of k and ε.
            let (mut rk, mut re) = (0.0, 0.0);
            for a in 0..dims {
                let sa = s[a];
                let o = &ops[a];
                let qa = q[a];
                let (fp, fm) = (o.fp[qa], o.fm[qa]);
                let (vp, vm) = (u[a][c], u[a][c - sa]);
                // Zero flux of k and ε through walls (and through the faces of blocked cells).
                let closed_p = blocked[c + sa] || (qa == GHOST + l.n[a] - 1 && is_closed(&bc[2 * a + 1]));
                let closed_m = blocked[c - sa] || (qa == GHOST && is_closed(&bc[2 * a]));
                for (phi, sigma, r) in [(k, md.sigma_k, &mut rk), (e, md.sigma_eps, &mut re)] {
                    let pc = phi[c];
                    let (pe, pw) = (phi[c + sa], phi[c - sa]);
                    let plus = if vp >= 0.0 {
                        face_value(scheme, pw, pc, pe)
                    } else {
                        let pee = if qa + 2 < l.p[a] { phi[c + 2 * sa] } else { pe };
                        face_value(scheme, pee, pe, pc)
                    };
                    let minus = if vm >= 0.0 {
                        let pww = if qa >= 2 { phi[c - 2 * sa] } else { pw };
                        face_value(scheme, pww, pw, pc)
                    } else {
                        face_value(scheme, pe, pc, pw)
                    };
                    let gp = nu + 0.5 * ((nu_eff[c] - nu) + (nu_eff[c + sa] - nu).max(0.0)) / sigma;
                    let gm = nu + 0.5 * ((nu_eff[c] - nu) + (nu_eff[c - sa] - nu).max(0.0)) / sigma;
                    let mut flux = 0.0;
                    if !closed_p {
                        flux += fp * (gp * o.hp[qa] * (pe - pc) - vp * (plus - pc));
                    }
                    if !closed_m {
                        flux -= fm * (gm * o.hm[qa] * (pc - pw) - vm * (minus - pc));
                    }
                    *r += flux;
                }
            }
            let k_new = ((kc + dt * (rk + pk)) / (1.0 + dt * ec / kc)).max(K_MIN);
            let eps_new = match (eps_wall, md.variant) {
                (Some(ew), _) => ew.max(EPS_MIN),
                (None, Variant::Standard) => {
                    ((ec + dt * (re + md.c1 * ec / kc * pk)) / (1.0 + dt * md.c2 * ec / kc)).max(EPS_MIN)
                }
                (None, Variant::Realizable) => {
                    let strain = s2.sqrt();
                    let eta = strain * kc / ec;
                    let c1 = (eta / (eta + 5.0)).max(0.43);
                    let sink = md.c2 * ec / (kc + (nu * ec).sqrt());
                    ((ec + dt * (re + c1 * strain * ec)) / (1.0 + dt * sink)).max(EPS_MIN)
                }
            };
            (k_new, eps_new)
        };
        // Every cell is computed from the old values alone: any thread count gives the same bits.
        self.k_new.par_chunks_mut(plane).zip(self.eps_new.par_chunks_mut(plane)).enumerate().for_each(
            |(kk, (kp, ep))| {
                let base = kk * plane;
                for o in 0..plane {
                    let (a, b) = cell(base + o);
                    kp[o] = a;
                    ep[o] = b;
                }
            },
        );
        std::mem::swap(&mut st.k, &mut self.k_new);
        std::mem::swap(&mut st.eps, &mut self.eps_new);
        self.fill_ghosts(grid, bc, t, st);
        self.fill_nu_eff(grid, bc, blocked, nu, u, st);
    }
}

fn is_closed(b: &Boundary) -> bool {
    matches!(b, Boundary::Wall { .. } | Boundary::Slip | Boundary::Axis)
}

/// Calls `f(cell, ghost)` for every interior cell on `side` and the first ghost cell across it.
fn for_side_cells(l: &crate::grid::Layout, side: usize, mut f: impl FnMut(usize, usize)) {
    let a = side / 2;
    let (b1, b2) = ((a + 1) % 3, (a + 2) % 3);
    let qa = if side % 2 == 0 { GHOST } else { GHOST + l.n[a] - 1 };
    for o2 in GHOST..GHOST + l.n[b2] {
        for o1 in GHOST..GHOST + l.n[b1] {
            let mut q = [0; 3];
            q[a] = qa;
            q[b1] = o1;
            q[b2] = o2;
            let c = l.at(q[0], q[1], q[2]);
            let g = if side % 2 == 0 { c - l.s[a] } else { c + l.s[a] };
            f(c, g);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_viscosity_follows_the_log_law() {
        // In the log layer τ_w = ρ u_τ² with u_τ = C_μ^{1/4} k^{1/2} (equilibrium) and u_p/u_τ = ln(E y+)/κ,
        // so ν_w u_p / y_p must equal u_τ².
        let (nu, y, k): (f64, f64, f64) = (1.5e-5, 2e-3, 0.05);
        let ut = 0.09f64.powf(0.25) * k.sqrt();
        let yplus = ut * y / nu;
        let up = ut * (E_WALL * yplus).ln() / KAPPA;
        let nw = wall_viscosity(0.09, k, y, nu);
        assert!((nw * up / y - ut * ut).abs() < 1e-12 * ut * ut, "{} vs {}", nw * up / y, ut * ut);
        // In the viscous sublayer it is the molecular viscosity.
        assert_eq!(wall_viscosity(0.09, 1e-8, 1e-5, nu), nu);
    }

    /// Shih et al. (1995) built C_μ so that an equilibrium log layer (production = dissipation, so
    /// (S k/ε)² C_μ = 1) keeps the standard value: in simple shear du/dy = γ (W = 0, A_s = √6 cos 30°,
    /// U* = S = γ) at S k/ε = 3.33 it gives C_μ = 1/(4.04 + 2.1213 · 3.33) = 0.0900; without strain
    /// 1/A₀. A strong strain (large S k/ε, as at a stagnation point) lowers it as 1/(S k/ε).
    #[test]
    fn realizable_c_mu_is_the_standard_value_in_an_equilibrium_log_layer() {
        let (k, eps) = (0.3, 0.1);
        let gamma = 3.33 * eps / k;
        let mut g = [[0.0; 3]; 3];
        g[0][1] = gamma;
        let cm = realizable_c_mu(&g, k, eps);
        assert!((cm - 1.0 / (4.04 + 6f64.sqrt() * (std::f64::consts::PI / 6.0).cos() * 3.33)).abs() < 1e-12);
        assert!((cm - 0.0900).abs() < 2e-4, "C_mu = {cm}");
        assert!((realizable_c_mu(&[[0.0; 3]; 3], k, eps) - 1.0 / 4.04).abs() < 1e-15);
        // Axisymmetric stagnation-point strain (u_r = a r/2, u_z = −a z, hoop a/2) at S k/ε = 30.
        let a: f64 = 1.0;
        let strain = (2.0 * (0.25 + 1.0 + 0.25) * a * a).sqrt();
        let k2 = 30.0 * eps / strain;
        let g = [[0.5 * a, 0.0, 0.0], [0.0, -a, 0.0], [0.0, 0.0, 0.5 * a]];
        // W = −1/√6 (φ = π/3, A_s = √6/2), U* = S̃ = S/√2.
        let cm = realizable_c_mu(&g, k2, eps);
        let want = 1.0 / (4.04 + 0.5 * 6f64.sqrt() * 30.0 / 2f64.sqrt());
        assert!((cm - want).abs() < 1e-12, "C_mu = {cm}, want {want}");
        assert!(cm < 0.5 * 0.09, "C_mu = {cm} at a stagnation point");
    }
}
