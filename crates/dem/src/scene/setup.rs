//! From a [`SceneConfig`] to engine objects: materials, pair table, walls, regions, initial particles,
//! injectors.

use super::config::*;
use crate::contact::{PairProps, PairTable};
use crate::error::DemError;
use crate::insertion::{lattice_fill, random_fill, FillTarget, InjectionRate, Injector, Region};
use crate::particles::NewParticle;
use crate::walls::{Cylinder, MeshWall, Plane, Rectangle, Wall, WallShape};
use spatter_core::distribution::SizeDistribution;
use spatter_core::material::Material;
use spatter_core::mesh::TriMesh;
use spatter_core::motion::{Motion, MotionTable};
use spatter_core::rng::{seeded, Rng};
use spatter_core::{Aabb, Vec3};

/// Largest diameter a distribution can produce, if bounded.
pub fn max_diameter(d: &SizeDistribution) -> Option<f64> {
    match d {
        SizeDistribution::Mono { diameter } => Some(*diameter),
        SizeDistribution::Uniform { max, .. } => Some(*max),
        SizeDistribution::Normal { mean, std_dev } => Some(mean + 3.0 * std_dev),
        SizeDistribution::LogNormal { .. } => None,
        SizeDistribution::Tabulated { diameters, .. } => diameters.last().copied(),
    }
}

/// Smallest diameter a distribution can produce (a lower bound for the time-step check).
pub fn min_diameter(d: &SizeDistribution) -> f64 {
    match d {
        SizeDistribution::Mono { diameter } => *diameter,
        SizeDistribution::Uniform { min, .. } => *min,
        SizeDistribution::Normal { mean, std_dev } => (mean - 3.0 * std_dev).max(0.1 * mean),
        // The 0.1 % quantile.
        SizeDistribution::LogNormal { median, geometric_std } => median * (-3.09 * geometric_std.ln()).exp(),
        SizeDistribution::Tabulated { diameters, .. } => diameters[0],
    }
}

/// Engine objects built from a scene.
pub struct Built {
    pub materials: Vec<Material>,
    pub pairs: PairTable<PairProps>,
    pub walls: Vec<Wall>,
}

fn material_index(cfg: &SceneConfig, name: &str, key: &str) -> Result<u16, DemError> {
    cfg.materials.keys().position(|k| k == name).map(|i| i as u16).ok_or_else(|| DemError::Config {
        key: key.into(),
        message: format!("material \"{name}\" is not in [materials]"),
    })
}

fn load_mesh(cfg: &SceneConfig, file: &std::path::Path, scale: f64) -> Result<TriMesh, DemError> {
    Ok(TriMesh::load(&cfg.resolve(file), scale)?)
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
        }
    }
    let pairs = PairTable::build(n, |a, b| {
        let v = &values[a * n + b];
        let mut p = PairProps::new(&materials[a], &materials[b], v.friction, v.restitution);
        p.rolling_friction = v.rolling_friction;
        p.rolling_viscous = v.rolling_viscous_s_m;
        p.work_of_adhesion = v.work_of_adhesion_j_m2;
        p
    });
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
                WallShape::Mesh(Box::new(MeshWall::new(load_mesh(cfg, file, *scale)?)))
            }
        };
        let motion = match &w.motion {
            MotionConfig::Fixed => Motion::Fixed,
            MotionConfig::Translation { velocity_m_s } => Motion::Translation { velocity: *velocity_m_s },
            MotionConfig::Rotation { center_m, axis, angular_speed_rad_s } => {
                Motion::rotation(*center_m, *axis, *angular_speed_rad_s)
            }
            MotionConfig::Tabulated { file, reference_point_m } => {
                let path = cfg.resolve(file);
                let text = std::fs::read_to_string(&path)
                    .map_err(|source| DemError::Io { path: path.clone(), source })?;
                let table = MotionTable::parse(&text, *reference_point_m).map_err(|e| DemError::Config {
                    key: format!("walls[{i}].motion.file"),
                    message: format!("{}: {e}", path.display()),
                })?;
                Motion::Tabulated(table)
            }
        };
        walls.push(Wall { name: w.name.clone(), shape, material, motion });
    }
    Ok(Built { materials, pairs, walls })
}

/// The engine region of a region configuration.
pub fn region(cfg: &SceneConfig, r: &RegionConfig) -> Result<Region, DemError> {
    Ok(match r {
        RegionConfig::Box { min_m, max_m } => Region::Box(Aabb::new(*min_m, *max_m)),
        RegionConfig::Cylinder { base_m, axis, radius_m, height_m } => {
            Region::Cylinder { base: *base_m, axis: axis.normalize(), radius: *radius_m, height: *height_m }
        }
        RegionConfig::Mesh { file, scale } => Region::mesh(load_mesh(cfg, file, *scale)?),
    })
}

/// The particles of the `fill` entries, in order, avoiding each other.
pub fn initial_particles(cfg: &SceneConfig) -> Result<Vec<NewParticle>, DemError> {
    let mut placed: Vec<(Vec3, f64)> = Vec::new();
    let mut out = Vec::new();
    for (i, f) in cfg.fill.iter().enumerate() {
        let material = material_index(cfg, &f.material, &format!("fill[{i}].material"))?;
        let reg = region(cfg, &f.region)?;
        let mut rng: Rng = seeded(cfg.seed, 1000 + i as u64);
        let spheres: Vec<(Vec3, f64)> = match f.method {
            FillMethod::Random => {
                let target = match (f.count, f.volume_fraction) {
                    (Some(n), _) => FillTarget::Count(n),
                    (None, Some(v)) => FillTarget::VolumeFraction(v),
                    (None, None) => FillTarget::Count(0),
                };
                random_fill(&reg, &f.size, target, &placed, f.max_attempts, &mut rng)
            }
            FillMethod::Lattice => {
                let d_max = max_diameter(&f.size);
                let spacing = f.spacing_m.or(d_max.map(|d| 1.01 * d)).unwrap_or(0.0);
                let r_site = 0.5 * spacing;
                let sites = lattice_fill(&reg, spacing, r_site, f.lattice);
                let mut v = Vec::with_capacity(sites.len());
                for x in sites {
                    // Redraw diameters larger than the spacing (unbounded distributions).
                    let mut d = f.size.sample(&mut rng);
                    for _ in 0..100 {
                        if d <= spacing {
                            break;
                        }
                        d = f.size.sample(&mut rng);
                    }
                    let r = 0.5 * d.min(spacing);
                    if placed.iter().all(|(y, ry)| (*y - x).length() >= r + ry) {
                        v.push((x, r));
                    }
                }
                v
            }
        };
        for &(x, r) in &spheres {
            let mut p = NewParticle::at(x, r, material);
            p.vel = f.velocity_m_s;
            p.frozen = f.frozen;
            out.push(p);
        }
        placed.extend(spheres);
    }
    Ok(out)
}

/// The injectors of the `inject` entries with their regions.
pub fn injectors(cfg: &SceneConfig) -> Result<Vec<(Injector, Region)>, DemError> {
    let mut out = Vec::new();
    for (i, j) in cfg.inject.iter().enumerate() {
        let material = material_index(cfg, &j.material, &format!("inject[{i}].material"))?;
        let rho = cfg.materials[&j.material].density;
        let rate = match (j.particles_per_s, j.kg_per_s) {
            (Some(n), _) => InjectionRate::ParticlesPerSecond(n),
            (None, Some(m)) => InjectionRate::KgPerSecond(m),
            (None, None) => InjectionRate::ParticlesPerSecond(0.0),
        };
        let inj = Injector {
            number_rate: Injector::number_rate(rate, &j.size, rho),
            dist: j.size.clone(),
            start: j.start_s,
            end: j.end_s.unwrap_or(f64::INFINITY),
            velocity: j.velocity_m_s,
            material,
            attempts: j.attempts,
            inserted: 0,
            rng: seeded(cfg.seed, 2000 + i as u64),
        };
        out.push((inj, region(cfg, &j.region)?));
    }
    Ok(out)
}
