//! Sensor patches selected by a box: the triangles of a vehicle part whose centroid lies in the box become
//! a part of their own (same motion and report group as the part they were cut from), so their wet area is
//! followed over time like any part's and their map is drawn on its own.

use super::parts::NamedPart;
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;

/// A sensor patch cut out of a vehicle part by an axis-aligned box (`[[sensor_boxes]]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorBox {
    /// Name of the patch: a new part in the maps, tables and `sensors.csv`.
    pub name: String,
    /// The vehicle part the patch is cut from (not a wheel).
    pub part: String,
    /// Lowest corner of the box, in the part files' coordinates after `scale` \[m\].
    pub min_m: Vec3,
    /// Highest corner of the box \[m\].
    pub max_m: Vec3,
}

impl Validate for SensorBox {
    fn validate(&self, c: &mut Checker) {
        if self.name.trim().is_empty() {
            c.fail("name", "name = \"\": give the patch a name");
        }
        let (lo, hi) = (self.min_m, self.max_m);
        if !(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z) {
            c.fail(
                "max_m",
                format!(
                    "max_m = [{}, {}, {}] must be above min_m = [{}, {}, {}] in x, y and z",
                    hi.x, hi.y, hi.z, lo.x, lo.y, lo.z
                ),
            );
        }
    }
}

/// Why a box cannot cut its patch (the message names no key; the caller adds it).
#[derive(Debug, PartialEq)]
pub struct CutError {
    /// The key the error belongs to, relative to the box (`part`, `min_m`, `name`).
    pub key: &'static str,
    pub message: String,
}

/// Cuts the patch of `b` out of `parts` (in place: the part keeps its other triangles, the patch is
/// appended after it). Returns the index of the part cut from. Wheels (`wheel_names`) cannot be cut: a
/// patch would lose the wheel's spin.
pub fn cut(parts: &mut Vec<NamedPart>, b: &SensorBox, wheel_names: &[&str]) -> Result<usize, CutError> {
    let names = || parts.iter().map(|p| p.name.as_str()).collect::<Vec<_>>().join(", ");
    if parts.iter().any(|p| p.name == b.name) {
        return Err(CutError {
            key: "name",
            message: format!("name = \"{}\" is already a part's name; the parts are: {}", b.name, names()),
        });
    }
    let Some(k) = parts.iter().position(|p| p.name == b.part) else {
        return Err(CutError {
            key: "part",
            message: format!("part = \"{}\" names no vehicle part; the parts are: {}", b.part, names()),
        });
    };
    if wheel_names.contains(&b.part.as_str()) {
        return Err(CutError {
            key: "part",
            message: format!(
                "part = \"{}\" is a wheel; a patch cut from it would not spin with it. Follow the whole wheel \
                 in `sensors` instead",
                b.part
            ),
        });
    }
    let mesh = &parts[k].mesh;
    let inside = |t: usize| {
        let c = mesh.centroid(t);
        c.cmpge(b.min_m).all() && c.cmple(b.max_m).all()
    };
    let (mut patch, mut rest) = (Vec::new(), Vec::new());
    for t in 0..mesh.triangles.len() {
        let soup = if inside(t) { &mut patch } else { &mut rest };
        soup.extend(mesh.corners(t));
    }
    let bounds = mesh.bounds();
    let span = format!(
        "the part spans [{:.3}, {:.3}, {:.3}] to [{:.3}, {:.3}, {:.3}] m",
        bounds.min.x, bounds.min.y, bounds.min.z, bounds.max.x, bounds.max.y, bounds.max.z
    );
    if patch.is_empty() {
        return Err(CutError {
            key: "min_m",
            message: format!("no triangle of part \"{}\" has its centroid in the box; {span}", b.part),
        });
    }
    if rest.is_empty() {
        return Err(CutError {
            key: "min_m",
            message: format!(
                "the box holds every triangle of part \"{}\" ({span}); name the part in `sensors` instead",
                b.part
            ),
        });
    }
    parts[k].mesh = TriMesh::from_triangle_soup(&rest);
    parts.push(NamedPart { name: b.name.clone(), mesh: TriMesh::from_triangle_soup(&patch) });
    Ok(k)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plate() -> NamedPart {
        // A 1 m × 1 m plate in z = 0 of 4 × 4 squares (32 triangles).
        NamedPart { name: "cab".into(), mesh: TriMesh::rectangle(1.0, 1.0, 0.0, 4, 4) }
    }

    fn boxed(min: [f64; 3], max: [f64; 3]) -> SensorBox {
        SensorBox {
            name: "lens".into(),
            part: "cab".into(),
            min_m: Vec3::from_array(min),
            max_m: Vec3::from_array(max),
        }
    }

    /// The triangles whose centroid lies in the box move to the patch; area is conserved.
    #[test]
    fn a_box_cuts_the_triangles_whose_centroid_it_holds() {
        let mut parts = vec![plate()];
        let area = parts[0].mesh.total_area();
        let b0 = parts[0].mesh.bounds();
        // One quarter of the plate: the box around its lowest 2 × 2 squares (8 triangles).
        let lo = [b0.min.x - 0.01, b0.min.y - 0.01, -0.1];
        let hi = [b0.min.x + 0.5, b0.min.y + 0.5, 0.1];
        assert_eq!(cut(&mut parts, &boxed(lo, hi), &[]), Ok(0));
        assert_eq!(parts.len(), 2);
        assert_eq!((parts[0].mesh.triangles.len(), parts[1].mesh.triangles.len()), (24, 8));
        assert!((parts[1].mesh.total_area() - 0.25 * area).abs() < 1e-12);
        assert!((parts[0].mesh.total_area() + parts[1].mesh.total_area() - area).abs() < 1e-12);
        assert_eq!(parts[1].name, "lens");
    }

    #[test]
    fn empty_full_unknown_wheel_and_duplicate_boxes_are_named() {
        let mut parts = vec![plate()];
        let e = cut(&mut parts, &boxed([5.0, 5.0, 5.0], [6.0, 6.0, 6.0]), &[]).unwrap_err();
        assert!(e.key == "min_m" && e.message.starts_with("no triangle of part \"cab\""), "{e:?}");
        let e = cut(&mut parts, &boxed([-9.0; 3], [9.0; 3]), &[]).unwrap_err();
        assert!(e.message.contains("every triangle"), "{e:?}");
        let mut b = boxed([-9.0; 3], [9.0; 3]);
        b.part = "roof".into();
        let e = cut(&mut parts, &b, &[]).unwrap_err();
        assert_eq!(
            (e.key, e.message.as_str()),
            ("part", "part = \"roof\" names no vehicle part; the parts are: cab")
        );
        let e = cut(&mut parts, &boxed([-9.0; 3], [9.0; 3]), &["cab"]).unwrap_err();
        assert!(e.message.contains("is a wheel"), "{e:?}");
        b.name = "cab".into();
        let e = cut(&mut parts, &b, &[]).unwrap_err();
        assert_eq!(e.key, "name");
        assert_eq!(parts.len(), 1, "nothing cut on an error");
    }
}
