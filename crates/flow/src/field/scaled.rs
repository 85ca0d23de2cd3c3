//! Similarity scaling of a rotor flow from model scale to full scale.
//!
//! A rotor flow computed (or measured) on a model rotor is carried over to a full-size rotor at the same
//! thrust coefficient C_T and the same height z_d/R by scaling lengths with the rotor radius R and
//! velocities with the induced velocity v_ind = √(T/(2ρA)) (momentum theory); times then scale with
//! R/v_ind (Jasion 2013, §5.3 and Table 5.2, which scales its 0.5 m model rotor to the Bell 47 and the
//! AW101 this way). With C_T held constant the tip speed ΩR scales like v_ind (v_ind = ΩR √C_T / 2 in the
//! convention C_T = T/(½ρA(ΩR)²)), so the rotor's revolution period scales like R/v_ind too.
//!
//! A field sampled at full-scale position x and time t is the model field at x/L and t/T_s, with the
//! velocity multiplied by V, its gradient by V/L, its time derivative by V/T_s, k by V² and ε by V³/L
//! (L = R_full/R_model, V = v_full/v_model, T_s = L/V). The scaling is linear: the viscous near-wall
//! layer (Reynolds number) is not scaled, which the thesis notes under-estimates the wall shear and the
//! wall lift at full scale.

use super::{FlowField, Sample};
use spatter_core::{Aabb, Vec3};

/// Length and velocity factors from model scale to full scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RotorScaling {
    /// L = R_full / R_model \[-\].
    pub length: f64,
    /// V = v_full / v_model \[-\].
    pub velocity: f64,
}

impl RotorScaling {
    /// No scaling.
    pub const IDENTITY: RotorScaling = RotorScaling { length: 1.0, velocity: 1.0 };

    /// The factors from a model rotor (radius \[m\], induced velocity \[m/s\]) to a full-scale one.
    pub fn between(model: (f64, f64), full: (f64, f64)) -> Self {
        RotorScaling { length: full.0 / model.0, velocity: full.1 / model.1 }
    }

    /// Time factor T_s = L / V \[-\].
    pub fn time(&self) -> f64 {
        self.length / self.velocity
    }

    /// The scaling back from full scale to model scale.
    pub fn inverse(&self) -> Self {
        RotorScaling { length: 1.0 / self.length, velocity: 1.0 / self.velocity }
    }
}

/// A field carried to another scale by a [`RotorScaling`] (the model field is `inner`).
#[derive(Clone, Debug)]
pub struct ScaledField<F> {
    pub inner: F,
    pub scaling: RotorScaling,
}

impl<F: FlowField> FlowField for ScaledField<F> {
    #[inline]
    fn sample(&self, x: Vec3, t: f64, hint: &mut u32, want_grad: bool) -> Option<Sample> {
        let RotorScaling { length: l, velocity: v } = self.scaling;
        let ts = l / v;
        let s = self.inner.sample(x / l, t / ts, hint, want_grad)?;
        Some(Sample {
            u: s.u * v,
            grad: s.grad * (v / l),
            du_dt: s.du_dt * (v / ts),
            k: s.k * v * v,
            eps: s.eps * v * v * v / l,
        })
    }

    fn bounds(&self) -> Option<Aabb> {
        self.inner.bounds().map(|b| Aabb::new(b.min * self.scaling.length, b.max * self.scaling.length))
    }

    fn has_turbulence(&self) -> bool {
        self.inner.has_turbulence()
    }

    fn tet_hint_count(&self) -> usize {
        self.inner.tet_hint_count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::analytic::{AnalyticField, AnalyticSet};
    use crate::field::rotor::{induced_velocity, RotorDownwash};
    use crate::field::tetmesh::NONE;
    use std::f64::consts::PI;

    /// Downward volume flux through the disk z = z_d, r < `r_max` \[m³/s\], by the midpoint rule on `n`
    /// rings.
    fn downward_flux<F: FlowField>(f: &F, r_max: f64, z_d: f64, n: usize) -> f64 {
        let dr = r_max / n as f64;
        (0..n)
            .map(|i| {
                let r = (i as f64 + 0.5) * dr;
                let w =
                    f.sample(Vec3::new(r, 0.0, z_d), 0.0, &mut NONE.clone(), false).map_or(0.0, |s| -s.u.z);
                w * 2.0 * PI * r * dr
            })
            .sum()
    }

    /// Jasion (2013) Table 5.2: the 0.5 m model rotor (weight 0.6 g N) and the Bell 47 (R = 5.66 m,
    /// W = 8.8 kN, §6.1); air 1.19 kg/m³ (Table 6.1).
    fn model_and_bell47() -> (RotorDownwash, f64, f64) {
        let rho = 1.19;
        let (r_m, t_m) = (0.5, 0.6 * 9.81);
        let (r_f, t_f) = (5.66, 8800.0);
        let mut model = RotorDownwash::new(Vec3::new(0.0, 0.0, 0.68 * r_m), r_m, t_m, 47.1);
        model.air_density_kg_m3 = rho;
        let v_full = induced_velocity(t_f, rho, r_f);
        (model, r_f, v_full)
    }

    #[test]
    fn a_scaled_model_rotor_has_the_momentum_theory_downwash_of_the_full_rotor() {
        // Momentum theory (Jasion 2013 eq. 6.1–6.3): ṁ = ρ v_ind A with v_ind = √(T/(2ρA)), 6.06 m/s for
        // the Bell 47. The model rotor is the analytic downwash out of ground effect (hub at 3R), whose
        // volume flux through the disk plane is momentum theory's up to the smoothing of the slipstream
        // edge and the ground factor: the flux within 1.5 R over the disk area, within 1 %.
        let (mut model, r_f, v_full) = model_and_bell47();
        assert!((v_full - 6.06).abs() < 0.01, "{v_full}");
        let r_m = model.radius_m;
        model.hub_m.z = 3.0 * r_m;
        let v_model = model.induced_velocity();
        let field = AnalyticSet { parts: vec![AnalyticField::Rotor(model)], turbulence: None };
        let own = downward_flux(&field, 1.5 * r_m, 3.0 * r_m, 600) / (PI * r_m * r_m);
        assert!((own - v_model).abs() < 0.01 * v_model, "model: {own} m/s, momentum theory {v_model}");
        // Scaled by R and v_ind to the Bell 47, the flux through the full-size disk plane (hub at 3 R_full)
        // over the full-size disk area is the Bell 47's v_ind within the same 1 % (0.06 m/s) …
        let up = RotorScaling::between((r_m, v_model), (r_f, v_full));
        let scaled = ScaledField { inner: field, scaling: up };
        let full = downward_flux(&scaled, 1.5 * r_f, 3.0 * r_f, 600) / (PI * r_f * r_f);
        assert!((full - v_full).abs() < 0.01 * v_full, "scaled: {full} m/s, momentum theory {v_full}");
        // … and exactly (to rounding, 10⁻¹² relative) the model's ratio to momentum theory.
        assert!((full / v_full - own / v_model).abs() < 1e-12, "{} vs {}", full / v_full, own / v_model);
    }

    #[test]
    fn scaling_then_unscaling_is_the_identity() {
        let (model, r_f, v_full) = model_and_bell47();
        let v_model = model.induced_velocity();
        let r_m = model.radius_m;
        let up = RotorScaling::between((r_m, v_model), (r_f, v_full));
        assert!(
            (up.length - 11.32).abs() < 1e-12
                && (up.inverse().inverse().velocity - up.velocity).abs() < 1e-15
        );
        assert!((up.time() * up.inverse().time() - 1.0).abs() < 1e-15);
        let points = [
            (Vec3::new(0.3, 0.1, 0.2), 0.0),
            (Vec3::new(0.55, -0.2, 0.05), 0.037),
            (Vec3::new(1.1, 0.4, 0.12), 0.41),
        ];
        let rel = |p: Vec3, q: Vec3| (p - q).length() / q.length().max(1e-12);
        // A smooth closed-form unsteady field (a Lamb–Oseen vortex whose core grows with time in a
        // stagnation-point flow): velocity and gradient back to rounding (10⁻¹² and 10⁻⁹ relative).
        let smooth = AnalyticSet {
            parts: vec![
                AnalyticField::LambOseen {
                    circulation: 0.8,
                    core_radius: 0.05,
                    centre: Vec3::new(0.5, 0.0, 0.1),
                    axis: Vec3::Y,
                    nu: 1.5e-3,
                },
                AnalyticField::StagnationPoint {
                    strain_rate: 2.0,
                    centre: Vec3::ZERO,
                    normal: Vec3::Z,
                    axisymmetric: true,
                },
            ],
            turbulence: None,
        };
        let round =
            ScaledField { inner: ScaledField { inner: smooth.clone(), scaling: up }, scaling: up.inverse() };
        for (x, t) in points {
            let a = smooth.sample(x, t, &mut NONE.clone(), true).unwrap();
            let b = round.sample(x, t, &mut NONE.clone(), true).unwrap();
            assert!(rel(b.u, a.u) < 1e-12, "{x:?} {t}: {:?} vs {:?}", b.u, a.u);
            assert!(rel(b.du_dt, a.du_dt) < 1e-9, "{x:?} {t}: ∂u/∂t {:?} vs {:?}", b.du_dt, a.du_dt);
            for j in 0..3 {
                assert!(rel(b.grad.col(j), a.grad.col(j)) < 1e-9, "gradient column {j} at {x:?}");
            }
        }
        // The rotor downwash, whose velocity is a finite difference of its stream function: x·L/L and
        // t·T_s/T_s differ from x and t in the last bit, which the differencing (and, with tip vortices,
        // the table's interpolation) turns into relative differences of about 10⁻¹⁰ (measured);
        // tolerance 10⁻⁸ on the velocity.
        let field = AnalyticSet { parts: vec![AnalyticField::Rotor(model.clone())], turbulence: None };
        let round =
            ScaledField { inner: ScaledField { inner: field.clone(), scaling: up }, scaling: up.inverse() };
        for (x, t) in points {
            let a = field.sample(x, t, &mut NONE.clone(), false).unwrap().u;
            let b = round.sample(x, t, &mut NONE.clone(), false).unwrap().u;
            assert!(rel(b, a) < 1e-8, "{x:?} {t}: {b:?} vs {a:?}");
        }
        // The same with the tabulated tip vortices.
        let mut vortical = model;
        vortical.tip_vortices = true;
        let field = AnalyticSet { parts: vec![AnalyticField::Rotor(vortical)], turbulence: None };
        let round =
            ScaledField { inner: ScaledField { inner: field.clone(), scaling: up }, scaling: up.inverse() };
        for (x, t) in points {
            let a = field.sample(x, t, &mut NONE.clone(), false).unwrap().u;
            let b = round.sample(x, t, &mut NONE.clone(), false).unwrap().u;
            assert!(rel(b, a) < 1e-8, "{x:?} {t}: {b:?} vs {a:?}");
        }
    }
}
