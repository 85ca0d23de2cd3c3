//! Special functions of the vortex rings: complete elliptic integrals K(m), E(m) and the exponential
//! integral E₁(x), each exact (for stream functions and references) and fast (for velocities in hot
//! loops).

use std::f64::consts::PI;
use std::sync::LazyLock;

/// Beyond this argument E₁ is taken as zero (E₁(30) = 3 × 10⁻¹⁵): the core correction of a ring is
/// dropped where αQ/r_c² exceeds it.
pub const CORE_CUTOFF: f64 = 30.0;

/// Complete elliptic integrals K(m) and E(m) of parameter m = k² < 1 by the arithmetic–geometric mean
/// (Abramowitz & Stegun 17.6); exact to rounding.
pub fn elliptic_ke(m: f64) -> (f64, f64) {
    let mut a = 1.0;
    let mut b = (1.0 - m).sqrt();
    let mut c = m.sqrt();
    let mut sum = 0.5 * c * c;
    let mut pow = 0.5;
    for _ in 0..40 {
        if c.abs() < 1e-16 {
            break;
        }
        let an = 0.5 * (a + b);
        let bn = (a * b).sqrt();
        c = 0.5 * (a - b);
        a = an;
        b = bn;
        pow *= 2.0;
        sum += pow * c * c;
    }
    let k = PI / (2.0 * a);
    (k, k * (1.0 - sum))
}

/// K(m) and E(m) by the polynomial approximations of Hastings, Abramowitz & Stegun 17.3.34 and 17.3.36,
/// |error| ≤ 2 × 10⁻⁸ for 0 ≤ m < 1: one logarithm instead of the AGM's square roots (ring velocities).
#[inline]
pub fn elliptic_ke_fast(m: f64) -> (f64, f64) {
    let m1 = 1.0 - m;
    let l = -m1.ln();
    let k = (1.386_294_361_12
        + m1 * (0.096_663_442_59
            + m1 * (0.035_900_923_83 + m1 * (0.037_425_637_13 + m1 * 0.014_511_962_12))))
        + l * (0.5
            + m1 * (0.124_985_935_97
                + m1 * (0.068_802_485_76 + m1 * (0.033_283_553_46 + m1 * 0.004_417_870_12))));
    let e = (1.0
        + m1 * (0.443_251_414_63
            + m1 * (0.062_606_012_20 + m1 * (0.047_573_835_46 + m1 * 0.017_365_064_51))))
        + l * m1
            * (0.249_983_683_10 + m1 * (0.092_001_800_37 + m1 * (0.040_696_975_26 + m1 * 0.005_264_496_39)));
    (k, e)
}

/// Exponential integral E₁(x) = ∫ₓ^∞ e^(−t)/t dt for x > 0: the power series below x = 1
/// (Abramowitz & Stegun 5.1.11) and the continued fraction above (A&S 5.1.22, evaluated by the modified
/// Lentz method); relative error ≈ 10⁻¹⁵. Zero from x = [`CORE_CUTOFF`] on.
pub fn exp_integral_e1(x: f64) -> f64 {
    if x >= CORE_CUTOFF {
        return 0.0;
    }
    if x < 1.0 {
        let mut term = 1.0;
        let mut sum = 0.0;
        for k in 1..60 {
            let kf = k as f64;
            term *= -x / kf;
            let add = -term / kf;
            sum += add;
            if add.abs() < 1e-17 * sum.abs() {
                break;
            }
        }
        return -EULER_GAMMA - x.ln() + sum;
    }
    e1_continued_fraction_scaled(x) * (-x).exp()
}

/// eˣ E₁(x) for x ≥ 1 by the continued fraction of A&S 5.1.22 (modified Lentz).
fn e1_continued_fraction_scaled(x: f64) -> f64 {
    let tiny = 1e-300;
    let mut b = x + 1.0;
    let mut c = 1.0 / tiny;
    let mut d = 1.0 / b;
    let mut h = d;
    for i in 1..200 {
        let an = -((i * i) as f64);
        b += 2.0;
        d = 1.0 / (an * d + b);
        c = b + an / c;
        let del = c * d;
        h *= del;
        if (del - 1.0).abs() < 1e-16 {
            break;
        }
    }
    h
}

/// Nodes of the fast E₁ tables.
const E1_NODES: usize = 1025;

/// Ein(x) = E₁(x) + ln x + γ on \[0, 1\] and x eˣ E₁(x) as a function of u = 1/x on \[0, 1\] (both smooth),
/// on uniform grids of [`E1_NODES`] nodes, from [`exp_integral_e1`] (Ein(0) = 0, x eˣ E₁ → 1 as u → 0).
static E1_TABLES: LazyLock<(Vec<f64>, Vec<f64>)> = LazyLock::new(|| {
    let h = 1.0 / (E1_NODES - 1) as f64;
    let ein = (0..E1_NODES)
        .map(|k| {
            let x = k as f64 * h;
            if k == 0 {
                0.0
            } else {
                exp_integral_e1(x) + x.ln() + EULER_GAMMA
            }
        })
        .collect();
    let scaled = (0..E1_NODES)
        .map(|k| {
            let u = k as f64 * h;
            if k == 0 {
                1.0
            } else {
                let x = 1.0 / u;
                // x eˣ E₁(x) by the continued fraction (no overflow of eˣ for large x).
                x * e1_continued_fraction_scaled(x)
            }
        })
        .collect();
    (ein, scaled)
});

/// Euler's constant γ.
const EULER_GAMMA: f64 = 0.577_215_664_901_532_9;

/// Cubic (4-point Lagrange) interpolation of `table` on \[0, 1\] at `t`.
#[inline]
fn table_lookup(table: &[f64], t: f64) -> f64 {
    let n = table.len();
    let f = t * (n - 1) as f64;
    // Truncation equals `floor` after the clamp to ≥ 1 (they differ only for negative f).
    let i = (f as isize).clamp(1, n as isize - 3) as usize;
    let s = f - i as f64;
    let (a, b, c, d) = (s + 1.0, s, s - 1.0, s - 2.0);
    let w = [-b * c * d / 6.0, a * c * d / 2.0, -a * b * d / 2.0, a * b * c / 6.0];
    w[0] * table[i - 1] + w[1] * table[i] + w[2] * table[i + 1] + w[3] * table[i + 2]
}

/// E₁(x) from the tables of `E1_TABLES` (relative error below 10⁻¹⁰, tested against
/// [`exp_integral_e1`]); zero from [`CORE_CUTOFF`] on.
#[inline]
pub fn exp_integral_e1_fast(x: f64) -> f64 {
    if x >= CORE_CUTOFF {
        return 0.0;
    }
    let (ein, scaled) = &*E1_TABLES;
    if x < 1.0 {
        table_lookup(ein, x) - x.ln() - EULER_GAMMA
    } else {
        table_lookup(scaled, 1.0 / x) * (-x).exp() / x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exponential_integral_values() {
        // A&S Table 5.1: E₁(0.5) = 0.5597735948, E₁(1) = 0.2193839344, E₁(2) = 0.04890051071,
        // E₁(10) = 4.156968929e-6.
        for (x, e) in [(0.5, 0.5597735948), (1.0, 0.2193839344), (2.0, 0.04890051071), (10.0, 4.156968929e-6)]
        {
            assert!((exp_integral_e1(x) / e - 1.0).abs() < 1e-9, "E1({x}) = {}", exp_integral_e1(x));
        }
        // Continuity at the switch from series to continued fraction.
        assert!((exp_integral_e1(1.0 - 1e-12) - exp_integral_e1(1.0)).abs() < 1e-11);
    }

    #[test]
    fn elliptic_integrals() {
        // A&S Table 17.1: K(0.5) = 1.8540746773, E(0.5) = 1.3506438810.
        let (k, e) = elliptic_ke(0.5);
        assert!((k - 1.8540746773).abs() < 1e-10 && (e - 1.3506438810).abs() < 1e-10);
        let (k, e) = elliptic_ke(0.0);
        assert!((k - PI / 2.0).abs() < 1e-15 && (e - PI / 2.0).abs() < 1e-15);
    }

    #[test]
    fn fast_versions_agree_with_the_exact_ones() {
        // Hastings' approximations: |error| ≤ 2e-8 (A&S 17.3.34, 17.3.36).
        for k in 0..2000 {
            let m = k as f64 / 2000.0 * 0.999_999;
            let (k0, e0) = elliptic_ke(m);
            let (k1, e1) = elliptic_ke_fast(m);
            assert!((k0 - k1).abs() < 3e-8 && (e0 - e1).abs() < 3e-8, "m = {m}: {k0} {k1} {e0} {e1}");
        }
        for k in 1..3000 {
            let x = k as f64 * 0.01;
            let a = exp_integral_e1(x);
            let b = exp_integral_e1_fast(x);
            assert!((a - b).abs() <= 1e-10 * a, "E1({x}): {a} vs {b}");
        }
    }
}
