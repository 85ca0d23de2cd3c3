//! A DEM bed under a flow: building the bed (read from a bed file or poured here), stepping it with the
//! fluid forces on its exposed grains, and taking out the grains that leave it.

use super::forces::{BedFlowForces, BedFlowProbe, BedForceSettings};
use super::near_ground::GroundFlow;
use crate::bed_lab::bed_file;
use rand::{Rng, SeedableRng};
use serde::{Deserialize, Serialize};
use spatter_core::check::{Checker, Validate};
use spatter_core::material::Material;
use spatter_core::motion::Motion;
use spatter_core::Vec3;
use spatter_dem::contact::{
    Composed, LinearCohesion, LinearHistory, NoRolling, PairProps, PairTable, RestitutionDamping,
};
use spatter_dem::sim::SimState;
use spatter_dem::walls::{Plane, Wall, WallShape};
use spatter_dem::{DemError, NewParticle, Settings, Simulation};
use spatter_flow::forces::Fluid;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// The contact law of the bed: linear spring with linear cohesion (k_coh = 0: none), restitution
/// damping, linear tangential spring with Coulomb friction.
pub type BedLaw = Composed<LinearCohesion, RestitutionDamping, LinearHistory, NoRolling>;

/// Gravitational acceleration of the bed \[m/s²\].
pub const G: f64 = 9.81;

/// The DEM bed under the flow. Scenario table `[dem_bed]` of the `brownout` kind (see docs/brownout.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DemBedConfig {
    /// A bed file from the bed laboratory (`spatter run` of a `dem` scene with a pour); its grains keep
    /// their radii and positions, the density is the ground's. Give this **or** `grain_diameter_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// Pour a bed of grains of this diameter \[m\] …
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grain_diameter_m: Option<f64>,
    /// … over a patch of this size along and across the flow \[m\] …
    #[serde(default = "patch")]
    pub patch_size_m: [f64; 2],
    /// … in this many layers.
    #[serde(default = "layers")]
    pub layers: usize,
    /// Normal spring stiffness k_n \[N/m\]; default: an impact at `impact_speed_m_s` overlaps 10 % of
    /// the smallest radius, k_n = m (v / 0.1 r)².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stiffness_n_m: Option<f64>,
    #[serde(default = "impact")]
    pub impact_speed_m_s: f64,
    /// Sliding friction coefficient and restitution of grain–grain and grain–wall contacts.
    #[serde(default = "friction")]
    pub friction: f64,
    #[serde(default = "restitution")]
    pub restitution: f64,
    /// Linear cohesion stiffness k_coh \[N/m\] (0: cohesionless) and cohesion radius over radius.
    #[serde(default)]
    pub cohesion_stiffness_n_m: f64,
    #[serde(default = "coh_ratio")]
    pub cohesion_radius_ratio: f64,
    /// DEM time step \[s\]; default 1/25 of the contact time π √(m/(2 k_n)) of the smallest grains.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dt_s: Option<f64>,
    /// Settling time of a poured bed before the flow starts \[s\]; default 4 √(2H/g) (H: pour height).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_s: Option<f64>,
    /// A grain whose centre rises this many largest diameters above the bed's top leaves the bed.
    #[serde(default = "release")]
    pub release_height_over_diameter: f64,
    /// The fluid forces on the exposed grains.
    #[serde(default)]
    pub forces: BedForceSettings,
    /// Seed of the pour's jitter.
    #[serde(default = "seed")]
    pub seed: u64,
    /// Brownout: distance of the patch centre from the rotor axis over R (on the +x axis).
    #[serde(default = "patch_r")]
    pub radius_over_radius: f64,
    /// Brownout: simulated time of the patch under the flow \[s\] (at most the cloud's duration).
    #[serde(default = "duration")]
    pub duration_s: f64,
}

fn patch() -> [f64; 2] {
    [4e-3, 2e-3]
}
fn layers() -> usize {
    4
}
fn impact() -> f64 {
    2.0
}
fn friction() -> f64 {
    0.5
}
fn restitution() -> f64 {
    0.3
}
fn coh_ratio() -> f64 {
    1.1
}
fn release() -> f64 {
    3.0
}
fn seed() -> u64 {
    1
}
fn patch_r() -> f64 {
    0.85
}
fn duration() -> f64 {
    0.2
}

impl Default for DemBedConfig {
    fn default() -> Self {
        DemBedConfig {
            file: None,
            grain_diameter_m: Some(300e-6),
            patch_size_m: patch(),
            layers: layers(),
            stiffness_n_m: None,
            impact_speed_m_s: impact(),
            friction: friction(),
            restitution: restitution(),
            cohesion_stiffness_n_m: 0.0,
            cohesion_radius_ratio: coh_ratio(),
            dt_s: None,
            settle_s: None,
            release_height_over_diameter: release(),
            forces: BedForceSettings::default(),
            seed: seed(),
            radius_over_radius: patch_r(),
            duration_s: duration(),
        }
    }
}

/// Most grains a poured patch may hold.
pub const MAX_GRAINS: usize = 200_000;

impl Validate for DemBedConfig {
    fn validate(&self, c: &mut Checker) {
        match (&self.file, self.grain_diameter_m) {
            (Some(_), Some(_)) => {
                c.fail("file", "give a bed file (file) or a grain size to pour (grain_diameter_m), not both")
            }
            (None, None) => c.fail(
                "grain_diameter_m",
                "give the bed: file = \"bed.txt\" (a bed file) or grain_diameter_m [m] to pour one",
            ),
            (None, Some(d)) => {
                c.positive("grain_diameter_m", d);
                if self.patch_size_m.iter().any(|&l| !(l.is_finite() && l > 0.0)) {
                    c.fail(
                        "patch_size_m",
                        format!(
                            "patch_size_m = {:?} must be two positive lengths in metres",
                            self.patch_size_m
                        ),
                    );
                } else if d.is_finite() && d > 0.0 {
                    let (nx, ny) = lattice(self.patch_size_m, d);
                    if nx < 2 || ny < 2 {
                        c.fail(
                            "patch_size_m",
                            format!(
                                "patch_size_m = {:?} holds fewer than 2 × 2 grains of {d} m (spacing 1.2 d)",
                                self.patch_size_m
                            ),
                        );
                    } else if nx * ny * self.layers > MAX_GRAINS {
                        c.fail("patch_size_m", format!("patch_size_m = {:?} with {} layers would pour {} grains (at most {MAX_GRAINS})", self.patch_size_m, self.layers, nx * ny * self.layers));
                    }
                }
                if self.layers == 0 || self.layers > 100 {
                    c.fail("layers", format!("layers = {} must be 1 to 100", self.layers));
                }
            }
            // The bed file is read here too (resolved against the scenario's folder), so `spatter check`
            // refuses a missing or garbled one; the run reads it again from its absolute path.
            (Some(p), None) => {
                let full = c.resolve(p);
                if !full.is_file() && !full.is_dir() {
                    c.file_exists("file", p);
                } else if let Err(e) = read_bed_file(&full) {
                    c.fail("file", format!("file = \"{}\": {e}", p.display()));
                }
            }
        }
        if let Some(k) = self.stiffness_n_m {
            c.positive("stiffness_n_m", k);
        }
        c.positive("impact_speed_m_s", self.impact_speed_m_s);
        c.non_negative("friction", self.friction);
        c.in_range("restitution", self.restitution, 0.0, false, 1.0, true);
        c.non_negative("cohesion_stiffness_n_m", self.cohesion_stiffness_n_m);
        c.in_range("cohesion_radius_ratio", self.cohesion_radius_ratio, 1.0, true, 2.0, true);
        if let Some(dt) = self.dt_s {
            c.positive("dt_s", dt);
        }
        if let Some(s) = self.settle_s {
            c.non_negative("settle_s", s);
        }
        c.positive("release_height_over_diameter", self.release_height_over_diameter);
        c.positive("forces.wall_drag_factor", self.forces.wall_drag_factor);
        c.non_negative("radius_over_radius", self.radius_over_radius);
        c.positive("duration_s", self.duration_s);
    }
}

/// Grains per row and column of the pour lattice (spacing 1.2 d).
fn lattice(size: [f64; 2], d: f64) -> (usize, usize) {
    let n = |l: f64| ((l - 0.2 * d) / (1.2 * d)).floor().max(0.0) as usize;
    (n(size[0]), n(size[1]))
}

/// One grain as it left the bed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Released {
    pub time: f64,
    pub id: u32,
    pub diameter: f64,
    pub mass: f64,
    /// Centre \[m\] and velocity \[m/s\] in the bed's frame.
    pub pos: Vec3,
    pub vel: Vec3,
}

/// The evolving state of a [`BedFlow`] besides its static set-up; checkpointed.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BedFlowState {
    pub sim: SimState<<BedLaw as spatter_dem::contact::ContactLaw>::State>,
    pub z_ground: f64,
    pub z_release: f64,
    pub t0: f64,
    pub entrained_count: u64,
    pub entrained_mass: f64,
}

/// A settled bed under a flow.
pub struct BedFlow {
    pub sim: Simulation<BedLaw>,
    /// The flow's ground plane (the top layer's centres one radius above it) \[m\].
    pub z_ground: f64,
    /// Centres above this height leave the bed \[m\].
    pub z_release: f64,
    /// The DEM time at which the flow started (after settling) \[s\].
    pub t0: f64,
    /// Grains that left the bed so far and their mass \[kg\].
    pub entrained_count: u64,
    pub entrained_mass: f64,
    /// The hook's last friction velocity and exposed count.
    pub probe: Arc<Mutex<BedFlowProbe>>,
    /// Largest grain diameter \[m\].
    pub d_max: f64,
    /// The patch (x, y) extent in the bed's frame \[m\].
    pub footprint: [f64; 4],
}

impl BedFlow {
    /// Builds the bed of `cfg` with grain density `density` \[kg/m³\] in `fluid` under `flow`: reads or
    /// pours it, settles a poured bed without flow, finds the ground plane and installs the fluid forces.
    /// With `resume`, the bed continues from that state instead (no settling).
    pub fn build<G: GroundFlow + 'static>(
        cfg: &DemBedConfig,
        density: f64,
        fluid: Fluid,
        flow: Arc<G>,
        resume: Option<BedFlowState>,
    ) -> Result<BedFlow, String> {
        let grains = grains(cfg)?;
        if grains.is_empty() {
            return Err("the bed holds no grains".into());
        }
        let r_min = grains.iter().map(|g| g.1).fold(f64::MAX, f64::min);
        let r_max = grains.iter().map(|g| g.1).fold(0.0, f64::max);
        let m_min = density * 4.0 / 3.0 * std::f64::consts::PI * r_min.powi(3);
        let k = cfg.stiffness_n_m.unwrap_or(m_min * (cfg.impact_speed_m_s / (0.1 * r_min)).powi(2));
        let dt = cfg.dt_s.unwrap_or(std::f64::consts::PI * (0.5 * m_min / k).sqrt() / 25.0);
        let sand = Material { youngs_modulus: 1e9, poisson_ratio: 0.25, density };
        let mats = vec![sand.clone()];
        let props = PairTable::build(1, |_, _| {
            let mut p = PairProps::new(&sand, &sand, cfg.friction, cfg.restitution);
            p.cohesion_stiffness = cfg.cohesion_stiffness_n_m;
            p
        });
        let law = Composed::new(
            LinearCohesion::new(k, cfg.cohesion_radius_ratio),
            RestitutionDamping::default(),
            LinearHistory::default(),
            NoRolling,
        );
        let mut sim = Simulation::new(law, mats, props, dt, Settings::default());
        sim.gravity = Vec3::new(0.0, 0.0, -G);
        // A box around the grains: floor and four side walls.
        let (mut lo, mut hi) = (Vec3::splat(f64::MAX), Vec3::splat(f64::MIN));
        for &(p, r) in &grains {
            lo = lo.min(p - Vec3::splat(r));
            hi = hi.max(p + Vec3::splat(r));
        }
        if let (None, Some(_)) = (&cfg.file, cfg.grain_diameter_m) {
            lo = Vec3::new(0.0, 0.0, 0.0);
            hi = Vec3::new(cfg.patch_size_m[0], cfg.patch_size_m[1], hi.z);
        }
        for (name, point, normal) in [
            ("floor", lo, Vec3::Z),
            ("upwind", lo, Vec3::X),
            ("downwind", hi, -Vec3::X),
            ("left", lo, Vec3::Y),
            ("right", hi, -Vec3::Y),
        ] {
            sim.add_wall(Wall {
                name: name.into(),
                shape: WallShape::Plane(Plane::new(point, normal)),
                material: 0,
                motion: Motion::Fixed,
            });
        }
        for &(p, r) in &grains {
            sim.add_particle(NewParticle::at(p, r, 0));
        }
        let poured = cfg.file.is_none();
        let resumed =
            resume.as_ref().map(|s| (s.z_ground, s.z_release, s.t0, s.entrained_count, s.entrained_mass));
        if let Some(state) = resume {
            sim.restore(state.sim).map_err(|e| format!("checkpoint of the bed: {e}"))?;
        } else if poured {
            let t = cfg.settle_s.unwrap_or(4.0 * (2.0 * hi.z / G).sqrt());
            let n = (t / dt).ceil() as u64;
            sim.run_steps(n).map_err(|e| format!("settling the poured bed: {e}"))?;
            for v in sim.particles.vel.iter_mut().chain(sim.particles.omega.iter_mut()) {
                *v = Vec3::ZERO;
            }
            sim.invalidate();
        }
        let d_max = 2.0 * r_max;
        let (z_ground, z_release, t0, count, mass) = resumed.unwrap_or_else(|| {
            let top = sim
                .particles
                .pos
                .iter()
                .zip(&sim.particles.radius)
                .map(|(p, r)| p.z + r)
                .fold(f64::MIN, f64::max);
            (
                ground_plane(&sim.particles.pos, &sim.particles.radius),
                top + cfg.release_height_over_diameter * d_max,
                sim.time(),
                0,
                0.0,
            )
        });
        let mut forces = BedFlowForces::new(flow, fluid, density, z_ground, cfg.forces);
        forces.t0 = t0;
        // The probe (friction velocity, exposed grains) at the flow's start, for the first output row.
        let p = &sim.particles;
        forces.observe(sim.time(), &p.pos, &p.radius, &p.inv_mass);
        let probe = forces.probe.clone();
        sim.set_external_forces(Box::new(forces));
        Ok(BedFlow {
            sim,
            z_ground,
            z_release,
            t0,
            entrained_count: count,
            entrained_mass: mass,
            probe,
            d_max,
            footprint: [lo.x, hi.x, lo.y, hi.y],
        })
    }

    /// Time since the flow started \[s\].
    pub fn flow_time(&self) -> f64 {
        self.sim.time() - self.t0
    }

    /// One DEM step; the grains whose centre rose above [`BedFlow::z_release`] are taken out and returned.
    pub fn step(&mut self, out: &mut Vec<Released>) -> Result<(), DemError> {
        self.sim.step()?;
        let p = &self.sim.particles;
        let z = self.z_release;
        let n0 = out.len();
        for i in 0..p.len() {
            if p.inv_mass[i] > 0.0 && p.pos[i].z > z {
                out.push(Released {
                    time: self.sim.time() - self.t0,
                    id: p.id[i],
                    diameter: 2.0 * p.radius[i],
                    mass: p.mass(i),
                    pos: p.pos[i],
                    vel: p.vel[i],
                });
            }
        }
        if out.len() > n0 {
            // In order of ids (the store is sorted by cell), so the hand-over order is fixed.
            out[n0..].sort_by_key(|r| r.id);
            for r in &out[n0..] {
                self.entrained_count += 1;
                self.entrained_mass += r.mass;
            }
            let keep: Vec<bool> =
                p.pos.iter().zip(&p.inv_mass).map(|(x, &im)| im == 0.0 || x.z <= z).collect();
            self.sim.particles.retain(|i| keep[i]);
            self.sim.invalidate();
        }
        Ok(())
    }

    /// The evolving state, for checkpoints.
    pub fn state(&self) -> BedFlowState {
        BedFlowState {
            sim: self.sim.state(),
            z_ground: self.z_ground,
            z_release: self.z_release,
            t0: self.t0,
            entrained_count: self.entrained_count,
            entrained_mass: self.entrained_mass,
        }
    }
}

/// The flow's ground plane of a bed \[m\]: the mean of z − r over its top layer (the grains exposed
/// without a flow direction: not covered by another grain), so that the top layer's centres sit one
/// radius above it on average.
pub fn ground_plane(pos: &[Vec3], radius: &[f64]) -> f64 {
    let active = vec![true; pos.len()];
    let mut top = Vec::new();
    // Without a ground plane yet, search every grain (z_ground far below).
    super::exposure::exposure(
        pos,
        radius,
        &active,
        Vec3::X,
        f64::MIN / 4.0,
        &mut Default::default(),
        &mut top,
    );
    // The top layer: uncovered grains within a largest diameter of the highest top.
    let r_max = radius.iter().copied().fold(0.0, f64::max);
    let z_top = pos.iter().zip(radius).map(|(p, r)| p.z + r).fold(f64::MIN, f64::max);
    let (mut s, mut n) = (0.0, 0usize);
    for i in 0..pos.len() {
        if top[i] && pos[i].z + radius[i] > z_top - 2.0 * r_max {
            s += pos[i].z - radius[i];
            n += 1;
        }
    }
    if n == 0 {
        z_top - 2.0 * r_max
    } else {
        s / n as f64
    }
}

/// The grains (centre, radius) of a bed file; any material name is accepted (the grains take the
/// ground's density). The error names the file, the line and the field.
pub fn read_bed_file(path: &std::path::Path) -> Result<Vec<(Vec3, f64)>, String> {
    if path.is_dir() {
        return Err(format!("{} is a folder, not a bed file", path.display()));
    }
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let names: std::collections::BTreeSet<&str> = text
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .filter_map(|l| l.split_whitespace().nth(2))
        .collect();
    let names: Vec<&str> = names.into_iter().collect();
    let spheres = bed_file::parse(&text, &names).map_err(|e| format!("{}: {e}", path.display()))?;
    if spheres.is_empty() {
        return Err(format!("{}: the bed file holds no grains", path.display()));
    }
    Ok(spheres.iter().map(|s| (s.pos, s.radius)).collect())
}

/// The grains (centre, radius) of the bed: read from the bed file or placed for the pour (a lattice of
/// spacing 1.2 d, every other layer shifted by half a spacing, jittered by ±0.1 d, layers 1.2 d apart).
fn grains(cfg: &DemBedConfig) -> Result<Vec<(Vec3, f64)>, String> {
    if let Some(path) = &cfg.file {
        return read_bed_file(path);
    }
    let d = cfg.grain_diameter_m.ok_or("no grain_diameter_m")?;
    let (nx, ny) = lattice(cfg.patch_size_m, d);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(cfg.seed);
    let a = 1.2 * d;
    let mut out = Vec::with_capacity(nx * ny * cfg.layers);
    for l in 0..cfg.layers {
        let shift = if l % 2 == 1 { 0.5 * a } else { 0.0 };
        let (mx, my) =
            if l % 2 == 1 { (nx.saturating_sub(1).max(1), ny.saturating_sub(1).max(1)) } else { (nx, ny) };
        for j in 0..my {
            for i in 0..mx {
                let jx: f64 = rng.random_range(-0.1..0.1);
                let jy: f64 = rng.random_range(-0.1..0.1);
                let x = 0.6 * d + shift + i as f64 * a + jx * d;
                let y = 0.6 * d + shift + j as f64 * a + jy * d;
                let z = 0.6 * d + l as f64 * a;
                out.push((Vec3::new(x, y, z), 0.5 * d));
            }
        }
    }
    Ok(out)
}
