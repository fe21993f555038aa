//! `chatterspice capture SCOPE.csv`: a scope capture of the contact → the
//! chatter it shows.

use std::fmt::Write as _;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};

use chatterspice::capture::{Capture, Closed, Trace, read_capture};
use chatterspice::report::{self, units::engineering};

use super::{emit, refuse_existing};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum CaptureFormat {
    /// Levels, thresholds and every edge, for people.
    Table,
    /// The capture object (docs/output.md), for scripts.
    Json,
    /// The `time,state` file that `--measured` reads.
    Csv,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ClosedLevel {
    High,
    Low,
}

#[derive(Debug, Args)]
pub struct CaptureArgs {
    /// The scope's CSV export (plain time,value; Tektronix, Keysight, Rigol,
    /// Siglent or PicoScope layouts are recognised).
    #[arg(value_name = "SCOPE.csv")]
    pub file: PathBuf,
    /// The channel: its name (CH2, 2, Channel B) or number [default: the
    /// first].
    #[arg(long, value_name = "NAME|N")]
    pub channel: Option<String>,
    /// The lower hysteresis threshold, in the trace's unit [default: 30 %
    /// of the way between the levels]. Give --high too. With given
    /// thresholds each edge is timed where it crosses the far one (a fall
    /// at --low, a rise at --high), as a Schmitt input switches; with the
    /// defaults, at its 50 % crossing.
    #[arg(
        long,
        value_name = "V",
        allow_negative_numbers = true,
        requires = "high"
    )]
    pub low: Option<f64>,
    /// The upper threshold [default: 70 % of the way]. Give --low too.
    #[arg(
        long,
        value_name = "V",
        allow_negative_numbers = true,
        requires = "low"
    )]
    pub high: Option<f64>,
    /// Which level is the closed contact [default: the one the trace ends
    /// on].
    #[arg(long, value_enum)]
    pub closed: Option<ClosedLevel>,
    #[arg(long, value_enum, default_value_t = CaptureFormat::Table)]
    pub format: CaptureFormat,
    /// Write to FILE instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,
    /// Replace FILE if it exists.
    #[arg(long)]
    pub force: bool,
}

/// Reads and analyses the capture `file`: its trace and what it shows.
pub fn analyse(
    file: &std::path::Path,
    channel: Option<&str>,
    thresholds: Option<(f64, f64)>,
    closed: Option<ClosedLevel>,
) -> Result<(Trace, Capture)> {
    report::protect_input(file);
    let trace = read_capture(file, channel)?;
    let closed = closed.map(|c| match c {
        ClosedLevel::High => Closed::High,
        ClosedLevel::Low => Closed::Low,
    });
    let source = file.file_name().map_or_else(
        || file.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    let capture = Capture::of(&source, &trace, thresholds, closed)
        .with_context(|| format!("{}: channel {}", file.display(), trace.channel))?;
    Ok((trace, capture))
}

pub fn capture(args: &CaptureArgs) -> Result<()> {
    refuse_existing(args.output.as_deref(), args.force)?;
    let thresholds = args.low.zip(args.high);
    let (_, c) = analyse(&args.file, args.channel.as_deref(), thresholds, args.closed)?;
    let text = match args.format {
        CaptureFormat::Json => {
            let mut t = serde_json::to_string_pretty(&c).expect("a capture serializes");
            t.push('\n');
            t
        }
        CaptureFormat::Csv => c.state_csv(),
        CaptureFormat::Table => table(&c),
    };
    emit(&text, args.output.as_deref(), args.force)
}

fn table(c: &Capture) -> String {
    let mut out = String::new();
    let time = |t: f64| format!("{:.4} ms", t * 1e3);
    let _ = writeln!(
        out,
        "capture  {} ({} layout), channel {}: {} samples every {}",
        c.source,
        c.layout,
        c.channel,
        c.samples,
        engineering(c.sample_interval, "s")
    );
    let _ = writeln!(
        out,
        "levels   open {:.4}, closed {:.4}; thresholds {:.4} / {:.4}",
        c.levels.open, c.levels.closed, c.thresholds.low, c.thresholds.high
    );
    let _ = match (c.first_make, c.settle_time) {
        (Some(f), Some(s)) => writeln!(
            out,
            "contact  first make {}, {} bounces, closed for good {} (bounce time {})",
            time(f),
            c.bounce_count,
            time(s),
            engineering(s - f, "s")
        ),
        (Some(f), None) => writeln!(
            out,
            "contact  first make {}, {} bounces, open at the end of the capture",
            time(f),
            c.bounce_count
        ),
        _ => writeln!(out, "contact  never closes in the capture"),
    };
    out.push('\n');
    let _ = writeln!(out, "{:>4}  {:<6}  {:>12}", "#", "edge", "time");
    let mut events: Vec<(f64, &str)> = c.makes.iter().map(|&t| (t, "make")).collect();
    events.extend(c.breaks.iter().map(|&t| (t, "break")));
    events.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (i, (t, what)) in events.iter().enumerate() {
        let _ = writeln!(out, "{:>4}  {:<6}  {:>12}", i + 1, what, time(*t));
    }
    out
}
