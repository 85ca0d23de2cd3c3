//! Validation of a whole snow configuration. It lives apart from the configuration types because the
//! fixed-time-step refusal needs the impact model ([`super::dt_guard`]), which is built from them.

use super::config::*;
use spatter_core::check::{Checker, Validate};

impl Validate for SnowConfig {
    fn validate(&self, c: &mut Checker) {
        c.item("particle", &self.particle);
        if self.particle.youngs_modulus.is_infinite() {
            c.fail("particle.youngs_modulus_pa", "the particle must have a finite Young's modulus");
        }
        if let Some(t) = self.ice_temperature_c {
            c.in_range(
                "ice_temperature_c",
                t,
                ICE_TEMPERATURE_RANGE_C.0,
                true,
                ICE_TEMPERATURE_RANGE_C.1,
                true,
            );
        }
        c.item("wall", &self.wall);
        if let Some(d) = self.partner_diameter_m {
            c.positive("partner_diameter_m", d);
        }
        c.item("contact", &self.contact);
        c.item("integration", &self.integration);
        c.item("grid", &self.grid);
        c.item("bisection", &self.bisection);
        c.item("fit", &self.fit);
        c.item("sensitivity", &self.sensitivity);
        c.item("rough_wall", &self.rough_wall);
        // The rough-wall speed defaults follow the grid's velocity scale, so the order is checked here.
        let (lo, hi) = self.rough_wall.speed_range(self.grid.velocity_scale_m_s);
        if lo > hi {
            let key = if self.rough_wall.normal_speed_min_m_s.is_some() {
                "rough_wall.normal_speed_min_m_s"
            } else {
                "rough_wall.normal_speed_max_m_s"
            };
            c.fail(key, format!("rough-wall speed range is inverted: normal_speed_min_m_s = {lo} is above normal_speed_max_m_s = {hi}"));
        }
        if self.mode == Mode::Sensitivity {
            let jobs = self.grid.jobs().saturating_mul(self.sensitivity.cases.len() as u64);
            if jobs > MAX_IMPACTS {
                c.fail(
                    "sensitivity.cases",
                    format!(
                        "{} cases × {} grid impacts = {jobs} impacts is above the cap of {MAX_IMPACTS} impacts per run",
                        self.sensitivity.cases.len(),
                        self.grid.jobs()
                    ),
                );
            }
        }
        c.item("single", &self.single);
        // A fixed time step above 1/8 of the shortest Hertz time of the run is refused (snow::dt_guard);
        // checked only when everything else is valid, since the Hertz times need valid values.
        if let Some(dt) = self.integration.dt_s {
            if dt.is_finite() && dt > 0.0 {
                let mut rest = self.clone();
                rest.integration.dt_s = None;
                if Checker::run(&rest, None).is_ok() {
                    if let Some(msg) = super::dt_guard::refusal(self) {
                        c.nested("integration", |c| c.fail("dt_s", msg));
                    }
                }
            }
        }
    }
}
