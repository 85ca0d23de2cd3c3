//! Analytic flow fields. A scenario lists one or more; their velocities add up.
//!
//! Vortices use the convention of Jasion (2013) eq. 6.14: the
//! core radius r_c is the radius of peak swirl, so the Lamb–Oseen vortex reads
//! V_θ(r) = Γ/(2π r) · (1 − exp(−α r²/r_c²)) with α = 1.25643 (peak 0.7153 Γ/(2π r_c) at r = r_c).

use super::{fd_gradient, rotor::RotorDownwash, wall_jet::WallJet, FlowField, Sample};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::math::orthonormal_basis;
use spatter_core::{Aabb, Mat3, Vec3};
use std::f64::consts::PI;

/// α of the Lamb–Oseen vortex with r_c = radius of peak swirl (root of 1 + 2α = e^α).
pub const LAMB_OSEEN_ALPHA: f64 = 1.25643;

/// One analytic flow.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum AnalyticField {
    /// u = U everywhere.
    Uniform {
        #[serde(rename = "velocity_m_s")]
        velocity: Vec3,
    },
    /// Stagnation-point flow onto the plane through `centre_m` with unit normal `normal`:
    /// planar u = a (x₁ t₁ − z n), axisymmetric u = a (x₁ t₁ + x₂ t₂ − 2 z n), with (x₁, x₂, z) the
    /// coordinates of x − centre in the basis (t₁, t₂, n) (Hiemenz / Homann inviscid outer flows).
    StagnationPoint {
        #[serde(rename = "strain_rate_1_s")]
        strain_rate: f64,
        #[serde(rename = "centre_m", default)]
        centre: Vec3,
        #[serde(default = "z_axis")]
        normal: Vec3,
        #[serde(default)]
        axisymmetric: bool,
    },
    /// Lamb–Oseen vortex about the line through `centre_m` along `axis` (right-handed circulation Γ).
    /// With `viscosity_m2_s` = ν > 0 the core grows viscously, r_c(t)² = r_c0² + 4αν t in the
    /// peak-radius convention (Lamb 1932, the Gaussian core's 4νt scaled by α).
    LambOseen {
        #[serde(rename = "circulation_m2_s")]
        circulation: f64,
        #[serde(rename = "core_radius_m")]
        core_radius: f64,
        #[serde(rename = "centre_m", default)]
        centre: Vec3,
        #[serde(default = "z_axis")]
        axis: Vec3,
        #[serde(rename = "viscosity_m2_s", default)]
        nu: f64,
    },
    /// Rankine vortex: solid-body rotation inside `core_radius_m`, potential vortex outside.
    Rankine {
        #[serde(rename = "circulation_m2_s")]
        circulation: f64,
        #[serde(rename = "core_radius_m")]
        core_radius: f64,
        #[serde(rename = "centre_m", default)]
        centre: Vec3,
        #[serde(default = "z_axis")]
        axis: Vec3,
    },
    /// A radial or planar wall jet (see [`WallJet`]).
    WallJet(WallJet),
    /// The helicopter rotor downwash model (see [`RotorDownwash`]).
    Rotor(RotorDownwash),
}

fn z_axis() -> Vec3 {
    Vec3::Z
}

impl Validate for AnalyticField {
    fn validate(&self, c: &mut Checker) {
        let unit = |c: &mut Checker, key: &str, v: Vec3| {
            c.finite_vec(key, v);
            if v.length() < 1e-12 {
                c.fail(key, format!("{key} = [{}, {}, {}] must be a non-zero direction", v.x, v.y, v.z));
            }
        };
        match self {
            AnalyticField::Uniform { velocity } => c.finite_vec("velocity_m_s", *velocity),
            AnalyticField::StagnationPoint { strain_rate, centre, normal, .. } => {
                c.finite("strain_rate_1_s", *strain_rate);
                c.finite_vec("centre_m", *centre);
                unit(c, "normal", *normal);
            }
            AnalyticField::LambOseen { circulation, core_radius, centre, axis, nu } => {
                c.finite("circulation_m2_s", *circulation);
                c.positive("core_radius_m", *core_radius);
                c.finite_vec("centre_m", *centre);
                unit(c, "axis", *axis);
                c.non_negative("viscosity_m2_s", *nu);
            }
            AnalyticField::Rankine { circulation, core_radius, centre, axis } => {
                c.finite("circulation_m2_s", *circulation);
                c.positive("core_radius_m", *core_radius);
                c.finite_vec("centre_m", *centre);
                unit(c, "axis", *axis);
            }
            AnalyticField::WallJet(w) => w.validate(c),
            AnalyticField::Rotor(r) => r.validate(c),
        }
    }
}

/// Swirl speed of a Lamb–Oseen vortex at distance `r` (peak-radius convention) \[m/s\].
#[inline]
pub fn lamb_oseen_swirl(circulation: f64, core_radius: f64, r: f64) -> f64 {
    if r <= 0.0 {
        return 0.0;
    }
    let s = r / core_radius;
    circulation / (2.0 * PI * r) * (1.0 - (-LAMB_OSEEN_ALPHA * s * s).exp())
}

/// Swirl speed of a Rankine vortex \[m/s\].
#[inline]
pub fn rankine_swirl(circulation: f64, core_radius: f64, r: f64) -> f64 {
    if r < core_radius {
        circulation * r / (2.0 * PI * core_radius * core_radius)
    } else {
        circulation / (2.0 * PI * r)
    }
}

/// Velocity of a line vortex with swirl law `v(r)` about the line (centre, axis).
fn vortex_velocity(x: Vec3, centre: Vec3, axis: Vec3, v: impl Fn(f64) -> f64) -> Vec3 {
    let a = axis.normalize();
    let d = x - centre;
    let radial = d - d.dot(a) * a;
    let r = radial.length();
    if r <= 0.0 {
        return Vec3::ZERO;
    }
    v(r) / r * a.cross(radial)
}

impl AnalyticField {
    /// Velocity at `x`, time `t` \[m/s\].
    pub fn velocity(&self, x: Vec3, t: f64) -> Vec3 {
        match self {
            AnalyticField::Uniform { velocity } => *velocity,
            AnalyticField::StagnationPoint { strain_rate, centre, normal, axisymmetric } => {
                let n = normal.normalize();
                let (t1, t2) = orthonormal_basis(n);
                let d = x - *centre;
                let (x1, x2, z) = (d.dot(t1), d.dot(t2), d.dot(n));
                if *axisymmetric {
                    *strain_rate * (x1 * t1 + x2 * t2 - 2.0 * z * n)
                } else {
                    *strain_rate * (x1 * t1 - z * n)
                }
            }
            AnalyticField::LambOseen { circulation, core_radius, centre, axis, nu } => {
                let rc = (core_radius * core_radius + 4.0 * LAMB_OSEEN_ALPHA * nu * t.max(0.0)).sqrt();
                vortex_velocity(x, *centre, *axis, |r| lamb_oseen_swirl(*circulation, rc, r))
            }
            AnalyticField::Rankine { circulation, core_radius, centre, axis } => {
                vortex_velocity(x, *centre, *axis, |r| rankine_swirl(*circulation, *core_radius, r))
            }
            AnalyticField::WallJet(w) => w.velocity(x),
            AnalyticField::Rotor(r) => r.velocity(x, t),
        }
    }

    /// A length over which the field varies (step of finite-difference gradients).
    fn length_scale(&self) -> f64 {
        match self {
            AnalyticField::Uniform { .. } | AnalyticField::StagnationPoint { .. } => 1.0,
            AnalyticField::LambOseen { core_radius, .. } | AnalyticField::Rankine { core_radius, .. } => {
                *core_radius
            }
            AnalyticField::WallJet(w) => w.thickness_m,
            AnalyticField::Rotor(r) => r.radius_m * 0.01,
        }
    }

    /// Velocity gradient (column j = ∂u/∂x_j).
    pub fn gradient(&self, x: Vec3, t: f64) -> Mat3 {
        match self {
            AnalyticField::Uniform { .. } => Mat3::ZERO,
            _ => fd_gradient(|p| self.velocity(p, t), x, 1e-5 * self.length_scale()),
        }
    }

    /// ∂u/∂t (non-zero for the growing Lamb–Oseen core and the rotor's vortex rings).
    pub fn time_derivative(&self, x: Vec3, t: f64) -> Vec3 {
        match self {
            AnalyticField::LambOseen { nu, .. } if *nu > 0.0 => {
                let h = 1e-6 * (1.0 + t.abs());
                (self.velocity(x, t + h) - self.velocity(x, (t - h).max(0.0))) / (t + h - (t - h).max(0.0))
            }
            AnalyticField::Rotor(r) if r.tip_vortices => {
                let h = 1e-4 / r.omega_rad_s.max(1e-9);
                (self.velocity(x, t + h) - self.velocity(x, t - h)) / (2.0 * h)
            }
            _ => Vec3::ZERO,
        }
    }
}

/// Constant turbulence properties for analytic fields (drives the random walk).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantTurbulence {
    #[serde(rename = "k_m2_s2")]
    pub k: f64,
    #[serde(rename = "epsilon_m2_s3")]
    pub epsilon: f64,
}

/// A sum of analytic fields with optional constant turbulence.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AnalyticSet {
    pub parts: Vec<AnalyticField>,
    pub turbulence: Option<ConstantTurbulence>,
}

impl AnalyticSet {
    pub fn velocity(&self, x: Vec3, t: f64) -> Vec3 {
        self.parts.iter().map(|p| p.velocity(x, t)).sum()
    }
}

impl FlowField for AnalyticSet {
    #[inline]
    fn sample(&self, x: Vec3, t: f64, _hint: &mut u32, want_grad: bool) -> Option<Sample> {
        let mut s = Sample { u: self.velocity(x, t), ..Default::default() };
        if want_grad {
            for p in &self.parts {
                s.grad += p.gradient(x, t);
                s.du_dt += p.time_derivative(x, t);
            }
        }
        if let Some(tb) = self.turbulence {
            s.k = tb.k;
            s.eps = tb.epsilon;
        }
        Some(s)
    }

    fn bounds(&self) -> Option<Aabb> {
        None
    }

    fn has_turbulence(&self) -> bool {
        self.turbulence.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn divergence(f: &AnalyticField, x: Vec3) -> f64 {
        let g = f.gradient(x, 0.0);
        g.x_axis.x + g.y_axis.y + g.z_axis.z
    }

    #[test]
    fn lamb_oseen_peak_and_far_field() {
        // Peak at r = r_c: 0.7153 Γ/(2π r_c) (derived from the profile of Jasion (2013) eq. 6.14).
        let (g, rc) = (6.48, 0.17);
        let peak = lamb_oseen_swirl(g, rc, rc);
        assert!((peak / (g / (2.0 * PI * rc)) - 0.71533).abs() < 1e-5);
        // Maximum really is at r_c.
        assert!(lamb_oseen_swirl(g, rc, 0.99 * rc) < peak && lamb_oseen_swirl(g, rc, 1.01 * rc) < peak);
        // Potential vortex far away.
        assert!((lamb_oseen_swirl(g, rc, 10.0 * rc) - g / (2.0 * PI * 10.0 * rc)).abs() < 1e-12);
        // Direction: right-handed about +z.
        let f = AnalyticField::LambOseen {
            circulation: 1.0,
            core_radius: 0.1,
            centre: Vec3::ZERO,
            axis: Vec3::Z,
            nu: 0.0,
        };
        let v = f.velocity(Vec3::new(0.2, 0.0, 3.0), 0.0);
        assert!(v.y > 0.0 && v.x.abs() < 1e-15 && v.z == 0.0);
        assert!(divergence(&f, Vec3::new(0.05, 0.07, 0.0)).abs() < 1e-6);
        // Vorticity on the axis: ω = Γ α/(π r_c²).
        let g = f.gradient(Vec3::new(1e-9, 0.0, 0.0), 0.0);
        let om = crate::forces::model::vorticity(&g).z;
        assert!((om / (LAMB_OSEEN_ALPHA / (PI * 0.01)) - 1.0).abs() < 1e-6, "{om}");
    }

    #[test]
    fn rankine_and_stagnation() {
        let f = AnalyticField::Rankine {
            circulation: 2.0 * PI,
            core_radius: 1.0,
            centre: Vec3::ZERO,
            axis: Vec3::Z,
        };
        // Γ = 2π, R = 1: v = r inside, 1/r outside.
        assert!((f.velocity(Vec3::new(0.5, 0.0, 0.0), 0.0) - Vec3::new(0.0, 0.5, 0.0)).length() < 1e-15);
        assert!((f.velocity(Vec3::new(0.0, 2.0, 0.0), 0.0) - Vec3::new(-0.5, 0.0, 0.0)).length() < 1e-15);
        let s = AnalyticField::StagnationPoint {
            strain_rate: 2.0,
            centre: Vec3::ZERO,
            normal: Vec3::Z,
            axisymmetric: true,
        };
        let u = s.velocity(Vec3::new(1.0, 1.0, 0.5), 0.0);
        assert!((u.z + 2.0).abs() < 1e-14 && (u.x.hypot(u.y) - 2.0 * 2f64.sqrt()).abs() < 1e-14);
        assert!(divergence(&s, Vec3::new(0.3, -0.2, 0.7)).abs() < 1e-9);
        let s = AnalyticField::StagnationPoint {
            strain_rate: 2.0,
            centre: Vec3::ZERO,
            normal: Vec3::Z,
            axisymmetric: false,
        };
        assert!(divergence(&s, Vec3::new(0.3, -0.2, 0.7)).abs() < 1e-9);
        assert_eq!(s.velocity(Vec3::new(0.0, 0.0, 1.0), 0.0), Vec3::new(0.0, 0.0, -2.0));
    }
}
