//! What `chatterspice raw FILE` prints: one plot as CSV, a JSON summary
//! of every plot, or every vector's count, minimum and maximum.
//!
//! CSV: the header row is the vector names; a complex vector becomes two
//! columns `NAME.re`, `NAME.im` (the AC frequency axis stays one real
//! column). Values are written by `zmij`: the shortest string that reads
//! back to the identical `f64` (`0.001`, `1.5`, `0.0`, `1e-7`), so output
//! is byte-identical across runs and platforms and loses nothing. A
//! vector shorter than the plot (`unpadded`) leaves its cells empty. Large
//! binary files are streamed ([`super::stream_csv`]) with the same bytes.

use std::io::Write;

use serde::Serialize;

pub use super::error::ExportError;
use super::types::{Plot, RawFile, Vector};

/// Plot `index`, or the last plot (the main analysis after an `.op`).
pub fn select_plot(raw: &RawFile, index: Option<usize>) -> Result<&Plot, ExportError> {
    let count = raw.plots.len();
    let index = index.unwrap_or(count.saturating_sub(1));
    raw.plots
        .get(index)
        .ok_or(ExportError::NoSuchPlot { index, count })
}

/// The CSV cell text of a value (see the module doc).
pub fn format_value(x: f64) -> String {
    zmij::Buffer::new().format(x).to_owned()
}

/// Writes `plot` as CSV.
pub fn plot_csv<W: Write>(plot: &Plot, out: W) -> Result<(), ExportError> {
    let mut w = csv::Writer::from_writer(out);
    let vectors: Vec<Vector<'_>> = (0..plot.variables.len())
        .filter_map(|i| plot.vector(i))
        .collect();
    let mut header = Vec::new();
    for (var, vec) in plot.variables.iter().zip(&vectors) {
        match vec {
            Vector::Real(_) => header.push(var.name.clone()),
            Vector::Complex(_) => {
                header.push(format!("{}.re", var.name));
                header.push(format!("{}.im", var.name));
            }
        }
    }
    w.write_record(&header)?;

    let mut record = csv::ByteRecord::new();
    let mut digits = zmij::Buffer::new();
    let mut push = |record: &mut csv::ByteRecord, x: Option<f64>| match x {
        Some(x) => record.push_field(digits.format(x).as_bytes()),
        None => record.push_field(b""),
    };
    for i in 0..plot.points() {
        record.clear();
        for vec in &vectors {
            match vec {
                Vector::Real(v) => push(&mut record, v.get(i).copied()),
                Vector::Complex(v) => {
                    let c = v.get(i);
                    push(&mut record, c.map(|c| c.re));
                    push(&mut record, c.map(|c| c.im));
                }
            }
        }
        w.write_byte_record(&record)?;
    }
    w.flush()?;
    Ok(())
}

#[derive(Serialize)]
struct Summary<'a> {
    plots: Vec<PlotSummary<'a>>,
    warnings: Vec<String>,
}

#[derive(Serialize)]
struct PlotSummary<'a> {
    index: usize,
    name: &'a str,
    title: &'a str,
    date: &'a str,
    commands: &'a [String],
    dialect: &'static str,
    encoding: &'static str,
    step: Option<StepSummary>,
    flags: FlagsSummary<'a>,
    points: usize,
    declared_points: usize,
    variables: Vec<VariableSummary<'a>>,
}

#[derive(Serialize)]
struct StepSummary {
    index: usize,
    count: usize,
    first_point: usize,
}

#[derive(Serialize)]
struct FlagsSummary<'a> {
    complex: bool,
    padded: bool,
    other: &'a [String],
}

#[derive(Serialize)]
struct VariableSummary<'a> {
    index: usize,
    name: &'a str,
    #[serde(rename = "type")]
    kind: &'a str,
    complex: bool,
    points: usize,
    attributes: &'a [String],
}

/// A pretty-printed JSON summary of every plot: name, dialect (`ngspice`,
/// `ltspice`), encoding (`utf-8`, `utf-16le`), step (`null`, or `index`,
/// `count` and `first_point` for one step of a stepped plot), flags,
/// variables and point counts, plus the reader's warnings. Ends with a
/// newline.
pub fn summary_json(raw: &RawFile) -> String {
    let plots = raw
        .plots
        .iter()
        .enumerate()
        .map(|(index, p)| PlotSummary {
            index,
            name: &p.name,
            title: &p.title,
            date: &p.date,
            commands: &p.commands,
            dialect: p.dialect.as_str(),
            encoding: p.encoding.as_str(),
            step: p.step.map(|s| StepSummary {
                index: s.index,
                count: s.count,
                first_point: s.first_point,
            }),
            flags: FlagsSummary {
                complex: p.flags.complex,
                padded: p.flags.padded,
                other: &p.flags.other,
            },
            points: p.points(),
            declared_points: p.declared_points,
            variables: p
                .variables
                .iter()
                .enumerate()
                .map(|(i, v)| {
                    let vec = p.vector(i);
                    VariableSummary {
                        index: i,
                        name: &v.name,
                        kind: &v.kind,
                        complex: matches!(vec, Some(Vector::Complex(_))),
                        points: vec.map_or(0, |v| v.len()),
                        attributes: &v.attributes,
                    }
                })
                .collect(),
        })
        .collect();
    let summary = Summary {
        plots,
        warnings: raw.warnings.iter().map(ToString::to_string).collect(),
    };
    // Plain structs of strings and numbers always serialize.
    let mut s = serde_json::to_string_pretty(&summary).unwrap_or_default();
    s.push('\n');
    s
}

/// The count and range of one vector's values; for a complex vector, of
/// their magnitudes. `NaN`s are left out of the range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VectorStats {
    /// How many values the vector has.
    pub points: usize,
    /// The smallest value (magnitude); `None` when there is none but `NaN`.
    pub min: Option<f64>,
    /// The largest value (magnitude); `None` when there is none but `NaN`.
    pub max: Option<f64>,
}

impl VectorStats {
    /// The statistics of `vector`: every value is read.
    ///
    /// ```
    /// use chatterspice::rawfile::{Vector, export::VectorStats};
    ///
    /// let s = VectorStats::of(Vector::Real(&[0.5, f64::NAN, -2.0, 3.0]));
    /// assert_eq!((s.points, s.min, s.max), (4, Some(-2.0), Some(3.0)));
    /// ```
    pub fn of(vector: Vector<'_>) -> VectorStats {
        let range = match vector {
            Vector::Real(v) => range_of_slice(v),
            Vector::Complex(v) => range(v.iter().map(|c| c.norm())),
        };
        VectorStats {
            points: vector.len(),
            min: range.map(|r| r.0),
            max: range.map(|r| r.1),
        }
    }
}

/// The least and greatest of `values` that are not `NaN`.
fn range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    // `f64::min` and `max` pass over a `NaN`; a range that stays inverted
    // had no other value.
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
        (lo.min(x), hi.max(x))
    });
    (lo <= hi).then_some((lo, hi))
}

/// [`range`] of a slice, eight running ranges at a time (one chain of
/// comparisons took 3× as long).
fn range_of_slice(values: &[f64]) -> Option<(f64, f64)> {
    let mut lo = [f64::INFINITY; 8];
    let mut hi = [f64::NEG_INFINITY; 8];
    let chunks = values.chunks_exact(8);
    let rest = chunks.remainder();
    for chunk in chunks {
        for k in 0..8 {
            lo[k] = lo[k].min(chunk[k]);
            hi[k] = hi[k].max(chunk[k]);
        }
    }
    let lo = lo.iter().chain(rest).fold(f64::INFINITY, |a, &b| a.min(b));
    let hi = hi
        .iter()
        .chain(rest)
        .fold(f64::NEG_INFINITY, |a, &b| a.max(b));
    (lo <= hi).then_some((lo, hi))
}

/// A table of every plot's vectors with their [`VectorStats`]: a line
/// per plot (index, name, real or complex, points), then one per vector
/// (name, type, points, min, max; `-` for no value). Every value of every
/// vector is read, so this is also the fastest output that proves a whole
/// read. Numbers as in the CSV. Ends with a newline.
pub fn stats_table(raw: &RawFile) -> String {
    let mut out = String::new();
    let mut digits = zmij::Buffer::new();
    let mut number = |x: Option<f64>| x.map_or("-".to_owned(), |x| digits.format(x).to_owned());
    for (index, plot) in raw.plots.iter().enumerate() {
        let kind = if plot.is_complex() {
            "complex (min and max of |value|)"
        } else {
            "real"
        };
        let points = plot.points();
        let s = if points == 1 { "" } else { "s" };
        out.push_str(&format!(
            "plot {index}: {}, {kind}, {points} point{s}\n",
            plot.name
        ));
        let mut rows = vec![[
            "vector".to_owned(),
            "type".to_owned(),
            "points".to_owned(),
            "min".to_owned(),
            "max".to_owned(),
        ]];
        for (i, var) in plot.variables.iter().enumerate() {
            let Some(vector) = plot.vector(i) else {
                continue;
            };
            let stats = VectorStats::of(vector);
            rows.push([
                var.name.clone(),
                var.kind.clone(),
                stats.points.to_string(),
                number(stats.min),
                number(stats.max),
            ]);
        }
        let mut widths = [0usize; 5];
        for row in &rows {
            for (w, cell) in widths.iter_mut().zip(row) {
                *w = (*w).max(cell.chars().count());
            }
        }
        for row in &rows {
            let mut line = String::new();
            for (k, (cell, &w)) in row.iter().zip(&widths).enumerate() {
                let pad = " ".repeat(w - cell.chars().count());
                // Names to the left, numbers to the right.
                if k < 2 {
                    line.push_str(&format!("  {cell}{pad}"));
                } else {
                    line.push_str(&format!("  {pad}{cell}"));
                }
            }
            out.push_str(line.trim_end());
            out.push('\n');
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ac() -> RawFile {
        let text = "Title: t\nDate: d\nPlotname: AC Analysis\nFlags: complex\n\
                    No. Variables: 2\nNo. Points: 2\nVariables:\n\
                    \t0\tfrequency\tfrequency\tgrid=3\n\t1\tv(out)\tvoltage\nValues:\n\
                    0\t\t1e2,3e-300\n\t0.5,-0.25\n1\t\t1e3,1\n\t0.1,-0.2\n";
        RawFile::parse(text.as_bytes()).unwrap()
    }

    #[test]
    fn csv_splits_complex_and_keeps_frequency_real() {
        let raw = ac();
        let mut out = Vec::new();
        plot_csv(&raw.plots[0], &mut out).unwrap();
        assert_eq!(
            String::from_utf8(out).unwrap(),
            "frequency,v(out).re,v(out).im\n100.0,0.5,-0.25\n1000.0,0.1,-0.2\n"
        );
    }

    #[test]
    fn values_round_trip() {
        for x in [0.1, -2.2250738585072014e-308, 1.0 / 3.0, 6.02214076e23] {
            assert_eq!(format_value(x).parse::<f64>().unwrap(), x);
        }
    }

    #[test]
    fn missing_plot_says_what_exists() {
        let raw = ac();
        let err = select_plot(&raw, Some(3)).unwrap_err().to_string();
        assert!(err.contains("1 plot(s), numbered 0 to 0"), "{err}");
        assert_eq!(select_plot(&raw, None).unwrap().name, "AC Analysis");
    }

    #[test]
    fn stats_read_every_value_and_take_magnitudes_of_complex_ones() {
        let table = stats_table(&ac());
        let lines: Vec<&str> = table.lines().collect();
        assert_eq!(
            lines[0],
            "plot 0: AC Analysis, complex (min and max of |value|), 2 points"
        );
        let cells = |k: usize| lines[k].split_whitespace().collect::<Vec<_>>();
        assert_eq!(cells(1), ["vector", "type", "points", "min", "max"]);
        assert_eq!(cells(2), ["frequency", "frequency", "2", "100.0", "1000.0"]);
        // |0.1 - 0.2i| and |0.5 - 0.25i|.
        let min = format_value((0.1f64 * 0.1 + 0.2 * 0.2).sqrt());
        let max = format_value((0.5f64 * 0.5 + 0.25 * 0.25).sqrt());
        assert_eq!(cells(3), ["v(out)", "voltage", "2", &min, &max]);
        // Numbers are right-aligned under their heading.
        assert_eq!(lines[1].find("max").map(|i| i + 3), Some(lines[3].len()));
        let empty = VectorStats::of(Vector::Real(&[f64::NAN]));
        assert_eq!((empty.points, empty.min, empty.max), (1, None, None));
        // Eight lanes and a remainder: the range wherever its ends are.
        for len in [0usize, 1, 7, 8, 9, 17, 64] {
            for at in 0..len {
                let mut v: Vec<f64> = (0..len).map(|k| (k % 5) as f64).collect();
                v[at] = -1.0;
                v[len - 1 - at] = 9.0;
                if len > 2 {
                    v[(at + 1) % len] = f64::NAN;
                }
                let expected = range(v.iter().copied());
                assert_eq!(range_of_slice(&v), expected, "{len} {at}");
            }
        }
        assert_eq!(range_of_slice(&[]), None);
    }

    #[test]
    fn summary_lists_variables() {
        let json: serde_json::Value = serde_json::from_str(&summary_json(&ac())).unwrap();
        assert_eq!(json["plots"][0]["variables"][1]["name"], "v(out)");
        assert_eq!(json["plots"][0]["variables"][1]["complex"], true);
        assert_eq!(json["plots"][0]["variables"][0]["complex"], false);
        assert_eq!(json["plots"][0]["points"], 2);
    }
}
