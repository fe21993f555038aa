//! The armature's motion piece by piece: a [`Segment`] is a stretch of a
//! trajectory between two instants, with the surface that pushes on the
//! armature there and how it moves (at rest, held over an integrator
//! step, a closed-form piece, an integrated step, a Hunt–Crossley contact
//! step, or a step of the two-stage engine). The engines record their
//! motion as segments; the trajectory reads position, velocity and forces
//! off them.

use super::driven::{Piece, State, StepKind};
use super::hunt_crossley::HcStep;
use super::integrate::Dopri5Step;
use super::linear::LinearPiece;
use super::two_stage::span::Span as StagedSpan;

/// Which surface pushes on the armature over a segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Side {
    Open,
    Make,
    Back,
}

/// How the armature moves over a segment.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum Motion {
    /// At rest at `x` (m) under a constant contact force (N): the step
    /// drive's armature held on the rest stop or pressed on a rigid
    /// contact.
    Rest { x: f64, force: f64 },
    /// Held at `x` (m) by the rest stop or a rigid contact over one
    /// integrator step of the drive's own state, exact at its end `y1`;
    /// the contact force (N) linear from `forces.0` at the start to
    /// `forces.1` at the end.
    Held {
        x: f64,
        step: Dopri5Step<3>,
        y1: State,
        forces: (f64, f64),
    },
    /// A closed-form piece of the step drive, on its own clock from the
    /// segment's start.
    Linear(LinearPiece),
    /// One integrator step in (u = x − g, v, drive state), exact at its
    /// end `y1`.
    Integrated { step: Dopri5Step<3>, y1: State },
    /// One step of a Hunt–Crossley contact under the step drive, touched
    /// at `touch` (s).
    Contact { step: HcStep, touch: f64 },
    /// One step of the two-stage engine: the state is
    /// `(u_a, v_a, u_b, v_b, e)`; the contact point is the blade's.
    Staged(Box<StagedSpan>),
}

/// A stretch of the trajectory between two instants.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Segment {
    pub(super) t0: f64,
    pub(super) t1: f64,
    pub(super) side: Side,
    pub(super) motion: Motion,
}

impl Segment {
    /// The armature at rest at `x` over [t0, t1], pushed by `force` (N)
    /// of the surface it rests on (`on_contact`: the make contact, else
    /// the rest stop).
    pub(super) fn rest(t0: f64, t1: f64, x: f64, on_contact: bool, force: f64) -> Self {
        Segment {
            t0,
            t1,
            side: if on_contact { Side::Make } else { Side::Back },
            motion: Motion::Rest { x, force },
        }
    }

    /// One integrator step of a held armature at `x`, cut at `t1` where
    /// the drive's state is `y1`, pushed by the surface it rests on
    /// (`on_contact`: the make contact, else the rest stop) with `forces`
    /// (N) at the step's start and at `t1`.
    pub(crate) fn held(
        step: Dopri5Step<3>,
        t1: f64,
        y1: State,
        x: f64,
        on_contact: bool,
        forces: (f64, f64),
    ) -> Self {
        Segment {
            t0: step.t0,
            t1,
            side: if on_contact { Side::Make } else { Side::Back },
            motion: Motion::Held {
                x,
                step,
                y1,
                forces,
            },
        }
    }

    /// One integrator step of the cycle, cut at `t1` where the state is
    /// `y1`; `side` is 0 in flight, 1 on the make contact, −1 on the rest
    /// stop.
    pub(crate) fn integrated(step: Dopri5Step<3>, t1: f64, y1: State, side: i8) -> Self {
        Segment {
            t0: step.t0,
            t1,
            side: match side {
                1 => Side::Make,
                -1 => Side::Back,
                _ => Side::Open,
            },
            motion: Motion::Integrated { step, y1 },
        }
    }

    /// The integrator step under this segment as a closing records it:
    /// held, in flight or in the make contact; `None` for a closed-form
    /// piece and for the back stop's contact, which a closing never has.
    pub(crate) fn piece(&self) -> Option<Piece<'_>> {
        let (phase, step, y1) = match &self.motion {
            Motion::Held { step, y1, .. } => (StepKind::Held, step, y1),
            Motion::Integrated { step, y1 } if self.side == Side::Open => {
                (StepKind::Flight, step, y1)
            }
            Motion::Integrated { step, y1 } if self.side == Side::Make => {
                (StepKind::Contact, step, y1)
            }
            _ => return None,
        };
        Some(Piece {
            phase,
            step,
            t1: self.t1,
            y1: *y1,
        })
    }

    /// s, where the segment starts and ends.
    pub(crate) fn span(&self) -> (f64, f64) {
        (self.t0, self.t1)
    }

    /// (s, m): the end of the segment and the position there, for a
    /// contact at `g`.
    pub(crate) fn end_position(&self, g: f64) -> (f64, f64) {
        let x = match &self.motion {
            Motion::Rest { x, .. } | Motion::Held { x, .. } => *x,
            Motion::Linear(piece) => piece.state(self.t1 - self.t0).0,
            Motion::Integrated { y1, .. } => g + y1[0],
            Motion::Contact { step, touch } => g + step.at(self.t1 - touch).0,
            // The armature, whose position sets the coil's inductance.
            Motion::Staged(piece) => g + piece.y1[0],
        };
        (self.t1, x)
    }
}

/// (s, m): `start`, then the position at the end of every segment (the
/// contact at `g`), strictly increasing in time.
pub(crate) fn path_of(start: (f64, f64), segments: &[Segment], g: f64) -> Vec<(f64, f64)> {
    let mut out = Vec::with_capacity(segments.len() + 1);
    out.push(start);
    for segment in segments {
        let (t, x) = segment.end_position(g);
        if out.last().is_none_or(|&(tp, _)| t > tp) {
            out.push((t, x));
        }
    }
    out
}
