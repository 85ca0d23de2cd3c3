//! A helicopter rotor downwash model: momentum theory, ground effect and analytic tip vortices.
//!
//! Sources: Jasion (2013) eq. 4.13, 4.26–4.27, 6.1–6.3, 6.11–6.14 (`digests/seed_003_brownout.md` §4.3,
//! §4.5, §4.6, §6.4).
//!
//! **Mean flow.** The rotor (axis +z, hub at `hub_m`, ground plane z = `ground_z_m`) has induced velocity
//! v_ind = √(T/(2ρA)) (momentum theory). The free wake is the classical actuator-disk slipstream: on the
//! axis w(z′) = −v_ind (1 + z′/√(z′² + R²)) with z′ the depth below the disk, reaching 2 v_ind far below,
//! and the slipstream radius R_w = R √(v_ind/|w|) carries the disk's volume flux (contraction to R/√2).
//! The flow is written with a Stokes stream function, so it is divergence-free by construction:
//!
//! ψ(r, z) = −½ v_ind R² S(r²/R_w²) · G(ζ),   u_r = −(1/r) ∂ψ/∂z,   u_z = (1/r) ∂ψ/∂r,
//!
//! with S a smoothed min(s, 1) (the slipstream's shear layer, sharpness `shear_layer_sharpness`) and,
//! in ground effect, G(ζ) = 1 − (1 + ζ) e^(−ζ), ζ = (z − z_ground)/h(r): the downwash turns into a radial
//! wall jet of thickness h = h₀ + s·max(r − R, 0) whose velocity peaks at height h and vanishes at the
//! ground. Far from the ground G → 1 and the free slipstream is recovered. This is an engineering model
//! (no entrainment: the wall jet's flux is the rotor's), meant for particle studies, not a CFD substitute.
//!
//! **Tip vortices.** Each of the N_b blades sheds a tip vortex, represented as a ring (helix → ring, as in
//! the thesis) born at the tip every 2π/(N_b Ω), convected at `vortex_speed_fraction`·v_ind along the
//! slipstream boundary and then radially along the ground at height `vortex_path_height`·R (Table 5.1:
//! ≈ R/4). Circulation Γ_v = 2T/(N_b ρ Ω R²) (Γ_v = T/(ρΩR²) for two blades, Jasion L2566), core radius
//! with Ananthan strain and Squire diffusion (eq. 6.13)
//!
//! r_c(ψ) = √(r_c0² + 4 α δ_v ν ψ/Ω) / √(1 + ε),   δ_v = 1 + a₁ Γ_v/ν,   ε = (r_v − R)/R,   ψ = Ω·age,
//!
//! and Lamb–Oseen swirl (eq. 6.14) in the meridional plane about the ring's core (the thesis's 2-D
//! treatment; the ring's self-induction is neglected), plus its mirror image in the ground.

use super::analytic::LAMB_OSEEN_ALPHA;
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;
use std::f64::consts::PI;

/// Rotor model parameters. Scenario table `{ kind = "rotor", … }`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorDownwash {
    /// Rotor hub (disk centre) \[m\]; the axis is +z.
    pub hub_m: Vec3,
    /// Rotor radius R \[m\].
    pub radius_m: f64,
    /// Thrust T \[N\] (hover: the weight).
    pub thrust_n: f64,
    /// Air density \[kg/m³\].
    #[serde(default = "default_rho")]
    pub air_density_kg_m3: f64,
    /// Kinematic viscosity ν \[m²/s\] (vortex core diffusion).
    #[serde(default = "default_nu")]
    pub kinematic_viscosity_m2_s: f64,
    /// Number of blades N_b.
    #[serde(default = "default_blades")]
    pub blades: u32,
    /// Rotor speed Ω \[rad/s\].
    pub omega_rad_s: f64,
    /// Ground plane height \[m\]; `ground = false` for a rotor out of ground effect.
    #[serde(default)]
    pub ground_z_m: f64,
    #[serde(default = "yes")]
    pub ground: bool,
    /// Wall-jet thickness h₀ at r = R, as a fraction of R.
    #[serde(default = "default_layer")]
    pub ground_layer_thickness: f64,
    /// dh/dr of the wall jet beyond r = R.
    #[serde(default = "default_spreading")]
    pub ground_layer_spreading: f64,
    /// Sharpness k of the slipstream edge (larger = thinner shear layer).
    #[serde(default = "default_sharpness")]
    pub shear_layer_sharpness: f64,
    /// Superpose the tip-vortex rings.
    #[serde(default)]
    pub tip_vortices: bool,
    /// Initial core radius r_c0 / R (Jasion: 0.03).
    #[serde(default = "default_core")]
    pub core_radius_fraction: f64,
    /// Squire's a₁ (Jasion: 2 × 10⁻⁴).
    #[serde(default = "default_a1")]
    pub squire_a1: f64,
    /// Height of the vortex path along the ground / R (Table 5.1: ≈ 0.25).
    #[serde(default = "default_path")]
    pub vortex_path_height: f64,
    /// Convection speed of the vortices / v_ind (Jasion L2116: ≈ ½).
    #[serde(default = "default_speed")]
    pub vortex_speed_fraction: f64,
    /// Vortices older than this many revolutions are dropped.
    #[serde(default = "default_age")]
    pub vortex_max_age_revs: f64,
}

fn default_rho() -> f64 {
    1.225
}
fn default_nu() -> f64 {
    1.5e-5
}
fn default_blades() -> u32 {
    2
}
fn yes() -> bool {
    true
}
fn default_layer() -> f64 {
    0.15
}
fn default_spreading() -> f64 {
    0.09
}
fn default_sharpness() -> f64 {
    20.0
}
fn default_core() -> f64 {
    0.03
}
fn default_a1() -> f64 {
    2e-4
}
fn default_path() -> f64 {
    0.25
}
fn default_speed() -> f64 {
    0.5
}
fn default_age() -> f64 {
    10.0
}

impl Validate for RotorDownwash {
    fn validate(&self, c: &mut Checker) {
        c.finite_vec("hub_m", self.hub_m);
        c.positive("radius_m", self.radius_m);
        c.positive("thrust_n", self.thrust_n);
        c.positive("air_density_kg_m3", self.air_density_kg_m3);
        c.positive("kinematic_viscosity_m2_s", self.kinematic_viscosity_m2_s);
        if self.blades == 0 {
            c.fail("blades", "blades = 0 must be at least 1");
        }
        c.positive("omega_rad_s", self.omega_rad_s);
        c.finite("ground_z_m", self.ground_z_m);
        if self.ground && self.hub_m.z <= self.ground_z_m {
            c.fail(
                "hub_m",
                format!("hub_m.z = {} must lie above ground_z_m = {}", self.hub_m.z, self.ground_z_m),
            );
        }
        c.positive("ground_layer_thickness", self.ground_layer_thickness);
        c.non_negative("ground_layer_spreading", self.ground_layer_spreading);
        c.positive("shear_layer_sharpness", self.shear_layer_sharpness);
        c.positive("core_radius_fraction", self.core_radius_fraction);
        c.non_negative("squire_a1", self.squire_a1);
        c.positive("vortex_path_height", self.vortex_path_height);
        c.positive("vortex_speed_fraction", self.vortex_speed_fraction);
        c.positive("vortex_max_age_revs", self.vortex_max_age_revs);
    }
}

/// Momentum-theory induced velocity v_ind = √(T/(2ρA)) \[m/s\] (Jasion eq. 4.13, 6.1–6.3).
pub fn induced_velocity(thrust: f64, rho: f64, radius: f64) -> f64 {
    (thrust / (2.0 * rho * PI * radius * radius)).sqrt()
}

/// Mass flow through the disk ṁ = ρ v_ind A \[kg/s\].
pub fn mass_flow(thrust: f64, rho: f64, radius: f64) -> f64 {
    rho * induced_velocity(thrust, rho, radius) * PI * radius * radius
}

/// Cheeseman & Bennett (1955) power ratio P_IGE/P_OGE = 1 − (R/z_d)²/16 at constant thrust (eq. 4.26).
pub fn cheeseman_bennett(z_over_r: f64) -> f64 {
    1.0 - 1.0 / (16.0 * z_over_r * z_over_r)
}

/// Hayden (1976) power ratio P_IGE/P_OGE = 1/(0.9926 + 0.0379 (2R/z_d)²) (eq. 4.27).
pub fn hayden(z_over_r: f64) -> f64 {
    let q = 2.0 / z_over_r;
    1.0 / (0.9926 + 0.0379 * q * q)
}

/// Tip-vortex circulation Γ_v = 2T/(N_b ρ Ω R²) \[m²/s\].
pub fn tip_vortex_circulation(thrust: f64, blades: u32, rho: f64, omega: f64, radius: f64) -> f64 {
    2.0 * thrust / (blades as f64 * rho * omega * radius * radius)
}

/// Squire's turbulent-diffusion factor δ_v = 1 + a₁ Γ_v/ν.
pub fn squire_delta(a1: f64, circulation: f64, nu: f64) -> f64 {
    1.0 + a1 * circulation / nu
}

/// Core radius r_c \[m\] at wake age ψ \[rad\] with strain ε (Jasion eq. 6.13).
pub fn core_radius(rc0: f64, delta_v: f64, nu: f64, psi: f64, omega: f64, strain: f64) -> f64 {
    (rc0 * rc0 + 4.0 * LAMB_OSEEN_ALPHA * delta_v * nu * psi / omega).sqrt() / (1.0 + strain).sqrt()
}

/// Smoothed min(s, 1) with S(0) = 0, S(∞) = 1.
fn smooth_min1(s: f64, k: f64) -> f64 {
    let sm = |x: f64| -((-k * x).exp() + (-k).exp()).ln() / k;
    let s0 = sm(0.0);
    (sm(s) - s0) / (1.0 - s0)
}

impl RotorDownwash {
    pub fn induced_velocity(&self) -> f64 {
        induced_velocity(self.thrust_n, self.air_density_kg_m3, self.radius_m)
    }

    pub fn circulation(&self) -> f64 {
        tip_vortex_circulation(
            self.thrust_n,
            self.blades,
            self.air_density_kg_m3,
            self.omega_rad_s,
            self.radius_m,
        )
    }

    /// Axial speed of the free slipstream |w| at depth z′ below the disk.
    pub fn slipstream_speed(&self, depth: f64) -> f64 {
        let r = self.radius_m;
        self.induced_velocity() * (1.0 + depth / (depth * depth + r * r).sqrt())
    }

    /// Slipstream radius at depth z′ \[m\].
    pub fn slipstream_radius(&self, depth: f64) -> f64 {
        self.radius_m * (self.induced_velocity() / self.slipstream_speed(depth).max(1e-300)).sqrt()
    }

    /// Stokes stream function ψ(r, z) of the mean flow \[m³/s\].
    pub fn stream_function(&self, r: f64, z: f64) -> f64 {
        let depth = self.hub_m.z - z;
        let rw = self.slipstream_radius(depth);
        let r0 = self.radius_m;
        let mut psi = -0.5
            * self.induced_velocity()
            * r0
            * r0
            * smooth_min1(r * r / (rw * rw), self.shear_layer_sharpness);
        if self.ground {
            let h = r0 * self.ground_layer_thickness + self.ground_layer_spreading * (r - r0).max(0.0);
            let zeta = ((z - self.ground_z_m) / h).max(0.0);
            psi *= 1.0 - (1.0 + zeta) * (-zeta).exp();
        }
        psi
    }

    /// Mean-flow velocity (u_r, u_z) at (r, z).
    pub fn mean_velocity_rz(&self, r: f64, z: f64) -> (f64, f64) {
        self.velocity_rz(r, z, |r, z| self.stream_function(r, z))
    }

    /// Position (r_v, z_v) of a vortex ring of age `age` \[s\] along its path.
    pub fn vortex_position(&self, age: f64) -> (f64, f64) {
        let s = self.vortex_speed_fraction * self.induced_velocity() * age;
        let z_path = self.ground_z_m + self.vortex_path_height * self.radius_m;
        let leg = if self.ground { (self.hub_m.z - z_path).max(0.0) } else { f64::INFINITY };
        if s < leg {
            (self.slipstream_radius(s), self.hub_m.z - s)
        } else {
            (self.slipstream_radius(leg) + (s - leg), z_path)
        }
    }

    /// (circulation, core radius) of a ring of age `age` at radius `r_v`.
    pub fn vortex_core(&self, age: f64, r_v: f64) -> f64 {
        let gamma = self.circulation();
        let nu = self.kinematic_viscosity_m2_s;
        let dv = squire_delta(self.squire_a1, gamma, nu);
        let strain = (r_v - self.radius_m) / self.radius_m;
        core_radius(
            self.core_radius_fraction * self.radius_m,
            dv,
            nu,
            self.omega_rad_s * age,
            self.omega_rad_s,
            strain,
        )
    }

    /// Stokes stream function of the rings alive at time `t` and their ground images \[m³/s\].
    pub fn vortex_stream_function(&self, r: f64, z: f64, t: f64) -> f64 {
        let gamma = self.circulation();
        let period = 2.0 * PI / (self.blades as f64 * self.omega_rad_s);
        let max_age = self.vortex_max_age_revs * 2.0 * PI / self.omega_rad_s;
        let newest = (t / period).floor();
        let mut psi = 0.0;
        let mut j = 0.0;
        loop {
            let age = t - (newest - j) * period;
            if age > max_age {
                break;
            }
            j += 1.0;
            let (rv, zv) = self.vortex_position(age);
            let rc = self.vortex_core(age, rv);
            // The tip vortex turns the flow down inboard of its core (it bounds the slipstream): with
            // Lamb's sign convention that is circulation −Γ_v. The ground image has +Γ_v.
            psi -= ring_stream_function(gamma, rv, zv, rc, r, z);
            if self.ground {
                psi += ring_stream_function(gamma, rv, 2.0 * self.ground_z_m - zv, rc, r, z);
            }
        }
        psi
    }

    /// (u_r, u_z) = (−(1/r)∂ψ/∂z, (1/r)∂ψ/∂r) by central differences of `psi`.
    fn velocity_rz(&self, r: f64, z: f64, psi: impl Fn(f64, f64) -> f64) -> (f64, f64) {
        if self.ground && z <= self.ground_z_m {
            return (0.0, 0.0);
        }
        let h = 1e-6 * self.radius_m;
        if r < h {
            // On the axis ψ ∝ r²: u_r = 0 and (1/r)∂ψ/∂r → 2ψ/r².
            return (0.0, 2.0 * psi(h, z) / (h * h));
        }
        let dpsi_dz = (psi(r, z + h) - psi(r, z - h)) / (2.0 * h);
        let dpsi_dr = (psi(r + h, z) - psi(r - h, z)) / (2.0 * h);
        (-dpsi_dz / r, dpsi_dr / r)
    }

    /// Velocity at `x` and time `t` \[m/s\].
    pub fn velocity(&self, x: Vec3, t: f64) -> Vec3 {
        let d = x - self.hub_m;
        let rho = Vec3::new(d.x, d.y, 0.0);
        let r = rho.length();
        let (ur, uz) = if self.tip_vortices {
            self.velocity_rz(r, x.z, |r, z| self.stream_function(r, z) + self.vortex_stream_function(r, z, t))
        } else {
            self.mean_velocity_rz(r, x.z)
        };
        let e_r = if r > 0.0 { rho / r } else { Vec3::ZERO };
        ur * e_r + uz * Vec3::Z
    }
}

/// Complete elliptic integrals K(m) and E(m) of parameter m = k² < 1 by the arithmetic–geometric mean
/// (Abramowitz & Stegun 17.6).
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

/// Stokes stream function at (r, z) of a vortex ring of circulation Γ, radius r_v at height z_v: the
/// thin ring of Lamb (1932) §161, ψ = (Γ/2π)√(r r_v)[(2/k − k)K − (2/k)E], k² = 4 r r_v/((r + r_v)² +
/// (z − z_v)²), multiplied by the Lamb–Oseen core factor 1 − exp(−α d²/r_c²) of the distance d to the
/// core line so that the velocity stays finite and vanishes there. Any ψ gives a divergence-free flow.
pub fn ring_stream_function(gamma: f64, rv: f64, zv: f64, rc: f64, r: f64, z: f64) -> f64 {
    let dz = z - zv;
    let d2 = (r - rv) * (r - rv) + dz * dz;
    if d2 <= 0.0 || r <= 0.0 {
        return 0.0;
    }
    let m = (4.0 * r * rv / ((r + rv) * (r + rv) + dz * dz)).min(1.0 - 1e-16);
    let k = m.sqrt();
    let (kk, ee) = elliptic_ke(m);
    let thin = gamma / (2.0 * PI) * (r * rv).sqrt() * ((2.0 / k - k) * kk - 2.0 / k * ee);
    thin * (1.0 - (-LAMB_OSEEN_ALPHA * d2 / (rc * rc)).exp())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::fd_gradient;

    fn bell47(ground: bool) -> RotorDownwash {
        RotorDownwash {
            hub_m: Vec3::new(0.0, 0.0, 0.68 * 5.66),
            radius_m: 5.66,
            thrust_n: 8800.0,
            air_density_kg_m3: 1.19,
            kinematic_viscosity_m2_s: 1.82e-5 / 1.19,
            blades: 2,
            omega_rad_s: 35.6,
            ground_z_m: 0.0,
            ground,
            ground_layer_thickness: 0.15,
            ground_layer_spreading: 0.09,
            shear_layer_sharpness: 20.0,
            tip_vortices: false,
            core_radius_fraction: 0.03,
            squire_a1: 2e-4,
            vortex_path_height: 0.25,
            vortex_speed_fraction: 0.5,
            vortex_max_age_revs: 10.0,
        }
    }

    #[test]
    fn momentum_theory_and_ground_effect_values() {
        // digests/seed_003_brownout.md §6.4 item 1 ([R]): v_ind = 6.06 m/s, ṁ = 725.9 kg/s.
        assert!((induced_velocity(8800.0, 1.19, 5.66) - 6.06).abs() < 0.005);
        assert!((mass_flow(8800.0, 1.19, 5.66) - 725.9).abs() < 0.5);
        // §6.4 item 2 ([D]), 4 decimals: z_d/R = 0.5, 0.68, 1.5, 4.
        for (z, cb, hy) in
            [(0.5, 0.7500, 0.6254), (0.68, 0.8648, 0.7573), (1.5, 0.9722, 0.9434), (4.0, 0.9961, 0.9979)]
        {
            assert!((cheeseman_bennett(z) - cb).abs() < 5e-5, "CB {z}");
            assert!((hayden(z) - hy).abs() < 5e-5, "Hayden {z}: {}", hayden(z));
        }
    }

    #[test]
    fn tip_vortex_values() {
        // §4.6 / §6.4 item 14 ([D]): Γ_v = 6.48 m²/s, δ_v = 85.8 (ν = 1.53e-5), r_c0 = 0.03R = 0.170 m.
        let g = tip_vortex_circulation(8800.0, 2, 1.19, 35.6, 5.66);
        assert!((g - 6.48).abs() < 0.005, "{g}");
        let dv = squire_delta(2e-4, g, 1.53e-5);
        assert!((dv - 85.8).abs() < 0.05, "{dv}");
        assert!((0.03 * 5.66f64 - 0.170).abs() < 0.001);
        // Core growth: unstrained, r_c² − r_c0² = 4αδ_vν t.
        let rc = core_radius(0.17, dv, 1.53e-5, 35.6 * 2.0, 35.6, 0.0);
        assert!((rc * rc - 0.17 * 0.17 - 4.0 * LAMB_OSEEN_ALPHA * dv * 1.53e-5 * 2.0).abs() < 1e-12);
        // Stretching (ε > 0) thins the core by 1/√(1+ε).
        assert!((core_radius(0.17, dv, 1.53e-5, 0.0, 35.6, 0.44) - 0.17 / 1.2).abs() < 1e-12);
    }

    #[test]
    fn free_slipstream_contracts_and_doubles_speed() {
        let r = bell47(false);
        let vi = r.induced_velocity();
        // On the axis at the disk: v_ind; far below: 2 v_ind; radius → R/√2.
        let (_, uz) = r.mean_velocity_rz(0.0, r.hub_m.z);
        assert!((uz + vi).abs() < 1e-6 * vi, "{uz}");
        let far = r.hub_m.z - 200.0 * r.radius_m;
        let (_, uz) = r.mean_velocity_rz(0.0, far);
        assert!((uz + 2.0 * vi).abs() < 1e-3 * vi);
        assert!((r.slipstream_radius(1e4 * r.radius_m) - r.radius_m / 2f64.sqrt()).abs() < 1e-3);
        // Volume flux through a plane below the disk equals π R² v_ind (stream function at large r).
        let psi = r.stream_function(3.0 * r.radius_m, r.hub_m.z - 2.0);
        assert!((2.0 * PI * psi.abs() / (PI * r.radius_m.powi(2) * vi) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn ground_effect_flow_is_divergence_free_and_turns_radial() {
        let mut r = bell47(true);
        r.tip_vortices = true;
        for x in [
            Vec3::new(3.0, 1.0, 1.0),
            Vec3::new(8.0, -2.0, 0.4),
            Vec3::new(1.0, 0.5, 3.0),
            Vec3::new(12.0, 3.0, 1.5),
        ] {
            let g = fd_gradient(|p| r.velocity(p, 0.37), x, 1e-5);
            let div = g.x_axis.x + g.y_axis.y + g.z_axis.z;
            let scale = g.x_axis.length() + g.y_axis.length() + g.z_axis.length();
            assert!(div.abs() < 1e-4 * scale, "{x}: {div} vs {scale}");
        }
        assert_eq!(r.velocity(Vec3::new(7.0, 0.0, 0.0), 0.0), Vec3::ZERO, "no flow through the ground");
        // Mean flow: outflow along the ground beyond the disk edge, of the order of v_ind at r = 1.5R
        // (Jasion Fig. 6.1).
        r.tip_vortices = false;
        assert!(r.velocity(Vec3::new(1.5 * 5.66, 0.0, 0.1), 0.0).x > 0.0);
        let peak = (1..200)
            .map(|i| r.velocity(Vec3::new(1.5 * 5.66, 0.0, i as f64 * 0.01), 0.0).x)
            .fold(0.0, f64::max);
        let vi = r.induced_velocity();
        assert!(peak > 0.5 * vi && peak < 2.0 * vi, "{peak} vs v_ind {vi}");
    }

    #[test]
    fn elliptic_integrals_and_ring_velocity() {
        // A&S Table 17.1: K(0.5) = 1.8540746773, E(0.5) = 1.3506438810.
        let (k, e) = elliptic_ke(0.5);
        assert!((k - 1.8540746773).abs() < 1e-10 && (e - 1.3506438810).abs() < 1e-10);
        // A thin ring's speed on its axis is Γ r_v²/(2 (r_v² + z²)^(3/2)) (Lamb §161).
        let (g, rv) = (2.0, 1.0);
        let h = 1e-4;
        let z = 0.7;
        let uz_axis = 2.0 * ring_stream_function(g, rv, 0.0, 1e-3, h, z) / (h * h);
        let expect = g * rv * rv / (2.0 * (rv * rv + z * z).powf(1.5));
        assert!((uz_axis.abs() - expect).abs() < 1e-4 * expect, "{uz_axis} vs {expect}");
    }

    #[test]
    fn tip_vortex_turns_down_inboard_of_its_core() {
        // A ring just born at the tip: inboard of its core the flow goes down (it bounds the wake).
        let r = bell47(true);
        let rv = r.radius_m;
        let zc = r.hub_m.z;
        let uz = |x: f64| {
            let h = 1e-6;
            let psi = |a: f64| -ring_stream_function(r.circulation(), rv, zc, 0.1, a, zc);
            (psi(x + h) - psi(x - h)) / (2.0 * h) / x
        };
        assert!(uz(rv - 0.3) < 0.0 && uz(rv + 0.3) > 0.0, "{} {}", uz(rv - 0.3), uz(rv + 0.3));
    }

    #[test]
    fn vortex_path_follows_the_wake_and_the_ground() {
        let r = bell47(true);
        let (rv, zv) = r.vortex_position(0.0);
        assert!((rv - 5.66).abs() < 1e-12 && (zv - r.hub_m.z).abs() < 1e-12);
        let (rv, zv) = r.vortex_position(10.0);
        assert!((zv - 0.25 * 5.66).abs() < 1e-12 && rv > 5.66);
    }
}
