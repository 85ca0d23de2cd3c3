//! The fluid at the spheres from the CFD grid, and the momentum the spheres give back to the fluid.

use super::void_fraction::VoidFraction;
use crate::fluid_forces::{FluidSampler, LocalFluid};
use rayon::prelude::*;
use spatter_cfd::grid::GHOST;
use spatter_cfd::Flow;
use spatter_core::Vec3;

/// The pressure gradient ρ ∂p/∂x_a \[Pa/m\] at the velocity nodes of component a (the nodes sit at the
/// faces between two cells, where the gradient is the two-point difference). Nodes outside the
/// interior faces (ghost layers, boundary faces) take the value of the nearest interior face, so that
/// spheres next to a boundary see the gradient of the fluid beside them rather than of unfilled ghost
/// pressures. Written into `out` (resized on first use).
pub fn pressure_gradient_nodes(flow: &Flow, out: &mut [Vec<f64>; 3]) {
    let l = flow.grid.layout;
    let rho = flow.fluid.density;
    let p = &flow.state.p;
    for (a, o) in out.iter_mut().enumerate() {
        o.resize(l.len(), 0.0);
        let dc = &flow.grid.metric[a].dc;
        if l.n[a] < 2 {
            o.iter_mut().for_each(|v| *v = 0.0);
            continue;
        }
        // Plane by plane in parallel; every value is one formula of its own node.
        o.par_chunks_mut(l.plane()).enumerate().for_each(|(k, plane)| {
            let base = k * l.plane();
            for (off, v) in plane.iter_mut().enumerate() {
                let mut q = l.coords(base + off);
                for (b, qb) in q.iter_mut().enumerate() {
                    // Interior cells GHOST..GHOST+n; along a the face between q and q + 1 must join two.
                    let hi = if b == a { GHOST + l.n[b] - 2 } else { GHOST + l.n[b] - 1 };
                    *qb = (*qb).clamp(GHOST, hi);
                }
                let c0 = l.at(q[0], q[1], q[2]);
                *v = rho * (p[c0 + l.s[a]] - p[c0]) / dc[q[a]];
            }
        });
    }
}

/// The fluid of a CFD grid as seen by the spheres: the solver's velocity is the superficial velocity
/// U = α u, so the interstitial velocity at a sphere is U/α with α of the sphere's cell; ∇p is the
/// trilinear interpolation of the face gradients (the dynamic pressure: the solver's p excludes the
/// hydrostatic part, whose force on a sphere is added as buoyancy by the caller).
pub struct GridFluid<'a> {
    pub flow: &'a Flow,
    pub void_fraction: &'a VoidFraction,
    pub grad_p: &'a [Vec<f64>; 3],
}

impl FluidSampler for GridFluid<'_> {
    fn fluid_at(&self, x: Vec3, _t: f64, _hint: &mut u32) -> Option<LocalFluid> {
        let q = x.to_array();
        let c = VoidFraction::cell_of(&self.flow.grid, x)?;
        let alpha = self.void_fraction.alpha[c];
        let u = Vec3::from(self.flow.velocity_at(q)?) / alpha;
        let grad_p = Vec3::from(self.flow.velocity_at_nodes(self.grad_p, q)?);
        Some(LocalFluid { u, grad_p, alpha })
    }
}
