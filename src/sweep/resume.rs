//! A sweep's identity, and continuing an interrupted sweep from its rows.
//!
//! Beside each sweep CSV (`sweep.csv`, `sweep.K-of-N.csv`) a small JSON
//! file (`sweep.meta.json`, `sweep.K-of-N.meta.json`) says which sweep the
//! rows belong to: the tool's version, a digest of the scenario and its
//! netlist, the seed, the sample count, the shard and the mode, and
//! whether every sample of the shard is in the CSV. A sweep stopped by a
//! signal keeps its finished rows whole in its CSV and is marked
//! incomplete. While it runs, a sweep writes `sweep.csv.partial` and
//! `sweep.meta.json.partial` ([`partial`]); at the end, or at SIGINT,
//! SIGTERM or SIGHUP, they become `sweep.csv` and `sweep.meta.json`. A
//! sweep killed outright (SIGKILL, a power cut) leaves the partial files,
//! which are as good. `sweep --resume DIR` checks that either is the same
//! sweep, reads its rows back ([`finished_rows`]) and runs the rest, to
//! the same files an uninterrupted run writes.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use csv::{ByteRecord, ReaderBuilder};
use serde::{Deserialize, Serialize};
use thiserror::Error;

use super::record::{ProbeRecord, SampleRecord, Shard};
use super::verdict::SampleVerdict;
use crate::chatter::Outcome;

/// Which sweep a CSV holds rows of.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Identity {
    /// `chatterspice <version>`.
    pub tool: String,
    /// FNV-1a (64-bit, hex) of the scenario's text and its netlist's.
    pub scenario_digest: String,
    /// The random sweep's seed; `None` for a grid.
    pub seed: Option<u64>,
    /// Samples of the whole sweep (not of the shard).
    pub samples: u64,
    /// `K/N`, or `None` for the whole sweep.
    pub shard: Option<String>,
    /// `mechanics` or `circuit`.
    pub mode: String,
    /// Whether each sample also ran with an ideal contact.
    pub ideal: bool,
}

/// The file beside a sweep CSV.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Meta {
    /// Which sweep the rows belong to; its fields sit at the top level of
    /// the JSON.
    #[serde(flatten)]
    pub identity: Identity,
    /// Whether every sample of the shard has its row.
    pub complete: bool,
    /// Rows in the CSV.
    pub rows: u64,
}

impl Meta {
    /// Pretty JSON, `\n`-terminated.
    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("plain data serializes");
        text.push('\n');
        text
    }
}

/// Why a sweep cannot be resumed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum ResumeError {
    /// The identity file cannot be read, so no sweep is known to have run
    /// there.
    #[error(
        "{}: cannot read it, so there is no sweep to resume here (a sweep writes it beside its \
         CSV)",
        path.display()
    )]
    NoMeta {
        /// The identity file.
        path: PathBuf,
        /// Why it cannot be read.
        #[source]
        source: std::io::Error,
    },
    /// The identity file is not the JSON a sweep writes.
    #[error("{}: not a sweep's identity file: {problem}", path.display())]
    BadMeta {
        /// The identity file.
        path: PathBuf,
        /// The JSON parser's message.
        problem: String,
    },
    /// The sweep there has every row already.
    #[error("{}: the sweep there is complete: there is nothing to resume", path.display())]
    Complete {
        /// The identity file.
        path: PathBuf,
    },
    /// The rows there belong to another sweep: its scenario, seed, sample
    /// count, shard, mode, ideal-contact setting or tool version differs.
    #[error(
        "{}: the sweep there is another one: its {field} is {theirs}, this one's is {ours}; \
         resume with the same scenario, seed and options",
        path.display()
    )]
    Different {
        /// The identity file.
        path: PathBuf,
        /// The first field that differs, in words (e.g. `seed`).
        field: &'static str,
        /// Its value in the identity file.
        theirs: String,
        /// Its value for this sweep.
        ours: String,
    },
    /// The CSV of the interrupted sweep cannot be read.
    #[error("{}: cannot read the rows to resume from", path.display())]
    ReadCsv {
        /// The CSV.
        path: PathBuf,
        /// Why it cannot be read.
        #[source]
        source: std::io::Error,
    },
    /// The CSV's header is not the one this sweep writes, or a whole row
    /// cannot be read back or is not the sample due.
    #[error("{}: line {line}: {problem}; the rows cannot be resumed from", path.display())]
    BadRow {
        /// The CSV.
        path: PathBuf,
        /// 1-based line of the row (1: the header).
        line: u64,
        /// What is wrong with it.
        problem: String,
    },
}

/// `sweep.csv` → `sweep.meta.json`.
pub fn meta_path(csv: &Path) -> PathBuf {
    let name = csv.file_name().map_or_else(String::new, |n| {
        let n = n.to_string_lossy();
        n.strip_suffix(".csv").unwrap_or(&n).to_owned()
    });
    csv.with_file_name(format!("{name}.meta.json"))
}

/// FNV-1a, 64-bit, of `parts` one after the other, as 16 hex digits: an
/// identity check, not a cryptographic one.
pub fn digest(parts: &[&[u8]]) -> String {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &b in *part {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
        // Parts are separated, so ("ab", "c") differs from ("a", "bc").
        h ^= 0xff;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// Where a running sweep keeps a file before it is complete: the name
/// with `.partial` added (`sweep.csv.partial`).
pub fn partial(path: &Path) -> PathBuf {
    let mut name = path.as_os_str().to_owned();
    name.push(".partial");
    PathBuf::from(name)
}

/// The first field in which two identities differ (shard aside): (name,
/// `a`'s value, `b`'s value).
pub fn differs(a: &Identity, b: &Identity) -> Option<(&'static str, String, String)> {
    let show = |v: &Option<u64>| v.map_or_else(|| "none".to_owned(), |s| s.to_string());
    if a.scenario_digest != b.scenario_digest {
        Some((
            "scenario (digest of the scenario and netlist)",
            a.scenario_digest.clone(),
            b.scenario_digest.clone(),
        ))
    } else if a.seed != b.seed {
        Some(("seed", show(&a.seed), show(&b.seed)))
    } else if a.samples != b.samples {
        Some(("sample count", a.samples.to_string(), b.samples.to_string()))
    } else if a.mode != b.mode {
        Some(("mode", a.mode.clone(), b.mode.clone()))
    } else if a.ideal != b.ideal {
        Some((
            "ideal-contact setting",
            a.ideal.to_string(),
            b.ideal.to_string(),
        ))
    } else if a.tool != b.tool {
        Some(("tool version", a.tool.clone(), b.tool.clone()))
    } else {
        None
    }
}

/// The identity file beside sweep CSV `csv`, when there is one.
pub fn meta_beside(csv: &Path) -> Result<Option<Meta>, ResumeError> {
    let path = meta_path(csv);
    if !path.exists() {
        return Ok(None);
    }
    let text = crate::input::read_to_string(&path).map_err(|source| ResumeError::NoMeta {
        path: path.clone(),
        source,
    })?;
    serde_json::from_str(&text)
        .map(Some)
        .map_err(|e| ResumeError::BadMeta {
            path,
            problem: e.to_string(),
        })
}

/// Reads the identity file `path` and checks it belongs to the sweep
/// `ours` and is incomplete.
pub fn check_meta(path: &Path, ours: &Identity) -> Result<Meta, ResumeError> {
    let path = path.to_path_buf();
    let text = crate::input::read_to_string(&path).map_err(|source| ResumeError::NoMeta {
        path: path.clone(),
        source,
    })?;
    let meta: Meta = serde_json::from_str(&text).map_err(|e| ResumeError::BadMeta {
        path: path.clone(),
        problem: e.to_string(),
    })?;
    let theirs = &meta.identity;
    let show = |v: &Option<String>| v.clone().unwrap_or_else(|| "none".to_owned());
    let differs = differs(theirs, ours).or_else(|| {
        (theirs.shard != ours.shard).then(|| ("shard", show(&theirs.shard), show(&ours.shard)))
    });
    if let Some((field, theirs, ours)) = differs {
        return Err(ResumeError::Different {
            path,
            field,
            theirs,
            ours,
        });
    }
    if meta.complete {
        return Err(ResumeError::Complete { path });
    }
    Ok(meta)
}

/// The finished rows of an interrupted sweep CSV, read as a stream: each
/// whole row that continues the sequence of `shard`'s samples goes to
/// `each`, in file order. Returns the length of the file's header and
/// those rows, in bytes (what a resumed sweep keeps). `header` is the
/// header this sweep writes; `keys` and `probes` its widths; `columns` its
/// optional columns.
pub fn finished_rows<E: From<ResumeError>>(
    path: &Path,
    header: &[u8],
    keys: usize,
    signals: usize,
    columns: super::table::Columns,
    shard: Shard,
    each: impl FnMut(SampleRecord) -> Result<(), E>,
) -> Result<u64, E> {
    read_rows(path, header, keys, signals, columns, Some(shard), each)
}

/// Every whole row of sweep CSV `path` to `each`, in file order, whatever
/// their indices (a merge that allowed missing samples).
pub fn all_rows<E: From<ResumeError>>(
    path: &Path,
    header: &[u8],
    keys: usize,
    signals: usize,
    columns: super::table::Columns,
    each: impl FnMut(SampleRecord) -> Result<(), E>,
) -> Result<u64, E> {
    read_rows(path, header, keys, signals, columns, None, each)
}

/// The rows of `path`, one at a time, a buffer's worth in memory; with
/// `shard`, only while they continue its sequence of samples.
fn read_rows<E: From<ResumeError>>(
    path: &Path,
    header: &[u8],
    keys: usize,
    signals: usize,
    columns: super::table::Columns,
    shard: Option<Shard>,
    mut each: impl FnMut(SampleRecord) -> Result<(), E>,
) -> Result<u64, E> {
    let cannot = |source| ResumeError::ReadCsv {
        path: path.to_owned(),
        source,
    };
    let bad = |line: u64, problem: String| ResumeError::BadRow {
        path: path.to_owned(),
        line,
        problem,
    };
    let mut file = crate::input::open_regular(path).map_err(cannot)?;
    let mut start = Vec::with_capacity(header.len());
    (&mut file)
        .take(header.len() as u64)
        .read_to_end(&mut start)
        .map_err(cannot)?;
    if start != header {
        return Err(bad(
            1,
            "its header is not the one this sweep writes (other keys, probes or options)".into(),
        )
        .into());
    }
    // Only whole lines: a row cut by the stop is run again.
    let whole = last_newline_end(&mut file).map_err(cannot)?;
    file.seek(SeekFrom::Start(header.len() as u64))
        .map_err(cannot)?;
    let body =
        BufReader::with_capacity(1 << 16, file).take(whole.saturating_sub(header.len() as u64));
    let mut reader = ReaderBuilder::new().has_headers(false).from_reader(body);
    let width = super::table::width(keys, signals, columns);
    let mut row = ByteRecord::new();
    let mut end = header.len() as u64;
    let mut line = 1;
    let mut rows = 0;
    loop {
        match reader.read_byte_record(&mut row) {
            Ok(false) => break,
            Ok(true) => {}
            Err(e) => return Err(bad(line + 1, e.to_string()).into()),
        }
        line += 1;
        if row.len() != width {
            // A row written partly before the stop and partly after it.
            break;
        }
        let record = parse_row(&row, keys, signals, columns).map_err(|p| bad(line, p))?;
        if let Some(shard) = shard {
            let expected = shard.sample(rows);
            if record.index != expected {
                return Err(bad(
                    line,
                    format!("sample {} where {expected} was due", record.index),
                )
                .into());
            }
        }
        each(record)?;
        rows += 1;
        end = header.len() as u64 + reader.position().byte();
    }
    Ok(end)
}

/// The length of `file` up to and including its last newline (0 without
/// one), read from its end backwards.
fn last_newline_end(file: &mut File) -> std::io::Result<u64> {
    let len = file.seek(SeekFrom::End(0))?;
    let mut block = vec![0u8; 1 << 16];
    let mut to = len;
    while to > 0 {
        let from = to.saturating_sub(block.len() as u64);
        let chunk = &mut block[..(to - from) as usize];
        file.seek(SeekFrom::Start(from))?;
        file.read_exact(chunk)?;
        if let Some(i) = chunk.iter().rposition(|&b| b == b'\n') {
            return Ok(from + i as u64 + 1);
        }
        to = from;
    }
    Ok(0)
}

/// The record of a row that [`super::table::rows`] wrote.
fn parse_row(
    row: &ByteRecord,
    keys: usize,
    signals: usize,
    columns: super::table::Columns,
) -> Result<SampleRecord, String> {
    let mut cells = row
        .iter()
        .map(|c| std::str::from_utf8(c).unwrap_or("\u{fffd}"));
    let mut next = || cells.next().unwrap_or("");
    fn number(cell: &str) -> Result<Option<f64>, String> {
        if cell.is_empty() {
            return Ok(None);
        }
        cell.parse()
            .map(Some)
            .map_err(|_| format!("`{cell}` is not a number"))
    }
    fn count(cell: &str) -> Result<Option<usize>, String> {
        if cell.is_empty() {
            return Ok(None);
        }
        cell.parse()
            .map(Some)
            .map_err(|_| format!("`{cell}` is not a count"))
    }
    let index_cell = next();
    let index = index_cell
        .parse()
        .map_err(|_| format!("`{index_cell}` is not a sample index"))?;
    let mut values = Vec::with_capacity(keys);
    for _ in 0..keys {
        values.extend(number(next())?);
    }
    let outcome_cell = next();
    let outcome = if outcome_cell.is_empty() {
        None
    } else {
        Some(
            Outcome::parse(outcome_cell)
                .ok_or_else(|| format!("`{outcome_cell}` is not an outcome"))?,
        )
    };
    let bounce_count = count(next())?;
    let first_impact = number(next())?;
    let settle_time = number(next())?;
    let bounce_time = number(next())?;
    let (release_time, nc_bounce_time) = if columns.coil {
        (number(next())?, number(next())?)
    } else {
        (None, None)
    };
    let (arc_count, arc_energy, breakdowns) = if columns.arc {
        (count(next())?, number(next())?, count(next())?)
    } else {
        (None, None, None)
    };
    let mut probes = Vec::with_capacity(signals);
    for _ in 0..signals {
        let edges = count(next())?;
        let peak = number(next())?;
        let lockout = number(next())?;
        let stable_for = number(next())?;
        let ideal_edges = if columns.ideal { count(next())? } else { None };
        if let (Some(edges), Some(peak)) = (edges, peak) {
            probes.push(ProbeRecord {
                edges,
                peak,
                ideal_edges,
                lockout,
                stable_for,
            });
        }
    }
    let verdict_cell = next();
    let verdict = SampleVerdict::parse(verdict_cell)
        .ok_or_else(|| format!("`{verdict_cell}` is not a verdict"))?;
    let failed_limits = next().split_whitespace().map(str::to_owned).collect();
    let error = Some(next()).filter(|e| !e.is_empty()).map(str::to_owned);
    Ok(SampleRecord {
        index,
        values,
        outcome,
        bounce_count,
        first_impact,
        settle_time,
        bounce_time,
        release_time,
        nc_bounce_time,
        arc_count,
        arc_energy,
        breakdowns,
        probes,
        verdict,
        failed_limits,
        error,
    })
}

/// Cuts the file at `path` after its last newline (a row being written
/// when the process stopped), keeping the whole rows before it.
pub fn truncate_to_whole_lines(path: &Path) -> std::io::Result<()> {
    let bytes = std::fs::read(path)?;
    let whole = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    if whole < bytes.len() {
        let file = std::fs::OpenOptions::new().write(true).open(path)?;
        file.set_len(whole as u64)?;
    }
    Ok(())
}

/// Rows in a CSV file's bytes, the header not counted.
pub fn row_count(bytes: &[u8]) -> u64 {
    let lines = bytes.iter().filter(|&&b| b == b'\n').count() as u64;
    lines.saturating_sub(1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::table::{self, Columns};

    fn record(index: u64) -> SampleRecord {
        SampleRecord {
            index,
            values: vec![1.5e-4 + index as f64 * 1e-7, 0.1],
            outcome: Some(Outcome::Stuck),
            bounce_count: Some(5),
            first_impact: Some(1.8e-4),
            settle_time: Some(1.2e-3),
            bounce_time: Some(1.02e-3),
            release_time: None,
            nc_bounce_time: None,
            arc_count: Some(2),
            arc_energy: Some(3.25e-5),
            breakdowns: Some(0),
            probes: vec![ProbeRecord {
                edges: 7,
                peak: 3.3,
                ideal_edges: Some(1),
                lockout: Some(2e-4),
                stable_for: Some(1e-4),
            }],
            verdict: SampleVerdict::Fail,
            failed_limits: vec!["limits.max_bounces".into(), "probe[0].max_edges".into()],
            error: None,
        }
    }

    #[test]
    fn rows_read_back_to_the_records_written_and_a_cut_row_is_dropped() {
        let keys = vec!["mechanics.mass".to_owned(), "surface.damping".to_owned()];
        let signals = vec!["v(a,b)".to_owned()];
        let columns = Columns {
            coil: false,
            ideal: true,
            arc: true,
        };
        let header = table::header(&keys, &signals, columns);
        let mut failed = record(2);
        failed.outcome = None;
        failed.probes.clear();
        failed.verdict = SampleVerdict::Error;
        failed.error = Some("ngspice failed: timeout, after 60 s".into());
        let records = vec![record(0), record(1), failed];
        let mut bytes = header.clone();
        bytes.extend(table::rows(&records, 2, 1, columns));
        let whole = bytes.len();
        bytes.extend(b"3,1.5e-4,0.1,stu");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sweep.csv");
        std::fs::write(&path, &bytes).unwrap();
        let mut back = Vec::new();
        let kept = finished_rows(&path, &header, 2, 1, columns, Shard::WHOLE, |r| {
            back.push(r);
            Ok::<_, ResumeError>(())
        })
        .unwrap();
        assert_eq!(back, records);
        assert_eq!(kept, whole as u64);
        truncate_to_whole_lines(&path).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), bytes[..whole]);
        assert_eq!(row_count(&bytes[..whole]), 3);

        // Rows of another shard's sequence are not this sweep's.
        let shard: Shard = "2/3".parse().unwrap();
        let err = finished_rows(&path, &header, 2, 1, columns, shard, |_| {
            Ok::<_, ResumeError>(())
        })
        .unwrap_err();
        assert!(
            err.to_string().contains("sample 0 where 1 was due"),
            "{err}"
        );
    }

    #[test]
    fn the_identity_file_names_what_differs() {
        let ours = Identity {
            tool: "chatterspice 0.1.0".into(),
            scenario_digest: digest(&[b"a", b"b"]),
            seed: Some(7),
            samples: 64,
            shard: None,
            mode: "circuit".into(),
            ideal: false,
        };
        assert_ne!(digest(&[b"a", b"b"]), digest(&[b"ab"]));
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("sweep.csv");
        assert_eq!(meta_path(&csv), dir.path().join("sweep.meta.json"));
        let write = |identity: &Identity, complete: bool| {
            let meta = Meta {
                identity: identity.clone(),
                complete,
                rows: 3,
            };
            std::fs::write(meta_path(&csv), meta.to_json()).unwrap();
        };
        write(&ours, false);
        let meta = meta_path(&csv);
        assert_eq!(check_meta(&meta, &ours).unwrap().rows, 3);
        write(
            &Identity {
                seed: Some(8),
                ..ours.clone()
            },
            false,
        );
        let err = check_meta(&meta, &ours).unwrap_err().to_string();
        assert!(err.contains("seed is 8, this one's is 7"), "{err}");
        write(&ours, true);
        let err = check_meta(&meta, &ours).unwrap_err().to_string();
        assert!(err.contains("complete"), "{err}");
    }
}
