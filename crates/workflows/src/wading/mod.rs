//! The wading workflow (in progress): a vehicle made of named parts drives through a wading channel.
//!
//! Built so far: the channel generated from a few numbers with the still water's extent, wheels placed on
//! its road and the body's pitch from the axle heights ([`channel`]); the vehicle's parts read from
//! multi-solid STL files, and the reach of a wheel mesh from its axle ([`parts`]); wheels found by part
//! name and checked against their declared radius, the vehicle checked against the channel's width and
//! placed on the road with its pitch, ω = v/R ([`vehicle`]). The scenario kind, the run loop on the SPH
//! engine and the reports are still to come (issue #20).

pub mod channel;
pub mod parts;
pub mod vehicle;
