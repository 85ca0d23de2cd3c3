//! `spatter run` under a real `mpirun` (OpenMPI), in a build with the `mpi` feature:
//! `cargo test -p spatter-cli --features mpi --test mpi_ranks` (CI runs it; needs libopenmpi-dev).
//! One rank under mpirun is the ordinary run, file for file; several ranks are refused by every rank with
//! one sentence on rank 0, before anything is written, and never hang.
#![cfg(feature = "mpi")]

mod common;
use common::assert_same_files;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

/// Seconds after which a hung job is killed (`timeout`), so a broken rank makes the test fail, not hang.
const KILL_AFTER_S: u64 = 120;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples").join(name)
}

fn mpirun(ranks: usize, args: &[&str]) -> Output {
    let out = Command::new("timeout")
        .arg(KILL_AFTER_S.to_string())
        .args(["mpirun", "--oversubscribe", "-n", &ranks.to_string(), env!("CARGO_BIN_EXE_spatter")])
        .args(args)
        // Containers and CI often run as root; OpenMPI refuses that unless told.
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .expect("mpirun starts (install libopenmpi-dev / openmpi-bin)");
    assert_ne!(out.status.code(), Some(124), "mpirun -n {ranks} hung for {KILL_AFTER_S} s");
    out
}

fn plain(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spatter")).args(args).output().unwrap()
}

#[test]
fn one_rank_under_mpirun_is_the_ordinary_run() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = example("sph_dam_break.toml");
    let scenario = scenario.to_str().unwrap();
    let a = tmp.path().join("plain");
    let b = tmp.path().join("mpirun1");
    let run = |out: &Path| {
        ["run", scenario, "--smoke", "--threads", "1", "--out", out.to_str().unwrap()].map(String::from)
    };
    let (ra, rb) = (run(&a), run(&b));
    let pa = plain(&ra.each_ref().map(String::as_str));
    assert!(pa.status.success(), "{}", String::from_utf8_lossy(&pa.stderr));
    let pb = mpirun(1, &rb.each_ref().map(String::as_str));
    assert!(pb.status.success(), "{}", String::from_utf8_lossy(&pb.stderr));
    assert_same_files(&a, &b, "a plain run against mpirun -n 1");
}

#[test]
fn several_ranks_are_refused_once_before_anything_is_written() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("two");
    let scenario = example("sph_dam_break.toml");
    let started = std::time::Instant::now();
    let o = mpirun(
        2,
        &["run", scenario.to_str().unwrap(), "--smoke", "--threads", "1", "--out", out.to_str().unwrap()],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.matches("started on 2 ranks").count(), 1, "one sentence, from rank 0: {err}");
    assert!(err.contains("kind `sph` runs in one process"), "{err}");
    assert!(!out.exists(), "nothing written");
    assert!(started.elapsed() < Duration::from_secs(60));
    // Commands other than `run` are refused under several ranks as well.
    let v = mpirun(2, &["validate", "--quick"]);
    assert_eq!(v.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&v.stderr).matches("only `spatter run`").count(), 1);
}
