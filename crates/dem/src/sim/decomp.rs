//! The DEM step on several ranks: domain decomposition of the spheres.
//!
//! Space is split by recursive coordinate bisection ([`Rcb`]) of the particle centres when the run is
//! decomposed (every rank built the same set-up and keeps the particles in its box). Each rank integrates
//! only the particles it owns. Walls, analytic and mesh, are replicated: every rank holds them whole and
//! moves them by the same kinematics; a particle's wall contacts are computed by its owner.
//!
//! * **Ownership changes only at a neighbour-list rebuild.** Between rebuilds a particle moves less than
//!   half the Verlet skin, so it may leave its owner's box by that much; at the rebuild it migrates to the
//!   rank whose box holds it, with its whole state and the contact history that involves it (the states
//!   of its pair contacts keyed by both ids, and of its wall contacts keyed by (id, wall, triangle)).
//! * **Ghosts.** At a rebuild every rank sends each neighbour the particles within the halo width
//!   `w = 2 r_max + range + skin` of that neighbour's box (the cell of the neighbour search: every pair
//!   the Verlet list can hold has one partner within `w` of the other's box). Before every force
//!   evaluation their positions, velocities and spins are sent again along the same lists.
//! * **Cross-rank contacts are computed on both ranks** ("newton off"): each rank keeps, per owned
//!   particle, a list of ghost partners with one contact state each and applies the force to its own
//!   particle only. The contact law sees the pair from the lower id's side on both ranks, with inputs
//!   formed so that they are bit-identical whichever particle is local (negation and commutative sums
//!   are exact), so the two copies of the state stay identical and the forces are equal and opposite.
//!   Energies and contact counts of such a pair are booked by the rank owning the lower id.
//! * **Collectives at fixed points**: one maximum per step (largest speed for the displacement bound, and
//!   whether any rank needs a rebuild, so all ranks rebuild in the same step), one per force evaluation
//!   (the largest overlap, for the blow-up stop) and one per step for a non-finite state. An error is
//!   raised on every rank alike with the text of the rank that saw it.
//! * **Determinism**: a run on a given number of ranks repeats bit for bit (messages are read in rank
//!   order, sorts are stable, reductions exact or in rank order). Another number of ranks adds the contact
//!   forces of a particle in another order, so it agrees with a one-rank run to round-off, which a dense
//!   granular packing amplifies (bulk quantities agree; trajectories of single grains do not).
//!
//! Rigid bodies (clumps) live whole on the rank of their centre of mass ([`super::rank_bodies`]). The
//! multi-step and implicit integrators are refused on several ranks with a sentence naming what to
//! change.

use super::forces::{Acc, SlotOut};
use super::neighbors::{pair_key, Carries, PairCarry, WallCarry};
use super::{Integrator, ParticleView, Simulation};
use crate::clump::NO_BODY;
use crate::contact::{ContactInput, ContactLaw, PairTable};
use crate::error::DemError;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::comm::{Comm, WireReader, WireWriter};
use spatter_core::rcb::Rcb;
use spatter_core::{Aabb, Vec3};

/// Particles per parallel block of the ghost contact loop.
const BLOCK: usize = 1024;

pub use spatter_core::rcb::DEFAULT_REBALANCE;

/// The particles of other ranks near this rank's box, and the contacts of owned particles with them.
#[derive(Clone, Debug)]
pub(crate) struct Ghosts<S> {
    pub id: Vec<u32>,
    pub material: Vec<u16>,
    pub pos: Vec<Vec3>,
    pub vel: Vec<Vec3>,
    pub omega: Vec<Vec3>,
    pub radius: Vec<f64>,
    pub inv_mass: Vec<f64>,
    /// Ghost partners of owned particle i: `nbr[start[i]..start[i+1]]` (ghost indices, ascending).
    pub start: Vec<u32>,
    pub nbr: Vec<u32>,
    /// One contact state per partner slot, from the lower id's point of view.
    pub state: Vec<S>,
}

impl<S> Default for Ghosts<S> {
    fn default() -> Self {
        Ghosts {
            id: Vec::new(),
            material: Vec::new(),
            pos: Vec::new(),
            vel: Vec::new(),
            omega: Vec::new(),
            radius: Vec::new(),
            inv_mass: Vec::new(),
            start: vec![0],
            nbr: Vec::new(),
            state: Vec::new(),
        }
    }
}

impl<S> Ghosts<S> {
    fn clear_particles(&mut self) {
        self.id.clear();
        self.material.clear();
        self.pos.clear();
        self.vel.clear();
        self.omega.clear();
        self.radius.clear();
        self.inv_mass.clear();
    }
}

/// What a checkpoint part of a rank keeps of the split ([`Simulation::rank_state`]).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RankState<S> {
    /// The split of space over the ranks.
    pub partition: Rcb,
    /// Contact states of this rank's particles with ghosts, keyed by the pair's ids (sorted).
    pub ghost_contacts: Vec<(u64, S)>,
}

/// This rank's share of a decomposed run.
#[derive(Clone, Debug)]
pub(crate) struct Decomp<S> {
    rcb: Rcb,
    rank: usize,
    size: usize,
    boxes: Vec<Aabb>,
    /// Ranks whose box lies within the halo width of this rank's box (at the last rebuild), sorted.
    peer_ranks: Vec<usize>,
    /// Per entry of `peer_ranks`: the local indices of the particles sent as ghosts at the last rebuild.
    send: Vec<Vec<u32>>,
    pub(crate) ghosts: Ghosts<S>,
    /// Contact states carried from before the split, restored at the first rebuild.
    pending: Carries<S>,
    /// The ghosts' values were sent after the last drift (no refresh needed before the next evaluation).
    fresh: bool,
    /// Particles received by migration at the last rebuild.
    last_migrants: usize,
    /// Times the split was rebuilt for balance since this rank's state was made or loaded.
    rebalances: u64,
}

/// A state written for another rank ([`bincode`]: the exact bits of every number).
fn put<T: serde::Serialize>(w: &mut WireWriter, v: &T) {
    let bytes = bincode::serialize(v).expect("contact states serialise to memory");
    w.bytes(&bytes);
}

/// A state read back from another rank of this run.
fn get<T: serde::de::DeserializeOwned>(r: &mut WireReader) -> T {
    let bad = "message from another rank of this run";
    bincode::deserialize(r.bytes().expect(bad)).expect(bad)
}

impl<L: ContactLaw> Simulation<L> {
    /// Advances one time step on the ranks of `comm` (collective: every rank calls it once per step).
    /// On one rank this is [`Self::step`], bit for bit. On several, every rank must have built the same
    /// set-up; the first call splits the particles ([`Self::decompose`]). An error (a blow-up on any rank)
    /// is returned by every rank with the same text.
    pub fn step_with(&mut self, comm: &dyn Comm) -> Result<(), DemError> {
        if comm.size() == 1 && self.decomp.is_none() {
            return self.step();
        }
        if self.decomp.is_none() {
            self.decompose(comm)?;
        }
        if self.dt <= 0.0 || !self.dt.is_finite() {
            return Err(DemError::Config {
                key: "dt_s".into(),
                message: format!("dt_s = {} must be a positive number of seconds", self.dt),
            });
        }
        // Whether any rank needs a rebuild or fresh forces (particles or walls added, a resume).
        let mut flags =
            [f64::from(u8::from(self.st.needs_rebuild)), f64::from(u8::from(!self.st.forces_valid))];
        comm.all_max_f64(&mut flags);
        let (rebuild, evaluate) = (flags[0] > 0.0, flags[1] > 0.0);
        if rebuild {
            self.rebuild_with(comm);
        }
        match self.settings.integrator {
            Integrator::VelocityVerlet => {
                if evaluate {
                    self.evaluate_with(comm)?;
                }
                let vmax = self.kick_drift(0.5, true, true);
                let vmax = vmax.max(self.bodies_kick(0.5, true, true));
                self.ghosts_moved();
                if !self.settings.rotation {
                    self.clear_spins();
                }
                self.advance_time_with(comm, vmax);
                self.half_step_velocities = true;
                self.maybe_rebuild_with(comm);
                self.half_step_velocities = false;
                self.evaluate_with(comm)?;
                self.kick_drift(0.5, false, false);
                self.bodies_kick(0.5, false, false);
            }
            Integrator::SymplecticEuler => {
                self.evaluate_with(comm)?;
                let vmax = self.kick_drift(1.0, true, false);
                let vmax = vmax.max(self.bodies_kick(1.0, true, false));
                self.ghosts_moved();
                self.advance_time_with(comm, vmax);
                self.maybe_rebuild_with(comm);
                self.st.forces_valid = false;
            }
            other => return Err(self.refuse(format!("the integrator {other:?}"))),
        }
        self.st.step += 1;
        self.st.energy_requested = false;
        if !self.settings.rotation {
            self.clear_spins();
        }
        self.check_finite_with(comm)
    }

    /// The sentence for a feature that runs on one rank only.
    fn refuse(&self, what: String) -> DemError {
        DemError::Config {
            key: "ranks".into(),
            message: format!(
                "{what} runs on one rank only in this version; use velocity_verlet or symplectic_euler under \
                 mpirun, or start the run without mpirun"
            ),
        }
    }

    /// Splits the particles (every rank holds the same set) over the ranks of `comm`: each rank keeps
    /// those in its box, and the bodies whose centre of mass is in its box with their members. Does
    /// nothing on one rank or when already split. Refuses, on every rank alike, what runs on one rank
    /// only (multi-step and implicit integrators) and more ranks than particles. Rank 0 keeps the energy accounts, the removal count and the mesh impact records of the
    /// state it splits (the set-up, or a checkpoint joined by [`Self::join_parts`]); the others start
    /// theirs from zero, so that the sums over ranks are the run's.
    pub fn decompose(&mut self, comm: &dyn Comm) -> Result<(), DemError> {
        let points = self.particles.pos.clone();
        self.decompose_over(comm, &points)
    }

    /// [`Self::decompose`] with the split of space balanced over `points` (the same on every rank)
    /// instead of the particles present: for a scene that fills up during the run, points spread over
    /// where the particles will be.
    pub fn decompose_over(&mut self, comm: &dyn Comm, points: &[Vec3]) -> Result<(), DemError> {
        if comm.size() == 1 || self.decomp.is_some() {
            return Ok(());
        }
        if !matches!(self.settings.integrator, Integrator::VelocityVerlet | Integrator::SymplecticEuler) {
            return Err(self.refuse(format!("the integrator {:?}", self.settings.integrator)));
        }
        // No periodic axes: the domain only has to be finite (the boxes' outer faces are infinite).
        let bounds = Aabb::from_points(points);
        let rcb =
            Rcb::from_points(points, comm.size(), bounds, [false; 3]).map_err(|e| DemError::Config {
                key: "ranks".into(),
                message: format!("splitting the particles over the ranks: {e}"),
            })?;
        let rank = comm.rank();
        let pending = self.collect_carries();
        let owned: Vec<bool> = self.owner_ranks(&rcb).into_iter().map(|o| o == rank).collect();
        self.particles.retain(|i| owned[i]);
        self.keep_owned_bodies(&rcb, rank);
        self.refresh_members();
        self.st.list = Default::default();
        self.st.wall_list = Default::default();
        self.st.needs_rebuild = true;
        if rank != 0 {
            // The sums over the ranks stay the run's (at the start all but the accounts are zero; after
            // a repartitioned resume the joined state holds the run's totals on every rank).
            self.st.energy = Default::default();
            self.st.removed = 0;
            let last = &mut self.st.last;
            (last.elastic, last.pair_contacts, last.wall_contacts) = (0.0, 0, 0);
            for w in &mut self.walls {
                if let crate::walls::WallShape::Mesh(m) = &mut w.shape {
                    m.records = crate::walls::MeshRecords::new(m.records.impacts.len());
                }
            }
        }
        self.decomp = Some(Decomp {
            boxes: rcb.boxes(),
            rcb,
            rank,
            size: comm.size(),
            peer_ranks: Vec::new(),
            send: Vec::new(),
            ghosts: Ghosts::default(),
            pending,
            fresh: false,
            last_migrants: 0,
            rebalances: 0,
        });
        Ok(())
    }

    /// What a checkpoint part keeps of the split besides [`Self::state`] (`None` on one rank): the split
    /// of space and the contact states with ghosts, keyed by the ids of the pair.
    pub fn rank_state(&self) -> Option<RankState<L::State>> {
        let d = self.decomp.as_ref()?;
        let (g, p) = (&d.ghosts, &self.particles);
        let default = L::State::default();
        let mut ghost_contacts = Vec::new();
        if g.start.len() == p.len() + 1 {
            for i in 0..p.len() {
                for k in g.start[i] as usize..g.start[i + 1] as usize {
                    if g.state[k] != default {
                        ghost_contacts.push((pair_key(p.id[i], g.id[g.nbr[k] as usize]), g.state[k]));
                    }
                }
            }
        }
        ghost_contacts.sort_unstable_by_key(|c| c.0);
        Some(RankState { partition: d.rcb.clone(), ghost_contacts })
    }

    /// Continues a rank's state restored by [`Self::restore`] from a checkpoint written on as many
    /// ranks: takes the split, gets the ghosts (at their current positions) and their contact states
    /// back. Collective. The run then goes on bit for bit as if it had not stopped: the ghost lists may
    /// hold other far candidates than before, but every pair within reach, with its state, and in the
    /// same order.
    pub fn restore_rank_state(&mut self, rs: RankState<L::State>, comm: &dyn Comm) -> Result<(), DemError> {
        if rs.partition.ranks() != comm.size() {
            return Err(DemError::Resume(format!(
                "the checkpoint was written on {} ranks, this run has {}; resume on as many ranks, or join \
                 the parts and split them afresh (--repartition, Simulation::join_parts)",
                rs.partition.ranks(),
                comm.size()
            )));
        }
        let rank = comm.rank();
        self.decomp = Some(Decomp {
            boxes: rs.partition.boxes(),
            rcb: rs.partition,
            rank,
            size: comm.size(),
            peer_ranks: Vec::new(),
            send: Vec::new(),
            ghosts: Ghosts::default(),
            pending: Default::default(),
            fresh: false,
            last_migrants: 0,
            rebalances: 0,
        });
        let r_max = self.st.r_max;
        let (range_pp, _) = self.range_max(r_max);
        let mut arm = [self.st.bodies.largest_arm()];
        comm.all_max_f64(&mut arm);
        let (width, peer_width) = self.halo_widths(r_max, arm[0]);
        if let Some(d) = self.decomp.as_mut() {
            let mut peer_ranks: Vec<usize> = d.rcb.peers(d.rank, peer_width).iter().map(|p| p.rank).collect();
            peer_ranks.dedup();
            d.peer_ranks = peer_ranks;
        }
        self.exchange_ghosts(comm, width);
        self.build_ghost_list(range_pp, &rs.ghost_contacts);
        Ok(())
    }

    /// Joins the mesh impact records of all ranks (each rank records the contacts of its own particles):
    /// afterwards rank 0 holds the sums (counts exact, the rest added in rank order) and the other ranks
    /// zeros, so that rank 0 writes the run's records and the sums over ranks stay right as the run goes
    /// on. Collective; nothing on one rank.
    pub fn gather_mesh_records(&mut self, comm: &dyn Comm) {
        if self.decomp.is_none() {
            return;
        }
        let root = comm.is_root();
        for w in &mut self.walls {
            let crate::walls::WallShape::Mesh(m) = &mut w.shape else { continue };
            let r = &mut m.records;
            let mut counts = r.impacts.clone();
            comm.all_sum_u64(&mut counts);
            r.impacts = counts;
            for v in [
                &mut r.normal_impulse,
                &mut r.tangential_impulse,
                &mut r.impact_speed_sum,
                &mut r.impact_angle_sum,
                &mut r.eroded_mass,
            ] {
                comm.sum_f64_ordered(v);
            }
            if !root {
                r.impacts.fill(0);
                for v in [
                    &mut r.normal_impulse,
                    &mut r.tangential_impulse,
                    &mut r.impact_speed_sum,
                    &mut r.impact_angle_sum,
                    &mut r.eroded_mass,
                ] {
                    v.fill(0.0);
                }
            }
        }
    }

    /// [`Self::add_particle`] on a run split over ranks: every rank calls it with the same particle; the
    /// rank whose box holds it adds it, the others only count its id (ids stay those of a one-rank run).
    /// Not split, the plain method.
    pub fn add_particle_split(&mut self, p: crate::particles::NewParticle) -> u32 {
        match &self.decomp {
            Some(d) if d.rcb.owner(p.pos) != d.rank => self.particles.skip_id(),
            _ => self.add_particle(p),
        }
    }

    /// Number of ranks the particles are split over (1 when not split).
    pub fn ranks(&self) -> usize {
        self.decomp.as_ref().map_or(1, |d| d.size)
    }

    /// The split of space over the ranks (`None` on one rank).
    pub fn partition(&self) -> Option<&Rcb> {
        self.decomp.as_ref().map(|d| &d.rcb)
    }

    /// The owner of a point and this rank's number, when the particles are split.
    pub(super) fn decomp_owner(&self, x: Vec3) -> Option<(usize, usize)> {
        self.decomp.as_ref().map(|d| (d.rcb.owner(x), d.rank))
    }

    /// This rank's box, when the particles are split.
    pub fn rank_box(&self) -> Option<Aabb> {
        self.decomp.as_ref().map(|d| d.boxes[d.rank])
    }

    /// Ghost particles held and particles received by migration at the last rebuild, on this rank.
    pub fn exchange_counts(&self) -> (usize, usize) {
        self.decomp.as_ref().map_or((0, 0), |d| (d.ghosts.id.len(), d.last_migrants))
    }

    /// The owned particles moved: the ghosts' values must be sent again before the next evaluation.
    fn ghosts_moved(&mut self) {
        if let Some(d) = self.decomp.as_mut() {
            d.fresh = false;
        }
    }

    /// Time, displacement bounds, and whether a rebuild is due, from the largest speed over all ranks.
    fn advance_time_with(&mut self, comm: &dyn Comm, vmax: f64) {
        let mut m = [vmax, f64::from(u8::from(self.st.needs_rebuild))];
        comm.all_max_f64(&mut m);
        self.st.needs_rebuild = m[1] > 0.0;
        self.advance_time(m[0]);
    }

    /// [`Self::maybe_rebuild`] on ranks: the criterion is the same on every rank (global bounds and
    /// radius), so all rebuild in the same step.
    fn maybe_rebuild_with(&mut self, comm: &dyn Comm) {
        let skin = self.skin();
        let dp = self.st.disp_particles;
        let dw = self.st.disp_walls;
        if self.st.needs_rebuild || !self.settings.verlet_list || (2.0 * dp).max(dp + dw) > skin {
            self.rebuild_with(comm);
        }
    }

    /// A rebuild on ranks: carries, domain removal, migration of the particles that left this rank's box
    /// (with their contact history), the lists, then the ghosts and their contact list.
    fn rebuild_with(&mut self, comm: &dyn Comm) {
        let (mut carry, mut wall_carry) = self.collect_carries();
        if let Some(d) = self.decomp.as_mut() {
            // Ghost contacts: the same pair is held by the rank of each partner (identical states).
            let g = &d.ghosts;
            let p = &self.particles;
            let default = L::State::default();
            for i in 0..super::neighbors::listed(&g.start, p.len()) {
                for k in g.start[i] as usize..g.start[i + 1] as usize {
                    if g.state[k] != default {
                        carry.push((pair_key(p.id[i], g.id[g.nbr[k] as usize]), g.state[k]));
                    }
                }
            }
            let (pc, wc) = std::mem::take(&mut d.pending);
            carry.extend(pc);
            wall_carry.extend(wc);
        }
        self.remove_outside_domain();
        self.rebalance_if_needed(comm);
        let mut r = [self.particles.radius.iter().copied().fold(0.0, f64::max), self.st.bodies.largest_arm()];
        comm.all_max_f64(&mut r);
        let r_max = r[0];
        self.st.r_max = r_max;
        let (range_pp, _) = self.range_max(r_max);
        let (width, peer_width) = self.halo_widths(r_max, r[1]);
        self.migrate(comm, peer_width, &mut carry, &mut wall_carry);
        carry.sort_unstable_by_key(|c| c.0);
        carry.dedup_by_key(|c| c.0);
        wall_carry.sort_unstable_by_key(|c| c.0);
        self.build_lists(r_max, &carry, &wall_carry);
        self.exchange_ghosts(comm, width);
        self.build_ghost_list(range_pp, &carry);
        self.finish_rebuild();
    }

    /// Sets the load imbalance (the most particles on one rank over the mean) above which a run on
    /// several ranks rebuilds its split, at a neighbour-list rebuild, from where the particles are;
    /// `None` keeps the first split. Default [`DEFAULT_REBALANCE`]; values below 1 are taken as 1.
    pub fn set_rebalance(&mut self, imbalance: Option<f64>) {
        self.rebalance = imbalance.map(|v| v.max(1.0));
    }

    /// Times the split was rebuilt for balance since this state was made or loaded (0 on one rank).
    pub fn rebalances(&self) -> u64 {
        self.decomp.as_ref().map_or(0, |d| d.rebalances)
    }

    /// Dynamic load balancing at a neighbour-list rebuild (the only time particles change owner): when
    /// the imbalance exceeds the limit, the split is rebuilt over the particles where they are
    /// ([`Rcb::improved`]), and the rebuild's migration takes every particle, with its contact history,
    /// to its new owner. Depends on the state only, so a resumed run rebalances where the uninterrupted
    /// one did. Collective.
    fn rebalance_if_needed(&mut self, comm: &dyn Comm) {
        let (Some(limit), Some(d)) = (self.rebalance, self.decomp.as_ref()) else { return };
        let p = &self.particles;
        let Some(rcb) = Rcb::improved(comm, limit, &p.id, &p.pos, d.rcb.domain(), [false; 3]) else { return };
        if let Some(d) = self.decomp.as_mut() {
            d.boxes = rcb.boxes();
            d.rcb = rcb;
            d.rebalances += 1;
        }
    }

    /// Sends every particle outside this rank's box to its owner (a member: every body whose centre left
    /// it, with its members), with its wall carries and the pair carries that involve it, and appends
    /// what arrives. Also sets the neighbours: the ranks whose boxes lie within `peer_width`.
    fn migrate(
        &mut self,
        comm: &dyn Comm,
        peer_width: f64,
        carry: &mut Vec<PairCarry<L::State>>,
        wall_carry: &mut Vec<WallCarry<L::State>>,
    ) {
        let Some(d) = self.decomp.as_ref() else { return };
        let owners = self.owner_ranks(&d.rcb);
        let leaving_bodies = self.leaving_bodies(&d.rcb, d.rank);
        let body_ids: Vec<u32> = if self.st.bodies.is_empty() {
            Vec::new()
        } else {
            (0..self.particles.len()).map(|i| self.body_id_of(i)).collect()
        };
        let body_records: Vec<_> =
            leaving_bodies.iter().map(|&(o, k)| (o, self.st.bodies.record(k))).collect();
        let Some(d) = self.decomp.as_mut() else { return };
        let mut peer_ranks: Vec<usize> = d.rcb.peers(d.rank, peer_width).iter().map(|p| p.rank).collect();
        peer_ranks.dedup();
        d.peer_ranks = peer_ranks;
        let p = &mut self.particles;
        let leaving: Vec<(usize, usize)> =
            owners.iter().enumerate().filter_map(|(i, &o)| (o != d.rank).then_some((o, i))).collect();
        let far = leaving.iter().any(|(o, _)| d.peer_ranks.binary_search(o).is_err());
        let mut flag = [u64::from(far)];
        comm.all_sum_u64(&mut flag);
        let dest: Vec<usize> = if flag[0] > 0 { (0..d.size).collect() } else { d.peer_ranks.clone() };
        // Destination (index into `dest`) of every leaving id, for the pair carries.
        let mut to: Vec<(u32, usize)> = leaving
            .iter()
            .map(|&(o, i)| (p.id[i], dest.binary_search(&o).expect("the owner is a destination")))
            .collect();
        to.sort_unstable();
        let mut parts: Vec<(WireWriter, u32)> =
            dest.iter().map(|_| (WireWriter::with_capacity(0), 0)).collect();
        let has_ext = !p.ext_force.is_empty();
        for &(o, i) in &leaving {
            let k = dest.binary_search(&o).expect("the owner is a destination");
            let (w, n) = &mut parts[k];
            *n += 1;
            w.u32(p.id[i]).u32(u32::from(p.material[i])).u32(body_ids.get(i).copied().unwrap_or(NO_BODY));
            w.vec3(p.pos[i]).vec3(p.vel[i]).vec3(p.omega[i]).vec3(p.force[i]).vec3(p.torque[i]);
            w.f64(p.radius[i]).f64(p.inv_mass[i]);
            let (ef, et) = if has_ext { (p.ext_force[i], p.ext_torque[i]) } else { (Vec3::ZERO, Vec3::ZERO) };
            w.vec3(ef).vec3(et);
        }
        // Wall carries travel with their particle; pair carries go to the new owner of either partner
        // (the sender keeps its copy: the partner that stays may now see the migrant as a ghost).
        let mut walls: Vec<Vec<&WallCarry<L::State>>> = vec![Vec::new(); dest.len()];
        for c in wall_carry.iter() {
            if let Ok(m) = to.binary_search_by_key(&c.0 .0, |t| t.0) {
                walls[to[m].1].push(c);
            }
        }
        let mut pairs: Vec<Vec<&PairCarry<L::State>>> = vec![Vec::new(); dest.len()];
        for c in carry.iter() {
            let (a, b) = ((c.0 >> 32) as u32, c.0 as u32);
            let da = to.binary_search_by_key(&a, |t| t.0).ok().map(|m| to[m].1);
            let db = to.binary_search_by_key(&b, |t| t.0).ok().map(|m| to[m].1);
            if let Some(k) = da {
                pairs[k].push(c);
            }
            if let Some(k) = db.filter(|&k| Some(k) != da) {
                pairs[k].push(c);
            }
        }
        let mut bodies: Vec<Vec<&crate::clump::BodyRecord>> = vec![Vec::new(); dest.len()];
        for (o, r) in &body_records {
            bodies[dest.binary_search(o).expect("the owner is a destination")].push(r);
        }
        let out: Vec<Vec<u8>> = parts
            .into_iter()
            .zip(walls.iter().zip(&pairs))
            .zip(&bodies)
            .map(|(((body, n), (wc, pc)), bc)| {
                let mut w = WireWriter::with_capacity(0);
                w.u32(n).bytes(&body.finish());
                w.u32(wc.len() as u32);
                for c in wc {
                    w.u32(c.0 .0).u32(u32::from(c.0 .1)).u32(c.0 .2);
                    put(&mut w, &(c.1, c.2));
                }
                w.u32(pc.len() as u32);
                for c in pc {
                    w.u64(c.0);
                    put(&mut w, &c.1);
                }
                w.u32(bc.len() as u32);
                for r in bc {
                    put(&mut w, *r);
                }
                w.finish()
            })
            .collect();
        let got =
            if flag[0] > 0 { comm.all_to_all_bytes(&out) } else { comm.neighbour_exchange(&dest, &out) };
        if !leaving.is_empty() {
            let mut keep = vec![true; p.len()];
            for &(_, i) in &leaving {
                keep[i] = false;
            }
            p.retain(|i| keep[i]);
        }
        let bad = "migration message from another rank of this run";
        let mut arrived = 0;
        let first = p.len();
        let (mut arrived_bodies, mut arrived_body_ids) = (Vec::new(), Vec::new());
        for buf in &got {
            let mut r = WireReader::new(buf);
            let n = r.u32().expect(bad);
            let mut b = WireReader::new(r.bytes().expect(bad));
            for _ in 0..n {
                p.id.push(b.u32().expect(bad));
                p.material.push(b.u32().expect(bad) as u16);
                arrived_body_ids.push(b.u32().expect(bad));
                p.pos.push(b.vec3().expect(bad));
                p.vel.push(b.vec3().expect(bad));
                p.omega.push(b.vec3().expect(bad));
                p.force.push(b.vec3().expect(bad));
                p.torque.push(b.vec3().expect(bad));
                p.radius.push(b.f64().expect(bad));
                p.inv_mass.push(b.f64().expect(bad));
                let (ef, et) = (b.vec3().expect(bad), b.vec3().expect(bad));
                if !p.ext_force.is_empty() || ef != Vec3::ZERO || et != Vec3::ZERO {
                    let len = p.id.len();
                    p.ext_force.resize(len - 1, Vec3::ZERO);
                    p.ext_torque.resize(len - 1, Vec3::ZERO);
                    p.ext_force.push(ef);
                    p.ext_torque.push(et);
                }
                arrived += 1;
            }
            for _ in 0..r.u32().expect(bad) {
                let key = (r.u32().expect(bad), r.u32().expect(bad) as u16, r.u32().expect(bad));
                let (s, o): (L::State, SlotOut) = get(&mut r);
                wall_carry.push((key, s, o));
            }
            for _ in 0..r.u32().expect(bad) {
                let key = r.u64().expect(bad);
                carry.push((key, get(&mut r)));
            }
            for _ in 0..r.u32().expect(bad) {
                arrived_bodies.push(get(&mut r));
            }
        }
        d.last_migrants = arrived;
        if !leaving_bodies.is_empty() {
            let mut keep = vec![true; self.st.bodies.len()];
            for &(_, k) in &leaving_bodies {
                keep[k] = false;
            }
            self.drop_bodies(&keep);
        }
        self.attach_arrived(first, &arrived_body_ids, arrived_bodies);
    }

    /// Sends every neighbour the owned particles within `width` of its box (kept as send lists) and
    /// takes what arrives as this rank's ghosts.
    fn exchange_ghosts(&mut self, comm: &dyn Comm, width: f64) {
        let Some(d) = self.decomp.as_mut() else { return };
        let p = &self.particles;
        d.send = d
            .peer_ranks
            .iter()
            .map(|&r| {
                let near = d.boxes[r].inflated(width);
                (0..p.len() as u32).filter(|&i| near.contains(p.pos[i as usize])).collect()
            })
            .collect();
        let out: Vec<Vec<u8>> = d
            .send
            .iter()
            .map(|list| {
                let mut w = WireWriter::with_capacity(96 * list.len());
                for &i in list {
                    let i = i as usize;
                    w.u32(p.id[i]).u32(u32::from(p.material[i])).f64(p.radius[i]).f64(p.inv_mass[i]);
                    w.vec3(p.pos[i]).vec3(p.vel[i]).vec3(p.omega[i]);
                }
                w.finish()
            })
            .collect();
        let got = comm.neighbour_exchange(&d.peer_ranks, &out);
        let g = &mut d.ghosts;
        g.clear_particles();
        let bad = "ghost message from another rank of this run";
        for buf in &got {
            let mut r = WireReader::new(buf);
            while !r.is_done() {
                g.id.push(r.u32().expect(bad));
                g.material.push(r.u32().expect(bad) as u16);
                g.radius.push(r.f64().expect(bad));
                g.inv_mass.push(r.f64().expect(bad));
                g.pos.push(r.vec3().expect(bad));
                g.vel.push(r.vec3().expect(bad));
                g.omega.push(r.vec3().expect(bad));
            }
        }
        d.fresh = true;
    }

    /// The ghost partners of every owned particle (the same distance test as the half list) and their
    /// contact states from `carry`.
    fn build_ghost_list(&mut self, range_pp: f64, carry: &[PairCarry<L::State>]) {
        let skin = self.skin();
        let r_max = self.st.r_max;
        let Some(d) = self.decomp.as_mut() else { return };
        let p = &self.particles;
        let g = &mut d.ghosts;
        let extra = range_pp + skin;
        let mut grid = spatter_core::grid::CellGrid::new();
        if !g.pos.is_empty() {
            grid.rebuild(&g.pos, (2.0 * r_max + extra).max(1e-300));
        }
        let (gpos, grad, gim) = (&g.pos, &g.radius, &g.inv_mass);
        let parts: Vec<(Vec<u32>, Vec<u32>)> = (0..p.len().div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let (i0, i1) = (b * BLOCK, ((b + 1) * BLOCK).min(p.len()));
                let mut counts = Vec::with_capacity(i1 - i0);
                let mut nb = Vec::new();
                for i in i0..i1 {
                    let before = nb.len();
                    if !gpos.is_empty() {
                        let (xi, ri) = (p.pos[i], p.radius[i]);
                        grid.for_each_candidate(xi, |j| {
                            let j = j as usize;
                            let c = ri + grad[j] + extra;
                            let frozen = p.inv_mass[i] == 0.0 && gim[j] == 0.0;
                            if (gpos[j] - xi).length_squared() < c * c && !frozen {
                                nb.push(j as u32);
                            }
                        });
                        nb[before..].sort_unstable();
                    }
                    counts.push((nb.len() - before) as u32);
                }
                (counts, nb)
            })
            .collect();
        g.start.clear();
        g.start.push(0);
        g.nbr.clear();
        for (counts, nb) in &parts {
            g.nbr.extend_from_slice(nb);
            for &c in counts {
                let last = *g.start.last().expect("starts with 0");
                g.start.push(last + c);
            }
        }
        let default = L::State::default();
        g.state.clear();
        g.state.resize(g.nbr.len(), default);
        if !carry.is_empty() {
            for i in 0..p.len() {
                for k in g.start[i] as usize..g.start[i + 1] as usize {
                    let j = g.nbr[k] as usize;
                    // The test of the half list's restore (neighbors.rs), so that both ranks agree.
                    let c = p.radius[i] + g.radius[j] + range_pp;
                    if (g.pos[j] - p.pos[i]).length_squared() >= c * c * (1.0 + 1e-9) + 1e-300 {
                        continue;
                    }
                    if let Ok(m) = carry.binary_search_by_key(&pair_key(p.id[i], g.id[j]), |c| c.0) {
                        g.state[k] = carry[m].1;
                    }
                }
            }
        }
    }

    /// Sends the current position, velocity and spin of the particles of the last ghost exchange again
    /// (same lists, same order). Collective.
    fn refresh_ghosts(&mut self, comm: &dyn Comm) {
        let Some(d) = self.decomp.as_mut() else { return };
        if std::mem::take(&mut d.fresh) {
            return;
        }
        let p = &self.particles;
        let out: Vec<Vec<u8>> = d
            .send
            .iter()
            .map(|list| {
                let mut w = WireWriter::with_capacity(72 * list.len());
                for &i in list {
                    let i = i as usize;
                    w.vec3(p.pos[i]).vec3(p.vel[i]).vec3(p.omega[i]);
                }
                w.finish()
            })
            .collect();
        let got = comm.neighbour_exchange(&d.peer_ranks, &out);
        let g = &mut d.ghosts;
        let bad = "ghost message from another rank of this run";
        let mut k = 0;
        for buf in &got {
            let mut r = WireReader::new(buf);
            while !r.is_done() {
                g.pos[k] = r.vec3().expect(bad);
                g.vel[k] = r.vec3().expect(bad);
                g.omega[k] = r.vec3().expect(bad);
                k += 1;
            }
        }
    }

    /// [`Self::evaluate`] on ranks: ghosts refreshed first; the blow-up test on the largest overlap over
    /// all ranks.
    fn evaluate_with(&mut self, comm: &dyn Comm) -> Result<(), DemError> {
        self.refresh_ghosts(comm);
        self.compute_forces();
        self.evaluations += 1;
        if !self.st.bodies.is_empty() {
            self.reduce_body_forces();
        }
        self.st.forces_valid = true;
        let local = self.st.last.max_overlap_ratio;
        let mut m = [local];
        comm.all_max_f64(&mut m);
        self.st.last.max_overlap_ratio = m[0];
        if m[0] > self.settings.max_overlap_fraction {
            let mine = (local == m[0] || local.is_nan()).then(|| self.blow_up_overlap());
            return Err(shared_error(comm, mine));
        }
        self.evaluated_ids = self.particles.next_id();
        Ok(())
    }

    /// [`Self::check_finite`] on ranks: the error of the lowest rank that has one, on every rank.
    fn check_finite_with(&mut self, comm: &dyn Comm) -> Result<(), DemError> {
        let mine = self.check_finite().err();
        let mut any = [f64::from(u8::from(mine.is_some()))];
        comm.all_max_f64(&mut any);
        if any[0] > 0.0 {
            return Err(shared_error(comm, mine));
        }
        Ok(())
    }
}

/// The error of the lowest rank that has one, raised on every rank (collective; at least one rank
/// passes `Some`).
fn shared_error(comm: &dyn Comm, mine: Option<DemError>) -> DemError {
    let mut w = WireWriter::with_capacity(256);
    if let Some(e) = &mine {
        match e {
            DemError::BlowUp { particle, step, time_s, what, cause } => {
                w.u32(0)
                    .u32(*particle)
                    .u64(*step)
                    .f64(*time_s)
                    .bytes(what.as_bytes())
                    .bytes(cause.as_bytes());
            }
            other => {
                w.u32(1).bytes(other.to_string().as_bytes());
            }
        }
    }
    let all = comm.all_gather_bytes(&w.finish());
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    let Some(buf) = all.iter().find(|b| !b.is_empty()) else {
        return mine.unwrap_or_else(|| DemError::Config {
            key: "ranks".into(),
            message: "an error on another rank".into(),
        });
    };
    let mut r = WireReader::new(buf);
    let bad = "error message from another rank of this run";
    if r.u32().expect(bad) == 0 {
        let (particle, step, time_s) = (r.u32().expect(bad), r.u64().expect(bad), r.f64().expect(bad));
        let what = text(r.bytes().expect(bad));
        let cause = text(r.bytes().expect(bad));
        return DemError::BlowUp { particle, step, time_s, what, cause };
    }
    DemError::Config { key: "ranks".into(), message: text(r.bytes().expect(bad)) }
}

/// The contacts of owned particles with ghosts, force on the owned particle only. Inputs are formed
/// exactly as in the pair loop (forces.rs), from the lower id's side, so the rank holding the other
/// partner computes the same contact bit for bit. Parallel over blocks of owned particles; the
/// per-block sums are combined in block order (identical for any thread count).
pub(super) fn ghost_contacts<L: ContactLaw>(
    law: &L,
    params: &PairTable<L::Params>,
    g: &mut Ghosts<L::State>,
    p: &ParticleView,
    range_quick: f64,
    dt: f64,
    (force, torque): (&mut [Vec3], &mut [Vec3]),
) -> Acc {
    let n = p.pos.len();
    if g.nbr.is_empty() || g.start.len() != n + 1 {
        return Acc::default();
    }
    let default = L::State::default();
    let (gid, gmat, gpos, gvel, gom, grad, gim) =
        (&g.id, &g.material, &g.pos, &g.vel, &g.omega, &g.radius, &g.inv_mass);
    let start = &g.start;
    let nbr = &g.nbr;
    // Blocks of owned particles with their force rows and their slots.
    let mut blocks = Vec::with_capacity(n.div_ceil(BLOCK));
    let (mut f_rest, mut t_rest, mut s_rest) = (force, torque, &mut g.state[..]);
    for b in 0..n.div_ceil(BLOCK) {
        let (i0, i1) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
        let (f, fr) = std::mem::take(&mut f_rest).split_at_mut(i1 - i0);
        let (t, tr) = std::mem::take(&mut t_rest).split_at_mut(i1 - i0);
        let (s, sr) = std::mem::take(&mut s_rest).split_at_mut((start[i1] - start[i0]) as usize);
        (f_rest, t_rest, s_rest) = (fr, tr, sr);
        blocks.push((i0, i1, f, t, s));
    }
    let accs: Vec<Acc> = blocks
        .into_par_iter()
        .map(|(i0, i1, f, tq, states)| {
            let mut acc = Acc::default();
            let s0 = start[i0] as usize;
            for i in i0..i1 {
                let (xi, ri, ii) = (p.pos[i], p.radius[i], p.inv_mass[i]);
                let (vi, wri) = (p.vel[i], ri * p.omega[i]);
                let row = params.row(p.material[i] as usize);
                let (mut fi, mut ti) = (Vec3::ZERO, Vec3::ZERO);
                for k in start[i] as usize..start[i + 1] as usize {
                    let j = nbr[k] as usize;
                    let state = &mut states[k - s0];
                    let d = xi - gpos[j];
                    let rj = grad[j];
                    let rs = ri + rj;
                    let reach = rs + range_quick;
                    let dist2 = d.length_squared();
                    if dist2 >= reach * reach {
                        *state = default;
                        continue;
                    }
                    let s = if gid[j] < p.id[i] { -1.0 } else { 1.0 };
                    let dist = dist2.sqrt();
                    let nrm = if dist > 0.0 { d * (1.0 / dist) } else { s * Vec3::Z };
                    let inv = ii + gim[j];
                    let q = 1.0 / (rs * inv);
                    let (i_eff, w_rel) = if L::USES_ROTATION {
                        let inv_i = 2.5 * (ii / (ri * ri) + gim[j] / (rj * rj));
                        (1.0 / inv_i, s * (p.omega[i] - gom[j]))
                    } else {
                        (0.0, Vec3::ZERO)
                    };
                    let c = ContactInput {
                        normal: s * nrm,
                        overlap: rs - dist,
                        r_eff: ri * rj * inv * q,
                        radius_sum: ri + rj,
                        m_eff: rs * q,
                        i_eff,
                        v_rel: s * (vi - gvel[j] - (wri + rj * gom[j]).cross(nrm)),
                        w_rel,
                        dt,
                    };
                    match law.compute(&row[gmat[j] as usize], &c, state) {
                        None => *state = default,
                        Some(o) => {
                            let cr = c.normal.cross(o.force);
                            fi += s * o.force;
                            if L::USES_ROTATION {
                                ti += s * o.rolling_torque - ri * cr;
                            } else {
                                ti -= ri * cr;
                            }
                            // The lower id's rank books the pair (each pair once over all ranks).
                            if s > 0.0 {
                                acc.dissipated += o.dissipated;
                                acc.elastic += o.energy;
                                acc.pair_contacts += 1;
                            }
                            let rmin = if ri < rj { ri } else { rj };
                            let (a, b) = if s > 0.0 { (p.id[i], gid[j]) } else { (gid[j], p.id[i]) };
                            acc.note_overlap(c.overlap / rmin, a, b);
                        }
                    }
                }
                f[i - i0] += fi;
                tq[i - i0] += ti;
            }
            acc
        })
        .collect();
    accs.into_iter().fold(Acc::default(), Acc::combine)
}

/// Collective totals: every rank calls them at the same point and gets the same value (floating-point
/// sums added in rank order). Before the split (every rank holds the whole set-up) and on one rank they
/// are the plain methods.
impl<L: ContactLaw> Simulation<L> {
    /// Number of particles over all ranks.
    pub fn particle_count_with(&self, comm: &dyn Comm) -> u64 {
        if self.decomp.is_none() {
            return self.particles.len() as u64;
        }
        let mut n = [self.particles.len() as u64];
        comm.all_sum_u64(&mut n);
        n[0]
    }

    /// Particles removed for leaving the domain, over all ranks.
    pub fn removed_count_with(&self, comm: &dyn Comm) -> u64 {
        if self.decomp.is_none() {
            return self.st.removed;
        }
        let mut n = [self.st.removed];
        comm.all_sum_u64(&mut n);
        n[0]
    }

    /// [`Self::energy`] over all ranks: every account is a per-rank part of the run's.
    pub fn energy_with(&self, comm: &dyn Comm) -> super::EnergyReport {
        let mut e = self.energy();
        if self.decomp.is_none() {
            return e;
        }
        let mut v =
            [e.kinetic, e.rotational, e.elastic, e.potential, e.dissipated, e.external_work, e.wall_work];
        comm.sum_f64_ordered(&mut v);
        [e.kinetic, e.rotational, e.elastic, e.potential, e.dissipated, e.external_work, e.wall_work] = v;
        let mut c = [e.pair_contacts, e.wall_contacts];
        comm.all_sum_u64(&mut c);
        [e.pair_contacts, e.wall_contacts] = c;
        e
    }

    /// Every rank's particles in one store, in id order (collective on a split run; a copy of the
    /// particles otherwise). Body indices of members are those of each rank's own bodies: for the
    /// particles' geometry and motion (bed files, packing densities), not for rigid-body bookkeeping.
    pub fn gathered_particles(&self, comm: &dyn Comm) -> crate::particles::Particles {
        if self.decomp.is_none() {
            return self.particles.clone();
        }
        let bytes = bincode::serialize(&self.particles).expect("particles serialise to memory");
        let mut all = crate::particles::Particles::new();
        for buf in comm.all_gather_bytes(&bytes) {
            let part: crate::particles::Particles =
                bincode::deserialize(&buf).expect("particles from another rank of this run");
            all.append(part);
        }
        all.sort_by_id();
        all
    }

    /// Total contact force on wall `w` over all ranks \[N\].
    pub fn wall_force_with(&self, comm: &dyn Comm, w: usize) -> Vec3 {
        let f = self.wall_force(w);
        if self.decomp.is_none() {
            return f;
        }
        let mut v = [f.x, f.y, f.z];
        comm.sum_f64_ordered(&mut v);
        Vec3::new(v[0], v[1], v[2])
    }
}
