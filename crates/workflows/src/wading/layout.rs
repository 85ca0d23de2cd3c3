//! The channel a run drives through, generated from its dimensions ([`ChannelSpec`]) or read from an STL
//! file ([`StlChannel`]): what the run needs of either — the road the wheels roll on, the still water's
//! extent, the surfaces that become walls, the pool's fill and the room around it.

use super::channel::{ChannelSpec, Road};
use super::channel_stl::StlChannel;
use super::config::ChannelConfig;
use super::geometry::{road_mesh, side_walls_mesh};
use super::parts::NamedPart;
use super::vehicle::check_width;
use crate::sph_scene::config::{FillConfig, FillType};
use spatter_core::check::Invalid;
use spatter_core::mesh::TriMesh;
use spatter_core::Vec3;

/// The channel of a run.
#[derive(Clone, Debug)]
pub enum Channel {
    Generated(ChannelSpec),
    File(StlChannel),
}

impl Channel {
    /// The channel of `[channel]`: generated, or read from its file. Errors give the `[channel]` key
    /// (`file`, `water_depth_m`, or the missing dimension) and the message.
    pub fn new(cfg: &ChannelConfig) -> Result<Self, (String, String)> {
        if let Some(file) = &cfg.file {
            return StlChannel::read(file, cfg.water_depth_m)
                .map(Channel::File)
                .map_err(|e| (e.key.to_owned(), e.message));
        }
        cfg.generated().map(Channel::Generated).ok_or_else(|| {
            ("file".to_owned(), "give the generated channel's dimensions or file = \"….stl\"".to_owned())
        })
    }

    /// The road the wheels roll on.
    pub fn road(&self) -> &dyn Road {
        match self {
            Channel::Generated(c) => c,
            Channel::File(f) => f,
        }
    }

    /// Where the still water surface meets the road along the centre line, `(x_in, x_out)` \[m\].
    pub fn waterline(&self) -> (f64, f64) {
        match self {
            Channel::Generated(c) => c.waterline(),
            Channel::File(f) => f.waterline,
        }
    }

    /// End of the pool floor \[m\]: by default the run ends when the front axle gets there.
    pub fn pool_end_x(&self) -> f64 {
        match self {
            Channel::Generated(c) => c.pool_end_x(),
            Channel::File(f) => f.pool_end_x,
        }
    }

    /// The pool floor (the lowest road point), splash heights are measured from it \[m\].
    pub fn floor_z(&self) -> f64 {
        match self {
            Channel::Generated(c) => -c.pool_depth_m,
            Channel::File(f) => f.floor_z,
        }
    }

    /// Height of the still water surface \[m\].
    pub fn water_z(&self) -> f64 {
        match self {
            Channel::Generated(c) => c.water_z(),
            Channel::File(f) => f.water_z,
        }
    }

    /// Water depth over the floor \[m\] (the study's `x`).
    pub fn water_depth(&self) -> f64 {
        match self {
            Channel::Generated(c) => c.water_depth_m,
            Channel::File(f) => f.water_depth,
        }
    }

    /// Extent along the channel `(x_min, x_max)` \[m\].
    pub fn x_range(&self) -> (f64, f64) {
        match self {
            Channel::Generated(c) => (0.0, c.length()),
            Channel::File(f) => f.x_range,
        }
    }

    /// Extent across the channel `(y_min, y_max)` \[m\]: between the side walls of a generated channel,
    /// the road's extent of one from a file.
    pub fn y_range(&self) -> (f64, f64) {
        match self {
            Channel::Generated(c) => (-0.5 * c.width_m, 0.5 * c.width_m),
            Channel::File(f) => f.y_range,
        }
    }

    /// The centre line across \[m\]: where a vehicle driving by its speed is centred.
    pub fn centre_y(&self) -> f64 {
        match self {
            Channel::Generated(_) => 0.0,
            Channel::File(f) => f.y_mid(),
        }
    }

    /// Highest point of the channel's surfaces \[m\].
    pub fn top_z(&self) -> f64 {
        match self {
            Channel::Generated(c) => c.wall_height_m,
            Channel::File(f) => f.top_z,
        }
    }

    /// The surfaces that become walls of the scene, each with its name: `channel_road` and
    /// `channel_walls` of a generated channel, `channel_<solid>` for every solid of a file.
    pub fn surfaces(&self) -> Vec<(String, TriMesh)> {
        match self {
            Channel::Generated(c) => vec![
                ("channel_road".to_owned(), road_mesh(c)),
                ("channel_walls".to_owned(), side_walls_mesh(c)),
            ],
            Channel::File(f) => {
                f.solids.iter().map(|(p, _)| (format!("channel_{}", p.name), p.mesh.clone())).collect()
            }
        }
    }

    /// A vehicle of `parts` as wide as the channel or wider, named under `channel.width_m` (generated) or
    /// `channel.file`.
    pub fn check_vehicle_width(&self, parts: &[NamedPart]) -> Option<Invalid> {
        match self {
            Channel::Generated(c) => {
                check_width(parts, c.width_m, "channel.width_m", &format!("width_m = {} m", c.width_m))
            }
            Channel::File(f) => {
                let w = f.y_range.1 - f.y_range.0;
                let what =
                    format!("the channel of file = \"{}\", {w:.3} m across its road,", f.file.display());
                check_width(parts, w, "channel.file", &what)
            }
        }
    }

    /// The pool at rest with hydrostatic pressure: a flood fill of the lattice at spacing `dp` between
    /// the waterline points (one spacing beyond each), from the floor to the water surface, centred
    /// across the channel for any width (`⌊width/dp⌋` sites across), seeded in the water's middle (a
    /// generated channel) or over its deepest centre-line point (a file), so that it stays in the pool.
    pub fn pool_fill(&self, dp: f64) -> FillConfig {
        let (x_in, x_out) = self.waterline();
        let (y_lo, y_hi) = self.y_range();
        let n_across = ((y_hi - y_lo) / dp + 1e-9).floor();
        let half = 0.5 * n_across * dp;
        let mid = 0.5 * (y_lo + y_hi);
        let floor = self.floor_z();
        let seed = match self {
            Channel::Generated(c) => Vec3::new(0.5 * (x_in + x_out), 0.5 * dp, floor + 0.5 * c.water_depth_m),
            Channel::File(f) => {
                let x = f.deepest_x;
                let road = f.road_z(x, mid).unwrap_or(floor);
                Vec3::new(x, mid + 0.5 * dp, 0.5 * (road + f.water_z))
            }
        };
        FillConfig {
            kind: FillType::Flood,
            min_m: Vec3::new(x_in - dp, mid - half, floor),
            max_m: Vec3::new(x_out + dp, mid + half, self.water_z()),
            seed_m: Some(seed),
            velocity_m_s: Vec3::ZERO,
            hydrostatic: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::wading::channel_stl::tests::write_channel_file;
    use crate::wading::config::ChannelConfig;
    use crate::wading::run::{plan, scene, tests::config};
    use crate::wading::vehicle::place_along;
    use spatter_core::check::Checker;

    /// The test scenario's channel (`run::tests::config`) as a file of its road and walls, at 0.1 m
    /// spacing (three layers of water 0.3 m deep).
    fn both(dir: &std::path::Path) -> (crate::wading::WadingConfig, crate::wading::WadingConfig) {
        let mut generated = config(dir);
        generated.fluid.spacing_m = 0.1;
        let spec = generated.channel.generated().unwrap();
        let file = dir.join("channel.stl");
        write_channel_file(&file, &spec);
        let mut from_file = generated.clone();
        from_file.channel = ChannelConfig { file: Some(file), ..ChannelConfig::from(spec.clone()) };
        from_file.channel.approach_length_m = None;
        from_file.channel.ramp_length_m = None;
        from_file.channel.pool_length_m = None;
        from_file.channel.pool_depth_m = None;
        from_file.channel.exit_length_m = None;
        from_file.channel.width_m = None;
        from_file.channel.wall_height_m = None;
        (generated, from_file)
    }

    /// A channel file describing the generated channel's geometry holds the same pool: the same water
    /// level and fluid particle count (expected identical: the same lattice in the same fill box; the
    /// stated tolerance is 1 % for a flood fill stopped by the same surfaces sampled from other
    /// triangles), at rest with hydrostatic pressure: the top layer dp/2 under the water level, and the
    /// lowest layer (within 2 dp of the floor: the fill keeps its clearance from the wall) at
    /// p = ρ₀ g (z_water − z) (hydrostatics, the free surface at the water level) to 10⁻⁶. The vehicle starts at the same place, and its wheels stand on
    /// the road found by ray casting as on the generated one (to 10⁻⁹ m).
    #[test]
    fn a_channel_file_of_the_generated_geometry_holds_the_same_pool() {
        let dir = tempfile::tempdir().unwrap();
        let (generated, from_file) = both(dir.path());
        let (pg, pf) = (plan(&generated).unwrap(), plan(&from_file).unwrap());
        assert_eq!(pf.channel.water_z(), pg.channel.water_z());
        assert_eq!(pf.channel.floor_z(), pg.channel.floor_z());
        assert!((pf.x_front0 - pg.x_front0).abs() < 1e-9, "{} vs {}", pf.x_front0, pg.x_front0);
        for t in [0.0, 0.5, 1.0, 2.0] {
            let a = place_along(&pg.parts, &generated.vehicle.wheels, pg.channel.road(), &pg.travel, t);
            let b = place_along(&pf.parts, &from_file.vehicle.wheels, pf.channel.road(), &pf.travel, t);
            for w in &generated.vehicle.wheels {
                let (qa, qb) = (a.apply(w.axle_m), b.apply(w.axle_m));
                assert!((qa - qb).length() < 1e-9, "t = {t}, wheel {}: {qa} vs {qb}", w.part);
            }
        }
        let sg = scene(&generated, &pg, &dir.path().join("g")).unwrap();
        let sf = scene(&from_file, &pf, &dir.path().join("f")).unwrap();
        assert_eq!(sf.fill[0].max_m.z, sg.fill[0].max_m.z);
        let names: Vec<&str> = sf.walls.iter().take(2).map(|w| w.name.as_str()).collect();
        assert_eq!(names, ["channel_road", "channel_walls"]);
        let (simg, _) = crate::sph_scene::build(&sg).unwrap();
        let (simf, _) = crate::sph_scene::build(&sf).unwrap();
        let (ng, nf) = (simg.fluid.len(), simf.fluid.len());
        assert!(ng > 1000, "{ng} fluid particles");
        assert!(
            (nf as f64 - ng as f64).abs() <= 0.01 * ng as f64,
            "fluid particles: file {nf}, generated {ng}"
        );
        let eos = simf.params.eos();
        let (dp, g, rho0) = (0.1, simf.params.gravity.length(), simf.params.rest_density);
        let (floor, water) = (pf.channel.floor_z(), pf.channel.water_z());
        let z_min = simf.fluid.pos.iter().map(|p| p.z).fold(f64::INFINITY, f64::min);
        let z_max = simf.fluid.pos.iter().map(|p| p.z).fold(f64::NEG_INFINITY, f64::max);
        assert!((z_max + 0.5 * dp - water).abs() < 1e-9, "top layer {z_max} under the water level {water}");
        assert!(z_min < floor + 2.0 * dp, "lowest layer {z_min} m, floor {floor} m");
        eprintln!("fluid particles: generated {ng}, file {nf}; lowest layer at {z_min} m (floor {floor} m)");
        let mut lowest = 0;
        for (p, rho) in simf.fluid.pos.iter().zip(&simf.fluid.rho) {
            if p.z < z_min + 0.5 * dp {
                lowest += 1;
                let expect = rho0 * g * (water - p.z);
                let got = eos.pressure(*rho);
                assert!((got - expect).abs() < 1e-6 * expect, "at {p}: {got} Pa vs {expect} Pa");
            }
        }
        assert!(lowest > 100, "{lowest} particles on the floor");
    }

    /// `spatter check` (the scenario's validation) names every problem of a channel file by its key.
    #[test]
    fn check_names_bad_channel_files() {
        let dir = tempfile::tempdir().unwrap();
        let (generated, from_file) = both(dir.path());
        assert!(Checker::run(&from_file, None).is_ok());
        let keys = |cfg: &crate::wading::WadingConfig| -> Vec<(String, String)> {
            Checker::run(cfg, None).unwrap_err().into_iter().map(|e| (e.key, e.message)).collect()
        };
        let mut c = from_file.clone();
        c.channel.water_depth_m = 0.6;
        let e = keys(&c);
        assert!(e[0].0 == "channel.water_depth_m" && e[0].1.contains("above the road at its start"), "{e:?}");
        let mut c = from_file.clone();
        c.channel.width_m = Some(3.0);
        let e = keys(&c);
        assert!(e[0].0 == "channel.width_m" && e[0].1.contains("remove it"), "{e:?}");
        let mut c = from_file.clone();
        c.vehicle.parts[0].scale = 2.0;
        let e = keys(&c);
        assert!(e[0].0 == "channel.file" && e[0].1.contains("is not wider than the vehicle"), "{e:?}");
        let mut c = from_file.clone();
        c.channel.file = Some(dir.path().join("none.stl"));
        let e = keys(&c);
        assert!(e[0].0 == "channel.file" && e[0].1.contains("no such file"), "{e:?}");
        let mut c = generated.clone();
        c.channel.ramp_length_m = None;
        let e = keys(&c);
        assert!(e[0].0 == "channel" && e[0].1.starts_with("ramp_length_m is missing"), "{e:?}");
    }
}
