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

/// Smallest diameter of a `normal` distribution as a fraction of its mean: the truncation is at
/// max(mean − 3σ, `NORMAL_FLOOR_FRACTION` × mean), so a wide normal (σ > 0.3 mean) cannot draw vanishing
/// particles, whose time step and contact detection would be meaningless.
pub const NORMAL_FLOOR_FRACTION: f64 = 0.1;

/// Truncation interval `[lo, hi]` \[m\] of the normal with `mean` and `std_dev` \[m\].
fn normal_bounds(mean: f64, std_dev: f64) -> (f64, f64) {
    ((mean - 3.0 * std_dev).max(NORMAL_FLOOR_FRACTION * mean), mean + 3.0 * std_dev)
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
    /// Normal by number with `mean` and `std_dev`, truncated to `[max(mean − 3σ, mean/10), mean + 3σ]`
    /// (see [`NORMAL_FLOOR_FRACTION`]; the floor matters only for σ > 0.3 mean).
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
                let (lo, hi) = normal_bounds(*mean, *std_dev);
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

    /// Smallest diameter a draw can produce \[m\]: the diameter of `mono`, the lower end of `uniform`,
    /// max(mean − 3σ, mean/10) of the truncated `normal`, the first diameter of a `tabulated` one; `None`
    /// for the log-normal, which is unbounded below.
    pub fn min_diameter(&self) -> Option<f64> {
        match self {
            SizeDistribution::Mono { diameter } => Some(*diameter),
            SizeDistribution::Uniform { min, .. } => Some(*min),
            SizeDistribution::Normal { mean, std_dev } => Some(normal_bounds(*mean, *std_dev).0),
            SizeDistribution::LogNormal { .. } => None,
            SizeDistribution::Tabulated { diameters, .. } => diameters.first().copied(),
        }
    }

    /// Largest diameter a draw can produce \[m\]: the diameter of `mono`, the upper end of `uniform`,
    /// mean + 3σ of the truncated `normal`, the last diameter of a `tabulated` one; `None` for the
    /// log-normal, which is unbounded above.
    pub fn max_diameter(&self) -> Option<f64> {
        match self {
            SizeDistribution::Mono { diameter } => Some(*diameter),
            SizeDistribution::Uniform { max, .. } => Some(*max),
            SizeDistribution::Normal { mean, std_dev } => Some(normal_bounds(*mean, *std_dev).1),
            SizeDistribution::LogNormal { .. } => None,
            SizeDistribution::Tabulated { diameters, .. } => diameters.last().copied(),
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

    /// Standard normal CDF Φ(z) = ½ erfc(−z/√2) ([`crate::special::erfc`], relative error < 1.2·10⁻⁷).
    fn normal_cdf(z: f64) -> f64 {
        0.5 * crate::special::erfc(-z / std::f64::consts::SQRT_2)
    }

    /// Mean and standard deviation of N(μ, σ²) truncated to [lo, hi]: with α = (lo − μ)/σ,
    /// β = (hi − μ)/σ, Z = Φ(β) − Φ(α), mean = μ + σ (φ(α) − φ(β))/Z and
    /// variance = σ² [1 + (α φ(α) − β φ(β))/Z − ((φ(α) − φ(β))/Z)²] (Johnson, Kotz & Balakrishnan 1994,
    /// *Continuous Univariate Distributions* vol. 1, ch. 13, truncated normal distributions).
    fn truncated_normal_moments(mu: f64, sigma: f64, lo: f64, hi: f64) -> (f64, f64) {
        let pdf = |z: f64| (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let (a, b) = ((lo - mu) / sigma, (hi - mu) / sigma);
        let z = normal_cdf(b) - normal_cdf(a);
        let m = (pdf(a) - pdf(b)) / z;
        let var = 1.0 + (a * pdf(a) - b * pdf(b)) / z - m * m;
        (mu + sigma * m, sigma * var.sqrt())
    }

    #[test]
    fn truncated_normal_matches_its_analytic_moments_and_respects_its_bounds() {
        // 2·10⁵ draws for σ = 0.2, 0.5 and 1.0 × mean (mean 1 mm): the truncation is at mean ± 3σ for the
        // first, at the floor mean/10 (α = −1.8 and −0.9) for the others. Tolerances: 5 standard errors of
        // the sample, s/√n for the mean (1.1 % of s) and s √((κ − 1)/(4n)) for the standard deviation with
        // a kurtosis κ ≤ 4 (the untruncated normal has 3), i.e. 0.97 % of s. The former floor
        // f64::MIN_POSITIVE would give for σ = 0.5 mean (α = −2, same formulas) a mean lower by 2.9 % of s
        // and an s higher by 2.4 %: both outside these tolerances.
        let mean = 1e-3;
        let n = 200_000;
        for (k, sd_frac) in [0.2, 0.5, 1.0].into_iter().enumerate() {
            let dist = SizeDistribution::Normal { mean, std_dev: sd_frac * mean };
            // The stated bounds, max(mean − 3σ, mean/10) and mean + 3σ, are the ones reported.
            let lo = (mean - 3.0 * sd_frac * mean).max(0.1 * mean);
            let hi = mean + 3.0 * sd_frac * mean;
            assert_eq!(dist.min_diameter(), Some(lo));
            assert_eq!(dist.max_diameter(), Some(hi));
            let mut r = seeded(7, k as u64);
            let d: Vec<f64> = (0..n).map(|_| dist.sample(&mut r)).collect();
            let m = d.iter().sum::<f64>() / n as f64;
            let s = (d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
            let (m_an, s_an) = truncated_normal_moments(mean, sd_frac * mean, lo, hi);
            let se_m = s_an / (n as f64).sqrt();
            let se_s = s_an * (3.0 / (4.0 * n as f64)).sqrt();
            assert!((m - m_an).abs() < 5.0 * se_m, "σ = {sd_frac} mean: mean {m:e} vs {m_an:e}");
            assert!((s - s_an).abs() < 5.0 * se_s, "σ = {sd_frac} mean: std {s:e} vs {s_an:e}");
            // No draw outside the stated bounds (exact: the sampler rejects outside them).
            let (dmin, dmax) = d.iter().fold((f64::INFINITY, 0.0f64), |(a, b), x| (a.min(*x), b.max(*x)));
            assert!(dmin >= lo && dmax <= hi, "σ = {sd_frac} mean: draws in [{dmin:e}, {dmax:e}]");
            // The lower bound is reached, not just respected: the chance of a draw within 1 % of the mean
            // above the floor is ≥ φ(α)·0.01/(σ/mean)/Z ≥ 2.2·10⁻⁴ (least likely case α = −3, σ = 0.2 mean),
            // i.e. ≥ 44 expected draws out of 2·10⁵: missing all has probability < e⁻⁴⁴.
            assert!(dmin < lo + 0.01 * mean, "σ = {sd_frac} mean: smallest draw {dmin:e}, floor {lo:e}");
        }
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
