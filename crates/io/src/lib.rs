//! `spatter-io`: what a run leaves on disk.
//!
//! * [`run`] — the run folder, the context a job runs in and the summary it returns;
//! * [`csv`] — time series with units in the header, resumable after a checkpoint;
//! * [`vtu`] — VTK XML unstructured grids (particles and triangle meshes);
//! * [`vtr`] — VTK XML rectilinear grids (structured flow fields);
//! * [`vtk`] — the one VTK reader: legacy `.vtk` and XML `.vtu/.vts/.vtr/.vti` (ours, ParaView's,
//!   OpenFOAM's `foamToVTK`) into one unstructured dataset, and `.pvd`/`.series` time series;
//! * [`pvd`] — ParaView `.pvd` collections that tie VTU snapshots to times;
//! * [`checkpoint`] — atomic, versioned, checksummed binary snapshots of a job's state;
//! * [`rank_checkpoint`] — the same for a run split over ranks: one part per rank and a manifest;
//! * [`runlog`] — the current run's `log.txt`, where the program's one `tracing` subscriber writes;
//! * [`plot`] — PNG/SVG charts and mesh colour maps;
//! * [`summary`] — `summary.json`, a run's result in machine-readable form;
//! * [`report`] — self-contained HTML reports of runs and studies.

pub mod checkpoint;
pub mod csv;
pub mod paths;
pub mod plot;
pub mod pvd;
pub mod rank_checkpoint;
pub mod report;
pub mod run;
pub mod runlog;
pub mod summary;
pub mod vtk;
mod vtk_xml;
pub mod vtr;
pub mod vtu;

/// Formats `x` so that it parses back to the same `f64` (shortest round-trip form), in exponent notation
/// for very large or small magnitudes.
pub fn fmt_f64(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || (1e-4..1e15).contains(&a) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn float_formatting_round_trips() {
        for x in [0.0, 1.0, -2.5, 1e-20, 6.02214076e23, 0.1, 1.0 / 3.0, 123456.789, f64::MIN_POSITIVE] {
            let s = super::fmt_f64(x);
            assert_eq!(s.parse::<f64>().unwrap(), x, "{s}");
        }
        assert_eq!(super::fmt_f64(1e-20), "1e-20");
    }
}
