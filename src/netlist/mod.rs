//! The netlist stage: from a contact [`Waveform`](crate::waveform::Waveform)
//! and the user's circuit to the files ngspice runs.
//!
//! - [`contact`]: the include file that defines the contact subcircuit
//!   (`.subckt CONTACT a b`), in one of several [`ContactElement`]s, plus
//!   any data files it reads.
//! - [`deck`]: the run deck built around the user's netlist, which is read
//!   and never written: the title is kept, the contact include is added,
//!   the files it includes are written in ([`inline`]), `.control` blocks
//!   and `*#` command lines are left out, probes are saved, and the
//!   netlist is checked for what the run needs (an `X` line using the
//!   contact, a `.tran` long enough to cover the chatter).
//! - [`inline`]: included files and `.lib` sections, read, checked and
//!   written into the deck, so that ngspice runs no command from data.
//! - [`number`]: SPICE numbers with scale suffixes (`10u`, `1meg`).
//!
//! Everything here is text in, text out, and deterministic.

pub mod arc;
pub mod coil;
pub mod contact;
pub mod deck;
pub mod elements;
mod error;
pub mod inline;
mod lexical;
pub mod number;

pub use contact::{
    ContactElement, ContactInclude, DEFAULT_POINTS_PER_SOURCE, EVENT_RAMP_ABOVE_POINTS,
    check_subckt_name, contact_include, contact_include_split,
};
pub use deck::{
    Deck, DeckRequest, DeckWarning, Tran, instance_nodes_of, instances_of, param_value,
    prepare_deck, prepare_deck_with_params, save_names,
};
pub use number::parse_number;

pub use error::NetlistError;
