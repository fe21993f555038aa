//! `sweep.svg`: a picture of a sweep, hand-written SVG like the run plot.
//!
//! - A random sweep: histograms, one panel each, of the bounce time
//!   (closed samples) and of every probe's edges (one bar per count).
//! - A grid sweep: the bounce time and every probe's edges against the
//!   first grid key, one line per value of the second key when there is
//!   one. A sample without a bounce time (the contact did not end closed)
//!   breaks the line.
//!
//! A grid of more than 20 000 points is drawn thinned (every k-th value
//! of the first key, at most 16 lines), as its title says; the summary
//! still counts every sample.
//!
//! Coordinates have one decimal, labels the digits their tick step needs:
//! the same sweep gives the same bytes.

use std::fmt::Write as _;

use super::error::SweepError;
use super::sample::Sampler;
use super::summary::{Collected, column};
use crate::report::svg::escape;

const WIDTH: f64 = 760.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 190.0;
const PANEL: f64 = 220.0;
const GAP: f64 = 70.0;
const TOP: f64 = 75.0;
const PLOT_WIDTH: f64 = WIDTH - LEFT - RIGHT;
const COLORS: [&str; 8] = [
    "#1f5fa8", "#c0392b", "#2a8a3a", "#e67e22", "#8e44ad", "#16a085", "#7f8c8d", "#d35400",
];
/// Histogram bars of a continuous value.
const BINS: usize = 30;
/// The most points a grid plot draws; a larger grid is thinned.
const MAX_POINTS: u64 = 20_000;
/// The most lines a thinned grid plot draws.
const MAX_SERIES: u64 = 16;

/// (x, y) points of a line; a `None` y breaks it.
type Points = Vec<(f64, Option<f64>)>;

/// A named line.
type Series = (String, Points);

/// One panel's content.
enum Content {
    /// (bin start, bin end, count) bars.
    Bars(Vec<(f64, f64, u64)>),
    Lines(Vec<Series>),
}

struct Panel {
    title: String,
    x_label: String,
    y_label: String,
    content: Content,
}

/// The SVG of a sweep.
pub fn render(collected: &Collected, sampler: &Sampler) -> Result<String, SweepError> {
    let panels = if sampler.is_grid() {
        grid_panels(collected, sampler)?
    } else {
        random_panels(collected)?
    };
    let height = TOP + panels.len() as f64 * (PANEL + GAP) + 10.0;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH}\" height=\"{height:.0}\" \
         viewBox=\"0 0 {WIDTH} {height:.0}\" font-family=\"sans-serif\" font-size=\"12\">"
    );
    let _ = writeln!(
        out,
        "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n\
         <text x=\"{LEFT}\" y=\"28\" font-size=\"16\">sweep of {} ({} samples)</text>",
        escape(&collected.keys.join(", ")),
        collected.len()
    );
    for (i, panel) in panels.iter().enumerate() {
        draw(&mut out, panel, TOP + i as f64 * (PANEL + GAP));
    }
    out.push_str("</svg>\n");
    Ok(out)
}

fn random_panels(c: &Collected) -> Result<Vec<Panel>, SweepError> {
    let mut panels = vec![Panel {
        title: format!(
            "bounce time ({} closed samples)",
            c.count(column::BOUNCE_TIME)
        ),
        x_label: "bounce time (ms)".to_owned(),
        y_label: "samples".to_owned(),
        content: Content::Bars(histogram(c)?),
    }];
    for (p, signal) in c.signals.iter().enumerate() {
        let counts = c.edge_counts(p);
        let bars = match (counts.keys().next(), counts.keys().next_back()) {
            (Some(&lo), Some(&hi)) => (lo..=hi)
                .map(|e| {
                    let n = counts.get(&e).copied().unwrap_or(0);
                    (f64::from(e) - 0.4, f64::from(e) + 0.4, n)
                })
                .collect(),
            _ => Vec::new(),
        };
        panels.push(Panel {
            title: format!("{signal}: Schmitt edges"),
            x_label: "edges".to_owned(),
            y_label: "samples".to_owned(),
            content: Content::Bars(bars),
        });
    }
    Ok(panels)
}

/// [`BINS`] bars of the bounce times, in ms, from the smallest to the
/// largest.
fn histogram(c: &Collected) -> Result<Vec<(f64, f64, u64)>, SweepError> {
    let Some((lo, hi)) = c.range(column::BOUNCE_TIME) else {
        return Ok(Vec::new());
    };
    let (lo, hi) = (lo * 1e3, hi * 1e3);
    let width = if hi > lo {
        (hi - lo) / BINS as f64
    } else {
        1e-3
    };
    let mut counts = vec![0u64; BINS];
    c.for_each_row(|row| {
        let t = row[column::BOUNCE_TIME];
        if t.is_finite() {
            let bin = (((t * 1e3 - lo) / width) as usize).min(BINS - 1);
            counts[bin] += 1;
        }
    })?;
    Ok(counts
        .iter()
        .enumerate()
        .map(|(i, &n)| (lo + i as f64 * width, lo + (i + 1) as f64 * width, n))
        .collect())
}

fn grid_panels(c: &Collected, sampler: &Sampler) -> Result<Vec<Panel>, SweepError> {
    let keys = sampler.keys();
    let steps = sampler.grid_steps();
    let inner = u64::from(steps.get(1).copied().unwrap_or(1));
    let outer = u64::from(steps.first().copied().unwrap_or(1));
    // A large grid is drawn thinned to at most MAX_POINTS points: at most
    // MAX_SERIES lines, each with every `stride`-th value of the first key.
    let (series_stride, stride) = if c.len() as u64 > MAX_POINTS {
        let series_stride = inner.div_ceil(MAX_SERIES);
        let series = inner.div_ceil(series_stride);
        (series_stride, (outer * series).div_ceil(MAX_POINTS).max(1))
    } else {
        (1, 1)
    };
    let kept = inner.div_ceil(series_stride) as usize;
    let mut series_names = vec![String::new(); kept];
    // Per series, per probe (0: the bounce time, 1 + p: probe p's edges).
    let probes = c.signals.len();
    let mut lines: Vec<Vec<Points>> = vec![vec![Vec::new(); kept]; 1 + probes];
    let mut failed = None;
    c.for_each_row(|row| {
        let index = row[column::INDEX] as u64;
        let (a, b) = (index / inner, index % inner);
        if a % stride != 0 || b % series_stride != 0 || failed.is_some() {
            return;
        }
        let values = match sampler.values_vec(index) {
            Ok(v) => v,
            Err(e) => {
                failed = Some(e);
                return;
            }
        };
        let s = (b / series_stride) as usize;
        if let Some(&v) = values.get(1) {
            series_names[s] = format!("{} = {v:?}", keys[1]);
        }
        let value = |x: f64| x.is_finite().then_some(x);
        lines[0][s].push((values[0], value(row[column::BOUNCE_TIME] * 1e3)));
        for p in 0..probes {
            lines[1 + p][s].push((values[0], value(row[column::EDGES + p])));
        }
    })?;
    if let Some(e) = failed {
        return Err(e);
    }
    let thinned = if stride > 1 || series_stride > 1 {
        format!(" (every {})", thinning(stride, series_stride, keys))
    } else {
        String::new()
    };
    let named =
        |points: Vec<Points>| -> Vec<Series> { series_names.iter().cloned().zip(points).collect() };
    let mut lines = lines.into_iter();
    let mut panels = vec![Panel {
        title: format!("bounce time against {}{thinned}", keys[0]),
        x_label: keys[0].clone(),
        y_label: "bounce time (ms)".to_owned(),
        content: Content::Lines(named(lines.next().unwrap_or_default())),
    }];
    for (signal, points) in c.signals.iter().zip(lines) {
        panels.push(Panel {
            title: format!("{signal}: Schmitt edges against {}{thinned}", keys[0]),
            x_label: keys[0].clone(),
            y_label: "edges".to_owned(),
            content: Content::Lines(named(points)),
        });
    }
    Ok(panels)
}

/// "2-th value of a, 4-th of b": what a thinned grid plot shows.
fn thinning(stride: u64, series_stride: u64, keys: &[String]) -> String {
    let nth = |k: u64| {
        if k == 1 {
            String::new()
        } else {
            format!("{k}-th ")
        }
    };
    let mut parts = vec![format!("{}value of {}", nth(stride), keys[0])];
    if series_stride > 1 {
        if let Some(b) = keys.get(1) {
            parts.push(format!("{}of {b}", nth(series_stride)));
        }
    }
    parts.join(", ")
}

fn draw(out: &mut String, panel: &Panel, top: f64) {
    let (x_range, y_range) = match &panel.content {
        Content::Bars(bars) => (
            bars.first()
                .map(|b| b.0)
                .zip(bars.last().map(|b| b.1))
                .unwrap_or((0.0, 1.0)),
            (
                0.0,
                bars.iter().map(|b| b.2).max().unwrap_or(1).max(1) as f64,
            ),
        ),
        Content::Lines(lines) => {
            let points: Vec<(f64, Option<f64>)> =
                lines.iter().flat_map(|l| l.1.iter()).copied().collect();
            let span = |v: Vec<f64>| match (
                v.iter().copied().reduce(f64::min),
                v.iter().copied().reduce(f64::max),
            ) {
                (Some(a), Some(b)) => (a, b),
                _ => (0.0, 1.0),
            };
            let (y0, y1) = span(points.iter().filter_map(|p| p.1).collect());
            (
                span(points.iter().map(|p| p.0).collect()),
                (y0.min(0.0), y1),
            )
        }
    };
    let (x0, x1) = widen(x_range);
    let (y0, y1) = widen(y_range);
    let x_ticks = ticks(x0, x1, false);
    // Counts have whole ticks.
    let y_ticks = ticks(y0, y1, matches!(panel.content, Content::Bars(_)));
    let (x0, x1) = (x0.min(x_ticks[0]), x1.max(*x_ticks.last().unwrap_or(&x1)));
    let (y0, y1) = (y0.min(y_ticks[0]), y1.max(*y_ticks.last().unwrap_or(&y1)));
    let px = |x: f64| LEFT + (x - x0) / (x1 - x0) * PLOT_WIDTH;
    let py = |y: f64| top + PANEL - (y - y0) / (y1 - y0) * PANEL;
    let _ = writeln!(
        out,
        "<text x=\"{LEFT}\" y=\"{:.1}\" font-size=\"13\">{}</text>",
        top - 8.0,
        escape(&panel.title)
    );
    for &t in &x_ticks {
        let _ = writeln!(
            out,
            "<line x1=\"{0:.1}\" y1=\"{top:.1}\" x2=\"{0:.1}\" y2=\"{1:.1}\" stroke=\"#e3e3e3\"/>\
             <text x=\"{0:.1}\" y=\"{2:.1}\" text-anchor=\"middle\">{3}</text>",
            px(t),
            top + PANEL,
            top + PANEL + 16.0,
            label(t, &x_ticks)
        );
    }
    for &t in &y_ticks {
        let _ = writeln!(
            out,
            "<line x1=\"{LEFT}\" y1=\"{0:.1}\" x2=\"{1:.1}\" y2=\"{0:.1}\" stroke=\"#e3e3e3\"/>\
             <text x=\"{2:.1}\" y=\"{3:.1}\" text-anchor=\"end\">{4}</text>",
            py(t),
            LEFT + PLOT_WIDTH,
            LEFT - 6.0,
            py(t) + 4.0,
            label(t, &y_ticks)
        );
    }
    let _ = writeln!(
        out,
        "<rect x=\"{LEFT}\" y=\"{top:.1}\" width=\"{PLOT_WIDTH}\" height=\"{PANEL}\" fill=\"none\" \
         stroke=\"#333333\"/>\n<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\n\
         <text transform=\"translate({:.1},{:.1}) rotate(-90)\" text-anchor=\"middle\">{}</text>",
        LEFT + PLOT_WIDTH / 2.0,
        top + PANEL + 34.0,
        escape(&panel.x_label),
        LEFT - 55.0,
        top + PANEL / 2.0,
        escape(&panel.y_label)
    );
    match &panel.content {
        Content::Bars(bars) => {
            for &(a, b, n) in bars.iter().filter(|b| b.2 > 0) {
                let _ = writeln!(
                    out,
                    "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"{}\"/>",
                    px(a),
                    py(n as f64),
                    (px(b) - px(a)).max(0.5),
                    py(0.0) - py(n as f64),
                    COLORS[0]
                );
            }
        }
        Content::Lines(lines) => {
            for (k, (name, points)) in lines.iter().enumerate() {
                let color = COLORS[k % COLORS.len()];
                let mut path = String::new();
                let mut pen_down = false;
                for point in points {
                    match point {
                        (x, Some(y)) => {
                            let _ = write!(
                                path,
                                "{}{:.1},{:.1} ",
                                if pen_down { "L" } else { "M" },
                                px(*x),
                                py(*y)
                            );
                            pen_down = true;
                            let _ = writeln!(
                                out,
                                "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"2.5\" fill=\"{color}\"/>",
                                px(*x),
                                py(*y)
                            );
                        }
                        (_, None) => pen_down = false,
                    }
                }
                let _ = writeln!(
                    out,
                    "<path d=\"{}\" fill=\"none\" stroke=\"{color}\" stroke-width=\"1.5\"/>",
                    path.trim_end()
                );
                if !name.is_empty() {
                    let y = top + 14.0 + 16.0 * k as f64;
                    let _ = writeln!(
                        out,
                        "<text x=\"{:.1}\" y=\"{y:.1}\" fill=\"{color}\">{}</text>",
                        LEFT + PLOT_WIDTH + 10.0,
                        escape(name)
                    );
                }
            }
        }
    }
}

/// A range with room: a single value becomes a small interval.
fn widen((a, b): (f64, f64)) -> (f64, f64) {
    if b > a {
        (a, b)
    } else if a == 0.0 {
        (0.0, 1.0)
    } else {
        (a - a.abs() * 0.1, b + b.abs() * 0.1)
    }
}

/// Round ticks (1, 2, 5 × 10ⁿ apart, at least 1 when `whole`) covering
/// [a, b], about five.
fn ticks(a: f64, b: f64, whole: bool) -> Vec<f64> {
    let raw = (b - a) / 5.0;
    let raw = if whole { raw.max(1.0) } else { raw };
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * magnitude);
    let first = (a / step).floor() as i64;
    let last = (b / step).ceil() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// A tick label with the decimals its step needs.
fn label(value: f64, ticks: &[f64]) -> String {
    let step = if ticks.len() > 1 {
        ticks[1] - ticks[0]
    } else {
        1.0
    };
    if step.abs() < 1e-3 || value.abs() >= 1e6 {
        return format!("{value:.2e}");
    }
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let text = format!("{value:.decimals$}");
    if text.starts_with("-") && text.trim_start_matches(['-', '0', '.']).is_empty() {
        text[1..].to_owned()
    } else {
        text
    }
}
