//! A picture of one run: the contact and each probed signal over time, as
//! a hand-written SVG document.
//!
//! Stacked panels share the time axis: on top the contact (open/closed,
//! or its resistance on a log axis), then one panel per probe with its
//! Schmitt thresholds dashed and its edges marked (▲ rising at `high`,
//! ▼ falling at `low`). Ticks are in engineering units (µs, ms; mV, V;
//! mA, A), one prefix per axis.
//!
//! # Decimation
//! A transient can hold 10⁵–10⁶ points, far more than the plot has pixel
//! columns. Each column keeps the first, lowest, highest and last sample
//! that fall into it, in time order, so the drawn line has the envelope
//! of the data: a spike one sample wide still reaches its peak. The
//! signal's values at the window's ends are interpolated, so the line
//! starts and ends on the frame.
//!
//! # Determinism
//! Coordinates are written with one decimal (a tenth of a pixel), labels
//! with the decimals their tick step needs; the same input gives the same
//! bytes. Non-finite samples are skipped, so no `NaN` reaches the file.

use std::fmt::Write as _;

use thiserror::Error;

use super::units::{engineering, prefix, significant};
use crate::analysis::{Direction, Edge, ProbeAnalysis};
use crate::chatter::{ContactState, Interval};

/// Why a plot could not be drawn.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SvgError {
    /// The time window is not finite with start < end.
    #[error("plot window {start:e} s to {end:e} s: it needs finite start < end")]
    Window {
        /// s
        start: f64,
        /// s
        end: f64,
    },
    /// A series has a different number of values than of times.
    #[error("`{name}` has {values} values for {time} times; give one value per time")]
    Length {
        /// The series' name (a probe's signal, or `contact resistance`).
        name: String,
        /// The number of times.
        time: usize,
        /// The number of values.
        values: usize,
    },
    /// A series' time decreases.
    #[error("`{name}`: time goes back at sample {index}; pass the samples in time order")]
    Unsorted {
        /// The series' name.
        name: String,
        /// The 0-based index of the first sample earlier than the one
        /// before it.
        index: usize,
    },
    /// The plot has neither a contact trace nor a probe.
    #[error("nothing to plot: give a contact trace or at least one probe")]
    Empty,
}

/// Samples of one signal: `time` in s, non-decreasing, and `value`, one
/// per time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Series<'a> {
    /// s
    pub time: &'a [f64],
    /// The values, in the signal's unit.
    pub value: &'a [f64],
}

/// What the top panel shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactTrace<'a> {
    /// The chatter's intervals (e.g. `chatter.intervals`), as a logic
    /// trace: closed up, open down.
    States(&'a [Interval]),
    /// Contact resistance in Ω (e.g. from the contact waveform), on a
    /// log axis; values ≤ 0 are skipped.
    Resistance(Series<'a>),
}

/// One probed signal's panel.
#[derive(Debug, Clone, PartialEq)]
pub struct ProbePanel<'a> {
    /// The signal's name, e.g. `v(in)`.
    pub name: String,
    /// SI unit symbol of the values (`V`, `A`), or empty.
    pub unit: String,
    /// The samples.
    pub series: Series<'a>,
    /// The lower Schmitt threshold, in `unit`.
    pub low: f64,
    /// The upper Schmitt threshold, in `unit`.
    pub high: f64,
    /// Edges to mark, in time order.
    pub edges: Vec<Edge>,
}

impl<'a> ProbePanel<'a> {
    /// The panel for an analysed probe and its samples.
    pub fn from_analysis(analysis: &ProbeAnalysis, series: Series<'a>) -> ProbePanel<'a> {
        ProbePanel {
            name: analysis.signal.clone(),
            unit: analysis.kind.unit().to_owned(),
            series,
            low: analysis.low,
            high: analysis.high,
            edges: analysis.transitions.clone(),
        }
    }
}

/// Everything one picture shows.
#[derive(Debug, Clone, PartialEq)]
pub struct SvgPlot<'a> {
    /// The line over the picture.
    pub title: String,
    /// s, the time axis from `.0` to `.1` (see [`suggested_window`]).
    pub window: (f64, f64),
    /// The top panel; `None` leaves it out.
    pub contact: Option<ContactTrace<'a>>,
    /// One panel per probe, top to bottom.
    pub probes: Vec<ProbePanel<'a>>,
    /// Arcs and breakdowns to mark on the contact panel: (start, end, s;
    /// `true` for an arc, `false` for a breakdown).
    pub arcs: Vec<(f64, f64, bool)>,
    /// s, the armature's impacts on the pole face (a relay with a contact
    /// blade), marked above the contact panel.
    pub pole_face: Vec<f64>,
}

/// A small downward triangle over the contact panel (whose top is `top`)
/// at each pole-face impact in the window `(t0, t1)`.
fn pole_face_marks(
    out: &mut String,
    impacts: &[f64],
    (t0, t1): (f64, f64),
    x: &dyn Fn(f64) -> f64,
    top: f64,
) {
    for &t in impacts.iter().filter(|&&t| t >= t0 && t <= t1) {
        let xt = x(t);
        let _ = writeln!(
            out,
            r#"<path d="M{} {}L{} {}L{} {}Z" fill="{EDGE_COLOR}"><title>pole-face impact at {} s</title></path>"#,
            num(xt - 4.0),
            num(top - 7.0),
            num(xt + 4.0),
            num(top - 7.0),
            num(xt),
            num(top - 1.0),
            num(t)
        );
    }
}

/// A time window from 0 to a little after `last_event` (s; e.g. the last
/// edge or the settle time), rounded up to a round number and capped at
/// `t_end`; the whole record without an event.
pub fn suggested_window(last_event: Option<f64>, t_end: f64) -> (f64, f64) {
    match last_event {
        Some(t) if t > 0.0 && t.is_finite() => (0.0, round_up(1.2 * t).min(t_end)),
        _ => (0.0, t_end),
    }
}

// Layout, in px.
const WIDTH: f64 = 960.0;
const LEFT: f64 = 90.0;
const RIGHT: f64 = 30.0;
const TOP: f64 = 56.0;
const GAP: f64 = 30.0;
const CONTACT_HEIGHT: f64 = 70.0;
const PROBE_HEIGHT: f64 = 170.0;
const BOTTOM: f64 = 50.0;
const PLOT_WIDTH: f64 = WIDTH - LEFT - RIGHT;
/// Pixel columns the data is decimated to.
const COLUMNS: usize = PLOT_WIDTH as usize;

const SIGNAL_COLOR: &str = "#1f5fa8";
const CONTACT_COLOR: &str = "#2a8a3a";
const THRESHOLD_COLOR: &str = "#c0392b";
const EDGE_COLOR: &str = "#e67e22";
const GRID_COLOR: &str = "#e3e3e3";
const ARC_COLOR: &str = "#d4145a";
const BREAKDOWN_COLOR: &str = "#8e44ad";
const AXIS_COLOR: &str = "#333333";

/// The SVG document for `plot`.
pub fn render(plot: &SvgPlot) -> Result<String, SvgError> {
    let layout = Layout::of(plot)?;
    let mut out = String::new();
    heading(&mut out, &plot.title, layout.height);
    legend(&mut out, plot.probes.is_empty());

    let mut top = TOP;
    let mut clip = 0;
    if let Some(points) = &layout.contact {
        contact_panel(&mut out, plot, &layout, points, top, &mut clip);
        top += CONTACT_HEIGHT + GAP;
    }
    for (p, points) in plot.probes.iter().zip(&layout.probes) {
        probe_panel(&mut out, p, &layout, points, top, &mut clip);
        top += PROBE_HEIGHT + GAP;
    }
    // The shared time axis under the last panel.
    time_axis(&mut out, &layout, top - GAP);
    out.push_str("</svg>\n");
    Ok(out)
}

/// What the panels share: the window, the time axis and the picture's
/// height, with the data checked and decimated to the plot's columns.
struct Layout {
    /// s, the time axis from `.0` to `.1`.
    window: (f64, f64),
    /// The time axis's ticks and labels.
    time: Axis,
    /// px, the whole picture.
    height: f64,
    /// The contact trace's points, when there is a contact panel.
    contact: Option<Vec<(f64, f64)>>,
    /// Each probe's points, in panel order.
    probes: Vec<Vec<(f64, f64)>>,
    /// px, the closed intervals shaded behind the probes.
    bands: Vec<(f64, f64)>,
}

impl Layout {
    /// The layout of `plot`, or why it cannot be drawn.
    fn of(plot: &SvgPlot) -> Result<Layout, SvgError> {
        let (t0, t1) = plot.window;
        if !(t0.is_finite() && t1.is_finite() && t0 < t1) {
            return Err(SvgError::Window { start: t0, end: t1 });
        }
        if plot.contact.is_none() && plot.probes.is_empty() {
            return Err(SvgError::Empty);
        }
        let contact = match plot.contact {
            Some(trace) => Some(contact_points(trace, t0, t1)?),
            None => None,
        };
        let mut probes = Vec::with_capacity(plot.probes.len());
        for p in &plot.probes {
            check(&p.name, p.series)?;
            probes.push(decimate(p.series.time, p.series.value, t0, t1, COLUMNS));
        }

        let panels = usize::from(contact.is_some()) as f64 * (CONTACT_HEIGHT + GAP)
            + plot.probes.len() as f64 * (PROBE_HEIGHT + GAP);
        let height = TOP + panels - GAP + BOTTOM;
        let time = Axis::linear(t0, t1, 8).with_unit("s");
        let bands = match plot.contact {
            Some(ContactTrace::States(intervals)) => closed_bands(intervals, t0, t1),
            _ => Vec::new(),
        };
        Ok(Layout {
            window: (t0, t1),
            time,
            height,
            contact,
            probes,
            bands,
        })
    }

    /// px, the abscissa of time `t` (s).
    fn x(&self, t: f64) -> f64 {
        let (t0, t1) = self.window;
        LEFT + (t - t0) / (t1 - t0) * PLOT_WIDTH
    }

    /// A panel's clip path (numbered on from `clip`, the number returned)
    /// and its vertical grid lines at the time ticks.
    fn frame(&self, out: &mut String, clip: &mut usize, top: f64, height: f64) -> usize {
        *clip += 1;
        let _ = writeln!(
            out,
            r#"<clipPath id="panel{clip}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath>"#,
            num(LEFT),
            num(top),
            num(PLOT_WIDTH),
            num(height)
        );
        for &t in &self.time.ticks {
            let _ = writeln!(
                out,
                r#"<line x1="{x}" y1="{}" x2="{x}" y2="{}" stroke="{GRID_COLOR}"/>"#,
                num(top),
                num(top + height),
                x = num(self.x(t))
            );
        }
        *clip
    }
}

/// The document's opening: the `<svg>` element `height` px high, its
/// title, the white background and the title line over the picture.
fn heading(out: &mut String, title: &str, height: f64) {
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="Helvetica, Arial, sans-serif" font-size="12">"#,
        w = num(WIDTH),
        h = num(height),
    );
    let _ = writeln!(out, "<title>{}</title>", escape(title));
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        out,
        r#"<text x="{}" y="24" font-size="16" font-weight="bold">{}</text>"#,
        num(LEFT),
        escape(title)
    );
}

/// The contact panel at `top`: the trace (`points`) with its arcs and
/// breakdowns behind it and the pole-face impacts over it.
fn contact_panel(
    out: &mut String,
    plot: &SvgPlot,
    layout: &Layout,
    points: &[(f64, f64)],
    top: f64,
    clip: &mut usize,
) {
    let (t0, t1) = layout.window;
    let x = |t: f64| layout.x(t);
    let _ = writeln!(out, "<g>");
    let id = layout.frame(out, clip, top, CONTACT_HEIGHT);
    let (axis, label, values): (Axis, &str, Vec<(f64, f64)>) = match plot.contact {
        Some(ContactTrace::Resistance(_)) => {
            let (lo, hi) = extent(points).unwrap_or((0.0, 1.0));
            (Axis::decades(lo, hi), "contact resistance", points.to_vec())
        }
        _ => (
            Axis::states(),
            match (plot.arcs.is_empty(), plot.pole_face.is_empty()) {
                (true, true) => "contact",
                (true, false) => "contact (▼ pole-face impacts)",
                (false, true) => "contact (arcs shaded, breakdowns low)",
                (false, false) => "contact (arcs shaded, breakdowns low, ▼ pole-face impacts)",
            },
            points.to_vec(),
        ),
    };
    let y = |v: f64| top + CONTACT_HEIGHT * (1.0 - axis.fraction(v));
    y_ticks(out, &axis, top, CONTACT_HEIGHT);
    // Arcs as bands behind the trace (at least 2 px wide, so a
    // microsecond arc in a 10 ms window shows), breakdowns as ticks.
    let _ = writeln!(out, r#"<g clip-path="url(#panel{id})">"#);
    for &(a, b, arc) in plot.arcs.iter().filter(|m| m.1 >= t0 && m.0 <= t1) {
        let (xa, xb) = (x(a.max(t0)), x(b.min(t1)));
        let (color, what, h0, h1) = if arc {
            (ARC_COLOR, "arc", top, CONTACT_HEIGHT)
        } else {
            (
                BREAKDOWN_COLOR,
                "breakdown",
                top + 0.75 * CONTACT_HEIGHT,
                0.25 * CONTACT_HEIGHT,
            )
        };
        let _ = writeln!(
            out,
            r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{color}" fill-opacity="0.35"><title>{what} {} to {} s</title></rect>"#,
            num(xa.min(xb - 2.0)),
            num(h0),
            num((xb - xa).max(2.0)),
            num(h1),
            num(a),
            num(b)
        );
    }
    let _ = writeln!(
        out,
        r#"<polyline fill="none" stroke="{CONTACT_COLOR}" stroke-width="1.5" stroke-linejoin="round" points="{}"/></g>"#,
        polyline(&values, x, y)
    );
    pole_face_marks(out, &plot.pole_face, (t0, t1), &x, top);
    panel_frame(out, top, CONTACT_HEIGHT);
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}" font-weight="bold">{}</text>"#,
        num(LEFT),
        num(top - 8.0),
        label
    );
    let _ = writeln!(out, "</g>");
}

/// Probe `p`'s panel at `top`: the closures shaded, the thresholds
/// dashed, the signal (`points`) and its edges marked.
fn probe_panel(
    out: &mut String,
    p: &ProbePanel,
    layout: &Layout,
    points: &[(f64, f64)],
    top: f64,
    clip: &mut usize,
) {
    let (t0, t1) = layout.window;
    let x = |t: f64| layout.x(t);
    let _ = writeln!(out, "<g>");
    let id = layout.frame(out, clip, top, PROBE_HEIGHT);
    for &(a, b) in &layout.bands {
        let _ = writeln!(
            out,
            r#"<rect x="{}" y="{}" width="{}" height="{}" fill="{CONTACT_COLOR}" fill-opacity="0.08"/>"#,
            num(a),
            num(top),
            num(b - a),
            num(PROBE_HEIGHT)
        );
    }
    let (lo, hi) =
        extent(points).map_or((p.low, p.high), |(lo, hi)| (lo.min(p.low), hi.max(p.high)));
    let pad = 0.08 * (hi - lo);
    let axis = Axis::linear(lo - pad, hi + pad, 6).with_unit(&p.unit);
    let y = |v: f64| top + PROBE_HEIGHT * (1.0 - axis.fraction(v));
    y_ticks(out, &axis, top, PROBE_HEIGHT);
    let _ = writeln!(out, r#"<g clip-path="url(#panel{id})">"#);
    for (name, level) in [("high", p.high), ("low", p.low)] {
        let _ = writeln!(
            out,
            r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="{THRESHOLD_COLOR}" stroke-dasharray="6 4" stroke-opacity="0.8"/>"#,
            num(LEFT),
            num(LEFT + PLOT_WIDTH),
            y = num(y(level))
        );
        let _ = writeln!(
            out,
            r#"<text x="{}" y="{}" text-anchor="end" font-size="10" fill="{THRESHOLD_COLOR}">{name} {}</text>"#,
            num(LEFT + PLOT_WIDTH - 4.0),
            num(y(level) - 3.0),
            escape(&axis.precise(level))
        );
    }
    let _ = writeln!(
        out,
        r#"<polyline fill="none" stroke="{SIGNAL_COLOR}" stroke-width="1.5" stroke-linejoin="round" points="{}"/>"#,
        polyline(points, x, y)
    );
    for e in p.edges.iter().filter(|e| e.time >= t0 && e.time <= t1) {
        let (level, tip) = match e.direction {
            Direction::Rising => (p.high, -5.0),
            Direction::Falling => (p.low, 5.0),
        };
        let (cx, cy) = (x(e.time), y(level));
        let _ = writeln!(
            out,
            r#"<path d="M{} {}L{} {}L{} {}Z" fill="{EDGE_COLOR}"/>"#,
            num(cx),
            num(cy + tip),
            num(cx - 4.0),
            num(cy - tip),
            num(cx + 4.0),
            num(cy - tip)
        );
    }
    let _ = writeln!(out, "</g>");
    panel_frame(out, top, PROBE_HEIGHT);
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}"><tspan font-weight="bold">{}</tspan>  {}</text>"#,
        num(LEFT),
        num(top - 8.0),
        escape(&p.name),
        escape(&edge_summary(&p.edges))
    );
    let _ = writeln!(out, "</g>");
}

/// The shared time axis along `bottom` (px): ticks, their labels and the
/// axis's name.
fn time_axis(out: &mut String, layout: &Layout, bottom: f64) {
    let time = &layout.time;
    for &t in &time.ticks {
        let _ = writeln!(
            out,
            r#"<line x1="{x}" y1="{}" x2="{x}" y2="{}" stroke="{AXIS_COLOR}"/>"#,
            num(bottom),
            num(bottom + 5.0),
            x = num(layout.x(t))
        );
        let _ = writeln!(
            out,
            r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
            num(layout.x(t)),
            num(bottom + 18.0),
            escape(&time.label(t))
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{}" y="{}" text-anchor="middle">time</text>"#,
        num(LEFT + PLOT_WIDTH / 2.0),
        num(bottom + 38.0)
    );
}

/// The key at the top right: what the line styles mean.
fn legend(out: &mut String, contact_only: bool) {
    if contact_only {
        return;
    }
    let right = LEFT + PLOT_WIDTH;
    let y = 24.0;
    let _ = writeln!(
        out,
        r#"<g font-size="11"><line x1="{}" y1="{y0}" x2="{}" y2="{y0}" stroke="{SIGNAL_COLOR}" stroke-width="1.5"/><text x="{}" y="{y1}">signal</text><line x1="{}" y1="{y0}" x2="{}" y2="{y0}" stroke="{THRESHOLD_COLOR}" stroke-dasharray="6 4"/><text x="{}" y="{y1}">thresholds</text><path d="M{} {}L{} {}L{} {}Z" fill="{EDGE_COLOR}"/><text x="{}" y="{y1}">edges</text></g>"#,
        num(right - 290.0),
        num(right - 265.0),
        num(right - 260.0),
        num(right - 205.0),
        num(right - 180.0),
        num(right - 175.0),
        num(right - 60.0),
        num(y - 9.0),
        num(right - 64.0),
        num(y - 1.0),
        num(right - 56.0),
        num(y - 1.0),
        num(right - 50.0),
        y0 = num(y - 4.0),
        y1 = num(y),
    );
}

fn panel_frame(out: &mut String, top: f64, height: f64) {
    let _ = writeln!(
        out,
        r#"<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="{AXIS_COLOR}"/>"#,
        num(LEFT),
        num(top),
        num(PLOT_WIDTH),
        num(height)
    );
}

fn y_ticks(out: &mut String, axis: &Axis, top: f64, height: f64) {
    for &v in &axis.ticks {
        let y = num(top + height * (1.0 - axis.fraction(v)));
        let _ = writeln!(
            out,
            r#"<line x1="{}" y1="{y}" x2="{}" y2="{y}" stroke="{GRID_COLOR}"/>"#,
            num(LEFT),
            num(LEFT + PLOT_WIDTH),
        );
        let _ = writeln!(
            out,
            r#"<text x="{}" y="{}" text-anchor="end">{}</text>"#,
            num(LEFT - 6.0),
            num(top + height * (1.0 - axis.fraction(v)) + 4.0),
            escape(&axis.label(v))
        );
    }
}

/// "3 edges (2 glitches), shortest pulse 12 µs".
fn edge_summary(edges: &[Edge]) -> String {
    let n = edges.len();
    let mut s = format!("{n} edge{}", if n == 1 { "" } else { "s" });
    if n > 1 {
        let g = n - 1;
        let _ = write!(s, " ({g} glitch{})", if g == 1 { "" } else { "es" });
    }
    let shortest = edges.iter().filter_map(|e| e.width).min_by(f64::total_cmp);
    if let Some(w) = shortest {
        let _ = write!(s, ", shortest pulse {}", engineering(w, "s"));
    }
    s
}

fn check(name: &str, s: Series) -> Result<(), SvgError> {
    if s.time.len() != s.value.len() {
        return Err(SvgError::Length {
            name: name.to_owned(),
            time: s.time.len(),
            values: s.value.len(),
        });
    }
    match s.time.windows(2).position(|w| w[1] < w[0]) {
        Some(k) => Err(SvgError::Unsorted {
            name: name.to_owned(),
            index: k + 1,
        }),
        None => Ok(()),
    }
}

/// The closed intervals inside [t0, t1] as pixel spans, shaded behind the
/// probes so that a glitch can be read against the closure that caused
/// it. Spans less than half a pixel apart merge, and each is at least half
/// a pixel wide, so thousands of closures stay a few hundred rectangles.
fn closed_bands(intervals: &[Interval], t0: f64, t1: f64) -> Vec<(f64, f64)> {
    let x = |t: f64| LEFT + (t.clamp(t0, t1) - t0) / (t1 - t0) * PLOT_WIDTH;
    let mut bands: Vec<(f64, f64)> = Vec::new();
    let closed = intervals
        .iter()
        .filter(|i| i.state == ContactState::Closed && i.end >= t0 && i.start <= t1);
    for i in closed {
        let (a, b) = (x(i.start), x(i.end).max(x(i.start) + 0.5));
        match bands.last_mut() {
            Some(last) if a - last.1 < 0.5 => last.1 = last.1.max(b),
            _ => bands.push((a, b)),
        }
    }
    bands
}

/// The contact trace as decimated (time, value) points: states as 0 (open)
/// and 1 (closed) with vertical steps, resistance as log₁₀ Ω.
fn contact_points(trace: ContactTrace, t0: f64, t1: f64) -> Result<Vec<(f64, f64)>, SvgError> {
    match trace {
        ContactTrace::States(intervals) => {
            let (mut time, mut value) = (Vec::new(), Vec::new());
            for i in intervals {
                let level = match i.state {
                    ContactState::Open => 0.0,
                    ContactState::Closed => 1.0,
                };
                time.extend([i.start, i.end]);
                value.extend([level, level]);
            }
            check(
                "contact",
                Series {
                    time: &time,
                    value: &value,
                },
            )?;
            Ok(decimate(&time, &value, t0, t1, COLUMNS))
        }
        ContactTrace::Resistance(s) => {
            check("contact resistance", s)?;
            let log: Vec<f64> = s
                .value
                .iter()
                .map(|&r| if r > 0.0 { r.log10() } else { f64::NAN })
                .collect();
            Ok(decimate(s.time, &log, t0, t1, COLUMNS))
        }
    }
}

/// At most four points per pixel column over [t0, t1] (module overview),
/// plus the values interpolated at t0 and t1 when the data extends past
/// them. Non-finite samples are skipped. `time` must be non-decreasing.
pub(crate) fn decimate(
    time: &[f64],
    value: &[f64],
    t0: f64,
    t1: f64,
    columns: usize,
) -> Vec<(f64, f64)> {
    let finite = |k: usize| time[k].is_finite() && value[k].is_finite();
    let first = time.partition_point(|&t| t < t0);
    let end = time.partition_point(|&t| t <= t1);
    let mut out = Vec::new();
    // The line enters at t0 from the last finite sample before it.
    let before = (0..first).rev().find(|&k| finite(k));
    let inside = (first..end).find(|&k| finite(k));
    if let (Some(a), Some(b)) = (
        before,
        inside.or_else(|| (end..time.len()).find(|&k| finite(k))),
    ) {
        out.push((t0, lerp(time[a], value[a], time[b], value[b], t0)));
    }
    let column = |t: f64| (((t - t0) / (t1 - t0) * columns as f64) as usize).min(columns - 1);
    let mut k = first;
    while k < end {
        if !finite(k) {
            k += 1;
            continue;
        }
        let c = column(time[k]);
        let (mut lo, mut hi, mut last) = (k, k, k);
        let mut j = k + 1;
        while j < end && column(time[j]) == c {
            if finite(j) {
                if value[j] < value[lo] {
                    lo = j;
                }
                if value[j] > value[hi] {
                    hi = j;
                }
                last = j;
            }
            j += 1;
        }
        let mut picks = [k, lo, hi, last];
        picks.sort_unstable();
        let mut previous = None;
        for p in picks {
            if previous != Some(p) {
                out.push((time[p], value[p]));
                previous = Some(p);
            }
        }
        k = j;
    }
    let after = (end..time.len()).find(|&k| finite(k));
    let last_inside = (first..end).rev().find(|&k| finite(k)).or(before);
    if let (Some(a), Some(b)) = (last_inside, after) {
        out.push((t1, lerp(time[a], value[a], time[b], value[b], t1)));
    }
    out
}

fn lerp(t0: f64, v0: f64, t1: f64, v1: f64, t: f64) -> f64 {
    if t1 == t0 {
        v1
    } else {
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    }
}

fn extent(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let mut it = points.iter().map(|p| p.1);
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), v| (lo.min(v), hi.max(v))))
}

fn polyline(points: &[(f64, f64)], x: impl Fn(f64) -> f64, y: impl Fn(f64) -> f64) -> String {
    let mut s = String::with_capacity(points.len() * 12);
    for (i, &(t, v)) in points.iter().enumerate() {
        if i > 0 {
            s.push(' ');
        }
        let _ = write!(s, "{},{}", num(x(t)), num(y(v)));
    }
    s
}

/// How tick values become labels.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Scale {
    /// Engineering prefix 10^exponent, `decimals` after the point.
    Linear { exponent: i32, decimals: usize },
    /// Ticks are log₁₀ of the value.
    Decades,
    /// 0 open, 1 closed.
    States,
}

/// A value axis: its range, ticks and labels.
#[derive(Debug, Clone, PartialEq)]
struct Axis {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
    scale: Scale,
    unit: String,
}

impl Axis {
    /// Round ticks (1, 2 or 5 × 10^k apart), about `target` of them.
    fn linear(lo: f64, hi: f64, target: usize) -> Axis {
        let (lo, hi) = if hi > lo {
            (lo, hi)
        } else {
            let d = if lo == 0.0 { 1.0 } else { 0.1 * lo.abs() };
            (lo - d, hi + d)
        };
        let raw = (hi - lo) / target as f64;
        let magnitude = 10f64.powi(raw.log10().floor() as i32);
        let step = [1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .map(|m| m * magnitude)
            .find(|&s| s >= raw * (1.0 - 1e-9))
            .unwrap_or(10.0 * magnitude);
        let first = (lo / step - 1e-9).ceil() as i64;
        let last = (hi / step + 1e-9).floor() as i64;
        let ticks: Vec<f64> = (first..=last).map(|i| i as f64 * step).collect();
        let largest = ticks.iter().fold(0f64, |m, t| m.max(t.abs())).max(step);
        let exponent = (3.0 * (largest.log10() / 3.0).floor()).clamp(-15.0, 12.0) as i32;
        let step_in_prefix = step / 10f64.powi(exponent);
        let decimals = (-(step_in_prefix.log10() + 1e-9).floor()).max(0.0) as usize;
        Axis {
            lo,
            hi,
            ticks,
            scale: Scale::Linear { exponent, decimals },
            unit: String::new(),
        }
    }

    /// log₁₀ Ω from `lo` to `hi`, ticks on whole decades (every third when
    /// there are many).
    fn decades(lo: f64, hi: f64) -> Axis {
        let (lo, hi) = ((lo - 0.3).floor(), (hi + 0.3).ceil());
        let stride = if hi - lo > 8.0 { 3 } else { 1 };
        let ticks = (lo as i64..=hi as i64)
            .filter(|d| d.rem_euclid(stride) == 0)
            .map(|d| d as f64)
            .collect();
        Axis {
            lo,
            hi,
            ticks,
            scale: Scale::Decades,
            unit: "Ω".to_owned(),
        }
    }

    fn states() -> Axis {
        Axis {
            lo: -0.25,
            hi: 1.25,
            ticks: vec![0.0, 1.0],
            scale: Scale::States,
            unit: String::new(),
        }
    }

    fn with_unit(mut self, unit: &str) -> Axis {
        unit.clone_into(&mut self.unit);
        self
    }

    /// Where `v` sits, 0 at `lo` and 1 at `hi`.
    fn fraction(&self, v: f64) -> f64 {
        (v - self.lo) / (self.hi - self.lo)
    }

    /// `v` with three significant digits in the axis's prefix, e.g. a
    /// threshold: "2.31 V" on an axis labelled "0 V, 1 V, ...".
    fn precise(&self, v: f64) -> String {
        match self.scale {
            Scale::Linear { exponent, .. } => significant(v, exponent, &self.unit),
            _ => self.label(v),
        }
    }

    fn label(&self, v: f64) -> String {
        match self.scale {
            Scale::Linear { exponent, decimals } => {
                let scaled = v / 10f64.powi(exponent);
                let mut n = format!("{scaled:.decimals$}");
                if n.trim_start_matches(['-', '0', '.']).is_empty() {
                    n = format!("{:.decimals$}", 0.0);
                }
                format!("{n} {}{}", prefix(exponent), self.unit)
            }
            Scale::Decades => engineering(10f64.powf(v.round()), &self.unit),
            Scale::States if v >= 0.5 => "closed".to_owned(),
            Scale::States => "open".to_owned(),
        }
    }
}

/// The smallest of 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k not below `x`.
fn round_up(x: f64) -> f64 {
    let magnitude = 10f64.powi(x.log10().floor() as i32);
    [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0]
        .into_iter()
        .map(|m| m * magnitude)
        .find(|&r| r >= x * (1.0 - 1e-12))
        .unwrap_or(10.0 * magnitude)
}

/// A coordinate with one decimal, never "-0.0".
fn num(x: f64) -> String {
    let s = format!("{x:.1}");
    if s == "-0.0" { "0.0".to_owned() } else { s }
}

/// Text for XML content and attribute values.
pub(crate) fn escape(text: &str) -> String {
    let mut s = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => s.push_str("&amp;"),
            '<' => s.push_str("&lt;"),
            '>' => s.push_str("&gt;"),
            '"' => s.push_str("&quot;"),
            '\'' => s.push_str("&apos;"),
            c => s.push(c),
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::{ProbeKind, analyze_samples};
    use crate::scenario::Probe;

    /// Tags open and close in order (a small XML well-formedness check:
    /// enough to catch a missing `</g>` or an unescaped `<`).
    fn assert_balanced(svg: &str) {
        let mut stack: Vec<&str> = Vec::new();
        let mut rest = svg;
        while let Some(open) = rest.find('<') {
            let close = rest[open..].find('>').expect("an unclosed tag") + open;
            let tag = &rest[open + 1..close];
            assert!(!tag.contains('<'), "`<` inside a tag: {tag}");
            if let Some(name) = tag.strip_prefix('/') {
                assert_eq!(stack.pop(), Some(name), "closing {name}");
            } else if !tag.ends_with('/') {
                stack.push(tag.split_whitespace().next().unwrap());
            }
            // Text between tags must not hold a bare `>`... or `&` that is
            // not an entity.
            let text_end = rest[close..].find('<').map_or(rest.len(), |i| i + close);
            let text = &rest[close + 1..text_end];
            for (i, _) in text.match_indices('&') {
                let entity = &text[i..];
                assert!(
                    ["&amp;", "&lt;", "&gt;", "&quot;", "&apos;"]
                        .iter()
                        .any(|e| entity.starts_with(e)),
                    "bare & in {text}"
                );
            }
            rest = &rest[close + 1..];
        }
        assert!(stack.is_empty(), "unclosed: {stack:?}");
    }

    fn square(n: usize) -> (Vec<f64>, Vec<f64>) {
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-6).collect();
        let value = (0..n)
            .map(|k| if (k / 100) % 2 == 1 { 3.3 } else { 0.0 })
            .collect();
        (time, value)
    }

    fn demo<'a>(time: &'a [f64], value: &'a [f64], intervals: &'a [Interval]) -> SvgPlot<'a> {
        let probe = Probe::new("v(in)", 0.99, 2.31);
        let a = analyze_samples(&probe, ProbeKind::Voltage, time, value, &[]).unwrap();
        SvgPlot {
            title: "MCU input <relay K1> & \"bounce\"".to_owned(),
            window: (0.0, 1e-3),
            contact: Some(ContactTrace::States(intervals)),
            probes: vec![ProbePanel::from_analysis(&a, Series { time, value })],
            arcs: Vec::new(),
            pole_face: Vec::new(),
        }
    }

    fn intervals() -> Vec<Interval> {
        use ContactState::{Closed, Open};
        [(Open, 0.0, 1e-4), (Closed, 1e-4, 2e-4), (Open, 2e-4, 3e-4)]
            .into_iter()
            .chain([(Closed, 3e-4, 2e-3)])
            .map(|(state, start, end)| Interval { state, start, end })
            .collect()
    }

    #[test]
    fn a_one_sample_spike_survives_decimation() {
        // 10^6 samples of 0 with one sample of 1 V: 840 columns keep it.
        let n = 1_000_000;
        let time: Vec<f64> = (0..n).map(|k| k as f64 * 1e-9).collect();
        let mut value = vec![0.0; n];
        value[612_345] = 1.0;
        value[3] = -0.5;
        let points = decimate(&time, &value, 0.0, time[n - 1], COLUMNS);
        assert!(points.len() <= 4 * COLUMNS, "{}", points.len());
        assert!(points.contains(&(time[612_345], 1.0)));
        assert!(points.contains(&(time[3], -0.5)));
        assert!(points.windows(2).all(|w| w[0].0 <= w[1].0), "time order");
        // And in the picture: the spike reaches the top of the range.
        let probe = ProbePanel {
            name: "v(x)".to_owned(),
            unit: "V".to_owned(),
            series: Series {
                time: &time,
                value: &value,
            },
            low: 0.2,
            high: 0.8,
            edges: vec![],
        };
        let plot = SvgPlot {
            title: "spike".to_owned(),
            window: (0.0, 1e-3),
            contact: None,
            probes: vec![probe],
            arcs: Vec::new(),
            pole_face: Vec::new(),
        };
        let svg = render(&plot).unwrap();
        // The range [-0.5, 1] V padded by 8 % of its span: [-0.62, 1.12].
        let expected = num(TOP + PROBE_HEIGHT * (1.0 - (1.0 + 0.62) / 1.74));
        let line = svg.lines().find(|l| l.contains("<polyline")).unwrap();
        assert!(line.contains(&format!(",{expected}")), "{expected}");
        assert_balanced(&svg);
    }

    #[test]
    fn decimation_interpolates_the_window_ends() {
        let time = [0.0, 1.0, 2.0, 3.0];
        let value = [0.0, 10.0, 20.0, 30.0];
        let points = decimate(&time, &value, 0.5, 2.5, 4);
        assert_eq!(
            points,
            vec![(0.5, 5.0), (1.0, 10.0), (2.0, 20.0), (2.5, 25.0)]
        );
        // Non-finite samples are skipped, not drawn.
        let points = decimate(&time, &[0.0, f64::NAN, 20.0, 30.0], 0.0, 3.0, 4);
        assert_eq!(points, vec![(0.0, 0.0), (2.0, 20.0), (3.0, 30.0)]);
    }

    #[test]
    fn pole_face_impacts_are_marked_over_the_contact_panel() {
        let (time, value) = square(2001);
        let iv = intervals();
        let mut plot = demo(&time, &value, &iv);
        // Two in the 1 ms window, one after it.
        plot.pole_face = vec![3e-4, 4.5e-4, 2e-3];
        let svg = render(&plot).unwrap();
        assert_balanced(&svg);
        assert_eq!(
            svg.matches("<title>pole-face impact at ").count(),
            2,
            "{svg}"
        );
        assert!(svg.contains("pole-face impacts)"));
        assert!(
            !render(&demo(&time, &value, &iv))
                .unwrap()
                .contains("pole-face")
        );
    }

    #[test]
    fn arcs_and_breakdowns_are_marked_on_the_contact_panel() {
        let (time, value) = square(2001);
        let iv = intervals();
        let mut plot = demo(&time, &value, &iv);
        // A 1 µs arc at 200 µs, a breakdown at 250 µs, one outside.
        plot.arcs = vec![
            (2e-4, 2.01e-4, true),
            (2.5e-4, 2.6e-4, false),
            (5e-3, 6e-3, true),
        ];
        let svg = render(&plot).unwrap();
        assert_balanced(&svg);
        assert_eq!(svg.matches("<title>arc ").count(), 1, "{svg}");
        assert_eq!(svg.matches("<title>breakdown ").count(), 1);
        // 1 µs of a 1 ms window is under a pixel: drawn 2 px wide.
        assert!(svg.contains(&format!(r#"width="2.0" height="{}""#, num(CONTACT_HEIGHT))));
        assert!(svg.contains("arcs shaded"));
        assert!(
            !render(&demo(&time, &value, &iv))
                .unwrap()
                .contains("<title>arc")
        );
    }

    #[test]
    fn output_is_deterministic_and_well_formed() {
        let (time, value) = square(2001);
        let iv = intervals();
        let a = render(&demo(&time, &value, &iv)).unwrap();
        let b = render(&demo(&time, &value, &iv)).unwrap();
        assert_eq!(a, b);
        assert_eq!(a.matches("<svg").count(), 1);
        assert_eq!(a.matches("</svg>").count(), 1);
        assert!(!a.contains("NaN") && !a.contains("inf"), "{a}");
        assert_balanced(&a);
        // The title is escaped, the panels labelled, thresholds named.
        assert!(a.contains("MCU input &lt;relay K1&gt; &amp; &quot;bounce&quot;"));
        assert!(a.contains(">contact</text>") && a.contains(">closed</text>"));
        // Both closures shade the probe panel: 100–200 µs and 300 µs on.
        let x = |t: f64| num(LEFT + t / 1e-3 * PLOT_WIDTH);
        for (a0, width) in [(x(1e-4), "84.0"), (x(3e-4), "588.0")] {
            let band = format!(
                r#"<rect x="{a0}" y="{}" width="{width}""#,
                num(TOP + CONTACT_HEIGHT + GAP)
            );
            assert!(a.contains(&band), "{band}");
        }
        assert!(
            a.contains(">high 2.31 V<") && a.contains(">low 0.99 V<"),
            "{a}"
        );
        // 1 ms window: ticks in µs or ms, never raw seconds.
        assert!(
            a.contains(">0.2 ms</text>") && a.contains(">1.0 ms</text>"),
            "{a}"
        );
        // Edges just before 100, 200, ... 1000 µs: 10 in the window (plus
        // the legend's marker), 20 overall.
        assert_eq!(
            a.matches(&format!(r#"fill="{EDGE_COLOR}"/>"#)).count(),
            10 + 1
        );
        assert!(
            a.contains("20 edges (19 glitches), shortest pulse 100 µs"),
            "{a}"
        );
    }

    #[test]
    fn resistance_on_a_log_axis() {
        let time = [0.0, 1e-4, 1.0001e-4, 2e-4, 2.0001e-4, 1e-3];
        let r = [1e9, 1e9, 0.05, 0.05, 1e9, 1e9];
        let plot = SvgPlot {
            title: "R".to_owned(),
            window: (0.0, 1e-3),
            contact: Some(ContactTrace::Resistance(Series {
                time: &time,
                value: &r,
            })),
            probes: vec![],
            arcs: Vec::new(),
            pole_face: Vec::new(),
        };
        let svg = render(&plot).unwrap();
        assert_balanced(&svg);
        assert!(svg.contains(">contact resistance</text>"));
        // log10 0.05 ≈ −1.3: the axis spans −2 to 10 decades, ticked on
        // every third.
        for label in ["1 Ω", "1 kΩ", "1 MΩ", "1 GΩ"] {
            assert!(svg.contains(&format!(">{label}</text>")), "{label}: {svg}");
        }
    }

    #[test]
    fn bad_input_is_refused() {
        let (time, value) = square(10);
        let iv = intervals();
        let mut plot = demo(&time, &value, &iv);
        plot.window = (1e-3, 1e-3);
        assert!(matches!(render(&plot), Err(SvgError::Window { .. })));
        plot.window = (0.0, f64::NAN);
        assert!(matches!(render(&plot), Err(SvgError::Window { .. })));
        plot.window = (0.0, 1e-3);
        plot.probes[0].series.value = &value[..5];
        assert!(matches!(render(&plot), Err(SvgError::Length { .. })));
        let empty = SvgPlot {
            title: String::new(),
            window: (0.0, 1.0),
            contact: None,
            probes: vec![],
            arcs: Vec::new(),
            pole_face: Vec::new(),
        };
        assert_eq!(render(&empty), Err(SvgError::Empty));
    }

    #[test]
    fn labels_in_engineering_units() {
        assert_eq!(engineering(3e-6, "s"), "3 µs");
        assert_eq!(engineering(12.5e-6, "s"), "12.5 µs");
        assert_eq!(engineering(0.05, "Ω"), "50 mΩ");
        assert_eq!(engineering(1e9, "Ω"), "1 GΩ");
        assert_eq!(engineering(999.6e-6, "s"), "1 ms");
        assert_eq!(significant(0.99, 0, "V"), "0.99 V");
        assert_eq!(significant(-0.0001, -3, "A"), "-0.1 mA");
        let a = Axis::linear(-0.2, 3.5, 6).with_unit("V");
        assert_eq!(a.ticks.first(), Some(&0.0));
        assert_eq!(a.label(1.0), "1 V");
        let a = Axis::linear(0.0, 2.4e-3, 6).with_unit("A");
        assert_eq!(a.label(1.2e-3), "1.2 mA");
        let a = Axis::linear(-1e-3, 1e-3, 4).with_unit("A");
        assert_eq!(a.label(-5e-4), "-0.5 mA");
        assert_eq!(a.label(0.0), "0.0 mA");
        assert_eq!(suggested_window(Some(3.1e-3), 0.02), (0.0, 4e-3));
        assert_eq!(suggested_window(Some(0.019), 0.02), (0.0, 0.02));
        assert_eq!(suggested_window(None, 0.02), (0.0, 0.02));
    }
}
