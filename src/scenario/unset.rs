//! `unset = [...]`: keys of a scenario's base that the scenario removes
//! before its own keys are merged in, and the step force a `[coil]`
//! displaces by itself.
//!
//! Each entry is a dotted key path, written as in a TOML file:
//! `"mechanics.force"`, `"limits"` (a whole section),
//! `'envelope."surface.stiffness"'` (a key with a dot in its name). An
//! entry that is not such a path, names no section of a scenario, or
//! names a key none of the bases sets is an error at its own line: a
//! misspelt `unset` never passes silently.

use std::path::Path;

use super::error::{Location, ScenarioError};

/// The top-level sections (and arrays of tables) a scenario may have.
const SECTIONS: &[&str] = &[
    "mechanics",
    "coil",
    "surface",
    "back_stop",
    "blade",
    "pole_face",
    "contact",
    "simulation",
    "circuit",
    "probe",
    "limits",
    "sweep",
    "datasheet",
    "fit",
    "provenance",
    "arc",
    "envelope",
];

/// One key removed from the bases by a file's `unset`.
pub(super) struct Removed {
    /// The key as the key index spells it: its segments joined by dots.
    pub(super) path: String,
    /// The line of its `unset` entry in the file that removed it.
    pub(super) line: Option<usize>,
}

/// A dotted key path written as a TOML key: bare segments
/// (`A-Za-z0-9_-`) and quoted ones (`"…"` or `'…'`, without escapes),
/// joined by dots with optional blanks around them.
pub(super) fn key_path(written: &str) -> Result<Vec<String>, String> {
    let mut segments = Vec::new();
    let mut rest = written.trim();
    if rest.is_empty() {
        return Err("is empty; write a dotted key path such as \"mechanics.force\"".into());
    }
    loop {
        let (segment, after) = match rest.chars().next() {
            Some(quote @ ('"' | '\'')) => {
                let body = &rest[1..];
                let end = body.find(quote).ok_or_else(|| {
                    format!("has a {quote} that is not closed; quote a key with a dot in its name, e.g. envelope.\"surface.stiffness\"")
                })?;
                (body[..end].to_owned(), &body[end + 1..])
            }
            _ => {
                let end = rest
                    .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
                    .unwrap_or(rest.len());
                if end == 0 {
                    return Err(format!(
                        "is not a dotted key path: `{}` cannot start a key; write e.g. \
                         \"mechanics.force\" or 'envelope.\"surface.stiffness\"'",
                        rest.chars().next().unwrap_or(' ')
                    ));
                }
                (rest[..end].to_owned(), &rest[end..])
            }
        };
        segments.push(segment);
        let after = after.trim_start();
        if after.is_empty() {
            return Ok(segments);
        }
        match after.strip_prefix('.') {
            Some(next) => rest = next.trim_start(),
            None if after.starts_with('[') => {
                return Err(format!(
                    "names an element of an array: an array such as [[probe]] is replaced \
                     whole, so unset `{}` whole and write the elements you keep again",
                    quoted_path(&segments)
                ));
            }
            None => {
                return Err(format!(
                    "is not a dotted key path: `{after}` follows `{}`; keys are joined by dots",
                    quoted_path(&segments)
                ));
            }
        }
    }
}

/// The `unset` entries of the file at `origin` (its text `text`), removed
/// from `below`, the merged table of its bases. Returns what was removed,
/// for messages about keys that are then missing.
pub(super) fn apply(
    value: toml::Value,
    below: &mut toml::Table,
    origin: &Path,
    text: &str,
) -> Result<Vec<Removed>, ScenarioError> {
    let at = |key: &str| Location {
        path: origin.to_owned(),
        line: super::keys::line_of(text, key),
    };
    let toml::Value::Array(entries) = value else {
        return Err(ScenarioError::Unset {
            at: at("unset"),
            path: String::new(),
            problem: format!(
                "`unset` must be an array of dotted key paths, e.g. unset = [\"mechanics.force\"], \
                 not {}",
                value.type_str()
            ),
        });
    };
    let mut removed = Vec::new();
    for (i, entry) in entries.into_iter().enumerate() {
        let here = at(&format!("unset[{i}]"));
        let toml::Value::String(written) = entry else {
            return Err(ScenarioError::Unset {
                at: here,
                path: entry.to_string(),
                problem: "must be text: a dotted key path such as \"mechanics.force\"".into(),
            });
        };
        let fail = |problem: String| ScenarioError::Unset {
            at: here.clone(),
            path: written.clone(),
            problem,
        };
        let segments = key_path(&written).map_err(&fail)?;
        if !SECTIONS.contains(&segments[0].as_str()) {
            return Err(fail(format!(
                "`{}` is not a section of a scenario (misspelt?); the sections are: {}",
                segments[0],
                SECTIONS.join(", ")
            )));
        }
        remove(below, &segments, 0).map_err(&fail)?;
        removed.push(Removed {
            path: segments.join("."),
            line: here.line,
        });
    }
    Ok(removed)
}

/// `segments[depth..]` removed from `table` (the table at
/// `segments[..depth]`), and any table it leaves empty.
fn remove(table: &mut toml::Table, segments: &[String], depth: usize) -> Result<(), String> {
    let key = &segments[depth];
    let whole = quoted_path(segments);
    let here = quoted_path(&segments[..=depth]);
    let Some(value) = table.get_mut(key) else {
        let keys: Vec<String> = table
            .keys()
            .map(|k| quoted_path(std::slice::from_ref(k)))
            .collect();
        let holds = match (depth, keys.is_empty()) {
            (_, true) => String::new(),
            (0, false) => format!("; it has the sections {}", keys.join(", ")),
            (_, false) => format!(
                "; in [{}] it sets {}",
                quoted_path(&segments[..depth]),
                keys.join(", ")
            ),
        };
        return Err(format!(
            "the base does not set `{whole}`, so there is nothing to unset (misspelt?){holds}"
        ));
    };
    if depth + 1 == segments.len() {
        table.remove(key);
        return Ok(());
    }
    let toml::Value::Table(inner) = value else {
        let what = if value.is_array() {
            "an array"
        } else {
            "a value"
        };
        return Err(format!(
            "the base's `{here}` is {what}, not a table, so it has no `{whole}`: unset `{here}` \
             whole"
        ));
    };
    remove(inner, segments, depth + 1)?;
    if inner.is_empty() {
        table.remove(key);
    }
    Ok(())
}

/// `segments` written back as a TOML key path, quoting any segment that
/// is not a bare key.
pub(super) fn quoted_path(segments: &[String]) -> String {
    segments
        .iter()
        .map(|s| {
            let bare = !s.is_empty()
                && s.chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if bare { s.clone() } else { format!("\"{s}\"") }
        })
        .collect::<Vec<_>>()
        .join(".")
}

/// A `[coil]` written over a base's step force replaces it: a coil-driven
/// relay has no step force. `table` is the file's own table, `below` the
/// merged table of its bases; returns whether a force was removed.
pub(super) fn coil_displaces_force(table: &toml::Table, below: &mut toml::Table) -> bool {
    let own_coil = matches!(table.get("coil"), Some(toml::Value::Table(_)));
    let own_force = matches!(
        table.get("mechanics"),
        Some(toml::Value::Table(m)) if m.contains_key("force")
    );
    if !own_coil || own_force {
        return false;
    }
    match below.get_mut("mechanics") {
        Some(toml::Value::Table(m)) => m.remove("force").is_some(),
        _ => false,
    }
}
