//! Turns a validated [`SphConfig`] into a ready [`Simulation`].

use super::config::{axis_index, face_index, FillType, SphConfig, WallType};
use spatter_core::comm::{Comm, SERIAL};
use spatter_core::mesh::TriMesh;
use spatter_core::{Aabb, Vec3};
use spatter_sph::error::SphError;
use spatter_sph::kernel::Dim;
use spatter_sph::params::{DragParams, SphParams};
use spatter_sph::sim::{Simulation, WallOptions};

/// Numbers fixed while building, reported in the log.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BuildInfo {
    /// U_max used for the sound speed \[m/s\].
    pub u_max: f64,
    /// Sound speed c₀ \[m/s\].
    pub sound_speed: f64,
    pub fluid_particles: usize,
    pub wall_particles: usize,
    /// Settings the log should warn about (adhesion outside the calibrated range, a sound speed below the
    /// capillary limit).
    #[serde(default)]
    pub warnings: Vec<String>,
}

/// Builds the simulation (file paths as given: the scenario loader has made them absolute).
pub fn build(cfg: &SphConfig) -> Result<(Simulation, BuildInfo), SphError> {
    build_with(cfg, &SERIAL)
}

/// [`build`] on the ranks of `comm`: every rank builds the whole set-up the same way, then keeps the
/// fluid in its box (see [`Simulation::initialize_with`]); the counts in [`BuildInfo`] are the whole run's.
pub fn build_with(cfg: &SphConfig, comm: &dyn Comm) -> Result<(Simulation, BuildInfo), SphError> {
    let f = &cfg.fluid;
    let dim = if f.dimensions == 2 { Dim::Two } else { Dim::Three };
    let dp = f.spacing_m;
    let mut p = SphParams::water(dim, dp, 1.0);
    if let Some(h) = f.h_over_dp {
        p.h_over_dp = h;
    }
    p.kernel = f.kernel;
    p.rest_density = f.density_kg_m3;
    p.gamma = f.gamma;
    p.gravity = f.gravity_m_s2;
    if dim == Dim::Two {
        p.gravity.y = 0.0;
    }
    p.artificial_viscosity = f.artificial_viscosity;
    p.kinematic_viscosity = f.kinematic_viscosity_m2_s;
    p.density_diffusion = f.density_diffusion;
    p.cfl = f.cfl;
    p.max_dt = f.max_dt_s.unwrap_or(f64::INFINITY);
    p.shifting = f.shifting;
    p.surface_tension = f.surface_tension_n_m;
    p.curvature_weight = f.curvature_weight;
    p.density_window = f.density_window;
    p.guard_offset = f.guard_offset;
    p.wet_distance = cfg.sensors.wet_distance_m.unwrap_or(p.wet_distance);
    p.wet_lateral = cfg.sensors.wet_lateral_m.unwrap_or(p.wet_lateral);
    p.drag = DragParams {
        enabled: cfg.drag.enabled,
        air_density: cfg.drag.air_density_kg_m3,
        air_viscosity: cfg.drag.air_viscosity_pa_s,
        air_velocity: cfg.drag.air_velocity_m_s,
    };
    let mut sim = Simulation::new(p);

    // Kinematic tree.
    let mut nodes: Vec<(&str, usize)> = Vec::new();
    for (i, m) in cfg.motions.iter().enumerate() {
        let parent = crate::motions::parent_index(&cfg.motions, i).map(|k| nodes[k].1);
        let motion =
            crate::motions::own_motion(m).map_err(|e| SphError::Setup(format!("motions[{i}].{e}")))?;
        let node = sim.add_motion(motion, parent);
        nodes.push((m.name.as_str(), node));
    }
    let node_of =
        |name: &Option<String>| name.as_deref().and_then(|n| nodes.iter().find(|e| e.0 == n).map(|e| e.1));

    // Walls.
    for (i, w) in cfg.walls.iter().enumerate() {
        let opts = WallOptions { adhesion: w.adhesion, slip: w.slip };
        let node = node_of(&w.motion);
        let key = |k: &str| format!("walls[{i}].{k}");
        match w.kind {
            WallType::Tank | WallType::Block => {
                let (lo, hi) = (w.min_m.unwrap_or(Vec3::ZERO), w.max_m.unwrap_or(Vec3::ZERO));
                let mut b = Aabb::new(lo, hi);
                if dim == Dim::Two {
                    b.min.y = 0.0;
                    b.max.y = 0.0;
                }
                if w.kind == WallType::Tank {
                    let mut closed = [true; 6];
                    for face in w.open_faces.clone().unwrap_or_else(|| vec!["+z".into()]) {
                        if let Some(k) = face_index(&face) {
                            closed[k] = false;
                        }
                    }
                    sim.add_tank(&w.name, b, closed, w.layers, node, opts);
                } else {
                    sim.add_block(&w.name, b, w.layers, node, opts);
                }
            }
            WallType::Mesh => {
                let file = w
                    .file
                    .as_deref()
                    .ok_or_else(|| SphError::Setup(format!("{} is missing", key("file"))))?;
                let mesh = TriMesh::load(file, w.scale)?;
                sim.add_mesh(&w.name, mesh, w.layers, node, opts)?;
            }
            WallType::Cylinder => {
                let r = w.radius_m.unwrap_or(1.0);
                let l = w.length_m.unwrap_or(1.0);
                let facet = std::f64::consts::TAU * r / w.segments as f64;
                let rings = (l / facet).ceil().max(1.0) as usize;
                let mesh = spatter_core::shapes::cylinder(
                    w.center_m.unwrap_or(Vec3::ZERO),
                    w.axis.unwrap_or(Vec3::Y),
                    r,
                    l,
                    w.segments,
                    rings,
                );
                sim.add_mesh(&w.name, mesh, w.layers, node, opts)?;
            }
        }
    }

    // Sound speed: c₀ ≥ 10 U_max, U_max from the dam-break front speed 2√(gH) over the fill height H
    // (Ritter 1892; it bounds gravity-driven flows released from rest), the fill velocities and the wall
    // speeds over the run.
    let g = sim.params.gravity.length();
    let mut u_est: f64 = 0.0;
    for fc in &cfg.fill {
        let height = if g > 0.0 {
            let down = sim.params.gravity / g;
            let corners = (0..8).map(|k| {
                Vec3::new(
                    if k & 1 == 0 { fc.min_m.x } else { fc.max_m.x },
                    if k & 2 == 0 { fc.min_m.y } else { fc.max_m.y },
                    if k & 4 == 0 { fc.min_m.z } else { fc.max_m.z },
                )
                .dot(down)
            });
            let (lo, hi) = corners.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
            hi - lo
        } else {
            0.0
        };
        u_est = u_est.max(2.0 * (g * height).sqrt()).max(fc.velocity_m_s.length());
    }
    for k in 0..=8 {
        let t = cfg.output.end_time_s * k as f64 / 8.0;
        sim.boundary.update_kinematics(&sim.tree, t);
        u_est = u_est.max(sim.boundary.max_speed());
    }
    sim.boundary.update_kinematics(&sim.tree, 0.0);
    let u_max = f.max_velocity_m_s.unwrap_or(u_est).max(u_est);
    if u_max.is_nan() || u_max <= 0.0 {
        return Err(SphError::Setup(
            "cannot estimate the flow speed (no gravity, no fill velocity, no moving wall): set fluid.max_velocity_m_s".into(),
        ));
    }
    let c0 = match f.sound_speed_m_s {
        Some(c) if c < 10.0 * u_max => {
            return Err(SphError::Setup(format!(
                "fluid.sound_speed_m_s = {c} is below 10 × U_max = {} m/s (U_max estimated from the fill height, fill \
                 velocities and wall speeds); raise it or leave it out",
                10.0 * u_max
            )))
        }
        Some(c) => c,
        None => f.sound_speed_factor * u_max,
    };
    // With surface tension the liquid is also compressed by its cohesion and, near an adhesive wall, by
    // the adhesion: c₀ ≥ 10 √(p/ρ₀) as well (`SphParams::capillary_sound_speed`).
    let mut warnings = Vec::new();
    let max_adhesion = cfg.walls.iter().map(|w| w.adhesion).fold(0.0, f64::max);
    let c_cap = sim.params.capillary_sound_speed(max_adhesion);
    let c0 = if f.sound_speed_m_s.is_none() && c_cap > c0 {
        c_cap
    } else {
        if c_cap > c0 {
            warnings.push(format!(
                "fluid.sound_speed_m_s = {c0} m/s is below 10 √(p/ρ₀) = {c_cap:.4} m/s for the cohesive and adhesive \
                 pressure: the liquid at adhesive walls is compressed by more than 1 %"
            ));
        }
        c0
    };
    sim.params.sound_speed = c0;
    if f.surface_tension_n_m > 0.0 {
        for w in &cfg.walls {
            if let Some(note) = spatter_sph::params::SphParams::adhesion_note(w.adhesion) {
                warnings.push(format!("wall `{}`: {note}", w.name));
            }
        }
    } else if let Some(note) = inert_adhesion_note(cfg) {
        warnings.push(note);
    }

    // Fluid.
    for (i, fc) in cfg.fill.iter().enumerate() {
        let mut region = Aabb::new(fc.min_m, fc.max_m);
        if dim == Dim::Two {
            region.min.y = 0.0;
            region.max.y = 0.0;
        }
        let n = match fc.kind {
            FillType::Box => sim.fill_box(region, fc.velocity_m_s, fc.hydrostatic),
            FillType::Flood => sim
                .flood_fill(fc.seed_m.unwrap_or(region.center()), region, fc.velocity_m_s, fc.hydrostatic)
                .map_err(|e| SphError::Setup(format!("fill[{i}]: {e}")))?,
        };
        if n == 0 {
            return Err(SphError::Setup(format!(
                "fill[{i}] holds no lattice site clear of the walls (region [{}, {}, {}]–[{}, {}, {}], spacing {dp} m)",
                fc.min_m.x, fc.min_m.y, fc.min_m.z, fc.max_m.x, fc.max_m.y, fc.max_m.z
            )));
        }
    }

    // Domain, periodicity, sensors.
    if let (Some(lo), Some(hi)) = (cfg.domain.min_m, cfg.domain.max_m) {
        let mut d = Aabb::new(lo, hi);
        if dim == Dim::Two {
            d.min.y = d.min.y.min(-1.0);
            d.max.y = d.max.y.max(1.0);
        }
        sim.set_domain(d);
    }
    for a in &cfg.domain.periodic {
        if let Some(k) = axis_index(a) {
            sim.set_periodic(k);
        }
    }
    if let Some(h) = &cfg.sensors.height {
        sim.set_flux_planes((0..=h.bins).map(|k| h.base_z_m + k as f64 * h.bin_m).collect());
    }
    let info = BuildInfo {
        u_max,
        sound_speed: c0,
        fluid_particles: sim.fluid.len(),
        wall_particles: sim.boundary.len(),
        warnings,
    };
    sim.initialize_with(comm)?;
    Ok((sim, info))
}

/// Without surface tension the Akinci adhesion of every wall is zero (it is a multiple of the cohesion,
/// [`SphParams::adhesion_per_factor`]): a note naming the walls whose `adhesion` would then do nothing.
fn inert_adhesion_note(cfg: &SphConfig) -> Option<String> {
    let named: Vec<&str> = cfg.walls.iter().filter(|w| w.adhesion > 0.0).map(|w| w.name.as_str()).collect();
    (cfg.fluid.surface_tension_n_m <= 0.0 && !named.is_empty()).then(|| {
        format!(
            "fluid.surface_tension_n_m = 0: the adhesion of {} acts only with surface tension (the wall's \
             pull is a multiple of the liquid's cohesion) and has no effect in this run; set \
             surface_tension_n_m (0.072 N/m for water) for adhesion to act",
            named.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
        )
    })
}
