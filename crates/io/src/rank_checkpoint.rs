//! Checkpoints of a run split over several ranks.
//!
//! Every rank writes its own state as an ordinary checkpoint file ([`crate::checkpoint`]) named
//! `checkpoint/part_g000007_r0003.bin` (generation 7, rank 3); then rank 0 writes `checkpoint.bin` as a
//! *manifest*: the same header (magic `SPTRMANI`, format version, input hash, length, checksum) over a body
//! listing the rank count, the generation and each part's length and checksum. Only then are the parts of
//! older generations deleted. Every file is written atomically (temporary file, flushed, renamed), so a
//! kill at any moment leaves a `checkpoint.bin` whose parts are all on disk: either the new generation
//! (the manifest was renamed into place) or the previous one (not yet deleted).
//!
//! A one-rank run keeps writing its state into `checkpoint.bin` itself ([`crate::checkpoint::save`]),
//! byte for byte as before; [`load_parts`] reads such a file as the whole state, so a one-rank checkpoint
//! resumes on several ranks (with `--repartition`), and a checkpoint of N ranks resumes on N ranks (each
//! takes its part) or, with `--repartition`, on any number (every rank reads every part and the job
//! re-partitions). Another rank count without `--repartition` is refused with
//! [`CheckpointError::RankCount`] on every rank alike.
//!
//! All functions here are collective: every rank calls them at the same point; an error on any rank is
//! returned by every rank (its own error, or [`CheckpointError::OnRank`] naming the rank that failed).

use crate::checkpoint::{decode, encode, fnv1a, read_verified, write_atomic, CheckpointError, Kind};
use serde::{de::DeserializeOwned, Deserialize, Serialize};
use spatter_core::comm::{Comm, WireReader, WireWriter};
use std::path::{Path, PathBuf};

/// Folder of the run folder holding the parts.
pub const PARTS_DIR: &str = "checkpoint";

/// The body of `checkpoint.bin` when several ranks wrote the checkpoint.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Manifest {
    /// Generation of the parts (one more with every checkpoint of the run).
    pub generation: u64,
    /// Per rank, in rank order: body length \[bytes\] and FNV-1a checksum of its part.
    pub parts: Vec<(u64, u64)>,
}

impl Manifest {
    /// Number of ranks that wrote the checkpoint.
    pub fn ranks(&self) -> usize {
        self.parts.len()
    }

    /// Decodes a verified manifest body read from `path`.
    pub(crate) fn decode(path: &Path, body: &[u8]) -> Result<Self, CheckpointError> {
        let m: Manifest = decode(path, body)?;
        if m.parts.is_empty() {
            return Err(CheckpointError::Damaged {
                path: path.to_owned(),
                what: "a manifest of no parts".into(),
            });
        }
        Ok(m)
    }
}

/// Path of rank `rank`'s part of generation `generation` under the run folder `root`.
pub fn part_path(root: &Path, generation: u64, rank: usize) -> PathBuf {
    root.join(PARTS_DIR).join(format!("part_g{generation:06}_r{rank:04}.bin"))
}

/// What a resumed run reads ([`load_parts`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Resumed<S, P> {
    /// The checkpoint of a one-rank run: the whole state (on several ranks every rank reads it).
    Whole(S),
    /// This rank's own part, on as many ranks as wrote the checkpoint.
    Mine(P),
    /// Every part, in the rank order of the run that wrote them (`--repartition`).
    All(Vec<P>),
}

/// Every rank's outcome, on every rank: `Ok` when all succeeded, else this rank's own error or the
/// lowest failing rank's message.
fn collective<T>(comm: &dyn Comm, mine: Result<T, CheckpointError>) -> Result<T, CheckpointError> {
    if comm.size() == 1 {
        return mine;
    }
    let text = match &mine {
        Ok(_) => Vec::new(),
        Err(e) => e.to_string().into_bytes(),
    };
    let all = comm.all_gather_bytes(&text);
    match mine {
        Err(e) => Err(e),
        Ok(v) => match all.iter().enumerate().find(|(_, t)| !t.is_empty()) {
            None => Ok(v),
            Some((rank, t)) => {
                Err(CheckpointError::OnRank { rank, message: String::from_utf8_lossy(t).into_owned() })
            }
        },
    }
}

/// Rank 0's value of `f()` (or its error) on every rank.
fn from_root(
    comm: &dyn Comm,
    f: impl FnOnce() -> Result<Vec<u8>, CheckpointError>,
) -> Result<Vec<u8>, CheckpointError> {
    let mut msg = Vec::new();
    let mut mine = None;
    if comm.is_root() {
        let r = f();
        let mut w = WireWriter::with_capacity(16);
        match &r {
            Ok(bytes) => {
                w.u32(1);
                msg = w.finish();
                msg.extend_from_slice(bytes);
            }
            Err(e) => {
                w.u32(0);
                msg = w.finish();
                msg.extend_from_slice(e.to_string().as_bytes());
            }
        }
        mine = Some(r);
    }
    comm.broadcast_bytes(0, &mut msg);
    if let Some(r) = mine {
        return r;
    }
    let ok = WireReader::new(&msg).u32().unwrap_or(0) == 1;
    let rest = msg.get(4..).unwrap_or_default().to_vec();
    if ok {
        Ok(rest)
    } else {
        Err(CheckpointError::OnRank { rank: 0, message: String::from_utf8_lossy(&rest).into_owned() })
    }
}

/// Writes this rank's `part` and, on rank 0, the manifest (see the module docs); collective. On one rank
/// use [`crate::checkpoint::save`].
pub fn save_parts<P: Serialize>(
    root: &Path,
    input_hash: u64,
    part: &P,
    comm: &dyn Comm,
) -> Result<(), CheckpointError> {
    let manifest_path = root.join("checkpoint.bin");
    // The next generation after the one `checkpoint.bin` lists now (0 after a one-rank checkpoint).
    let generation = from_root(comm, || {
        let g = match read_verified(&manifest_path, 0) {
            Ok((Kind::Manifest, body)) => Manifest::decode(&manifest_path, &body)?.generation + 1,
            _ => 0,
        };
        Ok(g.to_le_bytes().to_vec())
    })?;
    let generation = WireReader::new(&generation).u64().unwrap_or(0);
    let path = part_path(root, generation, comm.rank());
    let written = (|| {
        std::fs::create_dir_all(root.join(PARTS_DIR))
            .map_err(|source| CheckpointError::Io { path: root.join(PARTS_DIR), source })?;
        let body = encode(&path, part)?;
        write_atomic(&path, Kind::State, input_hash, &body)?;
        Ok((body.len() as u64, fnv1a(&body)))
    })();
    let (len, sum) = collective(comm, written)?;
    let mut w = WireWriter::with_capacity(16);
    w.u64(len).u64(sum);
    let entries = comm.all_gather_bytes(&w.finish());
    let parts: Vec<(u64, u64)> = entries
        .iter()
        .map(|b| {
            let mut r = WireReader::new(b);
            (r.u64().unwrap_or(0), r.u64().unwrap_or(0))
        })
        .collect();
    from_root(comm, || {
        let body = encode(&manifest_path, &Manifest { generation, parts })?;
        write_atomic(&manifest_path, Kind::Manifest, input_hash, &body)?;
        remove_other_generations(root, generation);
        Ok(Vec::new())
    })?;
    Ok(())
}

/// Deletes the parts of every generation but `keep` (best effort: a file left over is only disk space).
fn remove_other_generations(root: &Path, keep: u64) {
    let mine = format!("part_g{keep:06}_");
    let Ok(rd) = std::fs::read_dir(root.join(PARTS_DIR)) else { return };
    for e in rd.flatten() {
        let name = e.file_name();
        let name = name.to_string_lossy();
        if name.starts_with("part_g") && !name.starts_with(&mine) {
            if let Err(err) = std::fs::remove_file(e.path()) {
                tracing::warn!("cannot delete the old checkpoint part {}: {err}", e.path().display());
            }
        }
    }
}

/// Reads the checkpoint in `root` for a run on the ranks of `comm` (collective; see the module docs).
/// `repartition`: the run may continue on another rank count than the one that wrote the checkpoint
/// (every rank then gets every part, or the whole one-rank state).
pub fn load_parts<S: DeserializeOwned, P: DeserializeOwned>(
    root: &Path,
    input_hash: u64,
    comm: &dyn Comm,
    repartition: bool,
) -> Result<Resumed<S, P>, CheckpointError> {
    let manifest_path = root.join("checkpoint.bin");
    // Rank 0 reads checkpoint.bin; a manifest goes to every rank, a one-rank state is read by each.
    let head = from_root(comm, || {
        let (kind, body) = read_verified(&manifest_path, input_hash)?;
        Ok(match kind {
            Kind::State => Vec::new(),
            Kind::Manifest => {
                Manifest::decode(&manifest_path, &body)?;
                body
            }
        })
    })?;
    let ranks = comm.size();
    if head.is_empty() {
        if ranks > 1 && !repartition {
            return Err(CheckpointError::RankCount { path: manifest_path, written: 1, ranks });
        }
        let whole = (|| {
            let (_, body) = read_verified(&manifest_path, input_hash)?;
            decode(&manifest_path, &body)
        })();
        return collective(comm, whole).map(Resumed::Whole);
    }
    let manifest = Manifest::decode(&manifest_path, &head)?;
    let written = manifest.ranks();
    let read_part = |rank: usize| -> Result<P, CheckpointError> {
        let path = part_path(root, manifest.generation, rank);
        let (_, body) = read_verified(&path, input_hash)?;
        let (len, sum) = manifest.parts[rank];
        if body.len() as u64 != len || fnv1a(&body) != sum {
            return Err(CheckpointError::Damaged {
                path,
                what: format!(
                    "it is not the part {} lists (another checkpoint's part?)",
                    manifest_path.display()
                ),
            });
        }
        decode(&path, &body)
    };
    if repartition {
        let all = (0..written).map(read_part).collect::<Result<Vec<P>, _>>();
        return collective(comm, all).map(Resumed::All);
    }
    if written != ranks {
        return Err(CheckpointError::RankCount { path: manifest_path, written, ranks });
    }
    collective(comm, read_part(comm.rank())).map(Resumed::Mine)
}

/// Removes the checkpoint of the run folder `root` (`checkpoint.bin` and the parts), when the run has
/// finished.
pub fn remove(root: &Path) -> std::io::Result<()> {
    let manifest = root.join("checkpoint.bin");
    if manifest.exists() {
        std::fs::remove_file(&manifest)?;
    }
    let parts = root.join(PARTS_DIR);
    if parts.is_dir() {
        std::fs::remove_dir_all(&parts)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use spatter_core::comm::ThreadComm;

    type State = (u64, Vec<f64>);

    fn part(rank: usize, generation: u64) -> State {
        (rank as u64, vec![generation as f64, 1.0 / (rank as f64 + 3.0)])
    }

    /// Each rank gets back exactly the part it wrote; the old generation is gone once the new one is
    /// listed; a one-rank reader without --repartition is refused with the sentence naming both counts.
    #[test]
    fn parts_round_trip_and_old_generations_go() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        for g in 0..3u64 {
            let ok = ThreadComm::run(3, |c| save_parts(root, 9, &part(c.rank(), g), c).is_ok());
            assert!(ok.iter().all(|&o| o));
        }
        let back = ThreadComm::run(3, |c| load_parts::<State, State>(root, 9, c, false).unwrap());
        for (r, b) in back.into_iter().enumerate() {
            assert_eq!(b, Resumed::Mine(part(r, 2)));
        }
        let mut names: Vec<String> = std::fs::read_dir(root.join(PARTS_DIR))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["part_g000002_r0000.bin", "part_g000002_r0001.bin", "part_g000002_r0002.bin"]);
        assert_eq!(crate::checkpoint::written_by(&root.join("checkpoint.bin"), 9).unwrap(), 3);
        // Another rank count: refused alike on every rank, unless re-partitioning.
        let e =
            ThreadComm::run(2, |c| load_parts::<State, State>(root, 9, c, false).unwrap_err().to_string());
        assert_eq!(e[0], e[1]);
        assert!(e[0].contains("written by 3 ranks and this run has 2 ranks: add --repartition"), "{}", e[0]);
        let e = crate::checkpoint::load::<State>(&root.join("checkpoint.bin"), 9).unwrap_err().to_string();
        assert!(e.contains("this run has 1 rank") && e.contains("mpirun -n 3"), "{e}");
        let all = ThreadComm::run(2, |c| load_parts::<State, State>(root, 9, c, true).unwrap());
        for a in all {
            assert_eq!(a, Resumed::All((0..3).map(|r| part(r, 2)).collect()));
        }
        // Another input is refused on every rank.
        let e =
            ThreadComm::run(3, |c| load_parts::<State, State>(root, 8, c, false).unwrap_err().to_string());
        assert!(e.iter().all(|t| t.contains("different scenario")), "{e:?}");
        remove(root).unwrap();
        assert!(!root.join("checkpoint.bin").exists() && !root.join(PARTS_DIR).exists());
    }

    /// A one-rank checkpoint (the plain format) is the whole state on any rank count with --repartition,
    /// and refused without it.
    #[test]
    fn a_one_rank_checkpoint_is_the_whole_state() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        crate::checkpoint::save(&root.join("checkpoint.bin"), 5, &part(0, 4)).unwrap();
        let one = ThreadComm::run(1, |c| load_parts::<State, State>(root, 5, c, false).unwrap());
        assert_eq!(one[0], Resumed::Whole(part(0, 4)));
        let two = ThreadComm::run(2, |c| load_parts::<State, State>(root, 5, c, true).unwrap());
        assert!(two.iter().all(|r| *r == Resumed::Whole(part(0, 4))));
        let e =
            ThreadComm::run(2, |c| load_parts::<State, State>(root, 5, c, false).unwrap_err().to_string());
        assert!(
            e[0].contains("written by 1 rank and this run has 2 ranks") && e[0].contains("without mpirun")
        );
        // The first checkpoint on ranks after a one-rank one is generation 0 and replaces it.
        ThreadComm::run(2, |c| save_parts(root, 5, &part(c.rank(), 0), c).unwrap());
        assert_eq!(crate::checkpoint::written_by(&root.join("checkpoint.bin"), 5).unwrap(), 2);
    }

    /// A kill between the parts and the manifest leaves the previous generation readable; a part that is
    /// missing or not the one listed is refused on every rank, naming the rank.
    #[test]
    fn a_missing_or_foreign_part_is_refused_everywhere() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        ThreadComm::run(2, |c| save_parts(root, 3, &part(c.rank(), 0), c).unwrap());
        // New parts written, manifest not yet: the old manifest still lists generation 0.
        crate::checkpoint::save(&part_path(root, 1, 0), 3, &part(0, 1)).unwrap();
        let back = ThreadComm::run(2, |c| load_parts::<State, State>(root, 3, c, false).unwrap());
        assert_eq!(back[1], Resumed::Mine(part(1, 0)));
        // Rank 1's part replaced by another valid checkpoint file.
        crate::checkpoint::save(&part_path(root, 0, 1), 3, &part(1, 7)).unwrap();
        let e =
            ThreadComm::run(2, |c| load_parts::<State, State>(root, 3, c, false).unwrap_err().to_string());
        assert!(e[1].contains("r0001.bin") && e[1].contains("not the part"), "{}", e[1]);
        assert!(e[0].starts_with("rank 1: "), "{}", e[0]);
        std::fs::remove_file(part_path(root, 0, 1)).unwrap();
        let e =
            ThreadComm::run(2, |c| load_parts::<State, State>(root, 3, c, false).unwrap_err().to_string());
        assert!(e[0].starts_with("rank 1: ") && e[0].contains("r0001.bin"), "{}", e[0]);
    }
}
