//! Reading a raw file from disk straight into its columns: what
//! [`super::types::RawFile::read`] does first.
//!
//! For the files [`super::locate`] finds its way in (ngspice's binary
//! plots, whole or cut short by a killed run), every vector's `Vec` is
//! allocated once at the plot's whole point count, and the data are read a
//! block of points at a time ([`super::locate::BLOCK_BYTES`]) into a
//! reused buffer, each block's rows transposed into the columns. Nothing
//! holds the whole file beside the columns, so memory is the size of the
//! data plus a block a thread. Any other file is read whole and parsed in
//! memory.
//!
//! A large real plot is split by points between threads (one a core, at
//! most [`MAX_THREADS`]), each reading its own points with positional
//! reads into its own share of every column: the first touch of the
//! columns' fresh memory, the kernel's copies and the transposition, which
//! take about equal parts of the time, all run in parallel.

use std::fs::File;
use std::io;
use std::ops::Range;

use super::data::{transpose_complex, transpose_real};
use super::header::real_in_complex_plot;
use super::locate::{Located, POSITIONAL_READS, locate};
use super::types::{Column, Complex64, Plot, RawFile};

/// At most this many threads read one plot (measured on 2 cores: 2
/// threads take 0.58 of the time of one, 4 threads 0.54).
const MAX_THREADS: usize = 4;

/// A thread is worth starting for at least this much data.
const BYTES_A_THREAD: usize = 4 << 20;

/// The file's plots read into columns, or `None` when it is not one to
/// read this way (see [`super::locate`]).
pub(super) fn read(file: &mut File, len: u64) -> io::Result<Option<RawFile>> {
    let Some(located) = locate(file, len)? else {
        return Ok(None);
    };
    if located.is_empty() {
        // The parser says why.
        return Ok(None);
    }
    let mut plots = Vec::with_capacity(located.len());
    let mut warnings = Vec::new();
    for (index, place) in located.into_iter().enumerate() {
        warnings.extend(place.warning(index));
        plots.push(read_plot(file, place)?);
    }
    Ok(Some(RawFile { plots, warnings }))
}

/// One located plot with its values.
fn read_plot(file: &File, place: Located) -> io::Result<Plot> {
    let points = place.points as usize;
    let plot = &place.header.plot;
    // A killed run's vectors all have its points; otherwise a vector that
    // `dims=` makes shorter keeps its length (the rest is padding).
    let lens: Vec<usize> = if plot.declared_points == 0 {
        vec![points; place.header.nvars]
    } else {
        place
            .header
            .lengths
            .iter()
            .map(|&l| l.min(points))
            .collect()
    };
    let columns = if plot.flags.complex {
        read_complex(file, &place, &lens)?
    } else {
        let threads = threads_for(points.saturating_mul(place.row()));
        read_real(file, &place, &lens, threads)?
    };
    let mut plot = place.header.plot;
    plot.columns = columns;
    Ok(plot)
}

/// The columns of a complex plot (AC analyses: small), in one thread.
fn read_complex(file: &File, place: &Located, lens: &[usize]) -> io::Result<Vec<Column>> {
    let plot = &place.header.plot;
    let mut columns: Vec<Column> = plot
        .variables
        .iter()
        .zip(lens)
        .enumerate()
        .map(|(j, (v, &len))| {
            if real_in_complex_plot(v, j) {
                Column::Real(vec![0.0; len])
            } else {
                Column::Complex(vec![Complex64::new(0.0, 0.0); len])
            }
        })
        .collect();
    let mut buf = Vec::new();
    let mut blocks = place.blocks(file, &mut buf, 0..place.points as usize);
    while let Some((block, first)) = blocks.next_block()? {
        transpose_complex(block, place.row(), first, &mut columns);
    }
    Ok(columns)
}

/// How many threads read a plot of `bytes` of data: one a core, one
/// a [`BYTES_A_THREAD`], at most [`MAX_THREADS`]; one where reads move the
/// file's position.
fn threads_for(bytes: usize) -> usize {
    if !POSITIONAL_READS {
        return 1;
    }
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    (bytes / BYTES_A_THREAD).clamp(1, cores.min(MAX_THREADS))
}

/// The columns of a real plot, its points split between `threads`.
fn read_real(
    file: &File,
    place: &Located,
    lens: &[usize],
    threads: usize,
) -> io::Result<Vec<Column>> {
    let points = place.points as usize;
    let row = place.row();
    let mut columns: Vec<Vec<f64>> = lens.iter().map(|&len| vec![0.0; len]).collect();
    let threads = threads.max(1);
    let share = points.div_ceil(threads);
    let ranges: Vec<Range<usize>> = (0..threads)
        .map(|k| (k * share).min(points)..((k + 1) * share).min(points))
        .collect();
    // Each thread's share of every column: the values of its points.
    let mut shares: Vec<Vec<&mut [f64]>> = ranges.iter().map(|_| Vec::new()).collect();
    for column in columns.iter_mut() {
        let mut rest: &mut [f64] = column;
        for (mine, range) in shares.iter_mut().zip(&ranges) {
            let (head, tail) = rest.split_at_mut(range.len().min(rest.len()));
            mine.push(head);
            rest = tail;
        }
    }
    let fill = |range: Range<usize>, mut mine: Vec<&mut [f64]>| -> io::Result<()> {
        let mut buf = Vec::new();
        let mut blocks = place.blocks(file, &mut buf, range);
        while let Some((block, first)) = blocks.next_block()? {
            transpose_real(block, row, first, &mut mine);
        }
        Ok(())
    };
    let mut jobs = ranges.into_iter().zip(shares);
    let first = jobs.next();
    std::thread::scope(|scope| {
        let others: Vec<_> = jobs
            .map(|(range, mine)| scope.spawn(move || fill(range, mine)))
            .collect();
        // This thread reads the first share.
        let mut result = first.map_or(Ok(()), |(range, mine)| fill(range, mine));
        for other in others {
            let done = other
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
            result = result.and(done);
        }
        result
    })?;
    Ok(columns.into_iter().map(Column::Real).collect())
}

#[cfg(test)]
#[path = "direct_tests.rs"]
mod tests;
