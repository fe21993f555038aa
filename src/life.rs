//! Electrical life: how many operations the contacts last at a load,
//! from what their arcs put into them (docs/arcs.md, "Electrical life").
//!
//! Each arc of an operation (the bounce-opening arcs of the make and the
//! break arc) wears the contacts as its energy E times (Ī / 1 A)^p, Ī its
//! mean current and p = [`CURRENT_EXPONENT`]: the erosion per joule grows
//! with the current. With W_op that wear summed over the operation's arcs
//! and w the operation's wear factor, the life is N = B / (W_op · w), B a
//! constant of the relay fixed on one printed endurance figure by
//! simulating its test load. A datasheet's endurance test switches at
//! random phase of an AC supply, so an AC figure's W_op is the mean over
//! switching phases spread evenly over the period; a DC figure has one.
//!
//! The wear factor carries what the simulated arcs do not: an AC
//! operation at a supply of V (RMS) counts (V / [`REFERENCE_VOLTAGE`])^q,
//! q = [`VOLTAGE_EXPONENT`] (the arc that re-strikes after a current zero
//! at a higher recovery voltage, which the arc model does not strike), and
//! a DC one [`DC_TRANSFER`] (the material transfer of arcs of one
//! polarity). p, q and the DC factor are fitted on printed endurance
//! tables of nineteen relays (docs/arcs.md, "Which erosion law").
//!
//! Each figure's test circuit is built here: the supply (DC, or AC of the
//! figure's RMS voltage and frequency), a resistive load drawing the
//! figure's current, and the contact. The relay closes as it does
//! without a circuit (its step force, or its coil on the ideal DC step),
//! stays closed for a hold time after it settled, and breaks; the break's
//! gap opens at the arc's opening speed (the record of states has no
//! trajectory for it).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::chatter::{ContactState, Interval};
use crate::pipeline::{self, RunOptions};
use crate::scenario::{CircuitSection, Scenario};
pub use crate::scenario::{EnduranceFigure, Supply};
use crate::spice::Runner;

/// s, how long the contact stays closed after it settled before it breaks.
pub const HOLD: f64 = 5e-3;

/// How far above the model's breaking capacity a DC figure's current may
/// lie and still be simulated rather than refused outright: a printed
/// endurance figure at the printed capacity (which the model was fitted
/// to) sits on it, within rounding.
pub const CAPACITY_TOLERANCE: f64 = 0.02;

/// How many times its wear a direct-current operation counts, against
/// an alternating one at [`REFERENCE_VOLTAGE`]: the net material transfer
/// of arcs of one polarity added to their erosion (under alternating
/// current the polarity changes from one operation to the next and the
/// transfer cancels on average). Fitted with [`CURRENT_EXPONENT`] and
/// [`VOLTAGE_EXPONENT`] on printed tables whose DC figures are at 24-30 V
/// (docs/arcs.md, "Which erosion law"); the makers print the same life
/// at the rated DC load as at the rated AC one.
pub const DC_TRANSFER: f64 = 16.0;

/// The erosion law's current exponent p: an arc of energy E and mean
/// current Ī wears the contacts as E·(Ī/[`REFERENCE_CURRENT`])^p, the
/// erosion per joule growing with the arc's current (the molten metal its
/// roots eject). Fitted on printed endurance tables (docs/arcs.md, "Which
/// erosion law").
pub const CURRENT_EXPONENT: f64 = 0.5;

/// The AC wear factor's voltage exponent q: an AC operation at a supply
/// of V (RMS) counts (V/[`REFERENCE_VOLTAGE`])^q times its wear. The
/// simulated arc ends at the current zero; at a higher recovery voltage a
/// real one re-strikes across the hot gap more often and burns longer.
/// Fitted on printed endurance tables (docs/arcs.md, "Which erosion law").
pub const VOLTAGE_EXPONENT: f64 = 1.5;

/// V (RMS), the AC supply at which an operation's wear factor is 1.
pub const REFERENCE_VOLTAGE: f64 = 250.0;

/// The wear factor of an operation: [`DC_TRANSFER`] for direct current,
/// (V/[`REFERENCE_VOLTAGE`])^q for alternating current of `rms` volts.
pub fn wear_factor(supply: Supply, rms: f64) -> f64 {
    match supply {
        Supply::Dc => DC_TRANSFER,
        Supply::Ac => (rms / REFERENCE_VOLTAGE).powf(VOLTAGE_EXPONENT),
    }
}

/// A, the current at which an arc's wear is its energy.
pub const REFERENCE_CURRENT: f64 = 1.0;

/// The wear of one arc of energy `energy` (J), charge `charge` (C) and
/// duration `duration` (s) with the current exponent `exponent`: its
/// energy times (Ī/[`REFERENCE_CURRENT`])^p, Ī = charge/duration its mean
/// current (J at the reference current). An arc without duration wears
/// as its energy.
pub fn arc_wear(energy: f64, charge: f64, duration: f64, exponent: f64) -> f64 {
    if !(duration > 0.0 && charge > 0.0) || exponent == 0.0 {
        return energy;
    }
    energy * (charge / duration / REFERENCE_CURRENT).powf(exponent)
}

/// The default number of switching phases of an AC figure.
pub const DEFAULT_PHASES: usize = 16;

/// One figure's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FigureLife {
    /// The figure's test load in words, e.g. `5 A 30 VDC resistive`.
    pub load: String,
    /// As printed.
    pub operations: f64,
    /// The operations the calibrated model predicts at this load (`null`:
    /// the load puts no arc energy into the contacts, so the model
    /// predicts no electrical wear, or the figure is `refused`).
    pub predicted: Option<f64>,
    /// Why the model cannot price this figure (`null` when it can): its
    /// contact does not break the test load (beyond the breaking capacity
    /// at its voltage, or the break arc still burning when the test run
    /// ends). Such a figure has no finite life in the model and is never
    /// calibrated on.
    pub refused: Option<String>,
    /// predicted / printed.
    pub ratio: Option<f64>,
    /// J, the mean arc energy of one operation at this load.
    pub energy_per_operation: f64,
    /// J at the reference current, the mean wear of one operation: the sum
    /// over its arcs of E·(Ī/[`REFERENCE_CURRENT`])^p ([`arc_wear`]),
    /// before the `wear_factor`.
    pub wear_per_operation: f64,
    /// A, the arcs' mean current weighted by their energy: the Ī of the
    /// erosion law for the operation as a whole.
    pub arc_current: f64,
    /// How many times its wear the operation counts ([`wear_factor`]):
    /// [`DC_TRANSFER`] for a DC figure, (V/[`REFERENCE_VOLTAGE`])^q for
    /// an AC one of V volts (RMS).
    pub wear_factor: f64,
    /// How many switching phases were averaged (1 for DC).
    pub phases: usize,
    /// The mean over the even-numbered half of the phases relative to the
    /// mean over all of them, minus 1: how far the mean still moves (0
    /// for DC).
    pub convergence: f64,
}

/// The life at the scenario's own circuit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OwnLife {
    /// Operations: B / (W_op · w) (`null`: no arc energy, no electrical
    /// wear, or `refused`).
    pub operations: Option<f64>,
    /// Why the circuit's life cannot be priced (`null` when it can): the
    /// contact does not break the circuit's load within the run.
    pub refused: Option<String>,
    /// The B10 life with the printed Weibull shape (`null` without one).
    pub b10: Option<f64>,
    /// J, the arc energy of the circuit's operation.
    pub energy_per_operation: f64,
    /// J at the reference current, the wear of that operation
    /// ([`FigureLife::wear_per_operation`]).
    pub wear_per_operation: f64,
    /// A, its arcs' energy-weighted mean current.
    pub arc_current: f64,
    /// [`DC_TRANSFER`] for a circuit without a sine source;
    /// (V/[`REFERENCE_VOLTAGE`])^q for one with, V the largest sine
    /// amplitude of its sources over √2 (the reference voltage when the
    /// amplitude is not a number: a parameter).
    pub wear_factor: f64,
}

/// `life`'s report, also the `life` object of `run` and `check`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LifeReport {
    /// The figure B was calibrated on (0-based).
    pub calibrated_on: usize,
    /// J at the reference current: B = N_printed · W_op · wear factor of
    /// that figure, W_op its wear per operation.
    pub constant_j: f64,
    /// The erosion law's current exponent p ([`CURRENT_EXPONENT`]).
    pub current_exponent: f64,
    /// The AC wear factor's voltage exponent q ([`VOLTAGE_EXPONENT`]).
    pub voltage_exponent: f64,
    /// V (RMS), the AC supply whose wear factor is 1.
    pub reference_voltage: f64,
    /// The wear factor of a DC operation ([`DC_TRANSFER`]).
    pub dc_wear_factor: f64,
    /// A, the current at which an arc's wear is its energy.
    pub reference_current: f64,
    /// Every printed figure.
    pub figures: Vec<FigureLife>,
    /// At the scenario's own circuit, when it has one.
    pub life: Option<OwnLife>,
    /// The Weibull shape β the B10 life was computed with
    /// (`[datasheet] weibull_shape`; `null` without one: no B10).
    pub weibull_shape: Option<f64>,
    /// What the reader must know: every figure the model cannot price,
    /// with its reason.
    pub warnings: Vec<String>,
}

/// Whether `scenario` prints electrical endurance figures, so that a life
/// can be estimated for it.
pub fn has_figures(scenario: &Scenario) -> bool {
    scenario
        .datasheet
        .as_ref()
        .is_some_and(|d| !d.electrical_endurance.is_empty())
}

/// `[limits] min_electrical_life` (operations) held against the life at
/// the scenario's own circuit in `report`. A circuit whose operation puts
/// no arc energy into the contacts has no electrical wear: the limit holds
/// (with the largest finite number as its life, and a note saying why).
pub fn limit_check(limit: f64, report: &LifeReport) -> crate::check::LimitCheck {
    let (actual, note) = match &report.life {
        Some(OwnLife {
            refused: Some(why), ..
        }) => (Err(format!("the life cannot be priced: {why}")), None),
        Some(OwnLife {
            operations: Some(n),
            ..
        }) => (Ok(*n), None),
        Some(_) => (
            Ok(f64::MAX),
            Some(
                "unlimited by arcs: the circuit's operation puts no arc energy into the contacts"
                    .to_owned(),
            ),
        ),
        None => (
            Err("the scenario has no [circuit] to estimate the life at".to_owned()),
            None,
        ),
    };
    let mut check = crate::check::LimitCheck::new(
        "limits.min_electrical_life".into(),
        "electrical life at this circuit (operations)".into(),
        "",
        crate::check::Bound::Min,
        limit,
        actual,
    );
    if note.is_some() {
        check.note = note;
    }
    check
}

/// Why the life cannot be estimated.
#[derive(Debug, thiserror::Error)]
pub enum LifeError {
    /// Nothing printed to calibrate on.
    #[error(
        "{0}: no [datasheet] electrical_endurance figures: add the endurance figures the \
         datasheet prints, e.g. {{ operations = 1.0e5, voltage = 30.0, current = 5.0, supply = \"dc\" }}"
    )]
    NoFigures(PathBuf),
    /// A figure that cannot be simulated.
    #[error("{path}: datasheet.electrical_endurance figure {index}: {problem}")]
    BadFigure {
        /// The scenario file.
        path: PathBuf,
        /// 1-based.
        index: usize,
        /// What is wrong.
        problem: String,
    },
    /// No figure's load arcs and is broken, so none fixes B.
    #[error(
        "{path}: no printed endurance figure can fix the erosion constant: {reasons}. Give a \
         figure whose test load the contact breaks with an arc"
    )]
    NoArcEnergy {
        /// The scenario file.
        path: PathBuf,
        /// Why each figure cannot, joined.
        reasons: String,
    },
    /// The relay's closing.
    #[error(transparent)]
    Closing(#[from] crate::check::CheckError),
    /// A run of a test circuit.
    #[error("figure {index}'s test circuit, phase {phase}: {source}")]
    Run {
        /// 1-based.
        index: usize,
        /// 0-based.
        phase: usize,
        /// Why.
        #[source]
        source: Box<pipeline::RunError>,
    },
    /// The scenario's own circuit.
    #[error("the scenario's own circuit: {0}")]
    Own(#[source] Box<pipeline::RunError>),
    /// The work directory for the test circuits.
    #[error("cannot write the test circuit: {0}")]
    Io(#[from] std::io::Error),
}

/// The life estimate of `scenario` with `phases` switching phases per AC
/// figure, its ngspice runs through `runner`, `jobs` at a time. The
/// scenario's own circuit, when it has one, is run too.
pub fn estimate(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &RunOptions,
    phases: usize,
    jobs: usize,
) -> Result<LifeReport, LifeError> {
    estimate_at(scenario, runner, options, phases, jobs, None)
}

/// [`estimate`] with the scenario's own circuit already run (`own`, the
/// result of `run` or `check`): its operation energy is read from that
/// run instead of running the circuit again.
pub fn estimate_at(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &RunOptions,
    phases: usize,
    jobs: usize,
    own: Option<&pipeline::RunResult>,
) -> Result<LifeReport, LifeError> {
    let path = scenario.origin.clone();
    let figures = scenario
        .datasheet
        .as_ref()
        .map(|d| d.electrical_endurance.clone())
        .unwrap_or_default();
    if figures.is_empty() {
        return Err(LifeError::NoFigures(path));
    }
    validate(&figures, &path)?;
    let (closing, _) = crate::check::relay_closing(scenario)?;
    let arc = scenario.arc.unwrap_or_default().model();
    let gap = scenario.mechanics.gap;
    let dir = tempfile::Builder::new()
        .prefix("chatterspice-life-")
        .tempdir()?;
    let _remove = crate::interrupt::remove_at_stop(dir.path());
    let mut energies = Vec::with_capacity(figures.len());
    for (k, figure) in figures.iter().enumerate() {
        let beyond = beyond_capacity(figure, &arc, gap);
        energies.push(match beyond {
            Some(why) => FigureEnergy::refused(why),
            None => figure_energy(
                scenario,
                &closing,
                figure,
                k,
                phases,
                dir.path(),
                runner,
                options,
                jobs,
            )?,
        });
    }
    let Some(calibrated_on) = energies
        .iter()
        .position(|e| e.refused.is_none() && e.mean > 0.0)
    else {
        let reasons = figures
            .iter()
            .zip(&energies)
            .map(|(f, e)| {
                format!(
                    "{}: {}",
                    f.label(),
                    e.refused
                        .as_deref()
                        .unwrap_or("its load puts no arc energy into the contacts")
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
        return Err(LifeError::NoArcEnergy { path, reasons });
    };
    let wear = |f: &EnduranceFigure| wear_factor(f.supply, f.voltage);
    let b = figures[calibrated_on].operations
        * energies[calibrated_on].wear
        * wear(&figures[calibrated_on]);
    let mut warnings = Vec::new();
    let rows = figures
        .iter()
        .zip(&energies)
        .map(|(f, e)| {
            if let Some(why) = &e.refused {
                warnings.push(format!(
                    "the endurance figure at {} ({} operations) has no finite life in the \
                     model: {why}",
                    f.label(),
                    f.operations
                ));
            }
            let predicted = (e.refused.is_none() && e.mean > 0.0).then(|| b / (e.wear * wear(f)));
            FigureLife {
                load: f.label(),
                operations: f.operations,
                predicted,
                refused: e.refused.clone(),
                ratio: predicted.map(|p| p / f.operations),
                energy_per_operation: e.mean,
                wear_per_operation: e.wear,
                arc_current: e.current,
                wear_factor: wear(f),
                phases: e.phases,
                convergence: e.convergence,
            }
        })
        .collect();
    let shape = scenario.datasheet.as_ref().and_then(|d| d.weibull_shape);
    let life = own_life(scenario, runner, options, own, b, shape, &mut warnings)?;
    Ok(LifeReport {
        calibrated_on,
        constant_j: b,
        current_exponent: CURRENT_EXPONENT,
        voltage_exponent: VOLTAGE_EXPONENT,
        reference_voltage: REFERENCE_VOLTAGE,
        dc_wear_factor: DC_TRANSFER,
        reference_current: REFERENCE_CURRENT,
        figures: rows,
        life,
        weibull_shape: shape,
        warnings,
    })
}

/// The endurance figures checked: what a simulated test load needs.
fn validate(figures: &[EnduranceFigure], path: &std::path::Path) -> Result<(), LifeError> {
    for (k, f) in figures.iter().enumerate() {
        let problem = if !(f.operations > 0.0 && f.voltage > 0.0 && f.current > 0.0) {
            Some("operations, voltage and current must be > 0".to_owned())
        } else if f.load != "resistive" {
            Some(format!(
                "load \"{}\": only resistive test loads are simulated",
                f.load
            ))
        } else if f.frequency.is_some_and(|h| h.is_nan() || h <= 0.0) {
            Some("frequency must be > 0 Hz".to_owned())
        } else {
            None
        };
        if let Some(problem) = problem {
            return Err(LifeError::BadFigure {
                path: path.to_owned(),
                index: k + 1,
                problem,
            });
        }
    }
    Ok(())
}

/// Why `figure` cannot be priced before any run: a DC load beyond what
/// `arc` breaks at its voltage over the full gap `gap` (m) is never
/// broken.
fn beyond_capacity(
    figure: &EnduranceFigure,
    arc: &crate::arc::ArcModel,
    gap: f64,
) -> Option<String> {
    // A load beyond the breaking capacity at its voltage is never
    // broken: nothing to simulate.
    (figure.supply == Supply::Dc)
        .then(|| arc.breaking_current(figure.voltage, gap))
        .flatten()
        .filter(|&most| figure.current > most * (1.0 + CAPACITY_TOLERANCE))
        .map(|most| {
            format!(
                "beyond the breaking capacity: at {} V DC the contact breaks at most {:.3} A \
                 at its full gap",
                figure.voltage, most
            )
        })
}

/// The life at the scenario's own circuit, from `own` (its run) or a run
/// of it, with the erosion constant `b` (J); `None` without a circuit.
fn own_life(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &RunOptions,
    own: Option<&pipeline::RunResult>,
    b: f64,
    shape: Option<f64>,
    warnings: &mut Vec<String>,
) -> Result<Option<OwnLife>, LifeError> {
    let own_energy = |run: &pipeline::RunResult| {
        let totals = run.arcs.as_ref().map(|a| &a.totals);
        let refused = totals.and_then(|t| t.still_burning.as_ref()).map(|b| {
            format!(
                "the contact does not break the circuit's load: its arc still burns when the run \
                 ends, {:.3} ms after it struck, at a gap of {:.3} mm",
                b.duration * 1e3,
                b.gap * 1e3
            )
        });
        let wear = run.arcs.as_ref().map_or(Wear::default(), |a| {
            Wear::most_energetic_operation(&a.arcs, CURRENT_EXPONENT)
        });
        (
            totals.map_or(0.0, |t| t.max_operation_energy),
            wear,
            refused,
        )
    };
    let energy = match (&scenario.circuit, own) {
        (None, _) => None,
        (Some(_), Some(run)) => Some(own_energy(run)),
        (Some(_), None) => {
            let run = pipeline::run(scenario, runner, options)
                .map_err(|e| LifeError::Own(Box::new(e)))?;
            Some(own_energy(&run))
        }
    };
    // The run has read the netlist already.
    let supply = scenario.circuit.as_ref().and_then(|c| {
        crate::input::read_to_string(&c.netlist)
            .ok()
            .and_then(|text| alternating_supply(&text))
    });
    let wear_factor = match supply {
        None => DC_TRANSFER,
        Some(Some(rms)) => wear_factor(Supply::Ac, rms),
        Some(None) => {
            if energy.is_some() {
                warnings.push(format!(
                    "the circuit's sine source has no numeric amplitude: its AC wear factor is \
                     taken at {REFERENCE_VOLTAGE} V RMS"
                ));
            }
            1.0
        }
    };
    Ok(energy.map(|(e, w, refused)| {
        if let Some(why) = &refused {
            warnings.push(format!("no life at the scenario's circuit: {why}"));
        }
        let operations =
            (e > 0.0 && w.wear > 0.0 && refused.is_none()).then(|| b / (w.wear * wear_factor));
        OwnLife {
            operations,
            refused,
            b10: operations.zip(shape).map(|(n, beta)| b10(n, beta)),
            energy_per_operation: e,
            wear_per_operation: w.wear,
            arc_current: w.current,
            wear_factor,
        }
    }))
}

/// Whether a netlist drives its circuit from alternating current: an
/// independent source (`V…`, `I…`) with a sine (`SIN(…)`, `sin …`).
///
/// `None`: no sine source (a DC circuit). `Some(Some(v))`: v the largest
/// amplitude of its sine voltage sources over √2 (V RMS). `Some(None)`:
/// a sine source, but no sine voltage source with a numeric amplitude
/// (a current source, or an amplitude given by a parameter).
pub fn alternating_supply(netlist: &str) -> Option<Option<f64>> {
    let mut alternating = false;
    let mut largest: Option<f64> = None;
    for line in netlist.lines().skip(1) {
        let line = line.trim().to_ascii_lowercase();
        if !(line.starts_with('v') || line.starts_with('i')) {
            continue;
        }
        let words: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == '(' || c == ')' || c == ',')
            .filter(|w| !w.is_empty())
            .collect();
        let Some(at) = words.iter().position(|w| *w == "sin") else {
            continue;
        };
        alternating = true;
        // SIN(offset amplitude frequency …) of a voltage source.
        let amplitude = words
            .get(at + 2)
            .filter(|_| line.starts_with('v'))
            .and_then(|w| crate::netlist::parse_number(w))
            .map(f64::abs)
            .filter(|a| a.is_finite() && *a > 0.0);
        if let Some(a) = amplitude {
            largest = Some(largest.map_or(a, |b: f64| b.max(a)));
        }
    }
    alternating.then(|| largest.map(|a| a / std::f64::consts::SQRT_2))
}

/// `life`'s report as a table for people.
pub fn render(report: &LifeReport) -> String {
    use std::fmt::Write;
    let mut out = format!(
        "erosion constant B = {:.4e} J (at {} A), calibrated on figure {}; an arc wears E·(Ī/{} A)^{}, an \
         operation ×{} on DC, ×(V/{} V)^{} on AC\n",
        report.constant_j,
        report.reference_current,
        report.calibrated_on + 1,
        report.reference_current,
        report.current_exponent,
        report.dc_wear_factor,
        report.reference_voltage,
        report.voltage_exponent,
    );
    let width = report
        .figures
        .iter()
        .map(|f| f.load.chars().count())
        .max()
        .unwrap_or(0)
        .max(4);
    let _ = writeln!(
        out,
        "{:>6}  {:<width$} {:>12} {:>12} {:>8} {:>14} {:>7} {:>7} {:>12}",
        "figure",
        "load",
        "printed",
        "predicted",
        "ratio",
        "J/operation",
        "wear",
        "phases",
        "convergence"
    );
    for (k, f) in report.figures.iter().enumerate() {
        let _ = writeln!(
            out,
            "{:>6}  {:<width$} {:>12.4e} {:>12} {:>8} {:>14.4e} {:>7} {:>7} {:>+11.2}%",
            k + 1,
            f.load,
            f.operations,
            match (&f.refused, f.predicted) {
                (Some(_), _) => "not priced".to_owned(),
                (None, Some(p)) => format!("{p:.4e}"),
                (None, None) => "no wear".to_owned(),
            },
            f.ratio.map_or("-".to_owned(), |r| format!("{r:.3}")),
            f.energy_per_operation,
            format!("×{:.3}", f.wear_factor),
            f.phases,
            f.convergence * 100.0
        );
    }
    match &report.life {
        Some(l) => {
            let _ = writeln!(
                out,
                "life at the scenario's circuit: {} operations ({:.4e} J per operation, wear ×{:.3}){}",
                match (&l.refused, l.operations) {
                    (Some(_), _) => "not priced (see the warning)".to_owned(),
                    (None, Some(n)) => format!("{n:.4e}"),
                    (None, None) => "unlimited by arcs (no arc energy)".to_owned(),
                },
                l.energy_per_operation,
                l.wear_factor,
                l.b10
                    .zip(report.weibull_shape)
                    .map_or(String::new(), |(b, beta)| format!(
                        ", B10 {b:.4e} (Weibull shape {beta})"
                    ))
            );
        }
        None => out.push_str("the scenario has no [circuit]: no life at its own load\n"),
    }
    for w in &report.warnings {
        let _ = writeln!(out, "warning: {w}");
    }
    out
}

/// The B10 life of a Weibull distribution of shape `beta` whose mean is
/// `mean`: N·(−ln 0.9)^(1/β) / Γ(1 + 1/β).
pub fn b10(mean: f64, beta: f64) -> f64 {
    mean * (-(0.9f64.ln())).powf(1.0 / beta) / gamma(1.0 + 1.0 / beta)
}

/// Γ(x) for x in [1, 3] (Lanczos, g = 7, relative error below 1e-13).
fn gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (k, c) in C.iter().enumerate().skip(1) {
        a += c / (x + k as f64);
    }
    (2.0 * std::f64::consts::PI).sqrt() * t.powf(x + 0.5) * (-t).exp() * a
}

/// One phase's arc energy (J), its wear and, when its break arc still
/// burned when the test run ended, how long it had burned (s).
type PhaseResult = Result<(f64, Wear, Option<f64>), LifeError>;

/// The wear of one operation under the erosion law, and the mean current
/// it was priced at.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Wear {
    /// J at the reference current, Σ [`arc_wear`] over the arcs.
    wear: f64,
    /// A, the arcs' energy-weighted mean current.
    current: f64,
}

impl Wear {
    /// The wear of `arcs` (all of one operation) with exponent `p`.
    fn of<'a>(arcs: impl IntoIterator<Item = &'a crate::arc::ArcEvent>, p: f64) -> Wear {
        let (mut wear, mut energy, mut weighted) = (0.0, 0.0, 0.0);
        for a in arcs {
            wear += arc_wear(a.energy, a.charge, a.duration, p);
            energy += a.energy;
            if a.duration > 0.0 {
                weighted += a.energy * a.charge / a.duration;
            }
        }
        Wear {
            wear,
            current: if energy > 0.0 { weighted / energy } else { 0.0 },
        }
    }

    /// The wear of the operation of `arcs` with the most arc energy (the
    /// one `max_operation_energy` reports).
    fn most_energetic_operation(arcs: &[crate::arc::ArcEvent], p: f64) -> Wear {
        let last = arcs.iter().map(|a| a.operation).max();
        let Some(last) = last else {
            return Wear::default();
        };
        (0..=last)
            .map(|op| {
                let these = arcs.iter().filter(|a| a.operation == op);
                let energy: f64 = these.clone().map(|a| a.energy).sum();
                (energy, Wear::of(these, p))
            })
            .fold((f64::NEG_INFINITY, Wear::default()), |best, x| {
                if x.0 > best.0 { x } else { best }
            })
            .1
    }
}

/// One figure's simulated test load.
struct FigureEnergy {
    /// J, the mean arc energy of an operation.
    mean: f64,
    /// J at the reference current, the mean wear of an operation.
    wear: f64,
    /// A, the energy-weighted mean arc current over the phases.
    current: f64,
    /// Switching phases averaged.
    phases: usize,
    /// How far the mean still moves (see [`FigureLife::convergence`]).
    convergence: f64,
    /// Why the figure cannot be priced.
    refused: Option<String>,
}

impl FigureEnergy {
    fn refused(why: String) -> FigureEnergy {
        FigureEnergy {
            mean: 0.0,
            wear: 0.0,
            current: 0.0,
            phases: 0,
            convergence: 0.0,
            refused: Some(why),
        }
    }
}

/// One figure's test load run over its switching phases.
#[allow(clippy::too_many_arguments)]
fn figure_energy(
    scenario: &Scenario,
    closing: &crate::chatter::Chatter,
    figure: &EnduranceFigure,
    index: usize,
    phases: usize,
    dir: &Path,
    runner: &dyn Runner,
    options: &RunOptions,
    jobs: usize,
) -> Result<FigureEnergy, LifeError> {
    let settle = closing
        .intervals
        .iter()
        .rev()
        .find(|i| i.state == ContactState::Closed)
        .map_or(closing.t_end, |i| i.start);
    let t_break = settle + HOLD;
    let frequency = figure.frequency.unwrap_or(50.0);
    let tail = match figure.supply {
        Supply::Ac => 1.5 / frequency,
        Supply::Dc => 20e-3,
    };
    let t_stop = t_break + tail;
    let n = match figure.supply {
        Supply::Ac => phases.max(1),
        Supply::Dc => 1,
    };
    let resistance = figure.voltage / figure.current;
    let intervals = test_intervals(closing, t_break, t_stop);
    // (energy, the arc still burning at the run's end: how long it had burned)
    let run_phase = |phase: usize| -> PhaseResult {
        let source = match figure.supply {
            Supply::Dc => format!("DC {}", figure.voltage),
            Supply::Ac => format!(
                "SIN(0 {} {} 0 0 {})",
                figure.voltage * std::f64::consts::SQRT_2,
                frequency,
                360.0 * phase as f64 / n as f64
            ),
        };
        let netlist = format!(
            "endurance test load {} of the datasheet, phase {phase}\n\
             V1 supply 0 {source}\nR1 supply a {resistance}\nX1 a 0 CONTACT\n\
             .tran 1u {t_stop} 0 2u\n.end\n",
            index + 1
        );
        let file = dir.join(format!("figure{}_{phase}.cir", index + 1));
        std::fs::write(&file, netlist)?;
        let mut test = scenario.clone();
        test.circuit = Some(CircuitSection {
            netlist: file,
            subckt: "CONTACT".to_owned(),
            coil_subckt: "COIL".to_owned(),
            nc_subckt: None,
            params: std::collections::BTreeMap::new(),
        });
        test.probes.clear();
        test.arc = Some(scenario.arc.unwrap_or_default());
        // Only the arcs are read: no ideal-contact run to compare with.
        let options = RunOptions {
            compare_ideal: false,
            ..options.clone()
        };
        let run =
            pipeline::run_measured(&test, intervals.clone(), runner, &options).map_err(|e| {
                LifeError::Run {
                    index: index + 1,
                    phase,
                    source: Box::new(e),
                }
            })?;
        Ok(run.arcs.as_ref().map_or((0.0, Wear::default(), None), |a| {
            (
                a.totals.energy,
                Wear::of(&a.arcs, CURRENT_EXPONENT),
                a.totals.still_burning.as_ref().map(|b| b.duration),
            )
        }))
    };
    let mut energies = Vec::with_capacity(n);
    let (mut wear, mut weighted) = (0.0, 0.0);
    let mut burning: Option<f64> = None;
    for (e, w, still) in in_parallel(n, jobs, run_phase)? {
        energies.push(e);
        wear += w.wear / n as f64;
        weighted += w.current * e;
        if let Some(d) = still {
            burning = Some(burning.map_or(d, |b: f64| b.max(d)));
        }
    }
    let mean = energies.iter().sum::<f64>() / n as f64;
    let half: Vec<f64> = energies.iter().step_by(2).copied().collect();
    let half_mean = half.iter().sum::<f64>() / half.len() as f64;
    let convergence = if n > 1 && mean > 0.0 {
        half_mean / mean - 1.0
    } else {
        0.0
    };
    // An arc that outlasts the test run would price the figure by how
    // long the run was: the contact does not break this load.
    let refused = burning.map(|d| {
        format!(
            "the contact does not break its test load: the break arc still burns when the test \
             run ends, {:.1} ms after it struck",
            d * 1e3
        )
    });
    Ok(FigureEnergy {
        mean,
        wear,
        current: if mean > 0.0 {
            weighted / (mean * n as f64)
        } else {
            0.0
        },
        phases: n,
        convergence,
        refused,
    })
}

/// `closing`'s contact record up to `t_break`, held closed to it, then
/// open to `t_stop`: the test's one operation.
fn test_intervals(closing: &crate::chatter::Chatter, t_break: f64, t_stop: f64) -> Vec<Interval> {
    let mut intervals: Vec<Interval> = closing
        .intervals
        .iter()
        .filter(|i| i.start < t_break)
        .map(|i| Interval {
            end: i.end.min(t_break),
            ..*i
        })
        .collect();
    if let Some(last) = intervals.last_mut() {
        last.end = t_break;
    }
    intervals.push(Interval {
        state: ContactState::Open,
        start: t_break,
        end: t_stop,
    });
    intervals
}

/// `run(k)` for k in 0..n, `jobs` at a time, in order; the first error
/// (in that order) is the answer, and a stop before every one ran is an
/// error too.
fn in_parallel<T: Send>(
    n: usize,
    jobs: usize,
    run: impl Fn(usize) -> Result<T, LifeError> + Sync,
) -> Result<Vec<T>, LifeError> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: std::sync::Mutex<Vec<Option<Result<T, LifeError>>>> =
        std::sync::Mutex::new((0..n).map(|_| None).collect());
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, n.max(1)) {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                    if k >= n || crate::interrupt::stopping().is_some() {
                        break;
                    }
                    let result = run(k);
                    let failed = result.is_err();
                    results.lock().unwrap_or_else(|e| e.into_inner())[k] = Some(result);
                    if failed {
                        next.store(n, std::sync::atomic::Ordering::Relaxed);
                    }
                }
            });
        }
    });
    let mut out = Vec::with_capacity(n);
    for result in results.into_inner().unwrap_or_else(|e| e.into_inner()) {
        match result {
            Some(result) => out.push(result?),
            // Not run: an earlier error stopped the others, or a stop.
            None => continue,
        }
    }
    if out.len() < n {
        // Only a stop leaves runs undone without an error.
        return Err(LifeError::Io(std::io::Error::new(
            std::io::ErrorKind::Interrupted,
            "stopped before every phase ran",
        )));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sine_source_makes_a_circuit_alternating() {
        let rms = |text: &str| alternating_supply(text).flatten().unwrap();
        assert!((rms("t\nV1 a 0 SIN(0 325 50)\nR1 a 0 1\n") - 325.0 / 2f64.sqrt()).abs() < 1e-9);
        assert!((rms("t\nvs a 0 sin (0 1 60)\n") - 1.0 / 2f64.sqrt()).abs() < 1e-12);
        // The largest of two, with a suffix; a phase's sign does not count.
        let two = "t\nV1 a 0 SIN(0 0.17k 50)\nV2 b 0 sin(0 -339.4 50 0 0 90)\n";
        assert!((rms(two) - 339.4 / 2f64.sqrt()).abs() < 1e-9);
        // A current source's sine is AC, at no voltage of its own; so is a
        // parameter's amplitude.
        assert_eq!(
            alternating_supply("t\nI2 0 a dc 0 sin(0 1 1k)\n"),
            Some(None)
        );
        assert_eq!(
            alternating_supply("t\nV1 a 0 SIN(0 {vpk} 50)\n"),
            Some(None)
        );
        assert_eq!(alternating_supply("t\nV1 a 0 DC 24\nR1 a 0 1\n"), None);
        assert_eq!(
            alternating_supply("t\nV1 a 0 PULSE(0 5 0 1n 1n 1m 2m)\n"),
            None
        );
        // Not a source; the title line is not a card.
        assert_eq!(alternating_supply("t\nBsin a 0 v=sin(time)\n"), None);
        assert_eq!(alternating_supply("V1 a 0 SIN(0 1 50)\nR1 a 0 1\n"), None);
    }

    fn arc(operation: usize, energy: f64, charge: f64, duration: f64) -> crate::arc::ArcEvent {
        crate::arc::ArcEvent {
            operation,
            opening: "break".to_owned(),
            start: 0.0,
            duration,
            peak_current: 0.0,
            energy,
            charge,
            gap_at_end: 0.0,
            ends: "current_below_i_min",
        }
    }

    #[test]
    fn an_arc_wears_as_its_energy_times_its_current_to_the_exponent() {
        // 0.2 J at a mean current of 4 mC / 1 ms = 4 A.
        let w = arc_wear(0.2, 4e-3, 1e-3, 1.5);
        assert!((w - 0.2 * 4f64.powf(1.5) / REFERENCE_CURRENT.powf(1.5)).abs() < 1e-12);
        // p = 0: wear is energy; an arc without duration wears as its energy.
        assert_eq!(arc_wear(0.2, 4e-3, 1e-3, 0.0), 0.2);
        assert_eq!(arc_wear(0.2, 0.0, 0.0, 1.5), 0.2);
        // Twice the current at the same energy wears 2^p times as much.
        let ratio = arc_wear(1.0, 8e-3, 1e-3, 1.5) / arc_wear(1.0, 4e-3, 1e-3, 1.5);
        assert!((ratio - 2f64.powf(1.5)).abs() < 1e-12);
    }

    #[test]
    fn an_operation_wears_as_the_sum_over_its_arcs() {
        let p = 1.0;
        // Operation 0: a 10 A, 0.1 J arc and a 2 A, 0.3 J one; operation 1:
        // one 1 A arc of 0.5 J, the most energy but the least wear.
        let arcs = [
            arc(0, 0.1, 1e-3, 1e-4),
            arc(0, 0.3, 2e-3, 1e-3),
            arc(1, 0.5, 1e-3, 1e-3),
        ];
        let first = Wear::of(&arcs[..2], p);
        assert!((first.wear - (0.1 * 10.0 + 0.3 * 2.0)).abs() < 1e-12);
        // Energy-weighted: (0.1·10 + 0.3·2) / 0.4 = 4 A.
        assert!((first.current - 4.0).abs() < 1e-12);
        let most = Wear::most_energetic_operation(&arcs, p);
        assert!((most.wear - 0.5).abs() < 1e-12 && (most.current - 1.0).abs() < 1e-12);
        assert_eq!(Wear::most_energetic_operation(&[], p), Wear::default());
    }

    #[test]
    fn b10_of_a_weibull() {
        // β = 1 (exponential): B10 = mean · (−ln 0.9) = 0.10536·mean.
        assert!((b10(1.0, 1.0) - 0.105_360_515_657_826_3).abs() < 1e-12);
        // Γ(1.5) = √π/2.
        assert!((gamma(1.5) - std::f64::consts::PI.sqrt() / 2.0).abs() < 1e-13);
        // β = 2: mean·(−ln 0.9)^(1/2)/Γ(1.5).
        let expected = (0.105_360_515_657_826_3f64).sqrt() / (std::f64::consts::PI.sqrt() / 2.0);
        assert!((b10(1.0, 2.0) - expected).abs() < 1e-12);
        // A steeper Weibull puts B10 closer to the mean.
        assert!(b10(1.0, 3.0) > b10(1.0, 2.0));
    }
}
