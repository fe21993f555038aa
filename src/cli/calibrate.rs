//! `chatterspice fit` and `chatterspice parts`: parse, call the library's
//! calibration, print or write.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};

use chatterspice::calibrate::fit::{self, FitRequest, Record};
use chatterspice::calibrate::{parts, render};
use chatterspice::report;
use chatterspice::scenario::Scenario;
use chatterspice::waveform::read_state_csv;

use super::{emit, refuse_existing};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FitFormat {
    Table,
    Json,
}

#[derive(Debug, Args)]
pub struct FitArgs {
    /// Scenario file (TOML): the prior, with the keys to fit in [fit] free
    /// and any datasheet figures in [datasheet].
    #[arg(value_name = "SCENARIO")]
    pub scenario: PathBuf,

    /// A scope capture of the contact (CSV) to fit the make/break times to,
    /// on its own time axis: the time offset is the model time of its
    /// t = 0 (the trigger), whatever pre-trigger samples it holds.
    #[arg(long, value_name = "SCOPE.csv", conflicts_with = "measured")]
    pub capture: Option<PathBuf>,

    /// With --capture: the channel to read (name or number).
    #[arg(long, value_name = "NAME|N", requires = "capture")]
    pub channel: Option<String>,

    /// A `time,state` file of the contact's states to fit the make/break
    /// times to.
    #[arg(long, value_name = "CHATTER.csv")]
    pub measured: Option<PathBuf>,

    /// The keys the fit may move, replacing [fit] free (comma-separated
    /// scenario keys such as surface.damping,mechanics.preload).
    #[arg(long, value_name = "KEY,...", value_delimiter = ',')]
    pub free: Vec<String>,

    /// Write the fitted scenario (with [provenance]) to FITTED.toml.
    #[arg(short = 'o', long = "output", value_name = "FITTED.toml")]
    pub output: Option<PathBuf>,

    /// Output format of the report on standard output.
    #[arg(long, value_enum, default_value_t = FitFormat::Table)]
    pub format: FitFormat,

    /// Also write fit.json and overlay.svg (measured and fitted contact
    /// state) into DIR.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,

    /// Replace files that already exist.
    #[arg(long)]
    pub force: bool,
}

/// The record to fit and, for a scope capture, its trace, levels and
/// thresholds for the overlay plot.
type Captured = (chatterspice::capture::Trace, chatterspice::capture::Capture);

fn read_record(args: &FitArgs) -> Result<(Option<Record>, Option<Captured>)> {
    if let Some(scope) = &args.capture {
        let (trace, c) = super::capture::analyse(scope, args.channel.as_deref(), None, None)?;
        // On the capture's own time axis: the fit's time offset is the
        // model time of the record's zero (the scope's trigger), whatever
        // pre-trigger samples the record holds.
        let record = Record {
            name: c.source.clone(),
            intervals: c.intervals.clone(),
        };
        return Ok((Some(record), Some((trace, c))));
    }
    let Some(csv) = &args.measured else {
        return Ok((None, None));
    };
    let text = chatterspice::input::read_to_string(csv)
        .with_context(|| format!("{}: cannot read the measured chatter", csv.display()))?;
    let intervals = read_state_csv(&text, csv)?;
    let name = csv.file_name().map_or_else(
        || csv.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    Ok((Some(Record { name, intervals }), None))
}

pub fn fit(args: &FitArgs) -> Result<()> {
    // Outputs never replace what the fit reads.
    for input in [
        Some(&args.scenario),
        args.capture.as_ref(),
        args.measured.as_ref(),
    ]
    .into_iter()
    .flatten()
    {
        report::protect_input(input);
    }
    refuse_existing(args.output.as_deref(), args.force)?;
    let _lock = match &args.report {
        Some(dir) => {
            let lock = chatterspice::output::OutputLock::acquire(dir, "fit")?;
            for name in ["fit.json", "overlay.svg"] {
                refuse_existing(Some(&dir.join(name)), args.force)?;
            }
            Some(lock)
        }
        None => None,
    };
    let text = chatterspice::input::read_to_string(&args.scenario)
        .with_context(|| format!("{}: cannot read the scenario", args.scenario.display()))?;
    let scenario = Scenario::parse(&text, &args.scenario)?;
    if let Some(circuit) = &scenario.circuit {
        report::protect_input(&circuit.netlist);
    }
    let (record, captured) = read_record(args)?;
    let request = FitRequest {
        record: record.clone(),
        free: args.free.clone(),
    };
    let result = fit::fit(&scenario, &request)?;
    if let Some(path) = &args.output {
        // A relative netlist path is relative to the prior's directory:
        // written elsewhere, the fitted file names it absolutely.
        let same_dir = path.parent().map(Path::new) == args.scenario.parent();
        let netlist = match (&scenario.circuit, same_dir) {
            (Some(c), false) => std::fs::canonicalize(&c.netlist).ok(),
            _ => None,
        };
        let toml = fit::fitted_toml(&text, &result, netlist.as_deref())
            .with_context(|| format!("{}: cannot re-read the scenario", args.scenario.display()))?;
        report::write_new_file(path, toml.as_bytes(), args.force)?;
    }
    if let Some(dir) = &args.report {
        let intervals = record.map(|r| r.intervals).unwrap_or_default();
        let overlay = captured.as_ref().map(|(trace, c)| render::TraceOverlay {
            time: &trace.time,
            value: &trace.value,
            open: c.levels.open,
            closed: c.levels.closed,
            low: c.thresholds.low,
            high: c.thresholds.high,
        });
        let svg = render::overlay_svg_with(&intervals, &result, overlay);
        let files = [
            ("fit.json".to_owned(), render::json(&result).into_bytes()),
            ("overlay.svg".to_owned(), svg.into_bytes()),
        ];
        report::write_bundle(dir, &files, args.force)?;
    }
    let out = match args.format {
        FitFormat::Table => render::table(&result),
        FitFormat::Json => render::json(&result),
    };
    emit(&out, None, false)
}

#[derive(Debug, Args)]
pub struct PartsArgs {
    /// A bundled part: write its scenario (to -o FILE, or standard output).
    /// Without it, list the parts.
    #[arg(value_name = "NAME")]
    pub name: Option<String>,

    /// Output format: of the list; with NAME, `json` prints the part (its
    /// figures and its scenario) as JSON instead of its TOML scenario.
    #[arg(long, value_enum, default_value_t = FitFormat::Table)]
    pub format: FitFormat,

    /// Write to FILE instead of standard output.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,

    /// Replace FILE if it already exists.
    #[arg(long, requires = "output")]
    pub force: bool,
}

pub fn parts(args: &PartsArgs) -> Result<()> {
    refuse_existing(args.output.as_deref(), args.force)?;
    let text = match &args.name {
        Some(name) => match args.format {
            FitFormat::Table => parts::find(name)?.scenario.to_owned(),
            FitFormat::Json => parts::part_json(&parts::find(name)?),
        },
        None => match args.format {
            FitFormat::Table => parts::table(),
            FitFormat::Json => parts::json(),
        },
    };
    emit(&text, args.output.as_deref().map(Path::new), args.force)
}
