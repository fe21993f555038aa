//! The library's errors as Python exceptions.
//!
//! Bad input (a scenario value, an unknown key, a broken raw file or
//! capture) is [`InputError`], a `ValueError`; a file that is not there is
//! `FileNotFoundError` (`PermissionError` when it cannot be read); ngspice
//! failing, or missing, is [`NgspiceError`] and the mechanics failing is
//! [`SimulationError`], both `RuntimeError`s. The message is the one the
//! command line prints: the library's error and each of its causes. An
//! exception about a scenario key carries `key`, `path` and `line`.

use std::error::Error as StdError;
use std::fmt::Write as _;
use std::io;
use std::path::Path;

use chatterspice::calibrate::fit::FitError;
use chatterspice::capture::{CaptureError, EdgeError};
use chatterspice::check::CheckError;
use chatterspice::envelope::EnvelopeError;
use chatterspice::life::LifeError;
use chatterspice::output::WriteError;
use chatterspice::pipeline::{CouplingError, PassError, RunError};
use chatterspice::rawfile::RawError;
use chatterspice::scenario::{Location, ScenarioError};
use chatterspice::spice::SpiceError;
use chatterspice::sweep::SweepError;
use chatterspice::sweep::files::FilesError;
use chatterspice::verdict::VerdictError;
use chatterspice::waveform::WaveformError;
use pyo3::exceptions::{
    PyFileExistsError, PyFileNotFoundError, PyPermissionError, PyRuntimeError, PyUserWarning,
    PyValueError,
};
use pyo3::prelude::*;

pyo3::create_exception!(
    chatterspice,
    InputError,
    PyValueError,
    "Bad input: a scenario key or value, a netlist, a raw file, a capture or \
     a measured record. `key`, `path` and `line` say where, when known."
);
pyo3::create_exception!(
    chatterspice,
    NgspiceError,
    PyRuntimeError,
    "ngspice could not be run, or failed on the deck; the message carries \
     ngspice's own words."
);
pyo3::create_exception!(
    chatterspice,
    SimulationError,
    PyRuntimeError,
    "The mechanics, the coil coupling or the analysis of a run failed."
);

pyo3::create_exception!(
    chatterspice,
    ChatterspiceWarning,
    PyUserWarning,
    "Something worth a look that did not stop the call: a run that is not \
     physical as set up, a coupling that fell back from lock-step to passes, \
     a life that could not be estimated, a remark on a limit's figure."
);

/// Issue each of `said` as a [`ChatterspiceWarning`], worded for Python.
pub fn warn_all(py: Python<'_>, said: &[String]) -> PyResult<()> {
    let category = py.get_type::<ChatterspiceWarning>();
    for text in said {
        let message = std::ffi::CString::new(pythonic(text).replace('\0', " ")).unwrap_or_default();
        PyErr::warn(py, &category, &message, 1)?;
    }
    Ok(())
}

/// `message` with the command line's options named as the Python
/// arguments that set them (`--keep-workdir` is `keep_workdir=True`).
pub fn pythonic(message: &str) -> String {
    const WORDS: [(&str, &str); 14] = [
        ("--keep-workdir", "keep_workdir=True"),
        ("--free KEY,...", "free=[...]"),
        ("--capture or --measured", "capture= or measured="),
        ("pass --mechanics-only", "pass mechanics_only=True"),
        ("drop --mechanics-only", "drop mechanics_only=True"),
        ("--mechanics-only", "mechanics_only=True"),
        ("drop --samples", "drop samples="),
        ("--samples ", "samples="),
        ("(or --samples)", "(or samples=)"),
        (
            "`chatterspice raw FILE --format csv` streams",
            "read_raw reads",
        ),
        ("--force overwrites", "force=True overwrites"),
        ("pass --force", "pass force=True"),
        ("--resume ", "resume="),
        ("choose another --out", "choose another out="),
    ];
    let mut text = message.to_owned();
    for (flag, argument) in WORDS {
        text = text.replace(flag, argument);
    }
    // Any other option: its argument's name (`--max-iterations` is
    // `max_iterations=`).
    let mut out = String::with_capacity(text.len());
    let mut rest = text.as_str();
    while let Some(at) = rest.find("--") {
        let (before, after) = rest.split_at(at);
        out.push_str(before);
        let name: String = after[2..]
            .chars()
            .take_while(|c| c.is_ascii_lowercase() || *c == '-')
            .collect();
        let starts_word = before
            .chars()
            .last()
            .is_none_or(|c| c.is_whitespace() || "(`'\"[".contains(c));
        if starts_word
            && name.len() > 1
            && name.chars().next().is_some_and(|c| c.is_ascii_lowercase())
        {
            out.push_str(&name.replace('-', "_"));
            out.push('=');
            rest = &after[2 + name.len()..];
        } else {
            out.push_str("--");
            rest = &after[2..];
        }
    }
    out.push_str(rest);
    out
}

/// Which Python exception an error becomes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Input,
    Ngspice,
    Simulation,
}

/// A library error on its way to Python: its kind, its message and where
/// in a scenario it is.
#[derive(Debug)]
pub struct Failure {
    kind: Kind,
    message: String,
    key: Option<String>,
    location: Option<Location>,
    /// Why a file could not be read, when that is the error.
    io: Option<io::ErrorKind>,
}

impl Failure {
    /// Bad input described by `message`.
    pub fn input(message: impl Into<String>) -> Failure {
        Failure {
            kind: Kind::Input,
            message: message.into(),
            key: None,
            location: None,
            io: None,
        }
    }

    /// The work of a call failed for a reason of its own.
    pub fn simulation(message: impl Into<String>) -> Failure {
        Failure {
            kind: Kind::Simulation,
            ..Failure::input(message)
        }
    }

    /// `path` could not be read: `what` it was meant to be.
    pub fn unreadable(path: &Path, what: &str, source: &io::Error) -> Failure {
        Failure {
            io: Some(source.kind()),
            ..Failure::input(format!("{}: cannot read {what}: {source}", path.display()))
        }
    }

    /// The same failure, its message after `context` (what was being
    /// read when it happened).
    pub fn within(self, context: impl std::fmt::Display) -> Failure {
        Failure {
            message: format!("{context}: {}", self.message),
            ..self
        }
    }

    fn of(kind: Kind, err: &(dyn StdError + 'static)) -> Failure {
        Failure {
            kind,
            message: with_causes(err),
            key: None,
            location: None,
            io: io_kind(err),
        }
    }

    /// A scenario error; `causes` false leaves out the parser's excerpt,
    /// which quotes text the user did not write (see `overlay`).
    pub fn scenario(err: &ScenarioError, causes: bool) -> Failure {
        let message = if causes {
            with_causes(err)
        } else {
            err.to_string()
        };
        Failure {
            kind: Kind::Input,
            message,
            key: err.key().map(str::to_owned),
            location: err.location().cloned(),
            io: io_kind(err),
        }
    }
}

impl Failure {
    /// The failure with the key, file and line its message names filled
    /// in where the error itself did not say them.
    fn located(self) -> Failure {
        let named = named_place(&self.message);
        let key = self.key.or_else(|| named_key(&self.message));
        let location = match (self.location, named) {
            (Some(l), _) => Some(l),
            (None, Some((path, line))) => Some(Location {
                path: path.into(),
                line,
            }),
            (None, None) => None,
        };
        Failure {
            key,
            location,
            ..self
        }
    }
}

/// The file (and line) a message starts with, `FILE: ...` or
/// `FILE:LINE: ...`, when it is a file's name.
fn named_place(message: &str) -> Option<(String, Option<usize>)> {
    let first = message.lines().next()?;
    let head = &first[..first.find(": ")?];
    let (path, line) = match head.rsplit_once(':') {
        Some((p, l)) if !p.is_empty() && l.chars().all(|c| c.is_ascii_digit()) && !l.is_empty() => {
            (p, l.parse::<usize>().ok())
        }
        _ => (head, None),
    };
    let looks_like_file = path.starts_with('<') && path.ends_with('>')
        || Path::new(path).extension().is_some_and(|e| {
            e.to_str().is_some_and(|e| {
                e.len() <= 5 && e.chars().all(|c| c.is_ascii_alphanumeric()) && !e.is_empty()
            })
        }) && !path.contains(' ')
        || Path::new(path).is_file();
    looks_like_file.then(|| (path.to_owned(), line))
}

/// The first scenario key a message names in backquotes, e.g.
/// `` `coil.drive_voltage` ``, or the `[limits] KEY` it names.
fn named_key(message: &str) -> Option<String> {
    let is_key = |k: &str| {
        k.contains('.')
            && !k.starts_with('.')
            && !k.ends_with('.')
            && k.chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_' || c == '.')
            && k.split('.').all(|part| {
                !part.is_empty() && part.chars().next().is_some_and(|c| c.is_ascii_lowercase())
            })
    };
    message
        .split('`')
        .skip(1)
        .step_by(2)
        .find(|k| is_key(k))
        .map(str::to_owned)
}

/// The error and each cause on lines of their own, as the command line
/// prints them.
fn with_causes(err: &(dyn StdError + 'static)) -> String {
    let mut text = err.to_string();
    let mut cause = err.source();
    while let Some(c) = cause {
        let shown = c.to_string();
        let mut lines = shown.trim_end().lines();
        if let Some(first) = lines.next() {
            let _ = write!(text, "\n  caused by: {first}");
        }
        for line in lines {
            let _ = write!(text, "\n    {line}");
        }
        cause = c.source();
    }
    text
}

/// How reading a file failed, when an I/O error is in the chain.
fn io_kind(err: &(dyn StdError + 'static)) -> Option<io::ErrorKind> {
    let mut cause = Some(err);
    while let Some(c) = cause {
        if let Some(e) = c.downcast_ref::<io::Error>() {
            return Some(e.kind());
        }
        cause = c.source();
    }
    None
}

impl From<Failure> for PyErr {
    fn from(f: Failure) -> PyErr {
        let f = Failure {
            message: pythonic(&f.message),
            ..f.located()
        };
        let err = match (f.kind, f.io) {
            (Kind::Input, Some(io::ErrorKind::NotFound)) => PyFileNotFoundError::new_err(f.message),
            (Kind::Input, Some(io::ErrorKind::AlreadyExists)) => {
                PyFileExistsError::new_err(f.message)
            }
            (Kind::Input, Some(io::ErrorKind::PermissionDenied)) => {
                PyPermissionError::new_err(f.message)
            }
            (Kind::Input, _) => InputError::new_err(f.message),
            (Kind::Ngspice, _) => NgspiceError::new_err(f.message),
            (Kind::Simulation, _) => SimulationError::new_err(f.message),
        };
        Python::attach(|py| {
            let value = err.value(py);
            let path = f.location.as_ref().map(|l| l.path.display().to_string());
            let line = f.location.as_ref().and_then(|l| l.line);
            // Setting attributes on a fresh exception cannot fail.
            let _ = value.setattr("key", f.key);
            let _ = value.setattr("path", path);
            let _ = value.setattr("line", line);
        });
        err
    }
}

impl From<ScenarioError> for Failure {
    fn from(e: ScenarioError) -> Failure {
        Failure::scenario(&e, true)
    }
}

impl From<SpiceError> for Failure {
    fn from(e: SpiceError) -> Failure {
        Failure::of(Kind::Ngspice, &e)
    }
}

impl From<RawError> for Failure {
    fn from(e: RawError) -> Failure {
        Failure::of(Kind::Input, &e)
    }
}

impl From<CaptureError> for Failure {
    fn from(e: CaptureError) -> Failure {
        Failure::of(Kind::Input, &e)
    }
}

impl From<EdgeError> for Failure {
    fn from(e: EdgeError) -> Failure {
        Failure::of(Kind::Input, &e)
    }
}

impl From<WaveformError> for Failure {
    fn from(e: WaveformError) -> Failure {
        Failure::of(Kind::Input, &e)
    }
}

impl From<FitError> for Failure {
    fn from(e: FitError) -> Failure {
        match e {
            // The scenario's own error names the file: said once.
            FitError::UnknownKey { key, source, .. } => {
                let scenario = Failure::scenario(&source, true);
                let message = match scenario.message.split_once(": ") {
                    Some((path, rest)) => format!("{path}: free key `{key}`: {rest}"),
                    None => format!("free key `{key}`: {}", scenario.message),
                };
                Failure {
                    message,
                    key: Some(key),
                    ..scenario
                }
            }
            e => Failure::of(Kind::Input, &e),
        }
    }
}

impl From<SweepError> for Failure {
    fn from(e: SweepError) -> Failure {
        match e {
            SweepError::Scenario(e) => e.into(),
            SweepError::Write(_) | SweepError::Scratch(_) | SweepError::Stopped => {
                Failure::of(Kind::Simulation, &e)
            }
            e => Failure::of(Kind::Input, &e),
        }
    }
}

impl From<FilesError> for Failure {
    fn from(e: FilesError) -> Failure {
        match e {
            FilesError::Sweep(e) => e.into(),
            FilesError::Exists { .. } | FilesError::Write(WriteError::Exists { .. }) => Failure {
                io: Some(io::ErrorKind::AlreadyExists),
                ..Failure::of(Kind::Input, &e)
            },
            FilesError::Resume(_) | FilesError::Write(_) => Failure::of(Kind::Input, &e),
            e => Failure::of(Kind::Simulation, &e),
        }
    }
}

impl From<CheckError> for Failure {
    fn from(e: CheckError) -> Failure {
        match e {
            CheckError::Scenario(e) => e.into(),
            CheckError::Run(e) => (*e).into(),
            CheckError::Motion { .. } | CheckError::Mechanics { .. } => {
                Failure::of(Kind::Simulation, &e)
            }
            e => Failure::of(Kind::Input, &e),
        }
    }
}

impl From<RunError> for Failure {
    fn from(e: RunError) -> Failure {
        let kind = match &e {
            RunError::Scenario(e) => return Failure::scenario(e, true),
            RunError::Pass(PassError::Spice { .. }) => Kind::Ngspice,
            RunError::Coupling(c) => match **c {
                CouplingError::Scenario(_)
                | CouplingError::Netlist(_)
                | CouplingError::NoCoil { .. }
                | CouplingError::NoCircuit { .. }
                | CouplingError::CoilInstances { .. }
                | CouplingError::NcNotInstantiated { .. } => Kind::Input,
                CouplingError::Spice { .. } => Kind::Ngspice,
                _ => Kind::Simulation,
            },
            RunError::Mechanics { .. }
            | RunError::Motion { .. }
            | RunError::Waveform { .. }
            | RunError::Arc { .. } => Kind::Simulation,
            // The netlist, a missing [circuit] or probe, a probe naming a
            // vector the circuit does not have, .tran missing.
            _ => Kind::Input,
        };
        Failure::of(kind, &e)
    }
}

impl From<EnvelopeError> for Failure {
    fn from(e: EnvelopeError) -> Failure {
        match e {
            EnvelopeError::Scenario(e) => e.into(),
            e => Failure::of(Kind::Input, &e),
        }
    }
}

impl From<LifeError> for Failure {
    fn from(e: LifeError) -> Failure {
        match e {
            LifeError::Closing(e) => e.into(),
            LifeError::Run { .. } | LifeError::Own(_) => {
                let kind = match &e {
                    LifeError::Run { source, .. } | LifeError::Own(source) => {
                        Failure::from_run_kind(source)
                    }
                    _ => Kind::Simulation,
                };
                Failure::of(kind, &e)
            }
            LifeError::Io(_) => Failure::of(Kind::Simulation, &e),
            e => Failure::of(Kind::Input, &e),
        }
    }
}

impl Failure {
    /// The kind a run error becomes.
    fn from_run_kind(e: &RunError) -> Kind {
        match e {
            RunError::Pass(PassError::Spice { .. }) => Kind::Ngspice,
            RunError::Mechanics { .. }
            | RunError::Motion { .. }
            | RunError::Waveform { .. }
            | RunError::Arc { .. } => Kind::Simulation,
            _ => Kind::Input,
        }
    }
}

impl From<VerdictError> for Failure {
    fn from(e: VerdictError) -> Failure {
        match e {
            VerdictError::Run(e) => e.into(),
            VerdictError::Check(e) => e.into(),
            VerdictError::Life(e) => e.into(),
            VerdictError::Envelope(e) => e.into(),
            VerdictError::Spice(e) => e.into(),
            e => Failure::of(Kind::Simulation, &e),
        }
    }
}
