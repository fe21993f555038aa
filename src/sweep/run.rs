//! Running a sweep: every sample of a shard, on `jobs` threads, its rows
//! written in index order as they come in.
//!
//! Workers claim chunks of consecutive samples (512 for the mechanics
//! alone, where a sample takes microseconds; 1 with ngspice, where it
//! takes tens of milliseconds), evaluate them with their own copy of the
//! scenario, and format the chunk's CSV rows themselves. The calling
//! thread only puts the chunks in order, writes them and flushes: so a
//! sweep cut short leaves the header and whole rows, and
//! `--mechanics-only` is not held back by one thread formatting numbers.
//! A chunk that finishes early waits in memory until the ones before it
//! are written.
//!
//! With ngspice a sample is one ngspice process: a sweep reads the bounced
//! run's probes only, so by default it does not run the ideal contact
//! that `run` compares with. When asked to (`RunOptions::compare_ideal`,
//! the CLI's `--ideal`), a sample runs its two ngspice processes one after
//! the other, so that `jobs` stays the number of ngspice processes at
//! once either way.

use std::collections::BTreeMap;
use std::io::Write;
use std::num::NonZeroUsize;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc;

use crate::chatter::Chatter;
use crate::coil::{Closing, Operation};
use crate::mechanics::simulate;
use crate::pipeline::{self, RunOptions, RunResult};
use crate::plan::Plan;
use crate::scenario::Scenario;
use crate::spice::Runner;

use super::error::SweepError;
use super::record::{ProbeRecord, SampleRecord, Shard};
use super::sample::Sampler;
use super::summary::Collected;
use super::table;
use super::verdict::{SampleVerdict, verdict};

/// What each sample runs.
#[derive(Clone, Copy)]
pub enum SweepMode<'r> {
    /// The mechanics alone: outcome, bounces, times; no probes.
    Mechanics,
    /// The whole pipeline with this runner (e.g. [`Ngspice`](crate::spice::Ngspice)).
    Circuit(&'r dyn Runner),
}

/// The old name of [`SweepMode`].
#[deprecated(note = "renamed to `SweepMode`")]
pub type Mode<'r> = SweepMode<'r>;

impl std::fmt::Debug for SweepMode<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SweepMode::Mechanics => f.write_str("Mechanics"),
            SweepMode::Circuit(_) => f.write_str("Circuit(..)"),
        }
    }
}

/// How to run a sweep.
#[derive(Debug, Clone)]
pub struct SweepOptions<'r> {
    /// The mechanics alone, or the whole pipeline through a runner.
    pub mode: SweepMode<'r>,
    /// Threads evaluating samples (with ngspice: ngspice processes at once).
    pub jobs: NonZeroUsize,
    /// The slice of the samples to run ([`Shard::WHOLE`] for all).
    pub shard: Shard,
    /// Each sample's pipeline options; the ideal-contact run is off by
    /// default (see the module overview).
    pub run: RunOptions,
}

impl SweepOptions<'_> {
    /// `mode` on one thread per core, the whole sweep.
    pub fn new(mode: SweepMode<'_>) -> SweepOptions<'_> {
        SweepOptions {
            mode,
            jobs: std::thread::available_parallelism().unwrap_or(NonZeroUsize::MIN),
            shard: Shard::WHOLE,
            run: RunOptions {
                compare_ideal: false,
                ideal_alongside: false,
                ..RunOptions::default()
            },
        }
    }
}

/// Told how far a sweep has got (e.g. a progress bar). Called from the
/// thread that called [`run`].
pub trait Progress {
    /// The sweep is about to run `total` samples.
    fn start(&self, total: u64) {
        let _ = total;
    }
    /// `done` more samples are written.
    fn advance(&self, done: u64) {
        let _ = done;
    }
    /// Every sample is written.
    fn finish(&self) {}
    /// Whether the caller wants the sweep stopped (an embedding that goes
    /// on running, where a signal does not end the process): the sweep
    /// then writes no more rows and fails with [`SweepError::Stopped`].
    fn stopped(&self) -> bool {
        false
    }
}

/// No progress reporting.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {}

/// Samples per chunk a worker claims.
fn chunk_len(mode: SweepMode<'_>) -> u64 {
    match mode {
        SweepMode::Mechanics => 512,
        SweepMode::Circuit(_) => 1,
    }
}

/// Run the samples of `options.shard` of `sampler`'s sweep of `scenario`,
/// writing the CSV header and then each row, in index order, to `out`
/// (flushed after every chunk). Returns the collected results for the
/// summary. A sample that fails is a row with its error; only a failure
/// to write, or a scenario that cannot run at all, is an error.
pub fn run(
    scenario: &Scenario,
    sampler: &Sampler,
    options: &SweepOptions<'_>,
    out: &mut dyn Write,
    progress: &dyn Progress,
) -> Result<Collected, SweepError> {
    run_from(scenario, sampler, options, out, progress, None)
}

/// The CSV header and columns of `scenario`'s sweep with `sampler`'s keys
/// under `options`: what [`run`] writes first.
pub fn layout(
    scenario: &Scenario,
    sampler: &Sampler,
    options: &SweepOptions<'_>,
) -> Result<(Vec<u8>, Vec<String>, table::Columns), SweepError> {
    let signals = signals(scenario, options)?;
    let columns = columns(scenario, options);
    Ok((
        table::header(sampler.keys(), &signals, columns),
        signals,
        columns,
    ))
}

fn columns(scenario: &Scenario, options: &SweepOptions<'_>) -> table::Columns {
    let circuit = matches!(options.mode, SweepMode::Circuit(_));
    table::Columns {
        coil: scenario.coil.is_some(),
        ideal: options.run.compare_ideal && circuit,
        arc: scenario.arc.is_some() && circuit,
    }
}

/// [`run`], continuing a sweep whose first `done.len()` samples of the
/// shard have their rows already (read back by
/// [`super::resume::finished_rows`] into `done`): `out` already holds the
/// header and those rows, and gets the rest. `None`: a sweep from its
/// start, as [`run`].
pub fn run_from(
    scenario: &Scenario,
    sampler: &Sampler,
    options: &SweepOptions<'_>,
    out: &mut dyn Write,
    progress: &dyn Progress,
    done: Option<Collected>,
) -> Result<Collected, SweepError> {
    let signals = signals(scenario, options)?;
    // Resolved once, the netlist read once (a netlist that cannot be read
    // would fail every sample): each worker's plan starts from this one.
    let base = base_plan(scenario, options)?;
    let base = &base;
    let columns = columns(scenario, options);
    let probes = signals.len();
    if done.is_none() {
        let header = table::header(sampler.keys(), &signals, columns);
        out.write_all(&header)
            .and_then(|()| out.flush())
            .map_err(SweepError::Write)?;
    }
    let total = options.shard.len(sampler.count());
    let first = done.as_ref().map_or(0, |d| d.len() as u64).min(total);
    let chunk = chunk_len(options.mode);
    let chunks = (total - first).div_ceil(chunk);
    let mut collected = done.unwrap_or_else(|| Collected::new(sampler.keys().to_vec(), signals));
    progress.start(total);
    progress.advance(first);

    let next = AtomicU64::new(0);
    let stop = AtomicBool::new(false);
    let jobs = options.jobs.get();
    let (tx, rx) = mpsc::sync_channel::<(u64, Vec<u8>, Vec<SampleRecord>)>(4 * jobs);
    let written = std::thread::scope(|scope| {
        for _ in 0..jobs {
            let tx = tx.clone();
            let (next, stop) = (&next, &stop);
            scope.spawn(move || {
                let mut worker = Worker::new(base, sampler, options);
                loop {
                    let c = next.fetch_add(1, Ordering::Relaxed);
                    if c >= chunks || stop.load(Ordering::Relaxed) {
                        break;
                    }
                    let positions = first + c * chunk..(first + (c + 1) * chunk).min(total);
                    let records: Vec<SampleRecord> = positions
                        .map(|p| worker.evaluate(options.shard.sample(p)))
                        .collect();
                    let rows = table::rows(&records, sampler.keys().len(), probes, columns);
                    if tx.send((c, rows, records)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        let mut pending = BTreeMap::new();
        let mut expected = 0;
        // `rx` is moved in: returning early drops it, so that a worker
        // blocked on a full channel gets an error and stops.
        for (c, rows, records) in rx {
            pending.insert(c, (rows, records));
            while let Some((rows, records)) = pending.remove(&expected) {
                if progress.stopped() {
                    stop.store(true, Ordering::Relaxed);
                    return Err(SweepError::Stopped);
                }
                // Excluding a stop's finisher, which counts the rows
                // written and keeps them for `--resume`.
                let written = crate::interrupt::unless_stopping(|| {
                    out.write_all(&rows).and_then(|()| out.flush())
                });
                match written {
                    Some(Ok(())) => {}
                    Some(Err(e)) => {
                        stop.store(true, Ordering::Relaxed);
                        return Err(SweepError::Write(e));
                    }
                    None => {
                        stop.store(true, Ordering::Relaxed);
                        return Ok(());
                    }
                }
                for record in &records {
                    if let Err(e) = collected.add(record) {
                        stop.store(true, Ordering::Relaxed);
                        return Err(e);
                    }
                }
                progress.advance(records.len() as u64);
                expected += 1;
            }
        }
        Ok(())
    });
    written?;
    progress.finish();
    Ok(collected)
}

/// The probed signals of a sweep, or why it cannot run.
fn signals(scenario: &Scenario, options: &SweepOptions<'_>) -> Result<Vec<String>, SweepError> {
    Ok(match options.mode {
        SweepMode::Mechanics if scenario.coil.is_some() && scenario.dc_step().is_none() => {
            return Err(SweepError::CoilNeedsCircuit {
                path: scenario.origin.clone(),
            });
        }
        SweepMode::Mechanics
            if scenario.limits.is_some_and(|l| {
                l.max_release_time.is_some()
                    || l.max_nc_bounce_time.is_some()
                    || l.max_nc_bounces.is_some()
            }) =>
        {
            return Err(SweepError::ReleaseLimitsNeedCircuit {
                path: scenario.origin.clone(),
            });
        }
        SweepMode::Mechanics if scenario.limits.is_some_and(|l| l.has_arc_limits()) => {
            return Err(SweepError::ArcLimitsNeedCircuit {
                path: scenario.origin.clone(),
            });
        }
        SweepMode::Mechanics => Vec::new(),
        SweepMode::Circuit(_) => {
            if scenario.circuit.is_none() || scenario.probes.is_empty() {
                return Err(SweepError::NeedsCircuit {
                    path: scenario.origin.clone(),
                });
            }
            scenario.probes.iter().map(|p| p.signal.clone()).collect()
        }
    })
}

/// Run sample `index` of `sampler`'s sweep of `scenario` on its own
/// (the sweep's workers share one resolved plan instead).
pub fn run_sample(
    scenario: &Scenario,
    sampler: &Sampler,
    index: u64,
    options: &SweepOptions<'_>,
) -> SampleRecord {
    match base_plan(scenario, options) {
        Ok(base) => Worker::new(&base, sampler, options).evaluate(index),
        Err(e) => SampleRecord {
            error: Some(one_line(&e)),
            ..blank(index)
        },
    }
}

/// The old name of [`run_sample`].
#[deprecated(note = "renamed to `run_sample`")]
pub fn evaluate(
    scenario: &Scenario,
    sampler: &Sampler,
    index: u64,
    options: &SweepOptions<'_>,
) -> SampleRecord {
    run_sample(scenario, sampler, index, options)
}

/// Sample `index`'s record before anything ran: every value absent.
fn blank(index: u64) -> SampleRecord {
    SampleRecord {
        index,
        values: Vec::new(),
        outcome: None,
        bounce_count: None,
        first_impact: None,
        settle_time: None,
        bounce_time: None,
        release_time: None,
        nc_bounce_time: None,
        arc_count: None,
        arc_energy: None,
        breakdowns: None,
        probes: Vec::new(),
        verdict: SampleVerdict::Error,
        failed_limits: Vec::new(),
        error: None,
    }
}

/// The plan every sample starts from: the netlist read once for a circuit
/// sweep, not at all for the mechanics alone.
fn base_plan(scenario: &Scenario, options: &SweepOptions<'_>) -> Result<Plan, SweepError> {
    Ok(match options.mode {
        SweepMode::Circuit(_) => Plan::new(scenario.clone())?,
        SweepMode::Mechanics => Plan::without_circuit(scenario.clone())?,
    })
}

/// One thread's state: a copy of the sweep's plan, given each sample's
/// values in turn.
struct Worker<'a, 'r> {
    /// The sweep's plan, copied once per worker: every sample sets the same
    /// keys, so after [`Plan::renumber`] it is the sweep's plan with this
    /// sample's values (a copy per sample cost a tenth of a
    /// mechanics-only sample's time).
    plan: Plan,
    sampler: &'a Sampler,
    options: &'a SweepOptions<'r>,
    values: Vec<f64>,
}

impl<'a, 'r> Worker<'a, 'r> {
    fn new(base: &'a Plan, sampler: &'a Sampler, options: &'a SweepOptions<'r>) -> Self {
        Worker {
            plan: base.clone(),
            sampler,
            options,
            values: vec![0.0; sampler.keys().len()],
        }
    }

    fn evaluate(&mut self, index: u64) -> SampleRecord {
        let mut record = blank(index);
        if let Err(e) = self.sampler.values(index, &mut self.values) {
            record.error = Some(one_line(&e));
            return record;
        }
        record.values = self.values.clone();
        let keys = self.sampler.keys();
        // Small: one pair per varied key.
        let pairs: Vec<(&str, f64)> = keys
            .iter()
            .map(String::as_str)
            .zip(self.values.iter().copied())
            .collect();
        if let Err(e) = self.plan.renumber(&pairs) {
            record.error = Some(format!("invalid sample: {}", one_line(&e)));
            return record;
        }
        let plan = &self.plan;
        let scenario = plan.scenario();
        if scenario.coil.is_some() {
            // Without the circuit, the relay closes on the ideal DC step of
            // its coil, as `bounce` and `check` simulate it (closing times
            // from the coil being energized at t = 0).
            let SweepMode::Circuit(runner) = self.options.mode else {
                match crate::check::relay_chatter(scenario) {
                    Ok(chatter) => {
                        record_chatter(&mut record, &chatter);
                        (record.verdict, record.failed_limits) = verdict(scenario, &chatter, None);
                    }
                    Err(e) => record.error = Some(one_line(&e)),
                }
                return record;
            };
            // The relay moves in its circuit: the coupled run gives the
            // chatter too.
            match pipeline::run_plan(plan, runner, &self.options.run) {
                Ok(result) => {
                    record_chatter(&mut record, &result.chatter);
                    // Closing times count from the coil being energized.
                    let origin = Closing::first(&result.chatter, &result.operations).origin;
                    record.first_impact = record.first_impact.map(|t| t - origin);
                    record.settle_time = record.settle_time.map(|t| t - origin);
                    let worst = |get: fn(&Operation) -> Option<f64>| {
                        result.operations.iter().filter_map(get).reduce(f64::max)
                    };
                    record.release_time = worst(|op| op.release_time);
                    record.nc_bounce_time = worst(|op| op.nc_bounce_time);
                    record_probes(&mut record, &result);
                    (record.verdict, record.failed_limits) =
                        verdict(scenario, &result.chatter, Some(&result));
                }
                Err(e) => record.error = Some(one_line(&e)),
            }
            return record;
        }
        let chatter = match scenario
            .mechanics()
            .map_err(|e| one_line(&e))
            .and_then(|m| {
                let build = plan.two_stage();
                if build.is_one_mass() {
                    simulate(&m, &plan.surface(), &plan.settings()).map_err(|e| one_line(&e))
                } else {
                    crate::mechanics::two_stage::step_closing(
                        &m,
                        &build,
                        &plan.surface(),
                        &plan.settings(),
                    )
                    .map(|t| t.into_chatter())
                    .map_err(|e| one_line(&e))
                }
            }) {
            Ok(chatter) => chatter,
            Err(e) => {
                record.error = Some(e);
                return record;
            }
        };
        record_chatter(&mut record, &chatter);
        match self.options.mode {
            SweepMode::Mechanics => {
                (record.verdict, record.failed_limits) = verdict(scenario, &chatter, None);
            }
            SweepMode::Circuit(runner) => match pipeline::run_plan(plan, runner, &self.options.run)
            {
                Ok(result) => {
                    record_probes(&mut record, &result);
                    (record.verdict, record.failed_limits) =
                        verdict(scenario, &chatter, Some(&result));
                }
                Err(e) => record.error = Some(one_line(&e)),
            },
        }
        record
    }
}

/// The chatter's columns of a record.
fn record_chatter(record: &mut SampleRecord, chatter: &Chatter) {
    record.outcome = Some(chatter.outcome);
    record.bounce_count = Some(chatter.bounce_count);
    record.first_impact = chatter.first_impact;
    record.settle_time = chatter.settle_time;
    record.bounce_time = chatter
        .first_impact
        .zip(chatter.settle_time)
        .filter(|_| chatter.outcome.is_closed())
        .map(|(first, settle)| settle - first);
}

/// The probes' columns of a record.
fn record_probes(record: &mut SampleRecord, result: &RunResult) {
    record.probes = result
        .probes
        .iter()
        .map(|p| ProbeRecord {
            edges: p.analysis.edges,
            peak: p.analysis.max.abs().max(p.analysis.min.abs()),
            ideal_edges: p.ideal.as_ref().map(|i| i.edges),
            lockout: p.analysis.debounce.map(|d| d.lockout),
            stable_for: p.analysis.debounce.map(|d| d.stable_for),
        })
        .collect();
    if let Some(arcs) = &result.arcs {
        record.arc_count = Some(arcs.totals.count);
        record.arc_energy = Some(arcs.totals.energy);
        record.breakdowns = Some(arcs.totals.breakdowns);
    }
}

/// An error and its causes on one line, each cause's first line only:
/// later lines carry work directories and log tails, which differ from
/// run to run and would make the CSV depend on more than the samples.
pub fn one_line(err: &dyn std::error::Error) -> String {
    let mut parts: Vec<String> = Vec::new();
    let mut cause = Some(err);
    while let Some(e) = cause {
        let text = e.to_string();
        let first = text.lines().next().unwrap_or_default().trim().to_owned();
        // A transparent wrapper repeats its source.
        if !first.is_empty() && parts.last() != Some(&first) {
            parts.push(first);
        }
        cause = e.source();
    }
    parts.join(": ")
}
