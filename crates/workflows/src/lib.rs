//! Workflows built on the engines: snow regime maps, DEM scenes, deposition, SPH scenes, flow scenes,
//! brownout.

pub mod bed_flow;
pub mod bed_lab;
pub mod brownout;
pub mod cfd;
pub mod cfd_dem;
pub mod dem_scene;
pub mod deposition;
pub mod fluid_forces;
pub mod gravelometer;
pub mod motions;
pub mod snow;
pub mod sph_scene;
pub mod wading;
