//! Sampled records the coupling passes between the circuit and the
//! mechanics: a path thinned for ngspice, values interpolated at any time,
//! and how far two chatter sequences' events moved.

use crate::chatter::Chatter;
use crate::mechanics::Trajectory;

/// The points of `path` (s, m) that its linear interpolation needs to
/// stay within `tolerance` (m) of every point: the integrator's steps
/// are far denser than the path's shape needs (thousands of them while
/// the contact rests), and each one would be a breakpoint for ngspice.
/// The first and last points are always kept.
pub fn thin(path: &[(f64, f64)], tolerance: f64) -> Vec<(f64, f64)> {
    let Some(&first) = path.first() else {
        return Vec::new();
    };
    let mut out = vec![first];
    let mut start = 0;
    let mut end = 2;
    // The chord from `start` passes within `tolerance` of an intermediate
    // point (t, x) exactly when its slope lies in
    // [(x − tol − x0)/(t − t0), (x + tol − x0)/(t − t0)]: keep the
    // intersection over the points passed so far, one point per step.
    let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
    while end < path.len() {
        let (t0, x0) = path[start];
        let (tm, xm) = path[end - 1];
        let dt = tm - t0;
        if dt > 0.0 {
            lo = lo.max((xm - tolerance - x0) / dt);
            hi = hi.min((xm + tolerance - x0) / dt);
        } else if (xm - x0).abs() > tolerance {
            (lo, hi) = (f64::INFINITY, f64::NEG_INFINITY);
        }
        let (t1, x1) = path[end];
        let slope = (x1 - x0) / (t1 - t0);
        if slope >= lo && slope <= hi {
            end += 1;
        } else {
            start = end - 1;
            out.push(path[start]);
            end = start + 2;
            (lo, hi) = (f64::NEG_INFINITY, f64::INFINITY);
        }
    }
    if path.len() > 1 {
        out.push(path[path.len() - 1]);
    }
    out
}

/// The rest stop's record of a driven cycle.
pub fn back_of(trajectory: &Trajectory) -> &Chatter {
    trajectory
        .back()
        .expect("a driven cycle records its rest stop")
}

/// s, the largest move of an impact or release time between two
/// sequences; infinite when they do not have the same events.
pub fn event_change(a: &Chatter, b: &Chatter) -> f64 {
    if a.impacts.len() != b.impacts.len() {
        return f64::INFINITY;
    }
    let mut change: f64 = 0.0;
    for (p, q) in a.impacts.iter().zip(&b.impacts) {
        change = change.max((p.impact_time - q.impact_time).abs());
        match (p.release_time, q.release_time) {
            (Some(r), Some(s)) => change = change.max((r - s).abs()),
            (None, None) => {}
            _ => return f64::INFINITY,
        }
    }
    change
}

/// Linear interpolation in (time, value) samples, held before the first
/// and after the last, for a caller that asks at times close to the last
/// (an integrator stepping through the record): it first tries the
/// interval of the previous call and its neighbour before searching.
pub struct Interpolator<'a> {
    samples: &'a [(f64, f64)],
    hint: std::cell::Cell<usize>,
}

/// The old name of [`Interpolator`].
#[deprecated(note = "renamed to `Interpolator`")]
pub type Cursor<'a> = Interpolator<'a>;

impl<'a> Interpolator<'a> {
    /// An interpolator over `samples`, (time, value) pairs in increasing time.
    pub fn new(samples: &'a [(f64, f64)]) -> Self {
        Interpolator {
            samples,
            hint: std::cell::Cell::new(1),
        }
    }

    /// The sample value at `t`.
    pub fn at(&self, t: f64) -> f64 {
        let s = self.samples;
        // k is the first index whose time is past t: unique, so a hint
        // that brackets t is the answer the search would give.
        let brackets = |k: usize| k > 0 && k < s.len() && s[k - 1].0 <= t && s[k].0 > t;
        let hint = self.hint.get();
        let k = if brackets(hint) {
            hint
        } else if brackets(hint + 1) {
            hint + 1
        } else {
            s.partition_point(|&(ts, _)| ts <= t)
        };
        self.hint.set(k);
        interpolate_at(s, t, k)
    }
}

/// The value at `t` given `k`, the first sample past `t`.
pub fn interpolate_at(samples: &[(f64, f64)], t: f64, k: usize) -> f64 {
    if k == 0 {
        return samples.first().map_or(0.0, |&(_, v)| v);
    }
    if k == samples.len() {
        return samples[k - 1].1;
    }
    let (t0, v0) = samples[k - 1];
    let (t1, v1) = samples[k];
    if t1 > t0 {
        v0 + (v1 - v0) * (t - t0) / (t1 - t0)
    } else {
        v1
    }
}
