//! Pair properties (material a × material b) and the symmetric table of precomputed pair parameters.

use serde::{Deserialize, Serialize};
use spatter_core::material::{effective_modulus, effective_shear_modulus, Material};

/// Everything a contact law may need to know about a pair of materials; each sub-law precomputes its own
/// parameters from it once per pair type.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PairProps {
    /// The two materials (a, b).
    pub materials: [Material; 2],
    /// Effective Young's modulus E* \[Pa\].
    pub e_star: f64,
    /// Effective shear modulus G* \[Pa\] (Mindlin).
    pub g_star: f64,
    /// Sliding friction coefficient μ \[-\].
    pub friction: f64,
    /// Rolling friction coefficient μ_r \[-\] (constant-torque rolling law).
    pub rolling_friction: f64,
    /// Viscous rolling coefficient μ_rv \[s/m\] (viscous rolling law).
    pub rolling_viscous: f64,
    /// Coefficient of restitution e ∈ (0, 1].
    pub restitution: f64,
    /// Work of adhesion Γ \[J/m²\] for adhesive normal laws (0 = none).
    pub work_of_adhesion: f64,
    /// Coefficient-of-restitution model of the pair, read by the speed-dependent damping law
    /// ([`crate::restitution_models::SpeedDependentDamping`], e.g. Thornton's e(V) with a yield stress);
    /// `None` lets that law use its own model. [`super::RestitutionDamping`] always uses the constant
    /// `restitution`.
    pub restitution_model: Option<crate::restitution_models::RestitutionModel>,
    /// Linear (Hooke) normal stiffness k_n of this pair \[N/m\], overriding the law's global choice
    /// (`None` = the law's own stiffness). A particle–wall pair carries the wall stiffness this way
    /// (Jasion 2013, Appendix C: k_wall = 24 k_n).
    #[serde(default)]
    pub stiffness: Option<f64>,
    /// Linear cohesion stiffness k_coh ≥ 0 \[N/m\] of [`super::LinearCohesion`] (0 = no cohesion): the
    /// attractive force k_coh·δ_coh acts while the cohesion radii overlap by δ_coh.
    #[serde(default)]
    pub cohesion_stiffness: f64,
}

impl PairProps {
    /// Pair of materials `a`, `b` with friction μ, restitution e, and no rolling resistance or adhesion.
    pub fn new(a: &Material, b: &Material, friction: f64, restitution: f64) -> Self {
        PairProps {
            materials: [a.clone(), b.clone()],
            e_star: effective_modulus(a, b),
            g_star: effective_shear_modulus(a, b),
            friction,
            rolling_friction: 0.0,
            rolling_viscous: 0.0,
            restitution,
            work_of_adhesion: 0.0,
            restitution_model: None,
            stiffness: None,
            cohesion_stiffness: 0.0,
        }
    }
}

/// A symmetric `n × n` table of per-pair-type values (`n` material types), stored as the full square so a
/// lookup is one multiply-add.
#[derive(Clone, Debug, PartialEq)]
pub struct PairTable<P> {
    n: usize,
    items: Vec<P>,
}

impl<P: Clone> PairTable<P> {
    /// Builds the table by calling `f(a, b)` for `a ≤ b` and mirroring.
    pub fn build(n: usize, mut f: impl FnMut(usize, usize) -> P) -> Self {
        let mut upper: Vec<Option<P>> = vec![None; n * n];
        for a in 0..n {
            for b in a..n {
                upper[a * n + b] = Some(f(a, b));
            }
        }
        let items = (0..n * n)
            .map(|k| {
                let (a, b) = (k / n, k % n);
                let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
                upper[lo * n + hi].clone().expect("filled above")
            })
            .collect();
        PairTable { n, items }
    }

    /// Number of material types.
    pub fn types(&self) -> usize {
        self.n
    }

    /// Value of pair (a, b).
    #[inline(always)]
    pub fn get(&self, a: usize, b: usize) -> &P {
        &self.items[a * self.n + b]
    }

    /// The values of pairs (a, 0), (a, 1) … (a, n − 1).
    #[inline(always)]
    pub fn row(&self, a: usize) -> &[P] {
        &self.items[a * self.n..][..self.n]
    }

    /// Value at flat index `k = a·n + b`.
    #[inline(always)]
    pub fn at(&self, k: usize) -> &P {
        &self.items[k]
    }

    /// Flat index `a·n + b` for [`PairTable::at`].
    #[inline(always)]
    pub fn flat(&self, a: usize, b: usize) -> usize {
        a * self.n + b
    }

    /// The pair index of (a, b) (same for (b, a)): `min·n + max`.
    #[inline(always)]
    pub fn index(&self, a: usize, b: usize) -> usize {
        let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
        lo * self.n + hi
    }

    /// Applies `f` to every entry, keeping the layout.
    pub fn map<Q: Clone>(&self, mut f: impl FnMut(usize, &P) -> Q) -> PairTable<Q> {
        let n = self.n;
        PairTable::build(n, |a, b| f(a * n + b, self.get(a, b)))
    }
}
