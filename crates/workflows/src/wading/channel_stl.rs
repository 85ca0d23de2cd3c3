//! A wading channel read from a multi-solid ASCII STL file (`[channel] file = "…"`).
//!
//! Coordinates as for the generated channel: x along the channel (the direction of travel), y across,
//! z up. Every solid whose name starts with `road` (`road`, `road_ramp_in`, …) is the road the wheels
//! roll on; every other solid is a wall of the channel (side walls, end walls). All solids become walls
//! of the SPH scene. The water fills the channel to `water_depth_m` above the road's lowest point; the
//! still water's extent along x, the end of the pool floor and the centre line across are found from the
//! road's height along the centre line, by casting rays straight down onto the road's triangles.
//!
//! Checks: every wall must rise above the still water surface — from the file alone a wall that holds
//! the water cannot be told from one the water would flow over, so a solid the water covers (a low kerb,
//! an obstacle on the pool floor) is refused as a wall; it belongs to the road (a solid named `road_…`:
//! the wheels climb it where they meet it, and it is still a wall of the scene). The road must lie under
//! the whole centre line from its start to its end (else the water would run out through the gap and
//! the pool search would read the gap as dry ground), and rise above the water at both ends.

use super::bisect::bisect;
use super::channel::Road;
use super::parts::{read_parts, NamedPart};
use spatter_core::mesh::TriMesh;
use spatter_core::tri_bvh::TriBvh;
use spatter_core::Vec3;
use std::path::Path;

/// Samples of the road's height along the centre line.
const PROFILE_SAMPLES: usize = 4000;

/// Height above the lowest centre-line road point within which the road counts as pool floor \[m\].
pub const FLOOR_TOLERANCE: f64 = 1e-3;

/// Why a channel file cannot be used: the `[channel]` key it concerns (`file` or `water_depth_m`) and a
/// sentence naming the file.
#[derive(Clone, Debug, PartialEq)]
pub struct ChannelFileError {
    pub key: &'static str,
    pub message: String,
}

fn file_err(message: String) -> ChannelFileError {
    ChannelFileError { key: "file", message }
}

/// A channel read from a file, with the still water's extent.
#[derive(Clone, Debug)]
pub struct StlChannel {
    /// The file it was read from.
    pub file: std::path::PathBuf,
    /// Every solid of the file and whether it is road.
    pub solids: Vec<(NamedPart, bool)>,
    road: TriMesh,
    bvh: TriBvh,
    /// Lowest point of the road \[m\]: the pool floor the water depth is measured from.
    pub floor_z: f64,
    /// Height of the still water surface \[m\].
    pub water_z: f64,
    /// Water depth over the road's lowest point \[m\] (`water_depth_m`).
    pub water_depth: f64,
    /// The road's extent across, `(y_min, y_max)` \[m\]; its middle is the centre line.
    pub y_range: (f64, f64),
    /// The road's extent along, `(x_min, x_max)` \[m\].
    pub x_range: (f64, f64),
    /// Where the still water surface meets the road along the centre line, `(x_in, x_out)` \[m\].
    pub waterline: (f64, f64),
    /// The last centre-line point of the pool floor (road within [`FLOOR_TOLERANCE`] of its lowest
    /// centre-line height) \[m\].
    pub pool_end_x: f64,
    /// The lowest centre-line road point's x \[m\] (where the pool fill starts).
    pub deepest_x: f64,
    /// Highest point of every solid \[m\].
    pub top_z: f64,
}

impl StlChannel {
    /// Reads `path` (an ASCII STL with named solids) and fills it to `water_depth` \[m\] above the road's
    /// lowest point. Errors name the file and the reason: no file, no solid, a solid without triangles,
    /// no road solid, no wall solid, water that would run over a wall or out over the road's ends, a
    /// stretch of the centre line without road.
    pub fn read(path: &Path, water_depth: f64) -> Result<Self, ChannelFileError> {
        let parts = read_parts(path, 1.0).map_err(|e| file_err(e.to_string()))?;
        let is_road = |n: &str| n.starts_with("road");
        let names: Vec<&str> = parts.iter().map(|p| p.name.as_str()).collect();
        if !parts.iter().any(|p| is_road(&p.name)) {
            return Err(file_err(format!(
                "{}: no road solid (its solids are: {}); name the road's solid `road` (or `road_…`) and the \
                 walls anything else, in an ASCII STL (`solid road … endsolid road`)",
                path.display(),
                names.join(", ")
            )));
        }
        if parts.iter().all(|p| is_road(&p.name)) {
            return Err(file_err(format!(
                "{}: no wall solid (its solids are: {}); the water needs side walls: add solids named e.g. \
                 `wall_left` and `wall_right`",
                path.display(),
                names.join(", ")
            )));
        }
        let soup: Vec<Vec3> = parts
            .iter()
            .filter(|p| is_road(&p.name))
            .flat_map(|p| (0..p.mesh.triangles.len()).flat_map(|t| p.mesh.corners(t)))
            .collect();
        let road = TriMesh::from_triangle_soup(&soup);
        let bvh = TriBvh::build(&road);
        let rb = road.bounds();
        let floor_z = rb.min.z;
        let water_z = floor_z + water_depth;
        let top_z = parts.iter().map(|p| p.mesh.bounds().max.z).fold(f64::NEG_INFINITY, f64::max);
        let solids: Vec<(NamedPart, bool)> =
            parts.into_iter().map(|p| (p.clone(), is_road(&p.name))).collect();
        for (p, road) in &solids {
            let top = p.mesh.bounds().max.z;
            if !road && top <= water_z {
                return Err(ChannelFileError {
                    key: "water_depth_m",
                    message: format!(
                        "water_depth_m = {water_depth} m puts the water surface at z = {water_z:.4} m (above the road's \
                         lowest point z = {floor_z} m), over the top of wall `{}` (z = {top} m) of {}: the water \
                         would run out; lower it or raise the wall (a kerb or obstacle the water may cover \
                         belongs to the road: name its solid `road_…`)",
                        p.name,
                        path.display()
                    ),
                });
            }
        }
        let mut ch = StlChannel {
            file: path.to_owned(),
            solids,
            road,
            bvh,
            floor_z,
            water_z,
            water_depth,
            y_range: (rb.min.y, rb.max.y),
            x_range: (rb.min.x, rb.max.x),
            waterline: (0.0, 0.0),
            pool_end_x: 0.0,
            deepest_x: 0.0,
            top_z,
        };
        ch.find_pool(path, water_depth)?;
        Ok(ch)
    }

    /// Middle of the road across \[m\].
    pub fn y_mid(&self) -> f64 {
        0.5 * (self.y_range.0 + self.y_range.1)
    }

    /// Height of the road's top surface at `(x, y)` \[m\], `None` where no road lies under the point: the
    /// highest crossing of the vertical line with a road triangle, on that triangle's plane (exact on
    /// level triangles).
    pub fn road_z(&self, x: f64, y: f64) -> Option<f64> {
        let b = self.bvh.bounds();
        let a = Vec3::new(x, y, b.max.z + 1.0);
        let e = Vec3::new(x, y, b.min.z - 1.0);
        let (_, t) = self.bvh.segment_first_hit(&self.road, a, e)?;
        let [p, q, r] = self.road.corners(t as usize);
        let n = (q - p).cross(r - p);
        if n.z == 0.0 {
            return Some(p.z.max(q.z).max(r.z));
        }
        Some(p.z - (n.x * (x - p.x) + n.y * (y - p.y)) / n.z)
    }

    /// Along the centre line: where the water surface meets the road, the deepest point and the end of
    /// the pool floor. The road must lie under the whole centre line (a gap is named by
    /// [`Self::check_gaps`]), rise above the water at both ends (else the water would run out there), and
    /// the water must reach the centre line.
    fn find_pool(&mut self, path: &Path, depth: f64) -> Result<(), ChannelFileError> {
        let y = self.y_mid();
        let (x0, x1) = self.x_range;
        let mut xs: Vec<f64> =
            (0..=PROFILE_SAMPLES).map(|i| x0 + (x1 - x0) * i as f64 / PROFILE_SAMPLES as f64).collect();
        // x0 + (x1 − x0) can round past x1.
        xs[PROFILE_SAMPLES] = x1;
        let zs: Vec<Option<f64>> = xs.iter().map(|&x| self.road_z(x, y)).collect();
        self.check_gaps(path, &xs, &zs)?;
        let wet = |z: Option<f64>| z.is_some_and(|z| z < self.water_z);
        let runs_out = |end: &str, x: f64, z: Option<f64>| {
            ChannelFileError {
            key: "water_depth_m",
            message: format!(
                "water_depth_m = {depth} m puts the water surface at z = {:.4} m, above the road at its {end} \
                 (x = {x} m, z = {}) on the centre line y = {y} m of {}: the water would run out of the channel; \
                 lower it or make the road rise above the water at both ends",
                self.water_z,
                z.map_or("no road".to_owned(), |z| format!("{z} m")),
                path.display()
            ),
        }
        };
        if wet(zs[0]) {
            return Err(runs_out("start", xs[0], zs[0]));
        }
        if wet(zs[PROFILE_SAMPLES]) {
            return Err(runs_out("end", xs[PROFILE_SAMPLES], zs[PROFILE_SAMPLES]));
        }
        let (Some(first), Some(last)) = (zs.iter().position(|&z| wet(z)), zs.iter().rposition(|&z| wet(z)))
        else {
            return Err(ChannelFileError {
                key: "water_depth_m",
                message: format!(
                    "the water ({depth} m over the road's lowest point z = {} m) does not reach the centre line \
                     y = {y} m of {}'s road anywhere: deepen the water or lower the road there",
                    self.floor_z,
                    path.display()
                ),
            });
        };
        let above = |x: f64| self.road_z(x, y).is_none_or(|z| z >= self.water_z);
        let x_in = bisect(xs[first - 1], xs[first], above).1;
        let x_out = bisect(xs[last + 1], xs[last], above).1;
        let (k_deep, z_deep) = zs
            .iter()
            .enumerate()
            .filter_map(|(k, z)| z.map(|z| (k, z)))
            .fold((0, f64::INFINITY), |b, (k, z)| if z < b.1 { (k, z) } else { b });
        let floor = |x: f64| self.road_z(x, y).is_some_and(|z| z <= z_deep + FLOOR_TOLERANCE);
        let k_end = (k_deep..=last).rev().find(|&k| floor(xs[k])).unwrap_or(k_deep);
        let end = bisect(xs[(k_end + 1).min(PROFILE_SAMPLES)], xs[k_end], |x| !floor(x)).1;
        self.waterline = (x_in, x_out);
        self.deepest_x = xs[k_deep];
        self.pool_end_x = end;
        Ok(())
    }
}

impl StlChannel {
    /// The first stretch of the centre line (samples `xs`, road heights `zs`) without road under it, as
    /// an error naming the file and where it starts and ends (each edge refined by bisection). A road
    /// that stops short of the road's x extent on the centre line (a wider apron elsewhere sets that
    /// extent) is such a stretch too. Gaps narrower than the sampling (1/4000 of the road's length) are
    /// not seen.
    fn check_gaps(&self, path: &Path, xs: &[f64], zs: &[Option<f64>]) -> Result<(), ChannelFileError> {
        // The end samples lie exactly on the road's end edges, where a ray may miss the triangles by
        // rounding: a single missing sample at an end is no gap (narrower than one sample, like any gap
        // this check cannot see).
        let n = zs.len();
        let edge_miss =
            |k: usize| (k == 0 && n > 1 && zs[1].is_some()) || (k + 1 == n && n > 1 && zs[n - 2].is_some());
        let Some(k) = (0..n).position(|k| zs[k].is_none() && !edge_miss(k)) else {
            return Ok(());
        };
        let y = self.y_mid();
        let no_road = |x: f64| self.road_z(x, y).is_none();
        let from = if k == 0 { xs[0] } else { bisect(xs[k], xs[k - 1], no_road).0 };
        let to = match zs[k..].iter().position(Option::is_some) {
            Some(j) => bisect(xs[k + j - 1], xs[k + j], no_road).0,
            None => xs[xs.len() - 1],
        };
        Err(file_err(format!(
            "{}: no road under the centre line y = {y} m from x = {from:.3} m to x = {to:.3} m (the road \
             solids reach from x = {} m to {} m): the water would run out through the gap and the wheels \
             would have nothing to roll on; close the road along the centre line from its start to its end",
            path.display(),
            self.x_range.0,
            self.x_range.1
        )))
    }
}

impl Road for StlChannel {
    /// The wheel is a disc of radius `r` standing on the road in the vertical plane along `heading`: the
    /// axle is as high as the highest of road(s) + √(r² − s²) over the points s ∈ [−r, r] of the disc's
    /// footprint line (33 samples, then a golden-section search around the best one, to 10⁻¹² r).
    /// `-∞` where no road lies under the footprint.
    fn axle_height(&self, x: f64, y: f64, r: f64, heading: f64) -> f64 {
        let (sh, ch) = heading.sin_cos();
        let f = |s: f64| match self.road_z(x + s * ch, y + s * sh) {
            Some(z) => z + (r * r - s * s).max(0.0).sqrt(),
            None => f64::NEG_INFINITY,
        };
        const N: usize = 32;
        let ds = 2.0 * r / N as f64;
        let (mut best_s, mut best) = (0.0, f(0.0));
        for i in 0..=N {
            let s = -r + i as f64 * ds;
            let v = f(s);
            if v > best {
                (best_s, best) = (s, v);
            }
        }
        if best == f64::NEG_INFINITY {
            return best;
        }
        // Golden-section search for the maximum on [best_s − ds, best_s + ds].
        let g = 0.5 * (5f64.sqrt() - 1.0);
        let (mut a, mut b) = ((best_s - ds).max(-r), (best_s + ds).min(r));
        let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
        let (mut fc, mut fd) = (f(c), f(d));
        while b - a > 1e-12 * r {
            if fc > fd {
                b = d;
                (d, fd) = (c, fc);
                c = b - g * (b - a);
                fc = f(c);
            } else {
                a = c;
                (c, fc) = (d, fd);
                d = a + g * (b - a);
                fd = f(d);
            }
        }
        best.max(fc).max(fd)
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::wading::channel::tests::channel;
    use crate::wading::channel::ChannelSpec;
    use crate::wading::geometry::{road_mesh, side_walls_mesh, write_stl};

    /// Writes the generated channel `c` as one multi-solid STL (`road`, `walls`) at `path`.
    pub(crate) fn write_channel_file(path: &Path, c: &ChannelSpec) {
        let dir = path.parent().unwrap();
        let (a, b) = (dir.join("road_part.stl"), dir.join("walls_part.stl"));
        write_stl(&a, "road", &road_mesh(c)).unwrap();
        write_stl(&b, "walls", &side_walls_mesh(c)).unwrap();
        let text = std::fs::read_to_string(&a).unwrap() + &std::fs::read_to_string(&b).unwrap();
        std::fs::write(path, text).unwrap();
    }

    /// The generated test channel written to a file and read back: the same floor, water surface and
    /// waterline (to 10⁻⁹ m, the bisection on the ray-cast profile), the pool's end within
    /// [`FLOOR_TOLERANCE`] / slope (the exit ramp rises 0.5 m over 3 m) of the generated one, the road's
    /// height at every point, and the same axle heights as the analytic profile
    /// (`ChannelSpec::axle_z`: flat, on a ramp, over a kink) to 10⁻⁹ m.
    #[test]
    fn a_file_of_the_generated_channel_reads_as_it() {
        let dir = tempfile::tempdir().unwrap();
        let c = channel();
        let f = dir.path().join("channel.stl");
        write_channel_file(&f, &c);
        let s = StlChannel::read(&f, c.water_depth_m).unwrap();
        assert_eq!(s.floor_z, -c.pool_depth_m);
        assert_eq!(s.water_z, c.water_z());
        assert_eq!((s.x_range, s.y_range), ((0.0, c.length()), (-2.0, 2.0)));
        let (a, b) = c.waterline();
        assert!((s.waterline.0 - a).abs() < 1e-9 && (s.waterline.1 - b).abs() < 1e-9, "{:?}", s.waterline);
        let end_tol = FLOOR_TOLERANCE / (0.5 / 3.0) + 1e-9;
        assert!(
            s.pool_end_x >= c.pool_end_x() && s.pool_end_x - c.pool_end_x() <= end_tol,
            "pool end {} vs {}",
            s.pool_end_x,
            c.pool_end_x()
        );
        assert_eq!(
            s.solids.iter().map(|(p, r)| (p.name.as_str(), *r)).collect::<Vec<_>>(),
            [("road", true), ("walls", false)]
        );
        for i in 0..=90 {
            let x = 0.2 * i as f64;
            for y in [-1.9, 0.0, 1.3] {
                let z = s.road_z(x, y).unwrap();
                assert!((z - c.road_z(x)).abs() < 1e-12, "road at ({x}, {y}): {z} vs {}", c.road_z(x));
            }
            for r in [0.3, 0.5] {
                let (zs, zc) = (s.axle_height(x, 0.4, r, 0.0), c.axle_z(x, r));
                assert!((zs - zc).abs() < 1e-9, "axle of radius {r} at x = {x}: {zs} vs {zc}");
            }
        }
        assert!(s.road_z(-0.1, 0.0).is_none() && s.road_z(3.0, 2.1).is_none());
    }

    /// Triangles of road strips across y ∈ [−2, 2] m along each profile `(x, z)` (corners joined by
    /// straight pieces), facing up.
    fn road_strips(profiles: &[&[(f64, f64)]]) -> Vec<Vec3> {
        let mut soup = Vec::new();
        for prof in profiles {
            for w in prof.windows(2) {
                let ((x0, z0), (x1, z1)) = (w[0], w[1]);
                let (a, b) = (Vec3::new(x0, -2.0, z0), Vec3::new(x1, -2.0, z1));
                let (c, d) = (Vec3::new(x1, 2.0, z1), Vec3::new(x0, 2.0, z0));
                soup.extend([a, b, c, a, c, d]);
            }
        }
        soup
    }

    /// Writes a channel file of the road triangles `road` and side walls 1.5 m high at y = ±2 m over
    /// x ∈ [0, 10] m; returns its path.
    fn strip_channel(dir: &Path, road: &[Vec3]) -> std::path::PathBuf {
        let wall = |y: f64| {
            let p = |x: f64, z: f64| Vec3::new(x, y, z);
            let (a, b, c, d) = (p(0.0, 0.0), p(10.0, 0.0), p(10.0, 1.5), p(0.0, 1.5));
            if y > 0.0 {
                [a, b, c, a, c, d]
            } else {
                [a, d, c, a, c, b]
            }
        };
        let walls: Vec<Vec3> = wall(2.0).into_iter().chain(wall(-2.0)).collect();
        let (a, b) = (dir.join("road_part.stl"), dir.join("walls_part.stl"));
        write_stl(&a, "road", &TriMesh::from_triangle_soup(road)).unwrap();
        write_stl(&b, "walls", &TriMesh::from_triangle_soup(&walls)).unwrap();
        let f = dir.join("channel.stl");
        let text = std::fs::read_to_string(&a).unwrap() + &std::fs::read_to_string(&b).unwrap();
        std::fs::write(&f, text).unwrap();
        f
    }

    /// A road with a 1 m gap under the centre line (x = 4 … 5 m) and a road that starts on the centre
    /// line 1 m after its apron at the side: both are refused, naming the file and the stretch without
    /// road (edges to the 3 decimals printed); closing the gap makes the same file read.
    #[test]
    fn a_centre_line_without_road_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let ramp_in: &[(f64, f64)] = &[(0.0, 0.5), (2.0, 0.0), (4.0, 0.0)];
        let ramp_out: &[(f64, f64)] = &[(5.0, 0.0), (8.0, 0.0), (10.0, 0.5)];
        let f = strip_channel(dir.path(), &road_strips(&[ramp_in, ramp_out]));
        let e = StlChannel::read(&f, 0.3).unwrap_err();
        assert_eq!(e.key, "file");
        assert!(
            e.message.contains(
                "channel.stl: no road under the centre line y = 0 m from x = 4.000 m to x = 5.000 m"
            ),
            "{}",
            e.message
        );
        assert!(e.message.contains("the water would run out through the gap"), "{}", e.message);
        let f = strip_channel(dir.path(), &road_strips(&[ramp_in, &[(4.0, 0.0), (5.0, 0.0)], ramp_out]));
        let s = StlChannel::read(&f, 0.3).unwrap();
        assert!(
            (s.waterline.0 - 0.8).abs() < 1e-9 && (s.waterline.1 - 9.2).abs() < 1e-9,
            "{:?}",
            s.waterline
        );
        // On the centre line the road starts at x = 1 m; an apron at the side starts at x = 0.
        let mut road = road_strips(&[&[(1.0, 0.5), (3.0, 0.0), (8.0, 0.0), (10.0, 0.5)]]);
        let p = |x: f64, y: f64| Vec3::new(x, y, 0.5);
        road.extend([p(0.0, 1.0), p(1.0, 1.0), p(1.0, 2.0), p(0.0, 1.0), p(1.0, 2.0), p(0.0, 2.0)]);
        let e = StlChannel::read(&strip_channel(dir.path(), &road), 0.3).unwrap_err();
        assert!(
            e.message.contains("from x = 0.000 m to x = 1.000 m (the road solids reach from x = 0 m"),
            "{}",
            e.message
        );
    }

    /// A ray that misses the road exactly at one of its end edges (rounding) is no gap; two missing
    /// samples at an end, or one inside, are.
    #[test]
    fn a_single_missing_end_sample_is_no_gap() {
        let dir = tempfile::tempdir().unwrap();
        let ramp: &[(f64, f64)] = &[(0.0, 0.5), (2.0, 0.0), (8.0, 0.0), (10.0, 0.5)];
        let f = strip_channel(dir.path(), &road_strips(&[ramp]));
        let s = StlChannel::read(&f, 0.3).unwrap();
        let xs: Vec<f64> = (0..=10).map(f64::from).collect();
        let road = |missing: &[usize]| -> Vec<Option<f64>> {
            (0..=10).map(|k| (!missing.contains(&k)).then_some(0.0)).collect()
        };
        for ok in [&[][..], &[0], &[10], &[0, 10]] {
            assert!(s.check_gaps(&f, &xs, &road(ok)).is_ok(), "{ok:?}");
        }
        for gap in [&[0, 1][..], &[9, 10], &[5]] {
            assert!(s.check_gaps(&f, &xs, &road(gap)).is_err(), "{gap:?}");
        }
    }

    #[test]
    fn channel_files_that_cannot_hold_the_pool_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let c = channel();
        let f = dir.path().join("channel.stl");
        write_channel_file(&f, &c);
        // Walls 1 m above the road, the floor 0.5 m below: 1.6 m of water tops them.
        let e = StlChannel::read(&f, 1.6).unwrap_err();
        assert_eq!(e.key, "water_depth_m");
        assert!(e.message.contains("over the top of wall `walls` (z = 1 m)"), "{}", e.message);
        // 0.6 m over the floor is above the road's ends (z = 0).
        let e = StlChannel::read(&f, 0.6).unwrap_err();
        assert_eq!(e.key, "water_depth_m");
        assert!(e.message.contains("above the road at its start (x = 0 m, z = 0 m)"), "{}", e.message);
        let text = std::fs::read_to_string(&f).unwrap();
        std::fs::write(&f, text.replace("solid road", "solid floor")).unwrap();
        let e = StlChannel::read(&f, 0.3).unwrap_err();
        assert_eq!(e.key, "file");
        assert!(e.message.contains("no road solid (its solids are: floor, walls)"), "{}", e.message);
        std::fs::write(&f, text.replace("solid walls", "solid road_walls")).unwrap();
        let e = StlChannel::read(&f, 0.3).unwrap_err();
        assert!(e.message.contains("no wall solid"), "{}", e.message);
        let e = StlChannel::read(&dir.path().join("none.stl"), 0.3).unwrap_err();
        assert!(e.key == "file" && e.message.contains("none.stl"), "{e:?}");
    }
}
