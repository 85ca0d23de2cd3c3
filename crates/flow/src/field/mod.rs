//! Flow fields the particles move in.
//!
//! * [`analytic`] — uniform flow, stagnation-point flow, Lamb–Oseen and Rankine vortices, wall jets and
//!   the rotor downwash model of [`rotor`], summed;
//! * [`imported`] — CFD results read from VTK files, located and interpolated on a conforming
//!   tetrahedral decomposition ([`tetmesh`], [`decompose`]);
//! * [`scaled`] — a model-scale rotor flow carried to full scale by R and v_ind;
//! * [`dispersion`] — turbulent dispersion by a discrete random walk driven by k and ε.
//!
//! Every field implements [`FlowField`]: the velocity at a point and time, optionally its gradient,
//! and k, ε where known.

pub mod analytic;
pub mod decompose;
pub mod dispersion;
pub mod imported;
pub mod rotor;
pub mod scaled;
pub use spatter_core::special;
pub mod tetmesh;
pub mod wall_jet;

use spatter_core::{Aabb, Mat3, Vec3};
use std::path::PathBuf;
use thiserror::Error;

pub use analytic::{AnalyticField, AnalyticSet};
pub use imported::{ImportOptions, ImportedField, Interpolation};

/// The fluid at one point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Velocity \[m/s\].
    pub u: Vec3,
    /// Velocity gradient, column j = ∂u/∂x_j \[1/s\] (only filled when asked for).
    pub grad: Mat3,
    /// Local time derivative ∂u/∂t \[m/s²\].
    pub du_dt: Vec3,
    /// Turbulent kinetic energy k \[m²/s²\] (0 when unknown).
    pub k: f64,
    /// Dissipation rate ε \[m²/s³\] (0 when unknown).
    pub eps: f64,
}

impl Default for Sample {
    /// Fluid at rest, zero gradient (note `Mat3::default()` would be the identity).
    fn default() -> Self {
        Sample { u: Vec3::ZERO, grad: Mat3::ZERO, du_dt: Vec3::ZERO, k: 0.0, eps: 0.0 }
    }
}

/// A velocity field.
pub trait FlowField: Send + Sync {
    /// The fluid at `x` and time `t`, or `None` when `x` lies outside the field's domain. `hint` is the
    /// caller's location cache (one per particle, start with [`tetmesh::NONE`]); analytic fields
    /// ignore it. The gradient is computed only when `want_grad`.
    fn sample(&self, x: Vec3, t: f64, hint: &mut u32, want_grad: bool) -> Option<Sample>;

    /// Bounding box of the domain, `None` when unbounded.
    fn bounds(&self) -> Option<Aabb>;

    /// Whether k and ε are available.
    fn has_turbulence(&self) -> bool;

    /// Number of distinct location-hint values (cells), 0 for analytic fields.
    fn tet_hint_count(&self) -> usize {
        0
    }
}

/// A borrowed field is a field (e.g. a tracker over a field shared with other code).
impl<T: FlowField> FlowField for &T {
    #[inline]
    fn sample(&self, x: Vec3, t: f64, hint: &mut u32, want_grad: bool) -> Option<Sample> {
        (**self).sample(x, t, hint, want_grad)
    }
    fn bounds(&self) -> Option<Aabb> {
        (**self).bounds()
    }
    fn has_turbulence(&self) -> bool {
        (**self).has_turbulence()
    }
    fn tet_hint_count(&self) -> usize {
        (**self).tet_hint_count()
    }
}

/// Why a flow field could not be built.
#[derive(Debug, Error)]
pub enum FieldError {
    #[error(transparent)]
    Vtk(#[from] spatter_io::vtk::VtkError),
    #[error("flow field {path}: {message}")]
    Data { path: PathBuf, message: String },
    #[error("flow field: {0}")]
    Config(String),
}

/// Any field the tracker can use (static dispatch through a match).
#[derive(Clone, Debug)]
pub enum Field {
    Analytic(AnalyticSet),
    Imported(Box<ImportedField>),
}

impl FlowField for Field {
    #[inline]
    fn sample(&self, x: Vec3, t: f64, hint: &mut u32, want_grad: bool) -> Option<Sample> {
        match self {
            Field::Analytic(a) => a.sample(x, t, hint, want_grad),
            Field::Imported(f) => f.sample(x, t, hint, want_grad),
        }
    }

    fn bounds(&self) -> Option<Aabb> {
        match self {
            Field::Analytic(a) => a.bounds(),
            Field::Imported(f) => f.bounds(),
        }
    }

    fn has_turbulence(&self) -> bool {
        match self {
            Field::Analytic(a) => a.has_turbulence(),
            Field::Imported(f) => f.has_turbulence(),
        }
    }

    fn tet_hint_count(&self) -> usize {
        match self {
            Field::Analytic(_) => 0,
            Field::Imported(f) => f.tet_hint_count(),
        }
    }
}

/// Central-difference gradient of `f` at `x` with step `h` (column j = ∂u/∂x_j); error O(h²).
pub fn fd_gradient(f: impl Fn(Vec3) -> Vec3, x: Vec3, h: f64) -> Mat3 {
    let d = |e: Vec3| (f(x + h * e) - f(x - h * e)) / (2.0 * h);
    Mat3::from_cols(d(Vec3::X), d(Vec3::Y), d(Vec3::Z))
}
