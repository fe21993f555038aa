//! The relay as it is built: the armature, the contact blade it carries,
//! the overtravel and the pole face (docs/model.md, "The two-stage relay").
//!
//! The one-mass model moves the armature and the moving contact together.
//! In a relay the moving contact sits on a leaf spring, the blade, carried
//! by the armature. The blade's contact point makes the contact; the
//! armature travels on (the overtravel), bending the blade, and stops on
//! the pole face. That second impact shakes the blade and may open the
//! contact again: a second burst of bounces.
//!
//! Coordinates toward closing, both 0 at rest: `x_a` (the armature,
//! measured at the contact) and `x_b` (the blade's contact point).
//!
//! ```text
//! F_b = s_b (x_a − x_b) + r_b (ẋ_a − ẋ_b)            the blade's spring
//! m ẍ_a + r ẋ_a + s x_a + p = F(t, x_a) − F_b − F_pole(x_a − g − o, ẋ_a)
//! m_b ẍ_b = F_b − F_c(x_b − g, ẋ_b)
//! ```
//!
//! with `F_c` the contact's surface law and `F_pole` the pole face's. The
//! same engine also runs the one-mass model with the contact released by
//! its force (`surface.release = "force"`): without a blade the contact
//! law acts on the armature itself.
//!
//! The engine ([`engine`]) is event-driven: between events the motion is
//! integrated by DOP853 with dense output; every impact, release,
//! lift-off and landing is located on the dense output by bisection to
//! adjacent floats, and the state after it is set exactly on the surface.
//! A closing ends when an energy bound (docs/model.md §11) proves that the
//! contact can no longer release (`stuck`), or reach the contact again
//! (`ends_open`).
//!
//! The files run one way: the relay as built (`relay.rs`), the model its
//! engines share (`model.rs`: state, modes, equations of motion), one
//! linear mode (`linear_mode.rs`), the motion piece by piece (`span.rs`), the
//! run's result (`run.rs`), the energy bound (`energy.rs`), a run in
//! progress (`propagation.rs`: events, records, endings), the exact
//! propagator (`linear.rs`) and the integrating one with the entry points
//! ([`engine`]). This file only declares and re-exports.

pub(crate) mod energy;
pub mod engine;
pub(crate) mod linear;
mod linear_mode;
pub(crate) mod model;
mod propagation;
mod relay;
pub(crate) mod run;
pub(crate) mod span;
pub(crate) mod stepper;

pub use engine::{driven_run, simulate_two_stage, step_closing};
#[doc(hidden)]
pub use linear::with_baseline_steps;
pub(crate) use relay::validate_all;
pub use relay::{Blade, PoleFace, Release, TwoStage};
pub use run::{Horizon, TwoStageRun};

#[cfg(test)]
mod tests;
