//! `spatter-scenario`: scenario files.
//!
//! A scenario is a TOML file whose top-level `kind` key names the workflow or engine that runs it. This
//! crate reads the file, rejects anything malformed with a message that names the file, line:column, key,
//! value and expected form ([`ScenarioError`]), checks physical ranges through
//! [`spatter_core::check::Validate`] before anything runs, and hands back the typed configuration
//! ([`Scenario`]) together with the fully resolved input (every default filled in) for `run.toml`.
//!
//! * [`source`] — reading the file and locating byte offsets and key paths in it;
//! * [`parse`] — typed deserialisation and validation with located errors;
//! * [`paths`] — relative file paths made absolute against the scenario's folder;
//! * [`kinds`] — the registry of scenario kinds;
//! * [`job`] — the job driver: run folder, `run.toml`, log, checkpoints, finiteness check, `summary.json`.

pub mod job;
pub mod kinds;
pub mod parse;
pub mod source;

pub use kinds::{load, load_str, Loaded, Scenario, KINDS};
pub use parse::ScenarioError;
