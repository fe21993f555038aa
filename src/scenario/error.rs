//! Where a scenario is wrong, and what to change.

use super::*;

/// A place in a scenario file: the file and, when known, the 1-based line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    pub path: PathBuf,
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
pub enum ScenarioError {
    #[error("{}: cannot read the scenario file", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{at}: not valid TOML (column {column}): {message}")]
    Syntax {
        at: Location,
        column: usize,
        message: String,
        #[source]
        source: Box<toml::de::Error>,
    },
    #[error("{at}: unknown key `{key}` (misspelt?); {expected}")]
    UnknownKey {
        at: Location,
        key: String,
        expected: String,
        #[source]
        source: Box<toml::de::Error>,
    },
    #[error("{at}: `{key}` is missing: {help}")]
    MissingKey {
        at: Location,
        key: String,
        help: String,
        #[source]
        source: Option<Box<toml::de::Error>>,
    },
    #[error("{at}: bad value for `{key}`: {message}")]
    BadValue {
        at: Location,
        key: String,
        message: String,
        #[source]
        source: Box<toml::de::Error>,
    },
    #[error("{at}: `{key}` = {value:?} {requirement}")]
    Invalid {
        at: Location,
        key: String,
        value: f64,
        requirement: String,
    },
    #[error("{at}: `{key}` must not be empty: {help}")]
    Empty {
        at: Location,
        key: String,
        help: &'static str,
    },
    #[error("{at}: `{key}` and `{other}` cannot both be given: {advice}")]
    Conflict {
        at: Location,
        key: String,
        other: String,
        advice: &'static str,
    },
    #[error(
        "{at}: `{key}` is not a key of surface law \"{law}\", which takes {takes}; \
         remove it or change `surface.law`"
    )]
    NotForLaw {
        at: Location,
        key: String,
        law: SurfaceLaw,
        takes: &'static str,
    },
    #[error(
        "{}: a coil-driven relay ([coil], docs/model.md §7) is simulated only with its driver \
         circuit, by `run` (the coil coupled to the netlist); for the mechanics alone \
         replace [coil] with `mechanics.force`, the closing force in N",
        path.display()
    )]
    CoilDriveUnsupported { path: PathBuf },
    #[error("{at}: `{key}` is not a number of the scenario{within}; use one of: {known}")]
    UnknownNumber {
        at: Location,
        key: String,
        /// Where the key was named, e.g. " (in [sweep.vary])"; empty for a
        /// library call.
        within: &'static str,
        /// The keys that are numbers, comma-separated.
        known: String,
    },
    #[error("{at}: `{key}`: {problem}")]
    Sweep {
        at: Location,
        key: String,
        problem: String,
    },
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
        path: PathBuf,
        scenario: PathBuf,
        #[source]
        source: std::io::Error,
    },
}

impl ScenarioError {
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
            ScenarioError::Read { .. }
            | ScenarioError::Syntax { .. }
            | ScenarioError::CoilDriveUnsupported { .. } => None,
            ScenarioError::NetlistRead { .. } => Some("circuit.netlist"),
        }
    }
}
