//! Rigid bodies in the simulation: adding clumps, reducing member forces onto bodies, integrating the
//! bodies and placing their members (see [`crate::clump`] for the scheme).
//!
//! Every loop here runs only when the simulation has bodies; a run of free spheres never enters it.
//! Parallel loops are over bodies (each sums its own members in member order) or over particles (each
//! reads its own body), so results do not depend on the thread count.

use super::Simulation;
use crate::clump::rotation::{free_rotation, omega_space, spin_isotropic};
use crate::clump::{ClumpTemplate, NewBody, NO_BODY};
use crate::contact::ContactLaw;
use crate::error::DemError;
use crate::particles::NewParticle;
use rayon::prelude::*;
use spatter_core::Vec3;

/// Bodies per parallel task.
const BODY_CHUNK: usize = 512;
/// Particles per parallel task of the member pass.
const PARTICLE_CHUNK: usize = 4096;

impl<L: ContactLaw> Simulation<L> {
    /// Registers a clump template; returns its index for [`Simulation::add_clump`].
    pub fn add_template(&mut self, t: ClumpTemplate) -> usize {
        self.templates.push(t);
        self.templates.len() - 1
    }

    /// The registered clump templates.
    pub fn templates(&self) -> &[ClumpTemplate] {
        &self.templates
    }

    /// The rigid bodies.
    pub fn bodies(&self) -> &crate::clump::Bodies {
        &self.st.bodies
    }

    /// Adds a rigid body of template `template` and material `material` (its density gives the mass,
    /// see [`ClumpTemplate::body_mass`]); the members become particles with consecutive ids. Returns the
    /// body id. Like [`Simulation::add_particle`], no overlap check is made here.
    pub fn add_clump(&mut self, template: usize, material: u16, b: NewBody) -> Result<u32, DemError> {
        let t = self.templates.get(template).ok_or_else(|| DemError::Config {
            key: "template".into(),
            message: format!("no clump template with index {template} ({} registered)", self.templates.len()),
        })?;
        let mat = self.materials.get(material as usize).ok_or_else(|| DemError::Config {
            key: "material".into(),
            message: format!("no material with index {material}"),
        })?;
        let (mass, inertia, k2) = t.body_mass(mat.density);
        if !(mass > 0.0 && mass.is_finite() && inertia.min_element() > 0.0) {
            return Err(DemError::Config {
                key: "template".into(),
                message: format!("template `{}` gives a body of mass {mass} kg, inertia {inertia:?}", t.name),
            });
        }
        let offsets: Vec<Vec3> = t.spheres.iter().map(|s| s.0).collect();
        let radii: Vec<f64> = t.spheres.iter().map(|s| s.1).collect();
        let vol_sum: f64 = radii.iter().map(|&r| r * r * r).sum();
        let contact_mass = |r: f64| match self.settings.clump_contact_mass {
            super::ClumpContactMass::Body => mass,
            super::ClumpContactMass::MemberShare => mass * (r * r * r / vol_sum),
        };
        let first_id = self.particles.next_id();
        let bodies = &mut self.st.bodies;
        let bi = bodies.push(template as u32, b, mass, inertia, k2, &offsets, first_id);
        let (q, x, v, w) = (bodies.quat[bi], bodies.pos[bi], bodies.vel[bi], bodies.omega[bi]);
        for (k, &r) in radii.iter().enumerate() {
            let arm = bodies.arm[bodies.member_start[bi] as usize + k];
            let p = NewParticle {
                pos: x + arm,
                vel: member_velocity(v, w, arm),
                omega: w,
                radius: r,
                material,
                frozen: false,
            };
            self.particles.push_member(p, 1.0 / contact_mass(r), bi as u32);
            self.st.r_max = self.st.r_max.max(r);
        }
        let _ = q;
        let e = &mut self.st.energy;
        e.injected_kinetic += 0.5 * mass * v.length_squared();
        e.injected_rotational += bodies.rotational_energy(bi);
        e.injected_moment += mass * x;
        bodies.force[bi] = mass * self.gravity;
        bodies.torque[bi] = Vec3::ZERO;
        self.st.needs_rebuild = true;
        self.st.forces_valid = false;
        self.refresh_members();
        Ok(bodies_id(&self.st.bodies, bi))
    }

    /// Recomputes each member's particle index (after any change of the particle order).
    pub(crate) fn refresh_members(&mut self) {
        let bodies = &mut self.st.bodies;
        if bodies.is_empty() {
            return;
        }
        let p = &self.particles;
        bodies.member_index.clear();
        bodies.member_index.resize(bodies.offset.len(), u32::MAX);
        for k in 0..p.len() {
            let b = p.body[k];
            if b != NO_BODY {
                let b = b as usize;
                let slot = bodies.member_start[b] + (p.id[k] - bodies.first_id[b]);
                bodies.member_index[slot as usize] = k as u32;
            }
        }
    }

    /// Sets the members' forces and torques to their persistent external parts only (the body carries
    /// gravity): called after a pass that gave every particle its weight.
    pub(crate) fn clear_member_base_forces(&mut self) {
        let p = &mut self.particles;
        let has_ext = !p.ext_force.is_empty();
        for k in 0..p.len() {
            if p.body[k] != NO_BODY {
                p.force[k] = if has_ext { p.ext_force[k] } else { Vec3::ZERO };
                p.torque[k] = if has_ext { p.ext_torque[k] } else { Vec3::ZERO };
            }
        }
    }

    /// Sums the member forces and torques of the last evaluation onto their bodies, adds gravity.
    pub(crate) fn reduce_body_forces(&mut self) {
        let g = self.gravity;
        let p = &self.particles;
        let b = &mut self.st.bodies;
        let (start, idx, arm, inv_m) = (&b.member_start, &b.member_index, &b.arm, &b.inv_mass);
        b.force.par_iter_mut().zip(b.torque.par_iter_mut()).enumerate().with_min_len(BODY_CHUNK).for_each(
            |(bi, (f, t))| {
                let (s0, s1) = (start[bi] as usize, start[bi + 1] as usize);
                let k0 = idx[s0] as usize;
                let mut fs = p.force[k0];
                let mut ts = arm[s0].cross(p.force[k0]) + p.torque[k0];
                for s in s0 + 1..s1 {
                    let k = idx[s] as usize;
                    fs += p.force[k];
                    ts += arm[s].cross(p.force[k]) + p.torque[k];
                }
                if g != Vec3::ZERO {
                    fs += g / inv_m[bi];
                }
                *f = fs;
                *t = ts;
            },
        );
    }

    /// Kicks the bodies by `frac`·Δt (force and torque of the last evaluation); with `drift`, moves and
    /// turns them by Δt. Then places the members (positions only with `drift`), and with `reset` sets the
    /// members' forces to their persistent external parts. Returns the largest member speed.
    pub(crate) fn bodies_kick(&mut self, frac: f64, drift: bool, reset: bool) -> f64 {
        if self.st.bodies.is_empty() {
            return 0.0;
        }
        let h = frac * self.dt;
        let dt = self.dt;
        let b = &mut self.st.bodies;
        {
            let (inv_m, inv_i, k2, force, torque) = (&b.inv_mass, &b.inv_inertia, &b.k2, &b.force, &b.torque);
            b.pos
                .par_iter_mut()
                .zip(b.vel.par_iter_mut())
                .zip(b.quat.par_iter_mut())
                .zip(b.omega.par_iter_mut().zip(b.angmom.par_iter_mut()))
                .enumerate()
                .with_min_len(BODY_CHUNK)
                .for_each(|(bi, (((x, v), q), (w, pi)))| {
                    // Written like the free-sphere kick, so a one-sphere body moves exactly like a sphere.
                    let hm = h * inv_m[bi];
                    *v += hm * force[bi];
                    if k2[bi] > 0.0 {
                        // Isotropic: the gyroscopic term ω × Iω vanishes, I ω̇ = T.
                        *w += (2.5 * hm / k2[bi]) * torque[bi];
                        if drift {
                            spin_isotropic(q, *w, dt);
                        }
                    } else {
                        *pi += h * (q.conjugate() * torque[bi]);
                        if drift {
                            free_rotation(q, pi, inv_i[bi], dt);
                        }
                        *w = omega_space(*q, *pi, inv_i[bi]);
                    }
                    if drift {
                        *x += *v * dt;
                    }
                });
        }
        if drift {
            // Member arms in space, q rᵢ (each member reads its own body).
            let (start, quat) = (&b.member_start, &b.quat);
            let nb = b.len();
            let offset = &b.offset;
            b.arm.par_chunks_mut(PARTICLE_CHUNK).enumerate().for_each(|(c, arms)| {
                let s0 = c * PARTICLE_CHUNK;
                // The body of slot s0 (binary search in the CSR offsets), then walk forward.
                let mut bi = start.partition_point(|&x| x as usize <= s0).saturating_sub(1).min(nb - 1);
                for (k, a) in arms.iter_mut().enumerate() {
                    let s = s0 + k;
                    while start[bi + 1] as usize <= s {
                        bi += 1;
                    }
                    *a = if offset[s] == Vec3::ZERO { Vec3::ZERO } else { quat[bi] * offset[s] };
                }
            });
        }
        // Members from their bodies (each particle reads its own body).
        let b = &self.st.bodies;
        let p = &mut self.particles;
        let has_ext = !p.ext_force.is_empty();
        let (ids, body, ext_f, ext_t) = (&p.id, &p.body, &p.ext_force, &p.ext_torque);
        p.pos
            .par_chunks_mut(PARTICLE_CHUNK)
            .zip(p.vel.par_chunks_mut(PARTICLE_CHUNK))
            .zip(p.omega.par_chunks_mut(PARTICLE_CHUNK))
            .zip(p.force.par_chunks_mut(PARTICLE_CHUNK).zip(p.torque.par_chunks_mut(PARTICLE_CHUNK)))
            .enumerate()
            .map(|(c, (((xs, vs), ws), (fs, ts)))| {
                let mut v2max: f64 = 0.0;
                for k in 0..xs.len() {
                    let i = c * PARTICLE_CHUNK + k;
                    let bi = body[i];
                    if bi == NO_BODY {
                        continue;
                    }
                    let bi = bi as usize;
                    let slot = (b.member_start[bi] + (ids[i] - b.first_id[bi])) as usize;
                    let arm = b.arm[slot];
                    if drift {
                        xs[k] = b.pos[bi] + arm;
                    }
                    vs[k] = member_velocity(b.vel[bi], b.omega[bi], arm);
                    ws[k] = b.omega[bi];
                    v2max = v2max.max(vs[k].length_squared());
                    if reset {
                        fs[k] = if has_ext { ext_f[i] } else { Vec3::ZERO };
                        ts[k] = if has_ext { ext_t[i] } else { Vec3::ZERO };
                    }
                }
                v2max
            })
            .reduce(|| 0.0, f64::max)
            .sqrt()
    }

    /// Removes the bodies whose centre of mass left the domain (with their members) and books the energy
    /// they take out; called by the rebuild before particles are removed. Returns the number of removed
    /// member spheres.
    pub(crate) fn remove_bodies_outside(&mut self, dom: &spatter_core::Aabb) -> usize {
        let b = &self.st.bodies;
        if b.is_empty() {
            return 0;
        }
        let keep: Vec<bool> = b.pos.iter().map(|&x| dom.contains(x)).collect();
        if keep.iter().all(|&k| k) {
            return 0;
        }
        let back = if self.half_step_velocities { 0.5 * self.dt } else { 0.0 };
        let e = &mut self.st.energy;
        for (bi, &k) in keep.iter().enumerate() {
            if !k {
                let m = b.mass(bi);
                e.injected_kinetic -= 0.5 * m * b.vel[bi].length_squared();
                e.injected_rotational -= b.rotational_energy(bi);
                e.injected_moment -= m * (b.pos[bi] - back * b.vel[bi]);
            }
        }
        let map = self.st.bodies.retain(&keep);
        let p = &mut self.particles;
        let n0 = p.len();
        let body = p.body.clone();
        p.retain(|i| body[i] == NO_BODY || map[body[i] as usize] != NO_BODY);
        for x in p.body.iter_mut() {
            if *x != NO_BODY {
                *x = map[*x as usize];
            }
        }
        n0 - p.len()
    }
}

/// Velocity of a member at arm `arm` from the centre of mass: V + ω × arm (exactly V at zero arm).
#[inline]
fn member_velocity(v: Vec3, w: Vec3, arm: Vec3) -> Vec3 {
    if arm == Vec3::ZERO {
        v
    } else {
        v + w.cross(arm)
    }
}

fn bodies_id(b: &crate::clump::Bodies, bi: usize) -> u32 {
    b.id[bi]
}
