//! Files of a snow run: CSV tables with units in the headers, regime-map pictures (PNG + SVG) and the
//! `regime_map.json` wall rule.

use super::bisection::{BracketStatus, CriticalSpeed};
use super::config::GridConfig;
use super::regime::ImpactRecord;
use spatter_core::regime::{PolyFit, RegimeMap};
use spatter_io::csv::CsvSeries;
use spatter_io::plot::Chart;
use std::io;
use std::path::{Path, PathBuf};

/// Red (stick) and blue (bounce) of the thesis's regime maps.
pub const STICK_RGB: (u8, u8, u8) = (214, 39, 40);
pub const BOUNCE_RGB: (u8, u8, u8) = (31, 119, 180);
/// Colour of interface points and fitted boundaries.
pub const INTERFACE_RGB: (u8, u8, u8) = (0, 140, 60);

/// Distinct line colours for sensitivity cases: black for the baseline, then pairs of shades per varied
/// property (E, ν, Γ, σ_y: light for the low value, dark for the high one).
pub fn case_colour(i: usize) -> (u8, u8, u8) {
    const C: [(u8, u8, u8); 9] = [
        (0, 0, 0),
        (230, 159, 0),
        (160, 90, 0),
        (86, 180, 233),
        (0, 80, 160),
        (240, 120, 120),
        (170, 0, 0),
        (90, 200, 120),
        (0, 110, 50),
    ];
    if i < C.len() {
        C[i]
    } else {
        let t = (i as f64 * 0.618).fract();
        spatter_io::plot::viridis(t)
    }
}

/// How the axes of pictures are scaled.
#[derive(Clone, Copy, Debug)]
pub struct Axes {
    pub normalised: bool,
    /// Velocity scale \[m/s\].
    pub v_scale: f64,
    /// Diameter scale \[m\].
    pub d_scale: f64,
}

impl Axes {
    pub fn of(grid: &GridConfig) -> Self {
        Axes {
            normalised: grid.normalised_axes,
            v_scale: grid.velocity_scale_m_s,
            d_scale: grid.diameter_scale_m,
        }
    }

    /// Plot coordinate of a speed \[m/s\].
    pub fn v(&self, v: f64) -> f64 {
        if self.normalised {
            v / self.v_scale
        } else {
            v
        }
    }

    /// Plot coordinate of a diameter \[m\] (µm on SI axes).
    pub fn d(&self, d: f64) -> f64 {
        if self.normalised {
            d / self.d_scale
        } else {
            d * 1e6
        }
    }

    pub fn v_label(&self) -> String {
        if self.normalised {
            format!("normal impact speed / {} m/s", self.v_scale)
        } else {
            "normal impact speed [m/s]".into()
        }
    }

    pub fn d_label(&self) -> String {
        if self.normalised {
            format!("particle diameter / {} mm", self.d_scale * 1e3)
        } else {
            "particle diameter [µm]".into()
        }
    }
}

/// Column names of [`write_impacts`].
pub const IMPACT_COLUMNS: [&str; 22] = [
    "case",
    "diameter_m",
    "normal_speed_m_s",
    "tangential_speed_m_s",
    "angle_deg",
    "aim_x_m",
    "aim_y_m",
    "stick",
    "decision",
    "restitution_input",
    "restitution_realised",
    "rebound_normal_m_s",
    "rebound_tangential_m_s",
    "max_overlap_m",
    "contact_duration_s",
    "slip_speed_m_s",
    "end_tangential_speed_m_s",
    "dt_s",
    "hertz_time_s",
    "steps",
    "energy_ratio",
    "energy_created",
];

/// Every impact, one row each (`case` numbers sensitivity cases; `decision` 0 separated, 1 bound, 2 check
/// time). Units are in the column names. `max_overlap_m` is the largest overlap from first touch to the
/// end of the run, at least the peak of the first compression for sticks too (runs are not ended before
/// it); the `rebound_*` columns of a stick are its velocity when the run was decided, and its
/// `contact_duration_s` the time simulated (docs/snow.md §1). `energy_ratio` is the rebound's kinetic
/// energy over the impact's (0 for sticks) and `energy_created` is 1 when it exceeds 1 + 1e-3: energy made
/// by the integration, a numerical failure ([`ImpactResult::created_energy`]).
///
/// [`ImpactResult::created_energy`]: super::impact::ImpactResult::created_energy
pub fn write_impacts(path: &Path, sets: &[(usize, &[ImpactRecord])]) -> io::Result<()> {
    let mut csv = CsvSeries::create(path, &IMPACT_COLUMNS)?;
    for (case, records) in sets {
        for r in records.iter() {
            let v = r.result.rebound_velocity;
            csv.row(&[
                *case as f64,
                r.diameter,
                r.normal_speed,
                r.tangential_speed,
                r.angle_deg,
                r.aim[0],
                r.aim[1],
                if r.sticks() { 1.0 } else { 0.0 },
                r.result.decision.code(),
                r.restitution_input,
                r.result.restitution,
                v[2],
                (v[0] * v[0] + v[1] * v[1]).sqrt(),
                r.result.max_overlap,
                r.result.contact_duration,
                r.result.slip_speed,
                r.result.tangential_speed,
                r.dt,
                r.hertz_time,
                r.result.steps as f64,
                r.result.energy_ratio,
                if r.result.created_energy() { 1.0 } else { 0.0 },
            ])?;
        }
    }
    csv.flush()
}

/// Interface points: the grid bracket `[d, v_stick, v_bounce]` and the boundary speed used for the fit
/// (bracket midpoint, or refined by bisection), with normalised values.
pub fn write_interface(
    path: &Path,
    brackets: &[[f64; 3]],
    points: &[[f64; 2]],
    axes: &Axes,
) -> io::Result<()> {
    let mut csv = CsvSeries::create(
        path,
        &[
            "diameter_m",
            "highest_stick_m_s",
            "lowest_bounce_m_s",
            "critical_normal_speed_m_s",
            "diameter_norm",
            "critical_normal_speed_norm",
        ],
    )?;
    for (b, p) in brackets.iter().zip(points) {
        csv.row(&[p[0], b[1], b[2], p[1], p[0] / axes.d_scale, p[1] / axes.v_scale])?;
    }
    csv.flush()
}

/// Bisection results.
pub fn write_critical_speeds(path: &Path, speeds: &[CriticalSpeed]) -> io::Result<()> {
    let mut csv = CsvSeries::create(
        path,
        &[
            "diameter_m",
            "critical_normal_speed_m_s",
            "highest_stick_m_s",
            "lowest_bounce_m_s",
            "status",
            "impacts",
            "energy_created",
        ],
    )?;
    for c in speeds {
        let status = match c.status {
            BracketStatus::Found => 0.0,
            BracketStatus::BelowRange => -1.0,
            BracketStatus::AboveRange => 1.0,
        };
        // Outside the bracket the critical speed (and, above it, the lowest bounce) is undefined: a gap.
        let found = c.status == BracketStatus::Found;
        let above = c.status == BracketStatus::AboveRange;
        csv.row_with_gaps(&[
            Some(c.diameter),
            found.then_some(c.v_crit),
            Some(c.low),
            (!above).then_some(c.high),
            Some(status),
            Some(c.impacts as f64),
            Some(c.energy_created as f64),
        ])?;
    }
    csv.flush()
}

/// Writes `regime_map.json`.
pub fn write_regime_map(path: &Path, map: &RegimeMap) -> io::Result<()> {
    let text = serde_json::to_string_pretty(map).map_err(io::Error::other)?;
    std::fs::write(path, text + "\n")
        .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))
}

/// Samples a fit of v_crit(d) as plot points over its range.
pub fn fit_curve(fit: &PolyFit, axes: &Axes) -> Vec<(f64, f64)> {
    let [lo, hi] = fit.x_range;
    (0..=100)
        .map(|i| {
            let d = if fit.log10 {
                lo * (hi / lo).powf(i as f64 / 100.0)
            } else {
                lo + (hi - lo) * i as f64 / 100.0
            };
            (axes.v(fit.eval(d)), axes.d(d))
        })
        .collect()
}

/// Saves `chart` as `stem.png` (and `stem.svg` when `svg`); returns the PNG path.
pub fn save_chart(
    chart: &Chart,
    dir: &spatter_io::run::RunDir,
    stem: &str,
    svg: bool,
) -> io::Result<PathBuf> {
    let png = dir.path(&format!("{stem}.png"));
    chart.save_png(&png)?;
    if svg {
        chart.save_svg(&dir.path(&format!("{stem}.svg")))?;
    }
    Ok(png)
}

/// A y range for data between `lo` and `hi` (linear axis) with room above the data for a legend of
/// `entries` rows: the legend sits in the upper right corner and would otherwise hide the points there
/// (about 19 px per row and 25 px of frame on a 900 × 650 picture with a plot area of ~545 px).
pub fn y_range_with_legend(lo: f64, hi: f64, entries: usize) -> (f64, f64) {
    let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) };
    let bottom = lo - 0.05 * span;
    let room = (0.05 + 0.035 * entries as f64).min(0.5);
    (bottom, (hi - room * bottom) / (1.0 - room))
}

/// The regime map picture: stick red, bounce blue, interface points and the fitted boundary.
pub fn regime_chart(
    title: &str,
    records: &[ImpactRecord],
    interface: &[[f64; 2]],
    fit: Option<&PolyFit>,
    axes: &Axes,
) -> Chart {
    let stick: Vec<(f64, f64)> =
        records.iter().filter(|r| r.sticks()).map(|r| (axes.v(r.normal_speed), axes.d(r.diameter))).collect();
    let bounce: Vec<(f64, f64)> = records
        .iter()
        .filter(|r| !r.sticks())
        .map(|r| (axes.v(r.normal_speed), axes.d(r.diameter)))
        .collect();
    let mut chart = Chart::new(title, &axes.v_label(), &axes.d_label())
        .markers(&format!("stick ({})", stick.len()), &stick, STICK_RGB)
        .markers(&format!("bounce ({})", bounce.len()), &bounce, BOUNCE_RGB);
    let ds = records.iter().map(|r| axes.d(r.diameter));
    let (lo, hi) = ds.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), d| (a.min(d), b.max(d)));
    if lo.is_finite() && hi.is_finite() {
        let (y0, y1) = y_range_with_legend(lo, hi, 3);
        chart = chart.y_range(y0, y1);
    }
    if let Some(f) = fit {
        chart = chart.line_colored("fitted boundary v_crit(d)", &fit_curve(f, axes), INTERFACE_RGB);
    } else if !interface.is_empty() {
        let pts: Vec<(f64, f64)> = interface.iter().map(|p| (axes.v(p[1]), axes.d(p[0]))).collect();
        chart = chart.line_colored("interface", &pts, INTERFACE_RGB);
    }
    chart
}
