//! From a [`SceneConfig`] to engine objects: materials, pair table, walls, regions, initial particles,
//! injectors.

use super::config::*;
use spatter_core::distribution::SizeDistribution;
use spatter_core::material::Material;
use spatter_core::mesh::TriMesh;
use spatter_core::motion::Motion;
use spatter_core::rng::{seeded, Rng};
use spatter_core::{Aabb, Vec3};
use spatter_dem::clump::{ClumpTemplate, NewBody};
use spatter_dem::contact::{PairProps, PairTable};
use spatter_dem::error::DemError;
use spatter_dem::insertion::{
    lattice_fill, random_clump_fill, random_fill, ClumpMix, ClumpShape, FillTarget, InjectionRate, Injector,
    InjectorState, OverlapIndex, Region, WallClearance,
};
use spatter_dem::particles::NewParticle;
use spatter_dem::restitution_models::{RestitutionModel, YieldGeometry};
use spatter_dem::walls::{Cylinder, MeshWall, Plane, Rectangle, Wall, WallShape};
use spatter_dem::wear::WearTable;

pub use spatter_dem::insertion::max_diameter;

/// Standard normal quantile of 10⁻³ (Abramowitz & Stegun 1964, table 26.1: z = −3.090 23).
const Z_1E3: f64 = -3.090_232_3;

/// Diameter for the time-step check \[m\]: the smallest diameter the distribution can produce
/// ([`SizeDistribution::min_diameter`], e.g. max(mean − 3σ, mean/10) of the truncated normal), or for the
/// log-normal, which is unbounded below, its 10⁻³ quantile median × σ_g^−3.09 (one draw in a thousand is
/// smaller).
pub fn min_diameter(d: &SizeDistribution) -> f64 {
    match (d.min_diameter(), d) {
        (Some(dmin), _) => dmin,
        (None, SizeDistribution::LogNormal { median, geometric_std }) => median * geometric_std.powf(Z_1E3),
        (None, _) => unreachable!("only the log-normal is unbounded below"),
    }
}

/// Engine objects built from a scene.
pub struct Built {
    pub materials: Vec<Material>,
    pub pairs: PairTable<PairProps>,
    pub walls: Vec<Wall>,
    /// Clump templates in the order of `[templates]` (alphabetical).
    pub templates: Vec<ClumpTemplate>,
    pub wear: WearTable,
    /// Forces from outside the engine (a workflow's fluid drag), installed in the simulation.
    pub external: Option<Box<dyn spatter_dem::sim::ExternalForces>>,
}

impl Built {
    /// Whether some pair's restitution depends on the impact speed (the scene then runs the
    /// speed-dependent damping law, whose contacts carry their coefficient).
    pub fn speed_dependent_restitution(&self) -> bool {
        let n = self.pairs.types();
        (0..n * n)
            .any(|k| matches!(self.pairs.at(k).restitution_model, Some(RestitutionModel::Thornton { .. })))
    }
}

fn material_index(cfg: &SceneConfig, name: &str, key: &str) -> Result<u16, DemError> {
    cfg.materials.keys().position(|k| k == name).map(|i| i as u16).ok_or_else(|| DemError::Config {
        key: key.into(),
        message: format!("material \"{name}\" is not in [materials]"),
    })
}

/// Materials, pair table and walls.
pub fn build(cfg: &SceneConfig) -> Result<Built, DemError> {
    let materials: Vec<Material> = cfg.materials.values().cloned().collect();
    let n = materials.len();
    let mut values = vec![cfg.pair_defaults.clone(); n * n];
    for (i, p) in cfg.pairs.iter().enumerate() {
        let a = material_index(cfg, &p.materials[0], &format!("pairs[{i}].materials[0]"))? as usize;
        let b = material_index(cfg, &p.materials[1], &format!("pairs[{i}].materials[1]"))? as usize;
        for (x, y) in [(a, b), (b, a)] {
            let v = &mut values[x * n + y];
            if let Some(f) = p.friction {
                v.friction = f;
            }
            if let Some(e) = p.restitution {
                v.restitution = e;
            }
            if let Some(r) = p.rolling_friction {
                v.rolling_friction = r;
            }
            if let Some(r) = p.rolling_viscous_s_m {
                v.rolling_viscous_s_m = r;
            }
            if let Some(w) = p.work_of_adhesion_j_m2 {
                v.work_of_adhesion_j_m2 = w;
            }
            if let Some(k) = p.restitution_model {
                v.restitution_model = k;
            }
            if let Some(y) = p.yield_stress_pa {
                v.yield_stress_pa = Some(y);
            }
            if let Some(f) = p.thornton_form {
                v.thornton_form = f;
            }
            if let Some(k) = p.stiffness_n_m {
                v.stiffness_n_m = Some(k);
            }
            if let Some(k) = p.cohesion_stiffness_n_m {
                v.cohesion_stiffness_n_m = k;
            }
        }
    }
    let pairs = PairTable::build(n, |a, b| {
        let v = &values[a * n + b];
        let mut p = PairProps::new(&materials[a], &materials[b], v.friction, v.restitution);
        p.rolling_friction = v.rolling_friction;
        p.rolling_viscous = v.rolling_viscous_s_m;
        p.work_of_adhesion = v.work_of_adhesion_j_m2;
        p.stiffness = v.stiffness_n_m;
        p.cohesion_stiffness = v.cohesion_stiffness_n_m;
        p.restitution_model = Some(match v.restitution_model {
            RestitutionKind::Constant => RestitutionModel::Constant { restitution: v.restitution },
            RestitutionKind::Thornton => RestitutionModel::Thornton {
                yield_stress_pa: v.yield_stress_pa.unwrap_or(0.0),
                form: v.thornton_form,
                // Eq. 31 with the contact's R* and m*: Thornton's result for two spheres, equal to the
                // wall formula (Eq. 32) on a wall, and free of the question which material is the particle.
                yield_geometry: YieldGeometry::Pair,
            },
        });
        p
    });
    let tree = crate::motions::tree(&cfg.motions)
        .map_err(|(i, message)| DemError::Config { key: format!("motions[{i}]"), message })?;
    let mut walls = Vec::new();
    for (i, w) in cfg.walls.iter().enumerate() {
        let material = material_index(cfg, &w.material, &format!("walls[{i}].material"))?;
        let shape = match &w.shape {
            ShapeConfig::Plane { point_m, normal } => WallShape::Plane(Plane::new(*point_m, *normal)),
            ShapeConfig::Rectangle { center_m, half_u_m, half_v_m } => {
                WallShape::Rectangle(Rectangle { center: *center_m, half_u: *half_u_m, half_v: *half_v_m })
            }
            ShapeConfig::Cylinder { point_m, axis, radius_m, inside, axial_min_m, axial_max_m } => {
                WallShape::Cylinder(Cylinder {
                    point: *point_m,
                    axis: axis.normalize(),
                    radius: *radius_m,
                    inside: *inside,
                    axial_min: axial_min_m.unwrap_or(f64::NEG_INFINITY),
                    axial_max: axial_max_m.unwrap_or(f64::INFINITY),
                })
            }
            ShapeConfig::Mesh { file, scale } => {
                WallShape::Mesh(Box::new(MeshWall::new(TriMesh::load(file, *scale)?)))
            }
        };
        let motion = match w.motion.as_deref().and_then(|m| cfg.motions.iter().position(|n| n.name == m)) {
            Some(node) => tree.world_motion(node),
            None => Motion::Fixed,
        };
        walls.push(Wall { name: w.name.clone(), shape, material, motion });
    }
    if let Some(p) = &cfg.probe {
        let material = material_index(cfg, &p.material, "probe.material")?;
        walls.push(super::probe::wall(p, material)?);
    }
    let mut templates = Vec::with_capacity(cfg.templates.len());
    for (name, t) in &cfg.templates {
        templates.push(t.build(name)?);
    }
    let mut wear = WearTable::new(n);
    for (i, w) in cfg.wear.iter().enumerate() {
        let a = material_index(cfg, &w.particle_material, &format!("wear[{i}].particle_material"))?;
        let b = material_index(cfg, &w.wall_material, &format!("wear[{i}].wall_material"))?;
        wear.set(a as usize, b as usize, w.model());
    }
    Ok(Built { materials, pairs, walls, templates, wear, external: None })
}

/// The insertion mix of a `clumps` table: the named templates with their body masses at `density`
/// \[kg/m³\] and probabilities per body from the ratios.
pub fn clump_mix(
    cfg: &SceneConfig,
    mix: &ClumpMixConfig,
    templates: &[ClumpTemplate],
    density: f64,
) -> Result<ClumpMix, DemError> {
    let mut shapes = Vec::with_capacity(mix.templates.len());
    for (k, name) in mix.templates.iter().enumerate() {
        let index = cfg.templates.keys().position(|t| t == name).ok_or_else(|| DemError::Config {
            key: format!("clumps.templates[{k}]"),
            message: format!("template \"{name}\" is not in [templates]"),
        })?;
        let t = &templates[index];
        let (mass, _, _) = t.body_mass(density);
        shapes.push(ClumpShape { template: index, members: t.spheres.clone(), mass, volume: mass / density });
    }
    let masses: Vec<f64> = shapes.iter().map(|s| s.mass).collect();
    Ok(ClumpMix::new(shapes, &super::clumps::mix_weights(mix, &masses)))
}

/// The engine region of a region configuration.
pub fn region(r: &RegionConfig) -> Result<Region, DemError> {
    Ok(match r {
        RegionConfig::Box { min_m, max_m } => Region::Box(Aabb::new(*min_m, *max_m)),
        RegionConfig::Cylinder { base_m, axis, radius_m, height_m } => {
            Region::Cylinder { base: *base_m, axis: axis.normalize(), radius: *radius_m, height: *height_m }
        }
        RegionConfig::Mesh { file, scale } => Region::mesh(TriMesh::load(file, *scale)?),
    })
}

/// Consecutive draws above the lattice spacing after which a lattice fill gives up.
const LATTICE_REDRAWS: u32 = 10_000;

/// What the fills place at t = 0.
#[derive(Debug, Default)]
pub struct Initial {
    pub spheres: Vec<NewParticle>,
    /// Rigid bodies: template index, material, placement.
    pub bodies: Vec<(usize, u16, NewBody)>,
}

/// The spheres of the `[bed]` file, then the spheres and rigid bodies of the `fill` entries, in order,
/// avoiding each other, the bed and `walls` (placed as at t = 0).
///
/// A random fill that cannot reach its `count` or `volume_fraction` (a drawn sphere found no free place
/// in `max_attempts` random positions) is an error naming the key, with the number placed: running with
/// fewer particles than asked for would be a different experiment. A lattice fill takes the sites that
/// are inside the region and clear of walls and earlier fills; diameters larger than the spacing are
/// redrawn (the lattice truncates the distribution there, and says so in the log). A clump fill places
/// whole bodies in random orientations (random fill only); a body that finds no place is an error too.
pub fn initial_particles(
    cfg: &SceneConfig,
    walls: &[Wall],
    templates: &[ClumpTemplate],
) -> Result<Initial, DemError> {
    let clear = WallClearance::new(walls, 0.0);
    let mut placed: Vec<(Vec3, f64)> = Vec::new();
    let mut out = Initial::default();
    if let Some(b) = &cfg.bed {
        let names = cfg.material_names();
        let spheres = crate::bed_lab::bed_file::read(&b.file, &names)
            .map_err(|message| DemError::Config { key: "bed.file".into(), message })?;
        for s in spheres {
            let material = material_index(cfg, &s.material, "bed.file")?;
            let mut p = NewParticle::at(s.pos, s.radius, material);
            p.vel = s.vel;
            p.omega = s.omega;
            placed.push((s.pos, s.radius));
            out.spheres.push(p);
        }
        tracing::info!("bed: {} spheres from {}", out.spheres.len(), b.file.display());
    }
    for (i, f) in cfg.fill.iter().enumerate() {
        let material = material_index(cfg, &f.material, &format!("fill[{i}].material"))?;
        let reg = region(&f.region)?;
        let mut rng: Rng = seeded(cfg.seed, 1000 + i as u64);
        if let Some(mix) = &f.clumps {
            let density = cfg.materials[&f.material].density;
            let mix =
                clump_mix(cfg, mix, templates, density).map_err(|e| prefixed(e, &format!("fill[{i}].")))?;
            let (target, key) = match (f.count, f.volume_fraction) {
                (None, Some(v)) => (FillTarget::VolumeFraction(v), "volume_fraction"),
                (n, _) => (FillTarget::Count(n.unwrap_or(0)), "count"),
            };
            let got = random_clump_fill(&reg, &mix, target, &placed, &clear, f.max_attempts, &mut rng);
            if let Some(slot) = got.stuck_at {
                let name = &templates[mix.shapes[slot].template].name;
                return Err(DemError::Config {
                    key: format!("fill[{i}].{key}"),
                    message: format!(
                        "the region is full or too small: placed {} bodies; the next body (template `{name}`, \
                         bounding radius {:.3e} m) found no position and orientation with every member sphere \
                         inside the region, clear of walls and of earlier particles, in max_attempts = {} \
                         tries. Enlarge the region, ask for fewer bodies, or raise max_attempts",
                        got.bodies.len(),
                        mix.shapes[slot].bounding_radius(),
                        f.max_attempts
                    ),
                });
            }
            for b in &got.bodies {
                let shape = &mix.shapes[b.slot];
                for &(c, r) in &shape.members {
                    placed.push((b.pos + b.quat * c, r));
                }
                let body = NewBody { pos: b.pos, quat: b.quat, vel: f.velocity_m_s, omega: Vec3::ZERO };
                out.bodies.push((shape.template, material, body));
            }
            tracing::info!("fill[{i}]: {} bodies", got.bodies.len());
            continue;
        }
        let Some(size) = &f.size else { continue };
        let spheres: Vec<(Vec3, f64)> = match f.method {
            FillMethod::Random => {
                let (target, key) = match (f.count, f.volume_fraction) {
                    (Some(n), _) => (FillTarget::Count(n), "count"),
                    (None, Some(v)) => (FillTarget::VolumeFraction(v), "volume_fraction"),
                    (None, None) => (FillTarget::Count(0), "count"),
                };
                let got = random_fill(&reg, size, target, &placed, &clear, f.max_attempts, &mut rng);
                if let Some(d) = got.stuck_at {
                    let reached = match target {
                        FillTarget::Count(n) => format!("placed {} of {n} particles", got.spheres.len()),
                        FillTarget::VolumeFraction(v) => format!(
                            "reached a solid fraction of {:.4} of the requested {v} ({} particles)",
                            got.solid / reg.volume(),
                            got.spheres.len()
                        ),
                    };
                    return Err(DemError::Config {
                        key: format!("fill[{i}].{key}"),
                        message: format!(
                            "the region is full: {reached}; the next sphere (diameter {d:e} m) found no place \
                             inside the region, clear of walls and of earlier particles, in max_attempts = {} \
                             random positions. Enlarge the region, ask for fewer particles, or raise \
                             max_attempts (random sequential addition of equal spheres jams near a solid \
                             fraction of 0.38; use method = \"lattice\" for denser packings)",
                            f.max_attempts
                        ),
                    });
                }
                got.spheres
            }
            FillMethod::Lattice => {
                let d_max = max_diameter(size);
                let spacing = f.spacing_m.or(d_max.map(|d| 1.01 * d)).unwrap_or(0.0);
                let r_site = 0.5 * spacing;
                let sites = lattice_fill(&reg, spacing, r_site, f.lattice);
                let mut index =
                    OverlapIndex::new(spacing.max(2.0 * placed.iter().map(|p| p.1).fold(0.0, f64::max)));
                let b = reg.bounds().inflated(placed.iter().map(|p| p.1).fold(0.0, f64::max));
                for &(x, r) in &placed {
                    if b.contains(x) {
                        index.insert(x, r);
                    }
                }
                let mut v = Vec::with_capacity(sites.len());
                let mut pending: Option<f64> = None;
                let mut redraws = 0u64;
                for x in sites {
                    // The next diameter not above the spacing; a site that cannot take it passes it on.
                    let d = match pending {
                        Some(d) => d,
                        None => {
                            let mut d = size.sample(&mut rng);
                            let mut k = 0;
                            while d > spacing {
                                k += 1;
                                if k > LATTICE_REDRAWS {
                                    return Err(DemError::Config {
                                        key: format!("fill[{i}].spacing_m"),
                                        message: format!(
                                            "spacing_m = {spacing} m is below nearly every diameter of the \
                                             size distribution ({LATTICE_REDRAWS} draws in a row were larger)"
                                        ),
                                    });
                                }
                                d = size.sample(&mut rng);
                            }
                            redraws += k as u64;
                            d
                        }
                    };
                    let r = 0.5 * d;
                    if clear.overlapping(x, r).is_some() || index.overlaps(x, r) {
                        pending = Some(d);
                        continue;
                    }
                    pending = None;
                    v.push((x, r));
                }
                if redraws > 0 {
                    tracing::warn!(
                        "fill[{i}]: {redraws} diameters above spacing_m = {spacing} m were redrawn (a lattice \
                         fill truncates the size distribution at its spacing)"
                    );
                }
                tracing::info!("fill[{i}]: {} particles on the lattice", v.len());
                v
            }
        };
        for &(x, r) in &spheres {
            let mut p = NewParticle::at(x, r, material);
            p.vel = f.velocity_m_s;
            p.frozen = f.frozen;
            out.spheres.push(p);
        }
        placed.extend(spheres);
    }
    Ok(out)
}

/// A configuration error with its key prefixed (e.g. by `fill[0].`).
fn prefixed(e: DemError, prefix: &str) -> DemError {
    match e {
        DemError::Config { key, message } => DemError::Config { key: format!("{prefix}{key}"), message },
        e => e,
    }
}

/// The injectors of the `inject` entries with their regions.
pub fn injectors(
    cfg: &SceneConfig,
    templates: &[ClumpTemplate],
) -> Result<Vec<(Injector, Region)>, DemError> {
    let mut out = Vec::new();
    for (i, j) in cfg.inject.iter().enumerate() {
        let material = material_index(cfg, &j.material, &format!("inject[{i}].material"))?;
        let rate = match (j.particles_per_s, j.kg_per_s) {
            (Some(n), _) => InjectionRate::ParticlesPerSecond(n),
            (None, Some(m)) => InjectionRate::KgPerSecond(m),
            (None, None) => InjectionRate::ParticlesPerSecond(0.0),
        };
        let density = cfg.materials[&j.material].density;
        let clumps = match &j.clumps {
            Some(m) => Some(
                clump_mix(cfg, m, templates, density).map_err(|e| prefixed(e, &format!("inject[{i}].")))?,
            ),
            None => None,
        };
        // A clump injector draws no diameters; its distribution is never sampled.
        let dist = j.size.clone().unwrap_or(SizeDistribution::Mono { diameter: 0.0 });
        let inj = Injector {
            dist,
            clumps,
            rate,
            density,
            start: j.start_s,
            end: j.end_s.unwrap_or(f64::INFINITY),
            velocity: j.velocity_m_s,
            material,
            attempts: j.attempts,
            state: InjectorState::new(seeded(cfg.seed, 2000 + i as u64)),
        };
        out.push((inj, region(&j.region)?));
    }
    Ok(out)
}
