//! What the netlist stage reports: the errors that stop a deck (each
//! naming the file and line to fix) and the warnings about what the deck
//! changed.

use std::fmt;
use std::io;
use std::path::PathBuf;

use thiserror::Error;

use crate::waveform::format_time;

/// Errors of this stage. Netlist problems name the file and the 1-based
/// line; every message says what to change.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum NetlistError {
    /// The coil include was given no armature trajectory.
    #[error("the armature trajectory for the coil is empty: give at least one (time, x) point")]
    EmptyTrajectory,
    /// A trajectory point's time does not follow the one before it, or
    /// its position is not finite.
    #[error(
        "armature trajectory point {index} at {time:?} s does not follow {previous:?} s \
         (or its position is not finite): times must strictly increase"
    )]
    BadTrajectory {
        /// The 0-based index of the point.
        index: usize,
        /// s, the point's time.
        time: f64,
        /// s, the time of the point before it.
        previous: f64,
    },
    /// The subcircuit name is not a SPICE identifier.
    #[error(
        "contact subcircuit name {name:?} {problem}: use a SPICE identifier (a letter or `_`, \
         then letters, digits or `_`) such as CONTACT, instantiated as `X1 a b CONTACT`"
    )]
    BadSubcktName {
        /// The name given.
        name: String,
        /// What is wrong with it.
        problem: &'static str,
    },
    /// The contact element's name is none of `pwl`, `event-ramp`, `switch`.
    #[error("unknown contact element {name:?}: use one of `pwl`, `event-ramp`, `switch`")]
    UnknownElement {
        /// The name given.
        name: String,
    },
    /// The include given to add the arc to has no contact subcircuit.
    #[error(
        "the include of subcircuit {subckt} has no `.subckt {subckt} a b` ... `.ends {subckt}` \
         to add the arc to: give the include `contact_include` made"
    )]
    NotAContactInclude {
        /// The subcircuit name looked for.
        subckt: String,
    },
    /// The chosen contact element cannot represent the waveform.
    #[error(
        "contact element `{element}` cannot represent this waveform: {reason}; use element `pwl`"
    )]
    ElementUnsupported {
        /// The element asked for, as the scenario and `--element` name it
        /// (`event-ramp`, ...).
        element: String,
        /// What in the waveform it cannot represent.
        reason: String,
    },
    /// The netlist file is empty or blank.
    #[error("{}: the netlist is empty: give it a title line, the circuit and a `.tran` line", netlist.display())]
    EmptyNetlist {
        /// The netlist file.
        netlist: PathBuf,
    },
    /// No `X` line of the netlist or its includes uses the contact.
    #[error(
        "{}: no `X` line instantiates the contact subcircuit `{subckt}`: add one between the \
         contact's two nodes, e.g. `X1 a b {subckt}`",
        netlist.display()
    )]
    NoContactInstance {
        /// The netlist file.
        netlist: PathBuf,
        /// The contact's subcircuit name.
        subckt: String,
    },
    /// The scenario has a coil, but no `X` line uses its subcircuit.
    #[error(
        "{}: no `X` line instantiates the coil subcircuit `{subckt}`: the scenario has a \
         [coil], so the netlist's driver must drive it, e.g. `X2 coil_plus coil_minus {subckt}`",
        netlist.display()
    )]
    NoCoilInstance {
        /// The netlist file.
        netlist: PathBuf,
        /// The coil's subcircuit name.
        subckt: String,
    },
    /// A `circuit.params` key names no top-level `.param` of the netlist.
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
        /// The netlist file.
        netlist: PathBuf,
        /// The parameter the scenario overrides.
        name: String,
        /// The parameters the netlist defines, comma-separated (empty
        /// when none).
        defined: String,
    },
    /// The netlist defines a subcircuit of the contact's name itself.
    #[error(
        "{}: line {line}: the netlist defines its own `.subckt {subckt}`, which clashes with the \
         generated contact: remove that definition (chatterspice provides it) or name the \
         contact differently in the scenario's `circuit.subckt`",
        netlist.display()
    )]
    SubcktConflict {
        /// The file that defines it.
        netlist: PathBuf,
        /// 1-based line of the `.subckt`.
        line: usize,
        /// The contact's subcircuit name.
        subckt: String,
    },
    /// An `.include` or `.lib` names a file that does not exist.
    #[error(
        "{}: line {line}: `{card}` names {}, which does not exist: fix the path (a relative \
         path is read from the netlist's directory)",
        netlist.display(), resolved.display()
    )]
    MissingInclude {
        /// The file that holds the card.
        netlist: PathBuf,
        /// 1-based line of the card.
        line: usize,
        /// The card, as written.
        card: String,
        /// The path it names, resolved against the file's directory.
        resolved: PathBuf,
    },
    /// An included file exists but cannot be read (or is not a regular
    /// file, or is too large).
    #[error("{}: cannot read {} (included at line {line}): {source}", netlist.display(), included.display())]
    ReadInclude {
        /// The file that includes it.
        netlist: PathBuf,
        /// 1-based line of the include.
        line: usize,
        /// The included file.
        included: PathBuf,
        /// Why it cannot be read.
        #[source]
        source: io::Error,
    },
    /// The netlist's title line makes ngspice read it as a script.
    #[error(
        "{}: line 1 starts with `*ng_script`, which makes ngspice run the file as a command \
         script: chatterspice runs circuits, not scripts; give the netlist a plain title line",
        netlist.display()
    )]
    ScriptTitle {
        /// The netlist file.
        netlist: PathBuf,
    },
    /// A file includes itself, directly or through others.
    #[error(
        "{}: line {line}: `{}` is already being included (the files include each other in a \
         circle): remove one of the includes",
        netlist.display(), included.display()
    )]
    IncludeCycle {
        /// The file whose include closes the circle.
        netlist: PathBuf,
        /// 1-based line of that include.
        line: usize,
        /// The file included again.
        included: PathBuf,
    },
    /// Includes nest deeper than the limit.
    #[error(
        "{}: line {line}: includes nest more than {depth} deep: flatten the include chain",
        netlist.display()
    )]
    IncludeTooDeep {
        /// The file whose include goes too deep.
        netlist: PathBuf,
        /// 1-based line of that include.
        line: usize,
        /// The nesting limit.
        depth: usize,
    },
    /// The included files together exceed the size limit.
    #[error(
        "{}: line {line}: the included files come to more than {limit} bytes: include only the \
         models the circuit uses",
        netlist.display()
    )]
    IncludeTooLarge {
        /// The file whose include passes the limit.
        netlist: PathBuf,
        /// 1-based line of that include.
        line: usize,
        /// The limit, in bytes.
        limit: usize,
    },
    /// A `.lib FILE SECTION` names a section the file does not have.
    #[error(
        "{}: line {line}: {} has no section `{section}` (`.lib {section}` ... `.endl`): check \
         the section name",
        netlist.display(), library.display()
    )]
    MissingLibSection {
        /// The file that holds the `.lib` card.
        netlist: PathBuf,
        /// 1-based line of the card.
        line: usize,
        /// The library file.
        library: PathBuf,
        /// The section asked for.
        section: String,
    },
    /// A `.control` block is not closed by `.endc`.
    #[error("{}: line {line}: `.control` has no `.endc`: close the block with `.endc`", netlist.display())]
    UnclosedControl {
        /// The file that holds the block.
        netlist: PathBuf,
        /// 1-based line of the `.control`.
        line: usize,
    },
    /// The netlist has no `.tran` card outside `.control` blocks.
    #[error(
        "{}: no `.tran` analysis{}: add a line such as `.tran 1u {}` (the run needs a transient \
         analysis that covers the chatter)",
        netlist.display(),
        control_note(*control_line),
        format_time(*stop)
    )]
    NoTran {
        /// The netlist file.
        netlist: PathBuf,
        /// s, the stop time to suggest.
        stop: f64,
        /// The first line of a `.control` block that was left out.
        control_line: Option<usize>,
    },
    /// The netlist has more than one `.tran` card.
    #[error(
        "{}: lines {first} and {second} both hold a `.tran` analysis: keep one",
        netlist.display()
    )]
    TwoTran {
        /// The netlist file.
        netlist: PathBuf,
        /// 1-based line of the first `.tran`.
        first: usize,
        /// 1-based line of the second.
        second: usize,
    },
    /// The `.tran` card cannot be read (missing or bad numbers).
    #[error("{}: line {line}: `{card}`: {problem}", netlist.display())]
    BadTran {
        /// The netlist file.
        netlist: PathBuf,
        /// 1-based line of the card.
        line: usize,
        /// The card, as written.
        card: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The `.tran` stops before the chatter ends.
    #[error(
        "{}: line {line}: `.tran` stops at {} s, before the chatter ends at {} s: set its stop \
         time to at least {} s, e.g. `{card}`",
        netlist.display(),
        format_time(*tstop),
        format_time(*chatter_end),
        format_time(*stop)
    )]
    TranTooShort {
        /// The netlist file.
        netlist: PathBuf,
        /// 1-based line of the `.tran`.
        line: usize,
        /// s, the `.tran` stop time.
        tstop: f64,
        /// s, the `.tran` step.
        tstep: f64,
        /// s, when the chatter ends.
        chatter_end: f64,
        /// s, the stop time to use.
        stop: f64,
        /// The user's card with that stop time (step, TSTART, TMAX and
        /// `uic` kept).
        card: String,
    },
    /// A probe's signal is not `v(node)`, `v(node1,node2)` or `i(vsource)`.
    #[error(
        "probe `{signal}` is not a voltage `v(node)`, `v(node1,node2)` or a current \
         `i(vsource)`: write it in one of those forms"
    )]
    BadProbe {
        /// The probe's signal, as written.
        signal: String,
    },
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

/// Something the deck changed or the user may want to change.
#[derive(Debug, Clone, PartialEq)]
pub enum DeckWarning {
    /// A `.control` block was left out of the run.
    ControlRemoved {
        /// The file that holds it.
        netlist: PathBuf,
        /// 1-based line of the `.control`.
        first: usize,
        /// 1-based line of the `.endc`.
        last: usize,
    },
    /// Text follows `.end`, which ngspice ignores too.
    IgnoredAfterEnd {
        /// The netlist file.
        netlist: PathBuf,
        /// 1-based line of the first such text.
        line: usize,
    },
    /// The `.tran` covers the chatter but stops soon after it.
    StopShort {
        /// The netlist file.
        netlist: PathBuf,
        /// 1-based line of the `.tran`.
        line: usize,
        /// s, its stop time.
        tstop: f64,
        /// s, its step.
        tstep: f64,
        /// s, the stop time to use instead.
        wanted: f64,
        /// The user's card with that stop time (step, TSTART, TMAX and
        /// `uic` kept).
        card: String,
    },
    /// The first line, which ngspice takes as the title, looks like a
    /// dot-card.
    TitleIsCard {
        /// The netlist file.
        netlist: PathBuf,
        /// The first line.
        text: String,
    },
    /// `interp` was removed from an `.options` card.
    InterpRemoved {
        /// The file that holds the card.
        netlist: PathBuf,
        /// 1-based line of the card.
        line: usize,
    },
    /// A `*#` line, which ngspice runs as a command.
    CommandCommentRemoved {
        /// The file that holds it.
        netlist: PathBuf,
        /// 1-based line.
        line: usize,
    },
}

impl fmt::Display for DeckWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DeckWarning::InterpRemoved { netlist, line } => write!(
                f,
                "{}: line {line}: `interp` is left out of the run's `.options`: ngspice 39 \
                 writes an interpolated raw file whose time stamps run slow wherever its time \
                 step exceeds the `.tran` step (and more points than it declares), so the \
                 analysis would be wrong; the run keeps every point ngspice computes instead",
                netlist.display()
            ),
            DeckWarning::CommandCommentRemoved { netlist, line } => write!(
                f,
                "{}: line {line}: the `*#` line is left out of the run: ngspice runs such a \
                 comment as a command, and chatterspice runs no commands from netlists; write \
                 `* #` for a plain comment",
                netlist.display()
            ),
            DeckWarning::ControlRemoved {
                netlist,
                first,
                last,
            } => write!(
                f,
                "{}: lines {first}-{last}: the `.control` block is left out of the run: \
                 chatterspice runs the netlist's dot-analyses in batch mode and writes the raw \
                 file itself (the block's commands would run a second analysis, write elsewhere \
                 or quit first); move what it sets into dot-cards such as `.options`",
                netlist.display()
            ),
            DeckWarning::IgnoredAfterEnd { netlist, line } => write!(
                f,
                "{}: line {line}: text after `.end` is ignored, as ngspice does",
                netlist.display()
            ),
            DeckWarning::StopShort {
                netlist,
                line,
                tstop,
                card,
                ..
            } => write!(
                f,
                "{}: line {line}: `.tran` stops at {} s, soon after the chatter: to see the \
                 circuit settle, use `{card}`",
                netlist.display(),
                format_time(*tstop)
            ),
            DeckWarning::TitleIsCard { netlist, text } => write!(
                f,
                "{}: line 1 `{text}` is read by ngspice as the title and ignored: put a title \
                 line first",
                netlist.display()
            ),
        }
    }
}
