//! Scenario source text: reading, line/column lookup, and finding a key path in the document.

use crate::parse::ScenarioError;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The text of a scenario file and where it came from.
#[derive(Clone, Debug)]
pub struct Source {
    pub path: PathBuf,
    pub text: String,
    doc: Option<toml_edit::Document<String>>,
}

impl Source {
    /// Reads `path`, refusing empty files and files that are not text.
    pub fn read(path: &Path) -> Result<Self, ScenarioError> {
        let bytes = std::fs::read(path)
            .map_err(|e| ScenarioError::whole_file(path, format!("cannot read the scenario file: {e}")))?;
        Self::from_bytes(path, &bytes)
    }

    /// Checks `bytes` are non-empty UTF-8 text and keeps them.
    pub fn from_bytes(path: &Path, bytes: &[u8]) -> Result<Self, ScenarioError> {
        if bytes.iter().all(|b| b.is_ascii_whitespace()) {
            return Err(ScenarioError::whole_file(
                path,
                format!(
                    "the file is empty; a scenario needs at least `kind = \"…\"` (one of: {})",
                    crate::KINDS.join(", ")
                ),
            ));
        }
        let text = match std::str::from_utf8(bytes) {
            Ok(t) if !t.contains('\0') => t.to_owned(),
            Ok(t) => {
                let at = t.find('\0').unwrap_or(0);
                return Err(ScenarioError::whole_file(
                    path,
                    format!("this is binary data, not a TOML text file (NUL byte at offset {at})"),
                ));
            }
            Err(e) => {
                return Err(ScenarioError::whole_file(
                    path,
                    format!(
                        "this is binary data, not a TOML text file (invalid UTF-8 at byte {})",
                        e.valid_up_to()
                    ),
                ))
            }
        };
        let doc = toml_edit::Document::parse(text.clone()).ok();
        Ok(Source { path: path.to_owned(), text, doc })
    }

    /// 1-based (line, column) of byte `offset` (column counted in characters).
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = offset.min(self.text.len());
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let col = before.rsplit('\n').next().map(|s| s.chars().count()).unwrap_or(0) + 1;
        (line, col)
    }

    /// Folder holding the file (relative paths in the scenario are resolved against it); `.` for a bare
    /// file name such as `scenario.toml` (whose parent is the empty path).
    pub fn base_dir(&self) -> PathBuf {
        match self.path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_owned(),
            _ => PathBuf::from("."),
        }
    }

    /// Span of the value at dotted `key` path (`a.b[2].c`); if the key is absent (a default was used),
    /// the span of its nearest present parent and `false`.
    pub fn locate(&self, key: &str) -> Option<(Range<usize>, bool)> {
        let doc = self.doc.as_ref()?;
        let mut item: &toml_edit::Item = doc.as_item();
        let mut best = None;
        for seg in split_path(key) {
            let next = match seg {
                Seg::Key(k) => item.get(k.as_str()),
                Seg::Index(i) => item.get(i),
            };
            match next {
                Some(n) => {
                    if let Some(span) = item_span(n) {
                        best = Some(span);
                    }
                    item = n;
                }
                // Absent: point at the nearest present parent (the file's start for a top-level key).
                None => return Some((best.unwrap_or(0..0), false)),
            }
        }
        best.map(|s| (s, true))
    }

    /// Span of a top-level `key = value` line, from the key's start to the value's end.
    pub fn key_value_span(&self, key: &str) -> Option<Range<usize>> {
        let doc = self.doc.as_ref()?;
        let (k, v) = doc.as_table().get_key_value(key)?;
        let ks = k.span()?;
        let vs = item_span(v)?;
        Some(ks.start..vs.end)
    }
}

fn item_span(item: &toml_edit::Item) -> Option<Range<usize>> {
    match item {
        toml_edit::Item::Value(v) => v.span(),
        toml_edit::Item::Table(t) => t.span(),
        toml_edit::Item::ArrayOfTables(a) => a.span(),
        toml_edit::Item::None => None,
    }
}

enum Seg {
    Key(String),
    Index(usize),
}

fn split_path(key: &str) -> Vec<Seg> {
    let mut out = Vec::new();
    for part in key.split('.') {
        let mut rest = part;
        if let Some(i) = rest.find('[') {
            if i > 0 {
                out.push(Seg::Key(rest[..i].to_owned()));
            }
            rest = &rest[i..];
            while let Some(stripped) = rest.strip_prefix('[') {
                let end = stripped.find(']').unwrap_or(stripped.len());
                if let Ok(n) = stripped[..end].parse() {
                    out.push(Seg::Index(n));
                }
                rest = stripped.get(end + 1..).unwrap_or("");
            }
        } else if !rest.is_empty() {
            out.push(Seg::Key(rest.to_owned()));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locates_nested_keys_and_array_elements() {
        let text = "kind = \"x\"\n[materials.ice]\npoisson_ratio = 0.6\n\n[[walls]]\nradius = 1.0\n[[walls]]\nradius = -2.0\n";
        let s = Source::from_bytes(Path::new("a.toml"), text.as_bytes()).unwrap();
        let (span, exact) = s.locate("materials.ice.poisson_ratio").unwrap();
        assert!(exact);
        assert_eq!(&s.text[span.clone()], "0.6");
        assert_eq!(s.line_col(span.start), (3, 17));
        let (span, exact) = s.locate("walls[1].radius").unwrap();
        assert!(exact);
        assert_eq!(s.line_col(span.start), (8, 10));
        let (_, exact) = s.locate("materials.ice.density_kg_m3").unwrap();
        assert!(!exact, "absent key falls back to its table");
        assert_eq!(&s.text[s.key_value_span("kind").unwrap()], "kind = \"x\"");
    }
}
