//! The scenario file of kind `wading`: every key, its unit and default (documented in `docs/wading.md`).

use super::channel::ChannelSpec;
use super::channel_stl::StlChannel;
use super::patches::SensorBox;
use super::path::VehiclePath;
use super::timeline::SpeedProfile;
use super::vehicle::{PartFile, WheelSpec};
use crate::sph_scene::config::{DragConfig, FluidConfig};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use std::path::{Path, PathBuf};

/// `file` must exist and `parse` must accept its text, so a garbled table fails at `spatter check`; the
/// parser's message names the file, line, value and expected form.
fn parsed_file<T>(
    c: &mut Checker,
    key: &str,
    file: &Path,
    parse: impl Fn(&str, &Path) -> Result<T, String>,
) -> Option<T> {
    let full = c.resolve(file);
    if !full.is_file() {
        c.file_exists(key, file);
        return None;
    }
    match std::fs::read_to_string(&full) {
        Err(e) => {
            c.fail(key, format!("{}: {e}", file.display()));
            None
        }
        Ok(text) => parse(&text, &full).map_err(|e| c.fail(key, e)).ok(),
    }
}

/// Fastest vehicle speed a wading run accepts \[m/s\] (360 km/h). The water's sound speed, and with it
/// the number of time steps, grows with the vehicle speed: a mistyped 1e6 m/s would ask for billions of
/// steps (and a path thousands of kilometres long) instead of an error.
pub const MAX_SPEED_M_S: f64 = 100.0;

/// Refuses a vehicle speed above [`MAX_SPEED_M_S`] under `key`, `what` saying where it comes from.
fn check_speed(c: &mut Checker, key: &str, what: &str, v: f64) {
    if v > MAX_SPEED_M_S {
        c.fail(
            key,
            format!(
                "{what} {v} m/s is faster than {MAX_SPEED_M_S} m/s; wading speeds are a few m/s (the time step \
                 shrinks as the speed grows)"
            ),
        );
    }
}

fn d_adhesion() -> f64 {
    1.0
}
fn d_start_gap() -> f64 {
    0.2
}
fn d_cap() -> f64 {
    0.48
}
fn d_bin() -> f64 {
    0.25
}
fn d_top() -> f64 {
    12.0
}
fn d_drag() -> DragConfig {
    DragConfig { enabled: true, ..DragConfig::default() }
}

/// The whole scenario (`kind = "wading"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WadingConfig {
    /// Free text shown in the log.
    #[serde(default)]
    pub title: String,
    /// Water and numerics, as in the `sph` kind (`fluid.dimensions` must be 3).
    pub fluid: FluidConfig,
    /// Air drag on the water, as in the `sph` kind; on by default (air at rest).
    #[serde(default = "d_drag")]
    pub drag: DragConfig,
    pub channel: ChannelConfig,
    pub vehicle: VehicleConfig,
    pub motion: MotionSpec,
    /// Sensor patches: names of vehicle parts whose wet fraction is followed over time.
    #[serde(default)]
    pub sensors: Vec<String>,
    /// Sensor patches cut out of vehicle parts by boxes (`[[sensor_boxes]]`); each is followed over time
    /// like the parts in `sensors`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub sensor_boxes: Vec<SensorBox>,
    #[serde(default)]
    pub output: WadingOutput,
}

/// The `[channel]` table: a channel generated from its dimensions, or read from an STL file (`file`),
/// both holding water `water_depth_m` deep. Every key is documented in `docs/wading.md`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelConfig {
    /// A channel read from a multi-solid ASCII STL file (solids `road…` and walls) instead of generated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// Flat road before the entry ramp \[m\] (generated channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub approach_length_m: Option<f64>,
    /// Horizontal length of each ramp \[m\] (generated channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_length_m: Option<f64>,
    /// Length of the flat pool floor \[m\] (generated channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pool_length_m: Option<f64>,
    /// Depth of the pool floor below the road \[m\] (generated channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pool_depth_m: Option<f64>,
    /// Flat road after the exit ramp \[m\] (generated channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exit_length_m: Option<f64>,
    /// Width between the side walls \[m\] (generated channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width_m: Option<f64>,
    /// Height of the side walls above the road \[m\] (generated channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_height_m: Option<f64>,
    /// Water depth \[m\] (the study's `x`): over the pool floor of a generated channel, over the road's
    /// lowest point of a channel from a file.
    pub water_depth_m: f64,
    /// Akinci adhesion factor of the road and the walls (needs surface tension). Default 1.
    #[serde(default = "d_adhesion")]
    pub adhesion: f64,
}

impl ChannelConfig {
    /// The generated channel's keys as `(name, value)`.
    fn dimensions(&self) -> [(&'static str, Option<f64>); 7] {
        [
            ("approach_length_m", self.approach_length_m),
            ("ramp_length_m", self.ramp_length_m),
            ("pool_length_m", self.pool_length_m),
            ("pool_depth_m", self.pool_depth_m),
            ("exit_length_m", self.exit_length_m),
            ("width_m", self.width_m),
            ("wall_height_m", self.wall_height_m),
        ]
    }

    /// The generated channel, when `file` is not given and every dimension is.
    pub fn generated(&self) -> Option<ChannelSpec> {
        if self.file.is_some() {
            return None;
        }
        Some(ChannelSpec {
            approach_length_m: self.approach_length_m?,
            ramp_length_m: self.ramp_length_m?,
            pool_length_m: self.pool_length_m?,
            pool_depth_m: self.pool_depth_m?,
            exit_length_m: self.exit_length_m?,
            width_m: self.width_m?,
            wall_height_m: self.wall_height_m?,
            water_depth_m: self.water_depth_m,
            adhesion: self.adhesion,
        })
    }
}

impl From<ChannelSpec> for ChannelConfig {
    fn from(c: ChannelSpec) -> Self {
        ChannelConfig {
            file: None,
            approach_length_m: Some(c.approach_length_m),
            ramp_length_m: Some(c.ramp_length_m),
            pool_length_m: Some(c.pool_length_m),
            pool_depth_m: Some(c.pool_depth_m),
            exit_length_m: Some(c.exit_length_m),
            width_m: Some(c.width_m),
            wall_height_m: Some(c.wall_height_m),
            water_depth_m: c.water_depth_m,
            adhesion: c.adhesion,
        }
    }
}

impl Validate for ChannelConfig {
    fn validate(&self, c: &mut Checker) {
        match &self.file {
            Some(file) => {
                for (key, v) in self.dimensions() {
                    if v.is_some() {
                        c.fail(
                            key,
                            format!(
                                "{key} is a dimension of a generated channel, but the channel comes from file = \
                                 \"{}\"; remove it",
                                file.display()
                            ),
                        );
                    }
                }
                c.positive("water_depth_m", self.water_depth_m);
                c.non_negative("adhesion", self.adhesion);
                let full = c.resolve(file);
                if !full.is_file() {
                    return c.file_exists("file", file);
                }
                if self.water_depth_m > 0.0 {
                    if let Err(e) = StlChannel::read(&full, self.water_depth_m) {
                        c.fail(e.key, e.message);
                    }
                }
            }
            None => match self.generated() {
                Some(g) => g.validate(c),
                None => {
                    for (key, v) in self.dimensions() {
                        if v.is_none() {
                            // Reported on the table (the key itself is not in the file to point at).
                            c.fail(
                                "",
                                format!(
                                    "{key} is missing: a generated channel needs {key} (see docs/wading.md), \
                                     or give file = \"channel.stl\" for a channel read from an STL file"
                                ),
                            );
                        }
                    }
                }
            },
        }
    }
}

/// The vehicle: its part files, its wheels and the adhesion of its surfaces.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleConfig {
    pub parts: Vec<PartFile>,
    pub wheels: Vec<WheelSpec>,
    /// Akinci adhesion factor of every vehicle part (needs `fluid.surface_tension_n_m` > 0). Default 1.
    #[serde(default = "d_adhesion")]
    pub adhesion: f64,
    /// Gap between the front wheels' leading edge and the water's edge at the start \[m\]. Default 0.2.
    #[serde(default = "d_start_gap")]
    pub start_gap_m: f64,
}

/// How the vehicle moves: a constant speed or a speed table along the channel, or a free path (exactly
/// one).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// Constant speed along +x \[m/s\].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_m_s: Option<f64>,
    /// Speed table: rows `t_s speed_m_s`, linearly interpolated, held beyond the ends.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// A free path of the front axle (`[motion.path]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<PathSpec>,
}

/// A path `t x y [z]` of the front axle's centre-line point, from a file or inline (exactly one).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathSpec {
    /// File of rows `t_s x_m y_m [z_m]` (whitespace or commas, `#` comments, an optional header line).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// Rows `[t_s, x_m, y_m]` or `[t_s, x_m, y_m, z_m]` given inline.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rows: Option<Vec<Vec<f64>>>,
}

/// What is written and when the run ends.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WadingOutput {
    /// End of the run \[s\]; default: when the front axle reaches the end of the pool floor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end_time_s: Option<f64>,
    /// Particle and wall snapshots (VTU + PVD) \[s\]; default end/40.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vtu_interval_s: Option<f64>,
    /// Time-series rows \[s\]; default end/400.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sample_interval_s: Option<f64>,
    /// Top of the colour scale of every wetting map (fraction of the time wet). Default 0.48.
    #[serde(default = "d_cap")]
    pub wetting_cap: f64,
    /// Splash-height bin as a fraction of the water depth. Default 0.25.
    #[serde(default = "d_bin")]
    pub splash_bin_over_depth: f64,
    /// Highest splash height recorded, in water depths above the pool floor. Default 12.
    #[serde(default = "d_top")]
    pub splash_top_over_depth: f64,
    /// Front-axle x positions at which every part's wetting at that moment is written
    /// (`wetting/instant_NN/`) \[m\], increasing, between the start and the end of the run. Default none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub map_positions_m: Vec<f64>,
}

impl Default for WadingOutput {
    fn default() -> Self {
        WadingOutput {
            end_time_s: None,
            vtu_interval_s: None,
            sample_interval_s: None,
            wetting_cap: d_cap(),
            splash_bin_over_depth: d_bin(),
            splash_top_over_depth: d_top(),
            map_positions_m: Vec::new(),
        }
    }
}

impl WadingConfig {
    /// Refuses a spacing whose particles could not fit in memory, from a lower bound: the water of the
    /// pool (pool length × width × water depth / dp³) and the road's wall particles (the channel's length
    /// × width / dp², four layers), without the vehicle's surfaces and the ramps' water. A channel from a
    /// file is not estimated here.
    fn check_memory(&self, c: &mut Checker) {
        let dp = self.fluid.spacing_m;
        let Some(ch) = self.channel.generated() else { return };
        if !(dp > 0.0 && dp.is_finite()) {
            return;
        }
        let length = ch.approach_length_m + 2.0 * ch.ramp_length_m + ch.pool_length_m + ch.exit_length_m;
        let water = ch.pool_length_m * ch.width_m * ch.water_depth_m / (dp * dp * dp);
        let road = 4.0 * length * ch.width_m / (dp * dp);
        let n = water + road;
        if n.is_finite() {
            c.nested("fluid", |c| {
                c.memory_estimate(
                    "spacing_m",
                    &format!(
                        "spacing_m = {dp} m gives at least {n:.3e} particles (the pool's water and the road); × {} B, that",
                        crate::sph_scene::config::BYTES_PER_PARTICLE
                    ),
                    n * crate::sph_scene::config::BYTES_PER_PARTICLE,
                )
            });
        }
    }
}

impl Validate for WadingConfig {
    fn validate(&self, c: &mut Checker) {
        c.item("fluid", &self.fluid);
        if self.fluid.dimensions != 3 {
            c.nested("fluid", |c| {
                c.fail(
                    "dimensions",
                    format!("dimensions = {} but a wading run is 3D: set 3", self.fluid.dimensions),
                )
            });
        }
        c.nested("drag", |c| {
            c.positive("air_density_kg_m3", self.drag.air_density_kg_m3);
            c.positive("air_viscosity_pa_s", self.drag.air_viscosity_pa_s);
            c.finite_vec("air_velocity_m_s", self.drag.air_velocity_m_s);
        });
        c.item("channel", &self.channel);
        self.check_memory(c);
        self.check_vehicle_width(c);
        c.nested("vehicle", |c| {
            if self.vehicle.parts.is_empty() {
                c.fail(
                    "parts",
                    "the vehicle needs at least one part file ([[vehicle.parts]] file = \"….stl\")",
                );
            }
            for (i, p) in self.vehicle.parts.iter().enumerate() {
                c.element("parts", i, |c| {
                    let full = c.resolve(&p.file);
                    if full.is_file() {
                        // The same reading as the run's, so a broken part is found by `spatter check`.
                        if let Err(e) = super::parts::read_parts(&full, 1.0) {
                            c.fail("file", e.to_string());
                        }
                    } else {
                        c.file_exists("file", &p.file);
                    }
                    c.positive("scale", p.scale);
                });
            }
            if self.vehicle.wheels.is_empty() {
                c.fail("wheels", "the vehicle needs wheels ([[vehicle.wheels]] part, axle_m, radius_m)");
            }
            c.non_negative("adhesion", self.vehicle.adhesion);
            c.non_negative("start_gap_m", self.vehicle.start_gap_m);
        });
        c.nested("motion", |c| {
            match (self.motion.speed_m_s, &self.motion.file, &self.motion.path) {
            (Some(v), None, None) => {
                c.positive("speed_m_s", v);
                check_speed(c, "speed_m_s", "speed_m_s =", v);
            }
            (None, Some(f), None) => {
                if let Some(t) = parsed_file(c, "file", f, SpeedProfile::parse) {
                    check_speed(c, "file", &format!("{}: the fastest speed,", f.display()), t.max_speed());
                }
            }
            (None, None, Some(p)) => c.nested("path", |c| match (&p.file, &p.rows) {
                (Some(f), None) => {
                    if let Some(path) = parsed_file(c, "file", f, VehiclePath::parse) {
                        let what = format!("{}: the fastest speed along the path,", f.display());
                        check_speed(c, "file", &what, path.max_speed());
                    }
                }
                (None, Some(rows)) => match VehiclePath::from_rows(rows) {
                    Err(e) => c.fail("rows", e),
                    Ok(path) => check_speed(c, "rows", "the fastest speed along the path,", path.max_speed()),
                },
                _ => c.fail(
                    "file",
                    "give exactly one of file (rows `t_s x_m y_m [z_m]`) and rows ([[t, x, y], …] inline)",
                ),
            }),
            _ => c.fail(
                "speed_m_s",
                "give exactly one of speed_m_s (constant speed, m/s), file (a table of `t_s speed_m_s` rows) \
                 and [motion.path] (rows `t_s x_m y_m [z_m]` of the front axle)",
            ),
        }
        });
        c.nested("output", |c| {
            let o = &self.output;
            if let Some(t) = o.end_time_s {
                c.positive("end_time_s", t);
            }
            if let Some(t) = o.vtu_interval_s {
                c.positive("vtu_interval_s", t);
            }
            if let Some(t) = o.sample_interval_s {
                c.positive("sample_interval_s", t);
            }
            c.in_range("wetting_cap", o.wetting_cap, 0.0, false, 1.0, true);
            c.positive("splash_bin_over_depth", o.splash_bin_over_depth);
            c.positive("splash_top_over_depth", o.splash_top_over_depth);
            for (i, x) in o.map_positions_m.iter().enumerate() {
                let before = i.checked_sub(1).map(|j| o.map_positions_m[j]);
                if !(x.is_finite() && before.is_none_or(|b| *x > b)) {
                    c.fail(
                        &format!("map_positions_m[{i}]"),
                        format!("{x} m: the front-axle positions must be finite and increase"),
                    );
                }
            }
        });
        for (i, b) in self.sensor_boxes.iter().enumerate() {
            c.element("sensor_boxes", i, |c| b.validate(c));
        }
    }
}

impl WadingConfig {
    /// The vehicle against what its part files hold, when they read (their own problems are reported by
    /// their keys): wheels (part, axle direction, radius against the mesh), sensor names, and a vehicle
    /// as wide as the channel or wider.
    fn check_vehicle_width(&self, c: &mut Checker) {
        let mut parts = Vec::new();
        for p in &self.vehicle.parts {
            match super::parts::read_parts(&c.resolve(&p.file), p.scale) {
                Ok(mut read) => parts.append(&mut read),
                Err(_) => return,
            }
        }
        let mut channel = self.channel.clone();
        if let Some(f) = &channel.file {
            channel.file = Some(c.resolve(f));
        }
        let has_water = self.channel.water_depth_m > 0.0;
        if !parts.is_empty() && has_water {
            if let Ok(ch) = super::layout::Channel::new(&channel) {
                if let Some(e) = ch.check_vehicle_width(&parts) {
                    c.fail(&e.key, e.message);
                }
            }
        }
        // Then the wheels and sensors against the parts, as the run checks them.
        if parts.is_empty() {
            return;
        }
        let mut errs = super::vehicle::check_wheels(&parts, &self.vehicle.wheels);
        errs.extend(super::vehicle::check_sensor_names(&parts, &self.sensors));
        for e in errs {
            c.fail(&e.key, e.message);
        }
    }
}

impl spatter_io::run::Smoke for WadingConfig {
    /// Spacing doubled (an eighth of the particles) but kept to at most a third of the water depth (three
    /// particles over the depth, so that the pool still fills), and 20 ms of simulated time, two snapshots.
    fn smoke(&mut self) {
        let coarse = (2.0 * self.fluid.spacing_m).min(self.channel.water_depth_m / 3.0);
        self.fluid.spacing_m = self.fluid.spacing_m.max(coarse);
        let end = self.output.end_time_s.unwrap_or(f64::INFINITY).min(0.02);
        self.output.end_time_s = Some(end);
        self.output.vtu_interval_s = Some(end / 2.0);
        self.output.sample_interval_s = Some(end / 5.0);
    }
}
