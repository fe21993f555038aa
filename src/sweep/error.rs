//! Why a sweep cannot run.

use std::path::PathBuf;

use thiserror::Error;

use crate::scenario::ScenarioError;

/// Why a sweep cannot run (a failing *sample* is not an error: it is
/// recorded in its row).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SweepError {
    /// The scenario has no `[sweep]`, or one that names no key in
    /// `[sweep.vary]` or `[sweep.grid]`.
    #[error(
        "{}: nothing to sweep: add a [sweep] section with the numbers to vary, e.g.\n  \
         [sweep]\n  samples = 1000\n  [sweep.vary]\n  \"mechanics.mass\" = 0.1            # ±10 %\n  \
         \"surface.damping\" = {{ normal = 0.05 }}",
        path.display()
    )]
    NothingToVary {
        /// The scenario file.
        path: PathBuf,
    },
    /// A sample count was given (`--samples`) for a grid sweep, which runs
    /// each of its points once.
    #[error(
        "{}: --samples {samples} with a [sweep.grid]: a grid runs each of its points once; \
         drop --samples, or change the grid's `steps`",
        path.display()
    )]
    SamplesWithGrid {
        /// The scenario file.
        path: PathBuf,
        /// The sample count given.
        samples: u64,
    },
    /// The sample count is 0.
    #[error("{}: a sweep needs at least one sample; give --samples 1 or more", path.display())]
    NoSamples {
        /// The scenario file.
        path: PathBuf,
    },
    /// More samples than one sweep runs (`sweep::sample::MAX_SAMPLES`).
    #[error(
        "{}: {count} samples ({what}) is more than the {limit} one sweep runs; \
         use fewer, or run the study as several sweeps",
        path.display()
    )]
    TooManySamples {
        /// The scenario file.
        path: PathBuf,
        /// The samples asked for.
        count: u64,
        /// Where the count comes from: `sweep.samples` (or `--samples`),
        /// or the product of the grid's `steps`.
        what: &'static str,
        /// The most samples one sweep runs.
        limit: u64,
    },
    /// A key of `[sweep.vary]` has no value in the scenario to vary
    /// around.
    #[error("{}: `{key}` has no value in the scenario to vary around; set it", path.display())]
    NoNominal {
        /// The scenario file.
        path: PathBuf,
        /// The dotted number key.
        key: String,
    },
    /// Many redraws in a row all fell outside a key's bounds (a bound of its
    /// own such as `surface.restitution` ≤ 1, and ±4σ for a normal
    /// tolerance): the bounds leave (almost) nothing to draw from.
    #[error(
        "sample {index}: no value of `{key}` within its bounds after many draws; \
         lower its tolerance in [sweep.vary]"
    )]
    Truncation {
        /// The dotted number key.
        key: String,
        /// The sample's index.
        index: u64,
    },
    /// A circuit sweep of a scenario without a `[circuit]` netlist or
    /// without a `[[probe]]`.
    #[error(
        "{}: a circuit sweep needs a [circuit] netlist and at least one [[probe]]; \
         add them, or pass --mechanics-only to sweep the bounce alone",
        path.display()
    )]
    NeedsCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// A mechanics-only sweep of a coil-driven relay, which moves only in
    /// its driver circuit.
    #[error(
        "{}: a coil-driven relay without its circuit closes on the DC step of its coil, and \
         this one gives no voltage for it: set `coil.drive_voltage` (or \
         `datasheet.coil_voltage`), or drop --mechanics-only (each sample then runs the \
         coupled ngspice simulation)",
        path.display()
    )]
    CoilNeedsCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// A mechanics-only sweep of a scenario with release limits: the DC
    /// step never switches the coil off.
    #[error(
        "{}: the release limits (max_release_time, max_nc_bounce_time, max_nc_bounces) need \
         the coil switched off in the driver circuit: drop --mechanics-only, or remove those \
         limits",
        path.display()
    )]
    ReleaseLimitsNeedCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// A mechanics-only sweep of a scenario with arc limits, which only a
    /// circuit run measures.
    #[error(
        "{}: `limits.max_arc_energy`, `limits.max_arc_count` and `limits.max_arc_duration` \
         hold the arcs of the circuit run: drop --mechanics-only, or remove those limits",
        path.display()
    )]
    ArcLimitsNeedCircuit {
        /// The scenario file.
        path: PathBuf,
    },
    /// A shard that is not `K/N` with 1 ≤ K ≤ N.
    #[error("shard `{text}`: give K/N with 1 <= K <= N, e.g. --shard 3/8 for the third of eight")]
    Shard {
        /// The shard as given.
        text: String,
    },
    /// The caller stopped the sweep ([`super::Progress::stopped`]).
    #[error("the sweep was stopped")]
    Stopped,
    /// The CSV header or rows could not be written.
    #[error("cannot write the sweep's rows")]
    Write(#[source] std::io::Error),
    /// The per-sample numbers behind the summary and the plot could not be
    /// kept in, or read back from, their temporary file.
    #[error(
        "cannot keep the sweep's per-sample numbers in a temporary file (the system's \
         temporary directory, TMPDIR): is it full or not writable?"
    )]
    Scratch(#[source] std::io::Error),
    /// The scenario cannot be used, or cannot take a sweep's values (or
    /// its netlist cannot be read, for a circuit sweep).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
}
