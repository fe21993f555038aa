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
//! into their bounds. It is a few dozen lines on nalgebra, which the crate
//! already uses; the problem is tiny (≤ 6 parameters, tens of residuals),
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

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use serde::Serialize;
use thiserror::Error;

use super::sections::{DatasheetSection, Determined, FittedParameter, ProvenanceSection};
use crate::chatter::{ContactState, Interval};
use crate::coil::direct::direct_closing;
use crate::coil::pick_up::{LoadLine, PickUp, drop_out, pick_up};
use crate::coil::{Coil, Source};
use crate::mechanics::simulate;
use crate::scenario::{PrintedFigure, Scenario, ScenarioError};

#[path = "fit_breaking.rs"]
mod breaking;
#[path = "fit_report.rs"]
mod report;
#[path = "fit_start.rs"]
mod start;
use breaking::fit_breaking;
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

/// Which events take part: none dropped, or one adjacent pair of the
/// measured or of the modelled events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Candidate {
    All,
    DropMeasured(usize),
    DropModel(usize),
}

fn drop_pair(events: &[Event], j: usize) -> Vec<Event> {
    events
        .iter()
        .enumerate()
        .filter(|&(i, _)| i != j && i != j + 1)
        .map(|(_, e)| *e)
        .collect()
}

/// V, a pick-up or drop-out voltage `v` as the relay at the far end of
/// its coil's printed resistance tolerance shows it, when the figure is a
/// bound: the currents are the relay's, so the voltages scale with the
/// resistance (`v·(1 + t)` for a pick-up maximum, `v·(1 − t)` for a
/// drop-out minimum). A printed bound holds for every relay of the type,
/// whatever its coil, so the nominal relay must meet it with that room.
/// Any other figure: `v`.
pub fn coil_tolerance_corner(
    d: &DatasheetSection,
    name: &str,
    figure: &PrintedFigure,
    v: f64,
) -> f64 {
    let Some(t) = d.coil_resistance.and_then(|r| r.tolerance) else {
        return v;
    };
    if figure.typ.is_some() {
        return v;
    }
    match name {
        "pick_up_voltage" if figure.max.is_some() => v * (1.0 + t),
        "drop_out_voltage" if figure.min.is_some() => v * (1.0 - t),
        _ => v,
    }
}

/// The modelled events of one closing: the step-force engine, or with a
/// coil the direct engine on an ideal `voltage` step.
pub fn model_events(s: &Scenario, voltage: Option<f64>) -> Result<Vec<Event>, String> {
    let chatter = match (&s.coil, voltage) {
        (Some(c), Some(v)) => {
            direct_closing(
                &Coil::from(c),
                &Source {
                    voltage: v,
                    series_resistance: 0.0,
                },
                &s.armature(),
                &s.two_stage(),
                &s.surface(),
                &s.settings(),
            )
            .map_err(|e| e.to_string())?
            .0
        }
        (Some(_), None) => return Err("a coil-driven relay needs [datasheet] coil_voltage".into()),
        (None, _) if s.two_stage().is_one_mass() => {
            simulate(&s.armature(), &s.surface(), &s.settings()).map_err(|e| e.to_string())?
        }
        (None, _) => crate::mechanics::two_stage::step_closing(
            &s.armature(),
            &s.two_stage(),
            &s.surface(),
            &s.settings(),
        )
        .map_err(|e| e.to_string())?
        .into_chatter(),
    };
    Ok(events_of(&chatter.intervals))
}

/// The datasheet figures of scenario `s` (which has a coil), computed as
/// a datasheet measures them; `None` for a figure the relay does not
/// show (it never closes, say, or its closing cannot be simulated: see
/// [`datasheet_figures_or_failure`]).
pub fn datasheet_figures(s: &Scenario, d: &DatasheetSection) -> Vec<(&'static str, Option<f64>)> {
    figures_and_failure(s, d).0
}

/// [`datasheet_figures`], or why the relay's closing on the datasheet's
/// DC step cannot be simulated (the engine's own words).
pub fn datasheet_figures_or_failure(
    s: &Scenario,
    d: &DatasheetSection,
) -> Result<Vec<(&'static str, Option<f64>)>, String> {
    match figures_and_failure(s, d) {
        (_, Some(failure)) => Err(failure),
        (figures, None) => Ok(figures),
    }
}

/// The figures, each `None` that the closing gives when it cannot be
/// simulated, and why it cannot.
type FiguresAndFailure = (Vec<(&'static str, Option<f64>)>, Option<String>);

fn figures_and_failure(s: &Scenario, d: &DatasheetSection) -> FiguresAndFailure {
    let Some(section) = &s.coil else {
        return (
            d.figures().into_iter().map(|(n, _)| (n, None)).collect(),
            None,
        );
    };
    let coil = Coil::from(section);
    let m = s.armature();
    let build = s.two_stage();
    let line = LoadLine::of_relay(&m, &build);
    let wants = |f: Option<PrintedFigure>| f.is_some();
    let closing = match d.coil_voltage {
        Some(v) if wants(d.operate_time) || wants(d.bounce_time) => direct_closing(
            &coil,
            &Source {
                voltage: v,
                series_resistance: 0.0,
            },
            &m,
            &build,
            &s.surface(),
            &s.settings(),
        )
        .map_err(|e| e.to_string())
        .map(|(chatter, _)| chatter),
        _ => Err(String::new()),
    };
    let failure = closing.as_ref().err().filter(|e| !e.is_empty()).cloned();
    let closing = closing.ok();
    let operate = closing.as_ref().and_then(|c| c.first_impact);
    let settle = closing.as_ref().and_then(|c| c.settle_time);
    let mut out = Vec::new();
    for (name, _) in d.figures() {
        let value = match name {
            "coil_resistance" => Some(coil.resistance),
            "pick_up_voltage" => Some(pick_up(&coil, &line).voltage),
            "drop_out_voltage" => Some(drop_out(&coil, &line).voltage),
            "operate_time" => operate,
            "bounce_time" => operate.zip(settle).map(|(a, b)| b - a),
            // Not modelled: a relay's release time is set by the decay of
            // its flux (eddy currents, the coil's own circuit), which the
            // single-gap magnet with an ideal switch does not have.
            "release_time" => None,
            _ => None,
        };
        out.push((name, value));
    }
    (out, failure)
}

/// The pick-up of scenario `s` over its whole load line, with that line;
/// `None` without a coil.
pub fn pick_up_of(s: &Scenario) -> Option<(PickUp, LoadLine)> {
    let coil = Coil::from(s.coil.as_ref()?);
    let line = LoadLine::of_relay(&s.armature(), &s.two_stage());
    Some((pick_up(&coil, &line), line))
}

/// The fitting problem: the prior scenario, the free keys in log form,
/// and the evidence.
struct Problem<'a> {
    base: &'a Scenario,
    keys: Vec<String>,
    prior: Vec<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
    measured: Option<Vec<Event>>,
    datasheet: Option<DatasheetSection>,
    voltage: Option<f64>,
    evaluations: std::cell::Cell<usize>,
}

/// What one evaluation produced, for the residuals and the report.
struct Evaluation {
    model: Vec<Event>,
    figures: Vec<(&'static str, Option<f64>)>,
}

impl Problem<'_> {
    fn scenario_at(&self, u: &[f64]) -> Option<Scenario> {
        let mut s = self.base.clone();
        let values: Vec<(&str, f64)> = self
            .keys
            .iter()
            .zip(u)
            .zip(&self.prior)
            // A key at its prior keeps the prior's exact bits.
            .map(|((k, &v), &p)| (k.as_str(), if v == p.ln() { p } else { v.exp() }))
            .collect();
        s.set_numbers(&values).ok()?;
        Some(s)
    }

    fn evaluate(&self, u: &[f64]) -> Option<Evaluation> {
        self.evaluations.set(self.evaluations.get() + 1);
        let s = self.scenario_at(u)?;
        let model = match &self.measured {
            Some(_) => model_events(&s, self.voltage).ok()?,
            None => Vec::new(),
        };
        let figures = match &self.datasheet {
            Some(d) => datasheet_figures(&s, d),
            None => Vec::new(),
        };
        Some(Evaluation { model, figures })
    }

    /// The events of a candidate: (measured, model).
    fn matched(&self, e: &Evaluation, c: Candidate) -> (Vec<Event>, Vec<Event>) {
        let measured = self.measured.clone().unwrap_or_default();
        match c {
            Candidate::All => (measured, e.model.clone()),
            Candidate::DropMeasured(j) => (drop_pair(&measured, j), e.model.clone()),
            Candidate::DropModel(j) => (measured, drop_pair(&e.model, j)),
        }
    }

    fn data_len(&self) -> usize {
        self.measured.as_ref().map_or(0, |m| m.len() + 1)
            + self.datasheet.as_ref().map_or(0, |d| d.figures().len())
    }

    /// The scaled data residuals (no prior rows); `None` when the
    /// scenario is invalid at `u`.
    fn data_residuals(&self, u: &[f64], c: Candidate) -> Option<Vec<f64>> {
        let e = self.evaluate(u)?;
        let mut r = Vec::with_capacity(self.data_len());
        if self.measured.is_some() {
            let (measured, model) = self.matched(&e, c);
            let (rows, _) = event_residuals(&measured, &model);
            r.extend(rows.iter().map(|x| x / TIME_SCALE));
            // A dropped pair shortens the measured list: pad so that every
            // candidate has the same length.
            r.resize(self.measured.as_ref().map_or(0, |m| m.len() + 1), 0.0);
        }
        if let Some(d) = &self.datasheet {
            for ((name, figure), (_, model)) in d.figures().iter().zip(&e.figures) {
                r.push(match model {
                    Some(m) => {
                        figure.misfit(coil_tolerance_corner(d, name, figure, *m)) / RELATIVE_SCALE
                    }
                    // Shown, not fitted (see `datasheet_figures`).
                    None if *name == "release_time" => 0.0,
                    None => 1.0 / RELATIVE_SCALE,
                });
            }
        }
        Some(r)
    }

    /// Data residuals then the prior rows of the active keys.
    fn residuals(&self, u: &[f64], active: &[usize], c: Candidate) -> Option<Vec<f64>> {
        let mut r = self.data_residuals(u, c)?;
        let prior = self.prior.iter().map(|p| p.ln());
        for (k, p) in prior.enumerate() {
            if active.contains(&k) {
                r.push(PRIOR_WEIGHT * (u[k] - p));
            }
        }
        Some(r)
    }

    fn clamp(&self, u: &mut [f64]) {
        for (k, x) in u.iter_mut().enumerate() {
            *x = x.clamp(self.low[k].ln(), self.high[k].ln());
        }
    }

    /// Central-difference Jacobian of `f` over the active keys.
    fn jacobian(
        &self,
        u: &[f64],
        active: &[usize],
        f: impl Fn(&[f64]) -> Option<Vec<f64>>,
        rows: usize,
    ) -> Option<DMatrix<f64>> {
        let mut j = DMatrix::zeros(rows, active.len());
        for (col, &k) in active.iter().enumerate() {
            let mut up = u.to_vec();
            let mut down = u.to_vec();
            up[k] += JACOBIAN_STEP;
            down[k] -= JACOBIAN_STEP;
            let (a, b) = (f(&up)?, f(&down)?);
            for row in 0..rows {
                j[(row, col)] = (a[row] - b[row]) / (2.0 * JACOBIAN_STEP);
            }
        }
        Some(j)
    }

    /// Levenberg–Marquardt from `u0` over the active keys; the best point
    /// and its cost (sum of squares, prior rows included).
    fn solve(&self, u0: &[f64], active: &[usize], c: Candidate) -> (Vec<f64>, f64) {
        let mut u = u0.to_vec();
        self.clamp(&mut u);
        let f = |x: &[f64]| self.residuals(x, active, c);
        let Some(mut r) = f(&u) else {
            return (u, f64::INFINITY);
        };
        let mut cost = r.iter().map(|x| x * x).sum::<f64>();
        if active.is_empty() {
            return (u, cost);
        }
        let mut lambda = 1e-3;
        for _ in 0..100 {
            let Some(j) = self.jacobian(&u, active, f, r.len()) else {
                break;
            };
            let jt = j.transpose();
            let a = &jt * &j;
            let g = &jt * DVector::from_vec(r.clone());
            let mut improved = false;
            while lambda < 1e12 {
                let mut damped = a.clone();
                for d in 0..active.len() {
                    damped[(d, d)] += lambda * (a[(d, d)] + 1e-12);
                }
                let Some(step) = damped.lu().solve(&(-&g)) else {
                    lambda *= 10.0;
                    continue;
                };
                let mut trial = u.clone();
                for (col, &k) in active.iter().enumerate() {
                    trial[k] += step[col];
                }
                self.clamp(&mut trial);
                match f(&trial) {
                    Some(rt) => {
                        let ct = rt.iter().map(|x| x * x).sum::<f64>();
                        if ct < cost {
                            let gain = cost - ct;
                            let moved = trial
                                .iter()
                                .zip(&u)
                                .map(|(a, b)| (a - b).abs())
                                .fold(0.0, f64::max);
                            u = trial;
                            r = rt;
                            cost = ct;
                            lambda = (lambda / 3.0).max(1e-12);
                            improved = gain > 1e-12 * cost.max(1e-30) && moved > 1e-10;
                            break;
                        }
                        lambda *= 4.0;
                    }
                    None => lambda *= 4.0,
                }
            }
            if !improved {
                break;
            }
        }
        (u, cost)
    }
}

/// Halton point `i` (from 1) in base `b`: a deterministic, even spread.
fn halton(mut i: usize, b: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= b as f64;
        r += f * (i % b) as f64;
        i /= b;
    }
    r
}

/// The event residuals (s) of `measured` against `model` matched in order,
/// and the time offset (s, model time of the record's zero). One residual
/// per measured event and one for the model's extra events.
fn event_residuals(measured: &[Event], model: &[Event]) -> (Vec<f64>, f64) {
    let n = measured.len();
    let k = n.min(model.len());
    let offset = if k > 0 {
        (0..k)
            .map(|i| model[i].time - measured[i].time)
            .sum::<f64>()
            / k as f64
    } else {
        0.0
    };
    let last = model.last().map_or(0.0, |e| e.time);
    let mut r = Vec::with_capacity(n + 1);
    for (i, e) in measured.iter().enumerate() {
        r.push(if i < k {
            let kind = if model[i].kind == e.kind {
                0.0
            } else {
                COUNT_PENALTY
            };
            model[i].time - offset - e.time + kind
        } else {
            (last - offset - e.time) - COUNT_PENALTY
        });
    }
    r.push(if model.len() > n && n > 0 {
        (last - model[n - 1].time) + COUNT_PENALTY * (model.len() - n) as f64
    } else {
        0.0
    });
    (r, offset)
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

/// The free keys with their priors and their bounds, in the key's unit.
struct FreeKeys {
    keys: Vec<String>,
    prior: Vec<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
}

/// What the fit is held against: the record's events, the datasheet (when
/// it gives a figure) and the coil voltage of both.
struct Evidence {
    measured: Option<Vec<Event>>,
    datasheet: Option<DatasheetSection>,
    voltage: Option<f64>,
}

/// The point a stage reached and the cost there (sum of squares, prior
/// rows included).
type Point = (Vec<f64>, f64);

/// The outcome of holding the keys the data cannot see: the refitted
/// point, which keys are held, and the data Jacobian once every direction
/// left is determined (`None` when that never happened).
struct Held {
    best: Point,
    held: Vec<bool>,
    jacobian: Option<DMatrix<f64>>,
}

impl<'a> Problem<'a> {
    /// The problem of fitting `scenario` as `request` asks; an error for a
    /// request that cannot start (no free key, no evidence, a prior that
    /// does not simulate).
    fn new(scenario: &'a Scenario, request: &FitRequest) -> Result<Problem<'a>, FitError> {
        let path = scenario.origin.display().to_string();
        let FreeKeys {
            keys,
            prior,
            low,
            high,
        } = free_keys(scenario, request, &path)?;
        let Evidence {
            measured,
            datasheet,
            voltage,
        } = evidence(scenario, request, &path)?;
        let problem = Problem {
            base: scenario,
            keys,
            prior,
            low,
            high,
            measured,
            datasheet,
            voltage,
            evaluations: std::cell::Cell::new(0),
        };
        let u_prior: Vec<f64> = problem.prior.iter().map(|p| p.ln()).collect();
        if problem.data_residuals(&u_prior, Candidate::All).is_none() {
            let message = match scenario.clone().set_numbers(&[]) {
                Err(e) => e.to_string(),
                Ok(()) => "its parameters are invalid".to_owned(),
            };
            return Err(FitError::Prior { path, message });
        }
        Ok(problem)
    }
}

/// The free keys (the request's, else the scenario's `[fit] free`), each
/// with its prior and its bounds (`[fit] bounds`, else a decade either
/// side of the prior), checked.
fn free_keys(scenario: &Scenario, request: &FitRequest, path: &str) -> Result<FreeKeys, FitError> {
    let section = scenario.fit.clone().unwrap_or_default();
    let keys = if request.free.is_empty() {
        section.free.clone()
    } else {
        request.free.clone()
    };
    if keys.is_empty() {
        return Err(FitError::NoFreeKeys);
    }
    let (mut prior, mut low, mut high) = (Vec::new(), Vec::new(), Vec::new());
    for key in &keys {
        let value = scenario
            .number(key)
            .map_err(|source| FitError::UnknownKey {
                path: path.to_owned(),
                key: key.clone(),
                source: Box::new(source),
            })?
            .ok_or_else(|| FitError::NoPrior {
                path: path.to_owned(),
                key: key.clone(),
            })?;
        if !(value > 0.0 && value.is_finite()) {
            return Err(FitError::NotPositive {
                path: path.to_owned(),
                key: key.clone(),
                value,
            });
        }
        let [lo, hi] = section
            .bounds
            .get(key)
            .copied()
            .unwrap_or([value / 10.0, value * 10.0]);
        if !(lo > 0.0 && lo <= value && value <= hi && hi.is_finite()) {
            return Err(FitError::Bounds {
                path: path.to_owned(),
                key: key.clone(),
                low: lo,
                high: hi,
                prior: value,
            });
        }
        prior.push(value);
        low.push(lo);
        high.push(hi);
    }
    Ok(FreeKeys {
        keys,
        prior,
        low,
        high,
    })
}

/// The evidence: the record's events and the datasheet's figures, checked
/// (positive figures, a coil for the figures, a coil voltage for the
/// times and for a coil-driven record, at least one of the two).
fn evidence(scenario: &Scenario, request: &FitRequest, path: &str) -> Result<Evidence, FitError> {
    let datasheet = scenario
        .datasheet
        .clone()
        .filter(|d| !d.figures().is_empty());
    if let Some(d) = &scenario.datasheet {
        let all = [("coil_voltage", d.coil_voltage)]
            .into_iter()
            .chain(d.figures().into_iter().map(|(n, f)| (n, Some(f.nominal()))));
        for (figure, v) in all {
            if let Some(value) = v
                && !(value > 0.0 && value.is_finite())
            {
                return Err(FitError::BadFigure {
                    path: path.to_owned(),
                    figure,
                    value,
                });
            }
        }
    }
    if let Some(d) = &datasheet {
        if scenario.coil.is_none() {
            return Err(FitError::NeedsCoil {
                path: path.to_owned(),
                figure: d.figures()[0].0,
            });
        }
        let timed = d.operate_time.is_some() || d.bounce_time.is_some();
        if timed && d.coil_voltage.is_none() {
            return Err(FitError::NeedsVoltage {
                path: path.to_owned(),
            });
        }
    }
    let voltage = scenario.datasheet.as_ref().and_then(|d| d.coil_voltage);
    let measured = match &request.record {
        Some(record) => {
            let events = events_of(&record.intervals);
            if events.is_empty() {
                return Err(FitError::EmptyRecord {
                    name: record.name.clone(),
                });
            }
            if scenario.coil.is_some() && voltage.is_none() {
                return Err(FitError::NeedsVoltage {
                    path: path.to_owned(),
                });
            }
            Some(events)
        }
        None => None,
    };
    if measured.is_none() && datasheet.is_none() {
        return Err(FitError::NoEvidence);
    }
    Ok(Evidence {
        measured,
        datasheet,
        voltage,
    })
}

/// The starts of the local solver: the closed-form start, then the best
/// points of a coarse survey of the log-bounds box.
fn survey(problem: &Problem, u_prior: &[f64], active: &[usize]) -> Vec<Vec<f64>> {
    // A coarse survey of the log-bounds box (a Halton sequence:
    // deterministic and even) finds the basin: with many bounces the
    // misfit has many local minima where the event count changes, and
    // a local solver started far off lands in one of them.
    const BASES: [usize; 8] = [2, 3, 5, 7, 11, 13, 17, 19];
    let n = problem.keys.len();
    let survey = SURVEY_PER_KEY * n;
    let mut sampled: Vec<(f64, Vec<f64>)> = (1..=survey)
        .map(|i| {
            let u: Vec<f64> = (0..n)
                .map(|k| {
                    let (lo, hi) = (problem.low[k].ln(), problem.high[k].ln());
                    lo + (hi - lo) * halton(i, BASES[k % BASES.len()])
                })
                .collect();
            let cost = problem
                .residuals(&u, active, Candidate::All)
                .map_or(f64::INFINITY, |r| r.iter().map(|x| x * x).sum());
            (cost, u)
        })
        .collect();
    sampled.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut starts = vec![closed_form_start(problem, u_prior)];
    starts.extend(sampled.into_iter().take(EXTRA_STARTS).map(|(_, u)| u));
    starts
}

/// The best point Levenberg–Marquardt reaches from any of `starts`, with
/// every event taking part.
fn refine(problem: &Problem, starts: &[Vec<f64>], u_prior: &[f64], active: &[usize]) -> Point {
    let mut best = (u_prior.to_vec(), f64::INFINITY);
    for start in starts {
        let (u, cost) = problem.solve(start, active, Candidate::All);
        if cost < best.1 {
            best = (u, cost);
        }
    }
    best
}

/// With a record: refit from `best` with each adjacent pair of measured,
/// or modelled, events dropped, and keep the drop that cuts the misfit
/// tenfold (saying so in `notes`); else `best` with every event.
fn set_aside_bad_edge(
    problem: &Problem,
    best: Point,
    active: &[usize],
    notes: &mut Vec<String>,
) -> (Candidate, Point) {
    let Some(measured) = &problem.measured else {
        return (Candidate::All, best);
    };
    let n_model = problem.evaluate(&best.0).map_or(0, |e| e.model.len());
    let mut alternatives = Vec::new();
    for j in 0..measured.len().saturating_sub(1) {
        alternatives.push(Candidate::DropMeasured(j));
    }
    for j in 0..n_model.saturating_sub(1) {
        alternatives.push(Candidate::DropModel(j));
    }
    let mut chosen = (Candidate::All, best.clone());
    for c in alternatives {
        let (u, cost) = problem.solve(&best.0, active, c);
        if cost < 0.1 * best.1 && cost < chosen.1.1 {
            chosen = (c, (u, cost));
        }
    }
    if chosen.0 != Candidate::All {
        notes.push(match chosen.0 {
            Candidate::DropMeasured(j) => format!(
                "set aside the measured {} at {:.6e} s and the {} after it as a spurious glitch",
                measured[j].kind.as_str(),
                measured[j].time,
                measured[j + 1].kind.as_str()
            ),
            _ => {
                "the model has one bounce the record lacks (a missed edge pair); matched without it"
                    .to_owned()
            }
        });
    }
    chosen
}

/// Hold the keys the data cannot see at their priors, one per
/// near-singular direction of JᵀJ, refitting the rest after each (and
/// saying so in `notes`); `active` loses the held keys.
fn hold_blind_keys(
    problem: &Problem,
    mut best: Point,
    candidate: Candidate,
    u_prior: &[f64],
    active: &mut Vec<usize>,
    notes: &mut Vec<String>,
) -> Held {
    let keys = &problem.keys;
    let data_rows = problem.data_len();
    let mut held = vec![false; keys.len()];
    let mut jacobian = None;
    for _ in 0..keys.len() {
        let f = |x: &[f64]| problem.data_residuals(x, candidate);
        let Some(j) = problem.jacobian(&best.0, active, f, data_rows) else {
            break;
        };
        let a = j.transpose() * &j;
        let eigen = SymmetricEigen::new(a);
        let max = eigen.eigenvalues.iter().cloned().fold(0.0, f64::max);
        let (imin, min) = eigen.eigenvalues.iter().cloned().enumerate().fold(
            (0, f64::INFINITY),
            |acc, (i, v)| if v < acc.1 { (i, v) } else { acc },
        );
        if max > 0.0 && min > SINGULAR_RATIO * max {
            jacobian = Some(j);
            break;
        }
        // The key with the largest share of the blind direction; on a tie
        // (a pure ratio) the later key in the free list.
        let v = eigen.eigenvectors.column(imin);
        let mut pick = 0;
        for i in 0..active.len() {
            if v[i].abs() >= v[pick].abs() - 1e-6 {
                pick = i;
            }
        }
        let k = active[pick];
        let partners: Vec<String> = active
            .iter()
            .enumerate()
            .filter(|&(i, _)| i != pick && v[i].abs() > 0.1)
            .map(|(_, &a)| format!("`{}`", keys[a]))
            .collect();
        held[k] = true;
        active.retain(|&a| a != k);
        best.0[k] = u_prior[k];
        notes.push(format!(
            "`{}` is not determined by the evidence (it moves only together with {}); held at its prior {}",
            keys[k],
            if partners.is_empty() { "nothing: the evidence does not depend on it".to_owned() } else { partners.join(", ") },
            problem.prior[k]
        ));
        best = problem.solve(&best.0, active, candidate);
        if active.is_empty() {
            break;
        }
    }
    Held {
        best,
        held,
        jacobian,
    }
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
