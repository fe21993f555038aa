//! Reports: the last stage of the pipeline, where a result becomes text.
//!
//! One small module per format, each a pure function from the result to a
//! `String`:
//! - [`json`]: the contract of docs/output.md, for scripts;
//! - [`csv`]: one row per impact, for spreadsheets and plotting;
//! - [`table`]: a summary and an aligned impact table, for a person at a
//!   terminal, in engineering units;
//! - [`svg`]: a plot of the contact and the probed signals over time;
//! - [`bundle`]: every file of a `run --out DIR`.
//!
//! Output is deterministic: the same result gives byte-identical text (no
//! timestamps, fixed field order, shortest round-trip floats).
//! Files reach the disk through [`crate::output`], which never clobbers
//! an input or a user's file.

pub mod bundle;
pub mod csv;
#[cfg(feature = "png")]
mod glyphs;
pub mod json;
#[cfg(feature = "png")]
pub mod png;
pub mod svg;
pub mod table;
pub mod units;

use crate::chatter::Chatter;
use crate::mechanics::Dimensionless;

/// The formats a chatter result can be rendered in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The whole result as the JSON of docs/output.md.
    Json,
    /// The impacts as CSV, one row each.
    Csv,
    /// A summary and an impact table for a terminal.
    Table,
}

/// Render `chatter` in `format`. `dimensionless` (the relay's groups) is
/// added to the JSON when given; the other formats show the sequence only.
pub fn render(format: Format, chatter: &Chatter, dimensionless: Option<&Dimensionless>) -> String {
    match format {
        Format::Json => json::render(chatter, dimensionless),
        Format::Csv => csv::render(chatter),
        Format::Table => table::render(chatter),
    }
}

/// [`render`] for a two-stage relay: the pole face's impacts (when it
/// has one) are added to the JSON (`pole_face_impacts`) and the table.
pub fn render_two_stage(
    format: Format,
    chatter: &Chatter,
    dimensionless: Option<&Dimensionless>,
    pole_face: Option<&[crate::chatter::Impact]>,
) -> String {
    match format {
        Format::Json => json::render_with_pole_face(chatter, dimensionless, pole_face),
        Format::Csv => csv::render(chatter),
        Format::Table => {
            let mut text = table::render(chatter);
            if let Some(impacts) = pole_face {
                text.push_str(&table::pole_face(impacts));
            }
            text
        }
    }
}

pub use crate::output::{WriteError, is_input, protect_input, write_bundle, write_new_file};

/// Hand-built results for the renderers' tests: the contact record's
/// own fixtures.
#[cfg(test)]
pub(crate) use crate::chatter::fixtures;
