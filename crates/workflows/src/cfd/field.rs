//! A solved flow as a [`FlowField`]: the particle tracker, the deposition workflow and the force library
//! sample a `spatter-cfd` solution exactly as they sample analytic or imported fields.
//!
//! * **Frozen**: a finished flow (or one loaded from a checkpoint) sampled as a steady field;
//! * **live**: a flow that a workflow keeps stepping; after each fluid step it builds a new
//!   [`SolvedField`] over the flow and the velocity of the previous step ([`SolvedField::with_previous`]),
//!   which gives ∂u/∂t for the pressure-gradient and added-mass forces.
//!
//! Velocity is interpolated trilinearly from the staggered nodes (`Flow::velocity_at`); the gradient is
//! a central difference over half the local cell width (column j = ∂u/∂x_j, as the trait asks). An
//! axisymmetric (r, z) solution is swept around its axis: a point x is at radius
//! r = |(x − o) − ((x − o)·a) a| and axial position (x − o)·a from the origin o along the unit axis a, and
//! u = u_r e_r + u_z a (no swirl). With the k–ε model, k and ε are those of the cell holding the point
//! (they drive the tracker's random-walk dispersion); laminar flows report none.

use spatter_cfd::{Flow, Mode};
use spatter_core::{Aabb, Vec3};
use spatter_flow::field::{fd_gradient, FlowField, Sample};

/// Placement of an axisymmetric solution in 3D space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisFrame {
    /// A point on the axis where the grid's axial coordinate is 0 \[m\].
    pub origin: Vec3,
    /// Unit vector along the axis (the grid's second axis).
    pub axis: Vec3,
}

impl Default for AxisFrame {
    /// The axis is the world z axis through the origin.
    fn default() -> Self {
        AxisFrame { origin: Vec3::ZERO, axis: Vec3::Z }
    }
}

/// A [`Flow`] seen as a [`FlowField`].
pub struct SolvedField<'a> {
    flow: &'a Flow,
    /// Velocity nodes of the previous step and the step size, for ∂u/∂t.
    previous: Option<(&'a [Vec<f64>; 3], f64)>,
    frame: AxisFrame,
    /// Finite-difference step of the gradient \[m\].
    h: f64,
}

impl<'a> SolvedField<'a> {
    /// A frozen field (∂u/∂t = 0). Axisymmetric flows use [`AxisFrame::default`].
    pub fn new(flow: &'a Flow) -> Self {
        SolvedField { flow, previous: None, frame: AxisFrame::default(), h: 0.5 * flow.grid.min_width() }
    }

    /// A live field: `previous` are the velocity nodes `dt` seconds before the flow's current state.
    pub fn with_previous(mut self, previous: &'a [Vec<f64>; 3], dt: f64) -> Self {
        self.previous = Some((previous, dt));
        self
    }

    /// Places an axisymmetric solution (the axis is normalised; a zero axis keeps the default).
    pub fn with_frame(mut self, frame: AxisFrame) -> Self {
        let a = frame.axis.normalize_or_zero();
        if a != Vec3::ZERO {
            self.frame = AxisFrame { origin: frame.origin, axis: a };
        }
        self
    }

    /// Grid coordinates of world point `x` and, for axisymmetric flows, the radial unit vector.
    fn to_grid(&self, x: Vec3) -> ([f64; 3], Vec3) {
        match self.flow.grid.mode {
            Mode::Cartesian => (x.to_array(), Vec3::ZERO),
            Mode::Axisymmetric => {
                let d = x - self.frame.origin;
                let s = d.dot(self.frame.axis);
                let radial = d - s * self.frame.axis;
                let r = radial.length();
                let er = if r > 0.0 { radial / r } else { Vec3::ZERO };
                let zc = 0.5 * (self.flow.grid.axes[2].lo() + self.flow.grid.axes[2].hi());
                ([r, s, zc], er)
            }
        }
    }

    /// World velocity from grid velocity nodes `u` at `x` (`None` outside the grid).
    fn velocity_from(&self, x: Vec3) -> Option<Vec3> {
        let (q, er) = self.to_grid(x);
        let v = self.flow.velocity_at(q)?;
        Some(match self.flow.grid.mode {
            Mode::Cartesian => Vec3::from(v),
            Mode::Axisymmetric => v[0] * er + v[1] * self.frame.axis,
        })
    }
}

impl FlowField for SolvedField<'_> {
    fn sample(&self, x: Vec3, _t: f64, _hint: &mut u32, want_grad: bool) -> Option<Sample> {
        let u = self.velocity_from(x)?;
        let mut s = Sample { u, ..Sample::default() };
        if self.flow.state.turbulence.is_some() {
            let (q, _) = self.to_grid(x);
            if let Some((k, eps)) = spatter_cfd::output::turbulence_at(self.flow, q) {
                s.k = k;
                s.eps = eps;
            }
        }
        if want_grad {
            // Near the edge of the grid a one-sided point may fall outside: use the value at x there.
            s.grad = fd_gradient(|p| self.velocity_from(p).unwrap_or(u), x, self.h);
        }
        if let Some((prev, dt)) = self.previous {
            let (q, er) = self.to_grid(x);
            let old = self.flow.velocity_at_nodes(prev, q)?;
            let old = match self.flow.grid.mode {
                Mode::Cartesian => Vec3::from(old),
                Mode::Axisymmetric => old[0] * er + old[1] * self.frame.axis,
            };
            s.du_dt = (u - old) / dt;
        }
        Some(s)
    }

    fn bounds(&self) -> Option<Aabb> {
        let ax = &self.flow.grid.axes;
        Some(match self.flow.grid.mode {
            Mode::Cartesian => Aabb::new(
                Vec3::new(ax[0].lo(), ax[1].lo(), ax[2].lo()),
                Vec3::new(ax[0].hi(), ax[1].hi(), ax[2].hi()),
            ),
            Mode::Axisymmetric => {
                // The cylinder of radius R between the axial ends, boxed.
                let (r, a, o) = (ax[0].hi(), self.frame.axis, self.frame.origin);
                let (p0, p1) = (o + ax[1].lo() * a, o + ax[1].hi() * a);
                let ext = Vec3::new(
                    r * (1.0 - a.x * a.x).max(0.0).sqrt(),
                    r * (1.0 - a.y * a.y).max(0.0).sqrt(),
                    r * (1.0 - a.z * a.z).max(0.0).sqrt(),
                );
                Aabb::new(p0.min(p1) - ext, p0.max(p1) + ext)
            }
        })
    }

    fn has_turbulence(&self) -> bool {
        self.flow.state.turbulence.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_cfd::grid::{Axis, Grid};
    use spatter_cfd::{Boundary, Fluid, Numerics};
    use spatter_flow::field::tetmesh::NONE;

    fn wall() -> Boundary {
        Boundary::Wall { velocity_m_s: [0.0; 3] }
    }

    /// A closed stretched box whose nodes hold u = (y, 0, 0): linear, so every interpolation is exact.
    fn shear_flow() -> Flow {
        let g = Grid::new(
            [
                Axis::geometric(0.0, 2.0, 10, 1.1).unwrap(),
                Axis::uniform(0.0, 1.0, 8).unwrap(),
                Axis::uniform(0.0, 0.5, 4).unwrap(),
            ],
            Mode::Cartesian,
        )
        .unwrap();
        let n = g.layout.len();
        let bc = std::array::from_fn(|_| wall());
        let mut f =
            Flow::new(g, Fluid { density: 1.0, viscosity: 1e-3 }, bc, vec![false; n], Numerics::default())
                .unwrap();
        for c in 0..n {
            let q = f.grid.layout.coords(c);
            f.state.u[0][c] = f.grid.metric[1].xc[q[1]];
        }
        f
    }

    #[test]
    fn a_cartesian_solution_gives_velocity_gradient_and_time_derivative() {
        let f = shear_flow();
        let x = Vec3::new(0.77, 0.31, 0.2);
        let field = SolvedField::new(&f);
        let s = field.sample(x, 0.0, &mut NONE.clone(), true).unwrap();
        assert!((s.u - Vec3::new(0.31, 0.0, 0.0)).length() < 1e-12, "{:?}", s.u);
        // Column j = ∂u/∂x_j: only ∂u_x/∂y = 1.
        assert!((s.grad.col(1) - Vec3::X).length() < 1e-9, "{:?}", s.grad);
        assert!(s.grad.col(0).length() < 1e-9 && s.grad.col(2).length() < 1e-9);
        assert_eq!(s.du_dt, Vec3::ZERO, "frozen");
        assert!(field.sample(Vec3::new(2.5, 0.5, 0.2), 0.0, &mut NONE.clone(), false).is_none(), "outside");
        // Live: the previous step had half the velocity 0.1 s earlier.
        let old: [Vec<f64>; 3] = std::array::from_fn(|a| f.state.u[a].iter().map(|v| 0.5 * v).collect());
        let live = SolvedField::new(&f).with_previous(&old, 0.1);
        let s = live.sample(x, 0.0, &mut NONE.clone(), false).unwrap();
        assert!((s.du_dt - Vec3::new(0.31 * 0.5 / 0.1, 0.0, 0.0)).length() < 1e-12);
        let b = field.bounds().unwrap();
        assert_eq!((b.min, b.max), (Vec3::ZERO, Vec3::new(2.0, 1.0, 0.5)));
    }

    #[test]
    fn an_axisymmetric_solution_is_swept_around_its_axis() {
        let g = Grid::new(
            [
                Axis::uniform(0.0, 1.0, 8).unwrap(),
                Axis::uniform(-1.0, 2.0, 12).unwrap(),
                Axis::uniform(0.0, 1.0, 1).unwrap(),
            ],
            Mode::Axisymmetric,
        )
        .unwrap();
        let n = g.layout.len();
        let bc = [Boundary::Axis, wall(), wall(), wall(), Boundary::Slip, Boundary::Slip];
        let mut f =
            Flow::new(g, Fluid { density: 1.0, viscosity: 1e-3 }, bc, vec![false; n], Numerics::default())
                .unwrap();
        // u_r = r at the radial faces, u_z = 2 everywhere.
        for c in 0..n {
            let q = f.grid.layout.coords(c);
            f.state.u[0][c] = f.grid.metric[0].xf[q[0]];
            f.state.u[1][c] = 2.0;
        }
        let frame = AxisFrame { origin: Vec3::new(1.0, 0.0, 0.0), axis: Vec3::new(3.0, 0.0, 0.0) };
        let field = SolvedField::new(&f).with_frame(frame);
        // 0.3 m along the axis (+x), 0.2 m off it in +y: u = 0.2 e_y + 2 e_x.
        let s = field.sample(Vec3::new(1.3, 0.2, 0.0), 0.0, &mut NONE.clone(), true).unwrap();
        assert!((s.u - Vec3::new(2.0, 0.2, 0.0)).length() < 1e-12, "{:?}", s.u);
        // ∇(r e_r) in the plane normal to the axis is the identity there: ∂u_y/∂y = ∂u_z/∂z = 1.
        assert!((s.grad.col(1) - Vec3::Y).length() < 1e-9 && (s.grad.col(2) - Vec3::Z).length() < 1e-9);
        assert!(field.sample(Vec3::new(1.3, 1.2, 0.0), 0.0, &mut NONE.clone(), false).is_none(), "r > R");
        let b = field.bounds().unwrap();
        assert!(
            (b.min - Vec3::new(0.0, -1.0, -1.0)).length() < 1e-12
                && (b.max - Vec3::new(3.0, 1.0, 1.0)).length() < 1e-12
        );
    }

    #[test]
    fn a_written_snapshot_imported_as_a_vtk_field_gives_the_same_velocity() {
        // The frozen path through files: .vtr written by the flow kind, read by the deposition workflow's
        // importer. Cell-centred values of a linear field are exact, and so is linear interpolation.
        let f = shear_flow();
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.vtr");
        spatter_cfd::output::to_vtr(&f).unwrap().write(&p).unwrap();
        let mut opts = spatter_flow::field::ImportOptions::default();
        opts.names.velocity = "velocity_m_s".into();
        let imported = spatter_flow::field::ImportedField::load(&[(0.0, p)], &opts).unwrap();
        let solved = SolvedField::new(&f);
        for x in [Vec3::new(0.77, 0.31, 0.2), Vec3::new(1.5, 0.5, 0.3), Vec3::new(0.3, 0.8, 0.1)] {
            let a = imported.sample(x, 0.0, &mut NONE.clone(), false).unwrap().u;
            let b = solved.sample(x, 0.0, &mut NONE.clone(), false).unwrap().u;
            assert!((a - b).length() < 1e-9, "{x:?}: imported {a:?}, solved {b:?}");
        }
    }
}
