//! What a run takes and gives: the [`Runner`] that runs decks, a
//! [`RunRequest`] (the deck, its includes, the limit) and a successful
//! run's [`RunOutput`].

use std::path::PathBuf;
use std::time::Duration;

use super::error::SpiceError;
use crate::rawfile::RawFile;

/// Runs decks.
pub trait Runner: Send + Sync {
    /// Runs `req` to completion: its raw file and log, or why there is
    /// no usable result.
    fn run(&self, req: &RunRequest) -> Result<RunOutput, SpiceError>;

    /// Runs every request of `reqs`, giving for each what [`Runner::run`]
    /// would give, in order. A runner may share work between them (one
    /// simulator process for many decks); this default runs them one by
    /// one.
    fn run_many(&self, reqs: &[RunRequest]) -> Vec<Result<RunOutput, SpiceError>> {
        reqs.iter().map(|req| self.run(req)).collect()
    }

    /// Whether a coil-driven run through this runner may instead run in
    /// lock-step through ngspice's shared library (the real simulator:
    /// yes; a runner that serves recorded results: no).
    fn lock_step(&self) -> bool {
        false
    }
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
