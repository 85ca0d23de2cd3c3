//! Many-particle checks: energy conservation of an elastic gas in a box, and a settled pile whose floor
//! carries exactly its weight.

use crate::contact::{Composed, Frictionless, Hertz, HertzMindlinRolling, NoDamping, NoRolling, PairTable};
use crate::particles::NewParticle;
use crate::sim::{uniform_pairs, Settings, Simulation};
use crate::walls::{Plane, Wall, WallShape};
use spatter_core::distribution::SizeDistribution;
use spatter_core::material::Material;
use spatter_core::motion::Motion;
use spatter_core::rng::{seeded, RngExt};
use spatter_core::validation::Check;
use spatter_core::Vec3;

fn soft() -> Material {
    Material { youngs_modulus: 5e7, poisson_ratio: 0.3, density: 2500.0 }
}

fn box_planes<L: crate::contact::ContactLaw>(sim: &mut Simulation<L>, l: f64, side_mat: u16, floor_mat: u16) {
    let planes = [
        (Vec3::ZERO, Vec3::X, side_mat),
        (Vec3::splat(l), -Vec3::X, side_mat),
        (Vec3::ZERO, Vec3::Y, side_mat),
        (Vec3::splat(l), -Vec3::Y, side_mat),
        (Vec3::splat(l), -Vec3::Z, side_mat),
        (Vec3::ZERO, Vec3::Z, floor_mat),
    ];
    for (k, (p, n, m)) in planes.into_iter().enumerate() {
        sim.add_wall(Wall {
            name: format!("wall{k}"),
            shape: WallShape::Plane(Plane::new(p, n)),
            material: m,
            motion: Motion::Fixed,
        });
    }
}

/// `n` non-overlapping spheres with diameters uniform in `d` placed in the box \[0, l\]³ by random
/// sequential addition in draw order (a failed placement draws a new size and position).
///
/// This is the random stream the many-particle checks (here and in the engine tests) were verified with,
/// kept so that their initial states and recorded results stay the same: the first 256 draws are
/// consumed (an earlier fill sized its search cells from them), then each attempt draws a diameter and a
/// centre. Scene fills use [`crate::insertion::random_fill`], which places every draw.
pub(crate) fn draw_order_fill(
    l: f64,
    d: (f64, f64),
    n: u64,
    rng: &mut spatter_core::rng::Rng,
) -> Vec<(Vec3, f64)> {
    let dist = SizeDistribution::Uniform { min: d.0, max: d.1 };
    for _ in 0..256 {
        dist.sample(rng);
    }
    let mut out: Vec<(Vec3, f64)> = Vec::new();
    while (out.len() as u64) < n {
        let r = 0.5 * dist.sample(rng);
        let u = Vec3::new(rng.random(), rng.random(), rng.random());
        let x = u * l;
        let inside = x.cmpge(Vec3::splat(r)).all() && x.cmple(Vec3::splat(l - r)).all();
        if inside && out.iter().all(|(y, ry)| (*y - x).length_squared() >= (r + ry) * (r + ry)) {
            out.push((x, r));
        }
    }
    out
}

fn fill<L: crate::contact::ContactLaw>(sim: &mut Simulation<L>, l: f64, n: u64, speed: f64, seed: u64) {
    let mut rng = seeded(seed, 0);
    for (x, r) in draw_order_fill(l, (0.008, 0.012), n, &mut rng) {
        let mut p = NewParticle::at(x, r, 0);
        let u = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
        p.vel = u * 2.0 * speed;
        sim.add_particle(p);
    }
}

/// An elastic, frictionless gas of spheres in a box of planes conserves kinetic + elastic energy. The
/// largest relative deviation over the run must stay below 2e-3 at 60 steps per Hertz contact time
/// (velocity Verlet: bounded O(Δt²) error, no drift).
pub fn elastic_box(quick: bool) -> Vec<Check> {
    let mats = vec![soft()];
    let pairs = uniform_pairs(&mats, 0.0, 1.0);
    let law: Composed<Hertz, NoDamping, Frictionless, NoRolling> = Composed::default();
    let r_min: f64 = 0.004;
    let m_min = 2500.0 * 4.0 / 3.0 * std::f64::consts::PI * r_min.powi(3);
    let tc = spatter_core::timestep::hertz_time(0.5 * m_min, 0.5 * r_min, pairs.get(0, 0).e_star, 4.0);
    let mut sim = Simulation::new(law, mats, pairs, tc / 60.0, Settings::default());
    box_planes(&mut sim, 0.1, 0, 0);
    let n = if quick { 200 } else { 500 };
    fill(&mut sim, 0.1, n, 1.0, 5);
    let e0 = sim.energy().total();
    let mut dev: f64 = 0.0;
    let chunks = if quick { 20 } else { 100 };
    for _ in 0..chunks {
        if sim.run_steps(100).is_err() {
            dev = f64::INFINITY;
            break;
        }
        dev = dev.max((sim.energy().total() / e0 - 1.0).abs());
    }
    vec![Check::absolute(
        "dem_elastic_box_energy",
        "max |E(t)/E(0) - 1| [-]",
        0.0,
        dev,
        2e-3,
        "energy conservation of an elastic system (velocity Verlet, 60 steps per contact)",
    )]
}

/// The empty box of [`settled_pile`]: 10 cm of planes (material 1 for the four sides and the top, 0 for
/// the floor, wall 5), two materials of E = 50 MPa, ν = 0.3, ρ = 2500 kg/m³, friction 0.5 (none
/// between the two materials: frictionless sides), restitution 0.3, rolling resistance μ_r = 0.05,
/// gravity, Δt = 40 µs.
pub fn settled_pile_box() -> Simulation<HertzMindlinRolling> {
    let mats = vec![soft(), soft()];
    let base = uniform_pairs(&mats, 0.5, 0.3);
    let pairs = PairTable::build(2, |a, b| {
        let mut p = base.get(a, b).clone();
        p.rolling_friction = 0.05;
        if a != b {
            p.friction = 0.0;
        }
        p
    });
    let mut sim = Simulation::new(HertzMindlinRolling::default(), mats, pairs, 4e-5, Settings::default());
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    box_planes(&mut sim, 0.1, 1, 0);
    sim
}

/// Spheres poured into a box (frictionless side walls, frictional floor, rolling resistance μ_r = 0.05)
/// come to rest: translational kinetic energy below 1e-6 of the potential energy released, and the floor
/// force equals the total weight within 1 %.
pub fn settled_pile(quick: bool) -> Vec<Check> {
    let mut sim = settled_pile_box();
    fill(&mut sim, 0.1, if quick { 250 } else { 600 }, 0.2, 21);
    let pe0 = sim.energy().potential;
    let weight: f64 = sim.particles.free_mass() * 9.81;
    let ok = sim.run_steps(if quick { 15_000 } else { 40_000 }).is_ok();
    let e = sim.energy();
    let floor = sim.wall_force(5);
    let ratio = if ok { -floor.z / weight } else { f64::NAN };
    let ke = if ok { e.kinetic / (pe0 - e.potential) } else { f64::NAN };
    let src = "statics: floor force = weight (frictionless side walls)";
    vec![
        Check::relative("dem_settled_pile", "floor force / weight [-]", 1.0, ratio, 0.01, src),
        Check::absolute("dem_settled_pile", "KE / released potential energy [-]", 0.0, ke, 1e-6, src),
    ]
}
