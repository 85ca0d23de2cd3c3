//! Files written by VTK's own writers (python3-vtk9 9.1, the library inside ParaView) in the encodings
//! ParaView uses: `tests/fixtures/vtk/make_fixtures.py`. Each carries U = (1 + x + 2y, 3z − x, 0.5 + y)
//! as Float64 point data, which the imported field must reproduce exactly (linear interpolation on the
//! tetrahedral decomposition; tolerance 1e-12).

use spatter_core::Vec3;
use spatter_flow::field::tetmesh::NONE;
use spatter_flow::field::{FlowField, ImportOptions, ImportedField};
use spatter_io::vtk;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/vtk").join(name)
}

fn lin(p: Vec3) -> Vec3 {
    Vec3::new(1.0 + p.x + 2.0 * p.y, 3.0 * p.z - p.x, 0.5 + p.y)
}

fn check(name: &str, cells: usize, volume: f64) {
    let ds = vtk::read(&fixture(name)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(ds.n_cells(), cells, "{name}");
    let u = ds.point_array("U").unwrap();
    for (i, p) in ds.points.iter().enumerate() {
        assert!((u.vec3(i) - lin(*p)).length() < 1e-12, "{name}: point {i}");
    }
    let cid = ds.cell_array("cell_id").unwrap();
    assert_eq!(cid.values, (0..cells).map(|c| c as f64).collect::<Vec<_>>(), "{name}");
    let f = ImportedField::from_dataset(&ds, &ImportOptions::default()).unwrap();
    let vol: f64 = (0..f.mesh.tets.len()).map(|t| f.mesh.volume(t)).sum();
    // VTK stores points in single precision: coordinates like 0.1 carry a 1e-8 relative error.
    assert!((vol - volume).abs() < 1e-6 * volume, "{name}: volume {vol} vs {volume}");
    // Random points: every one inside the mesh gets the linear field.
    let b = f.mesh.bounds();
    let mut s = 11u64;
    let mut hint = NONE;
    let mut inside = 0;
    for _ in 0..3000 {
        let mut r = || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64
        };
        let x = b.min + b.extent() * Vec3::new(r(), r(), r());
        if let Some(smp) = f.sample(x, 0.0, &mut hint, false) {
            if f.mesh.locate(x, &mut NONE.clone()).is_some() {
                inside += 1;
                assert!((smp.u - lin(x)).length() < 1e-12, "{name} at {x}: {} vs {}", smp.u, lin(x));
            }
        }
    }
    assert!(inside > 500, "{name}: {inside}");
}

#[test]
fn image_data_zlib_appended() {
    check("grid.vti", 3 * 2 * 2, 1.5 * 0.8 * 0.6);
}

#[test]
fn rectilinear_grid_zlib_inline_base64() {
    check("grid.vtr", 2 * 3, 0.7 * 0.6 * 0.6);
}

#[test]
fn structured_grid_raw_appended_uint64_header() {
    // Sheared block: volume of the parallelepiped spanned by (1, 0, 0.1), (0.2, 1, 0), (0, 0, 1).
    check("grid.vts", 8, 1.0 * 1.0 * 1.0 - 0.0);
}

#[test]
fn unstructured_hexahedra_wedge_polyhedron_zlib_ascii_and_legacy() {
    // Two unit hexahedra, a wedge of volume ½ and a unit cube written as a polyhedron.
    for name in ["mixed.vtu", "mixed_ascii.vtu", "mixed_legacy.vtk"] {
        check(name, 4, 3.5);
    }
}
