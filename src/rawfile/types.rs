//! The types a raw file is read into: the file ([`RawFile`]), its plots
//! ([`Plot`]) with their header fields, flags, variables and steps, the
//! values of one vector ([`Vector`]) and what the reader recovered from
//! ([`RawWarning`]); the size limit of a file read whole
//! ([`MAX_LOADED_BYTES`]).

use std::fmt;

/// The largest raw file [`RawFile::read`] loads into memory: 4 GiB. The
/// values take about as much memory as the file.
pub const MAX_LOADED_BYTES: u64 = 4 << 30;

/// A complex value of an AC (or other complex) plot.
pub type Complex64 = num_complex::Complex<f64>;

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
    pub(super) columns: Vec<Column>,
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
pub(super) enum Column {
    Real(Vec<f64>),
    Complex(Vec<Complex64>),
}

impl Column {
    pub(super) fn as_vector(&self) -> Vector<'_> {
        match self {
            Column::Real(v) => Vector::Real(v),
            Column::Complex(v) => Vector::Complex(v),
        }
    }

    pub(super) fn len(&self) -> usize {
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
    pub(super) fn in_plot(mut self, index: usize) -> RawWarning {
        match &mut self {
            RawWarning::Truncated { plot, .. }
            | RawWarning::Restarted { plot, .. }
            | RawWarning::ExtraPoints { plot, .. }
            | RawWarning::TrailingData { plot, .. } => *plot = index,
        }
        self
    }

    /// The warning with its byte offset (if any) mapped by `f`.
    pub(super) fn map_offset(mut self, f: impl Fn(usize) -> usize) -> RawWarning {
        match &mut self {
            RawWarning::Truncated { offset, .. } | RawWarning::TrailingData { offset, .. } => {
                *offset = f(*offset)
            }
            RawWarning::Restarted { .. } | RawWarning::ExtraPoints { .. } => {}
        }
        self
    }
}

impl RawFile {
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
