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
