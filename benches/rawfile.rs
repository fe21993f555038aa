//! Raw reader throughput on files the size of a long chatter run
//! (≥ 50 MB), generated here rather than committed.
//!
//! `cargo bench --bench rawfile`
//!
//! Parse time only: the parsed file is freed outside the timing
//! (`iter_with_large_drop`), since returning 64 MB to the OS is not
//! parsing. `rawfile/read` times `RawFile::read` of a ~100 MB binary
//! file of 33 vectors on disk (in the page cache after the first read):
//! the file straight into the columns, as `chatterspice raw` reads it.

use std::fmt::Write as _;
use std::hint::black_box;

use chatterspice::rawfile::RawFile;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const VARS: usize = 8;

fn header(kind: &str, points: usize) -> String {
    header_of(VARS, kind, points)
}

fn header_of(vars: usize, kind: &str, points: usize) -> String {
    let mut h = format!(
        "Title: benchmark\nDate: Thu Jan  1 00:00:00  1970\nPlotname: Transient Analysis\n\
         Flags: real\nNo. Variables: {vars}\nNo. Points: {points:<8}\nVariables:\n\t0\ttime\ttime\n"
    );
    for i in 1..vars {
        let _ = writeln!(h, "\t{i}\tv(n{i})\tvoltage");
    }
    h.push_str(kind);
    h.push('\n');
    h
}

/// Smooth but non-repeating values, like node voltages.
fn value(point: usize, var: usize) -> f64 {
    if var == 0 {
        point as f64 * 1e-9
    } else {
        (point as f64 * 1e-3 * var as f64).sin() * 3.3 + var as f64 * 1e-7
    }
}

fn binary_file(points: usize) -> Vec<u8> {
    binary_file_of(VARS, points)
}

fn binary_file_of(vars: usize, points: usize) -> Vec<u8> {
    let mut f = header_of(vars, "Binary:", points).into_bytes();
    f.reserve(points * vars * 8);
    for p in 0..points {
        for v in 0..vars {
            f.extend_from_slice(&value(p, v).to_le_bytes());
        }
    }
    f
}

/// C's `%.15e`: `1.234567890123457e-03`.
fn c_style(x: f64, out: &mut String) {
    let s = format!("{x:.15e}");
    let (mantissa, exp) = s.split_once('e').unwrap_or((&s, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    let sign = if exp < 0 { '-' } else { '+' };
    let _ = write!(out, "{mantissa}e{sign}{:02}", exp.abs());
}

/// The batch writer's layout: `index\t\tvalue` then `\tvalue` lines.
fn ascii_file(points: usize) -> Vec<u8> {
    let mut f = header("Values:", points);
    for p in 0..points {
        let _ = write!(f, "{p}\t");
        for v in 0..VARS {
            f.push('\t');
            c_style(value(p, v), &mut f);
            f.push('\n');
        }
    }
    f.into_bytes()
}

fn bench(c: &mut Criterion) {
    let binary = binary_file(1_000_000);
    let ascii = ascii_file(300_000);
    assert!(binary.len() >= 50_000_000 && ascii.len() >= 50_000_000);
    // Sanity: both parse to the same shape.
    assert_eq!(
        RawFile::parse(&binary).unwrap().plots[0].points(),
        1_000_000
    );
    assert_eq!(RawFile::parse(&ascii).unwrap().plots[0].points(), 300_000);

    let mut g = c.benchmark_group("rawfile");
    g.sample_size(10);
    g.throughput(Throughput::Bytes(binary.len() as u64));
    g.bench_function(format!("binary {} MB", binary.len() / 1_000_000), |b| {
        b.iter_with_large_drop(|| RawFile::parse(black_box(&binary)).unwrap())
    });
    g.throughput(Throughput::Bytes(ascii.len() as u64));
    g.bench_function(format!("ascii {} MB", ascii.len() / 1_000_000), |b| {
        b.iter_with_large_drop(|| RawFile::parse(black_box(&ascii)).unwrap())
    });
    g.finish();
}

/// `RawFile::read` of a file on disk the size of `scripts/bench-raw-read`'s
/// (33 vectors, 392 000 points: 103 MB).
fn bench_read(c: &mut Criterion) {
    let (vars, points) = (33, 392_000);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.raw");
    std::fs::write(&path, binary_file_of(vars, points)).unwrap();
    let bytes = std::fs::metadata(&path).unwrap().len();
    let raw = RawFile::read(&path).unwrap();
    assert_eq!(raw.plots[0].points(), points);
    assert_eq!(
        raw.plots[0].real("v(n32)").unwrap()[points - 1],
        value(points - 1, 32)
    );
    drop(raw);

    let mut g = c.benchmark_group("rawfile");
    g.sample_size(10);
    g.throughput(Throughput::Bytes(bytes));
    g.bench_function(
        format!("read {} MB, {vars} vectors", bytes / 1_000_000),
        |b| b.iter_with_large_drop(|| RawFile::read(black_box(&path)).unwrap()),
    );
    g.finish();
}

criterion_group!(benches, bench, bench_read);
criterion_main!(benches);
