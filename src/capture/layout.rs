//! Instrument CSV layouts: from a scope's export to a time axis and its
//! value channels.
//!
//! The layout is recognised from the file itself:
//!
//! - **plain**: a header row (`time,value`, `Time (ms),CH1 (V)`,
//!   `t [us],v`), then rows of numbers; units in the time header honoured;
//! - **Tektronix TDS**: every row carries settings in columns 1–3
//!   (`Record Length,2500,`, `Sample Interval,...`, `Source,CH1`, ...) and
//!   the time and value in columns 4 and 5;
//! - **Tektronix MSO/MDO**: `key,value` metadata rows (`Model,MSO54`, ...),
//!   then a `TIME,CH1[,CH2...]` header, then data;
//! - **Keysight / Agilent InfiniiVision**: `x-axis,1[,2...]` then a unit row
//!   `second,Volt[,Volt...]`, then data;
//! - **Rigol**: `X,CH1[,CH2...],Start,Increment`, then a unit row
//!   `Sequence,Volt[,...],<start>,<increment>`, then rows of sample number
//!   and values: t = start + n·increment;
//! - **Siglent**: `key,value` metadata rows (`Record Length`, `Sample
//!   Interval`, ...), then a `Second,Value` (or `Second,CH1,...`) header;
//! - **PicoScope**: a name row `Time,Channel A[,Channel B]`, a unit row
//!   `(ms),(V)[,(V)]`, a blank line, then data.
//!
//! CRLF line ends, a byte-order mark, quoted fields and trailing commas are
//! accepted. Anything unreadable is an error naming the line and column.

use std::path::{Path, PathBuf};

use thiserror::Error;

/// Which exporter wrote the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// A header row, then rows of time and values.
    Plain,
    /// Tektronix TDS: settings in columns 1–3, time and value in 4 and 5.
    TektronixTds,
    /// Tektronix MSO/MDO: metadata rows, then a `TIME,CH1,...` header.
    TektronixMso,
    /// Keysight / Agilent InfiniiVision: `x-axis,1,...` and a unit row.
    Keysight,
    /// Rigol: sample numbers, with `Start` and `Increment` giving the time.
    Rigol,
    /// Siglent: metadata rows, then a `Second,Value` header.
    Siglent,
    /// PicoScope: a name row, a unit row and a blank line.
    PicoScope,
}

impl Layout {
    /// The layout's name in reports, e.g. `tektronix-mso`.
    pub fn as_str(self) -> &'static str {
        match self {
            Layout::Plain => "plain",
            Layout::TektronixTds => "tektronix-tds",
            Layout::TektronixMso => "tektronix-mso",
            Layout::Keysight => "keysight",
            Layout::Rigol => "rigol",
            Layout::Siglent => "siglent",
            Layout::PicoScope => "picoscope",
        }
    }
}

/// One channel of a capture, times in s.
#[derive(Debug, Clone, PartialEq)]
pub struct Trace {
    /// The exporter that wrote the file.
    pub layout: Layout,
    /// The channel's name as the file gives it.
    pub channel: String,
    /// Every channel the file has, in order.
    pub channels: Vec<String>,
    /// s, strictly increasing, at least 3 samples.
    pub time: Vec<f64>,
    /// The channel's samples in the file's unit (usually V), one per time.
    pub value: Vec<f64>,
}

/// Why a capture could not be read.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CaptureError {
    /// The file cannot be read.
    #[error("{}: cannot read the capture", path.display())]
    Io {
        /// The capture file.
        path: PathBuf,
        /// Why it cannot be read.
        #[source]
        source: std::io::Error,
    },
    /// A cell that must hold a number (a time, a value, a unit) does not.
    #[error("{}:{line}: column {column}: {problem}", path.display())]
    Cell {
        /// The capture file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// What was expected and what was found.
        problem: String,
    },
    /// The file as a whole does not make a trace: empty, no such channel,
    /// fewer than 3 samples, times that do not increase, ...
    #[error("{}: {problem}", path.display())]
    File {
        /// The capture file.
        path: PathBuf,
        /// What is wrong and how to fix it.
        problem: String,
    },
}

/// A row of cells with its 1-based line number.
struct Row {
    line: usize,
    cells: Vec<String>,
}

/// Splits CSV text into rows (quoted fields, CRLF, BOM; blank lines kept
/// as empty rows, since PicoScope's blank line is part of its layout).
/// The separator is a comma, or the semicolon or tab that exports in
/// locales with a decimal comma use (`-1,5E-03;0,052`), whose numbers are
/// then read with the comma as the decimal point.
fn rows(text: &str) -> Vec<Row> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let delimiter = delimiter(text);
    text.lines()
        .enumerate()
        .map(|(i, line)| {
            let mut cells = split(line.trim_end_matches('\r'), delimiter);
            if delimiter != ',' {
                for cell in &mut cells {
                    if cell.contains(',') && !cell.contains('.') {
                        let dotted = cell.replace(',', ".");
                        if number(&dotted).is_some() {
                            *cell = dotted;
                        }
                    }
                }
            }
            Row { line: i + 1, cells }
        })
        .collect()
}

/// `;` or a tab when the file's last lines (its data) are separated by
/// one of them on every line, else `,`.
fn delimiter(text: &str) -> char {
    let tail: Vec<&str> = text
        .lines()
        .rev()
        .filter(|l| !l.trim().is_empty())
        .take(20)
        .collect();
    [';', '\t']
        .into_iter()
        .find(|&d| !tail.is_empty() && tail.iter().all(|l| l.contains(d)))
        .unwrap_or(',')
}

fn split(line: &str, delimiter: char) -> Vec<String> {
    let mut cells = Vec::new();
    let mut cell = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cell.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            c if c == delimiter && !quoted => {
                cells.push(std::mem::take(&mut cell).trim().to_owned());
            }
            _ => cell.push(c),
        }
    }
    cells.push(cell.trim().to_owned());
    // Trailing commas leave empty cells.
    while cells.len() > 1 && cells.last().is_some_and(String::is_empty) {
        cells.pop();
    }
    if cells.len() == 1 && cells[0].is_empty() {
        cells.clear();
    }
    cells
}

fn number(cell: &str) -> Option<f64> {
    let v: f64 = cell.trim().parse().ok()?;
    v.is_finite().then_some(v)
}

/// Seconds per unit of a time header such as `Time (ms)`, `t [us]`,
/// `time_ns`, `(ms)`, `second`, `s`; `None` when it names no unit.
pub fn time_unit(header: &str) -> Option<f64> {
    let h = header.trim().to_ascii_lowercase();
    let inner = h
        .rsplit_once(['(', '['])
        .map(|(_, u)| u.trim_end_matches([')', ']']).trim().to_owned())
        .or_else(|| h.rsplit_once(['_', ' ']).map(|(_, u)| u.trim().to_owned()))
        .unwrap_or_else(|| h.clone());
    let scale = match inner.as_str() {
        "s" | "sec" | "second" | "seconds" => 1.0,
        "ms" | "msec" => 1e-3,
        "us" | "µs" | "μs" | "usec" => 1e-6,
        "ns" | "nsec" => 1e-9,
        "ps" => 1e-12,
        "ks" => 1e3,
        _ => return None,
    };
    Some(scale)
}

/// Reads the capture at `path`; `channel` picks a value channel by name
/// (`CH2`, `2`, `Channel B`, `B`) or 1-based number (default: the first).
pub fn read_capture(path: &Path, channel: Option<&str>) -> Result<Trace, CaptureError> {
    let text = crate::input::read_to_string(path).map_err(|source| CaptureError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_capture(&text, path, channel)
}

/// [`read_capture`] on text; `path` names it in errors.
pub fn parse_capture(
    text: &str,
    path: &Path,
    channel: Option<&str>,
) -> Result<Trace, CaptureError> {
    let rows = rows(text);
    let file_err = |problem: String| CaptureError::File {
        path: path.to_path_buf(),
        problem,
    };
    let first = rows
        .iter()
        .find(|r| !r.cells.is_empty())
        .ok_or_else(|| file_err("the file is empty".to_owned()))?;
    let key = |r: &Row, k: &str| r.cells.first().is_some_and(|c| c.eq_ignore_ascii_case(k));

    // Tektronix TDS: settings in columns 1–3 of data rows.
    if key(first, "Record Length") && first.cells.len() >= 5 {
        return tds(&rows, path, channel);
    }
    // Keysight: x-axis,1,2 then second,Volt.
    if key(first, "x-axis") {
        let names: Vec<String> = first.cells[1..].to_vec();
        return table(
            &rows,
            first.line,
            1,
            path,
            channel,
            Layout::Keysight,
            names,
            None,
        );
    }
    // Rigol: X,CH1,...,Start,Increment.
    if key(first, "X")
        && first
            .cells
            .iter()
            .any(|c| c.eq_ignore_ascii_case("Increment"))
    {
        return rigol(&rows, first, path, channel);
    }
    // Otherwise: metadata rows, then the header row right before the data.
    let data_start = rows
        .iter()
        .position(|r| {
            r.cells.len() >= 2 && number(&r.cells[0]).is_some() && number(&r.cells[1]).is_some()
        })
        .ok_or_else(|| {
            file_err("no rows of numbers: expected a time column and a value column".to_owned())
        })?;
    let header_index = rows[..data_start]
        .iter()
        .rposition(|r| r.cells.len() >= 2 && !r.cells[0].starts_with('('));
    let unit_row = rows[..data_start]
        .iter()
        .rposition(|r| r.cells.first().is_some_and(|c| c.starts_with('(')));
    let metadata = |k: &str| rows[..data_start].iter().any(|r| key(r, k));
    let Some(h) = header_index else {
        // No header at all: two or more columns of numbers.
        let n = rows[data_start].cells.len() - 1;
        let names = (1..=n).map(|i| format!("{i}")).collect();
        return table(
            &rows,
            rows[data_start].line - 1,
            0,
            path,
            channel,
            Layout::Plain,
            names,
            Some(1.0),
        );
    };
    let header = &rows[h];
    let names: Vec<String> = header.cells[1..].to_vec();
    if let Some(u) = unit_row.filter(|&u| u > h) {
        // PicoScope: the units are on their own row.
        let scale = time_unit(&rows[u].cells[0]).ok_or_else(|| CaptureError::Cell {
            path: path.to_path_buf(),
            line: rows[u].line,
            column: 1,
            problem: format!(
                "`{}` is not a time unit such as (s), (ms), (us)",
                rows[u].cells[0]
            ),
        })?;
        return table(
            &rows,
            rows[u].line,
            0,
            path,
            channel,
            Layout::PicoScope,
            names,
            Some(scale),
        );
    }
    let layout = if header.cells[0].eq_ignore_ascii_case("TIME") && h > 0 {
        Layout::TektronixMso
    } else if metadata("Sample Interval") || header.cells[0].eq_ignore_ascii_case("Second") {
        Layout::Siglent
    } else {
        Layout::Plain
    };
    let scale = time_unit(&header.cells[0]).unwrap_or(1.0);
    table(
        &rows,
        header.line,
        0,
        path,
        channel,
        layout,
        names,
        Some(scale),
    )
}

/// Picks the value column: by name (case-insensitive, `CH2` = `2`,
/// `Channel B` = `B`) or 1-based number.
fn pick(names: &[String], channel: Option<&str>, path: &Path) -> Result<usize, CaptureError> {
    let Some(want) = channel else { return Ok(0) };
    let norm = |s: &str| {
        let s = s.trim().to_ascii_lowercase();
        let s = s.split(['(', '[']).next().unwrap_or("").trim().to_owned();
        s.trim_start_matches("channel")
            .trim_start_matches("ch")
            .trim()
            .to_owned()
    };
    if let Some(i) = names.iter().position(|n| norm(n) == norm(want)) {
        return Ok(i);
    }
    if let Ok(n) = want.trim().parse::<usize>() {
        if (1..=names.len()).contains(&n) {
            return Ok(n - 1);
        }
    }
    Err(CaptureError::File {
        path: path.to_path_buf(),
        problem: format!("no channel `{want}`: the capture has {}", names.join(", ")),
    })
}

/// Data rows after line `header_line`, skipping `skip` rows (a unit row),
/// with time in column 0 (scaled to s by `scale`, or read from a unit row
/// when `None`) and values after it.
#[allow(clippy::too_many_arguments)]
fn table(
    rows: &[Row],
    header_line: usize,
    skip: usize,
    path: &Path,
    channel: Option<&str>,
    layout: Layout,
    names: Vec<String>,
    scale: Option<f64>,
) -> Result<Trace, CaptureError> {
    let names: Vec<String> = names.into_iter().filter(|n| !n.is_empty()).collect();
    if names.is_empty() {
        return Err(CaptureError::File {
            path: path.to_path_buf(),
            problem: "no value column after the time column".to_owned(),
        });
    }
    let col = pick(&names, channel, path)?;
    let mut after = rows.iter().filter(|r| r.line > header_line);
    let mut scale = scale;
    for _ in 0..skip {
        if let Some(units) = after.next() {
            if scale.is_none() || layout == Layout::Keysight {
                scale = units.cells.first().and_then(|u| time_unit(u)).or(Some(1.0));
            }
        }
    }
    let scale = scale.unwrap_or(1.0);
    let (mut time, mut value) = (Vec::new(), Vec::new());
    for r in after {
        if r.cells.is_empty() {
            continue;
        }
        let t = cell(r, 0, path, "a time")?;
        let v = cell(r, col + 1, path, "a value")?;
        time.push(t * scale);
        value.push(v);
    }
    finish(layout, names[col].clone(), names, time, value, path)
}

fn cell(r: &Row, i: usize, path: &Path, what: &str) -> Result<f64, CaptureError> {
    let text = r.cells.get(i).map_or("", String::as_str);
    number(text).ok_or_else(|| CaptureError::Cell {
        path: path.to_path_buf(),
        line: r.line,
        column: i + 1,
        problem: if text.is_empty() {
            format!("expected {what}, found nothing")
        } else {
            format!("expected {what}, found `{text}`")
        },
    })
}

fn finish(
    layout: Layout,
    channel: String,
    channels: Vec<String>,
    time: Vec<f64>,
    value: Vec<f64>,
    path: &Path,
) -> Result<Trace, CaptureError> {
    if time.len() < 3 {
        return Err(CaptureError::File {
            path: path.to_path_buf(),
            problem: format!("{} samples: a capture needs at least 3", time.len()),
        });
    }
    if let Some(k) = (1..time.len()).find(|&k| time[k] <= time[k - 1]) {
        return Err(CaptureError::File {
            path: path.to_path_buf(),
            problem: format!(
                "sample {} at {:e} s does not follow {:e} s: times must increase",
                k + 1,
                time[k],
                time[k - 1]
            ),
        });
    }
    Ok(Trace {
        layout,
        channel,
        channels,
        time,
        value,
    })
}

/// Tektronix TDS: time and value in columns 4 and 5 of every row, the
/// source channel in the `Source` row's column 2.
fn tds(rows: &[Row], path: &Path, channel: Option<&str>) -> Result<Trace, CaptureError> {
    let source = rows
        .iter()
        .find(|r| {
            r.cells
                .first()
                .is_some_and(|c| c.eq_ignore_ascii_case("Source"))
        })
        .and_then(|r| r.cells.get(1).cloned())
        .unwrap_or_else(|| "CH1".to_owned());
    if let Some(want) = channel {
        pick(std::slice::from_ref(&source), Some(want), path)?;
    }
    let (mut time, mut value) = (Vec::new(), Vec::new());
    for r in rows.iter().filter(|r| !r.cells.is_empty()) {
        time.push(cell(r, 3, path, "a time")?);
        value.push(cell(r, 4, path, "a value")?);
    }
    finish(
        Layout::TektronixTds,
        source.clone(),
        vec![source],
        time,
        value,
        path,
    )
}

/// Rigol: `X,CH1,...,Start,Increment`, then `Sequence,Volt,...,start,inc`.
fn rigol(
    rows: &[Row],
    header: &Row,
    path: &Path,
    channel: Option<&str>,
) -> Result<Trace, CaptureError> {
    let start_col = header
        .cells
        .iter()
        .position(|c| c.eq_ignore_ascii_case("Start"))
        .ok_or_else(|| CaptureError::Cell {
            path: path.to_path_buf(),
            line: header.line,
            column: header.cells.len(),
            problem: "a Rigol header needs `Start` and `Increment` columns".to_owned(),
        })?;
    let names: Vec<String> = header.cells[1..start_col].to_vec();
    let col = pick(&names, channel, path)?;
    let mut after = rows
        .iter()
        .filter(|r| r.line > header.line && !r.cells.is_empty());
    let units = after.next().ok_or_else(|| CaptureError::File {
        path: path.to_path_buf(),
        problem: "the Rigol header is not followed by its unit row with start and increment"
            .to_owned(),
    })?;
    let start = cell(units, start_col, path, "the start time")?;
    let increment = cell(units, start_col + 1, path, "the sample increment")?;
    if increment <= 0.0 {
        return Err(CaptureError::Cell {
            path: path.to_path_buf(),
            line: units.line,
            column: start_col + 2,
            problem: format!("the increment {increment:e} s must be > 0"),
        });
    }
    let (mut time, mut value) = (Vec::new(), Vec::new());
    for r in after {
        let n = cell(r, 0, path, "a sample number")?;
        time.push(start + n * increment);
        value.push(cell(r, col + 1, path, "a value")?);
    }
    finish(Layout::Rigol, names[col].clone(), names, time, value, path)
}
