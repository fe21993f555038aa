//! Step-size control shared by the two Runge–Kutta integrators
//! (Dormand–Prince 5(4) and DOP853): the tolerance a step must meet, and
//! the step to try next, refused once it has shrunk to rounding level.

use crate::mechanics::linalg::SVector;

use super::error::MechanicsError;

/// Tolerances: a step is accepted when every component's error estimate
/// is within `atol[i] + rtol·|y[i]|`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepTolerance<const N: usize> {
    /// The relative tolerance, the same for every component.
    pub rtol: f64,
    /// The absolute tolerance of each component, in its unit.
    pub atol: SVector<f64, N>,
}

/// The step to try from `t` with the controller's `h`: cut to land on
/// `t_stop` (then `true`: the last), and an error when the controller has
/// shrunk it to rounding level before getting there.
#[inline(always)]
pub(crate) fn trial_step(h: f64, t: f64, t_stop: f64) -> Result<(f64, bool), MechanicsError> {
    // A step that is not a positive finite number (the state overflowed,
    // or an open-ended integration was handed one) would repeat forever:
    // `min` drops a NaN, and 0.1 × ∞ is ∞.
    if !(h.is_finite() && h > 0.0 && t.is_finite()) {
        return Err(MechanicsError::StepSizeTooSmall { time: t, step: h });
    }
    let mut h = h.min(t_stop - t);
    let last = h >= t_stop - t;
    if last {
        h = t_stop - t;
    }
    let too_small = h.is_nan() || h <= 16.0 * f64::EPSILON * t.abs().max(h.abs());
    if too_small && !last {
        return Err(MechanicsError::StepSizeTooSmall { time: t, step: h });
    }
    Ok((h, last))
}
