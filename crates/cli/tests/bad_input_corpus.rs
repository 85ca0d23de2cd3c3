//! The bad-input corpus (`tests/bad_input/`): malformed files, wrong types, out-of-range physics, broken
//! referenced files, absurd sizes and settings that would make a run do nothing. Each file is run with
//! `spatter run` as a hostile user would: it must end within seconds with a specific error (the
//! fragments its `# expect:` lines name) and a non-zero exit code — never a panic, an abort, a hang, or
//! exit 0.

mod common;
use common::*;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// Longest a refused input may take.
const LIMIT: Duration = Duration::from_secs(20);

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/bad_input")
}

/// Runs `spatter run file`, killing it after [`LIMIT`]; returns (exit code, stdout + stderr, seconds).
fn run_limited(file: &Path, out: &Path) -> (Option<i32>, String, f64) {
    let t = Instant::now();
    let mut child = spatter()
        .arg("run")
        .arg(file)
        .arg("--out")
        .arg(out)
        .env("SPATTER_NO_PROGRESS", "1")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut text = String::new();
            child.stdout.take().unwrap().read_to_string(&mut text).unwrap();
            child.stderr.take().unwrap().read_to_string(&mut text).unwrap();
            return (status.code(), text, t.elapsed().as_secs_f64());
        }
        if t.elapsed() > LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            let note = format!("still running after {LIMIT:?}: a hang, or work that was not estimated");
            return (None, note, t.elapsed().as_secs_f64());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn every_bad_input_is_refused_with_a_specific_error() {
    let mut files: Vec<PathBuf> = std::fs::read_dir(corpus())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 60, "the corpus holds {} files, at least 60 expected", files.len());
    let tmp = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    for f in &files {
        let name = f.file_stem().unwrap().to_string_lossy().into_owned();
        let text = std::fs::read_to_string(f).unwrap_or_default();
        let expect: Vec<String> =
            text.lines().filter_map(|l| l.strip_prefix("# expect: ")).map(str::to_owned).collect();
        assert!(!expect.is_empty(), "{name}: no `# expect:` line");
        let (code, output, secs) = run_limited(f, &tmp.path().join(&name));
        let mut problems = Vec::new();
        match code {
            Some(1) | Some(2) => {}
            other => problems.push(format!("exit code {other:?}, expected 1 or 2")),
        }
        if output.contains("panicked") {
            problems.push("panicked".into());
        }
        if !output.contains("error") {
            problems.push("no error message".into());
        }
        for e in &expect {
            if !output.contains(e.as_str()) {
                problems.push(format!("expected `{e}` in the message"));
            }
        }
        if !problems.is_empty() {
            failures.push(format!("{name} ({secs:.1} s): {}\n{output}", problems.join("; ")));
        }
    }
    assert!(failures.is_empty(), "{} of {} inputs:\n\n{}", failures.len(), files.len(), failures.join("\n"));
}
