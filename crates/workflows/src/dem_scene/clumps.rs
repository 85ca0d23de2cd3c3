//! Scene keys of rigid multi-sphere bodies and wear: `[templates.<name>]`, the `clumps` mix of `[[fill]]`
//! and `[[inject]]`, and `[[wear]]` (every key documented in `docs/dem.md` §3).

use serde::{Deserialize, Serialize};
use spatter_core::check::Checker;
use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;
use spatter_dem::clump::fill::{check_closed, fill_count, fill_equal, read_sphere_file, TemplateError};
use spatter_dem::clump::shapes::{Ball, CutBall, Ellipsoid, MeshSolid, RoundedPolyhedron, Solid};
use spatter_dem::clump::{ClumpTemplate, MassBasis};
use spatter_dem::error::DemError;
use spatter_dem::wear::WearModel;
use std::f64::consts::PI;
use std::path::PathBuf;

/// A clump template: a shape and how it is made of spheres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemplateConfig {
    pub shape: TemplateShape,
    /// How a generated shape or closed mesh is filled with spheres (not for `spheres` files).
    #[serde(default)]
    pub packing: Option<Packing>,
    /// Which mass a body carries: `envelope` (ρ × volume of the shape; default for generated shapes and
    /// meshes), `spheres` (ρ × volume of the member spheres; default for sphere files) or `given`
    /// (`mass_kg`).
    #[serde(default)]
    pub mass_basis: Option<MassBasisKind>,
    /// Mass of one body for `mass_basis = "given"` \[kg\].
    #[serde(default)]
    pub mass_kg: Option<f64>,
}

/// Template shapes (`type = …`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum TemplateShape {
    Ball {
        radius_m: f64,
    },
    Ellipsoid {
        semi_axes_m: Vec3,
    },
    /// The ball above the plane z = `cut_z_m` (default −radius/3: the "one-third sphere" with the lower
    /// third of its diameter removed).
    CutBall {
        radius_m: f64,
        #[serde(default)]
        cut_z_m: Option<f64>,
    },
    /// A regular tetrahedron of `edge_m` grown by `rounding_m`.
    RoundedTetrahedron {
        edge_m: f64,
        rounding_m: f64,
    },
    /// A square pyramid (base side `base_m`, height `height_m`) grown by `rounding_m`.
    RoundedPyramid {
        base_m: f64,
        height_m: f64,
        rounding_m: f64,
    },
    /// The inside of a closed STL/OBJ surface, coordinates × `scale`.
    Mesh {
        file: PathBuf,
        #[serde(default = "one")]
        scale: f64,
    },
    /// A list of spheres, one `x y z r` line each (metres).
    Spheres {
        file: PathBuf,
    },
}

fn one() -> f64 {
    1.0
}

/// How a solid is filled (`type = "equal" | "count"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Packing {
    /// Touching equal spheres on a face-centred cubic lattice.
    Equal { sphere_diameter_m: f64 },
    /// `sphere_count` spheres of decreasing size, each the largest that fits.
    Count { sphere_count: usize },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MassBasisKind {
    Envelope,
    Spheres,
    Given,
}

/// A mix of templates for `[[fill]]` and `[[inject]]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClumpMixConfig {
    /// Template names (keys of `[templates]`).
    pub templates: Vec<String>,
    /// Relative amounts, one per template (default: equal).
    #[serde(default)]
    pub ratios: Option<Vec<f64>>,
    /// What the ratios count: `number` of bodies (default) or `mass`.
    #[serde(default)]
    pub basis: RatioBasis,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RatioBasis {
    #[default]
    Number,
    Mass,
}

/// A wear model for impacts of particles of one material on mesh walls of another.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WearConfig {
    pub particle_material: String,
    pub wall_material: String,
    /// `finnie` or `normal_energy`.
    pub model: WearKind,
    /// Finnie: k \[s²/m²\] (eroded mass per impacting mass per squared speed).
    #[serde(default)]
    pub k_s2_m2: Option<f64>,
    /// Normal energy: eroded mass per joule above the threshold \[kg/J\].
    #[serde(default)]
    pub coefficient_kg_j: Option<f64>,
    /// Normal energy: threshold of the normal impact energy \[J\] (default 0).
    #[serde(default)]
    pub threshold_j: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WearKind {
    Finnie,
    NormalEnergy,
}

impl WearConfig {
    /// The engine's model.
    pub fn model(&self) -> WearModel {
        match self.model {
            WearKind::Finnie => WearModel::Finnie { k: self.k_s2_m2.unwrap_or(0.0) },
            WearKind::NormalEnergy => WearModel::NormalEnergy {
                coefficient: self.coefficient_kg_j.unwrap_or(0.0),
                threshold: self.threshold_j,
            },
        }
    }

    pub(crate) fn validate(&self, c: &mut Checker) {
        match self.model {
            WearKind::Finnie => {
                match self.k_s2_m2 {
                    Some(k) => c.positive("k_s2_m2", k),
                    None => {
                        c.fail("k_s2_m2", "model = \"finnie\" needs k_s2_m2 (s²/m², e.g. 1.0)".to_string())
                    }
                }
                if self.coefficient_kg_j.is_some() {
                    c.fail("coefficient_kg_j", "belongs to model = \"normal_energy\"".to_string());
                }
            }
            WearKind::NormalEnergy => {
                match self.coefficient_kg_j {
                    Some(k) => c.positive("coefficient_kg_j", k),
                    None => c.fail(
                        "coefficient_kg_j",
                        "model = \"normal_energy\" needs coefficient_kg_j (kg per J above the threshold)"
                            .to_string(),
                    ),
                }
                c.non_negative("threshold_j", self.threshold_j);
                if self.k_s2_m2.is_some() {
                    c.fail("k_s2_m2", "belongs to model = \"finnie\"".to_string());
                }
            }
        }
    }
}

/// Largest number of spheres of one template (a finer packing is almost surely a unit mistake).
pub const MAX_TEMPLATE_SPHERES: f64 = 1e5;
/// Largest `sphere_count` of a `count` packing (its greedy search is quadratic in the count).
pub const MAX_SPHERE_COUNT: usize = 2000;

impl TemplateShape {
    /// The solid of a generated shape (`None` for meshes and sphere files).
    fn generated(&self) -> Option<Box<dyn Solid>> {
        Some(match *self {
            TemplateShape::Ball { radius_m } => Box::new(Ball { radius: radius_m }),
            TemplateShape::Ellipsoid { semi_axes_m } => Box::new(Ellipsoid { semi_axes: semi_axes_m }),
            TemplateShape::CutBall { radius_m, cut_z_m } => {
                Box::new(CutBall { radius: radius_m, cut_z: cut_z_m.unwrap_or(-radius_m / 3.0) })
            }
            TemplateShape::RoundedTetrahedron { edge_m, rounding_m } => {
                Box::new(RoundedPolyhedron::tetrahedron(edge_m, rounding_m))
            }
            TemplateShape::RoundedPyramid { base_m, height_m, rounding_m } => {
                Box::new(RoundedPolyhedron::square_pyramid(base_m, height_m, rounding_m))
            }
            TemplateShape::Mesh { .. } | TemplateShape::Spheres { .. } => return None,
        })
    }
}

impl TemplateConfig {
    /// Checks the keys (referenced files are read when the template is built, with errors naming them).
    pub(crate) fn validate(&self, c: &mut Checker) {
        c.nested("shape", |c| match &self.shape {
            TemplateShape::Ball { radius_m } => c.positive("radius_m", *radius_m),
            TemplateShape::Ellipsoid { semi_axes_m } => {
                c.finite_vec("semi_axes_m", *semi_axes_m);
                if semi_axes_m.is_finite() && semi_axes_m.min_element() <= 0.0 {
                    c.fail("semi_axes_m", "every semi-axis must be positive (metres)".to_string());
                }
            }
            TemplateShape::CutBall { radius_m, cut_z_m } => {
                c.positive("radius_m", *radius_m);
                if let Some(z) = cut_z_m {
                    c.in_range("cut_z_m", *z, -radius_m, false, *radius_m, false);
                }
            }
            TemplateShape::RoundedTetrahedron { edge_m, rounding_m } => {
                c.positive("edge_m", *edge_m);
                c.non_negative("rounding_m", *rounding_m);
            }
            TemplateShape::RoundedPyramid { base_m, height_m, rounding_m } => {
                c.positive("base_m", *base_m);
                c.positive("height_m", *height_m);
                c.non_negative("rounding_m", *rounding_m);
            }
            TemplateShape::Mesh { file, scale } => {
                c.mesh_file("file", file);
                c.positive("scale", *scale);
            }
            TemplateShape::Spheres { file } => c.file_exists("file", file),
        });
        let sphere_file = matches!(self.shape, TemplateShape::Spheres { .. });
        match (&self.packing, sphere_file) {
            (Some(_), true) => {
                c.fail("packing", "a sphere file is its own packing; remove packing".to_string())
            }
            (None, false) => c.fail(
                "packing",
                "a shape needs a packing, e.g. packing = { type = \"equal\", sphere_diameter_m = 5e-4 } or \
                 { type = \"count\", sphere_count = 20 }"
                    .to_string(),
            ),
            _ => {}
        }
        c.nested("packing", |c| match &self.packing {
            Some(Packing::Equal { sphere_diameter_m }) => {
                c.positive("sphere_diameter_m", *sphere_diameter_m);
                if let Some(solid) = self.shape.generated() {
                    // FCC at close packing: 0.74 of the volume in spheres of diameter d.
                    let n = 0.74 * solid.volume() / (PI / 6.0 * sphere_diameter_m.powi(3));
                    if n.is_finite() && n > MAX_TEMPLATE_SPHERES {
                        c.fail(
                            "sphere_diameter_m",
                            format!(
                                "sphere_diameter_m = {sphere_diameter_m} m packs about {n:.2e} spheres into one \
                                 body, above {MAX_TEMPLATE_SPHERES:e}; use larger spheres (check the units: \
                                 metres)"
                            ),
                        );
                    }
                }
            }
            Some(Packing::Count { sphere_count }) if *sphere_count == 0 || *sphere_count > MAX_SPHERE_COUNT => {
                c.fail(
                    "sphere_count",
                    format!("sphere_count = {sphere_count} must be between 1 and {MAX_SPHERE_COUNT}"),
                );
            }
            Some(Packing::Count { .. }) | None => {}
        });
        match (self.mass_basis, self.mass_kg) {
            (Some(MassBasisKind::Given), Some(m)) => c.positive("mass_kg", m),
            (Some(MassBasisKind::Given), None) => {
                c.fail("mass_kg", "mass_basis = \"given\" needs mass_kg (kg per body)".to_string())
            }
            (_, Some(_)) => c.fail("mass_kg", "is used only with mass_basis = \"given\"".to_string()),
            _ => {}
        }
        if sphere_file && self.mass_basis == Some(MassBasisKind::Envelope) {
            c.fail(
                "mass_basis",
                "a sphere file has no envelope volume; use \"spheres\" or \"given\"".to_string(),
            );
        }
    }

    /// Builds the template `name`. Errors name the key `templates.<name>.…` and, for files, the file and
    /// line.
    pub fn build(&self, name: &str) -> Result<ClumpTemplate, DemError> {
        let key = |k: &str| format!("templates.{name}.{k}");
        let from = |k: &str| {
            let key = key(k);
            move |e: TemplateError| DemError::Config { key: key.clone(), message: e.to_string() }
        };
        let packed = |solid: &dyn Solid| -> Result<Vec<(Vec3, f64)>, DemError> {
            match &self.packing {
                Some(Packing::Equal { sphere_diameter_m }) => {
                    fill_equal(solid, *sphere_diameter_m, name).map_err(from("packing.sphere_diameter_m"))
                }
                Some(Packing::Count { sphere_count }) => {
                    fill_count(solid, *sphere_count, name).map_err(from("packing.sphere_count"))
                }
                None => {
                    Err(DemError::Config { key: key("packing"), message: "a shape needs a packing".into() })
                }
            }
        };
        let (spheres, envelope) = match &self.shape {
            TemplateShape::Spheres { file } => (read_sphere_file(file).map_err(from("shape.file"))?, None),
            TemplateShape::Mesh { file, scale } => {
                let mesh = TriMesh::load(file, *scale)
                    .map_err(|e| DemError::Config { key: key("shape.file"), message: e.to_string() })?;
                check_closed(&mesh, file).map_err(from("shape.file"))?;
                let solid = MeshSolid::new(mesh);
                (packed(&solid)?, Some(solid.volume()))
            }
            shape => {
                let solid = shape.generated().expect("a generated shape");
                (packed(solid.as_ref())?, Some(solid.volume()))
            }
        };
        let mut t = ClumpTemplate::from_spheres(name, &spheres);
        if let Some(v) = envelope {
            t = t.with_envelope(v);
        }
        t = match (self.mass_basis, self.mass_kg) {
            (Some(MassBasisKind::Spheres), _) => t.with_mass_basis(MassBasis::Spheres),
            (Some(MassBasisKind::Given), Some(m)) => t.with_mass_basis(MassBasis::Kilograms(m)),
            _ => t,
        };
        Ok(t)
    }
}

/// Checks a mix against the scene's templates.
pub(crate) fn check_mix(c: &mut Checker, mix: &ClumpMixConfig, templates: &[&str]) {
    c.nested("clumps", |c| {
        if mix.templates.is_empty() {
            c.fail("templates", "name at least one template of [templates]".to_string());
        }
        for (k, t) in mix.templates.iter().enumerate() {
            if !templates.contains(&t.as_str()) {
                c.fail(
                    &format!("templates[{k}]"),
                    format!(
                        "templates[{k}] = \"{t}\" is not in [templates] (defined: {})",
                        if templates.is_empty() { "none".to_string() } else { templates.join(", ") }
                    ),
                );
            }
        }
        if let Some(r) = &mix.ratios {
            if r.len() != mix.templates.len() {
                c.fail(
                    "ratios",
                    format!(
                        "{} ratios for {} templates; give one per template",
                        r.len(),
                        mix.templates.len()
                    ),
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
}

/// Probabilities per drawn body of a mix whose bodies weigh `masses` \[kg\]: the ratios themselves
/// (number basis) or ratio / mass (mass basis: a template's share of the mass is its ratio).
pub(crate) fn mix_weights(mix: &ClumpMixConfig, masses: &[f64]) -> Vec<f64> {
    let ratios = mix.ratios.clone().unwrap_or_else(|| vec![1.0; mix.templates.len()]);
    match mix.basis {
        RatioBasis::Number => ratios,
        RatioBasis::Mass => ratios.iter().zip(masses).map(|(r, m)| r / m).collect(),
    }
}
