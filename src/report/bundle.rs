//! What `run --out DIR` writes: every artefact of one run, so that it can
//! be inspected, plotted again, or re-run by hand with ngspice.
//!
//! | file | contents |
//! |---|---|
//! | `report.json` | the `run` JSON ([`json::render_run`]) |
//! | `waveforms.csv` | time, contact resistance and every probe, at ngspice's time points |
//! | `waveforms_ideal.csv` | the same for the ideal-contact run, when there was one |
//! | `waveforms.raw` | the bounced run's whole transient plot, every saved vector, as an ngspice binary raw file |
//! | `waveforms_ideal.raw` | the same for the ideal-contact run, when there was one |
//! | `netlist.cir` | the deck that was run: the user's netlist plus the `.include` |
//! | `contact.inc` | the contact subcircuit (and any data files it reads) |
//! | `plot.svg` | the contact and the probes over the chatter |
//! | `plot.png` | the same plot as a picture (the `png` feature) |
//!
//! `cd DIR && ngspice netlist.cir` runs the same simulation again.

use thiserror::Error;

#[cfg(feature = "png")]
use super::png;
use super::svg::{self, ContactTrace, ProbePanel, Series, SvgPlot};
use super::{csv, json};
use crate::analysis::{AnalysisError, signal_values};
use crate::mechanics::Dimensionless;
use crate::pipeline::{INCLUDE_FILE, RunResult};
use crate::rawfile::Vector;

/// Why the files of a run could not be made (the run itself succeeded).
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum BundleError {
    /// A probed signal's samples cannot be read from the raw file.
    #[error("cannot tabulate the waveforms")]
    Waveforms(#[from] AnalysisError),
    /// The SVG plot cannot be drawn.
    #[error("cannot draw the plot")]
    Plot(#[from] svg::SvgError),
    /// The SVG plot cannot be rendered as a PNG.
    #[error("cannot render the plot as PNG")]
    #[cfg(feature = "png")]
    Png(#[from] png::PngError),
}

/// The files of `run`: (file name, contents), in the order of the table
/// above.
pub fn run_files(
    run: &RunResult,
    dimensionless: Option<&Dimensionless>,
) -> Result<Vec<(String, Vec<u8>)>, BundleError> {
    run_files_with_life(run, dimensionless, None)
}

/// [`run_files`] with the electrical life `life` in `report.json`.
pub fn run_files_with_life(
    run: &RunResult,
    dimensionless: Option<&Dimensionless>,
    life: Option<&crate::life::LifeReport>,
) -> Result<Vec<(String, Vec<u8>)>, BundleError> {
    // The probes' signals; without probes, every vector the run saved.
    let plot_vectors = |plot: &'_ crate::rawfile::Plot| -> Vec<String> {
        plot.variables
            .iter()
            .skip(1)
            .map(|v| v.name.clone())
            .collect()
    };
    let all: Vec<String> = plot_vectors(&run.simulation.plot);
    let signals: Vec<&str> = if run.probes.is_empty() {
        all.iter().map(String::as_str).collect()
    } else {
        run.probes.iter().map(|p| p.probe.signal.as_str()).collect()
    };
    let mut files = vec![
        (
            "report.json".to_owned(),
            json::render_run_with_life(run, dimensionless, life).into_bytes(),
        ),
        (
            "waveforms.csv".to_owned(),
            csv::waveforms(&run.simulation.plot, Some(&run.waveform), &signals)?.into_bytes(),
        ),
    ];
    if let Some(ideal) = &run.ideal {
        files.push((
            "waveforms_ideal.csv".to_owned(),
            csv::waveforms(&ideal.plot, None, &signals)?.into_bytes(),
        ));
    }
    files.push((
        "waveforms.raw".to_owned(),
        crate::rawfile::to_binary(&run.simulation.plot),
    ));
    if let Some(ideal) = &run.ideal {
        files.push((
            "waveforms_ideal.raw".to_owned(),
            crate::rawfile::to_binary(&ideal.plot),
        ));
    }
    files.push(("netlist.cir".to_owned(), run.deck.text.clone().into_bytes()));
    files.push((
        INCLUDE_FILE.to_owned(),
        run.include.text.clone().into_bytes(),
    ));
    for (name, contents) in &run.include.data_files {
        files.push((name.clone(), contents.clone().into_bytes()));
    }
    let svg = plot(run)?;
    #[cfg(feature = "png")]
    files.push(("plot.png".to_owned(), png::render(&svg)?.bytes));
    files.push(("plot.svg".to_owned(), svg.into_bytes()));
    Ok(files)
}

/// The SVG of a run: the chatter's states on top, then one panel per
/// probe, over the chatter and a little after.
pub fn plot(run: &RunResult) -> Result<String, BundleError> {
    let plot = &run.simulation.plot;
    let time: &[f64] = match plot.scale() {
        Some(Vector::Real(t)) => t,
        _ => &[],
    };
    let values = run
        .probes
        .iter()
        .map(|p| signal_values(plot, &p.probe.signal).map(|(v, _)| v))
        .collect::<Result<Vec<_>, _>>()?;
    let probes = run
        .probes
        .iter()
        .zip(&values)
        .map(|(p, v)| ProbePanel::from_analysis(&p.analysis, Series { time, value: v }))
        .collect();
    let last_edge = run
        .probes
        .iter()
        .filter_map(|p| p.analysis.last_edge)
        .fold(None, |acc: Option<f64>, t| {
            Some(acc.map_or(t, |a| a.max(t)))
        });
    let settle = run.chatter.settle_time.or(run.chatter.first_impact);
    let last_event = match (last_edge, settle) {
        (Some(a), Some(b)) => Some(a.max(b)),
        (a, b) => a.or(b),
    };
    let end = time.last().copied().unwrap_or(run.chatter.t_end);
    let title = format!(
        "{}: {} bounces, {}",
        run.netlist
            .file_name()
            .map_or_else(String::new, |n| n.to_string_lossy().into_owned()),
        run.chatter.bounce_count,
        run.chatter.outcome
    );
    Ok(svg::render(&SvgPlot {
        pole_face: run
            .pole_face
            .iter()
            .flatten()
            .map(|i| i.impact_time)
            .collect(),
        title,
        window: svg::suggested_window(last_event, end),
        contact: Some(ContactTrace::States(&run.chatter.intervals)),
        probes,
        arcs: run
            .arcs
            .iter()
            .flat_map(|r| {
                let arcs = r.arcs.iter().map(|a| (a.start, a.start + a.duration, true));
                let breakdowns = r
                    .breakdowns
                    .iter()
                    .map(|b| (b.start, b.start + b.duration, false));
                arcs.chain(breakdowns)
            })
            .collect(),
    })?)
}
