//! One closing: the cycle engine stopped where the closing's ending is
//! decided, with the endings of the step-force engine (docs/model.md §4).
//!
//! The cycle runs on to `t_end` whatever happens; a closing asks less. It
//! ends as soon as its outcome is known, on the understanding that the
//! drive does not weaken afterwards (a coil switched on and left on):
//!
//! - **stuck**: a rigid contact that stops the armature dead (restitution
//!   0) while the drive presses it on; a deformable one that, moving out
//!   of the surface, can no longer reach its edge (below);
//! - **resolved**: the opening after a release is shorter than
//!   `min_open_time` or smaller than `min_gap`; the contact is taken as
//!   closed since the last touch, and a rigid surface's endless sequence
//!   sums to its accumulation point `t_r + Δt/(1 − e)`;
//! - **the horizon**, with the drive frozen at its last value so that the
//!   rest of the motion is a closed-form [`LinearPiece`]: in flight it
//!   tells whether the contact would still be reached (`end_of_time`) or
//!   not (`never_closes` with the shortfall, or `ends_open`); in a
//!   Kelvin–Voigt contact, whether it would release (if not, stuck).
//!
//! **Sticking.** With a constant drive the engine's energy argument is
//! exact: `M = ½mv² + W_s(δ) + (s g + p) δ + ½ s δ² − ∫_g^x F dξ`
//! (`W_s` the surface's stored energy) never increases in contact, and a
//! release needs `M = ½mv² ≥ 0` at δ = 0; so `M < 0` means stuck for good.
//! A drive that varies has no such invariant, so the test is quasi-static:
//! the drive is frozen where it stands ([`DriveModel::frozen_work`]) and the
//! contact is stuck when, under that frozen drive, it could not reach the
//! edge of the surface again. It is checked at step ends once moving out
//! (past the deepest point, so the force peak has been seen). This is
//! exact for a constant drive and assumes that the drive does not weaken
//! afterwards — true of a closing drive, whose pull rises toward its final
//! value: for the coil the frozen pull is that of the smaller of the
//! present current and its final value V/R, which is right both when the
//! coil is slow against a contact swing (the flux, hence the pull, barely
//! moves; the frozen-current pull is the weaker, so the test errs on the
//! side of "not yet") and when it is fast (the current sits at V/R).
//! For a constant drive the endings are exact, which is what makes the
//! results equal the step-force engine's.

use super::model::{CycleTally, Ending, Model, Phase, PhaseEnd, Track};
use crate::chatter::{Chatter, Outcome, bounces};
use crate::mechanics::driven::{DriveModel, State};
use crate::mechanics::integrate::Dopri5Step;
use crate::mechanics::linear::LinearPiece;
use crate::mechanics::segment::Segment;
use crate::mechanics::surface::{Surface, surface_energy};

/// A finished closing.
pub(crate) struct ClosingRun {
    pub chatter: Chatter,
    /// s, the first lift-off from the rest stop (`None` if it never lifts
    /// or did not start on it).
    pub lift_off: Option<f64>,
    /// Every accepted step in time order, cut at events: they tile
    /// `[0, end]`; each is a `Piece` ([`Segment::piece`]).
    pub steps: Vec<Segment>,
    /// J, kinetic energy taken by rigid impacts and inelastic landings.
    pub jump_loss: f64,
    /// (s, state) where the run stopped.
    pub end: (f64, State),
}

/// J, the sticking margin `M` at (t, y) in the make contact.
fn margin<D: DriveModel>(model: &Model<'_, D>, t: f64, y: &State) -> f64 {
    let m = &model.m;
    let (u, v) = (y[0], y[1]);
    let g = m.gap;
    0.5 * m.mass * v * v
        + surface_energy(&model.stops.make, u)
        + (m.stiffness * g + m.preload) * u
        + 0.5 * m.stiffness * u * u
        - model.drive.frozen_work(t, y[2], g, g + u)
}

/// The closed-form Kelvin–Voigt contact from (t, y) with the drive
/// frozen there, with the surface's stiffness and damping; `None` for
/// another surface.
fn frozen_kv_piece<D: DriveModel>(
    model: &Model<'_, D>,
    t: f64,
    y: &State,
) -> Option<(LinearPiece, f64, f64)> {
    let Surface::KelvinVoigt { stiffness, damping } = model.stops.make else {
        return None;
    };
    let m = &model.m;
    let g = m.gap;
    let piece = LinearPiece::new(
        m.mass,
        m.damping + damping,
        m.stiffness + stiffness,
        model.drive_net(t, y) + stiffness * g,
        g + y[0],
        y[1],
    );
    Some((piece, stiffness, damping))
}

/// A Kelvin–Voigt contact that stuck at (t, y): its force keeps
/// oscillating toward the static value; with the drive frozen the rest is
/// a linear piece whose first two force extrema (a maximum and a minimum)
/// bound all later ones, as in the step-force engine.
fn kv_tail<D: DriveModel>(model: &Model<'_, D>, track: &mut Track, t: f64, y: &State) {
    let Some((piece, s0, r0)) = frozen_kv_piece(model, t, y) else {
        return;
    };
    let at_rest = s0 * (piece.x_eq - model.g());
    track.see_force(at_rest);
    let rate = piece.combo(-r0 * piece.omega2, s0 - 2.0 * piece.a * r0);
    for (_, varying) in piece.zeros(rate, piece.combo(s0, r0)).take(2) {
        track.see_force(at_rest + varying);
    }
}

/// After a make-contact `step` with no event: the stuck ending, if the
/// contact can no longer release.
pub(super) fn stuck_after<D: DriveModel>(
    model: &Model<'_, D>,
    rec: &mut CycleTally,
    step: &Dopri5Step<3>,
) -> Option<(PhaseEnd, f64, State)> {
    let (t1, y1) = (step.t1, step.y1);
    let v_hit = rec.make.impacts.last().map_or(0.0, |i| i.impact_velocity);
    // With a margin, so that rounding can never call a contact stuck that
    // will still release.
    let stick_margin = 1e-9 * 0.5 * model.m.mass * v_hit * v_hit;
    if y1[1] < 0.0 && margin(model, t1, &y1) < -stick_margin {
        kv_tail(model, &mut rec.make, t1, &y1);
        rec.ending = Some(Ending::Stuck { end: (t1, y1) });
        return Some((PhaseEnd::Stuck, t1, y1));
    }
    None
}

/// The opening since the last release touched again at (t, y) is below
/// resolution: closed since the touch before it.
pub(super) fn resolved<D: DriveModel>(
    model: &Model<'_, D>,
    rec: &mut CycleTally,
    t: f64,
    y: State,
) -> Ending {
    let track = &mut rec.make;
    let (released, farthest) = track.released.expect("a release came before");
    if let Some(last) = track.impacts.last_mut() {
        last.max_gap_after = Some(farthest);
    }
    track.unresolve(true);
    let accumulation = match model.stops.make {
        Surface::Rigid { restitution } if restitution < 1.0 => {
            Some(released + (t - released) / (1.0 - restitution))
        }
        _ => None,
    };
    Ending::Resolved {
        accumulation,
        end: (t, y),
    }
}

/// The closing reached the horizon at (t, y) in `phase`.
pub(super) fn at_horizon<D: DriveModel>(
    model: &Model<'_, D>,
    rec: &mut CycleTally,
    phase: Phase,
    t: f64,
    y: State,
) -> Ending {
    let g = model.g();
    let end = (t, y);
    match phase {
        Phase::Held => Ending::Open {
            reaches: false,
            reach: rec.reach,
            end,
        },
        Phase::Flight => {
            // Where the motion would go with the drive frozen: is the
            // contact still to be reached, and how far does it get?
            let m = &model.m;
            let x = g + y[0];
            let piece = LinearPiece::new(
                m.mass,
                m.damping,
                m.stiffness,
                model.drive_net(t, &y),
                x,
                y[1],
            );
            let tail = piece
                .first_extremum(true)
                .map_or(piece.x_eq.max(x), |(_, xm)| xm.max(x));
            let crossing = piece.crossing(g, true);
            // A flight after a release that will hit again: its largest
            // opening may still lie ahead.
            if let (Some(hit), Some((_, farthest))) = (crossing, rec.make.released) {
                let lowest = match hit.turned_at {
                    Some((_, x_turn)) => (g - farthest).min(x_turn),
                    None => g - farthest,
                };
                if let Some(last) = rec.make.impacts.last_mut() {
                    last.max_gap_after = Some(g - lowest);
                }
            }
            Ending::Open {
                reaches: crossing.is_some(),
                reach: rec.reach.max(tail),
                end,
            }
        }
        Phase::Make => {
            // A Kelvin–Voigt contact that would not release under the
            // frozen drive is stuck; otherwise it is still chattering.
            if let Some((piece, ..)) = frozen_kv_piece(model, t, &y) {
                if piece.crossing(g, false).is_none() {
                    kv_tail(model, &mut rec.make, t, &y);
                    return Ending::Stuck { end };
                }
            }
            Ending::InContact { end }
        }
        // Not reached: a closing stops at its first press, and has no
        // back-stop law.
        Phase::Pressed | Phase::Back => Ending::Stuck { end },
    }
}

/// The closing's record from the run that stopped at its ending.
pub(super) fn finish<D: DriveModel>(model: &Model<'_, D>, rec: CycleTally) -> ClosingRun {
    let t_end = model.settings.t_end;
    let g = model.g();
    let ending = rec.ending.expect("a closing stops at its ending");
    let since = rec.make.since;
    let (outcome, settle_time, accumulation_time, end) = match ending {
        Ending::Stuck { end } => (Outcome::Stuck, Some(since), None, end),
        Ending::Resolved { accumulation, end } => {
            (Outcome::Resolved, Some(since), accumulation, end)
        }
        Ending::Open {
            reaches: true, end, ..
        }
        | Ending::InContact { end } => (Outcome::EndOfTime, None, None, end),
        Ending::Open { end, .. } if rec.make.impacts.is_empty() => {
            (Outcome::NeverCloses, None, None, end)
        }
        Ending::Open { end, .. } => (Outcome::EndsOpen, None, None, end),
    };
    let shortfall = match ending {
        Ending::Open { reach, .. } if outcome == Outcome::NeverCloses => Some(g - reach),
        _ => None,
    };
    let lift_off = rec
        .log
        .iter()
        .find(|(_, e)| *e == PhaseEnd::Lift)
        .map(|&(t, _)| t);
    let (intervals, impacts) = rec.make.finish(t_end);
    ClosingRun {
        chatter: Chatter {
            outcome,
            first_impact: impacts.first().map(|i| i.impact_time),
            settle_time,
            bounce_count: bounces(&intervals),
            impacts,
            intervals,
            shortfall,
            accumulation_time,
            t_end,
        },
        lift_off,
        steps: rec.segments,
        jump_loss: rec.jump_loss,
        end,
    }
}
