//! Per-triangle deposition and impact statistics of one body.
//!
//! Impact means are weighted by the number of real particles a parcel stands for. The impact angle is
//! measured from the wall plane (90° = normal impact), θ = atan(v_n / v_t).

use serde::{Deserialize, Serialize};

/// Accumulators, one entry per triangle.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Deposit {
    /// Deposited mass \[kg\].
    pub mass: Vec<f64>,
    /// Deposited particles (sum of parcel counts).
    pub particles: Vec<f64>,
    /// Parcel impacts (stick, bounce or escape).
    pub impacts: Vec<u64>,
    /// Particles that hit (sum of parcel counts over impacts).
    pub impact_particles: Vec<f64>,
    /// Σ count·v_n \[m/s\].
    pub sum_vn: Vec<f64>,
    /// Σ count·v_t \[m/s\].
    pub sum_vt: Vec<f64>,
    /// Σ count·θ \[deg\].
    pub sum_angle: Vec<f64>,
}

/// One impact reported by the tracker.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Impact {
    pub body: u16,
    pub triangle: u32,
    /// Normal impact speed ≥ 0 \[m/s\].
    pub v_n: f64,
    /// Tangential impact speed \[m/s\].
    pub v_t: f64,
    /// Particles in the parcel.
    pub count: f64,
    /// Parcel mass \[kg\].
    pub mass: f64,
    /// What the wall did with the parcel.
    pub outcome: ImpactOutcome,
}

/// Result of an impact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ImpactOutcome {
    Stuck,
    Bounced,
    Escaped,
}

impl Deposit {
    pub fn new(n_triangles: usize) -> Self {
        Deposit {
            mass: vec![0.0; n_triangles],
            particles: vec![0.0; n_triangles],
            impacts: vec![0; n_triangles],
            impact_particles: vec![0.0; n_triangles],
            sum_vn: vec![0.0; n_triangles],
            sum_vt: vec![0.0; n_triangles],
            sum_angle: vec![0.0; n_triangles],
        }
    }

    /// Adds one impact.
    pub fn record(&mut self, i: &Impact) {
        let t = i.triangle as usize;
        self.impacts[t] += 1;
        self.impact_particles[t] += i.count;
        self.sum_vn[t] += i.count * i.v_n;
        self.sum_vt[t] += i.count * i.v_t;
        self.sum_angle[t] += i.count * i.v_n.atan2(i.v_t).to_degrees();
        if i.outcome == ImpactOutcome::Stuck {
            self.mass[t] += i.mass;
            self.particles[t] += i.count;
        }
    }

    fn mean(sum: &[f64], w: &[f64]) -> Vec<f64> {
        sum.iter().zip(w).map(|(s, w)| if *w > 0.0 { s / w } else { 0.0 }).collect()
    }

    /// Mean normal impact speed per triangle \[m/s\] (0 where nothing hit).
    pub fn mean_vn(&self) -> Vec<f64> {
        Self::mean(&self.sum_vn, &self.impact_particles)
    }

    pub fn mean_vt(&self) -> Vec<f64> {
        Self::mean(&self.sum_vt, &self.impact_particles)
    }

    pub fn mean_angle_deg(&self) -> Vec<f64> {
        Self::mean(&self.sum_angle, &self.impact_particles)
    }

    /// Deposited mass per area \[kg/m²\] given the triangle areas.
    pub fn mass_per_area(&self, areas: &[f64]) -> Vec<f64> {
        self.mass.iter().zip(areas).map(|(m, a)| if *a > 0.0 { m / a } else { 0.0 }).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weighted_means_and_mass() {
        let mut d = Deposit::new(2);
        d.record(&Impact {
            body: 0,
            triangle: 1,
            v_n: 1.0,
            v_t: 0.0,
            count: 3.0,
            mass: 3e-9,
            outcome: ImpactOutcome::Stuck,
        });
        d.record(&Impact {
            body: 0,
            triangle: 1,
            v_n: 1.0,
            v_t: 1.0,
            count: 1.0,
            mass: 1e-9,
            outcome: ImpactOutcome::Bounced,
        });
        assert_eq!(d.impacts, vec![0, 2]);
        assert_eq!(d.mass, vec![0.0, 3e-9]);
        assert!((d.mean_vn()[1] - 1.0).abs() < 1e-15);
        assert!((d.mean_vt()[1] - 0.25).abs() < 1e-15);
        assert!((d.mean_angle_deg()[1] - (3.0 * 90.0 + 45.0) / 4.0).abs() < 1e-12);
        assert_eq!(d.mass_per_area(&[1.0, 0.5])[1], 6e-9);
    }
}
