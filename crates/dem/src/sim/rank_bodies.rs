//! Rigid bodies (clumps) in a run split over ranks ([`super::decomp`]).
//!
//! A body and all its members live on one rank: the rank whose box holds the body's centre of mass.
//! So the reduction of member forces onto the body, the body's kick and drift and the placing of its
//! members stay local, exactly as on one rank; only contacts of members with particles of other ranks
//! cross the cut, through the same ghosts as single spheres (a ghost member carries its body's inverse
//! mass, which is all the contact laws read).
//!
//! * **Ownership** changes, like a sphere's, only at a neighbour-list rebuild: a body whose centre left
//!   its owner's box moves to the new owner with its whole state ([`BodyRecord`]) and its members (each
//!   with its contact history, as any sphere).
//! * **Halo**: a member stands up to the largest member arm `a` (distance from its body's centre) outside
//!   its owner's box, so the halo width grows by `a`, and ranks whose boxes lie within the width plus
//!   `a` exchange ghosts. Without bodies `a` = 0 and nothing changes.
//! * **Ids**: every rank builds the same set-up, so every body has the id it has on one rank; a body
//!   added during the run by every rank alike is kept by the rank of its centre, the others count its
//!   ids ([`Simulation::add_clump_split`]).
//! * **Joining checkpoint parts** ([`Simulation::join_parts`]) gathers the bodies of every part in id
//!   order.

use super::Simulation;
use crate::clump::BodyRecord;
use crate::clump::{Bodies, NewBody, NO_BODY};
use crate::contact::ContactLaw;
use crate::error::DemError;
use spatter_core::rcb::Rcb;

impl<L: ContactLaw> Simulation<L> {
    /// The rank that owns each particle under `rcb`: a free sphere by its centre, a member by its
    /// body's centre of mass.
    pub(super) fn owner_ranks(&self, rcb: &Rcb) -> Vec<usize> {
        let (p, b) = (&self.particles, &self.st.bodies);
        (0..p.len())
            .map(|i| if p.is_member(i) { rcb.owner(b.pos[p.body[i] as usize]) } else { rcb.owner(p.pos[i]) })
            .collect()
    }

    /// Keeps the bodies whose centre `rcb` gives to `rank` (their members were kept with them) and
    /// renumbers the members' body indices.
    pub(super) fn keep_owned_bodies(&mut self, rcb: &Rcb, rank: usize) {
        if self.st.bodies.is_empty() {
            return;
        }
        let keep: Vec<bool> = self.st.bodies.pos.iter().map(|&x| rcb.owner(x) == rank).collect();
        self.drop_bodies(&keep);
    }

    /// Removes the bodies with `keep[b]` false (their members must be gone already) and renumbers the
    /// body indices of the members left.
    pub(super) fn drop_bodies(&mut self, keep: &[bool]) {
        if keep.iter().all(|&k| k) {
            return;
        }
        let map = self.st.bodies.retain(keep);
        for b in self.particles.body.iter_mut() {
            if *b != NO_BODY {
                *b = map[*b as usize];
                debug_assert!(*b != NO_BODY, "a member stayed without its body");
            }
        }
    }

    /// The bodies whose centre `rcb` gives to another rank: (owner, body index), in index order.
    pub(super) fn leaving_bodies(&self, rcb: &Rcb, rank: usize) -> Vec<(usize, usize)> {
        let b = &self.st.bodies;
        (0..b.len()).filter_map(|k| Some((rcb.owner(b.pos[k]), k)).filter(|o| o.0 != rank)).collect()
    }

    /// The id of particle `i`'s body ([`NO_BODY`] for a free sphere): what a migrating member carries.
    pub(super) fn body_id_of(&self, i: usize) -> u32 {
        let p = &self.particles;
        if p.is_member(i) {
            self.st.bodies.id[p.body[i] as usize]
        } else {
            NO_BODY
        }
    }

    /// Takes the bodies that arrived by migration (`records`) and the members that arrived with them,
    /// the particles from index `first` on whose body ids are `body_ids` (one per arrived particle,
    /// [`NO_BODY`] for free spheres).
    pub(super) fn attach_arrived(&mut self, first: usize, body_ids: &[u32], records: Vec<BodyRecord>) {
        let any_member = body_ids.iter().any(|&b| b != NO_BODY);
        if !self.particles.body.is_empty() || any_member {
            let n = self.particles.len();
            self.particles.body.resize(n, NO_BODY);
        }
        if !any_member {
            return;
        }
        let mut index: Vec<(u32, u32)> =
            records.into_iter().map(|r| (r.id, self.st.bodies.push_record(r) as u32)).collect();
        index.sort_unstable();
        let p = &mut self.particles;
        for (k, &id) in body_ids.iter().enumerate() {
            if id != NO_BODY {
                let m = index.binary_search_by_key(&id, |e| e.0).expect("a member arrives with its body");
                p.body[first + k] = index[m].1;
            }
        }
    }

    /// Halo widths of a split run at a rebuild, from the largest radius `r_max` and member arm `arm` over
    /// all ranks: (the distance from a neighbour's box within which a particle is sent to it as a ghost,
    /// the distance between boxes within which two ranks exchange ghosts) \[m\].
    pub(super) fn halo_widths(&self, r_max: f64, arm: f64) -> (f64, f64) {
        let (range_pp, _) = self.range_max(r_max);
        let send = 2.0 * r_max + range_pp + self.skin() + arm;
        (send, send + arm)
    }

    /// [`Self::add_clump`] on a run split over ranks: every rank calls it with the same body; the rank
    /// whose box holds its centre adds it, the others only count its ids (body and members), so the ids
    /// stay those of a one-rank run. Returns the body id. Not split, the plain method.
    pub fn add_clump_split(&mut self, template: usize, material: u16, b: NewBody) -> Result<u32, DemError> {
        let owner = self.decomp_owner(b.pos);
        if owner.is_none_or(|(o, rank)| o == rank) {
            return self.add_clump(template, material, b);
        }
        let members = self
            .templates
            .get(template)
            .ok_or_else(|| DemError::Config {
                key: "template".into(),
                message: format!(
                    "no clump template with index {template} ({} registered)",
                    self.templates.len()
                ),
            })?
            .spheres
            .len();
        for _ in 0..members {
            self.particles.skip_id();
        }
        Ok(self.st.bodies.skip_id())
    }

    /// Bodies over all ranks (collective; the plain count when not split).
    pub fn body_count_with(&self, comm: &dyn spatter_core::comm::Comm) -> u64 {
        let mut n = [self.st.bodies.len() as u64];
        if self.ranks() > 1 {
            comm.all_sum_u64(&mut n);
        }
        n[0]
    }
}

/// The bodies of checkpoint parts joined into one state: each part's members point at their body by
/// id while the parts are gathered ([`JoinedBodies::take`]), then at its index in the joined set, which
/// holds every body in id order ([`JoinedBodies::finish`]).
pub(super) struct JoinedBodies {
    records: Vec<BodyRecord>,
    next_id: u32,
}

impl JoinedBodies {
    pub(super) fn new() -> Self {
        JoinedBodies { records: Vec::new(), next_id: 0 }
    }

    /// Takes the bodies of one part; the part's members' body field `body` is turned from body indices
    /// into body ids.
    pub(super) fn take(&mut self, bodies: &Bodies, body: &mut [u32]) {
        for b in body.iter_mut().filter(|b| **b != NO_BODY) {
            *b = bodies.id[*b as usize];
        }
        self.records.extend((0..bodies.len()).map(|k| bodies.record(k)));
        self.next_id = self.next_id.max(bodies.next_id());
    }

    /// The joined body set, in id order, and the members' body field `body` (holding ids) turned into
    /// indices of it.
    pub(super) fn finish(mut self, body: &mut [u32]) -> Result<Bodies, DemError> {
        self.records.sort_by_key(|r| r.id);
        if let Some(w) = self.records.windows(2).find(|w| w[0].id == w[1].id) {
            return Err(DemError::Resume(format!("body {} is held by two checkpoint parts", w[0].id)));
        }
        let ids: Vec<u32> = self.records.iter().map(|r| r.id).collect();
        let mut out = Bodies::default();
        for r in self.records {
            out.push_record(r);
        }
        out.skip_to(self.next_id);
        for b in body.iter_mut().filter(|b| **b != NO_BODY) {
            *b = ids.binary_search(b).map_err(|_| {
                DemError::Resume(format!("a member of body {b} is in the checkpoint, its body is not"))
            })? as u32;
        }
        Ok(out)
    }
}
