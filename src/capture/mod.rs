//! Scope captures of a contact: read an instrument's CSV export
//! ([`layout`]), find the contact's levels and edges ([`edges`]), and
//! report the chatter it shows in the names of the simulated one.

pub mod edges;
pub mod layout;

use serde::Serialize;

use crate::chatter::{Chatter, ContactState, Interval};

pub use edges::{Closed, EdgeError, Edges};
pub use layout::{CaptureError, Layout, Trace, parse_capture, read_capture};

/// What a capture shows: the JSON of `chatterspice capture`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Capture {
    /// What the trace was read from, as given (usually the file's path).
    pub source: String,
    /// The exporter's layout, as [`Layout::as_str`] names it.
    pub layout: &'static str,
    /// The channel analysed, as the file names it.
    pub channel: String,
    /// The number of samples in the trace.
    pub samples: usize,
    /// s, the median spacing of the samples.
    pub sample_interval: f64,
    /// The trace's open and closed levels.
    pub levels: Levels,
    /// The hysteresis thresholds the edges were found with.
    pub thresholds: Thresholds,
    /// s, on the capture's time axis: the first make; `None` if the
    /// contact never closes.
    pub first_make: Option<f64>,
    /// s, the start of the final closed interval; `None` if the capture
    /// does not end closed.
    pub settle_time: Option<f64>,
    /// Openings after the first make.
    pub bounce_count: usize,
    /// s, every make, in order.
    pub makes: Vec<f64>,
    /// s, every break, in order.
    pub breaks: Vec<f64>,
    /// The contact's states from the first sample to the last, on the
    /// capture's time axis.
    pub intervals: Vec<Interval>,
}

/// The two levels of a capture's trace, in the trace's unit (usually V).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Levels {
    /// The level while the contact is open.
    pub open: f64,
    /// The level while the contact is closed.
    pub closed: f64,
}

/// The hysteresis thresholds of a capture's edges, in the trace's unit
/// (`low < high`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Thresholds {
    /// The lower threshold.
    pub low: f64,
    /// The upper threshold.
    pub high: f64,
}

impl Capture {
    /// The chatter of `trace` (named `source`), with optional thresholds
    /// and polarity.
    pub fn of(
        source: &str,
        trace: &Trace,
        thresholds: Option<(f64, f64)>,
        closed: Option<Closed>,
    ) -> Result<Capture, EdgeError> {
        let e = edges::edges(&trace.time, &trace.value, thresholds, closed)?;
        let chatter = Chatter::from_intervals(e.intervals.clone());
        let mut steps: Vec<f64> = trace.time.windows(2).map(|w| w[1] - w[0]).collect();
        steps.sort_by(f64::total_cmp);
        Ok(Capture {
            source: source.to_owned(),
            layout: trace.layout.as_str(),
            channel: trace.channel.clone(),
            samples: trace.time.len(),
            sample_interval: steps[steps.len() / 2],
            levels: Levels {
                open: e.open,
                closed: e.closed,
            },
            thresholds: Thresholds {
                low: e.low,
                high: e.high,
            },
            first_make: chatter.first_impact,
            settle_time: chatter.settle_time,
            bounce_count: chatter.bounce_count,
            makes: e.makes,
            breaks: e.breaks,
            intervals: e.intervals,
        })
    }

    /// The `time,state` CSV that `--measured` reads: one row per state
    /// change and a last row at the end of the record. Its times start at
    /// 0 (the first sample); the capture's own time base is
    /// [`Capture::intervals`] less [`Capture::csv_origin`].
    pub fn state_csv(&self) -> String {
        let origin = self.csv_origin();
        let name = |s: ContactState| match s {
            ContactState::Open => "open",
            ContactState::Closed => "closed",
        };
        let mut out = String::from("time,state\n");
        for i in &self.intervals {
            out.push_str(&format!("{:?},{}\n", i.start - origin, name(i.state)));
        }
        if let Some(last) = self.intervals.last().filter(|l| l.end > l.start) {
            out.push_str(&format!("{:?},{}\n", last.end - origin, name(last.state)));
        }
        out
    }

    /// s, the capture time of the CSV's t = 0: its first sample.
    pub fn csv_origin(&self) -> f64 {
        self.intervals.first().map_or(0.0, |i| i.start)
    }

    /// The intervals from t = 0 at the first sample, as
    /// [`Capture::state_csv`] writes them (a circuit run cannot start
    /// before 0). The fit does not use them: it reads
    /// [`Capture::intervals`], on the capture's own axis, so that its time
    /// offset is measured from the scope's trigger whatever pre-trigger
    /// samples the record holds.
    pub fn shifted_intervals(&self) -> Vec<Interval> {
        let o = self.csv_origin();
        self.intervals
            .iter()
            .map(|i| Interval {
                state: i.state,
                start: i.start - o,
                end: i.end - o,
            })
            .collect()
    }
}
