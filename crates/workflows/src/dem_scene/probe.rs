//! Probe indentation (Jasion 2013, *Toward a Physics Based Entrainment Model for Simulation of Helicopter
//! Brownout*, PhD thesis, University of Southampton, Appendix C, after Danby's experiments): a rigid probe
//! — a sphere, a flat-ended rod or a closed mesh — is driven at constant speed into the bed of the scene,
//! the reaction force on it is sampled at a fixed rate, and the trace is analysed
//! ([`crate::bed_lab::probe_analysis`]). Keys in `docs/bed.md`.
//!
//! The probe is a wall of the scene (named `probe`) with a constant-velocity motion, so it meets the
//! spheres through the scene's contact law with its own material pair, and its force is the sum of its
//! contact forces. The *depth* y is how far the probe's leading point has passed the bed surface under it:
//! the surface is the highest point (along the drive direction) of the spheres whose centres lie within
//! the probe's footprint — the cylinder of the probe's largest radius about its drive axis — at the start.

use super::config::SceneConfig;
use crate::bed_lab::probe_analysis::{analyse, ProbeAnalysis, GAMMA_MAX_LENGTH_DP};
use serde::{Deserialize, Serialize};
use spatter_core::check::Checker;
use spatter_core::comm::Comm;
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use spatter_core::Vec3;
use spatter_dem::contact::ContactLaw;
use spatter_dem::error::DemError;
use spatter_dem::sim::Simulation;
use spatter_dem::walls::{Ball, MeshWall, Rod, Wall, WallKinematics, WallShape};
use spatter_io::plot::Chart;
use spatter_io::run::{RunContext, RunSummary};
use std::path::PathBuf;

/// Name of the probe's wall (a `[[walls]]` entry may not take it).
pub const WALL_NAME: &str = "probe";

/// `[probe]`: a probe driven into the bed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeConfig {
    /// Material of the probe (a key of `[materials]`; its pair with the bed's material sets the contact).
    pub material: String,
    /// Geometry at t = 0.
    pub shape: ProbeShape,
    /// Drive direction (normalised) \[default: straight down, (0, 0, −1)\].
    #[serde(default = "down")]
    pub direction: Vec3,
    /// Drive speed \[m/s\].
    pub speed_m_s: f64,
    /// The run ends when the depth below the bed surface reaches this \[m\].
    pub max_depth_m: f64,
    /// Force samples per second \[Hz\] (default 500, the experiment's rate).
    #[serde(default = "default_rate")]
    pub sample_hz: f64,
    /// Depth from which the probe counts as immersed and the trace is analysed \[m\] (default: the
    /// probe's diameter — the sphere's, the rod's, or the mesh's largest width across the drive).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub immersion_depth_m: Option<f64>,
}

fn down() -> Vec3 {
    Vec3::new(0.0, 0.0, -1.0)
}
fn default_rate() -> f64 {
    500.0
}
fn one() -> f64 {
    1.0
}

/// Probe geometry (`type = "sphere" | "rod" | "mesh"`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum ProbeShape {
    /// A solid sphere.
    Sphere { center_m: Vec3, radius_m: f64 },
    /// A solid rod with a flat leading end, its axis along the drive direction: `tip_m` is the centre of
    /// the leading end.
    Rod { tip_m: Vec3, radius_m: f64, length_m: f64 },
    /// A closed triangle mesh (STL/OBJ, coordinates × `scale`) where it is at t = 0.
    Mesh {
        file: PathBuf,
        #[serde(default = "one")]
        scale: f64,
    },
}

/// Checks of `[probe]` that need no files beyond the scenario.
pub(crate) fn check(c: &mut Checker, cfg: &SceneConfig, p: &ProbeConfig) {
    c.nested("probe", |c| {
        if !cfg.materials.contains_key(&p.material) {
            let known: Vec<&str> = cfg.materials.keys().map(String::as_str).collect();
            c.fail("material", format!("material = \"{}\" is not in [materials] ({})", p.material, known.join(", ")));
        }
        if !(p.direction.is_finite() && p.direction.length() > 0.0) {
            c.fail("direction", format!("direction = {} must be a non-zero vector", p.direction));
        }
        if !(p.speed_m_s.is_finite() && p.speed_m_s > 0.0) {
            c.fail("speed_m_s", format!("speed_m_s = {} must be a positive speed in m/s", p.speed_m_s));
        }
        if !(p.max_depth_m.is_finite() && p.max_depth_m > 0.0) {
            c.fail("max_depth_m", format!("max_depth_m = {} must be a positive depth in m", p.max_depth_m));
        }
        if !(p.sample_hz.is_finite() && p.sample_hz > 0.0) {
            c.fail("sample_hz", format!("sample_hz = {} must be a positive rate in Hz", p.sample_hz));
        } else if cfg.dt_s > 0.0 && p.sample_hz * cfg.dt_s > 1.0 {
            c.fail(
                "sample_hz",
                format!(
                    "sample_hz = {} is above one sample per step (1/dt_s = {:.6e} Hz); sample at most every step",
                    p.sample_hz,
                    1.0 / cfg.dt_s
                ),
            );
        }
        if let Some(d) = p.immersion_depth_m {
            if !(d.is_finite() && d >= 0.0 && d < p.max_depth_m) {
                c.fail(
                    "immersion_depth_m",
                    format!("immersion_depth_m = {d} must be ≥ 0 and below max_depth_m = {}", p.max_depth_m),
                );
            }
        }
        c.nested("shape", |c| match &p.shape {
            ProbeShape::Sphere { center_m, radius_m } => {
                c.finite_vec("center_m", *center_m);
                c.positive("radius_m", *radius_m);
            }
            ProbeShape::Rod { tip_m, radius_m, length_m } => {
                c.finite_vec("tip_m", *tip_m);
                c.positive("radius_m", *radius_m);
                c.positive("length_m", *length_m);
            }
            ProbeShape::Mesh { file, scale } => {
                c.positive("scale", *scale);
                c.mesh_file("file", file);
            }
        });
        if p.speed_m_s > 0.0 && p.max_depth_m > 0.0 && cfg.duration_s < p.max_depth_m / p.speed_m_s {
            c.fail(
                "max_depth_m",
                format!(
                    "max_depth_m = {} at speed_m_s = {} takes at least {:.6} s, longer than duration_s = {}",
                    p.max_depth_m,
                    p.speed_m_s,
                    p.max_depth_m / p.speed_m_s,
                    cfg.duration_s
                ),
            );
        }
        if cfg.gravity_m_s2.length() == 0.0 {
            c.fail("material", "a probe run needs gravity: the spectrum is normalised by the particle weight");
        }
        if cfg.pour.is_some() {
            c.fail("shape", "a probe runs in a settled bed: pour first, then start from its bed file ([bed] file)");
        }
        if cfg.walls.iter().any(|w| w.name == WALL_NAME) {
            c.fail("shape", format!("the probe is the wall `{WALL_NAME}`; rename the [[walls]] entry of that name"));
        }
    });
}

/// The probe as a wall of material `material`, moving along its direction at its speed.
pub(crate) fn wall(p: &ProbeConfig, material: u16) -> Result<Wall, DemError> {
    let dir = p.direction.normalize();
    let shape = match &p.shape {
        ProbeShape::Sphere { center_m, radius_m } => {
            WallShape::Ball(Ball { center: *center_m, radius: *radius_m })
        }
        ProbeShape::Rod { tip_m, radius_m, length_m } => {
            WallShape::Rod(Rod { base: *tip_m, axis: -dir, radius: *radius_m, length: *length_m })
        }
        ProbeShape::Mesh { file, scale } => {
            WallShape::Mesh(Box::new(MeshWall::new(TriMesh::load(file, *scale)?)))
        }
    };
    Ok(Wall {
        name: WALL_NAME.into(),
        shape,
        material,
        motion: Motion::Translation { velocity: dir * p.speed_m_s },
    })
}

/// The probe's leading point, axis point and footprint radius at t = 0 along unit `dir`.
fn geometry(shape: &WallShape, dir: Vec3) -> (f64, Vec3, f64) {
    match shape {
        WallShape::Ball(b) => (b.center.dot(dir) + b.radius, b.center, b.radius),
        WallShape::Rod(r) => (r.base.dot(dir), r.base, r.radius),
        WallShape::Mesh(m) => {
            let v = &m.mesh.vertices;
            let c = v.iter().fold(Vec3::ZERO, |a, x| a + *x) / v.len().max(1) as f64;
            let lead = v.iter().map(|x| x.dot(dir)).fold(f64::NEG_INFINITY, f64::max);
            let rf = v.iter().map(|x| perp(*x - c, dir)).fold(0.0, f64::max);
            (lead, c, rf)
        }
        _ => (0.0, Vec3::ZERO, 0.0),
    }
}

/// Length of the part of `v` perpendicular to unit `dir`.
fn perp(v: Vec3, dir: Vec3) -> f64 {
    (v - v.dot(dir) * dir).length()
}

/// The state of a probe run (part of the checkpoint).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProbeState {
    /// Index of the probe's wall.
    pub wall: usize,
    /// Unit drive direction.
    pub dir: Vec3,
    /// Position of the leading point along `dir` at t = 0 \[m\].
    pub lead0: f64,
    /// Position of the bed surface under the probe along `dir` at t = 0 \[m\].
    pub surface: f64,
    /// Depth from which the trace is analysed \[m\].
    pub immersion: f64,
    /// Mean diameter \[m\] and weight \[N\] of the bed's spheres at t = 0.
    pub d_p: f64,
    pub w_p: f64,
    /// Samples so far: (t \[s\], depth \[m\], force \[N\]).
    pub samples: Vec<(f64, f64, f64)>,
    /// Depth after the latest step \[m\].
    pub depth_now: f64,
}

impl ProbeState {
    /// Depth of the leading point below the bed surface at time `t` \[m\] (negative above it).
    pub fn depth(&self, speed: f64, t: f64) -> f64 {
        self.lead0 + speed * t - self.surface
    }
}

/// Finds the bed surface under the probe and checks the start: the probe must start above the bed and
/// clear of every sphere, and its largest depth must stay inside the bed.
pub(crate) fn start<L: ContactLaw>(p: &ProbeConfig, sim: &Simulation<L>) -> Result<ProbeState, DemError> {
    let err = |key: &str, message: String| DemError::Config { key: format!("probe.{key}"), message };
    let w = sim
        .walls
        .iter()
        .position(|w| w.name == WALL_NAME)
        .ok_or_else(|| err("shape", "no probe wall".into()))?;
    let wall = &sim.walls[w];
    let dir = p.direction.normalize();
    let (lead0, axis, rf) = geometry(&wall.shape, dir);
    let parts = &sim.particles;
    let (mut surface, mut bottom, mut under) = (f64::INFINITY, f64::NEG_INFINITY, 0usize);
    let (mut d_sum, mut w_sum, mut n) = (0.0, 0.0, 0usize);
    let g = sim.gravity.length();
    let kin = WallKinematics::of(&wall.motion, 0.0);
    for i in 0..parts.len() {
        let (x, r) = (parts.pos[i], parts.radius[i]);
        if !parts.is_member(i) {
            d_sum += 2.0 * r;
            w_sum += parts.mass(i) * g;
            n += 1;
        }
        if let Some(d) = wall.surface_distance(&kin, x, r) {
            return Err(err(
                "shape",
                format!(
                    "the probe starts inside the bed: it overlaps particle id {} (centre {x}, radius {r:e} m) by \
                     {:e} m; start it above the bed surface",
                    parts.id[i],
                    r - d
                ),
            ));
        }
        if perp(x - axis, dir) <= rf {
            surface = surface.min(x.dot(dir) - r);
            bottom = bottom.max(x.dot(dir) + r);
            under += 1;
        }
    }
    if under == 0 || n == 0 {
        return Err(err(
            "shape",
            format!("no sphere of the bed lies under the probe (footprint radius {rf:e} m about its axis through {axis})"),
        ));
    }
    if lead0 > surface {
        return Err(err(
            "shape",
            format!(
                "the probe starts inside the bed: its leading point is {:e} m below the bed surface under it; \
                 start it above the surface",
                lead0 - surface
            ),
        ));
    }
    if surface + p.max_depth_m > bottom {
        return Err(err(
            "max_depth_m",
            format!(
                "max_depth_m = {} reaches beyond the bed: the bed under the probe is {:e} m deep",
                p.max_depth_m,
                bottom - surface
            ),
        ));
    }
    let travel = p.max_depth_m + surface - lead0;
    let d_p = d_sum / n as f64;
    let width = 2.0 * rf;
    Ok(ProbeState {
        wall: w,
        dir,
        lead0,
        surface,
        immersion: p.immersion_depth_m.unwrap_or(width),
        d_p,
        w_p: w_sum / n as f64,
        samples: Vec::with_capacity((travel / p.speed_m_s * p.sample_hz).ceil().min(1e7) as usize + 1),
        depth_now: lead0 - surface,
    })
    .inspect(|s| {
        tracing::info!(
            "probe: bed surface {:.6e} m ahead of the leading point, {under} spheres under the probe, D_p = {:.4e} m",
            s.surface - s.lead0,
            s.d_p
        )
    })
}

/// Steps between two samples.
pub(crate) fn sample_every(p: &ProbeConfig, dt: f64) -> u64 {
    ((1.0 / (p.sample_hz * dt)).round() as u64).max(1)
}

/// Records a sample after a step that ends on the sampling grid: the force the particles exert on the
/// probe against its drive direction, from the step's last force evaluation. On several ranks the force
/// is summed over the ranks in rank order (collective at the sampling steps), so every rank keeps the same
/// samples.
pub(crate) fn after_step<L: ContactLaw>(
    p: &ProbeConfig,
    sim: &Simulation<L>,
    s: &mut ProbeState,
    every: u64,
    comm: &dyn Comm,
) {
    let t = sim.time();
    s.depth_now = s.depth(p.speed_m_s, t);
    if sim.step_count() % every == 0 {
        let force = -sim.wall_force_with(comm, s.wall).dot(s.dir);
        s.samples.push((t, s.depth_now, force));
    }
}

/// Writes `probe.csv`, `probe_spectrum.csv` and the two pictures, and adds the results to `s`.
pub(crate) fn finish(
    p: &ProbeConfig,
    state: &ProbeState,
    ctx: &RunContext,
    s: &mut RunSummary,
) -> Result<(), DemError> {
    let io = |path: &std::path::Path| {
        let path = path.to_owned();
        move |source| DemError::Io { path, source }
    };
    let depth: Vec<f64> = state.samples.iter().map(|x| x.1).collect();
    let force: Vec<f64> = state.samples.iter().map(|x| x.2).collect();
    let analysis = analyse(&depth, &force, state.immersion, state.d_p, state.w_p);
    let fit = analysis.as_ref().ok().map(|a| a.fit);
    let path = ctx.dir.path("probe.csv");
    let mut text = String::from("t_s,depth_m,force_N,mean_force_N\n");
    for &(t, y, f) in &state.samples {
        let mean = match fit {
            Some(law) if y >= state.immersion && y > 0.0 => law.at(y).to_string(),
            _ => String::new(),
        };
        text.push_str(&format!("{t},{y},{f},{mean}\n"));
    }
    std::fs::write(&path, text).map_err(io(&path))?;
    s.artifacts.push(("probe force against depth".into(), path));
    let reached = state.depth_now;
    s.scalar("probe_samples", state.samples.len() as f64);
    s.scalar("probe_depth_m", reached);
    s.scalar("probe_max_force_N", force.iter().copied().fold(0.0, f64::max));
    if reached < p.max_depth_m {
        s.headline.push(format!(
            "warning: probe: reached a depth of {reached:.4e} m of max_depth_m = {} by the end of the run",
            p.max_depth_m
        ));
    }
    force_plot(state, fit, ctx, s)?;
    match analysis {
        Ok(a) => report(&a, state, ctx, s)?,
        Err(e) => s.headline.push(format!("warning: probe: no analysis: {e}")),
    }
    Ok(())
}

fn force_plot(
    state: &ProbeState,
    fit: Option<crate::bed_lab::probe_analysis::PowerLaw>,
    ctx: &RunContext,
    s: &mut RunSummary,
) -> Result<(), DemError> {
    let mm = 1e3;
    let pts: Vec<(f64, f64)> = state.samples.iter().map(|x| (x.1 * mm, x.2)).collect();
    let mut chart = Chart::new(
        "Probe indentation: reaction force against depth",
        "depth below the bed surface [mm]",
        "force [N]",
    )
    .line_colored("force", &pts, (0, 114, 178));
    if let Some(law) = fit {
        let fitted: Vec<(f64, f64)> = state
            .samples
            .iter()
            .filter(|x| x.1 >= state.immersion && x.1 > 0.0)
            .map(|x| (x.1 * mm, law.at(x.1)))
            .collect();
        chart = chart.dashed(
            &format!("fit F = a y^p, p = {:.3} (after immersion)", law.p),
            &fitted,
            (213, 94, 0),
        );
    }
    let png = ctx.dir.path("probe_force.png");
    chart.save_png(&png).map_err(|source| DemError::Io { path: png.clone(), source })?;
    s.artifacts.push(("probe force against depth (picture)".into(), png));
    Ok(())
}

fn report(
    a: &ProbeAnalysis,
    state: &ProbeState,
    ctx: &RunContext,
    s: &mut RunSummary,
) -> Result<(), DemError> {
    let io = |path: &std::path::Path| {
        let path = path.to_owned();
        move |source| DemError::Io { path, source }
    };
    let path = ctx.dir.path("probe_spectrum.csv");
    let mut text = String::from("wavenumber_1_m,length_dp,psd_N2_m,psd_normalised\n");
    let norm = 1.0 / (state.w_p * state.w_p * state.d_p);
    for (k, p) in a.spectrum.wavenumber.iter().zip(&a.spectrum.psd) {
        text.push_str(&format!("{k},{},{p},{}\n", 1.0 / (k * state.d_p), p * norm));
    }
    std::fs::write(&path, text).map_err(io(&path))?;
    s.artifacts.push(("probe force spectrum".into(), path));
    s.scalar("probe_a", a.fit.a);
    s.scalar("probe_a_star", a.a_star);
    s.scalar("probe_p", a.fit.p);
    s.scalar("probe_peak_l_dp", a.peak_l_dp);
    s.headline.push(format!(
        "probe: F = a y^p after immersion ({} samples from y = {:.3e} m): a = {:.4e} N/m^p (F/W_p = {:.4e} (y/D_p)^p), \
         p = {:.3}; strongest length scale {:.3} D_p",
        a.samples, state.immersion, a.fit.a, a.a_star, a.fit.p, a.peak_l_dp
    ));
    if let Some(g) = a.gamma {
        s.scalar("probe_gamma", g);
        s.headline.push(format!("probe: spectral slope γ = {g:.3} over l < {GAMMA_MAX_LENGTH_DP} D_p"));
    }
    if let Some(k) = a.knee {
        s.scalar("probe_knee_l_dp", 1.0 / k.wavenumber);
        s.scalar("probe_slope_above_knee", k.slope_below);
        s.scalar("probe_slope_below_knee", k.slope_above);
        s.headline.push(format!(
            "probe: knee at l = {:.3e} D_p (slope {:.3} at larger, {:.3} at smaller length scales)",
            1.0 / k.wavenumber,
            k.slope_below,
            k.slope_above
        ));
    }
    // PSD against l/D_p, raw lines and bin means, with the γ line over its band.
    let raw: Vec<(f64, f64)> = a
        .spectrum
        .wavenumber
        .iter()
        .zip(&a.spectrum.psd)
        .map(|(k, p)| (1.0 / (k * state.d_p), p * norm))
        .collect();
    let binned: Vec<(f64, f64)> = a.binned.iter().map(|(k, p)| (1.0 / k, *p)).collect();
    let mut chart =
        Chart::new("Spectrum of the probe force fluctuation", "length scale l / D_p", "PSD / (W_p^2 D_p)")
            .log_x()
            .log_y()
            .line_colored("PSD", &raw, (160, 160, 160))
            .markers("bin means (10 per decade)", &binned, (0, 114, 178));
    if let Some(g) = a.gamma {
        let band: Vec<(f64, f64)> =
            a.binned.iter().copied().filter(|(k, _)| *k >= 1.0 / GAMMA_MAX_LENGTH_DP).collect();
        if let (Some(first), Some(last)) = (band.first(), band.last()) {
            // The least-squares line through the band, drawn from its first to its last bin: Ψ ∝ κ^γ = l^−γ.
            let n = band.len() as f64;
            let (mx, my) =
                band.iter().fold((0.0, 0.0), |acc, (k, p)| (acc.0 + k.log10() / n, acc.1 + p.log10() / n));
            let at = |k: f64| (1.0 / k, 10f64.powf(my + g * (k.log10() - mx)));
            chart = chart.dashed(&format!("slope γ = {g:.2}"), &[at(first.0), at(last.0)], (213, 94, 0));
        }
    }
    let png = ctx.dir.path("probe_psd.png");
    chart.save_png(&png).map_err(io(&png))?;
    s.artifacts.push(("probe force spectrum (picture)".into(), png));
    Ok(())
}
