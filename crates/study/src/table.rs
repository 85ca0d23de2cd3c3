//! The results table of a study, read from its case folders: one row per case with the varied values,
//! the case's status and every scalar it reported.

use crate::plan::{case_dir_name, table_text, Plan};
use spatter_io::summary::SummaryFile;
use std::path::Path;

/// Where a case stands.
#[derive(Clone, Debug, PartialEq)]
pub enum Status {
    Completed,
    /// Stopped with a checkpoint; a rerun resumes it.
    Interrupted,
    /// Ended with an error (its message).
    Failed(String),
    /// Never started (another shard's, or the study stopped before it).
    NotRun,
}

impl Status {
    fn word(&self) -> &'static str {
        match self {
            Status::Completed => "completed",
            Status::Interrupted => "interrupted",
            Status::Failed(_) => "failed",
            Status::NotRun => "not run",
        }
    }
}

/// One case's row.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    pub case: usize,
    /// Varied values as table text.
    pub values: Vec<String>,
    pub status: Status,
    /// Reported scalars (NaN for a non-finite one).
    pub scalars: Vec<(String, f64)>,
    /// Wall time of the case's last invocation \[s\].
    pub wall_time_s: f64,
    /// Worker threads the case ran with (0 when it did not finish).
    pub threads: usize,
}

/// The table of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    pub keys: Vec<String>,
    /// Scalar columns: every name any case reported, in the order of first appearance by case index.
    pub scalar_names: Vec<String>,
    pub rows: Vec<Row>,
}

impl Table {
    /// Reads every case folder of `plan` under `out`.
    pub fn read(plan: &Plan, out: &Path) -> Table {
        let mut names: Vec<String> = Vec::new();
        let rows = plan
            .cases
            .iter()
            .map(|c| {
                let dir = out.join("cases").join(case_dir_name(c.index));
                let (status, scalars, wall, threads) = match SummaryFile::read(&dir) {
                    Ok(Some(s)) => {
                        let status = if s.completed() { Status::Completed } else { Status::Interrupted };
                        let sc: Vec<(String, f64)> =
                            s.scalars.iter().map(|(k, v)| (k.clone(), v.unwrap_or(f64::NAN))).collect();
                        (status, sc, s.wall_time_s, s.threads)
                    }
                    Ok(None) => match std::fs::read_to_string(dir.join("error.txt")) {
                        Ok(msg) => (Status::Failed(msg.trim().to_owned()), Vec::new(), 0.0, 0),
                        Err(_) => (Status::NotRun, Vec::new(), 0.0, 0),
                    },
                    Err(msg) => (Status::Failed(msg), Vec::new(), 0.0, 0),
                };
                for (k, _) in &scalars {
                    if !names.contains(k) {
                        names.push(k.clone());
                    }
                }
                Row {
                    case: c.index,
                    values: c.values.iter().map(table_text).collect(),
                    status,
                    scalars,
                    wall_time_s: wall,
                    threads,
                }
            })
            .collect();
        Table { keys: plan.keys.clone(), scalar_names: names, rows }
    }

    /// Cases that have not completed, with the reason.
    pub fn unfinished(&self) -> Vec<(usize, String)> {
        self.rows
            .iter()
            .filter(|r| r.status != Status::Completed)
            .map(|r| {
                let why = match &r.status {
                    Status::Failed(m) => format!("failed: {}", m.lines().next().unwrap_or("")),
                    s => s.word().to_owned(),
                };
                (r.case, why)
            })
            .collect()
    }

    /// The value of scalar `name` for every case (NaN where absent).
    pub fn column(&self, name: &str) -> Vec<f64> {
        self.rows
            .iter()
            .map(|r| r.scalars.iter().find(|(k, _)| k == name).map(|(_, v)| *v).unwrap_or(f64::NAN))
            .collect()
    }

    /// `results.csv`: `case`, the varied keys, `status`, then every scalar (empty where a case did not
    /// report it). Numbers in their shortest exact form, so the file is the same wherever it is built.
    pub fn results_csv(&self) -> String {
        let mut s = String::from("case");
        for k in self.keys.iter().chain(std::iter::once(&"status".to_owned())).chain(&self.scalar_names) {
            s.push(',');
            s.push_str(&csv_field(k));
        }
        s.push('\n');
        for r in &self.rows {
            s.push_str(&r.case.to_string());
            for v in &r.values {
                s.push(',');
                s.push_str(&csv_field(v));
            }
            s.push(',');
            s.push_str(r.status.word());
            for name in &self.scalar_names {
                s.push(',');
                if let Some((_, v)) = r.scalars.iter().find(|(k, _)| k == name) {
                    s.push_str(&spatter_io::fmt_f64(*v));
                }
            }
            s.push('\n');
        }
        s
    }

    /// What every case cost: [`Cost`] per row, in case order.
    pub fn costs(&self) -> Vec<Cost> {
        self.rows.iter().map(Cost::of).collect()
    }

    /// `cost.csv`: per case the particles and steps (where the kind reports them), wall time, threads and
    /// core-hours. Empty cells where a case did not report a number.
    pub fn cost_csv(&self) -> String {
        let mut s = String::from(
            "case,particles,wall_particles,steps,wall_time_s,threads,core_hours,particle_steps_per_s\n",
        );
        let cell = |v: Option<f64>| v.map(spatter_io::fmt_f64).unwrap_or_default();
        for c in self.costs() {
            s.push_str(&format!(
                "{},{},{},{},{:.3},{},{:.6},{}\n",
                c.case,
                cell(c.particles),
                cell(c.wall_particles),
                cell(c.steps),
                c.wall_time_s,
                c.threads,
                c.core_hours(),
                c.particle_steps_per_s().map(|r| format!("{r:.4e}")).unwrap_or_default(),
            ));
        }
        s
    }

    /// Sum of the cases' wall times \[s\].
    pub fn total_wall_time_s(&self) -> f64 {
        self.rows.iter().map(|r| r.wall_time_s).sum()
    }
}

/// The cost of one case: its size (from the scalars the kind reports: `particles`, or `fluid_particles`
/// and `wall_particles` for the SPH kinds; `steps`) and its wall time and threads.
#[derive(Clone, Debug, PartialEq)]
pub struct Cost {
    pub case: usize,
    /// Moving particles (DEM particles, SPH fluid particles).
    pub particles: Option<f64>,
    /// Fixed or prescribed boundary particles (SPH wall particles).
    pub wall_particles: Option<f64>,
    pub steps: Option<f64>,
    /// Wall time of the case's last invocation \[s\].
    pub wall_time_s: f64,
    pub threads: usize,
}

impl Cost {
    fn of(r: &Row) -> Self {
        let get = |n: &str| r.scalars.iter().find(|(k, _)| k == n).map(|(_, v)| *v).filter(|v| v.is_finite());
        Cost {
            case: r.case,
            particles: get("particles").or_else(|| get("fluid_particles")),
            wall_particles: get("wall_particles"),
            steps: get("steps"),
            wall_time_s: r.wall_time_s,
            threads: r.threads,
        }
    }

    /// Wall time × threads, in hours.
    pub fn core_hours(&self) -> f64 {
        self.wall_time_s * self.threads.max(1) as f64 / 3600.0
    }

    /// Moving particles × steps / wall time, where both are reported.
    pub fn particle_steps_per_s(&self) -> Option<f64> {
        match (self.particles, self.steps) {
            (Some(n), Some(s)) if self.wall_time_s > 0.0 => Some(n * s / self.wall_time_s),
            _ => None,
        }
    }
}

/// A CSV field, quoted when it holds a comma, quote or line break.
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(scalars: &[(&str, f64)], wall: f64, threads: usize) -> Row {
        Row {
            case: 2,
            values: vec!["0.1".into()],
            status: Status::Completed,
            scalars: scalars.iter().map(|(k, v)| ((*k).to_owned(), *v)).collect(),
            wall_time_s: wall,
            threads,
        }
    }

    /// Core-hours are wall time × threads; particle-steps per second are moving particles × steps over the
    /// wall time; SPH kinds report their fluid and wall particles apart.
    #[test]
    fn the_cost_of_a_case_comes_from_its_size_wall_time_and_threads() {
        let sph =
            row(&[("fluid_particles", 5000.0), ("wall_particles", 40000.0), ("steps", 720.0)], 1800.0, 2);
        let c = Cost::of(&sph);
        assert_eq!((c.particles, c.wall_particles, c.steps), (Some(5000.0), Some(40000.0), Some(720.0)));
        assert!((c.core_hours() - 1.0).abs() < 1e-15);
        assert!((c.particle_steps_per_s().unwrap() - 2000.0).abs() < 1e-9);
        let snow = row(&[("impacts", 10.0)], 36.0, 1);
        let c = Cost::of(&snow);
        assert_eq!((c.particles, c.steps, c.particle_steps_per_s()), (None, None, None));
        let t = Table { keys: vec!["k".into()], scalar_names: Vec::new(), rows: vec![sph, snow] };
        let csv = t.cost_csv();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[1], "2,5000,40000,720,1800.000,2,1.000000,2.0000e3");
        assert_eq!(lines[2], "2,,,,36.000,1,0.010000,");
    }
}
