//! What the tests of the DEM engine on thread-ranks share: running ranks with a deadline, the soft
//! material, the box of planes, the ids over all ranks.

#![allow(dead_code)]

use spatter_core::comm::{Comm, ThreadComm, WireReader, WireWriter};
use spatter_core::material::Material;
use spatter_core::motion::Motion;
use spatter_core::Vec3;
use spatter_dem::contact::{ContactLaw, HertzMindlinRolling};
use spatter_dem::walls::{Plane, Wall, WallShape};
use spatter_dem::Simulation;
use std::sync::mpsc;
use std::time::Duration;

/// Runs `f` on `n` thread-ranks and fails (instead of hanging) if they take longer than `secs`.
pub fn on_ranks<T: Send + 'static>(
    n: usize,
    secs: u64,
    f: impl Fn(&dyn Comm) -> T + Send + Sync + 'static,
) -> Vec<T> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let out = ThreadComm::run(n, |c| f(c));
        let _ = tx.send(out);
    });
    match rx.recv_timeout(Duration::from_secs(secs)) {
        Ok(v) => v,
        Err(mpsc::RecvTimeoutError::Timeout) => panic!("{n} ranks did not finish within {secs} s: a hang"),
        Err(mpsc::RecvTimeoutError::Disconnected) => panic!("a rank panicked (see its message above)"),
    }
}

pub fn soft() -> Material {
    Material { youngs_modulus: 5e7, poisson_ratio: 0.3, density: 2500.0 }
}

pub fn plane(name: &str, p: Vec3, n: Vec3, material: u16) -> Wall {
    Wall { name: name.into(), shape: WallShape::Plane(Plane::new(p, n)), material, motion: Motion::Fixed }
}

/// The box [0, l]³ of planes; wall 5 is the floor.
pub fn box_planes<L: spatter_dem::contact::ContactLaw>(
    sim: &mut Simulation<L>,
    l: f64,
    side: u16,
    floor: u16,
) {
    sim.add_wall(plane("x0", Vec3::ZERO, Vec3::X, side));
    sim.add_wall(plane("x1", Vec3::splat(l), -Vec3::X, side));
    sim.add_wall(plane("y0", Vec3::ZERO, Vec3::Y, side));
    sim.add_wall(plane("y1", Vec3::splat(l), -Vec3::Y, side));
    sim.add_wall(plane("top", Vec3::splat(l), -Vec3::Z, side));
    sim.add_wall(plane("floor", Vec3::ZERO, Vec3::Z, floor));
}

/// Every rank's particle ids, gathered and sorted (collective).
pub fn all_ids<L: spatter_dem::contact::ContactLaw>(sim: &Simulation<L>, comm: &dyn Comm) -> Vec<u32> {
    let mut w = WireWriter::with_capacity(4 * sim.particles.len());
    for &id in &sim.particles.id {
        w.u32(id);
    }
    let mut ids = Vec::new();
    for buf in comm.all_gather_bytes(&w.finish()) {
        let mut r = WireReader::new(&buf);
        while !r.is_done() {
            ids.push(r.u32().expect("ids"));
        }
    }
    ids.sort_unstable();
    ids
}

/// The empty 10 cm box of a pile: the engine's settled-pile validation box
/// ([`spatter_dem::validation::bulk::settled_pile_box`]).
pub fn pile_box() -> Simulation<HertzMindlinRolling> {
    spatter_dem::validation::bulk::settled_pile_box()
}

/// Id, position and velocity of every particle on every rank, sorted by id (collective).
pub fn gather_by_id<L: ContactLaw>(sim: &Simulation<L>, comm: &dyn Comm) -> Vec<(u32, Vec3, Vec3)> {
    let p = &sim.particles;
    gather_rows(comm, (0..p.len()).map(|i| (p.id[i], p.pos[i], p.vel[i])))
}

/// This rank's (id, position, velocity) `rows` and every other rank's, sorted by id (collective).
pub fn gather_rows(comm: &dyn Comm, rows: impl Iterator<Item = (u32, Vec3, Vec3)>) -> Vec<(u32, Vec3, Vec3)> {
    let mut w = WireWriter::with_capacity(0);
    for (id, x, v) in rows {
        w.u32(id).vec3(x).vec3(v);
    }
    let mut all = Vec::new();
    for buf in comm.all_gather_bytes(&w.finish()) {
        let mut r = WireReader::new(&buf);
        while !r.is_done() {
            all.push((r.u32().unwrap(), r.vec3().unwrap(), r.vec3().unwrap()));
        }
    }
    all.sort_unstable_by_key(|a| a.0);
    all
}

/// Largest distance between the positions of the same ids in `a` and `b` \[m\]; the id sets must be equal.
pub fn largest_shift(a: &[(u32, Vec3, Vec3)], b: &[(u32, Vec3, Vec3)]) -> f64 {
    assert_eq!(a.iter().map(|x| x.0).collect::<Vec<_>>(), b.iter().map(|x| x.0).collect::<Vec<_>>());
    a.iter().zip(b).map(|(x, y)| (x.1 - y.1).length()).fold(0.0, f64::max)
}
