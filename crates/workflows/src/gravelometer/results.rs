//! What a gravelometer run reports: the damage map and strip shares on the panel, the impact statistics
//! of the first stones, the eroded mass after K impacts, the fate of every stone, and the first stone's
//! flight; read from the DEM scene's records ([`SceneResults`]) and files.

use super::config::{get, GravelometerConfig};
use super::geometry;
use super::scene::{Plan, BOX, CLAMP, PANEL, PIPE};
use super::GravelometerError;
use crate::dem_scene::events::ObjectRecord;
use crate::dem_scene::SceneResults;
use spatter_core::Vec3;
use spatter_io::fmt_f64;
use spatter_io::plot::{bar_chart_png, field_map_png_with_lines, Bars, Chart, FieldMap};
use spatter_io::run::{CurveRecord, MeshMapRecord, RunContext, RunSummary, ScalarTableRecord};
use spatter_io::vtu::Vtu;
use std::path::Path;

/// A table cell for a derived statistic: NaN here only ever means "undefined" (the share of a panel with
/// no damage, the spread of fewer than two impacts, the entrance angle of a stone that never left the
/// pipe) and is written as an empty cell, the tables' mark for a value undefined by design.
fn gap(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        fmt_f64(x)
    }
}

/// The headline of the impact statistics: mean ± SD (min–max) of speed and angle, without the undefined
/// parts (no SD of one impact, nothing but a sentence when no stone reached the panel).
pub(crate) fn impact_headline(speed: &Statistics, angle: &Statistics) -> String {
    match speed.n {
        0 => "no stone reached the panel: no impact statistics (lengthen duration_s)".to_string(),
        1 => format!(
            "first stone on the panel: speed {:.2} m/s, impact angle {:.1}°",
            speed.mean, angle.mean
        ),
        n => format!(
            "first {n} stones on the panel: speed {:.2} ± {:.2} m/s ({:.2}–{:.2}), impact angle {:.1} ± {:.1}° \
             ({:.1}–{:.1}°)",
            speed.mean, speed.sd, speed.min, speed.max, angle.mean, angle.sd, angle.min, angle.max
        ),
    }
}

/// Label of the strip-share curve a run records (a study overlays it across cases).
pub const STRIP_SHARE_CURVE: &str = "share of the eroded mass per strip";
/// Label of the strip-share table a run records (a study shows it with a column per case).
pub const STRIP_SHARE_TABLE: &str = "share of the eroded mass per strip in percent";

/// Mean, sample standard deviation (n − 1), minimum and maximum of a set of values; NaN where undefined
/// (no values; the deviation of a single value).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Statistics {
    pub n: usize,
    pub mean: f64,
    pub sd: f64,
    pub min: f64,
    pub max: f64,
}

impl Statistics {
    pub fn of(v: &[f64]) -> Self {
        let n = v.len();
        let nan = f64::NAN;
        if n == 0 {
            return Statistics { n, mean: nan, sd: nan, min: nan, max: nan };
        }
        let mean = v.iter().sum::<f64>() / n as f64;
        let sd = if n > 1 {
            (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
        } else {
            nan
        };
        let min = v.iter().copied().fold(f64::INFINITY, f64::min);
        let max = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        Statistics { n, mean, sd, min, max }
    }
}

/// Where every injected stone is at the end of the run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Accounting {
    pub injected: u64,
    /// Removed for leaving the domain (bounced back out of the box, or fell out).
    pub out_of_domain: u64,
    pub in_pipe: u64,
    /// Resting on or touching the panel or clamp.
    pub on_panel: u64,
    /// Elsewhere in the protection box (floor, walls, in flight).
    pub in_box: u64,
    /// Member spheres the engine removed, and the members of the stones found missing: equal when every
    /// stone is accounted for.
    pub removed_spheres: u64,
    pub removed_members_of_missing_stones: u64,
}

impl Accounting {
    /// Every injected stone is in exactly one place, and the engine's removals match the missing stones.
    pub fn balanced(&self) -> bool {
        self.out_of_domain + self.in_pipe + self.on_panel + self.in_box == self.injected
            && self.removed_spheres == self.removed_members_of_missing_stones
    }
}

/// One stone's first impact outside the pipe.
#[derive(Clone, Debug)]
pub struct Impact {
    pub body: u32,
    pub template: usize,
    pub wall: usize,
    pub t: f64,
    pub speed: f64,
    /// Impact angle α in the x–z plane: between the velocity and the panel's up direction \[deg\]
    /// (90° for horizontal flight onto the upright panel, above 90° for a stone flying downwards).
    pub alpha_deg: f64,
    /// Direction of flight at the pipe exit in the x–z plane, above the horizontal \[deg\].
    pub entrance_deg: f64,
    pub pipe_collisions: u64,
    /// Height of the impact along the panel's long edge from its bottom edge \[m\] (panel impacts).
    pub panel_s: f64,
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> GravelometerError + '_ {
    move |source| GravelometerError::Io { path: path.to_owned(), source }
}

/// The impact angle α of a velocity in the x–z plane against the panel's up direction `up` \[deg\].
pub fn impact_angle_deg(v: Vec3, up: Vec3) -> f64 {
    let (vx, vz) = (v.x, v.z);
    let len = vx.hypot(vz);
    if len == 0.0 {
        return f64::NAN;
    }
    ((vx * up.x + vz * up.z) / (len * up.x.hypot(up.z))).clamp(-1.0, 1.0).acos().to_degrees()
}

/// The first impacts outside the pipe, in time order (ties by body id).
pub fn impacts(r: &SceneResults, plan: &Plan, walls: &[&str]) -> Vec<Impact> {
    let idx = |n: &str| walls.iter().position(|w| *w == n).unwrap_or(usize::MAX);
    let (panel, pipe) = (idx(PANEL), idx(PIPE));
    let (mesh, _) = geometry::panel(&plan.dims);
    let mut out: Vec<Impact> = r
        .events
        .objects()
        .filter(|((body, _), rec)| *body && rec.first.is_some())
        .map(|((_, id), rec): ((bool, u32), &ObjectRecord)| {
            let f = rec.first.expect("filtered");
            let entrance_deg = rec.crossing.map_or(f64::NAN, |c| c.dir.z.atan2(c.dir.x).to_degrees());
            let panel_s = match (f.wall == panel, f.triangle) {
                (true, Some(t)) if (t as usize) < mesh.triangles.len() => {
                    plan.frame.coords(mesh.centroid(t as usize)).1
                }
                _ => f64::NAN,
            };
            Impact {
                body: id,
                template: rec.template.max(0) as usize,
                wall: f.wall,
                t: f.t,
                speed: f.speed,
                alpha_deg: impact_angle_deg(f.velocity, plan.frame.up),
                entrance_deg,
                pipe_collisions: rec.collisions.get(pipe).copied().unwrap_or(0),
                panel_s,
            }
        })
        .collect();
    out.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.body.cmp(&b.body)));
    out
}

/// Where the stones are at the end (see [`Accounting`]).
pub fn accounting(r: &SceneResults, plan: &Plan, injected: u64) -> Accounting {
    let mut a = Accounting { injected, removed_spheres: r.removed_spheres, ..Default::default() };
    let f = &plan.frame;
    let reach = 2.0 * plan.stone_radius + plan.dims.clamp_thickness;
    for &(_, _, p) in &r.bodies {
        let (across, s) = f.coords(p);
        let off = (p - f.center).dot(f.normal);
        if p.x < 0.0 {
            a.in_pipe += 1;
        } else if off.abs() < reach
            && across.abs() < 0.5 * f.width + reach
            && (-reach..f.length + reach).contains(&s)
        {
            a.on_panel += 1;
        } else {
            a.in_box += 1;
        }
    }
    let present: std::collections::BTreeSet<u32> = r.bodies.iter().map(|b| b.0).collect();
    let mut missing = 0;
    for ((body, id), rec) in r.events.objects() {
        if body && (id as u64) < injected && !present.contains(&id) {
            missing += 1;
            a.removed_members_of_missing_stones +=
                r.template_members.get(rec.template.max(0) as usize).copied().unwrap_or(0) as u64;
        }
    }
    // Stones the log never saw (placed and removed within one step) count as missing without members.
    a.out_of_domain = injected.saturating_sub(r.bodies.len() as u64).max(missing);
    a
}

/// Linear interpolation of column `col` of a series at time `t` (NaN outside).
fn interpolate(rows: &[Vec<f64>], col: usize, t: f64) -> f64 {
    for w in rows.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        if a[0] <= t && t <= b[0] {
            let f = if b[0] > a[0] { (t - a[0]) / (b[0] - a[0]) } else { 1.0 };
            return a[col] + f * (b[col] - a[col]);
        }
    }
    f64::NAN
}

/// Histogram of `v` in `bins` equal bins over its range: (labels, counts).
fn histogram(v: &[f64], bins: usize, digits: usize) -> (Vec<String>, Vec<f64>) {
    let s = Statistics::of(v);
    if v.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let (lo, hi) = if s.max > s.min { (s.min, s.max) } else { (s.min - 0.5, s.max + 0.5) };
    let w = (hi - lo) / bins as f64;
    let mut counts = vec![0.0; bins];
    for x in v {
        counts[(((x - lo) / w).floor() as usize).min(bins - 1)] += 1.0;
    }
    let labels = (0..bins)
        .map(|k| format!("{:.*}–{:.*}", digits, lo + w * k as f64, digits, lo + w * (k + 1) as f64))
        .collect();
    (labels, counts)
}

/// Writes every result file and adds the scalars, lines and artifacts to `summary`.
pub fn report(
    cfg: &GravelometerConfig,
    plan: &Plan,
    strips: &[usize],
    r: &SceneResults,
    ctx: &RunContext,
    summary: &mut RunSummary,
) -> Result<(), GravelometerError> {
    let dir = ctx.dir;
    let walls = [PANEL, CLAMP, PIPE, BOX];
    let n_strips = plan.dims.strips;
    let (mesh, _) = geometry::panel(&plan.dims);
    let panel = r.mesh_walls.iter().find(|w| w.name == PANEL).ok_or_else(|| GravelometerError::Config {
        key: "panel".into(),
        message: "the scene has no panel wall".into(),
    })?;
    let em = &panel.eroded_mass;
    // Strip shares.
    let mut strip_mass = vec![0.0; n_strips];
    let mut strip_impacts = vec![0u64; n_strips];
    for (t, &k) in strips.iter().enumerate() {
        strip_mass[k - 1] += em[t];
        strip_impacts[k - 1] += panel.impacts[t];
    }
    let total: f64 = strip_mass.iter().sum();
    let share: Vec<f64> =
        strip_mass.iter().map(|m| if total > 0.0 { 100.0 * m / total } else { f64::NAN }).collect();
    let len = plan.dims.panel_length;
    let rows: Vec<Vec<String>> = (0..n_strips)
        .map(|k| {
            let top = len * (1.0 - k as f64 / n_strips as f64);
            let bottom = len * (1.0 - (k + 1) as f64 / n_strips as f64);
            vec![
                (k + 1).to_string(),
                fmt_f64(bottom),
                fmt_f64(top),
                fmt_f64(strip_mass[k]),
                gap(share[k]),
                strip_impacts[k].to_string(),
            ]
        })
        .collect();
    let path = dir.path("strips.csv");
    spatter_io::csv::write_table(
        &path,
        &["strip", "from_m", "to_m", "eroded_mass_kg", "share_percent", "impacts"],
        &rows,
    )
    .map_err(io_err(&path))?;
    // For a study: the shares of every case in one chart (strip number against share) and one table
    // with a column per case (docs/studies.md, "Curves and tables side by side").
    summary.curves.push(CurveRecord {
        label: STRIP_SHARE_CURVE.into(),
        csv: path.clone(),
        x_column: "strip".into(),
        y_column: "share_percent".into(),
        x_label: "strip (1 = top)".into(),
        y_label: "share of the eroded mass [%]".into(),
    });
    summary.artifacts.push(("damage share per strip".into(), path));
    let png = dir.path("strips.png");
    let names: Vec<String> = (1..=n_strips).map(|k| format!("strip {k}")).collect();
    bar_chart_png(
        &png,
        &format!("{}: share of the eroded mass per strip (1 = top)", cfg.input.standard.label()),
        "share of eroded mass [%]",
        &names,
        &[Bars { label: "simulation", values: &share, intervals: &[] }],
    )
    .map_err(io_err(&png))?;
    summary.artifacts.push(("damage share per strip (chart)".into(), png));
    let mut rows = Vec::new();
    for (k, s) in share.iter().enumerate() {
        if s.is_finite() {
            let name = format!("strip_{}_share_percent", k + 1);
            summary.scalar(&name, *s);
            rows.push((format!("strip {}", k + 1), name));
        }
    }
    if !rows.is_empty() {
        summary.scalar_tables.push(ScalarTableRecord { label: STRIP_SHARE_TABLE.into(), rows });
    }
    summary.scalar("panel_eroded_mass_kg", total);
    // Damage centroid: height along the panel from its bottom edge, and height above the pipe axis.
    if total > 0.0 {
        let (mut s_c, mut z_c) = (0.0, 0.0);
        for (t, m) in em.iter().enumerate() {
            let c = mesh.centroid(t);
            s_c += m * plan.frame.coords(c).1;
            z_c += m * c.z;
        }
        summary.scalar("damage_centroid_along_panel_m", s_c / total);
        summary.scalar("damage_centroid_height_m", z_c / total);
        summary.headline.push(format!(
            "panel: {total:.4e} kg eroded; damage centroid {:.1} mm above the pipe axis ({:.1} mm up the panel from \
             its bottom edge); shares per strip (1 = top): {}",
            1e3 * z_c / total,
            1e3 * s_c / total,
            share.iter().map(|s| format!("{s:.1} %")).collect::<Vec<_>>().join(", ")
        ));
    } else {
        summary.headline.push("panel: no eroded mass (no stone reached it)".into());
    }
    // Map in panel coordinates and the VTU.
    let cols = geometry::panel_columns(plan.dims.panel_width, plan.dims.triangle_size);
    let nrows = geometry::panel_rows(len, plan.dims.triangle_size, n_strips);
    let cell_area = plan.dims.panel_width * len / (cols * nrows) as f64;
    let mut cells = vec![0.0; cols * nrows];
    for (t, m) in em.iter().enumerate() {
        let (i, j) = ((t / 2) / cols, (t / 2) % cols);
        cells[j + cols * i] += m / cell_area;
    }
    let x_faces: Vec<f64> =
        (0..=cols).map(|j| 1e3 * plan.dims.panel_width * (j as f64 / cols as f64 - 0.5)).collect();
    let y_faces: Vec<f64> = (0..=nrows).map(|i| 1e3 * len * i as f64 / nrows as f64).collect();
    let lines: Vec<(f64, String)> = (0..n_strips)
        .map(|k| (1e3 * len * (1.0 - k as f64 / n_strips as f64), format!("{}", k + 1)))
        .collect();
    let png = dir.path("panel_damage.png");
    field_map_png_with_lines(
        &png,
        &FieldMap {
            x_faces: &x_faces,
            y_faces: &y_faces,
            values: &cells,
            title: &format!(
                "{}: eroded mass on the panel (seen from the pipe), strips numbered from the top",
                cfg.input.standard.label()
            ),
            x_label: "across the panel [mm]",
            y_label: "up the panel from its bottom edge [mm]",
            colorbar_label: "eroded mass per area [kg/m²]",
        },
        &lines,
    )
    .map_err(io_err(&png))?;
    summary.artifacts.push(("damage map on the panel".into(), png));
    let vtu = dir.path("panel_damage.vtu");
    let strip_i: Vec<i64> = strips.iter().map(|&s| s as i64).collect();
    let per_area: Vec<f64> = (0..em.len()).map(|t| em[t] / mesh.area(t)).collect();
    Vtu::triangles(&mesh.vertices, &mesh.triangles)
        .cell_scalar("eroded_mass_kg", em)
        .cell_scalar("eroded_mass_per_area_kg_m2", &per_area)
        .cell_int("impacts", &panel.impacts.iter().map(|&i| i as i64).collect::<Vec<_>>())
        .cell_int("strip", &strip_i)
        .write(&vtu)
        .map_err(io_err(&vtu))?;
    // The map as a record, so that a study's gallery redraws every case's panel on one colour scale.
    summary.maps.push(MeshMapRecord {
        label: "panel damage".into(),
        vtu: vtu.clone(),
        array: "eroded_mass_per_area_kg_m2".into(),
        view_dir: (-plan.frame.normal).to_array(),
        up: plan.frame.up.to_array(),
        title: format!("{}: eroded mass on the panel (seen from the pipe)", cfg.input.standard.label()),
        colorbar_label: "eroded mass per area [kg/m²]".into(),
        scale: None,
    });
    summary.artifacts.push(("damage on the panel (ParaView)".into(), vtu));

    // Impacts outside the pipe; statistics of the first N on the panel.
    let all = impacts(r, plan, &walls);
    let n = get(cfg.input.output.first_n);
    let first: Vec<&Impact> = all.iter().filter(|i| i.wall == 0).take(n).collect();
    let template_name = |k: usize| plan.stones.get(k).map_or("?".to_string(), |s| s.name.clone());
    let rows: Vec<Vec<String>> = all
        .iter()
        .enumerate()
        .map(|(k, i)| {
            vec![
                (k + 1).to_string(),
                i.body.to_string(),
                template_name(i.template),
                walls.get(i.wall).unwrap_or(&"?").to_string(),
                fmt_f64(i.t),
                fmt_f64(i.speed),
                gap(i.alpha_deg),
                gap(i.entrance_deg),
                i.pipe_collisions.to_string(),
                gap(i.panel_s),
            ]
        })
        .collect();
    let path = dir.path("impacts.csv");
    spatter_io::csv::write_table(
        &path,
        &[
            "impact",
            "stone",
            "template",
            "wall",
            "t_s",
            "speed_m_s",
            "angle_deg",
            "entrance_angle_deg",
            "pipe_collisions",
            "height_on_panel_m",
        ],
        &rows,
    )
    .map_err(io_err(&path))?;
    summary.artifacts.push(("first impact of every stone outside the pipe".into(), path));
    let quantities: [(&str, &str, Vec<f64>); 5] = [
        ("impact_speed", "m_s", first.iter().map(|i| i.speed).collect()),
        ("impact_angle", "deg", first.iter().map(|i| i.alpha_deg).collect()),
        ("entrance_angle", "deg", first.iter().map(|i| i.entrance_deg).filter(|x| x.is_finite()).collect()),
        ("pipe_collisions", "", first.iter().map(|i| i.pipe_collisions as f64).collect()),
        ("height_on_panel", "m", first.iter().map(|i| i.panel_s).filter(|x| x.is_finite()).collect()),
    ];
    let mut rows = Vec::new();
    for (base, unit, v) in &quantities {
        let s = Statistics::of(v);
        let name = if unit.is_empty() { base.to_string() } else { format!("{base}_{unit}") };
        rows.push(vec![name, s.n.to_string(), gap(s.mean), gap(s.sd), gap(s.min), gap(s.max)]);
        for (what, x) in [("mean", s.mean), ("sd", s.sd), ("min", s.min), ("max", s.max)] {
            if x.is_finite() {
                let key =
                    if unit.is_empty() { format!("{base}_{what}") } else { format!("{base}_{what}_{unit}") };
                summary.scalar(&key, x);
            }
        }
    }
    // Share of the first stones striking with α > 90°, against the panel's up direction (moving down on
    // the upright SAE panel): the study found more above 90° than below there, "under the influence of
    // gravity". Over the stones with a defined angle.
    let alphas: Vec<f64> = quantities[1].2.iter().copied().filter(|a| a.is_finite()).collect();
    if !alphas.is_empty() {
        let down = alphas.iter().filter(|&&a| a > 90.0).count();
        summary.scalar("impact_angle_above_90_share", down as f64 / alphas.len() as f64);
    }
    let path = dir.path("impact_statistics.csv");
    spatter_io::csv::write_table(&path, &["quantity", "n", "mean", "sd", "min", "max"], &rows)
        .map_err(io_err(&path))?;
    summary.artifacts.push((format!("impact statistics of the first {n} stones on the panel"), path));
    let speed = Statistics::of(&quantities[0].2);
    let angle = Statistics::of(&quantities[1].2);
    summary.headline.push(impact_headline(&speed, &angle));
    for (k, (name, _, v)) in quantities.iter().take(2).enumerate() {
        let (labels, counts) = histogram(v, 8, 1);
        let png = dir.path(&format!("{name}_histogram.png"));
        bar_chart_png(
            &png,
            &format!(
                "first {} stones on the panel: {}",
                v.len(),
                if k == 0 { "impact speed [m/s]" } else { "impact angle α [deg]" }
            ),
            "stones",
            &labels,
            &[Bars { label: "count", values: &counts, intervals: &[] }],
        )
        .map_err(io_err(&png))?;
        summary.artifacts.push((format!("histogram of {name}"), png));
    }
    let pipe_hits: u64 = all.iter().map(|i| i.pipe_collisions).sum();
    if !all.is_empty() {
        summary.scalar("pipe_collisions_per_stone", pipe_hits as f64 / all.len() as f64);
    }
    // Eroded mass after K impacts (panel, clamp or fly-over into the box, as counted in the study).
    let k = get(cfg.input.output.cutoff_impacts);
    summary.scalar("impacts_counted", all.len() as f64);
    if all.len() >= k {
        let t_k = all[k - 1].t;
        let path = dir.path("wear.csv");
        let (head, rows) = spatter_io::csv::read_series(&path).map_err(io_err(&path))?;
        let col = head.iter().position(|h| h == "panel_eroded_mass_kg");
        let m = col.map_or(f64::NAN, |c| interpolate(&rows, c, t_k));
        if m.is_finite() {
            summary.scalar(&format!("eroded_mass_after_{k}_impacts_kg"), m);
            summary.scalar(&format!("time_of_impact_{k}_s"), t_k);
            summary
                .headline
                .push(format!("after {k} impacts (t = {t_k:.4} s): {m:.4e} kg eroded from the panel"));
        }
    } else {
        summary.headline.push(format!(
            "only {} stones hit the panel, clamp or box: no eroded mass after {k} impacts (lengthen duration_s)",
            all.len()
        ));
    }
    // Where every stone ended.
    let injected = summary.scalars.iter().find(|(n, _)| n == "injected_count").map_or(0.0, |s| s.1) as u64;
    let a = accounting(r, plan, injected);
    let path = dir.path("stones.csv");
    spatter_io::csv::write_table(
        &path,
        &["where", "stones"],
        &[
            vec!["injected".into(), a.injected.to_string()],
            vec!["on_panel".into(), a.on_panel.to_string()],
            vec!["in_box".into(), a.in_box.to_string()],
            vec!["in_pipe".into(), a.in_pipe.to_string()],
            vec!["out_of_domain".into(), a.out_of_domain.to_string()],
        ],
    )
    .map_err(io_err(&path))?;
    summary.artifacts.push(("where the stones ended".into(), path));
    for (name, v) in [
        ("stones_injected", a.injected),
        ("stones_on_panel", a.on_panel),
        ("stones_in_box", a.in_box),
        ("stones_in_pipe", a.in_pipe),
        ("stones_out_of_domain", a.out_of_domain),
    ] {
        summary.scalar(name, v as f64);
    }
    summary.headline.push(format!(
        "stones: {} injected = {} on the panel + {} in the box + {} in the pipe + {} out of the domain{}",
        a.injected,
        a.on_panel,
        a.in_box,
        a.in_pipe,
        a.out_of_domain,
        if a.balanced() {
            ""
        } else {
            " — WARNING: the removed member spheres do not match the missing stones"
        }
    ));
    summary.scalar("launch_speed_m_s", plan.launch.length());
    summary.scalar("dt_s", plan.dt);
    first_stone(plan, r, ctx, summary)?;
    Ok(())
}

/// The first stone's flight (x(t), highest point in the pipe, pipe-wall collisions), from
/// `trajectories.csv` and the event log: the single-particle diagnostics.
fn first_stone(
    plan: &Plan,
    r: &SceneResults,
    ctx: &RunContext,
    summary: &mut RunSummary,
) -> Result<(), GravelometerError> {
    let path = ctx.dir.path("trajectories.csv");
    let Ok((head, rows)) = spatter_io::csv::read_series(&path) else { return Ok(()) };
    let col = |n: &str| head.iter().position(|h| h == n);
    let (Some(body), Some(id), Some(t), Some(x), Some(z)) =
        (col("body"), col("id"), col("t_s"), col("x_m"), col("z_m"))
    else {
        return Ok(());
    };
    let rows: Vec<&Vec<f64>> = rows.iter().filter(|r| r[body] == 1.0 && r[id] == 0.0).collect();
    if rows.is_empty() {
        return Ok(());
    }
    let in_pipe: Vec<&&Vec<f64>> = rows.iter().filter(|r| r[x] < 0.0).collect();
    let max_height = in_pipe.iter().map(|r| r[z]).fold(f64::NEG_INFINITY, f64::max);
    if max_height.is_finite() {
        summary.scalar("first_stone_max_height_in_pipe_m", max_height);
    }
    // Speed along the axis and time at the pipe exit (x = 0), interpolated between the logged states.
    if let Some(vx) = col("vx_m_s") {
        if let Some(w) = rows.windows(2).find(|w| w[0][x] < 0.0 && w[1][x] >= 0.0) {
            let f = -w[0][x] / (w[1][x] - w[0][x]);
            let lerp = |c: usize| w[0][c] + f * (w[1][c] - w[0][c]);
            summary.scalar("first_stone_exit_time_s", lerp(t));
            summary.scalar("first_stone_exit_speed_m_s", lerp(vx));
        }
    }
    let pipe = 2;
    let hits = r.events.objects().find(|(k, _)| *k == (true, 0)).map_or(0, |(_, rec)| rec.collisions[pipe]);
    summary.scalar("first_stone_pipe_collisions", hits as f64);
    let points: Vec<(f64, f64)> = rows.iter().map(|r| (r[t], r[x])).collect();
    let png = ctx.dir.path("first_stone_x_t.png");
    Chart::new("first stone: position along the pipe axis (pipe exit at 0)", "t [s]", "x [m]")
        .line("x(t)", &points)
        .dashed("pipe exit", &[(points[0].0, 0.0), (points[points.len() - 1].0, 0.0)], (120, 120, 120))
        .dashed(
            "panel centre",
            &[
                (points[0].0, plan.dims.panel_distance),
                (points[points.len() - 1].0, plan.dims.panel_distance),
            ],
            (200, 80, 80),
        )
        .save_png(&png)
        .map_err(io_err(&png))?;
    summary.artifacts.push(("first stone x(t)".into(), png));
    summary.headline.push(format!(
        "first stone: highest point in the pipe {:.2} mm above the axis, {hits} pipe-wall collisions",
        1e3 * max_height
    ));
    Ok(())
}
