//! Neighbour and wall-candidate lists: rebuilt with a skin, particles re-sorted by cell at every rebuild,
//! contact states (and for wall slots their contact flags) carried over by stable ids.

use super::forces::SlotOut;
use super::Simulation;
use crate::contact::ContactLaw;
use crate::par::{blocks, colour_phases, Group};
use crate::walls::{WallKinematics, WallShape};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Half neighbour list in CSR form: the partners j > i of particle i are `nbr[start[i]..start[i+1]]`
/// (low 31 bits; the top bit is set when j has the lower id), with one contact state each (from the
/// lower-id particle's point of view).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PairList<S> {
    pub start: Vec<u32>,
    pub nbr: Vec<u32>,
    pub state: Vec<S>,
    /// The two colouring phases of groups (see [`crate::par::colour_phases`]).
    pub phases: [Vec<Group>; 2],
}

impl<S> Default for PairList<S> {
    fn default() -> Self {
        PairList { start: vec![0], nbr: Vec::new(), state: Vec::new(), phases: [Vec::new(), Vec::new()] }
    }
}

/// Wall candidates per particle in CSR form: slots `start[i]..start[i+1]`, sorted by (wall, triangle).
/// Analytic walls use triangle 0.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WallList<S> {
    pub start: Vec<u32>,
    pub wall: Vec<u16>,
    pub tri: Vec<u32>,
    pub state: Vec<S>,
    /// What each slot did in the last evaluation; its `active` flag tells a new contact from a
    /// continuing one, so it is carried over rebuilds and checkpointed with the state.
    pub out: Vec<SlotOut>,
    /// Particle blocks for the parallel wall loop.
    pub blocks: Vec<Group>,
}

impl<S> Default for WallList<S> {
    fn default() -> Self {
        WallList {
            start: vec![0],
            wall: Vec::new(),
            tri: Vec::new(),
            state: Vec::new(),
            out: Vec::new(),
            blocks: Vec::new(),
        }
    }
}

const BLOCK: usize = 1024;

/// Index bits of a neighbour-list entry; the top bit flags that the partner has the lower id.
pub(crate) const NBR_MASK: u32 = 0x7fff_ffff;

impl<L: ContactLaw> Simulation<L> {
    /// Rebuilds the neighbour and wall lists: removes particles outside the domain, sorts the particle
    /// arrays by cell, builds the half list and the wall candidates, and restores every contact state.
    pub(crate) fn rebuild(&mut self) {
        let (carry, wall_carry) = self.collect_carries();
        self.remove_outside_domain();
        let r_max = self.particles.radius.iter().copied().fold(0.0, f64::max);
        self.build_lists(r_max, &carry, &wall_carry);
        self.finish_rebuild();
    }

    /// Step 1 of a rebuild: the states of the pair and wall slots in contact, keyed by ids (pair
    /// carries sorted by [`pair_key`], wall carries by (particle id, wall, triangle)).
    pub(super) fn collect_carries(&self) -> Carries<L::State> {
        let default = L::State::default();
        let mut carry: Vec<(u64, L::State)> = Vec::new();
        {
            let p = &self.particles;
            let l = &self.st.list;
            for i in 0..listed(&l.start, p.len()) {
                for k in l.start[i] as usize..l.start[i + 1] as usize {
                    if l.state[k] != default {
                        let (a, b) = (p.id[i], p.id[(l.nbr[k] & NBR_MASK) as usize]);
                        carry.push((pair_key(a, b), l.state[k]));
                    }
                }
            }
        }
        carry.sort_unstable_by_key(|c| c.0);
        let mut wall_carry: Vec<WallCarry<L::State>> = Vec::new();
        {
            let p = &self.particles;
            let wl = &self.st.wall_list;
            let out = |k: usize| wl.out.get(k).copied().unwrap_or_default();
            for i in 0..listed(&wl.start, p.len()) {
                for k in wl.start[i] as usize..wl.start[i + 1] as usize {
                    if wl.state[k] != default || out(k).active {
                        wall_carry.push(((p.id[i], wl.wall[k], wl.tri[k]), wl.state[k], out(k)));
                    }
                }
            }
        }
        wall_carry.sort_unstable_by_key(|c| c.0);
        (carry, wall_carry)
    }

    /// Step 2 of a rebuild: drops the particles that left the domain (a body leaves as a whole when its
    /// centre of mass does) and books the energy they take out.
    pub(super) fn remove_outside_domain(&mut self) {
        if let Some(dom) = self.settings.domain {
            let removed_members = self.remove_bodies_outside(&dom);
            self.st.removed += removed_members as u64;
            let n0 = self.particles.len();
            let pos = self.particles.pos.clone();
            // The energy the removed particles take out of the budget. Between the kicks of velocity Verlet
            // the velocities belong to the half step, so the potential energy is taken at the matching
            // position x − ½Δt v: then a particle in free flight leaves with its energy at the end of the
            // last step up to m g²Δt²/8.
            let p = &self.particles;
            let e = &mut self.st.energy;
            let back = if self.half_step_velocities { 0.5 * self.dt } else { 0.0 };
            for (i, &x) in pos.iter().enumerate() {
                if p.inv_mass[i] > 0.0 && !p.is_member(i) && !dom.contains(x) {
                    let m = p.mass(i);
                    e.injected_kinetic -= 0.5 * m * p.vel[i].length_squared();
                    e.injected_rotational -= 0.5 * p.inertia(i) * p.omega[i].length_squared();
                    e.injected_moment -= m * (x - back * p.vel[i]);
                }
            }
            let members = self.particles.body.clone();
            let is_member = |i: usize| !members.is_empty() && members[i] != crate::clump::NO_BODY;
            self.particles.retain(|i| is_member(i) || dom.contains(pos[i]));
            self.st.removed += (n0 - self.particles.len()) as u64;
        }
    }

    /// Steps 3 to 6 of a rebuild, with `r_max` the largest radius \[m\] (over all ranks): sorts the
    /// particles by cell, builds the half list and the wall candidates, and restores the carried states.
    pub(super) fn build_lists(
        &mut self,
        r_max: f64,
        carry: &[PairCarry<L::State>],
        wall_carry: &[WallCarry<L::State>],
    ) {
        let default = L::State::default();
        // 3. Sort by cell.
        self.st.r_max = r_max;
        let (range_pp, range_pw) = self.range_max(r_max);
        let skin = self.skin();
        let n = self.particles.len();
        let cell = (2.0 * r_max + range_pp + skin).max(1e-300);
        if n > 0 {
            self.scratch.grid.rebuild(&self.particles.pos, cell);
            self.scratch.perm.clear();
            self.scratch.perm.extend_from_slice(self.scratch.grid.entries());
            self.particles.permute(&self.scratch.perm, &mut self.scratch.permute);
        }

        // 4. Half list. After the permutation, new index k is entries()[k], so the grid's cell ranges are
        //    ranges of new indices.
        let p = &self.particles;
        let grid = &self.scratch.grid;
        let extra = range_pp + skin;
        // Two frozen spheres or two members of one body never interact.
        let body = &p.body;
        let has_bodies = !body.is_empty();
        let both_frozen = |i: usize, j: usize| {
            (p.inv_mass[i] == 0.0 && p.inv_mass[j] == 0.0)
                || (has_bodies && body[i] == body[j] && body[i] != crate::clump::NO_BODY)
        };
        let parts: Vec<(Vec<u32>, Vec<u32>)> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let (i0, i1) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
                let mut counts = Vec::with_capacity(i1 - i0);
                let mut nb = Vec::with_capacity((i1 - i0) * 8);
                for i in i0..i1 {
                    let xi = p.pos[i];
                    let ri = p.radius[i];
                    let before = nb.len();
                    grid.for_each_candidate_run(xi, |run| {
                        for j in run.start.max(i + 1)..run.end {
                            let c = ri + p.radius[j] + extra;
                            if (p.pos[j] - xi).length_squared() < c * c && !both_frozen(i, j) {
                                nb.push(j as u32 | ((p.id[j] < p.id[i]) as u32) << 31);
                            }
                        }
                    });
                    counts.push((nb.len() - before) as u32);
                }
                (counts, nb)
            })
            .collect();
        let list = &mut self.st.list;
        let total: usize = parts.iter().map(|p| p.1.len()).sum();
        list.start.clear();
        list.start.reserve_exact(n + 1);
        list.start.push(0);
        list.nbr.clear();
        // Exact capacities (no growth slack), shrunk when the list got much shorter.
        if list.nbr.capacity() > total + total / 4 + 64 {
            list.nbr.shrink_to(total);
            list.state.shrink_to(total);
        }
        list.nbr.reserve_exact(total);
        let mut span = 1usize;
        for (counts, nb) in &parts {
            let mut k = 0usize;
            for &c in counts {
                let i = list.start.len() - 1;
                let s = &nb[k..k + c as usize];
                if let Some(&last) = s.last() {
                    span = span.max((last & NBR_MASK) as usize - i + 1);
                }
                list.nbr.extend_from_slice(s);
                k += c as usize;
                list.start.push(list.nbr.len() as u32);
            }
        }
        drop(parts);
        colour_phases(n, span, &mut list.phases);

        // 5. Restore pair states.
        list.state.clear();
        list.state.reserve_exact(list.nbr.len());
        list.state.resize(list.nbr.len(), default);
        if !carry.is_empty() {
            let reach = range_pp;
            for i in 0..n {
                for k in list.start[i] as usize..list.start[i + 1] as usize {
                    let j = (list.nbr[k] & NBR_MASK) as usize;
                    let c = p.radius[i] + p.radius[j] + reach;
                    if (p.pos[j] - p.pos[i]).length_squared() >= c * c * (1.0 + 1e-9) + 1e-300 {
                        continue;
                    }
                    let key = pair_key(p.id[i], p.id[j]);
                    if let Ok(m) = carry.binary_search_by_key(&key, |c| c.0) {
                        list.state[k] = carry[m].1;
                    }
                }
            }
        }

        // 6. Wall candidates.
        let t = self.st.time;
        let kin: Vec<WallKinematics> = self.walls.iter().map(|w| WallKinematics::of(&w.motion, t)).collect();
        let walls = &self.walls;
        type Part = (Vec<u32>, Vec<(u16, u32)>);
        let wparts: Vec<Part> = (0..n.div_ceil(BLOCK))
            .into_par_iter()
            .map(|b| {
                let (i0, i1) = (b * BLOCK, ((b + 1) * BLOCK).min(n));
                let mut counts = Vec::with_capacity(i1 - i0);
                let mut slots = Vec::new();
                let mut tris = Vec::new();
                for i in i0..i1 {
                    let before = slots.len();
                    if p.inv_mass[i] != 0.0 {
                        let reach = p.radius[i] + range_pw + skin;
                        for (w, wall) in walls.iter().enumerate() {
                            let x = kin[w].to_reference(p.pos[i]);
                            match &wall.shape {
                                WallShape::Mesh(m) => {
                                    tris.clear();
                                    m.for_each_near(x, reach, |tri| tris.push(tri));
                                    tris.sort_unstable();
                                    slots.extend(tris.iter().map(|&tri| (w as u16, tri)));
                                }
                                _ => {
                                    if wall.analytic_hit(x, reach).is_some() {
                                        slots.push((w as u16, 0));
                                    }
                                }
                            }
                        }
                    }
                    counts.push((slots.len() - before) as u32);
                }
                (counts, slots)
            })
            .collect();
        let wl = &mut self.st.wall_list;
        wl.start.clear();
        wl.start.push(0);
        wl.wall.clear();
        wl.tri.clear();
        for (counts, slots) in &wparts {
            let mut k = 0;
            for &c in counts {
                for &(w, tri) in &slots[k..k + c as usize] {
                    wl.wall.push(w);
                    wl.tri.push(tri);
                }
                k += c as usize;
                wl.start.push(wl.wall.len() as u32);
            }
        }
        wl.state.clear();
        wl.state.resize(wl.wall.len(), default);
        wl.out.clear();
        wl.out.resize(wl.wall.len(), SlotOut::default());
        if !wall_carry.is_empty() {
            for i in 0..n {
                for k in wl.start[i] as usize..wl.start[i + 1] as usize {
                    let key = (p.id[i], wl.wall[k], wl.tri[k]);
                    if let Ok(m) = wall_carry.binary_search_by_key(&key, |c| c.0) {
                        wl.state[k] = wall_carry[m].1;
                        wl.out[k] = wall_carry[m].2;
                    }
                }
            }
        }
        blocks(n, BLOCK, &mut wl.blocks);

        // Rebuild-only buffers are released: steady-state memory is the particles and the lists.
        self.scratch.grid = spatter_core::grid::CellGrid::new();
        self.scratch.perm = Vec::new();
        self.scratch.permute = crate::particles::PermuteScratch::default();
    }

    /// The end of a rebuild: displacement bounds reset, counters, clump members.
    pub(super) fn finish_rebuild(&mut self) {
        self.st.disp_particles = 0.0;
        self.st.disp_walls = 0.0;
        self.st.needs_rebuild = false;
        self.st.rebuilds += 1;
        self.refresh_members();
    }
}

/// The state of a pair slot in contact, keyed by [`pair_key`] of the two ids.
pub(super) type PairCarry<S> = (u64, S);

/// (particle id, wall, triangle), state and last output of a wall slot in contact.
pub(super) type WallCarry<S> = ((u32, u16, u32), S, SlotOut);

/// The pair and wall carries of a rebuild.
pub(super) type Carries<S> = (Vec<PairCarry<S>>, Vec<WallCarry<S>>);

/// Order-independent key of a particle pair.
#[inline]
pub(super) fn pair_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

/// How many particles a neighbour list built at the last rebuild covers (`start` its offsets, `n` the
/// particles now): the first `start.len() − 1`. Particles added since (injection, a pour) are appended
/// after them without slots and keep the others' indices until the next rebuild sorts them, so the
/// contact history of the listed ones is still where the list says. 0 for a list never built, or one
/// that covers more particles than there are (none are removed between rebuilds).
pub(super) fn listed(start: &[u32], n: usize) -> usize {
    match start.len().checked_sub(1) {
        Some(m) if m <= n => m,
        _ => 0,
    }
}
