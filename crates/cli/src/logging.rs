//! Logging: every event goes to the run's `log.txt`; warnings and errors also to the terminal (printed
//! above the progress bar).

use indicatif::ProgressBar;
use std::fs::File;
use std::io::{self, Write};
use std::sync::{Arc, Mutex};
use tracing::{Level, Metadata};
use tracing_subscriber::fmt::MakeWriter;

#[derive(Clone)]
pub struct Tee {
    file: Option<Arc<Mutex<File>>>,
    bar: ProgressBar,
}

pub struct TeeWriter {
    file: Option<Arc<Mutex<File>>>,
    bar: Option<ProgressBar>,
    buf: Vec<u8>,
}

impl Write for TeeWriter {
    fn write(&mut self, b: &[u8]) -> io::Result<usize> {
        self.buf.extend_from_slice(b);
        Ok(b.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

impl Drop for TeeWriter {
    fn drop(&mut self) {
        if let Some(f) = &self.file {
            if let Ok(mut f) = f.lock() {
                let _ = f.write_all(&self.buf);
                let _ = f.flush();
            }
        }
        if let Some(bar) = &self.bar {
            let text = String::from_utf8_lossy(&self.buf).into_owned();
            bar.suspend(|| eprint!("{text}"));
        }
    }
}

impl<'a> MakeWriter<'a> for Tee {
    type Writer = TeeWriter;

    fn make_writer(&'a self) -> TeeWriter {
        TeeWriter { file: self.file.clone(), bar: Some(self.bar.clone()), buf: Vec::new() }
    }

    fn make_writer_for(&'a self, meta: &Metadata<'_>) -> TeeWriter {
        let to_terminal = *meta.level() <= Level::WARN;
        TeeWriter { file: self.file.clone(), bar: to_terminal.then(|| self.bar.clone()), buf: Vec::new() }
    }
}

/// Routes `tracing` events to `log_file` (appending) and warnings to the terminal. Call once per process.
pub fn init(log_file: Option<&std::path::Path>, bar: &ProgressBar) -> io::Result<()> {
    let file = match log_file {
        Some(p) => Some(Arc::new(Mutex::new(std::fs::OpenOptions::new().create(true).append(true).open(p)?))),
        None => None,
    };
    let tee = Tee { file, bar: bar.clone() };
    let _ = tracing_subscriber::fmt()
        .with_writer(tee)
        .with_ansi(false)
        .with_target(false)
        .with_max_level(Level::INFO)
        .try_init();
    Ok(())
}
