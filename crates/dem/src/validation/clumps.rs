//! Rigid multi-sphere bodies (clumps) through the engine: template inertia against the analytic solids,
//! the union of overlapping spheres against its closed form, torque-free rotation (invariants and Euler's
//! exact solution with the intermediate-axis flip), a one-sphere clump against the free sphere, and a
//! dumbbell dropped flat and on one end.
//!
//! The scenes are `pub(crate)` so the engine's unit tests (`sim/clump_tests.rs`) run the same set-ups.

use super::impact::rigid;
use crate::clump::fill::fill_equal;
use crate::clump::mass::of_spheres;
use crate::clump::shapes::{Ball, Ellipsoid, Solid};
use crate::clump::{ClumpTemplate, NewBody};
use crate::contact::restitution_fit::{damping_coefficient, restitution};
use crate::contact::{HertzMindlin, PairProps, PairTable};
use crate::sim::{ClumpContactMass, Settings, Simulation};
use crate::walls::{MeshWall, Plane, Wall, WallShape};
use spatter_core::material::Material;
use spatter_core::math::sphere_volume;
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use spatter_core::validation::Check;
use spatter_core::{Quat, Vec3};
use std::f64::consts::PI;

const SRC_SOLID: &str =
    "moments of inertia of the solid ball and ellipsoid (e.g. Landau & Lifshitz, Mechanics §32)";
const SRC_EULER: &str = "torque-free rigid body, Euler's equations and their elliptic-function solution (Landau & Lifshitz, Mechanics §37)";
const SRC_IMPULSE: &str = "rigid-body impact impulse (Brach, Mechanical Impact Dynamics, 1991, ch. 4)";

fn soft() -> Material {
    Material { youngs_modulus: 5e7, poisson_ratio: 0.3, density: 2500.0 }
}

fn al_oxide() -> Material {
    Material { youngs_modulus: 380e9, poisson_ratio: 0.23, density: 4000.0 }
}

/// A simulation of material `m` (index 0) and a rigid wall material (index 1), Hertz–Mindlin, friction
/// `mu`, restitution `e` for every pair.
pub(crate) fn two_material_sim(
    m: &Material,
    mu: f64,
    e: f64,
    dt: f64,
    settings: Settings,
) -> Simulation<HertzMindlin> {
    let wall = rigid(m.poisson_ratio);
    let mats = vec![m.clone(), wall];
    let pairs = PairTable::build(2, |a, b| PairProps::new(&mats[a], &mats[b], mu, e));
    Simulation::new(HertzMindlin::default(), mats, pairs, dt, settings)
}

// ---------------------------------------------------------------------------------------------------
// Template inertia

/// Ball and ellipsoid filled with equal spheres on an FCC lattice, envelope mass: principal moments
/// against (2/5) M R² and (M/5)(b² + c²) etc., within the fill error (the lattice keeps a sphere radius
/// inside the surface and leaves gaps, an error of order d/R: the tolerance is d/R); principal axes of the
/// ellipsoid along its semi-axes. The union of two spheres overlapping by one radius against the exact
/// volume and axial moment, within the integrator's own error estimate. Solid fraction of the 615-sphere
/// ball of Qian et al. (2022): 615 (0.5/5)³ = 0.615.
pub fn template_inertia(quick: bool) -> Vec<Check> {
    let case = "clump_template_inertia";
    let mut out = Vec::new();
    let rho = 2500.0;
    // Ball R = 2.5 mm.
    let rr = 2.5e-3;
    let ball = Ball { radius: rr };
    let ds: &[f64] = if quick { &[0.5e-3] } else { &[0.5e-3, 0.25e-3] };
    for &d in ds {
        let (m, i) = fill_inertia(&ball, d, rho);
        let want = 0.4 * m * rr * rr;
        for k in 0..3 {
            out.push(Check::relative(
                case,
                format!("ball R = 2.5 mm, fill d = {} mm: I{} / (2/5 M R²) [-]", d * 1e3, k + 1),
                1.0,
                i[k] / want,
                d / rr,
                SRC_SOLID,
            ));
        }
    }
    // Ellipsoid 4 × 3 × 2 mm.
    let ax = Vec3::new(4e-3, 3e-3, 2e-3);
    let ell = Ellipsoid { semi_axes: ax };
    let ds: &[f64] = if quick { &[0.4e-3] } else { &[0.4e-3, 0.2e-3] };
    for &d in ds {
        let s = fill_equal(&ell, d, "ellipsoid").expect("the ellipsoid fits its fill spheres");
        let t = ClumpTemplate::from_spheres("ellipsoid", &s).with_envelope(ell.volume());
        let (m, i, _) = t.body_mass(rho);
        let want = Vec3::new(ax.y * ax.y + ax.z * ax.z, ax.x * ax.x + ax.z * ax.z, ax.x * ax.x + ax.y * ax.y)
            * (m / 5.0);
        for k in 0..3 {
            out.push(Check::relative(
                case,
                format!("ellipsoid 4x3x2 mm, fill d = {} mm: I{} / analytic [-]", d * 1e3, k + 1),
                1.0,
                i[k] / want[k],
                d / ax.z,
                SRC_SOLID,
            ));
        }
        let mut worst: f64 = 0.0;
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            let body_axis = t.props.axes * axis;
            worst = worst.max(1.0 - body_axis.dot(axis).abs());
        }
        out.push(Check::absolute(
            case,
            format!("ellipsoid fill d = {} mm: 1 - |cos| principal axis to semi-axis [-]", d * 1e3),
            0.0,
            worst,
            1e-9,
            SRC_SOLID,
        ));
    }
    // Two spheres of radius r at distance r: union = 2 spheres − lens; the lens is two caps of height
    // h = r − d/2, a cap's moment about its axis π h³ (3h² − 15rh + 20r²)/30 per unit density.
    let (r, dist) = (1.0, 1.0);
    let p = of_spheres(&[(Vec3::ZERO, r), (Vec3::new(dist, 0.0, 0.0), r)]);
    let h = r - 0.5 * dist;
    let cap_v = PI * h * h * (3.0 * r - h) / 3.0;
    let cap_i = PI * h.powi(3) * (3.0 * h * h - 15.0 * r * h + 20.0 * r * r) / 30.0;
    let vol = 2.0 * sphere_volume(r) - 2.0 * cap_v;
    let i_axis = 2.0 * 0.4 * sphere_volume(r) * r * r - 2.0 * cap_i;
    let src = "union of two overlapping spheres: sphere minus spherical-cap volume and moment (closed form)";
    let tol = p.error_estimate;
    out.push(Check::relative(
        case,
        "two spheres overlapping by r: union volume [m³]",
        vol,
        p.volume,
        tol,
        src,
    ));
    out.push(Check::relative(
        case,
        "two spheres overlapping by r: moment about the axis per unit density [m⁵]",
        i_axis,
        p.principal.x,
        tol,
        src,
    ));
    // Qian et al. (2022) ball: 615 spheres of 0.5 mm in a 5 mm ball.
    let qian: Vec<(Vec3, f64)> = (0..615).map(|k| (Vec3::new(k as f64 * 1e-3, 0.0, 0.0), 0.25e-3)).collect();
    let t = ClumpTemplate::from_spheres("qian", &qian).with_envelope(sphere_volume(2.5e-3));
    out.push(Check::relative(
        case,
        "solid fraction of 615 spheres of 0.5 mm in a 5 mm ball [-]",
        0.615,
        t.solid_fraction().unwrap_or(f64::NAN),
        1e-12,
        "Qian et al. (2022) CMES 133:2, ball composite",
    ));
    out
}

/// Mass \[kg\] and principal moments \[kg m²\] of `solid` filled with spheres of diameter `d`, envelope
/// mass at density `rho`.
fn fill_inertia(solid: &dyn Solid, d: f64, rho: f64) -> (f64, Vec3) {
    let s = fill_equal(solid, d, "fill").expect("the solid fits its fill spheres");
    let t = ClumpTemplate::from_spheres("fill", &s).with_envelope(solid.volume());
    let (m, i, _) = t.body_mass(rho);
    (m, i)
}

// ---------------------------------------------------------------------------------------------------
// Torque-free rotation

/// Three unequal spheres in a triangle: an asymmetric body (I₁ < I₂ < I₃ well apart).
pub(crate) fn asymmetric(r: f64) -> ClumpTemplate {
    ClumpTemplate::from_spheres(
        "asym",
        &[
            (Vec3::ZERO, r),
            (Vec3::new(1.8 * r, 0.0, 0.0), 0.8 * r),
            (Vec3::new(0.4 * r, 1.5 * r, 0.0), 0.6 * r),
        ],
    )
}

/// One asymmetric body alone in the engine (no walls, no gravity), time step `dt`, started with
/// orientation `q` and space-frame angular velocity `omega`.
pub(crate) fn free_body(dt: f64, q: Quat, omega: Vec3) -> Simulation<HertzMindlin> {
    let mut sim = two_material_sim(&soft(), 0.5, 0.5, dt, Settings::default());
    let t = sim.add_template(asymmetric(1e-2));
    sim.add_clump(t, 0, NewBody { pos: Vec3::ZERO, quat: q, vel: Vec3::X * 0.1, omega })
        .expect("valid template");
    sim
}

/// Largest relative drift of the space-frame angular momentum and the rotational energy and the largest
/// ||q| − 1| of a torque-free body over `steps` steps.
pub(crate) fn torque_free_drift(steps: usize) -> (f64, f64, f64) {
    let q0 = Quat::from_rotation_x(0.3) * Quat::from_rotation_z(1.1);
    let mut sim = free_body(1e-5, q0, Vec3::new(2.0, 5.0, -3.0));
    let b = sim.bodies();
    let l0 = b.angular_momentum(0);
    let e0 = b.rotational_energy(0);
    let (mut dl, mut de, mut dq): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for _ in 0..steps {
        if sim.step().is_err() {
            return (f64::NAN, f64::NAN, f64::NAN);
        }
        let b = sim.bodies();
        dl = dl.max((b.angular_momentum(0) - l0).length() / l0.length());
        de = de.max((b.rotational_energy(0) - e0).abs() / e0);
        dq = dq.max((b.quat[0].length() - 1.0).abs());
    }
    (dl, de, dq)
}

/// A torque-free asymmetric body over 10⁵ steps (quick: 2·10⁴): |L| in space to 1e-10, rotational energy
/// to 1e-8, |q| = 1 to 1e-12 (the tolerances of the verification plan).
pub fn torque_free_body(quick: bool) -> Vec<Check> {
    let case = "clump_torque_free_invariants";
    let steps = if quick { 20_000 } else { 100_000 };
    let (dl, de, dq) = torque_free_drift(steps);
    let label = |s: &str| format!("{s} over {steps} steps [-]");
    vec![
        Check::absolute(case, label("max |L(t) - L(0)| / |L|"), 0.0, dl, 1e-10, SRC_EULER),
        Check::absolute(case, label("max |E_rot(t)/E_rot(0) - 1|"), 0.0, de, 1e-8, SRC_EULER),
        Check::absolute(case, label("max ||q| - 1|"), 0.0, dq, 1e-12, SRC_EULER),
    ]
}

/// Euler's torque-free solution for principal moments `i` (ascending) and body-frame angular momentum
/// `pi`: the time between sign changes of π₂ (the intermediate component; sn of the elliptic solution,
/// zeros 2K(k) apart) \[s\]. Landau & Lifshitz §37: with A = (I₃ − I₂)(M² − 2EI₁), B = (I₂ − I₁)(2EI₃ −
/// M²), the argument runs at √(max(A, B)/(I₁I₂I₃)) and k² = min(A, B)/max(A, B).
pub(crate) fn euler_half_period(i: Vec3, pi: Vec3) -> f64 {
    let m2 = pi.length_squared();
    let two_e = (pi * pi / i).element_sum();
    let a = (i.z - i.y) * (m2 - two_e * i.x);
    let b = (i.y - i.x) * (two_e * i.z - m2);
    // k'² = 1 − k² = |A − B|/max, A − B = (I₃ − I₁)(M² − 2EI₂), M² − 2EI₂ written without cancellation.
    let sep = pi.x * pi.x * (1.0 - i.y / i.x) + pi.z * pi.z * (1.0 - i.y / i.z);
    let big = a.max(b);
    let kp = ((i.z - i.x) * sep.abs() / big).sqrt();
    let rate = (big / (i.x * i.y * i.z)).sqrt();
    2.0 * complete_elliptic_k(kp) / rate
}

/// The complete elliptic integral of the first kind K(k) from the complementary modulus k' = √(1 − k²),
/// by the arithmetic–geometric mean: K = π / (2 AGM(1, k')) (Abramowitz & Stegun 17.6).
pub(crate) fn complete_elliptic_k(kp: f64) -> f64 {
    let (mut a, mut g) = (1.0f64, kp);
    for _ in 0..64 {
        if (a - g).abs() <= 1e-16 * a {
            break;
        }
        (a, g) = (0.5 * (a + g), (a * g).sqrt());
    }
    PI / (2.0 * a)
}

/// Largest |π_j| on the torque-free orbit around the stable axis `a` (0 or 2): where the third component
/// vanishes, π_j² = I_j (2E I_a − M²)/(I_a − I_j) (conservation of M² and E).
pub(crate) fn stable_amplitude(i: Vec3, pi: Vec3, a: usize, j: usize) -> f64 {
    let m2 = pi.length_squared();
    let two_e = (pi * pi / i).element_sum();
    (i[j] * (two_e * i[a] - m2) / (i[a] - i[j])).sqrt()
}

/// What a spin run measured: times of the sign changes of π_axis and the largest |π| components.
pub(crate) struct Spin {
    pub crossings: Vec<f64>,
    pub max_abs: Vec3,
    pub min_along: f64,
    pub inertia: Vec3,
    pub pi0: Vec3,
}

/// Spins the asymmetric body about principal axis `axis` with |π| along it and a 2 % perturbation on the
/// other two, for `steps` steps of `dt`; records the sign changes of π_axis (linearly interpolated) and
/// the extremes of π.
pub(crate) fn spin_about(axis: usize, steps: usize, dt: f64) -> Spin {
    // Inertia first (body frame = space frame for q = 1).
    let probe = free_body(dt, Quat::IDENTITY, Vec3::ZERO);
    let inertia = probe.bodies().inertia(0);
    let mut pi = Vec3::splat(0.02);
    pi[axis] = 1.0;
    // About 20 rad/s about the spin axis.
    let pi = pi * (20.0 * inertia[axis]);
    let mut sim = free_body(dt, Quat::IDENTITY, pi / inertia);
    let mut out = Spin { crossings: Vec::new(), max_abs: Vec3::ZERO, min_along: 1.0, inertia, pi0: pi };
    let mut prev = pi[axis];
    for s in 0..steps {
        if sim.step().is_err() {
            out.crossings.clear();
            out.max_abs = Vec3::splat(f64::NAN);
            return out;
        }
        let p = sim.bodies().angmom[0];
        out.max_abs = out.max_abs.max(p.abs());
        out.min_along = out.min_along.min(p[axis].abs() / p.length());
        if p[axis] * prev < 0.0 {
            let f = prev / (prev - p[axis]);
            out.crossings.push((s as f64 + f) * dt);
        }
        prev = p[axis];
    }
    out
}

/// Rotation about the intermediate principal axis flips periodically (tennis-racket or Dzhanibekov
/// effect), with the half-period of Euler's elliptic solution; about the smallest and largest axes it is
/// stable, and the transverse components stay within the exact orbit's amplitude.
pub fn intermediate_axis(quick: bool) -> Vec<Check> {
    let case = "clump_intermediate_axis_flip";
    // ω Δt = 2·10⁻³: about 12 500 steps per flip.
    let dt = 1e-4;
    let steps = if quick { 40_000 } else { 200_000 };
    let mut out = Vec::new();
    let s = spin_about(1, steps, dt);
    let want = euler_half_period(s.inertia, s.pi0);
    let measured = if s.crossings.len() >= 2 {
        (s.crossings[s.crossings.len() - 1] - s.crossings[0]) / (s.crossings.len() - 1) as f64
    } else {
        f64::NAN
    };
    out.push(Check::relative(
        case,
        format!("intermediate axis: time between flips [s] ({} flips)", s.crossings.len()),
        want,
        measured,
        1e-3,
        SRC_EULER,
    ));
    for a in [0, 2] {
        let s = spin_about(a, steps / 4, dt);
        for j in (0..3).filter(|&j| j != a) {
            out.push(Check::relative(
                case,
                format!("stable axis {}: largest |pi{}| / |pi| [-]", a + 1, j + 1),
                stable_amplitude(s.inertia, s.pi0, a, j) / s.pi0.length(),
                s.max_abs[j] / s.pi0.length(),
                1e-3,
                SRC_EULER,
            ));
        }
        out.push(Check::absolute(
            case,
            format!("stable axis {}: flips [-]", a + 1),
            0.0,
            if s.max_abs.is_nan() { f64::NAN } else { s.crossings.len() as f64 },
            0.0,
            SRC_EULER,
        ));
    }
    out
}

// ---------------------------------------------------------------------------------------------------
// One-sphere clump against the free sphere

/// State of particle 0 after each step: position, velocity, angular velocity as bits.
pub(crate) type Trajectory = Vec<[u64; 9]>;

/// Chung & Ooi (2011) test 4 kind of impact (an Al-oxide sphere, R = 2.5 mm, 3.9 m/s at 30° from the
/// normal, μ = 0.092, e = 0.98) on the shared edge of a two-triangle STL floor, then a second free sphere
/// hits it (a pair contact) — with a free sphere or a one-sphere clump as the first. Returns the
/// trajectory over `steps` steps and whether both a wall and a pair contact happened.
pub(crate) fn one_sphere_trajectory(as_clump: bool, steps: usize) -> (Trajectory, bool) {
    let m = al_oxide();
    let r = 2.5e-3;
    let mut sim = two_material_sim(&m, 0.092, 0.98, 2e-8, Settings::default());
    let l = 8.0 * r;
    sim.add_wall(Wall {
        name: "floor".into(),
        shape: WallShape::Mesh(Box::new(MeshWall::new(TriMesh::rectangle(l, l, 0.0, 1, 1)))),
        material: 1,
        motion: Motion::Fixed,
    });
    let th = 30f64.to_radians();
    let spot = Vec3::new(0.5 * l, 0.5 * l, 0.0);
    let v = 3.9 * Vec3::new(th.sin(), 0.0, -th.cos());
    let x0 = spot + Vec3::new(0.0, 0.0, r + 1e-6) - v * (1e-6 / v.z.abs());
    let w0 = Vec3::new(3.0, -20.0, 7.0);
    if as_clump {
        let t = sim.add_template(ClumpTemplate::from_spheres("one", &[(Vec3::new(0.3, 0.1, 0.2), r)]));
        let q = Quat::from_rotation_z(0.4);
        sim.add_clump(t, 0, NewBody { pos: x0, quat: q, vel: v, omega: w0 }).expect("valid template");
    } else {
        let mut p = crate::NewParticle::at(x0, r, 0);
        p.vel = v;
        p.omega = w0;
        sim.add_particle(p);
    }
    let mut b = crate::NewParticle::at(x0 + Vec3::new(2.0 * r + 2e-5, 0.0, 3e-4), r, 0);
    b.vel = Vec3::new(-1.0, 0.0, 0.0);
    sim.add_particle(b);
    let mut traj = Vec::with_capacity(steps);
    let (mut wall, mut pair) = (false, false);
    for _ in 0..steps {
        if sim.step().is_err() {
            return (traj, false);
        }
        wall |= sim.last_evaluation().wall_contacts > 0;
        pair |= sim.last_evaluation().pair_contacts > 0;
        let p = &sim.particles;
        let Some(i) = p.index_of(0) else { return (traj, false) };
        let mut row = [0u64; 9];
        for (k, v) in [p.pos[i], p.vel[i], p.omega[i]].into_iter().enumerate() {
            for (c, x) in v.to_array().into_iter().enumerate() {
                row[3 * k + c] = x.to_bits();
            }
        }
        traj.push(row);
    }
    (traj, wall && pair)
}

/// A one-sphere clump moves bit for bit like the free sphere through a wall impact on an STL edge and a
/// pair contact.
pub fn one_sphere_clump(quick: bool) -> Vec<Check> {
    let steps = if quick { 4000 } else { 12_000 };
    let (free, ok_f) = one_sphere_trajectory(false, steps);
    let (clump, ok_c) = one_sphere_trajectory(true, steps);
    let differing = free.iter().zip(&clump).filter(|(a, b)| a != b).count();
    let value =
        if ok_f && ok_c && free.len() == steps && clump.len() == steps { differing as f64 } else { f64::NAN };
    vec![Check::absolute(
        "clump_one_sphere_equals_free_sphere",
        format!("steps (of {steps}) where x, v or omega differ in any bit [-]"),
        0.0,
        value,
        0.0,
        "a one-sphere rigid body is the free sphere (Chung & Ooi 2011 test 4 impact on an STL edge, then a pair contact)",
    )]
}

// ---------------------------------------------------------------------------------------------------
// Dumbbell

/// Two equal spheres of radius r touching at the centre of mass, lying along x.
pub(crate) fn dumbbell(r: f64) -> ClumpTemplate {
    ClumpTemplate::from_spheres("dumbbell", &[(Vec3::new(-r, 0.0, 0.0), r), (Vec3::new(r, 0.0, 0.0), r)])
}

/// Throws a body of template `t` with orientation `q` at velocity `v0` \[m/s\] (downwards, v0.z < 0) onto
/// the plane z = 0 (no gravity, soft material on a rigid wall, restitution `e`, friction `mu`, time step
/// `dt` \[s\]) and runs until the contact has ended. Returns the simulation and the velocity before; `None`
/// if it never touched or blew up.
pub(crate) fn drop_on_plane(
    t: ClumpTemplate,
    q: Quat,
    (e, mu): (f64, f64),
    settings: Settings,
    v0: Vec3,
    dt: f64,
) -> Option<(Simulation<HertzMindlin>, Vec3)> {
    let r = t.max_radius();
    let mut sim = two_material_sim(&soft(), mu, e, dt, settings);
    sim.add_wall(Wall {
        name: "floor".into(),
        shape: WallShape::Plane(Plane::new(Vec3::ZERO, Vec3::Z)),
        material: 1,
        motion: Motion::Fixed,
    });
    let ti = sim.add_template(t);
    // The lowest member surface 0.2 r above the floor.
    let low = sim.templates()[ti].spheres.iter().map(|&(c, rr)| (q * c).z - rr).fold(f64::INFINITY, f64::min);
    let x0 = Vec3::new(0.0, 0.0, -low + 0.2 * r);
    sim.add_clump(ti, 0, NewBody { pos: x0, quat: q, vel: v0, omega: Vec3::ZERO }).ok()?;
    let mut touched = false;
    for _ in 0..(0.1 / dt) as usize {
        sim.step().ok()?;
        if sim.last_evaluation().wall_contacts > 0 {
            touched = true;
        } else if touched {
            return Some((sim, v0));
        }
    }
    None
}

/// Restitution of a dumbbell dropped flat: (member share, body mass) contact mass → (e_out, spin × r).
pub(crate) fn dumbbell_flat_restitution(e: f64, mass: ClumpContactMass, dt: f64) -> (f64, f64) {
    let settings = Settings { clump_contact_mass: mass, ..Settings::default() };
    let r = 1e-3;
    match drop_on_plane(dumbbell(r), Quat::IDENTITY, (e, 0.3), settings, Vec3::new(0.0, 0.0, -1.0), dt) {
        Some((sim, v0)) => {
            let b = sim.bodies();
            (b.vel[0].z / -v0.z, b.omega[0].length() * r)
        }
        None => (f64::NAN, f64::NAN),
    }
}

/// The restitution a dumbbell dropped flat realises with the body mass as contact mass: each of the two
/// contacts moves half the body but is damped for the whole, so the dashpot coefficient seen by the
/// moving mass is √2 times the calibrated one; the realised e is that of the scale-free Hertz impact
/// with √2 c (tensile clamp on).
pub(crate) fn dumbbell_flat_body_mass_restitution(e: f64) -> f64 {
    restitution(damping_coefficient(e, 1.5, true) * 2f64.sqrt(), 1.5, true)
}

/// A dumbbell dropped flat on a plane bounces with the restitution its contact mass implies (member
/// share: the pair's e exactly; body mass: the √2-stronger dashpot) and does not spin. The realised e
/// converges to first order in Δt (the dashpot sees the half-step velocity); measured at e = 0.2 with the
/// body mass: −2.2·10⁻³ at 620 steps per contact (Δt = 0.2 µs), −1.2·10⁻³ at 0.1 µs, −6.5·10⁻⁴ at 0.05 µs.
/// The full variant runs at 0.05 µs, the quick one at 0.2 µs.
pub fn dumbbell_flat(quick: bool) -> Vec<Check> {
    let case = "clump_dumbbell_flat";
    let (es, dt): (&[f64], f64) = if quick { (&[0.5], 2e-7) } else { (&[0.2, 0.5, 0.8], 5e-8) };
    let src =
        "Hertz impact with restitution damping (Chung & Ooi 2011 test 3 calibration), two equal contacts";
    let mut out = Vec::new();
    for &e in es {
        let (e_share, spin) = dumbbell_flat_restitution(e, ClumpContactMass::MemberShare, dt);
        out.push(Check::relative(
            case,
            format!("member-share mass, e = {e}: e_out [-]"),
            e,
            e_share,
            2e-3,
            src,
        ));
        out.push(Check::absolute(
            case,
            format!("member-share mass, e = {e}: |omega| r [m/s]"),
            0.0,
            spin,
            1e-9,
            src,
        ));
        let (e_body, _) = dumbbell_flat_restitution(e, ClumpContactMass::Body, dt);
        out.push(Check::relative(
            case,
            format!("body mass, e = {e}: e_out [-]"),
            dumbbell_flat_body_mass_restitution(e),
            e_body,
            2e-3,
            src,
        ));
    }
    out
}

/// What a dumbbell dropped on one end did, against the rigid-body impulse prediction.
pub(crate) struct EndImpact {
    pub v: Vec3,
    pub v_pred: Vec3,
    pub omega: Vec3,
    pub omega_pred: Vec3,
    pub ke: f64,
    pub ke0: f64,
}

/// A dumbbell tilted by `tilt_deg` about y dropped at `speed` on a frictionless plane (e = 1), time step
/// `dt`: for a short elastic impact the impulse is J = 2 v_n / (1/M + (r_c × n)·I⁻¹(r_c × n)) along n,
/// r_c from the centre of mass to the contact point; the body leaves with V = V₀ + J n/M and ω =
/// I⁻¹(r_c × J n). The prediction holds the orientation fixed during the contact; the body turns by an
/// angle ∝ v^{4/5} meanwhile, so the deviation shrinks with the speed and not with Δt (measured at 60°
/// tilt: 0.9 % in ω at 1 m/s, 0.15 % at 0.1 m/s, 0.02 % at 0.01 m/s; the same at Δt = 0.1 and 0.2 µs).
pub(crate) fn dumbbell_end_impact(tilt_deg: f64, speed: f64, dt: f64) -> Option<EndImpact> {
    let r = 1e-3;
    let q = Quat::from_rotation_y(tilt_deg.to_radians());
    let (sim, v0) =
        drop_on_plane(dumbbell(r), q, (1.0, 0.0), Settings::default(), Vec3::new(0.0, 0.0, -speed), dt)?;
    let b = sim.bodies();
    let m = b.mass(0);
    let inertia = b.inertia(0);
    let low = q * Vec3::new(r, 0.0, 0.0);
    let low = if low.z < 0.0 { low } else { -low };
    let rc = low - Vec3::new(0.0, 0.0, r);
    let n = Vec3::Z;
    // Inverse inertia in space at the orientation of the impact (it turns little during the contact).
    let inv_i_space = |v: Vec3| q * ((q.conjugate() * v) / inertia);
    let k = rc.cross(n);
    let j = 2.0 * (-v0.z) / (1.0 / m + k.dot(inv_i_space(k)));
    Some(EndImpact {
        v: b.vel[0],
        v_pred: v0 + n * (j / m),
        omega: b.omega[0],
        omega_pred: inv_i_space(rc.cross(n * j)),
        ke: 0.5 * m * b.vel[0].length_squared() + b.rotational_energy(0),
        ke0: 0.5 * m * v0.length_squared(),
    })
}

/// A dumbbell dropped on one end at 0.1 m/s starts rotating with the angular momentum the impact impulse
/// predicts.
pub fn dumbbell_on_end(quick: bool) -> Vec<Check> {
    let case = "clump_dumbbell_on_end";
    let tilts: &[f64] = if quick { &[30.0] } else { &[15.0, 30.0, 60.0] };
    let mut out = Vec::new();
    for &tilt in tilts {
        const SPEED: f64 = 0.1;
        let d = dumbbell_end_impact(tilt, SPEED, 2e-7);
        let nan = || f64::NAN;
        let (dv, dw, dk) = match &d {
            Some(d) => (
                (d.v - d.v_pred).length() / SPEED,
                (d.omega - d.omega_pred).length() / d.omega_pred.length(),
                (d.ke - d.ke0).abs() / d.ke0,
            ),
            None => (nan(), nan(), nan()),
        };
        let label = |s: &str| format!("tilt {tilt}°: {s} [-]");
        out.push(Check::absolute(case, label("|V - V_pred| / |V0|"), 0.0, dv, 5e-3, SRC_IMPULSE));
        out.push(Check::absolute(
            case,
            label("|omega - omega_pred| / |omega_pred|"),
            0.0,
            dw,
            5e-3,
            SRC_IMPULSE,
        ));
        out.push(Check::absolute(case, label("|KE / KE0 - 1| (elastic)"), 0.0, dk, 1e-3, SRC_IMPULSE));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// K(k) against tabulated values (Abramowitz & Stegun Table 17.1: K(sin 30°) = 1.685750355,
    /// K(sin 60°) = 2.156515648, K(sin 89°) = 5.434909830).
    #[test]
    fn complete_elliptic_integral_matches_the_table() {
        for (deg, k) in [(30.0f64, 1.685_750_355), (60.0, 2.156_515_648), (89.0, 5.434_909_830)] {
            let kp = deg.to_radians().cos();
            assert!((complete_elliptic_k(kp) - k).abs() < 1e-8, "K({deg}°) = {}", complete_elliptic_k(kp));
        }
        assert!((complete_elliptic_k(1.0) - PI / 2.0).abs() < 1e-15);
    }
}
