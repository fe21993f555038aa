//! One plot of a binary raw file to CSV, streamed: the file is read a
//! block of points at a time and each block written out before the next is
//! read, so memory stays bounded (a few MB) whatever the file's size.
//!
//! Streaming covers the files ngspice writes in batch mode: binary,
//! padded plots whose data end where `No. Points:` says (at the end of the
//! file or at the next plot's header), or a killed run's last plot cut
//! anywhere. Anything else (ASCII, unpadded vectors, the irregular data of
//! `.options interp`, LTspice's files) returns `None`, and the caller
//! reads the file whole with [`super::types::RawFile::read`], which copes with
//! all of them.
//!
//! Numbers are written by [`zmij`]: the shortest digits that read back to
//! the identical `f64` (`1.5`, `0.001`, `1e-7`, `3.3000000000000003`).

use std::fs::File;
use std::io::Write;
use std::path::Path;

use super::error::{ExportError, RawError};
use super::header::real_in_complex_plot;
use super::locate::{Located, locate};
use super::read::regular_file;
use super::types::RawWarning;

/// Writes plot `index` (default: the last) of the raw file at `path` as
/// CSV to `out`, streaming. `Ok(None)`: the file is not one this streams
/// (see the module overview); nothing was written. Otherwise the
/// warnings (a killed run's cut data).
pub fn stream_csv<W: Write>(
    path: &Path,
    index: Option<usize>,
    out: W,
) -> Result<Option<Vec<RawWarning>>, ExportError> {
    let io = |source: std::io::Error| RawError::Io {
        path: path.to_path_buf(),
        source,
    };
    regular_file(path)?;
    let mut file = crate::input::open_regular(path).map_err(io)?;
    let len = file.metadata().map_err(io)?.len();
    let Some(plots) = locate(&mut file, len).map_err(io)? else {
        return Ok(None);
    };
    if plots.is_empty() {
        // The in-memory reader says why.
        return Ok(None);
    }
    let count = plots.len();
    let chosen = index.unwrap_or(count - 1);
    let Some(plot) = plots.get(chosen) else {
        return Err(ExportError::NoSuchPlot {
            index: chosen,
            count,
        });
    };
    write_plot(&file, plot, chosen, out, &io)
}

fn write_plot<W: Write>(
    file: &File,
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
    let row = located.row();
    // Formatting, not reading, is the cost: about 15 ns a number with
    // zmij. (Splitting a block between two threads was measured slower on
    // the 2-core development machine.)
    let mut buf = Vec::new();
    let mut text = Vec::new();
    let mut blocks = located.blocks(file, &mut buf, 0..located.points as usize);
    while let Some((data, _)) = blocks.next_block().map_err(io)? {
        format_rows(data, row, width, &pairs, &mut text);
        out.write_all(&text)?;
    }
    out.flush()?;
    Ok(Some(located.warning(index).into_iter().collect()))
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
