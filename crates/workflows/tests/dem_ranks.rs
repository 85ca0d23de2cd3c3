//! The `dem` kind on several ranks, with ranks as threads ([`ThreadComm`]): the hopper example (mesh walls,
//! injection) on 2 ranks against 1, a run on 2 ranks stopped and resumed on 2 ranks bit for bit, and a
//! settling pile stopped on 2 (or 1) ranks and resumed on another rank count with `--repartition`.

use spatter_core::check::Checker;
use spatter_core::comm::ThreadComm;
use spatter_core::control::{Finished, StopAfterPolls, Unattended};
use spatter_io::run::{RunContext, RunDir};
use spatter_workflows::dem_scene::{run, SceneConfig};
use std::path::{Path, PathBuf};

/// The hopper example (`examples/dem_hopper.toml`) shortened to `duration_s` with outputs every
/// `output_s`.
fn hopper(duration_s: f64, output_s: f64) -> SceneConfig {
    example("dem_hopper", "dem_hopper.stl", duration_s, output_s)
}

/// The example `examples/<name>.toml` with its mesh file `stl` made absolute, shortened to `duration_s`
/// with outputs every `output_s`.
fn example(name: &str, stl: &str, duration_s: f64, output_s: f64) -> SceneConfig {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(root.join(format!("{name}.toml"))).unwrap();
    let path = root.join(stl);
    let body: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with("kind"))
        .map(|l| l.replace(&format!("{stl:?}"), &format!("{:?}", path.to_str().unwrap())))
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
    on_ranks_with(cfg, dir, n, (resume, false), control)
}

/// [`on_ranks`] with (`resume`, `repartition`).
fn on_ranks_with(
    cfg: &SceneConfig,
    dir: &Path,
    n: usize,
    (resume, repartition): (bool, bool),
    control: impl Fn() -> Box<dyn spatter_core::control::RunControl> + Sync,
) -> Vec<Result<Finished, String>> {
    let d = RunDir::create(dir).unwrap();
    ThreadComm::run(n, |comm| {
        let c = control();
        let ctx = RunContext { comm, repartition, ..RunContext::new(&d, c.as_ref(), resume) };
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

/// The stones example (`examples/dem_stones.toml`: clumps of two templates injected above a mesh panel,
/// Finnie wear) for 0.06 s (40 000 steps; a stone every 5 ms, the first reach the panel after about
/// 0.045 s) on 2 ranks against 1. The split cuts through the injection region, so stones are placed on both ranks and
/// cross the cut as they fall. `bodies.csv` (every stone's centre, orientation and velocities, gathered
/// from both ranks in id order), `energy.csv` and `wear.csv` agree with one rank within 10⁻⁹ of each
/// column's scale (measured: `bodies.csv` and `wear.csv` identical, `energy.csv` 2·10⁻¹⁵), the run
/// summary counts every body, and the member spheres of the last output are split over the two pieces.
#[test]
fn stones_on_two_ranks_match_one() {
    let cfg = example("dem_stones", "dem_stones_panel.stl", 0.06, 0.01);
    let tmp = tempfile::tempdir().unwrap();
    let (one, two) = (tmp.path().join("one"), tmp.path().join("two"));
    assert_eq!(on_ranks(&cfg, &one, 1, false, || Box::new(Unattended)), [Ok(Finished::Completed)]);
    let done = on_ranks(&cfg, &two, 2, false, || Box::new(Unattended));
    assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{done:?}");
    let (_, bodies) = csv(&one.join("bodies.csv"));
    let (_, wear) = csv(&one.join("wear.csv"));
    assert!(bodies.last().unwrap()[1] >= 10.0, "stones were injected");
    assert!(wear.last().unwrap()[1] > 0.0, "stones hit the panel");
    for file in ["bodies.csv", "energy.csv", "wear.csv"] {
        let d = assert_same_table(&one.join(file), &two.join(file));
        eprintln!("stones on 2 ranks: {file} within {d:e} of one rank");
    }
    // The run summary's body count (rank 0's summary on 2 ranks) counts the bodies of both ranks.
    let bodies_counted = |dir: &Path, n: usize| {
        let d = RunDir::create(&dir.join("again")).unwrap();
        ThreadComm::run(n, |comm| {
            let ctx = RunContext { comm, ..RunContext::new(&d, &Unattended, false) };
            let s = run(&example("dem_stones", "dem_stones_panel.stl", 0.012, 0.01), &ctx).unwrap();
            s.scalars.iter().find(|(k, _)| k == "bodies").map(|(_, v)| *v).expect("a bodies scalar")
        })
    };
    let (b1, b2) = (bodies_counted(&one, 1), bodies_counted(&two, 2));
    assert!(b1[0] >= 2.0 && b2.iter().all(|&b| b == b1[0]), "bodies {b1:?} on one rank, {b2:?} on two");
    let last = csv(&one.join("energy.csv")).1.len() - 1;
    let pieces: Vec<usize> = (0..2)
        .map(|r| {
            let piece = two.join(format!("particles/particles_{last:05}_r{r:04}.vtu"));
            spatter_io::vtk::read(&piece).unwrap().points.len()
        })
        .collect();
    eprintln!("member spheres per rank at the end: {pieces:?}");
    assert!(pieces.iter().all(|&n| n > 0), "both ranks hold stones: {pieces:?}");
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

/// The settling pile of `examples/dem_pile.toml`: 507 grains (5–6 mm) on a face-centred cubic lattice
/// (6 mm between neighbours) in a 6 cm box of planes, released at rest; they collapse onto the floor and each other (friction 0.5, restitution
/// 0.4) over the 0.04 s (4 000 steps) of the run.
fn pile() -> SceneConfig {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(root.join("dem_pile.toml")).unwrap();
    let body: String =
        text.lines().filter(|l| !l.trim_start().starts_with("kind")).collect::<Vec<_>>().join("\n");
    let cfg: SceneConfig = toml::from_str(&body).unwrap();
    Checker::run(&cfg, Some(&root)).unwrap();
    cfg
}

/// Copies the run folder `from` to `to` (a stopped run, to resume it in several ways).
fn copy_dir(from: &Path, to: &Path) {
    for f in files(from) {
        let dest = to.join(&f);
        std::fs::create_dir_all(dest.parent().unwrap()).unwrap();
        std::fs::copy(from.join(&f), dest).unwrap();
    }
}

/// The largest difference of `energy.csv` column `name` between run folders `a` and `b`, relative to the
/// column's largest magnitude in `a`; the rows' steps and particle counts must be equal.
fn column_difference(a: &Path, b: &Path, name: &str) -> f64 {
    let (cols, ra) = csv(&a.join("energy.csv"));
    let (_, rb) = csv(&b.join("energy.csv"));
    assert_eq!(ra.len(), rb.len(), "{b:?}: rows");
    let col = |n: &str| cols.iter().position(|c| c == n).unwrap();
    for (x, y) in ra.iter().zip(&rb) {
        for exact in ["step", "particles"] {
            assert_eq!(x[col(exact)], y[col(exact)], "{b:?}: {exact}");
        }
    }
    let k = col(name);
    let scale = ra.iter().map(|r| r[k].abs()).fold(0.0, f64::max).max(1e-300);
    ra.iter().zip(&rb).map(|(x, y)| (x[k] - y[k]).abs() / scale).fold(0.0, f64::max)
}

/// The ids in the last particle output of run folder `dir` (every piece of a `.pvtu`), sorted.
fn last_ids(dir: &Path) -> Vec<i64> {
    let mut names: Vec<PathBuf> = files(&dir.join("particles"))
        .into_iter()
        .filter(|f| f.extension().is_some_and(|e| e == "vtu"))
        .collect();
    names.sort();
    let last = names.last().unwrap().to_str().unwrap()[..15].to_string();
    let mut ids = Vec::new();
    for f in names.iter().filter(|f| f.to_str().unwrap().starts_with(&last)) {
        let ds = spatter_io::vtk::read(&dir.join("particles").join(f)).unwrap();
        ids.extend(ds.point_array("id").unwrap().values.iter().map(|&v| v as i64));
    }
    ids.sort_unstable();
    ids
}

/// The settling pile stopped after 2 500 of its 4 000 steps on 2 thread-ranks and resumed with
/// `--repartition` on 1 and on 2 ranks, and stopped on 1 rank and resumed on 2: every `energy.csv` row
/// has the uninterrupted run's step and particle count, the last output holds every id once, and the
/// kinetic energy, the potential energy (the height of the centre of mass) and the budget total stay within
/// 10⁻⁹ of their scale of the uninterrupted run on the rank count that wrote the checkpoint. The resumed
/// run is the same state with the same contact history; only the order in which forces are added
/// differs (as between runs on 1 and 2 ranks), so the difference is round-off, grown by the collapse of
/// the packing (measured below 10⁻¹²). Without `--repartition` another rank count is refused.
#[test]
fn pile_resumes_on_another_rank_count() {
    let cfg = pile();
    let tmp = tempfile::tempdir().unwrap();
    let dir = |name: &str| tmp.path().join(name);
    for (ranks, name) in [(1, "one"), (2, "two")] {
        let done = on_ranks(&cfg, &dir(name), ranks, false, || Box::new(Unattended));
        assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{done:?}");
        let stopped = on_ranks(&cfg, &dir(&format!("{name}_stopped")), ranks, false, || {
            Box::new(StopAfterPolls::new(2500))
        });
        assert!(stopped.iter().all(|f| *f == Ok(Finished::Interrupted)), "{stopped:?}");
    }
    let n = csv(&dir("one").join("energy.csv")).1[0][2] as i64;
    assert!(n > 500, "the lattice fill holds {n} grains");
    let refused = on_ranks(&cfg, &dir("two_stopped"), 1, true, || Box::new(Unattended));
    assert!(refused[0].as_ref().is_err_and(|e| e.contains("add --repartition")), "{refused:?}");
    for (from, ranks) in [("two", 1), ("two", 2), ("one", 2)] {
        let resumed = dir(&format!("{from}_on_{ranks}"));
        copy_dir(&dir(&format!("{from}_stopped")), &resumed);
        let done = on_ranks_with(&cfg, &resumed, ranks, (true, true), || Box::new(Unattended));
        assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{from} on {ranks}: {done:?}");
        let parts = resumed.join("checkpoint");
        assert!(!resumed.join("checkpoint.bin").exists() && !parts.exists(), "the checkpoint is removed");
        let ids = last_ids(&resumed);
        assert_eq!(ids, (0..n).collect::<Vec<i64>>(), "{from} on {ranks}: every id once");
        for column in ["kinetic_J", "potential_J", "total_J"] {
            let d = column_difference(&dir(from), &resumed, column);
            eprintln!("{from} ranks resumed on {ranks}: {column} within {d:e} of its scale");
            assert!(d <= 1e-9, "{from} resumed on {ranks} ranks: {column} differs by {d:e} of its scale");
        }
    }
}

/// The stones example (clump injection, a stone every 5 ms) for 30 ms on two thread-ranks, stopped after
/// 12 000 of its 20 000 steps (18 ms: the stones of four placements in flight) and resumed: on two ranks every file
/// byte for byte as the uninterrupted two-rank run (the bodies, their members and the injector go on
/// where they were); with `--repartition` on one rank `bodies.csv` has the same rows within 10⁻⁹ of each
/// column's scale (the same state; only the order of force sums may change; measured identical).
#[test]
fn stones_resume_on_two_ranks_bit_for_bit_and_on_one() {
    let cfg = example("dem_stones", "dem_stones_panel.stl", 0.03, 0.01);
    let tmp = tempfile::tempdir().unwrap();
    let dir = |name: &str| tmp.path().join(name);
    let done = on_ranks(&cfg, &dir("full"), 2, false, || Box::new(Unattended));
    assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{done:?}");
    let stopped = on_ranks(&cfg, &dir("stopped"), 2, false, || Box::new(StopAfterPolls::new(12_000)));
    assert!(stopped.iter().all(|f| *f == Ok(Finished::Interrupted)), "{stopped:?}");
    copy_dir(&dir("stopped"), &dir("on_one"));
    let resumed = on_ranks(&cfg, &dir("stopped"), 2, true, || Box::new(Unattended));
    assert!(resumed.iter().all(|f| *f == Ok(Finished::Completed)), "{resumed:?}");
    let (full, split) = (dir("full"), dir("stopped"));
    assert_eq!(files(&full), files(&split), "the same files");
    for f in files(&full).iter().filter(|f| !f.starts_with("log.txt")) {
        assert!(
            std::fs::read(full.join(f)).unwrap() == std::fs::read(split.join(f)).unwrap(),
            "{f:?} differs"
        );
    }
    let done = on_ranks_with(&cfg, &dir("on_one"), 1, (true, true), || Box::new(Unattended));
    assert_eq!(done, [Ok(Finished::Completed)]);
    let (_, rows) = csv(&full.join("bodies.csv"));
    assert!(rows.len() >= 8, "stones in flight: {} rows", rows.len());
    let d = assert_same_table(&full.join("bodies.csv"), &dir("on_one").join("bodies.csv"));
    eprintln!("stones from 2 ranks resumed on 1: bodies.csv within {d:e}");
}

/// Spheres and pebbles (clumps) thrown across a 10 cm box of planes under gravity, with the event log
/// (first wall impacts with their angles, collisions per wall, the first crossing of the plane x = 5 cm)
/// and the trajectories of the first five objects and of spheres 50 and 60, for 0.1 s (10 000 steps).
fn events_scene() -> SceneConfig {
    let text = r#"
dt_s = 1e-5
duration_s = 0.1
output_interval_s = 0.02
gravity_m_s2 = [0, 0, -9.81]
seed = 5

[materials.grain]
youngs_modulus_pa = 5e7
poisson_ratio = 0.3
density_kg_m3 = 2500

[pair_defaults]
friction = 0.3
restitution = 0.8

[[walls]]
name = "x0"
material = "grain"
shape = { type = "plane", point_m = [0, 0, 0], normal = [1, 0, 0] }
[[walls]]
name = "x1"
material = "grain"
shape = { type = "plane", point_m = [0.1, 0, 0], normal = [-1, 0, 0] }
[[walls]]
name = "y0"
material = "grain"
shape = { type = "plane", point_m = [0, 0, 0], normal = [0, 1, 0] }
[[walls]]
name = "y1"
material = "grain"
shape = { type = "plane", point_m = [0, 0.1, 0], normal = [0, -1, 0] }
[[walls]]
name = "floor"
material = "grain"
shape = { type = "plane", point_m = [0, 0, 0], normal = [0, 0, 1] }

[templates.pebble]
shape = { type = "ellipsoid", semi_axes_m = [0.004, 0.003, 0.0025] }
packing = { type = "equal", sphere_diameter_m = 0.0016 }

[[fill]]
material = "grain"
region = { type = "box", min_m = [0.005, 0.005, 0.02], max_m = [0.045, 0.095, 0.09] }
size = { kind = "mono", diameter = 0.006 }
count = 40
velocity_m_s = [1.0, 0.3, 0]

[[fill]]
material = "grain"
region = { type = "box", min_m = [0.055, 0.005, 0.02], max_m = [0.095, 0.095, 0.09] }
size = { kind = "mono", diameter = 0.006 }
count = 40
velocity_m_s = [-1.0, -0.2, 0.5]

[[fill]]
material = "grain"
region = { type = "box", min_m = [0.01, 0.01, 0.1], max_m = [0.09, 0.09, 0.14] }
clumps = { templates = ["pebble"] }
count = 10
velocity_m_s = [0.5, 0, -0.5]

[output.events]
angle_plane_normal = [0, 1, 0]
crossing_plane = { point_m = [0.05, 0, 0], normal = [1, 0, 0] }

[output.trajectories]
every_steps = 100
first = 5
ids = [50, 60]
"#;
    let cfg: SceneConfig = toml::from_str(text).unwrap();
    Checker::run(&cfg, None).unwrap();
    cfg
}

/// Two CSV files with the same header and rows, every cell within 10⁻⁹ of its column's scale (an empty
/// cell, NaN, only against an empty cell); returns the largest relative difference.
fn assert_same_table(a: &Path, b: &Path) -> f64 {
    let ((ca, ra), (cb, rb)) = (csv(a), csv(b));
    assert_eq!(ca, cb, "{}", a.display());
    assert_eq!(ra.len(), rb.len(), "rows of {}", b.display());
    let mut worst: f64 = 0.0;
    for c in 0..ca.len() {
        let scale = ra.iter().map(|r| r[c].abs()).filter(|v| v.is_finite()).fold(0.0, f64::max).max(1e-300);
        for (x, y) in ra.iter().zip(&rb) {
            let same_gap = x[c].is_nan() && y[c].is_nan();
            let d = if same_gap { 0.0 } else { (x[c] - y[c]).abs() / scale };
            assert!(d <= 1e-9, "{}, column {}: {} against {}", b.display(), ca[c], y[c], x[c]);
            worst = worst.max(d);
        }
    }
    worst
}

/// The event log and the trajectories on ranks ([`events_scene`]): on 2 and 3 thread-ranks `events.csv`
/// and `trajectories.csv` hold the rows of one rank (every object that hit a wall or met the plane, its
/// first impact, collisions per wall and first crossing; the followed objects in the one-rank order) within
/// 10⁻⁹ of each column's scale (measured: identical; 90 objects, 69 hit a wall, 68 cross the plane). A 2-rank
/// run stopped after 5 000 steps resumes bit for bit on 2 ranks and, with `--repartition`, on 1 rank with
/// the one-rank tables.
#[test]
fn events_and_trajectories_on_ranks_match_one_rank() {
    let cfg = events_scene();
    let tmp = tempfile::tempdir().unwrap();
    let dir = |name: &str| tmp.path().join(name);
    for (ranks, name) in [(1, "one"), (2, "two"), (3, "three")] {
        let done = on_ranks(&cfg, &dir(name), ranks, false, || Box::new(Unattended));
        assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{name}: {done:?}");
    }
    let (head, rows) = csv(&dir("one").join("events.csv"));
    let crossed = head.iter().position(|h| h == "crossing_t_s").unwrap();
    let first = head.iter().position(|h| h == "first_impact_t_s").unwrap();
    let n_crossed = rows.iter().filter(|r| r[crossed].is_finite()).count();
    let n_hit = rows.iter().filter(|r| r[first].is_finite()).count();
    eprintln!("{} objects logged, {n_hit} hit a wall, {n_crossed} crossed the plane", rows.len());
    assert!(
        rows.len() >= 90 && n_crossed >= 20 && n_hit >= 40,
        "{} rows, {n_hit} hits, {n_crossed} crossings",
        rows.len()
    );
    for name in ["two", "three"] {
        for file in ["events.csv", "trajectories.csv"] {
            let d = assert_same_table(&dir("one").join(file), &dir(name).join(file));
            eprintln!("{name} ranks: {file} within {d:e}");
        }
    }
    let stopped = on_ranks(&cfg, &dir("stopped"), 2, false, || Box::new(StopAfterPolls::new(5000)));
    assert!(stopped.iter().all(|f| *f == Ok(Finished::Interrupted)), "{stopped:?}");
    copy_dir(&dir("stopped"), &dir("on_one"));
    let done = on_ranks(&cfg, &dir("stopped"), 2, true, || Box::new(Unattended));
    assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{done:?}");
    for f in files(&dir("two")).iter().filter(|f| !f.starts_with("log.txt")) {
        let same =
            std::fs::read(dir("two").join(f)).unwrap() == std::fs::read(dir("stopped").join(f)).unwrap();
        assert!(same, "resumed on 2 ranks: {f:?} differs");
    }
    let done = on_ranks_with(&cfg, &dir("on_one"), 1, (true, true), || Box::new(Unattended));
    assert_eq!(done, [Ok(Finished::Completed)]);
    for file in ["events.csv", "trajectories.csv"] {
        let d = assert_same_table(&dir("one").join(file), &dir("on_one").join(file));
        eprintln!("2 ranks resumed on 1: {file} within {d:e}");
    }
}

/// The bed pour of `examples/bed_pour.toml` cut to 200 spheres of 1 cm poured one per millisecond and
/// 0.25 s (6 250 steps: the pour and the first landings), on 1 and 2 thread-ranks. The split starts over a lattice in the pour region (the
/// box is empty at the start) and is rebuilt as the bed grows. Every addition needs the state of every
/// rank (which spheres still fall freely, the top of the quiet bed, the spheres near the release height),
/// so the ranks draw the same positions as one rank: the particle counts of `energy.csv` exact, its
/// kinetic and potential energy and the densities of `packing.csv` (written by rank 0 from the particles
/// of both ranks) within 10⁻⁹ of their scale (measured: 1.3·10⁻¹³ and below), and `bed.txt` holds every
/// sphere once. Later the
/// frictionless spheres collapse into a packing, which amplifies round-off (the order of force sums
/// differs between one and two ranks) into other grain positions: measured 2·10⁻¹¹ of the potential
/// energy at 0.3 s, 3·10⁻⁵ at 0.4 s, 8·10⁻⁴ at 0.5 s, so the comparison stops before.
#[test]
fn bed_pour_on_two_ranks_matches_one() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let text = std::fs::read_to_string(root.join("bed_pour.toml")).unwrap();
    let body: String =
        text.lines().filter(|l| !l.trim_start().starts_with("kind")).collect::<Vec<_>>().join("\n");
    let mut cfg: SceneConfig = toml::from_str(&body).unwrap();
    Checker::run(&cfg, Some(&root)).unwrap();
    cfg.duration_s = 0.25;
    cfg.output_interval_s = 0.05;
    cfg.pour.as_mut().unwrap().count = 200;
    let tmp = tempfile::tempdir().unwrap();
    let dir = |name: &str| tmp.path().join(name);
    for (ranks, name) in [(1, "one"), (2, "two")] {
        let done = on_ranks(&cfg, &dir(name), ranks, false, || Box::new(Unattended));
        assert!(done.iter().all(|f| *f == Ok(Finished::Completed)), "{name}: {done:?}");
    }
    let (cols, rows) = csv(&dir("one").join("energy.csv"));
    let n = cols.iter().position(|c| c == "particles").unwrap();
    assert_eq!(rows.last().unwrap()[n], 200.0, "every sphere poured");
    // Steps and particle counts exact; the energies (rotational energy is only round-off here: the
    // spheres are frictionless) within 10⁻⁹ of their scale.
    for column in ["kinetic_J", "potential_J"] {
        let d = column_difference(&dir("one"), &dir("two"), column);
        eprintln!("bed pour on 2 ranks: {column} within {d:e}");
        assert!(d <= 1e-9, "{column}: {d:e}");
    }
    let fractions = |d: &Path| -> Vec<f64> {
        let text = std::fs::read_to_string(d.join("packing.csv")).unwrap();
        text.lines().skip(1).map(|l| l.rsplit(',').next().unwrap().parse().unwrap()).collect()
    };
    let (a, b) = (fractions(&dir("one")), fractions(&dir("two")));
    eprintln!("packing densities: {a:?} on one rank, {b:?} on two");
    assert_eq!(a.len(), b.len());
    assert!(a.iter().zip(&b).all(|(x, y)| (x - y).abs() <= 1e-9), "{a:?} against {b:?}");
    let bed = |d: &Path| std::fs::read_to_string(d.join("bed.txt")).unwrap();
    assert_eq!(
        bed(&dir("one")).lines().count(),
        bed(&dir("two")).lines().count(),
        "bed.txt holds every sphere once"
    );
}
