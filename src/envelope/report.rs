//! What an envelope gives: each quantity as a band over the kept relays,
//! the counts, and the worst relay.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::scenario::EnvelopeRange;
use crate::sweep::summary::Distribution;

/// A quantity over the kept relays.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Band {
    /// The smallest value.
    pub min: f64,
    /// The 50th percentile (nearest rank).
    pub median: f64,
    /// The 95th percentile (nearest rank).
    pub p95: f64,
    /// The largest value.
    pub max: f64,
}

impl Band {
    /// The band of `values` (non-finite values left out); `None` when
    /// none is left.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Option<Band> {
        Distribution::of(values.into_iter()).map(|d| Band {
            min: d.min,
            median: d.median,
            p95: d.p95,
            max: d.max,
        })
    }
}

/// The worst kept relay: the one with the least room left on a limit (or,
/// without limits, the most bounces).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct WorstRelay {
    /// Its index in the draw, from 0.
    pub index: usize,
    /// Its sampled values, by key.
    pub values: BTreeMap<String, f64>,
    /// The limit it is worst on, when there are limits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit: Option<String>,
}

/// A sampled relay that could not be simulated.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FailedRelay {
    /// Its index in the draw, from 0.
    pub index: usize,
    /// Its sampled values, by key.
    pub values: BTreeMap<String, f64>,
    /// Why: the engine's or the circuit run's own words.
    pub reason: String,
}

/// What an envelope gave.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EnvelopeReport {
    /// Relays drawn.
    pub samples: usize,
    /// Relays that met every printed figure and ran.
    pub kept: usize,
    /// Relays the datasheet excludes: they miss at least one printed
    /// figure.
    pub rejected_relays: usize,
    /// The rejections by the figure missed (`operate_time`, …): a relay
    /// that misses several figures counts under each, so these can add up
    /// to more than `rejected_relays`.
    pub rejected: BTreeMap<String, usize>,
    /// Relays that could not be simulated. They are not rejections (the
    /// datasheet does not exclude them): a check over an envelope with any
    /// fails ("relays not evaluated").
    pub failed: usize,
    /// Each relay that could not be simulated, with its values and why.
    pub failures: Vec<FailedRelay>,
    /// Where the ranges come from (`[envelope] source`).
    pub source: Option<String>,
    /// What was sampled: each key's range (a printed tolerance included).
    pub ranges: BTreeMap<String, EnvelopeRange>,
    /// Every quantity as a band over the kept relays: `bounce_count`,
    /// `operate_time`, `bounce_time`, `settle_time`, and per probe
    /// `<signal>.edges`, `.lockout`, `.stable_for`, `.peak`.
    pub quantities: BTreeMap<String, Band>,
    /// The worst kept relay.
    pub worst: Option<WorstRelay>,
    /// Each sampled key's unit in this scenario (a surface's stiffness in
    /// its law's unit), for the table.
    #[serde(skip)]
    pub units: BTreeMap<String, &'static str>,
}
