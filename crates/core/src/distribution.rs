//! Particle size distributions (diameters in metres).

use crate::rng::{Rng, RngExt};
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

/// Whether a tabulated size distribution gives cumulative fractions by number (Q0) or by mass (Q3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PsdBasis {
    Number,
    Mass,
}

/// A distribution of particle diameters \[m\]. Sampling always draws particles by number, so a mass-based
/// table is converted (within each table interval the mass density is taken as uniform in d).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SizeDistribution {
    /// Every particle has `diameter`.
    Mono { diameter: f64 },
    /// Uniform by number on `[min, max]`.
    Uniform { min: f64, max: f64 },
    /// Normal by number with `mean` and `std_dev`, truncated to `[mean − 3σ, mean + 3σ] ∩ (0, ∞)`.
    Normal { mean: f64, std_dev: f64 },
    /// Log-normal by number: ln d ~ N(ln `median`, ln `geometric_std`), `geometric_std` ≥ 1.
    LogNormal { median: f64, geometric_std: f64 },
    /// Cumulative fractions (0 → 1, non-decreasing) at increasing `diameters`.
    Tabulated { diameters: Vec<f64>, cumulative: Vec<f64>, basis: PsdBasis },
}

impl SizeDistribution {
    /// Checks that the parameters describe a distribution of positive diameters; the message names the
    /// offending parameter.
    pub fn check(&self) -> Result<(), String> {
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!("{name} = {v} must be a positive diameter in metres"))
            }
        };
        match self {
            SizeDistribution::Mono { diameter } => pos("diameter", *diameter),
            SizeDistribution::Uniform { min, max } => {
                pos("min", *min)?;
                pos("max", *max)?;
                if max < min {
                    return Err(format!("max = {max} is smaller than min = {min}"));
                }
                Ok(())
            }
            SizeDistribution::Normal { mean, std_dev } => {
                pos("mean", *mean)?;
                if !(std_dev.is_finite() && *std_dev >= 0.0) {
                    return Err(format!("std_dev = {std_dev} must be ≥ 0"));
                }
                Ok(())
            }
            SizeDistribution::LogNormal { median, geometric_std } => {
                pos("median", *median)?;
                if !(geometric_std.is_finite() && *geometric_std >= 1.0) {
                    return Err(format!("geometric_std = {geometric_std} must be ≥ 1"));
                }
                Ok(())
            }
            SizeDistribution::Tabulated { diameters, cumulative, .. } => {
                if diameters.len() < 2 || diameters.len() != cumulative.len() {
                    return Err(format!(
                        "diameters ({}) and cumulative ({}) need the same length, at least 2",
                        diameters.len(),
                        cumulative.len()
                    ));
                }
                for (i, d) in diameters.iter().enumerate() {
                    pos(&format!("diameters[{i}]"), *d)?;
                }
                if diameters.windows(2).any(|w| w[1] <= w[0]) {
                    return Err("diameters must increase strictly".into());
                }
                if cumulative.windows(2).any(|w| w[1] < w[0]) {
                    return Err("cumulative fractions must not decrease".into());
                }
                let (first, last) = (cumulative[0], cumulative[cumulative.len() - 1]);
                if first.abs() > 1e-9 || (last - 1.0).abs() > 1e-9 {
                    return Err(format!("cumulative must run from 0 to 1, found {first} … {last}"));
                }
                Ok(())
            }
        }
    }

    /// Draws one diameter \[m\].
    pub fn sample(&self, rng: &mut Rng) -> f64 {
        match self {
            SizeDistribution::Mono { diameter } => *diameter,
            SizeDistribution::Uniform { min, max } => min + (max - min) * rng.random::<f64>(),
            SizeDistribution::Normal { mean, std_dev } => {
                let lo = (mean - 3.0 * std_dev).max(f64::MIN_POSITIVE);
                let hi = mean + 3.0 * std_dev;
                loop {
                    let z: f64 = StandardNormal.sample(rng);
                    let d = mean + std_dev * z;
                    if d >= lo && d <= hi {
                        return d;
                    }
                }
            }
            SizeDistribution::LogNormal { median, geometric_std } => {
                let z: f64 = StandardNormal.sample(rng);
                median * (geometric_std.ln() * z).exp()
            }
            SizeDistribution::Tabulated { diameters, cumulative, basis } => {
                let weights = interval_number_weights(diameters, cumulative, *basis);
                let total: f64 = weights.iter().sum();
                let mut u = rng.random::<f64>() * total;
                let mut k = weights.len() - 1;
                for (i, w) in weights.iter().enumerate() {
                    if u < *w {
                        k = i;
                        break;
                    }
                    u -= w;
                }
                let (a, b) = (diameters[k], diameters[k + 1]);
                let v: f64 = rng.random();
                match basis {
                    PsdBasis::Number => a + (b - a) * v,
                    // Number density ∝ d⁻³ inside the interval: invert its CDF.
                    PsdBasis::Mass => {
                        let (ia, ib) = (a.powi(-2), b.powi(-2));
                        (ia + v * (ib - ia)).powf(-0.5)
                    }
                }
            }
        }
    }

    /// Mean particle volume \[m³\] by number (analytic where possible), for converting mass rates to
    /// number rates.
    pub fn mean_volume(&self) -> f64 {
        use std::f64::consts::PI;
        let v = |d: f64| PI / 6.0 * d * d * d;
        match self {
            SizeDistribution::Mono { diameter } => v(*diameter),
            SizeDistribution::Uniform { min, max } => {
                if max == min {
                    v(*min)
                } else {
                    PI / 6.0 * (max.powi(4) - min.powi(4)) / (4.0 * (max - min))
                }
            }
            SizeDistribution::LogNormal { median, geometric_std } => {
                let s = geometric_std.ln();
                v(*median) * (4.5 * s * s).exp()
            }
            _ => {
                // Deterministic quadrature by sampling with a fixed stream.
                let mut rng = crate::rng::seeded(0x5eed, 0);
                let n = 20_000;
                (0..n).map(|_| v(self.sample(&mut rng))).sum::<f64>() / n as f64
            }
        }
    }
}

/// Number weight of each table interval.
fn interval_number_weights(d: &[f64], q: &[f64], basis: PsdBasis) -> Vec<f64> {
    (0..d.len() - 1)
        .map(|k| {
            let dq = q[k + 1] - q[k];
            match basis {
                PsdBasis::Number => dq,
                // Mass uniform in d over [a, b]: number ∝ ∫ (dq/(b−a)) d⁻³ dd.
                PsdBasis::Mass => {
                    let (a, b) = (d[k], d[k + 1]);
                    dq / (b - a) * 0.5 * (a.powi(-2) - b.powi(-2))
                }
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::seeded;

    fn mean_of(dist: &SizeDistribution, n: usize) -> f64 {
        let mut r = seeded(42, 0);
        (0..n).map(|_| dist.sample(&mut r)).sum::<f64>() / n as f64
    }

    #[test]
    fn sample_means_match_analytic_means() {
        // Analytic means; tolerance 1 % at 10⁵ samples (standard error < 0.3 %).
        let u = SizeDistribution::Uniform { min: 1e-3, max: 3e-3 };
        assert!((mean_of(&u, 100_000) / 2e-3 - 1.0).abs() < 0.01);
        let ln = SizeDistribution::LogNormal { median: 1e-4, geometric_std: 1.5 };
        let s = 1.5f64.ln();
        let expect = 1e-4 * (0.5 * s * s).exp();
        assert!((mean_of(&ln, 100_000) / expect - 1.0).abs() < 0.01);
        let t = SizeDistribution::Tabulated {
            diameters: vec![1e-3, 2e-3],
            cumulative: vec![0.0, 1.0],
            basis: PsdBasis::Number,
        };
        assert!((mean_of(&t, 100_000) / 1.5e-3 - 1.0).abs() < 0.01);
    }

    #[test]
    fn mass_based_table_favours_small_particles_by_number() {
        // Uniform mass density on [1, 2] mm: number density ∝ d⁻³, mean = ∫d·d⁻³ / ∫d⁻³ = 4/3 mm.
        let t = SizeDistribution::Tabulated {
            diameters: vec![1e-3, 2e-3],
            cumulative: vec![0.0, 1.0],
            basis: PsdBasis::Mass,
        };
        assert!((mean_of(&t, 200_000) / (4.0 / 3.0 * 1e-3) - 1.0).abs() < 0.01);
    }

    #[test]
    fn misspelled_keys_are_rejected() {
        let e = serde_json::from_str::<SizeDistribution>(r#"{"kind":"mono","diameter":1e-5,"typo":3}"#)
            .unwrap_err();
        assert!(e.to_string().contains("unknown field `typo`"), "{e}");
    }

    #[test]
    fn bad_parameters_are_named() {
        let e = SizeDistribution::Mono { diameter: -1.0 }.check().unwrap_err();
        assert!(e.contains("diameter = -1"), "{e}");
        let e = SizeDistribution::LogNormal { median: 1e-3, geometric_std: 0.5 }.check().unwrap_err();
        assert!(e.contains("geometric_std"), "{e}");
        let e = SizeDistribution::Tabulated {
            diameters: vec![1.0, 0.5],
            cumulative: vec![0.0, 1.0],
            basis: PsdBasis::Number,
        }
        .check()
        .unwrap_err();
        assert!(e.contains("increase"), "{e}");
    }
}
