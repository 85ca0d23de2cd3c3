//! [`MpiComm`]: the [`Comm`] collectives over `MPI_COMM_WORLD`.

use crate::{Launch, LaunchError};
use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::SimpleCommunicator;
use mpi::traits::*;
use mpi::Count;
use spatter_core::comm::Comm;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

/// Message tags of the two rounds of a neighbour exchange (sizes, then payloads).
const TAG_SIZES: i32 = 0x5A11;
const TAG_DATA: i32 = 0x5A12;

/// The ranks of `MPI_COMM_WORLD`. It keeps no MPI handle (the world communicator is looked up per call),
/// so it is `Send + Sync` without unsafe code; it must only be used while the [`Launch`] that made it lives.
#[derive(Debug)]
pub struct MpiComm {
    rank: usize,
    size: usize,
    /// MPI granted calls from any thread, one at a time (`MPI_THREAD_SERIALIZED` or more).
    any_thread: bool,
    /// Nanoseconds spent inside the collectives ([`Comm::seconds_in_collectives`]).
    waited_ns: AtomicU64,
}

pub(crate) fn init(launcher_rank: usize) -> Result<Launch, LaunchError> {
    // Serialized: rayon's worker threads compute, and the one that runs the step (a worker, see
    // `Comm::calls_from_any_thread`) calls MPI. An MPI that grants less keeps the steps on the main
    // thread (funneled).
    let Some((universe, level)) = mpi::initialize_with_threading(mpi::Threading::Serialized) else {
        return Err(LaunchError {
            rank: launcher_rank,
            message: "MPI was already initialised in this process".into(),
        });
    };
    let world = universe.world();
    let any_thread = level >= mpi::Threading::Serialized;
    let comm = MpiComm {
        rank: world.rank() as usize,
        size: world.size() as usize,
        any_thread,
        waited_ns: AtomicU64::new(0),
    };
    // A panic on one rank must end the whole job, never leave the other ranks waiting in a collective.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        default_hook(info);
        eprintln!("rank {}: aborting all ranks after the error above", comm_rank());
        SimpleCommunicator::world().abort(101);
    }));
    Ok(Launch { comm: Box::new(comm), _universe: Some(universe) })
}

fn comm_rank() -> i32 {
    SimpleCommunicator::world().rank()
}

fn world() -> SimpleCommunicator {
    SimpleCommunicator::world()
}

/// Offsets of consecutive blocks of the given sizes.
fn displacements(counts: &[Count]) -> Vec<Count> {
    counts
        .iter()
        .scan(0, |at, &c| {
            let d = *at;
            *at += c;
            Some(d)
        })
        .collect()
}

fn count(len: usize) -> Count {
    // MPI counts are C ints: a message above 2 GiB is a decomposition bug, not an input error.
    Count::try_from(len).expect("an MPI message above 2^31 bytes")
}

fn split(buf: &[u8], counts: &[Count], displs: &[Count]) -> Vec<Vec<u8>> {
    counts.iter().zip(displs).map(|(&c, &d)| buf[d as usize..(d + c) as usize].to_vec()).collect()
}

/// The collectives themselves; the [`Comm`] methods time them.
impl MpiComm {
    /// Runs one collective and adds its wall time to [`Comm::seconds_in_collectives`] (two clock reads,
    /// about 50 ns, against the call's microsecond).
    fn timed<T>(&self, call: impl FnOnce() -> T) -> T {
        let started = Instant::now();
        let out = call();
        let ns = u64::try_from(started.elapsed().as_nanos()).unwrap_or(u64::MAX);
        self.waited_ns.fetch_add(ns, Ordering::Relaxed);
        out
    }

    fn untimed_all_gather_bytes(&self, local: &[u8]) -> Vec<Vec<u8>> {
        let w = world();
        let mut counts = vec![0 as Count; self.size];
        w.all_gather_into(&count(local.len()), &mut counts[..]);
        let displs = displacements(&counts);
        let mut buf = vec![0u8; counts.iter().map(|&c| c as usize).sum()];
        // Every rank knows every count: when all are zero no payload round is needed (and OpenMPI would
        // reject the empty buffers).
        if !buf.is_empty() {
            let mut part = PartitionMut::new(&mut buf[..], &counts[..], &displs[..]);
            w.all_gather_varcount_into(local, &mut part);
        }
        split(&buf, &counts, &displs)
    }
    fn untimed_neighbour_exchange(&self, peers: &[usize], out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        assert_eq!(peers.len(), out.len(), "one buffer per peer");
        let w = world();
        let n = peers.len();
        let sizes: Vec<u64> = out.iter().map(|b| b.len() as u64).collect();
        let mut got_sizes = vec![0u64; n];
        mpi::request::multiple_scope(2 * n, |scope, requests| {
            for (k, &p) in peers.iter().enumerate() {
                if p != self.rank {
                    requests.add(
                        w.process_at_rank(p as i32).immediate_send_with_tag(scope, &sizes[k], TAG_SIZES),
                    );
                }
            }
            for (k, slot) in got_sizes.iter_mut().enumerate() {
                if peers[k] != self.rank {
                    requests.add(
                        w.process_at_rank(peers[k] as i32)
                            .immediate_receive_into_with_tag(scope, slot, TAG_SIZES),
                    );
                }
            }
            let mut done = Vec::new();
            requests.wait_all(&mut done);
        });
        let mut got: Vec<Vec<u8>> = got_sizes.iter().map(|&s| vec![0u8; s as usize]).collect();
        for (k, &p) in peers.iter().enumerate() {
            if p == self.rank {
                got[k] = out[k].clone();
            }
        }
        mpi::request::multiple_scope(2 * n, |scope, requests| {
            // Empty payloads are not sent: both sides know the size from the first round.
            for (k, &p) in peers.iter().enumerate() {
                if p != self.rank && !out[k].is_empty() {
                    requests.add(w.process_at_rank(p as i32).immediate_send_with_tag(
                        scope,
                        &out[k][..],
                        TAG_DATA,
                    ));
                }
            }
            for (k, buf) in got.iter_mut().enumerate() {
                if peers[k] != self.rank && !buf.is_empty() {
                    requests.add(w.process_at_rank(peers[k] as i32).immediate_receive_into_with_tag(
                        scope,
                        &mut buf[..],
                        TAG_DATA,
                    ));
                }
            }
            let mut done = Vec::new();
            requests.wait_all(&mut done);
        });
        got
    }
    fn untimed_all_to_all_bytes(&self, out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        assert_eq!(out.len(), self.size, "one buffer per rank");
        let w = world();
        let send_counts: Vec<Count> = out.iter().map(|b| count(b.len())).collect();
        let mut recv_counts = vec![0 as Count; self.size];
        w.all_to_all_into(&send_counts[..], &mut recv_counts[..]);
        let flat = out.concat();
        let send_displs = displacements(&send_counts);
        let recv_displs = displacements(&recv_counts);
        let mut buf = vec![0u8; recv_counts.iter().map(|&c| c as usize).sum()];
        {
            let send = Partition::new(&flat[..], &send_counts[..], &send_displs[..]);
            let mut recv = PartitionMut::new(&mut buf[..], &recv_counts[..], &recv_displs[..]);
            w.all_to_all_varcount_into(&send, &mut recv);
        }
        split(&buf, &recv_counts, &recv_displs)
    }
    fn untimed_gather_bytes(&self, root: usize, local: &[u8]) -> Option<Vec<Vec<u8>>> {
        let w = world();
        let root_process = w.process_at_rank(root as i32);
        let n = count(local.len());
        if self.rank != root {
            root_process.gather_into(&n);
            root_process.gather_varcount_into(local);
            return None;
        }
        let mut counts = vec![0 as Count; self.size];
        root_process.gather_into_root(&n, &mut counts[..]);
        let displs = displacements(&counts);
        let mut buf = vec![0u8; counts.iter().map(|&c| c as usize).sum()];
        {
            let mut part = PartitionMut::new(&mut buf[..], &counts[..], &displs[..]);
            root_process.gather_varcount_into_root(local, &mut part);
        }
        Some(split(&buf, &counts, &displs))
    }
    fn untimed_broadcast_bytes(&self, root: usize, buf: &mut Vec<u8>) {
        let w = world();
        let root_process = w.process_at_rank(root as i32);
        let mut len = buf.len() as u64;
        root_process.broadcast_into(&mut len);
        buf.resize(len as usize, 0);
        // OpenMPI rejects the dangling pointer of an empty slice (MPI_ERR_ARG); every rank knows the
        // length now, so an empty payload is simply not sent.
        if len > 0 {
            root_process.broadcast_into(&mut buf[..]);
        }
    }
}

impl Comm for MpiComm {
    fn rank(&self) -> usize {
        self.rank
    }
    fn size(&self) -> usize {
        self.size
    }
    fn calls_from_any_thread(&self) -> bool {
        self.any_thread
    }
    fn all_max_f64(&self, values: &mut [f64]) {
        // MPI_MAX on doubles: exact in any order. A NaN is turned into +∞ first so that it wins on every
        // rank (MPI leaves comparisons with NaN to the C library).
        let local: Vec<f64> = values.iter().map(|&v| if v.is_nan() { f64::INFINITY } else { v }).collect();
        let had_nan: Vec<u64> = values.iter().map(|v| u64::from(v.is_nan())).collect();
        let mut nan = vec![0u64; values.len()];
        self.timed(|| {
            let w = world();
            w.all_reduce_into(&local[..], values, SystemOperation::max());
            w.all_reduce_into(&had_nan[..], &mut nan[..], SystemOperation::sum());
        });
        for (v, n) in values.iter_mut().zip(nan) {
            if n > 0 {
                *v = f64::NAN;
            }
        }
    }
    fn all_sum_u64(&self, values: &mut [u64]) {
        let local = values.to_vec();
        self.timed(|| world().all_reduce_into(&local[..], values, SystemOperation::sum()));
    }
    fn all_gather_bytes(&self, local: &[u8]) -> Vec<Vec<u8>> {
        self.timed(|| self.untimed_all_gather_bytes(local))
    }
    fn neighbour_exchange(&self, peers: &[usize], out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        self.timed(|| self.untimed_neighbour_exchange(peers, out))
    }
    fn all_to_all_bytes(&self, out: &[Vec<u8>]) -> Vec<Vec<u8>> {
        self.timed(|| self.untimed_all_to_all_bytes(out))
    }
    fn gather_bytes(&self, root: usize, local: &[u8]) -> Option<Vec<Vec<u8>>> {
        self.timed(|| self.untimed_gather_bytes(root, local))
    }
    fn broadcast_bytes(&self, root: usize, buf: &mut Vec<u8>) {
        self.timed(|| self.untimed_broadcast_bytes(root, buf))
    }
    fn barrier(&self) {
        self.timed(|| world().barrier());
    }
    fn seconds_in_collectives(&self) -> f64 {
        self.waited_ns.load(Ordering::Relaxed) as f64 * 1e-9
    }
    fn abort(&self, code: i32) -> ! {
        world().abort(code)
    }
}
