//! From a trace to the contact's states: two levels from the trace itself,
//! hysteresis thresholds between them, and each edge timed at the 50 %
//! crossing.
//!
//! - **Levels**: the two most populated bins of a 200-bin histogram of the
//!   values that lie at least a third of the range apart, each refined to
//!   the mean of the samples in its bin and its neighbours. Ringing,
//!   noise and quantisation spread a level over a few bins but do not move
//!   its mode; a capture that is mostly one level still has the other as
//!   the second mode.
//! - **Thresholds**: 30 % and 70 % of the way from the lower level to the
//!   higher (or the user's). An edge is a crossing of the far threshold
//!   after the near one: an excursion that does not cross both (ringing at
//!   a make, noise) is no edge.
//! - **Timing**: with the default thresholds, the last crossing of the
//!   50 % level before the threshold crossing, interpolated between its
//!   two samples (the contact's own instant, for a sharp edge). With the
//!   user's thresholds, the crossing of the far threshold itself: the
//!   instant a Schmitt input with those thresholds switches, so that on a
//!   slow (RC) edge the times follow the thresholds the user gave.
//! - **Polarity**: the level the trace ends on is closed (a capture of a
//!   closing ends closed), unless the user says which.

use crate::chatter::{ContactState, Interval};

/// Which level means closed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Closed {
    /// The higher of the two levels means closed.
    High,
    /// The lower of the two levels means closed.
    Low,
}

/// What the trace shows.
#[derive(Debug, Clone, PartialEq)]
pub struct Edges {
    /// The open level, in the trace's unit.
    pub open: f64,
    /// The closed level, in the trace's unit.
    pub closed: f64,
    /// The lower hysteresis threshold (low < high), in the trace's unit.
    pub low: f64,
    /// The upper hysteresis threshold, in the trace's unit.
    pub high: f64,
    /// s, every make, in order.
    pub makes: Vec<f64>,
    /// s, every break, in order.
    pub breaks: Vec<f64>,
    /// The contact's states from the first sample to the last.
    pub intervals: Vec<Interval>,
}

/// Why a trace has no chatter to find.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EdgeError {
    /// Every sample has the same value.
    #[error("the trace is flat ({value} throughout): there is no second level to find")]
    Flat {
        /// The trace's only value.
        value: f64,
    },
    /// The two most populated levels are within the trace's noise (or a
    /// few steps of its resolution): the trace shows one level only.
    #[error(
        "the trace stays at one level ({level}, noise σ {noise}): its other values (up to \
         {other}) are within the noise, so it shows no make or break; check the channel \
         (--channel) and that the capture caught the closing"
    )]
    OneLevel {
        /// The level the trace stays at.
        level: f64,
        /// The other candidate level, within the noise of `level`.
        other: f64,
        /// The trace's noise, 1σ.
        noise: f64,
    },
    /// The user's thresholds are not finite with `low < high`.
    #[error(
        "the thresholds low = {low} and high = {high} must be finite with low < high, \
         in the trace's unit"
    )]
    Thresholds {
        /// The lower threshold given.
        low: f64,
        /// The upper threshold given.
        high: f64,
    },
}

/// The two levels of `value`, lower first.
pub fn levels(value: &[f64]) -> Result<(f64, f64), EdgeError> {
    const BINS: usize = 200;
    let (min, max) = value
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if max.partial_cmp(&min) != Some(std::cmp::Ordering::Greater) {
        return Err(EdgeError::Flat { value: min });
    }
    let width = (max - min) / BINS as f64;
    let bin = |v: f64| (((v - min) / width) as usize).min(BINS - 1);
    let mut counts = [0usize; BINS];
    for &v in value {
        counts[bin(v)] += 1;
    }
    let first = (0..BINS)
        .max_by_key(|&i| (counts[i], std::cmp::Reverse(i)))
        .unwrap_or(0);
    let apart = BINS / 3;
    let second = (0..BINS)
        .filter(|&i| i.abs_diff(first) >= apart)
        .max_by_key(|&i| (counts[i], std::cmp::Reverse(i)))
        .unwrap_or(if first < BINS / 2 { BINS - 1 } else { 0 });
    let refine = |b: usize| {
        let (lo, hi) = (b.saturating_sub(1), (b + 1).min(BINS - 1));
        let (sum, n) = value
            .iter()
            .filter(|&&v| (lo..=hi).contains(&bin(v)))
            .fold((0.0, 0usize), |(s, n), &v| (s + v, n + 1));
        if n == 0 {
            min + (b as f64 + 0.5) * width
        } else {
            sum / n as f64
        }
    };
    let (a, b) = (refine(first), refine(second));
    let (lower, upper) = if a < b { (a, b) } else { (b, a) };
    let (noise, quantum) = spread(value, 0.5 * (lower + upper));
    if upper - lower < (LEVEL_NOISE_RATIO * noise).max(LEVEL_QUANTA * quantum) {
        return Err(EdgeError::OneLevel {
            level: if a < b { lower } else { upper },
            other: if a < b { upper } else { lower },
            noise,
        });
    }
    Ok((lower, upper))
}

/// Two levels must lie this many noise σ apart: a flat trace's noise puts
/// its "second mode" 3 to 5 σ from the first.
const LEVEL_NOISE_RATIO: f64 = 10.0;
/// ... and this many steps of the trace's resolution (an 8-bit scope's
/// flat trace flickers between two adjacent codes).
const LEVEL_QUANTA: f64 = 4.0;

/// The noise (σ, from the median absolute deviation of the samples on each
/// side of `mid`, the larger of the two) and the resolution (the smallest
/// step between distinct values) of `value`.
fn spread(value: &[f64], mid: f64) -> (f64, f64) {
    let mad = |mut side: Vec<f64>| {
        if side.is_empty() {
            return 0.0;
        }
        let n = side.len() / 2;
        let median = *side.select_nth_unstable_by(n, f64::total_cmp).1;
        let mut deviations: Vec<f64> = side.iter().map(|v| (v - median).abs()).collect();
        *deviations.select_nth_unstable_by(n, f64::total_cmp).1
    };
    let below: Vec<f64> = value.iter().copied().filter(|&v| v < mid).collect();
    let above: Vec<f64> = value.iter().copied().filter(|&v| v >= mid).collect();
    // σ of a normal distribution from its MAD.
    let noise = 1.4826 * mad(below).max(mad(above));
    let mut sorted = value.to_vec();
    sorted.sort_unstable_by(f64::total_cmp);
    let quantum = sorted
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|&d| d > 0.0)
        .fold(f64::INFINITY, f64::min);
    (noise, if quantum.is_finite() { quantum } else { 0.0 })
}

/// The edges of (`time`, `value`): thresholds `low`/`high` (default 30 %
/// and 70 % between the levels), closed level per `closed` (default: the
/// one the trace ends nearer to). With the default thresholds each edge
/// is timed at its 50 % crossing; with given ones, at its crossing of the
/// far threshold (`low` going down, `high` going up).
pub fn edges(
    time: &[f64],
    value: &[f64],
    thresholds: Option<(f64, f64)>,
    closed: Option<Closed>,
) -> Result<Edges, EdgeError> {
    if let Some((low, high)) = thresholds
        && !(low.is_finite() && high.is_finite() && low < high)
    {
        return Err(EdgeError::Thresholds { low, high });
    }
    let (lower, upper) = match (levels(value), thresholds) {
        (Ok(levels), _) => levels,
        // The user's thresholds say where the edges are even when the
        // trace shows no two clear levels (slow RC edges that never
        // settle): the levels are then those of the samples beyond them.
        (Err(e @ EdgeError::OneLevel { .. }), Some((low, high))) => {
            levels_beyond(value, low, high).ok_or(e)?
        }
        (Err(e), _) => return Err(e),
    };
    let (low, high) =
        thresholds.unwrap_or((lower + 0.3 * (upper - lower), lower + 0.7 * (upper - lower)));
    // Where an edge is timed: the 50 % level, or the far threshold.
    let given = thresholds.is_some();
    let mid = 0.5 * (low + high);
    let timing = |up: bool| match (given, up) {
        (false, _) => mid,
        (true, true) => high,
        (true, false) => low,
    };
    // Schmitt states: Some(true) high, Some(false) low, None not yet known.
    let mut state = if value[0] >= high {
        Some(true)
    } else if value[0] <= low {
        Some(false)
    } else {
        None
    };
    let initial = state;
    let mut transitions: Vec<(f64, bool)> = Vec::new();
    for k in 1..value.len() {
        let v = value[k];
        let to = if v >= high && state != Some(true) {
            Some(true)
        } else if v <= low && state != Some(false) {
            Some(false)
        } else {
            None
        };
        let Some(up) = to else { continue };
        if state.is_some() {
            transitions.push((mid_crossing(time, value, k, timing(up), up), up));
        }
        state = Some(up);
    }
    let ends_high = state.unwrap_or(value[value.len() - 1] >= mid);
    let closed_high = match closed {
        Some(Closed::High) => true,
        Some(Closed::Low) => false,
        None => ends_high,
    };
    let start_high = initial.unwrap_or_else(|| transitions.first().map_or(ends_high, |t| !t.1));
    let state_of = |high: bool| {
        if high == closed_high {
            ContactState::Closed
        } else {
            ContactState::Open
        }
    };
    let mut intervals = Vec::with_capacity(transitions.len() + 1);
    let mut since = time[0];
    let mut current = start_high;
    let (mut makes, mut breaks) = (Vec::new(), Vec::new());
    for &(t, up) in &transitions {
        let t = t.max(since);
        intervals.push(Interval {
            state: state_of(current),
            start: since,
            end: t,
        });
        if state_of(up) == ContactState::Closed {
            makes.push(t);
        } else {
            breaks.push(t);
        }
        since = t;
        current = up;
    }
    intervals.push(Interval {
        state: state_of(current),
        start: since,
        end: time[time.len() - 1],
    });
    let (open, closed_level) = if closed_high {
        (lower, upper)
    } else {
        (upper, lower)
    };
    Ok(Edges {
        open,
        closed: closed_level,
        low,
        high,
        makes,
        breaks,
        intervals,
    })
}

/// The means of the samples at or below `low` and at or above `high`, when
/// there are both: the levels of a trace read with the user's thresholds.
fn levels_beyond(value: &[f64], low: f64, high: f64) -> Option<(f64, f64)> {
    let mean = |keep: &dyn Fn(f64) -> bool| {
        let (sum, n) = value
            .iter()
            .filter(|&&v| keep(v))
            .fold((0.0, 0usize), |(s, n), &v| (s + v, n + 1));
        (n > 0).then(|| sum / n as f64)
    };
    Some((mean(&|v| v <= low)?, mean(&|v| v >= high)?))
}

/// The time the signal last crossed `mid` (going `up`) at or before sample
/// `k`, where it crossed the far threshold: linear between the samples.
fn mid_crossing(time: &[f64], value: &[f64], k: usize, mid: f64, up: bool) -> f64 {
    let past = |v: f64| if up { v >= mid } else { v <= mid };
    let mut j = k;
    while j > 0 && past(value[j - 1]) {
        j -= 1;
    }
    if j == 0 {
        return time[0];
    }
    let (t0, t1, v0, v1) = (time[j - 1], time[j], value[j - 1], value[j]);
    if v1 == v0 {
        return t1;
    }
    t0 + (mid - v0) / (v1 - v0) * (t1 - t0)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat trace with noise, or flickering between two codes of an
    /// 8-bit scope, shows no contact: refused, not read as hundreds of
    /// bounces. The same noise on a real 3.3 V step is read.
    #[test]
    fn noise_on_one_level_is_not_a_second_level() {
        let n = 20_000;
        // A deterministic pseudo-random sequence, roughly normal (sum of 4 uniforms).
        let mut state = 12345u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let noise: Vec<f64> = (0..n)
            .map(|_| 1e-3 * ((0..4).map(|_| uniform()).sum::<f64>() - 2.0) * 1.732)
            .collect();
        let flat: Vec<f64> = noise.iter().map(|e| 3.3 + e).collect();
        let err = levels(&flat).unwrap_err();
        assert!(matches!(err, EdgeError::OneLevel { .. }), "{err:?}");
        let codes: Vec<f64> = (0..n)
            .map(|i| if i % 7 == 3 { 3.32 } else { 3.30 })
            .collect();
        assert!(matches!(levels(&codes), Err(EdgeError::OneLevel { .. })));
        let step: Vec<f64> = noise
            .iter()
            .enumerate()
            .map(|(i, e)| if i < n / 10 { *e } else { 3.3 + e })
            .collect();
        let (lo, hi) = levels(&step).unwrap();
        assert!(lo.abs() < 1e-3 && (hi - 3.3).abs() < 1e-3, "{lo} {hi}");
    }

    #[test]
    fn levels_of_a_noisy_two_level_trace() {
        let v: Vec<f64> = (0..1000)
            .map(|i| if i < 300 { 5.0 } else { 0.02 } + 0.05 * ((i * 7919) % 13) as f64 / 13.0)
            .collect();
        let (lo, hi) = levels(&v).unwrap();
        assert!(
            (lo - 0.045).abs() < 0.03 && (hi - 5.025).abs() < 0.03,
            "{lo} {hi}"
        );
        assert!(levels(&[1.0; 10]).is_err());
    }

    /// An RC-shaped trace: 5 V open, a make at 100 µs falling toward
    /// 0.02 V with τ = 5 µs, a break at 200 µs rising back with τ = 20 µs,
    /// a make at 400 µs; sampled every 20 ns. Returns the trace and the
    /// closed-form crossing times of `low` (the falls) and `high` (the
    /// rise).
    fn rc_trace(low: f64, high: f64) -> (Vec<f64>, Vec<f64>, [f64; 3]) {
        let (open, closed, tf, tr) = (5.0, 0.02, 5e-6, 20e-6);
        let (make1, brk, make2) = (100e-6, 200e-6, 400e-6);
        let fall = |t: f64, from: f64, v0: f64| closed + (v0 - closed) * (-(t - from) / tf).exp();
        let rise = |t: f64, from: f64, v0: f64| open - (open - v0) * (-(t - from) / tr).exp();
        let at_break = fall(brk, make1, open);
        let at_make2 = rise(make2, brk, at_break);
        let value_at = |t: f64| match t {
            t if t < make1 => open,
            t if t < brk => fall(t, make1, open),
            t if t < make2 => rise(t, brk, at_break),
            t => fall(t, make2, at_make2),
        };
        let time: Vec<f64> = (0..30_000).map(|k| k as f64 * 20e-9).collect();
        let value = time.iter().map(|&t| value_at(t)).collect();
        let crossings = [
            make1 + tf * ((open - closed) / (low - closed)).ln(),
            brk + tr * ((open - at_break) / (open - high)).ln(),
            make2 + tf * ((at_make2 - closed) / (low - closed)).ln(),
        ];
        (time, value, crossings)
    }

    #[test]
    fn given_thresholds_time_an_rc_edge_where_it_crosses_them() {
        let mut seen = Vec::new();
        // Pairs sharing a midpoint too: their 50 % times would coincide.
        for (low, high) in [(1.0, 4.0), (2.0, 3.0), (0.5, 1.0), (4.0, 4.5)] {
            let (time, value, want) = rc_trace(low, high);
            let e = edges(&time, &value, Some((low, high)), None).unwrap();
            assert_eq!((e.low, e.high), (low, high));
            let got = [e.makes[0], e.breaks[0], e.makes[1]];
            assert_eq!((e.makes.len(), e.breaks.len()), (2, 1), "{low}/{high}");
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (g - w).abs() < 1e-9,
                    "{low}/{high}: edge at {g}, crossing at {w}"
                );
            }
            seen.push(got);
        }
        // The edges move with the thresholds, (1, 4) and (2, 3) included.
        for i in 0..seen.len() {
            for j in 0..i {
                assert!(
                    seen[i]
                        .iter()
                        .zip(&seen[j])
                        .all(|(a, b)| (a - b).abs() > 1e-7),
                    "{seen:?}"
                );
            }
        }
        // The default thresholds still time each edge at its 50 % level.
        let (time, value, _) = rc_trace(1.0, 4.0);
        let e = edges(&time, &value, None, None).unwrap();
        let mid = 0.5 * (e.low + e.high);
        let want = 100e-6 + 5e-6 * ((5.0 - 0.02) / (mid - 0.02)).ln();
        assert!((e.makes[0] - want).abs() < 1e-8, "{} vs {want}", e.makes[0]);
    }

    /// Edges too slow to settle leave no two clear levels: refused with
    /// the default thresholds, read with the user's.
    #[test]
    fn given_thresholds_read_a_trace_without_two_clear_levels() {
        let tau = 50e-6;
        let time: Vec<f64> = (0..4000).map(|k| k as f64 * 0.1e-6).collect();
        let value: Vec<f64> = time
            .iter()
            .map(|&t| {
                // Open, a make at 50 µs and a break at 250 µs, both slow.
                if t < 50e-6 {
                    5.0
                } else if t < 250e-6 {
                    5.0 * (-(t - 50e-6) / tau).exp()
                } else {
                    let v0 = 5.0 * (-200e-6 / tau).exp();
                    5.0 - (5.0 - v0) * (-(t - 250e-6) / tau).exp()
                }
            })
            .collect();
        let auto = edges(&time, &value, None, None);
        assert!(matches!(auto, Err(EdgeError::OneLevel { .. })), "{auto:?}");
        let e = edges(&time, &value, Some((1.0, 4.0)), Some(Closed::Low)).unwrap();
        assert_eq!(
            (e.makes.len(), e.breaks.len()),
            (1, 1),
            "{e:?} (auto: {auto:?})"
        );
        let make = 50e-6 + tau * 5.0f64.ln();
        assert!((e.makes[0] - make).abs() < 1e-9, "{} vs {make}", e.makes[0]);
        assert!(e.closed < 1.0 && e.open > 4.0, "{e:?}");
    }

    #[test]
    fn ringing_that_does_not_cross_both_thresholds_is_no_edge() {
        // 5 V open, a make at t = 10 with ringing down to 1.2 V (between
        // 30 % = 1.5 V and 50 %): one make.
        let time: Vec<f64> = (0..40).map(f64::from).collect();
        let value: Vec<f64> = (0..40)
            .map(|i| match i {
                i if i < 10 => 5.0,
                10 => 0.5,
                12 => 1.2,
                14 => 1.2,
                _ => 0.0,
            })
            .collect();
        let e = edges(&time, &value, None, None).unwrap();
        assert_eq!(e.makes.len(), 1);
        assert!(e.breaks.is_empty());
        // 50 % = 2.5 V between 5 V at t = 9 and 0.5 V at t = 10.
        assert!(
            (e.makes[0] - (9.0 + 2.5 / 4.5)).abs() < 1e-12,
            "{:?}",
            e.makes
        );
        assert_eq!(e.closed, 0.0);
        assert_eq!(e.intervals[0].state, ContactState::Open);
    }
}
