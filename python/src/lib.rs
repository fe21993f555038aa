//! The Python module `chatterspice`: the library's commands as functions
//! that return what the command line prints as JSON, parsed into dicts,
//! and waveforms as numpy arrays.
//!
//! Every function reads its scenario in one of three ways (see
//! [`load_scenario`]): a file by `path` (exactly as the command line reads
//! it), `toml_text` laid over the built-in default scenario ([`overlay`]),
//! or, with neither, the built-in default. The reports are the library's
//! own JSON text, parsed by Python's `json`, so they are the command
//! line's byte for byte. Long work runs with the GIL released.

mod error;
mod overlay;
mod raw;

use std::path::{Path, PathBuf};
use std::time::Duration;

use chatterspice::calibrate::fit::{self, FitRequest, Record};
use chatterspice::capture::{Capture, Closed, read_capture};
use chatterspice::chatter::{Chatter, Interval};
use chatterspice::check;
use chatterspice::commands;
use chatterspice::pipeline::{self, RunOptions};
use chatterspice::report::{self, Format};
use chatterspice::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use chatterspice::spice::Ngspice;
use chatterspice::sweep::{self, NoProgress, Sampler, SweepMode, SweepOptions};
use chatterspice::waveform::read_state_csv;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use error::Failure;

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
/// built-in default, or the built-in default itself.
fn load_scenario(path: Option<PathBuf>, toml_text: Option<String>) -> Result<Loaded, Failure> {
    match (path, toml_text) {
        (Some(p), Some(_)) => Err(Failure::input(format!(
            "give a scenario file ({}) or toml_text, not both",
            p.display()
        ))),
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
            let (scenario, text) = overlay::parse(&text)?;
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

/// `timeout` in seconds as a duration, or the error naming it.
fn seconds(timeout: f64) -> Result<Duration, Failure> {
    match Duration::try_from_secs_f64(timeout) {
        Ok(d) if timeout > 0.0 => Ok(d),
        _ => Err(Failure::input(format!(
            "timeout = {timeout}: give the wall-clock limit of each ngspice run in seconds, > 0 \
             (e.g. 60.0)"
        ))),
    }
}

/// The chatter sequence of one closing of the scenario: the JSON of
/// `chatterspice bounce --format json` as a dict.
#[pyfunction]
#[pyo3(name = "bounce", signature = (path=None, *, toml_text=None, measured=None))]
fn py_bounce<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    toml_text: Option<String>,
    measured: Option<PathBuf>,
) -> PyResult<Bound<'py, PyAny>> {
    let text = match measured {
        // As the command line: a measured record is reported as it is.
        Some(csv) => {
            let chatter = Chatter::from_intervals(read_measured(&csv)?);
            report::render(Format::Json, &chatter, None)
        }
        None => {
            let loaded = load_scenario(path, toml_text)?;
            py.detach(|| commands::bounce(&loaded.scenario, Format::Json))
                .map_err(Failure::from)?
        }
    };
    json(py, &text)
}

/// What `run` returns: the report and the waveforms of the run.
#[pyclass(module = "chatterspice", frozen)]
struct Run {
    /// The JSON of `chatterspice run --format json`, as a dict.
    #[pyo3(get)]
    report: Py<PyAny>,
    /// The bounced run's vectors by name, as in its raw file (`time`,
    /// `v(in)`, ...): float64 arrays.
    #[pyo3(get)]
    waveforms: Py<PyDict>,
    /// The ideal-contact run's vectors, or None without that run.
    #[pyo3(get)]
    ideal_waveforms: Option<Py<PyDict>>,
    /// The deck ngspice ran: the netlist with the contact included.
    #[pyo3(get)]
    deck: String,
    /// The contact include (`contact.inc`) that was run.
    #[pyo3(get)]
    include: String,
}

#[pymethods]
impl Run {
    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let names: Vec<String> = self.waveforms.bind(py).keys().extract()?;
        Ok(format!(
            "<chatterspice.Run: waveforms {}>",
            names.join(", ")
        ))
    }
}

/// The main job: the relay's chatter switching the scenario's circuit in
/// ngspice, and the analysis of every probe.
#[pyfunction]
#[pyo3(name = "run", signature = (path=None, *, toml_text=None, measured=None, ideal=true, timeout=60.0))]
fn py_run(
    py: Python<'_>,
    path: Option<PathBuf>,
    toml_text: Option<String>,
    measured: Option<PathBuf>,
    ideal: bool,
    timeout: f64,
) -> PyResult<Run> {
    let timeout = seconds(timeout)?;
    let loaded = load_scenario(path, toml_text)?;
    let intervals = measured.as_deref().map(read_measured).transpose()?;
    let options = RunOptions {
        timeout,
        compare_ideal: ideal,
        ..RunOptions::default()
    };
    let scenario = &loaded.scenario;
    let mut result = py.detach(|| -> Result<_, Failure> {
        let ngspice = ngspice(timeout)?;
        Ok(match intervals {
            Some(i) => pipeline::run_measured(scenario, i, &ngspice, &options)?,
            None => pipeline::run(scenario, &ngspice, &options)?,
        })
    })?;
    // As the command line shows it: relative to where the user is.
    if let Some(relative) = std::env::current_dir()
        .ok()
        .and_then(|cwd| result.netlist.strip_prefix(cwd).ok().map(Path::to_path_buf))
    {
        result.netlist = relative;
    }
    let dimensionless = commands::dimensionless(scenario);
    let text = report::json::render_run(&result, dimensionless.as_ref());
    let ideal_waveforms = match &result.ideal {
        Some(sim) => Some(raw::vectors(py, &sim.plot)?.unbind()),
        None => None,
    };
    Ok(Run {
        report: json(py, &text)?.unbind(),
        waveforms: raw::vectors(py, &result.simulation.plot)?.unbind(),
        ideal_waveforms,
        deck: result.deck.text.clone(),
        include: result.include.text.clone(),
    })
}

/// The scenario's limits held against the run: the JSON of `chatterspice
/// check --format json` as a dict (`passed` says whether all held).
#[pyfunction]
#[pyo3(name = "check", signature = (path=None, *, toml_text=None, measured=None, timeout=60.0))]
fn py_check<'py>(
    py: Python<'py>,
    path: Option<PathBuf>,
    toml_text: Option<String>,
    measured: Option<PathBuf>,
    timeout: f64,
) -> PyResult<Bound<'py, PyAny>> {
    let timeout = seconds(timeout)?;
    let loaded = load_scenario(path, toml_text)?;
    let scenario = &loaded.scenario;
    let intervals = measured.as_deref().map(read_measured).transpose()?;
    let options = RunOptions {
        timeout,
        ..RunOptions::default()
    };
    let needs_ngspice = commands::check_needs_ngspice(scenario, intervals.is_some());
    let (verdict, evidence) = py.detach(|| -> Result<_, Failure> {
        let ngspice = needs_ngspice.then(|| ngspice(timeout)).transpose()?;
        Ok(match (intervals, &ngspice) {
            (Some(i), n) => check::measured(scenario, i, n.as_ref().map(|n| n as _), &options)?,
            (None, Some(n)) => check::run_with(scenario, n, &options)?,
            (None, None) => check::relay_only(scenario)?,
        })
    })?;
    let dimensionless = commands::dimensionless(scenario);
    json(
        py,
        &report::json::render_check(&verdict, &evidence, dimensionless.as_ref()),
    )
}

/// What `sweep` returns: the summary and one row per sample.
#[pyclass(module = "chatterspice", frozen)]
struct Sweep {
    /// `summary.json` of `chatterspice sweep`, as a dict.
    #[pyo3(get)]
    summary: Py<PyAny>,
    /// `sweep.csv` as a list of dicts, one per sample in index order:
    /// numbers as int or float, empty cells as None, the rest as str.
    #[pyo3(get)]
    rows: Py<PyList>,
    /// `sweep.csv` as text.
    #[pyo3(get)]
    csv: String,
}

#[pymethods]
impl Sweep {
    fn __repr__(&self, py: Python<'_>) -> String {
        format!("<chatterspice.Sweep: {} rows>", self.rows.bind(py).len())
    }
}

/// Run the scenario many times with the numbers of its `[sweep]` varied.
#[pyfunction]
#[pyo3(name = "sweep", signature = (path=None, *, toml_text=None, samples=None, seed=None, jobs=None,
                    mechanics_only=false, ideal=false, timeout=60.0))]
#[allow(clippy::too_many_arguments)]
fn py_sweep(
    py: Python<'_>,
    path: Option<PathBuf>,
    toml_text: Option<String>,
    samples: Option<u64>,
    seed: Option<u64>,
    jobs: Option<usize>,
    mechanics_only: bool,
    ideal: bool,
    timeout: f64,
) -> PyResult<Sweep> {
    let timeout = seconds(timeout)?;
    let jobs = match jobs.map(std::num::NonZeroUsize::new) {
        Some(None) => return Err(Failure::input("jobs = 0: give at least 1").into()),
        Some(Some(j)) => Some(j),
        None => None,
    };
    let loaded = load_scenario(path, toml_text)?;
    let scenario = &loaded.scenario;
    let (summary, csv) = py.detach(|| -> Result<_, Failure> {
        let sampler = Sampler::new(scenario, samples, seed)?;
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
        let mut csv = Vec::new();
        let collected = sweep::run(scenario, &sampler, &options, &mut csv, &NoProgress)?;
        let summary = collected.summary(&sampler)?.to_json();
        Ok((summary, String::from_utf8_lossy(&csv).into_owned()))
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

/// What `fit` returns: the report and the fitted scenario.
#[pyclass(module = "chatterspice", frozen)]
struct Fit {
    /// The JSON of `chatterspice fit --format json`, as a dict.
    #[pyo3(get)]
    report: Py<PyAny>,
    /// The fitted scenario as TOML, with its `[provenance]` (what `fit -o
    /// FITTED.toml` writes; a netlist path in it is absolute).
    #[pyo3(get)]
    scenario: String,
}

#[pymethods]
impl Fit {
    fn __repr__(&self) -> String {
        "<chatterspice.Fit: .report, .scenario>".to_owned()
    }
}

/// Fit the scenario's free keys to a record of the contact (a scope
/// capture or a measured `time,state` file) and/or its `[datasheet]`.
#[pyfunction]
#[pyo3(name = "fit", signature = (path=None, *, toml_text=None, capture=None, channel=None, measured=None,
                    free=None))]
fn py_fit(
    py: Python<'_>,
    path: Option<PathBuf>,
    toml_text: Option<String>,
    capture: Option<PathBuf>,
    channel: Option<String>,
    measured: Option<PathBuf>,
    free: Option<Vec<String>>,
) -> PyResult<Fit> {
    let loaded = load_scenario(path, toml_text)?;
    let record = match (capture, measured) {
        (Some(_), Some(_)) => {
            return Err(Failure::input("give capture or measured, not both").into());
        }
        (Some(scope), None) => {
            let (_, c) = analyse(&scope, channel.as_deref(), None, None)?;
            Some(Record {
                name: c.source.clone(),
                intervals: c.shifted_intervals(),
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
    let scenario = &loaded.scenario;
    let result = py
        .detach(|| fit::fit(scenario, &request))
        .map_err(Failure::from)?;
    let netlist = scenario
        .circuit
        .as_ref()
        .and_then(|c| std::fs::canonicalize(&c.netlist).ok());
    let fitted = fit::fitted_toml(&loaded.text, &result, netlist.as_deref())
        .map_err(|e| Failure::input(format!("cannot re-read the scenario: {e}")))?;
    Ok(Fit {
        report: json(py, &chatterspice::calibrate::render::json(&result))?.unbind(),
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

/// A scope capture of the contact: the JSON of `chatterspice capture
/// --format json` as a dict.
#[pyfunction]
#[pyo3(name = "capture", signature = (path, *, channel=None, low=None, high=None, closed=None))]
fn py_capture<'py>(
    py: Python<'py>,
    path: PathBuf,
    channel: Option<String>,
    low: Option<f64>,
    high: Option<f64>,
    closed: Option<String>,
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

/// Read an ngspice or LTspice raw file: its plots as mappings of numpy
/// arrays.
#[pyfunction]
#[pyo3(name = "read_raw")]
fn py_read_raw(py: Python<'_>, path: PathBuf) -> PyResult<raw::RawFile> {
    raw::RawFile::read(py, &path)
}

/// Relay contact bounce from physics, run through ngspice.
#[pymodule]
#[pyo3(name = "chatterspice")]
fn chatterspice_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add_function(wrap_pyfunction!(py_bounce, m)?)?;
    m.add_function(wrap_pyfunction!(py_run, m)?)?;
    m.add_function(wrap_pyfunction!(py_check, m)?)?;
    m.add_function(wrap_pyfunction!(py_sweep, m)?)?;
    m.add_function(wrap_pyfunction!(py_fit, m)?)?;
    m.add_function(wrap_pyfunction!(py_capture, m)?)?;
    m.add_function(wrap_pyfunction!(py_read_raw, m)?)?;
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
