//! Drag laws written as a per-sphere momentum-exchange coefficient β \[kg/s\], so that the drag on a sphere
//! is F = β (u − v) with u the (interstitial) fluid velocity and v the sphere's velocity.
//!
//! Writing every law this way serves both uses: the one-way hook multiplies β by the slip, and the
//! coupled solver sums β over the spheres of a cell to get the fluid's exchange coefficient.

use serde::{Deserialize, Serialize};
use spatter_flow::forces::drag::DragLaw;
use spatter_flow::forces::Fluid;
use std::f64::consts::PI;

/// Which drag law acts on each sphere.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DragModel {
    /// Single-particle drag, C_D = 24/Re (1 + 0.15 Re^0.687) below Re = 1000 and 0.44 above (Schiller &
    /// Naumann 1933); the void fraction does not enter.
    SchillerNaumann,
    /// Di Felice (1994), Int. J. Multiphase Flow 20:153–159: C_D = (0.63 + 4.8/√Re_α)² with
    /// Re_α = α ρ_f d |u − v|/μ, times the voidage factor α^(2−χ),
    /// χ = 3.7 − 0.65 exp(−(1.5 − log₁₀ Re_α)²/2): F = ⅛ C_D ρ_f π d² α^(2−χ) |u − v| (u − v)
    /// (the form of CFDEM®coupling's `DiFeliceDrag`). The default.
    #[default]
    DiFelice,
    /// The Di Felice (Dallavalle) coefficient C_D = (0.63 + 4.8/√Re)² of a single sphere, with
    /// Re = ρ_f d |u − v|/μ and no voidage factor.
    DiFeliceSingle,
    /// Gidaspow (1994, *Multiphase Flow and Fluidization*, ch. 5): Ergun (1952) for α < 0.8,
    /// β_V = 150 (1−α)² μ/(α d²) + 1.75 (1−α) ρ_f |u − v|/d, and Wen & Yu (1966) for α ≥ 0.8,
    /// β_V = ¾ C_D α (1−α) ρ_f |u − v| α^(−2.65)/d with C_D = 24/(α Re)(1 + 0.15 (α Re)^0.687)
    /// (0.44 above α Re = 1000); β_V is per unit bed volume, one sphere of volume V_p takes
    /// β = β_V V_p/(1 − α).
    ErgunWenYu,
}

/// Below this solid fraction the Ergun branch's β_V/(1 − α) is evaluated at this value (the law is
/// only used above α = 0.8 there, so this only guards the division).
const MIN_SOLID: f64 = 1e-12;

impl DragModel {
    /// Exchange coefficient β \[kg/s\] of a sphere of diameter `d` \[m\] with slip speed `slip` = |u − v|
    /// \[m/s\] in fluid of void fraction `alpha` ∈ (0, 1]. Finite and continuous as the slip → 0.
    #[inline]
    pub fn beta(&self, fluid: &Fluid, d: f64, alpha: f64, slip: f64) -> f64 {
        let mu = fluid.viscosity;
        let stokes = 3.0 * PI * mu * d;
        let re = fluid.density * d * slip / mu;
        match self {
            DragModel::SchillerNaumann => stokes * DragLaw::SchillerNaumann.factor(re),
            DragModel::DiFelice => {
                // `DragLaw::DiFelice` returns f = C_D(Re_α) Re_α/24 · α^(1−χ) relative to Stokes drag at
                // Re, which is exactly ⅛ C_D ρ π d² α^(2−χ) |w| / (3πμd).
                let voidage = if alpha < 1.0 { Some(alpha) } else { None };
                stokes * DragLaw::DiFelice { voidage }.factor(re)
            }
            DragModel::DiFeliceSingle => stokes * DragLaw::DiFelice { voidage: None }.factor(re),
            DragModel::ErgunWenYu => {
                let vp = PI / 6.0 * d * d * d;
                if alpha < 0.8 {
                    let solid = (1.0 - alpha).max(MIN_SOLID);
                    let beta_v = 150.0 * solid * solid * mu / (alpha * d * d)
                        + 1.75 * solid * fluid.density * slip / d;
                    beta_v * vp / solid
                } else {
                    let re_a = alpha * re;
                    // C_D α Re = 24 (1 + 0.15 Re_α^0.687) stays finite as Re → 0.
                    let cd_re_a =
                        if re_a < 1000.0 { 24.0 * (1.0 + 0.15 * re_a.powf(0.687)) } else { 0.44 * re_a };
                    // ¾ C_D α ρ |w| α^(−2.65) V_p/d with C_D = cd_re_a/(α Re) and Re = ρ d |w|/μ.
                    0.75 * cd_re_a * mu / (d * d) * alpha.powf(-2.65) * vp
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn water() -> Fluid {
        Fluid { density: 1000.0, viscosity: 1e-3 }
    }

    #[test]
    fn every_law_reduces_to_its_single_sphere_form_at_alpha_one() {
        // At α = 1: Schiller–Naumann F = ⅛ C_D ρ π d² w² with C_D = 24/Re (1 + 0.15 Re^0.687) (Schiller &
        // Naumann 1933); Di Felice with and without voidage factor give the Dallavalle C_D; Wen–Yu gives
        // Schiller–Naumann. Tolerance 1e-12 relative (same formula, different algebra).
        let f = water();
        let d = 1e-3;
        for w in [1e-4, 0.01, 0.1, 0.5] {
            let re = f.density * d * w / f.viscosity;
            let drag = |cd: f64| 0.125 * cd * f.density * PI * d * d * w * w;
            let sn = drag(24.0 / re * (1.0 + 0.15 * re.powf(0.687)));
            let dv = drag((0.63 + 4.8 / re.sqrt()).powi(2));
            for (m, want) in [
                (DragModel::SchillerNaumann, sn),
                (DragModel::DiFelice, dv),
                (DragModel::DiFeliceSingle, dv),
                (DragModel::ErgunWenYu, sn),
            ] {
                let got = m.beta(&f, d, 1.0, w) * w;
                assert!((got / want - 1.0).abs() < 1e-12, "{m:?} w={w}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn di_felice_voidage_factor_and_ergun_branch() {
        // Di Felice (1994): F = ⅛ C_D(Re_α) ρ π d² α^(2−χ) w², Re_α = α Re, χ(Re_α) as in the paper; at
        // Re_α = 10^1.5, χ = 3.05 (the peak of the exponent's dip). Ergun (1952) below α = 0.8 per
        // Gidaspow (1994). Tolerance 1e-12 relative.
        let f = water();
        let d = 1e-3;
        let alpha = 0.6;
        let re_a = 10f64.powf(1.5);
        let w = re_a * f.viscosity / (alpha * f.density * d);
        let chi = 3.7 - 0.65;
        let cd = (0.63 + 4.8 / re_a.sqrt()).powi(2);
        let want = 0.125 * cd * f.density * PI * d * d * alpha.powf(2.0 - chi) * w * w;
        let got = DragModel::DiFelice.beta(&f, d, alpha, w) * w;
        assert!((got / want - 1.0).abs() < 1e-12, "{got} vs {want}");
        let vp = PI / 6.0 * d.powi(3);
        let beta_v = 150.0 * 0.16 * f.viscosity / (alpha * d * d) + 1.75 * 0.4 * f.density * w / d;
        let got = DragModel::ErgunWenYu.beta(&f, d, alpha, w);
        assert!((got / (beta_v * vp / 0.4) - 1.0).abs() < 1e-12);
    }
}
