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
                let (status, scalars, wall) = match SummaryFile::read(&dir) {
                    Ok(Some(s)) => {
                        let status = if s.completed() { Status::Completed } else { Status::Interrupted };
                        let sc: Vec<(String, f64)> =
                            s.scalars.iter().map(|(k, v)| (k.clone(), v.unwrap_or(f64::NAN))).collect();
                        (status, sc, s.wall_time_s)
                    }
                    Ok(None) => match std::fs::read_to_string(dir.join("error.txt")) {
                        Ok(msg) => (Status::Failed(msg.trim().to_owned()), Vec::new(), 0.0),
                        Err(_) => (Status::NotRun, Vec::new(), 0.0),
                    },
                    Err(msg) => (Status::Failed(msg), Vec::new(), 0.0),
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

    /// `cost.csv`: wall time of every case and the total.
    pub fn cost_csv(&self) -> String {
        let mut s = String::from("case,wall_time_s\n");
        for r in &self.rows {
            s.push_str(&format!("{},{:.3}\n", r.case, r.wall_time_s));
        }
        s
    }

    /// Sum of the cases' wall times \[s\].
    pub fn total_wall_time_s(&self) -> f64 {
        self.rows.iter().map(|r| r.wall_time_s).sum()
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
