//! The neighbour loops: wall extrapolation, surface normals and the fluid force/continuity pass.
//!
//! Every loop gathers over neighbours (each particle sums its own interactions in a fixed order), so the
//! results are identical for any number of threads. Fluid–fluid pair terms for particle i and neighbour j,
//! with `x_ij = x_i − x_j`, `v_ij = v_i − v_j`, `F = (1/r) dW/dr` (so `∇_i W_ij = x_ij F`):
//!
//! * pressure (symmetric form, thesis eq. 2.23): `a_i −= m (p_i/ρ_i² + p_j/ρ_j²) x_ij F`;
//! * Monaghan artificial viscosity (eq. 2.24–2.25, β = 0, `c̄ = c₀`, `1/ρ̄_ij = ½(1/ρ_i + 1/ρ_j)`):
//!   `a_i −= m Π_ij x_ij F`, `Π_ij = −α c₀ μ_ij / ρ̄_ij`, `μ_ij = h min(v_ij·x_ij, 0) / (r² + 0.01h²)`;
//! * Morris et al. (1997) laminar viscosity (eq. 2.26, μ = ρν; `(μ_i + μ_j)/(ρ_i ρ_j) = ν (1/ρ_i + 1/ρ_j)`):
//!   `a_i += m ν (1/ρ_i + 1/ρ_j) · r² F/(r² + 0.01h²) · v_ij`;
//! * continuity (eq. 2.21): `Dρ_i += m v_ij·x_ij F`;
//! * δ-SPH density diffusion (Molteni & Colagrossi 2009, Comput. Phys. Commun. 180:861) with the
//!   hydrostatic correction of Fourtakas et al. (2019, Comput. Fluids 190:346), linearised:
//!   `Dρ_i += 2δhc₀ (ρ_i − ρ_j − ρ₀ g·x_ij / c₀²) F m/ρ_j`;
//! * Akinci et al. (2013) cohesion and curvature, see [`crate::kernel::akinci_cohesion`].
//!
//! Walls (boundary particle b with volume V_b, extrapolated pressure p_b and density ρ_b, mass ρ_b V_b)
//! enter the same pressure, artificial-viscosity and continuity terms with the wall velocity, the laminar
//! term with the no-slip dummy velocity, and the Akinci adhesion force.

use crate::candidates::{Candidates, Coords32View, BATCH};
use crate::kernel::{AkinciSplines, Dim, Kernel, KernelKind};
use crate::neighbours::NeighbourGrid;
use crate::params::DragParams;
use rayon::prelude::*;
use spatter_core::Vec3;
use std::sync::atomic::{AtomicU8, Ordering::Relaxed};

/// Kernel evaluated in the hot loops (monomorphised per kernel kind).
pub(crate) trait KernelFn: Copy + Send + Sync {
    fn w(&self, r: f64) -> f64;
    /// `(1/r) dW/dr` for `r` below the support radius.
    fn f(&self, r: f64) -> f64;
    /// `(1/h, c)` when `F(r) = c (1 − r/(2h))³` (Wendland C2), for the single-precision batches.
    fn wendland(&self) -> Option<(f64, f64)> {
        None
    }
}

#[derive(Clone, Copy)]
pub(crate) struct Wendland {
    norm: f64,
    inv_h: f64,
    c: f64,
}

impl KernelFn for Wendland {
    #[inline(always)]
    fn w(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        let t = 1.0 - 0.5 * q;
        let t2 = t * t;
        self.norm * t2 * t2 * (2.0 * q + 1.0)
    }
    #[inline(always)]
    fn f(&self, r: f64) -> f64 {
        let t = 1.0 - 0.5 * r * self.inv_h;
        self.c * t * t * t
    }
    fn wendland(&self) -> Option<(f64, f64)> {
        Some((self.inv_h, self.c))
    }
}

#[derive(Clone, Copy)]
pub(crate) struct Cubic(Kernel);

impl KernelFn for Cubic {
    #[inline(always)]
    fn w(&self, r: f64) -> f64 {
        self.0.w(r)
    }
    #[inline(always)]
    fn f(&self, r: f64) -> f64 {
        self.0.grad_factor(r)
    }
}

/// Calls `body` with the monomorphised kernel of `k`.
macro_rules! with_kernel {
    ($k:expr, |$kf:ident| $body:expr) => {
        match $k.kind {
            KernelKind::WendlandC2 => {
                let $kf =
                    Wendland { norm: $k.norm(), inv_h: 1.0 / $k.h, c: -5.0 * $k.norm() / ($k.h * $k.h) };
                $body
            }
            KernelKind::CubicSpline => {
                let $kf = Cubic(*$k);
                $body
            }
        }
    };
}

/// A set of fluid particles (the real ones or their periodic images), sorted by cell.
#[derive(Clone, Copy)]
pub(crate) struct FluidSet<'a> {
    pub pos: &'a [Vec3],
    pub vel: &'a [Vec3],
    pub rho: &'a [f64],
    /// p/ρ² \[Pa m⁶/kg²\].
    pub pr: &'a [f64],
    /// 1/ρ \[m³/kg\].
    pub irho: &'a [f64],
    /// Single-precision copy of `pos` for the cut-off test.
    pub c32: Coords32View<'a>,
    /// Akinci surface normals (empty without surface tension).
    pub nrm: &'a [Vec3],
    /// Acceleration of each particle by the adhesion of all walls \[m/s²\] (empty without adhesion), for
    /// the wall pressure.
    pub adh: &'a [Vec3],
    pub grid: &'a NeighbourGrid,
}

/// Boundary particles (with periodic images) sorted by cell, with this step's extrapolated state.
#[derive(Clone, Copy)]
pub(crate) struct WallSet<'a> {
    pub pos: &'a [Vec3],
    /// Wall velocity.
    pub vel: &'a [Vec3],
    /// Canonical index of each entry (entries include periodic images).
    pub src: &'a [u32],
    /// Reference positions and part frames, for wall accelerations.
    pub ref_pos: &'a [Vec3],
    pub ref_normal: &'a [Vec3],
    pub frames: &'a [crate::boundary::Frame],
    /// Dummy velocity for the laminar term.
    pub vvisc: &'a [Vec3],
    pub rho: &'a [f64],
    pub pr: &'a [f64],
    pub irho: &'a [f64],
    pub vol: &'a [f64],
    pub part: &'a [u16],
    /// Single-precision copy of `pos` for the cut-off test.
    pub c32: Coords32View<'a>,
    pub grid: &'a NeighbourGrid,
    /// Per real fluid particle: 1 when some entry lies within the cut-off, as found by this step's
    /// [`wall_state`] (symmetric test, same pairs); the fluid pass then skips the wall query of the others.
    /// Empty when not known.
    pub touched: &'a [AtomicU8],
}

/// Storage of [`WallSet::touched`]: one flag per real fluid particle, set from several threads.
#[derive(Debug, Default)]
pub(crate) struct WallFlags(Vec<AtomicU8>);

impl Clone for WallFlags {
    fn clone(&self) -> Self {
        WallFlags(self.0.iter().map(|f| AtomicU8::new(f.load(Relaxed))).collect())
    }
}

impl WallFlags {
    /// `n` cleared flags.
    pub fn reset(&mut self, n: usize) {
        self.0.resize_with(n, || AtomicU8::new(0));
        self.0.par_iter().with_min_len(4096).for_each(|f| f.store(0, Relaxed));
    }

    pub fn as_slice(&self) -> &[AtomicU8] {
        &self.0
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.0.capacity()
    }
}

/// Constants of one pass.
#[derive(Clone, Debug)]
pub(crate) struct Consts {
    pub dim: Dim,
    pub m: f64,
    pub h: f64,
    pub support: f64,
    /// Squared pair cut-off: (2h)² less 10⁻⁴ of it (see `Simulation::consts`).
    pub r2max: f64,
    pub rho0: f64,
    /// ½ α c₀: Π_ij = −α c₀ μ_ij / ρ̄_ij with 1/ρ̄_ij = ½ (1/ρ_i + 1/ρ_j).
    pub av: f64,
    pub eta2: f64,
    pub nu: f64,
    /// 2 δ h c₀ (0 without density diffusion).
    pub dc: f64,
    /// ρ₀ g / c₀².
    pub gk: Vec3,
    pub g: Vec3,
    /// Akinci cohesion γ (0 without surface tension).
    pub gamma_st: f64,
    /// Factor of the curvature term.
    pub curv: f64,
    /// Adhesion β of each part.
    pub beta: Vec<f64>,
    pub drag: DragParams,
    /// Shifting coefficient A and this step's dt.
    pub shift_a: f64,
    pub dt: f64,
    pub spacing: f64,
    /// W(0).
    pub w0: f64,
    pub eos_b: f64,
    pub eos_gamma: f64,
    pub eos: crate::eos::Tait,
    pub akinci: AkinciSplines,
    /// Normal reach of the wet test per part \[m\]: the wet distance plus
    /// [`crate::boundary::Sampling::wet_reach`].
    pub wet_normal: Vec<f64>,
    /// Squared lateral reach of the wet test \[m²\].
    pub wet_lateral2: f64,
    /// Distance from a wall particle to the surface point it stands for, per part (dp/2 for lattice walls).
    pub wet_offset: Vec<f64>,
    pub slip_free: Vec<bool>,
}

impl Consts {
    /// Surface tension, drag or shifting: terms beyond pressure, viscosity and continuity.
    fn extra(&self) -> bool {
        self.gamma_st > 0.0 || self.drag.enabled || self.shift_a > 0.0
    }
}

/// Per-particle results of the fluid pass, and scratch it needs.
pub(crate) struct FluidOut<'a> {
    pub acc: &'a mut [Vec3],
    pub drho: &'a mut [f64],
    pub near: &'a mut [u32],
    /// Empty when shifting is off.
    pub shift: &'a mut [Vec3],
    /// Liquid fraction Σ V_j W_ij (scratch; length n with drag, else empty).
    pub phi: &'a mut [f64],
    /// Σ V_j ∇W_ij and −Σ V_j x_ij·∇W_ij (scratch; length n with shifting, else empty).
    pub gradc: &'a mut [Vec3],
    pub divr: &'a mut [f64],
}

/// Pass-wide statistics.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PassStats {
    pub max_acc: f64,
    /// Pairs within the support (fluid–fluid counted from both sides, plus fluid–wall).
    pub interactions: u64,
}

const CHUNK: usize = 512;

/// The Akinci normal `n_i = 2h Σ_j (m/ρ_j) ∇W_ij` of every real fluid particle.
pub(crate) fn normals(kernel: &Kernel, c: &Consts, fl: FluidSet, gh: FluidSet, out: &mut [Vec3]) {
    with_kernel!(kernel, |kf| {
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, chunk)| {
            for (o, n) in chunk.iter_mut().enumerate() {
                let i = ci * CHUNK + o;
                let xi = fl.pos[i];
                let mut s = Vec3::ZERO;
                for (ghost, set) in [(false, fl), (true, gh)] {
                    set.grid.for_each_run(xi, |run| {
                        for j in run {
                            if !ghost && j == i {
                                continue;
                            }
                            let dx = xi - set.pos[j];
                            let r2 = dx.length_squared();
                            if r2 < c.r2max {
                                s += dx * (kf.f(r2.sqrt()) * c.m / set.rho[j]);
                            }
                        }
                    });
                }
                *n = s * c.support;
            }
        })
    })
}

/// Akinci et al. (2013) adhesion acceleration of a fluid particle by wall entry `b`,
/// `−β_b ρ₀ V_b A(r) x_ib/r` with `dx = x_i − x_b`, `r = |dx|` below the support (zero without adhesion).
#[inline(always)]
fn adhesion_pair(c: &Consts, wl: &WallSet, b: usize, dx: Vec3, r: f64) -> Vec3 {
    let beta = c.beta[wl.part[b] as usize];
    if beta == 0.0 || r <= 0.0 {
        return Vec3::ZERO;
    }
    dx * (-beta * c.rho0 * wl.vol[b] * c.akinci.adhesion(r) / r)
}

/// The acceleration of every real fluid particle by the adhesion of all walls, `Σ_b` of
/// [`adhesion_pair`], for the wall pressure ([`wall_state`]): the walls push back on the liquid their
/// adhesion pulls on, as they do on its weight.
pub(crate) fn adhesion(c: &Consts, fl: FluidSet, wl: WallSet, out: &mut [Vec3]) {
    out.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, chunk)| {
        for (o, a) in chunk.iter_mut().enumerate() {
            let xi = fl.pos[ci * CHUNK + o];
            let mut s = Vec3::ZERO;
            wl.grid.for_each_run(xi, |run| {
                for b in run {
                    let dx = xi - wl.pos[b];
                    let r2 = dx.length_squared();
                    if r2 < c.r2max {
                        s += adhesion_pair(c, &wl, b, dx, r2.sqrt());
                    }
                }
            });
            *a = s;
        }
    })
}

/// Wall state of every entry of `wl`: Adami et al. (2012) pressure
/// `p_b = (Σ p_f W + (g − a_b)·Σ ρ_f x_bf W + Σ ρ_f (a_adh,f·x_bf) W)/Σ W`, `x_bf = x_b − x_f`
/// (clamped at 0 so walls never pull fluid; adhesion is modelled separately), density from the inverse
/// Tait law, and the dummy velocity `2 v_wall − ṽ` (no slip) or `ṽ` (free slip), ṽ the Shepard average
/// of the fluid velocity. `a_adh,f` is the adhesion acceleration of fluid particle f (`fl.adh`, empty
/// without adhesion): Adami's extrapolation integrates the momentum balance `∇p = ρ (g − a_b)` from the
/// fluid particle to the wall; an adhesive wall adds its own body force to that balance. Without it the
/// wall pressure did not carry the adhesion's pull, the liquid next to the wall had to be compressed to
/// carry it, the density diffusion drained that compression, and the contact line of 3D drops was pulled
/// onto the wall surface (0–0.01 dp instead of dp/2) and broke up (docs/sph.md). Also sets `wet` when a
/// fluid particle is within the wet distance, and `wl.touched` (when not empty) for every real fluid
/// particle within the cut-off of an entry.
#[allow(clippy::too_many_arguments)]
pub(crate) fn wall_state(
    kernel: &Kernel,
    c: &Consts,
    wl: WallSet,
    fl: FluidSet,
    gh: FluidSet,
    rho_b: &mut [f64],
    pr_b: &mut [f64],
    irho_b: &mut [f64],
    vvisc: &mut [Vec3],
    wet: &mut [bool],
) {
    with_kernel!(kernel, |kf| {
        rho_b
            .par_chunks_mut(CHUNK)
            .zip(pr_b.par_chunks_mut(CHUNK))
            .zip(irho_b.par_chunks_mut(CHUNK))
            .zip(vvisc.par_chunks_mut(CHUNK))
            .zip(wet.par_chunks_mut(CHUNK))
            .enumerate()
            .for_each(|(ci, ((((rho_c, pr_c), ir_c), vv_c), wet_c))| {
                let mut cand = Candidates::new();
                for o in 0..rho_c.len() {
                    let b = ci * CHUNK + o;
                    let xb = wl.pos[b];
                    // Wetness is judged from the point of the wall surface the particle stands for:
                    // fluid within the normal reach across the surface and the lateral reach along it.
                    let part = wl.part[b] as usize;
                    let (wet_n, wet_t2) = (c.wet_normal[part], c.wet_lateral2);
                    let normal = wl.frames[part].rot * wl.ref_normal[wl.src[b] as usize];
                    let xs = xb + normal * c.wet_offset[part];
                    let (mut sw, mut spw, mut srx, mut svw) = (0.0, 0.0, Vec3::ZERO, Vec3::ZERO);
                    let mut sad = 0.0;
                    let mut is_wet = false;
                    for (set, touched) in [(&fl, wl.touched), (&gh, &[][..])] {
                        // Neighbours collected without branching, then summed in the same order.
                        let mut sum = |list: &[u32]| {
                            for &j in list {
                                let j = j as usize;
                                if !touched.is_empty() {
                                    touched[j].store(1, Relaxed);
                                }
                                let dx = xb - set.pos[j];
                                let w = kf.w(dx.length_squared().sqrt());
                                sw += w;
                                spw += c.eos.pressure(set.rho[j]) * w;
                                srx += dx * (set.rho[j] * w);
                                if !set.adh.is_empty() {
                                    sad += set.adh[j].dot(dx) * set.rho[j] * w;
                                }
                                svw += set.vel[j] * w;
                                let d = set.pos[j] - xs;
                                let dn = d.dot(normal);
                                is_wet |= dn.abs() < wet_n && d.length_squared() - dn * dn < wet_t2;
                            }
                        };
                        let q = set.c32.query(xb, c.r2max);
                        set.grid.for_each_run(xb, |run| cand.collect(&q, &set.c32, run, &mut sum));
                        sum(cand.take());
                    }
                    let (p, vv) = if sw > 0.0 {
                        let f = &wl.frames[wl.part[b] as usize];
                        let acc_b = f.acceleration(f.to_world(wl.ref_pos[wl.src[b] as usize]));
                        let p = ((spw + (c.g - acc_b).dot(srx) + sad) / sw).max(0.0);
                        let vt = svw / sw;
                        let vv = if c.slip_free[wl.part[b] as usize] { vt } else { 2.0 * wl.vel[b] - vt };
                        (p, vv)
                    } else {
                        (0.0, wl.vel[b])
                    };
                    let rho =
                        if p > 0.0 { c.rho0 * (p / c.eos_b + 1.0).powf(1.0 / c.eos_gamma) } else { c.rho0 };
                    rho_c[o] = rho;
                    pr_c[o] = p / (rho * rho);
                    ir_c[o] = 1.0 / rho;
                    vv_c[o] = vv;
                    wet_c[o] = is_wet;
                }
            })
    })
}

/// Acceleration and density rate of fluid particle `(xi, vi, rhoi, pri)` due to wall entry `b`, given
/// `dx = xi − x_b`, `r2 = |dx|²` below the support.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn wall_pair<K: KernelFn, const EXTRA: bool>(
    kf: &K,
    c: &Consts,
    wl: &WallSet,
    b: usize,
    dx: Vec3,
    r2: f64,
    vi: Vec3,
    irhoi: f64,
    pri: f64,
) -> (Vec3, f64) {
    let r = r2.sqrt();
    let f = kf.f(r);
    let irhob = wl.irho[b];
    let mb = wl.rho[b] * wl.vol[b];
    let inv_d = 1.0 / (r2 + c.eta2);
    let vr = (vi - wl.vel[b]).dot(dx);
    let mu = c.h * vr.min(0.0) * inv_d;
    let s = -(pri + wl.pr[b]) + c.av * mu * (irhoi + irhob);
    let mut acc = dx * (mb * s * f);
    let d = mb * vr * f;
    acc += (vi - wl.vvisc[b]) * (mb * c.nu * (irhoi + irhob) * r2 * f * inv_d);
    if EXTRA && c.gamma_st > 0.0 {
        acc += adhesion_pair(c, wl, b, dx, r);
    }
    (acc, d)
}

/// Accumulators of a contiguous range of fluid particles.
struct Acc<'a> {
    acc: &'a mut [Vec3],
    drho: &'a mut [f64],
    phi: &'a mut [f64],
    gradc: &'a mut [Vec3],
    divr: &'a mut [f64],
}

fn split<T>(v: &mut [T], mid: usize) -> (&mut [T], &mut [T]) {
    if v.is_empty() {
        (&mut [], &mut [])
    } else {
        v.split_at_mut(mid)
    }
}

impl<'a> Acc<'a> {
    fn split_at(self, mid: usize) -> (Acc<'a>, Acc<'a>) {
        let (a0, a1) = self.acc.split_at_mut(mid);
        let (d0, d1) = self.drho.split_at_mut(mid);
        let (p0, p1) = split(self.phi, mid);
        let (g0, g1) = split(self.gradc, mid);
        let (v0, v1) = split(self.divr, mid);
        (
            Acc { acc: a0, drho: d0, phi: p0, gradc: g0, divr: v0 },
            Acc { acc: a1, drho: d1, phi: p1, gradc: g1, divr: v1 },
        )
    }
}

/// The fluid pass: acceleration, density rate, wall-proximity mask and shifting displacement of every
/// real fluid particle.
///
/// Fluid–fluid pairs are evaluated once and applied to both particles (Newton's third law). To do that
/// in parallel without locks and with a summation order independent of the thread count, the sorted
/// particles are cut into blocks of two cell layers (cells are half a support, so a pair spans at most
/// two layers upwards): block k only writes to blocks k and k+1, so all even blocks run in parallel, then
/// all odd blocks. Periodic images and walls are then gathered per particle, and gravity, drag and
/// shifting added.
pub(crate) fn fluid_pass(
    kernel: &Kernel,
    c: &Consts,
    fl: FluidSet,
    gh: FluidSet,
    wl: WallSet,
    out: FluidOut,
) -> PassStats {
    with_kernel!(kernel, |kf| {
        if c.extra() {
            fluid_pass_k::<_, true>(&kf, c, fl, gh, wl, out)
        } else {
            fluid_pass_k::<_, false>(&kf, c, fl, gh, wl, out)
        }
    })
}

/// Terms of one fluid pair: acceleration of i (j gets the opposite) and the density rates of i and j.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_terms<K: KernelFn, const EXTRA: bool>(
    kf: &K,
    c: &Consts,
    dx: Vec3,
    r2: f64,
    vij: Vec3,
    (rhoi, irhoi, pri): (f64, f64, f64),
    (rhoj, irhoj, prj): (f64, f64, f64),
    nij: Vec3,
) -> (Vec3, f64, f64, f64) {
    let r = r2.sqrt();
    let f = kf.f(r);
    let inv_d = 1.0 / (r2 + c.eta2);
    let vr = vij.dot(dx);
    let mu = c.h * vr.min(0.0) * inv_d;
    let s = -(pri + prj) + c.av * mu * (irhoi + irhoj);
    let mut a = dx * (c.m * s * f);
    let cont = c.m * vr * f;
    let (mut di, mut dj) = (cont, cont);
    if c.dc > 0.0 {
        let psi = c.dc * (rhoi - rhoj - c.gk.dot(dx)) * f * c.m;
        di += psi * irhoj;
        dj -= psi * irhoi;
    }
    a += vij * (c.m * c.nu * (irhoi + irhoj) * r2 * f * inv_d);
    if EXTRA && c.gamma_st > 0.0 && r > 0.0 {
        let kij = 2.0 * c.rho0 / (rhoi + rhoj);
        let coh = c.akinci.cohesion(r);
        a -= dx * (c.gamma_st * kij * c.m * coh / r);
        a -= nij * (c.gamma_st * kij * c.curv);
    }
    (a, di, dj, f)
}

fn fluid_pass_k<K: KernelFn, const EXTRA: bool>(
    kf: &K,
    c: &Consts,
    fl: FluidSet,
    gh: FluidSet,
    wl: WallSet,
    out: FluidOut,
) -> PassStats {
    let FluidOut { acc, drho, near, shift, phi, gradc, divr } = out;
    acc.par_iter_mut().for_each(|a| *a = Vec3::ZERO);
    drho.par_iter_mut().for_each(|d| *d = 0.0);
    phi.par_iter_mut().for_each(|d| *d = 0.0);
    gradc.par_iter_mut().for_each(|d| *d = Vec3::ZERO);
    divr.par_iter_mut().for_each(|d| *d = 0.0);
    // Pairs, even blocks then odd blocks.
    let layers = fl.grid.layers();
    let nblocks = layers.div_ceil(2);
    let mut pairs = 0u64;
    for parity in 0..2usize {
        if nblocks <= parity {
            break;
        }
        let first = fl.grid.layer_start(2 * parity);
        let accs =
            Acc { acc: &mut *acc, drho: &mut *drho, phi: &mut *phi, gradc: &mut *gradc, divr: &mut *divr };
        let (_, tail) = accs.split_at(first);
        let count = (nblocks - parity).div_ceil(2);
        pairs += tiles::<K, EXTRA>(kf, c, &fl, parity, count, tail, first);
    }
    let (phi, gradc, divr) = (&*phi, &*gradc, &*divr);
    // Images, walls and body forces, per particle.
    let shifting = !shift.is_empty();
    let process = |ci: usize,
                   acc_c: &mut [Vec3],
                   d_c: &mut [f64],
                   near_c: &mut [u32],
                   mut shift_c: Option<&mut [Vec3]>| {
        let mut st = PassStats::default();
        let mut scratch = WallScratch { cand: Candidates::new(), batch: Batch::new() };
        for o in 0..acc_c.len() {
            let i = ci * CHUNK + o;
            let r = finish_particle::<K, EXTRA>(
                kf,
                c,
                i,
                &fl,
                &gh,
                &wl,
                acc_c[o],
                d_c[o],
                phi,
                gradc,
                divr,
                &mut scratch,
            );
            acc_c[o] = r.acc;
            d_c[o] = r.drho;
            near_c[o] = r.near;
            if let Some(s) = shift_c.as_deref_mut() {
                s[o] = r.shift;
            }
            st.max_acc = st.max_acc.max(r.acc.length());
            st.interactions += r.interactions;
        }
        st
    };
    let merge = |a: PassStats, b: PassStats| PassStats {
        max_acc: a.max_acc.max(b.max_acc),
        interactions: a.interactions + b.interactions,
    };
    let chunks = acc.par_chunks_mut(CHUNK).zip(drho.par_chunks_mut(CHUNK)).zip(near.par_chunks_mut(CHUNK));
    let mut st = if shifting {
        chunks
            .zip(shift.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(ci, (((a, d), n), s))| process(ci, a, d, n, Some(s)))
            .reduce(PassStats::default, merge)
    } else {
        chunks
            .enumerate()
            .map(|(ci, ((a, d), n))| process(ci, a, d, n, None))
            .reduce(PassStats::default, merge)
    };
    st.interactions += 2 * pairs;
    st
}

/// Runs the blocks `k0, k0 + 2, …` (`count` of them, one parity) in parallel; `out` covers sorted
/// indices from `offset` on.
#[allow(clippy::too_many_arguments)]
fn tiles<K: KernelFn, const EXTRA: bool>(
    kf: &K,
    c: &Consts,
    fl: &FluidSet,
    k0: usize,
    count: usize,
    out: Acc,
    offset: usize,
) -> u64 {
    let layers = fl.grid.layers();
    if count == 1 {
        let home = fl.grid.layer_start(2 * k0)..fl.grid.layer_start((2 * k0 + 2).min(layers));
        let end = fl.grid.layer_start((2 * k0 + 4).min(layers));
        let (mut mine, _) = out.split_at(end - offset);
        return pair_block::<K, EXTRA>(kf, c, fl, home, offset, &mut mine);
    }
    let mid = count / 2;
    let k_mid = k0 + 2 * mid;
    let cut = fl.grid.layer_start(2 * k_mid);
    let (left, right) = out.split_at(cut - offset);
    let (a, b) = rayon::join(
        || tiles::<K, EXTRA>(kf, c, fl, k0, mid, left, offset),
        || tiles::<K, EXTRA>(kf, c, fl, k_mid, count - mid, right, cut),
    );
    a + b
}

/// All pairs (i, j > i) with i in `home`, applied to both particles.
fn pair_block<K: KernelFn, const EXTRA: bool>(
    kf: &K,
    c: &Consts,
    fl: &FluidSet,
    home: std::ops::Range<usize>,
    offset: usize,
    out: &mut Acc,
) -> u64 {
    // Neighbours are first collected without branching (see [`Candidates`]), then evaluated in a loop
    // free of unpredictable branches.
    let mut cand = Candidates::new();
    let mut batch = Batch::new();
    let mut pairs = 0u64;
    for i in home {
        let xi = fl.pos[i];
        let mut st = PairState::new(fl, i, c);
        let q = fl.c32.query(xi, c.r2max);
        fl.grid.for_each_run_after(xi, |run| {
            cand.collect(&q, &fl.c32, run.start.max(i + 1)..run.end, |list| {
                pairs += pair_list::<K, EXTRA>(kf, c, fl, list, &mut st, offset, out, &mut batch);
            });
        });
        pairs += pair_list::<K, EXTRA>(kf, c, fl, cand.take(), &mut st, offset, out, &mut batch);
        st.store(i - offset, out);
    }
    pairs
}

/// Running sums of the home particle of [`pair_block`].
struct PairState {
    xi: Vec3,
    vi: Vec3,
    si: (f64, f64, f64),
    ni: Vec3,
    vol_i: f64,
    ai: Vec3,
    di: f64,
    phi_i: f64,
    gc_i: Vec3,
    dv_i: f64,
}

impl Batch {
    fn new() -> Self {
        Batch {
            dx: [0.0; BATCH],
            dy: [0.0; BATCH],
            dz: [0.0; BATCH],
            vx: [0.0; BATCH],
            vy: [0.0; BATCH],
            vz: [0.0; BATCH],
            drho: [0.0; BATCH],
            irj: [0.0; BATCH],
            prj: [0.0; BATCH],
            ax: [0.0; BATCH],
            ay: [0.0; BATCH],
            az: [0.0; BATCH],
            ci: [0.0; BATCH],
            cj: [0.0; BATCH],
        }
    }
}

impl PairState {
    #[inline(always)]
    fn new(fl: &FluidSet, i: usize, c: &Consts) -> Self {
        let si = (fl.rho[i], fl.irho[i], fl.pr[i]);
        PairState {
            xi: fl.pos[i],
            vi: fl.vel[i],
            si,
            ni: if c.gamma_st > 0.0 && !fl.nrm.is_empty() { fl.nrm[i] } else { Vec3::ZERO },
            vol_i: c.m * si.1,
            ai: Vec3::ZERO,
            di: 0.0,
            phi_i: 0.0,
            gc_i: Vec3::ZERO,
            dv_i: 0.0,
        }
    }

    #[inline(always)]
    fn store(&self, o: usize, out: &mut Acc) {
        out.acc[o] += self.ai;
        out.drho[o] += self.di;
        if !out.phi.is_empty() {
            out.phi[o] += self.phi_i;
        }
        if !out.gradc.is_empty() {
            out.gradc[o] += self.gc_i;
            out.divr[o] += self.dv_i;
        }
    }
}

/// Evaluates the pairs (home, j) for the neighbours `list` (all within the support) and applies them.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn pair_list<K: KernelFn, const EXTRA: bool>(
    kf: &K,
    c: &Consts,
    fl: &FluidSet,
    list: &[u32],
    st: &mut PairState,
    offset: usize,
    out: &mut Acc,
    batch: &mut Batch,
) -> u64 {
    if !EXTRA {
        if let Some((inv_h, cw)) = kf.wendland() {
            batch_pairs(c, fl, list, st, offset, out, inv_h, cw, batch);
            return list.len() as u64;
        }
    }
    let need_phi = EXTRA && c.drag.enabled;
    let need_shift = EXTRA && c.shift_a > 0.0;
    let surface = EXTRA && c.gamma_st > 0.0;
    for &j in list {
        let j = j as usize;
        let dx = st.xi - fl.pos[j];
        let r2 = dx.length_squared();
        let sj = (fl.rho[j], fl.irho[j], fl.pr[j]);
        let nij = if surface { st.ni - fl.nrm[j] } else { Vec3::ZERO };
        let (a, dd_i, dd_j, f) = pair_terms::<K, EXTRA>(kf, c, dx, r2, st.vi - fl.vel[j], st.si, sj, nij);
        let o = j - offset;
        st.ai += a;
        out.acc[o] -= a;
        st.di += dd_i;
        out.drho[o] += dd_j;
        if need_phi {
            let w = kf.w(r2.sqrt());
            st.phi_i += c.m * sj.1 * w;
            out.phi[o] += st.vol_i * w;
        }
        if need_shift {
            let vol_j = c.m * sj.1;
            st.gc_i += dx * (vol_j * f);
            out.gradc[o] -= dx * (st.vol_i * f);
            st.dv_i -= vol_j * r2 * f;
            out.divr[o] -= st.vol_i * r2 * f;
        }
    }
    list.len() as u64
}

/// Neighbour batch of one home particle in single precision, laid out so that the pair terms compile to
/// packed SIMD instructions.
struct Batch {
    dx: [f32; BATCH],
    dy: [f32; BATCH],
    dz: [f32; BATCH],
    vx: [f32; BATCH],
    vy: [f32; BATCH],
    vz: [f32; BATCH],
    drho: [f32; BATCH],
    irj: [f32; BATCH],
    prj: [f32; BATCH],
    ax: [f32; BATCH],
    ay: [f32; BATCH],
    az: [f32; BATCH],
    ci: [f32; BATCH],
    cj: [f32; BATCH],
}

/// `n` (at most [`BATCH`]) rounded up to a multiple of 4, the lanes the compiler processes per iteration
/// of the vectorised pair terms on baseline x86-64 (SSE2): the loop then ends without a scalar remainder.
#[inline(always)]
fn padded(n: usize) -> usize {
    ((n + 3) & !3).min(BATCH)
}

/// Pressure, viscosity, continuity and δ-SPH terms for a list of neighbours, Wendland kernel, evaluated
/// in single precision (positions and velocities enter as differences computed in double precision; sums
/// are kept in double precision). Same terms as [`pair_terms`] without the extras.
// Index loops up to n = min(chunk length, BATCH): the compiler then drops every bounds check of the batch
// arrays (an iterator over the chunk measured 0.3–1.3 % more instructions per step).
#[allow(clippy::too_many_arguments, clippy::needless_range_loop)]
fn batch_pairs(
    c: &Consts,
    fl: &FluidSet,
    list: &[u32],
    st: &mut PairState,
    offset: usize,
    out: &mut Acc,
    inv_h: f64,
    cw: f64,
    b: &mut Batch,
) {
    // Arrays cut to equal lengths: one bounds test of a neighbour index then covers all of them.
    let np = fl.pos.len();
    let (pos, vel, rho, irho, pr) = (fl.pos, &fl.vel[..np], &fl.rho[..np], &fl.irho[..np], &fl.pr[..np]);
    let (xi, vi, rhoi) = (st.xi, st.vi, st.si.0);
    for chunk in list.chunks(BATCH) {
        let n = chunk.len().min(BATCH);
        // Gather.
        for t in 0..n {
            let j = chunk[t] as usize;
            let d = xi - pos[j];
            let v = vi - vel[j];
            b.dx[t] = d.x as f32;
            b.dy[t] = d.y as f32;
            b.dz[t] = d.z as f32;
            b.vx[t] = v.x as f32;
            b.vy[t] = v.y as f32;
            b.vz[t] = v.z as f32;
            b.drho[t] = (rhoi - rho[j]) as f32;
            b.irj[t] = irho[j] as f32;
            b.prj[t] = pr[j] as f32;
        }
        // Pair terms, vectorised.
        let (inv_h, cw, h) = (inv_h as f32, cw as f32, c.h as f32);
        let (eta2, av, m, nu, dc) = (c.eta2 as f32, c.av as f32, c.m as f32, c.nu as f32, c.dc as f32);
        let (gx, gy, gz) = (c.gk.x as f32, c.gk.y as f32, c.gk.z as f32);
        let (iri, pri) = (st.si.1 as f32, st.si.2 as f32);
        // Rounded up to whole vectors so that no scalar remainder loop runs: the lanes past n hold finite
        // values of earlier pairs (or zeros), whose results are never read.
        for t in 0..padded(n) {
            let (dx, dy, dz) = (b.dx[t], b.dy[t], b.dz[t]);
            let (vx, vy, vz) = (b.vx[t], b.vy[t], b.vz[t]);
            let r2 = dx * dx + dy * dy + dz * dz;
            let r = r2.sqrt();
            let q = 1.0 - 0.5 * r * inv_h;
            let f = cw * q * q * q;
            let inv_d = 1.0 / (r2 + eta2);
            let vr = vx * dx + vy * dy + vz * dz;
            let irj = b.irj[t];
            let mu = h * vr.min(0.0) * inv_d;
            let s = -(pri + b.prj[t]) + av * mu * (iri + irj);
            let ms = m * s * f;
            let lam = m * nu * (iri + irj) * r2 * f * inv_d;
            b.ax[t] = dx * ms + vx * lam;
            b.ay[t] = dy * ms + vy * lam;
            b.az[t] = dz * ms + vz * lam;
            let cont = m * vr * f;
            let psi = dc * (b.drho[t] - (gx * dx + gy * dy + gz * dz)) * f * m;
            b.ci[t] = cont + psi * irj;
            b.cj[t] = cont - psi * iri;
        }
        // Scatter. The home sums live in locals: kept in `st`, they would be stored and reloaded for every
        // neighbour (the compiler cannot rule out that `out` aliases them).
        let (mut ax, mut ay, mut az, mut di) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let no = out.acc.len();
        let (acc_o, drho_o) = (&mut *out.acc, &mut out.drho[..no]);
        for t in 0..n {
            let o = chunk[t] as usize - offset;
            let a = Vec3::new(b.ax[t] as f64, b.ay[t] as f64, b.az[t] as f64);
            ax += a.x;
            ay += a.y;
            az += a.z;
            acc_o[o] -= a;
            di += b.ci[t] as f64;
            drho_o[o] += b.cj[t] as f64;
        }
        st.ai += Vec3::new(ax, ay, az);
        st.di += di;
    }
}

/// Buffers of the batched wall interactions.
struct WallScratch {
    cand: Candidates,
    batch: Batch,
}

/// Wall interactions of one fluid particle, Wendland kernel, without extras: neighbours collected without
/// branching, then pressure, viscosity and continuity evaluated in single precision (as [`wall_pair`]).
/// Returns the acceleration, density rate, part mask and number of wall neighbours.
#[allow(clippy::too_many_arguments)]
fn walls_batched(
    c: &Consts,
    wl: &WallSet,
    xi: Vec3,
    vi: Vec3,
    si: (f64, f64, f64),
    inv_h: f64,
    cw: f64,
    sc: &mut WallScratch,
) -> (Vec3, f64, u32, u64) {
    let mut acc = Vec3::ZERO;
    let mut d = 0.0;
    let mut near = 0u32;
    let mut count = 0u64;
    let flush = |list: &[u32], b: &mut Batch, acc: &mut Vec3, d: &mut f64, near: &mut u32| {
        for (t, &j) in list.iter().enumerate() {
            let j = j as usize;
            let dx = xi - wl.pos[j];
            let vw = vi - wl.vel[j];
            let vv = vi - wl.vvisc[j];
            b.dx[t] = dx.x as f32;
            b.dy[t] = dx.y as f32;
            b.dz[t] = dx.z as f32;
            b.vx[t] = vw.x as f32;
            b.vy[t] = vw.y as f32;
            b.vz[t] = vw.z as f32;
            // Reuse the remaining lanes: dummy-velocity difference and wall mass.
            b.ax[t] = vv.x as f32;
            b.ay[t] = vv.y as f32;
            b.az[t] = vv.z as f32;
            b.drho[t] = (wl.rho[j] * wl.vol[j]) as f32;
            b.irj[t] = wl.irho[j] as f32;
            b.prj[t] = wl.pr[j] as f32;
            let part = wl.part[j] as u32;
            *near |= if part < 31 { 1 << part } else { 1 << 31 };
        }
        let (inv_h, cw, h) = (inv_h as f32, cw as f32, c.h as f32);
        let (eta2, av, nu) = (c.eta2 as f32, c.av as f32, c.nu as f32);
        let (iri, pri) = (si.1 as f32, si.2 as f32);
        let m = list.len();
        // Whole vectors, as in `batch_pairs`.
        for t in 0..padded(m.min(BATCH)) {
            let (dx, dy, dz) = (b.dx[t], b.dy[t], b.dz[t]);
            let r2 = dx * dx + dy * dy + dz * dz;
            let r = r2.sqrt();
            let q = 1.0 - 0.5 * r * inv_h;
            let f = cw * q * q * q;
            let inv_d = 1.0 / (r2 + eta2);
            let vr = b.vx[t] * dx + b.vy[t] * dy + b.vz[t] * dz;
            let irb = b.irj[t];
            let mb = b.drho[t];
            let mu = h * vr.min(0.0) * inv_d;
            let s = -(pri + b.prj[t]) + av * mu * (iri + irb);
            let ms = mb * s * f;
            let lam = mb * nu * (iri + irb) * r2 * f * inv_d;
            b.vx[t] = dx * ms + b.ax[t] * lam;
            b.vy[t] = dy * ms + b.ay[t] * lam;
            b.vz[t] = dz * ms + b.az[t] * lam;
            b.ci[t] = mb * vr * f;
        }
        for t in 0..m.min(BATCH) {
            *acc += Vec3::new(b.vx[t] as f64, b.vy[t] as f64, b.vz[t] as f64);
            *d += b.ci[t] as f64;
        }
    };
    let WallScratch { cand, batch } = sc;
    let mut flush_count = |list: &[u32]| {
        flush(list, batch, &mut acc, &mut d, &mut near);
        count += list.len() as u64;
    };
    let q = wl.c32.query(xi, c.r2max);
    wl.grid.for_each_run(xi, |run| cand.collect(&q, &wl.c32, run, &mut flush_count));
    flush_count(cand.take());
    (acc, d, near, count)
}

struct ParticleResult {
    acc: Vec3,
    drho: f64,
    near: u32,
    shift: Vec3,
    interactions: u64,
}

/// Adds periodic-image and wall interactions, gravity, drag and shifting to the pair sums of particle i.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn finish_particle<K: KernelFn, const EXTRA: bool>(
    kf: &K,
    c: &Consts,
    i: usize,
    fl: &FluidSet,
    gh: &FluidSet,
    wl: &WallSet,
    pair_acc: Vec3,
    pair_drho: f64,
    phi_pairs: &[f64],
    gradc_pairs: &[Vec3],
    divr_pairs: &[f64],
    scratch: &mut WallScratch,
) -> ParticleResult {
    let xi = fl.pos[i];
    let vi = fl.vel[i];
    let si = (fl.rho[i], fl.irho[i], fl.pr[i]);
    let st = EXTRA && c.gamma_st > 0.0;
    let ni = if st { fl.nrm[i] } else { Vec3::ZERO };
    let need_phi = EXTRA && c.drag.enabled;
    let need_shift = EXTRA && c.shift_a > 0.0;
    let mut acc = pair_acc;
    let mut d = pair_drho;
    let mut n_int = 0u64;
    let mut phi = if need_phi { phi_pairs[i] } else { 0.0 };
    let mut gradc = if need_shift { gradc_pairs[i] } else { Vec3::ZERO };
    let mut divr = if need_shift { divr_pairs[i] } else { 0.0 };
    gh.grid.for_each_run(xi, |run| {
        for j in run {
            let dx = xi - gh.pos[j];
            let r2 = dx.length_squared();
            if r2 >= c.r2max {
                continue;
            }
            n_int += 1;
            let sj = (gh.rho[j], gh.irho[j], gh.pr[j]);
            let nij = if st { ni - gh.nrm[j] } else { Vec3::ZERO };
            let (a, dd, _, f) = pair_terms::<K, EXTRA>(kf, c, dx, r2, vi - gh.vel[j], si, sj, nij);
            acc += a;
            d += dd;
            if need_phi {
                phi += c.m * sj.1 * kf.w(r2.sqrt());
            }
            if need_shift {
                gradc += dx * (c.m * sj.1 * f);
                divr -= c.m * sj.1 * r2 * f;
            }
        }
    });
    let mut near = 0u32;
    if !EXTRA {
        if let Some((inv_h, cw)) = kf.wendland() {
            // No wall entry within the cut-off (known from the wall pass): nothing to add.
            let none = !wl.touched.is_empty() && wl.touched[i].load(Relaxed) == 0;
            let (a, dd, nr, cnt) = if none {
                (Vec3::ZERO, 0.0, 0, 0)
            } else {
                walls_batched(c, wl, xi, vi, si, inv_h, cw, scratch)
            };
            acc += a;
            d += dd;
            near = nr;
            n_int += cnt;
            acc += c.g;
            return ParticleResult { acc, drho: d, near, shift: Vec3::ZERO, interactions: n_int };
        }
    }
    wl.grid.for_each_run(xi, |run| {
        for b in run {
            let dx = xi - wl.pos[b];
            let r2 = dx.length_squared();
            if r2 >= c.r2max {
                continue;
            }
            n_int += 1;
            let (a, dd) = wall_pair::<K, EXTRA>(kf, c, wl, b, dx, r2, vi, si.1, si.2);
            acc += a;
            d += dd;
            let part = wl.part[b] as u32;
            near |= if part < 31 { 1 << part } else { 1 << 31 };
            if need_phi || need_shift {
                let r = r2.sqrt();
                if need_phi {
                    phi += wl.vol[b] * kf.w(r);
                }
                if need_shift {
                    let f = kf.f(r);
                    gradc += dx * (wl.vol[b] * f);
                    divr -= wl.vol[b] * r2 * f;
                }
            }
        }
    });
    acc += c.g;
    if need_phi {
        acc += drag_acceleration(c, vi, si.0, phi + c.m * si.1 * c.w0);
    }
    let mut shift = Vec3::ZERO;
    if need_shift {
        // Lind et al. (2012) / Skillen et al. (2013): δr = −A h |v| dt ∇C, off at the free surface
        // (∇·r below 0.8 of its bulk value d), limited to 0.1 dp.
        let bulk = c.dim.count() as f64;
        if divr > 0.8 * bulk {
            shift = gradc * (-c.shift_a * c.h * vi.length() * c.dt);
            let l = shift.length();
            let cap = 0.1 * c.spacing;
            if l > cap {
                shift *= cap / l;
            }
        }
    }
    ParticleResult { acc, drho: d, near, shift, interactions: n_int }
}

/// Air-drag acceleration \[m/s²\] of a fluid particle (see [`crate::drag`]).
#[inline]
fn drag_acceleration(c: &Consts, v: Vec3, rho: f64, phi: f64) -> Vec3 {
    let vol = c.m / rho;
    crate::drag::acceleration(&c.drag, c.dim, v, c.m, vol, phi, vol * c.w0)
}

/// Force of the fluid on every wall entry \[N, N/m in 2D\] (the exact opposite of what the fluid pass
/// applies to the fluid, without gravity).
pub(crate) fn wall_loads(
    kernel: &Kernel,
    c: &Consts,
    wl: WallSet,
    fl: FluidSet,
    gh: FluidSet,
    out: &mut [Vec3],
) {
    let extra = c.extra();
    with_kernel!(kernel, |kf| {
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(ci, chunk)| {
            for (o, fo) in chunk.iter_mut().enumerate() {
                let b = ci * CHUNK + o;
                let xb = wl.pos[b];
                let mut f = Vec3::ZERO;
                for set in [fl, gh] {
                    set.grid.for_each_run(xb, |run| {
                        for j in run {
                            let dx = set.pos[j] - xb;
                            let r2 = dx.length_squared();
                            if r2 < c.r2max {
                                let (a, _) = if extra {
                                    wall_pair::<_, true>(
                                        &kf,
                                        c,
                                        &wl,
                                        b,
                                        dx,
                                        r2,
                                        set.vel[j],
                                        set.irho[j],
                                        set.pr[j],
                                    )
                                } else {
                                    wall_pair::<_, false>(
                                        &kf,
                                        c,
                                        &wl,
                                        b,
                                        dx,
                                        r2,
                                        set.vel[j],
                                        set.irho[j],
                                        set.pr[j],
                                    )
                                };
                                f -= a * c.m;
                            }
                        }
                    });
                }
                *fo = f;
            }
        })
    })
}

/// Shepard-interpolated pressure and velocity at a point (None where no fluid is within the support).
pub(crate) fn probe(kernel: &Kernel, c: &Consts, fl: FluidSet, gh: FluidSet, x: Vec3) -> Option<(f64, Vec3)> {
    let (mut sw, mut sp, mut sv) = (0.0, 0.0, Vec3::ZERO);
    for set in [fl, gh] {
        set.grid.for_each_run(x, |run| {
            for j in run {
                let r2 = (x - set.pos[j]).length_squared();
                if r2 < c.r2max {
                    let w = kernel.w(r2.sqrt()) * c.m / set.rho[j];
                    sw += w;
                    sp += w * c.eos.pressure(set.rho[j]);
                    sv += set.vel[j] * w;
                }
            }
        });
    }
    (sw > 0.0).then(|| (sp / sw, sv / sw))
}
