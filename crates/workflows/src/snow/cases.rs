//! The impact model of a configuration and the configurations of its sensitivity cases: what the run,
//! the time-step guard, the benchmark and the validation cases share.

use super::config::{SensitivityCase, SnowConfig};
use super::model::ImpactModel;
use spatter_dem::restitution_models::RestitutionModel;

/// The impact model of `cfg` (baseline of the configuration).
pub fn model_of(cfg: &SnowConfig) -> ImpactModel {
    ImpactModel {
        particle: cfg.particle.clone(),
        wall: cfg.wall.clone(),
        target: cfg.target,
        partner_diameter: cfg.partner_diameter_m,
        contact: cfg.contact.clone(),
        integration: cfg.integration.clone(),
    }
}

/// The configuration of sensitivity case `case`: the baseline with its values replaced.
pub fn case_config(cfg: &SnowConfig, case: &SensitivityCase) -> SnowConfig {
    let mut c = cfg.clone();
    if let Some(e) = case.youngs_modulus_pa {
        c.particle.youngs_modulus = e;
    }
    if let Some(nu) = case.poisson_ratio {
        c.particle.poisson_ratio = nu;
    }
    if let Some(g) = case.work_of_adhesion_j_m2 {
        c.contact.work_of_adhesion_j_m2 = g;
    }
    if let Some(sy) = case.yield_stress_pa {
        c.contact.restitution = match c.contact.restitution {
            RestitutionModel::Thornton { form, yield_geometry, .. } => {
                RestitutionModel::Thornton { yield_stress_pa: sy, form, yield_geometry }
            }
            RestitutionModel::Constant { .. } => RestitutionModel::Thornton {
                yield_stress_pa: sy,
                form: Default::default(),
                yield_geometry: Default::default(),
            },
        };
    }
    c
}
