//! Where a scenario is wrong, and what to change.

use std::fmt;
use std::path::PathBuf;

use thiserror::Error;

use super::law::SurfaceLaw;

/// A place in a scenario file: the file and, when known, the 1-based line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The scenario file, or `<stdin>` for one read from standard input.
    pub path: PathBuf,
    /// 1-based line, when the error can be traced to one.
    pub line: Option<usize>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}", self.path.display()),
            None => write!(f, "{}", self.path.display()),
        }
    }
}

/// Why a scenario file cannot be used. Each variant says where (`at`),
/// which key, and what to change.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ScenarioError {
    /// The scenario file could not be read.
    #[error("{}: cannot read the scenario file", path.display())]
    Read {
        /// The file as given.
        path: PathBuf,
        /// Why it could not be read.
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid TOML, or sets a key or a table twice.
    #[error("{at}: not valid TOML (column {column}): {message}")]
    Syntax {
        /// Where the parser stopped.
        at: Location,
        /// 1-based column of that place, in characters.
        column: usize,
        /// The parser's message; for a duplicate key, it names the key and the
        /// line that set it first.
        message: String,
        /// The parser's error.
        #[source]
        source: Box<toml::de::Error>,
    },
    /// A key its section does not have, such as a misspelt one.
    #[error("{at}: unknown key `{key}` (misspelt?); {expected}")]
    UnknownKey {
        /// Where the key is.
        at: Location,
        /// The dotted key, e.g. `mechanics.mas`.
        key: String,
        /// The keys the section has, in serde's words ("expected one of …").
        expected: String,
        /// The deserializer's error.
        #[source]
        source: Box<toml::de::Error>,
    },
    /// A required key or section is not given.
    #[error("{at}: `{key}` is missing: {help}")]
    MissingKey {
        /// Where it is missing: the enclosing table, or the key that needs it.
        at: Location,
        /// The dotted key that is missing.
        key: String,
        /// What the key means, or how to add it.
        help: String,
        /// The deserializer's error, when the deserializer found it missing;
        /// `None` when validation did.
        #[source]
        source: Option<Box<toml::de::Error>>,
    },
    /// A value of the wrong type (text for a number, …) or not one of the
    /// values a key takes (e.g. an unknown `surface.law`).
    #[error("{at}: bad value for `{key}`: {message}")]
    BadValue {
        /// Where the value is.
        at: Location,
        /// The dotted key whose value it is.
        key: String,
        /// The deserializer's message in a reader's words.
        message: String,
        /// The deserializer's error.
        #[source]
        source: Box<toml::de::Error>,
    },
    /// A number that is not finite, or outside the range its key allows.
    #[error("{at}: `{key}` = {value:?} {requirement}")]
    Invalid {
        /// Where the key is.
        at: Location,
        /// The dotted key, e.g. `mechanics.mass` or `probe[0].low`.
        key: String,
        /// The value given (a count that must be at least 1 reports 0).
        value: f64,
        /// What the value must be, and what the key means.
        requirement: String,
    },
    /// A text key that must name something is blank (`probe[i].signal`,
    /// `circuit.netlist`, `circuit.subckt`, …).
    #[error("{at}: `{key}` must not be empty: {help}")]
    Empty {
        /// Where the key is.
        at: Location,
        /// The dotted key.
        key: String,
        /// What the key holds.
        help: &'static str,
    },
    /// Two keys or sections that cannot be used together are both given.
    #[error("{at}: `{key}` and `{other}` cannot both be given: {why}; {advice}")]
    Conflict {
        /// Where `key` is.
        at: Location,
        /// The dotted key reported.
        key: String,
        /// The key or section it cannot be used with.
        other: String,
        /// Why the two exclude each other.
        why: &'static str,
        /// Which to keep, in the file that gives both.
        advice: &'static str,
    },
    /// Two keys or sections that cannot be used together, given by two
    /// different files of a chain of bases (one of them usually the
    /// scenario itself, the other its base).
    #[error("{at}: {conflict}")]
    BaseConflict {
        /// Where the one of the two given higher up the chain is.
        at: Location,
        /// The two keys, the file of each, and how to keep either.
        conflict: Box<InheritedConflict>,
    },
    /// An entry of `unset` that cannot be applied: not a key path, a path
    /// no base sets, or `unset` in a file without a `base`.
    #[error("{at}: `unset`{}: {problem}", entry(path))]
    Unset {
        /// Where the entry is.
        at: Location,
        /// The entry as written (empty when `unset` itself is malformed).
        path: String,
        /// What is wrong, and what to write instead.
        problem: String,
    },
    /// A key of `[surface]` or `[back_stop]` that the section's `law` does
    /// not read.
    #[error(
        "{at}: `{key}` is not a key of surface law \"{law}\", which takes {takes}; \
         remove it or change `surface.law`"
    )]
    NotForLaw {
        /// Where the key is.
        at: Location,
        /// The dotted key, e.g. `surface.damping`.
        key: String,
        /// The section's `law`.
        law: SurfaceLaw,
        /// The keys that law reads, as the message lists them.
        takes: &'static str,
    },
    /// The mechanics alone were asked of a coil-driven relay (a `[coil]`
    /// and no `mechanics.force`), which moves only coupled to its driver
    /// circuit.
    #[error(
        "{}: a coil-driven relay ([coil], docs/model.md §7) is simulated only with its driver \
         circuit, by `run` (the coil coupled to the netlist); for the mechanics alone \
         replace [coil] with `mechanics.force`, the closing force in N",
        path.display()
    )]
    CoilDriveUnsupported {
        /// The scenario file.
        path: PathBuf,
    },
    /// A key given as one of the scenario's numbers (in `[sweep]`, or to
    /// `Scenario::number` or `Scenario::set_number`) that is not one.
    #[error("{at}: `{key}` is not a number of the scenario{within}; use one of: {known}")]
    UnknownNumber {
        /// Where the key was named; no line for a library call.
        at: Location,
        /// The key as given.
        key: String,
        /// Where the key was named, e.g. " (named in [sweep.vary])"; empty for a
        /// library call.
        within: &'static str,
        /// The keys that are numbers, comma-separated.
        known: String,
    },
    /// A `[sweep]` key that cannot be used (a grid of more than two keys, a
    /// varied key the scenario gives no value or 0, a grid end outside the
    /// key's range), or a number key whose section the scenario lacks.
    #[error("{at}: `{key}`: {problem}")]
    Sweep {
        /// Where the key is; no line for a library call.
        at: Location,
        /// The key as shown in the message, e.g. `sweep.vary."mechanics.mass"`.
        key: String,
        /// What is wrong, and what to change.
        problem: String,
    },
    /// `base =` names a scenario that cannot be used: an unknown part, a
    /// file that cannot be read, or a chain of bases that comes back to
    /// itself.
    #[error("{at}: `base` = {base:?}: {problem}")]
    Base {
        /// Where `base` is.
        at: Location,
        /// The value of `base`.
        base: String,
        /// What is wrong, and what to write instead.
        problem: String,
    },
    /// The netlist named by `circuit.netlist` could not be read.
    #[error(
        "{}: cannot read the netlist named by `circuit.netlist` in {} ({})",
        path.display(),
        scenario.display(),
        if scenario.as_os_str() == "<stdin>" {
            "the scenario came from standard input, so a relative path is relative to the \
             working directory"
        } else {
            "relative paths are relative to the scenario file"
        }
    )]
    NetlistRead {
        /// The netlist's path, resolved against the scenario's directory.
        path: PathBuf,
        /// The scenario file that names it (`<stdin>` for standard input).
        scenario: PathBuf,
        /// Why it could not be read.
        #[source]
        source: std::io::Error,
    },
}

/// Two keys that exclude each other, each given by a different file of a
/// chain of bases: the body of [`ScenarioError::BaseConflict`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InheritedConflict {
    /// The dotted key reported.
    pub key: String,
    /// Which file, and which line of it, gives `key`.
    pub key_from: String,
    /// The key or section it cannot be used with.
    pub other: String,
    /// Which file, and which line of it, gives `other`.
    pub other_from: String,
    /// Why the two exclude each other.
    pub why: &'static str,
    /// How to keep either: which key to remove from the scenario, or to
    /// `unset` from its base.
    pub advice: String,
}

impl fmt::Display for InheritedConflict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "`{}` ({}) and `{}` ({}) cannot both be given: {}; {}",
            self.key, self.key_from, self.other, self.other_from, self.why, self.advice
        )
    }
}

/// " entry \"PATH\"" for an `unset` error about one entry, "" for one
/// about `unset` itself.
fn entry(path: &str) -> String {
    if path.is_empty() {
        String::new()
    } else {
        format!(" entry {path:?}")
    }
}

/// `Some(f(at))` for the variants that point at a place in the file, by
/// reference or by mutable reference as `$error` is borrowed.
macro_rules! located {
    ($error:expr, $at:ident => $value:expr) => {
        match $error {
            ScenarioError::UnknownKey { $at, .. }
            | ScenarioError::MissingKey { $at, .. }
            | ScenarioError::BadValue { $at, .. }
            | ScenarioError::Invalid { $at, .. }
            | ScenarioError::Empty { $at, .. }
            | ScenarioError::Conflict { $at, .. }
            | ScenarioError::BaseConflict { $at, .. }
            | ScenarioError::Unset { $at, .. }
            | ScenarioError::NotForLaw { $at, .. }
            | ScenarioError::UnknownNumber { $at, .. }
            | ScenarioError::Sweep { $at, .. }
            | ScenarioError::Syntax { $at, .. }
            | ScenarioError::Base { $at, .. } => Some($value),
            _ => None,
        }
    };
}

impl ScenarioError {
    /// The parser's error reduced to its message: for an error found in a
    /// merged document (a scenario with its bases), whose quoted text and
    /// line numbers are the merged document's, not any file's.
    pub(super) fn forget_merged_text(&mut self) {
        let plain = |e: &toml::de::Error| -> Box<toml::de::Error> {
            Box::new(<toml::de::Error as serde::de::Error>::custom(e.message()))
        };
        match self {
            ScenarioError::Syntax { source, .. }
            | ScenarioError::UnknownKey { source, .. }
            | ScenarioError::BadValue { source, .. } => *source = plain(source),
            ScenarioError::MissingKey {
                source: Some(source),
                ..
            } => *source = plain(source),
            _ => {}
        }
    }

    /// The place in a scenario file the error points at, when it points
    /// at one (its file and line).
    pub fn location(&self) -> Option<&Location> {
        located!(self, at => at)
    }

    /// [`ScenarioError::location`], to move it (an error found in merged
    /// or overlaid text, pointed back at the file its key came from).
    pub fn location_mut(&mut self) -> Option<&mut Location> {
        located!(self, at => at)
    }

    /// The dotted key the error is about, if it is about one.
    pub fn key(&self) -> Option<&str> {
        match self {
            ScenarioError::UnknownKey { key, .. }
            | ScenarioError::MissingKey { key, .. }
            | ScenarioError::BadValue { key, .. }
            | ScenarioError::Invalid { key, .. }
            | ScenarioError::Empty { key, .. }
            | ScenarioError::Conflict { key, .. }
            | ScenarioError::NotForLaw { key, .. }
            | ScenarioError::UnknownNumber { key, .. }
            | ScenarioError::Sweep { key, .. } => Some(key),
            ScenarioError::BaseConflict { conflict, .. } => Some(&conflict.key),
            ScenarioError::Base { .. } => Some("base"),
            ScenarioError::Unset { .. } => Some("unset"),
            ScenarioError::Read { .. }
            | ScenarioError::Syntax { .. }
            | ScenarioError::CoilDriveUnsupported { .. } => None,
            ScenarioError::NetlistRead { .. } => Some("circuit.netlist"),
        }
    }
}
