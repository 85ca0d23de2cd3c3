//! The study file: which base scenario, which keys to vary and how.
//!
//! ```toml
//! base = "snow_bisection.toml"   # the scenario every case starts from (relative to this file)
//! design = "sobol"               # grid (default) | list | latin_hypercube | sobol
//! samples = 64                   # latin_hypercube: points; sobol: base samples N (N(k + 2) cases)
//! seed = 1
//! outputs = ["v_crit_smallest_m_s"]   # scalars to analyse and plot (default: every scalar)
//!
//! [[vary]]
//! key = "contact.work_of_adhesion_j_m2"   # dotted path into the scenario, `walls[0].x` for arrays
//! from = 0.05
//! to = 0.5
//! scale = "log"                  # linear (default) | log
//! ```
//!
//! A `[[vary]]` entry gives either `values = [...]` (grid and list designs) or a range `from`, `to`
//! (and `steps` for a grid). Every problem is reported with the study file, line, column and key.

use serde::{Deserialize, Serialize};
use spatter_scenario::source::Source;
use spatter_scenario::ScenarioError;
use std::path::{Path, PathBuf};

/// How the cases of a study are chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DesignKind {
    /// Every combination of every key's values (full factorial); the last key varies fastest.
    #[default]
    Grid,
    /// Case j takes the j-th value of every key (all lists of one length).
    List,
    /// `samples` points of a Latin hypercube over the keys' ranges.
    LatinHypercube,
    /// A Saltelli design of `samples` base points (N(k + 2) cases) for Sobol sensitivity indices.
    Sobol,
}

/// How a range is divided or sampled.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scale {
    #[default]
    Linear,
    /// Uniform in the logarithm (both ends positive).
    Log,
}

/// One varied key.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Vary {
    /// Dotted key path into the scenario (`particle.youngs_modulus_pa`, `walls[1].motion.speed_m_s`).
    pub key: String,
    /// Explicit values (grid and list designs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values: Option<Vec<toml::Value>>,
    /// Lower end of the range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<f64>,
    /// Upper end of the range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to: Option<f64>,
    /// Points of a grid range, ends included.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<usize>,
    #[serde(default)]
    pub scale: Scale,
}

/// A study file as written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StudySpec {
    /// The base scenario file, relative to the study file.
    pub base: PathBuf,
    #[serde(default)]
    pub design: DesignKind,
    /// Latin hypercube points, or Sobol base samples N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples: Option<usize>,
    /// Seed of the sampled designs and of the bootstrap intervals.
    #[serde(default)]
    pub seed: u64,
    /// Bootstrap resamples for the confidence intervals of Sobol indices.
    #[serde(default = "default_bootstrap")]
    pub bootstrap: usize,
    /// Scalars to analyse and plot; empty means every scalar the cases report.
    #[serde(default)]
    pub outputs: Vec<String>,
    /// Title of the study's report.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub title: Option<String>,
    pub vary: Vec<Vary>,
}

fn default_bootstrap() -> usize {
    200
}

/// Largest number of cases a study may plan.
pub const MAX_CASES: usize = 1_000_000;

/// A study file read and checked, with the source kept for locating later errors.
#[derive(Clone, Debug)]
pub struct StudyFile {
    pub spec: StudySpec,
    pub source: Source,
}

impl StudyFile {
    /// Reads and checks the study at `path` (not yet the base scenario).
    pub fn read(path: &Path) -> Result<Self, Vec<ScenarioError>> {
        let source = Source::read(path).map_err(|e| vec![e])?;
        Self::from_source(source)
    }

    /// Like [`read`](Self::read) for text in memory.
    pub fn from_str(path: &Path, text: &str) -> Result<Self, Vec<ScenarioError>> {
        let source = Source::from_bytes(path, text.as_bytes()).map_err(|e| vec![e])?;
        Self::from_source(source)
    }

    fn from_source(source: Source) -> Result<Self, Vec<ScenarioError>> {
        let table: toml::Table =
            spatter_scenario::parse::typed(&source, &source.text).map_err(|e| vec![e])?;
        if table.contains_key("kind") {
            let at = source.locate("kind").map(|(s, _)| s.start).unwrap_or(0);
            return Err(vec![ScenarioError::at(
                &source,
                at,
                Some("kind".into()),
                "this looks like a scenario, not a study: run it with `spatter run`; a study names its \
                 scenario with `base = \"file.toml\"` and the keys to vary in [[vary]] tables",
            )]);
        }
        let spec: StudySpec = spatter_scenario::parse::typed(&source, &source.text).map_err(|e| vec![e])?;
        let file = StudyFile { spec, source };
        let errors = file.check();
        if errors.is_empty() {
            Ok(file)
        } else {
            Err(errors)
        }
    }

    /// The base scenario's path (relative paths resolved against the study's folder).
    pub fn base_path(&self) -> PathBuf {
        if self.spec.base.is_absolute() {
            self.spec.base.clone()
        } else {
            self.source.base_dir().join(&self.spec.base)
        }
    }

    /// An error located at `key` of the study file.
    pub fn error(&self, key: &str, message: impl Into<String>) -> ScenarioError {
        let at = self.source.locate(key).map(|(s, _)| s.start).unwrap_or(0);
        ScenarioError::at(&self.source, at, Some(key.to_owned()), message)
    }

    /// Checks that do not need the base scenario.
    fn check(&self) -> Vec<ScenarioError> {
        let s = &self.spec;
        let mut errors = Vec::new();
        let mut fail = |key: String, msg: String| errors.push(self.error(&key, msg));
        if s.vary.is_empty() {
            fail("vary".into(), "a study needs at least one [[vary]] table naming a key to vary".into());
        }
        let sampled = matches!(s.design, DesignKind::LatinHypercube | DesignKind::Sobol);
        match (sampled, s.samples) {
            (true, None) => fail(
                "samples".into(),
                format!(
                    "design = \"{}\" needs `samples` (the number of base points, e.g. 64)",
                    design_name(s.design)
                ),
            ),
            (true, Some(n)) if n < 2 => fail("samples".into(), format!("samples = {n} must be at least 2")),
            (true, Some(n)) if s.design == DesignKind::Sobol && n > crate::sensitivity::MAX_SAMPLES => fail(
                "samples".into(),
                format!(
                    "samples = {n} exceeds {} (the Sobol sequence's length)",
                    crate::sensitivity::MAX_SAMPLES
                ),
            ),
            (false, Some(_)) => fail(
                "samples".into(),
                format!(
                    "`samples` applies to design = \"latin_hypercube\" or \"sobol\", not \"{}\"",
                    design_name(s.design)
                ),
            ),
            _ => {}
        }
        if s.design == DesignKind::Sobol && s.vary.len() > crate::sensitivity::MAX_INPUTS {
            fail(
                "vary".into(),
                format!("a Sobol design varies at most {} keys", crate::sensitivity::MAX_INPUTS),
            );
        }
        let mut list_len: Option<(usize, usize)> = None;
        for (i, v) in s.vary.iter().enumerate() {
            let at = |k: &str| format!("vary[{i}].{k}");
            if v.key.trim().is_empty() {
                fail(at("key"), "key = \"\" names no scenario key".into());
            }
            if let Some(j) = s.vary[..i].iter().position(|w| w.key == v.key) {
                fail(at("key"), format!("key \"{}\" is already varied by vary[{j}]", v.key));
            }
            if v.key == "kind" {
                fail(
                    at("key"),
                    "a study cannot vary `kind`: every case runs the base scenario's kind".into(),
                );
            }
            let range = v.from.is_some() || v.to.is_some() || v.steps.is_some();
            match (&v.values, range, sampled) {
                (Some(_), true, _) => fail(
                    at("values"),
                    "give either `values` or a range (`from`, `to`, `steps`), not both".into(),
                ),
                (Some(_), false, true) => fail(
                    at("values"),
                    format!(
                        "design = \"{}\" samples a range: give `from` and `to` instead of `values`",
                        design_name(s.design)
                    ),
                ),
                (Some(vals), false, false) => {
                    if vals.is_empty() {
                        fail(at("values"), "values = [] is empty: give at least one value".into());
                    }
                    if s.design == DesignKind::List {
                        match list_len {
                            None => list_len = Some((i, vals.len())),
                            Some((j, n)) if n != vals.len() => fail(
                                at("values"),
                                format!(
                                    "design = \"list\" pairs the j-th values of every key: this list has {} \
                                     values, vary[{j}] has {n}",
                                    vals.len()
                                ),
                            ),
                            _ => {}
                        }
                    }
                }
                (None, false, _) => fail(
                    at("key"),
                    format!("vary[{i}] (\"{}\") needs `values = [...]` or a range `from`, `to`", v.key),
                ),
                (None, true, _) => {
                    if s.design == DesignKind::List {
                        fail(at("from"), "design = \"list\" takes explicit `values`".into());
                    }
                    let (Some(from), Some(to)) = (v.from, v.to) else {
                        fail(
                            at(if v.from.is_none() { "to" } else { "from" }),
                            "a range needs both `from` and `to`".into(),
                        );
                        continue;
                    };
                    if !from.is_finite() || !to.is_finite() {
                        fail(at("from"), format!("range {from} .. {to} must be finite numbers"));
                    } else if v.scale == Scale::Log && (from <= 0.0 || to <= 0.0) {
                        fail(at("from"), format!("scale = \"log\" needs positive ends, got {from} .. {to}"));
                    } else if sampled && from >= to {
                        fail(at("to"), format!("to = {to} must exceed from = {from} (an empty range)"));
                    } else if !sampled && from > to {
                        fail(at("to"), format!("to = {to} is below from = {from}; write the range upwards"));
                    }
                    match (sampled, v.steps) {
                        (true, Some(_)) => fail(
                            at("steps"),
                            format!("`steps` applies to grid ranges; design \"{}\" draws `samples` points", design_name(s.design)),
                        ),
                        (false, None) => fail(at("to"), "a grid range needs `steps` (points, ends included)".into()),
                        (false, Some(0)) => fail(at("steps"), "steps = 0 is an empty range: at least 1".into()),
                        (false, Some(n)) if n > 1 && from == to => fail(
                            at("steps"),
                            format!("steps = {n} over the empty range {from} .. {to}: give steps = 1 or distinct ends"),
                        ),
                        _ => {}
                    }
                }
            }
        }
        if errors.is_empty() {
            let n = self.case_count();
            if n > MAX_CASES {
                errors.push(self.error(
                    "vary",
                    format!(
                        "the study plans {n} cases, more than {MAX_CASES}; reduce the grid or the samples"
                    ),
                ));
            }
        }
        errors
    }

    /// Cases the design plans (saturating).
    pub fn case_count(&self) -> usize {
        let s = &self.spec;
        let k = s.vary.len();
        let n = s.samples.unwrap_or(0);
        match s.design {
            DesignKind::Grid => s.vary.iter().fold(1usize, |acc, v| {
                acc.saturating_mul(v.values.as_ref().map(Vec::len).or(v.steps).unwrap_or(1))
            }),
            DesignKind::List => s.vary.first().and_then(|v| v.values.as_ref()).map(Vec::len).unwrap_or(0),
            DesignKind::LatinHypercube => n,
            DesignKind::Sobol => n.saturating_mul(k + 2),
        }
    }
}

/// The design's name as written in a study file.
pub fn design_name(d: DesignKind) -> &'static str {
    match d {
        DesignKind::Grid => "grid",
        DesignKind::List => "list",
        DesignKind::LatinHypercube => "latin_hypercube",
        DesignKind::Sobol => "sobol",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(text: &str) -> Result<StudyFile, Vec<ScenarioError>> {
        StudyFile::from_str(Path::new("study.toml"), text)
    }

    fn first_error(text: &str) -> String {
        read(text).unwrap_err()[0].to_string()
    }

    #[test]
    fn a_grid_study_counts_its_cases() {
        let s = read(
            "base = \"b.toml\"\n[[vary]]\nkey = \"a\"\nvalues = [1, 2]\n[[vary]]\nkey = \"b.c\"\nfrom = 1.0\nto = 2.0\nsteps = 3\n",
        )
        .unwrap();
        assert_eq!(s.case_count(), 6);
        assert_eq!(s.base_path(), Path::new("./b.toml"));
    }

    #[test]
    fn bad_studies_name_line_and_key() {
        let e = first_error("base = \"b.toml\"\n[[vary]]\nkey = \"a\"\nvalues = []\n");
        assert!(e.contains("study.toml:4:") && e.contains("vary[0].values") && e.contains("empty"), "{e}");
        let e = first_error("base = \"b.toml\"\n[[vary]]\nkey = \"a\"\nfrom = 1.0\nto = 2.0\nsteps = 0\n");
        assert!(e.contains("vary[0].steps") && e.contains("empty range"), "{e}");
        let e = first_error("base = \"b.toml\"\n[[vary]]\nkey = \"a\"\nvalues = [1]\nsize = 3\n");
        assert!(e.contains("size"), "{e}");
        let e = first_error(
            "base = \"b.toml\"\ndesign = \"sobol\"\n[[vary]]\nkey = \"a\"\nfrom = 1.0\nto = 2.0\n",
        );
        assert!(e.contains("samples"), "{e}");
        let e = first_error("kind = \"dem\"\n");
        assert!(e.contains("not a study"), "{e}");
        let e = first_error("base = \"b.toml\"\ndesign = \"list\"\n[[vary]]\nkey = \"a\"\nvalues = [1, 2]\n[[vary]]\nkey = \"b\"\nvalues = [1]\n");
        assert!(e.contains("vary[1].values") && e.contains("has 2"), "{e}");
        let e = first_error(
            "base = \"b.toml\"\n[[vary]]\nkey = \"a\"\nvalues = [1]\n[[vary]]\nkey = \"a\"\nvalues = [2]\n",
        );
        assert!(e.contains("already varied"), "{e}");
        let e = first_error("base = \"b.toml\"\ndesign = \"latin_hypercube\"\nsamples = 4\n[[vary]]\nkey = \"a\"\nfrom = 1.0\nto = 1.0\n");
        assert!(e.contains("empty range"), "{e}");
        let e = first_error(
            "base = \"b.toml\"\n[[vary]]\nkey = \"a\"\nfrom = -1.0\nto = 2.0\nsteps = 2\nscale = \"log\"\n",
        );
        assert!(e.contains("positive"), "{e}");
        let e = first_error("base = 3\n");
        assert!(e.contains("base"), "{e}");
    }
}
