//! Finding the plots of a raw file on disk without loading it: each
//! plot's header is read and parsed on its own, and where its binary data
//! start and end follows from the header's counts and the file's size.
//! The reader from disk (the `direct` module) reads the data found here
//! straight into columns and the streaming CSV writer (the `stream`
//! module) turns them into CSV, both a block of points at a time.
//!
//! Only files whose every plot the in-memory parser
//! ([`super::types::RawFile::parse`]) would read as declared are located: ngspice's
//! binary plots, padded (or with every vector full length), each ending
//! where its `No. Points:` says, at the end of the file or exactly at the
//! next plot's header; or cut short (a killed run, the last plot). For any
//! other file (ASCII, LTspice's dialect, unpadded vectors, the irregular
//! data of `.options interp`, a `Flags:` line the data contradict, a
//! header this reader rejects) [`locate`] returns `None` and the caller
//! reads the file whole, which copes with all of them and names what is
//! wrong. So the plots located here are exactly those the parser gives.

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::ops::Range;

use super::header::{Cursor, DataKind, Header, next_is_header, parse_header};
use super::ltspice;
use super::types::{Dialect, RawWarning};

/// A first read of a plot's header; a longer one is read again whole up
/// to [`HEADER_LIMIT`].
const HEADER_FIRST: usize = 64 << 10;

/// A header and its `Binary:` line fit in this; a longer one is not
/// something ngspice writes (the in-memory reader says what is wrong).
const HEADER_LIMIT: usize = 1 << 20;

/// Bytes read at a time from a plot's data.
pub(super) const BLOCK_BYTES: usize = 256 << 10;

/// One plot's header and where its data are.
pub(super) struct Located {
    pub(super) header: Header,
    /// Byte offset of the first point.
    pub(super) data: u64,
    /// Whole points there.
    pub(super) points: u64,
    /// The point count fell short of `No. Points:` (or it was 0 and data
    /// followed): a killed run.
    pub(super) truncated: bool,
}

impl Located {
    /// Bytes a point: 8 a value, 16 in a complex plot.
    pub(super) fn row(&self) -> usize {
        let width = if self.header.plot.flags.complex {
            16
        } else {
            8
        };
        self.header.nvars * width
    }

    /// The warning the in-memory reader gives for this plot, the `index`th
    /// of its file: a killed run's cut data.
    pub(super) fn warning(&self, index: usize) -> Option<RawWarning> {
        self.truncated.then(|| RawWarning::Truncated {
            plot: index,
            declared: self.header.plot.declared_points,
            read: self.points as usize,
            offset: (self.data + self.points * self.row() as u64) as usize,
        })
    }

    /// The plot's points `points` (all of them: `0..self.points`) a block
    /// at a time (whole points, at most [`BLOCK_BYTES`] unless one point
    /// is larger), read into `buf`.
    pub(super) fn blocks<'a>(
        &self,
        file: &'a File,
        buf: &'a mut Vec<u8>,
        points: Range<usize>,
    ) -> Blocks<'a> {
        let row = self.row();
        let per_block = (BLOCK_BYTES / row).max(1);
        buf.resize(per_block * row, 0);
        Blocks {
            file,
            buf,
            row,
            offset: self.data + (points.start * row) as u64,
            first: 0,
            left: points.len(),
        }
    }
}

/// A run of a plot's points read a block at a time into one buffer, each
/// block from its own offset: several can read one file at once.
pub(super) struct Blocks<'a> {
    file: &'a File,
    buf: &'a mut Vec<u8>,
    /// Bytes a point.
    row: usize,
    /// Where the next block starts in the file.
    offset: u64,
    /// Index of the next block's first point, from the run's first.
    first: usize,
    /// Points not read yet.
    left: usize,
}

impl Blocks<'_> {
    /// The next block and the index of its first point (from the run's
    /// first); `None` after the last.
    pub(super) fn next_block(&mut self) -> io::Result<Option<(&[u8], usize)>> {
        if self.left == 0 {
            return Ok(None);
        }
        let rows = self.left.min(self.buf.len() / self.row);
        let block = &mut self.buf[..rows * self.row];
        read_exact_at(self.file, block, self.offset)?;
        let first = self.first;
        self.offset += (rows * self.row) as u64;
        self.first += rows;
        self.left -= rows;
        Ok(Some((block, first)))
    }
}

/// Whether [`read_exact_at`] leaves the file's position alone, so that
/// several threads can read one file.
pub(super) const POSITIONAL_READS: bool = cfg!(unix);

/// Fills `buf` from `offset` in `file`.
#[cfg(unix)]
fn read_exact_at(file: &File, buf: &mut [u8], offset: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, buf, offset)
}

/// Fills `buf` from `offset` in `file` (moving its position: one reader at
/// a time, see [`POSITIONAL_READS`]).
#[cfg(not(unix))]
fn read_exact_at(mut file: &File, buf: &mut [u8], offset: u64) -> io::Result<()> {
    file.seek(SeekFrom::Start(offset))?;
    file.read_exact(buf)
}

/// Every plot of the file (of `len` bytes) with its data, or `None` when
/// the file is not one located here (see the module overview).
pub(super) fn locate(file: &mut File, len: u64) -> io::Result<Option<Vec<Located>>> {
    let mut plots = Vec::new();
    let (mut title, mut date) = (String::new(), String::new());
    let mut pos = 0u64;
    let mut buf = Vec::new();
    loop {
        let Some(header) = next_header(file, len, &mut pos, &mut buf, &mut title, &mut date)?
        else {
            return Ok(None);
        };
        let Some(header) = header else {
            // Only blanks to the end of the file.
            return Ok(Some(plots));
        };
        let (located, next) = match place(file, len, pos, header)? {
            Some(placed) => placed,
            None => return Ok(None),
        };
        plots.push(located);
        match next {
            Some(next) => pos = next,
            // A cut plot runs to the end of the file.
            None => return Ok(Some(plots)),
        }
    }
}

/// The header of the plot at `pos` (blanks skipped), with `pos` moved to
/// its first data byte: `Some(None)` when only blanks are left, `None`
/// when it is not one to locate.
fn next_header(
    file: &mut File,
    len: u64,
    pos: &mut u64,
    buf: &mut Vec<u8>,
    title: &mut String,
    date: &mut String,
) -> io::Result<Option<Option<Header>>> {
    let mut limit = HEADER_FIRST;
    loop {
        read_at(file, *pos, limit as u64, buf)?;
        let whole = *pos + buf.len() as u64 == len;
        let mut cur = Cursor {
            bytes: buf,
            pos: 0,
            line: Some(1),
        };
        ltspice::skip_blank(&mut cur);
        if cur.at_end() {
            // Blanks longer than a header: not an ngspice file.
            return Ok(whole.then_some(None));
        }
        if !matches!(ltspice::utf16_start(cur.rest(), cur.at()), Ok(None)) {
            // LTspice's UTF-16 text (or a big-endian mark to refuse).
            return Ok(None);
        }
        if !has_data_line(cur.rest(), whole) {
            if whole || limit >= HEADER_LIMIT {
                return Ok(None);
            }
            limit = HEADER_LIMIT;
            continue;
        }
        let Ok(header) = parse_header(&mut cur, title, date) else {
            return Ok(None);
        };
        *pos += cur.pos as u64;
        return Ok(Some(Some(header)));
    }
}

/// Where the data of `header` (starting at `data`) end: the plot and the
/// offset of the next plot (`None` after a cut plot, which ends the file),
/// or `None` when the in-memory reader would read them otherwise.
fn place(
    file: &mut File,
    len: u64,
    data: u64,
    header: Header,
) -> io::Result<Option<(Located, Option<u64>)>> {
    let plot = &header.plot;
    let declared = plot.declared_points as u64;
    let uniform = plot.flags.padded || header.lengths.iter().all(|&l| l == plot.declared_points);
    if !matches!(header.data, DataKind::Binary) || plot.dialect != Dialect::Ngspice || !uniform {
        return Ok(None);
    }
    let complex = plot.flags.complex;
    let row = (header.nvars * if complex { 16 } else { 8 }) as u64;
    let available = len - data;
    let mut located = Located {
        header,
        data,
        points: available / row,
        truncated: true,
    };
    if declared == 0 {
        // A plot with no points, or a killed run whose data end the file.
        if available == 0 || header_at(file, data, false)? {
            located.points = 0;
            located.truncated = false;
            return Ok(Some((located, Some(data))));
        }
        return Ok(Some((located, None)));
    }
    let Some(end) = declared.checked_mul(row).and_then(|n| n.checked_add(data)) else {
        return Ok(None);
    };
    if end <= len {
        // Anything but the end or the next header (without blanks) there:
        // ngspice's interpolation, or garbage the parser reports.
        if end == len || header_at(file, end, false)? {
            located.points = declared;
            located.truncated = false;
            return Ok(Some((located, Some(end))));
        }
        return Ok(None);
    }
    // Cut short. Complex-flagged data that would end right there as real
    // values: the parser says the `Flags:` line is wrong.
    if complex {
        let theirs = data + declared * row / 2;
        if theirs == len || (theirs < len && header_at(file, theirs, true)?) {
            return Ok(None);
        }
    }
    Ok(Some((located, None)))
}

/// Whether a plot header starts at `offset` (after blanks with `trim`;
/// blanks up to the end of what is read count as a header, to be safe).
fn header_at(file: &mut File, offset: u64, trim: bool) -> io::Result<bool> {
    let mut head = Vec::new();
    read_at(file, offset, 64, &mut head)?;
    if !trim {
        return Ok(next_is_header(&head));
    }
    let trimmed = head.trim_ascii_start();
    Ok(next_is_header(trimmed) || (trimmed.is_empty() && head.len() == 64))
}

/// Whether `bytes` hold a whole `Binary:` or `Values:` line (its newline
/// in `bytes`, or `bytes` the rest of the file).
fn has_data_line(bytes: &[u8], whole: bool) -> bool {
    let mut lines = bytes.split(|&b| b == b'\n').peekable();
    while let Some(line) = lines.next() {
        let terminated = lines.peek().is_some();
        let is_data = [&b"Binary:"[..], b"Values:"]
            .iter()
            .any(|k| line.len() >= k.len() && line[..k.len()].eq_ignore_ascii_case(k));
        if is_data {
            return terminated || whole;
        }
    }
    false
}

/// Up to `limit` bytes from `offset` into `buf` (fewer at the end of the
/// file).
fn read_at(file: &mut File, offset: u64, limit: u64, buf: &mut Vec<u8>) -> io::Result<()> {
    buf.clear();
    file.seek(SeekFrom::Start(offset))?;
    file.by_ref().take(limit).read_to_end(buf)?;
    Ok(())
}
