//! Physical validation of inputs, with the dotted key path of every bad value.
//!
//! Engine and workflow configurations implement [`Validate`]; the scenario layer turns each [`Invalid`]
//! into a message naming the file, line:column, key, value and the expected range. A library user who
//! builds configurations in Rust gets the same checks without any file.
//!
//! ```
//! use spatter_core::check::{Checker, Validate};
//! struct Ball { radius: f64, restitution: f64 }
//! impl Validate for Ball {
//!     fn validate(&self, c: &mut Checker) {
//!         c.positive("radius", self.radius);
//!         c.in_range("restitution", self.restitution, 0.0, false, 1.0, true);
//!     }
//! }
//! let errs = Checker::run(&Ball { radius: -1.0, restitution: 1.5 }, None).unwrap_err();
//! assert_eq!(errs[0].key, "radius");
//! assert_eq!(errs[1].message, "restitution = 1.5 is outside (0, 1]");
//! ```

use std::path::{Path, PathBuf};

/// One value that failed its check.
#[derive(Clone, Debug, PartialEq)]
pub struct Invalid {
    /// Dotted path of the key, e.g. `materials.ice.poisson_ratio` or `walls[2].radius`.
    pub key: String,
    /// A sentence naming the value and the expected form, e.g. `poisson_ratio = 0.6 is outside [0, 0.5)`.
    pub message: String,
}

/// Something whose values can be checked before a run starts.
pub trait Validate {
    fn validate(&self, c: &mut Checker);
}

/// Collects [`Invalid`] entries while walking a configuration.
#[derive(Debug, Default)]
pub struct Checker {
    prefix: Vec<String>,
    errors: Vec<Invalid>,
    base_dir: Option<PathBuf>,
}

impl Checker {
    /// A checker; relative file paths are resolved against `base_dir` (the scenario file's folder).
    pub fn new(base_dir: Option<&Path>) -> Self {
        Checker { base_dir: base_dir.map(Path::to_owned), ..Default::default() }
    }

    /// Validates `item` and returns every problem found.
    pub fn run<T: Validate + ?Sized>(item: &T, base_dir: Option<&Path>) -> Result<(), Vec<Invalid>> {
        let mut c = Checker::new(base_dir);
        item.validate(&mut c);
        c.finish()
    }

    pub fn finish(self) -> Result<(), Vec<Invalid>> {
        if self.errors.is_empty() {
            Ok(())
        } else {
            Err(self.errors)
        }
    }

    /// Full dotted path of `key` under the current prefix.
    pub fn path(&self, key: &str) -> String {
        let mut s = String::new();
        for p in &self.prefix {
            if !s.is_empty() && !p.starts_with('[') {
                s.push('.');
            }
            s.push_str(p);
        }
        if !key.is_empty() {
            if !s.is_empty() && !key.starts_with('[') {
                s.push('.');
            }
            s.push_str(key);
        }
        s
    }

    /// Records a problem with `key` (relative to the current prefix).
    pub fn fail(&mut self, key: &str, message: impl Into<String>) {
        let key = self.path(key);
        self.errors.push(Invalid { key, message: message.into() });
    }

    /// Checks the fields of a nested table `key`.
    pub fn nested(&mut self, key: &str, f: impl FnOnce(&mut Checker)) {
        self.prefix.push(key.to_owned());
        f(self);
        self.prefix.pop();
    }

    /// Checks element `index` of array `key`.
    pub fn element(&mut self, key: &str, index: usize, f: impl FnOnce(&mut Checker)) {
        self.prefix.push(key.to_owned());
        self.prefix.push(format!("[{index}]"));
        f(self);
        self.prefix.pop();
        self.prefix.pop();
    }

    /// Validates a nested item that implements [`Validate`].
    pub fn item<T: Validate + ?Sized>(&mut self, key: &str, item: &T) {
        self.nested(key, |c| item.validate(c));
    }

    /// The last segment of `key`, used as the value's name in messages.
    fn name(key: &str) -> &str {
        key.rsplit('.').next().unwrap_or(key)
    }

    /// `v` must be finite and > 0.
    pub fn positive(&mut self, key: &str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(key, format!("{} = {} must be a positive number", Self::name(key), v));
        }
    }

    /// `v` must be finite and ≥ 0.
    pub fn non_negative(&mut self, key: &str, v: f64) {
        if !(v.is_finite() && v >= 0.0) {
            self.fail(key, format!("{} = {} must be zero or positive", Self::name(key), v));
        }
    }

    /// `v` must be finite.
    pub fn finite(&mut self, key: &str, v: f64) {
        if !v.is_finite() {
            self.fail(key, format!("{} = {} must be a finite number", Self::name(key), v));
        }
    }

    /// `v` must lie in the interval from `lo` to `hi`, each end open or closed; the message prints the
    /// interval in the usual bracket notation, e.g. `e = 1.5 is outside (0, 1]`.
    pub fn in_range(&mut self, key: &str, v: f64, lo: f64, lo_closed: bool, hi: f64, hi_closed: bool) {
        let ok_lo = if lo_closed { v >= lo } else { v > lo };
        let ok_hi = if hi_closed { v <= hi } else { v < hi };
        if !(ok_lo && ok_hi) || v.is_nan() {
            let l = if lo_closed { '[' } else { '(' };
            let r = if hi_closed { ']' } else { ')' };
            self.fail(key, format!("{} = {} is outside {l}{lo}, {hi}{r}", Self::name(key), v));
        }
    }

    /// Every component of a vector must be finite.
    pub fn finite_vec(&mut self, key: &str, v: crate::Vec3) {
        if !crate::math::is_finite(v) {
            self.fail(
                key,
                format!("{} = [{}, {}, {}] must have finite components", Self::name(key), v.x, v.y, v.z),
            );
        }
    }

    /// `path` (relative to the scenario's folder unless absolute) must name an existing file.
    pub fn file_exists(&mut self, key: &str, path: &Path) {
        let full = self.resolve(path);
        if full.is_dir() {
            self.fail(
                key,
                format!(
                    "{} = \"{}\" is a folder ({}); give the file inside it",
                    Self::name(key),
                    path.display(),
                    full.display()
                ),
            );
        } else if !full.is_file() {
            self.fail(
                key,
                format!("{} = \"{}\": no such file ({})", Self::name(key), path.display(), full.display()),
            );
        }
    }

    /// `path` (relative to the scenario's folder unless absolute) must name a mesh file (STL/OBJ) that
    /// reads and is valid: triangles present, every coordinate finite, no zero-area triangle (see
    /// [`crate::mesh::TriMesh::load`]). The message names the key, the file and the line or triangle.
    pub fn mesh_file(&mut self, key: &str, path: &Path) {
        let full = self.resolve(path);
        if !full.is_file() {
            return self.file_exists(key, path);
        }
        if let Err(e) = crate::mesh::TriMesh::load(&full, 1.0) {
            self.fail(key, format!("{} = \"{}\": {e}", Self::name(key), path.display()));
        }
    }

    /// `path` must name a motion table (`t vx vy vz wx wy wz` rows, times increasing) that parses; the
    /// message names the key, the file and the line.
    pub fn motion_table_file(&mut self, key: &str, path: &Path) {
        let full = self.resolve(path);
        if !full.is_file() {
            return self.file_exists(key, path);
        }
        let parsed = std::fs::read_to_string(&full).map_err(|e| e.to_string()).and_then(|t| {
            crate::motion::MotionTable::parse(&t, crate::Vec3::ZERO).map_err(|e| e.to_string())
        });
        if let Err(e) = parsed {
            self.fail(key, format!("{} = \"{}\": {e}", Self::name(key), path.display()));
        }
    }

    /// Refuses a run whose estimated memory `bytes` exceeds this machine's physical memory (1 TiB where
    /// it cannot be read): `what` says what was estimated and from which values, so the user can see
    /// which key to change. Checked before anything is allocated.
    pub fn memory_estimate(&mut self, key: &str, what: &str, bytes: f64) {
        let (limit, whose) = match physical_memory_bytes() {
            Some(m) => (m as f64, "this machine's memory"),
            None => (1024f64.powi(4), "the 1 TiB limit"),
        };
        if bytes.is_nan() || bytes > limit {
            self.fail(
                key,
                format!(
                    "{what} needs about {} of memory, more than {whose} ({}); choose a coarser or smaller setting",
                    fmt_bytes(bytes),
                    fmt_bytes(limit)
                ),
            );
        }
    }

    /// `path` resolved against the scenario's folder.
    pub fn resolve(&self, path: &Path) -> PathBuf {
        match &self.base_dir {
            Some(b) if path.is_relative() => b.join(path),
            _ => path.to_owned(),
        }
    }
}

/// Physical memory of this machine in bytes (Linux `/proc/meminfo`), if it can be read.
pub fn physical_memory_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// `bytes` as "12.3 GB" (decimal units).
pub fn fmt_bytes(bytes: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = bytes;
    let mut k = 0;
    while v >= 1000.0 && k + 1 < units.len() {
        v /= 1000.0;
        k += 1;
    }
    if k + 1 == units.len() && v >= 1000.0 {
        return format!("{bytes:.3e} B");
    }
    format!("{v:.1} {}", units[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_memory_is_refused_with_the_estimate() {
        let mut c = Checker::new(None);
        c.memory_estimate("spacing_m", "1.2e9 particles × 300 B", 3.6e11 * 1e6);
        c.memory_estimate("count", "a few particles", 1e6);
        let e = c.finish().unwrap_err();
        assert_eq!(e.len(), 1, "{e:?}");
        assert_eq!(e[0].key, "spacing_m");
        assert!(
            e[0].message.contains("1.2e9 particles") && e[0].message.contains("memory"),
            "{}",
            e[0].message
        );
        assert_eq!(fmt_bytes(1.5e9), "1.5 GB");
        assert_eq!(fmt_bytes(999.0), "999.0 B");
    }

    #[test]
    fn paths_and_messages() {
        let mut c = Checker::new(None);
        c.nested("materials", |c| {
            c.nested("ice", |c| c.in_range("poisson_ratio", 0.6, 0.0, true, 0.5, false));
        });
        c.element("walls", 2, |c| c.positive("radius", -3.0));
        c.file_exists("mesh", Path::new("/definitely/not/here.stl"));
        let e = c.finish().unwrap_err();
        assert_eq!(e[0].key, "materials.ice.poisson_ratio");
        assert_eq!(e[0].message, "poisson_ratio = 0.6 is outside [0, 0.5)");
        assert_eq!(e[1].key, "walls[2].radius");
        assert_eq!(e[1].message, "radius = -3 must be a positive number");
        assert!(e[2].message.contains("no such file"), "{}", e[2].message);
        // A folder where a file belongs says so (it used to read "no such file" for a path that exists).
        let dir = std::env::temp_dir();
        let mut c = Checker::new(None);
        c.file_exists("bed.file", &dir);
        c.mesh_file("walls[0].shape.file", &dir);
        let e = c.finish().unwrap_err();
        assert_eq!(e.len(), 2);
        for e in &e {
            assert!(
                e.message.contains("is a folder") && !e.message.contains("no such file"),
                "{}",
                e.message
            );
        }
    }
}
