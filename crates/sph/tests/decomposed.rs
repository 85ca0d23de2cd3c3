//! Runs split over several ranks (threads standing in for MPI ranks, `ThreadComm`) against the same runs
//! on one rank: particle set and mass exact, momentum balanced across ranks, the flow the same to within
//! stated tolerances, errors returned by every rank alike (never a hang).

use spatter_core::comm::{Comm, ThreadComm, WireReader, WireWriter};
use spatter_core::{Aabb, Vec3};
use spatter_sph::boundary::Slip;
use spatter_sph::sim::WallOptions;
use spatter_sph::{Dim, Simulation, SphParams};
use std::sync::mpsc;
use std::time::Duration;

const OPEN_TOP: [bool; 6] = [true, true, true, true, true, false];

/// Runs `f` on `n` thread-ranks and fails the test if they have not all finished within 120 s (a hang in
/// a collective is a failure, never a stuck test run).
fn on_ranks<T: Send + 'static>(n: usize, f: impl Fn(&ThreadComm) -> T + Send + Sync + 'static) -> Vec<T> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| ThreadComm::run(n, &f)));
        let _ = tx.send(out);
    });
    match rx.recv_timeout(Duration::from_secs(120)) {
        Ok(Ok(v)) => v,
        Ok(Err(e)) => std::panic::resume_unwind(e),
        Err(_) => panic!("{n} ranks did not finish within 120 s: a collective call hangs"),
    }
}

/// The a × 2a water column of Martin & Moyce (1952) in a 6a × 3a open tank, 2D, spacing a/20
/// (800 particles); the set-up of the `sph_dam_break_surge_front` validation case.
fn dam_break() -> Simulation {
    let a: f64 = 0.1;
    let g: f64 = 9.81;
    let dp = a / 20.0;
    let mut p = SphParams::water(Dim::Two, dp, 10.0 * (2.0 * g * 2.0 * a).sqrt());
    p.gravity = Vec3::new(0.0, 0.0, -g);
    let mut sim = Simulation::new(p);
    let tank = Aabb::new(Vec3::ZERO, Vec3::new(6.0 * a, 0.0, 3.0 * a));
    sim.add_tank("tank", tank, OPEN_TOP, None, None, WallOptions::default());
    sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(a, 0.0, 2.0 * a)), Vec3::ZERO, true);
    sim
}

/// Every rank's (id, position, velocity), gathered on every rank and sorted by id.
fn gathered(sim: &Simulation, comm: &dyn Comm) -> Vec<(u32, Vec3, Vec3)> {
    let mut w = WireWriter::with_capacity(52 * sim.fluid.len());
    for i in 0..sim.fluid.len() {
        w.u32(sim.fluid.id[i]).vec3(sim.fluid.pos[i]).vec3(sim.fluid.vel[i]);
    }
    let mut all = Vec::new();
    for buf in comm.all_gather_bytes(&w.finish()) {
        let mut r = WireReader::new(&buf);
        while !r.is_done() {
            all.push((r.u32().unwrap(), r.vec3().unwrap(), r.vec3().unwrap()));
        }
    }
    all.sort_by_key(|e| e.0);
    all
}

/// Reverses the storage order of the fluid: the same physical set-up whose sums run in another order.
fn reversed(mut sim: Simulation) -> Simulation {
    let n = sim.fluid.len();
    let f = &mut sim.fluid;
    for v in [&mut f.pos, &mut f.vel, &mut f.acc] {
        v.reverse();
    }
    f.rho.reverse();
    f.drho.reverse();
    f.id.reverse();
    f.near.reverse();
    f.shift.reverse();
    assert_eq!(f.len(), n);
    sim
}

/// One rank through `step_with` is today's `step`, bit for bit.
#[test]
fn one_rank_is_today() {
    let mut a = dam_break();
    a.initialize().unwrap();
    for _ in 0..30 {
        a.step().unwrap();
    }
    let b = on_ranks(1, |comm| {
        let mut b = dam_break();
        b.initialize_with(comm).unwrap();
        for _ in 0..30 {
            b.step_with(comm).unwrap();
        }
        b
    })
    .remove(0);
    assert_eq!(format!("{:?}", a.fluid), format!("{:?}", b.fluid));
    assert_eq!(a.dt.to_bits(), b.dt.to_bits());
    assert_eq!(a.last, b.last);
    assert_eq!(b.ranks(), 1);
}

/// Surge front (largest x + dp/2) of the dam break every `every` steps up to `steps` on `n` ranks, and
/// the final positions by id, checking in every step that the gathered id set is the initial one (no
/// particle lost or doubled) and that every rank holds the same time step.
fn dam_break_run(n: usize, steps: usize, every: usize) -> (Vec<(f64, f64)>, Vec<Vec3>, u64) {
    on_ranks(n, move |comm| {
        let mut sim = dam_break();
        let total = sim.fluid.len();
        let dp = sim.params.spacing;
        sim.initialize_with(comm).unwrap();
        assert_eq!(sim.ranks(), n);
        let mut fronts = Vec::new();
        for s in 1..=steps {
            sim.step_with(comm).unwrap();
            let mut dt = [sim.dt, -sim.dt];
            comm.all_max_f64(&mut dt);
            assert_eq!(dt[0], -dt[1], "every rank has the same time step");
            let all = gathered(&sim, comm);
            assert_eq!(all.len(), total, "particle count (mass) is exact at step {s}");
            assert!(all.iter().enumerate().all(|(k, e)| e.0 as usize == k), "ids 0..{total} once each");
            if s % every == 0 {
                let front = all.iter().map(|e| e.1.x).fold(0.0, f64::max) + 0.5 * dp;
                fronts.push((sim.time, front));
            }
        }
        (fronts, gathered(&sim, comm).into_iter().map(|e| e.1).collect(), sim.rebalances())
    })
    .remove(0)
}

/// On several ranks a rank's wall set holds the wall particles its fluid can see and none of the dry
/// walls far from all fluid: after 20 steps of the dam break on 4 ranks (the column fills the first sixth
/// of the tank) every rank holds every wall particle within one support of its own fluid and every wall
/// particle in its box within one support of any fluid (the ones whose wetting and loads it accounts
/// for), and none farther than 6 supports from every fluid particle (the region is the fluid's bounds
/// widened by one support and out to a lattice of 2 supports: 1 + 1 + 2√3 < 6 supports, counted brute
/// force here from the gathered fluid). The box of the rank at the column's front reaches to infinity;
/// the dry floor and back wall beyond half the tank are held by no rank. That the runs still agree with
/// one rank is `dam_break_2d_on_1_2_4_ranks` and `sensors_agree_across_rank_counts`.
#[test]
fn each_rank_holds_the_walls_its_fluid_reaches() {
    let held = on_ranks(4, |comm| {
        let mut sim = dam_break();
        sim.initialize_with(comm).unwrap();
        for _ in 0..20 {
            sim.step_with(comm).unwrap();
        }
        let support = sim.kernel().support();
        let all: Vec<Vec3> = gathered(&sim, comm).into_iter().map(|e| e.1).collect();
        let own = sim.fluid.pos.clone();
        let bx = sim.rank_box().unwrap();
        let nearest =
            |x: Vec3, set: &[Vec3]| set.iter().map(|&p| (p - x).length()).fold(f64::INFINITY, f64::min);
        let mut set = sim.wall_sources().to_vec();
        set.sort_unstable();
        set.dedup();
        let (mut missing, mut far, mut beyond_half) = (0, 0, 0);
        for i in 0..sim.boundary.len() {
            let x = sim.boundary.position(i);
            let held = set.binary_search(&(i as u32)).is_ok();
            let any = nearest(x, &all);
            let in_box = (0..3).all(|a| x[a] >= bx.min[a] && x[a] < bx.max[a]);
            if !held && (nearest(x, &own) <= support || (in_box && any <= support)) {
                missing += 1;
            }
            if held && any > 6.0 * support {
                far += 1;
            }
            if held && x.x > 0.3 {
                beyond_half += 1;
            }
        }
        (set.len(), missing, far, beyond_half, sim.boundary.len())
    });
    let total = held[0].4;
    for (rank, &(entries, missing, far, beyond_half, _)) in held.iter().enumerate() {
        eprintln!("rank {rank}: {entries} of {total} wall particles");
        assert_eq!(missing, 0, "rank {rank}: wall particles its fluid reaches are missing");
        assert_eq!(far, 0, "rank {rank}: wall particles far from every fluid are held");
        assert_eq!(beyond_half, 0, "rank {rank}: dry walls beyond half the tank are held");
        assert!(entries < total, "rank {rank}: {entries} of {total}");
    }
    // The upper inner quarter of the column is farther than a support from every wall: its rank holds none.
    assert!(held.iter().filter(|h| h.0 > 0).count() >= 3, "the ranks along the walls hold them");
}

/// The 2D dam break on 2 and 4 ranks against 1 rank, until the surge has run a column width
/// (T = t √(2g/a) ≈ 1.6; the Martin & Moyce 1952 set-up). The cuts run through the column and the surge,
/// so particles and halo cross them all the time. The particle set and count are exact in every step.
///
/// Not bit-identical: interior pairs are evaluated in single precision (the batch path) and pairs with
/// halo particles in double precision (like periodic images), so the runs differ from the first step at
/// the single-precision rounding of the cut pairs' terms; differences then grow with the flow. Measured
/// after 1200 steps: 3·10⁻¹¹ m at the front, below 10⁻⁸ m for any particle (any thread count: the engine
/// is bit-identical across thread counts). The test allows 10⁻⁴ dp = 5·10⁻¹⁰ m at the front and
/// 10⁻⁵ dp = 5·10⁻⁸ m for any particle. The split is rebuilt for balance as the column spreads (2 and 4
/// times here; `a_collapsing_column_is_rebalanced_over_the_ranks`), within the same tolerance. A halo only one support wide (wall entries near a cut then miss
/// the fluid beyond it) already moves particles by 4·10⁻⁶ m on 2 ranks and 1.6·10⁻⁵ m on 4 in this run.
#[test]
fn dam_break_2d_on_1_2_4_ranks() {
    let (steps, every) = (1200, 100);
    let dp = 0.005;
    let (serial, end1, _) = dam_break_run(1, steps, every);
    let front_end = serial.last().unwrap().1;
    assert!(front_end > 0.2, "the surge has run: front at {front_end} m");
    for n in [2, 4] {
        let (fronts, end, rebalances) = dam_break_run(n, steps, every);
        for (a, b) in serial.iter().zip(&fronts) {
            assert!((a.0 - b.0).abs() <= 1e-6 * a.0, "{n} ranks: time {} vs {}", b.0, a.0);
            let d = (a.1 - b.1).abs();
            assert!(d <= 1e-4 * dp, "{n} ranks at t = {} s: front {} m vs {} m", a.0, b.1, a.1);
        }
        let worst = end1.iter().zip(&end).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
        eprintln!(
            "dam break, {n} ranks: front differs by {:e} m, worst particle by {worst:e} m, {rebalances} rebalances",
            (serial.last().unwrap().1 - fronts.last().unwrap().1).abs()
        );
        assert!(worst <= 1e-5 * dp, "{n} ranks: a particle is {worst} m away from its one-rank position");
    }
}

/// A free blob with random velocities (no walls, no gravity; the `sph_conservation` validation set-up):
/// on 2 and 4 ranks the total momentum is conserved to round-off, so the pair forces computed on both
/// sides of a rank cut are exact opposites.
#[test]
fn momentum_balances_across_ranks() {
    for n in [2, 4] {
        let dp_rel = on_ranks(n, |comm| {
            let dp = 0.01;
            let mut p = SphParams::water(Dim::Three, dp, 20.0);
            p.gravity = Vec3::ZERO;
            p.density_window = [0.0, f64::INFINITY];
            let mut sim = Simulation::new(p);
            let mut pts = Vec::new();
            for k in 0..8 {
                for j in 0..8 {
                    for i in 0..8 {
                        pts.push(Vec3::new(i as f64, j as f64, k as f64) * dp);
                    }
                }
            }
            sim.add_particles(&pts, Vec3::ZERO);
            let mut rng = spatter_core::rng::seeded(7, 0);
            use spatter_core::rng::RngExt;
            for v in &mut sim.fluid.vel {
                *v = Vec3::new(
                    rng.random::<f64>() - 0.5,
                    rng.random::<f64>() - 0.5,
                    rng.random::<f64>() - 0.5,
                );
            }
            sim.set_domain(Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0)));
            let m = sim.params.mass();
            let p0: Vec3 = sim.fluid.vel.iter().copied().sum::<Vec3>() * m;
            let scale = m * sim.fluid.vel.iter().map(|v| v.length()).sum::<f64>();
            sim.initialize_with(comm).unwrap();
            for _ in 0..40 {
                sim.step_with(comm).unwrap();
            }
            let all = gathered(&sim, comm);
            assert_eq!(all.len(), pts.len());
            let p1: Vec3 = all.iter().map(|e| e.2).sum::<Vec3>() * m;
            (p1 - p0).length() / scale
        });
        // Same bound as the one-rank `sph_conservation` check: pairwise antisymmetric forces.
        assert!(dp_rel[0] < 1e-12, "{n} ranks: |ΔP|/Σm|v| = {:e}", dp_rel[0]);
    }
}

/// Plug flow at U = 1 cm/s along a channel periodic in x between no-slip plates (10 × 40 particles,
/// ν = 10⁻⁶ m²/s; a Stokes layer grows from each plate): the bulk moves 15 spacings in 400 steps, through
/// every cut of 4 ranks along x and across the periodic faces. Every step keeps every id exactly once.
///
/// Tolerance: interior pairs are evaluated in single precision (the batch path, relative rounding
/// ε₃₂ = 1.2·10⁻⁷ per term) and pairs with halo particles in double precision, like periodic images. In
/// this laminar flow the runs then differ by about ε₃₂ times the largest acceleration (the wall shear
/// ν U/dp² = 1 m/s²) times the time; the test allows ten times that. Reordering the sums alone (the same
/// run stored in reverse order) changes velocities by only 10⁻¹¹ m/s, so a missing or doubled halo
/// neighbour (an O(1) pressure error near a cut) would fail by orders of magnitude.
#[test]
fn periodic_shear_crosses_ranks() {
    let run = |n: usize, reverse: bool| {
        on_ranks(n, move |comm| {
            let l = 1e-3;
            let n_across = 10;
            let dp = l / n_across as f64;
            let u = 0.01;
            let mut p = SphParams::water(Dim::Two, dp, 10.0 * u);
            p.gravity = Vec3::ZERO;
            p.artificial_viscosity = 0.0;
            p.density_diffusion = 0.0;
            p.kinematic_viscosity = 1e-6;
            let lx = 40.0 * dp;
            let mut sim = Simulation::new(p);
            let layers = sim.default_layers();
            let thick = layers as f64 * dp;
            let wall = WallOptions { adhesion: 0.0, slip: Slip::NoSlip };
            let bottom = Aabb::new(Vec3::new(0.0, 0.0, -thick), Vec3::new(lx, 0.0, 0.0));
            let top = Aabb::new(Vec3::new(0.0, 0.0, l), Vec3::new(lx, 0.0, l + thick));
            sim.add_block("bottom", bottom, Some(layers), None, wall);
            sim.add_block("top", top, Some(layers), None, wall);
            sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(lx, 0.0, l)), Vec3::new(u, 0.0, 0.0), false);
            if reverse {
                sim = reversed(sim);
            }
            let total = sim.fluid.len();
            sim.set_domain(Aabb::new(
                Vec3::new(0.0, -1.0, -2.0 * thick),
                Vec3::new(lx, 1.0, l + 2.0 * thick),
            ));
            sim.set_periodic(0);
            sim.initialize_with(comm).unwrap();
            let mut migrated = [0u64];
            for s in 0..400 {
                sim.step_with(comm).unwrap();
                migrated[0] += sim.exchange_counts().1 as u64;
                let all = gathered(&sim, comm);
                assert_eq!(all.len(), total, "step {s}");
                assert!(all.iter().enumerate().all(|(k, e)| e.0 as usize == k), "ids once each, step {s}");
            }
            comm.all_sum_u64(&mut migrated);
            (gathered(&sim, comm), migrated[0], sim.time)
        })
        .remove(0)
    };
    let (one, _, t1) = run(1, false);
    let (rev, _, _) = run(1, true);
    let (four, migrated, t4) = run(4, false);
    let env = one.iter().zip(&rev).map(|(a, b)| (a.2 - b.2).length()).fold(0.0, f64::max);
    let w4 = one.iter().zip(&four).map(|(a, b)| (a.2 - b.2).length()).fold(0.0, f64::max);
    eprintln!("periodic shear: {migrated} migrations; worst |Δv| 4 ranks {w4:e} m/s, reordered {env:e} m/s");
    assert!(migrated > 100, "particles crossed the cuts: {migrated} migrations");
    let (u, nu, dp) = (0.01, 1e-6, 1e-4);
    let tol = 10.0 * f64::from(f32::EPSILON) * (nu * u / (dp * dp)) * t1;
    assert!(w4 <= tol, "worst velocity difference {w4:e} m/s > {tol:e} m/s");
    // The time step follows the largest acceleration, known to the same precision.
    assert!((t1 - t4).abs() <= 1e-5 * t1, "time after 400 steps: {t4} s vs {t1} s");
}

/// A 2D water column a × 4a (a = 0.1 m, spacing a/10: 400 particles) at the left of an open tank 8a
/// long. Split over 4 ranks it is cut along its height into four stacked boxes.
fn tall_column() -> Simulation {
    let a: f64 = 0.1;
    let g: f64 = 9.81;
    let dp = a / 10.0;
    let mut p = SphParams::water(Dim::Two, dp, 10.0 * (2.0 * g * 4.0 * a).sqrt());
    p.gravity = Vec3::new(0.0, 0.0, -g);
    let mut sim = Simulation::new(p);
    sim.add_tank(
        "tank",
        Aabb::new(Vec3::ZERO, Vec3::new(8.0 * a, 0.0, 5.0 * a)),
        OPEN_TOP,
        None,
        None,
        WallOptions::default(),
    );
    sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(a, 0.0, 4.0 * a)), Vec3::ZERO, true);
    sim
}

/// With load balancing off, a rank whose box empties during a run keeps stepping with the others: as
/// the tall column ([`tall_column`]) collapses on 4 ranks the upper boxes run dry. Every step keeps every
/// id exactly once, and the run goes on for 200 steps after the first rank has emptied, with sensors and
/// totals collective as ever.
#[test]
fn ranks_whose_boxes_empty_keep_stepping() {
    let counts = on_ranks(4, |comm| {
        let mut sim = tall_column();
        sim.set_rebalance(None);
        let total = sim.fluid.len();
        sim.initialize_with(comm).unwrap();
        let mut after_empty = None;
        let mut steps = 0;
        while after_empty.is_none_or(|s| steps < s + 200) {
            sim.step_with(comm).unwrap();
            steps += 1;
            assert!(steps < 20_000, "no rank emptied");
            let all = gathered(&sim, comm);
            assert_eq!(all.len(), total, "particle count at step {steps}");
            assert!(all.iter().enumerate().all(|(k, e)| e.0 as usize == k), "ids 0..{total} once each");
            let mut empty = [u64::from(sim.fluid.is_empty())];
            comm.all_sum_u64(&mut empty);
            if empty[0] > 0 && after_empty.is_none() {
                after_empty = Some(steps);
            }
        }
        let mass = total as f64 * sim.params.mass();
        assert!((sim.fluid_mass_with(comm) - mass).abs() <= 1e-12 * mass, "mass");
        assert!(sim.kinetic_energy_with(comm).is_finite());
        sim.fluid.len()
    });
    assert_eq!(counts.iter().sum::<usize>(), 400);
    assert!(counts.contains(&0), "a rank ended without particles: {counts:?}");
}

/// Dynamic load balancing: the tall column ([`tall_column`]) collapsing on 4 ranks with the default
/// limit (1.2). Every step keeps every id exactly once; no rank runs dry (with balancing off the two upper
/// boxes empty, `ranks_whose_boxes_empty_keep_stepping`); right after every check (every 20 steps) the
/// imbalance is within the limit; and after 1500 steps the run agrees with the same run on one rank to
/// round-off. Measured: 6 rebalances, fewest particles on a rank 71 of 400, every particle within
/// 2.5·10⁻⁷ m of its one-rank position (2.8·10⁻⁷ m on the fixed split: the difference is the
/// round-off of the halo pairs growing in this violent collapse, not the rebalancing). The test allows
/// 10⁻⁴ dp = 10⁻⁶ m; a missing halo neighbour moves particles by several 10⁻⁶ m within a few hundred
/// steps (`dam_break_2d_on_1_2_4_ranks`).
#[test]
fn a_collapsing_column_is_rebalanced_over_the_ranks() {
    let steps = 1500;
    let serial = on_ranks(1, move |comm| {
        let mut sim = tall_column();
        sim.initialize_with(comm).unwrap();
        for _ in 0..steps {
            sim.step_with(comm).unwrap();
        }
        gathered(&sim, comm)
    })
    .remove(0);
    let out = on_ranks(4, move |comm| {
        let mut sim = tall_column();
        let total = sim.fluid.len();
        sim.initialize_with(comm).unwrap();
        let (mut worst, mut fewest) = (0.0f64, usize::MAX);
        for s in 1..=steps {
            sim.step_with(comm).unwrap();
            let all = gathered(&sim, comm);
            assert_eq!(all.len(), total, "particle count at step {s}");
            assert!(all.iter().enumerate().all(|(k, e)| e.0 as usize == k), "ids 0..{total} once each");
            let mut least = [-(sim.fluid.len() as f64)];
            comm.all_max_f64(&mut least);
            fewest = fewest.min(-least[0] as usize);
            // The step just taken started with a check.
            if (s - 1) % spatter_sph::sim::REBALANCE_CHECK_STEPS as usize == 0 {
                worst = worst.max(spatter_core::rcb::Rcb::imbalance(comm, sim.fluid.len()));
            }
        }
        (gathered(&sim, comm), sim.rebalances(), worst, fewest)
    });
    let (end, rebalances, worst, fewest) = &out[0];
    let dp = 0.01;
    let far = serial.iter().zip(end).map(|(a, b)| (a.1 - b.1).length()).fold(0.0, f64::max);
    eprintln!(
        "tall column on 4 ranks: {rebalances} rebalances, worst imbalance after a check {worst}, \
         fewest particles on a rank {fewest}, worst particle {far:e} m from one rank"
    );
    assert!(*rebalances >= 1, "the split was never rebuilt");
    assert!(*fewest > 0, "a rank ran dry");
    assert!(*worst <= spatter_sph::sim::DEFAULT_REBALANCE, "imbalance {worst} after a check");
    assert!(far <= 1e-4 * dp, "a particle is {far} m away from its one-rank position");
}

/// A particle with a non-finite velocity on one rank: every rank returns the same blow-up error at the
/// end of the step (no rank left waiting in a collective).
#[test]
fn a_blow_up_on_one_rank_stops_every_rank() {
    let errs = on_ranks(3, |comm| {
        let mut sim = dam_break();
        sim.initialize_with(comm).unwrap();
        sim.step_with(comm).unwrap();
        if comm.rank() == 1 {
            let k = sim.fluid.len() / 2;
            sim.fluid.vel[k] = Vec3::new(f64::NAN, 0.0, 0.0);
        }
        let mut out = None;
        for _ in 0..3 {
            if let Err(e) = sim.step_with(comm) {
                out = Some(e.to_string());
                break;
            }
        }
        out
    });
    let first = errs[0].clone().expect("rank 0 reports the blow-up");
    assert!(first.contains("blow-up") && first.contains("non-finite"), "{first}");
    assert!(errs.iter().all(|e| e.as_deref() == Some(first.as_str())), "{errs:?}");
}

/// A set-up a decomposed run refuses, with the same sentence on every rank: more ranks than particles.
#[test]
fn refusals_are_the_same_on_every_rank() {
    let errs = on_ranks(8, |comm| {
        let mut p = SphParams::water(Dim::Two, 0.01, 1.0);
        p.gravity = Vec3::ZERO;
        let mut sim = Simulation::new(p);
        let pts: Vec<Vec3> = (0..5).map(|i| Vec3::new(i as f64 * 0.01, 0.0, 0.0)).collect();
        sim.add_particles(&pts, Vec3::ZERO);
        sim.initialize_with(comm).err().map(|e| e.to_string())
    });
    let e = errs[0].clone().expect("refused");
    assert!(e.contains("8 ranks for 5 particles"), "{e}");
    assert!(errs.iter().all(|x| x.as_deref() == Some(e.as_str())));
}

/// A drop 8 mm across (0.5 mm spacing, 208 particles) thrown at 1 m/s against a vertical wall of
/// adhesion factor 1, with the surface tension of water and gravity: capillary forces dominate (σ/(ρ dp²)
/// = 290 m/s²). Both need what the owner of a halo particle computes: its surface normal (the curvature
/// term pairs the normals of neighbours) and the wall adhesion it feels (the wall pushes back on it). On
/// 2 and 4 ranks, after 1500 steps (the drop has spread on the wall), every particle is within
/// 10⁻⁴ dp = 5·10⁻⁸ m of its one-rank position and the wall's wet record agrees (the tolerance of
/// `a_collapsing_column_is_rebalanced_over_the_ranks`). Measured 2026-11-27: 7.9·10⁻¹¹ m on 2 ranks,
/// 2.7·10⁻¹⁰ m on 4; with the halo's normals left at zero 1.1·10⁻⁶ m, with its adhesion left at zero
/// 3·10⁻⁴ m (0.6 dp) on 2 ranks.
#[test]
fn surface_tension_and_adhesion_on_1_2_4_ranks() {
    let dp = 0.0005;
    let steps = 1500;
    let run = move |n: usize| {
        on_ranks(n, move |comm| {
            let mut p = SphParams::water(Dim::Two, dp, 20.0);
            p.surface_tension = 0.072;
            let mut sim = Simulation::new(p);
            let wall = Aabb::new(Vec3::new(-0.01, 0.0, -0.05), Vec3::new(0.0, 0.0, 0.05));
            sim.add_block("wall", wall, None, None, WallOptions { adhesion: 1.0, ..WallOptions::default() });
            let (d, c) = (0.008, Vec3::new(0.005, 0.0, 0.0));
            let pts: Vec<Vec3> = (-8..8)
                .flat_map(|i| {
                    (-8..8).map(move |k| c + Vec3::new((i as f64 + 0.5) * dp, 0.0, (k as f64 + 0.5) * dp))
                })
                .filter(|x| (*x - c).length() < 0.5 * d)
                .collect();
            sim.add_particles(&pts, Vec3::new(-1.0, 0.0, 0.0));
            sim.set_domain(Aabb::new(Vec3::new(-0.05, -1.0, -0.1), Vec3::new(0.1, 1.0, 0.1)));
            sim.initialize_with(comm).unwrap();
            for _ in 0..steps {
                sim.step_with(comm).unwrap();
            }
            let wet = sim.wet_area_with(comm, 0, sim.time).wet_mean;
            (gathered(&sim, comm), wet)
        })
        .remove(0)
    };
    let (one, wet1) = run(1);
    assert_eq!(one.len(), 208);
    assert!(wet1 > 0.0, "the drop wets the wall");
    for n in [2, 4] {
        let (many, wet) = run(n);
        assert_eq!(many.len(), one.len(), "{n} ranks: particle count");
        let worst = one.iter().zip(&many).map(|(a, b)| (a.1 - b.1).length()).fold(0.0, f64::max);
        eprintln!(
            "drop on a wall, {n} ranks: worst particle {worst:e} m from one rank; wet {wet} against {wet1}"
        );
        assert!(worst <= 1e-4 * dp, "{n} ranks: a particle is {worst} m from its one-rank position");
        assert!((wet - wet1).abs() <= 1e-6 * wet1, "{n} ranks: mean wet {wet} against {wet1}");
    }
}

/// Sensors and totals on 1, 2 and 4 ranks after 200 steps of the dam break: kinetic energy, momentum,
/// mass, the tank's load, a probe in the column, a wall-pressure sensor on the back wall and the water at
/// the tank and its arrival rate (`part_water_with`; measured: 2·10⁻¹¹ and 2·10⁻⁸ relative). Collective
/// forms (`*_with`) agree with the one-rank plain methods within 10⁻⁶ relative, about ten single-precision
/// epsilons (the runs differ at the single-precision rounding of cut pairs, see
/// `dam_break_2d_on_1_2_4_ranks`; measured: up to 3·10⁻⁸ for the wall pressure, 10⁻¹⁰ for the energy); the
/// mass is exact. An entry counted on two ranks or on none would be off by its whole share. The tank's
/// wet area now and averaged over the run are among them: as the column falls the back wall above it
/// dries and leaves the wall sets (a flag left wet there would count a whole particle's area). A
/// wall-pressure sensor over the top of the back wall averages wet wall particles and dry ones that no
/// rank holds in its wall set (they read the dry state, 0 Pa, as on one rank).
#[test]
fn sensors_agree_across_rank_counts() {
    let sensors = |n: usize| {
        on_ranks(n, move |comm| {
            let mut sim = dam_break();
            sim.initialize_with(comm).unwrap();
            for _ in 0..200 {
                sim.step_with(comm).unwrap();
            }
            let load = sim.part_loads_with(comm)[0].force;
            let (p, v) = sim.probe_with(comm, Vec3::new(0.05, 0.0, 0.05)).unwrap();
            let pw = sim.wall_pressure_with(comm, Vec3::new(-0.0025, 0.0, 0.03), 0.02).unwrap();
            // Over the back wall's top: wet wall particles in the sets and dry ones above, outside every
            // rank's wall set on several ranks (a miscount changes the mean).
            let dry = sim.wall_pressure_with(comm, Vec3::new(-0.0025, 0.0, 0.19), 0.08).unwrap();
            let m = sim.momentum_with(comm);
            let wet = sim.wet_area_with(comm, 0, sim.time);
            let water = sim.part_water_with(comm, 0);
            [
                sim.kinetic_energy_with(comm),
                m.x,
                m.z,
                sim.fluid_mass_with(comm),
                load.x,
                load.z,
                p,
                v.x,
                v.z,
                pw,
                wet.wet_now,
                wet.wet_mean,
                dry,
                water.volume,
                water.arrival,
            ]
        })
        .remove(0)
    };
    let one = sensors(1);
    let names = [
        "E_kin", "P_x", "P_z", "mass", "F_x", "F_z", "p_probe", "u_probe", "w_probe", "p_wall", "wet_now",
        "wet_mean", "p_top", "water", "arrival",
    ];
    assert!(one[9] > 500.0, "the back-wall sensor is under water: {} Pa", one[9]);
    assert!(one[12] > 0.0, "the top sensor reaches wet wall particles: {} Pa", one[12]);
    assert!(one[13] > 0.0 && one[14] > 0.0, "water at the tank, arriving: {} m², {} m²/s", one[13], one[14]);
    for n in [2, 4] {
        let got = sensors(n);
        assert_eq!(got[3], one[3], "mass is exact");
        for k in 0..one.len() {
            // Momentum and probe velocities are compared against the scale of their largest component.
            let scale = match k {
                1 | 2 => one[1].abs().max(one[2].abs()),
                7 | 8 => one[7].abs().max(one[8].abs()),
                4 | 5 => one[4].abs().max(one[5].abs()),
                _ => one[k].abs(),
            };
            let rel = (got[k] - one[k]).abs() / scale;
            eprintln!("{n} ranks {}: {} vs {} (rel {rel:e})", names[k], got[k], one[k]);
            assert!(rel <= 1e-6, "{n} ranks, {}: {} vs {}", names[k], got[k], one[k]);
        }
    }
}

/// Wet flags and wet times agree across rank counts, also where the water leaves a wall: after 1000
/// steps of the dam break (t = 0.096 s, the column's top sunk from 0.2 to 0.164 m) every wall particle's
/// wet flag and wet time on 2 and 4 ranks equal the one-rank run's (flags exactly; times within 10⁻⁹ s,
/// the time steps differ at round-off: measured 5·10⁻¹² s), and at least five wall particles that were
/// wet are dry again (measured 12: the upper back wall and spots of the floor under the surge). The
/// upper back wall leaves the wall sets of the ranks as the column sinks; it dries in the wetting pass
/// before it leaves (the wall region reaches at least two supports beyond the fluid, which moves less than
/// a spacing per step), so this does not exercise the clearing of flags of particles that leave a set
/// while wet (`dry_walls_that_left`: after a fluid particle next to them is removed).
#[test]
fn walls_the_water_leaves_are_dry_on_every_rank_count() {
    let wetting = |n: usize| {
        on_ranks(n, move |comm| {
            let mut sim = dam_break();
            sim.initialize_with(comm).unwrap();
            for _ in 0..1000 {
                sim.step_with(comm).unwrap();
            }
            sim.wetting_with(comm)
        })
        .remove(0)
    };
    let (wet1, time1) = wetting(1);
    let dried = wet1.iter().zip(&time1).filter(|(&w, &t)| !w && t > 0.0).count();
    assert!(dried >= 5, "{dried} wall particles dried");
    for n in [2, 4] {
        let (wet, time) = wetting(n);
        let differ = wet.iter().zip(&wet1).filter(|(a, b)| a != b).count();
        let worst = time.iter().zip(&time1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        eprintln!("{n} ranks: {differ} wet flags differ, wet times by {worst:e} s; {dried} dried");
        assert_eq!(differ, 0, "{n} ranks: wet flags differ from one rank");
        assert!(worst <= 1e-9, "{n} ranks: wet times differ by {worst} s");
    }
}

/// A layer of water sliding out of the domain next to a wall leaves that wall dry on every rank count.
/// 2D, spacing 5 mm: a layer 3 cm deep and 10 cm long slides along the tank's floor at 2 m/s towards the
/// domain's end at x = 0.3 m, where it is removed (counted), while a pool rests in the far corner. On one
/// rank the floor the layer wetted dries in the wall pass after the last water over it left. On 2 and 4
/// ranks the rank that owned the layer ends with no fluid, so its wall region and wall set shrink in the
/// step the last water is removed and the floor there leaves the set without another pass: its wet flags
/// are cleared as it leaves. (With that clearing switched off, 2 ranks kept two floor particles wet
/// here that one rank had dried.)
#[test]
fn walls_next_to_water_leaving_the_domain_are_dry_on_every_rank_count() {
    fn layer() -> Simulation {
        let dp = 0.005;
        let mut p = SphParams::water(Dim::Two, dp, 30.0);
        p.gravity = Vec3::new(0.0, 0.0, -9.81);
        let mut sim = Simulation::new(p);
        sim.add_tank(
            "tank",
            Aabb::new(Vec3::ZERO, Vec3::new(0.6, 0.0, 0.2)),
            OPEN_TOP,
            None,
            None,
            WallOptions::default(),
        );
        sim.set_domain(Aabb::new(Vec3::new(-0.1, -1.0, -0.1), Vec3::new(0.3, 1.0, 0.3)));
        sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(0.05, 0.0, 0.04)), Vec3::ZERO, true);
        sim.fill_box(
            Aabb::new(Vec3::new(0.12, 0.0, 0.0), Vec3::new(0.22, 0.0, 0.03)),
            Vec3::new(2.0, 0.0, 0.0),
            true,
        );
        sim
    }
    let run = |n: usize| {
        on_ranks(n, move |comm| {
            let mut sim = layer();
            sim.initialize_with(comm).unwrap();
            let mut wet_floor_ahead = 0;
            while sim.time < 0.25 {
                sim.step_with(comm).unwrap();
                if (sim.time - 0.04).abs() < 0.5 * sim.dt {
                    // Mid-way: the layer is over the floor near the domain's end.
                    let (wet, _) = sim.wetting_with(comm);
                    let b = &sim.boundary;
                    wet_floor_ahead = (0..b.len())
                        .filter(|&i| {
                            wet[i] && b.position(i).x > 0.22 && b.position(i).x < 0.3 && b.position(i).z < 0.0
                        })
                        .count();
                }
            }
            // The removal counts are summed over the ranks in every step: each rank holds the total.
            let (wet, time) = sim.wetting_with(comm);
            (wet, time, sim.removed.outside_domain, wet_floor_ahead, sim.boundary.clone())
        })
        .remove(0)
    };
    let (wet1, time1, removed1, ahead1, b) = run(1);
    // What the case must show for the comparison to mean anything: the layer left the domain, it had
    // wetted the floor ahead, and that floor is dry at the end on one rank.
    assert!(removed1 >= 100, "{removed1} particles left the domain");
    assert!(ahead1 >= 5, "{ahead1} floor particles wet under the layer");
    let floor_ahead = |i: usize| b.position(i).x > 0.22 && b.position(i).x < 0.3 && b.position(i).z < 0.0;
    let dried = (0..b.len()).filter(|&i| floor_ahead(i) && !wet1[i] && time1[i] > 0.0).count();
    assert!(dried >= 5, "{dried} floor particles dried after the layer left");
    for n in [2, 4] {
        let (wet, time, removed, ahead, _) = run(n);
        let differ: Vec<usize> = (0..wet.len()).filter(|&i| wet[i] != wet1[i]).collect();
        let worst = time.iter().zip(&time1).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        eprintln!("{n} ranks: {removed} removed, {ahead} wet ahead, wet flags differ at {differ:?}, wet times by {worst:e} s");
        assert_eq!(removed, removed1, "{n} ranks: particles removed");
        assert!(differ.is_empty(), "{n} ranks: wet flags differ from one rank at {differ:?}");
        assert!(worst <= 1e-9, "{n} ranks: wet times differ by {worst} s");
    }
}
