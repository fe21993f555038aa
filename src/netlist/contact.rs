//! The contact include: an ngspice file that defines `.subckt <NAME> a b`,
//! a two-terminal element whose conductance follows a [`Waveform`].
//!
//! Three elements are available ([`ContactElement`]); the comparison that
//! chose the default is in `docs/contact-elements.md` (which also
//! measured an XSPICE `filesource`: without breakpoints, G jumps within a
//! time step and the integrator rings, so it is not offered):
//!
//! - [`ContactElement::Pwl`] (default): PWL voltage sources set a control
//!   node to G(t) in siemens and `B1 a b I = V(a,b) * V(g)` draws the
//!   current. Every corner of the waveform is a breakpoint of the PWL
//!   source, so edges land exactly; the B-source only multiplies, so
//!   nothing divides by a value near zero; plain SPICE, one file.
//! - [`ContactElement::EventRamp`]: an XSPICE `d_source` replays the edge
//!   start times from a data file and a `dac_bridge` turns them into
//!   linear 0→1 ramps of one edge time, which scale G between its two
//!   levels. `dac_bridge` posts a breakpoint at each edge start and end,
//!   so edges are as exact as with PWL, and the cost per time step does
//!   not grow with the number of bounces. Two-level waveforms only.
//! - [`ContactElement::Switch`]: a PWL control voltage (0 open, 1 closed)
//!   drives an `sw` switch between r_closed and r_open. Two states only:
//!   no finite edges, no graded resistance; it flips 60 % into an edge.
//!
//! # Why long PWL waveforms are split
//! ngspice evaluates a PWL source by scanning its point list from the
//! start, and joins a card's `+` continuation lines one at a time while
//! reading the deck: both cost more than linearly in the number of
//! points. The PWL is therefore emitted as several sources in series,
//! each covering a window of the points (see [`DEFAULT_POINTS_PER_SOURCE`]).
//! Windows are cut where G equals its minimum G_min; each window's source
//! holds G − G_min, which is zero at both of its ends, so outside its
//! window it is exactly zero (the first and last windows hold their end
//! values beyond the record, which is what a single PWL would do). The
//! sum is `V(g) = G_min + ΣΔ_k`: at any time one window carries the
//! waveform, every corner is still a breakpoint of one source, and as
//! every term is ≥ 0, G ≥ G_min > 0.
//!
//! Measured in ngspice 39, the split removes the deck-reading cost (40 000
//! points: 4.2 s to 0.1 s) but not the run cost: a source whose window is
//! over is still scanned to its end at every step (`VSRCload` only skips
//! the scan *before* the first point), so the windows together scan as
//! much as one long PWL. 10 000 bounces take ~77× the time of 1000. For
//! long sequences [`ContactElement::for_waveform`] picks
//! [`ContactElement::EventRamp`], whose cost is linear (~6×).
//!
//! # Output
//! The text is deterministic: the same waveform, name and element give the
//! same bytes (numbers via [`format_time`], no dates or versions).

use std::fmt;
use std::str::FromStr;

use super::error::NetlistError;
use crate::waveform::{Point, Waveform, format_time};

/// Points per PWL source before the waveform is split into windows.
/// 256 points keep each card to ~70 continuation lines (ngspice joins
/// them one at a time, quadratically) while a realistic closing (tens of
/// bounces, four points each) stays one source.
pub const DEFAULT_POINTS_PER_SOURCE: usize = 256;

/// Above this many points [`ContactElement::for_waveform`] picks
/// event-ramp. Measured (docs/contact-elements.md): 100 bounces (404
/// points) run in 0.07 s as PWL and 0.13 s as event-ramp, 1000 bounces
/// (4004 points) in 2.5 s and 1.1 s; the crossover lies near 500 bounces.
pub const EVENT_RAMP_ABOVE_POINTS: usize = 2000;

/// Emitted lines stay below this many characters.
const LINE_WIDTH: usize = 80;

/// The shortest edge [`ContactElement::EventRamp`] accepts, s: `d_source`
/// schedules itself 0.1 ns before each event, so events closer than that
/// would run out of order.
const EVENT_MIN_SPACING: f64 = 1e-9;

/// How the include models the contact; see the module overview.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum ContactElement {
    /// PWL control voltage, behavioural conductance. Exact, plain SPICE.
    #[default]
    Pwl,
    /// XSPICE `d_source` + `dac_bridge` ramps; two-level waveforms only.
    EventRamp,
    /// `sw` switch on a PWL control voltage; two states, no edges.
    Switch,
}

impl ContactElement {
    /// Every element, the default first.
    pub const ALL: [ContactElement; 3] = [
        ContactElement::Pwl,
        ContactElement::EventRamp,
        ContactElement::Switch,
    ];

    /// The name used in options and files: `pwl`, `event-ramp`, `switch`.
    pub fn as_str(self) -> &'static str {
        match self {
            ContactElement::Pwl => "pwl",
            ContactElement::EventRamp => "event-ramp",
            ContactElement::Switch => "switch",
        }
    }

    /// The element for `waveform`: [`ContactElement::EventRamp`] above
    /// [`EVENT_RAMP_ABOVE_POINTS`] when it can represent the waveform (the
    /// PWL's run time grows with points × steps, event-ramp's does not),
    /// else the default [`ContactElement::Pwl`].
    pub fn for_waveform(waveform: &Waveform) -> ContactElement {
        let points = waveform.points();
        if points.len() <= EVENT_RAMP_ABOVE_POINTS {
            return ContactElement::Pwl;
        }
        let (g_min, g_max) = levels(points);
        match two_level_ramps(points, g_min, g_max) {
            Ok(_) => ContactElement::EventRamp,
            Err(_) => ContactElement::Pwl,
        }
    }

    /// Needs ngspice built with XSPICE code models, which set ngspice's
    /// TRTOL to 1 for the whole circuit (more, smaller time steps).
    pub fn uses_xspice(self) -> bool {
        self == ContactElement::EventRamp
    }
}

impl fmt::Display for ContactElement {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for ContactElement {
    type Err = NetlistError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ContactElement::ALL
            .into_iter()
            .find(|e| e.as_str().eq_ignore_ascii_case(s.trim()))
            .ok_or_else(|| NetlistError::UnknownElement { name: s.to_owned() })
    }
}

/// A generated include file and what it needs.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactInclude {
    /// The element the include uses.
    pub element: ContactElement,
    /// The subcircuit it defines (`.subckt NAME a b`).
    pub subckt: String,
    /// The include file's text.
    pub text: String,
    /// Files the include or the deck reads besides it, by plain file
    /// name relative to the directory ngspice runs in: (file name,
    /// contents). [`ContactElement::EventRamp`]'s data file; `run` adds a
    /// coil-driven relay's coil include.
    pub data_files: Vec<(String, String)>,
    /// Corners of the waveform.
    pub points: usize,
    /// PWL sources the points were split into (0 when none is used).
    pub pwl_sources: usize,
}

/// The include for `waveform` as subcircuit `subckt`, with the default
/// split ([`DEFAULT_POINTS_PER_SOURCE`]).
pub fn contact_include(
    waveform: &Waveform,
    subckt: &str,
    element: ContactElement,
) -> Result<ContactInclude, NetlistError> {
    contact_include_split(waveform, subckt, element, DEFAULT_POINTS_PER_SOURCE)
}

/// [`contact_include`] with at most about `points_per_source` points per
/// PWL source (a window ends at the first cut point after that many;
/// `usize::MAX` never splits).
pub fn contact_include_split(
    waveform: &Waveform,
    subckt: &str,
    element: ContactElement,
    points_per_source: usize,
) -> Result<ContactInclude, NetlistError> {
    check_subckt_name(subckt)?;
    let points = waveform.points();
    let (g_min, g_max) = levels(points);
    let (t_first, t_last) = (points[0].time, points[points.len() - 1].time);

    let mut head = String::new();
    let mut body = String::new();
    let mut data_files = Vec::new();
    let mut pwl_sources = 0;
    let element_line = match element {
        ContactElement::Pwl => {
            let values: Vec<f64> = points.iter().map(|p| p.conductance).collect();
            pwl_sources = emit_chain(&mut body, points, &values, "g", points_per_source);
            line(&mut body, "B1 a b I = V(a,b) * V(g)");
            "pwl: PWL sources set V(g) = G in siemens; B1 draws I = V(a,b) * V(g)"
        }
        ContactElement::Switch => {
            if g_max == g_min {
                // One state only: a switch with ron = roff is not a switch.
                line(
                    &mut body,
                    &format!("R1 a b {}", format_time(reciprocal(g_min))),
                );
            } else {
                let values: Vec<f64> = points
                    .iter()
                    .map(|p| (p.conductance - g_min) / (g_max - g_min))
                    .collect();
                pwl_sources = emit_chain(&mut body, points, &values, "c", points_per_source);
                line(&mut body, "S1 a b c 0 contact_sw");
                line(
                    &mut body,
                    &format!(
                        ".model contact_sw sw vt=0.5 vh=0.1 ron={} roff={}",
                        format_time(reciprocal(g_max)),
                        format_time(reciprocal(g_min))
                    ),
                );
            }
            "switch: a PWL control V(c) (0 open, 1 closed) drives sw switch S1 \
             (ron = 1/G_max, roff = 1/G_min, flips at 0.6 / 0.4)"
        }
        ContactElement::EventRamp => {
            let ramps = two_level_ramps(points, g_min, g_max)?;
            let file = format!("{}_events.txt", subckt.to_ascii_lowercase());
            let state = |closed: bool| if closed { "1s" } else { "0s" };
            let mut data = format!(
                "* chatterspice: edge starts of contact subcircuit {subckt}: t (s), state\n"
            );
            data.push_str(&format!("0e0 {}\n", state(ramps.starts_closed)));
            for &(t, closed) in &ramps.events {
                data.push_str(&format!("{} {}\n", format_time(t), state(closed)));
            }
            let edge = format_time(ramps.edge);
            line(&mut body, "A1 [d] contact_ev");
            line(
                &mut body,
                &format!(".model contact_ev d_source (input_file=\"{file}\")"),
            );
            line(&mut body, "A2 [d] [c] contact_ramp");
            line(
                &mut body,
                &format!(
                    ".model contact_ramp dac_bridge (out_low=0 out_high=1 \
                     t_rise={edge} t_fall={edge})"
                ),
            );
            line(
                &mut body,
                &format!(
                    "B1 a b I = V(a,b) * ({} + {} * V(c))",
                    format_time(g_min),
                    format_time(g_max - g_min)
                ),
            );
            data_files.push((file, data));
            "event-ramp: XSPICE d_source A1 replays the edge starts from the data file, \
             dac_bridge A2 ramps V(c) 0..1 over one edge; B1 draws \
             I = V(a,b) * (G_min + (G_max - G_min) * V(c))"
        }
    };

    comment(
        &mut head,
        &format!(
            "chatterspice contact subcircuit {subckt}: the relay contact as a \
             time-varying conductance between nodes a and b."
        ),
    );
    comment(
        &mut head,
        "Include this file and instantiate the subcircuit between the contact's nodes:",
    );
    line(&mut head, &format!("*   X1 a b {subckt}"));
    comment(&mut head, &format!("Element {element_line}."));
    if element.uses_xspice() {
        comment(
            &mut head,
            "Needs ngspice with XSPICE code models; XSPICE devices set TRTOL to 1. \
             The data file is opened from the directory ngspice runs in.",
        );
    }
    let counts = format!(
        "{} points, {} PWL source{}, t = {} s to {} s, G = {} S to {} S.",
        points.len(),
        pwl_sources,
        if pwl_sources == 1 { "" } else { "s" },
        format_time(t_first),
        format_time(t_last),
        format_time(g_min),
        format_time(g_max)
    );
    comment(&mut head, &counts);

    let mut text = head;
    line(&mut text, &format!(".subckt {subckt} a b"));
    text.push_str(&body);
    line(&mut text, &format!(".ends {subckt}"));
    Ok(ContactInclude {
        element,
        subckt: subckt.to_owned(),
        text,
        data_files,
        points: points.len(),
        pwl_sources,
    })
}

/// S, the lowest and highest conductance.
fn levels(points: &[Point]) -> (f64, f64) {
    points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.conductance), hi.max(p.conductance))
        })
}

/// A SPICE identifier that is also safe in a file name: a letter or `_`,
/// then letters, digits or `_`.
pub fn check_subckt_name(name: &str) -> Result<(), NetlistError> {
    let problem = if name.is_empty() {
        Some("is empty")
    } else if name.chars().any(char::is_whitespace) {
        Some("contains whitespace")
    } else if !name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
    {
        Some("does not start with a letter or `_`")
    } else if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        Some("has a character other than letters, digits and `_`")
    } else {
        None
    };
    match problem {
        Some(problem) => Err(NetlistError::BadSubcktName {
            name: name.to_owned(),
            problem,
        }),
        None => Ok(()),
    }
}

/// Sources whose sum is `values` (one per point) on node `out`, returning
/// how many PWL sources were emitted. Split into windows as described in
/// the module overview when there are more than `per_source` points.
fn emit_chain(
    out: &mut String,
    points: &[Point],
    values: &[f64],
    node: &str,
    per_source: usize,
) -> usize {
    let base = values.iter().copied().fold(f64::INFINITY, f64::min);
    let mut cuts = vec![0];
    if points.len() > per_source {
        for (i, &v) in values.iter().enumerate() {
            let last = cuts[cuts.len() - 1];
            if v == base && i > last && i - last + 1 >= per_source && i + 1 < values.len() {
                cuts.push(i);
            }
        }
    }
    cuts.push(points.len() - 1);
    let name = node.to_ascii_uppercase();
    if cuts.len() == 2 {
        if points.len() == 1 {
            line(
                out,
                &format!("V{name} {node} 0 DC {}", format_time(values[0])),
            );
            return 0;
        }
        line(out, &format!("V{name} {node} 0 PWL("));
        pairs(out, points.iter().zip(values).map(|(p, &v)| (p.time, v)));
        return 1;
    }
    let windows = cuts.len() - 1;
    comment(
        out,
        &format!(
            "V({node}) = {} + {windows} window sources in series; each holds the waveform \
             minus that base within its window and is zero outside it.",
            format_time(base)
        ),
    );
    line(out, &format!("V{name}0 {node}0 0 DC {}", format_time(base)));
    for k in 0..windows {
        let (from, to) = (cuts[k], cuts[k + 1]);
        let minus = format!("{node}{k}");
        let plus = if k + 1 == windows {
            node.to_owned()
        } else {
            format!("{node}{}", k + 1)
        };
        line(out, &format!("V{name}{} {plus} {minus} PWL(", k + 1));
        pairs(
            out,
            points[from..=to]
                .iter()
                .zip(&values[from..=to])
                .map(|(p, &v)| (p.time, v - base)),
        );
    }
    windows
}

/// `+ t v t v ...` continuation lines, closed with `)`.
pub(crate) fn pairs(out: &mut String, values: impl Iterator<Item = (f64, f64)>) {
    let mut current = String::from("+");
    for (t, v) in values {
        let pair = format!(" {} {}", format_time(t), format_time(v));
        if current.len() > 1 && current.len() + pair.len() > LINE_WIDTH - 2 {
            line(out, &current);
            current = String::from("+");
        }
        current.push_str(&pair);
    }
    current.push_str(" )");
    line(out, &current);
}

/// 1/g to 15 significant digits: the resistance a conductance came from
/// (1/(1/1e9) is 9.999999999999999e8), to a part in 1e15.
fn reciprocal(g: f64) -> f64 {
    let r = 1.0 / g;
    format!("{r:.14e}").parse().unwrap_or(r)
}

pub(crate) fn line(out: &mut String, text: &str) {
    out.push_str(text);
    out.push('\n');
}

/// `* ` comment lines, wrapped at word boundaries.
pub(crate) fn comment(out: &mut String, text: &str) {
    let mut current = String::from("*");
    for word in text.split_whitespace() {
        if current.len() > 1 && current.len() + 1 + word.len() > LINE_WIDTH {
            line(out, &current);
            current = String::from("*");
        }
        current.push(' ');
        current.push_str(word);
    }
    line(out, &current);
}

/// A two-level waveform as ramp start events.
struct Ramps {
    starts_closed: bool,
    /// (edge start, s; closing) in time order.
    events: Vec<(f64, bool)>,
    /// s, the duration of every edge.
    edge: f64,
}

/// The edges of a waveform whose corners are all at G_min or G_max and
/// whose transitions all last the same time, or why it is not one.
fn two_level_ramps(points: &[Point], g_min: f64, g_max: f64) -> Result<Ramps, NetlistError> {
    let unsupported = |reason: String| NetlistError::ElementUnsupported {
        element: ContactElement::EventRamp.to_string(),
        reason,
    };
    if let Some(p) = points
        .iter()
        .find(|p| p.conductance != g_min && p.conductance != g_max)
    {
        return Err(unsupported(format!(
            "the conductance at {} s is {} S, neither of its two levels {} S and {} S",
            format_time(p.time),
            format_time(p.conductance),
            format_time(g_min),
            format_time(g_max)
        )));
    }
    let mut events = Vec::new();
    let mut edge: Option<f64> = None;
    for w in points.windows(2) {
        if w[0].conductance == w[1].conductance {
            continue;
        }
        let d = w[1].time - w[0].time;
        match edge {
            None => edge = Some(d),
            Some(e) if (d - e).abs() > 1e-6 * e => {
                return Err(unsupported(format!(
                    "its edges differ in length ({} s at {} s, {} s before)",
                    format_time(d),
                    format_time(w[0].time),
                    format_time(e)
                )));
            }
            Some(_) => {}
        }
        events.push((w[0].time, w[1].conductance == g_max));
    }
    // The differences of f64 times carry rounding noise (1.0001e-4 − 1e-4
    // is 1e-8 only to ~1e-12): 9 significant digits give back the edge time.
    let edge = edge.map_or(1.0, |e| format!("{e:.8e}").parse().unwrap_or(e));
    if edge < EVENT_MIN_SPACING {
        return Err(unsupported(format!(
            "its edges last {} s, below the {} s that d_source resolves",
            format_time(edge),
            format_time(EVENT_MIN_SPACING)
        )));
    }
    if let Some(&(t, _)) = events.first() {
        if t < EVENT_MIN_SPACING {
            return Err(unsupported(format!(
                "an edge starts at {} s, before d_source's first event at {} s",
                format_time(t),
                format_time(EVENT_MIN_SPACING)
            )));
        }
    }
    Ok(Ramps {
        starts_closed: points[0].conductance == g_max && g_max != g_min,
        events,
        edge,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chatter::{ContactState, Interval};
    use crate::waveform::ContactModel;

    const MODEL: ContactModel = ContactModel {
        r_closed: 0.05,
        r_open: 1e9,
        edge_time: 1e-8,
    };

    fn chatter(bounces: usize) -> Waveform {
        let mut ivs = Vec::new();
        let mut t = 1e-4;
        ivs.push(Interval {
            state: ContactState::Open,
            start: 0.0,
            end: t,
        });
        for _ in 0..bounces {
            for (state, d) in [(ContactState::Closed, 2e-5), (ContactState::Open, 1e-5)] {
                ivs.push(Interval {
                    state,
                    start: t,
                    end: t + d,
                });
                t += d;
            }
        }
        ivs.push(Interval {
            state: ContactState::Closed,
            start: t,
            end: t + 1e-4,
        });
        Waveform::from_intervals(&ivs, &MODEL).unwrap()
    }

    #[test]
    fn names_are_checked() {
        for bad in ["", "A B", "1X", "X-1", "Ä", "a.b", "x\t"] {
            let e = check_subckt_name(bad).unwrap_err();
            assert!(e.to_string().contains("X1 a b CONTACT"), "{e}");
        }
        for good in ["CONTACT", "k1_contact", "_c2"] {
            check_subckt_name(good).unwrap();
        }
    }

    #[test]
    fn elements_round_trip_their_names() {
        for e in ContactElement::ALL {
            assert_eq!(e.as_str().parse::<ContactElement>().unwrap(), e);
        }
        assert!("spice".parse::<ContactElement>().is_err());
        assert_eq!(ContactElement::default(), ContactElement::Pwl);
    }

    #[test]
    fn short_pwl_is_one_source_holding_g() {
        let w = chatter(2);
        let inc = contact_include(&w, "CONTACT", ContactElement::Pwl).unwrap();
        assert_eq!(inc.pwl_sources, 1);
        assert_eq!(inc.points, w.points().len());
        assert!(inc.text.contains("\n.subckt CONTACT a b\nVG g 0 PWL(\n"));
        assert!(inc.text.ends_with(".ends CONTACT\n"));
        assert!(inc.text.contains("+ 0e0 1e-9 1e-4 1e-9 1.0001e-4 2e1"));
        assert!(
            inc.text.lines().all(|l| l.len() <= LINE_WIDTH),
            "{}",
            inc.text
        );
    }

    #[test]
    fn split_windows_sum_to_the_waveform() {
        let w = chatter(40);
        let inc = contact_include_split(&w, "CONTACT", ContactElement::Pwl, 16).unwrap();
        assert!(inc.pwl_sources > 5, "{}", inc.pwl_sources);
        // Evaluate the emitted sources the way ngspice does and compare.
        let sources = parse_sources(&inc.text);
        let g = |t: f64| sources.iter().map(|s| pwl_at(s, t)).sum::<f64>();
        for p in w.points() {
            for t in [p.time, p.time + 3e-9, p.time + 5e-6] {
                let (want, got) = (w.conductance_at(t), g(t));
                assert!(
                    (got - want).abs() <= 1e-12 * want.max(1.0),
                    "t = {t:e}: {got:e} vs {want:e}"
                );
                assert!(got > 0.0);
            }
        }
    }

    /// (t, v) lists of every V source in an include; DC sources as one point.
    fn parse_sources(text: &str) -> Vec<Vec<(f64, f64)>> {
        let mut out: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut numbers: Option<Vec<f64>> = None;
        for l in text.lines() {
            if let Some(rest) = l.strip_prefix('+') {
                if let Some(n) = numbers.as_mut() {
                    n.extend(
                        rest.split_whitespace()
                            .filter_map(|x| x.parse::<f64>().ok()),
                    );
                    if rest.trim_end().ends_with(')') {
                        let n = numbers.take().unwrap();
                        out.push(n.chunks(2).map(|c| (c[0], c[1])).collect());
                    }
                }
            } else if l.starts_with('V') && l.ends_with("PWL(") {
                numbers = Some(Vec::new());
            } else if l.starts_with('V') && l.contains(" DC ") {
                let v: f64 = l.rsplit(' ').next().unwrap().parse().unwrap();
                out.push(vec![(0.0, v)]);
            }
        }
        out
    }

    fn pwl_at(p: &[(f64, f64)], t: f64) -> f64 {
        if t <= p[0].0 {
            return p[0].1;
        }
        for w in p.windows(2) {
            if t <= w[1].0 {
                return w[0].1 + (t - w[0].0) / (w[1].0 - w[0].0) * (w[1].1 - w[0].1);
            }
        }
        p[p.len() - 1].1
    }

    #[test]
    fn event_ramp_lists_edge_starts() {
        let w = chatter(1);
        let inc = contact_include(&w, "K1", ContactElement::EventRamp).unwrap();
        let (name, data) = &inc.data_files[0];
        assert_eq!(name, "k1_events.txt");
        let rows: Vec<&str> = data.lines().skip(1).collect();
        let t = |i: usize| format_time(w.points()[i].time);
        let want = [
            "0e0 0s".to_owned(),
            format!("{} 1s", t(1)),
            format!("{} 0s", t(3)),
            format!("{} 1s", t(5)),
        ];
        assert_eq!(rows, want);
        assert!(inc.text.contains("t_rise=1e-8 t_fall=1e-8"), "{}", inc.text);
    }

    #[test]
    fn event_ramp_refuses_other_shapes() {
        let ivs = [Interval {
            state: ContactState::Open,
            start: 0.0,
            end: 1.0,
        }];
        let flat = Waveform::from_intervals(&ivs, &MODEL).unwrap();
        let inc = contact_include(&flat, "C", ContactElement::EventRamp).unwrap();
        assert_eq!(inc.data_files[0].1.lines().count(), 2);
        let ivs = [
            Interval {
                state: ContactState::Open,
                start: 0.0,
                end: 1e-10,
            },
            Interval {
                state: ContactState::Closed,
                start: 1e-10,
                end: 1.0,
            },
        ];
        let at_zero = Waveform::from_intervals(&ivs, &MODEL).unwrap();
        let e = contact_include(&at_zero, "C", ContactElement::EventRamp).unwrap_err();
        assert!(e.to_string().contains("use element `pwl`"), "{e}");
    }

    #[test]
    fn long_two_level_waveforms_get_event_ramps() {
        assert_eq!(
            ContactElement::for_waveform(&chatter(100)),
            ContactElement::Pwl
        );
        assert_eq!(
            ContactElement::for_waveform(&chatter(1000)),
            ContactElement::EventRamp
        );
    }

    #[test]
    fn switch_of_a_constant_contact_is_a_resistor() {
        let ivs = [Interval {
            state: ContactState::Closed,
            start: 0.0,
            end: 1.0,
        }];
        let w = Waveform::from_intervals(&ivs, &MODEL).unwrap();
        let inc = contact_include(&w, "CONTACT", ContactElement::Switch).unwrap();
        assert!(inc.text.contains("\nR1 a b 5e-2\n"), "{}", inc.text);
    }
}
