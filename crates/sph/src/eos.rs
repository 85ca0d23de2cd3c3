//! Tait (Cole) equation of state for weakly compressible water:
//! `p = B [(ρ/ρ₀)^γ − 1]`, `B = c₀² ρ₀ / γ` (Monaghan 1994, J. Comput. Phys. 110:399; thesis eq. 2.36).
//! `p(ρ₀) = 0` and `dp/dρ(ρ₀) = c₀²`; the local sound speed is `c = c₀ (ρ/ρ₀)^{(γ−1)/2}`.

use serde::{Deserialize, Serialize};

/// Tait equation of state.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tait {
    /// Rest density ρ₀ \[kg/m³\].
    pub rho0: f64,
    /// Reference sound speed c₀ \[m/s\].
    pub c0: f64,
    /// Polytropic exponent γ (7 for water; 1 gives the linear law `p = c₀²(ρ − ρ₀)`).
    pub gamma: f64,
    b: f64,
    inv_rho0: f64,
    gamma_is_7: bool,
}

impl Tait {
    pub fn new(rho0: f64, c0: f64, gamma: f64) -> Self {
        Tait { rho0, c0, gamma, b: c0 * c0 * rho0 / gamma, inv_rho0: 1.0 / rho0, gamma_is_7: gamma == 7.0 }
    }

    /// Stiffness `B = c₀² ρ₀ / γ` \[Pa\].
    pub fn stiffness(&self) -> f64 {
        self.b
    }

    /// Pressure \[Pa\] at density `rho` \[kg/m³\].
    #[inline]
    pub fn pressure(&self, rho: f64) -> f64 {
        let x = rho * self.inv_rho0;
        let xg = if self.gamma_is_7 {
            let x2 = x * x;
            let x3 = x2 * x;
            x3 * x3 * x
        } else {
            x.powf(self.gamma)
        };
        self.b * (xg - 1.0)
    }

    /// Density \[kg/m³\] at pressure `p` \[Pa\] (inverse of [`pressure`](Self::pressure); `p > −B`).
    #[inline]
    pub fn density(&self, p: f64) -> f64 {
        self.rho0 * (p / self.b + 1.0).max(1e-12).powf(1.0 / self.gamma)
    }

    /// Local sound speed \[m/s\].
    #[inline]
    pub fn sound_speed(&self, rho: f64) -> f64 {
        self.c0 * (rho * self.inv_rho0).powf(0.5 * (self.gamma - 1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_at_rest_slope_c0_squared_and_invertible() {
        for gamma in [7.0, 1.0, 1.4] {
            let e = Tait::new(1000.0, 30.0, gamma);
            assert_eq!(e.pressure(1000.0), 0.0);
            let d = 1e-4;
            let slope = (e.pressure(1000.0 + d) - e.pressure(1000.0 - d)) / (2.0 * d);
            assert!((slope - 900.0).abs() < 1e-5, "γ = {gamma}: dp/dρ = {slope}");
            for rho in [950.0, 1000.0, 1003.7, 1040.0] {
                assert!((e.density(e.pressure(rho)) - rho).abs() < 1e-9, "γ = {gamma}, ρ = {rho}");
            }
            assert!((e.sound_speed(1000.0) - 30.0).abs() < 1e-12);
        }
        // Linear law for γ = 1: p = c₀²(ρ − ρ₀).
        let lin = Tait::new(1000.0, 20.0, 1.0);
        assert!((lin.pressure(1010.0) - 4000.0).abs() < 1e-9);
    }
}
