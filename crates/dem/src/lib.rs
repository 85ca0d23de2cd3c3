//! Soft-sphere discrete element engine.
