//! An envelope for people (a table of bands) and for scripts (the
//! `envelope` object added to the run or check JSON).

use std::fmt::Write;

use super::report::EnvelopeReport;
use crate::report::units::engineering;

/// The unit of an envelope quantity, by its name.
fn unit_of(name: &str) -> &'static str {
    let last = name.rsplit('.').next().unwrap_or(name);
    match last {
        "operate_time" | "bounce_time" | "settle_time" | "lockout" | "stable_for" => "s",
        "arc_energy" => "J",
        "peak" if name.starts_with("i(") => "A",
        "peak" => "V",
        _ => "",
    }
}

fn value(v: f64, unit: &str) -> String {
    if unit.is_empty() {
        format!("{v}")
    } else {
        engineering(v, unit)
    }
}

/// The envelope as a table: what was drawn, kept and rejected, each
/// quantity's band, and the worst relay's values.
pub fn band_table(report: &EnvelopeReport) -> String {
    let mut out = String::new();
    let _ = write!(
        out,
        "envelope: {} of {} relays kept",
        report.kept, report.samples
    );
    if report.rejected_relays > 0 {
        let reasons: Vec<String> = report
            .rejected
            .iter()
            .map(|(k, n)| format!("{k} {n}"))
            .collect();
        let _ = write!(
            out,
            "; {} rejected by the datasheet (missed: {}{})",
            report.rejected_relays,
            reasons.join(", "),
            if reasons.len() > 1 {
                "; a relay that misses several figures counts under each"
            } else {
                ""
            }
        );
    }
    let _ = writeln!(out);
    if report.failed > 0 {
        let _ = writeln!(
            out,
            "NOT EVALUATED: {} relay{} could not be simulated (a check over this envelope fails):",
            report.failed,
            if report.failed == 1 { "" } else { "s" }
        );
        for f in report.failures.iter().take(5) {
            let _ = writeln!(out, "  relay {}: {}", f.index, f.reason);
        }
        if report.failures.len() > 5 {
            let _ = writeln!(
                out,
                "  … and {} more (see the JSON's envelope.failures)",
                report.failures.len() - 5
            );
        }
    }
    if let Some(source) = &report.source {
        let _ = writeln!(out, "ranges: {source}");
    }
    let _ = writeln!(
        out,
        "\n{:<24} {:>10} {:>10} {:>10} {:>10}",
        "quantity", "min", "median", "p95", "max"
    );
    for (name, b) in &report.quantities {
        let unit = unit_of(name);
        let _ = writeln!(
            out,
            "{:<24} {:>10} {:>10} {:>10} {:>10}",
            name,
            value(b.min, unit),
            value(b.median, unit),
            value(b.p95, unit),
            value(b.max, unit)
        );
    }
    if let Some(w) = &report.worst {
        let _ = write!(out, "\nworst relay: {}", w.index);
        if let Some(limit) = &w.limit {
            let _ = write!(out, " (least room on {limit})");
        }
        let _ = writeln!(out);
        for (key, v) in &w.values {
            let _ = writeln!(
                out,
                "  {key:<22} {}",
                value(
                    *v,
                    report
                        .units
                        .get(key)
                        .copied()
                        .unwrap_or_else(|| crate::scenario::unit_of(key))
                )
            );
        }
    }
    out
}

/// `json` (a run or check report) with the envelope added under
/// `"envelope"`.
pub fn json_with_envelope(json: &str, report: &EnvelopeReport) -> String {
    let mut value: serde_json::Value =
        serde_json::from_str(json).expect("the reports are valid JSON");
    if let serde_json::Value::Object(map) = &mut value {
        map.insert(
            "envelope".to_owned(),
            serde_json::to_value(report).expect("an envelope serializes"),
        );
    }
    let mut text = serde_json::to_string_pretty(&value).expect("JSON serializes");
    text.push('\n');
    text
}
