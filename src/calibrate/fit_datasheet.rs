//! The datasheet's figures as a datasheet measures them: an ideal DC step
//! on the coil, the pick-up over the whole load line, the drop-out at the
//! closed position, the operate and bounce times from the direct coil
//! engine.

use super::{Event, events_of};
use crate::coil::direct::direct_closing;
use crate::coil::pick_up::{LoadLine, PickUp, drop_out, pick_up};
use crate::coil::{Coil, Source};
use crate::mechanics::simulate;
use crate::scenario::{DatasheetSection, PrintedFigure, Scenario};

/// V, a pick-up or drop-out voltage `v` as the relay at the far end of
/// its coil's printed resistance tolerance shows it, when the figure is a
/// bound: the currents are the relay's, so the voltages scale with the
/// resistance (`v·(1 + t)` for a pick-up maximum, `v·(1 − t)` for a
/// drop-out minimum). A printed bound holds for every relay of the type,
/// whatever its coil, so the nominal relay must meet it with that room.
/// Any other figure: `v`.
pub fn coil_tolerance_corner(
    d: &DatasheetSection,
    name: &str,
    figure: &PrintedFigure,
    v: f64,
) -> f64 {
    let Some(t) = d.coil_resistance.and_then(|r| r.tolerance) else {
        return v;
    };
    if figure.typ.is_some() {
        return v;
    }
    match name {
        "pick_up_voltage" if figure.max.is_some() => v * (1.0 + t),
        "drop_out_voltage" if figure.min.is_some() => v * (1.0 - t),
        _ => v,
    }
}

/// The modelled events of one closing: the step-force engine, or with a
/// coil the direct engine on an ideal `voltage` step.
pub fn model_events(s: &Scenario, voltage: Option<f64>) -> Result<Vec<Event>, String> {
    let chatter = match (&s.coil, voltage) {
        (Some(c), Some(v)) => {
            direct_closing(
                &Coil::from(c),
                &Source {
                    voltage: v,
                    series_resistance: 0.0,
                },
                &s.armature(),
                &s.two_stage(),
                &s.surface(),
                &s.settings(),
            )
            .map_err(|e| e.to_string())?
            .0
        }
        (Some(_), None) => return Err("a coil-driven relay needs [datasheet] coil_voltage".into()),
        (None, _) if s.two_stage().is_one_mass() => {
            simulate(&s.armature(), &s.surface(), &s.settings()).map_err(|e| e.to_string())?
        }
        (None, _) => crate::mechanics::two_stage::step_closing(
            &s.armature(),
            &s.two_stage(),
            &s.surface(),
            &s.settings(),
        )
        .map_err(|e| e.to_string())?
        .into_chatter(),
    };
    Ok(events_of(&chatter.intervals))
}

/// The datasheet figures of scenario `s` (which has a coil), computed as
/// a datasheet measures them; `None` for a figure the relay does not
/// show (it never closes, say, or its closing cannot be simulated: see
/// [`datasheet_figures_or_failure`]).
pub fn datasheet_figures(s: &Scenario, d: &DatasheetSection) -> Vec<(&'static str, Option<f64>)> {
    figures_and_failure(s, d).0
}

/// [`datasheet_figures`], or why the relay's closing on the datasheet's
/// DC step cannot be simulated (the engine's own words).
pub fn datasheet_figures_or_failure(
    s: &Scenario,
    d: &DatasheetSection,
) -> Result<Vec<(&'static str, Option<f64>)>, String> {
    match figures_and_failure(s, d) {
        (_, Some(failure)) => Err(failure),
        (figures, None) => Ok(figures),
    }
}

/// The figures, each `None` that the closing gives when it cannot be
/// simulated, and why it cannot.
type FiguresAndFailure = (Vec<(&'static str, Option<f64>)>, Option<String>);

fn figures_and_failure(s: &Scenario, d: &DatasheetSection) -> FiguresAndFailure {
    let Some(section) = &s.coil else {
        return (
            d.figures().into_iter().map(|(n, _)| (n, None)).collect(),
            None,
        );
    };
    let coil = Coil::from(section);
    let m = s.armature();
    let build = s.two_stage();
    let line = LoadLine::of_relay(&m, &build);
    let wants = |f: Option<PrintedFigure>| f.is_some();
    let closing = match d.coil_voltage {
        Some(v) if wants(d.operate_time) || wants(d.bounce_time) => direct_closing(
            &coil,
            &Source {
                voltage: v,
                series_resistance: 0.0,
            },
            &m,
            &build,
            &s.surface(),
            &s.settings(),
        )
        .map_err(|e| e.to_string())
        .map(|(chatter, _)| chatter),
        _ => Err(String::new()),
    };
    let failure = closing.as_ref().err().filter(|e| !e.is_empty()).cloned();
    let closing = closing.ok();
    let operate = closing.as_ref().and_then(|c| c.first_impact);
    let settle = closing.as_ref().and_then(|c| c.settle_time);
    let mut out = Vec::new();
    for (name, _) in d.figures() {
        let value = match name {
            "coil_resistance" => Some(coil.resistance),
            "pick_up_voltage" => Some(pick_up(&coil, &line).voltage),
            "drop_out_voltage" => Some(drop_out(&coil, &line).voltage),
            "operate_time" => operate,
            "bounce_time" => operate.zip(settle).map(|(a, b)| b - a),
            // Not modelled: a relay's release time is set by the decay of
            // its flux (eddy currents, the coil's own circuit), which the
            // single-gap magnet with an ideal switch does not have.
            "release_time" => None,
            _ => None,
        };
        out.push((name, value));
    }
    (out, failure)
}

/// The pick-up of scenario `s` over its whole load line, with that line;
/// `None` without a coil.
pub fn pick_up_of(s: &Scenario) -> Option<(PickUp, LoadLine)> {
    let coil = Coil::from(s.coil.as_ref()?);
    let line = LoadLine::of_relay(&s.armature(), &s.two_stage());
    Some((pick_up(&coil, &line), line))
}
