//! `[[probe]]`: the signals to measure, and their limits.

use serde::Deserialize;

use super::check::Check;
use super::error::ScenarioError;

/// `[[probe]]`: a measured signal, its Schmitt thresholds, and the limits
/// `check` holds it to (all optional).
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    /// An ngspice vector name, e.g. `v(in)`.
    pub signal: String,
    /// `probe[i].low`, V (A for a current): the lower Schmitt threshold,
    /// below `high`.
    pub low: f64,
    /// `probe[i].high`, V (A for a current): the upper Schmitt threshold.
    pub high: f64,
    /// Most Schmitt edges allowed (1 = one clean transition).
    #[serde(default)]
    pub max_edges: Option<u64>,
    /// Most glitches allowed (edges − 1).
    #[serde(default)]
    pub max_glitches: Option<u64>,
    /// Largest |value| allowed, in the signal's unit (inrush, spikes).
    #[serde(default)]
    pub max_peak: Option<f64>,
    /// Highest value allowed (e.g. an input's absolute maximum rating).
    #[serde(default)]
    pub max_value: Option<f64>,
    /// Lowest value allowed (e.g. −0.3 V below ground on an input).
    #[serde(default)]
    pub min_value: Option<f64>,
    /// s, the last edge must come by then (the signal has settled). Timed
    /// from t = 0, so it includes the operate time; `max_lockout` does not.
    #[serde(default)]
    pub max_last_edge: Option<f64>,
    /// s, the longest debounce lockout allowed: last edge − first edge (a
    /// debouncer that ignores its input for T after the first edge needs
    /// T > lockout).
    #[serde(default)]
    pub max_lockout: Option<f64>,
    /// s, the longest time allowed between two consecutive edges (a
    /// debouncer that waits for a stable input for T needs T > stable_for).
    #[serde(default)]
    pub max_stable_for: Option<f64>,
    /// Hold `max_peak`, `max_value` and `min_value` against the range
    /// without the integrator's ringing right after a contact edge
    /// (samples that alternate from one time point to the next), instead
    /// of against every sample (the default).
    #[serde(default)]
    pub ignore_ringing: bool,
}

impl Probe {
    /// A probe with thresholds and no limits.
    pub fn new(signal: impl Into<String>, low: f64, high: f64) -> Probe {
        Probe {
            signal: signal.into(),
            low,
            high,
            ..Probe::default()
        }
    }

    /// Whether any limit is set.
    pub fn has_limits(&self) -> bool {
        self.max_edges.is_some()
            || self.max_glitches.is_some()
            || self.max_peak.is_some()
            || self.max_value.is_some()
            || self.min_value.is_some()
            || self.max_last_edge.is_some()
            || self.max_lockout.is_some()
            || self.max_stable_for.is_some()
    }
}

impl Check<'_> {
    pub(super) fn probe(&self, i: usize, p: &Probe) -> Result<(), ScenarioError> {
        let key = |name: &str| format!("probe[{i}].{name}");
        self.not_empty(
            &key("signal"),
            &p.signal,
            "an ngspice vector name such as \"v(in)\"",
        )?;
        self.number(&key("high"), p.high, true, "")?;
        self.number(
            &key("low"),
            p.low,
            p.low < p.high,
            format!(
                "must be below `probe[{i}].high` = {:?} V: the Schmitt thresholds need low < high",
                p.high
            ),
        )?;
        if let Some(v) = p.max_peak {
            self.number(
                &key("max_peak"),
                v,
                v > 0.0,
                "must be > 0: the largest |value| allowed, in the signal's unit",
            )?;
        }
        if let Some(v) = p.max_last_edge {
            self.number(
                &key("max_last_edge"),
                v,
                v > 0.0,
                "must be > 0: the time by which the signal must have settled, in s",
            )?;
        }
        for (name, value) in [
            ("max_lockout", p.max_lockout),
            ("max_stable_for", p.max_stable_for),
        ] {
            if let Some(v) = value {
                self.number(
                    &key(name),
                    v,
                    v > 0.0,
                    "must be > 0: a debouncer's time, in s",
                )?;
            }
        }
        if let Some(v) = p.max_value {
            self.number(&key("max_value"), v, true, "")?;
        }
        if let Some(v) = p.min_value {
            let max = p.max_value.unwrap_or(f64::INFINITY);
            self.number(
                &key("min_value"),
                v,
                v < max,
                format!("must be below `probe[{i}].max_value` = {max:?}"),
            )?;
        }
        Ok(())
    }
}
