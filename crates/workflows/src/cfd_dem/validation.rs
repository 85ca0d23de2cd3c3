//! Reference cases of the CFD–DEM coupling for `spatter validate` (their fast forms run as unit tests):
//! the pressure gradient through a fixed bed against Ergun (1952) and a sphere settling with two-way
//! coupling against the Schiller & Naumann (1933) terminal velocity.

use super::*;
use crate::fluid_forces::DragModel;
use spatter_cfd::grid::{Axis, Grid};
use spatter_cfd::{Boundary, Fluid, Numerics};
use spatter_core::material::Material;
use spatter_core::validation::{Case, Check};
use spatter_dem::contact::HertzMindlin;
use spatter_dem::sim::uniform_pairs;
use spatter_dem::{NewParticle, Settings};
use std::f64::consts::PI;

/// Every coupling case.
pub fn validation_cases() -> Vec<Case> {
    vec![
        Case { name: "cfd_dem_ergun_fixed_bed", run: ergun_case },
        Case { name: "cfd_dem_settling_sphere", run: settling_case },
    ]
}

pub(crate) const G: Vec3 = Vec3::new(0.0, 0.0, -9.81);

pub(crate) fn water() -> Fluid {
    Fluid { density: 1000.0, viscosity: 1e-3 }
}

/// A DEM of glass spheres (ρ = 2500 kg/m³, soft) under gravity.
pub(crate) fn dem(dt: f64) -> Simulation<HertzMindlin> {
    let mats = vec![Material { youngs_modulus: 1e7, poisson_ratio: 0.25, density: 2500.0 }];
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats.clone(),
        uniform_pairs(&mats, 0.5, 0.5),
        dt,
        Settings::default(),
    );
    sim.gravity = G;
    sim
}

/// A box of `n` cells of edge `h` \[m\] with the given sides (x_min, x_max, y_min, y_max, z_min, z_max).
pub(crate) fn flow(n: [usize; 3], h: f64, bc: [Boundary; 6]) -> Result<Flow, String> {
    let mut axes = Vec::with_capacity(3);
    for &k in &n {
        axes.push(Axis::uniform(0.0, h * k as f64, k).map_err(|e| e.to_string())?);
    }
    let axes: [Axis; 3] = axes.try_into().map_err(|_| "three axes".to_string())?;
    let g = Grid::new(axes, Mode::Cartesian).map_err(|e| e.to_string())?;
    let len = g.layout.len();
    Flow::new(g, water(), bc, vec![false; len], Numerics::default()).map_err(|e| e.to_string())
}

/// Ergun (1952), Chem. Eng. Prog. 48:89–94: Δp/L = 150 μ (1−ε)² U/(ε³ d²) + 1.75 ρ (1−ε) U²/(ε³ d).
pub(crate) fn ergun(eps: f64, u: f64, d: f64, f: &Fluid) -> f64 {
    150.0 * f.viscosity * (1.0 - eps).powi(2) * u / (eps.powi(3) * d * d)
        + 1.75 * f.density * (1.0 - eps) * u * u / (eps.powi(3) * d)
}

/// ε of the fixed bed's simple cubic lattice of spacing 1.05 d.
pub(crate) fn lattice_porosity() -> f64 {
    1.0 - PI / (6.0 * 1.05f64.powi(3))
}

/// A fixed bed of 1 mm spheres on a simple cubic lattice of spacing 1.05 d (ε = 0.5477), 8 × 8 × 20
/// spheres, in a column of 4 × 4 × 24 cells of edge 2.1 mm with slip sides (each bed cell holds 8
/// spheres, so ε is uniform), water entering at the bottom with superficial velocity `u` \[m/s\], drag
/// `ergun_wen_yu`. Returns the pressure gradient inside the bed \[Pa/m\] after 0.05 s (fluid step
/// 1e-4 s) and ε of a bed cell. Every coupling step's momentum balance must close to 1e-12.
pub(crate) fn fixed_bed(model: MomentumModel, u: f64) -> Result<(f64, f64), String> {
    let d = 1e-3;
    let s = 1.05 * d;
    let h = 2.0 * s;
    let inlet = Boundary::Inlet { velocity_m_s: [0.0, 0.0, u], table: Default::default() };
    let outlet = Boundary::Outlet { pressure_pa: 0.0 };
    let f =
        flow([4, 4, 24], h, [Boundary::Slip, Boundary::Slip, Boundary::Slip, Boundary::Slip, inlet, outlet])?;
    let mut dm = dem(1e-5);
    let z0 = 2.0 * h;
    for k in 0..20 {
        for j in 0..8 {
            for i in 0..8 {
                let x =
                    Vec3::new(0.5 * s + s * i as f64, 0.5 * s + s * j as f64, z0 + 0.5 * s + s * k as f64);
                dm.add_particle(NewParticle { frozen: true, ..NewParticle::at(x, 0.5 * d, 0) });
            }
        }
    }
    let opts = CouplingOptions {
        forces: FluidForceOptions { drag: DragModel::ErgunWenYu, ..Default::default() },
        model,
        ..Default::default()
    };
    let mut c = Coupled::new(f, dm, opts).map_err(|e| e.to_string())?;
    while c.flow.state.t < 0.05 - 1e-9 {
        let rep = c.step().map_err(|e| e.to_string())?;
        if rep.relative_mismatch >= 1e-12 {
            return Err(format!("momentum balance off by {:e}", rep.relative_mismatch));
        }
    }
    // Cells 4..10 (z from 4h to 10h) lie well inside the bed (2h..12h).
    let (k1, k2) = (4, 10);
    let dp = c.flow.cell_pressure(1, 1, k1) - c.flow.cell_pressure(1, 1, k2);
    let eps = c.void_fraction().alpha[c.flow.grid.layout.cell(1, 1, 6)];
    Ok((dp / ((k2 - k1) as f64 * h), eps))
}

/// A 1 mm glass bead released from rest in a closed box of water (10 × 10 × 20 cells of 3 mm), fluid
/// step 1e-4 s, DEM step 1e-5 s, drag `schiller_naumann`. Returns the bead's mean settling speed and its
/// mean slip relative to the interstitial fluid at it over t = 0.12–0.15 s, and the Schiller–Naumann
/// terminal speed with buoyancy \[m/s\].
pub(crate) fn settling(model: MomentumModel) -> Result<(f64, f64, f64), String> {
    let h = 3e-3;
    let wall = || Boundary::Wall { velocity_m_s: [0.0; 3] };
    let f = flow([10, 10, 20], h, std::array::from_fn(|_| wall()))?;
    let mut d = dem(1e-5);
    d.add_particle(NewParticle::at(Vec3::new(5.1 * h, 4.9 * h, 18.2 * h), 5e-4, 0));
    let opts = CouplingOptions {
        forces: FluidForceOptions { drag: DragModel::SchillerNaumann, ..Default::default() },
        model,
        ..Default::default()
    };
    let mut c = Coupled::new(f, d, opts).map_err(|e| e.to_string())?;
    let (mut v_sum, mut slip_sum, mut n) = (0.0, 0.0, 0.0);
    while c.flow.state.t < 0.15 - 1e-9 {
        let rep = c.step().map_err(|e| e.to_string())?;
        if rep.relative_mismatch >= 1e-12 {
            return Err(format!("momentum balance off by {:e}", rep.relative_mismatch));
        }
        if c.flow.state.t > 0.12 {
            let x = c.dem.particles.pos[0];
            let v = c.dem.particles.vel[0].z;
            let u = c.flow.velocity_at(x.to_array()).ok_or("bead left the grid")?[2]
                / c.void_fraction().at(&c.flow.grid, x);
            v_sum += -v;
            slip_sum += u - v;
            n += 1.0;
        }
    }
    let wt = spatter_flow::forces::drag::DragLaw::SchillerNaumann.terminal_speed(
        &spatter_flow::forces::Fluid { density: 1000.0, viscosity: 1e-3 },
        1e-3,
        2500.0,
        9.81,
    );
    Ok((v_sum / n, slip_sum / n, wt))
}

fn ergun_case(quick: bool) -> Vec<Check> {
    let c = "cfd_dem_ergun_fixed_bed";
    let src = "Ergun (1952), Chem. Eng. Prog. 48:89-94, fixed bed of 1 mm spheres, eps = 0.5477";
    let cases: &[(MomentumModel, f64)] = if quick {
        &[(MomentumModel::B, 2e-3), (MomentumModel::A, 2e-3)]
    } else {
        &[
            (MomentumModel::B, 2e-3),
            (MomentumModel::B, 2e-2),
            (MomentumModel::A, 2e-3),
            (MomentumModel::A, 2e-2),
        ]
    };
    let eps = lattice_porosity();
    cases
        .iter()
        .map(|&(model, u)| {
            let grad = fixed_bed(model, u).map_or(f64::NAN, |r| r.0);
            let q = format!("dp/dz, model {model:?}, U = {u} m/s [Pa/m]");
            Check::relative(c, q, ergun(eps, u, 1e-3, &water()), grad, 0.01, src)
        })
        .collect()
}

fn settling_case(quick: bool) -> Vec<Check> {
    let c = "cfd_dem_settling_sphere";
    let src =
        "Schiller & Naumann (1933) terminal velocity with buoyancy, 1 mm glass bead in water, cells of 3 d";
    let models: &[MomentumModel] =
        if quick { &[MomentumModel::A] } else { &[MomentumModel::A, MomentumModel::B] };
    models
        .iter()
        .map(|&model| {
            let (v, wt) = settling(model).map_or((f64::NAN, 0.14595), |r| (r.0, r.2));
            Check::relative(c, format!("settling speed, model {model:?} [m/s]"), wt, v, 0.03, src)
        })
        .collect()
}
