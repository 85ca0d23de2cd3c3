//! The dust cloud: parcels released from an entrainment source on the ground, their concentration on a
//! grid, and the optical depth along lines of sight.
//!
//! * [`classes`] — grain size classes with mass fractions (e.g. a desert-floor size distribution by
//!   weight);
//! * [`source`] — a ground source of annuli × size classes with mass rates \[kg/s\], released as parcels
//!   whose mass adds up exactly to what the source has emitted;
//! * [`grid`] — mass concentration and extinction coefficient on a uniform grid (VTU), and the optical
//!   depth τ = ∫ β ds along a line by exact traversal of the grid's cells;
//! * [`sim`] — the source feeding the tracker over a ground that keeps what lands, and the mass balance
//!   entrained = airborne + redeposited + left.
//!
//! The extinction coefficient of a cloud of spheres is β = Σ n Q_ext π D²/4 with the extinction
//! efficiency Q_ext → 2 for grains much larger than the wavelength (the extinction paradox: diffraction
//! removes as much light as the geometric cross-section; van de Hulst 1957, *Light Scattering by Small
//! Particles*, §8.22). Visible light (0.4–0.7 µm) against grains of 10 µm and more is in that limit; the
//! transmitted fraction along a line is e^(−τ).

pub mod classes;
pub mod grid;
pub mod sim;
pub mod source;

/// Extinction efficiency of grains much larger than the wavelength.
pub const LARGE_PARTICLE_EXTINCTION: f64 = 2.0;
