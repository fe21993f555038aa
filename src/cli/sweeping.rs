//! `chatterspice sweep` and `chatterspice merge`: the sweep's files in
//! `--out` (written row by row, kept at a signal for `--resume`) and the
//! shards joined.

use std::io::{self, IsTerminal, Read};
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;

use chatterspice::pipeline::RunOptions;
use chatterspice::report;
use chatterspice::scenario::Scenario;
use chatterspice::spice::Ngspice;
use chatterspice::sweep::{self, Sampler, Shard, SweepMode, SweepOptions};

use super::{SimulatorArgs, Status, emit};

#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Scenario file (TOML) with a [sweep] section; `-` reads it from stdin.
    #[arg(value_name = "SCENARIO")]
    pub scenario: PathBuf,

    /// Random samples to run [default: `sweep.samples`, else 100]. Not
    /// with a [sweep.grid], which runs each of its points.
    #[arg(long, value_name = "N")]
    pub samples: Option<u64>,

    /// Seed of the random draws [default: `sweep.seed`, else 0].
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,

    /// Samples run at once [default: one per core]. With ngspice, each
    /// sample is one ngspice process: J is the most ngspice processes at
    /// once.
    #[arg(short = 'j', long, value_name = "J")]
    pub jobs: Option<NonZeroUsize>,

    /// Directory for sweep.csv, summary.json, sweep.svg and sweep.png (created if
    /// needed) [default: the current directory]. Existing files there are
    /// an error unless --force.
    #[arg(long, value_name = "DIR", conflicts_with = "resume")]
    pub out: Option<PathBuf>,

    /// Continue the sweep interrupted in DIR (by Ctrl-C or a signal) from
    /// its finished rows: the scenario, seed, sample count, shard and
    /// options must be the same (checked against DIR's sweep.meta.json);
    /// the files written are those of an uninterrupted run.
    #[arg(long, value_name = "DIR", conflicts_with = "force")]
    pub resume: Option<PathBuf>,

    /// Simulate the mechanics only (bounces and times, no circuit, no
    /// ngspice): microseconds per sample. A coil-driven relay closes on the
    /// ideal DC step of its coil (`coil.drive_voltage`, else
    /// `datasheet.coil_voltage`), as `bounce` and `check` simulate it.
    #[arg(long)]
    pub mechanics_only: bool,

    /// Run only the K-th of N slices (samples i with i % N == K-1) into
    /// sweep.K-of-N.csv; join the slices with `chatterspice merge`.
    #[arg(long, value_name = "K/N", value_parser = parse_shard)]
    pub shard: Option<Shard>,

    /// Replace files that already exist in DIR.
    #[arg(long)]
    pub force: bool,

    /// Also run each sample with an ideal contact, adding each probe's
    /// `<signal>.ideal_edges` column: two ngspice runs per sample, one
    /// after the other, so it takes twice as long.
    #[arg(long, conflicts_with = "mechanics_only")]
    pub ideal: bool,

    #[command(flatten)]
    pub simulator: SimulatorArgs,
}

#[derive(Debug, Args)]
pub struct MergeArgs {
    /// The merged CSV to write. An existing file is an error unless --force.
    #[arg(value_name = "OUT.csv")]
    pub output: PathBuf,

    /// The shards' CSVs, in any order.
    #[arg(value_name = "IN.csv", required = true)]
    pub inputs: Vec<PathBuf>,

    /// The sweep's number of samples, so that missing last samples are
    /// found too [default: up to the largest index present].
    #[arg(long, value_name = "N")]
    pub samples: Option<u64>,

    /// Write the rows there are even when samples are missing.
    #[arg(long)]
    pub allow_missing: bool,

    /// Replace OUT.csv if it already exists.
    #[arg(long)]
    pub force: bool,

    /// Accept shards that have no identity file beside them (IN.meta.json,
    /// which `sweep --shard` writes): their seed, scenario and sample count
    /// cannot be checked, and summary.json says `"identity": "unverified"`.
    /// Without it such a shard is refused.
    #[arg(long)]
    pub unverified: bool,
}

fn parse_shard(text: &str) -> Result<Shard, String> {
    text.parse::<Shard>().map_err(|e| e.to_string())
}

/// An indicatif bar on a terminal's stderr.
struct Bar(indicatif::ProgressBar);

impl sweep::Progress for Bar {
    fn start(&self, total: u64) {
        self.0.set_length(total);
    }
    fn advance(&self, done: u64) {
        self.0.inc(done);
    }
    fn finish(&self) {
        self.0.finish_and_clear();
    }
}

/// Exit status 1 when a sample failed a limit or could not run: the
/// sweep's files are written either way (by the library's
/// [`sweep::files::write`], which keeps the finished rows at a signal for
/// `--resume`).
pub fn sweep(args: &SweepArgs) -> Result<Status> {
    let (scenario, text) = load_scenario_text(&args.scenario)?;
    let sampler = Sampler::new(&scenario, args.samples, args.seed)?;
    let resume = args.resume.is_some();
    let dir = args
        .resume
        .clone()
        .or_else(|| args.out.clone())
        .unwrap_or_else(|| PathBuf::from("."));
    let ngspice = if args.mechanics_only {
        None
    } else {
        Some(args.simulator.ngspice()?)
    };
    let options = sweep_options(args, ngspice.as_ref());
    let destination = sweep::files::Destination {
        dir,
        resume,
        force: args.force,
        shard: args.shard,
    };
    let bar = progress_bar();
    let progress: &dyn sweep::Progress = match &bar {
        Some(b) => b,
        None => &sweep::NoProgress,
    };
    let written = sweep::files::write(
        &scenario,
        &text,
        &sampler,
        &options,
        &destination,
        progress,
        |note| eprintln!("{note}"),
    )?;
    let summary = written.summary;
    let mut text = summary.render_table();
    text.push_str(&format!(
        "\nwritten: {}\n",
        written
            .files
            .iter()
            .map(|f| f.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ));
    emit(&text, None, false)?;
    Ok(if summary.failing + summary.errors > 0 {
        Status::CheckFailed
    } else {
        Status::Success
    })
}

/// How the sweep runs, from the command line.
fn sweep_options<'n>(args: &SweepArgs, ngspice: Option<&'n Ngspice>) -> SweepOptions<'n> {
    let mut options = SweepOptions::new(match ngspice {
        Some(n) => SweepMode::Circuit(n),
        None => SweepMode::Mechanics,
    });
    if let Some(jobs) = args.jobs {
        options.jobs = jobs;
    }
    options.shard = args.shard.unwrap_or(Shard::WHOLE);
    // A sample is one ngspice process (two with --ideal, in turn), so
    // --jobs is the number of ngspice processes at once.
    options.run = RunOptions {
        compare_ideal: args.ideal,
        ideal_alongside: false,
        ..args.simulator.run_options()
    };
    options
}

/// A progress bar on stderr when it is a terminal.
fn progress_bar() -> Option<Bar> {
    if io::stderr().is_terminal() {
        let bar = indicatif::ProgressBar::new(0);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} samples, {per_sec}, {eta} left",
            )
            .expect("a valid template"),
        );
        Some(Bar(bar))
    } else {
        None
    }
}

/// A scenario file (or `-`, standard input) and its text, its files
/// protected as inputs.
fn load_scenario_text(path: &Path) -> Result<(Scenario, String)> {
    let text = if path == Path::new("-") {
        let mut text = String::new();
        io::stdin()
            .read_to_string(&mut text)
            .context("cannot read the scenario from standard input")?;
        text
    } else {
        chatterspice::input::read_to_string(path).map_err(|source| {
            chatterspice::scenario::ScenarioError::Read {
                path: path.to_owned(),
                source,
            }
        })?
    };
    let origin = if path == Path::new("-") {
        Path::new("<stdin>")
    } else {
        path
    };
    let scenario = Scenario::parse(&text, origin)?;
    if path != Path::new("-") {
        report::protect_input(path);
    }
    if let Some(circuit) = &scenario.circuit {
        report::protect_input(&circuit.netlist);
    }
    Ok((scenario, text))
}

pub fn merge(args: &MergeArgs) -> Result<()> {
    for input in &args.inputs {
        report::protect_input(input);
    }
    let report = sweep::merge::merge_files(
        &args.output,
        &args.inputs,
        args.samples,
        args.allow_missing,
        args.force,
        args.unverified,
    )?;
    if !report.duplicates.is_empty() {
        eprintln!(
            "note: {} sample(s) were in more than one input, with the same row: {}",
            report.duplicates.len(),
            sweep::table::ranges(&report.duplicates)
        );
    }
    if !report.missing.is_empty() {
        eprintln!(
            "warning: {} sample(s) missing: {}",
            report.missing.len(),
            sweep::table::ranges(&report.missing)
        );
    }
    eprintln!(
        "{}: {} rows from {} file(s)",
        args.output.display(),
        report.rows,
        args.inputs.len()
    );
    if args.unverified {
        eprintln!(
            "note: --unverified: shards without an identity file were merged unchecked; \
             summary.json says \"identity\": \"unverified\""
        );
    }
    Ok(())
}
