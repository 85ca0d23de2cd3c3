//! `spatter run` under a real `mpirun` (OpenMPI), in a build with the `mpi` feature:
//! `cargo test -p spatter-cli --features mpi --test mpi_ranks` (CI runs it; needs libopenmpi-dev).
//! One rank under mpirun is the ordinary run, file for file; the `sph` dam break on two ranks agrees with
//! it within the stated tolerance; kinds that do not run on several ranks are refused by every rank with
//! one sentence on rank 0, before anything is written, and never hang. A two-rank run stopped part-way
//! resumes on two ranks bit for bit, and on one rank with `--repartition` (refused without it). The DEM
//! hopper (mesh walls, injection) on two ranks agrees with one rank within the stated tolerance. A DEM
//! pile stopped on 2 ranks resumes on 1 and 2 ranks (and one stopped on 1 rank on 2) with `--repartition`
//! (refused without it); more ranks than particles is refused once on rank 0, never a hang. SIGTERM, to
//! `mpirun` or to every rank, stops a two-rank run with a checkpoint that resumes bit for bit.
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
    mpirun_env(ranks, args, &[])
}

/// [`mpirun`] with environment variables `envs` set on every rank (`-x`).
fn mpirun_env(ranks: usize, args: &[&str], envs: &[(&str, &str)]) -> Output {
    let mut c = Command::new("timeout");
    c.arg(KILL_AFTER_S.to_string()).args(["mpirun", "--oversubscribe", "-n", &ranks.to_string()]);
    for (k, v) in envs {
        c.args(["-x", k]).env(k, v);
    }
    let out = c
        .arg(env!("CARGO_BIN_EXE_spatter"))
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
    let scenario = example("snow_single.toml");
    let o = mpirun(
        2,
        &["run", scenario.to_str().unwrap(), "--smoke", "--threads", "1", "--out", out.to_str().unwrap()],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.matches("started on 2 ranks").count(), 1, "one sentence, from rank 0: {err}");
    assert!(err.contains("kind `snow_regime_map` runs in one process"), "{err}");
    assert!(!out.exists(), "nothing written");
    // Commands other than `run` are refused under several ranks as well.
    let v = mpirun(2, &["validate", "--quick"]);
    assert_eq!(v.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&v.stderr).matches("only `spatter run`").count(), 1);
}

/// Rows of a CSV file of numbers (empty cells as NaN) and its header.
fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines.map(|l| l.split(',').map(|v| v.parse().unwrap_or(f64::NAN)).collect()).collect();
    (head, rows)
}

/// Every `series.csv` column of run folder `b` within 10⁻⁶ of its scale of `a` (the largest magnitude of
/// the column in `a`, or of the force or moment vector it belongs to; 10⁻⁴ for the arrival rate of water
/// at a wall); particle and step counts exact.
fn assert_series_close(a: &Path, b: &Path, what: &str) {
    let (cols, rows1) = read_csv(&a.join("series.csv"));
    let (cols2, rows2) = read_csv(&b.join("series.csv"));
    assert_eq!(cols, cols2);
    assert_eq!(rows1.len(), rows2.len());
    let group = |name: &str| -> Vec<usize> {
        let members: Vec<usize> = if name.contains("_F") && name.ends_with("_N") {
            cols.iter()
                .enumerate()
                .filter(|(_, c)| c.contains("_F") && c.ends_with("_N"))
                .map(|(k, _)| k)
                .collect()
        } else if name.contains("_M") && name.ends_with("_Nm") {
            cols.iter()
                .enumerate()
                .filter(|(_, c)| c.contains("_M") && c.ends_with("_Nm"))
                .map(|(k, _)| k)
                .collect()
        } else {
            vec![cols.iter().position(|c| c == name).unwrap()]
        };
        members
    };
    for (k, name) in cols.iter().enumerate() {
        let scale = rows1
            .iter()
            .flat_map(|r| group(name).into_iter().map(move |j| r[j].abs()))
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        for (r1, r2) in rows1.iter().zip(&rows2) {
            let (x, y) = (r1[k], r2[k]);
            assert_eq!(x.is_nan(), y.is_nan(), "{what}, column {name}: {x} vs {y}");
            if name == "particles" || name == "step" {
                assert_eq!(x, y, "{what}, column {name}");
            } else if x.is_finite() {
                // The arrival rate of water at a wall sums the normal velocities of the water next to it,
                // which early in a run are tiny against the flow's speed whose round-off they carry
                // (measured: 2.4·10⁻⁶ of the column's scale on the dam break's first steps).
                let rel = if name.ends_with("_water_arrival_m3_s") { 1e-4 } else { 1e-6 };
                assert!((x - y).abs() <= rel * scale, "{what}, column {name}: {y} vs {x} (scale {scale})");
            }
        }
    }
}

/// The table `file` of run folder `b` against that of `a`: the same header and rows, every number within
/// 10⁻⁹ of its column's scale in `a` (the largest magnitude), the same empty cells.
fn assert_table_close(a: &Path, b: &Path, file: &str) {
    let ((cols, x), (cols2, y)) = (read_csv(&a.join(file)), read_csv(&b.join(file)));
    assert_eq!(cols, cols2, "{file}");
    assert_eq!(x.len(), y.len(), "{file} rows");
    for k in 0..cols.len() {
        let scale = x.iter().map(|r| r[k].abs()).filter(|v| v.is_finite()).fold(0.0, f64::max);
        for (r1, r2) in x.iter().zip(&y) {
            let (u, v) = (r1[k], r2[k]);
            assert!(
                (u.is_nan() && v.is_nan()) || (u - v).abs() <= 1e-9 * scale,
                "{file}, {}: {v} against {u}",
                cols[k]
            );
        }
    }
}

/// Runs `scenario` with `extra` arguments and `--threads 1` plainly into `dir/plain` and on two ranks
/// into `dir/mpirun2`, both to success; returns the two run folders.
fn plain_and_two_ranks(dir: &Path, scenario: &str, extra: &[&str]) -> (PathBuf, PathBuf) {
    let (a, b) = (dir.join("plain"), dir.join("mpirun2"));
    for (out, ranks) in [(&a, 1), (&b, 2)] {
        let mut args = vec!["run", scenario, "--threads", "1", "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = if ranks == 1 { plain(&args) } else { mpirun(ranks, &args) };
        assert!(o.status.success(), "{ranks} rank(s): {}", String::from_utf8_lossy(&o.stderr));
    }
    (a, b)
}

/// The 3D dam break (`--smoke`) on two ranks against a plain run: every `series.csv` column within 10⁻⁶
/// of its scale (the largest magnitude of the column, or of the force or moment vector it belongs to):
/// pairs across the rank cut are evaluated in double precision, the others in single precision, so the
/// runs differ at that rounding (measured: 1.1·10⁻⁹ for the kinetic energy, 7·10⁻⁹ for the tank load);
/// counts exact. Each output is a `.pvtu` of one piece per rank, holding every particle once.
#[test]
fn two_ranks_match_one_rank() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = example("sph_dam_break.toml");
    let (a, b) = plain_and_two_ranks(tmp.path(), scenario.to_str().unwrap(), &["--smoke"]);
    assert_series_close(&a, &b, "two ranks against one");
    let pvtu = std::fs::read_to_string(b.join("particles/particles_00001.pvtu")).unwrap();
    assert!(pvtu.contains("particles_00001_r0000.vtu") && pvtu.contains("particles_00001_r0001.vtu"));
    let script = format!(
        "import vtk\nr = vtk.vtkXMLPUnstructuredGridReader()\nr.SetFileName({:?})\nr.Update()\n\
         print(r.GetOutput().GetNumberOfPoints())",
        b.join("particles/particles_00001.pvtu").to_str().unwrap()
    );
    // The system Python, where `.ci/run` installs python3-vtk9; a `python3` earlier on PATH may lack VTK.
    match Command::new("/usr/bin/python3").args(["-c", &script]).output() {
        Ok(o) if o.status.success() => assert_eq!(String::from_utf8_lossy(&o.stdout).trim(), "16000"),
        other => assert!(std::env::var("SPATTER_REQUIRE_VTK").is_err(), "VTK is required here: {other:?}"),
    }
}

/// Rebalancing under a real `mpirun`: the 3D dam break (its first 0.05 s) on two ranks with the split
/// rebuilt whenever it is not even (`domain.rebalance_imbalance = 1`; the first split is even, and the
/// collapsing column moves particles across the cut), against a plain run. The log reports the rebuilds
/// (measured 2026-11-27: one), and every `series.csv` column agrees with the plain run within the
/// tolerance of `two_ranks_match_one_rank` (10⁻⁶ of its scale): moving the cut changes only which pairs
/// are summed in double precision.
#[test]
fn rebalancing_on_two_ranks_matches_one_rank() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example("sph_dam_break.toml"))
        .unwrap()
        .replace("end_time_s = 0.8", "end_time_s = 0.05")
        .replace("vtu_interval_s = 0.02", "vtu_interval_s = 0.05")
        + "\n[domain]\nrebalance_imbalance = 1.0\n";
    let scenario = common::write(tmp.path(), "dam.toml", text.as_bytes());
    let (a, b) = plain_and_two_ranks(tmp.path(), scenario.to_str().unwrap(), &[]);
    let log = std::fs::read_to_string(b.join("log.txt")).unwrap();
    let line = log.lines().find(|l| l.contains("load balance:")).expect("the log reports the load balance");
    let count: usize = line
        .split("rebuilt ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("a count of rebuilds in {line:?}"));
    eprintln!("{line}");
    assert!(count >= 1, "{line}");
    assert_series_close(&a, &b, "two rebalanced ranks against one");
}

/// The wading workflow on two ranks: the example truck (`--smoke`: 10 cm spacing, 20 ms, with the
/// surface tension and wall adhesion of the example) against a plain run. Rank 0 writes the geometry the
/// ranks read and the reports; `series.csv` agrees within the tolerance of `two_ranks_match_one_rank`
/// (measured 2026-11-27: 5·10⁻¹¹ of a column's magnitude), and the wet areas per part, the sensors'
/// wet fractions and the splash heights within 10⁻⁹ of their scale.
#[test]
fn wading_on_two_ranks_matches_one_rank() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = example("wading_truck.toml");
    let (a, b) = plain_and_two_ranks(tmp.path(), scenario.to_str().unwrap(), &["--smoke"]);
    assert_series_close(&a, &b, "wading on two ranks against one");
    for file in ["wetting.csv", "sensors.csv", "splash_height.csv", "wetting_groups.csv"] {
        assert_table_close(&a, &b, file);
    }
}

/// The command line of a `--smoke` dam break into `out` with `extra` arguments.
fn dam_break(out: &Path, extra: &[&str]) -> Vec<String> {
    let scenario = example("sph_dam_break.toml");
    let mut a: Vec<String> =
        ["run", scenario.to_str().unwrap(), "--smoke", "--threads", "1", "--out"].map(String::from).to_vec();
    a.push(out.to_str().unwrap().into());
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

fn strs(a: &[String]) -> Vec<&str> {
    a.iter().map(String::as_str).collect()
}

/// Two ranks stopped after 15 polls of 37 steps (a checkpoint written at every poll, by both ranks) and resumed on
/// two ranks: every file byte for byte as the uninterrupted two-rank run. The same checkpoint on one rank
/// is refused without `--repartition` (exit 2, one sentence, nothing changed) and continues with it,
/// within 10⁻⁶ of each `series.csv` column's scale of the uninterrupted two-rank run (the pairs across the
/// rank cut are summed in another precision and order once the fluid is on one rank; see
/// `two_ranks_match_one_rank`), the particle count exact.
#[test]
fn two_ranks_resume_on_two_and_on_one() {
    let tmp = tempfile::tempdir().unwrap();
    let (whole, split, one) = (tmp.path().join("whole"), tmp.path().join("split"), tmp.path().join("one"));
    let o = mpirun(2, &strs(&dam_break(&whole, &[])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // The second run logs debug messages: rank 1's go to its own log, which rank 0's log names.
    for (dir, log) in [(&split, "info"), (&one, "debug")] {
        let envs = [("SPATTER_STOP_AFTER_POLLS", "15"), ("RUST_LOG", log)];
        let o = mpirun_env(2, &strs(&dam_break(dir, &["--checkpoint-interval-s", "1e-9"])), &envs);
        assert_eq!(o.status.code(), Some(130), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(dir.join("checkpoint.bin").is_file());
        assert!(dir.join("checkpoint").read_dir().unwrap().count() == 2, "one part per rank");
    }
    assert!(!split.join("ranks").exists(), "rank 1 had nothing to say at level info");
    let rank1 = std::fs::read_to_string(one.join("ranks/log_r0001.txt")).unwrap();
    assert!(rank1.contains("checkpoint part 1 written"), "{rank1}");
    let log0 = std::fs::read_to_string(one.join("log.txt")).unwrap();
    assert!(log0.contains("see ranks/log_r0001.txt") && !log0.contains("checkpoint part 1"), "{log0}");
    let o = mpirun(2, &strs(&dam_break(&split, &["--resume"])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!split.join("checkpoint.bin").exists() && !split.join("checkpoint").exists());
    assert_same_files(&whole, &split, "two ranks against two ranks stopped and resumed on two");
    // Another rank count: refused on rank 0 with one sentence, before anything changes.
    let before = common::run_files(&one);
    let o = mpirun(1, &strs(&dam_break(&one, &["--resume"])));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(
        err.matches("written by 2 ranks and this run has 1 rank: add --repartition").count(),
        1,
        "{err}"
    );
    assert!(before == common::run_files(&one), "a refused resume changes nothing");
    let o = mpirun(1, &strs(&dam_break(&one, &["--resume", "--repartition"])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_series_close(&whole, &one, "two ranks against two resumed on one");
    // `--repartition` needs `--resume`.
    let o = mpirun(2, &strs(&dam_break(&tmp.path().join("fresh"), &["--repartition"])));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.matches("it needs --resume").count(), 1, "{err}");
}

/// A wading run on two ranks stopped at a checkpoint and resumed on two ranks writes every file byte
/// for byte as the uninterrupted two-rank run (the example truck, `--smoke`): the scene's state, the
/// wetting records and the reports rank 0 writes from them. Resumed on one rank with `--repartition`,
/// its `series.csv` agrees with the two-rank run as a one-rank run does.
#[test]
fn wading_on_two_ranks_resumes_bit_for_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = example("wading_truck.toml");
    let run = |out: &Path, extra: &[&str]| {
        let mut a = vec![
            "run",
            scenario.to_str().unwrap(),
            "--smoke",
            "--threads",
            "1",
            "--out",
            out.to_str().unwrap(),
        ];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let (whole, split) = (tmp.path().join("whole"), tmp.path().join("split"));
    let o = mpirun(2, &strs(&run(&whole, &[])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let one = tmp.path().join("one");
    let envs = [("SPATTER_STOP_AFTER_POLLS", "3")];
    for dir in [&split, &one] {
        let o = mpirun_env(2, &strs(&run(dir, &["--checkpoint-interval-s", "1e-9"])), &envs);
        assert_eq!(o.status.code(), Some(130), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(dir.join("checkpoint").read_dir().unwrap().count() == 2, "one part per rank");
    }
    let o = mpirun(2, &strs(&run(&split, &["--resume"])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_same_files(&whole, &split, "wading on two ranks against two ranks stopped and resumed on two");
    // On another rank count: within the tolerance of `two_ranks_match_one_rank`.
    let o = mpirun(1, &strs(&run(&one, &["--resume", "--repartition"])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_series_close(&whole, &one, "wading on two ranks against two resumed on one");
}

/// An `mpirun` started by a test: killed with its ranks when the test ends before it does (a failed
/// assertion, a hang), so that no rank outlives the test.
struct Job(std::process::Child);

impl Drop for Job {
    fn drop(&mut self) {
        if matches!(self.0.try_wait(), Ok(None)) {
            let mut pids: Vec<String> = children(self.0.id()).iter().map(u32::to_string).collect();
            pids.push(self.0.id().to_string());
            let _ = Command::new("sh").arg("-c").arg(format!("kill -KILL {}", pids.join(" "))).status();
            let _ = self.0.wait();
        }
    }
}

/// The processes whose parent is `pid` (from `/proc`).
fn children(pid: u32) -> Vec<u32> {
    let mut out = Vec::new();
    for e in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(p) = e.file_name().to_string_lossy().parse::<u32>() else { continue };
        let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else { continue };
        // pid (comm) state ppid …: the command may hold spaces, so read after its closing parenthesis.
        let after = &stat[stat.rfind(')').map_or(0, |k| k + 1)..];
        if after.split_whitespace().nth(1).and_then(|v| v.parse::<u32>().ok()) == Some(pid) {
            out.push(p);
        }
    }
    out
}

/// SIGTERM during a run on two ranks, as a batch system sends it at the end of a job's time, both ways it
/// arrives: (1) to `mpirun`, which delivers it to the ranks `odls_base_sigkill_timeout` seconds later and
/// kills them as long again after that (OpenMPI 4.1; measured: with 60 s nothing reaches the ranks for a
/// minute, so a long timeout only delays the stop; 3 s here); (2) to every rank at once, as Slurm signals
/// the tasks of a job step. Either way every rank stops after the same step and writes its checkpoint
/// part, the summary says "interrupted", and the run resumed on two ranks writes every file byte for byte
/// as the uninterrupted two-rank run. The run is the 3D dam break to 0.15 s (about 2 200 steps, 40 s here; long
/// against the 4 s before the forwarded signal arrives, on a faster machine too); the signal
/// goes out a second after the run folder's log appears (the handler is installed before the log is
/// opened), well before the end.
#[test]
fn sigterm_stops_every_rank_with_a_checkpoint_that_resumes_bit_for_bit() {
    use std::process::Stdio;
    use std::time::Instant;
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example("sph_dam_break.toml"))
        .unwrap()
        .replace("end_time_s = 0.8", "end_time_s = 0.15")
        .replace("vtu_interval_s = 0.02", "vtu_interval_s = 0.05");
    let scenario = common::write(tmp.path(), "dam.toml", text.as_bytes());
    let scenario = scenario.to_str().unwrap();
    let run = |out: &Path, extra: &[&str]| {
        let mut a = vec!["run", scenario, "--threads", "1", "--out", out.to_str().unwrap()];
        a.extend_from_slice(extra);
        a.into_iter().map(String::from).collect::<Vec<_>>()
    };
    let whole = tmp.path().join("whole");
    let o = mpirun(2, &strs(&run(&whole, &[])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for (name, to_ranks) in [("mpirun", false), ("ranks", true)] {
        let out = tmp.path().join(name);
        let mut job = Job(Command::new("mpirun")
            .args(["--oversubscribe", "--mca", "odls_base_sigkill_timeout", "3", "-n", "2"])
            .arg(env!("CARGO_BIN_EXE_spatter"))
            .args(run(&out, &[]))
            .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
            .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("mpirun starts"));
        let child = &mut job.0;
        let started = Instant::now();
        while !out.join("log.txt").is_file() {
            assert!(started.elapsed() < Duration::from_secs(60), "{name}: the run never opened its log");
            std::thread::sleep(Duration::from_millis(50));
        }
        std::thread::sleep(Duration::from_secs(1));
        let targets = if to_ranks { children(child.id()) } else { vec![child.id()] };
        assert_eq!(targets.len(), if to_ranks { 2 } else { 1 }, "{name}: both ranks run: {targets:?}");
        // The shell's own `kill` (no procps needed).
        let list: Vec<String> = targets.iter().map(u32::to_string).collect();
        let kill =
            Command::new("sh").arg("-c").arg(format!("kill -TERM {}", list.join(" "))).status().unwrap();
        assert!(kill.success(), "{name}: signal sent to {list:?}");
        let status = loop {
            if let Some(s) = child.try_wait().unwrap() {
                break s;
            }
            assert!(started.elapsed() < Duration::from_secs(KILL_AFTER_S), "{name}: mpirun did not end");
            std::thread::sleep(Duration::from_millis(100));
        };
        assert!(!status.success(), "{name}: stopped, not finished");
        let summary = std::fs::read_to_string(out.join("summary.json")).unwrap();
        assert!(summary.contains(r#""finished": "interrupted""#), "{name}: {summary}");
        assert!(out.join("checkpoint.bin").is_file(), "{name}");
        assert_eq!(out.join("checkpoint").read_dir().unwrap().count(), 2, "{name}: one part per rank");
        let o = mpirun(2, &strs(&run(&out, &["--resume"])));
        assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        assert_same_files(
            &whole,
            &out,
            &format!("two ranks against two stopped by SIGTERM to {name} and resumed"),
        );
    }
}

/// Every `energy.csv` column of run folder `b` within 10⁻⁹ of its scale in `a` (the largest magnitude of
/// the column); particle and step counts exact.
fn assert_energy_close(a: &Path, b: &Path, what: &str) {
    let (cols, rows1) = read_csv(&a.join("energy.csv"));
    let (cols2, rows2) = read_csv(&b.join("energy.csv"));
    assert_eq!(cols, cols2);
    assert_eq!(rows1.len(), rows2.len());
    for (k, name) in cols.iter().enumerate() {
        let scale = rows1.iter().map(|r| r[k].abs()).fold(0.0, f64::max);
        for (r1, r2) in rows1.iter().zip(&rows2) {
            if name == "particles" || name == "step" {
                assert_eq!(r1[k], r2[k], "{what}, column {name}");
            }
            let d = (r1[k] - r2[k]).abs();
            assert!(d <= 1e-9 * scale, "{what}, column {name}: {} vs {} (scale {scale})", r2[k], r1[k]);
        }
    }
}

/// The DEM hopper (STL hopper and plane walls, beads injected) on two ranks against a plain run, as
/// `--smoke` (40 steps: the run folder's layout, nothing injected yet) and shortened to 0.03 s (3 000
/// steps, three injections of beads falling towards the hopper): every `energy.csv` column within 10⁻⁹ of
/// its scale (a particle's contact forces are added in another order on two ranks, so the runs may differ
/// at round-off), particle and step counts exact; the particle outputs are `.pvtu` files of one piece per
/// rank, and the hopper's wall file is written once. The short run keeps its first split
/// (`rebalance_imbalance = inf`): its `dissipated_J` is round-off of the energy balance (about 10⁻¹⁶ J
/// at 0.03 s), and with balancing on the split follows the first injected beads, sums run in another
/// order and that column moves by 3.5·10⁻¹⁸ J, beyond 10⁻⁹ of its own scale.
#[test]
fn dem_hopper_on_two_ranks_matches_one_rank() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example("dem_hopper.toml")).unwrap();
    let stl = example("dem_hopper.stl");
    let short = tmp.path().join("hopper_short.toml");
    let text = text
        .replace("[engine]\n", "[engine]\nrebalance_imbalance = inf\n")
        .replace("duration_s = 1.5", "duration_s = 0.03")
        .replace("output_interval_s = 0.02", "output_interval_s = 0.01")
        .replace("\"dem_hopper.stl\"", &format!("{:?}", stl.to_str().unwrap()));
    std::fs::write(&short, text).unwrap();
    let smoke = example("dem_hopper.toml");
    for (scenario, extra) in [(smoke.as_path(), Some("--smoke")), (short.as_path(), None)] {
        let name = scenario.file_stem().unwrap().to_str().unwrap();
        let (a, b) = (tmp.path().join(format!("{name}_plain")), tmp.path().join(format!("{name}_mpirun2")));
        let args = |out: &Path| {
            let mut v = vec!["run".to_string(), scenario.to_str().unwrap().into()];
            v.extend(extra.map(String::from));
            v.extend(["--threads", "1", "--out", out.to_str().unwrap()].map(String::from));
            v
        };
        let pa = plain(&strs(&args(&a)));
        assert!(pa.status.success(), "{}", String::from_utf8_lossy(&pa.stderr));
        let pb = mpirun(2, &strs(&args(&b)));
        assert!(pb.status.success(), "{}", String::from_utf8_lossy(&pb.stderr));
        assert_energy_close(&a, &b, name);
        let pvtu = std::fs::read_to_string(b.join("particles/particles_00001.pvtu")).unwrap();
        assert!(pvtu.contains("particles_00001_r0000.vtu") && pvtu.contains("particles_00001_r0001.vtu"));
        assert!(b.join("walls/hopper_00001.vtu").is_file() && b.join("hopper_wall.pvd").is_file());
        if extra.is_none() {
            let (cols, rows) = read_csv(&b.join("energy.csv"));
            let n = cols.iter().position(|c| c == "particles").unwrap();
            assert!(rows.last().unwrap()[n] >= 20.0, "beads were injected: {:?}", rows.last());
        }
    }
}

/// Clumps under a real `mpirun`: the stones example (`examples/dem_stones.toml`: stones of two clump
/// templates injected above a mesh panel, Finnie wear) for its first 50 ms (33 333 steps, a stone every
/// 5 ms, the first reach the panel) on two ranks against a plain run. `bodies.csv` (every stone,
/// gathered from both ranks in id order), `energy.csv` and `wear.csv` agree within 10⁻⁹ of each column's
/// scale (measured on thread-ranks over 60 ms: `bodies.csv` and `wear.csv` identical), and both ranks
/// write member spheres. (Before the first impact `dissipated_J` is only the round-off of the energy
/// balance, about 10⁻¹⁶ J, which the order of sums over ranks changes: the run goes on until the
/// stones hit, so that the column has a physical scale.)
#[test]
fn dem_stones_on_two_ranks_matches_one_rank() {
    let tmp = tempfile::tempdir().unwrap();
    let stl = example("dem_stones_panel.stl");
    let text = std::fs::read_to_string(example("dem_stones.toml"))
        .unwrap()
        .replace("duration_s = 0.35", "duration_s = 0.05")
        .replace("\"dem_stones_panel.stl\"", &format!("{:?}", stl.to_str().unwrap()));
    let scenario = common::write(tmp.path(), "stones.toml", text.as_bytes());
    let (a, b) = plain_and_two_ranks(tmp.path(), scenario.to_str().unwrap(), &[]);
    assert_energy_close(&a, &b, "stones");
    for file in ["bodies.csv", "wear.csv"] {
        assert_table_close(&a, &b, file);
    }
    let (_, bodies) = read_csv(&a.join("bodies.csv"));
    assert!(bodies.len() >= 20, "stones were injected: {} rows", bodies.len());
    let (_, wear) = read_csv(&a.join("wear.csv"));
    assert!(wear.last().unwrap()[1] > 0.0, "stones hit the panel");
    let pvtu = std::fs::read_to_string(b.join("particles/particles_00005.pvtu")).unwrap();
    assert!(pvtu.contains("particles_00005_r0000.vtu") && pvtu.contains("particles_00005_r0001.vtu"));
}

/// A pour under a real `mpirun`: `examples/bed_pour.toml` cut to 200 spheres and 0.25 s (the pour and the
/// first landings; later the collapsing packing amplifies round-off, see `dem_ranks.rs`) on two ranks
/// against a plain run: the kinetic and potential energy of every `energy.csv` row within 10⁻⁹ of their
/// scale, particle counts exact, and the same packing densities (within 10⁻⁹) in `packing.csv`, which
/// rank 0 writes from the particles of both ranks.
#[test]
fn bed_pour_on_two_ranks_matches_one_rank() {
    let tmp = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(example("bed_pour.toml"))
        .unwrap()
        .replace("duration_s = 4.0", "duration_s = 0.25")
        .replace("count = 1000", "count = 200");
    let scenario = common::write(tmp.path(), "pour.toml", text.as_bytes());
    let (a, b) = plain_and_two_ranks(tmp.path(), scenario.to_str().unwrap(), &[]);
    for column in ["kinetic_J", "potential_J"] {
        let d = energy_difference(&a, &b, column);
        assert!(d <= 1e-9, "{column}: {d:e} of its scale");
    }
    let fractions = |d: &Path| -> Vec<f64> {
        let text = std::fs::read_to_string(d.join("packing.csv")).unwrap();
        text.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse().unwrap()).collect()
    };
    let (x, y) = (fractions(&a), fractions(&b));
    assert!(!x.is_empty() && x.len() == y.len(), "{x:?} against {y:?}");
    assert!(x.iter().zip(&y).all(|(u, v)| (u - v).abs() <= 1e-9), "{y:?} on two ranks, {x:?} on one");
}

/// The command line of `examples/dem_pile.toml` (507 grains settling in a box, 4 000 steps) into `out` with
/// `extra` arguments.
fn dem_pile(out: &Path, extra: &[&str]) -> Vec<String> {
    let scenario = example("dem_pile.toml");
    let mut a: Vec<String> =
        ["run", scenario.to_str().unwrap(), "--threads", "1", "--out"].map(String::from).to_vec();
    a.push(out.to_str().unwrap().into());
    a.extend(extra.iter().map(|s| s.to_string()));
    a
}

/// Copies the run folder `from` to `to`.
fn copy_dir(from: &Path, to: &Path) {
    for (rel, bytes) in common::run_files(from) {
        let dest = to.join(rel);
        std::fs::create_dir_all(dest.parent().unwrap()).unwrap();
        std::fs::write(dest, bytes).unwrap();
    }
    for f in common::SESSION_FILES {
        if from.join(f).is_file() {
            std::fs::copy(from.join(f), to.join(f)).unwrap();
        }
    }
}

/// The ids (sorted) and the centre of mass \[m\] of the particles of the last output of run folder `dir`
/// (every piece of a `.pvtu`; one material, so the mass goes with r³).
fn last_output(dir: &Path) -> (Vec<i64>, [f64; 3]) {
    let mut names: Vec<String> = std::fs::read_dir(dir.join("particles"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".vtu"))
        .collect();
    names.sort();
    let last = names.last().unwrap()[.."particles_00000".len()].to_string();
    let (mut ids, mut m, mut mx) = (Vec::new(), 0.0, [0.0; 3]);
    for n in names.iter().filter(|n| n.starts_with(&last)) {
        let ds = spatter_io::vtk::read(&dir.join("particles").join(n)).unwrap();
        ids.extend(ds.point_array("id").unwrap().values.iter().map(|&v| v as i64));
        let r = &ds.point_array("radius_m").unwrap().values;
        for (x, r) in ds.points.iter().zip(r) {
            let w = r * r * r;
            m += w;
            for k in 0..3 {
                mx[k] += w * x[k];
            }
        }
    }
    ids.sort_unstable();
    (ids, mx.map(|v| v / m))
}

/// The largest difference of `energy.csv` column `name` between run folders `a` and `b`, relative to the
/// column's largest magnitude in `a`; steps and particle counts of every row equal.
fn energy_difference(a: &Path, b: &Path, name: &str) -> f64 {
    let (cols, ra) = read_csv(&a.join("energy.csv"));
    let (_, rb) = read_csv(&b.join("energy.csv"));
    assert_eq!(ra.len(), rb.len(), "{b:?}: rows");
    let col = |n: &str| cols.iter().position(|c| c == n).unwrap();
    for (x, y) in ra.iter().zip(&rb) {
        for exact in ["step", "particles"] {
            assert_eq!(x[col(exact)], y[col(exact)], "{b:?}: {exact}");
        }
    }
    let k = col(name);
    let scale = ra.iter().map(|r| r[k].abs()).fold(0.0, f64::max);
    ra.iter().zip(&rb).map(|(x, y)| (x[k] - y[k]).abs() / scale).fold(0.0, f64::max)
}

/// `examples/dem_pile.toml` stopped after 2 500 of its 4 000 steps under `mpirun -n 2` and resumed with
/// `--repartition` on 1 and on 2 ranks, and stopped as a plain (one-rank) run and resumed on 2 ranks.
/// Without `--repartition` another rank count is refused on rank 0 with one sentence naming both counts,
/// and nothing changes. Each resumed run ends with every id once, every `energy.csv` row has the step and
/// particle count of the uninterrupted run on the rank count that wrote the checkpoint, and the kinetic
/// energy, the potential energy (the height of the centre of mass), the budget total (continuous across
/// the resume) and the centre of mass of the last output agree with that run within [`TOLERANCE`]
/// (10⁻⁹ of their scale; derived below).
#[test]
fn dem_pile_resumes_on_another_rank_count() {
    let tmp = tempfile::tempdir().unwrap();
    let d = |n: &str| tmp.path().join(n);
    let o = mpirun(2, &strs(&dem_pile(&d("whole2"), &[])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = plain(&strs(&dem_pile(&d("whole1"), &[])));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stop = [("SPATTER_STOP_AFTER_POLLS", "2500")];
    let o = mpirun_env(2, &strs(&dem_pile(&d("two"), &[])), &stop);
    assert_eq!(o.status.code(), Some(130), "{}", String::from_utf8_lossy(&o.stderr));
    let o = Command::new(env!("CARGO_BIN_EXE_spatter"))
        .args(strs(&dem_pile(&d("one"), &[])))
        .env(stop[0].0, stop[0].1)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(130), "{}", String::from_utf8_lossy(&o.stderr));
    for (from, ranks, counts) in
        [("two", 1, "2 ranks and this run has 1 rank"), ("one", 2, "1 rank and this run has 2")]
    {
        let before = common::run_files(&d(from));
        let o = mpirun(ranks, &strs(&dem_pile(&d(from), &["--resume"])));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert_eq!(err.matches(&format!("written by {counts}")).count(), 1, "{err}");
        assert_eq!(err.matches("add --repartition").count(), 1, "{err}");
        assert!(before == common::run_files(&d(from)), "a refused resume changes nothing");
    }
    let (ids0, _) = last_output(&d("whole2"));
    assert!(ids0.len() > 500 && ids0 == (0..ids0.len() as i64).collect::<Vec<i64>>(), "{ids0:?}");
    for (from, ranks, reference) in [("two", 1, "whole2"), ("two", 2, "whole2"), ("one", 2, "whole1")] {
        let dir = d(&format!("{from}_on_{ranks}"));
        copy_dir(&d(from), &dir);
        let o = mpirun(ranks, &strs(&dem_pile(&dir, &["--resume", "--repartition"])));
        assert!(o.status.success(), "{from} on {ranks}: {}", String::from_utf8_lossy(&o.stderr));
        assert!(!dir.join("checkpoint.bin").exists() && !dir.join("checkpoint").exists());
        let what = format!("{from} resumed on {ranks} against {reference}");
        let (ids, com) = last_output(&dir);
        assert_eq!(ids, ids0, "{what}: every id once");
        let (_, com0) = last_output(&d(reference));
        let dc = (0..3).map(|k| (com[k] - com0[k]).abs()).fold(0.0, f64::max) / 0.03;
        eprintln!("{what}: centre of mass within {dc:e} of the pile's height");
        assert!(dc <= TOLERANCE, "{what}: centre of mass {com:?} vs {com0:?}");
        for column in ["kinetic_J", "potential_J", "total_J"] {
            let e = energy_difference(&d(reference), &dir, column);
            eprintln!("{what}: {column} within {e:e} of its scale");
            assert!(e <= TOLERANCE, "{what}: {column} differs by {e:e} of its scale");
        }
    }
}

/// Tolerance of [`dem_pile_resumes_on_another_rank_count`], relative to each quantity's scale (the largest
/// magnitude of the `energy.csv` column; the 0.03 m height of the fill for the centre of mass). A resumed
/// run is the same state with the same contact history; it differs from the uninterrupted one only in
/// the order in which a particle's forces are added (the lists are rebuilt at the resume, the rank count
/// changes), that is by round-off of 10⁻¹⁶ relative, which the collapse of the packing amplifies over the
/// 1 500 steps after the resume (measured: 5·10⁻¹⁴ for the kinetic energy, 3·10⁻¹⁵ for the potential
/// energy, 1.4·10⁻¹⁵ for the centre of mass, 10⁻¹⁶ for the budget total). A lost contact history moves grains by some
/// 10⁻⁷ m within 200 steps (`crates/dem/tests/decomposed.rs`), 10⁻⁵ of the fill height, and the energy
/// accounts of a rank lost or counted twice shift the total by their whole size: 10⁻⁹ lies far above the
/// round-off and far below both.
const TOLERANCE: f64 = 1e-9;

/// A DEM scene of grains in a box of planes (`count` random grains of diameter `d` m in the region
/// `lo`…`hi`, a box 0.1 m wide), for `end` seconds.
fn dem_box(count: usize, d: f64, lo: [f64; 3], hi: [f64; 3], end: f64) -> String {
    let mut s = format!(
        "kind = \"dem\"\ndt_s = 5e-5\nduration_s = {end}\noutput_interval_s = {end}\n\
         gravity_m_s2 = [0, 0, -9.81]\n[materials.grain]\nyoungs_modulus_pa = 5e7\npoisson_ratio = 0.3\n\
         density_kg_m3 = 2500\n[pair_defaults]\nfriction = 0.5\nrestitution = 0.4\n"
    );
    for (name, p, n) in [
        ("floor", "[0, 0, 0]", "[0, 0, 1]"),
        ("x_low", "[0, 0, 0]", "[1, 0, 0]"),
        ("x_high", "[0.1, 0, 0]", "[-1, 0, 0]"),
        ("y_low", "[0, 0, 0]", "[0, 1, 0]"),
        ("y_high", "[0, 0.1, 0]", "[0, -1, 0]"),
    ] {
        s += &format!(
            "[[walls]]\nname = \"{name}\"\nmaterial = \"grain\"\n\
             shape = {{ type = \"plane\", point_m = {p}, normal = {n} }}\n"
        );
    }
    s + &format!(
        "[[fill]]\nmaterial = \"grain\"\nmethod = \"random\"\ncount = {count}\n\
         region = {{ type = \"box\", min_m = {lo:?}, max_m = {hi:?} }}\n\
         size = {{ kind = \"mono\", diameter = {d} }}\n"
    )
}

/// More ranks than particles: a DEM scene of 3 grains on 4 ranks and an SPH fill of 2 particles on 3
/// ranks are refused by every rank alike before the first step (the split gives every rank at least one
/// particle), the sentence naming both counts printed once by rank 0 (as an `error:` line), exit code 1,
/// no panic and no hang. A rank that is left without particles during a run is no error: with load
/// balancing off (`engine.rebalance_imbalance = inf`), 30 grains falling down a column split along its
/// height over 4 ranks all land in the lowest ranks' boxes, and the run ends with every grain, the two
/// upper ranks' pieces of the last output empty. With balancing on (the default, 1.2) the split follows
/// the grains down and every rank ends with its share (on 2 ranks here; on 4 the same run ended with 7, 8,
/// 7 and 8 grains).
#[test]
fn more_ranks_than_particles_is_refused_and_empty_ranks_run() {
    let tmp = tempfile::tempdir().unwrap();
    let dem = common::write(
        tmp.path(),
        "three.toml",
        dem_box(3, 0.005, [0.0; 3], [0.1, 0.1, 0.05], 0.01).as_bytes(),
    );
    let sph_text = std::fs::read_to_string(example("sph_dam_break.toml"))
        .unwrap()
        .replace("max_m = [0.3, 0.3, 0.6]", "max_m = [0.015, 0.015, 0.03]");
    let sph = common::write(tmp.path(), "two.toml", sph_text.as_bytes());
    for (scenario, ranks, sentence) in [
        (&dem, 4, "error: ranks: splitting the particles over the ranks: 4 ranks for 3 particles"),
        (&sph, 3, "error: SPH set-up: splitting the fluid over the ranks: 3 ranks for 2 particles"),
    ] {
        let out = tmp.path().join(format!("out{ranks}"));
        let o = mpirun(
            ranks,
            &["run", scenario.to_str().unwrap(), "--threads", "1", "--out", out.to_str().unwrap()],
        );
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert_eq!(err.matches(sentence).count(), 1, "one sentence, from rank 0: {err}");
        assert!(err.contains(&format!("use at most {} ranks", ranks - 1)), "{err}");
        assert!(!err.contains("panicked"), "{err}");
        // Refused at the split, before the first step: no step's output in the run folder (a hang is
        // caught by `mpirun`'s kill limit; no wall-clock limit here, timings belong to benchmarks).
        for step_output in ["energy.csv", "series.csv", "particles.pvd", "summary.json"] {
            assert!(!out.join(step_output).exists(), "{step_output} written before the refusal: {err}");
        }
    }
    let column = dem_box(30, 0.02, [0.0, 0.0, 0.1], [0.1, 0.1, 0.5], 0.3);
    let mut counts = Vec::new();
    // Balanced on 2 ranks: 4 oversubscribed ranks on a loaded two-core machine take minutes for the
    // 6 000 steps once every rank holds grains.
    for (name, engine, ranks) in [("fixed", "[engine]\nrebalance_imbalance = inf\n", 4), ("balanced", "", 2)]
    {
        let path = common::write(tmp.path(), &format!("{name}.toml"), (column.clone() + engine).as_bytes());
        let out = tmp.path().join(name);
        let o =
            mpirun(ranks, &["run", path.to_str().unwrap(), "--threads", "1", "--out", out.to_str().unwrap()]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let count = |r: usize| {
            let piece = out.join(format!("particles/particles_00001_r{r:04}.vtu"));
            spatter_io::vtk::read(&piece).unwrap().points.len()
        };
        let c: Vec<usize> = (0..ranks).map(count).collect();
        assert_eq!(c.iter().sum::<usize>(), 30, "{name}: {c:?}");
        counts.push(c);
    }
    assert_eq!(counts[0][2] + counts[0][3], 0, "the upper ranks' boxes emptied: {:?}", counts[0]);
    let most = *counts[1].iter().max().unwrap() as f64;
    assert!(most <= 1.2 * 30.0 / 2.0, "balanced split: {:?}", counts[1]);
}

/// The gravelometer under a real `mpirun`: `examples/gravelometer_sae.toml --smoke` (road gravel as
/// multi-sphere stones through the SAE pipe onto the panel) on two ranks against a plain run. Rank 0
/// writes the results from the records of both ranks: the strip shares, every impact and every stone's
/// fate agree within 10⁻⁹ of each column's scale.
#[test]
fn gravelometer_on_two_ranks_matches_one_rank() {
    let tmp = tempfile::tempdir().unwrap();
    let scenario = example("gravelometer_sae.toml");
    let (a, b) = plain_and_two_ranks(tmp.path(), scenario.to_str().unwrap(), &["--smoke"]);
    for file in ["strips.csv", "impacts.csv", "stones.csv", "wear.csv"] {
        assert_table_close(&a, &b, file);
    }
    let (_, impacts) = read_csv(&a.join("impacts.csv"));
    assert!(!impacts.is_empty(), "stones reached the panel");
}
