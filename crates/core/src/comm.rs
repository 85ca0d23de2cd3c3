//! Communication between the ranks of one run.
//!
//! A run split over several processes (MPI ranks) or, in tests, over several threads, talks through
//! [`Comm`]. The engines see only this trait, so they depend on no message-passing library: the MPI
//! implementation lives in its own crate and is handed to the job driver by the command line.
//!
//! Rules every implementation and every caller keep:
//! * every rank makes the same collective calls in the same order (a rank that skips one leaves the
//!   others waiting), and calls them only from the thread that runs the step, never from inside a
//!   parallel loop;
//! * reductions of floating-point sums are done in rank order ([`Comm::sum_f64_ordered`]) so that every
//!   rank obtains the same bits; maxima and integer sums are exact in any order;
//! * payloads are plain byte buffers, written and read with [`WireWriter`] / [`WireReader`]
//!   (little-endian, no padding), so no implementation needs to know the engines' types.
//!
//! [`SerialComm`] is the one-rank world every ordinary run uses; [`ThreadComm`] runs ranks as threads of
//! one process so that decomposed runs can be tested by a plain `cargo test`.

use crate::Vec3;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};

/// The ranks of one run and the collective operations between them.
pub trait Comm: Send + Sync {
    /// This rank's number, `0 ≤ rank < size`.
    fn rank(&self) -> usize;
    /// Number of ranks.
    fn size(&self) -> usize;
    /// Rank 0 writes the run folder, the log and the summary.
    fn is_root(&self) -> bool {
        self.rank() == 0
    }
    /// Element-wise maximum over all ranks, in place; identical bits on every rank. A minimum is the
    /// maximum of negated values.
    fn all_max_f64(&self, values: &mut [f64]);
    /// Element-wise sum over all ranks, in place (counts, flags); exact.
    fn all_sum_u64(&self, values: &mut [u64]);
    /// Every rank's buffer, on every rank, in rank order.
    fn all_gather_bytes(&self, local: &[u8]) -> Vec<Vec<u8>>;
    /// Point-to-point exchange with a symmetric set of peers: `out[k]` goes to `peers[k]`, and the
    /// result's `k`-th buffer is what `peers[k]` sent to this rank. `peers` must be sorted, without
    /// duplicates, and symmetric (if a lists b, b lists a); this rank may list itself.
    fn neighbour_exchange(&self, peers: &[usize], out: &[Vec<u8>]) -> Vec<Vec<u8>>;
    /// Every rank sends `out[r]` to rank `r` (`out.len() == size`) and receives one buffer from every rank,
    /// in rank order. For rare events (rebalancing, resuming on another rank count).
    fn all_to_all_bytes(&self, out: &[Vec<u8>]) -> Vec<Vec<u8>>;
    /// Every rank's buffer on `root` (in rank order), `None` elsewhere.
    fn gather_bytes(&self, root: usize, local: &[u8]) -> Option<Vec<Vec<u8>>>;
    /// `root`'s buffer copied into `buf` on every rank.
    fn broadcast_bytes(&self, root: usize, buf: &mut Vec<u8>);
    /// Waits until every rank has arrived.
    fn barrier(&self);
    /// Ends the whole run with `code` after an error one rank cannot share with the others (a failed
    /// write of its own piece, a panic): never leaves the other ranks waiting.
    fn abort(&self, code: i32) -> !;

    /// Whether the collectives may be called from any thread (one at a time), not only from the thread
    /// that started the transport: then a run may drive its steps from a worker of its thread pool.
    fn calls_from_any_thread(&self) -> bool {
        true
    }

    /// Wall time \[s\] this rank has spent inside the transport's collectives and exchanges since it
    /// started, waiting for the other ranks included: with the time of a run, a measure of how long a rank
    /// waited for slower ones (load imbalance) and for messages. 0 where the transport does not measure it
    /// (one rank, thread-ranks).
    fn seconds_in_collectives(&self) -> f64 {
        0.0
    }

    /// Element-wise sum over all ranks, added in rank order on every rank, so every rank holds the same
    /// bits whatever the transport does (an MPI sum may group terms differently on different ranks).
    fn sum_f64_ordered(&self, values: &mut [f64]) {
        if self.size() == 1 {
            return;
        }
        let mut w = WireWriter::with_capacity(8 * values.len());
        w.f64s(values);
        let all = self.all_gather_bytes(&w.finish());
        values.fill(0.0);
        for part in &all {
            let mut r = WireReader::new(part);
            for v in values.iter_mut() {
                // Every rank wrote `values.len()` numbers: a short buffer is a broken implementation.
                *v += r.f64().expect("every rank sends the same number of values");
            }
        }
    }
}

/// The world of an ordinary run: one rank, every collective is the identity.
#[derive(Clone, Copy, Debug, Default)]
pub struct SerialComm;

/// A shared serial world for defaults (`&SERIAL as &dyn Comm`).
pub static SERIAL: SerialComm = SerialComm;

impl Comm for SerialComm {
    fn rank(&self) -> usize {
        0
    }
    fn size(&self) -> usize {
        1
    }
    fn all_max_f64(&self, _values: &mut [f64]) {}
    fn all_sum_u64(&self, _values: &mut [u64]) {}
    fn all_gather_bytes(&self, local: &[u8]) -> Vec<Vec<u8>> {
        vec![local.to_vec()]
    }
    fn neighbour_exchange(&self, peers: &[usize], out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        assert!(peers.iter().all(|&p| p == 0), "a one-rank run has no peer but itself");
        out.to_vec()
    }
    fn all_to_all_bytes(&self, out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        assert_eq!(out.len(), 1, "a one-rank run sends one buffer");
        out.to_vec()
    }
    fn gather_bytes(&self, _root: usize, local: &[u8]) -> Option<Vec<Vec<u8>>> {
        Some(vec![local.to_vec()])
    }
    fn broadcast_bytes(&self, _root: usize, _buf: &mut Vec<u8>) {}
    fn barrier(&self) {}
    fn abort(&self, code: i32) -> ! {
        std::process::exit(code)
    }
}

/// Ranks as threads of one process, for tests of decomposed runs without MPI.
///
/// [`ThreadComm::run`] starts `n` threads, gives each its rank's `ThreadComm` and returns their results in
/// rank order. Every collective is a write to shared slots, a barrier, a read, and a second barrier (so
/// slots are free again for the next collective). If one rank panics the barrier is poisoned and every
/// other rank panics at its next collective instead of waiting forever, so a broken test fails, never hangs.
pub struct ThreadComm {
    rank: usize,
    shared: Arc<Shared>,
}

struct Shared {
    size: usize,
    /// `slots[from * size + to]`: the buffer `from` sends to `to` in the current collective.
    slots: Mutex<Vec<Option<Vec<u8>>>>,
    barrier: PoisonableBarrier,
}

impl ThreadComm {
    /// Runs `f` on `n` ranks (one thread each) and returns the ranks' results in rank order. Panics if a
    /// rank panicked, with that rank's message.
    pub fn run<T: Send>(n: usize, f: impl Fn(&ThreadComm) -> T + Sync) -> Vec<T> {
        assert!(n >= 1, "a run needs at least one rank");
        let shared = Arc::new(Shared {
            size: n,
            slots: Mutex::new(vec![None; n * n]),
            barrier: PoisonableBarrier::new(n),
        });
        std::thread::scope(|scope| {
            let handles: Vec<_> = (0..n)
                .map(|rank| {
                    let comm = ThreadComm { rank, shared: Arc::clone(&shared) };
                    let f = &f;
                    scope.spawn(move || {
                        let guard = PoisonOnPanic(&comm.shared.barrier);
                        let out = f(&comm);
                        std::mem::forget(guard);
                        out
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e))).collect()
        })
    }

    fn slots(&self) -> MutexGuard<'_, Vec<Option<Vec<u8>>>> {
        // A rank that panicked while holding the lock poisons it; the barrier reports that rank's failure.
        self.shared.slots.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn slot(&self, from: usize, to: usize) -> usize {
        from * self.shared.size + to
    }

    /// One collective round: `send` lists (destination, buffer); returns the buffers from `sources` in order.
    fn round(&self, send: Vec<(usize, Vec<u8>)>, sources: &[usize]) -> Vec<Vec<u8>> {
        {
            let mut slots = self.slots();
            for (to, buf) in send {
                let i = self.slot(self.rank, to);
                slots[i] = Some(buf);
            }
        }
        self.shared.barrier.wait();
        let got = {
            let mut slots = self.slots();
            sources
                .iter()
                .map(|&from| {
                    let i = self.slot(from, self.rank);
                    slots[i].take().unwrap_or_else(|| {
                        panic!(
                            "rank {} expected a message from rank {from}: peer lists are not symmetric",
                            self.rank
                        )
                    })
                })
                .collect()
        };
        self.shared.barrier.wait();
        got
    }
}

impl Comm for ThreadComm {
    fn rank(&self) -> usize {
        self.rank
    }
    fn size(&self) -> usize {
        self.shared.size
    }
    fn all_max_f64(&self, values: &mut [f64]) {
        let mut w = WireWriter::with_capacity(8 * values.len());
        w.f64s(values);
        for part in self.all_gather_bytes(&w.finish()) {
            let mut r = WireReader::new(&part);
            for v in values.iter_mut() {
                let x = r.f64().expect("every rank sends the same number of values");
                // NaN wins, so a blow-up on one rank is seen by all.
                if x > *v || x.is_nan() {
                    *v = x;
                }
            }
        }
    }
    fn all_sum_u64(&self, values: &mut [u64]) {
        let mut w = WireWriter::with_capacity(8 * values.len());
        w.u64s(values);
        let all = self.all_gather_bytes(&w.finish());
        values.fill(0);
        for part in all {
            let mut r = WireReader::new(&part);
            for v in values.iter_mut() {
                *v += r.u64().expect("every rank sends the same number of values");
            }
        }
    }
    fn all_gather_bytes(&self, local: &[u8]) -> Vec<Vec<u8>> {
        let all: Vec<usize> = (0..self.size()).collect();
        self.round(all.iter().map(|&to| (to, local.to_vec())).collect(), &all)
    }
    fn neighbour_exchange(&self, peers: &[usize], out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        assert_eq!(peers.len(), out.len(), "one buffer per peer");
        assert!(peers.windows(2).all(|w| w[0] < w[1]), "peers sorted without duplicates");
        assert!(peers.iter().all(|&p| p < self.size()), "peer rank out of range");
        self.round(peers.iter().copied().zip(out.iter().cloned()).collect(), peers)
    }
    fn all_to_all_bytes(&self, out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        assert_eq!(out.len(), self.size(), "one buffer per rank");
        let all: Vec<usize> = (0..self.size()).collect();
        self.round(out.iter().cloned().enumerate().collect(), &all)
    }
    fn gather_bytes(&self, root: usize, local: &[u8]) -> Option<Vec<Vec<u8>>> {
        let sources: Vec<usize> = if self.rank == root { (0..self.size()).collect() } else { Vec::new() };
        let got = self.round(vec![(root, local.to_vec())], &sources);
        (self.rank == root).then_some(got)
    }
    fn broadcast_bytes(&self, root: usize, buf: &mut Vec<u8>) {
        let send = if self.rank == root {
            (0..self.size()).map(|to| (to, buf.clone())).collect()
        } else {
            Vec::new()
        };
        let mut got = self.round(send, &[root]);
        *buf = got.pop().expect("one buffer from the root");
    }
    fn barrier(&self) {
        self.shared.barrier.wait();
    }
    fn abort(&self, code: i32) -> ! {
        self.shared.barrier.poison();
        panic!("rank {} aborted the run with code {code}", self.rank)
    }
}

/// A reusable barrier that can be poisoned: once a rank has failed, every wait panics.
struct PoisonableBarrier {
    n: usize,
    state: Mutex<BarrierState>,
    cv: Condvar,
}

struct BarrierState {
    arrived: usize,
    generation: u64,
    poisoned: bool,
}

impl PoisonableBarrier {
    fn new(n: usize) -> Self {
        PoisonableBarrier {
            n,
            state: Mutex::new(BarrierState { arrived: 0, generation: 0, poisoned: false }),
            cv: Condvar::new(),
        }
    }

    fn lock(&self) -> MutexGuard<'_, BarrierState> {
        self.state.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn wait(&self) {
        let mut s = self.lock();
        if s.poisoned {
            drop(s);
            panic!("another rank failed");
        }
        s.arrived += 1;
        if s.arrived == self.n {
            s.arrived = 0;
            s.generation += 1;
            self.cv.notify_all();
            return;
        }
        let generation = s.generation;
        while s.generation == generation && !s.poisoned {
            s = self.cv.wait(s).unwrap_or_else(|e| e.into_inner());
        }
        if s.generation == generation {
            drop(s);
            panic!("another rank failed");
        }
    }

    fn poison(&self) {
        self.lock().poisoned = true;
        self.cv.notify_all();
    }
}

/// Poisons the barrier when dropped during a rank's unwinding (forgotten on success).
struct PoisonOnPanic<'a>(&'a PoisonableBarrier);

impl Drop for PoisonOnPanic<'_> {
    fn drop(&mut self) {
        self.0.poison();
    }
}

/// Writes numbers into a message buffer: little-endian, no padding, no type tags.
#[derive(Debug, Default)]
pub struct WireWriter {
    buf: Vec<u8>,
}

impl WireWriter {
    pub fn with_capacity(bytes: usize) -> Self {
        WireWriter { buf: Vec::with_capacity(bytes) }
    }
    pub fn u32(&mut self, v: u32) -> &mut Self {
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }
    pub fn u64(&mut self, v: u64) -> &mut Self {
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }
    pub fn f64(&mut self, v: f64) -> &mut Self {
        self.buf.extend_from_slice(&v.to_le_bytes());
        self
    }
    pub fn vec3(&mut self, v: Vec3) -> &mut Self {
        self.f64(v.x).f64(v.y).f64(v.z)
    }
    pub fn f64s(&mut self, v: &[f64]) -> &mut Self {
        for &x in v {
            self.f64(x);
        }
        self
    }
    pub fn u64s(&mut self, v: &[u64]) -> &mut Self {
        for &x in v {
            self.u64(x);
        }
        self
    }
    pub fn bytes(&mut self, v: &[u8]) -> &mut Self {
        self.u64(v.len() as u64);
        self.buf.extend_from_slice(v);
        self
    }
    pub fn len(&self) -> usize {
        self.buf.len()
    }
    pub fn is_empty(&self) -> bool {
        self.buf.is_empty()
    }
    pub fn finish(self) -> Vec<u8> {
        self.buf
    }
}

/// A message ended before the value being read: the sender and the reader disagree on the layout.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("message truncated: {wanted} more bytes wanted at byte {at} of {len}")]
pub struct WireError {
    pub at: usize,
    pub wanted: usize,
    pub len: usize,
}

/// Reads numbers back in the order a [`WireWriter`] wrote them.
#[derive(Debug)]
pub struct WireReader<'a> {
    buf: &'a [u8],
    at: usize,
}

impl<'a> WireReader<'a> {
    pub fn new(buf: &'a [u8]) -> Self {
        WireReader { buf, at: 0 }
    }
    fn take<const N: usize>(&mut self) -> Result<[u8; N], WireError> {
        let end = self.at + N;
        let bytes =
            self.buf.get(self.at..end).ok_or(WireError { at: self.at, wanted: N, len: self.buf.len() })?;
        self.at = end;
        let mut out = [0u8; N];
        out.copy_from_slice(bytes);
        Ok(out)
    }
    pub fn u32(&mut self) -> Result<u32, WireError> {
        self.take().map(u32::from_le_bytes)
    }
    pub fn u64(&mut self) -> Result<u64, WireError> {
        self.take().map(u64::from_le_bytes)
    }
    pub fn f64(&mut self) -> Result<f64, WireError> {
        self.take().map(f64::from_le_bytes)
    }
    pub fn vec3(&mut self) -> Result<Vec3, WireError> {
        Ok(Vec3::new(self.f64()?, self.f64()?, self.f64()?))
    }
    pub fn bytes(&mut self) -> Result<&'a [u8], WireError> {
        let n = self.u64()? as usize;
        let end = self.at.checked_add(n).filter(|&e| e <= self.buf.len());
        let end = end.ok_or(WireError { at: self.at, wanted: n, len: self.buf.len() })?;
        let out = &self.buf[self.at..end];
        self.at = end;
        Ok(out)
    }
    /// True when every byte has been read.
    pub fn is_done(&self) -> bool {
        self.at == self.buf.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The collectives on 1–4 thread ranks give what their definitions say, identically on every rank.
    #[test]
    fn thread_ranks_honour_the_collectives() {
        for n in 1..=4 {
            let out = ThreadComm::run(n, |c| {
                let r = c.rank();
                let mut mx = [r as f64, -(r as f64)];
                c.all_max_f64(&mut mx);
                assert_eq!(mx, [(n - 1) as f64, 0.0]);
                let mut sum = [r as u64, 1];
                c.all_sum_u64(&mut sum);
                assert_eq!(sum, [(n * (n - 1) / 2) as u64, n as u64]);
                let all = c.all_gather_bytes(&[r as u8; 3]);
                assert_eq!(all, (0..n).map(|k| vec![k as u8; 3]).collect::<Vec<_>>());
                // Ring exchange with both neighbours (and self when the ring is short).
                let mut peers = vec![(r + 1) % n, (r + n - 1) % n];
                peers.sort_unstable();
                peers.dedup();
                let out: Vec<Vec<u8>> = peers.iter().map(|&p| vec![r as u8, p as u8]).collect();
                let got = c.neighbour_exchange(&peers, &out);
                for (k, &p) in peers.iter().enumerate() {
                    assert_eq!(got[k], vec![p as u8, r as u8], "from {p} to {r}");
                }
                let to_all: Vec<Vec<u8>> = (0..n).map(|to| vec![r as u8; to]).collect();
                let got = c.all_to_all_bytes(&to_all);
                assert_eq!(got, (0..n).map(|from| vec![from as u8; r]).collect::<Vec<_>>());
                let g = c.gather_bytes(n - 1, &[r as u8]);
                assert_eq!(g.is_some(), r == n - 1);
                if let Some(g) = g {
                    assert_eq!(g, (0..n).map(|k| vec![k as u8]).collect::<Vec<_>>());
                }
                let mut b = if r == 0 { vec![7, 8, 9] } else { Vec::new() };
                c.broadcast_bytes(0, &mut b);
                assert_eq!(b, vec![7, 8, 9]);
                c.barrier();
                // Sums that depend on grouping: every rank must hold the same bits, equal to rank order.
                let mut s = [0.1 * (r as f64 + 1.0), 1e16 * if r % 2 == 0 { 1.0 } else { -1.0 } + 1.0];
                c.sum_f64_ordered(&mut s);
                s
            });
            let mut expect = [0.0f64, 0.0];
            for r in 0..n {
                expect[0] += 0.1 * (r as f64 + 1.0);
                expect[1] += 1e16 * if r % 2 == 0 { 1.0 } else { -1.0 } + 1.0;
            }
            for s in &out {
                assert_eq!(s.map(f64::to_bits), expect.map(f64::to_bits), "{n} ranks");
            }
        }
    }

    /// A NaN on one rank reaches every rank through the maximum (a blow-up is never hidden).
    #[test]
    fn nan_wins_the_maximum() {
        let out = ThreadComm::run(3, |c| {
            let mut v = [if c.rank() == 1 { f64::NAN } else { 1.0 }];
            c.all_max_f64(&mut v);
            v[0]
        });
        assert!(out.iter().all(|v| v.is_nan()));
    }

    /// A rank that panics makes the others fail at their next collective instead of waiting forever.
    #[test]
    fn a_failing_rank_never_leaves_the_others_waiting() {
        let res = std::panic::catch_unwind(|| {
            ThreadComm::run(3, |c| {
                if c.rank() == 2 {
                    panic!("rank 2 fails");
                }
                c.barrier();
            })
        });
        assert!(res.is_err());
    }

    /// Peer lists that are not symmetric are a programming error and are reported, not waited on.
    #[test]
    fn asymmetric_peers_are_reported() {
        let res = std::panic::catch_unwind(|| {
            ThreadComm::run(2, |c| {
                let peers = if c.rank() == 0 { vec![1] } else { vec![] };
                let out = vec![vec![1u8]; peers.len()];
                c.neighbour_exchange(&peers, &out);
            })
        });
        assert!(res.is_err());
    }

    #[test]
    fn serial_world_is_the_identity() {
        let c: &dyn Comm = &SERIAL;
        let mut v = [1.5, -2.0];
        c.all_max_f64(&mut v);
        c.sum_f64_ordered(&mut v);
        assert_eq!(v, [1.5, -2.0]);
        assert_eq!(c.neighbour_exchange(&[0], &[vec![3]]), vec![vec![3]]);
        assert_eq!(c.gather_bytes(0, &[4]), Some(vec![vec![4]]));
        assert!(c.is_root());
    }

    #[test]
    fn wire_round_trip_and_truncation() {
        let mut w = WireWriter::default();
        w.u32(7).u64(u64::MAX).f64(-0.0).vec3(Vec3::new(1.0, f64::MIN_POSITIVE, 3.5)).bytes(b"abc");
        let buf = w.finish();
        let mut r = WireReader::new(&buf);
        assert_eq!(r.u32(), Ok(7));
        assert_eq!(r.u64(), Ok(u64::MAX));
        assert_eq!(r.f64().map(f64::to_bits), Ok((-0.0f64).to_bits()));
        assert_eq!(r.vec3(), Ok(Vec3::new(1.0, f64::MIN_POSITIVE, 3.5)));
        assert_eq!(r.bytes(), Ok(&b"abc"[..]));
        assert!(r.is_done());
        assert_eq!(r.u32(), Err(WireError { at: buf.len(), wanted: 4, len: buf.len() }));
        let mut short = WireReader::new(&buf[..10]);
        short.u32().unwrap();
        assert!(short.u64().is_err());
    }
}
