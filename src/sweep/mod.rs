//! Sweeps: the same relay and circuit run many times, each sample with
//! its own values of a few numbers, to answer "does the design hold for
//! every relay off the line, and how close to the edge is it?"
//! (`chatterspice sweep`, docs/sweep.md).
//!
//! A sweep is built from the scenario's `[sweep]` section in four parts,
//! one module each:
//! - [`sample`]: the values of sample `i` — random draws (`[sweep.vary]`,
//!   deterministic in (seed, key, i)) or the points of a one- or two-key
//!   grid (`[sweep.grid]`);
//! - [`mod@run`]: every sample through [`pipeline::run`](crate::pipeline::run)
//!   (mechanics → contact → netlist → ngspice → analysis) or through the
//!   mechanics alone, on several threads, each sample's outcome a
//!   [`Record`] — a failing sample (never closes, ngspice error, timeout)
//!   is a record too, and the sweep goes on;
//! - [`table`]: the records as `sweep.csv`, one row per sample in index
//!   order, and [`table::merge`] that joins the CSVs of shards;
//! - [`summary`]: distributions, the worst case and the failures, as
//!   `summary.json`, a table for people, and a plot ([`plot`]).
//!
//! # Determinism
//! Sample `i`'s values depend only on the seed and `i`, never on `--jobs`
//! or on the shard that runs it, and rows are written in index order, so
//! the same sweep gives byte-identical files however it is run. A shard
//! `K/N` runs the indices `i` with `i % N == K − 1` (interleaved rather
//! than contiguous, so that a grid's slow corner is spread over all
//! shards); merging the shards' CSVs gives the CSV of one run, byte for
//! byte.

pub mod plot;
pub mod resume;
pub mod run;
pub mod sample;
pub mod summary;
pub mod table;
pub mod verdict;

use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

use thiserror::Error;

use crate::chatter::Outcome;
use crate::scenario::ScenarioError;

pub use run::{Mode, NoProgress, Progress, SweepOptions, evaluate, run, run_from};
pub use sample::Sampler;
pub use summary::{Collected, Summary};
pub use verdict::Verdict;

/// Why a sweep cannot run (a failing *sample* is not an error: it is
/// recorded in its row).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SweepError {
    /// The scenario has no `[sweep]`, or one that names no key in
    /// `[sweep.vary]` or `[sweep.grid]`.
    #[error(
        "{}: nothing to sweep: add a [sweep] section with the numbers to vary, e.g.\n  \
         [sweep]\n  samples = 1000\n  [sweep.vary]\n  \"mechanics.mass\" = 0.1            # ±10 %\n  \
         \"surface.damping\" = {{ normal = 0.05 }}",
        path.display()
    )]
    NothingToVary {
        /// The scenario file.
        path: PathBuf,
    },
    /// A sample count was given (`--samples`) for a grid sweep, which runs
    /// each of its points once.
    #[error(
        "{}: --samples {samples} with a [sweep.grid]: a grid runs each of its points once; \
         drop --samples, or change the grid's `steps`",
        path.display()
    )]
    SamplesWithGrid {
        /// The scenario file.
        path: PathBuf,
        /// The sample count given.
        samples: u64,
    },
    /// The sample count is 0.
    #[error("{}: a sweep needs at least one sample; give --samples 1 or more", path.display())]
    NoSamples {
        /// The scenario file.
        path: PathBuf,
    },
    /// More samples than one sweep runs ([`sample::MAX_SAMPLES`]).
    #[error(
        "{}: {count} samples ({what}) is more than the {limit} one sweep runs; \
         use fewer, or run the study as several sweeps",
        path.display(),
        limit = sample::MAX_SAMPLES
    )]
    TooManySamples {
        /// The scenario file.
        path: PathBuf,
        /// The samples asked for.
        count: u64,
        /// Where the count comes from: `sweep.samples` (or `--samples`),
        /// or the product of the grid's `steps`.
        what: &'static str,
    },
    /// A key of `[sweep.vary]` has no value in the scenario to vary
    /// around.
    #[error("{}: `{key}` has no value in the scenario to vary around; set it", path.display())]
    NoNominal {
        /// The scenario file.
        path: PathBuf,
        /// The dotted number key.
        key: String,
    },
    /// Many redraws in a row all fell outside a key's bounds (a bound of its
    /// own such as `surface.restitution` ≤ 1, and ±4σ for a normal
    /// tolerance): the bounds leave (almost) nothing to draw from.
    #[error(
        "sample {index}: no value of `{key}` within its bounds after many draws; \
         lower its tolerance in [sweep.vary]"
    )]
    Truncation {
        /// The dotted number key.
        key: String,
        /// The sample's index.
        index: u64,
    },
    /// A circuit sweep of a scenario without a `[circuit]` netlist or
    /// without a `[[probe]]`.
    #[error(
        "{}: a circuit sweep needs a [circuit] netlist and at least one [[probe]]; \
         add them, or pass --mechanics-only to sweep the bounce alone",
        path.display()
    )]
    NeedsCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// A mechanics-only sweep of a coil-driven relay, which moves only in
    /// its driver circuit.
    #[error(
        "{}: a coil-driven relay moves only in its driver circuit: drop --mechanics-only \
         (each sample then runs the coupled ngspice simulation)",
        path.display()
    )]
    CoilNeedsCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// A mechanics-only sweep of a scenario with arc limits, which only a
    /// circuit run measures.
    #[error(
        "{}: `limits.max_arc_energy` and `limits.max_arc_count` hold the arcs of the \
         circuit run: drop --mechanics-only, or remove those limits",
        path.display()
    )]
    ArcLimitsNeedCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// A shard that is not `K/N` with 1 ≤ K ≤ N.
    #[error("shard `{text}`: give K/N with 1 <= K <= N, e.g. --shard 3/8 for the third of eight")]
    Shard {
        /// The shard as given.
        text: String,
    },
    /// The CSV header or rows could not be written.
    #[error("cannot write the sweep's rows")]
    Write(#[source] std::io::Error),
    /// The scenario cannot be used, or cannot take a sweep's values (or
    /// its netlist cannot be read, for a circuit sweep).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
}

/// The slice `K/N` of a sweep: the indices `i` with `i % N == K − 1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// K, 1-based.
    pub index: u64,
    /// N.
    pub count: u64,
}

impl Shard {
    /// The whole sweep, `1/1`.
    pub const WHOLE: Shard = Shard { index: 1, count: 1 };

    /// How many of `total` samples this shard runs.
    pub fn len(&self, total: u64) -> u64 {
        let first = self.index - 1;
        if total <= first {
            0
        } else {
            (total - first).div_ceil(self.count)
        }
    }

    /// Whether this shard runs nothing of `total`.
    pub fn is_empty(&self, total: u64) -> bool {
        self.len(total) == 0
    }

    /// The sample index of this shard's `position`-th sample.
    pub fn sample(&self, position: u64) -> u64 {
        self.index - 1 + position * self.count
    }
}

impl FromStr for Shard {
    type Err = SweepError;

    fn from_str(text: &str) -> Result<Shard, SweepError> {
        let bad = || SweepError::Shard {
            text: text.to_owned(),
        };
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let index: u64 = k.trim().parse().map_err(|_| bad())?;
        let count: u64 = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// One probe of one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbeRecord {
    /// Schmitt edges of the bounced run.
    pub edges: usize,
    /// max |value| over the run, in the probe's unit (V or A).
    pub peak: f64,
    /// Schmitt edges with an ideal contact, when that ran too.
    pub ideal_edges: Option<usize>,
}

/// What one sample gave: a row of `sweep.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    /// The sample's index in the sweep, from 0.
    pub index: u64,
    /// The varied keys' values, in [`Sampler::keys`] order.
    pub values: Vec<f64>,
    /// `None` when the sample failed before the mechanics ran.
    pub outcome: Option<Outcome>,
    /// Openings after the first make.
    pub bounce_count: Option<usize>,
    /// s, the first make: the operate time, from the force step or, for a
    /// coil-driven relay, from the coil being energized.
    pub first_impact: Option<f64>,
    /// s, closed for good, counted from the same moment as `first_impact`.
    pub settle_time: Option<f64>,
    /// s, settle time − first impact (when the contact closed for good).
    pub bounce_time: Option<f64>,
    /// s, for a coil-driven relay: the longest release time of its
    /// operations (coil off → the NO contact breaks).
    pub release_time: Option<f64>,
    /// s, for a coil-driven relay: the longest bounce on the rest stop
    /// (the NC contact) after a release.
    pub nc_bounce_time: Option<f64>,
    /// With `[arc]`: the run's arcs.
    pub arc_count: Option<usize>,
    /// J, with `[arc]`: all the run's arcs together.
    pub arc_energy: Option<f64>,
    /// With `[arc]`: the run's breakdowns of the open gap.
    pub breakdowns: Option<usize>,
    /// One per `[[probe]]`, for a circuit sweep that reached ngspice's
    /// results; empty otherwise.
    pub probes: Vec<ProbeRecord>,
    /// Whether the sample passed its limits, failed one, or could not run.
    pub verdict: Verdict,
    /// The keys of the limits that failed, in the scenario's order.
    pub failed_limits: Vec<String>,
    /// Why the sample failed: the error and its causes, one line.
    pub error: Option<String>,
}

impl Record {
    /// Whether the contact ended closed for good.
    pub fn closed(&self) -> bool {
        self.outcome.is_some_and(Outcome::is_closed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_partition_the_indices() {
        for total in [0u64, 1, 5, 10, 11] {
            let mut seen = Vec::new();
            for k in 1..=3 {
                let shard: Shard = format!("{k}/3").parse().unwrap();
                seen.extend((0..shard.len(total)).map(|p| shard.sample(p)));
            }
            seen.sort_unstable();
            assert_eq!(seen, (0..total).collect::<Vec<_>>(), "{total}");
        }
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        assert_eq!(" 2 / 5".parse::<Shard>().unwrap().to_string(), "2/5");
    }
}
