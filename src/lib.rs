//! # chatterspice
//!
//! Relay contact bounce from physics, into circuit simulation.
//!
//! The pipeline: a relay's moving contact is a damped oscillator driven
//! onto a fixed contact whose surface law (rigid, Kelvin–Voigt or
//! Hunt–Crossley) decides how it rebounds ([`mechanics`]); the engine
//! returns the exact chatter sequence ([`chatter`]); later stages turn it
//! into a contact resistance waveform ([`waveform`]), an ngspice netlist
//! ([`netlist`]), a batch run ([`spice`], [`rawfile`]) and an analysis of
//! the probed signals ([`analysis`]); [`pipeline`] runs them in order.
//! A coil-driven relay is coupled to its driver circuit ([`coil`]); on a
//! power load the contact arcs ([`arc`]); scope captures and datasheets
//! calibrate the model ([`capture`], [`calibrate`]). [`verdict`] is every
//! verdict a command gives (`run`, `check` with the electrical life among
//! its limits, `check --envelope`, `life`), computed once for the binary
//! and the Python package; [`commands`] holds the work of `bounce`.

pub mod analysis;
pub mod arc;
pub mod calibrate;
pub mod capture;
pub mod chatter;
pub mod check;
pub mod coil;
pub mod commands;
pub mod envelope;
pub mod input;
pub mod interrupt;
pub mod life;
pub mod mechanics;
pub mod netlist;
pub mod output;
pub mod pipeline;
pub mod plan;
pub mod rawfile;
pub mod report;
pub mod scenario;
pub mod spice;
pub mod sweep;
pub mod verdict;
pub mod waveform;

pub use chatter::{Chatter, ContactState, Impact, Interval, Outcome};
pub use mechanics::{Mechanics, MechanicsError, Settings, Surface, simulate};
