//! The command line: clap definitions and one handler per command.
//!
//! Handlers only read inputs, call the library, and print or write its
//! output; errors go back to `main` as `anyhow` errors with context, and
//! `main` turns them into a message and an exit code. To add a command,
//! add a variant to [`Command`], its `Args` struct, and a handler.

use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};

use chatterspice::mechanics::Dimensionless;
use chatterspice::rawfile::{RawFile, export};
use chatterspice::report::{self, Format};
use chatterspice::scenario::Scenario;
use chatterspice::simulate;

/// Relay contact bounce from physics, into circuit simulation.
#[derive(Debug, Parser)]
#[command(name = "chatterspice", version)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Mechanics only: the chatter sequence of one closing.
    Bounce(BounceArgs),
    /// Print a SPICE raw file: one plot as CSV, or a JSON summary of every plot.
    Raw(RawArgs),
}

impl Command {
    pub fn run(&self) -> Result<()> {
        match self {
            Command::Bounce(args) => bounce(args),
            Command::Raw(args) => raw(args),
        }
    }
}

#[derive(Debug, Args)]
pub struct BounceArgs {
    /// Scenario file (TOML); `-` reads it from stdin. Without it, the
    /// built-in default: a small signal relay.
    #[arg(value_name = "SCENARIO")]
    pub scenario: Option<PathBuf>,

    /// Output format.
    #[arg(long, value_enum, default_value_t = BounceFormat::Table)]
    pub format: BounceFormat,

    /// Write the report to FILE instead of standard output. An existing
    /// FILE is an error unless --force.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,

    /// Replace FILE if it already exists.
    #[arg(long, requires = "output")]
    pub force: bool,
}

#[derive(Debug, Args)]
pub struct RawArgs {
    /// The raw file (ngspice binary or ASCII).
    pub file: PathBuf,
    /// Plot to print as CSV, numbered from 0 in file order [default: the last].
    #[arg(long)]
    pub plot: Option<usize>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = RawFormat::Csv)]
    pub format: RawFormat,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RawFormat {
    /// One plot: a header of vector names, one row per point.
    Csv,
    /// A summary of every plot: name, flags, variables, points.
    Json,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BounceFormat {
    /// The JSON of interfaces.md §3, for scripts.
    Json,
    /// One row per impact, for spreadsheets.
    Csv,
    /// A summary and an impact table, for people.
    Table,
}

impl From<BounceFormat> for Format {
    fn from(f: BounceFormat) -> Format {
        match f {
            BounceFormat::Json => Format::Json,
            BounceFormat::Csv => Format::Csv,
            BounceFormat::Table => Format::Table,
        }
    }
}

fn bounce(args: &BounceArgs) -> Result<()> {
    refuse_existing(args.output.as_deref(), args.force)?;
    let scenario = load_scenario(args.scenario.as_deref())?;
    let mechanics = scenario.mechanics()?;
    let surface = scenario.surface();
    let chatter = simulate(&mechanics, &surface, &scenario.settings()).with_context(|| {
        format!(
            "{}: the mechanics simulation failed",
            scenario.origin.display()
        )
    })?;
    let dimensionless = Dimensionless::of(&mechanics, &surface);
    let text = report::render(args.format.into(), &chatter, Some(&dimensionless));
    emit(&text, args.output.as_deref(), args.force)
}

/// The named scenario file, stdin for `-`, or the built-in default.
fn load_scenario(path: Option<&Path>) -> Result<Scenario> {
    match path {
        None => Ok(Scenario::builtin_default()),
        Some(p) if p == Path::new("-") => {
            let mut text = String::new();
            io::stdin()
                .read_to_string(&mut text)
                .context("cannot read the scenario from standard input")?;
            // Relative paths in it resolve against the working directory.
            Ok(Scenario::parse(&text, Path::new("<stdin>"))?)
        }
        Some(p) => Ok(Scenario::load(p)?),
    }
}

/// Fail before doing any work if the output file exists; the write itself
/// re-checks, so a file created meanwhile is not clobbered either.
fn refuse_existing(output: Option<&Path>, force: bool) -> Result<()> {
    let Some(path) = output else {
        return Ok(());
    };
    if !force && path.symlink_metadata().is_ok() {
        bail!(
            "{}: already exists; pass --force to overwrite it, or choose another file",
            path.display()
        );
    }
    Ok(())
}

fn emit(text: &str, output: Option<&Path>, force: bool) -> Result<()> {
    match output {
        Some(path) => Ok(report::write_new_file(path, text.as_bytes(), force)?),
        None => {
            let mut stdout = io::stdout().lock();
            match stdout
                .write_all(text.as_bytes())
                .and_then(|()| stdout.flush())
            {
                // The reader stopped early (`| head`): not our failure.
                Err(e) if e.kind() == io::ErrorKind::BrokenPipe => Ok(()),
                result => result.context("cannot write to standard output"),
            }
        }
    }
}

fn raw(args: &RawArgs) -> Result<()> {
    let raw = RawFile::read(&args.file)?;
    for w in &raw.warnings {
        eprintln!("warning: {}: {w}", args.file.display());
    }
    // Checked for JSON too, so a wrong index is never silently ignored.
    let selected = export::select_plot(&raw, args.plot)
        .with_context(|| format!("in {}", args.file.display()))?;
    let mut out = io::BufWriter::new(io::stdout().lock());
    let written = match args.format {
        RawFormat::Csv => export::plot_csv(selected, &mut out),
        RawFormat::Json => out
            .write_all(export::summary_json(&raw).as_bytes())
            .map_err(export::ExportError::Write),
    }
    .and_then(|()| out.flush().map_err(export::ExportError::Write));
    match written {
        // The reader stopped early (`| head`): not our failure.
        Err(e) if e.is_broken_pipe() => Ok(()),
        result => Ok(result?),
    }
}
