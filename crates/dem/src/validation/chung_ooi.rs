//! Chung & Ooi (2011), "Benchmark tests for verifying discrete element modelling codes at particle impact
//! level", Granular Matter 13:643–656 — tests 1 to 8 with the numbers of that paper.
//!
//! Hertz normal, Mindlin tangential with history, restitution damping with the tensile clamp (the
//! engine's defaults); test 6 also under the conventions of its reference curve. The "rigid plane" is a
//! wall of E = ∞ with the sphere's Poisson ratio. Tests 2, 3, 4 and 6 run against the analytic plane and
//! against the same plane as a two-triangle STL with the impact on a face, on the shared edge and on the
//! shared vertex.

use super::impact::{pair_impact, wall_impact, Target};
use crate::contact::{Composed, CoulombLoad, Hertz, HertzMindlin, Mindlin, NoRolling, RestitutionDamping};
use spatter_core::material::Material;
use spatter_core::validation::Check;
use spatter_core::Vec3;

const SRC: &str = "Chung & Ooi (2011) Granular Matter 13:643";

fn mat(e: f64, nu: f64, rho: f64) -> Material {
    Material { youngs_modulus: e, poisson_ratio: nu, density: rho }
}

fn glass() -> Material {
    mat(48e9, 0.20, 2800.0)
}
fn limestone() -> Material {
    mat(20e9, 0.25, 2500.0)
}
fn al_alloy() -> Material {
    mat(70e9, 0.30, 2699.0)
}
fn mg_alloy() -> Material {
    mat(40e9, 0.35, 1800.0)
}
fn al_oxide() -> Material {
    mat(380e9, 0.23, 4000.0)
}
fn cast_iron() -> Material {
    mat(100e9, 0.25, 7000.0)
}
fn al_alloy_t4() -> Material {
    mat(70e9, 0.33, 2700.0)
}
fn steel() -> Material {
    mat(208e9, 0.30, 7850.0)
}
fn polyethylene() -> Material {
    mat(1e9, 0.40, 1400.0)
}
fn nylon() -> Material {
    mat(2.5e9, 0.40, 1000.0)
}
fn copper() -> Material {
    mat(120e9, 0.35, 8900.0)
}

/// The engine's default Hertz–Mindlin law.
fn law() -> HertzMindlin {
    HertzMindlin::default()
}

/// Hertz–Mindlin under the conventions that reproduce Chung & Ooi's test 6 curve: damping without the
/// tensile clamp (calibrated: e_out = e), friction capped by the elastic normal force. Without the clamp
/// the dashpot's impulse over a contact is zero (γ_n depends on δ only), so in gross sliding the impulse
/// ratio is still μ and the sliding branch stays exact.
fn reference_convention_law() -> HertzMindlin {
    let damping = RestitutionDamping { tensile_clamp: false, ..Default::default() };
    Composed::new(Hertz, damping, Mindlin, NoRolling).with_coulomb_load(CoulombLoad::Elastic)
}

fn steps(quick: bool) -> f64 {
    if quick {
        300.0
    } else {
        1000.0
    }
}

/// Test 1: two identical spheres head-on at ±10 m/s, elastic. References within 1 %.
pub fn test1(quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    for (name, m, f, d, t) in [
        ("glass", glass(), 10.70e3, 274.1e-6, 40.34e-6),
        ("limestone", limestone(), 7.11e3, 368.3e-6, 54.20e-6),
    ] {
        let o = pair_impact(
            &law(),
            &m,
            &m,
            0.010,
            0.010,
            0.0,
            1.0,
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(-10.0, 0.0, 0.0),
            Vec3::ZERO,
            Vec3::ZERO,
            steps(quick),
        );
        let case = format!("chung_ooi_1_{name}");
        out.push(Check::relative(&case, "F_max [N]", f, o.f_max, 0.01, SRC));
        out.push(Check::relative(&case, "delta_max [m]", d, o.delta_max, 0.01, SRC));
        out.push(Check::relative(&case, "t_c [s]", t, o.t_contact, 0.01, SRC));
        out.push(Check::absolute(
            &case,
            "rebound speed / impact speed [-]",
            1.0,
            o.v.x.abs() / 10.0,
            1e-3,
            SRC,
        ));
    }
    out
}

fn targets(quick: bool) -> &'static [Target] {
    if quick {
        &[Target::Plane, Target::StlEdge, Target::StlVertex]
    } else {
        &Target::ALL
    }
}

/// Test 2: sphere on a rigid plane, 0.2 m/s, elastic, frictionless. References within 1 %.
pub fn test2(quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    for (name, m, f, d, t) in [
        ("al_alloy", al_alloy(), 11.37e3, 49.72e-6, 731.7e-6),
        ("mg_alloy", mg_alloy(), 7.23e3, 52.12e-6, 767.1e-6),
    ] {
        for &tg in targets(quick) {
            let o = wall_impact(&law(), &m, 0.10, 0.0, 1.0, 0.2, 0.0, 0.0, tg, steps(quick));
            let case = format!("chung_ooi_2_{name}_{}", tg.label());
            out.push(Check::relative(&case, "F_max [N]", f, o.f_max, 0.01, SRC));
            out.push(Check::relative(&case, "delta_max [m]", d, o.delta_max, 0.01, SRC));
            out.push(Check::relative(&case, "t_c [s]", t, o.t_contact, 0.01, SRC));
        }
    }
    out
}

/// Test 3: restitution on a plane, R = 2.5 mm at 3.9 m/s: e_out = e_in (tensile clamp on; damping
/// calibrated for it). Tolerance 1 %: the time-discretisation error at the step used.
pub fn test3(quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    let es: &[f64] = if quick { &[0.2, 0.6, 1.0] } else { &[0.2, 0.4, 0.6, 0.8, 1.0] };
    for (name, m) in [("al_oxide", al_oxide()), ("cast_iron", cast_iron())] {
        for &tg in targets(quick) {
            for &e in es {
                let o = wall_impact(&law(), &m, 2.5e-3, 0.0, e, 3.9, 0.0, 0.0, tg, steps(quick));
                let case = format!("chung_ooi_3_{name}_{}", tg.label());
                out.push(Check::relative(
                    &case,
                    format!("e_out at e_in = {e} [-]"),
                    e,
                    o.v.z / 3.9,
                    0.01,
                    SRC,
                ));
            }
        }
    }
    out
}

/// Test 4: oblique impact at 3.9 m/s on a plane, μ = 0.092, e = 0.98. Al oxide against the reference
/// table (e_t and ω within 5 %); the Al alloy in the sliding regime (θ > 32.5°) against
/// e_t = 1 − μ(1+e)/tanθ and ω = −2.5μ(1+e)v cosθ/R (1 %).
///
/// Known deviation (docs/dem.md §4): at 5° the contact sticks for most of the impact. Angular momentum
/// about the contact point fixes ω′ = −(5/2) v_t (1 − e_t)/R, so the ω row demands e_t ∈ [0.9413, 0.9469]
/// (the reference pair itself is not consistent at its printed precision: e_t = 0.948 gives −17.7 rad/s).
/// The default law gives e_t = 0.963, ω = −12.5 rad/s; none of the tangential laws of this crate lands
/// in the window (`examples/tangential_laws_chung_ooi.rs`), so that row fails in the full report; at 10°
/// ω = −203 rad/s is 4.6 % below the reference −213. The quick variant checks 30° and 60°.
pub fn test4(quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    let (mu, e, r, v) = (0.092, 0.98, 2.5e-3, 3.9);
    let reference: &[(f64, f64, f64)] = &[
        (5.0, 0.948, -19.0),
        (10.0, 0.687, -213.0),
        (20.0, 0.616, -511.0),
        (30.0, 0.684, -617.0),
        (40.0, 0.781, -545.0),
        (50.0, 0.845, -457.0),
        (60.0, 0.893, -357.0),
        (70.0, 0.932, -246.0),
        (80.0, 0.966, -126.0),
    ];
    let pick: Vec<&(f64, f64, f64)> = if quick {
        reference.iter().filter(|r| [30.0, 60.0].contains(&r.0)).collect()
    } else {
        reference.iter().collect()
    };
    for &tg in targets(quick) {
        for &&(theta, e_t, w) in &pick {
            let th = theta.to_radians();
            let o =
                wall_impact(&law(), &al_oxide(), r, mu, e, v * th.cos(), v * th.sin(), 0.0, tg, steps(quick));
            let (et_ours, w_ours) = tangential_results(&o, v * th.sin());
            let case = format!("chung_ooi_4_al_oxide_{}", tg.label());
            out.push(Check::relative(&case, format!("e_t at {theta} deg [-]"), e_t, et_ours, 0.05, SRC));
            out.push(Check::relative(&case, format!("omega at {theta} deg [rad/s]"), w, w_ours, 0.05, SRC));
        }
    }
    let angles: &[f64] = if quick { &[45.0] } else { &[35.0, 45.0, 60.0, 85.0] };
    for &theta in angles {
        let th = f64::to_radians(theta);
        let o = wall_impact(
            &law(),
            &al_alloy_t4(),
            r,
            mu,
            e,
            v * th.cos(),
            v * th.sin(),
            0.0,
            Target::Plane,
            steps(quick),
        );
        let (et_ours, w_ours) = tangential_results(&o, v * th.sin());
        let case = "chung_ooi_4_al_alloy_sliding";
        out.push(Check::relative(
            case,
            format!("e_t at {theta} deg [-]"),
            1.0 - mu * (1.0 + e) / th.tan(),
            et_ours,
            0.01,
            SRC,
        ));
        let w_ref = -2.5 * mu * (1.0 + e) * v * th.cos() / r;
        out.push(Check::relative(case, format!("omega at {theta} deg [rad/s]"), w_ref, w_ours, 0.01, SRC));
    }
    out
}

/// Tangential restitution of the centre (v_t′/v_t) and spin in Chung & Ooi's sign convention
/// (negative for the forward roll that friction induces).
fn tangential_results(o: &super::impact::Outcome, v_t: f64) -> (f64, f64) {
    let t = o.tangent;
    let axis = Vec3::Z.cross(t);
    (o.v.dot(t) / v_t, -o.omega.dot(axis))
}

/// Test 5: a 10 µm sphere at v_n = 5 m/s with large tangential speed (gross sliding): Ψ₂ = Ψ₁ − 7 and
/// Rω′/(μ v_n) = −5. Tolerance 1 % (analytic rigid-body result).
pub fn test5(quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    let (mu, r, vn) = (0.3, 1e-5, 5.0);
    let psis: &[f64] = if quick { &[10.0] } else { &[7.5, 10.0, 14.0] };
    for (name, m) in [("steel", steel()), ("polyethylene", polyethylene())] {
        for &psi1 in psis {
            let vt = psi1 * mu * vn;
            let o = wall_impact(&law(), &m, r, mu, 1.0, vn, vt, 0.0, Target::Plane, steps(quick));
            let t = o.tangent;
            let axis = Vec3::Z.cross(t);
            // Contact-point tangential velocity after the impact: v + ω × (−R n).
            let vc = (o.v + o.omega.cross(-r * Vec3::Z)).dot(t);
            let case = format!("chung_ooi_5_{name}");
            out.push(Check::relative(
                &case,
                format!("Psi2 at Psi1 = {psi1} [-]"),
                psi1 - 7.0,
                vc / (mu * vn),
                0.01,
                SRC,
            ));
            let spin = -o.omega.dot(axis) * r / (mu * vn);
            out.push(Check::relative(
                &case,
                format!("R omega'/(mu v_n) at Psi1 = {psi1} [-]"),
                -5.0,
                spin,
                0.01,
                SRC,
            ));
        }
    }
    out
}

/// Contact-point tangential velocity of a sphere of radius `r` above the plane (n = +z) along `t`.
fn contact_velocity(v: Vec3, w: Vec3, r: f64, n: Vec3, t: Vec3) -> f64 {
    (v + w.cross(-r * n)).dot(t)
}

/// Test 6: a spinning sphere dropped on a plane at 0.2 m/s, μ = 0.4, e = 0.5: β = −v′_st/v_st against
/// x = 3.5μ(1+e)v_n/(Rω₀). Sliding (x < 1): β = x − 1 (absolute 0.01), with the default law and with the
/// reference convention. Al alloy at the reference points x = 1.21, 2.09, 4.51, 11.9 (absolute 0.03 on
/// β ∈ [−1, 1]) with the reference convention ([`reference_convention_law`]).
///
/// For x > 1 the contact sticks and β measures the elastic tangential rebound, which depends on the
/// history rule and on the damping conventions. The reference curve (its shape over x = 0.18…24, not only
/// the four points) is reproduced only when friction is capped by the elastic normal force and damping has
/// no tensile clamp; with the default law (total force, clamp) β levels off at −0.05 beyond x ≈ 5 where the
/// reference keeps falling to −0.34 at x = 24 (docs/dem.md §4). Under the reference convention x = 2.09
/// fails (0.091 vs 0.058) in the full report. The quick variant checks the sliding branch with both laws
/// and x = 4.51.
pub fn test6(quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    let (mu, e, r, vn) = (0.4, 0.5, 0.1, 0.2);
    let xs_slide: &[f64] = if quick { &[0.5] } else { &[0.2, 0.5, 0.8] };
    let refs: &[(f64, f64)] = &[(1.21, 0.096), (2.09, 0.058), (4.51, -0.139), (11.9, -0.259)];
    let refs: &[(f64, f64)] = if quick { &refs[2..3] } else { refs };
    for (name, m) in [("al_alloy", al_alloy()), ("nylon", nylon())] {
        for &tg in targets(quick) {
            for (convention, law) in [("", law()), ("_elastic_cap", reference_convention_law())] {
                let case = format!("chung_ooi_6_{name}_{}{convention}", tg.label());
                let run = |x: f64| {
                    let w0 = 3.5 * mu * (1.0 + e) * vn / (r * x);
                    // Spin about −(n × t̂) so that the contact point moves along +t̂ at speed R ω₀.
                    let o = wall_impact(&law, &m, r, mu, e, vn, 0.0, -w0, tg, steps(quick));
                    let v_st =
                        contact_velocity(Vec3::ZERO, -w0 * Vec3::Z.cross(o.tangent), r, Vec3::Z, o.tangent);
                    let v_st2 = contact_velocity(o.v, o.omega, r, Vec3::Z, o.tangent);
                    -v_st2 / v_st
                };
                for &x in xs_slide {
                    let beta = run(x);
                    out.push(Check::absolute(
                        &case,
                        format!("beta at x = {x} (sliding) [-]"),
                        x - 1.0,
                        beta,
                        0.01,
                        SRC,
                    ));
                }
                if name == "al_alloy" && !convention.is_empty() {
                    for &(x, b) in refs {
                        let beta = run(x);
                        out.push(Check::absolute(&case, format!("beta at x = {x} [-]"), b, beta, 0.03, SRC));
                    }
                }
            }
        }
    }
    out
}

/// Test 7: two identical spheres at ±0.2 m/s with opposite spins: no slip, spins and tangential
/// velocities unchanged (absolute 1e-9 relative to the spin).
pub fn test7(quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    let (mu, e, r) = (0.4, 0.5, 0.1);
    let spins: &[f64] = if quick { &[10.0] } else { &[1.0, 10.0, 30.0] };
    for (name, m) in [("al_alloy", al_alloy()), ("copper", copper())] {
        for &w in spins {
            let w1 = Vec3::new(0.0, w, 0.0);
            let o = pair_impact(
                &law(),
                &m,
                &m,
                r,
                r,
                mu,
                e,
                Vec3::new(0.2, 0.0, 0.0),
                Vec3::new(-0.2, 0.0, 0.0),
                w1,
                -w1,
                steps(quick),
            );
            let case = format!("chung_ooi_7_{name}");
            out.push(Check::absolute(
                &case,
                format!("|omega' - omega| / omega at {w} rad/s [-]"),
                0.0,
                (o.omega - w1).length() / w,
                1e-9,
                SRC,
            ));
            out.push(Check::absolute(
                &case,
                format!("tangential speed after at {w} rad/s [m/s]"),
                0.0,
                (o.v.y.powi(2) + o.v.z.powi(2)).sqrt(),
                1e-9,
                SRC,
            ));
            out.push(Check::relative(
                &case,
                format!("normal restitution at {w} rad/s [-]"),
                e,
                -o.v.x / 0.2,
                0.01,
                SRC,
            ));
        }
    }
    out
}

/// Test 8: a small sphere (R = 0.1) on a 5× larger, 1000× denser sphere at rest, spin varied: the
/// sliding branch β = x − 1 of test 6 (absolute 0.01).
pub fn test8(quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    let (mu, e, r1, r2, vn) = (0.4, 0.5, 0.1, 0.5, 0.2);
    let xs: &[f64] = if quick { &[0.5] } else { &[0.2, 0.5, 0.8] };
    for (name, m) in [("al_alloy", al_alloy()), ("nylon", nylon())] {
        let heavy = Material { density: 1000.0 * m.density, ..m.clone() };
        for &x in xs {
            let w0 = 3.5 * mu * (1.0 + e) * vn / (r1 * x);
            // Particle 1 moves +x towards particle 2; normal from 2 to 1 is −x. Spin about +z gives the
            // contact point (at +r1 x) the velocity ω × r1 x = +y r1 ω₀.
            let w1 = Vec3::new(0.0, 0.0, w0);
            let o = pair_impact(
                &law(),
                &m,
                &heavy,
                r1,
                r2,
                mu,
                e,
                Vec3::new(vn, 0.0, 0.0),
                Vec3::ZERO,
                w1,
                Vec3::ZERO,
                steps(quick),
            );
            let n = -Vec3::X;
            let t = Vec3::Y;
            let vc1 = |v: Vec3, w: Vec3| (v + w.cross(-r1 * n)).dot(t);
            let vc2 = |v: Vec3, w: Vec3| (v + w.cross(r2 * n)).dot(t);
            let before = vc1(Vec3::new(vn, 0.0, 0.0), w1);
            let after = vc1(o.v, o.omega) - vc2(o.v2, o.omega2);
            let case = format!("chung_ooi_8_{name}");
            out.push(Check::absolute(
                &case,
                format!("beta at x = {x} (sliding) [-]"),
                x - 1.0,
                -after / before,
                0.01,
                SRC,
            ));
        }
    }
    out
}
