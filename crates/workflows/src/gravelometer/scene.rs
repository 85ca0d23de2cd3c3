//! From a gravelometer configuration to a DEM scene: the generated meshes written as STL, the stone
//! templates, the launch velocity, the injector, and the event log that the results are read from. The
//! scene then runs through the DEM scene machinery ([`crate::dem_scene::run_collect`]).

use super::air::PipeAir;
use super::config::{get, AirMode, GravelometerConfig, StoneShape};
use super::geometry::{self, Dimensions, PanelFrame};
use super::GravelometerError;
use crate::dem_scene::events::{CrossingPlane, EventsConfig, TrajectoryConfig};
use crate::dem_scene::{
    ClumpMixConfig, EngineConfig, InjectConfig, OutputConfig, Packing, PairOverride, PairValues, RatioBasis,
    RegionConfig, SceneConfig, ShapeConfig, TemplateConfig, TemplateShape, WallConfig, WearConfig, WearKind,
};
use crate::fluid_forces::{FluidForceOptions, FluidForces, PrescribedFlow};
use spatter_core::material::{effective_modulus, Material};
use spatter_core::timestep::hertz_time;
use spatter_core::Vec3;
use spatter_dem::clump::ClumpTemplate;
use spatter_flow::forces::Fluid;
use std::collections::BTreeMap;
use std::path::Path;

/// Names of the generated walls.
pub const PANEL: &str = "panel";
pub const CLAMP: &str = "clamp";
pub const PIPE: &str = "pipe";
pub const BOX: &str = "protection_box";

/// Largest stone volume fraction the pipe is taken to pass at the launch speed (dense-phase conveying
/// begins around 0.2–0.3; above it the stones would queue at the inlet).
pub const MAX_PIPE_LOADING: f64 = 0.2;

/// Gravitational acceleration \[m/s²\].
pub const GRAVITY: Vec3 = Vec3::new(0.0, 0.0, -9.81);

/// Steps per Hertz contact of a stone on a wall (see `spatter_dem::timestep`).
const STEPS_PER_CONTACT: f64 = 20.0;

/// One stone template with the numbers the workflow needs.
#[derive(Clone, Debug)]
pub struct Stone {
    pub name: String,
    pub config: TemplateConfig,
    pub template: ClumpTemplate,
    /// Mass of one stone \[kg\].
    pub mass: f64,
    /// Volume-equivalent diameter \[m\].
    pub diameter: f64,
    /// Number ratio in the mix.
    pub ratio: f64,
}

/// Everything derived from the configuration before the run.
#[derive(Clone, Debug)]
pub struct Plan {
    pub dims: Dimensions,
    pub frame: PanelFrame,
    pub stones: Vec<Stone>,
    /// Mass-weighted mean volume-equivalent diameter of the mix \[m\].
    pub mean_diameter: f64,
    pub density: f64,
    /// Launch velocity at the pipe inlet \[m/s\].
    pub launch: Vec3,
    /// Time step \[s\].
    pub dt: f64,
    /// Stones fed per second (number) or kg per second.
    pub count_per_s: Option<f64>,
    pub kg_per_s: f64,
    pub feed_time: f64,
    /// Largest bounding radius of a stone \[m\].
    pub stone_radius: f64,
    /// The prescribed air field (`air = "prescribed"`), else `None`.
    pub air: Option<PipeAir>,
    /// The fastest the air is expected to blow \[m/s\]: the prescribed centreline speed, 1.3 × the
    /// bulk speed with coupled air (a developed pipe profile peaks at 1.22 U_b), 0 without air.
    pub air_speed: f64,
}

fn config_error(key: &str, message: String) -> GravelometerError {
    GravelometerError::Config { key: key.to_string(), message }
}

/// The stone templates of the configuration, packed and measured.
fn stones(cfg: &GravelometerConfig) -> Result<Vec<Stone>, GravelometerError> {
    let s = &cfg.input.stones;
    let member = get(s.member_diameter_m);
    let density = get(s.density_kg_m3);
    let configs: Vec<(String, TemplateConfig)> = match get(s.shape) {
        StoneShape::Sphere => vec![(
            "ball".to_string(),
            TemplateConfig {
                shape: TemplateShape::Ball { radius_m: 0.5 * get(s.sphere_diameter_m) },
                packing: Some(Packing::Equal { sphere_diameter_m: member }),
                mass_basis: None,
                mass_kg: None,
            },
        )],
        StoneShape::Standard => s
            .templates
            .iter()
            .flatten()
            .map(|(n, t)| {
                let mut t = t.clone();
                // Generated shapes without their own packing take the members of `member_diameter_m`.
                let file = matches!(t.shape, TemplateShape::Spheres { .. });
                if t.packing.is_none() && !file {
                    t.packing = Some(Packing::Equal { sphere_diameter_m: member });
                }
                (n.clone(), t)
            })
            .collect(),
    };
    let ratios = match get(s.shape) {
        StoneShape::Sphere => vec![1.0],
        StoneShape::Standard => s.ratios.clone().unwrap_or_else(|| vec![1.0; configs.len()]),
    };
    let mut out = Vec::new();
    for ((name, config), ratio) in configs.into_iter().zip(ratios) {
        let template = config.build(&name).map_err(|e| match e {
            spatter_dem::error::DemError::Config { key, message } => {
                config_error(&format!("stones.{key}"), message)
            }
            other => GravelometerError::Dem(other),
        })?;
        let mass = template.body_mass(density).0;
        let diameter = (6.0 * mass / (density * std::f64::consts::PI)).cbrt();
        out.push(Stone { name, config, template, mass, diameter, ratio });
    }
    Ok(out)
}

/// The empirical horizontal launch speed of stones leaving the feeder \[m/s\]:
/// v_h = K_h · Q_f / (ρ_p^{1/3} · D), with Q_f the air flow rate \[m³/s\], ρ_p the stone density
/// \[kg/m³\] and D the volume-equivalent diameter \[m\].
///
/// Qian et al. (2022) fit v_h as proportional to the air flow rate and falling with the stones' density
/// and size, with K_h = 59.6; the fitted expression itself did not survive in the published text, so
/// the form ρ_p^{1/3} D (the cube root of the stone mass up to a constant) is an assumption chosen to
/// give launch speeds of the measured order (13 m/s for the DIN grit, 26 m/s for SAE gravel).
pub fn empirical_launch_speed(k_h: f64, flow_m3_s: f64, density: f64, diameter: f64) -> f64 {
    k_h * flow_m3_s / (density.cbrt() * diameter)
}

/// Vertical speed of a stone entering the pipe after falling `height` from the feeder and bouncing
/// with restitution `e`: −e √(2 g h) (downwards).
pub fn feeder_vertical_speed(height: f64, e: f64, g: f64) -> f64 {
    -e * (2.0 * g * height).sqrt()
}

/// Derives the plan and checks what needs the built templates (stone size against the pipe, pipe
/// loading).
pub fn plan(cfg: &GravelometerConfig) -> Result<Plan, GravelometerError> {
    let i = &cfg.input;
    let dims = Dimensions {
        pipe_diameter: get(i.pipe.diameter_m),
        pipe_length: get(i.pipe.length_m),
        panel_width: get(i.panel.width_m),
        panel_length: get(i.panel.length_m),
        panel_angle_deg: get(i.panel.angle_deg),
        panel_distance: get(i.panel.distance_m),
        triangle_size: get(i.panel.triangle_size_m),
        strips: get(i.panel.strips),
        clamp_bar_width: get(i.clamp.bar_width_m),
        clamp_thickness: get(i.clamp.thickness_m),
        box_margin: get(i.protection_box.margin_m),
    };
    let stones = stones(cfg)?;
    let density = get(i.stones.density_kg_m3);
    // A stone's size: the member spheres' bounding sphere, or half the volume-equivalent diameter when
    // coarse members leave the stone's rim empty.
    let size = |s: &Stone| s.template.bounding_radius().max(0.5 * s.diameter);
    let stone_radius = stones.iter().map(size).fold(0.0, f64::max);
    let r_pipe = 0.5 * dims.pipe_diameter;
    if stone_radius >= 0.8 * r_pipe {
        let widest = stones.iter().max_by(|a, b| size(a).total_cmp(&size(b)));
        return Err(config_error(
            "stones",
            format!(
                "stone `{}` spans {:.1} mm across; the pipe (pipe.diameter_m = {}) needs room for it to fly: \
                 its diameter must exceed the stone's by 25 % (more than {:.1} mm)",
                widest.map_or("?", |s| s.name.as_str()),
                2e3 * stone_radius,
                dims.pipe_diameter,
                2e3 * stone_radius / 0.8
            ),
        ));
    }
    if stone_radius > 0.25 * dims.panel_distance {
        return Err(config_error(
            "panel.distance_m",
            format!(
                "panel.distance_m = {} leaves no room for stones of {:.1} mm",
                dims.panel_distance,
                2e3 * stone_radius
            ),
        ));
    }
    // Mix means (by mass): the diameter in the launch formula.
    let w: Vec<f64> = stones.iter().map(|s| s.ratio * s.mass).collect();
    let wsum: f64 = w.iter().sum();
    let mean_diameter = stones.iter().zip(&w).map(|(s, w)| s.diameter * w).sum::<f64>() / wsum;
    let mean_mass = wsum / stones.iter().map(|s| s.ratio).sum::<f64>();
    let g = 9.81;
    let vh = match i.launch.speed_m_s {
        Some(v) => v,
        None => {
            empirical_launch_speed(get(i.launch.k_h), get(i.launch.air_flow_m3_s), density, mean_diameter)
        }
    };
    let vz = feeder_vertical_speed(get(i.launch.fall_height_m), get(i.launch.feeder_restitution), g);
    let launch = Vec3::new(vh, 0.0, vz);
    let feed_time = get(i.stones.feed_time_s);
    let (count_per_s, kg_per_s) = match i.stones.count {
        Some(n) => (Some(n as f64 / feed_time), n as f64 * mean_mass / feed_time),
        None => (None, get(i.stones.charge_kg) / feed_time),
    };
    // Pipe loading: the stone volume flux against what the pipe passes at the launch speed.
    let area = std::f64::consts::PI * r_pipe * r_pipe;
    let flux = kg_per_s / density;
    // The stones move at least at their launch speed; prescribed air drags them to the air's speed.
    let carrier = match cfg.air() {
        AirMode::Prescribed | AirMode::Coupled => vh.max(get(i.pipe.air_velocity_m_s)),
        _ => vh,
    };
    let capacity = MAX_PIPE_LOADING * area * carrier;
    if flux > capacity {
        return Err(config_error(
            "stones.charge_kg",
            format!(
                "the feed of {kg_per_s:.4} kg/s ({flux:.3e} m³/s of stone) is more than the pipe passes: at the \
                 speed of {carrier:.2} m/s a {} m pipe carries at most {capacity:.3e} m³/s (a stone volume \
                 fraction of {MAX_PIPE_LOADING}); lower stones.charge_kg or stones.count, or lengthen \
                 stones.feed_time_s",
                dims.pipe_diameter
            ),
        ));
    }
    let air = (cfg.air() == AirMode::Prescribed).then(|| {
        let a = &i.air_field;
        PipeAir {
            length: dims.pipe_length,
            radius: r_pipe,
            bulk: get(i.pipe.air_velocity_m_s),
            exponent: get(a.profile_exponent),
            ramp: get(a.ramp_s),
            outside: get(a.outside),
        }
    });
    let air_speed = match cfg.air() {
        AirMode::None => 0.0,
        AirMode::Prescribed => air.as_ref().map_or(0.0, PipeAir::centreline),
        AirMode::Coupled => 1.3 * get(i.pipe.air_velocity_m_s),
    };
    let dt = match i.dt_s {
        Some(dt) => dt,
        None => auto_dt(cfg, &stones, top_speed(launch, air_speed)),
    };
    let frame = PanelFrame::new(&dims);
    Ok(Plan {
        dims,
        frame,
        stones,
        mean_diameter,
        density,
        launch,
        dt,
        count_per_s,
        kg_per_s,
        feed_time,
        stone_radius,
        air,
        air_speed,
    })
}

/// The one-way fluid forces of the prescribed air on every member sphere (drag by `air_field.drag`,
/// the K-correction, Archimedes buoyancy), or `None` without prescribed air.
pub fn air_forces(
    cfg: &GravelometerConfig,
    plan: &Plan,
) -> Option<Box<dyn spatter_dem::sim::ExternalForces>> {
    let air = plan.air?;
    let a = &cfg.input.air_field;
    let fluid = Fluid { density: get(a.density_kg_m3), viscosity: get(a.viscosity_pa_s) };
    let options = FluidForceOptions {
        fluid,
        drag: get(a.drag),
        k_correction: get(a.k_correction),
        pressure_force: true,
    };
    let sampler = PrescribedFlow::new(air, fluid.density, GRAVITY);
    Some(Box::new(FluidForces::new(sampler, options)))
}

/// The fastest a stone is expected to fly \[m/s\]: its launch speed, or the air's top speed
/// `air_speed` when that is faster.
pub fn top_speed(launch: Vec3, air_speed: f64) -> f64 {
    launch.length().max(air_speed)
}

fn stone_material(cfg: &GravelometerConfig) -> Material {
    let s = &cfg.input.stones;
    Material {
        youngs_modulus: get(s.youngs_modulus_pa),
        poisson_ratio: get(s.poisson_ratio),
        density: get(s.density_kg_m3),
    }
}

fn wall_material(cfg: &GravelometerConfig, density: f64) -> Material {
    let w = &cfg.input.walls;
    Material { youngs_modulus: get(w.youngs_modulus_pa), poisson_ratio: get(w.poisson_ratio), density }
}

/// Time step: 1/20 of the Hertz contact time of a stone on a wall at 1.5 × the launch speed, on its
/// smallest member, with a quarter of the stone's mass as the contact's effective mass (a contact off
/// the centre of mass also turns the stone: 1/m_eff = 1/m + r²/I, about 4/m for a compact stone hit at
/// its rim). The Rayleigh criterion of free spheres does not apply: the members of a rigid body carry
/// no elastic waves of their own.
fn auto_dt(cfg: &GravelometerConfig, stones: &[Stone], speed: f64) -> f64 {
    let m = stone_material(cfg);
    let w = wall_material(cfg, 7850.0);
    let e = effective_modulus(&m, &w);
    let mut dt = f64::INFINITY;
    for s in stones {
        let r = s.template.spheres.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
        dt = dt.min(hertz_time(0.25 * s.mass, r, e, 1.5 * speed.max(1.0)) / STEPS_PER_CONTACT);
    }
    dt
}

/// The strip (1 at the top) of each panel triangle, as [`write_geometry`] returns it, without writing.
pub fn strips(plan: &Plan) -> Vec<usize> {
    geometry::panel(&plan.dims).1
}

/// Writes the generated meshes to `dir` (STL) and returns the panel's strip of every triangle.
pub fn write_geometry(plan: &Plan, dir: &Path) -> Result<Vec<usize>, GravelometerError> {
    std::fs::create_dir_all(dir).map_err(|source| GravelometerError::Io { path: dir.to_owned(), source })?;
    let (panel, strips) = geometry::panel(&plan.dims);
    for (name, mesh) in [
        (PANEL, panel),
        (CLAMP, geometry::clamp(&plan.dims)),
        (PIPE, geometry::pipe(&plan.dims)),
        (BOX, geometry::protection_box(&plan.dims)),
    ] {
        let path = dir.join(format!("{name}.stl"));
        std::fs::write(&path, mesh.to_binary_stl())
            .map_err(|source| GravelometerError::Io { path, source })?;
    }
    Ok(strips)
}

/// The DEM scene of the run; meshes are read from `geometry` (see [`write_geometry`]).
pub fn scene(cfg: &GravelometerConfig, plan: &Plan, geometry: &Path) -> SceneConfig {
    let i = &cfg.input;
    let mut materials = BTreeMap::new();
    materials.insert("stone".to_string(), stone_material(cfg));
    materials.insert("steel".to_string(), wall_material(cfg, 7850.0));
    materials.insert("coating".to_string(), wall_material(cfg, get(i.walls.coating_density_kg_m3)));
    let c = &i.contact;
    let wall_pair = |other: &str| PairOverride {
        materials: ["stone".to_string(), other.to_string()],
        friction: c.stone_wall_friction,
        restitution: c.stone_wall_restitution,
        rolling_friction: None,
        rolling_viscous_s_m: None,
        work_of_adhesion_j_m2: None,
        restitution_model: None,
        yield_stress_pa: None,
        thornton_form: None,
        stiffness_n_m: None,
        cohesion_stiffness_n_m: None,
    };
    let mesh = |name: &str, material: &str| WallConfig {
        name: name.to_string(),
        material: material.to_string(),
        shape: ShapeConfig::Mesh { file: geometry.join(format!("{name}.stl")), scale: 1.0 },
        motion: None,
    };
    let templates: BTreeMap<String, TemplateConfig> =
        plan.stones.iter().map(|s| (s.name.clone(), s.config.clone())).collect();
    let r_pipe = 0.5 * plan.dims.pipe_diameter;
    let region_height = 3.0 * 2.0 * plan.stone_radius;
    let vh = plan.launch.x.max(1e-3);
    let box_bounds = geometry::box_bounds(&plan.dims);
    let pipe_min = Vec3::new(-plan.dims.pipe_length, -r_pipe, -r_pipe);
    let margin = Vec3::splat(0.05);
    let inject = InjectConfig {
        material: "stone".to_string(),
        region: RegionConfig::Cylinder {
            base_m: Vec3::new(-plan.dims.pipe_length + 0.5 * plan.stone_radius, 0.0, 0.0),
            axis: Vec3::X,
            radius_m: (r_pipe - plan.stone_radius) * 0.95,
            height_m: region_height,
        },
        size: None,
        clumps: Some(ClumpMixConfig {
            templates: plan.stones.iter().map(|s| s.name.clone()).collect(),
            ratios: Some(plan.stones.iter().map(|s| s.ratio).collect()),
            basis: RatioBasis::Number,
        }),
        particles_per_s: plan.count_per_s,
        kg_per_s: if plan.count_per_s.is_some() { None } else { Some(plan.kg_per_s) },
        start_s: 0.0,
        end_s: Some(plan.feed_time),
        velocity_m_s: plan.launch,
        // A stone clears the inlet region in region_height / v; place every half of that.
        interval_s: (0.5 * region_height / vh).max(plan.dt).min(plan.feed_time),
        attempts: 200,
    };
    let out_interval = get(i.output.output_interval_s);
    SceneConfig {
        dt_s: plan.dt,
        duration_s: get(i.duration_s),
        output_interval_s: out_interval,
        gravity_m_s2: GRAVITY,
        seed: get(i.seed),
        contact: Default::default(),
        engine: EngineConfig {
            domain_min_m: Some(pipe_min.min(box_bounds.min) - margin),
            domain_max_m: Some(box_bounds.max + margin),
            impact_speed_m_s: Some(1.5 * top_speed(plan.launch, plan.air_speed).max(1.0)),
            ..Default::default()
        },
        materials,
        pair_defaults: PairValues {
            friction: get(c.stone_stone_friction),
            restitution: get(c.stone_stone_restitution),
            ..Default::default()
        },
        pairs: vec![wall_pair("steel"), wall_pair("coating")],
        walls: vec![mesh(PANEL, "coating"), mesh(CLAMP, "steel"), mesh(PIPE, "steel"), mesh(BOX, "steel")],
        motions: Vec::new(),
        fill: Vec::new(),
        inject: vec![inject],
        templates,
        pour: None,
        bed: None,
        probe: None,
        wear: vec![WearConfig {
            particle_material: "stone".to_string(),
            wall_material: "coating".to_string(),
            model: WearKind::Finnie,
            k_s2_m2: i.wear.k_s2_m2,
            coefficient_kg_j: None,
            threshold_j: 0.0,
        }],
        output: OutputConfig {
            particles_vtu: get(i.output.particles_vtu),
            mesh_vtu: true,
            events: Some(EventsConfig {
                angle_plane_normal: Some(Vec3::Y),
                crossing_plane: Some(CrossingPlane { point_m: Vec3::ZERO, normal: Vec3::X }),
                first_impact_walls: vec![PANEL.to_string(), CLAMP.to_string(), BOX.to_string()],
            }),
            trajectories: Some(TrajectoryConfig {
                every_steps: ((1e-4 / plan.dt).round() as u64).max(1),
                ids: Vec::new(),
                first: 1,
            }),
            bed_file: None,
            packing: Vec::new(),
        },
    }
}
