//! What one sample gave (a row of `sweep.csv`), and the slice of the
//! samples a shard runs.

use std::fmt;
use std::str::FromStr;

use super::error::SweepError;
use super::verdict::SampleVerdict;
use crate::chatter::Outcome;

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
    /// s, last edge − first edge (`None` without an edge).
    pub lockout: Option<f64>,
    /// s, the longest time between two consecutive edges.
    pub stable_for: Option<f64>,
}

/// What one sample gave: a row of `sweep.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleRecord {
    /// The sample's index in the sweep, from 0.
    pub index: u64,
    /// The varied keys' values, in [`Sampler::keys`](super::sample::Sampler::keys) order.
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
    pub verdict: SampleVerdict,
    /// The keys of the limits that failed, in the scenario's order.
    pub failed_limits: Vec<String>,
    /// Why the sample failed: the error and its causes, one line.
    pub error: Option<String>,
}

/// The old name of [`SampleRecord`].
#[deprecated(note = "renamed to `SampleRecord`")]
pub type Record = SampleRecord;

impl SampleRecord {
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
