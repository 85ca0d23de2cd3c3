//! The coupled air of `air = "coupled"`: the air in the accelerating pipe and the protection box solved
//! on a Cartesian grid (`spatter-cfd`) and coupled two-way with the stones through the `cfd_dem`
//! coupling ([`crate::cfd_dem::partner::CoupledFluid`], stepped inside the gravelometer's DEM scene).
//!
//! * **Domain**: x from the pipe inlet (rounded out to whole cells) to the far wall of the protection
//!   box, y and z over the box, uniform cubic cells of `coupled_air.cell_size_m` with a cell face on the
//!   pipe-exit plane x = 0. Everything outside the pipe's bore upstream of x = 0 is solid (the pipe wall,
//!   and the box's back wall around the opening); the panel is a solid slab (front face on the panel,
//!   1.5 cells thick) and the clamp bars are solids (the generated meshes, `geometry/*.stl`).
//! * **Boundaries** (as in the published study, Qian et al. 2022): a velocity inlet over the pipe's
//!   bore at x = −L with the bulk speed `pipe.air_velocity_m_s` ramped linearly over
//!   `air_field.ramp_s` (the valve opening), a pressure outlet p = 0 on the box's far wall (x = max; the
//!   study's box outlet is not located in its text, so its place is assumed), no-slip walls elsewhere.
//! * **Turbulence**: laminar (default) or the study's standard k–ε, whose log-law wall functions act on
//!   the faces of the blocked cells that make the pipe.
//! * **Coupling**: model A, the divided void fraction, the drag law of `air_field.drag` on every member
//!   sphere (`docs/cfd.md`), Archimedes buoyancy; one fluid step every `dem_steps_per_fluid_step` DEM
//!   steps (default: a fluid Courant number of about 0.4 at 1.3 × the bulk speed).
//!
//! **Cell size against stone size.** Unresolved (volume-averaged) coupling asks for cells larger than
//! what they average: the drag laws take the interstitial velocity U/α of a cell and a void fraction α
//! that a particle in it lowers only a little. The study coupled per member sphere (0.5 mm) with cells
//! of about three member radii, which keeps the member rule but not the stone rule: a stone fills many
//! such cells. Here the default is a quarter of the pipe diameter — 7.5 mm for DIN 55996-1 (1.5 grit
//! diameters: one grit stone lowers α of its cell to about 0.89, its air is then read 12 % fast) and
//! 13 mm for SAE J400 (about one gravel stone: a large stone alone brings α of a cell down to about 0.5,
//! so its air reads up to twice as fast — coarser cells leave fewer than four across the pipe). The cost
//! is the pipe's resolution: four cells across the bore, the wall layer in the wall functions. Finer
//! cells resolve the pipe better and the stones worse; the key sets them.

use super::config::{get, CoupledTurbulence, GravelometerConfig};
use super::geometry;
use super::scene::Plan;
use super::GravelometerError;
use crate::cfd::config::{AxisSpec, BoundariesSpec, FluidSpec, GridSpec, NumericsSpec, TurbulenceSpec};
use crate::cfd::{build_domain, FlowDomain};
use crate::cfd_dem::partner::CoupledFluid;
use crate::cfd_dem::{Coupling, CouplingOptions, MomentumModel, VoidFractionMethod};
use crate::fluid_forces::FluidForceOptions;
use spatter_cfd::bc::{Boundary, TimeTable};
use spatter_cfd::solid::Solid;
use spatter_cfd::Flow;
use spatter_flow::forces::Fluid;
use std::path::Path;

/// Panel slab thickness in cells (an inclined slab thinner than about √2 cells can leave gaps between
/// blocked cell centres).
const SLAB_CELLS: f64 = 1.5;

/// Fluid Courant number the default `dem_steps_per_fluid_step` aims at, at [`SPEED_MARGIN`] × the bulk
/// speed.
const COURANT: f64 = 0.4;
/// The fastest air relative to the bulk speed (the centreline of a developed turbulent pipe flow is
/// 1.22 U_b; the jet core carries it into the box).
const SPEED_MARGIN: f64 = 1.3;

/// The flow problem of the coupled air.
#[derive(Clone, Debug)]
pub struct AirDomain {
    pub fluid: FluidSpec,
    pub grid: GridSpec,
    pub boundaries: BoundariesSpec,
    pub solids: Vec<Solid>,
    pub turbulence: TurbulenceSpec,
    pub numerics: NumericsSpec,
    /// DEM steps per fluid step.
    pub substeps: u32,
}

/// Cells covering `lo..hi` from the face at `origin` with cell size `h`: (min, max, cells).
fn axis_from(origin: f64, lo: f64, hi: f64, h: f64) -> AxisSpec {
    let below = ((origin - lo) / h - 1e-9).ceil().max(0.0);
    let above = ((hi - origin) / h - 1e-9).ceil().max(1.0);
    AxisSpec {
        min_m: origin - below * h,
        max_m: origin + above * h,
        cells: (below + above) as usize,
        growth_ratio: 1.0,
        cluster: 0.0,
    }
}

/// The flow problem of `cfg` (see the module docs); the panel slab is written to `geometry`.
pub fn domain(
    cfg: &GravelometerConfig,
    plan: &Plan,
    geometry_dir: &Path,
) -> Result<AirDomain, GravelometerError> {
    let i = &cfg.input;
    let h = get(i.coupled_air.cell_size_m);
    let d = &plan.dims;
    let r = 0.5 * d.pipe_diameter;
    let b = geometry::box_bounds(d);
    let half_y = b.min.y.abs().max(b.max.y.abs());
    let half_z = b.min.z.abs().max(b.max.z.abs());
    let grid = GridSpec {
        mode: spatter_cfd::Mode::Cartesian,
        x: axis_from(0.0, -d.pipe_length, b.max.x, h),
        y: axis_from(0.0, -half_y, half_y, h),
        z: Some(axis_from(0.0, -half_z, half_z, h)),
        max_memory_gb: None,
    };
    let slab = geometry_dir.join("panel_solid.stl");
    std::fs::write(&slab, geometry::panel_slab(d, SLAB_CELLS * h).to_binary_stl())
        .map_err(|source| GravelometerError::Io { path: slab.clone(), source })?;
    let solids = vec![
        // The pipe wall and the box's back wall: everything outside the bore upstream of the exit.
        Solid::BoxWithBore {
            min_m: [grid.x.min_m - h, grid.y.min_m - h, -half_z - 2.0 * h],
            max_m: [0.0, grid.y.max_m + h, half_z + 2.0 * h],
            a_m: [-1.0, 0.0, 0.0],
            b_m: [0.0, 0.0, 0.0],
            radius_m: r,
        },
        Solid::Mesh { file: slab, scale: 1.0 },
        Solid::Mesh { file: geometry_dir.join(format!("{}.stl", super::scene::CLAMP)), scale: 1.0 },
    ];
    let a = &i.air_field;
    let rho = get(a.density_kg_m3);
    let fluid = FluidSpec { density_kg_m3: rho, kinematic_viscosity_m2_s: get(a.viscosity_pa_s) / rho };
    let ramp = get(a.ramp_s);
    let table = if ramp > 0.0 {
        TimeTable { t_s: vec![0.0, ramp], factor: vec![0.0, 1.0] }
    } else {
        TimeTable::default()
    };
    let ub = get(i.pipe.air_velocity_m_s);
    let boundaries = BoundariesSpec {
        x_min: Boundary::Inlet { velocity_m_s: [ub, 0.0, 0.0], table },
        x_max: Boundary::Outlet { pressure_pa: 0.0 },
        ..Default::default()
    };
    let turbulence = match get(i.coupled_air.turbulence) {
        CoupledTurbulence::Laminar => TurbulenceSpec::Laminar,
        // Inlet length scale 0.07 D, the usual estimate for developed pipe flow.
        CoupledTurbulence::KEpsilon => TurbulenceSpec::KEpsilon {
            inlet_intensity: get(i.coupled_air.inlet_intensity),
            inlet_length_scale_m: 0.07 * d.pipe_diameter,
        },
    };
    let substeps = match i.coupled_air.dem_steps_per_fluid_step {
        Some(n) => n,
        None => ((COURANT * h / (SPEED_MARGIN * ub.max(1.0) * plan.dt)).floor() as u32).max(1),
    };
    Ok(AirDomain { fluid, grid, boundaries, solids, turbulence, numerics: NumericsSpec::default(), substeps })
}

/// Builds the flow of `dom` at rest and the coupling's fluid side.
pub fn coupled_fluid(cfg: &GravelometerConfig, dom: &AirDomain) -> Result<CoupledFluid, GravelometerError> {
    let flow: Flow = build_domain(&FlowDomain {
        fluid: &dom.fluid,
        grid: &dom.grid,
        boundaries: &dom.boundaries,
        solids: &dom.solids,
        turbulence: &dom.turbulence,
        numerics: &dom.numerics,
    })
    .map_err(|e| GravelometerError::Config { key: "coupled_air".into(), message: e.to_string() })?;
    let a = &cfg.input.air_field;
    let options = CouplingOptions {
        forces: FluidForceOptions {
            // Replaced by the flow's own fluid by the coupling.
            fluid: Fluid::default(),
            drag: get(a.drag),
            k_correction: get(a.k_correction),
            pressure_force: true,
        },
        model: MomentumModel::A,
        exchange: crate::cfd_dem::Exchange::Explicit,
        void_fraction: VoidFractionMethod::Divided,
        alpha_min: 0.3,
        dem_steps_per_fluid_step: dom.substeps,
    };
    let coupling = Coupling::new(flow, options)
        .map_err(|e| GravelometerError::Config { key: "coupled_air".into(), message: e.to_string() })?;
    Ok(CoupledFluid::new(coupling))
}
