//! Typed reading of a scenario and validation, with every error located in the file.

use crate::source::Source;
use serde::de::DeserializeOwned;
use spatter_core::check::{Checker, Validate};
use std::fmt;
use std::path::{Path, PathBuf};

/// A problem with a scenario file: where it is and what is expected instead.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioError {
    pub path: PathBuf,
    /// 1-based line and column, when the problem has a place in the file.
    pub position: Option<(usize, usize)>,
    /// Dotted key path, when the problem belongs to a key.
    pub key: Option<String>,
    pub message: String,
}

impl ScenarioError {
    /// A problem with the file as a whole (cannot read, empty, binary).
    pub fn whole_file(path: &Path, message: impl Into<String>) -> Self {
        ScenarioError { path: path.to_owned(), position: None, key: None, message: message.into() }
    }

    /// A problem at byte `offset` of `src`.
    pub fn at(src: &Source, offset: usize, key: Option<String>, message: impl Into<String>) -> Self {
        ScenarioError {
            path: src.path.clone(),
            position: Some(src.line_col(offset)),
            key,
            message: message.into(),
        }
    }
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if let Some((l, c)) = self.position {
            write!(f, ":{l}:{c}")?;
        }
        if let Some(k) = &self.key {
            write!(f, ": key `{k}`")?;
        }
        write!(f, ": {}", self.message)
    }
}

impl std::error::Error for ScenarioError {}

/// Deserialises `text` (the file's text, possibly with the `kind` line blanked out) into `T`.
pub fn typed<T: DeserializeOwned>(src: &Source, text: &str) -> Result<T, ScenarioError> {
    toml::from_str::<T>(text).map_err(|e| {
        let message = tidy(e.message());
        match e.span() {
            Some(span) => {
                let key = key_path_at(src, span.start);
                let snippet = src.text.get(span.clone()).unwrap_or("").trim();
                let message = if is_value_error(&message) && !snippet.is_empty() && snippet.len() < 80 {
                    format!("{message} (found `{snippet}`)")
                } else {
                    message
                };
                ScenarioError::at(src, span.start, key, message)
            }
            None => ScenarioError { path: src.path.clone(), position: None, key: None, message },
        }
    })
}

/// Runs the physical checks of `item`, locating each failing key in the file.
pub fn validate<T: Validate + ?Sized>(src: &Source, item: &T) -> Result<(), Vec<ScenarioError>> {
    Checker::run(item, Some(&src.base_dir())).map_err(|list| {
        list.into_iter()
            .map(|inv| match src.locate(&inv.key) {
                Some((span, true)) => ScenarioError::at(src, span.start, Some(inv.key), inv.message),
                Some((span, false)) => ScenarioError::at(
                    src,
                    span.start,
                    Some(inv.key.clone()),
                    format!("{} (this is the default; set `{}` explicitly)", inv.message, inv.key),
                ),
                None => ScenarioError {
                    path: src.path.clone(),
                    position: None,
                    key: Some(inv.key),
                    message: inv.message,
                },
            })
            .collect()
    })
}

fn is_value_error(m: &str) -> bool {
    m.starts_with("invalid type") || m.starts_with("invalid value") || m.starts_with("unknown variant")
}

/// Keeps the first line of a TOML error message and names TOML types the way users write them.
fn tidy(m: &str) -> String {
    let first = m.lines().next().unwrap_or(m).trim();
    first
        .replace("expected f64", "expected a number")
        .replace("expected u64", "expected a whole number")
        .replace("expected usize", "expected a whole number")
        .replace("expected u32", "expected a whole number")
}

/// Dotted key path of the deepest key whose key or value contains byte `offset`.
fn key_path_at(src: &Source, offset: usize) -> Option<String> {
    let doc = toml_edit::Document::parse(src.text.clone()).ok()?;
    let mut path = String::new();
    walk_table_like(doc.as_table(), offset, &mut path);
    (!path.is_empty()).then_some(path)
}

fn contains(span: Option<std::ops::Range<usize>>, offset: usize) -> bool {
    span.is_some_and(|s| s.start <= offset && offset < s.end.max(s.start + 1))
}

fn push_key(path: &mut String, k: &str) {
    if !path.is_empty() {
        path.push('.');
    }
    path.push_str(k);
}

fn walk_table_like(t: &dyn toml_edit::TableLike, offset: usize, path: &mut String) {
    for (k, item) in t.iter() {
        let key_span = t.key(k).and_then(|key| key.span());
        let hit_key = contains(key_span, offset);
        let hit_val = match item {
            toml_edit::Item::Value(v) => contains(v.span(), offset),
            toml_edit::Item::Table(tab) => contains(tab.span(), offset) || table_contains(tab, offset),
            toml_edit::Item::ArrayOfTables(a) => {
                a.iter().any(|tab| contains(tab.span(), offset) || table_contains(tab, offset))
            }
            toml_edit::Item::None => false,
        };
        if !(hit_key || hit_val) {
            continue;
        }
        push_key(path, k);
        match item {
            toml_edit::Item::Table(tab) => walk_table_like(tab, offset, path),
            toml_edit::Item::ArrayOfTables(a) => {
                for (i, tab) in a.iter().enumerate() {
                    if contains(tab.span(), offset) || table_contains(tab, offset) {
                        path.push_str(&format!("[{i}]"));
                        walk_table_like(tab, offset, path);
                        break;
                    }
                }
            }
            toml_edit::Item::Value(toml_edit::Value::InlineTable(it)) => walk_table_like(it, offset, path),
            toml_edit::Item::Value(toml_edit::Value::Array(arr)) => {
                for (i, v) in arr.iter().enumerate() {
                    if contains(v.span(), offset) {
                        path.push_str(&format!("[{i}]"));
                        if let toml_edit::Value::InlineTable(it) = v {
                            walk_table_like(it, offset, path);
                        }
                        break;
                    }
                }
            }
            _ => {}
        }
        return;
    }
}

/// Whether any key or value inside `t` (a table without a span of its own, e.g. dotted) holds `offset`.
fn table_contains(t: &toml_edit::Table, offset: usize) -> bool {
    t.iter().any(|(k, item)| {
        contains(t.key(k).and_then(|key| key.span()), offset)
            || match item {
                toml_edit::Item::Value(v) => contains(v.span(), offset),
                toml_edit::Item::Table(tab) => contains(tab.span(), offset) || table_contains(tab, offset),
                toml_edit::Item::ArrayOfTables(a) => a.iter().any(|tab| contains(tab.span(), offset)),
                toml_edit::Item::None => false,
            }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;
    use spatter_core::material::Material;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Toy {
        radius_m: f64,
        #[serde(default = "one")]
        restitution: f64,
        material: Material,
    }
    fn one() -> f64 {
        1.5
    }
    impl Validate for Toy {
        fn validate(&self, c: &mut Checker) {
            c.positive("radius_m", self.radius_m);
            c.in_range("restitution", self.restitution, 0.0, false, 1.0, true);
            c.item("material", &self.material);
        }
    }

    fn src(text: &str) -> Source {
        Source::from_bytes(Path::new("toy.toml"), text.as_bytes()).unwrap()
    }

    #[test]
    fn type_errors_name_key_and_place() {
        let s = src("radius_m = \"big\"\n[material]\nyoungs_modulus_pa = 1e9\npoisson_ratio = 0.3\ndensity_kg_m3 = 1000\n");
        let e = typed::<Toy>(&s, &s.text).unwrap_err();
        assert_eq!(e.position, Some((1, 12)));
        assert_eq!(e.key.as_deref(), Some("radius_m"));
        assert!(e.message.contains("expected a number") && e.message.contains("\"big\""), "{e}");
    }

    #[test]
    fn defaults_that_fail_point_to_their_table() {
        let s = src("radius_m = 1.0\n[material]\nyoungs_modulus_pa = 1e9\npoisson_ratio = 0.3\ndensity_kg_m3 = 1000\n");
        let t: Toy = typed(&s, &s.text).unwrap();
        let errs = validate(&s, &t).unwrap_err();
        assert_eq!(errs.len(), 1);
        assert_eq!(errs[0].position, Some((1, 1)));
        assert!(errs[0].message.contains("this is the default"), "{}", errs[0]);
    }
}
