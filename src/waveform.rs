//! The contact as a time-varying conductance (docs/model.md §5): the chatter
//! sequence becomes a piecewise-linear list of (time, conductance) points
//! that the netlist stage emits as an ngspice `PWL` source.
//!
//! # Quantity and interpolation
//! The points carry the **conductance** G = 1/R (S), not the resistance: a
//! behavioural element `I = V·G` then never divides by a value near zero,
//! and G stays finite at both ends (G_open = 1/R_open > 0).
//!
//! Between points G is interpolated **linearly**, which is exactly what an
//! ngspice PWL source does, so [`Waveform::conductance_at`] is the value the
//! circuit sees, with no extra points. Linear in G is also a plausible
//! edge: by Holm, a single a-spot of radius a conducts G = 2a/ρ, so a make
//! edge is a contact spot growing at a constant rate. (Log-space
//! interpolation, like XSPICE `aswitch`, would need several points per edge
//! to approximate through a PWL, and PWL cost grows with the point count.)
//!
//! # Edge convention
//! Each edge **starts at the event** and lasts `edge_time`: a make edge
//! runs from the impact time t_i (G_open) to t_i + edge_time (G_closed); a
//! break edge from the release time t_r (G_closed) to t_r + edge_time
//! (G_open). The electrical state therefore lags the mechanical one by at
//! most one `edge_time`, and the last edge may end after the sequence's
//! `t_end` (the points then run past it).
//!
//! # Strictly increasing points
//! ngspice misbehaves on non-increasing PWL times, so the intervals are
//! adjusted where they are shorter than the edge resolution:
//! - an **opening** shorter than `2·edge_time` (measured from the start of
//!   the break edge to the next impact) is merged into the closures around
//!   it: a separation that brief is below what the waveform resolves, and
//!   the contact is shown closed across it (counted in `merged_openings`);
//! - a **closure** is never dropped: the contacts did touch, and hiding the
//!   touch would hide the chatter itself (for a rigid surface every bounce
//!   is a zero-length closure). A closure shorter than one `edge_time` is
//!   widened into a triangular pulse: the make edge reaches G_closed and
//!   the break edge starts at once, up to `edge_time` after the recorded
//!   release (counted in `widened_closures`).
//!
//! Leading and trailing intervals are kept whatever their length.
//!
//! # Force-dependent closed resistance (Holm)
//! By default a closed contact has the constant resistance `r_closed`.
//! With a [`Holm`] law (docs/model.md §5) it follows the contact force F: the
//! constriction resistance of the contact spots falls as the force presses
//! them wider, R = R_film + R_ref·(F_ref/F)^m, with m = 1/2 for plastic and
//! 1/3 for elastic spots (Holm, *Electric Contacts*), clamped to `r_open`
//! as F → 0. Each closed plateau is then sampled at [`Holm`]'s step and the
//! PWL follows 1/R(F(t)) through it; the make edge ramps from G_open to the
//! first sample and the break edge from the last. A contact force that
//! drops to zero or below (Kelvin–Voigt pulls just before release) gives
//! R_open at that sample: the spot is gone before the contacts part.

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::chatter::{Chatter, ContactState, Interval};

/// The smallest `edge_time` relative to the largest time in the sequence:
/// 2⁻⁴⁰ ≈ 9.1e-13, so t + edge_time > t always holds in f64 (whose
/// relative spacing is 2⁻⁵²) with room for the sums the edges need.
const MIN_EDGE_RELATIVE: f64 = 9.094_947_017_729_282e-13;

/// Errors of this stage. Contact parameters name their scenario key; CSV
/// problems name the file and line.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum WaveformError {
    /// A contact parameter is out of its range or not finite.
    #[error("`{key}` = {value:?} {requirement}")]
    InvalidContact {
        /// The scenario key, e.g. `contact.r_closed`.
        key: &'static str,
        /// The value given, in the key's unit (Ω, s, N, ...).
        value: f64,
        /// What the value must satisfy.
        requirement: String,
    },
    /// `edge_time` is too small for the waveform's times to resolve
    /// (below about 9.1e-13 of the largest time).
    #[error(
        "the waveform runs to {t_end:?} s (`simulation.t_end`), so long that its times cannot \
         resolve edges of `contact.edge_time` = {edge_time:?} s: lower `simulation.t_end` to \
         what the circuit needs (a relay's chatter is over in milliseconds), or raise \
         `contact.edge_time` to at least {minimum:e} s"
    )]
    EdgeBelowResolution {
        /// s, `contact.edge_time`.
        edge_time: f64,
        /// s, the end of the sequence.
        t_end: f64,
        /// s, the smallest edge time it resolves.
        minimum: f64,
    },
    /// The sequence of states is empty.
    #[error("the state sequence has no intervals: give at least one")]
    NoIntervals,
    /// An interval is not finite, ends before it starts, or does not
    /// start where the one before it ends.
    #[error("interval {index} ({start:?} s to {end:?} s) {problem}")]
    BadInterval {
        /// The 0-based index of the interval.
        index: usize,
        /// s
        start: f64,
        /// s
        end: f64,
        /// What is wrong with it.
        problem: &'static str,
    },
    /// A state CSV's first non-blank line is not `time,state`.
    #[error("{}: line {line}: the header must be `time,state`, found `{found}`: add that header as the first line", path.display())]
    CsvHeader {
        /// The CSV file.
        path: PathBuf,
        /// 1-based line of the header.
        line: usize,
        /// The line found instead.
        found: String,
    },
    /// A state CSV has a header and no rows.
    #[error("{}: no state rows after the header: add at least one `time,state` row", path.display())]
    CsvEmpty {
        /// The CSV file.
        path: PathBuf,
    },
    /// A row of a state CSV cannot be read.
    #[error("{}: line {line}: {problem}", path.display())]
    CsvRow {
        /// The CSV file.
        path: PathBuf,
        /// 1-based line of the row.
        line: usize,
        /// What is wrong with it.
        problem: CsvProblem,
    },
}

/// What is wrong with one row of a state-change CSV.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CsvProblem {
    /// The row does not have two fields.
    #[error("expected 2 fields `time,state`, found {found}")]
    FieldCount {
        /// The number of fields found.
        found: usize,
    },
    /// The time is not a number.
    #[error("time `{text}` is not a number: write seconds, e.g. 1.5e-3")]
    BadTime {
        /// The time field, as written.
        text: String,
    },
    /// The time is NaN or infinite.
    #[error("time `{text}` is not finite: write seconds, e.g. 1.5e-3")]
    NonFiniteTime {
        /// The time field, as written.
        text: String,
    },
    /// The time is below 0.
    #[error("time {time:?} s is negative: shift the record so that it starts at t >= 0")]
    NegativeTime {
        /// s
        time: f64,
    },
    /// The time is not after the previous row's.
    #[error(
        "time {time:?} s does not follow the previous row's {previous:?} s: \
         rows must be in strictly increasing time"
    )]
    NonIncreasingTime {
        /// s, this row's time.
        time: f64,
        /// s, the previous row's time.
        previous: f64,
    },
    /// The state is none of `open`, `closed`, `0`, `1`.
    #[error("state `{text}` is not one of `open`, `closed`, `0` (open), `1` (closed)")]
    UnknownState {
        /// The state field, as written.
        text: String,
    },
}

/// The contact as a resistor (`[contact]` of the scenario). SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactModel {
    /// Ω, > 0.
    pub r_closed: f64,
    /// Ω, > r_closed and finite.
    pub r_open: f64,
    /// s, duration of each make or break edge, > 0.
    pub edge_time: f64,
}

/// A finite `value` for which `ok` holds, or the error naming `key`.
fn check(
    key: &'static str,
    value: f64,
    ok: bool,
    requirement: impl Into<String>,
) -> Result<(), WaveformError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(WaveformError::InvalidContact {
            key,
            value,
            requirement: requirement.into(),
        })
    }
}

impl ContactModel {
    /// Check every parameter; the error names its scenario key.
    pub fn validate(&self) -> Result<(), WaveformError> {
        check(
            "contact.r_closed",
            self.r_closed,
            self.r_closed > 0.0,
            "must be a finite value > 0: the closed contact resistance, in Ω",
        )?;
        check(
            "contact.r_open",
            self.r_open,
            self.r_open > self.r_closed,
            format!(
                "must be finite and exceed `contact.r_closed` = {:?} Ω: the open contact \
                 resistance, in Ω",
                self.r_closed
            ),
        )?;
        check(
            "contact.edge_time",
            self.edge_time,
            self.edge_time > 0.0,
            "must be a finite value > 0: the duration of each make or break edge, in s",
        )
    }

    /// S
    pub fn g_closed(&self) -> f64 {
        1.0 / self.r_closed
    }

    /// S
    pub fn g_open(&self) -> f64 {
        1.0 / self.r_open
    }
}

/// The force-dependent closed resistance R(F) = r_film + r_ref·(f_ref/F)^m
/// (`[contact.holm]` of the scenario). SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Holm {
    /// Ω, ≥ 0: the film (and bulk) resistance that no force removes.
    pub r_film: f64,
    /// Ω, > 0: the constriction resistance at `f_ref`.
    pub r_ref: f64,
    /// N, > 0.
    pub f_ref: f64,
    /// m, in (0, 1]: 1/2 for plastic contact spots, 1/3 for elastic.
    pub exponent: f64,
}

impl Holm {
    /// Check every parameter; the error names its scenario key.
    pub fn validate(&self) -> Result<(), WaveformError> {
        check(
            "contact.holm.r_film",
            self.r_film,
            self.r_film >= 0.0,
            "must be a finite value >= 0: the film resistance, in Ω",
        )?;
        check(
            "contact.holm.r_ref",
            self.r_ref,
            self.r_ref > 0.0,
            "must be a finite value > 0: the constriction resistance at `f_ref`, in Ω",
        )?;
        check(
            "contact.holm.f_ref",
            self.f_ref,
            self.f_ref > 0.0,
            "must be a finite value > 0: the force at which the constriction is `r_ref`, in N",
        )?;
        check(
            "contact.holm.exponent",
            self.exponent,
            self.exponent > 0.0 && self.exponent <= 1.0,
            "must be in (0, 1]: 0.5 for plastic contact spots, 1/3 for elastic",
        )
    }

    /// Ω at contact force `force` (N), at most `r_open`; `r_open` when the
    /// force is zero or pulls.
    pub fn resistance(&self, force: f64, r_open: f64) -> f64 {
        if force > 0.0 {
            (self.r_film + self.r_ref * (self.f_ref / force).powf(self.exponent)).min(r_open)
        } else {
            r_open
        }
    }
}

/// Plateau samples a Holm waveform takes per closure at most; a longer
/// closure (the final one, usually) is sampled over its start, where the
/// force still rings, and interpolated to its end, where it has settled.
pub const HOLM_MAX_SAMPLES: usize = 256;

/// Plateau samples per bounce closure: enough to follow a contact force
/// that rises and falls once per closure.
pub const HOLM_SAMPLES_PER_CLOSURE: usize = 16;

/// The closed conductance as the Holm law gives it from the force.
struct ForceLaw<'a> {
    holm: &'a Holm,
    /// N at each of the given times (s, increasing).
    forces: &'a mut dyn FnMut(&[f64]) -> Vec<f64>,
}

/// One corner of the piecewise-linear conductance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// s
    pub time: f64,
    /// S
    pub conductance: f64,
}

/// The contact conductance over time: strictly increasing points,
/// interpolated linearly (see the module overview for the conventions).
#[derive(Debug, Clone, PartialEq)]
pub struct Waveform {
    points: Vec<Point>,
    make_edges: usize,
    break_edges: usize,
    merged_openings: usize,
    widened_closures: usize,
}

/// A closed span after merging, with what it needs to emit its edges.
#[derive(Debug, Clone, Copy)]
struct Span {
    /// s, the impact (or the start of the record when closed from it).
    make: f64,
    /// s, the recorded release (or the end of the record).
    release: f64,
    /// Closed from the start of the record: no make edge.
    from_start: bool,
}

impl Span {
    /// s, when the break edge starts: the release, or one edge after the
    /// make when the closure is shorter than an edge.
    fn break_start(&self, edge: f64) -> f64 {
        if self.from_start {
            self.release
        } else {
            self.release.max(self.make + edge)
        }
    }
}

impl Waveform {
    /// The conductance of an engine result.
    pub fn from_chatter(
        chatter: &Chatter,
        model: &ContactModel,
    ) -> Result<Waveform, WaveformError> {
        Waveform::from_intervals(&chatter.intervals, model)
    }

    /// The conductance of an engine result with the force-dependent
    /// closed resistance of `holm`. `forces` gives the contact force (N)
    /// at increasing times (s) within the closures, e.g.
    /// [`mechanics::contact_forces`](crate::mechanics::contact_forces).
    pub fn from_chatter_holm(
        chatter: &Chatter,
        model: &ContactModel,
        holm: &Holm,
        mut forces: impl FnMut(&[f64]) -> Vec<f64>,
    ) -> Result<Waveform, WaveformError> {
        holm.validate()?;
        let mut law = ForceLaw {
            holm,
            forces: &mut forces,
        };
        Waveform::build(&chatter.intervals, model, Some(&mut law))
    }

    /// The conductance of a measured state-change CSV (see
    /// [`read_state_csv`]); `origin` names the file in errors.
    pub fn from_state_changes(
        text: &str,
        origin: &Path,
        model: &ContactModel,
    ) -> Result<Waveform, WaveformError> {
        Waveform::from_intervals(&read_state_csv(text, origin)?, model)
    }

    /// The conductance of intervals that tile [start of the first, end of
    /// the last] in order, each with `start <= end`.
    pub fn from_intervals(
        intervals: &[Interval],
        model: &ContactModel,
    ) -> Result<Waveform, WaveformError> {
        Waveform::build(intervals, model, None)
    }

    fn build(
        intervals: &[Interval],
        model: &ContactModel,
        law: Option<&mut ForceLaw>,
    ) -> Result<Waveform, WaveformError> {
        model.validate()?;
        check_tiling(intervals)?;
        let first = intervals[0];
        let last = intervals[intervals.len() - 1];
        let (t0, t_end) = (first.start, last.end);
        let edge = model.edge_time;
        let minimum = t0.abs().max(t_end.abs()) * MIN_EDGE_RELATIVE;
        if edge < minimum {
            return Err(WaveformError::EdgeBelowResolution {
                edge_time: edge,
                t_end,
                minimum,
            });
        }

        let mut merged_openings = 0;
        let mut spans: Vec<Span> = Vec::new();
        let mut in_closed = false;
        for iv in intervals {
            match iv.state {
                ContactState::Open => in_closed = false,
                ContactState::Closed if in_closed => {
                    // Consecutive closed intervals are one closure.
                    let span = spans.last_mut().expect("in_closed implies a span");
                    span.release = iv.end;
                }
                ContactState::Closed => {
                    in_closed = true;
                    if let Some(prev) = spans.last_mut() {
                        let r = prev.break_start(edge);
                        // Both forms: the difference for the documented
                        // rule, the sum for what the emitted points hold.
                        if iv.start - r < 2.0 * edge || r + 2.0 * edge > iv.start {
                            merged_openings += 1;
                            prev.release = prev.release.max(iv.end);
                            continue;
                        }
                    }
                    spans.push(Span {
                        make: iv.start,
                        release: iv.end,
                        from_start: iv.start == t0,
                    });
                }
            }
        }
        let ends_closed = last.state == ContactState::Closed;

        let (g_open, g_closed) = (model.g_open(), model.g_closed());
        let n = spans.len();
        // Each span's closed plateau, (start, end): after the make edge (or
        // from the start of the record) to the start of the break edge (or
        // the end of the record). A widened touch has start == end.
        let plateaus: Vec<(f64, f64)> = spans
            .iter()
            .enumerate()
            .map(|(i, span)| {
                let start = if span.from_start {
                    t0
                } else {
                    span.make + edge
                };
                let end = if i + 1 == n && ends_closed {
                    t_end.max(start)
                } else {
                    span.break_start(edge)
                };
                (start, end)
            })
            .collect();
        // The closed conductance at each plateau's corners: constant, or
        // sampled from the force.
        let samples: Vec<Vec<(f64, f64)>> = match law {
            None => plateaus
                .iter()
                .map(|&(a, b)| {
                    if b > a {
                        vec![(a, g_closed), (b, g_closed)]
                    } else {
                        vec![(a, g_closed)]
                    }
                })
                .collect(),
            Some(law) => holm_samples(&plateaus, n > 0 && ends_closed, law, model.r_open),
        };

        let mut w = Waveform {
            points: Vec::with_capacity(samples.iter().map(Vec::len).sum::<usize>() + 2 * n + 2),
            make_edges: 0,
            break_edges: 0,
            merged_openings,
            widened_closures: 0,
        };
        let starts_closed = spans.first().is_some_and(|s| s.from_start);
        if !starts_closed {
            w.push(t0, g_open);
        }
        let mut g_end = g_open;
        for (i, (span, corners)) in spans.iter().zip(&samples).enumerate() {
            if !span.from_start {
                w.push(span.make, g_open);
                w.make_edges += 1;
            }
            for &(t, g) in corners {
                w.push(t, g);
            }
            if i + 1 == n && ends_closed {
                g_end = corners.last().map_or(g_closed, |&(_, g)| g);
                break;
            }
            let b = span.break_start(edge);
            if b > span.release {
                w.widened_closures += 1;
            }
            w.push(b + edge, g_open);
            w.break_edges += 1;
        }
        if t_end > w.points[w.points.len() - 1].time {
            w.push(t_end, g_end);
        }
        Ok(w)
    }

    /// Append a corner. An exact repeat of the previous corner (a plateau
    /// of zero length) is skipped; the merging rules make every other
    /// time strictly later than the previous one.
    fn push(&mut self, time: f64, conductance: f64) {
        if let Some(p) = self.points.last() {
            if p.time == time && p.conductance == conductance {
                return;
            }
            debug_assert!(
                time > p.time,
                "waveform point {time:e} s does not follow {:e} s",
                p.time
            );
        }
        self.points.push(Point { time, conductance });
    }

    /// The corners, in strictly increasing time.
    pub fn points(&self) -> &[Point] {
        &self.points
    }

    /// Make plus break edges emitted.
    pub fn edge_count(&self) -> usize {
        self.make_edges + self.break_edges
    }

    /// Make edges emitted (open to closed).
    pub fn make_edges(&self) -> usize {
        self.make_edges
    }

    /// Break edges emitted (closed to open).
    pub fn break_edges(&self) -> usize {
        self.break_edges
    }

    /// Openings shorter than `2·edge_time` shown as closed.
    pub fn merged_openings(&self) -> usize {
        self.merged_openings
    }

    /// Closures shorter than `edge_time` widened to a one-edge pulse.
    pub fn widened_closures(&self) -> usize {
        self.widened_closures
    }

    /// S, the conductance at `time` (s), linear between corners and held
    /// constant before the first and after the last.
    pub fn conductance_at(&self, time: f64) -> f64 {
        let p = &self.points;
        let i = p.partition_point(|q| q.time <= time);
        if i == 0 {
            return p[0].conductance;
        }
        if i == p.len() {
            return p[i - 1].conductance;
        }
        let (a, b) = (p[i - 1], p[i]);
        let s = (time - a.time) / (b.time - a.time);
        a.conductance + s * (b.conductance - a.conductance)
    }

    /// Ω, 1 / [`Waveform::conductance_at`].
    pub fn resistance_at(&self, time: f64) -> f64 {
        1.0 / self.conductance_at(time)
    }

    /// The corners as a PWL body, `t1 g1 t2 g2 ...`, with
    /// [`format_time`] for both numbers: deterministic, and distinct times
    /// always print distinctly.
    pub fn pwl_body(&self) -> String {
        let mut out = String::new();
        for (i, p) in self.points.iter().enumerate() {
            if i > 0 {
                out.push(' ');
            }
            out.push_str(&format_time(p.time));
            out.push(' ');
            out.push_str(&format_time(p.conductance));
        }
        out
    }
}

/// The Holm conductance at sample times across each plateau. The step is
/// a [`HOLM_SAMPLES_PER_CLOSURE`]th of the shortest bounce closure (or a
/// [`HOLM_MAX_SAMPLES`]th of the only closure), and no plateau takes more
/// than [`HOLM_MAX_SAMPLES`] samples: past them the last sample is the
/// plateau's end. `final_closed`: the last plateau runs to the end of the
/// record rather than to a break.
fn holm_samples(
    plateaus: &[(f64, f64)],
    final_closed: bool,
    law: &mut ForceLaw,
    r_open: f64,
) -> Vec<Vec<(f64, f64)>> {
    let bounces = if final_closed {
        &plateaus[..plateaus.len().saturating_sub(1)]
    } else {
        plateaus
    };
    let shortest = bounces
        .iter()
        .map(|(a, b)| b - a)
        .filter(|&d| d > 0.0)
        .fold(f64::INFINITY, f64::min);
    let step = if shortest.is_finite() {
        shortest / HOLM_SAMPLES_PER_CLOSURE as f64
    } else {
        plateaus
            .last()
            .map_or(0.0, |(a, b)| (b - a) / HOLM_MAX_SAMPLES as f64)
    };
    let times: Vec<Vec<f64>> = plateaus
        .iter()
        .map(|&(a, b)| {
            let mut ts = vec![a];
            if b > a && step > 0.0 {
                let k = (((b - a) / step).ceil() as usize).clamp(1, HOLM_MAX_SAMPLES - 1);
                ts.extend((1..k).map(|j| a + j as f64 * step).filter(|&t| t < b));
                ts.push(b);
            }
            ts
        })
        .collect();
    let all: Vec<f64> = times.iter().flatten().copied().collect();
    let forces = (law.forces)(&all);
    let mut forces = forces.into_iter();
    times
        .into_iter()
        .map(|ts| {
            ts.into_iter()
                .map(|t| {
                    let f = forces.next().unwrap_or(0.0);
                    (t, 1.0 / law.holm.resistance(f, r_open))
                })
                .collect()
        })
        .collect()
}

/// A number in the shortest form that reads back to the same f64
/// (`{:e}`, e.g. `1.5e-3`, `0e0`): two distinct times never print the
/// same, and the output does not depend on the platform. ngspice reads
/// this form.
pub fn format_time(t: f64) -> String {
    format!("{t:e}")
}

fn check_tiling(intervals: &[Interval]) -> Result<(), WaveformError> {
    if intervals.is_empty() {
        return Err(WaveformError::NoIntervals);
    }
    let mut previous_end = None;
    for (index, iv) in intervals.iter().enumerate() {
        let bad = |problem| {
            Err(WaveformError::BadInterval {
                index,
                start: iv.start,
                end: iv.end,
                problem,
            })
        };
        if !(iv.start.is_finite() && iv.end.is_finite()) {
            return bad("is not finite");
        }
        if iv.end < iv.start {
            return bad("ends before it starts");
        }
        if previous_end.is_some_and(|e| e != iv.start) {
            return bad("does not start where the previous interval ends");
        }
        previous_end = Some(iv.end);
    }
    Ok(())
}

/// Read a measured chatter sequence: a CSV with the header `time,state`
/// and one row per state change, `state` being `open`, `closed`, `0`
/// (open) or `1` (closed), case-insensitive; times in s, ≥ 0 and strictly
/// increasing. Blank lines are skipped.
///
/// Each row says "from this time on, the contact is in this state"; the
/// record ends at the last row's time, so a file ends with a row that
/// repeats the final state at the end of the record (a final row that
/// changes the state gives a zero-length final interval: the state entered
/// at the very end). Rows that repeat the state are merged. `origin` names
/// the file in errors.
pub fn read_state_csv(text: &str, origin: &Path) -> Result<Vec<Interval>, WaveformError> {
    let row_err = |line, problem| WaveformError::CsvRow {
        path: origin.to_path_buf(),
        line,
        problem,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.trim()))
        .filter(|(_, l)| !l.is_empty());
    let Some((header_line, header)) = lines.next() else {
        return Err(WaveformError::CsvEmpty {
            path: origin.to_path_buf(),
        });
    };
    let fields: Vec<String> = header
        .split(',')
        .map(|f| f.trim().to_ascii_lowercase())
        .collect();
    if fields != ["time", "state"] {
        return Err(WaveformError::CsvHeader {
            path: origin.to_path_buf(),
            line: header_line,
            found: header.to_owned(),
        });
    }

    let mut rows: Vec<(f64, ContactState)> = Vec::new();
    for (line, row) in lines {
        let fields: Vec<&str> = row.split(',').map(str::trim).collect();
        if fields.len() != 2 {
            return Err(row_err(
                line,
                CsvProblem::FieldCount {
                    found: fields.len(),
                },
            ));
        }
        let text = fields[0];
        let time: f64 = text.parse().map_err(|_| {
            row_err(
                line,
                CsvProblem::BadTime {
                    text: text.to_owned(),
                },
            )
        })?;
        if !time.is_finite() {
            return Err(row_err(
                line,
                CsvProblem::NonFiniteTime {
                    text: text.to_owned(),
                },
            ));
        }
        if time < 0.0 {
            return Err(row_err(line, CsvProblem::NegativeTime { time }));
        }
        // No let chains: the crate's rust-version is 1.85.
        if let Some(&(previous, _)) = rows.last() {
            if time <= previous {
                return Err(row_err(
                    line,
                    CsvProblem::NonIncreasingTime { time, previous },
                ));
            }
        }
        let state = match fields[1].to_ascii_lowercase().as_str() {
            "open" | "0" => ContactState::Open,
            "closed" | "1" => ContactState::Closed,
            _ => {
                return Err(row_err(
                    line,
                    CsvProblem::UnknownState {
                        text: fields[1].to_owned(),
                    },
                ));
            }
        };
        rows.push((time, state));
    }
    if rows.is_empty() {
        return Err(WaveformError::CsvEmpty {
            path: origin.to_path_buf(),
        });
    }

    let mut intervals: Vec<Interval> = Vec::new();
    for &(time, state) in &rows {
        if let Some(iv) = intervals.last_mut() {
            iv.end = time;
            if iv.state == state {
                continue;
            }
        }
        intervals.push(Interval {
            state,
            start: time,
            end: time,
        });
    }
    Ok(intervals)
}

#[cfg(test)]
#[path = "waveform_tests.rs"]
mod tests;
