//! Workflows built on the engines: snow regime maps, DEM scenes, deposition, SPH scenes.

pub mod deposition;
pub mod snow;
pub mod wading;
