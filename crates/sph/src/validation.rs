//! Reference cases of `spatter validate` (hydrostatic tank, Poiseuille flow after Morris, Fox & Zhu
//! 1997, dam break against Martin & Moyce 1952). Each runs a reduced variant in
//! seconds (`quick = true`, also run by the crate's tests) and a finer one for the report.

use crate::boundary::Slip;
use crate::kernel::Dim;
use crate::params::SphParams;
use crate::sim::{Simulation, WallOptions};
use spatter_core::validation::{Case, Check};
use spatter_core::{Aabb, Vec3};

/// Every SPH validation case.
pub fn validation_cases() -> Vec<Case> {
    vec![
        Case { name: "sph_hydrostatic_tank", run: hydrostatic_tank },
        Case { name: "sph_poiseuille", run: poiseuille },
        Case { name: "sph_conservation", run: conservation },
        Case { name: "sph_dam_break_surge_front", run: dam_break_front },
        Case { name: "sph_dam_break_wall_pressure", run: dam_break_pressure },
        Case { name: "sph_sessile_drop", run: sessile_drop_angles },
        Case { name: "sph_submerged_solid", run: submerged_solid },
        Case { name: "sph_thin_shell_leak", run: thin_shell_leak },
        Case { name: "sph_wheel_wading", run: crate::wheel_wading::wheel_wading },
    ]
}

/// Advances until `t_end`, calling `sample` after every step.
fn run_until(sim: &mut Simulation, t_end: f64, mut sample: impl FnMut(&mut Simulation)) {
    sim.initialize().expect("validation set-up is valid");
    while sim.time < t_end {
        sim.step().expect("validation case runs without blow-up");
        sample(sim);
    }
}

const OPEN_TOP: [bool; 6] = [true, true, true, true, true, false];

/// What [`thin_shell_sweep`] counted.
#[derive(Clone, Copy, Debug)]
pub struct ShellSweep {
    /// Fluid particles at the start.
    pub particles: usize,
    /// Particles first found on the other side of the plate below its top edge: leaks.
    pub crossed: usize,
    /// Particles first found on the other side above the plate's top edge (splash thrown over it).
    pub over_top: usize,
    /// Particles missing at the end (removed from the domain).
    pub lost: usize,
    /// Times the wall guard stopped a particle from passing a wall (`guard.rs`).
    pub guard_hits: u64,
}

/// A plate one particle layer thick (an open mesh, `layers = 1`) spanning the whole cross-section of a
/// tank 0.4 × 0.1 m, water 0.15 m deep, sweeps through the water at 1 m/s along +x from x = 0.1 m
/// (prescribed by a tabulated motion) until `t_end` [s], at fluid spacing `dp` [m]. Counts every particle
/// that ever gets to the other side, through the plate or over its top edge (z = 0.32 m): from about
/// 0.11 s on, the bow wave runs up the plate and over it.
pub fn thin_shell_sweep(dp: f64, t_end: f64) -> ShellSweep {
    use spatter_core::mesh::TriMesh;
    const PLATE_TOP: f64 = 0.32;
    use spatter_core::motion::{Motion, MotionTable};
    let mut p = SphParams::water(Dim::Three, dp, 20.0);
    p.gravity = Vec3::new(0.0, 0.0, -9.81);
    let mut sim = Simulation::new(p);
    let inner = Aabb::new(Vec3::ZERO, Vec3::new(0.4, 0.1, 0.3));
    sim.add_tank("tank", inner, OPEN_TOP, None, None, WallOptions::default());
    // Plate x = 0.1, reaching 2 cm into the side walls and the floor; triangles about dp/0.6 wide.
    let (nx, ny) = ((0.14 / dp * 0.6).round() as usize, (0.34 / dp * 0.6).round() as usize);
    let mut plate = TriMesh::rectangle(0.14, 0.34, 0.0, nx.max(1), ny.max(1));
    plate.map_vertices(|v| Vec3::new(0.1, v.x - 0.02, v.y - 0.02));
    let table = MotionTable::parse("0 1 0 0 0 0 0\n1 1 0 0 0 0 0\n", Vec3::new(0.1, 0.05, 0.15))
        .expect("a valid motion table");
    let node = sim.add_motion(Motion::Tabulated(table), None);
    sim.add_mesh("plate", plate, Some(1), Some(node), WallOptions::default()).expect("a valid plate mesh");
    let particles = sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(0.4, 0.1, 0.15)), Vec3::ZERO, true);
    // Side of the plate (x beyond it) by particle id.
    let side = |sim: &Simulation| -> Vec<(u32, bool)> {
        let xp = 0.1 + sim.time;
        let mut s: Vec<(u32, bool)> =
            sim.fluid.id.iter().zip(&sim.fluid.pos).map(|(&i, x)| (i, x.x > xp)).collect();
        s.sort_unstable();
        s
    };
    sim.initialize().expect("validation set-up is valid");
    let start = side(&sim);
    // Per particle: None until it is first seen on the other side, then whether that was above the top.
    let mut ever_crossed: Vec<Option<bool>> = vec![None; start.len()];
    let mut guard_hits = 0;
    let mut height_of = std::collections::HashMap::new();
    while sim.time < t_end {
        sim.step().expect("validation case runs without blow-up");
        guard_hits += sim.last.guard_hits;
        height_of.clear();
        height_of.extend(sim.fluid.id.iter().zip(&sim.fluid.pos).map(|(&i, x)| (i, x.z)));
        for (id, now) in side(&sim) {
            if let Ok(k) = start.binary_search_by_key(&id, |s| s.0) {
                if start[k].1 != now && ever_crossed[k].is_none() {
                    ever_crossed[k] = Some(height_of[&id] > PLATE_TOP);
                }
            }
        }
    }
    ShellSweep {
        particles,
        crossed: ever_crossed.iter().filter(|&&c| c == Some(false)).count(),
        over_top: ever_crossed.iter().filter(|&&c| c == Some(true)).count(),
        lost: particles - sim.fluid.len(),
        guard_hits,
    }
}

/// Leak test (issue: "a moving thin shell sweeping through water loses no particle through it"): the
/// one-layer plate of [`thin_shell_sweep`] pushes water at 1 m/s; no particle may ever be found on the
/// other side of it below its top edge (water thrown over the top is not a leak). Quick: dp = 12.5 mm
/// for 0.12 s; full: dp = 8 mm for 0.2 s, 0.2 m of sweep, with the bow wave spilling over the plate.
/// Tolerance 0 (a count).
pub fn thin_shell_leak(quick: bool) -> Vec<Check> {
    let case = "sph_thin_shell_leak";
    let src = "a wall is impermeable (issue 6 leak test)";
    let (dp, t_end) = if quick { (0.0125, 0.12) } else { (0.008, 0.2) };
    let o = thin_shell_sweep(dp, t_end);
    vec![Check::absolute(
        case,
        format!("particles through the plate (of {}; {} thrown over it) [-]", o.particles, o.over_top),
        0.0,
        o.crossed as f64,
        0.0,
        src,
    )]
}

/// A fixed closed STL-like mesh (a cube of 6 dp) under 6 dp of water at rest: the fluid force on it is
/// its buoyancy ρ g V (Archimedes), and its whole surface reads wet (solid meshes are sampled inside the
/// surface, so the fluid rests dp/2 off it). Quick: the force averaged over the first 150 steps; full:
/// over 0.2–0.4 s, after the tank's first sloshing. Tolerance 2 % (measured −0.3 % at t = 0, +0.03 %
/// over 0.2–0.4 s); wet area exact (every first-layer particle wet).
pub fn submerged_solid(quick: bool) -> Vec<Check> {
    let case = "sph_submerged_solid";
    let src = "Archimedes: buoyancy = ρ g V";
    let dp = 0.01;
    let mut p = SphParams::water(Dim::Three, dp, 20.0);
    p.gravity = Vec3::new(0.0, 0.0, -9.81);
    let mut sim = Simulation::new(p);
    sim.add_tank(
        "tank",
        Aabb::new(Vec3::ZERO, Vec3::new(0.3, 0.1, 0.3)),
        OPEN_TOP,
        None,
        None,
        WallOptions::default(),
    );
    let cube = Aabb::new(Vec3::new(0.12, 0.02, 0.04), Vec3::new(0.18, 0.08, 0.10));
    let mesh = crate::boundary::box_surface(cube, [true; 6], false, Dim::Three);
    let k = sim.add_mesh("cube", mesh, None, None, WallOptions::default()).expect("a closed cube is valid");
    sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(0.3, 0.1, 0.16)), Vec3::ZERO, true);
    let buoyancy = 1000.0 * 9.81 * 0.06f64.powi(3);
    let (mut sum, mut n, mut steps) = (0.0, 0usize, 0usize);
    let mut dry_after_first = f64::NAN;
    let (from, t_end) = if quick { (0.0, f64::INFINITY) } else { (0.2, 0.4) };
    sim.initialize().expect("validation set-up is valid");
    while sim.time < t_end && (!quick || steps < 150) {
        sim.step().expect("validation case runs without blow-up");
        steps += 1;
        if steps == 1 {
            let w = crate::wetting::wet_area(&sim, k, sim.time);
            dry_after_first = (w.area - w.wet_now) / w.area;
        }
        if sim.time >= from {
            sum += sim.part_loads()[k].force.z;
            n += 1;
        }
    }
    let w = crate::wetting::wet_area(&sim, k, sim.time);
    let window = if quick { "first 150 steps" } else { "0.2–0.4 s" };
    vec![
        Check::relative(
            case,
            format!("vertical fluid force, mean over the {window} [N]"),
            buoyancy,
            sum / n as f64,
            0.02,
            src,
        ),
        Check::absolute(
            case,
            "dry fraction of the surface after the first step [-]",
            0.0,
            dry_after_first,
            1e-12,
            src,
        ),
        Check::absolute(
            case,
            "dry fraction of the surface at the end [-]",
            0.0,
            (w.area - w.wet_now) / w.area,
            1e-12,
            src,
        ),
    ]
}

/// Water at rest in a tank: pressure at depth within 2 % of ρgz after settling, no particle lost,
/// kinetic energy decaying. 2D; the full variant is finer and 3D.
pub fn hydrostatic_tank(quick: bool) -> Vec<Check> {
    let case = "sph_hydrostatic_tank";
    let (dim, dp, t_end) = if quick { (Dim::Two, 0.01, 1.0) } else { (Dim::Three, 0.01, 1.5) };
    let (width, depth): (f64, f64) = (0.4, 0.2);
    let g: f64 = 9.81;
    let mut p = SphParams::water(dim, dp, 10.0 * (2.0 * g * depth).sqrt());
    p.gravity = Vec3::new(0.0, 0.0, -g);
    let ly = if dim == Dim::Three { 0.1 } else { 0.0 };
    let mut sim = Simulation::new(p);
    sim.add_tank(
        "tank",
        Aabb::new(Vec3::ZERO, Vec3::new(width, ly, 2.0 * depth)),
        OPEN_TOP,
        None,
        None,
        WallOptions::default(),
    );
    let n0 = sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(width, ly, depth)), Vec3::ZERO, true);
    let mut ke_max: f64 = 0.0;
    let mut ke_late = Vec::new();
    run_until(&mut sim, t_end, |s| {
        let ke = s.kinetic_energy();
        ke_max = ke_max.max(ke);
        if s.time > 0.8 * t_end {
            ke_late.push(ke);
        }
    });
    let mut checks = Vec::new();
    let src = "hydrostatics p = ρ g z";
    for frac in [0.25, 0.5, 0.75] {
        let z = depth * (1.0 - frac);
        let x = Vec3::new(0.5 * width, 0.5 * ly, z);
        let (pr, _) = sim.probe(x).unwrap_or((f64::NAN, Vec3::ZERO));
        let want = 1000.0 * g * frac * depth;
        checks.push(Check::relative(
            case,
            format!("p at depth {:.3} m [Pa]", frac * depth),
            want,
            pr,
            0.02,
            src,
        ));
    }
    let lost = n0 - sim.fluid.len();
    checks.push(Check::absolute(case, "particles lost [-]", 0.0, lost as f64, 0.0, "closed tank"));
    let escaped = sim.fluid.pos.iter().filter(|x| x.x < 0.0 || x.x > width || x.z < 0.0).count();
    checks.push(Check::absolute(
        case,
        "particles outside the tank [-]",
        0.0,
        escaped as f64,
        0.0,
        "closed tank",
    ));
    // Kinetic energy at the end is below a fifth of its maximum (the start-up transient decays).
    let ke_end = ke_late.iter().copied().fold(0.0, f64::max);
    checks.push(Check::absolute(
        case,
        "KE(late)/KE(max) [-]",
        0.0,
        ke_end / ke_max.max(1e-300),
        0.2,
        "decay of the start-up transient",
    ));
    // Total fluid force on the tank equals the weight of the water.
    let load = sim.part_loads()[0].force.z;
    checks.push(Check::relative(
        case,
        "vertical load on the tank [N]",
        -sim.fluid_mass() * g,
        load,
        0.02,
        "weight of the water",
    ));
    checks
}

/// Start-up of plane Poiseuille flow (Morris, Fox & Zhu 1997, J. Comput. Phys. 136:214): plates 1 mm
/// apart, ν = 10⁻⁶ m²/s, body force 2·10⁻⁴ m/s², periodic in x. Velocity profile within 2 % of the
/// series solution (error relative to the steady centre-line speed).
pub fn poiseuille(quick: bool) -> Vec<Check> {
    let case = "sph_poiseuille";
    let l = 1e-3;
    let nu = 1e-6;
    let f = 2e-4;
    let n_across = if quick { 20 } else { 40 };
    let dp = l / n_across as f64;
    let u_max = f * l * l / (8.0 * nu);
    let mut p = SphParams::water(Dim::Two, dp, 10.0 * u_max);
    p.gravity = Vec3::new(f, 0.0, 0.0);
    p.artificial_viscosity = 0.0;
    p.density_diffusion = 0.0;
    p.kinematic_viscosity = nu;
    let lx = 16.0 * dp;
    let mut sim = Simulation::new(p);
    let n_layers = sim.default_layers();
    let layers = Some(n_layers);
    let wall = WallOptions { adhesion: 0.0, slip: Slip::NoSlip };
    let thick = n_layers as f64 * dp;
    sim.add_block(
        "bottom",
        Aabb::new(Vec3::new(0.0, 0.0, -thick), Vec3::new(lx, 0.0, 0.0)),
        layers,
        None,
        wall,
    );
    sim.add_block(
        "top",
        Aabb::new(Vec3::new(0.0, 0.0, l), Vec3::new(lx, 0.0, l + thick)),
        layers,
        None,
        wall,
    );
    sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(lx, 0.0, l)), Vec3::ZERO, false);
    sim.set_domain(Aabb::new(Vec3::new(0.0, -1.0, -2.0 * thick), Vec3::new(lx, 1.0, l + 2.0 * thick)));
    sim.set_periodic(0);
    let series = |z: f64, t: f64| {
        let mut u = f / (2.0 * nu) * z * (l - z);
        for n in 0..200 {
            let k = (2 * n + 1) as f64;
            u -= 4.0 * f * l * l / (nu * std::f64::consts::PI.powi(3) * k.powi(3))
                * (std::f64::consts::PI * z * k / l).sin()
                * (-(k * k) * std::f64::consts::PI.powi(2) * nu * t / (l * l)).exp();
        }
        u
    };
    let times: &[f64] = if quick { &[0.0225, 0.1125, 1.0] } else { &[0.0225, 0.045, 0.1125, 0.225, 1.0] };
    let mut checks = Vec::new();
    sim.initialize().expect("valid set-up");
    for &t in times {
        while sim.time < t {
            sim.step().expect("no blow-up");
        }
        // Mean u_x per lattice row against the series at the row centre.
        let mut sum = vec![0.0; n_across];
        let mut cnt = vec![0usize; n_across];
        for (x, v) in sim.fluid.pos.iter().zip(&sim.fluid.vel) {
            let k = ((x.z / dp).floor().max(0.0) as usize).min(n_across - 1);
            sum[k] += v.x;
            cnt[k] += 1;
        }
        let mut worst: f64 = 0.0;
        for k in 0..n_across {
            if cnt[k] > 0 {
                let z = (k as f64 + 0.5) * dp;
                worst = worst.max((sum[k] / cnt[k] as f64 - series(z, sim.time)).abs());
            }
        }
        checks.push(Check::absolute(
            case,
            format!("max |u − u_series|/u_max at t = {t} s [-]"),
            0.0,
            worst / u_max,
            0.02,
            "Morris, Fox & Zhu (1997) series solution",
        ));
    }
    checks
}

/// Momentum and mass of a free blob (no gravity, no walls) with random velocities: total momentum
/// conserved to round-off by the pairwise forces, particle count (mass) exact.
pub fn conservation(quick: bool) -> Vec<Check> {
    let case = "sph_conservation";
    let n = if quick { 8 } else { 14 };
    let dp = 0.01;
    let mut p = SphParams::water(Dim::Three, dp, 20.0);
    p.gravity = Vec3::ZERO;
    p.density_window = [0.0, f64::INFINITY];
    let mut sim = Simulation::new(p);
    let mut pts = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                pts.push(Vec3::new(i as f64, j as f64, k as f64) * dp);
            }
        }
    }
    sim.add_particles(&pts, Vec3::ZERO);
    let mut rng = spatter_core::rng::seeded(7, 0);
    use spatter_core::rng::RngExt;
    for v in &mut sim.fluid.vel {
        *v = Vec3::new(rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5, rng.random::<f64>() - 0.5);
    }
    sim.set_domain(Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0)));
    sim.initialize().expect("valid set-up");
    let p0 = sim.momentum();
    let scale = sim.params.mass() * sim.fluid.vel.iter().map(|v| v.length()).sum::<f64>();
    let steps = if quick { 40 } else { 400 };
    for _ in 0..steps {
        sim.step().expect("no blow-up");
    }
    let dpm = (sim.momentum() - p0).length() / scale;
    vec![
        Check::absolute(case, "|ΔP|/Σ m|v| [-]", 0.0, dpm, 1e-12, "pairwise antisymmetric forces"),
        Check::absolute(
            case,
            "particles lost [-]",
            0.0,
            (pts.len() - sim.fluid.len()) as f64,
            0.0,
            "mass is exact",
        ),
    ]
}

/// Martin & Moyce (1952) collapse of a water column of width a and height 2a (n² = 2, a = 2.25 in),
/// surge front Z = x/a against T = t √(2g/a), as digitised from their Fig. 3.
const MARTIN_MOYCE: [(f64, f64); 5] =
    [(0.832, 1.217), (1.219, 1.474), (1.997, 2.292), (2.547, 2.995), (3.345, 4.134)];

/// Surge front of the a × 2a dam break against Martin & Moyce (1952), error at each reference point (2D).
pub fn dam_break_front(quick: bool) -> Vec<Check> {
    let case = "sph_dam_break_surge_front";
    let a: f64 = 0.1;
    let g: f64 = 9.81;
    let dp = if quick { a / 20.0 } else { a / 50.0 };
    let mut p = SphParams::water(Dim::Two, dp, 10.0 * (2.0 * g * 2.0 * a).sqrt());
    p.gravity = Vec3::new(0.0, 0.0, -g);
    let mut sim = Simulation::new(p);
    sim.add_tank(
        "tank",
        Aabb::new(Vec3::ZERO, Vec3::new(6.0 * a, 0.0, 3.0 * a)),
        OPEN_TOP,
        None,
        None,
        WallOptions::default(),
    );
    sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(a, 0.0, 2.0 * a)), Vec3::ZERO, true);
    let tscale = (2.0 * g / a).sqrt();
    let t_end = (MARTIN_MOYCE[MARTIN_MOYCE.len() - 1].0 + 0.05) / tscale;
    let mut track: Vec<(f64, f64)> = Vec::new();
    run_until(&mut sim, t_end, |s| {
        let front = s.fluid.pos.iter().map(|x| x.x).fold(0.0, f64::max) + 0.5 * dp;
        track.push((s.time * tscale, front / a));
    });
    // The measured front lags inviscid solutions while the column is released (the membrane took a finite
    // time to clear, and floor friction slows the thin tongue): numerical models run 10–20 % ahead of the
    // data for T < 2. Each point is reported with a 20 % tolerance; the front speed over the developed phase
    // T ∈ [2.0, 3.35], which does not depend on the time origin, is checked at 5 %.
    let mut checks: Vec<Check> = MARTIN_MOYCE
        .iter()
        .map(|&(t_ref, z_ref)| {
            let z = interpolate(&track, t_ref);
            Check::relative(
                case,
                format!("Z = x/a at T = {t_ref}"),
                z_ref,
                z,
                0.20,
                "Martin & Moyce (1952), n² = 2, Fig. 3",
            )
        })
        .collect();
    let (t0, z0) = MARTIN_MOYCE[2];
    let (t1, z1) = MARTIN_MOYCE[4];
    let speed_ref = (z1 - z0) / (t1 - t0);
    let speed = (interpolate(&track, t1) - interpolate(&track, t0)) / (t1 - t0);
    checks.push(Check::relative(
        case,
        "front speed dZ/dT, T ∈ [2.0, 3.35]",
        speed_ref,
        speed,
        0.05,
        "Martin & Moyce (1952), n² = 2, Fig. 3",
    ));
    checks
}

/// Linear interpolation in a sorted table.
fn interpolate(table: &[(f64, f64)], x: f64) -> f64 {
    match table.iter().position(|p| p.0 >= x) {
        None => table.last().map(|p| p.1).unwrap_or(f64::NAN),
        Some(0) => table[0].1,
        Some(k) => {
            let (a, b) = (table[k - 1], table[k]);
            a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
        }
    }
}

/// Wall pressure p/(ρgH) at sensor P1 against T = t √(g/H) for the Buchner (2002) dam break at spacing
/// H/`n` (see [`dam_break_pressure`]).
pub fn dam_break_pressure_series(n: usize) -> Vec<(f64, f64)> {
    let h: f64 = 0.6;
    let g: f64 = 9.81;
    let dp = h / n as f64;
    let mut p = SphParams::water(Dim::Two, dp, 10.0 * (2.0 * g * h).sqrt());
    p.gravity = Vec3::new(0.0, 0.0, -g);
    let mut sim = Simulation::new(p);
    let lx = 5.366 * h;
    sim.add_tank(
        "tank",
        Aabb::new(Vec3::ZERO, Vec3::new(lx, 0.0, 3.0 * h)),
        OPEN_TOP,
        None,
        None,
        WallOptions::default(),
    );
    sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(2.0 * h, 0.0, h)), Vec3::ZERO, true);
    let tscale = (g / h).sqrt();
    let pscale = 1000.0 * g * h;
    // Sensor P1 as in Adami et al. (2012) and TrixiParticles.jl, following Greco (2001): the wall segment
    // z ∈ [0.07, 0.16] m whose top is at the experimental sensor centre.
    let sensor = Vec3::new(lx + 0.5 * dp, 0.0, 0.115);
    let radius = 0.045_f64.max(0.75 * dp);
    let mut series: Vec<(f64, f64)> = Vec::new();
    let t_end = 4.7 / tscale;
    run_until(&mut sim, t_end, |s| {
        let pw = s.wall_pressure(sensor, radius).unwrap_or(0.0);
        series.push((s.time * tscale, pw / pscale));
    });
    series
}

/// Dam break of Zhou et al. (1999) / Buchner (2002): column H = 0.6 m high and 2H wide in a tank 5.366 H
/// long; pressure sensor P1 on the opposite wall centred 0.16 m above the floor. Reference values from
/// Buchner's measurement (PhD thesis, TU Delft 2002) as digitised in the TrixiParticles.jl validation set
/// (`exp_pressure_sensor_P1.csv`), in p/(ρgH) against T = t √(g/H):
/// arrival (p first above 0.1) at T ≈ 2.48 and a quasi-steady level of 0.549 (mean over T ∈ [3.4, 4.6]).
pub fn dam_break_pressure(quick: bool) -> Vec<Check> {
    let case = "sph_dam_break_wall_pressure";
    let series = dam_break_pressure_series(if quick { 20 } else { 60 });
    let arrival = series.iter().find(|p| p.1 > 0.1).map(|p| p.0).unwrap_or(f64::NAN);
    let plateau: Vec<f64> = series.iter().filter(|p| p.0 >= 3.4 && p.0 <= 4.6).map(|p| p.1).collect();
    let mean = plateau.iter().sum::<f64>() / plateau.len().max(1) as f64;
    let src = "Buchner (2002) sensor P1, digitised by TrixiParticles.jl";
    if quick {
        // At H/20 the run-up reaches the sensor up to 8 % late (it converges to within 5 % at H/60, see the
        // full variant), and the quasi-steady level is not resolved; only the arrival is checked, at 10 %.
        return vec![Check::relative(
            case,
            "arrival T at P1 (p > 0.1 ρgH), H/20 [-]",
            2.48,
            arrival,
            0.10,
            src,
        )];
    }
    vec![
        Check::relative(case, "arrival T at P1 (p > 0.1 ρgH) [-]", 2.48, arrival, 0.05, src),
        Check::relative(case, "mean p/(ρgH) at P1, T ∈ [3.4, 4.6] [-]", 0.549, mean, 0.10, src),
    ]
}

/// Sessile drops on walls of increasing adhesion (2D): the static contact angle decreases monotonically
/// with the adhesion factor, and a wall that attracts the liquid as strongly as the liquid attracts itself
/// (factor 1) is wetted (θ < 90°). Measured angles are in docs/sph.md; they fall more steeply with the
/// factor than Young–Dupré for pair potentials (1 + cos θ = 2f) would have them.
pub fn sessile_drop_angles(quick: bool) -> Vec<Check> {
    use crate::sessile::{sessile_drop, SessileDrop};
    let case = "sph_sessile_drop";
    let factors = [0.5, 0.75, 1.0];
    let mut angles = Vec::new();
    for &f in &factors {
        // 2D for speed; the 3D drops are tested in tests/adhesion.rs.
        let mut d = SessileDrop::water(Dim::Two, f);
        if quick {
            d.resolution = 8;
            d.capillary_times = 8.0;
        } else {
            d.resolution = 12;
        }
        let r = sessile_drop(&d).expect("sessile drop runs");
        angles.push(r.contact_angle_deg);
    }
    angle_checks(case, &factors, &angles)
}

/// A check that passes when `lo ≤ value < hi`, written as the band check of [`Check`] (the quantity names
/// the band): the reference column shows the centre of the band, the tolerance its half-width (shrunk by 1e-9 relative so that
/// `value = hi` fails: the condition is strict).
fn in_band(case: &str, quantity: String, value: f64, lo: f64, hi: f64, source: &str) -> Check {
    let half = 0.5 * (hi - lo);
    Check::absolute(case, quantity, lo + half, value, half * (1.0 - 1e-9), source)
}

/// The sessile-drop conditions for the angles `angles[k]` [deg] measured at the adhesion factors
/// `factors[k]`: each step up in adhesion lowers θ (θ(f₂) − θ(f₁) in [−180°, 0°)), and θ at the last
/// factor (1: the wall attracts like the liquid itself) is below 90° (θ in [0°, 90°)). The printed
/// "ours" column holds the measured difference or angle.
fn angle_checks(case: &str, factors: &[f64], angles: &[f64]) -> Vec<Check> {
    let mut checks = Vec::new();
    for k in 0..factors.len() - 1 {
        checks.push(in_band(
            case,
            format!(
                "θ({}) − θ({}) in [−180, 0): {:.1}° → {:.1}° [deg]",
                factors[k + 1],
                factors[k],
                angles[k],
                angles[k + 1]
            ),
            angles[k + 1] - angles[k],
            -180.0,
            0.0,
            "contact angle decreases with adhesion",
        ));
    }
    let last = factors.len() - 1;
    checks.push(in_band(
        case,
        format!("θ({}) in [0, 90): wetted [deg]", factors[last]),
        angles[last],
        0.0,
        90.0,
        "a wall attracting like the liquid itself is wetted",
    ));
    checks
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_all_pass(checks: &[Check]) {
        for c in checks {
            eprintln!("{} {}: ref {} ours {} ({:?})", c.case, c.quantity, c.reference, c.ours, c.tolerance);
        }
        for c in checks {
            assert!(
                c.passed(),
                "{} — {}: reference {}, ours {}, tolerance {:?}",
                c.case,
                c.quantity,
                c.reference,
                c.ours,
                c.tolerance
            );
        }
    }

    #[test]
    fn hydrostatic_tank_quick() {
        assert_all_pass(&hydrostatic_tank(true));
    }

    #[test]
    fn poiseuille_quick() {
        assert_all_pass(&poiseuille(true));
    }

    #[test]
    fn conservation_quick() {
        assert_all_pass(&conservation(true));
    }

    #[test]
    fn dam_break_front_quick() {
        assert_all_pass(&dam_break_front(true));
    }

    #[test]
    fn sessile_checks_fail_on_wrong_angles() {
        let f = [0.5, 0.75, 1.0];
        let ok = angle_checks("c", &f, &[103.0, 57.0, 18.0]);
        assert!(ok.iter().all(|c| c.passed()));
        // The printed values are the real difference and angle.
        assert_eq!(ok[0].ours, -46.0);
        assert_eq!(ok[2].ours, 18.0);
        // Rising angle, equal angles (strict), and a non-wetting drop at adhesion 1.
        let bad = angle_checks("c", &f, &[100.0, 120.0, 120.0]);
        assert!(!bad[0].passed() && !bad[1].passed() && !bad[2].passed());
        let edge = angle_checks("c", &f, &[100.0, 95.0, 90.0]);
        assert!(edge[0].passed() && edge[1].passed() && !edge[2].passed(), "θ = 90° is not below 90°");
        assert!(!angle_checks("c", &f, &[100.0, 60.0, f64::NAN])[2].passed());
    }

    #[test]
    fn sessile_drop_quick() {
        assert_all_pass(&sessile_drop_angles(true));
    }

    #[test]
    fn submerged_solid_quick() {
        assert_all_pass(&submerged_solid(true));
    }

    /// The quick wheel through still water (`crate::wheel_wading`): under 2 CPU-minutes.
    #[test]
    fn wheel_wading_quick() {
        assert_all_pass(&crate::wheel_wading::wheel_wading(true));
    }

    #[test]
    fn dam_break_pressure_quick() {
        assert_all_pass(&dam_break_pressure(true));
    }
}
