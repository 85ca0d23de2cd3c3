//! Dotted key paths (`particle.youngs_modulus_pa`, `walls[1].motion.speed_m_s`) into a TOML document:
//! reading the value a scenario has there and replacing it, keeping the rest of the text as it is.

use toml_edit::{DocumentMut, Item, Value};

/// One step of a key path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Seg {
    Key(String),
    Index(usize),
}

/// Splits `a.b[2].c` into segments; `None` for a malformed path (empty part, unclosed or non-numeric
/// index).
pub fn parse(path: &str) -> Option<Vec<Seg>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if name.is_empty() {
            return None;
        }
        out.push(Seg::Key(name.to_owned()));
        while !rest.is_empty() {
            let inner = rest.strip_prefix('[')?;
            let end = inner.find(']')?;
            out.push(Seg::Index(inner[..end].trim().parse().ok()?));
            rest = &inner[end + 1..];
        }
    }
    Some(out)
}

/// Where a path stops matching the document.
#[derive(Clone, Debug, PartialEq)]
pub struct Missing {
    /// The longest prefix that exists (empty for the top level).
    pub found: String,
    /// Keys available at that place (for "did you mean").
    pub available: Vec<String>,
}

/// The value at `path`, or where the path leaves the document.
pub fn get<'a>(doc: &'a DocumentMut, path: &[Seg]) -> Result<&'a Item, Missing> {
    let mut item = doc.as_item();
    let mut found = String::new();
    for seg in path {
        let next = match seg {
            Seg::Key(k) => item.get(k.as_str()),
            Seg::Index(i) => match item {
                Item::ArrayOfTables(a) => a.get(*i).map(|_| &item[*i]),
                Item::Value(Value::Array(a)) => a.get(*i).map(|_| &item[*i]),
                _ => None,
            },
        };
        match next {
            Some(n) => {
                item = n;
                match seg {
                    Seg::Key(k) if found.is_empty() => found = k.clone(),
                    Seg::Key(k) => found = format!("{found}.{k}"),
                    Seg::Index(i) => found = format!("{found}[{i}]"),
                }
            }
            None => return Err(Missing { found, available: keys_of(item) }),
        }
    }
    Ok(item)
}

fn keys_of(item: &Item) -> Vec<String> {
    match item {
        Item::Table(t) => t.iter().map(|(k, _)| k.to_owned()).collect(),
        Item::Value(Value::InlineTable(t)) => t.iter().map(|(k, _)| k.to_owned()).collect(),
        Item::ArrayOfTables(a) => (0..a.len()).map(|i| format!("[{i}]")).collect(),
        Item::Value(Value::Array(a)) => (0..a.len()).map(|i| format!("[{i}]")).collect(),
        _ => Vec::new(),
    }
}

/// Replaces the value at `path` (which must exist, see [`get`]) by `value`.
pub fn set(doc: &mut DocumentMut, path: &[Seg], value: Value) -> bool {
    let mut item = doc.as_item_mut();
    for seg in path {
        let next = match seg {
            Seg::Key(k) => item.get_mut(k.as_str()),
            Seg::Index(i) => item.get_mut(*i),
        };
        match next {
            Some(n) => item = n,
            None => return false,
        }
    }
    match item {
        Item::Value(v) => {
            let decor = v.decor().clone();
            *v = value;
            *v.decor_mut() = decor;
            true
        }
        Item::None => false,
        other => {
            *other = Item::Value(value);
            true
        }
    }
}

/// The name of a TOML value's type, as a user reads it in a message.
pub fn type_name(item: &Item) -> &'static str {
    match item {
        Item::Value(Value::Float(_)) => "a number",
        Item::Value(Value::Integer(_)) => "an integer",
        Item::Value(Value::String(_)) => "a string",
        Item::Value(Value::Boolean(_)) => "true or false",
        Item::Value(Value::Array(_)) => "an array",
        Item::Value(Value::InlineTable(_)) | Item::Table(_) => "a table",
        Item::ArrayOfTables(_) => "an array of tables",
        Item::Value(Value::Datetime(_)) => "a date",
        Item::None => "nothing",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_parse_and_malformed_ones_are_refused() {
        assert_eq!(
            parse("walls[1].speed").unwrap(),
            vec![Seg::Key("walls".into()), Seg::Index(1), Seg::Key("speed".into())]
        );
        for bad in ["", "a..b", "a[x]", "a[1", ".a", "[0]"] {
            assert!(parse(bad).is_none(), "{bad}");
        }
    }

    #[test]
    fn values_are_found_and_replaced_in_place() {
        let text = "kind = \"x\"\n# note\n[particle]\nradius_m = 1.0 # keep\n[[walls]]\nz = 0.0\n[[walls]]\nz = 2.0\n";
        let mut doc: DocumentMut = text.parse().unwrap();
        let p = parse("walls[1].z").unwrap();
        assert_eq!(get(&doc, &p).unwrap().as_float(), Some(2.0));
        assert!(set(&mut doc, &p, Value::from(3.5)));
        let p = parse("particle.radius_m").unwrap();
        assert!(set(&mut doc, &p, Value::from(0.25)));
        let out = doc.to_string();
        assert!(
            out.contains("z = 3.5\n") && out.contains("radius_m = 0.25 # keep") && out.contains("# note"),
            "{out}"
        );
        let miss = get(&doc, &parse("particle.diameter_m").unwrap()).unwrap_err();
        assert_eq!(miss.found, "particle");
        assert_eq!(miss.available, vec!["radius_m".to_string()]);
        assert!(get(&doc, &parse("walls[5].z").unwrap()).is_err());
    }
}
