//! The wading workflow: a vehicle made of named parts drives through a wading channel (kind `wading`,
//! `docs/wading.md`).
//!
//! The channel is generated from a few numbers with the still water's extent, wheels are placed on its
//! road and the body's pitch follows the axle heights ([`channel`]); the vehicle's parts are read from
//! multi-solid STL files ([`parts`]), sensor patches cut out of them by boxes ([`patches`]); wheels are found by part name and checked against their declared
//! radius, the vehicle is checked against the channel's width and placed on the road ([`vehicle`]); the
//! speed over time ([`timeline`]); the channel surfaces and the placed parts are written as STL
//! ([`geometry`]); [`run`] turns all of it into an `sph` scene with motion tables (body pitch and travel,
//! wheel spin ω = v/R), runs it and writes the wading reports. Every boundary along one number (a waterline,
//! a trailing axle, the time a distance is reached) is found by the one bisection of [`bisect`].

pub mod bisect;
pub mod channel;
pub mod channel_stl;
pub mod config;
pub mod geometry;
#[cfg(test)]
mod knob_tests;
pub mod layout;
pub mod parts;
pub mod patches;
pub mod path;
pub mod run;
pub mod timeline;
pub mod vehicle;

pub use config::WadingConfig;
pub use run::{run, WadingError};
