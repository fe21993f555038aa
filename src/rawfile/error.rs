//! Why a raw file could not be read ([`RawError`]), and where in the
//! input the problem is ([`Position`]); why a plot could not be written
//! out ([`ExportError`], the error of the `export` and `stream` modules).

use std::fmt;
use std::path::PathBuf;

use thiserror::Error;

/// Where in the input a problem is: a line for text, a byte offset always.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Position {
    /// 1-based; `None` inside or after binary data, where lines mean nothing.
    pub line: Option<usize>,
    /// 0-based byte offset from the start of the file.
    pub offset: usize,
}

impl fmt::Display for Position {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "line {line} (byte {})", self.offset),
            None => write!(f, "byte {}", self.offset),
        }
    }
}

/// Why a raw file could not be read.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RawError {
    /// The file cannot be opened or read.
    #[error("cannot read raw file {path}: {source}")]
    Io {
        /// The raw file.
        path: PathBuf,
        /// Why it cannot be read.
        #[source]
        source: std::io::Error,
    },
    /// `error` in the file at `path`. Not a `source`: the message already
    /// holds it, and a cause line would repeat it.
    #[error("{path}: {error}")]
    InFile {
        /// The raw file.
        path: PathBuf,
        /// What is wrong in it.
        error: Box<RawError>,
    },
    /// The path is a directory, a device or a pipe.
    #[error(
        "{path}: not a regular file: a raw file is read from disk (a device or a pipe could \
         feed it without end)"
    )]
    NotAFile {
        /// The path given.
        path: PathBuf,
    },
    /// The file is larger than [`MAX_LOADED_BYTES`](super::types::MAX_LOADED_BYTES).
    #[error(
        "{path}: {size} bytes is more than the {limit} bytes this reader loads at once; \
         `chatterspice raw FILE --format csv` streams binary files of any size"
    )]
    TooLarge {
        /// The raw file.
        path: PathBuf,
        /// Its size, in bytes.
        size: u64,
        /// The limit, in bytes.
        limit: u64,
    },
    /// The input holds no plot (it is empty or blank).
    #[error("empty raw file: no plot header found")]
    Empty,
    /// A raw file in a form this reader does not read: a UTF-16
    /// big-endian header (LTspice's own files, UTF-16 little-endian, are
    /// read).
    #[error("at {at}: {what}: this reader reads UTF-8 and UTF-16 little-endian raw files")]
    Ltspice {
        /// What gave it away, e.g. `UTF-16 big-endian byte order mark`.
        what: &'static str,
        /// Where.
        at: Position,
    },
    /// A line where a header line should be is none.
    #[error(
        "at {at}: expected a raw file header line (`Title:`, `Plotname:`, ...), found {text:?}"
    )]
    UnexpectedLine {
        /// Where.
        at: Position,
        /// The line (its first 80 bytes).
        text: String,
    },
    /// A header count (`No. Variables:`, `No. Points:`) is not a whole
    /// number.
    #[error("at {at}: `{field}` needs a whole number, found {text:?}")]
    BadCount {
        /// Where.
        at: Position,
        /// The header field, e.g. `No. Points:`.
        field: &'static str,
        /// What it holds.
        text: String,
    },
    /// A plot's data starts before a header line it needs.
    #[error("at {at}: plot header has no `{field}` line before its data")]
    MissingHeader {
        /// Where.
        at: Position,
        /// The missing header field, e.g. `Plotname:`.
        field: &'static str,
    },
    /// `No. Variables:` is 0.
    #[error("at {at}: a plot needs at least one variable (`No. Variables: 0`)")]
    NoVariables {
        /// Where.
        at: Position,
    },
    /// A line of the `Variables:` list is not `index name type`.
    #[error("at {at}: variable line {text:?} {reason}")]
    BadVariable {
        /// Where.
        at: Position,
        /// The line.
        text: String,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// The input ends before every declared variable is listed.
    #[error("at {at}: the file ends inside the `Variables:` list ({found} of {expected} declared)")]
    MissingVariables {
        /// Where the `Variables:` list starts.
        at: Position,
        /// `No. Variables:`.
        expected: usize,
        /// Variables listed before the end.
        found: usize,
    },
    /// The binary data's size fits the other of real and complex, not the
    /// one `Flags:` says.
    #[error(
        "at {at}: the header's `Flags:` says {flagged}, but the data hold {bytes} bytes a \
         value for every declared point, as {found} values do: the `Flags:` line is wrong \
         (or the file was edited); fix it to `Flags: {found}`"
    )]
    FlagMismatch {
        /// Where the data start.
        at: Position,
        /// What `Flags:` says: `real` or `complex`.
        flagged: &'static str,
        /// What the data fit: the other one.
        found: &'static str,
        /// The bytes a value the data's size fits: 8 real, 16 complex.
        bytes: usize,
    },
    /// LTspice FastAccess data (vector after vector) end before every
    /// declared point of every vector: the vectors cannot be told apart.
    #[error(
        "at {at}: the FastAccess data of {vectors} vectors of {points} points need {expected} \
         bytes, but the file holds {found} (it was cut short, or `No. Points:` is wrong)"
    )]
    ShortFastAccess {
        /// Where the data start.
        at: Position,
        /// `No. Variables:`.
        vectors: usize,
        /// `No. Points:`.
        points: usize,
        /// Bytes the header's counts need.
        expected: u64,
        /// Bytes there are.
        found: usize,
    },
    /// A value of ASCII data cannot be read.
    #[error("at {at}: expected {expected}, found {text:?}")]
    BadValue {
        /// Where.
        at: Position,
        /// What was expected: a number, a complex value, a point index.
        expected: &'static str,
        /// What was found (its first 40 bytes).
        text: String,
    },
}

impl RawError {
    /// The error with its position (if any) mapped by `f`: from text
    /// decoded from UTF-16 back to the input.
    pub(super) fn map_position(mut self, f: impl Fn(Position) -> Position) -> RawError {
        match &mut self {
            RawError::Ltspice { at, .. }
            | RawError::UnexpectedLine { at, .. }
            | RawError::BadCount { at, .. }
            | RawError::MissingHeader { at, .. }
            | RawError::NoVariables { at }
            | RawError::BadVariable { at, .. }
            | RawError::MissingVariables { at, .. }
            | RawError::FlagMismatch { at, .. }
            | RawError::ShortFastAccess { at, .. }
            | RawError::BadValue { at, .. } => *at = f(*at),
            RawError::Io { .. }
            | RawError::InFile { .. }
            | RawError::NotAFile { .. }
            | RawError::TooLarge { .. }
            | RawError::Empty => {}
        }
        self
    }
}

/// Why a plot could not be rendered.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The plot asked for is not in the file.
    #[error("there is no plot {index}: the file has {count} plot(s), numbered 0 to {last}", last = .count.saturating_sub(1))]
    NoSuchPlot {
        /// The 0-based plot index asked for.
        index: usize,
        /// The number of plots in the file.
        count: usize,
    },
    /// Writing the output failed.
    #[error("cannot write the output: {0}")]
    Write(#[from] std::io::Error),
    /// The CSV writer failed (usually writing the output).
    #[error("cannot write the CSV output: {0}")]
    Csv(#[from] csv::Error),
    /// The raw file cannot be read.
    #[error(transparent)]
    Raw(#[from] RawError),
}

impl ExportError {
    /// The reader of the output went away (`chatterspice raw f | head`):
    /// not an error worth reporting.
    pub fn is_broken_pipe(&self) -> bool {
        let io = match self {
            ExportError::Write(e) => Some(e),
            ExportError::Csv(e) => match e.kind() {
                csv::ErrorKind::Io(e) => Some(e),
                _ => None,
            },
            ExportError::NoSuchPlot { .. } | ExportError::Raw(_) => None,
        };
        io.is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
    }
}
