//! Continuing a run from a checkpoint written on another number of ranks (`--repartition`).
//!
//! Each rank of a split run checkpoints its own particles, its neighbour lists with the contact states of
//! its pairs, the contact states of its particles with ghosts (a pair across a rank cut is held by both
//! ranks, with identical states), and its partial sums (energy accounts, removals, mesh impact records).
//! [`Simulation::join_parts`] turns these parts into the state of one rank that holds every particle: the
//! particles in id order, every contact state keyed by the ids of its pair (or by particle id, wall and
//! triangle) and restored into freshly built lists, the partial sums added in rank order. A run on one
//! rank then goes on from there; a run on several ranks splits this state afresh with
//! [`Simulation::decompose_over`], exactly as a run splits its set-up at the start.
//!
//! Rigid bodies are gathered in id order, each with its members (a body lives whole on one rank).
//!
//! The continued run is the same physical state with the same contact history, but not bit for bit the
//! uninterrupted one: the lists are rebuilt at the join (a rebuild re-sorts the particles, so forces are
//! added in another order), and on another number of ranks a particle's forces are added in another order
//! anyway (see [`super::decomp`]).

use super::decomp::RankState;
use super::rank_bodies::JoinedBodies;
use super::{DynState, EnergyAccounts, LastEvaluation, SimState, Simulation};
use crate::contact::ContactLaw;
use crate::error::DemError;
use crate::particles::Particles;
use crate::walls::{MeshRecords, WallShape};

/// One rank's part of a checkpoint: its state and, when several ranks wrote it, its share of the split.
pub type CheckpointPart<S> = (SimState<S>, Option<RankState<S>>);

impl<L: ContactLaw> Simulation<L> {
    /// Takes the state of a checkpoint written on any number of ranks: `parts` are the parts of the ranks
    /// that wrote it, in their rank order (a one-rank checkpoint is one part without a rank state, and is
    /// restored exactly as by [`Self::restore`]). Afterwards this simulation holds every particle, as on
    /// one rank, with all contact states, the energy accounts, removal counts and mesh records added in
    /// rank order; the neighbour lists are rebuilt at the current positions. To continue on several ranks,
    /// split it with [`Self::decompose_over`] (every rank joins the same parts alike).
    ///
    /// Refused with a sentence: no parts, parts of different steps, walls that do not match the scene,
    /// and a simulation already split over ranks.
    pub fn join_parts(&mut self, parts: Vec<CheckpointPart<L::State>>) -> Result<(), DemError> {
        if self.decomp.is_some() {
            return Err(DemError::Resume(
                "joining checkpoint parts into a run already split over ranks".into(),
            ));
        }
        let mut parts = parts;
        if parts.len() == 1 && parts[0].1.is_none() {
            let (state, _) = parts.pop().expect("one part");
            return self.restore(state).map_err(DemError::Resume);
        }
        if parts.is_empty() {
            return Err(DemError::Resume("the checkpoint has no parts".into()));
        }
        let mut joined = Particles::new();
        let (mut carry, mut wall_carry) = (Vec::new(), Vec::new());
        let mut records: Vec<Option<MeshRecords>> = Vec::new();
        let mut total: Option<DynState<L::State>> = None;
        let mut bodies = JoinedBodies::new();
        for (rank, (state, split)) in parts.into_iter().enumerate() {
            self.restore(state).map_err(|e| DemError::Resume(format!("the part of rank {rank}: {e}")))?;
            let (c, w) = self.collect_carries();
            carry.extend(c);
            wall_carry.extend(w);
            if let Some(s) = split {
                carry.extend(s.ghost_contacts);
            }
            let mine = self.walls.iter().map(|w| match &w.shape {
                WallShape::Mesh(m) => Some(&m.records),
                _ => None,
            });
            if rank == 0 {
                records = mine.map(|r| r.cloned()).collect();
            } else {
                for (sum, r) in records.iter_mut().zip(mine) {
                    if let (Some(sum), Some(r)) = (sum.as_mut(), r) {
                        sum.add(r);
                    }
                }
            }
            let mut part = std::mem::take(&mut self.particles);
            bodies.take(&self.st.bodies, &mut part.body);
            joined.append(part);
            let st = std::mem::take(&mut self.st);
            match total.as_mut() {
                None => total = Some(st),
                Some(t) => {
                    if st.step != t.step || st.time != t.time {
                        return Err(DemError::Resume(format!(
                            "the part of rank {rank} is at step {} (t = {} s), the part of rank 0 at step {} \
                             (t = {} s): the parts belong to different checkpoints",
                            st.step, st.time, t.step, t.time
                        )));
                    }
                    add_accounts(&mut t.energy, &st.energy);
                    add_last(&mut t.last, &st.last);
                    t.removed += st.removed;
                    t.r_max = t.r_max.max(st.r_max);
                    t.forces_valid &= st.forces_valid;
                    t.needs_rebuild |= st.needs_rebuild;
                }
            }
        }
        let mut st = total.expect("at least one part");
        st.list = Default::default();
        st.wall_list = Default::default();
        st.bodies = bodies.finish(&mut joined.body)?;
        self.st = st;
        joined.sort_by_id();
        self.particles = joined;
        self.evaluated_ids = self.particles.next_id();
        for (wall, r) in self.walls.iter_mut().zip(records) {
            if let (WallShape::Mesh(m), Some(r)) = (&mut wall.shape, r) {
                m.records = r;
            }
        }
        // A pair across a rank cut was held by both ranks with the same state: keep one.
        carry.sort_unstable_by_key(|c| c.0);
        carry.dedup_by_key(|c| c.0);
        wall_carry.sort_unstable_by_key(|c| c.0);
        let r_max = self.particles.radius.iter().copied().fold(0.0, f64::max);
        self.build_lists(r_max, &carry, &wall_carry);
        self.finish_rebuild();
        Ok(())
    }
}

/// Adds the accounts `b` of another rank to `a`.
fn add_accounts(a: &mut EnergyAccounts, b: &EnergyAccounts) {
    a.dissipated += b.dissipated;
    a.injected_kinetic += b.injected_kinetic;
    a.injected_rotational += b.injected_rotational;
    a.injected_moment += b.injected_moment;
    a.external_work += b.external_work;
    a.wall_work += b.wall_work;
}

/// Adds the last evaluation `b` of another rank to `a` (the largest overlap is the larger one).
fn add_last(a: &mut LastEvaluation, b: &LastEvaluation) {
    a.elastic += b.elastic;
    a.pair_contacts += b.pair_contacts;
    a.wall_contacts += b.wall_contacts;
    a.max_overlap_ratio = a.max_overlap_ratio.max(b.max_overlap_ratio);
    a.energy_booked &= b.energy_booked;
}
