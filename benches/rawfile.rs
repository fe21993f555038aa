//! Raw reader throughput on files the size of a long chatter run
//! (≥ 50 MB), generated here rather than committed.
//!
//! `cargo bench --bench rawfile`
//!
//! Parse time only: the parsed file is freed outside the timing
//! (`iter_with_large_drop`), since returning 64 MB to the OS is not
//! parsing.

use std::fmt::Write as _;
use std::hint::black_box;

use chatterspice::rawfile::RawFile;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};

const VARS: usize = 8;

fn header(kind: &str, points: usize) -> String {
    let mut h = format!(
        "Title: benchmark\nDate: Thu Jan  1 00:00:00  1970\nPlotname: Transient Analysis\n\
         Flags: real\nNo. Variables: {VARS}\nNo. Points: {points:<8}\nVariables:\n\t0\ttime\ttime\n"
    );
    for i in 1..VARS {
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
    let mut f = header("Binary:", points).into_bytes();
    f.reserve(points * VARS * 8);
    for p in 0..points {
        for v in 0..VARS {
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

criterion_group!(benches, bench);
criterion_main!(benches);
