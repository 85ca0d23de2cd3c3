//! Scenario configuration of the `deposition` and `forces` kinds. Every key is documented with its unit
//! and default in `docs/deposition.md` and `docs/flow.md`.

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;
use spatter_flow::field::analytic::{AnalyticField, ConstantTurbulence};
use spatter_flow::field::dispersion::DispersionSettings;
use spatter_flow::field::imported::{ArrayNames, Interpolation};
use spatter_flow::forces::model::ForceSwitches;
use spatter_flow::forces::ranking::RankingFactors;
use spatter_flow::forces::Fluid;
use spatter_flow::tracker::inject::InjectorSpec;
use spatter_flow::tracker::walls::WallRuleSpec;
use std::path::{Path, PathBuf};

/// `kind = "deposition"`: particles carried by a flow field onto STL bodies.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepositionConfig {
    #[serde(default)]
    pub fluid: Fluid,
    pub flow: FlowSpec,
    #[serde(default)]
    pub forces: ForceSwitches,
    /// Turbulent dispersion (discrete random walk); absent = off.
    #[serde(default)]
    pub dispersion: Option<DispersionSettings>,
    #[serde(default)]
    pub bodies: Vec<BodySpec>,
    pub injectors: Vec<InjectorSpec>,
    pub time: TimeSpec,
    /// Parcels leaving this box escape; absent = only the field's own domain.
    #[serde(default)]
    pub domain: Option<DomainBox>,
    #[serde(default)]
    pub output: OutputSpec,
}

/// The flow field: exactly one of `vtk`, `series`, `files` or `analytic`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowSpec {
    /// One VTK file (steady field).
    #[serde(default)]
    pub vtk: Option<PathBuf>,
    /// A `.pvd` or `.series` file listing a time series.
    #[serde(default)]
    pub series: Option<PathBuf>,
    /// An explicit time series.
    #[serde(default)]
    pub files: Vec<TimedFile>,
    /// Analytic fields (summed).
    #[serde(default)]
    pub analytic: Vec<AnalyticField>,
    /// Constant k and ε for analytic fields (drives the random walk).
    #[serde(default)]
    pub turbulence: Option<ConstantTurbulence>,
    #[serde(default)]
    pub interpolation: Interpolation,
    #[serde(default)]
    pub arrays: ArrayNames,
    /// Multiplies the coordinates of imported files (1e-3 for millimetres).
    #[serde(default = "one")]
    pub length_scale: f64,
    /// Period of a cyclic time series \[s\].
    #[serde(default)]
    pub period_s: Option<f64>,
}

/// One file of a time series.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimedFile {
    pub time_s: f64,
    pub file: PathBuf,
}

fn one() -> f64 {
    1.0
}

/// A body: an STL/OBJ surface with a wall rule.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    pub file: PathBuf,
    /// Multiplies the file's coordinates (1e-3 for millimetres).
    #[serde(default = "one")]
    pub scale: f64,
    /// Added after scaling \[m\].
    #[serde(default)]
    pub translate_m: Vec3,
    pub wall: WallRuleSpec,
    /// Distance from the wall at which the velocity is sampled for the wall-shear estimate τ_w ≈ μ u_t/h
    /// \[m\] (used with `max_wall_shear_pa` and by `[forces] wall_lift` without a fixed friction velocity).
    #[serde(default = "default_probe")]
    pub shear_probe_distance_m: f64,
    /// View direction (from the camera towards the body) of the deposit picture.
    #[serde(default = "default_view")]
    pub view_direction: Vec3,
    /// Screen-up direction of the deposit picture.
    #[serde(default = "default_up")]
    pub view_up: Vec3,
}

fn default_probe() -> f64 {
    1e-3
}
fn default_view() -> Vec3 {
    Vec3::new(-1.0, -1.0, -1.0)
}
fn default_up() -> Vec3 {
    Vec3::Z
}

/// Time stepping.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    pub dt_s: f64,
    pub duration_s: f64,
    /// Stop before `duration_s` once every injector is done and no parcel is airborne.
    #[serde(default = "yes")]
    pub stop_when_settled: bool,
}

fn yes() -> bool {
    true
}

/// A box \[m\].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainBox {
    pub min_m: Vec3,
    pub max_m: Vec3,
}

/// What to write.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Interval of the balance CSV rows and parcel snapshots \[s\].
    #[serde(default = "default_interval")]
    pub interval_s: f64,
    /// Write parcel snapshots (`parcels/*.vtu` + `parcels.pvd`).
    #[serde(default = "yes")]
    pub parcels: bool,
    /// Which per-triangle value the deposit pictures show.
    #[serde(default)]
    pub picture_quantity: PictureQuantity,
}

fn default_interval() -> f64 {
    0.01
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            interval_s: default_interval(),
            parcels: true,
            picture_quantity: PictureQuantity::default(),
        }
    }
}

/// Which per-triangle value the deposit picture shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PictureQuantity {
    #[default]
    MassPerArea,
    Impacts,
    MeanNormalSpeed,
}

impl Validate for FlowSpec {
    fn validate(&self, c: &mut Checker) {
        let given =
            [self.vtk.is_some(), self.series.is_some(), !self.files.is_empty(), !self.analytic.is_empty()]
                .iter()
                .filter(|b| **b)
                .count();
        if given != 1 {
            c.fail(
                "",
                format!("flow needs exactly one of `vtk`, `series`, `files`, `analytic`; {given} given"),
            );
        }
        if let Some(p) = &self.vtk {
            vtk_file(c, "vtk", p);
        }
        if let Some(p) = &self.series {
            vtk_series(c, "series", p);
        }
        for (i, f) in self.files.iter().enumerate() {
            c.element("files", i, |c| {
                c.finite("time_s", f.time_s);
                vtk_file(c, "file", &f.file);
            });
        }
        for (i, a) in self.analytic.iter().enumerate() {
            c.element("analytic", i, |c| a.validate(c));
        }
        if let Some(t) = &self.turbulence {
            c.nested("turbulence", |c| {
                c.non_negative("k_m2_s2", t.k);
                c.non_negative("epsilon_m2_s3", t.epsilon);
            });
            if self.analytic.is_empty() {
                c.fail(
                    "turbulence",
                    "turbulence applies to analytic fields only (imported files carry k and ε)",
                );
            }
        }
        c.positive("length_scale", self.length_scale);
        if let Some(p) = self.period_s {
            c.positive("period_s", p);
        }
    }
}

/// Memory per parcel for the size estimate \[B\] (tracker state, released parcels, deposit records, with
/// margin).
pub const BYTES_PER_PARCEL: u64 = 400;

/// `path` must name a VTK file the flow reader accepts (legacy or XML, sizes consistent, coordinates
/// finite); the message names the key and the file.
pub(crate) fn vtk_file(c: &mut Checker, key: &str, path: &Path) {
    let full = c.resolve(path);
    if !full.is_file() {
        return c.file_exists(key, path);
    }
    if let Err(e) = spatter_io::vtk::read(&full) {
        c.fail(key, format!("{key} = \"{}\": {e}", path.display()));
    }
}

/// `path` must name a time series (`.pvd`) listing at least one file, whose first snapshot passes
/// [`vtk_file`]; the others are read when the run reaches them. Messages name the key and the file.
pub(crate) fn vtk_series(c: &mut Checker, key: &str, path: &Path) {
    let full = c.resolve(path);
    if !full.is_file() {
        return c.file_exists(key, path);
    }
    match spatter_io::vtk::series::read_series(&full) {
        Err(e) => c.fail(key, format!("{key} = \"{}\": {e}", path.display())),
        Ok(list) => match list.first() {
            None => c.fail(key, format!("{key} = \"{}\" lists no files", path.display())),
            Some((_, f)) => vtk_file(c, key, f),
        },
    }
}

impl Validate for DepositionConfig {
    fn validate(&self, c: &mut Checker) {
        c.item("fluid", &self.fluid);
        c.item("flow", &self.flow);
        c.item("forces", &self.forces);
        if let Some(d) = &self.dispersion {
            c.item("dispersion", d);
        }
        for (i, b) in self.bodies.iter().enumerate() {
            c.element("bodies", i, |c| {
                // The name becomes a file name in the run folder (`bodies/<name>.vtu`, `<name>_deposit.png`).
                if b.name.is_empty() {
                    c.fail("name", "name must not be empty");
                } else if !b.name.chars().all(|ch| ch.is_ascii_alphanumeric() || "_.-".contains(ch))
                    || b.name.chars().all(|ch| ch == '.')
                {
                    c.fail(
                        "name",
                        format!(
                            "name = \"{}\" may only hold letters A–Z, a–z, digits and `_` `.` `-` (it names output files)",
                            b.name
                        ),
                    );
                }
                c.mesh_file("file", &b.file);
                c.positive("scale", b.scale);
                c.finite_vec("translate_m", b.translate_m);
                c.item("wall", &b.wall);
                c.positive("shear_probe_distance_m", b.shear_probe_distance_m);
                if b.view_direction.length() < 1e-12 || b.view_direction.cross(b.view_up).length() < 1e-12 {
                    c.fail("view_up", "view_direction and view_up must be non-zero and not parallel");
                }
            });
        }
        let mut names: Vec<&str> = self.bodies.iter().map(|b| b.name.as_str()).collect();
        names.sort_unstable();
        if names.windows(2).any(|w| w[0] == w[1]) {
            c.fail("bodies", "body names must be unique");
        }
        if self.injectors.is_empty() {
            c.fail("injectors", "at least one [[injectors]] table is needed");
        }
        if self.injectors.len() > u16::MAX as usize {
            c.fail("injectors", "too many injectors");
        }
        for (i, inj) in self.injectors.iter().enumerate() {
            c.element("injectors", i, |c| {
                inj.validate(c);
                c.memory_estimate(
                    "parcels",
                    &format!("parcels = {} × {BYTES_PER_PARCEL} B", inj.parcels),
                    inj.parcels as f64 * BYTES_PER_PARCEL as f64,
                );
            });
        }
        c.nested("time", |c| {
            c.positive("dt_s", self.time.dt_s);
            c.positive("duration_s", self.time.duration_s);
            if self.time.duration_s / self.time.dt_s > 1e9 {
                c.fail("dt_s", "more than 10⁹ steps: increase dt_s or shorten duration_s");
            } else if self.time.dt_s > self.time.duration_s {
                c.fail(
                    "dt_s",
                    format!(
                        "dt_s = {} is longer than duration_s = {}: the run would take one step and deposit nothing",
                        self.time.dt_s, self.time.duration_s
                    ),
                );
            }
        });
        if let Some(d) = &self.domain {
            c.nested("domain", |c| {
                c.finite_vec("min_m", d.min_m);
                c.finite_vec("max_m", d.max_m);
                if d.min_m.cmpge(d.max_m).any() {
                    c.fail("max_m", "max_m must exceed min_m in every component");
                }
            });
        }
        // An injector that releases every parcel outside the domain does nothing (each parcel escapes at once).
        if let Some(d) = &self.domain {
            let inside = |p: &Vec3| p.cmpge(d.min_m).all() && p.cmple(d.max_m).all();
            for (i, inj) in self.injectors.iter().enumerate() {
                use spatter_flow::tracker::inject::Region;
                let outside = match &inj.region {
                    Region::Points { points_m } => !points_m.is_empty() && !points_m.iter().any(inside),
                    Region::Box { min_m, max_m } => max_m.cmplt(d.min_m).any() || min_m.cmpgt(d.max_m).any(),
                    Region::Surface { .. } => false,
                };
                if outside {
                    c.element("injectors", i, |c| {
                        c.fail(
                            "region",
                            format!(
                                "the injection region of \"{}\" lies outside the domain [{}, {}]: every parcel \
                                 would escape at once",
                                inj.name, d.min_m, d.max_m
                            ),
                        )
                    });
                }
            }
        }
        c.nested("output", |c| c.positive("interval_s", self.output.interval_s));
    }
}

/// `kind = "forces"`: the nondimensional force ranking (Jasion 2013, Table 6.4).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForcesConfig {
    #[serde(default)]
    pub fluid: Fluid,
    #[serde(rename = "particle_density_kg_m3")]
    pub particle_density: f64,
    /// Velocity scale u₀ \[m/s\].
    #[serde(rename = "velocity_scale_m_s")]
    pub velocity_scale: f64,
    /// Surface energy σ of the cohesion term \[J/m²\].
    #[serde(rename = "surface_energy_j_m2", default)]
    pub surface_energy: f64,
    #[serde(rename = "gravity_m_s2", default = "default_g")]
    pub gravity: f64,
    /// One column per diameter \[m\].
    #[serde(rename = "diameters_m")]
    pub diameters: Vec<f64>,
    #[serde(default)]
    pub factors: RankingFactors,
}

fn default_g() -> f64 {
    9.81
}

impl Validate for ForcesConfig {
    fn validate(&self, c: &mut Checker) {
        c.item("fluid", &self.fluid);
        c.positive("particle_density_kg_m3", self.particle_density);
        c.positive("velocity_scale_m_s", self.velocity_scale);
        c.non_negative("surface_energy_j_m2", self.surface_energy);
        c.non_negative("gravity_m_s2", self.gravity);
        if self.diameters.is_empty() {
            c.fail("diameters_m", "diameters_m must list at least one diameter");
        }
        for (i, d) in self.diameters.iter().enumerate() {
            c.positive(&format!("diameters_m[{i}]"), *d);
        }
        let f = &self.factors;
        c.nested("factors", |c| {
            for (k, v) in [
                ("f_d", f.f_d),
                ("c_b", f.c_b),
                ("c_m", f.c_m),
                ("f_s", f.f_s),
                ("f_p", f.f_p),
                ("c_fr", f.c_fr),
            ] {
                c.finite(k, v);
            }
        });
    }
}

impl spatter_io::run::Smoke for DepositionConfig {
    /// At most 200 parcels per injector, 40 steps, an output every 10.
    fn smoke(&mut self) {
        for i in &mut self.injectors {
            i.parcels = i.parcels.min(200);
        }
        self.time.duration_s = self.time.duration_s.min(40.0 * self.time.dt_s);
        self.output.interval_s = self.output.interval_s.min(10.0 * self.time.dt_s);
    }
}

impl spatter_io::run::Smoke for ForcesConfig {
    /// A table of a few closed-form numbers is already quick.
    fn smoke(&mut self) {}
}
