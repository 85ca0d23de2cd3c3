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
        if !full.is_file() {
            self.fail(
                key,
                format!("{} = \"{}\": no such file ({})", Self::name(key), path.display(), full.display()),
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

#[cfg(test)]
mod tests {
    use super::*;

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
    }
}
