//! The DEM scene configuration (`kind = "dem"` scenario files). Every key is documented in `docs/dem.md`.

pub use super::clumps::{
    ClumpMixConfig, MassBasisKind, Packing, RatioBasis, TemplateConfig, TemplateShape, WearConfig, WearKind,
};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::distribution::SizeDistribution;
use spatter_core::material::Material;
use spatter_core::Vec3;
use spatter_dem::adhesion::{AdhesiveCoulomb, BreakCriterion, JkrDamping};
use spatter_dem::contact::RestitutionCalibration;
use spatter_dem::insertion::Lattice;
use spatter_dem::sim::Integrator;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A DEM scene: materials, pairs, walls, particles, time stepping and outputs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneConfig {
    /// Time step \[s\].
    pub dt_s: f64,
    /// Simulated time \[s\].
    pub duration_s: f64,
    /// Interval between outputs (energy row, VTU snapshots) \[s\].
    #[serde(default = "default_output_interval")]
    pub output_interval_s: f64,
    /// Gravitational acceleration \[m/s²\].
    #[serde(default = "default_gravity")]
    pub gravity_m_s2: Vec3,
    /// Seed of every random choice (fills, injections).
    #[serde(default)]
    pub seed: u64,
    #[serde(default)]
    pub contact: ContactConfig,
    #[serde(default)]
    pub engine: EngineConfig,
    /// Materials by name (particles and walls).
    pub materials: BTreeMap<String, Material>,
    /// Pair values for every material pair not listed in `pairs`.
    #[serde(default)]
    pub pair_defaults: PairValues,
    /// Per-pair overrides.
    #[serde(default)]
    pub pairs: Vec<PairOverride>,
    #[serde(default)]
    pub walls: Vec<WallConfig>,
    /// Prescribed motions, a tree (see [`crate::motions`]); walls name the node they follow.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub motions: Vec<MotionConfig>,
    /// Particles placed at t = 0.
    #[serde(default)]
    pub fill: Vec<FillConfig>,
    /// Particles injected over time.
    #[serde(default)]
    pub inject: Vec<InjectConfig>,
    /// Clump templates (rigid bodies made of spheres) by name.
    #[serde(default)]
    pub templates: BTreeMap<String, TemplateConfig>,
    /// Erosion wear of mesh walls per (particle material, wall material).
    #[serde(default)]
    pub wear: Vec<WearConfig>,
    /// A sparse pour that builds a bed (see `docs/bed.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pour: Option<PourConfig>,
    /// Start from the spheres of a bed file (see `docs/bed.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bed: Option<BedStart>,
    /// A probe driven into the bed (see `docs/bed.md`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probe: Option<ProbeConfig>,
    #[serde(default)]
    pub output: OutputConfig,
}

/// `[bed]`: the spheres of a bed file are placed at t = 0, before the fills.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BedStart {
    /// The bed file (relative to the scenario file's folder), e.g. the `bed.txt` a pour wrote.
    pub file: PathBuf,
}

/// A box whose packing density is reported (`[[output.packing]]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PackingRegion {
    /// Name in the summary (`packing_<name>`) and in `packing.csv`.
    pub name: String,
    /// Lower corner \[m\].
    pub min_m: Vec3,
    /// Upper corner \[m\].
    pub max_m: Vec3,
}

fn default_output_interval() -> f64 {
    0.01
}
fn default_gravity() -> Vec3 {
    Vec3::new(0.0, 0.0, -9.81)
}
fn yes() -> bool {
    true
}

/// Which contact laws to compose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactConfig {
    /// `hertz` (default), `hooke`, `jkr`, `dmt` or `sjkr`.
    #[serde(default)]
    pub normal: NormalKind,
    /// Hooke: constant stiffness \[N/m\] …
    #[serde(default)]
    pub hooke_stiffness_n_m: Option<f64>,
    /// … or the characteristic impact speed \[m/s\] from which k_n is derived.
    #[serde(default)]
    pub hooke_characteristic_speed_m_s: Option<f64>,
    /// `mindlin` (default, k_t = 8G*a, F = k_t ξ), `mindlin_rescale`, `mindlin_force`,
    /// `mindlin_rescale_force` (how the Mindlin history follows the contact radius, see
    /// [`spatter_dem::contact::MindlinHistory`]) or `linear` (k_t = ratio × k_n).
    #[serde(default)]
    pub tangential: TangentialKind,
    /// k_t / k_n of the linear tangential spring (default 2/7).
    #[serde(default = "default_linear_ratio")]
    pub linear_stiffness_ratio: f64,
    /// `none` (default), `constant_torque` or `viscous`.
    #[serde(default)]
    pub rolling: spatter_dem::contact::AnyRolling,
    /// Damping may not make the normal force tensile (default true).
    #[serde(default = "yes")]
    pub tensile_clamp: bool,
    /// `exact` (default) or `linearised` restitution calibration.
    #[serde(default)]
    pub damping_calibration: RestitutionCalibration,
    /// Tangential dashpot (default true).
    #[serde(default = "yes")]
    pub tangential_damping: bool,
    /// JKR: `critical_overlap` (default) or `pull_off_force`.
    #[serde(default)]
    pub jkr_break: BreakCriterion,
    /// JKR damping stiffness: `overlap` (default) or `contact_radius`.
    #[serde(default)]
    pub jkr_damping: JkrDamping,
    /// Adhesive laws' Coulomb force: `plus_twice_pull_off` (default), `hertz` or `total`.
    #[serde(default)]
    pub adhesive_coulomb: AdhesiveCoulomb,
    /// Hooke and Hertz: the normal force that caps friction, `total` (after damping, default) or
    /// `elastic` ([`spatter_dem::contact::CoulombLoad`]).
    #[serde(default)]
    pub coulomb_load: spatter_dem::contact::CoulombLoad,
    /// Hooke with linear cohesion: cohesion radius over particle radius, r_coh/r ≥ 1 (default 1.1, the
    /// value of Jasion 2013, Table C.2). Acts only in pairs with `cohesion_stiffness_n_m` > 0.
    #[serde(default = "default_cohesion_ratio")]
    pub cohesion_radius_ratio: f64,
}

fn default_cohesion_ratio() -> f64 {
    1.1
}

fn default_linear_ratio() -> f64 {
    2.0 / 7.0
}

impl Default for ContactConfig {
    fn default() -> Self {
        ContactConfig {
            normal: NormalKind::Hertz,
            hooke_stiffness_n_m: None,
            hooke_characteristic_speed_m_s: None,
            tangential: TangentialKind::Mindlin,
            linear_stiffness_ratio: default_linear_ratio(),
            rolling: Default::default(),
            tensile_clamp: true,
            damping_calibration: RestitutionCalibration::Exact,
            tangential_damping: true,
            jkr_break: Default::default(),
            jkr_damping: Default::default(),
            adhesive_coulomb: Default::default(),
            coulomb_load: Default::default(),
            cohesion_radius_ratio: default_cohesion_ratio(),
        }
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NormalKind {
    #[default]
    Hertz,
    Hooke,
    Jkr,
    Dmt,
    Sjkr,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TangentialKind {
    #[default]
    Mindlin,
    MindlinRescale,
    MindlinForce,
    MindlinRescaleForce,
    Linear,
}

impl TangentialKind {
    /// The Mindlin history rule of a Mindlin kind (`None` for `linear`).
    pub fn mindlin_history(self) -> Option<spatter_dem::contact::MindlinHistory> {
        use spatter_dem::contact::MindlinHistory as H;
        match self {
            TangentialKind::Mindlin => Some(H::Displacement),
            TangentialKind::MindlinRescale => Some(H::DisplacementRescaled),
            TangentialKind::MindlinForce => Some(H::Force),
            TangentialKind::MindlinRescaleForce => Some(H::ForceRescaled),
            TangentialKind::Linear => None,
        }
    }
}

/// Engine options.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EngineConfig {
    /// `velocity_verlet` (default), `symplectic_euler` (or `se`), or one of the study schemes `fe`,
    /// `rk2`, `rk4`, `ab2`, `ab4`, `abm4`, `bd1`, `bd2`, `bd4` (spheres only).
    #[serde(default)]
    pub integrator: Integrator,
    /// Fixed-point iterations per step of the implicit `bd1`, `bd2`, `bd4` (required by them, ≥ 1).
    #[serde(default)]
    pub iterations: Option<u32>,
    /// Verlet skin \[m\] (default 10 % of the largest diameter).
    #[serde(default)]
    pub skin_m: Option<f64>,
    /// Keep a Verlet list between rebuilds (default true).
    #[serde(default = "yes")]
    pub verlet_list: bool,
    /// Blow-up when an overlap exceeds this fraction of the smaller radius (default 0.25).
    #[serde(default = "default_overlap_fraction")]
    pub max_overlap_fraction: f64,
    /// Particles leaving the box `[domain_min_m, domain_max_m]` are removed and counted.
    #[serde(default)]
    pub domain_min_m: Option<Vec3>,
    #[serde(default)]
    pub domain_max_m: Option<Vec3>,
    /// Highest impact speed expected \[m/s\], for the Hertz time-step check (default: from gravity, the
    /// scene height and the initial and injection speeds).
    #[serde(default)]
    pub impact_speed_m_s: Option<f64>,
    /// Book elastic and dissipated energy per contact (default true; false is ~10 % faster and leaves
    /// `elastic_J` and `dissipated_J` at zero).
    #[serde(default = "yes")]
    pub track_energy: bool,
    /// How elastic and dissipated energy are obtained when `track_energy` is on: `"residual"` (default;
    /// elastic energy booked only in output steps, dissipation as the residual of the energy balance, which
    /// also holds the integrator's O(Δt²) energy error) or `"per_contact"` (every contact books its
    /// dashpot, slip and rolling work in every step; about 15 % slower).
    #[serde(default = "residual")]
    pub energy_method: spatter_dem::sim::EnergyMethod,
    /// The mass a clump member stands for in its contacts: `body` (default) or `member_share`.
    #[serde(default)]
    pub clump_contact_mass: spatter_dem::sim::ClumpContactMass,
    /// Integrate the spins of the spheres (default true); false keeps every sphere at ω = 0.
    #[serde(default = "yes")]
    pub rotation: bool,
    /// On several MPI ranks: the load imbalance (the most particles on one rank over the mean, ≥ 1)
    /// above which the split of space is rebuilt at a neighbour-list rebuild. Default 1.2; `inf` keeps
    /// the first split for the whole run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rebalance_imbalance: Option<f64>,
}

impl EngineConfig {
    /// The limit for [`spatter_dem::sim::Simulation::set_rebalance`]: `None` for never (`inf`).
    pub fn rebalance(&self) -> Option<f64> {
        spatter_core::rcb::rebalance_limit(self.rebalance_imbalance)
    }
}

fn residual() -> spatter_dem::sim::EnergyMethod {
    spatter_dem::sim::EnergyMethod::Residual
}

fn default_overlap_fraction() -> f64 {
    0.25
}

impl Default for EngineConfig {
    fn default() -> Self {
        EngineConfig {
            integrator: Integrator::VelocityVerlet,
            iterations: None,
            skin_m: None,
            verlet_list: true,
            max_overlap_fraction: default_overlap_fraction(),
            domain_min_m: None,
            domain_max_m: None,
            impact_speed_m_s: None,
            track_energy: true,
            energy_method: residual(),
            clump_contact_mass: Default::default(),
            rotation: true,
            rebalance_imbalance: None,
        }
    }
}

/// Values of a material pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairValues {
    /// Sliding friction μ (default 0.5).
    #[serde(default = "half")]
    pub friction: f64,
    /// Coefficient of restitution e ∈ (0, 1] (default 0.5).
    #[serde(default = "half")]
    pub restitution: f64,
    /// Constant-torque rolling friction μ_r (default 0).
    #[serde(default)]
    pub rolling_friction: f64,
    /// Viscous rolling coefficient \[s/m\] (default 0).
    #[serde(default)]
    pub rolling_viscous_s_m: f64,
    /// Work of adhesion Γ \[J/m²\] for `jkr`, `dmt`, `sjkr` (default 0).
    #[serde(default)]
    pub work_of_adhesion_j_m2: f64,
    /// `constant` (default: `restitution`) or `thornton` (e(V) from `yield_stress_pa`, fixed per contact
    /// at its impact speed).
    #[serde(default)]
    pub restitution_model: RestitutionKind,
    /// Yield stress σ_y \[Pa\] of `thornton` (p_y = 2.5 σ_y); required there, not allowed otherwise.
    #[serde(default)]
    pub yield_stress_pa: Option<f64>,
    /// `full` (default) or `power_law` form of Thornton's e(V).
    #[serde(default)]
    pub thornton_form: spatter_dem::restitution_models::ThorntonForm,
    /// `normal = "hooke"`: the pair's own linear stiffness k_n \[N/m\] (default: the global
    /// `contact.hooke_*` choice). A particle–wall pair sets the wall stiffness this way.
    #[serde(default)]
    pub stiffness_n_m: Option<f64>,
    /// `normal = "hooke"`: linear cohesion stiffness k_coh ≥ 0 \[N/m\] (default 0 = none).
    #[serde(default)]
    pub cohesion_stiffness_n_m: f64,
}

/// How a pair's coefficient of restitution is given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RestitutionKind {
    /// The same e at every impact speed (`restitution`).
    #[default]
    Constant,
    /// Thornton's (1997) elastic–perfectly-plastic e(V), yield velocity from the contact's E*, R*, m*.
    Thornton,
}

fn half() -> f64 {
    0.5
}

impl Default for PairValues {
    fn default() -> Self {
        PairValues {
            friction: 0.5,
            restitution: 0.5,
            rolling_friction: 0.0,
            rolling_viscous_s_m: 0.0,
            work_of_adhesion_j_m2: 0.0,
            restitution_model: RestitutionKind::Constant,
            yield_stress_pa: None,
            thornton_form: Default::default(),
            stiffness_n_m: None,
            cohesion_stiffness_n_m: 0.0,
        }
    }
}

/// Values of one named pair; unset keys keep `pair_defaults`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PairOverride {
    /// The two material names.
    pub materials: [String; 2],
    #[serde(default)]
    pub friction: Option<f64>,
    #[serde(default)]
    pub restitution: Option<f64>,
    #[serde(default)]
    pub rolling_friction: Option<f64>,
    #[serde(default)]
    pub rolling_viscous_s_m: Option<f64>,
    #[serde(default)]
    pub work_of_adhesion_j_m2: Option<f64>,
    #[serde(default)]
    pub restitution_model: Option<RestitutionKind>,
    #[serde(default)]
    pub yield_stress_pa: Option<f64>,
    #[serde(default)]
    pub thornton_form: Option<spatter_dem::restitution_models::ThorntonForm>,
    #[serde(default)]
    pub stiffness_n_m: Option<f64>,
    #[serde(default)]
    pub cohesion_stiffness_n_m: Option<f64>,
}

/// A wall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallConfig {
    pub name: String,
    pub material: String,
    pub shape: ShapeConfig,
    /// Name of the `[[motions]]` node the wall follows (default: fixed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motion: Option<String>,
}

/// Wall geometry (`type = "plane" | "rectangle" | "cylinder" | "mesh"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeConfig {
    /// Infinite one-sided plane; particles on the side `normal` points to.
    Plane { point_m: Vec3, normal: Vec3 },
    /// Finite two-sided rectangle `center_m ± a·half_u_m ± b·half_v_m`, |a|,|b| ≤ 1.
    Rectangle { center_m: Vec3, half_u_m: Vec3, half_v_m: Vec3 },
    /// Cylinder of `radius_m` about the axis through `point_m` along `axis`; `inside = true` keeps particles
    /// inside. Optional axial limits from `point_m` (open ends).
    Cylinder {
        point_m: Vec3,
        axis: Vec3,
        radius_m: f64,
        #[serde(default = "yes")]
        inside: bool,
        #[serde(default)]
        axial_min_m: Option<f64>,
        #[serde(default)]
        axial_max_m: Option<f64>,
    },
    /// Triangle mesh from an STL (ASCII/binary) or OBJ file, coordinates × `scale` (default 1).
    Mesh {
        file: PathBuf,
        #[serde(default = "one")]
        scale: f64,
    },
}

fn one() -> f64 {
    1.0
}

pub use super::pour::PourConfig;
pub use super::probe::{ProbeConfig, ProbeShape};
pub use crate::motions::{MotionConfig, MotionType};

/// A region for fills and injections (`type = "box" | "cylinder" | "mesh"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum RegionConfig {
    Box {
        min_m: Vec3,
        max_m: Vec3,
    },
    Cylinder {
        base_m: Vec3,
        axis: Vec3,
        radius_m: f64,
        height_m: f64,
    },
    /// The inside of a closed mesh.
    Mesh {
        file: PathBuf,
        #[serde(default = "one")]
        scale: f64,
    },
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FillMethod {
    /// Random sequential addition (default).
    #[default]
    Random,
    /// A lattice (`lattice`, `spacing_m`).
    Lattice,
}

/// Particles placed at t = 0.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FillConfig {
    pub material: String,
    pub region: RegionConfig,
    /// Diameter distribution of spheres (diameters in metres), e.g. `{ kind = "mono", diameter = 0.004 }`
    /// (exactly one of `size` and `clumps`).
    #[serde(default)]
    pub size: Option<SizeDistribution>,
    /// Rigid bodies of these templates instead of spheres (random fill only).
    #[serde(default)]
    pub clumps: Option<ClumpMixConfig>,
    #[serde(default)]
    pub method: FillMethod,
    /// Random fill: number of particles …
    #[serde(default)]
    pub count: Option<u64>,
    /// … or solid volume fraction of the region.
    #[serde(default)]
    pub volume_fraction: Option<f64>,
    /// Lattice type `fcc` (default) or `cubic`.
    #[serde(default)]
    pub lattice: Lattice,
    /// Lattice nearest-neighbour distance \[m\] (default: the largest diameter × 1.01).
    #[serde(default)]
    pub spacing_m: Option<f64>,
    /// Initial velocity \[m/s\].
    #[serde(default)]
    pub velocity_m_s: Vec3,
    /// Fixed spheres (rough walls).
    #[serde(default)]
    pub frozen: bool,
    /// Random fill: consecutive failed placements before giving up (default 100000).
    #[serde(default = "default_attempts")]
    pub max_attempts: u64,
}

fn default_attempts() -> u64 {
    100_000
}

/// Particles injected over time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InjectConfig {
    pub material: String,
    pub region: RegionConfig,
    /// Diameter distribution of spheres (exactly one of `size` and `clumps`).
    #[serde(default)]
    pub size: Option<SizeDistribution>,
    /// Rigid bodies of these templates instead of spheres.
    #[serde(default)]
    pub clumps: Option<ClumpMixConfig>,
    /// Rate in particles per second …
    #[serde(default)]
    pub particles_per_s: Option<f64>,
    /// … or in kilograms per second.
    #[serde(default)]
    pub kg_per_s: Option<f64>,
    #[serde(default)]
    pub start_s: f64,
    /// End of injection \[s\] (default: the end of the run).
    #[serde(default)]
    pub end_s: Option<f64>,
    #[serde(default)]
    pub velocity_m_s: Vec3,
    /// How often the injector places its due particles \[s\] (default 0.001).
    #[serde(default = "default_inject_interval")]
    pub interval_s: f64,
    /// Placement attempts per due particle (default 200).
    #[serde(default = "default_inject_attempts")]
    pub attempts: u64,
}

fn default_inject_interval() -> f64 {
    1e-3
}
fn default_inject_attempts() -> u64 {
    200
}

/// What is written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputConfig {
    /// Particle VTU snapshots + `particles.pvd` (default true).
    #[serde(default = "yes")]
    pub particles_vtu: bool,
    /// Mesh-wall VTU snapshots with impact records + `walls/<name>.pvd` (default true).
    #[serde(default = "yes")]
    pub mesh_vtu: bool,
    /// `events.csv`: first wall impact, collisions per wall and a plane crossing per body or sphere.
    #[serde(default)]
    pub events: Option<super::events::EventsConfig>,
    /// `trajectories.csv`: selected bodies and spheres every N steps.
    #[serde(default)]
    pub trajectories: Option<super::events::TrajectoryConfig>,
    /// Write `bed.txt`, the free spheres at the end of the run (default: true with `[pour]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bed_file: Option<bool>,
    /// Boxes whose packing density (solid volume fraction, spheres cut exactly by the faces) is reported
    /// at the end of the run.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub packing: Vec<PackingRegion>,
}

impl OutputConfig {
    /// Whether `bed.txt` is written.
    pub fn writes_bed(&self, pour: bool) -> bool {
        self.bed_file.unwrap_or(pour)
    }
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig {
            particles_vtu: true,
            mesh_vtu: true,
            events: None,
            trajectories: None,
            bed_file: None,
            packing: Vec::new(),
        }
    }
}

impl SceneConfig {
    /// Material names in index order (the order of the `materials` table).
    pub fn material_names(&self) -> Vec<&str> {
        self.materials.keys().map(String::as_str).collect()
    }
}

fn check_region(c: &mut Checker, key: &str, r: &RegionConfig) {
    c.nested(key, |c| match r {
        RegionConfig::Box { min_m, max_m } => {
            c.finite_vec("min_m", *min_m);
            c.finite_vec("max_m", *max_m);
            if !(max_m.cmpgt(*min_m).all()) {
                c.fail("max_m", "max_m must exceed min_m in x, y and z".to_string());
            }
        }
        RegionConfig::Cylinder { base_m, axis, radius_m, height_m } => {
            c.finite_vec("base_m", *base_m);
            check_direction(c, "axis", *axis);
            c.positive("radius_m", *radius_m);
            c.positive("height_m", *height_m);
        }
        RegionConfig::Mesh { file, scale } => {
            c.mesh_file("file", file);
            c.positive("scale", *scale);
        }
    });
}

/// Exactly one of `size` (spheres) and `clumps` (rigid bodies), each valid.
fn check_items(
    c: &mut Checker,
    size: Option<&SizeDistribution>,
    clumps: Option<&ClumpMixConfig>,
    templates: &[&str],
) {
    match (size, clumps) {
        (Some(d), None) => {
            if let Err(e) = d.check() {
                c.fail("size", e);
            }
        }
        (None, Some(m)) => super::clumps::check_mix(c, m, templates),
        (Some(_), Some(_)) => {
            c.fail("clumps", "give size (spheres) or clumps (rigid bodies), not both".to_string())
        }
        (None, None) => c.fail(
            "size",
            "missing: give size (a diameter distribution of spheres) or clumps (a mix of [templates])"
                .to_string(),
        ),
    }
}

fn check_direction(c: &mut Checker, key: &str, v: Vec3) {
    c.finite_vec(key, v);
    if v.length() == 0.0 {
        c.fail(key, format!("{key} = [0, 0, 0] is not a direction"));
    }
}

fn check_material_name(c: &mut Checker, cfg: &SceneConfig, key: &str, name: &str) {
    if !cfg.materials.contains_key(name) {
        c.fail(
            key,
            format!(
                "{key} = \"{name}\" is not in [materials] (defined: {})",
                cfg.material_names().join(", ")
            ),
        );
    }
}

/// Per-pair stiffness and cohesion need the Hooke normal law, and cohesion a constant restitution.
fn check_linear_pair_keys(
    c: &mut Checker,
    normal: NormalKind,
    stiffness: Option<f64>,
    cohesion: Option<f64>,
    thornton: bool,
) {
    if let Some(k) = stiffness {
        c.positive("stiffness_n_m", k);
        if normal != NormalKind::Hooke {
            c.fail(
                "stiffness_n_m",
                format!("stiffness_n_m = {k} applies to contact.normal = \"hooke\" only"),
            );
        }
    }
    if let Some(k) = cohesion {
        c.non_negative("cohesion_stiffness_n_m", k);
        if k > 0.0 && normal != NormalKind::Hooke {
            c.fail(
                "cohesion_stiffness_n_m",
                format!("cohesion_stiffness_n_m = {k} applies to contact.normal = \"hooke\" only"),
            );
        }
        if k > 0.0 && thornton {
            c.fail(
                "cohesion_stiffness_n_m",
                "linear cohesion is combined with a constant restitution only (restitution_model = \
                 \"constant\")"
                    .to_string(),
            );
        }
    }
}

fn check_pair_values(c: &mut Checker, v: &PairValues) {
    c.non_negative("friction", v.friction);
    c.in_range("restitution", v.restitution, 0.0, false, 1.0, true);
    c.non_negative("rolling_friction", v.rolling_friction);
    c.non_negative("rolling_viscous_s_m", v.rolling_viscous_s_m);
    c.non_negative("work_of_adhesion_j_m2", v.work_of_adhesion_j_m2);
    check_restitution_model(c, v.restitution_model, v.yield_stress_pa, v.yield_stress_pa.is_some());
}

/// `yield_stress_pa` is required by and only allowed with `restitution_model = "thornton"`; `written`
/// says whether this table itself gives it (an inherited value is not an error).
fn check_restitution_model(c: &mut Checker, kind: RestitutionKind, yield_stress: Option<f64>, written: bool) {
    match (kind, yield_stress) {
        (RestitutionKind::Thornton, None) => c.fail(
            "yield_stress_pa",
            "restitution_model = \"thornton\" needs yield_stress_pa, the yield stress σ_y in Pa (e.g. 1e6)"
                .to_string(),
        ),
        (RestitutionKind::Thornton, Some(y)) => c.positive("yield_stress_pa", y),
        (RestitutionKind::Constant, Some(y)) if written => c.fail(
            "yield_stress_pa",
            format!("yield_stress_pa = {y} is used only with restitution_model = \"thornton\""),
        ),
        (RestitutionKind::Constant, _) => {}
    }
}

/// Largest accepted number of time steps (`duration_s / dt_s`).
pub const MAX_STEPS: f64 = 1e11;

/// Memory per particle of a scene, for the size estimate before a fill \[B\] (state, neighbour list and
/// contact history of a settled packing, with margin).
pub const BYTES_PER_PARTICLE: u64 = 1000;

impl SceneConfig {
    /// Some pair has linear cohesion (`cohesion_stiffness_n_m` > 0).
    pub fn has_cohesion(&self) -> bool {
        self.pair_defaults.cohesion_stiffness_n_m > 0.0
            || self.pairs.iter().any(|p| p.cohesion_stiffness_n_m.is_some_and(|k| k > 0.0))
    }
}

/// The memory of a lattice fill, from the lattice points of its region's volume (√2/s³ per m³, the
/// densest lattice, fcc, at nearest-neighbour distance s): a spacing of a nanometre in a box of
/// centimetres asks for more particles than any machine holds, and would only fail once the lattice was
/// being built. Mesh regions are not estimated (their volume needs the file).
fn lattice_memory(c: &mut Checker, f: &FillConfig) {
    let spacing = f
        .spacing_m
        .or_else(|| f.size.as_ref().and_then(spatter_dem::insertion::max_diameter).map(|d| 1.01 * d));
    let volume = match &f.region {
        RegionConfig::Box { min_m, max_m } => {
            let e = *max_m - *min_m;
            (e.x * e.y * e.z).abs()
        }
        RegionConfig::Cylinder { radius_m, height_m, .. } => {
            std::f64::consts::PI * radius_m * radius_m * height_m.abs()
        }
        RegionConfig::Mesh { .. } => return,
    };
    if let Some(s) = spacing.filter(|&s| s > 0.0 && s.is_finite()) {
        let points = volume * std::f64::consts::SQRT_2 / (s * s * s);
        if points.is_finite() {
            let key = if f.spacing_m.is_some() { "spacing_m" } else { "size" };
            c.memory_estimate(
                key,
                &format!("about {points:.3e} lattice points at spacing {s} m × {BYTES_PER_PARTICLE} B"),
                points * BYTES_PER_PARTICLE as f64,
            );
        }
    }
}

impl Validate for SceneConfig {
    fn validate(&self, c: &mut Checker) {
        c.positive("dt_s", self.dt_s);
        c.positive("duration_s", self.duration_s);
        c.positive("output_interval_s", self.output_interval_s);
        let steps = self.duration_s / self.dt_s;
        if steps.is_finite() && steps > MAX_STEPS {
            c.fail(
                "dt_s",
                format!(
                    "duration_s / dt_s = {} / {} = {steps:.3e} steps is above {MAX_STEPS:e}; a run this long \
                     never ends — shorten duration_s or lengthen dt_s",
                    self.duration_s, self.dt_s
                ),
            );
        } else if self.dt_s > self.duration_s {
            c.fail(
                "dt_s",
                format!(
                    "dt_s = {} is longer than duration_s = {}: the run would take one step and show nothing",
                    self.dt_s, self.duration_s
                ),
            );
        }
        for (i, f) in self.fill.iter().enumerate() {
            if let Some(n) = f.count {
                c.element("fill", i, |c| {
                    c.memory_estimate(
                        "count",
                        &format!("count = {n} particles × {BYTES_PER_PARTICLE} B"),
                        n as f64 * BYTES_PER_PARTICLE as f64,
                    )
                });
            }
            if f.method == FillMethod::Lattice {
                c.element("fill", i, |c| lattice_memory(c, f));
            }
        }
        c.finite_vec("gravity_m_s2", self.gravity_m_s2);
        if self.materials.is_empty() {
            c.fail("materials", "at least one material is needed, e.g. [materials.glass]".to_string());
        }
        if self.materials.len() > u16::MAX as usize {
            c.fail("materials", "too many materials".to_string());
        }
        for (name, m) in &self.materials {
            c.nested("materials", |c| c.item(name, m));
        }
        c.nested("contact", |c| {
            let k = &self.contact;
            if k.normal == NormalKind::Hooke {
                match (k.hooke_stiffness_n_m, k.hooke_characteristic_speed_m_s) {
                    (Some(s), None) => c.positive("hooke_stiffness_n_m", s),
                    (None, Some(v)) => c.positive("hooke_characteristic_speed_m_s", v),
                    // Every pair has its own stiffness.
                    (None, None) if self.pair_defaults.stiffness_n_m.is_some() => {}
                    _ => c.fail(
                        "hooke_stiffness_n_m",
                        "normal = \"hooke\" needs exactly one of hooke_stiffness_n_m or \
                         hooke_characteristic_speed_m_s (or pair_defaults.stiffness_n_m)"
                            .to_string(),
                    ),
                }
            }
            c.in_range("cohesion_radius_ratio", k.cohesion_radius_ratio, 1.0, true, 2.0, true);
            c.positive("linear_stiffness_ratio", k.linear_stiffness_ratio);
            if matches!(k.normal, NormalKind::Jkr | NormalKind::Dmt | NormalKind::Sjkr)
                && k.tangential != TangentialKind::Mindlin
            {
                c.fail(
                    "tangential",
                    "adhesive normal laws are combined with tangential = \"mindlin\" only".to_string(),
                );
            }
            if matches!(k.normal, NormalKind::Jkr | NormalKind::Dmt | NormalKind::Sjkr)
                && k.coulomb_load != spatter_dem::contact::CoulombLoad::Total
            {
                c.fail(
                    "coulomb_load",
                    "applies to normal = \"hertz\" or \"hooke\"; adhesive laws choose their Coulomb force \
                     with adhesive_coulomb"
                        .to_string(),
                );
            }
        });
        c.nested("engine", |c| {
            let e = &self.engine;
            if let Some(s) = e.skin_m {
                c.positive("skin_m", s);
            }
            c.in_range("max_overlap_fraction", e.max_overlap_fraction, 0.0, false, 1.0, true);
            match (e.domain_min_m, e.domain_max_m) {
                (Some(a), Some(b)) => {
                    if !b.cmpgt(a).all() {
                        c.fail(
                            "domain_max_m",
                            "domain_max_m must exceed domain_min_m in x, y and z".to_string(),
                        );
                    }
                }
                (None, None) => {}
                _ => {
                    c.fail("domain_min_m", "give both domain_min_m and domain_max_m, or neither".to_string())
                }
            }
            if let Some(v) = e.impact_speed_m_s {
                c.positive("impact_speed_m_s", v);
            }
            if let Some(v) = e.rebalance_imbalance {
                c.in_range("rebalance_imbalance", v, 1.0, true, f64::INFINITY, true);
            }
            if let Some(scheme) = e.integrator.scheme() {
                if scheme.is_implicit() && e.iterations.unwrap_or(0) == 0 {
                    c.fail(
                        "iterations",
                        format!(
                            "integrator = \"{}\" is implicit and needs iterations ≥ 1 (fixed-point iterations \
                             per step; BD-p keeps its order with ≥ p, e.g. iterations = {})",
                            e.integrator.label().to_lowercase(),
                            scheme.nominal_order() + 1
                        ),
                    );
                }
                if scheme != spatter_dem::integrators::Scheme::Se && !self.templates.is_empty() {
                    c.fail(
                        "integrator",
                        format!(
                            "integrator = \"{}\" runs single spheres only; this scene has clump templates — \
                             use \"velocity_verlet\" or \"symplectic_euler\"",
                            e.integrator.label().to_lowercase()
                        ),
                    );
                }
            }
            if e.iterations.is_some() && !e.integrator.scheme().is_some_and(|s| s.is_implicit()) {
                c.fail(
                    "iterations",
                    "iterations applies to the implicit integrators bd1, bd2, bd4 only; remove it".to_string(),
                );
            }
            if !e.rotation && !self.templates.is_empty() {
                c.fail(
                    "rotation",
                    "rotation = false applies to spheres; this scene has clump templates, whose bodies \
                     always rotate — remove [templates] or set rotation = true"
                        .to_string(),
                );
            }
        });
        let thornton = self.pair_defaults.restitution_model == RestitutionKind::Thornton
            || self.pairs.iter().any(|p| p.restitution_model == Some(RestitutionKind::Thornton));
        c.nested("pair_defaults", |c| {
            check_pair_values(c, &self.pair_defaults);
            let d = &self.pair_defaults;
            check_linear_pair_keys(
                c,
                self.contact.normal,
                d.stiffness_n_m,
                Some(d.cohesion_stiffness_n_m),
                thornton,
            );
        });
        for (i, p) in self.pairs.iter().enumerate() {
            c.element("pairs", i, |c| {
                for (k, m) in p.materials.iter().enumerate() {
                    check_material_name(c, self, &format!("materials[{k}]"), m);
                }
                c.non_negative("friction", p.friction.unwrap_or(0.0));
                c.in_range("restitution", p.restitution.unwrap_or(1.0), 0.0, false, 1.0, true);
                c.non_negative("rolling_friction", p.rolling_friction.unwrap_or(0.0));
                c.non_negative("rolling_viscous_s_m", p.rolling_viscous_s_m.unwrap_or(0.0));
                c.non_negative("work_of_adhesion_j_m2", p.work_of_adhesion_j_m2.unwrap_or(0.0));
                check_linear_pair_keys(
                    c,
                    self.contact.normal,
                    p.stiffness_n_m,
                    p.cohesion_stiffness_n_m,
                    thornton,
                );
                let d = &self.pair_defaults;
                check_restitution_model(
                    c,
                    p.restitution_model.unwrap_or(d.restitution_model),
                    p.yield_stress_pa.or(d.yield_stress_pa),
                    p.yield_stress_pa.is_some(),
                );
            });
        }
        crate::motions::check_tree(c, &self.motions);
        for (i, w) in self.walls.iter().enumerate() {
            c.element("walls", i, |c| {
                check_material_name(c, self, "material", &w.material);
                if self.walls[..i].iter().any(|o| o.name == w.name) {
                    c.fail("name", format!("name = \"{}\" is used by an earlier wall", w.name));
                }
                if w.name.is_empty() || w.name.contains(['/', '\\']) {
                    c.fail("name", format!("name = \"{}\" must be non-empty without slashes", w.name));
                }
                c.nested("shape", |c| match &w.shape {
                    ShapeConfig::Plane { point_m, normal } => {
                        c.finite_vec("point_m", *point_m);
                        check_direction(c, "normal", *normal);
                    }
                    ShapeConfig::Rectangle { center_m, half_u_m, half_v_m } => {
                        c.finite_vec("center_m", *center_m);
                        check_direction(c, "half_u_m", *half_u_m);
                        check_direction(c, "half_v_m", *half_v_m);
                        if half_u_m.normalize_or_zero().dot(half_v_m.normalize_or_zero()).abs() > 1e-9 {
                            c.fail("half_v_m", "half_u_m and half_v_m must be perpendicular".to_string());
                        }
                    }
                    ShapeConfig::Cylinder { point_m, axis, radius_m, axial_min_m, axial_max_m, .. } => {
                        c.finite_vec("point_m", *point_m);
                        check_direction(c, "axis", *axis);
                        c.positive("radius_m", *radius_m);
                        if let (Some(a), Some(b)) = (axial_min_m, axial_max_m) {
                            if b <= a {
                                c.fail(
                                    "axial_max_m",
                                    format!("axial_max_m = {b} must exceed axial_min_m = {a}"),
                                );
                            }
                        }
                    }
                    ShapeConfig::Mesh { file, scale } => {
                        c.mesh_file("file", file);
                        c.positive("scale", *scale);
                    }
                });
                crate::motions::check_reference(c, "motion", w.motion.as_deref(), &self.motions);
            });
        }
        c.nested("output", |c| {
            if let Some(e) = &self.output.events {
                c.nested("events", |c| {
                    e.validate(c);
                    for (k, name) in e.first_impact_walls.iter().enumerate() {
                        if !self.walls.iter().any(|w| w.name == *name) {
                            c.fail(
                                &format!("first_impact_walls[{k}]"),
                                format!("\"{name}\" is not the name of a wall in [[walls]]"),
                            );
                        }
                    }
                });
            }
            if let Some(t) = &self.output.trajectories {
                c.nested("trajectories", |c| t.validate(c));
            }
            if self.output.writes_bed(self.pour.is_some()) && !self.templates.is_empty() {
                c.fail(
                    "bed_file",
                    "a bed file holds single spheres; this scene has clump templates — set bed_file = false"
                        .to_string(),
                );
            }
            for (i, p) in self.output.packing.iter().enumerate() {
                c.element("packing", i, |c| {
                    c.finite_vec("min_m", p.min_m);
                    c.finite_vec("max_m", p.max_m);
                    if !p.max_m.cmpgt(p.min_m).all() {
                        c.fail("max_m", "max_m must exceed min_m in x, y and z".to_string());
                    }
                    if p.name.is_empty() || !p.name.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
                    {
                        c.fail("name", format!("name = \"{}\" must be letters, digits and _", p.name));
                    }
                    if self.output.packing[..i].iter().any(|o| o.name == p.name) {
                        c.fail("name", format!("name = \"{}\" is used by an earlier entry", p.name));
                    }
                });
            }
        });
        if let Some(p) = &self.pour {
            super::pour::check(c, self, p);
        }
        if let Some(p) = &self.probe {
            super::probe::check(c, self, p);
        }
        if let Some(b) = &self.bed {
            c.nested("bed", |c| {
                let full = c.resolve(&b.file);
                if !full.is_file() {
                    c.file_exists("file", &b.file);
                } else if let Err(e) = crate::bed_lab::bed_file::read(&full, &self.material_names()) {
                    c.fail("file", format!("file = \"{}\": {e}", b.file.display()));
                }
            });
        }
        let template_names: Vec<&str> = self.templates.keys().map(String::as_str).collect();
        for (name, t) in &self.templates {
            c.nested("templates", |c| {
                if name.is_empty() || name.contains(['/', '\\']) {
                    c.fail(name, format!("template name \"{name}\" must be non-empty without slashes"));
                }
                c.nested(name, |c| t.validate(c))
            });
        }
        for (i, w) in self.wear.iter().enumerate() {
            c.element("wear", i, |c| {
                check_material_name(c, self, "particle_material", &w.particle_material);
                check_material_name(c, self, "wall_material", &w.wall_material);
                w.validate(c);
                let same = |o: &WearConfig| {
                    o.particle_material == w.particle_material && o.wall_material == w.wall_material
                };
                if self.wear[..i].iter().any(same) {
                    c.fail("wall_material", "an earlier [[wear]] entry has the same pair".to_string());
                }
            });
        }
        for (i, f) in self.fill.iter().enumerate() {
            c.element("fill", i, |c| {
                check_material_name(c, self, "material", &f.material);
                check_region(c, "region", &f.region);
                check_items(c, f.size.as_ref(), f.clumps.as_ref(), &template_names);
                if f.clumps.is_some() {
                    if f.method == FillMethod::Lattice {
                        c.fail("method", "clumps are placed by method = \"random\" only".to_string());
                    }
                    if f.frozen {
                        c.fail("frozen", "frozen applies to spheres, not to clumps".to_string());
                    }
                }
                c.finite_vec("velocity_m_s", f.velocity_m_s);
                match f.method {
                    FillMethod::Random => match (f.count, f.volume_fraction) {
                        (Some(_), None) => {}
                        (None, Some(v)) => c.in_range("volume_fraction", v, 0.0, false, 0.74, true),
                        _ => c.fail(
                            "count",
                            "a random fill needs exactly one of count or volume_fraction".to_string(),
                        ),
                    },
                    FillMethod::Lattice => {
                        if let Some(s) = f.spacing_m {
                            c.positive("spacing_m", s);
                        } else if f
                            .size
                            .as_ref()
                            .is_some_and(|d| spatter_dem::insertion::max_diameter(d).is_none())
                        {
                            c.fail(
                                "spacing_m",
                                "a lattice fill with an unbounded size distribution needs spacing_m"
                                    .to_string(),
                            );
                        }
                    }
                }
            });
        }
        for (i, j) in self.inject.iter().enumerate() {
            c.element("inject", i, |c| {
                check_material_name(c, self, "material", &j.material);
                check_region(c, "region", &j.region);
                check_items(c, j.size.as_ref(), j.clumps.as_ref(), &template_names);
                match (j.particles_per_s, j.kg_per_s) {
                    (Some(r), None) => c.positive("particles_per_s", r),
                    (None, Some(r)) => c.positive("kg_per_s", r),
                    _ => c.fail(
                        "particles_per_s",
                        "give exactly one of particles_per_s or kg_per_s".to_string(),
                    ),
                }
                c.non_negative("start_s", j.start_s);
                if let Some(e) = j.end_s {
                    if e <= j.start_s {
                        c.fail("end_s", format!("end_s = {e} must exceed start_s = {}", j.start_s));
                    }
                }
                c.positive("interval_s", j.interval_s);
                c.finite_vec("velocity_m_s", j.velocity_m_s);
            });
        }
    }
}

impl spatter_io::run::Smoke for SceneConfig {
    /// 40 steps, an output at the start, half-way and the end; fills of a counted size keep at most 200
    /// particles (lattice and fraction fills keep their region: they are set up, not stepped, in bulk), a
    /// pour at most 50, a probe's largest depth what half the run can reach.
    fn smoke(&mut self) {
        self.duration_s = self.duration_s.min(40.0 * self.dt_s);
        self.output_interval_s = self.output_interval_s.min(20.0 * self.dt_s);
        for f in &mut self.fill {
            if let Some(n) = &mut f.count {
                *n = (*n).min(200);
            }
        }
        if let Some(p) = &mut self.pour {
            p.count = p.count.min(50);
        }
        // A probe goes as deep as half the shortened run allows (it usually stays above the bed).
        if let Some(p) = &mut self.probe {
            p.max_depth_m = p.max_depth_m.min(0.5 * self.duration_s * p.speed_m_s);
            if let Some(d) = &mut p.immersion_depth_m {
                *d = d.min(0.5 * p.max_depth_m);
            }
        }
    }
}
