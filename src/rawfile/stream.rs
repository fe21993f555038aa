//! One plot of a binary raw file to CSV, streamed: the file is read a
//! block of points at a time and each block written out before the next is
//! read, so memory stays bounded (a few MB) whatever the file's size.
//!
//! Streaming covers the files ngspice writes in batch mode: binary,
//! padded plots whose data end where `No. Points:` says (at the end of the
//! file or at the next plot's header), or a killed run's last plot cut
//! anywhere. Anything else (ASCII, unpadded vectors, the irregular data of
//! `.options interp`, LTspice's files) returns `None`, and the caller
//! reads the file whole with [`super::RawFile::read`], which copes with
//! all of them.
//!
//! Numbers are written by [`zmij`]: the shortest digits that read back to
//! the identical `f64` (`1.5`, `0.001`, `1e-7`, `3.3000000000000003`).

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom, Write};
use std::path::Path;

use super::export::ExportError;
use super::{
    Cursor, DataKind, Dialect, Header, RawError, RawWarning, ltspice, next_is_header, parse_header,
    real_in_complex_plot, regular_file,
};

/// A header and its `Binary:` line fit in this; a longer one is not
/// something ngspice writes (and the in-memory reader will say what is
/// wrong with it).
const HEADER_LIMIT: usize = 1 << 20;

/// Points converted per block.
const BLOCK_BYTES: usize = 1 << 20;

/// One plot's header and where its data are.
struct Located {
    header: Header,
    /// Byte offset of the first point.
    data: u64,
    /// Whole points there.
    points: u64,
    /// The point count fell short of `No. Points:` (or it was 0).
    truncated: bool,
}

/// Writes plot `index` (default: the last) of the raw file at `path` as
/// CSV to `out`, streaming. `Ok(None)`: the file is not one this streams
/// (see the module overview); nothing was written. Otherwise the
/// warnings (a killed run's cut data).
pub fn stream_csv<W: Write>(
    path: &Path,
    index: Option<usize>,
    out: W,
) -> Result<Option<Vec<RawWarning>>, ExportError> {
    let in_file = |error: RawError| RawError::InFile {
        path: path.to_path_buf(),
        error: Box::new(error),
    };
    let io = |source: std::io::Error| RawError::Io {
        path: path.to_path_buf(),
        source,
    };
    let len = regular_file(path)?.len();
    let mut file =
        BufReader::with_capacity(BLOCK_BYTES, crate::input::open_regular(path).map_err(io)?);
    let Some(plots) = locate(&mut file, len).map_err(|e| match e {
        Locate::Raw(e) => in_file(e),
        Locate::Io(e) => io(e),
    })?
    else {
        return Ok(None);
    };
    if plots.is_empty() {
        return Err(in_file(RawError::Empty).into());
    }
    let count = plots.len();
    let chosen = index.unwrap_or(count - 1);
    let Some(plot) = plots.get(chosen) else {
        return Err(ExportError::NoSuchPlot {
            index: chosen,
            count,
        });
    };
    write_plot(&mut file, plot, chosen, out, &io)
}

enum Locate {
    Raw(RawError),
    Io(std::io::Error),
}

impl From<std::io::Error> for Locate {
    fn from(e: std::io::Error) -> Self {
        Locate::Io(e)
    }
}

/// Every plot's header and data, or `None` when the file is not one to
/// stream.
fn locate(file: &mut BufReader<File>, len: u64) -> Result<Option<Vec<Located>>, Locate> {
    let mut plots = Vec::new();
    let (mut title, mut date) = (String::new(), String::new());
    let mut pos = 0u64;
    let mut buf = Vec::new();
    while pos < len {
        file.seek(SeekFrom::Start(pos))?;
        buf.clear();
        file.by_ref()
            .take(HEADER_LIMIT as u64)
            .read_to_end(&mut buf)?;
        let mut cur = Cursor {
            bytes: &buf,
            pos: 0,
            line: Some(1),
        };
        cur.skip_blank_lines();
        if cur.at_end() {
            break;
        }
        if matches!(
            ltspice::utf16_start(cur.rest(), cur.at()),
            Ok(Some(_)) | Err(_)
        ) {
            // LTspice's UTF-16 text: the in-memory reader decodes it.
            return Ok(None);
        }
        if !has_data_line(cur.rest()) {
            // No `Binary:`/`Values:` within the limit: let the full reader
            // report what is wrong.
            return Ok(None);
        }
        let header = parse_header(&mut cur, &mut title, &mut date).map_err(Locate::Raw)?;
        if !matches!(header.data, DataKind::Binary) || header.plot.dialect != Dialect::Ngspice {
            return Ok(None);
        }
        let declared = header.plot.declared_points;
        let uniform = header.plot.flags.padded || header.lengths.iter().all(|&l| l == declared);
        if !uniform {
            return Ok(None);
        }
        let width = if header.plot.flags.complex { 16 } else { 8 };
        let row = (header.nvars * width) as u64;
        let data = pos + cur.pos as u64;
        let available = (len - data).checked_div(row).unwrap_or(0);
        let claimed = declared as u64;
        // Data the size the other kind of value would have: the full
        // reader says the `Flags:` line is wrong.
        let other = (header.nvars * if header.plot.flags.complex { 8 } else { 16 }) as u64;
        if claimed > 0
            && claimed.checked_mul(other) == Some(len - data)
            && claimed.checked_mul(row) != Some(len - data)
        {
            return Ok(None);
        }
        if declared == 0 || claimed > available {
            // A killed run: its data end the file.
            plots.push(Located {
                header,
                data,
                points: available,
                truncated: true,
            });
            break;
        }
        let end = data + claimed * row;
        // What follows must be the end or the next plot's header.
        file.seek(SeekFrom::Start(end))?;
        let mut next = [0u8; 64];
        let got = read_up_to(file, &mut next)?;
        let after = next[..got].trim_ascii_start();
        if !after.is_empty() && !next_is_header(after) {
            return Ok(None);
        }
        plots.push(Located {
            header,
            data,
            points: claimed,
            truncated: false,
        });
        pos = end;
    }
    Ok(Some(plots))
}

/// Whether `bytes` hold a `Binary:` or `Values:` line.
fn has_data_line(bytes: &[u8]) -> bool {
    bytes
        .split(|&b| b == b'\n')
        .any(|l| l.starts_with(b"Binary:") || l.starts_with(b"Values:"))
}

fn read_up_to(file: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match file.read(&mut buf[got..])? {
            0 => break,
            n => got += n,
        }
    }
    Ok(got)
}

fn write_plot<W: Write>(
    file: &mut BufReader<File>,
    located: &Located,
    index: usize,
    out: W,
    io: &dyn Fn(std::io::Error) -> RawError,
) -> Result<Option<Vec<RawWarning>>, ExportError> {
    let plot = &located.header.plot;
    let complex = plot.flags.complex;
    // Which values are complex (two columns) and which real.
    let pairs: Vec<bool> = plot
        .variables
        .iter()
        .enumerate()
        .map(|(j, v)| complex && !real_in_complex_plot(v, j))
        .collect();
    let mut names = Vec::new();
    for (v, &pair) in plot.variables.iter().zip(&pairs) {
        if pair {
            names.push(format!("{}.re", v.name));
            names.push(format!("{}.im", v.name));
        } else {
            names.push(v.name.clone());
        }
    }
    let mut w = csv::Writer::from_writer(out);
    w.write_record(&names)?;
    let mut out = w
        .into_inner()
        .map_err(|e| ExportError::Write(e.into_error()))?;

    let width = if complex { 16 } else { 8 };
    let row = located.header.nvars * width;
    // Formatting, not reading, is the cost: about 15 ns a number with
    // zmij. (Splitting a block between two threads was measured slower on
    // the 2-core development machine.)
    let rows_per_block = (BLOCK_BYTES / row.max(1)).max(1);
    let mut block = vec![0u8; rows_per_block * row];
    let mut text = Vec::new();
    file.seek(SeekFrom::Start(located.data)).map_err(io)?;
    let mut left = located.points;
    while left > 0 {
        let rows = (left as usize).min(rows_per_block);
        file.read_exact(&mut block[..rows * row]).map_err(io)?;
        format_rows(&block[..rows * row], row, width, &pairs, &mut text);
        out.write_all(&text)?;
        left -= rows as u64;
    }
    out.flush()?;
    let mut warnings = Vec::new();
    if located.truncated {
        warnings.push(RawWarning::Truncated {
            plot: index,
            declared: plot.declared_points,
            read: located.points as usize,
            offset: (located.data + located.points * row as u64) as usize,
        });
    }
    Ok(Some(warnings))
}

/// Appends the CSV lines of the points in `data` (`row` bytes each) to
/// `text`.
fn format_rows(data: &[u8], row: usize, width: usize, pairs: &[bool], text: &mut Vec<u8>) {
    text.clear();
    text.reserve(data.len() / 8 * 24);
    let mut digits = zmij::Buffer::new();
    if width == 8 {
        // A real plot: every value is one column.
        for r in data.chunks_exact(row) {
            for cell in r.chunks_exact(8) {
                push_number(text, &mut digits, f64_le(cell));
                text.push(b',');
            }
            if let Some(last) = text.last_mut() {
                *last = b'\n';
            }
        }
        return;
    }
    for r in data.chunks_exact(row) {
        for (j, &pair) in pairs.iter().enumerate() {
            let cell = &r[j * width..(j + 1) * width];
            if j > 0 {
                text.push(b',');
            }
            push_number(text, &mut digits, f64_le(&cell[..8]));
            if pair {
                text.push(b',');
                push_number(text, &mut digits, f64_le(&cell[8..16]));
            }
        }
        text.push(b'\n');
    }
}

/// Appends `x`: the shortest digits that read back to the same `f64`.
fn push_number(out: &mut Vec<u8>, buf: &mut zmij::Buffer, x: f64) {
    out.extend_from_slice(buf.format(x).as_bytes());
}

fn f64_le(bytes: &[u8]) -> f64 {
    let mut b = [0u8; 8];
    b.copy_from_slice(bytes);
    f64::from_le_bytes(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn every_number_reads_back_to_the_same_bits(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            let mut out = Vec::new();
            push_number(&mut out, &mut zmij::Buffer::new(), x);
            let back: f64 = std::str::from_utf8(&out).unwrap().parse().unwrap();
            if x.is_nan() {
                prop_assert!(back.is_nan());
            } else {
                prop_assert_eq!(back.to_bits(), x.to_bits());
            }
        }
    }
}
