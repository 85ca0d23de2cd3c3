//! `spatter bench dem`: a dense box of settled spheres under gravity, Hertz–Mindlin with history.
//!
//! The case: monodisperse-ish spheres (radius 0.9995–1.0 mm, soft glass E = 50 MPa, ν = 0.3,
//! ρ = 2500 kg/m³, μ = 0.5, e = 0.5) on a face-centred-cubic lattice filling a box of planes (floor and
//! four sides), settled under gravity for 4000 steps (untimed; 2000 in the quick box), then advanced for
//! 400 steps (200) with 1 and with 2 threads from the same state. Printed: particle-steps per second for
//! both thread counts, the parallel efficiency, the rates with the per-contact and without an energy
//! budget, the state bytes per particle (particles, neighbour list with contact histories, wall
//! candidates; the cell grid lives only during rebuilds), and the Verlet-list versus every-step cell
//! search comparison (a quarter of the steps). The comparison with LAMMPS (`bench/dem/compare.sh`) times
//! whole runs of 1000 steps with the `dem_bench` example instead.
//!
//! [`write_lammps_data`] writes the settled state as a LAMMPS data file for `bench/dem/compare.sh`, which
//! runs the same case in LAMMPS (`pair_style granular hertz/material … tangential mindlin`).

use crate::contact::{HertzMindlin, PairTable};
use crate::error::DemError;
use crate::particles::NewParticle;
use crate::sim::{uniform_pairs, Integrator, Settings, SimState, Simulation};
use crate::walls::{Plane, Wall, WallShape};
use spatter_core::material::Material;
use spatter_core::motion::Motion;
use spatter_core::rng::{seeded, RngExt};
use spatter_core::Vec3;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

/// Parameters of the benchmark box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoxCase {
    /// FCC unit cells along x, y, z (4 spheres per cell).
    pub cells: [usize; 3],
    /// Nominal radius \[m\].
    pub radius: f64,
    /// Time step \[s\].
    pub dt: f64,
    /// Young's modulus \[Pa\], Poisson ratio, density \[kg/m³\].
    pub youngs_modulus: f64,
    pub poisson_ratio: f64,
    pub density: f64,
    pub friction: f64,
    pub restitution: f64,
}

impl BoxCase {
    /// The full case: 32 × 32 × 25 cells = 102,400 spheres.
    pub fn full() -> Self {
        BoxCase {
            cells: [32, 32, 25],
            radius: 1e-3,
            dt: 5e-6,
            youngs_modulus: 5e7,
            poisson_ratio: 0.3,
            density: 2500.0,
            friction: 0.5,
            restitution: 0.5,
        }
    }

    /// A reduced case for quick runs: 14 × 14 × 10 cells = 7,840 spheres.
    pub fn quick() -> Self {
        BoxCase { cells: [14, 14, 10], ..Self::full() }
    }

    /// Number of spheres.
    pub fn count(&self) -> usize {
        4 * self.cells[0] * self.cells[1] * self.cells[2]
    }

    /// Lattice constant of the FCC cell \[m\] (nearest-neighbour distance 2R).
    pub fn lattice_constant(&self) -> f64 {
        2.0 * self.radius * std::f64::consts::SQRT_2
    }

    /// Box extent \[m\]: the lattice touches the floor and the four sides; the height leaves room above.
    pub fn extent(&self) -> Vec3 {
        let a = self.lattice_constant();
        let side = |n: usize| (n as f64 - 0.5) * a + 2.0 * self.radius;
        Vec3::new(side(self.cells[0]), side(self.cells[1]), side(self.cells[2]) + 4.0 * self.radius)
    }

    pub fn material(&self) -> Material {
        Material {
            youngs_modulus: self.youngs_modulus,
            poisson_ratio: self.poisson_ratio,
            density: self.density,
        }
    }
}

/// Builds the box with its walls and lattice of spheres (not yet settled).
pub fn dense_box(case: &BoxCase) -> Simulation<HertzMindlin> {
    let mat = case.material();
    let mats = vec![mat.clone(), mat];
    let pairs: PairTable<_> = uniform_pairs(&mats, case.friction, case.restitution);
    let mut sim = Simulation::new(HertzMindlin::default(), mats, pairs, case.dt, Settings::default());
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    let l = case.extent();
    let planes =
        [(Vec3::ZERO, Vec3::Z), (Vec3::ZERO, Vec3::X), (l, -Vec3::X), (Vec3::ZERO, Vec3::Y), (l, -Vec3::Y)];
    for (k, (p, n)) in planes.into_iter().enumerate() {
        sim.add_wall(Wall {
            name: format!("wall{k}"),
            shape: WallShape::Plane(Plane::new(p, n)),
            material: 1,
            motion: Motion::Fixed,
        });
    }
    let a = case.lattice_constant();
    let basis = [Vec3::ZERO, Vec3::new(0.5, 0.5, 0.0), Vec3::new(0.5, 0.0, 0.5), Vec3::new(0.0, 0.5, 0.5)];
    let r0 = case.radius;
    let origin = Vec3::splat(r0);
    let mut rng = seeded(2024, 0);
    for k in 0..case.cells[2] {
        for j in 0..case.cells[1] {
            for i in 0..case.cells[0] {
                for b in &basis {
                    let x = origin + (Vec3::new(i as f64, j as f64, k as f64) + *b) * a;
                    let r = r0 * (0.9995 + 0.0005 * rng.random::<f64>());
                    sim.add_particle(NewParticle::at(x, r, 0));
                }
            }
        }
    }
    sim
}

/// The tetrahedral 4-sphere clump of the clump benchmark: members of radius `r` on the corners of a
/// regular tetrahedron of edge 1.6 r (overlapping).
pub fn tetra_clump(r: f64) -> crate::clump::ClumpTemplate {
    let a = 0.8 * r / std::f64::consts::SQRT_2;
    let corners = [
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(1.0, -1.0, -1.0),
        Vec3::new(-1.0, 1.0, -1.0),
        Vec3::new(-1.0, -1.0, 1.0),
    ];
    let spheres: Vec<(Vec3, f64)> = corners.iter().map(|&c| (c * a, r)).collect();
    crate::clump::ClumpTemplate::from_spheres("tetra4", &spheres)
}

/// The clump case: as many member spheres as the sphere box has spheres, in 4-sphere clumps
/// ([`tetra_clump`], the same radius, material and contact law), on a cubic lattice with random seeded
/// orientations, 6 layers high, started at 0.2 m/s downwards (to settle in about as many steps as the
/// sphere box). Returns the
/// simulation and the box extent.
pub fn clump_box(case: &BoxCase) -> (Simulation<HertzMindlin>, Vec3) {
    let mat = case.material();
    let mats = vec![mat.clone(), mat];
    let pairs: PairTable<_> = uniform_pairs(&mats, case.friction, case.restitution);
    let mut sim = Simulation::new(HertzMindlin::default(), mats, pairs, case.dt, Settings::default());
    sim.gravity = Vec3::new(0.0, 0.0, -9.81);
    let t = sim.add_template(tetra_clump(case.radius));
    let rb = sim.templates()[t].bounding_radius();
    let spacing = 2.0 * rb + 0.1 * case.radius;
    let bodies = case.count() / 4;
    let layers = 6usize;
    let per_side = (bodies as f64 / layers as f64).sqrt().ceil() as usize;
    let side = per_side as f64 * spacing;
    let l = Vec3::new(side, side, (bodies.div_ceil(per_side * per_side)) as f64 * spacing + 4.0 * rb);
    let planes =
        [(Vec3::ZERO, Vec3::Z), (Vec3::ZERO, Vec3::X), (l, -Vec3::X), (Vec3::ZERO, Vec3::Y), (l, -Vec3::Y)];
    for (k, (p, n)) in planes.into_iter().enumerate() {
        sim.add_wall(Wall {
            name: format!("wall{k}"),
            shape: WallShape::Plane(Plane::new(p, n)),
            material: 1,
            motion: Motion::Fixed,
        });
    }
    let mut rng = seeded(2025, 0);
    let mut placed = 0;
    'fill: for k in 0.. {
        for j in 0..per_side {
            for i in 0..per_side {
                if placed == bodies {
                    break 'fill;
                }
                let x = Vec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * spacing;
                let axis = Vec3::new(
                    rng.random::<f64>() - 0.5,
                    rng.random::<f64>() - 0.5,
                    rng.random::<f64>() - 0.5,
                );
                let q = spatter_core::Quat::from_axis_angle(
                    axis.try_normalize().unwrap_or(Vec3::Z),
                    rng.random::<f64>() * std::f64::consts::TAU,
                );
                let b = crate::clump::NewBody {
                    vel: Vec3::new(0.0, 0.0, -0.2),
                    ..crate::clump::NewBody::at(x, q)
                };
                sim.add_clump(t, 0, b).expect("benchmark clump");
                placed += 1;
            }
        }
    }
    (sim, l)
}

/// Settling steps of the clump box before timing.
pub const CLUMP_SETTLE_STEPS: u64 = 30_000;

/// Times `steps` steps of the clump box restored from `state` on `threads` threads.
pub fn time_clump_run(
    case: &BoxCase,
    state: &SimState<<HertzMindlin as crate::contact::ContactLaw>::State>,
    threads: usize,
    steps: u64,
) -> Result<Timing, DemError> {
    let (mut sim, _) = clump_box(case);
    sim.energy_method = crate::sim::EnergyMethod::Residual;
    sim.restore(state.clone()).map_err(DemError::Resume)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| DemError::Config { key: "threads".into(), message: e.to_string() })?;
    let r0 = sim.rebuild_count();
    let e0 = sim.force_evaluations();
    let t = Instant::now();
    pool.install(|| {
        sim.run_steps(steps.saturating_sub(1))?;
        sim.request_energy();
        sim.run_steps(steps.min(1))
    })?;
    let seconds = t.elapsed().as_secs_f64();
    Ok(Timing {
        threads,
        steps,
        particles: sim.particles.len(),
        seconds,
        rebuilds: sim.rebuild_count() - r0,
        evaluations: sim.force_evaluations() - e0,
    })
}

/// Writes the particles as a LAMMPS data file (`atom_style sphere`, SI units): `Atoms` lines
/// `id type diameter density x y z`, and `Velocities` lines `id vx vy vz wx wy wz`.
pub fn write_lammps_data<L: crate::contact::ContactLaw>(
    sim: &Simulation<L>,
    box_extent: Vec3,
    path: &Path,
) -> Result<(), DemError> {
    let io = |e| DemError::Io { path: path.to_owned(), source: e };
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(io)?);
    let p = &sim.particles;
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by_key(|&i| p.id[i]);
    let mut text = String::new();
    text.push_str("spatter dem benchmark box (settled), SI units\n\n");
    text.push_str(&format!("{} atoms\n1 atom types\n\n", p.len()));
    text.push_str(&format!(
        "0 {:.10e} xlo xhi\n0 {:.10e} ylo yhi\n0 {:.10e} zlo zhi\n\n",
        box_extent.x, box_extent.y, box_extent.z
    ));
    text.push_str("Atoms # sphere\n\n");
    f.write_all(text.as_bytes()).map_err(io)?;
    for (k, &i) in order.iter().enumerate() {
        let x = p.pos[i];
        let rho = sim.materials()[p.material[i] as usize].density;
        writeln!(
            f,
            "{} 1 {:.17e} {:.17e} {:.17e} {:.17e} {:.17e}",
            k + 1,
            2.0 * p.radius[i],
            rho,
            x.x,
            x.y,
            x.z
        )
        .map_err(io)?;
    }
    writeln!(f, "\nVelocities\n").map_err(io)?;
    for (k, &i) in order.iter().enumerate() {
        let (v, w) = (p.vel[i], p.omega[i]);
        writeln!(
            f,
            "{} {:.17e} {:.17e} {:.17e} {:.17e} {:.17e} {:.17e}",
            k + 1,
            v.x,
            v.y,
            v.z,
            w.x,
            w.y,
            w.z
        )
        .map_err(io)?;
    }
    f.flush().map_err(io)
}

/// One timed run.
#[derive(Clone, Copy, Debug)]
pub struct Timing {
    pub threads: usize,
    pub steps: u64,
    pub particles: usize,
    pub seconds: f64,
    pub rebuilds: u64,
    /// Force evaluations in the timed steps.
    pub evaluations: u64,
}

impl Timing {
    /// Particle-steps per second.
    pub fn rate(&self) -> f64 {
        self.particles as f64 * self.steps as f64 / self.seconds
    }
}

/// Settles `sim` for `steps` steps (untimed).
pub fn settle<L: crate::contact::ContactLaw>(sim: &mut Simulation<L>, steps: u64) -> Result<(), DemError> {
    sim.run_steps(steps)
}

/// Restores `state` into a fresh box and times `steps` steps on `threads` threads.
pub fn time_run(
    case: &BoxCase,
    state: &SimState<<HertzMindlin as crate::contact::ContactLaw>::State>,
    threads: usize,
    steps: u64,
    verlet_list: bool,
    energy: Option<crate::sim::EnergyMethod>,
) -> Result<Timing, DemError> {
    time_run_with(case, state, threads, steps, verlet_list, energy, Integrator::VelocityVerlet)
}

/// Iterations per step the benchmark gives the implicit schemes (BD-p keeps its order with ≥ p; 4 for
/// all three, so that their rows compare at the same cost).
pub const BENCH_ITERATIONS: u32 = 4;

/// [`time_run`] with the time integrator `integrator` (the implicit ones with [`BENCH_ITERATIONS`]).
pub fn time_run_with(
    case: &BoxCase,
    state: &SimState<<HertzMindlin as crate::contact::ContactLaw>::State>,
    threads: usize,
    steps: u64,
    verlet_list: bool,
    energy: Option<crate::sim::EnergyMethod>,
    integrator: Integrator,
) -> Result<Timing, DemError> {
    let mut sim = dense_box(case);
    sim.settings.integrator = integrator;
    if integrator.scheme().is_some_and(|s| s.is_implicit()) {
        sim.settings.iterations = Some(BENCH_ITERATIONS);
    }
    sim.settings.verlet_list = verlet_list;
    sim.law.energy = energy.is_some();
    sim.energy_method = energy.unwrap_or_default();
    sim.restore(state.clone()).map_err(DemError::Resume)?;
    let r0 = sim.rebuild_count();
    let e0 = sim.force_evaluations();
    let t = Instant::now();
    run_on_threads(&mut sim, threads, steps)?;
    let seconds = t.elapsed().as_secs_f64();
    Ok(Timing {
        threads,
        steps,
        particles: sim.particles.len(),
        seconds,
        rebuilds: sim.rebuild_count() - r0,
        evaluations: sim.force_evaluations() - e0,
    })
}

/// Advances `sim` by `steps` steps on a pool of `threads` threads, with the energy budget requested in the
/// last step, as a run's output step would ask for it.
fn run_on_threads<L: crate::contact::ContactLaw>(
    sim: &mut Simulation<L>,
    threads: usize,
    steps: u64,
) -> Result<(), DemError> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| DemError::Config { key: "threads".into(), message: e.to_string() })?;
    pool.install(|| {
        sim.run_steps(steps.saturating_sub(1))?;
        sim.request_energy();
        sim.run_steps(steps.min(1))
    })
}

/// Restores `state` into a fresh box, advances it `steps` steps on `threads` threads as [`time_run`] does
/// (energy budget `energy`, Verlet list) and returns the bits of the final state ([`state_bits`]): the
/// reproducible check that a change to the engine left the motion bit for bit the same.
pub fn run_state_bits(
    case: &BoxCase,
    state: &SimState<<HertzMindlin as crate::contact::ContactLaw>::State>,
    threads: usize,
    steps: u64,
    energy: Option<crate::sim::EnergyMethod>,
) -> Result<String, DemError> {
    let mut sim = dense_box(case);
    sim.law.energy = energy.is_some();
    sim.energy_method = energy.unwrap_or_default();
    sim.restore(state.clone()).map_err(DemError::Resume)?;
    run_on_threads(&mut sim, threads, steps)?;
    Ok(state_bits(&sim))
}

/// The state of `sim` as text that differs between two runs exactly when a bit of the motion or the
/// energy budget differs: a header line with the step, the contact counts and the bits of the energy
/// report, then one line per particle in id order, `id` followed by the IEEE-754 bits of x, v and ω
/// (16 hex digits per component).
pub fn state_bits<L: crate::contact::ContactLaw>(sim: &Simulation<L>) -> String {
    use std::fmt::Write as _;
    let e = sim.energy();
    let mut s = format!(
        "step {} pair_contacts {} wall_contacts {} energy",
        sim.step_count(),
        e.pair_contacts,
        e.wall_contacts
    );
    for v in [e.kinetic, e.rotational, e.elastic, e.potential, e.dissipated, e.external_work, e.wall_work] {
        let _ = write!(s, " {:016x}", v.to_bits());
    }
    s.push('\n');
    let p = &sim.particles;
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by_key(|&i| p.id[i]);
    for i in order {
        let _ = write!(s, "{}", p.id[i]);
        for v in [p.pos[i], p.vel[i], p.omega[i]] {
            for c in v.to_array() {
                let _ = write!(s, " {:016x}", c.to_bits());
            }
        }
        s.push('\n');
    }
    s
}

/// Runs the benchmark and returns the lines to print. `quick` uses the reduced box and fewer steps.
pub fn bench(quick: bool) -> Result<Vec<String>, DemError> {
    let case = if quick { BoxCase::quick() } else { BoxCase::full() };
    let (settle_steps, steps) = if quick { (2000, 200) } else { (4000, 400) };
    let mut lines = Vec::new();
    let t = Instant::now();
    let mut sim = dense_box(&case);
    settle(&mut sim, settle_steps)?;
    let state = sim.state();
    lines.push(format!(
        "dem bench: {} spheres (FCC box {}x{}x{} cells), Hertz-Mindlin with history, gravity, dt = {:e} s; \
         settled {} steps in {:.1} s",
        sim.particles.len(),
        case.cells[0],
        case.cells[1],
        case.cells[2],
        case.dt,
        settle_steps,
        t.elapsed().as_secs_f64()
    ));
    lines.push(format!(
        "  contacts: {} particle-particle, {} particle-wall; neighbour pairs {}",
        sim.last_evaluation().pair_contacts,
        sim.last_evaluation().wall_contacts,
        sim.pair_list_len()
    ));
    use crate::sim::EnergyMethod::{PerContact, Residual};
    let one = time_run(&case, &state, 1, steps, true, Some(Residual))?;
    let two = time_run(&case, &state, 2, steps, true, Some(Residual))?;
    lines.push(format!(
        "  1 thread : {:.3e} particle-steps/s ({} steps in {:.2} s, {} list rebuilds)",
        one.rate(),
        one.steps,
        one.seconds,
        one.rebuilds
    ));
    lines.push(format!(
        "  2 threads: {:.3e} particle-steps/s ({} steps in {:.2} s); speed-up {:.2}, parallel efficiency {:.0} %",
        two.rate(),
        two.steps,
        two.seconds,
        two.rate() / one.rate(),
        50.0 * two.rate() / one.rate()
    ));
    let no_list_steps = (steps / 4).max(10);
    let pc = time_run(&case, &state, 1, steps, true, Some(PerContact))?;
    let ne = time_run(&case, &state, 1, steps, true, None)?;
    lines.push(format!(
        "  1 thread, energy budget per contact: {:.3e} particle-steps/s ({:.2}x); without energy budget: \
         {:.3e} ({:.2}x)",
        pc.rate(),
        pc.rate() / one.rate(),
        ne.rate(),
        ne.rate() / one.rate()
    ));
    let nl = time_run(&case, &state, 1, no_list_steps, false, Some(Residual))?;
    let wl = time_run(&case, &state, 1, no_list_steps, true, Some(Residual))?;
    lines.push(format!(
        "  neighbour search, 1 thread, {} steps: Verlet list {:.3e} particle-steps/s, cell search every step {:.3e} \
         (list is {:.2}x faster)",
        no_list_steps,
        wl.rate(),
        nl.rate(),
        wl.rate() / nl.rate()
    ));
    lines.push(format!(
        "  memory: {:.0} bytes per particle between steps (particles, pair list with histories, wall candidates)",
        sim.bytes_per_particle()
    ));
    lines.extend(bench_integrators(&case, &state, steps, one.rate())?);
    // The clumps start on a loose lattice six layers high: the bed needs about 0.15 s (30 000 steps)
    // to come to rest, whatever the footprint.
    lines.extend(bench_clumps(&case, CLUMP_SETTLE_STEPS, steps, one.rate(), two.rate())?);
    Ok(lines)
}

/// One row per time integrator on the settled box, 1 thread: particle-steps/s, force evaluations per
/// step (counted in the timed steps; the multi-step schemes take their first steps with RK4, which the
/// count includes) and the rate relative to velocity Verlet (`vv_rate`, the first row of the bench).
pub fn bench_integrators(
    case: &BoxCase,
    state: &SimState<<HertzMindlin as crate::contact::ContactLaw>::State>,
    steps: u64,
    vv_rate: f64,
) -> Result<Vec<String>, DemError> {
    use Integrator::*;
    let mut lines = vec![format!(
        "  integrators, 1 thread, {steps} steps each (implicit schemes with {BENCH_ITERATIONS} iterations):"
    )];
    for integrator in [VelocityVerlet, SymplecticEuler, Fe, Rk2, Rk4, Ab2, Ab4, Abm4, Bd1, Bd2, Bd4] {
        let t =
            time_run_with(case, state, 1, steps, true, Some(crate::sim::EnergyMethod::Residual), integrator)?;
        lines.push(format!(
            "    {:<5} {:.3e} particle-steps/s ({:.2}x velocity Verlet), {:.2} force evaluations per step",
            integrator.label(),
            t.rate(),
            t.rate() / vv_rate,
            t.evaluations as f64 / t.steps as f64
        ));
    }
    Ok(lines)
}

/// The clump case next to the sphere rates `sphere_one`, `sphere_two` (particle-steps/s on 1 and 2
/// threads): member-sphere-steps/s and the cost per member relative to a free sphere.
pub fn bench_clumps(
    case: &BoxCase,
    settle_steps: u64,
    steps: u64,
    sphere_one: f64,
    sphere_two: f64,
) -> Result<Vec<String>, DemError> {
    let mut lines = Vec::new();
    let t = Instant::now();
    let (mut sim, l) = clump_box(case);
    settle(&mut sim, settle_steps)?;
    let state = sim.state();
    lines.push(format!(
        "dem bench, clumps: {} member spheres in {} tetrahedral 4-sphere clumps (box {:.0} x {:.0} mm), settled {} \
         steps in {:.1} s; contacts {} member-member, {} member-wall",
        sim.particles.len(),
        sim.bodies().len(),
        l.x * 1e3,
        l.y * 1e3,
        settle_steps,
        t.elapsed().as_secs_f64(),
        sim.last_evaluation().pair_contacts,
        sim.last_evaluation().wall_contacts
    ));
    let one = time_clump_run(case, &state, 1, steps)?;
    let two = time_clump_run(case, &state, 2, steps)?;
    lines.push(format!(
        "  1 thread : {:.3e} member-sphere-steps/s, {:.2}x the cost of a free sphere ({} rebuilds)",
        one.rate(),
        sphere_one / one.rate(),
        one.rebuilds
    ));
    lines.push(format!(
        "  2 threads: {:.3e} member-sphere-steps/s, {:.2}x the cost of a free sphere; speed-up {:.2}",
        two.rate(),
        sphere_two / two.rate(),
        two.rate() / one.rate()
    ));
    Ok(lines)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clump_box_has_the_member_count_of_the_sphere_box_and_no_overlaps() {
        let case = BoxCase { cells: [4, 4, 3], ..BoxCase::full() };
        let (mut sim, _) = clump_box(&case);
        assert_eq!(sim.particles.len(), case.count());
        sim.run_steps(1).unwrap();
        assert_eq!(sim.last_evaluation().pair_contacts, 0, "clumps start apart");
        settle(&mut sim, 4000).unwrap();
        let e = *sim.last_evaluation();
        assert!(e.pair_contacts > 0 && e.wall_contacts > 0, "{e:?}");
    }

    #[test]
    fn state_bits_repeat_for_the_same_run_and_change_with_one_bit_of_state() {
        // The byte-identity check of docs/dem.md §5: two runs from the same state on 1 and 2 threads print
        // the same text (the engine is deterministic for any thread count, docs/dem.md §2), and a change
        // of one velocity by one unit in the last place shows.
        let case = BoxCase { cells: [3, 3, 2], ..BoxCase::full() };
        let mut sim = dense_box(&case);
        settle(&mut sim, 100).unwrap();
        let state = sim.state();
        let energy = Some(crate::sim::EnergyMethod::Residual);
        let one = run_state_bits(&case, &state, 1, 20, energy).unwrap();
        let two = run_state_bits(&case, &state, 2, 20, energy).unwrap();
        assert_eq!(one, two);
        assert_eq!(one.lines().count(), 1 + case.count());
        let before = state_bits(&sim);
        sim.particles.vel[5].x = f64::from_bits(sim.particles.vel[5].x.to_bits() ^ 1);
        assert_ne!(before, state_bits(&sim));
    }

    #[test]
    fn box_case_builds_without_overlaps_and_settles_in_contact() {
        let case = BoxCase { cells: [4, 4, 3], ..BoxCase::full() };
        let mut sim = dense_box(&case);
        assert_eq!(sim.particles.len(), case.count());
        settle(&mut sim, 300).unwrap();
        let e = sim.last_evaluation();
        // In an FCC packing every sphere touches up to 12 neighbours; settled under gravity the mean
        // coordination number 2·contacts/N exceeds 5 (the radii differ by at most 0.05 %).
        assert!(2.0 * e.pair_contacts as f64 > 5.0 * case.count() as f64, "{e:?}");
        assert!(e.max_overlap_ratio < 0.01, "{e:?}");
    }

    #[test]
    fn the_integrator_rows_count_the_force_evaluations_of_each_scheme() {
        // Evaluations per step once started (Jasion 2013, Table A.1): VV, SE, FE, AB2, AB4 one; RK2 and
        // ABM4 two; RK4 four; BD1, BD2, BD4 the iteration count (velocity Verlet reuses the stored forces
        // of the restored state for its first half kick). The multi-step
        // schemes start with RK4 steps (4 evaluations each): AB2 needs one, AB4 and ABM4 three, BD2 one
        // and BD4 three before their own formula takes over.
        let case = BoxCase { cells: [3, 3, 2], ..BoxCase::full() };
        let mut sim = dense_box(&case);
        settle(&mut sim, 50).unwrap();
        let state = sim.state();
        let n = 20;
        let count =
            |integrator| time_run_with(&case, &state, 1, n, true, None, integrator).unwrap().evaluations;
        use Integrator::*;
        let it = BENCH_ITERATIONS as u64;
        let all = [VelocityVerlet, SymplecticEuler, Fe, Rk2, Rk4, Ab2, Ab4, Abm4, Bd1, Bd2, Bd4];
        let got: Vec<u64> = all.iter().map(|i| count(*i)).collect();
        let want = vec![
            n,
            n,
            n,
            2 * n,
            4 * n,
            4 + (n - 1),
            3 * 4 + (n - 3),
            3 * 4 + 2 * (n - 3),
            it * n,
            4 + it * (n - 1),
            3 * 4 + it * (n - 3),
        ];
        assert_eq!(got, want);
    }
}
