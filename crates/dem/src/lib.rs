//! Soft-sphere discrete element engine.

pub mod adhesion;
pub mod restitution_models;

pub mod contact;
