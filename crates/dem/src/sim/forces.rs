//! Force evaluation: gravity and external forces, wall contacts, pair contacts.

use super::{ParticleView, Simulation};
use crate::contact::{ContactInput, ContactLaw};
use crate::error::DemError;
use crate::par::{run_groups, Group};
use crate::walls::mesh::HitBuffer;
use crate::walls::{WallHit, WallKinematics, WallShape};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use spatter_core::Vec3;

/// What one wall-candidate slot did in the last evaluation. `active` is also the slot's contact flag: a
/// contact *forms* (counts as an impact in the mesh records) in an evaluation where its slot was not
/// active in the previous one, whatever the contact law keeps as state (a stateless law's state always
/// equals its default). Carried over list rebuilds and seams with the state, and checkpointed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SlotOut {
    /// In contact in the last evaluation.
    pub active: bool,
    /// The contact formed in the last evaluation (the slot was not active in the one before).
    pub formed: bool,
    /// Signed normal force F_n \[N\] (the tangential magnitude is √(|F|² − F_n²)).
    pub normal_force: f64,
    /// Normal approach speed −v_rel·n \[m/s\].
    pub approach_speed: f64,
    /// Tangential speed of the particle centre relative to the wall, set in the evaluation in which the
    /// contact formed (0 otherwise) \[m/s\].
    #[serde(default)]
    pub tangential_speed: f64,
    /// Contact force on the particle \[N\] (the wall gets the opposite).
    pub force: Vec3,
}

/// Per-task reduction of one evaluation.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Acc {
    pub dissipated: f64,
    pub elastic: f64,
    pub wall_power: f64,
    pub pair_contacts: u64,
    pub wall_contacts: u64,
    pub max_ratio: f64,
    /// Ids of the pair with the largest overlap ratio (`u32::MAX` as second id for a wall).
    pub worst: (u32, u32),
}

impl Acc {
    pub(super) fn combine(a: Acc, b: Acc) -> Acc {
        let (max_ratio, worst) =
            if b.max_ratio > a.max_ratio { (b.max_ratio, b.worst) } else { (a.max_ratio, a.worst) };
        Acc {
            dissipated: a.dissipated + b.dissipated,
            elastic: a.elastic + b.elastic,
            wall_power: a.wall_power + b.wall_power,
            pair_contacts: a.pair_contacts + b.pair_contacts,
            wall_contacts: a.wall_contacts + b.wall_contacts,
            max_ratio,
            worst,
        }
    }

    #[inline]
    pub(super) fn note_overlap(&mut self, ratio: f64, a: u32, b: u32) {
        if ratio > self.max_ratio || ratio.is_nan() {
            self.max_ratio = if ratio.is_nan() { f64::INFINITY } else { ratio };
            self.worst = (a, b);
        }
    }
}

impl<L: ContactLaw> Simulation<L> {
    /// Computes forces and torques at the current state, updates contact states, energy accounts and mesh
    /// records.
    pub(crate) fn compute_forces(&mut self) {
        let t = self.st.time;
        let dt = self.dt;
        // The time over which incremental contact springs advance (a stage of a multi-stage scheme
        // advances them from the step start to the stage time).
        let cdt = self.trial_dt.unwrap_or(dt);
        self.scratch.kin.clear();
        self.scratch.kin.extend(self.walls.iter().map(|w| WallKinematics::of(&w.motion, t)));
        let g = self.gravity;
        let n = self.particles.len();

        // Gravity and persistent external forces (already set by the drift pass under velocity Verlet).
        if !std::mem::take(&mut self.base_forces_ready) {
            let p = &mut self.particles;
            let has_ext = !p.ext_force.is_empty();
            let (ext_f, ext_t) = (&p.ext_force, &p.ext_torque);
            const CHUNK: usize = 4096;
            let inv_mass = &p.inv_mass;
            p.force.par_chunks_mut(CHUNK).zip(p.torque.par_chunks_mut(CHUNK)).enumerate().for_each(
                |(c, (fs, ts))| {
                    for (k, (f, tq)) in fs.iter_mut().zip(ts.iter_mut()).enumerate() {
                        let i = c * CHUNK + k;
                        *f = if inv_mass[i] > 0.0 { g / inv_mass[i] } else { Vec3::ZERO };
                        *tq = Vec3::ZERO;
                        if has_ext {
                            *f += ext_f[i];
                            *tq += ext_t[i];
                        }
                    }
                },
            );
            if !self.st.bodies.is_empty() {
                self.clear_member_base_forces();
            }
        }
        // External work uses the velocities at evaluation time (half-step velocities under Verlet).
        let mut ext_power = 0.0;
        if !self.particles.ext_force.is_empty() {
            let p = &self.particles;
            ext_power += (0..n)
                .filter(|&i| p.inv_mass[i] > 0.0)
                .map(|i| p.ext_force[i].dot(p.vel[i]) + p.ext_torque[i].dot(p.omega[i]))
                .sum::<f64>();
        }
        if let Some(ext) = self.external.as_mut() {
            let p = &mut self.particles;
            let (bf, bt) = (&mut self.scratch.ext_force, &mut self.scratch.ext_torque);
            bf.clear();
            bf.resize(n, Vec3::ZERO);
            bt.clear();
            bt.resize(n, Vec3::ZERO);
            let view = ParticleView {
                id: &p.id,
                material: &p.material,
                pos: &p.pos,
                vel: &p.vel,
                omega: &p.omega,
                radius: &p.radius,
                inv_mass: &p.inv_mass,
            };
            ext.add(t, &view, bf, bt);
            for i in 0..n {
                if p.inv_mass[i] > 0.0 {
                    p.force[i] += bf[i];
                    p.torque[i] += bt[i];
                    ext_power += bf[i].dot(p.vel[i]) + bt[i].dot(p.omega[i]);
                }
            }
        }

        // Without energies wanted in this step the law skips its bookkeeping (forces are identical).
        let booking = self.booking_energy();
        let quiet;
        let law = if booking {
            &self.law
        } else {
            quiet = self.law.without_energy();
            &quiet
        };
        let params = &self.params;
        let walls = &self.walls;
        let kin = &self.scratch.kin;
        let crate::particles::Particles {
            id,
            material,
            pos,
            vel,
            omega,
            radius,
            inv_mass,
            force,
            torque,
            ..
        } = &mut self.particles;
        let (id, material, pos, vel, omega, radius, inv_mass) =
            (&*id, &*material, &*pos, &*vel, &*omega, &*radius, &*inv_mass);
        let default = L::State::default();

        // Wall contacts: each particle owns its slots.
        let wl = &mut self.st.wall_list;
        let (w_start, w_wall, w_tri) = (&wl.start, &wl.wall, &wl.tri);
        let wall_work = |g: &Group,
                         pbase: usize,
                         (f, tq): (&mut [Vec3], &mut [Vec3]),
                         sbase: usize,
                         (states, outs): (&mut [L::State], &mut [SlotOut])| {
            let mut acc = Acc::default();
            let mut raw = HitBuffer::default();
            let mut hits = HitBuffer::default();
            for i in g.work_begin as usize..g.work_end as usize {
                let (k0, k1) = (w_start[i] as usize, w_start[i + 1] as usize);
                if k0 == k1 {
                    continue;
                }
                let pi = WallParticle {
                    id: id[i],
                    r: radius[i],
                    vel: vel[i],
                    omega: omega[i],
                    inv_mass: inv_mass[i],
                    dt: cdt,
                };
                let (fi, ti) = (&mut f[i - pbase], &mut tq[i - pbase]);
                let mut k = k0;
                while k < k1 {
                    let w = w_wall[k] as usize;
                    let mut e = k + 1;
                    while e < k1 && w_wall[e] as usize == w {
                        e += 1;
                    }
                    let wall = &walls[w];
                    let kw = &kin[w];
                    let pp = params.get(material[i] as usize, wall.material as usize);
                    let reach = pi.r + law.range(pp, pi.r);
                    let (states, outs) = (&mut states[k - sbase..e - sbase], &mut outs[k - sbase..e - sbase]);
                    match &wall.shape {
                        WallShape::Mesh(m) => {
                            let x_ref = kw.to_reference(pos[i]);
                            m.resolve(x_ref, reach, &w_tri[k..e], &mut raw, &mut hits);
                            let hs = hits.as_slice();
                            let accepted = |s: usize| hs.iter().any(|h| h.slot == s);
                            // A contact that moved onto a neighbouring triangle inherits the state and
                            // the activity (it is not a new impact) of the nearest contact of this mesh
                            // that ended.
                            for h in hs {
                                let s = h.slot;
                                if outs[s].active {
                                    continue;
                                }
                                let mut best: Option<(f64, usize)> = None;
                                for s2 in 0..e - k {
                                    if accepted(s2) || !outs[s2].active {
                                        continue;
                                    }
                                    let [a, b, c] = m.mesh.corners(w_tri[k + s2] as usize);
                                    let (q, _) =
                                        spatter_core::mesh::closest_point_on_triangle(h.point, a, b, c);
                                    let d = (q - h.point).length_squared();
                                    if best.is_none_or(|(bd, _)| d < bd) {
                                        best = Some((d, s2));
                                    }
                                }
                                if let Some((_, s2)) = best {
                                    states[s] = states[s2];
                                    states[s2] = default;
                                    outs[s] = outs[s2];
                                    outs[s2] = SlotOut::default();
                                }
                            }
                            for s in 0..e - k {
                                if !accepted(s) {
                                    states[s] = default;
                                    outs[s] = SlotOut::default();
                                }
                            }
                            for h in hs {
                                let hit = kw.hit_to_world(h.point, h.normal, h.distance);
                                let (state, out) = (&mut states[h.slot], &mut outs[h.slot]);
                                if kw.fixed {
                                    wall_contact::<L, false>(
                                        law,
                                        pp,
                                        kw,
                                        hit,
                                        &pi,
                                        state,
                                        out,
                                        (fi, ti),
                                        &mut acc,
                                    );
                                } else {
                                    wall_contact::<L, true>(
                                        law,
                                        pp,
                                        kw,
                                        hit,
                                        &pi,
                                        state,
                                        out,
                                        (fi, ti),
                                        &mut acc,
                                    );
                                }
                            }
                        }
                        _ if kw.fixed => {
                            // A wall that never moves (the common case): no transforms, no wall velocity.
                            for (state, out) in states.iter_mut().zip(outs.iter_mut()) {
                                match wall.analytic_hit(pos[i], reach) {
                                    Some((point, normal, distance)) => {
                                        let hit = WallHit { point, normal, distance };
                                        wall_contact::<L, false>(
                                            law,
                                            pp,
                                            kw,
                                            hit,
                                            &pi,
                                            state,
                                            out,
                                            (fi, ti),
                                            &mut acc,
                                        )
                                    }
                                    None => {
                                        *state = default;
                                        *out = SlotOut::default();
                                    }
                                }
                            }
                        }
                        _ => {
                            let x_ref = kw.to_reference(pos[i]);
                            for (state, out) in states.iter_mut().zip(outs.iter_mut()) {
                                match wall.analytic_hit(x_ref, reach) {
                                    Some((q, nrm, d)) => {
                                        let hit = kw.hit_to_world(q, nrm, d);
                                        wall_contact::<L, true>(
                                            law,
                                            pp,
                                            kw,
                                            hit,
                                            &pi,
                                            state,
                                            out,
                                            (fi, ti),
                                            &mut acc,
                                        )
                                    }
                                    None => {
                                        *state = default;
                                        *out = SlotOut::default();
                                    }
                                }
                            }
                        }
                    }
                    k = e;
                }
            }
            acc
        };
        let acc_w = run_groups(
            &wl.blocks,
            0,
            (&mut force[..], &mut torque[..]),
            0,
            (&mut wl.state[..], &mut wl.out[..]),
            &wl.start,
            &wall_work,
            &Acc::combine,
        )
        .unwrap_or_default();

        // Pair contacts over the half list, in two colouring phases.
        let list = &mut self.st.list;
        let (l_start, l_nbr) = (&list.start, &list.nbr);
        let range_quick = {
            let r_max = self.st.r_max;
            let nmat = params.types();
            let mut m: f64 = 0.0;
            for a in 0..nmat {
                for b in 0..nmat {
                    m = m.max(law.range(params.get(a, b), 0.5 * r_max));
                }
            }
            m
        };
        // Two stages: first the geometry of the touching pairs among up to BUF neighbours of particle i
        // (short, independent iterations whose square roots and divisions overlap in the CPU), gathered for
        // several particles into a buffer of up to CAP candidates; then the contact law for each, in one call
        // per buffer.
        const BUF: usize = 16;
        const CAP: usize = 4 * BUF;
        const OWNERS: usize = 16;
        let pair_work = |g: &Group,
                         pbase: usize,
                         (f, tq): (&mut [Vec3], &mut [Vec3]),
                         sbase: usize,
                         states: &mut [L::State]| {
            // Re-sliced to one length: one bounds check per index covers every particle array.
            let np = pos.len();
            let (id, material, vel, omega, radius, inv_mass) =
                (&id[..np], &material[..np], &vel[..np], &omega[..np], &radius[..np], &inv_mass[..np]);
            let tq = &mut tq[..f.len()];
            let mut stage2 = PairStage {
                law,
                id,
                omega,
                inv_mass,
                dt: cdt,
                f,
                tq,
                pbase,
                acc: Acc::default(),
                fi: Vec3::ZERO,
                ti: Vec3::ZERO,
            };
            // A group has particles, so the pair table has at least one entry to fill the buffer with.
            let mut buf = [Candidate {
                slot: 0,
                j: 0,
                sign: 0.0,
                rj: 0.0,
                params: params.at(0),
                normal: Vec3::ZERO,
                overlap: 0.0,
                r_eff: 0.0,
                m_eff: 0.0,
                v_rel: Vec3::ZERO,
            }; CAP];
            let mut owners = [Owner { i: 0, ri: 0.0, ii: 0.0, end: 0, last: false }; OWNERS];
            let (mut nbuf, mut nown) = (0, 0);
            // i's neighbours are consecutive: carve them off the front of the rest.
            let (wb, we) = (g.work_begin as usize, g.work_end as usize);
            let starts = &l_start[wb..we + 1];
            let mut nbr_rest = &l_nbr[starts[0] as usize..];
            for (i, (&k0, &k1)) in (wb..we).zip(starts.iter().zip(&starts[1..])) {
                let len = (k1 - k0) as usize;
                let (nbrs, nr) = nbr_rest.split_at(len);
                nbr_rest = nr;
                // i's contact states, indexed from the group's first slot.
                let base = k0 as usize - sbase;
                let (xi, ri, ii) = (pos[i], radius[i], inv_mass[i]);
                // Loop invariants of i's geometry (the products are the same as inside the loop).
                let (vi, wri) = (vel[i], ri * omega[i]);
                let row = params.row(material[i] as usize);
                let mut c0 = 0;
                loop {
                    let c1 = nbrs.len().min(c0 + BUF);
                    if nbuf + (c1 - c0) > CAP || nown == OWNERS {
                        stage2.contacts(&buf[..nbuf], &owners[..nown], states);
                        (nbuf, nown) = (0, 0);
                    }
                    let slots = &mut states[base + c0..base + c1];
                    for (slot, (&e, state)) in (c0..c1).zip(nbrs[c0..c1].iter().zip(slots.iter_mut())) {
                        // The cheapest test first, with i and j as they come.
                        let j = (e & super::neighbors::NBR_MASK) as usize;
                        let d = xi - pos[j];
                        let rj = radius[j];
                        let rs = ri + rj;
                        let reach = rs + range_quick;
                        let dist2 = d.length_squared();
                        if dist2 >= reach * reach {
                            // A store is cheaper than comparing the state with the default.
                            *state = default;
                            continue;
                        }
                        // Orientation by id (flagged in the list's top bit); branch-free, the id order is
                        // random. (A table lookup: setting the sign bit from the flag measured 9 more
                        // instructions per particle-step.)
                        let sign = [1.0, -1.0][(e >> 31) as usize];
                        let dist = dist2.sqrt();
                        let n = if dist > 0.0 { d * (1.0 / dist) } else { sign * Vec3::Z };
                        // One division for both R* = ri rj/(ri + rj) and m* = 1/(1/mi + 1/mj).
                        let inv = ii + inv_mass[j];
                        let q = 1.0 / (rs * inv);
                        buf[nbuf] = Candidate {
                            slot: base + slot,
                            j,
                            sign,
                            rj,
                            params: &row[material[j] as usize],
                            normal: sign * n,
                            overlap: rs - dist,
                            r_eff: ri * rj * inv * q,
                            m_eff: rs * q,
                            v_rel: sign * (vi - vel[j] - (wri + rj * omega[j]).cross(n)),
                        };
                        nbuf += 1;
                    }
                    c0 = c1;
                    // Every particle gets an owner record, also without candidates: its force and torque
                    // sums are added in the same order as the partners' (see `PairStage::contacts`).
                    let last = c0 == nbrs.len();
                    owners[nown] = Owner { i, ri, ii, end: nbuf, last };
                    nown += 1;
                    if last {
                        break;
                    }
                }
            }
            stage2.contacts(&buf[..nbuf], &owners[..nown], states);
            stage2.acc
        };
        let mut acc = acc_w;
        for phase in 0..2 {
            let a = run_groups(
                &list.phases[phase],
                0,
                (&mut force[..], &mut torque[..]),
                0,
                &mut list.state[..],
                l_start,
                &pair_work,
                &Acc::combine,
            )
            .unwrap_or_default();
            acc = Acc::combine(acc, a);
        }
        // Contacts with the particles of other ranks (decomposed runs only).
        if let Some(d) = self.decomp.as_mut() {
            let view = ParticleView { id, material, pos, vel, omega, radius, inv_mass };
            let forces = (&mut force[..], &mut torque[..]);
            let a =
                super::decomp::ghost_contacts(law, params, &mut d.ghosts, &view, range_quick, cdt, forces);
            acc = Acc::combine(acc, a);
        }

        if self.trial_dt.is_some() {
            // A trial stage books nothing: the step's first evaluation did.
            self.st.last.pair_contacts = acc.pair_contacts;
            self.st.last.wall_contacts = acc.wall_contacts;
            self.st.last.max_overlap_ratio = acc.max_ratio;
            self.last_worst = acc.worst;
            return;
        }

        // Mesh impact records and wear (sequential: slots of different particles share triangles). The loop
        // runs over the wall slots in order (particle by particle, as the CSR list stores them); the
        // particle owning a slot is looked up only for a slot that records something, so a scene of
        // analytic walls without an event log pays one flag test per slot and nothing per particle.
        let wl = &self.st.wall_list;
        let p = &self.particles;
        let bodies = &self.st.bodies;
        self.impacts.clear();
        let mut i = 0usize;
        for k in 0..wl.out.len() {
            let o = wl.out[k];
            if !o.active {
                continue;
            }
            let w = wl.wall[k] as usize;
            let on_mesh = matches!(self.walls[w].shape, WallShape::Mesh(_));
            let record = self.record_impacts && o.formed;
            if !on_mesh && !record {
                continue;
            }
            // Slots are stored particle by particle, so the owner only moves forward: the first particle
            // at or after `i` whose slot range ends past k.
            i += wl.start[i + 1..].partition_point(|&end| end as usize <= k);
            if record {
                let wall = &self.walls[w];
                let (normal, v_wall) =
                    super::impacts::contact_frame(wall, &self.scratch.kin[w], wl.tri[k], p.pos[i]);
                self.impacts.push(super::WallImpact {
                    particle: p.id[i],
                    body: p.is_member(i).then(|| bodies.id[p.body[i] as usize]),
                    wall: w,
                    triangle: on_mesh.then_some(wl.tri[k]),
                    time: self.st.time,
                    normal,
                    velocity: p.vel[i] - v_wall,
                });
            }
            let wall = &mut self.walls[w];
            let wall_material = wall.material as usize;
            if let WallShape::Mesh(m) = &mut wall.shape {
                let t = wl.tri[k] as usize;
                let r = &mut m.records;
                let ft = (o.force.length_squared() - o.normal_force * o.normal_force).max(0.0).sqrt();
                r.normal_impulse[t] += o.normal_force.abs() * dt;
                r.tangential_impulse[t] += ft * dt;
                if o.formed {
                    let v_n = o.approach_speed.max(0.0);
                    r.impacts[t] += 1;
                    r.impact_speed_sum[t] += o.approach_speed;
                    r.impact_angle_sum[t] += v_n.atan2(o.tangential_speed).to_degrees();
                    if let Some(model) = self.wear.get(p.material[i] as usize, wall_material) {
                        // The impacting mass: the whole body for a clump member.
                        let mass = if p.is_member(i) { bodies.mass(p.body[i] as usize) } else { p.mass(i) };
                        r.eroded_mass[t] += model.eroded_mass(mass, v_n, o.tangential_speed);
                    }
                }
            }
        }

        let e = &mut self.st.energy;
        e.dissipated += acc.dissipated;
        e.wall_work += acc.wall_power * dt;
        e.external_work += ext_power * dt;
        self.st.last = super::LastEvaluation {
            elastic: acc.elastic,
            pair_contacts: acc.pair_contacts,
            wall_contacts: acc.wall_contacts,
            max_overlap_ratio: acc.max_ratio,
            energy_booked: booking,
        };
        self.last_worst = acc.worst;
    }

    /// Total contact force exerted by the particles on wall `w` in the last evaluation \[N\].
    pub fn wall_force(&self, w: usize) -> Vec3 {
        let wl = &self.st.wall_list;
        let mut f = Vec3::ZERO;
        for k in 0..wl.out.len() {
            if wl.out[k].active && wl.wall[k] as usize == w {
                f -= wl.out[k].force;
            }
        }
        f
    }

    /// The blow-up error for an excessive overlap found in the last evaluation.
    pub(crate) fn blow_up_overlap(&self) -> DemError {
        let (a, b) = self.last_worst;
        let r = self.st.last.max_overlap_ratio;
        // Three decimals, or three significant digits in exponent form for a ratio beyond 10⁴ (a particle
        // thrown 1e300 m into a wall printed a 300-digit number).
        let ratio = if r.abs() < 1e4 { format!("{r:.3}") } else { format!("{r:.3e}") };
        let what = if b == u32::MAX {
            match self.deepest_wall(a) {
                Some(name) => format!("overlap with wall `{name}` is {ratio} of its radius"),
                None => format!("overlap with a wall is {ratio} of its radius"),
            }
        } else {
            format!("overlap with particle id {b} is {ratio} of the smaller radius")
        };
        DemError::BlowUp {
            particle: a,
            step: self.st.step,
            time_s: self.st.time,
            what: format!("{what} (limit {})", self.settings.max_overlap_fraction),
            cause: self.likely_cause(true),
        }
    }

    /// Name of the wall that particle `id` overlaps most (diagnostics only).
    fn deepest_wall(&self, id: u32) -> Option<&str> {
        let i = self.particles.index_of(id)?;
        let (x, r) = (self.particles.pos[i], self.particles.radius[i]);
        let t = self.st.time;
        let mut best: Option<(f64, usize)> = None;
        for (w, wall) in self.walls.iter().enumerate() {
            let kin = WallKinematics::of(&wall.motion, t);
            if let Some(d) = wall.surface_distance(&kin, x, r) {
                if best.is_none_or(|(bd, _)| d < bd) {
                    best = Some((d, w));
                }
            }
        }
        best.map(|(_, w)| self.walls[w].name.as_str())
    }

    /// A sentence on what most likely went wrong; `overlap` for an overlap blow-up (the worst contact of
    /// the last evaluation is the culprit), false for a non-finite state.
    pub(crate) fn likely_cause(&self, overlap: bool) -> String {
        let tr = self.rayleigh_time();
        let dt_note = (self.dt > 0.3 * tr).then(|| {
            format!(
                "the time step dt = {:e} s is {:.2} of the Rayleigh time {:e} s; use dt ≤ 0.2 × Rayleigh time",
                self.dt,
                self.dt / tr,
                tr
            )
        });
        // A particle that no force evaluation had seen before this one cannot have been pushed that deep
        // by the time step: it was created overlapping.
        let (a, b) = self.last_worst;
        let new = |id: u32| id != u32::MAX && id >= self.evaluated_ids;
        if overlap && (new(a) || new(b)) {
            let partner = if b == u32::MAX {
                self.deepest_wall(a).map_or("a wall".to_string(), |n| format!("wall `{n}`"))
            } else {
                format!("particle id {}", if new(a) { b } else { a })
            };
            let id = if new(a) { a } else { b };
            let mut s = format!(
                "particle id {id} was created overlapping {partner} (this was its first force evaluation, so \
                 the time step is not the cause); check where particles are added (fill and inject regions \
                 against walls and other particles, lattice spacing, radii)"
            );
            if let Some(d) = dt_note {
                s.push_str(&format!("; separately, {d}"));
            }
            return s;
        }
        if let Some(d) = dt_note {
            d
        } else {
            "an impact too fast or a material too soft for this time step (reduce dt_s or check speeds, \
             moduli and wall motion)"
                .into()
        }
    }
}

/// A touching pair found in stage 1 of the pair loop. The law sees it from particle a (the lower id of i
/// and j, so that each state stays in one frame): `sign` is +1 when a = i, −1 when a = j, and turns the
/// geometry seen from i into a's exactly (negation is exact).
struct Candidate<'p, P> {
    /// Slot of the pair among i's neighbours.
    slot: usize,
    /// The partner of i.
    j: usize,
    sign: f64,
    /// Radius of j \[m\].
    rj: f64,
    /// Parameters of the pair type (looked up, and bounds-checked, in stage 1).
    params: &'p P,
    /// Unit normal, from b to a.
    normal: Vec3,
    /// Overlap δ \[m\].
    overlap: f64,
    /// R* \[m\].
    r_eff: f64,
    /// m* \[kg\].
    m_eff: f64,
    /// Contact-point velocity of a minus b's \[m/s\].
    v_rel: Vec3,
}

impl<P> Clone for Candidate<'_, P> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P> Copy for Candidate<'_, P> {}

/// Stage 2 of the pair loop for one group: what it reads, and the sums it adds into.
struct PairStage<'a, L: ContactLaw> {
    law: &'a L,
    id: &'a [u32],
    omega: &'a [Vec3],
    inv_mass: &'a [f64],
    /// Time step \[s\].
    dt: f64,
    /// Forces \[N\] and torques \[N m\] of the group's particles, indexed from particle `pbase`.
    f: &'a mut [Vec3],
    tq: &'a mut [Vec3],
    pbase: usize,
    acc: Acc,
    /// Running sums of the pair forces \[N\] and torques \[N m\] on the current particle i.
    fi: Vec3,
    ti: Vec3,
}

/// A run of candidates of particle i in the stage-2 buffer: candidates up to index `end`, radius `ri`
/// \[m\] and inverse mass `ii` \[1/kg\] of i; `last` when the run ends i's neighbours.
#[derive(Clone, Copy)]
struct Owner {
    i: usize,
    ri: f64,
    ii: f64,
    end: usize,
    last: bool,
}

impl<L: ContactLaw> PairStage<'_, L> {
    /// The contact law for the touching pairs `cands` of the particles in `owners` (in order, each run of
    /// candidates belonging to one particle i), whose states are `states` (indexed by
    /// `Candidate::slot`): adds the forces and torques on the partners, sums those on i apart and adds the
    /// sums into i's slots after i's last run (also for a particle without candidates, so that every
    /// force is summed in the same order for any buffer size), and books. Kept out of line and called
    /// once per buffer of several particles: inlined into the neighbour loop, its values shared the
    /// registers with stage 1's geometry and were spilled to the stack in every contact; called once per
    /// particle, its entry and exit cost about 80 instructions per particle.
    #[inline(never)]
    fn contacts(&mut self, cands: &[Candidate<'_, L::Params>], owners: &[Owner], states: &mut [L::State]) {
        let (law, id, omega, inv_mass, dt, pbase) =
            (self.law, self.id, self.omega, self.inv_mass, self.dt, self.pbase);
        let default = L::State::default();
        let f = &mut *self.f;
        let tq = &mut self.tq[..f.len()];
        let (mut acc, mut fi, mut ti) = (self.acc, self.fi, self.ti);
        let mut c = 0;
        for o in owners {
            let (i, ri, ii) = (o.i, o.ri, o.ii);
            for cand in &cands[c..o.end] {
                let (j, s, rj) = (cand.j, cand.sign, cand.rj);
                let (i_eff, w_rel) = if L::USES_ROTATION {
                    let inv_i = 2.5 * (ii / (ri * ri) + inv_mass[j] / (rj * rj));
                    (1.0 / inv_i, s * (omega[i] - omega[j]))
                } else {
                    (0.0, Vec3::ZERO)
                };
                let c = ContactInput {
                    normal: cand.normal,
                    overlap: cand.overlap,
                    r_eff: cand.r_eff,
                    radius_sum: ri + rj,
                    m_eff: cand.m_eff,
                    i_eff,
                    v_rel: cand.v_rel,
                    w_rel,
                    dt,
                };
                let state = &mut states[cand.slot];
                match law.compute(cand.params, &c, state) {
                    None => *state = default,
                    Some(o) => {
                        // The force acts on a, which is i for s = 1 and j for s = −1.
                        let fv = s * o.force;
                        let cr = c.normal.cross(o.force);
                        fi += fv;
                        f[j - pbase] -= fv;
                        if L::USES_ROTATION {
                            let rt = s * o.rolling_torque;
                            ti += rt - ri * cr;
                            tq[j - pbase] -= rt + rj * cr;
                        } else {
                            // No rolling torque (see `ContactLaw::USES_ROTATION`).
                            ti -= ri * cr;
                            tq[j - pbase] -= rj * cr;
                        }
                        acc.dissipated += o.dissipated;
                        acc.elastic += o.energy;
                        acc.pair_contacts += 1;
                        // Radii are positive: a compare is enough (no NaN handling).
                        let rmin = if ri < rj { ri } else { rj };
                        if c.overlap > acc.max_ratio * rmin {
                            let (a, b) = if s > 0.0 { (i, j) } else { (j, i) };
                            acc.note_overlap(c.overlap / rmin, id[a], id[b]);
                        }
                    }
                }
            }
            c = o.end;
            if o.last {
                // Force and torque on i, summed apart, are stored once.
                f[i - pbase] += fi;
                tq[i - pbase] += ti;
                (fi, ti) = (Vec3::ZERO, Vec3::ZERO);
            }
        }
        (self.acc, self.fi, self.ti) = (acc, fi, ti);
    }
}

/// What the wall loop reads of the particle in contact, loaded once per particle.
struct WallParticle {
    id: u32,
    /// Radius \[m\].
    r: f64,
    /// Velocity \[m/s\] and angular velocity \[rad/s\].
    vel: Vec3,
    omega: Vec3,
    /// 1/m \[1/kg\].
    inv_mass: f64,
    /// The time over which the contact springs advance \[s\].
    dt: f64,
}

/// One particle–wall contact at `hit` (world frame): the law, the force and torque on the particle (added
/// to `fi`, `ti`), the slot's output and the sums. With `MOVING` false the wall is fixed (zero velocity
/// everywhere, no work): the velocity terms are left out, which changes no bit of the result (subtracting
/// a zero vector is exact).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn wall_contact<L: ContactLaw, const MOVING: bool>(
    law: &L,
    pp: &L::Params,
    kw: &WallKinematics,
    hit: WallHit,
    p: &WallParticle,
    state: &mut L::State,
    out: &mut SlotOut,
    (fi, ti): (&mut Vec3, &mut Vec3),
    acc: &mut Acc,
) {
    let n = hit.normal;
    let r = p.r;
    let v_wall = if MOVING { kw.velocity_at(hit.point) } else { Vec3::ZERO };
    let v_rel = if MOVING { p.vel - r * p.omega.cross(n) - v_wall } else { p.vel - r * p.omega.cross(n) };
    let c = ContactInput {
        normal: n,
        overlap: r - hit.distance,
        r_eff: r,
        radius_sum: r,
        m_eff: 1.0 / p.inv_mass,
        i_eff: 0.4 * r * r / p.inv_mass,
        v_rel,
        w_rel: if MOVING { p.omega - kw.omega } else { p.omega },
        dt: p.dt,
    };
    let was_new = !out.active;
    match law.compute(pp, &c, state) {
        None => {
            *state = L::State::default();
            *out = SlotOut::default();
        }
        Some(o) => {
            *fi += o.force;
            *ti += o.rolling_torque - r * n.cross(o.force);
            acc.dissipated += o.dissipated;
            acc.elastic += o.energy;
            if MOVING {
                acc.wall_power += o.force.dot(v_wall) + o.rolling_torque.dot(kw.omega);
            }
            acc.wall_contacts += 1;
            acc.note_overlap(c.overlap / r, p.id, u32::MAX);
            let tangential_speed = if was_new {
                let vc = if MOVING { p.vel - v_wall } else { p.vel };
                (vc - vc.dot(n) * n).length()
            } else {
                0.0
            };
            *out = SlotOut {
                active: true,
                formed: was_new,
                normal_force: o.normal_force,
                approach_speed: -c.v_rel.dot(n),
                tangential_speed,
                force: o.force,
            };
        }
    }
}
