//! Time-step guard: the time step of a run against the shortest Hertz contact time among its impacts.
//!
//! The driver integrates explicitly (velocity Verlet), so a time step that is a large part of the contact
//! time gives wrong restitution and critical speeds and, beyond a limit, creates energy. The fractions
//! below were measured with the driver (docs/snow.md §3, "Time-step guard"):
//!
//! * at t_H/20 the realised restitution of a Hertz impact is off its input by 1.5 % (e = 0.5) and 3.2 %
//!   (e = 0.2), v_crit(10 µm) by −3.8 % (7.89 against the converged 8.20 m/s) and an elastic impact
//!   gains 1.5e-4 of its energy; at t_H/10 these are 2.4 %, 2.5 % and 1.8e-3, and the errors keep
//!   growing. A run with a fixed `dt_s` above [`DT_WARN_FRACTION`] × t_H,min (or with
//!   `steps_per_contact` below 20) is warned about;
//! * the heaviest damping (e → 0, β → −1) turns unstable from about 0.16 t_H on (the realised restitution
//!   of an e = 0.001 impact is 0.0015 at 0.125 t_H, 0.004 at 0.16 t_H and 0.03 at 0.17 t_H; at 0.25 t_H an
//!   impact of the thesis baseline leaves faster than it came), whatever the diameter or speed (the Hertz
//!   part is scale free); a `dt_s` above [`DT_LIMIT_FRACTION`] × t_H,min = t_H,min/8 is refused.
//!
//! The Hertz time t_H = 2.868(m*²/(R*E*²v))^{1/5} is the contact duration, the time scale an impact must
//! resolve. The Rayleigh time (a surface wave crossing the particle) bounds the step of dense packings
//! where forces travel through many contacts; for one particle hitting a wall or a sphere it is not what
//! limits the step. It does not depend on the impact speed (8.4 ns at d = 10 µm for ice, t_H/5 at 16 m/s
//! and t_H/11 at 0.34 m/s), so a Rayleigh fraction would be too strict for slow runs and too loose for fast
//! ones; the guard uses t_H.

use super::bed_index::BedIndex;
use super::cases::{case_config, model_of};
use super::config::{Mode, SnowConfig};
use super::model::Surface;

/// Fraction of the shortest Hertz time above which a run is warned about (1/20).
pub const DT_WARN_FRACTION: f64 = 0.05;

/// Fraction of the shortest Hertz time above which a fixed `dt_s` is refused (1/8).
pub const DT_LIMIT_FRACTION: f64 = 0.125;

/// The shortest Hertz contact time among the impacts of a run and where it occurs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShortestContact {
    /// Hertz time t_H at the reference speed max(v_n, V_s) \[s\].
    pub hertz_time: f64,
    /// Particle diameter \[m\].
    pub diameter: f64,
    /// Normal impact speed \[m/s\] (the top of the run's speed range).
    pub speed: f64,
}

/// The shortest Hertz time of the impacts `cfg` asks for: every diameter of the run at the top of its
/// speed range (t_H falls with the speed), for every sensitivity case, on the target the impacts hit
/// (in rough-wall mode the bed spheres and the flat wall of the reference v_crit). Bisection brackets
/// that widen beyond the configured range are not included (their impacts are still checked for
/// energy gain). `None` when the run has no impact with a finite, positive Hertz time.
pub fn shortest_contact(cfg: &SnowConfig) -> Option<ShortestContact> {
    let configs: Vec<SnowConfig> = match cfg.mode {
        Mode::Sensitivity => cfg.sensitivity.cases.iter().map(|k| case_config(cfg, k)).collect(),
        _ => vec![cfg.clone()],
    };
    let (grid_lo, grid_hi) = cfg.grid.speed_range();
    let (diameters, speed) = match cfg.mode {
        Mode::Grid | Mode::Sensitivity => (cfg.grid.diameter_axis(), grid_hi),
        Mode::Bisection => {
            let lo = cfg.bisection.speed_low_m_s.unwrap_or(grid_lo);
            let hi = cfg.bisection.speed_high_m_s.unwrap_or(grid_hi);
            (cfg.grid.diameter_axis(), lo.max(hi))
        }
        Mode::RoughWall => (
            vec![cfg.rough_wall.particle_diameter_m],
            cfg.rough_wall.speed_range(cfg.grid.velocity_scale_m_s).1,
        ),
        Mode::Single => (vec![cfg.single.diameter_m], cfg.single.normal_speed_m_s),
    };
    let empty = BedIndex::default();
    let mut best: Option<ShortestContact> = None;
    for c in &configs {
        let mut models = vec![(model_of(c), false)];
        if cfg.mode == Mode::RoughWall {
            let mut flat = model_of(c);
            flat.target = super::config::TargetKind::Wall;
            models = vec![(model_of(c), true), (flat, false)];
        }
        for (model, bed) in &models {
            let surface = if *bed {
                Surface::Bed {
                    spheres: &[],
                    top: 0.0,
                    sphere_radius: 0.5 * c.rough_wall.bed_sphere_diameter_m,
                    index: &empty,
                }
            } else {
                Surface::Configured
            };
            for &d in &diameters {
                let t = model.setup(d, speed, surface).1.hertz_time;
                if t.is_finite() && t > 0.0 && best.is_none_or(|b| t < b.hertz_time) {
                    best = Some(ShortestContact { hertz_time: t, diameter: d, speed });
                }
            }
        }
    }
    best
}

/// The largest time step of the run as a fraction of the Hertz time it must resolve: `dt_s` over the
/// shortest Hertz time when `dt_s` is given, else 1/`steps_per_contact` (each impact's step is its own
/// t_H over that number).
pub fn step_fraction(cfg: &SnowConfig) -> Option<(f64, ShortestContact)> {
    let shortest = shortest_contact(cfg)?;
    let fraction = match cfg.integration.dt_s {
        Some(dt) => dt / shortest.hertz_time,
        None => 1.0 / cfg.integration.steps_per_contact,
    };
    Some((fraction, shortest))
}

fn where_(s: &ShortestContact) -> String {
    format!("t_H = {:.4e} s at d = {:.3e} m, v_n = {} m/s", s.hertz_time, s.diameter, s.speed)
}

/// The refusal of a fixed `dt_s` above [`DT_LIMIT_FRACTION`] of the shortest Hertz time, as the message
/// of a validation error of `integration.dt_s`; `None` when the step is acceptable.
pub fn refusal(cfg: &SnowConfig) -> Option<String> {
    let dt = cfg.integration.dt_s?;
    let (fraction, s) = step_fraction(cfg)?;
    (fraction > DT_LIMIT_FRACTION).then(|| {
        format!(
            "dt_s = {dt:e} s is {fraction:.3} of the shortest Hertz contact time of the run ({}); the limit is \
             t_H/8 = {:.4e} s, above which the explicit integration of a damped contact creates energy and the \
             results mean nothing. Use dt_s ≤ {:.4e} s (≤ {:.4e} s avoids the time-step warning) or leave \
             dt_s unset (Δt = t_H/steps_per_contact per impact)",
            where_(&s),
            DT_LIMIT_FRACTION * s.hertz_time,
            DT_LIMIT_FRACTION * s.hertz_time,
            DT_WARN_FRACTION * s.hertz_time,
        )
    })
}

/// The warning for a time step above [`DT_WARN_FRACTION`] of the Hertz time (fixed `dt_s`, or
/// `steps_per_contact` below 20); `None` otherwise.
pub fn warning(cfg: &SnowConfig) -> Option<String> {
    let (fraction, s) = step_fraction(cfg)?;
    if fraction <= DT_WARN_FRACTION {
        return None;
    }
    Some(match cfg.integration.dt_s {
        Some(dt) => format!(
            "time step: integration.dt_s = {dt:e} s is {fraction:.3} of the shortest Hertz contact time of the run \
             ({}), above 1/20: realised restitution and critical speeds carry time-step errors of several per \
             cent (docs/snow.md §3). dt_s ≤ {:.4e} s avoids this warning",
            where_(&s),
            DT_WARN_FRACTION * s.hertz_time
        ),
        None => format!(
            "time step: integration.steps_per_contact = {} resolves each contact with fewer than 20 steps: \
             realised restitution and critical speeds carry time-step errors of several per cent \
             (docs/snow.md §3). Use at least 20 (default 200)",
            cfg.integration.steps_per_contact
        ),
    })
}
