//! Scenario text that sets only some keys, read over the built-in default
//! scenario (`toml_text=` of every function).
//!
//! The text's tables are laid over the default's key by key: a key the
//! text sets replaces the default's, a key it leaves out keeps the
//! default's value. Three places where keys belong together take the
//! text's whole table instead, so that no default key is left beside keys
//! that exclude it:
//! - arrays, `[[probe]]` among them, are replaced whole;
//! - a `[surface]` (or any table) that sets `law` replaces the default's,
//!   whose keys are those of its own law;
//! - a `[circuit]` that sets `netlist` replaces the default's and drops
//!   its `[[probe]]` (they probe the default's circuit); a `[coil]` drops
//!   the default's `mechanics.force`, `[circuit]` and `[[probe]]` (a coil
//!   is driven by its own circuit).
//!
//! Text that sets `base` names its own starting point (`"default"`,
//! `"part:NAME"` or a file) and is read as a scenario file would be,
//! without the default laid under it.
//!
//! The merged table is written back as TOML and read by
//! `Scenario::parse`, so every rule of the file format holds. An error
//! names the line of the text it came from, or of the default scenario
//! when the key came from there; relative paths in the text resolve
//! against the working directory.

use std::path::{Path, PathBuf};

use chatterspice::scenario::{DEFAULT_SCENARIO_TOML, Scenario, ScenarioError};
use toml::de::{DeTable, DeValue};
use toml::{Table, Value};

use crate::error::Failure;

/// The name errors give the text.
pub const TEXT_ORIGIN: &str = "<toml_text>";

/// `text` over the default scenario: the scenario and the whole TOML it
/// was read from. `origin` is the file the text stands for (errors name
/// it, and relative paths resolve against its directory); without it,
/// `<toml_text>` in the working directory. Text with a `base` of its own
/// is read exactly as a file at `origin` would be.
pub fn parse(text: &str, origin: Option<&Path>) -> Result<(Scenario, String), Failure> {
    let origin = origin.unwrap_or(Path::new(TEXT_ORIGIN));
    if let Ok(user) = text.parse::<Table>()
        && user.contains_key("base")
    {
        return Scenario::parse(text, origin)
            .map(|s| (s, text.to_owned()))
            .map_err(Failure::from);
    }
    let Ok(user) = text.parse::<Table>() else {
        // The library says where the syntax breaks, with its excerpt.
        return Scenario::parse(text, origin)
            .map(|s| (s, text.to_owned()))
            .map_err(Failure::from);
    };
    let default: Table = DEFAULT_SCENARIO_TOML
        .parse()
        .expect("the built-in scenario is valid TOML");
    let mut merged = overlay(default, user.clone());
    let from_default = !user.contains_key("coil")
        && !user
            .get("circuit")
            .and_then(Value::as_table)
            .is_some_and(|c| c.contains_key("netlist"));
    if from_default && let Some(Value::Table(circuit)) = merged.get_mut("circuit") {
        let netlist = default_netlist();
        circuit.insert(
            "netlist".to_owned(),
            Value::String(netlist.display().to_string()),
        );
    }
    let merged_text = toml::to_string(&merged).expect("a table read from TOML writes back");
    match Scenario::parse(&merged_text, origin) {
        Ok(scenario) => Ok((scenario, merged_text)),
        Err(mut err) => {
            relocate(&mut err, &merged_text, text);
            Err(Failure::scenario(&err, false))
        }
    }
}

/// `user` laid over `default` by the rules of the module overview.
fn overlay(mut default: Table, user: Table) -> Table {
    if user.contains_key("coil")
        && let Some(Value::Table(m)) = default.get_mut("mechanics")
    {
        m.remove("force");
    }
    if user.contains_key("coil") {
        default.remove("circuit");
        default.remove("probe");
    }
    if let Some(Value::Table(c)) = user.get("circuit")
        && c.contains_key("netlist")
    {
        default.remove("circuit");
        default.remove("probe");
    }
    merge(default, user)
}

fn merge(mut base: Table, over: Table) -> Table {
    for (key, value) in over {
        let merged = match (base.remove(&key), value) {
            (Some(Value::Table(b)), Value::Table(o)) if !o.contains_key("law") => {
                Value::Table(merge(b, o))
            }
            (_, v) => v,
        };
        base.insert(key, merged);
    }
    base
}

/// Point `err` at the line of the text (or of the default scenario) that
/// set the key it is about, instead of the merged text's line.
fn relocate(err: &mut ScenarioError, merged: &str, text: &str) {
    let Some(at) = err.location_mut() else {
        return;
    };
    let Some(line) = at.line else {
        return;
    };
    let key = key_on_line(merged, line);
    let default_origin = Scenario::builtin_default().origin;
    let mut path = key.as_str();
    loop {
        if let Some(l) = line_of(text, path) {
            at.line = Some(l);
            return;
        }
        if let Some(l) = line_of(DEFAULT_SCENARIO_TOML, path) {
            at.path = default_origin;
            at.line = Some(l);
            return;
        }
        match path.rfind(['.', '[']) {
            Some(i) => path = &path[..i],
            None => break,
        }
    }
    at.line = None;
}

/// The deepest dotted key whose name is on `line` of `text`.
fn key_on_line(text: &str, line: usize) -> String {
    keys(text)
        .into_iter()
        .rfind(|(_, l)| *l == line)
        .map(|(k, _)| k)
        .unwrap_or_default()
}

/// The line of `key` in `text`, if the text sets it.
fn line_of(text: &str, key: &str) -> Option<usize> {
    keys(text)
        .into_iter()
        .find(|(k, _)| k == key)
        .map(|(_, l)| l)
}

/// Every dotted key of `text` (`mechanics.mass`, `probe[0].low`) with the
/// line of its name, parents before children.
fn keys(text: &str) -> Vec<(String, usize)> {
    fn walk(table: &DeTable<'_>, prefix: &str, text: &str, out: &mut Vec<(String, usize)>) {
        for (key, value) in table.iter() {
            let path = if prefix.is_empty() {
                key.get_ref().to_string()
            } else {
                format!("{prefix}.{}", key.get_ref())
            };
            out.push((path.clone(), line_at(text, key.span().start)));
            match value.get_ref() {
                DeValue::Table(inner) => walk(inner, &path, text, out),
                DeValue::Array(items) => {
                    for (i, item) in items.iter().enumerate() {
                        let item_path = format!("{path}[{i}]");
                        out.push((item_path.clone(), line_at(text, item.span().start)));
                        if let DeValue::Table(inner) = item.get_ref() {
                            walk(inner, &item_path, text, out);
                        }
                    }
                }
                _ => {}
            }
        }
    }
    let mut out = Vec::new();
    if let Ok(tree) = DeTable::parse(text) {
        walk(tree.get_ref(), "", text, &mut out);
    }
    out
}

fn line_at(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The built-in scenario's circuit as the library names it: a name that
/// resolves to the text compiled in, not to a file, so the text runs
/// wherever the package is.
fn default_netlist() -> PathBuf {
    Scenario::builtin_default()
        .circuit
        .map(|c| c.netlist)
        .expect("the built-in scenario has a circuit")
}
