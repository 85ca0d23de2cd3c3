//! The crossing guard: no fluid particle passes through a wall or body surface, however thin.
//!
//! SPH wall forces alone cannot promise that (leaks through thin and fast walls are the classic complaint
//! about established codes). After every drift, each particle that had a part's boundary
//! particles within its kernel support is checked against that part's surface triangles: its displacement
//! over the step is expressed in the part's reference frame (old position with the part's old placement,
//! new position with the new one, so wall motion counts too) and intersected with the triangles through
//! the part's BVH. A particle that would cross is put back on the side it came from, `offset` in front of
//! the first triangle hit, and loses the velocity component (relative to the wall) that carried it
//! through. Up to four such corrections are tried (corners); if the path still crosses, the particle keeps
//! its old position relative to the part.

use crate::boundary::{Frame, Part};
use spatter_core::Vec3;

/// Outcome of guarding one particle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Guarded {
    pub pos: Vec3,
    pub vel: Vec3,
    /// True when the particle was stopped.
    pub hit: bool,
}

/// Checks the move `old → new` of a particle with velocity `vel` against `part`, whose frame went from
/// `f0` to `f1` during the step.
pub fn guard_particle(
    part: &Part,
    f0: &Frame,
    f1: &Frame,
    old: Vec3,
    new: Vec3,
    vel: Vec3,
    offset: f64,
) -> Guarded {
    let a = f0.to_reference(old);
    let mut b = f1.to_reference(new);
    let mut hit = false;
    let mut n_side = Vec3::ZERO;
    for _ in 0..4 {
        match part.bvh.segment_first_hit(&part.surface, a, b) {
            None => {
                if !hit {
                    return Guarded { pos: new, vel, hit: false };
                }
                let pos = f1.to_world(b);
                let n_world = f1.rot * n_side;
                let v_wall = f1.velocity(pos);
                let rel = vel - v_wall;
                let vn = rel.dot(n_world);
                let vel = if vn < 0.0 { vel - n_world * vn } else { vel };
                return Guarded { pos, vel, hit: true };
            }
            Some((s, t)) => {
                hit = true;
                let p = a + (b - a) * s;
                let n = part.surface.normal(t as usize);
                // Side the particle came from; a start exactly on the plane uses the direction of travel.
                let side = {
                    let d = n.dot(a - p);
                    if d != 0.0 {
                        d.signum()
                    } else {
                        -n.dot(b - a).signum()
                    }
                };
                n_side = n * side;
                b = p + n_side * offset;
            }
        }
    }
    // Could not find a free spot in four tries (deep concave corner): stay with the part.
    let pos = f1.to_world(a);
    Guarded { pos, vel: f1.velocity(pos), hit: true }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::boundary::{Boundary, Samples, Sampling, Slip};
    use spatter_core::mesh::TriMesh;
    use spatter_core::Mat3;

    fn plate() -> Part {
        let mut b = Boundary::default();
        let m = TriMesh::rectangle(1.0, 1.0, 0.0, 3, 3);
        b.add_part("plate", None, Samples::default(), m, Sampling::Lattice, 0.0, Slip::NoSlip, false);
        b.parts.pop().unwrap()
    }

    #[test]
    fn a_particle_is_stopped_in_front_of_a_static_plate() {
        let p = plate();
        let f = Frame::IDENTITY;
        let g = guard_particle(
            &p,
            &f,
            &f,
            Vec3::new(0.5, 0.5, 0.01),
            Vec3::new(0.55, 0.5, -0.02),
            Vec3::new(1.0, 0.0, -3.0),
            0.002,
        );
        assert!(g.hit);
        assert!((g.pos.z - 0.002).abs() < 1e-12, "{}", g.pos);
        assert_eq!(g.vel, Vec3::new(1.0, 0.0, 0.0), "normal velocity removed, tangential kept");
        // From below, through a shared edge of two triangles.
        let g = guard_particle(
            &p,
            &f,
            &f,
            Vec3::new(1.0 / 3.0, 0.5, -0.01),
            Vec3::new(1.0 / 3.0, 0.5, 0.01),
            Vec3::Z,
            0.002,
        );
        assert!(g.hit && (g.pos.z + 0.002).abs() < 1e-12);
        // A move that stays on one side is untouched.
        let g = guard_particle(
            &p,
            &f,
            &f,
            Vec3::new(0.5, 0.5, 0.01),
            Vec3::new(0.5, 0.5, 0.005),
            Vec3::ZERO,
            0.002,
        );
        assert!(!g.hit && g.pos == Vec3::new(0.5, 0.5, 0.005));
    }

    #[test]
    fn a_moving_plate_pushes_a_particle_it_would_sweep_past() {
        // The plate moves up by 0.03 m during the step; a particle at rest 0.01 m above it would end
        // 0.02 m below it in the plate frame.
        let p = plate();
        let f0 = Frame::IDENTITY;
        let f1 =
            Frame { origin: Vec3::new(0.0, 0.0, 0.03), vel: Vec3::new(0.0, 0.0, 3.0), ..Frame::IDENTITY };
        let x = Vec3::new(0.5, 0.5, 0.01);
        let g = guard_particle(&p, &f0, &f1, x, x, Vec3::ZERO, 0.002);
        assert!(g.hit);
        assert!((g.pos.z - 0.032).abs() < 1e-12, "{}", g.pos);
        assert!((g.vel.z - 3.0).abs() < 1e-12, "carried with the plate: {}", g.vel);
        // Rotation: same check with a frame rotated by 90° about x.
        let f1 = Frame { rot: Mat3::from_rotation_x(std::f64::consts::FRAC_PI_2), ..Frame::IDENTITY };
        let g = guard_particle(
            &p,
            &f0,
            &f1,
            Vec3::new(0.5, 0.01, 0.01),
            Vec3::new(0.5, 0.01, 0.01),
            Vec3::ZERO,
            0.002,
        );
        assert!(g.hit, "a particle swept by the rotating plate is stopped");
    }
}
