//! Bracketed root finding.
//!
//! Events are roots of an exact (or interpolated) trajectory on an interval
//! where the function is known to change sign exactly once, so every root
//! here is bracketed: the answer never leaves the bracket, and the
//! tolerance is on the bracket width.

/// Bisection on `[lo, hi]`, which must bracket a sign change of `f`.
/// Stops when the bracket is narrower than `tol · max(1, |lo|, |hi|)` or
/// cannot be split further. Returns `None` if `f(lo)` and `f(hi)` have the
/// same strict sign.
pub fn bisect(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, tol: f64) -> Option<f64> {
    let mut flo = f(lo);
    let fhi = f(hi);
    if flo == 0.0 {
        return Some(lo);
    }
    if fhi == 0.0 {
        return Some(hi);
    }
    if flo.signum() == fhi.signum() {
        return None;
    }
    for _ in 0..2100 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi || hi - lo <= tol * lo.abs().max(hi.abs()).max(1.0) {
            break;
        }
        let fm = f(mid);
        if fm == 0.0 {
            return Some(mid);
        }
        if fm.signum() == flo.signum() {
            lo = mid;
            flo = fm;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// A root of `f` in `[lo, hi]` by the Illinois variant of regula falsi,
/// for smooth functions known only by value (an interpolated trajectory).
/// `f_lo` and `f_hi` are the values at the ends, of opposite signs (if
/// not, the end nearer zero is returned). Converges superlinearly and
/// never leaves the bracket; stops once the bracket, or the last step, is
/// narrower than `tol` times the original width (a step that small, in
/// superlinear convergence, leaves less than that to the root), returning
/// the last point evaluated.
pub fn illinois(
    f: impl Fn(f64) -> f64,
    (mut lo, mut f_lo): (f64, f64),
    (mut hi, mut f_hi): (f64, f64),
    tol: f64,
) -> f64 {
    if f_lo == 0.0 {
        return lo;
    }
    if f_hi == 0.0 {
        return hi;
    }
    if f_lo.signum() == f_hi.signum() {
        return if f_lo.abs() < f_hi.abs() { lo } else { hi };
    }
    let width = tol * (hi - lo);
    // Which end the last step kept (−1 low, 1 high): halving the value at
    // an end kept twice in a row is what stops plain regula falsi from
    // creeping up on the root from one side.
    let mut kept = 0;
    let mut t = f64::NAN;
    for _ in 0..200 {
        let before = t;
        t = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
        if !(t > lo && t < hi) {
            t = 0.5 * (lo + hi);
        }
        let ft = f(t);
        if ft == 0.0 {
            break;
        }
        if ft.signum() == f_lo.signum() {
            (lo, f_lo) = (t, ft);
            if kept == 1 {
                f_hi *= 0.5;
            }
            kept = 1;
        } else {
            (hi, f_hi) = (t, ft);
            if kept == -1 {
                f_lo *= 0.5;
            }
            kept = -1;
        }
        if hi - lo <= width || (t - before).abs() <= width {
            break;
        }
    }
    t
}

/// A function's value and first two derivatives at `t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet {
    /// Where the function was evaluated.
    pub t: f64,
    /// The value f(t).
    pub f: f64,
    /// The first derivative f'(t).
    pub d1: f64,
    /// The second derivative f''(t).
    pub d2: f64,
}

/// The result of [`halley_bracketed`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Root {
    /// The root.
    pub t: f64,
    /// The last evaluation, within a converged step of `t` (`None` if an
    /// end of the bracket was an exact zero): a caller can extrapolate
    /// from it to `t` instead of evaluating once more.
    pub last: Option<Jet>,
}

/// A root of `f` in `[lo, hi]`, which must bracket a sign change, by
/// Halley iteration safeguarded with bisection. `f_lo` and `f_hi` are the
/// values at the ends, which the caller already has; `start` is a first
/// guess (the midpoint is used if it lies outside the bracket); `f`
/// returns the value and its first two derivatives.
///
/// A Halley step is taken only when it lands inside the current bracket
/// and shrinks faster than bisection would, so the bracket never widens
/// and the iteration cannot diverge. It stops at a step within a few ulps
/// of `t`, or once the cubic convergence rate seen on the last two steps
/// predicts that the next step would be (so a good start costs two or
/// three evaluations). If the ends have the same sign, returns the end
/// nearer zero.
pub fn halley_bracketed(
    f: impl Fn(f64) -> (f64, f64, f64),
    (mut lo, f_lo): (f64, f64),
    (mut hi, f_hi): (f64, f64),
    start: f64,
) -> Root {
    let at_end = |t| Root { t, last: None };
    if f_lo == 0.0 {
        return at_end(lo);
    }
    if f_hi == 0.0 {
        return at_end(hi);
    }
    if f_lo.signum() == f_hi.signum() {
        return at_end(if f_lo.abs() < f_hi.abs() { lo } else { hi });
    }
    let rising = f_lo < 0.0;
    let mut t = if start > lo && start < hi {
        start
    } else {
        0.5 * (lo + hi)
    };
    let mut step_before = hi - lo;
    // The last step, if it was a Halley step (for the convergence rate).
    let mut halley_before = f64::NAN;
    let mut last = None;
    for _ in 0..300 {
        let (ft, d1, d2) = f(t);
        let jet = Jet { t, f: ft, d1, d2 };
        last = Some(jet);
        if ft == 0.0 {
            break;
        }
        if (ft < 0.0) == rising {
            lo = t;
        } else {
            hi = t;
        }
        let tol = 4.0 * f64::EPSILON * t.abs().max(f64::MIN_POSITIVE);
        let step = -2.0 * ft * d1 / (2.0 * d1 * d1 - ft * d2);
        let next = t + step;
        if step.abs() <= tol {
            return Root {
                t: next.clamp(lo, hi),
                last,
            };
        }
        if next > lo && next < hi && 2.0 * step.abs() <= step_before.abs() {
            // Cubic convergence: the next step would be about
            // step·(step/step_before)³.
            let ratio = step / halley_before;
            if (step * ratio * ratio * ratio).abs() <= tol {
                return Root { t: next, last };
            }
            halley_before = step;
            step_before = step;
            t = next;
        } else {
            halley_before = f64::NAN;
            step_before = 0.5 * (hi - lo);
            t = lo + step_before;
            if hi - lo <= tol {
                return Root { t, last };
            }
        }
    }
    Root { t, last }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halley_finds_cosine_root_to_ulps() {
        let f = |t: f64| (t.cos(), -t.sin(), -t.cos());
        for start in [1.0, 1.2, 1.9, 7.0] {
            let r = halley_bracketed(f, (1.0, 1f64.cos()), (2.0, 2f64.cos()), start);
            assert!((r.t - std::f64::consts::FRAC_PI_2).abs() < 1e-15, "{start}");
            assert!((r.last.unwrap().t - r.t).abs() < 1e-4);
        }
    }

    #[test]
    fn halley_survives_a_flat_root_and_decreasing_function() {
        // x³ has zero derivatives at its root: Halley alone crawls.
        let f = |t: f64| {
            let d = t - 0.3;
            (-d * d * d, -3.0 * d * d, -6.0 * d)
        };
        let r = halley_bracketed(f, (0.0, f(0.0).0), (1.0, f(1.0).0), 0.9);
        assert!((r.t - 0.3).abs() < 1e-5, "{}", r.t);
    }

    #[test]
    fn halley_returns_an_exact_end() {
        let f = |t: f64| (t - 1.0, 1.0, 0.0);
        let r = halley_bracketed(f, (0.0, -1.0), (1.0, 0.0), 0.5);
        assert_eq!(r, Root { t: 1.0, last: None });
    }

    #[test]
    fn illinois_converges_on_a_lopsided_function() {
        // Convex on the whole bracket: plain regula falsi keeps the right
        // end forever and crawls.
        let f = |t: f64| t.exp() - 2.0;
        let r = illinois(f, (0.0, f(0.0)), (3.0, f(3.0)), 1e-15);
        assert!((r - 2f64.ln()).abs() < 1e-14, "{r}");
        assert_eq!(illinois(f, (0.0, -1.0), (1.0, -2.0), 1e-15), 0.0);
    }

    #[test]
    fn bisect_refuses_a_non_bracket() {
        assert_eq!(bisect(|t| t * t + 1.0, -1.0, 1.0, 1e-12), None);
        let r = bisect(|t| t - 0.25, 0.0, 1.0, 1e-15).unwrap();
        assert!((r - 0.25).abs() < 1e-15);
    }
}
