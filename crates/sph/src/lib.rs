//! Weakly compressible SPH engine for free-surface water.
