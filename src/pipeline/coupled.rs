//! The coil in the user's own driver circuit: two-way coupling between
//! ngspice and the mechanics by waveform relaxation.
//!
//! Each iteration runs the whole circuit in ngspice with the coil's
//! inductance following the armature path of the previous iteration
//! ([`coil_include`]) and the contact
//! following its chatter, reads the coil's flux linkage ψ(t) back, and
//! runs the mechanics under the magnetic pull it makes,
//! F_m = ψ²/(2 μ0 N² A) ([`Coil::force_from_flux`]), which depends on the
//! flux alone and not on where the armature is ([`crate::coil::simulate_forced_path`]).
//! The new path goes into the next circuit run, after the coil and the
//! mechanics have been settled against that run's coil voltage with no
//! ngspice ([`crate::coil::accelerate`], unless `accelerate` is off): the same
//! fixed point in fewer runs. The first iteration holds
//! the armature closed, at the fixed contact: it probes the driver's
//! voltage with the coil's inductance of the long held stretch and of the
//! release tail, where the driver's voltage depends most on the coil
//! (a flyback diode conducting). The loop stops when no event time (lift-off
//! excluded: every impact and release) moves by more than the tolerance
//! between two iterations, and fails when it has not after the allowed
//! number of iterations, reporting the last change.
//!
//! The passes use ngspice as it is, in batch runs, with the user's driver
//! untouched, and each half keeps its own exact event handling. Where
//! ngspice's shared library (libngspice) loads, the default is the
//! lock-step run instead ([`super::lockstep`]): one ngspice run with the
//! mechanics advanced at every time step; the passes remain the scheme
//! wherever the library is missing, and on request (see docs/coupling.md
//! for both, measured against each other).

use std::path::PathBuf;
use std::time::Duration;

use thiserror::Error;

use crate::arc::ArcVectors;
use crate::arc::GapProfile;
use crate::chatter::{Chatter, ContactState, Interval};
use crate::coil::accelerate::{CircuitRun, CouplingTolerances, settle};
use crate::coil::pick_up::{LoadLine, drop_out, pick_up};
#[cfg(test)]
use crate::coil::samples::interpolate_at;
use crate::coil::samples::{Interpolator, back_of, event_change, thin};
use crate::coil::timing::{CoilLevels, Operation, Switching, operations};
use crate::coil::{Coil, CoilError};
use crate::mechanics::Mechanics;
use crate::mechanics::Trajectory;
use crate::mechanics::cycle::{Stops, Stroke};
use crate::mechanics::two_stage::driven_run;
use crate::netlist::arc::with_arc;
use crate::netlist::coil::coil_include;
use crate::netlist::{
    self, ContactElement, Deck, DeckRequest, NetlistError, contact_include, instances_of,
};
use crate::plan::Plan;
use crate::rawfile::{Plot, Vector};
use crate::scenario::{Scenario, ScenarioError};
use crate::spice::{RunRequest, Runner, SpiceError};
use crate::waveform::{ContactModel, Waveform, WaveformError};

/// The include names in the run's work directory.
const CONTACT_FILE: &str = "contact.inc";
/// The coil include's file name in the run's work directory (and in
/// `--out`), which the deck `.include`s.
pub const COIL_FILE: &str = "coil.inc";

/// How to iterate.
#[derive(Debug, Clone, PartialEq)]
pub struct CouplingOptions {
    /// s: converged when no impact or release time moves more than this.
    pub tolerance: f64,
    /// The most iterations (one ngspice run each) before the run fails
    /// as not converged.
    pub max_iterations: usize,
    /// Wall-clock limit of each ngspice run.
    pub timeout: Duration,
    /// Keep every pass's ngspice work directory (they are named in the
    /// warnings of `run`).
    pub keep_workdir: bool,
    /// Settle the coil and the mechanics against each ngspice run's coil
    /// voltage before the next run (see [`crate::coil::accelerate`]); `false`
    /// is the plain relaxation, which hands the mechanics' path straight
    /// back to ngspice. Both converge to the same events.
    pub accelerate: bool,
    /// The passes' armature path, as given to ngspice, follows the
    /// mechanics within this fraction of the total air gap at rest
    /// ([`PATH_TOLERANCE`] by default; the lock-step run gives ngspice the
    /// armature's exact position and does not use it).
    pub path_tolerance: f64,
    /// How the coil and the armature are coupled: `None` picks the
    /// lock-step run when ngspice's shared library is there, else passes.
    pub coupling: Option<Coupling>,
}

/// How a coil-driven run couples the coil and the armature.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Coupling {
    /// One ngspice run through the shared library, the mechanics advanced
    /// with its time steps ([`super::lockstep`]).
    LockStep,
    /// Whole ngspice runs repeated until the events stop moving (waveform
    /// relaxation).
    Passes,
}

impl Coupling {
    /// The name used in options and JSON: `lock-step`, `passes`.
    pub fn as_str(self) -> &'static str {
        match self {
            Coupling::LockStep => "lock-step",
            Coupling::Passes => "passes",
        }
    }
}

impl std::str::FromStr for Coupling {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim() {
            "lock-step" | "lockstep" => Ok(Coupling::LockStep),
            "passes" => Ok(Coupling::Passes),
            other => Err(format!(
                "unknown coupling `{other}`: use `lock-step` or `passes`"
            )),
        }
    }
}

impl Default for CouplingOptions {
    /// 0.1 µs is far below any relay's bounce (tens of µs) and well above
    /// the integrators' precision. Settled against each run's coil
    /// voltage, a whole cycle converges in three to five ngspice passes
    /// (the plain relaxation took five to eleven, a slow diode release the
    /// most): twenty allows for both schemes.
    fn default() -> Self {
        CouplingOptions {
            tolerance: 1e-7,
            max_iterations: 20,
            timeout: RunRequest::DEFAULT_TIMEOUT,
            keep_workdir: false,
            accelerate: true,
            path_tolerance: PATH_TOLERANCE,
            coupling: None,
        }
    }
}

/// One pass of the loop.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Iteration {
    /// s, the normally-open contact's first impact in this pass's
    /// mechanics; `None` if it never closed.
    pub first_impact: Option<f64>,
    /// The normally-open contact's bounce count in this pass's mechanics
    /// ([`Chatter::bounce_count`]).
    pub bounces: usize,
    /// s, the largest move of an event time from the previous iteration
    /// (infinite when the number of events changed).
    pub change: f64,
    /// s, ngspice's wall time.
    pub ngspice_elapsed: f64,
    /// How this ngspice run was coupled: `lock-step` (then the only one,
    /// and `change` is between the run's own events and the mechanics run
    /// again under its flux) or `passes`.
    pub scheme: Coupling,
}

/// A converged coupled run.
#[derive(Debug, Clone, PartialEq)]
pub struct Coupled {
    /// The normally-open contact over the whole run (see
    /// [`crate::coil::Cycle::make`]).
    pub chatter: Chatter,
    /// The rest stop as the normally-closed contact.
    pub back: Chatter,
    /// The coil switching found in the circuit.
    pub switching: Switching,
    /// The levels the coil's drive was read against (drop-out, pick-up).
    pub levels: CoilLevels,
    /// Each stroke with its timing.
    pub operations: Vec<Operation>,
    /// (s, m): the armature's path.
    pub path: Vec<(f64, f64)>,
    /// The circuit's last run (with the final path and chatter, up to the
    /// last iteration's change): the transient plot.
    pub plot: Plot,
    /// The coil instance in the netlist, e.g. `x2`: its current is
    /// `i(v.x2.vi)`, its flux linkage `v(x2.psi)`.
    pub coil_instance: String,
    /// Every pass of the loop, in order; the last one converged.
    pub iterations: Vec<Iteration>,
    /// The deck of the last circuit run: the user's netlist with the
    /// contact and coil `.include`s.
    pub deck: Deck,
    /// ngspice's version, e.g. `"39"`.
    pub version: Option<String>,
    /// What ngspice printed on the last circuit run.
    pub log: String,
    /// A relay with a pole face: the armature's impacts on it.
    pub pole_face: Vec<crate::chatter::Impact>,
    /// Why the run was coupled by passes although lock-step was asked for
    /// or would have been the default (said once per process).
    pub fallback: Option<String>,
}

impl Coupled {
    /// (s, A): the coil current of the last circuit run.
    pub fn current(&self) -> Vec<(f64, f64)> {
        series(&self.plot, &current_vector(&self.coil_instance)).unwrap_or_default()
    }

    /// (s, V): the voltage across the coil in the last circuit run.
    pub fn voltage(&self) -> Vec<(f64, f64)> {
        series(&self.plot, &voltage_vector(&self.coil_instance)).unwrap_or_default()
    }
}

/// The coil instance's current vector, e.g. `i(v.x2.vi)`.
pub fn current_vector(instance: &str) -> String {
    format!("i(v.{instance}.vi)")
}

/// The vector of the voltage across coil instance `instance`, e.g.
/// `v(x2.vt)`.
pub fn voltage_vector(instance: &str) -> String {
    format!("v({instance}.vt)")
}

/// The coil's flux-linkage vector, e.g. `v(x2.psi)`.
pub fn flux_vector(instance: &str) -> String {
    format!("v({instance}.psi)")
}

/// Why a coupled run failed.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum CouplingError {
    /// The scenario has no `[coil]`.
    #[error(
        "{}: no [coil] section: the coupled run needs the coil (resistance, turns, \
         pole_area, air_gap, iron_gap)",
        path.display()
    )]
    NoCoil {
        /// The scenario file.
        path: PathBuf,
    },
    /// The scenario has no `[circuit]`, so there is no driver to run.
    #[error(
        "{}: no [circuit] section: the coupled run needs the driver netlist that \
         instantiates the coil (X2 a b COIL) and the contact (X1 a b CONTACT)",
        path.display()
    )]
    NoCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// The netlist does not instantiate the coil subcircuit exactly once.
    #[error(
        "{}: the coil subcircuit `{subckt}` must be instantiated exactly once in the netlist \
         itself (found {found}), so that its current can be read back",
        netlist.display()
    )]
    CoilInstances {
        /// The user's netlist.
        netlist: PathBuf,
        /// The coil subcircuit's name (`circuit.coil_subckt`).
        subckt: String,
        /// How many instances of it the netlist has.
        found: usize,
    },
    /// `circuit.nc_subckt` names a subcircuit the netlist does not
    /// instantiate.
    #[error(
        "{}: `circuit.nc_subckt` = `{subckt}` is not instantiated in the netlist: add \
         an X line for the normally-closed contact (X3 a b {subckt}), or remove the key",
        netlist.display()
    )]
    NcNotInstantiated {
        /// The user's netlist.
        netlist: PathBuf,
        /// The normally-closed contact's subcircuit name
        /// (`circuit.nc_subckt`).
        subckt: String,
    },
    /// The scenario does not validate, or its netlist cannot be read
    /// (see [`Plan::new`]).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// An include (the contact's, the normally-closed contact's or the
    /// coil's) or the run deck could not be built.
    #[error(transparent)]
    Netlist(#[from] NetlistError),
    /// A contact's conductance over time could not be built from its
    /// chatter.
    #[error("{}: the contact waveform", path.display())]
    Waveform {
        /// The scenario file.
        path: PathBuf,
        /// Why the waveform could not be built.
        #[source]
        source: WaveformError,
    },
    /// The coil's parameters are invalid (iteration 0), or the mechanics
    /// under the coil's pull failed.
    #[error("{}: iteration {iteration}: the mechanics under the coil's pull", path.display())]
    Coil {
        /// The scenario file.
        path: PathBuf,
        /// The iteration, from 1; 0 for the check of the coil before the
        /// first.
        iteration: usize,
        /// Why the coil or the mechanics failed.
        #[source]
        source: CoilError,
    },
    /// ngspice failed on one iteration's circuit run.
    #[error("ngspice failed in iteration {iteration} of the coupled run of {}", netlist.display())]
    Spice {
        /// The user's netlist.
        netlist: PathBuf,
        /// The iteration, from 1.
        iteration: usize,
        /// The ngspice error.
        #[source]
        source: Box<SpiceError>,
    },
    /// An iteration's raw file lacks a vector the coupling reads back (or
    /// has no transient plot at all).
    #[error(
        "the raw file of iteration {iteration} has no `{vector}`: the coil's flux linkage \
         (a transient analysis is needed)"
    )]
    MissingVector {
        /// The iteration, from 1.
        iteration: usize,
        /// The vector's name, e.g. `v(x2.psi)`, or `time` for a plot with
        /// no real time scale.
        vector: String,
    },
    /// The event times still moved by more than the tolerance after the
    /// allowed number of iterations.
    #[error(
        "{}: the coupling did not converge in {iterations} iterations: event times still \
         moved by {change:e} s (tolerance {tolerance:e} s); allow more iterations \
         (`--max-iterations`), or look \
         for a drive that chatters itself",
        netlist.display()
    )]
    NotConverged {
        /// The user's netlist.
        netlist: PathBuf,
        /// The number of iterations run (`max_iterations`).
        iterations: usize,
        /// s, the last iteration's largest move of an event time
        /// (infinite when the number of events changed).
        change: f64,
        /// s, the tolerance it had to come within.
        tolerance: f64,
    },
}

/// Run `scenario`'s `[coil]` in its `[circuit]` until the armature path
/// and the circuit agree.
pub fn run_coupled(
    scenario: &Scenario,
    runner: &dyn Runner,
    options: &CouplingOptions,
) -> Result<Coupled, CouplingError> {
    run_coupled_plan(&Plan::new(scenario.clone())?, runner, options)
}

/// [`run_coupled`] of a [`Plan`].
pub fn run_coupled_plan(
    plan: &Plan,
    runner: &dyn Runner,
    options: &CouplingOptions,
) -> Result<Coupled, CouplingError> {
    let setup = Setup::of(plan)?;
    let fallback = match lock_step(&setup, runner, options)? {
        Ok(coupled) => return Ok(coupled),
        Err(fallback) => fallback,
    };
    passes(&setup, runner, options, fallback)
}

/// What a coupled run reads from its plan once: the coil and its levels,
/// the circuit and its netlist, the one coil instance and the vectors
/// read from it, the relay and its contact, and the signals to save.
struct Setup<'a> {
    origin: PathBuf,
    section: &'a crate::scenario::CoilSection,
    coil: Coil,
    levels: CoilLevels,
    circuit: &'a crate::scenario::CircuitSection,
    netlist_path: PathBuf,
    netlist_text: &'a str,
    coil_instance: String,
    mechanics: Mechanics,
    stops: Stops,
    settings: crate::mechanics::Settings,
    build: crate::mechanics::two_stage::TwoStage,
    model: ContactModel,
    /// The coil's flux, voltage and current vectors.
    psi: String,
    volts: String,
    signals: Vec<String>,
    arc: Option<crate::arc::ArcModel>,
}

impl<'a> Setup<'a> {
    fn of(plan: &'a Plan) -> Result<Setup<'a>, CouplingError> {
        let scenario = plan.scenario();
        let origin = scenario.origin.clone();
        let section = scenario
            .coil
            .as_ref()
            .ok_or_else(|| CouplingError::NoCoil {
                path: origin.clone(),
            })?;
        let coil = Coil::from(section);
        let levels = coil_levels(scenario, &coil);
        let circuit = scenario
            .circuit
            .as_ref()
            .ok_or_else(|| CouplingError::NoCircuit {
                path: origin.clone(),
            })?;
        let netlist = plan
            .netlist()
            .expect("there is a [circuit], so the plan read its netlist");
        let (netlist_path, netlist_text) = (netlist.path.clone(), netlist.text.as_str());
        let instances = instances_of(netlist_text, &circuit.coil_subckt);
        let [coil_instance] = instances.as_slice() else {
            return Err(CouplingError::CoilInstances {
                netlist: netlist_path,
                subckt: circuit.coil_subckt.clone(),
                found: instances.len(),
            });
        };
        if let Some(nc) = &circuit.nc_subckt {
            if instances_of(netlist_text, nc).is_empty() {
                return Err(CouplingError::NcNotInstantiated {
                    netlist: netlist_path,
                    subckt: nc.clone(),
                });
            }
        }
        // The coil makes the force.
        let mechanics = Mechanics {
            force: 0.0,
            ..scenario.armature()
        };
        coil.validate(mechanics.gap)
            .map_err(|source| CouplingError::Coil {
                path: origin.clone(),
                iteration: 0,
                source,
            })?;
        let stops = Stops {
            make: plan.surface(),
            back: plan.back_stop(),
        };
        let settings = plan.settings();
        let build = plan.two_stage();
        let model = ContactModel::from(&scenario.contact);
        let psi = flux_vector(coil_instance);
        let volts = voltage_vector(coil_instance);
        let current = current_vector(coil_instance);
        // The coil's own vectors too, in case the netlist `.save`s only some.
        let mut signals: Vec<&str> = scenario.probes.iter().map(|p| p.signal.as_str()).collect();
        signals.extend([psi.as_str(), volts.as_str(), current.as_str()]);
        // With [arc], the contact carries the arc in every pass.
        let arc = scenario.arc.map(|a| a.model());
        let arc_vectors = instances_of(netlist_text, &circuit.subckt)
            .first()
            .map(|instance| ArcVectors::of(instance));
        if let (Some(_), Some(vectors)) = (&arc, &arc_vectors) {
            signals.extend(vectors.all());
        }
        Ok(Setup {
            origin,
            section,
            coil,
            levels,
            circuit,
            netlist_path,
            netlist_text,
            coil_instance: coil_instance.clone(),
            mechanics,
            stops,
            settings,
            build,
            model,
            signals: signals.into_iter().map(str::to_owned).collect(),
            psi,
            volts,
            arc,
        })
    }

    /// The signals to save, as the deck takes them.
    fn probes(&self) -> Vec<&str> {
        self.signals.iter().map(String::as_str).collect()
    }

    /// The run's result from the pass it ends on (`iteration`): the
    /// motion's `records`, ngspice's plot, deck, version and log, and the
    /// coil's switching read from the plot, with the passes so far and
    /// why lock-step was not kept.
    fn coupled(
        &self,
        records: PassRecords,
        (plot, deck, version, log): (Plot, Deck, Option<String>, String),
        iteration: usize,
        iterations: Vec<Iteration>,
        fallback: Option<String>,
    ) -> Result<Coupled, CouplingError> {
        let (chatter, back, path, strokes, pole_face) = records;
        let switching = switching_of(&plot, &self.volts, &self.levels, iteration)?;
        Ok(Coupled {
            operations: operations(&strokes, &chatter.impacts, &switching),
            levels: self.levels,
            switching,
            chatter,
            back,
            path,
            plot,
            coil_instance: self.coil_instance.clone(),
            iterations,
            deck,
            version,
            log,
            pole_face,
            fallback,
        })
    }

    /// The motion of pass `iteration` (`cycle`, under the flux `flux` of
    /// its `plot`, the armature's path having been `path`) settled
    /// against the coil's own circuit as ngspice ran it, before the next
    /// pass (docs/coupling.md).
    fn settled(
        &self,
        plot: &Plot,
        flux: &[(f64, f64)],
        path: &[(f64, f64)],
        cycle: Trajectory,
        options: &CouplingOptions,
        iteration: usize,
    ) -> Result<Trajectory, CouplingError> {
        let Some(Vector::Real(time)) = plot.scale() else {
            return Err(CouplingError::MissingVector {
                iteration,
                vector: "time".to_owned(),
            });
        };
        let coil_volts = plot
            .real(&self.volts)
            .ok_or_else(|| CouplingError::MissingVector {
                iteration,
                vector: self.volts.clone(),
            })?;
        let flux_values: Vec<f64> = flux.iter().map(|&(_, v)| v).collect();
        let run = CircuitRun {
            time,
            volts: coil_volts,
            flux: &flux_values,
            path,
        };
        let thinning = options.path_tolerance * (self.coil.air_gap + self.coil.iron_gap);
        let (next, _) = settle(
            &self.coil,
            &run,
            cycle,
            &self.mechanics,
            &self.build,
            &self.stops,
            &self.settings,
            CouplingTolerances {
                events: options.tolerance,
                path: thinning,
            },
        )
        .map_err(|source| CouplingError::Coil {
            path: self.origin.clone(),
            iteration,
            source,
        })?;
        Ok(next)
    }

    /// The user's deck with the contact's and the coil's includes and
    /// the signals to save, run to at least `end`.
    fn deck(&self, end: f64) -> Result<Deck, CouplingError> {
        let probes = self.probes();
        Ok(netlist::prepare_deck_with_params(
            &DeckRequest {
                netlist_text: self.netlist_text,
                netlist_path: &self.netlist_path,
                include_file_name: CONTACT_FILE,
                subckt: &self.circuit.subckt,
                coil: Some((COIL_FILE, &self.circuit.coil_subckt)),
                probes: &probes,
                chatter_end: end,
                stop_at_least: end,
                options: if self.arc.is_some() {
                    &[crate::netlist::arc::ARC_OPTIONS]
                } else {
                    &[]
                },
            },
            &self.circuit.param_list(),
        )?)
    }

    /// One ngspice run of `deck` with `includes`, as pass `iteration`.
    fn pass(
        &self,
        runner: &dyn Runner,
        deck: &Deck,
        includes: Vec<(String, String)>,
        options: &CouplingOptions,
        iteration: usize,
    ) -> Result<super::pass::Simulation, CouplingError> {
        super::pass::circuit_pass(
            runner,
            super::pass::Pass {
                run: "coupled",
                netlist: &self.netlist_path,
                deck,
                includes,
                timeout: options.timeout,
                keep_workdir: options.keep_workdir,
            },
        )
        .map_err(|e| match e {
            super::pass::PassError::Spice { source, .. } => CouplingError::Spice {
                netlist: self.netlist_path.clone(),
                iteration,
                source,
            },
            _ => CouplingError::MissingVector {
                iteration,
                vector: self.psi.clone(),
            },
        })
    }

    /// The coil's flux in `plot` and the relay's motion under its pull,
    /// in pass `iteration`.
    fn mechanics_under(
        &self,
        plot: &Plot,
        iteration: usize,
    ) -> Result<(Vec<(f64, f64)>, Trajectory), CouplingError> {
        let flux = series(plot, &self.psi).ok_or_else(|| CouplingError::MissingVector {
            iteration,
            vector: self.psi.clone(),
        })?;
        let flux_at = Interpolator::new(&flux);
        let pull = |t: f64, _x: f64| self.coil.force_from_flux(flux_at.at(t));
        let cycle = driven_run(
            &self.mechanics,
            &self.build,
            &self.stops,
            &self.settings,
            &pull,
        )
        .map_err(|source| CouplingError::Coil {
            path: self.origin.clone(),
            iteration,
            source,
        })?;
        Ok((flux, cycle))
    }
}

/// The coupled run in lock-step, ngspice's shared library calling the
/// mechanics at every time point: `Ok(Err(note))` where it is not run
/// that way (`note`: why, or `None` when passes were asked for) or its
/// result is not kept (its own events and the mechanics under its flux
/// differ by more than the tolerance), and the passes run instead.
fn lock_step(
    setup: &Setup<'_>,
    runner: &dyn Runner,
    options: &CouplingOptions,
) -> Result<Result<Coupled, Option<String>>, CouplingError> {
    let library = match lock_step_library(options, runner) {
        Ok(library) => library,
        Err(note) => return Ok(Err(note)),
    };
    let (coil, mechanics, stops, settings, build, model, arc) = (
        setup.coil,
        setup.mechanics,
        setup.stops,
        setup.settings,
        setup.build,
        setup.model,
        setup.arc,
    );
    let (section, circuit) = (setup.section, setup.circuit);
    let coil_instance = &setup.coil_instance;
    let relay = super::lockstep::Relay {
        mechanics,
        build,
        stops,
        settings,
        coil,
        contact: model,
        flux: format!("{coil_instance}.psi").to_ascii_lowercase(),
        arc,
    };
    let lock = super::lockstep::LockStepRunner::new(library, relay);
    let mut contact = super::lockstep::contact_include(
        &circuit.subckt,
        super::lockstep::MAKE_SOURCE,
        arc.as_ref(),
        setup.mechanics.gap - setup.mechanics.initial_position,
    )?;
    if let Some(nc) = &circuit.nc_subckt {
        contact.push_str(&super::lockstep::contact_include(
            nc,
            super::lockstep::BREAK_SOURCE,
            None,
            0.0,
        )?);
    }
    let deck = setup.deck(0.0)?;
    let includes = vec![
        (CONTACT_FILE.to_owned(), contact),
        (
            COIL_FILE.to_owned(),
            netlist::coil::coil_include_external(section, &circuit.coil_subckt)?,
        ),
    ];
    let simulation = setup.pass(&lock, &deck, includes, options, 1)?;
    let stats = lock.last_stats().unwrap_or_default();
    let plot = simulation.plot;
    let (_, cycle) = setup.mechanics_under(&plot, 1)?;
    // The rest stop's changes count where the circuit has the
    // normally-closed contact to see them.
    let mut change = changes_moved(&stats.make_changes, &cycle.chatter().intervals);
    if circuit.nc_subckt.is_some() {
        change = change.max(changes_moved(
            &stats.break_changes,
            &back_of(&cycle).intervals,
        ));
    }
    if change <= options.tolerance {
        let iterations = vec![Iteration {
            first_impact: cycle.chatter().first_impact,
            bounces: cycle.chatter().bounce_count,
            change,
            ngspice_elapsed: simulation.elapsed.as_secs_f64(),
            scheme: Coupling::LockStep,
        }];
        let thinning = options.path_tolerance * (coil.air_gap + coil.iron_gap);
        let ngspice = (plot, deck, simulation.version, simulation.log);
        return setup
            .coupled(records(cycle, thinning), ngspice, 1, iterations, None)
            .map(Ok);
    }
    Ok(Err(Some(if change.is_finite() {
        format!(
            "the lock-step run's own events and the mechanics under its flux differ \
                 by {change:e} s, more than the coupling tolerance ({:e} s): the coupling \
                 was run again as passes",
            options.tolerance
        )
    } else {
        // Seen when another user of the library in this process
        // (PySpice, a ctypes binding) initialised it before us.
        "the lock-step run's own events and the mechanics under its flux do not have \
             the same contact changes (another user of ngspice's shared library in this \
             process, such as PySpice, can cause this): the coupling was run again as \
             passes"
            .to_owned()
    })))
}

/// The coupled run as passes: each ngspice run with the contact and the
/// coil's armature path of the last, until no event moves more than the
/// tolerance. `fallback`: why lock-step was not run or kept.
fn passes(
    setup: &Setup<'_>,
    runner: &dyn Runner,
    options: &CouplingOptions,
    fallback: Option<String>,
) -> Result<Coupled, CouplingError> {
    let (coil, settings, model, arc) = (setup.coil, setup.settings, setup.model, setup.arc);
    let (origin, section, circuit) = (&setup.origin, setup.section, setup.circuit);
    let netlist_path = setup.netlist_path.clone();
    // Iteration 0, the probe of the driver: the coil with the armature
    // held closed (its inductance while the contact is held and through the
    // release tail, the slow part of the coupling; docs/coupling.md), the
    // contacts as before any motion: NO open, NC closed.
    let mut chatter = steady_chatter(ContactState::Open, settings.t_end);
    let mut back = steady_chatter(ContactState::Closed, settings.t_end);
    let mut path = vec![(0.0, setup.mechanics.gap)];
    let mut iterations: Vec<Iteration> = Vec::new();
    for iteration in 1..=options.max_iterations {
        let waveform =
            Waveform::from_chatter(&chatter, &model).map_err(|source| CouplingError::Waveform {
                path: origin.clone(),
                source,
            })?;
        let mut contact = contact_include(
            &waveform,
            &circuit.subckt,
            ContactElement::for_waveform(&waveform),
        )?;
        if let Some(arc) = &arc {
            // The probe's contact is open at its rest gap, whatever the
            // coil's armature does.
            let gap = if iteration == 1 {
                GapProfile::from_path(
                    setup.mechanics.gap,
                    &[(0.0, setup.mechanics.initial_position)],
                )
            } else {
                GapProfile::from_path(setup.mechanics.gap, &path)
            };
            contact = with_arc(contact, arc, &gap)?;
        }
        if let Some(nc) = &circuit.nc_subckt {
            contact
                .text
                .push_str(&nc_include(&back, &model, nc, origin)?);
        }
        let end = chatter.intervals.last().map_or(0.0, |iv| iv.start);
        let deck = setup.deck(end)?;
        let mut includes = vec![
            (CONTACT_FILE.to_owned(), contact.text),
            (
                COIL_FILE.to_owned(),
                coil_include(section, &circuit.coil_subckt, &path)?,
            ),
        ];
        includes.extend(contact.data_files);
        let simulation = setup.pass(runner, &deck, includes, options, iteration)?;
        let ngspice_elapsed = simulation.elapsed.as_secs_f64();
        let version = simulation.version;
        let log = simulation.log;
        let plot = simulation.plot;
        let (flux, cycle) = setup.mechanics_under(&plot, iteration)?;
        let change =
            event_change(&chatter, cycle.chatter()).max(event_change(&back, back_of(&cycle)));
        iterations.push(Iteration {
            first_impact: cycle.chatter().first_impact,
            bounces: cycle.chatter().bounce_count,
            change,
            ngspice_elapsed,
            scheme: Coupling::Passes,
        });
        let converged = change <= options.tolerance && iteration > 1;
        let thinning = options.path_tolerance * (coil.air_gap + coil.iron_gap);
        let (strokes, pole_face) = if converged || !options.accelerate {
            let (strokes, pole_face);
            (chatter, back, path, strokes, pole_face) = records(cycle, thinning);
            (strokes, pole_face)
        } else {
            let next = setup.settled(&plot, &flux, &path, cycle, options, iteration)?;
            (chatter, back, path, _, _) = records(next, thinning);
            continue;
        };
        if converged {
            let records = (chatter, back, path, strokes, pole_face);
            let ngspice = (plot, deck, version, log);
            return setup.coupled(records, ngspice, iteration, iterations, fallback);
        }
    }
    Err(CouplingError::NotConverged {
        netlist: netlist_path,
        iterations: options.max_iterations,
        change: iterations.last().map_or(f64::INFINITY, |i| i.change),
        tolerance: options.tolerance,
    })
}

/// The levels `coil`'s drive is read against: the drop-out and pick-up
/// voltages of the relay of `scenario` (its magnet against its load line),
/// and the coil's L/R with the armature open.
pub fn coil_levels(scenario: &Scenario, coil: &Coil) -> CoilLevels {
    let line = LoadLine::of_relay(&scenario.armature(), &scenario.two_stage());
    CoilLevels {
        drop_out_voltage: drop_out(coil, &line).voltage,
        pick_up_voltage: pick_up(coil, &line).voltage,
        time_constant: coil.inductance(0.0) / coil.resistance,
    }
}

/// The coil's switching in `plot`, read from the voltage across it
/// (`volts`) against `levels`, of ngspice run `iteration`.
fn switching_of(
    plot: &Plot,
    volts: &str,
    levels: &CoilLevels,
    iteration: usize,
) -> Result<Switching, CouplingError> {
    let vector = |name: &str| {
        plot.real(name).ok_or_else(|| CouplingError::MissingVector {
            iteration,
            vector: name.to_owned(),
        })
    };
    let Some(Vector::Real(time)) = plot.scale() else {
        return Err(CouplingError::MissingVector {
            iteration,
            vector: "time".to_owned(),
        });
    };
    Ok(Switching::from_coil(time, vector(volts)?, levels))
}

/// The shared library to run a lock-step coupling with, or why not (a
/// note for the user when lock-step was asked for, or would have been the
/// default and is missing: said once per process).
fn lock_step_library(
    options: &CouplingOptions,
    runner: &dyn Runner,
) -> Result<&'static crate::spice::shared::Library, Option<String>> {
    static SAID: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    let asked = match options.coupling {
        Some(Coupling::Passes) => return Err(None),
        Some(Coupling::LockStep) => true,
        None => false,
    };
    let once = |note: String| {
        (asked || !SAID.swap(true, std::sync::atomic::Ordering::SeqCst)).then_some(note)
    };
    if !runner.lock_step() {
        return Err(asked
            .then(|| "this runner runs whole decks only: the coupling ran as passes".to_owned()));
    }
    crate::spice::shared::library().map_err(|why| {
        once(format!(
            "{why}; the coupling ran as passes instead of lock-step"
        ))
    })
}

/// s, the largest move between the change times `a` and the changes of
/// `intervals`; infinite when their numbers differ.
fn changes_moved(a: &[f64], intervals: &[Interval]) -> f64 {
    let b: Vec<f64> = intervals.iter().skip(1).map(|iv| iv.start).collect();
    if a.len() != b.len() {
        return f64::INFINITY;
    }
    a.iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// How closely the armature path given to the circuit follows the
/// mechanics, relative to the total air gap at rest: the coil current
/// `ψ (g_a + l_eq − x)/(μ0 N² A)` then moves by less than 1e-4 of itself
/// wherever the armature is (the smallest gap left, at the contact, is
/// some tenths of the gap at rest), far below what moves an impact by
/// the coupling's tolerance; a flight is then some hundred points, as
/// many as ngspice's own steps over it.
///
/// It leaves a bias of its own, though: on `solenoid.toml` the armature's
/// return onto its rest stop, 4 ms of flight under the decaying flux after
/// the release, lands 0.2 µs later with this path than with a path a
/// hundred times closer (which the lock-step run's exact position agrees
/// with to 33 ns).
pub const PATH_TOLERANCE: f64 = 1e-5;

/// The normally-closed contact's subcircuit `subckt`, following the
/// rest stop's chatter `back`, with the NO contact's electrical model: a
/// PWL include appended to the contact's (its few dozen points never need
/// the event-driven element, which would also need a data file).
pub fn nc_include(
    back: &Chatter,
    model: &ContactModel,
    subckt: &str,
    origin: &std::path::Path,
) -> Result<String, CouplingError> {
    let waveform =
        Waveform::from_chatter(back, model).map_err(|source| CouplingError::Waveform {
            path: origin.to_owned(),
            source,
        })?;
    Ok(contact_include(&waveform, subckt, ContactElement::Pwl)?.text)
}

/// The records a pass hands on: the two contacts' chatter, the armature
/// path thinned to `thinning` (m) for ngspice, and the strokes.
fn records(trajectory: Trajectory, thinning: f64) -> PassRecords {
    let path = thin(&trajectory.path(), thinning);
    let strokes = trajectory.strokes().to_vec();
    let pole_face = trajectory.pole_face_impacts().to_vec();
    let (make, back) = trajectory.into_contacts();
    let back = back.expect("a driven cycle records its rest stop");
    (make, back, path, strokes, pole_face)
}

/// What a converged pass hands on: the NO and NC contacts' records, the
/// armature's path, the strokes and the pole-face impacts.
type PassRecords = (
    Chatter,
    Chatter,
    Vec<(f64, f64)>,
    Vec<Stroke>,
    Vec<crate::chatter::Impact>,
);

/// A contact in `state` from 0 to `t_end`: before the first iteration,
/// the NO contact open and the NC contact closed (the armature at rest).
fn steady_chatter(state: ContactState, t_end: f64) -> Chatter {
    Chatter::from_intervals(vec![Interval {
        state,
        start: 0.0,
        end: t_end,
    }])
}

/// (time, value) of vector `name` in a transient plot.
fn series(plot: &Plot, name: &str) -> Option<Vec<(f64, f64)>> {
    let Some(Vector::Real(time)) = plot.scale() else {
        return None;
    };
    let values = plot.real(name)?;
    Some(time.iter().copied().zip(values.iter().copied()).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Linear interpolation in (time, value) samples, held beyond both ends.
    fn interpolate(samples: &[(f64, f64)], t: f64) -> f64 {
        interpolate_at(samples, t, samples.partition_point(|&(s, _)| s <= t))
    }

    #[test]
    fn the_cursor_gives_what_the_search_gives_in_any_order() {
        let samples: Vec<(f64, f64)> = (0..200)
            .map(|k| {
                let t = f64::from(k) * 1e-3 + if k % 7 == 0 { 5e-4 } else { 0.0 };
                (t, (f64::from(k) * 0.37).sin())
            })
            .collect();
        let cursor = Interpolator::new(&samples);
        // Forward, backward, repeated, out of range, exactly on samples.
        let mut times: Vec<f64> = (0..2000).map(|k| f64::from(k) * 1.1e-4 - 0.01).collect();
        times.extend(times.clone().into_iter().rev());
        times.extend(samples.iter().map(|s| s.0));
        times.extend([0.1, 0.05, 0.1500001, -1.0, 1.0, 0.05]);
        for t in times {
            assert_eq!(cursor.at(t), interpolate(&samples, t), "at {t}");
        }
    }

    /// The thinning as first written: every chord checked against every
    /// point it passes (quadratic in a long straight stretch).
    fn thin_by_rescanning(path: &[(f64, f64)], tolerance: f64) -> Vec<(f64, f64)> {
        let mut out = vec![path[0]];
        let (mut start, mut end) = (0, 2);
        while end < path.len() {
            let ((t0, x0), (t1, x1)) = (path[start], path[end]);
            let fits = path[start + 1..end].iter().all(|&(t, x)| {
                let line = x0 + (x1 - x0) * (t - t0) / (t1 - t0);
                (x - line).abs() <= tolerance
            });
            if fits {
                end += 1;
            } else {
                start = end - 1;
                out.push(path[start]);
                end = start + 2;
            }
        }
        if path.len() > 1 {
            out.push(path[path.len() - 1]);
        }
        out
    }

    #[test]
    fn thinning_in_one_pass_keeps_the_points_the_rescan_kept() {
        // A bouncing path: flights, flat holds and noise at the tolerance.
        let path: Vec<(f64, f64)> = (0..5000)
            .map(|k| {
                let t = f64::from(k) * 1e-6;
                let x = (4e-4 * (t * 2e3).sin().abs()).min(3e-4)
                    + 1e-9 * (f64::from(k) * 12.9898).sin();
                (t, x)
            })
            .collect();
        for tol in [1e-10, 1e-9, 1e-8, 1e-6] {
            assert_eq!(thin(&path, tol), thin_by_rescanning(&path, tol), "{tol}");
        }
    }

    #[test]
    fn thinning_keeps_the_shape_within_the_tolerance() {
        // A parabola sampled finely, then a long rest.
        let mut path: Vec<(f64, f64)> = (0..=1000)
            .map(|k| {
                let t = f64::from(k) * 1e-6;
                (t, 4e-4 * (t / 1e-3).powi(2))
            })
            .collect();
        path.extend((1..=1000).map(|k| (1e-3 + f64::from(k) * 1e-6, 4e-4)));
        let tol = 1e-9;
        let thin = thin(&path, tol);
        // A chord of a parabola x'' = 800 m/s² is off by x''·h²/8 at its
        // middle: 1 nm allows h = 3.2 µs, some 320 chords for the
        // millisecond, and one for the rest.
        assert!((300..360).contains(&thin.len()), "{}", thin.len());
        assert_eq!(thin.first(), path.first());
        assert_eq!(thin.last(), path.last());
        // Every original point is within the tolerance of the thinned line.
        for &(t, x) in &path {
            let k = thin.partition_point(|p| p.0 <= t).clamp(1, thin.len() - 1);
            let ((t0, x0), (t1, x1)) = (thin[k - 1], thin[k]);
            let line = x0 + (x1 - x0) * (t - t0) / (t1 - t0);
            assert!((x - line).abs() <= tol * (1.0 + 1e-9), "{t} {x} {line}");
        }
        assert_eq!(super::thin(&path[..1], tol), path[..1].to_vec());
        assert!(super::thin(&[], tol).is_empty());
    }
}
