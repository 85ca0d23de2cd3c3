//! Bisection of the boundary between the two sides of a test along one number (a position, a time).

/// Most halvings. A bracket of a few metres or seconds closes to neighbouring numbers in about 60
/// halvings, and no bracket of finite numbers needs more than about 2 100 (the binary exponents between
/// the smallest and the largest double); 200 is ample for the brackets used here and keeps a
/// predicate that is not monotone from looping long.
const MAX_HALVINGS: usize = 200;

/// Narrows the bracket `[out, inside]` (either order) around the point where `is_out` changes from true
/// (at `out`) to false (at `inside`) by halving it until the two ends are neighbouring numbers (the
/// midpoint `½ (out + inside)` equals one of them) or after [`MAX_HALVINGS`] halvings. Returns the
/// final `(out, inside)`: the last number found on each side.
pub fn bisect(mut out: f64, mut inside: f64, mut is_out: impl FnMut(f64) -> bool) -> (f64, f64) {
    for _ in 0..MAX_HALVINGS {
        let mid = 0.5 * (out + inside);
        if mid == out || mid == inside {
            break;
        }
        if is_out(mid) {
            out = mid;
        } else {
            inside = mid;
        }
    }
    (out, inside)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The boundary of x ≥ √2 is found to neighbouring numbers around `f64::sqrt(2)` (correctly
    /// rounded, IEEE 754), from either side and in either order of the bracket.
    #[test]
    fn brackets_close_to_neighbouring_numbers() {
        let r = 2f64.sqrt();
        // The next double above a positive one.
        let next = |x: f64| f64::from_bits(x.to_bits() + 1);
        let (o, i) = bisect(0.0, 3.0, |x| x * x < 2.0);
        assert!(o < i && next(o) == i, "{o} {i}");
        assert!(o <= r && r <= i);
        let (o, i) = bisect(3.0, 0.0, |x| x * x >= 2.0);
        assert!(i < o && next(i) == o && i <= r && r <= o, "{o} {i}");
        // A bracket of one number stays as it is.
        assert_eq!(bisect(1.0, 1.0, |_| true), (1.0, 1.0));
    }
}
