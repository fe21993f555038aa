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
mod rows;
mod verdicts;
mod work;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

use chatterspice::calibrate::fit::{self, FitRequest, Record};
use chatterspice::capture::{Capture, Closed, read_capture};
use chatterspice::chatter::{Chatter, Interval};
use chatterspice::check;
use chatterspice::commands;
use chatterspice::netlist::ContactElement;
use chatterspice::pipeline::Coupling;
use chatterspice::pipeline::{self, RunOptions, RunResult};
use chatterspice::report::{self, Format};
use chatterspice::scenario::{BUNDLED_PARTS, DEFAULT_SCENARIO_TOML, Scenario, bundled_part};
use chatterspice::sweep::files::{self, Destination};
use chatterspice::sweep::{self, Sampler, SweepMode, SweepOptions};
use chatterspice::waveform::read_state_csv;
use pyo3::prelude::*;

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

/// The Run of `result`, its report the JSON `text`.
pub(crate) fn run_result(py: Python<'_>, result: &RunResult, text: &str) -> PyResult<Run> {
    let ideal_waveforms = match &result.ideal {
        Some(sim) => Some(raw::vectors(py, &sim.plot)?.unbind()),
        None => None,
    };
    let shown = |p: &Option<PathBuf>| p.as_ref().map(|d| d.display().to_string());
    let workdir = &result.simulation.workdir;
    Ok(Run {
        report: json(py, text)?.unbind(),
        waveforms: raw::vectors(py, &result.simulation.plot)?.unbind(),
        ideal_waveforms,
        deck: result.deck.text.clone(),
        include: result.include.text.clone(),
        log: result.simulation.log.clone(),
        ideal_log: result.ideal.as_ref().map(|s| s.log.clone()),
        workdir: shown(workdir),
        raw_path: shown(
            &workdir
                .as_ref()
                .map(|d| d.join(chatterspice::spice::ngspice::RAW_NAME)),
        ),
        ideal_workdir: shown(&result.ideal.as_ref().and_then(|s| s.workdir.clone())),
    })
}

/// The scenario run many times with the numbers of its ``[sweep]``
/// varied, as ``chatterspice sweep``.
///
/// Returns a Sweep: ``summary`` (``summary.json`` as a dict), ``rows``
/// (``sweep.csv`` as one dict per sample in index order) and ``csv``
/// (that file's text, byte for byte). With ``out=DIR`` the sweep writes
/// the command's files into DIR as ``chatterspice sweep --out DIR`` does
/// (``sweep.csv`` row by row while it runs, then ``summary.json``,
/// ``sweep.svg``, ``sweep.png`` and ``sweep.meta.json``), and ``rows``
/// reads the rows back from ``sweep.csv`` when asked (``len``, indexing,
/// iteration), so that memory does not grow with the samples; ``csv`` is
/// then None.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``).
///     samples: samples of a random sweep (≥ 1); default the scenario's.
///     seed: the random sweep's seed; default the scenario's.
///     jobs: samples run at once (≥ 1); default one per core.
///     out: a directory (str, bytes or os.PathLike, created if needed)
///         to write the sweep's files into. A sweep's files already there
///         are an error (FileExistsError) unless ``force=True``.
///     force: replace the sweep's files in ``out``.
///     resume: the directory of a sweep that was stopped (by Ctrl-C, or a
///         signal to the command), continued from its finished rows into
///         the files an uninterrupted sweep writes: the scenario, seed,
///         samples and options must be the same.
///     mechanics_only: the relay alone, no circuit and no ngspice.
///     ideal: also run the ideal contact for every sample.
///     timeout: the wall-clock limit of each ngspice run, in s.
///     element, coupling, max_iterations, coupling_tolerance, ngspice,
///         no_spiceinit: how each sample runs ngspice (see ``run``).
///     progress: a callable ``progress(done, total)``, called on the
///         calling thread with the samples done so far (at most every
///         20 ms, and once at the end); an exception it raises stops the
///         sweep and is raised.
///
/// Raises InputError, NgspiceError, FileExistsError; KeyboardInterrupt on
/// Ctrl-C, with the sweep stopped, its ngspice processes killed and work
/// directories removed (with ``out``, its finished rows kept there for
/// ``resume``).
#[pyfunction]
#[pyo3(name = "sweep", signature = (path=None, *, toml_text=None, origin=None, samples=None,
                                    seed=None, jobs=None, out=None, force=false, resume=None,
                                    mechanics_only=false, ideal=false,
                                    timeout=Duration::from_secs(60), element=None, coupling=None,
                                    max_iterations=20, coupling_tolerance=1e-7, ngspice=None,
                                    no_spiceinit=false, progress=None))]
#[pyo3(
    text_signature = "(path=None, *, toml_text=None, origin=None, samples=None, seed=None, jobs=None, out=None, force=False, resume=None, mechanics_only=False, ideal=False, timeout=60.0, element=None, coupling=None, max_iterations=20, coupling_tolerance=1e-07, ngspice=None, no_spiceinit=False, progress=None)"
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
    #[pyo3(from_py_with = args::out_arg)] out: Option<PathBuf>,
    #[pyo3(from_py_with = args::force_arg)] force: bool,
    #[pyo3(from_py_with = args::resume_arg)] resume: Option<PathBuf>,
    #[pyo3(from_py_with = args::mechanics_only_arg)] mechanics_only: bool,
    #[pyo3(from_py_with = args::ideal_arg)] ideal: bool,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
    #[pyo3(from_py_with = args::element_arg)] element: Option<ContactElement>,
    #[pyo3(from_py_with = args::coupling_arg)] coupling: Option<Coupling>,
    #[pyo3(from_py_with = args::max_iterations_arg)] max_iterations: usize,
    #[pyo3(from_py_with = args::coupling_tolerance_arg)] coupling_tolerance: f64,
    #[pyo3(from_py_with = args::ngspice_arg)] ngspice: Option<PathBuf>,
    #[pyo3(from_py_with = args::no_spiceinit_arg)] no_spiceinit: bool,
    #[pyo3(from_py_with = args::progress_arg)] progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Sweep> {
    let simulator = verdicts::Simulator {
        timeout,
        element,
        coupling,
        max_iterations,
        coupling_tolerance,
        ngspice,
        no_spiceinit,
    };
    if mechanics_only && ideal {
        return Err(Failure::input(
            "ideal=True runs each sample's circuit with an ideal contact, which \
             mechanics_only=True leaves out: give one of them",
        )
        .into());
    }
    let destination = match (out, resume) {
        (Some(_), Some(_)) => {
            return Err(Failure::input(
                "resume= continues the sweep in its own directory: give out= or resume=, \
                 not both",
            )
            .into());
        }
        (_, Some(_)) if force => {
            return Err(Failure::input(
                "resume= keeps the rows in its directory, which force=True would replace: \
                 give one of them",
            )
            .into());
        }
        (Some(dir), None) => Some(Destination {
            dir,
            resume: false,
            force,
            shard: None,
        }),
        (None, Some(dir)) => Some(Destination {
            dir,
            resume: true,
            force: false,
            shard: None,
        }),
        (None, None) if force => {
            return Err(
                Failure::input("force=True replaces the files of out=DIR: give out= too").into(),
            );
        }
        (None, None) => None,
    };
    let jobs = self::jobs(jobs);
    let loaded = load_scenario(path, toml_text, origin)?;
    let Loaded { scenario, text } = loaded;
    let to = destination.clone();
    let (summary, kept) =
        work::interruptible(py, progress.as_ref(), move |ticker| -> Result<_, Failure> {
            let sampler = Sampler::new(&scenario, samples, seed)?;
            let ngspice = (!mechanics_only).then(|| simulator.locate()).transpose()?;
            let mut options = SweepOptions::new(match &ngspice {
                Some(n) => SweepMode::Circuit(n),
                None => SweepMode::Mechanics,
            });
            if let Some(j) = jobs {
                options.jobs = j;
            }
            options.run = RunOptions {
                compare_ideal: ideal,
                ideal_alongside: false,
                ..simulator.run_options()
            };
            if let Some(to) = &to {
                let written =
                    files::write(&scenario, &text, &sampler, &options, to, &*ticker, |_| {})?;
                return Ok((
                    written.summary.to_json(),
                    Kept::File(written.files[0].clone(), written.rows),
                ));
            }
            let mut sink = work::Sink::new(Arc::clone(&ticker));
            let collected = sweep::run(&scenario, &sampler, &options, &mut sink, &*ticker)?;
            let summary = collected.summary(&sampler)?.to_json();
            Ok((
                summary,
                Kept::Text(String::from_utf8_lossy(&sink.bytes).into_owned()),
            ))
        })?;
    let summary = json(py, &summary)?.unbind();
    Ok(match kept {
        Kept::Text(csv) => Sweep {
            summary,
            rows: rows::all(py, &csv)?.into_any().unbind(),
            csv: Some(csv),
            out: None,
        },
        Kept::File(csv, len) => Sweep {
            summary,
            rows: Bound::new(py, rows::SweepRows::new(csv, len))?
                .into_any()
                .unbind(),
            csv: None,
            out: destination.map(|d| d.dir.display().to_string()),
        },
    })
}

/// Where a sweep's rows are: its CSV text, or the file it wrote and its
/// row count.
enum Kept {
    Text(String),
    File(PathBuf, u64),
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
/// A Ctrl-C that came while numpy loaded.
static SIGINT_WHILE_LOADING: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// SIGINT's handler while numpy loads: noted, raised once it has loaded.
#[pyfunction]
fn note_sigint(signum: i32, frame: Bound<'_, PyAny>) {
    let _ = (signum, frame);
    SIGINT_WHILE_LOADING.store(true, std::sync::atomic::Ordering::SeqCst);
}

/// numpy and its C API, loaded whole: a KeyboardInterrupt inside numpy's
/// own import becomes an ImportError there ("Importing the numpy
/// C-extensions failed"), so on the main thread, under Python's own
/// SIGINT handler, a Ctrl-C is held until numpy has loaded and then
/// raised as the KeyboardInterrupt it is.
fn load_numpy(py: Python<'_>) -> PyResult<()> {
    let load = || -> PyResult<()> {
        py.import("numpy")?;
        drop(numpy::PyArray1::<f64>::zeros(py, 0, false));
        Ok(())
    };
    let signal = py.import("signal")?;
    let threading = py.import("threading")?;
    let on_main = threading
        .call_method0("current_thread")?
        .is(&threading.call_method0("main_thread")?);
    let default = signal.getattr("default_int_handler")?;
    let sigint = signal.getattr("SIGINT")?;
    if !on_main || !signal.call_method1("getsignal", (&sigint,))?.is(&default) {
        return load();
    }
    signal.call_method1("signal", (&sigint, wrap_pyfunction!(note_sigint, py)?))?;
    let loaded = load();
    signal.call_method1("signal", (&sigint, &default))?;
    loaded?;
    if SIGINT_WHILE_LOADING.swap(false, std::sync::atomic::Ordering::SeqCst) {
        return Err(pyo3::exceptions::PyKeyboardInterrupt::new_err(()));
    }
    Ok(())
}

#[pymodule]
#[pyo3(name = "chatterspice")]
fn chatterspice_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    // numpy and its C API now, with the package: a Ctrl-C while they load
    // is then a KeyboardInterrupt of the import, never a failure to reach
    // the API inside a call.
    load_numpy(py)?;
    m.add_function(wrap_pyfunction!(py_bounce, m)?)?;
    m.add_function(wrap_pyfunction!(verdicts::py_run, m)?)?;
    m.add_function(wrap_pyfunction!(verdicts::py_check, m)?)?;
    m.add_function(wrap_pyfunction!(verdicts::py_envelope, m)?)?;
    m.add_function(wrap_pyfunction!(verdicts::py_life, m)?)?;
    m.add_function(wrap_pyfunction!(py_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(py_fit, m)?)?;
    m.add_function(wrap_pyfunction!(py_capture, m)?)?;
    m.add_function(wrap_pyfunction!(py_read_raw, m)?)?;
    m.add_function(wrap_pyfunction!(py_parts, m)?)?;
    m.add_function(wrap_pyfunction!(py_part, m)?)?;
    m.add_function(wrap_pyfunction!(py_pwl, m)?)?;
    m.add_class::<Run>()?;
    m.add_class::<Sweep>()?;
    m.add_class::<rows::SweepRows>()?;
    m.add_class::<Fit>()?;
    m.add_class::<raw::RawFile>()?;
    m.add_class::<raw::Plot>()?;
    m.add("InputError", py.get_type::<error::InputError>())?;
    m.add("NgspiceError", py.get_type::<error::NgspiceError>())?;
    m.add("SimulationError", py.get_type::<error::SimulationError>())?;
    m.add(
        "ChatterspiceWarning",
        py.get_type::<error::ChatterspiceWarning>(),
    )?;
    m.add("DEFAULT_SCENARIO", DEFAULT_SCENARIO_TOML)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    let mapping = py.import("collections.abc")?.getattr("Mapping")?;
    mapping.call_method1("register", (py.get_type::<raw::Plot>(),))?;
    mapping.call_method1("register", (py.get_type::<raw::RawFile>(),))?;
    let sequence = py.import("collections.abc")?.getattr("Sequence")?;
    sequence.call_method1("register", (py.get_type::<rows::SweepRows>(),))?;
    Ok(())
}
