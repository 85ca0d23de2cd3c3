//! Adhesion over the range users set (the wading study varies it ×0.1 to ×10): the contact angle of a
//! sessile drop keeps falling as the wall's adhesion factor grows, and no particle is removed.

use spatter_sph::sessile::{sessile_drop, SessileDrop};
use spatter_sph::Dim;

/// 2D drops at R/8 over 8 capillary times on walls of adhesion 1, 2 and 10. Above 1 the wall wets
/// completely and the drop spreads to a film, so the angle is limited by the film's thickness: it may
/// then stay level (1° allowed for the noise of the film's height), never rise. Until 2026-11-25 the film
/// reached the plate's edge and was drawn round it; the angle measured 18°, 10.5° and 36° (rising).
#[test]
fn contact_angle_keeps_falling_with_strong_adhesion() {
    let mut angles = Vec::new();
    for f in [1.0, 2.0, 10.0] {
        let mut d = SessileDrop::water(Dim::Two, f);
        d.resolution = 8;
        d.capillary_times = 8.0;
        let r = sessile_drop(&d).unwrap();
        assert_eq!(r.removed, 0, "adhesion {f}: particles removed");
        assert!(r.settled(), "adhesion {f}: not settled, {r:?}");
        angles.push(r.contact_angle_deg);
    }
    assert!(angles[1] < angles[0], "adhesion 2 wets more than 1: {angles:?}");
    assert!(angles[2] <= angles[1] + 1.0, "adhesion 10 wets no less than 2: {angles:?}");
    assert!(angles[1] < 15.0, "adhesion 2 wets (nearly) completely: {angles:?}");
}
