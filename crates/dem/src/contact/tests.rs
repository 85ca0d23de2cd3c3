//! Kernel-level tests: one contact driven directly, without the engine.

use super::*;
use spatter_core::material::Material;
use spatter_core::Vec3;
use std::f64::consts::PI;

fn input(overlap: f64, v_rel: Vec3, r_eff: f64, m_eff: f64, dt: f64) -> ContactInput {
    ContactInput {
        normal: Vec3::Z,
        overlap,
        r_eff,
        radius_sum: r_eff,
        m_eff,
        i_eff: 0.4 * m_eff * r_eff * r_eff,
        v_rel,
        w_rel: Vec3::ZERO,
        dt,
    }
}

/// Head-on impact of a sphere (radius r, mass m) on a rigid flat wall at speed v0, velocity Verlet with
/// `steps_per_contact` steps per Hertz contact time. Returns (F_max, δ_max, t_c, e).
fn wall_impact<L: ContactLaw>(
    law: &L,
    props: &PairProps,
    r: f64,
    m: f64,
    v0: f64,
    steps: f64,
) -> (f64, f64, f64, f64) {
    let p = law.params(0, props);
    let tc = spatter_core::timestep::hertz_time(m, r, props.e_star, v0);
    let dt = tc / steps;
    // Gap z (centre height − r): start just touching, approaching.
    let (mut z, mut v) = (0.0f64, -v0);
    let mut s = L::State::default();
    let (mut fmax, mut dmax, mut t, mut t_end) = (0.0f64, 0.0f64, 0.0, None);
    let mut f = 0.0;
    for _ in 0..(10.0 * steps) as usize {
        v += 0.5 * dt * f / m;
        z += v * dt;
        t += dt;
        let c = input(-z, Vec3::new(0.0, 0.0, v), r, m, dt);
        f = match law.compute(&p, &c, &mut s) {
            Some(o) => o.force.z,
            None => {
                s = L::State::default();
                0.0
            }
        };
        v += 0.5 * dt * f / m;
        fmax = fmax.max(f);
        dmax = dmax.max(-z);
        if z > 0.0 && v > 0.0 && t_end.is_none() {
            t_end = Some(t);
            break;
        }
    }
    (fmax, dmax, t_end.unwrap_or(f64::NAN), v / v0)
}

fn glass() -> Material {
    Material::new(48e9, 0.2, 2800.0).unwrap()
}

fn rigid(nu: f64) -> Material {
    Material::new(f64::INFINITY, nu, 1000.0).unwrap()
}

#[test]
fn elastic_hertz_impact_matches_closed_forms() {
    // Closed forms of Chung & Ooi (2011), Eq. 1–3, sphere on a rigid wall; 1 % tolerance
    // as in the reference table. R = 0.1, v = 0.2, Al alloy (test 2).
    let al = Material::new(70e9, 0.3, 2699.0).unwrap();
    let props = PairProps::new(&al, &rigid(0.3), 0.0, 1.0);
    let (r, v0) = (0.1, 0.2);
    let m = al.density * 4.0 / 3.0 * PI * r * r * r;
    let e_star = props.e_star;
    let d_max = (15.0 * m * v0 * v0 / (16.0 * e_star * r.sqrt())).powf(0.4);
    let f_max = 4.0 / 3.0 * e_star * r.sqrt() * d_max.powf(1.5);
    let law: Composed<Hertz, NoDamping, Frictionless, NoRolling> = Composed::default();
    let (f, d, t, e) = wall_impact(&law, &props, r, m, v0, 200.0);
    let tc = spatter_core::timestep::hertz_time(m, r, e_star, v0);
    assert!((f / f_max - 1.0).abs() < 0.01, "F_max {f} vs {f_max}");
    assert!((d / d_max - 1.0).abs() < 0.01, "δ_max {d} vs {d_max}");
    assert!((t / tc - 1.0).abs() < 0.01, "t_c {t} vs {tc}");
    assert!((e - 1.0).abs() < 1e-3, "elastic e {e}");
    // Chung & Ooi (2011) test 2 numbers for Al: 11.37 kN, 49.72 µm, 731.7 µs.
    assert!(
        (f / 11.37e3 - 1.0).abs() < 0.01
            && (d / 49.72e-6 - 1.0).abs() < 0.01
            && (t / 731.7e-6 - 1.0).abs() < 0.01
    );
}

#[test]
fn calibrated_damping_realises_the_input_restitution_with_and_without_clamp() {
    // Chung & Ooi (2011) test 3: e_out = e_in. Tolerance 0.5 % at 400 steps per contact (the
    // time discretisation error of velocity Verlet with a velocity-dependent force).
    for clamp in [true, false] {
        for e_in in [0.2, 0.5, 0.8] {
            let law = Composed::new(
                Hertz,
                RestitutionDamping { tensile_clamp: clamp, ..Default::default() },
                Frictionless,
                NoRolling,
            );
            let props = PairProps::new(&glass(), &rigid(0.2), 0.0, e_in);
            let m = 2800.0 * 4.0 / 3.0 * PI * 1e-6;
            let (_, _, _, e) = wall_impact(&law, &props, 0.01, m, 3.9, 400.0);
            assert!((e / e_in - 1.0).abs() < 0.005, "clamp {clamp}: e_in {e_in} → e_out {e}");
        }
    }
}

#[test]
fn linearised_damping_with_clamp_shows_the_known_restitution_shift() {
    // Known effect of a tensile clamp: closed-form damping with the clamp gives e_in = 0.5 → e_out ≈ 0.55.
    let law = Composed::new(
        Hertz,
        RestitutionDamping { calibration: RestitutionCalibration::Linearised, ..Default::default() },
        Frictionless,
        NoRolling,
    );
    let props = PairProps::new(&glass(), &rigid(0.2), 0.0, 0.5);
    let m = 2800.0 * 4.0 / 3.0 * PI * 1e-6;
    let (_, _, _, e) = wall_impact(&law, &props, 0.01, m, 3.9, 400.0);
    assert!((e - 0.55).abs() < 0.01, "{e}");
}

#[test]
fn tangential_history_rotates_with_the_contact_and_keeps_its_length() {
    let props = PairProps::new(&glass(), &glass(), 0.5, 1.0);
    let law: HertzMindlin = Composed::new(Hertz, RestitutionDamping::default(), Mindlin, NoRolling);
    let p = law.params(0, &props);
    let mut s = <HertzMindlin as ContactLaw>::State::default();
    let dt = 1e-7;
    let mut c = input(1e-5, Vec3::new(1e-3, 0.0, 0.0), 0.005, 1e-3, dt);
    c.v_rel = Vec3::new(0.01, 0.0, 0.0);
    law.compute(&p, &c, &mut s).unwrap();
    let before = s.tangential.xi.length();
    assert!(before > 0.0);
    // Rotate the contact normal by 30° about y with no further sliding.
    let q = spatter_core::Quat::from_axis_angle(Vec3::Y, 30f64.to_radians());
    c.normal = q * Vec3::Z;
    c.v_rel = Vec3::ZERO;
    let out = law.compute(&p, &c, &mut s).unwrap();
    assert!(s.tangential.xi.dot(c.normal).abs() < 1e-15 * before.max(1e-300) + 1e-20);
    assert!((s.tangential.xi.length() / before - 1.0).abs() < 1e-12);
    assert!(out.tangential_force(c.normal).dot(c.normal).abs() < 1e-9);
}

#[test]
fn coulomb_cap_holds_and_a_cycle_never_injects_energy() {
    // Drive a Hertz–Mindlin contact through random cycles of normal load and tangential motion that end
    // where they started (δ back to its start, net tangential displacement zero). The work the contact
    // does on the particles over the cycle, ∮F·v dt, must not be positive (no energy injection), and
    // |F_t| ≤ μ F_n at every step.
    let props = PairProps::new(&glass(), &glass(), 0.3, 0.7);
    for law_damped in [true, false] {
        let damping = RestitutionDamping { tangential: law_damped, ..Default::default() };
        let law = Composed::new(Hertz, damping, Mindlin, NoRolling);
        let p = law.params(0, &props);
        let mut rng = spatter_core::rng::seeded(7, law_damped as u64);
        use spatter_core::rng::RngExt;
        for _cycle in 0..20 {
            let mut s = <HertzMindlin as ContactLaw>::State::default();
            let n_steps = 2000;
            let dt = 1e-7;
            let (a_n, a_x, a_y): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
            // Integer frequencies: every signal returns to its start value at t = 1.
            let fx = rng.random_range(1..4) as f64;
            let fy = rng.random_range(1..4) as f64;
            let mut work = 0.0;
            let mut e_scale = 0.0f64;
            for k in 0..n_steps {
                let t = (k as f64 + 0.5) / n_steps as f64;
                let ph = 2.0 * PI * t;
                // δ(t) = δ0 (1 + a sin) stays positive; tangential displacement periodic.
                let d0 = 2e-6;
                let overlap = d0 * (1.0 + 0.9 * a_n * (fx * ph).sin());
                let vdn = -d0 * 0.9 * a_n * fx * 2.0 * PI * (fx * ph).cos() / (n_steps as f64 * dt);
                let amp = 5e-6;
                let vx = amp * a_x * 2.0 * PI * (ph).cos() / (n_steps as f64 * dt);
                let vy = amp * a_y * 2.0 * PI * fy * (fy * ph).cos() / (n_steps as f64 * dt);
                let v = Vec3::new(vx, vy, vdn);
                let c = input(overlap, v, 0.005, 1e-3, dt);
                let out = law.compute(&p, &c, &mut s).unwrap();
                let ft = out.tangential_force(Vec3::Z).length();
                assert!(ft <= 0.3 * out.normal_force.max(0.0) * (1.0 + 1e-12) + 1e-12, "Coulomb cap");
                work += out.force.dot(v) * dt;
                e_scale = e_scale.max(out.energy);
            }
            // Over a closed cycle the contact absorbs (dissipates or still stores) energy: the work done
            // on the particles is ≤ 0. Tolerance 1e-6 of the largest stored energy (midpoint-rule error).
            assert!(work <= 1e-6 * e_scale, "energy injected: work {work} J (scale {e_scale} J)");
        }
    }
}

#[test]
fn constant_torque_rolling_stops_without_reversing() {
    let mut props = PairProps::new(&glass(), &rigid(0.2), 0.5, 1.0);
    props.rolling_friction = 0.1;
    let law = Composed::new(Hertz, NoDamping, Frictionless, ConstantTorque);
    let p = law.params(0, &props);
    let mut s = Default::default();
    let (r, m) = (0.01, 2800.0 * 4.0 / 3.0 * PI * 1e-6);
    let inertia = 0.4 * m * r * r;
    let mut w = Vec3::new(3.0, 0.0, 0.0);
    let dt = 1e-6;
    let overlap = 1e-6;
    let mut steps = 0;
    while w.x > 0.0 && steps < 1_000_000 {
        let mut c = input(overlap, Vec3::ZERO, r, m, dt);
        c.w_rel = w;
        c.i_eff = inertia;
        let out = law.compute(&p, &c, &mut s).unwrap();
        w += out.rolling_torque / inertia * dt;
        assert!(w.x >= 0.0, "rolling rotation reversed");
        steps += 1;
    }
    // Constant deceleration μ_r R F_n / I: stops after ω₀ I / (μ_r R F_n) seconds (±1 step).
    let f_n = 4.0 / 3.0 * props.e_star * (r * overlap).sqrt() * overlap;
    let t_stop = 3.0 * inertia / (0.1 * r * f_n);
    assert!(((steps as f64) * dt - t_stop).abs() <= 2.0 * dt, "{} vs {t_stop}", steps as f64 * dt);
}

#[test]
fn viscous_rolling_torque_has_the_model_b_value_and_direction() {
    // Ai et al. (2011) model B: M = −μ_rv R*² F_n ω_roll with ω_roll = ω_rel − (ω_rel·n) n (twist about n
    // excluded), dissipating M·ω_roll = μ_rv R*² F_n |ω_roll|² (W, × Δt per step). Glass sphere r = 1 cm
    // on a rigid wall (R* = r), δ = 1 µm, F_n = (4/3) E* √R* δ^{3/2} (Johnson 1985 §4.2; no damping, no
    // friction, so the rolling torque is the only output besides F_n), μ_rv = 0.3 s/m, ω_rel = (2, −1,
    // 5) rad/s with n = ẑ. Tolerance 1e-12 relative (round-off only).
    let mut props = PairProps::new(&glass(), &rigid(0.2), 0.5, 1.0);
    props.rolling_viscous = 0.3;
    let law = Composed::new(Hertz, NoDamping, Frictionless, ViscousRolling);
    let p = law.params(0, &props);
    let (r, m, dt, overlap) = (0.01, 2800.0 * 4.0 / 3.0 * PI * 1e-6, 1e-6, 1e-6);
    let mut c = input(overlap, Vec3::ZERO, r, m, dt);
    c.w_rel = Vec3::new(2.0, -1.0, 5.0);
    let out = law.compute(&p, &c, &mut Default::default()).unwrap();
    let f_n = 4.0 / 3.0 * props.e_star * (r * overlap).sqrt() * overlap;
    assert!((out.normal_force / f_n - 1.0).abs() < 1e-12, "{} vs {f_n}", out.normal_force);
    let w_roll = Vec3::new(2.0, -1.0, 0.0);
    let expect = -0.3 * r * r * f_n * w_roll;
    assert!(
        (out.rolling_torque - expect).length() < 1e-12 * expect.length(),
        "{} vs {expect}",
        out.rolling_torque
    );
    let diss = 0.3 * r * r * f_n * w_roll.length_squared() * dt;
    assert!((out.dissipated / diss - 1.0).abs() < 1e-12, "{} vs {diss}", out.dissipated);
    // The torque is linear in ω_roll (twice the rotation, twice the torque) and independent of the twist.
    c.w_rel = Vec3::new(4.0, -2.0, -7.0);
    let out2 = law.compute(&p, &c, &mut Default::default()).unwrap();
    assert!((out2.rolling_torque - 2.0 * expect).length() < 1e-12 * expect.length());
    // No-reversal limit: with Δt larger than the decay time I_eff/(μ_rv R*² F_n) the torque is capped at
    // I_eff |ω_roll|/Δt, which stops the relative rolling rotation in one step and no more.
    c.w_rel = w_roll;
    c.dt = 10.0 * c.i_eff / (0.3 * r * r * f_n);
    let out3 = law.compute(&p, &c, &mut Default::default()).unwrap();
    let w_next = w_roll + out3.rolling_torque / c.i_eff * c.dt;
    assert!(w_next.length() < 1e-12 * w_roll.length(), "after one step ω_roll = {w_next}");
}

/// Work absorbed by a Mindlin spring (no dashpot, no sliding) over the cycle: displace by `d` along x at
/// stiffness `k0`, change the stiffness to `k1` at rest, then move back until the force has vanished.
fn stiffness_cycle(history: MindlinHistory, k0: f64, k1: f64, d: f64) -> f64 {
    let law = MindlinVariant { history };
    let p = MindlinParams::new(1e9, 1e9);
    let mut s = SpringHistory::default();
    let (n, dt) = (20_000, 1e-6);
    let v = d / (n as f64 * dt);
    let c = input(1e-6, Vec3::ZERO, 1e-3, 1e-3, dt);
    let mut absorbed = 0.0;
    let mut step = |s: &mut SpringHistory, k: f64, vx: f64| {
        let vt = Vec3::new(vx, 0.0, 0.0);
        let t = law.force(&p, s, k, 0.0, 1e30, vt, &c, true);
        absorbed += -t.force.dot(vt) * dt;
        t.force.x
    };
    for _ in 0..n {
        step(&mut s, k0, v);
    }
    for i in 1..=n {
        step(&mut s, k0 + (k1 - k0) * i as f64 / n as f64, 0.0);
    }
    // Back until the spring no longer pulls towards −x (force on i along +x ≤ 0 means it still pulls).
    for _ in 0..100 * n {
        if step(&mut s, k1, -v / 10.0) >= 0.0 {
            break;
        }
    }
    absorbed
}

#[test]
fn mindlin_history_rules_match_their_closed_form_cycle_energies() {
    // Closed forms (linear spring, stiffness change at rest, see MindlinHistory's table): the work the
    // contact absorbs over the cycle. Positive = dissipated, negative = energy created. Tolerance 1 %
    // of ½k_hi d² (Riemann-sum error of the discrete cycle, O(1/n) with n = 20 000 steps per leg).
    let (lo, hi, d) = (1e5, 3e5, 1e-6);
    let half = |k: f64| 0.5 * k * d * d;
    use MindlinHistory::*;
    let cases = [
        // (rule, k0 → k1, expected absorbed)
        (Displacement, hi, lo, half(hi) - half(lo)),
        (Displacement, lo, hi, half(lo) - half(hi)),
        (DisplacementRescaled, hi, lo, half(hi) - half(lo) * (lo / hi).powi(2)),
        (DisplacementRescaled, lo, hi, half(lo) - half(hi)),
        (Force, hi, lo, half(hi) - half(hi) * hi / lo),
        (Force, lo, hi, half(lo) - half(lo) * lo / hi),
        (ForceRescaled, hi, lo, half(hi) - half(lo)),
        (ForceRescaled, lo, hi, half(lo) - half(lo) * lo / hi),
    ];
    for (rule, k0, k1, expected) in cases {
        let w = stiffness_cycle(rule, k0, k1, d);
        assert!(
            (w - expected).abs() < 0.01 * half(hi),
            "{rule:?} {k0:e} → {k1:e}: absorbed {w:e} J, closed form {expected:e} J"
        );
    }
    // Only the Thornton et al. (2013) rule never creates energy, whichever way the stiffness changes.
    for rule in [Displacement, DisplacementRescaled, Force, ForceRescaled] {
        let worst = stiffness_cycle(rule, hi, lo, d).min(stiffness_cycle(rule, lo, hi, d));
        assert_eq!(worst >= -1e-3 * half(hi), rule == ForceRescaled, "{rule:?}: worst cycle {worst:e} J");
    }
}

#[test]
fn mindlin_variant_with_displacement_history_is_mindlin_bit_for_bit() {
    // The folded spring-law code must give the default law exactly: an oblique impact, every step compared.
    let props = PairProps::new(&glass(), &rigid(0.2), 0.3, 0.7);
    let a: HertzMindlin = Composed::new(Hertz, RestitutionDamping::default(), Mindlin, NoRolling);
    let v = MindlinVariant { history: MindlinHistory::Displacement };
    let b = Composed::new(Hertz, RestitutionDamping::default(), v, NoRolling);
    let (pa, pb) = (a.params(0, &props), b.params(0, &props));
    let (mut sa, mut sb) = (Default::default(), Default::default());
    for k in 0..400 {
        let t = k as f64 / 400.0;
        let overlap = 1e-6 * (PI * t).sin();
        let vel = Vec3::new(0.3 * (3.0 * t).cos(), 0.1, -0.02 * (PI * t).cos());
        let c = input(overlap, vel, 0.005, 1e-3, 1e-8);
        assert_eq!(a.compute(&pa, &c, &mut sa), b.compute(&pb, &c, &mut sb), "step {k}");
    }
}

#[test]
fn rescaled_history_follows_the_contact_radius_only_when_it_shrinks() {
    // ξ = 1 µm stored at k_prev; the next step has no motion. ForceRescaled keeps the force when k grows
    // (scale k_prev/k) and scales it by a/a_prev when k shrinks (scale 1): exact arithmetic.
    let law = MindlinVariant { history: MindlinHistory::ForceRescaled };
    let p = MindlinParams::new(1e9, 10.0);
    let c = input(1e-6, Vec3::ZERO, 1e-3, 1e-3, 1e-6);
    for (k_prev, k, f_expected) in [(2e5, 4e5, 0.2), (4e5, 2e5, 0.2), (4e5, 1e5, 0.1)] {
        let mut s = SpringHistory { xi: Vec3::new(1e-6, 0.0, 0.0), k_prev };
        let t = law.force(&p, &mut s, k, 0.0, 1e30, Vec3::ZERO, &c, false);
        let f = if k > k_prev { k_prev * 1e-6 } else { k * 1e-6 };
        assert!((f - f_expected).abs() < 1e-15);
        assert!((t.force.x + f).abs() < 1e-12 * f, "{k_prev:e} → {k:e}: {} vs {}", t.force.x, -f);
    }
}

#[test]
fn the_standard_law_stores_only_its_tangential_history_per_contact() {
    // Memory per contact is what the 400 B/particle budget is spent on (docs/dem.md §5): the
    // Hertz–Mindlin state is the history vector and the previous stiffness, nothing else (no padding).
    assert_eq!(std::mem::size_of::<<HertzMindlin as ContactLaw>::State>(), 32);
}

#[test]
fn speed_dependent_damping_fixes_its_coefficient_at_first_touch_only() {
    // The coefficient follows the impact speed of the first evaluation; later, slower evaluations of the
    // same contact keep it (Thornton's e(V) is a property of the impact).
    use crate::restitution_models::{RestitutionModel, SpeedDependentDamping, SpeedDependentState};
    let law =
        SpeedDependentDamping { model: RestitutionModel::default(), base: RestitutionDamping::default() };
    let props = PairProps::new(&glass(), &rigid(0.3), 0.5, 0.0);
    let p = <SpeedDependentDamping as DampingLaw>::params(&law, 0, &props, 1.5);
    let fast = input(1e-6, Vec3::new(0.0, 0.0, -2.0), 1e-3, 1e-5, 1e-9);
    let slow = input(1e-6, Vec3::new(0.0, 0.0, -0.1), 1e-3, 1e-5, 1e-9);
    let mut s = SpeedDependentState::default();
    law.in_contact(&p, &fast, &mut s);
    let c_first = s.c_n;
    assert!(s.formed && c_first > 0.0);
    law.in_contact(&p, &slow, &mut s);
    assert_eq!(s.c_n, c_first, "a formed contact keeps its coefficient");
    // A contact that formed at the slow speed gets another coefficient (so the check above can fail).
    let mut s_slow = SpeedDependentState::default();
    law.in_contact(&p, &slow, &mut s_slow);
    assert!((s_slow.c_n - c_first).abs() > 1e-3 * c_first, "{} vs {c_first}", s_slow.c_n);
}

#[test]
fn coulomb_load_chooses_the_total_or_the_elastic_normal_force() {
    // A sliding Hertz contact unloading fast: the dashpot pulls the total normal force below the elastic
    // one, here to the tensile clamp (zero). With `Total` the cap μ·max(F_n, 0) is then zero, with `Elastic`
    // it is μ·F_ne = μ (4/3) E* √R* δ^{3/2} (Hertz closed form, exact up to round-off).
    let mu = 0.4;
    let props = PairProps::new(&glass(), &rigid(0.2), mu, 0.3);
    let (r, m, dt, overlap): (f64, f64, f64, f64) = (0.005, 1e-3, 1e-8, 1e-6);
    let f_ne = 4.0 / 3.0 * props.e_star * r.sqrt() * overlap.powf(1.5);
    // Separating at 100 m/s: γ_n v_n ≫ F_ne, so the total normal force is clamped to zero.
    let c = input(overlap, Vec3::new(5.0, 0.0, 100.0), r, m, dt);
    for (load, cap) in [(CoulombLoad::Total, 0.0), (CoulombLoad::Elastic, mu * f_ne)] {
        let law =
            Composed::new(Hertz, RestitutionDamping::default(), Mindlin, NoRolling).with_coulomb_load(load);
        let p = law.params(0, &props);
        let mut s = Default::default();
        let out = law.compute(&p, &c, &mut s).unwrap();
        assert_eq!(out.normal_force, 0.0, "{load:?}: the clamp holds the total normal force at zero");
        let ft = out.tangential_force(Vec3::Z);
        assert!((ft.length() - cap).abs() <= 1e-12 * f_ne, "{load:?}: |F_t| {} vs μF_c {cap}", ft.length());
        assert!(ft.x <= 0.0, "{load:?}: friction opposes the sliding direction");
    }
    // While loading, the dashpot adds to the elastic force: the elastic cap is the smaller one.
    let c = input(overlap, Vec3::new(5.0, 0.0, -0.01), r, m, dt);
    let caps: Vec<f64> = [CoulombLoad::Total, CoulombLoad::Elastic]
        .iter()
        .map(|&load| {
            let law = Composed::new(Hertz, RestitutionDamping::default(), Mindlin, NoRolling)
                .with_coulomb_load(load);
            let mut s = Default::default();
            let out = law.compute(&law.params(0, &props), &c, &mut s).unwrap();
            out.tangential_force(Vec3::Z).length() / mu
        })
        .collect();
    assert!((caps[1] - f_ne).abs() <= 1e-12 * f_ne && caps[0] > caps[1] * (1.0 + 1e-6), "caps {caps:?}");
}
