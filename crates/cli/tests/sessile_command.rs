//! `spatter sessile`: the contact-angle calibration utility of the SPH engine.

mod common;
use common::*;

/// Two coarse, short 2D drops: the table and the CSV are written, and the wall of higher adhesion is
/// wetted more (smaller angle; the trend the `sph_sessile_drop` validation case checks at finer settings).
#[test]
fn prints_and_writes_one_angle_per_adhesion_factor() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("angles.csv");
    let out = spatter()
        .args(["sessile", "--adhesion", "0.75,1.0", "--resolution", "6", "--capillary-times", "4", "--csv"])
        .arg(&csv)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("contact angle/deg"), "{stdout}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("adhesion,contact_angle_deg,base_m,height_m,residual_motion,removed_particles")
    );
    let angles: Vec<f64> = lines.map(|l| l.split(',').nth(1).unwrap().parse().unwrap()).collect();
    assert_eq!(angles.len(), 2);
    assert!(angles.iter().all(|a| (0.0..=180.0).contains(a)), "{angles:?}");
    assert!(angles[1] < angles[0], "more adhesion, smaller angle: {angles:?}");
}

/// Out-of-range options are refused before anything runs, each named with its value and range.
#[test]
fn out_of_range_options_are_named() {
    let out = spatter()
        .args(["sessile", "--adhesion", "-1,0.5", "--radius-m", "0", "--capillary-times", "0.5"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    for e in [
        "--adhesion -1 is outside [0, 10]",
        "--radius-m 0 is outside (0, 0.1] m",
        "--capillary-times 0.5 is outside [1, 100]",
    ] {
        assert!(err.contains(e), "expected `{e}` in:\n{err}");
    }
    assert!(!String::from_utf8_lossy(&out.stdout).contains("contact angle"), "nothing ran");
}

/// Measured contact angles per material map to adhesion factors: a table of coarse 2D drops, then one
/// check per material. The less wetting material (larger angle) gets the smaller factor, and each checked
/// drop lands within 15° of its target (linear interpolation in a coarse table).
#[test]
fn contact_angles_map_to_adhesion_factors() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("materials.csv");
    let out = spatter()
        .args([
            "sessile",
            "--contact-angle",
            "paint=80,glass=30",
            "--resolution",
            "6",
            "--capillary-times",
            "4",
        ])
        .arg("--csv")
        .arg(&csv)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("material,measured_angle_deg,adhesion,contact_angle_deg,base_m,height_m,residual_motion,removed_particles")
    );
    let rows: Vec<Vec<String>> = lines.map(|l| l.split(',').map(str::to_owned).collect()).collect();
    assert_eq!(rows.len(), 2, "{text}");
    let f = |k: usize, c: usize| rows[k][c].parse::<f64>().unwrap();
    assert_eq!(rows[0][0], "paint");
    assert!(f(0, 2) < f(1, 2), "paint wets less than glass: {text}");
    for k in 0..2 {
        assert!((f(k, 3) - f(k, 1)).abs() < 15.0, "checked angle near the target: {text}\n{stdout}");
    }
}

/// `--contact-angle` needs `name=degrees` with an angle in (0, 180), and excludes `--adhesion`.
#[test]
fn bad_contact_angles_are_named() {
    let out = spatter().args(["sessile", "--contact-angle", "glass=190,=30,rubber"]).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    for e in [
        "--contact-angle glass=190 is not an angle in (0, 180) degrees",
        "--contact-angle `=30` has no material name",
        "--contact-angle `rubber` is not `name=degrees`",
    ] {
        assert!(err.contains(e), "expected `{e}` in:\n{err}");
    }
    let both =
        spatter().args(["sessile", "--contact-angle", "glass=30", "--adhesion", "1"]).output().unwrap();
    assert!(!both.status.success());
}
