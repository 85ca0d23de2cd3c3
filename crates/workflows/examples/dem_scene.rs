//! Runs a `kind = "dem"` scenario file without the CLI (for development and the LAMMPS comparison):
//!
//! `cargo run --release -p spatter-dem --example dem_scene -- examples/dem_hopper.toml runs/hopper [--resume]`

use spatter_core::control::RunControl;
use spatter_io::run::{RunContext, RunDir};
use spatter_workflows::dem_scene::SceneConfig;
use std::path::Path;

struct Progress;

impl RunControl for Progress {
    fn stop_requested(&self) -> bool {
        false
    }
    fn progress(&self, done: u64, total: u64) {
        if done % 20_000 == 0 {
            eprintln!("step {done} / {total}");
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: dem_scene <scenario.toml> <out dir> [--resume]");
        std::process::exit(2);
    }
    let path = Path::new(&args[1]);
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let body: String =
        text.lines().filter(|l| !l.trim_start().starts_with("kind")).collect::<Vec<_>>().join("\n");
    let cfg: SceneConfig = toml::from_str(&body).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    // Relative file paths are relative to the scenario's folder, as for `spatter run`.
    let folder = path.parent().unwrap_or(Path::new("."));
    let cfg =
        spatter_io::paths::absolute_paths(cfg, folder).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let dir = RunDir::create(Path::new(&args[2])).expect("output folder");
    let resume = args.iter().any(|a| a == "--resume");
    let t = std::time::Instant::now();
    match spatter_workflows::dem_scene::run(&cfg, &RunContext::new(&dir, &Progress, resume)) {
        Ok(s) => {
            for l in s.headline {
                println!("{l}");
            }
            for (k, p) in s.artifacts {
                println!("{k}: {}", p.display());
            }
            println!("wall time {:.1} s", t.elapsed().as_secs_f64());
        }
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
