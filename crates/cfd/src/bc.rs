//! Boundary conditions on the six sides of the box: no-slip (possibly moving) and free-slip walls,
//! symmetry planes and the axis, velocity inlets with a time table, fixed-pressure outlets and
//! total-pressure sides.
//!
//! Pressures in this module are in pascals, as the user gives them; the solver divides them by the
//! density (it works in kinematic pressure p/ρ, m²/s²).

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};

/// Names of the sides in storage order.
pub const SIDES: [&str; 6] = ["x_min", "x_max", "y_min", "y_max", "z_min", "z_max"];

/// A time table of a scale factor: piecewise linear between the points, held constant outside them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeTable {
    /// Times \[s\], strictly increasing.
    pub t_s: Vec<f64>,
    /// Factor at each time \[-\].
    pub factor: Vec<f64>,
}

impl TimeTable {
    /// The factor at time `t` (1 for an empty table).
    pub fn at(&self, t: f64) -> f64 {
        let (ts, fs) = (&self.t_s, &self.factor);
        if ts.is_empty() {
            return 1.0;
        }
        if t <= ts[0] {
            return fs[0];
        }
        let n = ts.len();
        if t >= ts[n - 1] {
            return fs[n - 1];
        }
        let i = ts.partition_point(|&x| x <= t) - 1;
        let s = (t - ts[i]) / (ts[i + 1] - ts[i]);
        fs[i] + s * (fs[i + 1] - fs[i])
    }

    /// The linear ramp 0 → 1 over `t_ramp` seconds (the opening of a valve).
    pub fn ramp(t_ramp: f64) -> Self {
        TimeTable { t_s: vec![0.0, t_ramp], factor: vec![0.0, 1.0] }
    }
}

impl Validate for TimeTable {
    fn validate(&self, c: &mut Checker) {
        if self.t_s.len() != self.factor.len() {
            c.fail(
                "factor",
                format!(
                    "has {} values but t_s has {}; give one factor per time",
                    self.factor.len(),
                    self.t_s.len()
                ),
            );
        }
        for (i, w) in self.t_s.windows(2).enumerate() {
            if w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) {
                c.fail(
                    "t_s",
                    format!("times must increase strictly; t_s[{}] = {} follows {}", i + 1, w[1], w[0]),
                );
            }
        }
        for (i, &t) in self.t_s.iter().enumerate() {
            c.finite(&format!("t_s[{i}]"), t);
        }
        for (i, &f) in self.factor.iter().enumerate() {
            c.finite(&format!("factor[{i}]"), f);
        }
    }
}

/// What happens on one side of the box.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum Boundary {
    /// No-slip wall; `velocity_m_s` is its tangential velocity (a moving lid). The normal part is ignored.
    Wall {
        #[serde(default)]
        velocity_m_s: [f64; 3],
    },
    /// Free-slip wall, also a symmetry plane: zero normal velocity and zero shear.
    Slip,
    /// The axis r = 0 of an axisymmetric grid (behaves like a symmetry plane of zero area).
    Axis,
    /// Velocity inlet: `velocity_m_s` × `table(t)`.
    Inlet {
        velocity_m_s: [f64; 3],
        #[serde(default)]
        table: TimeTable,
    },
    /// Outlet at fixed static pressure `pressure_pa` \[Pa\]; zero normal gradient of the velocity.
    Outlet {
        #[serde(default)]
        pressure_pa: f64,
    },
    /// Total-pressure side (OpenFOAM's `totalPressure`): where the fluid enters, the static pressure on
    /// the face is p = p₀ − ½ρu_n² with p₀ = `total_pressure_pa` × `table(t)` \[Pa\] and u_n the face's
    /// normal velocity; where it leaves, p = p₀. The velocity has zero normal gradient both ways, as at
    /// an outlet (fluid enters in the direction it has next to the side).
    TotalPressure {
        total_pressure_pa: f64,
        #[serde(default)]
        table: TimeTable,
    },
}

impl Default for Boundary {
    fn default() -> Self {
        Boundary::Wall { velocity_m_s: [0.0; 3] }
    }
}

impl Boundary {
    /// Prescribed velocity of the side at time t (walls and inlets), `None` otherwise.
    pub fn velocity(&self, t: f64) -> Option<[f64; 3]> {
        match self {
            Boundary::Wall { velocity_m_s } => Some(*velocity_m_s),
            Boundary::Inlet { velocity_m_s, table } => {
                let f = table.at(t);
                Some(velocity_m_s.map(|v| v * f))
            }
            _ => None,
        }
    }

    /// Whether the side holds the pressure (an outlet or a total-pressure side): its normal velocity is
    /// found by the pressure correction, and it fixes the pressure level of the fluid it touches.
    pub fn holds_pressure(&self) -> bool {
        matches!(self, Boundary::Outlet { .. } | Boundary::TotalPressure { .. })
    }

    /// Static pressure the side holds at time `t` \[Pa\] on a face whose inward normal velocity is
    /// `u_in` \[m/s\] (positive into the domain), for fluid of density `rho` \[kg/m³\]; `None` for sides
    /// that do not hold the pressure.
    pub fn static_pressure(&self, t: f64, u_in: f64, rho: f64) -> Option<f64> {
        match self {
            Boundary::Outlet { pressure_pa } => Some(*pressure_pa),
            Boundary::TotalPressure { total_pressure_pa, table } => {
                let p0 = total_pressure_pa * table.at(t);
                Some(if u_in > 0.0 { p0 - 0.5 * rho * u_in * u_in } else { p0 })
            }
            _ => None,
        }
    }
}

impl Validate for Boundary {
    fn validate(&self, c: &mut Checker) {
        match self {
            Boundary::Wall { velocity_m_s } => c.finite_vec("velocity_m_s", (*velocity_m_s).into()),
            Boundary::Inlet { velocity_m_s, table } => {
                c.finite_vec("velocity_m_s", (*velocity_m_s).into());
                c.item("table", table);
            }
            Boundary::Outlet { pressure_pa } => c.finite("pressure_pa", *pressure_pa),
            Boundary::TotalPressure { total_pressure_pa, table } => {
                c.finite("total_pressure_pa", *total_pressure_pa);
                c.item("table", table);
            }
            Boundary::Slip | Boundary::Axis => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_table_interpolates_and_holds_its_ends() {
        let t = TimeTable { t_s: vec![0.0, 1.0, 3.0], factor: vec![0.0, 1.0, 0.5] };
        assert_eq!(t.at(-1.0), 0.0);
        assert_eq!(t.at(0.5), 0.5);
        assert_eq!(t.at(2.0), 0.75);
        assert_eq!(t.at(9.0), 0.5);
        assert_eq!(TimeTable::default().at(4.0), 1.0);
        let bad = TimeTable { t_s: vec![0.0, 2.0, 1.0], factor: vec![0.0, 1.0] };
        let errs = Checker::run(&bad, None).unwrap_err();
        assert_eq!(errs.len(), 2, "{errs:?}");
        assert!(errs.iter().any(|e| e.message.contains("increase strictly")));
    }

    #[test]
    fn total_pressure_holds_p0_minus_the_dynamic_pressure_of_inflow_and_p0_on_outflow() {
        let table = TimeTable { t_s: vec![0.0, 2.0], factor: vec![0.0, 1.0] };
        let b = Boundary::TotalPressure { total_pressure_pa: 100.0, table };
        // Inflow at 2 m/s into air of 1.2 kg/m³ at t = 1 s: p₀ = 50 Pa, ½ρu² = 2.4 Pa.
        assert_eq!(b.static_pressure(1.0, 2.0, 1.2), Some(50.0 - 2.4));
        // Outflow: the static pressure is p₀.
        assert_eq!(b.static_pressure(1.0, -2.0, 1.2), Some(50.0));
        assert_eq!(b.static_pressure(5.0, 0.0, 1.2), Some(100.0));
        assert!(b.holds_pressure() && !Boundary::Slip.holds_pressure());
        assert_eq!(Boundary::Outlet { pressure_pa: 7.0 }.static_pressure(3.0, 1.0, 1.2), Some(7.0));
        assert_eq!(Boundary::Slip.static_pressure(0.0, 0.0, 1.0), None);
        // A non-finite total pressure or a bad table is refused with the key named.
        let bad = Boundary::TotalPressure {
            total_pressure_pa: f64::NAN,
            table: TimeTable { t_s: vec![1.0, 0.0], factor: vec![1.0, 1.0] },
        };
        let errs = Checker::run(&bad, None).unwrap_err();
        assert_eq!(errs.len(), 2, "{errs:?}");
        assert!(errs.iter().any(|e| e.key.contains("total_pressure_pa")), "{errs:?}");
        assert!(
            errs.iter().any(|e| e.key.contains("t_s") && e.message.contains("increase strictly")),
            "{errs:?}"
        );
    }
}
