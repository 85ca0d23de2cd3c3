//! Bed preparation by a sparse pour (Jasion 2013, Appendix C.2): spheres are added one at a time at a
//! random horizontal position in a box or a vertical cylinder, a random gap above the highest particle of
//! the bed over the region, clear of the spheres still falling, and fall onto the growing bed; the pour is
//! settled when the kinetic energy of the particles falls below a threshold. Keys in `docs/bed.md`.
//!
//! A poured sphere counts as *falling* (not part of the bed, so the next sphere is not stacked on it)
//! while its vertical velocity is that of free fall from its release, v_z = v_z0 − g (t − t₀), to within
//! 4 g Δt (the integrators follow a constant acceleration, up to a start-up lag of at most a step's worth
//! of gravity: velocity Verlet's first half kick uses the zero force of a new sphere); its first contact
//! ends that for good. Spheres moving faster than √(g r) (bounced off the bed or knocked in the air) do not
//! count as the bed top either: the bed top is that of the quiet spheres.

use super::config::{RegionConfig, SceneConfig};
use serde::{Deserialize, Serialize};
use spatter_core::check::Checker;
use spatter_core::comm::{Comm, WireReader, WireWriter};
use spatter_core::distribution::SizeDistribution;
use spatter_core::rng::{seeded, Rng, RngExt};
use spatter_core::Vec3;
use spatter_dem::contact::ContactLaw;
use spatter_dem::error::DemError;
use spatter_dem::insertion::WallClearance;
use spatter_dem::particles::{NewParticle, Particles};
use spatter_dem::sim::Simulation;

/// `[pour]`: a sparse pour into a box or a vertical cylinder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PourConfig {
    /// Material of the poured spheres (a key of `[materials]`).
    pub material: String,
    /// Diameter distribution \[m\].
    pub size: SizeDistribution,
    /// Where spheres are added: a `box` or a `cylinder` with a vertical axis. The spheres start inside
    /// it (horizontally inset by their radius); its top limits the height of the bed.
    pub region: RegionConfig,
    /// Number of spheres to pour.
    pub count: u64,
    /// Time between two additions \[s\].
    pub interval_s: f64,
    /// Gap between a new sphere's bottom and the top of the highest particle over the region, as a
    /// range in radii of the new sphere, drawn uniformly (default [1, 4], the thesis's choice).
    #[serde(default = "default_gap")]
    pub gap_radii: [f64; 2],
    /// Velocity of a new sphere \[m/s\] (default 0).
    #[serde(default)]
    pub velocity_m_s: Vec3,
    /// Settled when the kinetic energy (translation and rotation) per sphere is below this fraction of
    /// m g d, the work of lifting a sphere by its diameter (default 10⁻⁴, an r.m.s. speed of about
    /// 0.014 √(g d)).
    #[serde(default = "default_settled")]
    pub settled_energy_ratio: f64,
    /// End the run when the bed has settled (default true); otherwise run to `duration_s`.
    #[serde(default = "yes")]
    pub stop_when_settled: bool,
}

fn default_gap() -> [f64; 2] {
    [1.0, 4.0]
}
fn default_settled() -> f64 {
    1e-4
}
fn yes() -> bool {
    true
}

/// Progress of a pour (part of the checkpoint).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct PourState {
    rng: Rng,
    /// Spheres poured so far.
    pub poured: u64,
    /// Time of the last addition \[s\].
    pub last_pour_s: f64,
    /// Time at which the bed was found settled \[s\].
    pub settled_s: Option<f64>,
    /// Spheres still in free fall: (id, release time \[s\], vertical release speed \[m/s\]).
    falling: Vec<(u32, f64, f64)>,
    /// Additions put off to the next interval because no position clear of the falling spheres was found.
    pub postponed: u64,
}

impl PourState {
    /// A fresh pour with the scene's seed (its own random stream, so fills and injectors do not change it).
    pub fn new(seed: u64) -> Self {
        PourState {
            rng: seeded(seed, 3000),
            poured: 0,
            last_pour_s: 0.0,
            settled_s: None,
            falling: Vec::new(),
            postponed: 0,
        }
    }
}

/// The pour's region as (horizontal shape, bottom z, top z).
enum Footprint {
    Rect { min: [f64; 2], max: [f64; 2] },
    Disc { center: [f64; 2], radius: f64 },
}

fn footprint(r: &RegionConfig) -> Option<(Footprint, f64, f64)> {
    match r {
        RegionConfig::Box { min_m, max_m } => {
            Some((Footprint::Rect { min: [min_m.x, min_m.y], max: [max_m.x, max_m.y] }, min_m.z, max_m.z))
        }
        RegionConfig::Cylinder { base_m, axis, radius_m, height_m } => {
            let up = axis.z.signum();
            let (z0, z1) =
                if up > 0.0 { (base_m.z, base_m.z + height_m) } else { (base_m.z - height_m, base_m.z) };
            Some((Footprint::Disc { center: [base_m.x, base_m.y], radius: *radius_m }, z0, z1))
        }
        RegionConfig::Mesh { .. } => None,
    }
}

impl Footprint {
    fn covers(&self, x: Vec3, margin: f64) -> bool {
        match self {
            Footprint::Rect { min, max } => {
                x.x >= min[0] - margin
                    && x.x <= max[0] + margin
                    && x.y >= min[1] - margin
                    && x.y <= max[1] + margin
            }
            Footprint::Disc { center, radius } => (x.x - center[0]).hypot(x.y - center[1]) <= radius + margin,
        }
    }

    /// A uniform random point of the footprint inset by `r`.
    fn sample(&self, r: f64, rng: &mut Rng) -> (f64, f64) {
        match self {
            Footprint::Rect { min, max } => {
                let u: f64 = rng.random();
                let v: f64 = rng.random();
                (min[0] + r + u * (max[0] - min[0] - 2.0 * r), min[1] + r + v * (max[1] - min[1] - 2.0 * r))
            }
            Footprint::Disc { center, radius } => {
                let u: f64 = rng.random();
                let v: f64 = rng.random();
                let rho = (radius - r) * u.sqrt();
                let phi = std::f64::consts::TAU * v;
                (center[0] + rho * phi.cos(), center[1] + rho * phi.sin())
            }
        }
    }

    /// The smallest horizontal width.
    fn width(&self) -> f64 {
        match self {
            Footprint::Rect { min, max } => (max[0] - min[0]).min(max[1] - min[1]),
            Footprint::Disc { radius, .. } => 2.0 * radius,
        }
    }
}

/// Checks of `[pour]` (called from the scene's validation).
pub(crate) fn check(c: &mut Checker, cfg: &SceneConfig, p: &PourConfig) {
    c.nested("pour", |c| {
        if !cfg.materials.contains_key(&p.material) {
            c.fail(
                "material",
                format!(
                    "material = \"{}\" is not in [materials] (defined: {})",
                    p.material,
                    cfg.material_names().join(", ")
                ),
            );
        }
        if let Err(e) = p.size.check() {
            c.fail("size", e);
        }
        if p.count == 0 {
            c.fail("count", "count = 0: a pour needs at least one sphere".to_string());
        }
        c.memory_estimate(
            "count",
            &format!("count = {} particles × {} B", p.count, super::config::BYTES_PER_PARTICLE),
            p.count as f64 * super::config::BYTES_PER_PARTICLE as f64,
        );
        c.positive("interval_s", p.interval_s);
        c.finite_vec("velocity_m_s", p.velocity_m_s);
        c.positive("settled_energy_ratio", p.settled_energy_ratio);
        let [g0, g1] = p.gap_radii;
        if !(g0.is_finite() && g1.is_finite() && g0 >= 0.0 && g1 >= g0) {
            c.fail(
                "gap_radii",
                format!("gap_radii = [{g0}, {g1}] must be a range 0 ≤ low ≤ high, e.g. [1, 4]"),
            );
        }
        let g = cfg.gravity_m_s2;
        if !(g.x == 0.0 && g.y == 0.0 && g.z < 0.0) {
            c.fail(
                "region",
                format!(
                    "a pour needs gravity along −z (gravity_m_s2 = [0, 0, −g]); found [{}, {}, {}]",
                    g.x, g.y, g.z
                ),
            );
        }
        match &p.region {
            RegionConfig::Box { min_m, max_m } => {
                c.nested("region", |c| {
                    c.finite_vec("min_m", *min_m);
                    c.finite_vec("max_m", *max_m);
                    if !max_m.cmpgt(*min_m).all() {
                        c.fail("max_m", "max_m must exceed min_m in x, y and z".to_string());
                    }
                });
            }
            RegionConfig::Cylinder { base_m, axis, radius_m, height_m } => c.nested("region", |c| {
                c.finite_vec("base_m", *base_m);
                c.positive("radius_m", *radius_m);
                c.positive("height_m", *height_m);
                if !(axis.x == 0.0 && axis.y == 0.0 && axis.z != 0.0) {
                    c.fail(
                        "axis",
                        format!(
                            "a pour cylinder is vertical: axis = [0, 0, 1]; found [{}, {}, {}]",
                            axis.x, axis.y, axis.z
                        ),
                    );
                }
            }),
            RegionConfig::Mesh { .. } => c.fail(
                "region",
                "a pour region is a box or a vertical cylinder (type = \"box\" or \"cylinder\")".to_string(),
            ),
        }
        let Some((fp, z0, z1)) = footprint(&p.region) else { return };
        if let Some(d) = spatter_dem::insertion::max_diameter(&p.size) {
            if fp.width() <= d || z1 - z0 <= d {
                c.fail(
                    "region",
                    format!(
                        "the pour region ({:.4e} m wide, {:.4e} m high) must be wider and higher than the \
                         largest diameter {d:e} m",
                        fp.width(),
                        z1 - z0
                    ),
                );
            }
        }
        if let (Some(lo), Some(hi)) = (cfg.engine.domain_min_m, cfg.engine.domain_max_m) {
            let (bmin, bmax) = match &p.region {
                RegionConfig::Box { min_m, max_m } => (*min_m, *max_m),
                RegionConfig::Cylinder { base_m, radius_m, .. } => (
                    Vec3::new(base_m.x - radius_m, base_m.y - radius_m, z0),
                    Vec3::new(base_m.x + radius_m, base_m.y + radius_m, z1),
                ),
                RegionConfig::Mesh { .. } => return,
            };
            if bmax.z > hi.z {
                c.fail(
                    "region",
                    format!(
                        "the pour region reaches z = {} m, above the domain (engine.domain_max_m z = {} m): \
                         spheres poured there would leave the domain at once; lower the region or raise the \
                         domain",
                        bmax.z, hi.z
                    ),
                );
            } else if !(bmin.cmpge(lo).all() && bmax.cmple(hi).all()) {
                c.fail(
                    "region",
                    format!(
                        "the pour region [{bmin}, {bmax}] must lie inside the domain [engine.domain_min_m, \
                         engine.domain_max_m] = [{lo}, {hi}]"
                    ),
                );
            }
        }
    });
}

/// Random horizontal positions tried per addition before it is put off to the next interval.
const TRIES: u32 = 200;

/// Adds the next sphere of the pour to `sim` (the caller calls this every `interval_s` while
/// `state.poured < count`): a random horizontal position in the region inset by its radius, its bottom a
/// random gap above the top of the highest quiet bed particle (not falling, speed ≤ √(g r)) over the
/// region (or the region's bottom), clear of
/// the walls and of the spheres still falling. When no such position is found in [`TRIES`] draws, the
/// addition waits for the next interval.
pub(crate) fn add_next<L: ContactLaw>(
    sim: &mut Simulation<L>,
    p: &PourConfig,
    material: u16,
    state: &mut PourState,
    comm: &dyn Comm,
) -> Result<(), DemError> {
    let Some((fp, z0, z1)) = footprint(&p.region) else { return Ok(()) };
    let split = sim.ranks() > 1;
    let t = sim.time();
    let g = sim.gravity.length();
    let parts = &sim.particles;
    // Which of the falling spheres still fall freely (on ranks: as the rank holding each finds).
    let tol = 4.0 * g * sim.dt;
    let mut still = vec![0.0; state.falling.len()];
    for i in 0..parts.len() {
        if let Some(k) = state.falling.iter().position(|f| f.0 == parts.id[i]) {
            let (_, t0, vz0) = state.falling[k];
            let free = (parts.vel[i].z - (vz0 - g * (t - t0))).abs() <= tol
                && parts.vel[i].x == p.velocity_m_s.x
                && parts.vel[i].y == p.velocity_m_s.y;
            still[k] = f64::from(u8::from(free));
        }
    }
    if split {
        comm.all_max_f64(&mut still);
    }
    let mut k = 0;
    state.falling.retain(|_| {
        k += 1;
        still[k - 1] > 0.0
    });
    let d = p.size.sample(&mut state.rng);
    let r = 0.5 * d;
    let u: f64 = state.rng.random();
    let gap = r * (p.gap_radii[0] + u * (p.gap_radii[1] - p.gap_radii[0]));
    let mut r_max = [parts.radius.iter().copied().fold(r, f64::max)];
    if split {
        comm.all_max_f64(&mut r_max);
    }
    let r_max = r_max[0];
    let mut top = [z0];
    for i in 0..parts.len() {
        let quiet = parts.vel[i].length_squared() <= g * parts.radius[i];
        if quiet && fp.covers(parts.pos[i], r_max) && !state.falling.iter().any(|f| f.0 == parts.id[i]) {
            top[0] = top[0].max(parts.pos[i].z + parts.radius[i]);
        }
    }
    if split {
        comm.all_max_f64(&mut top);
    }
    let top = top[0];
    let z = top + gap + r;
    if z + r > z1 {
        return Err(DemError::Config {
            key: "pour.region".into(),
            message: format!(
                "after {} of {} spheres the bed reaches z = {top:.6e} m (t = {t:.6} s): the next sphere \
                 (diameter {d:e} m, gap {gap:.3e} m) would start above the region's top z = {z1} m. Raise \
                 the region's top or pour fewer spheres",
                state.poured, p.count
            ),
        });
    }
    let walls = WallClearance::new(&sim.walls, t);
    // The spheres near the release height (of every rank; the test below does not depend on order).
    let mut near: Vec<(Vec3, f64)> = (0..parts.len())
        .filter(|&i| (parts.pos[i].z - z).abs() < parts.radius[i] + r)
        .map(|i| (parts.pos[i], parts.radius[i]))
        .collect();
    if split {
        near = gather_spheres(&near, comm);
    }
    for _ in 0..TRIES {
        let (x, y) = fp.sample(r, &mut state.rng);
        let pos = Vec3::new(x, y, z);
        let clear = near.iter().all(|&(xi, ri)| (xi - pos).length() >= ri + r);
        if clear && walls.overlapping(pos, r).is_none() {
            let mut np = NewParticle::at(pos, r, material);
            np.vel = p.velocity_m_s;
            let id = sim.add_particle_split(np);
            state.falling.push((id, t, p.velocity_m_s.z));
            state.poured += 1;
            state.last_pour_s = t;
            return Ok(());
        }
    }
    state.postponed += 1;
    Ok(())
}

/// Every rank's (centre, radius) pairs (collective).
fn gather_spheres(mine: &[(Vec3, f64)], comm: &dyn Comm) -> Vec<(Vec3, f64)> {
    let mut w = WireWriter::with_capacity(32 * mine.len());
    for (x, r) in mine {
        w.vec3(*x).f64(*r);
    }
    let mut all = Vec::new();
    for buf in comm.all_gather_bytes(&w.finish()) {
        let mut rd = WireReader::new(&buf);
        let bad = "pour message from another rank of this run";
        while !rd.is_done() {
            all.push((rd.vec3().expect(bad), rd.f64().expect(bad)));
        }
    }
    all
}

/// Kinetic energy (translation and rotation, solid spheres) and Σ m g d of the free spheres \[J\].
pub(crate) fn kinetic_and_scale(p: &Particles, g: f64) -> (f64, f64) {
    let (mut ke, mut scale) = (0.0, 0.0);
    for i in 0..p.len() {
        if p.inv_mass[i] <= 0.0 {
            continue;
        }
        let m = 1.0 / p.inv_mass[i];
        let r = p.radius[i];
        ke += 0.5 * m * (p.vel[i].length_squared() + 0.4 * r * r * p.omega[i].length_squared());
        scale += m * g * 2.0 * r;
    }
    (ke, scale)
}

/// Whether the pour is settled at the current time: every sphere poured, the last one given the time to
/// fall freely through the whole region height, and the kinetic energy below `settled_energy_ratio`
/// × Σ m g d.
pub(crate) fn settled<L: ContactLaw>(
    sim: &Simulation<L>,
    p: &PourConfig,
    state: &PourState,
    comm: &dyn Comm,
) -> bool {
    if state.poured < p.count {
        return false;
    }
    let Some((_, z0, z1)) = footprint(&p.region) else { return false };
    let g = sim.gravity.length();
    let fall = (2.0 * (z1 - z0) / g).sqrt();
    if sim.time() < state.last_pour_s + fall {
        return false;
    }
    let (ke, scale) = kinetic_and_scale(&sim.particles, g);
    let mut sums = [ke, scale];
    if sim.ranks() > 1 {
        comm.sum_f64_ordered(&mut sums);
    }
    sums[0] <= p.settled_energy_ratio * sums[1]
}

/// The packing profile box of a pour region: the box itself, or for a cylinder the square inscribed in
/// its cross-section (an exact sphere–cylinder cut is not needed for a profile).
pub(crate) fn profile_box(p: &PourConfig) -> Option<spatter_core::Aabb> {
    let (fp, z0, z1) = footprint(&p.region)?;
    Some(match fp {
        Footprint::Rect { min, max } => {
            spatter_core::Aabb::new(Vec3::new(min[0], min[1], z0), Vec3::new(max[0], max[1], z1))
        }
        Footprint::Disc { center, radius } => {
            let h = radius / std::f64::consts::SQRT_2;
            spatter_core::Aabb::new(
                Vec3::new(center[0] - h, center[1] - h, z0),
                Vec3::new(center[0] + h, center[1] + h, z1),
            )
        }
    })
}
