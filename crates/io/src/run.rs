//! The run folder and the context a job runs in.
//!
//! A run writes one folder: `run.toml` (the fully resolved input), `log.txt`, CSV time series, VTU/PVD
//! snapshots, pictures, and `checkpoint.bin` while it is unfinished.

use crate::checkpoint::CheckpointError;
use serde::{de::DeserializeOwned, Deserialize, Serialize};
use spatter_core::comm::{Comm, SERIAL};
use spatter_core::control::{Finished, RunControl};
use std::io;
use std::path::{Path, PathBuf};

/// A run's output folder.
#[derive(Clone, Debug)]
pub struct RunDir {
    root: PathBuf,
}

impl RunDir {
    /// Uses `root` as the run folder, creating it (and its parents) if needed.
    pub fn create(root: &Path) -> io::Result<Self> {
        std::fs::create_dir_all(root).map_err(|e| {
            io::Error::new(e.kind(), format!("cannot create run folder {}: {e}", root.display()))
        })?;
        Ok(RunDir { root: root.to_owned() })
    }

    pub fn root(&self) -> &Path {
        &self.root
    }

    /// `root/rel`, with the parent folders of that path created.
    pub fn path(&self, rel: &str) -> PathBuf {
        let p = self.root.join(rel);
        if let Some(parent) = p.parent() {
            // Creation errors surface when the file itself is written.
            let _ = std::fs::create_dir_all(parent);
        }
        p
    }

    /// Writes `text` to `root/rel` and returns the full path.
    pub fn write_text(&self, rel: &str, text: &str) -> io::Result<PathBuf> {
        let p = self.path(rel);
        std::fs::write(&p, text)
            .map_err(|e| io::Error::new(e.kind(), format!("cannot write {}: {e}", p.display())))?;
        Ok(p)
    }

    /// Path of the job's checkpoint file.
    pub fn checkpoint_path(&self) -> PathBuf {
        self.root.join("checkpoint.bin")
    }
}

/// Everything a job needs from the program that starts it.
pub struct RunContext<'a> {
    /// Where outputs go.
    pub dir: &'a RunDir,
    /// Stop requests (Ctrl-C, SIGTERM), periodic checkpoint requests and progress reporting.
    pub control: &'a dyn RunControl,
    /// Continue from `dir/checkpoint.bin` instead of starting afresh.
    pub resume: bool,
    /// Hash of the resolved input ([`crate::checkpoint::fnv1a`] of `run.toml`), stamped into every
    /// checkpoint and checked on resume; 0 when the job runs without an input file (library use).
    pub input_hash: u64,
    /// The ranks this run is split over (one, [`SERIAL`], unless started by `mpirun`).
    pub comm: &'a dyn Comm,
    /// With [`RunContext::resume`]: the checkpoint may come from another number of ranks than `comm`
    /// has (`--repartition`); the job then splits the state afresh.
    pub repartition: bool,
}

impl<'a> RunContext<'a> {
    /// A one-rank context without an input hash (checkpoints are not stamped, any checkpoint is accepted).
    pub fn new(dir: &'a RunDir, control: &'a dyn RunControl, resume: bool) -> Self {
        RunContext { dir, control, resume, input_hash: 0, comm: &SERIAL, repartition: false }
    }

    /// Writes `state` to `dir/checkpoint.bin` atomically, stamped with [`RunContext::input_hash`].
    pub fn save_checkpoint<T: Serialize>(&self, state: &T) -> Result<(), CheckpointError> {
        crate::checkpoint::save(&self.dir.checkpoint_path(), self.input_hash, state)?;
        tracing::debug!("checkpoint written to {}", self.dir.checkpoint_path().display());
        Ok(())
    }

    /// Reads `dir/checkpoint.bin`, refusing a damaged one, another format or another input.
    pub fn load_checkpoint<T: DeserializeOwned>(&self) -> Result<T, CheckpointError> {
        crate::checkpoint::load(&self.dir.checkpoint_path(), self.input_hash)
    }

    /// On several ranks: every rank writes its `part` and rank 0 the manifest `dir/checkpoint.bin`
    /// ([`crate::rank_checkpoint::save_parts`]; collective). A one-rank job writes its whole state with
    /// [`RunContext::save_checkpoint`] instead.
    pub fn save_checkpoint_part<P: Serialize>(&self, part: &P) -> Result<(), CheckpointError> {
        crate::rank_checkpoint::save_parts(self.dir.root(), self.input_hash, part, self.comm)?;
        tracing::debug!("checkpoint part {} written", self.comm.rank());
        Ok(())
    }

    /// Reads the checkpoint of a job that runs on ranks: a one-rank state `S` or per-rank parts `P`
    /// ([`crate::rank_checkpoint::load_parts`] with [`RunContext::repartition`]; collective).
    pub fn load_checkpoint_parts<S: DeserializeOwned, P: DeserializeOwned>(
        &self,
    ) -> Result<crate::rank_checkpoint::Resumed<S, P>, CheckpointError> {
        crate::rank_checkpoint::load_parts(self.dir.root(), self.input_hash, self.comm, self.repartition)
    }

    /// True when the job should write a checkpoint now and carry on (periodic checkpoints).
    pub fn checkpoint_due(&self) -> bool {
        self.control.checkpoint_due()
    }

    /// Whether to stop, and whether to write a checkpoint, now. Collective on several ranks: a stop
    /// request (a signal reaches the ranks at different moments) on any rank stops every rank after the
    /// same step, and rank 0's timer decides the periodic checkpoints. On one rank: the control's stop
    /// request, else its checkpoint timer (not asked when stopping).
    pub fn poll(&self) -> Poll {
        let stop = self.control.stop_requested();
        if self.comm.size() == 1 {
            return Poll { stop, checkpoint: !stop && self.checkpoint_due() };
        }
        let due = self.comm.is_root() && self.checkpoint_due();
        let mut v = [f64::from(u8::from(stop)), f64::from(u8::from(due))];
        self.comm.all_max_f64(&mut v);
        Poll { stop: v[0] > 0.0, checkpoint: v[1] > 0.0 }
    }
}

/// What [`RunContext::poll`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Poll {
    /// Stop now (after writing a checkpoint).
    pub stop: bool,
    /// Write a periodic checkpoint and carry on.
    pub checkpoint: bool,
}

/// What a job tells the user when it returns.
#[derive(Clone, Debug)]
pub struct RunSummary {
    pub finished: Finished,
    /// Lines worth printing (key results, counts, warnings).
    pub headline: Vec<String>,
    /// Labelled output files (pictures, tables) the user will want to open.
    pub artifacts: Vec<(String, PathBuf)>,
    /// Named scalar results (name carries the unit, e.g. `stick_fraction`, `total_J`): the columns a study's
    /// results table gets for this run, one row per case.
    pub scalars: Vec<(String, f64)>,
    /// Colour maps on triangle meshes the run drew, with what it takes to draw them again: a study redraws
    /// the same map of every case on one colour scale.
    pub maps: Vec<MeshMapRecord>,
    /// Curves the run wrote as CSV columns: a study overlays the same curve of every case in one plot.
    pub curves: Vec<CurveRecord>,
    /// Named tables of scalars (row label → scalar name), e.g. the wet fraction of every part: a study
    /// shows each as one table with a column per case.
    pub scalar_tables: Vec<ScalarTableRecord>,
}

/// A per-triangle colour map a run drew with [`crate::plot::mesh_map_png`] from a cell array of a triangle
/// `.vtu` it wrote.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshMapRecord {
    /// Names the map; the same map of two runs of a study has the same label (e.g. `panel deposit`).
    pub label: String,
    /// The triangle `.vtu` holding the values (relative to the run folder in `summary.json`).
    pub vtu: PathBuf,
    /// The cell array drawn.
    pub array: String,
    /// Direction the mesh is seen along and the up vector of the picture.
    pub view_dir: [f64; 3],
    pub up: [f64; 3],
    /// Title and colour-bar label of the picture.
    pub title: String,
    pub colorbar_label: String,
    /// The fixed colour scale (low, high) the run drew the map on, when the user fixed one (e.g. the
    /// `wetting_cap` of the `sph` and `wading` kinds); `None` when the run scaled the map to its own values.
    /// A study draws every case's map on this scale when all cases fixed the same one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<[f64; 2]>,
}

/// A curve a run wrote as two columns of a CSV table (e.g. a splash-height distribution).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CurveRecord {
    /// Names the curve; the same curve of two runs of a study has the same label.
    pub label: String,
    /// The CSV file (relative to the run folder in `summary.json`), with a header row.
    pub csv: PathBuf,
    /// Header names of the x and y columns.
    pub x_column: String,
    pub y_column: String,
    /// Axis labels of a plot (name and unit).
    pub x_label: String,
    pub y_label: String,
}

/// A named table of scalars the run reported: one row per entry, the value being the scalar of that name
/// in [`RunSummary::scalars`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScalarTableRecord {
    /// Names the table and the quantity with its unit, e.g. `mean wet fraction per part`.
    pub label: String,
    /// (row label, scalar name) in the order the rows are shown.
    pub rows: Vec<(String, String)>,
}

impl RunSummary {
    pub fn new(finished: Finished) -> Self {
        RunSummary {
            finished,
            headline: Vec::new(),
            artifacts: Vec::new(),
            scalars: Vec::new(),
            maps: Vec::new(),
            curves: Vec::new(),
            scalar_tables: Vec::new(),
        }
    }

    /// Records the scalar result `name` (unit in the name) for study tables.
    pub fn scalar(&mut self, name: &str, value: f64) {
        self.scalars.push((name.to_owned(), value));
    }
}

/// A reduced-size variant of a job's configuration (`spatter run --smoke`): the same scenario cut to a
/// few steps, parcels or impacts, so that it runs to the end in seconds and still writes every output.
/// CI runs every example this way; the resolved input (`run.toml`) shows the reduced values.
pub trait Smoke {
    /// Shrinks the run in place.
    fn smoke(&mut self);
}
