//! Analysis: what the probed signals did while the contact bounced.
//!
//! The stage between the raw file and the reports. Everything here is a
//! pure function of sampled waveforms: `time` (s, the transient plot's
//! scale) and `values` (V or A) of one vector.
//!
//! # Samples and interpolation
//! ngspice writes its accepted time points, whose spacing its truncation
//! error control adapts to the circuit. Nothing is known between two
//! points, so a threshold crossing is located by **linear interpolation**
//! between the two samples that bracket it, and integrals use the
//! trapezoid rule over the same straight lines. That is the best the data
//! allows; the error of a crossing is about Δt²·|v''| / (8·|v'|) for a
//! sample spacing Δt, and nil where the simulator kept the signal linear
//! (e.g. on a PWL ramp between breakpoints). Repeated instants (a step
//! stored as two points at one time) are accepted: nothing divides by a
//! time step.
//!
//! # Schmitt edges (docs/output.md)
//! A probe has two thresholds `low < high`. The level is **high** once the
//! signal reaches `high` (v ≥ high) and stays so until it reaches `low`
//! (v ≤ low), and the other way round: noise around one threshold does not
//! toggle it. An *edge* is a change of level; its time is the
//! interpolated crossing of the threshold that caused it.
//!
//! The level at the first sample is high (v ≥ high), low (v ≤ low) or
//! [`Level::Undetermined`] in between. An undetermined level becomes
//! defined when the signal first reaches a threshold, and that first
//! reach is **not** an edge: the input had no defined level before, so
//! nothing changed for a logic input reading it. A start at a rail (the
//! normal case: a pulled-up input at supply) is a defined level.
//!
//! `glitches` = edges − 1 when there is at least one edge, else 0: the
//! edges beyond the one a clean switch would give.
//!
//! # Currents
//! For a current probe (`i(v1)`, `@r1[i]`, or a vector the raw file types
//! as `current`) the analysis adds the peak |i| and the charge ∫ i dt,
//! over the whole record and per closure of the contact (the closed
//! intervals of the chatter sequence, see [`closures`]).
//!
//! # Integration overshoot at a contact's edge
//! A contact switches its conductance by ten decades within one edge
//! time, and a capacitor across it (or an inductor in series) then has a
//! time constant far shorter than ngspice's steps. The trapezoidal rule,
//! ngspice's default, is not damped there: in one step its solution goes
//! past where the signal is going, and it may alternate up and down from
//! one time point to the next while it decays, for instance to −157 mV on
//! an input that discharges from 3.3 V to 16 µV. Such samples are the
//! integrator's, not the circuit's. After each contact edge (the starts
//! and ends of the closures given), [`integration_ringing`] looks, within
//! [`RINGING_LOOKAHEAD`] samples of the edge, for at least
//! [`RINGING_EXTREMA`] local extrema in a row, one per sample, swinging
//! less and less: samples that alternate about a smooth curve. Those
//! samples, and the samples that then move monotonically back to the next
//! reversal or the next edge, are listed in [`ProbeAnalysis::ringing`],
//! and the range without them is [`ProbeAnalysis::min_without_ringing`]
//! and [`ProbeAnalysis::max_without_ringing`]. Nothing else is ever left
//! out: a peak that rises in one step and falls smoothly (the inrush of a
//! capacitor through a small resistance) is the circuit's, and so is a
//! physical oscillation, which ngspice resolves with several points per
//! period and which never alternates point to point. `min` and `max` are
//! always the extremes of every sample, and the limits hold them unless
//! the probe sets `ignore_ringing = true`. Edges and currents use every
//! sample.
//!
//! # Comparison with an ideal contact
//! [`compare`] sets a probe's analysis beside the same circuit's with a
//! single clean make at the first impact and reports what the bounce
//! added. Every difference is *bounced − ideal*.

use std::borrow::Cow;

use serde::Serialize;
use thiserror::Error;

use crate::chatter::{Chatter, ContactState};
use crate::rawfile::{Plot, Vector};
use crate::scenario::Probe;

/// Why a signal could not be analysed.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum AnalysisError {
    /// The probed signal is neither a vector of the plot nor a `v(a,b)`
    /// of two node voltages it holds.
    #[error(
        "`{signal}` is not a vector of the plot \"{plot}\"; change the probe's `signal` to one of: {}",
        available.join(", ")
    )]
    MissingSignal {
        /// The probe's signal, as written.
        signal: String,
        /// The plot's name (its `Plotname:`).
        plot: String,
        /// The plot's vector names, sorted.
        available: Vec<String>,
    },
    #[error(
        "`{signal}` in the plot \"{plot}\" is complex; edges need a transient analysis (`.tran`)"
    )]
    /// The signal's vector holds complex values (an AC or noise plot).
    ComplexSignal {
        /// The probe's signal, as written.
        signal: String,
        /// The plot's name.
        plot: String,
    },
    #[error(
        "the plot \"{plot}\" has {} as its scale, not time; analyse the transient plot (`.tran`)",
        scale.as_deref().map_or_else(|| "no vector".to_owned(), |s| format!("`{s}`"))
    )]
    /// The plot's scale (its first vector) is not a real `time` vector.
    NotTransient {
        /// The plot's name.
        plot: String,
        /// The name of the plot's scale vector; `None` if it has no vectors.
        scale: Option<String>,
    },
    /// The signal has no samples.
    #[error("`{signal}` has no samples; the simulation wrote no points")]
    Empty {
        /// The signal's name.
        signal: String,
    },
    #[error(
        "`{signal}` has {values} samples but time has {time}; \
         the raw file's vectors must have one value per time point"
    )]
    /// The signal and the time scale have different numbers of samples.
    LengthMismatch {
        /// The signal's name.
        signal: String,
        /// The number of time samples.
        time: usize,
        /// The number of signal samples.
        values: usize,
    },
    #[error(
        "`{signal}` is {value} at t = {time:e} s (sample {index}); \
         the simulation diverged there, check the circuit and the ngspice log"
    )]
    /// A sample of the signal, or of time (then `signal` is `"time"`), is
    /// NaN or infinite.
    NotFinite {
        /// The signal's name, or `"time"`.
        signal: String,
        /// The 0-based index of the sample.
        index: usize,
        /// s; NaN itself when the time is what is not finite.
        time: f64,
        /// The sample that is not finite, in the signal's unit.
        value: f64,
    },
    #[error(
        "time goes back from {previous:e} s to {time:e} s at sample {index}; \
         the scale must not decrease (is this the transient plot?)"
    )]
    /// A time sample is smaller than the one before it.
    TimeGoesBack {
        /// The 0-based index of the sample.
        index: usize,
        /// s, the sample before.
        previous: f64,
        /// s, the sample at `index`.
        time: f64,
    },
    #[error(
        "probe `{signal}`: thresholds low = {low} and high = {high} need low < high, both finite; \
         change the probe's `low`/`high`"
    )]
    /// The probe's thresholds are not finite with `low < high`.
    Thresholds {
        /// The probe's signal.
        signal: String,
        /// The `low` threshold, in the signal's unit.
        low: f64,
        /// The `high` threshold, in the signal's unit.
        high: f64,
    },
    #[error(
        "closure {index} of `{signal}` runs from {start:e} s to {end:e} s; \
         a closure needs finite start <= end"
    )]
    /// A closure window is not finite or ends before it starts.
    BadClosure {
        /// The current probe's signal.
        signal: String,
        /// The 0-based index of the closure.
        index: usize,
        /// s
        start: f64,
        /// s
        end: f64,
    },
    #[error(
        "closure {index} ({start:e} s to {end:e} s) lies outside the record of `{signal}` \
         ({record_start:e} s to {record_end:e} s); simulate up to the sequence's end"
    )]
    /// A closure window lies wholly before or after the simulated record.
    ClosureOutsideRecord {
        /// The current probe's signal.
        signal: String,
        /// The 0-based index of the closure.
        index: usize,
        /// s
        start: f64,
        /// s
        end: f64,
        /// s, the first time sample.
        record_start: f64,
        /// s, the last time sample.
        record_end: f64,
    },
    #[error(
        "cannot compare `{bounced}` with `{ideal}`: the ideal run must analyse the same signal \
         with the same thresholds"
    )]
    /// [`compare`] was given analyses of different signals or thresholds.
    NotComparable {
        /// The bounced run's signal.
        bounced: String,
        /// The ideal run's signal.
        ideal: String,
    },
}

/// What a probed vector measures, deciding units and the current analysis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ProbeKind {
    /// V
    Voltage,
    /// A
    Current,
    /// Anything else (a behavioural quantity, a power...): unit unknown.
    Other,
}

impl ProbeKind {
    /// Classify a signal by its name, the way ngspice spells vectors:
    /// `v(...)` is a voltage, `i(...)` and a device's `@dev[i]` a current.
    /// Otherwise the raw file's type field (`raw_type`, e.g. `"current"`
    /// for `v1#branch`) decides, when known.
    pub fn classify(signal: &str, raw_type: Option<&str>) -> ProbeKind {
        let name = signal.trim().to_ascii_lowercase();
        let call = |f: &str| name.starts_with(f) && name.ends_with(')');
        if call("v(") {
            return ProbeKind::Voltage;
        }
        if call("i(") || (name.starts_with('@') && name.ends_with("[i]")) {
            return ProbeKind::Current;
        }
        match raw_type.map(str::to_ascii_lowercase).as_deref() {
            Some("voltage") => ProbeKind::Voltage,
            Some("current") => ProbeKind::Current,
            _ => ProbeKind::Other,
        }
    }

    /// The SI unit symbol, empty for [`ProbeKind::Other`].
    pub fn unit(self) -> &'static str {
        match self {
            ProbeKind::Voltage => "V",
            ProbeKind::Current => "A",
            ProbeKind::Other => "",
        }
    }
}

/// The Schmitt level of a signal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Level {
    /// The signal last reached `low` (v ≤ low), not `high` since.
    Low,
    /// The signal last reached `high` (v ≥ high), not `low` since.
    High,
    /// Between the thresholds and neither reached yet.
    Undetermined,
}

/// Which way an edge goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Low to high: the signal crossed `high` going up.
    Rising,
    /// High to low: the signal crossed `low` going down.
    Falling,
}

/// One Schmitt transition.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Edge {
    /// s, the interpolated crossing of the threshold.
    pub time: f64,
    /// Rising (crossed `high`) or falling (crossed `low`).
    pub direction: Direction,
    /// s, time to the next edge: the width of the pulse this edge starts.
    /// `None` for the last edge, whose level lasts to the end of the record.
    pub width: Option<f64>,
}

/// The Schmitt trigger's view of a signal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Schmitt {
    /// Level at the first sample.
    pub initial_state: Level,
    /// Level at the last sample.
    pub final_state: Level,
    /// In time order, alternating in direction.
    pub edges: Vec<Edge>,
}

/// The current of one closure of the contact.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ClosureCurrent {
    /// s, the closure's window as given, clipped to the record.
    pub start: f64,
    /// s
    pub end: f64,
    /// A, the largest |i| in the window (≥ 0).
    pub peak: f64,
    /// s, when `peak` occurs (the earliest such instant).
    pub peak_time: f64,
    /// C, ∫ i dt over the window (signed, like the current).
    pub charge: f64,
}

/// Peak and charge of a current probe.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurrentAnalysis {
    /// A, the largest |i| of the whole record (≥ 0).
    pub peak: f64,
    /// s, when `peak` occurs.
    pub peak_time: f64,
    /// C, ∫ i dt over the whole record.
    pub charge: f64,
    /// C, the sum of the closures' charges.
    pub closed_charge: f64,
    /// One entry per closure given, in the order given.
    pub per_closure: Vec<ClosureCurrent>,
}

/// Everything the analysis says about one probe. The first seven fields
/// are the contract of docs/output.md, in its order; absent values are
/// `null` in JSON, never omitted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbeAnalysis {
    /// The probe's signal, as written in the scenario.
    pub signal: String,
    /// Number of Schmitt edges.
    pub edges: usize,
    /// edges − 1 when edges ≥ 1, else 0.
    pub glitches: usize,
    /// s, time of the first edge.
    pub first_edge: Option<f64>,
    /// s, time of the last edge: where the signal settled.
    pub last_edge: Option<f64>,
    /// Smallest sample (V, A, ...): every sample, the integrator's
    /// ringing after a contact edge included.
    pub min: f64,
    /// Largest sample, every sample included.
    pub max: f64,
    /// The smallest sample without the integrator's ringing after contact
    /// edges (see the module overview), when that differs from `min`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_without_ringing: Option<f64>,
    /// The largest sample without the integrator's ringing, when that
    /// differs from `max`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_without_ringing: Option<f64>,
    /// Voltage, current or other: decides the unit and the current analysis.
    pub kind: ProbeKind,
    /// The `low` threshold used, in the signal's unit.
    pub low: f64,
    /// The `high` threshold used, in the signal's unit.
    pub high: f64,
    /// Schmitt level at the first sample.
    pub initial_state: Level,
    /// Schmitt level at the last sample.
    pub final_state: Level,
    /// The last sample.
    pub final_value: f64,
    /// s, the shortest time between two consecutive edges (the shortest
    /// glitch); `None` with fewer than two edges.
    pub shortest_pulse: Option<f64>,
    /// Every edge, in time order.
    pub transitions: Vec<Edge>,
    /// For a current probe: peak and charge; `None` otherwise.
    pub current: Option<CurrentAnalysis>,
    /// For a current probe: the pulses, each a departure from the
    /// starting level (and usually its return: two edges). `glitches` of a
    /// current counts the pulses after the first. `None` for a voltage.
    pub pulses: Option<usize>,
    /// What a debouncer of this signal must cover; `None` without an edge.
    pub debounce: Option<Debounce>,
    /// The integration ringing found after contact edges, whose samples
    /// `min` and `max` leave out (see the module overview); empty when
    /// there is none. Not part of the JSON contract: a run reports it as
    /// a warning ([`ProbeAnalysis::threshold_warning`]).
    #[serde(skip)]
    pub ringing: Vec<Ringing>,
}

/// Samples of a probe right after a contact edge that the integrator,
/// not the circuit, put there: an overshoot past where the signal was
/// going, or the trapezoidal rule's ringing (up and down from one time
/// point to the next), and the recovery from it. They are left out of
/// the probe's `min` and `max`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ringing {
    /// s, the contact edge (a closure's start or end) it follows.
    pub edge: f64,
    /// s, the first sample left out: the first overshoot.
    pub start: f64,
    /// s, the last sample left out: the end of the recovery.
    pub end: f64,
    /// How many samples overshoot (one per local extremum in a row); the
    /// recovery after them is left out too.
    pub samples: usize,
    /// The lowest sample left out, in the signal's unit.
    pub min: f64,
    /// The highest sample left out.
    pub max: f64,
}

/// An integrator's overshoot starts within this many samples of a
/// contact edge: the first steps after the edge are the ones that
/// overshoot.
pub const RINGING_LOOKAHEAD: usize = 6;

/// The fewest local extrema in a row, one per sample and swinging less
/// and less, that are taken for ringing whatever their shape: a real
/// signal's extremum is one sample, a resolved oscillation's extrema are
/// several samples apart.
pub const RINGING_EXTREMA: usize = 3;

/// The integrator's overshoots of (`time`, `values`) after each contact
/// edge at `edges` (s), and for each sample whether it is left out of the
/// range (see the module overview). After the overshooting samples, the
/// samples that move monotonically back from them, up to the next
/// reversal or the next edge, are left out too: a monotone stretch has
/// its extremes at its ends, and the end it settles at is kept, so no
/// extreme of the signal is lost with them.
pub fn integration_ringing(
    time: &[f64],
    values: &[f64],
    edges: &[f64],
) -> (Vec<Ringing>, Vec<bool>) {
    let n = values.len().min(time.len());
    let mut left_out = vec![false; n];
    let mut found = Vec::new();
    if n < 4 {
        return (found, left_out);
    }
    let step = |k: usize| values[k + 1] - values[k];
    // Sample k (not the first or last) is a local extremum: the steps on
    // either side of it go opposite ways.
    let extremum = |k: usize| {
        let (before, after) = (step(k - 1), step(k));
        before != 0.0 && after != 0.0 && (before > 0.0) != (after > 0.0)
    };
    let mut sorted: Vec<f64> = edges.iter().copied().filter(|t| t.is_finite()).collect();
    sorted.sort_by(f64::total_cmp);
    sorted.dedup();
    for (i, &edge) in sorted.iter().enumerate() {
        let next_edge = sorted.get(i + 1).copied().unwrap_or(f64::INFINITY);
        let first = time[..n].partition_point(|&t| t < edge).max(1);
        let mut k = first;
        while k < (first + RINGING_LOOKAHEAD).min(n - 1) {
            if left_out[k] || !extremum(k) {
                k += 1;
                continue;
            }
            let mut last = k;
            while last + 1 < n - 1 && extremum(last + 1) {
                last += 1;
            }
            let into = step(k - 1).abs();
            let ringing = last + 1 - k >= RINGING_EXTREMA && step(last).abs() < into;
            if !ringing {
                k = last + 1;
                continue;
            }
            // The recovery: on in the direction the last overshoot left.
            let back = step(last) > 0.0;
            let mut end = last;
            while end + 2 < n
                && time[end + 1] < next_edge
                && step(end + 1) != 0.0
                && (step(end + 1) > 0.0) == back
            {
                end += 1;
            }
            let out = &values[k..=end];
            found.push(Ringing {
                edge,
                start: time[k],
                end: time[end],
                samples: last + 1 - k,
                min: out.iter().copied().fold(f64::INFINITY, f64::min),
                max: out.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            });
            left_out[k..=end].iter_mut().for_each(|x| *x = true);
            break;
        }
    }
    (found, left_out)
}

/// The two figures a designer sizes a debouncer with, from a probe's
/// edges.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Debounce {
    /// s, last edge − first edge: a debouncer that ignores its input for
    /// T after the first edge needs T > lockout.
    pub lockout: f64,
    /// s, the longest time between two consecutive edges: a debouncer
    /// that waits for its input to be stable for T needs T > stable_for
    /// (0 with a single edge).
    pub stable_for: f64,
}

impl Debounce {
    /// The figures of edges at `times` (s, in order); `None` without one.
    pub fn of(times: &[f64]) -> Option<Debounce> {
        let (first, last) = (times.first()?, times.last()?);
        Some(Debounce {
            lockout: last - first,
            stable_for: times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max),
        })
    }
}

impl ProbeAnalysis {
    /// What a reader of the probe's figures must be told, as one warning:
    /// that the signal crossed neither threshold it would have to (no
    /// edge, and its whole range on one side of a threshold: such a probe
    /// reports 0 edges however much the signal moved), and that samples
    /// of integration ringing beyond the signal's range were left out of
    /// its `min` and `max` ([`ProbeAnalysis::ringing_warning`]). `None`
    /// when neither applies.
    pub fn threshold_warning(&self) -> Option<String> {
        let parts: Vec<String> = [self.no_edge_warning(), self.ringing_warning()]
            .into_iter()
            .flatten()
            .collect();
        (!parts.is_empty()).then(|| parts.join("; "))
    }

    /// When the integrator's ringing after a contact edge reaches beyond
    /// the range of the other samples (so that it sets the minimum or the
    /// maximum): a sentence saying where, how far, what the limits hold
    /// and how to avoid it.
    pub fn ringing_warning(&self) -> Option<String> {
        if self.min_without_ringing.is_none() && self.max_without_ringing.is_none() {
            return None;
        }
        let (lo, hi) = self.range_without_ringing();
        let unit = self.kind.unit();
        let e = |v: f64| crate::report::units::engineering(v, unit);
        let beyond = |r: &Ringing| (lo - r.min).max(r.max - hi);
        let worst = self
            .ringing
            .iter()
            .max_by(|a, b| beyond(a).total_cmp(&beyond(b)))?;
        let edges = self.ringing.iter().filter(|r| beyond(r) > 0.0).count();
        let far = if worst.min < lo { worst.min } else { worst.max };
        Some(format!(
            "{}: right after {edges} contact edge{} ngspice's samples ring up and down from one \
             time point to the next (out to {}, after the edge at {:.4} ms): the integration of \
             the contact's sharp edge, not the signal. The range is {} to {} with them and {} to \
             {} without them; limits hold the range with them unless the probe sets \
             `ignore_ringing = true`. `.options method=gear trtol=1` in the netlist avoids the \
             ringing",
            self.signal,
            if edges == 1 { "" } else { "s" },
            e(far),
            worst.edge * 1e3,
            e(self.min),
            e(self.max),
            e(lo),
            e(hi),
        ))
    }

    /// (min, max) without the integrator's ringing after contact edges.
    pub fn range_without_ringing(&self) -> (f64, f64) {
        (
            self.min_without_ringing.unwrap_or(self.min),
            self.max_without_ringing.unwrap_or(self.max),
        )
    }

    /// (min, max) as a probe's limits hold them: every sample, or without
    /// the integrator's ringing when `ignore_ringing`.
    pub fn range_for_limits(&self, ignore_ringing: bool) -> (f64, f64) {
        if ignore_ringing {
            self.range_without_ringing()
        } else {
            (self.min, self.max)
        }
    }

    /// When the signal crossed neither threshold it would have to: the
    /// first half of [`ProbeAnalysis::threshold_warning`].
    fn no_edge_warning(&self) -> Option<String> {
        if self.edges > 0 {
            return None;
        }
        let unit = self.kind.unit();
        let e = |v: f64| crate::report::units::engineering(v, unit);
        let (which, value) = if self.max < self.high && self.min > self.low {
            ("either threshold", None)
        } else if self.max < self.high {
            ("its `high` threshold", Some(self.high))
        } else if self.min > self.low {
            ("its `low` threshold", Some(self.low))
        } else {
            return None;
        };
        Some(format!(
            "{}: no edge: the signal never crosses {which}{} (low {}, high {}); its range is {} to \
             {}: check the probe's thresholds and units",
            self.signal,
            value.map_or_else(String::new, |v| format!(" at {}", e(v))),
            e(self.low),
            e(self.high),
            e(self.min),
            e(self.max),
        ))
    }
}

/// What the bounce added to a probe, compared with a run of the same
/// circuit whose contact makes once, cleanly, at the first impact.
/// Every difference is *bounced − ideal*: positive means the bounce added.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// The bounced run's signal.
    pub signal: String,
    /// Edges the bounce added (negative if it removed some).
    pub extra_edges: i64,
    /// Glitches the bounce added.
    pub extra_glitches: i64,
    /// s, the bounced run's last edge minus the ideal's: how much later the
    /// signal settles. `None` unless both runs have an edge.
    pub settle_delay: Option<f64>,
    /// Whether both runs end at the same level; if not, `settle_delay`
    /// compares edges that mean different things.
    pub same_final_state: bool,
    /// Difference of the largest samples.
    pub max_difference: f64,
    /// Difference of the smallest samples (negative: the bounce went lower).
    pub min_difference: f64,
    /// A, difference of the peak |i| (currents only).
    pub peak_difference: Option<f64>,
    /// C, difference of the whole-record charge (currents only).
    pub charge_difference: Option<f64>,
}

/// The closed intervals of a chatter sequence as `(start, end)` in s, the
/// closures [`analyze`] integrates a current over. The first begins at the
/// first impact. The contact waveform lags each by up to one edge time
/// (its edges start at the events); widen the windows for that if the
/// break edge's charge matters.
pub fn closures(chatter: &Chatter) -> Vec<(f64, f64)> {
    chatter
        .intervals
        .iter()
        .filter(|i| i.state == ContactState::Closed)
        .map(|i| (i.start, i.end))
        .collect()
}

/// Analyse `probe` in `plot`, which must be a transient plot (its scale is
/// `time`). `closures` (s) are only used when the signal is a current.
pub fn analyze(
    plot: &Plot,
    probe: &Probe,
    closures: &[(f64, f64)],
) -> Result<ProbeAnalysis, AnalysisError> {
    let scale = plot.variables.first();
    let time = match (scale, plot.scale()) {
        (Some(var), Some(Vector::Real(t))) if var.kind.eq_ignore_ascii_case("time") => t,
        _ => {
            return Err(AnalysisError::NotTransient {
                plot: plot.name.clone(),
                scale: scale.map(|v| v.name.clone()),
            });
        }
    };
    let (values, raw_type) = signal_values(plot, &probe.signal)?;
    let kind = ProbeKind::classify(&probe.signal, raw_type.as_deref());
    analyze_samples(probe, kind, time, &values, closures)
}

/// The samples of `signal` in `plot`, and the raw file's type for it. A
/// vector ngspice wrote is used as it is; a differential voltage
/// `v(a,b)`, which ngspice's raw files never hold, is computed as
/// v(a) − v(b) (node `0` being ground).
pub fn signal_values<'p>(
    plot: &'p Plot,
    signal: &str,
) -> Result<(Cow<'p, [f64]>, Option<String>), AnalysisError> {
    let missing = || {
        let mut available: Vec<String> = plot.variables.iter().map(|v| v.name.clone()).collect();
        available.sort();
        AnalysisError::MissingSignal {
            signal: signal.to_owned(),
            plot: plot.name.clone(),
            available,
        }
    };
    let real = |index: usize| match plot.vector(index) {
        Some(Vector::Real(v)) => Ok(v),
        _ => Err(AnalysisError::ComplexSignal {
            signal: signal.to_owned(),
            plot: plot.name.clone(),
        }),
    };
    if let Some(index) = plot.index_of(signal) {
        let kind = plot.variables[index].kind.clone();
        return Ok((Cow::Borrowed(real(index)?), Some(kind)));
    }
    let Some((a, b)) = differential_nodes(signal) else {
        return Err(missing());
    };
    let node = |name: &str| -> Result<Option<&'p [f64]>, AnalysisError> {
        if name == "0" {
            return Ok(None);
        }
        let index = plot.index_of(&format!("v({name})")).ok_or_else(missing)?;
        real(index).map(Some)
    };
    let values = match (node(a)?, node(b)?) {
        (Some(va), Some(vb)) => va.iter().zip(vb).map(|(x, y)| x - y).collect(),
        (Some(va), None) => va.to_vec(),
        (None, Some(vb)) => vb.iter().map(|y| -y).collect(),
        (None, None) => vec![0.0; plot.points()],
    };
    Ok((Cow::Owned(values), Some("voltage".to_owned())))
}

/// `v(a,b)` → `("a", "b")`, spaces allowed, case kept.
fn differential_nodes(signal: &str) -> Option<(&str, &str)> {
    let inner = signal
        .trim()
        .strip_prefix(['v', 'V'])?
        .trim_start()
        .strip_prefix('(')?
        .strip_suffix(')')?;
    let (a, b) = inner.split_once(',')?;
    let (a, b) = (a.trim(), b.trim());
    (!a.is_empty() && !b.is_empty()).then_some((a, b))
}

/// Analyse sampled data: `time` (s, non-decreasing) and `values` of
/// `probe.signal`, in the unit of `probe.low`/`probe.high`. The current
/// analysis over `closures` (s) is done when `kind` is a current; for
/// every signal, the closures' starts and ends are the contact edges
/// after which integration ringing is looked for.
pub fn analyze_samples(
    probe: &Probe,
    kind: ProbeKind,
    time: &[f64],
    values: &[f64],
    closures: &[(f64, f64)],
) -> Result<ProbeAnalysis, AnalysisError> {
    let schmitt = schmitt(&probe.signal, time, values, probe.low, probe.high)?;
    let contact_edges: Vec<f64> = closures.iter().flat_map(|&(a, b)| [a, b]).collect();
    let (ringing, left_out) = integration_ringing(time, values, &contact_edges);
    let range = |keep: &dyn Fn(usize) -> bool| {
        values
            .iter()
            .enumerate()
            .filter(|&(k, _)| keep(k))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, &v)| {
                (lo.min(v), hi.max(v))
            })
    };
    let (min, max) = range(&|_| true);
    // The first and last samples are never left out: the range has one.
    let (lo, hi) = range(&|k| !left_out.get(k).copied().unwrap_or(false));
    let differs = |a: f64, b: f64| (a != b).then_some(b);
    let current = match kind {
        ProbeKind::Current => Some(current(&probe.signal, time, values, closures)?),
        _ => None,
    };
    let edges = &schmitt.edges;
    let times: Vec<f64> = edges.iter().map(|e| e.time).collect();
    // A current pulse is two edges (it rises and falls): count pulses.
    let pulses = (kind == ProbeKind::Current).then(|| edges.len().div_ceil(2));
    Ok(ProbeAnalysis {
        signal: probe.signal.clone(),
        edges: edges.len(),
        glitches: match pulses {
            Some(p) => p.saturating_sub(1),
            None => edges.len().saturating_sub(1),
        },
        pulses,
        first_edge: edges.first().map(|e| e.time),
        last_edge: edges.last().map(|e| e.time),
        min,
        max,
        min_without_ringing: differs(min, lo),
        max_without_ringing: differs(max, hi),
        kind,
        low: probe.low,
        high: probe.high,
        initial_state: schmitt.initial_state,
        final_state: schmitt.final_state,
        final_value: values[values.len() - 1],
        shortest_pulse: edges.iter().filter_map(|e| e.width).min_by(f64::total_cmp),
        transitions: schmitt.edges,
        current,
        debounce: Debounce::of(&times),
        ringing,
    })
}

/// Check what every analysis relies on: as many values as times, at least
/// one sample, everything finite, time never decreasing.
pub fn check_samples(signal: &str, time: &[f64], values: &[f64]) -> Result<(), AnalysisError> {
    if time.len() != values.len() {
        return Err(AnalysisError::LengthMismatch {
            signal: signal.to_owned(),
            time: time.len(),
            values: values.len(),
        });
    }
    if time.is_empty() {
        return Err(AnalysisError::Empty {
            signal: signal.to_owned(),
        });
    }
    for (index, (&t, &v)) in time.iter().zip(values).enumerate() {
        if !t.is_finite() {
            return Err(AnalysisError::NotFinite {
                signal: "time".to_owned(),
                index,
                time: t,
                value: t,
            });
        }
        if index > 0 && t < time[index - 1] {
            return Err(AnalysisError::TimeGoesBack {
                index,
                previous: time[index - 1],
                time: t,
            });
        }
        if !v.is_finite() {
            return Err(AnalysisError::NotFinite {
                signal: signal.to_owned(),
                index,
                time: t,
                value: v,
            });
        }
    }
    Ok(())
}

/// The Schmitt edges of `values` over `time` with thresholds `low < high`
/// (see the module overview for the rules and the undetermined start).
pub fn schmitt(
    signal: &str,
    time: &[f64],
    values: &[f64],
    low: f64,
    high: f64,
) -> Result<Schmitt, AnalysisError> {
    if !(low.is_finite() && high.is_finite() && low < high) {
        return Err(AnalysisError::Thresholds {
            signal: signal.to_owned(),
            low,
            high,
        });
    }
    check_samples(signal, time, values)?;
    let level_of = |v: f64| {
        if v >= high {
            Level::High
        } else if v <= low {
            Level::Low
        } else {
            Level::Undetermined
        }
    };
    let initial_state = level_of(values[0]);
    let mut state = initial_state;
    let mut edges: Vec<Edge> = Vec::new();
    for k in 1..values.len() {
        let v = values[k];
        let (threshold, direction, next) = match state {
            Level::Undetermined => {
                // Defining the level is not an edge (module overview).
                state = level_of(v);
                continue;
            }
            Level::Low if v >= high => (high, Direction::Rising, Level::High),
            Level::High if v <= low => (low, Direction::Falling, Level::Low),
            _ => continue,
        };
        // The previous sample did not reach `threshold` (else the level
        // would have changed there), so the denominator is not zero.
        let (v0, t0, t1) = (values[k - 1], time[k - 1], time[k]);
        let fraction = (threshold - v0) / (v - v0);
        edges.push(Edge {
            time: t0 + fraction * (t1 - t0),
            direction,
            width: None,
        });
        state = next;
    }
    for k in 1..edges.len() {
        edges[k - 1].width = Some(edges[k].time - edges[k - 1].time);
    }
    Ok(Schmitt {
        initial_state,
        final_state: state,
        edges,
    })
}

/// Peak |i| and charge of a current, over the whole record and per closure
/// (s, each `start <= end`). A closure partly outside the record is
/// clipped to it; one wholly outside is an error.
pub fn current(
    signal: &str,
    time: &[f64],
    values: &[f64],
    closures: &[(f64, f64)],
) -> Result<CurrentAnalysis, AnalysisError> {
    check_samples(signal, time, values)?;
    let (first, last) = (time[0], time[time.len() - 1]);
    let whole = window(time, values, first, last);
    let mut per_closure = Vec::with_capacity(closures.len());
    for (index, &(start, end)) in closures.iter().enumerate() {
        if !(start.is_finite() && end.is_finite() && start <= end) {
            return Err(AnalysisError::BadClosure {
                signal: signal.to_owned(),
                index,
                start,
                end,
            });
        }
        if end < first || start > last {
            return Err(AnalysisError::ClosureOutsideRecord {
                signal: signal.to_owned(),
                index,
                start,
                end,
                record_start: first,
                record_end: last,
            });
        }
        let (start, end) = (start.max(first), end.min(last));
        let w = window(time, values, start, end);
        per_closure.push(ClosureCurrent {
            start,
            end,
            peak: w.peak,
            peak_time: w.peak_time,
            charge: w.charge,
        });
    }
    Ok(CurrentAnalysis {
        peak: whole.peak,
        peak_time: whole.peak_time,
        charge: whole.charge,
        closed_charge: per_closure.iter().map(|c| c.charge).sum(),
        per_closure,
    })
}

/// What the ideal contact's run says beside the bounced one (see
/// [`Comparison`] for the signs). Both must analyse the same signal
/// (ignoring case) with the same thresholds.
pub fn compare(
    bounced: &ProbeAnalysis,
    ideal: &ProbeAnalysis,
) -> Result<Comparison, AnalysisError> {
    if !bounced.signal.eq_ignore_ascii_case(&ideal.signal)
        || bounced.low != ideal.low
        || bounced.high != ideal.high
    {
        return Err(AnalysisError::NotComparable {
            bounced: bounced.signal.clone(),
            ideal: ideal.signal.clone(),
        });
    }
    let count = |n: usize| i64::try_from(n).unwrap_or(i64::MAX);
    let settle_delay = match (bounced.last_edge, ideal.last_edge) {
        (Some(b), Some(i)) => Some(b - i),
        _ => None,
    };
    let both = |f: fn(&CurrentAnalysis) -> f64| match (&bounced.current, &ideal.current) {
        (Some(b), Some(i)) => Some(f(b) - f(i)),
        _ => None,
    };
    Ok(Comparison {
        signal: bounced.signal.clone(),
        extra_edges: count(bounced.edges) - count(ideal.edges),
        extra_glitches: count(bounced.glitches) - count(ideal.glitches),
        settle_delay,
        same_final_state: bounced.final_state == ideal.final_state,
        max_difference: bounced.max - ideal.max,
        min_difference: bounced.min - ideal.min,
        peak_difference: both(|c| c.peak),
        charge_difference: both(|c| c.charge),
    })
}

/// Peak |v| and ∫ v dt over a window.
struct Window {
    peak: f64,
    peak_time: f64,
    charge: f64,
}

/// The value at `t` on the straight lines between samples (the first of
/// repeated instants; the end values outside the record).
fn interpolate(time: &[f64], values: &[f64], t: f64) -> f64 {
    let k = time.partition_point(|&x| x < t);
    if k == 0 {
        return values[0];
    }
    if k == time.len() {
        return values[k - 1];
    }
    let (t0, t1, v0, v1) = (time[k - 1], time[k], values[k - 1], values[k]);
    if t1 == t0 {
        v1
    } else {
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    }
}

/// Peak |v| and trapezoid ∫ v dt over [a, b] inside the record, with the
/// values at the ends interpolated: on straight lines the extremes are at
/// samples or at the ends, so the peak is exact for the data.
fn window(time: &[f64], values: &[f64], a: f64, b: f64) -> Window {
    let inner_start = time.partition_point(|&x| x <= a);
    let inner_end = time.partition_point(|&x| x < b).max(inner_start);
    let ends = [(a, interpolate(time, values, a))];
    let inner = time[inner_start..inner_end]
        .iter()
        .copied()
        .zip(values[inner_start..inner_end].iter().copied());
    let points = ends
        .into_iter()
        .chain(inner)
        .chain([(b, interpolate(time, values, b))]);
    let mut w = Window {
        peak: f64::NEG_INFINITY,
        peak_time: a,
        charge: 0.0,
    };
    let mut previous: Option<(f64, f64)> = None;
    for (t, v) in points {
        if v.abs() > w.peak {
            w.peak = v.abs();
            w.peak_time = t;
        }
        if let Some((t0, v0)) = previous {
            w.charge += 0.5 * (v + v0) * (t - t0);
        }
        previous = Some((t, v));
    }
    w
}

#[cfg(test)]
mod debounce_tests {
    use super::Debounce;

    #[test]
    fn lockout_spans_the_edges_and_stable_for_is_the_longest_gap() {
        let d = Debounce::of(&[1.0e-3, 1.2e-3, 1.25e-3, 1.9e-3, 2.0e-3]).unwrap();
        assert!((d.lockout - 1.0e-3).abs() < 1e-15);
        assert!((d.stable_for - 0.65e-3).abs() < 1e-15);
        let one = Debounce::of(&[3e-3]).unwrap();
        assert_eq!((one.lockout, one.stable_for), (0.0, 0.0));
        assert_eq!(Debounce::of(&[]), None);
    }
}

#[cfg(test)]
#[path = "analysis_tests.rs"]
mod tests;
