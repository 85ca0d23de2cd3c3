//! The `dem` kind on several ranks, with ranks as threads ([`ThreadComm`]): the hopper example (mesh walls,
//! injection) on 2 ranks against 1, and a run on 2 ranks stopped and resumed on 2 ranks bit for bit.

use spatter_core::check::Checker;
use spatter_core::comm::ThreadComm;
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_io::run::{RunContext, RunDir};
use spatter_workflows::dem_scene::{run, SceneConfig};
use std::path::{Path, PathBuf};

/// The hopper example (`examples/dem_hopper.toml`) with its mesh file made absolute, shortened to
/// `duration_s` with outputs every `output_s`.
fn hopper(duration_s: f64, output_s: f64) -> SceneConfig {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(root.join("dem_hopper.toml")).unwrap();
    let stl = root.join("dem_hopper.stl");
    let body: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("kind"))
        .map(|l| l.replace("\"dem_hopper.stl\"", &format!("{:?}", stl.to_str().unwrap())))
        .collect::<Vec<_>>()
        .join("\n");
    let mut cfg: SceneConfig = toml::from_str(&body).unwrap();
    Checker::run(&cfg, Some(&root)).unwrap();
    cfg.duration_s = duration_s;
    cfg.output_interval_s = output_s;
    cfg
}

/// Runs `cfg` on `n` thread-ranks into `dir`; every rank's outcome.
fn on_ranks(
    cfg: &SceneConfig,
    dir: &Path,
    n: usize,
    resume: bool,
    control: impl Fn() -> Box<dyn spatter_core::control::RunControl> + Sync,
) -> Vec<Result<Finished, String>> {
    let d = RunDir::create(dir).unwrap();
    ThreadComm::run(n, |comm| {
        let c = control();
        let ctx = RunContext { comm, ..RunContext::new(&d, c.as_ref(), resume) };
        run(cfg, &ctx).map(|s| s.finished).map_err(|e| e.to_string())
    })
}

fn csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    spatter_io::csv::read_series(path).unwrap()
}

/// The hopper for 0.06 s (beads injected at t = 0 fall towards the hopper; 1 200 steps) on 2 ranks
/// against 1: the particle count in every `energy.csv` row exact, every energy column within 1e-9 of its
/// scale (the largest magnitude of the column on one rank). Not bit-identical: a particle's contact
/// forces are added in another order on two ranks; in free fall and the first impacts the difference
/// stays at round-off (measured below 1e-12). Every output is a `.pvtu` naming one piece per rank, the
/// pieces together hold every particle once.
#[test]
fn hopper_on_two_ranks_matches_one() {
    let cfg = hopper(0.06, 0.02);
    let tmp = tempfile::tempdir().unwrap();
    let (one, two) = (tmp.path().join("one"), tmp.path().join("two"));
    let done = on_ranks(&cfg, &one, 1, false, || Box::new(Unattended));
    assert_eq!(done, [Ok(Finished::Completed)]);
    let done = on_ranks(&cfg, &two, 2, false, || Box::new(Unattended));
    assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{done:?}");
    let (cols, rows1) = csv(&one.join("energy.csv"));
    let (cols2, rows2) = csv(&two.join("energy.csv"));
    assert_eq!(cols, cols2);
    assert_eq!(rows1.len(), rows2.len());
    let n_col = cols.iter().position(|c| c == "particles").unwrap();
    assert!(rows1.last().unwrap()[n_col] > 50.0, "beads were injected: {:?}", rows1.last());
    let mut worst: f64 = 0.0;
    for (c, name) in cols.iter().enumerate() {
        let scale = rows1.iter().map(|r| r[c].abs()).fold(0.0, f64::max).max(1e-300);
        for (a, b) in rows1.iter().zip(&rows2) {
            if c == n_col || name == "step" {
                assert_eq!(a[c], b[c], "column {name}");
            }
            let d = (a[c] - b[c]).abs() / scale;
            worst = worst.max(d);
            assert!(d <= 1e-9, "column {name}: {} on 2 ranks, {} on 1", b[c], a[c]);
        }
    }
    eprintln!("hopper on 2 ranks: largest relative difference {worst:e}");
    let last = rows1.len() - 1;
    let pvtu = std::fs::read_to_string(two.join(format!("particles/particles_{last:05}.pvtu"))).unwrap();
    let mut total = 0;
    for r in 0..2 {
        let piece = format!("particles_{last:05}_r{r:04}.vtu");
        assert!(pvtu.contains(&format!("Source=\"{piece}\"")), "{pvtu}");
        total += spatter_io::vtk::read(&two.join("particles").join(&piece)).unwrap().points.len();
    }
    assert_eq!(total as f64, rows1[last][n_col], "every particle in one piece");
    // The mesh wall's records are written once, by rank 0, with the sums over both ranks.
    let w1 = std::fs::read_to_string(one.join(format!("walls/hopper_{last:05}.vtu"))).unwrap();
    let w2 = std::fs::read_to_string(two.join(format!("walls/hopper_{last:05}.vtu"))).unwrap();
    assert_eq!(w1.len(), w2.len());
}

/// Stops like the [`StopAfterPolls`] and asks for a checkpoint at every poll after the first `k` (one
/// checkpoint generation per step from then on).
struct CheckpointLate(StopAfterPolls, std::sync::atomic::AtomicU64);

impl spatter_core::control::RunControl for CheckpointLate {
    fn stop_requested(&self) -> bool {
        self.0.stop_requested()
    }
    fn checkpoint_due(&self) -> bool {
        use std::sync::atomic::Ordering;
        self.1.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |k| k.checked_sub(1)).is_err()
    }
}

fn files(root: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(root, &p, out);
            } else {
                out.push(p.strip_prefix(root).unwrap().to_owned());
            }
        }
    }
    let mut v = Vec::new();
    walk(root, root, &mut v);
    v.sort();
    v
}

/// The hopper (1 200 steps; 15 beads injected at step 1 000) on two thread-ranks, stopped after 1 100
/// steps (checkpoints at every step from step 1 000 on, so old generations are replaced) and resumed on two
/// ranks, leaves every file byte for byte as the uninterrupted two-rank run; a resume on one rank is
/// refused.
#[test]
fn two_ranks_resume_bit_for_bit() {
    let cfg = hopper(0.012, 0.004);
    let tmp = tempfile::tempdir().unwrap();
    let (full, split) = (tmp.path().join("full"), tmp.path().join("split"));
    let done = on_ranks(&cfg, &full, 2, false, || Box::new(Unattended));
    assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{done:?}");
    let (cols, rows) = csv(&full.join("energy.csv"));
    let n = cols.iter().position(|c| c == "particles").unwrap();
    assert!(rows.last().unwrap()[n] >= 10.0, "beads in flight: {:?}", rows.last());
    let stopped =
        on_ranks(&cfg, &split, 2, false, || Box::new(CheckpointLate(StopAfterPolls::new(1100), 1000.into())));
    assert!(stopped.iter().all(|f| *f == Ok(Finished::Interrupted)), "{stopped:?}");
    let parts = std::fs::read_dir(split.join("checkpoint")).unwrap().count();
    assert_eq!(parts, 2, "one part per rank, the older generations deleted");
    assert!(split.join("checkpoint.bin").is_file());
    let refused = on_ranks(&cfg, &split, 1, true, || Box::new(Unattended));
    assert!(refused[0].is_err(), "{refused:?}");
    let resumed = on_ranks(&cfg, &split, 2, true, || Box::new(Unattended));
    assert!(resumed.iter().all(|f| *f == Ok(Finished::Completed)), "{resumed:?}");
    assert_eq!(files(&full), files(&split), "the same files");
    for f in files(&full) {
        if f.starts_with("log.txt") {
            continue;
        }
        assert!(
            std::fs::read(full.join(&f)).unwrap() == std::fs::read(split.join(&f)).unwrap(),
            "{f:?} differs"
        );
    }
}
