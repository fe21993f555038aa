//! The impacts as CSV: one row per impact, for spreadsheets and plots.
//!
//! The header is the impact field names of the JSON (docs/output.md),
//! in the same order; an absent value (the release of the final, stuck
//! contact) is an empty cell. Only the impacts are here: the summary
//! (outcome, settle time) and the open/closed `intervals` are in the JSON.
//! A result without impacts gives the header alone. Numbers are SI, in
//! Rust's shortest round-trip form; no cell ever needs quoting.

use crate::analysis::{AnalysisError, signal_values};
use crate::chatter::{Chatter, Impact};
use crate::rawfile::{Plot, Vector};
use crate::waveform::Waveform;

/// The column names, matching [`Impact`]'s JSON field names.
pub const HEADER: [&str; 9] = [
    "impact_time",
    "impact_velocity",
    "release_time",
    "release_velocity",
    "restitution",
    "contact_time",
    "peak_force",
    "min_force",
    "max_gap_after",
];

fn row(i: &Impact) -> [Option<f64>; 9] {
    [
        Some(i.impact_time),
        Some(i.impact_velocity),
        i.release_time,
        i.release_velocity,
        i.restitution,
        i.contact_time,
        i.peak_force,
        i.min_force,
        i.max_gap_after,
    ]
}

/// The header line and one line per impact, `\n`-terminated.
pub fn render(chatter: &Chatter) -> String {
    let mut out = HEADER.join(",");
    out.push('\n');
    for impact in &chatter.impacts {
        let cells: Vec<String> = row(impact)
            .iter()
            .map(|v| v.map_or_else(String::new, |x| format!("{x:?}")))
            .collect();
        out.push_str(&cells.join(","));
        out.push('\n');
    }
    out
}

/// A simulation's signals as CSV, one row per ngspice time point: `time`
/// (s), then `contact_resistance` (Ω, from `contact` at that time) when
/// given, then each of `signals` in its own unit. Names with a comma
/// (`v(a,b)`) are quoted. Fails only when a signal is not in `plot`.
pub fn waveforms(
    plot: &Plot,
    contact: Option<&Waveform>,
    signals: &[&str],
) -> Result<String, AnalysisError> {
    let time: &[f64] = match plot.scale() {
        Some(Vector::Real(t)) => t,
        _ => &[],
    };
    let columns = signals
        .iter()
        .map(|s| signal_values(plot, s).map(|(values, _)| values))
        .collect::<Result<Vec<_>, _>>()?;
    let mut out = ::csv::Writer::from_writer(Vec::new());
    let mut header = vec!["time"];
    if contact.is_some() {
        header.push("contact_resistance");
    }
    header.extend_from_slice(signals);
    let written = out.write_record(&header).and_then(|()| {
        for (i, &t) in time.iter().enumerate() {
            let mut row = vec![format!("{t:?}")];
            if let Some(w) = contact {
                row.push(format!("{:?}", w.resistance_at(t)));
            }
            row.extend(columns.iter().map(|c| format!("{:?}", c[i])));
            out.write_record(&row)?;
        }
        Ok(())
    });
    // Writing into a Vec cannot fail.
    written.expect("CSV into memory");
    let bytes = out.into_inner().expect("CSV into memory");
    Ok(String::from_utf8(bytes).expect("CSV of ASCII names and numbers"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixtures;

    #[test]
    fn header_matches_the_json_field_names() {
        let json = serde_json::to_value(&fixtures::stuck().impacts[0]).unwrap();
        let mut names: Vec<&str> = json
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        let mut header = HEADER.to_vec();
        names.sort_unstable();
        header.sort_unstable();
        assert_eq!(header, names);
    }

    #[test]
    fn one_row_per_impact_with_empty_cells_for_absent_values() {
        let text = render(&fixtures::stuck());
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 1 + 3);
        assert_eq!(lines[0], HEADER.join(","));
        assert!(
            lines[1].starts_with("0.0012,0.31,0.00121,-0.26,"),
            "{}",
            lines[1]
        );
        assert!(lines[1].ends_with(",2.1,-0.1,3e-6"), "{}", lines[1]);
        assert_eq!(lines[3], "0.0016,0.05,,,,,0.6,0.36,");
        for line in &lines {
            assert_eq!(line.split(',').count(), HEADER.len());
        }
    }

    #[test]
    fn cells_round_trip_exactly() {
        let chatter = fixtures::stuck();
        let text = render(&chatter);
        let second: Vec<f64> = text
            .lines()
            .nth(2)
            .unwrap()
            .split(',')
            .map(|c| c.parse().unwrap())
            .collect();
        assert_eq!(second, row(&chatter.impacts[1]).map(Option::unwrap));
    }

    #[test]
    fn no_impacts_gives_the_header_alone() {
        assert_eq!(
            render(&fixtures::never_closes()),
            format!("{}\n", HEADER.join(","))
        );
    }
}
