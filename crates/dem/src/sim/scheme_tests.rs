//! Tests of the study integrators (FE, RK2, RK4, AB2, AB4, ABM4, BD1, BD2, BD4) on particle assemblies:
//! nominal orders on a smooth contact problem, contact history advanced once per step, bit-for-bit
//! resume from a checkpoint with the multi-step history, thread-count independence, bad settings.

use super::tests::{box_walls, fill, sandwiched_oscillator, soft};
use super::*;
use crate::contact::{Composed, Hooke, HookeStiffness, LinearHistory, NoDamping, NoRolling};
use crate::integrators::Scheme;
use crate::walls::{Plane, Wall, WallShape};
use spatter_core::motion::Motion;

const NEW: [Integrator; 9] = [
    Integrator::Fe,
    Integrator::Rk2,
    Integrator::Rk4,
    Integrator::Ab2,
    Integrator::Ab4,
    Integrator::Abm4,
    Integrator::Bd1,
    Integrator::Bd2,
    Integrator::Bd4,
];

#[test]
fn every_scheme_reaches_its_nominal_order_on_the_sandwiched_oscillator() {
    // The sphere held between two planes (both contacts stay closed) is the harmonic oscillator
    // x'' = −ω²x with x = A cos ωt: a smooth problem, on which each scheme must show its textbook global
    // order (Hairer, Nørsett & Wanner, Solving Ordinary Differential Equations I, 1993; the orders of
    // Jasion 2013, Table A.1): FE, BD1 1; RK2, AB2, BD2 2; RK4, AB4, ABM4, BD4 4. Measured from the state
    // error at 2.25 periods with 100 and 200 steps per period; tolerance ±0.2 (the ratio of two runs
    // still carries the next-order term).
    let a = 5e-5;
    let error = |integrator, n: usize| {
        let (omega, dt, xs) = sandwiched_oscillator(integrator, n, 2.25);
        let t = (xs.len() - 1) as f64 * dt;
        let (x, v) = xs[xs.len() - 1];
        (omega * (x - a * (omega * t).cos())).hypot(v + a * omega * (omega * t).sin())
    };
    for integrator in NEW {
        let Some(scheme) = integrator.scheme() else { panic!("{integrator:?} is a scheme") };
        let p = (error(integrator, 100) / error(integrator, 200)).log2();
        let nominal = scheme.nominal_order() as f64;
        assert!((p - nominal).abs() < 0.2, "{integrator:?}: order {p}, nominal {nominal}");
    }
}

/// A sphere (r = 1 cm, ρ = 2500) squeezed between two fixed planes by δ₀ = 1e-4 m each (Hooke k = 1e5 N/m,
/// linear tangential spring k_t = 2/7 k, μ = 0.9, no damping, rotation off), pushed sideways at v₀: with
/// the spin held at zero each tangential spring stretches by the lateral displacement x, so x'' = −ω_t² x
/// with ω_t = √(2 k_t/m) as long as it sticks (k_t A ≈ 0.3 N ≪ μ k δ₀ = 9 N). Returns ω_t, Δt and the
/// lateral positions after every step.
fn lateral_oscillator(integrator: Integrator, steps_per_period: usize, periods: f64) -> (f64, f64, Vec<f64>) {
    let (r, rho, k, d0) = (0.01, 2500.0, 1e5, 1e-4);
    let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
    let kt = 2.0 / 7.0 * k;
    let omega = (2.0 * kt / m).sqrt();
    let dt = 2.0 * std::f64::consts::PI / omega / steps_per_period as f64;
    let mats = vec![Material::new(5e7, 0.3, rho).unwrap()];
    let law = Composed::new(
        Hooke { stiffness: HookeStiffness::Constant(k) },
        NoDamping,
        LinearHistory::default(),
        NoRolling,
    );
    let settings = Settings { integrator, iterations: Some(5), rotation: false, ..Settings::default() };
    let mut sim = Simulation::new(law, mats.clone(), uniform_pairs(&mats, 0.9, 1.0), dt, settings);
    let h = 2.0 * (r - d0);
    for (p, n) in [(Vec3::ZERO, Vec3::Z), (Vec3::new(0.0, 0.0, h), -Vec3::Z)] {
        sim.add_wall(Wall {
            name: "w".into(),
            shape: WallShape::Plane(Plane::new(p, n)),
            material: 0,
            motion: Motion::Fixed,
        });
    }
    let mut p = crate::NewParticle::at(Vec3::new(0.0, 0.0, 0.5 * h), r, 0);
    p.vel = Vec3::new(0.01, 0.0, 0.0);
    sim.add_particle(p);
    let n = (periods * steps_per_period as f64).round() as usize;
    let mut xs = vec![0.0];
    for _ in 0..n {
        sim.step().unwrap();
        xs.push(sim.particles.pos[0].x);
    }
    (omega, dt, xs)
}

#[test]
fn multi_stage_schemes_advance_the_contact_history_once_per_step() {
    // The tangential springs advance once per step, in the step's first evaluation, by Δt times the
    // sliding velocity of yₙ (stages advance a copy by their own c·Δt and discard it). The lateral motion
    // of `lateral_oscillator` then follows x = (v₀/ω_t) sin(ω_t t) to first order in Δt whatever the
    // scheme: the spring sums Δt vₙ₊₁ (a right-endpoint rule), so s ≈ x + ½Δt v, which acts as a dashpot
    // of rate γ = ω_t²Δt/4 and lowers the amplitude by γt ≈ 11 % after 2.25 periods at 200 steps per
    // period (measured 12 %; velocity Verlet and symplectic Euler advance the spring by exactly the
    // displacement here and have no such error). Checked for RK4 (four evaluations per step), ABM4 (two)
    // and BD2 (five iterations): error below 20 % of the amplitude at 200 steps per period, order 1 ± 0.2
    // from 200 and 400 steps. A history advanced in every stage would stiffen the spring up to fourfold
    // (the phase would be off by ~100 %).
    for integrator in [Integrator::Rk4, Integrator::Abm4, Integrator::Bd2] {
        let err = |n: usize| {
            let (omega, dt, xs) = lateral_oscillator(integrator, n, 2.25);
            let t = (xs.len() - 1) as f64 * dt;
            let amp = 0.01 / omega;
            (xs[xs.len() - 1] - amp * (omega * t).sin()).abs() / amp
        };
        let (e1, e2) = (err(200), err(400));
        assert!(e1 < 0.2, "{integrator:?}: error {e1} of the amplitude");
        let p = (e1 / e2).log2();
        assert!((p - 1.0).abs() < 0.2, "{integrator:?}: order {p}");
    }
}

/// A pile of 500 spheres poured into a 6 cm box with Hertz–Mindlin contacts and a plane floor, with one
/// more sphere added after `add_at` steps.
fn pile(settings: Settings) -> Simulation<crate::contact::HertzMindlin> {
    let mats = vec![soft()];
    let pairs = uniform_pairs(&mats, 0.5, 0.5);
    let mut sim = Simulation::new(crate::contact::HertzMindlin::default(), mats, pairs, 2e-5, settings);
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    box_walls(&mut sim, 0.06, 0, 0, false);
    fill(&mut sim, 0.06, 500, (0.005, 0.007), 0.5, 5);
    sim
}

/// Adds a sphere of radius 2 mm at the first free spot of a grid in the box.
fn add_one<L: ContactLaw>(sim: &mut Simulation<L>) {
    let r = 0.002;
    let free = |x: Vec3| {
        let q = &sim.particles;
        (0..q.len()).all(|i| (q.pos[i] - x).length() > q.radius[i] + r + 1e-4)
    };
    let spots = (0..20).flat_map(|k| {
        (0..20).map(move |j| Vec3::new(0.005 + 0.0025 * j as f64, 0.03, 0.055 - 0.0025 * k as f64))
    });
    let Some(x) = spots.into_iter().find(|&x| free(x)) else { panic!("no free spot") };
    let mut p = crate::NewParticle::at(x, r, 0);
    p.vel = Vec3::new(0.0, 0.0, -0.2);
    sim.add_particle(p);
}

#[test]
fn a_checkpoint_carries_the_multi_step_history_and_the_run_resumes_bit_for_bit() {
    // Run 300 steps, checkpoint (through bincode, as the scene driver does), run 300 more with a sphere
    // added at step 400; a fresh simulation restored from the checkpoint must end identical to the bit.
    // One uninterrupted run on one thread must equal the same run on two.
    for integrator in [Integrator::Ab4, Integrator::Abm4, Integrator::Bd2, Integrator::Rk2] {
        let settings = Settings { integrator, iterations: Some(2), ..Settings::default() };
        let run_to_end = |sim: &mut Simulation<_>, from: u64| {
            for s in from..600 {
                if s == 400 {
                    add_one(sim);
                }
                sim.step().unwrap();
            }
        };
        let mut a = pile(settings.clone());
        a.run_steps(300).unwrap();
        let bytes = bincode::serialize(&a.state()).unwrap();
        if integrator.scheme().is_some_and(|s| s.history() > 0) {
            assert!(!a.st.history.past.is_empty(), "{integrator:?} keeps a history");
        }
        run_to_end(&mut a, 300);
        assert!(a.rebuild_count() > 2, "lists were rebuilt");
        let last = a.last_evaluation();
        assert!(last.pair_contacts > 20 && last.wall_contacts > 5, "{last:?}");
        let mut b = pile(settings.clone());
        b.restore(bincode::deserialize(&bytes).unwrap()).unwrap();
        run_to_end(&mut b, 300);
        assert_eq!(a.particles, b.particles, "{integrator:?}: resumed run differs");
        assert_eq!(a.energy().total().to_bits(), b.energy().total().to_bits());
        let threads = |n: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(n).build().unwrap();
            pool.install(|| {
                let mut s = pile(settings.clone());
                run_to_end(&mut s, 0);
                s.particles
            })
        };
        assert_eq!(threads(1), threads(2), "{integrator:?}: 1 and 2 threads differ");
        assert_eq!(threads(1), a.particles, "{integrator:?}: interrupted run differs");
    }
}

#[test]
fn an_implicit_scheme_without_iterations_and_a_clump_scene_are_refused() {
    let mut sim = pile(Settings { integrator: Integrator::Bd2, ..Settings::default() });
    match sim.step() {
        Err(DemError::Config { key, message }) => {
            assert_eq!(key, "iterations");
            assert!(message.contains("BD2"), "{message}");
        }
        other => panic!("expected a configuration error, got {other:?}"),
    }
    assert_eq!(Scheme::parse("bd4").map(Integrator::of_scheme), Some(Integrator::Bd4));
}
