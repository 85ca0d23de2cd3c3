//! Reference cases of the flow engine for `spatter validate`.
//!
//! | case | what is compared |
//! |---|---|
//! | `flow_table_6_4` | Jasion (2013) Table 6.4 reference magnitudes, A_H, A_H/F_D0 = 9.90, A_B |
//! | `flow_closed_forms` | Schiller–Naumann, Odar–Hamilton, Oesterle–Bui-Dinh, Dennis, Mei, Di Felice, Table 3.1, pull-off inverse (Jones, Ibrahim), damping ratio ξ(e), rotor momentum theory, ground effect, tip vortex |
//! | `flow_terminal_velocity` | settling speed of a sphere: Schiller–Naumann against an independently solved force balance; Stokes and the library's own solver as consistency checks |
//! | `flow_relaxation` | exponential relaxation to a uniform flow (consistency check of the integrator) |
//! | `flow_lamb_oseen_stokes` | outward drift of heavy particles in a Lamb–Oseen vortex vs the small-St law (raw and extrapolated to Δt → 0); drift grows with St |
//! | `flow_basset` | a light sphere rising with added mass and Basset force vs the Laplace-transform solution |
//! | `flow_linear_field` | a linear field on an imported unstructured mesh reproduced exactly |
//! | `flow_mass_balance` | injected = deposited + escaped + airborne, exactly |

use crate::field::analytic::{AnalyticField, AnalyticSet, ConstantTurbulence};
use crate::field::tetmesh::{kuhn_box, NONE};
use crate::field::{FlowField, ImportOptions, ImportedField};
use crate::forces::drag::{di_felice_cd, di_felice_chi, schiller_naumann_fd, DragLaw};
use crate::forces::history::{odar_hamilton_as_printed, BassetSettings};
use crate::forces::lift::{mei_correction, oesterle_bui_dinh, torque_coefficient, TorqueLaw};
use crate::forces::model::{ForceModel, ForceSwitches};
use crate::forces::ranking::{reference_terms, table_6_4_input};
use crate::forces::wall_lift::WallLiftLaw;
use crate::forces::{stokes_time, Fluid};
use crate::tracker::inject::NewParcel;
use crate::tracker::walls::{Body, Restitution, WallRule};
use crate::tracker::{TrackSettings, Tracker};
use spatter_core::mesh::TriMesh;
use spatter_core::validation::{Case, Check};
use spatter_core::{Aabb, Vec3};

const JASION: &str = "Jasion (2013), PhD thesis, Southampton";

/// Every flow case.
pub fn validation_cases() -> Vec<Case> {
    vec![
        Case { name: "flow_table_6_4", run: table_6_4 },
        Case { name: "flow_closed_forms", run: closed_forms },
        Case { name: "flow_terminal_velocity", run: terminal_velocity },
        Case { name: "flow_relaxation", run: relaxation },
        Case { name: "flow_lamb_oseen_stokes", run: lamb_oseen },
        Case { name: "flow_basset", run: basset },
        Case { name: "flow_linear_field", run: linear_field },
        Case { name: "flow_mass_balance", run: mass_balance },
    ]
}

fn table_6_4(_quick: bool) -> Vec<Check> {
    let r = reference_terms(&table_6_4_input());
    let src = "Jasion 2013 Table 6.4, 3 significant figures";
    let sizes = ["10 µm", "300 µm", "500 µm"];
    let table: [(&str, [f64; 3]); 10] = [
        ("F_D0", [2.20e-3, 7.34e-5, 4.40e-5]),
        ("F_B0", [5.62e-2, 1.03e-2, 7.94e-3]),
        ("F_M0", [3.60e-4, 3.60e-4, 3.60e-4]),
        ("F_S0", [1.24e-9, 6.79e-9, 8.77e-9]),
        ("F_G0", [2.73e-6, 8.18e-5, 1.36e-4]),
        ("F_P0", [8.06e-3, 2.69e-4, 1.61e-4]),
        ("F_Fr0", [7.71e-3, -9.31e-6, -6.23e-5]),
        ("A_H", [2.18e-2, 7.27e-4, 4.36e-4]),
        ("A_H/F_D0", [9.90, 9.90, 9.90]),
        ("A_B", [0.388, 7.09e-2, 5.49e-2]),
    ];
    let mut out = Vec::new();
    for (sym, vals) in table {
        let row = r.row(sym).expect("every symbol is in the table");
        for k in 0..3 {
            // Half a unit in the third digit (inclusive: 8.175e-5 prints as 8.18e-5); F_Fr0 (a
            // near-cancelling difference the thesis truncates) one unit.
            let digits = if sym == "F_Fr0" { 1.0 } else { 0.5 };
            let tol = digits * 10f64.powf(vals[k].abs().log10().floor() - 2.0) / vals[k].abs() * (1.0 + 1e-9);
            out.push(Check::relative(
                "flow_table_6_4",
                format!("{sym} at {} [-]", sizes[k]),
                vals[k],
                row.values[k],
                tol,
                src,
            ));
        }
    }
    out
}

fn closed_forms(_quick: bool) -> Vec<Check> {
    use crate::field::rotor::*;
    let c = |q: &str, reference: f64, ours: f64, tol: f64, src: &str| {
        Check::relative("flow_closed_forms", q, reference, ours, tol, src)
    };
    let d61 = format!("{JASION}, closed forms of chapter 6");
    let ver = "Di Felice (1994), Int. J. Multiphase Flow 20:153";
    let d64 = format!("{JASION}, chapter 6 (wall effects)");
    let mut out = vec![
        c("Schiller–Naumann f(1) [-]", 1.15, schiller_naumann_fd(1.0), 5e-5, &d61),
        c("Schiller–Naumann f(100) [-]", 4.5489, schiller_naumann_fd(100.0), 5e-5, &d61),
        c("Schiller–Naumann f(800) [-]", 15.8086, schiller_naumann_fd(800.0), 5e-5, &d61),
        c("Odar–Hamilton as printed C_B(0) [-]", 1808.44, odar_hamilton_as_printed(0.0), 5e-5, &d61),
        c("Odar–Hamilton as printed C_B(1) [-]", 5.1008, odar_hamilton_as_printed(1.0), 5e-5, &d61),
        c("Oesterle–Bui-Dinh C_LM(10, 10) [-]", 0.86366, oesterle_bui_dinh(10.0, 10.0), 5e-5, &d61),
        c("Oesterle–Bui-Dinh C_LM(50, 100) [-]", 0.46695, oesterle_bui_dinh(50.0, 100.0), 5e-5, &d61),
        c("Dennis C_M(10) [-]", 20.1062, torque_coefficient(TorqueLaw::Dennis, 10.0), 5e-5, &d61),
        c("Dennis C_M(100) [-]", 2.574, torque_coefficient(TorqueLaw::Dennis, 100.0), 5e-5, &d61),
        c("Mei C_Ls(β=0.1, Re=1) [-]", 0.91481, mei_correction(0.1, 1.0), 5e-5, &d61),
        c("Mei C_Ls(β=0.1, Re=40) [-]", 0.12119, mei_correction(0.1, 40.0), 5e-5, &d61),
        c("Mei C_Ls(β=0.1, Re=41) [-]", 0.10610, mei_correction(0.1, 41.0), 5e-5, &d61),
        c("Di Felice C_d(Re=1) [-]", 29.4849, di_felice_cd(1.0), 5e-6, ver),
        c("Di Felice C_d(Re=1000) [-]", 0.61119, di_felice_cd(1000.0), 1e-5, ver),
        c("Di Felice χ(Re=10^1.5) [-]", 3.05, di_felice_chi(10f64.powf(1.5)), 1e-12, ver),
        c("wall lift F⁺ Saffman at a⁺=1 [-]", 6.46, WallLiftLaw::Saffman.f_plus(1.0), 1e-12, &d61),
        c(
            "wall lift F⁺ Leighton–Acrivos at a⁺=1 [-]",
            9.22,
            WallLiftLaw::LeightonAcrivos.f_plus(1.0),
            1e-12,
            &d61,
        ),
        c("wall lift F⁺ Hall at a⁺=1 [-]", 20.9, WallLiftLaw::Hall.f_plus(1.0), 1e-12, &d61),
        c("wall lift F⁺ Mollinger at a⁺=1 [-]", 56.9, WallLiftLaw::Mollinger.f_plus(1.0), 1e-12, &d61),
        c("Bell 47 v_ind [m/s]", 6.06, induced_velocity(8800.0, 1.19, 5.66), 1e-3, &d64),
        c("Bell 47 mass flow [kg/s]", 725.9, mass_flow(8800.0, 1.19, 5.66), 1e-3, &d64),
        c("Cheeseman–Bennett z/R=0.5 [-]", 0.75, cheeseman_bennett(0.5), 1e-4, &d64),
        c("Cheeseman–Bennett z/R=0.68 [-]", 0.8648, cheeseman_bennett(0.68), 1e-4, &d64),
        c("Hayden z/R=0.5 [-]", 0.6254, hayden(0.5), 1e-4, &d64),
        c("Hayden z/R=1.5 [-]", 0.9434, hayden(1.5), 1e-4, &d64),
        c("tip vortex Γ_v [m²/s]", 6.48, tip_vortex_circulation(8800.0, 2, 1.19, 35.6, 5.66), 1e-3, &d64),
        c(
            "Squire δ_v [-]",
            85.8,
            squire_delta(2e-4, tip_vortex_circulation(8800.0, 2, 1.19, 35.6, 5.66), 1.53e-5),
            1e-3,
            &d64,
        ),
        c(
            "Lamb–Oseen peak factor [-]",
            0.7153,
            crate::field::analytic::lamb_oseen_swirl(2.0 * std::f64::consts::PI, 1.0, 1.0),
            1e-4,
            &d64,
        ),
    ];
    out.extend(pull_off_and_damping(&d61));
    out
}

/// Jasion (2013) chapter 6: the pull-off inverse check (measured pull-off forces → σ with the JKR form
/// (3/2)πσr, Jasion eq. 3.54, L1253) and the damping ratio of the restitution-to-damping map (eq. 3.64).
fn pull_off_and_damping(d61: &str) -> Vec<Check> {
    use crate::forces::contact::*;
    let case = "flow_closed_forms";
    // The thesis quotes σ to 3 significant figures: half a unit in the third digit (as for Table 6.4).
    let half_unit = |v: f64| 0.5 * 10f64.powf(v.abs().log10().floor() - 2.0) / v.abs() * (1.0 + 1e-9);
    let src = format!("{d61} item 7 (Jasion L1253, JKR pull-off (3/2)πσr inverted)");
    let mut out = Vec::new();
    for (who, f_nn, d_um, sigma) in [
        ("Jones", 20.0, 6.0, 1.41e-3),
        ("Jones", 40.0, 6.0, 2.83e-3),
        ("Jones", 10.0, 35.0, 1.21e-4),
        ("Jones", 20.0, 35.0, 2.43e-4),
        ("Ibrahim", 34.0, 72.0, 2.00e-4),
    ] {
        let ours = surface_energy_from_pull_off(PullOffTheory::Jkr, f_nn * 1e-9, 0.5 * d_um * 1e-6);
        out.push(Check::relative(
            case,
            format!("σ from {who} {f_nn} nN at d = {d_um} µm [J/m²]"),
            sigma,
            ours,
            half_unit(sigma),
            src.clone(),
        ));
    }
    // Forward: σ = 2e-4 J/m² (Table 6.1) gives Ibrahim's 34 nN at 72 µm; the measurement is quoted to 2
    // digits, so half a unit in the second digit (0.5 nN).
    out.push(Check::relative(
        case,
        "JKR pull-off at σ = 2e-4 J/m², d = 72 µm [N]",
        34e-9,
        pull_off_force(PullOffTheory::Jkr, 2e-4, 36e-6),
        0.5 / 34.0,
        format!("{d61} item 7 (Ibrahim et al., Jasion L1253)"),
    ));
    out.push(Check::relative(
        case,
        "DMT/JKR pull-off ratio 2πσr/(1.5πσr) [-]",
        4.0 / 3.0,
        pull_off_force(PullOffTheory::Dmt, 2e-4, 36e-6) / pull_off_force(PullOffTheory::Jkr, 2e-4, 36e-6),
        1e-12,
        format!("{d61} item 7 (Jasion eq. 3.54–3.55)"),
    ));
    // ξ(e) = −ln e/√(π² + ln²e), quoted to 4 decimals; half a unit in the 4th (5e-5 absolute).
    let src = format!("{d61} item 8 (Jasion eq. 3.64, ξ = −ln e/√(π² + ln²e))");
    out.push(Check::absolute(
        case,
        "damping ratio ξ(e = 0.2) [-]",
        0.4559,
        damping_ratio(0.2),
        5e-5,
        src.clone(),
    ));
    out.push(Check::absolute(case, "damping ratio ξ(e = 1e-4) [-]", 0.9465, damping_ratio(1e-4), 5e-5, src));
    // The linear contact with c from eq. 3.64 rebounds with the e it was built for (e = 0.5).
    let (k, m) = (1.0, 1.0);
    out.push(Check::relative(
        case,
        "linear contact restitution with c(e = 0.5), k = m = 1 [-]",
        0.5,
        linear_contact_restitution(linear_damping_coefficient(0.5, k, m), k, m),
        1e-12,
        format!("{d61} item 8 (analytic damped oscillator, rebound at t = π/ω_d)"),
    ));
    out
}

fn air() -> Fluid {
    Fluid { density: 1.2, viscosity: 1.8e-5 }
}

fn still() -> AnalyticSet {
    AnalyticSet { parts: vec![AnalyticField::Uniform { velocity: Vec3::ZERO }], turbulence: None }
}

fn single(
    field: AnalyticSet,
    sw: ForceSwitches,
    fluid: Fluid,
    dt: f64,
    p: NewParcel,
) -> Tracker<AnalyticSet> {
    let mut tr =
        Tracker::new(field, ForceModel::new(fluid, sw), TrackSettings { dt, ..Default::default() }, vec![]);
    tr.add(p, 0);
    tr
}

fn terminal_velocity(_quick: bool) -> Vec<Check> {
    let mut out = Vec::new();
    let fluid = Fluid { density: 1.19, viscosity: 1.82e-5 };
    // Stokes regime: 10 µm sand, v_t = (ρ_p − ρ_f) g d²/(18μ) (7.43 mm/s for r_p = 5 µm).
    let (d, rho) = (10e-6, 2480.0);
    let tau = stokes_time(&fluid, d, rho);
    let sw = ForceSwitches { drag: DragLaw::Stokes, ..Default::default() };
    let mut tr = single(
        still(),
        sw,
        fluid,
        tau,
        NewParcel { pos: Vec3::ZERO, vel: Vec3::ZERO, diameter: d, density: rho, count: 1.0 },
    );
    for _ in 0..60 {
        let _ = tr.step();
    }
    // Consistency check of the integrator: the exponential update is exact for constant forces, so it
    // must land on Stokes' law to rounding (7.43 mm/s).
    let analytic = (rho - fluid.density) * 9.81 * d * d / (18.0 * fluid.viscosity);
    out.push(Check::relative(
        "flow_terminal_velocity",
        "consistency: Stokes settling speed, 10 µm sand [m/s]",
        analytic,
        -tr.state.parcels[0].vel.z,
        1e-9,
        "Stokes law v = (ρ_p − ρ_f) g d²/(18μ); integrator consistency check",
    ));
    // Schiller–Naumann regime: 300 µm sand (Re ≈ 30), implicit force balance.
    let (d, rho) = (300e-6, 2480.0);
    let tau = stokes_time(&fluid, d, rho);
    let mut tr = single(
        still(),
        ForceSwitches::default(),
        fluid,
        tau / 5.0,
        NewParcel { pos: Vec3::ZERO, vel: Vec3::ZERO, diameter: d, density: rho, count: 1.0 },
    );
    for _ in 0..300 {
        let _ = tr.step();
    }
    // Independent reference: the force balance (ρ_p − ρ_f) g πd³/6 = ½ C_D ρ_f (πd²/4) v² with
    // C_D = 24/Re (1 + 0.15 Re^0.687), Re = ρ_f d v/μ, for ρ_f = 1.19 kg/m³, μ = 1.82e-5 Pa s,
    // d = 300 µm, ρ_p = 2480 kg/m³, g = 9.81 m/s², solved for v with 30 significant digits (mpmath
    // findroot, outside this code): v = 2.2223022835 m/s at Re = 43.5913. The tracker reaches it
    // through its own drag factor, so a wrong factor or buoyancy fails here.
    let reference = 2.2223022835;
    out.push(Check::relative(
        "flow_terminal_velocity",
        "Schiller–Naumann settling speed, 300 µm sand (Re = 43.59) [m/s]",
        reference,
        -tr.state.parcels[0].vel.z,
        1e-9,
        "force balance with C_D = 24/Re (1 + 0.15 Re^0.687), solved independently (mpmath)",
    ));
    // Consistency of the tracker with the library's own implicit solver (same drag factor).
    out.push(Check::relative(
        "flow_terminal_velocity",
        "consistency: tracker vs DragLaw::terminal_speed, 300 µm sand [m/s]",
        DragLaw::SchillerNaumann.terminal_speed(&fluid, d, rho, 9.81),
        -tr.state.parcels[0].vel.z,
        1e-9,
        "integrator consistency check (not an independent validation)",
    ));
    out
}

fn relaxation(_quick: bool) -> Vec<Check> {
    let u = Vec3::new(10.0, 0.0, 0.0);
    let (d, rho) = (50e-6, 1000.0);
    let tau = stokes_time(&air(), d, rho);
    let sw = ForceSwitches { drag: DragLaw::Stokes, gravity: Vec3::ZERO, ..Default::default() };
    let field = AnalyticSet { parts: vec![AnalyticField::Uniform { velocity: u }], turbulence: None };
    let mut tr = single(
        field,
        sw,
        air(),
        tau / 4.0,
        NewParcel { pos: Vec3::ZERO, vel: Vec3::ZERO, diameter: d, density: rho, count: 1.0 },
    );
    let mut out = Vec::new();
    for k in 1..=8 {
        let _ = tr.step();
        if k % 4 == 0 {
            let t = tr.state.time;
            let expect = 10.0 * (1.0 - (-t / tau).exp());
            // Consistency check of the integrator (exact for constant u and τ by construction).
            out.push(Check::relative(
                "flow_relaxation",
                format!("consistency: u_p at t = {}τ [m/s]", k / 4),
                expect,
                tr.state.parcels[0].vel.x,
                1e-12,
                "v = U(1 − e^(−t/τ)); integrator consistency check",
            ));
        }
    }
    out
}

fn lamb_oseen(quick: bool) -> Vec<Check> {
    let (gamma, rc, r0) = (1.0, 0.05, 0.1);
    let v0 = crate::field::analytic::lamb_oseen_swirl(gamma, rc, r0);
    let period = 2.0 * std::f64::consts::PI * r0 / v0;
    let steps = if quick { 40_000 } else { 160_000 };
    let run = |st: f64, steps: usize| {
        let field = AnalyticSet {
            parts: vec![AnalyticField::LambOseen {
                circulation: gamma,
                core_radius: rc,
                centre: Vec3::ZERO,
                axis: Vec3::Z,
                nu: 0.0,
            }],
            turbulence: None,
        };
        let d = 20e-6;
        let rho = st * period * 18.0 * air().viscosity / (d * d);
        let sw = ForceSwitches {
            drag: DragLaw::Stokes,
            gravity: Vec3::ZERO,
            buoyancy: false,
            ..Default::default()
        };
        let mut tr = single(
            field,
            sw,
            air(),
            2.0 * period / steps as f64,
            NewParcel {
                pos: Vec3::new(r0, 0.0, 0.0),
                vel: Vec3::ZERO,
                diameter: d,
                density: rho,
                count: 1.0,
            },
        );
        for _ in 0..steps {
            let _ = tr.step();
        }
        tr.state.parcels[0].pos.length() / r0
    };
    // Small-St law dr/dt = τ_p v²/r by RK4.
    let st = 1e-3;
    let tau = st * period;
    let f = |r: f64| tau * crate::field::analytic::lamb_oseen_swirl(gamma, rc, r).powi(2) / r;
    let (mut r, n) = (r0, 10_000);
    let h = 2.0 * period / n as f64;
    for _ in 0..n {
        let k1 = f(r);
        let k2 = f(r + 0.5 * h * k1);
        let k3 = f(r + 0.5 * h * k2);
        let k4 = f(r + h * k3);
        r += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    }
    let law = r / r0 - 1.0;
    let small = run(st, steps) - 1.0;
    // Richardson extrapolation over N and 2N steps removes the first-order stepping error.
    let small_2n = run(st, 2 * steps) - 1.0;
    let extrapolated = 2.0 * small_2n - small;
    let mid = run(0.1, steps);
    let heavy = run(0.3, steps);
    let src = "small-St drift dr/dt = τ_p v²/r (Maxey 1987)";
    // The stepping moves a tracer outward by 2π²/N per turn (N steps per turn; measured 1.968e-3 of r₀
    // after 2 turns at N = 20 000): 2.8 % of the drift in the quick run, 0.69 % in the full one
    // (measured 2.16 % and 0.46 %). The small-St law itself is first order in St: its neglected
    // terms are ≈ St = 1e-3 of the drift (the extrapolated error scales with St: −1.04e-3 at
    // St = 1e-3, −3.5e-4 at 3e-4).
    let n_turn = steps as f64 / 2.0;
    let stepping_bias = 2.0 * 2.0 * std::f64::consts::PI.powi(2) / n_turn / law;
    vec![
        Check::relative(
            "flow_lamb_oseen_stokes",
            "drift Δr/r₀ after 2 turns, St = 1e-3 [-]",
            law,
            small,
            if quick { 0.03 } else { 0.01 },
            format!("{src}; first-order stepping bias {:.2} %", 100.0 * stepping_bias),
        ),
        Check::relative(
            "flow_lamb_oseen_stokes",
            "drift Δr/r₀ after 2 turns, St = 1e-3, extrapolated to Δt → 0 [-]",
            law,
            extrapolated,
            2e-3,
            format!("{src}; Richardson over N and 2N steps; the law neglects O(St) = 1e-3"),
        ),
        // Trend: heavier particles centrifuge out farther (the check passes when St 0.3 ends outside St 0.1).
        Check::absolute(
            "flow_lamb_oseen_stokes",
            "r(St=0.3) > r(St=0.1) > r(St=1e-3) [bool]",
            1.0,
            f64::from(u8::from(heavy > mid && mid > small + 1.0)),
            0.0,
            "Maxey 1987: drift grows with St",
        ),
    ]
}

fn basset(quick: bool) -> Vec<Check> {
    use crate::field::special::erfc;
    let fluid = Fluid { density: 1000.0, viscosity: 1e-3 };
    let (d, rho) = (100e-6, 500.0);
    let tau = stokes_time(&fluid, d, rho);
    let v_inf = (1.0 - 2.0) * (-9.81) * tau;
    let erfcx = |x: f64| (x * x).exp() * erfc(x);
    let exact = |s: f64| 2.0 * (1.0 - erfcx(0.5 * s.sqrt())) - (1.0 - erfcx(s.sqrt()));
    let n = if quick { 400 } else { 1600 };
    let sw = ForceSwitches {
        drag: DragLaw::Stokes,
        added_mass_coefficient: 0.5,
        // The default history settings (window 1 τ_p capped at 64 steps, exponential tail beyond).
        basset: Some(BassetSettings::default()),
        ..Default::default()
    };
    let mut tr = single(
        still(),
        sw,
        fluid,
        tau / n as f64,
        NewParcel { pos: Vec3::ZERO, vel: Vec3::ZERO, diameter: d, density: rho, count: 1.0 },
    );
    let mut out = Vec::new();
    for k in 1..=4 * n {
        let _ = tr.step();
        if k % (2 * n) == 0 {
            let s = (k / n) as f64;
            out.push(Check::absolute(
                "flow_basset",
                format!("V(t = {s}τ_p) / v_∞ [-]"),
                exact(s),
                tr.state.parcels[0].vel.z / v_inf,
                // First order in Δt: 1.9e-4 at 400 steps per τ_p, 5e-5 at 1600 (full window); the tail
                // kernel adds at most 6e-4 of the share older than the window.
                2e-3,
                "Laplace-transform solution of the Maxey–Riley equation with Basset term (ρ_p/ρ_f = ½)",
            ));
        }
    }
    out
}

fn linear_field(_quick: bool) -> Vec<Check> {
    // A jittered tetrahedral mesh written as an ASCII .vtu, read back by the XML reader.
    let (points, tets) = kuhn_box(Vec3::new(-0.3, 0.1, 0.0), Vec3::new(1.0, 0.7, 0.5), [6, 5, 4], 0.3);
    let lin = |p: Vec3| Vec3::new(1.0 + 2.0 * p.x - p.y, 0.5 * p.z - 3.0 * p.x, 4.0 * p.y + 0.25);
    let join = |v: Vec<String>| v.join(" ");
    let xml = format!(
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\"><UnstructuredGrid><Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\"><Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">{}</DataArray></Points><Cells><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">{}</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">{}</DataArray><DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">{}</DataArray></Cells><PointData><DataArray type=\"Float64\" Name=\"U\" NumberOfComponents=\"3\" format=\"ascii\">{}</DataArray></PointData></Piece></UnstructuredGrid></VTKFile>",
        points.len(),
        tets.len(),
        join(points.iter().flat_map(|p| p.to_array()).map(|x| format!("{x:e}")).collect()),
        join(tets.iter().flatten().map(|i| i.to_string()).collect()),
        join((1..=tets.len()).map(|i| (4 * i).to_string()).collect()),
        join(vec!["10".to_owned(); tets.len()]),
        join(points.iter().flat_map(|p| lin(*p).to_array()).map(|x| format!("{x:e}")).collect()),
    );
    let ds =
        spatter_io::vtk::xml::parse(xml.as_bytes(), std::path::Path::new("linear.vtu")).expect("valid VTU");
    let f = ImportedField::from_dataset(&ds, &ImportOptions::default()).expect("velocity present");
    let mut worst: f64 = 0.0;
    let mut s = 3u64;
    let mut hint = NONE;
    for _ in 0..2000 {
        let r = |s: &mut u64| {
            *s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (*s >> 11) as f64 / (1u64 << 53) as f64
        };
        let x = Vec3::new(-0.3 + r(&mut s), 0.1 + 0.7 * r(&mut s), 0.5 * r(&mut s));
        if let Some(smp) = f.sample(x, 0.0, &mut hint, false) {
            worst = worst.max((smp.u - lin(x)).length());
        }
    }
    vec![Check::absolute(
        "flow_linear_field",
        "max |u − u_linear| on 2000 points [m/s]",
        0.0,
        worst,
        1e-11,
        "linear interpolation on tetrahedra is exact for linear fields",
    )]
}

fn mass_balance(quick: bool) -> Vec<Check> {
    let field = AnalyticSet {
        parts: vec![
            AnalyticField::Uniform { velocity: Vec3::new(2.0, 0.0, -1.0) },
            AnalyticField::LambOseen {
                circulation: 0.5,
                core_radius: 0.1,
                centre: Vec3::new(0.0, 0.0, 0.2),
                axis: Vec3::Y,
                nu: 0.0,
            },
        ],
        turbulence: Some(ConstantTurbulence { k: 0.5, epsilon: 2.0 }),
    };
    let mut plate = TriMesh::rectangle(1.0, 1.0, 0.0, 4, 4);
    plate.map_vertices(|v| v - Vec3::new(0.5, 0.5, 0.0));
    let body = Body::new("plate", plate, WallRule::Reflect(Restitution { normal: 0.3, tangential: 0.9 }));
    let mut trap = TriMesh::rectangle(0.2, 0.2, 0.05, 2, 2);
    trap.map_vertices(|v| v + Vec3::new(0.1, -0.1, 0.0));
    let settings = TrackSettings {
        dt: 2e-4,
        domain: Some(Aabb::new(Vec3::new(-1.0, -1.0, -0.5), Vec3::new(1.0, 1.0, 1.0))),
        dispersion: Some(Default::default()),
        max_bounces: 8,
        resort_interval: 20,
    };
    let mut tr = Tracker::new(
        field,
        ForceModel::new(air(), ForceSwitches::default()),
        settings,
        vec![body, Body::new("trap", trap, WallRule::Trap)],
    );
    let n = if quick { 2000 } else { 20_000 };
    for i in 0..n {
        let f = i as f64 / n as f64;
        tr.add(
            NewParcel {
                pos: Vec3::new(f - 0.6, (7.0 * f).fract() - 0.5, 0.3 + 0.3 * (13.0 * f).fract()),
                vel: Vec3::ZERO,
                diameter: 10e-6 + 90e-6 * (3.0 * f).fract(),
                density: 917.0,
                count: 1.0 + 9.0 * (5.0 * f).fract(),
            },
            0,
        );
    }
    // 0.6 s: the mean flow carries parcels 1.2 m downstream, so some leave the domain (x = 1 m), some are
    // trapped or stick, and some are still airborne. A failed step makes the balance NaN, so the check
    // fails instead of passing on a stopped run.
    let failed = (0..3000).map(|_| tr.step()).any(|r| r.is_err());
    let (inj, rhs) = tr.mass_balance();
    let b = &tr.state.balance;
    // The balance is only a test when every outcome is present: some parcels on each body or trapped,
    // some through the domain boundary, some still in the air.
    let all_outcomes = b.n_deposited > 0 && b.n_escaped > 0 && tr.airborne() > 0;
    vec![
        Check::absolute(
            "flow_mass_balance",
            "injected − (deposited + escaped + airborne) [kg]",
            0.0,
            if failed { f64::NAN } else { inj - rhs },
            0.0,
            "exact summation (Shewchuk 1997)",
        ),
        Check::absolute(
            "flow_mass_balance",
            "deposited, escaped and airborne parcels all present [1 = yes]",
            1.0,
            f64::from(u8::from(all_outcomes)),
            0.0,
            "test design: every term of the balance is exercised",
        ),
    ]
}

#[cfg(test)]
mod tests {
    #[test]
    fn quick_validation_cases_pass() {
        for case in super::validation_cases() {
            for c in (case.run)(true) {
                assert!(
                    c.passed(),
                    "{} / {}: reference {}, ours {} ({:?})",
                    c.case,
                    c.quantity,
                    c.reference,
                    c.ours,
                    c.tolerance
                );
            }
        }
    }
}
