//! Engine tests: thread-count independence, energy conservation and dissipation, a settled pile.

use super::*;
use crate::contact::{
    Composed, Frictionless, Hertz, HertzMindlin, HertzMindlinRolling, NoDamping, NoRolling,
};
use crate::walls::{MeshWall, Plane, Wall, WallShape};
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use spatter_core::rng::seeded;

/// Six planes around the box [0, l]³ (material `mat`), optionally with the floor as a mesh.
fn box_walls<L: ContactLaw>(sim: &mut Simulation<L>, l: f64, mat: u16, floor_mat: u16, mesh_floor: bool) {
    let planes = [
        (Vec3::ZERO, Vec3::X),
        (Vec3::splat(l), -Vec3::X),
        (Vec3::ZERO, Vec3::Y),
        (Vec3::splat(l), -Vec3::Y),
        (Vec3::splat(l), -Vec3::Z),
    ];
    for (k, (p, n)) in planes.iter().enumerate() {
        sim.add_wall(Wall {
            name: format!("side{k}"),
            shape: WallShape::Plane(Plane::new(*p, *n)),
            material: mat,
            motion: Motion::Fixed,
        });
    }
    let floor = if mesh_floor {
        // A 3 × 3 patch of triangles covering the floor, extended beyond the box.
        let mut m = TriMesh::rectangle(l + 0.2 * l, l + 0.2 * l, 0.0, 3, 3);
        m.map_vertices(|v| v - Vec3::new(0.1 * l, 0.1 * l, 0.0));
        WallShape::Mesh(Box::new(MeshWall::new(m)))
    } else {
        WallShape::Plane(Plane::new(Vec3::ZERO, Vec3::Z))
    };
    sim.add_wall(Wall { name: "floor".into(), shape: floor, material: floor_mat, motion: Motion::Fixed });
}

fn soft() -> Material {
    Material::new(5e7, 0.3, 2500.0).unwrap()
}

fn fill<L: ContactLaw>(sim: &mut Simulation<L>, l: f64, n: u64, d: (f64, f64), speed: f64, seed: u64) {
    let mut rng = seeded(seed, 0);
    let got = crate::validation::bulk::draw_order_fill(l, d, n, &mut rng);
    assert_eq!(got.len() as u64, n);
    use spatter_core::rng::RngExt;
    for (x, r) in got {
        let mut p = crate::NewParticle::at(x, r, 0);
        let u = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        p.vel = u * (2.0 * speed);
        p.omega = Vec3::new(rng.random::<f64>() - 0.5, 0.0, rng.random::<f64>() - 0.5) * (speed / r);
        sim.add_particle(p);
    }
}

#[test]
fn results_are_bit_identical_for_one_and_two_threads() {
    // A dense little pile with friction, damping, rolling-free Hertz–Mindlin, planes and a mesh floor;
    // the colouring groups depend on the data only, so 1 and 2 threads must agree to the bit.
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mats = vec![soft(), Material::new(1e8, 0.3, 2500.0).unwrap()];
            let pairs = uniform_pairs(&mats, 0.5, 0.5);
            let mut sim = Simulation::new(HertzMindlin::default(), mats, pairs, 2e-5, Settings::default());
            sim.gravity = Vec3::new(0.0, 0.0, -9.81);
            box_walls(&mut sim, 0.1, 1, 1, true);
            fill(&mut sim, 0.1, 700, (0.006, 0.009), 0.5, 11);
            sim.run_steps(400).unwrap();
            assert!(sim.rebuild_count() > 2, "lists were rebuilt during the run");
            assert!(sim.last_evaluation().pair_contacts > 20, "{}", sim.last_evaluation().pair_contacts);
            (sim.particles.clone(), sim.energy())
        })
    };
    let (a, ea) = run(1);
    let (b, eb) = run(2);
    assert_eq!(a, b, "particle state differs between 1 and 2 threads");
    assert_eq!(ea.total().to_bits(), eb.total().to_bits());
}

#[test]
fn elastic_box_conserves_energy_and_the_budget_closes_with_friction() {
    // 300 elastic frictionless spheres in a box of planes, no gravity: KE + rotational + elastic must stay
    // constant. Tolerance 2e-3 relative over ~40 collision times per particle with 60 steps per Hertz
    // contact time (velocity Verlet energy error is O(dt²) per contact and does not accumulate).
    let mats = vec![soft()];
    let pairs = uniform_pairs(&mats, 0.0, 1.0);
    let law: Composed<Hertz, NoDamping, Frictionless, NoRolling> = Composed::default();
    let r_min: f64 = 0.004;
    let m_min = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r_min.powi(3);
    let tc = spatter_core::timestep::hertz_time(0.5 * m_min, 0.5 * r_min, pairs.get(0, 0).e_star, 4.0);
    let mut sim = Simulation::new(law, mats.clone(), pairs.clone(), tc / 60.0, Settings::default());
    box_walls(&mut sim, 0.1, 0, 0, false);
    fill(&mut sim, 0.1, 300, (0.008, 0.012), 1.0, 5);
    let e0 = sim.energy().total();
    let mut max_dev: f64 = 0.0;
    for _ in 0..40 {
        sim.run_steps(100).unwrap();
        max_dev = max_dev.max((sim.energy().total() / e0 - 1.0).abs());
    }
    assert!(sim.energy().dissipated == 0.0);
    assert!(max_dev < 2e-3, "elastic energy drift {max_dev}");

    // With Coulomb friction and damping the mechanical energy falls, and mechanical + dissipated stays at
    // its initial value. Tolerance 2.5 %: dissipation is booked with the velocities the forces were
    // evaluated with (half-step velocities under Verlet), an O(Δt) error; at t_c/60 this frictional gas
    // (each particle ~40 collisions) ends 1.0 % off, at t_c/240 0.24 % (measured, first order).
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats,
        uniform_pairs(&[soft()], 0.4, 0.7),
        tc / 60.0,
        Settings::default(),
    );
    box_walls(&mut sim, 0.1, 0, 0, false);
    fill(&mut sim, 0.1, 300, (0.008, 0.012), 1.0, 5);
    let e0 = sim.energy();
    sim.run_steps(4000).unwrap();
    let e1 = sim.energy();
    assert!(e1.mechanical() < 0.8 * e0.mechanical(), "damping works");
    assert!((e1.total() / e0.total() - 1.0).abs() < 0.025, "budget: {} vs {}", e1.total(), e0.total());
}

#[test]
fn damped_contacts_never_gain_energy() {
    // Damped, frictional, with gravity: the mechanical energy (kinetic + rotational + elastic + potential)
    // must never exceed its initial value (tolerance 1e-9 relative for round-off), and must fall.
    let mats = vec![soft()];
    let pairs = uniform_pairs(&mats, 0.5, 0.5);
    let mut sim = Simulation::new(HertzMindlin::default(), mats, pairs, 2e-5, Settings::default());
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    box_walls(&mut sim, 0.1, 0, 0, true);
    fill(&mut sim, 0.1, 300, (0.008, 0.012), 0.5, 9);
    let e0 = sim.energy().mechanical();
    for _ in 0..300 {
        sim.run_steps(10).unwrap();
        let e = sim.energy().mechanical();
        assert!(e <= e0 + 1e-9 * e0.abs(), "energy grew: {e} > {e0}");
    }
    assert!(sim.energy().mechanical() < e0);
}

#[test]
fn settled_pile_rests_and_the_floor_carries_its_weight() {
    // Spheres (with rolling resistance μ_r = 0.05, else free spheres keep rolling for a long time) poured
    // into a box with frictionless side walls settle; then the kinetic energy is below 1e-6 of the
    // potential energy released, and the floor force equals the total weight within 1 % (side walls
    // without friction carry no vertical load, so statics demands exactly the weight).
    let mats = vec![soft(), soft()];
    let mut pairs = uniform_pairs(&mats, 0.5, 0.3);
    pairs = pairs.map(|k, p| {
        let mut p = p.clone();
        if k != 0 {
            p.friction = 0.0;
        }
        p
    });
    let pairs = pairs.map(|_, p| {
        let mut p = p.clone();
        p.rolling_friction = 0.05;
        p
    });
    let mut sim = Simulation::new(HertzMindlinRolling::default(), mats, pairs, 4e-5, Settings::default());
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    box_walls(&mut sim, 0.1, 1, 0, false);
    fill(&mut sim, 0.1, 250, (0.008, 0.012), 0.2, 21);
    let pe0 = sim.energy().potential;
    let weight: f64 = sim.particles.free_mass() * 9.81;
    sim.run_steps(15_000).unwrap();
    let e = sim.energy();
    let floor = sim.walls.len() - 1;
    let f = sim.wall_force(floor);
    assert!(e.kinetic < 1e-6 * (pe0 - e.potential), "still moving: {e:?}");
    // Spin about a single contact normal (a sphere twisting on the floor) meets no resistance without a
    // torsion model, so the rotational energy decays more slowly; it must still be tiny.
    assert!(e.rotational < 1e-5 * (pe0 - e.potential), "still spinning: {e:?}");
    assert!((-f.z / weight - 1.0).abs() < 0.01, "floor force {} N vs weight {weight} N", -f.z);
}

#[test]
fn blow_ups_name_the_particle_the_step_and_the_cause() {
    // Two spheres created overlapping by half a radius: stopped at once, the cause says so.
    let mats = vec![soft()];
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats.clone(),
        uniform_pairs(&mats, 0.5, 0.5),
        1e-6,
        Settings::default(),
    );
    sim.add_particle(crate::NewParticle::at(Vec3::ZERO, 0.01, 0));
    let b = sim.add_particle(crate::NewParticle::at(Vec3::new(0.015, 0.0, 0.0), 0.01, 0));
    match sim.step() {
        Err(crate::DemError::BlowUp { particle, step, what, cause, .. }) => {
            assert!(particle == 0 || particle == b);
            assert_eq!(step, 0);
            assert!(what.contains("overlap") && what.contains(&format!("id {}", 1 - particle)), "{what}");
            assert!(cause.contains("overlapping"), "{cause}");
        }
        other => panic!("expected a blow-up, got {other:?}"),
    }
    // A time step of 5 Rayleigh times: a fast impact on the floor overshoots; the message blames dt.
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats.clone(),
        uniform_pairs(&mats, 0.5, 0.5),
        1.0,
        Settings::default(),
    );
    let mut p = crate::NewParticle::at(Vec3::new(0.0, 0.0, 0.0105), 0.01, 0);
    p.vel = Vec3::new(0.0, 0.0, -5.0);
    sim.add_particle(p);
    sim.dt = 5.0 * sim.rayleigh_time();
    sim.add_wall(Wall {
        name: "floor".into(),
        shape: WallShape::Plane(Plane::new(Vec3::ZERO, Vec3::Z)),
        material: 0,
        motion: Motion::Fixed,
    });
    let err = sim.run_steps(1000).unwrap_err().to_string();
    assert!(err.contains("particle id 0") && err.contains("Rayleigh") && err.contains("step"), "{err}");
}

#[test]
fn a_particle_created_overlapping_is_blamed_on_its_creation_not_on_the_time_step() {
    // A sphere created 60 % of its radius into the floor, with a time step of 5 Rayleigh times as well:
    // the first force evaluation already sees the overlap, so the cause is the creation (naming the
    // wall), with the time step mentioned separately.
    let mats = vec![soft()];
    let new_sim = || {
        let mut sim = Simulation::new(
            HertzMindlin::default(),
            mats.clone(),
            uniform_pairs(&mats, 0.5, 0.5),
            1e-6,
            Settings::default(),
        );
        sim.add_wall(Wall {
            name: "floor".into(),
            shape: WallShape::Plane(Plane::new(Vec3::ZERO, Vec3::Z)),
            material: 0,
            motion: Motion::Fixed,
        });
        sim
    };
    let mut sim = new_sim();
    sim.add_particle(crate::NewParticle::at(Vec3::new(0.0, 0.0, 0.004), 0.01, 0));
    sim.dt = 5.0 * sim.rayleigh_time();
    match sim.step() {
        Err(crate::DemError::BlowUp { particle: 0, step: 0, what, cause, .. }) => {
            assert!(what.starts_with("overlap with wall `floor` is 0.600"), "{what}");
            assert!(cause.starts_with("particle id 0 was created overlapping wall `floor`"), "{cause}");
            assert!(cause.contains("separately, the time step") && cause.contains("Rayleigh"), "{cause}");
        }
        other => panic!("expected a blow-up, got {other:?}"),
    }
    // A sphere resting on the floor for 100 steps, then a second one added half a radius into it: the
    // blow-up comes at the later step and names the new particle and its partner.
    let mut sim = new_sim();
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    sim.add_particle(crate::NewParticle::at(Vec3::new(0.0, 0.0, 0.01), 0.01, 0));
    sim.run_steps(100).unwrap();
    let b = sim.add_particle(crate::NewParticle::at(Vec3::new(0.0, 0.0, 0.025), 0.01, 0));
    let err = sim.step().unwrap_err().to_string();
    assert!(err.contains("at step 100") && err.contains("overlap with particle id"), "{err}");
    assert!(err.contains(&format!("particle id {b} was created overlapping particle id 0")), "{err}");
    // Deep overlaps reached by motion are not blamed on creation: see the time-step case above.
}

#[test]
fn switching_off_energy_bookkeeping_leaves_the_motion_unchanged() {
    let run = |energy: bool| {
        let mats = vec![soft()];
        let law = HertzMindlin { energy, ..Default::default() };
        let mut sim =
            Simulation::new(law, mats.clone(), uniform_pairs(&mats, 0.5, 0.5), 2e-5, Settings::default());
        sim.gravity = Vec3::new(0.0, 0.0, -9.81);
        box_walls(&mut sim, 0.1, 0, 0, true);
        fill(&mut sim, 0.1, 200, (0.008, 0.012), 0.5, 3);
        sim.run_steps(300).unwrap();
        (sim.particles.clone(), sim.energy())
    };
    let (a, ea) = run(true);
    let (b, eb) = run(false);
    assert_eq!(a, b, "forces must not depend on the bookkeeping");
    assert!(ea.dissipated > 0.0 && eb.dissipated == 0.0 && eb.elastic == 0.0);
}

#[test]
fn external_force_hook_and_persistent_forces_act_and_are_booked() {
    // No gravity; a constant hook force F on one sphere for time t gives v = F t / m (exact under Verlet
    // for a constant force) and the external work ½ m v² (tolerance 1e-9 relative).
    struct Push(Vec3);
    impl ExternalForces for Push {
        fn add(&mut self, _t: f64, p: &ParticleView, f: &mut [Vec3], _tq: &mut [Vec3]) {
            for (i, id) in p.id.iter().enumerate() {
                if *id == 0 {
                    f[i] += self.0;
                }
            }
        }
    }
    let mats = vec![soft()];
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats.clone(),
        uniform_pairs(&mats, 0.5, 0.5),
        1e-4,
        Settings::default(),
    );
    sim.add_particle(crate::NewParticle::at(Vec3::ZERO, 0.01, 0));
    sim.add_particle(crate::NewParticle::at(Vec3::new(1.0, 0.0, 0.0), 0.01, 0));
    sim.set_external_forces(Box::new(Push(Vec3::new(0.0, 0.02, 0.0))));
    sim.particles.external_force_mut().0[1] = Vec3::new(0.0, 0.0, -0.01);
    sim.run_steps(1000).unwrap();
    let i0 = sim.particles.index_of(0).unwrap();
    let i1 = sim.particles.index_of(1).unwrap();
    let m = sim.particles.mass(i0);
    let t = sim.time();
    assert!((sim.particles.vel[i0].y / (0.02 * t / m) - 1.0).abs() < 1e-9);
    assert!((sim.particles.vel[i1].z / (-0.01 * t / m) - 1.0).abs() < 1e-9);
    let e = sim.energy();
    // Work booked with the half-step velocities: exact for a constant force.
    assert!((e.external_work / e.kinetic - 1.0).abs() < 1e-9, "{e:?}");
}

#[test]
fn a_rising_floor_lifts_a_sphere_and_the_wall_work_closes_the_budget() {
    // A plane moving up at 0.05 m/s under a resting sphere: the sphere ends up riding on it at the same
    // speed, and mechanical + dissipated − wall work stays at its initial value (1 % tolerance, see the
    // bookkeeping note above).
    let mats = vec![soft()];
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats.clone(),
        uniform_pairs(&mats, 0.5, 0.5),
        2e-5,
        Settings::default(),
    );
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    sim.add_wall(Wall {
        name: "lift".into(),
        shape: WallShape::Plane(Plane::new(Vec3::ZERO, Vec3::Z)),
        material: 0,
        motion: Motion::Translation { velocity: Vec3::new(0.0, 0.0, 0.05) },
    });
    sim.add_particle(crate::NewParticle::at(Vec3::new(0.0, 0.0, 0.0101), 0.01, 0));
    let e0 = sim.energy().total();
    sim.run_steps(25_000).unwrap();
    assert!((sim.particles.vel[0].z - 0.05).abs() < 1e-3, "{}", sim.particles.vel[0]);
    let e = sim.energy();
    assert!(e.wall_work > 0.0);
    assert!((e.total() - e0).abs() < 0.01 * e.wall_work, "{e:?} vs {e0}");
}

#[test]
fn cylinder_walls_contain_from_inside_and_repel_from_outside() {
    use crate::walls::Cylinder;
    let mats = vec![soft()];
    let cyl = |inside: bool| {
        WallShape::Cylinder(Cylinder {
            point: Vec3::ZERO,
            axis: Vec3::Z,
            radius: 0.05,
            inside,
            axial_min: f64::NEG_INFINITY,
            axial_max: f64::INFINITY,
        })
    };
    for inside in [true, false] {
        let mut sim = Simulation::new(
            HertzMindlin::default(),
            mats.clone(),
            uniform_pairs(&mats, 0.0, 1.0),
            1e-5,
            Settings::default(),
        );
        sim.add_wall(Wall { name: "c".into(), shape: cyl(inside), material: 0, motion: Motion::Fixed });
        let x = if inside { 0.03 } else { 0.08 };
        let mut p = crate::NewParticle::at(Vec3::new(x, 0.0, 0.0), 0.01, 0);
        p.vel = Vec3::new(if inside { 1.0 } else { -1.0 }, 0.0, 0.0);
        sim.add_particle(p);
        sim.run_steps(3000).unwrap();
        // Elastic and frictionless: the radial velocity is reversed, the speed kept (1e-3).
        let v = sim.particles.vel[0];
        assert!((v.x + p.vel.x).abs() < 1e-3 && v.y.abs() < 1e-9, "inside {inside}: {v}");
        let r = sim.particles.pos[0].truncate().length();
        assert!(if inside { r < 0.04 } else { r > 0.06 }, "inside {inside}: r = {r}");
    }
}

/// Runs `n` steps, asking for the energy budget in the last one (residual method).
fn run_to_output<L: ContactLaw>(sim: &mut Simulation<L>, n: u64) {
    sim.run_steps(n - 1).unwrap();
    sim.request_energy();
    sim.run_steps(1).unwrap();
}

#[test]
fn residual_energy_method_leaves_the_motion_unchanged_and_matches_the_per_contact_budget() {
    // The damped, frictional gas of the energy test above, with gravity and a mesh floor, once with
    // per-contact bookkeeping and once with the residual method. The trajectories must agree to the bit,
    // the elastic energy of the requested output steps too. The residual closes the budget by construction,
    // so the two dissipations differ exactly by the closure error of the per-contact budget (its O(Δt)
    // half-step error, bounded by 2.5 % in the test above) plus the residual's O(Δt²) integrator error:
    // tolerance 2.5 % of the initial mechanical energy above the rest state (measured 1.05 % at this
    // Δt = 2e-5 s; under 1 % at Δt = 1e-5 s, i.e. first order as expected of the per-contact sum).
    let run = |method: EnergyMethod| {
        let mats = vec![soft()];
        let mut sim =
            Simulation::new(HertzMindlin::default(), mats.clone(), uniform_pairs(&mats, 0.4, 0.7), 2e-5, {
                Settings::default()
            });
        sim.energy_method = method;
        sim.gravity = Vec3::new(0.0, 0.0, -9.81);
        box_walls(&mut sim, 0.1, 0, 0, true);
        fill(&mut sim, 0.1, 250, (0.008, 0.012), 0.5, 4);
        let e0 = sim.energy();
        let mut series = Vec::new();
        for _ in 0..30 {
            run_to_output(&mut sim, 50);
            series.push(sim.energy());
        }
        (sim.particles.clone(), e0, series)
    };
    let (pa, e0, sa) = run(EnergyMethod::PerContact);
    let (pb, e0b, sb) = run(EnergyMethod::Residual);
    assert_eq!(pa, pb, "the energy method must not change the motion");
    assert_eq!(e0, e0b);
    // Energy above the lowest possible potential (all particles on the floor): a scale for the tolerance.
    let scale = e0.kinetic + e0.rotational + e0.potential - sb.last().unwrap().potential;
    let mut prev = 0.0;
    for (a, b) in sa.iter().zip(&sb) {
        assert_eq!(a.elastic.to_bits(), b.elastic.to_bits());
        assert_eq!(a.kinetic.to_bits(), b.kinetic.to_bits());
        assert!(
            (a.dissipated - b.dissipated).abs() < 0.025 * scale,
            "{} vs {} (scale {scale})",
            a.dissipated,
            b.dissipated
        );
        // The residual dissipation grows (the integrator's error is far below the dissipation per output
        // interval here; 1e-6 of the scale allows for it).
        assert!(b.dissipated >= prev - 1e-6 * scale, "dissipation fell: {} after {prev}", b.dissipated);
        prev = b.dissipated;
    }
    assert!(prev > 0.3 * scale, "the gas lost energy: {prev} of {scale}");
}

#[test]
fn residual_energy_method_shows_only_the_integrator_error_for_elastic_contacts() {
    // The elastic box of `elastic_box_conserves_energy_and_the_budget_closes_with_friction` under the
    // residual method: nothing is dissipated, so the residual is the velocity Verlet energy error, bounded
    // by the same 2e-3 of the total energy.
    let mats = vec![soft()];
    let pairs = uniform_pairs(&mats, 0.0, 1.0);
    let law: Composed<Hertz, NoDamping, Frictionless, NoRolling> = Composed::default();
    let r_min: f64 = 0.004;
    let m_min = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r_min.powi(3);
    let tc = spatter_core::timestep::hertz_time(0.5 * m_min, 0.5 * r_min, pairs.get(0, 0).e_star, 4.0);
    let mut sim = Simulation::new(law, mats, pairs, tc / 60.0, Settings::default());
    sim.energy_method = EnergyMethod::Residual;
    box_walls(&mut sim, 0.1, 0, 0, false);
    fill(&mut sim, 0.1, 300, (0.008, 0.012), 1.0, 5);
    let e0 = sim.energy().total();
    let mut max_dev: f64 = 0.0;
    let mut booked = 0;
    for _ in 0..40 {
        run_to_output(&mut sim, 100);
        let e = sim.energy();
        max_dev = max_dev.max((e.dissipated / e0).abs());
        booked += u32::from(e.elastic > 0.0);
    }
    assert!(max_dev < 2e-3, "residual {max_dev}");
    assert!(booked > 10, "the requested steps booked the elastic energy ({booked} of 40 with contacts)");
}

#[test]
fn residual_energy_method_accounts_for_inserted_and_removed_particles() {
    // Particles fall freely under gravity (no contacts) out of the domain, more are added during the run.
    // Velocity Verlet integrates a constant force exactly, so nothing may appear as dissipated but the
    // error of taking a removed particle's energy between the kicks, at most m g²Δt²/8 each (see
    // `rebuild`), plus round-off (1e-12 of the energy that passed through).
    let mats = vec![soft()];
    let settings = Settings {
        domain: Some(Aabb::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 2.0))),
        ..Default::default()
    };
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats.clone(),
        uniform_pairs(&mats, 0.5, 0.5),
        1e-4,
        settings,
    );
    sim.energy_method = EnergyMethod::Residual;
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    let mut scale: f64 = 0.0;
    for k in 0..20 {
        let mut p =
            crate::NewParticle::at(Vec3::new(0.05 * k as f64 - 0.5, 0.0, 0.9 - 0.09 * k as f64), 0.01, 0);
        p.vel = Vec3::new(0.1, -0.2, 0.3 * k as f64 - 2.0);
        p.omega = Vec3::new(3.0, 0.0, 1.0);
        sim.add_particle(p);
    }
    for round in 0..10 {
        run_to_output(&mut sim, 500);
        let e = sim.energy();
        scale = scale.max(e.kinetic);
        let m = sim.particles.mass(0);
        let bound = sim.removed_count() as f64 * m * 9.81f64.powi(2) * 1e-8 / 8.0 + 1e-12 * scale;
        assert!(e.dissipated.abs() <= bound, "round {round}: residual {} > {bound}", e.dissipated);
        let mut p = crate::NewParticle::at(Vec3::new(0.1 * round as f64, 0.3, 0.5), 0.01, 0);
        p.vel = Vec3::new(0.0, 0.0, 1.0);
        sim.add_particle(p);
    }
    assert!(sim.removed_count() > 10, "particles left the domain: {}", sim.removed_count());
}
