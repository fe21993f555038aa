//! What a sweep found, in a few numbers: the distribution of bounces,
//! bounce times and probe edges and peaks (min, median, p95, max, mean),
//! the worst sample and its values, and how many samples failed.
//!
//! [`Collected`] keeps a few numbers per sample as rows are written (not
//! the rows themselves), in index order; [`Collected::summary`] reduces
//! them. Quantiles are nearest-rank: the p-quantile of n sorted values is
//! the value at rank ⌈p·n⌉, so it is always one of the samples. The worst
//! sample is the one with the highest (could not run, failed a limit, did
//! not end closed, edges over all probes, bounce time), the lowest index
//! on a tie: a sample that errored outranks any that ran.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;

use crate::chatter::Outcome;
use crate::report::units::prefix;

use super::error::SweepError;
use super::record::SampleRecord;
use super::sample::Sampler;
use super::verdict::SampleVerdict;

/// How bad a sample is, compared field by field: (could not run, failed a
/// limit, did not end closed, edges, bounce time).
type Badness = (bool, bool, bool, u64, f64);

/// How many error messages the summary quotes.
const QUOTED_ERRORS: usize = 5;

/// Per-sample numbers for the summary and the plot, in index order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Collected {
    /// The varied keys, in [`Sampler::keys`] order.
    pub keys: Vec<String>,
    /// The probes' signals, in `[[probe]]` order; empty for a
    /// mechanics-only sweep.
    pub signals: Vec<String>,
    /// Each sample's index in the sweep.
    pub index: Vec<u64>,
    /// Each sample's chatter outcome; `None` when it failed before the
    /// mechanics ran.
    pub outcome: Vec<Option<Outcome>>,
    /// Each sample's openings after the first make.
    pub bounce_count: Vec<Option<u32>>,
    /// s
    pub bounce_time: Vec<Option<f64>>,
    /// s
    pub settle_time: Vec<Option<f64>>,
    /// s, a coil-driven relay's longest release time.
    pub release_time: Vec<Option<f64>>,
    /// J, with `[arc]`: all arcs of the sample.
    pub arc_energy: Vec<Option<f64>>,
    /// `[probe][sample]`
    pub edges: Vec<Vec<Option<u32>>>,
    /// `[probe][sample]`, max |value|.
    pub peak: Vec<Vec<Option<f64>>>,
    /// Each sample's verdict.
    pub verdict: Vec<SampleVerdict>,
    /// Samples that failed each limit, by limit key.
    pub failed_limits: BTreeMap<String, u64>,
    /// The first errors, with their sample index.
    pub first_errors: Vec<(u64, String)>,
}

impl Collected {
    /// Nothing yet, for a sweep of `keys` with probes `signals`.
    pub fn new(keys: Vec<String>, signals: Vec<String>) -> Collected {
        let n = signals.len();
        Collected {
            keys,
            signals,
            edges: vec![Vec::new(); n],
            peak: vec![Vec::new(); n],
            ..Collected::default()
        }
    }

    /// Add the next sample.
    pub fn add(&mut self, r: &SampleRecord) {
        self.index.push(r.index);
        self.outcome.push(r.outcome);
        self.bounce_count
            .push(r.bounce_count.map(|n| u32::try_from(n).unwrap_or(u32::MAX)));
        self.bounce_time.push(r.bounce_time);
        self.settle_time.push(r.settle_time);
        self.release_time.push(r.release_time);
        self.arc_energy.push(r.arc_energy);
        for (p, (edges, peak)) in self.edges.iter_mut().zip(&mut self.peak).enumerate() {
            let probe = r.probes.get(p);
            edges.push(probe.map(|x| u32::try_from(x.edges).unwrap_or(u32::MAX)));
            peak.push(probe.map(|x| x.peak));
        }
        self.verdict.push(r.verdict);
        for key in &r.failed_limits {
            *self.failed_limits.entry(key.clone()).or_insert(0) += 1;
        }
        if let Some(e) = &r.error {
            if self.first_errors.len() < QUOTED_ERRORS {
                self.first_errors.push((r.index, e.clone()));
            }
        }
    }

    /// Samples collected.
    pub fn len(&self) -> usize {
        self.index.len()
    }

    /// Whether none were.
    pub fn is_empty(&self) -> bool {
        self.index.is_empty()
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
        let mut outcomes = BTreeMap::new();
        for o in &self.outcome {
            *outcomes
                .entry(o.map_or("none", Outcome::as_str))
                .or_insert(0) += 1;
        }
        let mut verdicts = BTreeMap::new();
        for v in &self.verdict {
            *verdicts.entry(v.as_str()).or_insert(0) += 1;
        }
        let count = |v: SampleVerdict| self.verdict.iter().filter(|&&x| x == v).count() as u64;
        let (failing, errors) = (count(SampleVerdict::Fail), count(SampleVerdict::Error));
        let probes = self
            .signals
            .iter()
            .enumerate()
            .map(|(p, signal)| ProbeSummary {
                signal: signal.clone(),
                edges: Distribution::of(self.edges[p].iter().flatten().map(|&e| f64::from(e))),
                peak: Distribution::of(self.peak[p].iter().flatten().copied()),
            })
            .collect();
        let worst = match self.worst() {
            Some(i) => {
                let index = self.index[i];
                let values = values(index)?;
                Some(Worst {
                    index,
                    outcome: self.outcome[i].map(Outcome::as_str),
                    bounce_count: self.bounce_count[i],
                    bounce_time: self.bounce_time[i],
                    edges: self.edges.iter().map(|e| e[i]).collect(),
                    values: self.keys.iter().cloned().zip(values).collect(),
                    verdict: self.verdict[i].as_str(),
                })
            }
            None => None,
        };
        Ok(Summary {
            samples: n,
            kind: if grid { "grid" } else { "random" },
            seed,
            keys: self.keys.clone(),
            outcomes,
            verdicts,
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
            bounce_count: Distribution::of(
                self.bounce_count.iter().flatten().map(|&b| f64::from(b)),
            ),
            bounce_time: Distribution::of(self.bounce_time.iter().flatten().copied()),
            settle_time: Distribution::of(self.settle_time.iter().flatten().copied()),
            release_time: Distribution::of(self.release_time.iter().flatten().copied()),
            arc_energy: Distribution::of(self.arc_energy.iter().flatten().copied()),
            probes,
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

    /// The position of the worst sample (see the module overview).
    fn worst(&self) -> Option<usize> {
        let key = |i: usize| {
            let edges: u64 = self
                .edges
                .iter()
                .map(|e| u64::from(e[i].unwrap_or(0)))
                .sum();
            (
                self.verdict[i] == SampleVerdict::Error,
                self.verdict[i] == SampleVerdict::Fail,
                !self.outcome[i].is_some_and(Outcome::is_closed),
                edges,
                self.bounce_time[i].unwrap_or(0.0),
            )
        };
        let mut best: Option<(usize, Badness)> = None;
        for i in 0..self.len() {
            let k = key(i);
            let better = best.as_ref().is_none_or(|(_, b)| {
                (k.0, k.1, k.2, k.3)
                    .cmp(&(b.0, b.1, b.2, b.3))
                    .then(k.4.total_cmp(&b.4))
                    == std::cmp::Ordering::Greater
            });
            if better {
                best = Some((i, k));
            }
        }
        best.map(|(i, _)| i)
    }
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
        let rank = |p: f64| v[((p * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1];
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

    #[test]
    fn nearest_rank_quantiles() {
        let d = Distribution::of((1..=100).map(f64::from)).unwrap();
        assert_eq!((d.min, d.median, d.p95, d.max), (1.0, 50.0, 95.0, 100.0));
        assert_eq!(d.mean, 50.5);
        let one = Distribution::of([3.0].into_iter()).unwrap();
        assert_eq!((one.median, one.p95), (3.0, 3.0));
        assert!(Distribution::of(std::iter::empty()).is_none());
    }

    #[test]
    fn engineering_units() {
        assert_eq!(eng(1.234e-3, "s"), "1.23 ms");
        assert_eq!(eng(12.0, ""), "12");
        assert_eq!(eng(3.3, "V"), "3.30 V");
    }
}
