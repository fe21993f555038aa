//! Every verdict the user asks for, computed once: what `run`, `check`,
//! `check --envelope` and `life` decide, for the command line and the
//! Python package alike.
//!
//! The rooms below compute their parts: [`pipeline`] the run through
//! ngspice, [`check`](mod@crate::check) the limits against a closing or a
//! run, [`life`](mod@crate::life) the electrical life, [`envelope`] every
//! relay the datasheet allows. This
//! layer composes them as a command does: a run with the life at its
//! circuit, a check with `[limits] min_electrical_life` held like every
//! other limit. The front ends only read their arguments into
//! [`RunOptions`] and [`LifeOptions`], call one function here and present
//! its outcome (the JSON comes from the outcome itself), so that a
//! scenario gets the same answer whichever door it came in by.

use std::path::Path;
use std::sync::OnceLock;

use thiserror::Error;

use crate::chatter::Interval;
use crate::check::{self, CheckError, Evidence, Verdict};
use crate::commands;
use crate::envelope::{self, Envelope, EnvelopeError, EnvelopeOptions};
use crate::life::{self, LifeError, LifeReport};
use crate::mechanics::Dimensionless;
use crate::pipeline::{self, RunError, RunOptions, RunResult};
use crate::report;
use crate::scenario::Scenario;
use crate::spice::{Ngspice, Runner, SpiceError};

/// Why a verdict could not be reached: the error of the part that failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum VerdictError {
    /// The run through ngspice.
    #[error(transparent)]
    Run(#[from] RunError),
    /// The limits, or the closing they are held against.
    #[error(transparent)]
    Check(#[from] CheckError),
    /// The electrical life.
    #[error(transparent)]
    Life(#[from] LifeError),
    /// The envelope's draw or its relays.
    #[error(transparent)]
    Envelope(#[from] EnvelopeError),
    /// ngspice could not be found or started.
    #[error(transparent)]
    Spice(#[from] SpiceError),
}

/// The electrical life a run or a check estimates.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LifeOptions {
    /// Switching phases averaged over the period of an AC figure.
    pub phases: usize,
    /// Estimate the life of a scenario with endurance figures (a check
    /// with `[limits] min_electrical_life` estimates it either way).
    pub estimate: bool,
    /// ngspice runs at a time.
    pub jobs: usize,
}

impl Default for LifeOptions {
    fn default() -> Self {
        LifeOptions {
            phases: life::DEFAULT_PHASES,
            estimate: true,
            jobs: cpus(),
        }
    }
}

/// The number of CPUs, at least 1.
pub fn cpus() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
}

/// ngspice, located the first time a verdict needs it (a check of the
/// relay's limits alone never does).
pub struct LazyNgspice<'a> {
    locate: Box<dyn Fn() -> Result<Ngspice, SpiceError> + Send + Sync + 'a>,
    found: OnceLock<Ngspice>,
}

impl<'a> LazyNgspice<'a> {
    /// ngspice as `locate` finds it, when it is first needed.
    pub fn new(locate: impl Fn() -> Result<Ngspice, SpiceError> + Send + Sync + 'a) -> Self {
        LazyNgspice {
            locate: Box::new(locate),
            found: OnceLock::new(),
        }
    }

    /// ngspice, located now if it was not yet.
    pub fn get(&self) -> Result<&Ngspice, SpiceError> {
        if let Some(found) = self.found.get() {
            return Ok(found);
        }
        let located = (self.locate)()?;
        Ok(self.found.get_or_init(|| located))
    }
}

/// What a run decided: the run, the electrical life at its circuit, and
/// what is worth saying about it.
#[derive(Debug)]
pub struct RunOutcome {
    /// The run, its netlist shown relative to the working directory when
    /// it is below it.
    pub result: RunResult,
    /// The electrical life at the run's circuit (from the run's arcs),
    /// for a scenario with endurance figures.
    pub life: Option<LifeReport>,
    /// The relay's dimensionless groups (a step-force relay).
    pub dimensionless: Option<Dimensionless>,
    /// Things worth a look that did not stop the run: the run's own
    /// warnings, then a life that could not be estimated.
    pub warnings: Vec<String>,
}

impl RunOutcome {
    /// The run JSON (`run --format json`).
    pub fn json(&self) -> String {
        report::json::render_run_with_life(
            &self.result,
            self.dimensionless.as_ref(),
            self.life.as_ref(),
        )
    }
}

/// `run`: `scenario`'s circuit through `runner`, switched by its relay's
/// mechanics (by the record `measured` when given), and the electrical
/// life at that circuit as `life` asks.
pub fn run(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &RunOptions,
    measured: Option<Vec<Interval>>,
    life: &LifeOptions,
) -> Result<RunOutcome, VerdictError> {
    let mut result = match measured {
        Some(intervals) => pipeline::run_measured(scenario, intervals, runner, options)?,
        None => pipeline::run(scenario, runner, options)?,
    };
    let mut warnings = result.warnings.clone();
    let life = estimate_life(
        scenario,
        runner,
        options,
        Some(&result),
        false,
        life,
        &mut warnings,
    )?;
    if let Some(relative) = std::env::current_dir()
        .ok()
        .and_then(|cwd| result.netlist.strip_prefix(cwd).ok().map(Path::to_path_buf))
    {
        result.netlist = relative;
    }
    Ok(RunOutcome {
        result,
        life,
        dimensionless: commands::dimensionless(scenario),
        warnings,
    })
}

/// The life of `scenario` at its circuit's run `own` (`None`: run the
/// circuit), or `None` when the scenario prints no endurance figures or
/// the options leave it out and it is not `needed` (for a limit). A life
/// that is not needed and cannot be estimated is a warning, not a failure.
fn estimate_life(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &RunOptions,
    own: Option<&RunResult>,
    needed: bool,
    life: &LifeOptions,
    warnings: &mut Vec<String>,
) -> Result<Option<LifeReport>, VerdictError> {
    if !(needed || (life.estimate && life::has_figures(scenario))) {
        return Ok(None);
    }
    match life::estimate_at(scenario, runner, options, life.phases, life.jobs, own) {
        Ok(report) => {
            // What the life could not price is said where the run's
            // warnings are, for the front ends to signal it.
            warnings.extend(
                report
                    .warnings
                    .iter()
                    .map(|w| format!("electrical life: {w}")),
            );
            Ok(Some(report))
        }
        Err(e) if !needed && crate::interrupt::stopping().is_none() => {
            warnings.push(format!("the electrical life was not estimated: {e}"));
            Ok(None)
        }
        Err(e) => Err(e.into()),
    }
}

/// What a check decided: every limit (the life's too), what it was
/// decided on, and what is worth saying about it.
#[derive(Debug)]
pub struct CheckOutcome {
    /// Every limit, `passed` when all hold.
    pub verdict: Verdict,
    /// The closing, or the run, the limits were held against.
    pub evidence: Evidence,
    /// The electrical life at the circuit: with `[limits]
    /// min_electrical_life` always, else for a scenario with endurance
    /// figures whose circuit the check ran.
    pub life: Option<LifeReport>,
    /// The relay's dimensionless groups (a step-force relay).
    pub dimensionless: Option<Dimensionless>,
    /// The run's warnings, and a life that could not be estimated.
    pub warnings: Vec<String>,
    /// Remarks on a limit's figure (e.g. why the life is unlimited),
    /// each starting with the limit's key.
    pub notes: Vec<String>,
}

impl CheckOutcome {
    /// The check JSON (`check --format json`).
    pub fn json(&self) -> String {
        report::json::render_check_with_life(
            &self.verdict,
            &self.evidence,
            self.dimensionless.as_ref(),
            self.life.as_ref(),
        )
    }
}

/// `check`: `scenario`'s limits held against its closing (the record
/// `measured` when given) and, when a limit needs it, its run through
/// ngspice; `[limits] min_electrical_life` against the life estimated as
/// `life` asks.
pub fn check(
    scenario: &Scenario,
    ngspice: &LazyNgspice<'_>,
    options: &RunOptions,
    measured: Option<Vec<Interval>>,
    life: &LifeOptions,
) -> Result<CheckOutcome, VerdictError> {
    let needs_ngspice = commands::check_needs_ngspice(scenario, measured.is_some());
    let (verdict, evidence) = match measured {
        Some(intervals) => {
            let runner = match needs_ngspice {
                true => Some(ngspice.get()? as &dyn Runner),
                false => None,
            };
            check::measured(scenario, intervals, runner, options)?
        }
        None if needs_ngspice => check::run_with(scenario, ngspice.get()?, options)?,
        // The relay's limits alone: no circuit, no ngspice needed.
        None => check::relay_only(scenario)?,
    };
    let mut warnings = match &evidence {
        Evidence::Run(run) => run.warnings.clone(),
        Evidence::Mechanics(..) => Vec::new(),
    };
    let limit = scenario.limits.and_then(|l| l.min_electrical_life);
    let own = match &evidence {
        Evidence::Run(run) => Some(run.as_ref()),
        Evidence::Mechanics(..) => None,
    };
    let life = if limit.is_some() || own.is_some() {
        estimate_life(
            scenario,
            ngspice.get()?,
            options,
            own,
            limit.is_some(),
            life,
            &mut warnings,
        )?
    } else {
        None
    };
    let mut notes = Vec::new();
    let verdict = match (limit, &life) {
        (Some(limit), Some(life)) => {
            let row = life::limit_check(limit, life);
            if let Some(note) = &row.note {
                notes.push(format!("min_electrical_life: {note}"));
            }
            let mut checks = verdict.checks;
            checks.push(row);
            Verdict::new(checks)
        }
        _ => verdict,
    };
    Ok(CheckOutcome {
        verdict,
        evidence,
        life,
        dimensionless: commands::dimensionless(scenario),
        warnings,
        notes,
    })
}

/// `check --envelope`: every relay the datasheet allows, each limit held
/// against the worst kept relay.
pub fn check_envelope(
    scenario: &Scenario,
    ngspice: &LazyNgspice<'_>,
    options: &EnvelopeOptions,
) -> Result<Envelope, VerdictError> {
    let runner = match commands::check_needs_ngspice(scenario, false) {
        true => Some(ngspice.get()? as &dyn Runner),
        false => None,
    };
    Ok(envelope::run(scenario, runner, options)?)
}

/// The JSON of `check --envelope`: the worst relay's check, with the
/// bands under `envelope`.
pub fn envelope_check_json(env: &Envelope) -> String {
    let worst = env
        .worst()
        .expect("an envelope that kept a relay has a worst one");
    envelope::json_with_envelope(
        &report::json::render_check(&env.verdict, &worst.evidence, None),
        &env.report,
    )
}

/// `run --envelope`: the run's relay and every relay the datasheet
/// allows, the bands laid into the run's JSON.
pub fn run_envelope(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &EnvelopeOptions,
) -> Result<Envelope, VerdictError> {
    Ok(envelope::run(scenario, Some(runner), options)?)
}

/// `life`: the electrical life of `scenario` from its endurance figures,
/// and at its own circuit when it has one.
pub fn life(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &RunOptions,
    life: &LifeOptions,
) -> Result<LifeReport, VerdictError> {
    Ok(life::estimate(
        scenario,
        runner,
        options,
        life.phases,
        life.jobs,
    )?)
}

/// The `life` JSON (`life --format json`).
pub fn life_json(report: &LifeReport) -> String {
    let mut text = serde_json::to_string_pretty(report).expect("the report serializes");
    text.push('\n');
    text
}
