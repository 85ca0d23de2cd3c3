//! Checkpoints: a job's whole state as a versioned binary file, written atomically (temporary file, then
//! rename) so that an interruption while writing never destroys the previous checkpoint.

use serde::{de::DeserializeOwned, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

const MAGIC: &[u8; 8] = b"SPTRCKPT";
const VERSION: u32 = 1;

#[derive(Debug, Error)]
pub enum CheckpointError {
    #[error("checkpoint {path}: {source}")]
    Io { path: PathBuf, source: std::io::Error },
    #[error("checkpoint {path} is not a spatter checkpoint (wrong header)")]
    NotACheckpoint { path: PathBuf },
    #[error("checkpoint {path} has format version {found}; this build reads version {VERSION}")]
    Version { path: PathBuf, found: u32 },
    #[error("checkpoint {path} cannot be decoded (written by another scenario or build?): {message}")]
    Decode { path: PathBuf, message: String },
}

/// Writes `value` to `path` atomically.
pub fn save<T: Serialize>(path: &Path, value: &T) -> Result<(), CheckpointError> {
    let io = |source| CheckpointError::Io { path: path.to_owned(), source };
    let body = bincode::serialize(value)
        .map_err(|e| CheckpointError::Decode { path: path.to_owned(), message: e.to_string() })?;
    let tmp = path.with_extension("bin.tmp");
    {
        let mut f = std::fs::File::create(&tmp).map_err(io)?;
        f.write_all(MAGIC).map_err(io)?;
        f.write_all(&VERSION.to_le_bytes()).map_err(io)?;
        f.write_all(&body).map_err(io)?;
        f.sync_all().map_err(io)?;
    }
    std::fs::rename(&tmp, path).map_err(io)
}

/// Reads a checkpoint written by [`save`].
pub fn load<T: DeserializeOwned>(path: &Path) -> Result<T, CheckpointError> {
    let bytes =
        std::fs::read(path).map_err(|source| CheckpointError::Io { path: path.to_owned(), source })?;
    if bytes.len() < 12 || &bytes[..8] != MAGIC {
        return Err(CheckpointError::NotACheckpoint { path: path.to_owned() });
    }
    let found = u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]);
    if found != VERSION {
        return Err(CheckpointError::Version { path: path.to_owned(), found });
    }
    bincode::deserialize(&bytes[12..])
        .map_err(|e| CheckpointError::Decode { path: path.to_owned(), message: e.to_string() })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_is_exact_and_garbage_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("checkpoint.bin");
        let state = (42u64, vec![0.1f64, 1.0 / 3.0, f64::MIN_POSITIVE], String::from("x"));
        save(&p, &state).unwrap();
        let back: (u64, Vec<f64>, String) = load(&p).unwrap();
        assert_eq!(back, state);
        std::fs::write(&p, b"hello").unwrap();
        let e = load::<u64>(&p).unwrap_err().to_string();
        assert!(e.contains("not a spatter checkpoint"), "{e}");
    }
}
