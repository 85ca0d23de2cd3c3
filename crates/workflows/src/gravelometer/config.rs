//! The `gravelometer` scenario: keys, the presets of the two standards, validation.
//!
//! Every key is optional except `standard`; a key left out takes the preset's value, and the loaded
//! configuration holds every value (so `run.toml` lists them all) together with `assumed`, the keys whose
//! preset value is an assumption (the published study does not give it) and which the file did not set.
//! Every key is documented in `docs/gravelometer.md`.

use super::air::Outside;
use crate::dem_scene::{TemplateConfig, TemplateShape};
use crate::fluid_forces::{DragModel, KCorrection};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;
use std::collections::BTreeMap;

/// The test standard whose set-up the presets reproduce.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Standard {
    /// DIN 55996-1: 30 mm pipe, 500 g chilled-iron grit in 10 s, 100 × 200 mm panel at 54°, 5 strips.
    #[serde(rename = "din_55996_1")]
    Din55996_1,
    /// SAE J400: 52 mm pipe, 1 pint of road gravel in 7 s, 100 × 300 mm upright panel, 6 strips.
    SaeJ400,
}

/// What drives the stones along the pipe.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AirMode {
    /// No air: the stones leave the feeder with the empirical launch velocity and fly ballistically.
    #[default]
    None,
    /// A developed pipe-flow air field drags the stones (one-way fluid forces).
    Prescribed,
    /// Air and stones coupled both ways (CFD-DEM).
    Coupled,
}

/// Stone shapes: the standard's stones or the single-particle steel ball.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StoneShape {
    /// The preset templates of the standard (or `stones.templates`).
    #[default]
    Standard,
    /// A ball of `stones.sphere_diameter_m` (the single-particle cases S1–S5).
    Sphere,
}

/// `[pipe]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PipeKeys {
    pub diameter_m: Option<f64>,
    pub length_m: Option<f64>,
    /// Mean air speed in the pipe \[m/s\].
    pub air_velocity_m_s: Option<f64>,
}

/// `[panel]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PanelKeys {
    pub width_m: Option<f64>,
    pub length_m: Option<f64>,
    pub angle_deg: Option<f64>,
    /// From the pipe exit to the panel centre along the pipe axis \[m\].
    pub distance_m: Option<f64>,
    pub triangle_size_m: Option<f64>,
    pub strips: Option<usize>,
}

/// `[clamp]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClampKeys {
    pub bar_width_m: Option<f64>,
    pub thickness_m: Option<f64>,
}

/// `[protection_box]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoxKeys {
    pub margin_m: Option<f64>,
}

/// `[stones]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StoneKeys {
    pub shape: Option<StoneShape>,
    pub sphere_diameter_m: Option<f64>,
    /// Diameter of the equal member spheres every template is packed with \[m\].
    pub member_diameter_m: Option<f64>,
    pub density_kg_m3: Option<f64>,
    pub youngs_modulus_pa: Option<f64>,
    pub poisson_ratio: Option<f64>,
    /// Mass fed in `feed_time_s` \[kg\].
    pub charge_kg: Option<f64>,
    pub feed_time_s: Option<f64>,
    /// Feed exactly this many stones over the feed time instead of the charge.
    pub count: Option<u64>,
    /// Stone templates by name (rigid multi-sphere bodies, as `[templates]` of a DEM scene).
    pub templates: Option<BTreeMap<String, TemplateConfig>>,
    /// Number ratios of the templates, alphabetical order (default equal).
    pub ratios: Option<Vec<f64>>,
}

/// `[launch]`: the stones' velocity when they are placed at the pipe inlet.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LaunchKeys {
    /// Constant of the empirical initial-velocity formula.
    pub k_h: Option<f64>,
    /// Air flow rate Q_f \[m³/s\] (default: pipe air velocity × pipe cross-section).
    pub air_flow_m3_s: Option<f64>,
    /// Horizontal launch speed \[m/s\] instead of the formula.
    pub speed_m_s: Option<f64>,
    /// Fall height from the feeder into the pipe \[m\].
    pub fall_height_m: Option<f64>,
    /// Coefficient of restitution of the stone's bounce into the pipe.
    pub feeder_restitution: Option<f64>,
}

/// `[contact]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactKeys {
    pub stone_wall_restitution: Option<f64>,
    pub stone_wall_friction: Option<f64>,
    pub stone_stone_restitution: Option<f64>,
    pub stone_stone_friction: Option<f64>,
}

/// `[walls]`: the material of pipe, box, clamp and (coated) panel.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallKeys {
    pub youngs_modulus_pa: Option<f64>,
    pub poisson_ratio: Option<f64>,
    /// Density of the coating, for the eroded depth \[kg/m³\].
    pub coating_density_kg_m3: Option<f64>,
}

/// `[air_field]`: the prescribed air of `air = "prescribed"` (see [`super::air`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AirFieldKeys {
    /// Exponent n of the power-law pipe profile u = U_c (1 − r/R)^{1/n}.
    pub profile_exponent: Option<f64>,
    /// Length of the linear inlet ramp from still air to the steady flow \[s\].
    pub ramp_s: Option<f64>,
    /// The air beyond the pipe exit.
    pub outside: Option<Outside>,
    /// Drag law on every member sphere.
    pub drag: Option<DragModel>,
    /// Air density \[kg/m³\].
    pub density_kg_m3: Option<f64>,
    /// Air dynamic viscosity \[Pa s\].
    pub viscosity_pa_s: Option<f64>,
    /// Correction of the transverse drag of the porous multi-sphere stones (default none, K = 1).
    pub k_correction: Option<KCorrection>,
}

/// The turbulence model of the coupled air.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoupledTurbulence {
    /// Standard k–ε with log-law wall functions on the faces of the blocked cells that make the pipe and
    /// the box (the published study's model).
    KEpsilon,
    /// No model: the molecular viscosity only (the default).
    #[default]
    Laminar,
}

/// `[coupled_air]`: the solved air flow of `air = "coupled"` (see [`super::coupled`]); drag law, air
/// properties and the inlet ramp come from `[air_field]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoupledAirKeys {
    /// Edge of the cubic flow cells \[m\].
    pub cell_size_m: Option<f64>,
    /// `"k_epsilon"` or `"laminar"`.
    pub turbulence: Option<CoupledTurbulence>,
    /// Turbulence intensity at the pipe inlet \[-\] (k–ε only).
    pub inlet_intensity: Option<f64>,
    /// DEM steps per fluid step (default: a fluid Courant number of about 0.4).
    pub dem_steps_per_fluid_step: Option<u32>,
}

/// `[wear]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WearKeys {
    /// Finnie's constant k \[s²/m²\].
    pub k_s2_m2: Option<f64>,
}

/// `[output]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputKeys {
    /// Impact statistics over the first N stones to hit the panel.
    pub first_n: Option<usize>,
    /// Report the eroded mass after this many impacts (panel, clamp or fly-over).
    pub cutoff_impacts: Option<usize>,
    /// Write the stones' member spheres as VTU.
    pub particles_vtu: Option<bool>,
    /// Interval of VTU snapshots and time series \[s\].
    pub output_interval_s: Option<f64>,
}

/// The scenario file as written: every key optional but `standard`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GravelometerInput {
    pub standard: Standard,
    #[serde(default)]
    pub air: Option<AirMode>,
    #[serde(default)]
    pub duration_s: Option<f64>,
    /// Time step \[s\] (default: from the Hertz contact time and the Rayleigh time of the stones).
    #[serde(default)]
    pub dt_s: Option<f64>,
    #[serde(default)]
    pub seed: Option<u64>,
    #[serde(default)]
    pub pipe: PipeKeys,
    #[serde(default)]
    pub panel: PanelKeys,
    #[serde(default)]
    pub clamp: ClampKeys,
    #[serde(default)]
    pub protection_box: BoxKeys,
    #[serde(default)]
    pub stones: StoneKeys,
    #[serde(default)]
    pub launch: LaunchKeys,
    #[serde(default)]
    pub contact: ContactKeys,
    #[serde(default)]
    pub walls: WallKeys,
    #[serde(default)]
    pub air_field: AirFieldKeys,
    #[serde(default)]
    pub coupled_air: CoupledAirKeys,
    #[serde(default)]
    pub wear: WearKeys,
    #[serde(default)]
    pub output: OutputKeys,
    /// Written by the loader: the keys whose value is an assumption of the preset (read back, ignored).
    #[serde(default)]
    pub assumed: Vec<String>,
}

/// A gravelometer scenario with every preset value filled in (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(from = "GravelometerInput", into = "GravelometerInput")]
pub struct GravelometerConfig {
    pub input: GravelometerInput,
}

impl From<GravelometerConfig> for GravelometerInput {
    fn from(c: GravelometerConfig) -> Self {
        c.input
    }
}

impl From<GravelometerInput> for GravelometerConfig {
    fn from(mut input: GravelometerInput) -> Self {
        let (preset, assumed_keys) = preset(input.standard);
        let mut assumed = Vec::new();
        {
            let mut f = Filler { assumed_keys: &assumed_keys, assumed: &mut assumed };
            let i = &mut input;
            let p = &preset;
            f.take(&mut i.air, &p.air, "air");
            f.take(&mut i.duration_s, &p.duration_s, "duration_s");
            f.take(&mut i.seed, &p.seed, "seed");
            f.take(&mut i.pipe.diameter_m, &p.pipe.diameter_m, "pipe.diameter_m");
            f.take(&mut i.pipe.length_m, &p.pipe.length_m, "pipe.length_m");
            f.take(&mut i.pipe.air_velocity_m_s, &p.pipe.air_velocity_m_s, "pipe.air_velocity_m_s");
            f.take(&mut i.panel.width_m, &p.panel.width_m, "panel.width_m");
            f.take(&mut i.panel.length_m, &p.panel.length_m, "panel.length_m");
            f.take(&mut i.panel.angle_deg, &p.panel.angle_deg, "panel.angle_deg");
            f.take(&mut i.panel.distance_m, &p.panel.distance_m, "panel.distance_m");
            f.take(&mut i.panel.triangle_size_m, &p.panel.triangle_size_m, "panel.triangle_size_m");
            f.take(&mut i.panel.strips, &p.panel.strips, "panel.strips");
            f.take(&mut i.clamp.bar_width_m, &p.clamp.bar_width_m, "clamp.bar_width_m");
            f.take(&mut i.clamp.thickness_m, &p.clamp.thickness_m, "clamp.thickness_m");
            f.take(&mut i.protection_box.margin_m, &p.protection_box.margin_m, "protection_box.margin_m");
            let (s, ps) = (&mut i.stones, &p.stones);
            f.take(&mut s.shape, &ps.shape, "stones.shape");
            f.take(&mut s.sphere_diameter_m, &ps.sphere_diameter_m, "stones.sphere_diameter_m");
            f.take(&mut s.member_diameter_m, &ps.member_diameter_m, "stones.member_diameter_m");
            f.take(&mut s.density_kg_m3, &ps.density_kg_m3, "stones.density_kg_m3");
            f.take(&mut s.youngs_modulus_pa, &ps.youngs_modulus_pa, "stones.youngs_modulus_pa");
            f.take(&mut s.poisson_ratio, &ps.poisson_ratio, "stones.poisson_ratio");
            f.take(&mut s.charge_kg, &ps.charge_kg, "stones.charge_kg");
            f.take(&mut s.feed_time_s, &ps.feed_time_s, "stones.feed_time_s");
            f.take(&mut s.templates, &ps.templates, "stones.templates");
            let l = &mut i.launch;
            f.take(&mut l.k_h, &p.launch.k_h, "launch.k_h");
            f.take(&mut l.fall_height_m, &p.launch.fall_height_m, "launch.fall_height_m");
            f.take(&mut l.feeder_restitution, &p.launch.feeder_restitution, "launch.feeder_restitution");
            let (c, pc) = (&mut i.contact, &p.contact);
            f.take(
                &mut c.stone_wall_restitution,
                &pc.stone_wall_restitution,
                "contact.stone_wall_restitution",
            );
            f.take(&mut c.stone_wall_friction, &pc.stone_wall_friction, "contact.stone_wall_friction");
            f.take(
                &mut c.stone_stone_restitution,
                &pc.stone_stone_restitution,
                "contact.stone_stone_restitution",
            );
            f.take(&mut c.stone_stone_friction, &pc.stone_stone_friction, "contact.stone_stone_friction");
            f.take(&mut i.walls.youngs_modulus_pa, &p.walls.youngs_modulus_pa, "walls.youngs_modulus_pa");
            f.take(&mut i.walls.poisson_ratio, &p.walls.poisson_ratio, "walls.poisson_ratio");
            f.take(
                &mut i.walls.coating_density_kg_m3,
                &p.walls.coating_density_kg_m3,
                "walls.coating_density_kg_m3",
            );
            let (a, pa) = (&mut i.air_field, &p.air_field);
            f.take(&mut a.profile_exponent, &pa.profile_exponent, "air_field.profile_exponent");
            f.take(&mut a.ramp_s, &pa.ramp_s, "air_field.ramp_s");
            f.take(&mut a.outside, &pa.outside, "air_field.outside");
            f.take(&mut a.drag, &pa.drag, "air_field.drag");
            f.take(&mut a.density_kg_m3, &pa.density_kg_m3, "air_field.density_kg_m3");
            f.take(&mut a.viscosity_pa_s, &pa.viscosity_pa_s, "air_field.viscosity_pa_s");
            f.take(&mut a.k_correction, &pa.k_correction, "air_field.k_correction");
            let (a, pa) = (&mut i.coupled_air, &p.coupled_air);
            f.take(&mut a.cell_size_m, &pa.cell_size_m, "coupled_air.cell_size_m");
            f.take(&mut a.turbulence, &pa.turbulence, "coupled_air.turbulence");
            f.take(&mut a.inlet_intensity, &pa.inlet_intensity, "coupled_air.inlet_intensity");
            f.take(&mut i.wear.k_s2_m2, &p.wear.k_s2_m2, "wear.k_s2_m2");
            let r = &mut i.output;
            f.take(&mut r.first_n, &p.output.first_n, "output.first_n");
            f.take(&mut r.cutoff_impacts, &p.output.cutoff_impacts, "output.cutoff_impacts");
            f.take(&mut r.particles_vtu, &p.output.particles_vtu, "output.particles_vtu");
            f.take(&mut r.output_interval_s, &p.output.output_interval_s, "output.output_interval_s");
        }
        // Generated template shapes without a packing of their own take the member spheres.
        if let (Some(m), Some(ts)) = (input.stones.member_diameter_m, input.stones.templates.as_mut()) {
            for t in ts.values_mut() {
                if t.packing.is_none() && !matches!(t.shape, TemplateShape::Spheres { .. }) {
                    t.packing = Some(crate::dem_scene::Packing::Equal { sphere_diameter_m: m });
                }
            }
        }
        // A flow rate derived from the pipe's air velocity is not an assumption of its own.
        if input.launch.air_flow_m3_s.is_none() {
            if let (Some(v), Some(d)) = (input.pipe.air_velocity_m_s, input.pipe.diameter_m) {
                input.launch.air_flow_m3_s = Some(v * std::f64::consts::PI * 0.25 * d * d);
                if assumed.iter().any(|k| k == "pipe.air_velocity_m_s") {
                    assumed.push("launch.air_flow_m3_s".into());
                }
            }
        }
        if input.launch.speed_m_s.is_none() {
            assumed.push("launch (the form of the empirical launch-speed formula)".into());
        }
        // A resolved file read back keeps its list (its values are all set, so nothing is filled).
        let mut all = std::mem::take(&mut input.assumed);
        for k in assumed {
            if !all.contains(&k) {
                all.push(k);
            }
        }
        input.assumed = all;
        GravelometerConfig { input }
    }
}

struct Filler<'a> {
    assumed_keys: &'a [&'static str],
    assumed: &'a mut Vec<String>,
}

impl Filler<'_> {
    fn take<T: Clone>(&mut self, dst: &mut Option<T>, src: &Option<T>, key: &str) {
        if dst.is_none() {
            *dst = src.clone();
            if self.assumed_keys.contains(&key) {
                self.assumed.push(key.to_string());
            }
        }
    }
}

/// A preset template: packed with `stones.member_diameter_m` when the run is planned.
fn template(shape: TemplateShape) -> TemplateConfig {
    TemplateConfig { shape, packing: None, mass_basis: None, mass_kg: None }
}

/// The preset of a standard and the keys whose value is assumed.
///
/// Published values (Qian, Zou, Zang, Chen & Tsubokura 2022, "A CFD-DEM-wear coupling method for stone
/// chip resistance of automotive coatings with a rigid connection particle method for non-spherical
/// particles", CMES): pipe diameters 30 mm (DIN) and 52 mm (SAE); 500 g in 10 s (DIN), 1 pint in 7 s
/// (SAE); panels 100 × 200 mm at 54° (DIN) and 100 × 300 mm upright (SAE); 5 and 6 strips; 31.1 m/s of air
/// in the SAE pipe at 0.48 MPa; K_h = 59.6; simulated 1 s (DIN) and 2 s (SAE); member spheres of 0.5 mm;
/// a "one-third sphere" grit shape (DIN) and two ellipsoids and two rounded pyramids (SAE); 30 stones in
/// the statistics and 40 impacts in the parametric comparison. Everything else is assumed (listed).
pub fn preset(standard: Standard) -> (GravelometerInput, Vec<&'static str>) {
    let mut assumed = vec![
        "pipe.length_m",
        "panel.distance_m",
        "clamp.bar_width_m",
        "clamp.thickness_m",
        "protection_box.margin_m",
        "stones.density_kg_m3",
        "stones.youngs_modulus_pa",
        "stones.poisson_ratio",
        "stones.templates",
        "launch.fall_height_m",
        "launch.feeder_restitution",
        "contact.stone_wall_restitution",
        "contact.stone_wall_friction",
        "contact.stone_stone_restitution",
        "contact.stone_stone_friction",
        "walls.youngs_modulus_pa",
        "walls.poisson_ratio",
        "walls.coating_density_kg_m3",
        "wear.k_s2_m2",
        "air_field.ramp_s",
        "coupled_air.inlet_intensity",
    ];
    let common = GravelometerInput {
        standard,
        air: Some(AirMode::None),
        duration_s: None,
        dt_s: None,
        seed: Some(1),
        pipe: PipeKeys::default(),
        panel: PanelKeys { triangle_size_m: Some(0.005), ..Default::default() },
        clamp: ClampKeys { bar_width_m: Some(0.01), thickness_m: Some(0.005) },
        protection_box: BoxKeys { margin_m: Some(0.08) },
        stones: StoneKeys {
            shape: Some(StoneShape::Standard),
            sphere_diameter_m: Some(0.005),
            youngs_modulus_pa: None,
            poisson_ratio: Some(0.25),
            ..Default::default()
        },
        launch: LaunchKeys {
            k_h: Some(59.6),
            air_flow_m3_s: None,
            speed_m_s: None,
            fall_height_m: Some(0.2),
            feeder_restitution: Some(0.5),
        },
        contact: ContactKeys {
            stone_wall_restitution: Some(0.5),
            stone_wall_friction: Some(0.3),
            stone_stone_restitution: Some(0.5),
            stone_stone_friction: Some(0.3),
        },
        walls: WallKeys {
            youngs_modulus_pa: Some(2.0e11),
            poisson_ratio: Some(0.3),
            coating_density_kg_m3: Some(1200.0),
        },
        air_field: AirFieldKeys {
            profile_exponent: Some(7.0),
            ramp_s: Some(0.02),
            outside: Some(Outside::FreeJet),
            drag: Some(DragModel::DiFelice),
            // Dry air at 20 °C and 101.325 kPa.
            density_kg_m3: Some(1.204),
            viscosity_pa_s: Some(1.81e-5),
            k_correction: Some(KCorrection::None),
        },
        coupled_air: CoupledAirKeys {
            cell_size_m: None,
            turbulence: Some(CoupledTurbulence::Laminar),
            inlet_intensity: Some(0.05),
            dem_steps_per_fluid_step: None,
        },
        wear: WearKeys { k_s2_m2: Some(1.0) },
        output: OutputKeys {
            first_n: Some(30),
            cutoff_impacts: Some(40),
            particles_vtu: Some(true),
            output_interval_s: Some(0.005),
        },
        assumed: Vec::new(),
    };
    let v = Vec3::new;
    let p = match standard {
        Standard::Din55996_1 => {
            // The single-particle tests of the study used the DIN accelerating pipe: 290 mm long.
            assumed.push("pipe.air_velocity_m_s");
            let member = 0.5e-3;
            let mut t = BTreeMap::new();
            // Chilled-iron grit of 4–5 mm as a "one-third sphere": a ball of radius 2.5 mm with the lower
            // third of its diameter cut off (volume-equivalent diameter 4.5 mm).
            t.insert(
                "grit".to_string(),
                template(TemplateShape::CutBall { radius_m: 2.5e-3, cut_z_m: None }),
            );
            GravelometerInput {
                duration_s: Some(1.0),
                pipe: PipeKeys { diameter_m: Some(0.03), length_m: Some(0.29), air_velocity_m_s: Some(28.0) },
                // A quarter of the pipe diameter: 1.5 grit diameters (see super::coupled).
                coupled_air: CoupledAirKeys { cell_size_m: Some(0.0075), ..common.coupled_air.clone() },
                panel: PanelKeys {
                    width_m: Some(0.1),
                    length_m: Some(0.2),
                    angle_deg: Some(54.0),
                    distance_m: Some(0.2),
                    strips: Some(5),
                    ..common.panel.clone()
                },
                stones: StoneKeys {
                    member_diameter_m: Some(member),
                    density_kg_m3: Some(7400.0),
                    youngs_modulus_pa: Some(1.7e11),
                    charge_kg: Some(0.5),
                    feed_time_s: Some(10.0),
                    templates: Some(t),
                    ..common.stones.clone()
                },
                ..common
            }
        }
        Standard::SaeJ400 => {
            // One pint (4.732e-4 m³) of gravel at an assumed bulk density of 1500 kg/m³.
            assumed.push("stones.charge_kg");
            assumed.push("stones.member_diameter_m");
            let member = 1.0e-3;
            let mut t = BTreeMap::new();
            // Water-worn road gravel passing 15.9 mm and retained on 9.5 mm (SAE J400): two ellipsoids
            // and two rounded square pyramids, sizes assumed within that sieve range.
            t.insert(
                "ellipsoid_large".to_string(),
                template(TemplateShape::Ellipsoid { semi_axes_m: v(7.0e-3, 5.5e-3, 4.5e-3) }),
            );
            t.insert(
                "ellipsoid_small".to_string(),
                template(TemplateShape::Ellipsoid { semi_axes_m: v(5.5e-3, 4.5e-3, 3.5e-3) }),
            );
            t.insert(
                "pyramid_large".to_string(),
                template(TemplateShape::RoundedPyramid { base_m: 11e-3, height_m: 8e-3, rounding_m: 1.5e-3 }),
            );
            t.insert(
                "pyramid_small".to_string(),
                template(TemplateShape::RoundedPyramid {
                    base_m: 8.5e-3,
                    height_m: 6.5e-3,
                    rounding_m: 1.2e-3,
                }),
            );
            GravelometerInput {
                duration_s: Some(2.0),
                pipe: PipeKeys { diameter_m: Some(0.052), length_m: Some(0.3), air_velocity_m_s: Some(31.1) },
                // A quarter of the pipe diameter: about one gravel stone (see super::coupled).
                coupled_air: CoupledAirKeys { cell_size_m: Some(0.013), ..common.coupled_air.clone() },
                panel: PanelKeys {
                    width_m: Some(0.1),
                    length_m: Some(0.3),
                    angle_deg: Some(90.0),
                    // A nozzle-to-panel distance of 55 cm is quoted for SAE J400 set-ups; minus the pipe.
                    distance_m: Some(0.25),
                    strips: Some(6),
                    ..common.panel.clone()
                },
                stones: StoneKeys {
                    member_diameter_m: Some(member),
                    density_kg_m3: Some(2650.0),
                    youngs_modulus_pa: Some(5.0e10),
                    charge_kg: Some(4.732e-4 * 1500.0),
                    feed_time_s: Some(7.0),
                    templates: Some(t),
                    ..common.stones.clone()
                },
                ..common
            }
        }
    };
    (p, assumed)
}

/// A filled value (every key is filled by the preset when the configuration is loaded).
pub(crate) fn get<T: Copy>(v: Option<T>) -> T {
    v.expect("filled by the preset")
}

impl Standard {
    /// The standard's name as printed on titles.
    pub fn label(self) -> &'static str {
        match self {
            Standard::Din55996_1 => "DIN 55996-1",
            Standard::SaeJ400 => "SAE J400",
        }
    }
}

impl GravelometerConfig {
    pub fn air(&self) -> AirMode {
        self.input.air.unwrap_or_default()
    }
}

impl Validate for GravelometerConfig {
    fn validate(&self, c: &mut Checker) {
        let i = &self.input;
        let pos = |c: &mut Checker, k: &str, v: Option<f64>| c.positive(k, v.unwrap_or(f64::NAN));
        pos(c, "duration_s", i.duration_s);
        if let Some(dt) = i.dt_s {
            c.positive("dt_s", dt);
            if dt > i.duration_s.unwrap_or(f64::INFINITY) {
                c.fail("dt_s", format!("dt_s = {dt} is longer than duration_s"));
            }
        }
        match self.air() {
            AirMode::None => {}
            AirMode::Prescribed => {}
            AirMode::Coupled => {}
        }
        let coupled = self.air() == AirMode::Coupled;
        c.nested("coupled_air", |c| {
            if !coupled {
                return;
            }
            let a = &i.coupled_air;
            let h = a.cell_size_m.unwrap_or(f64::NAN);
            pos(c, "cell_size_m", a.cell_size_m);
            if let Some(d) = i.pipe.diameter_m {
                if h > 0.5 * d {
                    c.fail(
                        "cell_size_m",
                        format!(
                            "cell_size_m = {h} m leaves fewer than two cells across the pipe (pipe.diameter_m = \
                             {d} m): give at most {} m",
                            0.5 * d
                        ),
                    );
                }
            }
            c.in_range("inlet_intensity", a.inlet_intensity.unwrap_or(f64::NAN), 0.0, false, 1.0, true);
            if a.dem_steps_per_fluid_step == Some(0) {
                c.fail("dem_steps_per_fluid_step", "= 0: give at least 1 DEM step per fluid step");
            }
        });
        c.nested("pipe", |c| {
            pos(c, "diameter_m", i.pipe.diameter_m);
            pos(c, "length_m", i.pipe.length_m);
            pos(c, "air_velocity_m_s", i.pipe.air_velocity_m_s);
        });
        c.nested("panel", |c| {
            let p = &i.panel;
            pos(c, "width_m", p.width_m);
            pos(c, "length_m", p.length_m);
            pos(c, "distance_m", p.distance_m);
            pos(c, "triangle_size_m", p.triangle_size_m);
            let a = p.angle_deg.unwrap_or(f64::NAN);
            if !(a > 0.0 && a <= 90.0) {
                c.fail(
                    "angle_deg",
                    format!(
                        "angle_deg = {a} is outside (0°, 90°]: the panel's angle to the horizontal, 90° upright \
                         (SAE J400), 54° for DIN 55996-1"
                    ),
                );
            }
            let strips = p.strips.unwrap_or(0);
            if strips == 0 {
                c.fail("strips", "strips = 0: the panel needs at least one strip".to_string());
            }
            if let (Some(l), Some(h)) = (p.length_m, p.triangle_size_m) {
                let rows = (l / h).ceil();
                if l > 0.0 && h > 0.0 && rows < strips as f64 {
                    c.fail(
                        "strips",
                        format!(
                            "strips = {strips} is more than the {rows} rows of panel triangles along the \
                             {l} m long edge at triangle_size_m = {h}; use a smaller triangle_size_m (at \
                             most {:.4} m) or fewer strips",
                            l / strips as f64
                        ),
                    );
                }
                if l > 0.0 && h > 0.0 {
                    let tris = 2.0 * rows * (p.width_m.unwrap_or(0.0) / h).ceil();
                    c.memory_estimate("triangle_size_m", &format!("{tris:.0} panel triangles × 200 B"), tris * 200.0);
                }
            }
        });
        c.nested("clamp", |c| {
            pos(c, "bar_width_m", i.clamp.bar_width_m);
            pos(c, "thickness_m", i.clamp.thickness_m);
            if let (Some(b), Some(l)) = (i.clamp.bar_width_m, i.panel.length_m) {
                if 2.0 * b >= l {
                    c.fail("bar_width_m", format!("bar_width_m = {b}: two bars cover the whole {l} m panel"));
                }
            }
        });
        c.nested("protection_box", |c| pos(c, "margin_m", i.protection_box.margin_m));
        c.nested("stones", |c| {
            let s = &i.stones;
            pos(c, "sphere_diameter_m", s.sphere_diameter_m);
            pos(c, "member_diameter_m", s.member_diameter_m);
            pos(c, "density_kg_m3", s.density_kg_m3);
            pos(c, "youngs_modulus_pa", s.youngs_modulus_pa);
            c.in_range("poisson_ratio", s.poisson_ratio.unwrap_or(f64::NAN), 0.0, true, 0.5, false);
            pos(c, "charge_kg", s.charge_kg);
            pos(c, "feed_time_s", s.feed_time_s);
            if s.count == Some(0) {
                c.fail("count", "count = 0: feed at least one stone".to_string());
            }
            if let Some(n) = s.count {
                c.memory_estimate(
                    "count",
                    &format!("count = {n} stones × 500 members × 1000 B"),
                    n as f64 * 5e5,
                );
            }
            let names: Vec<&String> = s.templates.iter().flat_map(|t| t.keys()).collect();
            if s.shape == Some(StoneShape::Standard) && names.is_empty() {
                c.fail("templates", "name at least one stone template".to_string());
            }
            for (name, t) in s.templates.iter().flatten() {
                c.nested("templates", |c| c.nested(name, |c| t.validate(c)));
            }
            if let Some(r) = &s.ratios {
                if r.len() != names.len() {
                    c.fail(
                        "ratios",
                        format!("{} ratios for {} templates; give one per template", r.len(), names.len()),
                    );
                }
                for (k, v) in r.iter().enumerate() {
                    c.non_negative(&format!("ratios[{k}]"), *v);
                }
                if r.iter().sum::<f64>() <= 0.0 {
                    c.fail("ratios", "at least one ratio must be positive".to_string());
                }
            }
        });
        c.nested("launch", |c| {
            let l = &i.launch;
            pos(c, "k_h", l.k_h);
            pos(c, "air_flow_m3_s", l.air_flow_m3_s);
            if let Some(v) = l.speed_m_s {
                // Air may start the stones from rest (the single-particle tests).
                match self.air() {
                    AirMode::Prescribed | AirMode::Coupled => c.non_negative("speed_m_s", v),
                    _ => c.positive("speed_m_s", v),
                }
            }
            c.non_negative("fall_height_m", l.fall_height_m.unwrap_or(f64::NAN));
            c.in_range("feeder_restitution", l.feeder_restitution.unwrap_or(f64::NAN), 0.0, true, 1.0, true);
        });
        c.nested("contact", |c| {
            let k = &i.contact;
            for (key, e) in [
                ("stone_wall_restitution", k.stone_wall_restitution),
                ("stone_stone_restitution", k.stone_stone_restitution),
            ] {
                c.in_range(key, e.unwrap_or(f64::NAN), 0.0, false, 1.0, true);
            }
            c.non_negative("stone_wall_friction", k.stone_wall_friction.unwrap_or(f64::NAN));
            c.non_negative("stone_stone_friction", k.stone_stone_friction.unwrap_or(f64::NAN));
        });
        c.nested("walls", |c| {
            pos(c, "youngs_modulus_pa", i.walls.youngs_modulus_pa);
            c.in_range("poisson_ratio", i.walls.poisson_ratio.unwrap_or(f64::NAN), 0.0, true, 0.5, false);
            pos(c, "coating_density_kg_m3", i.walls.coating_density_kg_m3);
        });
        c.nested("air_field", |c| {
            let a = &i.air_field;
            let n = a.profile_exponent.unwrap_or(f64::NAN);
            if !(1.0..=20.0).contains(&n) {
                c.fail(
                    "profile_exponent",
                    format!(
                        "profile_exponent = {n}: the exponent n of the turbulent pipe profile (1 − r/R)^(1/n) lies \
                         between 1 and 20 (7 near Re = 1e5, larger at higher Reynolds numbers)"
                    ),
                );
            }
            c.non_negative("ramp_s", a.ramp_s.unwrap_or(f64::NAN));
            pos(c, "density_kg_m3", a.density_kg_m3);
            pos(c, "viscosity_pa_s", a.viscosity_pa_s);
            if let Some(k) = &a.k_correction {
                c.nested("k_correction", |c| k.validate(c));
            }
        });
        c.nested("wear", |c| pos(c, "k_s2_m2", i.wear.k_s2_m2));
        c.nested("output", |c| {
            if i.output.first_n == Some(0) {
                c.fail("first_n", "first_n = 0: the statistics need at least one stone".to_string());
            }
            if i.output.cutoff_impacts == Some(0) {
                c.fail("cutoff_impacts", "cutoff_impacts = 0: give at least one impact".to_string());
            }
            pos(c, "output_interval_s", i.output.output_interval_s);
        });
    }
}

impl spatter_io::run::Smoke for GravelometerConfig {
    /// Three one-sphere stones of the templates' outer size, soft, through a 3 cm pipe onto the panel
    /// 6 cm further on: the whole chain down to the results in a second or two.
    fn smoke(&mut self) {
        let i = &mut self.input;
        i.stones.count = Some(3);
        i.stones.feed_time_s = Some(0.002);
        for t in i.stones.templates.iter_mut().flat_map(|t| t.values_mut()) {
            if !matches!(t.shape, TemplateShape::Spheres { .. }) {
                t.packing = Some(crate::dem_scene::Packing::Count { sphere_count: 1 });
            }
        }
        i.stones.member_diameter_m = Some(i.stones.sphere_diameter_m.unwrap_or(5e-3));
        i.stones.youngs_modulus_pa = Some(i.stones.youngs_modulus_pa.unwrap_or(1e9).min(1e9));
        i.pipe.length_m = Some(i.pipe.length_m.unwrap_or(0.03).min(0.03));
        i.panel.distance_m = Some(i.panel.distance_m.unwrap_or(0.06).min(0.06));
        i.panel.triangle_size_m = Some(i.panel.triangle_size_m.unwrap_or(0.01).max(0.01));
        let launch = i.launch.speed_m_s.unwrap_or(10.0).max(5.0);
        let flight = 0.12 / launch;
        i.duration_s = Some(i.duration_s.unwrap_or(1.0).min(flight + 0.004));
        i.output.output_interval_s = Some(i.duration_s.unwrap_or(0.02) / 4.0);
        // Coupled air: two cells across the pipe (the coarsest the keys allow).
        if let (Some(h), Some(d)) = (i.coupled_air.cell_size_m, i.pipe.diameter_m) {
            i.coupled_air.cell_size_m = Some(h.max(0.5 * d));
        }
    }
}
