//! Physical and numerical parameters of an SPH simulation, with the defaults documented in `docs/sph.md`.

use crate::eos::Tait;
use crate::kernel::{Dim, Kernel, KernelKind};
use serde::{Deserialize, Serialize};
use spatter_core::Vec3;

/// Adhesion factors `[low, high]` of walls for which `spatter sessile` resolves a contact angle (see
/// [`SphParams::adhesion_note`] and docs/sph.md, "Sessile-drop calibration").
pub const ADHESION_CALIBRATED: [f64; 2] = [0.75, 3.0];

/// Air drag on fluid particles (the wading thesis gives no equation; model choice in [`crate::drag`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DragParams {
    pub enabled: bool,
    /// Air density \[kg/m³\] (1.204 at 20 °C).
    pub air_density: f64,
    /// Air dynamic viscosity \[Pa s\] (1.81e-5 at 20 °C).
    pub air_viscosity: f64,
    /// Air velocity \[m/s\]: zero for quiescent air.
    pub air_velocity: Vec3,
}

impl Default for DragParams {
    fn default() -> Self {
        DragParams { enabled: false, air_density: 1.204, air_viscosity: 1.81e-5, air_velocity: Vec3::ZERO }
    }
}

/// Everything the solver needs to know about the fluid and the numerics.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SphParams {
    pub dim: Dim,
    /// Particle spacing dp \[m\].
    pub spacing: f64,
    /// Smoothing length over spacing, h/dp (support radius 2h). Default 2.0 in 2D, 1.5 in 3D: Wendland
    /// C2 needs about 50 (2D) / 110 (3D) neighbours to keep a regular lattice from rearranging.
    pub h_over_dp: f64,
    pub kernel: KernelKind,
    /// Rest density ρ₀ \[kg/m³\]. Default 1000.
    pub rest_density: f64,
    /// Reference sound speed c₀ \[m/s\]; must be at least 10 U_max (thesis L720).
    pub sound_speed: f64,
    /// Tait exponent γ. Default 7.
    pub gamma: f64,
    /// Gravity \[m/s²\]. Default (0, 0, −9.81).
    pub gravity: Vec3,
    /// Monaghan artificial-viscosity α (β = 0). Default 0.02.
    pub artificial_viscosity: f64,
    /// Laminar (Morris et al. 1997) kinematic viscosity ν \[m²/s\]. Default 1e-6 (water).
    pub kinematic_viscosity: f64,
    /// δ-SPH density-diffusion coefficient δ (Molteni & Colagrossi 2009 with the Fourtakas et al. 2019
    /// hydrostatic correction). Default 0.1; 0 switches it off.
    pub density_diffusion: f64,
    /// Courant number of the acoustic and force time-step limits. Default 0.2.
    pub cfl: f64,
    /// Largest time step \[s\]. Default: unlimited.
    pub max_dt: f64,
    /// Particle-shifting coefficient A (Lind et al. 2012 / Skillen et al. 2013 form); 0 = off (default).
    pub shifting: f64,
    /// Surface tension σ \[N/m\] realised by Akinci et al. (2013) cohesion; 0 = off (default).
    pub surface_tension: f64,
    /// Weight of the Akinci curvature term relative to its SI form at support radius 2 dp (default 1).
    pub curvature_weight: f64,
    pub drag: DragParams,
    /// Particles whose density leaves `[lo, hi]·ρ₀` are removed and counted. Default [0.7, 1.3].
    pub density_window: [f64; 2],
    /// Wet criterion, normal reach \[m\]: a boundary particle is wet while a fluid particle lies within this
    /// distance of the surface point it stands for *along the surface normal* (either side) and within
    /// [`SphParams::wet_lateral`] of it along the surface. The surface point is dp/2 in front of a lattice
    /// or solid wall particle, a shell sample itself with the reach grown by dp
    /// (`Sampling::wet_reach`). Default 1.5·dp: water that arrives at a wall rests 0.4–1.4 dp off it
    /// (docs/sph.md §7).
    pub wet_distance: f64,
    /// Wet criterion, lateral reach \[m\] along the surface (see [`SphParams::wet_distance`]). Default
    /// 0.75·dp: the wall particle one row above a still water line (1 dp from the top fluid row along
    /// the wall) stays dry, a particle of the patch a wall particle stands for (side dp) wets it.
    pub wet_lateral: f64,
    /// A particle stopped at a wall it would have crossed is put back this far in front of it, as a
    /// fraction of dp. Default 0.2.
    pub guard_offset: f64,
}

impl SphParams {
    /// Water at spacing `dp` with sound speed `c0`, every other value at its documented default.
    pub fn water(dim: Dim, dp: f64, c0: f64) -> Self {
        SphParams {
            dim,
            spacing: dp,
            h_over_dp: match dim {
                Dim::Two => 2.0,
                Dim::Three => 1.5,
            },
            kernel: KernelKind::WendlandC2,
            rest_density: 1000.0,
            sound_speed: c0,
            gamma: 7.0,
            gravity: Vec3::new(0.0, 0.0, -9.81),
            artificial_viscosity: 0.02,
            kinematic_viscosity: 1e-6,
            density_diffusion: 0.1,
            cfl: 0.2,
            max_dt: f64::INFINITY,
            shifting: 0.0,
            surface_tension: 0.0,
            curvature_weight: 1.0,
            drag: DragParams::default(),
            density_window: [0.7, 1.3],
            wet_distance: 1.5 * dp,
            wet_lateral: 0.75 * dp,
            guard_offset: 0.2,
        }
    }

    pub fn h(&self) -> f64 {
        self.h_over_dp * self.spacing
    }

    pub fn kernel(&self) -> Kernel {
        Kernel::new(self.kernel, self.dim, self.h())
    }

    pub fn eos(&self) -> Tait {
        Tait::new(self.rest_density, self.sound_speed, self.gamma)
    }

    /// Particle volume dp^d \[m³, or m² per metre of depth in 2D\].
    pub fn particle_volume(&self) -> f64 {
        self.spacing.powi(self.dim.count())
    }

    /// Particle mass ρ₀ dp^d \[kg, or kg/m in 2D\].
    pub fn mass(&self) -> f64 {
        self.rest_density * self.particle_volume()
    }

    /// Sound speed c₀ = `factor` · U_max with `factor ≥ 10` (thesis L718–720).
    pub fn sound_speed_for(u_max: f64, factor: f64) -> f64 {
        factor * u_max
    }

    /// Akinci adhesion β per unit of a wall's `adhesion` factor: β = factor · γ · M_C/M_A with
    /// `M_X = ∫₀^R r^d X(r) dr` (d the dimension). A wall of factor 1 then pulls on the fluid near it (in the
    /// virial sense) as strongly as the fluid pulls on itself — the parameterisation of the thesis's
    /// Preonlab runs ("adhesion factor × cohesion", Arjun & Michael 2022): 1 wets like the liquid itself, 0 does not
    /// attract at all, and the sessile-drop utility maps factors to contact angles.
    pub fn adhesion_per_factor(&self) -> f64 {
        let gamma = self.cohesion_coefficient();
        if gamma == 0.0 {
            return 0.0;
        }
        let support = self.kernel().support();
        let d = self.dim.count();
        let moment = |f: &dyn Fn(f64) -> f64| {
            let n = 4000;
            let dr = support / n as f64;
            (0..n)
                .map(|i| {
                    let r = (i as f64 + 0.5) * dr;
                    r.powi(d) * f(r) * dr
                })
                .sum::<f64>()
        };
        let mc = moment(&|r| crate::kernel::akinci_cohesion(r, support));
        let ma = moment(&|r| crate::kernel::akinci_adhesion(r, support));
        gamma * mc / ma
    }

    /// Pressure that the Akinci cohesion adds to the equation-of-state pressure in the bulk (its virial
    /// pressure at uniform density): 2D `(π/2) ρ₀² γ ∫ r² C dr`, 3D `(2π/3) ρ₀² γ ∫ r³ C dr` \[Pa\].
    /// Inside a cohesive liquid at rest the EOS pressure is this plus the Laplace jump (measured: 676 Pa
    /// predicted, ≈ 700 Pa found for σ = 0.072 N/m, dp = 0.2 mm, 2D).
    pub fn cohesive_pressure(&self) -> f64 {
        let gamma = self.cohesion_coefficient();
        if gamma == 0.0 {
            return 0.0;
        }
        let support = self.kernel().support();
        let d = self.dim.count();
        let n = 4000;
        let dr = support / n as f64;
        let moment: f64 = (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * dr;
                r.powi(d) * crate::kernel::akinci_cohesion(r, support) * dr
            })
            .sum();
        let rho2 = self.rest_density * self.rest_density;
        match self.dim {
            Dim::Two => std::f64::consts::PI / 2.0 * rho2 * gamma * moment,
            Dim::Three => 2.0 * std::f64::consts::PI / 3.0 * rho2 * gamma * moment,
        }
    }

    /// Smallest sound speed \[m/s\] that keeps the compression of the liquid by its own cohesion and by a
    /// wall of adhesion factor `adhesion` below about 1 %: `10 √(p_c max(1, f)/ρ₀)`, `p_c` the cohesive
    /// pressure ([`SphParams::cohesive_pressure`]). The criterion `c₀ ≥ 10 √(p_max/ρ₀)` is the one the
    /// weakly compressible Riemann-SPH codes use beside `c₀ ≥ 10 U_max`. An adhesive wall pulls the liquid
    /// near it with about f times the cohesive pressure (the adhesion spline is scaled to the cohesion's
    /// virial moment, [`SphParams::adhesion_per_factor`]); with the sound speed of the flow alone a factor of
    /// 10 compressed the liquid at the wall by 20–30 % and the density window removed it. 0 without surface
    /// tension.
    pub fn capillary_sound_speed(&self, adhesion: f64) -> f64 {
        let p = self.cohesive_pressure() * adhesion.max(1.0);
        10.0 * (p / self.rest_density).sqrt()
    }

    /// Adhesion factors within which the sessile-drop calibration resolves a contact angle: at and below
    /// 0.5 a resting drop does not wet the wall (180°: it balls up), so below
    /// [`ADHESION_CALIBRATED`]`[0]` the angle is not resolved; above [`ADHESION_CALIBRATED`]`[1]` the wall
    /// wets completely (the drop spreads to a film one to three spacings thick, θ below about 8° in 2D and
    /// 13° in 3D), so a larger factor changes the angle little and mostly presses the film harder onto the
    /// wall. See [`SphParams::adhesion_note`] and the tables of docs/sph.md.
    pub fn adhesion_note(adhesion: f64) -> Option<String> {
        let [lo, hi] = ADHESION_CALIBRATED;
        if adhesion > 0.0 && adhesion < lo {
            Some(format!(
                "adhesion {adhesion} is below the calibrated range {lo}–{hi}: a resting drop wets such a wall little \
                 or not at all (contact angle above about 70° in 2D and 120° in 3D, 180° from 0.5 down)"
            ))
        } else if adhesion > hi {
            Some(format!(
                "adhesion {adhesion} is above the calibrated range {lo}–{hi}: the wall already wets completely \
                 (contact angle below about 8° in 2D and 13° in 3D); a larger factor mostly presses the water film \
                 harder onto the wall"
            ))
        } else {
            None
        }
    }

    /// The Akinci cohesion coefficient γ that gives surface tension σ for a flat interface in the
    /// continuum limit (Kirkwood–Buff/Fowler integral of the pair potential, uniform density):
    /// 3D `σ = (π/8) ρ₀² γ ∫ r⁴ C(r) dr`, 2D `σ = (ρ₀²/3) γ ∫ r³ C(r) dr`.
    pub fn cohesion_coefficient(&self) -> f64 {
        if self.surface_tension <= 0.0 {
            return 0.0;
        }
        let support = self.kernel().support();
        let moment = |power: i32| {
            let n = 4000;
            let dr = support / n as f64;
            (0..n)
                .map(|i| {
                    let r = (i as f64 + 0.5) * dr;
                    r.powi(power) * crate::kernel::akinci_cohesion(r, support) * dr
                })
                .sum::<f64>()
        };
        let rho2 = self.rest_density * self.rest_density;
        match self.dim {
            Dim::Three => self.surface_tension / (std::f64::consts::PI / 8.0 * rho2 * moment(4)),
            Dim::Two => self.surface_tension / (rho2 / 3.0 * moment(3)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cohesion_coefficient_scales_as_expected() {
        // γ ∝ σ, and in 3D γ ∝ 1/R² (the pair-potential moment grows as R²).
        let mut p = SphParams::water(Dim::Three, 0.001, 20.0);
        p.surface_tension = 0.072;
        let g1 = p.cohesion_coefficient();
        p.spacing = 0.002;
        let g2 = p.cohesion_coefficient();
        assert!(g1 > 0.0 && (g1 / g2 - 4.0).abs() < 1e-6, "{g1} {g2}");
        p.surface_tension = 0.036;
        assert!((p.cohesion_coefficient() / g2 - 0.5).abs() < 1e-12);
    }
}
