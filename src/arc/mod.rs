//! Arcs and gap breakdown at the contact (docs/arcs.md).
//!
//! A contact that separates while it carries current arcs when the current
//! is at least the material's minimum arc current I_min and the circuit
//! can drive at least its minimum arc voltage V_min across the gap. The
//! arc burns at V_arc = V_min + E·gap(t) (electrode drops plus a column of
//! gradient E as long as the gap) and goes out when the current falls
//! below I_min. An open gap that is not arcing holds at most its breakdown
//! voltage V_bd(gap): above it the gap conducts, an arc if the current
//! that flows can reach I_min, otherwise a discharge at V_bd that lasts
//! while the circuit pushes (the envelope of the showering arc).
//!
//! - [`ArcSection`] is the scenario's `[arc]`, [`ArcModel`] its resolved
//!   numbers;
//! - [`breakdown_voltage`] is V_bd(d) in air;
//! - [`gap::GapProfile`] is gap(t) from the armature's own trajectory;
//! - [`vectors`] names what the arc element (written with the contact
//!   include, so ngspice carries the arc) puts in the raw file;
//! - [`analysis`] finds every arc and breakdown in the run's raw file;
//! - [`making`] is each make's peak current and what it does to the
//!   contact spot (the contact force at a coil-driven relay's makes comes
//!   from its run: [`crate::pipeline::make_force`]);
//! - [`breaking`] is the largest DC current the contact breaks, and the
//!   arc constants fitted to a printed breaking curve.

pub mod analysis;
pub mod breaking;
pub mod gap;
pub mod making;
mod model;
pub mod vectors;

pub use analysis::{ArcEvent, ArcReport, ArcTotals, Breakdown, StillBurning};
pub use gap::GapProfile;
pub use model::{
    ArcModel, ArcSection, DEFAULT_CAPACITANCE, DEFAULT_FIELD, DEFAULT_LOW_CURRENT,
    DEFAULT_LOW_CURRENT_GAP, DEFAULT_OPENING_SPEED, FIELD_EMISSION_FIELD, Material,
    PASCHEN_MINIMUM, REFERENCE_MATERIAL, breakdown_voltage,
};
pub use vectors::ArcVectors;
