//! The law of the wall over a smooth surface: friction velocity, wall units, and the velocity at a height.
//!
//! Wall units (Jasion 2013 eq. 3.20–3.22): u_* = √(τ_w/ρ_f), y⁺ = y u_*/ν, u⁺ = u/u_*; a particle of
//! diameter D_p measures D_p⁺ = D_p u_*/ν (= D_p/δ_ν with the viscous length δ_ν = ν/u_*). The profile is
//! the viscous sublayer u⁺ = y⁺ below y⁺ ≈ 5 and the log law u⁺ = ln(y⁺)/κ + B above y⁺ ≈ 30
//! (κ = 0.41, B = 5.5 as in the thesis), joined through the buffer layer by Spalding's (1961) single
//! formula
//!
//! y⁺ = u⁺ + e^(−κB) [e^(κu⁺) − 1 − κu⁺ − (κu⁺)²/2 − (κu⁺)³/6],
//!
//! which is used everywhere here. Given a velocity u at a height y (a wall function), u_* follows from
//! Re_y = u y/ν = u⁺ y⁺(u⁺), solved for u⁺ by Newton's method (the left side increases with u⁺).

/// von Kármán constant κ.
pub const KAPPA: f64 = 0.41;
/// Additive constant of the smooth-wall log law (Jasion 2013 §3.2.1).
pub const LOG_LAW_B: f64 = 5.5;

/// y⁺ at which the velocity is u⁺ (Spalding 1961).
#[inline]
pub fn spalding_y_plus(u_plus: f64) -> f64 {
    let k = KAPPA * u_plus;
    u_plus + (-KAPPA * LOG_LAW_B).exp() * (k.exp() - 1.0 - k - 0.5 * k * k - k * k * k / 6.0)
}

/// dy⁺/du⁺ of [`spalding_y_plus`].
#[inline]
fn spalding_slope(u_plus: f64) -> f64 {
    let k = KAPPA * u_plus;
    1.0 + (-KAPPA * LOG_LAW_B).exp() * KAPPA * (k.exp() - 1.0 - k - 0.5 * k * k)
}

/// Solves g(u⁺) = 0 for an increasing g by Newton's method from `guess`, safeguarded by bisection on
/// \[0, hi\].
fn solve_increasing(g: impl Fn(f64) -> (f64, f64), guess: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, guess.max(1.0));
    while g(hi).0 < 0.0 {
        hi *= 2.0;
    }
    let mut x = guess.clamp(lo, hi);
    for _ in 0..100 {
        let (f, df) = g(x);
        if f.abs() <= 1e-14 * (1.0 + x) {
            break;
        }
        if f < 0.0 {
            lo = x;
        } else {
            hi = x;
        }
        let newton = x - f / df;
        x = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if hi - lo < 1e-15 * hi {
            break;
        }
    }
    x
}

/// u⁺ at y⁺ (the inverse of [`spalding_y_plus`]); u⁺ = y⁺ in the sublayer, ln(y⁺)/κ + B in the log layer.
pub fn u_plus(y_plus: f64) -> f64 {
    if y_plus <= 0.0 {
        return 0.0;
    }
    let guess = if y_plus < 10.0 { y_plus } else { y_plus.ln() / KAPPA + LOG_LAW_B };
    solve_increasing(|u| (spalding_y_plus(u) - y_plus, spalding_slope(u)), guess)
}

/// Friction velocity u_* \[m/s\] of a smooth wall under which the speed parallel to the wall is `speed`
/// \[m/s\] at height `y` \[m\], kinematic viscosity `nu` \[m²/s\]: solves u y/ν = u⁺ y⁺(u⁺), u_* = u/u⁺.
pub fn friction_velocity_from_speed(speed: f64, y: f64, nu: f64) -> f64 {
    let re_y = speed.abs() * y / nu;
    if re_y <= 0.0 {
        return 0.0;
    }
    let guess = if re_y < 100.0 { re_y.sqrt() } else { (re_y.ln() / KAPPA).max(1.0) };
    let u = solve_increasing(
        |u| (u * spalding_y_plus(u) - re_y, spalding_y_plus(u) + u * spalding_slope(u)),
        guess,
    );
    speed.abs() / u
}

/// Speed \[m/s\] at height `y` above a smooth wall with friction velocity `u_star`: u_* u⁺(y u_*/ν).
pub fn speed_at(y: f64, u_star: f64, nu: f64) -> f64 {
    u_star * u_plus(y * u_star / nu)
}

/// y⁺ = y u_*/ν.
#[inline]
pub fn y_plus(y: f64, u_star: f64, nu: f64) -> f64 {
    y * u_star / nu
}

/// D_p⁺ = D_p u_*/ν: the particle diameter in viscous lengths (Jasion Fig. 6.6).
#[inline]
pub fn particle_d_plus(d: f64, u_star: f64, nu: f64) -> f64 {
    d * u_star / nu
}

/// Wall shear stress τ_w = ρ_f u_*² \[Pa\].
#[inline]
pub fn wall_shear_stress(u_star: f64, rho_f: f64) -> f64 {
    rho_f * u_star * u_star
}

/// Wall shear stress τ_w = μ ∂u/∂n \[Pa\] from the wall-normal gradient of the wall-parallel speed
/// (a field that resolves the viscous sublayer).
#[inline]
pub fn wall_shear_from_gradient(mu: f64, du_dn: f64) -> f64 {
    mu * du_dn.abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spalding_matches_sublayer_and_log_law() {
        // u⁺ = y⁺ for y⁺ ≪ 5 and u⁺ = ln(y⁺)/κ + B for y⁺ ≫ 30 (Spalding 1961 by construction).
        assert!((u_plus(0.5) - 0.5).abs() < 1e-3);
        assert!((u_plus(1.0) - 1.0).abs() < 5e-3);
        for yp in [100.0, 300.0, 1000.0] {
            let log = f64::ln(yp) / KAPPA + LOG_LAW_B;
            assert!((u_plus(yp) - log).abs() < 0.02 * log, "{yp}: {} vs {log}", u_plus(yp));
        }
        // Round trip.
        for up in [0.3, 4.0, 11.0, 25.0] {
            assert!((u_plus(spalding_y_plus(up)) - up).abs() < 1e-10);
        }
    }

    #[test]
    fn friction_velocity_inverts_the_profile() {
        let nu = 1.82e-5 / 1.19;
        for (u_star, y) in [(0.05, 1e-4), (0.3, 0.01), (0.25, 0.85), (1.0, 2.0)] {
            let u = speed_at(y, u_star, nu);
            let back = friction_velocity_from_speed(u, y, nu);
            assert!((back / u_star - 1.0).abs() < 1e-10, "{u_star} {y}: {back}");
        }
        // Log-law hand value: u* = 0.25 m/s, y = 0.85 m, ν = 1.5294e-5: y⁺ = 13 894,
        // u = 0.25 (ln(13 894)/0.41 + 5.5) = 7.190 m/s (Spalding differs from the pure log law by < 0.1 %).
        let u = speed_at(0.85, 0.25, nu);
        let log = 0.25 * ((0.85 * 0.25 / nu).ln() / KAPPA + LOG_LAW_B);
        assert!((u - log).abs() < 1e-3 * log, "{u} vs {log}");
        assert!((log - 7.190).abs() < 0.002, "{log}");
        assert_eq!(wall_shear_stress(0.25, 1.2), 0.075);
    }
}
