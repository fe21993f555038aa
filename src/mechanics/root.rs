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
