//! Hydrostatic load estimates for a wheel standing on the floor in water shallower than its radius (the
//! loads of the wheel case, [`crate::wheel_wading`], `docs/sph.md` §4).
//!
//! The pressure on the wheel's lower mantle is taken as hydrostatic under a level on each face: the
//! bow wave's run-up on the front, the wake's level on the rear. Only where water touches the mantle
//! does it press on it: near the contact line, where the gap between mantle and floor is below about
//! one particle spacing, the fluid does not enter. That wedge is found from the fluid itself: the
//! occupancy of a shell next to the mantle, binned by angle ([`MANTLE_BINS`], [`mantle_bin`]), falls
//! to below half its value on the middle of the face ([`wet_gap`]).

use std::f64::consts::PI;

/// Gravity \[m/s²\].
pub const G: f64 = 9.81;
/// Density of water \[kg/m³\] ([`crate::params::SphParams::water`]).
pub const RHO: f64 = 1000.0;
/// Number of angle bins over the lower half of the mantle (2° each), from the rear end of the axle's
/// horizontal (bin 0, angle −180°) through the bottom (−90°) to the front end (bin 89, 0°).
pub const MANTLE_BINS: usize = 90;

/// The bin of the lower mantle at the angle `theta` \[rad\] from the forward horizontal (negative below
/// the axle), or `None` above the axle.
pub fn mantle_bin(theta: f64) -> Option<usize> {
    if !(-PI..0.0).contains(&theta) {
        return None;
    }
    Some((((theta + PI) / PI * MANTLE_BINS as f64) as usize).min(MANTLE_BINS - 1))
}

/// Heights above the floor \[m\] of the two edges of bin `i` on a wheel of radius `r` standing on it,
/// lower first.
fn bin_heights(r: f64, i: usize) -> (f64, f64) {
    let edge = |k: usize| r + r * (-PI + PI * k as f64 / MANTLE_BINS as f64).sin();
    let (a, b) = (edge(i), edge(i + 1));
    (a.min(b), a.max(b))
}

/// Half the chord a horizontal line at height `z` \[m\] above the floor cuts from a wheel of radius `r`
/// standing on it: how far the mantle reaches along the floor at that height \[m\] (z clamped to [0, r]).
pub fn half_chord(r: f64, z: f64) -> f64 {
    let z = z.clamp(0.0, r);
    (r * r - (r - z) * (r - z)).sqrt()
}

/// Upward hydrostatic force \[N\] on the lower half-mantle (one side of the axle) of a cylinder of radius
/// `r` and width `b` standing on the floor under water up to `level` \[m\] on that side: ρ g b times the
/// area between the water surface and the mantle over the horizontal distances s from the contact line
/// where the mantle is below the surface and at least `gap` above the floor (s from
/// √(r² − (r − gap)²) to √(r² − (r − level)²); midpoint rule, 4 000 intervals).
pub fn mantle_lift(r: f64, b: f64, level: f64, gap: f64) -> f64 {
    let (s0, s1) = (half_chord(r, gap), half_chord(r, level));
    if s1 <= s0 {
        return 0.0;
    }
    const N: usize = 4000;
    let ds = (s1 - s0) / N as f64;
    let area: f64 = (0..N)
        .map(|i| {
            let s = s0 + (i as f64 + 0.5) * ds;
            level - (r - (r * r - s * s).sqrt())
        })
        .sum::<f64>()
        * ds;
    RHO * G * b * area
}

/// Horizontal hydrostatic force \[N\] on a wheel of width `b` with water up to `front` on its front face
/// and `rear` on its rear face (heights above the floor, m): −½ ρ g b (front² − rear²), negative when
/// the front stands higher (the water pushes the wheel back).
pub fn hydrostatic_drag(b: f64, front: f64, rear: f64) -> f64 {
    -0.5 * RHO * G * b * (front * front - rear * rear)
}

/// Height above the floor \[m\] where the wetted part of one face of the lower mantle ends towards the
/// contact line, from `occupancy`, the mean number of fluid particles per bin ([`mantle_bin`]) in a
/// shell next to the mantle. On the face (`front`: bins 45–89, otherwise 0–44) the reference is the
/// mean occupancy of the bins whose centre lies between `depth`/4 and 3 `depth`/4 above the floor;
/// going down from `depth`/2 towards the bottom, the first bin holding less than half the reference is
/// dry, and the wetted mantle ends at its upper edge. 0 when no bin is dry (water down to the contact
/// line), `r` when the face holds no water at all.
pub fn wet_gap(r: f64, depth: f64, occupancy: &[f64], front: bool) -> f64 {
    let bins: Vec<usize> =
        if front { (MANTLE_BINS / 2..MANTLE_BINS).collect() } else { (0..MANTLE_BINS / 2).rev().collect() };
    // `bins` runs from the bottom outwards on either face.
    let centre = |i: usize| {
        let (lo, hi) = bin_heights(r, i);
        0.5 * (lo + hi)
    };
    let mid: Vec<f64> = bins
        .iter()
        .filter(|&&i| (0.25 * depth..=0.75 * depth).contains(&centre(i)))
        .map(|&i| occupancy[i])
        .collect();
    let reference = mid.iter().sum::<f64>() / mid.len().max(1) as f64;
    if reference <= 0.0 {
        return r;
    }
    bins.iter()
        .rev()
        .filter(|&&i| centre(i) < 0.5 * depth)
        .find(|&&i| occupancy[i] < 0.5 * reference)
        .map_or(0.0, |&i| bin_heights(r, i).1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mantle's lift with no dry wedge is ρ g b times the circular segment of height `level`
    /// (R² acos((R − h)/R) − (R − h)√(2Rh − h²)) halved per side, to 10⁻⁶; a level below the wedge
    /// lifts nothing.
    #[test]
    fn mantle_lift_is_the_segment_s_buoyancy() {
        let (r, b, h): (f64, f64, f64) = (0.3, 0.1, 0.2);
        let seg = r * r * ((r - h) / r).acos() - (r - h) * (2.0 * r * h - h * h).sqrt();
        let want = 0.5 * RHO * G * b * seg;
        assert!(
            (mantle_lift(r, b, h, 0.0) - want).abs() < 1e-6 * want,
            "{} {want}",
            mantle_lift(r, b, h, 0.0)
        );
        assert_eq!(mantle_lift(r, b, 0.01, 0.02), 0.0);
    }

    /// Still water on both faces: no horizontal load; 0.3 m against 0.2 m on a 0.1 m wheel is
    /// ½·1000·9.81·0.1·(0.09 − 0.04) = 24.525 N backwards (hydrostatics of a vertical plate).
    #[test]
    fn hydrostatic_drag_is_the_plate_s() {
        assert_eq!(hydrostatic_drag(0.1, 0.2, 0.2), 0.0);
        assert!((hydrostatic_drag(0.1, 0.3, 0.2) + 24.525).abs() < 1e-9);
    }

    /// Bins: −180° is bin 0, −90° is bin 45, just below 0° is bin 89, angles above the axle have none;
    /// the bottom bins' edges are 0 and R(1 − cos 2°) above the floor.
    #[test]
    fn mantle_bins_run_from_rear_to_front() {
        assert_eq!(mantle_bin(-PI), Some(0));
        assert_eq!(mantle_bin(-0.5 * PI), Some(45));
        assert_eq!(mantle_bin(-1e-9), Some(89));
        assert_eq!(mantle_bin(0.1), None);
        let (lo, hi) = bin_heights(0.3, 45);
        assert!(lo.abs() < 1e-12 && (hi - 0.3 * (1.0 - 2f64.to_radians().cos())).abs() < 1e-12);
    }

    /// An occupancy profile dry below a known height on each face gives that height as the wet end (to
    /// the height a bin spans, under 4 mm near the bottom of a 0.3 m wheel); a fully wet face gives 0 and an
    /// empty one the radius.
    #[test]
    fn wet_gap_finds_where_the_water_stops() {
        let (r, depth) = (0.3, 0.2);
        let height = |i: usize| {
            let (lo, hi) = bin_heights(r, i);
            0.5 * (lo + hi)
        };
        // Front wet down to 20 mm, rear to 30 mm.
        let occ: Vec<f64> = (0..MANTLE_BINS)
            .map(|i| {
                let end = if i >= 45 { 0.02 } else { 0.03 };
                if height(i) > end {
                    3.0
                } else {
                    0.2
                }
            })
            .collect();
        let (f, b) = (wet_gap(r, depth, &occ, true), wet_gap(r, depth, &occ, false));
        assert!((f - 0.02).abs() < 0.004, "front {f}");
        assert!((b - 0.03).abs() < 0.004, "rear {b}");
        assert_eq!(wet_gap(r, depth, &[3.0; MANTLE_BINS], true), 0.0);
        assert_eq!(wet_gap(r, depth, &[0.0; MANTLE_BINS], false), r);
    }
}
