//! Event log and trajectories of a scene (`[output.events]`, `[output.trajectories]`): per body or free
//! sphere its first wall impact (time, wall, triangle, speed, angle in space and in a chosen plane), its
//! wall collisions per wall and its first crossing of a chosen plane; and the motion of selected bodies
//! and spheres every N steps.
//!
//! Objects are keyed by kind and stable id: a rigid body by its body id, a free sphere by its particle
//! id. Both are numbered from 0 in insertion order (bodies and particles separately; members take
//! particle ids too). The log reads the engine's [`WallImpact`]s after every step and is checkpointed
//! with the scene, so an interrupted and resumed run writes the same files.

use serde::{Deserialize, Serialize};
use spatter_core::check::Checker;
use spatter_core::Vec3;
use spatter_dem::contact::ContactLaw;
use spatter_dem::sim::{Simulation, WallImpact};
use std::collections::BTreeMap;

/// `[output.events]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventsConfig {
    /// Normal of the plane in which impact angles are also measured (e.g. `[1, 0, 0]`: the angle seen in
    /// the y–z plane). Without it that column is NaN.
    #[serde(default)]
    pub angle_plane_normal: Option<Vec3>,
    /// A plane whose first crossing by each body or sphere is recorded, `{ point_m, normal }`.
    #[serde(default)]
    pub crossing_plane: Option<CrossingPlane>,
    /// Names of the walls whose contacts count as a first impact (default: every wall). Collisions are
    /// counted on every wall either way.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub first_impact_walls: Vec<String>,
}

/// A plane through `point_m` with normal `normal` (need not be unit length).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrossingPlane {
    pub point_m: Vec3,
    pub normal: Vec3,
}

/// `[output.trajectories]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrajectoryConfig {
    /// A row per selected object every this many steps.
    pub every_steps: u64,
    /// Ids to follow (body ids for bodies, particle ids for free spheres).
    #[serde(default)]
    pub ids: Vec<u32>,
    /// Also follow every object whose id is below this: the first K inserted bodies and spheres.
    #[serde(default)]
    pub first: u32,
}

impl EventsConfig {
    pub(crate) fn validate(&self, c: &mut Checker) {
        if let Some(m) = self.angle_plane_normal {
            check_direction(c, "angle_plane_normal", m);
        }
        if let Some(p) = &self.crossing_plane {
            c.nested("crossing_plane", |c| {
                c.finite_vec("point_m", p.point_m);
                check_direction(c, "normal", p.normal);
            });
        }
    }
}

impl TrajectoryConfig {
    pub(crate) fn validate(&self, c: &mut Checker) {
        if self.every_steps == 0 {
            c.fail("every_steps", "every_steps = 0: give a positive number of steps".to_string());
        }
        if self.ids.is_empty() && self.first == 0 {
            c.fail("ids", "select objects to follow: ids = [...] and/or first = K".to_string());
        }
    }

    /// Whether the object with this id is followed.
    fn follows(&self, id: u32) -> bool {
        id < self.first || self.ids.contains(&id)
    }
}

fn check_direction(c: &mut Checker, key: &str, v: Vec3) {
    c.finite_vec(key, v);
    if v.length() == 0.0 {
        c.fail(key, format!("{key} = [0, 0, 0] is not a direction"));
    }
}

/// A body (`true`) or a free sphere (`false`) and its stable id.
pub(super) type Key = (bool, u32);

/// The first wall impact of a body or free sphere.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct FirstImpact {
    /// Time \[s\].
    pub t: f64,
    /// Index of the wall.
    pub wall: usize,
    /// Triangle of a mesh wall.
    pub triangle: Option<u32>,
    /// |v| of the touching sphere's centre relative to the wall \[m/s\].
    pub speed: f64,
    /// Approach speed along the wall normal \[m/s\].
    pub normal_speed: f64,
    /// Angle between the velocity and the wall plane \[deg\].
    pub angle_deg: f64,
    /// The same angle seen in the plane of `angle_plane_normal` \[deg\] (NaN without one).
    pub plane_angle_deg: f64,
    /// Velocity of the touching sphere's centre relative to the wall \[m/s\].
    pub velocity: Vec3,
}

/// The first crossing of the crossing plane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Crossing {
    /// Time \[s\].
    pub t: f64,
    /// Centre (of mass) at the end of the step that crossed \[m\].
    pub pos: Vec3,
    /// Unit direction of motion there.
    pub dir: Vec3,
}

/// What the log knows of one body or free sphere.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ObjectRecord {
    /// Template index of a body, −1 for a sphere.
    pub template: i64,
    pub first: Option<FirstImpact>,
    /// Contacts formed per wall (a body touching a wall with several members in one step counts once).
    pub collisions: Vec<u64>,
    /// Signed distance to the crossing plane after the last step (NaN before the first, and on a rank
    /// the object has left).
    pub(super) side: f64,
    pub crossing: Option<Crossing>,
}

/// The state of the event log (checkpointed).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct EventLog {
    pub(super) records: BTreeMap<Key, ObjectRecord>,
    /// List rebuilds of the simulation at the last step taken in (the only steps at which objects change
    /// rank; `None` until the first step after a start or resume).
    #[serde(skip)]
    pub(super) rebuilds_seen: Option<u64>,
}

impl EventLog {
    pub(super) fn record(&mut self, key: Key, template: i64, walls: usize) -> &mut ObjectRecord {
        self.records.entry(key).or_insert_with(|| ObjectRecord {
            template,
            collisions: vec![0; walls],
            side: f64::NAN,
            ..Default::default()
        })
    }

    /// Takes in the wall impacts of the last step and the plane crossings.
    pub fn after_step<L: ContactLaw>(&mut self, sim: &Simulation<L>, cfg: &EventsConfig) {
        let t = sim.time();
        let walls = sim.walls.len();
        let bodies = sim.bodies();
        let template_of = |b: u32| body_template(bodies, b);
        let plane = cfg.angle_plane_normal.map(|m| m.normalize());
        let counts_as_first = |w: usize| {
            cfg.first_impact_walls.is_empty()
                || cfg.first_impact_walls.iter().any(|n| *n == sim.walls[w].name)
        };
        let mut counted: Vec<(Key, usize)> = Vec::new();
        for imp in sim.last_impacts() {
            let key: Key = match imp.body {
                Some(b) => (true, b),
                None => (false, imp.particle),
            };
            let template = imp.body.map_or(-1, template_of);
            let rec = self.record(key, template, walls);
            if !counted.contains(&(key, imp.wall)) {
                counted.push((key, imp.wall));
                rec.collisions[imp.wall] += 1;
            }
            if !counts_as_first(imp.wall) {
                continue;
            }
            let candidate = first_impact(imp, plane);
            // Among the contacts of one object that form in the same step, the fastest normal approach.
            match &mut rec.first {
                None => rec.first = Some(candidate),
                Some(f) if f.t == t && candidate.normal_speed > f.normal_speed => *f = candidate,
                Some(_) => {}
            }
        }
        if let Some(pl) = &cfg.crossing_plane {
            let n = pl.normal.normalize();
            let p = &sim.particles;
            let check = |key: Key, template: i64, x: Vec3, v: Vec3, log: &mut Self| {
                let s = (x - pl.point_m).dot(n);
                let rec = log.record(key, template, walls);
                if rec.crossing.is_none() && rec.side.is_finite() && (rec.side < 0.0) != (s < 0.0) {
                    rec.crossing = Some(Crossing { t, pos: x, dir: v.normalize_or_zero() });
                }
                rec.side = s;
            };
            for k in 0..bodies.len() {
                check((true, bodies.id[k]), bodies.template[k] as i64, bodies.pos[k], bodies.vel[k], self);
            }
            for i in (0..p.len()).filter(|&i| !p.is_member(i)) {
                check((false, p.id[i]), -1, p.pos[i], p.vel[i], self);
            }
        }
    }

    /// Columns of `events.csv` for a scene with these wall names.
    pub fn columns(wall_names: &[String]) -> Vec<String> {
        let mut c: Vec<String> = [
            "body",
            "id",
            "template",
            "first_impact_t_s",
            "first_impact_wall",
            "first_impact_triangle",
            "first_impact_speed_m_s",
            "first_impact_normal_speed_m_s",
            "first_impact_angle_deg",
            "first_impact_plane_angle_deg",
            "first_impact_vx_m_s",
            "first_impact_vy_m_s",
            "first_impact_vz_m_s",
        ]
        .iter()
        .map(|s| s.to_string())
        .collect();
        c.extend(wall_names.iter().map(|w| format!("collisions_{w}")));
        c.extend(
            [
                "crossing_t_s",
                "crossing_x_m",
                "crossing_y_m",
                "crossing_z_m",
                "crossing_dir_x",
                "crossing_dir_y",
                "crossing_dir_z",
            ]
            .iter()
            .map(|s| s.to_string()),
        );
        c
    }

    /// Rows of `events.csv`: one per body or sphere that hit a wall or was checked against the crossing
    /// plane, bodies first, by id; a gap (`None`, an empty cell) where an event did not happen (the wall
    /// index is −1 then) and for the in-plane angle of an impact whose velocity is normal to that plane.
    pub fn rows(&self) -> Vec<Vec<Option<f64>>> {
        let mut keys: Vec<&Key> = self.records.keys().collect();
        keys.sort_by_key(|k| (!k.0, k.1));
        keys.into_iter()
            .map(|k| {
                let r = &self.records[k];
                let mut row: Vec<Option<f64>> =
                    vec![Some(k.0 as u8 as f64), Some(k.1 as f64), Some(r.template as f64)];
                match &r.first {
                    Some(f) => row.extend([
                        Some(f.t),
                        Some(f.wall as f64),
                        Some(f.triangle.map_or(-1.0, |t| t as f64)),
                        Some(f.speed),
                        Some(f.normal_speed),
                        Some(f.angle_deg),
                        // NaN by design when the velocity has no component in the plane.
                        Some(f.plane_angle_deg).filter(|a| !a.is_nan()),
                        Some(f.velocity.x),
                        Some(f.velocity.y),
                        Some(f.velocity.z),
                    ]),
                    None => {
                        row.extend([None, Some(-1.0), Some(-1.0), None, None, None, None, None, None, None])
                    }
                }
                row.extend(r.collisions.iter().map(|&c| Some(c as f64)));
                match &r.crossing {
                    Some(c) => {
                        row.extend([c.t, c.pos.x, c.pos.y, c.pos.z, c.dir.x, c.dir.y, c.dir.z].map(Some))
                    }
                    None => row.extend([None; 7]),
                }
                row
            })
            .collect()
    }

    /// Every body (`true`) or free sphere (`false`) the log knows, with its stable id and record, in id
    /// order (bodies and spheres mixed).
    pub fn objects(&self) -> impl Iterator<Item = ((bool, u32), &ObjectRecord)> {
        self.records.iter().map(|(k, r)| (*k, r))
    }

    /// Objects that hit a wall, and objects that crossed the plane.
    pub fn counts(&self) -> (usize, usize) {
        let hit = self.records.values().filter(|r| r.first.is_some()).count();
        let crossed = self.records.values().filter(|r| r.crossing.is_some()).count();
        (hit, crossed)
    }
}

/// The template of the body with id `b` among `bodies` (−1 when it is not there). On one rank the ids are
/// sorted (they grow in insertion order and removal keeps the order); on several ranks bodies that
/// arrived from another rank are appended, so a miss of the binary search looks through them.
pub(super) fn body_template(bodies: &spatter_dem::clump::Bodies, b: u32) -> i64 {
    let k = bodies.id.binary_search(&b).ok().or_else(|| bodies.id.iter().position(|&x| x == b));
    k.map_or(-1, |k| bodies.template[k] as i64)
}

fn first_impact(imp: &WallImpact, plane: Option<Vec3>) -> FirstImpact {
    FirstImpact {
        t: imp.time,
        wall: imp.wall,
        triangle: imp.triangle,
        speed: imp.speed(),
        normal_speed: -imp.velocity.dot(imp.normal),
        angle_deg: imp.angle_deg(),
        plane_angle_deg: plane.map_or(f64::NAN, |m| imp.angle_in_plane_deg(m)),
        velocity: imp.velocity,
    }
}

/// Columns of `trajectories.csv`.
pub const TRAJECTORY_COLUMNS: &[&str] = &[
    "t_s", "body", "id", "x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s", "qw", "qx", "qy", "qz",
    "wx_rad_s", "wy_rad_s", "wz_rad_s",
];

/// Rows of `trajectories.csv` at the current time: the followed bodies (centre of mass, orientation of the
/// principal frame) then the followed free spheres (orientation 1, 0, 0, 0: spheres carry none).
pub fn trajectory_rows<L: ContactLaw>(sim: &Simulation<L>, cfg: &TrajectoryConfig) -> Vec<Vec<f64>> {
    let t = sim.time();
    let b = sim.bodies();
    let p = &sim.particles;
    let mut rows = Vec::new();
    for k in (0..b.len()).filter(|&k| cfg.follows(b.id[k])) {
        let q = b.quat[k];
        rows.push(trajectory_row(t, true, b.id[k], b.pos[k], b.vel[k], [q.w, q.x, q.y, q.z], b.omega[k]));
    }
    let mut spheres: Vec<usize> = (0..p.len()).filter(|&i| !p.is_member(i) && cfg.follows(p.id[i])).collect();
    spheres.sort_by_key(|&i| p.id[i]);
    for i in spheres {
        rows.push(trajectory_row(t, false, p.id[i], p.pos[i], p.vel[i], [1.0, 0.0, 0.0, 0.0], p.omega[i]));
    }
    rows
}

/// One row of `trajectories.csv` in the order of [`TRAJECTORY_COLUMNS`]; `q` is (w, x, y, z).
fn trajectory_row(t: f64, body: bool, id: u32, x: Vec3, v: Vec3, q: [f64; 4], w: Vec3) -> Vec<f64> {
    let kind = if body { 1.0 } else { 0.0 };
    vec![t, kind, id as f64, x.x, x.y, x.z, v.x, v.y, v.z, q[0], q[1], q[2], q[3], w.x, w.y, w.z]
}
