//! The `brownout` scenario: rotor, ground, lift-off analysis, entrainment, cloud and outputs.
//! Every key is documented in `docs/brownout.md`.

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::{Aabb, Vec3};
use spatter_flow::cloud::classes::SizeClasses;
use spatter_flow::field::rotor::RotorDownwash;
use spatter_flow::forces::wall_lift::WallLiftLaw;
use spatter_flow::forces::Fluid;
use spatter_flow::liftoff::entrainment::{EntrainmentModel, Threshold};
use spatter_flow::liftoff::incipient::{PullOff, RockingSettings};

pub use crate::bed_flow::DemBedConfig;

pub use super::imported::{ImportedFlowConfig, ModelScale};
pub use super::rans::{FlowChoice, RansConfig, RansTurbulence};

/// A `brownout` scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BrownoutConfig {
    pub rotor: RotorConfig,
    /// The mean flow: analytic (default) or the solved axisymmetric RANS rotor.
    #[serde(default)]
    pub flow: FlowChoice,
    /// Air (density, viscosity).
    #[serde(default = "thesis_air")]
    pub air: Fluid,
    pub ground: GroundConfig,
    #[serde(default)]
    pub liftoff: LiftoffConfig,
    pub entrainment: EntrainmentConfig,
    pub cloud: CloudConfig,
    #[serde(default)]
    pub output: OutputConfig,
    /// The DEM bed patch under the rotor (with `entrainment.source = "dem_bed"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dem_bed: Option<DemBedConfig>,
}

/// What feeds the cloud.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EntrainmentSource {
    /// The empirical model's flux over the annuli (default).
    #[default]
    Model,
    /// The grains that leave a DEM bed patch under the flow (`[dem_bed]`); the model's flux is still
    /// computed and written for comparison, but releases nothing.
    DemBed,
}

fn thesis_air() -> Fluid {
    Fluid { density: 1.19, viscosity: 1.82e-5 }
}

/// The rotor in hover over flat ground at z = 0, axis through the origin.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorConfig {
    /// Rotor radius R \[m\].
    pub radius_m: f64,
    /// Thrust T \[N\] (give this or `thrust_coefficient`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thrust_n: Option<f64>,
    /// C_T = T/(½ρπR²(ΩR)²) (British convention, Jasion eq. 4.23).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thrust_coefficient: Option<f64>,
    /// Rotor speed Ω \[rad/s\].
    pub omega_rad_s: f64,
    /// Hub height over the ground z_d/R.
    pub height_over_radius: f64,
    #[serde(default = "two")]
    pub blades: u32,
    /// Superpose the tip vortices (rings as a fluctuation about the mean flow).
    #[serde(default)]
    pub tip_vortices: bool,
    #[serde(default = "ten")]
    pub vortex_max_age_revs: f64,
    #[serde(default = "rc0")]
    pub core_radius_fraction: f64,
    #[serde(default = "quarter")]
    pub vortex_path_height: f64,
    #[serde(default = "half")]
    pub vortex_speed_fraction: f64,
}

fn two() -> u32 {
    2
}
fn ten() -> f64 {
    10.0
}
fn rc0() -> f64 {
    0.03
}
fn quarter() -> f64 {
    0.25
}
fn half() -> f64 {
    0.5
}

impl RotorConfig {
    /// Thrust \[N\] from `thrust_n` or `thrust_coefficient`.
    pub fn thrust(&self, rho: f64) -> f64 {
        match (self.thrust_n, self.thrust_coefficient) {
            (Some(t), _) => t,
            (None, Some(ct)) => {
                let r = self.radius_m;
                ct * 0.5 * rho * std::f64::consts::PI * r * r * (self.omega_rad_s * r).powi(2)
            }
            (None, None) => 0.0,
        }
    }

    /// The rotor downwash model of this rotor in `air`.
    pub fn downwash(&self, air: &Fluid) -> RotorDownwash {
        let r = self.radius_m;
        let mut d = RotorDownwash::new(
            Vec3::new(0.0, 0.0, self.height_over_radius * r),
            r,
            self.thrust(air.density),
            self.omega_rad_s,
        );
        d.air_density_kg_m3 = air.density;
        d.kinematic_viscosity_m2_s = air.nu();
        d.blades = self.blades;
        d.tip_vortices = self.tip_vortices;
        d.vortex_max_age_revs = self.vortex_max_age_revs;
        d.core_radius_fraction = self.core_radius_fraction;
        d.vortex_path_height = self.vortex_path_height;
        d.vortex_speed_fraction = self.vortex_speed_fraction;
        d
    }
}

impl Validate for RotorConfig {
    fn validate(&self, c: &mut Checker) {
        c.positive("radius_m", self.radius_m);
        c.positive("omega_rad_s", self.omega_rad_s);
        match (self.thrust_n, self.thrust_coefficient) {
            (Some(_), Some(_)) => c.fail("thrust_n", "give thrust_n or thrust_coefficient, not both"),
            (None, None) => c.fail("thrust_n", "give the thrust: thrust_n [N] or thrust_coefficient"),
            (Some(t), None) => {
                if !(t.is_finite() && t > 0.0) {
                    c.fail(
                        "thrust_n",
                        format!("thrust_n = {t} must be a positive thrust in newtons (hover: the weight)"),
                    );
                }
            }
            (None, Some(ct)) => {
                if !(ct.is_finite() && ct > 0.0) {
                    c.fail("thrust_coefficient", format!("thrust_coefficient = {ct} must be positive"));
                }
            }
        }
        if !(self.height_over_radius.is_finite() && self.height_over_radius > 0.0) {
            c.fail(
                "height_over_radius",
                format!(
                    "height_over_radius = {} puts the rotor on or below the ground; give the hub height above the ground over the radius, z_d/R > 0 (the Bell 47 case: 0.68)",
                    self.height_over_radius
                ),
            );
        }
        if self.blades == 0 {
            c.fail("blades", "blades = 0 must be at least 1");
        }
        c.positive("vortex_max_age_revs", self.vortex_max_age_revs);
        c.in_range("core_radius_fraction", self.core_radius_fraction, 0.0, false, 0.1, true);
        c.positive("vortex_path_height", self.vortex_path_height);
        c.positive("vortex_speed_fraction", self.vortex_speed_fraction);
    }
}

/// Grain size distribution of the ground.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SizeConfig {
    /// Normal by mass, truncated to [min_m, max_m], in `classes` equal classes.
    NormalByMass { mean_m: f64, std_dev_m: f64, min_m: f64, max_m: f64, classes: usize },
    /// Explicit classes: diameters and mass weights (normalised).
    Classes { diameters_m: Vec<f64>, mass_weights: Vec<f64> },
}

impl SizeConfig {
    pub fn classes(&self) -> Result<SizeClasses, String> {
        match self {
            SizeConfig::NormalByMass { mean_m, std_dev_m, min_m, max_m, classes } => {
                SizeClasses::normal_by_mass(*mean_m, *std_dev_m, *min_m, *max_m, *classes)
            }
            SizeConfig::Classes { diameters_m, mass_weights } => {
                SizeClasses::new(diameters_m.clone(), mass_weights.clone())
            }
        }
    }
}

/// The ground: grain density, adhesion, bed geometry and size distribution.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundConfig {
    #[serde(default = "sand")]
    pub density_kg_m3: f64,
    #[serde(default = "sigma")]
    pub surface_energy_j_m2: f64,
    #[serde(default)]
    pub pull_off: PullOff,
    #[serde(default = "half")]
    pub asperity_ratio: f64,
    pub size: SizeConfig,
}

fn sand() -> f64 {
    2480.0
}
fn sigma() -> f64 {
    2e-4
}

impl Validate for GroundConfig {
    fn validate(&self, c: &mut Checker) {
        c.positive("density_kg_m3", self.density_kg_m3);
        c.non_negative("surface_energy_j_m2", self.surface_energy_j_m2);
        c.in_range("asperity_ratio", self.asperity_ratio, 0.0, false, 2.0, false);
        if let Err(e) = self.size.classes() {
            c.fail("size", e);
        }
    }
}

/// The lift-off analysis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LiftoffConfig {
    /// Factor on the ground speeds (the thesis's mean + 2u′ with u′ = 15 %: 1.3).
    #[serde(default = "gust")]
    pub gust_factor: f64,
    /// Wall-jet peak searched up to this height / R.
    #[serde(default = "half")]
    pub shear_max_height_over_radius: f64,
    /// Ground points from / to this distance / R.
    #[serde(default = "r_min")]
    pub radius_min_over_radius: f64,
    #[serde(default = "r_max")]
    pub radius_max_over_radius: f64,
    #[serde(default = "points")]
    pub points: usize,
    /// Diameters of the map \[m\]; default 25 from 10 µm to 1 mm (logarithmic).
    #[serde(default = "map_diameters")]
    pub diameters_m: Vec<f64>,
    /// Wall-bounded lift law.
    #[serde(default = "regimes")]
    pub wall_lift: WallLiftLaw,
    /// Critical Shields parameter θ* of the exceedance map (Jasion's τ_ref = 0.03 ρ_p g D).
    #[serde(default = "shields_mixed")]
    pub shields_critical: f64,
    /// Times over the unsteady window at which the exceedance map samples the wall shear.
    #[serde(default = "exceedance_samples")]
    pub exceedance_samples: usize,
    /// Factor on the ground speeds of the exceedance map (1: the unsteady field as it is).
    #[serde(default = "one")]
    pub exceedance_gust_factor: f64,
}

fn shields_mixed() -> f64 {
    spatter_flow::liftoff::shields::SHIELDS_MIXED
}
fn exceedance_samples() -> usize {
    64
}

fn gust() -> f64 {
    1.3
}
fn r_min() -> f64 {
    0.05
}
fn r_max() -> f64 {
    3.0
}
fn points() -> usize {
    60
}
fn map_diameters() -> Vec<f64> {
    (0..25).map(|k| 10e-6 * 10f64.powf(k as f64 / 12.0)).collect()
}
fn regimes() -> WallLiftLaw {
    WallLiftLaw::Regimes
}

impl Default for LiftoffConfig {
    fn default() -> Self {
        LiftoffConfig {
            gust_factor: gust(),
            shear_max_height_over_radius: half(),
            radius_min_over_radius: r_min(),
            radius_max_over_radius: r_max(),
            points: points(),
            diameters_m: map_diameters(),
            wall_lift: regimes(),
            shields_critical: shields_mixed(),
            exceedance_samples: exceedance_samples(),
            exceedance_gust_factor: one(),
        }
    }
}

impl Validate for LiftoffConfig {
    fn validate(&self, c: &mut Checker) {
        c.positive("gust_factor", self.gust_factor);
        c.positive("shear_max_height_over_radius", self.shear_max_height_over_radius);
        c.non_negative("radius_min_over_radius", self.radius_min_over_radius);
        if self.radius_max_over_radius <= self.radius_min_over_radius {
            c.fail("radius_max_over_radius", "radius_max_over_radius must exceed radius_min_over_radius");
        }
        if self.points < 2 {
            c.fail("points", format!("points = {} must be at least 2", self.points));
        }
        if self.diameters_m.is_empty() || self.diameters_m.iter().any(|d| !(d.is_finite() && *d > 0.0)) {
            c.fail("diameters_m", "diameters_m must list positive diameters in metres");
        }
        c.positive("shields_critical", self.shields_critical);
        if !(1..=10_000).contains(&self.exceedance_samples) {
            c.fail(
                "exceedance_samples",
                format!("exceedance_samples = {} must be 1 to 10000", self.exceedance_samples),
            );
        }
        c.positive("exceedance_gust_factor", self.exceedance_gust_factor);
    }
}

/// The threshold friction velocity constants.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ThresholdChoice {
    ShaoLu,
    Bagnold,
}

impl ThresholdChoice {
    pub fn threshold(self) -> Threshold {
        match self {
            ThresholdChoice::ShaoLu => Threshold::SHAO_LU,
            ThresholdChoice::Bagnold => Threshold::BAGNOLD,
        }
    }
}

/// The entrainment source.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EntrainmentConfig {
    /// `{ model = "white", … }`, `{ model = "haehnel", coefficient_1_s = … }` or
    /// `{ model = "wachspress", coefficient_kg_s2_m5 = … }`.
    pub model: EntrainmentModel,
    #[serde(default = "shao_lu")]
    pub threshold: ThresholdChoice,
    /// Factor on the ground speeds of the source (1: the mean flow).
    #[serde(default = "one")]
    pub gust_factor: f64,
    /// Annuli of the source from / to this distance / R, and how many.
    #[serde(default = "src_min")]
    pub radius_min_over_radius: f64,
    #[serde(default = "r_max")]
    pub radius_max_over_radius: f64,
    #[serde(default = "annuli")]
    pub annuli: usize,
    /// Height of the reference speed of the Wachspress model \[m\].
    #[serde(default = "ref_height")]
    pub reference_height_m: f64,
    /// With tip vortices: times per shedding period over which the flux is averaged.
    #[serde(default = "phases")]
    pub phases: usize,
    /// What feeds the cloud: the model (default) or the DEM bed patch.
    #[serde(default)]
    pub source: EntrainmentSource,
}

fn phases() -> usize {
    8
}

fn shao_lu() -> ThresholdChoice {
    ThresholdChoice::ShaoLu
}
fn one() -> f64 {
    1.0
}
fn src_min() -> f64 {
    0.2
}
fn annuli() -> usize {
    28
}
fn ref_height() -> f64 {
    0.3
}

impl Validate for EntrainmentConfig {
    fn validate(&self, c: &mut Checker) {
        c.item("model", &self.model);
        c.positive("gust_factor", self.gust_factor);
        c.non_negative("radius_min_over_radius", self.radius_min_over_radius);
        if self.radius_max_over_radius <= self.radius_min_over_radius {
            c.fail("radius_max_over_radius", "radius_max_over_radius must exceed radius_min_over_radius");
        }
        if self.annuli == 0 {
            c.fail("annuli", "annuli = 0 must be at least 1");
        }
        c.positive("reference_height_m", self.reference_height_m);
        if self.phases == 0 || self.phases > 1000 {
            c.fail("phases", format!("phases = {} must be 1 to 1000", self.phases));
        }
    }
}

/// The tracked cloud.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudConfig {
    /// Time step \[s\] and duration \[s\].
    pub dt_s: f64,
    pub duration_s: f64,
    /// Mass of one parcel \[kg\].
    pub parcel_mass_kg: f64,
    /// Release height above the ground \[m\].
    #[serde(default = "release")]
    pub release_height_m: f64,
    /// Domain: a box of half-width `domain_radius_over_radius`·R and height `domain_height_over_radius`·R.
    #[serde(default = "dom_r")]
    pub domain_radius_over_radius: f64,
    #[serde(default = "dom_h")]
    pub domain_height_over_radius: f64,
    #[serde(default = "seed")]
    pub seed: u64,
}

fn release() -> f64 {
    0.03
}
fn dom_r() -> f64 {
    4.0
}
fn dom_h() -> f64 {
    2.0
}
fn seed() -> u64 {
    1
}

impl Validate for CloudConfig {
    fn validate(&self, c: &mut Checker) {
        c.positive("dt_s", self.dt_s);
        c.positive("duration_s", self.duration_s);
        if self.dt_s.is_finite() && self.duration_s.is_finite() && self.duration_s / self.dt_s > 1e8 {
            c.fail(
                "duration_s",
                format!("duration_s / dt_s = {:.3e} steps is more than 10⁸", self.duration_s / self.dt_s),
            );
        }
        c.positive("parcel_mass_kg", self.parcel_mass_kg);
        c.positive("release_height_m", self.release_height_m);
        c.positive("domain_radius_over_radius", self.domain_radius_over_radius);
        c.positive("domain_height_over_radius", self.domain_height_over_radius);
    }
}

/// A pilot's line of sight.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineOfSight {
    pub name: String,
    /// Eye point and target point \[m\] (rotor axis through the origin, ground at z = 0).
    pub from_m: Vec3,
    pub to_m: Vec3,
}

/// What is written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputConfig {
    /// Interval of the time series rows, cloud snapshots and optical depths \[s\].
    #[serde(default = "interval")]
    pub interval_s: f64,
    /// Cells of the concentration grid over the domain (x, y, z).
    #[serde(default = "cells")]
    pub grid_cells: [usize; 3],
    #[serde(default)]
    pub lines_of_sight: Vec<LineOfSight>,
}

fn interval() -> f64 {
    0.1
}
fn cells() -> [usize; 3] {
    [48, 48, 16]
}

impl Default for OutputConfig {
    fn default() -> Self {
        OutputConfig { interval_s: interval(), grid_cells: cells(), lines_of_sight: Vec::new() }
    }
}

impl BrownoutConfig {
    /// The cloud's domain box \[m\].
    pub fn domain(&self) -> Aabb {
        let r = self.rotor.radius_m;
        let w = self.cloud.domain_radius_over_radius * r;
        Aabb::new(Vec3::new(-w, -w, 0.0), Vec3::new(w, w, self.cloud.domain_height_over_radius * r))
    }

    /// The moment-balance settings of the ground.
    pub fn rocking(&self) -> RockingSettings {
        RockingSettings {
            surface_energy: self.ground.surface_energy_j_m2,
            pull_off: self.ground.pull_off,
            asperity_ratio: self.ground.asperity_ratio,
            wall_lift: self.liftoff.wall_lift,
            ..RockingSettings::default()
        }
    }
}

impl Validate for BrownoutConfig {
    fn validate(&self, c: &mut Checker) {
        c.item("rotor", &self.rotor);
        c.item("flow", &self.flow);
        if !matches!(self.flow, FlowChoice::Analytic) && self.rotor.tip_vortices {
            c.nested("rotor", |c| {
                c.fail(
                    "tip_vortices",
                    "tip_vortices = true: the analytic tip vortices belong to flow.kind = \"analytic\"; a RANS flow is the mean flow and an imported field carries its own vortices (set tip_vortices = false)",
                )
            });
        }
        c.item("air", &self.air);
        c.item("ground", &self.ground);
        c.item("liftoff", &self.liftoff);
        c.item("entrainment", &self.entrainment);
        c.item("cloud", &self.cloud);
        match (&self.dem_bed, self.entrainment.source) {
            (None, EntrainmentSource::DemBed) => c.nested("entrainment", |c| {
                c.fail("source", "source = \"dem_bed\" needs a [dem_bed] table (the bed patch under the rotor)")
            }),
            (Some(_), EntrainmentSource::Model) => c.fail(
                "dem_bed",
                "[dem_bed] is given but entrainment.source = \"model\"; set entrainment.source = \"dem_bed\" to run the bed patch, or remove [dem_bed]",
            ),
            (Some(b), EntrainmentSource::DemBed) => {
                c.item("dem_bed", b);
                let (r, w) = (self.rotor.radius_m, self.cloud.domain_radius_over_radius);
                let reach = b.radius_over_radius * r + b.patch_size_m[0].max(b.patch_size_m[1]);
                if r > 0.0 && w > 0.0 && reach >= w * r {
                    c.nested("dem_bed", |c| {
                        c.fail(
                            "radius_over_radius",
                            format!(
                                "radius_over_radius = {}: the patch (centre {:.3} m from the rotor axis) lies outside the cloud domain, which ends {:.3} m from the axis (cloud.domain_radius_over_radius × R)",
                                b.radius_over_radius,
                                b.radius_over_radius * r,
                                w * r
                            ),
                        )
                    });
                }
                if self.cloud.duration_s.is_finite() && b.duration_s > self.cloud.duration_s {
                    c.nested("dem_bed", |c| {
                        c.fail(
                            "duration_s",
                            format!(
                                "duration_s = {} s is longer than the cloud's duration_s = {} s",
                                b.duration_s, self.cloud.duration_s
                            ),
                        )
                    });
                }
            }
            (None, EntrainmentSource::Model) => {}
        }
        c.nested("output", |c| {
            c.positive("interval_s", self.output.interval_s);
            if self.output.grid_cells.iter().any(|&n| n == 0 || n > 1000) {
                c.fail(
                    "grid_cells",
                    format!("grid_cells = {:?}: each count must be 1 to 1000", self.output.grid_cells),
                );
            }
        });
        let dom = self.domain();
        if self.rotor.radius_m > 0.0
            && self.cloud.domain_radius_over_radius > 0.0
            && self.cloud.domain_height_over_radius > 0.0
        {
            for (i, l) in self.output.lines_of_sight.iter().enumerate() {
                c.element("output.lines_of_sight", i, |c| {
                    for (key, p) in [("from_m", l.from_m), ("to_m", l.to_m)] {
                        if !dom.contains(p) {
                            c.fail(
                                key,
                                format!(
                                    "line of sight `{}`: {key} = [{}, {}, {}] m lies outside the cloud domain [{}, {}] × [{}, {}] × [0, {}] m (cloud.domain_radius_over_radius, cloud.domain_height_over_radius)",
                                    l.name, p.x, p.y, p.z, dom.min.x, dom.max.x, dom.min.y, dom.max.y, dom.max.z
                                ),
                            );
                        }
                    }
                });
            }
        }
    }
}

impl spatter_io::run::Smoke for BrownoutConfig {
    fn smoke(&mut self) {
        self.cloud.duration_s = self.cloud.duration_s.min(5.0 * self.cloud.dt_s);
        self.output.interval_s = self.output.interval_s.min(2.0 * self.cloud.dt_s);
        self.output.grid_cells = [8, 8, 4];
        self.liftoff.points = self.liftoff.points.min(8);
        self.liftoff.exceedance_samples = self.liftoff.exceedance_samples.min(4);
        self.entrainment.annuli = self.entrainment.annuli.min(6);
        self.entrainment.phases = self.entrainment.phases.min(2);
        if let Some(b) = &mut self.dem_bed {
            b.duration_s = b.duration_s.min(self.cloud.duration_s);
            b.settle_s = Some(b.settle_s.map_or(2e-3, |s| s.min(2e-3)));
            b.layers = b.layers.min(2);
            if let Some(d) = b.grain_diameter_m {
                // At most 6 × 4 grains per layer.
                b.patch_size_m = [b.patch_size_m[0].min(7.4 * d), b.patch_size_m[1].min(5.0 * d)];
            }
        }
        if let FlowChoice::Rans(r) = &mut self.flow {
            r.radial_cells = r.radial_cells.min(16);
            r.axial_cells = r.axial_cells.min(12);
            r.max_steps = Some(r.max_steps.map_or(20, |n| n.min(20)));
        }
    }
}
