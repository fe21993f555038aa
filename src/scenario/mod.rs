//! The scenario file: one TOML file that describes a relay, its contact
//! surface and, optionally, the circuit it switches (docs/scenario.md).
//! Every command starts here.
//!
//! Loading has three steps, and every error names the file, the line when
//! there is one, and the dotted key (`mechanics.mass`, `probe[0].low`):
//! 1. TOML syntax, parsed into a tree that remembers where each key is;
//! 2. shape: serde structs with `deny_unknown_fields`, so a misspelt key
//!    is an error instead of a silently ignored line;
//! 3. physics: every number finite and in range, sections consistent
//!    (a step `force` or a `[coil]`, the keys of one surface law).
//!
//! A validated [`Scenario`] converts into the library's inputs:
//! [`Scenario::mechanics`], [`Scenario::surface`], [`Scenario::settings`].

mod access;
mod arc;
mod base;
#[cfg(test)]
mod base_tests;
mod builder;
mod builtin;
mod calibration;
mod check;
mod circuit;
mod coil;
mod contact;
mod document;
mod endurance;
mod envelope;
mod error;
mod figure;
mod keys;
mod law;
mod limits;
mod load;
mod mechanics;
mod model;
mod nominal;
mod numbers;
mod probes;
mod simulation;
mod surface;
mod sweep;
#[cfg(test)]
mod tests;
mod two_stage;
mod unset;

pub use base::{BUNDLED_PARTS, bundled_part, bundled_part_text};
pub use builder::ScenarioBuilder;
pub use builtin::{DEFAULT_NETLIST, DEFAULT_SCENARIO_TOML};
pub use calibration::{
    BreakingFigure, DatasheetSection, Determined, FitSection, FittedParameter, ProvenanceSection,
};
pub use circuit::CircuitSection;
pub use coil::CoilSection;
pub use contact::{ContactSection, HolmSection};
pub use endurance::{EnduranceFigure, Supply};
pub use envelope::{EnvelopeRange, EnvelopeSection};
pub use error::{InheritedConflict, Location, ScenarioError};
pub use figure::{FigureKind, PRINTED_PRECISION, PrintedFigure, TYPICAL_BAND};
pub use law::{ReleaseRule, SurfaceLaw};
pub use limits::LimitsSection;
pub use mechanics::MechanicsSection;
pub use model::Scenario;
pub use numbers::{ENVELOPE, NUMBER_KEYS, unit_of};
pub use probes::Probe;
pub use simulation::SimulationSection;
pub use surface::SurfaceSection;
pub use sweep::{GridAxis, SweepSection, Tolerance};
pub use two_stage::{BladeSection, PoleFaceSection};

pub use crate::arc::ArcSection;
