//! Wall shear stress along the ground under any flow field.
//!
//! A field that resolves the viscous sublayer gives τ_w = μ ∂u/∂n directly; the analytic rotor and most
//! imported RANS fields do not (the rotor's wall jet is an inviscid profile that vanishes at the ground).
//! Here the wall shear comes from a wall function: the speed parallel to the ground at a height y is put
//! into the smooth-wall law of the wall ([`super::wall_law`]) and solved for u_*:
//!
//! * [`ShearMethod::JetPeak`] (default) uses the local maximum of the ground-parallel speed between the
//!   ground and `max_height_m` — the velocity maximum of the wall jet — and its height. The log law is
//!   the inner layer of a turbulent wall jet up to about its maximum; for the Bell 47 wall jet
//!   (U_m ≈ 6–9 m/s at y_m ≈ 0.8 m) it gives c_f = τ_w/(½ρU_m²) ≈ 2.5 × 10⁻³, the order of the skin
//!   friction of turbulent wall jets at these Reynolds numbers (a few 10⁻³; review of Launder & Rodi
//!   1981);
//! * [`ShearMethod::FixedHeight`] uses the speed at a given height (a first cell centre, or the 0.1 m of
//!   Leese's 1964 full-scale measurements).
//!
//! Speeds may be multiplied by a gust factor (the thesis evaluates forces at the peak velocity
//! mean + 2u′, with u′ = 10–20 % of the mean in its RANS field: factor 1.2–1.4).

use super::shields::{fraction_above, shields_parameter};
use super::wall_law::{friction_velocity_from_speed, wall_shear_stress};
use crate::field::FlowField;
use crate::forces::Fluid;
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;

/// How the wall shear is estimated from the field.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum ShearMethod {
    /// Log law at the speed maximum below `max_height_m`, searched on `samples` heights (geometric from
    /// 1 mm).
    JetPeak {
        #[serde(rename = "max_height_m")]
        max_height: f64,
        #[serde(default = "default_samples")]
        samples: usize,
    },
    /// Log law at the speed at `height_m`.
    FixedHeight {
        #[serde(rename = "height_m")]
        height: f64,
    },
}

fn default_samples() -> usize {
    96
}

impl Validate for ShearMethod {
    fn validate(&self, c: &mut Checker) {
        match self {
            ShearMethod::JetPeak { max_height, samples } => {
                c.positive("max_height_m", *max_height);
                if *samples < 4 {
                    c.fail("samples", format!("samples = {samples} must be at least 4"));
                }
            }
            ShearMethod::FixedHeight { height } => c.positive("height_m", *height),
        }
    }
}

/// The ground under one point.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GroundShear {
    /// Distance along the ground from the origin \[m\].
    pub distance: f64,
    /// Speed parallel to the ground used by the wall function \[m/s\] (gust factor included) and its
    /// height \[m\].
    pub speed: f64,
    pub height: f64,
    /// Friction velocity \[m/s\] and wall shear stress \[Pa\].
    pub u_star: f64,
    pub tau_w: f64,
}

/// Ground-parallel speed of `field` at `x` (ground normal +z), or 0 outside the field.
fn parallel_speed<F: FlowField>(field: &F, x: Vec3, t: f64) -> f64 {
    let mut hint = crate::field::tetmesh::NONE;
    field.sample(x, t, &mut hint, false).map(|s| s.u.x.hypot(s.u.y)).unwrap_or(0.0)
}

/// Where and how the ground shear is sampled: the ground points `origin + distance·direction` (ground
/// plane through `origin`, normal +z), the wall function, and a gust factor on the speeds.
#[derive(Clone, Debug, PartialEq)]
pub struct GroundProbe {
    pub origin: Vec3,
    pub direction: Vec3,
    /// Distances along the ground \[m\].
    pub distances: Vec<f64>,
    pub method: ShearMethod,
    /// Factor on the sampled speeds (1 = the field as it is).
    pub gust: f64,
}

/// Wall shear of `field` at time `t` at the ground points of `probe`.
pub fn ground_shear<F: FlowField>(field: &F, probe: &GroundProbe, t: f64, fluid: &Fluid) -> Vec<GroundShear> {
    let direction = probe.direction;
    let dir = Vec3::new(direction.x, direction.y, 0.0).normalize_or_zero();
    let nu = fluid.nu();
    probe
        .distances
        .iter()
        .map(|&s| {
            let base = probe.origin + s * dir;
            let (speed, height) = match probe.method {
                ShearMethod::FixedHeight { height } => {
                    (parallel_speed(field, base + height * Vec3::Z, t), height)
                }
                ShearMethod::JetPeak { max_height, samples } => {
                    let lo: f64 = 1e-3_f64.min(0.5 * max_height);
                    let ratio = (max_height / lo).powf(1.0 / (samples - 1) as f64);
                    (0..samples)
                        .map(|k| {
                            let y = lo * ratio.powi(k as i32);
                            (parallel_speed(field, base + y * Vec3::Z, t), y)
                        })
                        .fold((0.0, lo), |best, v| if v.0 > best.0 { v } else { best })
                }
            };
            let speed = probe.gust * speed;
            let u_star = friction_velocity_from_speed(speed, height, nu);
            GroundShear {
                distance: s,
                speed,
                height,
                u_star,
                tau_w: wall_shear_stress(u_star, fluid.density),
            }
        })
        .collect()
}

/// Fraction of the times `times` at which the Shields parameter θ = τ_w/(ρ_p g D) of a grain of
/// diameter `d` and density `rho_p` exceeds `theta_c`, at each ground point of `probe`.
pub fn shields_exceedance<F: FlowField>(
    field: &F,
    probe: &GroundProbe,
    times: &[f64],
    fluid: &Fluid,
    (d, rho_p): (f64, f64),
    g: f64,
    theta_c: f64,
) -> Vec<f64> {
    let series: Vec<Vec<GroundShear>> = times.iter().map(|&t| ground_shear(field, probe, t, fluid)).collect();
    exceedance_table(&series, &[d], rho_p, g, theta_c).into_iter().map(|row| row[0].fraction).collect()
}

/// Shields statistics of one grain size at one ground point over a time series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Exceedance {
    /// Fraction of the samples with θ > θ* \[-\].
    pub fraction: f64,
    /// Mean and largest Shields parameter over the samples \[-\].
    pub mean: f64,
    pub max: f64,
}

/// Shields exceedance at every ground point (outer index) for every diameter of `diameters` (inner
/// index) from a time series of wall shear: `series[k]` is [`ground_shear`] at the k-th of equally
/// spaced times.
pub fn exceedance_table(
    series: &[Vec<GroundShear>],
    diameters: &[f64],
    rho_p: f64,
    g: f64,
    theta_c: f64,
) -> Vec<Vec<Exceedance>> {
    let points = series.first().map_or(0, Vec::len);
    let n = series.len().max(1) as f64;
    (0..points)
        .map(|i| {
            diameters
                .iter()
                .map(|&d| {
                    let theta: Vec<f64> =
                        series.iter().map(|s| shields_parameter(s[i].tau_w, rho_p, g, d)).collect();
                    Exceedance {
                        fraction: fraction_above(&theta, theta_c),
                        mean: theta.iter().sum::<f64>() / n,
                        max: theta.iter().copied().fold(0.0, f64::max),
                    }
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::Sample;
    use spatter_core::Aabb;

    /// A uniform flow along x whose speed pulses as U₀(1 + ½ sin 2πt) at every height.
    struct Pulsing(f64);

    impl FlowField for Pulsing {
        fn sample(&self, _x: Vec3, t: f64, _h: &mut u32, _g: bool) -> Option<Sample> {
            let u = self.0 * (1.0 + 0.5 * (std::f64::consts::TAU * t).sin());
            Some(Sample { u: Vec3::new(u, 0.0, 0.0), ..Default::default() })
        }
        fn bounds(&self) -> Option<Aabb> {
            None
        }
        fn has_turbulence(&self) -> bool {
            false
        }
    }

    #[test]
    fn fixed_height_shear_and_exceedance_of_a_pulsing_flow() {
        let fluid = Fluid { density: 1.19, viscosity: 1.82e-5 };
        let method = ShearMethod::FixedHeight { height: 0.1 };
        let f = Pulsing(5.0);
        let probe = |distances: Vec<f64>, gust: f64| GroundProbe {
            origin: Vec3::ZERO,
            direction: Vec3::X,
            distances,
            method,
            gust,
        };
        let g = ground_shear(&f, &probe(vec![1.0, 2.0], 1.0), 0.0, &fluid);
        let u_star = friction_velocity_from_speed(5.0, 0.1, fluid.nu());
        assert!((g[0].u_star - u_star).abs() < 1e-12 && (g[1].tau_w - 1.19 * u_star * u_star).abs() < 1e-12);
        // The threshold at the mean speed is exceeded while sin > 0: half the period (400 samples).
        let d = 300e-6;
        let theta0 = shields_parameter(1.19 * u_star * u_star, 2480.0, 9.81, d);
        let times: Vec<f64> = (0..400).map(|k| (k as f64 + 0.5) / 400.0).collect();
        let frac = shields_exceedance(&f, &probe(vec![1.0], 1.0), &times, &fluid, (d, 2480.0), 9.81, theta0);
        assert!((frac[0] - 0.5).abs() < 1e-12, "{frac:?}");
        // A gust factor of 1.5 lifts the whole cycle above it except where 1.5(1 + ½ sin) < 1.
        let frac = shields_exceedance(&f, &probe(vec![1.0], 1.5), &times, &fluid, (d, 2480.0), 9.81, theta0);
        // Below the threshold where 1 + ½ sin < 2/3, i.e. sin < −2/3: a fraction ½ − asin(2/3)/π.
        let below = 0.5 - (2.0f64 / 3.0).asin() / std::f64::consts::PI;
        assert!((frac[0] - (1.0 - below)).abs() < 3.0 / 400.0, "{} vs {}", frac[0], 1.0 - below);
    }

    #[test]
    fn exceedance_of_a_sinusoidal_friction_velocity_is_the_arccos_fraction() {
        // A flow whose speed at 0.1 m pulses as U(t) = U₀(1 + ½ sin 2πt): the friction velocity of the
        // wall function grows monotonically with U, so θ > θ* exactly while U > U*, the speed whose
        // wall-function u* gives θ*: while sin 2πt > s* = 2(U*/U₀ − 1), a fraction arccos(s*)/π of the
        // period (analytic). 2000 equally spaced samples: tolerance 1/2000 + rounding.
        let fluid = Fluid { density: 1.19, viscosity: 1.82e-5 };
        let probe = GroundProbe {
            origin: Vec3::ZERO,
            direction: Vec3::X,
            distances: vec![1.0, 2.0],
            method: ShearMethod::FixedHeight { height: 0.1 },
            gust: 1.0,
        };
        let f = Pulsing(6.0);
        let n = 2000;
        let series: Vec<Vec<GroundShear>> =
            (0..n).map(|k| ground_shear(&f, &probe, (k as f64 + 0.5) / n as f64, &fluid)).collect();
        let (rho_p, g) = (2480.0, 9.81);
        let diameters = [10e-6, 50e-6, 150e-6, 500e-6];
        let theta_c = super::super::shields::SHIELDS_MIXED;
        let table = exceedance_table(&series, &diameters, rho_p, g, theta_c);
        assert_eq!(table.len(), 2);
        for (k, &d) in diameters.iter().enumerate() {
            let u_star_c = (theta_c * rho_p * g * d / fluid.density).sqrt();
            let u_c = super::super::wall_law::speed_at(0.1, u_star_c, fluid.nu());
            let s = (2.0 * (u_c / 6.0 - 1.0)).clamp(-1.0, 1.0);
            let expect = s.acos() / std::f64::consts::PI;
            let e = table[0][k];
            assert!((e.fraction - expect).abs() <= 1.0 / n as f64 + 1e-12, "{d}: {} vs {expect}", e.fraction);
            assert_eq!(e, table[1][k], "a uniform flow is the same at both points");
            assert!(e.max >= e.mean && e.mean > 0.0);
        }
        // The four sizes span the cases: always above, partly, and never above the threshold.
        let f: Vec<f64> = table[0].iter().map(|e| e.fraction).collect();
        assert!(f[0] == 1.0 && f[1] > 0.0 && f[1] < 1.0 && f[2] < f[1] && f[3] == 0.0, "{f:?}");
    }

    #[test]
    fn jet_peak_finds_the_wall_jet_maximum() {
        // The Bell 47 wall jet (analytic rotor) peaks at about h = 0.15 R above the ground at r = R.
        use crate::field::analytic::{AnalyticField, AnalyticSet};
        use crate::field::rotor::RotorDownwash;
        let rotor = RotorDownwash::bell47(0.68);
        let field = AnalyticSet { parts: vec![AnalyticField::Rotor(rotor)], turbulence: None };
        let fluid = Fluid { density: 1.19, viscosity: 1.82e-5 };
        let method = ShearMethod::JetPeak { max_height: 3.0, samples: 200 };
        let probe =
            GroundProbe { origin: Vec3::ZERO, direction: Vec3::X, distances: vec![5.66], method, gust: 1.0 };
        let g = ground_shear(&field, &probe, 0.0, &fluid)[0];
        assert!(g.height > 0.5 && g.height < 1.2, "{g:?}");
        // c_f = τ_w/(½ρU²) of the order of turbulent wall jets' (a few 10⁻³, Launder & Rodi 1981).
        let cf = g.tau_w / (0.5 * 1.19 * g.speed * g.speed);
        assert!(cf > 2e-3 && cf < 4e-3, "{cf}");
    }
}
