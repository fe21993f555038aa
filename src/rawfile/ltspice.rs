//! LTspice's dialect: UTF-16 text, `f32` values, the FastAccess layout,
//! the sign LTspice leaves on some time stamps, and `.step` runs written
//! as one plot.

use super::data::read_ascii;
use super::error::{Position, RawError};
use super::header::{
    Cursor, DataKind, Header, field, le_f64, next_is_header, parse_header, real_in_complex_plot,
};
use super::types::{Column, Complex64, Dialect, Encoding, Plot, RawWarning, Step};

// ---------------------------------------------------------------------------
// UTF-16 text

/// Whether a plot header in UTF-16 little-endian starts `rest`: `Some`
/// with the length of its byte order mark (0 or 2). LTspice writes no
/// mark, so the text is told by its zero high bytes (`T\0i\0...`).
pub(super) fn utf16_start(rest: &[u8], at: Position) -> Result<Option<usize>, RawError> {
    if rest.starts_with(&[0xff, 0xfe]) {
        return Ok(Some(2));
    }
    if rest.starts_with(&[0xfe, 0xff]) {
        return Err(RawError::Ltspice {
            what: "UTF-16 big-endian byte order mark",
            at,
        });
    }
    Ok((rest.len() >= 4 && rest[0] != 0 && rest[1] == 0 && rest[3] == 0).then_some(0))
}

/// UTF-16 little-endian text turned into UTF-8, with what it takes to find
/// the input offset of any offset in the UTF-8 text.
pub(super) struct Transcoded {
    pub(super) text: Vec<u8>,
    /// `(text offset, input offset)` pairs: at the start and after every
    /// character that is not ASCII. Between two marks every character is
    /// one UTF-8 byte for two input bytes.
    marks: Vec<(usize, usize)>,
}

impl Transcoded {
    /// The input offset of `offset` in the text.
    pub(super) fn input_offset(&self, offset: usize) -> usize {
        let i = self
            .marks
            .partition_point(|&(t, _)| t <= offset)
            .saturating_sub(1);
        let (t, o) = self.marks[i];
        let here = o + 2 * offset.saturating_sub(t);
        // Inside a non-ASCII character: its end.
        match self.marks.get(i + 1) {
            Some(&(_, next)) => here.min(next),
            None => here,
        }
    }

    /// A position in the text as a position in the input, which starts at
    /// `base`.
    pub(super) fn position(&self, p: Position, base: usize) -> Position {
        Position {
            line: p.line,
            offset: base + self.input_offset(p.offset),
        }
    }
}

/// Whether `line` (a line of text, without its `\n`) starts the data.
fn is_data_line(line: &[u8]) -> bool {
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    field(line, "Binary:").is_some() || field(line, "Values:").is_some()
}

/// Decodes UTF-16 little-endian `input` to UTF-8: with `header_only`, up
/// to and with the `Binary:` or `Values:` line (what follows `Binary:` is
/// not text), else all of it. Unpaired surrogates and an odd last byte
/// become U+FFFD.
pub(super) fn transcode(input: &[u8], header_only: bool) -> Transcoded {
    let capacity = if header_only {
        input.len().min(1 << 16) / 2
    } else {
        input.len() / 2
    };
    let mut text = Vec::with_capacity(capacity);
    let mut marks = vec![(0, 0)];
    let mut pos = 0;
    let mut line_start = 0;
    let unit_at = |p: usize| {
        input
            .get(p..p + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
    };
    while let Some(unit) = unit_at(pos) {
        if unit < 0x80 {
            text.push(unit as u8);
            pos += 2;
            if unit == u16::from(b'\n') {
                if header_only && is_data_line(&text[line_start..text.len() - 1]) {
                    break;
                }
                line_start = text.len();
            }
            continue;
        }
        let units = [Some(unit), unit_at(pos + 2)];
        let (c, used) = match char::decode_utf16(units.into_iter().flatten()).next() {
            Some(Ok(c)) => (c, c.len_utf16()),
            _ => (char::REPLACEMENT_CHARACTER, 1),
        };
        let mut buf = [0u8; 4];
        text.extend_from_slice(c.encode_utf8(&mut buf).as_bytes());
        pos += 2 * used;
        marks.push((text.len(), pos));
    }
    if !header_only && pos < input.len() {
        // An odd last byte.
        text.extend_from_slice("\u{fffd}".as_bytes());
        marks.push((text.len(), input.len()));
    }
    Transcoded { text, marks }
}

/// Whether `bytes` start (after blanks) with a plot header, in UTF-8 or
/// UTF-16.
pub(super) fn header_follows(bytes: &[u8]) -> bool {
    let at = Position {
        line: None,
        offset: 0,
    };
    match utf16_start(bytes, at) {
        Ok(Some(bom)) => {
            let head = &bytes[bom..bytes.len().min(bom + 64)];
            next_is_header(transcode(head, false).text.trim_ascii_start())
        }
        Ok(None) => next_is_header(bytes.trim_ascii_start()),
        Err(_) => false,
    }
}

/// Skips blank lines in UTF-8 or UTF-16 (`\n\0`, ` \0`...).
pub(super) fn skip_blank(cur: &mut Cursor<'_>) {
    loop {
        match cur.rest() {
            [b @ (b' ' | b'\t' | b'\r' | b'\n'), 0, ..] => {
                if *b == b'\n' {
                    if let Some(l) = cur.line.as_mut() {
                        *l += 1;
                    }
                }
                cur.pos += 2;
            }
            [b' ' | b'\t' | b'\r' | b'\n', ..] => cur.skip_blank_lines(),
            _ => break,
        }
    }
}

/// Reads one plot whose header is UTF-16 (after a byte order mark of
/// `bom` bytes): the header and ASCII values through UTF-8 text, binary
/// values from the input.
pub(super) fn read_utf16_plot(
    cur: &mut Cursor<'_>,
    bom: usize,
    title: &mut String,
    date: &mut String,
    index: usize,
) -> Result<(Plot, Vec<RawWarning>), RawError> {
    let start = cur.pos + bom;
    let header_text = transcode(&cur.bytes[start..], true);
    let mut text_cur = Cursor {
        bytes: &header_text.text,
        pos: 0,
        line: cur.line,
    };
    let mut header = parse_header(&mut text_cur, title, date)
        .map_err(|e| e.map_position(|p| header_text.position(p, start)))?;
    header.plot.encoding = Encoding::Utf16Le;
    header.plot.dialect = Dialect::Ltspice;
    cur.pos = start + header_text.input_offset(text_cur.pos);
    cur.line = text_cur.line;
    match header.data {
        DataKind::Binary => read_binary(cur, header, index),
        DataKind::Ascii => {
            let base = cur.pos;
            let values = transcode(cur.rest(), false);
            let mut text_cur = Cursor {
                bytes: &values.text,
                pos: 0,
                line: cur.line,
            };
            let (plot, warnings) = read_ascii(&mut text_cur, header, index)
                .map_err(|e| e.map_position(|p| values.position(p, base)))?;
            cur.pos = base + values.input_offset(text_cur.pos);
            cur.line = text_cur.line;
            let warnings = warnings
                .into_iter()
                .map(|w| w.map_offset(|o| base + values.input_offset(o)))
                .collect();
            Ok((plot, warnings))
        }
    }
}

// ---------------------------------------------------------------------------
// Binary values

/// How one value of a vector is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Cell {
    F64,
    F32,
    /// `(re, im)`, two `f64`.
    Complex,
}

impl Cell {
    fn width(self) -> usize {
        match self {
            Cell::F64 => 8,
            Cell::F32 => 4,
            Cell::Complex => 16,
        }
    }
}

/// Each vector's storage: every value complex in a complex plot; else the
/// first vector (the scale, or an operating point's first value) an
/// `f64`, the others `f32` unless `Flags:` says `double`.
fn cells(plot: &Plot) -> Vec<Cell> {
    let double = plot.flags.has("double");
    (0..plot.variables.len())
        .map(|j| {
            if plot.flags.complex {
                Cell::Complex
            } else if double || j == 0 {
                Cell::F64
            } else {
                Cell::F32
            }
        })
        .collect()
}

fn columns_of(plot: &Plot, len: usize) -> Vec<Column> {
    plot.variables
        .iter()
        .enumerate()
        .map(|(j, v)| {
            if plot.flags.complex && !real_in_complex_plot(v, j) {
                Column::Complex(vec![Complex64::new(0.0, 0.0); len])
            } else {
                Column::Real(vec![0.0; len])
            }
        })
        .collect()
}

/// Stores the value in `bytes` (one cell) at `i` of `col`. A complex
/// plot's frequency scale keeps the real part (LTspice writes 0 as its
/// imaginary part).
#[inline]
fn store(col: &mut Column, i: usize, cell: Cell, bytes: &[u8]) {
    match col {
        Column::Real(v) => {
            if let Some(d) = v.get_mut(i) {
                *d = match cell {
                    Cell::F32 => f64::from(le_f32(bytes)),
                    Cell::F64 | Cell::Complex => le_f64(bytes, 0),
                };
            }
        }
        Column::Complex(v) => {
            if let Some(d) = v.get_mut(i) {
                *d = Complex64::new(le_f64(bytes, 0), le_f64(bytes, 8));
            }
        }
    }
}

#[inline]
fn le_f32(bytes: &[u8]) -> f32 {
    let mut b = [0u8; 4];
    if let Some(src) = bytes.get(..4) {
        b.copy_from_slice(src);
    }
    f32::from_le_bytes(b)
}

/// Reads the binary values of an LTspice plot: point after point, or with
/// `fastaccess` vector after vector.
pub(super) fn read_binary(
    cur: &mut Cursor<'_>,
    header: Header,
    index: usize,
) -> Result<(Plot, Vec<RawWarning>), RawError> {
    let mut plot = header.plot;
    let cells = cells(&plot);
    let row: usize = cells.iter().map(|c| c.width()).sum();
    let declared = plot.declared_points;
    let rest = cur.rest();
    let at = cur.at();
    cur.line = None;
    let mut warnings = Vec::new();

    if declared == 0 && (rest.is_empty() || header_follows(rest)) {
        plot.columns = columns_of(&plot, 0);
        return Ok((plot, warnings));
    }
    if plot.flags.has("fastaccess") && declared > 0 {
        let need = (declared as u64).saturating_mul(row as u64);
        if need > rest.len() as u64 {
            return Err(RawError::ShortFastAccess {
                at,
                vectors: cells.len(),
                points: declared,
                expected: need,
                found: rest.len(),
            });
        }
        let mut columns = columns_of(&plot, declared);
        let mut start = 0;
        for (col, &cell) in columns.iter_mut().zip(&cells) {
            let w = cell.width();
            let block = &rest[start..start + declared * w];
            for (i, value) in block.chunks_exact(w).enumerate() {
                store(col, i, cell, value);
            }
            start += declared * w;
        }
        plot.columns = columns;
        cur.pos += start;
    } else if !plot.flags.has("fastaccess") {
        // Whole points the bytes hold, whatever the header claims.
        let fits = rest.len() / row;
        let whole = if declared == 0 {
            fits
        } else {
            declared.min(fits)
        };
        let mut columns = columns_of(&plot, whole);
        for (i, r) in rest[..whole * row].chunks_exact(row).enumerate() {
            let mut off = 0;
            for (col, &cell) in columns.iter_mut().zip(&cells) {
                let w = cell.width();
                store(col, i, cell, &r[off..off + w]);
                off += w;
            }
        }
        plot.columns = columns;
        cur.pos += whole * row;
        if declared == 0 || whole < declared {
            warnings.push(RawWarning::Truncated {
                plot: index,
                declared,
                read: whole,
                offset: cur.pos,
            });
            // Only the last plot of a file can be cut: the rest is the
            // partial point.
            cur.pos = cur.bytes.len();
            return Ok((plot, warnings));
        }
    } else {
        // FastAccess with no points declared: nothing to read.
        plot.columns = columns_of(&plot, 0);
    }
    let after = cur.rest();
    if !after.trim_ascii().is_empty() && !header_follows(after) {
        warnings.push(RawWarning::TrailingData {
            plot: index,
            declared,
            offset: cur.pos,
            bytes: after.len(),
        });
        cur.pos = cur.bytes.len();
    }
    Ok((plot, warnings))
}

// ---------------------------------------------------------------------------
// After reading

/// LTspice sets the sign bit of some time stamps (points its compression
/// kept): time is their absolute value.
pub(super) fn unsign_time(plot: &mut Plot) {
    let is_time = plot
        .variables
        .first()
        .is_some_and(|v| v.kind.eq_ignore_ascii_case("time"));
    if let (true, Some(Column::Real(t))) = (is_time, plot.columns.first_mut()) {
        for x in t.iter_mut() {
            *x = x.abs();
        }
    }
}

/// Whether a plot has a scale: all but LTspice's single-point analyses.
fn has_scale(plot: &Plot) -> bool {
    let name = plot.name.to_ascii_lowercase();
    !["operating point", "transfer function", "integrated noise"]
        .iter()
        .any(|n| name.starts_with(n))
}

/// Where each step of a stepped plot starts: wherever the scale comes
/// back to its first value, or every point when there is no scale.
fn step_starts(plot: &Plot) -> Vec<usize> {
    let n = plot.points();
    if !has_scale(plot) {
        return (0..n).collect();
    }
    let mut starts = vec![0];
    match plot.columns.first() {
        Some(Column::Real(x)) if !x.is_empty() => {
            starts.extend((1..x.len()).filter(|&k| x[k] == x[0]));
        }
        Some(Column::Complex(x)) if !x.is_empty() => {
            starts.extend((1..x.len()).filter(|&k| x[k] == x[0]));
        }
        _ => {}
    }
    starts
}

/// A stepped plot (`Flags: ... stepped`) as one plot per step (see
/// [`Step`]); any other plot as it is.
pub(super) fn split_steps(mut plot: Plot) -> Vec<Plot> {
    if !plot.flags.has("stepped") {
        return vec![plot];
    }
    let starts = step_starts(&plot);
    if starts.len() <= 1 {
        plot.step = Some(Step {
            index: 0,
            count: 1,
            first_point: 0,
        });
        return vec![plot];
    }
    let count = starts.len();
    let mut columns = std::mem::take(&mut plot.columns);
    let mut steps = Vec::with_capacity(count);
    // From the last step back, each taking the tail of every column.
    for (index, &first_point) in starts.iter().enumerate().rev() {
        let mut step = Plot {
            columns: Vec::with_capacity(columns.len()),
            ..plot.clone()
        };
        for col in columns.iter_mut() {
            let tail = match col {
                Column::Real(v) => Column::Real(v.split_off(first_point.min(v.len()))),
                Column::Complex(v) => Column::Complex(v.split_off(first_point.min(v.len()))),
            };
            step.columns.push(tail);
        }
        step.step = Some(Step {
            index,
            count,
            first_point,
        });
        steps.push(step);
    }
    steps.reverse();
    steps
}
