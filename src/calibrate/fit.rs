//! Fitting a scenario to evidence: a record of the contact's make and
//! break times (a scope capture or a `time,state` file) and/or the figures
//! of the relay's datasheet.
//!
//! # What is fitted
//!
//! The free keys are scenario numbers (`surface.damping`,
//! `mechanics.preload`, …). They are fitted as logarithms: every key is
//! positive and their sizes span many decades, so a step of 0.1 means
//! "10 % more" for each of them alike, which keeps the normal equations
//! well scaled.
//!
//! **A record** gives make/break times. The model's events are matched to
//! the measured ones in order; the record's time zero is its trigger, not
//! the moment the force was applied, so the offset between the two time
//! axes is a parameter too. It is linear and solved in closed form at every
//! evaluation (the mean of the matched differences), which is the same as
//! fitting it jointly. A differing number of events is penalised (each
//! unmatched event costs its distance to the model's last event plus a
//! fixed penalty), never ignored. One spurious glitch (a break and make
//! pair the model does not have) or one missing bounce is absorbed by
//! refitting with each adjacent pair of measured, or modelled, events
//! dropped, and keeping the drop that reduces the misfit tenfold.
//!
//! **A datasheet** gives figures in IEC 61810 meanings, computed here as a
//! datasheet measures them: an ideal DC step on the coil, no driver
//! circuit. With the single-gap magnet `L(x) = μ0N²A/(g_a − x + l_eq)`
//! and the armature's load line `p + s·x` ([`crate::coil::pick_up`]):
//! pick-up is the smallest current `i = V_pu/R_c` whose pull `½ i² L'(x)`
//! beats the load at every position of the travel. That is the pull at
//! rest against the preload only while `s·a ≤ 2p` (`a = g_a + l_eq`); a
//! stiffer spring makes the armature lift off and stall part-way, at
//! `x* = (s·a − 2p)/(3s)`, and that point sets the pick-up. At drop-out
//! the pull at the closed position equals the load there,
//! `½ i² L'(g) = s·g + p`. The operate and bounce times come from
//! the direct coil engine ([`crate::coil::simulate_direct`]). A release
//! time is shown but not fitted: a relay's release is paced by the decay
//! of its flux (eddy currents, the coil's own circuit), which this magnet
//! with an ideal switch does not have. The report says where the fitted
//! relay's pick-up binds (at rest, or part-way at which position).
//!
//! # The solver
//!
//! Levenberg–Marquardt with a central-difference Jacobian (the event
//! times come out of an adaptive integrator, so there is no analytic
//! derivative), Marquardt's diagonal scaling, and the parameters clamped
//! into their bounds. It is a few dozen lines on a small dense matrix of its
//! own (`fit_dense.rs`); the problem is tiny (≤ 6 parameters, tens of residuals),
//! and the candidates (dropped pairs) and held keys need control of the
//! residual function that a general crate's trait would only wrap. With
//! many bounces the misfit has local minima wherever the event count
//! changes, so the solver starts from the prior and from the best points of
//! a survey of the log-bounds box (a Halton sequence, 40 points per free
//! key: deterministic and even), and the best result is kept.
//!
//! # What the evidence determines
//!
//! At the optimum, with `J` the Jacobian of the data residuals in the log
//! parameters and `rms²` their mean square per degree of freedom, the
//! covariance is `(JᵀJ)⁻¹·rms²`; a key's 1σ is its value times the square
//! root of its diagonal entry. A direction in which `JᵀJ` is near-singular
//! (smallest/largest eigenvalue below 1e-9) is one the data cannot see:
//! e.g. a step force closing on a Kelvin–Voigt surface depends on the force
//! and the gap only through their ratio (with the mass and stiffness fixed).
//! The key that dominates such a direction is held at its prior and the
//! rest refitted; a weak penalty toward the prior (1 % of the timing scale
//! per e-fold) keeps the iteration away from absurd values meanwhile. A
//! held key, or one whose σ exceeds its value, is reported as not
//! determined.

use std::time::Instant;

use serde::Serialize;
use thiserror::Error;

use super::sections::{DatasheetSection, Determined, FittedParameter, ProvenanceSection};
use crate::chatter::{ContactState, Interval};
use crate::scenario::{PrintedFigure, Scenario, ScenarioError};

#[path = "fit_breaking.rs"]
mod breaking;
#[path = "fit_datasheet.rs"]
mod datasheet;
#[path = "fit_dense.rs"]
mod dense;
#[path = "fit_problem.rs"]
mod problem;
#[path = "fit_report.rs"]
mod report;
#[path = "fit_solver.rs"]
mod solver;
#[path = "fit_start.rs"]
mod start;
use breaking::fit_breaking;
pub use datasheet::{
    coil_tolerance_corner, datasheet_figures, datasheet_figures_or_failure, model_events,
    pick_up_of,
};
use problem::{Candidate, Problem};
use solver::{hold_blind_keys, refine, set_aside_bad_edge, survey};
use start::closed_form_start;

/// s: residuals of event times are divided by this before they are
/// squared, so that they weigh like relative datasheet misfits.
const TIME_SCALE: f64 = 1e-6;
/// Datasheet residuals are relative, divided by this (0.1 %).
pub(super) const RELATIVE_SCALE: f64 = 1e-3;
/// s, the cost of each event the model lacks or adds, on top of its
/// distance.
const COUNT_PENALTY: f64 = 50e-6;
/// Weight of the pull toward the prior, per e-fold of a key.
const PRIOR_WEIGHT: f64 = 1e-2;
/// Central-difference step in the log parameters.
const JACOBIAN_STEP: f64 = 1e-4;
/// Below this eigenvalue ratio of JᵀJ a direction is not determined.
const SINGULAR_RATIO: f64 = 1e-9;
/// Starts besides the prior: the best points of the survey.
const EXTRA_STARTS: usize = 4;
/// Survey points per free key.
const SURVEY_PER_KEY: usize = 40;

/// Why a fit cannot start.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum FitError {
    /// Neither the request nor the scenario's `[fit]` names a free key.
    #[error(
        "no free keys: list the keys the fit may move in [fit] free = [...] or with --free KEY,..."
    )]
    NoFreeKeys,
    /// The arc's keys cannot be fitted to the breaking curve.
    #[error("{path}: {problem}")]
    Breaking {
        /// The scenario file.
        path: String,
        /// What is wrong and what to do.
        problem: String,
    },
    /// A free key is not a number key of the scenario.
    #[error("{path}: free key `{key}`: {source}")]
    UnknownKey {
        /// The scenario file.
        path: String,
        /// The free key, e.g. `surface.damping`.
        key: String,
        /// Why the scenario does not know the key.
        #[source]
        source: Box<ScenarioError>,
    },
    /// A free key is left unset in the scenario: there is no prior.
    #[error(
        "{path}: free key `{key}` has no value in the scenario to start from: give it a prior value"
    )]
    NoPrior {
        /// The scenario file.
        path: String,
        /// The free key.
        key: String,
    },
    /// A free key's prior is zero, negative or not finite: the fit works
    /// in logarithms.
    #[error(
        "{path}: free key `{key}` = {value} cannot be fitted: the fit works in logarithms and needs a positive prior"
    )]
    NotPositive {
        /// The scenario file.
        path: String,
        /// The free key.
        key: String,
        /// The prior value, in the key's unit.
        value: f64,
    },
    /// A key's `[fit] bounds` are not positive and increasing, or do not
    /// contain its prior.
    #[error(
        "{path}: [fit] bounds for `{key}` = [{low}, {high}] must be positive, increasing and contain the prior {prior}"
    )]
    Bounds {
        /// The scenario file.
        path: String,
        /// The free key.
        key: String,
        /// The lower bound, in the key's unit.
        low: f64,
        /// The upper bound, in the key's unit.
        high: f64,
        /// The prior value, in the key's unit.
        prior: f64,
    },
    /// Neither a record nor a `[datasheet]` figure was given.
    #[error(
        "nothing to fit to: pass --capture or --measured, or give figures in the scenario's [datasheet]"
    )]
    NoEvidence,
    /// The scenario has datasheet figures but no `[coil]` to compute them.
    #[error(
        "{path}: [datasheet] {figure} needs a coil: add a [coil] section (the datasheet figures are those of a coil-driven relay)"
    )]
    NeedsCoil {
        /// The scenario file.
        path: String,
        /// The first datasheet figure given, e.g. `pick_up_voltage`.
        figure: &'static str,
    },
    /// A time figure, or a record of a coil-driven relay, needs the
    /// `[datasheet] coil_voltage` it was measured with.
    #[error(
        "{path}: [datasheet] coil_voltage is needed: the times and a coil-driven record are measured with that DC step on the coil"
    )]
    NeedsVoltage {
        /// The scenario file.
        path: String,
    },
    /// A datasheet figure (or `coil_voltage`) is not positive and finite.
    #[error("{path}: [datasheet] {figure} = {value} must be a positive, finite number")]
    BadFigure {
        /// The scenario file.
        path: String,
        /// The figure's key, e.g. `operate_time`.
        figure: &'static str,
        /// The value given (V or s).
        value: f64,
    },
    /// The record has a single state: no event to match.
    #[error("{name}: the record has no make or break edge to fit")]
    EmptyRecord {
        /// The record's name.
        name: String,
    },
    /// The scenario with its prior values fails to simulate.
    #[error("{path}: the prior scenario cannot be simulated: {message}")]
    Prior {
        /// The scenario file.
        path: String,
        /// Why it cannot be simulated.
        message: String,
    },
}

/// A make (the contact closes) or a break (it opens).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EventKind {
    /// The contact closes.
    Make,
    /// The contact opens.
    Break,
}

impl EventKind {
    /// `"make"` or `"break"`, as in the JSON report.
    pub fn as_str(self) -> &'static str {
        match self {
            EventKind::Make => "make",
            EventKind::Break => "break",
        }
    }
}

/// One change of contact state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Event {
    /// Make or break.
    pub kind: EventKind,
    /// s
    pub time: f64,
}

/// The changes of state of a tiling of intervals: every interval's start
/// but the first's.
pub fn events_of(intervals: &[Interval]) -> Vec<Event> {
    intervals
        .iter()
        .skip(1)
        .map(|i| Event {
            kind: match i.state {
                ContactState::Closed => EventKind::Make,
                ContactState::Open => EventKind::Break,
            },
            time: i.start,
        })
        .collect()
}

/// A measured record of the contact: its name (for messages and the
/// provenance) and its states.
#[derive(Debug, Clone)]
pub struct Record {
    /// The file or capture it came from, as messages name it.
    pub name: String,
    /// The contact's states, tiling the record's time in order.
    pub intervals: Vec<Interval>,
}

/// What to fit to and what may move.
#[derive(Debug, Clone, Default)]
pub struct FitRequest {
    /// A record of make/break times.
    pub record: Option<Record>,
    /// Free keys replacing `[fit] free` (empty: use the scenario's).
    pub free: Vec<String>,
}

/// One free key's outcome.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ParameterRow {
    /// The scenario key, e.g. `mechanics.preload`.
    pub key: String,
    /// The value the fit started from, in the key's unit.
    pub prior: f64,
    /// The fitted value, in the key's unit.
    pub value: f64,
    /// 1σ; `None` for a key held at its prior.
    pub sigma: Option<f64>,
    /// Whether the evidence fixes the key: not held at its prior, and its
    /// 1σ smaller than its value; `"exactly"` when as many datasheet
    /// figures as free keys fix it (its σ then comes from their
    /// tolerances).
    pub determined: Determined,
}

/// One measured event against the model's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventRow {
    /// Make or break.
    pub kind: EventKind,
    /// s, on the record's time axis; `None` for a model event the record
    /// lacks.
    pub measured: Option<f64>,
    /// s, on the record's time axis (model time less the offset); `None`
    /// for a measured event the model lacks.
    pub model: Option<f64>,
    /// s, model − measured; `None` unless both are known.
    pub residual: Option<f64>,
    /// The event was set aside as the one bad edge.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub dropped: bool,
}

/// The bounces (breaks) of the record against the model's, over the
/// matched events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BounceCount {
    /// Breaks in the record.
    pub measured: usize,
    /// Breaks in the model.
    pub model: usize,
}

/// One datasheet figure against the model's.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureRow {
    /// The `[datasheet]` key, e.g. `pick_up_voltage`.
    pub figure: &'static str,
    /// The datasheet's value that stands for the figure (V for a voltage,
    /// Ω for a resistance, s for a time): the typical value, else the
    /// maximum, else the minimum.
    pub target: f64,
    /// The figure as printed: a number (typical) or `{typ, min, max,
    /// tolerance}`.
    pub printed: PrintedFigure,
    /// How the fit used it: `"target"` (a typical value, matched) or
    /// `"bound"` (a minimum, maximum or tolerance only, held).
    pub role: &'static str,
    /// Whether the model meets the figure as printed (inside its bounds;
    /// a typical value alone within ±20 %); `None` when the model does not
    /// show it.
    pub met: Option<bool>,
    /// The model's value, same unit; `None` when the model does not show
    /// it (it never closes, say) or does not model it (`release_time`).
    pub model: Option<f64>,
    /// (model − target)/target.
    pub residual: Option<f64>,
    /// For a pick-up maximum or drop-out minimum with a printed coil
    /// tolerance: the model's voltage with its coil at the far end of that
    /// tolerance, which is what the bound is held against (V).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub at_coil_tolerance: Option<f64>,
    /// This figure limits the fit: a bound the model sits on (or crosses),
    /// or the target with the largest relative misfit.
    pub binds: bool,
    /// m, for `pick_up_voltage`: where along the travel the model's pull
    /// only just beats the load (0 at rest); for `drop_out_voltage`: the
    /// closed position the pull must hold. Absent for the times.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position: Option<f64>,
}

/// The result of [`fit`].
#[derive(Debug, Clone, Serialize)]
pub struct FitReport {
    /// One row per free key, in the order given.
    pub parameters: Vec<ParameterRow>,
    /// The record's events against the model's, in time order; empty
    /// without a record.
    pub events: Vec<EventRow>,
    /// `None` (null) without a record.
    pub bounce_count: Option<BounceCount>,
    /// One row per datasheet figure given; empty without a datasheet.
    pub datasheet: Vec<FigureRow>,
    /// s, model time minus record time (the record's trigger is not the
    /// model's zero); `None` without a record.
    pub time_offset: Option<f64>,
    /// s for a record fit (events only); relative for a datasheet-only fit.
    pub rms_residual: f64,
    /// How many times the model was simulated.
    pub evaluations: usize,
    /// s, wall clock.
    pub elapsed: f64,
    /// Where the fitted relay's pick-up binds, in words (`at rest (x = 0)`
    /// or `part-way, at x = … mm of the … mm travel`); `None` unless the
    /// datasheet gives a pick-up voltage.
    pub pick_up_binds: Option<String>,
    /// What the fit decided on its own (held keys, a dropped edge), and
    /// where the pick-up binds.
    pub notes: Vec<String>,
    /// The scenario with the fitted values and its `[provenance]`.
    #[serde(skip)]
    pub fitted: Scenario,
    /// What was fitted to: the record's name and/or `datasheet`, joined
    /// by ` + `.
    #[serde(skip)]
    pub fitted_to: String,
    /// With `arc.low_current` (and `arc.field`) free: the arc constants
    /// fitted to the printed DC breaking capacity, each figure beside the
    /// fitted model's breakable current.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub breaking: Option<crate::arc::breaking::BreakingFit>,
    /// The scenario's own `[provenance]` when only the arc was fitted: its
    /// mechanics' record stays, the arc's rows are added to it.
    #[serde(skip)]
    pub kept_provenance: Option<ProvenanceSection>,
}

impl FitReport {
    /// The `[provenance]` section for the fitted scenario.
    pub fn provenance(&self) -> ProvenanceSection {
        let fitted = self.parameters.iter().map(|p| {
            (
                p.key.clone(),
                FittedParameter {
                    prior: p.prior,
                    value: p.value,
                    sigma: p.sigma,
                    determined: p.determined,
                },
            )
        });
        if let Some(kept) = &self.kept_provenance {
            let mut merged = kept.clone();
            merged.parameters.extend(fitted);
            if !merged.fitted_to.contains("dc_breaking") {
                merged.fitted_to.push_str(" + dc_breaking");
            }
            return merged;
        }
        ProvenanceSection {
            fitted_to: self.fitted_to.clone(),
            rms_residual: self.rms_residual,
            time_offset: self.time_offset,
            pick_up_binds: self.pick_up_binds.clone(),
            parameters: fitted.collect(),
        }
    }
}

/// Fit `scenario`'s free keys to the evidence; the scenario's own
/// `[datasheet]` figures take part whenever it has any.
pub fn fit(scenario: &Scenario, request: &FitRequest) -> Result<FitReport, FitError> {
    let started = Instant::now();
    // The arc's keys are fitted in closed form to the breaking curve; the
    // rest by the mechanics fit below.
    let free: Vec<String> = if request.free.is_empty() {
        scenario
            .fit
            .as_ref()
            .map(|f| f.free.clone())
            .unwrap_or_default()
    } else {
        request.free.clone()
    };
    let (arc_keys, mechanical): (Vec<String>, Vec<String>) =
        free.into_iter().partition(|k| k.starts_with("arc."));
    if arc_keys.is_empty() {
        return fit_mechanics(scenario, request, started);
    }
    let arc_only = mechanical.is_empty();
    let mut report = if arc_only {
        FitReport {
            parameters: Vec::new(),
            events: Vec::new(),
            bounce_count: None,
            datasheet: Vec::new(),
            time_offset: None,
            rms_residual: 0.0,
            evaluations: 0,
            elapsed: 0.0,
            pick_up_binds: None,
            notes: Vec::new(),
            breaking: None,
            kept_provenance: scenario.provenance.clone(),
            fitted: scenario.clone(),
            fitted_to: "dc_breaking".to_owned(),
        }
    } else {
        let mut scenario = scenario.clone();
        if let Some(f) = scenario.fit.as_mut() {
            f.free.retain(|k| !k.starts_with("arc."));
        }
        let request = FitRequest {
            record: request.record.clone(),
            free: if request.free.is_empty() {
                Vec::new()
            } else {
                mechanical
            },
        };
        fit_mechanics(&scenario, &request, started)?
    };
    fit_breaking(scenario, &arc_keys, &mut report)?;
    if arc_only {
        // The breaking fit's own misfit: rms of ln(model/printed).
        report.rms_residual = report.breaking.as_ref().map_or(0.0, |b| b.rms_log_error);
    }
    report.elapsed = started.elapsed().as_secs_f64();
    Ok(report)
}

fn fit_mechanics(
    scenario: &Scenario,
    request: &FitRequest,
    started: Instant,
) -> Result<FitReport, FitError> {
    let problem = Problem::new(scenario, request)?;
    let u_prior: Vec<f64> = problem.prior.iter().map(|p| p.ln()).collect();
    let mut active: Vec<usize> = (0..problem.keys.len()).collect();
    let mut notes = Vec::new();

    // Multistart over the full candidate.
    let starts = survey(&problem, &u_prior, &active);
    let best = refine(&problem, &starts, &u_prior, &active);
    // One bad edge: a glitch in the record, or a bounce it missed.
    let (candidate, best) = set_aside_bad_edge(&problem, best, &active, &mut notes);
    // The keys the data cannot see stay at their priors.
    let held = hold_blind_keys(&problem, best, candidate, &u_prior, &mut active, &mut notes);
    let parameters = report::uncertainties(&problem, &held, candidate, &u_prior, &active);
    Ok(report::assemble(
        &problem,
        request,
        &held.best.0,
        candidate,
        parameters,
        notes,
        started,
    ))
}

/// The fitted scenario as TOML: the prior file's text with the fitted
/// values put in and a `[provenance]` section, so that every key the user
/// wrote stays (comments do not survive).
///
/// `netlist`, when given, replaces `circuit.netlist`: a relative path in
/// the prior is relative to the prior's directory, which is not the fitted
/// file's when it is written elsewhere.
pub fn fitted_toml(
    prior_text: &str,
    report: &FitReport,
    netlist: Option<&std::path::Path>,
) -> Result<String, toml::de::Error> {
    let mut table: toml::Table = toml::from_str(prior_text)?;
    if let (Some(path), Some(toml::Value::Table(circuit))) = (netlist, table.get_mut("circuit")) {
        circuit.insert(
            "netlist".to_owned(),
            toml::Value::String(path.display().to_string()),
        );
    }
    for p in &report.parameters {
        let mut parts = p.key.splitn(2, '.');
        let (Some(section), Some(name)) = (parts.next(), parts.next()) else {
            continue;
        };
        let entry = table
            .entry(section.to_owned())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        if let toml::Value::Table(t) = entry {
            t.insert(name.to_owned(), toml::Value::Float(p.value));
        }
    }
    let provenance =
        toml::Value::try_from(report.provenance()).expect("provenance serializes to TOML");
    table.insert("provenance".to_owned(), provenance);
    Ok(toml::to_string(&table).expect("a TOML table serializes"))
}

#[cfg(test)]
#[path = "fit_tests.rs"]
mod tests;
