//! A two-stage run: how far it goes ([`Horizon`]) and what it returns
//! ([`TwoStageRun`]): the records of the contact, the pole face and the
//! rest stop, the strokes, and the motion step by step.

use super::span::{Span, state_at};
use crate::chatter::{Chatter, Impact};
use crate::mechanics::cycle::Stroke;

/// How far a run goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Horizon {
    /// One closing, stopped where its ending is decided (the drive is
    /// taken not to weaken afterwards).
    Closing,
    /// The whole run to `t_end`: releases and returns to the rest stop
    /// included.
    Cycle,
}

/// A two-stage run.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoStageRun {
    /// The contact's record: the blade's contact point on the fixed
    /// contact (the armature's without a blade), both bursts.
    pub contact: Chatter,
    /// The armature's impacts on the pole face, in time order (velocities
    /// of the armature; a release velocity is negative, away from it).
    pub pole_face: Vec<Impact>,
    /// The armature on its rest stop (the normally-closed side): its
    /// landings (a driven cycle only; empty under a step force).
    pub back: Chatter,
    /// Every stroke of the armature (a driven run).
    pub strokes: Vec<Stroke>,
    /// s, the first lift-off from the rest stop.
    pub lift_off: Option<f64>,
    /// Integration steps taken.
    pub steps: usize,
    /// The motion, step by step, for the armature's trajectory.
    pub(crate) pieces: Vec<Span>,
}

impl TwoStageRun {
    /// (m, m/s, m, m/s): armature position and velocity, blade contact
    /// point position and velocity at `t` (s), held at the ends.
    pub fn state(&self, t: f64, gap: f64) -> (f64, f64, f64, f64) {
        let y = state_at(&self.pieces, t);
        (gap + y[0], y[1], gap + y[2], y[3])
    }
}
