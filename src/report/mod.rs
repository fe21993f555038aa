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

/// Hand-built results for the renderers' tests: the engine is tested on
/// its own, and these pin down every shape a report must handle.
#[cfg(test)]
pub(crate) mod fixtures {
    use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome};

    fn interval(state: ContactState, start: f64, end: f64) -> Interval {
        Interval { state, start, end }
    }

    /// Two bounces, then stuck on the third impact (Kelvin–Voigt-like).
    pub fn stuck() -> Chatter {
        use ContactState::{Closed, Open};
        let bounce = |t: f64, v: f64, tr: f64, vr: f64, peak: f64, min: f64, gap: f64| Impact {
            impact_time: t,
            impact_velocity: v,
            release_time: Some(tr),
            release_velocity: Some(vr),
            restitution: Some(-vr / v),
            contact_time: Some(tr - t),
            peak_force: Some(peak),
            min_force: Some(min),
            max_gap_after: Some(gap),
        };
        Chatter {
            outcome: Outcome::Stuck,
            first_impact: Some(0.0012),
            settle_time: Some(0.0016),
            bounce_count: 2,
            impacts: vec![
                bounce(0.0012, 0.31, 0.00121, -0.26, 2.1, -0.1, 3.0e-6),
                bounce(0.0014, 0.2, 0.001405, -0.15, 1.25, -0.04, 1.0e-6),
                Impact {
                    impact_time: 0.0016,
                    impact_velocity: 0.05,
                    release_time: None,
                    release_velocity: None,
                    restitution: None,
                    contact_time: None,
                    peak_force: Some(0.6),
                    min_force: Some(0.36),
                    max_gap_after: None,
                },
            ],
            intervals: vec![
                interval(Open, 0.0, 0.0012),
                interval(Closed, 0.0012, 0.00121),
                interval(Open, 0.00121, 0.0014),
                interval(Closed, 0.0014, 0.001405),
                interval(Open, 0.001405, 0.0016),
                interval(Closed, 0.0016, 0.02),
            ],
            shortfall: None,
            accumulation_time: None,
            t_end: 0.02,
        }
    }

    /// The gap is beyond the overshoot: no impact at all.
    pub fn never_closes() -> Chatter {
        Chatter {
            outcome: Outcome::NeverCloses,
            first_impact: None,
            settle_time: None,
            bounce_count: 0,
            impacts: vec![],
            intervals: vec![interval(ContactState::Open, 0.0, 0.02)],
            shortfall: Some(2.5e-5),
            accumulation_time: None,
            t_end: 0.02,
        }
    }
}
