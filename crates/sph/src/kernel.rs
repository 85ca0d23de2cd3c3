//! Smoothing kernels with support radius `2h`, in two or three dimensions, and the Akinci et al. (2013)
//! cohesion and adhesion splines.
//!
//! * Wendland C2: `W = α_D (1 − q/2)⁴ (2q + 1)`, `q = r/h ≤ 2`, `α_D = 7/(4πh²)` (2D), `21/(16πh³)` (3D)
//!   (Wendland 1995, Adv. Comput. Math. 4:389; in the form used by Crespo et al. 2015, DualSPHysics, CPC 187).
//! * Cubic spline: `W = α_D [1 − 1.5q² + 0.75q³]` for `q < 1`, `α_D 0.25 (2 − q)³` for `1 ≤ q < 2`,
//!   `α_D = 10/(7πh²)` (2D), `1/(πh³)` (3D) (Monaghan & Lattanzio 1985, A&A 149:135).
//!
//! The hot loops need the gradient as `∇_i W_ij = (x_i − x_j) · F(r)` with `F = (1/r) dW/dr`, so the kernels
//! expose [`Kernel::grad_factor`] (never divides by `r`).

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Spatial dimension of a simulation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Dim {
    /// Plane flow in x–z; particles have y = 0 and masses per metre of depth.
    Two,
    Three,
}

impl Dim {
    pub fn count(self) -> i32 {
        match self {
            Dim::Two => 2,
            Dim::Three => 3,
        }
    }
}

/// Which smoothing kernel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KernelKind {
    #[default]
    WendlandC2,
    CubicSpline,
}

/// A kernel of smoothing length `h` \[m\]; support radius `2h`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Kernel {
    pub kind: KernelKind,
    pub dim: Dim,
    pub h: f64,
    /// Normalisation α_D \[m⁻ᵈ\].
    norm: f64,
    inv_h: f64,
}

impl Kernel {
    pub fn new(kind: KernelKind, dim: Dim, h: f64) -> Self {
        let norm = match (kind, dim) {
            (KernelKind::WendlandC2, Dim::Two) => 7.0 / (4.0 * PI * h * h),
            (KernelKind::WendlandC2, Dim::Three) => 21.0 / (16.0 * PI * h * h * h),
            (KernelKind::CubicSpline, Dim::Two) => 10.0 / (7.0 * PI * h * h),
            (KernelKind::CubicSpline, Dim::Three) => 1.0 / (PI * h * h * h),
        };
        Kernel { kind, dim, h, norm, inv_h: 1.0 / h }
    }

    /// Support radius `2h` \[m\].
    #[inline]
    pub fn support(&self) -> f64 {
        2.0 * self.h
    }

    /// `W(r)` \[m⁻ᵈ\].
    #[inline]
    pub fn w(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        if q >= 2.0 {
            return 0.0;
        }
        match self.kind {
            KernelKind::WendlandC2 => {
                let t = 1.0 - 0.5 * q;
                let t2 = t * t;
                self.norm * t2 * t2 * (2.0 * q + 1.0)
            }
            KernelKind::CubicSpline => {
                if q < 1.0 {
                    self.norm * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
                } else {
                    let t = 2.0 - q;
                    self.norm * 0.25 * t * t * t
                }
            }
        }
    }

    /// `F(r) = (1/r) dW/dr` \[m⁻ᵈ⁻²\] (≤ 0), so that `∇_i W_ij = (x_i − x_j) F(r_ij)`. Finite at `r = 0`.
    #[inline]
    pub fn grad_factor(&self, r: f64) -> f64 {
        let q = r * self.inv_h;
        if q >= 2.0 {
            return 0.0;
        }
        let c = self.norm * self.inv_h * self.inv_h;
        match self.kind {
            KernelKind::WendlandC2 => {
                let t = 1.0 - 0.5 * q;
                -5.0 * c * t * t * t
            }
            KernelKind::CubicSpline => {
                if q < 1.0 {
                    c * (-3.0 + 2.25 * q)
                } else {
                    let t = 2.0 - q;
                    -0.75 * c * t * t / q
                }
            }
        }
    }

    /// Normalisation α_D \[m⁻ᵈ\].
    pub fn norm(&self) -> f64 {
        self.norm
    }

    /// `W(0)`: a particle's own contribution to kernel sums.
    pub fn w0(&self) -> f64 {
        self.w(0.0)
    }
}

/// Akinci et al. (2013) cohesion spline `C(r)` with support radius `support` \[m⁻³ scale; see module docs\].
///
/// `C(r) = 32/(π R⁹) · { (R − r)³ r³ if R/2 < r ≤ R;  2 (R − r)³ r³ − R⁶/64 if 0 < r ≤ R/2;  0 otherwise }`
/// (Akinci, Akinci & Teschner 2013, "Versatile surface tension and adhesion for SPH fluids", ACM TOG 32(6)
/// 182, eq. 2; the branch condition is garbled in the wading thesis's text).
#[inline]
pub fn akinci_cohesion(r: f64, support: f64) -> f64 {
    if r > support || r <= 0.0 {
        return 0.0;
    }
    let rr = support;
    let r6 = {
        let r3 = rr * rr * rr;
        r3 * r3
    };
    let c = 32.0 / (PI * r6 * rr * rr * rr);
    let a = (rr - r) * r;
    let a3 = a * a * a;
    if 2.0 * r > rr {
        c * a3
    } else {
        c * (2.0 * a3 - r6 / 64.0)
    }
}

/// Akinci et al. (2013) adhesion spline `A(r) = 0.007/R^3.25 · (−4r²/R + 6r − 2R)^{1/4}` on `R/2 < r ≤ R`,
/// zero elsewhere (eq. 7 of the paper).
#[inline]
pub fn akinci_adhesion(r: f64, support: f64) -> f64 {
    if r > support || 2.0 * r <= support {
        return 0.0;
    }
    let x = -4.0 * r * r / support + 6.0 * r - 2.0 * support;
    0.007 / support.powf(3.25) * x.max(0.0).sqrt().sqrt()
}

/// The Akinci splines with their support-dependent constants computed once (hot loops).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AkinciSplines {
    support: f64,
    coh: f64,
    r6_64: f64,
    adh: f64,
}

impl AkinciSplines {
    pub fn new(support: f64) -> Self {
        let r3 = support * support * support;
        AkinciSplines {
            support,
            coh: 32.0 / (PI * r3 * r3 * r3),
            r6_64: r3 * r3 / 64.0,
            adh: 0.007 / support.powf(3.25),
        }
    }

    /// Same as [`akinci_cohesion`].
    #[inline(always)]
    pub fn cohesion(&self, r: f64) -> f64 {
        if r > self.support || r <= 0.0 {
            return 0.0;
        }
        let a = (self.support - r) * r;
        let a3 = a * a * a;
        if 2.0 * r > self.support {
            self.coh * a3
        } else {
            self.coh * (2.0 * a3 - self.r6_64)
        }
    }

    /// Same as [`akinci_adhesion`].
    #[inline(always)]
    pub fn adhesion(&self, r: f64) -> f64 {
        if r > self.support || 2.0 * r <= self.support {
            return 0.0;
        }
        let x = -4.0 * r * r / self.support + 6.0 * r - 2.0 * self.support;
        self.adh * x.max(0.0).sqrt().sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ W dV by the midpoint rule on radial shells.
    fn integral(k: &Kernel) -> f64 {
        let n = 20_000;
        let dr = k.support() / n as f64;
        (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * dr;
                let shell = match k.dim {
                    Dim::Two => 2.0 * PI * r,
                    Dim::Three => 4.0 * PI * r * r,
                };
                k.w(r) * shell * dr
            })
            .sum()
    }

    #[test]
    fn kernels_are_normalised_and_gradients_match_finite_differences() {
        for kind in [KernelKind::WendlandC2, KernelKind::CubicSpline] {
            for dim in [Dim::Two, Dim::Three] {
                let k = Kernel::new(kind, dim, 0.013);
                // Midpoint rule with 20 000 shells: error ≪ 1e-6.
                assert!((integral(&k) - 1.0).abs() < 1e-6, "{kind:?} {dim:?}: {}", integral(&k));
                for i in 1..40 {
                    let r = k.support() * i as f64 / 40.0;
                    let e = 1e-7 * k.h;
                    let fd = (k.w(r + e) - k.w(r - e)) / (2.0 * e);
                    let an = k.grad_factor(r) * r;
                    assert!((fd - an).abs() <= 1e-6 * k.w0() / k.h, "{kind:?} {dim:?} r={r}: {fd} vs {an}");
                }
                assert!(k.w(k.support()) < 1e-12 * k.w0());
                assert_eq!(k.grad_factor(1.01 * k.support()), 0.0);
            }
        }
    }

    #[test]
    fn akinci_splines_match_the_tabulated_values() {
        // Akinci et al. (2013), support radius 1: C(r)·h³ and A(r)·h³.
        let c = |r: f64| akinci_cohesion(r, 1.0);
        let a = |r: f64| akinci_adhesion(r, 1.0);
        for (r, want) in [
            (0.10, -0.14430388),
            (0.25, -0.02486796),
            (0.50, 0.15915494),
            (0.75, 0.06714349),
            (0.90, 0.00742553),
        ] {
            assert!((c(r) - want).abs() < 1e-8, "C({r}) = {} vs {want}", c(r));
        }
        assert!(c(0.2728990).abs() < 1e-6, "zero crossing of C");
        assert!((c(1e-9) + 0.15915494).abs() < 1e-7, "C → −1/(2π) as r → 0");
        for (r, want) in [(0.60, 0.00442719), (0.75, 0.00494975), (0.90, 0.00442719)] {
            assert!((a(r) - want).abs() < 1e-8, "A({r}) = {} vs {want}", a(r));
        }
        assert_eq!(a(0.5), 0.0);
        assert_eq!(a(0.3), 0.0);
        assert_eq!(a(1.01), 0.0);
        let pre = AkinciSplines::new(0.02);
        for i in 0..50 {
            let r = 0.02 * i as f64 / 49.0;
            assert!(
                (pre.cohesion(r) - akinci_cohesion(r, 0.02)).abs()
                    <= 1e-12 * akinci_cohesion(0.01, 0.02).abs()
            );
            assert!(
                (pre.adhesion(r) - akinci_adhesion(r, 0.02)).abs() <= 1e-12 * akinci_adhesion(0.015, 0.02)
            );
        }
        // Scaling: both splines scale as R⁻³ f(r/R).
        let s = 0.02;
        assert!((akinci_cohesion(0.75 * s, s) * s.powi(3) - 0.06714349).abs() < 1e-8);
        assert!((akinci_adhesion(0.75 * s, s) * s.powi(3) - 0.00494975).abs() < 1e-8);
    }
}
