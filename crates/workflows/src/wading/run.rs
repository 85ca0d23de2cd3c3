//! Running a `wading` scenario: the vehicle placed on the road and its motion tables, the `sph` scene
//! they make (channel, pool, moving parts, splash-height sensors), then the wading reports (sensor
//! series, wetting per group, the study's scalars).

use super::config::WadingConfig;
use super::geometry::write_stl;
use super::layout::Channel;
use super::parts::{bounds, read_parts, NamedPart};
use super::path::VehiclePath;
use super::timeline::{SpeedProfile, Travel};
use super::vehicle::{check_wheels, front_wheel, place_along, rear_wheel, wheelbase, Placement};
use crate::sph_scene::config::{
    DomainConfig, HeightConfig, MotionConfig, MotionType, OutputConfig, SensorConfig, SphConfig, WallConfig,
    WallType,
};
use spatter_core::control::Finished;
use spatter_core::Vec3;
use spatter_io::run::{CurveRecord, RunContext, RunSummary, ScalarTableRecord};
use spatter_sph::boundary::Slip;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// A wading run that cannot start or finish.
#[derive(Debug, thiserror::Error)]
pub enum WadingError {
    /// A setting or file that does not fit, naming the scenario key.
    #[error("{key}: {message}")]
    Input { key: String, message: String },
    #[error(transparent)]
    Sph(#[from] spatter_sph::error::SphError),
    #[error(transparent)]
    Mesh(#[from] spatter_core::mesh::MeshError),
    #[error("{0}")]
    Io(String),
}

fn input(key: &str, message: impl Into<String>) -> WadingError {
    WadingError::Input { key: key.into(), message: message.into() }
}

fn io_err(path: &Path) -> impl Fn(std::io::Error) -> WadingError + '_ {
    move |e| WadingError::Io(format!("{}: {e}", path.display()))
}

/// The vehicle read and checked, with its motion along the channel.
pub struct Plan {
    pub parts: Vec<NamedPart>,
    /// Report group of each part.
    pub groups: Vec<String>,
    /// The front axle's way over time.
    pub travel: Travel,
    /// Front axle's x at t = 0 \[m\].
    pub x_front0: f64,
    /// When the front wheels' leading edge reaches the still water \[s\].
    pub t_enter: f64,
    /// End of the run \[s\].
    pub t_end: f64,
    /// Largest front-wheel radius \[m\].
    pub r_front: f64,
    /// Sensor patches followed over time: the parts named in `sensors`, then the box patches.
    pub sensors: Vec<String>,
    /// Times of the instantaneous wetting maps (front axle at `output.map_positions_m`) \[s\].
    pub map_times: Vec<f64>,
    /// The channel, generated or read from its file.
    pub channel: Channel,
}

/// Reads the parts, checks the wheels and the width, and fixes the start and the end of the run.
pub fn plan(cfg: &WadingConfig) -> Result<Plan, WadingError> {
    let channel = Channel::new(&cfg.channel).map_err(|(k, m)| input(&format!("channel.{k}"), m))?;
    let mut parts = Vec::new();
    let mut groups = Vec::new();
    for (i, pf) in cfg.vehicle.parts.iter().enumerate() {
        let read = read_parts(&pf.file, pf.scale)
            .map_err(|e| input(&format!("vehicle.parts[{i}].file"), e.to_string()))?;
        for p in read {
            if parts.iter().any(|q: &NamedPart| q.name == p.name) {
                return Err(input(
                    &format!("vehicle.parts[{i}].file"),
                    format!("part `{}` is also in an earlier file; part names must be unique", p.name),
                ));
            }
            groups.push(pf.group.clone().unwrap_or_else(|| p.name.clone()));
            parts.push(p);
        }
    }
    let wheel_names: Vec<&str> = cfg.vehicle.wheels.iter().map(|w| w.part.as_str()).collect();
    for (i, b) in cfg.sensor_boxes.iter().enumerate() {
        let k = super::patches::cut(&mut parts, b, &wheel_names)
            .map_err(|e| input(&format!("sensor_boxes[{i}].{}", e.key), e.message))?;
        groups.push(groups[k].clone());
    }
    let mut errs = check_wheels(&parts, &cfg.vehicle.wheels);
    errs.extend(super::vehicle::check_sensor_names(&parts, &cfg.sensors));
    if let Some(e) = errs.into_iter().next() {
        return Err(input(&e.key, e.message));
    }
    if let Some(e) = channel.check_vehicle_width(&parts) {
        return Err(input(&e.key, e.message));
    }
    let front = front_wheel(&cfg.vehicle.wheels);
    let r_front = front.map(|w| w.radius_m).unwrap_or(0.0);
    let (x_in, _) = channel.waterline();
    let y0 = channel.centre_y();
    let along = |speed| Travel::Along { x0: x_in - r_front - cfg.vehicle.start_gap_m, y0, speed };
    let m = &cfg.motion;
    let travel = match (&m.speed_m_s, &m.file, &m.path) {
        (Some(v), _, _) => along(SpeedProfile::constant(*v)),
        (None, Some(f), _) => {
            let text = std::fs::read_to_string(f)
                .map_err(|e| input("motion.file", format!("{}: {e}", f.display())))?;
            along(SpeedProfile::parse(&text, f).map_err(|e| input("motion.file", e))?)
        }
        (None, None, Some(p)) => {
            Travel::Path { path: read_path(p)?, wheelbase: wheelbase(&cfg.vehicle.wheels) }
        }
        (None, None, None) => return Err(input("motion.speed_m_s", "give speed_m_s, file or [motion.path]")),
    };
    let on_path = matches!(travel, Travel::Path { .. });
    let x_front0 = travel.front(0.0).0;
    let t_enter = travel.time_to_x(x_in - r_front).unwrap_or(0.0);
    let t_end = match cfg.output.end_time_s {
        Some(t) => t,
        None => travel.time_to_x(channel.pool_end_x()).ok_or_else(|| {
            if on_path {
                input(
                    "motion.path",
                    format!(
                        "the path's front axle never reaches the end of the pool floor (x = {} m); give \
                         output.end_time_s or a path that gets there",
                        channel.pool_end_x()
                    ),
                )
            } else {
                input(
                    "motion.file",
                    "the speed table comes to rest before the front wheels reach the end of the pool; give \
                     output.end_time_s or a table that keeps moving",
                )
            }
        })?,
    };
    if let Travel::Path { path: p, .. } = &travel {
        check_path(cfg, &channel, &parts, p, &travel, t_end)?;
    }
    if let Channel::File(f) = &channel {
        check_road_under_axles(cfg, f, &parts, &travel, t_end)?;
    }
    let mut map_times = Vec::new();
    for (i, x) in cfg.output.map_positions_m.iter().enumerate() {
        let x_end = travel.front(t_end).0;
        // The end itself is a valid position (its time may come out a rounding error beyond the end).
        match travel.time_to_x(*x).filter(|t| *x >= x_front0 && *t <= t_end * (1.0 + 1e-9)) {
            Some(t) => map_times.push(t.min(t_end)),
            None => {
                return Err(input(
                    &format!("output.map_positions_m[{i}]"),
                    format!(
                    "{x} m: the front axle travels from x = {x_front0:.3} m to {x_end:.3} m during the run"
                ),
                ))
            }
        }
    }
    let mut sensors = cfg.sensors.clone();
    sensors.extend(cfg.sensor_boxes.iter().map(|b| b.name.clone()));
    Ok(Plan { parts, groups, travel, x_front0, t_enter, t_end, r_front, sensors, map_times, channel })
}

/// The path of `[motion.path]`, read from its file or its rows; errors under `motion.path.file` (with
/// the file's line) or `motion.path.rows`.
fn read_path(p: &super::config::PathSpec) -> Result<VehiclePath, WadingError> {
    match (&p.file, &p.rows) {
        (Some(f), None) => {
            let text = std::fs::read_to_string(f)
                .map_err(|e| input("motion.path.file", format!("{}: {e}", f.display())))?;
            VehiclePath::parse(&text, f).map_err(|e| input("motion.path.file", e))
        }
        (None, Some(rows)) => VehiclePath::from_rows(rows).map_err(|e| input("motion.path", e)),
        _ => Err(input("motion.path.file", "give exactly one of file and rows")),
    }
}

/// Relative tolerance of a path row's height against the height the road carries the front axle at.
pub const PATH_Z_TOLERANCE: f64 = 0.05;

/// On a channel from a file, road under both axles all the way (sampled every 2 cm of travel): the
/// message names the time, the axle and the road's extent.
fn check_road_under_axles(
    cfg: &WadingConfig,
    f: &super::channel_stl::StlChannel,
    parts: &[NamedPart],
    travel: &Travel,
    t_end: f64,
) -> Result<(), WadingError> {
    let wheels = &cfg.vehicle.wheels;
    let (Some(front), Some(rear)) = (front_wheel(wheels), rear_wheel(wheels)) else { return Ok(()) };
    let b = bounds(parts);
    let y_mid = 0.5 * (b.min.y + b.max.y);
    let dt = (0.02 / travel.max_speed().max(1e-9)).min(0.01);
    let n = (t_end / dt).ceil() as usize;
    for k in 0..=n {
        let t = (k as f64 * dt).min(t_end);
        let p = place_along(parts, wheels, f, travel, t);
        for (which, w) in [("front", front), ("rear", rear)] {
            let q = p.apply(Vec3::new(w.axle_m.x, y_mid, w.axle_m.z));
            if f.road_z(q.x, q.y).is_none() {
                return Err(input(
                    "channel.file",
                    format!(
                        "at t = {t:.3} s the {which} axle is over x = {:.3} m, y = {:.3} m, where {} has no road \
                         (its road spans x from {} to {} m, y from {} to {} m): lengthen the road or start the \
                         vehicle further in",
                        q.x,
                        q.y,
                        f.file.display(),
                        f.x_range.0,
                        f.x_range.1,
                        f.y_range.0,
                        f.y_range.1
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// A path's heights agree with the road (within [`PATH_Z_TOLERANCE`] of the front wheel's radius), and
/// the vehicle stays inside the channel all the way: the corners of its parts' bounding box, placed on
/// the road, between the side walls and over the channel's length, sampled every 2 cm of travel.
fn check_path(
    cfg: &WadingConfig,
    channel: &Channel,
    parts: &[NamedPart],
    path: &VehiclePath,
    travel: &Travel,
    t_end: f64,
) -> Result<(), WadingError> {
    let c = channel.road();
    let wheels = &cfg.vehicle.wheels;
    let r_front = front_wheel(wheels).map(|w| w.radius_m).unwrap_or(0.0);
    let key = || if path.origin_at(0.0).starts_with("rows[") { "motion.path" } else { "motion.path.file" };
    for h in &path.heights {
        let (x, y) = travel.front(h.t);
        let heading = place_along(parts, wheels, c, travel, h.t).yaw;
        let z = c.axle_height(x, y, r_front, heading);
        if (h.z - z).abs() > PATH_Z_TOLERANCE * r_front {
            return Err(input(
                key(),
                format!(
                    "{}: z = {} m, but the road carries the front axle at z = {z:.4} m there (x = {x:.3} m, \
                     y = {y:.3} m): the wheels roll on the road; give its height within {} m ({} % of the wheel \
                     radius) or leave z out",
                    h.origin,
                    h.z,
                    PATH_Z_TOLERANCE * r_front,
                    PATH_Z_TOLERANCE * 100.0
                ),
            ));
        }
    }
    let b = bounds(parts);
    let corners: Vec<Vec3> = (0..8)
        .map(|k| {
            Vec3::new(
                if k & 1 == 0 { b.min.x } else { b.max.x },
                if k & 2 == 0 { b.min.y } else { b.max.y },
                if k & 4 == 0 { b.min.z } else { b.max.z },
            )
        })
        .collect();
    let ((y_lo, y_hi), (x_lo, x_hi)) = (channel.y_range(), channel.x_range());
    let dt = (0.02 / travel.max_speed().max(1e-9)).min(0.01);
    let n = (t_end / dt).ceil() as usize;
    for k in 0..=n {
        let t = (k as f64 * dt).min(t_end);
        let p = place_along(parts, wheels, c, travel, t);
        let heading = p.yaw;
        if heading.cos() < 0.2 {
            return Err(input(
                key(),
                format!(
                    "at t = {t:.3} s (after {}) the path heads {:.1}° off the channel's axis (+x); the vehicle \
                     drives along the channel, within 78° of +x",
                    path.origin_at(t),
                    heading.to_degrees()
                ),
            ));
        }
        for q in corners.iter().map(|&q| p.apply(q)) {
            let beyond = if q.y > y_hi || q.y < y_lo {
                let wall = if q.y > y_hi { y_hi } else { y_lo };
                Some(format!("y = {:.3} m, beyond the side wall at y = {wall:+} m", q.y))
            } else if q.x < x_lo || q.x > x_hi {
                Some(format!("x = {:.3} m, beyond the channel's ends (x from {x_lo} to {x_hi} m)", q.x))
            } else {
                None
            };
            if let Some(what) = beyond {
                return Err(input(
                    key(),
                    format!(
                        "at t = {t:.3} s (after {}) the vehicle leaves the channel: a corner of its parts reaches \
                         {what}; keep the path inside the channel",
                        path.origin_at(t)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Rows `t vx vy vz wx wy wz` of the body's motion about its rear axle (the placement's pivot, in the
/// world at t = 0), sampled every `dt` up to `t_end` and one step beyond: velocity and pitch rate by
/// central differences of the placement on the road.
fn body_table(plan: &Plan, place: &dyn Fn(f64) -> Placement, dt: f64) -> String {
    let pose = |t: f64| {
        let p = place(t);
        (p.pivot + p.shift, p.pitch, p.yaw)
    };
    let n = (plan.t_end / dt).ceil() as usize + 1;
    let eps = 1e-4 * dt;
    let mut s = String::from("# t_s vx vy vz wx wy wz: the vehicle body about its rear axle\n");
    for k in 0..=n {
        let t = k as f64 * dt;
        let (p1, a1, y1) = pose(t + eps);
        let (p0, a0, y0) = pose((t - eps).max(0.0));
        let h = t + eps - (t - eps).max(0.0);
        let v = (p1 - p0) / h;
        // Nose up (pitch growing) is a rotation about the body's −y axis, which the heading ψ has turned
        // to (sin ψ, −cos ψ, 0); the heading turns about +z. (`+ 0.0` writes a zero as `0`, not `-0`.)
        let pitch_rate = (a1 - a0) / h;
        let yaw_rate = wrap_angle(y1 - y0) / h;
        let (sin_h, cos_h) = (0.5 * (y0 + y1)).sin_cos();
        let (wx, wy, wz) = (sin_h * pitch_rate + 0.0, -(cos_h * pitch_rate), yaw_rate + 0.0);
        let _ = writeln!(s, "{t} {} {} {} {wx} {wy} {wz}", v.x, v.y, v.z);
    }
    s
}

/// Angle `a` \[rad\] brought into (−π, π].
fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if a > PI || a <= -PI {
        a - TAU * ((a + PI) / TAU).floor()
    } else {
        a
    }
}

/// Rows of a wheel's spin relative to the body: ω = v(t)/R about the axle (rolling without slip), the
/// axle along the body's y axis as it was at t = 0 (heading ψ₀: (−sin ψ₀, cos ψ₀, 0)), the frame the body
/// carries its wheels' tables in.
fn wheel_table(plan: &Plan, yaw0: f64, radius: f64, dt: f64) -> String {
    let n = (plan.t_end / dt).ceil() as usize + 1;
    let (sin0, cos0) = yaw0.sin_cos();
    let mut s = String::from("# t_s vx vy vz wx wy wz: wheel spin relative to the body, omega = v/R\n");
    for k in 0..=n {
        let t = k as f64 * dt;
        let w = plan.travel.speed(t) / radius;
        let _ = writeln!(s, "{t} 0 0 0 {} {} 0", -(sin0 * w) + 0.0, cos0 * w);
    }
    s
}

fn write_text(path: &Path, text: &str) -> Result<(), WadingError> {
    if let Some(d) = path.parent() {
        std::fs::create_dir_all(d).map_err(io_err(d))?;
    }
    std::fs::write(path, text).map_err(io_err(path))
}

/// The `sph` scene of the run, with its geometry and motion files written under `geo`.
pub fn scene(cfg: &WadingConfig, plan: &Plan, geo: &Path) -> Result<SphConfig, WadingError> {
    scene_with_files(cfg, plan, geo, true)
}

/// [`scene`]; the geometry and motion files are written only when `write` (on several ranks rank 0
/// writes them and every rank reads them).
fn scene_with_files(
    cfg: &WadingConfig,
    plan: &Plan,
    geo: &Path,
    write: bool,
) -> Result<SphConfig, WadingError> {
    let write_text = |path: &Path, text: &str| if write { write_text(path, text) } else { Ok(()) };
    let write_stl = |path: &Path, name: &str, mesh: &spatter_core::mesh::TriMesh| {
        if write {
            write_stl(path, name, mesh).map_err(io_err(path))
        } else {
            Ok(())
        }
    };
    let ch = &plan.channel;
    let dp = cfg.fluid.spacing_m;
    let wheels = &cfg.vehicle.wheels;
    let place = |t: f64| place_along(&plan.parts, wheels, ch.road(), &plan.travel, t);
    let p0 = place(0.0);
    let pivot0 = p0.pivot + p0.shift;
    // Motion tables sampled every 2 cm of travel (at most 10 ms).
    let dt = (0.02 / plan.travel.max_speed().max(1e-9)).min(0.01);
    let body_file = geo.join("motion_body.txt");
    write_text(&body_file, &body_table(plan, &place, dt))?;
    let mut motions = vec![MotionConfig {
        name: "body".into(),
        parent: None,
        kind: MotionType::Table,
        velocity_m_s: None,
        center_m: None,
        axis: None,
        angular_speed_rad_s: None,
        file: Some(body_file),
        reference_point_m: Some(pivot0),
    }];
    let mut walls = Vec::new();
    let layers = Some((2.0 * cfg.fluid.h_over_dp.unwrap_or(1.5)).ceil() as usize);
    for (name, mesh) in ch.surfaces() {
        let file = geo.join(format!("{name}.stl"));
        write_stl(&file, &name, &mesh)?;
        walls.push(wall(&name, file, None, cfg.channel.adhesion, layers));
    }
    // The middle of the axles across the vehicle (its own frame), for the wheels' view side.
    let (lo_y, hi_y) = wheels
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), w| (a.min(w.axle_m.y), b.max(w.axle_m.y)));
    let axles_mid_y = 0.5 * (lo_y + hi_y);
    for part in &plan.parts {
        let mut mesh = part.mesh.clone();
        mesh.vertices.iter_mut().for_each(|v| *v = p0.apply(*v));
        let file = geo.join(format!("{}.stl", part.name));
        write_stl(&file, &part.name, &mesh)?;
        let motion = match wheels.iter().find(|w| w.part == part.name) {
            Some(w) => {
                let name = format!("spin_{}", part.name);
                let f = geo.join(format!("motion_{}.txt", part.name));
                write_text(&f, &wheel_table(plan, p0.yaw, w.radius_m, dt))?;
                motions.push(MotionConfig {
                    name: name.clone(),
                    parent: Some("body".into()),
                    kind: MotionType::Table,
                    velocity_m_s: None,
                    center_m: None,
                    axis: None,
                    angular_speed_rad_s: None,
                    file: Some(f),
                    reference_point_m: Some(p0.apply(w.axle_m)),
                });
                name
            }
            None => "body".into(),
        };
        let mut w = wall(&part.name, file, Some(motion), cfg.vehicle.adhesion, None);
        // A wheel's map is seen from outside the vehicle, looking at its outer face: the side is the
        // wheel's side of the vehicle (its own frame, against the middle of the axles), so a vehicle off
        // the channel's centre line still shows both wheels from outside.
        if let Some(spec) = wheels.iter().find(|w| w.part == part.name) {
            let side = if spec.axle_m.y >= axles_mid_y { -1.0 } else { 1.0 };
            w.view_dir = Some(Vec3::new(0.0, side, 0.0));
            w.up = Some(Vec3::Z);
        }
        walls.push(w);
    }
    // The pool: a flood fill of the still water, centred across the channel for any width.
    let fill = ch.pool_fill(dp);
    let floor = ch.floor_z();
    // The box particles may not leave: the channel and the vehicle with room above for the splash.
    let vb = bounds(&plan.parts);
    let reach = (vb.max - vb.min).length();
    let x = ch.water_depth();
    let top = ch.top_z().max(floor + cfg.output.splash_top_over_depth * x) + reach;
    let ((x_lo, x_hi), (y_lo, y_hi)) = (ch.x_range(), ch.y_range());
    let domain = DomainConfig {
        min_m: Some(Vec3::new((plan.x_front0 - reach).min(x_lo) - 1.0, y_lo - 1.0, floor - 1.0)),
        max_m: Some(Vec3::new(x_hi + 1.0, y_hi + 1.0, top)),
        periodic: Vec::new(),
        rebalance_imbalance: None,
    };
    let bin = cfg.output.splash_bin_over_depth * x;
    let bins = (cfg.output.splash_top_over_depth / cfg.output.splash_bin_over_depth).ceil() as usize;
    let t_end = plan.t_end;
    Ok(SphConfig {
        title: if cfg.title.is_empty() { "wading".into() } else { cfg.title.clone() },
        fluid: cfg.fluid.clone(),
        drag: cfg.drag.clone(),
        domain,
        motions,
        walls,
        fill: vec![fill],
        output: OutputConfig {
            end_time_s: t_end,
            vtu_interval_s: Some(cfg.output.vtu_interval_s.unwrap_or(t_end / 40.0)),
            sample_interval_s: Some(cfg.output.sample_interval_s.unwrap_or(t_end / 400.0)),
            wall_particles: false,
            wetting_cap: Some(cfg.output.wetting_cap),
            wetting_map_times_s: plan.map_times.clone(),
        },
        sensors: SensorConfig {
            wet_distance_m: None,
            wet_lateral_m: None,
            probes: Vec::new(),
            wall_probes: Vec::new(),
            height: Some(HeightConfig {
                base_z_m: floor,
                bin_m: bin,
                bins,
                window_s: [plan.t_enter.min(t_end), t_end],
                reference_depth_m: Some(x),
            }),
        },
    })
}

fn wall(
    name: &str,
    file: PathBuf,
    motion: Option<String>,
    adhesion: f64,
    layers: Option<usize>,
) -> WallConfig {
    WallConfig {
        name: name.into(),
        kind: WallType::Mesh,
        min_m: None,
        max_m: None,
        open_faces: None,
        layers,
        file: Some(file),
        scale: 1.0,
        center_m: None,
        axis: None,
        radius_m: None,
        length_m: None,
        segments: 48,
        motion,
        adhesion,
        slip: Slip::default(),
        wetting_map: true,
        view_dir: None,
        up: None,
    }
}

/// Runs the scenario in `ctx`: see `docs/wading.md` for the files written.
pub fn run(cfg: &WadingConfig, ctx: &RunContext) -> Result<RunSummary, WadingError> {
    let plan = plan(cfg)?;
    let geo = ctx.dir.path("geometry");
    // On several ranks rank 0 writes the geometry and every rank reads it: all wait until it is written,
    // and a rank 0 that failed to write ends every rank.
    let comm = ctx.comm;
    let scfg = scene_with_files(cfg, &plan, &geo, comm.is_root());
    if comm.size() > 1 {
        let mut failed = [u64::from(scfg.is_err())];
        comm.all_sum_u64(&mut failed);
        if failed[0] > 0 && scfg.is_ok() {
            return Err(WadingError::Io(
                "rank 0 could not write the geometry files (its error ends the run)".into(),
            ));
        }
    }
    let scfg = scfg?;
    if comm.is_root() {
        tracing::info!(
            "wading: {} parts, front axle from x = {:.3} m, water reached at t = {:.3} s, end at t = {:.3} s (front axle at x = {:.3} m)",
            plan.parts.len(),
            plan.x_front0,
            plan.t_enter,
            plan.t_end,
            plan.travel.front(plan.t_end).0
        );
    }
    let mut summary = crate::sph_scene::run(&scfg, ctx)?;
    // Rank 0 wrote the results; the reports read them.
    if summary.finished != Finished::Completed || !comm.is_root() {
        return Ok(summary);
    }
    report(cfg, &plan, ctx, &mut summary)?;
    Ok(summary)
}

/// Sensor series, wetting per group and the study's scalars, from the files the scene wrote.
fn report(
    cfg: &WadingConfig,
    plan: &Plan,
    ctx: &RunContext,
    summary: &mut RunSummary,
) -> Result<(), WadingError> {
    let dir = ctx.dir;
    // Areas and mean wet fractions per wall from wetting.csv.
    let wet_csv = dir.path("wetting.csv");
    let text = std::fs::read_to_string(&wet_csv).map_err(io_err(&wet_csv))?;
    let mut area: Vec<(String, f64, f64)> = Vec::new();
    for line in text.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() >= 5 {
            let a = f[1].trim().parse().unwrap_or(0.0);
            let m = f[3].trim().parse().unwrap_or(0.0);
            area.push((f[0].trim().to_owned(), a, m));
        }
    }
    // Groups: area-weighted mean wet fraction.
    let mut groups: Vec<(String, f64, f64)> = Vec::new();
    for (part, group) in plan.parts.iter().zip(&plan.groups) {
        let Some((_, a, m)) = area.iter().find(|(n, _, _)| *n == part.name) else { continue };
        match groups.iter_mut().find(|g| g.0 == *group) {
            Some(g) => {
                g.1 += a;
                g.2 += m;
            }
            None => groups.push((group.clone(), *a, *m)),
        }
    }
    let rows: Vec<Vec<String>> = groups
        .iter()
        .map(|(g, a, m)| {
            let f = if *a > 0.0 { m / a } else { 0.0 };
            summary.scalar(&format!("group_{g}_mean_wet_fraction"), f);
            vec![g.clone(), spatter_io::fmt_f64(*a), spatter_io::fmt_f64(*m), spatter_io::fmt_f64(f)]
        })
        .collect();
    let gpath = dir.path("wetting_groups.csv");
    spatter_io::csv::write_table(
        &gpath,
        &["group", "area_m2", "mean_wet_area_m2", "mean_wet_fraction"],
        &rows,
    )
    .map_err(io_err(&gpath))?;
    summary.artifacts.push(("wetting per group".into(), gpath));
    // Sensor series from series.csv: wet fraction, water at the patch and its arrival rate over time.
    if !plan.sensors.is_empty() {
        sensor_series(plan, dir, &area, summary)?;
    }
    // Which instantaneous map is which vehicle position.
    if !plan.map_times.is_empty() {
        let rows: Vec<Vec<String>> = plan
            .map_times
            .iter()
            .zip(&cfg.output.map_positions_m)
            .enumerate()
            .map(|(n, (t, x))| {
                vec![format!("instant_{n:02}"), spatter_io::fmt_f64(*t), spatter_io::fmt_f64(*x)]
            })
            .collect();
        let p = dir.path("wetting/instants.csv");
        spatter_io::csv::write_table(&p, &["folder", "t_s", "front_axle_x_m"], &rows).map_err(io_err(&p))?;
        summary.artifacts.push(("instantaneous wetting maps (folders, times, positions)".into(), p));
        for n in 0..plan.map_times.len() {
            for part in &plan.parts {
                let png = dir.path(&format!("wetting/instant_{n:02}/{}.png", part.name));
                if png.is_file() {
                    summary.artifacts.push((format!("{} wet at position {n}", part.name), png));
                }
            }
        }
    }
    // The study's scalars under the wading names.
    let get = |n: &str| summary.scalars.iter().find(|(k, _)| k == n).map(|e| e.1);
    if let Some(top) = get("splash_top_bin_height_over_depth") {
        summary.scalar("max_splash_height_over_depth", top);
    }
    let vehicle: (f64, f64) = plan
        .parts
        .iter()
        .filter_map(|p| area.iter().find(|(n, _, _)| *n == p.name))
        .fold((0.0, 0.0), |acc, (_, a, m)| (acc.0 + a, acc.1 + m));
    if vehicle.0 > 0.0 {
        summary.scalar("vehicle_mean_wet_fraction", vehicle.1 / vehicle.0);
    }
    // The wet fractions as tables a study shows side by side, one column per case.
    let reported = |n: &str| summary.scalars.iter().any(|(k, _)| k == n);
    let part_rows: Vec<(String, String)> = area
        .iter()
        .map(|(n, _, _)| (n.clone(), format!("{n}_mean_wet_fraction")))
        .filter(|(_, k)| reported(k))
        .collect();
    let mut group_rows: Vec<(String, String)> =
        groups.iter().map(|(g, _, _)| (g.clone(), format!("group_{g}_mean_wet_fraction"))).collect();
    if reported("vehicle_mean_wet_fraction") {
        group_rows.push(("whole vehicle".into(), "vehicle_mean_wet_fraction".into()));
    }
    summary.scalar_tables.push(ScalarTableRecord {
        label: "mean wet fraction per part (area fraction, averaged over the run)".into(),
        rows: part_rows,
    });
    summary.scalar_tables.push(ScalarTableRecord {
        label: "mean wet fraction per report group (area-weighted)".into(),
        rows: group_rows,
    });
    summary.headline.insert(
        0,
        format!(
            "wading: front axle from x = {:.3} m to {:.3} m (pool end {:.3} m), water depth {} m",
            plan.x_front0,
            plan.travel.front(plan.t_end).0,
            plan.channel.pool_end_x(),
            cfg.channel.water_depth_m
        ),
    );
    Ok(())
}

/// What `sensors.csv` holds per sensor, one quantity each.
struct SensorQuantity {
    /// Column of `series.csv` it comes from (after `<part>_`).
    source: &'static str,
    /// Divided by the sensor's area (the wet fraction).
    per_area: bool,
    /// Its column in `sensors.csv` (after `<sensor>_`).
    column: &'static str,
    /// Its curve in the summary: "<sensor> <phrase> over time", y axis "<of> <sensor>".
    phrase: &'static str,
    of: &'static str,
    /// The plot's y axis and file.
    axis: &'static str,
    png: &'static str,
}

const SENSOR_QUANTITIES: [SensorQuantity; 3] = [
    SensorQuantity {
        source: "wet_area_m2",
        per_area: true,
        column: "wet_fraction",
        phrase: "wet fraction",
        of: "wet fraction of",
        axis: "wet fraction of the patch",
        png: "sensors.png",
    },
    SensorQuantity {
        source: "water_m3",
        per_area: false,
        column: "water_m3",
        phrase: "water",
        of: "water [m³] at",
        axis: "water at the patch [m³]",
        png: "sensors_water.png",
    },
    SensorQuantity {
        source: "water_arrival_m3_s",
        per_area: false,
        column: "water_arrival_m3_s",
        phrase: "water arrival rate",
        of: "water arriving [m³/s] at",
        axis: "water arriving at the patch [m³/s]",
        png: "sensors_arrival.png",
    },
];

/// `sensors.csv` and its plots: per sensor part its wet fraction, the water within its wet reach and the
/// rate at which water arrives there (series.csv's `<part>_wet_area_m2`, `_water_m3`,
/// `_water_arrival_m3_s`; docs/wading.md, "Results").
fn sensor_series(
    plan: &Plan,
    dir: &spatter_io::run::RunDir,
    area: &[(String, f64, f64)],
    summary: &mut RunSummary,
) -> Result<(), WadingError> {
    let spath = dir.path("series.csv");
    let text = std::fs::read_to_string(&spath).map_err(io_err(&spath))?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').map(str::trim).collect();
    // Per quantity and sensor: (sensor, series column, divisor).
    let mut cols: Vec<Vec<(String, usize, f64)>> = Vec::new();
    for SensorQuantity { source, per_area, .. } in SENSOR_QUANTITIES {
        let mut q = Vec::new();
        for (k, s) in plan.sensors.iter().enumerate() {
            let col = header.iter().position(|h| *h == format!("{s}_{source}"));
            let a = area.iter().find(|(n, _, _)| n == s).map(|e| e.1);
            match (col, a) {
                (Some(c), Some(a)) => {
                    q.push((s.clone(), c, if per_area { a.max(f64::MIN_POSITIVE) } else { 1.0 }))
                }
                _ => {
                    return Err(WadingError::Io(format!(
                        "{}: no column {s}_{source} for sensors[{k}] (or no area in wetting.csv)",
                        spath.display()
                    )))
                }
            }
        }
        cols.push(q);
    }
    let mut rows = Vec::new();
    let mut curves: Vec<Vec<Vec<(f64, f64)>>> = cols.iter().map(|q| vec![Vec::new(); q.len()]).collect();
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        let t: f64 = f.first().and_then(|s| s.trim().parse().ok()).unwrap_or(f64::NAN);
        let mut row = vec![spatter_io::fmt_f64(t)];
        for (q, c) in cols.iter().zip(curves.iter_mut()) {
            for ((_, col, div), pts) in q.iter().zip(c.iter_mut()) {
                let v: f64 = f.get(*col).and_then(|s| s.trim().parse().ok()).unwrap_or(f64::NAN);
                row.push(spatter_io::fmt_f64(v / div));
                pts.push((t, v / div));
            }
        }
        rows.push(row);
    }
    let mut head = vec!["t_s".to_owned()];
    for (sq, q) in SENSOR_QUANTITIES.iter().zip(&cols) {
        head.extend(q.iter().map(|(s, _, _)| format!("{s}_{}", sq.column)));
    }
    let head_ref: Vec<&str> = head.iter().map(String::as_str).collect();
    let p = dir.path("sensors.csv");
    spatter_io::csv::write_table(&p, &head_ref, &rows).map_err(io_err(&p))?;
    for (sq, (q, c)) in SENSOR_QUANTITIES.iter().zip(cols.iter().zip(&curves)) {
        for (s, _, _) in q {
            summary.curves.push(CurveRecord {
                label: format!("{s} {} over time", sq.phrase),
                csv: p.clone(),
                x_column: "t_s".into(),
                y_column: format!("{s}_{}", sq.column),
                x_label: "time [s]".into(),
                y_label: format!("{} {s}", sq.of),
            });
        }
        let mut chart = spatter_io::plot::Chart::new("Sensor patches", "time [s]", sq.axis);
        for ((s, _, _), pts) in q.iter().zip(c) {
            chart = chart.line(s, pts);
        }
        let png = dir.path(sq.png);
        chart.save_png(&png).map_err(io_err(&png))?;
        summary.artifacts.push((format!("sensor plot: {}", sq.axis), png));
    }
    summary.artifacts.push(("sensor series (wet fraction, water, arrival rate)".into(), p));
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::wading::config::{MotionSpec, PathSpec, WadingOutput};
    use crate::wading::patches::SensorBox;
    use crate::wading::vehicle::{place_on_road, PartFile};
    use spatter_core::mesh::TriMesh;
    use spatter_core::motion::{Motion, MotionTable};

    fn wheel(centre: Vec3, r: f64) -> TriMesh {
        crate::wading::vehicle::tests::wheel_mesh(centre, r, 0.1, 24)
    }

    /// A two-axle vehicle (wheels of radius 0.4 m, wheelbase 3 m) given 2 m above its road position, and
    /// a channel 3 m wide with 0.3 m of water on a 0.5 m deep pool.
    pub(crate) fn config(dir: &Path) -> WadingConfig {
        let file = dir.join("car.stl");
        let mut text = String::new();
        for (name, x, y) in [("fl", 3.0, 0.8), ("fr", 3.0, -0.8), ("rl", 0.0, 0.8), ("rr", 0.0, -0.8)] {
            let p = dir.join(format!("{name}.stl"));
            write_stl(&p, name, &wheel(Vec3::new(x, y, 2.4), 0.4)).unwrap();
            text.push_str(&std::fs::read_to_string(&p).unwrap());
        }
        std::fs::write(&file, text).unwrap();
        let toml = format!(
            r#"
            sensors = ["fl"]
            [fluid]
            spacing_m = 0.05
            [channel]
            approach_length_m = 4.0
            ramp_length_m = 2.0
            pool_length_m = 5.0
            pool_depth_m = 0.5
            exit_length_m = 1.0
            width_m = 3.0
            wall_height_m = 0.8
            water_depth_m = 0.3
            [vehicle]
            parts = [{{ file = "{}" }}]
            wheels = [
                {{ part = "fl", axle_m = [3.0, 0.8, 2.4], radius_m = 0.4 }},
                {{ part = "fr", axle_m = [3.0, -0.8, 2.4], radius_m = 0.4 }},
                {{ part = "rl", axle_m = [0.0, 0.8, 2.4], radius_m = 0.4 }},
                {{ part = "rr", axle_m = [0.0, -0.8, 2.4], radius_m = 0.4 }},
            ]
            [motion]
            speed_m_s = 2.0
            "#,
            file.display()
        );
        let cfg: WadingConfig = toml::from_str(&toml).unwrap();
        assert_eq!(cfg.output, WadingOutput::default());
        assert_eq!(cfg.vehicle.parts, vec![PartFile { file, scale: 1.0, group: None }]);
        cfg
    }

    /// The body's motion table, integrated by the engine's kinematics, keeps both axles on the road
    /// (axle height from the channel profile, `ChannelSpec::axle_z`) and the wheelbase at 3 m through the
    /// entry ramp and across the pool, to 2 mm; the run starts with the front wheel 0.2 m before the water
    /// and ends with the front axle at the end of the pool floor.
    #[test]
    fn the_motion_tables_keep_the_wheels_on_the_road() {
        let dir = tempfile::tempdir().unwrap();
        let cfg = config(dir.path());
        let plan = plan(&cfg).unwrap();
        let c = &cfg.channel.generated().unwrap();
        let (x_in, _) = c.waterline();
        assert!((plan.x_front0 - (x_in - 0.4 - 0.2)).abs() < 1e-12);
        assert!((plan.t_enter - 0.1).abs() < 1e-9, "{}", plan.t_enter);
        assert!((plan.x_front0 + 2.0 * plan.t_end - c.pool_end_x()).abs() < 1e-9);
        let geo = dir.path().join("geometry");
        let scene = scene(&cfg, &plan, &geo).unwrap();
        let body = &scene.motions[0];
        let text = std::fs::read_to_string(body.file.as_ref().unwrap()).unwrap();
        let motion = Motion::Tabulated(MotionTable::parse(&text, body.reference_point_m.unwrap()).unwrap());
        let p0 = place_on_road(&plan.parts, &cfg.vehicle.wheels, c, (plan.x_front0, 0.0), 0.0);
        let front0 = p0.apply(Vec3::new(3.0, 0.8, 2.4));
        let rear0 = p0.apply(Vec3::new(0.0, 0.8, 2.4));
        // At x = 4.2 the front wheel already rests on the entry ramp (it starts at x = 4).
        assert!(
            (front0.z - c.axle_z(4.2, 0.4)).abs() < 1e-6 && front0.z < 0.4,
            "placed on the road: {front0}"
        );
        assert!((front0.y - 0.8).abs() < 1e-12, "centred across the channel: {front0}");
        for k in 0..=20 {
            let t = plan.t_end * k as f64 / 20.0;
            let pose = motion.pose(t);
            let (f, r) = (pose.apply(front0), pose.apply(rear0));
            let x_f = plan.x_front0 + 2.0 * t;
            assert!((f.x - x_f).abs() < 2e-3, "t = {t}: front axle at x = {} not {x_f}", f.x);
            assert!((f.z - c.axle_z(f.x, 0.4)).abs() < 2e-3, "t = {t}: front axle {f} off the road");
            assert!((r.z - c.axle_z(r.x, 0.4)).abs() < 2e-3, "t = {t}: rear axle {r} off the road");
            assert!(((f - r).length() - 3.0).abs() < 2e-3, "t = {t}: wheelbase {}", (f - r).length());
        }
        // Wheels spin at v/R = 5 rad/s about +y relative to the body.
        let spin = &scene.motions[1];
        let text = std::fs::read_to_string(spin.file.as_ref().unwrap()).unwrap();
        let table = MotionTable::parse(&text, spin.reference_point_m.unwrap()).unwrap();
        assert_eq!(table.rates(0.3), (Vec3::ZERO, Vec3::new(0.0, 5.0, 0.0)));
        // The pool is centred across the channel and reaches the waterline; splash heights from the floor.
        let fill = &scene.fill[0];
        assert!((fill.min_m.y + fill.max_m.y).abs() < 1e-12 && fill.max_m.z == c.water_z());
        let h = scene.sensors.height.as_ref().unwrap();
        assert_eq!((h.base_z_m, h.reference_depth_m), (-0.5, Some(0.3)));
        assert!((h.bin_m - 0.075).abs() < 1e-12 && h.bins == 48);
    }

    /// A box cuts the roof's triangles whose centroid it holds into a sensor part of the roof's group
    /// (one 0.5 m column of a 2 m × 1 m roof of 0.5 m squares: 0.5 m²), followed like a named sensor;
    /// map positions become the times the front axle reaches them (x = x₀ + v t at 2 m/s).
    #[test]
    fn box_patches_become_sensor_parts_and_map_positions_become_times() {
        let dir = tempfile::tempdir().unwrap();
        let mut cfg = config(dir.path());
        let roof = dir.path().join("roof.stl");
        let mut mesh = TriMesh::rectangle(2.0, 1.0, 3.0, 4, 2);
        mesh.map_vertices(|v| v + Vec3::new(0.5, -0.5, 0.0));
        write_stl(&roof, "roof", &mesh).unwrap();
        cfg.vehicle.parts.push(PartFile { file: roof, scale: 1.0, group: Some("body".into()) });
        cfg.sensor_boxes = vec![SensorBox {
            name: "antenna".into(),
            part: "roof".into(),
            min_m: Vec3::new(0.4, -0.6, 2.9),
            max_m: Vec3::new(1.0, 0.6, 3.1),
        }];
        cfg.output.map_positions_m = vec![5.0, 6.0];
        let plan = plan(&cfg).unwrap();
        assert_eq!(plan.sensors, vec!["fl".to_owned(), "antenna".to_owned()]);
        let k = plan.parts.iter().position(|p| p.name == "antenna").unwrap();
        assert_eq!(plan.groups[k], "body");
        assert!((plan.parts[k].mesh.total_area() - 0.5).abs() < 1e-12);
        let roof = plan.parts.iter().find(|p| p.name == "roof").unwrap();
        assert!((roof.mesh.total_area() - 1.5).abs() < 1e-12);
        for (t, x) in plan.map_times.iter().zip([5.0, 6.0]) {
            assert!((t - (x - plan.x_front0) / 2.0).abs() < 1e-9, "{t} for x = {x}");
        }
        let scene = scene(&cfg, &plan, &dir.path().join("geometry")).unwrap();
        assert_eq!(scene.output.wetting_map_times_s, plan.map_times);
        assert!(scene.walls.iter().any(|w| w.name == "antenna" && w.motion.as_deref() == Some("body")));
        cfg.output.map_positions_m = vec![100.0];
        let e = plan_err(&cfg);
        assert!(e.starts_with("output.map_positions_m[0]: 100 m: the front axle travels from x ="), "{e}");
        cfg.output.map_positions_m.clear();
        cfg.sensor_boxes[0].part = "fl".into();
        let e = plan_err(&cfg);
        assert!(e.starts_with("sensor_boxes[0].part: part = \"fl\" is a wheel"), "{e}");
    }

    /// `sensors.csv` from a scene's `series.csv`: per sensor its wet area over its area (from
    /// `wetting.csv`), the water at it and its arrival rate as written; a sensor without its columns is
    /// named. Hand-made tables: sensor `fl` of area 2 m² (wet 0.5 m² at t = 0.1 s: 25 %).
    #[test]
    fn the_sensor_table_holds_wet_fraction_water_and_arrival() {
        let dir = tempfile::tempdir().unwrap();
        let cfg = config(dir.path());
        let plan = plan(&cfg).unwrap();
        assert_eq!(plan.sensors, vec!["fl".to_owned()]);
        let rd = spatter_io::run::RunDir::create(&dir.path().join("run")).unwrap();
        let series =
            "t_s,fl_Fx_N,fl_wet_area_m2,fl_water_m3,fl_water_arrival_m3_s\n0,1,0,0,0\n0.1,2,0.5,0.003,0.02\n";
        std::fs::write(rd.path("series.csv"), series).unwrap();
        let area = vec![("fl".to_owned(), 2.0, 0.1)];
        let mut summary = RunSummary::new(Finished::Completed);
        sensor_series(&plan, &rd, &area, &mut summary).unwrap();
        let text = std::fs::read_to_string(rd.path("sensors.csv")).unwrap();
        let rows: Vec<&str> = text.lines().collect();
        assert_eq!(rows[0], "t_s,fl_wet_fraction,fl_water_m3,fl_water_arrival_m3_s");
        let last: Vec<f64> = rows[2].split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(last, vec![0.1, 0.25, 0.003, 0.02]);
        for png in ["sensors.png", "sensors_water.png", "sensors_arrival.png"] {
            assert!(rd.path(png).is_file(), "{png}");
        }
        std::fs::write(rd.path("series.csv"), "t_s,fl_wet_area_m2\n0,0\n").unwrap();
        let e = sensor_series(&plan, &rd, &area, &mut summary).unwrap_err().to_string();
        assert!(e.contains("no column fl_water_m3 for sensors[0]"), "{e}");
    }

    /// Rows `t v ω` of a motion table's text.
    fn table_rows(path: &Path) -> Vec<Vec<f64>> {
        let text = std::fs::read_to_string(path).unwrap();
        text.lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
            .collect()
    }

    /// A straight path along the centre line at 2 m/s (two rows) moves the vehicle as `speed_m_s = 2`
    /// does: the same placement at t = 0 (to 1e-12 m) and the same motion tables, row for row (times to
    /// 1e-12 s: the sampling step 2 cm / v_max takes v_max from the path's samples), to 1e-7 m/s and
    /// rad/s. (The tables differentiate the placement over 2·10⁻⁶ s, so position round-off of
    /// 10⁻¹⁵ m — the path's cubic evaluated on a line — shows as up to 10⁻⁹ m/s.)
    #[test]
    fn a_straight_path_moves_the_vehicle_as_the_speed_does() {
        let dir = tempfile::tempdir().unwrap();
        let cfg = config(dir.path());
        let by_speed = plan(&cfg).unwrap();
        let geo_speed = dir.path().join("by_speed");
        let scene_speed = scene(&cfg, &by_speed, &geo_speed).unwrap();
        let mut on_path = cfg.clone();
        let (x0, t1) = (by_speed.x_front0, by_speed.t_end + 1.0);
        on_path.motion = MotionSpec {
            speed_m_s: None,
            file: None,
            path: Some(PathSpec {
                file: None,
                rows: Some(vec![vec![0.0, x0, 0.0], vec![t1, x0 + 2.0 * t1, 0.0]]),
            }),
        };
        let by_path = plan(&on_path).unwrap();
        assert!((by_path.t_end - by_speed.t_end).abs() < 1e-9, "{} vs {}", by_path.t_end, by_speed.t_end);
        assert!((by_path.t_enter - by_speed.t_enter).abs() < 1e-9);
        on_path.output.end_time_s = Some(by_speed.t_end);
        let by_path = plan(&on_path).unwrap();
        let geo_path = dir.path().join("by_path");
        let scene_path = scene(&on_path, &by_path, &geo_path).unwrap();
        for (a, b) in scene_speed.motions.iter().zip(&scene_path.motions) {
            let (ra, rb) = (a.reference_point_m.unwrap(), b.reference_point_m.unwrap());
            assert!((ra - rb).length() < 1e-12, "{}: reference point {ra} vs {rb}", a.name);
            let (ta, tb) = (table_rows(a.file.as_ref().unwrap()), table_rows(b.file.as_ref().unwrap()));
            assert_eq!(ta.len(), tb.len(), "{}", a.name);
            for (x, y) in ta.iter().zip(&tb) {
                assert!((x[0] - y[0]).abs() < 1e-12, "{}: times {} vs {}", a.name, x[0], y[0]);
                for j in 1..7 {
                    assert!(
                        (x[j] - y[j]).abs() < 1e-7,
                        "{} at t = {}: column {j}: {} vs {}",
                        a.name,
                        x[0],
                        x[j],
                        y[j]
                    );
                }
            }
        }
        for part in ["fl", "rr"] {
            let a = TriMesh::load(&geo_speed.join(format!("{part}.stl")), 1.0).unwrap();
            let b = TriMesh::load(&geo_path.join(format!("{part}.stl")), 1.0).unwrap();
            for (u, v) in a.vertices.iter().zip(&b.vertices) {
                assert!((*u - *v).length() < 1e-12, "{part}: {u} vs {v}");
            }
        }
    }

    /// The vehicle on an arc of radius ρ = 30 m at 2 m/s (ω = 1/15 rad/s, rows every 0.25 s over 3 s),
    /// wheelbase L = 3 m: the integrated body motion keeps the front axle on the path (to 3 mm, the motion
    /// table's integration) and, once the rear axle has driven onto the arc (t ≥ L/v = 1.5 s), the rear
    /// axle's centre-line point on the same circle (to 3 mm); before that the rear axle is on the straight
    /// line that continues the path backwards (y = −0.3 m). The body heading lags the tangent ω t by the
    /// chord angle asin(L / 2ρ) = 0.05002 rad (geometry of a chord of length L in a circle of radius ρ; to
    /// 2 mrad), both axles on the road; each wheel spins about the body's lateral axis at v/R (to 10⁻⁴:
    /// the table samples the speed every 2 cm).
    #[test]
    fn on_a_curved_path_the_rear_axle_trails_the_front_on_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let mut cfg = config(dir.path());
        let x0 = plan(&cfg).unwrap().x_front0;
        let (r, w) = (30.0, 2.0 / 30.0);
        let rows: Vec<Vec<f64>> = (0..=12)
            .map(|k| {
                let t = 0.25 * k as f64;
                vec![t, x0 + r * (w * t).sin(), -0.3 + r * (1.0 - (w * t).cos())]
            })
            .collect();
        cfg.motion =
            MotionSpec { speed_m_s: None, file: None, path: Some(PathSpec { file: None, rows: Some(rows) }) };
        cfg.output.end_time_s = Some(3.0);
        let plan = plan(&cfg).unwrap();
        let scene = scene(&cfg, &plan, &dir.path().join("geometry")).unwrap();
        let c = cfg.channel.generated().unwrap();
        let load = |k: usize| {
            let m = &scene.motions[k];
            let text = std::fs::read_to_string(m.file.as_ref().unwrap()).unwrap();
            Motion::Tabulated(MotionTable::parse(&text, m.reference_point_m.unwrap()).unwrap())
        };
        let mut tree = spatter_core::motion::KinematicTree::new();
        let body = tree.add(load(0), None);
        let spin = tree.add(load(1), Some(body));
        let p0 = place_along(&plan.parts, &cfg.vehicle.wheels, &c, &plan.travel, 0.0);
        let front0 = p0.apply(Vec3::new(3.0, 0.0, 2.4));
        let rear0 = p0.apply(Vec3::new(0.0, 0.0, 2.4));
        let axle0 = p0.apply(Vec3::new(3.0, 1.0, 2.4)) - p0.apply(Vec3::new(3.0, 0.0, 2.4));
        let chord = (3.0 / (2.0 * r)).asin();
        for k in 0..30 {
            let t = 0.1 * k as f64;
            let f = tree.world_point(body, t, front0);
            let rr = tree.world_point(body, t, rear0);
            let (xp, yp) = (x0 + r * (w * t).sin(), -0.3 + r * (1.0 - (w * t).cos()));
            assert!((f.x - xp).hypot(f.y - yp) < 3e-3, "t = {t}: front axle {f} off the path ({xp}, {yp})");
            if t >= 1.5 {
                let off = (rr.x - x0).hypot(rr.y - (r - 0.3)) - r;
                assert!(off.abs() < 3e-3, "t = {t}: rear axle {rr} {off} m off the circle");
            } else {
                assert!((rr.y + 0.3).abs() < 3e-3, "t = {t}: rear axle {rr} off the lead-in line");
            }
            assert!((f.z - c.axle_z(f.x, 0.4)).abs() < 3e-3, "t = {t}: front axle {f} off the road");
            assert!((rr.z - c.axle_z(rr.x, 0.4)).abs() < 3e-3, "t = {t}: rear axle {rr} off the road");
            let fwd = f - rr;
            let heading = fwd.y.atan2(fwd.x);
            if t >= 1.5 {
                assert!((heading - (w * t - chord)).abs() < 2e-3, "t = {t}: body heading {heading}");
            }
            // The wheel's own spin (its angular velocity less the body's) lies along the body's axle.
            let rel = tree.angular_velocity(spin, t) - tree.angular_velocity(body, t);
            let axle = tree.rotation(body, t) * axle0;
            assert!(rel.cross(axle).length() < 1e-9 * rel.length(), "t = {t}: spin {rel} not along {axle}");
            assert!(
                (rel.length() - plan.travel.speed(t) / 0.4).abs() < 1e-4 * 5.0,
                "t = {t}: ω = {}",
                rel.length()
            );
            assert!((plan.travel.speed(t) - 2.0).abs() < 0.01);
        }
    }

    /// On a straight path along x (off the centre line, y = 0.3 m, through the entry ramp) the trailing
    /// rear axle changes nothing: every placement equals, bit for bit, the one headed along the path's
    /// tangent (the model before the rear axle trailed).
    #[test]
    fn on_a_straight_path_the_trailing_rear_axle_changes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let mut cfg = config(dir.path());
        let x0 = plan(&cfg).unwrap().x_front0;
        cfg.motion = MotionSpec {
            speed_m_s: None,
            file: None,
            path: Some(PathSpec {
                file: None,
                rows: Some(vec![vec![0.0, x0, 0.3], vec![1.0, x0 + 1.5, 0.3], vec![3.0, x0 + 6.5, 0.3]]),
            }),
        };
        cfg.output.end_time_s = Some(3.0);
        let plan = plan(&cfg).unwrap();
        let Travel::Path { path, .. } = &plan.travel else { panic!("a path") };
        let c = cfg.channel.generated().unwrap();
        for k in 0..=300 {
            let t = 0.01 * k as f64;
            let tangent = place_on_road(&plan.parts, &cfg.vehicle.wheels, &c, path.point(t), path.heading(t));
            let trailing = place_along(&plan.parts, &cfg.vehicle.wheels, &c, &plan.travel, t);
            assert_eq!(trailing, tangent, "t = {t}");
        }
    }

    /// A path that leaves the channel, a row height off the road, a garbled file and one row are named
    /// by key, file, line and value.
    #[test]
    fn bad_paths_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let mut cfg = config(dir.path());
        let x0 = plan(&cfg).unwrap().x_front0;
        let path_rows = |rows: Vec<Vec<f64>>| MotionSpec {
            speed_m_s: None,
            file: None,
            path: Some(PathSpec { file: None, rows: Some(rows) }),
        };
        cfg.output.end_time_s = Some(2.0);
        // 0.7 m off the centre line the vehicle (1.8 m wide) reaches beyond the wall at y = 1.5 m.
        cfg.motion = path_rows(vec![vec![0.0, x0, 0.7], vec![2.0, x0 + 4.0, 0.7]]);
        let e = plan_err(&cfg);
        assert!(
            e.starts_with("motion.path: at t = 0.000 s (after rows[0]) the vehicle leaves the channel"),
            "{e}"
        );
        assert!(e.contains("reaches y = 1.600 m, beyond the side wall at y = +1.5 m"), "{e}");
        // Heights: on the flat approach the front axle rides at R = 0.4 m.
        cfg.motion = path_rows(vec![vec![0.0, x0 - 1.0, 0.0, 0.4], vec![2.0, x0 + 3.0, 0.0, 0.9]]);
        let e = plan_err(&cfg);
        assert!(
            e.starts_with("motion.path: rows[1]: z = 0.9 m, but the road carries the front axle at z = "),
            "{e}"
        );
        let f = dir.path().join("path.csv");
        std::fs::write(&f, "t_s,x_m,y_m\n0,4.2,0\n1,6.2,zero\n").unwrap();
        cfg.motion = MotionSpec {
            speed_m_s: None,
            file: None,
            path: Some(PathSpec { file: Some(f.clone()), rows: None }),
        };
        let e = plan_err(&cfg);
        assert!(
            e.starts_with("motion.path.file: ") && e.contains("path.csv line 3: `zero` is not a number"),
            "{e}"
        );
        std::fs::write(&f, "0 4.2 0\n").unwrap();
        let e = plan_err(&cfg);
        assert!(e.contains("path.csv: 1 row(s); a path needs at least two rows"), "{e}");
        std::fs::write(&f, "0 4.2 0\n1 4.0 0\n").unwrap();
        cfg.output.end_time_s = None;
        let e = plan_err(&cfg);
        assert!(
            e.starts_with("motion.path: the path's front axle never reaches the end of the pool floor"),
            "{e}"
        );
        let mut both = cfg.clone();
        both.motion.speed_m_s = Some(2.0);
        let errs = spatter_core::check::Checker::run(&both, None).unwrap_err();
        assert!(
            errs.iter().any(|e| e.key == "motion.speed_m_s" && e.message.contains("exactly one")),
            "{errs:?}"
        );
    }

    fn plan_err(cfg: &WadingConfig) -> String {
        plan(cfg).err().unwrap().to_string()
    }

    #[test]
    fn unknown_sensors_and_stalling_tables_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let mut cfg = config(dir.path());
        cfg.sensors = vec!["fl".into(), "mirror".into()];
        let e = plan(&cfg).err().unwrap().to_string();
        assert!(
            e.starts_with("sensors[1]: \"mirror\" names no vehicle part; the parts are: fl, fr, rl, rr"),
            "{e}"
        );
        cfg.sensors.clear();
        let table = dir.path().join("v.txt");
        std::fs::write(&table, "0 2\n1 0\n").unwrap();
        cfg.motion = MotionSpec { speed_m_s: None, file: Some(table), path: None };
        let e = plan(&cfg).err().unwrap().to_string();
        assert!(e.starts_with("motion.file: the speed table comes to rest"), "{e}");
        cfg.vehicle.wheels[0].part = "front".into();
        let e = plan(&cfg).err().unwrap().to_string();
        assert!(e.starts_with("vehicle.wheels[0].part: part = \"front\" names no part"), "{e}");
    }
}
