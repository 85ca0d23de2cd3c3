//! The registry format of `spatter validate`: engines expose reference cases that compare a computed number
//! with a published or analytic one.

/// How a comparison is judged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Tolerance {
    /// |ours − reference| ≤ tol · |reference|.
    Relative(f64),
    /// |ours − reference| ≤ tol.
    Absolute(f64),
}

/// One compared quantity.
#[derive(Clone, Debug, PartialEq)]
pub struct Check {
    /// Case name, e.g. `chung_ooi_1_glass`.
    pub case: String,
    /// Quantity with unit, e.g. `F_max [N]`.
    pub quantity: String,
    pub reference: f64,
    pub ours: f64,
    pub tolerance: Tolerance,
    /// Where the reference comes from.
    pub source: String,
}

impl Check {
    /// A comparison judged by `tolerance`.
    pub fn new(
        case: impl Into<String>,
        quantity: impl Into<String>,
        reference: f64,
        ours: f64,
        tolerance: Tolerance,
        source: impl Into<String>,
    ) -> Self {
        Check {
            case: case.into(),
            quantity: quantity.into(),
            reference,
            ours,
            tolerance,
            source: source.into(),
        }
    }

    /// Passes when |ours − reference| ≤ tol · |reference|.
    pub fn relative(
        case: impl Into<String>,
        quantity: impl Into<String>,
        reference: f64,
        ours: f64,
        tol: f64,
        source: impl Into<String>,
    ) -> Self {
        Self::new(case, quantity, reference, ours, Tolerance::Relative(tol), source)
    }

    /// Passes when |ours − reference| ≤ tol.
    pub fn absolute(
        case: impl Into<String>,
        quantity: impl Into<String>,
        reference: f64,
        ours: f64,
        tol: f64,
        source: impl Into<String>,
    ) -> Self {
        Self::new(case, quantity, reference, ours, Tolerance::Absolute(tol), source)
    }

    /// Relative error |ours − reference| / |reference| (absolute error when the reference is 0).
    pub fn error(&self) -> f64 {
        let d = (self.ours - self.reference).abs();
        if self.reference == 0.0 {
            d
        } else {
            d / self.reference.abs()
        }
    }

    pub fn passed(&self) -> bool {
        let d = (self.ours - self.reference).abs();
        match self.tolerance {
            Tolerance::Relative(t) => d <= t * self.reference.abs(),
            Tolerance::Absolute(t) => d <= t,
        }
    }
}

/// A registered validation case. `run(quick)` returns its comparisons; `quick = true` is the reduced
/// variant that also runs in CI.
#[derive(Clone, Copy)]
pub struct Case {
    pub name: &'static str,
    pub run: fn(quick: bool) -> Vec<Check>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pass_and_fail() {
        assert!(Check::relative("c", "q", 100.0, 100.9, 0.01, "s").passed());
        assert!(!Check::relative("c", "q", 100.0, 101.1, 0.01, "s").passed());
        assert!(Check::absolute("c", "q", 0.0, -0.05, 0.1, "s").passed());
        assert!(!Check::relative("c", "q", 1.0, f64::NAN, 0.1, "s").passed(), "NaN never passes");
    }
}
