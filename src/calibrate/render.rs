//! A fit's report as a table, as JSON, and as an overlay plot of the
//! measured and the fitted contact state.

use std::fmt::Write;

use super::fit::{EventKind, FitReport};
use crate::chatter::{ContactState, Interval};
use crate::report::units::engineering;
use crate::scenario::unit_of;

/// `fit --format json`: the report's fields (see the calibration guide).
pub fn json(report: &FitReport) -> String {
    let mut text = serde_json::to_string_pretty(report).expect("a fit report serializes");
    text.push('\n');
    text
}

/// `v` in engineering units (`63 Ω`, `10 ms`), or `-` when absent; a
/// key without a unit keeps four significant digits.
fn number(v: Option<f64>, unit: &str) -> String {
    match v {
        None => "-".to_owned(),
        Some(v) if unit.is_empty() => format!("{v:.4}"),
        Some(v) => engineering(v, unit),
    }
}

/// `fit --format table`: parameters, then events, then datasheet figures,
/// then the notes.
pub fn table(report: &FitReport) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<24} {:>13} {:>13} {:>13}  determined",
        "parameter", "prior", "value", "sigma"
    );
    for p in &report.parameters {
        let _ = writeln!(
            out,
            "{:<24} {:>13} {:>13} {:>13}  {}",
            p.key,
            number(Some(p.prior), unit_of(&p.key)),
            number(Some(p.value), unit_of(&p.key)),
            number(p.sigma, unit_of(&p.key)),
            match p.determined {
                crate::scenario::Determined::No => "no",
                crate::scenario::Determined::Yes => "yes",
                crate::scenario::Determined::Exactly => "exactly",
            }
        );
    }
    if !report.events.is_empty() {
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "{:<6} {:>13} {:>13} {:>13}",
            "event", "measured", "model", "residual"
        );
        for e in &report.events {
            let _ = writeln!(
                out,
                "{:<6} {:>13} {:>13} {:>13}{}",
                e.kind.as_str(),
                number(e.measured, "s"),
                number(e.model, "s"),
                number(e.residual, "s"),
                if e.dropped { "  (set aside)" } else { "" }
            );
        }
    }
    if let Some(b) = report.bounce_count {
        let _ = writeln!(out, "bounces: measured {}, model {}", b.measured, b.model);
    }
    if let Some(t) = report.time_offset {
        let _ = writeln!(
            out,
            "time offset: {} (model time of the record's zero)",
            engineering(t, "s")
        );
    }
    if !report.datasheet.is_empty() {
        let _ = writeln!(out);
        let _ = writeln!(
            out,
            "{:<18} {:>22} {:>10} {:>10}",
            "figure", "datasheet", "model", "misfit"
        );
        for f in &report.datasheet {
            let unit = super::printed::unit_of(f.figure);
            let _ = writeln!(
                out,
                "{:<18} {:>22} {:>10} {:>10}{}",
                f.figure,
                super::printed::printed_text(&f.printed, unit),
                number(f.model, unit),
                match (f.role, f.model) {
                    (_, None) => "-".to_owned(),
                    ("bound", Some(m)) if f.printed.holds(m) => "met".to_owned(),
                    (_, Some(m)) => format!("{:+.3}%", f.printed.misfit(m) * 100.0),
                },
                if f.binds { "  (binds)" } else { "" }
            );
        }
    }
    if let Some(b) = &report.breaking {
        let _ = writeln!(out);
        let _ = write!(out, "{}", breaking_rows(&b.rows));
        let _ = writeln!(
            out,
            "arc fitted at the full gap {}: field {}, low-current term C {} + D {}·gap (rms of ln(model/printed) {:.4})",
            engineering(b.gap, "m"),
            engineering(b.field, "V/m"),
            engineering(b.low_current, "V·A"),
            engineering(b.low_current_gap, "V·A/m"),
            b.rms_log_error
        );
    }
    // A record's misfit is a time; a datasheet's alone is relative.
    let rms = if report.events.is_empty() {
        format!("{:.4} %", report.rms_residual * 100.0)
    } else {
        engineering(report.rms_residual, "s")
    };
    let _ = writeln!(
        out,
        "\nrms residual {rms}; {} evaluations in {}",
        report.evaluations,
        engineering(report.elapsed, "s")
    );
    for n in &report.notes {
        let _ = writeln!(out, "note: {n}");
    }
    out
}

/// An SVG of two contact-state traces on the record's time axis: the
/// measured one on top, the fitted model's below (shifted by the time
/// offset), with the edge thresholds of a two-level trace (30 % / 70 %).
pub fn overlay_svg(measured: &[Interval], report: &FitReport) -> String {
    overlay_svg_with(measured, report, None)
}

/// The analog trace a record was read from, for [`overlay_svg_with`]:
/// times on the record's axis, its levels and thresholds in its unit.
#[derive(Debug, Clone, Copy)]
pub struct TraceOverlay<'a> {
    /// s, the samples' times on the record's axis.
    pub time: &'a [f64],
    /// The samples (V, or whatever the capture measured), one per time.
    pub value: &'a [f64],
    /// The trace's level while the contact is open.
    pub open: f64,
    /// The trace's level while the contact is closed.
    pub closed: f64,
    /// The lower edge threshold, in the trace's unit.
    pub low: f64,
    /// The upper edge threshold, in the trace's unit.
    pub high: f64,
}

/// [`overlay_svg`], with the measured lane drawn over the analog trace
/// (grey, scaled so that its open level meets the open state and its
/// closed level the closed one) and the trace's own thresholds.
pub fn overlay_svg_with(
    measured: &[Interval],
    report: &FitReport,
    trace: Option<TraceOverlay<'_>>,
) -> String {
    let model: Vec<(EventKind, f64)> = report
        .events
        .iter()
        .filter_map(|e| e.model.map(|t| (e.kind, t)))
        .collect();
    let start = measured.first().map_or(0.0, |i| i.start);
    let end = measured
        .last()
        .map_or(1.0, |i| i.end)
        .max(model.last().map_or(start, |m| m.1));
    let span = (end - start).max(1e-12);
    let (w, h, left, right) = (900.0, 300.0, 60.0, 20.0);
    let x = |t: f64| left + (t - start) / span * (w - left - right);
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(svg, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    // The analog trace under the measured lane (top 30): at most two
    // points (its extremes) per pixel column.
    let fractions = match trace {
        Some(tr) if tr.open != tr.closed => {
            let frac = |v: f64| (v - tr.open) / (tr.closed - tr.open);
            let mut points = String::new();
            let columns = (w - left - right) as usize;
            let mut column = usize::MAX;
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            let flush = |points: &mut String, c: usize, lo: f64, hi: f64| {
                if c < columns && lo.is_finite() {
                    let xx = left + c as f64;
                    let _ = write!(
                        points,
                        "{xx:.1},{:.1} {xx:.1},{:.1} ",
                        30.0 + 80.0 * frac(lo),
                        30.0 + 80.0 * frac(hi)
                    );
                }
            };
            for (&t, &v) in tr.time.iter().zip(tr.value) {
                let c = ((x(t) - left).max(0.0)) as usize;
                if c != column {
                    flush(&mut points, column, lo, hi);
                    column = c;
                    (lo, hi) = (v, v);
                } else {
                    (lo, hi) = (lo.min(v), hi.max(v));
                }
            }
            flush(&mut points, column, lo, hi);
            let _ = writeln!(
                svg,
                r##"<polyline points="{points}" fill="none" stroke="#999" stroke-width="1"/>"##
            );
            let (a, b) = (frac(tr.low), frac(tr.high));
            [a.min(b), a.max(b)]
        }
        _ => [0.3, 0.7],
    };
    // Lane `top` .. `top + 80`: open high, closed low.
    let lane = |svg: &mut String, top: f64, label: &str, steps: &[(f64, bool)], colour: &str| {
        let y = |closed: bool| if closed { top + 80.0 } else { top };
        for frac in fractions {
            let yy = top + 80.0 * frac;
            let _ = writeln!(
                svg,
                r##"<line x1="{left}" x2="{}" y1="{yy}" y2="{yy}" stroke="#bbb" stroke-dasharray="4 3"/>"##,
                w - right
            );
        }
        let mut points = String::new();
        let mut state = false;
        let _ = write!(points, "{:.2},{:.2} ", x(start), y(state));
        for &(t, closed) in steps {
            let _ = write!(
                points,
                "{:.2},{:.2} {:.2},{:.2} ",
                x(t),
                y(state),
                x(t),
                y(closed)
            );
            state = closed;
        }
        let _ = write!(points, "{:.2},{:.2}", x(end), y(state));
        let _ = writeln!(
            svg,
            r#"<polyline points="{points}" fill="none" stroke="{colour}" stroke-width="1.5"/>"#
        );
        let _ = writeln!(svg, r#"<text x="4" y="{}">{label}</text>"#, top + 45.0);
    };
    let measured_steps: Vec<(f64, bool)> = measured
        .iter()
        .map(|i| (i.start, i.state == ContactState::Closed))
        .collect();
    let model_steps: Vec<(f64, bool)> = model
        .iter()
        .map(|&(k, t)| (t, k == EventKind::Make))
        .collect();
    lane(&mut svg, 30.0, "measured", &measured_steps, "#1f77b4");
    lane(&mut svg, 170.0, "fitted", &model_steps, "#d62728");
    // The axis ends in engineering units ("0 s", "12.5 ms"), as the other
    // plots write them.
    let (from, to) = (
        crate::report::units::engineering(start, "s"),
        crate::report::units::engineering(end, "s"),
    );
    let _ = writeln!(
        svg,
        r#"<text x="{left}" y="{}">{from}</text><text x="{}" y="{}" text-anchor="end">{to}</text>"#,
        h - 8.0,
        w - right,
        h - 8.0
    );
    svg.push_str("</svg>\n");
    svg
}

/// DC breaking figures beside the model's breakable current, one line
/// each: `dc_breaking  30 V: 8 A printed, model 7.93 A (0.991)`.
pub fn breaking_rows(rows: &[crate::arc::breaking::BreakingRow]) -> String {
    use std::fmt::Write;
    let mut out = String::new();
    for r in rows {
        let model = match r.model {
            Some(m) => format!(
                "model {} ({:.3} of printed)",
                engineering(m, "A"),
                m / r.printed
            ),
            None => "model: breaks any current (the supply is below V_min + E·gap)".to_owned(),
        };
        let _ = writeln!(
            out,
            "  dc_breaking       {} at {}  ({model})",
            engineering(r.printed, "A"),
            engineering(r.voltage, "V"),
        );
    }
    out
}
