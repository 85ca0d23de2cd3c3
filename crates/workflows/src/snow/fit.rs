//! Least-squares polynomial fits of the stick/bounce boundary, in the [`PolyFit`] form the deposition
//! workflow reads.

use spatter_core::regime::PolyFit;

/// Least-squares polynomial of degree `degree` through `(x, y)` points, in log10–log10 space when `log10`
/// (then all values must be positive). The degree is lowered when there are too few points. Returns
/// `None` without points.
///
/// Solved by Householder QR on the Vandermonde matrix of the argument mapped to [−1, 1] (well conditioned),
/// then converted back to coefficients of the plain argument.
pub fn fit_polynomial(
    points: &[(f64, f64)],
    degree: usize,
    log10: bool,
    x_name: &str,
    y_name: &str,
) -> Option<PolyFit> {
    let pts: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(x, y)| x.is_finite() && y.is_finite() && (!log10 || (*x > 0.0 && *y > 0.0)))
        .collect();
    if pts.is_empty() {
        return None;
    }
    let map = |v: f64| if log10 { v.log10() } else { v };
    let us: Vec<f64> = pts.iter().map(|p| map(p.0)).collect();
    let ws: Vec<f64> = pts.iter().map(|p| map(p.1)).collect();
    let (umin, umax) = us.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &u| (a.min(u), b.max(u)));
    let distinct = {
        let mut s = us.clone();
        s.sort_by(f64::total_cmp);
        s.dedup();
        s.len()
    };
    let deg = degree.min(distinct.saturating_sub(1));
    let (c, h) = if umax > umin { (0.5 * (umax + umin), 0.5 * (umax - umin)) } else { (umin, 1.0) };
    let n = pts.len();
    let m = deg + 1;
    // Vandermonde in s = (u − c)/h.
    let mut a = vec![0.0; n * m];
    for (i, &u) in us.iter().enumerate() {
        let s = (u - c) / h;
        let mut p = 1.0;
        for j in 0..m {
            a[i * m + j] = p;
            p *= s;
        }
    }
    let coef_s = least_squares(&mut a, n, m, &ws)?;
    // Expand Σ b_j ((u − c)/h)^j into powers of u.
    let mut coef_u = vec![0.0; m];
    let mut binom = vec![vec![0.0; m]; m];
    for j in 0..m {
        binom[j][0] = 1.0;
        for k in 1..=j {
            binom[j][k] = binom[j - 1][k - 1] + if k < j { binom[j - 1][k] } else { 0.0 };
        }
    }
    for (j, &b) in coef_s.iter().enumerate() {
        // ((u − c)/h)^j = h^{-j} Σ_k C(j,k) u^k (−c)^{j−k}
        let hj = h.powi(j as i32);
        for (k, cu) in coef_u.iter_mut().enumerate().take(j + 1) {
            *cu += b / hj * binom[j][k] * (-c).powi((j - k) as i32);
        }
    }
    let xmin = pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let xmax = pts.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
    let mut fit = PolyFit {
        x: x_name.into(),
        y: y_name.into(),
        log10,
        coefficients: coef_u,
        x_range: [xmin, xmax],
        rms_relative_error: 0.0,
    };
    let sq: f64 = pts.iter().map(|&(x, y)| ((fit.eval(x) - y) / y).powi(2)).sum();
    fit.rms_relative_error = (sq / n as f64).sqrt();
    Some(fit)
}

/// Solves min ‖A b − y‖ for the `n × m` row-major matrix `a` (overwritten) by Householder QR.
fn least_squares(a: &mut [f64], n: usize, m: usize, y: &[f64]) -> Option<Vec<f64>> {
    let mut y = y.to_vec();
    for k in 0..m {
        let norm = (k..n).map(|i| a[i * m + k].powi(2)).sum::<f64>().sqrt();
        if norm == 0.0 {
            return None;
        }
        let alpha = if a[k * m + k] > 0.0 { -norm } else { norm };
        let mut v: Vec<f64> = (k..n).map(|i| a[i * m + k]).collect();
        v[0] -= alpha;
        let vnorm2: f64 = v.iter().map(|x| x * x).sum();
        if vnorm2 == 0.0 {
            continue;
        }
        for j in k..m {
            let dot: f64 = (k..n).map(|i| v[i - k] * a[i * m + j]).sum();
            let f = 2.0 * dot / vnorm2;
            for i in k..n {
                a[i * m + j] -= f * v[i - k];
            }
        }
        let dot: f64 = (k..n).map(|i| v[i - k] * y[i]).sum();
        let f = 2.0 * dot / vnorm2;
        for i in k..n {
            y[i] -= f * v[i - k];
        }
    }
    let mut b = vec![0.0; m];
    for k in (0..m).rev() {
        let s: f64 = ((k + 1)..m).map(|j| a[k * m + j] * b[j]).sum();
        let d = a[k * m + k];
        if d.abs() < 1e-300 {
            return None;
        }
        b[k] = (y[k] - s) / d;
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_an_exact_polynomial_and_a_power_law() {
        // y = 1 − 2x + 0.5x² sampled exactly: the fit returns the coefficients to round-off.
        let pts: Vec<(f64, f64)> =
            (0..20).map(|i| i as f64 * 0.3).map(|x| (x, 1.0 - 2.0 * x + 0.5 * x * x)).collect();
        let f = fit_polynomial(&pts, 2, false, "x", "y").unwrap();
        for (c, e) in f.coefficients.iter().zip([1.0, -2.0, 0.5]) {
            assert!((c - e).abs() < 1e-10, "{:?}", f.coefficients);
        }
        // v = 0.01 d^-1.2 in log–log space is a straight line.
        let pts: Vec<(f64, f64)> =
            (0..30).map(|i| 1e-5 * (1.0 + i as f64 * 0.3)).map(|d| (d, 0.01 * d.powf(-1.2))).collect();
        let f = fit_polynomial(&pts, 3, true, "d", "v").unwrap();
        assert!(f.rms_relative_error < 1e-10);
        assert!((f.eval(2e-5) - 0.01 * 2e-5f64.powf(-1.2)).abs() < 1e-9 * f.eval(2e-5));
        // Too few points lower the degree instead of failing.
        let f = fit_polynomial(&[(1.0, 2.0), (2.0, 3.0)], 4, false, "x", "y").unwrap();
        assert_eq!(f.coefficients.len(), 2);
        assert!(fit_polynomial(&[], 2, false, "x", "y").is_none());
    }
}
