//! Which grains of a bed feel the flow: the exposure rule.
//!
//! A grain i (centre x_i, radius r_i) is **exposed** unless it is
//!
//! * **covered**: another grain j lies on top of it — their outlines overlap in plan view
//!   (horizontal centre distance < r_i + r_j) and j's centre is more than ½(r_i + r_j) higher (a grain
//!   resting in a pocket on top of i sits about 0.82 d higher, a side neighbour at the same level 0);
//! * **sheltered**: it lies in the lee of a grain j that protrudes above it — j is upwind (0 < (x_i −
//!   x_j)·ê ≤ 2(r_i + r_j), ê the flow direction), in line with it (lateral offset < ½(r_i + r_j)), and
//!   j's top stands more than r_i above i's top;
//! * **buried**: its centre lies more than a largest diameter below the flow's ground plane (such grains
//!   are always covered; the rule skips them without a search).
//!
//! Exposed grains feel the full flow at their own centre height; the others none. Grains of a level top
//! layer are all exposed; a grain sunk in a pocket behind a protruding neighbour, and every grain of the
//! layers below the top, are not. This is a binary shadow model (the flow inside the bed and partial
//! shadowing are not modelled); the bed's flow ground plane (zero-plane displacement) is set so that the
//! top layer's centres sit one radius above it, as for a grain on a wall in the moment balance.

use rayon::prelude::*;
use spatter_core::Vec3;

/// Reusable buffers of the column search.
#[derive(Clone, Debug, Default)]
pub struct ExposureScratch {
    start: Vec<u32>,
    items: Vec<u32>,
}

/// Fills `out[i]` with the exposure of every grain (`active[i]` false: never exposed, e.g. frozen).
/// `dir` is the horizontal flow direction, `z_ground` the flow's ground plane \[m\]. Deterministic and
/// independent of the thread count (each grain's flag depends only on the positions).
pub fn exposure(
    pos: &[Vec3],
    radius: &[f64],
    active: &[bool],
    dir: Vec3,
    z_ground: f64,
    scratch: &mut ExposureScratch,
    out: &mut Vec<bool>,
) {
    let n = pos.len();
    out.clear();
    out.resize(n, false);
    if n == 0 {
        return;
    }
    let r_max = radius.iter().copied().fold(0.0, f64::max);
    let z_min = z_ground - 2.0 * r_max;
    let cand = |i: usize| active[i] && pos[i].z >= z_min;
    // Columns of width 2 r_max over the candidates' footprint.
    let h = 2.0 * r_max;
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for i in (0..n).filter(|&i| cand(i)) {
        x0 = x0.min(pos[i].x);
        y0 = y0.min(pos[i].y);
        x1 = x1.max(pos[i].x);
        y1 = y1.max(pos[i].y);
    }
    if x0 > x1 {
        return;
    }
    let nx = ((x1 - x0) / h).floor() as usize + 1;
    let ny = ((y1 - y0) / h).floor() as usize + 1;
    let cell = |p: Vec3| -> (usize, usize) {
        (
            ((p.x - x0) / h).floor().clamp(0.0, (nx - 1) as f64) as usize,
            ((p.y - y0) / h).floor().clamp(0.0, (ny - 1) as f64) as usize,
        )
    };
    // Counting sort of the candidates by column (ascending index within a column).
    let ExposureScratch { start, items } = scratch;
    start.clear();
    start.resize(nx * ny + 1, 0);
    for i in (0..n).filter(|&i| cand(i)) {
        let (cx, cy) = cell(pos[i]);
        start[cy * nx + cx + 1] += 1;
    }
    for c in 0..nx * ny {
        start[c + 1] += start[c];
    }
    items.clear();
    items.resize(start[nx * ny] as usize, 0);
    let mut fill = start.clone();
    for i in (0..n).filter(|&i| cand(i)) {
        let (cx, cy) = cell(pos[i]);
        let c = cy * nx + cx;
        items[fill[c] as usize] = i as u32;
        fill[c] += 1;
    }
    let (start, items) = (&*start, &*items);
    let dir = Vec3::new(dir.x, dir.y, 0.0).normalize_or(Vec3::X);
    let side = Vec3::new(-dir.y, dir.x, 0.0);
    // Reach: upwind shelter up to 2(r_i + r_j) ≤ 4 r_max = 2 columns.
    out.par_iter_mut().enumerate().for_each(|(i, e)| {
        if !cand(i) {
            return;
        }
        let (xi, ri) = (pos[i], radius[i]);
        let (cx, cy) = cell(xi);
        for gy in cy.saturating_sub(2)..=(cy + 2).min(ny - 1) {
            for gx in cx.saturating_sub(2)..=(cx + 2).min(nx - 1) {
                let c = gy * nx + gx;
                for &j in &items[start[c] as usize..start[c + 1] as usize] {
                    let j = j as usize;
                    if j == i {
                        continue;
                    }
                    let (xj, rj) = (pos[j], radius[j]);
                    let d = xi - xj;
                    let sum = ri + rj;
                    let dh2 = d.x * d.x + d.y * d.y;
                    // Covered from above.
                    if dh2 < sum * sum && xj.z - xi.z > 0.5 * sum {
                        return;
                    }
                    // In the lee of a protruding upwind grain.
                    let s = d.dot(dir);
                    if s > 0.0
                        && s <= 2.0 * sum
                        && d.dot(side).abs() < 0.5 * sum
                        && (xj.z + rj) - (xi.z + ri) > ri
                    {
                        return;
                    }
                }
            }
        }
        *e = true;
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(pos: &[Vec3], r: f64, dir: Vec3) -> Vec<bool> {
        let radius = vec![r; pos.len()];
        let active = vec![true; pos.len()];
        let mut out = Vec::new();
        exposure(pos, &radius, &active, dir, 0.0, &mut ExposureScratch::default(), &mut out);
        out
    }

    #[test]
    fn level_row_is_exposed_a_covered_grain_is_not() {
        // Three touching grains in a row at one level, and a fourth resting on the pocket between the
        // first two (centre √3 r higher, half a diameter along): the two under it are covered. With the
        // flow along +x the third grain lies in the fourth's lee (3 r downwind, its top √3 r lower); with
        // the flow along −x it is upwind and exposed.
        let r = 1.0;
        let pos = [
            Vec3::new(0.0, 0.0, r),
            Vec3::new(2.0, 0.0, r),
            Vec3::new(4.0, 0.0, r),
            Vec3::new(1.0, 0.0, r + 3f64.sqrt() * r),
        ];
        assert_eq!(run(&pos, r, Vec3::X), vec![false, false, false, true]);
        assert_eq!(run(&pos, r, -Vec3::X), vec![false, false, true, true]);
        // Without the fourth grain the level row is exposed everywhere.
        assert_eq!(run(&pos[..3], r, Vec3::X), vec![true, true, true]);
    }

    #[test]
    fn a_low_grain_behind_a_protruding_one_is_sheltered_only_downwind() {
        // Grain 1 sits 2.5 r lower and 2.5 r downwind of grain 0 (their outlines do not overlap in plan
        // view, so it is not covered).
        let r = 1.0;
        let pos = [Vec3::new(0.0, 0.0, 3.0), Vec3::new(2.5, 0.0, 0.5)];
        // Flow along +x: grain 1 is in grain 0's lee (top 4 vs 1.5: more than r higher).
        assert_eq!(run(&pos, r, Vec3::X), vec![true, false]);
        // Flow along −x: grain 0 is downwind of grain 1, which does not protrude; both exposed.
        assert_eq!(run(&pos, r, -Vec3::X), vec![true, true]);
        // Lateral offset of a diameter: not in line, exposed.
        let pos = [Vec3::new(0.0, 0.0, 3.0), Vec3::new(2.5, 2.0, 0.5)];
        assert_eq!(run(&pos, r, Vec3::X), vec![true, true]);
    }
}
