//! The verdict of one sample: did the design hold?
//!
//! [`verdict`] is the single place where a sample is judged, by the same
//! rules as `chatterspice check` ([`crate::check`]): a circuit sweep holds
//! each sample's run against `[limits]` and every probe's limits; a
//! `--mechanics-only` sweep has no circuit, so it holds the chatter
//! against `[limits]` alone and ignores probe limits. Without limits every
//! sample that ran passes. A sample that could not run is
//! [`SampleVerdict::Error`], whatever its limits.

use crate::chatter::Chatter;
use crate::check;
use crate::pipeline::RunResult;
use crate::scenario::Scenario;

/// The `verdict` column of `sweep.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum SampleVerdict {
    /// The sample ran and every limit held (or it had none).
    Pass,
    /// A limit failed.
    Fail,
    /// The sample could not run to the end (see its `error`).
    Error,
}

/// The old name of [`SampleVerdict`].
#[deprecated(note = "renamed to `SampleVerdict`")]
pub type Verdict = SampleVerdict;

impl SampleVerdict {
    /// The name in the CSV and the JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            SampleVerdict::Pass => "pass",
            SampleVerdict::Fail => "fail",
            SampleVerdict::Error => "error",
        }
    }

    /// The verdict named `text` (as written by [`SampleVerdict::as_str`]).
    pub fn parse(text: &str) -> Option<SampleVerdict> {
        match text {
            "pass" => Some(SampleVerdict::Pass),
            "fail" => Some(SampleVerdict::Fail),
            "error" => Some(SampleVerdict::Error),
            _ => None,
        }
    }
}

/// The verdict of a sample that ran, and the keys of the limits it
/// failed (`limits.max_bounce_time`, `probe[0].max_edges`, …) in the
/// scenario's order: `run` is `None` for a mechanics-only sweep.
pub fn verdict(
    scenario: &Scenario,
    chatter: &Chatter,
    run: Option<&RunResult>,
) -> (SampleVerdict, Vec<String>) {
    let checked = match run {
        Some(run) => check::evaluate(scenario, run),
        None => match &scenario.limits {
            Some(limits) => check::Verdict::new(check::relay_checks(limits, chatter, &[])),
            None => return (SampleVerdict::Pass, Vec::new()),
        },
    };
    let failed: Vec<String> = checked.failures().map(|c| c.key.clone()).collect();
    if failed.is_empty() {
        (SampleVerdict::Pass, failed)
    } else {
        (SampleVerdict::Fail, failed)
    }
}
