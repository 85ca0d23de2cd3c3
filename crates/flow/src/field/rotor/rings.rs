//! Vortex rings: the thin ring of Lamb (1932) §161 with a Lamb–Oseen core, its stream function and its
//! velocity in closed form, and the path, strength and core of the rotor's tip-vortex rings against
//! wake age.
//!
//! **Ring.** A ring of circulation Γ and radius a at height z₀ has, at (r, z), with Δz = z − z₀,
//! P = (r + a)² + Δz², Q = (r − a)² + Δz² (Q = squared distance to the core line) and m = 4ra/P,
//!
//! ψ_thin = (Γ/2π) √P [(1 − m/2) K(m) − E(m)],
//! u_z,thin = (1/r) ∂ψ/∂r = Γ/(2π√P) [K + (a² − r² − Δz²) E/Q],
//! u_r,thin = −(1/r) ∂ψ/∂z = Γ Δz/(2π r √P) [−K + (a² + r² + Δz²) E/Q],
//!
//! with K, E the complete elliptic integrals of parameter m (Lamb 1932 §161; the velocity forms as in
//! Saffman 1992, *Vortex Dynamics*, §10.2). Near its core line the thin ring is a 2-D point vortex,
//! ψ_thin ≈ (Γ/2π)√(ra)[ln(8√(ra)/d) − 2] with d = √Q. A Lamb–Oseen core of radius r_c (radius of peak
//! swirl, α = 1.25643, Jasion 2013 eq. 6.14) has the 2-D stream function −(Γ/2π)[ln d + ½E₁(αd²/r_c²)],
//! so the cored ring is
//!
//! ψ = ψ_thin − (Γ/4π) √(ra) E₁(αQ/r_c²),
//!
//! with E₁ the exponential integral: near the core the swirl is Γ/(2πd)(1 − e^(−αd²/r_c²)) and the
//! logarithmic self-induced velocity of the thin ring is cancelled (finite velocity on the core line),
//! far from it (E₁ ~ e^(−x)/x) the thin ring is recovered, and being a stream function it is
//! divergence-free. This is the thin-core form (r_c ≪ a): the correction is dropped where
//! αQ/r_c² > 50 and inboard of r = a/2.
//!
//! **Tip-vortex path** (Jasion 2013 §6.6, eq. 6.11–6.13): a ring of age τ has travelled s = v_c τ
//! (v_c = `vortex_speed_fraction` · v_ind) down the slipstream boundary r = R_w(s), z = z_hub − s, and,
//! in ground effect, beyond the depth where it reaches the path height, radially along the ground. The
//! two legs are blended over ±b of arc length around the corner, b = min(R/10, leg/2), with the quintic
//! smoothstep weight, so that the path (and the field as a function of time) is twice differentiable.
//! Its core radius is r_c² = (r_c0² + 4αδ_v ν τ) R/r_v: Squire's diffusion with δ_v = 1 + a₁Γ_v/ν and
//! Ananthan's strain 1/(1 + ε) with ε = (r_v − R)/R.

use super::super::analytic::LAMB_OSEEN_ALPHA;
use super::special::{elliptic_ke, elliptic_ke_fast, exp_integral_e1, exp_integral_e1_fast, CORE_CUTOFF};
use super::RotorDownwash;
use std::f64::consts::PI;

/// Stokes stream function at (r, z) of a vortex ring of circulation Γ, radius r_v at height z_v with
/// Lamb–Oseen core radius r_c (module documentation) \[m³/s\].
pub fn ring_stream_function(gamma: f64, rv: f64, zv: f64, rc: f64, r: f64, z: f64) -> f64 {
    let dz = z - zv;
    let q = (r - rv) * (r - rv) + dz * dz;
    if q <= 0.0 || r <= 0.0 {
        return 0.0;
    }
    let p = (r + rv) * (r + rv) + dz * dz;
    let m = (4.0 * r * rv / p).min(1.0 - 1e-16);
    let (kk, ee) = elliptic_ke(m);
    let thin = gamma / (2.0 * PI) * p.sqrt() * ((1.0 - 0.5 * m) * kk - ee);
    if r < 0.5 * rv {
        return thin;
    }
    thin - gamma / (4.0 * PI) * (r * rv).sqrt() * exp_integral_e1(LAMB_OSEEN_ALPHA * q / (rc * rc))
}

/// Below this r/r_v the ring velocity takes its value on the axis (u_r = 0): the bracket of u_r,thin
/// vanishes like (r/a)² there and loses digits to cancellation.
const AXIS_FRACTION: f64 = 1e-6;

/// Where a point lies relative to a ring's core line: what the core term of ψ needs.
#[derive(Clone, Copy, Debug)]
struct CoreGeometry {
    /// Squared distance to the core line Q, the point's r, r − a, Δz and Γ/(4π)·√(ra).
    q: f64,
    r: f64,
    r_minus_a: f64,
    dz: f64,
    g_sqrt_ra: f64,
    /// Whether the core correction applies at all (r ≥ a/2).
    cored: bool,
}

impl CoreGeometry {
    /// The geometry of (r, z) for a ring of circulation Γ, radius a = `rv` at height `zv`: on the axis
    /// (r < 10⁻⁶ a) without a core term; on the core line itself a hair (10⁻⁸ a) off it, where the
    /// cored velocity is finite.
    #[inline]
    fn new(gamma: f64, rv: f64, zv: f64, r: f64, z: f64) -> Self {
        let mut dz = z - zv;
        if r < AXIS_FRACTION * rv {
            return CoreGeometry {
                q: rv * rv + dz * dz,
                r,
                r_minus_a: r - rv,
                dz,
                g_sqrt_ra: 0.0,
                cored: false,
            };
        }
        let mut q = (r - rv) * (r - rv) + dz * dz;
        if q < 1e-16 * rv * rv {
            dz += 1e-8 * rv;
            q = (r - rv) * (r - rv) + dz * dz;
        }
        let g = gamma / (2.0 * PI);
        CoreGeometry {
            q,
            r,
            r_minus_a: r - rv,
            dz,
            g_sqrt_ra: 0.5 * g * (r * rv).sqrt(),
            cored: r >= 0.5 * rv,
        }
    }

    /// The velocity of the core term, the curl of ψ_c = −(Γ/4π)√(ra) E₁(αQ/r_c²) for a core of radius
    /// `rc` (zero where it is dropped).
    #[inline]
    fn core_term(&self, rc: f64) -> (f64, f64) {
        let x = LAMB_OSEEN_ALPHA * self.q / (rc * rc);
        if !self.cored || x >= CORE_CUTOFF {
            return (0.0, 0.0);
        }
        let e1 = exp_integral_e1_fast(x);
        let ex_q = (-x).exp() / self.q;
        // ∂ψ_c/∂r = −G [E₁/(2r) − 2(r − a) e^(−x)/Q],  ∂ψ_c/∂z = G · 2Δz e^(−x)/Q,  G = (Γ/4π)√(ra).
        let g = self.g_sqrt_ra;
        let dpsi_dr = -g * (0.5 * e1 / self.r - 2.0 * self.r_minus_a * ex_q);
        let dpsi_dz = g * 2.0 * self.dz * ex_q;
        (-dpsi_dz / self.r, dpsi_dr / self.r)
    }
}

/// The thin-ring velocity at one point and the geometry its core term needs.
#[derive(Clone, Copy, Debug)]
struct Thin {
    ur: f64,
    uz: f64,
    geometry: CoreGeometry,
}

#[inline]
fn thin_ring(gamma: f64, rv: f64, zv: f64, r: f64, z: f64) -> Thin {
    let geometry = CoreGeometry::new(gamma, rv, zv, r, z);
    if r < AXIS_FRACTION * rv {
        // On the axis: u_z = Γ a²/(2 L^{3/2}), u_r = 0; the core correction is zero there.
        let l = geometry.q;
        return Thin { ur: 0.0, uz: gamma * rv * rv / (2.0 * l * l.sqrt()), geometry };
    }
    let (q, dz) = (geometry.q, geometry.dz);
    let p = (r + rv) * (r + rv) + dz * dz;
    let m = (4.0 * r * rv / p).min(1.0 - 1e-16);
    let (kk, ee) = elliptic_ke_fast(m);
    let sp = p.sqrt();
    let g = gamma / (2.0 * PI);
    let uz = g / sp * (kk + (rv * rv - r * r - dz * dz) * ee / q);
    let ur = g * dz / (r * sp) * (-kk + (rv * rv + r * r + dz * dz) * ee / q);
    Thin { ur, uz, geometry }
}

impl Thin {
    /// (u_r, u_z) with a Lamb–Oseen core of radius `rc`: the thin ring plus the core term.
    #[inline]
    fn with_core(&self, rc: f64) -> (f64, f64) {
        let (a, b) = self.geometry.core_term(rc);
        (self.ur + a, self.uz + b)
    }
}

/// Velocity (u_r, u_z) \[m/s\] at (r, z) of a ring of circulation Γ, radius r_v at height z_v with core
/// radius r_c: the closed form of the module documentation (equal to the derivatives of
/// [`ring_stream_function`]).
#[inline]
pub fn ring_velocity(gamma: f64, rv: f64, zv: f64, rc: f64, r: f64, z: f64) -> (f64, f64) {
    thin_ring(gamma, rv, zv, r, z).with_core(rc)
}

/// u(r_c = `rc_a`) − u(r_c = `rc_b`) \[m/s\] of the same ring at (r, z): the thin ring cancels, so only
/// the two core terms are evaluated (no elliptic integrals, and no cancellation of the thin ring's
/// velocity in the difference).
#[inline]
pub fn ring_core_difference(
    gamma: f64,
    rv: f64,
    zv: f64,
    rc_a: f64,
    rc_b: f64,
    r: f64,
    z: f64,
) -> (f64, f64) {
    let geometry = CoreGeometry::new(gamma, rv, zv, r, z);
    let (a, b) = (geometry.core_term(rc_a), geometry.core_term(rc_b));
    (a.0 - b.0, a.1 - b.1)
}

/// One tip-vortex ring: radius, height and core radius \[m\].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ring {
    pub r: f64,
    pub z: f64,
    pub rc: f64,
}

/// The rotor's tip-vortex system with every constant precomputed: path, core growth, circulation and
/// which ages are alive at a given time.
#[derive(Clone, Debug, PartialEq)]
pub struct VortexPath {
    /// Circulation Γ_v \[m²/s\] (the physical ring carries −Γ_v, its ground image +Γ_v).
    pub gamma: f64,
    /// Rotor radius R \[m\].
    pub radius: f64,
    /// Hub height \[m\].
    pub hub_z: f64,
    /// Ground height \[m\] (`None` out of ground effect).
    pub ground_z: Option<f64>,
    /// Convection speed along the path v_c \[m/s\].
    pub speed: f64,
    /// Induced velocity v_ind \[m/s\].
    pub v_ind: f64,
    /// Shedding period 2π/(N_b Ω) \[s\].
    pub period: f64,
    /// Oldest age kept \[s\].
    pub max_age: f64,
    /// Height of the radial leg \[m\].
    pub z_path: f64,
    /// Arc length of the descending leg \[m\] (∞ out of ground effect).
    pub leg: f64,
    /// Slipstream radius at the end of the descending leg \[m\].
    pub r_leg: f64,
    /// Half-width of the blend between the legs \[m\] of arc length.
    pub blend: f64,
    /// Box (r_min, r_max, z_min, z_max) of the path \[m\], widened by its sampling step.
    pub bounds: [f64; 4],
    /// r_c0² \[m²\] and 4αδ_vν \[m²/s\] of the core growth.
    pub rc0_sq: f64,
    pub growth: f64,
}

impl VortexPath {
    pub fn new(rotor: &RotorDownwash) -> Self {
        let gamma = rotor.circulation();
        let nu = rotor.kinematic_viscosity_m2_s;
        let dv = super::squire_delta(rotor.squire_a1, gamma, nu);
        let v_ind = rotor.induced_velocity();
        let z_path = rotor.ground_z_m + rotor.vortex_path_height * rotor.radius_m;
        let leg = if rotor.ground { (rotor.hub_m.z - z_path).max(0.0) } else { f64::INFINITY };
        let rc0 = rotor.core_radius_fraction * rotor.radius_m;
        let mut path = VortexPath {
            gamma,
            radius: rotor.radius_m,
            hub_z: rotor.hub_m.z,
            ground_z: rotor.ground.then_some(rotor.ground_z_m),
            speed: rotor.vortex_speed_fraction * v_ind,
            v_ind,
            period: 2.0 * PI / (rotor.blades as f64 * rotor.omega_rad_s),
            max_age: rotor.vortex_max_age_revs * 2.0 * PI / rotor.omega_rad_s,
            z_path,
            leg,
            r_leg: 0.0,
            blend: 0.0,
            bounds: [0.0; 4],
            rc0_sq: rc0 * rc0,
            growth: 4.0 * LAMB_OSEEN_ALPHA * dv * nu,
        };
        if leg.is_finite() {
            path.r_leg = path.slipstream_radius(leg);
            path.blend = (0.1 * rotor.radius_m).min(0.5 * leg);
        }
        let mut b = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
        const SAMPLES: usize = 1024;
        for k in 0..=SAMPLES {
            let (r, z) = path.position(path.max_age * k as f64 / SAMPLES as f64);
            b = [b[0].min(r), b[1].max(r), b[2].min(z), b[3].max(z)];
        }
        // Between samples the path moves by at most one sampling step of arc length (|dP/ds| ≤ √2).
        let step = 1.5 * path.arc_max() / SAMPLES as f64;
        path.bounds = [b[0] - step, b[1] + step, b[2] - step, b[3] + step];
        path
    }

    /// Slipstream radius R_w = R √(v_ind/|w|) at depth `depth` below the disk, |w| = v_ind(1 + d/√(d² + R²)).
    #[inline]
    pub fn slipstream_radius(&self, depth: f64) -> f64 {
        let r = self.radius;
        r / (1.0 + depth / (depth * depth + r * r).sqrt()).sqrt()
    }

    /// Position (r_v, z_v) of a ring of age `age` \[s\].
    #[inline]
    pub fn position(&self, age: f64) -> (f64, f64) {
        let s = self.speed * age;
        let down = |s: f64| (self.slipstream_radius(s), self.hub_z - s);
        let out = |s: f64| (self.r_leg + (s - self.leg), self.z_path);
        let b = self.blend;
        if s <= self.leg - b {
            down(s)
        } else if s >= self.leg + b {
            out(s)
        } else {
            // Quintic smoothstep w = 6t⁵ − 15t⁴ + 10t³ over the blend.
            let t = (s - (self.leg - b)) / (2.0 * b);
            let w = t * t * t * (t * (6.0 * t - 15.0) + 10.0);
            let (d, o) = (down(s), out(s));
            (d.0 + w * (o.0 - d.0), d.1 + w * (o.1 - d.1))
        }
    }

    /// Core radius r_c \[m\] of a ring of age `age` at radius `rv` (eq. 6.13).
    #[inline]
    pub fn core(&self, age: f64, rv: f64) -> f64 {
        ((self.rc0_sq + self.growth * age) * self.radius / rv).sqrt()
    }

    /// The ring of age `age`.
    #[inline]
    pub fn ring(&self, age: f64) -> Ring {
        let (r, z) = self.position(age);
        Ring { r, z, rc: self.core(age, r) }
    }

    /// Phase φ = t − ⌊t/P⌋P ∈ \[0, P) of time `t`: the rings alive have ages φ + jP ≤ max_age.
    #[inline]
    pub fn phase(&self, t: f64) -> f64 {
        let p = self.period;
        let phi = t - (t / p).floor() * p;
        if phi >= p {
            0.0
        } else {
            phi.max(0.0)
        }
    }

    /// Number of rings alive at phase `phi`: the j ≥ 0 with φ + jP ≤ max_age.
    #[inline]
    pub fn count(&self, phi: f64) -> usize {
        if phi > self.max_age {
            0
        } else {
            ((self.max_age - phi) / self.period).floor() as usize + 1
        }
    }

    /// Velocity (u_r, u_z) at (r, z) of a ring at (r_v, z_v) with core radius `rc` and its ground image.
    /// The tip vortex turns the flow down inboard of its core: circulation −Γ_v; the image has +Γ_v.
    #[inline]
    pub fn ring_and_image(&self, rv: f64, zv: f64, rc: f64, r: f64, z: f64) -> (f64, f64) {
        let (mut ur, mut uz) = ring_velocity(-self.gamma, rv, zv, rc, r, z);
        if let Some(zg) = self.ground_z {
            let (a, b) = ring_velocity(self.gamma, rv, 2.0 * zg - zv, rc, r, z);
            ur += a;
            uz += b;
        }
        (ur, uz)
    }

    /// Vortex velocity (u_r, u_z) at (r, z) of the rings j = 0..`count` at phase `phi` (ages φ + jP) and
    /// their images, each with the core radius `core(ring)` (e.g. the ring's own `rc`).
    pub fn velocity_rings(
        &self,
        phi: f64,
        count: usize,
        r: f64,
        z: f64,
        core: impl Fn(&Ring) -> f64,
    ) -> (f64, f64) {
        let (mut ur, mut uz) = (0.0, 0.0);
        for j in 0..count {
            let ring = self.ring(phi + j as f64 * self.period);
            let (a, b) = self.ring_and_image(ring.r, ring.z, core(&ring), r, z);
            ur += a;
            uz += b;
        }
        (ur, uz)
    }

    /// Arc length along the path at the end of the rings' life v_c·max_age \[m\].
    #[inline]
    pub fn arc_max(&self) -> f64 {
        self.speed * self.max_age
    }

    /// Depth below the disk at which the slipstream radius is `w` (inverse of [`Self::slipstream_radius`]):
    /// 0 for w ≥ R, ∞ for w ≤ R/√2.
    #[inline]
    pub fn slipstream_depth(&self, w: f64) -> f64 {
        let r = self.radius;
        if w >= r {
            return 0.0;
        }
        let y = (r / w) * (r / w) - 1.0;
        if y >= 1.0 {
            return f64::INFINITY;
        }
        y * r / (1.0 - y * y).sqrt()
    }

    /// Disjoint arc-length intervals \[s₀, s₁\] of the path (descending leg, radial leg, merged when they
    /// overlap; empty when s₁ < s₀) that may come within `reach` of (r, z): a superset of the points of
    /// the path closer than `reach`.
    #[inline]
    pub fn arc_windows(&self, r: f64, z: f64, reach: f64) -> [(f64, f64); 2] {
        let s_end = self.arc_max();
        let mut out = [(1.0, 0.0), (1.0, 0.0)];
        let [r0, r1, z0, z1] = self.bounds;
        if r < r0 - reach || r > r1 + reach || z < z0 - reach || z > z1 + reach {
            return out;
        }
        // In the blend the path lies between the two legs' curves, which part by less than √2 times the
        // arc length from the corner (≤ √2 b): widen the reach by 1.5 b.
        let b = self.blend;
        let reach_b = reach + 1.5 * b;
        // Descending leg (to the end of the blend): z_v = z_hub − s and r_v = R_w(s) (decreasing in s).
        let s0 = (self.hub_z - z - reach_b).max(self.slipstream_depth(r + reach_b)).max(0.0);
        let s1 =
            (self.hub_z - z + reach_b).min(self.slipstream_depth(r - reach_b)).min(self.leg + b).min(s_end);
        out[0] = (s0, s1);
        // Radial leg (from the start of the blend): r_v = r_leg + s − leg within reach of r, when z is
        // within reach of its height.
        if self.leg.is_finite() && (z - self.z_path).abs() <= reach_b {
            let s0 = (self.leg + r - self.r_leg - reach_b).max(self.leg - b);
            let s1 = (self.leg + r - self.r_leg + reach_b).min(s_end);
            out[1] = (s0, s1);
        }
        // Overlapping windows (both legs near the corner) are merged, so that no ring is counted twice.
        let [(a0, a1), (b0, b1)] = out;
        if a1 >= a0 && b1 >= b0 && a1 >= b0 && b1 >= a0 {
            out = [(a0.min(b0), a1.max(b1)), (1.0, 0.0)];
        }
        out
    }

    /// Range of ring indices j (at phase `phi`, below `count`) whose core may lie within `reach` of
    /// (r, z) ([`Self::arc_windows`] turned into ages φ + jP); empty ranges have lo > hi.
    #[inline]
    pub fn candidates(&self, phi: f64, count: usize, r: f64, z: f64, reach: f64) -> [(usize, usize); 2] {
        let mut out = [(1, 0), (1, 0)];
        if count == 0 {
            return out;
        }
        for (o, (s0, s1)) in out.iter_mut().zip(self.arc_windows(r, z, reach)) {
            if s1 < s0 {
                continue;
            }
            let a_lo = s0 / self.speed - phi;
            let a_hi = s1 / self.speed - phi;
            if a_hi < 0.0 {
                continue;
            }
            let lo = (a_lo / self.period).ceil().max(0.0);
            let hi = (a_hi / self.period).floor();
            if hi >= lo && lo < count as f64 {
                *o = (lo as usize, (hi as usize).min(count - 1));
            }
        }
        out
    }

    /// Smallest core radius along the path \[m\] (sampled at 257 ages; the core grows by diffusion and
    /// shrinks by stretching).
    pub fn min_core(&self) -> f64 {
        (0..=256).map(|k| self.ring(self.max_age * k as f64 / 256.0).rc).fold(f64::INFINITY, f64::min)
    }

    /// ∫ f(τ) dτ over the ages τ = s/v_c of the arc-length interval \[s₀, s₁\], by 4-point Gauss–Legendre
    /// on panels no longer than `panel` in s, with panel breaks at the ends of the corner blend.
    pub fn integrate_arc(
        &self,
        s0: f64,
        s1: f64,
        panel: f64,
        mut f: impl FnMut(f64) -> (f64, f64),
    ) -> (f64, f64) {
        let mut acc = (0.0, 0.0);
        if s1 <= s0 {
            return acc;
        }
        // Panel breaks where the path changes form (start and end of the blend).
        let cuts = [self.leg - self.blend, self.leg + self.blend];
        let mut pieces = [(s0, s1), (1.0, 0.0), (1.0, 0.0)];
        let (mut n, mut from) = (0, s0);
        for c in cuts {
            if c > from && c < s1 {
                pieces[n] = (from, c);
                n += 1;
                from = c;
            }
        }
        pieces[n] = (from, s1);
        for (a, b) in pieces {
            if b <= a {
                continue;
            }
            let n = ((b - a) / panel).ceil().max(1.0) as usize;
            let h = (b - a) / n as f64;
            for k in 0..n {
                let mid = a + (k as f64 + 0.5) * h;
                for (x, w) in GAUSS_LEGENDRE_4 {
                    let (u, v) = f((mid + 0.5 * h * x) / self.speed);
                    let scale = w * 0.5 * h / self.speed;
                    acc.0 += scale * u;
                    acc.1 += scale * v;
                }
            }
        }
        acc
    }

    /// Time average of the rings' velocity (u_r, u_z) at (r, z): over one shedding period the rings
    /// sweep every age once, so ⟨Σ_j u_j⟩ = (1/P) ∫₀^max_age u(τ) dτ, here with the core radius
    /// `core(ring)`, by [`Self::integrate_arc`] on panels of length `panel`.
    pub fn mean_rings(&self, r: f64, z: f64, panel: f64, core: impl Fn(&Ring) -> f64) -> (f64, f64) {
        let (u, v) = self.integrate_arc(0.0, self.arc_max(), panel, |age| {
            let ring = self.ring(age);
            self.ring_and_image(ring.r, ring.z, core(&ring), r, z)
        });
        (u / self.period, v / self.period)
    }

    /// The tip-vortex fluctuation (u_r, u_z) at (r, z), time `t`, by direct summation: the rings alive
    /// minus their time average (the mean flow already carries the average), [`Self::velocity_rings`]
    /// − [`Self::mean_rings`] on panels of a quarter of the smallest core. The reference the table is
    /// tested against; one call costs a few hundred ring evaluations.
    pub fn velocity_direct(&self, r: f64, z: f64, t: f64) -> (f64, f64) {
        let phi = self.phase(t);
        let (a, b) = self.velocity_rings(phi, self.count(phi), r, z, |ring| ring.rc);
        let (c, d) = self.mean_rings(r, z, 0.25 * self.min_core(), |ring| ring.rc);
        (a - c, b - d)
    }
}

/// Nodes and weights of 4-point Gauss–Legendre quadrature on \[−1, 1\] (Abramowitz & Stegun Table 25.4).
const GAUSS_LEGENDRE_4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thin_ring_speed_on_its_axis() {
        // A thin ring's speed on its axis is Γ r_v²/(2 (r_v² + z²)^(3/2)) (Lamb 1932 §161).
        let (g, rv) = (2.0, 1.0);
        let h = 1e-4;
        let z = 0.7;
        let uz_axis = 2.0 * ring_stream_function(g, rv, 0.0, 1e-3, h, z) / (h * h);
        let expect = g * rv * rv / (2.0 * (rv * rv + z * z).powf(1.5));
        assert!((uz_axis - expect).abs() < 1e-4 * expect, "{uz_axis} vs {expect}");
        let (ur, uz) = ring_velocity(g, rv, 0.0, 1e-3, 0.0, z);
        assert!(ur == 0.0 && (uz - expect).abs() < 1e-12 * expect);
    }

    #[test]
    fn closed_form_velocity_equals_stream_function_derivatives() {
        // u_r = −(1/r)∂ψ/∂z, u_z = (1/r)∂ψ/∂r by central differences of ψ (step 1e-6, error ~1e-9),
        // away from, near and inside the core.
        let (g, rv, zv, rc) = (-6.48, 5.2, 1.4, 0.2);
        for (r, z) in [(3.0, 0.5), (5.0, 1.3), (5.3, 1.45), (5.25, 1.42), (9.0, 4.0), (0.3, 2.0), (5.2, 0.4)]
        {
            let h = 1e-6;
            let psi = |a: f64, b: f64| ring_stream_function(g, rv, zv, rc, a, b);
            let ur_fd = -(psi(r, z + h) - psi(r, z - h)) / (2.0 * h) / r;
            let uz_fd = (psi(r + h, z) - psi(r - h, z)) / (2.0 * h) / r;
            let (ur, uz) = ring_velocity(g, rv, zv, rc, r, z);
            let scale = ur.abs() + uz.abs() + 1e-3;
            assert!((ur - ur_fd).abs() < 1e-6 * scale, "({r}, {z}): u_r {ur} vs {ur_fd}");
            assert!((uz - uz_fd).abs() < 1e-6 * scale, "({r}, {z}): u_z {uz} vs {uz_fd}");
        }
    }

    #[test]
    fn core_difference_equals_the_difference_of_two_cored_rings() {
        // The thin ring cancels: u(r_c) − u(s) from the core terms alone equals the difference of the two
        // full velocities to round-off (10⁻¹² of the larger speed), away from, near, on and inside the
        // core line, inboard of a/2 and on the axis.
        let (g, rv, zv, rc, s) = (-6.48, 5.2, 1.4, 0.2, 0.45);
        let points = [
            (3.0, 0.5),
            (5.0, 1.3),
            (5.3, 1.45),
            (5.25, 1.42),
            (5.2, 1.4),
            (9.0, 4.0),
            (2.0, 1.4),
            (0.0, 2.0),
        ];
        for (r, z) in points {
            let (a, b) = ring_velocity(g, rv, zv, rc, r, z);
            let (c, d) = ring_velocity(g, rv, zv, s, r, z);
            let (dr, dz) = ring_core_difference(g, rv, zv, rc, s, r, z);
            let scale = a.abs().max(b.abs()).max(c.abs()).max(d.abs()).max(1e-3);
            assert!(((a - c) - dr).abs() < 1e-12 * scale, "({r}, {z}): u_r {} vs {dr}", a - c);
            assert!(((b - d) - dz).abs() < 1e-12 * scale, "({r}, {z}): u_z {} vs {dz}", b - d);
        }
        // Inboard of a/2 and on the axis there is no core term: the difference is exactly zero.
        assert_eq!(ring_core_difference(g, rv, zv, rc, s, 2.0, 1.4), (0.0, 0.0));
        assert_eq!(ring_core_difference(g, rv, zv, rc, s, 0.0, 2.0), (0.0, 0.0));
    }

    #[test]
    fn core_is_lamb_oseen_near_the_core_line() {
        // Close to the core line a large ring looks like a 2-D Lamb–Oseen vortex: peak swirl
        // 0.7153 Γ/(2π r_c) at distance r_c (Jasion eq. 6.14), to O(r_c/a) — the ring's self-induced
        // drift is removed by averaging the two points on either side of the core.
        let (g, rv, rc) = (6.48, 50.0, 0.17);
        let expect = 0.71533 * g / (2.0 * PI * rc);
        for (dr, dz) in [(0.0, rc), (rc, 0.0), (0.6 * rc, 0.8 * rc)] {
            let (a1, b1) = ring_velocity(g, rv, 0.0, rc, rv + dr, dz);
            let (a2, b2) = ring_velocity(g, rv, 0.0, rc, rv - dr, -dz);
            let swirl = 0.5 * (a1 - a2).hypot(b1 - b2);
            assert!((swirl / expect - 1.0).abs() < 0.01, "({dr}, {dz}): {swirl} vs {expect}");
        }
        // Finite on the core line: the self-induced speed of a cored ring, Γ/(4πa)(ln(8a/r_c) + O(1))
        // (Saffman 1992 §10.2), below the peak swirl.
        let (ur, uz) = ring_velocity(g, rv, 0.0, rc, rv, 0.0);
        let self_induced = g / (4.0 * PI * rv) * (8.0 * rv / rc).ln();
        assert!(
            ur.abs() < 1e-3 * uz.abs() && uz.abs() > 0.5 * self_induced && uz.abs() < 1.5 * self_induced,
            "{ur} {uz}"
        );
    }
}
