//! Blocked cells: solids inside the grid given as analytic shapes or closed STL/OBJ surfaces.
//!
//! A cell is blocked when its centre lies inside a solid (staircase representation: the wall runs along
//! the faces of blocked cells). A box thinner than the cells (a plate) blocks the one layer of cells that
//! contains its mid-plane, so thin plates never fall between cell centres.

use crate::grid::Grid;
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::mesh::TriMesh;
use spatter_core::tri_bvh::TriBvh;
use spatter_core::Vec3;
use std::path::PathBuf;

/// One solid.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum Solid {
    /// Axis-aligned box (also a plate when thin along one axis).
    Box { min_m: [f64; 3], max_m: [f64; 3] },
    /// Solid cylinder from `a_m` to `b_m`.
    Cylinder { a_m: [f64; 3], b_m: [f64; 3], radius_m: f64 },
    /// Everything farther than `radius_m` from the line through `a_m` and `b_m`: the wall of a pipe whose
    /// bore is the fluid.
    PipeWall { a_m: [f64; 3], b_m: [f64; 3], radius_m: f64 },
    /// An axis-aligned box with a round bore along the line through `a_m` and `b_m`: the bore (closer
    /// than `radius_m` to the line) is fluid. A pipe wall of finite length, or a wall with a round
    /// opening.
    BoxWithBore { min_m: [f64; 3], max_m: [f64; 3], a_m: [f64; 3], b_m: [f64; 3], radius_m: f64 },
    /// A closed triangulated surface (STL or OBJ) scaled by `scale`.
    Mesh {
        file: PathBuf,
        #[serde(default = "one")]
        scale: f64,
    },
}

fn one() -> f64 {
    1.0
}

impl Validate for Solid {
    fn validate(&self, c: &mut Checker) {
        match self {
            Solid::Box { min_m, max_m } | Solid::BoxWithBore { min_m, max_m, .. } => {
                for a in 0..3 {
                    if max_m[a].is_nan() || min_m[a].is_nan() || max_m[a] < min_m[a] {
                        c.fail(
                            "max_m",
                            format!("max_m[{a}] = {} must be ≥ min_m[{a}] = {}", max_m[a], min_m[a]),
                        );
                    }
                }
                if let Solid::BoxWithBore { a_m, b_m, radius_m, .. } = self {
                    c.positive("radius_m", *radius_m);
                    let d = Vec3::from(*b_m) - Vec3::from(*a_m);
                    if d.length().is_nan() || d.length() <= 0.0 {
                        c.fail("b_m", "the axis end points a_m and b_m must differ");
                    }
                }
            }
            Solid::Cylinder { a_m, b_m, radius_m } | Solid::PipeWall { a_m, b_m, radius_m } => {
                c.positive("radius_m", *radius_m);
                let d = Vec3::from(*b_m) - Vec3::from(*a_m);
                if d.length().is_nan() || d.length() <= 0.0 {
                    c.fail("b_m", "the axis end points a_m and b_m must differ");
                }
            }
            Solid::Mesh { file, scale } => {
                c.positive("scale", *scale);
                c.file_exists("file", file);
            }
        }
    }
}

/// Why the solids could not be placed.
#[derive(Debug, thiserror::Error)]
pub enum SolidError {
    #[error(transparent)]
    Mesh(#[from] spatter_core::mesh::MeshError),
    #[error("solid mesh {file}: not closed ({open_edges} edges belong to only one triangle); the inside of an open surface is undefined")]
    NotClosed { file: PathBuf, open_edges: usize },
    #[error("solid mesh {file}: encloses a negative volume ({volume} m³): the triangles are wound inside-out; flip their orientation")]
    InsideOut { file: PathBuf, volume: f64 },
    #[error("solids[{index}]: {source}")]
    At { index: usize, source: Box<SolidError> },
}

/// A point-inside test prepared from a [`Solid`].
enum Inside {
    Box { lo: Vec3, hi: Vec3 },
    Cyl { a: Vec3, axis: Vec3, len: f64, r2: f64, outside: bool },
    BoxWithBore { lo: Vec3, hi: Vec3, a: Vec3, axis: Vec3, r2: f64 },
    Mesh { mesh: Box<TriMesh>, bvh: TriBvh },
}

impl Inside {
    fn new(s: &Solid) -> Result<Self, SolidError> {
        Ok(match s {
            Solid::Box { min_m, max_m } => Inside::Box { lo: (*min_m).into(), hi: (*max_m).into() },
            Solid::Cylinder { a_m, b_m, radius_m } | Solid::PipeWall { a_m, b_m, radius_m } => {
                let a = Vec3::from(*a_m);
                let d = Vec3::from(*b_m) - a;
                Inside::Cyl {
                    a,
                    axis: d / d.length(),
                    len: d.length(),
                    r2: radius_m * radius_m,
                    outside: matches!(s, Solid::PipeWall { .. }),
                }
            }
            Solid::BoxWithBore { min_m, max_m, a_m, b_m, radius_m } => {
                let a = Vec3::from(*a_m);
                Inside::BoxWithBore {
                    lo: (*min_m).into(),
                    hi: (*max_m).into(),
                    a,
                    axis: (Vec3::from(*b_m) - a).normalize(),
                    r2: radius_m * radius_m,
                }
            }
            Solid::Mesh { file, scale } => {
                let mesh = TriMesh::load(file, *scale)?;
                let open_edges = mesh.topology().edge_use_count.iter().filter(|&&n| n != 2).count();
                if open_edges > 0 {
                    return Err(SolidError::NotClosed { file: file.clone(), open_edges });
                }
                let volume = mesh.signed_volume();
                if volume <= 0.0 {
                    return Err(SolidError::InsideOut { file: file.clone(), volume });
                }
                let bvh = TriBvh::build(&mesh);
                Inside::Mesh { mesh: Box::new(mesh), bvh }
            }
        })
    }

    /// Whether the cell with centre `p` and widths `h` is blocked.
    fn blocks(&self, p: Vec3, h: Vec3) -> bool {
        match self {
            Inside::Box { lo, hi } => (0..3).all(|a| {
                let (l, u) = (lo[a], hi[a]);
                if u - l < h[a] {
                    // Thin along this axis: block the layer holding the mid-plane.
                    let m = 0.5 * (l + u);
                    m >= p[a] - 0.5 * h[a] && m < p[a] + 0.5 * h[a]
                } else {
                    p[a] >= l && p[a] <= u
                }
            }),
            Inside::Cyl { a, axis, len, r2, outside } => {
                let d = p - *a;
                let s = d.dot(*axis);
                let rr = (d - s * *axis).length_squared();
                if *outside {
                    rr > *r2
                } else {
                    s >= 0.0 && s <= *len && rr <= *r2
                }
            }
            Inside::BoxWithBore { lo, hi, a, axis, r2 } => {
                let d = p - *a;
                let rr = (d - d.dot(*axis) * *axis).length_squared();
                (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]) && rr > *r2
            }
            Inside::Mesh { mesh, bvh } => bvh.bounds().contains(p) && bvh.contains_point(mesh, p),
        }
    }
}

/// The blocked flag of every padded cell of `grid` (ghost cells are never blocked).
pub fn blocked_cells(grid: &Grid, solids: &[Solid]) -> Result<Vec<bool>, SolidError> {
    let l = grid.layout;
    let mut out = vec![false; l.len()];
    if solids.is_empty() {
        return Ok(out);
    }
    let tests: Vec<Inside> = solids
        .iter()
        .enumerate()
        .map(|(index, s)| Inside::new(s).map_err(|e| SolidError::At { index, source: Box::new(e) }))
        .collect::<Result<_, _>>()?;
    for k in 0..l.n[2] {
        for j in 0..l.n[1] {
            for i in 0..l.n[0] {
                let c = l.cell(i, j, k);
                let q = l.coords(c);
                let p = Vec3::from(grid.centre(q));
                let h = Vec3::new(grid.metric[0].d[q[0]], grid.metric[1].d[q[1]], grid.metric[2].d[q[2]]);
                out[c] = tests.iter().any(|t| t.blocks(p, h));
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pipe_wall_keeps_the_bore_and_a_thin_plate_blocks_one_layer() {
        let g = Grid::uniform_box([-1.0; 3], [1.0; 3], [20, 20, 10]).unwrap();
        let pipe = Solid::PipeWall { a_m: [0.0, 0.0, -1.0], b_m: [0.0, 0.0, 1.0], radius_m: 0.8 };
        let b = blocked_cells(&g, &[pipe]).unwrap();
        let open = (0..b.len()).filter(|&c| g.layout.interior(g.layout.coords(c)) && !b[c]).count();
        // Bore area π 0.8² over cell area 0.01, times 10 layers: 201 ± staircase error.
        let expect = std::f64::consts::PI * 0.64 / 0.01 * 10.0;
        assert!((open as f64 - expect).abs() / expect < 0.05, "{open} vs {expect}");
        // The same bore through a box that ends at z = 0: the upper half of the grid stays open.
        let block = Solid::BoxWithBore {
            min_m: [-2.0, -2.0, -2.0],
            max_m: [2.0, 2.0, 0.0],
            a_m: [0.0, 0.0, -1.0],
            b_m: [0.0, 0.0, 1.0],
            radius_m: 0.8,
        };
        let bb = blocked_cells(&g, &[block]).unwrap();
        for c in 0..b.len() {
            let q = g.layout.coords(c);
            if g.layout.interior(q) {
                let upper = g.centre(q)[2] > 0.0;
                assert_eq!(bb[c], b[c] && !upper, "cell {q:?}");
            }
        }
        let plate = Solid::Box { min_m: [-1.0, -1.0, 0.01], max_m: [1.0, 1.0, 0.02] };
        let b = blocked_cells(&g, &[plate]).unwrap();
        let n: usize = b.iter().filter(|&&x| x).count();
        assert_eq!(n, 400, "one full layer of 20×20 cells");
    }

    #[test]
    fn open_and_inside_out_meshes_are_refused_with_the_file_named() {
        let dir = tempfile::tempdir().unwrap();
        let mut cube = spatter_core::shapes::box_mesh(spatter_core::Aabb::new(Vec3::ZERO, Vec3::ONE));
        let g = Grid::uniform_box([-1.0; 3], [2.0; 3], [6, 6, 6]).unwrap();
        let p = dir.path().join("cube.stl");
        std::fs::write(&p, cube.to_binary_stl()).unwrap();
        let b = blocked_cells(&g, &[Solid::Mesh { file: p.clone(), scale: 1.0 }]).unwrap();
        assert_eq!(b.iter().filter(|&&x| x).count(), 8, "the 2×2×2 cells whose centres lie in the unit cube");
        for t in cube.triangles.iter_mut() {
            t.swap(1, 2);
        }
        std::fs::write(&p, cube.to_binary_stl()).unwrap();
        let e = blocked_cells(&g, &[Solid::Mesh { file: p.clone(), scale: 1.0 }]).unwrap_err().to_string();
        assert!(e.contains("solids[0]") && e.contains("inside-out") && e.contains("cube.stl"), "{e}");
        cube.triangles.pop();
        std::fs::write(&p, cube.to_binary_stl()).unwrap();
        let e = blocked_cells(&g, &[Solid::Mesh { file: p, scale: 1.0 }]).unwrap_err().to_string();
        assert!(e.contains("not closed"), "{e}");
    }
}
