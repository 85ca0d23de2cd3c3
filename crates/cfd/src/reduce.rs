//! Parallel loops over k-planes and reductions whose result does not depend on the number of threads.
//!
//! Every reduction sums each interior plane sequentially in index order and then adds the plane sums in
//! plane order, so the floating-point result is the same for 1, 2 or 64 threads.
//!
//! Two things keep the overhead of the many short parallel loops of a time step (a pressure solve is a
//! few hundred of them, on multigrid levels down to a handful of cells) small:
//! * a layout with fewer than [`PARALLEL_MIN_CELLS`] padded cells is looped over on the calling thread
//!   (the same per-plane arithmetic, so the same bits);
//! * [`in_pool`] runs a whole step on a worker thread of the pool: a parallel loop started from a
//!   thread outside the pool (the program's main thread) hands its work to the pool and sleeps until
//!   it is done, a round trip through the scheduler per loop; started from a worker it costs nothing
//!   when the other workers are busy or absent.

use crate::grid::{Layout, GHOST};
use rayon::prelude::*;

/// Layouts with fewer padded cells than this are looped over on the calling thread: below it the cost
/// of sharing the work exceeds the work (a 3 µs loop against tens of µs of thread wake-ups).
pub const PARALLEL_MIN_CELLS: usize = 8192;

/// Whether loops over `l` run in parallel.
#[inline]
fn parallel(l: &Layout) -> bool {
    l.len() >= PARALLEL_MIN_CELLS
}

/// Runs `f` on a worker thread of the current rayon pool (directly when already on one) and returns its
/// result; see the module docs.
pub fn in_pool<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    rayon::scope(|_| f())
}

/// Sum over interior cells of `f(c)` (padded index `c`), deterministic for any thread count.
pub fn sum_interior(l: &Layout, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let plane_sum = |k: usize| {
        let mut s = 0.0;
        for j in GHOST..GHOST + l.n[1] {
            let row = l.at(0, j, k);
            for i in GHOST..GHOST + l.n[0] {
                s += f(row + i);
            }
        }
        s
    };
    let planes = GHOST..GHOST + l.n[2];
    if !parallel(l) {
        // Plane sums added in plane order, as below.
        return planes.map(plane_sum).sum();
    }
    let partial: Vec<f64> = planes.into_par_iter().map(plane_sum).collect();
    partial.iter().sum()
}

/// Maximum over interior cells of `f(c)`; NaN wins (so a NaN field is never reported as small).
pub fn max_interior(l: &Layout, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let plane_max = |k: usize| {
        let mut m = f64::NEG_INFINITY;
        for j in GHOST..GHOST + l.n[1] {
            let row = l.at(0, j, k);
            for i in GHOST..GHOST + l.n[0] {
                let v = f(row + i);
                if v.is_nan() || v > m {
                    m = v;
                    if v.is_nan() {
                        return f64::NAN;
                    }
                }
            }
        }
        m
    };
    let planes = GHOST..GHOST + l.n[2];
    let partial: Vec<f64> = if parallel(l) {
        planes.into_par_iter().map(plane_max).collect()
    } else {
        planes.map(plane_max).collect()
    };
    partial.iter().fold(f64::NEG_INFINITY, |a, &b| if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) })
}

/// Dot product over interior cells.
pub fn dot(l: &Layout, a: &[f64], b: &[f64]) -> f64 {
    sum_interior(l, |c| a[c] * b[c])
}

/// Runs `f(k, plane)` in parallel for every interior k-plane of `v` (`plane` is the whole padded plane k).
pub fn for_planes(l: &Layout, v: &mut [f64], f: impl Fn(usize, &mut [f64]) + Sync) {
    let n = l.plane();
    if !parallel(l) {
        for (k, plane) in v.chunks_mut(n).enumerate().take(GHOST + l.n[2]).skip(GHOST) {
            f(k, plane)
        }
        return;
    }
    v.par_chunks_mut(n).enumerate().for_each(|(k, plane)| {
        if k >= GHOST && k < GHOST + l.n[2] {
            f(k, plane)
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sums_are_the_same_on_one_and_two_threads() {
        let l = Layout::new([17, 13, 11]);
        let v: Vec<f64> =
            (0..l.len()).map(|i| ((i as f64) * 0.618).sin() * 1e3 + 1.0 / (i as f64 + 1.0)).collect();
        let run = |t: usize| {
            rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap().install(|| dot(&l, &v, &v))
        };
        assert_eq!(run(1).to_bits(), run(2).to_bits());
        assert_eq!(run(1).to_bits(), run(3).to_bits());
    }
}
