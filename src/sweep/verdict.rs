//! The verdict of one sample: did the design hold?
//!
//! [`verdict`] is the single place where a sample is judged. The limits
//! (`[limits]`, `chatterspice check`) are being written on another
//! branch; until they arrive every sample that ran passes, and a sample
//! that could not run is [`Verdict::Error`]. Plugging the check in means
//! changing only the body of [`verdict`]: it already receives the
//! scenario (whose limits apply), the chatter and, for a circuit sweep,
//! the whole run.

use crate::chatter::Chatter;
use crate::pipeline::RunResult;
use crate::scenario::Scenario;

/// The `verdict` column of `sweep.csv`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Verdict {
    Pass,
    /// A limit failed.
    Fail,
    /// The sample could not run to the end (see its `error`).
    Error,
}

impl Verdict {
    /// The name in the CSV and the JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Pass => "pass",
            Verdict::Fail => "fail",
            Verdict::Error => "error",
        }
    }

    /// The verdict named `text` (as written by [`Verdict::as_str`]).
    pub fn parse(text: &str) -> Option<Verdict> {
        match text {
            "pass" => Some(Verdict::Pass),
            "fail" => Some(Verdict::Fail),
            "error" => Some(Verdict::Error),
            _ => None,
        }
    }
}

/// The verdict of a sample that ran: `run` is `None` for a
/// mechanics-only sweep.
pub fn verdict(scenario: &Scenario, chatter: &Chatter, run: Option<&RunResult>) -> Verdict {
    // No limits yet (see the module overview): nothing can fail.
    let _ = (scenario, chatter, run);
    Verdict::Pass
}
