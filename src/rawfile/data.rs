//! The data of a raw file: binary (padded or not) and ASCII values into
//! columns, with what a killed or restarted run leaves; the transposition
//! of binary points into columns, which the reader from disk (the
//! `direct` module) shares.

use super::error::RawError;
use super::header::{
    Cursor, Header, Sections, next_is_header, real_in_complex_plot, scale_increases, sections, text,
};
use super::types::{Column, Complex64, Plot, RawWarning, Variable};

pub(super) fn read_binary(
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
    let shape = Shape::of(&plot, nvars, &lengths);
    let rest = cur.rest();
    let start = cur.pos;
    if shape.open_ended && (rest.is_empty() || next_is_header(rest)) {
        // A plot that legitimately has no points (or a run that failed
        // before its first point): nothing to read, nothing lost.
        plot.columns = empty_columns(&plot);
        cur.line = None;
        return Ok((plot, Vec::new()));
    }
    check_flags(cur, rest, &shape)?;

    let interpolated = interpolated_sections(rest, &shape, &plot.variables);
    let irregular = interpolated.is_some();
    let sections = interpolated.unwrap_or_default();
    let extra = sections.points.saturating_sub(shape.declared);
    let mut warnings = Vec::new();
    if sections.restarts > 0 {
        warnings.push(RawWarning::Restarted {
            plot: index,
            restarts: sections.restarts,
            dropped: sections.dropped,
        });
    }
    let (columns, read, used) = if shape.uniform {
        let row = shape.row;
        // Whole points the bytes hold, whatever the header claims.
        let whole = if shape.open_ended {
            rest.len() / row
        } else if irregular {
            sections.points
        } else {
            shape.declared.min(rest.len() / row)
        };
        let skip = sections.skip;
        let data = &rest[skip..skip + whole * row];
        let lens: Vec<usize> = if shape.open_ended || extra > 0 {
            vec![whole; nvars]
        } else {
            lengths.iter().map(|&l| l.min(whole)).collect()
        };
        let columns = read_rows(data, &plot, &lens, &shape);
        (columns, whole, skip + whole * row)
    } else {
        read_binary_unpadded(rest, &plot, &lengths, shape.width)
    };
    plot.columns = columns;
    cur.pos = start + used + sections.tail;
    cur.line = None;
    warnings.extend(count_warning(cur, &shape, index, extra, read));
    Ok((plot, warnings))
}

/// The layout of a binary plot's data, as its header declares it.
struct Shape {
    /// Variables a point.
    nvars: usize,
    /// Whether the values are complex (16 bytes) or real (8 bytes).
    complex: bool,
    /// Bytes a value.
    width: usize,
    /// The points the header declares; 0 for a run still writing.
    declared: usize,
    /// Bytes a point, all variables.
    row: usize,
    /// Every point has every variable: padded, or all vectors full length.
    uniform: bool,
    /// No point count declared: read what is there.
    open_ended: bool,
}

impl Shape {
    /// The shape of `plot`'s data, with `nvars` variables of `lengths`
    /// points each.
    fn of(plot: &Plot, nvars: usize, lengths: &[usize]) -> Shape {
        let complex = plot.flags.complex;
        let width = if complex { 16 } else { 8 };
        let declared = plot.declared_points;
        Shape {
            nvars,
            complex,
            width,
            declared,
            row: nvars * width,
            uniform: plot.flags.padded || lengths.iter().all(|&l| l == declared),
            open_ended: declared == 0,
        }
    }
}

/// An error for data that end exactly where the other kind of value would
/// put them: the `Flags:` line is wrong (8 bytes a value for real, 16 for
/// complex).
fn check_flags(cur: &Cursor<'_>, rest: &[u8], shape: &Shape) -> Result<(), RawError> {
    let Shape {
        nvars,
        complex,
        declared,
        row,
        ..
    } = *shape;
    if !(shape.uniform && !shape.open_ended && declared > 0) {
        return Ok(());
    }
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
    Ok(())
}

/// The sections of data that do not end where the header says, at the end
/// of the file or at the next plot's header: a file that went through
/// `.options interp`, walked point by point (restarts, extra points).
/// `None` for data read as declared.
fn interpolated_sections(rest: &[u8], shape: &Shape, variables: &[Variable]) -> Option<Sections> {
    let Shape { declared, row, .. } = *shape;
    let overrun = shape.uniform
        && !shape.open_ended
        && row > 0
        && declared
            .checked_mul(row)
            .is_some_and(|end| rest.len() > end && !next_is_header(&rest[end..]));
    if !overrun {
        return None;
    }
    // Less than a whole point past the declared ones, and no restart:
    // not ngspice's doing; the garbage is reported where it starts.
    Some(sections(rest, row, variables))
        .filter(|s| s.restarts > 0 || s.points > declared)
        .filter(|s| s.points > 0)
}

/// The columns of whole points `data` (`shape.row` bytes each), `lens`
/// values in each column.
fn read_rows(data: &[u8], plot: &Plot, lens: &[usize], shape: &Shape) -> Vec<Column> {
    if !shape.complex {
        let mut cols: Vec<Vec<f64>> = lens.iter().map(|&l| vec![0.0; l]).collect();
        let mut slices: Vec<&mut [f64]> = cols.iter_mut().map(Vec::as_mut_slice).collect();
        transpose_real(data, shape.row, 0, &mut slices);
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
        transpose_complex(data, shape.row, 0, &mut cols);
        cols
    }
}

/// Points at a time in [`transpose_real`]'s tiles.
const TILE: usize = 4;

/// The points in `block` (`row` bytes each, 8 a value; the first is point
/// `first` of `columns`) into `columns`, a tile of [`TILE`] points at a
/// time: each column gets its tile's values in one run, read from a few
/// hundred bytes of the block. (Point by point, a value to each column in
/// turn, measured 1.7× slower; column by column over the whole block, 3×.)
pub(super) fn transpose_real(block: &[u8], row: usize, first: usize, columns: &mut [&mut [f64]]) {
    let whole = block.len() / (row * TILE) * (row * TILE);
    let (tiles, rest) = block.split_at(whole);
    for (t, tile) in tiles.chunks_exact(row * TILE).enumerate() {
        let at = first + t * TILE;
        for (j, column) in columns.iter_mut().enumerate() {
            let Some(dst) = column
                .get_mut(at..)
                .and_then(|d| d.first_chunk_mut::<TILE>())
            else {
                // A vector shorter than the plot (`dims=`): one at a time.
                for (i, point) in tile.chunks_exact(row).enumerate() {
                    if let (Some(d), Some(cell)) = (column.get_mut(at + i), cell_at(point, j)) {
                        *d = f64::from_le_bytes(*cell);
                    }
                }
                continue;
            };
            for (i, d) in dst.iter_mut().enumerate() {
                if let Some(cell) = tile.get(i * row..).and_then(|p| cell_at(p, j)) {
                    *d = f64::from_le_bytes(*cell);
                }
            }
        }
    }
    let at = first + tiles.len() / row;
    for (i, point) in rest.chunks_exact(row).enumerate() {
        for (j, column) in columns.iter_mut().enumerate() {
            if let (Some(d), Some(cell)) = (column.get_mut(at + i), cell_at(point, j)) {
                *d = f64::from_le_bytes(*cell);
            }
        }
    }
}

/// The 8 bytes of value `j` of a point.
#[inline]
fn cell_at(point: &[u8], j: usize) -> Option<&[u8; 8]> {
    point.get(j * 8..).and_then(<[u8]>::first_chunk::<8>)
}

/// As [`transpose_real`] for a complex plot: 16 bytes a value, `(re, im)`;
/// a real column (the frequency scale) keeps the real part.
pub(super) fn transpose_complex(block: &[u8], row: usize, first: usize, columns: &mut [Column]) {
    for (i, point) in block.chunks_exact(row).enumerate() {
        for (column, cell) in columns.iter_mut().zip(point.chunks_exact(16)) {
            let Some((re, im)) = cell.split_first_chunk::<8>() else {
                continue;
            };
            let re = f64::from_le_bytes(*re);
            match column {
                Column::Real(v) => {
                    if let Some(d) = v.get_mut(first + i) {
                        *d = re;
                    }
                }
                Column::Complex(v) => {
                    if let (Some(d), Some(im)) = (v.get_mut(first + i), im.first_chunk::<8>()) {
                        *d = Complex64::new(re, f64::from_le_bytes(*im));
                    }
                }
            }
        }
    }
}

/// The warning for a plot of `read` points where the header declares
/// another count: more (interpolation's `extra` points), or fewer (the run
/// was cut: only the last plot of a file can be, so `cur` moves to the end
/// past the partial point).
fn count_warning(
    cur: &mut Cursor<'_>,
    shape: &Shape,
    index: usize,
    extra: usize,
    read: usize,
) -> Option<RawWarning> {
    let declared = shape.declared;
    if extra > 0 {
        Some(RawWarning::ExtraPoints {
            plot: index,
            declared,
            read,
        })
    } else if shape.open_ended || read < declared {
        let warning = RawWarning::Truncated {
            plot: index,
            declared,
            read,
            offset: cur.pos,
        };
        // Only the last plot of a file can be cut: the rest is the partial point.
        cur.pos = cur.bytes.len();
        Some(warning)
    } else {
        None
    }
}

pub(super) fn empty_columns(plot: &Plot) -> Vec<Column> {
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
pub(super) fn read_binary_unpadded(
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

#[inline]
pub(super) fn f64_at(bytes: &[u8], off: usize) -> f64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(&bytes[off..off + 8]);
    f64::from_le_bytes(b)
}

/// Tokens of an ASCII data section, tracking lines for error messages.
pub(super) struct Tokens<'a, 'c> {
    cur: &'c mut Cursor<'a>,
}

impl<'a> Tokens<'a, '_> {
    pub(super) fn skip_ws(&mut self) {
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
    pub(super) fn token(&mut self) -> (&'a [u8], bool) {
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

    pub(super) fn peek(&self) -> Option<u8> {
        self.cur.bytes.get(self.cur.pos).copied()
    }
}

pub(super) enum Got<T> {
    Value(T),
    /// The input ended (or was cut) here.
    End,
}

pub(super) fn parse_f64(tok: &[u8]) -> Option<f64> {
    std::str::from_utf8(tok).ok()?.parse::<f64>().ok()
}

impl Tokens<'_, '_> {
    pub(super) fn real(&mut self) -> Result<Got<f64>, RawError> {
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

    pub(super) fn complex(&mut self) -> Result<Got<(f64, f64)>, RawError> {
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

pub(super) fn read_ascii(
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

pub(super) fn truncate(c: &mut Column, len: usize) {
    match c {
        Column::Real(v) => v.truncate(len),
        Column::Complex(v) => v.truncate(len),
    }
}
