//! The run's `log.txt`: the one file every `tracing` event of the current job is written to.
//!
//! No job writes `log.txt` itself. The program installs one `tracing` subscriber whose writer forwards
//! every formatted event to [`append`]; the job driver points the sink at the run folder's `log.txt` when
//! a job starts ([`open`]) and closes it when the job ends ([`close`]), so jobs run one after another in
//! one process (the cases of a study) each get their own log.

use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

static SINK: Mutex<Option<(PathBuf, File)>> = Mutex::new(None);

/// Sends log lines to `path` from now on: appended when `append` (a resumed run), otherwise the file
/// starts empty.
pub fn open(path: &Path, append: bool) -> io::Result<()> {
    let file = std::fs::OpenOptions::new()
        .create(true)
        .write(true)
        .append(append)
        .truncate(!append)
        .open(path)
        .map_err(|e| io::Error::new(e.kind(), format!("cannot open {}: {e}", path.display())))?;
    if let Ok(mut s) = SINK.lock() {
        *s = Some((path.to_owned(), file));
    }
    Ok(())
}

/// Stops writing to the current log file (flushing it).
pub fn close() {
    if let Ok(mut s) = SINK.lock() {
        if let Some((_, f)) = s.as_mut() {
            let _ = f.flush();
        }
        *s = None;
    }
}

/// The file log lines go to now, if any.
pub fn current() -> Option<PathBuf> {
    SINK.lock().ok().and_then(|s| s.as_ref().map(|(p, _)| p.clone()))
}

/// Appends formatted log text to the current log file (nothing when none is open).
pub fn append(text: &[u8]) {
    if let Ok(mut s) = SINK.lock() {
        if let Some((_, f)) = s.as_mut() {
            let _ = f.write_all(text);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_go_to_the_open_file_only() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.txt");
        let b = dir.path().join("b.txt");
        append(b"lost\n");
        open(&a, false).unwrap();
        append(b"one\n");
        open(&b, false).unwrap();
        append(b"two\n");
        close();
        append(b"lost\n");
        open(&a, true).unwrap();
        append(b"three\n");
        assert_eq!(current().as_deref(), Some(a.as_path()));
        close();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "one\nthree\n");
        assert_eq!(std::fs::read_to_string(&b).unwrap(), "two\n");
    }
}
