//! The one rule for relative file paths: in a scenario they are relative to the scenario file's folder.
//! After validation the loader rewrites them to absolute paths with [`absolute_paths`], so the run does not
//! depend on the working directory and the resolved input it writes (`run.toml`) can be run again from
//! anywhere. Engines and workflows take the paths of a configuration as they are (a relative path is then
//! relative to the working directory); a library user who builds a configuration from a file of their own
//! calls [`absolute_paths`] with that file's folder, as the loader does.
//!
//! Convention: a key that names a file is called `file`, `vtk` or `series` (see `docs/scenario.md`).
//! A test re-checks the `run.toml` of every example from another folder, so a path key outside the
//! convention cannot go unnoticed.

use serde::de::DeserializeOwned;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// Keys whose string values are file paths.
pub const PATH_KEYS: &[&str] = &["file", "vtk", "series"];

/// `cfg` with every relative path under a [`PATH_KEYS`] key joined to `base` (made absolute).
pub fn absolute_paths<T: Serialize + DeserializeOwned>(cfg: T, base: &Path) -> Result<T, String> {
    let base =
        std::path::absolute(base).map_err(|e| format!("cannot make {} absolute: {e}", base.display()))?;
    let mut value = toml::Value::try_from(&cfg).map_err(|e| e.to_string())?;
    let mut changed = false;
    walk(&mut value, None, &base, &mut changed);
    if !changed {
        return Ok(cfg);
    }
    value.try_into().map_err(|e: toml::de::Error| e.to_string())
}

fn walk(v: &mut toml::Value, key: Option<&str>, base: &Path, changed: &mut bool) {
    match v {
        toml::Value::String(s) if key.is_some_and(|k| PATH_KEYS.contains(&k)) => {
            let p = PathBuf::from(s.as_str());
            if p.is_relative() {
                *s = base.join(p).to_string_lossy().into_owned();
                *changed = true;
            }
        }
        toml::Value::Table(t) => t.iter_mut().for_each(|(k, x)| walk(x, Some(k), base, changed)),
        // Array elements inherit the key (e.g. `files = [{ file = … }]` or a list of paths).
        toml::Value::Array(a) => a.iter_mut().for_each(|x| walk(x, key, base, changed)),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Inner {
        file: PathBuf,
        name: String,
    }
    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Cfg {
        vtk: Option<PathBuf>,
        parts: Vec<Inner>,
        title: String,
    }

    #[test]
    fn relative_paths_become_absolute_and_nothing_else_changes() {
        let cfg = Cfg {
            vtk: Some("flow/field.vtu".into()),
            parts: vec![
                Inner { file: "a.stl".into(), name: "a.stl".into() },
                Inner { file: "/abs/b.stl".into(), name: "b".into() },
            ],
            title: "file".into(),
        };
        let out = absolute_paths(cfg, Path::new("/base/dir")).unwrap();
        assert_eq!(out.vtk.as_deref(), Some(Path::new("/base/dir/flow/field.vtu")));
        assert_eq!(out.parts[0].file, Path::new("/base/dir/a.stl"));
        assert_eq!(out.parts[0].name, "a.stl", "only path keys are touched");
        assert_eq!(out.parts[1].file, Path::new("/abs/b.stl"), "absolute paths are kept");
        assert_eq!(out.title, "file");
    }
}
