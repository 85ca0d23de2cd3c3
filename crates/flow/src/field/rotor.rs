//! A helicopter rotor downwash model: momentum theory, ground effect and analytic tip vortices.
//!
//! Sources: Jasion (2013) eq. 4.13, 4.26–4.27, 6.1–6.3, 6.11–6.14.
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

pub mod rings;
pub mod special;
pub mod table;

use super::analytic::LAMB_OSEEN_ALPHA;
pub use rings::{ring_stream_function, ring_velocity, VortexPath};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::Vec3;
pub use special::elliptic_ke;
use std::f64::consts::PI;
use std::sync::{Arc, OnceLock};
pub use table::VortexTable;

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
    /// Evaluate the tip vortices from a precomputed table plus the exact rings near the point
    /// ([`table`]); `false` sums every ring directly (same field within [`table::TABLE_TOLERANCE`],
    /// slower).
    #[serde(default = "yes")]
    pub vortex_table: bool,
    /// The table, built on first use (not part of the configuration).
    #[serde(skip)]
    pub vortex_cache: VortexCache,
}

/// Lazily built [`VortexTable`] of a rotor, shared by its clones. Compares equal to any other cache: it
/// is derived data, not configuration.
#[derive(Clone, Default)]
pub struct VortexCache(OnceLock<Option<Arc<VortexTable>>>);

impl PartialEq for VortexCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for VortexCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0.get() {
            Some(Some(t)) => write!(f, "VortexCache({} nodes)", t.nodes()),
            Some(None) => write!(f, "VortexCache(direct)"),
            None => write!(f, "VortexCache(not built)"),
        }
    }
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
    /// A rotor with hub `hub_m`, radius, thrust and speed, every other key at its default.
    pub fn new(hub_m: Vec3, radius_m: f64, thrust_n: f64, omega_rad_s: f64) -> Self {
        RotorDownwash {
            hub_m,
            radius_m,
            thrust_n,
            air_density_kg_m3: default_rho(),
            kinematic_viscosity_m2_s: default_nu(),
            blades: default_blades(),
            omega_rad_s,
            ground_z_m: 0.0,
            ground: true,
            ground_layer_thickness: default_layer(),
            ground_layer_spreading: default_spreading(),
            shear_layer_sharpness: default_sharpness(),
            tip_vortices: false,
            core_radius_fraction: default_core(),
            squire_a1: default_a1(),
            vortex_path_height: default_path(),
            vortex_speed_fraction: default_speed(),
            vortex_max_age_revs: default_age(),
            vortex_table: true,
            vortex_cache: VortexCache::default(),
        }
    }

    /// The Bell 47 (H-13) in hover of Jasion (2013) Ch. 6 at hub height `z_d_over_r`·R above the ground
    /// at z = 0: R = 5.66 m, T = W = 8.8 kN, Ω = 35.6 rad/s, two blades, air ρ = 1.19 kg/m³,
    /// μ = 1.82 × 10⁻⁵ Pa s (Table 6.1); tip vortices off.
    pub fn bell47(z_d_over_r: f64) -> Self {
        let radius = 5.66;
        let mut r = RotorDownwash::new(Vec3::new(0.0, 0.0, z_d_over_r * radius), radius, 8800.0, 35.6);
        r.air_density_kg_m3 = 1.19;
        r.kinematic_viscosity_m2_s = 1.82e-5 / 1.19;
        r
    }

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

    /// The tip-vortex system (path, core growth, circulation) with its constants precomputed.
    pub fn vortex_path(&self) -> VortexPath {
        VortexPath::new(self)
    }

    /// Position (r_v, z_v) of a vortex ring of age `age` \[s\] along its path.
    pub fn vortex_position(&self, age: f64) -> (f64, f64) {
        self.vortex_path().position(age)
    }

    /// Core radius \[m\] of a ring of age `age` at radius `r_v` (eq. 6.13).
    pub fn vortex_core(&self, age: f64, r_v: f64) -> f64 {
        self.vortex_path().core(age, r_v)
    }

    /// Stokes stream function of the rings alive at time `t` and their ground images \[m³/s\].
    pub fn vortex_stream_function(&self, r: f64, z: f64, t: f64) -> f64 {
        let path = self.vortex_path();
        let phi = path.phase(t);
        let mut psi = 0.0;
        for j in 0..path.count(phi) {
            let ring = path.ring(phi + j as f64 * path.period);
            // The tip vortex turns the flow down inboard of its core (it bounds the slipstream): with
            // Lamb's sign convention that is circulation −Γ_v. The ground image has +Γ_v.
            psi -= ring_stream_function(path.gamma, ring.r, ring.z, ring.rc, r, z);
            if let Some(zg) = path.ground_z {
                psi += ring_stream_function(path.gamma, ring.r, 2.0 * zg - ring.z, ring.rc, r, z);
            }
        }
        psi
    }

    /// The tip-vortex table when it is in use (built on the first call; `None` with `tip_vortices` or
    /// `vortex_table` off, or when the rotor was changed after the table was built).
    pub fn tabulated_vortices(&self) -> Option<&VortexTable> {
        if !(self.tip_vortices && self.vortex_table) {
            return None;
        }
        let table = self
            .vortex_cache
            .0
            .get_or_init(|| {
                let mut source = self.clone();
                source.vortex_cache = VortexCache::default();
                VortexTable::build(&source).map(Arc::new)
            })
            .as_deref()?;
        (table.source == *self).then_some(table)
    }

    /// Velocity (u_r, u_z) of the tip vortices at (r, z), time `t`: the table with the exact near rings,
    /// or the direct sum over every ring.
    pub fn vortex_velocity_rz(&self, r: f64, z: f64, t: f64) -> (f64, f64) {
        if self.ground && z <= self.ground_z_m {
            return (0.0, 0.0);
        }
        match self.tabulated_vortices() {
            Some(table) => table.velocity(r, z, t),
            None => self.vortex_path().velocity_direct(r, z, t),
        }
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
        let (mut ur, mut uz) = self.mean_velocity_rz(r, x.z);
        if self.tip_vortices {
            let (a, b) = self.vortex_velocity_rz(r, x.z, t);
            ur += a;
            uz += b;
        }
        let e_r = if r > 0.0 { rho / r } else { Vec3::ZERO };
        ur * e_r + uz * Vec3::Z
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::fd_gradient;

    fn bell47(ground: bool) -> RotorDownwash {
        let mut r = RotorDownwash::bell47(0.68);
        r.ground = ground;
        r
    }

    #[test]
    fn momentum_theory_and_ground_effect_values() {
        // Momentum theory for the Bell 47 of Jasion (2013) (W = 8.8 kN, R = 5.66 m, ρ = 1.19): v_ind = 6.06 m/s, ṁ = 725.9 kg/s.
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

    #[test]
    fn vortex_velocity_is_the_curl_of_the_vortex_stream_function() {
        // The closed-form ring velocities summed over every ring equal the central differences of the
        // summed stream function: u_r = −(1/r)∂ψ/∂z, u_z = (1/r)∂ψ/∂r.
        let mut r = bell47(true);
        r.tip_vortices = true;
        r.vortex_table = false;
        let t = 0.731;
        for (x, z) in [(3.0, 1.0), (6.5, 1.5), (8.0, 0.3), (5.0, 3.5), (12.0, 2.0)] {
            let h = 1e-6 * r.radius_m;
            let psi = |a: f64, b: f64| r.vortex_stream_function(a, b, t);
            let ur = -(psi(x, z + h) - psi(x, z - h)) / (2.0 * h) / x;
            let uz = (psi(x + h, z) - psi(x - h, z)) / (2.0 * h) / x;
            let path = r.vortex_path();
            let phi = path.phase(t);
            let (a, b) = path.velocity_rings(phi, path.count(phi), x, z, |ring| ring.rc);
            let scale = a.abs() + b.abs() + 1e-2;
            assert!(
                (a - ur).abs() < 1e-5 * scale && (b - uz).abs() < 1e-5 * scale,
                "({x}, {z}): {a} {b} vs {ur} {uz}"
            );
        }
    }
}
