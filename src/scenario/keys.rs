//! Where each key of a scenario file is: lines for messages, and the
//! plain-words translation of the TOML parser's errors.

use std::ops::Range;
use std::path::Path;

use toml::de::{DeTable, DeValue};

use super::error::{Location, ScenarioError};

pub(super) fn line_column(text: &str, at: usize) -> (usize, usize) {
    let at = at.min(text.len());
    let before = &text.as_bytes()[..at];
    let line = before.iter().filter(|&&b| b == b'\n').count() + 1;
    let line_start = before
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let column = String::from_utf8_lossy(&before[line_start..])
        .chars()
        .count()
        + 1;
    (line, column)
}

/// The 1-based line of top-level or dotted `key` in `text`, if it is there.
pub(super) fn line_of(text: &str, key: &str) -> Option<usize> {
    let tree = DeTable::parse(text).ok()?;
    KeyIndex::new(&tree, text).line_of_key(key)
}

/// Every key of the parsed file with its dotted path and where it is, so
/// that errors from serde (which know a byte span) and from validation
/// (which know a key) can both name the key and the line.
pub(super) struct KeyIndex<'t> {
    pub(super) text: &'t str,
    pub(super) document_span: Range<usize>,
    pub(super) entries: Vec<KeyEntry>,
}

pub(super) struct KeyEntry {
    pub(super) path: String,
    pub(super) key_span: Range<usize>,
    pub(super) value_span: Range<usize>,
}

impl<'t> KeyIndex<'t> {
    pub(super) fn new(tree: &toml::Spanned<DeTable<'_>>, text: &'t str) -> Self {
        let mut entries = Vec::new();
        Self::walk(tree.get_ref(), "", &mut entries);
        KeyIndex {
            text,
            document_span: tree.span(),
            entries,
        }
    }

    pub(super) fn walk(table: &DeTable<'_>, prefix: &str, out: &mut Vec<KeyEntry>) {
        for (key, value) in table.iter() {
            let path = join_key(prefix, key.get_ref());
            out.push(KeyEntry {
                path: path.clone(),
                key_span: key.span(),
                value_span: value.span(),
            });
            match value.get_ref() {
                DeValue::Table(inner) => Self::walk(inner, &path, out),
                DeValue::Array(items) => {
                    for (i, item) in items.into_iter().enumerate() {
                        let item_path = format!("{path}[{i}]");
                        out.push(KeyEntry {
                            path: item_path.clone(),
                            key_span: item.span(),
                            value_span: item.span(),
                        });
                        if let DeValue::Table(inner) = item.get_ref() {
                            Self::walk(inner, &item_path, out);
                        }
                    }
                }
                _ => {}
            }
        }
    }

    /// The line of `key`, or of its nearest ancestor present in the file
    /// (a missing key is reported at its section's header).
    pub(super) fn line_of_key(&self, key: &str) -> Option<usize> {
        let mut key = key;
        loop {
            if let Some(e) = self.entries.iter().find(|e| e.path == key) {
                return Some(line_column(self.text, e.key_span.start).0);
            }
            key = &key[..key.rfind(['.', '['])?];
        }
    }

    /// The key an error span belongs to: exactly a key or value span if
    /// one matches, else the innermost value containing it; "" for the
    /// document itself.
    pub(super) fn key_at(&self, span: &Range<usize>) -> &str {
        if *span == self.document_span {
            return "";
        }
        // Children follow their parent in `entries`, and an array of one
        // table can share its span with that table: search from the end
        // so that the deepest key wins.
        if let Some(e) = self
            .entries
            .iter()
            .rev()
            .find(|e| e.key_span == *span || e.value_span == *span)
        {
            return &e.path;
        }
        self.entries
            .iter()
            .filter(|e| e.value_span.start <= span.start && span.end <= e.value_span.end)
            .min_by_key(|e| e.value_span.len())
            .map_or("", |e| e.path.as_str())
    }

    /// Turn a serde error (unknown key, missing key, wrong type) into one
    /// that names the dotted key.
    pub(super) fn shape_error(&self, mut source: toml::de::Error, origin: &Path) -> ScenarioError {
        // With the text, the error displays an excerpt with the key marked.
        source.set_input(Some(self.text));
        let span = source.span();
        let at = Location {
            path: origin.to_owned(),
            line: span.as_ref().map(|s| line_column(self.text, s.start).0),
        };
        let here = span.as_ref().map_or("", |s| self.key_at(s)).to_owned();
        let message = source.message().trim_end().to_owned();
        let source = Box::new(source);
        // serde's own wording (`de::Error::unknown_field`, `missing_field`)
        // is the only place the field name is available.
        let unknown = message
            .strip_prefix("unknown field `")
            .and_then(|rest| rest.split_once("`, "));
        if let Some((_, expected)) = unknown {
            return ScenarioError::UnknownKey {
                at,
                key: here,
                expected: expected.to_owned(),
                source,
            };
        }
        let missing = message
            .strip_prefix("missing field `")
            .and_then(|rest| rest.split_once('`'));
        if let Some((name, _)) = missing {
            let key = join_key(&here, name);
            return ScenarioError::MissingKey {
                at,
                help: key_help(&key).to_owned(),
                key,
                source: Some(source),
            };
        }
        ScenarioError::BadValue {
            at,
            key: here,
            message: plain_type_error(&message),
            source,
        }
    }
}

/// "duplicate key" said with the key's name and where it was first set:
/// the earlier line that starts with the same key (or table header).
pub(super) fn duplicate_message(text: &str, name: &str, line: usize) -> String {
    if name.is_empty() {
        return "duplicate key: a key or table is given twice".to_owned();
    }
    let header = format!("[{name}]");
    let first = text.lines().take(line.saturating_sub(1)).position(|l| {
        let l = l.trim_start();
        l.starts_with(&header)
            || l.strip_prefix(name)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
    });
    let table = text
        .lines()
        .nth(line.saturating_sub(1))
        .is_some_and(|l| l.trim_start().starts_with('['));
    let what = if table {
        format!("the table `[{name}]` appears twice")
    } else {
        format!("duplicate key `{name}`: it is set twice in the same table")
    };
    match first {
        Some(n) => format!("{what} (first on line {}); keep one", n + 1),
        None => format!("{what}; keep one"),
    }
}

/// serde's "invalid type: string \"x\", expected f64" in a user's words.
pub(super) fn plain_type_error(message: &str) -> String {
    let Some(rest) = message.strip_prefix("invalid type: ") else {
        return message.to_owned();
    };
    let Some((found, expected)) = rest.rsplit_once(", expected ") else {
        return message.to_owned();
    };
    let found = if let Some(s) = found.strip_prefix("string ") {
        format!("the text {s}")
    } else if let Some(n) = found.strip_prefix("integer ") {
        format!("the integer {}", n.trim_matches('`'))
    } else if let Some(n) = found.strip_prefix("floating point ") {
        format!("the number {}", n.trim_matches('`'))
    } else if let Some(b) = found.strip_prefix("boolean ") {
        b.trim_matches('`').to_owned()
    } else if found == "map" {
        "a table".to_owned()
    } else if found == "sequence" {
        "an array".to_owned()
    } else {
        found.to_owned()
    };
    let expected = match expected {
        "f64" | "f32" => "a number (e.g. 2.0e-4, no quotes)",
        "u64" | "u32" | "usize" | "u16" | "u8" | "i64" | "i32" => "a whole number (no quotes)",
        "a boolean" | "bool" => "true or false",
        "a string" => "text in quotes",
        other => other,
    };
    format!("found {found}, expected {expected}")
}

pub(super) fn join_key(prefix: &str, name: &str) -> String {
    if prefix.is_empty() {
        name.to_owned()
    } else {
        format!("{prefix}.{name}")
    }
}

/// What a required key means, for "missing" messages.
pub(super) fn key_help(key: &str) -> &'static str {
    match key {
        "mechanics" => "add a [mechanics] section: mass, stiffness, damping, force, gap",
        "surface" => "add a [surface] section with `law` and its keys",
        "mechanics.mass" => "the effective moving mass, in kg",
        "mechanics.stiffness" => "the contact-spring stiffness, in N/m",
        "mechanics.damping" => "the structural damping in N·s/m (0 is allowed)",
        "mechanics.gap" => "the contact travel from rest to the fixed contact, in m",
        "surface.law" => "one of \"rigid\", \"kelvin-voigt\", \"hunt-crossley\"",
        "circuit.netlist" => "the netlist file, relative to the scenario file",
        k if k.starts_with("coil.") => {
            "the [coil] section needs resistance, turns, pole_area, air_gap, iron_gap"
        }
        k if k.starts_with("probe") => "each [[probe]] needs signal, low and high",
        _ => "see docs/scenario.md for the keys of each section",
    }
}
