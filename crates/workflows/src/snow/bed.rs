//! Rough walls: beds of frozen spheres, and the statistics of many impacts on them.
//!
//! The thesis made its rough wall by inserting 1 µm ABS spheres at random positions in a box, overlaps
//! allowed, and raised the volume fraction "to receive a suitable surface roughness" (Lind 2017;
//! the fractions are not published). [`random_insertion`] does exactly that; [`settled`] instead settles the
//! spheres geometrically into the box until no two overlap (a loose random packing; no dynamics).
//! Bed spheres are frozen: infinite mass, no motion (free wall spheres would be knocked away by the impacts).

use super::impact::BedSphere;
use spatter_core::grid::CellGrid;
use spatter_core::rng::{Rng, RngExt};
use spatter_core::Vec3;

/// A bed of equal frozen spheres, square of side `width` centred on the z axis, resting on z = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct Bed {
    pub spheres: Vec<BedSphere>,
    /// Highest point of any sphere \[m\].
    pub top: f64,
    /// Side of the square footprint \[m\].
    pub width: f64,
    /// Sphere radius \[m\].
    pub sphere_radius: f64,
    /// Sphere volume over box volume (overlapping volume counted twice) \[-\].
    pub nominal_fraction: f64,
}

fn finish(centres: Vec<Vec3>, r: f64, width: f64, thickness: f64) -> Bed {
    let top = centres.iter().map(|c| c.z + r).fold(0.0, f64::max);
    let n = centres.len() as f64;
    Bed {
        spheres: centres.iter().map(|c| BedSphere { centre: c.to_array(), radius: r }).collect(),
        top,
        width,
        sphere_radius: r,
        nominal_fraction: n * 4.0 / 3.0 * std::f64::consts::PI * r.powi(3) / (width * width * thickness),
    }
}

/// Number of spheres of diameter `d` that fill `fraction` of a `width² × thickness` box.
pub fn sphere_count(width: f64, thickness: f64, d: f64, fraction: f64) -> usize {
    (fraction * width * width * thickness / (std::f64::consts::PI / 6.0 * d * d * d)).round().max(1.0)
        as usize
}

/// Uniformly random centres in the box (centres at least one radius inside it), overlaps allowed.
pub fn random_insertion(width: f64, thickness: f64, d: f64, fraction: f64, rng: &mut Rng) -> Bed {
    let r = 0.5 * d;
    let n = sphere_count(width, thickness, d, fraction);
    let h = (thickness - 2.0 * r).max(0.0);
    let centres = (0..n)
        .map(|_| {
            Vec3::new(
                (rng.random::<f64>() - 0.5) * width,
                (rng.random::<f64>() - 0.5) * width,
                r + rng.random::<f64>() * h,
            )
        })
        .collect();
    finish(centres, r, width, thickness)
}

/// Spheres settled into the box (side walls, floor z = 0) geometrically, without dynamics: every sphere is
/// lowered by 0.1 r per iteration (a kinematic stand-in for gravity) and the overlaps are projected apart
/// after each, then projection alone continues until the largest overlap is below 10⁻³ d.
pub fn settled(width: f64, thickness: f64, d: f64, fraction: f64, rng: &mut Rng) -> Bed {
    let r = 0.5 * d;
    let n = sphere_count(width, thickness, d, fraction);
    let half = 0.5 * width - r;
    let mut pos: Vec<Vec3> = (0..n)
        .map(|_| {
            Vec3::new(
                (rng.random::<f64>() - 0.5) * 2.0 * half.max(0.0),
                (rng.random::<f64>() - 0.5) * 2.0 * half.max(0.0),
                r + rng.random::<f64>() * 3.0 * thickness,
            )
        })
        .collect();
    let mut grid = CellGrid::new();
    let mut shift = vec![Vec3::ZERO; n];
    let clamp = |p: &mut Vec3| {
        p.x = p.x.clamp(-half, half);
        p.y = p.y.clamp(-half, half);
        p.z = p.z.max(r);
    };
    let fall_iterations = (3.0 * thickness / (0.1 * r)).ceil() as usize + 200;
    // One projection pass: moves every pair apart by half its overlap (Jacobi) and returns the largest
    // overlap it found.
    let mut pass = |pos: &mut Vec<Vec3>| -> f64 {
        grid.rebuild(pos, d);
        shift.iter_mut().for_each(|s| *s = Vec3::ZERO);
        let mut worst: f64 = 0.0;
        for i in 0..n {
            let pi = pos[i];
            grid.for_each_candidate(pi, |j| {
                let j = j as usize;
                if j == i {
                    return;
                }
                let dv = pi - pos[j];
                let dist = dv.length();
                if dist < d {
                    let ov = d - dist;
                    worst = worst.max(ov);
                    // Coincident centres (e.g. two spheres clamped into the same corner) separate along a
                    // direction fixed by their indices.
                    let dir = if dist > 1e-9 * d {
                        // A level pair (e.g. both on the floor, squeezed between walls) is tilted so that
                        // one of them can ride up and out instead of being pushed sideways for ever.
                        let u = dv / dist;
                        if u.z.abs() < 1e-3 {
                            (u + Vec3::new(0.0, 0.0, if i > j { 0.1 } else { -0.1 })).normalize()
                        } else {
                            u
                        }
                    } else {
                        let a = (i.min(j) * 7919 + i.max(j)) as f64;
                        let u = Vec3::new(a.sin(), a.cos(), 0.3).normalize();
                        if i < j {
                            u
                        } else {
                            -u
                        }
                    };
                    shift[i] += dir * (0.5 * ov);
                }
            });
        }
        for (p, s) in pos.iter_mut().zip(&shift) {
            *p += *s;
            clamp(p);
        }
        worst
    };
    for _ in 0..fall_iterations {
        for p in pos.iter_mut() {
            p.z -= 0.1 * r;
            clamp(p);
        }
        for _ in 0..4 {
            pass(&mut pos);
        }
    }
    // Relax without gravity until no overlap above 10⁻³ d is left (a pass that finds none moves nothing
    // beyond that size).
    for _ in 0..20_000 {
        if pass(&mut pos) < 1e-3 * d {
            break;
        }
    }
    finish(pos, r, width, thickness)
}

/// Two-sided standard normal quantile z with P(|Z| ≤ z) = `confidence` (Acklam's rational
/// approximation, relative error below 1.2e-9).
pub fn normal_quantile_two_sided(confidence: f64) -> f64 {
    let p = 0.5 + 0.5 * confidence;
    // Acklam (2003), upper region p > 0.97575 and central region.
    const A: [f64; 6] = [
        -3.969683028665376e1,
        2.209460984245205e2,
        -2.759285104469687e2,
        1.38357751867269e2,
        -3.066479806614716e1,
        2.506628277459239,
    ];
    const B: [f64; 5] = [
        -5.447609879822406e1,
        1.615858368580409e2,
        -1.556989798598866e2,
        6.680131188771972e1,
        -1.328068155288572e1,
    ];
    const C: [f64; 6] = [
        -7.784894002430293e-3,
        -3.223964580411365e-1,
        -2.400758277161838,
        -2.549732539343734,
        4.374664141464968,
        2.938163982698783,
    ];
    const D: [f64; 4] = [7.784695709041462e-3, 3.224671290700398e-1, 2.445134137142996, 3.754408661907416];
    if p > 0.97575 {
        let q = (-2.0 * (1.0 - p).ln()).sqrt();
        -(((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

/// Wilson score interval (Wilson 1927) of a binomial proportion with `k` successes in `n` trials at
/// two-sided `confidence`: (estimate k/n, lower, upper).
pub fn wilson_interval(k: usize, n: usize, confidence: f64) -> (f64, f64, f64) {
    if n == 0 {
        return (f64::NAN, 0.0, 1.0);
    }
    let z = normal_quantile_two_sided(confidence);
    let nf = n as f64;
    let p = k as f64 / nf;
    let z2 = z * z;
    let denom = 1.0 + z2 / nf;
    let centre = (p + z2 / (2.0 * nf)) / denom;
    let half = z / denom * (p * (1.0 - p) / nf + z2 / (4.0 * nf * nf)).sqrt();
    (p, (centre - half).max(0.0), (centre + half).min(1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_core::rng::seeded;

    #[test]
    fn wilson_interval_reference_values() {
        // z(95 %) = 1.959964 (standard normal tables). Wilson 95 % for 8/10: [0.4902, 0.9433]; for 0/20:
        // [0, 0.1611] (Newcombe 1998, Table I style values, 4 digits).
        assert!((normal_quantile_two_sided(0.95) - 1.959964).abs() < 1e-6);
        assert!((normal_quantile_two_sided(0.99) - 2.575829).abs() < 1e-6);
        let (p, lo, hi) = wilson_interval(8, 10, 0.95);
        assert_eq!(p, 0.8);
        assert!((lo - 0.4902).abs() < 1e-4 && (hi - 0.9433).abs() < 1e-4, "{lo} {hi}");
        let (_, lo, hi) = wilson_interval(0, 20, 0.95);
        assert_eq!(lo, 0.0);
        assert!((hi - 0.1611).abs() < 1e-4, "{hi}");
    }

    #[test]
    fn beds_have_the_requested_content() {
        let mut rng = seeded(3, 0);
        let bed = random_insertion(10e-6, 4e-6, 1e-6, 0.64, &mut rng);
        assert_eq!(bed.spheres.len(), sphere_count(10e-6, 4e-6, 1e-6, 0.64));
        assert!((bed.nominal_fraction - 0.64).abs() < 0.01);
        assert!(bed.top <= 4e-6 + 1e-12 && bed.top > 3e-6);
        let mut rng = seeded(3, 1);
        let bed = settled(8e-6, 3e-6, 1e-6, 0.5, &mut rng);
        // No overlaps left beyond the relaxation tolerance, every sphere inside the box and on/above the floor.
        let s = &bed.spheres;
        for i in 0..s.len() {
            let a = Vec3::from(s[i].centre);
            assert!(a.z >= 0.5e-6 - 1e-15 && a.x.abs() <= 3.5e-6 + 1e-15);
            for b in &s[i + 1..] {
                let dist = (a - Vec3::from(b.centre)).length();
                assert!(dist > 1e-6 * (1.0 - 2e-3), "{i}: {a:?} {:?} {dist}", b.centre);
            }
        }
        // Settled without overlaps, the spheres form a loose random packing: solid fraction below the
        // random-close-packing 0.64 and above 0.35 (a small box with walls packs looser than the bulk 0.55–0.6).
        let phi = s.len() as f64 * std::f64::consts::PI / 6.0 * 1e-18 / (8e-6 * 8e-6 * bed.top);
        assert!(phi > 0.35 && phi < 0.64, "{phi}");
    }
}
