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

/// A root of `f` in `[lo, hi]`, which must bracket a sign change, by
/// Newton iteration safeguarded with bisection: a Newton step is taken
/// only when it lands inside the current bracket and shrinks faster than
/// bisection would. `f` returns the value and its derivative. Converges to
/// a few ulps of the root (the bracket never widens, so it cannot
/// diverge); returns the better end if the bracket is not a sign change.
pub fn newton_bracketed(f: impl Fn(f64) -> (f64, f64), mut lo: f64, mut hi: f64) -> f64 {
    let (flo, _) = f(lo);
    let (fhi, _) = f(hi);
    if flo == 0.0 {
        return lo;
    }
    if fhi == 0.0 {
        return hi;
    }
    if flo.signum() == fhi.signum() {
        return if flo.abs() < fhi.abs() { lo } else { hi };
    }
    let rising = flo < 0.0;
    let mut t = 0.5 * (lo + hi);
    let mut step_before = hi - lo;
    let mut step = step_before;
    let (mut ft, mut dft) = f(t);
    for _ in 0..300 {
        if ft == 0.0 {
            return t;
        }
        let newton = if dft != 0.0 { t - ft / dft } else { f64::NAN };
        let fast = (2.0 * ft).abs() <= (step_before * dft).abs();
        step_before = step;
        if newton > lo && newton < hi && fast {
            step = t - newton;
            t = newton;
        } else {
            step = 0.5 * (hi - lo);
            t = lo + step;
        }
        let tol = 4.0 * f64::EPSILON * t.abs().max(f64::MIN_POSITIVE);
        if step.abs() <= tol || hi - lo <= tol {
            return t;
        }
        (ft, dft) = f(t);
        if (ft < 0.0) == rising {
            lo = t;
        } else {
            hi = t;
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn newton_finds_cosine_root_to_ulps() {
        let r = newton_bracketed(|t| (t.cos(), -t.sin()), 1.0, 2.0);
        assert!((r - std::f64::consts::FRAC_PI_2).abs() < 1e-15);
    }

    #[test]
    fn newton_survives_a_flat_start_and_decreasing_function() {
        // x³ has a zero derivative at its root: Newton alone crawls.
        let r = newton_bracketed(|t| (-(t - 0.3).powi(3), -3.0 * (t - 0.3).powi(2)), 0.0, 1.0);
        assert!((r - 0.3).abs() < 1e-5, "{r}");
    }

    #[test]
    fn bisect_refuses_a_non_bracket() {
        assert_eq!(bisect(|t| t * t + 1.0, -1.0, 1.0, 1e-12), None);
        let r = bisect(|t| t - 0.25, 0.0, 1.0, 1e-15).unwrap();
        assert!((r - 0.25).abs() < 1e-15);
    }
}
