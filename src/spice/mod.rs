//! Running ngspice: the netlist goes in, a [`RawFile`](crate::rawfile::RawFile) (or a typed failure)
//! comes out.
//!
//! Everything above this module talks to a [`Runner`]:
//! - [`Ngspice`] runs the real program in batch mode
//!   (`ngspice -b -r out.raw -D norefvalue deck.cir`, no shell; many decks in one
//!   process when asked for many at once) in a fresh work directory
//!   per run, reads stdout and stderr on their own threads (a full pipe
//!   would stall the child), and kills and reaps it at a wall-clock timeout
//!   — nothing in ngspice times out by itself;
//! - [`FakeRunner`] serves committed raw files, so analysis and reports are
//!   testable on machines without ngspice.
//!
//! A failed run is a [`SpiceError`] that says what went wrong in the
//! user's terms (the deck line, the simulated time and node, the timeout),
//! names the work directory and carries the tail of ngspice's log. The
//! log is read by [`classify::classify`], which knows that `Note:` and
//! `Warning:` lines are not failures.
//!
//! Runs share no state: a [`Runner`] is `Send + Sync` and many runs may go
//! at once (sweeps run them in parallel).

pub mod classify;
mod error;
pub mod fake;
pub mod ngspice;
mod run;
pub mod shared;

pub use classify::{Exit, Failure};
pub use error::{LOG_TAIL_LINES, RunContext, SpiceError, log_tail};
pub use fake::FakeRunner;
pub use ngspice::Ngspice;
pub use run::{RunOutput, RunRequest, Runner};
