//! What the mechanics engines fail on, and the limits that end a run
//! before it exhausts memory. Parameter errors name the scenario key to
//! change; run-time errors carry the time and the numbers that explain them.

use thiserror::Error;

/// A parameter the engine cannot work with. `name` is the scenario key
/// (`mechanics.mass`, `surface.restitution`, …) so that callers can point
/// at the line to change.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum MechanicsError {
    /// A parameter is out of its range (a mass ≤ 0, a restitution > 1, a
    /// value that is not finite, ...).
    #[error("`{name}` = {value} is not valid: {requirement}")]
    InvalidParameter {
        /// The scenario key, e.g. `mechanics.mass`.
        name: &'static str,
        /// The value given, in the key's unit.
        value: f64,
        /// What the value must satisfy.
        requirement: &'static str,
    },
    /// An adaptive integrator shrank its step to rounding level (or the
    /// state stopped being finite) without meeting its tolerance.
    #[error(
        "the contact integrator could not meet its tolerance at t = {time} s \
         (step fell to {step} s); the surface is too stiff for its damping — \
         check `surface.stiffness` and `surface.chi`"
    )]
    StepSizeTooSmall {
        /// s, when it happened.
        time: f64,
        /// s, the step it fell to.
        step: f64,
    },
    /// One nonlinear contact took more than [`MAX_CONTACT_STEPS`]
    /// integration steps.
    #[error(
        "one contact took more than {steps} integration steps (t = {time} s) without ending: \
         the surface law's time scale is far from the armature's — check `surface.stiffness`, \
         `surface.chi` and `mechanics.force`"
    )]
    ContactTooLong {
        /// s, when the contact was given up.
        time: f64,
        /// The step limit, [`MAX_CONTACT_STEPS`].
        steps: usize,
    },
    /// A driven simulation made more than [`MAX_EVENTS`] impacts.
    #[error(
        "more than {events} impacts by t = {time} s: the armature would chatter without end \
         (restitution near 1, or no damping); add damping, or raise \
         `simulation.min_open_time` / `simulation.min_gap` to end it as resolved"
    )]
    TooManyEvents {
        /// s, when the limit was reached.
        time: f64,
        /// The impacts made by then (at least [`MAX_EVENTS`]).
        events: usize,
    },
}

/// The most impacts one simulation records. A real relay makes tens; an
/// undamped or perfectly elastic model makes them without end, and a
/// sequence stops here with outcome `event_limit` (about 70 MB of
/// results at the cap).
pub const MAX_EVENTS: usize = 100_000;

/// The most integration steps one contact of a nonlinear surface takes
/// before it is given up as unphysical.
pub const MAX_CONTACT_STEPS: usize = 2_000_000;

/// The most integration steps one simulation under a varying drive (the
/// coil) takes, about 100 MB of trajectory: a real relay's cycle takes a
/// few thousand.
pub const MAX_DRIVEN_STEPS: usize = 500_000;

/// What the driven mechanics (a drive that varies in time and position:
/// the coil) can fail on. Parameter errors name the key to change;
/// run-time errors carry the time and state.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum DriveError {
    /// A parameter of the drive or the run is out of its range.
    #[error("`{name}` = {value} is not valid: {requirement}")]
    InvalidParameter {
        /// The scenario key, e.g. `mechanics.initial_position`.
        name: &'static str,
        /// The value given, in the key's unit.
        value: f64,
        /// What the value must satisfy.
        requirement: &'static str,
    },
    /// What the mechanics engine itself failed on.
    #[error(transparent)]
    Mechanics(#[from] MechanicsError),
    /// The engine's answer breaks what physics guarantees (an impact that
    /// approaches backwards, energy from nowhere, an opening wider than
    /// the energy allows): an error of the engine, reported instead of a
    /// result.
    #[error(
        "the simulated motion breaks the physics at t = {time:.6e} s: {what}; the relay: {relay}. \
         This is a defect of chatterspice's engine, not of your scenario: please report it with \
         the scenario"
    )]
    Impossible {
        /// s, where it was seen.
        time: f64,
        /// What broke, with the numbers.
        what: String,
        /// The relay's keys and values.
        relay: String,
    },
    /// The armature pressed through the contact to the magnet's pole face.
    #[error(
        "the armature reached the pole face (x = {position} m ≥ `coil.air_gap` = {pole} m) \
         at t = {time} s: the contact cannot hold the magnetic pull; stiffen \
         `surface.stiffness`, lower the drive, or end the run earlier with `simulation.t_end`"
    )]
    ArmatureAtPole {
        /// s, when it reached the pole.
        time: f64,
        /// m, the armature's position then.
        position: f64,
        /// m, the pole face's position (`coil.air_gap`).
        pole: f64,
    },
    /// The run needs more than [`MAX_DRIVEN_STEPS`] integration steps:
    /// the armature's natural period is far too short for the horizon.
    #[error(
        "the motion needs more than {steps} integration steps by t = {time:.4e} s of the run's \
         {t_end} s: with `mechanics.mass` = {mass:e} kg on `mechanics.stiffness` = {stiffness:e} \
         N/m the armature's natural period is {period:.3e} s, too short to follow over the run; check \
         `mechanics.mass` (in kg: a signal relay's armature is 0.1 to 5 g) and the stiffnesses, \
         or shorten `simulation.t_end`"
    )]
    TooManySteps {
        /// The step limit, [`MAX_DRIVEN_STEPS`].
        steps: usize,
        /// s, how far the run got.
        time: f64,
        /// s, the run's horizon.
        t_end: f64,
        /// kg, `mechanics.mass`.
        mass: f64,
        /// N/m, `mechanics.stiffness`.
        stiffness: f64,
        /// s, the natural period 2π√(m/s).
        period: f64,
    },
    /// The drive's force function returned NaN or an infinity.
    #[error(
        "the drive force is {value} N at t = {time} s, x = {position} m: \
         the force function must return a finite force for every time and position"
    )]
    DriveNotFinite {
        /// s
        time: f64,
        /// m, the armature's position.
        position: f64,
        /// N, the force returned.
        value: f64,
    },
}
