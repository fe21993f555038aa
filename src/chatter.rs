//! The chatter sequence: what one closing of the contact looks like.
//!
//! This is the engine's result and the contract every later stage reads
//! (waveform, reports, checks). Field names match the JSON of
//! docs/output.md. All values are SI; times are measured from t = 0,
//! the instant the closing force is applied.

use serde::Serialize;

/// How a chatter sequence ended (docs/model.md §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// The contact no longer releases: closed for good.
    Stuck,
    /// The next opening would be shorter than `min_open_time` or open less
    /// than `min_gap`: the rest of the sequence is below resolution and the
    /// contact is taken as closed from the last retained impact on.
    Resolved,
    /// The moving contact never reaches the fixed one.
    NeverCloses,
    /// The contact was touched but the final state is open.
    EndsOpen,
    /// Still chattering at `t_end`.
    EndOfTime,
    /// Still chattering at the most impacts a simulation records (the
    /// mechanics' `MAX_EVENTS`): the sequence is cut there (an undamped or
    /// perfectly elastic model).
    EventLimit,
}

impl Outcome {
    /// The contract name used in JSON and CSV.
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Stuck => "stuck",
            Outcome::Resolved => "resolved",
            Outcome::NeverCloses => "never_closes",
            Outcome::EndsOpen => "ends_open",
            Outcome::EndOfTime => "end_of_time",
            Outcome::EventLimit => "event_limit",
        }
    }

    /// The outcome named `text` (as written by [`Outcome::as_str`]).
    pub fn parse(text: &str) -> Option<Outcome> {
        [
            Outcome::Stuck,
            Outcome::Resolved,
            Outcome::NeverCloses,
            Outcome::EndsOpen,
            Outcome::EndOfTime,
            Outcome::EventLimit,
        ]
        .into_iter()
        .find(|o| o.as_str() == text)
    }

    /// Whether the sequence ended with the contact closed for good.
    pub fn is_closed(self) -> bool {
        matches!(self, Outcome::Stuck | Outcome::Resolved)
    }
}

impl std::fmt::Display for Outcome {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One contact between the moving and the fixed contact.
///
/// Velocities are positive toward the fixed contact, so an impact velocity
/// is positive and a release velocity negative. Forces are the force the
/// fixed contact exerts on the moving one, positive pushing it back.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Impact {
    /// s, when the contacts touch.
    pub impact_time: f64,
    /// m/s, approach speed at the touch (> 0).
    pub impact_velocity: f64,
    /// s, when they separate; `None` for a contact that never releases
    /// (or is still closed at `t_end`).
    pub release_time: Option<f64>,
    /// m/s, velocity at separation (< 0); `None` with `release_time`.
    pub release_velocity: Option<f64>,
    /// −release_velocity / impact_velocity; `None` without a release.
    pub restitution: Option<f64>,
    /// s, release_time − impact_time; `None` without a release.
    pub contact_time: Option<f64>,
    /// N, largest contact force during the contact. `None` for a rigid
    /// surface, whose force is an impulse (except when it sticks: then the
    /// static force).
    pub peak_force: Option<f64>,
    /// N, most negative (or smallest) contact force during the contact.
    /// Negative values are the Kelvin–Voigt "sticky force" artefact.
    pub min_force: Option<f64>,
    /// m, largest opening between this release and the next impact;
    /// `None` if the contact did not release.
    pub max_gap_after: Option<f64>,
}

/// Releases after the first impact that opened the contact, in a
/// sequence of intervals that starts open: every open interval but the
/// one before the first impact.
pub(crate) fn bounces(intervals: &[Interval]) -> usize {
    intervals
        .iter()
        .filter(|i| i.state == ContactState::Open)
        .count()
        .saturating_sub(1)
}

impl Impact {
    /// A touch at `time` (s) at `velocity` (m/s), before anything else
    /// about the contact is known.
    pub fn touch(time: f64, velocity: f64) -> Impact {
        Impact {
            impact_time: time,
            impact_velocity: velocity,
            release_time: None,
            release_velocity: None,
            restitution: None,
            contact_time: None,
            peak_force: None,
            min_force: None,
            max_gap_after: None,
        }
    }
}

/// Electrical state of the contact over an interval.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactState {
    /// The contacts are apart: no current flows.
    Open,
    /// The contacts touch: the contact conducts.
    Closed,
}

impl ContactState {
    /// The contract name used in JSON and CSV.
    pub fn as_str(self) -> &'static str {
        match self {
            ContactState::Open => "open",
            ContactState::Closed => "closed",
        }
    }
}

/// A maximal time span with one contact state. Intervals tile [0, t_end]
/// in order; `start <= end` always (a rigid surface gives closed intervals
/// of zero length).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Interval {
    /// The state throughout the interval.
    pub state: ContactState,
    /// s
    pub start: f64,
    /// s
    pub end: f64,
}

/// The complete result of one closing.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Chatter {
    /// How the sequence ended.
    pub outcome: Outcome,
    /// s, the first touch; `None` if the contact never closes.
    pub first_impact: Option<f64>,
    /// s, start of the final closed interval; `None` if the sequence does
    /// not end closed.
    pub settle_time: Option<f64>,
    /// Releases after the first impact that opened the contact.
    pub bounce_count: usize,
    /// Every impact, in time order; empty for a recorded sequence of
    /// states ([`Chatter::from_intervals`]).
    pub impacts: Vec<Impact>,
    /// The contact's states, in time order, each starting where the one
    /// before ends.
    pub intervals: Vec<Interval>,
    /// m, for `never_closes`: how far short of the gap the moving contact
    /// turns back (gap − largest reach). `None` otherwise.
    pub shortfall: Option<f64>,
    /// s, for a rigid surface whose bounces form a Zeno sequence: the time
    /// at which the collapsed tail of ever shorter bounces accumulates.
    pub accumulation_time: Option<f64>,
    /// s, the simulated horizon.
    pub t_end: f64,
}

impl Chatter {
    /// The summary of a recorded sequence of states (e.g. a scope capture)
    /// that tiles its record in order: `first_impact` is the first closed
    /// interval, `settle_time` the start of a final closed one, and a
    /// bounce every opening after the first impact. The outcome is `stuck`
    /// when the record ends closed (closed to the end of what was seen),
    /// `ends_open` when it ends open after closing, `never_closes` when it
    /// never closes. There are no impacts: a record of states has no
    /// velocities or forces.
    pub fn from_intervals(intervals: Vec<Interval>) -> Chatter {
        let first_impact = intervals
            .iter()
            .find(|i| i.state == ContactState::Closed)
            .map(|i| i.start);
        let last = intervals.last().copied();
        let ends_closed = last.is_some_and(|i| i.state == ContactState::Closed);
        let bounce_count = match first_impact {
            Some(first) => intervals
                .iter()
                .filter(|i| i.state == ContactState::Open && i.start >= first)
                .count(),
            None => 0,
        };
        Chatter {
            outcome: match (first_impact, ends_closed) {
                (None, _) => Outcome::NeverCloses,
                (Some(_), true) => Outcome::Stuck,
                (Some(_), false) => Outcome::EndsOpen,
            },
            first_impact,
            settle_time: if ends_closed {
                last.map(|i| i.start)
            } else {
                None
            },
            bounce_count,
            impacts: Vec::new(),
            shortfall: None,
            accumulation_time: None,
            t_end: last.map_or(0.0, |i| i.end),
            intervals,
        }
    }
}

/// Hand-built contact records for the tests of every stage that reads
/// one (waveform, reports, checks): the engine is tested on its own, and
/// these pin down every shape a record can take.
#[cfg(test)]
pub(crate) mod fixtures {
    use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome};

    fn interval(state: ContactState, start: f64, end: f64) -> Interval {
        Interval { state, start, end }
    }

    /// Two bounces, then stuck on the third impact (Kelvin–Voigt-like).
    pub fn stuck() -> Chatter {
        use ContactState::{Closed, Open};
        let bounce = |t: f64, v: f64, tr: f64, vr: f64, peak: f64, min: f64, gap: f64| Impact {
            impact_time: t,
            impact_velocity: v,
            release_time: Some(tr),
            release_velocity: Some(vr),
            restitution: Some(-vr / v),
            contact_time: Some(tr - t),
            peak_force: Some(peak),
            min_force: Some(min),
            max_gap_after: Some(gap),
        };
        Chatter {
            outcome: Outcome::Stuck,
            first_impact: Some(0.0012),
            settle_time: Some(0.0016),
            bounce_count: 2,
            impacts: vec![
                bounce(0.0012, 0.31, 0.00121, -0.26, 2.1, -0.1, 3.0e-6),
                bounce(0.0014, 0.2, 0.001405, -0.15, 1.25, -0.04, 1.0e-6),
                Impact {
                    impact_time: 0.0016,
                    impact_velocity: 0.05,
                    release_time: None,
                    release_velocity: None,
                    restitution: None,
                    contact_time: None,
                    peak_force: Some(0.6),
                    min_force: Some(0.36),
                    max_gap_after: None,
                },
            ],
            intervals: vec![
                interval(Open, 0.0, 0.0012),
                interval(Closed, 0.0012, 0.00121),
                interval(Open, 0.00121, 0.0014),
                interval(Closed, 0.0014, 0.001405),
                interval(Open, 0.001405, 0.0016),
                interval(Closed, 0.0016, 0.02),
            ],
            shortfall: None,
            accumulation_time: None,
            t_end: 0.02,
        }
    }

    /// The gap is beyond the overshoot: no impact at all.
    pub fn never_closes() -> Chatter {
        Chatter {
            outcome: Outcome::NeverCloses,
            first_impact: None,
            settle_time: None,
            bounce_count: 0,
            impacts: vec![],
            intervals: vec![interval(ContactState::Open, 0.0, 0.02)],
            shortfall: Some(2.5e-5),
            accumulation_time: None,
            t_end: 0.02,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiling(first: ContactState, bounds: &[f64]) -> Vec<Interval> {
        let mut state = first;
        bounds
            .windows(2)
            .map(|w| {
                let iv = Interval {
                    state,
                    start: w[0],
                    end: w[1],
                };
                state = match state {
                    ContactState::Open => ContactState::Closed,
                    ContactState::Closed => ContactState::Open,
                };
                iv
            })
            .collect()
    }

    #[test]
    fn a_recorded_sequence_is_summarised_like_the_engine_s() {
        let c = Chatter::from_intervals(tiling(
            ContactState::Open,
            &[0.0, 1.0, 1.1, 1.5, 1.6, 1.8, 5.0],
        ));
        assert_eq!(c.outcome, Outcome::Stuck);
        assert_eq!(c.first_impact, Some(1.0));
        assert_eq!(c.settle_time, Some(1.8));
        assert_eq!(c.bounce_count, 2);
        assert_eq!(c.t_end, 5.0);
        assert!(c.impacts.is_empty());

        let open = Chatter::from_intervals(tiling(ContactState::Open, &[0.0, 1.0, 1.1, 2.0]));
        assert_eq!(open.outcome, Outcome::EndsOpen);
        assert_eq!(open.settle_time, None);
        assert_eq!(open.bounce_count, 1);

        let never = Chatter::from_intervals(tiling(ContactState::Open, &[0.0, 2.0]));
        assert_eq!(never.outcome, Outcome::NeverCloses);
        assert_eq!((never.first_impact, never.bounce_count), (None, 0));

        // Closed from the start of the record: no bounce before it opens.
        let closed = Chatter::from_intervals(tiling(ContactState::Closed, &[0.0, 1.0, 1.2, 3.0]));
        assert_eq!(closed.first_impact, Some(0.0));
        assert_eq!(closed.bounce_count, 1);
    }
}
