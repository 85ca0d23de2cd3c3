//! Exactly rounded floating-point sums (Shewchuk 1997, "Adaptive precision floating-point arithmetic and
//! fast robust geometric predicates", the non-overlapping partials of Python's `math.fsum`).
//!
//! The mass balance of a run is kept with these, so "injected = deposited + escaped + airborne" holds
//! bit for bit when every parcel is counted exactly once, whatever the order of the additions.

use serde::{Deserialize, Serialize};

/// A sum kept as non-overlapping partials.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ExactSum {
    partials: Vec<f64>,
}

impl ExactSum {
    pub fn new() -> Self {
        ExactSum::default()
    }

    /// Adds `x` exactly.
    pub fn add(&mut self, mut x: f64) {
        let mut i = 0;
        for j in 0..self.partials.len() {
            let mut y = self.partials[j];
            if x.abs() < y.abs() {
                std::mem::swap(&mut x, &mut y);
            }
            let hi = x + y;
            let lo = y - (hi - x);
            if lo != 0.0 {
                self.partials[i] = lo;
                i += 1;
            }
            x = hi;
        }
        self.partials.truncate(i);
        self.partials.push(x);
    }

    /// Adds every partial of `other` (the result is the exact sum of both).
    pub fn merge(&mut self, other: &ExactSum) {
        for &p in &other.partials {
            self.add(p);
        }
    }

    /// The exact sum correctly rounded to the nearest `f64`.
    pub fn value(&self) -> f64 {
        let p = &self.partials;
        let mut n = p.len();
        if n == 0 {
            return 0.0;
        }
        n -= 1;
        let mut hi = p[n];
        let mut lo = 0.0;
        while n > 0 {
            let x = hi;
            n -= 1;
            let y = p[n];
            hi = x + y;
            let yr = hi - x;
            lo = y - yr;
            if lo != 0.0 {
                break;
            }
        }
        // Round-half-even correction (as in CPython's fsum).
        if n > 0 && ((lo < 0.0 && p[n - 1] < 0.0) || (lo > 0.0 && p[n - 1] > 0.0)) {
            let y = lo * 2.0;
            let x = hi + y;
            let yr = x - hi;
            if y == yr {
                hi = x;
            }
        }
        hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cancellation_and_order_independence() {
        let mut s = ExactSum::new();
        for x in [1e100, 1.0, -1e100, 1e-100] {
            s.add(x);
        }
        assert_eq!(s.value(), 1.0 + 1e-100);
        // 0.1 added ten times is exactly rounded 1.0 only with exact summation.
        let mut s = ExactSum::new();
        (0..10).for_each(|_| s.add(0.1));
        assert_eq!(s.value(), 1.0);
        // Any order and any split give the same bits.
        let xs: Vec<f64> =
            (1..2000).map(|i| (i as f64).sqrt() * 1e-13 * if i % 3 == 0 { -1.0 } else { 1.0 }).collect();
        let mut a = ExactSum::new();
        xs.iter().for_each(|&x| a.add(x));
        let (mut b, mut c) = (ExactSum::new(), ExactSum::new());
        xs.iter().rev().enumerate().for_each(|(i, &x)| if i % 2 == 0 { b.add(x) } else { c.add(x) });
        b.merge(&c);
        assert_eq!(a.value().to_bits(), b.value().to_bits());
    }
}
