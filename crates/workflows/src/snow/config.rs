//! Configuration of the `snow_regime_map` scenario kind. Every key is documented in `docs/snow.md`.

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::material::Material;
use spatter_dem::adhesion::{AdhesiveCoulomb, BreakCriterion, JkrDamping};
use spatter_dem::contact::RestitutionCalibration;
use spatter_dem::restitution_models::RestitutionModel;

use super::impact::StickCriterion;

/// What the run does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Every (diameter, normal speed[, angle]) of the grid (default).
    #[default]
    Grid,
    /// v_crit(d) by bisection for every diameter of the grid.
    Bisection,
    /// The grid for the baseline and every sensitivity case.
    Sensitivity,
    /// Stick probability against normal speed on a bed of frozen spheres.
    RoughWall,
    /// One impact recorded step by step (force–overlap loop, trajectory).
    Single,
}

/// What the particle hits in grid and bisection modes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TargetKind {
    /// A flat wall of the wall material (default).
    #[default]
    Wall,
    /// One frozen sphere of the wall material (infinite mass), diameter `partner_diameter_m`.
    WallSphere,
    /// A free particle of the particle material at rest, diameter `partner_diameter_m` (default: equal).
    Particle,
}

/// Normal contact law.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NormalLawKind {
    /// Full hysteretic JKR (default).
    #[default]
    Jkr,
    /// DMT: Hertz − 2πΓR*.
    Dmt,
    /// Simplified JKR: Hertz − (3/2)πΓR*.
    Sjkr,
    /// Hertz without adhesion.
    Hertz,
}

/// Which E* enters the yield velocity of the restitution model (the thesis does not say).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CorModulus {
    /// The E* of the contacting pair (ice–ABS on the wall). Default.
    #[default]
    Pair,
    /// The E* of two particles (ice–ice).
    Particle,
}

/// Axis spacing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Spacing {
    #[default]
    Linear,
    Log,
}

/// `[contact]`: the contact law of particle and wall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactConfig {
    pub normal_law: NormalLawKind,
    /// Γ \[J/m²\].
    pub work_of_adhesion_j_m2: f64,
    pub break_criterion: BreakCriterion,
    pub damping_stiffness: JkrDamping,
    pub damping_calibration: RestitutionCalibration,
    pub tensile_clamp: bool,
    pub tangential_damping: bool,
    pub coulomb_normal_force: AdhesiveCoulomb,
    /// Sliding friction μ \[-\].
    pub friction: f64,
    /// Constant-torque rolling friction μ_r \[-\] (0 = none).
    pub rolling_friction: f64,
    pub restitution: RestitutionModel,
    pub restitution_modulus: CorModulus,
}

impl Default for ContactConfig {
    fn default() -> Self {
        ContactConfig {
            normal_law: NormalLawKind::Jkr,
            work_of_adhesion_j_m2: 0.2,
            break_criterion: BreakCriterion::CriticalOverlap,
            damping_stiffness: JkrDamping::Overlap,
            damping_calibration: RestitutionCalibration::Linearised,
            tensile_clamp: false,
            tangential_damping: true,
            coulomb_normal_force: AdhesiveCoulomb::PlusTwicePullOff,
            friction: 0.05,
            rolling_friction: 0.0,
            restitution: RestitutionModel::default(),
            restitution_modulus: CorModulus::Pair,
        }
    }
}

impl Validate for ContactConfig {
    fn validate(&self, c: &mut Checker) {
        c.non_negative("work_of_adhesion_j_m2", self.work_of_adhesion_j_m2);
        c.non_negative("friction", self.friction);
        c.non_negative("rolling_friction", self.rolling_friction);
        c.item("restitution", &self.restitution);
    }
}

/// `[integration]`: time step, check time and stick criterion.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IntegrationConfig {
    /// Time steps per Hertz contact time: Δt = t_H / this (ignored when `dt_s` is set).
    pub steps_per_contact: f64,
    /// Fixed time step \[s\] for every run (the thesis used 1e-9).
    pub dt_s: Option<f64>,
    /// Check time in Hertz contact times after first touch.
    pub check_time_contacts: f64,
    /// Fixed check time \[s\] (overrides `check_time_contacts`).
    pub check_time_s: Option<f64>,
    pub stick_criterion: StickCriterion,
    /// Slip speed counted as static, as a fraction of the impact speed.
    pub static_slip_ratio: f64,
    /// Relative safety margin of the early "bound" decision.
    pub bound_margin: f64,
    /// Dashpot forces from velocities predicted to the end of the step (true) or from the half-step
    /// velocities of plain velocity Verlet (false, LIGGGHTS).
    pub predict_velocity: bool,
}

impl Default for IntegrationConfig {
    fn default() -> Self {
        IntegrationConfig {
            steps_per_contact: 200.0,
            dt_s: None,
            check_time_contacts: 20.0,
            check_time_s: None,
            stick_criterion: StickCriterion::NormalOverlap,
            static_slip_ratio: 1e-3,
            bound_margin: 0.01,
            predict_velocity: true,
        }
    }
}

/// Largest accepted `steps_per_contact`: a run polls for a stop between impacts, so one impact must stay
/// short; 1e6 steps per Hertz time is far beyond where the integration error stops changing.
pub const MAX_STEPS_PER_CONTACT: f64 = 1e6;

impl Validate for IntegrationConfig {
    fn validate(&self, c: &mut Checker) {
        if !(self.steps_per_contact.is_finite() && self.steps_per_contact >= 10.0) {
            c.fail(
                "steps_per_contact",
                format!("steps_per_contact = {} must be at least 10", self.steps_per_contact),
            );
        } else if self.steps_per_contact > MAX_STEPS_PER_CONTACT {
            c.fail(
                "steps_per_contact",
                format!(
                    "steps_per_contact = {} is above {MAX_STEPS_PER_CONTACT:e}: one impact would take hours and \
                     could not be stopped between impacts (the integration error is at round-off level from \
                     about 1e4 steps per contact)",
                    self.steps_per_contact
                ),
            );
        }
        if let Some(dt) = self.dt_s {
            c.positive("dt_s", dt);
        }
        c.positive("check_time_contacts", self.check_time_contacts);
        if let Some(t) = self.check_time_s {
            c.positive("check_time_s", t);
        }
        c.in_range("static_slip_ratio", self.static_slip_ratio, 0.0, false, 1.0, true);
        c.in_range("bound_margin", self.bound_margin, 0.0, true, 0.5, true);
    }
}

/// `[grid]`: the (diameter, normal speed[, angle]) grid, also the diameter list of bisection mode.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GridConfig {
    pub diameter_min_m: f64,
    pub diameter_max_m: f64,
    pub diameters: usize,
    pub diameter_spacing: Spacing,
    /// Lowest normal speed \[m/s\] (default: `velocity_scale_m_s` / `normal_speeds`).
    pub normal_speed_min_m_s: Option<f64>,
    /// Highest normal speed \[m/s\] (default: `velocity_scale_m_s`).
    pub normal_speed_max_m_s: Option<f64>,
    pub normal_speeds: usize,
    pub speed_spacing: Spacing,
    /// Impact angles from the wall normal \[deg\]; v_t = v_n tan θ. One angle 0 = normal impacts.
    pub angles_deg: Vec<f64>,
    /// Speed that normalised axes divide by \[m/s\].
    pub velocity_scale_m_s: f64,
    /// Length that normalised diameters divide by \[m\].
    pub diameter_scale_m: f64,
    /// Plot normalised axes (true) or SI axes.
    pub normalised_axes: bool,
    /// Refine every grid interface bracket by bisection (to `bisection.relative_tolerance`) before fitting.
    pub refine_interface: bool,
}

/// Largest number of impacts one run may ask for (grid points × angles, × cases in sensitivity mode; speeds
/// × impacts per speed on the rough wall). Every impact keeps a record of about 150 bytes, so the cap
/// bounds the memory of a run to a few hundred MB; the thesis map has 2300.
pub const MAX_IMPACTS: u64 = 2_000_000;

/// Product of job counts without overflow (saturating), for the cap checks.
fn job_count(factors: &[usize]) -> u64 {
    factors.iter().fold(1u64, |acc, &f| acc.saturating_mul(f as u64))
}

/// The velocity scale chosen for the thesis's normalised axes (see `docs/snow.md`, "Velocity
/// normalisation").
pub const THESIS_VELOCITY_SCALE: f64 = 16.0;

impl Default for GridConfig {
    fn default() -> Self {
        GridConfig {
            diameter_min_m: 10e-6,
            diameter_max_m: 100e-6,
            diameters: 46,
            diameter_spacing: Spacing::Linear,
            normal_speed_min_m_s: None,
            normal_speed_max_m_s: None,
            normal_speeds: 50,
            speed_spacing: Spacing::Linear,
            angles_deg: vec![0.0],
            velocity_scale_m_s: THESIS_VELOCITY_SCALE,
            diameter_scale_m: 1e-3,
            normalised_axes: true,
            refine_interface: true,
        }
    }
}

fn axis(lo: f64, hi: f64, n: usize, spacing: Spacing) -> Vec<f64> {
    if n == 1 {
        return vec![lo];
    }
    (0..n)
        .map(|i| {
            let f = i as f64 / (n - 1) as f64;
            match spacing {
                Spacing::Linear => lo + f * (hi - lo),
                Spacing::Log => lo * (hi / lo).powf(f),
            }
        })
        .collect()
}

impl GridConfig {
    /// Diameters \[m\].
    pub fn diameter_axis(&self) -> Vec<f64> {
        axis(self.diameter_min_m, self.diameter_max_m, self.diameters, self.diameter_spacing)
    }

    /// Lowest and highest normal speed \[m/s\].
    pub fn speed_range(&self) -> (f64, f64) {
        (
            self.normal_speed_min_m_s.unwrap_or(self.velocity_scale_m_s / self.normal_speeds.max(1) as f64),
            self.normal_speed_max_m_s.unwrap_or(self.velocity_scale_m_s),
        )
    }

    /// Normal speeds \[m/s\].
    pub fn speed_axis(&self) -> Vec<f64> {
        let (lo, hi) = self.speed_range();
        axis(lo, hi, self.normal_speeds, self.speed_spacing)
    }

    /// Number of impacts of the grid: diameters × normal speeds × angles (saturating).
    pub fn jobs(&self) -> u64 {
        job_count(&[self.diameters, self.normal_speeds, self.angles_deg.len()])
    }
}

/// Accepted particle and bed-sphere diameters \[m\]: from 1 nm (below it the continuum contact laws do not
/// apply, and the impact arithmetic loses its meaning — 1e-300 m gave NaN rebound speeds) to 10 cm.
pub const DIAMETER_RANGE_M: (f64, f64) = (1e-9, 0.1);

/// `d` must be a diameter in [`DIAMETER_RANGE_M`].
fn grain_diameter(c: &mut Checker, key: &str, d: f64) {
    let (lo, hi) = DIAMETER_RANGE_M;
    if d.is_nan() || d <= 0.0 {
        c.positive(key, d);
    } else if !(lo..=hi).contains(&d) {
        c.fail(key, format!("{key} = {d} must be a diameter between {lo:e} and {hi:e} m"));
    }
}

impl Validate for GridConfig {
    fn validate(&self, c: &mut Checker) {
        grain_diameter(c, "diameter_min_m", self.diameter_min_m);
        grain_diameter(c, "diameter_max_m", self.diameter_max_m);
        if self.diameter_max_m < self.diameter_min_m {
            c.fail(
                "diameter_max_m",
                format!(
                    "diameter_max_m = {} is below diameter_min_m = {}",
                    self.diameter_max_m, self.diameter_min_m
                ),
            );
        }
        if self.diameters == 0 || self.diameters > 100_000 {
            c.fail("diameters", format!("diameters = {} must be between 1 and 100000", self.diameters));
        }
        if self.normal_speeds == 0 || self.normal_speeds > 100_000 {
            c.fail(
                "normal_speeds",
                format!("normal_speeds = {} must be between 1 and 100000", self.normal_speeds),
            );
        }
        c.positive("velocity_scale_m_s", self.velocity_scale_m_s);
        c.positive("diameter_scale_m", self.diameter_scale_m);
        if let Some(v) = self.normal_speed_min_m_s {
            c.positive("normal_speed_min_m_s", v);
        }
        if let Some(v) = self.normal_speed_max_m_s {
            c.positive("normal_speed_max_m_s", v);
        }
        let (lo, hi) = self.speed_range();
        if self.velocity_scale_m_s > 0.0 && hi < lo {
            c.fail(
                "normal_speed_max_m_s",
                format!("normal_speed_max_m_s = {hi} is below the lowest speed {lo}"),
            );
        }
        if self.angles_deg.is_empty() {
            c.fail("angles_deg", "angles_deg must list at least one angle (0 for normal impacts)");
        }
        let jobs = self.jobs();
        if jobs > MAX_IMPACTS {
            let key = if self.normal_speeds >= self.diameters { "normal_speeds" } else { "diameters" };
            c.fail(
                key,
                format!(
                    "diameters × normal_speeds × angles_deg = {} × {} × {} = {jobs} impacts is above the cap of {MAX_IMPACTS} impacts per run",
                    self.diameters,
                    self.normal_speeds,
                    self.angles_deg.len()
                ),
            );
        }
        for (i, a) in self.angles_deg.iter().enumerate() {
            c.element("angles_deg", i, |c| c.in_range("", *a, 0.0, true, 89.0, true));
        }
    }
}

/// `[bisection]`: v_crit(d) by bisection.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BisectionConfig {
    /// Initial bracket, lower end \[m/s\] (default: the grid's lowest speed).
    pub speed_low_m_s: Option<f64>,
    /// Initial bracket, upper end \[m/s\] (default: the grid's highest speed).
    pub speed_high_m_s: Option<f64>,
    /// Relative width of the final bracket.
    pub relative_tolerance: f64,
    /// How often the bracket may be widened by a factor of 4 when it does not contain v_crit.
    pub max_expansions: u32,
}

impl Default for BisectionConfig {
    fn default() -> Self {
        BisectionConfig {
            speed_low_m_s: None,
            speed_high_m_s: None,
            relative_tolerance: 1e-3,
            max_expansions: 6,
        }
    }
}

impl Validate for BisectionConfig {
    fn validate(&self, c: &mut Checker) {
        if let Some(v) = self.speed_low_m_s {
            c.positive("speed_low_m_s", v);
        }
        if let Some(v) = self.speed_high_m_s {
            c.positive("speed_high_m_s", v);
        }
        if let (Some(lo), Some(hi)) = (self.speed_low_m_s, self.speed_high_m_s) {
            if hi <= lo {
                c.fail("speed_high_m_s", format!("speed_high_m_s = {hi} must be above speed_low_m_s = {lo}"));
            }
        }
        c.in_range("relative_tolerance", self.relative_tolerance, 1e-9, true, 0.5, true);
    }
}

/// `[fit]`: least-squares polynomials of the stick/bounce boundary (log10–log10).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FitConfig {
    /// Polynomial degree.
    pub degree: usize,
    /// Fit in log10–log10 space (true) or in SI units.
    pub log10: bool,
}

impl Default for FitConfig {
    fn default() -> Self {
        FitConfig { degree: 2, log10: true }
    }
}

impl Validate for FitConfig {
    fn validate(&self, c: &mut Checker) {
        if self.degree > 8 {
            c.fail("degree", format!("degree = {} is above 8", self.degree));
        }
    }
}

/// One sensitivity case: the baseline with some values replaced.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensitivityCase {
    pub name: String,
    /// Particle Young's modulus \[Pa\].
    #[serde(default)]
    pub youngs_modulus_pa: Option<f64>,
    /// Particle Poisson ratio.
    #[serde(default)]
    pub poisson_ratio: Option<f64>,
    /// Γ \[J/m²\].
    #[serde(default)]
    pub work_of_adhesion_j_m2: Option<f64>,
    /// Yield stress of the Thornton restitution model \[Pa\].
    #[serde(default)]
    pub yield_stress_pa: Option<f64>,
    /// The thesis's stick count for this case, printed beside ours.
    #[serde(default)]
    pub thesis_sticks: Option<u32>,
}

impl SensitivityCase {
    fn new(
        name: &str,
        e: Option<f64>,
        nu: Option<f64>,
        g: Option<f64>,
        sy: Option<f64>,
        thesis: u32,
    ) -> Self {
        SensitivityCase {
            name: name.into(),
            youngs_modulus_pa: e,
            poisson_ratio: nu,
            work_of_adhesion_j_m2: g,
            yield_stress_pa: sy,
            thesis_sticks: Some(thesis),
        }
    }

    /// Baseline and the Table 3 extremes with the thesis's stick counts (L503–531).
    pub fn thesis_table() -> Vec<SensitivityCase> {
        vec![
            Self::new("baseline", None, None, None, None, 217),
            Self::new("E = 8.9 GPa", Some(8.9e9), None, None, None, 222),
            Self::new("E = 11.2 GPa", Some(11.2e9), None, None, None, 215),
            Self::new("nu = 0.29", None, Some(0.29), None, None, 217),
            Self::new("nu = 0.36", None, Some(0.36), None, None, 217),
            Self::new("Gamma = 0.1 J/m2", None, None, Some(0.1), None, 71),
            Self::new("Gamma = 1 J/m2", None, None, Some(1.0), None, 1283),
            Self::new("sigma_y = 0.5 MPa", None, None, None, Some(0.5e6), 512),
            Self::new("sigma_y = 1.5 MPa", None, None, None, Some(1.5e6), 88),
        ]
    }
}

/// `[sensitivity]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensitivityConfig {
    pub cases: Vec<SensitivityCase>,
}

impl Default for SensitivityConfig {
    fn default() -> Self {
        SensitivityConfig { cases: SensitivityCase::thesis_table() }
    }
}

impl Validate for SensitivityConfig {
    fn validate(&self, c: &mut Checker) {
        if self.cases.is_empty() {
            c.fail("cases", "cases must list at least one case");
        }
        for (i, k) in self.cases.iter().enumerate() {
            c.element("cases", i, |c| {
                if let Some(v) = k.youngs_modulus_pa {
                    c.positive("youngs_modulus_pa", v);
                }
                if let Some(v) = k.poisson_ratio {
                    c.in_range("poisson_ratio", v, 0.0, true, 0.5, false);
                }
                if let Some(v) = k.work_of_adhesion_j_m2 {
                    c.non_negative("work_of_adhesion_j_m2", v);
                }
                if let Some(v) = k.yield_stress_pa {
                    c.positive("yield_stress_pa", v);
                }
            });
        }
    }
}

/// How the rough-wall bed is built.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Packing {
    /// Uniformly random centres in the bed box at the target volume fraction, overlaps allowed (thesis).
    #[default]
    RandomInsertion,
    /// Spheres dropped into the box and relaxed under gravity until no two overlap.
    Settled,
}

/// `[rough_wall]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RoughWallConfig {
    /// Diameter of the impacting particle \[m\].
    pub particle_diameter_m: f64,
    /// Diameter of the bed spheres \[m\].
    pub bed_sphere_diameter_m: f64,
    pub packing: Packing,
    /// Nominal volume fraction of the bed (random insertion counts overlapping volume twice).
    pub volume_fraction: f64,
    /// Bed thickness \[m\] (default 4 bed-sphere diameters).
    pub bed_thickness_m: Option<f64>,
    /// Side of the square bed \[m\] (default 3 particle diameters).
    pub bed_width_m: Option<f64>,
    pub impacts_per_speed: usize,
    /// Lowest normal speed \[m/s\] (default 0.005 × the grid's velocity scale).
    pub normal_speed_min_m_s: Option<f64>,
    /// Highest normal speed \[m/s\] (default 0.3 × the grid's velocity scale).
    pub normal_speed_max_m_s: Option<f64>,
    pub normal_speeds: usize,
    pub speed_spacing: Spacing,
    /// Seed of the bed and of the impact positions.
    pub seed: u64,
    /// Confidence level of the Wilson intervals.
    pub confidence: f64,
}

impl Default for RoughWallConfig {
    fn default() -> Self {
        RoughWallConfig {
            particle_diameter_m: 10e-6,
            bed_sphere_diameter_m: 1e-6,
            packing: Packing::RandomInsertion,
            volume_fraction: 0.64,
            bed_thickness_m: None,
            bed_width_m: None,
            impacts_per_speed: 40,
            normal_speed_min_m_s: None,
            normal_speed_max_m_s: None,
            normal_speeds: 30,
            speed_spacing: Spacing::Log,
            seed: 1,
            confidence: 0.95,
        }
    }
}

impl RoughWallConfig {
    /// Normal speeds \[m/s\] for the velocity scale `scale` \[m/s\].
    pub fn speed_axis(&self, scale: f64) -> Vec<f64> {
        let (lo, hi) = self.speed_range(scale);
        axis(lo, hi, self.normal_speeds, self.speed_spacing)
    }

    /// Lowest and highest normal speed \[m/s\] for the velocity scale `scale` \[m/s\].
    pub fn speed_range(&self, scale: f64) -> (f64, f64) {
        (self.normal_speed_min_m_s.unwrap_or(0.005 * scale), self.normal_speed_max_m_s.unwrap_or(0.3 * scale))
    }

    pub fn bed_thickness(&self) -> f64 {
        self.bed_thickness_m.unwrap_or(4.0 * self.bed_sphere_diameter_m)
    }

    pub fn bed_width(&self) -> f64 {
        self.bed_width_m.unwrap_or(3.0 * self.particle_diameter_m)
    }
}

impl Validate for RoughWallConfig {
    fn validate(&self, c: &mut Checker) {
        grain_diameter(c, "particle_diameter_m", self.particle_diameter_m);
        grain_diameter(c, "bed_sphere_diameter_m", self.bed_sphere_diameter_m);
        c.in_range("volume_fraction", self.volume_fraction, 0.0, false, 2.0, true);
        if let Some(v) = self.bed_thickness_m {
            c.positive("bed_thickness_m", v);
            if v < self.bed_sphere_diameter_m {
                c.fail(
                    "bed_thickness_m",
                    format!(
                        "bed_thickness_m = {v} is below bed_sphere_diameter_m = {}: the bed must hold one layer",
                        self.bed_sphere_diameter_m
                    ),
                );
            }
        }
        if let Some(w) = self.bed_width_m {
            c.positive("bed_width_m", w);
            if w < 2.0 * self.particle_diameter_m {
                c.fail("bed_width_m", format!("bed_width_m = {w} must be at least two particle diameters"));
            }
        }
        let count = self.bed_width().powi(2) * self.bed_thickness() * self.volume_fraction
            / (std::f64::consts::PI / 6.0 * self.bed_sphere_diameter_m.powi(3));
        if count > 2.0e6 {
            c.fail("bed_width_m", format!("the bed would hold {count:.0} spheres; at most 2e6 are allowed"));
        }
        if self.impacts_per_speed == 0 {
            c.fail("impacts_per_speed", "impacts_per_speed must be at least 1");
        }
        if self.normal_speeds == 0 {
            c.fail("normal_speeds", "normal_speeds must be at least 1");
        }
        if let Some(v) = self.normal_speed_min_m_s {
            c.positive("normal_speed_min_m_s", v);
        }
        if let Some(v) = self.normal_speed_max_m_s {
            c.positive("normal_speed_max_m_s", v);
        }
        let jobs = job_count(&[self.normal_speeds, self.impacts_per_speed]);
        if jobs > MAX_IMPACTS {
            let key = if self.normal_speeds >= self.impacts_per_speed {
                "normal_speeds"
            } else {
                "impacts_per_speed"
            };
            c.fail(
                key,
                format!(
                    "normal_speeds × impacts_per_speed = {} × {} = {jobs} impacts is above the cap of {MAX_IMPACTS} impacts per run",
                    self.normal_speeds, self.impacts_per_speed
                ),
            );
        }
        c.in_range("confidence", self.confidence, 0.5, true, 1.0, false);
    }
}

/// `[single]`: the impact of `mode = "single"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SingleConfig {
    /// Particle diameter \[m\].
    pub diameter_m: f64,
    /// Normal impact speed \[m/s\].
    pub normal_speed_m_s: f64,
    /// Tangential impact speed \[m/s\].
    pub tangential_speed_m_s: f64,
}

impl Default for SingleConfig {
    fn default() -> Self {
        SingleConfig { diameter_m: 10e-6, normal_speed_m_s: 10.0, tangential_speed_m_s: 0.0 }
    }
}

impl Validate for SingleConfig {
    fn validate(&self, c: &mut Checker) {
        grain_diameter(c, "diameter_m", self.diameter_m);
        c.positive("normal_speed_m_s", self.normal_speed_m_s);
        c.non_negative("tangential_speed_m_s", self.tangential_speed_m_s);
    }
}

/// The `snow_regime_map` scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SnowConfig {
    #[serde(default)]
    pub mode: Mode,
    /// The impacting particle (ice, thesis Table 2).
    #[serde(default = "ice")]
    pub particle: Material,
    /// Temperature of the ice particle \[°C\], in \[−40, 0\]. When given, the particle's Young's modulus
    /// is E_ice(T) of thesis Eq. 20 ([`super::material::ice_youngs_modulus`]) and replaces `particle.youngs_modulus_pa`
    /// (sensitivity cases that set a modulus still replace it in turn). See [`SnowConfig::resolved`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ice_temperature_c: Option<f64>,
    /// The wall (ABS, thesis Table 2); also the material of wall spheres and the rough-wall bed.
    #[serde(default = "abs")]
    pub wall: Material,
    #[serde(default)]
    pub target: TargetKind,
    /// Diameter of the partner sphere for `wall_sphere` (default 1 µm) and `particle` (default: the
    /// particle's own) targets \[m\].
    #[serde(default)]
    pub partner_diameter_m: Option<f64>,
    #[serde(default)]
    pub contact: ContactConfig,
    #[serde(default)]
    pub integration: IntegrationConfig,
    #[serde(default)]
    pub grid: GridConfig,
    #[serde(default)]
    pub bisection: BisectionConfig,
    #[serde(default)]
    pub fit: FitConfig,
    #[serde(default)]
    pub sensitivity: SensitivityConfig,
    #[serde(default)]
    pub rough_wall: RoughWallConfig,
    #[serde(default)]
    pub single: SingleConfig,
    /// Also write SVG versions of the pictures.
    #[serde(default = "yes")]
    pub svg: bool,
}

fn yes() -> bool {
    true
}

/// Accepted `ice_temperature_c` \[°C\]: ice below its melting point, and not so cold that the fit of
/// thesis Eq. 20 (measurements mostly at −12 °C) is stretched far beyond its data (E = 10.5 GPa at −30 °C,
/// 11.5 GPa at −40 °C).
pub const ICE_TEMPERATURE_RANGE_C: (f64, f64) = (-40.0, 0.0);

impl SnowConfig {
    /// The configuration the run uses: `ice_temperature_c`, when given, turned into the particle's
    /// Young's modulus by thesis Eq. 20; otherwise a copy.
    pub fn resolved(&self) -> SnowConfig {
        let mut c = self.clone();
        if let Some(t) = self.ice_temperature_c {
            c.particle.youngs_modulus = super::material::ice_youngs_modulus(t);
        }
        c
    }
}

/// Ice (thesis Table 2): E = 9.8 GPa, ν = 0.31, ρ = 920 kg/m³.
pub fn ice() -> Material {
    Material { youngs_modulus: 9.8e9, poisson_ratio: 0.31, density: 920.0 }
}

/// ABS plastic (thesis Table 2): E = 2.0 GPa, ν = 0.35, ρ = 1100 kg/m³.
pub fn abs() -> Material {
    Material { youngs_modulus: 2.0e9, poisson_ratio: 0.35, density: 1100.0 }
}

impl Default for SnowConfig {
    /// The thesis baseline: ice on ABS, grid mode.
    fn default() -> Self {
        SnowConfig {
            mode: Mode::Grid,
            particle: ice(),
            ice_temperature_c: None,
            wall: abs(),
            target: TargetKind::Wall,
            partner_diameter_m: None,
            contact: ContactConfig::default(),
            integration: IntegrationConfig::default(),
            grid: GridConfig::default(),
            bisection: BisectionConfig::default(),
            fit: FitConfig::default(),
            sensitivity: SensitivityConfig::default(),
            rough_wall: RoughWallConfig::default(),
            single: SingleConfig::default(),
            svg: true,
        }
    }
}

impl spatter_io::run::Smoke for SnowConfig {
    /// A 6 × 5 grid (bisection and sensitivity work on its diameters and speeds), a coarse bisection
    /// tolerance, and 3 speeds × 3 impacts on the rough wall.
    fn smoke(&mut self) {
        self.grid.diameters = self.grid.diameters.min(6);
        self.grid.normal_speeds = self.grid.normal_speeds.min(5);
        self.bisection.relative_tolerance = self.bisection.relative_tolerance.max(0.05);
        self.rough_wall.normal_speeds = self.rough_wall.normal_speeds.min(3);
        self.rough_wall.impacts_per_speed = self.rough_wall.impacts_per_speed.min(3);
    }
}
