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

pub mod coil;
pub mod contact;
pub mod deck;
pub mod inline;
pub mod number;

use std::io;
use std::path::PathBuf;

use thiserror::Error;

use crate::waveform::format_time;

pub use contact::{
    ContactElement, ContactInclude, DEFAULT_POINTS_PER_SOURCE, EVENT_RAMP_ABOVE_POINTS,
    check_subckt_name, contact_include, contact_include_split,
};
pub use deck::{
    Deck, DeckRequest, DeckWarning, Tran, instance_nodes_of, instances_of, param_value,
    prepare_deck, prepare_deck_with_params, save_names,
};
pub use number::parse_number;

/// Errors of this stage. Netlist problems name the file and the 1-based
/// line; every message says what to change.
#[derive(Debug, Error)]
pub enum NetlistError {
    #[error("the armature trajectory for the coil is empty: give at least one (time, x) point")]
    EmptyTrajectory,
    #[error(
        "armature trajectory point {index} at {time:?} s does not follow {previous:?} s \
         (or its position is not finite): times must strictly increase"
    )]
    BadTrajectory {
        index: usize,
        time: f64,
        previous: f64,
    },
    #[error(
        "contact subcircuit name {name:?} {problem}: use a SPICE identifier (a letter or `_`, \
         then letters, digits or `_`) such as CONTACT, instantiated as `X1 a b CONTACT`"
    )]
    BadSubcktName { name: String, problem: &'static str },
    #[error("unknown contact element {name:?}: use one of `pwl`, `event-ramp`, `switch`")]
    UnknownElement { name: String },
    #[error(
        "the include of subcircuit {subckt} has no `.subckt {subckt} a b` ... `.ends {subckt}` \
         to add the arc to: give the include `contact_include` made"
    )]
    NotAContactInclude { subckt: String },
    #[error(
        "contact element `{element}` cannot represent this waveform: {reason}; use element `pwl`"
    )]
    ElementUnsupported {
        element: ContactElement,
        reason: String,
    },
    #[error("{}: the netlist is empty: give it a title line, the circuit and a `.tran` line", netlist.display())]
    EmptyNetlist { netlist: PathBuf },
    #[error(
        "{}: no `X` line instantiates the contact subcircuit `{subckt}`: add one between the \
         contact's two nodes, e.g. `X1 a b {subckt}`",
        netlist.display()
    )]
    NoContactInstance { netlist: PathBuf, subckt: String },
    #[error(
        "{}: no `X` line instantiates the coil subcircuit `{subckt}`: the scenario has a \
         [coil], so the netlist's driver must drive it, e.g. `X2 coil_plus coil_minus {subckt}`",
        netlist.display()
    )]
    NoCoilInstance { netlist: PathBuf, subckt: String },
    #[error(
        "{}: `circuit.params.{name}`: the netlist defines no top-level `.param {name}` (in the \
         file or the files it includes) for the scenario to override{}",
        netlist.display(),
        if defined.is_empty() {
            format!("; it defines no .param at all: add `.param {name}=<value>` and use `{{{name}}}`")
        } else {
            format!("; it defines: {defined}")
        }
    )]
    UnknownParam {
        netlist: PathBuf,
        name: String,
        defined: String,
    },
    #[error(
        "{}: line {line}: the netlist defines its own `.subckt {subckt}`, which clashes with the \
         generated contact: remove that definition (chatterspice provides it) or name the \
         contact differently in the scenario's `circuit.subckt`",
        netlist.display()
    )]
    SubcktConflict {
        netlist: PathBuf,
        line: usize,
        subckt: String,
    },
    #[error(
        "{}: line {line}: `{card}` names {}, which does not exist: fix the path (a relative \
         path is read from the netlist's directory)",
        netlist.display(), resolved.display()
    )]
    MissingInclude {
        netlist: PathBuf,
        line: usize,
        card: String,
        resolved: PathBuf,
    },
    #[error("{}: cannot read {} (included at line {line}): {source}", netlist.display(), included.display())]
    ReadInclude {
        netlist: PathBuf,
        line: usize,
        included: PathBuf,
        #[source]
        source: io::Error,
    },
    #[error(
        "{}: line 1 starts with `*ng_script`, which makes ngspice run the file as a command \
         script: chatterspice runs circuits, not scripts; give the netlist a plain title line",
        netlist.display()
    )]
    ScriptTitle { netlist: PathBuf },
    #[error(
        "{}: line {line}: `{}` is already being included (the files include each other in a \
         circle): remove one of the includes",
        netlist.display(), included.display()
    )]
    IncludeCycle {
        netlist: PathBuf,
        line: usize,
        included: PathBuf,
    },
    #[error(
        "{}: line {line}: includes nest more than {depth} deep: flatten the include chain",
        netlist.display()
    )]
    IncludeTooDeep {
        netlist: PathBuf,
        line: usize,
        depth: usize,
    },
    #[error(
        "{}: line {line}: the included files come to more than {limit} bytes: include only the \
         models the circuit uses",
        netlist.display()
    )]
    IncludeTooLarge {
        netlist: PathBuf,
        line: usize,
        limit: usize,
    },
    #[error(
        "{}: line {line}: {} has no section `{section}` (`.lib {section}` ... `.endl`): check \
         the section name",
        netlist.display(), library.display()
    )]
    MissingLibSection {
        netlist: PathBuf,
        line: usize,
        library: PathBuf,
        section: String,
    },
    #[error("{}: line {line}: `.control` has no `.endc`: close the block with `.endc`", netlist.display())]
    UnclosedControl { netlist: PathBuf, line: usize },
    #[error(
        "{}: no `.tran` analysis{}: add a line such as `.tran 1u {}` (the run needs a transient \
         analysis that covers the chatter)",
        netlist.display(),
        control_note(*control_line),
        format_time(*stop)
    )]
    NoTran {
        netlist: PathBuf,
        /// s, the stop time to suggest.
        stop: f64,
        /// The first line of a `.control` block that was left out.
        control_line: Option<usize>,
    },
    #[error(
        "{}: lines {first} and {second} both hold a `.tran` analysis: keep one",
        netlist.display()
    )]
    TwoTran {
        netlist: PathBuf,
        first: usize,
        second: usize,
    },
    #[error("{}: line {line}: `{card}`: {problem}", netlist.display())]
    BadTran {
        netlist: PathBuf,
        line: usize,
        card: String,
        problem: String,
    },
    #[error(
        "{}: line {line}: `.tran` stops at {} s, before the chatter ends at {} s: set its stop \
         time to at least {} s, e.g. `.tran {} {}`",
        netlist.display(),
        format_time(*tstop),
        format_time(*chatter_end),
        format_time(*stop),
        format_time(*tstep),
        format_time(*stop)
    )]
    TranTooShort {
        netlist: PathBuf,
        line: usize,
        /// s
        tstop: f64,
        /// s
        tstep: f64,
        /// s
        chatter_end: f64,
        /// s, the stop time to use.
        stop: f64,
    },
    #[error(
        "probe `{signal}` is not a voltage `v(node)`, `v(node1,node2)` or a current \
         `i(vsource)`: write it in one of those forms"
    )]
    BadProbe { signal: String },
}

fn control_note(line: Option<usize>) -> String {
    match line {
        Some(l) => format!(
            " outside the `.control` block at line {l}, which a batch run leaves out \
             (its `tran` command does not count)"
        ),
        None => String::new(),
    }
}
