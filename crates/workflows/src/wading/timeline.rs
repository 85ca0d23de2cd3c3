//! The vehicle's progress over time: a constant speed or a speed table along the channel, or a free path.

use super::bisect::bisect;
use super::path::VehiclePath;
use std::path::Path;

/// Where the front axle's centre-line point is over time \[m, s\], its heading and its speed.
#[derive(Clone, Debug, PartialEq)]
pub enum Travel {
    /// Along +x from `x0` on the channel's centre line `y0` (heading 0) at a speed over time.
    Along { x0: f64, y0: f64, speed: SpeedProfile },
    /// A free path `t x y [z]` of the front axle; the rear axle, `wheelbase` \[m\] behind, trails it on
    /// the path ([`VehiclePath::trailing_heading`]).
    Path { path: VehiclePath, wheelbase: f64 },
}

impl Travel {
    /// Front axle's centre-line point `(x, y)` at `t` \[m\].
    pub fn front(&self, t: f64) -> (f64, f64) {
        match self {
            Travel::Along { x0, y0, speed } => (x0 + speed.distance(t), *y0),
            Travel::Path { path, .. } => path.point(t),
        }
    }

    /// The body's heading at `t` \[rad from +x towards +y\] with the rear axle `behind` \[m\] (horizontal)
    /// behind the front one: along +x, or on a path the direction from the rear axle, trailing on the path
    /// ([`VehiclePath::trailing_heading`]), to the front axle.
    pub fn heading_with(&self, t: f64, behind: f64) -> f64 {
        match self {
            Travel::Along { .. } => 0.0,
            Travel::Path { path, .. } => path.trailing_heading(t, behind),
        }
    }

    /// [`Self::heading_with`] the whole wheelbase behind (the heading on level road; on a slope the
    /// placement shortens the horizontal distance, see [`super::vehicle::place_along`]).
    pub fn heading(&self, t: f64) -> f64 {
        match self {
            Travel::Along { .. } => 0.0,
            Travel::Path { wheelbase, .. } => self.heading_with(t, *wheelbase),
        }
    }

    /// Speed over the ground at `t` \[m/s\] (horizontal), which turns the wheels at ω = v/R.
    pub fn speed(&self, t: f64) -> f64 {
        match self {
            Travel::Along { speed, .. } => speed.speed(t),
            Travel::Path { path, .. } => path.speed(t),
        }
    }

    /// Largest speed \[m/s\].
    pub fn max_speed(&self) -> f64 {
        match self {
            Travel::Along { speed, .. } => speed.max_speed(),
            Travel::Path { path, .. } => path.max_speed(),
        }
    }

    /// First time the front axle reaches `x` \[m\] or beyond, `None` if never.
    pub fn time_to_x(&self, x: f64) -> Option<f64> {
        match self {
            Travel::Along { x0, speed, .. } => speed.time_to(x - x0),
            Travel::Path { path, .. } => path.time_to_x(x),
        }
    }
}

/// Vehicle speed over time \[m/s\]: rows `(t, v)` linearly interpolated and held beyond the ends; the
/// distance travelled is the exact integral of that piecewise linear speed.
#[derive(Clone, Debug, PartialEq)]
pub struct SpeedProfile {
    times: Vec<f64>,
    speeds: Vec<f64>,
}

impl SpeedProfile {
    /// A constant speed.
    pub fn constant(v: f64) -> Self {
        SpeedProfile { times: vec![0.0], speeds: vec![v] }
    }

    /// Parses rows `t_s speed_m_s` (whitespace or commas; `#` starts a comment): times strictly
    /// increasing from t ≥ 0, speeds ≥ 0 and not all zero. Errors name the file and the line.
    pub fn parse(text: &str, path: &Path) -> Result<Self, String> {
        let mut times = Vec::new();
        let mut speeds = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let at = || format!("{} line {}", path.display(), i + 1);
            let vals: Result<Vec<f64>, _> = line
                .split(|c: char| c == ',' || c.is_whitespace())
                .filter(|s| !s.is_empty())
                .map(str::parse)
                .collect();
            let vals = vals.map_err(|_| format!("{}: `{line}` is not two numbers `t_s speed_m_s`", at()))?;
            let [t, v] = vals[..] else {
                return Err(format!(
                    "{}: `{line}` has {} values, expected two: `t_s speed_m_s`",
                    at(),
                    vals.len()
                ));
            };
            if !(t.is_finite() && t >= 0.0) || times.last().is_some_and(|&p| t <= p) {
                return Err(format!("{}: time {t} s must be ≥ 0 and above the previous row's", at()));
            }
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{}: speed {v} m/s must be ≥ 0 (the vehicle drives along +x)", at()));
            }
            times.push(t);
            speeds.push(v);
        }
        if times.is_empty() {
            return Err(format!("{}: no rows (expected `t_s speed_m_s` per line)", path.display()));
        }
        if speeds.iter().all(|&v| v == 0.0) {
            return Err(format!("{}: every speed is 0; the vehicle would never move", path.display()));
        }
        Ok(SpeedProfile { times, speeds })
    }

    /// Speed at `t` \[m/s\].
    pub fn speed(&self, t: f64) -> f64 {
        let (ts, vs) = (&self.times, &self.speeds);
        if t <= ts[0] {
            return vs[0];
        }
        for k in 1..ts.len() {
            if t <= ts[k] {
                let f = (t - ts[k - 1]) / (ts[k] - ts[k - 1]);
                return vs[k - 1] + f * (vs[k] - vs[k - 1]);
            }
        }
        vs[vs.len() - 1]
    }

    /// Distance travelled from 0 to `t` \[m\].
    pub fn distance(&self, t: f64) -> f64 {
        let (ts, vs) = (&self.times, &self.speeds);
        let mut d = vs[0] * t.min(ts[0]);
        for k in 1..ts.len() {
            if t <= ts[k - 1] {
                return d;
            }
            let hi = t.min(ts[k]);
            d += 0.5 * (vs[k - 1] + self.speed(hi)) * (hi - ts[k - 1]);
        }
        let last = ts[ts.len() - 1];
        d + vs[vs.len() - 1] * (t - last).max(0.0)
    }

    /// Time at which the distance `s` has been travelled \[s\], `None` if never (the table ends at rest
    /// before it). Bisection on the non-decreasing distance.
    pub fn time_to(&self, s: f64) -> Option<f64> {
        if s <= 0.0 {
            return Some(0.0);
        }
        let last = self.times[self.times.len() - 1];
        let v_end = self.speeds[self.speeds.len() - 1];
        if self.distance(last) < s && v_end <= 0.0 {
            return None;
        }
        let mut hi = last.max(1e-3);
        while self.distance(hi) < s {
            hi *= 2.0;
        }
        Some(bisect(0.0, hi, |t| self.distance(t) < s).1)
    }

    /// Largest speed of the table \[m/s\].
    pub fn max_speed(&self) -> f64 {
        self.speeds.iter().copied().fold(0.0, f64::max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_speed_covers_v_t() {
        let p = SpeedProfile::constant(2.5);
        assert_eq!(p.distance(4.0), 10.0);
        assert!((p.time_to(10.0).unwrap() - 4.0).abs() < 1e-12);
        assert_eq!(p.speed(7.0), 2.5);
    }

    /// Accelerating from 0 to 2 m/s over 2 s then holding: 2 m in the ramp (½ a t²), then 2 m/s.
    #[test]
    fn a_speed_table_integrates_exactly() {
        let p = SpeedProfile::parse("# t v\n0 0\n2, 2\n", Path::new("v.txt")).unwrap();
        assert!((p.distance(1.0) - 0.5).abs() < 1e-12);
        assert!((p.distance(2.0) - 2.0).abs() < 1e-12);
        assert!((p.distance(5.0) - 8.0).abs() < 1e-12);
        assert!((p.time_to(8.0).unwrap() - 5.0).abs() < 1e-9);
        assert!((p.speed(1.0) - 1.0).abs() < 1e-15);
        let stops = SpeedProfile::parse("0 1\n1 0\n", Path::new("v.txt")).unwrap();
        assert!(stops.time_to(0.4).is_some() && stops.time_to(0.6).is_none());
    }

    #[test]
    fn bad_tables_are_named_by_line() {
        let e = SpeedProfile::parse("0 1\n0 2\n", Path::new("v.txt")).unwrap_err();
        assert!(e.contains("v.txt line 2") && e.contains("above the previous"), "{e}");
        let e = SpeedProfile::parse("0 1 2\n", Path::new("v.txt")).unwrap_err();
        assert!(e.contains("line 1") && e.contains("3 values"), "{e}");
        let e = SpeedProfile::parse("0 x\n", Path::new("v.txt")).unwrap_err();
        assert!(e.contains("not two numbers"), "{e}");
        let e = SpeedProfile::parse("0 0\n", Path::new("v.txt")).unwrap_err();
        assert!(e.contains("every speed is 0"), "{e}");
        assert!(SpeedProfile::parse("", Path::new("v.txt")).unwrap_err().contains("no rows"));
    }
}
