//! From a study file to the list of cases: the design's values for every varied key, written into the
//! base scenario's fully resolved input, and every case validated before anything runs.

use crate::keys::{self, Seg};
use crate::sensitivity::{latin_hypercube, SaltelliDesign};
use crate::spec::{design_name, DesignKind, Scale, StudyFile, Vary};
use spatter_scenario::ScenarioError;
use std::path::{Path, PathBuf};
use toml_edit::{DocumentMut, Item, Value};

/// One case of a study.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Position in the design (0-based); also the case's folder name `case_NNNNN`.
    pub index: usize,
    /// The value of every varied key, in the study's `[[vary]]` order.
    pub values: Vec<toml::Value>,
    /// The case's scenario: the base's resolved input with the values written in.
    pub text: String,
}

/// Every case of a study, ready to run.
#[derive(Clone, Debug)]
pub struct Plan {
    /// The varied keys, in `[[vary]]` order.
    pub keys: Vec<String>,
    pub cases: Vec<Case>,
    /// The Saltelli design, for a Sobol study.
    pub saltelli: Option<SaltelliDesign>,
    /// The base scenario's `kind`.
    pub kind: String,
    /// The base scenario file.
    pub base: PathBuf,
}

/// Folder name of case `index`.
pub fn case_dir_name(index: usize) -> String {
    format!("case_{index:05}")
}

impl Plan {
    /// A case named with its values, for captions and legends: `case 3: adhesion = 0.1, enabled = true`
    /// (each key by its last part).
    pub fn caption(&self, case: &Case) -> String {
        let values: Vec<String> = self
            .keys
            .iter()
            .zip(&case.values)
            .map(|(k, v)| format!("{} = {}", k.rsplit('.').next().unwrap_or(k), table_text(v)))
            .collect();
        format!("case {}: {}", case.index, values.join(", "))
    }

    /// Reads the base scenario, checks every varied key against it and builds every case. `case_root` is
    /// where case folders will be (case scenarios are validated as if they were there).
    pub fn new(study: &StudyFile, case_root: &Path) -> Result<Plan, Vec<ScenarioError>> {
        let base = study.base_path();
        if !base.is_file() {
            return Err(vec![study.error(
                "base",
                format!("base = {:?}: no scenario file at {}", study.spec.base, base.display()),
            )]);
        }
        let loaded = spatter_scenario::load(&base)?;
        let resolved = loaded.scenario.resolved_toml().map_err(|e| {
            vec![study.error("base", format!("cannot write the base scenario's resolved input: {e}"))]
        })?;
        let doc: DocumentMut = resolved.parse().map_err(|e| {
            vec![study.error("base", format!("the base scenario's resolved input is not TOML: {e}"))]
        })?;
        let mut errors = Vec::new();
        let mut paths = Vec::new();
        for (i, v) in study.spec.vary.iter().enumerate() {
            match check_key(study, &doc, i, v) {
                Ok(p) => paths.push(p),
                Err(e) => errors.push(e),
            }
        }
        if !errors.is_empty() {
            return Err(errors);
        }
        let (rows, saltelli) = design_values(study);
        let mut cases = Vec::with_capacity(rows.len());
        for (index, raw) in rows.into_iter().enumerate() {
            let mut values = Vec::with_capacity(raw.len());
            let mut doc = doc.clone();
            for (i, (path, value)) in paths.iter().zip(raw).enumerate() {
                let item = keys::get(&doc, path)
                    .map_err(|_| vec![study.error(&format!("vary[{i}].key"), "key vanished")])?;
                let value = adapt(study, i, item, value).map_err(|e| vec![e])?;
                let edit = to_edit_value(&value).map_err(|m| vec![study.error(&format!("vary[{i}]"), m)])?;
                keys::set(&mut doc, path, edit);
                values.push(value);
            }
            let header = format!(
                "# Case {index} of the study {}: {}\n",
                study.source.path.display(),
                study
                    .spec
                    .vary
                    .iter()
                    .zip(&values)
                    .map(|(v, x)| format!("{} = {}", v.key, x))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            let text = format!("{header}{doc}");
            let path = case_root.join(case_dir_name(index)).join("case.toml");
            if let Err(list) = spatter_scenario::load_str(&path, &text) {
                return Err(list.into_iter().map(|e| case_error(study, index, &values, e)).collect());
            }
            cases.push(Case { index, values, text });
        }
        Ok(Plan {
            keys: study.spec.vary.iter().map(|v| v.key.clone()).collect(),
            cases,
            saltelli,
            kind: loaded.scenario.kind().to_owned(),
            base,
        })
    }

    /// Indices of the cases shard `i` of `n` runs (1 ≤ i ≤ n): every n-th case starting at i − 1.
    pub fn shard(&self, i: usize, n: usize) -> impl Iterator<Item = &Case> {
        self.cases.iter().filter(move |c| c.index % n == i - 1)
    }
}

/// The key's path, if the base scenario has it (with every default filled in).
fn check_key(study: &StudyFile, doc: &DocumentMut, i: usize, v: &Vary) -> Result<Vec<Seg>, ScenarioError> {
    let at = format!("vary[{i}].key");
    let path = keys::parse(&v.key).ok_or_else(|| {
        study.error(
            &at,
            format!("key = \"{}\" is not a key path like `particle.radius_m` or `walls[0].z`", v.key),
        )
    })?;
    match keys::get(doc, &path) {
        Ok(Item::Value(_)) => Ok(path),
        Ok(item) => Err(study.error(
            &at,
            format!(
                "key \"{}\" is {} in the base scenario; a study varies single values (name a key inside it)",
                v.key,
                keys::type_name(item)
            ),
        )),
        Err(m) => {
            let place = if m.found.is_empty() {
                "at the top level".to_owned()
            } else {
                format!("under `{}`", m.found)
            };
            let avail = if m.available.is_empty() {
                String::new()
            } else {
                format!("; keys there: {}", m.available.join(", "))
            };
            Err(study.error(
                &at,
                format!("the base scenario has no key \"{}\" (defaults filled in) {place}{avail}", v.key),
            ))
        }
    }
}

/// The design's raw values, one row per case, one value per varied key.
fn design_values(study: &StudyFile) -> (Vec<Vec<toml::Value>>, Option<SaltelliDesign>) {
    let s = &study.spec;
    let k = s.vary.len();
    let sample = |v: &Vary, u: f64| -> toml::Value {
        let (a, b) = (v.from.unwrap_or(0.0), v.to.unwrap_or(1.0));
        toml::Value::Float(match v.scale {
            Scale::Linear => a + u * (b - a),
            Scale::Log => (a.ln() + u * (b.ln() - a.ln())).exp(),
        })
    };
    match s.design {
        DesignKind::Grid => {
            let axes: Vec<Vec<toml::Value>> = s.vary.iter().map(axis_values).collect();
            let total: usize = axes.iter().map(Vec::len).product();
            let rows = (0..total)
                .map(|mut r| {
                    let mut row = vec![toml::Value::Boolean(false); k];
                    for (i, axis) in axes.iter().enumerate().rev() {
                        row[i] = axis[r % axis.len()].clone();
                        r /= axis.len();
                    }
                    row
                })
                .collect();
            (rows, None)
        }
        DesignKind::List => {
            let n = s.vary.first().and_then(|v| v.values.as_ref()).map(Vec::len).unwrap_or(0);
            let rows = (0..n)
                .map(|j| {
                    s.vary
                        .iter()
                        .map(|v| {
                            v.values.as_ref().map(|x| x[j].clone()).unwrap_or(toml::Value::Boolean(false))
                        })
                        .collect()
                })
                .collect();
            (rows, None)
        }
        DesignKind::LatinHypercube => {
            let pts = latin_hypercube(s.samples.unwrap_or(0), k, s.seed);
            (pts.iter().map(|p| s.vary.iter().zip(p).map(|(v, &u)| sample(v, u)).collect()).collect(), None)
        }
        DesignKind::Sobol => {
            let d = SaltelliDesign { n: s.samples.unwrap_or(0), k, seed: s.seed as u32 };
            let rows = (0..d.runs())
                .map(|r| s.vary.iter().zip(d.point(r)).map(|(v, u)| sample(v, u)).collect())
                .collect();
            (rows, Some(d))
        }
    }
}

/// The values of one key on a grid: its list, or its range divided into `steps` points (ends exact).
fn axis_values(v: &Vary) -> Vec<toml::Value> {
    if let Some(vals) = &v.values {
        return vals.clone();
    }
    let (a, b, n) = (v.from.unwrap_or(0.0), v.to.unwrap_or(0.0), v.steps.unwrap_or(1));
    (0..n)
        .map(|i| {
            let t = if n == 1 { 0.0 } else { i as f64 / (n - 1) as f64 };
            let x = if i == 0 {
                a
            } else if i + 1 == n {
                b
            } else {
                match v.scale {
                    Scale::Linear => a + t * (b - a),
                    Scale::Log => (a.ln() + t * (b.ln() - a.ln())).exp(),
                }
            };
            toml::Value::Float(x)
        })
        .collect()
}

/// `value` converted to the type the base scenario has at the key: an integer where it has a number
/// becomes a number; a number where it has an integer must be whole.
fn adapt(study: &StudyFile, i: usize, base: &Item, value: toml::Value) -> Result<toml::Value, ScenarioError> {
    let key = &study.spec.vary[i].key;
    let at = if study.spec.vary[i].values.is_some() {
        format!("vary[{i}].values")
    } else {
        format!("vary[{i}].from")
    };
    let wrong = |want: &str| {
        study.error(
            &at,
            format!(
                "key \"{key}\" is {want} in the base scenario, but the study gives {value} ({})",
                value.type_str()
            ),
        )
    };
    match (base, &value) {
        (Item::Value(Value::Float(_)), toml::Value::Float(_)) => Ok(value),
        (Item::Value(Value::Float(_)), toml::Value::Integer(n)) => Ok(toml::Value::Float(*n as f64)),
        (Item::Value(Value::Integer(_)), toml::Value::Integer(_)) => Ok(value),
        (Item::Value(Value::Integer(_)), toml::Value::Float(x)) if x.fract() == 0.0 && x.abs() < 9.0e15 => {
            if matches!(study.spec.design, DesignKind::Sobol | DesignKind::LatinHypercube) {
                return Err(wrong("an integer"));
            }
            Ok(toml::Value::Integer(*x as i64))
        }
        (Item::Value(Value::Integer(_)), _) => Err(wrong("an integer")),
        (Item::Value(Value::Float(_)), _) => Err(wrong("a number")),
        (Item::Value(Value::String(_)), toml::Value::String(_)) => Ok(value),
        (Item::Value(Value::Boolean(_)), toml::Value::Boolean(_)) => Ok(value),
        (Item::Value(Value::Array(_)), toml::Value::Array(_)) => Ok(value),
        (Item::Value(Value::InlineTable(_)), toml::Value::Table(_)) => Ok(value),
        (item, _) => Err(wrong(keys::type_name(item))),
    }
}

/// A `toml` value as a `toml_edit` value (through its TOML text, which both crates share).
fn to_edit_value(v: &toml::Value) -> Result<Value, String> {
    let text = match v {
        toml::Value::Float(x) if !x.is_finite() => return Err(format!("value {x} is not finite")),
        other => other.to_string(),
    };
    text.parse::<Value>().map_err(|e| format!("value {text} cannot be written as TOML: {e}"))
}

/// A case's validation error, told as a problem of the study (which case, which values) at the varied
/// key it concerns when there is one.
fn case_error(study: &StudyFile, index: usize, values: &[toml::Value], e: ScenarioError) -> ScenarioError {
    let assigned = study
        .spec
        .vary
        .iter()
        .zip(values)
        .map(|(v, x)| format!("{} = {}", v.key, x))
        .collect::<Vec<_>>()
        .join(", ");
    let culprit =
        e.key.as_ref().and_then(|k| study.spec.vary.iter().position(|v| &v.key == k || k.ends_with(&v.key)));
    let at = match culprit {
        Some(i) => format!("vary[{i}].key"),
        None => "vary".to_owned(),
    };
    let what = e.key.as_ref().map(|k| format!("key `{k}`: ")).unwrap_or_default();
    study.error(
        &at,
        format!(
            "case {index} ({assigned}) of design \"{}\" is not a valid scenario: {what}{}",
            design_name(study.spec.design),
            e.message
        ),
    )
}

/// The text of a value in a results table: numbers in their shortest exact form, strings unquoted.
pub fn table_text(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(x) => spatter_io::fmt_f64(*x),
        toml::Value::Integer(n) => n.to_string(),
        toml::Value::String(s) => s.clone(),
        toml::Value::Boolean(b) => b.to_string(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::StudyFile;

    /// A study next to a copy of the snow bisection example (any kind would do; this one is small).
    fn study(dir: &Path, body: &str) -> Result<Plan, Vec<ScenarioError>> {
        std::fs::write(dir.join("base.toml"), "kind = \"snow_regime_map\"\nmode = \"bisection\"\n").unwrap();
        let path = dir.join("study.toml");
        std::fs::write(&path, format!("base = \"base.toml\"\n{body}")).unwrap();
        let s = StudyFile::read(&path)?;
        Plan::new(&s, &dir.join("cases"))
    }

    #[test]
    fn a_grid_varies_the_last_key_fastest_with_exact_ends() {
        let dir = tempfile::tempdir().unwrap();
        let p = study(
            dir.path(),
            "[[vary]]\nkey = \"particle.poisson_ratio\"\nvalues = [0.2, 0.3]\n[[vary]]\nkey = \"particle.density_kg_m3\"\nfrom = 100\nto = 1000\nsteps = 3\nscale = \"log\"\n",
        )
        .unwrap();
        assert_eq!(p.cases.len(), 6);
        let dens: Vec<f64> = p.cases.iter().map(|c| c.values[1].as_float().unwrap()).collect();
        assert_eq!(dens[0], 100.0);
        assert!((dens[1] - 316.227_766_016_837_94).abs() < 1e-9);
        assert_eq!(dens[2], 1000.0);
        assert_eq!(p.cases[3].values[0].as_float(), Some(0.3));
        assert!(p.cases[4].text.contains("density_kg_m3 = 316.22776601683"), "{}", p.cases[4].text);
        assert_eq!(p.kind, "snow_regime_map");
        let shard: Vec<usize> = p.shard(2, 4).map(|c| c.index).collect();
        assert_eq!(shard, vec![1, 5]);
    }

    #[test]
    fn bad_keys_values_and_cases_name_the_study_key() {
        let dir = tempfile::tempdir().unwrap();
        let e = study(dir.path(), "[[vary]]\nkey = \"particle.radius_m\"\nvalues = [1.0]\n").unwrap_err();
        let m = e[0].to_string();
        assert!(m.contains("vary[0].key") && m.contains("no key") && m.contains("poisson_ratio"), "{m}");
        let e =
            study(dir.path(), "[[vary]]\nkey = \"particle.poisson_ratio\"\nvalues = [\"x\"]\n").unwrap_err();
        let m = e[0].to_string();
        assert!(m.contains("is a number") && m.contains("string"), "{m}");
        let e = study(dir.path(), "[[vary]]\nkey = \"particle.poisson_ratio\"\nvalues = [0.3, 0.7]\n")
            .unwrap_err();
        let m = e[0].to_string();
        assert!(
            m.contains("case 1") && m.contains("poisson_ratio = 0.7") && m.contains("study.toml:"),
            "{m}"
        );
        let e = study(dir.path(), "[[vary]]\nkey = \"particle\"\nvalues = [1.0]\n").unwrap_err();
        assert!(e[0].to_string().contains("a table"), "{}", e[0]);
    }

    #[test]
    fn a_sobol_plan_has_n_times_k_plus_2_cases_inside_the_ranges() {
        let dir = tempfile::tempdir().unwrap();
        let p = study(
            dir.path(),
            "design = \"sobol\"\nsamples = 8\n[[vary]]\nkey = \"particle.poisson_ratio\"\nfrom = 0.2\nto = 0.4\n[[vary]]\nkey = \"particle.youngs_modulus_pa\"\nfrom = 1e9\nto = 1e10\nscale = \"log\"\n",
        )
        .unwrap();
        assert_eq!(p.cases.len(), 32);
        for c in &p.cases {
            let nu = c.values[0].as_float().unwrap();
            let e = c.values[1].as_float().unwrap();
            assert!((0.2..0.4).contains(&nu) && (1e9..1e10).contains(&e), "{nu} {e}");
        }
        assert!(p.saltelli.is_some());
    }
}
