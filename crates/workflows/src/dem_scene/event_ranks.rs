//! The event log and the trajectories of a scene split over ranks.
//!
//! Each rank logs the objects (bodies and free spheres) it owns: the wall impacts its particles make and
//! the plane crossings of its objects. An object changes rank only at a neighbour-list rebuild; in that
//! step the rank it left hands its last signed distance to the crossing plane on to the rank it went to,
//! so a crossing in the step of the move is seen as on one rank. The records an object leaves behind
//! (its first impact, its collisions so far) stay where they were made and are merged when the log is
//! written: collisions add up, the earliest first impact and crossing count. So `events.csv` is the
//! one-rank file. The followed objects' trajectory rows are gathered on rank 0 in the one-rank order.

use super::events::{trajectory_rows, EventLog, Key, TrajectoryConfig};
use spatter_core::comm::{Comm, WireReader, WireWriter};
use spatter_dem::contact::ContactLaw;
use spatter_dem::sim::Simulation;
use std::collections::BTreeSet;

impl EventLog {
    /// Hands the plane side of every object that left this rank in the last step to the rank it went
    /// to (collective; only in steps with a list rebuild, and the first step after a start or resume,
    /// which all ranks share). Call before taking in the step ([`EventLog::after_step`]).
    pub(crate) fn hand_over<L: ContactLaw>(&mut self, sim: &Simulation<L>, comm: &dyn Comm) {
        if sim.ranks() == 1 {
            return;
        }
        let rebuilds = sim.rebuild_count();
        if self.rebuilds_seen == Some(rebuilds) {
            return;
        }
        self.rebuilds_seen = Some(rebuilds);
        let here = local_objects(sim);
        let mut w = WireWriter::with_capacity(0);
        for (key, rec) in self.records.iter_mut() {
            if rec.side.is_finite() && !here.contains(key) {
                w.u32(u32::from(key.0)).u32(key.1).f64(rec.side);
                rec.side = f64::NAN;
            }
        }
        let walls = sim.walls.len();
        for buf in comm.all_gather_bytes(&w.finish()) {
            let mut r = WireReader::new(&buf);
            let bad = "event message from another rank of this run";
            while !r.is_done() {
                let key: Key = (r.u32().expect(bad) == 1, r.u32().expect(bad));
                let side = r.f64().expect(bad);
                if here.contains(&key) {
                    let template = template_of(sim, key);
                    self.record(key, template, walls).side = side;
                }
            }
        }
    }

    /// Adds the records of `other` (another rank's) to this log: collisions add up, the earlier first
    /// impact (in one step an object is on one rank only) and the earlier crossing are kept.
    pub(crate) fn merge(&mut self, other: EventLog) {
        for (key, r) in other.records {
            let Some(mine) = self.records.get_mut(&key) else {
                self.records.insert(key, r);
                continue;
            };
            mine.template = mine.template.max(r.template);
            for (a, b) in mine.collisions.iter_mut().zip(&r.collisions) {
                *a += b;
            }
            if let Some(f) = r.first {
                if mine.first.is_none_or(|m| f.t < m.t) {
                    mine.first = Some(f);
                }
            }
            if let Some(c) = r.crossing {
                if mine.crossing.is_none_or(|m| c.t < m.t) {
                    mine.crossing = Some(c);
                }
            }
            if !mine.side.is_finite() {
                mine.side = r.side;
            }
        }
    }

    /// The log of the whole run: this log merged with every other rank's, in rank order (collective; the
    /// log itself on one rank).
    pub(crate) fn gathered(&self, comm: &dyn Comm) -> EventLog {
        if comm.size() == 1 {
            return self.clone();
        }
        let bytes = bincode::serialize(self).expect("an event log serialises to memory");
        let mut all = EventLog::default();
        for buf in comm.all_gather_bytes(&bytes) {
            let part: EventLog = bincode::deserialize(&buf).expect("event log from another rank of this run");
            all.merge(part);
        }
        all
    }
}

/// The objects this rank owns: its bodies and free spheres.
fn local_objects<L: ContactLaw>(sim: &Simulation<L>) -> BTreeSet<Key> {
    let p = &sim.particles;
    let mut here: BTreeSet<Key> = sim.bodies().id.iter().map(|&b| (true, b)).collect();
    here.extend((0..p.len()).filter(|&i| !p.is_member(i)).map(|i| (false, p.id[i])));
    here
}

/// The template of a local body (−1 for a sphere).
fn template_of<L: ContactLaw>(sim: &Simulation<L>, key: Key) -> i64 {
    if key.0 {
        super::events::body_template(sim.bodies(), key.1)
    } else {
        -1
    }
}

/// [`trajectory_rows`] of every rank, in the one-rank order (bodies then spheres, each by id);
/// collective on several ranks.
pub(crate) fn trajectory_rows_with<L: ContactLaw>(
    sim: &Simulation<L>,
    cfg: &TrajectoryConfig,
    comm: &dyn Comm,
) -> Vec<Vec<f64>> {
    let rows = trajectory_rows(sim, cfg);
    if sim.ranks() == 1 {
        return rows;
    }
    let width = super::events::TRAJECTORY_COLUMNS.len();
    let mut w = WireWriter::with_capacity(8 * width * rows.len());
    for x in rows.iter().flatten() {
        w.f64(*x);
    }
    let mut all: Vec<Vec<f64>> = Vec::new();
    for buf in comm.all_gather_bytes(&w.finish()) {
        let mut r = WireReader::new(&buf);
        while !r.is_done() {
            all.push(
                (0..width).map(|_| r.f64().expect("trajectory rows from another rank of this run")).collect(),
            );
        }
    }
    // Columns 1 and 2: body (1) or sphere (0), and the id.
    all.sort_by(|a, b| b[1].total_cmp(&a[1]).then(a[2].total_cmp(&b[2])));
    all
}

#[cfg(test)]
mod tests {
    use super::super::events::{CrossingPlane, EventsConfig};
    use super::*;
    use spatter_core::comm::ThreadComm;
    use spatter_core::material::Material;
    use spatter_core::Vec3;
    use spatter_dem::contact::HertzMindlin;
    use spatter_dem::sim::uniform_pairs;
    use spatter_dem::{NewParticle, Settings};

    /// A sphere moving at 1 m/s along x past frozen anchors, a rebuild in every step (no Verlet list),
    /// so it changes rank in the very step it crosses the cut between two ranks.
    fn scene() -> Simulation<HertzMindlin> {
        let mats = vec![Material { youngs_modulus: 5e7, poisson_ratio: 0.3, density: 2500.0 }];
        let pairs = uniform_pairs(&mats, 0.5, 0.5);
        let settings = Settings { verlet_list: false, ..Settings::default() };
        let mut sim = Simulation::new(HertzMindlin::default(), mats, pairs, 1e-5, settings);
        sim.set_rebalance(None);
        let mut a = NewParticle::at(Vec3::new(-0.0004, 0.0, 0.0), 0.001, 0);
        a.vel = Vec3::X;
        sim.add_particle(a);
        // Three points on each side of x = 0.0002 (the sphere counts on the left): the cut.
        for (x, y) in [(-0.5, 0.0), (-0.3, 0.0), (0.0008, 0.3), (0.3, 0.0), (0.5, 0.0)] {
            let mut f = NewParticle::at(Vec3::new(x, y, 0.0), 0.001, 0);
            f.frozen = true;
            sim.add_particle(f);
        }
        sim
    }

    /// The crossing of a plane laid exactly on the cut between two ranks, by a sphere that changes rank
    /// in the step it crosses (the case the hand-over of the plane side exists for), is logged at the
    /// one-rank time and place (the same bits); without the hand-over the rank it arrives at would see
    /// no earlier side and miss the crossing.
    #[test]
    fn a_crossing_in_the_step_of_a_change_of_rank_is_logged() {
        let run = |comm: &dyn Comm, plane_x: Option<f64>| {
            let mut sim = scene();
            sim.decompose(comm).unwrap();
            // The cut: the upper x face of rank 0's box (on one rank the value two ranks find).
            let x = plane_x.unwrap_or_else(|| sim.rank_box().map_or(0.0, |b| b.max.x));
            let mut x_all = [if comm.rank() == 0 { x } else { f64::NEG_INFINITY }];
            comm.all_max_f64(&mut x_all);
            let cfg = EventsConfig {
                angle_plane_normal: None,
                crossing_plane: Some(CrossingPlane {
                    point_m: Vec3::new(x_all[0], 0.0, 0.0),
                    normal: Vec3::X,
                }),
                first_impact_walls: Vec::new(),
            };
            let mut log = EventLog::default();
            let mut owners = Vec::new();
            for _ in 0..100 {
                sim.step_with(comm).unwrap();
                log.hand_over(&sim, comm);
                log.after_step(&sim, &cfg);
                owners.push(sim.particles.index_of(0).is_some());
            }
            (log.gathered(comm), x_all[0], owners)
        };
        let two = ThreadComm::run(2, |c| run(c, None));
        let cut = two[0].1;
        assert!(cut > -0.0004 && cut < 0.0006, "the cut {cut} lies in the sphere's path");
        let moved = (1..100).any(|k| two[0].2[k] != two[0].2[k - 1]);
        assert!(moved, "the sphere changed rank");
        let one = ThreadComm::run(1, |c| run(c, Some(cut)));
        let crossing = |log: &EventLog| log.records.get(&(false, 0)).and_then(|r| r.crossing);
        let want = crossing(&one[0].0).expect("one rank logs the crossing");
        for (r, got) in two.iter().enumerate() {
            assert_eq!(crossing(&got.0), Some(want), "rank {r}");
        }
    }
}
