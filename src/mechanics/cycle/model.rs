//! The cycle engine's model and records: the relay, its stops and the
//! drive with the equations of each phase of the motion ([`Model`]), the
//! events that end a phase ([`PhaseEnd`]), and what a run has recorded so
//! far ([`CycleTally`]: each contact's [`Track`], the event log, the steps;
//! a closing's [`Ending`]).

use crate::chatter::{ContactState, Impact, Interval};
use crate::mechanics::driven::{DriveModel, State};
use crate::mechanics::integrate::{Dopri5, StepTolerance};
use crate::mechanics::parameters::{Mechanics, Settings, Stops};
use crate::mechanics::segment::Segment;
use crate::mechanics::surface::{Surface, surface_force};

/// How a closing ended, and where the run stopped: (s, state).
#[derive(Debug, Clone, Copy)]
pub(super) enum Ending {
    /// Closed for good from the last touch.
    Stuck { end: (f64, State) },
    /// The opening that ended at `end` is below resolution: closed from
    /// the touch before it; `accumulation` (s) for a rigid surface.
    Resolved {
        accumulation: Option<f64>,
        end: (f64, State),
    },
    /// Open at the horizon; `reaches`: the frozen drive would still
    /// close the contact; `reach` (m): the largest x, counting the
    /// frozen motion's.
    Open {
        reaches: bool,
        reach: f64,
        end: (f64, State),
    },
    /// In a contact at the horizon that may still release.
    InContact { end: (f64, State) },
}

/// The phase of the motion, each with its own equations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Phase {
    Held,
    Flight,
    Make,
    Pressed,
    Back,
}

/// What ended a phase.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum PhaseEnd {
    Lift,
    TouchMake,
    TouchBack,
    ReleaseMake,
    ReleaseBack,
    Break,
    Horizon,
    /// A closing's contact has stuck for good (a closing run only).
    Stuck,
}

/// One contact's record: its intervals and impacts.
pub(super) struct Track {
    pub(super) intervals: Vec<Interval>,
    pub(super) impacts: Vec<Impact>,
    pub(super) state: ContactState,
    pub(super) since: f64,
    /// The last release: (s, smallest distance reached since, in m, from
    /// this contact's surface). Cleared at the next touch.
    pub(super) released: Option<(f64, f64)>,
}

impl Track {
    pub(super) fn new(state: ContactState) -> Self {
        Track {
            intervals: Vec::new(),
            impacts: Vec::new(),
            state,
            since: 0.0,
            released: None,
        }
    }

    pub(super) fn change(&mut self, t: f64, to: ContactState) {
        if self.state != to {
            self.intervals.push(Interval {
                state: self.state,
                start: self.since,
                end: t,
            });
            self.state = to;
            self.since = t;
        }
    }

    /// A touch at `t` at `speed` (> 0): the contact closes.
    pub(super) fn touch(&mut self, t: f64, speed: f64) {
        if let (Some((_, farthest)), Some(last)) = (self.released.take(), self.impacts.last_mut()) {
            last.max_gap_after = Some(farthest);
        }
        self.change(t, ContactState::Closed);
        self.impacts.push(Impact::touch(t, speed));
    }

    /// The contact opens at `t`, separating at `speed` (> 0).
    pub(super) fn release(&mut self, t: f64, speed: f64) {
        self.change(t, ContactState::Open);
        if let Some(last) = self.impacts.last_mut() {
            last.release_time = Some(t);
            last.release_velocity = Some(-speed);
            last.restitution = Some(speed / last.impact_velocity);
            last.contact_time = Some(t - last.impact_time);
        }
        self.released = Some((t, 0.0));
    }

    /// The opening since the last release is below resolution: the
    /// contact is taken as closed since the last touch. The cycle goes on
    /// from there as one contact, and forgets the release; a closing stops
    /// there and keeps it on the last impact's record (its release, and
    /// the opening it made, as the step-force engine reports a resolved
    /// sequence).
    pub(super) fn unresolve(&mut self, keep_release: bool) {
        self.released = None;
        let Some(closed) = self.intervals.pop() else {
            return;
        };
        debug_assert_eq!(closed.state, ContactState::Closed);
        self.state = ContactState::Closed;
        self.since = closed.start;
        if keep_release {
            return;
        }
        if let Some(last) = self.impacts.last_mut() {
            last.release_time = None;
            last.release_velocity = None;
            last.restitution = None;
            last.contact_time = None;
        }
    }

    /// The force on the contact now in its last impact's record.
    pub(super) fn see_force(&mut self, f: f64) {
        if let Some(last) = self.impacts.last_mut() {
            last.peak_force = Some(last.peak_force.map_or(f, |p| p.max(f)));
            last.min_force = Some(last.min_force.map_or(f, |p| p.min(f)));
        }
    }

    /// Note how far from the surface the armature got.
    pub(super) fn see_distance(&mut self, d: f64) {
        if let Some((_, farthest)) = &mut self.released {
            *farthest = farthest.max(d);
        }
    }

    pub(super) fn finish(mut self, t_end: f64) -> (Vec<Interval>, Vec<Impact>) {
        self.intervals.push(Interval {
            state: self.state,
            start: self.since.min(t_end),
            end: t_end,
        });
        (self.intervals, self.impacts)
    }
}

/// The relay, its stops and the drive: everything the right-hand side
/// needs.
pub(super) struct Model<'a, D> {
    pub(super) m: Mechanics,
    pub(super) stops: Stops,
    pub(super) settings: Settings,
    pub(super) drive: &'a D,
    pub(super) tol: StepTolerance<3>,
    /// Stop where one closing's ending is decided (a closing run).
    pub(super) closing: bool,
}

/// What the run has produced so far.
pub(super) struct CycleTally {
    pub(super) make: Track,
    pub(super) back: Track,
    /// Every touch, release and lift-off, in order.
    pub(super) log: Vec<(f64, PhaseEnd)>,
    /// Every accepted step, cut at its event (held ones too).
    pub(super) segments: Vec<Segment>,
    /// m, the largest x reached.
    pub(super) reach: f64,
    /// J, kinetic energy taken by rigid impacts and inelastic landings.
    pub(super) jump_loss: f64,
    /// How a closing ended, once it has (a closing run only).
    pub(super) ending: Option<Ending>,
}

impl CycleTally {
    /// The armature passed through `x`; the gap is `g`.
    pub(super) fn see_position(&mut self, x: f64, g: f64) {
        self.reach = self.reach.max(x);
        self.make.see_distance(g - x);
        self.back.see_distance(x);
    }
}

impl<D: DriveModel> Model<'_, D> {
    pub(super) fn g(&self) -> f64 {
        self.m.gap
    }

    /// N, the drive at (t, x, e) less the spring at x and the preload:
    /// > 0 pushes toward closing.
    pub(super) fn net(&self, t: f64, x: f64, e: f64) -> f64 {
        self.drive.force(t, x, e) - self.m.preload - self.m.stiffness * x
    }

    /// N, the drive at (t, y) less the preload.
    pub(super) fn drive_net(&self, t: f64, y: &State) -> f64 {
        self.drive.force(t, self.g() + y[0], y[2]) - self.m.preload
    }

    /// N, the NO contact's force at u (> 0 in it) and rate v.
    pub(super) fn make_force(&self, y: &State) -> f64 {
        surface_force(&self.stops.make, y[0], y[1])
    }

    /// N, the back stop's force at x = g + u (< 0 in it), pushing +x.
    ///
    /// Out of line, so that `rhs` is small enough to be inlined into the
    /// integrator's stepper (measured on a closing of 1139 steps: 215 µs
    /// so, 280 µs with `rhs` called).
    #[inline(never)]
    pub(super) fn back_force(&self, y: &State) -> f64 {
        match self.stops.back {
            Some(s) => surface_force(&s, -(self.g() + y[0]), -y[1]),
            None => 0.0,
        }
    }

    #[inline(always)]
    pub(super) fn rhs(&self, phase: Phase, t: f64, y: &State) -> State {
        let g = self.g();
        match phase {
            Phase::Held => State::new(0.0, 0.0, self.drive.rate(t, 0.0, y[2])),
            Phase::Pressed => State::new(0.0, 0.0, self.drive.rate(t, g, y[2])),
            Phase::Flight | Phase::Make | Phase::Back => {
                let x = g + y[0];
                let contact = match phase {
                    Phase::Make => -self.make_force(y),
                    Phase::Back => self.back_force(y),
                    _ => 0.0,
                };
                let a = (self.net(t, x, y[2]) - self.m.damping * y[1] + contact) / self.m.mass;
                State::new(y[1], a, self.drive.rate(t, x, y[2]))
            }
        }
    }

    /// N/s, the rate of the contact force of `phase` (make or back)
    /// along the motion at (t, y).
    pub(super) fn force_rate(&self, phase: Phase, t: f64, y: &State) -> f64 {
        let a = self.rhs(phase, t, y)[1];
        // Penetration, its rate and acceleration into the surface.
        let (surface, d, dd, ddd) = match phase {
            Phase::Make => (Some(self.stops.make), y[0], y[1], a),
            _ => (self.stops.back, -(self.g() + y[0]), -y[1], -a),
        };
        match surface {
            Some(Surface::KelvinVoigt { stiffness, damping }) => stiffness * dd + damping * ddd,
            Some(Surface::HuntCrossley {
                stiffness,
                exponent,
                chi,
            }) if d > 0.0 && 1.0 + chi * dd > 0.0 => {
                stiffness
                    * (exponent * d.powf(exponent - 1.0) * dd * (1.0 + chi * dd)
                        + d.powf(exponent) * chi * ddd)
            }
            _ => 0.0,
        }
    }

    /// N, the force on a held armature at (t, y) from what holds it: the
    /// rest stop against the preload's excess over the drive, or the make
    /// contact against the drive's excess over the preload and spring.
    pub(super) fn held_force(&self, phase: Phase, t: f64, y: &State) -> f64 {
        match phase {
            Phase::Held => self.m.preload - self.drive.force(t, 0.0, y[2]),
            _ => self.net(t, self.g(), y[2]),
        }
    }

    /// Whether a held phase still holds at (t, y): the preload keeps the
    /// armature on the rest stop, or the drive keeps it pressed on the NO
    /// contact.
    pub(super) fn holds(&self, phase: Phase, t: f64, y: &State) -> bool {
        match phase {
            Phase::Held => self.drive.force(t, 0.0, y[2]) <= self.m.preload,
            _ => self.net(t, self.g(), y[2]) >= 0.0,
        }
    }

    /// s, the time scale of a phase, for the first trial step.
    pub(super) fn scale(&self, phase: Phase, speed: f64) -> f64 {
        let m = &self.m;
        let free = (m.mass / m.stiffness).sqrt();
        let surface = match phase {
            Phase::Held | Phase::Pressed => return self.drive.time_scale(),
            Phase::Flight => return free,
            Phase::Make => Some(self.stops.make),
            Phase::Back => self.stops.back,
        };
        match surface {
            Some(Surface::KelvinVoigt { stiffness, .. }) => {
                (m.mass / (m.stiffness + stiffness)).sqrt()
            }
            Some(Surface::HuntCrossley {
                stiffness,
                exponent,
                ..
            }) if speed > 0.0 => {
                // The depth at which the surface alone stops the impact,
                // crossed at the impact speed.
                let depth = ((exponent + 1.0) * m.mass * speed * speed / (2.0 * stiffness))
                    .powf(1.0 / (exponent + 1.0));
                (depth / speed).min(free)
            }
            _ => free,
        }
    }

    pub(super) fn solver(
        &self,
        phase: Phase,
        t: f64,
        y: State,
    ) -> Dopri5<3, impl Fn(f64, &State) -> State + '_> {
        let h0 = 1e-2 * self.scale(phase, y[1].abs());
        Dopri5::new(
            move |t, y: &State| self.rhs(phase, t, y),
            t,
            y,
            h0,
            self.tol,
        )
    }

    /// Whether the opening since `track`'s last release, touched again at
    /// `t`, is below resolution.
    /// `t` and the state `y` there give the scale of the motion: the gap,
    /// or the drive's equilibrium if that lies farther.
    pub(super) fn unresolved(&self, track: &Track, t: f64, y: &State) -> bool {
        let Some((released, farthest)) = track.released else {
            return false;
        };
        let s = &self.settings;
        let x_eq = self.drive_net(t, y) / self.m.stiffness;
        let min_gap = s.min_gap.max(1e3 * f64::EPSILON * x_eq.abs().max(self.g()));
        let min_open = s.min_open_time.max(1e3 * f64::EPSILON * t);
        t - released < min_open || farthest < min_gap
    }
}
