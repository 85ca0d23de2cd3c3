//! Bodies (STL surfaces) and what happens to a parcel that hits one.
//!
//! Hits are found as the first crossing of the parcel's path segment over a step with a triangle
//! (core `TriBvh`; the particle centre is tracked, as in Fluent's DPM). The rules:
//!
//! * `reflect` — v′ = e_t v_t − e_n v_n n: normal and tangential restitution coefficients;
//! * `trap` — the parcel stays where it hit (deposited);
//! * `escape` — the parcel leaves the computation at the wall (counted as escaped);
//! * `regime_map` — stick/bounce from the snow workflow's regime-map JSON (`spatter.regime_map.v1`,
//!   the stick/bounce map of Lind 2017): the parcel sticks when its normal impact speed is below the
//!   critical speed of its diameter, v_n < v_crit(d), and — when set — its tangential speed is below
//!   `max_tangential_speed_m_s` (the tangential condition of the thesis's CFD, L575) and the local wall
//!   shear stress is below `max_wall_shear_pa` (aerodynamic rip-off); otherwise it bounces with the
//!   given restitution.

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::mesh::TriMesh;
use spatter_core::regime::RegimeMap;
use spatter_core::tri_bvh::TriBvh;
use spatter_core::Vec3;
use std::path::PathBuf;

/// Restitution of a bounce.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Restitution {
    /// Normal coefficient e_n ∈ \[0, 1\].
    #[serde(default = "one")]
    pub normal: f64,
    /// Tangential coefficient e_t ∈ \[0, 1\].
    #[serde(default = "one")]
    pub tangential: f64,
}

fn one() -> f64 {
    1.0
}

impl Default for Restitution {
    fn default() -> Self {
        Restitution { normal: 1.0, tangential: 1.0 }
    }
}

impl Validate for Restitution {
    fn validate(&self, c: &mut Checker) {
        c.in_range("normal", self.normal, 0.0, true, 1.0, true);
        c.in_range("tangential", self.tangential, 0.0, true, 1.0, true);
    }
}

/// A wall rule as written in a scenario (`rule = "reflect" | "trap" | "escape" | "regime_map"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "rule", rename_all = "snake_case", deny_unknown_fields)]
pub enum WallRuleSpec {
    Reflect {
        #[serde(default)]
        restitution: Restitution,
    },
    Trap,
    Escape,
    RegimeMap {
        /// The regime-map JSON written by the snow workflow.
        file: PathBuf,
        /// Restitution of parcels that bounce.
        #[serde(default)]
        bounce: Restitution,
        /// Stick only when the tangential impact speed is below this \[m/s\].
        #[serde(default)]
        max_tangential_speed_m_s: Option<f64>,
        /// Stick only where the wall shear stress is below this \[Pa\] (rip-off).
        #[serde(default)]
        max_wall_shear_pa: Option<f64>,
    },
}

impl Validate for WallRuleSpec {
    fn validate(&self, c: &mut Checker) {
        match self {
            WallRuleSpec::Reflect { restitution } => c.item("restitution", restitution),
            WallRuleSpec::RegimeMap { file, bounce, max_tangential_speed_m_s, max_wall_shear_pa } => {
                let full = c.resolve(file);
                if !full.is_file() {
                    c.file_exists("file", file);
                } else if let Err(e) = load_regime_map(&full) {
                    c.fail("file", format!("file = \"{}\": {e}", file.display()));
                }
                c.item("bounce", bounce);
                if let Some(v) = max_tangential_speed_m_s {
                    c.non_negative("max_tangential_speed_m_s", *v);
                }
                if let Some(v) = max_wall_shear_pa {
                    c.non_negative("max_wall_shear_pa", *v);
                }
            }
            WallRuleSpec::Trap | WallRuleSpec::Escape => {}
        }
    }
}

/// The rule in force on a body, with its regime map loaded.
#[derive(Clone, Debug, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub enum WallRule {
    Reflect(Restitution),
    Trap,
    Escape,
    RegimeMap {
        map: RegimeMap,
        bounce: Restitution,
        max_tangential_speed: Option<f64>,
        max_wall_shear: Option<f64>,
    },
}

/// Why a regime map could not be used.
#[derive(Debug, thiserror::Error)]
pub enum WallRuleError {
    #[error("regime map {path}: cannot read it: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("regime map {path}: {message}")]
    Format { path: PathBuf, message: String },
}

/// Reads and checks a regime-map JSON file: syntax (with line and column), schema tag and both fits (a
/// reversed `x_range` or an empty coefficient list would make every impact panic or stick wrongly); the
/// message names the file and the key.
pub fn load_regime_map(path: &std::path::Path) -> Result<RegimeMap, WallRuleError> {
    let text = std::fs::read_to_string(path)
        .map_err(|source| WallRuleError::Io { path: path.to_owned(), source })?;
    let map: RegimeMap = serde_json::from_str(&text)
        .map_err(|e| WallRuleError::Format { path: path.to_owned(), message: e.to_string() })?;
    map.check().map_err(|message| WallRuleError::Format { path: path.to_owned(), message })?;
    Ok(map)
}

impl WallRule {
    /// Loads the rule, reading its regime map file when it has one (a relative path is relative to the
    /// working directory; the scenario loader has made it absolute).
    pub fn from_spec(spec: &WallRuleSpec) -> Result<Self, WallRuleError> {
        Ok(match spec {
            WallRuleSpec::Reflect { restitution } => WallRule::Reflect(*restitution),
            WallRuleSpec::Trap => WallRule::Trap,
            WallRuleSpec::Escape => WallRule::Escape,
            WallRuleSpec::RegimeMap { file, bounce, max_tangential_speed_m_s, max_wall_shear_pa } => {
                let map = load_regime_map(file)?;
                WallRule::RegimeMap {
                    map,
                    bounce: *bounce,
                    max_tangential_speed: *max_tangential_speed_m_s,
                    max_wall_shear: *max_wall_shear_pa,
                }
            }
        })
    }

    /// The outcome of an impact of a particle of diameter `d` with normal speed `v_n` ≥ 0, tangential
    /// speed `v_t` on a triangle whose wall shear stress is `tau_w`.
    #[inline]
    pub fn outcome(&self, d: f64, v_n: f64, v_t: f64, tau_w: f64) -> Outcome {
        match self {
            WallRule::Reflect(r) => Outcome::Bounce(*r),
            WallRule::Trap => Outcome::Stick,
            WallRule::Escape => Outcome::Escape,
            WallRule::RegimeMap { map, bounce, max_tangential_speed, max_wall_shear } => {
                let sticks = map.sticks(d, v_n)
                    && max_tangential_speed.is_none_or(|m| v_t < m)
                    && max_wall_shear.is_none_or(|m| tau_w < m);
                if sticks {
                    Outcome::Stick
                } else {
                    Outcome::Bounce(*bounce)
                }
            }
        }
    }
}

/// What happens at one impact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Outcome {
    Stick,
    Bounce(Restitution),
    Escape,
}

/// A body: its surface, search tree and wall rule.
#[derive(Clone, Debug)]
pub struct Body {
    pub name: String,
    pub mesh: TriMesh,
    pub bvh: TriBvh,
    pub rule: WallRule,
    /// Wall shear stress estimate per triangle \[Pa\] (zero unless computed).
    pub wall_shear: Vec<f64>,
}

impl Body {
    pub fn new(name: impl Into<String>, mesh: TriMesh, rule: WallRule) -> Self {
        let bvh = TriBvh::build(&mesh);
        let n = mesh.triangles.len();
        Body { name: name.into(), mesh, bvh, rule, wall_shear: vec![0.0; n] }
    }

    /// Estimates the wall shear stress on every triangle as τ_w ≈ μ |u_t(h)|/h from the fluid velocity
    /// `h` off the centroid on the side the normal points to (where a closed body's fluid is).
    pub fn estimate_wall_shear(&mut self, mu: f64, h: f64, mut velocity: impl FnMut(Vec3) -> Option<Vec3>) {
        for t in 0..self.mesh.triangles.len() {
            let n = self.mesh.normal(t);
            let p = self.mesh.centroid(t) + h * n;
            self.wall_shear[t] = match velocity(p) {
                Some(u) => mu * (u - u.dot(n) * n).length() / h,
                None => 0.0,
            };
        }
    }
}

/// The closest body surface point to a parcel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearWall {
    /// Distance from the parcel centre to the surface \[m\].
    pub distance: f64,
    /// Unit vector from the surface point to the parcel centre (away from the wall); the triangle
    /// normal when the centre lies on the surface.
    pub away: Vec3,
    pub body: usize,
    pub triangle: u32,
}

/// The closest surface point of any body within `radius` of `x` (a BVH query per body whose radius
/// shrinks to the best distance found; bodies farther than `radius` cost one box test).
#[inline]
pub fn nearest_wall(bodies: &[Body], x: Vec3, radius: f64) -> Option<NearWall> {
    let mut best: Option<NearWall> = None;
    let mut r = radius;
    for (k, b) in bodies.iter().enumerate() {
        if let Some(h) = b.bvh.closest_point(&b.mesh, x, r) {
            if best.is_none_or(|w| h.distance < w.distance) {
                r = h.distance;
                let away = if h.distance > 0.0 {
                    (x - h.point) / h.distance
                } else {
                    b.mesh.normal(h.triangle as usize)
                };
                best = Some(NearWall { distance: h.distance, away, body: k, triangle: h.triangle });
            }
        }
    }
    best
}

/// Reflected velocity: v′ = e_t v_t − e_n v_n n with `n` the unit normal on the side the particle came
/// from and v_n = −v·n ≥ 0.
#[inline]
pub fn reflect(v: Vec3, n: Vec3, r: Restitution) -> Vec3 {
    let vn = v.dot(n);
    let vt = v - vn * n;
    r.tangential * vt - r.normal * vn * n
}

/// Regime maps for tests.
#[cfg(test)]
pub(crate) mod tests_support {
    use spatter_core::regime::{PolyFit, RegimeMap};

    /// A map with v_crit(d) = `v_crit` for every diameter.
    pub(crate) fn map(v_crit: f64) -> RegimeMap {
        // v_crit(d) = v_crit (constant in log-log space: log10 v = log10 v_crit).
        let fit = PolyFit {
            x: "diameter_m".into(),
            y: "critical_normal_speed_m_s".into(),
            log10: true,
            coefficients: vec![v_crit.log10()],
            x_range: [1e-6, 1e-3],
            rms_relative_error: 0.0,
        };
        RegimeMap {
            schema: RegimeMap::SCHEMA.into(),
            description: "test".into(),
            v_crit_of_d: fit.clone(),
            d_crit_of_vn: fit,
            interface: vec![],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::tests_support::map as test_map;
    use super::*;

    #[test]
    fn reflection_conserves_or_damps() {
        let v = Vec3::new(3.0, 0.0, -4.0);
        let n = Vec3::Z;
        assert_eq!(reflect(v, n, Restitution::default()), Vec3::new(3.0, 0.0, 4.0));
        let r = Restitution { normal: 0.5, tangential: 0.8 };
        assert!((reflect(v, n, r) - Vec3::new(2.4, 0.0, 2.0)).length() < 1e-15);
    }

    #[test]
    fn regime_rule_with_thresholds() {
        let rule = WallRule::RegimeMap {
            map: test_map(1.0),
            bounce: Restitution { normal: 0.3, tangential: 0.9 },
            max_tangential_speed: Some(5.0),
            max_wall_shear: Some(2.0),
        };
        assert_eq!(rule.outcome(20e-6, 0.5, 1.0, 0.1), Outcome::Stick);
        assert!(matches!(rule.outcome(20e-6, 1.5, 1.0, 0.1), Outcome::Bounce(_)), "too fast normally");
        assert!(matches!(rule.outcome(20e-6, 0.5, 6.0, 0.1), Outcome::Bounce(_)), "too fast tangentially");
        assert!(matches!(rule.outcome(20e-6, 0.5, 1.0, 3.0), Outcome::Bounce(_)), "ripped off by shear");
    }

    #[test]
    fn wall_shear_estimate_in_stagnation_point_flows() {
        use crate::field::analytic::{AnalyticField, AnalyticSet};
        use crate::field::FlowField;
        // Hiemenz (planar) and Homann (axisymmetric) outer flows u = a(x₁t₁ [+ x₂t₂] − {1,2} z n) onto a
        // plate: the velocity parallel to the wall does not depend on the height, u_t = a r with r the
        // in-plane distance from the stagnation line/point, so the estimate τ_w = μ|u_t(h)|/h is exactly
        // μ a r/h for any probe distance h. Checked per triangle to 1e-12 relative on a plate at z = 0
        // (planar flow, r = |x − x₀|) and on the same plate rotated off every axis (axisymmetric flow).
        let (mu, a, h) = (1.8e-5, 40.0, 2e-3);
        let centre = Vec3::new(0.23, -0.11, 0.0);
        let mut plate = TriMesh::rectangle(1.0, 0.8, 0.0, 10, 8);
        plate.map_vertices(|v| v - Vec3::new(0.5, 0.4, 0.0));
        for (axisymmetric, rot) in [
            (false, spatter_core::Mat3::IDENTITY),
            (true, spatter_core::Mat3::from_axis_angle(Vec3::new(0.3, -0.5, 0.8).normalize(), 0.9)),
        ] {
            let mut mesh = plate.clone();
            mesh.map_vertices(|v| rot * v);
            let normal = rot * Vec3::Z;
            let field = AnalyticSet {
                parts: vec![AnalyticField::StagnationPoint {
                    strain_rate: a,
                    centre: rot * centre,
                    normal,
                    axisymmetric,
                }],
                turbulence: None,
            };
            let mut body = Body::new("plate", mesh, WallRule::Trap);
            body.estimate_wall_shear(mu, h, |p| field.sample(p, 0.0, &mut 0, false).map(|s| s.u));
            for t in 0..body.mesh.triangles.len() {
                // In-plane offset of the centroid from the stagnation point, in the plate's own frame.
                let c = rot.transpose() * body.mesh.centroid(t) - centre;
                let r = if axisymmetric { c.truncate().length() } else { c.x.abs() };
                let expect = mu * a * r / h;
                let got = body.wall_shear[t];
                assert!(
                    (got - expect).abs() <= 1e-12 * expect.max(1e-300) + 1e-18,
                    "triangle {t}: {got} vs {expect}"
                );
            }
            assert!(body.wall_shear.iter().any(|&w| w > 0.1 * mu * a / h), "nontrivial shear");
        }
    }

    #[test]
    fn regime_map_file_is_checked() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("map.json");
        std::fs::write(&p, serde_json::to_string(&test_map(1.0)).unwrap()).unwrap();
        let spec = WallRuleSpec::RegimeMap {
            file: p.clone(),
            bounce: Restitution::default(),
            max_tangential_speed_m_s: None,
            max_wall_shear_pa: None,
        };
        assert!(WallRule::from_spec(&spec).is_ok());
        let mut bad = test_map(1.0);
        bad.schema = "other".into();
        std::fs::write(&p, serde_json::to_string(&bad).unwrap()).unwrap();
        let e = WallRule::from_spec(&spec).unwrap_err().to_string();
        assert!(e.contains("map.json") && e.contains("spatter.regime_map.v1"), "{e}");
        // A reversed diameter range (used to panic in the clamp of every impact) and an empty
        // coefficient list (used to give v_crit = 10⁰ = 1 m/s silently) are refused with file and key.
        let mut bad = test_map(1.0);
        bad.v_crit_of_d.x_range = [1e-3, 1e-6];
        std::fs::write(&p, serde_json::to_string(&bad).unwrap()).unwrap();
        let e = WallRule::from_spec(&spec).unwrap_err().to_string();
        assert!(e.contains("map.json") && e.contains("v_crit_of_d.x_range"), "{e}");
        let mut bad = test_map(1.0);
        bad.v_crit_of_d.coefficients.clear();
        std::fs::write(&p, serde_json::to_string(&bad).unwrap()).unwrap();
        let e = WallRule::from_spec(&spec).unwrap_err().to_string();
        assert!(e.contains("map.json") && e.contains("v_crit_of_d.coefficients"), "{e}");
    }
}
