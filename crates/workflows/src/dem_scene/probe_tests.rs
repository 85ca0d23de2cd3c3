//! Probe-indentation tests: a probe run on a small bed (force zero until contact, the run ends at the
//! largest depth, the analysis' outputs), bit-for-bit resume with the probe's samples in the
//! checkpoint, and the bad-input messages by key.

use super::*;
use spatter_core::check::Checker;
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_io::run::{RunContext, RunDir, RunSummary};

/// A 6 × 6 diameter box (d = 10 mm, k_n = 10⁴ N/m, μ = 0.5) holding a simple-cubic lattice of spheres
/// four layers deep (bed surface near z = 0.04 m), and a sphere probe of radius 10 mm whose
/// `[probe]` keys are `probe` (the shape and material are given here).
fn probe_scene(probe: &str) -> String {
    format!(
        r#"
dt_s = 4e-5
duration_s = 0.2
output_interval_s = 0.01

[contact]
normal = "hooke"
hooke_stiffness_n_m = 1e4
tangential = "linear"

[engine]
track_energy = false

[materials.glass]
youngs_modulus_pa = 6e10
poisson_ratio = 0.25
density_kg_m3 = 2500

[pair_defaults]
friction = 0.5
restitution = 0.3

[[walls]]
name = "floor"
material = "glass"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [0, 0, 1] }}
[[walls]]
name = "xlo"
material = "glass"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [1, 0, 0] }}
[[walls]]
name = "xhi"
material = "glass"
shape = {{ type = "plane", point_m = [0.06, 0, 0], normal = [-1, 0, 0] }}
[[walls]]
name = "ylo"
material = "glass"
shape = {{ type = "plane", point_m = [0, 0, 0], normal = [0, 1, 0] }}
[[walls]]
name = "yhi"
material = "glass"
shape = {{ type = "plane", point_m = [0, 0.06, 0], normal = [0, -1, 0] }}

[[fill]]
material = "glass"
region = {{ type = "box", min_m = [0, 0, 0], max_m = [0.06, 0.06, 0.0415] }}
size = {{ kind = "mono", diameter = 0.01 }}
method = "lattice"
lattice = "cubic"
spacing_m = 0.0101

[probe]
material = "glass"
shape = {{ type = "sphere", center_m = [0.0301, 0.0299, 0.056], radius_m = 0.01 }}
{probe}
"#
    )
}

const PROBE: &str = "speed_m_s = 0.5\nmax_depth_m = 0.02\nsample_hz = 2500\nimmersion_depth_m = 0.004\n";

fn parse(text: &str) -> SceneConfig {
    toml::from_str(text).unwrap_or_else(|e| panic!("{e}"))
}

fn scalar(s: &RunSummary, name: &str) -> f64 {
    s.scalars.iter().find(|(k, _)| k == name).map(|(_, v)| *v).unwrap_or_else(|| panic!("no scalar {name}"))
}

#[test]
fn a_probe_meets_the_bed_at_its_surface_and_stops_at_its_largest_depth() {
    // Exact expectations: the force is zero while the probe's leading point is more than 1 mm above the
    // bed surface (no contact can exist), and the run ends on the first step at or beyond max_depth_m (0.02 m;
    // steps 0.02 mm apart, samples 0.2 mm apart).
    let cfg = parse(&probe_scene(PROBE));
    Checker::run(&cfg, None).unwrap_or_else(|e| panic!("{e:?}"));
    let tmp = tempfile::tempdir().unwrap();
    let dir = RunDir::create(tmp.path()).unwrap();
    let s = run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.finished, Finished::Completed);
    let text = std::fs::read_to_string(dir.path("probe.csv")).unwrap();
    let rows: Vec<Vec<f64>> =
        text.lines().skip(1).map(|l| l.split(',').take(3).map(|v| v.parse().unwrap()).collect()).collect();
    assert!(rows.len() > 100, "{} samples", rows.len());
    for r in &rows {
        if r[1] < -1e-3 {
            assert_eq!(r[2], 0.0, "force above the bed at depth {}", r[1]);
        }
    }
    // Below 5 mm the bed (four layers on a floor) resists on average with more than one sphere's
    // weight, m g = 12.8 mN (the probe pushes spheres aside and down at 0.5 m/s; single samples may be
    // zero while the probe passes a gap of the lattice).
    let deep: Vec<f64> = rows.iter().filter(|r| r[1] > 5e-3).map(|r| r[2]).collect();
    let mean = deep.iter().sum::<f64>() / deep.len() as f64;
    let weight = 2500.0 * std::f64::consts::PI / 6.0 * 1e-6 * 9.81;
    assert!(mean > weight, "mean force below 5 mm {mean} N, one sphere's weight {weight} N");
    let last = rows.last().unwrap()[1];
    assert!((0.02 - 0.5 / 2500.0..0.02 + 0.5 * 4e-5 + 1e-12).contains(&last), "last sample at depth {last}");
    let reached = scalar(&s, "probe_depth_m");
    assert!((0.02..0.02 + 0.5 * 4e-5 + 1e-12).contains(&reached), "the run ends at depth {reached}");
    for name in ["probe_a", "probe_p", "probe_a_star", "probe_peak_l_dp"] {
        assert!(scalar(&s, name).is_finite(), "{name}");
    }
    for f in ["probe_force.png", "probe_psd.png", "probe_spectrum.csv"] {
        assert!(dir.path(f).is_file(), "{f}");
    }
}

#[test]
fn an_interrupted_probe_run_resumes_bit_for_bit() {
    let cfg = parse(&probe_scene(PROBE));
    let tmp = tempfile::tempdir().unwrap();
    let full = RunDir::create(&tmp.path().join("full")).unwrap();
    let s = run(&cfg, &RunContext::new(&full, &Unattended, false)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    let part = RunDir::create(&tmp.path().join("part")).unwrap();
    // Stop with the probe in the bed (step 1200 of about 1450, t = 0.048 s).
    let s = run(&cfg, &RunContext::new(&part, &StopAfterPolls::new(1200), false)).unwrap();
    assert_eq!(s.finished, Finished::Interrupted);
    let s = run(&cfg, &RunContext::new(&part, &Unattended, true)).unwrap();
    assert_eq!(s.finished, Finished::Completed);
    for rel in ["probe.csv", "probe_spectrum.csv", "energy.csv", "particles.pvd"] {
        let a = std::fs::read(full.root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"));
        let b = std::fs::read(part.root().join(rel)).unwrap();
        assert!(a == b, "{rel} differs between the uninterrupted and the resumed run");
    }
}

#[test]
fn bad_probes_are_refused_with_the_key() {
    let errs = |probe: &str| Checker::run(&parse(&probe_scene(probe)), None).unwrap_err();
    let key_says = |probe: &str, key: &str, want: &str| {
        let e = errs(probe);
        let m = &e.iter().find(|e| e.key == key).unwrap_or_else(|| panic!("{key}: {e:?}")).message;
        assert!(m.contains(want), "{key}: {m}");
    };
    key_says("speed_m_s = 0\nmax_depth_m = 0.02", "probe.speed_m_s", "positive speed");
    key_says("speed_m_s = -0.1\nmax_depth_m = 0.02", "probe.speed_m_s", "-0.1");
    key_says(
        "speed_m_s = 0.5\nmax_depth_m = 0.02\nsample_hz = 1e5",
        "probe.sample_hz",
        "above one sample per step",
    );
    key_says("speed_m_s = 0.01\nmax_depth_m = 0.02", "probe.max_depth_m", "longer than duration_s");
    key_says(
        "speed_m_s = 0.5\nmax_depth_m = 0.02\nimmersion_depth_m = 0.03",
        "probe.immersion_depth_m",
        "below max_depth_m",
    );
    // At run time: a probe that starts inside the bed, and a depth beyond the bed.
    let tmp = tempfile::tempdir().unwrap();
    let run_err = |text: String| {
        let cfg = parse(&text);
        Checker::run(&cfg, None).unwrap_or_else(|e| panic!("{e:?}"));
        let dir = RunDir::create(tmp.path()).unwrap();
        run(&cfg, &RunContext::new(&dir, &Unattended, false)).unwrap_err().to_string()
    };
    let inside = probe_scene(PROBE)
        .replace("center_m = [0.0301, 0.0299, 0.056]", "center_m = [0.0301, 0.0299, 0.045]");
    let e = run_err(inside);
    assert!(e.contains("probe.shape") && e.contains("starts inside the bed"), "{e}");
    let deep = probe_scene("speed_m_s = 0.5\nmax_depth_m = 0.06\nimmersion_depth_m = 0.004");
    let e = run_err(deep);
    assert!(e.contains("probe.max_depth_m") && e.contains("beyond the bed"), "{e}");
}

/// The probe on ranks (ranks as threads), into a bed read from a `[bed]` file: the lattice bed of
/// [`probe_scene`] written out as `bed.txt` at t = 0, then the probe driven into that bed on 1, 2 and 3
/// ranks. The bed's spheres are split over the ranks like any particles, the force on the probe is summed
/// over the ranks at every sample, and rank 0 writes the trace: the sample times and depths are those of
/// one rank exactly, the forces within 10⁻⁹ of the largest force (a sphere's contact forces are added in
/// another order on several ranks; measured below), and the fitted law within 10⁻⁶. An interrupted 2-rank
/// probe run resumes bit for bit on 2 ranks.
#[test]
fn a_probe_into_a_bed_file_on_ranks_matches_one_rank() {
    use spatter_core::comm::ThreadComm;
    let tmp = tempfile::tempdir().unwrap();
    // The bed: the fill alone, written at once.
    let fill_only =
        probe_scene("").split("[probe]").next().unwrap().replace("duration_s = 0.2", "duration_s = 4e-5")
            + "[output]\nbed_file = true\n";
    let bed_dir = RunDir::create(&tmp.path().join("bed")).unwrap();
    run(&parse(&fill_only), &RunContext::new(&bed_dir, &Unattended, false)).unwrap();
    let bed = bed_dir.path("bed.txt");
    let fill = probe_scene("");
    let (start, end) = (fill.find("[[fill]]").unwrap(), fill.find("[probe]").unwrap());
    let text = probe_scene(PROBE)
        .replace(&fill[start..end], &format!("[bed]\nfile = {:?}\n\n", bed.to_str().unwrap()));
    let cfg = parse(&text);
    Checker::run(&cfg, None).unwrap_or_else(|e| panic!("{e:?}"));
    assert!(cfg.fill.is_empty() && cfg.bed.is_some());
    let on = |n: usize,
              name: &str,
              control: &(dyn Fn() -> Box<dyn spatter_core::control::RunControl> + Sync),
              resume: bool| {
        let d = RunDir::create(&tmp.path().join(name)).unwrap();
        let done = ThreadComm::run(n, |comm| {
            let c = control();
            let ctx = RunContext { comm, ..RunContext::new(&d, c.as_ref(), resume) };
            run(&cfg, &ctx).map_err(|e| e.to_string())
        });
        (d, done.into_iter().next().unwrap().unwrap())
    };
    let trace = |d: &RunDir| -> Vec<Vec<f64>> {
        let text = std::fs::read_to_string(d.path("probe.csv")).unwrap();
        text.lines().skip(1).map(|l| l.split(',').take(3).map(|v| v.parse().unwrap()).collect()).collect()
    };
    let (one, s1) = on(1, "one", &|| Box::new(Unattended), false);
    let rows1 = trace(&one);
    assert!(rows1.len() > 100, "{} samples", rows1.len());
    let f_max = rows1.iter().map(|r| r[2].abs()).fold(0.0, f64::max);
    assert!(f_max > 0.05, "the probe met the bed: largest force {f_max} N");
    for n in [2, 3] {
        let (d, s) = on(n, &format!("r{n}"), &|| Box::new(Unattended), false);
        assert_eq!(s.finished, Finished::Completed);
        let rows = trace(&d);
        assert_eq!(rows.len(), rows1.len(), "{n} ranks: samples");
        let mut worst: f64 = 0.0;
        for (a, b) in rows1.iter().zip(&rows) {
            assert_eq!((a[0], a[1]), (b[0], b[1]), "{n} ranks: sample time and depth");
            worst = worst.max((a[2] - b[2]).abs() / f_max);
        }
        eprintln!("probe on {n} ranks: forces within {worst:e} of the largest");
        assert!(worst <= 1e-9, "{n} ranks: forces differ by {worst:e} of the largest");
        for name in ["probe_a", "probe_p", "probe_depth_m"] {
            let (x, y) = (scalar(&s1, name), scalar(&s, name));
            assert!((x - y).abs() <= 1e-6 * x.abs(), "{n} ranks: {name} {y} against {x}");
        }
    }
    // Stopped with the probe in the bed on 2 ranks, resumed on 2: the same bits as straight through.
    let (_, s) = on(2, "part", &|| Box::new(StopAfterPolls::new(1200)), false);
    assert_eq!(s.finished, Finished::Interrupted);
    let (part, s) = on(2, "part", &|| Box::new(Unattended), true);
    assert_eq!(s.finished, Finished::Completed);
    let full = RunDir::create(&tmp.path().join("r2")).unwrap();
    for rel in ["probe.csv", "probe_spectrum.csv", "energy.csv"] {
        let a = std::fs::read(full.root().join(rel)).unwrap();
        let b = std::fs::read(part.root().join(rel)).unwrap();
        assert!(a == b, "{rel} differs between the uninterrupted and the resumed 2-rank run");
    }
}
