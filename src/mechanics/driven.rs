//! What the integrated engines (the cycle engine and the two-stage
//! engine) share with their users: the `DriveModel` trait (a force that
//! varies in time and position and may carry a state of its own, such as
//! the coil's flux), the state the cycle engine integrates, a view of one
//! of its steps (`Piece`) and the event-location numerics.
//!
//! The state is `(u, v, e)`: `u = x − g` (m, the position relative to the
//! fixed contact, so that the µm penetrations keep their precision), the
//! velocity `v` (m/s) and the drive's state `e`. Each phase of the motion
//! is integrated by `Dopri5` from the exact event state that started it.
//!
//! Events are never read off samples. Each accepted step is split at the
//! velocity zero it may contain (x is monotonic on each part,
//! `monotone_parts`), a level crossing is bracketed by the values at the
//! ends of a monotonic part, and located by bisection on the step's
//! interpolant down to adjacent floats (`first_true`); the state after
//! an event is the interpolated state *at* the event time with `u` set
//! exactly to the level. Turning points and force extrema are found the
//! same way, as sign changes of the velocity and of the force rate
//! (`sign_change`). Steps are far shorter than any oscillation (≈ 1000 a
//! period at the tolerance used), so a part holds at most one sign change.

use crate::mechanics::linalg::Vector3;

use super::error::DriveError;
use super::integrate::{Dopri5Step, StepTolerance};
use super::parameters::Mechanics;

/// `(u = x − g, v, e)`: m, m/s, and the drive's own state.
pub(crate) type State = Vector3<f64>;

/// Relative tolerance of the integration. At 1e-11 the impact times of a
/// whole sequence agree with the closed-form engine to ~1e-9.
pub(crate) const RTOL: f64 = 1e-11;

/// What pushes the armature toward the fixed contact, as the integrated
/// engines take it: a force with a state of its own and the work the
/// sticking tests need. A trajectory's public `Drive` (a step, or a force
/// `F(t, x)`) becomes one of these; so does the coil on its source.
pub(crate) trait DriveModel {
    /// N, the force toward closing at time `t` (s), position `x` (m) and
    /// drive state `e`.
    fn force(&self, t: f64, x: f64, e: f64) -> f64;
    /// de/dt.
    fn rate(&self, t: f64, x: f64, e: f64) -> f64;
    /// J, the work of the drive frozen in its state at (t, x = `to`, e)
    /// on an armature moving from `from` to `to` (m): the sticking test's
    /// `∫ F dξ`.
    fn frozen_work(&self, t: f64, e: f64, from: f64, to: f64) -> f64;
    /// The scale of `e` for its absolute tolerance.
    fn e_scale(&self) -> f64;
    /// s, the time scale of `e` while the armature is held.
    fn time_scale(&self) -> f64;
    /// m, the largest position the model holds for (the pole face).
    fn pole(&self) -> f64;
    /// J, the work of the drive with its state `e` held (its own dynamics
    /// stopped) on an armature moving from `from` to `to` (m): the
    /// potential of the energy bound that ends a two-stage closing. By
    /// default [`DriveModel::frozen_work`].
    fn held_work(&self, t: f64, e: f64, from: f64, to: f64) -> f64 {
        self.frozen_work(t, e, from, to)
    }
    /// N, the force when it is a constant (the step drive), which lets an
    /// engine solve the motion in closed form; `None` otherwise.
    fn constant(&self) -> Option<f64> {
        None
    }
}

/// Which equations a step integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum StepKind {
    Held,
    Flight,
    Contact,
}

/// One accepted step, cut at the event that ended its phase: valid on
/// `[step.t0, t1]`, where the state is `y1` (the exact event state for
/// the last step of a phase). A view of a trajectory's segment.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Piece<'a> {
    pub phase: StepKind,
    pub step: &'a Dopri5Step<3>,
    pub t1: f64,
    pub y1: State,
}

impl Piece<'_> {
    /// s, where the piece starts.
    pub fn t0(&self) -> f64 {
        self.step.t0
    }

    /// The state at the start.
    pub fn y0(&self) -> State {
        self.step.y0
    }

    /// The interpolated state at `t` in `[t0, t1]`, exact at the ends.
    pub fn at(&self, t: f64) -> State {
        if t == self.t1 {
            self.y1
        } else {
            state_on(self.step, t)
        }
    }
}

/// The integration tolerance for `m` under `drive`, once the drive is
/// known to be finite where the run starts (drive state `e0`).
pub(crate) fn start_tolerance<D: DriveModel>(
    m: &Mechanics,
    drive: &D,
    e0: f64,
) -> Result<StepTolerance<3>, DriveError> {
    let x0 = m.initial_position;
    let f0 = drive.force(0.0, x0, e0);
    if !f0.is_finite() {
        return Err(DriveError::DriveNotFinite {
            time: 0.0,
            position: x0,
            value: f0,
        });
    }
    let omega = (m.stiffness / m.mass).sqrt();
    Ok(StepTolerance {
        rtol: RTOL,
        atol: State::new(RTOL * m.gap, RTOL * m.gap * omega, RTOL * drive.e_scale()),
    })
}

/// The first time in `[lo, hi]` at which `cond` holds, given that it does
/// not at `lo` and does at `hi`: bisection down to adjacent floats, so the
/// answer is the upper end of a bracket no wider than one ulp.
pub(crate) fn first_true(cond: impl Fn(f64) -> bool, mut lo: f64, mut hi: f64) -> f64 {
    loop {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            return hi;
        }
        if cond(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
}

/// Where `f` changes sign strictly between `lo` and `hi` (opposite
/// signs at the ends), bisected to adjacent floats; `None` otherwise.
pub(crate) fn sign_change(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> Option<f64> {
    let (a, b) = (f(lo), f(hi));
    if !((a > 0.0 && b < 0.0) || (a < 0.0 && b > 0.0)) {
        return None;
    }
    let falling = a > 0.0;
    Some(first_true(
        |t| {
            let r = f(t);
            if falling { r <= 0.0 } else { r >= 0.0 }
        },
        lo,
        hi,
    ))
}

/// A step split at the velocity zero it may contain.
pub(crate) struct MonotoneParts {
    bounds: [(f64, f64); 2],
    n: usize,
    /// (time, state) of the turning point, if any.
    pub turn: Option<(f64, State)>,
}

impl MonotoneParts {
    /// The one or two time spans on which x is monotonic, in order.
    pub fn spans(&self) -> &[(f64, f64)] {
        &self.bounds[..self.n]
    }
}

/// The step split at the velocity zero it may contain: up to two parts,
/// each with x monotonic, and the turning point if any.
pub(crate) fn monotone_parts(step: &Dopri5Step<3>) -> MonotoneParts {
    let (v0, v1) = (step.y0[1], step.y1[1]);
    if (v0 > 0.0 && v1 < 0.0) || (v0 < 0.0 && v1 > 0.0) {
        let up = v0 > 0.0;
        let tz = first_true(
            |t| {
                let v = step.at(t)[1];
                if up { v <= 0.0 } else { v >= 0.0 }
            },
            step.t0,
            step.t1,
        );
        let yz = step.at(tz);
        MonotoneParts {
            bounds: [(step.t0, tz), (tz, step.t1)],
            n: 2,
            turn: Some((tz, yz)),
        }
    } else {
        MonotoneParts {
            bounds: [(step.t0, step.t1), (0.0, 0.0)],
            n: 1,
            turn: None,
        }
    }
}

/// The state on `step` at `t`, exact at its ends.
pub(crate) fn state_on(step: &Dopri5Step<3>, t: f64) -> State {
    if t == step.t0 {
        step.y0
    } else if t == step.t1 {
        step.y1
    } else {
        step.at(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::Surface;
    use crate::mechanics::surface::{surface_energy, surface_force, surface_loss};

    #[test]
    fn first_true_brackets_to_one_ulp() {
        let t = first_true(|t| t >= 0.3, 0.0, 1.0);
        assert!(t >= 0.3);
        assert!(f64::from_bits(t.to_bits() - 1) < 0.3);
        // The answer is the upper end: the condition holds there.
        let t = first_true(|t| t * t >= 2.0, 1.0, 2.0);
        assert!(t * t >= 2.0 && (t - 2f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn surface_power_splits_into_stored_and_lost() {
        // Fc·δ̇ = d/dt(stored energy) + loss, for every law, on and off
        // the clamp of Hunt–Crossley.
        let surfaces = [
            Surface::KelvinVoigt {
                stiffness: 8e4,
                damping: 0.4,
            },
            Surface::HuntCrossley {
                stiffness: 1e9,
                exponent: 1.5,
                chi: 0.5,
            },
        ];
        for s in surfaces {
            for (u, v) in [(1e-6, 0.3), (2e-6, -0.2), (2e-6, -3.0)] {
                let h = 1e-12;
                let stored_rate =
                    (surface_energy(&s, u + h * v) - surface_energy(&s, u - h * v)) / (2.0 * h);
                let power = surface_force(&s, u, v) * v;
                let lost = surface_loss(&s, u, v);
                let scale = power.abs() + stored_rate.abs() + lost.abs();
                assert!(
                    (power - stored_rate - lost).abs() < 1e-6 * scale,
                    "{s:?} {u} {v}"
                );
                assert!(lost >= 0.0);
            }
        }
    }
}
