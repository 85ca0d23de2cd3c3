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

/// Where log lines go: the path, and the file once it is open (a log opened with
/// [`open_when_written`] is created by its first line).
struct Sink {
    path: PathBuf,
    file: Option<File>,
    append: bool,
}

static SINK: Mutex<Option<Sink>> = Mutex::new(None);

fn open_file(path: &Path, append: bool) -> io::Result<File> {
    std::fs::OpenOptions::new()
        .create(true)
        .write(true)
        .append(append)
        .truncate(!append)
        .open(path)
        .map_err(|e| io::Error::new(e.kind(), format!("cannot open {}: {e}", path.display())))
}

/// Sends log lines to `path` from now on: appended when `append` (a resumed run), otherwise the file
/// starts empty.
pub fn open(path: &Path, append: bool) -> io::Result<()> {
    let file = open_file(path, append)?;
    if let Ok(mut s) = SINK.lock() {
        *s = Some(Sink { path: path.to_owned(), file: Some(file), append });
    }
    Ok(())
}

/// Like [`open`], but the file (and its folder) is created only when the first line arrives, so a
/// process with nothing to say leaves no file (the ranks other than 0 of a run on several ranks).
pub fn open_when_written(path: &Path, append: bool) {
    if let Ok(mut s) = SINK.lock() {
        *s = Some(Sink { path: path.to_owned(), file: None, append });
    }
}

/// True when the current log file has been created (always after [`open`]; after
/// [`open_when_written`] once a line was written).
pub fn written() -> bool {
    SINK.lock().ok().is_some_and(|s| s.as_ref().is_some_and(|s| s.file.is_some()))
}

/// Stops writing to the current log file (flushing it).
pub fn close() {
    if let Ok(mut s) = SINK.lock() {
        if let Some(f) = s.as_mut().and_then(|s| s.file.as_mut()) {
            let _ = f.flush();
        }
        *s = None;
    }
}

/// The file log lines go to now, if any.
pub fn current() -> Option<PathBuf> {
    SINK.lock().ok().and_then(|s| s.as_ref().map(|s| s.path.clone()))
}

/// Appends formatted log text to the current log file (nothing when none is open).
pub fn append(text: &[u8]) {
    if let Ok(mut s) = SINK.lock() {
        if let Some(sink) = s.as_mut() {
            if sink.file.is_none() {
                if let Some(parent) = sink.path.parent() {
                    let _ = std::fs::create_dir_all(parent);
                }
                // A log that cannot be created loses its lines; the run itself goes on.
                sink.file = open_file(&sink.path, sink.append).ok();
            }
            if let Some(f) = sink.file.as_mut() {
                let _ = f.write_all(text);
            }
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
        // Created by the first line only.
        let c = dir.path().join("ranks").join("c.txt");
        open_when_written(&c, false);
        assert!(!written() && !c.exists());
        append(b"four\n");
        assert!(written());
        close();
        assert_eq!(std::fs::read_to_string(&c).unwrap(), "four\n");
    }
}
