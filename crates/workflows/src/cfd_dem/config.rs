//! Scenario configuration of the `cfd_dem` kind: a flow on a Cartesian grid (the `flow` kind's
//! `[fluid]`, `[grid]`, `[boundaries]`, `[[solids]]`, `[turbulence]` and `[numerics]` tables, same keys)
//! coupled two-way to a DEM scene (`[dem]`, the body of a `kind = "dem"` file) through the options of
//! `[coupling]`. Every key is documented with its unit and default in `docs/cfd.md`.

use super::CouplingOptions;
use crate::cfd::config::{
    BoundariesSpec, CutNormal, FluidSpec, GridSpec, NumericsSpec, OutputSpec, ProbeSpec, SliceSpec,
    TurbulenceSpec,
};
use crate::dem_scene::SceneConfig;
use serde::{Deserialize, Serialize};
use spatter_cfd::solid::Solid;
use spatter_cfd::Mode;
use spatter_core::check::{Checker, Validate};

/// `kind = "cfd_dem"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CfdDemConfig {
    /// Free text for the log and pictures.
    #[serde(default)]
    pub title: String,
    #[serde(default)]
    pub fluid: FluidSpec,
    pub grid: GridSpec,
    #[serde(default)]
    pub boundaries: BoundariesSpec,
    #[serde(default)]
    pub solids: Vec<Solid>,
    #[serde(default)]
    pub turbulence: TurbulenceSpec,
    /// The fluid step is `coupling.dem_steps_per_fluid_step × dem.dt_s`: `dt_s` and `dt_max_s` do not
    /// apply (giving them is an error), nor does `courant`.
    #[serde(default)]
    pub numerics: NumericsSpec,
    /// The DEM scene: time step, duration, materials, walls, fills, injectors, particle outputs.
    pub dem: SceneConfig,
    #[serde(default)]
    pub coupling: CouplingOptions,
    #[serde(default)]
    pub output: CfdDemOutput,
}

/// What is written and how often.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CfdDemOutput {
    /// Interval of the fluid `.vtr` and particle `.vtu` snapshots \[s\]; default `dem.output_interval_s`.
    #[serde(default)]
    pub field_interval_s: Option<f64>,
    /// Interval of the `series.csv` and `probes.csv` rows \[s\]; default `dem.duration_s / 200`.
    #[serde(default)]
    pub sample_interval_s: Option<f64>,
    /// Points where the fluid velocity and pressure are recorded.
    #[serde(default)]
    pub probes: Vec<ProbeSpec>,
    /// The cut of `speed.png` and `void_fraction.png`; default normal to y through the middle.
    #[serde(default)]
    pub slice: Option<SliceSpec>,
}

impl CfdDemOutput {
    pub fn field_interval(&self, dem: &SceneConfig) -> f64 {
        self.field_interval_s.unwrap_or(dem.output_interval_s)
    }

    pub fn sample_interval(&self, dem: &SceneConfig) -> f64 {
        self.sample_interval_s.unwrap_or(dem.duration_s / 200.0)
    }

    /// The picture cut: (normal axis, coordinate) with the default filled in from `grid`.
    pub fn cut(&self, grid: &GridSpec) -> (usize, f64) {
        match self.slice {
            Some(s) => (
                match s.normal {
                    CutNormal::X => 0,
                    CutNormal::Y => 1,
                    CutNormal::Z => 2,
                },
                s.at_m,
            ),
            None => (1, 0.5 * (grid.y.min_m + grid.y.max_m)),
        }
    }

    /// The same keys as the `flow` kind's `[output]`, to validate them with its rules.
    fn as_flow_output(&self) -> OutputSpec {
        OutputSpec {
            field_interval_s: self.field_interval_s,
            sample_interval_s: self.sample_interval_s,
            probes: self.probes.clone(),
            slice: self.slice,
            ghia_re: None,
        }
    }
}

impl Validate for CfdDemConfig {
    fn validate(&self, c: &mut Checker) {
        c.nested("fluid", |c| {
            c.positive("density_kg_m3", self.fluid.density_kg_m3);
            c.positive("kinematic_viscosity_m2_s", self.fluid.kinematic_viscosity_m2_s);
        });
        c.item("grid", &self.grid);
        if self.grid.mode != Mode::Cartesian {
            c.fail(
                "grid.mode",
                "CFD–DEM coupling needs a Cartesian grid (the axisymmetric mode has no 3D particle cells)",
            );
        }
        c.item("boundaries", &self.boundaries);
        for (i, s) in self.solids.iter().enumerate() {
            c.element("solids", i, |c| s.validate(c));
        }
        c.item("turbulence", &self.turbulence);
        c.item("numerics", &self.numerics);
        c.nested("numerics", |c| {
            for (key, v) in [("dt_s", self.numerics.dt_s), ("dt_max_s", self.numerics.dt_max_s)] {
                if let Some(v) = v {
                    c.fail(
                        key,
                        format!(
                            "= {v} s: the fluid step of a cfd_dem run is coupling.dem_steps_per_fluid_step × \
                             dem.dt_s; leave {key} out"
                        ),
                    );
                }
            }
        });
        c.item("dem", &self.dem);
        c.item("coupling", &self.coupling);
        if self.coupling.forces.fluid != spatter_flow::forces::Fluid::default() {
            c.fail("coupling.fluid", "the coupled fluid is the one of [fluid]; leave coupling.fluid out");
        }
        c.item("output", &self.output.as_flow_output());
        let steps_per_fluid = self.coupling.dem_steps_per_fluid_step as f64;
        if self.dem.duration_s < steps_per_fluid * self.dem.dt_s {
            c.fail(
                "dem.duration_s",
                format!(
                    "= {} s is shorter than one fluid step (coupling.dem_steps_per_fluid_step × dem.dt_s = {} s)",
                    self.dem.duration_s,
                    steps_per_fluid * self.dem.dt_s
                ),
            );
        }
    }
}

impl spatter_io::run::Smoke for CfdDemConfig {
    /// The DEM scene's smoke cut (40 DEM steps, at most 200 particles per counted fill), at least one
    /// fluid step; every output is still written.
    fn smoke(&mut self) {
        self.dem.smoke();
        let fluid_dt = self.coupling.dem_steps_per_fluid_step as f64 * self.dem.dt_s;
        self.dem.duration_s = self.dem.duration_s.max(fluid_dt);
        self.output.field_interval_s = Some(self.dem.duration_s / 2.0);
        self.output.sample_interval_s = Some(fluid_dt);
    }
}
