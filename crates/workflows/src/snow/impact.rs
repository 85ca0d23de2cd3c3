//! The single-impact driver: one sphere hits a flat wall, a single sphere (frozen or free) or a bed of
//! frozen spheres, and the run reports stick or bounce.
//!
//! The contact forces come from the DEM engine's contact laws ([`ContactLaw::compute`]), the same code a
//! full DEM run uses; only the integration loop is lean (one particle, one or a few contacts, no
//! neighbour search). Time integration is velocity Verlet (as LIGGGHTS): half kick, drift, forces at the
//! new positions with the half-step velocities, half kick.
//!
//! # Set-up
//!
//! The particle starts exactly at first touch with its impact velocity (the thesis placed it so that the
//! contact began at one fixed time step whatever the speed): contact forms at step 0. The
//! wall normal is +z; the tangential velocity is along +x. For a sphere or a bed the start point is found
//! by sweeping the particle along its straight approach path to the first touching partner.
//!
//! # Outcome
//!
//! The run ends as soon as the outcome is certain:
//!
//! * **bounce** — no contact is left and the particle moves away on a path that meets no partner;
//! * **stick** — the mechanical energy left (kinetic + energy stored in the contacts, minus the motion of
//!   the centre of mass of a free pair) is below the work needed to break every active contact
//!   (Σ U_break; JKR W_neck = 0.935503 F_cδ_c, zero for laws without a neck), with a safety margin, and
//!   the deepest overlap has passed its first maximum (so the maximum overlap is reported). Damping,
//!   friction and breaking only remove energy, so such a particle can never leave;
//! * otherwise at the **check time**, where the particle sticks if a contact is still active (thesis
//!   criterion: the normal overlap persists) and, under [`StickCriterion::StaticTangential`], the contact
//!   point also does not slide.

use super::bed_index::{sweep_hit, BedIndex};
use serde::{Deserialize, Serialize};
use spatter_core::Vec3;
use spatter_dem::contact::{ContactInput, ContactLaw};

/// How a run decides that a particle stuck.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StickCriterion {
    /// A contact is still active at the check time (snow thesis, L483). Default.
    #[default]
    NormalOverlap,
    /// As [`StickCriterion::NormalOverlap`], and the contact point does not slide at the check time
    /// (the particle centre moves tangentially slower than `static_slip_ratio` × the impact speed, so
    /// neither sliding nor rolling): the thesis's originally intended criterion (position unchanged).
    StaticTangential,
}

/// Stick or bounce.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Outcome {
    Stick,
    Bounce,
}

/// Why a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Decision {
    /// All contacts broke and the particle flies away.
    Separated,
    /// The remaining energy cannot break the active contacts.
    Bound,
    /// The check time was reached.
    CheckTime,
}

impl Decision {
    /// Short code for CSV files: 0 separated, 1 bound, 2 check time.
    pub fn code(self) -> f64 {
        match self {
            Decision::Separated => 0.0,
            Decision::Bound => 1.0,
            Decision::CheckTime => 2.0,
        }
    }
}

/// A rigid sphere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    /// Radius \[m\].
    pub radius: f64,
    /// Mass \[kg\].
    pub mass: f64,
}

impl Sphere {
    /// A sphere of diameter `d` \[m\] and density `rho` \[kg/m³\].
    pub fn of_diameter(d: f64, rho: f64) -> Self {
        Sphere { radius: 0.5 * d, mass: rho * std::f64::consts::PI / 6.0 * d * d * d }
    }

    /// Moment of inertia (2/5) m R² \[kg m²\].
    pub fn inertia(&self) -> f64 {
        0.4 * self.mass * self.radius * self.radius
    }
}

/// A frozen sphere of a rough wall.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BedSphere {
    /// Centre \[m\].
    pub centre: [f64; 3],
    /// Radius \[m\].
    pub radius: f64,
}

/// What the particle hits.
#[derive(Clone, Copy, Debug)]
pub enum Target<'a> {
    /// The flat wall z = 0 (particle–wall).
    Plane,
    /// One sphere centred at the origin: frozen (infinite mass, a wall sphere) or free (particle–particle,
    /// initially at rest).
    Sphere { radius: f64, free_mass: Option<f64> },
    /// A bed of frozen spheres below z = `top` (rough wall); the particle comes from above. `index` is the
    /// cell list of `spheres` ([`BedIndex::new`]), built once per bed.
    Bed { spheres: &'a [BedSphere], top: f64, index: &'a BedIndex },
}

/// One impact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impact {
    /// The moving particle.
    pub particle: Sphere,
    /// Normal approach speed v_n > 0 \[m/s\] (towards the wall, along −z).
    pub normal_speed: f64,
    /// Tangential speed v_t ≥ 0 \[m/s\] along +x.
    pub tangential_speed: f64,
    /// Lateral aim point (x, y) \[m\] of the approach path (bed and sphere targets).
    pub aim: [f64; 2],
}

/// Integration and classification settings of one run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriverSettings {
    /// Time step \[s\].
    pub dt: f64,
    /// Time after first touch at which the outcome is read \[s\].
    pub check_time: f64,
    /// Stick criterion.
    pub criterion: StickCriterion,
    /// Slip speed below which a contact counts as static, as a fraction of the impact speed.
    pub static_slip_ratio: f64,
    /// Relative safety margin of the energy test for an early stick decision (e.g. 0.01).
    pub bound_margin: f64,
    /// Evaluate velocity-dependent forces with velocities predicted to the end of the step (second-order
    /// accurate dashpots) instead of the half-step velocities of plain velocity Verlet (LIGGGHTS).
    pub predict_velocity: bool,
}

/// The result of one impact.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ImpactResult {
    pub outcome: Outcome,
    pub decision: Decision,
    /// Particle velocity at the end (relative to a free partner) \[m/s\].
    pub rebound_velocity: [f64; 3],
    /// Realised normal restitution: rebound normal speed / impact normal speed (0 when stuck).
    pub restitution: f64,
    /// Largest overlap over all contacts up to the end of the run \[m\]. A run never ends before the
    /// deepest overlap has passed its first maximum, so for sticks too this is at least the peak of the
    /// first compression (on a flat wall or a single sphere the largest overlap of the whole impact: the
    /// normal energy only decreases after it).
    pub max_overlap: f64,
    /// Time from first touch to the last contact break \[s\]; for a stuck particle the time simulated
    /// (to the early decision or the check time).
    pub contact_duration: f64,
    /// Slip speed of the contact point at the end \[m/s\].
    pub slip_speed: f64,
    /// Tangential speed of the particle centre (relative to the partner) at the end \[m/s\].
    pub tangential_speed: f64,
    /// Time steps integrated.
    pub steps: u64,
    /// Kinetic energy of the rebound (translation and rotation of the relative motion) over that of the
    /// impact, for a bounce; 0 for a stick. Damping, friction and the adhesive neck only remove energy, so
    /// a value above 1 means the integration created energy (see [`ImpactResult::created_energy`]).
    pub energy_ratio: f64,
}

/// Relative energy gain above which a bounce counts as a numerical failure: 1e-3, five times the largest
/// gain of an elastic (e = 1) Hertz or JKR impact integrated with Δt = t_H/20 (the warning fraction of the
/// time-step guard, measured 1.9e-4 over d = 10–100 µm and v_n = 0.5–32 m/s), so settings the guard
/// accepts silently never trip it.
pub const ENERGY_GAIN_TOLERANCE: f64 = 1e-3;

impl ImpactResult {
    /// Whether the particle left with more kinetic energy than it came with (by more than
    /// [`ENERGY_GAIN_TOLERANCE`]): energy created by the integration, a numerical failure (time step too
    /// large). For a normal impact on a flat wall this is a realised restitution above √1.001 ≈ 1.0005.
    pub fn created_energy(&self) -> bool {
        self.outcome == Outcome::Bounce && self.energy_ratio > 1.0 + ENERGY_GAIN_TOLERANCE
    }
}

/// Geometry of a contact seen from the particle.
#[derive(Clone, Copy)]
struct Geom {
    n: Vec3,
    overlap: f64,
    r_partner: f64,
}

/// One active contact: partner index, law state, energy needed to break it.
struct Slot<S> {
    id: usize,
    state: S,
    u_break: f64,
}

/// The state of the moving bodies.
#[derive(Clone, Copy)]
struct Bodies {
    x: Vec3,
    v: Vec3,
    w: Vec3,
    /// Free partner (sphere target only).
    xp: Vec3,
    vp: Vec3,
    wp: Vec3,
}

/// Forces and torques on particle (f, t) and partner (fp, tp).
#[derive(Clone, Copy, Default)]
struct Loads {
    f: Vec3,
    t: Vec3,
    fp: Vec3,
    tp: Vec3,
    energy: f64,
    u_break: f64,
    max_overlap: f64,
    slip: f64,
    /// Sum of the signed normal forces of all contacts \[N\] and the largest overlap of an active contact
    /// (−∞ without contacts), for traces.
    normal_force: f64,
    active_overlap: f64,
}

/// One time step of a traced impact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TracePoint {
    /// Time since first touch \[s\].
    pub t: f64,
    /// Largest overlap of an active contact \[m\] (`None` without contact).
    pub overlap: Option<f64>,
    /// Sum of the signed normal contact forces on the particle \[N\] (positive repulsive).
    pub normal_force: f64,
    /// Particle centre \[m\] and velocity \[m/s\] (relative to a free partner).
    pub position: [f64; 3],
    pub velocity: [f64; 3],
    /// Active contacts.
    pub contacts: usize,
}

/// Runs one impact with contact law `law` and its pair parameters `params`.
///
/// `break_energy(r_eff)` is the energy \[J\] needed to break a freshly formed contact of effective radius
/// `r_eff` (JKR neck work; 0 for laws without a neck). With `trace`, every step is recorded and the run
/// continues to the check time (no early decision), so the whole history is seen.
pub fn run_impact<L: ContactLaw>(
    law: &L,
    params: &L::Params,
    break_energy: &dyn Fn(f64) -> f64,
    target: Target<'_>,
    imp: &Impact,
    s: &DriverSettings,
    mut trace: Option<&mut Vec<TracePoint>>,
) -> ImpactResult {
    let p = imp.particle;
    let r = p.radius;
    let m = p.mass;
    let inertia = p.inertia();
    let v0 = Vec3::new(imp.tangential_speed, 0.0, -imp.normal_speed);
    let speed0 = v0.length();
    let (free_mass, partner_radius) = match target {
        Target::Sphere { radius, free_mass } => (free_mass, radius),
        _ => (None, 0.0),
    };
    let partner_inertia = free_mass.map(|mp| 0.4 * mp * partner_radius * partner_radius);

    // Start at first touch.
    let x0 = start_position(target, r, imp.aim, v0);
    let mut b = Bodies { x: x0, v: v0, w: Vec3::ZERO, xp: Vec3::ZERO, vp: Vec3::ZERO, wp: Vec3::ZERO };
    // Kinetic energy of the relative motion (the centre of mass of a free pair keeps its energy) plus
    // `stored` \[J\].
    let energy = |b: &Bodies, stored: f64| -> f64 {
        let mut e = 0.5 * m * b.v.length_squared() + 0.5 * inertia * b.w.length_squared() + stored;
        if let (Some(mp), Some(ip)) = (free_mass, partner_inertia) {
            let vcm = (m * b.v + mp * b.vp) / (m + mp);
            e += 0.5 * mp * b.vp.length_squared() + 0.5 * ip * b.wp.length_squared()
                - 0.5 * (m + mp) * vcm.length_squared();
        }
        e
    };
    let kinetic0 = energy(&b, 0.0);

    let mut slots: Vec<Slot<L::State>> = Vec::with_capacity(4);
    let r_eff_of = |rp: f64| if rp.is_infinite() { r } else { r * rp / (r + rp) };
    let max_bed_radius = match target {
        Target::Bed { index, .. } => index.max_radius(),
        _ => 0.0,
    };
    let bed_range = law.range(params, r_eff_of(max_bed_radius.max(1e-300)));
    let bed_reach = r + max_bed_radius + bed_range;
    // Range and break energy depend on the partner radius only: computed once per distinct radius (every
    // partner of a run usually has the same one), not per contact visit.
    let per_radius = std::cell::Cell::new((f64::NAN, 0.0, 0.0));
    let radius_consts = |rp: f64| -> (f64, f64) {
        let (last, range, u_break) = per_radius.get();
        if last == rp {
            return (range, u_break);
        }
        let r_eff = r_eff_of(rp);
        let v = (law.range(params, r_eff), break_energy(r_eff));
        per_radius.set((rp, v.0, v.1));
        v
    };

    // Candidate bed spheres near the particle (a Verlet list with a skin of one bed-sphere diameter),
    // rebuilt when the particle has moved by half the skin.
    let mut candidates: Vec<usize> = Vec::new();
    let mut list_centre = Vec3::splat(f64::INFINITY);
    let list_skin = (2.0 * max_bed_radius).max(1e-3 * r);

    let dt = s.dt;
    let compute = |b: &Bodies,
                   slots: &mut Vec<Slot<L::State>>,
                   candidates: &mut Vec<usize>,
                   lc: &mut Vec3| {
        let mut l = Loads { active_overlap: f64::NEG_INFINITY, ..Loads::default() };
        let mut visit = |id: usize, g: Geom, slots: &mut Vec<Slot<L::State>>| {
            let pos = slots.iter().position(|sl| sl.id == id);
            let r_eff = r_eff_of(g.r_partner);
            let (range, u_break) = radius_consts(g.r_partner);
            if pos.is_none() && g.overlap < -range {
                return;
            }
            let (partner_v, partner_w, i_eff) = match (free_mass, partner_inertia) {
                (Some(_), Some(ip)) => (b.vp, b.wp, 1.0 / (1.0 / inertia + 1.0 / ip)),
                _ => (Vec3::ZERO, Vec3::ZERO, inertia),
            };
            let m_eff = match free_mass {
                Some(mp) => m * mp / (m + mp),
                None => m,
            };
            let v_rel = b.v + b.w.cross(-r * g.n)
                - (partner_v
                    + partner_w.cross(if g.r_partner.is_finite() { g.r_partner * g.n } else { Vec3::ZERO }));
            let input = ContactInput {
                normal: g.n,
                overlap: g.overlap,
                r_eff,
                radius_sum: if g.r_partner.is_finite() { r + g.r_partner } else { r },
                m_eff,
                i_eff,
                v_rel,
                w_rel: b.w - partner_w,
                dt,
            };
            let idx = match pos {
                Some(i) => i,
                None => {
                    slots.push(Slot { id, state: L::State::default(), u_break });
                    slots.len() - 1
                }
            };
            match law.compute(params, &input, &mut slots[idx].state) {
                Some(out) => {
                    let ft = out.tangential_force(g.n);
                    l.f += out.force;
                    l.t += (-r * g.n).cross(ft) + out.rolling_torque;
                    if g.r_partner.is_finite() {
                        l.fp -= out.force;
                        l.tp += -(g.r_partner * g.n).cross(ft) - out.rolling_torque;
                    }
                    l.energy += out.energy;
                    l.u_break += slots[idx].u_break;
                    l.max_overlap = l.max_overlap.max(g.overlap);
                    l.active_overlap = l.active_overlap.max(g.overlap);
                    l.normal_force += out.normal_force;
                    let vt = v_rel - v_rel.dot(g.n) * g.n;
                    l.slip = l.slip.max(vt.length());
                }
                None => {
                    slots.swap_remove(idx);
                }
            }
        };
        match target {
            Target::Plane => {
                visit(0, Geom { n: Vec3::Z, overlap: r - b.x.z, r_partner: f64::INFINITY }, slots);
            }
            Target::Sphere { radius, .. } => {
                let d = b.x - b.xp;
                let dist = d.length();
                visit(0, Geom { n: d / dist, overlap: r + radius - dist, r_partner: radius }, slots);
            }
            Target::Bed { spheres, index, .. } => {
                if (b.x - *lc).length() > 0.5 * list_skin {
                    // Verlet list from the cell list: only the cells around the particle are searched.
                    *lc = b.x;
                    candidates.clear();
                    let reach = bed_reach + list_skin;
                    index.for_each_in_box(b.x - Vec3::splat(reach), b.x + Vec3::splat(reach), |i| {
                        if (b.x - Vec3::from(spheres[i].centre)).length_squared() < reach * reach {
                            candidates.push(i);
                        }
                    });
                    // Cell order differs from index order; visiting in index order keeps the results
                    // independent of the search structure.
                    candidates.sort_unstable();
                }
                for &i in candidates.iter() {
                    let q = spheres[i];
                    let d = b.x - Vec3::from(q.centre);
                    let dist = d.length();
                    if dist < r + q.radius + bed_reach && dist > 0.0 {
                        visit(
                            i,
                            Geom { n: d / dist, overlap: r + q.radius - dist, r_partner: q.radius },
                            slots,
                        );
                    }
                }
            }
        }
        l
    };

    let mut loads = compute(&b, &mut slots, &mut candidates, &mut list_centre);
    let mut max_overlap = loads.max_overlap;
    let record = |trace: &mut Option<&mut Vec<TracePoint>>, t: f64, b: &Bodies, l: &Loads, n: usize| {
        if let Some(tr) = trace.as_deref_mut() {
            tr.push(TracePoint {
                t,
                overlap: (n > 0).then_some(l.active_overlap),
                normal_force: l.normal_force,
                position: (b.x - b.xp).to_array(),
                velocity: (b.v - b.vp).to_array(),
                contacts: n,
            });
        }
    };
    record(&mut trace, 0.0, &b, &loads, slots.len());
    let tracing = trace.is_some();
    let mut flight: Option<FreeFlight> = None;
    let mut last_contact_time = 0.0;
    let mut t = 0.0;
    let max_steps = (s.check_time / dt).ceil().max(1.0) as u64;
    let mut decision = Decision::CheckTime;
    let mut steps = 0u64;
    let needs_static = s.criterion == StickCriterion::StaticTangential
        && !(imp.tangential_speed == 0.0 && matches!(target, Target::Plane));
    // The early "bound" decision waits until the deepest active overlap has passed its first maximum, so
    // `max_overlap` of a stick is the peak of the first compression (a slow grain is provably bound
    // right after first touch, long before it reaches its deepest overlap).
    let mut peaked = false;
    let mut last_overlap = loads.active_overlap;

    while steps < max_steps {
        // Velocity Verlet.
        b.v += 0.5 * dt / m * loads.f;
        b.w += 0.5 * dt / inertia * loads.t;
        if let (Some(mp), Some(ip)) = (free_mass, partner_inertia) {
            b.vp += 0.5 * dt / mp * loads.fp;
            b.wp += 0.5 * dt / ip * loads.tp;
            b.xp += dt * b.vp;
        }
        b.x += dt * b.v;
        loads = if s.predict_velocity {
            // Forces at t + Δt with velocities predicted to t + Δt (second order for the dashpots).
            let mut bp = b;
            bp.v += 0.5 * dt / m * loads.f;
            bp.w += 0.5 * dt / inertia * loads.t;
            if let (Some(mp), Some(ip)) = (free_mass, partner_inertia) {
                bp.vp += 0.5 * dt / mp * loads.fp;
                bp.wp += 0.5 * dt / ip * loads.tp;
            }
            compute(&bp, &mut slots, &mut candidates, &mut list_centre)
        } else {
            compute(&b, &mut slots, &mut candidates, &mut list_centre)
        };
        b.v += 0.5 * dt / m * loads.f;
        b.w += 0.5 * dt / inertia * loads.t;
        if let (Some(mp), Some(ip)) = (free_mass, partner_inertia) {
            b.vp += 0.5 * dt / mp * loads.fp;
            b.wp += 0.5 * dt / ip * loads.tp;
        }
        steps += 1;
        t += dt;
        record(&mut trace, t, &b, &loads, slots.len());
        max_overlap = max_overlap.max(loads.max_overlap);
        peaked |= loads.active_overlap < last_overlap;
        last_overlap = loads.active_overlap;
        if !slots.is_empty() {
            last_contact_time = t;
            let e = energy(&b, loads.energy);
            if peaked
                && !needs_static
                && e < loads.u_break - s.bound_margin * loads.u_break.abs().max(f64::MIN_POSITIVE)
            {
                decision = Decision::Bound;
                break;
            }
        } else if !tracing && receding(target, &b, r, bed_range, &mut flight) {
            decision = Decision::Separated;
            break;
        }
    }

    let rel_v = b.v - b.vp;
    let wall_normal = match target {
        Target::Sphere { .. } => (b.x - b.xp).normalize(),
        _ => Vec3::Z,
    };
    let tangential_speed = (rel_v - rel_v.dot(wall_normal) * wall_normal).length();
    let stuck = match decision {
        Decision::Separated => false,
        Decision::Bound => true,
        Decision::CheckTime => {
            !slots.is_empty()
                && (s.criterion == StickCriterion::NormalOverlap
                    || tangential_speed <= s.static_slip_ratio * speed0.max(f64::MIN_POSITIVE))
        }
    };
    let normal_out = rel_v.dot(wall_normal);
    ImpactResult {
        outcome: if stuck { Outcome::Stick } else { Outcome::Bounce },
        decision,
        rebound_velocity: rel_v.to_array(),
        restitution: if stuck { 0.0 } else { normal_out.max(0.0) / imp.normal_speed },
        max_overlap,
        contact_duration: if stuck { t } else { last_contact_time },
        slip_speed: loads.slip,
        tangential_speed,
        steps,
        energy_ratio: if stuck { 0.0 } else { energy(&b, 0.0) / kinetic0 },
    }
}

/// The first bed hit ahead of a particle in free flight: velocity and position when it was searched and
/// the distance to it \[m\]. While the velocity stays the same (no contact, no force) and the particle has
/// not yet covered that distance, the answer stands and the search is not repeated.
#[derive(Clone, Copy)]
struct FreeFlight {
    v: Vec3,
    x: Vec3,
    hit: f64,
}

/// Whether a particle without contacts is moving away for good; `range` is the largest gap at which a
/// bed contact can act. On a bed the straight path ahead is searched through the bed's cell list once per
/// free flight (`flight` caches the result), so the cost does not grow with the bed.
fn receding(target: Target<'_>, b: &Bodies, r: f64, range: f64, flight: &mut Option<FreeFlight>) -> bool {
    match target {
        Target::Plane => b.v.z > 0.0,
        Target::Sphere { .. } => (b.v - b.vp).dot(b.x - b.xp) > 0.0,
        Target::Bed { spheres, top, index } => {
            if b.v.z <= 0.0 {
                return false;
            }
            if b.x.z - r > top + range {
                return true;
            }
            if let Some(f) = *flight {
                if f.v == b.v && (b.x - f.x).length() < f.hit {
                    return false;
                }
            }
            // The straight path ahead must not come within range of any bed sphere.
            match index.first_hit(spheres, b.x, b.v.normalize(), r + range) {
                None => true,
                Some((hit, _)) => {
                    *flight = Some(FreeFlight { v: b.v, x: b.x, hit });
                    false
                }
            }
        }
    }
}

/// Position of first touch along the approach path through the aim point.
fn start_position(target: Target<'_>, r: f64, aim: [f64; 2], v0: Vec3) -> Vec3 {
    match target {
        Target::Plane => Vec3::new(aim[0], aim[1], r),
        Target::Sphere { radius, .. } => {
            let u = v0.normalize();
            let far = Vec3::new(aim[0], aim[1], 0.0) - u * (10.0 * (r + radius));
            match sweep_hit(far, u, Vec3::ZERO, r + radius) {
                Some(s) => touch(far + u * s, Vec3::ZERO, r + radius),
                // A miss: start level with the sphere's top, the particle passes by.
                None => far,
            }
        }
        Target::Bed { spheres, top, index } => {
            let u = v0.normalize();
            let lift = (top + 2.0 * r) / (-u.z).max(1e-3);
            let far = Vec3::new(aim[0], aim[1], 0.0) - u * lift;
            match index.first_hit(spheres, far, u, r) {
                Some((s, i)) => {
                    let q = spheres[i];
                    touch(far + u * s, Vec3::from(q.centre), r + q.radius)
                }
                None => Vec3::new(aim[0], aim[1], r),
            }
        }
    }
}

/// Nudges `x` towards `c` until the overlap rr − |x − c| is not negative (rounding of the sweep).
fn touch(mut x: Vec3, c: Vec3, rr: f64) -> Vec3 {
    for _ in 0..8 {
        let d = x - c;
        let gap = d.length() - rr;
        if gap <= 0.0 {
            break;
        }
        x -= d.normalize() * (gap + rr * f64::EPSILON);
    }
    x
}
