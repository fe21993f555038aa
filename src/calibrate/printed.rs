//! How a printed datasheet figure reads in a table: its unit, from its
//! name, and its typical value, limits and tolerance in engineering units.
//! Shared by the parts listing and the fit report.

use crate::report::units::engineering;
use crate::scenario::PrintedFigure;

/// The unit of a datasheet figure.
pub(crate) fn unit_of(name: &str) -> &'static str {
    if name.ends_with("_voltage") {
        "V"
    } else if name.ends_with("_resistance") {
        "Ω"
    } else if name.ends_with("_current") {
        "A"
    } else {
        "s"
    }
}

/// A printed figure in engineering units: `≤ 10 ms`, `63 Ω ±10 %`,
/// `1 ms typ., ≤ 5 ms`.
pub(crate) fn printed_text(f: &PrintedFigure, unit: &str) -> String {
    let mut parts = Vec::new();
    if let Some(t) = f.typ {
        let mut text = engineering(t, unit);
        if let Some(tol) = f.tolerance {
            text.push_str(&format!(" ±{} %", (tol * 1e5).round() / 1e3));
        }
        if f.min.is_some() || f.max.is_some() {
            text.push_str(" typ.");
        }
        parts.push(text);
    }
    if let Some(v) = f.min {
        parts.push(format!("≥ {}", engineering(v, unit)));
    }
    if let Some(v) = f.max {
        parts.push(format!("≤ {}", engineering(v, unit)));
    }
    parts.join(", ")
}
