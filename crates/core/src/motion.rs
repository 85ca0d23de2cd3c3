//! Prescribed rigid-body kinematics for walls and bodies: fixed, constant translation, rotation about an
//! axis, a tabulated `t vx vy vz wx wy wz` history (linearly interpolated), and hierarchies of these
//! (a wheel rotating on a translating chassis).
//!
//! A [`Pose`] maps a body's reference coordinates (its position at t = 0) to world coordinates:
//! `x = pivot + translation + rotation · (x₀ − pivot)`, where `pivot` is the body's reference point.

use crate::{Quat, Vec3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Rigid placement of a body at some time.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Reference point of the body at t = 0 \[m\].
    pub pivot: Vec3,
    /// Displacement of the reference point since t = 0 \[m\].
    pub translation: Vec3,
    /// Rotation since t = 0 about the reference point.
    pub rotation: Quat,
}

impl Pose {
    pub const IDENTITY: Pose = Pose { pivot: Vec3::ZERO, translation: Vec3::ZERO, rotation: Quat::IDENTITY };

    /// World position of reference-frame point `x0`.
    #[inline]
    pub fn apply(&self, x0: Vec3) -> Vec3 {
        self.pivot + self.translation + self.rotation * (x0 - self.pivot)
    }

    /// Reference-frame point that is at world position `x`.
    #[inline]
    pub fn inverse_apply(&self, x: Vec3) -> Vec3 {
        self.pivot + self.rotation.inverse() * (x - self.pivot - self.translation)
    }

    /// Current position of the reference point.
    pub fn center(&self) -> Vec3 {
        self.pivot + self.translation
    }
}

/// One body's own motion, relative to its parent's reference frame (or the world).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Motion {
    Fixed,
    /// Constant velocity \[m/s\].
    Translation {
        velocity: Vec3,
    },
    /// Constant rotation at `angular_speed` \[rad/s\] about the line through `center` along `axis`
    /// (right-hand rule; `axis` is normalised on construction).
    Rotation {
        center: Vec3,
        axis: Vec3,
        angular_speed: f64,
    },
    Tabulated(MotionTable),
    /// Node `node` of a kinematic tree: its own motion relative to its parent's reference frame, composed
    /// with every ancestor's (a wheel spinning on a moving chassis), for an engine that moves each wall by
    /// one motion.
    Nested {
        tree: Box<KinematicTree>,
        node: usize,
    },
}

/// A velocity history `t vx vy vz wx wy wz` (SI units; ω in rad/s about the moving reference point),
/// linearly interpolated in time and held constant beyond its first and last rows.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MotionTable {
    reference_point: Vec3,
    times: Vec<f64>,
    velocity: Vec<Vec3>,
    angular_velocity: Vec<Vec3>,
    /// Displacement and rotation accumulated from t = 0 up to each row's time.
    knot_translation: Vec<Vec3>,
    knot_rotation: Vec<Quat>,
}

/// A motion table that cannot be used.
#[derive(Debug, Error, PartialEq)]
pub enum MotionError {
    #[error("motion table line {line}: {message}")]
    Line { line: usize, message: String },
    #[error("motion table: {0}")]
    Table(String),
}

impl MotionTable {
    /// Parses whitespace- or comma-separated rows `t vx vy vz wx wy wz`; `#` starts a comment.
    /// Times must increase strictly; the table must have at least one row.
    pub fn parse(text: &str, reference_point: Vec3) -> Result<Self, MotionError> {
        let mut rows = Vec::new();
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let vals: Result<Vec<f64>, _> = line
                .split(|c: char| c.is_whitespace() || c == ',')
                .filter(|w| !w.is_empty())
                .map(str::parse)
                .collect();
            let vals = vals.map_err(|_| MotionError::Line {
                line: i + 1,
                message: format!("`{line}` is not seven numbers `t vx vy vz wx wy wz`"),
            })?;
            if vals.len() != 7 {
                return Err(MotionError::Line {
                    line: i + 1,
                    message: format!("expected seven numbers `t vx vy vz wx wy wz`, found {}", vals.len()),
                });
            }
            if let Some(k) = vals.iter().position(|v| !v.is_finite()) {
                let name = ["t", "vx", "vy", "vz", "wx", "wy", "wz"][k];
                return Err(MotionError::Line {
                    line: i + 1,
                    message: format!("{name} = {} is not a finite number", vals[k]),
                });
            }
            rows.push((i + 1, vals));
        }
        if rows.is_empty() {
            return Err(MotionError::Table("holds no rows; expected lines `t vx vy vz wx wy wz`".into()));
        }
        for w in rows.windows(2) {
            if w[1].1[0] <= w[0].1[0] {
                return Err(MotionError::Line {
                    line: w[1].0,
                    message: format!("time {} does not increase (previous row has {})", w[1].1[0], w[0].1[0]),
                });
            }
        }
        let times = rows.iter().map(|r| r.1[0]).collect();
        let velocity = rows.iter().map(|r| Vec3::new(r.1[1], r.1[2], r.1[3])).collect();
        let angular_velocity = rows.iter().map(|r| Vec3::new(r.1[4], r.1[5], r.1[6])).collect();
        Ok(Self::from_rows(reference_point, times, velocity, angular_velocity))
    }

    /// Builds a table from rows already in memory (times strictly increasing, at least one row).
    pub fn from_rows(
        reference_point: Vec3,
        times: Vec<f64>,
        velocity: Vec<Vec3>,
        angular_velocity: Vec<Vec3>,
    ) -> Self {
        let mut table = MotionTable {
            reference_point,
            times,
            velocity,
            angular_velocity,
            knot_translation: Vec::new(),
            knot_rotation: Vec::new(),
        };
        table.integrate_knots();
        table
    }

    /// Integrates displacement and rotation from t = 0 to every row time.
    fn integrate_knots(&mut self) {
        let n = self.times.len();
        self.knot_translation = vec![Vec3::ZERO; n];
        self.knot_rotation = vec![Quat::IDENTITY; n];
        // Accumulate from t = 0 forwards to each knot (knots before 0 are reached backwards).
        for k in 0..n {
            let (d, q) = self.integrate(0.0, self.times[k], Vec3::ZERO, Quat::IDENTITY);
            self.knot_translation[k] = d;
            self.knot_rotation[k] = q;
        }
    }

    /// Velocity and angular velocity at time `t` (linear interpolation, held beyond the ends).
    pub fn rates(&self, t: f64) -> (Vec3, Vec3) {
        let n = self.times.len();
        if t <= self.times[0] {
            return (self.velocity[0], self.angular_velocity[0]);
        }
        if t >= self.times[n - 1] {
            return (self.velocity[n - 1], self.angular_velocity[n - 1]);
        }
        let k = self.times.partition_point(|&tk| tk <= t) - 1;
        let s = (t - self.times[k]) / (self.times[k + 1] - self.times[k]);
        (
            self.velocity[k].lerp(self.velocity[k + 1], s),
            self.angular_velocity[k].lerp(self.angular_velocity[k + 1], s),
        )
    }

    /// Integrates from `t0` (state `d0`, `q0`) to `t1`: displacement exactly (trapezoid on a piecewise
    /// linear velocity, split at knots) and rotation with midpoint sub-steps (exact for a fixed axis).
    fn integrate(&self, t0: f64, t1: f64, d0: Vec3, q0: Quat) -> (Vec3, Quat) {
        let mut cuts: Vec<f64> = vec![t0];
        let (lo, hi) = (t0.min(t1), t0.max(t1));
        let inner = self.times.iter().copied().filter(|&t| t > lo && t < hi);
        if t1 >= t0 {
            cuts.extend(inner);
        } else {
            cuts.extend(inner.rev());
        }
        cuts.push(t1);
        let (mut d, mut q) = (d0, q0);
        for w in cuts.windows(2) {
            let (a, b) = (w[0], w[1]);
            let va = self.rates(a).0;
            let vb = self.rates(b).0;
            d += 0.5 * (va + vb) * (b - a);
            const SUB: usize = 8;
            for j in 0..SUB {
                let tm = a + (b - a) * (j as f64 + 0.5) / SUB as f64;
                let w_mid = self.rates(tm).1;
                let angle = w_mid * ((b - a) / SUB as f64);
                q = (Quat::from_scaled_axis(angle) * q).normalize();
            }
        }
        (d, q)
    }

    fn pose(&self, t: f64) -> Pose {
        // Start from the nearest knot at or before t (or t = 0 when t precedes every knot).
        let k = self.times.partition_point(|&tk| tk <= t);
        let (t0, d0, q0) = if k == 0 {
            (0.0, Vec3::ZERO, Quat::IDENTITY)
        } else {
            (self.times[k - 1], self.knot_translation[k - 1], self.knot_rotation[k - 1])
        };
        let (translation, rotation) = self.integrate(t0, t, d0, q0);
        Pose { pivot: self.reference_point, translation, rotation }
    }
}

impl Motion {
    /// A rotation with the axis normalised (a zero axis means no rotation).
    pub fn rotation(center: Vec3, axis: Vec3, angular_speed: f64) -> Self {
        Motion::Rotation { center, axis: axis.normalize_or_zero(), angular_speed }
    }

    /// Placement at time `t` \[s\].
    pub fn pose(&self, t: f64) -> Pose {
        match self {
            Motion::Fixed => Pose::IDENTITY,
            Motion::Translation { velocity } => Pose { translation: *velocity * t, ..Pose::IDENTITY },
            Motion::Rotation { center, axis, angular_speed } => Pose {
                pivot: *center,
                translation: Vec3::ZERO,
                rotation: Quat::from_axis_angle(*axis, angular_speed * t),
            },
            Motion::Tabulated(table) => table.pose(t),
            Motion::Nested { tree, node } => {
                // The node's own reference point, carried through the whole chain; a rigid placement is
                // fixed by where that point goes and by the rotation.
                let pivot = tree.nodes[*node].0.pose(0.0).pivot;
                let translation = tree.world_point(*node, t, pivot) - pivot;
                Pose { pivot, translation, rotation: tree.rotation(*node, t) }
            }
        }
    }

    /// Velocity \[m/s\] at time `t` of the body point currently at `x` (same frame as the motion).
    pub fn velocity_at(&self, t: f64, x: Vec3) -> Vec3 {
        match self {
            Motion::Fixed => Vec3::ZERO,
            Motion::Translation { velocity } => *velocity,
            Motion::Rotation { center, axis, angular_speed } => (*axis * *angular_speed).cross(x - *center),
            Motion::Tabulated(table) => {
                let (v, w) = table.rates(t);
                let c = table.pose(t).center();
                v + w.cross(x - c)
            }
            Motion::Nested { tree, node } => tree.velocity_at(*node, t, x),
        }
    }

    /// Angular velocity \[rad/s\] at time `t`.
    pub fn angular_velocity(&self, t: f64) -> Vec3 {
        match self {
            Motion::Fixed | Motion::Translation { .. } => Vec3::ZERO,
            Motion::Rotation { axis, angular_speed, .. } => *axis * *angular_speed,
            Motion::Tabulated(table) => table.rates(t).1,
            Motion::Nested { tree, node } => tree.angular_velocity(*node, t),
        }
    }
}

/// Bodies whose motions are nested: each node moves relative to its parent's reference frame.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct KinematicTree {
    nodes: Vec<(Motion, Option<usize>)>,
}

impl KinematicTree {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a body moving by `motion` relative to `parent` (or the world); returns its index.
    /// Panics if `parent` is not an existing node (parents come before children).
    pub fn add(&mut self, motion: Motion, parent: Option<usize>) -> usize {
        if let Some(p) = parent {
            assert!(p < self.nodes.len(), "parent {p} must be added before its child");
        }
        self.nodes.push((motion, parent));
        self.nodes.len() - 1
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The motion of node `i` in the world: its own motion when it has no parent, else the composed
    /// [`Motion::Nested`].
    pub fn world_motion(&self, i: usize) -> Motion {
        match &self.nodes[i] {
            (own, None) => own.clone(),
            (_, Some(_)) => Motion::Nested { tree: Box::new(self.clone()), node: i },
        }
    }

    /// World placement of body `i` at time `t`, as a map from its reference coordinates to the world.
    pub fn world_point(&self, i: usize, t: f64, x0: Vec3) -> Vec3 {
        let (motion, parent) = &self.nodes[i];
        let local = motion.pose(t).apply(x0);
        match parent {
            Some(p) => self.world_point(*p, t, local),
            None => local,
        }
    }

    /// Reference coordinates of body `i` of the world point `x`.
    pub fn reference_point(&self, i: usize, t: f64, x: Vec3) -> Vec3 {
        let (motion, parent) = &self.nodes[i];
        let local = match parent {
            Some(p) => self.reference_point(*p, t, x),
            None => x,
        };
        motion.pose(t).inverse_apply(local)
    }

    /// World velocity \[m/s\] at time `t` of body `i`'s material point currently at world position `x`.
    pub fn velocity_at(&self, i: usize, t: f64, x: Vec3) -> Vec3 {
        let (motion, parent) = &self.nodes[i];
        match parent {
            None => motion.velocity_at(t, x),
            Some(p) => {
                let x_parent_ref = self.reference_point(*p, t, x);
                let v_rel = motion.velocity_at(t, x_parent_ref);
                self.rotation(*p, t) * v_rel + self.velocity_at(*p, t, x)
            }
        }
    }

    /// World angular velocity \[rad/s\] of body `i`.
    pub fn angular_velocity(&self, i: usize, t: f64) -> Vec3 {
        let (motion, parent) = &self.nodes[i];
        match parent {
            None => motion.angular_velocity(t),
            Some(p) => self.rotation(*p, t) * motion.angular_velocity(t) + self.angular_velocity(*p, t),
        }
    }

    /// World rotation of body `i` since t = 0.
    pub fn rotation(&self, i: usize, t: f64) -> Quat {
        let (motion, parent) = &self.nodes[i];
        let own = motion.pose(t).rotation;
        match parent {
            Some(p) => self.rotation(*p, t) * own,
            None => own,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn rotation_moves_points_on_circles() {
        let m = Motion::rotation(Vec3::new(1.0, 0.0, 0.0), Vec3::Z, PI); // half a turn per second
        let p = m.pose(1.0).apply(Vec3::new(2.0, 0.0, 0.0));
        assert!((p - Vec3::new(0.0, 0.0, 0.0)).length() < 1e-12);
        let v = m.velocity_at(0.0, Vec3::new(2.0, 0.0, 0.0));
        assert!((v - Vec3::new(0.0, PI, 0.0)).length() < 1e-12);
    }

    #[test]
    fn tabulated_translation_integrates_exactly() {
        // v_x ramps 0 → 2 m/s over 1 s then holds: x(1) = 1, x(2) = 3.
        let t = MotionTable::parse("# t vx vy vz wx wy wz\n0 0 0 0 0 0 0\n1, 2, 0, 0, 0, 0, 0\n", Vec3::ZERO)
            .unwrap();
        let m = Motion::Tabulated(t);
        assert!((m.pose(1.0).translation.x - 1.0).abs() < 1e-12);
        assert!((m.pose(2.0).translation.x - 3.0).abs() < 1e-12);
        assert!((m.pose(0.5).translation.x - 0.25).abs() < 1e-12);
        assert!((m.velocity_at(0.25, Vec3::ZERO).x - 0.5).abs() < 1e-12);
    }

    #[test]
    fn tabulated_constant_spin_matches_analytic_rotation() {
        let t = MotionTable::parse("0 0 0 0 0 0 2\n10 0 0 0 0 0 2\n", Vec3::ZERO).unwrap();
        let m = Motion::Tabulated(t);
        let q = m.pose(0.7).rotation;
        let expect = Quat::from_axis_angle(Vec3::Z, 1.4);
        assert!(q.angle_between(expect) < 1e-12);
    }

    #[test]
    fn bad_tables_name_the_line() {
        let e = MotionTable::parse("0 0 0 0 0 0 0\n0 1 0 0 0 0 0\n", Vec3::ZERO).unwrap_err();
        assert!(e.to_string().contains("line 2") && e.to_string().contains("does not increase"), "{e}");
        let e = MotionTable::parse("0 0 0\n", Vec3::ZERO).unwrap_err();
        assert!(e.to_string().contains("line 1") && e.to_string().contains("found 3"), "{e}");
        assert!(MotionTable::parse("\n# nothing\n", Vec3::ZERO).is_err());
        // A value that overflowed (a speed of 1e308 scaled up) names its column, not the count.
        let e = MotionTable::parse("0 1 0 0 0 0 0\n1 inf 0 0 0 0 0\n", Vec3::ZERO).unwrap_err();
        assert!(
            e.to_string().contains("line 2") && e.to_string().contains("vx = inf is not a finite number"),
            "{e}"
        );
    }

    #[test]
    fn wheel_on_a_moving_chassis() {
        // Chassis moves at 10 m/s along x; wheel of radius 0.5 rolls (ω = +20 rad/s about +y, centre at z = 0.5).
        let mut tree = KinematicTree::new();
        let chassis = tree.add(Motion::Translation { velocity: Vec3::new(10.0, 0.0, 0.0) }, None);
        let wheel = tree.add(Motion::rotation(Vec3::new(0.0, 0.0, 0.5), Vec3::Y, 20.0), Some(chassis));
        // Rolling without slip: the contact point (bottom of the wheel) is at rest, the top moves at 20 m/s.
        let t = 0.3;
        let centre = tree.world_point(wheel, t, Vec3::new(0.0, 0.0, 0.5));
        assert!((centre - Vec3::new(3.0, 0.0, 0.5)).length() < 1e-12);
        let bottom = centre - Vec3::new(0.0, 0.0, 0.5);
        let top = centre + Vec3::new(0.0, 0.0, 0.5);
        assert!(tree.velocity_at(wheel, t, bottom).length() < 1e-12);
        assert!((tree.velocity_at(wheel, t, top) - Vec3::new(20.0, 0.0, 0.0)).length() < 1e-12);
        assert!((tree.angular_velocity(wheel, t) - Vec3::new(0.0, 20.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn a_nested_motion_moves_as_its_tree_node() {
        // A wheel (ω = 20 rad/s about y through (0, 0, 0.5)) on a chassis that turns at 0.4 rad/s about z
        // through (2, 1, 0) while a table drives it along x: the single motion of the wheel places every
        // point, and gives its velocity and spin, as the tree does (round-off only).
        let table =
            MotionTable::parse("0 1 0 0 0 0 0.4\n10 3 0 0 0 0 0.4\n", Vec3::new(2.0, 1.0, 0.0)).unwrap();
        let mut tree = KinematicTree::new();
        let chassis = tree.add(Motion::Tabulated(table), None);
        let wheel = tree.add(Motion::rotation(Vec3::new(0.0, 0.0, 0.5), Vec3::Y, 20.0), Some(chassis));
        let nested = tree.world_motion(wheel);
        assert!(matches!(nested, Motion::Nested { .. }));
        assert_eq!(tree.world_motion(chassis), tree.nodes[chassis].0, "a root node is its own motion");
        for t in [0.0, 0.37, 2.5] {
            let pose = nested.pose(t);
            for x0 in [Vec3::new(0.0, 0.0, 0.5), Vec3::new(0.3, -0.2, 0.9), Vec3::new(-1.0, 2.0, 0.0)] {
                let want = tree.world_point(wheel, t, x0);
                assert!((pose.apply(x0) - want).length() < 1e-12, "t = {t}: {x0}");
                let x = want;
                assert!((nested.velocity_at(t, x) - tree.velocity_at(wheel, t, x)).length() < 1e-12);
                assert!((pose.inverse_apply(x) - x0).length() < 1e-12);
            }
            assert!((nested.angular_velocity(t) - tree.angular_velocity(wheel, t)).length() < 1e-12);
        }
        // Analytic: after 2.5 s the chassis has turned 1 rad about z, so the wheel spins about the turned y
        // axis, plus the chassis's own 0.4 rad/s about z.
        let w = nested.angular_velocity(2.5);
        let want = Vec3::new(-20.0 * 1f64.sin(), 20.0 * 1f64.cos(), 0.4);
        assert!((w - want).length() < 1e-12, "{w} vs {want}");
    }
}
