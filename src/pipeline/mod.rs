//! The main job, `chatterspice run`: every stage of the pipeline in order.
//!
//! scenario → [`crate::mechanics::two_stage::step_closing`] (the chatter and the armature's motion) →
//! [`Waveform`] (the contact conductance) → [`netlist`]
//! (the contact include and the user's netlist with the `.include` added)
//! → a [`Runner`] (ngspice in batch mode) → the raw file →
//! [`analysis`] of every `[[probe]]`.
//!
//! The same circuit is run a second time with an **ideal contact**: a
//! single clean make at the first impact. The difference between the two
//! runs is what the bounce added (extra edges, a later settled edge, higher
//! peaks); it isolates the bounce from whatever the circuit does on its
//! own, such as a filter's delay. Both runs go to the runner at once, on
//! two threads: they are independent ngspice processes.
//!
//! Nothing here prints or touches the user's files: the result carries
//! the deck and the include that were run, and the raw data, for the
//! reports to write wherever the caller wants.

pub mod coupled;
pub mod ledger;
pub mod lockstep;
pub mod make_force;
pub mod pass;

pub use pass::{Pass, PassError, Simulation, circuit_pass};

pub use coupled::{
    Coupled, Coupling, CouplingError, CouplingOptions, Iteration, nc_include, run_coupled,
};

use std::path::PathBuf;
use std::time::Duration;

use thiserror::Error;

use crate::analysis::{self, AnalysisError, Comparison, ProbeAnalysis};
use crate::arc::ArcVectors;
use crate::arc::{ArcModel, ArcReport, GapProfile, analysis::MissingArcVector};
use crate::chatter::{Chatter, ContactState, Interval};
use crate::coil::Operation;
use crate::mechanics::Surface;
use crate::mechanics::{MechanicsError, contact_forces};
use crate::netlist::arc::with_arc;
use crate::netlist::{self, ContactElement, ContactInclude, Deck, DeckRequest, NetlistError};
use crate::plan::{Netlist, Plan};
use crate::rawfile::Plot;
use crate::scenario::{Probe, Scenario, ScenarioError};
use crate::spice::{RunRequest, Runner};
use crate::waveform::{ContactModel, Holm, Waveform, WaveformError};

/// The file name of the contact include in the run's work directory (and
/// in `--out`), which the deck `.include`s.
pub const INCLUDE_FILE: &str = "contact.inc";

/// The simulation should run this many times the end of the chatter, so
/// that the circuit's response to the last make (a filter settling, a
/// capacitor charging) shows too; a shorter `.tran` is a warning.
pub const STOP_MARGIN: f64 = 1.2;

/// How to run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOptions {
    /// Wall-clock limit of each ngspice run.
    pub timeout: Duration,
    /// Keep ngspice's work directories (named in the result and in errors).
    pub keep_workdir: bool,
    /// How the contact is emitted; `None` lets
    /// [`ContactElement::for_waveform`] choose (PWL, or the event-driven
    /// ramp for long two-level sequences, where a PWL gets slow).
    pub element: Option<ContactElement>,
    /// Also run the ideal contact and compare (needs a first impact).
    pub compare_ideal: bool,
    /// Run the ideal contact's ngspice at the same time as the bounced
    /// one (two processes), rather than after it. A sweep, which already
    /// runs one sample per job, turns this off.
    pub ideal_alongside: bool,
    /// For a coil-driven relay: how the coupling iterates (its `timeout`
    /// is replaced by the one above).
    pub coupling: CouplingOptions,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            timeout: RunRequest::DEFAULT_TIMEOUT,
            keep_workdir: false,
            element: None,
            compare_ideal: true,
            ideal_alongside: true,
            coupling: CouplingOptions::default(),
        }
    }
}

impl RunOptions {
    /// The options a front end's simulator settings give (`--timeout`,
    /// `--element`, `--coupling`, `--max-iterations`,
    /// `--coupling-tolerance` and their Python keywords); the rest default.
    pub fn simulator(
        timeout: Duration,
        element: Option<ContactElement>,
        coupling: Option<Coupling>,
        max_iterations: usize,
        tolerance: f64,
    ) -> RunOptions {
        RunOptions {
            timeout,
            element,
            coupling: CouplingOptions {
                tolerance,
                max_iterations,
                coupling,
                ..CouplingOptions::default()
            },
            ..RunOptions::default()
        }
    }
}

/// Why a run failed. Each variant names the file, key or run to look at.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum RunError {
    /// A circuit pass failed (ngspice, or its raw file).
    #[error(transparent)]
    Pass(#[from] PassError),
    /// An include (the contact's or the coil's) or the run deck could not
    /// be built.
    #[error(transparent)]
    Netlist(#[from] NetlistError),
    /// For a coil-driven relay: the coupled run, or the normally-closed
    /// contact's include, failed.
    #[error(transparent)]
    Coupling(Box<CouplingError>),
    /// The scenario does not validate, or its netlist cannot be read
    /// (see [`Plan::new`]).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The mechanics (the armature's motion under the step force, or the
    /// contact force for the Holm law) could not be simulated.
    #[error("{}: the mechanics simulation failed", path.display())]
    Mechanics {
        /// The scenario file.
        path: PathBuf,
        /// Why the simulation failed.
        #[source]
        source: MechanicsError,
    },
    /// The two-stage relay's motion (`[blade]`, `[pole_face]`, a contact
    /// released by force) could not be simulated.
    #[error("{}: the mechanics simulation failed", path.display())]
    Motion {
        /// The scenario file.
        path: PathBuf,
        /// Why the simulation failed.
        #[source]
        source: crate::mechanics::DriveError,
    },
    /// A coil-driven relay in a circuit without its coil has no DC step to
    /// close on.
    #[error(
        "{}: the netlist does not instantiate the coil subcircuit, so the relay closes on the \
         ideal DC step of its coil voltage: give `coil.drive_voltage` (V) or \
         `datasheet.coil_voltage`, or instantiate the coil (X2 a b COIL) in the netlist",
        path.display()
    )]
    NoDriveVoltage {
        /// The scenario file.
        path: PathBuf,
    },
    /// The closing on the ideal DC step of the coil could not be simulated.
    #[error("{}: the closing on the coil's DC step failed", path.display())]
    DcStep {
        /// The scenario file.
        path: PathBuf,
        /// Why it failed.
        #[source]
        source: crate::coil::CoilError,
    },
    /// The contact conductance over time could not be built from the
    /// chatter.
    #[error("{}: cannot build the contact waveform", path.display())]
    Waveform {
        /// The scenario file.
        path: PathBuf,
        /// Why the waveform could not be built.
        #[source]
        source: WaveformError,
    },
    /// The scenario has no `[circuit]`, so there is nothing to simulate.
    #[error(
        "{}: no [circuit] section: `run` needs the netlist the contact switches; add\n  \
         [circuit]\n  netlist = \"my_circuit.cir\"   # instantiates the contact as X1 a b CONTACT",
        path.display()
    )]
    NoCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// The scenario has no `[[probe]]`, so there is nothing to measure. Not
    /// returned by this version, which runs such a circuit and measures
    /// nothing; kept for callers that match on it.
    #[error(
        "{}: no [[probe]]: `run` measures the signals the probes name; add\n  \
         [[probe]]\n  signal = \"v(in)\"\n  low = 0.99\n  high = 2.31",
        path.display()
    )]
    NoProbes {
        /// The scenario file.
        path: PathBuf,
    },
    /// `[contact.holm]` with a measured chatter sequence, which has no
    /// contact force for the Holm law ([`run_measured`]).
    #[error(
        "{}: [contact.holm] needs the contact force, which a measured chatter sequence \
         does not have: remove [contact.holm] (r_closed is used) or simulate the relay",
        path.display()
    )]
    HolmNeedsForce {
        /// The scenario file.
        path: PathBuf,
    },
    /// With `[arc]`: the raw file lacks a vector the arc analysis reads.
    #[error("{}: cannot analyse the arcs of the {run} run", netlist.display())]
    Arc {
        /// The run: `bounced` or `coupled`.
        run: &'static str,
        /// The user's netlist.
        netlist: PathBuf,
        /// The contact instance and the vector that is missing.
        #[source]
        source: MissingArcVector,
    },
    /// The arcs and breakdowns took more energy than the circuit gave.
    #[error("{}: {message}", netlist.display())]
    Energy {
        /// The user's netlist.
        netlist: PathBuf,
        /// What was taken and what was given.
        message: String,
    },
    /// A `[[probe]]` could not be analysed in a run's transient plot.
    #[error("{}: probe `{signal}` ({run} run)", origin.display())]
    Probe {
        /// The scenario file.
        origin: PathBuf,
        /// The probe's ngspice vector, e.g. `v(out)`.
        signal: String,
        /// The run: `bounced`, `ideal` or `coupled`.
        run: &'static str,
        /// Why the analysis failed.
        #[source]
        source: Box<AnalysisError>,
    },
}

/// One probe: its analysis, and what the bounce added over the ideal run.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbeResult {
    /// The `[[probe]]` as the scenario gives it.
    pub probe: Probe,
    /// The probe in the bounced run (the coupled run, for a coil-driven
    /// relay).
    pub analysis: ProbeAnalysis,
    /// The probe in the ideal-contact run, when there was one.
    pub ideal: Option<ProbeAnalysis>,
    /// What the bounce added (bounced − ideal), when there was an
    /// ideal-contact run.
    pub comparison: Option<Comparison>,
}

/// Everything `run` produced.
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// The user's netlist (as named by the scenario).
    pub netlist: PathBuf,
    /// The contact's chatter sequence (for a coil-driven relay, the
    /// normally-open contact's over the whole run).
    pub chatter: Chatter,
    /// The contact conductance over time that the include follows.
    pub waveform: Waveform,
    /// The contact include that was run (written as [`INCLUDE_FILE`]).
    pub include: ContactInclude,
    /// The deck that was run: the user's netlist plus the `.include`.
    pub deck: Deck,
    /// The bounced run (for a coil-driven relay, the coupling's last
    /// circuit run).
    pub simulation: Simulation,
    /// The ideal-contact run, when there was one.
    pub ideal: Option<Simulation>,
    /// Every `[[probe]]`, in the scenario's order.
    pub probes: Vec<ProbeResult>,
    /// Things worth a look that did not stop the run, in order.
    pub warnings: Vec<String>,
    /// For a coil-driven relay: the passes of the coupling, the last one
    /// converged.
    pub coupling: Option<Vec<Iteration>>,
    /// For a coil-driven relay: each operation (closing and release) with
    /// its timing. Empty for a step force.
    pub operations: Vec<Operation>,
    /// For a coil-driven relay: the drop-out and pick-up levels its coil's
    /// drive was read against.
    pub coil_levels: Option<crate::coil::CoilLevels>,
    /// With `[arc]`: every arc and breakdown at the contact.
    pub arcs: Option<ArcReport>,
    /// The run's energy ledger: what the sources delivered and where it
    /// went (arcs and breakdowns taking more than the circuit gave is an
    /// error, never a result).
    pub energy: ledger::EnergyLedger,
    /// With `[pole_face]`: the armature's impacts on the pole face (the
    /// contact's record is then the blade's).
    pub pole_face: Option<Vec<crate::chatter::Impact>>,
    /// Every make of the contact (the first and each re-make after a
    /// bounce): its peak current and, where the run knows the contact
    /// force, the spot's voltage, temperature and weld margin.
    pub makes: Vec<crate::arc::making::Make>,
}

/// Run the whole pipeline on `scenario` with `runner`. A scenario with a
/// `[coil]` runs the coil in the circuit, coupled to the mechanics
/// ([`run_coupled`]); there is no ideal-contact run then.
pub fn run(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &RunOptions,
) -> Result<RunResult, RunError> {
    run_plan(&Plan::new(scenario.clone())?, runner, options)
}

/// [`run`] of a [`Plan`]: the scenario resolved once, its netlist read
/// once (a sweep runs each sample's plan).
pub fn run_plan(
    plan: &Plan,
    runner: &dyn Runner,
    options: &RunOptions,
) -> Result<RunResult, RunError> {
    let scenario = plan.scenario();
    check_circuit(scenario)?;
    if scenario.coil.is_some() {
        if drives_its_coil(plan) {
            return run_coil(plan, runner, options);
        }
        return run_dc_step(plan, runner, options);
    }
    let mechanics = plan.mechanics()?;
    let (surface, settings) = (plan.surface(), plan.settings());
    let trajectory = crate::mechanics::two_stage::step_closing(
        &mechanics,
        &plan.two_stage(),
        &surface,
        &settings,
    )
    .map_err(|source| RunError::Motion {
        path: scenario.origin.clone(),
        source,
    })?;
    let gap = GapProfile::from_trajectory(&trajectory);
    let pole_face = plan
        .two_stage()
        .pole_face
        .is_some()
        .then(|| trajectory.pole_face_impacts().to_vec());
    let chatter = trajectory.chatter().clone();
    let (waveform, model) = contact_waveform_of(scenario, surface, &chatter)?;
    let mut result = run_chatter(plan, chatter, waveform, &model, gap, runner, options)?;
    result.pole_face = pole_face;
    // A step-force relay knows its contact force at every instant.
    result.makes = contact_makes(
        scenario,
        plan.netlist().map(|n| n.text.as_str()),
        &result.simulation.plot,
        &result.waveform,
        &result.chatter,
        Some(&|t| trajectory.contact_force(t)),
        &[],
    );
    Ok(result)
}

/// Every make of `chatter` in `plot`: the contact current is the voltage
/// across the contact instance's nodes times the waveform's conductance;
/// `force_at` (N at s) where the run knows the contact force; `coil_offs`
/// (s) where the coil was switched off, which ends an operation.
fn contact_makes(
    scenario: &Scenario,
    netlist_text: Option<&str>,
    plot: &Plot,
    waveform: &Waveform,
    chatter: &Chatter,
    force_at: Option<&dyn Fn(f64) -> f64>,
    coil_offs: &[f64],
) -> Vec<crate::arc::making::Make> {
    let (Some(circuit), Some(text)) = (&scenario.circuit, netlist_text) else {
        return Vec::new();
    };
    let Some((a, b)) = netlist::instance_nodes_of(text, &circuit.subckt)
        .into_iter()
        .next()
    else {
        return Vec::new();
    };
    let Some(crate::rawfile::Vector::Real(time)) = plot.scale() else {
        return Vec::new();
    };
    let zero = vec![0.0; time.len()];
    let node = |n: &str| {
        if matches!(n, "0" | "gnd") {
            Some(zero.as_slice())
        } else {
            plot.real(&format!("v({n})"))
        }
    };
    let (Some(va), Some(vb)) = (node(&a), node(&b)) else {
        return Vec::new();
    };
    let current: Vec<f64> = (0..time.len().min(va.len()).min(vb.len()))
        .map(|k| (va[k] - vb[k]) * waveform.conductance_at(time[k]))
        .collect();
    let material = scenario
        .arc
        .and_then(|a| a.material)
        .unwrap_or(crate::arc::REFERENCE_MATERIAL)
        .spot();
    crate::arc::making::makes(
        time,
        &current,
        &analysis::closures(chatter),
        force_at,
        &material,
        coil_offs,
    )
}

/// Whether the circuit drives the relay's coil: its netlist instantiates
/// the coil subcircuit, or it wants the normally-closed contact (which
/// follows the coil's release). Otherwise the circuit holds the contact
/// only, and the relay closes on the ideal DC step of its coil.
fn drives_its_coil(plan: &Plan) -> bool {
    let Some(circuit) = &plan.scenario().circuit else {
        return false;
    };
    circuit.nc_subckt.is_some()
        || plan
            .netlist()
            .is_none_or(|n| !netlist::instances_of(&n.text, &circuit.coil_subckt).is_empty())
}

/// A coil-driven relay whose circuit holds only its contact: the closing
/// on the ideal DC step of `coil.drive_voltage` (else
/// `datasheet.coil_voltage`) from t = 0, as a datasheet measures it, then
/// the contact through the circuit.
fn run_dc_step(
    plan: &Plan,
    runner: &dyn Runner,
    options: &RunOptions,
) -> Result<RunResult, RunError> {
    let scenario = plan.scenario();
    let path = || scenario.origin.clone();
    let (coil, source) = scenario
        .dc_step()
        .ok_or_else(|| RunError::NoDriveVoltage { path: path() })?;
    let (chatter, two_stage) = crate::coil::direct::direct_closing(
        &coil,
        &source,
        &scenario.armature(),
        &plan.two_stage(),
        &plan.surface(),
        &plan.settings(),
    )
    .map_err(|source| RunError::DcStep {
        path: path(),
        source,
    })?;
    // The opening gap of an arc at a DC step's contact: each opening at
    // the arc's opening speed, as for a measured record.
    let gap = record_gap(scenario, &chatter.intervals);
    let pole_face = two_stage
        .clone()
        .filter(|_| plan.two_stage().pole_face.is_some());
    // The contact force at each make, from the closing's own motion.
    let force = make_force::dc_step(plan, &coil, &source, two_stage.clone());
    let pole_face = pole_face.map(|run| run.pole_face);
    let (waveform, model) = contact_waveform_of(scenario, plan.surface(), &chatter)?;
    let mut result = run_chatter(plan, chatter, waveform, &model, gap, runner, options)?;
    result.pole_face = pole_face;
    result.makes = contact_makes(
        scenario,
        plan.netlist().map(|n| n.text.as_str()),
        &result.simulation.plot,
        &result.waveform,
        &result.chatter,
        force.as_deref(),
        &[],
    );
    Ok(result)
}

/// [`run`] with a measured chatter sequence (e.g. from
/// [`read_state_csv`](crate::waveform::read_state_csv)) instead of the
/// mechanics: `scenario` supplies the contact, the circuit and the probes.
/// The result's chatter has the intervals and the summary but no impacts
/// (a record of states has no velocities or forces), so a `[contact.holm]`
/// law, which needs the force, is refused.
pub fn run_measured(
    scenario: &Scenario,
    intervals: Vec<Interval>,
    runner: &dyn Runner,
    options: &RunOptions,
) -> Result<RunResult, RunError> {
    let plan = Plan::new(scenario.clone())?;
    check_circuit(scenario)?;
    if scenario.contact.holm.is_some() {
        return Err(RunError::HolmNeedsForce {
            path: scenario.origin.clone(),
        });
    }
    let chatter = Chatter::from_intervals(intervals);
    let model = ContactModel::from(&scenario.contact);
    let waveform = Waveform::from_intervals(&chatter.intervals, &model).map_err(|source| {
        RunError::Waveform {
            path: scenario.origin.clone(),
            source,
        }
    })?;
    let gap = record_gap(scenario, &chatter.intervals);
    run_chatter(&plan, chatter, waveform, &model, gap, runner, options)
}

/// gap(t) of a measured record of states, which has no positions: each
/// opening moves at `arc.opening_speed` (its default without `[arc]`) up
/// to `mechanics.gap`.
pub fn record_gap(scenario: &Scenario, intervals: &[Interval]) -> GapProfile {
    let speed = scenario.arc.map_or(crate::arc::DEFAULT_OPENING_SPEED, |a| {
        a.model().opening_speed
    });
    GapProfile::from_intervals(intervals, speed, scenario.mechanics.gap)
}

/// The scenario has what `run` needs besides the relay: a circuit. A
/// circuit without probes runs too (the relay, the contact and every
/// vector ngspice saves; nothing is measured).
fn check_circuit(scenario: &Scenario) -> Result<(), RunError> {
    if scenario.circuit.is_none() {
        return Err(RunError::NoCircuit {
            path: scenario.origin.clone(),
        });
    }
    Ok(())
}

/// From the contact waveform on: include, deck, both ngspice runs, probes.
/// `model` is the ideal contact's.
fn run_chatter(
    plan: &Plan,
    chatter: Chatter,
    waveform: Waveform,
    model: &ContactModel,
    gap: GapProfile,
    runner: &dyn Runner,
    options: &RunOptions,
) -> Result<RunResult, RunError> {
    let scenario = plan.scenario();
    let origin = &scenario.origin;
    let Netlist {
        path: netlist_path,
        text: netlist_text,
    } = plan.netlist().ok_or_else(|| RunError::NoCircuit {
        path: origin.clone(),
    })?;
    let netlist_path = netlist_path.clone();
    let circuit = scenario
        .circuit
        .as_ref()
        .expect("netlist() returned Some, so there is a [circuit]");
    let element = options
        .element
        .unwrap_or_else(|| ContactElement::for_waveform(&waveform));
    let include = netlist::contact_include(&waveform, &circuit.subckt, element)?;
    let arc = arc_setup(scenario, netlist_text);
    let include = match &arc {
        Some(a) => with_arc(include, &a.model, &gap)?,
        None => include,
    };

    let mut signals: Vec<&str> = scenario.probes.iter().map(|p| p.signal.as_str()).collect();
    if let Some(a) = &arc {
        signals.extend(a.vectors.all());
    }
    let end = chatter_end(&chatter) + model.edge_time;
    let deck = netlist::prepare_deck_with_params(
        &DeckRequest {
            netlist_text,
            netlist_path: &netlist_path,
            include_file_name: INCLUDE_FILE,
            subckt: &circuit.subckt,
            coil: None,
            probes: &signals,
            chatter_end: end,
            stop_at_least: end * STOP_MARGIN,
            options: if arc.is_some() {
                &[crate::netlist::arc::ARC_OPTIONS]
            } else {
                &[]
            },
        },
        &circuit.param_list(),
    )?;

    let ideal_include = ideal_include(
        origin,
        options.compare_ideal,
        &chatter,
        model,
        &circuit.subckt,
        element,
    )?;

    let pass = |run: &'static str, include: &ContactInclude| {
        let mut includes = vec![(INCLUDE_FILE.to_owned(), include.text.clone())];
        includes.extend(include.data_files.iter().cloned());
        Pass {
            run,
            netlist: &netlist_path,
            deck: &deck,
            includes,
            timeout: options.timeout,
            keep_workdir: options.keep_workdir,
        }
    };
    let bounced_pass = pass("bounced", &include);
    let ideal_pass = ideal_include.as_ref().map(|i| pass("ideal", i));
    let (simulation, ideal) =
        bounced_and_ideal(runner, options.ideal_alongside, bounced_pass, ideal_pass)?;

    let probes = probe_results(
        scenario,
        &chatter,
        ("bounced", &simulation.plot),
        ideal.as_ref().map(|sim| &sim.plot),
    )?;

    let arcs = arc
        .as_ref()
        .map(|a| {
            a.report(
                ("bounced", &simulation.plot),
                &gap,
                &chatter,
                &[],
                &netlist_path,
            )
        })
        .transpose()?;
    let energy = energy_ledger(
        &simulation.plot,
        &deck.text,
        circuit,
        arcs.as_ref(),
        &netlist_path,
    )?;

    let mut warnings: Vec<String> = deck.warnings.iter().map(ToString::to_string).collect();
    warnings.extend(simulation.warnings.iter().cloned());
    warnings.extend(probes.iter().filter_map(|p| p.analysis.threshold_warning()));
    warnings.extend(arc_warnings(
        scenario,
        netlist_text,
        arcs.as_ref(),
        &simulation.plot,
        &waveform,
        &chatter,
        &gap,
    ));
    let makes = contact_makes(
        scenario,
        Some(netlist_text),
        &simulation.plot,
        &waveform,
        &chatter,
        None,
        &[],
    );
    Ok(RunResult {
        coupling: None,
        operations: Vec::new(),
        coil_levels: None,
        pole_face: None,
        makes,
        arcs,
        energy,
        netlist: netlist_path,
        chatter,
        waveform,
        include,
        deck,
        simulation,
        ideal,
        probes,
        warnings,
    })
}

/// Every probe of `scenario` analysed in `plot` (named `run` in errors)
/// and, with an ideal-contact run, in its plot too and compared. Currents
/// are integrated over the chatter's closures, and over the ideal
/// contact's one closure (from the first impact on) in its run.
fn probe_results(
    scenario: &Scenario,
    chatter: &Chatter,
    (run, plot): (&'static str, &Plot),
    ideal_plot: Option<&Plot>,
) -> Result<Vec<ProbeResult>, RunError> {
    let closures = analysis::closures(chatter);
    let ideal_closures: Vec<(f64, f64)> = chatter
        .first_impact
        .map(|t| (t, chatter.t_end.max(t)))
        .into_iter()
        .collect();
    let mut probes = Vec::with_capacity(scenario.probes.len());
    for probe in &scenario.probes {
        let probe_error = |run, source| RunError::Probe {
            origin: scenario.origin.clone(),
            signal: probe.signal.clone(),
            run,
            source: Box::new(source),
        };
        let analysis =
            analysis::analyze(plot, probe, &closures).map_err(|e| probe_error(run, e))?;
        let ideal = ideal_plot
            .map(|p| analysis::analyze(p, probe, &ideal_closures))
            .transpose()
            .map_err(|e| probe_error("ideal", e))?;
        let comparison = ideal
            .as_ref()
            .map(|ideal| analysis::compare(&analysis, ideal))
            .transpose()
            .map_err(|e| probe_error("ideal", e))?;
        probes.push(ProbeResult {
            probe: probe.clone(),
            analysis,
            ideal,
            comparison,
        });
    }
    Ok(probes)
}

/// `run` for a coil-driven relay: the coupled run, then the probes of its
/// last circuit run.
fn run_coil(plan: &Plan, runner: &dyn Runner, options: &RunOptions) -> Result<RunResult, RunError> {
    let scenario = plan.scenario();
    let coupled = coupled::run_coupled_plan(
        plan,
        runner,
        &CouplingOptions {
            timeout: options.timeout,
            keep_workdir: options.keep_workdir,
            ..options.coupling.clone()
        },
    )
    .map_err(|e| RunError::Coupling(Box::new(e)))?;
    let circuit = scenario
        .circuit
        .as_ref()
        .expect("check_circuit found a [circuit]");
    let model = ContactModel::from(&scenario.contact);
    let waveform =
        Waveform::from_chatter(&coupled.chatter, &model).map_err(|source| RunError::Waveform {
            path: scenario.origin.clone(),
            source,
        })?;
    let element = options
        .element
        .unwrap_or_else(|| ContactElement::for_waveform(&waveform));
    let mut include = netlist::contact_include(&waveform, &circuit.subckt, element)?;
    let netlist_text = plan.netlist().map(|n| n.text.as_str());
    let arc = netlist_text.and_then(|text| arc_setup(scenario, text));
    let gap = GapProfile::from_path(scenario.mechanics.gap, &coupled.path);
    if let Some(a) = &arc {
        include = with_arc(include, &a.model, &gap)?;
    }
    // The deck `.include`s the coil too: `--out` writes it beside the
    // contact include, so that the deck runs again by hand.
    if let Some(coil) = &scenario.coil {
        let text = netlist::coil::coil_include(coil, &circuit.coil_subckt, &coupled.path)?;
        include
            .data_files
            .push((coupled::COIL_FILE.to_owned(), text));
    }
    if let Some(nc) = &circuit.nc_subckt {
        let nc = nc_include(&coupled.back, &model, nc, &scenario.origin)
            .map_err(|e| RunError::Coupling(Box::new(e)))?;
        include.text.push_str(&nc);
    }
    let probes = probe_results(scenario, &coupled.chatter, ("coupled", &coupled.plot), None)?;
    let coil_offs: Vec<f64> = coupled
        .operations
        .iter()
        .filter_map(|op| op.coil_off)
        .collect();
    let arcs = arc
        .as_ref()
        .map(|a| {
            a.report(
                ("coupled", &coupled.plot),
                &gap,
                &coupled.chatter,
                &coil_offs,
                &circuit.netlist,
            )
        })
        .transpose()?;
    let energy = energy_ledger(
        &coupled.plot,
        &coupled.deck.text,
        circuit,
        arcs.as_ref(),
        &circuit.netlist,
    )?;
    let elapsed: f64 = coupled.iterations.iter().map(|i| i.ngspice_elapsed).sum();
    let netlist_path = circuit.netlist.clone();
    let mut warnings: Vec<String> = coupled
        .deck
        .warnings
        .iter()
        .map(ToString::to_string)
        .collect();
    warnings.extend(coupled.fallback.clone());
    warnings.extend(
        coupled
            .operations
            .iter()
            .filter_map(crate::coil::Operation::reclosure_warning),
    );
    if let Some(text) = netlist_text {
        warnings.extend(arc_warnings(
            scenario,
            text,
            arcs.as_ref(),
            &coupled.plot,
            &waveform,
            &coupled.chatter,
            &gap,
        ));
    }
    // The contact force at each make, from the armature moved again under
    // the converged pass's flux.
    let force = make_force::coupled(plan, &coupled);
    if force.is_none() && !coupled.chatter.impacts.is_empty() {
        warnings.push(
            "the contact force at the makes could not be rebuilt from the coupled run, so \
             the makes have no spot figures or weld margin"
                .to_owned(),
        );
    }
    let makes = contact_makes(
        scenario,
        netlist_text,
        &coupled.plot,
        &waveform,
        &coupled.chatter,
        force.as_deref(),
        &coil_offs,
    );
    Ok(RunResult {
        makes,
        netlist: netlist_path,
        chatter: coupled.chatter,
        waveform,
        include,
        deck: coupled.deck,
        simulation: Simulation {
            plot: coupled.plot,
            version: coupled.version,
            elapsed: Duration::from_secs_f64(elapsed),
            warnings: Vec::new(),
            workdir: None,
            log: coupled.log,
        },
        ideal: None,
        probes,
        warnings,
        coupling: Some(coupled.iterations),
        coil_levels: Some(coupled.levels),
        operations: coupled.operations,
        pole_face: plan
            .two_stage()
            .pole_face
            .is_some()
            .then_some(coupled.pole_face),
        arcs,
        energy,
    })
}

/// What to say about arcs: with `[arc]`, an arc still burning when the
/// simulation stopped; without it, a result that is not physical because
/// the contact would have arced or its gap broken down.
fn arc_warnings(
    scenario: &Scenario,
    netlist_text: &str,
    arcs: Option<&ArcReport>,
    plot: &Plot,
    waveform: &Waveform,
    chatter: &Chatter,
    gap: &GapProfile,
) -> Vec<String> {
    if let Some(report) = arcs {
        let mut warnings = Vec::new();
        if let Some(circuit) = &scenario.circuit {
            let instances = netlist::instances_of(netlist_text, &circuit.subckt);
            if instances.len() > 1 {
                warnings.push(format!(
                    "the netlist has {} instances of {}: each carries the arc, but the arcs \
                     reported are those of `{}` only",
                    instances.len(),
                    circuit.subckt,
                    instances[0]
                ));
            }
        }
        if let Some(a) = &report.totals.still_burning {
            warnings.push(format!(
                "the arc at {} (from {:.4} ms) still burns when the simulation stops, after \
                 {:.3} ms and {:.4} J: the circuit holds it above the arc voltage \
                 V_min + E·gap + (C + D·gap)/|i| at a {:.3} mm gap; extend .tran, or the \
                 contact does not break this load",
                a.opening,
                a.start * 1e3,
                a.duration * 1e3,
                a.energy,
                a.gap * 1e3
            ));
        }
        return warnings;
    }
    let Some(circuit) = &scenario.circuit else {
        return Vec::new();
    };
    let Some((a, b)) = netlist::instance_nodes_of(netlist_text, &circuit.subckt)
        .into_iter()
        .next()
    else {
        return Vec::new();
    };
    let vector = |node: &str| (!matches!(node, "0" | "gnd")).then(|| format!("v({node})"));
    let (va, vb) = (vector(&a), vector(&b));
    crate::arc::analysis::unphysical_warning(
        plot,
        (va.as_deref(), vb.as_deref()),
        |t| waveform.conductance_at(t),
        chatter,
        gap,
    )
    .into_iter()
    .collect()
}

/// With `[arc]`: the arc numbers, and the contact instance the arcs are
/// read from (the first, when the netlist has several) with the vectors
/// its deck must save.
struct ArcSetup {
    model: ArcModel,
    vectors: ArcVectors,
    instance: String,
}

/// The ideal contact's include (closed for good from the first impact)
/// to compare the run with, when `compare` and the contact closes.
fn ideal_include(
    origin: &std::path::Path,
    compare: bool,
    chatter: &Chatter,
    model: &ContactModel,
    subckt: &str,
    element: ContactElement,
) -> Result<Option<ContactInclude>, RunError> {
    let Some(first) = chatter.first_impact.filter(|_| compare) else {
        return Ok(None);
    };
    let ideal =
        ideal_waveform(first, chatter.t_end, model).map_err(|source| RunError::Waveform {
            path: origin.to_owned(),
            source,
        })?;
    Ok(Some(netlist::contact_include(&ideal, subckt, element)?))
}

/// The bounced run and, when asked, the ideal contact's beside it (in
/// parallel when `alongside`), the bounced run's error first.
fn bounced_and_ideal(
    runner: &dyn Runner,
    alongside: bool,
    bounced: Pass<'_>,
    ideal: Option<Pass<'_>>,
) -> Result<(Simulation, Option<Simulation>), PassError> {
    let (simulation, ideal) = if alongside {
        std::thread::scope(|scope| {
            let ideal = ideal.map(|p| scope.spawn(move || circuit_pass(runner, p)));
            let bounced = circuit_pass(runner, bounced);
            let ideal = ideal.map(|handle| handle.join().expect("the ideal run does not panic"));
            (bounced, ideal)
        })
    } else {
        let simulation = circuit_pass(runner, bounced);
        (simulation, ideal.map(|p| circuit_pass(runner, p)))
    };
    Ok((simulation?, ideal.transpose()?))
}

/// The energy ledger of `plot`, the run of deck `deck` for `circuit`,
/// with the run's `arcs`; an error when the arcs and breakdowns took more
/// than the circuit gave.
fn energy_ledger(
    plot: &Plot,
    deck: &str,
    circuit: &crate::scenario::CircuitSection,
    arcs: Option<&ArcReport>,
    netlist: &std::path::Path,
) -> Result<ledger::EnergyLedger, RunError> {
    let mut ours = vec![circuit.subckt.as_str(), circuit.coil_subckt.as_str()];
    ours.extend(circuit.nc_subckt.as_deref());
    let elements = netlist::elements::top_level(deck, &ours);
    let energy = ledger::ledger(plot, &elements, arcs);
    match energy.violation() {
        Some(message) => Err(RunError::Energy {
            netlist: netlist.to_owned(),
            message,
        }),
        None => Ok(energy),
    }
}

/// `None` without `[arc]`, or when the netlist has no contact instance
/// (the deck names that error).
fn arc_setup(scenario: &Scenario, netlist_text: &str) -> Option<ArcSetup> {
    let section = scenario.arc.as_ref()?;
    let circuit = scenario.circuit.as_ref()?;
    let instance = netlist::instances_of(netlist_text, &circuit.subckt)
        .into_iter()
        .next()?;
    Some(ArcSetup {
        model: section.model(),
        vectors: ArcVectors::of(&instance),
        instance,
    })
}

impl ArcSetup {
    /// Every arc and breakdown of run `run` (named in errors) in `plot`.
    fn report(
        &self,
        (run, plot): (&'static str, &Plot),
        gap: &GapProfile,
        chatter: &Chatter,
        coil_offs: &[f64],
        netlist: &std::path::Path,
    ) -> Result<ArcReport, RunError> {
        crate::arc::analysis::analyze(plot, &self.instance, &self.model, gap, chatter, coil_offs)
            .map_err(|source| RunError::Arc {
                run,
                netlist: netlist.to_owned(),
                source,
            })
    }
}

/// The contact waveform of `chatter` as `scenario`'s `[contact]` section
/// describes it: constant `r_closed`, or the Holm law on the contact
/// force. Also returns the model of the ideal contact to compare with,
/// whose closed resistance is the settled one (for Holm: at the final
/// contact force).
pub fn contact_waveform(
    scenario: &Scenario,
    chatter: &Chatter,
) -> Result<(Waveform, ContactModel), RunError> {
    contact_waveform_of(scenario, scenario.surface(), chatter)
}

/// [`contact_waveform`] with the surface law `surface` (a plan's).
fn contact_waveform_of(
    scenario: &Scenario,
    surface: Surface,
    chatter: &Chatter,
) -> Result<(Waveform, ContactModel), RunError> {
    let origin = &scenario.origin;
    let mut model = ContactModel::from(&scenario.contact);
    let waveform_error = |source| RunError::Waveform {
        path: origin.clone(),
        source,
    };
    let mechanics_error = |source| RunError::Mechanics {
        path: origin.clone(),
        source,
    };
    let Some(holm) = scenario.contact.holm.as_ref().map(Holm::from) else {
        let waveform = Waveform::from_chatter(chatter, &model).map_err(waveform_error)?;
        return Ok((waveform, model));
    };
    let mechanics = scenario.mechanics()?;
    let mut failure = None;
    let waveform = Waveform::from_chatter_holm(chatter, &model, &holm, |times| {
        contact_forces(&mechanics, &surface, chatter, times).unwrap_or_else(|e| {
            failure = Some(e);
            vec![0.0; times.len()]
        })
    })
    .map_err(waveform_error)?;
    if let Some(e) = failure {
        return Err(mechanics_error(e));
    }
    if chatter.settle_time.is_some() {
        let settled = contact_forces(&mechanics, &surface, chatter, &[chatter.t_end])
            .map_err(mechanics_error)?;
        if settled[0] > 0.0 {
            model.r_closed = holm.resistance(settled[0], model.r_open);
        }
    }
    Ok((waveform, model))
}

/// s, the last change of contact state: the circuit must be simulated at
/// least this far for the run to show the whole chatter.
pub fn chatter_end(chatter: &Chatter) -> f64 {
    chatter.intervals.last().map_or(0.0, |iv| iv.start)
}

/// A contact that closes cleanly at `first_impact` and stays closed to
/// `t_end`: what the circuit would see without bounce.
pub fn ideal_waveform(
    first_impact: f64,
    t_end: f64,
    model: &ContactModel,
) -> Result<Waveform, WaveformError> {
    let intervals = [
        Interval {
            state: ContactState::Open,
            start: 0.0,
            end: first_impact,
        },
        Interval {
            state: ContactState::Closed,
            start: first_impact,
            end: t_end.max(first_impact),
        },
    ];
    Waveform::from_intervals(&intervals, model)
}
