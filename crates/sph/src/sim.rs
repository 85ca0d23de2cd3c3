//! The simulation state, its set-up and the time step.
//!
//! **Time integration** — velocity Verlet (kick–drift–kick) with one force evaluation per step:
//! `x ← x + dt (v + ½dt a)`, `v* = v + dt a`, `ρ* = ρ + dt Dρ`; forces `a'`, `Dρ'` are evaluated at
//! `(x, v*, ρ*)`; then `v ← v* + ½dt (a' − a)`, `ρ ← ρ* + ½dt (Dρ' − Dρ)`. For velocity-independent forces
//! this is the symplectic velocity Verlet scheme; velocity-dependent terms (viscosity, continuity) use the
//! predicted velocity.
//!
//! **Time step** (logged with every output) — `dt = min(C h/(c_max + v_max), C √(h/a_max), 0.125 h²/ν,
//! dt_max)` with the Courant number `C` (Monaghan 1992; Crespo et al. 2015), `c_max` the largest Tait sound
//! speed, `v_max` the largest fluid speed plus the largest wall speed.
//!
//! **Each step**: predictor and drift → wall kinematics at the new time → crossing guard → periodic wrap →
//! removal of particles outside the domain box or the density window (counted, never fatal) and a
//! finiteness check (a blow-up stops with the particle, step and time) → re-sort by cell → periodic images
//! → wall state (Adami extrapolation, wetting) → surface normals (with surface tension) → forces →
//! corrector → next time step.

use crate::boundary::{
    block_lattice, box_surface, mesh_samples, solid_samples, tank_lattice, Boundary, Faces, Frame, Sampling,
    Slip,
};
use crate::candidates::Coords32;
use crate::error::SphError;
use crate::fill::{fill_box, flood_fill, Clearance};
use crate::fluid::{Fluid, PermuteScratch};
use crate::guard::guard_particle;
use crate::kernel::{Dim, Kernel};
use crate::local_walls::{point_gap, LocalWalls};
use crate::neighbours::NeighbourGrid;
use crate::params::SphParams;
use crate::pass::{self, Consts, FluidOut, FluidSet, PassStats, WallSet};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::comm::{Comm, SERIAL};
use spatter_core::mesh::TriMesh;
use spatter_core::motion::{KinematicTree, Motion};
use spatter_core::{Aabb, Vec3};
use std::mem::take;

#[path = "decomp.rs"]
mod decomp;
pub use decomp::{DEFAULT_REBALANCE, REBALANCE_CHECK_STEPS};

/// Wall properties shared by every kind of part.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WallOptions {
    /// Akinci adhesion β as a multiple of the cohesion γ (0: none).
    pub adhesion: f64,
    pub slip: Slip,
}

impl Default for WallOptions {
    fn default() -> Self {
        WallOptions { adhesion: 0.0, slip: Slip::NoSlip }
    }
}

/// Particles removed so far, by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Removed {
    pub outside_domain: u64,
    pub density_window: u64,
}

/// Numbers of the last step.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StepStats {
    pub max_speed: f64,
    pub max_acc: f64,
    pub max_density_ratio: f64,
    pub min_density_ratio: f64,
    pub interactions: u64,
    /// Particles stopped by the crossing guard in the last step.
    pub guard_hits: u64,
    pub dt_acoustic: f64,
    pub dt_force: f64,
    pub dt_viscous: f64,
    /// Time step of the last step taken \[s\].
    pub dt_taken: f64,
}

/// Fluid force and torque on one part \[N, N m; per metre of depth in 2D\].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PartLoad {
    pub force: Vec3,
    /// About the part's torque point (moving with the part).
    pub torque: Vec3,
}

/// Wall-clock seconds spent in the phases of [`Simulation::step`] since the simulation was created or
/// loaded (not checkpointed).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhaseTimes {
    pub predict: f64,
    pub walls_guard: f64,
    pub sort: f64,
    pub wall_state: f64,
    pub forces: f64,
    pub correct: f64,
}

/// Scratch buffers rebuilt from the state; never part of a checkpoint.
#[derive(Clone, Debug, Default)]
struct Work {
    grid: NeighbourGrid,
    perm_buf: Vec<u32>,
    perm_u: Vec<u32>,
    pr: Vec<f64>,
    irho: Vec<f64>,
    /// Single-precision positions of the sorted fluid, ghosts and walls for the cut-off test.
    c32: Coords32,
    g_c32: Coords32,
    w_c32: Coords32,
    nrm: Vec<Vec3>,
    acc_new: Vec<Vec3>,
    drho_new: Vec<f64>,
    phi: Vec<f64>,
    gradc: Vec<Vec3>,
    divr: Vec<f64>,
    keep: Vec<bool>,
    frames_old: Vec<Frame>,
    // Periodic images of fluid particles.
    g_src: Vec<u32>,
    g_pos: Vec<Vec3>,
    g_vel: Vec<Vec3>,
    g_rho: Vec<f64>,
    g_pr: Vec<f64>,
    g_irho: Vec<f64>,
    g_nrm: Vec<Vec3>,
    /// Adhesion accelerations of the fluid and its periodic images (empty without adhesion).
    adh: Vec<Vec3>,
    g_adh: Vec<Vec3>,
    g_grid: NeighbourGrid,
    g_tmp_u: Vec<u32>,
    g_tmp_v: Vec<Vec3>,
    // Wall particles (with periodic images) in cell order.
    w_src: Vec<u32>,
    w_ghost: Vec<bool>,
    w_pos: Vec<Vec3>,
    w_vel: Vec<Vec3>,
    w_vvisc: Vec<Vec3>,
    w_rho: Vec<f64>,
    w_pr: Vec<f64>,
    w_irho: Vec<f64>,
    w_vol: Vec<f64>,
    w_part: Vec<u16>,
    w_wet: Vec<bool>,
    w_load: Vec<Vec3>,
    w_grid: NeighbourGrid,
    w_tmp_u: Vec<u32>,
    w_tmp_b: Vec<bool>,
    /// Fluid particles with a wall entry within the cut-off (set by the wall pass).
    w_touched: pass::WallFlags,
    /// On several ranks: the wall particles within one support of this rank's wall region.
    w_local: LocalWalls,
    /// Boundary size when the wall set was built.
    w_built_len: usize,
    /// The wall region the set was selected for (`None`: one rank, the whole boundary).
    w_region: Option<Option<Aabb>>,
    /// Boundary indices of the set being replaced (scratch of the wall set's rebuild on several ranks).
    w_left: Vec<u32>,
    walls_built: bool,
    ready: bool,
    times: PhaseTimes,
}

/// A weakly compressible SPH simulation.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Simulation {
    pub params: SphParams,
    pub tree: KinematicTree,
    pub fluid: Fluid,
    pub boundary: Boundary,
    /// Particles leaving this box are removed (periodic axes wrap instead).
    pub domain: Aabb,
    pub periodic: [bool; 3],
    pub time: f64,
    pub steps: u64,
    /// Time step of the next step \[s\].
    pub dt: f64,
    pub removed: Removed,
    pub next_id: u32,
    pub last: StepStats,
    /// Heights of horizontal planes counting volume crossing them (see [`Simulation::set_flux_planes`]).
    pub flux_planes: Vec<f64>,
    /// Volume that crossed each plane upwards / downwards since the counters were reset \[m³, m² in 2D\].
    pub flux_up: Vec<f64>,
    pub flux_down: Vec<f64>,
    initialized: bool,
    #[serde(skip)]
    work: Work,
    /// This rank's share of space when the run is split over several ranks (None on one rank).
    #[serde(skip)]
    decomp: Option<decomp::Decomp>,
    /// On several ranks: the load imbalance (most particles on a rank over the mean) above which the
    /// split is rebuilt from where the particles are ([`Self::set_rebalance`]); `None` never. Not part of
    /// a checkpoint: the scenario sets it again on a resume.
    #[serde(skip, default = "decomp::default_rebalance")]
    rebalance: Option<f64>,
}

impl Simulation {
    pub fn new(params: SphParams) -> Self {
        Simulation {
            params,
            tree: KinematicTree::new(),
            fluid: Fluid::default(),
            boundary: Boundary::default(),
            domain: Aabb::EMPTY,
            periodic: [false; 3],
            time: 0.0,
            steps: 0,
            dt: 0.0,
            removed: Removed::default(),
            next_id: 0,
            last: StepStats::default(),
            flux_planes: Vec::new(),
            flux_up: Vec::new(),
            flux_down: Vec::new(),
            initialized: false,
            work: Work::default(),
            decomp: None,
            rebalance: decomp::default_rebalance(),
        }
    }

    pub fn kernel(&self) -> Kernel {
        self.params.kernel()
    }

    /// Default number of lattice wall layers: enough to fill the kernel support.
    pub fn default_layers(&self) -> usize {
        (self.kernel().support() / self.params.spacing).ceil() as usize
    }

    /// Adds a body motion to the kinematic tree (relative to `parent`); returns its node.
    pub fn add_motion(&mut self, motion: Motion, parent: Option<usize>) -> usize {
        self.tree.add(motion, parent)
    }

    /// A container with fluid inside `inner` and lattice walls behind the `closed` faces.
    pub fn add_tank(
        &mut self,
        name: &str,
        inner: Aabb,
        closed: Faces,
        layers: Option<usize>,
        node: Option<usize>,
        w: WallOptions,
    ) -> usize {
        let (dp, dim) = (self.params.spacing, self.params.dim);
        let layers = layers.unwrap_or_else(|| self.default_layers());
        let s = tank_lattice(inner, closed, layers, dp, dim);
        let surface = box_surface(inner, closed, true, dim);
        self.boundary.add_part(name, node, s, surface, Sampling::Lattice, w.adhesion, w.slip, false)
    }

    /// A solid box (fluid outside) with `layers` lattice layers inside its faces.
    pub fn add_block(
        &mut self,
        name: &str,
        block: Aabb,
        layers: Option<usize>,
        node: Option<usize>,
        w: WallOptions,
    ) -> usize {
        let (dp, dim) = (self.params.spacing, self.params.dim);
        let layers = layers.unwrap_or_else(|| self.default_layers());
        let s = block_lattice(block, layers, dp, dim);
        let surface = box_surface(block, [true; 6], false, dim);
        self.boundary.add_part(
            name,
            node,
            s,
            surface,
            Sampling::Mesh(Default::default()),
            w.adhesion,
            w.slip,
            true,
        );
        let k = self.boundary.parts.len() - 1;
        self.boundary.parts[k].sampling = Sampling::Lattice;
        k
    }

    /// A triangle-mesh wall or body (3D only), sampled at the spacing. A closed mesh is a solid: `layers`
    /// layers inside it, the first dp/2 behind the surface (default: [`Self::default_layers`], enough to
    /// fill the kernel support). An open mesh is a shell: one layer on the surface plus `layers − 1`
    /// behind it against the normals (default 1).
    pub fn add_mesh(
        &mut self,
        name: &str,
        mesh: TriMesh,
        layers: Option<usize>,
        node: Option<usize>,
        w: WallOptions,
    ) -> Result<usize, SphError> {
        if self.params.dim == Dim::Two {
            return Err(SphError::Setup(format!("mesh part `{name}`: meshes need a 3D simulation")));
        }
        if mesh.triangles.is_empty() {
            return Err(SphError::Setup(format!("mesh part `{name}` has no triangles")));
        }
        let seed = 0x5350_4800 + self.boundary.parts.len() as u64;
        let topo = mesh.topology();
        let closed = !topo.edge_use_count.is_empty() && topo.edge_use_count.iter().all(|&c| c == 2);
        let dp = self.params.spacing;
        let (s, sampling) = if closed {
            let (s, cov) = solid_samples(&mesh, dp, layers.unwrap_or_else(|| self.default_layers()), seed);
            (s, Sampling::Solid(cov))
        } else {
            let (s, cov) = mesh_samples(&mesh, dp, layers.unwrap_or(1), seed);
            (s, Sampling::Mesh(cov))
        };
        Ok(self.boundary.add_part(name, node, s, mesh, sampling, w.adhesion, w.slip, closed))
    }

    /// Sets the domain box; particles leaving it are removed and counted.
    pub fn set_domain(&mut self, b: Aabb) {
        self.domain = b;
    }

    /// Makes axis `axis` (0 = x, 1 = y, 2 = z) periodic over the domain box's extent along it.
    pub fn set_periodic(&mut self, axis: usize) {
        self.periodic[axis] = true;
    }

    /// Counts volume crossing the horizontal planes `z = heights[k]` (upward and downward separately).
    pub fn set_flux_planes(&mut self, heights: Vec<f64>) {
        self.flux_up = vec![0.0; heights.len()];
        self.flux_down = vec![0.0; heights.len()];
        self.flux_planes = heights;
    }

    fn add_fluid_points(&mut self, pts: &[Vec3], vel: Vec3, hydrostatic: bool) -> usize {
        let eos = self.params.eos();
        let g = self.params.gravity;
        let gl = g.length();
        // Free surface: the highest particle (against gravity) plus half a spacing.
        let top = if gl > 0.0 && hydrostatic {
            let up = -g / gl;
            pts.iter().map(|p| p.dot(up)).fold(f64::NEG_INFINITY, f64::max) + 0.5 * self.params.spacing
        } else {
            0.0
        };
        let shifting = self.params.shifting > 0.0;
        for p in pts {
            let rho = if gl > 0.0 && hydrostatic {
                let depth = top - p.dot(-g / gl);
                eos.density(self.params.rest_density * gl * depth)
            } else {
                self.params.rest_density
            };
            self.fluid.push(*p, vel, rho, self.next_id, shifting);
            self.next_id += 1;
        }
        pts.len()
    }

    /// Fills `region` with fluid on the lattice `region.min + (i + ½)·dp`, skipping solids and keeping the
    /// default clearance from walls; densities hydrostatic below the top of the fill when `hydrostatic`.
    pub fn fill_box(&mut self, region: Aabb, vel: Vec3, hydrostatic: bool) -> usize {
        let pts = fill_box(
            &self.boundary,
            region,
            self.params.spacing,
            self.params.dim,
            Clearance::for_spacing(self.params.spacing),
        );
        self.add_fluid_points(&pts, vel, hydrostatic)
    }

    /// Flood-fills the lattice of `region` from `seed` without crossing walls.
    pub fn flood_fill(
        &mut self,
        seed: Vec3,
        region: Aabb,
        vel: Vec3,
        hydrostatic: bool,
    ) -> Result<usize, SphError> {
        let pts = flood_fill(
            &self.boundary,
            seed,
            region,
            self.params.spacing,
            self.params.dim,
            Clearance::for_spacing(self.params.spacing),
        )
        .map_err(SphError::Setup)?;
        Ok(self.add_fluid_points(&pts, vel, hydrostatic))
    }

    /// Adds fluid particles at given points (density ρ₀).
    pub fn add_particles(&mut self, pts: &[Vec3], vel: Vec3) -> usize {
        self.add_fluid_points(pts, vel, false)
    }

    /// Prepares the run: wall volumes, placement at the current time, the first force evaluation and
    /// time step. Call once after set-up.
    pub fn initialize(&mut self) -> Result<(), SphError> {
        self.initialize_with(&SERIAL)
    }

    /// [`Self::initialize`] on the ranks of `comm`. With several ranks every rank holds the same set-up
    /// (built the same way on each); the fluid is then split by recursive coordinate bisection and each
    /// rank keeps the particles in its box (see [`Self::step_with`]). Collective: call on every rank.
    pub fn initialize_with(&mut self, comm: &dyn Comm) -> Result<(), SphError> {
        if self.decomp.is_none() && self.fluid.is_empty() {
            return Err(SphError::Setup("no fluid particles: fill a region or add particles".into()));
        }
        self.default_domain();
        for a in 0..3 {
            if self.periodic[a] {
                let len = self.domain.max[a] - self.domain.min[a];
                if len.is_nan() || len <= 2.0 * self.kernel().support() {
                    return Err(SphError::Setup(format!(
                        "periodic axis {a}: the domain length {len} m must exceed two kernel supports ({} m)",
                        2.0 * self.kernel().support()
                    )));
                }
            }
        }
        let kernel = self.kernel();
        self.boundary.compute_volumes(&kernel, self.params.spacing);
        self.boundary.update_kinematics(&self.tree, self.time);
        if self.flux_up.len() != self.flux_planes.len() {
            self.flux_up = vec![0.0; self.flux_planes.len()];
            self.flux_down = vec![0.0; self.flux_planes.len()];
        }
        if comm.size() > 1 {
            self.decompose(comm)?;
        }
        self.prepare_sets_with(comm);
        let st = self.passes_timed(0.0, &mut || 0.0, comm);
        // The wet flags of the start (weight 0: no wet time yet), so that a map or a series row at t = 0
        // shows the wetting of the liquid at rest rather than all walls dry.
        self.accumulate_wetting(0.0);
        let n = self.fluid.len();
        self.fluid.acc[..n].copy_from_slice(&self.work.acc_new[..n]);
        self.fluid.drho[..n].copy_from_slice(&self.work.drho_new[..n]);
        if self.decomp.is_some() {
            self.reduce_step(comm, st, decomp::LocalCounts::default())?;
        } else {
            self.update_dt(st);
        }
        self.initialized = true;
        Ok(())
    }

    /// Without a domain box: the box around the fluid and the walls, widened by a tenth of its largest
    /// extent (at least ten spacings).
    fn default_domain(&mut self) {
        if self.domain.is_empty() {
            let mut b = Aabb::from_points(&self.fluid.pos).union(Aabb::from_points(&self.boundary.ref_pos));
            let margin = (0.1 * b.extent().max_element()).max(10.0 * self.params.spacing);
            b = b.inflated(margin);
            self.domain = b;
        }
    }

    /// Rebuilds every scratch structure from the state (after loading a checkpoint). Changes no state.
    pub fn refresh(&mut self) {
        self.refresh_with(&SERIAL)
    }

    /// [`Self::refresh`] on the ranks of `comm` (the halo comes from the neighbours). Collective.
    pub fn refresh_with(&mut self, comm: &dyn Comm) {
        self.boundary.update_kinematics(&self.tree, self.time);
        self.prepare_sets_with(comm);
        self.wall_state_with(Some(comm));
    }

    fn consts(&self, dt: f64) -> Consts {
        let p = &self.params;
        let k = self.kernel();
        let eos = p.eos();
        let gamma_st = p.cohesion_coefficient();
        let support = k.support();
        let d = p.dim.count();
        Consts {
            dim: p.dim,
            m: p.mass(),
            h: k.h,
            support,
            // Lattice neighbours sit exactly at the support (3 dp for h = 1.5 dp); rounding puts them on
            // either side of it. Leaving out pairs within 10⁻⁴ of r² = (2h)², where every kernel term is 0
            // to 10⁻¹³ (Wendland; 10⁻⁸ cubic spline), neither counts nor evaluates pairs that do nothing.
            r2max: support * support * (1.0 - 1e-4),
            rho0: p.rest_density,
            av: 0.5 * p.artificial_viscosity * p.sound_speed,
            eta2: 0.01 * k.h * k.h,
            nu: p.kinematic_viscosity,
            dc: 2.0 * p.density_diffusion * k.h * p.sound_speed,
            gk: p.gravity * (p.rest_density / (p.sound_speed * p.sound_speed)),
            g: p.gravity,
            gamma_st,
            curv: p.curvature_weight * (2.0 * p.spacing / support).powi(d),
            beta: {
                let per_factor = p.adhesion_per_factor();
                self.boundary.parts.iter().map(|q| q.adhesion * per_factor).collect()
            },
            drag: p.drag,
            shift_a: p.shifting,
            dt,
            spacing: p.spacing,
            w0: k.w0(),
            eos_b: eos.stiffness(),
            eos_gamma: p.gamma,
            eos,
            akinci: crate::kernel::AkinciSplines::new(support),
            wet_normal: self
                .boundary
                .parts
                .iter()
                .map(|q| p.wet_distance + q.sampling.wet_reach(p.spacing))
                .collect(),
            wet_lateral2: p.wet_lateral * p.wet_lateral,
            wet_offset: self.boundary.parts.iter().map(|q| q.sampling.surface_offset(p.spacing)).collect(),
            slip_free: self.boundary.parts.iter().map(|q| q.slip == Slip::FreeSlip).collect(),
        }
    }

    /// Sorts the fluid by cell, computes pressures, periodic images and the wall set.
    fn prepare_sets(&mut self) {
        self.prepare_sets_with(&SERIAL)
    }

    /// [`Self::prepare_sets`]; on several ranks the images are the halo received from the neighbours.
    fn prepare_sets_with(&mut self, comm: &dyn Comm) {
        let support = self.kernel().support();
        let w = &mut self.work;
        w.grid.rebuild(&self.fluid.pos, support);
        // After permuting, the grid's cell ranges index the sorted arrays directly.
        let identity = w.grid.entries().iter().enumerate().all(|(k, &i)| k == i as usize);
        if !identity {
            w.perm_buf.clear();
            w.perm_buf.extend_from_slice(w.grid.entries());
            let scratch = PermuteScratch { v3: &mut w.acc_new, f: &mut w.drho_new, u: &mut w.perm_u };
            self.fluid.permute(&w.perm_buf, scratch);
        }
        let origin = self.coords_origin();
        let w = &mut self.work;
        w.c32.fill(&self.fluid.pos, origin);
        // Dry wall particles skip their fluid query.
        w.grid.build_reach();
        self.compute_pressure();
        if self.decomp.is_some() {
            self.exchange_halo(comm);
        } else {
            self.build_fluid_images();
        }
        self.build_wall_set();
        self.work.ready = true;
    }

    fn compute_pressure(&mut self) {
        let eos = self.params.eos();
        let n = self.fluid.len();
        let w = &mut self.work;
        w.pr.resize(n, 0.0);
        w.irho.resize(n, 0.0);
        w.pr.par_iter_mut().zip(w.irho.par_iter_mut()).zip(self.fluid.rho.par_iter()).for_each(
            |((pr, ir), &rho)| {
                *ir = 1.0 / rho;
                *pr = eos.pressure(rho) * *ir * *ir;
            },
        );
    }

    /// Images of fluid particles within one support of a periodic face, shifted by the period.
    fn build_fluid_images(&mut self) {
        let support = self.kernel().support();
        let w = &mut self.work;
        w.g_src.clear();
        w.g_pos.clear();
        if self.periodic.iter().any(|&p| p) {
            for a in 0..3 {
                if !self.periodic[a] {
                    continue;
                }
                let (lo, hi) = (self.domain.min[a], self.domain.max[a]);
                let len = hi - lo;
                // Real particles, then the images made for earlier axes (corners).
                let n_real = self.fluid.len();
                let n_before = w.g_pos.len();
                for i in 0..n_real + n_before {
                    let (x, src) = if i < n_real {
                        (self.fluid.pos[i], i as u32)
                    } else {
                        (w.g_pos[i - n_real], w.g_src[i - n_real])
                    };
                    if x[a] < lo + support {
                        let mut y = x;
                        y[a] += len;
                        w.g_pos.push(y);
                        w.g_src.push(src);
                    }
                    if x[a] > hi - support {
                        let mut y = x;
                        y[a] -= len;
                        w.g_pos.push(y);
                        w.g_src.push(src);
                    }
                }
            }
        }
        self.sort_images();
    }

    /// Sorts the images (`g_pos`, `g_src`) by cell and fills in their state.
    fn sort_images(&mut self) {
        let support = self.kernel().support();
        let origin = self.coords_origin();
        let w = &mut self.work;
        w.g_grid.rebuild(&w.g_pos, support);
        let perm = w.g_grid.entries();
        w.g_tmp_u.clear();
        w.g_tmp_u.extend(perm.iter().map(|&i| w.g_src[i as usize]));
        std::mem::swap(&mut w.g_src, &mut w.g_tmp_u);
        w.g_tmp_v.clear();
        w.g_tmp_v.extend(perm.iter().map(|&i| w.g_pos[i as usize]));
        std::mem::swap(&mut w.g_pos, &mut w.g_tmp_v);
        w.g_c32.fill(&w.g_pos, origin);
        self.gather_image_state();
    }

    /// Copies velocity, density and pressure of the sources into the images.
    fn gather_image_state(&mut self) {
        if self.decomp.is_some() {
            self.gather_halo_state();
            return;
        }
        let w = &mut self.work;
        let f = &self.fluid;
        w.g_vel.clear();
        w.g_vel.extend(w.g_src.iter().map(|&s| f.vel[s as usize]));
        w.g_rho.clear();
        w.g_rho.extend(w.g_src.iter().map(|&s| f.rho[s as usize]));
        w.g_pr.clear();
        w.g_pr.extend(w.g_src.iter().map(|&s| w.pr[s as usize]));
        w.g_irho.clear();
        w.g_irho.extend(w.g_src.iter().map(|&s| w.irho[s as usize]));
    }

    /// The wall particles (and their periodic images) in cell order. Static walls without periodic
    /// images are sorted once.
    fn build_wall_set(&mut self) {
        let support = self.kernel().support();
        let periodic = self.periodic.iter().any(|&p| p);
        let origin = self.coords_origin();
        let w = &mut self.work;
        let b = &self.boundary;
        // On several ranks only the walls within one support of the rank's wall region: the ones its fluid
        // sees and the ones in its box any fluid reaches (module `local_walls`, `Decomp::wall_region`).
        // `None` inside means no fluid near: no walls.
        let region = self.decomp.as_ref().map(|d| d.wall_region(&self.fluid.pos, &w.g_pos, support));
        if w.walls_built
            && !periodic
            && !b.any_moving()
            && w.w_built_len == b.len()
            && w.w_c32.origin() == origin
            && w.w_region == region
        {
            return;
        }
        w.w_built_len = b.len();
        w.w_region = region;
        if region.is_some() {
            // The entries of the set being replaced, to clear the wet flags of those that leave it; at the
            // first build (after a split, a resume or a gather of the wetting records) every wet flag, so
            // that afterwards every wall particle outside the set is dry on this rank, as in a run that
            // stepped on.
            w.w_left.clear();
            if w.walls_built {
                w.w_left.extend_from_slice(&w.w_src);
            } else {
                w.w_left.extend((0..b.len()).filter(|&i| b.wet[i]).map(|i| i as u32));
            }
        }
        w.w_src.clear();
        w.w_ghost.clear();
        w.w_pos.clear();
        // Periodic runs select after adding the images, below.
        match region {
            Some(None) => {}
            Some(Some(region)) if !periodic => {
                w.w_local.select(b, &region, support, &mut w.w_src, &mut w.w_pos)
            }
            _ => {
                for i in 0..b.len() {
                    w.w_src.push(i as u32);
                    w.w_pos.push(b.position(i));
                }
            }
        }
        w.w_ghost.resize(w.w_src.len(), false);
        for a in 0..3 {
            if !self.periodic[a] {
                continue;
            }
            let (lo, hi) = (self.domain.min[a], self.domain.max[a]);
            let len = hi - lo;
            for i in 0..w.w_pos.len() {
                let x = w.w_pos[i];
                for (cond, shift) in [(x[a] < lo + support, len), (x[a] > hi - support, -len)] {
                    if cond {
                        let mut y = x;
                        y[a] += shift;
                        w.w_pos.push(y);
                        w.w_src.push(w.w_src[i]);
                        w.w_ghost.push(true);
                    }
                }
            }
        }
        if let (Some(Some(region)), true) = (region, periodic) {
            let mut k = 0;
            for j in 0..w.w_src.len() {
                if point_gap(w.w_pos[j], &region) <= support {
                    (w.w_src[k], w.w_ghost[k], w.w_pos[k]) = (w.w_src[j], w.w_ghost[j], w.w_pos[j]);
                    k += 1;
                }
            }
            w.w_src.truncate(k);
            w.w_ghost.truncate(k);
            w.w_pos.truncate(k);
        }
        w.w_grid.rebuild(&w.w_pos, support);
        // Fluid particles far from every wall skip their wall query.
        w.w_grid.build_reach();
        if !periodic && !b.any_moving() {
            w.w_grid.release_scratch();
        }
        let perm = w.w_grid.entries();
        w.w_tmp_u.clear();
        w.w_tmp_u.extend(perm.iter().map(|&i| w.w_src[i as usize]));
        std::mem::swap(&mut w.w_src, &mut w.w_tmp_u);
        w.w_tmp_b.clear();
        w.w_tmp_b.extend(perm.iter().map(|&i| w.w_ghost[i as usize]));
        std::mem::swap(&mut w.w_ghost, &mut w.w_tmp_b);
        // The dummy-velocity buffer is free here: use it to permute the positions.
        w.w_vvisc.clear();
        w.w_vvisc.extend(perm.iter().map(|&i| w.w_pos[i as usize]));
        std::mem::swap(&mut w.w_pos, &mut w.w_vvisc);
        w.w_c32.fill(&w.w_pos, origin);
        let n = w.w_src.len();
        w.w_vel.clear();
        w.w_vel.extend(w.w_src.iter().map(|&s| b.velocity(s as usize)));
        w.w_vol.clear();
        w.w_vol.extend(w.w_src.iter().map(|&s| b.volume[s as usize]));
        w.w_part.clear();
        w.w_part.extend(w.w_src.iter().map(|&s| b.part[s as usize]));
        w.w_vvisc.resize(n, Vec3::ZERO);
        w.w_rho.resize(n, 0.0);
        w.w_pr.resize(n, 0.0);
        w.w_irho.resize(n, 0.0);
        w.w_wet.resize(n, false);
        w.walls_built = true;
        if region.is_some() {
            self.dry_walls_that_left();
        }
    }

    /// On several ranks, after the wall set was reselected: a wall particle that left it has no fluid
    /// within one support (the region covers every wall particle any fluid reaches in the rank's box), so
    /// it is dry; only entries of the set get their wet flag from the wetting pass, so clear it here.
    /// Usually it has dried in the pass already (the set reaches two supports beyond the fluid, which
    /// moves less than a spacing per step); not so when a fluid particle next to it was removed (it left
    /// the domain or the density window).
    fn dry_walls_that_left(&mut self) {
        let w = &mut self.work;
        // `w_tmp_u` is scratch after the permutation; it holds the new set in selection order.
        w.w_tmp_u.clear();
        w.w_tmp_u.extend_from_slice(&w.w_src);
        w.w_tmp_u.sort_unstable();
        for &s in &w.w_left {
            if w.w_tmp_u.binary_search(&s).is_err() {
                self.boundary.wet[s as usize] = false;
            }
        }
        w.w_left.clear();
    }

    /// Origin of the single-precision coordinates of the cut-off test: the lower corner of the domain
    /// box (zero without one). Fixed for a run, so results do not depend on when it was resumed.
    fn coords_origin(&self) -> Vec3 {
        let min = self.domain.min;
        if min.is_finite() {
            min
        } else {
            Vec3::ZERO
        }
    }

    /// Read-only views of the fluid, its periodic images (both without surface normals) and the walls
    /// (with whatever wall state `work` holds) for the neighbour passes.
    fn views(&self) -> (FluidSet<'_>, FluidSet<'_>, WallSet<'_>) {
        let w = &self.work;
        let fl = FluidSet {
            pos: &self.fluid.pos,
            vel: &self.fluid.vel,
            rho: &self.fluid.rho,
            pr: &w.pr,
            irho: &w.irho,
            c32: w.c32.view(),
            nrm: &[],
            adh: &[],
            grid: &w.grid,
        };
        let gh = FluidSet {
            pos: &w.g_pos,
            vel: &w.g_vel,
            rho: &w.g_rho,
            pr: &w.g_pr,
            irho: &w.g_irho,
            c32: w.g_c32.view(),
            nrm: &[],
            adh: &[],
            grid: &w.g_grid,
        };
        let wl = WallSet {
            pos: &w.w_pos,
            vel: &w.w_vel,
            src: &w.w_src,
            ref_pos: &self.boundary.ref_pos,
            ref_normal: &self.boundary.ref_normal,
            frames: &self.boundary.frames,
            vvisc: &w.w_vvisc,
            rho: &w.w_rho,
            pr: &w.w_pr,
            irho: &w.w_irho,
            vol: &w.w_vol,
            part: &w.w_part,
            c32: w.w_c32.view(),
            grid: &w.w_grid,
            touched: w.w_touched.as_slice(),
        };
        (fl, gh, wl)
    }

    /// Wall extrapolation only (probes and loads between steps). The output buffers are moved out of
    /// `work` while the pass reads the views (no copy, no allocation).
    fn wall_state_only(&mut self) {
        self.wall_state_with(None)
    }

    /// [`Self::wall_state_only`]; with `comm` on several ranks the wall adhesion of the halo particles
    /// is exchanged first (collective), without it the last exchange's is used (the positions have not
    /// moved since: sensors between steps).
    fn wall_state_with(&mut self, comm: Option<&dyn Comm>) {
        let kernel = self.kernel();
        let c = self.consts(self.dt);
        let w = &mut self.work;
        w.w_touched.reset(self.fluid.len());
        let (mut rho, mut pr, mut irho) = (take(&mut w.w_rho), take(&mut w.w_pr), take(&mut w.w_irho));
        let (mut vvisc, mut wet) = (take(&mut w.w_vvisc), take(&mut w.w_wet));
        let (mut adh, mut g_adh) = (take(&mut w.adh), take(&mut w.g_adh));
        // The walls push back on the liquid their adhesion pulls on, like on its weight.
        let adhesive = c.gamma_st > 0.0 && c.beta.iter().any(|&b| b != 0.0);
        if adhesive {
            adh.resize(self.fluid.len(), Vec3::ZERO);
            let (fl, _, wl) = self.views();
            pass::adhesion(&c, fl, wl, &mut adh);
            if self.decomp.is_some() {
                if let Some(comm) = comm {
                    self.exchange_halo_adhesion(comm, &adh);
                }
                self.halo_adhesion(&mut g_adh);
            } else {
                g_adh.clear();
                g_adh.extend(self.work.g_src.iter().map(|&s| adh[s as usize]));
            }
        }
        let (fl, gh, wl) = self.views();
        let (fl, gh) =
            if adhesive { (FluidSet { adh: &adh, ..fl }, FluidSet { adh: &g_adh, ..gh }) } else { (fl, gh) };
        pass::wall_state(&kernel, &c, wl, fl, gh, &mut rho, &mut pr, &mut irho, &mut vvisc, &mut wet);
        let w = &mut self.work;
        (w.w_rho, w.w_pr, w.w_irho, w.w_vvisc, w.w_wet) = (rho, pr, irho, vvisc, wet);
        (w.adh, w.g_adh) = (adh, g_adh);
    }

    /// Time step of the last step taken \[s\] (0 before the first).
    pub fn last_dt(&self) -> f64 {
        self.last.dt_taken
    }

    /// Time spent per phase of the step so far.
    pub fn phase_times(&self) -> PhaseTimes {
        self.work.times
    }

    /// Wall state, surface normals and the fluid pass; results in `work.acc_new`, `work.drho_new`. On
    /// several ranks the halo's wall adhesion and surface normals come from their owners (collective).
    fn passes_timed(&mut self, dt: f64, lap: &mut dyn FnMut() -> f64, comm: &dyn Comm) -> PassStats {
        let kernel = self.kernel();
        let c = self.consts(dt);
        self.wall_state_with(Some(comm));
        self.work.times.wall_state += lap();
        let n = self.fluid.len();
        let st_on = c.gamma_st > 0.0;
        let (mut nrm, mut g_nrm) = (take(&mut self.work.nrm), take(&mut self.work.g_nrm));
        if st_on {
            nrm.resize(n, Vec3::ZERO);
            let (fl, gh, _) = self.views();
            pass::normals(&kernel, &c, fl, gh, &mut nrm);
            if self.decomp.is_some() {
                self.halo_normals(comm, &nrm, &mut g_nrm);
            } else {
                g_nrm.clear();
                g_nrm.extend(self.work.g_src.iter().map(|&s| nrm[s as usize]));
            }
        }
        let w = &mut self.work;
        let (mut acc, mut drho, mut phi) = (take(&mut w.acc_new), take(&mut w.drho_new), take(&mut w.phi));
        let (mut gradc, mut divr) = (take(&mut w.gradc), take(&mut w.divr));
        let (mut near, mut shift) = (take(&mut self.fluid.near), take(&mut self.fluid.shift));
        acc.resize(n, Vec3::ZERO);
        drho.resize(n, 0.0);
        phi.resize(if c.drag.enabled { n } else { 0 }, 0.0);
        let ns = if c.shift_a > 0.0 { n } else { 0 };
        gradc.resize(ns, Vec3::ZERO);
        divr.resize(ns, 0.0);
        let (fl, gh, wl) = self.views();
        let (fl, gh) =
            if st_on { (FluidSet { nrm: &nrm, ..fl }, FluidSet { nrm: &g_nrm, ..gh }) } else { (fl, gh) };
        let out = FluidOut {
            acc: &mut acc,
            drho: &mut drho,
            near: &mut near,
            shift: &mut shift,
            phi: &mut phi,
            gradc: &mut gradc,
            divr: &mut divr,
        };
        let st = pass::fluid_pass(&kernel, &c, fl, gh, wl, out);
        (self.fluid.near, self.fluid.shift) = (near, shift);
        let w = &mut self.work;
        (w.nrm, w.g_nrm, w.acc_new, w.drho_new, w.phi, w.gradc, w.divr) =
            (nrm, g_nrm, acc, drho, phi, gradc, divr);
        w.times.forces += lap();
        st
    }

    fn update_dt(&mut self, st: PassStats) {
        let (vmax2, rmax, rmin) = self.local_extrema();
        self.set_dt(vmax2, rmax, rmin, st);
    }

    /// Largest squared speed, largest and smallest density of this rank's fluid.
    fn local_extrema(&self) -> (f64, f64, f64) {
        // Maxima and minima do not depend on the order: reduced in parallel.
        self.fluid
            .vel
            .par_iter()
            .zip(self.fluid.rho.par_iter())
            .with_min_len(4096)
            .fold(
                || (0.0f64, 0.0f64, f64::INFINITY),
                |(vm, rx, rn), (v, &r)| (vm.max(v.length_squared()), rx.max(r), rn.min(r)),
            )
            .reduce(|| (0.0f64, 0.0f64, f64::INFINITY), |a, b| (a.0.max(b.0), a.1.max(b.1), a.2.min(b.2)))
    }

    /// The next time step from the largest squared speed, the density range and the pass statistics.
    fn set_dt(&mut self, vmax2: f64, rmax: f64, rmin: f64, st: PassStats) {
        let p = &self.params;
        let h = p.h();
        let eos = p.eos();
        let vmax = vmax2.sqrt();
        let cmax = eos.sound_speed(rmax.max(p.rest_density));
        let vwall = self.boundary.max_speed();
        let dt_a = p.cfl * h / (cmax + vmax + vwall);
        let dt_f = if st.max_acc > 0.0 { p.cfl * (h / st.max_acc).sqrt() } else { f64::INFINITY };
        let dt_v =
            if p.kinematic_viscosity > 0.0 { 0.125 * h * h / p.kinematic_viscosity } else { f64::INFINITY };
        // Capillary waves (Brackbill, Kothe & Zemach 1992): dt < √(ρ dp³ / (2πσ)); half of it.
        let dt_s = if p.surface_tension > 0.0 {
            0.5 * (p.rest_density * p.spacing.powi(3) / (2.0 * std::f64::consts::PI * p.surface_tension))
                .sqrt()
        } else {
            f64::INFINITY
        };
        self.dt = dt_a.min(dt_f).min(dt_v).min(dt_s).min(p.max_dt);
        self.last.max_speed = vmax;
        self.last.max_acc = st.max_acc;
        self.last.interactions = st.interactions;
        self.last.max_density_ratio = rmax / p.rest_density;
        self.last.min_density_ratio = rmin / p.rest_density;
        self.last.dt_acoustic = dt_a;
        self.last.dt_force = dt_f;
        self.last.dt_viscous = dt_v;
    }

    /// Advances one time step of `self.dt`.
    pub fn step(&mut self) -> Result<(), SphError> {
        if !self.initialized {
            self.initialize()?;
        }
        let dt = self.dt;
        let t1 = self.time + dt;
        let clock = std::time::Instant::now();
        let mut lap = {
            let mut last = clock;
            move || {
                let now = std::time::Instant::now();
                let d = (now - last).as_secs_f64();
                last = now;
                d
            }
        };
        self.last.guard_hits = self.predict_and_move_walls(dt, t1, &mut lap);
        self.wrap_and_remove()?;
        self.work.times.walls_guard += lap();
        // Forces at the new positions.
        self.prepare_sets();
        self.work.times.sort += lap();
        let st = self.passes_timed(dt, &mut lap, &SERIAL);
        self.accumulate_wetting(dt);
        self.correct(dt);
        self.time = t1;
        self.steps += 1;
        self.update_dt(st);
        self.last.dt_taken = dt;
        self.work.times.correct += lap();
        Ok(())
    }

    /// Predictor and drift: `x ← x + dt (v + ½dt a) + shift`, `v* = v + dt a`, `ρ* = ρ + dt Dρ`.
    /// The start of a step shared by [`Self::step`] and the step over ranks: predictor, then the walls
    /// move to the new time `t1` \[s\] (the old frames kept for the guard), plane fluxes are counted and
    /// the guard stops crossings. Returns the number of guard hits.
    pub(crate) fn predict_and_move_walls(&mut self, dt: f64, t1: f64, lap: &mut dyn FnMut() -> f64) -> u64 {
        self.predict(dt);
        self.work.times.predict += lap();
        self.work.frames_old.clear();
        self.work.frames_old.extend_from_slice(&self.boundary.frames);
        self.count_flux();
        self.boundary.update_kinematics(&self.tree, t1);
        self.guard()
    }

    fn predict(&mut self, dt: f64) {
        {
            let f = &mut self.fluid;
            let shift = &f.shift;
            let shifting = !shift.is_empty();
            f.pos
                .par_iter_mut()
                .zip(f.vel.par_iter_mut())
                .zip(f.rho.par_iter_mut())
                .zip(f.acc.par_iter().zip(f.drho.par_iter()))
                .enumerate()
                .for_each(|(i, (((x, v), rho), (a, d)))| {
                    *x += (*v + *a * (0.5 * dt)) * dt;
                    if shifting {
                        *x += shift[i];
                    }
                    *v += *a * dt;
                    *rho += d * dt;
                });
        }
    }

    /// Corrector: `v ← v* + ½dt (a' − a)`, `ρ ← ρ* + ½dt (Dρ' − Dρ)`, and the new rates become current.
    fn correct(&mut self, dt: f64) {
        {
            let w = &self.work;
            let f = &mut self.fluid;
            let half = 0.5 * dt;
            f.vel.par_iter_mut().zip(f.acc.par_iter_mut()).zip(w.acc_new.par_iter()).for_each(
                |((v, a), an)| {
                    *v += (*an - *a) * half;
                    *a = *an;
                },
            );
            f.rho.par_iter_mut().zip(f.drho.par_iter_mut()).zip(w.drho_new.par_iter()).for_each(
                |((r, d), dn)| {
                    *r += (dn - *d) * half;
                    *d = *dn;
                },
            );
        }
    }

    /// Applies the crossing guard to every particle that was near a wall; returns how many were stopped.
    fn guard(&mut self) -> u64 {
        let parts = &self.boundary.parts;
        if parts.is_empty() {
            return 0;
        }
        let f0s = &self.work.frames_old;
        let f1s = &self.boundary.frames;
        let offset = self.params.guard_offset * self.params.spacing;
        let dt = self.dt;
        let f = &mut self.fluid;
        let (acc, shift) = (&f.acc, &f.shift);
        f.pos
            .par_iter_mut()
            .zip(f.vel.par_iter_mut())
            .zip(f.near.par_iter())
            .enumerate()
            .map(|(i, ((x, v), &mask))| {
                if mask == 0 {
                    return 0u64;
                }
                let old = old_position(*x, *v, acc[i], shift.get(i).copied(), dt);
                let mut hit = 0;
                for (k, part) in parts.iter().enumerate() {
                    let bit = if k < 31 { 1u32 << k } else { 1u32 << 31 };
                    if mask & bit == 0 {
                        continue;
                    }
                    let g = guard_particle(part, &f0s[k], &f1s[k], old, *x, *v, offset);
                    if g.hit {
                        *x = g.pos;
                        *v = g.vel;
                        hit = 1;
                    }
                }
                hit
            })
            .sum()
    }

    fn count_flux(&mut self) {
        if self.flux_planes.is_empty() {
            return;
        }
        let vol0 = self.params.particle_volume();
        let f = &self.fluid;
        for (i, x) in f.pos.iter().enumerate() {
            let z0 = old_position(*x, f.vel[i], f.acc[i], f.shift.get(i).copied(), self.dt).z;
            let z1 = x.z;
            if z0 == z1 {
                continue;
            }
            for (k, &zp) in self.flux_planes.iter().enumerate() {
                if z0 < zp && z1 >= zp {
                    self.flux_up[k] += vol0;
                } else if z0 >= zp && z1 < zp {
                    self.flux_down[k] += vol0;
                }
            }
        }
    }

    /// Resets the plane-flux counters.
    pub fn reset_flux(&mut self) {
        self.flux_up.iter_mut().for_each(|v| *v = 0.0);
        self.flux_down.iter_mut().for_each(|v| *v = 0.0);
    }

    fn wrap_and_remove(&mut self) -> Result<(), SphError> {
        let n = self.fluid.len();
        let d = self.domain;
        let per = self.periodic;
        let lo_rho = self.params.density_window[0] * self.params.rest_density;
        let hi_rho = self.params.density_window[1] * self.params.rest_density;
        let w = &mut self.work;
        let wrap = |x: &mut Vec3| {
            for a in 0..3 {
                if per[a] {
                    let len = d.max[a] - d.min[a];
                    if x[a] < d.min[a] {
                        x[a] += len;
                    } else if x[a] >= d.max[a] {
                        x[a] -= len;
                    }
                }
            }
        };
        // One parallel read pass with the outcome of a scan in order: the first particle (lowest index)
        // with a non-finite state stops the run, after the particles before it were wrapped; otherwise the
        // counts of what leaves the domain (judged at the wrapped position) or the density window, and
        // the first such index. Positions are written only when an axis is periodic.
        let (pos, vel, rho) = (&mut self.fluid.pos, &self.fluid.vel, &self.fluid.rho);
        let none = (usize::MAX, 0u64, 0u64, usize::MAX);
        let (bad, removed_domain, removed_density, first_removed) = pos
            .par_iter()
            .zip(vel.par_iter().zip(rho.par_iter()))
            .enumerate()
            .with_min_len(4096)
            .map(|(i, (x, (v, &r)))| {
                if !(spatter_core::math::is_finite(*x) && spatter_core::math::is_finite(*v) && r.is_finite())
                {
                    return (i, 0, 0, usize::MAX);
                }
                let mut y = *x;
                wrap(&mut y);
                if !d.contains(y) {
                    (usize::MAX, 1, 0, i)
                } else if r < lo_rho || r > hi_rho {
                    (usize::MAX, 0, 1, i)
                } else {
                    none
                }
            })
            .reduce(|| none, |a, b| (a.0.min(b.0), a.1 + b.1, a.2 + b.2, a.3.min(b.3)));
        let periodic = per.iter().any(|&p| p);
        if bad < n {
            let i = bad;
            if periodic {
                pos[..i].par_iter_mut().with_min_len(4096).for_each(wrap);
            }
            let what = if !spatter_core::math::is_finite(pos[i]) {
                "position"
            } else if !spatter_core::math::is_finite(vel[i]) {
                "velocity"
            } else {
                "density"
            };
            return Err(self.blow_up(self.fluid.id[i], what, self.steps + 1, self.time + self.dt, self.dt));
        }
        if periodic {
            pos.par_iter_mut().with_min_len(4096).for_each(wrap);
        }
        if removed_domain + removed_density > 0 {
            // Only now build the mask (no per-step buffer when nothing leaves).
            w.keep.clear();
            w.keep.resize(n, true);
            for i in first_removed..n {
                let x = self.fluid.pos[i];
                let rho = self.fluid.rho[i];
                w.keep[i] = d.contains(x) && rho >= lo_rho && rho <= hi_rho;
            }
            self.fluid.retain(&w.keep);
            self.removed.outside_domain += removed_domain;
            self.removed.density_window += removed_density;
        }
        Ok(())
    }

    /// The error for fluid particle `id` found with a non-finite `what` in step `step` (time `time`,
    /// time step `dt`).
    fn blow_up(&self, id: u32, what: &'static str, step: u64, time: f64, dt: f64) -> SphError {
        SphError::BlowUp {
            step,
            time,
            id,
            what,
            cause: format!(
                "the time step ({dt:.3e} s) is too large for the forces, or the sound speed ({} m/s) is below \
                 10× the flow speed; lower `cfl` or raise the sound speed",
                self.params.sound_speed
            ),
        }
    }

    fn accumulate_wetting(&mut self, dt: f64) {
        let decomp = self.decomp.as_ref();
        let w = &self.work;
        let b = &mut self.boundary;
        for k in 0..w.w_src.len() {
            if w.w_ghost[k] || decomp.is_some_and(|d| !d.owns(w.w_pos[k])) {
                continue;
            }
            let s = w.w_src[k] as usize;
            b.wet[s] = w.w_wet[k];
            if w.w_wet[k] {
                b.wet_time[s] += dt;
            }
        }
    }

    /// Fluid force and torque on every part in the current state.
    pub fn part_loads(&mut self) -> Vec<PartLoad> {
        if !self.work.ready {
            self.refresh();
        }
        self.compute_pressure();
        self.gather_image_state();
        self.wall_state_only();
        let kernel = self.kernel();
        let c = self.consts(self.dt);
        let mut load = take(&mut self.work.w_load);
        load.resize(self.work.w_src.len(), Vec3::ZERO);
        let (fl, gh, wl) = self.views();
        pass::wall_loads(&kernel, &c, wl, fl, gh, &mut load);
        self.work.w_load = load;
        let w = &self.work;
        let mut loads = vec![PartLoad::default(); self.boundary.parts.len()];
        let centres: Vec<Vec3> = self
            .boundary
            .parts
            .iter()
            .enumerate()
            .map(|(k, p)| self.boundary.frames[k].to_world(p.torque_point))
            .collect();
        let decomp = self.decomp.as_ref();
        for k in 0..w.w_src.len() {
            // On several ranks each rank adds the entries in its box (summed by `part_loads_with`).
            if w.w_ghost[k] || decomp.is_some_and(|d| !d.owns(w.w_pos[k])) {
                continue;
            }
            let part = w.w_part[k] as usize;
            loads[part].force += w.w_load[k];
            loads[part].torque += (w.w_pos[k] - centres[part]).cross(w.w_load[k]);
        }
        loads
    }

    /// Shepard-interpolated pressure \[Pa\] and velocity at `x` (None where no fluid is near).
    pub fn probe(&mut self, x: Vec3) -> Option<(f64, Vec3)> {
        if !self.work.ready {
            self.refresh();
        }
        self.compute_pressure();
        self.gather_image_state();
        let kernel = self.kernel();
        let c = self.consts(self.dt);
        let (fl, gh, _) = self.views();
        pass::probe(&kernel, &c, fl, gh, x)
    }

    /// Mean extrapolated wall pressure \[Pa\] of the first-layer wall particles within `radius` of `x`
    /// (a wall pressure sensor), or None when none is in range. Uses the state of the last step.
    pub fn wall_pressure(&mut self, x: Vec3, radius: f64) -> Option<f64> {
        let (s, n) = self.wall_pressure_sum(x, radius);
        (n > 0).then(|| s / n as f64)
    }

    /// Sum of the extrapolated pressures \[Pa\] and number of the first-layer wall entries within
    /// `radius` of `x` (on several ranks: of the entries in this rank's box).
    fn wall_pressure_sum(&mut self, x: Vec3, radius: f64) -> (f64, usize) {
        if !self.work.ready {
            self.refresh();
        }
        let w = &self.work;
        let eos = self.params.eos();
        let decomp = self.decomp.as_ref();
        let (mut s, mut n) = (0.0, 0usize);
        let mut read = Vec::new();
        for k in 0..w.w_src.len() {
            let src = w.w_src[k] as usize;
            if w.w_ghost[k] || self.boundary.area[src] <= 0.0 || decomp.is_some_and(|d| !d.owns(w.w_pos[k])) {
                continue;
            }
            if (w.w_pos[k] - x).length() <= radius {
                s += eos.pressure(w.w_rho[k]);
                n += 1;
                if decomp.is_some() {
                    read.push(src as u32);
                }
            }
        }
        if let Some(d) = decomp {
            // The first-layer wall particles this rank owns within the radius but outside its wall set have
            // no fluid within one support: they read the dry wall state (no extrapolated pressure, the rest
            // density), as they do on one rank.
            read.sort_unstable();
            let dry = eos.pressure(self.params.rest_density);
            let b = &self.boundary;
            self.work.w_local.for_each_within(b, x, radius, |i, p| {
                if b.area[i] > 0.0 && read.binary_search(&(i as u32)).is_err() && d.owns(p) {
                    s += dry;
                    n += 1;
                }
            });
        }
        (s, n)
    }

    /// Total kinetic energy of the fluid \[J, J/m in 2D\].
    pub fn kinetic_energy(&self) -> f64 {
        0.5 * self.params.mass() * self.fluid.vel.iter().map(|v| v.length_squared()).sum::<f64>()
    }

    /// Total fluid momentum \[kg m/s\].
    pub fn momentum(&self) -> Vec3 {
        self.fluid.vel.iter().copied().sum::<Vec3>() * self.params.mass()
    }

    /// Total fluid mass \[kg, kg/m in 2D\].
    pub fn fluid_mass(&self) -> f64 {
        self.params.mass() * self.fluid.len() as f64
    }

    /// Current pressure of every fluid particle \[Pa\] (in storage order).
    pub fn pressures(&self) -> Vec<f64> {
        let eos = self.params.eos();
        self.fluid.rho.iter().map(|&r| eos.pressure(r)).collect()
    }

    /// Bytes held by the state and every scratch buffer (walls and cell lists included), per fluid
    /// particle.
    pub fn bytes_per_particle(&self) -> f64 {
        fn b<T>(v: &Vec<T>) -> usize {
            v.capacity() * std::mem::size_of::<T>()
        }
        let w = &self.work;
        let fluid_scratch = b(&w.pr)
            + b(&w.irho)
            + b(&w.nrm)
            + b(&w.acc_new)
            + b(&w.drho_new)
            + b(&w.phi)
            + b(&w.gradc)
            + b(&w.divr)
            + b(&w.keep)
            + b(&w.perm_buf)
            + b(&w.perm_u)
            + w.c32.bytes()
            + w.grid.bytes();
        let images = b(&w.g_src)
            + b(&w.g_pos)
            + b(&w.g_vel)
            + b(&w.g_rho)
            + b(&w.g_pr)
            + b(&w.g_irho)
            + b(&w.g_nrm)
            + b(&w.adh)
            + b(&w.g_adh)
            + b(&w.g_tmp_u)
            + b(&w.g_tmp_v)
            + w.g_c32.bytes()
            + w.g_grid.bytes();
        let walls = self.boundary.bytes()
            + w.w_c32.bytes()
            + b(&w.w_src)
            + b(&w.w_ghost)
            + b(&w.w_pos)
            + b(&w.w_vel)
            + b(&w.w_vvisc)
            + b(&w.w_rho)
            + b(&w.w_pr)
            + b(&w.w_irho)
            + b(&w.w_vol)
            + b(&w.w_part)
            + b(&w.w_wet)
            + b(&w.w_load)
            + b(&w.w_tmp_u)
            + b(&w.w_tmp_b)
            + w.w_touched.bytes()
            + w.w_grid.bytes();
        (self.fluid.bytes() + fluid_scratch + images + walls) as f64 / self.fluid.len().max(1) as f64
    }
}

/// Position before the drift of the current step, from the drifted position, the predicted velocity
/// `v* = v + dt a`, the acceleration and the shift: `x − dt (v* − ½ dt a) − shift`.
#[inline]
fn old_position(x: Vec3, v_pred: Vec3, a: Vec3, shift: Option<Vec3>, dt: f64) -> Vec3 {
    x - (v_pred - a * (0.5 * dt)) * dt - shift.unwrap_or(Vec3::ZERO)
}
