//! The bounce result for a person at a terminal: a summary, then the
//! impacts as an aligned table, in engineering units (ms, µs, mm/s, mN,
//! µm) so that a typical relay reads without exponents.
//!
//! Times keep four decimals of a millisecond (0.1 µs) so that impacts a
//! few microseconds apart stay distinguishable; other quantities keep four
//! significant digits.

use std::fmt::Write;

use super::units::engineering;
use crate::analysis::ProbeAnalysis;
use crate::arc::ArcReport;
use crate::chatter::{Chatter, ContactState, Impact, Outcome};
use crate::check::{Bound, Verdict, quantity};
use crate::coil::{Closing, Operation};
use crate::pipeline::{ProbeResult, RunResult};

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
            format!("{} ({})", chatter.outcome, explain(chatter)),
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
    out.push_str(&align(&rows, 0));
    out
}

/// The pole face in one line: how often the armature hit it, and when
/// first.
fn pole_face_line(impacts: &[crate::chatter::Impact]) -> String {
    match impacts.first() {
        None => "the armature never reached the pole face".to_owned(),
        Some(first) => format!(
            "{} pole-face impact{}, the first at {} ({})",
            impacts.len(),
            if impacts.len() == 1 { "" } else { "s" },
            ms(Some(first.impact_time)),
            engineering(first.impact_velocity, "m/s"),
        ),
    }
}

/// The armature's impacts on the pole face, as a table under the
/// contact's (a relay with a pole face).
pub fn pole_face(impacts: &[crate::chatter::Impact]) -> String {
    let mut out = String::from("\npole face (the armature)\n");
    if impacts.is_empty() {
        out.push_str("  not reached\n");
        return out;
    }
    let mut rows = vec![
        ["#", "impact", "v impact", "release", "v release"].map(String::from),
        ["", "ms", "mm/s", "ms", "mm/s"].map(String::from),
    ];
    for (n, i) in impacts.iter().enumerate() {
        rows.push([
            (n + 1).to_string(),
            fixed(Some(i.impact_time * 1e3), 4),
            sig(Some(i.impact_velocity * 1e3), ""),
            fixed(i.release_time.map(|t| t * 1e3), 4),
            sig(i.release_velocity.map(|v| v * 1e3), ""),
        ]);
    }
    out.push_str(&align(&rows, 0));
    out
}

/// The `run` result for a person: the relay in one line, the circuit run,
/// a table of the probes (each followed by the ideal contact's row), and a
/// sentence per probe saying what the bounce added. Current probes get a
/// table of their closures.
pub fn render_run(run: &RunResult) -> String {
    render_run_with_life(run, None)
}

/// [`render_run`] with the electrical life `life` estimated at the run's
/// circuit.
pub fn render_run_with_life(run: &RunResult, life: Option<&crate::life::LifeReport>) -> String {
    let mut out = String::new();
    for (label, value) in run_lines(run) {
        let _ = writeln!(out, "{label:<8} {value}");
    }

    out.push('\n');
    if run.probes.is_empty() {
        let _ = writeln!(
            out,
            "probes   none: nothing measured; add a [[probe]] to measure a signal, or keep \
             every saved vector with --out DIR (waveforms.csv, waveforms.raw)"
        );
    }
    let mut rows = vec![PROBE_HEADER.map(String::from)];
    for p in &run.probes {
        rows.push(probe_row(&p.analysis.signal, &p.analysis));
        if let Some(ideal) = &p.ideal {
            rows.push(probe_row("  ideal contact", ideal));
        }
    }
    if !run.probes.is_empty() {
        out.push_str(&align(&rows, 1));
    }

    for p in &run.probes {
        out.push('\n');
        probe_paragraph(&mut out, p);
    }
    if !run.makes.is_empty() {
        out.push('\n');
        out.push_str(&render_makes(&run.makes));
    }
    if let Some(report) = &run.arcs {
        out.push('\n');
        out.push_str(&render_arcs(report));
    }
    if let Some(life) = life {
        out.push_str("\nelectrical life\n");
        out.push_str(&crate::life::render(life));
    }
    // Warnings are not part of the table: the CLI prints them on stderr.
    out
}

/// The head of the run table, as (label, text): the relay, its pole face,
/// the contact, the circuit, the coil's coupling and each operation.
fn run_lines(run: &RunResult) -> Vec<(&'static str, String)> {
    let mut lines = vec![("relay", relay_line(run))];
    if let Some(impacts) = &run.pole_face {
        lines.push(("pole", pole_face_line(impacts)));
    }
    lines.extend([
        ("contact", contact_line(run)),
        ("circuit", circuit_line(run)),
    ]);
    if let Some(passes) = &run.coupling {
        let last = passes.last().map_or(f64::NAN, |p| p.change);
        let text = match passes.as_slice() {
            [one] if one.scheme == crate::pipeline::Coupling::LockStep => format!(
                "coupled to the circuit in lock-step, one ngspice run; its events and the \
                 mechanics under its flux differ by {}",
                engineering(last, "s")
            ),
            _ => format!(
                "coupled to the circuit in {} passes, last change {}",
                passes.len(),
                engineering(last, "s")
            ),
        };
        lines.push(("coil", text));
    }
    for (k, op) in run.operations.iter().enumerate() {
        lines.push(("", operation_line(k + 1, op)));
    }
    lines.push(("energy", energy_line(&run.energy)));
    lines
}

/// The energy ledger in one line: what the sources delivered and where it
/// went.
fn energy_line(e: &crate::pipeline::ledger::EnergyLedger) -> String {
    let mut text = format!("{} delivered", engineering(e.delivered, "J"));
    if e.stored_start != 0.0 || e.stored_end != 0.0 {
        text.push_str(&format!(
            ", stored {} at the start and {} at the end",
            engineering(e.stored_start, "J"),
            engineering(e.stored_end, "J")
        ));
    }
    if let Some(r) = e.resistors {
        text.push_str(&format!(", {} in resistors", engineering(r, "J")));
    }
    text.push_str(&format!(
        ", {} in arcs, {} in breakdowns",
        engineering(e.arcs, "J"),
        engineering(e.breakdowns, "J")
    ));
    if let Some(rest) = e.elsewhere {
        text.push_str(&format!(", {} elsewhere", engineering(rest, "J")));
    }
    if !e.complete() {
        text.push_str(&format!(
            " (not balanced: {} not accounted for)",
            e.unaccounted.join(", ")
        ));
    }
    text
}

/// The relay in one line: its bounces and outcome, and the first
/// closing's operate, bounce and settle times when it closed for good.
fn relay_line(run: &RunResult) -> String {
    let c = &run.chatter;
    let closing = Closing::first(c, &run.operations);
    // A coil-driven relay: its first operation's closing, which ends when
    // the coil goes off whatever the run does after.
    if let Some(op) = run.operations.first().filter(|op| op.coil_off.is_some()) {
        if let (Some(operate), Some(settle)) = (op.operate_time, op.settle_time) {
            return format!(
                "{} bounce{}, closed for good until the coil went off at {}; operate {}, bounce \
                 time {}, closed for good {}{}",
                op.stroke.bounces,
                if op.stroke.bounces == 1 { "" } else { "s" },
                ms(op.coil_off),
                ms(Some(operate)),
                ms(Some(settle - operate)),
                ms(Some(settle)),
                from_coil_on(&closing),
            );
        }
    }
    match (closing.operate_time, closing.settle_time) {
        (Some(operate), Some(settle)) => format!(
            "{} bounce{}, {} ({}); operate {}, bounce time {}, closed for good {}{}",
            c.bounce_count,
            if c.bounce_count == 1 { "" } else { "s" },
            c.outcome,
            explain(c),
            ms(Some(operate)),
            ms(Some(settle - operate)),
            ms(Some(settle)),
            from_coil_on(&closing),
        ),
        _ => format!("{} ({}), {} bounces", c.outcome, explain(c), c.bounce_count),
    }
}

/// The contact element in one line: its kind, points, edges, and what the
/// waveform merged or widened.
fn contact_line(run: &RunResult) -> String {
    let w = &run.waveform;
    let mut contact = format!(
        "{} element, {} points, {} makes, {} breaks",
        run.include.element,
        run.include.points,
        w.make_edges(),
        w.break_edges()
    );
    if w.merged_openings() > 0 {
        let _ = write!(contact, ", {} openings merged", w.merged_openings());
    }
    if w.widened_closures() > 0 {
        let _ = write!(contact, ", {} touches widened", w.widened_closures());
    }
    contact
}

/// The circuit run in one line: the netlist, the ngspice version, the
/// points and the wall-clock times (the ideal contact's too).
fn circuit_line(run: &RunResult) -> String {
    let sim = &run.simulation;
    let mut circuit = format!(
        "{}: ngspice {}, {} points in {:.3} s",
        run.netlist.display(),
        sim.version.as_deref().unwrap_or("(version unknown)"),
        sim.plot.points(),
        sim.elapsed.as_secs_f64()
    );
    if let Some(ideal) = &run.ideal {
        let _ = write!(
            circuit,
            "; ideal contact {:.3} s",
            ideal.elapsed.as_secs_f64()
        );
    }
    circuit
}

/// One probe's sentence: what the bounce did to it against the ideal
/// contact (or its edges and range alone), then for a current probe its
/// pulses, charge and a table of its closures.
fn probe_paragraph(out: &mut String, p: &ProbeResult) {
    let a = &p.analysis;
    let unit = a.kind.unit();
    let _ = write!(out, "{}: ", a.signal);
    match &p.comparison {
        Some(cmp) => {
            let added = match cmp.extra_edges {
                0 => "the bounce adds no edge".to_owned(),
                1 => "the bounce adds 1 edge".to_owned(),
                n if n > 0 => format!("the bounce adds {n} edges"),
                n => format!("the bounce removes {} edges", -n),
            };
            out.push_str(&added);
            if let Some(delay) = cmp.settle_delay {
                if delay != 0.0 {
                    let _ = write!(
                        out,
                        "; the last edge comes {} {} the ideal contact's",
                        engineering(delay.abs(), "s"),
                        if delay > 0.0 { "after" } else { "before" }
                    );
                }
            }
            if !cmp.same_final_state {
                out.push_str("; it ends at a different level than with an ideal contact");
            }
            let _ = writeln!(
                out,
                "; range {} to {} (ideal: {} to {})",
                engineering(a.min, unit),
                engineering(a.max, unit),
                engineering(a.min - cmp.min_difference, unit),
                engineering(a.max - cmp.max_difference, unit),
            );
        }
        None => {
            let _ = writeln!(
                out,
                "{} edge{}; range {} to {}",
                a.edges,
                if a.edges == 1 { "" } else { "s" },
                engineering(a.min, unit),
                engineering(a.max, unit)
            );
        }
    }
    if let Some(current) = &a.current {
        let pulses = a.pulses.unwrap_or(0);
        let _ = writeln!(
            out,
            "  {pulses} pulse{} (2 edges each; glitches count the pulses after the first), \
             peak {} at {}, charge {} ({} while closed)",
            if pulses == 1 { "" } else { "s" },
            engineering(current.peak, "A"),
            ms(Some(current.peak_time)),
            engineering(current.charge, "C"),
            engineering(current.closed_charge, "C"),
        );
        let mut rows = vec![["closure", "from", "to", "peak", "charge"].map(String::from)];
        for (n, k) in current.per_closure.iter().enumerate() {
            rows.push([
                format!("  {}", n + 1),
                ms(Some(k.start)),
                ms(Some(k.end)),
                engineering(k.peak, "A"),
                engineering(k.charge, "C"),
            ]);
        }
        out.push_str(&align(&rows, 1));
    }
}

/// The makes of a run: one row each, with the spot figures where the
/// force is known.
pub fn render_makes(makes: &[crate::arc::making::Make]) -> String {
    let mut out = String::from(
        "makes (peak contact current of each closure; weld margin U_m/U at that peak):\n",
    );
    let mut rows = vec![
        [
            "make",
            "operation",
            "which",
            "at",
            "peak",
            "force",
            "spot",
            "T max",
            "weld margin",
        ]
        .map(str::to_owned),
    ];
    for (k, m) in makes.iter().enumerate() {
        let or_dash = |v: Option<String>| v.unwrap_or_else(|| "-".to_owned());
        rows.push([
            (k + 1).to_string(),
            (m.operation + 1).to_string(),
            if m.bounce == 0 {
                "first".to_owned()
            } else {
                format!("after bounce {}", m.bounce)
            },
            engineering(m.time, "s"),
            engineering(m.peak_current, "A"),
            or_dash(m.force.map(|f| engineering(f, "N"))),
            or_dash(m.spot_voltage.map(|u| engineering(u, "V"))),
            or_dash(m.t_max.map(|t| format!("{t:.0} K"))),
            or_dash(m.weld_margin.map(|w| format!("{w:.3}"))),
        ]);
    }
    out.push_str(&align(&rows, 1));
    out
}

/// The arcs of a run: the totals line, then one row per arc and per
/// breakdown.
pub fn render_arcs(report: &ArcReport) -> String {
    let mut out = String::new();
    let t = &report.totals;
    let m = &report.model;
    let _ = writeln!(
        out,
        "arcs: {} arc{}, {} in all (most in one operation: {}); {} breakdown{}, {}; \
         contact peak {} (V_min {}, I_min {}, field {}, low-current term {} + {}·gap)",
        t.count,
        if t.count == 1 { "" } else { "s" },
        engineering(t.energy, "J"),
        engineering(t.max_operation_energy, "J"),
        t.breakdowns,
        if t.breakdowns == 1 { "" } else { "s" },
        engineering(t.breakdown_energy, "J"),
        engineering(report.peak_voltage, "V"),
        engineering(m.v_min, "V"),
        engineering(m.i_min, "A"),
        engineering(m.field, "V/m"),
        engineering(m.low_current, "V·A"),
        engineering(m.low_current_gap, "V·A/m"),
    );
    if report.arcs.is_empty() && report.breakdowns.is_empty() {
        return out;
    }
    let mut rows = vec![
        [
            "event", "opening", "start", "duration", "peak", "energy", "ends",
        ]
        .map(String::from),
    ];
    for a in &report.arcs {
        rows.push([
            "  arc".to_owned(),
            a.opening.clone(),
            ms(Some(a.start)),
            engineering(a.duration, "s"),
            engineering(a.peak_current, "A"),
            engineering(a.energy, "J"),
            a.ends.replace('_', " "),
        ]);
    }
    for b in &report.breakdowns {
        rows.push([
            "  breakdown".to_owned(),
            b.opening.clone(),
            ms(Some(b.start)),
            engineering(b.duration, "s"),
            engineering(b.peak_voltage, "V"),
            engineering(b.energy, "J"),
            if b.reignited {
                "arc followed"
            } else {
                "collapsed"
            }
            .to_owned(),
        ]);
    }
    out.push_str(&align(&rows, 2));
    out
}

/// Probe analyses alone (`raw --signal`): the probe table of `run`, and
/// the pulses of current probes.
pub fn render_probes(probes: &[ProbeAnalysis]) -> String {
    let mut rows = vec![PROBE_HEADER.map(String::from)];
    for a in probes {
        rows.push(probe_row(&a.signal, a));
    }
    let mut out = align(&rows, 1);
    for a in probes {
        if let (Some(pulses), Some(current)) = (a.pulses, &a.current) {
            let _ = writeln!(
                out,
                "{}: {pulses} pulse{} (2 edges each; glitches count the pulses after the \
                 first), peak {} at {}, charge {}",
                a.signal,
                if pulses == 1 { "" } else { "s" },
                engineering(current.peak, "A"),
                ms(Some(current.peak_time)),
                engineering(current.charge, "C"),
            );
        }
    }
    out
}

/// A check for a person: the verdict, the relay in one line, then one row
/// per limit with its margin, failures marked.
pub fn render_check(verdict: &Verdict, chatter: &Chatter, operations: &[Operation]) -> String {
    render_check_of("relay", verdict, chatter, operations)
}

/// [`render_check`] with the relay's line labelled `label` (e.g. `worst
/// relay 16 of 32`, for a check over an envelope).
pub fn render_check_of(
    label: &str,
    verdict: &Verdict,
    chatter: &Chatter,
    operations: &[Operation],
) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{}: {} of {} limits failed",
        if verdict.passed { "PASS" } else { "FAIL" },
        verdict.failed,
        verdict.checks.len()
    );
    let closing = Closing::first(chatter, operations);
    let (outcome, bounces) = match operations.first() {
        Some(op) => (op.outcome(chatter.outcome), op.stroke.bounces),
        None => (chatter.outcome, chatter.bounce_count),
    };
    let _ = writeln!(
        out,
        "{label}: {}, {} bounces, operate {}, bounce time {}, closed for good {}{}",
        outcome,
        bounces,
        ms(closing.operate_time),
        ms(closing.bounce_time),
        ms(closing.settle_time),
        from_coil_on(&closing),
    );
    out.push('\n');
    if verdict.checks.is_empty() {
        out.push_str(
            "no limits to hold: add a [limits] section or limits on a [[probe]] to check \
             these figures against\n",
        );
        return out;
    }
    let mut rows =
        vec![["", "limit", "quantity", "actual", "", "limit", "margin"].map(String::from)];
    for c in &verdict.checks {
        let margin = match (c.margin, &c.note) {
            (Some(m), _) => {
                let relative = if c.limit != 0.0 {
                    format!(" ({:+.0} %)", 100.0 * m / c.limit.abs())
                } else {
                    String::new()
                };
                format!("{}{relative}", signed(m, c.unit))
            }
            (None, Some(note)) => note.clone(),
            (None, None) => ABSENT.to_owned(),
        };
        rows.push([
            if c.passed { "pass" } else { "FAIL" }.to_owned(),
            c.key.clone(),
            c.quantity.clone(),
            c.actual
                .map_or_else(|| ABSENT.to_owned(), |a| quantity(a, c.unit)),
            match c.bound {
                Bound::Max => "<=".to_owned(),
                Bound::Min => ">=".to_owned(),
            },
            quantity(c.limit, c.unit),
            margin,
        ]);
    }
    out.push_str(&align(&rows, 3));
    out
}

/// A margin with its sign.
fn signed(value: f64, unit: &str) -> String {
    let text = quantity(value.abs(), unit);
    if value < 0.0 {
        format!("-{text}")
    } else {
        format!("+{text}")
    }
}

/// The columns of [`probe_row`].
const PROBE_HEADER: [&str; 10] = [
    "probe",
    "edges",
    "glitches",
    "first edge",
    "last edge",
    "shortest pulse",
    "lockout",
    "stable for",
    "min",
    "max",
];

fn probe_row(label: &str, a: &ProbeAnalysis) -> [String; 10] {
    let unit = a.kind.unit();
    let time = |t: Option<f64>| t.map_or_else(|| ABSENT.to_owned(), |t| engineering(t, "s"));
    [
        label.to_owned(),
        a.edges.to_string(),
        a.glitches.to_string(),
        ms(a.first_edge),
        ms(a.last_edge),
        time(a.shortest_pulse),
        time(a.debounce.map(|d| d.lockout)),
        time(a.debounce.map(|d| d.stable_for)),
        with_and_without(a.min, a.min_without_ringing, unit),
        with_and_without(a.max, a.max_without_ringing, unit),
    ]
}

/// An extreme of every sample, and beside it, when it differs, the same
/// extreme without the integrator's ringing: `-157 mV (16 µV w/o ringing)`.
fn with_and_without(all: f64, without: Option<f64>, unit: &str) -> String {
    match without {
        Some(w) => format!(
            "{} ({} w/o ringing)",
            engineering(all, unit),
            engineering(w, unit)
        ),
        None => engineering(all, unit),
    }
}

/// What the ending means, in words; at the end of time, what is true
/// there: closed since when, or still bouncing.
fn explain(chatter: &Chatter) -> String {
    match chatter.outcome {
        Outcome::Stuck => "closed for good".to_owned(),
        Outcome::Resolved => "closed for good; later bounces are below resolution".to_owned(),
        Outcome::NeverCloses => "the contacts never touch".to_owned(),
        Outcome::EndsOpen => "touched, but the contact ends open".to_owned(),
        Outcome::EndOfTime => match chatter.intervals.last() {
            Some(last) if last.state == ContactState::Closed => format!(
                "closed since {}, not yet proven to stay closed at {}",
                ms(Some(last.start)),
                ms(Some(chatter.t_end))
            ),
            _ => "still bouncing at the end of the simulation".to_owned(),
        },
        Outcome::EventLimit => {
            "still bouncing after 100 000 impacts: the model has no losses".to_owned()
        }
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
/// Right-aligned columns (numbers), except the first `left` columns
/// (names read better left-aligned).
fn align<const N: usize>(rows: &[[String; N]], left: usize) -> String {
    let width = |c: usize| rows.iter().map(|r| r[c].chars().count()).max().unwrap_or(0);
    let widths: Vec<usize> = (0..N).map(width).collect();
    let mut out = String::new();
    for row in rows {
        let cells: Vec<String> = row
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(i, (cell, &w))| {
                if i < left {
                    format!("{cell:<w$}")
                } else {
                    format!("{cell:>w$}")
                }
            })
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
    // Far below the column's unit (a force released at zero, less its
    // rounding): four significant digits with an exponent, never a row of
    // zeros.
    if magnitude < -3 {
        return format!("{v:.3e}{unit}");
    }
    let decimals = (DIGITS - 1 - magnitude).clamp(0, 12) as usize;
    format!("{v:.decimals$}{unit}")
}

/// Where the times of a closing count from, when not t = 0.
fn from_coil_on(closing: &Closing) -> String {
    if closing.origin == 0.0 {
        String::new()
    } else {
        format!(" (from coil on at {})", ms(Some(closing.origin)))
    }
}

/// One operation of a coil-driven relay: what the coil did and how the
/// contacts answered, times from the coil's switching.
fn operation_line(number: usize, op: &Operation) -> String {
    let time = |t: Option<f64>| t.map_or_else(|| "-".to_owned(), |t| engineering(t, "s"));
    let s = &op.stroke;
    if let Some(after) = op.recloses_after {
        return format!(
            "operation {number}: re-closure with the coil off, {} after the release: makes at \
             {}, {} bounces in {}",
            time(Some(after)),
            time(s.first_make),
            s.bounces,
            time(op.bounce_time)
        );
    }
    let mut line = format!("operation {number}: coil on {}", time(op.coil_on));
    if s.first_make.is_some() {
        let _ = write!(
            line,
            ", operate +{}, {} bounces in {}, closed for good +{}",
            time(op.operate_time),
            s.bounces,
            time(op.bounce_time),
            time(op.settle_time)
        );
    } else {
        line.push_str(", never makes");
    }
    if let Some(off) = op.coil_off {
        let _ = write!(
            line,
            "; coil off {}, release +{}",
            time(Some(off)),
            time(op.release_time)
        );
        if op.nc_make_time.is_some() {
            let _ = write!(
                line,
                ", NC make +{} ({} bounces in {})",
                time(op.nc_make_time),
                s.back_bounces,
                time(op.nc_bounce_time)
            );
        } else if op.release_time.is_some() {
            line.push_str(", not back on its rest stop before it closes again or the run ends");
        }
    }
    line
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
