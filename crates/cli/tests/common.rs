//! Helpers for running the `spatter` binary in tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn spatter() -> Command {
    Command::new(env!("CARGO_BIN_EXE_spatter"))
}

/// Writes `bytes` as `name` in `dir` and returns its path.
pub fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Runs `spatter check <file>` and returns (exit code, stderr).
pub fn check(file: &Path) -> (i32, String) {
    let out: Output = spatter().arg("check").arg(file).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Asserts that checking `text` fails with exit code 2, without a panic, and that stderr holds every
/// fragment in `expect`.
pub fn rejects(name: &str, text: &[u8], expect: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), name, text);
    let (code, err) = check(&f);
    assert!(!err.contains("panicked"), "panic on {name}:\n{err}");
    assert_eq!(code, 2, "exit code for {name}; stderr:\n{err}");
    for e in expect {
        assert!(err.contains(e), "{name}: expected `{e}` in:\n{err}");
    }
}

/// Files that legitimately differ between two runs of the same input: the log (timestamps), the summary
/// and the report (wall time).
pub const SESSION_FILES: &[&str] = &["log.txt", "summary.json", "report.html"];

/// Every file of a run folder but the [`SESSION_FILES`], by path relative to `root`.
pub fn run_files(root: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    fn walk(root: &Path, dir: &Path, out: &mut std::collections::BTreeMap<PathBuf, Vec<u8>>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                let rel = p.strip_prefix(root).unwrap().to_owned();
                if !SESSION_FILES.iter().any(|s| rel == Path::new(s)) {
                    out.insert(rel, std::fs::read(&p).unwrap());
                }
            }
        }
    }
    let mut out = std::collections::BTreeMap::new();
    walk(root, root, &mut out);
    out
}

/// The two run folders hold the same files (but the [`SESSION_FILES`]), byte for byte; `what` names the
/// comparison in the failure message.
pub fn assert_same_files(a: &Path, b: &Path, what: &str) {
    let (fa, fb) = (run_files(a), run_files(b));
    assert!(!fa.is_empty(), "{what}: {} holds no files", a.display());
    assert_eq!(
        fa.keys().collect::<Vec<_>>(),
        fb.keys().collect::<Vec<_>>(),
        "{what}: the runs wrote other files"
    );
    for (name, bytes) in &fa {
        assert!(bytes == &fb[name], "{what}: {} differs", name.display());
    }
}
