//! Calibration: from a real relay's evidence (a record of its contact
//! state, a datasheet) to the parameters of a scenario, with an honest
//! statement of what the evidence determined.

pub mod fit;
pub mod parts;
mod printed;
pub mod render;

/// The scenario sections calibration reads and writes (`[datasheet]`,
/// `[fit]`, `[provenance]`), defined with the other sections in
/// [`crate::scenario`].
pub mod sections {
    pub use crate::scenario::{
        DatasheetSection, Determined, FitSection, FittedParameter, PrintedFigure, ProvenanceSection,
    };
}
