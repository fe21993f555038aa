//! Why a run gave no result: [`SpiceError`], with the work directory and
//! the last lines of ngspice's log ([`RunContext`], [`log_tail`]).

use std::fmt;
use std::io;
use std::path::PathBuf;
use std::time::Duration;

use thiserror::Error;

use super::classify::Failure;
use crate::rawfile::{RawError, RawWarning};

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
            write!(f, " (removed; keep it with --keep-workdir)")?;
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
