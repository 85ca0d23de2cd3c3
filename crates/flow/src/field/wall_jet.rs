//! Turbulent wall jets (radial, as under a rotor or an impinging jet, or planar).
//!
//! Velocity profile of Verhoff (1963), as used for wall jets by e.g. Launder & Rodi (1983):
//!
//! u/u_m = f(η) = 1.48 η^(1/7) (1 − erf(0.68 η)),    η = z / δ,
//!
//! with δ the height where u = u_m/2. The maximum velocity decays as u_m = U₀ (r₀/r)^n and δ grows
//! linearly, δ = δ₀ + s (r − r₀) (Launder & Rodi: n ≈ 1.1 radial, 0.5 planar; s ≈ 0.09). Inside r < r₀
//! (the impingement region) u_m grows linearly from the axis, u_m = U₀ r/r₀, at constant δ₀.
//!
//! The wall-normal velocity follows from continuity so that the field is divergence-free:
//! radial: w = −(1/r)[(r u_m)′ δ F(η) − r u_m δ′ (η f(η) − F(η))], planar: the same without r,
//! F(η) = ∫₀^η f. (w has a jump at r₀ where u_m′ does.)

use super::special::erf;
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;
use std::sync::OnceLock;

/// Wall-jet parameters. Scenario table `{ kind = "wall_jet", … }`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallJet {
    /// Impingement point on the wall \[m\].
    #[serde(default)]
    pub origin_m: Vec3,
    /// Wall normal pointing into the fluid.
    #[serde(default = "z_axis")]
    pub normal: Vec3,
    /// Maximum velocity U₀ at r₀ \[m/s\].
    pub max_velocity_m_s: f64,
    /// Reference distance r₀ from the origin \[m\].
    pub reference_distance_m: f64,
    /// Half-velocity thickness δ₀ at r₀ \[m\].
    pub thickness_m: f64,
    /// dδ/dr.
    #[serde(default = "default_spreading")]
    pub spreading_rate: f64,
    /// Exponent n of u_m ∝ r^(−n); default 1.1 (radial) — use 0.5 for a planar jet.
    #[serde(default = "default_decay")]
    pub decay_exponent: f64,
    /// Planar jet flowing along `direction` instead of a radial one.
    #[serde(default)]
    pub planar: bool,
    /// Flow direction of a planar jet (projected onto the wall).
    #[serde(default = "x_axis")]
    pub direction: Vec3,
}

fn z_axis() -> Vec3 {
    Vec3::Z
}
fn x_axis() -> Vec3 {
    Vec3::X
}
fn default_spreading() -> f64 {
    0.09
}
fn default_decay() -> f64 {
    1.1
}

impl Validate for WallJet {
    fn validate(&self, c: &mut Checker) {
        c.finite_vec("origin_m", self.origin_m);
        if self.normal.length() < 1e-12 || !spatter_core::math::is_finite(self.normal) {
            c.fail("normal", "normal must be a finite non-zero direction");
        }
        c.finite("max_velocity_m_s", self.max_velocity_m_s);
        c.positive("reference_distance_m", self.reference_distance_m);
        c.positive("thickness_m", self.thickness_m);
        c.non_negative("spreading_rate", self.spreading_rate);
        c.non_negative("decay_exponent", self.decay_exponent);
        if self.planar {
            let d = self.direction
                - self.direction.dot(self.normal.normalize_or_zero()) * self.normal.normalize_or_zero();
            if d.length() < 1e-12 {
                c.fail("direction", "direction must have a component along the wall");
            }
        }
    }
}

/// The Verhoff profile f(η).
#[inline]
pub fn verhoff(eta: f64) -> f64 {
    if eta <= 0.0 {
        return 0.0;
    }
    1.48 * eta.powf(1.0 / 7.0) * (1.0 - erf(0.68 * eta))
}

const ETA_MAX: f64 = 8.0;
const TABLE_N: usize = 4000;

/// F(η) = ∫₀^η f on a table (Simpson in s = η^(1/7), where the integrand 7·1.48 s⁷(1 − erf(0.68 s⁷)) is
/// smooth), linearly interpolated.
fn integral_table() -> &'static Vec<f64> {
    static T: OnceLock<Vec<f64>> = OnceLock::new();
    T.get_or_init(|| {
        let g = |s: f64| 7.0 * 1.48 * s.powi(7) * (1.0 - erf(0.68 * s.powi(7)));
        let mut out = Vec::with_capacity(TABLE_N + 1);
        out.push(0.0);
        for i in 1..=TABLE_N {
            let (e0, e1) = ((i - 1) as f64 * ETA_MAX / TABLE_N as f64, i as f64 * ETA_MAX / TABLE_N as f64);
            let (s0, s1) = (e0.powf(1.0 / 7.0), e1.powf(1.0 / 7.0));
            let m = 8;
            let h = (s1 - s0) / m as f64;
            let mut acc = g(s0) + g(s1);
            for k in 1..m {
                acc += if k % 2 == 1 { 4.0 } else { 2.0 } * g(s0 + k as f64 * h);
            }
            out.push(out[i - 1] + acc * h / 3.0);
        }
        out
    })
}

/// F(η) = ∫₀^η f(η′) dη′, cubic Hermite between table nodes with F′ = f, so that dF/dη = f to high
/// order (the wall-normal velocity is then divergence-free to within the finite-difference error).
pub fn verhoff_integral(eta: f64) -> f64 {
    let t = integral_table();
    if eta <= 0.0 {
        return 0.0;
    }
    let h = ETA_MAX / TABLE_N as f64;
    if eta >= ETA_MAX {
        return t[TABLE_N];
    }
    let u = eta / h;
    let i = (u as usize).min(TABLE_N - 1);
    let s = u - i as f64;
    let (e0, e1) = (i as f64 * h, (i + 1) as f64 * h);
    // The first interval holds the η^(1/7) singularity of f: integrate the power law exactly there.
    if i == 0 {
        return 1.48 * 7.0 / 8.0 * eta.powf(8.0 / 7.0) * (1.0 - erf(0.68 * eta))
            + (t[1] - 1.48 * 7.0 / 8.0 * e1.powf(8.0 / 7.0) * (1.0 - erf(0.68 * e1))) * s;
    }
    let (h00, h10, h01, h11) = (
        2.0 * s * s * s - 3.0 * s * s + 1.0,
        s * s * s - 2.0 * s * s + s,
        -2.0 * s * s * s + 3.0 * s * s,
        s * s * s - s * s,
    );
    h00 * t[i] + h10 * h * verhoff(e0) + h01 * t[i + 1] + h11 * h * verhoff(e1)
}

impl WallJet {
    /// (u_m, du_m/dr, δ, dδ/dr) at distance `r` along the wall.
    fn scales(&self, r: f64) -> (f64, f64, f64, f64) {
        let (u0, r0, d0) = (self.max_velocity_m_s, self.reference_distance_m, self.thickness_m);
        if r < r0 {
            (u0 * r / r0, u0 / r0, d0, 0.0)
        } else {
            let n = self.decay_exponent;
            let um = u0 * (r0 / r).powf(n);
            (um, -n * um / r, d0 + self.spreading_rate * (r - r0), self.spreading_rate)
        }
    }

    /// Velocity at `x` \[m/s\]; zero behind the wall.
    pub fn velocity(&self, x: Vec3) -> Vec3 {
        let n = self.normal.normalize();
        let d = x - self.origin_m;
        let z = d.dot(n);
        if z <= 0.0 {
            return Vec3::ZERO;
        }
        let inplane = d - z * n;
        if self.planar {
            let dir = (self.direction - self.direction.dot(n) * n).normalize();
            let s = inplane.dot(dir);
            if s <= 0.0 {
                return Vec3::ZERO;
            }
            let (um, dum, del, ddel) = self.scales(s);
            let eta = z / del;
            let (f, ff) = (verhoff(eta), verhoff_integral(eta));
            let w = -(dum * del * ff - um * ddel * (eta * f - ff));
            return um * f * dir + w * n;
        }
        let r = inplane.length();
        let (um, dum, del, ddel) = self.scales(r);
        let eta = z / del;
        let (f, ff) = (verhoff(eta), verhoff_integral(eta));
        if r < 1e-12 * self.reference_distance_m {
            // Axis: u_r = 0, w = −2 (U₀/r₀) δ₀ F(η).
            return -2.0 * self.max_velocity_m_s / self.reference_distance_m * del * ff * n;
        }
        let e_r = inplane / r;
        // (r u_m)′ = u_m + r u_m′.
        let w = -((um + r * dum) * del * ff - r * um * ddel * (eta * f - ff)) / r;
        um * f * e_r + w * n
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::fd_gradient;

    #[test]
    fn verhoff_profile_is_half_at_eta_one_and_peaks_near_one() {
        // u = u_m/2 at η = 1 by the definition of δ (Verhoff's fit gives 0.4975).
        assert!((verhoff(1.0) - 0.5).abs() < 0.005);
        let peak = (1..400).map(|i| verhoff(i as f64 * 0.001)).fold(0.0, f64::max);
        assert!((peak - 1.0).abs() < 0.002, "{peak}");
        // F(∞) by Simpson in η on a fine grid away from 0 plus the small-η power law.
        let h = 1e-4;
        let mut s = 1.48 * 7.0 / 8.0 * 0.01f64.powf(8.0 / 7.0); // ∫₀^0.01 ≈ 1.48 η^{1/7}
        let mut e = 0.01;
        while e < 8.0 {
            s += h / 6.0 * (verhoff(e) + 4.0 * verhoff(e + h / 2.0) + verhoff(e + h));
            e += h;
        }
        assert!((verhoff_integral(8.0) - s).abs() < 1e-4, "{} vs {s}", verhoff_integral(8.0));
    }

    #[test]
    fn wall_jet_is_divergence_free_and_has_no_slip() {
        for planar in [false, true] {
            let j = WallJet {
                origin_m: Vec3::new(0.0, 0.0, 0.0),
                normal: Vec3::Z,
                max_velocity_m_s: 8.0,
                reference_distance_m: 1.0,
                thickness_m: 0.1,
                spreading_rate: 0.09,
                decay_exponent: if planar { 0.5 } else { 1.1 },
                planar,
                direction: Vec3::X,
            };
            for x in [Vec3::new(1.7, 0.4, 0.05), Vec3::new(3.0, -1.0, 0.2), Vec3::new(0.5, 0.2, 0.07)] {
                let g = fd_gradient(|p| j.velocity(p), x, 1e-6);
                let div = g.x_axis.x + g.y_axis.y + g.z_axis.z;
                let scale = g.x_axis.length() + g.y_axis.length() + g.z_axis.length();
                assert!(div.abs() < 1e-5 * scale, "planar {planar} at {x}: div {div}, |∇u| {scale}");
            }
            assert_eq!(j.velocity(Vec3::new(2.0, 0.0, 0.0)).x, 0.0, "no slip at the wall");
            // Maximum velocity at r₀ is U₀ near η ≈ 0.16.
            let um = (1..300).map(|i| j.velocity(Vec3::new(1.0, 0.0, i as f64 * 1e-3)).x).fold(0.0, f64::max);
            assert!((um - 8.0).abs() < 0.02, "{um}");
        }
    }
}
