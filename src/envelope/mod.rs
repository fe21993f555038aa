//! Envelopes: a scenario over every relay its datasheet allows.
//!
//! A datasheet fixes a few figures, mostly as maxima with tolerances; it
//! does not fix the contact surface, the blade or the overtravel. The
//! scenario's `[envelope]` gives the ranges of the keys it does not fix,
//! and a printed tolerance (`datasheet.coil_resistance = { typ = 63,
//! tolerance = 0.1 }`) adds its key's range. The envelope is sampled
//! quasi-randomly (a Halton sequence, shifted by the seed: even,
//! reproducible); each sampled relay is screened against the datasheet's
//! printed bounds on the ideal DC step (no ngspice), the relays that meet
//! them all are run (each through the same resolved plan, its netlist read
//! once), and every quantity becomes a band over the kept relays. A check
//! holds each limit against the worst kept relay.

mod gather;
mod render;
mod report;

pub use render::{band_table, json_with_envelope};
pub use report::{Band, EnvelopeReport, FailedRelay, WorstRelay};

use std::collections::BTreeMap;
use std::num::NonZeroUsize;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::{Rng, SeedableRng};
use thiserror::Error;

use crate::calibrate::fit::{datasheet_figures, datasheet_figures_or_failure};
use crate::chatter::Chatter;
use crate::check::{self, Evidence, LimitCheck, Verdict};
use crate::coil::timing::Closing;
use crate::pipeline::{self, RunOptions, RunResult};
use crate::plan::Plan;
use crate::scenario::{DatasheetSection, EnvelopeRange, Scenario, ScenarioError};
use crate::spice::Runner;
use crate::sweep::run::one_line;
use gather::Gather;

/// How to sample an envelope.
#[derive(Debug, Clone)]
pub struct EnvelopeOptions {
    /// Relays drawn (before the datasheet screens them).
    pub samples: usize,
    /// Shifts the quasi-random sequence: the same seed draws the same
    /// relays.
    pub seed: u64,
    /// Relays run at once.
    pub jobs: NonZeroUsize,
    /// How each kept relay's circuit runs (the ideal-contact comparison is
    /// never run for an envelope).
    pub run: RunOptions,
}

impl Default for EnvelopeOptions {
    fn default() -> Self {
        EnvelopeOptions {
            samples: 32,
            seed: 1,
            jobs: NonZeroUsize::MIN,
            run: RunOptions::default(),
        }
    }
}

/// Why an envelope cannot be run.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum EnvelopeError {
    /// The scenario has no `[envelope]` and no printed tolerance to sample.
    #[error(
        "{}: no [envelope] to sample: add one with the ranges of the keys the datasheet does \
         not fix, e.g. \"surface.damping\" = {{ min = 1.0, max = 4.0 }}",
        path.display()
    )]
    NoEnvelope {
        /// The scenario file.
        path: std::path::PathBuf,
    },
    /// `--samples 0`.
    #[error("--samples must be at least 1")]
    NoSamples,
    /// The scenario cannot be resolved.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// Every sampled relay was rejected or failed, so there is no band.
    #[error(
        "{}: none of the {samples} sampled relays was kept ({reasons}); widen the [envelope] \
         or check the datasheet figures",
        path.display()
    )]
    NoneKept {
        /// The scenario file.
        path: std::path::PathBuf,
        /// Relays drawn.
        samples: usize,
        /// Why they were rejected, as `figure: count` pairs.
        reasons: String,
    },
}

/// One kept relay's outcome.
#[derive(Debug, Clone)]
pub struct Kept {
    /// Its index in the draw.
    pub index: usize,
    /// Its sampled values, in [`Draw::keys`] order.
    pub values: Vec<f64>,
    /// Its quantities, by name.
    pub quantities: BTreeMap<String, f64>,
    /// Its verdict on the scenario's limits (empty without limits).
    pub verdict: Verdict,
    /// What the verdict was reached on.
    pub evidence: Evidence,
}

/// The sampled relays: the keys and their ranges, and each relay's values.
#[derive(Debug, Clone)]
pub struct Draw {
    /// The sampled keys.
    pub keys: Vec<String>,
    /// Their ranges, in `keys` order.
    pub ranges: Vec<EnvelopeRange>,
    /// One row of values per relay.
    pub relays: Vec<Vec<f64>>,
}

/// The first primes: the Halton bases of the first dimensions.
const PRIMES: [u64; 24] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89,
];

/// The radical inverse of `i` in base `b`.
fn radical_inverse(mut i: u64, b: u64) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

/// The keys to sample: the `[envelope]`'s, and the coil resistance within
/// its printed tolerance when the envelope does not give it.
pub fn ranges_of(scenario: &Scenario) -> BTreeMap<String, EnvelopeRange> {
    let mut ranges = scenario
        .envelope
        .as_ref()
        .map(|e| e.ranges.clone())
        .unwrap_or_default();
    let tolerance = scenario
        .datasheet
        .as_ref()
        .and_then(|d| d.coil_resistance)
        .filter(|_| scenario.coil.is_some());
    if let Some(figure) = tolerance {
        let (lo, hi) = figure.band();
        if lo.is_finite() && hi.is_finite() && lo < hi {
            ranges
                .entry("coil.resistance".to_owned())
                .or_insert(EnvelopeRange {
                    min: lo,
                    max: hi,
                    log: false,
                });
        }
    }
    ranges
}

/// Draw `options.samples` relays of `scenario`'s envelope.
pub fn draw(scenario: &Scenario, options: &EnvelopeOptions) -> Result<Draw, EnvelopeError> {
    if options.samples == 0 {
        return Err(EnvelopeError::NoSamples);
    }
    let ranges = ranges_of(scenario);
    if ranges.is_empty() {
        return Err(EnvelopeError::NoEnvelope {
            path: scenario.origin.clone(),
        });
    }
    let (keys, ranges): (Vec<String>, Vec<EnvelopeRange>) = ranges.into_iter().unzip();
    // One shift per dimension (Cranley–Patterson rotation): the seed moves
    // the whole sequence, which stays as even as Halton's.
    let mut rng = ChaCha8Rng::seed_from_u64(options.seed);
    let shift: Vec<f64> = (0..keys.len())
        .map(|_| (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
        .collect();
    let relays = (0..options.samples)
        .map(|i| {
            ranges
                .iter()
                .enumerate()
                .map(|(d, r)| {
                    let base = PRIMES[d % PRIMES.len()];
                    let u = (radical_inverse(i as u64 + 1, base) + shift[d]).fract();
                    r.at(u)
                })
                .collect()
        })
        .collect();
    Ok(Draw {
        keys,
        ranges,
        relays,
    })
}

/// Everything an envelope run gives: the report and each kept relay.
#[derive(Debug)]
pub struct Envelope {
    /// The bands, the counts and the worst relay.
    pub report: EnvelopeReport,
    /// The kept relays, in draw order.
    pub kept: Vec<Kept>,
    /// For a check: each limit held against its worst kept relay.
    pub verdict: Verdict,
}

impl Envelope {
    /// The kept relay the report calls worst.
    pub fn worst(&self) -> Option<&Kept> {
        let index = self.report.worst.as_ref()?.index;
        self.kept.iter().find(|k| k.index == index)
    }
}

/// Run `scenario` over its envelope: draw, screen against the datasheet,
/// run each kept relay (through `runner` when the scenario has a circuit
/// and probes or limits that need it; the relay alone otherwise), and
/// band the results.
pub fn run(
    scenario: &Scenario,
    runner: Option<&dyn Runner>,
    options: &EnvelopeOptions,
) -> Result<Envelope, EnvelopeError> {
    let draw = draw(scenario, options)?;
    let circuit = runner.filter(|_| scenario.circuit.is_some() && !scenario.probes.is_empty());
    // Resolved once, the netlist read once: each relay renumbers a copy.
    let base = match circuit {
        Some(_) => Plan::new(scenario.clone())?,
        None => Plan::without_circuit(scenario.clone())?,
    };
    let run_options = RunOptions {
        compare_ideal: false,
        ideal_alongside: false,
        ..options.run.clone()
    };
    let outcomes: Mutex<Vec<Outcome>> = Mutex::new(Vec::new());
    let next = AtomicUsize::new(0);
    // With a circuit, the relays run on threads of their own whose circuit
    // passes are gathered into rounds, one ngspice process per job and
    // round; without, the relays alone on one thread per job.
    let threads = match circuit {
        Some(_) => (options.jobs.get() * RELAYS_PER_PROCESS).min(draw.relays.len()),
        None => options.jobs.get().min(draw.relays.len()),
    };
    let gather = circuit.map(|runner| Gather::new(runner, options.jobs.get(), threads));
    let runner: Option<&dyn Runner> = gather.as_ref().map(|g| g as &dyn Runner);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            scope.spawn(|| {
                // Leaves the gatherer however the thread ends (a panic
                // too), so that no round waits for it.
                let _leave = gather.as_ref().map(Gather::member);
                let mut plan = base.clone();
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(values) = draw.relays.get(i) else {
                        break;
                    };
                    let outcome = relay(&mut plan, &draw.keys, values, i, runner, &run_options);
                    outcomes
                        .lock()
                        .unwrap_or_else(|e| e.into_inner())
                        .push((i, outcome));
                }
            });
        }
    });
    let mut outcomes = outcomes.into_inner().unwrap_or_else(|e| e.into_inner());
    outcomes.sort_by_key(|(i, _)| *i);
    let mut rejected: BTreeMap<String, usize> = BTreeMap::new();
    let mut failures = Vec::new();
    let mut kept = Vec::new();
    for (index, outcome) in outcomes {
        match outcome {
            Ok(k) => kept.push(k),
            Err(NotKept::Rejected(figures)) => {
                for r in figures {
                    *rejected.entry(r.to_owned()).or_default() += 1;
                }
            }
            Err(NotKept::Failed(reason)) => failures.push(FailedRelay {
                index,
                values: draw
                    .keys
                    .iter()
                    .cloned()
                    .zip(draw.relays[index].iter().copied())
                    .collect(),
                reason,
            }),
        }
    }
    let rejected_relays = draw.relays.len() - kept.len() - failures.len();
    if kept.is_empty() {
        let mut reasons: Vec<String> = rejected.iter().map(|(k, n)| format!("{k}: {n}")).collect();
        if let Some(f) = failures.first() {
            reasons.push(format!(
                "{} not evaluated, the first because {}",
                failures.len(),
                f.reason
            ));
        }
        return Err(EnvelopeError::NoneKept {
            path: scenario.origin.clone(),
            samples: draw.relays.len(),
            reasons: reasons.join(", "),
        });
    }
    let (mut verdict, worst) = worst_case(&kept);
    if !failures.is_empty() {
        verdict = not_evaluated(verdict, &failures);
    }
    let mut names: Vec<&String> = kept.iter().flat_map(|k| k.quantities.keys()).collect();
    names.sort();
    names.dedup();
    let quantities = names
        .into_iter()
        .filter_map(|name| {
            Band::of(kept.iter().filter_map(|k| k.quantities.get(name).copied()))
                .map(|b| (name.clone(), b))
        })
        .collect();
    let worst = worst.map(|(i, limit)| WorstRelay {
        index: kept[i].index,
        values: draw
            .keys
            .iter()
            .cloned()
            .zip(kept[i].values.iter().copied())
            .collect(),
        limit,
    });
    let units = draw
        .keys
        .iter()
        .map(|k| (k.clone(), scenario.unit_of_key(k)))
        .collect();
    let report = EnvelopeReport {
        units,
        samples: draw.relays.len(),
        kept: kept.len(),
        rejected_relays,
        rejected,
        failed: failures.len(),
        failures,
        source: scenario.envelope.as_ref().and_then(|e| e.source.clone()),
        ranges: draw.keys.iter().cloned().zip(draw.ranges).collect(),
        quantities,
        worst,
    };
    Ok(Envelope {
        report,
        kept,
        verdict,
    })
}

/// Relays whose circuit runs one ngspice process takes in turn (per job):
/// its start-up is paid once for them.
const RELAYS_PER_PROCESS: usize = 16;

/// A relay's place in the draw, and what became of it.
type Outcome = (usize, Result<Kept, NotKept>);

/// Why a sampled relay is not among the kept ones.
#[derive(Debug)]
enum NotKept {
    /// It misses these printed figures: a relay the datasheet excludes.
    Rejected(Vec<&'static str>),
    /// It could not be simulated: never a relay the datasheet excludes,
    /// so a check over the envelope cannot pass with it.
    Failed(String),
}

/// The verdict of `kept`'s worst relays, with one more check that fails:
/// the relays not evaluated, the first reasons in its note.
fn not_evaluated(verdict: Verdict, failures: &[FailedRelay]) -> Verdict {
    let mut checks = verdict.checks;
    let reasons: Vec<String> = failures
        .iter()
        .take(3)
        .map(|f| format!("relay {}: {}", f.index, f.reason))
        .collect();
    checks.push(LimitCheck::count_at_most(
        "envelope".to_owned(),
        "relays not evaluated".to_owned(),
        0,
        failures.len(),
        format!(
            "{} relay{} of the envelope could not be simulated; {}",
            failures.len(),
            if failures.len() == 1 { "" } else { "s" },
            reasons.join("; ")
        ),
    ));
    Verdict::new(checks)
}

/// One sampled relay: set its values, screen it against the datasheet,
/// run it. `Err` carries the reasons it was not kept.
fn relay(
    plan: &mut Plan,
    keys: &[String],
    values: &[f64],
    index: usize,
    runner: Option<&dyn Runner>,
    options: &RunOptions,
) -> Result<Kept, NotKept> {
    let pairs: Vec<(&str, f64)> = keys
        .iter()
        .map(String::as_str)
        .zip(values.iter().copied())
        .collect();
    if let Err(e) = plan.renumber(&pairs) {
        return Err(NotKept::Failed(format!(
            "the model refuses its values: {e}"
        )));
    }
    let scenario = plan.scenario();
    let missed = screen_or_failure(scenario).map_err(NotKept::Failed)?;
    if !missed.is_empty() {
        return Err(NotKept::Rejected(missed));
    }
    let (verdict, evidence) = match runner {
        Some(runner) => match pipeline::run_plan(plan, runner, options) {
            Ok(result) => (
                check::evaluate(scenario, &result),
                Evidence::Run(Box::new(result)),
            ),
            Err(e) => return Err(NotKept::Failed(one_line(&e))),
        },
        None => match check::relay_only(scenario) {
            Ok(found) => found,
            Err(e) => return Err(NotKept::Failed(one_line(&e))),
        },
    };
    Ok(Kept {
        index,
        values: values.to_vec(),
        quantities: quantities(&evidence),
        verdict,
        evidence,
    })
}

/// The printed figures the relay of `scenario` misses, computed as the
/// datasheet measures them (the ideal DC step of the coil, no circuit):
/// each figure that bounds every relay (a maximum, a minimum, a
/// tolerance) that the relay does not meet or does not show (it never
/// closes). A release time is not modelled and never rejects.
pub fn screen(scenario: &Scenario) -> Vec<&'static str> {
    let (Some(d), Some(_)) = (&scenario.datasheet, &scenario.coil) else {
        return Vec::new();
    };
    missed(d, datasheet_figures(scenario, d))
}

/// [`screen`], or why the relay's closing on the datasheet's DC step
/// cannot be simulated: such a relay is not one the datasheet excludes.
pub fn screen_or_failure(scenario: &Scenario) -> Result<Vec<&'static str>, String> {
    let (Some(d), Some(_)) = (&scenario.datasheet, &scenario.coil) else {
        return Ok(Vec::new());
    };
    Ok(missed(d, datasheet_figures_or_failure(scenario, d)?))
}

/// The bounding figures of `d` that the modelled values miss.
fn missed(d: &DatasheetSection, model: Vec<(&'static str, Option<f64>)>) -> Vec<&'static str> {
    d.figures()
        .into_iter()
        .zip(model)
        .filter(|((name, figure), _)| *name != "release_time" && figure.is_bound())
        .filter(|((_, figure), (_, value))| value.is_none_or(|v| !figure.holds(v)))
        .map(|((name, _), _)| name)
        .collect()
}

/// A kept relay's quantities, by name.
fn quantities(evidence: &Evidence) -> BTreeMap<String, f64> {
    let chatter: &Chatter = evidence.chatter();
    let timing = Closing::first(chatter, evidence.operations());
    let mut q = BTreeMap::new();
    q.insert("bounce_count".to_owned(), chatter.bounce_count as f64);
    if let Some(t) = timing.operate_time {
        q.insert("operate_time".to_owned(), t);
    }
    if let Some(t) = timing.bounce_time {
        q.insert("bounce_time".to_owned(), t);
    }
    if let Some(t) = timing.settle_time {
        q.insert("settle_time".to_owned(), t);
    }
    if let Some(d) = check::contact_debounce(chatter, &timing) {
        q.insert("lockout".to_owned(), d.lockout);
        q.insert("stable_for".to_owned(), d.stable_for);
    }
    if let Evidence::Run(run) = evidence {
        probe_quantities(run, &mut q);
    }
    q
}

fn probe_quantities(run: &RunResult, q: &mut BTreeMap<String, f64>) {
    for p in &run.probes {
        let a = &p.analysis;
        let name = |what: &str| format!("{}.{what}", p.probe.signal);
        q.insert(name("edges"), a.edges as f64);
        q.insert(name("peak"), a.max.abs().max(a.min.abs()));
        if let Some(d) = a.debounce {
            q.insert(name("lockout"), d.lockout);
            q.insert(name("stable_for"), d.stable_for);
        }
    }
    if let Some(arcs) = &run.arcs {
        q.insert("arc_count".to_owned(), arcs.totals.count as f64);
        q.insert("arc_energy".to_owned(), arcs.totals.energy);
    }
    if let Some(pole) = &run.pole_face {
        q.insert("pole_face_impacts".to_owned(), pole.len() as f64);
    }
}

/// Each limit held against its worst kept relay (the least room left;
/// a relay that cannot show the quantity is worst), and the worst relay
/// overall: the least room left relative to its limit, or without limits
/// the most bounces. Returns its position in `kept` and its limit.
fn worst_case(kept: &[Kept]) -> (Verdict, Option<(usize, Option<String>)>) {
    let room = |c: &LimitCheck| match c.margin {
        Some(m) => m / c.limit.abs().max(f64::MIN_POSITIVE),
        None => f64::NEG_INFINITY,
    };
    let mut checks: Vec<LimitCheck> = Vec::new();
    let mut overall: Option<(usize, f64, String)> = None;
    let n = kept.first().map_or(0, |k| k.verdict.checks.len());
    for c in 0..n {
        let mut worst: Option<(usize, f64)> = None;
        for (i, k) in kept.iter().enumerate() {
            let Some(check) = k.verdict.checks.get(c) else {
                continue;
            };
            let r = room(check);
            if worst.is_none_or(|(_, w)| r < w) {
                worst = Some((i, r));
            }
        }
        let Some((i, r)) = worst else { continue };
        let mut check = kept[i].verdict.checks[c].clone();
        let relay = format!("worst of {} relays: relay {}", kept.len(), kept[i].index);
        check.note = Some(match check.note.take() {
            Some(n) => format!("{relay}; {n}"),
            None => relay,
        });
        if overall.as_ref().is_none_or(|(_, w, _)| r < *w) {
            overall = Some((i, r, check.key.clone()));
        }
        checks.push(check);
    }
    let worst = match overall {
        Some((i, _, key)) => Some((i, Some(key))),
        None => kept
            .iter()
            .enumerate()
            .max_by_key(|(_, k)| k.quantities.get("bounce_count").map_or(0, |b| *b as u64))
            .map(|(i, _)| (i, None)),
    };
    (Verdict::new(checks), worst)
}
