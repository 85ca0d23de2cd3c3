//! The scenario file of kind `sph`: every key, its unit and default (documented in `docs/sph.md`).

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;
use spatter_sph::boundary::Slip;
use spatter_sph::kernel::KernelKind;
use std::path::PathBuf;

fn d_dimensions() -> u8 {
    3
}
fn d_density() -> f64 {
    1000.0
}
fn d_ten() -> f64 {
    10.0
}
fn d_gamma() -> f64 {
    7.0
}
fn d_gravity() -> Vec3 {
    Vec3::new(0.0, 0.0, -9.81)
}
fn d_alpha() -> f64 {
    0.02
}
fn d_nu() -> f64 {
    1e-6
}
fn d_delta() -> f64 {
    0.1
}
fn d_cfl() -> f64 {
    0.2
}
fn d_one() -> f64 {
    1.0
}
fn d_window() -> [f64; 2] {
    [0.7, 1.3]
}
fn d_guard() -> f64 {
    0.2
}
fn d_true() -> bool {
    true
}
fn d_segments() -> usize {
    48
}
fn d_air_density() -> f64 {
    1.204
}
fn d_air_viscosity() -> f64 {
    1.81e-5
}

/// The whole scenario (`kind = "sph"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphConfig {
    /// Free text shown in the log.
    #[serde(default)]
    pub title: String,
    pub fluid: FluidConfig,
    #[serde(default)]
    pub drag: DragConfig,
    #[serde(default)]
    pub domain: DomainConfig,
    #[serde(default)]
    pub motions: Vec<MotionConfig>,
    #[serde(default)]
    pub walls: Vec<WallConfig>,
    pub fill: Vec<FillConfig>,
    pub output: OutputConfig,
    #[serde(default)]
    pub sensors: SensorConfig,
}

/// Fluid and numerics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidConfig {
    /// 2 (x–z plane) or 3.
    #[serde(default = "d_dimensions")]
    pub dimensions: u8,
    /// Particle spacing dp.
    pub spacing_m: f64,
    /// h/dp; default 2.0 (2D) or 1.5 (3D).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub h_over_dp: Option<f64>,
    #[serde(default)]
    pub kernel: KernelKind,
    #[serde(default = "d_density")]
    pub density_kg_m3: f64,
    /// Largest flow speed expected, U_max; default estimated from the fill height (dam-break front speed
    /// 2√(gH)), the fill velocities and the wall speeds. A given value can raise U_max above that estimate,
    /// never lower it below.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_velocity_m_s: Option<f64>,
    /// c₀ = factor · U_max, factor ≥ 10.
    #[serde(default = "d_ten")]
    pub sound_speed_factor: f64,
    /// Explicit c₀ (must still be ≥ 10 U_max).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sound_speed_m_s: Option<f64>,
    #[serde(default = "d_gamma")]
    pub gamma: f64,
    #[serde(default = "d_gravity")]
    pub gravity_m_s2: Vec3,
    #[serde(default = "d_alpha")]
    pub artificial_viscosity: f64,
    #[serde(default = "d_nu")]
    pub kinematic_viscosity_m2_s: f64,
    #[serde(default = "d_delta")]
    pub density_diffusion: f64,
    #[serde(default = "d_cfl")]
    pub cfl: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_dt_s: Option<f64>,
    #[serde(default)]
    pub shifting: f64,
    #[serde(default)]
    pub surface_tension_n_m: f64,
    #[serde(default = "d_one")]
    pub curvature_weight: f64,
    #[serde(default = "d_window")]
    pub density_window: [f64; 2],
    #[serde(default = "d_guard")]
    pub guard_offset: f64,
}

/// Air drag on the fluid particles.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DragConfig {
    #[serde(default)]
    pub enabled: bool,
    #[serde(default = "d_air_density")]
    pub air_density_kg_m3: f64,
    #[serde(default = "d_air_viscosity")]
    pub air_viscosity_pa_s: f64,
    #[serde(default)]
    pub air_velocity_m_s: Vec3,
}

impl Default for DragConfig {
    fn default() -> Self {
        DragConfig {
            enabled: false,
            air_density_kg_m3: d_air_density(),
            air_viscosity_pa_s: d_air_viscosity(),
            air_velocity_m_s: Vec3::ZERO,
        }
    }
}

/// The box particles may not leave (default: everything at t = 0, enlarged by 10 % or 10 dp).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainConfig {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_m: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_m: Option<Vec3>,
    /// Periodic axes among "x", "y", "z" (need `min_m`/`max_m`).
    #[serde(default)]
    pub periodic: Vec<String>,
    /// On several MPI ranks: the load imbalance (the most fluid particles on one rank over the mean,
    /// ≥ 1) above which the split of space is rebuilt from where the particles are; checked every 20
    /// steps. Default 1.2; `inf` keeps the first split for the whole run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rebalance_imbalance: Option<f64>,
}

impl DomainConfig {
    /// The limit for [`spatter_sph::Simulation::set_rebalance`]: `None` for never (`inf`).
    pub fn rebalance(&self) -> Option<f64> {
        spatter_core::rcb::rebalance_limit(self.rebalance_imbalance)
    }
}

pub use crate::motions::{MotionConfig, MotionType};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WallType {
    /// Container: fluid inside `min_m..max_m`, lattice walls behind the closed faces.
    Tank,
    /// Solid box, fluid outside.
    Block,
    /// STL/OBJ surface.
    Mesh,
    /// Closed cylinder (wheel).
    Cylinder,
}

/// A wall or body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallConfig {
    pub name: String,
    #[serde(rename = "type")]
    pub kind: WallType,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_m: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_m: Option<Vec3>,
    /// Tank faces left open, among "-x", "+x", "-y", "+y", "-z", "+z" (default: "+z").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub open_faces: Option<Vec<String>>,
    /// Particle layers: default ⌈2h/dp⌉ for tanks, blocks, closed meshes and cylinders (solids), 1 for
    /// open meshes (shells).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layers: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// Multiplies mesh coordinates (1e-3 for a file in millimetres).
    #[serde(default = "d_one")]
    pub scale: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub center_m: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_m: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub length_m: Option<f64>,
    #[serde(default = "d_segments")]
    pub segments: usize,
    /// Name of the motion it follows (default: fixed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<String>,
    /// Akinci adhesion β as a multiple of the cohesion γ (needs `surface_tension_n_m` > 0).
    #[serde(default)]
    pub adhesion: f64,
    #[serde(default)]
    pub slip: Slip,
    /// Write wetting maps (VTU, PNG) for this wall.
    #[serde(default = "d_true")]
    pub wetting_map: bool,
    /// View direction and up vector of the wetting PNG (default: looking at the wall's main face).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view_dir: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Vec3>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FillType {
    /// Lattice points of `min_m..max_m` outside solids and walls.
    Box,
    /// Lattice points of `min_m..max_m` reachable from `seed_m` without crossing a wall.
    Flood,
}

/// A fluid region.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FillConfig {
    #[serde(rename = "type")]
    pub kind: FillType,
    pub min_m: Vec3,
    pub max_m: Vec3,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed_m: Option<Vec3>,
    #[serde(default)]
    pub velocity_m_s: Vec3,
    /// Start with hydrostatic density below the top of the region.
    #[serde(default = "d_true")]
    pub hydrostatic: bool,
}

/// What is written and when.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputConfig {
    pub end_time_s: f64,
    /// Particle snapshots (VTU + PVD); default end_time/50.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vtu_interval_s: Option<f64>,
    /// Time-series rows (CSV); default end_time/500.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_interval_s: Option<f64>,
    /// Also write wall particles once (`walls.vtu`).
    #[serde(default)]
    pub wall_particles: bool,
    /// Top of the colour scale of the wetting PNGs (fraction of the time wet, in (0, 1]); default: the
    /// largest value of each map. A fixed cap puts the maps of several runs on one scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wetting_cap: Option<f64>,
    /// Times at which every part's wetting at that moment is written (`wetting/instant_NN/<part>.vtu` and
    /// `.png`, wet or dry on the scale 0–1) \[s\], increasing, within the run. Default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub wetting_map_times_s: Vec<f64>,
}

impl OutputConfig {
    pub fn vtu_interval(&self) -> f64 {
        self.vtu_interval_s.unwrap_or(self.end_time_s / 50.0)
    }
    pub fn sample_interval(&self) -> f64 {
        self.sample_interval_s.unwrap_or(self.end_time_s / 500.0)
    }
}

/// A point probe of pressure and velocity (Shepard interpolation of the fluid).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeConfig {
    pub name: String,
    pub position_m: Vec3,
}

/// A wall pressure sensor: mean extrapolated pressure of the wall particles within `radius_m`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallProbeConfig {
    pub name: String,
    pub position_m: Vec3,
    pub radius_m: f64,
}

/// Splash-height sensors: resident fluid volume per height bin and volume flux through the bin edges,
/// time-averaged over `window_s`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HeightConfig {
    /// Height 0 of the bins (e.g. the channel floor).
    pub base_z_m: f64,
    pub bin_m: f64,
    pub bins: usize,
    /// Averaging window [t0, t1].
    pub window_s: [f64; 2],
    /// Heights are also reported divided by this (water depth x); default: bin_m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_depth_m: Option<f64>,
}

#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorConfig {
    /// Wet criterion, normal reach \[m\]: a wall particle is wet while fluid lies within this distance of
    /// the surface point it stands for across the surface (default: 1.5 dp; shells reach dp further,
    /// `Sampling::wet_reach`) and within `wet_lateral_m` along it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wet_distance_m: Option<f64>,
    /// Wet criterion, lateral reach \[m\] along the surface (default: 0.75 dp).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wet_lateral_m: Option<f64>,
    #[serde(default)]
    pub probes: Vec<ProbeConfig>,
    #[serde(default)]
    pub wall_probes: Vec<WallProbeConfig>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height: Option<HeightConfig>,
}

/// Parses a face name like "+z".
pub fn face_index(s: &str) -> Option<usize> {
    ["-x", "+x", "-y", "+y", "-z", "+z"].iter().position(|f| *f == s)
}

/// Parses an axis name.
pub fn axis_index(s: &str) -> Option<usize> {
    ["x", "y", "z"].iter().position(|f| *f == s)
}

/// A box given by `min_m`/`max_m`; in 2D (`plane`) only x and z must increase.
fn check_box(c: &mut Checker, min: Option<Vec3>, max: Option<Vec3>, what: &str, plane: bool) {
    match (min, max) {
        (Some(lo), Some(hi)) => {
            c.finite_vec("min_m", lo);
            c.finite_vec("max_m", hi);
            let ok = lo.x < hi.x && lo.z < hi.z && (plane || lo.y < hi.y);
            if !ok {
                let which = if plane { "in x and z" } else { "in every component" };
                c.fail("max_m", format!("max_m = [{}, {}, {}] must exceed min_m {which}", hi.x, hi.y, hi.z));
            }
        }
        _ => c.fail("min_m", format!("a {what} needs `min_m` and `max_m` ([x, y, z] in metres)")),
    }
}

/// Memory per particle for the size estimate \[B\] (fluid state, neighbour lists and wall data measured
/// at about 300 B, with margin).
pub const BYTES_PER_PARTICLE: f64 = 400.0;

/// Largest accepted number of time steps, estimated before the run from `end_time_s` and the acoustic
/// time step (see [`SphConfig::estimated_steps`]).
pub const MAX_STEPS: f64 = 1e10;

impl SphConfig {
    /// A lower bound on the number of time steps: `end_time_s` over the acoustic limit
    /// 0.4 h / c₀ with c₀ = `sound_speed_factor` × the free-fall speed from the top of the highest fill
    /// (the run's own c₀ is at least this, its step at most this long); `None` without fills.
    pub fn estimated_steps(&self) -> Option<f64> {
        let dp = self.fluid.spacing_m;
        let h = self.fluid.h_over_dp.unwrap_or(if self.fluid.dimensions == 2 { 2.0 } else { 1.5 }) * dp;
        let top = self.fill.iter().map(|f| (f.max_m.z - f.min_m.z).abs()).fold(0.0, f64::max);
        let u = self.fluid.max_velocity_m_s.unwrap_or(0.0).max((2.0 * 9.81 * top).sqrt());
        let c0 = self.fluid.sound_speed_factor * u;
        (c0 > 0.0 && h > 0.0).then(|| self.output.end_time_s * c0 / (0.4 * h))
    }

    /// Rough particle count before anything is built: fill boxes over dp^d, plus tank and block walls
    /// (their surface over dp^(d−1), times the wall layers). Mesh and cylinder walls are not counted.
    pub fn estimated_particles(&self) -> f64 {
        let dp = self.fluid.spacing_m;
        let plane = self.fluid.dimensions == 2;
        let size = |a: Vec3, b: Vec3| {
            let e = (b - a).abs();
            if plane {
                e.x * e.z / (dp * dp)
            } else {
                e.x * e.y * e.z / (dp * dp * dp)
            }
        };
        let surface = |a: Vec3, b: Vec3| {
            let e = (b - a).abs();
            if plane {
                2.0 * (e.x + e.z) / dp
            } else {
                2.0 * (e.x * e.y + e.y * e.z + e.x * e.z) / (dp * dp)
            }
        };
        let fluid: f64 = self.fill.iter().map(|f| size(f.min_m, f.max_m)).sum();
        let walls: f64 = self
            .walls
            .iter()
            .filter(|w| matches!(w.kind, WallType::Tank | WallType::Block))
            .filter_map(|w| Some(surface(w.min_m?, w.max_m?) * w.layers.unwrap_or(3) as f64))
            .sum();
        fluid + walls
    }
}

/// The camera of a wall's wetting picture: `view_dir` and `up` finite and non-zero, and not parallel
/// when both are given (the picture could not be drawn; found here rather than after the run).
fn check_view(c: &mut Checker, view_dir: Option<Vec3>, up: Option<Vec3>) {
    let usable = |v: Vec3| spatter_core::math::is_finite(v) && v.length() > 0.0;
    for (key, v) in [("view_dir", view_dir), ("up", up)] {
        if let Some(v) = v.filter(|&v| !usable(v)) {
            c.fail(key, format!("{key} = {:?} must be a finite, non-zero direction [x, y, z]", v.to_array()));
        }
    }
    if let (Some(v), Some(u)) = (view_dir, up) {
        if usable(v) && usable(u) && v.normalize().cross(u.normalize()).length() < 1e-6 {
            c.fail(
                "up",
                format!(
                    "up = {:?} is parallel to view_dir = {:?}; the picture needs an up direction across the view",
                    u.to_array(),
                    v.to_array()
                ),
            );
        }
    }
}

impl Validate for SphConfig {
    fn validate(&self, c: &mut Checker) {
        c.item("fluid", &self.fluid);
        if self.fluid.spacing_m > 0.0 && self.fluid.spacing_m.is_finite() {
            let n = self.estimated_particles();
            c.nested("fluid", |c| {
                c.memory_estimate(
                    "spacing_m",
                    &format!(
                        "spacing_m = {} m gives about {n:.3e} fluid and wall particles; × {BYTES_PER_PARTICLE} B, that",
                        self.fluid.spacing_m
                    ),
                    n * BYTES_PER_PARTICLE,
                )
            });
        }
        let plane = self.fluid.dimensions == 2;
        c.nested("drag", |c| {
            c.positive("air_density_kg_m3", self.drag.air_density_kg_m3);
            c.positive("air_viscosity_pa_s", self.drag.air_viscosity_pa_s);
            c.finite_vec("air_velocity_m_s", self.drag.air_velocity_m_s);
        });
        c.nested("domain", |c| {
            let d = &self.domain;
            if d.min_m.is_some() || d.max_m.is_some() {
                check_box(c, d.min_m, d.max_m, "domain", plane);
            }
            for (i, a) in d.periodic.iter().enumerate() {
                if axis_index(a).is_none() {
                    c.element("periodic", i, |c| {
                        c.fail("", format!("periodic axis \"{a}\" must be \"x\", \"y\" or \"z\""))
                    });
                }
            }
            if !d.periodic.is_empty() && (d.min_m.is_none() || d.max_m.is_none()) {
                c.fail("periodic", "periodic axes need the domain box `min_m` and `max_m`");
            }
            if let Some(v) = d.rebalance_imbalance {
                c.in_range("rebalance_imbalance", v, 1.0, true, f64::INFINITY, true);
            }
        });
        crate::motions::check_tree(c, &self.motions);
        let wall_names: Vec<&str> = self.walls.iter().map(|w| w.name.as_str()).collect();
        for (i, w) in self.walls.iter().enumerate() {
            c.element("walls", i, |c| {
                if wall_names.iter().filter(|n| **n == w.name).count() > 1 {
                    c.fail("name", format!("name \"{}\" is used by more than one wall", w.name));
                }
                crate::motions::check_reference(c, "motion", w.motion.as_deref(), &self.motions);
                c.non_negative("adhesion", w.adhesion);
                if let Some(l) = w.layers {
                    if l == 0 {
                        c.fail("layers", "layers = 0 must be at least 1");
                    }
                }
                match w.kind {
                    WallType::Tank | WallType::Block => {
                        check_box(c, w.min_m, w.max_m, "tank or block", plane);
                        for (k, f) in w.open_faces.iter().flatten().enumerate() {
                            if face_index(f).is_none() {
                                c.element("open_faces", k, |c| {
                                    c.fail("", format!("face \"{f}\" must be one of \"-x\", \"+x\", \"-y\", \"+y\", \"-z\", \"+z\""))
                                });
                            }
                        }
                    }
                    WallType::Mesh => {
                        match &w.file {
                            Some(f) => c.mesh_file("file", f),
                            None => c.fail("file", "a mesh wall needs `file` (.stl or .obj)"),
                        }
                        c.positive("scale", w.scale);
                    }
                    WallType::Cylinder => {
                        match w.center_m {
                            Some(v) => c.finite_vec("center_m", v),
                            None => c.fail("center_m", "a cylinder needs `center_m`"),
                        }
                        match w.axis {
                            Some(a) if a.length() > 0.0 && spatter_core::math::is_finite(a) => {}
                            _ => c.fail("axis", "a cylinder needs a non-zero `axis`"),
                        }
                        match w.radius_m {
                            Some(r) => c.positive("radius_m", r),
                            None => c.fail("radius_m", "a cylinder needs `radius_m`"),
                        }
                        match w.length_m {
                            Some(l) => c.positive("length_m", l),
                            None => c.fail("length_m", "a cylinder needs `length_m`"),
                        }
                        if w.segments < 3 {
                            c.fail("segments", format!("segments = {} must be at least 3", w.segments));
                        }
                    }
                }
                if matches!(w.kind, WallType::Mesh | WallType::Cylinder) && self.fluid.dimensions == 2 {
                    c.fail("type", "mesh and cylinder walls need `dimensions = 3`");
                }
                check_view(c, w.view_dir, w.up);
            });
        }
        if self.fill.is_empty() {
            c.fail("fill", "at least one [[fill]] region is needed");
        }
        // Fluid lives inside the tanks (and the domain): a fill box that misses all of them makes no fluid.
        let tanks: Vec<(Vec3, Vec3)> = self
            .walls
            .iter()
            .filter(|w| w.kind == WallType::Tank)
            .filter_map(|w| Some((w.min_m?, w.max_m?)))
            .chain(self.domain.min_m.zip(self.domain.max_m))
            .collect();
        let overlaps = |(a, b): &(Vec3, Vec3), f: &FillConfig| {
            let axes: &[usize] = if plane { &[0, 2] } else { &[0, 1, 2] };
            axes.iter().all(|&k| f.min_m[k] < b[k] && f.max_m[k] > a[k])
        };
        for (i, f) in self.fill.iter().enumerate() {
            c.element("fill", i, |c| {
                if !tanks.is_empty() && !tanks.iter().any(|t| overlaps(t, f)) {
                    c.fail(
                        "min_m",
                        format!(
                            "the fill box [{}, {}] lies outside every tank and the domain: it would make no fluid",
                            f.min_m, f.max_m
                        ),
                    );
                }
                check_box(c, Some(f.min_m), Some(f.max_m), "fill region", plane);
                c.finite_vec("velocity_m_s", f.velocity_m_s);
                if f.kind == FillType::Flood {
                    match f.seed_m {
                        Some(s) => c.finite_vec("seed_m", s),
                        None => c.fail("seed_m", "a flood fill needs `seed_m = [x, y, z]`"),
                    }
                }
            });
        }
        c.nested("output", |c| {
            let o = &self.output;
            c.positive("end_time_s", o.end_time_s);
            if let Some(n) = self.estimated_steps().filter(|n| *n > MAX_STEPS) {
                c.fail(
                    "end_time_s",
                    format!(
                        "end_time_s = {} s needs at least {n:.3e} time steps at spacing_m = {} m (above \
                         {MAX_STEPS:e}); a run this long never ends",
                        o.end_time_s, self.fluid.spacing_m
                    ),
                );
            }
            if let Some(v) = o.vtu_interval_s {
                c.positive("vtu_interval_s", v);
            }
            if let Some(v) = o.wetting_cap {
                c.in_range("wetting_cap", v, 0.0, false, 1.0, true);
            }
            for (i, t) in o.wetting_map_times_s.iter().enumerate() {
                let before = i.checked_sub(1).map(|j| o.wetting_map_times_s[j]);
                if !(t.is_finite() && *t >= 0.0 && *t <= o.end_time_s && before.is_none_or(|b| *t > b)) {
                    c.fail(
                        &format!("wetting_map_times_s[{i}]"),
                        format!(
                            "{t} s: the times must increase and lie within the run, 0 to end_time_s = {} s",
                            o.end_time_s
                        ),
                    );
                }
            }
            if let Some(v) = o.sample_interval_s {
                c.positive("sample_interval_s", v);
            }
        });
        c.nested("sensors", |c| {
            let s = &self.sensors;
            if let Some(d) = s.wet_distance_m {
                c.positive("wet_distance_m", d);
            }
            if let Some(d) = s.wet_lateral_m {
                c.positive("wet_lateral_m", d);
            }
            for (i, p) in s.probes.iter().enumerate() {
                c.element("probes", i, |c| c.finite_vec("position_m", p.position_m));
            }
            for (i, p) in s.wall_probes.iter().enumerate() {
                c.element("wall_probes", i, |c| {
                    c.finite_vec("position_m", p.position_m);
                    c.positive("radius_m", p.radius_m);
                });
            }
            if let Some(h) = &s.height {
                c.nested("height", |c| {
                    c.finite("base_z_m", h.base_z_m);
                    c.positive("bin_m", h.bin_m);
                    if h.bins == 0 {
                        c.fail("bins", "bins = 0 must be at least 1");
                    }
                    if !(h.window_s[0] >= 0.0 && h.window_s[1] > h.window_s[0]) {
                        c.fail(
                            "window_s",
                            format!(
                                "window_s = [{}, {}] must satisfy 0 ≤ t0 < t1",
                                h.window_s[0], h.window_s[1]
                            ),
                        );
                    }
                    if let Some(x) = h.reference_depth_m {
                        c.positive("reference_depth_m", x);
                    }
                });
            }
        });
    }
}

impl Validate for FluidConfig {
    fn validate(&self, c: &mut Checker) {
        if self.dimensions != 2 && self.dimensions != 3 {
            c.fail("dimensions", format!("dimensions = {} must be 2 or 3", self.dimensions));
        }
        c.positive("spacing_m", self.spacing_m);
        if let Some(h) = self.h_over_dp {
            c.in_range("h_over_dp", h, 1.0, true, 4.0, true);
        }
        c.positive("density_kg_m3", self.density_kg_m3);
        if let Some(u) = self.max_velocity_m_s {
            c.positive("max_velocity_m_s", u);
        }
        if self.sound_speed_factor.is_nan() || self.sound_speed_factor < 10.0 {
            c.fail(
                "sound_speed_factor",
                format!("sound_speed_factor = {} must be at least 10 (c₀ ≥ 10 U_max keeps density changes below 1 %)", self.sound_speed_factor),
            );
        }
        if let Some(s) = self.sound_speed_m_s {
            c.positive("sound_speed_m_s", s);
            if let Some(u) = self.max_velocity_m_s {
                if s < 10.0 * u {
                    c.fail(
                        "sound_speed_m_s",
                        format!(
                            "sound_speed_m_s = {s} must be at least 10 × max_velocity_m_s = {}",
                            10.0 * u
                        ),
                    );
                }
            }
        }
        c.in_range("gamma", self.gamma, 1.0, true, 10.0, true);
        c.finite_vec("gravity_m_s2", self.gravity_m_s2);
        c.in_range("artificial_viscosity", self.artificial_viscosity, 0.0, true, 1.0, true);
        c.non_negative("kinematic_viscosity_m2_s", self.kinematic_viscosity_m2_s);
        c.in_range("density_diffusion", self.density_diffusion, 0.0, true, 1.0, true);
        c.in_range("cfl", self.cfl, 0.0, false, 0.5, true);
        if let Some(d) = self.max_dt_s {
            c.positive("max_dt_s", d);
        }
        c.in_range("shifting", self.shifting, 0.0, true, 10.0, true);
        c.non_negative("surface_tension_n_m", self.surface_tension_n_m);
        c.non_negative("curvature_weight", self.curvature_weight);
        let [lo, hi] = self.density_window;
        if !((0.0..1.0).contains(&lo) && hi > 1.0) {
            c.fail("density_window", format!("density_window = [{lo}, {hi}] must satisfy 0 ≤ lo < 1 < hi"));
        }
        c.in_range("guard_offset", self.guard_offset, 0.0, false, 1.0, true);
    }
}

impl spatter_io::run::Smoke for SphConfig {
    /// 2.5 ms of simulated time (a few tens of steps at the usual spacings), two snapshots, five samples.
    fn smoke(&mut self) {
        let end = self.output.end_time_s.min(2.5e-3);
        self.output.end_time_s = end;
        self.output.vtu_interval_s = Some(end / 2.0);
        self.output.sample_interval_s = Some(end / 5.0);
    }
}
