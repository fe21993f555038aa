//! The bounce result for a person at a terminal: a summary, then the
//! impacts as an aligned table, in engineering units (ms, µs, mm/s, mN,
//! µm) so that a typical relay reads without exponents.
//!
//! Times keep four decimals of a millisecond (0.1 µs) so that impacts a
//! few microseconds apart stay distinguishable; other quantities keep four
//! significant digits.

use std::fmt::Write;

use crate::chatter::{Chatter, Impact, Outcome};

/// Summary and impact table, `\n`-terminated.
pub fn render(chatter: &Chatter) -> String {
    let mut out = String::new();
    let bounce_time = match (chatter.first_impact, chatter.settle_time) {
        (Some(first), Some(settle)) => Some(settle - first),
        _ => None,
    };
    let mut summary = vec![
        (
            "outcome",
            format!("{} ({})", chatter.outcome, explain(chatter.outcome)),
        ),
        ("first impact", ms(chatter.first_impact)),
        ("settle time", ms(chatter.settle_time)),
        ("bounce time", ms(bounce_time)),
        ("bounces", chatter.bounce_count.to_string()),
    ];
    if let Some(t) = chatter.accumulation_time {
        summary.push(("accumulation", ms(Some(t))));
    }
    if let Some(shortfall) = chatter.shortfall {
        summary.push(("shortfall", sig(Some(shortfall * 1e6), " µm")));
    }
    summary.push(("simulated to", ms(Some(chatter.t_end))));
    let label_width = summary.iter().map(|(l, _)| l.len()).max().unwrap_or(0);
    for (label, value) in &summary {
        // Writing to a String cannot fail.
        let _ = writeln!(out, "{label:<label_width$}  {value}");
    }

    if chatter.impacts.is_empty() {
        return out;
    }
    out.push('\n');
    let mut rows = vec![
        [
            "#",
            "impact",
            "v impact",
            "release",
            "v release",
            "e",
            "contact",
            "peak force",
            "min force",
            "max gap after",
        ]
        .map(String::from),
        ["", "ms", "mm/s", "ms", "mm/s", "", "µs", "mN", "mN", "µm"].map(String::from),
    ];
    for (n, impact) in chatter.impacts.iter().enumerate() {
        rows.push(impact_row(n + 1, impact));
    }
    out.push_str(&align(&rows));
    out
}

fn explain(outcome: Outcome) -> &'static str {
    match outcome {
        Outcome::Stuck => "closed for good",
        Outcome::Resolved => "closed for good; later bounces are below resolution",
        Outcome::NeverCloses => "the contacts never touch",
        Outcome::EndsOpen => "touched, but the contact ends open",
        Outcome::EndOfTime => "still bouncing at the end of the simulation",
    }
}

fn impact_row(n: usize, i: &Impact) -> [String; 10] {
    [
        n.to_string(),
        fixed(Some(i.impact_time * 1e3), 4),
        sig(Some(i.impact_velocity * 1e3), ""),
        fixed(i.release_time.map(|t| t * 1e3), 4),
        sig(i.release_velocity.map(|v| v * 1e3), ""),
        fixed(i.restitution, 3),
        sig(i.contact_time.map(|t| t * 1e6), ""),
        sig(i.peak_force.map(|f| f * 1e3), ""),
        sig(i.min_force.map(|f| f * 1e3), ""),
        sig(i.max_gap_after.map(|g| g * 1e6), ""),
    ]
}

/// Right-aligned columns two spaces apart.
fn align<const N: usize>(rows: &[[String; N]]) -> String {
    let width = |c: usize| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0);
    let widths: Vec<usize> = (0..N).map(width).collect();
    let mut out = String::new();
    for row in rows {
        let cells: Vec<String> = row
            .iter()
            .zip(&widths)
            .map(|(cell, &w)| format!("{cell:>w$}"))
            .collect();
        out.push_str(cells.join("  ").trim_end());
        out.push('\n');
    }
    out
}

const ABSENT: &str = "-";

/// Seconds as milliseconds with four decimals.
fn ms(seconds: Option<f64>) -> String {
    match seconds {
        Some(s) => format!("{:.4} ms", s * 1e3),
        None => ABSENT.to_owned(),
    }
}

fn fixed(value: Option<f64>, decimals: usize) -> String {
    value.map_or_else(|| ABSENT.to_owned(), |v| format!("{v:.decimals$}"))
}

/// Four significant digits, without an exponent.
fn sig(value: Option<f64>, unit: &str) -> String {
    const DIGITS: i32 = 4;
    let Some(v) = value else {
        return ABSENT.to_owned();
    };
    if v == 0.0 || !v.is_finite() {
        return format!("{v}{unit}");
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (DIGITS - 1 - magnitude).clamp(0, 12) as usize;
    format!("{v:.decimals$}{unit}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fixtures;

    #[test]
    fn summary_in_engineering_units() {
        let text = render(&fixtures::stuck());
        let expected_summary = "\
outcome       stuck (closed for good)
first impact  1.2000 ms
settle time   1.6000 ms
bounce time   0.4000 ms
bounces       2
simulated to  20.0000 ms
";
        assert!(text.starts_with(expected_summary), "{text}");
    }

    #[test]
    fn impact_table_is_aligned_with_units() {
        let text = render(&fixtures::stuck());
        let table: Vec<&str> = text.lines().skip_while(|l| !l.is_empty()).skip(1).collect();
        assert_eq!(table.len(), 2 + 3, "{text}");
        assert!(table[1].contains("ms") && table[1].contains("mm/s") && table[1].contains("µs"));
        // Row 1: 1.2 ms, 310 mm/s, release at 1.21 ms, −260 mm/s, 10 µs.
        let cells: Vec<&str> = table[2].split_whitespace().collect();
        assert_eq!(
            cells,
            [
                "1", "1.2000", "310.0", "1.2100", "-260.0", "0.839", "10.00", "2100", "-100.0",
                "3.000"
            ]
        );
        // The stuck contact has no release.
        let last: Vec<&str> = table[4].split_whitespace().collect();
        assert_eq!(
            last,
            [
                "3", "1.6000", "50.00", "-", "-", "-", "-", "600.0", "360.0", "-"
            ]
        );
        // Right-aligned: every row of the table ends in the same column.
        let ends: Vec<usize> = table.iter().map(|l| l.chars().count()).collect();
        assert!(ends.iter().all(|&e| e == ends[0]), "{ends:?}\n{text}");
    }

    #[test]
    fn never_closes_shows_the_shortfall_and_no_table() {
        let text = render(&fixtures::never_closes());
        assert!(
            text.contains("never_closes (the contacts never touch)"),
            "{text}"
        );
        assert!(text.contains("first impact  -\n"), "{text}");
        assert!(text.contains("bounce time   -\n"), "{text}");
        assert!(text.contains("shortfall     25.00 µm\n"), "{text}");
        assert!(!text.contains("\n\n"), "{text}");
    }

    #[test]
    fn significant_digits() {
        assert_eq!(sig(Some(0.001234567), ""), "0.001235");
        assert_eq!(sig(Some(-98765.4), ""), "-98765");
        assert_eq!(sig(Some(0.0), " µm"), "0 µm");
        assert_eq!(sig(None, ""), "-");
    }
}
