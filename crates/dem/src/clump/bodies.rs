//! The rigid-body set beside the sphere store.
//!
//! A clump is one [`Bodies`] entry plus its member spheres, which live in the ordinary
//! [`Particles`](crate::Particles) store (so every contact — sphere, clump member, wall of any kind — goes
//! through the same pair and wall loops). A member is flagged with its body index in `Particles::body`;
//! members of one body get consecutive particle ids, `first_id .. first_id + count`, and the member slot is
//! `id − first_id`, so the body finds its members again after every re-sort of the particle arrays.
//!
//! Members carry 1/m = 1/M of their body: the contact laws use the body mass as the particle mass in m*
//! (the physical choice for a rigid composite; the sphere's own mass would make the damping far too weak
//! for the body's inertia). The free-sphere kick also moves members, but their state is overwritten from
//! the body in the same step (cheaper than a branch in the kick of every sphere).

use serde::{Deserialize, Serialize};
use spatter_core::{Quat, Vec3};

/// No body: the particle is a free sphere.
pub const NO_BODY: u32 = u32::MAX;

/// Rigid bodies, structure-of-arrays. Member arrays (`offset`, `arm`, `member_index`) are flattened,
/// body b's members at `member_start[b] .. member_start[b + 1]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Bodies {
    /// Stable body id (never reused within a run).
    pub id: Vec<u32>,
    /// Index of the template in the simulation's template list.
    pub template: Vec<u32>,
    /// Centre of mass \[m\].
    pub pos: Vec<Vec3>,
    /// Orientation: body (principal) frame → space.
    pub quat: Vec<Quat>,
    /// Velocity of the centre of mass \[m/s\].
    pub vel: Vec<Vec3>,
    /// Angular velocity in space \[rad/s\].
    pub omega: Vec<Vec3>,
    /// Angular momentum in the principal frame \[kg m²/s\] (the integrated variable of anisotropic bodies).
    pub angmom: Vec<Vec3>,
    /// 1/M \[1/kg\].
    pub inv_mass: Vec<f64>,
    /// Principal inverse moments of inertia \[1/(kg m²)\].
    pub inv_inertia: Vec<Vec3>,
    /// For an isotropic body, k² = I/(0.4 M) \[m²\] (for one sphere r² itself), used as 1/I = 2.5/(M k²)
    /// exactly as for a free sphere; 0 for an anisotropic body.
    pub k2: Vec<f64>,
    /// Particle id of the first member.
    pub first_id: Vec<u32>,
    /// CSR offsets of the members (length = bodies + 1).
    pub member_start: Vec<u32>,
    /// Member centres in the principal frame, relative to the centre of mass \[m\].
    pub offset: Vec<Vec3>,
    /// Member centres relative to the centre of mass in space, q r \[m\] (kept current by the drift).
    pub arm: Vec<Vec3>,
    /// Particle index of each member (refreshed after every change of the particle order).
    #[serde(skip)]
    pub member_index: Vec<u32>,
    /// Total force of the last evaluation, gravity included \[N\].
    pub force: Vec<Vec3>,
    /// Total torque about the centre of mass of the last evaluation \[N m\].
    pub torque: Vec<Vec3>,
    next_id: u32,
}

/// One body's whole state ([`Bodies::record`]): what travels when the body changes rank.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct BodyRecord {
    pub id: u32,
    pub template: u32,
    pub pos: Vec3,
    pub quat: Quat,
    pub vel: Vec3,
    pub omega: Vec3,
    pub angmom: Vec3,
    pub inv_mass: f64,
    pub inv_inertia: Vec3,
    pub k2: f64,
    pub first_id: u32,
    pub offset: Vec<Vec3>,
    pub arm: Vec<Vec3>,
    pub force: Vec3,
    pub torque: Vec3,
}

/// A new body to add: where and how it moves (the shape and mass come from a template).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewBody {
    /// Centre of mass \[m\].
    pub pos: Vec3,
    /// Orientation of the template's principal frame.
    pub quat: Quat,
    /// Velocity \[m/s\].
    pub vel: Vec3,
    /// Angular velocity \[rad/s\].
    pub omega: Vec3,
}

impl NewBody {
    /// A body at rest at `pos` with orientation `quat`.
    pub fn at(pos: Vec3, quat: Quat) -> Self {
        NewBody { pos, quat, vel: Vec3::ZERO, omega: Vec3::ZERO }
    }
}

impl Bodies {
    pub fn len(&self) -> usize {
        self.id.len()
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }

    /// The id the next body will get.
    pub fn next_id(&self) -> u32 {
        self.next_id
    }

    /// Members of body `b` (range into the flattened member arrays).
    #[inline]
    pub fn members(&self, b: usize) -> std::ops::Range<usize> {
        self.member_start[b] as usize..self.member_start[b + 1] as usize
    }

    /// Mass of body `b` \[kg\].
    pub fn mass(&self, b: usize) -> f64 {
        1.0 / self.inv_mass[b]
    }

    /// Principal moments of inertia of body `b` \[kg m²\].
    pub fn inertia(&self, b: usize) -> Vec3 {
        self.inv_inertia[b].recip()
    }

    /// Space-frame angular momentum of body `b` \[kg m²/s\].
    pub fn angular_momentum(&self, b: usize) -> Vec3 {
        if self.k2[b] > 0.0 {
            self.omega[b] / self.inv_inertia[b].x
        } else {
            self.quat[b] * self.angmom[b]
        }
    }

    /// Rotational kinetic energy of body `b` \[J\].
    pub fn rotational_energy(&self, b: usize) -> f64 {
        if self.k2[b] > 0.0 {
            0.5 * self.omega[b].length_squared() / self.inv_inertia[b].x
        } else {
            let pi = self.angmom[b];
            0.5 * pi.dot(pi * self.inv_inertia[b])
        }
    }

    /// Appends a body of mass `mass` \[kg\], principal moments `inertia` \[kg m²\], member offsets
    /// `offsets` (principal frame, from the centre of mass) whose members get the particle ids
    /// `first_id ..`; `k2` > 0 marks an isotropic body (see the field). Returns the body index.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn push(
        &mut self,
        template: u32,
        b: NewBody,
        mass: f64,
        inertia: Vec3,
        k2: f64,
        offsets: &[Vec3],
        first_id: u32,
    ) -> usize {
        if self.member_start.is_empty() {
            self.member_start.push(0);
        }
        let inv_i = inertia.recip();
        let q = b.quat.normalize();
        self.id.push(self.next_id);
        self.next_id += 1;
        self.template.push(template);
        self.pos.push(b.pos);
        self.quat.push(q);
        self.vel.push(b.vel);
        self.omega.push(b.omega);
        // π = I (qᵀ ω q).
        self.angmom.push(inertia * (q.conjugate() * b.omega));
        self.inv_mass.push(1.0 / mass);
        self.inv_inertia.push(inv_i);
        self.k2.push(k2);
        self.first_id.push(first_id);
        self.offset.extend_from_slice(offsets);
        self.arm.extend(offsets.iter().map(|&r| q * r));
        self.member_index.extend(std::iter::repeat_n(u32::MAX, offsets.len()));
        self.member_start.push(self.offset.len() as u32);
        self.force.push(Vec3::ZERO);
        self.torque.push(Vec3::ZERO);
        self.len() - 1
    }

    /// Counts a body that another rank adds (a run split over ranks gives every body the id it has on one
    /// rank); returns that id.
    pub(crate) fn skip_id(&mut self) -> u32 {
        self.next_id += 1;
        self.next_id - 1
    }

    /// Makes the next new body's id at least `next_id` (a joined state continues the numbering of its
    /// parts).
    pub(crate) fn skip_to(&mut self, next_id: u32) {
        self.next_id = self.next_id.max(next_id);
    }

    /// Largest distance of a member centre from its body's centre of mass \[m\] (0 without bodies): how
    /// far a member may stand outside the box of the rank that owns its body.
    pub fn largest_arm(&self) -> f64 {
        self.offset.iter().map(|o| o.length()).fold(0.0, f64::max)
    }

    /// The whole state of body `b`, to move it to another rank or into a joined state.
    pub(crate) fn record(&self, b: usize) -> BodyRecord {
        let r = self.members(b);
        BodyRecord {
            id: self.id[b],
            template: self.template[b],
            pos: self.pos[b],
            quat: self.quat[b],
            vel: self.vel[b],
            omega: self.omega[b],
            angmom: self.angmom[b],
            inv_mass: self.inv_mass[b],
            inv_inertia: self.inv_inertia[b],
            k2: self.k2[b],
            first_id: self.first_id[b],
            offset: self.offset[r.clone()].to_vec(),
            arm: self.arm[r].to_vec(),
            force: self.force[b],
            torque: self.torque[b],
        }
    }

    /// Appends the body `r` exactly as it was recorded (its members' particle indices unknown until
    /// [`crate::Simulation`] refreshes them); returns its index. The next new body's id stays above it.
    pub(crate) fn push_record(&mut self, r: BodyRecord) -> usize {
        if self.member_start.is_empty() {
            self.member_start.push(0);
        }
        self.next_id = self.next_id.max(r.id + 1);
        self.id.push(r.id);
        self.template.push(r.template);
        self.pos.push(r.pos);
        self.quat.push(r.quat);
        self.vel.push(r.vel);
        self.omega.push(r.omega);
        self.angmom.push(r.angmom);
        self.inv_mass.push(r.inv_mass);
        self.inv_inertia.push(r.inv_inertia);
        self.k2.push(r.k2);
        self.first_id.push(r.first_id);
        self.member_index.extend(std::iter::repeat_n(u32::MAX, r.offset.len()));
        self.offset.extend(r.offset);
        self.arm.extend(r.arm);
        self.member_start.push(self.offset.len() as u32);
        self.force.push(r.force);
        self.torque.push(r.torque);
        self.len() - 1
    }

    /// Keeps the bodies for which `keep[b]` is true; returns the map old index → new index (`NO_BODY` for
    /// removed bodies).
    pub(crate) fn retain(&mut self, keep: &[bool]) -> Vec<u32> {
        let mut map = vec![NO_BODY; self.len()];
        let mut next = 0u32;
        for (b, &k) in keep.iter().enumerate() {
            if k {
                map[b] = next;
                next += 1;
            }
        }
        let old = std::mem::take(self);
        self.next_id = old.next_id;
        self.member_start.push(0);
        for (b, _) in keep.iter().enumerate().filter(|k| *k.1) {
            self.id.push(old.id[b]);
            self.template.push(old.template[b]);
            self.pos.push(old.pos[b]);
            self.quat.push(old.quat[b]);
            self.vel.push(old.vel[b]);
            self.omega.push(old.omega[b]);
            self.angmom.push(old.angmom[b]);
            self.inv_mass.push(old.inv_mass[b]);
            self.inv_inertia.push(old.inv_inertia[b]);
            self.k2.push(old.k2[b]);
            self.first_id.push(old.first_id[b]);
            let r = old.members(b);
            self.offset.extend_from_slice(&old.offset[r.clone()]);
            self.arm.extend_from_slice(&old.arm[r.clone()]);
            self.member_index.extend_from_slice(&old.member_index[r]);
            self.member_start.push(self.offset.len() as u32);
            self.force.push(old.force[b]);
            self.torque.push(old.torque[b]);
        }
        map
    }

    /// Bytes of body state per member sphere (for memory reports).
    pub fn bytes_per_member(&self) -> f64 {
        if self.offset.is_empty() {
            return 0.0;
        }
        let per_body = 4 + 4 + 24 + 32 + 24 + 24 + 24 + 8 + 24 + 8 + 4 + 4 + 24 + 24;
        let per_member = 24 + 24 + 4;
        (self.len() * per_body) as f64 / self.offset.len() as f64 + per_member as f64
    }
}
