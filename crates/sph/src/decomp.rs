//! The step on several ranks: domain decomposition of the fluid.
//!
//! Space is split by recursive coordinate bisection ([`Rcb`]) of the initial fluid; each rank owns the
//! fluid particles inside its box and steps only those. Per step, beyond the work of a one-rank step:
//!
//! 1. **migration** — after the drift (and periodic wrap) every particle whose position lies in another
//!    rank's box is sent there with its whole state (position, velocity, density, their rates, id, wall
//!    mask, shift). A particle moves less than a fraction of h per step, so its new owner is a neighbour;
//!    one integer sum per step checks this, and the rare exception goes through an all-to-all;
//! 2. **halo** — every rank sends the fluid within *two* kernel supports of each neighbour's box
//!    (position, velocity, density; periodic images are the same exchange with a shift, to a neighbour or
//!    to itself). Pressure and 1/ρ of a halo particle are computed from its density by the same equation of
//!    state as on its owner, so they never travel. The send lists are kept so that sensors between steps
//!    can refresh velocity and density without rebuilding them;
//! 3. **reductions** — the time step comes from maxima over all ranks (exact, identical everywhere), the
//!    counts (interactions, guard stops, removals) from integer sums.
//!
//! Walls are replicated: every rank holds the whole boundary and moves it by the same kinematics, but its
//! wall set holds only the wall particles within one support of its box (`local_walls`). The
//! state of a wall entry (Adami extrapolation) needs the fluid within one support of it; with a halo two
//! supports wide every wall entry within one support of the box, the only ones the owned fluid sees, gets
//! a complete neighbourhood, so no wall state travels. (Sending one support of fluid plus the wall state
//! of a band would save halo volume at the cost of a third message per step.) Wetting of a wall entry is
//! accumulated by the rank whose box holds it.
//!
//! **Errors never hang a run**: a particle with a non-finite state is dropped from its rank, the step goes
//! on, and the lowest such id over all ranks is reported by every rank at the end of the step.
//!
//! **Determinism**: a run on a given number of ranks repeats bit for bit (messages are read in rank order,
//! sorts are stable, reductions exact). Another number of ranks sums forces in another order (halo
//! particles are neighbours like periodic images), so results agree with a one-rank run to round-off,
//! which grows where the flow is chaotic; the particle set and the total mass are exact.
//!
//! **Surface tension and wall adhesion** need two quantities each owner computes from its whole
//! neighbourhood: the surface normal of every particle (the curvature term pairs the normals of
//! neighbours) and the adhesion acceleration a wall's particles pull every fluid particle with (the walls
//! push back on it in their extrapolated state). Both are sent to the halo after they are computed, over
//! the lists of that step's halo exchange: two more neighbour exchanges per step, only when the run has
//! surface tension (normals) and an adhesive wall (adhesion).

use super::{PartLoad, PassStats, Simulation};
use crate::error::SphError;
use crate::local_walls::point_gap;
use rayon::prelude::*;
use spatter_core::comm::{Comm, WireReader, WireWriter};
use spatter_core::rcb::{Peer, Rcb};
use spatter_core::{Aabb, Vec3};

/// Halo width in kernel supports (see the module documentation).
const HALO_SUPPORTS: f64 = 2.0;

/// Steps between two checks of the load balance (one reduction of two numbers each).
pub const REBALANCE_CHECK_STEPS: u64 = 20;

pub use spatter_core::rcb::DEFAULT_REBALANCE;

pub(crate) fn default_rebalance() -> Option<f64> {
    Some(DEFAULT_REBALANCE)
}

/// This rank's share of a decomposed run.
#[derive(Clone, Debug)]
pub(crate) struct Decomp {
    rcb: Rcb,
    rank: usize,
    size: usize,
    boxes: Vec<Aabb>,
    /// Ranks (with periodic shifts) whose box lies within the halo width of this rank's box.
    peers: Vec<Peer>,
    /// The distinct ranks of `peers`, sorted (this rank included when it has periodic self-images).
    peer_ranks: Vec<usize>,
    /// Per entry of `peer_ranks`: the local index and shift of every particle sent in the last halo
    /// exchange, in the order sent.
    send: Vec<Vec<(u32, Vec3)>>,
    /// Velocity and density of the received halo particles, by receive slot.
    halo_vel: Vec<Vec3>,
    halo_rho: Vec<f64>,
    /// Adhesion acceleration of the received halo particles, by receive slot, from their owners' walls
    /// (exchanged with the wall state when wall adhesion acts; positions do not change until the next
    /// exchange, so sensors between steps reuse it).
    halo_adh: Vec<Vec3>,
    /// Bytes sent in the last halo exchange and migration (diagnostics).
    pub(crate) last_halo: usize,
    pub(crate) last_migrants: usize,
    /// Times the split was rebuilt for balance since this rank's state was made or loaded.
    rebalances: u64,
}

impl Decomp {
    /// True when `x` lies in this rank's box: the rank accounts for a wall entry there (wetting, loads,
    /// wall probes).
    pub(super) fn owns(&self, x: Vec3) -> bool {
        self.rcb.owner(x) == self.rank
    }

    /// The region whose walls this rank needs (it selects those within one support of it), or `None`
    /// when no fluid is near and it needs none: its box, cut down to one support around the fluid it
    /// owns or receives (`owned`, `halo`), widened outward to multiples of [`WALL_REGION_STEP`]
    /// supports from the world origin.
    ///
    /// That covers every wall particle within one support of the rank's own fluid (the walls its
    /// particles interact with) and every wall particle in its box that any fluid reaches (the ones
    /// whose wetting and loads it accounts for: fluid within one support of its box is in its halo).
    /// The outer boxes of the split reach to infinity; without the cut a rank at the water's edge would
    /// hold every dry wall beyond it — the approach road, the channel walls above the water line, the
    /// vehicle's body — and in a large wading run one such rank would hold about 10⁶ wall particles
    /// against a few thousand on the others (docs/scaling.md). The widening makes the region change only
    /// when the fluid has moved by about a step, so that static walls are reselected rarely; it depends
    /// on the current positions only, so a resumed run selects exactly what the uninterrupted run held.
    pub(super) fn wall_region(&self, owned: &[Vec3], halo: &[Vec3], support: f64) -> Option<Aabb> {
        let bounds = |x: &[Vec3]| {
            x.par_iter()
                .with_min_len(4096)
                .fold(|| Aabb::EMPTY, |b, &p| b.grown_to(p))
                .reduce(|| Aabb::EMPTY, Aabb::union)
        };
        let near = bounds(owned).union(bounds(halo));
        if near.is_empty() {
            return None;
        }
        let step = WALL_REGION_STEP * support;
        let near = Aabb::new(
            ((near.min - Vec3::splat(support)) / step).floor() * step,
            ((near.max + Vec3::splat(support)) / step).ceil() * step,
        );
        let b = self.boxes[self.rank];
        let region = Aabb::new(b.min.max(near.min), b.max.min(near.max));
        (!region.is_empty()).then_some(region)
    }
}

/// The lattice, in kernel supports, that a rank's wall region is widened to ([`Decomp::wall_region`]).
const WALL_REGION_STEP: f64 = 2.0;

/// What one rank saw in its part of a step, before the reductions.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct LocalCounts {
    guard_hits: u64,
    removed_domain: u64,
    removed_density: u64,
    /// The lowest id with a non-finite state and what was not finite (0 position, 1 velocity, 2 density).
    bad: Option<(u32, u8)>,
}

const WHAT: [&str; 3] = ["position", "velocity", "density"];

impl Simulation {
    /// Advances one time step on the ranks of `comm` (collective: every rank calls it once per step).
    /// On one rank this is [`Self::step`], bit for bit. On several, every rank must have built the same
    /// set-up; the first call splits the fluid (see [`Self::initialize_with`]). An error (a blow-up on any
    /// rank) is returned by every rank with the same text.
    pub fn step_with(&mut self, comm: &dyn Comm) -> Result<(), SphError> {
        if comm.size() == 1 && self.decomp.is_none() {
            return self.step();
        }
        if !self.initialized {
            self.initialize_with(comm)?;
        }
        self.rebalance_if_needed(comm);
        let dt = self.dt;
        let t1 = self.time + dt;
        let mut clock = std::time::Instant::now();
        let mut lap = move || {
            let now = std::time::Instant::now();
            let d = (now - clock).as_secs_f64();
            clock = now;
            d
        };
        let guard_hits = self.predict_and_move_walls(dt, t1, &mut lap);
        let bad = self.drop_non_finite();
        let before = self.removed;
        // Cannot fail: the only error of the wrap is a non-finite particle, dropped above.
        self.wrap_and_remove()?;
        let counts = LocalCounts {
            guard_hits,
            removed_domain: self.removed.outside_domain - before.outside_domain,
            removed_density: self.removed.density_window - before.density_window,
            bad,
        };
        // The global counts are added after the reduction.
        self.removed = before;
        self.migrate(comm);
        self.work.times.walls_guard += lap();
        self.prepare_sets_with(comm);
        self.work.times.sort += lap();
        let st = self.passes_timed(dt, &mut lap, comm);
        self.accumulate_wetting(dt);
        self.correct(dt);
        self.time = t1;
        self.steps += 1;
        self.last.dt_taken = dt;
        self.reduce_step(comm, st, counts)?;
        self.work.times.correct += lap();
        Ok(())
    }

    /// Splits the (replicated) fluid over the ranks of `comm`; each rank keeps the particles in its box.
    /// Called by [`Self::initialize_with`]; does nothing on one rank or when already split.
    pub fn decompose(&mut self, comm: &dyn Comm) -> Result<(), SphError> {
        if comm.size() == 1 || self.decomp.is_some() {
            return Ok(());
        }
        self.default_domain();
        let rcb = Rcb::from_points(&self.fluid.pos, comm.size(), self.domain, self.periodic)
            .map_err(|e| SphError::Setup(format!("splitting the fluid over the ranks: {e}")))?;
        let rank = comm.rank();
        let keep: Vec<bool> = self.fluid.pos.iter().map(|&x| rcb.owner(x) == rank).collect();
        self.fluid.retain(&keep);
        self.install_partition(rcb, comm);
        Ok(())
    }

    /// Sets the load imbalance (the most particles on one rank over the mean) above which a run on
    /// several ranks rebuilds its split from where the particles are now; `None` keeps the first split
    /// for the whole run. Default [`DEFAULT_REBALANCE`]; values below 1 are taken as 1.
    pub fn set_rebalance(&mut self, imbalance: Option<f64>) {
        self.rebalance = imbalance.map(|v| v.max(1.0));
    }

    /// Times the split was rebuilt for balance since this state was made or loaded (0 on one rank).
    pub fn rebalances(&self) -> u64 {
        self.decomp.as_ref().map_or(0, |d| d.rebalances)
    }

    /// Dynamic load balancing, at the start of a step every [`REBALANCE_CHECK_STEPS`] steps: when the
    /// imbalance exceeds the limit, the split is rebuilt over the particles where they are
    /// ([`Rcb::improved`]) and the step's migration takes every particle to its new owner. The decision
    /// and the new split depend on the state only, so a resumed run rebalances where the uninterrupted
    /// one did. Collective.
    fn rebalance_if_needed(&mut self, comm: &dyn Comm) {
        let (Some(limit), Some(d)) = (self.rebalance, self.decomp.as_ref()) else { return };
        if self.steps % REBALANCE_CHECK_STEPS != 0 {
            return;
        }
        let count = d.rebalances + 1;
        let f = &self.fluid;
        let Some(rcb) = Rcb::improved(comm, limit, &f.id, &f.pos, self.domain, self.periodic) else { return };
        self.install_partition(rcb, comm);
        if let Some(d) = self.decomp.as_mut() {
            d.rebalances = count;
        }
    }

    /// Takes `rcb` as the split of space over the ranks of `comm` (boxes, neighbours, empty halo lists).
    fn install_partition(&mut self, rcb: Rcb, comm: &dyn Comm) {
        let rank = comm.rank();
        let width = HALO_SUPPORTS * self.kernel().support();
        let peers = rcb.peers(rank, width);
        let mut peer_ranks: Vec<usize> = peers.iter().map(|p| p.rank).collect();
        peer_ranks.dedup();
        self.decomp = Some(Decomp {
            boxes: rcb.boxes(),
            rcb,
            rank,
            size: comm.size(),
            send: vec![Vec::new(); peer_ranks.len()],
            peers,
            peer_ranks,
            halo_vel: Vec::new(),
            halo_rho: Vec::new(),
            halo_adh: Vec::new(),
            last_halo: 0,
            last_migrants: 0,
            rebalances: 0,
        });
        self.work.ready = false;
        self.work.walls_built = false;
    }

    /// The split of space over the ranks (`None` on one rank): a checkpoint of a run on ranks saves it
    /// beside each rank's state, so that a resume on the same ranks continues with the same boxes.
    pub fn partition(&self) -> Option<&Rcb> {
        self.decomp.as_ref().map(|d| &d.rcb)
    }

    /// Continues a rank's state loaded from a checkpoint written on the same ranks: takes `rcb` (its
    /// [`Self::partition`] then) as the split and rebuilds the scratch state ([`Self::refresh_with`]).
    /// Collective. The run then goes on bit for bit as if it had not stopped.
    pub fn restore_partition(&mut self, rcb: Rcb, comm: &dyn Comm) -> Result<(), SphError> {
        if rcb.ranks() != comm.size() {
            return Err(SphError::Setup(format!(
                "the checkpoint's split is for {} ranks, this run has {}",
                rcb.ranks(),
                comm.size()
            )));
        }
        self.install_partition(rcb, comm);
        self.refresh_with(comm);
        Ok(())
    }

    /// Joins the states of every rank of a checkpointed run (in rank order, each with the split it was
    /// saved with) into one state that holds every particle, ready to be split afresh over another number
    /// of ranks ([`Self::decompose`] at the next step, or [`Self::repartition`]). Every wall particle's wet
    /// flag is the one its owner kept; wet times and plane fluxes are added in rank order and kept only
    /// where `totals` is true (rank 0), zero elsewhere, so that the collective sums stay right.
    pub fn join_parts(parts: Vec<(Simulation, Option<Rcb>)>, totals: bool) -> Result<Simulation, SphError> {
        let mut it = parts.into_iter();
        let Some((mut sim, _)) = it.next() else {
            return Err(SphError::Setup("a checkpoint of no ranks".into()));
        };
        let mut rest: Vec<(Simulation, Option<Rcb>)> = it.collect();
        if !rest.is_empty() {
            let n = sim.boundary.len();
            if rest.iter().any(|(p, _)| p.boundary.len() != n || p.flux_up.len() != sim.flux_up.len()) {
                return Err(SphError::Setup("the checkpoint's parts hold different walls".into()));
            }
        }
        // Wet flags: the owner's (rank 0 holds its own in `sim`).
        if let Some(rcb) = rest.first().and_then(|(_, r)| r.clone()) {
            for i in 0..sim.boundary.len() {
                let owner = rcb.owner(sim.boundary.position(i));
                if owner > 0 {
                    if let Some((p, _)) = rest.get(owner - 1) {
                        sim.boundary.wet[i] = p.boundary.wet[i];
                    }
                }
            }
        }
        for (p, _) in &mut rest {
            let f = &mut p.fluid;
            sim.fluid.pos.append(&mut f.pos);
            sim.fluid.vel.append(&mut f.vel);
            sim.fluid.rho.append(&mut f.rho);
            sim.fluid.acc.append(&mut f.acc);
            sim.fluid.drho.append(&mut f.drho);
            sim.fluid.id.append(&mut f.id);
            sim.fluid.near.append(&mut f.near);
            sim.fluid.shift.append(&mut f.shift);
            for (a, b) in sim.boundary.wet_time.iter_mut().zip(&p.boundary.wet_time) {
                *a += b;
            }
            for (a, b) in sim.flux_up.iter_mut().zip(&p.flux_up) {
                *a += b;
            }
            for (a, b) in sim.flux_down.iter_mut().zip(&p.flux_down) {
                *a += b;
            }
        }
        if !totals {
            sim.boundary.wet_time.fill(0.0);
            sim.flux_up.fill(0.0);
            sim.flux_down.fill(0.0);
        }
        sim.decomp = None;
        sim.work.ready = false;
        sim.work.walls_built = false;
        Ok(sim)
    }

    /// Splits a joined state ([`Self::join_parts`], or a one-rank checkpoint) over the ranks of `comm`
    /// afresh and rebuilds the scratch state; on one rank only the latter. Collective.
    pub fn repartition(&mut self, comm: &dyn Comm) -> Result<(), SphError> {
        if comm.size() > 1 {
            self.decompose(comm)?;
        }
        self.refresh_with(comm);
        Ok(())
    }

    /// Number of ranks the fluid is split over (1 when not split).
    pub fn ranks(&self) -> usize {
        self.decomp.as_ref().map_or(1, |d| d.size)
    }

    /// This rank's box, when the fluid is split.
    pub fn rank_box(&self) -> Option<Aabb> {
        self.decomp.as_ref().map(|d| d.boxes[d.rank])
    }

    /// Wall entries (wall particles and their periodic images) in this rank's wall set: on several ranks
    /// only those near its box and its fluid (module `local_walls`, [`Decomp::wall_region`]).
    pub fn wall_entries(&self) -> usize {
        self.work.w_src.len()
    }

    /// The boundary index of every entry of this rank's wall set, in the set's order (an index appears
    /// once more for each periodic image).
    pub fn wall_sources(&self) -> &[u32] {
        &self.work.w_src
    }

    /// Halo particles received and particles migrated in the last step on this rank.
    pub fn exchange_counts(&self) -> (usize, usize) {
        self.decomp.as_ref().map_or((0, 0), |d| (d.last_halo, d.last_migrants))
    }

    /// Removes every particle with a non-finite position, velocity or density; returns the lowest such id
    /// and what was not finite.
    fn drop_non_finite(&mut self) -> Option<(u32, u8)> {
        let f = &self.fluid;
        let what = |i: usize| -> Option<u8> {
            if !spatter_core::math::is_finite(f.pos[i]) {
                Some(0)
            } else if !spatter_core::math::is_finite(f.vel[i]) {
                Some(1)
            } else if !f.rho[i].is_finite() {
                Some(2)
            } else {
                None
            }
        };
        let worst = (0..f.len())
            .into_par_iter()
            .with_min_len(4096)
            .filter_map(|i| what(i).map(|w| (f.id[i], w)))
            .min_by_key(|&(id, _)| id)?;
        let keep: Vec<bool> = (0..f.len()).map(|i| what(i).is_none()).collect();
        self.fluid.retain(&keep);
        Some(worst)
    }

    /// Sends every particle outside this rank's box to its owner and appends the particles received.
    fn migrate(&mut self, comm: &dyn Comm) {
        let Some(d) = self.decomp.as_mut() else { return };
        let f = &mut self.fluid;
        let shifting = !f.shift.is_empty();
        let leaving: Vec<(usize, usize)> = f
            .pos
            .par_iter()
            .enumerate()
            .with_min_len(4096)
            .filter_map(|(i, &x)| {
                let o = d.rcb.owner(x);
                (o != d.rank).then_some((o, i))
            })
            .collect();
        let far = leaving.iter().any(|(o, _)| d.peer_ranks.binary_search(o).is_err());
        let mut flag = [far as u64];
        comm.all_sum_u64(&mut flag);
        // Destinations: the neighbours, or every rank when some particle jumped further.
        let dest: Vec<usize> = if flag[0] > 0 { (0..d.size).collect() } else { d.peer_ranks.clone() };
        let mut out: Vec<WireWriter> = dest.iter().map(|_| WireWriter::with_capacity(0)).collect();
        for &(o, i) in &leaving {
            let k = dest.binary_search(&o).expect("the owner is a destination");
            let w = &mut out[k];
            w.vec3(f.pos[i]).vec3(f.vel[i]).f64(f.rho[i]).vec3(f.acc[i]).f64(f.drho[i]);
            w.u32(f.id[i]).u32(f.near[i]);
            if shifting {
                w.vec3(f.shift[i]);
            }
        }
        let out: Vec<Vec<u8>> = out.into_iter().map(WireWriter::finish).collect();
        let got =
            if flag[0] > 0 { comm.all_to_all_bytes(&out) } else { comm.neighbour_exchange(&dest, &out) };
        if !leaving.is_empty() {
            let mut keep = vec![true; f.len()];
            for &(_, i) in &leaving {
                keep[i] = false;
            }
            f.retain(&keep);
        }
        let mut arrived = 0;
        for buf in &got {
            let mut r = WireReader::new(buf);
            while !r.is_done() {
                // The buffers were written just above by the same code on the sending rank.
                let bad = "migration message from another rank of this run";
                f.pos.push(r.vec3().expect(bad));
                f.vel.push(r.vec3().expect(bad));
                f.rho.push(r.f64().expect(bad));
                f.acc.push(r.vec3().expect(bad));
                f.drho.push(r.f64().expect(bad));
                f.id.push(r.u32().expect(bad));
                f.near.push(r.u32().expect(bad));
                if shifting {
                    f.shift.push(r.vec3().expect(bad));
                }
                arrived += 1;
            }
        }
        d.last_migrants = arrived;
    }

    /// Builds the halo: sends the fluid within the halo width of every neighbour's box (shifted for
    /// periodic images), keeps the send lists, and puts what arrives into the image arrays.
    pub(super) fn exchange_halo(&mut self, comm: &dyn Comm) {
        let width = HALO_SUPPORTS * self.kernel().support();
        let Some(d) = self.decomp.as_mut() else { return };
        let f = &self.fluid;
        for list in &mut d.send {
            list.clear();
        }
        for peer in &d.peers {
            let k = d.peer_ranks.binary_search(&peer.rank).expect("peer ranks come from the peers");
            let target = Aabb::new(d.boxes[peer.rank].min + peer.shift, d.boxes[peer.rank].max + peer.shift);
            let shift = peer.shift;
            let picked: Vec<(u32, Vec3)> = f
                .pos
                .par_iter()
                .enumerate()
                .with_min_len(4096)
                .filter_map(|(i, &x)| (point_gap(x, &target) <= width).then_some((i as u32, shift)))
                .collect();
            d.send[k].extend_from_slice(&picked);
        }
        let out: Vec<Vec<u8>> = d
            .send
            .iter()
            .map(|list| {
                let mut w = WireWriter::with_capacity(56 * list.len());
                for &(i, s) in list {
                    let i = i as usize;
                    w.vec3(f.pos[i] - s).vec3(f.vel[i]).f64(f.rho[i]);
                }
                w.finish()
            })
            .collect();
        let got = comm.neighbour_exchange(&d.peer_ranks, &out);
        let w = &mut self.work;
        w.g_pos.clear();
        w.g_src.clear();
        d.halo_vel.clear();
        d.halo_rho.clear();
        for buf in &got {
            let mut r = WireReader::new(buf);
            while !r.is_done() {
                let bad = "halo message from another rank of this run";
                w.g_src.push(w.g_pos.len() as u32);
                w.g_pos.push(r.vec3().expect(bad));
                d.halo_vel.push(r.vec3().expect(bad));
                d.halo_rho.push(r.f64().expect(bad));
            }
        }
        d.last_halo = w.g_pos.len();
        self.sort_images();
    }

    /// Sends the current velocity and density of the particles of the last halo exchange again (same
    /// lists, same order), so that sensors between steps see the corrected state. Collective.
    pub(super) fn refresh_halo(&mut self, comm: &dyn Comm) {
        let Some(d) = self.decomp.as_mut() else { return };
        let f = &self.fluid;
        let out: Vec<Vec<u8>> = d
            .send
            .iter()
            .map(|list| {
                let mut w = WireWriter::with_capacity(32 * list.len());
                for &(i, _) in list {
                    w.vec3(f.vel[i as usize]).f64(f.rho[i as usize]);
                }
                w.finish()
            })
            .collect();
        let got = comm.neighbour_exchange(&d.peer_ranks, &out);
        let mut slot = 0;
        for buf in &got {
            let mut r = WireReader::new(buf);
            while !r.is_done() {
                let bad = "halo message from another rank of this run";
                d.halo_vel[slot] = r.vec3().expect(bad);
                d.halo_rho[slot] = r.f64().expect(bad);
                slot += 1;
            }
        }
        self.gather_halo_state();
    }

    /// Sends `values` (one per owned particle) of the particles of the last halo exchange (same lists,
    /// same order) and returns what arrives, by receive slot. Collective. For the quantities the owner
    /// computes from its whole neighbourhood within a step: surface normals and wall adhesion.
    fn halo_vec3(d: &Decomp, comm: &dyn Comm, values: &[Vec3]) -> Vec<Vec3> {
        let out: Vec<Vec<u8>> = d
            .send
            .iter()
            .map(|list| {
                let mut w = WireWriter::with_capacity(24 * list.len());
                for &(i, _) in list {
                    w.vec3(values[i as usize]);
                }
                w.finish()
            })
            .collect();
        let got = comm.neighbour_exchange(&d.peer_ranks, &out);
        let mut v = Vec::with_capacity(d.halo_vel.len());
        for buf in &got {
            let mut r = WireReader::new(buf);
            while !r.is_done() {
                v.push(r.vec3().expect("halo message from another rank of this run"));
            }
        }
        v
    }

    /// The surface normals of the halo particles, in image order (`g_src`), into `out`. Collective.
    pub(super) fn halo_normals(&self, comm: &dyn Comm, nrm: &[Vec3], out: &mut Vec<Vec3>) {
        let Some(d) = self.decomp.as_ref() else { return };
        let by_slot = Self::halo_vec3(d, comm, nrm);
        out.clear();
        out.extend(self.work.g_src.iter().map(|&s| by_slot[s as usize]));
    }

    /// Exchanges the wall adhesion of the owned particles (`adh`) for that of the halo, kept by receive
    /// slot. Collective.
    pub(super) fn exchange_halo_adhesion(&mut self, comm: &dyn Comm, adh: &[Vec3]) {
        let Some(d) = self.decomp.as_ref() else { return };
        let by_slot = Self::halo_vec3(d, comm, adh);
        if let Some(d) = self.decomp.as_mut() {
            d.halo_adh = by_slot;
        }
    }

    /// The wall adhesion of the halo particles from the last exchange, in image order, into `out`.
    pub(super) fn halo_adhesion(&self, out: &mut Vec<Vec3>) {
        let Some(d) = self.decomp.as_ref() else { return };
        out.clear();
        out.extend(self.work.g_src.iter().map(|&s| d.halo_adh[s as usize]));
    }

    /// Velocity, density, p/ρ² and 1/ρ of the halo particles from the received values, by the equation
    /// of state the owner uses (bit-identical to the owner's values).
    pub(super) fn gather_halo_state(&mut self) {
        let eos = self.params.eos();
        let Some(d) = self.decomp.as_ref() else { return };
        let w = &mut self.work;
        w.g_vel.clear();
        w.g_vel.extend(w.g_src.iter().map(|&s| d.halo_vel[s as usize]));
        w.g_rho.clear();
        w.g_rho.extend(w.g_src.iter().map(|&s| d.halo_rho[s as usize]));
        w.g_irho.clear();
        w.g_irho.extend(w.g_rho.iter().map(|&rho| 1.0 / rho));
        w.g_pr.clear();
        w.g_pr.extend(w.g_rho.iter().zip(&w.g_irho).map(|(&rho, &ir)| eos.pressure(rho) * ir * ir));
    }

    /// The reductions at the end of a step on several ranks: maxima for the time step (exact), sums of
    /// the counts; then the blow-up check, raised on every rank alike.
    pub(super) fn reduce_step(
        &mut self,
        comm: &dyn Comm,
        st: PassStats,
        counts: LocalCounts,
    ) -> Result<(), SphError> {
        let (v2, rmax, rmin) = self.local_extrema();
        let bad = counts.bad.map_or(f64::NEG_INFINITY, |(id, _)| -f64::from(id));
        let mut r1 = [v2, rmax, -rmin, st.max_acc, bad];
        comm.all_max_f64(&mut r1);
        let mut r2 = [st.interactions, counts.guard_hits, counts.removed_domain, counts.removed_density];
        comm.all_sum_u64(&mut r2);
        self.set_dt(r1[0], r1[1], -r1[2], PassStats { max_acc: r1[3], interactions: r2[0] });
        self.last.guard_hits = r2[1];
        self.removed.outside_domain += r2[2];
        self.removed.density_window += r2[3];
        if r1[4] == f64::NEG_INFINITY {
            return Ok(());
        }
        // Someone dropped a non-finite particle: the lowest id, and what its owner saw.
        let id = (-r1[4]) as u32;
        let mut w = WireWriter::with_capacity(8);
        if let Some((bad_id, what)) = counts.bad {
            w.u32(bad_id).u32(u32::from(what));
        }
        let what = comm
            .all_gather_bytes(&w.finish())
            .iter()
            .filter_map(|b| {
                let mut r = WireReader::new(b);
                Some((r.u32().ok()?, r.u32().ok()?))
            })
            .find(|&(i, _)| i == id)
            .map_or("state", |(_, w)| WHAT[(w as usize).min(2)]);
        Err(self.blow_up(id, what, self.steps, self.time, self.last.dt_taken))
    }
}

/// Collective forms of the sensors and totals: every rank calls them at the same point with the same
/// arguments and gets the same value (floating-point sums added in rank order). On one rank they are the
/// plain methods.
impl Simulation {
    /// Number of fluid particles over all ranks.
    pub fn fluid_count_with(&self, comm: &dyn Comm) -> u64 {
        let mut n = [self.fluid.len() as u64];
        comm.all_sum_u64(&mut n);
        n[0]
    }

    /// [`Self::kinetic_energy`] over all ranks \[J, J/m in 2D\].
    pub fn kinetic_energy_with(&self, comm: &dyn Comm) -> f64 {
        let mut e = [self.kinetic_energy()];
        comm.sum_f64_ordered(&mut e);
        e[0]
    }

    /// [`Self::momentum`] over all ranks \[kg m/s\].
    pub fn momentum_with(&self, comm: &dyn Comm) -> Vec3 {
        let p = self.momentum();
        let mut v = [p.x, p.y, p.z];
        comm.sum_f64_ordered(&mut v);
        Vec3::new(v[0], v[1], v[2])
    }

    /// [`Self::fluid_mass`] over all ranks \[kg, kg/m in 2D\] (count × particle mass: exact).
    pub fn fluid_mass_with(&self, comm: &dyn Comm) -> f64 {
        self.params.mass() * self.fluid_count_with(comm) as f64
    }

    /// [`Self::part_loads`] over all ranks: each rank adds the wall entries in its box, after the halo
    /// got the state of the last corrector.
    pub fn part_loads_with(&mut self, comm: &dyn Comm) -> Vec<PartLoad> {
        if self.decomp.is_none() {
            return self.part_loads();
        }
        self.refresh_halo(comm);
        let loads = self.part_loads();
        let mut v: Vec<f64> =
            loads.iter().flat_map(|l| [l.force, l.torque]).flat_map(|x| [x.x, x.y, x.z]).collect();
        comm.sum_f64_ordered(&mut v);
        v.chunks_exact(6)
            .map(|c| PartLoad { force: Vec3::new(c[0], c[1], c[2]), torque: Vec3::new(c[3], c[4], c[5]) })
            .collect()
    }

    /// [`Self::probe`] evaluated by the rank whose box holds `x` (its halo covers the kernel support
    /// around `x`) and sent to every rank.
    pub fn probe_with(&mut self, comm: &dyn Comm, x: Vec3) -> Option<(f64, Vec3)> {
        let Some(owner) = self.decomp.as_ref().map(|d| d.rcb.owner(x)) else {
            return self.probe(x);
        };
        self.refresh_halo(comm);
        let mut buf = Vec::new();
        if comm.rank() == owner {
            let mut w = WireWriter::with_capacity(40);
            if let Some((p, v)) = self.probe(x) {
                w.f64(p).vec3(v);
            }
            buf = w.finish();
        }
        comm.broadcast_bytes(owner, &mut buf);
        let mut r = WireReader::new(&buf);
        let p = r.f64().ok()?;
        Some((p, r.vec3().ok()?))
    }

    /// [`Self::wall_pressure`] over all ranks: the entries of every rank's box, one mean.
    pub fn wall_pressure_with(&mut self, comm: &dyn Comm, x: Vec3, radius: f64) -> Option<f64> {
        if self.decomp.is_none() {
            return self.wall_pressure(x, radius);
        }
        let (s, n) = self.wall_pressure_sum(x, radius);
        let mut sum = [s];
        comm.sum_f64_ordered(&mut sum);
        let mut count = [n as u64];
        comm.all_sum_u64(&mut count);
        (count[0] > 0).then(|| sum[0] / count[0] as f64)
    }
}

/// Wetting on several ranks: each wall particle's wet flag is kept by the rank whose box holds it, and its
/// wet time is split over the ranks that owned it while it was wet (each step's dt goes to one rank).
impl Simulation {
    /// True when wall particle `i` lies in this rank's box now (always on one rank).
    fn owns_wall(&self, i: usize) -> bool {
        self.decomp.as_ref().is_none_or(|d| d.owns(self.boundary.position(i)))
    }

    /// [`crate::wetting::wet_area`] over all ranks (collective).
    pub fn wet_area_with(&self, comm: &dyn Comm, k: usize, elapsed: f64) -> crate::wetting::WetArea {
        let mut w = crate::wetting::wet_area(self, k, elapsed);
        if self.decomp.is_none() {
            return w;
        }
        let part = &self.boundary.parts[k];
        let b = &self.boundary;
        // The mean is a sum over every particle's partial wet time; "wet now" counts owned particles.
        let now: f64 =
            (part.start..part.end).filter(|&i| b.wet[i] && self.owns_wall(i)).map(|i| b.area[i]).sum();
        let mut v = [now, w.wet_mean];
        comm.sum_f64_ordered(&mut v);
        (w.wet_now, w.wet_mean) = (v[0], v[1]);
        w
    }

    /// [`crate::wetting::part_water`] over the ranks of `comm` (each rank's own fluid, summed in rank
    /// order). Collective.
    pub fn part_water_with(&self, comm: &dyn Comm, k: usize) -> crate::wetting::PartWater {
        let mut w = crate::wetting::part_water(self, k);
        if self.decomp.is_some() {
            let mut v = [w.volume, w.arrival];
            comm.sum_f64_ordered(&mut v);
            (w.volume, w.arrival) = (v[0], v[1]);
        }
        w
    }

    /// The wet flag and total wet time \[s\] of every wall particle, gathered from the ranks that hold
    /// them (collective); on one rank the boundary's own arrays.
    pub fn wetting_with(&self, comm: &dyn Comm) -> (Vec<bool>, Vec<f64>) {
        let b = &self.boundary;
        if self.decomp.is_none() {
            return (b.wet.clone(), b.wet_time.clone());
        }
        let mut wet: Vec<u64> = (0..b.len()).map(|i| u64::from(b.wet[i] && self.owns_wall(i))).collect();
        comm.all_sum_u64(&mut wet);
        let mut time = b.wet_time.clone();
        comm.sum_f64_ordered(&mut time);
        (wet.iter().map(|&w| w > 0).collect(), time)
    }

    /// Gathers the wetting records ([`Self::wetting_with`]): afterwards every rank holds every wall
    /// particle's current wet flag, rank 0 the whole wet time and the others none, so the maps drawn from
    /// the boundary on rank 0 are the run's, and the collective sums stay right if the run steps on.
    pub fn gather_wetting(&mut self, comm: &dyn Comm) {
        if self.decomp.is_none() {
            return;
        }
        let (wet, mut time) = self.wetting_with(comm);
        if comm.rank() != 0 {
            time.fill(0.0);
        }
        self.boundary.wet = wet;
        self.boundary.wet_time = time;
        // Flags of wall particles outside this rank's wall set are never rewritten while they stay out:
        // the next wall set build clears them again.
        self.work.walls_built = false;
    }
}
