//! One circuit pass: a run deck and its include files through the
//! simulator, and the transient plot read back. The plain run, the
//! ideal-contact comparison and every pass of the coil coupling run their
//! circuits through [`circuit_pass`], so an ngspice failure reads the same
//! wherever it happens: named at the line of the user's file (or of a file
//! it includes) that ngspice rejected.

use std::path::{Path, PathBuf};
use std::time::Duration;

use thiserror::Error;

use crate::netlist::Deck;
use crate::rawfile::Plot;
use crate::spice::{Failure, RunRequest, Runner, SpiceError};

/// One ngspice run as the reports need it.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulation {
    /// The transient plot.
    pub plot: Plot,
    /// e.g. `"39"`.
    pub version: Option<String>,
    /// Wall-clock time of the ngspice run (for a coil-driven relay, the
    /// sum over the coupling's passes).
    pub elapsed: Duration,
    /// ngspice's `Warning:` lines and the raw reader's warnings (empty for
    /// a coil-driven relay).
    pub warnings: Vec<String>,
    /// The kept work directory, when asked for.
    pub workdir: Option<PathBuf>,
    /// What ngspice printed (for a coil-driven relay, on the last
    /// circuit run).
    pub log: String,
}

/// Why a circuit pass gave no plot.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum PassError {
    /// ngspice failed on one of the runs.
    #[error(
        "ngspice failed on the {run} run of {}{}",
        netlist.display(),
        match line {
            None => String::new(),
            Some((file, l)) if file == netlist => format!(
                ": the error is on line {l} of that file (ngspice counts the lines of the \
                 deck it ran, which has the contact `.include` added and included files \
                 written in)"
            ),
            Some((file, l)) => format!(": the error is on line {l} of {}, which it includes", file.display()),
        }
    )]
    Spice {
        /// The run: `bounced`, `ideal` or `coupled`.
        run: &'static str,
        /// The user's netlist.
        netlist: PathBuf,
        /// The file (the netlist or one it includes) and line, when
        /// ngspice named a deck line that came from one.
        line: Option<(PathBuf, usize)>,
        /// The ngspice error.
        #[source]
        source: Box<SpiceError>,
    },
    /// ngspice ran, but its raw file has no transient plot to analyse.
    #[error(
        "{}: the raw file of the {run} run has no transient plot (ngspice wrote: {plots}); \
         the netlist's .tran analysis did not produce one",
        netlist.display()
    )]
    NoTransient {
        /// The run: `bounced`, `ideal` or `coupled`.
        run: &'static str,
        /// The user's netlist.
        netlist: PathBuf,
        /// The names of the plots the raw file has, each in backticks,
        /// comma-separated (empty when it has none).
        plots: String,
    },
}

/// What one pass runs.
#[derive(Debug, Clone)]
pub struct Pass<'a> {
    /// The run's name in messages (`bounced`, `ideal`, `coupled`).
    pub run: &'static str,
    /// The user's netlist, named in messages.
    pub netlist: &'a Path,
    /// The deck to run.
    pub deck: &'a Deck,
    /// The files the deck `.include`s by plain name: (name, text).
    pub includes: Vec<(String, String)>,
    /// The wall-clock limit of the simulator.
    pub timeout: Duration,
    /// Keep the work directory for inspection.
    pub keep_workdir: bool,
}

/// Runs `pass` with `runner`: the deck and its includes in a work
/// directory, the simulator, the raw file's last transient plot.
pub fn circuit_pass(runner: &dyn Runner, pass: Pass<'_>) -> Result<Simulation, PassError> {
    let result = runner.run(&RunRequest {
        deck: pass.deck.text.clone(),
        includes: pass.includes,
        timeout: pass.timeout,
        keep_workdir: pass.keep_workdir,
    });
    simulation_of(pass.run, result, pass.netlist, pass.deck)
}

fn simulation_of(
    run: &'static str,
    result: Result<crate::spice::RunOutput, SpiceError>,
    netlist: &Path,
    deck: &Deck,
) -> Result<Simulation, PassError> {
    let output = result.map_err(|source| {
        let line = match source.failure() {
            Some(Failure::Netlist {
                line: Some(l),
                text,
                ..
            }) => deck
                .source_line(*l)
                .map(|(file, line)| (file.to_path_buf(), line))
                // Only when the deck line is the one ngspice echoed.
                .filter(|_| {
                    let deck_line = deck.text.lines().nth(l - 1).unwrap_or_default();
                    text.as_ref()
                        .is_none_or(|t| deck_line.trim().eq_ignore_ascii_case(t.trim()))
                }),
            _ => None,
        };
        PassError::Spice {
            run,
            netlist: netlist.to_owned(),
            line,
            source: Box::new(source),
        }
    })?;
    let crate::spice::RunOutput {
        raw,
        version,
        elapsed,
        workdir,
        warnings,
        log,
        ..
    } = output;
    let plot_names = || {
        raw.plots
            .iter()
            .map(|p| format!("`{}`", p.name))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let plot = raw
        .last_transient()
        .cloned()
        .ok_or_else(|| PassError::NoTransient {
            run,
            netlist: netlist.to_owned(),
            plots: plot_names(),
        })?;
    Ok(Simulation {
        plot,
        version,
        elapsed,
        warnings,
        workdir,
        log,
    })
}
