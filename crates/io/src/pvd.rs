//! ParaView `.pvd` collections: a list of (time, file) pairs that ParaView opens as one time series.
//! The file is rewritten completely on every push, so it is valid whenever a run stops.

use std::io;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug)]
pub struct PvdSeries {
    path: PathBuf,
    entries: Vec<(f64, String)>,
}

impl PvdSeries {
    /// An empty series to be written at `path`.
    pub fn new(path: &Path) -> Self {
        PvdSeries { path: path.to_owned(), entries: Vec::new() }
    }

    /// The series already at `path` (for resuming), or an empty one.
    pub fn load_or_new(path: &Path) -> io::Result<Self> {
        let mut s = Self::new(path);
        if let Ok(text) = std::fs::read_to_string(path) {
            for line in text.lines().filter(|l| l.contains("<DataSet")) {
                let get = |key: &str| {
                    let start = line.find(&format!("{key}=\""))? + key.len() + 2;
                    let end = line[start..].find('"')? + start;
                    Some(line[start..end].to_owned())
                };
                match (get("timestep").and_then(|t| t.parse().ok()), get("file")) {
                    (Some(t), Some(f)) => s.entries.push((t, f)),
                    _ => {
                        return Err(io::Error::new(
                            io::ErrorKind::InvalidData,
                            format!("{}: unreadable DataSet line `{line}`", path.display()),
                        ))
                    }
                }
            }
        }
        Ok(s)
    }

    /// Adds `file` (relative to the .pvd's folder) at time `time` \[s\] and rewrites the collection.
    pub fn push(&mut self, time: f64, file: &str) -> io::Result<()> {
        self.entries.push((time, file.to_owned()));
        self.write()
    }

    /// Drops entries later than `time` (used when resuming from a checkpoint taken at `time`).
    pub fn truncate_after(&mut self, time: f64) -> io::Result<()> {
        self.entries.retain(|(t, _)| *t <= time);
        self.write()
    }

    pub fn entries(&self) -> &[(f64, String)] {
        &self.entries
    }

    fn write(&self) -> io::Result<()> {
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
        );
        for (t, f) in &self.entries {
            s.push_str(&format!(
                "    <DataSet timestep=\"{}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
                crate::fmt_f64(*t),
                f.replace('&', "&amp;").replace('"', "&quot;")
            ));
        }
        s.push_str("  </Collection>\n</VTKFile>\n");
        std::fs::write(&self.path, s)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", self.path.display())))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_reload_truncate() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("particles.pvd");
        let mut s = PvdSeries::new(&p);
        s.push(0.0, "particles_0000.vtu").unwrap();
        s.push(0.5, "particles_0001.vtu").unwrap();
        s.push(1e-7, "odd.vtu").unwrap();
        let mut back = PvdSeries::load_or_new(&p).unwrap();
        assert_eq!(back.entries(), s.entries());
        back.truncate_after(0.25).unwrap();
        assert_eq!(PvdSeries::load_or_new(&p).unwrap().entries().len(), 2);
    }
}
