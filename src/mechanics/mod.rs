//! The mechanics engine: the chatter of a closing relay contact, exactly.
//!
//! The moving contact is a damped one-degree-of-freedom oscillator
//! `m ẍ + r ẋ + s x = f − p` pushed toward a fixed contact at `x = g`
//! (Uchikoshi, Azuma & Kikuchi, "Rebound characteristics of the equivalent
//! stiffness surface", 1973; docs/model.md). What happens at
//! `x ≥ g` is the surface law ([`Surface`]).
//!
//! The engine is event-driven. Between events the motion is one of:
//! - a linear piece with constant force (free flight, or contact with a
//!   Kelvin–Voigt surface), solved in closed form in every damping regime
//!   ([`linear`]); impacts and releases are roots of that closed form,
//!   bracketed between consecutive extrema and polished by safeguarded
//!   Halley iteration, in the exact phase form of a half swing when
//!   under-damped;
//! - a nonlinear contact (Hunt–Crossley), integrated by an adaptive
//!   8th-order Runge–Kutta method with dense output and event location
//!   ([`dop853`]), in variables that keep the motion smooth through touch
//!   and release ([`hunt_crossley`]).
//!
//! Under a drive that varies in time and position (a coil), the same
//! events, surface laws and endings are integrated with event location
//! by one engine, [`cycle`]: the whole operating cycle (make, hold,
//! release, the rest stop), or one closing stopped where its ending is
//! decided. [`driven`] holds what it shares with its users (the drive, the
//! state, the event-location numerics) and [`forced`] its entry points for
//! a force `F(t, x)`.
//!
//! [`simulate_drive`] is the one entry point for any drive: the step
//! force through the exact engine, a force `F(t, x)` through the cycle;
//! either way the result is one [`Trajectory`], with position, velocity,
//! gap and contact forces at any time and the event list.
//!
//! Sign conventions: `x` is the displacement toward the fixed contact
//! (m), velocities are positive toward it, and contact forces are the
//! force the fixed contact puts on the moving one, positive pushing back.

pub mod cycle;
pub mod dop853;
pub mod driven;
pub mod engine;
pub mod force;
pub mod forced;
pub mod hunt_crossley;
pub mod integrate;
pub mod linear;
pub mod root;
pub mod surface;
pub mod trajectory;
pub mod two_stage;

pub use engine::{
    ImpactResponse, ResponseEnd, critical_impact_speed, impact_response, simulate, validate,
};
pub use force::contact_forces;
pub use surface::Surface;
pub use trajectory::{Drive, Event, EventKind, Trajectory, simulate_drive};

use thiserror::Error;

/// The moving contact and its drive (docs/model.md §1). SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mechanics {
    /// kg, effective moving mass `m`.
    pub mass: f64,
    /// N/m, suspension (contact-spring) stiffness `s`.
    pub stiffness: f64,
    /// N·s/m, structural damping `r` (may be 0).
    pub damping: f64,
    /// N, closing force `f`, a step at t = 0.
    pub force: f64,
    /// m, travel from rest to the fixed contact `g`.
    pub gap: f64,
    /// m, `x(0)`.
    pub initial_position: f64,
    /// m/s, `ẋ(0)`.
    pub initial_velocity: f64,
    /// N, return-spring preload `p` holding the armature on its rest stop;
    /// with a step force it simply subtracts from `f`.
    pub preload: f64,
}

/// When to stop and what is too small to matter (docs/model.md §4).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// s, the simulated horizon.
    pub t_end: f64,
    /// s, an opening shorter than this ends the sequence as `resolved`.
    pub min_open_time: f64,
    /// m, an opening smaller than this ends the sequence as `resolved`.
    pub min_gap: f64,
}

impl Default for Settings {
    /// 20 ms horizon (a signal relay settles in ≤ 5 ms); 1 ns and 1 nm are
    /// far below what any circuit or contact surface can resolve.
    fn default() -> Self {
        Settings {
            t_end: 0.02,
            min_open_time: 1e-9,
            min_gap: 1e-9,
        }
    }
}

/// The paper's dimensionless groups (docs/model.md §1–2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dimensionless {
    /// rad/s, ωn = √(s/m); dimensionless time is τ = ωn t.
    pub omega_n: f64,
    /// ζ = r / (2√(m s)).
    pub zeta: f64,
    /// m, F = (f − p)/s, the static deflection under the closing force.
    pub static_deflection: f64,
    /// k0 = g/F.
    pub k0: f64,
    /// ζ0 = r0 / (2√(m s)) (Kelvin–Voigt only).
    pub zeta0: Option<f64>,
    /// β = 1 + s0/s (Kelvin–Voigt only).
    pub beta: Option<f64>,
    /// σ = ζ + ζ0 (Kelvin–Voigt only).
    pub sigma: Option<f64>,
    /// ζ' = σ/√β, the damping ratio of the in-contact oscillation.
    pub zeta_prime: Option<f64>,
    /// γ = (1 + k0 s0/s)/β: the in-contact equilibrium is γF.
    pub gamma: Option<f64>,
}

impl Dimensionless {
    /// The dimensionless view of a relay and surface.
    pub fn of(m: &Mechanics, surface: &Surface) -> Dimensionless {
        let omega_n = (m.stiffness / m.mass).sqrt();
        let crit = 2.0 * (m.mass * m.stiffness).sqrt();
        let zeta = m.damping / crit;
        let f_net = m.force - m.preload;
        let static_deflection = f_net / m.stiffness;
        let k0 = m.gap / static_deflection;
        let (zeta0, beta, sigma, zeta_prime, gamma) = match *surface {
            Surface::KelvinVoigt { stiffness, damping } => {
                let zeta0 = damping / crit;
                let beta = 1.0 + stiffness / m.stiffness;
                let sigma = zeta + zeta0;
                let gamma = (1.0 + k0 * stiffness / m.stiffness) / beta;
                (
                    Some(zeta0),
                    Some(beta),
                    Some(sigma),
                    Some(sigma / beta.sqrt()),
                    Some(gamma),
                )
            }
            _ => (None, None, None, None, None),
        };
        Dimensionless {
            omega_n,
            zeta,
            static_deflection,
            k0,
            zeta0,
            beta,
            sigma,
            zeta_prime,
            gamma,
        }
    }
}

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
