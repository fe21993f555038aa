//! `sweep.csv`: one row per sample, and the merge of shards' CSVs.
//!
//! Columns: `index`, each varied key (its name, e.g. `mechanics.mass`, in
//! sorted order), `outcome`, `bounce_count`, `first_impact` (s, the
//! operate time: coil on or force step → first make), `settle_time` (s, coil on or force step → closed for good),
//! `bounce_time` (s, first make → closed for good); for a
//! coil-driven relay `release_time` and `nc_bounce_time` (s, the longest
//! of its operations: coil off → break, and the bounce on the rest stop);
//! with `[arc]` `arc_count`, `arc_energy` (J, all arcs of the run) and
//! `breakdowns`; then per probe
//! `<signal>.edges`, `<signal>.peak` (max |value|, V or A),
//! `<signal>.lockout` and `<signal>.stable_for` (s, the debounce figures), then
//! `verdict` (`pass`, `fail`, `error`; see [`super::verdict`]),
//! `failed_limits` (the keys of the limits that failed, space-separated,
//! e.g. `limits.max_bounce_time probe[0].max_edges`) and `error` (why the
//! sample could not run, one line). An absent value is an empty cell. Numbers are SI in Rust's
//! shortest round-trip form; quoting (a signal `v(a,b)`, an error with a
//! comma) is the `csv` crate's, so every row parses back.
//!
//! [`merge`] joins shards' CSVs into the CSV one run would have written,
//! byte for byte: the same header, rows sorted by index.

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::io::{Read, Write};
use std::path::PathBuf;

use csv::{ByteRecord, ReaderBuilder, Writer};
use thiserror::Error;

use super::record::SampleRecord;

/// The columns before the probes', after the varied keys.
pub const OUTCOME_COLUMNS: [&str; 5] = [
    "outcome",
    "bounce_count",
    "first_impact",
    "settle_time",
    "bounce_time",
];

/// The columns of a coil-driven relay's release, after the outcome's.
pub const RELEASE_COLUMNS: [&str; 2] = ["release_time", "nc_bounce_time"];

/// The arc columns of a circuit sweep with `[arc]`, before the probes'.
pub const ARC_COLUMNS: [&str; 3] = ["arc_count", "arc_energy", "breakdowns"];

/// Which optional columns a sweep's CSV has.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Columns {
    /// The release columns of a coil-driven relay.
    pub coil: bool,
    /// Each probe's `<signal>.ideal_edges`.
    pub ideal: bool,
    /// The arc columns (`[arc]`, circuit sweeps).
    pub arc: bool,
}

/// The header line for `keys` and probe `signals`, with the optional
/// columns `columns` asks for.
pub fn header(keys: &[String], signals: &[String], columns: Columns) -> Vec<u8> {
    let Columns { coil, ideal, arc } = columns;
    let mut w = Writer::from_writer(Vec::new());
    let mut names: Vec<String> = vec!["index".to_owned()];
    names.extend(keys.iter().cloned());
    names.extend(OUTCOME_COLUMNS.iter().map(|s| (*s).to_owned()));
    if coil {
        names.extend(RELEASE_COLUMNS.iter().map(|s| (*s).to_owned()));
    }
    if arc {
        names.extend(ARC_COLUMNS.iter().map(|s| (*s).to_owned()));
    }
    for s in signals {
        names.push(format!("{s}.edges"));
        names.push(format!("{s}.peak"));
        names.push(format!("{s}.lockout"));
        names.push(format!("{s}.stable_for"));
        if ideal {
            names.push(format!("{s}.ideal_edges"));
        }
    }
    names.push("verdict".to_owned());
    names.push("failed_limits".to_owned());
    names.push("error".to_owned());
    w.write_record(&names).expect("writing to memory");
    w.into_inner().expect("writing to memory")
}

/// The number of columns of a sweep of `keys` varied keys and `signals`
/// probes, with the optional columns `columns` asks for.
pub fn width(keys: usize, signals: usize, columns: Columns) -> usize {
    let Columns { coil, ideal, arc } = columns;
    1 + keys
        + OUTCOME_COLUMNS.len()
        + if coil { RELEASE_COLUMNS.len() } else { 0 }
        + if arc { ARC_COLUMNS.len() } else { 0 }
        + signals * if ideal { 5 } else { 4 }
        + 3
}

/// The rows of `records` for a sweep of `keys` varied keys and `probes`
/// probes, each `\n`-terminated. A record without values or probes (a
/// sample that failed before them) has empty cells there, so every row
/// has the header's width.
pub fn rows(records: &[SampleRecord], keys: usize, probes: usize, columns: Columns) -> Vec<u8> {
    let Columns { coil, ideal, arc } = columns;
    let mut w = Writer::from_writer(Vec::with_capacity(records.len() * 96));
    let mut cell = String::new();
    let mut number = |w: &mut Writer<Vec<u8>>, value: Option<f64>| {
        cell.clear();
        if let Some(v) = value {
            use std::fmt::Write as _;
            let _ = write!(cell, "{v:?}");
        }
        w.write_field(&cell).expect("writing to memory");
    };
    for r in records {
        w.write_field(r.index.to_string())
            .expect("writing to memory");
        for i in 0..keys {
            number(&mut w, r.values.get(i).copied());
        }
        w.write_field(r.outcome.map_or("", |o| o.as_str()))
            .expect("writing to memory");
        w.write_field(r.bounce_count.map_or_else(String::new, |n| n.to_string()))
            .expect("writing to memory");
        number(&mut w, r.first_impact);
        number(&mut w, r.settle_time);
        number(&mut w, r.bounce_time);
        if coil {
            number(&mut w, r.release_time);
            number(&mut w, r.nc_bounce_time);
        }
        if arc {
            let count = |n: Option<usize>| n.map_or_else(String::new, |n| n.to_string());
            w.write_field(count(r.arc_count))
                .expect("writing to memory");
            number(&mut w, r.arc_energy);
            w.write_field(count(r.breakdowns))
                .expect("writing to memory");
        }
        for i in 0..probes {
            let p = r.probes.get(i);
            w.write_field(p.map_or_else(String::new, |p| p.edges.to_string()))
                .expect("writing to memory");
            number(&mut w, p.map(|p| p.peak));
            number(&mut w, p.and_then(|p| p.lockout));
            number(&mut w, p.and_then(|p| p.stable_for));
            if ideal {
                w.write_field(
                    p.and_then(|p| p.ideal_edges)
                        .map_or_else(String::new, |n| n.to_string()),
                )
                .expect("writing to memory");
            }
        }
        w.write_field(r.verdict.as_str())
            .expect("writing to memory");
        w.write_field(r.failed_limits.join(" "))
            .expect("writing to memory");
        w.write_field(r.error.as_deref().unwrap_or(""))
            .expect("writing to memory");
        w.write_record(None::<&[u8]>).expect("writing to memory");
    }
    w.into_inner().expect("writing to memory")
}

/// Why shards' CSVs could not be merged.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum MergeError {
    /// An input could not be read as CSV.
    #[error("{}: cannot read it", path.display())]
    Read {
        /// The input.
        path: PathBuf,
        /// Why it could not be read.
        #[source]
        source: csv::Error,
    },
    /// An input is empty: it has no header.
    #[error("{}: empty, not even a header; was the shard started?", path.display())]
    NoHeader {
        /// The input.
        path: PathBuf,
    },
    /// An input's header differs from the first input's.
    #[error(
        "{}: its header differs from {}'s; merge only the shards of one sweep \
         (same scenario, keys and mode)",
        path.display(),
        first.display()
    )]
    Header {
        /// The input.
        path: PathBuf,
        /// The first input, whose header the others must have.
        first: PathBuf,
    },
    /// A row's first cell is not a sample index.
    #[error("{}, line {line}: `{text}` is not a sample index; is this a sweep CSV?", path.display())]
    Index {
        /// The input.
        path: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The cell.
        text: String,
    },
    /// An input's rows are not in increasing index order.
    #[error(
        "{}, line {line}: index {index} after {previous}; a shard's rows are in index order, \
         was the file edited?",
        path.display()
    )]
    Unsorted {
        /// The input.
        path: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The row's index.
        index: u64,
        /// The index of the row before it, not below `index`.
        previous: u64,
    },
    /// Two inputs hold different rows for the same index.
    #[error(
        "index {index} is in {} and in {} with different values; were these shards of \
         different sweeps (seed, samples)?",
        first.display(),
        second.display()
    )]
    Conflict {
        /// The sample index.
        index: u64,
        /// The input whose row was kept first.
        first: PathBuf,
        /// The input with the other row.
        second: PathBuf,
    },
    /// Indices below the largest found, or below the expected sample
    /// count, are in no input (and missing ones were not allowed).
    #[error(
        "{count} sample(s) missing: {ranges}; rerun the shards that hold them, or pass \
         --allow-missing to write the rows there are"
    )]
    Missing {
        /// How many indices are missing.
        count: u64,
        /// The missing indices as ranges, e.g. `3–5, 9`.
        ranges: String,
    },
    /// The merged CSV could not be written.
    #[error("cannot write the merged CSV")]
    Write(#[source] std::io::Error),
}

/// What a merge found.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct MergeReport {
    /// Rows written.
    pub rows: u64,
    /// Indices found in more than one input (with identical rows; one was
    /// kept).
    pub duplicates: Vec<u64>,
    /// Indices absent from every input, below the largest one found, or
    /// below `expected` when given.
    pub missing: Vec<u64>,
}

/// `[3, 4, 5, 9]` → `"3–5, 9"`.
pub fn ranges(indices: &[u64]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < indices.len() {
        let start = indices[i];
        let mut end = start;
        while i + 1 < indices.len() && indices[i + 1] == end + 1 {
            i += 1;
            end = indices[i];
        }
        out.push(if start == end {
            start.to_string()
        } else {
            format!("{start}–{end}")
        });
        i += 1;
    }
    out.join(", ")
}

struct Input<R: Read> {
    path: PathBuf,
    reader: csv::Reader<R>,
    previous: Option<u64>,
}

impl<R: Read> Input<R> {
    /// The next row and its index.
    fn next(&mut self) -> Result<Option<(u64, ByteRecord)>, MergeError> {
        let mut record = ByteRecord::new();
        let more = self
            .reader
            .read_byte_record(&mut record)
            .map_err(|source| MergeError::Read {
                path: self.path.clone(),
                source,
            })?;
        if !more {
            return Ok(None);
        }
        let line = record.position().map_or(0, |p| p.line());
        let text = String::from_utf8_lossy(record.get(0).unwrap_or_default()).into_owned();
        let index: u64 = text.parse().map_err(|_| MergeError::Index {
            path: self.path.clone(),
            line,
            text: text.clone(),
        })?;
        if let Some(previous) = self.previous.filter(|&p| p >= index) {
            return Err(MergeError::Unsorted {
                path: self.path.clone(),
                line,
                index,
                previous,
            });
        }
        self.previous = Some(index);
        Ok(Some((index, record)))
    }
}

/// Merge `inputs` (each a shard's CSV: a name for messages and its
/// reader) into `out`: the common header, then every row in index order.
/// Each input must be in index order (a shard's CSV is). A row in two
/// inputs is written once if identical, an error if not. Missing indices
/// (below the largest, or below `expected` samples) are an error unless
/// `allow_missing`. Streams: memory does not grow with the sweep.
pub fn merge<R: Read>(
    inputs: Vec<(PathBuf, R)>,
    out: &mut dyn Write,
    expected: Option<u64>,
    allow_missing: bool,
) -> Result<MergeReport, MergeError> {
    let mut readers = Vec::with_capacity(inputs.len());
    let mut header: Option<(PathBuf, ByteRecord)> = None;
    for (path, read) in inputs {
        let mut reader = ReaderBuilder::new().has_headers(false).from_reader(read);
        let mut first = ByteRecord::new();
        let has = reader
            .read_byte_record(&mut first)
            .map_err(|source| MergeError::Read {
                path: path.clone(),
                source,
            })?;
        if !has {
            return Err(MergeError::NoHeader { path });
        }
        match &header {
            None => header = Some((path.clone(), first)),
            Some((first_path, h)) if *h != first => {
                return Err(MergeError::Header {
                    path,
                    first: first_path.clone(),
                });
            }
            Some(_) => {}
        }
        readers.push(Input {
            path,
            reader,
            previous: None,
        });
    }
    let Some((_, header)) = header else {
        return Ok(MergeReport::default());
    };

    // Rows go to `out` as they are merged, before the missing ones are
    // known: `merge_files` keeps them and writes the file only on success.
    let mut w = Writer::from_writer(out);
    w.write_byte_record(&header)
        .map_err(|e| MergeError::Write(e.into()))?;
    let mut heap = BinaryHeap::new();
    let mut heads: Vec<Option<ByteRecord>> = Vec::with_capacity(readers.len());
    for (i, input) in readers.iter_mut().enumerate() {
        let head = input.next()?;
        if let Some((index, _)) = &head {
            heap.push(Reverse((*index, i)));
        }
        heads.push(head.map(|(_, r)| r));
    }
    let mut report = MergeReport::default();
    let mut last: Option<(u64, usize, ByteRecord)> = None;
    while let Some(Reverse((index, i))) = heap.pop() {
        let record = heads[i].take().expect("a head for every heap entry");
        if let Some(next) = readers[i].next()? {
            heap.push(Reverse((next.0, i)));
            heads[i] = Some(next.1);
        }
        match &last {
            Some((previous, from, kept)) if *previous == index => {
                if *kept != record {
                    return Err(MergeError::Conflict {
                        index,
                        first: readers[*from].path.clone(),
                        second: readers[i].path.clone(),
                    });
                }
                report.duplicates.push(index);
                continue;
            }
            Some((previous, _, _)) => report.missing.extend(previous + 1..index),
            None => report.missing.extend(0..index),
        }
        w.write_byte_record(&record)
            .map_err(|e| MergeError::Write(e.into()))?;
        report.rows += 1;
        last = Some((index, i, record));
    }
    let end = last.as_ref().map_or(0, |(index, _, _)| index + 1);
    if let Some(expected) = expected {
        report.missing.extend(end..expected);
    }
    w.flush().map_err(MergeError::Write)?;
    if !report.missing.is_empty() && !allow_missing {
        return Err(MergeError::Missing {
            count: report.missing.len() as u64,
            ranges: ranges(&report.missing),
        });
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chatter::Outcome;
    use crate::sweep::{ProbeRecord, SampleVerdict};
    use std::io::Cursor;

    fn record(index: u64) -> SampleRecord {
        SampleRecord {
            index,
            values: vec![1.5e-4, 0.25],
            outcome: Some(Outcome::Stuck),
            bounce_count: Some(3),
            first_impact: Some(1e-3),
            settle_time: Some(2e-3),
            bounce_time: Some(1e-3),
            release_time: None,
            arc_count: None,
            arc_energy: None,
            breakdowns: None,
            nc_bounce_time: None,
            probes: vec![ProbeRecord {
                edges: 5,
                peak: 3.3,
                ideal_edges: None,
                lockout: None,
                stable_for: None,
            }],
            verdict: SampleVerdict::Pass,
            failed_limits: vec![],
            error: None,
        }
    }

    #[test]
    fn rows_match_the_header_and_quote_what_needs_it() {
        let keys = vec!["mechanics.mass".to_owned(), "surface.damping".to_owned()];
        let h = header(&keys, &["v(a,b)".to_owned()], Columns::default());
        assert_eq!(
            String::from_utf8(h).unwrap(),
            "index,mechanics.mass,surface.damping,outcome,bounce_count,first_impact,settle_time,\
             bounce_time,\"v(a,b).edges\",\"v(a,b).peak\",\"v(a,b).lockout\",\"v(a,b).stable_for\",verdict,failed_limits,error\n"
        );
        let mut failed = record(1);
        failed.probes.clear();
        failed.outcome = None;
        failed.bounce_count = None;
        failed.verdict = SampleVerdict::Error;
        failed.error = Some("ngspice failed: timeout, 60 s".to_owned());
        failed.probes = vec![];
        let text = String::from_utf8(rows(&[record(0)], 2, 1, Columns::default())).unwrap();
        assert_eq!(
            text,
            "0,0.00015,0.25,stuck,3,0.001,0.002,0.001,5,3.3,,,pass,,\n"
        );
        failed.values.clear();
        let text = String::from_utf8(rows(&[failed], 2, 1, Columns::default())).unwrap();
        assert_eq!(
            text,
            "1,,,,,0.001,0.002,0.001,,,,,error,,\"ngspice failed: timeout, 60 s\"\n"
        );
    }

    fn csv_of(indices: &[u64]) -> Vec<u8> {
        let mut out = header(&["k".to_owned()], &[], Columns::default());
        let records: Vec<SampleRecord> = indices
            .iter()
            .map(|&i| SampleRecord {
                probes: vec![],
                values: vec![i as f64],
                ..record(i)
            })
            .collect();
        out.extend(rows(&records, 1, 0, Columns::default()));
        out
    }

    #[test]
    fn merge_interleaves_reports_duplicates_and_refuses_gaps() {
        let inputs = vec![
            ("a".into(), Cursor::new(csv_of(&[0, 2, 4]))),
            ("b".into(), Cursor::new(csv_of(&[1, 3, 4]))),
        ];
        let mut out = Vec::new();
        let report = merge(inputs, &mut out, Some(5), false).unwrap();
        assert_eq!(out, csv_of(&[0, 1, 2, 3, 4]));
        assert_eq!(report.duplicates, vec![4]);

        let gap = vec![("a".into(), Cursor::new(csv_of(&[0, 3])))];
        let err = merge(gap, &mut Vec::new(), Some(6), false).unwrap_err();
        assert!(err.to_string().contains("1–2, 4–5"), "{err}");
        let gap = vec![("a".into(), Cursor::new(csv_of(&[0, 3])))];
        let report = merge(gap, &mut Vec::new(), None, true).unwrap();
        assert_eq!(report.missing, vec![1, 2]);

        let other = header(&["j".to_owned()], &[], Columns::default());
        let err = merge(
            vec![
                ("a".into(), Cursor::new(csv_of(&[0]))),
                ("b".into(), Cursor::new(other)),
            ],
            &mut Vec::new(),
            None,
            false,
        )
        .unwrap_err();
        assert!(matches!(err, MergeError::Header { .. }), "{err}");

        let unsorted = vec![("a".into(), Cursor::new(csv_of(&[2, 1])))];
        assert!(matches!(
            merge(unsorted, &mut Vec::new(), None, true).unwrap_err(),
            MergeError::Unsorted { .. }
        ));
    }
}
