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
//! The files run one way, from the leaves up: the parameters
//! (`parameters.rs`: [`Mechanics`], [`Settings`], the stops, validation),
//! the errors and limits (`error.rs`), the surface laws ([`surface`]) and
//! the numerics ([`root`], [`linear`], `step_control.rs`, [`integrate`],
//! [`dop853`]) at the bottom; the engines above them; the motion as
//! segments (`segment.rs`) and the [`Trajectory`] built from them at the
//! top. This file only declares and re-exports.
//!
//! Sign conventions: `x` is the displacement toward the fixed contact
//! (m), velocities are positive toward it, and contact forces are the
//! force the fixed contact puts on the moving one, positive pushing back.

pub mod contact_force;
pub mod cycle;
pub mod dop853;
pub mod driven;
pub mod engine;
mod error;
pub mod forced;
pub mod hunt_crossley;
pub mod integrate;
pub mod linalg;
pub mod linear;
pub(crate) mod locate;
mod parameters;
pub mod root;
pub(crate) mod segment;
mod step_control;
pub mod surface;
pub mod trajectory;
pub mod two_stage;

/// The old name of [`contact_force`].
#[doc(hidden)]
pub use contact_force as force;
pub use contact_force::contact_forces;
pub use engine::{ImpactResponse, ResponseEnd, critical_impact_speed, impact_response, simulate};
pub use error::{DriveError, MAX_CONTACT_STEPS, MAX_DRIVEN_STEPS, MAX_EVENTS, MechanicsError};
pub use parameters::{Dimensionless, Mechanics, PROOF_SPAN, Settings, validate};
pub use surface::Surface;
pub use trajectory::{Drive, Trajectory, TrajectoryEvent, TrajectoryEventKind, simulate_drive};
#[allow(deprecated)]
pub use trajectory::{Event, EventKind};
