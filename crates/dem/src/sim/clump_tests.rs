//! Rigid multi-sphere bodies in the engine: a one-sphere body against the free sphere, dumbbell impacts,
//! torque-free rotation, energy, thread-count independence and exact resume.

use super::*;
use crate::clump::{ClumpTemplate, NewBody};
use crate::contact::restitution_fit::{damping_coefficient, restitution};
use crate::contact::{HertzMindlin, PairProps, PairTable};
use crate::validation::impact::rigid;
use crate::walls::{Cylinder, MeshWall, Plane, Wall, WallShape};
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use spatter_core::rng::{seeded, RngExt};
use spatter_core::Quat;

fn al_oxide() -> Material {
    Material { youngs_modulus: 380e9, poisson_ratio: 0.23, density: 4000.0 }
}

fn soft() -> Material {
    Material::new(5e7, 0.3, 2500.0).unwrap()
}

fn two_material_sim(m: &Material, mu: f64, e: f64, dt: f64, settings: Settings) -> Simulation<HertzMindlin> {
    let wall = rigid(m.poisson_ratio);
    let mats = vec![m.clone(), wall];
    let pairs = PairTable::build(2, |a, b| PairProps::new(&mats[a], &mats[b], mu, e));
    Simulation::new(HertzMindlin::default(), mats, pairs, dt, settings)
}

/// The two-triangle square of side `l` in the plane z = 0 (diagonal from the origin), as a mesh wall.
fn square_mesh(l: f64) -> WallShape {
    WallShape::Mesh(Box::new(MeshWall::new(TriMesh::rectangle(l, l, 0.0, 1, 1))))
}

/// Chung & Ooi (2011) test 4 (oblique impact of an Al-oxide sphere, R = 2.5 mm, 3.9 m/s at 30° from the
/// normal, μ = 0.092, e = 0.98) on the shared edge of a two-triangle STL floor, then a second free sphere
/// hits it head-on (test 1 kind of pair contact) — once with a free sphere and once with a one-sphere
/// clump. The trajectories must be identical bit for bit.
#[test]
fn a_one_sphere_clump_moves_exactly_like_the_free_sphere() {
    let run = |as_clump: bool| {
        let m = al_oxide();
        let r = 2.5e-3;
        let mut sim = two_material_sim(&m, 0.092, 0.98, 2e-8, Settings::default());
        let l = 8.0 * r;
        sim.add_wall(Wall {
            name: "floor".into(),
            shape: square_mesh(l),
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
            sim.add_clump(t, 0, NewBody { pos: x0, quat: q, vel: v, omega: w0 }).unwrap();
        } else {
            let mut p = crate::NewParticle::at(x0, r, 0);
            p.vel = v;
            p.omega = w0;
            sim.add_particle(p);
        }
        // A free partner that meets the rebounding sphere.
        let mut b = crate::NewParticle::at(x0 + Vec3::new(2.0 * r + 2e-5, 0.0, 3e-4), r, 0);
        b.vel = Vec3::new(-1.0, 0.0, 0.0);
        sim.add_particle(b);
        let mut traj = Vec::new();
        let mut touched = (false, false);
        for _ in 0..4000 {
            sim.step().unwrap();
            touched.0 |= sim.last_evaluation().wall_contacts > 0;
            touched.1 |= sim.last_evaluation().pair_contacts > 0;
            let p = &sim.particles;
            let i = p.index_of(0).unwrap();
            traj.push((p.pos[i], p.vel[i], p.omega[i], p.force[i], p.torque[i]));
        }
        assert!(touched.0 && touched.1, "both contacts must happen: {touched:?}");
        traj
    };
    let free = run(false);
    let clump = run(true);
    let bits = |v: Vec3| v.to_array().map(f64::to_bits);
    for (k, (a, b)) in free.iter().zip(&clump).enumerate() {
        assert_eq!(bits(a.0), bits(b.0), "position at step {k}");
        assert_eq!(bits(a.1), bits(b.1), "velocity at step {k}");
        assert_eq!(bits(a.2), bits(b.2), "angular velocity at step {k}");
    }
}

/// Two equal spheres of radius r touching at the centre of mass, lying along x.
fn dumbbell(r: f64) -> ClumpTemplate {
    ClumpTemplate::from_spheres("dumbbell", &[(Vec3::new(-r, 0.0, 0.0), r), (Vec3::new(r, 0.0, 0.0), r)])
}

/// Drops a body of template `t` with orientation `q` at speed `v` onto the plane z = 0 (no gravity) and
/// returns (v before, v after, ω after, the body).
fn drop_on_plane(
    t: ClumpTemplate,
    q: Quat,
    e: f64,
    mu: f64,
    settings: Settings,
) -> (Simulation<HertzMindlin>, Vec3, f64) {
    let m = soft();
    let r = t.max_radius();
    let mut sim = two_material_sim(&m, mu, e, 2e-7, settings);
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
    let v0 = Vec3::new(0.0, 0.0, -1.0);
    sim.add_clump(ti, 0, NewBody { pos: x0, quat: q, vel: v0, omega: Vec3::ZERO }).unwrap();
    let mut touched = false;
    for _ in 0..200_000 {
        sim.step().unwrap();
        let c = sim.last_evaluation().wall_contacts > 0;
        if c {
            touched = true;
        } else if touched {
            break;
        }
    }
    assert!(touched);
    (sim, v0, r)
}

/// Dropped flat, both members of a dumbbell touch at once and share the load: each contact moves half the
/// body. With the member-share contact mass the body bounces with the pair's restitution e (calibrated
/// exactly for a single Hertz contact; Chung & Ooi test 3 convention). With the body mass as contact mass
/// each contact is damped as for twice its load: the dashpot coefficient seen by the moving mass is √2
/// times the calibrated one, and the realised e is that of the scale-free Hertz impact with √2 c.
#[test]
fn a_dumbbell_dropped_flat_bounces_with_the_restitution_its_contact_mass_implies() {
    for e in [0.5, 0.8] {
        let share = Settings { clump_contact_mass: ClumpContactMass::MemberShare, ..Settings::default() };
        let (sim, v0, r) = drop_on_plane(dumbbell(1e-3), Quat::IDENTITY, e, 0.3, share);
        let b = sim.bodies();
        let e_out = b.vel[0].z / -v0.z;
        assert!((e_out - e).abs() < 2e-3 * e, "member share: e_out = {e_out}, e = {e}");
        assert!(b.omega[0].length() * r < 1e-9, "no spin from a symmetric impact: {:?}", b.omega[0]);

        let (sim, v0, _) = drop_on_plane(dumbbell(1e-3), Quat::IDENTITY, e, 0.3, Settings::default());
        let e_out = sim.bodies().vel[0].z / -v0.z;
        let c = damping_coefficient(e, 1.5, true);
        let expected = restitution(c * 2f64.sqrt(), 1.5, true);
        assert!(
            (e_out - expected).abs() < 2e-3 * expected,
            "body mass: e_out = {e_out}, expected {expected}"
        );
        assert!(e_out < e);
    }
}

/// Dropped tilted, a dumbbell touches with its lower end only. For a short elastic frictionless impact the
/// impulse is J = 2 v_n / (1/M + (r_c × n)·I⁻¹(r_c × n)) along n (rigid-body impact with e = 1, e.g.
/// Brach, *Mechanical Impact Dynamics*, 1991, ch. 4), r_c from the centre of mass to the contact point:
/// the body leaves with V = V₀ + J n/M and ω = I⁻¹(r_c × J n).
#[test]
fn a_dumbbell_dropped_on_one_end_spins_up_as_the_impulse_predicts() {
    let r = 1e-3;
    let tilt = 30f64.to_radians();
    let q = Quat::from_rotation_y(tilt);
    let (sim, v0, _) = drop_on_plane(dumbbell(r), q, 1.0, 0.0, Settings::default());
    let b = sim.bodies();
    let m = b.mass(0);
    let inertia = b.inertia(0);
    // The lower member is the one at +x rotated by +30° about y (z = −r sin 30°); contact point below it.
    let low = q * Vec3::new(r, 0.0, 0.0);
    let low = if low.z < 0.0 { low } else { -low };
    let rc = low - Vec3::new(0.0, 0.0, r);
    let n = Vec3::Z;
    // Inverse inertia in space at the orientation of the impact (it turns little during the contact).
    let inv_i_space = |v: Vec3| q * ((q.conjugate() * v) / inertia);
    let k = rc.cross(n);
    let j = 2.0 * (-v0.z) / (1.0 / m + k.dot(inv_i_space(k)));
    let v_pred = v0 + n * (j / m);
    let w_pred = inv_i_space(rc.cross(n * j));
    let (v, w) = (b.vel[0], b.omega[0]);
    assert!((v - v_pred).length() < 5e-3 * v0.length(), "V = {v:?}, predicted {v_pred:?}");
    assert!((w - w_pred).length() < 5e-3 * w_pred.length(), "ω = {w:?}, predicted {w_pred:?}");
    // Elastic: the kinetic energy is back.
    let ke0 = 0.5 * m * v0.length_squared();
    let ke = 0.5 * m * v.length_squared() + b.rotational_energy(0);
    assert!((ke - ke0).abs() < 1e-3 * ke0, "KE {ke} against {ke0}");
}

/// Three unequal spheres in a triangle: an asymmetric body.
fn asymmetric(r: f64) -> ClumpTemplate {
    ClumpTemplate::from_spheres(
        "asym",
        &[
            (Vec3::ZERO, r),
            (Vec3::new(1.8 * r, 0.0, 0.0), 0.8 * r),
            (Vec3::new(0.4 * r, 1.5 * r, 0.0), 0.6 * r),
        ],
    )
}

/// A torque-free asymmetric body in the engine (no walls, no gravity): over 10⁵ steps the space-frame
/// angular momentum holds to 1e-10, the rotational energy to 1e-8 and |q| = 1 to 1e-12; members stay at
/// their body positions.
#[test]
fn a_torque_free_asymmetric_body_conserves_angular_momentum_and_energy() {
    let m = soft();
    let mut sim = two_material_sim(&m, 0.5, 0.5, 1e-5, Settings::default());
    let t = sim.add_template(asymmetric(1e-2));
    let q0 = Quat::from_rotation_x(0.3) * Quat::from_rotation_z(1.1);
    sim.add_clump(
        t,
        0,
        NewBody { pos: Vec3::ZERO, quat: q0, vel: Vec3::X * 0.1, omega: Vec3::new(2.0, 5.0, -3.0) },
    )
    .unwrap();
    let b = sim.bodies();
    let l0 = b.angular_momentum(0);
    let e0 = b.rotational_energy(0);
    let (mut dl, mut de, mut dq): (f64, f64, f64) = (0.0, 0.0, 0.0);
    for _ in 0..100_000 {
        sim.step().unwrap();
        let b = sim.bodies();
        dl = dl.max((b.angular_momentum(0) - l0).length() / l0.length());
        de = de.max((b.rotational_energy(0) - e0).abs() / e0);
        dq = dq.max((b.quat[0].length() - 1.0).abs());
    }
    assert!(dl < 1e-10, "|ΔL|/|L| = {dl:e}");
    assert!(de < 1e-8, "ΔE/E = {de:e}");
    assert!(dq < 1e-12, "||q| − 1| = {dq:e}");
    let b = sim.bodies();
    let tpl = &sim.templates()[0];
    for (k, &(c, _)) in tpl.spheres.iter().enumerate() {
        let i = sim.particles.index_of(b.first_id[0] + k as u32).unwrap();
        let want = b.pos[0] + b.quat[0] * c;
        assert!((sim.particles.pos[i] - want).length() < 1e-15, "member {k} off its body");
        let vw = b.vel[0] + b.omega[0].cross(b.quat[0] * c);
        assert!((sim.particles.vel[i] - vw).length() < 1e-12);
    }
}

/// Four overlapping spheres on the corners of a tetrahedron (edge 1.6 r).
fn tetra(r: f64) -> ClumpTemplate {
    let a = 0.8 * r;
    let pts = [
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(-1.0, -1.0, 1.0),
    ];
    let s: Vec<(Vec3, f64)> = pts.iter().map(|&p| (p * (a / 2f64.sqrt()), r)).collect();
    ClumpTemplate::from_spheres("tetra", &s)
}

/// A box [0, l]³ of planes with a mesh floor, a post (cylinder, outside) and a slowly turning side wall,
/// with clumps of two templates and free spheres thrown around at random.
fn clump_box(e: f64, mu: f64, gravity: bool, seed: u64) -> Simulation<HertzMindlin> {
    let m = soft();
    let l = 0.1;
    let mut sim = two_material_sim(&m, mu, e, 2e-6, Settings::default());
    if gravity {
        sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    }
    for (k, (p, n)) in [
        (Vec3::ZERO, Vec3::X),
        (Vec3::splat(l), -Vec3::X),
        (Vec3::ZERO, Vec3::Y),
        (Vec3::splat(l), -Vec3::Y),
        (Vec3::splat(l), -Vec3::Z),
    ]
    .into_iter()
    .enumerate()
    {
        sim.add_wall(Wall {
            name: format!("side{k}"),
            shape: WallShape::Plane(Plane::new(p, n)),
            material: 1,
            motion: Motion::Fixed,
        });
    }
    let mut floor = TriMesh::rectangle(1.2 * l, 1.2 * l, 0.0, 3, 3);
    floor.map_vertices(|v| v - Vec3::new(0.1 * l, 0.1 * l, 0.0));
    sim.add_wall(Wall {
        name: "floor".into(),
        shape: WallShape::Mesh(Box::new(MeshWall::new(floor))),
        material: 1,
        motion: Motion::Fixed,
    });
    sim.add_wall(Wall {
        name: "post".into(),
        shape: WallShape::Cylinder(Cylinder {
            point: Vec3::new(0.5 * l, 0.5 * l, 0.0),
            axis: Vec3::Z,
            radius: 0.01,
            inside: false,
            axial_min: f64::NEG_INFINITY,
            axial_max: f64::INFINITY,
        }),
        material: 1,
        motion: Motion::Rotation {
            center: Vec3::new(0.5 * l, 0.5 * l, 0.0),
            axis: Vec3::Z,
            angular_speed: 3.0,
        },
    });
    let r = 4e-3;
    let t1 = sim.add_template(tetra(r));
    let t2 = sim.add_template(dumbbell(r));
    let mut rng = seeded(seed, 0);
    let mut placed: Vec<(Vec3, f64)> = Vec::new();
    let mut tries = 0;
    while placed.len() < 30 && tries < 100_000 {
        tries += 1;
        let kind = placed.len() % 3;
        let rad = match kind {
            0 => sim.templates()[t1].bounding_radius(),
            1 => sim.templates()[t2].bounding_radius(),
            _ => r,
        };
        let x = Vec3::new(rng.random::<f64>(), rng.random::<f64>(), rng.random::<f64>())
            * (l - 2.0 * rad - 0.004)
            + Vec3::splat(rad + 0.002);
        let post = Vec3::new(0.5 * l, 0.5 * l, x.z);
        if (x - post).length() < 0.01 + rad + 1e-3
            || placed.iter().any(|&(y, ry)| (x - y).length() < rad + ry)
        {
            continue;
        }
        placed.push((x, rad));
        let v = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        let q = Quat::from_scaled_axis(
            Vec3::new(rng.random::<f64>(), rng.random::<f64>(), rng.random::<f64>()) * 3.0,
        );
        let w = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5)
            * 100.0;
        match kind {
            0 => sim.add_clump(t1, 0, NewBody { pos: x, quat: q, vel: v, omega: w }).map(|_| ()).unwrap(),
            1 => sim.add_clump(t2, 0, NewBody { pos: x, quat: q, vel: v, omega: w }).map(|_| ()).unwrap(),
            _ => {
                let mut p = crate::NewParticle::at(x, r, 0);
                p.vel = v;
                sim.add_particle(p);
            }
        }
    }
    assert_eq!(placed.len(), 30);
    sim
}

/// Elastic contacts (e = 1) with friction among clumps, spheres, planes, an STL floor and a turning post:
/// the mechanical energy never grows beyond the work of the moving wall plus the integrator's O(Δt²)
/// error, and the per-contact budget closes.
#[test]
fn energy_never_grows_in_elastic_clump_collisions_and_the_budget_closes() {
    let mut sim = clump_box(1.0, 0.3, false, 3);
    let e0 = sim.energy();
    let scale = e0.kinetic + e0.rotational;
    let mut contacts = 0;
    for _ in 0..20 {
        sim.run_steps(500).unwrap();
        let e = sim.energy();
        contacts += e.pair_contacts + e.wall_contacts;
        let mech = e.kinetic + e.rotational + e.elastic;
        assert!(
            mech - e.wall_work <= scale * (1.0 + 2e-3),
            "energy grew: {mech} (wall work {})",
            e.wall_work
        );
        assert!(
            (e.total() - e0.total()).abs() < 1e-2 * scale,
            "budget: {} against {}",
            e.total(),
            e0.total()
        );
    }
    assert!(contacts > 0);
}

fn snapshot(sim: &Simulation<HertzMindlin>) -> Vec<u64> {
    let p = &sim.particles;
    let b = sim.bodies();
    let mut out = Vec::new();
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by_key(|&i| p.id[i]);
    for i in order {
        for v in [p.pos[i], p.vel[i], p.omega[i]] {
            out.extend(v.to_array().map(f64::to_bits));
        }
    }
    for k in 0..b.len() {
        out.extend(b.quat[k].to_array().map(f64::to_bits));
        out.extend(b.angmom[k].to_array().map(f64::to_bits));
    }
    out
}

#[test]
fn clump_runs_are_bit_identical_for_one_and_two_threads() {
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut sim = clump_box(0.5, 0.5, true, 7);
            sim.run_steps(3000).unwrap();
            snapshot(&sim)
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn an_interrupted_and_resumed_clump_run_is_bit_identical() {
    let mut whole = clump_box(0.5, 0.5, true, 11);
    whole.run_steps(3000).unwrap();
    let mut first = clump_box(0.5, 0.5, true, 11);
    first.run_steps(1700).unwrap();
    let bytes = bincode::serialize(&first.state()).unwrap();
    drop(first);
    let mut second = clump_box(0.5, 0.5, true, 11);
    second.restore(bincode::deserialize(&bytes).unwrap()).unwrap();
    second.run_steps(1300).unwrap();
    assert_eq!(snapshot(&whole), snapshot(&second));
}

/// Free fall: a clump under gravity alone follows x₀ + ½ g t² (velocity Verlet is exact for a constant
/// force).
#[test]
fn a_clump_falls_freely_under_gravity() {
    let m = soft();
    let mut sim = two_material_sim(&m, 0.5, 0.5, 1e-4, Settings::default());
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    let t = sim.add_template(tetra(1e-3));
    sim.add_clump(t, 0, NewBody::at(Vec3::new(0.0, 0.0, 1.0), Quat::from_rotation_x(0.3))).unwrap();
    sim.run_steps(1000).unwrap();
    let b = sim.bodies();
    let want = 1.0 - 0.5 * 9.81 * 0.1f64.powi(2);
    assert!((b.pos[0].z - want).abs() < 1e-12, "z = {}, want {want}", b.pos[0].z);
    assert!((b.vel[0].z + 9.81 * 0.1).abs() < 1e-12);
}
