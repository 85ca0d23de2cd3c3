//! The OpenFOAM wedge case (`tests/fixtures/openfoam/wedge`, made by `scripts/openfoam/run_wedge.sh`
//! with OpenFOAM v1912: snappyHexMesh hex/prism/polyhedron mesh, simpleFoam k–ε, 10 m/s): both exports
//! read, agree with each other, decompose into the right volume, and sample like flow around the wedge.

use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;
use spatter_flow::field::tetmesh::NONE;
use spatter_flow::field::{FlowField, ImportOptions, ImportedField, Interpolation};
use spatter_io::vtk;
use std::path::PathBuf;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/fixtures/openfoam/wedge").join(name)
}

#[test]
fn xml_and_legacy_exports_hold_the_same_mesh_and_data() {
    let xml = vtk::read(&fixture("internal.vtu")).unwrap_or_else(|e| panic!("{e}"));
    let legacy = vtk::read(&fixture("internal.vtk")).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(xml.points.len(), legacy.points.len());
    assert_eq!(xml.n_cells(), legacy.n_cells());
    assert_eq!(xml.cell_types, legacy.cell_types);
    assert!(xml.cell_types.contains(&42), "the snapped mesh has polyhedra");
    // Same points and velocities (both single precision).
    for (a, b) in xml.points.iter().zip(&legacy.points) {
        assert!((*a - *b).length() < 1e-6);
    }
    let (ua, ub) = (xml.point_array("U").unwrap(), legacy.point_array("U").unwrap());
    for i in 0..ua.len() {
        assert!((ua.vec3(i) - ub.vec3(i)).length() < 1e-5);
    }
    assert!(legacy.point_array("U").is_some() && legacy.cell_array("U").is_some());
    for name in ["U", "k", "epsilon"] {
        assert!(xml.cell_array(name).is_some() && xml.point_array(name).is_some(), "{name}");
    }
}

fn field(mode: Interpolation) -> ImportedField {
    let opts = ImportOptions { interpolation: mode, ..Default::default() };
    ImportedField::load(&[(0.0, fixture("internal.vtu"))], &opts).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn decomposition_fills_the_fluid_volume_and_the_flow_is_sensible() {
    // checkMesh (checkMesh.txt): "Total volume = 1.2764006". The snapped boundary faces are not planar;
    // OpenFOAM splits them about their centres, we fan-split them (2 triangles per quad), which changes
    // the enclosed volume by about 2e-5 m³: tolerance 1e-4 relative. The wedge STL encloses 3.6e-3 m³.
    let wedge = TriMesh::load(&fixture("wedge.stl"), 1.0).unwrap();
    assert!((wedge.signed_volume() - 0.5 * 0.3 * 0.12 * 0.2).abs() < 1e-12);
    for mode in [Interpolation::Point, Interpolation::CellPoint, Interpolation::Cell] {
        let f = field(mode);
        let vol: f64 = (0..f.mesh.tets.len()).map(|t| f.mesh.volume(t)).sum();
        assert!((vol / 1.2764006 - 1.0).abs() < 1e-4, "{mode:?}: {vol}");
        assert!(f.has_turbulence());
        let mut h = NONE;
        // Free stream upstream: ≈ 10 m/s along x, k ≈ 0.015 m²/s².
        let s = f.sample(Vec3::new(-0.5, 0.0, 0.06), 0.0, &mut h, true).unwrap();
        assert!((s.u - Vec3::new(10.0, 0.0, 0.0)).length() < 0.5, "{mode:?} {}", s.u);
        assert!(s.k > 0.005 && s.k < 0.05, "{}", s.k);
        // Inside the wedge: no fluid.
        assert!(f.sample(Vec3::new(0.25, 0.0, 0.03), 0.0, &mut NONE.clone(), false).is_none());
        // Flow over the slope is deflected upwards; behind the rear face it recirculates (u_x < 0
        // somewhere in the near wake).
        let s = f.sample(Vec3::new(0.15, 0.0, 0.09), 0.0, &mut h, false).unwrap();
        assert!(s.u.z > 1.0, "{mode:?}: {}", s.u);
        let reverse = (1..20).any(|i| {
            let x = Vec3::new(0.3 + 0.01 * i as f64, 0.0, 0.03);
            f.sample(x, 0.0, &mut h, false).is_some_and(|s| s.u.x < 0.0)
        });
        assert!(reverse, "{mode:?}: no recirculation behind the rear face");
    }
}
