//! The netlist stage: from a contact [`Waveform`](crate::waveform::Waveform)
//! and the user's circuit to the files ngspice runs.
//!
//! - [`contact`]: the include file that defines the contact subcircuit
//!   (`.subckt CONTACT a b`), in one of several [`ContactElement`]s, plus
//!   any data files it reads.
//! - [`number`]: SPICE numbers with scale suffixes (`10u`, `1meg`).
//!
//! Everything here is text in, text out, and deterministic.

pub mod contact;
pub mod number;

use thiserror::Error;

pub use contact::{
    ContactElement, ContactInclude, DEFAULT_POINTS_PER_SOURCE, check_subckt_name, contact_include,
    contact_include_split,
};
pub use number::parse_number;

/// Errors of this stage. Netlist problems name the file and the 1-based
/// line; every message says what to change.
#[derive(Debug, Error)]
pub enum NetlistError {
    #[error(
        "contact subcircuit name {name:?} {problem}: use a SPICE identifier (a letter or `_`, \
         then letters, digits or `_`) such as CONTACT, instantiated as `X1 a b CONTACT`"
    )]
    BadSubcktName { name: String, problem: &'static str },
    #[error(
        "unknown contact element {name:?}: use one of `pwl`, `event-ramp`, `filesource`, `switch`"
    )]
    UnknownElement { name: String },
    #[error(
        "contact element `{element}` cannot represent this waveform: {reason}; use element `pwl`"
    )]
    ElementUnsupported {
        element: ContactElement,
        reason: String,
    },
}

