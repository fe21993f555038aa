//! `run`, `check`, `envelope` and `life`: each the library's verdict
//! function of the command of that name (`chatterspice::verdict`), with
//! the command's options as keyword arguments of the same defaults. This
//! module only reads the arguments and presents the outcome: the report
//! is the outcome's own JSON, its warnings are issued as
//! `ChatterspiceWarning`s.

use std::path::PathBuf;
use std::time::Duration;

use chatterspice::envelope::{self, EnvelopeOptions};
use chatterspice::netlist::ContactElement;
use chatterspice::pipeline::{Coupling, RunOptions};
use chatterspice::spice::{Ngspice, SpiceError};
use chatterspice::verdict::{self, LazyNgspice, LifeOptions};
use pyo3::prelude::*;

use crate::error::{Failure, warn_all};
use crate::results::Run;
use crate::{args, json, load_scenario, read_measured, work};

/// How ngspice is run: the options `run`, `check`, `envelope`, `life`
/// and `sweep` share with the command line's.
#[derive(Debug, Clone)]
pub struct Simulator {
    pub timeout: Duration,
    pub element: Option<ContactElement>,
    pub coupling: Option<Coupling>,
    pub max_iterations: usize,
    pub coupling_tolerance: f64,
    pub ngspice: Option<PathBuf>,
    pub no_spiceinit: bool,
}

impl Simulator {
    /// ngspice, located (`ngspice`, else `$CHATTERSPICE_NGSPICE`, else on
    /// `PATH`) and probed within the timeout.
    pub fn locate(&self) -> Result<Ngspice, SpiceError> {
        Ok(
            Ngspice::locate_within(self.ngspice.as_deref(), self.timeout)?
                .skip_user_init(self.no_spiceinit),
        )
    }

    /// The run options these arguments set; the rest default.
    pub fn run_options(&self) -> RunOptions {
        RunOptions::simulator(
            self.timeout,
            self.element,
            self.coupling,
            self.max_iterations,
            self.coupling_tolerance,
        )
    }
}

/// The envelope's sampling, as `--samples`, `--seed` and `--jobs`.
fn envelope_options(
    samples: usize,
    seed: u64,
    jobs: Option<u64>,
    run: RunOptions,
) -> EnvelopeOptions {
    EnvelopeOptions {
        samples,
        seed,
        jobs: crate::jobs(jobs).unwrap_or_else(|| {
            std::thread::available_parallelism().unwrap_or(std::num::NonZeroUsize::MIN)
        }),
        run,
    }
}

/// The life options of `life_phases` and `no_life`.
fn life_options(phases: usize, no_life: bool) -> LifeOptions {
    LifeOptions {
        phases,
        estimate: !no_life,
        ..LifeOptions::default()
    }
}

/// The relay's chatter switching the scenario's circuit in ngspice, and
/// the analysis of every probe: the main job, as ``chatterspice run``.
///
/// Returns a Run: ``report`` (the JSON of ``chatterspice run --format
/// json``, with ``life`` for a scenario with endurance figures),
/// ``waveforms`` (every vector of the raw file as a float64 array:
/// ``time`` in s, voltages in V, currents in A), the ideal-contact run's
/// ``ideal_waveforms``, the ``deck`` and contact ``include`` ngspice ran,
/// its ``log``, and with ``keep_workdir`` the ``workdir`` and
/// ``raw_path`` left behind. The run's warnings are issued as
/// ``ChatterspiceWarning``.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``).
///     measured: a ``time,state`` CSV record switching the circuit
///         instead of the mechanics.
///     ideal: also run an ideal contact (one clean edge) and compare.
///     timeout: the wall-clock limit of each ngspice run, in s.
///     keep_workdir: leave ngspice's work directories (deck, includes,
///         raw file) in place and name them in the result.
///     element: how the contact is emitted: ``"pwl"``, ``"event-ramp"``
///         or ``"switch"``; default pwl, or event-ramp for sequences of
///         more than 2000 points.
///     coupling: with a ``[coil]``, ``"lock-step"`` (one ngspice run
///         through its shared library) or ``"passes"``; default
///         lock-step when the library is installed and the contact has
///         no ``[arc]``, else passes.
///     max_iterations: with a ``[coil]``, the most coupling passes.
///     coupling_tolerance: with a ``[coil]``, converged when no event
///         moves more than this between passes, in s.
///     ngspice: the ngspice program; default ``$CHATTERSPICE_NGSPICE``,
///         else ngspice on ``PATH``.
///     no_spiceinit: start ngspice without the user's ``~/.spiceinit``.
///     envelope: also run every relay the datasheet allows and lay the
///         bands into the report under ``envelope``.
///     samples, seed, jobs: the envelope's relays drawn, the seed of the
///         draw and the relays run at once (default one per core).
///     life_phases: switching phases averaged over an AC endurance
///         figure's period.
///     no_life: do not estimate the electrical life.
///
/// Raises InputError, FileNotFoundError, NgspiceError (ngspice missing,
/// failing or timing out), SimulationError; KeyboardInterrupt on Ctrl-C,
/// with every ngspice process killed and work directory removed.
#[pyfunction]
#[pyo3(name = "run", signature = (path=None, *, toml_text=None, origin=None, measured=None,
                                  ideal=true, timeout=Duration::from_secs(60),
                                  keep_workdir=false, element=None, coupling=None,
                                  max_iterations=20, coupling_tolerance=1e-7, ngspice=None,
                                  no_spiceinit=false, envelope=false, samples=32, seed=1,
                                  jobs=None, life_phases=chatterspice::life::DEFAULT_PHASES,
                                  no_life=false))]
#[pyo3(
    text_signature = "(path=None, *, toml_text=None, origin=None, measured=None, ideal=True, timeout=60.0, keep_workdir=False, element=None, coupling=None, max_iterations=20, coupling_tolerance=1e-07, ngspice=None, no_spiceinit=False, envelope=False, samples=32, seed=1, jobs=None, life_phases=16, no_life=False)"
)]
#[allow(clippy::too_many_arguments)]
pub fn py_run(
    py: Python<'_>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::measured_arg)] measured: Option<PathBuf>,
    #[pyo3(from_py_with = args::ideal_arg)] ideal: bool,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
    #[pyo3(from_py_with = args::keep_workdir_arg)] keep_workdir: bool,
    #[pyo3(from_py_with = args::element_arg)] element: Option<ContactElement>,
    #[pyo3(from_py_with = args::coupling_arg)] coupling: Option<Coupling>,
    #[pyo3(from_py_with = args::max_iterations_arg)] max_iterations: usize,
    #[pyo3(from_py_with = args::coupling_tolerance_arg)] coupling_tolerance: f64,
    #[pyo3(from_py_with = args::ngspice_arg)] ngspice: Option<PathBuf>,
    #[pyo3(from_py_with = args::no_spiceinit_arg)] no_spiceinit: bool,
    #[pyo3(from_py_with = args::envelope_arg)] envelope: bool,
    #[pyo3(from_py_with = args::envelope_samples_arg)] samples: usize,
    #[pyo3(from_py_with = args::envelope_seed_arg)] seed: u64,
    #[pyo3(from_py_with = args::jobs_arg)] jobs: Option<u64>,
    #[pyo3(from_py_with = args::life_phases_arg)] life_phases: usize,
    #[pyo3(from_py_with = args::no_life_arg)] no_life: bool,
) -> PyResult<Run> {
    let simulator = Simulator {
        timeout,
        element,
        coupling,
        max_iterations,
        coupling_tolerance,
        ngspice,
        no_spiceinit,
    };
    if envelope && measured.is_some() {
        return Err(Failure::input(
            "envelope=True samples the relay's mechanics, which measured= replaces",
        )
        .into());
    }
    let loaded = load_scenario(path, toml_text, origin)?;
    let intervals = measured.as_deref().map(read_measured).transpose()?;
    let options = RunOptions {
        compare_ideal: ideal,
        keep_workdir,
        ..simulator.run_options()
    };
    let life = life_options(life_phases, no_life);
    let scenario = loaded.scenario;
    let (outcome, text) = work::interruptible(py, None, move |_| -> Result<_, Failure> {
        let ngspice = simulator.locate()?;
        let outcome = verdict::run(&scenario, &ngspice, &options, intervals, &life)?;
        let mut text = outcome.json();
        if envelope {
            let sampling = envelope_options(samples, seed, jobs, options);
            let env = verdict::run_envelope(&scenario, &ngspice, &sampling)?;
            text = envelope::json_with_envelope(&text, &env.report);
        }
        Ok((outcome, text))
    })?;
    warn_all(py, &outcome.warnings)?;
    crate::run_result(py, &outcome.result, &text)
}

/// The scenario's limits held against its closing and, when a limit
/// needs it, its run through ngspice, as ``chatterspice check``.
///
/// Returns the JSON of ``chatterspice check --format json`` as a dict:
/// ``passed`` is False when a limit failed (where the command exits with
/// 1), ``failed`` counts them and ``checks`` lists every limit with
/// ``key``, ``actual``, ``limit`` and ``margin`` (in the limit's unit: s,
/// V, counts) and ``passed``; ``[limits] min_electrical_life`` is held
/// against the life estimated at the circuit (``life``). Relay limits
/// alone need no ngspice. With ``envelope=True``, the JSON of ``check
/// --envelope``: each limit against the worst relay the datasheet allows.
/// The run's warnings and notes are issued as ``ChatterspiceWarning``.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``).
///     measured: a ``time,state`` CSV record instead of the mechanics.
///     timeout, element, coupling, max_iterations, coupling_tolerance,
///         ngspice, no_spiceinit: how ngspice runs (see ``run``).
///     envelope, samples, seed, jobs: the envelope (see ``run``).
///     life_phases, no_life: the electrical life (see ``run``); a
///         ``min_electrical_life`` limit estimates it either way.
///
/// Raises InputError, FileNotFoundError, NgspiceError, SimulationError;
/// KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(name = "check", signature = (path=None, *, toml_text=None, origin=None, measured=None,
                                    timeout=Duration::from_secs(60), element=None,
                                    coupling=None, max_iterations=20, coupling_tolerance=1e-7,
                                    ngspice=None, no_spiceinit=false, envelope=false,
                                    samples=32, seed=1, jobs=None,
                                    life_phases=chatterspice::life::DEFAULT_PHASES,
                                    no_life=false))]
#[pyo3(
    text_signature = "(path=None, *, toml_text=None, origin=None, measured=None, timeout=60.0, element=None, coupling=None, max_iterations=20, coupling_tolerance=1e-07, ngspice=None, no_spiceinit=False, envelope=False, samples=32, seed=1, jobs=None, life_phases=16, no_life=False)"
)]
#[allow(clippy::too_many_arguments)]
pub fn py_check<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::measured_arg)] measured: Option<PathBuf>,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
    #[pyo3(from_py_with = args::element_arg)] element: Option<ContactElement>,
    #[pyo3(from_py_with = args::coupling_arg)] coupling: Option<Coupling>,
    #[pyo3(from_py_with = args::max_iterations_arg)] max_iterations: usize,
    #[pyo3(from_py_with = args::coupling_tolerance_arg)] coupling_tolerance: f64,
    #[pyo3(from_py_with = args::ngspice_arg)] ngspice: Option<PathBuf>,
    #[pyo3(from_py_with = args::no_spiceinit_arg)] no_spiceinit: bool,
    #[pyo3(from_py_with = args::envelope_arg)] envelope: bool,
    #[pyo3(from_py_with = args::envelope_samples_arg)] samples: usize,
    #[pyo3(from_py_with = args::envelope_seed_arg)] seed: u64,
    #[pyo3(from_py_with = args::jobs_arg)] jobs: Option<u64>,
    #[pyo3(from_py_with = args::life_phases_arg)] life_phases: usize,
    #[pyo3(from_py_with = args::no_life_arg)] no_life: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let simulator = Simulator {
        timeout,
        element,
        coupling,
        max_iterations,
        coupling_tolerance,
        ngspice,
        no_spiceinit,
    };
    if envelope && measured.is_some() {
        return Err(Failure::input(
            "envelope=True samples the relay's mechanics, which measured= replaces",
        )
        .into());
    }
    let loaded = load_scenario(path, toml_text, origin)?;
    let intervals = measured.as_deref().map(read_measured).transpose()?;
    let life = life_options(life_phases, no_life);
    let scenario = loaded.scenario;
    let (text, said) = work::interruptible(py, None, move |_| -> Result<_, Failure> {
        let options = simulator.run_options();
        let ngspice = LazyNgspice::new(|| simulator.locate());
        if envelope {
            let sampling = envelope_options(samples, seed, jobs, options);
            let env = verdict::check_envelope(&scenario, &ngspice, &sampling)?;
            return Ok((verdict::envelope_check_json(&env), Vec::new()));
        }
        let outcome = verdict::check(&scenario, &ngspice, &options, intervals, &life)?;
        let mut said = outcome.warnings.clone();
        said.extend(outcome.notes.iter().cloned());
        Ok((outcome.json(), said))
    })?;
    warn_all(py, &said)?;
    json(py, &text)
}

/// Every relay the datasheet allows: the scenario's ``[envelope]`` (and
/// its printed tolerances) sampled, the relays that meet every printed
/// figure kept and run, each limit held against the worst kept relay;
/// ``check(envelope=True)``, as ``chatterspice check --envelope``.
///
/// Returns the JSON of ``chatterspice check --envelope --format json`` as
/// a dict: the worst relay's ``checks`` and ``passed``, and under
/// ``envelope`` the bands (min, median, p95, max) of every quantity, the
/// counts drawn, kept and rejected, and the worst relay.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``).
///     samples: relays drawn (≥ 1).
///     seed: the seed of the quasi-random draw (the same seed draws the
///         same relays).
///     jobs: relays run at once; default one per core.
///     timeout, element, coupling, max_iterations, coupling_tolerance,
///         ngspice, no_spiceinit: how ngspice runs (see ``run``).
///
/// Raises InputError (no ``[envelope]``, every relay rejected, a bad
/// argument), NgspiceError, SimulationError; KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(name = "envelope", signature = (path=None, *, toml_text=None, origin=None, samples=32,
                                       seed=1, jobs=None, timeout=Duration::from_secs(60),
                                       element=None, coupling=None, max_iterations=20,
                                       coupling_tolerance=1e-7, ngspice=None,
                                       no_spiceinit=false))]
#[pyo3(
    text_signature = "(path=None, *, toml_text=None, origin=None, samples=32, seed=1, jobs=None, timeout=60.0, element=None, coupling=None, max_iterations=20, coupling_tolerance=1e-07, ngspice=None, no_spiceinit=False)"
)]
#[allow(clippy::too_many_arguments)]
pub fn py_envelope<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::envelope_samples_arg)] samples: usize,
    #[pyo3(from_py_with = args::envelope_seed_arg)] seed: u64,
    #[pyo3(from_py_with = args::jobs_arg)] jobs: Option<u64>,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
    #[pyo3(from_py_with = args::element_arg)] element: Option<ContactElement>,
    #[pyo3(from_py_with = args::coupling_arg)] coupling: Option<Coupling>,
    #[pyo3(from_py_with = args::max_iterations_arg)] max_iterations: usize,
    #[pyo3(from_py_with = args::coupling_tolerance_arg)] coupling_tolerance: f64,
    #[pyo3(from_py_with = args::ngspice_arg)] ngspice: Option<PathBuf>,
    #[pyo3(from_py_with = args::no_spiceinit_arg)] no_spiceinit: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let simulator = Simulator {
        timeout,
        element,
        coupling,
        max_iterations,
        coupling_tolerance,
        ngspice,
        no_spiceinit,
    };
    let loaded = load_scenario(path, toml_text, origin)?;
    let scenario = loaded.scenario;
    let text = work::interruptible(py, None, move |_| -> Result<_, Failure> {
        let sampling = envelope_options(samples, seed, jobs, simulator.run_options());
        let ngspice = LazyNgspice::new(|| simulator.locate());
        let env = verdict::check_envelope(&scenario, &ngspice, &sampling)?;
        Ok(verdict::envelope_check_json(&env))
    })?;
    json(py, &text)
}

/// The contacts' electrical life, as ``chatterspice life``: each printed
/// endurance figure's test load simulated over its switching phases, the
/// erosion constant calibrated on the first figure, the others and the
/// scenario's own circuit predicted.
///
/// Returns the JSON of ``chatterspice life --format json`` as a dict:
/// ``calibrated_on``, ``constant_j`` (J at 1 A), the erosion law's
/// constants, ``figures`` (each with ``operations``, ``predicted``,
/// ``ratio``, ``energy_per_operation``, ``wear_per_operation``,
/// ``wear_factor``),
/// ``life`` at the scenario's circuit (``operations``, ``b10``) and
/// ``weibull_shape``.
///
/// Parameters:
///     path, toml_text, origin: the scenario (see ``bounce``), with
///         ``[datasheet] electrical_endurance``.
///     phases: switching phases averaged over the period of an AC figure
///         (2 to 1024).
///     jobs: ngspice runs at a time; default the number of CPUs.
///     timeout, element, coupling, max_iterations, coupling_tolerance,
///         ngspice, no_spiceinit: how ngspice runs (see ``run``).
///
/// Raises InputError (no endurance figures, a bad figure), NgspiceError,
/// SimulationError; KeyboardInterrupt on Ctrl-C.
#[pyfunction]
#[pyo3(name = "life", signature = (path=None, *, toml_text=None, origin=None,
                                   phases=chatterspice::life::DEFAULT_PHASES, jobs=None,
                                   timeout=Duration::from_secs(60), element=None,
                                   coupling=None, max_iterations=20, coupling_tolerance=1e-7,
                                   ngspice=None, no_spiceinit=false))]
#[pyo3(
    text_signature = "(path=None, *, toml_text=None, origin=None, phases=16, jobs=None, timeout=60.0, element=None, coupling=None, max_iterations=20, coupling_tolerance=1e-07, ngspice=None, no_spiceinit=False)"
)]
#[allow(clippy::too_many_arguments)]
pub fn py_life<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::path_arg)] path: Option<PathBuf>,
    #[pyo3(from_py_with = args::toml_text_arg)] toml_text: Option<String>,
    #[pyo3(from_py_with = args::origin_arg)] origin: Option<PathBuf>,
    #[pyo3(from_py_with = args::phases_arg)] phases: usize,
    #[pyo3(from_py_with = args::jobs_arg)] jobs: Option<u64>,
    #[pyo3(from_py_with = args::timeout_arg)] timeout: Duration,
    #[pyo3(from_py_with = args::element_arg)] element: Option<ContactElement>,
    #[pyo3(from_py_with = args::coupling_arg)] coupling: Option<Coupling>,
    #[pyo3(from_py_with = args::max_iterations_arg)] max_iterations: usize,
    #[pyo3(from_py_with = args::coupling_tolerance_arg)] coupling_tolerance: f64,
    #[pyo3(from_py_with = args::ngspice_arg)] ngspice: Option<PathBuf>,
    #[pyo3(from_py_with = args::no_spiceinit_arg)] no_spiceinit: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let simulator = Simulator {
        timeout,
        element,
        coupling,
        max_iterations,
        coupling_tolerance,
        ngspice,
        no_spiceinit,
    };
    let loaded = load_scenario(path, toml_text, origin)?;
    let scenario = loaded.scenario;
    let options = LifeOptions {
        phases,
        jobs: crate::jobs(jobs).map_or_else(verdict::cpus, std::num::NonZeroUsize::get),
        ..LifeOptions::default()
    };
    let text = work::interruptible(py, None, move |_| -> Result<_, Failure> {
        let ngspice = simulator.locate()?;
        let report = verdict::life(&scenario, &ngspice, &simulator.run_options(), &options)?;
        Ok(verdict::life_json(&report))
    })?;
    json(py, &text)
}
