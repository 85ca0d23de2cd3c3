//! Clump templates: the member spheres of one body shape in its principal frame, with the mass
//! properties per unit density.
//!
//! A template is built from spheres in any frame ([`ClumpTemplate::from_spheres`]); it is moved to the
//! centre of mass and rotated to the principal axes (moments ascending: the body x axis is the axis of the
//! smallest moment). How much mass the body carries is the [`MassBasis`]:
//!
//! * `Spheres`: the mass of the union of the member spheres, ρ V_union;
//! * `Envelope`: the mass of the solid the spheres fill, ρ V_envelope (generated shapes and filled STL
//!   files know it) — the porous fill then weighs what the real stone weighs;
//! * `Kilograms(m)`: a given mass.
//!
//! In the last two cases the inertia is scaled by the same factor as the mass (the member distribution is
//! kept, so the principal axes and the radii of gyration are those of the spheres).

use super::mass::{of_spheres, MassProperties};
use spatter_core::Vec3;

/// Which mass a body of this template carries (module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MassBasis {
    /// ρ × volume of the union of the member spheres.
    Spheres,
    /// ρ × volume of the enveloping solid (requires a known envelope).
    Envelope,
    /// A fixed mass \[kg\].
    Kilograms(f64),
}

/// A clump shape (module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct ClumpTemplate {
    pub name: String,
    /// Member spheres in the principal frame: centre relative to the centre of mass \[m\], radius \[m\].
    pub spheres: Vec<(Vec3, f64)>,
    /// Mass properties per unit density of the member union, in the input frame.
    pub props: MassProperties,
    /// Volume of the solid the spheres fill, if known \[m³\].
    pub envelope_volume: Option<f64>,
    pub mass_basis: MassBasis,
}

impl ClumpTemplate {
    /// A template from spheres (centre \[m\], radius \[m\]) in any frame. Radii must be positive and
    /// everything finite (checked by the callers that read user input).
    pub fn from_spheres(name: &str, spheres: &[(Vec3, f64)]) -> Self {
        let props = of_spheres(spheres);
        let to_body = props.axes.conjugate();
        let mut members: Vec<(Vec3, f64)> =
            spheres.iter().map(|&(c, r)| (to_body * (c - props.center), r)).collect();
        // A member at the centre of mass sits exactly there (no round-off arm).
        if spheres.len() == 1 {
            members[0].0 = Vec3::ZERO;
        }
        ClumpTemplate {
            name: name.to_string(),
            spheres: members,
            props,
            envelope_volume: None,
            mass_basis: MassBasis::Spheres,
        }
    }

    /// The same template with a known envelope volume \[m³\] and the mass basis `Envelope`.
    pub fn with_envelope(mut self, volume: f64) -> Self {
        self.envelope_volume = Some(volume);
        self.mass_basis = MassBasis::Envelope;
        self
    }

    /// The same template with another mass basis.
    pub fn with_mass_basis(mut self, basis: MassBasis) -> Self {
        self.mass_basis = basis;
        self
    }

    /// Number of member spheres.
    pub fn len(&self) -> usize {
        self.spheres.len()
    }

    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }

    /// Largest distance from the centre of mass to a member surface \[m\].
    pub fn bounding_radius(&self) -> f64 {
        self.spheres.iter().map(|(c, r)| c.length() + r).fold(0.0, f64::max)
    }

    /// Largest member radius \[m\].
    pub fn max_radius(&self) -> f64 {
        self.spheres.iter().map(|s| s.1).fold(0.0, f64::max)
    }

    /// Mass \[kg\], principal moments \[kg m²\] and, for an isotropic body, k² = I/(0.4 M) \[m²\] (else 0)
    /// of a body of density `density` \[kg/m³\].
    pub fn body_mass(&self, density: f64) -> (f64, Vec3, f64) {
        let m_spheres = if self.spheres.len() == 1 {
            // Written as the free-sphere store writes it, so a one-sphere body weighs exactly the same.
            density * spatter_core::math::sphere_volume(self.spheres[0].1)
        } else {
            density * self.props.volume
        };
        let mass = match self.mass_basis {
            MassBasis::Spheres => m_spheres,
            MassBasis::Envelope => density * self.envelope_volume.unwrap_or(self.props.volume),
            MassBasis::Kilograms(m) => m,
        };
        let scale = mass / (density * self.props.volume);
        let inertia = self.props.principal * density * scale;
        let k2 = if self.spheres.len() == 1 && mass == m_spheres {
            let r = self.spheres[0].1;
            r * r
        } else if (inertia.max_element() - inertia.min_element()) <= 1e-12 * inertia.max_element() {
            2.5 * inertia.x / mass
        } else {
            0.0
        };
        let inertia = if k2 > 0.0 { Vec3::splat(0.4 * mass * k2) } else { inertia };
        (mass, inertia, k2)
    }

    /// Solid fraction of the envelope filled by the member spheres, V_union / V_envelope (for a fill of N
    /// equal spheres of diameter d in a ball of diameter D: N (d/D)³).
    pub fn solid_fraction(&self) -> Option<f64> {
        self.envelope_volume.map(|v| self.props.volume / v)
    }
}
