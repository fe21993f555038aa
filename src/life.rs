//! Electrical life: how many operations the contacts last at a load,
//! from the energy their arcs put into them (docs/arcs.md, "Electrical
//! life").
//!
//! Each operation erodes the contacts in proportion to the energy of its
//! arcs (the bounce-opening arcs of the make and the break arc): with E_op
//! that energy the life is N = B / E_op, B a constant of the relay fixed
//! on one printed endurance figure by simulating its test load. A
//! datasheet's endurance test switches at random phase of an AC supply,
//! so an AC figure's E_op is the mean over switching phases spread evenly
//! over the period; a DC figure has one.
//!
//! A direct-current operation wears the contacts [`DC_TRANSFER`] times
//! what its arc energy alone says: every arc of one polarity carries metal
//! the same way, from one contact to the other, and the transfer adds to
//! the loss; under alternating current the arcs' polarity changes from one
//! operation to the next and the transfer cancels on average.
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

/// How many times its arc energy a direct-current operation wears the
/// contacts, against 1 for an alternating one: the net material transfer
/// of arcs of one polarity added to their erosion. Calibrated on a silver
/// alloy (AgNi) relay that prints 1e5 operations both at 3 A 250 V AC and
/// at 5 A 30 V DC, where arc energy alone makes the DC life 3.55 times the
/// printed one (docs/arcs.md, "Direct current").
pub const DC_TRANSFER: f64 = 3.5;

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
    /// How many times its arc energy the operation wears the contacts:
    /// [`DC_TRANSFER`] for a DC figure, 1 for AC.
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
    /// Operations: B / E_op (`null`: no arc energy, no electrical wear, or
    /// `refused`).
    pub operations: Option<f64>,
    /// Why the circuit's life cannot be priced (`null` when it can): the
    /// contact does not break the circuit's load within the run.
    pub refused: Option<String>,
    /// The B10 life with the printed Weibull shape (`null` without one).
    pub b10: Option<f64>,
    /// J, the arc energy of the circuit's operation.
    pub energy_per_operation: f64,
    /// [`DC_TRANSFER`] for a circuit without a sine source, 1 for one
    /// with (an AC circuit).
    pub wear_factor: f64,
}

/// `life`'s report, also the `life` object of `run` and `check`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LifeReport {
    /// The figure B was calibrated on (0-based).
    pub calibrated_on: usize,
    /// J, B = N_printed · E_op of that figure.
    pub constant_j: f64,
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
    let wear = |f: &EnduranceFigure| match f.supply {
        Supply::Dc => DC_TRANSFER,
        Supply::Ac => 1.0,
    };
    let b = figures[calibrated_on].operations
        * energies[calibrated_on].mean
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
            let predicted = (e.refused.is_none() && e.mean > 0.0).then(|| b / (e.mean * wear(f)));
            FigureLife {
                load: f.label(),
                operations: f.operations,
                predicted,
                refused: e.refused.clone(),
                ratio: predicted.map(|p| p / f.operations),
                energy_per_operation: e.mean,
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
        (totals.map_or(0.0, |t| t.max_operation_energy), refused)
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
    let wear_factor = match &scenario.circuit {
        // The run has read the netlist already.
        Some(c)
            if crate::input::read_to_string(&c.netlist)
                .is_ok_and(|text| alternating_supply(&text)) =>
        {
            1.0
        }
        _ => DC_TRANSFER,
    };
    Ok(energy.map(|(e, refused)| {
        if let Some(why) = &refused {
            warnings.push(format!("no life at the scenario's circuit: {why}"));
        }
        let operations = (e > 0.0 && refused.is_none()).then(|| b / (e * wear_factor));
        OwnLife {
            operations,
            refused,
            b10: operations.zip(shape).map(|(n, beta)| b10(n, beta)),
            energy_per_operation: e,
            wear_factor,
        }
    }))
}

/// Whether a netlist drives its circuit from alternating current: an
/// independent source (`V…`, `I…`) with a sine (`SIN(…)`, `sin …`).
pub fn alternating_supply(netlist: &str) -> bool {
    netlist.lines().skip(1).any(|line| {
        let line = line.trim().to_ascii_lowercase();
        let mut words = line.split(|c: char| c.is_whitespace() || c == '(');
        let is_source = line.starts_with('v') || line.starts_with('i');
        is_source && words.any(|w| w == "sin")
    })
}

/// `life`'s report as a table for people.
pub fn render(report: &LifeReport) -> String {
    use std::fmt::Write;
    let mut out = format!(
        "erosion constant B = {:.4e} J, calibrated on figure {}\n",
        report.constant_j,
        report.calibrated_on + 1
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
        "{:>6}  {:<width$} {:>12} {:>12} {:>8} {:>14} {:>5} {:>7} {:>12}",
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
            "{:>6}  {:<width$} {:>12.4e} {:>12} {:>8} {:>14.4e} {:>5} {:>7} {:>+11.2}%",
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
            format!("×{}", f.wear_factor),
            f.phases,
            f.convergence * 100.0
        );
    }
    match &report.life {
        Some(l) => {
            let _ = writeln!(
                out,
                "life at the scenario's circuit: {} operations ({:.4e} J per operation, wear ×{}){}",
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

/// One phase's arc energy (J) and, when its break arc still burned when
/// the test run ended, how long it had burned (s).
type PhaseResult = Result<(f64, Option<f64>), LifeError>;

/// One figure's simulated test load.
struct FigureEnergy {
    /// J, the mean arc energy of an operation.
    mean: f64,
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
        Ok(run.arcs.as_ref().map_or((0.0, None), |a| {
            (
                a.totals.energy,
                a.totals.still_burning.as_ref().map(|b| b.duration),
            )
        }))
    };
    let mut energies = Vec::with_capacity(n);
    let mut burning: Option<f64> = None;
    for (e, still) in in_parallel(n, jobs, run_phase)? {
        energies.push(e);
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
        assert!(alternating_supply("t\nV1 a 0 SIN(0 325 50)\nR1 a 0 1\n"));
        assert!(alternating_supply("t\nvs a 0 sin (0 1 60)\n"));
        assert!(alternating_supply("t\nI2 0 a dc 0 sin(0 1 1k)\n"));
        assert!(!alternating_supply("t\nV1 a 0 DC 24\nR1 a 0 1\n"));
        assert!(!alternating_supply("t\nV1 a 0 PULSE(0 5 0 1n 1n 1m 2m)\n"));
        // Not a source; the title line is not a card.
        assert!(!alternating_supply("t\nBsin a 0 v=sin(time)\n"));
        assert!(!alternating_supply("V1 a 0 SIN(0 1 50)\nR1 a 0 1\n"));
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
