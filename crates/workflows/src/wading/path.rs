//! A free vehicle path: rows `t x y [z]` of the front axle's centre-line point, inline or from a file.
//!
//! Between rows x(t) and y(t) are each a monotone cubic Hermite curve (Fritsch & Carlson, "Monotone
//! piecewise cubic interpolation", SIAM J. Numer. Anal. 17, 1980): continuous in position and velocity, so
//! the heading (the direction of the horizontal velocity, the path's tangent) turns smoothly, and never
//! overshooting the rows, so a vehicle that waits (two rows at one place) stands still instead of rolling
//! back and forth. Rows on a straight line at constant speed give that line exactly (up to round-off).
//! Before the first row (t = 0) nothing happens; after the last the vehicle stands at the last point with
//! its last heading.

use super::bisect::bisect;
use std::path::Path;

/// One row's optional height: the front axle's height the row demands \[m\], and where the row came
/// from (for messages).
#[derive(Clone, Debug, PartialEq)]
pub struct RowHeight {
    pub t: f64,
    pub z: f64,
    /// `"path.csv line 4"` or `"motion.path.rows[3]"`.
    pub origin: String,
}

/// The path of the front axle's centre-line point over time (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct VehiclePath {
    times: Vec<f64>,
    xy: Vec<[f64; 2]>,
    /// Tangents dx/dt, dy/dt at every row (Fritsch–Carlson).
    slopes: Vec<[f64; 2]>,
    /// Rows that gave a height (checked against the road by the caller).
    pub heights: Vec<RowHeight>,
    /// Where each row came from, for messages.
    origins: Vec<String>,
}

impl VehiclePath {
    /// Parses a file of rows `t_s x_m y_m [z_m]` (whitespace or commas; `#` starts a comment; a first line
    /// of column names is skipped). Errors name the file, the line, the value and the expected form.
    pub fn parse(text: &str, path: &Path) -> Result<Self, String> {
        let mut rows = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let at = format!("{} line {}", path.display(), i + 1);
            let fields: Vec<&str> =
                line.split(|c: char| c == ',' || c.is_whitespace()).filter(|s| !s.is_empty()).collect();
            let vals: Vec<Option<f64>> = fields.iter().map(|s| s.parse::<f64>().ok()).collect();
            if rows.is_empty() && vals.iter().all(Option::is_none) {
                // A header of column names.
                continue;
            }
            if let Some(k) = vals.iter().position(Option::is_none) {
                return Err(format!(
                    "{at}: `{}` is not a number; expected rows `t_s x_m y_m` or `t_s x_m y_m z_m`",
                    fields[k]
                ));
            }
            rows.push((at, vals.into_iter().flatten().collect::<Vec<f64>>()));
        }
        Self::from_located(rows, &path.display().to_string())
    }

    /// Rows given inline (`motion.path.rows`), each `[t, x, y]` or `[t, x, y, z]`.
    pub fn from_rows(rows: &[Vec<f64>]) -> Result<Self, String> {
        let located = rows.iter().enumerate().map(|(k, r)| (format!("rows[{k}]"), r.clone())).collect();
        Self::from_located(located, "rows")
    }

    fn from_located(rows: Vec<(String, Vec<f64>)>, what: &str) -> Result<Self, String> {
        let mut times = Vec::new();
        let mut xy = Vec::new();
        let mut heights = Vec::new();
        let mut origins = Vec::new();
        for (at, v) in rows {
            if !(v.len() == 3 || v.len() == 4) {
                return Err(format!(
                    "{at}: {} values, expected three `t_s x_m y_m` or four `t_s x_m y_m z_m`",
                    v.len()
                ));
            }
            if let Some(x) = v.iter().find(|x| !x.is_finite()) {
                return Err(format!("{at}: {x} is not a finite number"));
            }
            let t = v[0];
            match times.last() {
                None if t != 0.0 => {
                    return Err(format!("{at}: the first row's time is {t} s; the path starts at t = 0"))
                }
                Some(&p) if t <= p => {
                    return Err(format!(
                        "{at}: time {t} s does not increase (the row before is at {p} s); times must increase"
                    ))
                }
                _ => {}
            }
            times.push(t);
            xy.push([v[1], v[2]]);
            if let Some(&z) = v.get(3) {
                heights.push(RowHeight { t, z, origin: at.clone() });
            }
            origins.push(at);
        }
        if times.len() < 2 {
            return Err(format!(
                "{what}: {} row(s); a path needs at least two rows `t_s x_m y_m [z_m]` (the start at t = 0 \
                 and a later one)",
                times.len()
            ));
        }
        if xy.windows(2).all(|w| w[0] == w[1]) {
            return Err(format!("{what}: every row is at the same place; the vehicle would never move"));
        }
        let slopes = fritsch_carlson(&times, &xy);
        Ok(VehiclePath { times, xy, slopes, heights, origins })
    }

    /// Time of the last row \[s\].
    pub fn last_time(&self) -> f64 {
        self.times[self.times.len() - 1]
    }

    /// Segment index and local parameter at `t` clamped to the rows' span.
    fn segment(&self, t: f64) -> (usize, f64, f64) {
        let n = self.times.len();
        let t = t.clamp(self.times[0], self.times[n - 1]);
        let k = (self.times.partition_point(|&tk| tk <= t).max(1) - 1).min(n - 2);
        let h = self.times[k + 1] - self.times[k];
        (k, (t - self.times[k]) / h, h)
    }

    /// Front axle's centre-line point `(x, y)` at `t` \[m\].
    pub fn point(&self, t: f64) -> (f64, f64) {
        let (k, s, h) = self.segment(t);
        let (s2, s3) = (s * s, s * s * s);
        let (h00, h10, h01, h11) =
            (2.0 * s3 - 3.0 * s2 + 1.0, s3 - 2.0 * s2 + s, -2.0 * s3 + 3.0 * s2, s3 - s2);
        let c = |a: usize| {
            // A coordinate that stays put over the segment is returned as it is (the cubic's weights sum
            // to one only up to round-off), so a path along a line x or y = const stays exactly on it.
            if self.xy[k][a] == self.xy[k + 1][a] && self.slopes[k][a] == 0.0 && self.slopes[k + 1][a] == 0.0
            {
                return self.xy[k][a];
            }
            h00 * self.xy[k][a]
                + h10 * h * self.slopes[k][a]
                + h01 * self.xy[k + 1][a]
                + h11 * h * self.slopes[k + 1][a]
        };
        (c(0), c(1))
    }

    /// The point `dist` \[m\] (straight-line, horizontal) behind the point at `t` along the way it came:
    /// the latest earlier time on the path at that distance, found by stepping back 16 samples per row
    /// interval and bisecting. Before the first row the path is continued backwards as a straight line
    /// along its heading at t = 0 (as if the vehicle had driven straight into the first row). After the
    /// last row the point of the last row's time is used (the vehicle stands).
    pub fn trailing_point(&self, t: f64, dist: f64) -> (f64, f64) {
        let t = t.clamp(0.0, self.last_time());
        let f = self.point(t);
        let away = |tau: f64| {
            let q = self.point(tau);
            (q.0 - f.0).hypot(q.1 - f.1) >= dist
        };
        // Sample times from t back to 0: the rows' times below t, each interval cut in 16.
        let (k, _, _) = self.segment(t);
        let mut near = t;
        let mut found = None;
        'back: for j in (0..=k).rev() {
            let (t0, t1) = (self.times[j], self.times[j + 1].min(t));
            for i in (0..16).rev() {
                let tau = t0 + (t1 - t0) * i as f64 / 16.0;
                if tau >= near {
                    continue;
                }
                if away(tau) {
                    found = Some((tau, near));
                    break 'back;
                }
                near = tau;
            }
        }
        if let Some((lo, hi)) = found {
            // `lo` is at least `dist` away, `hi` closer: the last time at least `dist` away.
            let (lo, _) = bisect(lo, hi, away);
            return self.point(lo);
        }
        // On the straight continuation before the start: P₀ − s u with |P₀ − s u − F| = dist, s ≥ 0.
        let p0 = self.point(0.0);
        let (uy, ux) = self.heading(0.0).sin_cos();
        let (wx, wy) = (p0.0 - f.0, p0.1 - f.1);
        let wu = wx * ux + wy * uy;
        let s = wu + (wu * wu - (wx * wx + wy * wy) + dist * dist).max(0.0).sqrt();
        (p0.0 - s * ux, p0.1 - s * uy)
    }

    /// Heading \[rad\] of a vehicle whose front axle is on the path at `t` and whose rear axle, `dist` \[m\]
    /// behind, is on the path too ([`Self::trailing_point`]): the direction from the rear to the front
    /// point. On a circle of radius ρ it lags the tangent by asin(dist / 2ρ); on a straight path it is the
    /// path's direction. With no wheelbase (`dist` ≤ 0: a single axle) the rear point is the front point: the path's
    /// tangent heading is used.
    pub fn trailing_heading(&self, t: f64, dist: f64) -> f64 {
        if dist <= 0.0 {
            return self.heading(t);
        }
        let f = self.point(t.clamp(0.0, self.last_time()));
        let r = self.trailing_point(t, dist);
        (f.1 - r.1).atan2(f.0 - r.0)
    }

    /// Horizontal velocity `(vx, vy)` at `t` \[m/s\]; zero after the last row.
    pub fn velocity(&self, t: f64) -> (f64, f64) {
        if t > self.last_time() {
            return (0.0, 0.0);
        }
        let (k, s, h) = self.segment(t);
        let s2 = s * s;
        let (d00, d10, d01, d11) =
            (6.0 * s2 - 6.0 * s, 3.0 * s2 - 4.0 * s + 1.0, -6.0 * s2 + 6.0 * s, 3.0 * s2 - 2.0 * s);
        let c = |a: usize| {
            (d00 * self.xy[k][a] + d01 * self.xy[k + 1][a]) / h
                + d10 * self.slopes[k][a]
                + d11 * self.slopes[k + 1][a]
        };
        (c(0), c(1))
    }

    /// Speed along the path \[m/s\] (horizontal).
    pub fn speed(&self, t: f64) -> f64 {
        let (vx, vy) = self.velocity(t);
        vx.hypot(vy)
    }

    /// Heading \[rad\] (angle of the tangent from +x towards +y) at `t`. Where the vehicle stands (zero
    /// velocity) the heading of its segment's chord, else of the nearest moving time before, else after.
    pub fn heading(&self, t: f64) -> f64 {
        let (vx, vy) = self.velocity(t.min(self.last_time()));
        if vx != 0.0 || vy != 0.0 {
            return vy.atan2(vx);
        }
        let (k, _, _) = self.segment(t);
        let order = (0..=k).rev().chain(k + 1..self.xy.len() - 1);
        for j in order {
            let (a, b) = (self.xy[j], self.xy[j + 1]);
            if a != b {
                return (b[1] - a[1]).atan2(b[0] - a[0]);
            }
        }
        0.0
    }

    /// Largest speed \[m/s\], sampled 64 times per segment.
    pub fn max_speed(&self) -> f64 {
        let mut v = 0.0f64;
        for w in self.times.windows(2) {
            for j in 0..=64 {
                v = v.max(self.speed(w[0] + (w[1] - w[0]) * j as f64 / 64.0));
            }
        }
        v
    }

    /// First time the front axle reaches `x` or beyond \[s\], `None` if it never does. Sampled 64 times
    /// per segment, then bisection.
    pub fn time_to_x(&self, x: f64) -> Option<f64> {
        let reached = |t: f64| self.point(t).0 >= x;
        if reached(0.0) {
            return Some(0.0);
        }
        let mut prev = 0.0;
        for w in self.times.windows(2) {
            for j in 1..=64 {
                let t = w[0] + (w[1] - w[0]) * j as f64 / 64.0;
                if reached(t) {
                    return Some(bisect(prev, t, |t| !reached(t)).1);
                }
                prev = t;
            }
        }
        None
    }

    /// Where the row at or before `t` came from (`"path.csv line 5"`), for messages.
    pub fn origin_at(&self, t: f64) -> &str {
        let (k, s, _) = self.segment(t);
        &self.origins[if s >= 1.0 { k + 1 } else { k }]
    }
}

/// Tangents of a monotone cubic Hermite interpolant per coordinate (Fritsch & Carlson 1980): the mean of
/// the neighbouring secants where they agree in sign, zero at a local extremum or a stop, limited so that
/// the curve does not overshoot; at the ends the one-sided three-point slope ([`end_slope`]).
fn fritsch_carlson(t: &[f64], p: &[[f64; 2]]) -> Vec<[f64; 2]> {
    let n = t.len();
    let mut m = vec![[0.0; 2]; n];
    for a in 0..2 {
        let d: Vec<f64> = (0..n - 1).map(|k| (p[k + 1][a] - p[k][a]) / (t[k + 1] - t[k])).collect();
        if n == 2 {
            m[0][a] = d[0];
            m[1][a] = d[0];
        } else {
            m[0][a] = end_slope(t[1] - t[0], t[2] - t[1], d[0], d[1]);
            m[n - 1][a] = end_slope(t[n - 1] - t[n - 2], t[n - 2] - t[n - 3], d[n - 2], d[n - 3]);
        }
        for k in 1..n - 1 {
            m[k][a] = if d[k - 1] * d[k] > 0.0 { 0.5 * (d[k - 1] + d[k]) } else { 0.0 };
        }
        for k in 0..n - 1 {
            if d[k] == 0.0 {
                m[k][a] = 0.0;
                m[k + 1][a] = 0.0;
                continue;
            }
            let (al, be) = (m[k][a] / d[k], m[k + 1][a] / d[k]);
            let r = al * al + be * be;
            if r > 9.0 {
                let tau = 3.0 / r.sqrt();
                m[k][a] = tau * al * d[k];
                m[k + 1][a] = tau * be * d[k];
            }
        }
    }
    m
}

/// Slope at the end of a row sequence from the secants `d0` (the end segment, length `h0`) and `d1` (the
/// next, `h1`): the three-point formula ((2h₀ + h₁)d₀ − h₀d₁)/(h₀ + h₁), second-order accurate and exact
/// on a line, with the shape-preserving limits of Moler's `pchip` (Numerical Computing with MATLAB, 2004,
/// §3.4): zero if it turns against d₀, at most 3d₀ where the secants change sign.
fn end_slope(h0: f64, h1: f64, d0: f64, d1: f64) -> f64 {
    let m = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1);
    if m * d0 <= 0.0 {
        0.0
    } else if d0 * d1 < 0.0 && m.abs() > 3.0 * d0.abs() {
        3.0 * d0
    } else {
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A straight line at constant speed is reproduced to round-off, with the heading of the line.
    #[test]
    fn a_straight_path_is_a_line() {
        let rows = vec![vec![0.0, 1.0, 0.5], vec![0.7, 2.4, 1.2], vec![2.0, 5.0, 2.5]];
        let p = VehiclePath::from_rows(&rows).unwrap();
        for j in 0..=40 {
            let t = 2.0 * j as f64 / 40.0;
            let (x, y) = p.point(t);
            assert!((x - (1.0 + 2.0 * t)).abs() < 1e-12 && (y - (0.5 + t)).abs() < 1e-12, "t = {t}: {x} {y}");
            assert!((p.heading(t) - 0.5f64.atan()).abs() < 1e-12);
            assert!((p.speed(t) - 5f64.sqrt()).abs() < 1e-12);
        }
        assert_eq!(p.point(3.0), p.point(2.0));
        assert_eq!(p.speed(3.0), 0.0);
        assert!((p.heading(3.0) - 0.5f64.atan()).abs() < 1e-12, "the last heading is kept at rest");
        assert!((p.time_to_x(3.0).unwrap() - 1.0).abs() < 1e-12);
        assert!(p.time_to_x(5.5).is_none());
    }

    /// A single axle (no wheelbase) has no rear point to trail: its heading is the path's tangent, exactly.
    #[test]
    fn a_single_axle_heads_along_the_tangent() {
        let rows: Vec<Vec<f64>> = (0..=8)
            .map(|k| {
                let a = 0.1 * k as f64;
                vec![k as f64, 20.0 * a.sin(), 20.0 * (1.0 - a.cos())]
            })
            .collect();
        let p = VehiclePath::from_rows(&rows).unwrap();
        for t in [0.0, 1.3, 4.0, 7.9] {
            assert_eq!(p.trailing_heading(t, 0.0), p.heading(t), "t = {t}");
        }
    }

    /// Rows on a circle of radius 20 m driven at 2 m/s (turning at ω = 0.1 rad/s, 1 rad in all), 0.5 s
    /// (1 m of arc) apart: the Hermite curve stays within 1 mm of the circle and its heading is the
    /// circle's tangent ω t to 1 mrad. Expected error: the secant-mean tangents are central differences,
    /// off by h² ω² v/6 in velocity, i.e. h² ω²/6 = 4·10⁻⁴ rad in heading (h = 0.5 s).
    #[test]
    fn a_curved_path_turns_with_its_tangent() {
        let (r, w) = (20.0, 0.1);
        let rows: Vec<Vec<f64>> = (0..=20)
            .map(|k| {
                let t = 0.5 * k as f64;
                vec![t, r * (w * t).sin(), r * (1.0 - (w * t).cos())]
            })
            .collect();
        let p = VehiclePath::from_rows(&rows).unwrap();
        for j in 1..200 {
            let t = 0.05 * j as f64;
            let (x, y) = p.point(t);
            let off = (x.hypot(y - r) - r).abs();
            assert!(off < 1e-3, "t = {t}: {off} m off the circle");
            if t > 0.5 && t < 9.5 {
                assert!(
                    (p.heading(t) - w * t).abs() < 1e-3,
                    "t = {t}: heading {} not {}",
                    p.heading(t),
                    w * t
                );
                assert!((p.speed(t) - 2.0).abs() < 0.01, "t = {t}: speed {}", p.speed(t));
            }
        }
    }

    /// A stop (two rows at one place) is held without rolling back: x never decreases.
    #[test]
    fn a_stop_does_not_overshoot() {
        let rows = vec![vec![0.0, 0.0, 0.0], vec![1.0, 2.0, 0.0], vec![2.0, 2.0, 0.0], vec![3.0, 4.0, 0.0]];
        let p = VehiclePath::from_rows(&rows).unwrap();
        let mut last = f64::NEG_INFINITY;
        for j in 0..=300 {
            let (x, _) = p.point(0.01 * j as f64);
            assert!(x >= last - 1e-12, "rolls back at t = {}", 0.01 * j as f64);
            last = x;
        }
        assert_eq!(p.point(1.5), (2.0, 0.0));
        assert_eq!(p.heading(1.5), 0.0, "standing: the heading of the way it came");
    }

    #[test]
    fn bad_paths_are_named_by_line_and_value() {
        let f = Path::new("path.csv");
        let e = VehiclePath::parse("t_s,x_m,y_m\n0,1,0\n0.5,2,0\n0.4,3,0\n", f).unwrap_err();
        assert!(e.starts_with("path.csv line 4: time 0.4 s does not increase"), "{e}");
        let e = VehiclePath::parse("0 1 0\n1 2 x\n", f).unwrap_err();
        assert!(e.starts_with("path.csv line 2: `x` is not a number; expected rows `t_s x_m y_m`"), "{e}");
        let e = VehiclePath::parse("0 1 0\n", f).unwrap_err();
        assert!(e.contains("path.csv: 1 row(s); a path needs at least two rows"), "{e}");
        let e = VehiclePath::parse("0 1\n1 2\n", f).unwrap_err();
        assert!(e.starts_with("path.csv line 1: 2 values, expected three"), "{e}");
        let e = VehiclePath::parse("0.5 1 0\n1 2 0\n", f).unwrap_err();
        assert!(e.contains("line 1: the first row's time is 0.5 s; the path starts at t = 0"), "{e}");
        let e = VehiclePath::from_rows(&[vec![0.0, 1.0, 0.0], vec![1.0, 1.0, 0.0]]).unwrap_err();
        assert!(e.contains("every row is at the same place"), "{e}");
        let e = VehiclePath::from_rows(&[vec![0.0, 1.0, 0.0], vec![1.0, f64::NAN, 0.0]]).unwrap_err();
        assert!(e.starts_with("rows[1]: NaN is not a finite number"), "{e}");
        let p = VehiclePath::parse("# t x y z\n0 1 0 0.4\n1 2 0\n", f).unwrap();
        assert_eq!(p.heights, vec![RowHeight { t: 0.0, z: 0.4, origin: "path.csv line 2".into() }]);
        assert_eq!(p.origin_at(0.5), "path.csv line 2");
    }
}
