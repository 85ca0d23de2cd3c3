//! The particle store: spheres as structure-of-arrays, with stable ids.
//!
//! Arrays are re-sorted by neighbour-search cell whenever the contact list is rebuilt (cache locality); a
//! particle's *index* therefore changes over a run, its *id* never does. Contact history is keyed by ids.
//!
//! Frozen particles (rough walls made of fixed spheres) have infinite mass and moment of inertia
//! (`inv_mass = 0`): they are never integrated, keep the velocity they were given, and a
//! contact with one behaves like a contact with a rigid body (m* = m of the free partner).

use crate::clump::NO_BODY;
use serde::{Deserialize, Serialize};
use spatter_core::math::sphere_volume;
use spatter_core::Vec3;

/// Spheres, structure-of-arrays. All vectors have the same length.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Particles {
    /// Stable id (never reused within a run).
    pub id: Vec<u32>,
    /// Material index into the simulation's material list.
    pub material: Vec<u16>,
    /// Position of the centre \[m\].
    pub pos: Vec<Vec3>,
    /// Velocity \[m/s\].
    pub vel: Vec<Vec3>,
    /// Angular velocity \[rad/s\].
    pub omega: Vec<Vec3>,
    /// Radius \[m\].
    pub radius: Vec<f64>,
    /// 1/m \[1/kg\]; 0 for a frozen particle.
    pub inv_mass: Vec<f64>,
    /// Force of the last evaluation \[N\] (contacts, gravity, external).
    pub force: Vec<Vec3>,
    /// Torque of the last evaluation \[N m\].
    pub torque: Vec<Vec3>,
    /// Persistent external force per particle \[N\] (e.g. fluid drag), added at every evaluation; empty
    /// until first used (see [`Particles::external_force_mut`]).
    pub ext_force: Vec<Vec3>,
    /// Persistent external torque per particle \[N m\]; empty until first used.
    pub ext_torque: Vec<Vec3>,
    /// Index of the rigid body the sphere belongs to ([`NO_BODY`] for a free sphere); empty while the
    /// simulation has no bodies (see [`crate::clump`]).
    #[serde(default)]
    pub body: Vec<u32>,
    next_id: u32,
}

/// A new particle to add.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewParticle {
    pub pos: Vec3,
    pub vel: Vec3,
    pub omega: Vec3,
    /// Radius \[m\].
    pub radius: f64,
    /// Material index.
    pub material: u16,
    /// Fixed in space (infinite mass).
    pub frozen: bool,
}

impl NewParticle {
    /// A free particle at rest.
    pub fn at(pos: Vec3, radius: f64, material: u16) -> Self {
        NewParticle { pos, vel: Vec3::ZERO, omega: Vec3::ZERO, radius, material, frozen: false }
    }
}

impl Particles {
    pub fn new() -> Self {
        Self::default()
    }

    pub fn len(&self) -> usize {
        self.id.len()
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }

    /// The id the next added particle will get.
    pub fn next_id(&self) -> u32 {
        self.next_id
    }

    /// Appends a particle of material density `density` \[kg/m³\]; returns its id.
    pub fn push(&mut self, p: NewParticle, density: f64) -> u32 {
        let id = self.next_id;
        self.next_id += 1;
        let m = density * sphere_volume(p.radius);
        self.id.push(id);
        self.material.push(p.material);
        self.pos.push(p.pos);
        self.vel.push(p.vel);
        self.omega.push(if p.frozen { Vec3::ZERO } else { p.omega });
        self.radius.push(p.radius);
        self.inv_mass.push(if p.frozen { 0.0 } else { 1.0 / m });
        self.force.push(Vec3::ZERO);
        self.torque.push(Vec3::ZERO);
        if !self.ext_force.is_empty() {
            self.ext_force.push(Vec3::ZERO);
            self.ext_torque.push(Vec3::ZERO);
        }
        if !self.body.is_empty() {
            self.body.push(NO_BODY);
        }
        id
    }

    /// Takes the next id without adding a particle: on a run split over ranks, every rank counts the ids
    /// of the particles added on the others, so that ids stay those of a one-rank run.
    pub(crate) fn skip_id(&mut self) -> u32 {
        let id = self.next_id;
        self.next_id += 1;
        id
    }

    /// Appends a member sphere of body `body` that carries the body's inverse mass `inv_mass` \[1/kg\]
    /// (the mass its contacts see); returns its id.
    pub(crate) fn push_member(&mut self, p: NewParticle, inv_mass: f64, body: u32) -> u32 {
        let id = self.push(NewParticle { frozen: false, ..p }, 1.0);
        self.body.resize(self.len(), NO_BODY);
        let i = self.len() - 1;
        self.inv_mass[i] = inv_mass;
        self.body[i] = body;
        id
    }

    /// Whether particle `i` (index) is a member of a rigid body.
    #[inline]
    pub fn is_member(&self, i: usize) -> bool {
        !self.body.is_empty() && self.body[i] != NO_BODY
    }

    /// Whether particle `i` (index) is frozen.
    #[inline]
    pub fn is_frozen(&self, i: usize) -> bool {
        self.inv_mass[i] == 0.0
    }

    /// Mass of particle `i` \[kg\] (∞ for a frozen particle).
    #[inline]
    pub fn mass(&self, i: usize) -> f64 {
        1.0 / self.inv_mass[i]
    }

    /// 1/I of particle `i` \[1/(kg m²)\], I = (2/5) m r² (0 for a frozen particle).
    #[inline]
    pub fn inv_inertia(&self, i: usize) -> f64 {
        2.5 * self.inv_mass[i] / (self.radius[i] * self.radius[i])
    }

    /// Moment of inertia of particle `i` \[kg m²\] (∞ for a frozen particle).
    pub fn inertia(&self, i: usize) -> f64 {
        0.4 * self.radius[i] * self.radius[i] / self.inv_mass[i]
    }

    /// Total mass of the free (not frozen) particles \[kg\].
    pub fn free_mass(&self) -> f64 {
        self.inv_mass.iter().filter(|&&m| m > 0.0).map(|m| 1.0 / m).sum()
    }

    /// The persistent external force and torque arrays (allocated on first call). Values stay until
    /// changed and follow their particle through re-sorting.
    pub fn external_force_mut(&mut self) -> (&mut [Vec3], &mut [Vec3]) {
        if self.ext_force.len() != self.len() {
            self.ext_force.resize(self.len(), Vec3::ZERO);
            self.ext_torque.resize(self.len(), Vec3::ZERO);
        }
        (&mut self.ext_force, &mut self.ext_torque)
    }

    /// Index of the particle with id `id` (linear search; for tests and post-processing).
    pub fn index_of(&self, id: u32) -> Option<usize> {
        self.id.iter().position(|&x| x == id)
    }

    /// Reorders every array so that new index k holds old index `perm[k]`; `scratch` buffers are reused.
    pub fn permute(&mut self, perm: &[u32], scratch: &mut PermuteScratch) {
        debug_assert_eq!(perm.len(), self.len());
        fn apply<T: Copy>(v: &mut Vec<T>, perm: &[u32], buf: &mut Vec<T>) {
            if v.is_empty() {
                return;
            }
            buf.clear();
            buf.extend(perm.iter().map(|&k| v[k as usize]));
            std::mem::swap(v, buf);
        }
        let s = scratch;
        apply(&mut self.id, perm, &mut s.u32s);
        apply(&mut self.material, perm, &mut s.u16s);
        apply(&mut self.pos, perm, &mut s.vecs);
        apply(&mut self.vel, perm, &mut s.vecs);
        apply(&mut self.omega, perm, &mut s.vecs);
        apply(&mut self.force, perm, &mut s.vecs);
        apply(&mut self.torque, perm, &mut s.vecs);
        apply(&mut self.ext_force, perm, &mut s.vecs);
        apply(&mut self.ext_torque, perm, &mut s.vecs);
        apply(&mut self.radius, perm, &mut s.f64s);
        apply(&mut self.inv_mass, perm, &mut s.f64s);
        apply(&mut self.body, perm, &mut s.u32s);
    }

    /// Removes the particles for which `remove(index)` is true (order of the rest is kept).
    pub fn retain(&mut self, mut keep: impl FnMut(usize) -> bool) {
        let mask: Vec<bool> = (0..self.len()).map(&mut keep).collect();
        fn filter<T>(v: &mut Vec<T>, mask: &[bool]) {
            if v.is_empty() {
                return;
            }
            let mut k = 0;
            v.retain(|_| {
                let r = mask[k];
                k += 1;
                r
            });
        }
        filter(&mut self.id, &mask);
        filter(&mut self.material, &mask);
        filter(&mut self.pos, &mask);
        filter(&mut self.vel, &mask);
        filter(&mut self.omega, &mask);
        filter(&mut self.force, &mask);
        filter(&mut self.torque, &mask);
        filter(&mut self.ext_force, &mask);
        filter(&mut self.ext_torque, &mask);
        filter(&mut self.radius, &mask);
        filter(&mut self.inv_mass, &mask);
        filter(&mut self.body, &mask);
    }

    /// Appends every particle of `other` (ids kept; the next id is the larger of the two). The optional
    /// arrays (external force and torque, body index) are kept when either store has them, with zero
    /// or [`NO_BODY`] for the particles that had none.
    pub fn append(&mut self, mut other: Particles) {
        let (n, m) = (self.len(), other.len());
        if !self.ext_force.is_empty() || !other.ext_force.is_empty() {
            self.external_force_mut();
            other.external_force_mut();
        }
        if !self.body.is_empty() || !other.body.is_empty() {
            self.body.resize(n, NO_BODY);
            other.body.resize(m, NO_BODY);
        }
        self.id.append(&mut other.id);
        self.material.append(&mut other.material);
        self.pos.append(&mut other.pos);
        self.vel.append(&mut other.vel);
        self.omega.append(&mut other.omega);
        self.radius.append(&mut other.radius);
        self.inv_mass.append(&mut other.inv_mass);
        self.force.append(&mut other.force);
        self.torque.append(&mut other.torque);
        self.ext_force.append(&mut other.ext_force);
        self.ext_torque.append(&mut other.ext_torque);
        self.body.append(&mut other.body);
        self.next_id = self.next_id.max(other.next_id);
    }

    /// Sorts the particles by id.
    pub fn sort_by_id(&mut self) {
        let mut perm: Vec<u32> = (0..self.len() as u32).collect();
        perm.sort_unstable_by_key(|&k| self.id[k as usize]);
        self.permute(&perm, &mut PermuteScratch::default());
    }

    /// Bytes of particle state per particle (for memory reports).
    pub fn bytes_per_particle(&self) -> usize {
        let ext = if self.ext_force.is_empty() { 0 } else { 48 };
        let body = if self.body.is_empty() { 0 } else { 4 };
        4 + 2 + 5 * 24 + 2 * 8 + ext + body
    }
}

/// Reusable buffers for [`Particles::permute`].
#[derive(Clone, Debug, Default)]
pub struct PermuteScratch {
    u32s: Vec<u32>,
    u16s: Vec<u16>,
    vecs: Vec<Vec3>,
    f64s: Vec<f64>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permutation_keeps_ids_with_their_data_and_frozen_has_infinite_mass() {
        let mut p = Particles::new();
        for k in 0..5 {
            let mut np = NewParticle::at(Vec3::new(k as f64, 0.0, 0.0), 0.1 + 0.01 * k as f64, 0);
            np.frozen = k == 3;
            p.push(np, 1000.0);
        }
        let mut s = PermuteScratch::default();
        p.permute(&[4, 2, 0, 3, 1], &mut s);
        assert_eq!(p.id, vec![4, 2, 0, 3, 1]);
        for i in 0..5 {
            assert_eq!(p.pos[i].x, p.id[i] as f64);
            assert_eq!(p.radius[i], 0.1 + 0.01 * p.id[i] as f64);
        }
        let f = p.index_of(3).unwrap();
        assert!(p.is_frozen(f) && p.inv_inertia(f) == 0.0 && p.mass(f).is_infinite());
        p.retain(|i| p_id_not(i, 2));
        fn p_id_not(i: usize, idx: usize) -> bool {
            i != idx
        }
        assert_eq!(p.len(), 4);
        assert_eq!(p.next_id(), 5, "ids are never reused");
    }
}
