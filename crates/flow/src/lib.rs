//! Particle-fluid forces, flow fields, Lagrangian tracker and deposition.
