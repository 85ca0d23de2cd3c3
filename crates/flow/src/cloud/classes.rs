//! Grain size classes with mass fractions.

use serde::Serialize;
use spatter_core::special::erf;

/// Diameters \[m\] and the fraction of the bed's mass in each (summing to 1).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SizeClasses {
    pub diameters: Vec<f64>,
    pub mass_fractions: Vec<f64>,
}

impl SizeClasses {
    /// Classes from diameters and non-negative mass weights (normalised). Fails when the lengths
    /// differ, a diameter is not positive, a weight is negative or not finite, or the weights carry no
    /// mass.
    pub fn new(diameters: Vec<f64>, weights: Vec<f64>) -> Result<Self, String> {
        if diameters.len() != weights.len() || diameters.is_empty() {
            return Err(format!(
                "{} diameters and {} weights: give one weight per diameter, at least one",
                diameters.len(),
                weights.len()
            ));
        }
        if let Some(d) = diameters.iter().find(|d| !(d.is_finite() && **d > 0.0)) {
            return Err(format!("diameter {d} m must be positive"));
        }
        if let Some(w) = weights.iter().find(|w| !(w.is_finite() && **w >= 0.0)) {
            return Err(format!("mass weight {w} must be a non-negative number"));
        }
        let total: f64 = weights.iter().sum();
        if total <= 0.0 {
            return Err("the size distribution carries no mass (every weight is zero)".into());
        }
        Ok(SizeClasses { diameters, mass_fractions: weights.iter().map(|w| w / total).collect() })
    }

    /// `n` classes of equal width on \[`min`, `max`\] \[m\] from a normal distribution of diameters by mass
    /// (mean, standard deviation \[m\]), each class weighted by the normal's probability over its width
    /// (e.g. the desert floor of Rodgers as used by Jasion 2013 §6.5: mean 300 µm, 120 µm, 10–500 µm).
    pub fn normal_by_mass(mean: f64, std_dev: f64, min: f64, max: f64, n: usize) -> Result<Self, String> {
        if !(min > 0.0 && max > min && n > 0 && std_dev > 0.0) {
            return Err(format!(
                "normal size distribution needs 0 < min < max, std_dev > 0 and classes ≥ 1 (min {min}, max {max}, std_dev {std_dev}, classes {n})"
            ));
        }
        let w = (max - min) / n as f64;
        let cdf = |d: f64| 0.5 * (1.0 + erf((d - mean) / (std_dev * std::f64::consts::SQRT_2)));
        let diameters = (0..n).map(|k| min + (k as f64 + 0.5) * w).collect();
        let weights =
            (0..n).map(|k| (cdf(min + (k + 1) as f64 * w) - cdf(min + k as f64 * w)).max(0.0)).collect();
        SizeClasses::new(diameters, weights)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_classes_and_bad_input() {
        let c = SizeClasses::normal_by_mass(300e-6, 120e-6, 10e-6, 500e-6, 7).unwrap();
        assert!((c.mass_fractions.iter().sum::<f64>() - 1.0).abs() < 1e-12);
        assert!((c.diameters[0] - 45e-6).abs() < 1e-12);
        // Symmetric about the mean within the truncation: the class at 325 µm (covering 290–360 µm)
        // carries the most mass.
        let k = (0..7).max_by(|&a, &b| c.mass_fractions[a].total_cmp(&c.mass_fractions[b])).unwrap();
        assert_eq!(k, 4);
        assert!(SizeClasses::new(vec![1e-4], vec![0.0]).unwrap_err().contains("no mass"));
        assert!(SizeClasses::new(vec![-1e-4], vec![1.0]).is_err());
        assert!(SizeClasses::new(vec![1e-4, 2e-4], vec![1.0]).is_err());
        // A normal far outside the class range carries no mass.
        assert!(SizeClasses::normal_by_mass(1.0, 1e-6, 10e-6, 500e-6, 5).unwrap_err().contains("no mass"));
    }
}
