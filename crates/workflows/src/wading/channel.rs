//! The wading channel generated from a few numbers, and wheels placed on its road.
//!
//! Coordinates: x along the channel (the direction of travel), y across it (centred on y = 0), z up with
//! the road at z = 0. Along x: a flat approach road, an entry ramp down to the pool floor, the flat pool
//! floor, an exit ramp back up to the road and a flat exit road. The water fills the pool to the depth
//! `water_depth_m` over its floor, at rest; its surface meets the two ramps at the same height, so the
//! water body is symmetric about the pool's centre along x and about y = 0 across.

use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};

/// The channel's dimensions \[m\]; every key is documented in `docs/wading.md`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ChannelSpec {
    /// Flat road before the entry ramp \[m\].
    pub approach_length_m: f64,
    /// Horizontal length of each ramp \[m\].
    pub ramp_length_m: f64,
    /// Length of the flat pool floor \[m\].
    pub pool_length_m: f64,
    /// Depth of the pool floor below the road \[m\].
    pub pool_depth_m: f64,
    /// Flat road after the exit ramp \[m\].
    pub exit_length_m: f64,
    /// Width between the side walls \[m\].
    pub width_m: f64,
    /// Height of the side walls above the road \[m\].
    pub wall_height_m: f64,
    /// Water depth over the pool floor \[m\] (the study's `x`).
    pub water_depth_m: f64,
    /// Akinci adhesion factor of the road and the walls (needs surface tension). Default 1.
    #[serde(default = "one")]
    pub adhesion: f64,
}

fn one() -> f64 {
    1.0
}

impl Validate for ChannelSpec {
    fn validate(&self, c: &mut Checker) {
        c.positive("approach_length_m", self.approach_length_m);
        c.positive("ramp_length_m", self.ramp_length_m);
        c.positive("pool_length_m", self.pool_length_m);
        c.positive("pool_depth_m", self.pool_depth_m);
        c.non_negative("exit_length_m", self.exit_length_m);
        c.positive("width_m", self.width_m);
        c.positive("wall_height_m", self.wall_height_m);
        c.positive("water_depth_m", self.water_depth_m);
        c.non_negative("adhesion", self.adhesion);
        if self.water_depth_m > self.pool_depth_m {
            c.fail(
                "water_depth_m",
                format!(
                    "water_depth_m = {} m is deeper than the pool (pool_depth_m = {} m): the water would run out \
                     over the road; lower it or deepen the pool",
                    self.water_depth_m, self.pool_depth_m
                ),
            );
        }
    }
}

impl ChannelSpec {
    /// Break points `(x, z)` of the road profile, from the start of the approach to the end of the exit.
    pub fn profile(&self) -> [(f64, f64); 6] {
        let a = self.approach_length_m;
        let r = self.ramp_length_m;
        let l = self.pool_length_m;
        let d = self.pool_depth_m;
        [
            (0.0, 0.0),
            (a, 0.0),
            (a + r, -d),
            (a + r + l, -d),
            (a + 2.0 * r + l, 0.0),
            (a + 2.0 * r + l + self.exit_length_m, 0.0),
        ]
    }

    /// Total length \[m\].
    pub fn length(&self) -> f64 {
        self.profile()[5].0
    }

    /// Road height at `x` \[m\] (flat beyond the ends).
    pub fn road_z(&self, x: f64) -> f64 {
        let p = self.profile();
        if x <= p[0].0 {
            return p[0].1;
        }
        for w in p.windows(2) {
            let ((x0, z0), (x1, z1)) = (w[0], w[1]);
            if x <= x1 && x1 > x0 {
                return z0 + (z1 - z0) * (x - x0) / (x1 - x0);
            }
        }
        p[5].1
    }

    /// Height of the still water surface \[m\].
    pub fn water_z(&self) -> f64 {
        self.water_depth_m - self.pool_depth_m
    }

    /// Where the still water surface meets the entry and the exit ramp, `(x_in, x_out)` \[m\].
    pub fn waterline(&self) -> (f64, f64) {
        let p = self.profile();
        let f = self.water_depth_m / self.pool_depth_m;
        (p[2].0 - f * self.ramp_length_m, p[3].0 + f * self.ramp_length_m)
    }

    /// End of the flat pool floor \[m\]: the run stops when the front wheels' axle gets there.
    pub fn pool_end_x(&self) -> f64 {
        self.profile()[3].0
    }

    /// Height of the axle of a wheel of radius `r` \[m\] whose axle is at `x`, resting on the road: the
    /// highest centre of a circle of radius r touching the profile from above (on a ramp the contact
    /// point moves up the slope; over a kink the wheel rests on the kink).
    pub fn axle_z(&self, x: f64, r: f64) -> f64 {
        axle_z_on(&self.profile(), x, r)
    }
}

/// A road the wheels roll on: the generated channel or one read from an STL file.
pub trait Road {
    /// Height \[m\] of the axle of a wheel of radius `r` \[m\] resting on the road with its axle over
    /// `(x, y)` and its wheel plane along `heading` \[rad from +x towards +y\].
    fn axle_height(&self, x: f64, y: f64, r: f64, heading: f64) -> f64;
}

impl Road for ChannelSpec {
    /// The profile does not change across the channel (`y` plays no part); seen along a heading ψ its
    /// break points are 1/cos ψ further apart (a ramp of slope s looks like one of slope s cos ψ).
    fn axle_height(&self, x: f64, _y: f64, r: f64, heading: f64) -> f64 {
        if heading == 0.0 {
            return self.axle_z(x, r);
        }
        let c = heading.cos().abs().max(1e-6);
        let p = self.profile().map(|(xk, zk)| (x + (xk - x) / c, zk));
        axle_z_on(&p, x, r)
    }
}

/// [`ChannelSpec::axle_z`] on the piecewise linear profile `p` (break points `(x, z)`, x increasing,
/// flat beyond the ends).
fn axle_z_on(p: &[(f64, f64); 6], x: f64, r: f64) -> f64 {
    let p = *p;
    let mut z = f64::NEG_INFINITY;
    // Tangent to a segment (or to the flat road continued beyond the ends).
    let mut lines: Vec<((f64, f64), (f64, f64))> = p.windows(2).map(|w| (w[0], w[1])).collect();
    lines.push(((f64::NEG_INFINITY, p[0].1), p[0]));
    lines.push((p[5], (f64::INFINITY, p[5].1)));
    for ((x0, z0), (x1, z1)) in lines {
        let s = if x1.is_finite() && x0.is_finite() && x1 > x0 { (z1 - z0) / (x1 - x0) } else { 0.0 };
        let k = (1.0 + s * s).sqrt();
        let xt = x + s * r / k;
        if xt >= x0 && xt <= x1 {
            let zl = if x0.is_finite() { z0 + s * (x - x0) } else { z1 };
            z = z.max(zl + r * k);
        }
    }
    // Resting on a convex kink.
    for (xv, zv) in p {
        let dx = xv - x;
        if dx.abs() <= r {
            z = z.max(zv + (r * r - dx * dx).sqrt());
        }
    }
    z
}

/// `n = ⌊(hi − lo)/dp⌋` lattice coordinates spaced `dp`, centred in `[lo, hi]`: a fill symmetric about the
/// middle whatever the width (the lattice `lo + (i + ½) dp` leaves the whole remainder on one side).
pub fn centred_lattice(lo: f64, hi: f64, dp: f64) -> Vec<f64> {
    let n = ((hi - lo) / dp + 1e-9).floor().max(0.0) as usize;
    let mid = 0.5 * (lo + hi);
    (0..n).map(|i| mid + (i as f64 - 0.5 * (n as f64 - 1.0)) * dp).collect()
}

/// Pitch \[rad\] of a body whose front and rear axles are at `(x_front, z_front)` and `(x_rear, z_rear)`:
/// positive nose up (a rotation about −y for travel along +x).
pub fn pitch(front: (f64, f64), rear: (f64, f64)) -> f64 {
    (front.1 - rear.1).atan2(front.0 - rear.0)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A channel with every dimension set, shared by the wading tests.
    pub(crate) fn channel() -> ChannelSpec {
        ChannelSpec {
            approach_length_m: 4.0,
            ramp_length_m: 3.0,
            pool_length_m: 6.0,
            pool_depth_m: 0.5,
            exit_length_m: 2.0,
            width_m: 4.0,
            wall_height_m: 1.0,
            water_depth_m: 0.3,
            adhesion: 1.0,
        }
    }

    #[test]
    fn profile_and_waterline_are_symmetric() {
        let c = channel();
        assert_eq!(c.length(), 18.0);
        assert_eq!(c.road_z(2.0), 0.0);
        assert!((c.road_z(5.5) + 0.25).abs() < 1e-12);
        assert_eq!(c.road_z(10.0), -0.5);
        assert!((c.road_z(14.5) + 0.25).abs() < 1e-12);
        assert!((c.water_z() + 0.2).abs() < 1e-12);
        let (a, b) = c.waterline();
        // Water 0.3 m deep on a 0.5 m floor reaches 0.6 of the ramp's length up each ramp.
        assert!((a - (7.0 - 1.8)).abs() < 1e-12 && (b - (13.0 + 1.8)).abs() < 1e-12);
        let centre = 0.5 * (c.profile()[2].0 + c.profile()[3].0);
        assert!((0.5 * (a + b) - centre).abs() < 1e-12);
        assert!((c.road_z(a) - c.water_z()).abs() < 1e-12 && (c.road_z(b) - c.water_z()).abs() < 1e-12);
        assert_eq!(c.pool_end_x(), 13.0);
    }

    /// A wheel of radius R on flat road sits at R; on a ramp of slope s at line(x) + R √(1 + s²) (the
    /// contact point moves uphill by s R/√(1 + s²)); just past the top of the exit ramp it rests on the kink.
    #[test]
    fn wheels_rest_on_the_road() {
        let c = channel();
        let r = 0.5;
        assert!((c.axle_z(1.0, r) - r).abs() < 1e-12);
        assert!((c.axle_z(10.0, r) - (-0.5 + r)).abs() < 1e-12);
        let s: f64 = -0.5 / 3.0;
        let k = (1.0 + s * s).sqrt();
        assert!((c.axle_z(5.5, r) - (c.road_z(5.5) + r * k)).abs() < 1e-12);
        // Over the convex kink at the end of the exit ramp (x = 16, z = 0): centre straight above it.
        assert!((c.axle_z(16.0, r) - r).abs() < 1e-12);
        // Never below the road anywhere along the channel, and touching it.
        for i in 0..=360 {
            let x = i as f64 * 0.05;
            let z = c.axle_z(x, r);
            let clearance = (0..=200)
                .map(|j| {
                    let xs = x - r + j as f64 * r / 100.0;
                    z - (r * r - (xs - x).powi(2)).max(0.0).sqrt() - c.road_z(xs)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(clearance > -1e-9 && clearance < 2e-3, "x = {x}: clearance {clearance}");
        }
    }

    #[test]
    fn a_lattice_across_is_centred_for_any_width() {
        for w in [1.0, 1.003, 0.987] {
            let ys = centred_lattice(-0.5 * w, 0.5 * w, 0.01);
            let (lo, hi) = (ys[0], ys[ys.len() - 1]);
            assert!((lo + hi).abs() < 1e-12, "width {w}: {lo} … {hi}");
            assert!((ys[1] - ys[0] - 0.01).abs() < 1e-12);
        }
        assert_eq!(centred_lattice(0.0, 1.0, 0.01).len(), 100);
    }

    #[test]
    fn pitch_follows_the_axles() {
        assert!((pitch((4.0, 1.0), (0.0, 1.0))).abs() < 1e-15);
        assert!((pitch((4.0, 0.0), (0.0, 1.0)) + 0.25f64.atan()).abs() < 1e-15);
    }

    #[test]
    fn a_pool_deeper_than_the_channel_is_named() {
        let mut c = channel();
        c.water_depth_m = 0.6;
        c.width_m = -1.0;
        let errs = Checker::run(&c, None).unwrap_err();
        let keys: Vec<&str> = errs.iter().map(|e| e.key.as_str()).collect();
        assert!(keys.contains(&"water_depth_m") && keys.contains(&"width_m"), "{errs:?}");
        let msg = &errs.iter().find(|e| e.key == "water_depth_m").unwrap().message;
        assert!(msg.contains("0.6 m is deeper than the pool (pool_depth_m = 0.5 m)"), "{msg}");
    }
}
