//! The two-stage motion piece by piece: one accepted step of either
//! propagator, cut at its event, with how its state is had between its
//! ends (DOP853's dense output, or the exact solution of a linear mode).

use std::sync::Arc;

use super::linear_mode::{LinearMode, W};
use super::model::{StopMode, StopModes, Y};
use crate::mechanics::dop853::Dense;

/// How a piece's state is had between its ends.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Interpolant {
    /// DOP853's dense output of the step.
    Dense(Box<Dense<5>>),
    /// The exact solution of a linear mode from `w0` (scaled deviation
    /// from the mode's equilibrium) at `t0`, over steps of the mode's `h`
    /// from `t0` (the last one shorter).
    Linear { w0: W, mode: Arc<LinearMode> },
}

/// One accepted step, cut at its event: valid on `[t0, t1]`, exact `y1`
/// at `t1`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Span {
    pub motion: Interpolant,
    pub t0: f64,
    pub t1: f64,
    pub y1: Y,
    pub modes: StopModes,
}

impl Span {
    pub(crate) fn dense(dense: Dense<5>, t1: f64, y1: Y, modes: StopModes) -> Span {
        Span {
            t0: dense.t0,
            motion: Interpolant::Dense(Box::new(dense)),
            t1,
            y1,
            modes,
        }
    }

    pub(crate) fn at(&self, t: f64) -> Y {
        if t >= self.t1 {
            return self.y1;
        }
        let t = t.max(self.t0);
        match &self.motion {
            Interpolant::Dense(dense) => dense.at(t),
            Interpolant::Linear { w0, mode } => {
                // Step by step as the propagation went, then within the step.
                let (mut w, mut t0) = (*w0, self.t0);
                while t - t0 > mode.h {
                    w = mode.phi * w;
                    t0 += mode.h;
                }
                mode.y_of(&mode.at(&w, t - t0))
            }
        }
    }

    /// Whether the contact is closed over this piece.
    pub(crate) fn contact_closed(&self) -> bool {
        self.modes.contact != StopMode::Open
    }
}

/// The state at `t` on a run's pieces, held at the ends.
pub(crate) fn state_at(pieces: &[Span], t: f64) -> Y {
    let k = pieces.partition_point(|p| p.t1 < t);
    match pieces.get(k).or(pieces.last()) {
        Some(p) => p.at(t),
        None => Y::zeros(),
    }
}
