//! The generated geometry of a gravelometer: accelerating pipe, protection box, inclined panel with its
//! strips, and the clamp, as triangle meshes in one frame.
//!
//! Frame: x along the pipe axis in the direction of flight, z up, y across. The pipe runs from
//! x = −length to its exit at x = 0; the panel centre sits on the axis at x = `distance_m`. The panel is
//! inclined by `angle` to the horizontal and leans away from the pipe: its "up" direction along the long
//! edge is u = (cos θ, 0, sin θ), its width direction w = (0, 1, 0) and its front normal n = u × w =
//! (−sin θ, 0, cos θ) faces the pipe. A stone flying along +x meets the panel at the impingement angle θ
//! (90° for the upright SAE panel, 54° for DIN).

use spatter_core::mesh::TriMesh;
use spatter_core::{Aabb, Vec3};

/// Dimensions of the generated parts \[m\], angle \[deg\].
#[derive(Clone, Debug, PartialEq)]
pub struct Dimensions {
    pub pipe_diameter: f64,
    pub pipe_length: f64,
    pub panel_width: f64,
    pub panel_length: f64,
    pub panel_angle_deg: f64,
    pub panel_distance: f64,
    pub triangle_size: f64,
    pub strips: usize,
    pub clamp_bar_width: f64,
    pub clamp_thickness: f64,
    pub box_margin: f64,
}

/// The panel's frame: centre and unit directions (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PanelFrame {
    pub center: Vec3,
    /// Up along the long (inclined) edge.
    pub up: Vec3,
    /// Across the panel (= +y).
    pub across: Vec3,
    /// Front normal, towards the pipe.
    pub normal: Vec3,
    pub width: f64,
    pub length: f64,
}

impl PanelFrame {
    pub fn new(d: &Dimensions) -> Self {
        let t = d.panel_angle_deg.to_radians();
        let up = Vec3::new(t.cos(), 0.0, t.sin());
        let across = Vec3::Y;
        PanelFrame {
            center: Vec3::new(d.panel_distance, 0.0, 0.0),
            up,
            across,
            normal: up.cross(across),
            width: d.panel_width,
            length: d.panel_length,
        }
    }

    /// Panel coordinates of a point: (across from the centre line, along the long edge from the
    /// bottom edge) \[m\]; the bottom edge is at 0, the top at `length`.
    pub fn coords(&self, p: Vec3) -> (f64, f64) {
        let r = p - self.center;
        (r.dot(self.across), r.dot(self.up) + 0.5 * self.length)
    }

    /// Strip (1 = top … `strips` = bottom) of a point at height `s` along the long edge from the bottom.
    pub fn strip_of(&self, s: f64, strips: usize) -> usize {
        let from_top = (self.length - s) / self.length * strips as f64;
        (from_top.floor().max(0.0) as usize).min(strips - 1) + 1
    }
}

/// Rows of triangles along the panel's long edge: `length / triangle_size` rounded up, then up to a
/// multiple of the strip count so that strip boundaries run along triangle edges.
pub fn panel_rows(length: f64, triangle_size: f64, strips: usize) -> usize {
    let rows = (length / triangle_size).ceil().max(1.0) as usize;
    rows.div_ceil(strips) * strips
}

/// Columns of triangles across the panel.
pub fn panel_columns(width: f64, triangle_size: f64) -> usize {
    (width / triangle_size).ceil().max(1.0) as usize
}

/// The panel as `rows × columns` rectangles of two triangles each, normals towards the pipe, and the
/// strip (1-based, from the top) of every triangle.
pub fn panel(d: &Dimensions) -> (TriMesh, Vec<usize>) {
    let f = PanelFrame::new(d);
    let rows = panel_rows(d.panel_length, d.triangle_size, d.strips);
    let cols = panel_columns(d.panel_width, d.triangle_size);
    let mut vertices = Vec::with_capacity((rows + 1) * (cols + 1));
    for i in 0..=rows {
        let s = d.panel_length * (i as f64 / rows as f64 - 0.5);
        for j in 0..=cols {
            let a = d.panel_width * (j as f64 / cols as f64 - 0.5);
            vertices.push(f.center + s * f.up + a * f.across);
        }
    }
    let id = |i: usize, j: usize| (i * (cols + 1) + j) as u32;
    let mut triangles = Vec::with_capacity(2 * rows * cols);
    let mut strips = Vec::with_capacity(2 * rows * cols);
    for i in 0..rows {
        // Row i spans s from i/rows to (i+1)/rows of the length from the bottom edge.
        let s_mid = d.panel_length * (i as f64 + 0.5) / rows as f64;
        let strip = f.strip_of(s_mid, d.strips);
        for j in 0..cols {
            // (up, across) is right-handed about the front normal: counter-clockwise seen from the pipe.
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            strips.push(strip);
            strips.push(strip);
        }
    }
    (TriMesh { vertices, triangles }, strips)
}

/// Number of segments around the pipe: the circumference in pieces of about the panel triangle size,
/// at least 24 (the facets then lie within 0.9 % of the radius of the circle).
pub fn pipe_segments(d: &Dimensions) -> usize {
    ((std::f64::consts::PI * d.pipe_diameter / d.triangle_size).ceil() as usize).max(24)
}

/// The pipe wall: a polygonal tube of [`pipe_segments`] facets from x = −length to 0, inscribed in the
/// circle of the pipe's diameter, normals towards the axis (the stones fly inside).
pub fn pipe(d: &Dimensions) -> TriMesh {
    let n = pipe_segments(d);
    let r = 0.5 * d.pipe_diameter;
    let ring_len = std::f64::consts::PI * d.pipe_diameter / n as f64;
    let rings = ((d.pipe_length / ring_len).ceil() as usize).max(1);
    let mut soup = Vec::with_capacity(6 * n * rings);
    let at = |k: usize, i: usize| {
        let phi = std::f64::consts::TAU * (k % n) as f64 / n as f64;
        let x = -d.pipe_length + d.pipe_length * i as f64 / rings as f64;
        Vec3::new(x, r * phi.cos(), r * phi.sin())
    };
    for i in 0..rings {
        for k in 0..n {
            let (a, b, c, e) = (at(k, i), at(k + 1, i), at(k + 1, i + 1), at(k, i + 1));
            // Counter-clockwise seen from the axis.
            soup.extend([a, c, b, a, e, c]);
        }
    }
    TriMesh::from_triangle_soup(&soup)
}

/// Triangles of an axis-aligned box face as a quad `a, b, c, e` (counter-clockwise seen from the side
/// the normal points to).
fn quad(soup: &mut Vec<Vec3>, a: Vec3, b: Vec3, c: Vec3, e: Vec3) {
    soup.extend([a, b, c, a, c, e]);
}

/// Bounds of the protection box: the panel (with the clamp) and the pipe exit, grown by the margin,
/// from the pipe-exit plane x = 0 forward.
pub fn box_bounds(d: &Dimensions) -> Aabb {
    let f = PanelFrame::new(d);
    let mut b = Aabb::EMPTY;
    for (sa, ss) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
        let p = f.center + 0.5 * sa * f.width * f.across + 0.5 * ss * f.length * f.up;
        b = b.grown_to(p).grown_to(p + d.clamp_thickness * f.normal);
    }
    let r = 0.5 * d.pipe_diameter;
    b = b.grown_to(Vec3::new(0.0, -r, -r)).grown_to(Vec3::new(0.0, r, r));
    let m = d.box_margin;
    Aabb::new(Vec3::new(0.0, b.min.y - m, b.min.z - m), b.max + Vec3::splat(m))
}

/// The protection box: five closed faces and a back face at the pipe exit (x = 0) with a square opening
/// of the pipe's diameter around the axis; normals inwards.
pub fn protection_box(d: &Dimensions) -> TriMesh {
    let b = box_bounds(d);
    let (x0, y0, z0) = (b.min.x, b.min.y, b.min.z);
    let (x1, y1, z1) = (b.max.x, b.max.y, b.max.z);
    let v = Vec3::new;
    let mut s = Vec::new();
    quad(&mut s, v(x1, y0, z0), v(x1, y0, z1), v(x1, y1, z1), v(x1, y1, z0)); // front (x1), normal −x
    quad(&mut s, v(x0, y0, z0), v(x1, y0, z0), v(x1, y1, z0), v(x0, y1, z0)); // floor, normal +z
    quad(&mut s, v(x0, y0, z1), v(x0, y1, z1), v(x1, y1, z1), v(x1, y0, z1)); // roof, normal −z
    quad(&mut s, v(x0, y0, z0), v(x0, y0, z1), v(x1, y0, z1), v(x1, y0, z0)); // side y0, normal +y
    quad(&mut s, v(x0, y1, z0), v(x1, y1, z0), v(x1, y1, z1), v(x0, y1, z1)); // side y1, normal −y
                                                                              // Back face x = x0 (normal +x) around the opening |y|, |z| ≤ r.
    let r = 0.5 * d.pipe_diameter;
    let back = |s: &mut Vec<Vec3>, ya: f64, yb: f64, za: f64, zb: f64| {
        quad(s, v(x0, ya, za), v(x0, yb, za), v(x0, yb, zb), v(x0, ya, zb));
    };
    back(&mut s, y0, y1, z0, -r);
    back(&mut s, y0, y1, r, z1);
    back(&mut s, y0, -r, -r, r);
    back(&mut s, r, y1, -r, r);
    TriMesh::from_triangle_soup(&s)
}

/// The clamp: two bars holding the panel's top and bottom edges, each `clamp_bar_width` deep over the
/// panel and `clamp_thickness` thick in front of it, across the whole width; closed boxes.
pub fn clamp(d: &Dimensions) -> TriMesh {
    let f = PanelFrame::new(d);
    let mut s = Vec::new();
    let (hw, hl) = (0.5 * f.width, 0.5 * f.length);
    for (lo, hi) in [(hl - d.clamp_bar_width, hl), (-hl, -hl + d.clamp_bar_width)] {
        panel_cuboid(&mut s, &f, (-hw, hw), (lo, hi), (0.0, d.clamp_thickness));
    }
    TriMesh::from_triangle_soup(&s)
}

/// The panel as a closed slab for the flow solver's blocked cells: its front face is the panel, its
/// back `thickness` behind it (a slab thinner than a flow cell could slip between the cell centres).
pub fn panel_slab(d: &Dimensions, thickness: f64) -> TriMesh {
    let f = PanelFrame::new(d);
    let mut s = Vec::new();
    let (hw, hl) = (0.5 * f.width, 0.5 * f.length);
    panel_cuboid(&mut s, &f, (-hw, hw), (-hl, hl), (-thickness, 0.0));
    TriMesh::from_triangle_soup(&s)
}

/// Appends the triangles of the closed box spanning `across`, `up` and `normal` (ranges in the panel
/// frame) to `s`, faces outwards.
fn panel_cuboid(s: &mut Vec<Vec3>, f: &PanelFrame, across: (f64, f64), up: (f64, f64), normal: (f64, f64)) {
    let p = |a: f64, u: f64, n: f64| f.center + a * f.across + u * f.up + n * f.normal;
    let ((a0, a1), (u0, u1), (n0, n1)) = (across, up, normal);
    let c = [
        p(a0, u0, n0),
        p(a1, u0, n0),
        p(a1, u1, n0),
        p(a0, u1, n0),
        p(a0, u0, n1),
        p(a1, u0, n1),
        p(a1, u1, n1),
        p(a0, u1, n1),
    ];
    // (across, up, normal) is left-handed, so counter-clockwise seen from outside runs the corners in
    // this order.
    quad(s, c[4], c[7], c[6], c[5]);
    quad(s, c[0], c[1], c[2], c[3]);
    quad(s, c[0], c[4], c[5], c[1]);
    quad(s, c[2], c[6], c[7], c[3]);
    quad(s, c[1], c[5], c[6], c[2]);
    quad(s, c[0], c[3], c[7], c[4]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn din() -> Dimensions {
        Dimensions {
            pipe_diameter: 0.03,
            pipe_length: 0.29,
            panel_width: 0.1,
            panel_length: 0.2,
            panel_angle_deg: 54.0,
            panel_distance: 0.2,
            triangle_size: 0.005,
            strips: 5,
            clamp_bar_width: 0.01,
            clamp_thickness: 0.005,
            box_margin: 0.1,
        }
    }

    #[test]
    fn the_panel_has_its_area_its_angle_and_equal_strips_numbered_from_the_top() {
        let d = din();
        let (m, strips) = panel(&d);
        // Area of the 100 × 200 mm panel (DIN 55996-1 as used by Qian et al. 2022), exact to round-off.
        assert!((m.total_area() - 0.02).abs() < 1e-12, "{}", m.total_area());
        // Every normal faces the pipe and makes 54° with the horizontal plane's normal's complement:
        // n = (−sin 54°, 0, cos 54°).
        let t = 54f64.to_radians();
        for k in 0..m.triangles.len() {
            let n = m.normal(k);
            assert!((n - Vec3::new(-t.sin(), 0.0, t.cos())).length() < 1e-12, "{n}");
        }
        // Five strips of equal area, strip 1 highest.
        let mut area = [0.0; 5];
        let mut z = [0.0; 5];
        for k in 0..m.triangles.len() {
            area[strips[k] - 1] += m.area(k);
            z[strips[k] - 1] += m.area(k) * m.centroid(k).z;
        }
        for s in 0..5 {
            assert!((area[s] - 0.004).abs() < 1e-12, "strip {}: {}", s + 1, area[s]);
            if s > 0 {
                assert!(z[s] < z[s - 1], "strip {} sits below strip {}", s + 1, s);
            }
        }
    }

    #[test]
    fn rows_follow_the_triangle_size_and_the_strip_count() {
        assert_eq!(panel_rows(0.2, 0.005, 5), 40);
        assert_eq!(panel_rows(0.3, 0.007, 6), 48);
        assert_eq!(panel_rows(0.3, 0.1, 6), 6);
        let d = Dimensions { panel_angle_deg: 90.0, strips: 6, panel_length: 0.3, ..din() };
        let f = PanelFrame::new(&d);
        assert_eq!(f.strip_of(0.3, 6), 1);
        assert_eq!(f.strip_of(0.0, 6), 6);
        assert_eq!(f.strip_of(0.1499, 6), 4);
        assert_eq!(f.coords(Vec3::new(0.2, 0.01, 0.05)), (0.01, 0.2));
    }

    #[test]
    fn the_pipe_is_a_tube_of_the_given_size_facing_its_axis() {
        let d = din();
        let m = pipe(&d);
        let n = pipe_segments(&d) as f64;
        // Lateral area of the inscribed n-gon prism: n · 2r sin(π/n) · L.
        let r = 0.015;
        let expect = n * 2.0 * r * (std::f64::consts::PI / n).sin() * 0.29;
        assert!((m.total_area() - expect).abs() < 1e-12 * expect, "{} vs {expect}", m.total_area());
        for k in 0..m.triangles.len() {
            let c = m.centroid(k);
            let radial = Vec3::new(0.0, c.y, c.z).normalize();
            assert!(m.normal(k).dot(radial) < -0.99, "triangle {k} faces away from the axis");
        }
        let b = m.bounds();
        assert!((b.min.x + 0.29).abs() < 1e-15 && b.max.x.abs() < 1e-15);
    }

    #[test]
    fn box_and_clamp_are_closed_where_they_should_be() {
        let d = din();
        let clamp = clamp(&d);
        // Two closed bars: volume 2 × width × bar × thickness (outward normals give a positive volume).
        let v = 2.0 * 0.1 * 0.01 * 0.005;
        assert!((clamp.signed_volume() - v).abs() < 1e-12, "{}", clamp.signed_volume());
        let b = box_bounds(&d);
        let boxm = protection_box(&d);
        // Inner surface: the six faces minus the square opening of side D at the back.
        let e = b.extent();
        let area = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x) - 0.03 * 0.03;
        assert!((boxm.total_area() - area).abs() < 1e-12, "{} vs {area}", boxm.total_area());
        // The box faces look inwards: every normal points towards the box centre.
        let mid = 0.5 * (b.min + b.max);
        for k in 0..boxm.triangles.len() {
            assert!(boxm.normal(k).dot(mid - boxm.centroid(k)) > 0.0, "box triangle {k} faces outwards");
        }
        // The panel lies inside the box.
        let (p, _) = panel(&d);
        assert!(p.vertices.iter().all(|v| b.contains(*v)));
    }
}
