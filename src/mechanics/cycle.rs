//! The whole operating cycle of a relay under a drive that rises and
//! falls: pull-in and make-side chatter, the contact held closed, the
//! release when the drive weakens, the return stroke and the bounce of
//! the armature on its rest stop (the normally-closed contact), and so on
//! for as many pulses as the drive gives (docs/model.md §7).
//!
//! This is the one engine for every drive that varies in time or
//! position. ClosingRun as a cycle (`run`) nothing ends before `t_end`: a
//! stuck contact stays in its contact phase and releases by the same rule
//! that ends every contact (the moving contact back at the surface, moving
//! out), so the break of the normally-open (NO) contact is found where the
//! pull no longer holds it. ClosingRun as one closing (`run_closing`) it stops
//! where the closing's ending is decided, on the understanding that the
//! drive does not weaken afterwards (`closing`: the sticking test and the
//! endings at the horizon).
//!
//! The state is `(u = x − g, v, e)` of [`super::driven`], and so are the
//! numerics: Dormand–Prince 5(4) with dense output, each step split at its
//! velocity zero, every crossing bracketed on a monotonic part and
//! polished by bisection on the interpolant. The phases:
//!
//! - **held** on the rest stop at x = 0 by the preload, while the drive
//!   does not beat it; it lifts off when `F(t, 0) > p`;
//! - **flight**, ending at a touch of the NO contact (x = g, moving up) or
//!   of the rest stop (x = 0, moving down);
//! - **make contact**, the NO surface law (Kelvin–Voigt, Hunt–Crossley),
//!   until the release (x back at g, moving out);
//! - **pressed** against a rigid NO surface while the drive holds it
//!   there, `F(t, g) ≥ p + s g`; it breaks when it no longer does;
//! - **back contact**, the rest stop's own surface law (the back stop),
//!   with penetration `−x`, until x is back at 0 moving up.
//!
//! Without a back-stop law the landing is inelastic: the armature is held
//! on the rest stop at once. A rigid surface with restitution below 1
//! makes an endless sequence of ever shorter bounces; as in the engine, an
//! opening shorter than `min_open_time` or smaller than `min_gap` is not
//! resolved: the contact is taken as closed since the previous touch, held
//! (pressed, or on the rest stop). A held armature sits at exactly x = 0
//! (or g): the static penetration of a deformable stop under the preload,
//! `p/s_b`, is neglected there.
//!
//! Contact forces (peak and minimum per contact) are taken at the events,
//! at the ends of the steps and at the zeros of the force's rate inside
//! them, bisected on the interpolant.
//!
//! Every accepted step is kept, cut at its event, as a segment of the
//! armature's trajectory; a closing hands the same steps on as
//! its record (`ClosingRun`).

use super::driven::{self, DriveModel, State, first_true, monotone_parts, state_on};
use super::error::{DriveError, MAX_DRIVEN_STEPS, MAX_EVENTS, MechanicsError};
use super::integrate::Dopri5Step;
pub use super::parameters::Stops;
use super::parameters::{Mechanics, PROOF_SPAN, Settings};
use super::segment::{Segment, path_of};
use super::surface::Surface;
use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome};
pub(crate) use closing::ClosingRun;
use model::{CycleTally, Ending, Model, Phase, PhaseEnd, Track};

mod closing;
mod model;

/// One stroke of the armature: from leaving the rest stop (lift-off) to
/// leaving it again, or to the end of the run. All times in s from t = 0.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Stroke {
    /// The armature leaves the rest stop: the normally-closed contact
    /// opens.
    pub lift_off: f64,
    /// The first touch of the NO contact; `None` if this stroke never
    /// reached it.
    pub first_make: Option<f64>,
    /// The start of the NO contact's last closed interval in this stroke:
    /// closed for good from here until the break. `None` when the stroke
    /// never made, or ended at `t_end` in a flight after a release (still
    /// bouncing).
    pub last_make: Option<f64>,
    /// NO openings between the first and the last make.
    pub bounces: usize,
    /// The last release of the NO contact, after which the armature went
    /// back to its rest stop; `None` if it did not within the run.
    pub break_time: Option<f64>,
    /// The first touch of the rest stop after the break: the NC contact
    /// makes. `None` if the armature did not come back within the run.
    pub back_make: Option<f64>,
    /// The start of the NC contact's last closed interval in this stroke.
    pub back_last_make: Option<f64>,
    /// NC openings between the first and the last back make.
    pub back_bounces: usize,
}

impl Stroke {
    /// s, from the first make to the last: the make-side bounce time.
    pub fn bounce_time(&self) -> Option<f64> {
        Some(self.last_make? - self.first_make?)
    }

    /// s, from the first back make to the last: the NC (break-side)
    /// bounce time.
    pub fn back_bounce_time(&self) -> Option<f64> {
        Some(self.back_last_make? - self.back_make?)
    }
}

/// A simulated cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct Cycle {
    /// The normally-open contact over the whole run. Its summary fields
    /// (`outcome`, `first_impact`, `settle_time`, `bounce_count`) are those
    /// of the first stroke's closing, the contract of a chatter sequence;
    /// `impacts` and `intervals` cover every stroke, release included.
    pub make: Chatter,
    /// The rest stop as the normally-closed contact, closed while the
    /// armature is on it; its impacts are the landings.
    pub back: Chatter,
    /// Every stroke of the armature, in time order.
    pub strokes: Vec<Stroke>,
    /// (s, m): the armature's path, at every accepted step and event.
    pub path: Vec<(f64, f64)>,
    /// The motion itself, step by step, for the armature's trajectory.
    pub(crate) segments: Vec<Segment>,
}

/// Simulate from t = 0 to `settings.t_end` under `drive`, from the
/// drive's state `e0`. Parameters must have been validated.
pub(crate) fn run_cycle<D: DriveModel>(
    m: &Mechanics,
    stops: &Stops,
    settings: &Settings,
    drive: &D,
    e0: f64,
) -> Result<Cycle, DriveError> {
    Ok(simulated(m, stops, settings, drive, e0, false)?.finish())
}

/// One closing under `drive` onto `surface`, from the drive's state
/// `e0`: the same engine, stopped where the closing's ending is decided
/// ([`closing`]). Parameters must have been validated.
pub(crate) fn run_closing<D: DriveModel>(
    m: &Mechanics,
    surface: &Surface,
    settings: &Settings,
    drive: &D,
    e0: f64,
) -> Result<ClosingRun, DriveError> {
    let stops = Stops {
        make: *surface,
        back: None,
    };
    let sim = simulated(m, &stops, settings, drive, e0, true)?;
    let mut run = closing::finish(&sim.model, sim.rec);
    // Closed at t_end but not yet proven to stay: followed on, with the
    // drive as it is, up to PROOF_SPAN × t_end; stuck (settled where it
    // was) only if nothing happens to the contact before the proof.
    let c = &run.chatter;
    let closed = c
        .intervals
        .last()
        .is_some_and(|i| i.state == ContactState::Closed);
    if c.outcome == Outcome::EndOfTime && closed {
        let longer = Settings {
            t_end: settings.t_end * PROOF_SPAN,
            ..*settings
        };
        let last = c.impacts.last().map(|i| i.impact_time);
        if let Ok(sim) = simulated(m, &stops, &longer, drive, e0, true) {
            let proof = closing::finish(&sim.model, sim.rec).chatter;
            if proof.outcome.is_closed() && proof.settle_time == last {
                run.chatter.outcome = proof.outcome;
                run.chatter.settle_time = proof.settle_time;
            }
        }
    }
    Ok(run)
}

fn simulated<'a, D: DriveModel>(
    m: &Mechanics,
    stops: &Stops,
    settings: &Settings,
    drive: &'a D,
    e0: f64,
    closing: bool,
) -> Result<Sim<'a, D>, DriveError> {
    let tol = driven::start_tolerance(m, drive, e0)?;
    let x0 = m.initial_position;
    let held = x0 == 0.0 && m.initial_velocity <= 0.0;
    let back_state = if held {
        ContactState::Closed
    } else {
        ContactState::Open
    };
    let mut sim = Sim {
        model: Model {
            m: *m,
            stops: *stops,
            settings: *settings,
            drive,
            tol,
            closing,
        },
        rec: CycleTally {
            make: Track::new(ContactState::Open),
            back: Track::new(back_state),
            log: Vec::new(),
            segments: Vec::new(),
            reach: x0,
            jump_loss: 0.0,
            ending: None,
        },
    };
    let y0 = State::new(x0 - m.gap, if held { 0.0 } else { m.initial_velocity }, e0);
    sim.simulate(if held { Phase::Held } else { Phase::Flight }, y0)?;
    Ok(sim)
}

struct Sim<'a, D> {
    model: Model<'a, D>,
    rec: CycleTally,
}

impl<D: DriveModel> Sim<'_, D> {
    /// ClosingRun the phases from `phase` at (0, y) to `t_end`.
    fn simulate(&mut self, mut phase: Phase, mut y: State) -> Result<(), DriveError> {
        let mut t = 0.0;
        loop {
            let events = self.rec.make.impacts.len() + self.rec.back.impacts.len();
            if events >= MAX_EVENTS {
                return Err(MechanicsError::TooManyEvents { time: t, events }.into());
            }
            let (event, te, mut ye) = self.phase(phase, t, y)?;
            if self.model.closing && event == PhaseEnd::Horizon {
                let ending = closing::at_horizon(&self.model, &mut self.rec, phase, te, ye);
                self.rec.ending = Some(ending);
            }
            let rec = &mut self.rec;
            phase = match event {
                PhaseEnd::Horizon | PhaseEnd::Stuck => return Ok(()),
                PhaseEnd::Lift => {
                    rec.log.push((te, PhaseEnd::Lift));
                    rec.back.change(te, ContactState::Open);
                    rec.back.released = Some((te, 0.0));
                    Phase::Flight
                }
                PhaseEnd::ReleaseMake | PhaseEnd::Break => {
                    rec.log.push((te, PhaseEnd::ReleaseMake));
                    rec.make.release(te, (-ye[1]).max(0.0));
                    Phase::Flight
                }
                PhaseEnd::ReleaseBack => {
                    rec.log.push((te, PhaseEnd::ReleaseBack));
                    rec.back.release(te, ye[1].max(0.0));
                    Phase::Flight
                }
                PhaseEnd::TouchMake => self.touch_make(te, &mut ye),
                PhaseEnd::TouchBack => self.touch_back(te, &mut ye),
            };
            if self.rec.ending.is_some() {
                return Ok(());
            }
            (t, y) = (te, ye);
        }
    }

    /// The NO contact touched at `t` with state `y` (u = 0): the phase
    /// that follows; `y` becomes the state after the touch.
    fn touch_make(&mut self, t: f64, y: &mut State) -> Phase {
        let (model, rec) = (&self.model, &mut self.rec);
        let speed = y[1];
        let mass = model.m.mass;
        if model.unresolved(&rec.make, t, y) {
            if model.closing {
                rec.ending = Some(closing::resolved(model, rec, t, *y));
                return Phase::Flight;
            }
            rec.make.unresolve(false);
            return match model.stops.make {
                Surface::Rigid { .. } => {
                    rec.jump_loss += 0.5 * mass * speed * speed;
                    self.press(t, y)
                }
                _ => Phase::Make,
            };
        }
        rec.log.push((t, PhaseEnd::TouchMake));
        rec.make.touch(t, speed);
        match model.stops.make {
            Surface::Rigid { restitution } => {
                let out = restitution * speed;
                rec.jump_loss += 0.5 * mass * (speed * speed - out * out);
                if out == 0.0 {
                    let phase = self.press(t, y);
                    if self.model.closing && phase == Phase::Pressed {
                        // Held against the surface by the static
                        // overtravel force: stuck for good.
                        self.rec.ending = Some(Ending::Stuck { end: (t, *y) });
                    }
                    return phase;
                }
                y[1] = -out;
                rec.log.push((t, PhaseEnd::ReleaseMake));
                rec.make.release(t, out);
                Phase::Flight
            }
            _ => {
                rec.make.see_force(model.make_force(y));
                Phase::Make
            }
        }
    }

    /// Held against a rigid NO contact from `t`, if the drive holds it.
    fn press(&mut self, t: f64, y: &mut State) -> Phase {
        y[1] = 0.0;
        let held_by = self.model.net(t, self.model.g(), y[2]);
        if held_by >= 0.0 {
            self.rec.make.see_force(held_by);
            Phase::Pressed
        } else {
            self.rec.log.push((t, PhaseEnd::ReleaseMake));
            self.rec.make.release(t, 0.0);
            Phase::Flight
        }
    }

    /// The rest stop touched at `t` with state `y` (x = 0).
    fn touch_back(&mut self, t: f64, y: &mut State) -> Phase {
        let (model, rec) = (&self.model, &mut self.rec);
        let speed = -y[1];
        let mass = model.m.mass;
        if model.closing {
            // A closing's landing: the opening after the last contact
            // reached the whole gap, and the next touch starts afresh
            // from the rest stop (no resolution test against the release).
            if let Some(last) = rec.make.impacts.last_mut() {
                last.max_gap_after.get_or_insert(model.g());
            }
            rec.make.released = None;
        }
        let deformable = matches!(
            model.stops.back,
            Some(Surface::KelvinVoigt { .. } | Surface::HuntCrossley { .. })
        );
        if model.unresolved(&rec.back, t, y) {
            rec.back.unresolve(false);
            if deformable {
                return Phase::Back;
            }
            rec.jump_loss += 0.5 * mass * speed * speed;
            return rest(y);
        }
        rec.log.push((t, PhaseEnd::TouchBack));
        rec.back.touch(t, speed);
        let out = match model.stops.back {
            None => 0.0,
            Some(Surface::Rigid { restitution }) => restitution * speed,
            Some(_) => {
                rec.back.see_force(model.back_force(y));
                return Phase::Back;
            }
        };
        rec.jump_loss += 0.5 * mass * (speed * speed - out * out);
        if out == 0.0 {
            return rest(y);
        }
        y[1] = out;
        rec.log.push((t, PhaseEnd::ReleaseBack));
        rec.back.release(t, out);
        Phase::Flight
    }

    /// Integrate `phase` from (t0, y0) to its event: (event, time, state
    /// at the event, with the position set exactly to its level).
    fn phase(
        &mut self,
        phase: Phase,
        t0: f64,
        y0: State,
    ) -> Result<(PhaseEnd, f64, State), DriveError> {
        let (model, rec) = (&self.model, &mut self.rec);
        let g = model.g();
        let t_end = model.settings.t_end;
        if t0 >= t_end {
            return Ok((PhaseEnd::Horizon, t0, y0));
        }
        let held = matches!(phase, Phase::Held | Phase::Pressed);
        let (level, ends) = if phase == Phase::Held {
            (-g, PhaseEnd::Lift)
        } else {
            (0.0, PhaseEnd::Break)
        };
        if held && !model.holds(phase, t0, &y0) {
            return Ok((ends, t0, y0));
        }
        // One segment per accepted step, cut at the event; a held one
        // carries the force of what holds it at both ends.
        let side = match phase {
            Phase::Make => 1,
            Phase::Back => -1,
            _ => 0,
        };
        let mut held_by = if held {
            model.held_force(phase, t0, &y0)
        } else {
            0.0
        };
        let mut solver = model.solver(phase, t0, y0);
        loop {
            let step = solver.step(t_end)?;
            let found = if held {
                if model.holds(phase, step.t1, &step.y1) {
                    None
                } else {
                    let te = first_true(|t| !model.holds(phase, t, &step.at(t)), step.t0, step.t1);
                    let mut ye = state_on(&step, te);
                    (ye[0], ye[1]) = (level, 0.0);
                    Some((ends, te, ye))
                }
            } else {
                match moving_event(model, rec, phase, &step)? {
                    None if phase == Phase::Make && model.closing => {
                        closing::stuck_after(model, rec, &step)
                    }
                    found => found,
                }
            };
            let (te, ye) = found.map_or((step.t1, step.y1), |(_, te, ye)| (te, ye));
            if held {
                let f = model.held_force(phase, te, &ye);
                if phase == Phase::Pressed && found.is_none() {
                    rec.make.see_force(f);
                }
                let pressed = phase == Phase::Pressed;
                let segment = Segment::held(step, te, ye, g + level, pressed, (held_by, f));
                rec.segments.push(segment);
                held_by = f;
            } else {
                rec.segments.push(Segment::integrated(step, te, ye, side));
            }
            if rec.segments.len() > MAX_DRIVEN_STEPS {
                let m = &model.m;
                return Err(DriveError::TooManySteps {
                    steps: MAX_DRIVEN_STEPS,
                    time: te,
                    t_end,
                    mass: m.mass,
                    stiffness: m.stiffness,
                    period: std::f64::consts::TAU * (m.mass / m.stiffness).sqrt(),
                });
            }
            if let Some(found) = found {
                return Ok(found);
            }
            if step.t1 >= t_end {
                return Ok((PhaseEnd::Horizon, step.t1, step.y1));
            }
        }
    }

    fn finish(self) -> Cycle {
        let t_end = self.model.settings.t_end;
        let g = self.model.g();
        let rec = self.rec;
        let lift_offs = lift_offs(&rec.log);
        let (make_intervals, make_impacts) = rec.make.finish(t_end);
        let (back_intervals, back_impacts) = rec.back.finish(t_end);
        let strokes = strokes(&lift_offs, &make_impacts, &back_impacts);
        let make = summary(
            make_intervals,
            make_impacts,
            strokes.first(),
            g - rec.reach,
            t_end,
        );
        let ends_closed = back_intervals
            .last()
            .filter(|i| i.state == ContactState::Closed)
            .map(|i| i.start);
        let back = Chatter {
            outcome: if ends_closed.is_some() {
                Outcome::Stuck
            } else {
                Outcome::EndsOpen
            },
            first_impact: back_impacts.first().map(|i| i.impact_time),
            settle_time: ends_closed,
            bounce_count: strokes.iter().map(|s| s.back_bounces).sum(),
            impacts: back_impacts,
            intervals: back_intervals,
            shortfall: None,
            accumulation_time: None,
            t_end,
        };
        let path = path_of((0.0, self.model.m.initial_position), &rec.segments, g);
        Cycle {
            make,
            back,
            strokes,
            path,
            segments: rec.segments,
        }
    }
}

/// Held on the rest stop.
fn rest(y: &mut State) -> Phase {
    y[1] = 0.0;
    Phase::Held
}

/// The first event of a moving phase inside `step`, with the bookkeeping
/// of the step (reach, distances, contact forces).
fn moving_event<D: DriveModel>(
    model: &Model<'_, D>,
    rec: &mut CycleTally,
    phase: Phase,
    step: &Dopri5Step<3>,
) -> Result<Option<(PhaseEnd, f64, State)>, DriveError> {
    let g = model.g();
    let parts = monotone_parts(step);
    // A crossing of `level` (in u) in the given direction on a monotonic
    // part [a, b].
    let crossing = |a: f64, b: f64, level: f64, up: bool| -> Option<(f64, State)> {
        let (ua, ub) = (state_on(step, a)[0], state_on(step, b)[0]);
        let crosses = if up {
            ua < level && ub >= level
        } else {
            ua > level && ub <= level
        };
        crosses.then(|| {
            let te = first_true(
                |t| {
                    let u = step.at(t)[0];
                    if up { u >= level } else { u <= level }
                },
                a,
                b,
            );
            let mut ye = state_on(step, te);
            ye[0] = level;
            (te, ye)
        })
    };
    let mut found = None;
    for &(a, b) in parts.spans() {
        found = match phase {
            Phase::Flight => crossing(a, b, 0.0, true)
                .map(|(t, y)| (PhaseEnd::TouchMake, t, y))
                .or_else(|| crossing(a, b, -g, false).map(|(t, y)| (PhaseEnd::TouchBack, t, y))),
            Phase::Make => crossing(a, b, 0.0, false).map(|(t, y)| (PhaseEnd::ReleaseMake, t, y)),
            Phase::Back => crossing(a, b, -g, true).map(|(t, y)| (PhaseEnd::ReleaseBack, t, y)),
            Phase::Held | Phase::Pressed => None,
        };
        if found.is_some() {
            break;
        }
    }
    let (t_last, y_last) = match found {
        Some((_, te, ye)) => (te, ye),
        None => (step.t1, step.y1),
    };
    // The turning point counts only if it comes before the event.
    let turn = parts.turn.filter(|&(tz, _)| tz <= t_last);
    if let Some((_, yz)) = turn {
        rec.see_position(g + yz[0], g);
    }
    rec.see_position(g + y_last[0], g);
    let track_force = |rec: &mut CycleTally, side: Phase| {
        // The force at the end, and at its extremum inside the step: a
        // zero of its rate, bisected on the interpolant.
        let rate = |t: f64| {
            let y = state_on(step, t);
            model.force_rate(side, t, &y)
        };
        let extremum = driven::sign_change(rate, step.t0, t_last).map(|tz| state_on(step, tz));
        for y in std::iter::once(y_last).chain(extremum) {
            match side {
                Phase::Make => rec.make.see_force(model.make_force(&y)),
                _ => rec.back.see_force(model.back_force(&y)),
            }
        }
    };
    match phase {
        Phase::Make => {
            let pole = model.drive.pole();
            if g + y_last[0] >= pole {
                let tp = first_true(|t| g + step.at(t)[0] >= pole, step.t0, t_last);
                return Err(DriveError::ArmatureAtPole {
                    time: tp,
                    position: g + state_on(step, tp)[0],
                    pole,
                });
            }
            track_force(rec, Phase::Make);
        }
        Phase::Back => track_force(rec, Phase::Back),
        _ => {}
    }
    Ok(found)
}

/// s, the lift-offs in an event log: every departure from a held rest,
/// and every release from the back stop after which the armature next
/// touches the NO contact (the others are NC bounces).
fn lift_offs(log: &[(f64, PhaseEnd)]) -> Vec<f64> {
    let mut out = Vec::new();
    for (k, &(t, event)) in log.iter().enumerate() {
        let lifts = match event {
            PhaseEnd::Lift => true,
            PhaseEnd::ReleaseBack => log[k + 1..]
                .iter()
                .find(|(_, e)| matches!(e, PhaseEnd::TouchMake | PhaseEnd::TouchBack))
                .is_some_and(|(_, e)| *e == PhaseEnd::TouchMake),
            _ => false,
        };
        if lifts {
            out.push(t);
        }
    }
    out
}

/// The NO contact's chatter, summarised by its first stroke.
pub(crate) fn summary(
    intervals: Vec<Interval>,
    impacts: Vec<Impact>,
    first: Option<&Stroke>,
    shortfall: f64,
    t_end: f64,
) -> Chatter {
    let first_impact = impacts.first().map(|i| i.impact_time);
    let (outcome, settle_time, bounce_count) = match first {
        Some(s) if s.first_make.is_some() => match s.last_make {
            Some(last) => (Outcome::Stuck, Some(last), s.bounces),
            None => (Outcome::EndOfTime, None, s.bounces),
        },
        _ => (Outcome::NeverCloses, None, 0),
    };
    Chatter {
        outcome,
        first_impact,
        settle_time,
        bounce_count,
        impacts,
        intervals,
        shortfall: (outcome == Outcome::NeverCloses).then_some(shortfall.max(0.0)),
        accumulation_time: None,
        t_end,
    }
}

/// Cut the run into strokes at the lift-offs.
pub(crate) fn strokes(lift_offs: &[f64], make: &[Impact], back: &[Impact]) -> Vec<Stroke> {
    let mut out = Vec::with_capacity(lift_offs.len());
    for (k, &lift_off) in lift_offs.iter().enumerate() {
        let until = lift_offs.get(k + 1).copied().unwrap_or(f64::INFINITY);
        let within = |i: &&Impact| i.impact_time >= lift_off && i.impact_time < until;
        let makes: Vec<&Impact> = make.iter().filter(within).collect();
        let last = makes.last();
        // The break: the last release, when the armature reached the rest
        // stop after it.
        let landing = back
            .iter()
            .filter(within)
            .find(|b| last.is_none_or(|m| m.release_time.is_some_and(|r| b.impact_time > r)));
        let ended_in_flight = last.is_some_and(|m| m.release_time.is_some()) && landing.is_none();
        let backs: Vec<&Impact> = match landing {
            Some(first) => back
                .iter()
                .filter(within)
                .filter(|b| b.impact_time >= first.impact_time)
                .collect(),
            None => Vec::new(),
        };
        out.push(Stroke {
            lift_off,
            first_make: makes.first().map(|i| i.impact_time),
            last_make: if ended_in_flight {
                None
            } else {
                last.map(|i| i.impact_time)
            },
            bounces: makes.len().saturating_sub(1),
            break_time: landing.and(last.and_then(|m| m.release_time)),
            back_make: backs.first().map(|i| i.impact_time),
            back_last_make: backs
                .last()
                .filter(|b| b.release_time.is_none_or(|r| r >= until))
                .map(|i| i.impact_time),
            back_bounces: backs.len().saturating_sub(1),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coil::{simulate_cycle, simulate_forced};

    /// A small relay, undamped so that the strokes have closed forms.
    fn relay() -> Mechanics {
        Mechanics {
            mass: 2e-4,
            stiffness: 800.0,
            damping: 0.0,
            force: 0.0,
            gap: 4.5e-4,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.1,
        }
    }

    fn settings(t_end: f64) -> Settings {
        Settings {
            t_end,
            ..Settings::default()
        }
    }

    /// `f0` from t = 0 until `off`, nothing after.
    fn pulse(f0: f64, off: f64) -> impl Fn(f64, f64) -> f64 {
        move |t, _| if t < off { f0 } else { 0.0 }
    }

    #[test]
    fn a_drive_that_stays_on_closes_as_the_closing_engine_does() {
        let m = Mechanics {
            damping: 0.04,
            ..relay()
        };
        let surface = Surface::KelvinVoigt {
            stiffness: 8e4,
            damping: 0.37536,
        };
        let stops = Stops {
            make: surface,
            back: None,
        };
        let closing = simulate_forced(&m, &surface, &settings(0.02), |_, _| 0.5).unwrap();
        let cycle = simulate_cycle(&m, &stops, &settings(0.02), |_, _| 0.5).unwrap();
        assert_eq!(cycle.make.impacts.len(), closing.impacts.len());
        for (a, b) in cycle.make.impacts.iter().zip(&closing.impacts) {
            assert!((a.impact_time - b.impact_time).abs() < 1e-12, "{a:?} {b:?}");
            let peak = (a.peak_force.unwrap() / b.peak_force.unwrap() - 1.0).abs();
            assert!(peak < 1e-4, "{peak}");
        }
        assert_eq!(cycle.make.settle_time, closing.settle_time);
        assert_eq!(cycle.make.bounce_count, closing.bounce_count);
        let [stroke] = cycle.strokes.as_slice() else {
            panic!("{:?}", cycle.strokes)
        };
        assert_eq!(stroke.lift_off, 0.0);
        assert_eq!(stroke.break_time, None);
        assert_eq!(
            stroke.bounce_time(),
            closing
                .settle_time
                .map(|s| s - closing.first_impact.unwrap())
        );
    }

    #[test]
    fn release_and_back_stop_bounce_follow_the_closed_forms() {
        // Rigid stops, no damping: the armature is pressed on the NO
        // contact until the force drops at `off`, leaves it at rest from
        // x = g, and swings about −p/s onto the rest stop, where each
        // bounce at speed w flies 2/ω·atan(w s/(ω p)).
        let m = relay();
        let (e, off) = (0.5, 8e-3);
        let stops = Stops {
            make: Surface::Rigid { restitution: e },
            back: Some(Surface::Rigid { restitution: e }),
        };
        let cycle = simulate_cycle(&m, &stops, &settings(0.02), pulse(0.5, off)).unwrap();
        let [stroke] = cycle.strokes.as_slice() else {
            panic!("{:?}", cycle.strokes)
        };
        let omega = (m.stiffness / m.mass).sqrt();
        let x_p = m.preload / m.stiffness;
        // The closing: from rest about x_eq = (f − p)/s.
        let x_eq = (0.5 - m.preload) / m.stiffness;
        let first_make = (1.0 - m.gap / x_eq).acos() / omega;
        assert!((stroke.first_make.unwrap() / first_make - 1.0).abs() < 1e-9);
        let break_time = stroke.break_time.unwrap();
        assert!((break_time - off).abs() < 1e-12, "{break_time}");
        let swing = (x_p / (m.gap + x_p)).acos() / omega;
        let back_make = stroke.back_make.unwrap();
        assert!(
            ((back_make - off) / swing - 1.0).abs() < 1e-9,
            "{back_make}"
        );
        let speed = omega * ((m.gap + x_p).powi(2) - x_p * x_p).sqrt();
        let first = cycle
            .back
            .impacts
            .iter()
            .find(|i| i.impact_time == back_make)
            .unwrap();
        assert!((first.impact_velocity / speed - 1.0).abs() < 1e-9);
        assert_eq!(first.restitution, Some(e));
        // The bounces on the rest stop sum to the NC bounce time.
        let expected: f64 = (1..=stroke.back_bounces as i32)
            .map(|k| 2.0 / omega * (e.powi(k) * speed / (omega * x_p)).atan())
            .sum();
        let bounce = stroke.back_bounce_time().unwrap();
        assert!(
            (bounce / expected - 1.0).abs() < 1e-9,
            "{bounce} {expected}"
        );
        assert!(stroke.back_bounces >= 10, "{stroke:?}");
        // At the end it rests on the stop: the NC contact is closed.
        assert_eq!(
            cycle.back.intervals.last().unwrap().state,
            ContactState::Closed
        );
        assert_eq!(
            cycle.make.intervals.last().unwrap().state,
            ContactState::Open
        );
    }

    #[test]
    fn every_pulse_is_a_stroke_with_a_deformable_back_stop() {
        let m = Mechanics {
            damping: 0.2,
            ..relay()
        };
        let stops = Stops {
            make: Surface::KelvinVoigt {
                stiffness: 8e4,
                damping: 1.5,
            },
            back: Some(Surface::KelvinVoigt {
                stiffness: 4e4,
                damping: 1.0,
            }),
        };
        let pulses = [(0.0, 10e-3), (20e-3, 30e-3)];
        let force = |t: f64, _x: f64| {
            if pulses.iter().any(|&(on, off)| (on..off).contains(&t)) {
                0.6
            } else {
                0.0
            }
        };
        let cycle = simulate_cycle(&m, &stops, &settings(0.04), force).unwrap();
        assert_eq!(cycle.strokes.len(), 2, "{:?}", cycle.strokes);
        for (stroke, (on, off)) in cycle.strokes.iter().zip(pulses) {
            let (first, last) = (stroke.first_make.unwrap(), stroke.last_make.unwrap());
            let (brk, back) = (stroke.break_time.unwrap(), stroke.back_make.unwrap());
            assert!(
                on <= stroke.lift_off && stroke.lift_off < first,
                "{stroke:?}"
            );
            assert!(
                first <= last && last < off && off < brk && brk < back,
                "{stroke:?}"
            );
            assert!(stroke.bounces > 0 && stroke.back_bounces > 0, "{stroke:?}");
            assert!(stroke.back_last_make.unwrap() >= back);
        }
        // The second stroke starts from the rest where the first left it:
        // the same closing, shifted by the lift-off.
        let [a, b] = [&cycle.strokes[0], &cycle.strokes[1]];
        // The same closing, shifted by the pulse; the second starts out of
        // the back stop's static dent (p/s_b = 2.5 µm), a little later.
        let late = (b.first_make.unwrap() - 20e-3) - a.first_make.unwrap();
        assert!(late > 0.0 && late < 1e-4, "{late}");
        assert_eq!(a.bounces, b.bounces);
        // The path moves forward in time and stays between the stops, up
        // to the surfaces' dent: at most v·√(m/s0), 0.1 mm on the soft
        // back stop hit at ~1 m/s.
        assert!(cycle.path.windows(2).all(|w| w[1].0 > w[0].0));
        assert!(
            cycle
                .path
                .iter()
                .all(|&(_, x)| (-1e-4..m.gap + 1e-4).contains(&x))
        );
        // Intervals tile the run.
        for chatter in [&cycle.make, &cycle.back] {
            assert!(chatter.intervals.windows(2).all(|w| w[0].end == w[1].start));
            assert_eq!(chatter.intervals.last().unwrap().end, 0.04);
        }
    }
}
