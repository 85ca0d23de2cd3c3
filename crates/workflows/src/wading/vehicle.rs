//! The vehicle: its part files, its wheels (found by part name, with axle and radius), checks that name
//! the scenario key of every problem, and its placement on the channel's road.

use super::bisect::bisect;
use super::channel::{pitch, Road};
use super::parts::{bounds, wheel_reach, NamedPart};
use serde::{Deserialize, Serialize};
use spatter_core::check::Invalid;
use spatter_core::Vec3;
use std::path::PathBuf;

fn one() -> f64 {
    1.0
}

fn axis_y() -> Vec3 {
    Vec3::Y
}

/// A mesh file of the vehicle; its solids become parts ([`super::parts::read_parts`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PartFile {
    pub file: PathBuf,
    /// Coordinate factor (0.001 for files in mm). Default 1.
    #[serde(default = "one")]
    pub scale: f64,
    /// Report group of the file's parts (cab, chassis, wheels, sensors, …). Default: the part's name.
    #[serde(default)]
    pub group: Option<String>,
}

/// A wheel: a part that rolls about its axle.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WheelSpec {
    /// Name of the part (a solid of one of the files).
    pub part: String,
    /// A point of the axle in the files' coordinates (after `scale`) \[m\].
    pub axle_m: Vec3,
    /// Rolling radius \[m\]; the wheel turns at ω = v/R.
    pub radius_m: f64,
    /// Axle direction. Default `[0, 1, 0]` (across the channel).
    #[serde(default = "axis_y")]
    pub axis: Vec3,
}

/// Relative mismatch allowed between a wheel's declared radius and its mesh's reach from the axle.
pub const RADIUS_TOLERANCE: f64 = 0.02;

/// Every problem of the wheels against the parts read: a wheel whose part does not exist (the message
/// lists the parts), an axle not across the channel (y), and a wheel whose mesh does not reach its
/// declared radius from its axle (it would not touch the road, or would sink into it), each under the key
/// `vehicle.wheels[k]…`.
pub fn check_wheels(parts: &[NamedPart], wheels: &[WheelSpec]) -> Vec<Invalid> {
    let mut errs = Vec::new();
    let names: Vec<&str> = parts.iter().map(|p| p.name.as_str()).collect();
    for (k, w) in wheels.iter().enumerate() {
        let key = |field: &str| format!("vehicle.wheels[{k}].{field}");
        let Some(part) = parts.iter().find(|p| p.name == w.part) else {
            errs.push(Invalid {
                key: key("part"),
                message: format!("part = \"{}\" names no part; the parts are: {}", w.part, names.join(", ")),
            });
            continue;
        };
        if let Some(j) = wheels[..k].iter().position(|o| o.part == w.part) {
            errs.push(Invalid {
                key: key("part"),
                message: format!(
                    "part = \"{}\" is already wheel {j} (vehicle.wheels[{j}]); each wheel is its own part",
                    w.part
                ),
            });
            continue;
        }
        if !(w.radius_m > 0.0 && w.radius_m.is_finite()) {
            errs.push(Invalid {
                key: key("radius_m"),
                message: format!("radius_m = {} must be > 0", w.radius_m),
            });
            continue;
        }
        let axis = w.axis.normalize_or_zero();
        if axis == Vec3::ZERO {
            errs.push(Invalid { key: key("axis"), message: "axis = [0, 0, 0] has no direction".into() });
            continue;
        }
        if axis.y.abs() < 0.999 {
            // Before the reach: measured about another axis the mesh's reach says nothing about the radius.
            errs.push(Invalid {
                key: key("axis"),
                message: format!(
                    "axis = [{}, {}, {}]: wheels roll about the y axis (across the channel)",
                    w.axis.x, w.axis.y, w.axis.z
                ),
            });
            continue;
        }
        let reach = wheel_reach(&part.mesh, w.axle_m, axis);
        if (reach - w.radius_m).abs() > RADIUS_TOLERANCE * w.radius_m {
            errs.push(Invalid {
                key: key("radius_m"),
                message: format!(
                    "radius_m = {} m, but the mesh of part `{}` reaches {reach:.4} m from the axle at [{}, {}, {}]: \
                     placed by its radius the wheel would {} the road; give the axle and radius of the mesh \
                     (within {} %)",
                    w.radius_m,
                    w.part,
                    w.axle_m.x,
                    w.axle_m.y,
                    w.axle_m.z,
                    if reach < w.radius_m { "not touch" } else { "sink into" },
                    RADIUS_TOLERANCE * 100.0
                ),
            });
        }
    }
    errs
}

/// Every sensor name (`sensors[k]`) that names no part read, the message listing the parts.
pub fn check_sensor_names(parts: &[NamedPart], sensors: &[String]) -> Vec<Invalid> {
    let names: Vec<&str> = parts.iter().map(|p| p.name.as_str()).collect();
    sensors
        .iter()
        .enumerate()
        .filter(|(_, s)| !names.contains(&s.as_str()))
        .map(|(k, s)| Invalid {
            key: format!("sensors[{k}]"),
            message: format!("\"{s}\" names no vehicle part; the parts are: {}", names.join(", ")),
        })
        .collect()
}

/// A vehicle as wide as the channel or wider: `width` \[m\] across the channel, reported under `key`
/// with `what` describing where the width comes from (`"width_m = 4 m"`).
pub fn check_width(parts: &[NamedPart], width: f64, key: &str, what: &str) -> Option<Invalid> {
    let b = bounds(parts);
    let across = b.max.y - b.min.y;
    (across >= width).then(|| Invalid {
        key: key.into(),
        message: format!(
            "{what} is not wider than the vehicle ({across:.3} m across its parts): it would not fit between the \
             walls"
        ),
    })
}

/// Rigid placement of the vehicle on the road: rotate by `pitch` \[rad\] (nose up positive) about the
/// rear axle, then turn by `yaw` \[rad\] (the heading, from +x towards +y) about the vertical through it,
/// then translate by `shift` \[m\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub pitch: f64,
    pub yaw: f64,
    pub pivot: Vec3,
    pub shift: Vec3,
}

impl Placement {
    /// World position of a point given in the files' coordinates.
    pub fn apply(&self, x: Vec3) -> Vec3 {
        let d = x - self.pivot;
        // Nose up for travel along +x: a rotation by −pitch about +y.
        let (s, c) = (-self.pitch).sin_cos();
        let mut r = Vec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
        if self.yaw != 0.0 {
            let (s, c) = self.yaw.sin_cos();
            r = Vec3::new(c * r.x - s * r.y, s * r.x + c * r.y, r.z);
        }
        self.pivot + r + self.shift
    }
}

/// The front wheel: the largest axle x.
pub fn front_wheel(wheels: &[WheelSpec]) -> Option<&WheelSpec> {
    wheels.iter().max_by(|a, b| a.axle_m.x.total_cmp(&b.axle_m.x))
}

/// The rear wheel: the smallest axle x.
pub fn rear_wheel(wheels: &[WheelSpec]) -> Option<&WheelSpec> {
    wheels.iter().min_by(|a, b| a.axle_m.x.total_cmp(&b.axle_m.x))
}

/// Wheelbase \[m\]: the distance between the front and the rear axle in the x–z plane of the files (0
/// without wheels).
pub fn wheelbase(wheels: &[WheelSpec]) -> f64 {
    match (front_wheel(wheels), rear_wheel(wheels)) {
        (Some(f), Some(r)) => ((f.axle_m.x - r.axle_m.x).powi(2) + (f.axle_m.z - r.axle_m.z).powi(2)).sqrt(),
        _ => 0.0,
    }
}

/// Places the vehicle so that its front axle (the wheels' largest axle x), at the middle of the parts'
/// extent across, is over `front = (x, y)` with the vehicle heading along `heading` \[rad from +x towards
/// +y\], every wheel on the road: the front and rear axle heights from [`Road::axle_height`], the rear
/// axle on the road at the axle-to-axle distance behind the front one along the heading, and the pitch
/// from the two. `front = (x, 0)` with heading 0 centres the vehicle across the generated channel.
/// `wheels` must have passed [`check_wheels`]; the heading must be within 90° of +x.
pub fn place_on_road(
    parts: &[NamedPart],
    wheels: &[WheelSpec],
    road: &dyn Road,
    front_at: (f64, f64),
    heading: f64,
) -> Placement {
    let (Some(front), Some(rear)) = (front_wheel(wheels), rear_wheel(wheels)) else {
        return Placement { pitch: 0.0, yaw: 0.0, pivot: Vec3::ZERO, shift: Vec3::ZERO };
    };
    let b = bounds(parts);
    let y_mid = 0.5 * (b.min.y + b.max.y);
    let (x_front, y_front) = front_at;
    // The rear axle sits on the road at the wheelbase behind the front one along the heading (bisection
    // on its x: the distance grows as the rear axle moves back).
    let span = wheelbase(wheels);
    let zf = road.axle_height(x_front, y_front, front.radius_m, heading);
    let (cos_h, tan_h) = (heading.cos(), heading.tan());
    let rear_y = |xr: f64| y_front + (xr - x_front) * tan_h;
    let dist = |xr: f64| {
        let yr = rear_y(xr);
        ((x_front - xr).powi(2)
            + (y_front - yr).powi(2)
            + (zf - road.axle_height(xr, yr, rear.radius_m, heading)).powi(2))
        .sqrt()
    };
    let (lo, hi) = bisect(x_front - span - 1.0, x_front, |xr| dist(xr) > span);
    let x_rear = 0.5 * (lo + hi);
    let y_rear = rear_y(x_rear);
    let zr = road.axle_height(x_rear, y_rear, rear.radius_m, heading);
    let th = (zf - zr).atan2((x_front - x_rear) / cos_h)
        - pitch((front.axle_m.x, front.axle_m.z), (rear.axle_m.x, rear.axle_m.z));
    // The pivot (the rear wheel's axle point, `dy` off the centre line) turns with the heading.
    let dy = rear.axle_m.y - y_mid;
    let (sin_h, cos_h) = heading.sin_cos();
    Placement {
        pitch: th,
        yaw: heading,
        pivot: rear.axle_m,
        shift: Vec3::new(
            x_rear - sin_h * dy - rear.axle_m.x,
            y_rear - y_mid + (cos_h - 1.0) * dy,
            zr - rear.axle_m.z,
        ),
    }
}

/// The vehicle placed on the road at time `t` of its travel ([`place_on_road`]). On a path the rear
/// axle trails the front one on the path: the heading is the direction from the path's point the rear
/// axle's horizontal distance behind to the front axle, and since that distance is the wheelbase shortened
/// by the pitch (on a ramp), it is found by fixed-point iteration (three rounds from the whole wheelbase:
/// the distance changes by (1 − cos θ) of the wheelbase, the heading by far less).
pub fn place_along(
    parts: &[NamedPart],
    wheels: &[WheelSpec],
    road: &dyn Road,
    travel: &super::timeline::Travel,
    t: f64,
) -> Placement {
    let front = travel.front(t);
    let mut p = place_on_road(parts, wheels, road, front, travel.heading(t));
    if let (super::timeline::Travel::Path { .. }, Some(rear)) = (travel, rear_wheel(wheels)) {
        let b = bounds(parts);
        let rear_mid = Vec3::new(rear.axle_m.x, 0.5 * (b.min.y + b.max.y), rear.axle_m.z);
        for _ in 0..3 {
            let r = p.apply(rear_mid);
            let behind = (front.0 - r.x).hypot(front.1 - r.y);
            p = place_on_road(parts, wheels, road, front, travel.heading_with(t, behind));
        }
    }
    p
}

/// Angular speed \[rad/s\] about +axis of a wheel of radius `r` rolling without slip at speed `v` along
/// +x with its axle along +y: ω = v/R (the contact point `v e_x + ω e_y × (−R e_z)` is at rest).
pub fn rolling_speed(v: f64, r: f64) -> f64 {
    v / r
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use spatter_core::mesh::TriMesh;

    /// The tread of a wheel for the wading tests: a cylinder of radius `r` and width `2 half_width` about
    /// the axle through `centre` along y, `n` facets round.
    pub(crate) fn wheel_mesh(centre: Vec3, r: f64, half_width: f64, n: usize) -> TriMesh {
        let mut soup = Vec::new();
        for k in 0..n {
            let a0 = k as f64 / n as f64 * std::f64::consts::TAU;
            let a1 = (k + 1) as f64 / n as f64 * std::f64::consts::TAU;
            let p = |a: f64, y: f64| centre + Vec3::new(r * a.cos(), y, r * a.sin());
            let (y0, y1) = (-half_width, half_width);
            soup.extend([p(a0, y0), p(a1, y0), p(a1, y1)]);
            soup.extend([p(a0, y0), p(a1, y1), p(a0, y1)]);
        }
        TriMesh::from_triangle_soup(&soup)
    }

    fn truck() -> (Vec<NamedPart>, Vec<WheelSpec>) {
        let mut parts = Vec::new();
        let mut wheels = Vec::new();
        for (name, x, y) in
            [("wheel_fl", 4.0, 1.0), ("wheel_fr", 4.0, -1.0), ("wheel_rl", 0.0, 1.0), ("wheel_rr", 0.0, -1.0)]
        {
            let c = Vec3::new(x, y, 0.5);
            parts.push(NamedPart { name: name.into(), mesh: wheel_mesh(c, 0.5, 0.15, 32) });
            wheels.push(WheelSpec { part: name.into(), axle_m: c, radius_m: 0.5, axis: Vec3::Y });
        }
        (parts, wheels)
    }

    /// The shared test channel, lengthened to take the 4 m wheelbase.
    fn channel() -> crate::wading::channel::ChannelSpec {
        crate::wading::channel::ChannelSpec {
            approach_length_m: 8.0,
            pool_length_m: 10.0,
            ..crate::wading::channel::tests::channel()
        }
    }

    #[test]
    fn wheels_are_checked_by_name_and_radius() {
        let (parts, mut wheels) = truck();
        assert!(check_wheels(&parts, &wheels).is_empty());
        wheels[1].part = "wheel_xx".into();
        wheels[2].radius_m = 0.6;
        let errs = check_wheels(&parts, &wheels);
        assert_eq!(errs.len(), 2, "{errs:?}");
        assert_eq!(errs[0].key, "vehicle.wheels[1].part");
        assert!(
            errs[0].message.contains("\"wheel_xx\" names no part; the parts are: wheel_fl, wheel_fr"),
            "{}",
            errs[0].message
        );
        assert_eq!(errs[1].key, "vehicle.wheels[2].radius_m");
        assert!(errs[1].message.contains("would not touch the road"), "{}", errs[1].message);
    }

    #[test]
    fn a_vehicle_wider_than_the_channel_is_named() {
        let (parts, _) = truck();
        assert!(check_width(&parts, channel().width_m, "channel.width_m", "width_m = 4 m").is_none());
        let e = check_width(&parts, 2.2, "channel.width_m", "width_m = 2.2 m").unwrap();
        assert_eq!(e.key, "channel.width_m");
        assert!(e.message.contains("2.300 m across"), "{}", e.message);
    }

    /// On the flat approach the truck stands level with its axles at R; with the front axle on the entry
    /// ramp it pitches nose down and both wheels touch the road (axle heights from the channel's profile).
    #[test]
    fn the_vehicle_stands_on_the_road() {
        let (parts, wheels) = truck();
        let c = channel();
        let p = place_on_road(&parts, &wheels, &c, (6.0, 0.0), 0.0);
        assert!(p.pitch.abs() < 1e-12);
        let f = p.apply(wheels[0].axle_m);
        assert!((f - Vec3::new(6.0, 1.0, 0.5)).length() < 1e-12, "{f}");
        for x_front in [9.5, 11.0, 13.0, 20.0, 23.5] {
            let p = place_on_road(&parts, &wheels, &c, (x_front, 0.0), 0.0);
            let f = p.apply(wheels[0].axle_m);
            let r = p.apply(wheels[2].axle_m);
            assert!((f.x - x_front).abs() < 1e-9, "front axle at {} not {x_front}", f.x);
            assert!(((f - r).length() - 4.0).abs() < 1e-9, "wheelbase kept");
            assert!((f.z - c.axle_z(f.x, 0.5)).abs() < 1e-6, "front wheel on the road at {x_front}: {f}");
            assert!((r.z - c.axle_z(r.x, 0.5)).abs() < 1e-6, "rear wheel on the road at {x_front}: {r}");
            if x_front == 9.5 {
                assert!(p.pitch < -0.05, "nose down on the entry ramp: {}", p.pitch);
            }
        }
        assert!((rolling_speed(3.0, 0.5) - 6.0).abs() < 1e-15);
    }
}
