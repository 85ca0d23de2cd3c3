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

/// 3D drops at R/6 on walls of adhesion 1, 1.25 and 2. Until 2026-11-26 the wall pressure did not carry
/// the adhesion's pull (only the liquid's pressure and weight): drops on walls from factor 1 to 1.5 were
/// pulled onto the wall surface at the contact line (lowest particles 0–0.01 dp above it), broke up and
/// lost particles to the density window (1 and 130 removed at 1 and 1.25). Now each settles in one piece,
/// the partly wetting drops with their lowest particles about dp/2 off the wall like water filled against
/// it, and the angle falls with the factor (measured 105°, 92°, 17°; docs/sph.md, "3D").
#[test]
fn drops_settle_in_3d_across_the_former_unsettled_band() {
    let mut angles = Vec::new();
    for f in [1.0, 1.25, 2.0] {
        let mut d = SessileDrop::water(Dim::Three, f);
        d.resolution = 6;
        d.capillary_times = 8.0;
        let dp = d.radius / d.resolution as f64;
        let r = sessile_drop(&d).unwrap();
        assert_eq!(r.removed, 0, "adhesion {f}: particles removed, {r:?}");
        assert!(r.settled(), "adhesion {f}: not settled, {r:?}");
        // dp/2 is the rest distance; 0.3–0.7 dp allows the lattice's unevenness under a curved contact line.
        // At 2 the drop spreads to a film one particle thick, which rests on the wall surface itself
        // (measured 0.000–0.009 dp from 1.5 t_c on); it settles without losing particles.
        if f < 2.0 {
            assert!(
                r.standoff > 0.3 * dp && r.standoff < 0.7 * dp,
                "adhesion {f}: lowest particle {:.3} dp above the wall",
                r.standoff / dp
            );
        }
        angles.push(r.contact_angle_deg);
    }
    assert!(angles[0] > angles[1] && angles[1] > angles[2], "angle falls with adhesion: {angles:?}");
    assert!(angles[2] < 30.0, "adhesion 2 spreads the drop: {angles:?}");
}
