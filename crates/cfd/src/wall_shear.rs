//! Wall shear stress along the no-slip sides of the grid, as the momentum equation sees it.
//!
//! For every fluid cell next to a `wall` side: the tangential speed relative to the wall at the cell
//! centre u_p, the centre's distance y_p, the viscosity of the wall face ν_w (the molecular viscosity
//! for laminar flows; with k–ε the log-law wall viscosity of [`crate::turbulence::wall_viscosity`]),
//! the kinematic wall shear τ_w/ρ = ν_w u_p / y_p, the friction velocity u_* = √(τ_w/ρ) and
//! y⁺ = u_* y_p/ν. Along the ground of an axisymmetric rotor case this is the radial wall-shear profile
//! that the thesis of Jasion (2013, Ch. 6) compares with Leese's (1964) full-scale measurements.

use crate::bc::Boundary;
use crate::grid::{Mode, GHOST};
use crate::solver::Flow;
use crate::turbulence::wall_viscosity;

/// Wall shear at one wall-adjacent cell.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallPoint {
    /// Grid coordinates of the cell centre \[m\] (axisymmetric: r, axial, azimuthal placeholder).
    pub centre: [f64; 3],
    /// Distance of the cell centre from the wall \[m\].
    pub y: f64,
    /// Tangential speed relative to the wall at the cell centre \[m/s\].
    pub speed: f64,
    /// Kinematic wall shear stress τ_w/ρ \[m²/s²\].
    pub tau_over_rho: f64,
    /// Friction velocity √(τ_w/ρ) \[m/s\].
    pub u_star: f64,
    /// u_* y / ν \[-\].
    pub y_plus: f64,
}

impl Flow {
    /// The wall shear of every fluid cell next to `side` (0 = x_min … 5 = z_max), in the grid's cell
    /// order; empty when the side is not a no-slip wall.
    pub fn wall_shear(&self, side: usize) -> Vec<WallPoint> {
        let Boundary::Wall { velocity_m_s } = &self.bc[side] else { return Vec::new() };
        let g = &self.grid;
        let l = g.layout;
        let a = side / 2;
        let nu = self.fluid.viscosity;
        let dims = if g.mode == Mode::Axisymmetric { 2 } else { 3 };
        let qa = if side % 2 == 0 { GHOST } else { GHOST + l.n[a] - 1 };
        let mut out = Vec::new();
        for k in 0..l.n[2] {
            for j in 0..l.n[1] {
                for i in 0..l.n[0] {
                    let q = [i + GHOST, j + GHOST, k + GHOST];
                    if q[a] != qa {
                        continue;
                    }
                    let c = l.at(q[0], q[1], q[2]);
                    if self.blocked[c] {
                        continue;
                    }
                    let y = 0.5 * g.metric[a].d[q[a]];
                    let uc = self.cell_velocity(i, j, k);
                    let speed = (0..dims)
                        .filter(|&b| b != a)
                        .map(|b| (uc[b] - velocity_m_s[b]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    let nu_w = match (&self.turbulence, &self.state.turbulence) {
                        (Some(t), Some(ts)) => wall_viscosity(t.model.c_mu, ts.k[c], y, nu),
                        _ => nu,
                    };
                    let tau = nu_w * speed / y;
                    let u_star = tau.sqrt();
                    out.push(WallPoint {
                        centre: g.centre(q),
                        y,
                        speed,
                        tau_over_rho: tau,
                        u_star,
                        y_plus: u_star * y / nu,
                    });
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use crate::bc::Boundary;
    use crate::grid::{Axis, Grid, Mode};
    use crate::solver::{Flow, Fluid, Numerics};

    /// Developed plane Poiseuille flow between walls H apart at mean speed U (Re = UH/ν = 10, 64 × 16
    /// cells, uniform inlet, 4H long): u = 6U y(H − y)/H², τ_w/ρ = 6νU/H (White, Viscous Fluid Flow §3-3).
    /// The wall cell's estimate ν u_p/y_p at y_p = Δ/2 is, for the exact profile, its secant
    /// 6νU/H · (1 − Δ/(2H)); the solver's profile is within 0.0058 U of Poiseuille's (docs/cfd.md §5),
    /// which at the wall cell (u_p = 0.18 U) is 3.2 %: within 3.5 % of the secant on both walls in the
    /// developed part (x > 3H), and exactly ν u_p/y_p.
    #[test]
    fn laminar_channel_flow_has_the_poiseuille_wall_shear() {
        let (h, u, nu) = (1.0, 1.0, 0.1);
        let g = Grid::new(
            [
                Axis::uniform(0.0, 4.0, 64).unwrap(),
                Axis::uniform(0.0, h, 16).unwrap(),
                Axis::uniform(0.0, 0.1, 1).unwrap(),
            ],
            Mode::Cartesian,
        )
        .unwrap();
        let n = g.layout.len();
        let wall = Boundary::Wall { velocity_m_s: [0.0; 3] };
        let bc = [
            Boundary::Inlet { velocity_m_s: [u, 0.0, 0.0], table: Default::default() },
            Boundary::Outlet { pressure_pa: 0.0 },
            wall.clone(),
            wall,
            Boundary::Slip,
            Boundary::Slip,
        ];
        let mut f =
            Flow::new(g, Fluid { density: 1.0, viscosity: nu }, bc, vec![false; n], Numerics::default())
                .unwrap();
        crate::cavity::run_to_steady(&mut f, 1e-6, 40.0).unwrap();
        let want = 6.0 * nu * u / h * (1.0 - 1.0 / 32.0);
        for side in [2, 3] {
            let w = f.wall_shear(side);
            assert_eq!(w.len(), 64);
            for p in w.iter().filter(|p| p.centre[0] > 3.0) {
                assert!((p.tau_over_rho / want - 1.0).abs() < 0.035, "side {side}: {p:?}, want {want}");
                assert!((p.tau_over_rho - nu * p.speed / p.y).abs() < 1e-12 * p.tau_over_rho);
                assert!((p.y - 1.0 / 32.0).abs() < 1e-12);
            }
        }
        assert!(f.wall_shear(0).is_empty(), "an inlet has no wall shear");
    }
}
