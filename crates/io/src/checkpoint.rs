//! Checkpoints: a job's whole state as a versioned, checksummed binary file, written atomically
//! (temporary file, flushed to disk, then renamed over the old one) so that a kill while writing never
//! destroys the previous checkpoint.
//!
//! Layout (little-endian):
//!
//! | bytes | content |
//! |---|---|
//! | 0–7 | magic `SPTRCKPT` |
//! | 8–11 | format version ([`VERSION`]) |
//! | 12–19 | hash of the resolved input that wrote it ([`fnv1a`] of the `run.toml` text; 0 = not stamped) |
//! | 20–27 | body length in bytes |
//! | 28–35 | [`fnv1a`] checksum of the body |
//! | 36– | body (bincode) |
//!
//! [`load`] refuses, each with a sentence naming the file: a file that is not a checkpoint, another format
//! version, a truncated or extended file, a body whose checksum does not match (a flipped byte), and a
//! checkpoint stamped with another input. Decoding happens only after all of these pass.
//!
//! A run split over several ranks writes one such file per rank and a *manifest* listing them, in the same
//! layout with the magic `SPTRMANI` (see [`crate::rank_checkpoint`]); [`verify`] accepts both, [`load`]
//! refuses a manifest with a sentence naming its rank count.

use serde::{de::DeserializeOwned, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

const MAGIC: &[u8; 8] = b"SPTRCKPT";
/// Magic of the manifest of a checkpoint written on several ranks.
const MANIFEST_MAGIC: &[u8; 8] = b"SPTRMANI";
/// Format version written by this build. Version 1 had no input hash, length or checksum.
pub const VERSION: u32 = 2;
const HEADER: usize = 36;

#[derive(Debug, Error)]
pub enum CheckpointError {
    #[error("checkpoint {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("checkpoint {path} is not a spatter checkpoint (wrong header); start afresh without --resume")]
    NotACheckpoint { path: PathBuf },
    #[error(
        "checkpoint {path} has format version {found}; this build reads version {VERSION}, so the run cannot \
         be resumed — start it afresh without --resume"
    )]
    Version { path: PathBuf, found: u32 },
    #[error("checkpoint {path} is damaged ({what}); it cannot be resumed — start afresh without --resume")]
    Damaged { path: PathBuf, what: String },
    #[error(
        "checkpoint {path} was written by a different scenario (input hash {found:016x}, this one \
         {expected:016x}); resume with the scenario that wrote it, or start afresh without --resume"
    )]
    OtherInput { path: PathBuf, found: u64, expected: u64 },
    #[error("checkpoint {path} cannot be decoded (written by another build?): {message}")]
    Decode { path: PathBuf, message: String },
    /// The checkpoint was written on another number of ranks than this run has.
    #[error(
        "checkpoint {path} was written by {} and this run has {}: add --repartition to continue on {} \
         (the results then differ from an uninterrupted {written}-rank run at round-off level), or {}",
        ranks_text(*written), ranks_text(*ranks), ranks_text(*ranks), same_ranks_hint(*written)
    )]
    RankCount { path: PathBuf, written: usize, ranks: usize },
    /// Another rank failed to read or write its part of a checkpoint (the rank's own error is on its
    /// standard error stream).
    #[error("rank {rank}: {message}")]
    OnRank { rank: usize, message: String },
}

fn ranks_text(n: usize) -> String {
    if n == 1 {
        "1 rank".into()
    } else {
        format!("{n} ranks")
    }
}

fn same_ranks_hint(written: usize) -> String {
    if written == 1 {
        "resume it without mpirun".into()
    } else {
        format!("resume it on {written} ranks (mpirun -n {written})")
    }
}

/// What a checkpoint file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A whole job's state ([`save`]).
    State,
    /// The manifest of a checkpoint written on several ranks ([`crate::rank_checkpoint`]).
    Manifest,
}

/// 64-bit FNV-1a hash of `bytes`.
///
/// Written here rather than taken from a crate: it is five lines, and its property that matters for
/// checksums is easy to see — every step `h ← (h ⊕ b)·p` is a bijection of `h` for a given byte, so two
/// inputs of equal length that differ in any single byte always hash differently.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    h
}

/// Writes `value` to `path` atomically, stamped with `input_hash` (see the module docs).
pub fn save<T: Serialize>(path: &Path, input_hash: u64, value: &T) -> Result<(), CheckpointError> {
    let body = encode(path, value)?;
    write_atomic(path, Kind::State, input_hash, &body)
}

/// The body [`save`] writes for `value` (bincode); `path` names the file in the error.
pub(crate) fn encode<T: Serialize>(path: &Path, value: &T) -> Result<Vec<u8>, CheckpointError> {
    bincode::serialize(value)
        .map_err(|e| CheckpointError::Decode { path: path.to_owned(), message: e.to_string() })
}

/// Writes header and `body` to `path` atomically (temporary file, flushed, renamed, folder synced).
pub(crate) fn write_atomic(
    path: &Path,
    kind: Kind,
    input_hash: u64,
    body: &[u8],
) -> Result<(), CheckpointError> {
    let io = |source| CheckpointError::Io { path: path.to_owned(), source };
    let mut tmp_name = path.as_os_str().to_owned();
    tmp_name.push(".tmp");
    let tmp = PathBuf::from(tmp_name);
    {
        let mut f = std::fs::File::create(&tmp).map_err(io)?;
        let mut head = Vec::with_capacity(HEADER);
        head.extend_from_slice(match kind {
            Kind::State => MAGIC,
            Kind::Manifest => MANIFEST_MAGIC,
        });
        head.extend_from_slice(&VERSION.to_le_bytes());
        head.extend_from_slice(&input_hash.to_le_bytes());
        head.extend_from_slice(&(body.len() as u64).to_le_bytes());
        head.extend_from_slice(&fnv1a(body).to_le_bytes());
        f.write_all(&head).map_err(io)?;
        f.write_all(body).map_err(io)?;
        f.sync_all().map_err(io)?;
    }
    std::fs::rename(&tmp, path).map_err(io)?;
    // The rename is durable only once the folder's entry is on disk.
    if let Some(parent) = path.parent() {
        if let Ok(d) = std::fs::File::open(parent) {
            let _ = d.sync_all();
        }
    }
    Ok(())
}

/// The fields of a checkpoint header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    pub version: u32,
    pub input_hash: u64,
    pub body_len: u64,
    pub checksum: u64,
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

/// Checks the file's bytes and returns what it holds and the verified body.
fn verified<'a>(path: &Path, bytes: &'a [u8], input_hash: u64) -> Result<(Kind, &'a [u8]), CheckpointError> {
    let damaged = |what: String| CheckpointError::Damaged { path: path.to_owned(), what };
    let kind = match bytes.get(..8) {
        Some(m) if m == MAGIC => Kind::State,
        Some(m) if m == MANIFEST_MAGIC => Kind::Manifest,
        _ => Kind::State,
    };
    if bytes.len() < 12 || (&bytes[..8] != MAGIC && &bytes[..8] != MANIFEST_MAGIC) {
        if bytes.len() < 8 && (MAGIC.starts_with(bytes) || MANIFEST_MAGIC.starts_with(bytes)) {
            return Err(damaged(format!("only {} bytes, cut off inside the header", bytes.len())));
        }
        return Err(CheckpointError::NotACheckpoint { path: path.to_owned() });
    }
    let version = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if version != VERSION {
        return Err(CheckpointError::Version { path: path.to_owned(), found: version });
    }
    if bytes.len() < HEADER {
        return Err(damaged(format!("{} bytes, cut off inside the {HEADER}-byte header", bytes.len())));
    }
    let h = Header {
        version,
        input_hash: u64_at(bytes, 12),
        body_len: u64_at(bytes, 20),
        checksum: u64_at(bytes, 28),
    };
    let body = &bytes[HEADER..];
    if body.len() as u64 != h.body_len {
        return Err(damaged(format!(
            "the header announces {} bytes of state, the file holds {} (truncated or appended to)",
            h.body_len,
            body.len()
        )));
    }
    let sum = fnv1a(body);
    if sum != h.checksum {
        return Err(damaged(format!("checksum {sum:016x} of the state, {:016x} expected", h.checksum)));
    }
    if input_hash != 0 && h.input_hash != input_hash {
        return Err(CheckpointError::OtherInput {
            path: path.to_owned(),
            found: h.input_hash,
            expected: input_hash,
        });
    }
    Ok((kind, body))
}

/// Reads the file at `path` and returns what it holds and its verified body (see [`load`]).
pub(crate) fn read_verified(path: &Path, input_hash: u64) -> Result<(Kind, Vec<u8>), CheckpointError> {
    let bytes =
        std::fs::read(path).map_err(|source| CheckpointError::Io { path: path.to_owned(), source })?;
    let (kind, body) = verified(path, &bytes, input_hash)?;
    let at = bytes.len() - body.len();
    let mut bytes = bytes;
    bytes.drain(..at);
    Ok((kind, bytes))
}

/// Decodes a verified body.
pub(crate) fn decode<T: DeserializeOwned>(path: &Path, body: &[u8]) -> Result<T, CheckpointError> {
    bincode::deserialize(body)
        .map_err(|e| CheckpointError::Decode { path: path.to_owned(), message: e.to_string() })
}

/// Reads a checkpoint written by [`save`], refusing it (see the module docs) unless it is intact and, when
/// `input_hash` is not 0, stamped with that hash.
/// A manifest (a checkpoint written on several ranks) is refused with [`CheckpointError::RankCount`].
pub fn load<T: DeserializeOwned>(path: &Path, input_hash: u64) -> Result<T, CheckpointError> {
    let (kind, body) = read_verified(path, input_hash)?;
    if kind == Kind::Manifest {
        let written = crate::rank_checkpoint::Manifest::decode(path, &body)?.ranks();
        return Err(CheckpointError::RankCount { path: path.to_owned(), written, ranks: 1 });
    }
    decode(path, &body)
}

/// Checks that the checkpoint at `path` is intact and belongs to `input_hash` without decoding it.
/// A manifest is checked as a file (the parts it lists are checked when they are read).
pub fn verify(path: &Path, input_hash: u64) -> Result<(), CheckpointError> {
    written_by(path, input_hash).map(|_| ())
}

/// Checks the checkpoint at `path` like [`verify`] and returns the number of ranks that wrote it (1 for
/// the checkpoint of a one-rank run).
pub fn written_by(path: &Path, input_hash: u64) -> Result<usize, CheckpointError> {
    let (kind, body) = read_verified(path, input_hash)?;
    match kind {
        Kind::State => Ok(1),
        Kind::Manifest => Ok(crate::rank_checkpoint::Manifest::decode(path, &body)?.ranks()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type State = (u64, Vec<f64>, String);

    fn state() -> State {
        (42u64, vec![0.1f64, 1.0 / 3.0, f64::MIN_POSITIVE, -0.0], String::from("x"))
    }

    #[test]
    fn round_trip_is_exact_and_garbage_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("checkpoint.bin");
        save(&p, 7, &state()).unwrap();
        let back: State = load(&p, 7).unwrap();
        assert_eq!(back, state());
        assert!(!dir.path().join("checkpoint.bin.tmp").exists(), "the temporary file is renamed");
        std::fs::write(&p, b"hello there, not a checkpoint").unwrap();
        let e = load::<u64>(&p, 7).unwrap_err().to_string();
        assert!(e.contains("not a spatter checkpoint"), "{e}");
    }

    #[test]
    fn another_input_and_another_version_are_refused_with_a_sentence() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("checkpoint.bin");
        save(&p, 7, &state()).unwrap();
        let e = load::<State>(&p, 8).unwrap_err().to_string();
        assert!(e.contains("different scenario"), "{e}");
        // Unstamped readers (library use without an input file) accept any stamp.
        assert_eq!(load::<State>(&p, 0).unwrap(), state());
        let mut bytes = std::fs::read(&p).unwrap();
        bytes[8..12].copy_from_slice(&1u32.to_le_bytes());
        std::fs::write(&p, &bytes).unwrap();
        let e = load::<State>(&p, 7).unwrap_err().to_string();
        assert!(e.contains("format version 1") && e.contains("cannot be resumed"), "{e}");
    }

    /// Every truncation and every single flipped byte is refused, never decoded, never a panic.
    #[test]
    fn every_truncation_and_every_flipped_byte_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("checkpoint.bin");
        save(&p, 7, &state()).unwrap();
        let good = std::fs::read(&p).unwrap();
        for len in 0..good.len() {
            std::fs::write(&p, &good[..len]).unwrap();
            assert!(load::<State>(&p, 7).is_err(), "truncated to {len} bytes was accepted");
        }
        for i in 0..good.len() {
            for flip in [0x01u8, 0x80, 0xff] {
                let mut b = good.clone();
                b[i] ^= flip;
                std::fs::write(&p, &b).unwrap();
                assert!(load::<State>(&p, 7).is_err(), "byte {i} ^ {flip:#x} was accepted");
            }
        }
    }

    #[test]
    fn a_failed_write_leaves_the_previous_checkpoint() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("checkpoint.bin");
        save(&p, 7, &state()).unwrap();
        // A kill during the next write leaves a partial temporary file beside the good checkpoint.
        std::fs::write(dir.path().join("checkpoint.bin.tmp"), b"SPTRCKPT\x02\0").unwrap();
        assert_eq!(load::<State>(&p, 7).unwrap(), state());
        // The next save replaces the stale temporary file.
        save(&p, 7, &(1u64, vec![2.0], String::new())).unwrap();
        assert_eq!(load::<State>(&p, 7).unwrap().0, 1);
    }

    #[test]
    fn fnv1a_matches_the_published_test_vectors() {
        // FNV-1a 64-bit test vectors from the FNV reference (Fowler, Noll, Vo; IETF draft
        // draft-eastlake-fnv): "" and "a" and "foobar".
        assert_eq!(fnv1a(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(fnv1a(b"a"), 0xaf63_dc4c_8601_ec8c);
        assert_eq!(fnv1a(b"foobar"), 0x8594_4171_f739_67e8);
    }
}
