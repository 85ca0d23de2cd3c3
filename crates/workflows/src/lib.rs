//! Workflows built on the engines: snow regime maps, DEM scenes, deposition, SPH scenes.

pub mod snow;
