//! Parcel injection from points, boxes or the faces of an STL surface (e.g. a tyre).
//!
//! An injector releases `parcels` parcels, evenly in time over `[start_s, end_s]` (all at the first
//! step at or after `start_s` when the two are equal). The number released by time t is
//! ⌊parcels · (t − start)/(end − start)⌋, so the release is deterministic and resumable. Diameters are
//! drawn from the size distribution (by number); every parcel stands for `particles_per_parcel`
//! particles, or carries `mass_per_parcel_kg`, or — with `mass_flow_kg_s` — the mass flow divided by
//! the parcel rate.

use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::distribution::SizeDistribution;
use spatter_core::mesh::TriMesh;
use spatter_core::rng::{seeded, Rng, RngExt};
use spatter_core::Vec3;
use std::path::PathBuf;

/// Where parcels start.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case", deny_unknown_fields)]
pub enum Region {
    /// Cycles through the listed points.
    Points { points_m: Vec<Vec3> },
    /// Uniformly inside the box.
    Box { min_m: Vec3, max_m: Vec3 },
    /// Uniformly (by area) on the faces of an STL/OBJ surface, `offset_m` off the surface along the
    /// face normal.
    Surface {
        file: PathBuf,
        #[serde(default = "one")]
        scale: f64,
        #[serde(default)]
        offset_m: f64,
    },
}

fn one() -> f64 {
    1.0
}

/// An injector as written in a scenario (`[[injectors]]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InjectorSpec {
    #[serde(default = "default_name")]
    pub name: String,
    pub region: Region,
    /// Particle size distribution (diameters in m).
    pub size: SizeDistribution,
    #[serde(rename = "density_kg_m3")]
    pub density: f64,
    /// Initial velocity \[m/s\].
    #[serde(rename = "velocity_m_s", default)]
    pub velocity: Vec3,
    /// Extra speed along the face normal for surface injection \[m/s\].
    #[serde(rename = "normal_speed_m_s", default)]
    pub normal_speed: f64,
    /// Standard deviation of a Gaussian velocity perturbation per component \[m/s\].
    #[serde(rename = "velocity_spread_m_s", default)]
    pub velocity_spread: f64,
    /// Number of parcels released.
    pub parcels: u64,
    #[serde(default)]
    pub start_s: f64,
    #[serde(default)]
    pub end_s: f64,
    /// Particles per parcel (default 1 when neither mass option is given).
    #[serde(default)]
    pub particles_per_parcel: Option<f64>,
    /// Mass of every parcel \[kg\].
    #[serde(default)]
    pub mass_per_parcel_kg: Option<f64>,
    /// Mass flow \[kg/s\] (needs end_s > start_s).
    #[serde(default)]
    pub mass_flow_kg_s: Option<f64>,
    #[serde(default)]
    pub seed: u64,
}

fn default_name() -> String {
    "injector".into()
}

impl Validate for InjectorSpec {
    fn validate(&self, c: &mut Checker) {
        match &self.region {
            Region::Points { points_m } => {
                if points_m.is_empty() {
                    c.fail("region.points_m", "points_m must list at least one point");
                }
                for (i, p) in points_m.iter().enumerate() {
                    c.finite_vec(&format!("region.points_m[{i}]"), *p);
                }
            }
            Region::Box { min_m, max_m } => {
                c.finite_vec("region.min_m", *min_m);
                c.finite_vec("region.max_m", *max_m);
                if min_m.cmpgt(*max_m).any() {
                    c.fail("region.max_m", "max_m must be ≥ min_m in every component");
                }
            }
            Region::Surface { file, scale, offset_m } => {
                c.file_exists("region.file", file);
                c.positive("region.scale", *scale);
                c.non_negative("region.offset_m", *offset_m);
            }
        }
        if let Err(m) = self.size.check() {
            c.fail("size", m);
        }
        c.positive("density_kg_m3", self.density);
        c.finite_vec("velocity_m_s", self.velocity);
        c.finite("normal_speed_m_s", self.normal_speed);
        c.non_negative("velocity_spread_m_s", self.velocity_spread);
        if self.parcels == 0 {
            c.fail("parcels", "parcels = 0 must be at least 1 (an injector releases at least one parcel)");
        }
        c.non_negative("start_s", self.start_s);
        if self.end_s.is_nan() || self.end_s < self.start_s {
            c.fail("end_s", format!("end_s = {} must be ≥ start_s = {}", self.end_s, self.start_s));
        }
        let n = [
            self.particles_per_parcel.is_some(),
            self.mass_per_parcel_kg.is_some(),
            self.mass_flow_kg_s.is_some(),
        ]
        .iter()
        .filter(|b| **b)
        .count();
        if n > 1 {
            c.fail(
                "particles_per_parcel",
                "give at most one of particles_per_parcel, mass_per_parcel_kg, mass_flow_kg_s",
            );
        }
        if let Some(v) = self.particles_per_parcel {
            c.positive("particles_per_parcel", v);
        }
        if let Some(v) = self.mass_per_parcel_kg {
            c.positive("mass_per_parcel_kg", v);
        }
        if let Some(v) = self.mass_flow_kg_s {
            c.positive("mass_flow_kg_s", v);
            if self.end_s <= self.start_s {
                c.fail("mass_flow_kg_s", "mass_flow_kg_s needs end_s > start_s");
            }
        }
    }
}

/// A new parcel's initial state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewParcel {
    pub pos: Vec3,
    pub vel: Vec3,
    pub diameter: f64,
    pub density: f64,
    pub count: f64,
}

/// The running state of an injector.
#[derive(Clone, Debug)]
pub struct Injector {
    pub spec: InjectorSpec,
    /// Parcels released so far.
    pub released: u64,
    rng: Rng,
    surface: Option<SurfaceSampler>,
}

/// What a checkpoint keeps of an injector (its specification comes from the scenario).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InjectorState {
    pub released: u64,
    pub rng: Rng,
}

#[derive(Clone, Debug)]
struct SurfaceSampler {
    mesh: TriMesh,
    cdf: Vec<f64>,
}

/// Why an injector could not be prepared.
#[derive(Debug, thiserror::Error)]
#[error("injector `{name}`: {message}")]
pub struct InjectError {
    pub name: String,
    pub message: String,
}

impl Injector {
    /// Prepares injector number `index` (its random stream) and reads its surface file, if any (a relative
    /// path is relative to the working directory; the scenario loader has made it absolute).
    pub fn new(spec: InjectorSpec, index: u64) -> Result<Self, InjectError> {
        let rng = seeded(spec.seed, 0x1000 + index);
        let mut inj = Injector { spec, released: 0, rng, surface: None };
        inj.load_surface()?;
        Ok(inj)
    }

    /// The resumable state.
    pub fn state(&self) -> InjectorState {
        InjectorState { released: self.released, rng: self.rng.clone() }
    }

    /// Continues from a checkpointed state.
    pub fn restore(&mut self, s: &InjectorState) {
        self.released = s.released;
        self.rng = s.rng.clone();
    }

    /// Reads the surface of a surface injector.
    pub fn load_surface(&mut self) -> Result<(), InjectError> {
        if let Region::Surface { file, scale, .. } = &self.spec.region {
            let mesh = TriMesh::load(file, *scale)
                .map_err(|e| InjectError { name: self.spec.name.clone(), message: e.to_string() })?;
            let mut cdf = Vec::with_capacity(mesh.triangles.len());
            let mut acc = 0.0;
            for t in 0..mesh.triangles.len() {
                acc += mesh.area(t);
                cdf.push(acc);
            }
            if acc <= 0.0 {
                return Err(InjectError {
                    name: self.spec.name.clone(),
                    message: "the surface has no area".into(),
                });
            }
            self.surface = Some(SurfaceSampler { mesh, cdf });
        }
        Ok(())
    }

    /// Particles per parcel for diameter `d`.
    fn count_for(&self, d: f64) -> f64 {
        let s = &self.spec;
        let m_particle = crate::forces::sphere_mass(d, s.density);
        if let Some(m) = s.mass_per_parcel_kg {
            m / m_particle
        } else if let Some(mf) = s.mass_flow_kg_s {
            mf * (s.end_s - s.start_s) / s.parcels as f64 / m_particle
        } else {
            s.particles_per_parcel.unwrap_or(1.0)
        }
    }

    /// How many parcels are due by time `t` in total.
    fn due(&self, t: f64) -> u64 {
        let s = &self.spec;
        if t < s.start_s {
            return 0;
        }
        if s.end_s <= s.start_s {
            return s.parcels;
        }
        let f = ((t - s.start_s) / (s.end_s - s.start_s)).clamp(0.0, 1.0);
        // The 1e-9 absorbs round-off in the time ratio (a step ending exactly at a release time).
        ((s.parcels as f64 * f + 1e-9).floor() as u64).min(s.parcels)
    }

    /// Releases the parcels due by the end of the step ending at `t_end`, calling `out` for each.
    pub fn release(&mut self, t_end: f64, mut out: impl FnMut(NewParcel)) {
        let due = self.due(t_end);
        while self.released < due {
            let p = self.sample();
            out(p);
            self.released += 1;
        }
    }

    fn sample(&mut self) -> NewParcel {
        let d = self.spec.size.sample(&mut self.rng);
        let mut vel = self.spec.velocity;
        let pos = match &self.spec.region {
            Region::Points { points_m } => points_m[(self.released % points_m.len() as u64) as usize],
            Region::Box { min_m, max_m } => {
                let r = Vec3::new(self.rng.random(), self.rng.random(), self.rng.random());
                *min_m + (*max_m - *min_m) * r
            }
            Region::Surface { offset_m, .. } => {
                let s = self.surface.as_ref().expect("surface injector prepared by Injector::new");
                let total = *s.cdf.last().unwrap_or(&0.0);
                let u: f64 = self.rng.random::<f64>() * total;
                let t = s.cdf.partition_point(|&c| c <= u).min(s.cdf.len() - 1);
                let [a, b, c] = s.mesh.corners(t);
                let (mut r1, mut r2): (f64, f64) = (self.rng.random(), self.rng.random());
                if r1 + r2 > 1.0 {
                    r1 = 1.0 - r1;
                    r2 = 1.0 - r2;
                }
                let n = s.mesh.normal(t);
                vel += self.spec.normal_speed * n;
                a + r1 * (b - a) + r2 * (c - a) + *offset_m * n
            }
        };
        if self.spec.velocity_spread > 0.0 {
            let z = Vec3::new(
                StandardNormal.sample(&mut self.rng),
                StandardNormal.sample(&mut self.rng),
                StandardNormal.sample(&mut self.rng),
            );
            vel += self.spec.velocity_spread * z;
        }
        NewParcel { pos, vel, diameter: d, density: self.spec.density, count: self.count_for(d) }
    }

    /// Total parcels this injector will release.
    pub fn total(&self) -> u64 {
        self.spec.parcels
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(region: Region) -> InjectorSpec {
        InjectorSpec {
            name: "t".into(),
            region,
            size: SizeDistribution::Mono { diameter: 50e-6 },
            density: 917.0,
            velocity: Vec3::X,
            normal_speed: 0.0,
            velocity_spread: 0.0,
            parcels: 100,
            start_s: 0.1,
            end_s: 0.2,
            particles_per_parcel: None,
            mass_per_parcel_kg: None,
            mass_flow_kg_s: Some(1e-3),
            seed: 5,
        }
    }

    #[test]
    fn release_schedule_and_mass_flow() {
        let mut inj = Injector::new(spec(Region::Box { min_m: Vec3::ZERO, max_m: Vec3::ONE }), 0).unwrap();
        let mut got = Vec::new();
        inj.release(0.05, |p| got.push(p));
        assert!(got.is_empty());
        inj.release(0.15, |p| got.push(p));
        assert_eq!(got.len(), 50);
        inj.release(1.0, |p| got.push(p));
        assert_eq!(got.len(), 100);
        // Mass released = mass flow × duration.
        let m: f64 = got.iter().map(|p| p.count * crate::forces::sphere_mass(p.diameter, p.density)).sum();
        assert!((m - 1e-4).abs() < 1e-15);
        assert!(got.iter().all(|p| p.pos.cmpge(Vec3::ZERO).all() && p.pos.cmple(Vec3::ONE).all()));
    }

    #[test]
    fn zero_parcels_are_refused() {
        // With mass_flow_kg_s the parcel mass would be mass flow × duration / 0 = ∞.
        let mut s = spec(Region::Box { min_m: Vec3::ZERO, max_m: Vec3::ONE });
        assert!(Checker::run(&s, None).is_ok());
        s.parcels = 0;
        let e = Checker::run(&s, None).unwrap_err();
        assert_eq!(e[0].key, "parcels");
        assert!(e[0].message.starts_with("parcels = 0 must be at least 1"), "{}", e[0].message);
    }

    #[test]
    fn surface_injection_lies_on_the_offset_surface() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("plate.stl");
        std::fs::write(&path, TriMesh::rectangle(2.0, 1.0, 0.0, 4, 2).to_binary_stl()).unwrap();
        let mut s = spec(Region::Surface { file: path, scale: 1.0, offset_m: 1e-3 });
        s.normal_speed = 2.0;
        s.start_s = 0.0;
        s.end_s = 0.0;
        s.mass_flow_kg_s = None;
        let mut inj = Injector::new(s, 0).unwrap_or_else(|e| panic!("{e}"));
        let mut got = Vec::new();
        inj.release(0.0, |p| got.push(p));
        assert_eq!(got.len(), 100);
        for p in &got {
            assert!((p.pos.z - 1e-3).abs() < 1e-12);
            assert!(p.pos.x >= 0.0 && p.pos.x <= 2.0 && p.pos.y >= 0.0 && p.pos.y <= 1.0);
            assert_eq!(p.vel, Vec3::new(1.0, 0.0, 2.0));
        }
    }
}
