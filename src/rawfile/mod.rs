//! The SPICE raw file reader: what ngspice (or LTspice) hands back after a
//! run.
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
//!   axis, so a complex plot's `frequency` scale is stored as real.
//!
//! LTspice writes the same structure in a dialect of its own ([`Dialect`]),
//! read into the same types:
//! - the header in UTF-16 little-endian, with no byte order mark (one is
//!   skipped if there); for ASCII data the values too. Names (plots,
//!   vectors, the title) are kept exactly, beyond ASCII included
//!   (`Noise Spectral Density - (V/Hz½ or A/Hz½)`). A UTF-8 header is read
//!   as LTspice's when a `Command:` line names LTspice, or an `Offset:` or
//!   `Backannotation:` line, or a flag only LTspice writes, says so;
//! - binary values: the first vector (time, frequency, the swept source,
//!   an operating point's first value) an `f64`, every other an `f32`
//!   (stored as the `f64` it converts to exactly), unless `Flags:` says
//!   `double` (all `f64`); complex plots store every value, the frequency
//!   included, as an `(re, im)` pair of `f64`. Points follow one another,
//!   or with `Flags: ... fastaccess` each vector's values are contiguous;
//! - time stamps with their sign bit set (LTspice's waveform compression
//!   leaves some negative) are read as their absolute value;
//! - `.step` runs (`Flags: ... stepped`) are one plot holding every step:
//!   the reader splits it into one [`Plot`] per step, with [`Plot::step`]
//!   saying which (see [`Step`] for how steps are told apart);
//! - `Offset:`, `Backannotation:`, `Output:` and other `Key: value` lines
//!   are kept verbatim in [`Plot::other_header_lines`];
//! - bytes after the declared points that are not another plot's header
//!   (LTspice has been seen to leave an all-zero point there) are left
//!   unread, with a [`RawWarning::TrailingData`]; a file cut short keeps
//!   its whole points with a [`RawWarning::Truncated`], but FastAccess
//!   data cut short are an error ([`RawError::ShortFastAccess`]).
//!
//! Malformed input is an error naming the line (text) or byte offset
//! (binary; offsets count the file's bytes, in UTF-16 text too); the
//! reader never panics and never allocates more than the input can fill,
//! whatever the header claims. Values are stored once, one `Vec` per
//! vector, so memory is the size of the data (LTspice's `f32` values take
//! twice their size as `f64`).

mod data;
mod direct;
pub mod export;
mod header;
mod locate;
mod ltspice;
mod stream;
#[cfg(test)]
mod tests;

pub use stream::stream_csv;

use data::*;
use header::*;

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
    /// The `Title:` line: the netlist's title.
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
    /// The `Flags:` line.
    pub flags: Flags,
    /// The vectors, in `Variables:` order; the first is the scale.
    pub variables: Vec<Variable>,
    /// `No. Points:` as written; 0 for a killed run. For one step of a
    /// stepped plot, the count of the whole plot (every step).
    pub declared_points: usize,
    /// Whose layout the values were read in: ngspice's or LTspice's.
    pub dialect: Dialect,
    /// How the header's text was encoded.
    pub encoding: Encoding,
    /// For one step of an LTspice `.step` run (`Flags: ... stepped`): which
    /// step. `None` for a plot that is not stepped.
    pub step: Option<Step>,
    columns: Vec<Column>,
}

/// The layout of a plot's values, told from its header.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Dialect {
    /// ngspice's (the SPICE3 layout): every binary value an `f64` (a pair
    /// of them when complex), one point after the other.
    #[default]
    Ngspice,
    /// LTspice's: in binary, the scale an `f64` and the other vectors `f32`
    /// unless `Flags:` says `double` (complex plots: every value, the
    /// frequency included, a pair of `f64`); point after point, or vector
    /// after vector with `fastaccess`. Told by a UTF-16 header, a
    /// `Command:` line naming LTspice, an `Offset:` or `Backannotation:`
    /// line, or a flag only LTspice writes (`forward`, `stepped`,
    /// `fastaccess`, `double`).
    Ltspice,
}

impl Dialect {
    /// `"ngspice"` or `"ltspice"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Dialect::Ngspice => "ngspice",
            Dialect::Ltspice => "ltspice",
        }
    }
}

/// The encoding of a plot's header (and, for ASCII data, of its values).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Encoding {
    /// UTF-8 (or plain ASCII): what ngspice writes.
    #[default]
    Utf8,
    /// UTF-16 little-endian, with or without a byte order mark: what
    /// LTspice writes. Binary data after `Binary:` are bytes as usual.
    Utf16Le,
}

impl Encoding {
    /// `"utf-8"` or `"utf-16le"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Encoding::Utf8 => "utf-8",
            Encoding::Utf16Le => "utf-16le",
        }
    }
}

/// One step of a stepped plot. LTspice writes every step of a `.step` run
/// into one plot, one after the other; the reader splits it into one
/// [`Plot`] per step. Without LTspice's `.log` file the steps are told
/// apart by the scale: a step starts wherever the scale (time, frequency,
/// the swept source) comes back to its first value. A plot without a
/// scale (`Operating Point`, `Transfer Function`, `Integrated Noise`) has
/// one point a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    /// 0-based, in file order.
    pub index: usize,
    /// How many steps the stepped plot holds.
    pub count: usize,
    /// Where in the stepped plot (all steps together, 0-based) this step's
    /// first point is.
    pub first_point: usize,
}

/// The `Flags:` line.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Flags {
    /// `complex` rather than `real`.
    pub complex: bool,
    /// False with `unpadded`: vectors shorter than the plot have no values
    /// written past their end.
    pub padded: bool,
    /// The other flags, as written: LTspice's `forward`, `log`, `linear`,
    /// `stepped`, `fastaccess`, `double` (see [`Flags::has`]).
    pub other: Vec<String>,
}

impl Flags {
    /// Whether `flag` is among [`Flags::other`], ignoring ASCII case
    /// (`flags.has("stepped")`).
    pub fn has(&self, flag: &str) -> bool {
        self.other.iter().any(|f| f.eq_ignore_ascii_case(flag))
    }
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
    /// The values of a real plot (and a complex plot's frequency scale).
    Real(&'a [f64]),
    /// The values of a complex plot.
    Complex(&'a [Complex64]),
}

impl Vector<'_> {
    /// The number of values.
    pub fn len(&self) -> usize {
        match self {
            Vector::Real(v) => v.len(),
            Vector::Complex(v) => v.len(),
        }
    }

    /// Whether the vector has no values.
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
    /// Bytes after an LTspice plot's declared points that are neither
    /// another plot's header nor the end of the file (LTspice has been
    /// seen to leave an all-zero point there). They are not read.
    TrailingData {
        /// Index of the plot in the file (the last step of a stepped one).
        plot: usize,
        /// `No. Points:` as written.
        declared: usize,
        /// Byte offset where the unread bytes start.
        offset: usize,
        /// How many bytes are not read.
        bytes: usize,
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
                         the simulator finished the file); read {read} whole points, data cut at byte {offset}"
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
            RawWarning::TrailingData {
                plot,
                declared,
                offset,
                bytes,
            } => write!(
                f,
                "plot {plot}: {bytes} byte(s) from byte {offset}, after the {declared} points the \
                 header declares, are not a plot header; they were not read"
            ),
        }
    }
}

impl RawWarning {
    /// The warning about plot `plot` instead.
    fn in_plot(mut self, index: usize) -> RawWarning {
        match &mut self {
            RawWarning::Truncated { plot, .. }
            | RawWarning::Restarted { plot, .. }
            | RawWarning::ExtraPoints { plot, .. }
            | RawWarning::TrailingData { plot, .. } => *plot = index,
        }
        self
    }

    /// The warning with its byte offset (if any) mapped by `f`.
    fn map_offset(mut self, f: impl Fn(usize) -> usize) -> RawWarning {
        match &mut self {
            RawWarning::Truncated { offset, .. } | RawWarning::TrailingData { offset, .. } => {
                *offset = f(*offset)
            }
            RawWarning::Restarted { .. } | RawWarning::ExtraPoints { .. } => {}
        }
        self
    }
}

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
    /// The file is larger than [`MAX_LOADED_BYTES`].
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
    fn map_position(mut self, f: impl Fn(Position) -> Position) -> RawError {
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
    ///
    /// ngspice's binary files (whole, or cut short by a killed run) are
    /// read from the disk straight into the columns a block of points at a
    /// time, so memory is the size of the values plus a 256 KiB buffer; any
    /// other file (ASCII, LTspice's, `.options interp`, unpadded) is read
    /// whole and parsed as [`RawFile::parse`] does. Both give the same
    /// plots and warnings.
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
        let mut file = crate::input::open_regular(path).map_err(io)?;
        let len = file.metadata().map_err(io)?.len();
        if let Some(raw) = direct::read(&mut file, len).map_err(io)? {
            return Ok(raw);
        }
        drop(file);
        let bytes = crate::input::read_limited(path, MAX_LOADED_BYTES).map_err(io)?;
        RawFile::parse(&bytes).map_err(|error| RawError::InFile {
            path: path.to_path_buf(),
            error: Box::new(error),
        })
    }

    /// Parses the bytes of a raw file.
    ///
    /// ```
    /// use chatterspice::rawfile::RawFile;
    ///
    /// let text = "Title: divider\nDate: today\nPlotname: Transient Analysis\n\
    ///             Flags: real\nNo. Variables: 2\nNo. Points: 2\nVariables:\n\
    ///             \t0\ttime\ttime\n\t1\tv(out)\tvoltage\nValues:\n\
    ///             0\t0.0\n\t1.5\n1\t1e-3\n\t1.65\n";
    /// let raw = RawFile::parse(text.as_bytes())?;
    /// let plot = raw.last_transient().expect("a transient plot");
    /// assert_eq!(plot.real("v(out)"), Some(&[1.5, 1.65][..]));
    /// # Ok::<(), chatterspice::rawfile::RawError>(())
    /// ```
    pub fn parse(bytes: &[u8]) -> Result<RawFile, RawError> {
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
            ltspice::skip_blank(&mut cur);
            if cur.at_end() {
                break;
            }
            let index = plots.len();
            let (mut plot, warning) = match ltspice::utf16_start(cur.rest(), cur.at())? {
                Some(bom) => ltspice::read_utf16_plot(&mut cur, bom, &mut title, &mut date, index)?,
                None => {
                    let header = parse_header(&mut cur, &mut title, &mut date)?;
                    match (header.data, header.plot.dialect) {
                        (DataKind::Binary, Dialect::Ngspice) => {
                            read_binary(&mut cur, header, index)?
                        }
                        (DataKind::Binary, Dialect::Ltspice) => {
                            ltspice::read_binary(&mut cur, header, index)?
                        }
                        (DataKind::Ascii, _) => read_ascii(&mut cur, header, index)?,
                    }
                }
            };
            if plot.dialect == Dialect::Ltspice {
                ltspice::unsign_time(&mut plot);
            }
            let steps = ltspice::split_steps(plot);
            // A stepped plot's warnings are about where its data end: in
            // its last step.
            let last = index + steps.len().saturating_sub(1);
            warnings.extend(warning.into_iter().map(|w| w.in_plot(last)));
            plots.extend(steps);
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

    /// Whether the plot's values are complex (`Flags: complex`).
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
