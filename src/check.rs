//! Design checks: a scenario's limits held against what the relay and the
//! circuit did (`chatterspice check`, and a library call for a user's own
//! `cargo test`).
//!
//! Limits come from `[limits]` (the relay: bounces, bounce time, first make,
//! operate time) and from each `[[probe]]` (edges, glitches, peak, value
//! range, the time of the last edge). Every limit becomes one
//! [`LimitCheck`] with its margin, the room left before it fails: limit −
//! actual for an upper limit, actual − limit for a lower one, so a
//! negative margin is by how much it failed. A quantity that does not
//! exist (a relay that never settles has no settle time) fails its limit
//! with no margin.
//!
//! ```no_run
//! use chatterspice::{check, scenario::Scenario, spice::Ngspice};
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let scenario = Scenario::load("relay.toml".as_ref())?;
//! let verdict = check::run(&scenario, &Ngspice::find()?)?;
//! assert!(verdict.passed, "{verdict}");
//! # Ok(())
//! # }
//! ```

use std::fmt;
use std::path::PathBuf;

use serde::Serialize;
use thiserror::Error;

use crate::analysis::{Debounce, ProbeAnalysis};
use crate::arc::ArcReport;
use crate::chatter::{Chatter, Impact, Interval};
use crate::coil::{Closing, Operation};
use crate::mechanics::{MechanicsError, simulate};
use crate::pipeline::{self, RunError, RunOptions, RunResult};
use crate::report::units::engineering;
use crate::scenario::{LimitsSection, Probe, Scenario, ScenarioError};
use crate::spice::Runner;

/// Which side a limit bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Bound {
    /// The quantity must not exceed the limit.
    Max,
    /// The quantity must not fall below the limit.
    Min,
}

/// One limit against its quantity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LimitCheck {
    /// The scenario key that set the limit, e.g. `limits.max_bounces` or
    /// `probe[0].max_edges`.
    pub key: String,
    /// What was measured, e.g. `bounces` or `v(in) edges`.
    pub quantity: String,
    /// SI unit symbol of `limit`, `actual` and `margin`; empty for counts.
    pub unit: &'static str,
    /// Whether `limit` is a maximum or a minimum.
    pub bound: Bound,
    /// The limit from the scenario, in `unit`.
    pub limit: f64,
    /// `None` when the quantity does not exist (the check then fails).
    pub actual: Option<f64>,
    /// Whether the limit held: `actual` exists and the margin is ≥ 0.
    pub passed: bool,
    /// Room left before the limit (negative: by how much it failed).
    pub margin: Option<f64>,
    /// Why `actual` is absent, when it is.
    pub note: Option<String>,
}

impl LimitCheck {
    /// A check of `actual` (or why it could not be measured) against `limit`.
    pub fn new(
        key: String,
        quantity: String,
        unit: &'static str,
        bound: Bound,
        limit: f64,
        actual: Result<f64, String>,
    ) -> LimitCheck {
        let (actual, note) = match actual {
            Ok(v) => (Some(v), None),
            Err(why) => (None, Some(why)),
        };
        let margin = actual.map(|a| match bound {
            Bound::Max => limit - a,
            Bound::Min => a - limit,
        });
        LimitCheck {
            key,
            quantity,
            unit,
            bound,
            limit,
            actual,
            passed: margin.is_some_and(|m| m >= 0.0),
            margin,
            note,
        }
    }

    /// A count held to at most `limit`, with a note: how an envelope says
    /// that some of its relays were not evaluated.
    pub(crate) fn count_at_most(
        key: String,
        quantity: String,
        limit: usize,
        actual: usize,
        note: String,
    ) -> LimitCheck {
        let mut check = LimitCheck::new(
            key,
            quantity,
            "",
            Bound::Max,
            limit as f64,
            Ok(actual as f64),
        );
        check.note = Some(note);
        check
    }
}

/// Every limit of a scenario, checked.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    /// All limits held.
    pub passed: bool,
    /// Number of limits that failed.
    pub failed: usize,
    /// In scenario order: `[limits]` first, then each probe's.
    pub checks: Vec<LimitCheck>,
}

impl Verdict {
    /// The verdict of `checks`: passed when none failed.
    pub fn new(checks: Vec<LimitCheck>) -> Verdict {
        let failed = checks.iter().filter(|c| !c.passed).count();
        Verdict {
            passed: failed == 0,
            failed,
            checks,
        }
    }

    /// The checks that failed.
    pub fn failures(&self) -> impl Iterator<Item = &LimitCheck> {
        self.checks.iter().filter(|c| !c.passed)
    }
}

impl fmt::Display for Verdict {
    /// One line per limit: `PASS`/`FAIL`, key, actual against limit, and
    /// the margin.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}: {} of {} limits failed",
            if self.passed { "PASS" } else { "FAIL" },
            self.failed,
            self.checks.len()
        )?;
        for c in &self.checks {
            writeln!(
                f,
                "  {} {}: {} {} {}{}",
                if c.passed { "pass" } else { "FAIL" },
                c.key,
                c.actual
                    .map_or_else(|| "-".to_owned(), |a| quantity(a, c.unit)),
                match c.bound {
                    Bound::Max => "<=",
                    Bound::Min => ">=",
                },
                quantity(c.limit, c.unit),
                match (&c.margin, &c.note) {
                    (Some(m), _) => format!(" (margin {})", quantity(*m, c.unit)),
                    (None, Some(note)) => format!(" ({note})"),
                    (None, None) => String::new(),
                }
            )?;
        }
        Ok(())
    }
}

/// A count as an integer, anything else in engineering notation.
pub fn quantity(value: f64, unit: &str) -> String {
    if unit.is_empty() && value.fract() == 0.0 && value.abs() < 1e15 {
        format!("{value:.0}")
    } else {
        engineering(value, unit)
    }
}

/// Why a check could not be made (as opposed to failing).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CheckError {
    /// Nothing to check: the scenario has no `[limits]` and no probe with
    /// a limit. Not returned by this version's checks, which report the
    /// figures and pass when there is nothing to hold; kept for callers
    /// that match on it.
    #[error(
        "{}: nothing to check: add a [limits] section (max_bounce_time, max_bounces, \
         max_operate_time, max_settle_time, max_lockout, max_stable_for; with a coil max_release_time, \
         max_nc_bounce_time, max_nc_bounces; with [arc] max_arc_energy, max_arc_count) or limits on a [[probe]] (max_edges, \
         max_glitches, max_peak, max_value, min_value, max_last_edge, max_lockout, max_stable_for)",
        path.display()
    )]
    NoLimits {
        /// The scenario file.
        path: PathBuf,
    },
    /// The scenario cannot be simulated as asked (e.g. the mechanics
    /// alone of a coil-driven relay).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The two-stage relay, or a coil on its DC step, could not be
    /// simulated.
    #[error("{}: the mechanics simulation failed", path.display())]
    Motion {
        /// The scenario file.
        path: PathBuf,
        /// Why.
        #[source]
        source: crate::mechanics::DriveError,
    },
    /// A coil-driven relay without its driver circuit needs the voltage
    /// of its DC step.
    #[error(
        "{}: a coil-driven relay without its driver circuit is checked on an ideal DC step \
         of its coil voltage: give `coil.drive_voltage` (V) or `datasheet.coil_voltage`",
        path.display()
    )]
    NoDriveVoltage {
        /// The scenario file.
        path: PathBuf,
    },
    /// The mechanics simulation failed.
    #[error("{}: the mechanics simulation failed", path.display())]
    Mechanics {
        /// The scenario file.
        path: PathBuf,
        /// Why it failed.
        #[source]
        source: MechanicsError,
    },
    /// The run through the circuit simulator failed.
    #[error(transparent)]
    Run(#[from] Box<RunError>),
}

/// The relay's limits against a chatter sequence and, for a coil-driven
/// relay, its operations (the release limits hold for every one).
pub fn relay_checks(
    limits: &LimitsSection,
    chatter: &Chatter,
    operations: &[Operation],
) -> Vec<LimitCheck> {
    let never = |what: &str| format!("the contact {what} ({})", chatter.outcome);
    let first = chatter.first_impact.ok_or_else(|| never("never touches"));
    // Closing times from each operation's own t = 0 (coil on, or the
    // force step), the longest of all operations. A re-closure with the
    // coil off has no energisation to time an operate or settle time
    // from; its bounces count like any closing's.
    let closings = Closing::all(chatter, operations);
    let numbered = |k: usize, what: &str| {
        if operations.len() > 1 {
            format!("operation {}: the contact {what}", k + 1)
        } else {
            never(what)
        }
    };
    let longest = |get: fn(&Closing) -> Option<f64>, what: &str, reclosures: bool| {
        closings
            .iter()
            .enumerate()
            .filter(|(k, _)| reclosures || !operations.get(*k).is_some_and(Operation::is_reclosure))
            .map(|(k, c)| get(c).ok_or_else(|| numbered(k, what)))
            .reduce(larger_or_why)
            .unwrap_or_else(|| Err(never(what)))
    };
    let debounce = |get: fn(&Debounce) -> f64| {
        closings
            .iter()
            .map(|c| {
                contact_debounce(chatter, c)
                    .map(|d| get(&d))
                    .ok_or_else(|| never("never closes for good"))
            })
            .reduce(larger_or_why)
            .unwrap_or_else(|| Err(never("never closes for good")))
    };
    let operate = longest(|c| c.operate_time, "never touches", false);
    let settle = longest(|c| c.settle_time, "never closes for good", false);
    let bounce_time = longest(|c| c.bounce_time, "never closes for good", true);
    // Bounces: the most of any operation's closing (re-closures included).
    let bounces = if operations.is_empty() {
        first.clone().map(|_| chatter.bounce_count as f64)
    } else {
        operations
            .iter()
            .enumerate()
            .map(|(k, op)| {
                op.stroke
                    .first_make
                    .map(|_| op.stroke.bounces as f64)
                    .ok_or_else(|| numbered(k, "never touches"))
            })
            .reduce(larger_or_why)
            .unwrap_or_else(|| Err(never("never touches")))
    };
    let nc_bounces = |op: &Operation| op.nc_bounce_time.map(|_| op.stroke.back_bounces as f64);
    let rows = [
        (
            limits.max_bounces.map(|l| l as f64),
            "max_bounces",
            "bounces",
            "",
            bounces,
        ),
        (
            limits.max_bounce_time,
            "max_bounce_time",
            "bounce time",
            "s",
            bounce_time,
        ),
        (
            limits.max_operate_time,
            "max_operate_time",
            "operate time",
            "s",
            operate.clone(),
        ),
        (
            limits.max_first_make,
            "max_first_make",
            "first make",
            "s",
            operate,
        ),
        (
            limits.max_lockout,
            "max_lockout",
            "contact lockout",
            "s",
            debounce(|d| d.lockout),
        ),
        (
            limits.max_stable_for,
            "max_stable_for",
            "contact stable for",
            "s",
            debounce(|d| d.stable_for),
        ),
        (
            limits.max_settle_time,
            "max_settle_time",
            "closed for good",
            "s",
            settle,
        ),
        (
            limits.max_release_time,
            "max_release_time",
            "release time",
            "s",
            worst_release(operations, "release", |op| op.release_time),
        ),
        (
            limits.max_nc_bounce_time,
            "max_nc_bounce_time",
            "NC bounce time",
            "s",
            worst_release(operations, "NC bounce", |op| op.nc_bounce_time),
        ),
        (
            limits.max_nc_bounces.map(|l| l as f64),
            "max_nc_bounces",
            "NC bounces",
            "",
            worst_release(operations, "NC bounce", nc_bounces),
        ),
    ];
    rows.into_iter()
        .filter_map(|(limit, key, label, unit, value)| {
            let limit = limit?;
            Some(LimitCheck::new(
                format!("limits.{key}"),
                label.into(),
                unit,
                Bound::Max,
                limit,
                value,
            ))
        })
        .collect()
}

/// The larger of two figures, or the first reason one of them has none.
fn larger_or_why(a: Result<f64, String>, b: Result<f64, String>) -> Result<f64, String> {
    match (a, b) {
        (Ok(a), Ok(b)) => Ok(a.max(b)),
        (Err(e), _) | (_, Err(e)) => Err(e),
    }
}

/// The largest of `get` over the operations, for a limit on what happens
/// at or after a release (`what`: "release", "NC bounce"); why not when
/// no operation has one.
fn worst_release(
    operations: &[Operation],
    what: &str,
    get: impl Fn(&Operation) -> Option<f64>,
) -> Result<f64, String> {
    release_unevaluated(operations, what)?;
    let values: Vec<f64> = operations.iter().filter_map(get).collect();
    if values.is_empty() {
        let why = if what == "release" {
            "the contact never broke after the coil went off"
        } else {
            "the armature is not back on its rest stop before the run ends"
        };
        Err(format!(
            "not evaluated: no {what} in the run ({why}; raise `simulation.t_end` and the \
             `.tran` stop time)"
        ))
    } else {
        Ok(values.into_iter().fold(f64::NEG_INFINITY, f64::max))
    }
}

/// Why a limit on the releases cannot be held yet: the coil is never
/// switched off within the run, or an operation's coil goes off and the
/// run ends before its contact breaks (a part's `simulation.t_end` shorter
/// than the driver's on-time). Such a limit fails as not evaluated; it
/// never passes on a release that was not simulated.
fn release_unevaluated(operations: &[Operation], what: &str) -> Result<(), String> {
    if !operations.iter().any(|op| op.coil_off.is_some()) {
        return Err(format!(
            "not evaluated: the coil is never switched off within the run, so there is no \
             {what} to hold; switch it off in the driver before `simulation.t_end` and the \
             `.tran` stop time"
        ));
    }
    if let Some(op) = operations
        .iter()
        .find(|op| op.coil_off.is_some() && op.release_time.is_none())
    {
        return Err(format!(
            "not evaluated: the coil goes off at {} but the run ends before the contact \
             breaks; raise `simulation.t_end` (and the `.tran` stop time) past the release",
            crate::report::units::engineering(op.coil_off.unwrap_or_default(), "s")
        ));
    }
    Ok(())
}

/// Probe `index`'s limits against its analysis.
pub fn probe_checks(index: usize, probe: &Probe, a: &ProbeAnalysis) -> Vec<LimitCheck> {
    let key = |name: &str| format!("probe[{index}].{name}");
    let what = |q: &str| format!("{} {q}", probe.signal);
    let unit = a.kind.unit();
    let mut out = Vec::new();
    if let Some(limit) = probe.max_edges {
        out.push(LimitCheck::new(
            key("max_edges"),
            what("edges"),
            "",
            Bound::Max,
            limit as f64,
            Ok(a.edges as f64),
        ));
    }
    if let Some(limit) = probe.max_glitches {
        out.push(LimitCheck::new(
            key("max_glitches"),
            what("glitches"),
            "",
            Bound::Max,
            limit as f64,
            Ok(a.glitches as f64),
        ));
    }
    let (lo, hi) = a.range_for_limits(probe.ignore_ringing);
    if let Some(limit) = probe.max_peak {
        out.push(LimitCheck::new(
            key("max_peak"),
            what("peak |value|"),
            unit,
            Bound::Max,
            limit,
            Ok(hi.abs().max(lo.abs())),
        ));
    }
    if let Some(limit) = probe.max_value {
        out.push(LimitCheck::new(
            key("max_value"),
            what("maximum"),
            unit,
            Bound::Max,
            limit,
            Ok(hi),
        ));
    }
    if let Some(limit) = probe.min_value {
        out.push(LimitCheck::new(
            key("min_value"),
            what("minimum"),
            unit,
            Bound::Min,
            limit,
            Ok(lo),
        ));
    }
    if let Some(limit) = probe.max_last_edge {
        out.push(LimitCheck::new(
            key("max_last_edge"),
            what("last edge"),
            "s",
            Bound::Max,
            limit,
            a.last_edge
                .ok_or_else(|| "the signal never crosses its thresholds".to_owned()),
        ));
    }
    let debounce = |get: fn(&Debounce) -> f64| {
        a.debounce
            .as_ref()
            .map(get)
            .ok_or_else(|| "the signal never crosses its thresholds".to_owned())
    };
    if let Some(limit) = probe.max_lockout {
        out.push(LimitCheck::new(
            key("max_lockout"),
            what("lockout"),
            "s",
            Bound::Max,
            limit,
            debounce(|d| d.lockout),
        ));
    }
    if let Some(limit) = probe.max_stable_for {
        out.push(LimitCheck::new(
            key("max_stable_for"),
            what("stable for"),
            "s",
            Bound::Max,
            limit,
            debounce(|d| d.stable_for),
        ));
    }
    out
}

/// The contact's own debounce figures in `closing`: its transitions (every
/// make and break) from the first make to closed for good; `None` when the
/// closing never settles.
pub fn contact_debounce(chatter: &Chatter, closing: &Closing) -> Option<Debounce> {
    let first = closing.origin + closing.operate_time?;
    let settle = closing.origin + closing.settle_time?;
    let inside = |t: f64| t >= first - 1e-15 && t <= settle + 1e-15;
    let mut times: Vec<f64> = chatter
        .impacts
        .iter()
        .flat_map(|i| std::iter::once(i.impact_time).chain(i.release_time))
        .filter(|&t| inside(t))
        .collect();
    times.sort_by(f64::total_cmp);
    Debounce::of(&times)
}

/// Every limit of `scenario` against a finished run.
pub fn evaluate(scenario: &Scenario, run: &RunResult) -> Verdict {
    let mut checks = scenario
        .limits
        .as_ref()
        .map(|l| relay_checks(l, &run.chatter, &run.operations))
        .unwrap_or_default();
    if let Some(limits) = &scenario.limits {
        checks.extend(arc_checks(limits, run.arcs.as_ref(), &run.operations));
    }
    checks.extend(making_checks(scenario, &run.makes));
    for (i, (probe, result)) in scenario.probes.iter().zip(&run.probes).enumerate() {
        checks.extend(probe_checks(i, probe, &result.analysis));
    }
    Verdict::new(checks)
}

/// `max_arc_energy` and `max_arc_count` against the worst operation of
/// the run's arcs. A break the run did not reach (the coil goes off but
/// the run ends before the contact breaks) has an arc that was never
/// simulated: the limits then fail as not evaluated.
pub fn arc_checks(
    limits: &LimitsSection,
    arcs: Option<&ArcReport>,
    operations: &[Operation],
) -> Vec<LimitCheck> {
    let unreached = operations
        .iter()
        .find(|op| op.coil_off.is_some() && op.release_time.is_none())
        .and_then(|op| op.coil_off);
    let missing = || match unreached {
        Some(off) => format!(
            "not evaluated: the coil goes off at {off} s but the run ends before the contact \
             breaks, so that break's arc was never simulated; raise `simulation.t_end` (and \
             the `.tran` stop time)"
        ),
        None => "the run has no arc report: add an [arc] section".to_owned(),
    };
    // An arc still burning at the end: every figure of the run is a
    // lower bound, so no arc limit can pass.
    let burning = arcs.and_then(|a| a.totals.still_burning.as_ref());
    let missing = || match burning {
        Some(b) => format!(
            "the arc at {} still burns when the run ends, after {} and {}: the contact \
             does not break this load within the run (extend the `.tran` stop time to see \
             whether it ever does)",
            b.opening,
            crate::report::units::engineering(b.duration, "s"),
            crate::report::units::engineering(b.energy, "J")
        ),
        None => missing(),
    };
    let arcs = arcs.filter(|a| unreached.is_none() && a.totals.still_burning.is_none());
    let mut out = Vec::new();
    if let Some(limit) = limits.max_arc_energy {
        out.push(LimitCheck::new(
            "limits.max_arc_energy".into(),
            "arc energy in one operation".into(),
            "J",
            Bound::Max,
            limit,
            arcs.map(|a| a.totals.max_operation_energy)
                .ok_or_else(missing),
        ));
    }
    if let Some(limit) = limits.max_arc_count {
        out.push(LimitCheck::new(
            "limits.max_arc_count".into(),
            "arcs in one operation".into(),
            "",
            Bound::Max,
            limit as f64,
            arcs.map(|a| a.totals.max_operation_count as f64)
                .ok_or_else(missing),
        ));
    }
    if let Some(limit) = limits.max_arc_duration {
        out.push(LimitCheck::new(
            "limits.max_arc_duration".into(),
            "longest arc".into(),
            "s",
            Bound::Max,
            limit,
            arcs.map(|a| a.totals.longest).ok_or_else(missing),
        ));
    }
    out
}

/// `max_making_current`, `min_weld_margin` and the datasheet's
/// `making_current` against the run's worst make.
pub fn making_checks(scenario: &Scenario, makes: &[crate::arc::making::Make]) -> Vec<LimitCheck> {
    let worst_current = makes
        .iter()
        .map(|m| m.peak_current)
        .fold(None, |w: Option<f64>, c| Some(w.map_or(c, |w| w.max(c))));
    let no_make = || "the contact never closed in the run: no make to measure".to_owned();
    let mut out = Vec::new();
    let limits = scenario.limits.unwrap_or_default();
    let printed = scenario
        .datasheet
        .as_ref()
        .and_then(|d| d.making_current)
        .and_then(|f| f.max.or(f.typ));
    for (key, limit) in [
        ("limits.max_making_current", limits.max_making_current),
        ("datasheet.making_current", printed),
    ] {
        if let Some(limit) = limit {
            out.push(LimitCheck::new(
                key.into(),
                "peak current of the worst make".into(),
                "A",
                Bound::Max,
                limit,
                worst_current.ok_or_else(no_make),
            ));
        }
    }
    if let Some(limit) = limits.min_weld_margin {
        let worst = makes
            .iter()
            .filter_map(|m| m.weld_margin)
            .fold(None, |w: Option<f64>, m| Some(w.map_or(m, |w| w.min(m))));
        out.push(LimitCheck::new(
            "limits.min_weld_margin".into(),
            "weld margin U_m/U of the worst make".into(),
            "",
            Bound::Min,
            limit,
            worst.ok_or_else(|| {
                if makes.is_empty() {
                    no_make()
                } else {
                    "not evaluated: the run has no contact force at its makes (a measured \
                     record has none, nor a rigid contact closed on its coil's DC step)"
                        .to_owned()
                }
            }),
        ));
    }
    out
}

/// What [`run`] did to reach its verdict.
#[derive(Debug, Clone, PartialEq)]
pub enum Evidence {
    /// Only the mechanics: no probe has a limit. The armature's impacts on
    /// the pole face, for a relay that has one.
    Mechanics(Chatter, Option<Vec<Impact>>),
    /// The whole pipeline through ngspice.
    Run(Box<RunResult>),
}

impl Evidence {
    /// The chatter sequence the verdict was reached on.
    pub fn chatter(&self) -> &Chatter {
        match self {
            Evidence::Mechanics(c, _) => c,
            Evidence::Run(r) => &r.chatter,
        }
    }

    /// The operations of a coil-driven relay's run; none otherwise.
    pub fn operations(&self) -> &[Operation] {
        match self {
            Evidence::Mechanics(..) => &[],
            Evidence::Run(r) => &r.operations,
        }
    }
}

/// Check `scenario`: the mechanics alone when only `[limits]` are set,
/// the whole `run` through `runner` when a probe has a limit or the relay
/// is coil-driven.
pub fn run(scenario: &Scenario, runner: &dyn Runner) -> Result<Verdict, CheckError> {
    run_with(scenario, runner, &RunOptions::default()).map(|(verdict, _)| verdict)
}

/// [`run`] with run options, returning the evidence too.
pub fn run_with(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &RunOptions,
) -> Result<(Verdict, Evidence), CheckError> {
    let probe_limits = needs_circuit(scenario);
    // A coil-driven relay moves in its driver circuit when it has one;
    // without one, on the ideal DC step of its coil voltage.
    if probe_limits || (scenario.coil.is_some() && scenario.circuit.is_some()) {
        let result = pipeline::run(scenario, runner, options).map_err(Box::new)?;
        return Ok((evaluate(scenario, &result), Evidence::Run(Box::new(result))));
    }
    relay_only(scenario)
}

/// Whether a limit needs the circuit run: a probe's limits, the arc
/// limits, or the making limits (a printed making current with a
/// circuit to make it in).
pub fn needs_circuit(scenario: &Scenario) -> bool {
    let circuit_limits = scenario
        .limits
        .as_ref()
        .is_some_and(|l| l.has_arc_limits() || l.has_making_limits());
    let printed_making = scenario.circuit.is_some()
        && scenario
            .datasheet
            .as_ref()
            .is_some_and(|d| d.making_current.is_some());
    scenario.probes.iter().any(Probe::has_limits) || circuit_limits || printed_making
}

/// Check `scenario` against a measured chatter sequence (a scope record)
/// instead of its mechanics: the `[limits]` on the record alone, and, when
/// a probe has a limit and a `runner` is given, the record switching the
/// circuit through it (without a runner the probe limits are not looked at).
pub fn measured(
    scenario: &Scenario,
    intervals: Vec<Interval>,
    runner: Option<&dyn Runner>,
    options: &RunOptions,
) -> Result<(Verdict, Evidence), CheckError> {
    let probe_limits = needs_circuit(scenario);
    if let (true, Some(runner)) = (probe_limits, runner) {
        let result =
            pipeline::run_measured(scenario, intervals, runner, options).map_err(Box::new)?;
        return Ok((evaluate(scenario, &result), Evidence::Run(Box::new(result))));
    }
    let chatter = Chatter::from_intervals(intervals);
    let checks = scenario
        .limits
        .as_ref()
        .map(|l| relay_checks(l, &chatter, &[]))
        .unwrap_or_default();
    Ok((Verdict::new(checks), Evidence::Mechanics(chatter, None)))
}

/// The `[limits]` of `scenario` on the mechanics alone, without ngspice;
/// probe limits are not looked at (use [`run_with`] for those).
///
/// ```
/// use chatterspice::check::relay_only;
/// use chatterspice::scenario::{LimitsSection, Scenario};
///
/// // The built-in relay bounces 5 times: a limit of 4 fails, 5 holds.
/// let mut scenario = Scenario::builtin_default();
/// for (max, holds) in [(4, false), (5, true)] {
///     scenario.limits = Some(LimitsSection { max_bounces: Some(max), ..Default::default() });
///     let (verdict, _) = relay_only(&scenario)?;
///     assert_eq!(verdict.passed, holds);
/// }
/// # Ok::<(), chatterspice::check::CheckError>(())
/// ```
pub fn relay_only(scenario: &Scenario) -> Result<(Verdict, Evidence), CheckError> {
    let (chatter, pole_face) = relay_closing(scenario)?;
    let checks = scenario
        .limits
        .as_ref()
        .map(|l| relay_checks(l, &chatter, &[]))
        .unwrap_or_default();
    Ok((
        Verdict::new(checks),
        Evidence::Mechanics(chatter, pole_face),
    ))
}

/// The relay's own closing, as built, without a circuit: the step force
/// (the exact one-mass engine, or the two-stage one), or for a coil-driven
/// relay the ideal DC step of `coil.drive_voltage` (else
/// `datasheet.coil_voltage`) on its coil, as a datasheet measures; with
/// the armature's impacts on the pole face, for a relay that has one.
pub fn relay_closing(scenario: &Scenario) -> Result<(Chatter, Option<Vec<Impact>>), CheckError> {
    let path = || scenario.origin.clone();
    let build = scenario.two_stage();
    let with_pole = build.pole_face.is_some();
    if scenario.coil.is_some() {
        let (chatter, run) = dc_step(scenario)?;
        let pole = with_pole.then(|| run.map(|r| r.pole_face).unwrap_or_default());
        return Ok((chatter, pole));
    }
    let mechanics = scenario.mechanics()?;
    if build.is_one_mass() {
        return simulate(&mechanics, &scenario.surface(), &scenario.settings())
            .map(|chatter| (chatter, None))
            .map_err(|source| CheckError::Mechanics {
                path: path(),
                source,
            });
    }
    let trajectory = crate::mechanics::two_stage::step_closing(
        &mechanics,
        &build,
        &scenario.surface(),
        &scenario.settings(),
    )
    .map_err(|source| CheckError::Motion {
        path: path(),
        source,
    })?;
    let pole = with_pole.then(|| trajectory.pole_face_impacts().to_vec());
    Ok((trajectory.into_chatter(), pole))
}

/// [`relay_closing`]'s chatter alone.
pub fn relay_chatter(scenario: &Scenario) -> Result<Chatter, CheckError> {
    relay_closing(scenario).map(|(chatter, _)| chatter)
}

/// A coil-driven relay without its driver circuit: the ideal DC step of
/// `coil.drive_voltage` (else `datasheet.coil_voltage`) on its coil from
/// t = 0, as a datasheet measures. The closing's chatter, and the
/// two-stage record when the relay has a blade (or releases by force).
pub fn dc_step(
    scenario: &Scenario,
) -> Result<(Chatter, Option<crate::mechanics::two_stage::TwoStageRun>), CheckError> {
    let path = || scenario.origin.clone();
    let (coil, source) = scenario
        .dc_step()
        .ok_or_else(|| CheckError::NoDriveVoltage { path: path() })?;
    crate::coil::direct::direct_closing(
        &coil,
        &source,
        &scenario.armature(),
        &scenario.two_stage(),
        &scenario.surface(),
        &scenario.settings(),
    )
    .map_err(|source| CheckError::Motion {
        path: path(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixtures;

    #[test]
    fn margins_are_room_left_and_negative_when_failed() {
        let chatter = fixtures::stuck(); // 2 bounces, 0.4 ms bounce time
        let limits = LimitsSection {
            max_bounces: Some(1),
            max_bounce_time: Some(1e-3),
            max_operate_time: Some(1e-3),
            max_settle_time: Some(1e-3),
            ..LimitsSection::default()
        };
        let checks = relay_checks(&limits, &chatter, &[]);
        let by_key = |k: &str| checks.iter().find(|c| c.key == k).unwrap();
        let bounces = by_key("limits.max_bounces");
        assert!(!bounces.passed);
        assert_eq!(bounces.margin, Some(1.0 - chatter.bounce_count as f64));
        let time = by_key("limits.max_bounce_time");
        let bt = chatter.settle_time.unwrap() - chatter.first_impact.unwrap();
        assert!(time.passed);
        assert_eq!(time.margin, Some(1e-3 - bt));
        let operate = by_key("limits.max_operate_time");
        assert_eq!(operate.margin, Some(1e-3 - chatter.first_impact.unwrap()));
        let settle = by_key("limits.max_settle_time");
        assert_eq!(settle.margin, Some(1e-3 - chatter.settle_time.unwrap()));
        let v = Verdict::new(checks.clone());
        assert!(!v.passed);
        assert_eq!(v.failed, checks.iter().filter(|c| !c.passed).count());
        assert!(v.to_string().contains("FAIL limits.max_bounces"), "{v}");
    }

    #[test]
    fn release_limits_hold_for_the_worst_operation() {
        use crate::coil::{Stroke, Switching, operations};
        let stroke = |lift_off: f64, nc_bounces: usize| Stroke {
            lift_off,
            first_make: Some(lift_off + 2e-3),
            last_make: Some(lift_off + 3e-3),
            bounces: 2,
            break_time: Some(lift_off + 12e-3),
            back_make: Some(lift_off + 13e-3),
            back_last_make: Some(lift_off + 13e-3 + 0.5e-3 * nc_bounces as f64),
            back_bounces: nc_bounces,
        };
        // Two operations: released 2 ms and 4 ms after the coil went off.
        let switching = Switching {
            on: vec![0.0, 20e-3],
            off: vec![10e-3, 28e-3],
        };
        let ops = operations(&[stroke(1e-3, 2), stroke(21e-3, 4)], &[], &switching);
        let limits = LimitsSection {
            max_release_time: Some(3e-3),
            max_nc_bounce_time: Some(3e-3),
            max_nc_bounces: Some(4),
            ..LimitsSection::default()
        };
        let checks = relay_checks(&limits, &fixtures::stuck(), &ops);
        let by_key = |k: &str| checks.iter().find(|c| c.key == k).unwrap();
        let release = by_key("limits.max_release_time");
        assert!(!release.passed);
        assert!(
            (release.actual.unwrap() - 5e-3).abs() < 1e-12,
            "{release:?}"
        );
        let nc = by_key("limits.max_nc_bounce_time");
        assert!(
            nc.passed && (nc.actual.unwrap() - 2e-3).abs() < 1e-12,
            "{nc:?}"
        );
        assert_eq!(by_key("limits.max_nc_bounces").actual, Some(4.0));
        // No release within the run: the limit fails and says why.
        let held = relay_checks(&limits, &fixtures::stuck(), &[]);
        assert!(
            held.iter().all(|c| !c.passed && c.note.is_some()),
            "{held:?}"
        );
        assert!(held[0].note.as_deref().unwrap().contains("switched off"));
    }

    #[test]
    fn a_relay_that_never_closes_fails_every_relay_limit_with_a_reason() {
        let chatter = fixtures::never_closes();
        let limits = LimitsSection {
            max_bounces: Some(10),
            max_bounce_time: Some(1.0),
            max_operate_time: Some(1.0),
            max_first_make: Some(1.0),
            ..LimitsSection::default()
        };
        let checks = relay_checks(&limits, &chatter, &[]);
        assert_eq!(checks.len(), 4);
        for c in &checks {
            assert!(!c.passed, "{c:?}");
            assert!(c.margin.is_none());
            assert!(c.note.as_deref().unwrap().contains("never"), "{c:?}");
        }
    }

    #[test]
    fn a_limit_met_exactly_passes_with_zero_margin() {
        let c = LimitCheck::new("k".into(), "q".into(), "", Bound::Max, 3.0, Ok(3.0));
        assert!(c.passed);
        assert_eq!(c.margin, Some(0.0));
        let low = LimitCheck::new("k".into(), "q".into(), "V", Bound::Min, -0.3, Ok(-0.5));
        assert!(!low.passed);
        assert!((low.margin.unwrap() + 0.2).abs() < 1e-12);
    }
}
