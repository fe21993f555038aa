//! The work of the `bounce` and `check` commands as library calls, shared
//! by the binary and the Python package so that both print the same
//! report for the same scenario.
//!
//! `bounce` picks the engine a scenario needs (the one-mass closed forms,
//! the two-stage relay, or a coil on its ideal DC step) and renders the
//! chatter; `check` decides whether its limits need ngspice at all. The
//! callers read the inputs and print or return the text.

use crate::check::{self, CheckError};
use crate::mechanics::{Dimensionless, simulate, two_stage};
use crate::report::{self, Format};
use crate::scenario::Scenario;

/// The chatter of one closing of `scenario`, rendered as `chatterspice
/// bounce --format FORMAT` prints it: with a step force, the exact
/// one-mass engine or the two-stage one; with a `[coil]`, the ideal DC
/// step of its coil voltage (no circuit).
///
/// ```
/// use chatterspice::{commands, report::Format, scenario::Scenario};
///
/// let json = commands::bounce(&Scenario::builtin_default(), Format::Json)?;
/// let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
/// assert_eq!(doc["bounce_count"], 5);
/// # Ok::<(), chatterspice::check::CheckError>(())
/// ```
pub fn bounce(scenario: &Scenario, format: Format) -> Result<String, CheckError> {
    let build = scenario.two_stage();
    if scenario.coil.is_some() {
        let (chatter, run) = check::dc_step(scenario)?;
        let pole_face = build
            .pole_face
            .is_some()
            .then(|| run.as_ref().map_or(&[][..], |r| &r.pole_face[..]));
        return Ok(report::render_two_stage(format, &chatter, None, pole_face));
    }
    let (mechanics, surface, settings) = (
        scenario.mechanics()?,
        scenario.surface(),
        scenario.settings(),
    );
    let dimensionless = Dimensionless::of(&mechanics, &surface);
    if build.is_one_mass() {
        let chatter =
            simulate(&mechanics, &surface, &settings).map_err(|source| CheckError::Mechanics {
                path: scenario.origin.clone(),
                source,
            })?;
        return Ok(report::render(format, &chatter, Some(&dimensionless)));
    }
    let trajectory =
        two_stage::step_closing(&mechanics, &build, &surface, &settings).map_err(|source| {
            CheckError::Motion {
                path: scenario.origin.clone(),
                source,
            }
        })?;
    let pole_face = build
        .pole_face
        .is_some()
        .then(|| trajectory.pole_face_impacts());
    Ok(report::render_two_stage(
        format,
        trajectory.chatter(),
        Some(&dimensionless),
        pole_face,
    ))
}

/// Whether `check` of `scenario` runs ngspice: when a limit needs the
/// circuit (a probe's or an arc limit), or, for a simulated closing, when
/// a coil-driven relay has its driver circuit. With a `measured` record
/// only the limits that need the circuit do.
pub fn check_needs_ngspice(scenario: &Scenario, measured: bool) -> bool {
    let coil_in_circuit = scenario.coil.is_some() && scenario.circuit.is_some();
    check::needs_circuit(scenario) || (!measured && coil_in_circuit)
}

/// The paper's dimensionless groups of a step-force scenario, which the
/// JSON reports carry; `None` for a coil-driven relay.
pub fn dimensionless(scenario: &Scenario) -> Option<Dimensionless> {
    scenario
        .mechanics()
        .ok()
        .map(|m| Dimensionless::of(&m, &scenario.surface()))
}
