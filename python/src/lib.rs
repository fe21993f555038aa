//! The Python module `chatterspice`: the library's commands as functions
//! that return what the command line prints as JSON, parsed into dicts,
//! and waveforms as numpy arrays.
//!
//! Every function reads its scenario in one of three ways (see
//! [`load_scenario`]): a file by `path` (exactly as the command line reads
//! it), `toml_text` laid over the built-in default scenario ([`overlay`]),
//! or, with neither, the built-in default. The reports are the library's
//! own JSON text, parsed by Python's `json`, so they are the command
//! line's byte for byte. Long work runs on a thread of its own with the
//! GIL released, stopped by Ctrl-C ([`work`]); arguments are read by
//! [`args`], so that a bad one is an `InputError` naming it.

mod args;
mod error;
mod overlay;
mod raw;
mod results;
mod work;

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use chatterspice::calibrate::fit::{self, FitRequest, Record};
use chatterspice::capture::{Capture, Closed, read_capture};
use chatterspice::chatter::{Chatter, Interval};
use chatterspice::check;
use chatterspice::commands;
use chatterspice::envelope::{self, EnvelopeOptions};
use chatterspice::pipeline::{self, RunOptions, RunResult};
use chatterspice::report::{self, Format};
use chatterspice::scenario::{BUNDLED_PARTS, DEFAULT_SCENARIO_TOML, Scenario, bundled_part};
use chatterspice::spice::{Ngspice, RunOutput, RunRequest, Runner, SpiceError};
use chatterspice::sweep::{self, Sampler, SweepMode, SweepOptions};
use chatterspice::waveform::read_state_csv;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use error::Failure;
use results::{Fit, Run, Sweep};

/// Python's `json.loads(text)`.
pub(crate) fn json<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (text,))
}

/// A scenario and the whole TOML text it was read from.
struct Loaded {
    scenario: Scenario,
    text: String,
}

/// The scenario of a call: the file at `path`, `toml_text` over the
/// built-in default (or over its own `base`), or the built-in default.
fn load_scenario(
    path: Option<PathBuf>,
    toml_text: Option<String>,
    origin: Option<PathBuf>,
) -> Result<Loaded, Failure> {
    match (path, toml_text) {
        (Some(p), Some(_)) => Err(Failure::input(format!(
            "give a scenario file ({}) or toml_text, not both",
            p.display()
        ))),
        (_, None) if origin.is_some() => Err(Failure::input(
            "origin names the file toml_text stands for: give it with toml_text, or give the \
             file as path",
        )),
        (None, None) => Ok(Loaded {
            scenario: Scenario::builtin_default(),
            text: DEFAULT_SCENARIO_TOML.to_owned(),
        }),
        (Some(p), None) => {
            let text = chatterspice::input::read_to_string(&p)
                .map_err(|e| Failure::unreadable(&p, "the scenario file", &e))?;
            Ok(Loaded {
                scenario: Scenario::parse(&text, &p)?,
                text,
            })
        }
        (None, Some(text)) => {
            let (scenario, text) = overlay::parse(&text, origin.as_deref())?;
            Ok(Loaded { scenario, text })
        }
    }
}

/// A measured `time,state` record's intervals.
fn read_measured(path: &Path) -> Result<Vec<Interval>, Failure> {
    let text = chatterspice::input::read_to_string(path)
        .map_err(|e| Failure::unreadable(path, "the measured chatter", &e))?;
    Ok(read_state_csv(&text, path)?)
}

/// ngspice, located (`$CHATTERSPICE_NGSPICE`, else on `PATH`) and probed
/// within `timeout`.
fn ngspice(timeout: Duration) -> Result<Ngspice, Failure> {
    Ok(Ngspice::locate_within(None, timeout)?)
}

/// `jobs` as the library takes it.
fn jobs(jobs: Option<u64>) -> Option<std::num::NonZeroUsize> {
    jobs.and_then(|j| usize::try_from(j).ok())
        .and_then(std::num::NonZeroUsize::new)
}

/// The chatter of one closing of the relay.
///
/// Returns the JSON of ``chatterspice bounce --format json`` as a dict:
/// ``outcome``, ``first_impact`` (s), ``settle_time`` (s),
/// ``bounce_count``, ``impacts`` (times in s, velocities in m/s, peak
/// force in N, ...), ``intervals`` (``state``, ``start``, ``end`` in s),
/// ``dimensionless`` and, for a two-stage relay, ``pole_face_impacts``.
///
/// Parameters:
///     path: a scenario file (str or os.PathLike), read as
///         ``chatterspice bounce FILE`` reads it.
///     toml_text: scenario TOML laid over the built-in default, or read
///         from its own ``base = "default" | "part:NAME" | "file.toml"``.
///     origin: the file ``toml_text`` stands for: errors name it and
///         relative paths (a ``base``, ``circuit.netlist``) resolve
///         against its directory; default ``<toml_text>`` in the working
///         directory.
///     measured: a ``time,state`` CSV record reported instead of the
///         mechanics (no scenario is read).
///
/// Raises InputError (bad scenario or argument), FileNotFoundError,
/// SimulationError; KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(name = "bounce", signature = (path=None, *, toml_text=None, origin=None, measured=None))]
fn py_bounce<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::measured_arg)] measured: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let text = match measured {
        // As the command line: a measured record is reported as it is.
        Some(csv) => {
            let chatter = Chatter::from_intervals(read_measured(&csv)?);
            report::render(Format::Json, &chatter, None)
        }
        None => {
            let loaded = load_scenario(path, toml_text, origin)?;
            work::interruptible(py, None, move |_| {
                Ok(commands::bounce(&loaded.scenario, Format::Json)?)
            })?
        }
    };
    json(py, &text)
}

/// What one ngspice run of a call said, recorded on its way through.
struct Said {
    deck: String,
    includes: Vec<String>,
    log: String,
}

/// ngspice, recording each run's deck and log (the library's result
/// keeps the plot, not the log).
struct Recorder {
    ngspice: Ngspice,
    said: Mutex<Vec<Said>>,
}

impl Recorder {
    fn note(&self, req: &RunRequest, out: &Result<RunOutput, SpiceError>) {
        if let Ok(out) = out {
            let mut said = self.said.lock().unwrap_or_else(|e| e.into_inner());
            said.push(Said {
                deck: req.deck.clone(),
                includes: req.includes.iter().map(|(_, text)| text.clone()).collect(),
                log: out.log.clone(),
            });
        }
    }

    /// The logs of the bounced run (its deck is `deck` and it includes
    /// `include`) and of the other (ideal-contact) run, the last of each.
    fn logs(&self, deck: &str, include: &str) -> (String, Option<String>) {
        let said = self.said.lock().unwrap_or_else(|e| e.into_inner());
        let bounced = |s: &Said| s.deck == deck && s.includes.iter().any(|i| i == include);
        let log = said
            .iter()
            .rev()
            .find(|s| bounced(s))
            .or(said.last())
            .map(|s| s.log.clone())
            .unwrap_or_default();
        let other = said
            .iter()
            .rev()
            .find(|s| !bounced(s))
            .map(|s| s.log.clone());
        (log, other)
    }
}

impl Runner for Recorder {
    fn run(&self, req: &RunRequest) -> Result<RunOutput, SpiceError> {
        let out = self.ngspice.run(req);
        self.note(req, &out);
        out
    }

    fn run_many(&self, reqs: &[RunRequest]) -> Vec<Result<RunOutput, SpiceError>> {
        let outs = self.ngspice.run_many(reqs);
        for (req, out) in reqs.iter().zip(&outs) {
            self.note(req, out);
        }
        outs
    }
}

/// The relay's chatter switching the scenario's circuit in ngspice, and
/// the analysis of every probe: the main job.
///
/// Returns a Run: ``report`` (the JSON of ``chatterspice run --format
/// json``), ``waveforms`` (every vector of the raw file as a float64
/// array: ``time`` in s, voltages in V, currents in A), the ideal-contact
/// run's ``ideal_waveforms``, the ``deck`` and contact ``include`` ngspice
/// ran, its ``log``, and with ``keep_workdir`` the ``workdir`` and
/// ``raw_path`` left behind.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``).
///     measured: a ``time,state`` CSV record switching the circuit
///         instead of the mechanics.
///     ideal: also run an ideal contact (one clean edge) and compare.
///     timeout: the wall-clock limit of each ngspice run, in s.
///     keep_workdir: leave ngspice's work directories (deck, includes,
///         raw file) in place and name them in the result.
///
/// Raises InputError, FileNotFoundError, NgspiceError (ngspice missing,
/// failing or timing out), SimulationError; KeyboardInterrupt on Ctrl-C,
/// with every ngspice process killed and work directory removed.
#[pyfunction]
#[pyo3(name = "run", signature = (path=None, *, toml_text=None, origin=None, measured=None,
                                  ideal=true, timeout=Duration::from_secs(60),
                                  keep_workdir=false))]
#[pyo3(
    text_signature = "(path=None, *, toml_text=None, origin=None, measured=None, ideal=True, timeout=60.0, keep_workdir=False)"
)]
#[allow(clippy::too_many_arguments)]
fn py_run(
    py: Python<'_>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::measured_arg)] measured: Option<PathBuf>,
    #[pyo3(from_py_with = args::ideal_arg)] ideal: bool,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
    #[pyo3(from_py_with = args::keep_workdir_arg)] keep_workdir: bool,
) -> PyResult<Run> {
    let loaded = load_scenario(path, toml_text, origin)?;
    let intervals = measured.as_deref().map(read_measured).transpose()?;
    let options = RunOptions {
        timeout,
        compare_ideal: ideal,
        keep_workdir,
        ..RunOptions::default()
    };
    let scenario = loaded.scenario;
    let (mut result, logs, dimensionless) =
        work::interruptible(py, None, move |_| -> Result<_, Failure> {
            let recorder = Recorder {
                ngspice: ngspice(timeout)?,
                said: Mutex::new(Vec::new()),
            };
            let result: RunResult = match intervals {
                Some(i) => pipeline::run_measured(&scenario, i, &recorder, &options)?,
                None => pipeline::run(&scenario, &recorder, &options)?,
            };
            let logs = recorder.logs(&result.deck.text, &result.include.text);
            Ok((result, logs, commands::dimensionless(&scenario)))
        })?;
    // As the command line shows it: relative to where the user is.
    if let Some(relative) = std::env::current_dir()
        .ok()
        .and_then(|cwd| result.netlist.strip_prefix(cwd).ok().map(Path::to_path_buf))
    {
        result.netlist = relative;
    }
    let text = report::json::render_run(&result, dimensionless.as_ref());
    let ideal_waveforms = match &result.ideal {
        Some(sim) => Some(raw::vectors(py, &sim.plot)?.unbind()),
        None => None,
    };
    let shown = |p: &Option<PathBuf>| p.as_ref().map(|d| d.display().to_string());
    let workdir = &result.simulation.workdir;
    Ok(Run {
        report: json(py, &text)?.unbind(),
        waveforms: raw::vectors(py, &result.simulation.plot)?.unbind(),
        ideal_waveforms,
        deck: result.deck.text.clone(),
        include: result.include.text.clone(),
        log: logs.0,
        ideal_log: result.ideal.as_ref().and(logs.1),
        workdir: shown(workdir),
        raw_path: shown(
            &workdir
                .as_ref()
                .map(|d| d.join(chatterspice::spice::ngspice::RAW_NAME)),
        ),
        ideal_workdir: shown(&result.ideal.as_ref().and_then(|s| s.workdir.clone())),
    })
}

/// The scenario's limits held against its closing and, when a limit
/// needs it, its run through ngspice.
///
/// Returns the JSON of ``chatterspice check --format json`` as a dict:
/// ``passed`` is False when a limit failed (where the command exits with
/// 1), ``failed`` counts them and ``checks`` lists every limit with
/// ``key``, ``actual``, ``limit`` and ``margin`` (in the limit's unit: s,
/// V, counts) and ``passed``. Relay limits alone need no ngspice.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``).
///     measured: a ``time,state`` CSV record instead of the mechanics.
///     timeout: the wall-clock limit of each ngspice run, in s.
///
/// Raises InputError, FileNotFoundError, NgspiceError, SimulationError;
/// KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(name = "check", signature = (path=None, *, toml_text=None, origin=None, measured=None,
                                    timeout=Duration::from_secs(60)))]
#[pyo3(text_signature = "(path=None, *, toml_text=None, origin=None, measured=None, timeout=60.0)")]
fn py_check<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::measured_arg)] measured: Option<PathBuf>,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
) -> PyResult<Bound<'py, PyAny>> {
    let loaded = load_scenario(path, toml_text, origin)?;
    let scenario = loaded.scenario;
    let intervals = measured.as_deref().map(read_measured).transpose()?;
    let options = RunOptions {
        timeout,
        ..RunOptions::default()
    };
    let needs_ngspice = commands::check_needs_ngspice(&scenario, intervals.is_some());
    let text = work::interruptible(py, None, move |_| -> Result<_, Failure> {
        let ngspice = needs_ngspice.then(|| ngspice(timeout)).transpose()?;
        let (verdict, evidence) = match (intervals, &ngspice) {
            (Some(i), n) => check::measured(&scenario, i, n.as_ref().map(|n| n as _), &options)?,
            (None, Some(n)) => check::run_with(&scenario, n, &options)?,
            (None, None) => check::relay_only(&scenario)?,
        };
        let dimensionless = commands::dimensionless(&scenario);
        Ok(report::json::render_check(
            &verdict,
            &evidence,
            dimensionless.as_ref(),
        ))
    })?;
    json(py, &text)
}

/// Every relay the datasheet allows: the scenario's ``[envelope]`` (and
/// its printed tolerances) sampled, the relays that meet every printed
/// figure kept and run, each limit held against the worst kept relay.
///
/// Returns the JSON of ``chatterspice check --envelope --format json`` as
/// a dict: the worst relay's ``checks`` and ``passed``, and under
/// ``envelope`` the bands (min, median, p95, max) of every quantity, the
/// counts drawn, kept and rejected, and the worst relay.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``).
///     samples: relays drawn (≥ 1).
///     seed: the seed of the quasi-random draw (the same seed draws the
///         same relays).
///     jobs: relays run at once; default one per core.
///     timeout: the wall-clock limit of each ngspice run, in s.
///
/// Raises InputError (no ``[envelope]``, every relay rejected, a bad
/// argument), NgspiceError, SimulationError; KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(name = "envelope", signature = (path=None, *, toml_text=None, origin=None, samples=Some(32),
                                       seed=Some(1), jobs=None, timeout=Duration::from_secs(60)))]
#[pyo3(
    text_signature = "(path=None, *, toml_text=None, origin=None, samples=32, seed=1, jobs=None, timeout=60.0)"
)]
#[allow(clippy::too_many_arguments)]
fn py_envelope<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::samples_arg)] samples: Option<u64>,
    #[pyo3(from_py_with = args::seed_arg)] seed: Option<u64>,
    #[pyo3(from_py_with = args::jobs_arg)] jobs: Option<u64>,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
) -> PyResult<Bound<'py, PyAny>> {
    let loaded = load_scenario(path, toml_text, origin)?;
    let scenario = loaded.scenario;
    let defaults = EnvelopeOptions::default();
    let options = EnvelopeOptions {
        samples: samples.map_or(defaults.samples, |s| {
            usize::try_from(s).unwrap_or(usize::MAX)
        }),
        seed: seed.unwrap_or(defaults.seed),
        jobs: self::jobs(jobs).unwrap_or_else(|| {
            std::thread::available_parallelism().unwrap_or(std::num::NonZeroUsize::MIN)
        }),
        run: RunOptions {
            timeout,
            ..RunOptions::default()
        },
    };
    let needs_ngspice = commands::check_needs_ngspice(&scenario, false);
    let text = work::interruptible(py, None, move |_| -> Result<_, Failure> {
        let ngspice = needs_ngspice.then(|| ngspice(timeout)).transpose()?;
        let runner = ngspice.as_ref().map(|n| n as &dyn Runner);
        let env = envelope::run(&scenario, runner, &options)?;
        let worst = env
            .worst()
            .expect("an envelope that kept a relay has a worst one");
        Ok(envelope::json_with_envelope(
            &report::json::render_check(&env.verdict, &worst.evidence, None),
            &env.report,
        ))
    })?;
    json(py, &text)
}

/// The scenario run many times with the numbers of its ``[sweep]``
/// varied, as ``chatterspice sweep`` (writing no files).
///
/// Returns a Sweep: ``summary`` (``summary.json`` as a dict), ``rows``
/// (``sweep.csv`` as one dict per sample in index order) and ``csv``
/// (that file's text, byte for byte).
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``).
///     samples: samples of a random sweep (≥ 1); default the scenario's.
///     seed: the random sweep's seed; default the scenario's.
///     jobs: samples run at once (≥ 1); default one per core.
///     mechanics_only: the relay alone, no circuit and no ngspice.
///     ideal: also run the ideal contact for every sample.
///     timeout: the wall-clock limit of each ngspice run, in s.
///     progress: a callable ``progress(done, total)``, called on the
///         calling thread with the samples done so far (at most every
///         20 ms, and once at the end); an exception it raises stops the
///         sweep and is raised.
///
/// Raises InputError, NgspiceError; KeyboardInterrupt on Ctrl-C, with the
/// sweep stopped, its ngspice processes killed and work directories
/// removed.
#[pyfunction]
#[pyo3(name = "sweep", signature = (path=None, *, toml_text=None, origin=None, samples=None,
                                    seed=None, jobs=None, mechanics_only=false, ideal=false,
                                    timeout=Duration::from_secs(60), progress=None))]
#[pyo3(
    text_signature = "(path=None, *, toml_text=None, origin=None, samples=None, seed=None, jobs=None, mechanics_only=False, ideal=False, timeout=60.0, progress=None)"
)]
#[allow(clippy::too_many_arguments)]
fn py_sweep<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::samples_arg)] samples: Option<u64>,
    #[pyo3(from_py_with = args::seed_arg)] seed: Option<u64>,
    #[pyo3(from_py_with = args::jobs_arg)] jobs: Option<u64>,
    #[pyo3(from_py_with = args::mechanics_only_arg)] mechanics_only: bool,
    #[pyo3(from_py_with = args::ideal_arg)] ideal: bool,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
    #[pyo3(from_py_with = args::progress_arg)] progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Sweep> {
    let jobs = self::jobs(jobs);
    let loaded = load_scenario(path, toml_text, origin)?;
    let scenario = loaded.scenario;
    let (summary, csv) =
        work::interruptible(py, progress.as_ref(), move |ticker| -> Result<_, Failure> {
            let sampler = Sampler::new(&scenario, samples, seed)?;
            let ngspice = (!mechanics_only).then(|| ngspice(timeout)).transpose()?;
            let mut options = SweepOptions::new(match &ngspice {
                Some(n) => SweepMode::Circuit(n),
                None => SweepMode::Mechanics,
            });
            if let Some(j) = jobs {
                options.jobs = j;
            }
            options.run = RunOptions {
                timeout,
                compare_ideal: ideal,
                ideal_alongside: false,
                ..RunOptions::default()
            };
            let mut sink = work::Sink::new(Arc::clone(&ticker));
            let collected = sweep::run(&scenario, &sampler, &options, &mut sink, &*ticker)?;
            let summary = collected.summary(&sampler)?.to_json();
            Ok((summary, String::from_utf8_lossy(&sink.bytes).into_owned()))
        })?;
    Ok(Sweep {
        summary: json(py, &summary)?.unbind(),
        rows: csv_rows(py, &csv)?.unbind(),
        csv,
    })
}

/// The rows of the sweep's CSV as dicts.
fn csv_rows<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyList>> {
    let bad = |e: csv::Error| Failure::input(format!("the sweep's CSV: {e}"));
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers().map_err(bad)?.clone();
    let rows = PyList::empty(py);
    for record in reader.records() {
        let record = record.map_err(bad)?;
        let row = PyDict::new(py);
        for (name, cell) in header.iter().zip(record.iter()) {
            let value = if cell.is_empty() {
                py.None().into_bound(py)
            } else if let Ok(i) = cell.parse::<i64>() {
                i.into_pyobject(py)?.into_any()
            } else if let Ok(f) = cell.parse::<f64>() {
                f.into_pyobject(py)?.into_any()
            } else {
                cell.into_pyobject(py)?.into_any()
            };
            row.set_item(name, value)?;
        }
        rows.append(row)?;
    }
    Ok(rows)
}

/// Fit the scenario's free keys to a record of the contact (a scope
/// capture or a measured ``time,state`` file) and/or its ``[datasheet]``.
///
/// Returns a Fit: ``report`` (the JSON of ``chatterspice fit --format
/// json``: ``parameters`` with ``key``, ``value``, ``sigma``,
/// ``determined``, ...) and ``scenario``, the fitted scenario's TOML with
/// its ``[provenance]``, which reads back with ``toml_text=``.
///
/// Parameters:
///     path, toml_text, origin: the prior scenario (see ``bounce``).
///     capture: a scope capture of the contact (CSV, Tektronix, Keysight,
///         Rigol, Siglent or PicoScope export).
///     channel: the capture's channel, e.g. ``"CH1"``.
///     measured: a ``time,state`` CSV record (instead of ``capture``).
///     free: the dotted keys to fit (``"surface.damping"`` or a list of
///         them); default ``[fit] free``.
///
/// Raises InputError (no free key, a bad record), FileNotFoundError;
/// KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(name = "fit", signature = (path=None, *, toml_text=None, origin=None, capture=None,
                                  channel=None, measured=None, free=None))]
#[allow(clippy::too_many_arguments)]
fn py_fit(
    py: Python<'_>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::capture_arg)] capture: Option<PathBuf>,
    #[pyo3(from_py_with = args::channel_arg)] channel: Option<String>,
    #[pyo3(from_py_with = args::measured_arg)] measured: Option<PathBuf>,
    #[pyo3(from_py_with = args::free_arg)] free: Option<Vec<String>>,
) -> PyResult<Fit> {
    let loaded = load_scenario(path, toml_text, origin)?;
    let record = match (capture, measured) {
        (Some(_), Some(_)) => {
            return Err(Failure::input("give capture or measured, not both").into());
        }
        (Some(scope), None) => {
            let (_, c) = analyse(&scope, channel.as_deref(), None, None)?;
            Some(Record {
                name: c.source.clone(),
                intervals: c.intervals.clone(),
            })
        }
        (None, Some(csv)) => Some(Record {
            name: file_name(&csv),
            intervals: read_measured(&csv)?,
        }),
        (None, None) => None,
    };
    let request = FitRequest {
        record,
        free: free.unwrap_or_default(),
    };
    let Loaded { scenario, text } = loaded;
    let netlist = scenario
        .circuit
        .as_ref()
        .and_then(|c| std::fs::canonicalize(&c.netlist).ok());
    let (report, fitted) = work::interruptible(py, None, move |_| -> Result<_, Failure> {
        let result = fit::fit(&scenario, &request)?;
        let fitted = fit::fitted_toml(&text, &result, netlist.as_deref())
            .map_err(|e| Failure::input(format!("cannot re-read the scenario: {e}")))?;
        Ok((chatterspice::calibrate::render::json(&result), fitted))
    })?;
    Ok(Fit {
        report: json(py, &report)?.unbind(),
        scenario: fitted,
    })
}

fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

/// A scope capture read and analysed: its trace and what it shows.
fn analyse(
    path: &Path,
    channel: Option<&str>,
    thresholds: Option<(f64, f64)>,
    closed: Option<Closed>,
) -> Result<(chatterspice::capture::Trace, Capture), Failure> {
    let trace = read_capture(path, channel)?;
    let capture = Capture::of(&file_name(path), &trace, thresholds, closed).map_err(|e| {
        Failure::from(e).within(format_args!(
            "{}: channel {}",
            path.display(),
            trace.channel
        ))
    })?;
    Ok((trace, capture))
}

/// A scope capture of the contact, read and analysed.
///
/// Returns the JSON of ``chatterspice capture --format json`` as a dict:
/// ``layout``, ``channel``, ``samples``, ``levels`` and ``thresholds``
/// (V), ``makes`` and ``breaks`` (s), ``bounce_count``, ``first_make``
/// and ``settle_time`` (s).
///
/// Parameters:
///     path: the capture (plain CSV, Tektronix, Keysight, Rigol, Siglent
///         or PicoScope export).
///     channel: the channel to read, e.g. ``"CH1"``; default the first.
///     low, high: the thresholds in V (both or neither); default from
///         the two levels the trace shows.
///     closed: ``"high"`` or ``"low"``, the level of the closed contact;
///         default found from the trace.
///
/// Raises InputError, FileNotFoundError.
#[pyfunction]
#[pyo3(name = "capture", signature = (path, *, channel=None, low=None, high=None, closed=None))]
fn py_capture<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::file_arg)] path: PathBuf,
    #[pyo3(from_py_with = args::channel_arg)] channel: Option<String>,
    #[pyo3(from_py_with = args::low_arg)] low: Option<f64>,
    #[pyo3(from_py_with = args::high_arg)] high: Option<f64>,
    #[pyo3(from_py_with = args::closed_arg)] closed: Option<String>,
) -> PyResult<Bound<'py, PyAny>> {
    let thresholds = match (low, high) {
        (Some(l), Some(h)) => Some((l, h)),
        (None, None) => None,
        _ => return Err(Failure::input("give low and high together, or neither").into()),
    };
    let closed = match closed.as_deref() {
        None => None,
        Some("high") => Some(Closed::High),
        Some("low") => Some(Closed::Low),
        Some(other) => {
            return Err(Failure::input(format!(
                "closed = {other:?}: give \"high\" or \"low\", the level of the closed contact"
            ))
            .into());
        }
    };
    let (_, c) = analyse(&path, channel.as_deref(), thresholds, closed)?;
    let text = serde_json::to_string(&c).expect("a capture serializes");
    json(py, &text)
}

/// Read an ngspice or LTspice raw file whole (binary or ASCII, real or
/// complex, several plots, a killed run's cut data).
///
/// Returns a RawFile: ``plots`` in file order, each a read-only mapping
/// from vector name to a read-only 1-D numpy array (float64, complex128
/// for a complex plot's vectors) that views the data read, without a
/// copy. The file used as a mapping is its last plot.
///
/// Parameters:
///     path: the raw file (str or os.PathLike).
///
/// Raises InputError (a broken file), FileNotFoundError.
#[pyfunction]
#[pyo3(name = "read_raw", signature = (path))]
fn py_read_raw(
    py: Python<'_>,
    #[pyo3(from_py_with = args::file_arg)] path: PathBuf,
) -> PyResult<raw::RawFile> {
    raw::RawFile::read(py, &path)
}

/// The names of the bundled parts, sorted: each is a scenario of a real
/// relay, used as ``toml_text='base = "part:NAME"'`` (its text is
/// ``part(NAME)``).
#[pyfunction]
#[pyo3(name = "parts")]
fn py_parts() -> Vec<&'static str> {
    let mut names: Vec<&'static str> = BUNDLED_PARTS.iter().map(|(n, _)| *n).collect();
    names.sort_unstable();
    names
}

/// The scenario TOML of the bundled part ``name`` (one of ``parts()``).
///
/// Raises InputError for a name that is not bundled, listing the parts.
#[pyfunction]
#[pyo3(name = "part", signature = (name))]
fn py_part(name: &Bound<'_, PyAny>) -> PyResult<&'static str> {
    let text: Option<&'static str> = name.extract::<String>().ok().and_then(|n| bundled_part(&n));
    text.ok_or_else(|| {
        Failure::input(format!(
            "name = {}: not a bundled part; the parts are: {}",
            name.repr()
                .map_or_else(|_| "?".to_owned(), |r| r.to_string()),
            py_parts().join(", ")
        ))
        .into()
    })
}

/// The contact as a netlist include (a ``.subckt`` with a PWL source),
/// as ``chatterspice pwl --element pwl`` prints it: the text to
/// ``.include`` into a circuit of your own.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``); its
///         ``[circuit] subckt`` names the subcircuit (default
///         ``CONTACT``).
///     measured: a ``time,state`` CSV record instead of the mechanics.
///
/// Raises InputError, FileNotFoundError, SimulationError;
/// KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(name = "pwl", signature = (path=None, *, toml_text=None, origin=None, measured=None))]
fn py_pwl(
    py: Python<'_>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::measured_arg)] measured: Option<PathBuf>,
) -> PyResult<String> {
    let loaded = load_scenario(path, toml_text, origin)?;
    let intervals = measured.as_deref().map(read_measured).transpose()?;
    let scenario = loaded.scenario;
    work::interruptible(py, None, move |_| contact_include(&scenario, intervals))
}

/// The PWL contact include of `scenario`'s closing, or of `intervals`.
fn contact_include(
    scenario: &Scenario,
    intervals: Option<Vec<Interval>>,
) -> Result<String, Failure> {
    use chatterspice::netlist::{self, ContactElement};
    use chatterspice::waveform::{ContactModel, Waveform};
    let (waveform, gap) = match intervals {
        Some(intervals) => {
            let model = ContactModel::from(&scenario.contact);
            let gap = pipeline::record_gap(scenario, &intervals);
            (Waveform::from_intervals(&intervals, &model)?, gap)
        }
        None if scenario.coil.is_some() => {
            let (chatter, _) = check::dc_step(scenario)?;
            let gap = pipeline::record_gap(scenario, &chatter.intervals);
            (pipeline::contact_waveform(scenario, &chatter)?.0, gap)
        }
        None => {
            let trajectory = chatterspice::mechanics::two_stage::step_closing(
                &scenario.mechanics()?,
                &scenario.two_stage(),
                &scenario.surface(),
                &scenario.settings(),
            )
            .map_err(|e| {
                Failure::simulation(format!(
                    "{}: the mechanics simulation failed: {e}",
                    scenario.origin.display()
                ))
            })?;
            let gap = chatterspice::arc::GapProfile::from_trajectory(&trajectory);
            let chatter = trajectory.into_chatter();
            (pipeline::contact_waveform(scenario, &chatter)?.0, gap)
        }
    };
    let subckt = scenario
        .circuit
        .as_ref()
        .map_or("CONTACT", |c| c.subckt.as_str());
    let bad = |e: chatterspice::netlist::NetlistError| Failure::input(e.to_string());
    let mut include =
        netlist::contact_include(&waveform, subckt, ContactElement::Pwl).map_err(bad)?;
    if let Some(arc) = &scenario.arc {
        include = netlist::arc::with_arc(include, &arc.model(), &gap).map_err(bad)?;
    }
    Ok(include.text)
}

/// Relay contact bounce from physics, run through ngspice.
///
/// Every function that simulates takes its scenario one of three ways:
/// ``path``, a scenario file read exactly as the command line reads it;
/// ``toml_text``, TOML laid over the built-in default scenario (keys it
/// leaves out keep the default's values) or over its own ``base``; or
/// neither, the built-in default itself. Reports are the command line's
/// JSON (``--format json``) as dicts; waveforms are numpy arrays. Numbers
/// are in SI units (s, V, A, m, N, kg). Ctrl-C stops any call.
#[pymodule]
#[pyo3(name = "chatterspice")]
fn chatterspice_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(py_bounce, m)?)?;
    m.add_function(wrap_pyfunction!(py_run, m)?)?;
    m.add_function(wrap_pyfunction!(py_check, m)?)?;
    m.add_function(wrap_pyfunction!(py_envelope, m)?)?;
    m.add_function(wrap_pyfunction!(py_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(py_fit, m)?)?;
    m.add_function(wrap_pyfunction!(py_capture, m)?)?;
    m.add_function(wrap_pyfunction!(py_read_raw, m)?)?;
    m.add_function(wrap_pyfunction!(py_parts, m)?)?;
    m.add_function(wrap_pyfunction!(py_part, m)?)?;
    m.add_function(wrap_pyfunction!(py_pwl, m)?)?;
    m.add_class::<Run>()?;
    m.add_class::<Sweep>()?;
    m.add_class::<Fit>()?;
    m.add_class::<raw::RawFile>()?;
    m.add_class::<raw::Plot>()?;
    m.add("InputError", py.get_type::<error::InputError>())?;
    m.add("NgspiceError", py.get_type::<error::NgspiceError>())?;
    m.add("SimulationError", py.get_type::<error::SimulationError>())?;
    m.add("DEFAULT_SCENARIO", DEFAULT_SCENARIO_TOML)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    let mapping = py.import("collections.abc")?.getattr("Mapping")?;
    mapping.call_method1("register", (py.get_type::<raw::Plot>(),))?;
    mapping.call_method1("register", (py.get_type::<raw::RawFile>(),))?;
    Ok(())
}
