//! The SPICE raw file reader: what ngspice hands back after a run.
//!
//! A raw file is one or more *plots* (one per analysis: `.op`, `.tran`,
//! `.ac`, ...) concatenated with no separator. Each plot is a text header
//! (`Title:`, `Date:`, `Command:`, `Plotname:`, `Flags:`, `No. Variables:`,
//! `No. Points:`, `Dimensions:`, `Option:`, `Variables:`) followed by either
//! `Binary:` (point-major little-endian `f64`; complex plots store every
//! value as a `(re, im)` pair) or `Values:` (ASCII: a point index, then one
//! value per line, `re,im` for complex plots).
//!
//! What this reader deliberately copes with, because real files do it:
//! - both ASCII layouts: the batch writer's (`0\t\t<v>` and no blank line)
//!   and the `.control` `write` command's (` 0\t<v>`, blank line after each
//!   point), extra `key=value` attributes after the type, separated by a tab
//!   (batch) or a space (`write`);
//! - the `Command: version 44` line of ngspice 44+ and any other
//!   `Command:`/`Option:`/`Dimensions:` lines;
//! - `Flags: ... unpadded` with vectors shorter than the plot (`dims=`);
//! - a killed run: the batch writer patches `No. Points:` only when the
//!   analysis ends, so a killed run leaves `0` there and the data cut at an
//!   arbitrary byte. The point count is derived from the data, read up to
//!   the last whole point, and a [`RawWarning`] says so;
//! - `.options interp` in ngspice 39: more points than `No. Points:`
//!   declares (read, up to the next plot's header, with a warning), and
//!   with UIC the data started over several times, the variables and
//!   `Binary:` written again after an all-zero point (the last start's
//!   points are kept, with a warning). Its time stamps also run slow
//!   where the simulator's step exceeds the `.tran` step, which no reader
//!   can undo: `run` leaves `interp` out of the deck;
//! - ngspice 39 leaves garbage in the imaginary part of the AC frequency
//!   axis, so a complex plot's `frequency` scale is stored as real;
//! - LTspice's dialect (UTF-16 header, `f32` values, `FastAccess` layout) is
//!   detected and refused with a message saying so, rather than misread.
//!
//! Malformed input is an error naming the line (text) or byte offset
//! (binary); the reader never panics and never allocates more than the
//! input can fill, whatever the header claims. Values are stored once, one
//! `Vec` per vector, so memory is the size of the data.

pub mod export;
mod stream;

pub use stream::stream_csv;

use std::fmt;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// The largest raw file [`RawFile::read`] loads into memory: 4 GiB. The
/// values take about as much memory as the file.
pub const MAX_LOADED_BYTES: u64 = 4 << 30;

/// A complex value of an AC (or other complex) plot.
pub type Complex64 = nalgebra::Complex<f64>;

/// Everything in one raw file.
#[derive(Debug, Clone, PartialEq)]
pub struct RawFile {
    /// In file order (e.g. the `.op` plot before the `.tran` plot).
    pub plots: Vec<Plot>,
    /// Things the reader recovered from, e.g. a killed run's cut data.
    pub warnings: Vec<RawWarning>,
}

/// One analysis result.
#[derive(Debug, Clone, PartialEq)]
pub struct Plot {
    pub title: String,
    /// As written by the simulator (free text, local time).
    pub date: String,
    /// e.g. `Transient Analysis`, `AC Analysis`, `Operating Point`.
    pub name: String,
    /// `Command:` lines (ngspice 44+ writes `version 44`), in order.
    pub commands: Vec<String>,
    /// `Option:` lines, verbatim.
    pub options: Vec<String>,
    /// `Dimensions:` line, verbatim, for multi-dimensional plots.
    pub dimensions: Option<String>,
    /// Header lines of a form this reader does not interpret, verbatim.
    pub other_header_lines: Vec<String>,
    pub flags: Flags,
    pub variables: Vec<Variable>,
    /// `No. Points:` as written; 0 for a killed run.
    pub declared_points: usize,
    columns: Vec<Column>,
}

/// The `Flags:` line.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Flags {
    /// `complex` rather than `real`.
    pub complex: bool,
    /// False with `unpadded`: vectors shorter than the plot have no values
    /// written past their end.
    pub padded: bool,
    /// Flags this reader does not interpret (LTspice's `forward`, `log`...).
    pub other: Vec<String>,
}

/// One vector's declaration in the `Variables:` section.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Variable {
    /// e.g. `time`, `v(out)`, `i(v1)`.
    pub name: String,
    /// The type field: `time`, `voltage`, `current`, `frequency`, ...
    pub kind: String,
    /// Extra fields after the type (`grid=3`, `dims=5`, ...), verbatim.
    pub attributes: Vec<String>,
}

/// Borrowed values of one vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Vector<'a> {
    Real(&'a [f64]),
    Complex(&'a [Complex64]),
}

impl Vector<'_> {
    pub fn len(&self) -> usize {
        match self {
            Vector::Real(v) => v.len(),
            Vector::Complex(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[derive(Debug, Clone, PartialEq)]
enum Column {
    Real(Vec<f64>),
    Complex(Vec<Complex64>),
}

impl Column {
    fn as_vector(&self) -> Vector<'_> {
        match self {
            Column::Real(v) => Vector::Real(v),
            Column::Complex(v) => Vector::Complex(v),
        }
    }

    fn len(&self) -> usize {
        self.as_vector().len()
    }
}

/// Something the reader recovered from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RawWarning {
    /// The data of a plot ended early (a killed or crashed run): the plot
    /// holds the whole points that were there.
    Truncated {
        /// Index of the plot in the file.
        plot: usize,
        /// `No. Points:` as written (0 when the writer never patched it).
        declared: usize,
        /// Whole points read.
        read: usize,
        /// Byte offset where the incomplete point (if any) starts.
        offset: usize,
    },
    /// ngspice 39 with `.options interp` can start a plot's data over: it
    /// writes the variables and `Binary:` again after a point or so. The
    /// points before the last restart are dropped (they are all-zero
    /// points of an abandoned start).
    Restarted {
        /// Index of the plot in the file.
        plot: usize,
        /// How many times the data started over.
        restarts: usize,
        /// Points dropped before the last restart.
        dropped: usize,
    },
    /// A plot held whole points past its `No. Points:` with no plot header
    /// after them: ngspice 39 writes these with `.options interp`
    /// (repeated time stamps included). They belong to the plot and are
    /// read.
    ExtraPoints {
        /// Index of the plot in the file.
        plot: usize,
        /// `No. Points:` as written.
        declared: usize,
        /// Whole points read, more than declared.
        read: usize,
    },
}

impl fmt::Display for RawWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RawWarning::Truncated {
                plot,
                declared,
                read,
                offset,
            } => {
                if *declared == 0 {
                    write!(
                        f,
                        "plot {plot}: header says 0 points (the run was killed before \
                         ngspice finished the file); read {read} whole points, data cut at byte {offset}"
                    )
                } else {
                    write!(
                        f,
                        "plot {plot}: header says {declared} points but the data ends at byte \
                         {offset} after {read} whole points (the file was cut short)"
                    )
                }
            }
            RawWarning::Restarted {
                plot,
                restarts,
                dropped,
            } => write!(
                f,
                "plot {plot}: the data starts over {restarts} time(s) (ngspice re-declares the \
                 variables and `Binary:` with `.options interp`); the {dropped} point(s) before \
                 the last start were dropped"
            ),
            RawWarning::ExtraPoints {
                plot,
                declared,
                read,
            } => write!(
                f,
                "plot {plot}: header says {declared} points but the data holds {read} whole points \
                 (ngspice writes more than it declares with `.options interp`); all {read} are read"
            ),
        }
    }
}

/// Where in the input a problem is: a line for text, a byte offset always.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Position {
    /// 1-based; `None` inside or after binary data, where lines mean nothing.
    pub line: Option<usize>,
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
pub enum RawError {
    #[error("cannot read raw file {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// `error` in the file at `path`. Not a `source`: the message already
    /// holds it, and a cause line would repeat it.
    #[error("{path}: {error}")]
    InFile { path: PathBuf, error: Box<RawError> },
    #[error(
        "{path}: not a regular file: a raw file is read from disk (a device or a pipe could \
         feed it without end)"
    )]
    NotAFile { path: PathBuf },
    #[error(
        "{path}: {size} bytes is more than the {limit} bytes this reader loads at once; \
         `chatterspice raw FILE --format csv` streams binary files of any size"
    )]
    TooLarge {
        path: PathBuf,
        size: u64,
        limit: u64,
    },
    #[error("empty raw file: no plot header found")]
    Empty,
    #[error(
        "this is an LTspice raw file ({what}, at {at}); chatterspice reads ngspice raw files only: \
         re-run the netlist in ngspice, or export the waveforms from LTspice as text"
    )]
    Ltspice { what: &'static str, at: Position },
    #[error(
        "at {at}: expected a raw file header line (`Title:`, `Plotname:`, ...), found {text:?}"
    )]
    UnexpectedLine { at: Position, text: String },
    #[error("at {at}: `{field}` needs a whole number, found {text:?}")]
    BadCount {
        at: Position,
        field: &'static str,
        text: String,
    },
    #[error("at {at}: plot header has no `{field}` line before its data")]
    MissingHeader { at: Position, field: &'static str },
    #[error("at {at}: a plot needs at least one variable (`No. Variables: 0`)")]
    NoVariables { at: Position },
    #[error("at {at}: variable line {text:?} {reason}")]
    BadVariable {
        at: Position,
        text: String,
        reason: &'static str,
    },
    #[error("at {at}: the file ends inside the `Variables:` list ({found} of {expected} declared)")]
    MissingVariables {
        at: Position,
        expected: usize,
        found: usize,
    },
    #[error(
        "at {at}: the header's `Flags:` says {flagged}, but the data hold {bytes} bytes a \
         value for every declared point, as {found} values do: the `Flags:` line is wrong \
         (or the file was edited); fix it to `Flags: {found}`"
    )]
    FlagMismatch {
        at: Position,
        flagged: &'static str,
        found: &'static str,
        bytes: usize,
    },
    #[error("at {at}: expected {expected}, found {text:?}")]
    BadValue {
        at: Position,
        expected: &'static str,
        text: String,
    },
}

/// The metadata of `path`, which must be a regular file: a device or a
/// pipe could feed a reader without end.
fn regular_file(path: &Path) -> Result<std::fs::Metadata, RawError> {
    let meta = std::fs::metadata(path).map_err(|source| RawError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    if !meta.is_file() {
        return Err(RawError::NotAFile {
            path: path.to_path_buf(),
        });
    }
    Ok(meta)
}

impl RawFile {
    /// Reads and parses a raw file; errors name the path. Only regular
    /// files of at most [`MAX_LOADED_BYTES`] are read (a device such as
    /// `/dev/zero` would never end).
    pub fn read(path: impl AsRef<Path>) -> Result<RawFile, RawError> {
        let path = path.as_ref();
        let io = |source| RawError::Io {
            path: path.to_path_buf(),
            source,
        };
        let meta = regular_file(path)?;
        if meta.len() > MAX_LOADED_BYTES {
            return Err(RawError::TooLarge {
                path: path.to_path_buf(),
                size: meta.len(),
                limit: MAX_LOADED_BYTES,
            });
        }
        let bytes = std::fs::read(path).map_err(io)?;
        RawFile::parse(&bytes).map_err(|error| RawError::InFile {
            path: path.to_path_buf(),
            error: Box::new(error),
        })
    }

    /// Parses the bytes of a raw file.
    pub fn parse(bytes: &[u8]) -> Result<RawFile, RawError> {
        detect_utf16(bytes)?;
        let mut cur = Cursor {
            bytes,
            pos: 0,
            line: Some(1),
        };
        let mut plots = Vec::new();
        let mut warnings = Vec::new();
        let mut title = String::new();
        let mut date = String::new();
        loop {
            cur.skip_blank_lines();
            if cur.at_end() {
                break;
            }
            let header = parse_header(&mut cur, &mut title, &mut date)?;
            let index = plots.len();
            let (plot, warning) = match header.data {
                DataKind::Binary => read_binary(&mut cur, header, index)?,
                DataKind::Ascii => read_ascii(&mut cur, header, index)?,
            };
            plots.push(plot);
            warnings.extend(warning);
        }
        if plots.is_empty() {
            return Err(RawError::Empty);
        }
        Ok(RawFile { plots, warnings })
    }

    /// The last transient-analysis plot (ngspice names it "Transient
    /// Analysis"; a deck with `.op` first has the operating point before it).
    pub fn last_transient(&self) -> Option<&Plot> {
        self.plots
            .iter()
            .rev()
            .find(|p| p.name.to_ascii_lowercase().starts_with("transient"))
    }

    /// The first plot whose name is `name`, ignoring case
    /// (e.g. `"transient analysis"`).
    pub fn plot_named(&self, name: &str) -> Option<&Plot> {
        self.plots
            .iter()
            .find(|p| p.name.eq_ignore_ascii_case(name))
    }
}

impl Plot {
    /// Number of points: the length of the longest vector (they differ only
    /// in `unpadded` plots).
    pub fn points(&self) -> usize {
        self.columns.iter().map(Column::len).max().unwrap_or(0)
    }

    pub fn is_complex(&self) -> bool {
        self.flags.complex
    }

    /// Index of the vector called `name`, ignoring ASCII case.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.variables
            .iter()
            .position(|v| v.name.eq_ignore_ascii_case(name))
    }

    /// The vector at `index` in `Variables:` order.
    pub fn vector(&self, index: usize) -> Option<Vector<'_>> {
        self.columns.get(index).map(Column::as_vector)
    }

    /// The vector called `name` (case-insensitive), e.g. `"V(OUT)"`.
    pub fn column(&self, name: &str) -> Option<Vector<'_>> {
        self.index_of(name).and_then(|i| self.vector(i))
    }

    /// A real vector by name; `None` if absent or complex.
    pub fn real(&self, name: &str) -> Option<&[f64]> {
        match self.column(name)? {
            Vector::Real(v) => Some(v),
            Vector::Complex(_) => None,
        }
    }

    /// A complex vector by name; `None` if absent or real.
    pub fn complex(&self, name: &str) -> Option<&[Complex64]> {
        match self.column(name)? {
            Vector::Complex(v) => Some(v),
            Vector::Real(_) => None,
        }
    }

    /// The scale (time, frequency, sweep): by convention the first vector.
    pub fn scale(&self) -> Option<Vector<'_>> {
        self.vector(0)
    }
}

// ---------------------------------------------------------------------------
// Input cursor

struct Cursor<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// 1-based line of `pos`; `None` once binary data made lines meaningless.
    line: Option<usize>,
}

impl<'a> Cursor<'a> {
    fn at(&self) -> Position {
        Position {
            line: self.line,
            offset: self.pos,
        }
    }

    fn at_end(&self) -> bool {
        self.pos >= self.bytes.len()
    }

    fn rest(&self) -> &'a [u8] {
        &self.bytes[self.pos.min(self.bytes.len())..]
    }

    /// The next line without its terminator (`\n`, `\r\n`).
    fn next_line(&mut self) -> Option<&'a [u8]> {
        if self.at_end() {
            return None;
        }
        let rest = self.rest();
        let (line, used) = match rest.iter().position(|&b| b == b'\n') {
            Some(n) => (&rest[..n], n + 1),
            None => (rest, rest.len()),
        };
        self.pos += used;
        if let Some(l) = self.line.as_mut() {
            *l += 1;
        }
        Some(line.strip_suffix(b"\r").unwrap_or(line))
    }

    fn skip_blank_lines(&mut self) {
        while let Some(&b) = self.rest().first() {
            match b {
                b'\n' => {
                    self.pos += 1;
                    if let Some(l) = self.line.as_mut() {
                        *l += 1;
                    }
                }
                b' ' | b'\t' | b'\r' => self.pos += 1,
                _ => break,
            }
        }
    }
}

fn detect_utf16(bytes: &[u8]) -> Result<(), RawError> {
    let at = Position {
        line: Some(1),
        offset: 0,
    };
    if bytes.starts_with(&[0xff, 0xfe]) || bytes.starts_with(&[0xfe, 0xff]) {
        return Err(RawError::Ltspice {
            what: "UTF-16 byte order mark",
            at,
        });
    }
    // LTspice writes its header as UTF-16LE without a BOM: "T\0i\0t\0...".
    if bytes.len() >= 4 && bytes[0] != 0 && bytes[1] == 0 && bytes[3] == 0 {
        return Err(RawError::Ltspice {
            what: "UTF-16 text header",
            at,
        });
    }
    Ok(())
}

// ---------------------------------------------------------------------------
// Header

#[derive(Clone, Copy, PartialEq, Eq)]
enum DataKind {
    Binary,
    Ascii,
}

struct Header {
    plot: Plot,
    nvars: usize,
    /// Per vector: how many values it has (differs from the point count only
    /// through `dims=` in an unpadded plot).
    lengths: Vec<usize>,
    data: DataKind,
}

/// `line` starts with `key` (ASCII case-insensitive); returns the rest, trimmed.
fn field<'a>(line: &'a [u8], key: &str) -> Option<&'a [u8]> {
    let k = key.as_bytes();
    if line.len() >= k.len() && line[..k.len()].eq_ignore_ascii_case(k) {
        Some(line[k.len()..].trim_ascii())
    } else {
        None
    }
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn parse_count(value: &[u8], at: Position, field: &'static str) -> Result<usize, RawError> {
    std::str::from_utf8(value)
        .ok()
        .and_then(|s| s.trim().parse::<usize>().ok())
        .ok_or_else(|| RawError::BadCount {
            at,
            field,
            text: text(value),
        })
}

fn parse_header(
    cur: &mut Cursor<'_>,
    title: &mut String,
    date: &mut String,
) -> Result<Header, RawError> {
    let header_start = cur.at();
    let mut name: Option<String> = None;
    let mut flags: Option<Flags> = None;
    let mut nvars: Option<usize> = None;
    let mut npoints: Option<usize> = None;
    let mut commands = Vec::new();
    let mut options = Vec::new();
    let mut other = Vec::new();
    let mut dimensions = None;
    let mut variables: Option<Vec<Variable>> = None;
    let mut ltspice = false;

    loop {
        let at = cur.at();
        let Some(line) = cur.next_line() else {
            return Err(RawError::MissingHeader {
                at,
                field: "Binary:` or `Values:",
            });
        };
        if line.trim_ascii().is_empty() {
            continue;
        }
        if let Some(v) = field(line, "Title:") {
            *title = text(v);
        } else if let Some(v) = field(line, "Date:") {
            *date = text(v);
        } else if let Some(v) = field(line, "Plotname:") {
            name = Some(text(v));
        } else if let Some(v) = field(line, "Flags:") {
            flags = Some(parse_flags(v));
        } else if let Some(v) = field(line, "No. Variables:") {
            nvars = Some(parse_count(v, at, "No. Variables:")?);
        } else if let Some(v) = field(line, "No. Points:") {
            npoints = Some(parse_count(v, at, "No. Points:")?);
        } else if let Some(v) = field(line, "Dimensions:") {
            dimensions = Some(text(v));
        } else if let Some(v) = field(line, "Command:") {
            ltspice |= v.windows(7).any(|w| w.eq_ignore_ascii_case(b"ltspice"));
            commands.push(text(v));
        } else if let Some(v) = field(line, "Option:") {
            options.push(text(v));
        } else if let Some(v) = field(line, "Variables:") {
            let n = nvars.ok_or(RawError::MissingHeader {
                at,
                field: "No. Variables:",
            })?;
            if n == 0 {
                return Err(RawError::NoVariables { at });
            }
            // The first declaration may share the `Variables:` line.
            let first = (!v.is_empty()).then_some(v);
            variables = Some(parse_variables(cur, n, first, at)?);
        } else if field(line, "Binary:").is_some() || field(line, "Values:").is_some() {
            let data = if field(line, "Binary:").is_some() {
                DataKind::Binary
            } else {
                DataKind::Ascii
            };
            let flags = flags.unwrap_or(Flags {
                complex: false,
                padded: true,
                other: Vec::new(),
            });
            if ltspice
                || flags
                    .other
                    .iter()
                    .any(|f| f.eq_ignore_ascii_case("fastaccess"))
            {
                let double = flags.other.iter().any(|f| f.eq_ignore_ascii_case("double"));
                if data == DataKind::Binary && !(double || flags.complex) {
                    return Err(RawError::Ltspice {
                        what: "binary data with 32-bit float values",
                        at,
                    });
                }
                if flags
                    .other
                    .iter()
                    .any(|f| f.eq_ignore_ascii_case("fastaccess"))
                {
                    return Err(RawError::Ltspice {
                        what: "FastAccess (vector-major) layout",
                        at,
                    });
                }
            }
            let npoints = npoints.ok_or(RawError::MissingHeader {
                at,
                field: "No. Points:",
            })?;
            let variables = variables.ok_or(RawError::MissingHeader {
                at,
                field: "Variables:",
            })?;
            let name = name.ok_or(RawError::MissingHeader {
                at: header_start,
                field: "Plotname:",
            })?;
            // The row size follows the declarations actually read.
            let nvars = variables.len();
            let lengths = variables
                .iter()
                .map(|v| vector_length(v, npoints))
                .collect();
            return Ok(Header {
                plot: Plot {
                    title: title.clone(),
                    date: date.clone(),
                    name,
                    commands,
                    options,
                    dimensions,
                    other_header_lines: other,
                    flags,
                    variables,
                    declared_points: npoints,
                    columns: Vec::new(),
                },
                nvars,
                lengths,
                data,
            });
        } else if looks_like_header_line(line) {
            other.push(text(line));
        } else {
            return Err(RawError::UnexpectedLine {
                at,
                text: text(&line[..line.len().min(80)]),
            });
        }
    }
}

/// `Key: value` with a short alphabetic key (LTspice's `Offset:`,
/// `Backannotation:`...): kept, not interpreted.
fn looks_like_header_line(line: &[u8]) -> bool {
    match line.iter().position(|&b| b == b':') {
        Some(n) if n > 0 && n <= 32 => line[..n]
            .iter()
            .all(|&b| b.is_ascii_alphabetic() || b == b' ' || b == b'.'),
        _ => false,
    }
}

fn parse_flags(v: &[u8]) -> Flags {
    let mut flags = Flags {
        complex: false,
        padded: true,
        other: Vec::new(),
    };
    for word in v
        .split(|b| b.is_ascii_whitespace())
        .filter(|w| !w.is_empty())
    {
        if word.eq_ignore_ascii_case(b"complex") {
            flags.complex = true;
        } else if word.eq_ignore_ascii_case(b"real") {
            flags.complex = false;
        } else if word.eq_ignore_ascii_case(b"unpadded") {
            flags.padded = false;
        } else if word.eq_ignore_ascii_case(b"padded") {
            flags.padded = true;
        } else {
            flags.other.push(text(word));
        }
    }
    flags
}

fn parse_variables(
    cur: &mut Cursor<'_>,
    n: usize,
    first: Option<&[u8]>,
    header_at: Position,
) -> Result<Vec<Variable>, RawError> {
    // Capacity from the input, not from the header's claim.
    let mut vars = Vec::with_capacity(n.min(cur.rest().len() / 4 + 1));
    let mut pending = first;
    for i in 0..n {
        let at = cur.at();
        let line = match pending.take() {
            Some(l) => l,
            None => cur.next_line().ok_or(RawError::MissingVariables {
                at: header_at,
                expected: n,
                found: i,
            })?,
        };
        let mut words = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty());
        let bad = |reason| RawError::BadVariable {
            at,
            text: text(line),
            reason,
        };
        let index = words.next().ok_or(bad("is empty"))?;
        if !index.iter().all(u8::is_ascii_digit) {
            return Err(bad("does not start with the variable's index"));
        }
        let name = words.next().ok_or(bad("has no name"))?;
        let kind = words.next().ok_or(bad("has no type"))?;
        vars.push(Variable {
            name: text(name),
            kind: text(kind),
            attributes: words.map(text).collect(),
        });
    }
    Ok(vars)
}

/// A vector's length: the plot's point count unless `dims=` says fewer
/// (ngspice's own reader does the same).
fn vector_length(v: &Variable, npoints: usize) -> usize {
    let dims = v.attributes.iter().find_map(|a| {
        let (k, val) = a.split_once('=')?;
        k.eq_ignore_ascii_case("dims").then_some(val)
    });
    let Some(dims) = dims else { return npoints };
    let product = dims
        .split(',')
        .map(|d| d.trim().parse::<usize>().ok())
        .try_fold(1usize, |acc, d| acc.checked_mul(d?));
    match product {
        Some(p) if p <= npoints => p,
        _ => npoints,
    }
}

// ---------------------------------------------------------------------------
// Data

/// Whether a vector is stored as real in a complex plot: the AC frequency
/// axis, whose imaginary part ngspice 39 fills with garbage.
fn real_in_complex_plot(v: &Variable, index: usize) -> bool {
    index == 0 && v.kind.eq_ignore_ascii_case("frequency")
}

/// For declared-0 plots: whether what follows is the next plot's header
/// rather than data (a legitimately empty plot).
fn next_is_header(rest: &[u8]) -> bool {
    let head = &rest[..rest.len().min(16)];
    let starts = |k: &[u8]| head.len() >= k.len() && head[..k.len()].eq_ignore_ascii_case(k);
    starts(b"Title:") || starts(b"Plotname:") || starts(b"Date:")
}

/// Whether the first value of each of the first `points` rows of `row`
/// bytes (the scale: time, frequency) is finite and never decreases.
fn scale_increases(data: &[u8], row: usize, points: usize) -> bool {
    let mut previous = f64::NEG_INFINITY;
    for k in 0..points.min(data.len() / row.max(1)) {
        let x = le_f64(&data[k * row..], 0);
        if !x.is_finite() || x < previous {
            return false;
        }
        previous = x;
    }
    true
}

/// Where a plot's binary data really are, walked point by point.
#[derive(Debug, Default)]
struct Sections {
    /// Bytes before the last start of the data (dropped points and the
    /// re-declarations).
    skip: usize,
    /// Whole points after it, up to the next plot's header or the end.
    points: usize,
    /// Bytes of a partial point after them (only at the end of the file).
    tail: usize,
    restarts: usize,
    dropped: usize,
}

/// Walks `rest` (a plot's binary data, `row` bytes a point) one point at a
/// time: a re-declaration of `vars` and `Binary:` at a point boundary
/// starts the data over; the next plot's header or the end of the file
/// ends them.
fn sections(rest: &[u8], row: usize, vars: &[Variable]) -> Sections {
    let mut s = Sections::default();
    let mut at = 0;
    loop {
        let here = &rest[at..];
        if here.is_empty() || next_is_header(here) {
            break;
        }
        if here[0] == b'\t' {
            if let Some(len) = redeclaration(here, vars) {
                s.restarts += 1;
                s.dropped += s.points;
                s.points = 0;
                at += len;
                s.skip = at;
                continue;
            }
        }
        if here.len() < row {
            s.tail = here.len();
            break;
        }
        s.points += 1;
        at += row;
    }
    s
}

/// The length of a re-declaration of `vars` (`\t0\ttime\ttime` ... then
/// `Binary:`) at the start of `bytes`, if there is one.
fn redeclaration(bytes: &[u8], vars: &[Variable]) -> Option<usize> {
    let mut pos = 0;
    for v in vars {
        let line_len = bytes
            .get(pos..)?
            .iter()
            .take(4096)
            .position(|&b| b == b'\n')?;
        let line = &bytes[pos..pos + line_len];
        let mut words = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|w| !w.is_empty());
        if !words.next()?.iter().all(u8::is_ascii_digit) || words.next()? != v.name.as_bytes() {
            return None;
        }
        pos += line_len + 1;
    }
    bytes
        .get(pos..)?
        .starts_with(b"Binary:\n")
        .then_some(pos + b"Binary:\n".len())
}

fn read_binary(
    cur: &mut Cursor<'_>,
    header: Header,
    index: usize,
) -> Result<(Plot, Vec<RawWarning>), RawError> {
    let Header {
        mut plot,
        nvars,
        lengths,
        ..
    } = header;
    let complex = plot.flags.complex;
    let width = if complex { 16 } else { 8 };
    let declared = plot.declared_points;
    let rest = cur.rest();
    let start = cur.pos;

    let uniform = plot.flags.padded || lengths.iter().all(|&l| l == declared);
    let row = nvars * width;
    let open_ended = declared == 0;
    if open_ended && (rest.is_empty() || next_is_header(rest)) {
        // A plot that legitimately has no points (or a run that failed
        // before its first point): nothing to read, nothing lost.
        plot.columns = empty_columns(&plot);
        cur.line = None;
        return Ok((plot, Vec::new()));
    }

    // Data that end exactly where the other kind of value would put them:
    // the `Flags:` line is wrong (8 bytes a value for real, 16 for complex).
    if uniform && !open_ended && declared > 0 {
        let other = if complex { 8 } else { 16 };
        let ends_there = |end: usize| {
            rest.len() == end
                || rest
                    .get(end..)
                    .is_some_and(|r| next_is_header(r.trim_ascii_start()))
        };
        let theirs = declared.checked_mul(nvars * other);
        // Flagged real with twice the data: extra real points (ngspice's
        // interpolation writes some) are told from complex values by the
        // scale, which does not increase when read with the wrong size.
        // Flagged complex with half the data: real values.
        if theirs.is_some_and(ends_there)
            && !declared.checked_mul(row).is_some_and(ends_there)
            && (complex
                || (!scale_increases(rest, row, declared)
                    && scale_increases(rest, nvars * other, declared)))
        {
            return Err(RawError::FlagMismatch {
                at: cur.at(),
                flagged: if complex { "complex" } else { "real" },
                found: if complex { "real" } else { "complex" },
                bytes: other,
            });
        }
    }
    // A file whose data do not end where the header says, at the end of
    // the file or at the next plot's header, went through `.options
    // interp`: walk it point by point (restarts, extra points).
    let irregular = uniform
        && !open_ended
        && row > 0
        && declared
            .checked_mul(row)
            .is_some_and(|end| rest.len() > end && !next_is_header(&rest[end..]));
    let sections = if irregular {
        // Less than a whole point past the declared ones, and no restart:
        // not ngspice's doing; the garbage is reported where it starts.
        Some(sections(rest, row, &plot.variables))
            .filter(|s| s.restarts > 0 || s.points > declared)
            .unwrap_or_default()
    } else {
        Sections::default()
    };
    let irregular = irregular && sections.points > 0;
    let sections = if irregular {
        sections
    } else {
        Sections::default()
    };
    let extra = sections.points.saturating_sub(declared);
    let (skip, tail) = (sections.skip, sections.tail);
    let mut warnings = Vec::new();
    if sections.restarts > 0 {
        warnings.push(RawWarning::Restarted {
            plot: index,
            restarts: sections.restarts,
            dropped: sections.dropped,
        });
    }
    let (read, used) = if uniform {
        // Whole points the bytes hold, whatever the header claims.
        let whole = if open_ended {
            rest.len() / row
        } else if irregular {
            sections.points
        } else {
            declared.min(rest.len() / row)
        };
        let data = &rest[skip..skip + whole * row];
        let lens: Vec<usize> = if open_ended || extra > 0 {
            vec![whole; nvars]
        } else {
            lengths.iter().map(|&l| l.min(whole)).collect()
        };
        // One pass over the rows, each value written straight to its place
        // in its column (sized up front, so no capacity checks): the input
        // is read once, and the output pages are touched in order.
        let columns = if !complex {
            let mut cols: Vec<Vec<f64>> = lens.iter().map(|&l| vec![0.0; l]).collect();
            for (i, r) in data.chunks_exact(row).enumerate() {
                for (col, cell) in cols.iter_mut().zip(r.chunks_exact(8)) {
                    if let Some(d) = col.get_mut(i) {
                        *d = le_f64(cell, 0);
                    }
                }
            }
            cols.into_iter().map(Column::Real).collect()
        } else {
            let mut cols: Vec<Column> = plot
                .variables
                .iter()
                .enumerate()
                .map(|(j, v)| {
                    if real_in_complex_plot(v, j) {
                        Column::Real(vec![0.0; lens[j]])
                    } else {
                        Column::Complex(vec![Complex64::new(0.0, 0.0); lens[j]])
                    }
                })
                .collect();
            for (i, r) in data.chunks_exact(row).enumerate() {
                for (col, cell) in cols.iter_mut().zip(r.chunks_exact(16)) {
                    match col {
                        Column::Real(v) => {
                            if let Some(d) = v.get_mut(i) {
                                *d = le_f64(cell, 0);
                            }
                        }
                        Column::Complex(v) => {
                            if let Some(d) = v.get_mut(i) {
                                *d = Complex64::new(le_f64(cell, 0), le_f64(cell, 8));
                            }
                        }
                    }
                }
            }
            cols
        };
        plot.columns = columns;
        (whole, skip + whole * row)
    } else {
        let (columns, read, used) = read_binary_unpadded(rest, &plot, &lengths, width);
        plot.columns = columns;
        (read, used)
    };
    cur.pos = start + used + tail;
    cur.line = None;

    if extra > 0 {
        warnings.push(RawWarning::ExtraPoints {
            plot: index,
            declared,
            read,
        });
    } else if open_ended || read < declared {
        warnings.push(RawWarning::Truncated {
            plot: index,
            declared,
            read,
            offset: cur.pos,
        });
        // Only the last plot of a file can be cut: the rest is the partial point.
        cur.pos = cur.bytes.len();
    }
    Ok((plot, warnings))
}

fn empty_columns(plot: &Plot) -> Vec<Column> {
    plot.variables
        .iter()
        .enumerate()
        .map(|(j, v)| {
            if !plot.flags.complex || real_in_complex_plot(v, j) {
                Column::Real(Vec::new())
            } else {
                Column::Complex(Vec::new())
            }
        })
        .collect()
}

/// Unpadded plots with short vectors: the row size varies, so walk point
/// by point.
fn read_binary_unpadded(
    rest: &[u8],
    plot: &Plot,
    lengths: &[usize],
    width: usize,
) -> (Vec<Column>, usize, usize) {
    let mut columns = empty_columns(plot);
    let mut pos = 0;
    let mut read = 0;
    for i in 0..plot.declared_points {
        let need = lengths.iter().filter(|&&l| i < l).count() * width;
        if need == 0 || rest.len() - pos < need {
            break;
        }
        for (j, col) in columns.iter_mut().enumerate() {
            if i >= lengths[j] {
                continue;
            }
            match col {
                Column::Real(v) => v.push(f64_at(rest, pos)),
                Column::Complex(v) => {
                    v.push(Complex64::new(f64_at(rest, pos), f64_at(rest, pos + 8)))
                }
            }
            pos += width;
        }
        read += 1;
    }
    (columns, read, pos)
}

/// The f64 at `off` in a cell of at least `off + 8` bytes.
#[inline]
fn le_f64(cell: &[u8], off: usize) -> f64 {
    let mut b = [0u8; 8];
    if let Some(src) = cell.get(off..off + 8) {
        b.copy_from_slice(src);
    }
    f64::from_le_bytes(b)
}

#[inline]
fn f64_at(bytes: &[u8], off: usize) -> f64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&bytes[off..off + 8]);
    f64::from_le_bytes(b)
}

/// Tokens of an ASCII data section, tracking lines for error messages.
struct Tokens<'a, 'c> {
    cur: &'c mut Cursor<'a>,
}

impl<'a> Tokens<'a, '_> {
    fn skip_ws(&mut self) {
        let bytes = self.cur.bytes;
        let mut pos = self.cur.pos;
        let mut lines = 0;
        while let Some(&b) = bytes.get(pos) {
            match b {
                b'\n' => lines += 1,
                b' ' | b'\t' | b'\r' => {}
                _ => break,
            }
            pos += 1;
        }
        self.cur.pos = pos;
        if let Some(l) = self.cur.line.as_mut() {
            *l += lines;
        }
    }

    /// The next token ending at whitespace or `,`; `complete` is false when
    /// it runs into the end of the input (a cut number).
    fn token(&mut self) -> (&'a [u8], bool) {
        let bytes = self.cur.bytes;
        let start = self.cur.pos;
        let mut end = start;
        while let Some(&b) = bytes.get(end) {
            if b.is_ascii_whitespace() || b == b',' {
                break;
            }
            end += 1;
        }
        self.cur.pos = end;
        (&bytes[start..end], end < bytes.len())
    }

    fn peek(&self) -> Option<u8> {
        self.cur.bytes.get(self.cur.pos).copied()
    }
}

enum Got<T> {
    Value(T),
    /// The input ended (or was cut) here.
    End,
}

fn parse_f64(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse::<f64>().ok()
}

impl Tokens<'_, '_> {
    fn real(&mut self) -> Result<Got<f64>, RawError> {
        self.skip_ws();
        let at = self.cur.at();
        let (tok, complete) = self.token();
        if tok.is_empty() && self.peek().is_none() || !complete {
            return Ok(Got::End);
        }
        parse_f64(tok)
            .map(Got::Value)
            .ok_or_else(|| RawError::BadValue {
                at,
                expected: "a number",
                text: text(&tok[..tok.len().min(40)]),
            })
    }

    fn complex(&mut self) -> Result<Got<(f64, f64)>, RawError> {
        self.skip_ws();
        let at = self.cur.at();
        let (re_tok, complete) = self.token();
        if !complete {
            return Ok(Got::End);
        }
        let bad = |text_: &[u8]| RawError::BadValue {
            at,
            expected: "a complex value `re,im`",
            text: text(&text_[..text_.len().min(40)]),
        };
        let re = parse_f64(re_tok).ok_or_else(|| bad(re_tok))?;
        self.skip_ws();
        match self.peek() {
            Some(b',') => self.cur.pos += 1,
            None => return Ok(Got::End),
            Some(_) => return Err(bad(re_tok)),
        }
        self.skip_ws();
        let (im_tok, complete) = self.token();
        if !complete {
            return Ok(Got::End);
        }
        let im = parse_f64(im_tok).ok_or_else(|| bad(im_tok))?;
        Ok(Got::Value((re, im)))
    }
}

fn read_ascii(
    cur: &mut Cursor<'_>,
    header: Header,
    index: usize,
) -> Result<(Plot, Vec<RawWarning>), RawError> {
    let Header {
        mut plot,
        nvars,
        lengths,
        ..
    } = header;
    let complex = plot.flags.complex;
    let declared = plot.declared_points;
    let padded = plot.flags.padded;

    // A value takes at least two bytes ("0\n"): bound allocations by the input.
    let cap = |len: usize| len.min(cur.rest().len() / (2 * nvars) + 1);
    let mut columns: Vec<Column> = plot
        .variables
        .iter()
        .enumerate()
        .map(|(j, v)| {
            if !complex || real_in_complex_plot(v, j) {
                Column::Real(Vec::with_capacity(cap(lengths[j])))
            } else {
                Column::Complex(Vec::with_capacity(cap(lengths[j])))
            }
        })
        .collect();

    let open_ended = declared == 0;
    let mut read = 0usize;
    let mut cut_at = None;
    let mut tokens = Tokens { cur };
    let mut extra = false;
    'points: loop {
        if !open_ended && read >= declared {
            // More points than declared (`.options interp`): go on while
            // what follows is a point index, not the next plot's header.
            tokens.skip_ws();
            if padded
                && lengths.iter().all(|&l| l == declared)
                && tokens.peek().is_some_and(|b| b.is_ascii_digit())
            {
                extra = true;
            } else {
                break;
            }
        }
        tokens.skip_ws();
        let point_start = tokens.cur.at();
        if tokens.peek().is_none() {
            if !open_ended {
                cut_at = Some(point_start.offset);
            }
            break;
        }
        let (idx, complete) = tokens.token();
        let is_index = !idx.is_empty() && idx.iter().all(u8::is_ascii_digit);
        if !is_index {
            if open_ended {
                // The next plot's header: rewind to its start.
                tokens.cur.pos = point_start.offset;
                tokens.cur.line = point_start.line;
                break;
            }
            return Err(RawError::BadValue {
                at: point_start,
                expected: "a point index",
                text: text(&idx[..idx.len().min(40)]),
            });
        }
        if !complete {
            cut_at = Some(point_start.offset);
            break;
        }
        // Values go straight into the columns; a cut point is rolled back.
        for (j, col) in columns.iter_mut().enumerate() {
            let present = open_ended || extra || read < lengths[j];
            if !present && !padded {
                continue;
            }
            let store = present;
            let got = if complex {
                match tokens.complex()? {
                    Got::Value((re, im)) => {
                        if store {
                            match col {
                                Column::Real(v) => v.push(re),
                                Column::Complex(v) => v.push(Complex64::new(re, im)),
                            }
                        }
                        true
                    }
                    Got::End => false,
                }
            } else {
                match tokens.real()? {
                    Got::Value(x) => {
                        if store {
                            if let Column::Real(v) = col {
                                v.push(x);
                            }
                        }
                        true
                    }
                    Got::End => false,
                }
            };
            if !got {
                for c in columns.iter_mut() {
                    truncate(c, read);
                }
                cut_at = Some(point_start.offset);
                break 'points;
            }
        }
        read += 1;
    }
    plot.columns = columns;
    if extra && read > declared {
        let warning = RawWarning::ExtraPoints {
            plot: index,
            declared,
            read,
        };
        if cut_at.is_some() {
            cur.pos = cur.bytes.len();
        }
        return Ok((plot, vec![warning]));
    }
    let warning = match cut_at {
        Some(offset) if open_ended || read < declared => Some(RawWarning::Truncated {
            plot: index,
            declared,
            read,
            offset,
        }),
        _ => None,
    };
    if warning.is_some() {
        cur.pos = cur.bytes.len();
    }
    Ok((plot, warning.into_iter().collect()))
}

fn truncate(c: &mut Column, len: usize) {
    match c {
        Column::Real(v) => v.truncate(len),
        Column::Complex(v) => v.truncate(len),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(flags: &str, nvars: usize, points: &str, vars: &str, kind: &str) -> Vec<u8> {
        format!(
            "Title: t\nDate: d\nPlotname: Transient Analysis\nFlags: {flags}\n\
             No. Variables: {nvars}\nNo. Points: {points}\nVariables:\n{vars}{kind}\n"
        )
        .into_bytes()
    }

    fn binary(values: &[f64]) -> Vec<u8> {
        values.iter().flat_map(|v| v.to_le_bytes()).collect()
    }

    const TWO: &str = "\t0\ttime\ttime\n\t1\tv(out)\tvoltage\n";

    #[test]
    fn binary_real_plot_reads_columns_by_name_in_any_case() {
        let mut f = header("real", 2, "3       ", TWO, "Binary:");
        f.extend(binary(&[0.0, 1.0, 1.0, 2.0, 2.0, 3.0]));
        let raw = RawFile::parse(&f).unwrap();
        let p = &raw.plots[0];
        assert_eq!(p.points(), 3);
        assert_eq!(p.real("V(OUT)").unwrap(), &[1.0, 2.0, 3.0]);
        assert_eq!(p.real("time").unwrap(), &[0.0, 1.0, 2.0]);
        assert!(raw.warnings.is_empty());
    }

    #[test]
    fn killed_binary_run_reads_whole_points_and_warns() {
        let mut f = header("real", 2, "0       ", TWO, "Binary:");
        f.extend(binary(&[0.0, 1.0, 1.0, 2.0]));
        f.extend(&[1, 2, 3, 4, 5]); // a cut third point
        let raw = RawFile::parse(&f).unwrap();
        assert_eq!(raw.plots[0].points(), 2);
        assert!(matches!(
            raw.warnings[..],
            [RawWarning::Truncated {
                declared: 0,
                read: 2,
                ..
            }]
        ));
    }

    #[test]
    fn header_only_failed_run_is_an_empty_plot_without_warning() {
        let f = header("real", 2, "0       ", TWO, "Binary:");
        let raw = RawFile::parse(&f).unwrap();
        assert_eq!(raw.plots[0].points(), 0);
        assert!(raw.warnings.is_empty());
    }

    #[test]
    fn ascii_both_layouts_read_alike() {
        let batch = "0\t\t0.0e0\n\t1.5\n1\t\t1e-3\n\t2.5\n";
        let write = " 0\t0.0e0\n\t1.5\n\n 1\t1e-3\n\t2.5\n\n";
        for body in [batch, write] {
            let mut f = header("real", 2, "2", TWO, "Values:");
            f.extend(body.as_bytes());
            let raw = RawFile::parse(&f).unwrap();
            assert_eq!(raw.plots[0].real("v(out)").unwrap(), &[1.5, 2.5]);
        }
    }

    #[test]
    fn ascii_complex_with_spaces_around_the_comma() {
        let vars = "\t0\tfrequency\tfrequency grid=3\n\t1\tv(out)\tvoltage\n";
        let mut f = header("complex", 2, "1", vars, "Values:");
        f.extend(b" 0\t1.0e2,7.0\n\t0.5 , -0.25\n");
        let raw = RawFile::parse(&f).unwrap();
        let p = &raw.plots[0];
        assert_eq!(p.real("frequency").unwrap(), &[100.0]);
        assert_eq!(p.complex("v(out)").unwrap(), &[Complex64::new(0.5, -0.25)]);
        assert_eq!(p.variables[0].attributes, vec!["grid=3".to_string()]);
    }

    #[test]
    fn ascii_cut_mid_number_drops_the_point() {
        let mut f = header("real", 2, "0", TWO, "Values:");
        f.extend(b"0\t\t0.0\n\t1.5\n1\t\t1e-3\n\t2.5");
        let raw = RawFile::parse(&f).unwrap();
        assert_eq!(raw.plots[0].points(), 1);
        assert_eq!(raw.warnings.len(), 1);
    }

    #[test]
    fn unpadded_short_vector_binary() {
        let vars = "\t0\ttime\ttime\n\t1\tx\tvoltage dims=1\n";
        let mut f = header("real unpadded", 2, "2", vars, "Binary:");
        f.extend(binary(&[0.0, 9.0, 1.0]));
        let raw = RawFile::parse(&f).unwrap();
        let p = &raw.plots[0];
        assert_eq!(p.real("time").unwrap(), &[0.0, 1.0]);
        assert_eq!(p.real("x").unwrap(), &[9.0]);
    }

    #[test]
    fn errors_name_the_line() {
        let mut f = header("real", 2, "1", TWO, "Values:");
        f.extend(b"0\t\t0.0\n\tbogus\n");
        let err = RawFile::parse(&f).unwrap_err().to_string();
        assert!(err.contains("line 12"), "{err}");
        let err = RawFile::parse(b"Title: x\nNo. Points: many\n")
            .unwrap_err()
            .to_string();
        assert!(err.contains("line 2") && err.contains("many"), "{err}");
    }

    #[test]
    fn huge_claims_do_not_allocate() {
        let mut f = header("real", 2, "18446744073709551615", TWO, "Binary:");
        f.extend(binary(&[0.0, 1.0]));
        let raw = RawFile::parse(&f).unwrap();
        assert_eq!(raw.plots[0].points(), 1);
        assert_eq!(raw.warnings.len(), 1);
    }

    #[test]
    fn ltspice_utf16_is_refused_with_a_reason() {
        let utf16: Vec<u8> = "Title: * x\n"
            .encode_utf16()
            .flat_map(|u| u.to_le_bytes())
            .collect();
        let err = RawFile::parse(&utf16).unwrap_err().to_string();
        assert!(err.contains("LTspice"), "{err}");
    }
}
