//! `base =`: a scenario that starts from another one (`"default"`, a
//! bundled part `"part:NAME"`, or a file) and overrides it key by key.
//!
//! The bases are read first, each with its own `base` (a chain of them
//! is followed, a loop refused), and the tables are merged from the
//! bottom up: a section of the file replaces the base's keys one by one,
//! an array (`[[probe]]`) replaces the base's whole array, and a surface
//! section whose `law` changes starts afresh (the keys of one law mean
//! nothing to another). Relative paths (`circuit.netlist`) keep meaning
//! what they meant in the file that wrote them. A file's `unset` removes
//! keys of its bases before its own are merged in, and its `[coil]`
//! replaces its bases' step force (`unset.rs`). An error about a key
//! names the file and line the key came from, and two keys that exclude
//! each other, given by two files, are named with the file of each.

use std::path::{Path, PathBuf};

use toml::de::DeTable;

use super::builtin::{DEFAULT_SCENARIO_ORIGIN, DEFAULT_SCENARIO_TOML};
use super::error::{InheritedConflict, Location, ScenarioError};
use super::keys::{KeyIndex, line_column, line_of};
use super::unset::{self, Removed};

/// How deep a chain of bases may go before it is taken for a loop.
const MAX_DEPTH: usize = 16;

/// One file of a chain of bases, as read.
pub(super) struct Layer {
    /// Where it came from: a file, `part:NAME` or the built-in default.
    pub(super) origin: PathBuf,
    /// Its text.
    pub(super) text: String,
    /// The `base` value that named it, as the file above wrote it
    /// (`default`, `part:NAME`, `../lib/relay.toml`); `None` for the
    /// scenario itself.
    pub(super) named: Option<String>,
    /// The keys of its bases its `unset` removed.
    pub(super) removed: Vec<Removed>,
}

/// A scenario with its bases merged in: the merged TOML text and the
/// layers it came from, the base first and the file itself last.
pub(super) struct Expanded {
    pub(super) text: String,
    pub(super) layers: Vec<Layer>,
}

/// The scenario `text` (from `origin`) with its bases merged in; `None`
/// when it has no `base`.
pub(super) fn expand(text: &str, origin: &Path) -> Result<Option<Expanded>, ScenarioError> {
    let table = table_of(text, origin)?;
    if !table.contains_key("base") && !table.contains_key("unset") {
        return Ok(None);
    }
    let mut layers = Vec::new();
    let merged = resolve(
        text.to_owned(),
        origin.to_owned(),
        None,
        table,
        &mut layers,
        &mut Vec::new(),
    )?;
    let text = toml::to_string(&merged).map_err(|e| ScenarioError::Base {
        at: Location {
            path: origin.to_owned(),
            line: None,
        },
        base: String::new(),
        problem: format!("the merged scenario cannot be written as TOML: {e}"),
    })?;
    Ok(Some(Expanded { text, layers }))
}

/// The layers of `origin`'s scenario (named `named` by the file above
/// it) merged into one table, its bases pushed on `layers` before it.
fn resolve(
    text: String,
    origin: PathBuf,
    named: Option<String>,
    mut table: toml::Table,
    layers: &mut Vec<Layer>,
    chain: &mut Vec<PathBuf>,
) -> Result<toml::Table, ScenarioError> {
    absolute_paths(&mut table, &origin);
    let mut removed = Vec::new();
    let merged = match table.remove("base") {
        None => {
            if table.contains_key("unset") {
                return Err(ScenarioError::Unset {
                    at: Location {
                        path: origin.clone(),
                        line: line_of(&text, "unset"),
                    },
                    path: String::new(),
                    problem: "`unset` removes keys of a base, and this file has no `base`; \
                              remove the key from the file itself instead"
                        .into(),
                });
            }
            table
        }
        Some(value) => {
            let at = Location {
                path: origin.clone(),
                line: line_of(&text, "base"),
            };
            let toml::Value::String(base) = value else {
                return Err(ScenarioError::Base {
                    at,
                    base: value.to_string(),
                    problem: "must be text: \"default\", \"part:NAME\" or a file path".into(),
                });
            };
            let fail = |problem: String| ScenarioError::Base {
                at: at.clone(),
                base: base.clone(),
                problem,
            };
            if chain.len() >= MAX_DEPTH {
                return Err(fail(format!(
                    "the chain of bases is more than {MAX_DEPTH} deep; does it come back to itself?"
                )));
            }
            let (base_origin, base_text) = source_of(&base, &origin).map_err(&fail)?;
            if base_origin == origin || chain.contains(&base_origin) {
                return Err(fail(format!(
                    "the chain of bases comes back to {}",
                    base_origin.display()
                )));
            }
            let base_table = table_of(&base_text, &base_origin)?;
            chain.push(origin.clone());
            let below = resolve(
                base_text,
                base_origin,
                Some(base.clone()),
                base_table,
                layers,
                chain,
            );
            chain.pop();
            let mut below = below?;
            if let Some(entries) = table.remove("unset") {
                removed = unset::apply(entries, &mut below, &origin, &text)?;
            }
            unset::coil_displaces_force(&table, &mut below);
            merge(&mut below, table);
            below
        }
    };
    layers.push(Layer {
        origin,
        text,
        named,
        removed,
    });
    Ok(merged)
}

/// The text and the origin `base` names, seen from the file at `origin`.
fn source_of(base: &str, origin: &Path) -> Result<(PathBuf, String), String> {
    if base == "default" {
        return Ok((
            PathBuf::from(DEFAULT_SCENARIO_ORIGIN),
            DEFAULT_SCENARIO_TOML.to_owned(),
        ));
    }
    if let Some(name) = base.strip_prefix("part:") {
        return match bundled_part(name) {
            Some(text) => Ok((PathBuf::from(format!("part:{name}")), text.to_owned())),
            None => Err(format!(
                "no bundled part `{name}`; the parts are: {}",
                BUNDLED_PARTS
                    .iter()
                    .map(|(n, _)| *n)
                    .collect::<Vec<_>>()
                    .join(", ")
            )),
        };
    }
    let dir = origin.parent().unwrap_or(Path::new(""));
    let path = lexically_normal(&dir.join(base));
    match crate::input::read_to_string(&path) {
        Ok(text) => Ok((path, text)),
        Err(e) => Err(format!(
            "cannot read {} ({e}); a base is \"default\", \"part:NAME\" or a file path \
             relative to this file",
            path.display()
        )),
    }
}

/// The bundled parts' scenarios by name, for `base = "part:NAME"`.
pub const BUNDLED_PARTS: &[(&str, &str)] = &[
    (
        "omron-g5le-1-dc5",
        include_str!("../../parts/omron-g5le-1-dc5.toml"),
    ),
    (
        "songle-srd-05vdc-sl-c",
        include_str!("../../parts/songle-srd-05vdc-sl-c.toml"),
    ),
    (
        "panasonic-tq4-5v",
        include_str!("../../parts/panasonic-tq4-5v.toml"),
    ),
    (
        "finder-40.52-12vdc",
        include_str!("../../parts/finder-40.52-12vdc.toml"),
    ),
    (
        "coto-9104-05",
        include_str!("../../parts/coto-9104-05.toml"),
    ),
    (
        "te-v23145-12v",
        include_str!("../../parts/te-v23145-12v.toml"),
    ),
    (
        "te-axicom-im-5v",
        include_str!("../../parts/te-axicom-im-5v.toml"),
    ),
    (
        "te-rt1-rt314012",
        include_str!("../../parts/te-rt1-rt314012.toml"),
    ),
    (
        "omron-g8h-1c4t-r-12v",
        include_str!("../../parts/omron-g8h-1c4t-r-12v.toml"),
    ),
    (
        "te-card-e-v23057-12v",
        include_str!("../../parts/te-card-e-v23057-12v.toml"),
    ),
    ("te-rel-5v", include_str!("../../parts/te-rel-5v.toml")),
];

/// The scenario text of bundled part `name`.
pub fn bundled_part(name: &str) -> Option<&'static str> {
    BUNDLED_PARTS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, text)| *text)
}

/// [`bundled_part`] at compile time, for the parts' own table: a name
/// that is not bundled stops the build.
pub const fn bundled_part_text(name: &str) -> &'static str {
    let mut i = 0;
    while i < BUNDLED_PARTS.len() {
        if same(name.as_bytes(), BUNDLED_PARTS[i].0.as_bytes()) {
            return BUNDLED_PARTS[i].1;
        }
        i += 1;
    }
    panic!("not a bundled part")
}

/// `a == b`, at compile time.
const fn same(a: &[u8], b: &[u8]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

/// `text` as a TOML table; a syntax error names `origin`.
fn table_of(text: &str, origin: &Path) -> Result<toml::Table, ScenarioError> {
    toml::from_str::<toml::Table>(text).map_err(|source| {
        let start = source.span().map_or(0, |s| s.start);
        let (line, column) = line_column(text, start);
        ScenarioError::Syntax {
            at: Location {
                path: origin.to_owned(),
                line: Some(line),
            },
            column,
            message: source.message().trim_end().to_owned(),
            source: Box::new(source),
        }
    })
}

/// A relative `circuit.netlist` made absolute against `origin`'s
/// directory, so that it keeps naming the same file once merged into a
/// scenario elsewhere.
fn absolute_paths(table: &mut toml::Table, origin: &Path) {
    let Some(toml::Value::Table(circuit)) = table.get_mut("circuit") else {
        return;
    };
    let Some(toml::Value::String(netlist)) = circuit.get_mut("netlist") else {
        return;
    };
    if let Some(name) = super::builtin::builtin_netlist(origin, netlist) {
        *netlist = name.to_owned();
        return;
    }
    let dir = origin.parent().unwrap_or(Path::new(""));
    let joined = dir.join(&*netlist);
    let absolute = std::path::absolute(&joined).unwrap_or(joined);
    *netlist = lexically_normal(&absolute).display().to_string();
}

/// `over` merged into `into`, key by key: tables merge, anything else
/// (values, arrays) replaces; a table whose `law` changes is replaced.
fn merge(into: &mut toml::Table, over: toml::Table) {
    merge_in(into, over, None);
}

/// [`merge`] of the table at `parent` (its key, at the top: `None`). An
/// `[envelope]` range written in full (its `min` and its `max`) is the
/// user's range, `log` included: it replaces the base's, never inheriting
/// a `log = true` the user did not write. A printed figure of
/// `[datasheet]` (`making_current = { typ = 10 }`) is the figure as the
/// user's datasheet prints it: it replaces the base's whole, never keeping
/// a bound the user did not write.
fn merge_in(into: &mut toml::Table, over: toml::Table, parent: Option<&str>) {
    for (key, value) in over {
        let full_range = parent == Some("envelope")
            && matches!(&value, toml::Value::Table(t) if t.contains_key("min") && t.contains_key("max"));
        match (into.get_mut(&key), value) {
            (Some(toml::Value::Table(below)), toml::Value::Table(above))
                if !law_changes(below, &above) && !full_range && parent != Some("datasheet") =>
            {
                let at = if parent.is_none() {
                    Some(key.as_str())
                } else {
                    Some("")
                };
                merge_in(below, above, at)
            }
            (_, value) => {
                into.insert(key, value);
            }
        }
    }
}

fn law_changes(below: &toml::Table, above: &toml::Table) -> bool {
    above
        .get("law")
        .is_some_and(|law| below.get("law") != Some(law))
}

/// Where a key of the merged scenario comes from.
struct Source {
    /// The index of the layer that gives it (or removed it).
    layer: usize,
    /// Its line in that layer.
    line: usize,
    /// Whether that layer gives the key itself, not only a table around
    /// it or an `unset` entry that removed it.
    exact: bool,
}

impl Expanded {
    /// `error`, found in the merged text, made to point at the file (and
    /// line) its key came from: the topmost layer that gives the key or,
    /// failing that, the closest enclosing table, or the `unset` entry
    /// that removed it. Two keys that exclude each other, given by two
    /// different files, become a [`ScenarioError::BaseConflict`] that
    /// names both files and says how to keep either.
    pub(super) fn relocate(&self, mut error: ScenarioError) -> ScenarioError {
        // The parser quotes the merged document, lines and all: keep its
        // words only, the location below is the file's own.
        if self.layers.len() > 1 {
            error.forget_merged_text();
        }
        if let ScenarioError::Conflict {
            key, other, why, ..
        } = &error
            && let (Some(mine), Some(theirs)) = (self.source(key), self.source(other))
            && mine.exact
            && theirs.exact
            && mine.layer != theirs.layer
        {
            return self.base_conflict(key, mine, other, theirs, why);
        }
        let key = error.key().map(str::to_owned);
        let Some(at) = error.location_mut() else {
            return error;
        };
        let top = self.layers.last().map(|l| l.origin.clone());
        *at = Location {
            path: top.unwrap_or_default(),
            line: None,
        };
        if let Some(found) = key.and_then(|key| self.source(&key)) {
            *at = self.location(&found);
        }
        error
    }

    /// Where `key` comes from: the topmost layer that gives it or the
    /// deepest table around it, an `unset` entry standing for the key it
    /// removed from the layers below.
    fn source(&self, key: &str) -> Option<Source> {
        // A layer's key that the merged scenario no longer has was
        // replaced from above (an array, a table with another law) or
        // unset: that layer does not give it.
        let merged: Vec<String> = DeTable::parse(&self.text)
            .map(|tree| {
                KeyIndex::new(&tree, &self.text)
                    .entries
                    .into_iter()
                    .map(|e| e.path)
                    .collect()
            })
            .unwrap_or_default();
        let kept = |path: &str| merged.is_empty() || merged.iter().any(|p| p == path);
        let mut best: Option<(usize, Source)> = None;
        for (i, layer) in self.layers.iter().enumerate().rev() {
            if let Ok(tree) = DeTable::parse(&layer.text) {
                let index = KeyIndex::new(&tree, &layer.text);
                let mut probe = key;
                loop {
                    if let Some(e) = index
                        .entries
                        .iter()
                        .find(|e| e.path == probe && (i + 1 == self.layers.len() || kept(probe)))
                    {
                        let depth = probe.len();
                        if best.as_ref().is_none_or(|(d, _)| depth > *d) {
                            let line = line_column(&layer.text, e.key_span.start).0;
                            let exact = depth == key.len();
                            best = Some((
                                depth,
                                Source {
                                    layer: i,
                                    line,
                                    exact,
                                },
                            ));
                        }
                        break;
                    }
                    match probe.rfind(['.', '[']) {
                        Some(cut) => probe = &probe[..cut],
                        None => break,
                    }
                }
            }
            // What this layer unset, no layer below it gives any more.
            let covering = layer.removed.iter().find(|r| {
                key == r.path
                    || key
                        .strip_prefix(r.path.as_str())
                        .is_some_and(|rest| rest.starts_with(['.', '[']))
            });
            if let Some(r) = covering {
                if let Some(line) = r.line
                    && best.as_ref().is_none_or(|(d, _)| *d < r.path.len())
                {
                    let source = Source {
                        layer: i,
                        line,
                        exact: false,
                    };
                    best = Some((r.path.len(), source));
                }
                break;
            }
        }
        best.map(|(_, source)| source)
    }

    fn location(&self, source: &Source) -> Location {
        Location {
            path: self.layers[source.layer].origin.clone(),
            line: Some(source.line),
        }
    }

    /// The scenario's own file: the top layer.
    fn own(&self) -> &Layer {
        self.layers.last().expect("a scenario has a layer")
    }

    /// Which file gives a key, in a reader's words: the scenario's own
    /// file and line, or its base as the scenario wrote it (never the
    /// checkout the binary was built in) and the line in it.
    fn describe(&self, source: &Source) -> String {
        let top = self.layers.len() - 1;
        let layer = &self.layers[source.layer];
        let line = source.line;
        if source.layer == top {
            return format!("set in {} line {line}", layer.origin.display());
        }
        let named = layer.named.as_deref().unwrap_or_default();
        if source.layer + 1 == top {
            format!("set by its base \"{named}\", line {line}")
        } else {
            let above = &self.layers[source.layer + 1];
            format!(
                "set by \"{named}\", line {line}, the base of {}",
                above.origin.display()
            )
        }
    }

    /// The conflict of `key` (from `mine`) and `other` (from `theirs`),
    /// given by different files, with what to do in the scenario's own
    /// file to keep either.
    fn base_conflict(
        &self,
        key: &str,
        mine: Source,
        other: &str,
        theirs: Source,
        why: &'static str,
    ) -> ScenarioError {
        let top = self.layers.len() - 1;
        let own = self.own().origin.display().to_string();
        let drop = |name: &str, source: &Source| {
            let written =
                unset::quoted_path(&name.split('.').map(str::to_owned).collect::<Vec<_>>());
            if source.layer == top {
                format!("remove `{name}` from {own}")
            } else {
                format!(
                    "add `unset = [\"{}\"]` to {own}",
                    written.replace('"', "\\\"")
                )
            }
        };
        let advice = format!(
            "to keep `{other}`, {}; to keep `{key}`, {}",
            drop(key, &mine),
            drop(other, &theirs)
        );
        let upper = if mine.layer >= theirs.layer {
            &mine
        } else {
            &theirs
        };
        ScenarioError::BaseConflict {
            at: self.location(upper),
            conflict: Box::new(InheritedConflict {
                key: key.to_owned(),
                key_from: self.describe(&mine),
                other: other.to_owned(),
                other_from: self.describe(&theirs),
                why,
                advice,
            }),
        }
    }
}

/// `path` with `.` dropped and `dir/..` folded, without touching the file
/// system: `scenarios/../netlists/a.cir` → `netlists/a.cir`, which reads
/// better in messages. A `..` with nothing to fold stays.
pub(super) fn lexically_normal(path: &Path) -> PathBuf {
    use std::path::Component;
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            Component::CurDir => {}
            Component::ParentDir => match out.components().next_back() {
                Some(Component::Normal(_)) => {
                    out.pop();
                }
                Some(Component::RootDir | Component::Prefix(_)) => {}
                _ => out.push(".."),
            },
            other => out.push(other),
        }
    }
    out
}
