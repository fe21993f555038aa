//! One circuit pass: a run deck and its include files through the
//! simulator, and the transient plot read back. The plain run, the
//! ideal-contact comparison and every pass of the coil coupling run their
//! circuits through [`circuit_pass`], so an ngspice failure reads the same
//! wherever it happens: named at the line of the user's file (or of a file
//! it includes) that ngspice rejected.

use std::path::Path;
use std::time::Duration;

use super::{RunError, Simulation};
use crate::netlist::Deck;
use crate::spice::{Failure, RunRequest, Runner, SpiceError};

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
pub fn circuit_pass(runner: &dyn Runner, pass: Pass<'_>) -> Result<Simulation, RunError> {
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
) -> Result<Simulation, RunError> {
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
        RunError::Spice {
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
        .ok_or_else(|| RunError::NoTransient {
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
    })
}
