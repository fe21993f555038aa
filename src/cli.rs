//! The command line: clap definitions and one handler per command.
//!
//! Handlers only read inputs, call the library, and print or write its
//! output; errors go back to `main` as `anyhow` errors with context, and
//! `main` turns them into a message and an exit code. To add a command,
//! add a variant to [`Command`], its `Args` struct, and a handler.

use std::io::{self, Read, Write};
use std::num::NonZeroUsize;
use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};

use std::time::Duration;

mod bounce;
mod calibrate;
mod capture;
mod checking;
mod life;
mod pwl;
mod raw;
mod run;
mod sweeping;

use bounce::bounce;
use checking::check;
use life::life;
use pwl::pwl;
use run::run;
pub use sweeping::{MergeArgs, SweepArgs};
use sweeping::{merge, sweep};

use chatterspice::arc::GapProfile;
use chatterspice::chatter::Chatter;
use chatterspice::check;
use chatterspice::envelope;
use chatterspice::netlist::{self, ContactElement};
use chatterspice::pipeline::CouplingOptions;
use chatterspice::pipeline::{self, RunOptions};
use chatterspice::report::{self, Format};
use chatterspice::scenario::Scenario;
use chatterspice::spice::Ngspice;
use chatterspice::verdict;
use chatterspice::waveform::{ContactModel, Waveform, read_state_csv};

/// Relay contact bounce from physics, into circuit simulation.
#[derive(Debug, Parser)]
#[command(name = "chatterspice", version)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// The main job: the relay's chatter switching your circuit in ngspice,
    /// and what the bounce did to every probed signal.
    Run(RunArgs),
    /// Mechanics only: the chatter sequence of one closing.
    Bounce(BounceArgs),
    /// Print the ngspice include file with the contact subcircuit.
    Pwl(PwlArgs),
    /// Hold the scenario's [limits] and probe limits against the run:
    /// exit 0 when all hold, 1 when any fails, 2 on bad input.
    Check(CheckArgs),
    /// Print a SPICE raw file: one plot as CSV, or a JSON summary of every plot.
    Raw(raw::RawArgs),
    /// Run the scenario many times with the numbers of its [sweep] varied
    /// (Monte Carlo or a grid): sweep.csv, summary.json, sweep.svg, sweep.png.
    Sweep(SweepArgs),
    /// Join the CSVs of a sweep's shards (--shard K/N) into the CSV of one run.
    Merge(MergeArgs),
    /// A scope capture of the contact → the chatter it shows: levels,
    /// thresholds, every make and break (table, JSON, or the time,state CSV
    /// that --measured reads).
    Capture(capture::CaptureArgs),
    /// Fit the scenario's free keys to a record of the contact and/or its
    /// [datasheet] figures; writes the fitted scenario with [provenance].
    Fit(calibrate::FitArgs),
    /// The bundled relay parts (each fitted to its datasheet), or one
    /// part's scenario.
    Parts(calibrate::PartsArgs),
    /// Estimate the contacts' electrical life: simulate each printed
    /// endurance figure's test load over its switching phases, calibrate
    /// the erosion constant on the first and predict the others and the
    /// scenario's own circuit.
    Life(LifeArgs),
    /// Print a shell completion script: `chatterspice completions bash >
    /// ~/.local/share/bash-completion/completions/chatterspice`.
    Completions(CompletionsArgs),
}

/// `chatterspice completions SHELL`.
#[derive(Debug, Args)]
pub struct CompletionsArgs {
    /// The shell to complete for.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// The completion script for `shell`, on stdout.
fn completions(args: &CompletionsArgs) -> Result<()> {
    use clap::CommandFactory;
    let mut command = Cli::command();
    let mut out = Vec::new();
    clap_complete::generate(args.shell, &mut command, "chatterspice", &mut out);
    emit(&String::from_utf8_lossy(&out), None, false)
}

/// How a command that did its job ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    Success,
    /// `check` ran, and a limit failed (exit code 1); or a `sweep` ran and
    /// a sample failed a limit or could not run.
    CheckFailed,
}

impl Command {
    pub fn run(&self) -> Result<Status> {
        let done = |r: Result<()>| r.map(|()| Status::Success);
        match self {
            Command::Run(args) => done(run(args)),
            Command::Bounce(args) => done(bounce(args)),
            Command::Pwl(args) => done(pwl(args)),
            Command::Check(args) => check(args),
            Command::Raw(args) => done(raw::raw(args)),
            Command::Sweep(args) => sweep(args),
            Command::Merge(args) => done(merge(args)),
            Command::Capture(args) => done(capture::capture(args)),
            Command::Fit(args) => done(calibrate::fit(args)),
            Command::Parts(args) => done(calibrate::parts(args)),
            Command::Life(args) => done(life(args)),
            Command::Completions(args) => done(completions(args)),
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

    /// Report a measured chatter sequence instead of simulating one: a CSV
    /// `time,state` with one row per state change (open/closed or 0/1).
    #[arg(long, value_name = "CSV")]
    pub measured: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct RunArgs {
    /// Scenario file (TOML) with a [circuit] netlist and [[probe]]s; `-`
    /// reads it from stdin. Without it, the built-in default: a small
    /// signal relay switching an MCU input.
    #[arg(value_name = "SCENARIO")]
    pub scenario: Option<PathBuf>,

    /// Output format of the report on standard output.
    #[arg(long, value_enum, default_value_t = RunFormat::Table)]
    pub format: RunFormat,

    /// Also write every artefact into DIR: report.json, waveforms.csv,
    /// waveforms_ideal.csv, waveforms.raw, waveforms_ideal.raw (every saved
    /// vector, as ngspice binary raw files), netlist.cir, contact.inc,
    /// plot.svg, plot.png. Existing files there are an error unless --force.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,

    /// Replace files that already exist in DIR.
    #[arg(long, requires = "out")]
    pub force: bool,

    #[command(flatten)]
    pub simulator: SimulatorArgs,

    /// Skip the second run with an ideal contact (no comparison).
    #[arg(long)]
    pub no_ideal: bool,

    /// Use a measured chatter sequence instead of the mechanics: a CSV
    /// `time,state` with one row per state change (open/closed or 0/1).
    #[arg(long, value_name = "CSV")]
    pub measured: Option<PathBuf>,

    /// Keep ngspice's work directories and print where they are.
    #[arg(long)]
    pub keep_workdir: bool,

    #[command(flatten)]
    pub envelope: EnvelopeArgs,

    #[command(flatten)]
    pub life: LifeInRunArgs,
}

/// The electrical life `run` and `check` estimate for a scenario with
/// `[datasheet] electrical_endurance` (docs/arcs.md, "Electrical life").
#[derive(Debug, Args)]
pub struct LifeInRunArgs {
    /// Switching phases averaged over the period of each AC endurance
    /// figure (each phase is one ngspice run of the figure's test load).
    #[arg(long, value_name = "N", default_value_t = chatterspice::life::DEFAULT_PHASES,
          value_parser = parse_phases)]
    pub life_phases: usize,

    /// Do not estimate the electrical life (`check` still does when
    /// [limits] min_electrical_life asks for it).
    #[arg(long)]
    pub no_life: bool,
}

impl LifeInRunArgs {
    /// The life these arguments ask for.
    fn options(&self) -> chatterspice::verdict::LifeOptions {
        chatterspice::verdict::LifeOptions {
            phases: self.life_phases,
            estimate: !self.no_life,
            ..chatterspice::verdict::LifeOptions::default()
        }
    }
}

/// `--envelope` and its sampling: the options `run` and `check` share.
#[derive(Debug, Args)]
pub struct EnvelopeArgs {
    /// Run every relay the datasheet allows: sample the scenario's
    /// [envelope] (and its printed tolerances), keep the relays that meet
    /// every printed figure, and report each quantity as a band (min,
    /// median, p95, max); `check` holds each limit against the worst kept
    /// relay.
    #[arg(long)]
    pub envelope: bool,

    /// Relays drawn from the envelope.
    #[arg(long, value_name = "N", default_value_t = 32, requires = "envelope")]
    pub samples: usize,

    /// Seed of the quasi-random draw: the same seed draws the same relays.
    #[arg(long, value_name = "S", default_value_t = 1, requires = "envelope")]
    pub seed: u64,

    /// Relays run at once [default: one per core].
    #[arg(short = 'j', long, value_name = "J", requires = "envelope")]
    pub jobs: Option<NonZeroUsize>,
}

impl EnvelopeArgs {
    fn options(&self, run: RunOptions) -> chatterspice::envelope::EnvelopeOptions {
        chatterspice::envelope::EnvelopeOptions {
            samples: self.samples,
            seed: self.seed,
            jobs: self.jobs.unwrap_or_else(|| {
                std::thread::available_parallelism().unwrap_or(NonZeroUsize::MIN)
            }),
            run,
        }
    }
}

/// How ngspice is run: the options `run`, `check` and `sweep` share.
#[derive(Debug, Args)]
pub struct SimulatorArgs {
    /// Wall-clock limit of each ngspice run, in seconds (a sweep records a
    /// sample that reaches it as an error).
    #[arg(long, value_name = "S", default_value_t = 60.0, value_parser = parse_timeout)]
    pub timeout: f64,

    /// How the contact is emitted: pwl, event-ramp or switch [default:
    /// pwl, or event-ramp for sequences of more than 2000 points]. See the
    /// README's comparison.
    #[arg(long, value_name = "ELEMENT", value_parser = parse_element)]
    pub element: Option<ContactElement>,

    /// The ngspice program [default: $CHATTERSPICE_NGSPICE, else ngspice
    /// on PATH].
    #[arg(long, value_name = "PROGRAM")]
    pub ngspice: Option<PathBuf>,

    /// With a [coil]: the most coupling passes (ngspice run + mechanics)
    /// before giving up with exit 2.
    #[arg(long, value_name = "N", default_value_t = CouplingOptions::default().max_iterations,
          value_parser = parse_iterations)]
    pub max_iterations: usize,

    /// With a [coil]: converged when no impact or release time moves more
    /// than this between passes, in seconds.
    #[arg(long, value_name = "S", default_value_t = CouplingOptions::default().tolerance,
          value_parser = parse_tolerance)]
    pub coupling_tolerance: f64,

    /// With a [coil]: how the coil and the armature are coupled.
    /// `lock-step`: one ngspice run through its shared library
    /// (libngspice.so.0), the mechanics advanced with every time step;
    /// `passes`: whole ngspice runs repeated until the events stop moving
    /// [default: lock-step when the library is installed, else passes].
    #[arg(long, value_name = "SCHEME", value_parser = parse_coupling)]
    pub coupling: Option<chatterspice::pipeline::Coupling>,

    /// Start ngspice without the user's own start-up file
    /// (`~/.spiceinit`), as `ngspice -n` does; the system `spinit`, which
    /// loads the XSPICE code models, is read either way.
    #[arg(long)]
    pub no_spiceinit: bool,
}

impl SimulatorArgs {
    /// ngspice, located and probed within `--timeout`, started as these
    /// arguments say.
    fn ngspice(&self) -> Result<Ngspice> {
        Ok(self.locate()?)
    }

    /// ngspice as [`SimulatorArgs::ngspice`] finds it, for the library.
    fn locate(&self) -> Result<Ngspice, chatterspice::spice::SpiceError> {
        Ok(
            Ngspice::locate_within(self.ngspice.as_deref(), self.timeout())?
                .skip_user_init(self.no_spiceinit),
        )
    }

    /// ngspice, located when a verdict first needs it.
    fn lazy(&self) -> chatterspice::verdict::LazyNgspice<'_> {
        chatterspice::verdict::LazyNgspice::new(|| self.locate())
    }

    /// `--timeout`, which covers the version check too.
    fn timeout(&self) -> Duration {
        Duration::from_secs_f64(self.timeout)
    }

    /// The run options these arguments set; the rest default.
    fn run_options(&self) -> RunOptions {
        RunOptions::simulator(
            self.timeout(),
            self.element,
            self.coupling,
            self.max_iterations,
            self.coupling_tolerance,
        )
    }
}

fn parse_iterations(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "`{text}` is not a number of passes: give a whole number ≥ 1, e.g. 20"
        )),
    }
}

fn parse_coupling(text: &str) -> Result<chatterspice::pipeline::Coupling, String> {
    text.parse()
}

fn parse_tolerance(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 => Ok(s),
        _ => Err(format!(
            "`{text}` is not a tolerance: give a time in seconds > 0, e.g. 1e-7"
        )),
    }
}

#[derive(Debug, Args)]
pub struct CheckArgs {
    /// Scenario file (TOML) with [limits] and/or probe limits; `-` reads
    /// it from stdin.
    #[arg(value_name = "SCENARIO")]
    pub scenario: Option<PathBuf>,

    /// Output format.
    #[arg(long, value_enum, default_value_t = RunFormat::Table)]
    pub format: RunFormat,

    #[command(flatten)]
    pub simulator: SimulatorArgs,

    /// Check a measured chatter sequence instead of the mechanics: a CSV
    /// `time,state` with one row per state change (open/closed or 0/1).
    #[arg(long, value_name = "CSV", conflicts_with = "envelope")]
    pub measured: Option<PathBuf>,

    #[command(flatten)]
    pub envelope: EnvelopeArgs,

    #[command(flatten)]
    pub life: LifeInRunArgs,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum RunFormat {
    /// The run JSON of docs/output.md, for scripts.
    Json,
    /// A summary for people.
    Table,
}

#[derive(Debug, Args)]
pub struct PwlArgs {
    /// Scenario file (TOML); `-` reads it from stdin. Without it, the
    /// built-in default.
    #[arg(value_name = "SCENARIO")]
    pub scenario: Option<PathBuf>,

    /// Write the include to FILE instead of standard output. An existing
    /// FILE is an error unless --force.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    pub output: Option<PathBuf>,

    /// Replace FILE if it already exists.
    #[arg(long, requires = "output")]
    pub force: bool,

    /// How the contact is emitted: pwl, event-ramp or switch [default:
    /// pwl, or event-ramp for sequences of more than 2000 points]. Data
    /// files an element needs are written next to FILE.
    #[arg(long, value_name = "ELEMENT", value_parser = parse_element)]
    pub element: Option<ContactElement>,

    /// Use a measured chatter sequence instead of the mechanics: a CSV
    /// `time,state` with one row per state change (open/closed or 0/1).
    #[arg(long, value_name = "CSV")]
    pub measured: Option<PathBuf>,
}

fn parse_timeout(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 && Duration::try_from_secs_f64(s).is_ok() => Ok(s),
        _ => Err(format!(
            "`{text}` is not a time limit: give a number of seconds > 0, e.g. 60"
        )),
    }
}

fn parse_element(text: &str) -> Result<ContactElement, String> {
    text.parse::<ContactElement>().map_err(|e| e.to_string())
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum BounceFormat {
    /// The JSON of docs/output.md, for scripts.
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

#[derive(Debug, Args)]
pub struct LifeArgs {
    /// Scenario file (TOML) with [datasheet] electrical_endurance; `-`
    /// reads it from stdin. Its [circuit], if any, is the load whose life
    /// is estimated.
    #[arg(value_name = "SCENARIO")]
    pub scenario: Option<PathBuf>,

    /// Switching phases averaged over the period of an AC figure.
    #[arg(long, value_name = "N", default_value_t = chatterspice::life::DEFAULT_PHASES,
          value_parser = parse_phases)]
    pub phases: usize,

    /// Output format.
    #[arg(long, value_enum, default_value_t = RunFormat::Table)]
    pub format: RunFormat,

    /// ngspice runs at a time [default: the number of CPUs].
    #[arg(long, value_name = "N")]
    pub jobs: Option<std::num::NonZeroUsize>,

    #[command(flatten)]
    pub simulator: SimulatorArgs,
}

fn parse_phases(text: &str) -> Result<usize, String> {
    match text.parse::<usize>() {
        Ok(n) if (2..=1024).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{text}` is not a number of phases: give a whole number from 2 to 1024, e.g. 16"
        )),
    }
}

/// A measured chatter record (`--measured CSV`): its open/closed intervals.
fn read_measured(csv: &Path) -> Result<Vec<chatterspice::chatter::Interval>> {
    report::protect_input(csv);
    let text = chatterspice::input::read_to_string(csv)
        .with_context(|| format!("{}: cannot read the measured chatter", csv.display()))?;
    Ok(read_state_csv(&text, csv)?)
}

/// Fail before any work if `--out DIR` already holds a file the run
/// would write (or something in the way of one, or an input).
fn refuse_existing_bundle(dir: &Path, force: bool) -> Result<()> {
    let names = [
        "report.json",
        "waveforms.csv",
        "waveforms_ideal.csv",
        "waveforms.raw",
        "waveforms_ideal.raw",
        "netlist.cir",
        pipeline::INCLUDE_FILE,
        "plot.svg",
        "plot.png",
    ];
    for path in names.iter().map(|n| dir.join(n)) {
        match chatterspice::output::check_target(&path, force) {
            Err(report::WriteError::Exists { path }) => bail!(
                "{}: already exists; pass --force to overwrite the files in {}, or choose another --out",
                path.display(),
                dir.display()
            ),
            other => other?,
        }
    }
    Ok(())
}

/// The named scenario file, stdin for `-`, or the built-in default.
fn load_scenario(path: Option<&Path>) -> Result<Scenario> {
    let scenario = read_scenario(path)?;
    // Outputs never replace what the run reads.
    if let Some(p) = path.filter(|p| *p != Path::new("-")) {
        report::protect_input(p);
    }
    if let Some(circuit) = &scenario.circuit {
        report::protect_input(&circuit.netlist);
    }
    Ok(scenario)
}

fn read_scenario(path: Option<&Path>) -> Result<Scenario> {
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
    if report::is_input(path) {
        return Err(report::WriteError::IsInput {
            path: path.to_owned(),
        }
        .into());
    }
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
