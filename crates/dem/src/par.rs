//! Deterministic parallel processing of disjoint particle groups.
//!
//! Force accumulation must give bit-identical results whatever the thread count. The engine therefore
//! never lets two tasks add into the same particle, and fixes the order of every sum:
//!
//! * particles are split into *groups* of contiguous indices whose boundaries depend only on the data
//!   (never on the number of threads);
//! * a task owns the force/torque slots of its group and the contact slots of the particles it processes;
//! * groups are processed by recursive halving with `rayon::join`, and the per-group results (energy
//!   sums, maxima) are combined in the same binary tree every time.
//!
//! With one thread the same tree is walked sequentially, so the floating-point sums are identical.

use spatter_core::Vec3;

/// A contiguous particle range whose force slots one task owns (`own`), and the sub-range whose contacts
/// the task evaluates (`work`, ⊆ `own`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Group {
    pub own_begin: u32,
    pub own_end: u32,
    pub work_begin: u32,
    pub work_end: u32,
}

/// Mutable data that can be split at an index, so that disjoint parts go to different tasks.
pub trait Splittable: Sized + Send {
    fn split(self, at: usize) -> (Self, Self);
}

impl<T: Send> Splittable for &mut [T] {
    #[inline]
    fn split(self, at: usize) -> (Self, Self) {
        self.split_at_mut(at)
    }
}

impl<A: Splittable, B: Splittable> Splittable for (A, B) {
    #[inline]
    fn split(self, at: usize) -> (Self, Self) {
        let (a0, a1) = self.0.split(at);
        let (b0, b1) = self.1.split(at);
        ((a0, b0), (a1, b1))
    }
}

impl Splittable for () {
    #[inline]
    fn split(self, _at: usize) -> (Self, Self) {
        ((), ())
    }
}

/// Runs `work(group, particle_base, particle_data, slot_base, slot_data)` for every group, in parallel
/// where possible, and combines the results in a fixed binary tree. `particle_data` covers particles from
/// index `particle_base`, `slot_data` covers contact slots from `slot_base`; `slot_start[i]` is the first
/// slot of particle i. Returns `None` for no groups.
#[allow(clippy::too_many_arguments)]
pub fn run_groups<P, Q, A, W, C>(
    groups: &[Group],
    particle_base: usize,
    particle_data: P,
    slot_base: usize,
    slot_data: Q,
    slot_start: &[u32],
    work: &W,
    combine: &C,
) -> Option<A>
where
    P: Splittable,
    Q: Splittable,
    A: Send,
    W: Fn(&Group, usize, P, usize, Q) -> A + Sync,
    C: Fn(A, A) -> A + Sync,
{
    match groups.len() {
        0 => None,
        1 => Some(work(&groups[0], particle_base, particle_data, slot_base, slot_data)),
        n => {
            let mid = n / 2;
            let p_split = groups[mid].own_begin as usize;
            let s_split = slot_start[p_split] as usize;
            let (p_left, p_right) = particle_data.split(p_split - particle_base);
            let (s_left, s_right) = slot_data.split(s_split - slot_base);
            let (a, b) = rayon::join(
                || {
                    run_groups(
                        &groups[..mid],
                        particle_base,
                        p_left,
                        slot_base,
                        s_left,
                        slot_start,
                        work,
                        combine,
                    )
                },
                || run_groups(&groups[mid..], p_split, p_right, s_split, s_right, slot_start, work, combine),
            );
            match (a, b) {
                (Some(a), Some(b)) => Some(combine(a, b)),
                (a, b) => a.or(b),
            }
        }
    }
}

/// Splits `n` particles into blocks of about `block` for per-particle work (each block owns and works on
/// its own particles).
pub fn blocks(n: usize, block: usize, out: &mut Vec<Group>) {
    out.clear();
    let block = block.max(1);
    let mut b = 0;
    while b < n {
        let e = (b + block).min(n);
        out.push(Group { own_begin: b as u32, own_end: e as u32, work_begin: b as u32, work_end: e as u32 });
        b = e;
    }
}

/// The two colouring phases for a half neighbour list whose partner indices satisfy j − i < `span` for
/// every pair: chunks of at least `span` particles (and about n / 64 for parallelism), then groups of two
/// neighbouring chunks; phase 0 works on the even chunks, phase 1 on the odd ones. Every pair (i, j) with
/// i in chunk c has j in chunk c or c + 1, so the groups of one phase touch disjoint particles.
pub fn colour_phases(n: usize, span: usize, phases: &mut [Vec<Group>; 2]) {
    phases[0].clear();
    phases[1].clear();
    if n == 0 {
        return;
    }
    let chunk = span.max(n.div_ceil(64)).max(1);
    let nchunks = n.div_ceil(chunk);
    let bound = |c: usize| (c * chunk).min(n) as u32;
    for c in 0..nchunks {
        let g = Group {
            own_begin: bound(c),
            own_end: bound((c + 2).min(nchunks)),
            work_begin: bound(c),
            work_end: bound(c + 1),
        };
        phases[c % 2].push(g);
    }
}

/// Adds `v` into slot `i − base` of `f` (helper for readability in kernels).
#[inline(always)]
pub fn add(f: &mut [Vec3], base: usize, i: usize, v: Vec3) {
    f[i - base] += v;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phases_cover_every_chunk_once_and_groups_are_disjoint() {
        for (n, span) in [(1000, 37), (10, 100), (64, 1), (1, 1)] {
            let mut ph = [Vec::new(), Vec::new()];
            colour_phases(n, span, &mut ph);
            let mut covered = vec![0u32; n];
            for phase in &ph {
                for w in phase.windows(2) {
                    assert!(w[0].own_end <= w[1].own_begin, "groups of a phase overlap");
                }
                for g in phase {
                    assert!(g.work_end - g.work_begin >= span.min(n) as u32 || g.work_end as usize == n);
                    for c in &mut covered[g.work_begin as usize..g.work_end as usize] {
                        *c += 1;
                    }
                }
            }
            assert!(covered.iter().all(|&c| c == 1));
        }
    }

    #[test]
    fn results_do_not_depend_on_the_thread_count() {
        // Sum of 1/(i+1) over groups, combined in the fixed tree: identical for 1 and 3 threads.
        let n = 10_000;
        let mut groups = Vec::new();
        blocks(n, 97, &mut groups);
        let start: Vec<u32> = (0..=n as u32).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut f = vec![Vec3::ZERO; n];
                let s = run_groups(
                    &groups,
                    0,
                    &mut f[..],
                    0,
                    (),
                    &start,
                    &|g, base, f: &mut [Vec3], _, ()| {
                        let mut acc = 0.0;
                        for i in g.work_begin as usize..g.work_end as usize {
                            f[i - base].x = i as f64;
                            acc += 1.0 / (i as f64 + 1.0);
                        }
                        acc
                    },
                    &|a, b| a + b,
                )
                .unwrap();
                (s, f)
            })
        };
        let (a, fa) = run(1);
        let (b, fb) = run(3);
        assert_eq!(a.to_bits(), b.to_bits());
        assert_eq!(fa, fb);
    }
}
