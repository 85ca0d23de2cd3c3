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
