//! The registry of scenario kinds: the value of the top-level `kind` key, the configuration type it is
//! read into, and the function that runs it.
//!
//! Adding a kind is one line in the `kinds!` invocation below: the name, the variant, the configuration
//! type (serde + [`Validate`]), its `run(&Config, &RunContext) -> Result<RunSummary, E>` function, and
//! whether it runs split over several ranks (`ranks = true`: its `run` joins the collectives of
//! `ctx.comm`; see `docs/architecture.md`, "Running under mpirun").

#[allow(unused_imports)]
use crate::parse::{typed, validate, ScenarioError};
use crate::source::Source;
use serde::Serialize;
use spatter_core::check::Validate;
use spatter_io::paths::absolute_paths;
use spatter_io::run::{RunContext, RunSummary};
use std::path::Path;

/// Error returned by a running scenario.
pub type RunError = Box<dyn std::error::Error + Send + Sync>;

macro_rules! kinds {
    ($( $name:literal => $variant:ident($cfg:ty, $run:path), ranks = $ranks:literal, $doc:literal; )*) => {
        /// Every accepted value of `kind`.
        pub const KINDS: &[&str] = &[$($name),*];

        /// Every kind with whether it runs split over several ranks.
        pub const KIND_RANKS: &[(&str, bool)] = &[$(($name, $ranks)),*];

        /// A scenario read and validated from a file.
        #[derive(Debug)]
        #[allow(clippy::large_enum_variant)]
        pub enum Scenario {
            $( #[doc = $doc] $variant($cfg), )*
        }

        impl Scenario {
            /// The `kind` this scenario was read as.
            pub fn kind(&self) -> &'static str {
                match *self { $( Scenario::$variant(_) => $name, )* }
            }

            /// True when the kind runs split over several ranks (`mpirun -n N`); the others are refused on
            /// several ranks.
            pub fn runs_on_ranks(&self) -> bool {
                match *self { $( Scenario::$variant(_) => $ranks, )* }
            }

            /// Runs the scenario in `ctx`.
            #[allow(unused_variables)]
            pub fn run(&self, ctx: &RunContext) -> Result<RunSummary, RunError> {
                match *self { $( Scenario::$variant(ref c) => $run(c, ctx).map_err(|e| Box::new(e) as RunError), )* }
            }

            /// Cuts the scenario down to a smoke test (see [`spatter_io::run::Smoke`]).
            pub fn smoke(&mut self) {
                match *self { $( Scenario::$variant(ref mut c) => spatter_io::run::Smoke::smoke(c), )* }
            }

            /// The fully resolved input as TOML (`kind` first, every default filled in).
            pub fn resolved_toml(&self) -> Result<String, String> {
                match *self { $( Scenario::$variant(ref c) => resolved($name, c), )* }
            }

            #[allow(unused_variables)]
            fn read(kind: &str, src: &Source, body: &str) -> Result<Option<Self>, Vec<ScenarioError>> {
                match kind {
                    $( $name => {
                        let cfg: $cfg = typed(src, body).map_err(|e| vec![e])?;
                        validate(src, &cfg)?;
                        let cfg = absolute_paths(cfg, &src.base_dir())
                            .map_err(|e| vec![ScenarioError::whole_file(&src.path, e)])?;
                        Ok(Some(Scenario::$variant(cfg)))
                    } )*
                    _ => Ok(None),
                }
            }
        }
    };
}

kinds! {
    "dem" => Dem(spatter_workflows::dem_scene::SceneConfig, spatter_workflows::dem_scene::run), ranks = true,
        "A DEM scene: materials, particles (fills, injectors), walls (planes, cylinders, STL meshes with motion).";
    "sph" => Sph(spatter_workflows::sph_scene::SphConfig, spatter_workflows::sph_scene::run), ranks = true,
        "Free-surface water (WCSPH) with walls and moving bodies: wetting maps, splash heights, probes.";
    "snow_regime_map" => SnowRegimeMap(spatter_workflows::snow::SnowConfig, spatter_workflows::snow::run), ranks = false,
        "Stick/bounce regime map of snow grains hitting a wall: grid, bisection, sensitivity study, rough wall.";
    "deposition" => Deposition(spatter_workflows::deposition::DepositionConfig, spatter_workflows::deposition::run), ranks = false,
        "Particles carried by an analytic or imported (VTK) flow onto STL bodies: deposit maps, mass balance.";
    "wading" => Wading(spatter_workflows::wading::WadingConfig, spatter_workflows::wading::run), ranks = true,
        "A vehicle of named STL parts driving through a wading channel (generated or from an STL file): wetting per part, sensors, splash heights.";
    "flow" => Flow(spatter_workflows::cfd::FlowConfig, spatter_workflows::cfd::run), ranks = false,
        "Incompressible flow on a structured grid (Cartesian with solids, or axisymmetric): fields, probes, pictures.";
    "cfd_dem" => CfdDem(spatter_workflows::cfd_dem::CfdDemConfig, spatter_workflows::cfd_dem::run), ranks = false,
        "Flow on a Cartesian grid coupled two-way to a DEM scene (volume-averaged CFD-DEM): fluidised and fixed beds, settling.";
    "forces" => Forces(spatter_workflows::deposition::ForcesConfig, spatter_workflows::deposition::forces::run), ranks = false,
        "Nondimensional ranking of the particle-fluid forces for given scales (Jasion 2013 Table 6.4).";
    "gravelometer" => Gravelometer(spatter_workflows::gravelometer::GravelometerConfig, spatter_workflows::gravelometer::run), ranks = true,
        "Stone-chip test (DIN 55996-1, SAE J400): stones shot through a pipe at a coated panel; damage map, strip shares, impact statistics.";
    "brownout" => Brownout(spatter_workflows::brownout::BrownoutConfig, spatter_workflows::brownout::run), ranks = false,
        "Rotor over a sand bed: lift-off map, entrainment source, dust cloud concentration and optical depth.";
    "integrator_study" => IntegratorStudy(spatter_workflows::bed_lab::IntegratorStudyConfig, spatter_workflows::bed_lab::run_integrator_study), ranks = false,
        "The ten DEM time integrators on analytic single contacts: error sweeps, observed orders beside Jasion (2013).";
}

#[allow(dead_code)]
fn resolved<T: Serialize>(kind: &str, cfg: &T) -> Result<String, String> {
    let body = toml::to_string(cfg).map_err(|e| e.to_string())?;
    Ok(format!("# Fully resolved input, every default filled in.\nkind = \"{kind}\"\n{body}"))
}

/// A scenario together with its source file.
#[derive(Debug)]
pub struct Loaded {
    pub scenario: Scenario,
    pub source: Source,
}

/// Reads, parses and validates the scenario file at `path`.
pub fn load(path: &Path) -> Result<Loaded, Vec<ScenarioError>> {
    let source = Source::read(path).map_err(|e| vec![e])?;
    load_source(source)
}

/// Like [`load`] for text already in memory; `path` is used in messages and to resolve relative paths.
pub fn load_str(path: &Path, text: &str) -> Result<Loaded, Vec<ScenarioError>> {
    let source = Source::from_bytes(path, text.as_bytes()).map_err(|e| vec![e])?;
    load_source(source)
}

fn load_source(source: Source) -> Result<Loaded, Vec<ScenarioError>> {
    // Syntax first: a file that is not TOML gets the parser's located message.
    let table: toml::Table = typed(&source, &source.text).map_err(|e| vec![e])?;
    let expected = || format!("one of: {}", KINDS.join(", "));
    let kind = match table.get("kind") {
        Some(toml::Value::String(s)) => s.clone(),
        Some(other) => {
            let span = source.key_value_span("kind").unwrap_or(0..0);
            return Err(vec![ScenarioError::at(
                &source,
                span.start,
                Some("kind".into()),
                format!("kind = {other} must be a string, {}", expected()),
            )]);
        }
        None => {
            return Err(vec![ScenarioError::at(
                &source,
                0,
                Some("kind".into()),
                if table.contains_key("base") && table.contains_key("vary") {
                    "this is a parameter study (it has `base` and `[[vary]]`), not a scenario: run it with \
                     `spatter sweep FILE`"
                        .to_owned()
                } else {
                    format!("missing key `kind` at the top of the file; expected {}", expected())
                },
            )])
        }
    };
    // Blank the `kind = …` line with spaces so every other byte keeps its position for error messages.
    let span = source.key_value_span("kind").unwrap_or(0..0);
    let mut body = source.text.clone();
    body.replace_range(span.clone(), &" ".repeat(span.len()));
    match Scenario::read(&kind, &source, &body)? {
        Some(scenario) => Ok(Loaded { scenario, source }),
        None => {
            let at = source.locate("kind").map(|(s, _)| s.start).unwrap_or(0);
            Err(vec![ScenarioError::at(
                &source,
                at,
                Some("kind".into()),
                format!("unknown kind \"{kind}\"; expected {}", expected()),
            )])
        }
    }
}

#[allow(dead_code)]
fn assert_validate<T: Validate>() {}
