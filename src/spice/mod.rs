//! Running ngspice: the netlist goes in, a [`RawFile`] (or a typed failure)
//! comes out.
//!
//! Everything above this module talks to a [`Runner`]:
//! - [`Ngspice`] runs the real program in batch mode
//!   (`ngspice -b -r out.raw deck.cir`, no shell) in a fresh work directory
//!   per run, reads stdout and stderr on their own threads (a full pipe
//!   would stall the child), and kills and reaps it at a wall-clock timeout
//!   — nothing in ngspice times out by itself;
//! - [`FakeRunner`] serves committed raw files, so analysis and reports are
//!   testable on machines without ngspice.
//!
//! A failed run is a [`SpiceError`] that says what went wrong in the
//! user's terms (the deck line, the simulated time and node, the timeout),
//! names the work directory and carries the tail of ngspice's log. The
//! log is read by [`classify::classify`], which knows that `Note:` and
//! `Warning:` lines are not failures.
//!
//! Runs share no state: a [`Runner`] is `Send + Sync` and many runs may go
//! at once (sweeps run them in parallel).

pub mod classify;
pub mod fake;
pub mod ngspice;

use std::fmt;
use std::io;
use std::path::PathBuf;
use std::time::Duration;

use thiserror::Error;

use crate::rawfile::{RawError, RawFile, RawWarning};

pub use classify::{Exit, Failure};
pub use fake::FakeRunner;
pub use ngspice::Ngspice;

/// Runs one deck.
pub trait Runner: Send + Sync {
    /// Runs `req` to completion: its raw file and log, or why there is
    /// no usable result.
    fn run(&self, req: &RunRequest) -> Result<RunOutput, SpiceError>;
}

/// One simulation to run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunRequest {
    /// The netlist text, title line first, with its analysis lines.
    pub deck: String,
    /// Files the deck `.include`s, written next to it in the work
    /// directory: (plain file name, contents).
    pub includes: Vec<(String, String)>,
    /// Wall-clock limit; the process is killed when it is reached.
    pub timeout: Duration,
    /// Keep the work directory (deck, includes, raw file) after the run.
    pub keep_workdir: bool,
}

impl RunRequest {
    /// Default limit: a minute is far beyond any chatter simulation this
    /// tool generates (they take well under a second) but short enough that
    /// a stuck sweep fails instead of hanging.
    pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(60);

    /// A request for `deck` with no includes, the default timeout, and
    /// the work directory removed afterwards.
    pub fn new(deck: impl Into<String>) -> RunRequest {
        RunRequest {
            deck: deck.into(),
            includes: Vec::new(),
            timeout: Self::DEFAULT_TIMEOUT,
            keep_workdir: false,
        }
    }
}

/// A successful run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// The raw file ngspice wrote, read.
    pub raw: RawFile,
    /// ngspice's stdout and stderr, interleaved in arrival order (progress
    /// lines dropped).
    pub log: String,
    /// e.g. `"39"`, when the program reported one.
    pub version: Option<String>,
    /// Wall-clock time of the run.
    pub elapsed: Duration,
    /// The kept work directory, when asked for.
    pub workdir: Option<PathBuf>,
    /// ngspice's `Warning:` lines (once each) and the raw reader's warnings.
    pub warnings: Vec<String>,
}

/// Where a failed run happened and what ngspice said last.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunContext {
    /// The run's work directory (deck, includes, raw file).
    pub workdir: PathBuf,
    /// Whether the work directory still exists.
    pub kept: bool,
    /// The last lines of the log.
    pub log_tail: String,
}

impl fmt::Display for RunContext {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "  work directory: {}", self.workdir.display())?;
        if !self.kept {
            write!(f, " (removed; keep it with keep_workdir)")?;
        }
        if self.log_tail.trim().is_empty() {
            write!(f, "\n  ngspice printed nothing")
        } else {
            write!(f, "\n  ngspice log (last lines):")?;
            for line in self.log_tail.lines() {
                write!(f, "\n    {line}")?;
            }
            Ok(())
        }
    }
}

/// How many log lines an error message carries.
pub const LOG_TAIL_LINES: usize = 12;

/// The last `LOG_TAIL_LINES` non-blank lines of a log, skipping ngspice's
/// memory statistics, which end every log and say nothing about the failure.
pub fn log_tail(log: &str) -> String {
    let noise = [
        "Total DRAM available",
        "DRAM currently available",
        "Maximum ngspice program size",
        "Current ngspice program size",
        "Shared ngspice pages",
        "Text (code) pages",
        "Stack =",
        "Library pages",
        "Total elapsed time",
        "Total analysis time",
    ];
    let mut tail: Vec<String> = log
        .lines()
        .rev()
        .filter(|l| !l.trim().is_empty())
        .filter(|l| !noise.iter().any(|n| l.trim_start().starts_with(n)))
        .take(LOG_TAIL_LINES)
        .map(|l| shorten(l, LOG_LINE_CHARS))
        .collect();
    tail.reverse();
    tail.join("\n")
}

/// The longest log line an error message quotes, in characters.
const LOG_LINE_CHARS: usize = 300;

/// `line`, cut to `max` characters (control characters shown escaped).
fn shorten(line: &str, max: usize) -> String {
    let mut out: String = line
        .chars()
        .take(max)
        .flat_map(|c| {
            if c.is_control() && c != '\t' {
                c.escape_default().collect::<Vec<_>>()
            } else {
                vec![c]
            }
        })
        .collect();
    let total = line.chars().count();
    if total > max {
        out.push_str(&format!(" [... {} more characters]", total - max));
    }
    out
}

/// Why a run produced no usable result.
///
/// The run context is boxed so that `Result<RunOutput, SpiceError>` stays
/// small.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SpiceError {
    /// The ngspice program cannot be found or does not answer `-v`.
    #[error(
        "ngspice not found: cannot run `{}` ({source}); install it with \
         `apt-get install -y ngspice`, or set CHATTERSPICE_NGSPICE to the ngspice binary",
        program.display()
    )]
    NotFound {
        /// The program looked for.
        program: PathBuf,
        /// Why it cannot be run.
        #[source]
        source: io::Error,
    },
    /// The run's work directory cannot be created.
    #[error("cannot create a work directory in {}: {source}", parent.display())]
    WorkDir {
        /// The directory it was to be created in.
        parent: PathBuf,
        /// Why not.
        #[source]
        source: io::Error,
    },
    /// An include's name is not a plain file name, or is the deck's or
    /// the raw file's.
    #[error(
        "include file name {name:?} must be a plain file name (no directories, not \
         `deck.cir` or `out.raw`): it is written next to the deck in the work directory"
    )]
    IncludeName {
        /// The name given.
        name: String,
    },
    /// The deck or an include cannot be written to the work directory.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why not.
        #[source]
        source: io::Error,
    },
    /// The ngspice process cannot be started or waited for.
    #[error("cannot run `{}`: {source}\n{context}", program.display())]
    Process {
        /// The program.
        program: PathBuf,
        /// Why not.
        #[source]
        source: io::Error,
        /// The work directory.
        context: Box<RunContext>,
    },
    /// ngspice ran and failed; its log says how.
    #[error("{failure}\n{context}")]
    Failed {
        /// The failure, classified from the log.
        failure: Failure,
        /// The work directory and the log's tail.
        context: Box<RunContext>,
    },
    /// ngspice could not write its raw file (usually a full disk).
    #[error(
        "ngspice could not write its raw file in the temporary work directory {}: the file \
         system is probably full; free space there, or set TMPDIR to a directory with room\n{context}",
        dir.display()
    )]
    RawWrite {
        /// The work directory.
        dir: PathBuf,
        /// The work directory and the log's tail.
        context: Box<RunContext>,
    },
    /// ngspice ran past the timeout and was killed.
    #[error(
        "ngspice was still running after the {} s timeout and was killed; raise the \
         timeout, or shorten the analysis (a smaller stop time, a larger TMAX)\n{context}",
        limit.as_secs_f64()
    )]
    Timeout {
        /// The timeout.
        limit: Duration,
        /// The work directory and the log's tail.
        context: Box<RunContext>,
    },
    /// ngspice exited cleanly without writing a raw file.
    #[error(
        "ngspice finished without writing a raw file; does the deck have an analysis \
         line (.tran, .ac, .op) outside a .control block?\n{context}"
    )]
    MissingRaw {
        /// The work directory and the log's tail.
        context: Box<RunContext>,
    },
    /// The raw file ngspice wrote cannot be read.
    #[error("the raw file ngspice wrote is unreadable: {source}\n{context}")]
    BadRaw {
        /// Why.
        #[source]
        source: RawError,
        /// The work directory and the log's tail.
        context: Box<RunContext>,
    },
    /// ngspice exited cleanly but its raw file is cut short (a write
    /// failure, not a result).
    #[error("the raw file ngspice wrote is cut short: {warning}\n{context}")]
    TruncatedRaw {
        /// What the reader found.
        warning: RawWarning,
        /// The work directory and the log's tail.
        context: Box<RunContext>,
    },
}

impl SpiceError {
    /// The run's context (work directory, log tail), when there was a run.
    pub fn context(&self) -> Option<&RunContext> {
        match self {
            SpiceError::Process { context, .. }
            | SpiceError::Failed { context, .. }
            | SpiceError::Timeout { context, .. }
            | SpiceError::RawWrite { context, .. }
            | SpiceError::MissingRaw { context }
            | SpiceError::BadRaw { context, .. }
            | SpiceError::TruncatedRaw { context, .. } => Some(context),
            SpiceError::NotFound { .. }
            | SpiceError::WorkDir { .. }
            | SpiceError::IncludeName { .. }
            | SpiceError::Write { .. } => None,
        }
    }

    /// The classified failure, for [`SpiceError::Failed`].
    pub fn failure(&self) -> Option<&Failure> {
        match self {
            SpiceError::Failed { failure, .. } => Some(failure),
            _ => None,
        }
    }
}
