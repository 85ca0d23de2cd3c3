//! CSV output. Column names carry their units (`t_s`, `ke_J`, `force_N`); values are written in a form
//! that parses back to the identical `f64`.
//!
//! A value that is undefined by design (a probe with no fluid around it, an angle before the first
//! impact) is an empty cell, written with [`CsvSeries::row_with_gaps`]; `NaN` in a file is always a
//! failed computation, and the job driver refuses a run whose tables hold one.

use crate::fmt_f64;
use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Rows reach the disk at least this often while a series is being written, so a long run's tables can
/// be watched (and survive a hard kill) without a system call per row.
pub const FLUSH_INTERVAL: Duration = Duration::from_secs(1);

/// A numeric time series written row by row. Resumable: a checkpoint stores [`CsvSeries::bytes_written`]
/// and [`CsvSeries::resume`] cuts the file back to that length before appending, so an interrupted and
/// resumed run leaves the same file as an uninterrupted one. Buffered; a row is flushed with everything
/// before it once [`FLUSH_INTERVAL`] has passed since the last flush.
pub struct CsvSeries {
    path: PathBuf,
    out: BufWriter<File>,
    columns: usize,
    bytes: u64,
    flushed_at: Instant,
}

fn with_path(e: io::Error, path: &Path) -> io::Error {
    io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

impl CsvSeries {
    /// Creates (or truncates) `path` and writes the header line.
    pub fn create(path: &Path, columns: &[&str]) -> io::Result<Self> {
        let file = File::create(path).map_err(|e| with_path(e, path))?;
        let mut s = CsvSeries {
            path: path.to_owned(),
            out: BufWriter::new(file),
            columns: columns.len(),
            bytes: 0,
            flushed_at: Instant::now(),
        };
        let header = columns.join(",") + "\n";
        s.write_raw(header.as_bytes())?;
        Ok(s)
    }

    /// Reopens `path` after a checkpoint: keeps its first `byte_len` bytes and appends after them.
    pub fn resume(path: &Path, columns: &[&str], byte_len: u64) -> io::Result<Self> {
        let mut file =
            OpenOptions::new().read(true).write(true).open(path).map_err(|e| with_path(e, path))?;
        let len = file.metadata()?.len();
        if len < byte_len {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{} is shorter ({len} B) than its checkpoint says ({byte_len} B)", path.display()),
            ));
        }
        file.set_len(byte_len)?;
        file.seek(SeekFrom::Start(byte_len))?;
        Ok(CsvSeries {
            path: path.to_owned(),
            out: BufWriter::new(file),
            columns: columns.len(),
            bytes: byte_len,
            flushed_at: Instant::now(),
        })
    }

    fn write_raw(&mut self, b: &[u8]) -> io::Result<()> {
        self.out.write_all(b).map_err(|e| with_path(e, &self.path))?;
        self.bytes += b.len() as u64;
        Ok(())
    }

    /// Appends one row; the number of values must match the header. A NaN is written as `NaN` (a failed
    /// computation, which the job driver's final check refuses); use [`CsvSeries::row_with_gaps`] for
    /// values that are undefined by design.
    pub fn row(&mut self, values: &[f64]) -> io::Result<()> {
        self.write_row(values.len(), values.iter().map(|v| Some(*v)))
    }

    /// Appends one row in which `None` marks a value undefined by design, written as an empty cell
    /// ([`read_series`] reads it back as NaN).
    pub fn row_with_gaps(&mut self, values: &[Option<f64>]) -> io::Result<()> {
        self.write_row(values.len(), values.iter().copied())
    }

    fn write_row(&mut self, len: usize, values: impl Iterator<Item = Option<f64>>) -> io::Result<()> {
        if len != self.columns {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{}: row has {len} values, header has {}", self.path.display(), self.columns),
            ));
        }
        let mut line = String::with_capacity(16 * len);
        for (i, v) in values.enumerate() {
            if i > 0 {
                line.push(',');
            }
            if let Some(v) = v {
                line.push_str(&fmt_f64(v));
            }
        }
        line.push('\n');
        self.write_raw(line.as_bytes())?;
        if self.flushed_at.elapsed() >= FLUSH_INTERVAL {
            self.flush()?;
        }
        Ok(())
    }

    pub fn flush(&mut self) -> io::Result<()> {
        self.flushed_at = Instant::now();
        self.out.flush().map_err(|e| with_path(e, &self.path))
    }

    /// Bytes in the file once flushed (header included).
    pub fn bytes_written(&self) -> u64 {
        self.bytes
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for CsvSeries {
    fn drop(&mut self) {
        let _ = self.out.flush();
    }
}

/// Writes a table of already formatted cells (text columns allowed). Cells containing a comma, quote or
/// newline are quoted.
pub fn write_table(path: &Path, header: &[&str], rows: &[Vec<String>]) -> io::Result<()> {
    let quote = |s: &str| {
        if s.contains([',', '"', '\n']) {
            format!("\"{}\"", s.replace('"', "\"\""))
        } else {
            s.to_owned()
        }
    };
    let mut out = String::new();
    out.push_str(&header.iter().map(|h| quote(h)).collect::<Vec<_>>().join(","));
    out.push('\n');
    for r in rows {
        out.push_str(&r.iter().map(|c| quote(c)).collect::<Vec<_>>().join(","));
        out.push('\n');
    }
    std::fs::write(path, out).map_err(|e| with_path(e, path))
}

/// Reads a numeric CSV written by [`CsvSeries`]: the header and the rows; an empty cell (a gap) reads
/// as NaN.
pub fn read_series(path: &Path) -> io::Result<(Vec<String>, Vec<Vec<f64>>)> {
    let text = std::fs::read_to_string(path).map_err(|e| with_path(e, path))?;
    let mut lines = text.lines();
    let header: Vec<String> = lines.next().unwrap_or("").split(',').map(str::to_owned).collect();
    let mut rows = Vec::new();
    for (i, l) in lines.enumerate() {
        let row: Result<Vec<f64>, _> =
            l.split(',').map(|c| if c.is_empty() { Ok(f64::NAN) } else { c.parse() }).collect();
        rows.push(row.map_err(|_| {
            io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{} line {}: not numbers", path.display(), i + 2),
            )
        })?);
    }
    Ok((header, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resume_cuts_back_and_appends() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.csv");
        let mut a = CsvSeries::create(&p, &["t_s", "ke_J"]).unwrap();
        a.row(&[0.0, 1.0]).unwrap();
        let mark = a.bytes_written();
        a.row(&[0.1, 0.5]).unwrap(); // written after the checkpoint, lost on interruption
        drop(a);
        let mut b = CsvSeries::resume(&p, &["t_s", "ke_J"], mark).unwrap();
        b.row(&[0.1, 0.25]).unwrap();
        drop(b);
        let (h, rows) = read_series(&p).unwrap();
        assert_eq!(h, vec!["t_s", "ke_J"]);
        assert_eq!(rows, vec![vec![0.0, 1.0], vec![0.1, 0.25]]);
        let mut c = CsvSeries::create(&p, &["a"]).unwrap();
        assert!(c.row(&[1.0, 2.0]).is_err(), "width mismatch is an error");
        assert!(c.row_with_gaps(&[None, None]).is_err(), "width mismatch is an error");
    }

    /// Undefined values are empty cells that read back as NaN; a NaN passed to `row` stays visible.
    #[test]
    fn gaps_are_empty_cells_and_nan_stays_nan() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("g.csv");
        let mut a = CsvSeries::create(&p, &["t_s", "p_Pa", "v_m_s"]).unwrap();
        a.row_with_gaps(&[Some(0.5), None, Some(-2.0)]).unwrap();
        a.row(&[1.0, f64::NAN, 3.0]).unwrap();
        drop(a);
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "t_s,p_Pa,v_m_s\n0.5,,-2\n1,NaN,3\n");
        let (_, rows) = read_series(&p).unwrap();
        assert_eq!(rows[0][0], 0.5);
        assert!(rows[0][1].is_nan() && rows[1][1].is_nan());
        assert_eq!(rows[1][2], 3.0);
    }

    /// A row written after FLUSH_INTERVAL is on disk with the rows before it while the series is still
    /// open (a running job's table can be watched).
    #[test]
    fn rows_reach_the_disk_while_the_series_is_open() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("s.csv");
        let mut a = CsvSeries::create(&p, &["t_s"]).unwrap();
        a.row(&[0.0]).unwrap();
        std::thread::sleep(FLUSH_INTERVAL + Duration::from_millis(50));
        a.row(&[1.0]).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "t_s\n0\n1\n");
        drop(a);
    }
}
