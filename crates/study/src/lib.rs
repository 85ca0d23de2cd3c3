//! `spatter-study`: parameter studies over scenario files.
//!
//! A study names a base scenario and the keys to vary (`[[vary]]`), chooses a design (a full grid, paired
//! lists, a Latin hypercube, or a Saltelli design for Sobol sensitivity indices), and runs every case in a
//! folder of its own with its own resolved input. It then writes a results table (one row per case, the
//! scalar outputs each kind reports), comparison plots, Sobol indices for sampled designs, and a
//! self-contained HTML report.
//!
//! * [`spec`] — the study file and its checks, with errors located at file, line and key;
//! * [`keys`] — dotted key paths into a scenario's TOML;
//! * [`plan`] — the cases of a design, each validated as a scenario before anything runs;
//! * [`sweep`] — running the cases (all, or one shard of a batch job), skipping finished ones;
//! * [`table`] — the results table, built from the case folders (so shards merge by collecting);
//! * [`sensitivity`] — Saltelli design, Sobol first-order and total indices, Latin hypercube;
//! * [`outputs`] — the study's plots, Sobol tables and report.
//! * [`gallery`] — the same map of every case redrawn on one colour scale;
//! * [`curves`] — the same curve of every case overlaid, tables of scalars with a column per case.

pub mod curves;
pub mod gallery;
pub mod keys;
pub mod outputs;
pub mod plan;
pub mod sensitivity;
pub mod spec;
pub mod sweep;
pub mod table;

pub use plan::{Case, Plan};
pub use spec::StudyFile;
pub use sweep::{collect, run_study, CaseRunner, StudyError, SweepOptions, SweepOutcome};
