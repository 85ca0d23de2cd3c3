//! Fluid forces on DEM spheres and clumps: terminal velocity, torque on a turning body, thread
//! independence.

use super::*;
use spatter_core::material::Material;
use spatter_core::{Quat, Vec3};
use spatter_dem::clump::{ClumpTemplate, NewBody};
use spatter_dem::contact::HertzMindlin;
use spatter_dem::sim::uniform_pairs;
use spatter_dem::{NewParticle, Settings, Simulation};
use spatter_flow::field::analytic::{AnalyticField, AnalyticSet};
use std::f64::consts::PI;

const G: Vec3 = Vec3::new(0.0, 0.0, -9.81);

fn water() -> Fluid {
    Fluid { density: 1000.0, viscosity: 1e-3 }
}

fn glass() -> Material {
    Material::new(1e7, 0.25, 2500.0).unwrap()
}

fn uniform(u: Vec3) -> AnalyticSet {
    AnalyticSet { parts: vec![AnalyticField::Uniform { velocity: u }], turbulence: None }
}

fn sim_in(u: Vec3, drag: DragModel, dt: f64) -> Simulation<HertzMindlin> {
    sim_in_fluid(water(), glass(), u, drag, dt)
}

/// One-material DEM scene in the uniform flow `u` of `fluid` with gravity [`G`] and drag law `drag`.
fn sim_in_fluid(
    fluid: Fluid,
    material: Material,
    u: Vec3,
    drag: DragModel,
    dt: f64,
) -> Simulation<HertzMindlin> {
    let mats = vec![material];
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats.clone(),
        uniform_pairs(&mats, 0.5, 0.5),
        dt,
        Settings::default(),
    );
    sim.gravity = G;
    let options = FluidForceOptions { fluid, drag, ..Default::default() };
    let sampler = PrescribedFlow::new(uniform(u), fluid.density, G);
    sim.set_external_forces(Box::new(FluidForces::new(sampler, options)));
    sim
}

/// Schiller–Naumann terminal slip speed of a sphere (Schiller & Naumann 1933, C_D = 24/Re (1 + 0.15
/// Re^0.687)) with Archimedes buoyancy: (ρ_p − ρ_f) g V = ⅛ C_D ρ_f π d² w², solved by bisection on w.
fn schiller_naumann_terminal(d: f64, rho_p: f64, f: &Fluid, g: f64) -> f64 {
    let resid = |w: f64| {
        let re = f.density * d * w / f.viscosity;
        let cd = 24.0 / re * (1.0 + 0.15 * re.powf(0.687));
        0.125 * cd * f.density * PI * d * d * w * w - (rho_p - f.density) * g * PI / 6.0 * d.powi(3)
    };
    increasing_root(resid, 1e-9, 10.0)
}

/// The root of `f`, negative at `lo` and positive at `hi`, by 200 bisections.
fn increasing_root(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn a_sphere_in_a_uniform_flow_reaches_the_schiller_naumann_terminal_velocity() {
    // A 1 mm glass bead in water moving at U = (0.1, 0, 0.05) m/s: at steady state it moves with the
    // stream horizontally and sinks through it at the Schiller–Naumann terminal speed w_t
    // (≈ 0.16 m/s, Re ≈ 160, below the law's Re < 1000 limit). After 40 drag time scales the transient
    // is gone (e^−40); the steady state does not depend on Δt. Tolerance 1e-6 relative.
    let u = Vec3::new(0.1, 0.0, 0.05);
    let d = 1e-3;
    let mut sim = sim_in(u, DragModel::SchillerNaumann, 1e-4);
    sim.add_particle(NewParticle::at(Vec3::ZERO, 0.5 * d, 0));
    sim.run_steps(10_000).unwrap();
    let wt = schiller_naumann_terminal(d, 2500.0, &water(), 9.81);
    let v = sim.particles.vel[0];
    assert!((v.x / u.x - 1.0).abs() < 1e-6, "v = {v}");
    assert!(((u.z - v.z) / wt - 1.0).abs() < 1e-6, "slip {} vs w_t {wt}", u.z - v.z);
    assert!(v.y.abs() < 1e-12);
}

#[test]
fn a_steel_ball_settles_in_still_air_at_the_di_felice_terminal_velocity() {
    // Anchor A9 of the stone-chip verification (Qian et al. 2022, CMES): one sphere falling from rest in
    // still air (void fraction 1) under the drag law of Di Felice (1994), C_d = (0.63 + 4.8/√Re)²,
    // reaches v_t solving m g (1 − ρ_f/ρ_p) = (π/8) C_d(Re) ρ_f d² v_t², Re = ρ_f d v_t/μ, solved here
    // by bisection on v. The 5 mm steel ball of the study's single-particle tests in air at 20 °C:
    // v_t ≈ 32 m/s, Re ≈ 1e4. From rest the speed approaches v_t as tanh(g t/v_t) for a constant C_d,
    // so after 40 s the transient is below 1e-10; at the terminal state the forces balance whatever
    // the step. Tolerance 1e-6 relative.
    let air = Fluid { density: 1.204, viscosity: 1.81e-5 };
    let (d, rho_p) = (5e-3, 7850.0);
    let steel = Material::new(2e11, 0.3, rho_p).unwrap();
    let mut sim = sim_in_fluid(air, steel, Vec3::ZERO, DragModel::DiFelice, 1e-3);
    sim.add_particle(NewParticle::at(Vec3::ZERO, 0.5 * d, 0));
    sim.run_steps(40_000).unwrap();
    let weight = rho_p * PI / 6.0 * d.powi(3) * 9.81 * (1.0 - air.density / rho_p);
    let resid = |v: f64| {
        let re = air.density * d * v / air.viscosity;
        let cd = (0.63 + 4.8 / re.sqrt()).powi(2);
        PI / 8.0 * cd * air.density * d * d * v * v - weight
    };
    let vt = increasing_root(resid, 0.0, 1e3);
    let v = sim.particles.vel[0];
    assert!((-v.z / vt - 1.0).abs() < 1e-6, "settling {} m/s vs v_t {vt} m/s", -v.z);
    assert!(v.x.abs() < 1e-12 && v.y.abs() < 1e-12, "v = {v}");
    assert!(vt > 25.0 && vt < 40.0, "v_t {vt} m/s: the Newton regime of the study's ball");
}

#[test]
fn a_one_sphere_clump_moves_exactly_like_the_free_sphere() {
    // The hook sees a member like a free sphere; the body's kick is written like the sphere's, so the
    // two trajectories agree bit for bit (rigid multi-sphere verification: a one-sphere clump behaves
    // exactly like the free sphere).
    let u = Vec3::new(0.3, -0.1, 0.2);
    let mut a = sim_in(u, DragModel::DiFelice, 1e-4);
    a.add_particle(NewParticle::at(Vec3::ZERO, 5e-4, 0));
    let mut b = sim_in(u, DragModel::DiFelice, 1e-4);
    let t = b.add_template(ClumpTemplate::from_spheres("one", &[(Vec3::ZERO, 5e-4)]));
    b.add_clump(t, 0, NewBody::at(Vec3::ZERO, Quat::IDENTITY)).unwrap();
    a.run_steps(500).unwrap();
    b.run_steps(500).unwrap();
    assert_eq!(a.particles.pos[0], b.bodies().pos[0]);
    assert_eq!(a.particles.vel[0], b.bodies().vel[0]);
}

#[test]
fn drag_on_the_members_of_a_turning_dumbbell_gives_the_resisting_torque() {
    // Two spheres (r = 0.25 mm) at ±L = 1 mm on x, turning at ω₀ = 2 rad/s about z in still water, no
    // gravity: each member moves at ω₀L, feels −β(ω₀L) ω₀L along its velocity, and the body torque is
    // T_z = −2 β L² ω₀ (β of Schiller & Naumann 1933). The torque is read after one step of 1e-7 s, in
    // which ω changes by ~1e-6 relative: tolerance 1e-4 relative.
    let (r, l, w0) = (2.5e-4, 1e-3, 2.0);
    let mats = vec![glass()];
    let mut sim = Simulation::new(
        HertzMindlin::default(),
        mats.clone(),
        uniform_pairs(&mats, 0.5, 0.5),
        1e-7,
        Settings::default(),
    );
    let options =
        FluidForceOptions { fluid: water(), drag: DragModel::SchillerNaumann, ..Default::default() };
    let sampler = PrescribedFlow::new(uniform(Vec3::ZERO), 1000.0, Vec3::ZERO);
    sim.set_external_forces(Box::new(FluidForces::new(sampler, options)));
    let t = sim.add_template(ClumpTemplate::from_spheres(
        "dumbbell",
        &[(Vec3::new(-l, 0.0, 0.0), r), (Vec3::new(l, 0.0, 0.0), r)],
    ));
    let mut body = NewBody::at(Vec3::ZERO, Quat::IDENTITY);
    body.omega = Vec3::new(0.0, 0.0, w0);
    sim.add_clump(t, 0, body).unwrap();
    sim.run_steps(1).unwrap();
    let beta = DragModel::SchillerNaumann.beta(&water(), 2.0 * r, 1.0, w0 * l);
    let want = -2.0 * beta * l * l * w0;
    let tq = sim.bodies().torque[0];
    assert!((tq.z / want - 1.0).abs() < 1e-4, "torque {tq} vs {want}");
    assert!(sim.bodies().force[0].length() < 1e-6 * beta * w0 * l, "net force {}", sim.bodies().force[0]);
}

#[test]
fn fluid_forces_are_identical_for_any_thread_count() {
    // 3000 spheres in a Lamb–Oseen vortex with the fluid-acceleration pressure force: the forces after
    // 20 steps are bit-identical on 1 and 2 threads.
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mats = vec![glass()];
            let mut sim = Simulation::new(
                HertzMindlin::default(),
                mats.clone(),
                uniform_pairs(&mats, 0.5, 0.5),
                1e-5,
                Settings::default(),
            );
            sim.gravity = G;
            let field = AnalyticSet {
                parts: vec![AnalyticField::LambOseen {
                    circulation: 0.05,
                    core_radius: 0.01,
                    centre: Vec3::ZERO,
                    axis: Vec3::Z,
                    nu: 1e-6,
                }],
                turbulence: None,
            };
            let mut sampler = PrescribedFlow::new(field, 1000.0, G);
            sampler.pressure = PressureGradient::FluidAcceleration;
            sim.set_external_forces(Box::new(FluidForces::new(
                sampler,
                FluidForceOptions { fluid: water(), ..Default::default() },
            )));
            for k in 0..3000 {
                let (i, j, m) = ((k % 15) as f64, ((k / 15) % 20) as f64, (k / 300) as f64);
                sim.add_particle(NewParticle::at(
                    Vec3::new(-0.02 + 3e-3 * i, -0.03 + 3e-3 * j, 3e-3 * m),
                    5e-4,
                    0,
                ));
            }
            sim.run_steps(20).unwrap();
            (sim.particles.pos.clone(), sim.particles.force.clone())
        })
    };
    assert_eq!(run(1), run(2));
}

#[test]
fn the_fluid_acceleration_pressure_force_is_buoyancy_plus_rho_v_du_dt() {
    // In a steady inviscid flow Euler's equation gives ∇p = ρ_f (g − (u·∇)u); −V∇p is then Archimedes'
    // buoyancy plus ρ_f V (u·∇)u (the pressure-gradient force of Maxey & Riley 1983). Checked on the
    // axisymmetric stagnation-point flow u = a(x, y, −2z): (u·∇)u = a²(x, y, 4z). Tolerance 1e-12.
    let a = 2.0;
    let field = AnalyticSet {
        parts: vec![AnalyticField::StagnationPoint {
            strain_rate: a,
            centre: Vec3::ZERO,
            normal: Vec3::Z,
            axisymmetric: true,
        }],
        turbulence: None,
    };
    let mut s = PrescribedFlow::new(field, 1000.0, G);
    s.pressure = PressureGradient::FluidAcceleration;
    let x = Vec3::new(0.3, -0.1, 0.2);
    let f = s.fluid_at(x, 0.0, &mut 0).unwrap();
    let want = 1000.0 * (G - a * a * Vec3::new(x.x, x.y, 4.0 * x.z));
    assert!((f.grad_p - want).length() < 1e-12 * want.length(), "{} vs {want}", f.grad_p);
}
