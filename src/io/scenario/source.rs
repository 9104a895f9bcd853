//! Reading a scenario: `--set` overrides, parsing with key paths, and locating a key's line.

use super::schema::Scenario;
use crate::base::error::ScenarioError;
use std::path::Path;
use toml_edit::{DocumentMut, Item};

/// Largest scenario file read (bytes): mesh lists included, a scenario is text of a few
/// megabytes at most, and a larger file is more likely a mistake than a scene.
const MAX_SCENARIO_BYTES: u64 = 16 << 20;

/// A parsed scenario with the text it came from, for locating errors.
#[derive(Debug, Clone)]
pub struct Source {
    /// File name as given.
    pub file: String,
    /// Effective text (after overrides).
    pub text: String,
    /// The file's own text, where error lines are looked up: an override that adds a key
    /// adds a line to `text`, which would move every later line.
    own: String,
    /// Parsed scenario.
    pub scenario: Scenario,
    /// Keys set by `--set` (as `a.b[2].c`) with the argument that set each.
    set: Vec<(String, String)>,
}

impl Source {
    /// Reads `path`, applies `overrides` (`path.to.key=value`) and parses.
    pub fn load(path: &Path, overrides: &[String]) -> Result<Self, ScenarioError> {
        let file = path.display().to_string();
        let refuse = |message: String| ScenarioError {
            file: file.clone(),
            line: None,
            key: None,
            message,
        };
        // Checked before opening: a FIFO would block the open, a device never end.
        let meta = std::fs::metadata(path)
            .map_err(|e| refuse(format!("cannot read the scenario: {e}")))?;
        if !meta.is_file() {
            return Err(refuse(
                "cannot read the scenario: not a regular file".into(),
            ));
        }
        if meta.len() > MAX_SCENARIO_BYTES {
            return Err(refuse(format!(
                "the scenario is {} bytes; a scenario file may have at most {MAX_SCENARIO_BYTES} \
                 (16 MiB)",
                meta.len()
            )));
        }
        let text = std::fs::read_to_string(path)
            .map_err(|e| refuse(format!("cannot read the scenario: {e}")))?;
        Self::parse(&file, &text, overrides)
    }

    /// Parses scenario `text` named `file`, after applying `overrides`.
    pub fn parse(file: &str, text: &str, overrides: &[String]) -> Result<Self, ScenarioError> {
        let own = text.to_string();
        let text = apply_overrides(file, text, overrides)?;
        let set: Vec<(String, String)> = overrides
            .iter()
            .filter_map(|arg| {
                let (path, _) = arg.split_once('=')?;
                Some((canonical(&split_path(path.trim())), arg.clone()))
            })
            .collect();
        let err = |line, key: Option<String>, message: String| match set_by(&set, key.as_deref())
            .or_else(|| unknown_from_set(&set, key.as_deref(), &message))
        {
            Some(arg) => ScenarioError {
                file: file.to_string(),
                line: None,
                key,
                message: format!("{message} (the value comes from --set {arg})"),
            },
            None => ScenarioError {
                file: file.to_string(),
                line,
                key,
                message,
            },
        };
        let de = toml::Deserializer::parse(&text)
            .map_err(|e| err(line_of(&text, e.span()), None, e.message().to_string()))?;
        let scenario: Scenario = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            let key = (path != ".").then_some(path);
            let line = (key.as_deref())
                .and_then(|k| find_line(&own, k))
                .or_else(|| line_of(&text, inner.span()));
            err(line, key, inner.message().trim().to_string())
        })?;
        Ok(Source {
            file: file.to_string(),
            text,
            scenario,
            set,
            own,
        })
    }

    /// An error about a table the file lacks: it names the file's last line, where the
    /// table would go.
    pub fn missing(&self, key: &str, message: impl Into<String>) -> ScenarioError {
        ScenarioError {
            file: self.file.clone(),
            line: Some(self.own.lines().count().max(1)),
            key: Some(key.to_string()),
            message: message.into(),
        }
    }

    /// An error about `key` (dotted path with `[i]` indices), located on its line, or said
    /// to come from the `--set` that gave its value.
    pub fn error(&self, key: &str, message: impl Into<String>) -> ScenarioError {
        let message = message.into();
        match set_by(&self.set, Some(key)) {
            Some(arg) => ScenarioError {
                file: self.file.clone(),
                line: None,
                key: Some(key.to_string()),
                message: format!("{message} (the value comes from --set {arg})"),
            },
            None => ScenarioError {
                file: self.file.clone(),
                line: find_line(&self.own, key),
                key: Some(key.to_string()),
                message,
            },
        }
    }

    /// The scenario's name: its `name` key or the file stem.
    pub fn name(&self) -> String {
        self.scenario.name.clone().unwrap_or_else(|| {
            Path::new(&self.file)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scenario".into())
        })
    }
}

fn line_of(text: &str, span: Option<std::ops::Range<usize>>) -> Option<usize> {
    span.map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1)
}

/// Splits `a.b[2].c` (or `a.b.2.c`) into keys and indices.
fn split_path(path: &str) -> Vec<PathPart> {
    let mut parts = Vec::new();
    for seg in path.split('.') {
        let mut rest = seg;
        if let Some(open) = rest.find('[') {
            let (k, idx) = rest.split_at(open);
            if !k.is_empty() {
                parts.push(PathPart::Key(k.to_string()));
            }
            rest = idx;
            for ix in rest.split('[').filter(|s| !s.is_empty()) {
                let n = ix.trim_end_matches(']');
                match n.parse() {
                    Ok(i) => parts.push(PathPart::Index(i)),
                    Err(_) => parts.push(PathPart::Key(n.to_string())),
                }
            }
        } else if let Ok(i) = rest.parse::<usize>() {
            parts.push(PathPart::Index(i));
        } else {
            parts.push(PathPart::Key(rest.to_string()));
        }
    }
    parts
}

enum PathPart {
    Key(String),
    Index(usize),
}

/// A key path written as the errors write it: `a.b[2].c`.
fn canonical(parts: &[PathPart]) -> String {
    let mut out = String::new();
    for p in parts {
        match p {
            PathPart::Key(k) => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(k);
            }
            PathPart::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

/// Whether key path `inner` is `outer` or lies under it (`outer.x`, `outer[i]`).
fn within(inner: &str, outer: &str) -> bool {
    inner
        .strip_prefix(outer)
        .is_some_and(|rest| rest.is_empty() || rest.starts_with(['.', '[']))
}

/// The `--set` argument that set `key` or a table holding it, if any.
fn set_by<'a>(set: &'a [(String, String)], key: Option<&str>) -> Option<&'a str> {
    let key = canonical(&split_path(key?));
    (set.iter().find(|(path, _)| within(&key, path))).map(|(_, arg)| arg.as_str())
}

/// The `--set` argument that brought in the unknown key `key` (a path under a key the
/// scenario does not have, e.g. `--set nosuch.key=1`), for a message that says so.
fn unknown_from_set<'a>(
    set: &'a [(String, String)],
    key: Option<&str>,
    message: &str,
) -> Option<&'a str> {
    let key = canonical(&split_path(key?));
    (message.starts_with("unknown field")).then_some(())?;
    (set.iter().find(|(path, _)| within(path, &key))).map(|(_, arg)| arg.as_str())
}

/// Line of the deepest existing item on `path` in `text`.
fn find_line(text: &str, path: &str) -> Option<usize> {
    let doc: toml_edit::Document<String> = text.parse().ok()?;
    let mut item: &Item = doc.as_item();
    let mut line = None;
    for part in split_path(path) {
        let next = match &part {
            PathPart::Key(k) => item.get(k.as_str()),
            PathPart::Index(i) => item.get(*i),
        };
        let Some(next) = next else { break };
        if let Some(l) = line_of(text, item_span(next)) {
            line = Some(l);
        }
        item = next;
    }
    line
}

fn item_span(item: &Item) -> Option<std::ops::Range<usize>> {
    match item {
        Item::Value(v) => v.span(),
        Item::Table(t) => t.span(),
        Item::ArrayOfTables(a) => a.span(),
        Item::None => None,
    }
}

/// Applies `key.path=value` overrides to the text, keeping its layout (and so its lines).
fn apply_overrides(file: &str, text: &str, overrides: &[String]) -> Result<String, ScenarioError> {
    if overrides.is_empty() {
        return Ok(text.to_string());
    }
    let fail = |arg: &str, message: String| ScenarioError {
        file: file.to_string(),
        line: None,
        key: Some(arg.to_string()),
        message: format!("--set: {message}"),
    };
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| fail("", e.message().to_string()))?;
    for arg in overrides {
        let Some((path, raw)) = arg.split_once('=') else {
            return Err(fail(arg, "expected path.to.key=value".into()));
        };
        let value: toml_edit::Value = raw
            .trim()
            .parse()
            .unwrap_or_else(|_| toml_edit::Value::from(raw.trim()));
        let parts = split_path(path.trim());
        let Some((last, init)) = parts.split_last() else {
            return Err(fail(arg, "empty key path".into()));
        };
        let mut item: &mut Item = doc.as_item_mut();
        for part in init {
            item = match part {
                PathPart::Key(k) => {
                    if item.get(k.as_str()).is_none() {
                        item.as_table_like_mut()
                            .ok_or_else(|| fail(arg, format!("`{k}` is not inside a table")))?
                            .insert(k, Item::Table(toml_edit::Table::new()));
                    }
                    item.get_mut(k.as_str()).expect("inserted above")
                }
                PathPart::Index(i) => item
                    .get_mut(*i)
                    .ok_or_else(|| fail(arg, format!("no element [{i}]")))?,
            };
        }
        let path = path.trim();
        match last {
            PathPart::Key(k) => {
                let table = item
                    .as_table_like_mut()
                    .ok_or_else(|| fail(arg, format!("cannot set `{k}`: parent is not a table")))?;
                match table.get_mut(k) {
                    Some(slot) => {
                        replace(slot, value.decorated(" ", ""), path).map_err(|m| fail(arg, m))?
                    }
                    None => {
                        table.insert(k, Item::Value(value));
                    }
                }
            }
            PathPart::Index(i) => {
                let slot = item
                    .get_mut(*i)
                    .ok_or_else(|| fail(arg, format!("no element [{i}]")))?;
                replace(slot, value, path).map_err(|m| fail(arg, m))?;
            }
        }
    }
    Ok(doc.to_string())
}

/// Puts `value` in `slot` (the item at `path`): a table only by a table (an inline
/// `{ ... }`), so that `--set material[0]=5` is refused rather than dropping the table.
fn replace(slot: &mut Item, value: toml_edit::Value, path: &str) -> Result<(), String> {
    match (&*slot, value) {
        (Item::Table(_), toml_edit::Value::InlineTable(t)) => *slot = Item::Table(t.into_table()),
        (Item::Table(_), _) => {
            return Err(format!(
                "`{path}` is a table: give a whole table `{{ key = value, ... }}` or set one of \
                 its keys (`{path}.key=value`)"
            ));
        }
        (Item::ArrayOfTables(_), _) => {
            return Err(format!(
                "`{path}` is a list of tables: set a key of one of them (`{path}[0].key=value`)"
            ));
        }
        (_, value) => *slot = Item::Value(value),
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_overrides_nested_and_indexed_keys_keeping_lines() {
        let text = "[simulation]\nduration = 1.0\n\n[[material]]\nname = \"a\"\nE = 1.0\n";
        let out = apply_overrides(
            "f.toml",
            text,
            &["simulation.duration=2.5".into(), "material[0].E=3e9".into()],
        )
        .unwrap();
        assert!(out.contains("duration = 2.5"), "{out}");
        assert!(out.contains("E = 3e9"), "{out}");
        assert_eq!(find_line(&out, "material[0].E"), Some(6));
        assert_eq!(find_line(&out, "simulation.duration"), Some(2));
    }

    /// A table is replaced only by a table: `material[0]=5` dropped the material in
    /// silence, and the error that followed named a missing material.
    #[test]
    fn set_refuses_a_value_in_place_of_a_table() {
        let text = "[simulation]\nduration = 1.0\n\n[[material]]\nname = \"a\"\nE = 1.0\n";
        let set = |arg: &str| apply_overrides("f.toml", text, &[arg.to_string()]);
        let e = set("material[0]=5").unwrap_err().to_string();
        assert!(e.contains("`material[0]` is a table"), "{e}");
        let e = set("simulation=2").unwrap_err().to_string();
        assert!(e.contains("`simulation` is a table"), "{e}");
        let e = set("material=1").unwrap_err().to_string();
        assert!(e.contains("`material` is a list of tables"), "{e}");
        let out = set("material[0]={ name = \"b\", E = 2.0 }").unwrap();
        assert!(
            out.contains("name = \"b\"") && !out.contains("name = \"a\""),
            "{out}"
        );
    }
}
