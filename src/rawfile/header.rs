//! The header of a raw file: its plots, their variables and flags, and
//! where each plot's data begins and ends.

use super::error::{Position, RawError};
use super::types::{Dialect, Encoding, Flags, Plot, Variable};

pub(super) struct Cursor<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) pos: usize,
    /// 1-based line of `pos`; `None` once binary data made lines meaningless.
    pub(super) line: Option<usize>,
}

impl<'a> Cursor<'a> {
    pub(super) fn at(&self) -> Position {
        Position {
            line: self.line,
            offset: self.pos,
        }
    }

    pub(super) fn at_end(&self) -> bool {
        self.pos >= self.bytes.len()
    }

    pub(super) fn rest(&self) -> &'a [u8] {
        &self.bytes[self.pos.min(self.bytes.len())..]
    }

    /// The next line without its terminator (`\n`, `\r\n`).
    pub(super) fn next_line(&mut self) -> Option<&'a [u8]> {
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

    pub(super) fn skip_blank_lines(&mut self) {
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

// ---------------------------------------------------------------------------
// Header

#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum DataKind {
    Binary,
    Ascii,
}

pub(super) struct Header {
    pub(super) plot: Plot,
    pub(super) nvars: usize,
    /// Per vector: how many values it has (differs from the point count only
    /// through `dims=` in an unpadded plot).
    pub(super) lengths: Vec<usize>,
    pub(super) data: DataKind,
}

/// `line` starts with `key` (ASCII case-insensitive); returns the rest, trimmed.
pub(super) fn field<'a>(line: &'a [u8], key: &str) -> Option<&'a [u8]> {
    let k = key.as_bytes();
    if line.len() >= k.len() && line[..k.len()].eq_ignore_ascii_case(k) {
        Some(line[k.len()..].trim_ascii())
    } else {
        None
    }
}

pub(super) fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

pub(super) fn parse_count(
    value: &[u8],
    at: Position,
    field: &'static str,
) -> Result<usize, RawError> {
    std::str::from_utf8(value)
        .ok()
        .and_then(|s| s.trim().parse::<usize>().ok())
        .ok_or_else(|| RawError::BadCount {
            at,
            field,
            text: text(value),
        })
}

pub(super) fn parse_header(
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
    // Header lines only LTspice writes.
    let mut ltspice_lines = false;
    let mut command_names_ltspice = false;

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
            command_names_ltspice |= v.windows(7).any(|w| w.eq_ignore_ascii_case(b"ltspice"));
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
            let ltspice_flags = ["forward", "stepped", "fastaccess", "double"]
                .iter()
                .any(|f| flags.has(f));
            let dialect = if command_names_ltspice || ltspice_lines || ltspice_flags {
                Dialect::Ltspice
            } else {
                Dialect::Ngspice
            };
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
                    dialect,
                    encoding: Encoding::Utf8,
                    step: None,
                    columns: Vec::new(),
                },
                nvars,
                lengths,
                data,
            });
        } else if looks_like_header_line(line) {
            ltspice_lines |=
                field(line, "Offset:").is_some() || field(line, "Backannotation:").is_some();
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
pub(super) fn looks_like_header_line(line: &[u8]) -> bool {
    match line.iter().position(|&b| b == b':') {
        Some(n) if n > 0 && n <= 32 => line[..n]
            .iter()
            .all(|&b| b.is_ascii_alphabetic() || b == b' ' || b == b'.'),
        _ => false,
    }
}

pub(super) fn parse_flags(v: &[u8]) -> Flags {
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

pub(super) fn parse_variables(
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
pub(super) fn vector_length(v: &Variable, npoints: usize) -> usize {
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
pub(super) fn real_in_complex_plot(v: &Variable, index: usize) -> bool {
    index == 0 && v.kind.eq_ignore_ascii_case("frequency")
}

/// For declared-0 plots: whether what follows is the next plot's header
/// rather than data (a legitimately empty plot).
pub(super) fn next_is_header(rest: &[u8]) -> bool {
    let head = &rest[..rest.len().min(16)];
    let starts = |k: &[u8]| head.len() >= k.len() && head[..k.len()].eq_ignore_ascii_case(k);
    starts(b"Title:") || starts(b"Plotname:") || starts(b"Date:")
}

/// Whether the first value of each of the first `points` rows of `row`
/// bytes (the scale: time, frequency) is finite and never decreases.
pub(super) fn scale_increases(data: &[u8], row: usize, points: usize) -> bool {
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
pub(super) struct Sections {
    /// Bytes before the last start of the data (dropped points and the
    /// re-declarations).
    pub(super) skip: usize,
    /// Whole points after it, up to the next plot's header or the end.
    pub(super) points: usize,
    /// Bytes of a partial point after them (only at the end of the file).
    pub(super) tail: usize,
    pub(super) restarts: usize,
    pub(super) dropped: usize,
}

/// Walks `rest` (a plot's binary data, `row` bytes a point) one point at a
/// time: a re-declaration of `vars` and `Binary:` at a point boundary
/// starts the data over; the next plot's header or the end of the file
/// ends them.
pub(super) fn sections(rest: &[u8], row: usize, vars: &[Variable]) -> Sections {
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
pub(super) fn redeclaration(bytes: &[u8], vars: &[Variable]) -> Option<usize> {
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

/// The f64 at `off` in a cell of at least `off + 8` bytes.
#[inline]
pub(super) fn le_f64(cell: &[u8], off: usize) -> f64 {
    let mut b = [0u8; 8];
    if let Some(src) = cell.get(off..off + 8) {
        b.copy_from_slice(src);
    }
    f64::from_le_bytes(b)
}
