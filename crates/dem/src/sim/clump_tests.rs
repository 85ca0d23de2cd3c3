//! Rigid multi-sphere bodies in the engine: a one-sphere body against the free sphere, dumbbell impacts,
//! torque-free rotation, energy, thread-count independence and exact resume.

use super::*;
use crate::clump::{ClumpTemplate, NewBody};
use crate::contact::HertzMindlin;
use crate::validation::clumps::{
    drop_on_plane, dumbbell, dumbbell_end_impact, dumbbell_flat_body_mass_restitution,
    dumbbell_flat_restitution, free_body, one_sphere_trajectory, torque_free_drift, two_material_sim,
};
use crate::walls::{Cylinder, MeshWall, Plane, Wall, WallShape};
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use spatter_core::rng::{seeded, RngExt};
use spatter_core::Quat;

fn soft() -> Material {
    Material::new(5e7, 0.3, 2500.0).unwrap()
}

/// A one-sphere clump against the free sphere (the scene of `validation::clumps`): identical bits at
/// every step.
#[test]
fn a_one_sphere_clump_moves_exactly_like_the_free_sphere() {
    let (free, ok) = one_sphere_trajectory(false, 4000);
    assert!(ok, "the free sphere must touch the wall and the partner");
    let (clump, ok) = one_sphere_trajectory(true, 4000);
    assert!(ok, "the clump must touch the wall and the partner");
    for (k, (a, b)) in free.iter().zip(&clump).enumerate() {
        assert_eq!(a, b, "position, velocity or angular velocity differ at step {k}");
    }
}

/// Dropped flat, both members of a dumbbell touch at once and share the load: each contact moves half the
/// body. With the member-share contact mass the body bounces with the pair's restitution e (calibrated
/// exactly for a single Hertz contact; Chung & Ooi test 3 convention). With the body mass as contact mass
/// each contact is damped as for twice its load: the dashpot coefficient seen by the moving mass is √2
/// times the calibrated one, and the realised e is that of the scale-free Hertz impact with √2 c.
#[test]
fn a_dumbbell_dropped_flat_bounces_with_the_restitution_its_contact_mass_implies() {
    for e in [0.5, 0.8] {
        let (e_out, spin) = dumbbell_flat_restitution(e, ClumpContactMass::MemberShare, 2e-7);
        assert!((e_out - e).abs() < 2e-3 * e, "member share: e_out = {e_out}, e = {e}");
        assert!(spin < 1e-9, "no spin from a symmetric impact: {spin}");
        let (e_out, _) = dumbbell_flat_restitution(e, ClumpContactMass::Body, 2e-7);
        let expected = dumbbell_flat_body_mass_restitution(e);
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
    let d = dumbbell_end_impact(30.0, 0.1, 2e-7).expect("the dumbbell touches and leaves the floor");
    assert!((d.v - d.v_pred).length() < 5e-3 * 0.1, "V = {:?}, predicted {:?}", d.v, d.v_pred);
    let w = (d.omega - d.omega_pred).length();
    assert!(w < 5e-3 * d.omega_pred.length(), "ω = {:?}, predicted {:?}", d.omega, d.omega_pred);
    // Elastic: the kinetic energy is back.
    assert!((d.ke - d.ke0).abs() < 1e-3 * d.ke0, "KE {} against {}", d.ke, d.ke0);
}

/// A rigid composite thrown obliquely onto a wall leaves it spinning, turned by the tangential contact
/// force (Qian et al. 2022, CMES, Fig. 3: the rigid multi-sphere stone picks up rotation where a bonded
/// one keeps its orientation). A dumbbell lying across its flight (members at y = ±r), thrown at 45° onto
/// a plane: both members touch at once, so the torques of the normal forces cancel and friction alone
/// turns it — forwards, ω_y > 0 for flight along +x, the sense of rolling. Friction is then the only
/// torque about the centre of mass, with the contact's depth below it as lever arm, so
/// M r v_x + I_yy ω_y is the same before and after the impact (rigid-body impact mechanics, e.g. Brach,
/// *Mechanical Impact Dynamics*, 1991, ch. 4). The engine applies the tangential force at the member's
/// surface, r from its centre along the normal, so this holds to round-off (measured 7e-15 of the
/// friction impulse's M r Δv_x; asserted 1e-9). Without friction the body leaves without spin and with
/// its tangential velocity.
#[test]
fn a_dumbbell_thrown_obliquely_onto_a_wall_spins_up_by_its_friction_torque() {
    let r = 1e-3;
    let q = Quat::from_rotation_z(std::f64::consts::FRAC_PI_2);
    let v0 = Vec3::new(0.1, 0.0, -0.1);
    let (sim, _) =
        drop_on_plane(dumbbell(r), q, (0.5, 0.3), Settings::default(), v0, 2e-7).expect("touches and leaves");
    let b = sim.bodies();
    let (m, v, w) = (b.mass(0), b.vel[0], b.omega[0]);
    let i_yy = (q * ((q.conjugate() * Vec3::Y) * b.inertia(0))).y;
    let friction_share = m * r * (v.x - v0.x);
    let dl = m * r * v.x + i_yy * w.y - m * r * v0.x;
    eprintln!("v = {v:?}, ω = {w:?}; ΔL_y = {dl:e} of the friction impulse's M r Δv_x = {friction_share:e}");
    assert!(v.x < v0.x && v.z > 0.0, "friction slows it along x and it bounces: v = {v:?}");
    assert!(w.y > 0.0, "friction turns it forwards: ω = {w:?}");
    assert!(w.x.abs() + w.z.abs() < 1e-9 * w.y, "the symmetric contacts add no other spin: ω = {w:?}");
    assert!(dl.abs() < 1e-9 * friction_share.abs(), "M r v_x + I ω_y conserved: ΔL = {dl:e}");
    let (sim, _) =
        drop_on_plane(dumbbell(r), q, (0.5, 0.0), Settings::default(), v0, 2e-7).expect("touches and leaves");
    let b = sim.bodies();
    assert!(b.omega[0].length() * r < 1e-12, "no friction, no spin: ω = {:?}", b.omega[0]);
    assert!((b.vel[0].x - v0.x).abs() < 1e-12, "no friction, v_x kept: {:?}", b.vel[0]);
}

/// A torque-free asymmetric body in the engine (no walls, no gravity): over 10⁵ steps the space-frame
/// angular momentum holds to 1e-10, the rotational energy to 1e-8 and |q| = 1 to 1e-12; members stay at
/// their body positions.
#[test]
fn a_torque_free_asymmetric_body_conserves_angular_momentum_and_energy() {
    let (dl, de, dq) = torque_free_drift(100_000);
    assert!(dl < 1e-10, "|ΔL|/|L| = {dl:e}");
    assert!(de < 1e-8, "ΔE/E = {de:e}");
    assert!(dq < 1e-12, "||q| − 1| = {dq:e}");
    let mut sim = free_body(1e-5, Quat::from_rotation_x(0.3), Vec3::new(2.0, 5.0, -3.0));
    sim.run_steps(1000).unwrap();
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
