//! `chatterspice raw FILE`: a raw file (ngspice's or LTspice's) as CSV
//! (streamed for ngspice's binary files), a JSON summary of its plots,
//! every vector's count and range, or, with `--signal`, the probe analysis
//! of `run` on any raw file.

use std::io::{self, Write};
use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use serde::Serialize;

use chatterspice::analysis::{self, ProbeAnalysis};
use chatterspice::rawfile::{RawFile, export, stream_csv};
use chatterspice::report;
use chatterspice::scenario::Probe;

#[derive(Debug, Args)]
pub struct RawArgs {
    /// The raw file (ngspice or LTspice, binary or ASCII).
    pub file: PathBuf,
    /// Plot to use, numbered from 0 in file order (each step of an LTspice
    /// `.step` run is a plot) [default: the last].
    #[arg(long)]
    pub plot: Option<usize>,
    /// Output format [default: csv; table with --signal].
    #[arg(long, value_enum)]
    pub format: Option<RawFormat>,
    /// Analyse this vector as `run` analyses a probe (edges, glitches,
    /// first/last edge, shortest pulse, min, max): `v(node)`, `v(a,b)` or
    /// `i(source)`. Repeatable.
    #[arg(long, value_name = "S")]
    pub signal: Vec<String>,
    /// The Schmitt threshold going down, in the signal's unit; one for
    /// every --signal, or one each in order.
    #[arg(long, value_name = "L", allow_negative_numbers = true)]
    pub low: Vec<f64>,
    /// The Schmitt threshold going up; one for every --signal, or one each.
    #[arg(long, value_name = "H", allow_negative_numbers = true)]
    pub high: Vec<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RawFormat {
    /// One plot: a header of vector names, one row per point.
    Csv,
    /// A summary of every plot (name, flags, variables, points) or, with
    /// --signal, the probe analyses.
    Json,
    /// Every plot's vectors with their count, minimum and maximum (of the
    /// magnitude, for complex values): reads every value.
    Stats,
    /// With --signal: a table of the probe analyses, for people.
    Table,
}

pub fn raw(args: &RawArgs) -> Result<()> {
    if !args.signal.is_empty() {
        return probes(args);
    }
    if !args.low.is_empty() || !args.high.is_empty() {
        bail!("--low and --high are the thresholds of a --signal: name the vector to analyse");
    }
    let format = args.format.unwrap_or(RawFormat::Csv);
    if format == RawFormat::Table {
        bail!("--format table shows probe analyses: add --signal S --low L --high H");
    }
    if format == RawFormat::Csv {
        // Binary files from batch runs stream in bounded memory; anything
        // else is read whole below.
        let mut out = io::BufWriter::new(io::stdout().lock());
        match stream_csv(&args.file, args.plot, &mut out) {
            Ok(Some(warnings)) => {
                for w in &warnings {
                    eprintln!("warning: {}: {w}", args.file.display());
                }
                return Ok(());
            }
            Ok(None) => {}
            Err(e) if e.is_broken_pipe() => return Ok(()),
            Err(e) => return Err(e.into()),
        }
    }
    let raw = RawFile::read(&args.file)?;
    for w in &raw.warnings {
        eprintln!("warning: {}: {w}", args.file.display());
    }
    // Checked for JSON too, so a wrong index is never silently ignored.
    let selected = export::select_plot(&raw, args.plot)
        .with_context(|| format!("in {}", args.file.display()))?;
    let mut out = io::BufWriter::new(io::stdout().lock());
    let written = match format {
        RawFormat::Json => out
            .write_all(export::summary_json(&raw).as_bytes())
            .map_err(export::ExportError::Write),
        RawFormat::Stats => out
            .write_all(export::stats_table(&raw).as_bytes())
            .map_err(export::ExportError::Write),
        _ => export::plot_csv(selected, &mut out),
    }
    .and_then(|()| out.flush().map_err(export::ExportError::Write));
    match written {
        // The reader stopped early (`| head`): not our failure.
        Err(e) if e.is_broken_pipe() => Ok(()),
        result => Ok(result?),
    }
}

#[derive(Serialize)]
struct ProbesJson<'a> {
    source: String,
    plot: usize,
    plot_name: &'a str,
    points: usize,
    probes: &'a [ProbeAnalysis],
    warnings: Vec<String>,
}

/// `--signal`: each vector's probe analysis in the chosen plot.
fn probes(args: &RawArgs) -> Result<()> {
    let n = args.signal.len();
    let thresholds = |values: &[f64], flag: &str| -> Result<Vec<f64>> {
        match values.len() {
            1 => Ok(vec![values[0]; n]),
            k if k == n => Ok(values.to_vec()),
            0 => bail!(
                "--signal needs --low and --high, the Schmitt thresholds in the signal's unit \
                 (e.g. --low 0.99 --high 2.31 for a 3.3 V logic input)"
            ),
            k => bail!("{k} values of --{flag} for {n} --signal: give one for all, or one each"),
        }
    };
    let lows = thresholds(&args.low, "low")?;
    let highs = thresholds(&args.high, "high")?;
    let raw = RawFile::read(&args.file)?;
    let count = raw.plots.len();
    let index = args.plot.unwrap_or(count.saturating_sub(1));
    let plot = export::select_plot(&raw, Some(index))
        .with_context(|| format!("in {}", args.file.display()))?;
    let mut warnings: Vec<String> = raw.warnings.iter().map(ToString::to_string).collect();
    let mut results = Vec::with_capacity(n);
    for ((signal, &low), &high) in args.signal.iter().zip(&lows).zip(&highs) {
        if !(low.is_finite() && high.is_finite() && low < high) {
            bail!(
                "--signal {signal}: --low {low} and --high {high}: the thresholds must be \
                 finite numbers with low < high"
            );
        }
        let probe = Probe::new(signal.clone(), low, high);
        let analysed = analysis::analyze(plot, &probe, &[])
            .with_context(|| format!("{}: plot {index}", args.file.display()))?;
        warnings.extend(analysed.threshold_warning());
        results.push(analysed);
    }
    for w in &warnings {
        eprintln!("warning: {}: {w}", args.file.display());
    }
    let text = match args.format.unwrap_or(RawFormat::Table) {
        RawFormat::Json => {
            let doc = ProbesJson {
                source: args.file.display().to_string(),
                plot: index,
                plot_name: &plot.name,
                points: plot.points(),
                probes: &results,
                warnings,
            };
            let mut text = serde_json::to_string_pretty(&doc).expect("serializes");
            text.push('\n');
            text
        }
        RawFormat::Table => report::table::render_probes(&results),
        RawFormat::Csv | RawFormat::Stats => {
            bail!(
                "--format csv and stats describe the vectors themselves; with --signal choose \
                 table or json"
            )
        }
    };
    let mut out = io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r?),
    }
}
