//! Variance-based (Sobol) sensitivity indices from a Saltelli sampling design.
//!
//! For a model Y = f(X₁, …, X_k) with independent inputs, the first-order index S_i = V[E(Y|X_i)]/V(Y) is
//! the share of the output variance explained by X_i alone, and the total index S_Ti = E[V(Y|X₋ᵢ)]/V(Y)
//! the share that involves X_i in any way (alone or in interactions). S_Ti − S_i measures interactions;
//! S_Ti ≈ 0 means the input can be fixed anywhere in its range.
//!
//! Design (Saltelli 2002; Saltelli et al. 2010, "Variance based sensitivity analysis of model output.
//! Design and estimator for the total sensitivity index", Comput. Phys. Commun. 181, 259–270): two N × k
//! matrices A and B of quasi-random points in the unit cube (the first and last k coordinates of a
//! 2k-dimensional Owen-scrambled Sobol sequence), and for every input i the matrix A_B⁽ⁱ⁾, which is A with
//! column i taken from B. The model runs N(k + 2) times. Run r belongs to block r / N (0 = A, 1 = B,
//! 2 + i = A_B⁽ⁱ⁾) and row r mod N.
//!
//! Estimators (Saltelli et al. 2010, Table 2):
//! * first order (their (b)):  V_i ≈ (1/N) Σ_j (f(B)_j − f̄) · (f(A_B⁽ⁱ⁾)_j − f(A)_j), with f(B) centred on the
//!   mean f̄ of the A and B outputs (same expectation, lower variance for outputs far from zero);
//! * total (Jansen 1999, their (f)):  V_Ti ≈ (1/2N) Σ_j (f(A)_j − f(A_B⁽ⁱ⁾)_j)²;
//!
//! both divided by the variance of all 2N outputs of A and B. Confidence intervals come from a seeded
//! bootstrap over the rows j (percentile method), so they are reproducible.

use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// The Saltelli design for `k` inputs and `n` base samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SaltelliDesign {
    /// Base sample count N (rows of A and B).
    pub n: usize,
    /// Number of varied inputs k.
    pub k: usize,
    /// Scramble seed of the Sobol sequence.
    pub seed: u32,
}

/// Largest k the design supports: 2k Sobol dimensions, and the sequence has 256.
pub const MAX_INPUTS: usize = 128;
/// Largest N the design supports (the sequence's length).
pub const MAX_SAMPLES: usize = 1 << 16;

impl SaltelliDesign {
    /// Model runs the design needs: N(k + 2).
    pub fn runs(&self) -> usize {
        self.n * (self.k + 2)
    }

    /// The unit-cube point of run `r` (0 ≤ r < [`runs`](Self::runs)), one coordinate per input in [0, 1).
    pub fn point(&self, r: usize) -> Vec<f64> {
        let (block, j) = (r / self.n, r % self.n);
        let coord = |dim: usize| f64::from(sobol_burley::sample(j as u32, dim as u32, self.seed));
        (0..self.k)
            .map(|i| match block {
                0 => coord(i),
                1 => coord(self.k + i),
                b if b - 2 == i => coord(self.k + i),
                _ => coord(i),
            })
            .collect()
    }
}

/// Sensitivity indices of one output with respect to one input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Indices {
    /// First-order index S_i.
    pub first: f64,
    /// 95 % bootstrap interval of S_i.
    pub first_ci: (f64, f64),
    /// Total index S_Ti.
    pub total: f64,
    /// 95 % bootstrap interval of S_Ti.
    pub total_ci: (f64, f64),
}

/// Why indices cannot be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SensitivityError {
    #[error("expected {expected} outputs (N(k + 2) of the design), got {found}")]
    Length { expected: usize, found: usize },
    #[error("output of run {run} is {value}; indices need a finite output for every run")]
    NotFinite { run: usize, value: f64 },
    #[error("the output does not vary over the samples of A and B (variance 0); its indices are undefined")]
    Constant,
}

/// First-order and total indices of every input, from the outputs `f` of the design's runs in run order.
/// `bootstrap` resamples (0 for no intervals: they are then the point estimates) with generator `seed`.
pub fn indices(
    design: &SaltelliDesign,
    f: &[f64],
    bootstrap: usize,
    seed: u64,
) -> Result<Vec<Indices>, SensitivityError> {
    if f.len() != design.runs() {
        return Err(SensitivityError::Length { expected: design.runs(), found: f.len() });
    }
    if let Some((run, &value)) = f.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(SensitivityError::NotFinite { run, value });
    }
    let n = design.n;
    let rows: Vec<usize> = (0..n).collect();
    if estimate(design, f, &rows, 0).is_none() {
        return Err(SensitivityError::Constant);
    }
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut samples: Vec<Vec<(f64, f64)>> = vec![Vec::with_capacity(bootstrap); design.k];
    let mut resampled = vec![0usize; n];
    for _ in 0..bootstrap {
        for r in resampled.iter_mut() {
            *r = rng.random_range(0..n);
        }
        for (i, s) in samples.iter_mut().enumerate() {
            // A resample whose A and B outputs happen to be constant carries no information: skip it.
            if let Some(e) = estimate(design, f, &resampled, i) {
                s.push(e);
            }
        }
    }
    Ok((0..design.k)
        .map(|i| {
            let (first, total) = estimate(design, f, &rows, i).unwrap_or((f64::NAN, f64::NAN));
            let ci = |pick: fn(&(f64, f64)) -> f64, point: f64| {
                let mut v: Vec<f64> = samples[i].iter().map(pick).collect();
                if v.is_empty() {
                    return (point, point);
                }
                v.sort_by(f64::total_cmp);
                (percentile(&v, 0.025), percentile(&v, 0.975))
            };
            Indices { first, first_ci: ci(|e| e.0, first), total, total_ci: ci(|e| e.1, total) }
        })
        .collect())
}

/// (S_i, S_Ti) of input `i` over the given rows (with repetition for a bootstrap resample); `None` when the
/// outputs of A and B on those rows have no variance.
fn estimate(design: &SaltelliDesign, f: &[f64], rows: &[usize], i: usize) -> Option<(f64, f64)> {
    let n = design.n;
    let (fa, fb, fab) = (&f[..n], &f[n..2 * n], &f[(2 + i) * n..(3 + i) * n]);
    let m = rows.len() as f64;
    let mean = rows.iter().map(|&j| fa[j] + fb[j]).sum::<f64>() / (2.0 * m);
    let var = rows.iter().map(|&j| (fa[j] - mean).powi(2) + (fb[j] - mean).powi(2)).sum::<f64>() / (2.0 * m);
    if var <= 0.0 || !var.is_finite() {
        return None;
    }
    // f(B) enters centred on the sample mean: the same expectation (E[f(A_B) − f(A)] = 0), a much smaller
    // variance when the output's mean is large against its spread.
    let first = rows.iter().map(|&j| (fb[j] - mean) * (fab[j] - fa[j])).sum::<f64>() / m;
    let total = rows.iter().map(|&j| (fa[j] - fab[j]).powi(2)).sum::<f64>() / (2.0 * m);
    Some((first / var, total / var))
}

/// Linear-interpolated percentile `q` ∈ [0, 1] of sorted values.
fn percentile(sorted: &[f64], q: f64) -> f64 {
    let x = q * (sorted.len() - 1) as f64;
    let lo = x.floor() as usize;
    let hi = (lo + 1).min(sorted.len() - 1);
    sorted[lo] + (x - lo as f64) * (sorted[hi] - sorted[lo])
}

/// `n` points of a Latin hypercube in [0, 1)^k: every coordinate's range is cut into n equal strata and
/// each stratum holds exactly one point (McKay, Beckman & Conover 1979), with a random position inside it.
pub fn latin_hypercube(n: usize, k: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut points = vec![vec![0.0; k]; n];
    let mut perm: Vec<usize> = (0..n).collect();
    for dim in 0..k {
        // Fisher–Yates shuffle with the seeded generator.
        for a in (1..n).rev() {
            let b = rng.random_range(0..=a);
            perm.swap(a, b);
        }
        for (j, p) in points.iter_mut().enumerate() {
            let u: f64 = rng.random();
            p[dim] = (perm[j] as f64 + u) / n as f64;
        }
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The Ishigami function (Ishigami & Homma 1990) on x ∈ [−π, π]³ with a = 7, b = 0.1.
    fn ishigami(u: &[f64]) -> f64 {
        let x: Vec<f64> = u.iter().map(|&t| -PI + 2.0 * PI * t).collect();
        x[0].sin() + 7.0 * x[1].sin().powi(2) + 0.1 * x[2].powi(4) * x[0].sin()
    }

    /// Exact indices of the Ishigami function for a = 7, b = 0.1 (Sobol' & Levitan 1999; e.g. Saltelli et
    /// al. 2010 §4): V = a²/8 + bπ⁴/5 + b²π⁸/18 + 1/2, V₁ = (1 + bπ⁴/5)²/2, V₂ = a²/8, V₃ = 0,
    /// V₁₃ = 8b²π⁸/225.
    fn exact() -> ([f64; 3], [f64; 3]) {
        let (a, b) = (7.0_f64, 0.1_f64);
        let v = a * a / 8.0 + b * PI.powi(4) / 5.0 + b * b * PI.powi(8) / 18.0 + 0.5;
        let v1 = 0.5 * (1.0 + b * PI.powi(4) / 5.0).powi(2);
        let v2 = a * a / 8.0;
        let v13 = 8.0 * b * b * PI.powi(8) / 225.0;
        ([v1 / v, v2 / v, 0.0], [(v1 + v13) / v, v2 / v, v13 / v])
    }

    #[test]
    fn exact_ishigami_values_are_the_published_ones() {
        // Published to four digits: S = 0.3139, 0.4424, 0; S_T = 0.5576, 0.4424, 0.2437.
        let (s, st) = exact();
        for (got, want) in s.iter().chain(st.iter()).zip([0.3139, 0.4424, 0.0, 0.5576, 0.4424, 0.2437]) {
            assert!((got - want).abs() < 5e-5, "{got} vs {want}");
        }
    }

    #[test]
    fn ishigami_indices_match_the_exact_values() {
        // N = 2^13 base samples (57 344 runs). Tolerance 0.02 absolute on every index: the Saltelli/Jansen
        // estimators with Sobol points have errors of a few 1e-3 at this N (Saltelli et al. 2010, Fig. 3).
        let d = SaltelliDesign { n: 1 << 13, k: 3, seed: 7 };
        let f: Vec<f64> = (0..d.runs()).map(|r| ishigami(&d.point(r))).collect();
        let got = indices(&d, &f, 100, 1).unwrap();
        let (s, st) = exact();
        for i in 0..3 {
            assert!((got[i].first - s[i]).abs() < 0.02, "S{} = {} vs {}", i + 1, got[i].first, s[i]);
            assert!((got[i].total - st[i]).abs() < 0.02, "ST{} = {} vs {}", i + 1, got[i].total, st[i]);
            // The intervals hold the estimate, and their half-width (about two standard errors, ≈ 0.013 for
            // the total index at this N) is below 0.05.
            assert!(got[i].first_ci.0 <= got[i].first && got[i].first <= got[i].first_ci.1);
            assert!(got[i].total_ci.1 - got[i].total_ci.0 < 0.1, "{:?}", got[i]);
            assert!(got[i].first_ci.1 - got[i].first_ci.0 < 0.1, "{:?}", got[i]);
        }
    }

    #[test]
    fn an_additive_model_has_equal_first_and_total_indices() {
        // Y = X1 + 2 X2 on the unit square: V1 : V2 = 1 : 4, no interactions, so S = ST = (0.2, 0.8).
        let d = SaltelliDesign { n: 4096, k: 2, seed: 3 };
        let f: Vec<f64> = (0..d.runs()).map(|r| d.point(r)).map(|p| p[0] + 2.0 * p[1]).collect();
        let got = indices(&d, &f, 0, 0).unwrap();
        for (g, want) in got.iter().zip([0.2, 0.8]) {
            assert!((g.first - want).abs() < 0.01 && (g.total - want).abs() < 0.01, "{g:?}");
        }
    }

    #[test]
    fn design_blocks_take_the_right_columns() {
        let d = SaltelliDesign { n: 8, k: 3, seed: 0 };
        assert_eq!(d.runs(), 40);
        let a = d.point(5);
        let b = d.point(8 + 5);
        let ab1 = d.point(3 * 8 + 5); // A with column 1 from B
        assert_eq!(ab1, vec![a[0], b[1], a[2]]);
        assert!(a.iter().chain(&b).all(|u| (0.0..1.0).contains(u)));
    }

    #[test]
    fn bad_outputs_are_refused() {
        let d = SaltelliDesign { n: 4, k: 1, seed: 0 };
        assert!(matches!(indices(&d, &[1.0; 5], 0, 0), Err(SensitivityError::Length { .. })));
        let mut f = vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 1.0, 2.0, 3.0, 4.0];
        assert!(matches!(indices(&d, &[2.0; 12], 0, 0), Err(SensitivityError::Constant)));
        f[9] = f64::NAN;
        assert!(matches!(indices(&d, &f, 0, 0), Err(SensitivityError::NotFinite { run: 9, .. })));
    }

    #[test]
    fn latin_hypercube_fills_every_stratum_once() {
        let pts = latin_hypercube(16, 3, 42);
        for dim in 0..3 {
            let mut strata: Vec<usize> = pts.iter().map(|p| (p[dim] * 16.0) as usize).collect();
            strata.sort_unstable();
            assert_eq!(strata, (0..16).collect::<Vec<_>>());
        }
        assert_eq!(pts, latin_hypercube(16, 3, 42), "seeded");
    }
}
