//! Erosion wear of mesh walls, per triangle and per material pair.
//!
//! A wear model turns one impact into an eroded wall mass. It is evaluated **once per impact, at first
//! touch**: in the force evaluation in which a particle–triangle contact forms, with the particle centre's
//! velocity relative to the wall at that moment (under velocity Verlet the half-step velocity the contact
//! force saw, i.e. the approach velocity). This is the single-impact form of the erosion laws, which are
//! stated per impacting particle (eroded mass per impacting mass); integrating a rate along the contact
//! (LIGGGHTS `wear finnie`) instead would count sliding contacts continuously and depend on the contact
//! law. The particle mass is that of the impacting body (a clump's whole mass for a member contact).
//!
//! Models (selectable per particle material × wall material pair):
//!
//! * [`WearModel::Finnie`] — ductile micro-cutting, Finnie (1960), "Erosion of surfaces by solid
//!   particles", Wear 3:87–103, in the simplified form of ANSYS CFX and LIGGGHTS:
//!   Δm = k m v² f(γ), f(γ) = sin 2γ − 3 sin²γ for tan γ ≤ 1/3 (γ ≤ 18.43°), cos²γ/3 above, γ the impact
//!   angle between the velocity and the wall plane. Maximum 0.30278 at γ = 16.85°, **f(90°) = 0**:
//!   normal impacts erode nothing.
//! * [`WearModel::NormalEnergy`] — for brittle coatings that chip under normal impact: Δm =
//!   c max(0, ½ m v_n² − E_th), the normal kinetic energy above a threshold E_th (the threshold form
//!   used for the impact-energy rating of coatings in gravelometer tests, e.g. the critical impact energy
//!   of stone-chip resistance; c in kg/J). Largest at normal incidence, zero for grazing impacts.
//!
//! The model's name is written with the results (`WearModel::name`).

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};

/// An erosion law (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "model", rename_all = "snake_case", deny_unknown_fields)]
pub enum WearModel {
    /// Finnie micro-cutting: Δm = k m v² f(γ); `k` in s²/m² (eroded mass per impacting mass per v²).
    Finnie {
        #[serde(rename = "k_s2_m2")]
        k: f64,
    },
    /// Brittle normal-energy threshold: Δm = c max(0, ½ m v_n² − E_th); `c` in kg/J, `E_th` in J.
    NormalEnergy {
        #[serde(rename = "coefficient_kg_j")]
        coefficient: f64,
        #[serde(rename = "threshold_j", default)]
        threshold: f64,
    },
}

impl WearModel {
    /// Name written to the outputs.
    pub fn name(&self) -> &'static str {
        match self {
            WearModel::Finnie { .. } => "finnie",
            WearModel::NormalEnergy { .. } => "normal_energy",
        }
    }

    /// Eroded wall mass \[kg\] of one impact of a particle of mass `m` \[kg\] with normal approach speed
    /// `v_n` ≥ 0 and tangential speed `v_t` \[m/s\].
    pub fn eroded_mass(&self, m: f64, v_n: f64, v_t: f64) -> f64 {
        match *self {
            WearModel::Finnie { k } => {
                let v2 = v_n * v_n + v_t * v_t;
                if v2 <= 0.0 {
                    return 0.0;
                }
                let v = v2.sqrt();
                k * m * v2 * finnie_sc(v_n.abs() / v, v_t / v)
            }
            WearModel::NormalEnergy { coefficient, threshold } => {
                coefficient * (0.5 * m * v_n * v_n - threshold).max(0.0)
            }
        }
    }
}

impl Validate for WearModel {
    fn validate(&self, c: &mut Checker) {
        match *self {
            WearModel::Finnie { k } => c.non_negative("k_s2_m2", k),
            WearModel::NormalEnergy { coefficient, threshold } => {
                c.non_negative("coefficient_kg_j", coefficient);
                c.non_negative("threshold_j", threshold);
            }
        }
    }
}

/// Finnie's angle function f(γ), γ in radians between the velocity and the wall plane (module docs).
pub fn finnie_f(gamma: f64) -> f64 {
    let (s, c) = gamma.sin_cos();
    finnie_sc(s, c)
}

/// f(γ) from sin γ and cos γ (exactly 0 for a normal impact, cos γ = 0).
#[inline]
fn finnie_sc(s: f64, c: f64) -> f64 {
    if 3.0 * s > c {
        c * c / 3.0
    } else {
        2.0 * s * c - 3.0 * s * s
    }
}

/// Wear models per (particle material, wall material), `None` where no wear is computed.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WearTable {
    n: usize,
    models: Vec<Option<WearModel>>,
}

impl WearTable {
    /// An empty table for `n` materials.
    pub fn new(n: usize) -> Self {
        WearTable { n, models: vec![None; n * n] }
    }

    /// Sets the model of the (particle material `particle`, wall material `wall`) pair.
    pub fn set(&mut self, particle: usize, wall: usize, m: WearModel) {
        self.models[particle * self.n + wall] = Some(m);
    }

    #[inline]
    pub fn get(&self, particle: usize, wall: usize) -> Option<&WearModel> {
        if particle >= self.n || wall >= self.n {
            return None;
        }
        self.models[particle * self.n + wall].as_ref()
    }

    pub fn is_empty(&self) -> bool {
        self.models.iter().all(|m| m.is_none())
    }

    /// Names of the models in use, sorted and deduplicated.
    pub fn names(&self) -> Vec<&'static str> {
        let mut v: Vec<_> = self.models.iter().flatten().map(|m| m.name()).collect();
        v.sort_unstable();
        v.dedup();
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f(γ) of Finnie (1960, Wear 3:87–103) in the form of the stone-chip study (Qian et al. 2022, CMES):
    /// the two branches sin 2γ − 3 sin²γ and cos²γ/3 tabulated to five decimals (tolerance 5e-6);
    /// f(90°) = 0, f(54°) = 0.11516, the maximum 0.30278 at ½ atan(2/3) = 16.845° (angle to 1e-3°), the
    /// branches meeting at 0.3 where tan γ = 1/3 (18.435°).
    #[test]
    fn finnie_angle_function_matches_the_table() {
        let table = [
            (0.0, 0.0),
            (5.0, 0.15086),
            (10.0, 0.25156),
            (15.0, 0.29904),
            (16.845, 0.30278),
            (20.0, 0.29434),
            (30.0, 0.25),
            (45.0, 0.16667),
            (54.0, 0.11516),
            (60.0, 0.08333),
            (72.0, 0.03183),
            (90.0, 0.0),
        ];
        for (deg, f) in table {
            let got = finnie_f(f64::to_radians(deg));
            assert!((got - f).abs() < 5e-6, "f({deg}°) = {got}, table {f}");
        }
        // Continuous at tan γ = 1/3 (both branches 0.3); the maximum at ½ atan(2/3).
        let g = (1.0f64 / 3.0).atan();
        assert!((finnie_f(g - 1e-12) - 0.3).abs() < 1e-10 && (finnie_f(g + 1e-12) - 0.3).abs() < 1e-10);
        assert!((g.to_degrees() - 18.435).abs() < 1e-3 && (finnie_f(g) - 0.3).abs() < 1e-12);
        let gmax = 0.5 * (2.0f64 / 3.0).atan();
        assert!((gmax.to_degrees() - 16.845).abs() < 1e-3);
        assert!((finnie_f(gmax) - 0.302_775_637_7).abs() < 1e-9);
        for k in 0..1000 {
            assert!(finnie_f(k as f64 * 1.5708e-3) <= finnie_f(gmax) + 1e-15);
        }
    }

    #[test]
    fn eroded_mass_of_one_impact_is_the_closed_form() {
        let m = WearModel::Finnie { k: 2.0 };
        // 10 m/s at 30° to the plane: v_n = 5, v_t = 8.660; Δm = k m v² cos²γ/3 = 2 · 0.01 · 100 · 0.25.
        let th = 30f64.to_radians();
        let dm = m.eroded_mass(0.01, 10.0 * th.sin(), 10.0 * th.cos());
        assert!((dm - 2.0 * 0.01 * 100.0 * 0.25).abs() < 1e-12);
        assert_eq!(m.eroded_mass(0.01, 10.0, 0.0), 0.0, "Finnie: nothing at 90°");
        let b = WearModel::NormalEnergy { coefficient: 1e-6, threshold: 0.1 };
        // ½ · 0.01 · 10² = 0.5 J, 0.4 J above the threshold.
        assert!((b.eroded_mass(0.01, 10.0, 0.0) - 0.4e-6).abs() < 1e-18);
        assert_eq!(b.eroded_mass(0.01, 1.0, 10.0), 0.0, "below the threshold");
    }
}
