//! Sweeps: the same relay and circuit run many times, each sample with
//! its own values of a few numbers, to answer "does the design hold for
//! every relay off the line, and how close to the edge is it?"
//! (`chatterspice sweep`, docs/sweep.md).
//!
//! A sweep is built from the scenario's `[sweep]` section in four parts,
//! one module each:
//! - [`sample`]: the values of sample `i` — random draws (`[sweep.vary]`,
//!   deterministic in (seed, key, i)) or the points of a one- or two-key
//!   grid (`[sweep.grid]`);
//! - [`mod@run`]: every sample through [`pipeline::run`](crate::pipeline::run)
//!   (mechanics → contact → netlist → ngspice → analysis) or through the
//!   mechanics alone, on several threads, each sample's outcome a
//!   [`SampleRecord`] — a failing sample (never closes, ngspice error, timeout)
//!   is a record too, and the sweep goes on;
//! - [`table`]: the records as `sweep.csv`, one row per sample in index
//!   order, and [`table::merge`] that joins the CSVs of shards;
//! - [`summary`]: distributions, the worst case and the failures, as
//!   `summary.json`, a table for people, and a plot ([`plot`]), from a
//!   few numbers per sample kept in bounded memory (a temporary file
//!   beyond 65 536 samples), so that 10⁷ samples need no more memory
//!   than 10⁵;
//! - [`files`]: all of them written into a directory, the CSV row by row
//!   while the sweep runs (`sweep --out DIR`).
//!
//! # Determinism
//! Sample `i`'s values depend only on the seed and `i`, never on `--jobs`
//! or on the shard that runs it, and rows are written in index order, so
//! the same sweep gives byte-identical files however it is run. A shard
//! `K/N` runs the indices `i` with `i % N == K − 1` (interleaved rather
//! than contiguous, so that a grid's slow corner is spread over all
//! shards); merging the shards' CSVs gives the CSV of one run, byte for
//! byte.

mod error;
pub mod files;
pub mod merge;
pub mod plot;
mod record;
pub mod resume;
pub mod run;
pub mod sample;
mod spill;
pub mod summary;
pub mod table;
pub mod verdict;

pub use error::SweepError;
pub use record::{ProbeRecord, SampleRecord, Shard};
pub use run::{NoProgress, Progress, SweepMode, SweepOptions, run, run_from, run_sample};
pub use sample::Sampler;
pub use summary::{Collected, Summary};
pub use verdict::SampleVerdict;
#[allow(deprecated)]
pub use {record::Record, run::Mode, run::evaluate, verdict::Verdict};
