//! Every scenario file in `examples/` runs to the end (`spatter run --smoke`, a reduced size) and leaves outputs
//! that exist and hold finite numbers.

mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::time::Instant;

fn examples() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        // Study files (`spatter sweep`) are run by the study crate's tests.
        .filter(|p| !p.to_string_lossy().ends_with("_study.toml"))
        .collect();
    v.sort();
    assert!(v.len() >= 10, "examples found: {v:?}");
    v
}

/// Every number in a CSV file is finite or, where a quantity is undefined (a probe without fluid, a
/// critical speed outside the bracket), NaN; infinity never. Returns the number of numeric cells.
fn csv_numbers(path: &Path) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    let mut n = 0;
    for (i, line) in text.lines().enumerate().skip(1) {
        for cell in line.split(',') {
            if let Ok(x) = cell.trim().parse::<f64>() {
                assert!(!x.is_infinite(), "{}:{}: {cell}", path.display(), i + 1);
                n += 1;
            }
        }
    }
    n
}

fn files(dir: &Path, ext: &str, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            files(&p, ext, out);
        } else if p.extension().is_some_and(|x| x == ext) {
            out.push(p);
        }
    }
}

#[test]
fn every_example_runs_to_the_end_at_smoke_size() {
    let tmp = tempfile::tempdir().unwrap();
    let mut report = Vec::new();
    for ex in examples() {
        let name = ex.file_stem().unwrap().to_string_lossy().into_owned();
        let out = tmp.path().join(&name);
        let t = Instant::now();
        let o = spatter()
            .arg("run")
            .arg(&ex)
            .arg("--smoke")
            .arg("--out")
            .arg(&out)
            .env("SPATTER_NO_PROGRESS", "1")
            .output()
            .unwrap();
        let secs = t.elapsed().as_secs_f64();
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{name} failed:\n{}\n{stderr}", String::from_utf8_lossy(&o.stdout));
        assert!(!stderr.contains("panicked"), "{name}: {stderr}");
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
        assert_eq!(summary["finished"], "completed", "{name}");
        for pair in summary["scalars"].as_array().unwrap() {
            assert!(pair[1].as_f64().is_some_and(f64::is_finite), "{name}: scalar {pair}");
        }
        for a in summary["artifacts"].as_array().unwrap() {
            let rel = a[1].as_str().unwrap();
            assert!(out.join(rel).exists(), "{name}: artifact {a} missing");
        }
        let mut csvs = Vec::new();
        files(&out, "csv", &mut csvs);
        let numbers: usize = csvs.iter().map(|p| csv_numbers(p)).sum();
        let mut vtus = Vec::new();
        files(&out, "vtu", &mut vtus);
        for v in &vtus {
            let d = spatter_io::vtk::read(v).unwrap_or_else(|e| panic!("{name}: {}: {e}", v.display()));
            assert!(d.points.iter().all(|p| p.is_finite()), "{name}: {} has non-finite points", v.display());
            for a in d.point_data.iter().chain(&d.cell_data) {
                assert!(
                    a.values.iter().all(|x| x.is_finite()),
                    "{name}: {} array `{}` holds NaN or infinity",
                    v.display(),
                    a.name
                );
            }
        }
        // The resolved input of the reduced run is itself a valid scenario.
        let (code, err) = check(&out.join("run.toml"));
        assert_eq!(code, 0, "{name}: run.toml does not check: {err}");
        report.push(format!(
            "{name}: {secs:.1} s, {} CSV ({numbers} numbers), {} VTU",
            csvs.len(),
            vtus.len()
        ));
    }
    eprintln!("{}", report.join("\n"));
}
