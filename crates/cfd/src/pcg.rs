//! Conjugate gradients preconditioned by the multigrid V-cycle of [`crate::mg`].
//!
//! Stops when ‖b − A x‖₂ ≤ `rtol`·‖b‖₂ (or ‖b‖₂ is below `atol`). For a singular operator (no Dirichlet
//! face) the right-hand side and every preconditioned residual are projected onto zero mean over the active
//! cells, so the iteration stays in the range of A. Dot products use the thread-independent sums of
//! [`crate::reduce`].

use crate::grid::GHOST;
use crate::mg::Multigrid;
use crate::reduce::{dot, for_planes, sum_interior};

/// Solver settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PcgSettings {
    /// Relative residual target.
    pub rtol: f64,
    /// Absolute residual norm below which nothing is done.
    pub atol: f64,
    pub max_iterations: usize,
}

impl Default for PcgSettings {
    fn default() -> Self {
        PcgSettings { rtol: 1e-8, atol: 1e-300, max_iterations: 200 }
    }
}

/// Outcome of one solve.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PcgReport {
    pub iterations: usize,
    /// Final ‖r‖₂ / ‖b‖₂ (0 when b = 0).
    pub relative_residual: f64,
    pub converged: bool,
}

/// Work vectors of the solver.
#[derive(Clone, Debug)]
pub struct Pcg {
    pub mg: Multigrid,
    r: Vec<f64>,
    z: Vec<f64>,
    p: Vec<f64>,
    q: Vec<f64>,
    active_count: f64,
}

impl Pcg {
    pub fn new(mg: Multigrid) -> Self {
        let n = mg.op().layout.len();
        let op = mg.op();
        let active_count = sum_interior(&op.layout, |c| if op.active(c) { 1.0 } else { 0.0 });
        Pcg { mg, r: vec![0.0; n], z: vec![0.0; n], p: vec![0.0; n], q: vec![0.0; n], active_count }
    }

    /// Bytes held on the heap (multigrid levels and the four CG vectors).
    pub fn heap_bytes(&self) -> u64 {
        self.mg.heap_bytes()
            + 8 * (self.r.capacity() + self.z.capacity() + self.p.capacity() + self.q.capacity()) as u64
    }

    /// Subtracts the mean over active cells.
    fn project(&self, v: &mut [f64]) {
        let op = self.mg.op();
        let l = op.layout;
        let mean = sum_interior(&l, |c| if op.active(c) { v[c] } else { 0.0 }) / self.active_count.max(1.0);
        let diag = &op.diag;
        for_planes(&l, v, |k, plane| {
            let base = k * l.s[2];
            for j in GHOST..GHOST + l.n[1] {
                for i in GHOST..GHOST + l.n[0] {
                    let c = base + j * l.s[1] + i;
                    if diag[c] > 0.0 {
                        plane[c - base] -= mean;
                    }
                }
            }
        });
    }

    /// Solves A x = b, starting from the given x. `b` may be modified (projected) for singular operators.
    pub fn solve(&mut self, b: &mut [f64], x: &mut [f64], s: &PcgSettings) -> PcgReport {
        let singular = self.mg.op().singular;
        let l = self.mg.op().layout;
        if singular {
            self.project(b);
        }
        let bnorm = dot(&l, b, b).sqrt();
        if bnorm <= s.atol {
            return PcgReport { iterations: 0, relative_residual: 0.0, converged: true };
        }
        self.mg.op().residual(x, b, &mut self.r);
        if singular {
            let mut r = std::mem::take(&mut self.r);
            self.project(&mut r);
            self.r = r;
        }
        let target = (s.rtol * bnorm).max(s.atol);
        let mut rnorm = dot(&l, &self.r, &self.r).sqrt();
        if rnorm <= target {
            return PcgReport { iterations: 0, relative_residual: rnorm / bnorm, converged: true };
        }
        self.mg.precondition(&self.r, &mut self.z);
        if singular {
            let mut z = std::mem::take(&mut self.z);
            self.project(&mut z);
            self.z = z;
        }
        self.p.copy_from_slice(&self.z);
        let mut rz = dot(&l, &self.r, &self.z);
        for it in 1..=s.max_iterations {
            self.mg.op().apply(&self.p, &mut self.q);
            let pq = dot(&l, &self.p, &self.q);
            if pq.is_nan() || pq <= 0.0 {
                return PcgReport { iterations: it, relative_residual: rnorm / bnorm, converged: false };
            }
            let alpha = rz / pq;
            let (p, q) = (&self.p, &self.q);
            for_planes(&l, x, |k, plane| {
                let base = k * l.s[2];
                for (o, v) in plane.iter_mut().enumerate() {
                    *v += alpha * p[base + o];
                }
            });
            for_planes(&l, &mut self.r, |k, plane| {
                let base = k * l.s[2];
                for (o, v) in plane.iter_mut().enumerate() {
                    *v -= alpha * q[base + o];
                }
            });
            rnorm = dot(&l, &self.r, &self.r).sqrt();
            if rnorm <= target {
                return PcgReport { iterations: it, relative_residual: rnorm / bnorm, converged: true };
            }
            self.mg.precondition(&self.r, &mut self.z);
            if singular {
                let mut z = std::mem::take(&mut self.z);
                self.project(&mut z);
                self.z = z;
            }
            let rz_new = dot(&l, &self.r, &self.z);
            let beta = rz_new / rz;
            rz = rz_new;
            let z = &self.z;
            for_planes(&l, &mut self.p, |k, plane| {
                let base = k * l.s[2];
                for (o, v) in plane.iter_mut().enumerate() {
                    *v = z[base + o] + beta * *v;
                }
            });
        }
        PcgReport { iterations: s.max_iterations, relative_residual: rnorm / bnorm, converged: false }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::Layout;
    use crate::mg::Stencil;

    fn neumann_box(n: [usize; 3]) -> Stencil {
        let l = Layout::new(n);
        let mut s = Stencil::empty(l);
        for k in 0..n[2] {
            for j in 0..n[1] {
                for i in 0..n[0] {
                    let c = l.cell(i, j, k);
                    let q = [i, j, k];
                    for a in 0..3 {
                        if q[a] + 1 < n[a] {
                            s.a[a][c] = 1.0;
                            s.diag[c] += 1.0;
                            s.diag[l.cell(i, j, k) + l.s[a]] += 1.0;
                        }
                    }
                }
            }
        }
        s
    }

    #[test]
    fn pcg_solves_a_singular_neumann_problem_in_few_iterations_and_identically_on_any_thread_count() {
        let op = neumann_box([40, 33, 20]);
        let l = op.layout;
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(|| {
                let mut pcg = Pcg::new(Multigrid::new(op.clone()));
                let mut b: Vec<f64> = (0..l.len())
                    .map(|c| if op.active(c) { (c as f64 * 0.01).sin() + 0.3 } else { 0.0 })
                    .collect();
                let mut x = vec![0.0; l.len()];
                let rep = pcg.solve(&mut b, &mut x, &PcgSettings { rtol: 1e-10, ..Default::default() });
                // True residual.
                let mut r = vec![0.0; l.len()];
                op.residual(&x, &b, &mut r);
                let rel = (dot(&l, &r, &r) / dot(&l, &b, &b)).sqrt();
                (rep, rel, x)
            })
        };
        let (rep, rel, x1) = run(1);
        eprintln!("{rep:?}");
        assert!(rep.converged, "{rep:?}");
        assert!(rel < 1e-9, "true residual {rel}");
        assert!(rep.iterations <= 30, "{rep:?}");
        let (_, _, x2) = run(2);
        assert!(x1.iter().zip(&x2).all(|(a, b)| a.to_bits() == b.to_bits()), "thread-count independent");
    }
}
