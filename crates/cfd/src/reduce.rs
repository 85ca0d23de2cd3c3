//! Parallel loops over k-planes and reductions whose result does not depend on the number of threads.
//!
//! Every reduction sums each interior plane sequentially in index order and then adds the plane sums in
//! plane order, so the floating-point result is the same for 1, 2 or 64 threads.

use crate::grid::{Layout, GHOST};
use rayon::prelude::*;

/// Sum over interior cells of `f(c)` (padded index `c`), deterministic for any thread count.
pub fn sum_interior(l: &Layout, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let partial: Vec<f64> = (GHOST..GHOST + l.n[2])
        .into_par_iter()
        .map(|k| {
            let mut s = 0.0;
            for j in GHOST..GHOST + l.n[1] {
                let row = l.at(0, j, k);
                for i in GHOST..GHOST + l.n[0] {
                    s += f(row + i);
                }
            }
            s
        })
        .collect();
    partial.iter().sum()
}

/// Maximum over interior cells of `f(c)`; NaN wins (so a NaN field is never reported as small).
pub fn max_interior(l: &Layout, f: impl Fn(usize) -> f64 + Sync) -> f64 {
    let partial: Vec<f64> = (GHOST..GHOST + l.n[2])
        .into_par_iter()
        .map(|k| {
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
        })
        .collect();
    partial.iter().fold(f64::NEG_INFINITY, |a, &b| if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) })
}

/// Dot product over interior cells.
pub fn dot(l: &Layout, a: &[f64], b: &[f64]) -> f64 {
    sum_interior(l, |c| a[c] * b[c])
}

/// Runs `f(k, plane)` in parallel for every interior k-plane of `v` (`plane` is the whole padded plane k).
pub fn for_planes(l: &Layout, v: &mut [f64], f: impl Fn(usize, &mut [f64]) + Sync) {
    let n = l.plane();
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
