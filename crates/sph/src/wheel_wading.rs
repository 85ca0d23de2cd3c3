//! A wheel rolling through still water (the verification of the wading workflow, `docs/sph.md` §4):
//! a cylinder standing on the floor of a straight channel, its axis across, driven along +x at a
//! constant speed U and turning at ω = U/R, through water shallower than its radius. Measured after the
//! start-up: the bow wave's run-up on the wheel's front, the water's level in the wake behind it and
//! ahead of it, where the water touches the lower mantle, and the force of the water on the wheel.
//!
//! Estimates the case is held against:
//! * **Run-up** — Bernoulli along the stagnation streamline in the wheel's frame: water arriving at the
//!   wheel with the level η_a and the forward speed u_a (both measured a wheel radius ahead of its front)
//!   rises at the stagnation point by `(U − u_a)²/(2g)` over η_a. In a long wide channel η_a = u_a = 0
//!   and this is the velocity head `U²/(2g)`, the classical estimate of the water-level rise at the nose
//!   of a bridge pier.
//! * **Loads** — at Froude number U/√(gh) = 0.71 the pressure on the wheel is taken as hydrostatic under
//!   the run-up on its front (h + η_f) and under the wake's level on its rear (h + η_w), after the
//!   bluff-body picture in which the base pressure is that of the separated wake, not of the thin sheet
//!   the rising tread drags up: horizontally `F_x = −½ ρ g b [(h + η_f)² − (h + η_w)²]`,
//!   vertically the weight of the water column over the wetted lower mantle up to those levels
//!   ([`mantle_lift`]). The mantle meets the floor along a line, and the fluid rests about dp/2 off every
//!   wall, so no water gets into the wedge where the gap between mantle and floor is below about dp;
//!   where the wetted mantle ends on each face is measured in the fluid ([`wet_gap`]).

use crate::kernel::Dim;
use crate::params::SphParams;
use crate::sim::{Simulation, WallOptions};
use crate::wheel_loads::{
    half_chord, hydrostatic_drag, mantle_bin, mantle_lift, wet_gap, G, MANTLE_BINS, RHO,
};
use spatter_core::motion::{Motion, MotionTable};
use spatter_core::validation::Check;
use spatter_core::{Aabb, Vec3};

/// The set-up of [`wheel_through_water`] (SI units).
#[derive(Clone, Copy, Debug)]
pub struct WheelRun {
    /// Wheel radius R \[m\].
    pub radius: f64,
    /// Wheel width b \[m\].
    pub width: f64,
    /// Channel width \[m\]; the wheel runs along its middle.
    pub channel_width: f64,
    /// Still water depth h \[m\] (below R).
    pub depth: f64,
    /// Speed U \[m/s\], reached by a linear start from rest over `ramp` \[s\].
    pub speed: f64,
    pub ramp: f64,
    /// Fluid spacing \[m\].
    pub dp: f64,
    /// End of the run \[s\].
    pub t_end: f64,
    /// Water ahead of the wheel at the end of the run \[m\] (the channel's length follows).
    pub ahead: f64,
    /// Water behind the wheel at the start \[m\].
    pub behind: f64,
}

/// One sample of [`wheel_through_water`]; levels are water surfaces (highest particle centre + dp/2)
/// over the still level h, in the middle half of the wheel's width.
#[derive(Clone, Debug, Default)]
pub struct WheelSample {
    /// Time \[s\].
    pub t: f64,
    /// Axle position along the channel \[m\].
    pub x: f64,
    /// η_f: on the wheel's front (within 1.5 dp of the mantle) \[m\].
    pub front: f64,
    /// η_r: on the wheel's rear (within 1.5 dp of the mantle; water carried up the tread included) \[m\].
    pub rear: f64,
    /// η_w: the wake's level, the mean over the columns dp long between R + 2 dp and 2R behind the axle
    /// of each column's surface \[m\].
    pub wake: f64,
    /// η_a: one radius ahead of the wheel's front (2R ahead of the axle, a column 2 dp long) \[m\].
    pub ahead: f64,
    /// u_a: mean x velocity of the water in that column \[m/s\].
    pub ahead_u: f64,
    /// Fluid particles per 2° bin of the lower mantle ([`mantle_bin`]) whose centres lie within 2 dp of
    /// the mantle, over the wheel's whole width.
    pub shell: Vec<f64>,
    /// Force of the water on the wheel \[N\].
    pub force: Vec3,
}

/// Runs the wheel through the water and samples it every `every` \[s\]. The channel is a tank with an
/// open top, `behind` of water behind the wheel at the start and `ahead` in front of it at the end; the
/// wheel is a closed cylinder mesh (solid sampling, default layers) on a tabulated motion
/// `t vx 0 0 0 ω 0` about its axle, ω = U/R (rolling without slip on the floor).
pub fn wheel_through_water(w: &WheelRun, every: f64) -> Vec<WheelSample> {
    let (dp, r) = (w.dp, w.radius);
    // c₀ = 20 U: ten times a flow speed of up to 2U (the tread's top moves at 2U).
    let mut p = SphParams::water(Dim::Three, dp, 20.0 * w.speed);
    p.gravity = Vec3::new(0.0, 0.0, -G);
    let mut sim = Simulation::new(p);
    let behind = w.behind;
    let travel = w.speed * (w.t_end - 0.5 * w.ramp);
    let length = behind + 2.0 * r + travel + w.ahead;
    let top = (w.depth + 0.6 * r).max(r + 2.0 * dp);
    sim.add_tank(
        "channel",
        Aabb::new(Vec3::ZERO, Vec3::new(length, w.channel_width, top)),
        [true, true, true, true, true, false],
        None,
        None,
        WallOptions::default(),
    );
    let c0 = Vec3::new(behind + r, 0.5 * w.channel_width, r);
    let table = format!("0 0 0 0 0 0 0\n{} {} 0 0 0 {} 0\n", w.ramp, w.speed, w.speed / r);
    let table = MotionTable::parse(&table, c0).expect("a valid motion table");
    let node = sim.add_motion(Motion::Tabulated(table), None);
    // Facets about 2/3 dp wide round the mantle and across it.
    let segments = (1.5 * std::f64::consts::TAU * r / dp).ceil() as usize;
    let rings = (1.5 * w.width / dp).ceil() as usize;
    let mesh = spatter_core::shapes::cylinder(c0, Vec3::Y, r, w.width, segments, rings);
    let k =
        sim.add_mesh("wheel", mesh, None, Some(node), WallOptions::default()).expect("a closed wheel mesh");
    sim.fill_box(Aabb::new(Vec3::ZERO, Vec3::new(length, w.channel_width, w.depth)), Vec3::ZERO, true);
    sim.initialize().expect("validation set-up is valid");
    let level = |z: f64| z + 0.5 * dp - w.depth;
    // Wake columns, dp long, from 2R to R + 2 dp behind the axle.
    let wake_cols = ((r - 2.0 * dp) / dp).floor().max(1.0) as usize;
    let mut out = Vec::new();
    let mut next = every;
    while sim.time < w.t_end {
        sim.step().expect("validation case runs without blow-up");
        if sim.time < next {
            continue;
        }
        next += every;
        let c = sim.boundary.frames[k].to_world(c0);
        let (mut front, mut rear, mut ahead) = (f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        let (mut u_sum, mut n_ahead) = (0.0, 0usize);
        let mut wake = vec![f64::NEG_INFINITY; wake_cols];
        let mut shell = vec![0.0; MANTLE_BINS];
        for (x, v) in sim.fluid.pos.iter().zip(&sim.fluid.vel) {
            let d = *x - c;
            let radial = d.x.hypot(d.z);
            if d.y.abs() <= 0.5 * w.width && radial < r + 2.0 * dp {
                if let Some(i) = mantle_bin(d.z.atan2(d.x)) {
                    shell[i] += 1.0;
                }
            }
            if d.y.abs() > 0.25 * w.width {
                continue;
            }
            if radial < r + 1.5 * dp {
                if d.x > 0.0 {
                    front = front.max(x.z);
                } else {
                    rear = rear.max(x.z);
                }
            }
            let j = (-(d.x + r + 2.0 * dp) / dp).floor();
            if j >= 0.0 && (j as usize) < wake_cols {
                wake[j as usize] = wake[j as usize].max(x.z);
            }
            if (d.x - 2.0 * r).abs() < dp {
                ahead = ahead.max(x.z);
                u_sum += v.x;
                n_ahead += 1;
            }
        }
        let wet: Vec<f64> = wake.into_iter().filter(|z| z.is_finite()).collect();
        out.push(WheelSample {
            t: sim.time,
            x: c.x,
            front: level(front),
            rear: level(rear),
            wake: level(wet.iter().sum::<f64>() / wet.len().max(1) as f64),
            ahead: level(ahead),
            ahead_u: u_sum / n_ahead.max(1) as f64,
            shell,
            force: sim.part_loads()[k].force,
        });
    }
    out
}

/// Means of the samples with `from ≤ t < to`.
fn window(s: &[WheelSample], from: f64, to: f64) -> WheelSample {
    let w: Vec<&WheelSample> = s.iter().filter(|q| q.t >= from && q.t < to).collect();
    let n = w.len().max(1) as f64;
    let mean = |f: &dyn Fn(&WheelSample) -> f64| w.iter().map(|q| f(q)).sum::<f64>() / n;
    WheelSample {
        t: mean(&|q| q.t),
        x: mean(&|q| q.x),
        front: mean(&|q| q.front),
        rear: mean(&|q| q.rear),
        wake: mean(&|q| q.wake),
        ahead: mean(&|q| q.ahead),
        ahead_u: mean(&|q| q.ahead_u),
        shell: (0..MANTLE_BINS).map(|i| mean(&|q| q.shell[i])).collect(),
        force: Vec3::new(mean(&|q| q.force.x), mean(&|q| q.force.y), mean(&|q| q.force.z)),
    }
}

/// The set-up of the validation case at spacing `dp` \[m\].
fn case_run(dp: f64) -> WheelRun {
    WheelRun {
        radius: 0.3,
        width: 0.1,
        channel_width: 0.4,
        depth: 0.2,
        speed: 1.0,
        ramp: 0.1,
        dp,
        t_end: 1.25,
        ahead: 0.6,
        behind: 0.1,
    }
}

/// `sph_wheel_wading`: a wheel R = 0.3 m, b = 0.1 m in a channel 0.4 m wide, water h = 0.2 m deep
/// (h < R), U = 1 m/s (Froude number U/√(gh) = 0.71; velocity head U²/2g = 51 mm), ω = U/R, started
/// over 0.1 s and run for 1.25 s. Sampled every 10 ms; compared over 0.75–1.25 s. The wheel blocks a
/// quarter of the channel's width, more than the 7 % at which the flow past it chokes at this Froude
/// number (critical flow in the contraction beside it: 1.5 (q/σ)^{2/3} g^{-1/3} > h + U²/2g for
/// σ = 0.75), so water piles up ahead of it and runs ahead as a surge; until about 0.75 s the level
/// ahead still rises quickly and the drag with it, so the first half-second is left out:
///
/// * run-up over the level ahead, η_f − η_a, against Bernoulli's (U − u_a)²/(2g); tolerance dp (each of
///   the two surfaces is located to ±dp/2 by its highest particle centre);
/// * F_x and F_z against the hydrostatic loads of the run-up and the wake's level on the wetted mantle
///   (module doc); tolerance the change of those loads when each level moves by dp/2:
///   ρ g b (h + η_f + h + η_w) dp/2 for F_x and ρ g b (s_f + s_w − s_gf − s_gr) dp/2 for F_z (s the
///   half-lengths of the mantle below each level and below each measured end of the wetted mantle);
/// * steadiness: the means over 0.75–1 s and 1–1.25 s within 10 % of each other for F_x and 5 % for
///   F_z.
///
/// Quick: dp = 25 mm (h = 8 dp); full: dp = 12.5 mm. Both leave 0.6 m of water ahead of the wheel at
/// the end: the surge (about 1.6 m/s) reaches the end wall at about 1.2 s and its reflection the wheel
/// after the run. The full variant fails the F_z check (49.9 N against 58.3 N, tolerance 2.5 N;
/// `docs/sph.md` §4, §6): the pressure on the rear face is about half the hydrostatic pressure of the
/// wake's level, so the vertical estimate does not converge; F_x and the other checks pass at both
/// spacings.
pub fn wheel_wading(quick: bool) -> Vec<Check> {
    let w = case_run(if quick { 0.025 } else { 0.0125 });
    let s = wheel_through_water(&w, 0.01);
    wheel_checks(&w, &s)
}

/// The checks of [`wheel_wading`] on the samples `s` of the run `w`.
fn wheel_checks(w: &WheelRun, s: &[WheelSample]) -> Vec<Check> {
    let case = "sph_wheel_wading";
    let (a, b, all) = (window(s, 0.75, 1.0), window(s, 1.0, 1.26), window(s, 0.75, 1.26));
    let (r, h, bw, dp) = (w.radius, w.depth, w.width, w.dp);
    let (hf, hw) = (h + all.front, h + all.wake);
    let (gf, gr) = (wet_gap(r, h, &all.shell, true), wet_gap(r, h, &all.shell, false));
    let fx = hydrostatic_drag(bw, hf, hw);
    let fz = mantle_lift(r, bw, hf, gf) + mantle_lift(r, bw, hw, gr);
    let tol_fx = RHO * G * bw * (hf + hw) * 0.5 * dp;
    let s_wet = half_chord(r, hf) + half_chord(r, hw) - half_chord(r, gf) - half_chord(r, gr);
    let tol_fz = RHO * G * bw * s_wet * 0.5 * dp;
    let du = w.speed - all.ahead_u;
    let label = format!(
        "(mean 0.75–1.25 s: η_f = {:.4} m over the still level against U²/2g = {:.4} m; η_a = {:.4} m, u_a = {:.3} m/s)",
        all.front,
        w.speed * w.speed / (2.0 * G),
        all.ahead,
        all.ahead_u
    );
    let levels = format!(
        "η_f = {:.4} m, η_w = {:.4} m; highest water on the rear η_r = {:.4} m",
        all.front, all.wake, all.rear
    );
    let steady = |x: f64, y: f64| (x - y).abs() / (0.5 * (x + y)).abs();
    let mut checks = vec![
        Check::absolute(
            case,
            format!("run-up over the level ahead η_f − η_a [m] {label}"),
            du * du / (2.0 * G),
            all.front - all.ahead,
            dp,
            "Bernoulli on the stagnation streamline: (U − u_a)²/2g",
        ),
        Check::absolute(
            case,
            format!("F_x, mean 0.75–1.25 s [N] ({levels})"),
            fx,
            all.force.x,
            tol_fx,
            "hydrostatic load of the run-up and the wake's level",
        ),
        Check::absolute(
            case,
            format!(
                "F_z, mean 0.75–1.25 s [N] (wetted mantle down to {:.1} mm on the front, {:.1} mm on the rear)",
                gf * 1e3,
                gr * 1e3
            ),
            fz,
            all.force.z,
            tol_fz,
            "hydrostatic load of the run-up and the wake's level on the wetted lower mantle",
        ),
    ];
    for (name, x, y, tol) in [("F_x", a.force.x, b.force.x, 0.10), ("F_z", a.force.z, b.force.z, 0.05)] {
        checks.push(Check::absolute(
            case,
            format!("{name} steady: |mean 0.75–1 s − mean 1–1.25 s| / mean [-] ({x:.2} / {y:.2} N)"),
            0.0,
            steady(x, y),
            tol,
            "a steady state",
        ));
    }
    checks
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Samples of a steady state whose loads are the hydrostatic estimate of their levels, with the
    /// mantle wetted down to 20 mm on the front and 30 mm on the rear.
    fn steady_samples(w: &WheelRun, force: impl Fn(f64) -> Vec3) -> Vec<WheelSample> {
        let shell: Vec<f64> = (0..MANTLE_BINS)
            .map(|i| {
                let theta =
                    -std::f64::consts::PI + (i as f64 + 0.5) * std::f64::consts::PI / MANTLE_BINS as f64;
                let z = w.radius * (1.0 + theta.sin());
                let end = if theta > -0.5 * std::f64::consts::PI { 0.02 } else { 0.03 };
                if z > end {
                    6.0
                } else {
                    0.0
                }
            })
            .collect();
        (0..=125)
            .map(|i| WheelSample {
                t: 0.01 * i as f64,
                front: 0.06,
                rear: 0.0,
                wake: -0.03,
                ahead: 0.04,
                ahead_u: 0.25,
                shell: shell.clone(),
                force: force(0.01 * i as f64),
                ..WheelSample::default()
            })
            .collect()
    }

    /// The load checks compare with the hydrostatic loads of the run-up and the wake's level on the
    /// mantle wetted down to the measured ends: loads equal to that estimate pass, loads 20 % off fail
    /// at 12.5 mm (3.8 N and 8.3 N off against tolerances of 2.6 N and 2.0 N), and a drag that triples
    /// over the window fails the steadiness check. The run-up check sees 0.02 m against
    /// (1 − 0.25)²/2g = 0.0287 m (tolerance 0.0125 m).
    #[test]
    fn load_checks_compare_with_the_levels_and_can_fail() {
        let w = case_run(0.0125);
        let (h, r, b) = (w.depth, w.radius, w.width);
        let (hf, hw) = (h + 0.06, h - 0.03);
        let fx = hydrostatic_drag(b, hf, hw);
        let gf = wet_gap(r, h, &steady_samples(&w, |_| Vec3::ZERO)[0].shell, true);
        let gr = wet_gap(r, h, &steady_samples(&w, |_| Vec3::ZERO)[0].shell, false);
        assert!((gf - 0.02).abs() < 0.004 && (gr - 0.03).abs() < 0.004, "{gf} {gr}");
        let fz = mantle_lift(r, b, hf, gf) + mantle_lift(r, b, hw, gr);
        let good = wheel_checks(&w, &steady_samples(&w, |_| Vec3::new(fx, 0.0, fz)));
        assert!(good.iter().all(|c| c.passed()), "{good:#?}");
        assert!((good[1].reference - fx).abs() < 1e-9 && (good[2].reference - fz).abs() < 1e-9);
        let off = wheel_checks(&w, &steady_samples(&w, |_| Vec3::new(1.2 * fx, 0.0, 1.2 * fz)));
        assert!(!off[1].passed() && !off[2].passed(), "{off:#?}");
        assert!(off[0].passed() && off[3].passed() && off[4].passed());
        let creeping = wheel_checks(&w, &steady_samples(&w, |t| Vec3::new(fx * (t - 0.5), 0.0, fz)));
        assert!(!creeping[3].passed() && creeping[4].passed(), "{creeping:#?}");
    }
}
