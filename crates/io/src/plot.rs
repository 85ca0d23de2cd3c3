//! Pictures: line/marker charts (PNG or SVG), colour maps of values on triangle meshes and of cell
//! fields on 2D rectilinear grids.
//!
//! Text is drawn with DejaVu Sans embedded in the binary (`assets/fonts`), so pictures render the same on
//! every machine without system fonts.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;
use std::io;
use std::path::Path;
use std::sync::Once;

static FONT: Once = Once::new();
const FONT_BYTES: &[u8] = include_bytes!("../../../assets/fonts/DejaVuSans.ttf");

fn ensure_font() {
    FONT.call_once(|| {
        // The embedded font is valid; if registration failed text would be missing, never a crash.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_BYTES);
    });
}

fn err(path: &Path, e: impl std::fmt::Display) -> io::Error {
    io::Error::other(format!("cannot draw {}: {e}", path.display()))
}

#[derive(Clone, Debug)]
enum Kind {
    Line,
    Markers,
    Dashed,
}

#[derive(Clone, Debug)]
struct Series {
    label: String,
    points: Vec<(f64, f64)>,
    kind: Kind,
    color: RGBColor,
}

/// A chart of lines and markers with optional logarithmic axes.
#[derive(Clone, Debug)]
pub struct Chart {
    title: String,
    x_label: String,
    y_label: String,
    log_x: bool,
    log_y: bool,
    x_range: Option<(f64, f64)>,
    y_range: Option<(f64, f64)>,
    size: (u32, u32),
    series: Vec<Series>,
    /// Draw the legend in a column right of the plot instead of inside it.
    legend_right: bool,
}

/// A short tick label: plain notation for moderate magnitudes, `2.5e-6` style otherwise, with trailing
/// zeros removed.
pub fn tick_label(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 {
        return "0".into();
    }
    if (1e-3..1e4).contains(&a) {
        let s = format!("{:.4}", v);
        let s = s.trim_end_matches('0').trim_end_matches('.');
        return s.to_owned();
    }
    let s = format!("{:.3e}", v);
    match s.split_once('e') {
        Some((m, e)) => format!("{}e{}", m.trim_end_matches('0').trim_end_matches('.'), e),
        None => s,
    }
}

/// A colour-bar label of `v` for ticks `step` apart: as many decimals as the step needs to tell ticks
/// apart (one digit below the step's leading digit), trailing zeros dropped; as [`tick_label`] outside
/// [1e-3, 1e4) or for a zero step. The bar's ticks split its range in quarters, so they fall on arbitrary
/// values: 0…2520.3676 reads 630, 1260, 1890, 2520; 999…1001 reads 999, 999.5, 1000, 1000.5, 1001.
pub fn colour_bar_label(v: f64, step: f64) -> String {
    let a = v.abs();
    let step = step.abs();
    if v == 0.0 || !(1e-3..1e4).contains(&a) || !step.is_normal() {
        return tick_label(v);
    }
    let decimals = (1 - step.log10().floor() as i32).clamp(0, 9) as usize;
    let s = format!("{v:.decimals$}");
    let s = if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.') } else { &s };
    s.to_owned()
}

/// The tick label of `v` on a linear axis spanning `span` (0 for a log axis): a value within 1e-9 of the
/// span from zero is rounding noise of a zero and is printed as `0` (an axis whose data start at a
/// computed 2.7e-20 instead of 0 would otherwise label its first tick `2.711e-20`).
pub fn axis_tick_label(v: f64, span: f64) -> String {
    if v.abs() <= 1e-9 * span.abs() {
        return "0".into();
    }
    tick_label(v)
}

/// Colours assigned to series without an explicit colour (colour-blind friendly, Okabe–Ito).
const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

impl Chart {
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Chart {
            title: title.to_owned(),
            x_label: x_label.to_owned(),
            y_label: y_label.to_owned(),
            log_x: false,
            log_y: false,
            x_range: None,
            y_range: None,
            size: (900, 650),
            series: Vec::new(),
            legend_right: false,
        }
    }

    pub fn log_x(mut self) -> Self {
        self.log_x = true;
        self
    }

    pub fn log_y(mut self) -> Self {
        self.log_y = true;
        self
    }

    /// Fixes the x range instead of fitting it to the data.
    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    /// Puts the legend in a column right of the plot area (the picture grows by its width), so that
    /// it never covers a curve; for charts with many series whose curves fill the plot.
    pub fn legend_right(mut self) -> Self {
        self.legend_right = true;
        self
    }

    /// Picture size in pixels.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }

    fn next_color(&self) -> RGBColor {
        PALETTE[self.series.len() % PALETTE.len()]
    }

    pub fn line(mut self, label: &str, points: &[(f64, f64)]) -> Self {
        let color = self.next_color();
        self.series.push(Series { label: label.into(), points: points.to_vec(), kind: Kind::Line, color });
        self
    }

    pub fn line_colored(mut self, label: &str, points: &[(f64, f64)], rgb: (u8, u8, u8)) -> Self {
        let color = RGBColor(rgb.0, rgb.1, rgb.2);
        self.series.push(Series { label: label.into(), points: points.to_vec(), kind: Kind::Line, color });
        self
    }

    pub fn dashed(mut self, label: &str, points: &[(f64, f64)], rgb: (u8, u8, u8)) -> Self {
        let color = RGBColor(rgb.0, rgb.1, rgb.2);
        self.series.push(Series { label: label.into(), points: points.to_vec(), kind: Kind::Dashed, color });
        self
    }

    pub fn markers(mut self, label: &str, points: &[(f64, f64)], rgb: (u8, u8, u8)) -> Self {
        let color = RGBColor(rgb.0, rgb.1, rgb.2);
        self.series.push(Series { label: label.into(), points: points.to_vec(), kind: Kind::Markers, color });
        self
    }

    fn usable(&self, (x, y): (f64, f64)) -> bool {
        x.is_finite() && y.is_finite() && (!self.log_x || x > 0.0) && (!self.log_y || y > 0.0)
    }

    fn bounds(&self) -> ((f64, f64), (f64, f64)) {
        let pts = self.series.iter().flat_map(|s| s.points.iter().copied()).filter(|p| self.usable(*p));
        let (mut x0, mut x1, mut y0, mut y1) =
            (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for (x, y) in pts {
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
        let pad = |lo: f64, hi: f64, log: bool| -> (f64, f64) {
            if !lo.is_finite() {
                return if log { (0.1, 10.0) } else { (0.0, 1.0) };
            }
            if log {
                let (a, b) = (lo.log10(), hi.log10());
                let m = ((b - a) * 0.05).max(0.05);
                (10f64.powf(a - m), 10f64.powf(b + m))
            } else {
                let m = if hi > lo { (hi - lo) * 0.05 } else { lo.abs().max(1.0) * 0.05 };
                (lo - m, hi + m)
            }
        };
        (
            self.x_range.unwrap_or_else(|| pad(x0, x1, self.log_x)),
            self.y_range.unwrap_or_else(|| pad(y0, y1, self.log_y)),
        )
    }

    /// Writes the chart as PNG.
    pub fn save_png(&self, path: &Path) -> io::Result<()> {
        ensure_font();
        let root = BitMapBackend::new(path, self.picture_size()).into_drawing_area();
        self.draw(&root).map_err(|e| err(path, e))?;
        root.present().map_err(|e| err(path, e))
    }

    /// Writes the chart as SVG.
    pub fn save_svg(&self, path: &Path) -> io::Result<()> {
        ensure_font();
        let root = SVGBackend::new(path, self.picture_size()).into_drawing_area();
        self.draw(&root).map_err(|e| err(path, e))?;
        root.present().map_err(|e| err(path, e))
    }

    /// Width of the legend column \[px\] (0 with the legend inside): room for the longest label.
    fn legend_width(&self) -> u32 {
        if !self.legend_right {
            return 0;
        }
        let chars = self.series.iter().map(|s| s.label.chars().count()).max().unwrap_or(0) as u32;
        36 + 7 * chars
    }

    /// The picture size, legend column included.
    fn picture_size(&self) -> (u32, u32) {
        (self.size.0 + self.legend_width(), self.size.1)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        if self.legend_right {
            let (plot, side) = root.split_horizontally(self.size.0);
            self.draw_legend_column(&side)?;
            return self.draw_plot(&plot);
        }
        self.draw_plot(root)
    }

    /// The legend as a column of entries (line sample and label), top-aligned with the plot area.
    fn draw_legend_column<DB: DrawingBackend>(&self, side: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let style = TextStyle::from(("sans-serif", 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
        let mut y = 60;
        for s in self.series.iter().filter(|s| !s.label.is_empty()) {
            let c = s.color;
            match s.kind {
                Kind::Markers => side.draw(&Circle::new((14, y), 4, c.filled())).map_err(e)?,
                _ => side.draw(&PathElement::new(vec![(4, y), (26, y)], c.stroke_width(3))).map_err(e)?,
            }
            side.draw(&Text::new(s.label.clone(), (32, y), style.clone())).map_err(e)?;
            y += 22;
        }
        Ok(())
    }

    fn draw_plot<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let ((x0, x1), (y0, y1)) = self.bounds();
        match (self.log_x, self.log_y) {
            (false, false) => self.draw_in(root, x0..x1, y0..y1),
            (true, false) => self.draw_in(root, (x0..x1).log_scale(), y0..y1),
            (false, true) => self.draw_in(root, x0..x1, (y0..y1).log_scale()),
            (true, true) => self.draw_in(root, (x0..x1).log_scale(), (y0..y1).log_scale()),
        }
    }

    fn draw_in<DB, X, Y>(&self, root: &DrawingArea<DB, Shift>, xr: X, yr: Y) -> Result<(), String>
    where
        DB: DrawingBackend,
        X: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
        Y: plotters::coord::ranged1d::AsRangedCoord<Value = f64>,
        X::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
        Y::CoordDescType: plotters::coord::ranged1d::ValueFormatter<f64>,
    {
        let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let ((x0, x1), (y0, y1)) = self.bounds();
        let (x_span, y_span) =
            (if self.log_x { 0.0 } else { x1 - x0 }, if self.log_y { 0.0 } else { y1 - y0 });
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, ("sans-serif", 22))
            .margin(14)
            .x_label_area_size(48)
            .y_label_area_size(78)
            .build_cartesian_2d(xr, yr)
            .map_err(e)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|v| axis_tick_label(*v, x_span))
            .y_label_formatter(&|v| axis_tick_label(*v, y_span))
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(e)?;
        let mut any_label = false;
        for s in &self.series {
            let pts: Vec<(f64, f64)> = s.points.iter().copied().filter(|p| self.usable(*p)).collect();
            let color = s.color;
            let anno = match s.kind {
                Kind::Line => chart.draw_series(LineSeries::new(pts, color.stroke_width(2))).map_err(e)?,
                Kind::Dashed => {
                    chart.draw_series(DashedLineSeries::new(pts, 8, 5, color.stroke_width(2))).map_err(e)?
                }
                Kind::Markers => chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                    .map_err(e)?,
            };
            if !s.label.is_empty() && !self.legend_right {
                any_label = true;
                anno.label(s.label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color.stroke_width(3)));
            }
        }
        if any_label {
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 14))
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(e)?;
        }
        Ok(())
    }
}

/// Splits `text` into lines of at most `width` characters at spaces (a longer word gets a line of its own).
fn wrap_words(text: &str, width: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(l) if l.chars().count() + 1 + word.chars().count() <= width => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_owned()),
        }
    }
    lines
}

/// Perceptually uniform colour map (viridis, sampled at nine stops and interpolated linearly).
pub fn viridis(t: f64) -> (u8, u8, u8) {
    const STOPS: [(f64, f64, f64); 9] = [
        (68.0, 1.0, 84.0),
        (71.0, 44.0, 122.0),
        (59.0, 81.0, 139.0),
        (44.0, 113.0, 142.0),
        (33.0, 144.0, 141.0),
        (39.0, 173.0, 129.0),
        (92.0, 200.0, 99.0),
        (170.0, 220.0, 50.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let x = t * 8.0;
    let k = (x as usize).min(7);
    let f = x - k as f64;
    let (a, b) = (STOPS[k], STOPS[k + 1]);
    let mix = |p: f64, q: f64| (p + (q - p) * f).round() as u8;
    (mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Draws a vertical viridis colour bar `x0..x0 + 25` px wide between `top` and `bottom` px, with five
/// labelled ticks from `range.0` to `range.1` and `label` wrapped above it starting at `label_x`.
fn colour_bar<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    x0: i32,
    (top, bottom): (i32, i32),
    (vmin, vmax): (f64, f64),
    label: &str,
    label_x: i32,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let x1 = x0 + 25;
    let steps = 100;
    let y_at = |f: f64| bottom - ((bottom - top) as f64 * f).round() as i32;
    for k in 0..steps {
        let t0 = k as f64 / steps as f64;
        let (y_hi, y_lo) = (y_at((k + 1) as f64 / steps as f64), y_at(t0));
        let (r, g, b) = viridis(t0);
        root.draw(&Rectangle::new([(x0, y_hi), (x1, y_lo)], RGBColor(r, g, b).filled()))?;
    }
    root.draw(&Rectangle::new([(x0, top), (x1, bottom)], BLACK.stroke_width(1)))?;
    for k in 0..=4 {
        let f = k as f64 / 4.0;
        let y = y_at(f);
        root.draw(&PathElement::new(vec![(x1, y), (x1 + 4, y)], BLACK.stroke_width(1)))?;
        let text = colour_bar_label(vmin + f * (vmax - vmin), (vmax - vmin) / 4.0);
        root.draw(&Text::new(text, (x1 + 7, y - 7), ("sans-serif", 13)))?;
    }
    // The label is wrapped to the colour-bar column (about 20 characters a line) so it is never cut off.
    let lines = wrap_words(label, 20);
    let first = top - 12 - 16 * lines.len() as i32;
    for (k, line) in lines.iter().enumerate() {
        root.draw(&Text::new(line.clone(), (label_x, first + 16 * k as i32), ("sans-serif", 14)))?;
    }
    Ok(())
}

/// A scalar field on the cells of a 2D rectilinear grid, for [`field_map_png`].
#[derive(Clone, Copy, Debug)]
pub struct FieldMap<'a> {
    /// Face coordinates along the horizontal and vertical axes (strictly increasing).
    pub x_faces: &'a [f64],
    pub y_faces: &'a [f64],
    /// One value per cell, x fastest: cell (i, j) is `values[i + nx·j]`. NaN marks cells without data
    /// (solids), drawn grey.
    pub values: &'a [f64],
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub colorbar_label: &'a str,
}

/// Renders a [`FieldMap`] to scale (equal lengths on both axes; a side shorter than 300 px is stretched
/// to 300 px) with axes, ticks, a title across the picture and a viridis colour bar spanning the finite
/// values.
pub fn field_map_png(path: &Path, map: &FieldMap) -> io::Result<()> {
    field_map_png_with_lines(path, map, &[])
}

/// [`field_map_png`] with horizontal lines across the map at heights `lines` (e.g. the boundaries of
/// regions), each labelled with its text at the right end, drawn in white over a black outline.
pub fn field_map_png_with_lines(path: &Path, map: &FieldMap, lines: &[(f64, String)]) -> io::Result<()> {
    let (nx, ny) = (map.x_faces.len().saturating_sub(1), map.y_faces.len().saturating_sub(1));
    if nx == 0 || ny == 0 || map.values.len() != nx * ny {
        return Err(err(path, format!("{} values for a {nx} × {ny} grid", map.values.len())));
    }
    ensure_font();
    let (x0, x1) = (map.x_faces[0], map.x_faces[nx]);
    let (y0, y1) = (map.y_faces[0], map.y_faces[ny]);
    if !(x1 > x0 && y1 > y0) {
        return Err(err(path, "face coordinates must increase"));
    }
    let finite = map.values.iter().copied().filter(|v| v.is_finite());
    let vmax = finite.clone().fold(f64::NEG_INFINITY, f64::max);
    let vmin = finite.fold(f64::INFINITY, f64::min);
    let (vmin, vmax) = if !vmax.is_finite() {
        (0.0, 1.0)
    } else if vmax > vmin {
        (vmin, vmax)
    } else {
        (vmin - 0.5, vmin + 0.5)
    };
    // Plot area to scale within 760 × 640 px; a side that would be shorter than 300 px is stretched to
    // 300 px (long thin domains such as pipes), which the axis ticks make plain.
    let scale = (760.0 / (x1 - x0)).min(640.0 / (y1 - y0));
    let pw = ((x1 - x0) * scale).round().max(300.0) as u32;
    let ph = ((y1 - y0) * scale).round().max(300.0) as u32;
    let (left_axis, bottom_axis, margin, caption) = (78u32, 48u32, 14u32, 40u32);
    let chart_w = pw + left_axis + 2 * margin;
    let h = (ph + bottom_axis + 2 * margin + caption).max(600);
    // The title spans the whole picture; it sets the smallest width (about 11 px per character).
    let w = (chart_w + 170).max(40 + 11 * map.title.chars().count() as u32);
    let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| err(path, x))?;
    let e = |x: DrawingAreaErrorKind<_>| err(path, x);
    let body = root.titled(map.title, ("sans-serif", 22)).map_err(e)?;
    let (left, right) = body.split_horizontally(chart_w);
    let mut chart = ChartBuilder::on(&left)
        .margin(margin)
        .x_label_area_size(bottom_axis)
        .y_label_area_size(left_axis)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    let (xs, ys) = (x1 - x0, y1 - y0);
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(map.x_label)
        .y_desc(map.y_label)
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&|v| axis_tick_label(*v, xs))
        .y_label_formatter(&|v| axis_tick_label(*v, ys))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(e)?;
    let shade = |v: f64| -> RGBColor {
        if v.is_finite() {
            let (r, g, b) = viridis((v - vmin) / (vmax - vmin));
            RGBColor(r, g, b)
        } else {
            RGBColor(200, 200, 200)
        }
    };
    chart
        .draw_series((0..ny).flat_map(|j| {
            (0..nx).map(move |i| {
                Rectangle::new(
                    [(map.x_faces[i], map.y_faces[j]), (map.x_faces[i + 1], map.y_faces[j + 1])],
                    shade(map.values[i + nx * j]).filled(),
                )
            })
        }))
        .map_err(e)?;
    for (y, text) in lines {
        for (color, width) in [(BLACK, 3), (WHITE, 1)] {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x0, *y), (x1, *y)],
                    color.stroke_width(width),
                )))
                .map_err(e)?;
        }
        if !text.is_empty() {
            let at = chart.backend_coord(&(x1, *y));
            left.draw(&Text::new(
                text.clone(),
                (at.0 - 8 * text.chars().count() as i32 - 4, at.1 + 3),
                ("sans-serif", 13).into_font().color(&WHITE),
            ))
            .map_err(e)?;
        }
    }
    let top = 60;
    let bottom = (h as i32 - 110).min(top + 440);
    colour_bar(&right, 30, (top, bottom), (vmin, vmax), map.colorbar_label, 15).map_err(e)?;
    root.present().map_err(e)
}

/// A coordinate axis as seen on a picture (see [`axis_triad`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenAxis {
    /// `x`, `y` or `z`.
    pub label: &'static str,
    /// Projected direction (right, up) on the screen: unit length for an axis in the picture plane,
    /// shorter as it tilts towards the viewing direction.
    pub screen: (f64, f64),
    /// Component along the view direction (> 0: the axis points away from the viewer, into the picture).
    pub along: f64,
}

/// The x, y and z axes as seen on a picture looking along `view_dir` with `up` towards the top; `None`
/// when `view_dir` and `up` are zero or parallel.
pub fn axis_triad(view_dir: Vec3, up: Vec3) -> Option<[ScreenAxis; 3]> {
    let d = view_dir.normalize_or_zero();
    let right = d.cross(up).normalize_or_zero();
    if d == Vec3::ZERO || right == Vec3::ZERO {
        return None;
    }
    let screen_up = right.cross(d);
    let axis =
        |label, e: Vec3| ScreenAxis { label, screen: (e.dot(right), e.dot(screen_up)), along: e.dot(d) };
    Some([axis("x", Vec3::X), axis("y", Vec3::Y), axis("z", Vec3::Z)])
}

/// The caption of a mesh picture naming its view: `view direction [a, b, c] (camera → object), up [u, v, w]`.
pub fn view_caption(view_dir: Vec3, up: Vec3) -> String {
    let v = |a: Vec3| format!("[{}, {}, {}]", tick_label(a.x), tick_label(a.y), tick_label(a.z));
    format!("view direction {} (camera → object), up {}", v(view_dir), v(up))
}

/// Renders `mesh` seen along `view_dir` (orthographic, `up` towards the top of the picture), each triangle
/// coloured by its value; NaN values are drawn grey ("no data"). A colour bar labelled `colorbar_label`
/// shows the scale from 0 (or the minimum, if negative) to the maximum; an axis triad (x red, y green,
/// z blue, drawn as arrows in the picture plane, an axis along the view as a circle with a dot when it
/// points at the viewer or a cross when it points away) and a caption with the view direction and up
/// vector give the orientation. The picture has no other axes or ticks: the mesh is drawn to scale.
pub fn mesh_map_png(
    path: &Path,
    mesh: &TriMesh,
    values: &[f64],
    view_dir: Vec3,
    up: Vec3,
    title: &str,
    colorbar_label: &str,
) -> io::Result<()> {
    mesh_map_png_on_scale(path, mesh, values, (view_dir, up), (title, colorbar_label), auto_scale(values))
}

/// The colour scale [`mesh_map_png`] chooses for `values`: from 0 (or the minimum, if negative) to the
/// largest finite value; `(0, 1)` when there is nothing to scale.
pub fn auto_scale(values: &[f64]) -> (f64, f64) {
    let finite = values.iter().copied().filter(|v| v.is_finite());
    let vmax = finite.clone().fold(f64::NEG_INFINITY, f64::max);
    let vmin = finite.fold(f64::INFINITY, f64::min).min(0.0);
    if vmax.is_finite() && vmax > vmin {
        (vmin, vmax)
    } else {
        (0.0, 1.0)
    }
}

/// [`mesh_map_png`] on a given colour scale `(low, high)` (values outside it take the end colours), so
/// that maps of several runs can be compared colour for colour; `view` is (view direction, up) and
/// `labels` (title, colour-bar label).
pub fn mesh_map_png_on_scale(
    path: &Path,
    mesh: &TriMesh,
    values: &[f64],
    (view_dir, up): (Vec3, Vec3),
    (title, colorbar_label): (&str, &str),
    (vmin, vmax): (f64, f64),
) -> io::Result<()> {
    if !(vmin.is_finite() && vmax.is_finite() && vmax > vmin) {
        return Err(err(path, format!("colour scale {vmin}..{vmax} must be finite and increasing")));
    }
    if values.len() != mesh.triangles.len() {
        return Err(err(path, format!("{} values for {} triangles", values.len(), mesh.triangles.len())));
    }
    ensure_font();
    let Some(triad) = axis_triad(view_dir, up) else {
        return Err(err(path, "view direction and up vector must be non-zero and not parallel"));
    };
    let d = view_dir.normalize_or_zero();
    let right = d.cross(up).normalize_or_zero();
    let screen_up = right.cross(d);
    let project = |p: Vec3| (p.dot(right), p.dot(screen_up));
    let (mut x0, mut x1, mut y0, mut y1) =
        (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for v in &mesh.vertices {
        let (x, y) = project(*v);
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !x0.is_finite() {
        return Err(err(path, "mesh has no vertices"));
    }
    // Painter's algorithm: far triangles first.
    let mut order: Vec<usize> = (0..mesh.triangles.len()).collect();
    let depth: Vec<f64> = (0..mesh.triangles.len()).map(|t| mesh.centroid(t).dot(d)).collect();
    order.sort_by(|&a, &b| depth[b].total_cmp(&depth[a]));

    // Layout (pixels): the mesh to scale in [20, 830] × [50, 700], the caption below it, the colour bar
    // and the axis triad in the right-hand column.
    let (w, h) = (1000u32, 760u32);
    let (mx0, mx1, my0, my1) = (20.0, 830.0, 50.0, 700.0);
    let span_x = (x1 - x0).max(1e-300);
    let span_y = (y1 - y0).max(1e-300);
    let scale = ((mx1 - mx0) / span_x).min((my1 - my0) / span_y);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (px_c, py_c) = (0.5 * (mx0 + mx1), 0.5 * (my0 + my1));
    let to_px = |(x, y): (f64, f64)| -> (i32, i32) {
        ((px_c + (x - cx) * scale).round() as i32, (py_c - (y - cy) * scale).round() as i32)
    };

    let root = BitMapBackend::new(path, (w, h)).into_drawing_area();
    root.fill(&WHITE).map_err(|x| err(path, x))?;
    let centred = |size: u32| {
        TextStyle::from(("sans-serif", size).into_font()).pos(Pos::new(HPos::Center, VPos::Center))
    };
    root.draw(&Text::new(title.to_owned(), (((mx0 + mx1) / 2.0) as i32, 24), centred(22)))
        .map_err(|x| err(path, x))?;
    let shade = |v: f64| -> RGBColor {
        if v.is_finite() {
            let (r, g, b) = viridis((v - vmin) / (vmax - vmin));
            RGBColor(r, g, b)
        } else {
            RGBColor(200, 200, 200)
        }
    };
    for &t in &order {
        let [a, b, c] = mesh.corners(t);
        let poly = vec![to_px(project(a)), to_px(project(b)), to_px(project(c))];
        root.draw(&Polygon::new(poly, shade(values[t]).filled())).map_err(|x| err(path, x))?;
    }
    root.draw(&Text::new(view_caption(view_dir, up), (mx0 as i32, 734), ("sans-serif", 14)))
        .map_err(|x| err(path, x))?;

    colour_bar(&root, 870, (80, 520), (vmin, vmax), colorbar_label, 855).map_err(|x| err(path, x))?;

    // Axis triad: arrows of length `len` from the origin `o`, far axes first so near ones stay on top.
    let o = (925.0, 640.0);
    let len = 48.0;
    root.draw(&Text::new("axes", (o.0 as i32, 568), centred(13))).map_err(|x| err(path, x))?;
    let mut axes = triad;
    axes.sort_by(|a, b| b.along.total_cmp(&a.along));
    for ScreenAxis { label, screen: (ex, ey), along } in axes {
        let colour = match label {
            "x" => RGBColor(200, 30, 30),
            "y" => RGBColor(20, 140, 20),
            _ => RGBColor(30, 60, 210),
        };
        let pt = |x: f64, y: f64| (x.round() as i32, y.round() as i32);
        let flat = (ex * ex + ey * ey).sqrt();
        if flat < 0.2 {
            // Along the view: ⊙ pointing at the viewer, ⊗ pointing away.
            let c = pt(o.0, o.1);
            root.draw(&Circle::new(c, 7, colour.stroke_width(2))).map_err(|x| err(path, x))?;
            if along < 0.0 {
                root.draw(&Circle::new(c, 2, colour.filled())).map_err(|x| err(path, x))?;
            } else {
                for (a, b) in [((-4, -4), (4, 4)), ((-4, 4), (4, -4))] {
                    let seg = vec![(c.0 + a.0, c.1 + a.1), (c.0 + b.0, c.1 + b.1)];
                    root.draw(&PathElement::new(seg, colour.stroke_width(2))).map_err(|x| err(path, x))?;
                }
            }
            root.draw(&Text::new(label, (c.0 + 9, c.1 - 22), ("sans-serif", 16).into_font().color(&colour)))
                .map_err(|x| err(path, x))?;
            continue;
        }
        let tip = (o.0 + len * ex, o.1 - len * ey);
        let (ux, uy) = (ex / flat, -ey / flat);
        let head = 9.0_f64.min(len * flat);
        let base = (tip.0 - head * ux, tip.1 - head * uy);
        root.draw(&PathElement::new(vec![pt(o.0, o.1), pt(base.0, base.1)], colour.stroke_width(2)))
            .map_err(|x| err(path, x))?;
        let wing = 0.45 * head;
        let arrow = vec![
            pt(tip.0, tip.1),
            pt(base.0 - wing * uy, base.1 + wing * ux),
            pt(base.0 + wing * uy, base.1 - wing * ux),
        ];
        root.draw(&Polygon::new(arrow, colour.filled())).map_err(|x| err(path, x))?;
        let at = pt(tip.0 + 11.0 * ux, tip.1 + 11.0 * uy);
        let style = ("sans-serif", 16).into_font().color(&colour).pos(Pos::new(HPos::Center, VPos::Center));
        root.draw(&Text::new(label, at, style)).map_err(|x| err(path, x))?;
    }
    root.present().map_err(|x| err(path, x))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn png_size(p: &Path) -> (u32, u32) {
        let b = std::fs::read(p).unwrap();
        assert_eq!(&b[1..4], b"PNG");
        (u32::from_be_bytes(b[16..20].try_into().unwrap()), u32::from_be_bytes(b[20..24].try_into().unwrap()))
    }

    #[test]
    fn charts_render_png_and_svg() {
        let dir = tempfile::tempdir().unwrap();
        let pts: Vec<(f64, f64)> = (1..50).map(|i| (i as f64, (i as f64).powf(-0.8))).collect();
        let c = Chart::new("power law", "d [m]", "v [m/s]").log_x().log_y().line("fit", &pts).markers(
            "data",
            &pts,
            (200, 0, 0),
        );
        c.save_png(&dir.path().join("a.png")).unwrap();
        c.save_svg(&dir.path().join("a.svg")).unwrap();
        assert_eq!(png_size(&dir.path().join("a.png")), (900, 650));
        let svg = std::fs::read_to_string(dir.path().join("a.svg")).unwrap();
        assert!(svg.contains("power law"));
    }

    #[test]
    fn field_map_is_drawn_to_scale_and_checks_lengths() {
        let dir = tempfile::tempdir().unwrap();
        let xf = [0.0, 1.0, 2.0, 4.0];
        let yf = [0.0, 0.5, 1.0];
        let map = FieldMap {
            x_faces: &xf,
            y_faces: &yf,
            values: &[1.0, 2.0, f64::NAN, 0.0, -1.0, 3.0],
            title: "t",
            x_label: "x [m]",
            y_label: "y [m]",
            colorbar_label: "v",
        };
        let p = dir.path().join("f.png");
        field_map_png(&p, &map).unwrap();
        // 4 m × 1 m: 760 × 190 px plot (stretched to 300 px high), plus axes, margins and the colour bar.
        assert_eq!(png_size(&p), (760 + 78 + 28 + 170, 600));
        // A long title widens the picture instead of being cut.
        let long = "a title much longer than the plot is wide, as a pipe picture has it: speed on the cut";
        let thin_x = [0.0, 0.05];
        let thin_y = [0.0, 2.5, 5.0];
        let thin = FieldMap { x_faces: &thin_x, y_faces: &thin_y, values: &[1.0, 2.0], title: long, ..map };
        field_map_png(&p, &thin).unwrap();
        assert_eq!(png_size(&p).0, 40 + 11 * long.chars().count() as u32);
        let short = FieldMap { values: &[1.0; 5], ..map };
        assert!(field_map_png(&p, &short).unwrap_err().to_string().contains("5 values for a 3 × 2 grid"));
    }

    #[test]
    fn colour_bar_labels_wrap() {
        assert_eq!(
            wrap_words("deposited mass per area [kg/m²]", 20),
            vec!["deposited mass per", "area [kg/m²]"]
        );
        assert_eq!(wrap_words("x", 20), vec!["x"]);
    }

    #[test]
    fn tick_labels_are_short() {
        assert_eq!(tick_label(4.999999999999999e-6), "5e-6");
        assert_eq!(tick_label(0.25), "0.25");
        assert_eq!(tick_label(1200.0), "1200");
        assert_eq!(tick_label(2.5e7), "2.5e7");
        // Rounding noise of a zero on a linear axis reads 0; on a log axis (span 0) tiny values stay.
        assert_eq!(axis_tick_label(2.711e-20, 1.4e-3), "0");
        assert_eq!(axis_tick_label(2e-4, 1.4e-3), "2e-4");
        assert_eq!(axis_tick_label(2.711e-20, 0.0), "2.711e-20");
        // Colour bars: the decimals the tick step needs.
        let quarters = |lo: f64, hi: f64| -> Vec<String> {
            (0..=4).map(|k| colour_bar_label(lo + k as f64 / 4.0 * (hi - lo), (hi - lo) / 4.0)).collect()
        };
        assert_eq!(quarters(0.0, 2520.3676), ["0", "630", "1260", "1890", "2520"]);
        assert_eq!(quarters(999.0, 1001.0), ["999", "999.5", "1000", "1000.5", "1001"]);
        assert_eq!(quarters(0.0, 0.01), ["0", "0.0025", "0.005", "0.0075", "0.01"]);
        assert_eq!(quarters(-42.0, 42.0), ["-42", "-21", "0", "21", "42"]);
        assert_eq!(colour_bar_label(4.999999999999999e-6, 1e-6), "5e-6");
        assert_eq!(colour_bar_label(7.0, 0.0), "7");
    }

    #[test]
    fn axis_triad_and_caption_follow_the_view() {
        // Looking down (−z) with y up: right = d × up = x, so x points right, y up, z at the viewer.
        let t = axis_triad(-Vec3::Z, Vec3::Y).unwrap();
        assert_eq!(t.map(|a| a.label), ["x", "y", "z"]);
        assert_eq!(t[0].screen, (1.0, 0.0));
        assert_eq!(t[1].screen, (0.0, 1.0));
        assert_eq!((t[2].screen, t[2].along), ((0.0, 0.0), -1.0));
        // Isometric view along −(1, 1, 1) with z up: every axis projects to length √(2/3) (orthographic
        // projection of a unit vector at angle acos(1/√3) to the view), z straight up, x and y 30° below
        // the horizontal on either side; each axis has component −1/√3 along the view (towards the viewer).
        let t = axis_triad(-Vec3::ONE, Vec3::Z).unwrap();
        let s = (2.0f64 / 3.0).sqrt();
        for a in t {
            let (ex, ey) = a.screen;
            assert!(((ex * ex + ey * ey).sqrt() - s).abs() < 1e-15);
            assert!((a.along + 1.0 / 3f64.sqrt()).abs() < 1e-15);
        }
        let ((xx, xy), (yx, _), (zx, zy)) = (t[0].screen, t[1].screen, t[2].screen);
        assert!(zx.abs() < 1e-15 && (zy - s).abs() < 1e-15, "z up: {:?}", t[2].screen);
        assert!((xy / xx.abs() + 30f64.to_radians().tan()).abs() < 1e-15, "x 30° down");
        assert!(xx * yx < 0.0, "x and y on opposite sides");
        assert!(axis_triad(Vec3::Z, Vec3::Z).is_none());
        assert_eq!(
            view_caption(Vec3::new(0.6, 1.0, -0.9), Vec3::Z),
            "view direction [0.6, 1, -0.9] (camera → object), up [0, 0, 1]"
        );
    }

    #[test]
    fn mesh_map_renders_and_checks_lengths() {
        let dir = tempfile::tempdir().unwrap();
        let m = TriMesh::rectangle(2.0, 1.0, 0.0, 4, 2);
        let vals: Vec<f64> = (0..m.triangles.len()).map(|t| t as f64).collect();
        let p = dir.path().join("m.png");
        mesh_map_png(&p, &m, &vals, -Vec3::Z, Vec3::Y, "test", "mass [kg/m²]").unwrap();
        assert_eq!(png_size(&p), (1000, 760));
        assert!(mesh_map_png(&p, &m, &vals[1..], -Vec3::Z, Vec3::Y, "t", "x").is_err());
        assert!(mesh_map_png(&p, &m, &vals, Vec3::Y, Vec3::Y, "t", "x").is_err());
    }
}

#[cfg(test)]
mod picture_check {
    use super::*;
    /// Writes sample pictures to `$SPATTER_PICTURE_DIR` for looking at by eye (skipped when unset).
    #[test]
    fn sample_pictures() {
        let Ok(dir) = std::env::var("SPATTER_PICTURE_DIR") else { return };
        let dir = Path::new(&dir);
        let pts: Vec<(f64, f64)> = (1..50).map(|i| (i as f64 * 1e-6, 0.3 * (i as f64).powf(-0.8))).collect();
        Chart::new("critical speed", "diameter [m]", "v_crit [m/s]")
            .log_x()
            .log_y()
            .line("fit", &pts)
            .markers("stick", &pts[..10], (200, 30, 30))
            .save_png(&dir.join("chart.png"))
            .unwrap();
        let mut m = TriMesh::rectangle(2.0, 1.0, 0.0, 20, 10);
        m.map_vertices(|v| Vec3::new(v.x, v.y, 0.3 * (v.x * 3.0).sin()));
        let vals: Vec<f64> = (0..m.triangles.len()).map(|t| m.centroid(t).x * m.centroid(t).y).collect();
        mesh_map_png(
            &dir.join("mesh.png"),
            &m,
            &vals,
            Vec3::new(-0.3, -0.5, -1.0),
            Vec3::Y,
            "deposit",
            "kg/m²",
        )
        .unwrap();
        let xf: Vec<f64> = (0..=40).map(|i| 2.0 * (i as f64 / 40.0).powf(1.3)).collect();
        let yf: Vec<f64> = (0..=20).map(|j| j as f64 / 20.0).collect();
        let vals: Vec<f64> = (0..800)
            .map(|c| {
                let (x, y) = (xf[c % 40], yf[c / 40]);
                if (x - 0.5).hypot(y - 0.5) < 0.2 {
                    f64::NAN
                } else {
                    (3.0 * x).sin() * y
                }
            })
            .collect();
        let map = FieldMap {
            x_faces: &xf,
            y_faces: &yf,
            values: &vals,
            title: "field",
            x_label: "x [m]",
            y_label: "y [m]",
            colorbar_label: "velocity magnitude [m/s]",
        };
        field_map_png(&dir.join("field.png"), &map).unwrap();
    }
}

/// One series of a [`bar_chart_png`]: a value per category and, optionally, an interval drawn as a
/// whisker.
#[derive(Clone, Debug)]
pub struct Bars<'a> {
    pub label: &'a str,
    pub values: &'a [f64],
    /// `(low, high)` per category, or empty for no whiskers.
    pub intervals: &'a [(f64, f64)],
}

/// A grouped bar chart: one group per category (named under the axis), one bar per series, with
/// optional interval whiskers; non-finite values are left out.
pub fn bar_chart_png(
    path: &Path,
    title: &str,
    y_label: &str,
    categories: &[String],
    series: &[Bars],
) -> io::Result<()> {
    ensure_font();
    let n = categories.len().max(1);
    let finite = series
        .iter()
        .flat_map(|s| s.values.iter().copied().chain(s.intervals.iter().flat_map(|&(a, b)| [a, b])))
        .filter(|v| v.is_finite());
    let (lo, hi) = finite.fold((0.0f64, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    let hi = if hi.is_finite() && hi > lo { hi } else { lo + 1.0 };
    let pad = 0.06 * (hi - lo);
    // Room under the zero line for the category names.
    let (y0, y1) = (lo - 3.0 * pad, hi + pad);
    let width = (160 * n as u32 + 200).clamp(700, 1600);
    // The legend gets a column of its own right of the bars, so that it never covers one.
    let legend_w = 36 + 7 * series.iter().map(|s| s.label.chars().count()).max().unwrap_or(0) as u32;
    let picture = BitMapBackend::new(path, (width + legend_w, 620)).into_drawing_area();
    let (root, side) = picture.split_horizontally(width);
    let draw = || -> Result<(), String> {
        let e = |e: DrawingAreaErrorKind<_>| e.to_string();
        picture.fill(&WHITE).map_err(e)?;
        let style = TextStyle::from(("sans-serif", 14).into_font()).pos(Pos::new(HPos::Left, VPos::Center));
        for (si, s) in series.iter().enumerate() {
            let (color, y) = (PALETTE[si % PALETTE.len()], 60 + 22 * si as i32);
            side.draw(&Rectangle::new([(6, y - 5), (20, y + 5)], color.filled())).map_err(e)?;
            side.draw(&Text::new(s.label.to_owned(), (28, y), style.clone())).map_err(e)?;
        }
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(14)
            .x_label_area_size(10)
            .y_label_area_size(70)
            .build_cartesian_2d(-0.5f64..n as f64 - 0.5, y0..y1)
            .map_err(e)?;
        let span = y1 - y0;
        chart
            .configure_mesh()
            .disable_x_mesh()
            .x_labels(0)
            .y_desc(y_label)
            .y_label_formatter(&|v| axis_tick_label(*v, span))
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 16))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(e)?;
        chart
            .draw_series(std::iter::once(PathElement::new(vec![(-0.5, 0.0), (n as f64 - 0.5, 0.0)], BLACK)))
            .map_err(e)?;
        let m = series.len().max(1) as f64;
        let bar = 0.8 / m;
        for (si, s) in series.iter().enumerate() {
            let color = PALETTE[si % PALETTE.len()];
            let x_of = |ci: usize| ci as f64 - 0.4 + bar * si as f64;
            let rects = s.values.iter().enumerate().filter(|(_, v)| v.is_finite()).map(|(ci, &v)| {
                Rectangle::new([(x_of(ci) + 0.05 * bar, 0.0), (x_of(ci) + 0.95 * bar, v)], color.filled())
            });
            chart.draw_series(rects).map_err(e)?;
            let whiskers =
                s.intervals.iter().enumerate().filter(|(_, (a, b))| a.is_finite() && b.is_finite()).map(
                    |(ci, &(a, b))| {
                        let xc = x_of(ci) + 0.5 * bar;
                        PathElement::new(vec![(xc, a), (xc, b)], BLACK.stroke_width(2))
                    },
                );
            chart.draw_series(whiskers).map_err(e)?;
        }
        let names = categories.iter().enumerate().map(|(ci, c)| {
            Text::new(
                c.clone(),
                (ci as f64, lo - 1.5 * pad),
                TextStyle::from(("sans-serif", 14).into_font()).pos(Pos::new(HPos::Center, VPos::Center)),
            )
        });
        chart.draw_series(names).map_err(e)?;
        picture.present().map_err(e)
    };
    draw().map_err(|m| err(path, m))
}
