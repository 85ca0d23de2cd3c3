//! The prescribed air of `air = "prescribed"`: a developed turbulent pipe flow in the accelerating pipe
//! and, beyond its exit, a round free jet (or still air), switched on by the inlet ramp of the valve.
//! The stones feel it through the one-way fluid-force hook ([`crate::fluid_forces`]).
//!
//! Frame of the gravelometer geometry: the pipe axis is the x axis, the pipe runs from x = −L to its
//! exit at x = 0, r = √(y² + z²) is the distance from the axis.
//!
//! * **Pipe** (−L ≤ x ≤ 0, r < R): the power-law profile of developed turbulent pipe flow,
//!   u_x = U_c (1 − r/R)^{1/n}, whose bulk (cross-section mean) velocity is
//!   U_b = U_c · 2n² / ((n + 1)(2n + 1)) (Schlichting & Gersten, *Boundary-Layer Theory*, 8th ed.,
//!   §17.2; n = 7 is Prandtl's one-seventh law, good near Re_D ≈ 10⁵). U_b is given (`pipe.air_velocity_m_s`).
//! * **Free jet** (x > 0): a potential core carrying the pipe's centreline speed U_c that narrows
//!   linearly from the pipe radius to the axis at x_c, with a Gaussian shear layer around it; beyond x_c
//!   the self-similar round jet of Pope (2000, *Turbulent Flows*, §5.1, after Hussein, Capp & George
//!   1994): centreline speed U_0(x) = B U_b D / x with B = 5.8, half-velocity radius r_½ = S x with
//!   S = 0.094, radial profile exp(−ln 2 (r/r_½)²). The core length x_c = B D U_b/U_c makes the axis
//!   speed continuous; the shear-layer width grows from `EDGE_WIDTH` · R at the exit to S x_c at x_c,
//!   so the profile is continuous there too. The jet's radial (entrainment) velocity and its deflection
//!   by the panel are not modelled.
//! * **Still air** elsewhere (upstream of the inlet, outside the pipe wall, or beyond the exit with
//!   `air.outside = "stagnant"`).
//!
//! The whole field is scaled by the inlet ramp φ(t) = min(t / t_r, 1) (the valve opening; the
//! published study ramped its inlet velocity piecewise to the steady value, the ramp's shape and length
//! did not survive, so a linear ramp of `air.ramp_s` is an assumption).

use serde::{Deserialize, Serialize};
use spatter_core::{Aabb, Mat3, Vec3};
use spatter_flow::field::{FlowField, Sample};

/// Centreline-decay constant B of the self-similar round jet (Pope 2000, Table 5.1).
pub const JET_DECAY_B: f64 = 5.8;
/// Spreading rate S = dr_½/dx of the round jet (Pope 2000, Table 5.1).
pub const JET_SPREADING_S: f64 = 0.094;
/// Width of the jet's shear layer at the pipe exit, as a fraction of the pipe radius (the thickness
/// of the power-law profile's wall layer where u drops below half the centreline speed is under 1 %
/// of R; a few percent keeps the layer resolvable by a stone).
pub const EDGE_WIDTH: f64 = 0.05;

/// The air beyond the pipe exit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outside {
    /// A round turbulent free jet (the default).
    #[default]
    FreeJet,
    /// Still air: the stones fly ballistically (with air resistance) once out of the pipe.
    Stagnant,
}

/// The prescribed air field (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PipeAir {
    /// Pipe length L \[m\].
    pub length: f64,
    /// Pipe radius R \[m\].
    pub radius: f64,
    /// Bulk velocity U_b \[m/s\].
    pub bulk: f64,
    /// Power-law exponent n (profile (1 − r/R)^{1/n}).
    pub exponent: f64,
    /// Ramp time t_r \[s\] (0: the flow is on from t = 0).
    pub ramp: f64,
    pub outside: Outside,
}

impl PipeAir {
    /// Centreline speed U_c = U_b (n + 1)(2n + 1) / (2n²) \[m/s\].
    pub fn centreline(&self) -> f64 {
        let n = self.exponent;
        self.bulk * (n + 1.0) * (2.0 * n + 1.0) / (2.0 * n * n)
    }

    /// Length of the jet's potential core x_c = B D U_b / U_c \[m\].
    pub fn core_length(&self) -> f64 {
        JET_DECAY_B * 2.0 * self.radius * self.bulk / self.centreline()
    }

    /// The ramp factor φ(t) and its time derivative dφ/dt \[1/s\].
    pub fn ramp_factor(&self, t: f64) -> (f64, f64) {
        if self.ramp <= 0.0 || t >= self.ramp {
            (1.0, 0.0)
        } else if t <= 0.0 {
            (0.0, 0.0)
        } else {
            (t / self.ramp, 1.0 / self.ramp)
        }
    }

    /// The axial velocity of the steady (ramped-up) field at `x` \[m/s\].
    pub fn steady_axial(&self, x: Vec3) -> f64 {
        let r = (x.y * x.y + x.z * x.z).sqrt();
        let uc = self.centreline();
        if x.x < -self.length {
            return 0.0;
        }
        if x.x <= 0.0 {
            if r >= self.radius {
                return 0.0;
            }
            return uc * (1.0 - r / self.radius).powf(1.0 / self.exponent);
        }
        if self.outside == Outside::Stagnant {
            return 0.0;
        }
        let xc = self.core_length();
        let ln2 = std::f64::consts::LN_2;
        if x.x < xc {
            let f = x.x / xc;
            let core = self.radius * (1.0 - f);
            let width = EDGE_WIDTH * self.radius * (1.0 - f) + JET_SPREADING_S * x.x;
            if r <= core {
                uc
            } else {
                let e = (r - core) / width;
                uc * (-ln2 * e * e).exp()
            }
        } else {
            let e = r / (JET_SPREADING_S * x.x);
            uc * xc / x.x * (-ln2 * e * e).exp()
        }
    }
}

/// Step of the central differences of the velocity gradient \[m\] (only when a caller asks for the
/// gradient; the workflow's drag and buoyancy do not).
const GRAD_STEP: f64 = 1e-6;

impl FlowField for PipeAir {
    fn sample(&self, x: Vec3, t: f64, _hint: &mut u32, want_grad: bool) -> Option<Sample> {
        let (phi, dphi) = self.ramp_factor(t);
        let ux = self.steady_axial(x);
        let mut s = Sample {
            u: Vec3::new(phi * ux, 0.0, 0.0),
            du_dt: Vec3::new(dphi * ux, 0.0, 0.0),
            ..Sample::default()
        };
        if want_grad {
            // Column j = ∂u/∂x_j; only u_x is non-zero.
            let d = |e: Vec3| {
                phi * (self.steady_axial(x + GRAD_STEP * e) - self.steady_axial(x - GRAD_STEP * e))
                    / (2.0 * GRAD_STEP)
            };
            let g = Vec3::new(d(Vec3::X), d(Vec3::Y), d(Vec3::Z));
            s.grad =
                Mat3::from_cols(Vec3::new(g.x, 0.0, 0.0), Vec3::new(g.y, 0.0, 0.0), Vec3::new(g.z, 0.0, 0.0));
        }
        Some(s)
    }

    fn bounds(&self) -> Option<Aabb> {
        None
    }

    fn has_turbulence(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn din() -> PipeAir {
        PipeAir {
            length: 0.29,
            radius: 0.015,
            bulk: 28.0,
            exponent: 7.0,
            ramp: 0.0,
            outside: Outside::FreeJet,
        }
    }

    #[test]
    fn the_pipe_profile_carries_the_given_bulk_velocity() {
        // Bulk velocity = (1/πR²) ∫ u 2πr dr of the power-law profile; closed form 2n²/((n+1)(2n+1)) U_c
        // (Schlichting & Gersten §17.2: 0.8167 for n = 7). Midpoint rule over 200 000 rings, tolerance 1e-5
        // relative (the integrand's (1 − r/R)^{1/7} root at the wall limits the rule's order).
        let a = din();
        assert!((a.bulk / a.centreline() - 98.0 / 120.0).abs() < 1e-12);
        let n = 200_000;
        let dr = a.radius / n as f64;
        let mut q = 0.0;
        for k in 0..n {
            let r = (k as f64 + 0.5) * dr;
            q += a.steady_axial(Vec3::new(-0.1, r, 0.0)) * 2.0 * std::f64::consts::PI * r * dr;
        }
        let ub = q / (std::f64::consts::PI * a.radius * a.radius);
        assert!((ub / a.bulk - 1.0).abs() < 1e-5, "{ub}");
    }

    #[test]
    fn the_jet_is_continuous_and_decays_as_the_self_similar_round_jet() {
        // Pope (2000) §5.1: far from the exit U_0(x) = B U_b D / x and the half-velocity radius is S x.
        let a = din();
        let d = 2.0 * a.radius;
        let x = 40.0 * d;
        let u0 = a.steady_axial(Vec3::new(x, 0.0, 0.0));
        assert!((u0 - JET_DECAY_B * a.bulk * d / x).abs() < 1e-12 * u0);
        let half = a.steady_axial(Vec3::new(x, 0.0, JET_SPREADING_S * x));
        assert!((half / u0 - 0.5).abs() < 1e-12);
        // Continuity at the end of the potential core and at the pipe exit on the axis (1e-9 relative).
        let xc = a.core_length();
        for r in [0.0, 0.005, 0.02] {
            let below = a.steady_axial(Vec3::new(xc * (1.0 - 1e-12), r, 0.0));
            let above = a.steady_axial(Vec3::new(xc * (1.0 + 1e-12), r, 0.0));
            assert!((below - above).abs() <= 1e-9 * a.centreline(), "r = {r}: {below} vs {above}");
        }
        let inside = a.steady_axial(Vec3::new(-1e-9, 0.0, 0.0));
        let outside = a.steady_axial(Vec3::new(1e-9, 0.0, 0.0));
        assert!((inside - outside).abs() < 1e-9 * inside);
        // Still air upstream of the inlet, outside the pipe wall, and beyond the exit when stagnant.
        assert_eq!(a.steady_axial(Vec3::new(-0.3, 0.0, 0.0)), 0.0);
        assert_eq!(a.steady_axial(Vec3::new(-0.1, 0.0, 0.016)), 0.0);
        let still = PipeAir { outside: Outside::Stagnant, ..a };
        assert_eq!(still.steady_axial(Vec3::new(0.05, 0.0, 0.0)), 0.0);
    }

    #[test]
    fn a_sphere_on_the_pipe_axis_accelerates_towards_the_air_as_newton_drag_says() {
        // A 5 mm sphere of 1000 kg/m³ at rest on the axis of a long pipe (no gravity), air at the
        // centreline speed U_c: with the constant Newton-regime coefficient C_D = 0.44 of the Schiller &
        // Naumann (1933) law (valid above Re = 1000; here Re > 7000 throughout) the slip w = U_c − v obeys
        // m dw/dt = −⅛ C_D ρ_f π d² w², so w(t) = w₀ / (1 + k w₀ t) with k = ⅛ C_D ρ_f π d² / m, and the
        // distance travelled is U_c t − ln(1 + k w₀ t)/k. The DEM hook (fluid_forces) with this field, run
        // for 0.1 s at Δt = 1e-5 s, must match the slip within 1e-5 relative and the distance within 1e-4
        // (the slip falls by 20 % over the run, so a wrong law cannot pass).
        use crate::fluid_forces::{DragModel, FluidForceOptions, FluidForces, PrescribedFlow};
        use spatter_core::material::Material;
        use spatter_dem::contact::HertzMindlin;
        use spatter_dem::sim::uniform_pairs;
        use spatter_dem::{NewParticle, Settings, Simulation};
        use spatter_flow::forces::Fluid;
        use std::f64::consts::PI;
        let air = PipeAir { length: 2.0, ..din() };
        let fluid = Fluid { density: 1.204, viscosity: 1.81e-5 };
        let mats = vec![Material::new(1e9, 0.3, 1000.0).unwrap()];
        let dt = 1e-5;
        let mut sim = Simulation::new(
            HertzMindlin::default(),
            mats.clone(),
            uniform_pairs(&mats, 0.3, 0.5),
            dt,
            Settings::default(),
        );
        sim.gravity = Vec3::ZERO;
        let options = FluidForceOptions { fluid, drag: DragModel::SchillerNaumann, ..Default::default() };
        let flow = PrescribedFlow::new(air, fluid.density, Vec3::ZERO);
        sim.set_external_forces(Box::new(FluidForces::new(flow, options)));
        let d = 5e-3;
        let x0 = -1.9;
        sim.add_particle(NewParticle::at(Vec3::new(x0, 0.0, 0.0), 0.5 * d, 0));
        let steps = 10_000;
        sim.run_steps(steps).unwrap();
        let t = steps as f64 * dt;
        let m = 1000.0 * PI / 6.0 * d * d * d;
        let k = 0.125 * 0.44 * fluid.density * PI * d * d / m;
        let uc = air.centreline();
        let w = uc / (1.0 + k * uc * t);
        let x = x0 + uc * t - (1.0 + k * uc * t).ln() / k;
        let re_end = fluid.density * d * w / fluid.viscosity;
        assert!(re_end > 1000.0 && w < 0.85 * uc, "Re {re_end}, slip {w} of {uc}");
        let p = &sim.particles;
        assert!(((uc - p.vel[0].x) / w - 1.0).abs() < 1e-5, "slip {} vs {w}", uc - p.vel[0].x);
        // The distance within 1e-4: the engine evaluates the velocity-dependent drag with the velocity
        // of the previous half step, an error of first order in Δt in the position (2e-5 at this step).
        assert!(((p.pos[0].x - x0) / (x - x0) - 1.0).abs() < 1e-4, "x {} vs {x}", p.pos[0].x);
        assert!(p.vel[0].y == 0.0 && p.vel[0].z == 0.0);
    }

    #[test]
    fn the_ramp_scales_velocity_and_gives_its_time_derivative() {
        let a = PipeAir { ramp: 0.02, ..din() };
        let mut h = 0;
        let x = Vec3::new(-0.1, 0.0, 0.0);
        let s = a.sample(x, 0.005, &mut h, true).unwrap();
        let uc = a.centreline();
        assert!((s.u.x - 0.25 * uc).abs() < 1e-12 * uc);
        assert!((s.du_dt.x - uc / 0.02).abs() < 1e-9 * uc / 0.02);
        // On the axis the profile is flat across: ∂u_x/∂y = 0 by symmetry (central differences).
        assert!(s.grad.col(1).x.abs() < 1e-6, "{:?}", s.grad);
        let s = a.sample(x, 0.05, &mut h, false).unwrap();
        assert_eq!((s.u.x, s.du_dt.x), (uc, 0.0));
    }
}
