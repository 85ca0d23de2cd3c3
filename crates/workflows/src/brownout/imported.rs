//! A rotor flow imported from VTK files (`flow = { kind = "imported", … }`): a steady field or a time
//! series from another CFD code or an experiment, at full scale or at model scale. A model-scale field is
//! carried to the scenario's rotor by the similarity scaling of Jasion (2013, Table 5.2): C_T held
//! constant, lengths scaled with the rotor radius R, velocities with the induced velocity
//! v_ind = √(T/(2ρA)) and times with R/v_ind ([`spatter_flow::field::scaled`]).
//!
//! The field's frame: the rotor axis is the z axis through the origin and the ground the plane z = 0 (after
//! `length_scale`), as in the rest of the workflow.

use super::config::BrownoutConfig;
use crate::deposition::config::{vtk_file, vtk_series};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_flow::field::imported::{ArrayNames, ImportOptions, ImportedField, Interpolation};
use spatter_flow::field::rotor::induced_velocity;
use spatter_flow::field::scaled::{RotorScaling, ScaledField};
use spatter_flow::field::FlowField;
use std::path::PathBuf;

/// An imported rotor flow: one of `vtk` or `series`, how to read it, and its scale.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImportedFlowConfig {
    /// One VTK file (a steady field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vtk: Option<PathBuf>,
    /// A `.pvd` or `.series` file listing a time series (one mesh).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub series: Option<PathBuf>,
    #[serde(default)]
    pub interpolation: Interpolation,
    #[serde(default)]
    pub arrays: ArrayNames,
    /// Multiplies the file's coordinates (1e-3 for millimetres), before any model scaling.
    #[serde(default = "one")]
    pub length_scale: f64,
    /// Period of a cyclic time series in the file's time \[s\] (e.g. one revolution of the model rotor).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period_s: Option<f64>,
    /// The field is at model scale: carry it to the scenario's rotor by R and v_ind.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<ModelScale>,
}

fn one() -> f64 {
    1.0
}

/// The model rotor a field was computed for.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelScale {
    /// Radius of the model rotor \[m\] (in the file's lengths times `length_scale`).
    pub model_radius_m: f64,
    /// Induced velocity of the model rotor \[m/s\] (give this or `model_thrust_n`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_v_ind_m_s: Option<f64>,
    /// Thrust of the model rotor \[N\]; its induced velocity is √(T/(2ρA)) with ρ = `air.density_kg_m3`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_thrust_n: Option<f64>,
}

impl ModelScale {
    /// The model's induced velocity \[m/s\] (momentum theory from the thrust where that is given).
    pub fn model_v_ind(&self, rho: f64) -> f64 {
        match (self.model_v_ind_m_s, self.model_thrust_n) {
            (Some(v), _) => v,
            (None, Some(t)) => induced_velocity(t, rho, self.model_radius_m),
            (None, None) => f64::NAN,
        }
    }
}

impl Validate for ModelScale {
    fn validate(&self, c: &mut Checker) {
        if !(self.model_radius_m.is_finite() && self.model_radius_m > 0.0) {
            c.fail(
                "model_radius_m",
                format!(
                    "model_radius_m = {} must be the model rotor's radius, a positive length in metres",
                    self.model_radius_m
                ),
            );
        }
        match (self.model_v_ind_m_s, self.model_thrust_n) {
            (Some(_), Some(_)) => c.fail("model_v_ind_m_s", "give model_v_ind_m_s or model_thrust_n, not both"),
            (None, None) => c.fail(
                "model_v_ind_m_s",
                "give the model rotor's induced velocity model_v_ind_m_s [m/s] or its thrust model_thrust_n [N]",
            ),
            (Some(v), None) if !(v.is_finite() && v > 0.0) => c.fail(
                "model_v_ind_m_s",
                format!("model_v_ind_m_s = {v} must be the model rotor's induced velocity, a positive speed in m/s"),
            ),
            (None, Some(t)) if !(t.is_finite() && t > 0.0) => c.fail(
                "model_thrust_n",
                format!("model_thrust_n = {t} must be the model rotor's thrust, a positive force in newtons"),
            ),
            _ => {}
        }
    }
}

impl Validate for ImportedFlowConfig {
    fn validate(&self, c: &mut Checker) {
        match (&self.vtk, &self.series) {
            (Some(_), Some(_)) => c.fail("vtk", "give vtk (one file) or series (a time series), not both"),
            (None, None) => {
                c.fail("vtk", "give the field: vtk = \"file.vtu\" (steady) or series = \"file.pvd\"")
            }
            (Some(p), None) => vtk_file(c, "vtk", p),
            (None, Some(p)) => vtk_series(c, "series", p),
        }
        c.positive("length_scale", self.length_scale);
        if let Some(p) = self.period_s {
            c.positive("period_s", p);
        }
        if let Some(s) = &self.scale {
            c.item("scale", s);
        }
    }
}

/// The imported field at the scenario's scale, with the time window an unsteady one is sampled over.
pub struct Loaded {
    pub field: ScaledField<ImportedField>,
    /// Full-scale start time and length of the unsteady window \[s\] (the period of a cyclic series,
    /// else its span; 0 for a steady field).
    pub window: (f64, f64),
    pub frames: usize,
}

/// Reads the files of `ic` and scales them to `cfg`'s rotor.
pub fn load(cfg: &BrownoutConfig, ic: &ImportedFlowConfig) -> Result<Loaded, String> {
    let files: Vec<(f64, PathBuf)> = match (&ic.vtk, &ic.series) {
        (Some(v), _) => vec![(0.0, v.clone())],
        (None, Some(s)) => spatter_io::vtk::series::read_series(s).map_err(|e| e.to_string())?,
        (None, None) => return Err("no field file given (vtk or series)".into()),
    };
    let opts = ImportOptions {
        interpolation: ic.interpolation,
        names: ic.arrays.clone(),
        length_scale: ic.length_scale,
        period: ic.period_s,
    };
    let inner = ImportedField::load(&files, &opts).map_err(|e| e.to_string())?;
    let scaling = match &ic.scale {
        None => RotorScaling::IDENTITY,
        Some(s) => {
            let rho = cfg.air.density;
            let full_v = induced_velocity(cfg.rotor.thrust(rho), rho, cfg.rotor.radius_m);
            RotorScaling::between((s.model_radius_m, s.model_v_ind(rho)), (cfg.rotor.radius_m, full_v))
        }
    };
    let times = inner.times();
    let t0 = times.first().copied().unwrap_or(0.0);
    let span = match inner.period {
        Some(p) => p,
        None => times.last().copied().unwrap_or(0.0) - t0,
    };
    let frames = inner.n_frames();
    let ts = scaling.time();
    Ok(Loaded { field: ScaledField { inner, scaling }, window: (t0 * ts, span * ts), frames })
}

/// A field's velocity averaged over `times` (the mean flow of an unsteady field for the lift-off map).
pub struct TimeMean<'a, F> {
    pub inner: &'a F,
    pub times: Vec<f64>,
}

impl<F: FlowField> FlowField for TimeMean<'_, F> {
    fn sample(
        &self,
        x: spatter_core::Vec3,
        _t: f64,
        hint: &mut u32,
        want_grad: bool,
    ) -> Option<spatter_flow::field::Sample> {
        let n = self.times.len().max(1) as f64;
        let mut acc = spatter_flow::field::Sample::default();
        for &t in &self.times {
            let s = self.inner.sample(x, t, hint, want_grad)?;
            acc.u += s.u / n;
            acc.grad += s.grad * (1.0 / n);
            acc.k += s.k / n;
            acc.eps += s.eps / n;
        }
        Some(acc)
    }

    fn bounds(&self) -> Option<spatter_core::Aabb> {
        self.inner.bounds()
    }

    fn has_turbulence(&self) -> bool {
        self.inner.has_turbulence()
    }

    fn tet_hint_count(&self) -> usize {
        self.inner.tet_hint_count()
    }
}
