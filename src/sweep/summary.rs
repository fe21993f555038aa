//! What a sweep found, in a few numbers: the distribution of bounces,
//! bounce times and probe edges and peaks (min, median, p95, max, mean),
//! the worst sample and its values, and how many samples failed.
//!
//! [`Collected`] takes each sample as its row is written (not the rows
//! themselves): counts, sums and the worst sample as it goes, and a few
//! numbers per sample in a spill (`spill.rs`: bounded memory, a temporary file
//! beyond it) for the quantiles and the plot; [`Collected::summary`]
//! reduces them. Quantiles are nearest-rank: the p-quantile of n sorted
//! values is the value at rank ⌈p·n⌉, so it is always one of the samples.
//! The worst sample is the one with the highest (could not run, failed a
//! limit, did not end closed, edges over all probes, bounce time), the
//! lowest index on a tie: a sample that errored outranks any that ran.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use crate::chatter::Outcome;
use crate::report::units::prefix;

use super::error::SweepError;
use super::record::SampleRecord;
use super::sample::Sampler;
use super::spill::Spill;
use super::verdict::SampleVerdict;

/// How bad a sample is, compared field by field: (could not run, failed a
/// limit, did not end closed, edges, bounce time).
type Badness = (bool, bool, bool, u64, f64);

/// How many error messages the summary quotes.
const QUOTED_ERRORS: usize = 5;

/// The columns of a sample's row in the spill; a missing value is NaN.
pub(super) mod column {
    /// The sample's index in the sweep.
    pub const INDEX: usize = 0;
    /// Openings after the first make.
    pub const BOUNCES: usize = 1;
    /// s
    pub const BOUNCE_TIME: usize = 2;
    /// s
    pub const SETTLE_TIME: usize = 3;
    /// s
    pub const RELEASE_TIME: usize = 4;
    /// J
    pub const ARC_ENERGY: usize = 5;
    /// Probe `p`'s edges are at `EDGES + p`, its peak at `EDGES + probes + p`.
    pub const EDGES: usize = 6;
}

/// Running count, sum, min and max of a column's finite values.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Moments {
    count: u64,
    sum: f64,
    min: f64,
    max: f64,
}

impl Moments {
    const NONE: Moments = Moments {
        count: 0,
        sum: 0.0,
        min: f64::INFINITY,
        max: f64::NEG_INFINITY,
    };

    fn add(&mut self, x: f64) {
        if !x.is_finite() {
            return;
        }
        self.count += 1;
        self.sum += x;
        // total_cmp: -0 below +0, as a sort puts them.
        if x.total_cmp(&self.min).is_lt() {
            self.min = x;
        }
        if x.total_cmp(&self.max).is_gt() {
            self.max = x;
        }
    }
}

/// The worst sample so far, with what the summary quotes of it.
#[derive(Debug, Clone, PartialEq)]
struct WorstSoFar {
    badness: Badness,
    index: u64,
    outcome: Option<Outcome>,
    bounce_count: Option<u32>,
    bounce_time: Option<f64>,
    edges: Vec<Option<u32>>,
    verdict: SampleVerdict,
}

/// What a sweep's samples gave, for the summary and the plot, taken in
/// index order.
#[derive(Debug)]
pub struct Collected {
    /// The varied keys, in [`Sampler::keys`] order.
    pub keys: Vec<String>,
    /// The probes' signals, in `[[probe]]` order; empty for a
    /// mechanics-only sweep.
    pub signals: Vec<String>,
    /// Per sample, the [`column`]s.
    rows: Spill,
    moments: Vec<Moments>,
    outcomes: BTreeMap<&'static str, u64>,
    verdicts: BTreeMap<&'static str, u64>,
    /// Samples per number of edges, per probe.
    edge_counts: Vec<BTreeMap<u32, u64>>,
    worst: Option<WorstSoFar>,
    /// Samples that failed each limit, by limit key.
    failed_limits: BTreeMap<String, u64>,
    /// The first errors, with their sample index.
    first_errors: Vec<(u64, String)>,
}

impl Collected {
    /// Nothing yet, for a sweep of `keys` with probes `signals`.
    pub fn new(keys: Vec<String>, signals: Vec<String>) -> Collected {
        let width = column::EDGES + 2 * signals.len();
        Collected {
            rows: Spill::new(width),
            moments: vec![Moments::NONE; width],
            edge_counts: vec![BTreeMap::new(); signals.len()],
            keys,
            signals,
            outcomes: BTreeMap::new(),
            verdicts: BTreeMap::new(),
            worst: None,
            failed_limits: BTreeMap::new(),
            first_errors: Vec::new(),
        }
    }

    /// Add the next sample; an error when its numbers cannot be kept (the
    /// temporary file cannot be written).
    pub fn add(&mut self, r: &SampleRecord) -> Result<(), SweepError> {
        let probes = self.signals.len();
        let count = |n: usize| u32::try_from(n).unwrap_or(u32::MAX);
        let edges: Vec<Option<u32>> = (0..probes)
            .map(|p| r.probes.get(p).map(|x| count(x.edges)))
            .collect();
        let bounce_count = r.bounce_count.map(count);
        let mut row = vec![f64::NAN; self.rows.width()];
        row[column::INDEX] = r.index as f64;
        row[column::BOUNCES] = bounce_count.map_or(f64::NAN, f64::from);
        row[column::BOUNCE_TIME] = r.bounce_time.unwrap_or(f64::NAN);
        row[column::SETTLE_TIME] = r.settle_time.unwrap_or(f64::NAN);
        row[column::RELEASE_TIME] = r.release_time.unwrap_or(f64::NAN);
        row[column::ARC_ENERGY] = r.arc_energy.unwrap_or(f64::NAN);
        for p in 0..probes {
            row[column::EDGES + p] = edges[p].map_or(f64::NAN, f64::from);
            row[column::EDGES + probes + p] = r.probes.get(p).map_or(f64::NAN, |x| x.peak);
            if let Some(e) = edges[p] {
                *self.edge_counts[p].entry(e).or_insert(0) += 1;
            }
        }
        for (m, &x) in self.moments.iter_mut().zip(&row).skip(column::BOUNCES) {
            m.add(x);
        }
        self.rows.push(&row).map_err(SweepError::Scratch)?;
        *self
            .outcomes
            .entry(r.outcome.map_or("none", Outcome::as_str))
            .or_insert(0) += 1;
        *self.verdicts.entry(r.verdict.as_str()).or_insert(0) += 1;
        let badness = (
            r.verdict == SampleVerdict::Error,
            r.verdict == SampleVerdict::Fail,
            !r.outcome.is_some_and(Outcome::is_closed),
            edges.iter().map(|e| u64::from(e.unwrap_or(0))).sum(),
            r.bounce_time.unwrap_or(0.0),
        );
        let worse = self.worst.as_ref().is_none_or(|w| {
            let b = &w.badness;
            (badness.0, badness.1, badness.2, badness.3)
                .cmp(&(b.0, b.1, b.2, b.3))
                .then(badness.4.total_cmp(&b.4))
                .is_gt()
        });
        if worse {
            self.worst = Some(WorstSoFar {
                badness,
                index: r.index,
                outcome: r.outcome,
                bounce_count,
                bounce_time: r.bounce_time,
                edges,
                verdict: r.verdict,
            });
        }
        for key in &r.failed_limits {
            *self.failed_limits.entry(key.clone()).or_insert(0) += 1;
        }
        if let Some(e) = &r.error {
            if self.first_errors.len() < QUOTED_ERRORS {
                self.first_errors.push((r.index, e.clone()));
            }
        }
        Ok(())
    }

    /// Samples collected.
    pub fn len(&self) -> usize {
        self.rows.len() as usize
    }

    /// Whether none were.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Call `f` with each sample's [`column`]s, in index order.
    pub(super) fn for_each_row(&self, f: impl FnMut(&[f64])) -> Result<(), SweepError> {
        self.rows.for_each(f).map_err(SweepError::Scratch)
    }

    /// How many samples have a finite value in `column`.
    pub(super) fn count(&self, column: usize) -> u64 {
        self.moments[column].count
    }

    /// The smallest and largest finite value in `column`, if any.
    pub(super) fn range(&self, column: usize) -> Option<(f64, f64)> {
        let m = &self.moments[column];
        (m.count > 0).then_some((m.min, m.max))
    }

    /// The worst sample's index (see the module overview), if any.
    pub fn worst_index(&self) -> Option<u64> {
        self.worst.as_ref().map(|w| w.index)
    }

    /// Samples per number of edges of probe `p`.
    pub(super) fn edge_counts(&self, p: usize) -> &BTreeMap<u32, u64> {
        &self.edge_counts[p]
    }

    /// The summary; `sampler` gives the worst sample's values.
    pub fn summary(&self, sampler: &Sampler) -> Result<Summary, SweepError> {
        self.summary_with(sampler.is_grid(), sampler.seed(), |index| {
            sampler.values_vec(index)
        })
    }

    /// The summary of a grid (`grid`) or a random sweep of `seed`, with the
    /// worst sample's values from `values(index)`.
    pub fn summary_with(
        &self,
        grid: bool,
        seed: Option<u64>,
        values: impl Fn(u64) -> Result<Vec<f64>, SweepError>,
    ) -> Result<Summary, SweepError> {
        let n = self.len() as u64;
        let distributions = self.distributions()?;
        let count = |v: SampleVerdict| self.verdicts.get(v.as_str()).copied().unwrap_or(0);
        let (failing, errors) = (count(SampleVerdict::Fail), count(SampleVerdict::Error));
        let probes = self.signals.len();
        let worst = match &self.worst {
            Some(w) => Some(Worst {
                index: w.index,
                outcome: w.outcome.map(Outcome::as_str),
                bounce_count: w.bounce_count,
                bounce_time: w.bounce_time,
                edges: w.edges.clone(),
                values: self.keys.iter().cloned().zip(values(w.index)?).collect(),
                verdict: w.verdict.as_str(),
            }),
            None => None,
        };
        Ok(Summary {
            samples: n,
            kind: if grid { "grid" } else { "random" },
            seed,
            keys: self.keys.clone(),
            outcomes: self.outcomes.clone(),
            verdicts: self.verdicts.clone(),
            failing,
            errors,
            limits: self
                .failed_limits
                .iter()
                .map(|(key, &failing)| {
                    let fraction = failing as f64 / n.max(1) as f64;
                    (key.clone(), LimitFailures { failing, fraction })
                })
                .collect(),
            fraction_failing: if n == 0 {
                0.0
            } else {
                (failing + errors) as f64 / n as f64
            },
            bounce_count: distributions[column::BOUNCES],
            bounce_time: distributions[column::BOUNCE_TIME],
            settle_time: distributions[column::SETTLE_TIME],
            release_time: distributions[column::RELEASE_TIME],
            arc_energy: distributions[column::ARC_ENERGY],
            probes: self
                .signals
                .iter()
                .enumerate()
                .map(|(p, signal)| ProbeSummary {
                    signal: signal.clone(),
                    edges: distributions[column::EDGES + p],
                    peak: distributions[column::EDGES + probes + p],
                })
                .collect(),
            worst,
            first_errors: self
                .first_errors
                .iter()
                .map(|(index, error)| SampleError {
                    index: *index,
                    error: error.clone(),
                })
                .collect(),
            identity: None,
        })
    }

    /// Each column's distribution (`None` for the index and for a column
    /// without values).
    fn distributions(&self) -> Result<Vec<Option<Distribution>>, SweepError> {
        let counts: Vec<u64> = self.moments.iter().map(|m| m.count).collect();
        let mut wanted = Vec::new();
        for (c, &count) in counts.iter().enumerate().skip(column::BOUNCES) {
            if count > 0 {
                wanted.push((c, nearest_rank(0.5, count)));
                wanted.push((c, nearest_rank(0.95, count)));
            }
        }
        let found = self
            .rows
            .quantiles(&counts, &wanted)
            .map_err(SweepError::Scratch)?;
        let mut out = vec![None; counts.len()];
        for (pair, ranks) in found.chunks_exact(2).zip(wanted.chunks_exact(2)) {
            let c = ranks[0].0;
            let m = &self.moments[c];
            if let [Some(median), Some(p95)] = *pair {
                out[c] = Some(Distribution {
                    count: m.count,
                    min: m.min,
                    median,
                    p95,
                    max: m.max,
                    mean: m.sum / m.count as f64,
                });
            }
        }
        Ok(out)
    }
}

/// The 1-based nearest rank of the p-quantile of `n` values, ⌈p·n⌉.
fn nearest_rank(p: f64, n: u64) -> u64 {
    ((p * n as f64).ceil() as u64).clamp(1, n)
}

/// min, median, p95, max and mean of some samples' values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Distribution {
    /// How many samples had a value.
    pub count: u64,
    /// The smallest value, in the quantity's unit.
    pub min: f64,
    /// The 50th percentile (nearest-rank).
    pub median: f64,
    /// The 95th percentile (nearest-rank).
    pub p95: f64,
    /// The largest value.
    pub max: f64,
    /// The arithmetic mean.
    pub mean: f64,
}

impl Distribution {
    /// `None` without values.
    pub fn of(values: impl Iterator<Item = f64>) -> Option<Distribution> {
        let mut v: Vec<f64> = values.filter(|x| x.is_finite()).collect();
        if v.is_empty() {
            return None;
        }
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        v.sort_by(f64::total_cmp);
        let rank = |p: f64| v[(nearest_rank(p, v.len() as u64) - 1) as usize];
        Some(Distribution {
            count: v.len() as u64,
            min: v[0],
            median: rank(0.5),
            p95: rank(0.95),
            max: v[v.len() - 1],
            mean,
        })
    }
}

/// One probe's distributions.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbeSummary {
    /// The probe's ngspice vector, e.g. `v(in)`.
    pub signal: String,
    /// Schmitt edges per sample; `None` when no sample reached ngspice's
    /// results.
    pub edges: Option<Distribution>,
    /// max |value| per sample, in the signal's unit (V or A).
    pub peak: Option<Distribution>,
}

/// The worst sample.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Worst {
    /// Its index in the sweep.
    pub index: u64,
    /// Its chatter outcome, as in `sweep.csv`; `None` when it failed
    /// before the mechanics ran.
    pub outcome: Option<&'static str>,
    /// Its openings after the first make.
    pub bounce_count: Option<u32>,
    /// s, its first make → closed for good.
    pub bounce_time: Option<f64>,
    /// Per probe.
    pub edges: Vec<Option<u32>>,
    /// `pass`, `fail` or `error`.
    pub verdict: &'static str,
    /// Its values of the varied keys.
    pub values: BTreeMap<String, f64>,
}

/// The samples that failed one limit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LimitFailures {
    /// Samples that failed it.
    pub failing: u64,
    /// failing / samples.
    pub fraction: f64,
}

/// A sample that failed, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SampleError {
    /// The sample's index in the sweep.
    pub index: u64,
    /// The error and its causes, on one line.
    pub error: String,
}

/// `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Samples summarized (a shard's own, for a shard).
    pub samples: u64,
    /// `random` or `grid`.
    pub kind: &'static str,
    /// The random sweep's seed; `None` for a grid.
    pub seed: Option<u64>,
    /// The varied keys, sorted.
    pub keys: Vec<String>,
    /// Samples per chatter outcome (`none`: failed before the mechanics).
    pub outcomes: BTreeMap<&'static str, u64>,
    /// Samples per verdict.
    pub verdicts: BTreeMap<&'static str, u64>,
    /// Samples that failed a limit.
    pub failing: u64,
    /// Samples that could not run.
    pub errors: u64,
    /// Per limit key that some sample failed: how many, and the fraction
    /// of all samples.
    pub limits: BTreeMap<String, LimitFailures>,
    /// (failing + errors) / samples.
    pub fraction_failing: f64,
    /// Openings after the first make.
    pub bounce_count: Option<Distribution>,
    /// s
    pub bounce_time: Option<Distribution>,
    /// s
    pub settle_time: Option<Distribution>,
    /// s, coil off → the NO contact opens (a coil-driven relay only).
    pub release_time: Option<Distribution>,
    /// J, all arcs of a sample (with `[arc]` only).
    pub arc_energy: Option<Distribution>,
    /// One per `[[probe]]`, in file order; empty for a mechanics-only
    /// sweep.
    pub probes: Vec<ProbeSummary>,
    /// The worst sample (see the module overview); `None` without samples.
    pub worst: Option<Worst>,
    /// The first few errors.
    pub first_errors: Vec<SampleError>,
    /// A merged summary only: `verified` when every shard's identity file
    /// was checked, `unverified` when shards without one were accepted
    /// (`merge --unverified`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub identity: Option<&'static str>,
}

impl Summary {
    /// Pretty JSON, `\n`-terminated.
    pub fn to_json(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("a summary serializes");
        text.push('\n');
        text
    }

    /// A few lines for a person at a terminal.
    pub fn render_table(&self) -> String {
        let mut out = String::new();
        let what = match self.seed {
            Some(seed) => format!("random, seed {seed}"),
            None => "grid".to_owned(),
        };
        let _ = writeln!(
            out,
            "{} samples ({what}) of {}",
            self.samples,
            self.keys.join(", ")
        );
        let counts = |m: &BTreeMap<&str, u64>| {
            m.iter()
                .map(|(k, v)| format!("{k} {v}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(out, "outcomes: {}", counts(&self.outcomes));
        let _ = writeln!(
            out,
            "failing a limit: {}, errors: {} ({:.1} % failing)",
            self.failing,
            self.errors,
            100.0 * self.fraction_failing
        );
        for (key, f) in &self.limits {
            let _ = writeln!(
                out,
                "  {key}: {} sample{} failed it ({:.1} %)",
                f.failing,
                if f.failing == 1 { "" } else { "s" },
                100.0 * f.fraction
            );
        }
        let mut rows: Vec<(String, &Option<Distribution>, &str)> = vec![
            ("bounces".to_owned(), &self.bounce_count, ""),
            ("bounce time".to_owned(), &self.bounce_time, "s"),
            ("settle time".to_owned(), &self.settle_time, "s"),
            ("release time".to_owned(), &self.release_time, "s"),
            ("arc energy".to_owned(), &self.arc_energy, "J"),
        ];
        for p in &self.probes {
            rows.push((format!("{} edges", p.signal), &p.edges, ""));
            // A probe reads a voltage `v(...)` or a current `i(...)`.
            let unit = if p.signal.to_ascii_lowercase().starts_with("i(") {
                "A"
            } else {
                "V"
            };
            rows.push((format!("{} peak", p.signal), &p.peak, unit));
        }
        rows.retain(|(_, d, _)| d.is_some());
        // The name column fits the longest probe name.
        let width = rows
            .iter()
            .map(|(n, ..)| n.chars().count() + 2)
            .fold(16, usize::max);
        let _ = writeln!(
            out,
            "\n{:<width$}{:>12}{:>12}{:>12}{:>12}",
            "", "min", "median", "p95", "max"
        );
        for (name, d, unit) in &rows {
            if let Some(d) = d {
                let _ = writeln!(
                    out,
                    "{name:<width$}{:>12}{:>12}{:>12}{:>12}",
                    eng(d.min, unit),
                    eng(d.median, unit),
                    eng(d.p95, unit),
                    eng(d.max, unit)
                );
            }
        }
        if let Some(w) = &self.worst {
            let values = w
                .values
                .iter()
                .map(|(k, v)| format!("{k} = {v:?}"))
                .collect::<Vec<_>>()
                .join(", ");
            let mut what = vec![w.outcome.unwrap_or("none").to_owned()];
            if let Some(t) = w.bounce_time {
                what.push(format!("bounce time {}", eng(t, "s")));
            }
            if let Some(b) = w.bounce_count {
                what.push(format!("{b} bounces"));
            }
            for (p, e) in self.probes.iter().zip(&w.edges) {
                if let Some(e) = e {
                    what.push(format!("{} {e} edges", p.signal));
                }
            }
            let _ = writeln!(
                out,
                "\nworst: sample {} ({}): {values}",
                w.index,
                what.join(", ")
            );
        }
        for e in &self.first_errors {
            let _ = writeln!(out, "error in sample {}: {}", e.index, e.error);
        }
        out
    }
}

/// `value` with three significant digits (trailing zeros kept, so that
/// table columns line up) and an SI prefix; integers (counts, no unit) as
/// they are.
fn eng(value: f64, unit: &str) -> String {
    if unit.is_empty() {
        return if value.fract() == 0.0 && value.abs() < 1e15 {
            format!("{value}")
        } else {
            format!("{value:.3}")
        };
    }
    if value == 0.0 || !value.is_finite() {
        return format!("0 {unit}");
    }
    let exponent = (3.0 * (value.abs().log10() / 3.0).floor()).clamp(-12.0, 9.0) as i32;
    let prefix = prefix(exponent);
    let scaled = value / 10f64.powi(exponent);
    let decimals = if scaled.abs() >= 100.0 {
        0
    } else if scaled.abs() >= 10.0 {
        1
    } else {
        2
    };
    format!("{scaled:.decimals$} {prefix}{unit}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sweep::ProbeRecord;

    #[test]
    fn nearest_rank_quantiles() {
        let d = Distribution::of((1..=100).map(f64::from)).unwrap();
        assert_eq!((d.min, d.median, d.p95, d.max), (1.0, 50.0, 95.0, 100.0));
        assert_eq!(d.mean, 50.5);
        let one = Distribution::of([3.0].into_iter()).unwrap();
        assert_eq!((one.median, one.p95), (3.0, 3.0));
        assert!(Distribution::of(std::iter::empty()).is_none());
    }

    /// A sample with numbers from `i`, some missing, some failing.
    fn record(i: u64) -> SampleRecord {
        let u = ((i.wrapping_mul(0x9e37_79b9_7f4a_7c15) >> 11) as f64) / (1u64 << 53) as f64;
        let closed = i % 17 != 3;
        SampleRecord {
            index: i,
            values: vec![u],
            outcome: Some(if closed {
                Outcome::Stuck
            } else {
                Outcome::EndOfTime
            }),
            bounce_count: Some((i % 9) as usize),
            first_impact: Some(1e-3),
            settle_time: closed.then_some(1e-3 + u * 1e-3),
            bounce_time: closed.then_some(u * 1e-3),
            release_time: None,
            nc_bounce_time: None,
            arc_count: None,
            arc_energy: (i % 5 == 0).then_some(-u),
            breakdowns: None,
            probes: vec![ProbeRecord {
                edges: (i % 13) as usize,
                peak: 3.0 + u,
                ideal_edges: None,
                lockout: None,
                stable_for: None,
            }],
            verdict: if i % 11 == 0 {
                SampleVerdict::Fail
            } else {
                SampleVerdict::Pass
            },
            failed_limits: if i % 11 == 0 {
                vec!["max_bounces".to_owned()]
            } else {
                Vec::new()
            },
            error: None,
        }
    }

    #[test]
    fn a_summary_beyond_memory_is_the_summary_of_every_value() {
        // More samples than stay in memory: the quantiles come from the
        // temporary file, and must be those of sorting every value.
        let n = 3 * super::super::spill::RESIDENT_ROWS as u64 + 7;
        let mut c = Collected::new(vec!["k".to_owned()], vec!["v(out)".to_owned()]);
        let records: Vec<SampleRecord> = (0..n).map(record).collect();
        for r in &records {
            c.add(r).unwrap();
        }
        let s = c
            .summary_with(false, Some(1), |i| Ok(records[i as usize].values.clone()))
            .unwrap();
        let of = |f: &dyn Fn(&SampleRecord) -> Option<f64>| {
            Distribution::of(records.iter().filter_map(f))
        };
        assert_eq!(s.samples, n);
        assert_eq!(s.bounce_time, of(&|r| r.bounce_time));
        assert_eq!(s.settle_time, of(&|r| r.settle_time));
        assert_eq!(s.arc_energy, of(&|r| r.arc_energy));
        assert_eq!(s.bounce_count, of(&|r| r.bounce_count.map(|b| b as f64)));
        assert_eq!(s.release_time, None);
        assert_eq!(s.probes[0].edges, of(&|r| Some(r.probes[0].edges as f64)));
        assert_eq!(s.probes[0].peak, of(&|r| Some(r.probes[0].peak)));
        // The worst: failing first, then not closed, then edges, then
        // bounce time; the lowest index on a tie.
        let worst = (0..n as usize)
            .max_by(|&a, &b| {
                let key = |r: &SampleRecord| {
                    (
                        r.verdict == SampleVerdict::Fail,
                        !r.closed(),
                        r.probes[0].edges,
                    )
                };
                key(&records[a])
                    .cmp(&key(&records[b]))
                    .then(
                        records[a]
                            .bounce_time
                            .unwrap_or(0.0)
                            .total_cmp(&records[b].bounce_time.unwrap_or(0.0)),
                    )
                    .then(b.cmp(&a))
            })
            .unwrap();
        assert_eq!(s.worst.as_ref().map(|w| w.index), Some(worst as u64));
        assert_eq!(
            s.failing,
            records
                .iter()
                .filter(|r| r.verdict == SampleVerdict::Fail)
                .count() as u64
        );
        assert_eq!(s.limits["max_bounces"].failing, s.failing);
        assert_eq!(
            s.outcomes["end_of_time"],
            records.iter().filter(|r| !r.closed()).count() as u64
        );
    }

    #[test]
    fn engineering_units() {
        assert_eq!(eng(1.234e-3, "s"), "1.23 ms");
        assert_eq!(eng(12.0, ""), "12");
        assert_eq!(eng(3.3, "V"), "3.30 V");
    }
}
