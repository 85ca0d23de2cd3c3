//! Stick/bounce wall rules produced by the snow regime-map workflow and consumed by particle trackers.
//!
//! The file format is JSON (`regime_map.json`, schema tag [`RegimeMap::SCHEMA`]). The rule is the one of
//! the snow thesis (Lind 2017): a particle of diameter d hitting the wall with
//! normal speed v_n sticks when v_n < v_crit(d); otherwise it bounces.

use serde::{Deserialize, Serialize};

/// A least-squares polynomial y = Σ cₖ xᵏ, optionally in log10–log10 space, valid on `x_range`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PolyFit {
    /// Name and unit of the argument, e.g. `diameter_m`.
    pub x: String,
    /// Name and unit of the value, e.g. `critical_normal_speed_m_s`.
    pub y: String,
    /// When true the polynomial maps log10(x) to log10(y).
    pub log10: bool,
    /// Coefficients c₀, c₁, … in ascending powers.
    pub coefficients: Vec<f64>,
    /// Range of x the fit was made on; arguments outside are clamped to it.
    pub x_range: [f64; 2],
    /// Root-mean-square relative error of the fit at the points it was made from.
    pub rms_relative_error: f64,
}

impl PolyFit {
    /// Checks that the fit can be evaluated: at least one finite coefficient, a finite range with
    /// `x_range[0] ≤ x_range[1]` (and positive ends in log space). The message names the offending key.
    pub fn check(&self) -> Result<(), String> {
        if self.coefficients.is_empty() {
            return Err("coefficients is empty; expected at least one number".into());
        }
        if let Some(i) = self.coefficients.iter().position(|c| !c.is_finite()) {
            return Err(format!("coefficients[{i}] = {} is not a finite number", self.coefficients[i]));
        }
        let [a, b] = self.x_range;
        if !(a.is_finite() && b.is_finite()) || a > b {
            return Err(format!(
                "x_range = [{a}, {b}] must be two finite numbers, the first not above the second"
            ));
        }
        if self.log10 && a <= 0.0 {
            return Err(format!("x_range = [{a}, {b}] must be positive for a log10 fit"));
        }
        Ok(())
    }

    /// Evaluates the fit at `x`, clamped to `x_range`.
    pub fn eval(&self, x: f64) -> f64 {
        // max/min rather than clamp: a map that skipped `check` still evaluates instead of panicking.
        let x = x.max(self.x_range[0]).min(self.x_range[1]);
        let u = if self.log10 { x.log10() } else { x };
        let y = self.coefficients.iter().rev().fold(0.0, |acc, c| acc * u + c);
        if self.log10 {
            10f64.powf(y)
        } else {
            y
        }
    }
}

/// A stick/bounce regime map reduced to its boundary.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RegimeMap {
    /// Always [`RegimeMap::SCHEMA`].
    pub schema: String,
    /// Free text: materials, contact model, scenario it came from.
    pub description: String,
    /// Critical normal impact speed \[m/s\] as a function of diameter \[m\]: stick when v_n < v_crit(d).
    pub v_crit_of_d: PolyFit,
    /// Critical diameter \[m\] as a function of normal impact speed \[m/s\] (the thesis's form).
    pub d_crit_of_vn: PolyFit,
    /// Interface points `[diameter_m, critical_normal_speed_m_s]` the fits were made from.
    pub interface: Vec<[f64; 2]>,
}

impl RegimeMap {
    pub const SCHEMA: &'static str = "spatter.regime_map.v1";

    /// Checks the schema tag and both fits (see [`PolyFit::check`]); the message names the key, e.g.
    /// `v_crit_of_d.x_range = [0.0001, 0.00001] must be …`. Call it on every map read from a file.
    pub fn check(&self) -> Result<(), String> {
        if self.schema != Self::SCHEMA {
            return Err(format!("schema = \"{}\" is not \"{}\"", self.schema, Self::SCHEMA));
        }
        self.v_crit_of_d.check().map_err(|e| format!("v_crit_of_d.{e}"))?;
        self.d_crit_of_vn.check().map_err(|e| format!("d_crit_of_vn.{e}"))
    }

    /// Critical normal speed \[m/s\] for diameter `d` \[m\].
    pub fn critical_speed(&self, d: f64) -> f64 {
        self.v_crit_of_d.eval(d)
    }

    /// Whether a particle of diameter `d` \[m\] arriving with normal speed `v_n` \[m/s\] sticks.
    pub fn sticks(&self, d: f64, v_n: f64) -> bool {
        v_n.abs() < self.critical_speed(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_log_fit_evaluates_a_power_law_and_clamps() {
        // v = 0.01 · d^(-0.5): log10 v = -2 - 0.5 log10 d.
        let f = PolyFit {
            x: "diameter_m".into(),
            y: "critical_normal_speed_m_s".into(),
            log10: true,
            coefficients: vec![-2.0, -0.5],
            x_range: [1e-5, 1e-4],
            rms_relative_error: 0.0,
        };
        assert!((f.eval(1e-4) - 1.0).abs() < 1e-12);
        assert_eq!(f.eval(1e-3), f.eval(1e-4), "clamped above the range");
        let map = RegimeMap {
            schema: RegimeMap::SCHEMA.into(),
            description: String::new(),
            v_crit_of_d: f.clone(),
            d_crit_of_vn: f,
            interface: vec![],
        };
        assert!(map.sticks(1e-4, 0.99) && !map.sticks(1e-4, 1.01));
        assert_eq!(map.check(), Ok(()));
    }

    #[test]
    fn broken_maps_are_refused_with_the_key() {
        let good = PolyFit {
            x: "d".into(),
            y: "v".into(),
            log10: true,
            coefficients: vec![-2.0, -0.5],
            x_range: [1e-5, 1e-4],
            rms_relative_error: 0.0,
        };
        let map = |v: PolyFit| RegimeMap {
            schema: RegimeMap::SCHEMA.into(),
            description: String::new(),
            v_crit_of_d: v,
            d_crit_of_vn: good.clone(),
            interface: vec![],
        };
        let e = map(PolyFit { x_range: [1e-4, 1e-5], ..good.clone() }).check().unwrap_err();
        assert!(e.starts_with("v_crit_of_d.x_range"), "{e}");
        let e = map(PolyFit { coefficients: vec![], ..good.clone() }).check().unwrap_err();
        assert!(e.contains("coefficients is empty"), "{e}");
        let e = map(PolyFit { coefficients: vec![f64::NAN], ..good.clone() }).check().unwrap_err();
        assert!(e.contains("coefficients[0]"), "{e}");
        let e = map(PolyFit { x_range: [0.0, 1e-4], ..good.clone() }).check().unwrap_err();
        assert!(e.contains("positive"), "{e}");
        let mut m = map(good.clone());
        m.schema = "other".into();
        assert!(m.check().unwrap_err().contains("schema"));
    }
}
