//! Scenario configuration of the `flow` kind: an incompressible flow on a structured grid solved by
//! `spatter-cfd`. Every key is documented with its unit and default in `docs/cfd.md`.

use serde::{Deserialize, Serialize};
use spatter_cfd::momentum::Convection;
use spatter_cfd::solid::Solid;
use spatter_cfd::{Axis, Boundary, Flow, Mode};
use spatter_core::check::{Checker, Validate};

/// `kind = "flow"`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlowConfig {
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
    /// Actuator disks (axisymmetric grids only).
    #[serde(default)]
    pub actuator_disks: Vec<spatter_cfd::sources::ActuatorDisk>,
    #[serde(default)]
    pub turbulence: TurbulenceSpec,
    #[serde(default)]
    pub numerics: NumericsSpec,
    pub time: TimeSpec,
    #[serde(default)]
    pub output: OutputSpec,
}

/// Fluid properties (default: air at 20 °C and 1 atm).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FluidSpec {
    #[serde(default = "air_density")]
    pub density_kg_m3: f64,
    #[serde(default = "air_viscosity")]
    pub kinematic_viscosity_m2_s: f64,
}

fn air_density() -> f64 {
    1.204
}

fn air_viscosity() -> f64 {
    1.516e-5
}

impl Default for FluidSpec {
    fn default() -> Self {
        FluidSpec { density_kg_m3: air_density(), kinematic_viscosity_m2_s: air_viscosity() }
    }
}

/// One axis of the grid.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisSpec {
    pub min_m: f64,
    pub max_m: f64,
    pub cells: usize,
    /// Each cell this many times wider than the one before (geometric stretching; 1 = uniform).
    #[serde(default = "one")]
    pub growth_ratio: f64,
    /// tanh clustering towards both ends (0 = uniform, 1–3 typical for walls at both ends).
    #[serde(default)]
    pub cluster: f64,
}

fn one() -> f64 {
    1.0
}

impl AxisSpec {
    /// The axis.
    pub fn axis(&self) -> Result<Axis, String> {
        let r = if self.cluster > 0.0 {
            Axis::clustered(self.min_m, self.max_m, self.cells, self.cluster)
        } else {
            Axis::geometric(self.min_m, self.max_m, self.cells, self.growth_ratio)
        };
        r.map_err(|e| e.to_string())
    }
}

impl Validate for AxisSpec {
    fn validate(&self, c: &mut Checker) {
        c.finite("min_m", self.min_m);
        c.finite("max_m", self.max_m);
        if self.max_m.partial_cmp(&self.min_m) != Some(std::cmp::Ordering::Greater) {
            c.fail("max_m", format!("max_m = {} must be greater than min_m = {}", self.max_m, self.min_m));
        }
        if self.cells == 0 {
            c.fail("cells", "an axis needs at least one cell");
        }
        c.positive("growth_ratio", self.growth_ratio);
        c.non_negative("cluster", self.cluster);
        if self.cluster > 0.0 && self.growth_ratio != 1.0 {
            c.fail("cluster", "give either growth_ratio or cluster, not both");
        }
    }
}

/// The grid: three axes and the coordinate system.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridSpec {
    /// `cartesian` (x, y, z) or `axisymmetric` (x is the radius r from 0, y the axial coordinate).
    #[serde(default)]
    pub mode: Mode,
    pub x: AxisSpec,
    pub y: AxisSpec,
    /// Required for Cartesian grids; axisymmetric grids use one cell of one radian and may omit it.
    #[serde(default)]
    pub z: Option<AxisSpec>,
    /// Refuse grids needing more memory than this \[GB\]; default: the memory the system reports
    /// available when the scenario is read.
    #[serde(default)]
    pub max_memory_gb: Option<f64>,
}

impl GridSpec {
    /// The z axis, defaulted for axisymmetric grids.
    pub fn z_axis(&self) -> AxisSpec {
        self.z.unwrap_or(AxisSpec { min_m: 0.0, max_m: 1.0, cells: 1, growth_ratio: 1.0, cluster: 0.0 })
    }

    /// Cells per axis.
    pub fn cells(&self) -> [usize; 3] {
        [self.x.cells, self.y.cells, self.z_axis().cells]
    }

    /// Bytes the run will need: the solver's fields with the turbulence and body-force arrays (an upper
    /// bound whether or not the run has k–ε or actuator disks, [`Flow::memory_estimate`]) plus the output
    /// buffers of one snapshot (about 150 B per cell: cell fields, their copy in the writer and the base64
    /// text).
    pub fn memory_estimate(&self) -> u64 {
        let n = self.cells();
        let cells = n.iter().map(|&v| v as u64).product::<u64>();
        Flow::memory_estimate(n, true, true).saturating_add(cells.saturating_mul(150))
    }
}

/// Memory the system reports available \[B\] (`MemAvailable` of `/proc/meminfo`), if known.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

impl Validate for GridSpec {
    fn validate(&self, c: &mut Checker) {
        c.item("x", &self.x);
        c.item("y", &self.y);
        match (&self.z, self.mode) {
            (Some(z), _) => c.item("z", z),
            (None, Mode::Cartesian) => c.fail("z", "a Cartesian grid needs a z axis (min_m, max_m, cells)"),
            (None, Mode::Axisymmetric) => {}
        }
        if self.mode == Mode::Axisymmetric {
            if self.x.min_m != 0.0 {
                c.fail(
                    "x.min_m",
                    format!("= {}: the radial axis of an axisymmetric grid starts at 0", self.x.min_m),
                );
            }
            if self.z.is_some_and(|z| z.cells != 1) {
                c.fail("z.cells", "an axisymmetric grid has exactly one cell along z (one radian)");
            }
        }
        if let Some(m) = self.max_memory_gb {
            c.positive("max_memory_gb", m);
        }
        // Grids too large for memory are refused here, before anything is allocated.
        let cells: u128 = self.cells().iter().map(|&v| v as u128).product();
        if cells > 0 && self.cells().iter().all(|&v| v < 1 << 24) {
            let need = self.memory_estimate();
            let (limit, source) = match self.max_memory_gb {
                Some(gb) => (Some((gb * 1e9) as u64), "grid.max_memory_gb"),
                None => (available_memory(), "the memory this system reports available"),
            };
            if let Some(limit) = limit {
                if need > limit {
                    c.fail(
                        "x.cells",
                        format!(
                            "the grid {} × {} × {} = {cells} cells needs about {:.2} GB, more than {:.2} GB ({source}); use fewer cells",
                            self.x.cells,
                            self.y.cells,
                            self.z_axis().cells,
                            need as f64 / 1e9,
                            limit as f64 / 1e9
                        ),
                    );
                }
            }
        } else if cells > 0 {
            c.fail(
                "x.cells",
                format!(
                    "{} × {} × {} cells is beyond any memory",
                    self.x.cells,
                    self.y.cells,
                    self.z_axis().cells
                ),
            );
        }
    }
}

/// The six sides of the box (default: no-slip walls).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundariesSpec {
    #[serde(default)]
    pub x_min: Boundary,
    #[serde(default)]
    pub x_max: Boundary,
    #[serde(default)]
    pub y_min: Boundary,
    #[serde(default)]
    pub y_max: Boundary,
    #[serde(default)]
    pub z_min: Boundary,
    #[serde(default)]
    pub z_max: Boundary,
}

impl BoundariesSpec {
    /// In storage order x_min, x_max, y_min, y_max, z_min, z_max.
    pub fn sides(&self) -> [Boundary; 6] {
        [
            self.x_min.clone(),
            self.x_max.clone(),
            self.y_min.clone(),
            self.y_max.clone(),
            self.z_min.clone(),
            self.z_max.clone(),
        ]
    }
}

impl Validate for BoundariesSpec {
    fn validate(&self, c: &mut Checker) {
        for (name, b) in spatter_cfd::bc::SIDES.iter().zip(self.sides().iter()) {
            c.item(name, b);
        }
    }
}

/// The turbulence model (default laminar).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum TurbulenceSpec {
    /// No model: the molecular viscosity only.
    #[default]
    Laminar,
    /// Standard k–ε with log-law wall functions on the no-slip sides and blocked-cell faces (`docs/cfd.md` §2).
    KEpsilon {
        /// Turbulence intensity of the inlets \[-\].
        #[serde(default = "inlet_intensity")]
        inlet_intensity: f64,
        /// Turbulence length scale of the inlets \[m\] (about 0.07 D for a pipe of diameter D).
        inlet_length_scale_m: f64,
    },
    /// Realizable k–ε (Shih et al. 1995) with the same wall functions and inlet keys (`docs/cfd.md` §2).
    RealizableKEpsilon {
        #[serde(default = "inlet_intensity")]
        inlet_intensity: f64,
        inlet_length_scale_m: f64,
    },
}

impl TurbulenceSpec {
    /// The solver's k–ε model, or `None` when laminar.
    pub fn k_epsilon(&self) -> Option<spatter_cfd::turbulence::KEpsilon> {
        use spatter_cfd::turbulence::KEpsilon;
        match *self {
            TurbulenceSpec::Laminar => None,
            TurbulenceSpec::KEpsilon { inlet_intensity, inlet_length_scale_m } => {
                Some(KEpsilon::standard(inlet_intensity, inlet_length_scale_m))
            }
            TurbulenceSpec::RealizableKEpsilon { inlet_intensity, inlet_length_scale_m } => {
                Some(KEpsilon::realizable(inlet_intensity, inlet_length_scale_m))
            }
        }
    }
}

fn inlet_intensity() -> f64 {
    0.05
}

impl Validate for TurbulenceSpec {
    fn validate(&self, c: &mut Checker) {
        if let TurbulenceSpec::KEpsilon { inlet_intensity, inlet_length_scale_m }
        | TurbulenceSpec::RealizableKEpsilon { inlet_intensity, inlet_length_scale_m } = self
        {
            c.in_range("inlet_intensity", *inlet_intensity, 0.0, false, 1.0, true);
            c.positive("inlet_length_scale_m", *inlet_length_scale_m);
        }
    }
}

/// Time stepping and the pressure solver.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NumericsSpec {
    /// Face interpolation of the convected velocity: `van_leer`, `upwind` or `central`.
    #[serde(default)]
    pub convection: Convection,
    /// Courant number the adaptive step aims at.
    #[serde(default = "half")]
    pub courant: f64,
    /// Largest step \[s\]; default: no limit beyond stability.
    #[serde(default)]
    pub dt_max_s: Option<f64>,
    /// A fixed step \[s\] instead of the adaptive one.
    #[serde(default)]
    pub dt_s: Option<f64>,
    /// A step whose Courant number exceeds this stops the run as unstable, naming the cell.
    #[serde(default = "one")]
    pub max_courant: f64,
    /// Relative residual of the pressure solve.
    #[serde(default = "pressure_tol")]
    pub pressure_tolerance: f64,
    #[serde(default = "pressure_iter")]
    pub pressure_max_iterations: usize,
}

fn half() -> f64 {
    0.5
}

fn pressure_tol() -> f64 {
    1e-8
}

fn pressure_iter() -> usize {
    200
}

impl Default for NumericsSpec {
    fn default() -> Self {
        NumericsSpec {
            convection: Convection::VanLeer,
            courant: half(),
            dt_max_s: None,
            dt_s: None,
            max_courant: 1.0,
            pressure_tolerance: pressure_tol(),
            pressure_max_iterations: pressure_iter(),
        }
    }
}

impl Validate for NumericsSpec {
    fn validate(&self, c: &mut Checker) {
        c.in_range("courant", self.courant, 0.0, false, 1.0, true);
        if let Some(v) = self.dt_max_s {
            c.positive("dt_max_s", v);
        }
        if let Some(v) = self.dt_s {
            c.positive("dt_s", v);
        }
        c.positive("max_courant", self.max_courant);
        c.in_range("pressure_tolerance", self.pressure_tolerance, 0.0, false, 1.0, false);
        if self.pressure_max_iterations == 0 {
            c.fail("pressure_max_iterations", "must be at least 1");
        }
    }
}

/// How long to run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeSpec {
    pub end_time_s: f64,
    /// Stop early once the largest rate of change of any velocity, measured over one sample interval,
    /// falls below this \[m/s²\]; default: run to `end_time_s`.
    #[serde(default)]
    pub steady_rate_m_s2: Option<f64>,
    /// Stop after this many steps even before `end_time_s` (a run cut short on purpose, e.g. a quick look
    /// or `--smoke`); default: no limit.
    #[serde(default)]
    pub max_steps: Option<u64>,
}

impl Validate for TimeSpec {
    fn validate(&self, c: &mut Checker) {
        c.positive("end_time_s", self.end_time_s);
        if let Some(v) = self.steady_rate_m_s2 {
            c.positive("steady_rate_m_s2", v);
        }
        if self.max_steps == Some(0) {
            c.fail("max_steps", "must be at least 1 (leave it out to run to end_time_s)");
        }
    }
}

/// A point where velocity and pressure are recorded.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    pub name: String,
    pub at_m: [f64; 3],
}

/// The axis normal to the picture's cut.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CutNormal {
    X,
    Y,
    Z,
}

/// The planar cut drawn in `speed.png`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SliceSpec {
    pub normal: CutNormal,
    pub at_m: f64,
}

/// What is written and how often.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Interval of the `.vtr` field snapshots \[s\]; default: a tenth of the end time.
    #[serde(default)]
    pub field_interval_s: Option<f64>,
    /// Interval of the `series.csv` and `probes.csv` rows \[s\]; default: end time / 200.
    #[serde(default)]
    pub sample_interval_s: Option<f64>,
    #[serde(default)]
    pub probes: Vec<ProbeSpec>,
    /// The cut of `speed.png`; default: normal to z through the middle of the grid.
    #[serde(default)]
    pub slice: Option<SliceSpec>,
    /// Compare the centrelines with Ghia, Ghia & Shin (1982) at this Reynolds number (100 or 1000): the
    /// grid's x–y box is taken as the unit cavity and velocities are divided by the fastest wall speed.
    #[serde(default)]
    pub ghia_re: Option<u32>,
}

impl OutputSpec {
    pub fn field_interval(&self, end: f64) -> f64 {
        self.field_interval_s.unwrap_or(end / 10.0)
    }

    pub fn sample_interval(&self, end: f64) -> f64 {
        self.sample_interval_s.unwrap_or(end / 200.0)
    }
}

impl Validate for OutputSpec {
    fn validate(&self, c: &mut Checker) {
        if let Some(v) = self.field_interval_s {
            c.positive("field_interval_s", v);
        }
        if let Some(v) = self.sample_interval_s {
            c.positive("sample_interval_s", v);
        }
        for (i, p) in self.probes.iter().enumerate() {
            c.element("probes", i, |c| {
                if p.name.is_empty() || p.name.contains([',', '"', '\n']) {
                    c.fail("name", "give a name without commas or quotes (it becomes a CSV column)");
                }
                c.finite_vec("at_m", p.at_m.into());
            });
        }
        for (i, p) in self.probes.iter().enumerate() {
            if self.probes[..i].iter().any(|q| q.name == p.name) {
                c.element("probes", i, |c| {
                    c.fail("name", format!("`{}` is used by an earlier probe", p.name))
                });
            }
        }
        if let Some(s) = &self.slice {
            c.nested("slice", |c| c.finite("at_m", s.at_m));
        }
        if let Some(re) = self.ghia_re {
            if re != 100 && re != 1000 {
                c.fail("ghia_re", format!("= {re}: Ghia's tables used here are for Re = 100 and 1000"));
            }
        }
    }
}

impl Validate for FlowConfig {
    fn validate(&self, c: &mut Checker) {
        c.nested("fluid", |c| {
            c.positive("density_kg_m3", self.fluid.density_kg_m3);
            c.positive("kinematic_viscosity_m2_s", self.fluid.kinematic_viscosity_m2_s);
        });
        c.item("grid", &self.grid);
        c.item("boundaries", &self.boundaries);
        for (i, s) in self.solids.iter().enumerate() {
            c.element("solids", i, |c| s.validate(c));
        }
        let (r_max, (z_lo, z_hi)) = (self.grid.x.max_m, (self.grid.y.min_m, self.grid.y.max_m));
        for (i, d) in self.actuator_disks.iter().enumerate() {
            c.element("actuator_disks", i, |c| {
                d.validate(c);
                if d.radius_m > r_max {
                    c.fail(
                        "radius_m",
                        format!(
                            "= {} m reaches beyond the grid's radius grid.x.max_m = {r_max} m",
                            d.radius_m
                        ),
                    );
                }
                if !(d.axial_m > z_lo && d.axial_m < z_hi) {
                    c.fail(
                        "axial_m",
                        format!(
                            "= {} m lies outside the grid's axial extent ({z_lo} m, {z_hi} m) (grid.y)",
                            d.axial_m
                        ),
                    );
                }
            });
        }
        if !self.actuator_disks.is_empty() && self.grid.mode != Mode::Axisymmetric {
            c.fail(
                "actuator_disks",
                "actuator disks need grid.mode = \"axisymmetric\" (the disk sits on the axis)",
            );
        }
        c.item("turbulence", &self.turbulence);
        c.item("numerics", &self.numerics);
        c.item("time", &self.time);
        c.item("output", &self.output);
    }
}

impl spatter_io::run::Smoke for FlowConfig {
    /// At most 30 steps; every output (fields at the start and the end, series, probes, pictures) is
    /// still written.
    fn smoke(&mut self) {
        self.time.max_steps = Some(self.time.max_steps.map_or(30, |n| n.min(30)));
    }
}
