//! The two-stage engine: event location on DOP853's dense output.
//!
//! The state is `(u_a, v_a, u_b, v_b, e)`: the armature's and the blade's
//! positions relative to the contact's gap (`u = x − g`, so that µm
//! penetrations keep their precision), their velocities, and the drive's
//! own state (the coil's flux). Without a blade `(u_b, v_b)` is a copy of
//! the armature's, integrated by the same arithmetic.
//!
//! Each of the three stops (the fixed contact under the blade, the pole
//! face and the rest stop under the armature) is `Open`, `Engaged` (its
//! deformable law pushes) or `Pressed` (a rigid surface, or the rest stop
//! without a law of its own, holds the body still). Every mode has an
//! event function that is positive while the mode lasts; each accepted
//! step is sampled at four points of its dense output, and the first
//! function to turn negative is bisected on the interpolant down to
//! adjacent floats. At the event the state is set exactly on the surface
//! and the integrator restarts in the new mode.

use nalgebra::SVector;

use super::super::cycle::{Stroke, strokes, summary};
use super::super::dop853::{Dense, Dop853};
use super::super::driven::{Drive, first_true};
use super::super::integrate::Tolerance;
use super::super::{
    DriveError, MAX_DRIVEN_STEPS, MAX_EVENTS, Mechanics, MechanicsError, Settings, Surface,
};
use super::energy::EnergyBound;
use super::{Release, TwoStage, TwoStageRun};
use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome};

/// `(u_a, v_a, u_b, v_b, e)`.
pub(crate) type Y = SVector<f64, 5>;

/// Relative tolerance of the integration: impact and release times of a
/// whole sequence agree with the exact one-mass engine to about 1e-9.
pub(crate) const RTOL: f64 = 1e-11;

/// Sample points per step at which the event functions are checked.
const SAMPLES: usize = 4;

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

/// What holds a body at a stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stop {
    Open,
    Engaged,
    Pressed,
}

/// The three stops' modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Modes {
    pub(crate) contact: Stop,
    pub(crate) pole: Stop,
    pub(crate) rest: Stop,
}

/// How a piece's state is had between its ends.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Interpolant {
    /// DOP853's dense output of the step.
    Dense(Box<Dense<5>>),
    /// The exact solution of a linear mode from `w0` (scaled deviation
    /// from the mode's equilibrium) at `t0`.
    Linear {
        w0: super::linear::W,
        mode: std::sync::Arc<super::linear::LinearMode>,
    },
}

/// One accepted step, cut at its event: valid on `[t0, t1]`, exact `y1`
/// at `t1`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Span {
    pub motion: Interpolant,
    pub t0: f64,
    pub t1: f64,
    pub y1: Y,
    pub modes: Modes,
}

impl Span {
    pub(crate) fn dense(dense: Dense<5>, t1: f64, y1: Y, modes: Modes) -> Span {
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
            Interpolant::Linear { w0, mode } => mode.y_of(&mode.at(w0, t - self.t0)),
        }
    }

    /// Whether the contact is closed over this piece.
    pub(crate) fn contact_closed(&self) -> bool {
        self.modes.contact != Stop::Open
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

/// Which stop an event belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Which {
    Contact,
    Pole,
    Rest,
}

/// The model: parameters and the drive.
pub(crate) struct Relay<'a, D> {
    pub m: &'a Mechanics,
    pub build: &'a TwoStage,
    pub contact: Surface,
    pub back: Option<Surface>,
    /// Whether the armature has a rest stop at x = 0 (a driven run).
    pub rest: bool,
    pub drive: &'a D,
}

/// The force expression whose sign decides a force-released contact:
/// positive while the law pushes.
fn push(surface: &Surface, delta: f64, rate: f64) -> f64 {
    match *surface {
        Surface::KelvinVoigt { stiffness, damping } => stiffness * delta + damping * rate,
        Surface::HuntCrossley { chi, .. } => 1.0 + chi * rate,
        Surface::Rigid { .. } => delta,
    }
}

/// The law's force while engaged (a Kelvin–Voigt surface unclamped, as
/// the paper's rule has it; Hunt–Crossley clamped at 0).
fn law(surface: &Surface, delta: f64, rate: f64) -> f64 {
    match *surface {
        Surface::KelvinVoigt { stiffness, damping } => stiffness * delta + damping * rate,
        Surface::HuntCrossley { .. } => surface.force(delta.max(0.0), rate),
        Surface::Rigid { .. } => 0.0,
    }
}

impl<D: Drive> Relay<'_, D> {
    fn g(&self) -> f64 {
        self.m.gap
    }

    fn overtravel(&self) -> f64 {
        self.build.pole_face.map_or(f64::INFINITY, |p| p.overtravel)
    }

    fn blade_force(&self, y: &Y) -> f64 {
        match &self.build.blade {
            Some(b) => b.stiffness * (y[0] - y[2]) + b.damping * (y[1] - y[3]),
            None => 0.0,
        }
    }

    fn contact_force(&self, y: &Y, modes: Modes) -> f64 {
        if modes.contact == Stop::Engaged {
            law(&self.contact, y[2], y[3])
        } else {
            0.0
        }
    }

    fn pole_force(&self, y: &Y, modes: Modes) -> f64 {
        match (&self.build.pole_face, modes.pole) {
            (Some(p), Stop::Engaged) => law(&p.surface, y[0] - p.overtravel, y[1]),
            _ => 0.0,
        }
    }

    fn rest_force(&self, y: &Y, modes: Modes) -> f64 {
        match (&self.back, modes.rest) {
            (Some(b), Stop::Engaged) => law(b, -(self.g() + y[0]), -y[1]),
            _ => 0.0,
        }
    }

    /// N, the force toward closing on the armature from everything but
    /// its stops' constraints (and, without a blade, the contact).
    fn armature_push(&self, t: f64, y: &Y, modes: Modes) -> f64 {
        let m = self.m;
        let x = self.g() + y[0];
        let mut f = self.drive.force(t, x, y[4])
            - m.preload
            - m.stiffness * x
            - m.damping * y[1]
            - self.blade_force(y)
            - self.pole_force(y, modes)
            + self.rest_force(y, modes);
        if self.build.blade.is_none() {
            f -= self.contact_force(y, modes);
        }
        f
    }

    fn armature_held(&self, modes: Modes) -> bool {
        modes.pole == Stop::Pressed
            || modes.rest == Stop::Pressed
            || (self.build.blade.is_none() && modes.contact == Stop::Pressed)
    }

    pub(crate) fn rate(&self, t: f64, y: &Y, modes: Modes) -> Y {
        let x = self.g() + y[0];
        let held = self.armature_held(modes);
        let (ua, aa) = if held {
            (0.0, 0.0)
        } else {
            (y[1], self.armature_push(t, y, modes) / self.m.mass)
        };
        let (ub, ab) = match &self.build.blade {
            None => (ua, aa),
            Some(_) if modes.contact == Stop::Pressed => (0.0, 0.0),
            Some(b) => (
                y[3],
                (self.blade_force(y) - self.contact_force(y, modes)) / b.mass,
            ),
        };
        Y::new(ua, aa, ub, ab, self.drive.rate(t, x, y[4]))
    }

    /// The event function of `which` in `modes`: positive while the mode
    /// lasts.
    fn event(&self, which: Which, t: f64, y: &Y, modes: Modes) -> f64 {
        let force_rule = |release: Release, s: &Surface| {
            release == Release::Force && !matches!(s, Surface::Rigid { .. })
        };
        match which {
            Which::Contact => {
                let s = &self.contact;
                let by_force = force_rule(self.build.release, s);
                match modes.contact {
                    Stop::Open if by_force => (-y[2]).max(-push(s, y[2], y[3])),
                    Stop::Open => -y[2],
                    Stop::Engaged if by_force => y[2].min(push(s, y[2], y[3])),
                    Stop::Engaged => y[2],
                    Stop::Pressed => match self.build.blade {
                        Some(_) => self.blade_force(y),
                        None => self.armature_push(t, y, modes),
                    },
                }
            }
            Which::Pole => {
                let Some(p) = &self.build.pole_face else {
                    return 1.0;
                };
                let by_force = force_rule(p.release, &p.surface);
                let delta = y[0] - p.overtravel;
                match modes.pole {
                    Stop::Open if by_force => (-delta).max(-push(&p.surface, delta, y[1])),
                    Stop::Open => -delta,
                    Stop::Engaged if by_force => delta.min(push(&p.surface, delta, y[1])),
                    Stop::Engaged => delta,
                    Stop::Pressed => self.armature_push(t, y, modes),
                }
            }
            Which::Rest => {
                if !self.rest {
                    return 1.0;
                }
                let x = self.g() + y[0];
                match modes.rest {
                    Stop::Open => x,
                    Stop::Engaged => -x,
                    Stop::Pressed => -self.armature_push(t, y, modes),
                }
            }
        }
    }

    /// The first event in `(t0, t1]` on `dense`: (time, which).
    fn first_event(&self, dense: &Dense<5>, t1: f64, modes: Modes) -> Option<(f64, Which)> {
        const ALL: [Which; 3] = [Which::Contact, Which::Pole, Which::Rest];
        let t0 = dense.t0;
        let mut lo = t0;
        for k in 1..=SAMPLES {
            let hi = if k == SAMPLES {
                t1
            } else {
                t0 + (t1 - t0) * k as f64 / SAMPLES as f64
            };
            let y = dense.at(hi);
            let mut best: Option<(f64, Which)> = None;
            for which in ALL {
                if self.event(which, hi, &y, modes) < 0.0 {
                    let t = first_true(|t| self.event(which, t, &dense.at(t), modes) < 0.0, lo, hi);
                    if best.is_none_or(|(tb, _)| t < tb) {
                        best = Some((t, which));
                    }
                }
            }
            if best.is_some() {
                return best;
            }
            lo = hi;
        }
        None
    }

    /// The acceleration of `which`'s body toward its stop in `modes` (the
    /// stop open), m/s².
    fn toward(&self, which: Which, t: f64, y: &Y, modes: Modes) -> f64 {
        let r = self.rate(t, y, modes);
        match which {
            Which::Contact => r[3],
            Which::Pole => r[1],
            Which::Rest => -r[1],
        }
    }
}

/// The records a run builds.
pub(crate) struct Tally {
    contact: Vec<Impact>,
    intervals: Vec<Interval>,
    pole: Vec<Impact>,
    back: Vec<Impact>,
    back_intervals: Vec<Interval>,
    lift_offs: Vec<f64>,
    /// m, the blade's farthest reach before its first touch.
    reach: f64,
}

impl Tally {
    /// Whether the contact has been touched.
    pub(crate) fn contact_is_empty(&self) -> bool {
        self.contact.is_empty()
    }

    /// Take in the state `y` in `modes`: the engaged contact's force
    /// (`force(y)`), the opening after a release, the reach before the
    /// first touch.
    pub(crate) fn observe(&mut self, gap: f64, modes: Modes, y: &Y, force: impl Fn(&Y) -> f64) {
        match modes.contact {
            Stop::Engaged | Stop::Pressed => {
                let f = force(y);
                if let Some(last) = self.contact.last_mut() {
                    last.peak_force = Some(last.peak_force.map_or(f, |p: f64| p.max(f)));
                    last.min_force = Some(last.min_force.map_or(f, |p: f64| p.min(f)));
                }
            }
            Stop::Open => match self.contact.last_mut() {
                Some(last) => {
                    let opening = (-y[2]).max(0.0);
                    last.max_gap_after =
                        Some(last.max_gap_after.map_or(opening, |p: f64| p.max(opening)));
                }
                None => self.reach = self.reach.max(gap + y[2]),
            },
        }
    }

    fn switch(intervals: &mut Vec<Interval>, t: f64, state: ContactState) {
        if let Some(last) = intervals.last_mut() {
            if last.state == state {
                return;
            }
            last.end = t;
        }
        intervals.push(Interval {
            state,
            start: t,
            end: t,
        });
    }
}

fn release(impact: &mut Impact, t: f64, v: f64) {
    impact.release_time = Some(t);
    impact.release_velocity = Some(v);
    impact.contact_time = Some(t - impact.impact_time);
    impact.restitution = (impact.impact_velocity > 0.0).then(|| -v / impact.impact_velocity);
}

/// A run in progress: where it is, in which modes, and what it recorded.
pub(crate) struct Progress {
    pub t: f64,
    pub y: Y,
    pub modes: Modes,
    pub rec: Tally,
    pub pieces: Vec<Span>,
    pub steps: usize,
    pub bound: EnergyBound,
    /// The ending, when one was decided before the horizon.
    pub ending: Option<Outcome>,
}

impl Progress {
    /// Apply the event of `which` at `t` (state `y` there, before it).
    pub(crate) fn event<D: Drive>(
        &mut self,
        model: &Relay<'_, D>,
        settings: &Settings,
        which: Which,
        t: f64,
        mut y: Y,
    ) {
        self.modes = transition(model, settings, which, t, &mut y, self.modes, &mut self.rec);
        if let Some(last) = self.pieces.last_mut() {
            last.y1 = y;
        }
        self.t = t;
        self.y = y;
        if self.rec.contact.len() >= MAX_EVENTS {
            self.ending = Some(Outcome::EventLimit);
        }
    }

    /// Count one more step, failing past the limit.
    pub(crate) fn count_step(
        &mut self,
        m: &Mechanics,
        settings: &Settings,
    ) -> Result<(), DriveError> {
        self.steps += 1;
        if self.steps > MAX_DRIVEN_STEPS {
            return Err(DriveError::TooManySteps {
                steps: MAX_DRIVEN_STEPS,
                time: self.t,
                t_end: settings.t_end,
                mass: m.mass,
                stiffness: m.stiffness,
                period: 2.0 * std::f64::consts::PI * (m.mass / m.stiffness).sqrt(),
            });
        }
        Ok(())
    }
}

/// Simulate the relay of `model` from the drive's state `e0` to
/// `horizon`. Parameters must have been validated.
pub(crate) fn run<D: Drive>(
    model: &Relay<'_, D>,
    settings: &Settings,
    e0: f64,
    horizon: Horizon,
) -> Result<TwoStageRun, DriveError> {
    let mut progress = start(model, e0);
    match super::linear::LinearSystem::of(model) {
        Some(system) => super::linear::propagate(&system, model, settings, horizon, &mut progress)?,
        None => integrate(model, settings, horizon, &mut progress)?,
    }
    Ok(finish(model, settings, horizon, progress))
}

/// The state at t = 0: on the rest stop when the drive does not lift it.
fn start<D: Drive>(model: &Relay<'_, D>, e0: f64) -> Progress {
    let m = model.m;
    let g = m.gap;
    let x0 = m.initial_position;
    let mut y = Y::new(x0 - g, m.initial_velocity, x0 - g, m.initial_velocity, e0);
    let mut modes = Modes {
        contact: Stop::Open,
        pole: Stop::Open,
        rest: Stop::Open,
    };
    if model.rest
        && x0 == 0.0
        && m.initial_velocity <= 0.0
        && model.armature_push(0.0, &y, modes) <= 0.0
    {
        modes.rest = Stop::Pressed;
        y[1] = 0.0;
    }
    let mut rec = Tally {
        contact: Vec::new(),
        intervals: vec![Interval {
            state: ContactState::Open,
            start: 0.0,
            end: 0.0,
        }],
        pole: Vec::new(),
        back: Vec::new(),
        back_intervals: vec![Interval {
            state: if modes.rest == Stop::Pressed {
                ContactState::Closed
            } else {
                ContactState::Open
            },
            start: 0.0,
            end: 0.0,
        }],
        lift_offs: Vec::new(),
        reach: x0,
    };
    if modes.rest == Stop::Pressed {
        rec.back.push(Impact::touch(0.0, 0.0));
    } else if model.rest && x0 == 0.0 {
        rec.lift_offs.push(0.0);
    }
    Progress {
        t: 0.0,
        y,
        modes,
        rec,
        pieces: Vec::new(),
        steps: 0,
        bound: EnergyBound::new(),
        ending: None,
    }
}

/// DOP853 from event to event, to the horizon.
fn integrate<D: Drive>(
    model: &Relay<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    p: &mut Progress,
) -> Result<(), DriveError> {
    let tol = tolerance(model);
    let mut h = 0.05 / fastest(model);
    while p.t < settings.t_end && p.ending.is_none() {
        let modes = p.modes;
        let f = |t: f64, y: &Y| model.rate(t, y, modes);
        let mut solver = Dop853::new(f, p.t, p.y, h, tol);
        loop {
            p.count_step(model.m, settings)?;
            let step = solver.step(settings.t_end).map_err(DriveError::from)?;
            if !step.y1.iter().all(|v| v.is_finite()) {
                return Err(MechanicsError::StepSizeTooSmall {
                    time: step.t1,
                    step: step.t1 - step.t0,
                }
                .into());
            }
            let dense = solver.dense();
            h = solver.next_step();
            if let Some(error) = pole_limit(model, &step.y1, step.t1) {
                return Err(error);
            }
            match model.first_event(&dense, step.t1, modes) {
                None => {
                    sample(model, &dense, step.t1, modes, &mut p.rec);
                    p.pieces.push(Span::dense(dense, step.t1, step.y1, modes));
                    p.t = step.t1;
                    p.y = step.y1;
                    if horizon == Horizon::Closing
                        && let Some(end) = decided(model, &mut p.bound, p.t, &p.y, modes, &p.rec)
                    {
                        p.ending = Some(end);
                        return Ok(());
                    }
                    if p.t >= settings.t_end {
                        return Ok(());
                    }
                }
                Some((te, which)) => {
                    let ye = dense.at(te);
                    sample(model, &dense, te, modes, &mut p.rec);
                    p.pieces.push(Span::dense(dense, te, ye, modes));
                    p.event(model, settings, which, te, ye);
                    break;
                }
            }
        }
    }
    Ok(())
}

/// The run's records, with the motion held where it stopped to `t_end`.
fn finish<D: Drive>(
    model: &Relay<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    mut p: Progress,
) -> TwoStageRun {
    let t_end = settings.t_end;
    if p.t < t_end {
        p.pieces.push(Span::dense(
            Dense::constant(p.t, t_end, p.y),
            t_end,
            p.y,
            p.modes,
        ));
    }
    let rec = &mut p.rec;
    for list in [&mut rec.intervals, &mut rec.back_intervals] {
        if let Some(last) = list.last_mut() {
            last.end = t_end;
        }
    }
    let back = Chatter {
        outcome: Outcome::Stuck,
        first_impact: rec.back.first().map(|i| i.impact_time),
        settle_time: None,
        bounce_count: 0,
        impacts: std::mem::take(&mut rec.back),
        intervals: std::mem::take(&mut rec.back_intervals),
        shortfall: None,
        accumulation_time: None,
        t_end,
    };
    let strokes: Vec<Stroke> = strokes(&rec.lift_offs, &rec.contact, &back.impacts);
    let shortfall = model.g() - rec.reach;
    let contact = match horizon {
        Horizon::Cycle => summary(
            std::mem::take(&mut rec.intervals),
            std::mem::take(&mut rec.contact),
            strokes.first(),
            shortfall,
            t_end,
        ),
        Horizon::Closing => closing_summary(
            model,
            &mut p.bound,
            rec,
            p.ending,
            (p.t, p.y, p.modes),
            t_end,
        ),
    };
    TwoStageRun {
        contact,
        pole_face: std::mem::take(&mut p.rec.pole),
        back,
        lift_off: p.rec.lift_offs.first().copied(),
        strokes,
        steps: p.steps,
        pieces: p.pieces,
    }
}

/// The error when the armature has pressed through to the magnet's pole
/// (the drive's model ends there) at `time`.
fn pole_limit<D: Drive>(model: &Relay<'_, D>, y: &Y, time: f64) -> Option<DriveError> {
    let pole = model.drive.pole();
    let position = model.g() + y[0];
    (position >= pole).then_some(DriveError::ArmatureAtPole {
        time,
        position,
        pole,
    })
}

/// The closing's chatter: its ending decided by the energy bound, or read
/// at the horizon.
pub(crate) fn closing_summary<D: Drive>(
    model: &Relay<'_, D>,
    bound: &mut EnergyBound,
    rec: &mut Tally,
    ending: Option<Outcome>,
    (t, y, modes): (f64, Y, Modes),
    t_end: f64,
) -> Chatter {
    let impacts = std::mem::take(&mut rec.contact);
    let intervals = std::mem::take(&mut rec.intervals);
    let closed = modes.contact != Stop::Open;
    let outcome = match ending {
        Some(o) => o,
        None if impacts.is_empty() => Outcome::NeverCloses,
        None if closed => {
            if modes.contact == Stop::Pressed || bound.cannot_release(model, t, &y, modes) {
                Outcome::Stuck
            } else {
                Outcome::EndOfTime
            }
        }
        None => {
            if bound.cannot_reach(model, t, &y, modes) {
                Outcome::EndsOpen
            } else {
                Outcome::EndOfTime
            }
        }
    };
    let first_impact = impacts.first().map(|i| i.impact_time);
    let settle_time = if outcome.is_closed() {
        impacts.last().map(|i| i.impact_time)
    } else {
        None
    };
    let bounce_count = crate::chatter::bounces(&intervals);
    Chatter {
        outcome,
        first_impact,
        settle_time,
        bounce_count,
        impacts,
        intervals,
        shortfall: (outcome == Outcome::NeverCloses).then_some((model.g() - rec.reach).max(0.0)),
        accumulation_time: None,
        t_end,
    }
}

/// Whether a closing's ending is decided at `t`: the contact closed and
/// unable to release, or open after touching and unable to reach it again.
pub(crate) fn decided<D: Drive>(
    model: &Relay<'_, D>,
    bound: &mut EnergyBound,
    t: f64,
    y: &Y,
    modes: Modes,
    rec: &Tally,
) -> Option<Outcome> {
    if rec.contact.is_empty() || !bound.due() {
        return None;
    }
    match modes.contact {
        Stop::Engaged if bound.cannot_release(model, t, y, modes) => Some(Outcome::Stuck),
        Stop::Open if bound.cannot_reach(model, t, y, modes) => Some(Outcome::EndsOpen),
        _ => None,
    }
}

/// Apply the event of `which` at `t` to the state and the records; the
/// new modes.
pub(crate) fn transition<D: Drive>(
    model: &Relay<'_, D>,
    settings: &Settings,
    which: Which,
    t: f64,
    y: &mut Y,
    mut modes: Modes,
    rec: &mut Tally,
) -> Modes {
    let g = model.g();
    let no_blade = model.build.blade.is_none();
    match which {
        Which::Contact => match modes.contact {
            Stop::Open => {
                if y[2] <= 0.0 {
                    y[2] = 0.0;
                    if no_blade {
                        y[0] = 0.0;
                    }
                }
                let v = y[3];
                rec.contact.push(Impact::touch(t, v));
                Tally::switch(&mut rec.intervals, t, ContactState::Closed);
                modes.contact = match model.contact {
                    Surface::Rigid { restitution } => rigid(
                        model,
                        settings,
                        Which::Contact,
                        t,
                        y,
                        modes,
                        restitution,
                        rec,
                    ),
                    _ => Stop::Engaged,
                };
            }
            Stop::Engaged | Stop::Pressed => {
                if modes.contact == Stop::Engaged && y[2] <= 0.0 {
                    y[2] = 0.0;
                    if no_blade {
                        y[0] = 0.0;
                    }
                }
                if let Some(last) = rec.contact.last_mut() {
                    release(last, t, y[3]);
                }
                Tally::switch(&mut rec.intervals, t, ContactState::Open);
                modes.contact = Stop::Open;
            }
        },
        Which::Pole => {
            let o = model.overtravel();
            match modes.pole {
                Stop::Open => {
                    if y[0] <= o {
                        y[0] = o;
                    }
                    rec.pole.push(Impact::touch(t, y[1]));
                    let surface = model.build.pole_face.map(|p| p.surface);
                    modes.pole = match surface {
                        Some(Surface::Rigid { restitution }) => {
                            rigid(model, settings, Which::Pole, t, y, modes, restitution, rec)
                        }
                        _ => Stop::Engaged,
                    };
                }
                Stop::Engaged | Stop::Pressed => {
                    if modes.pole == Stop::Engaged && y[0] <= o {
                        y[0] = o;
                    }
                    if let Some(last) = rec.pole.last_mut() {
                        release(last, t, y[1]);
                    }
                    modes.pole = Stop::Open;
                }
            }
        }
        Which::Rest => match modes.rest {
            Stop::Open => {
                y[0] = -g;
                if no_blade {
                    y[2] = -g;
                }
                rec.back.push(Impact::touch(t, -y[1]));
                Tally::switch(&mut rec.back_intervals, t, ContactState::Closed);
                modes.rest = match model.back {
                    None => {
                        y[1] = 0.0;
                        if no_blade {
                            y[3] = 0.0;
                        }
                        Stop::Pressed
                    }
                    Some(Surface::Rigid { restitution }) => {
                        rigid(model, settings, Which::Rest, t, y, modes, restitution, rec)
                    }
                    Some(_) => Stop::Engaged,
                };
            }
            Stop::Engaged | Stop::Pressed => {
                y[0] = -g;
                if no_blade {
                    y[2] = -g;
                }
                if let Some(last) = rec.back.last_mut() {
                    release(last, t, -y[1]);
                }
                Tally::switch(&mut rec.back_intervals, t, ContactState::Open);
                rec.lift_offs.push(t);
                modes.rest = Stop::Open;
            }
        },
    }
    modes
}

/// A rigid impact of `which` at `t` with restitution `e`: the velocity
/// reversed, or the body pressed on the stop when the rebound would be
/// below resolution (shorter than `min_open_time` or smaller than
/// `min_gap`). Returns the stop's new mode; records the rebound.
#[allow(clippy::too_many_arguments)]
fn rigid<D: Drive>(
    model: &Relay<'_, D>,
    settings: &Settings,
    which: Which,
    t: f64,
    y: &mut Y,
    modes: Modes,
    e: f64,
    rec: &mut Tally,
) -> Stop {
    let no_blade = model.build.blade.is_none();
    // The velocity components of the body that hits, and its sign toward
    // the stop.
    let (idx, sign) = match which {
        Which::Contact => (if no_blade { 1 } else { 3 }, 1.0),
        Which::Pole => (1, 1.0),
        Which::Rest => (1, -1.0),
    };
    let v = y[idx];
    let w = e * v.abs();
    let mut open = modes;
    match which {
        Which::Contact => open.contact = Stop::Open,
        Which::Pole => open.pole = Stop::Open,
        Which::Rest => open.rest = Stop::Open,
    }
    let set_v = |y: &mut Y, value: f64| {
        y[idx] = value;
        if no_blade && idx == 1 {
            y[3] = value;
        }
        if no_blade && idx == 3 {
            y[1] = value;
        }
    };
    set_v(y, -sign * w);
    let a = model.toward(which, t, y, open);
    let resolved =
        a > 0.0 && (2.0 * w / a < settings.min_open_time || w * w / (2.0 * a) < settings.min_gap);
    let pressed = resolved || (w == 0.0 && a > 0.0);
    let list = match which {
        Which::Contact => &mut rec.contact,
        Which::Pole => &mut rec.pole,
        Which::Rest => &mut rec.back,
    };
    if pressed {
        set_v(y, 0.0);
        Stop::Pressed
    } else {
        if let Some(last) = list.last_mut() {
            release(last, t, -w);
        }
        let intervals = match which {
            Which::Contact => Some(&mut rec.intervals),
            Which::Rest => Some(&mut rec.back_intervals),
            Which::Pole => None,
        };
        if let Some(iv) = intervals {
            Tally::switch(iv, t, ContactState::Open);
        }
        if which == Which::Rest {
            rec.lift_offs.push(t);
        }
        Stop::Open
    }
}

/// Peak and minimum contact forces and the largest opening after each
/// release, sampled on the dense output of a step up to `t1`.
fn sample<D: Drive>(
    model: &Relay<'_, D>,
    dense: &Dense<5>,
    t1: f64,
    modes: Modes,
    rec: &mut Tally,
) {
    let t0 = dense.t0;
    for k in 0..=SAMPLES {
        let t = t0 + (t1 - t0) * k as f64 / SAMPLES as f64;
        rec.observe(model.g(), modes, &dense.at(t), |y| match modes.contact {
            // Pressed on a rigid contact: the blade's spring is the force.
            Stop::Pressed => model.blade_force(y),
            // F_c = max(0, ·) released by force: zero, not a rounding
            // below it, where the contact lets go.
            _ if model.build.release == Release::Force => law(&model.contact, y[2], y[3]).max(0.0),
            _ => law(&model.contact, y[2], y[3]),
        });
    }
}

/// Tolerances for the state's components.
fn tolerance<D: Drive>(model: &Relay<'_, D>) -> Tolerance<5> {
    let g = model.g();
    let omega = (model.m.stiffness / model.m.mass).sqrt();
    Tolerance {
        rtol: RTOL,
        atol: Y::new(
            RTOL * g,
            RTOL * g * omega,
            RTOL * g,
            RTOL * g * omega,
            RTOL * model.drive.e_scale(),
        ),
    }
}

/// rad/s, the fastest natural frequency in the model (the first trial step).
fn fastest<D: Drive>(model: &Relay<'_, D>) -> f64 {
    let m = model.m;
    let mut w = (m.stiffness / m.mass).sqrt();
    let mass_at_contact = model.build.blade.map_or(m.mass, |b| b.mass);
    if let Some(b) = &model.build.blade {
        w = w.max((b.stiffness / b.mass).sqrt());
    }
    let stiff = |s: &Surface| match *s {
        Surface::KelvinVoigt { stiffness, .. } => stiffness,
        _ => 0.0,
    };
    w = w.max((stiff(&model.contact) / mass_at_contact).sqrt());
    if let Some(p) = &model.build.pole_face {
        w = w.max((stiff(&p.surface) / m.mass).sqrt());
    }
    w
}

/// A constant force (the step drive), as a [`Drive`].
pub(crate) struct Constant {
    force: f64,
    time_scale: f64,
}

impl Drive for Constant {
    fn force(&self, _t: f64, _x: f64, _e: f64) -> f64 {
        self.force
    }

    fn rate(&self, _t: f64, _x: f64, _e: f64) -> f64 {
        0.0
    }

    fn frozen_work(&self, _t: f64, _e: f64, from: f64, to: f64) -> f64 {
        self.force * (to - from)
    }

    fn e_scale(&self) -> f64 {
        1.0
    }

    fn time_scale(&self) -> f64 {
        self.time_scale
    }

    fn pole(&self) -> f64 {
        f64::INFINITY
    }

    fn constant(&self) -> Option<f64> {
        Some(self.force)
    }
}

/// Simulate the relay of `m`, built as `build`, under `drive` from t = 0:
/// one closing (`Horizon::Closing`, stopped where its ending is decided)
/// or the whole run to `settings.t_end` (`Horizon::Cycle`).
///
/// The step drive (`mechanics.force` from t = 0) has no rest stop below
/// the contact, as in the one-mass engine; a force `F(t, x)` (N toward
/// closing at the armature's position) holds the armature on its rest
/// stop at x = 0 until it beats the preload, and `stops.back` is the rest
/// stop's law (`None`: landings are inelastic).
///
/// ```
/// use chatterspice::mechanics::cycle::Stops;
/// use chatterspice::mechanics::two_stage::{Blade, Horizon, PoleFace, Release, TwoStage,
///                                           simulate_two_stage};
/// use chatterspice::mechanics::Drive;
/// use chatterspice::{Mechanics, Settings, Surface};
///
/// let armature = Mechanics { mass: 2e-4, stiffness: 800.0, damping: 0.04, force: 0.6,
///                            gap: 4.5e-4, initial_position: 0.0, initial_velocity: 0.0,
///                            preload: 0.1 };
/// let relay = TwoStage {
///     blade: Some(Blade { mass: 3e-5, stiffness: 3000.0, damping: 0.0 }),
///     pole_face: Some(PoleFace { overtravel: 1.5e-4, release: Release::Position,
///                                surface: Surface::KelvinVoigt { stiffness: 1e6, damping: 5.0 } }),
///     release: Release::Position,
/// };
/// let stops = Stops { make: Surface::KelvinVoigt { stiffness: 8e4, damping: 0.2 }, back: None };
/// let settings = Settings { t_end: 0.02, ..Settings::default() };
/// let run = simulate_two_stage(&armature, &relay, &stops, &settings, Drive::Step,
///                              Horizon::Closing)?;
/// assert!(run.contact.first_impact.is_some());
/// // The armature reaches the pole face after the contact has made.
/// assert!(run.pole_face[0].impact_time > run.contact.impacts[0].impact_time);
/// # Ok::<(), chatterspice::mechanics::DriveError>(())
/// ```
pub fn simulate_two_stage(
    m: &Mechanics,
    build: &TwoStage,
    stops: &super::super::cycle::Stops,
    settings: &Settings,
    drive: super::super::Drive<'_>,
    horizon: Horizon,
) -> Result<TwoStageRun, DriveError> {
    super::validate_all(m, build, &stops.make, settings)?;
    match drive {
        super::super::Drive::Step => {
            if !m.force.is_finite() {
                return Err(DriveError::InvalidParameter {
                    name: "mechanics.force",
                    value: m.force,
                    requirement: "a finite force in N",
                });
            }
            let constant = Constant {
                force: m.force,
                time_scale: (m.mass / m.stiffness).sqrt(),
            };
            let model = Relay {
                m,
                build,
                contact: stops.make,
                back: None,
                rest: false,
                drive: &constant,
            };
            run(&model, settings, 0.0, horizon)
        }
        super::super::Drive::Force(force) => {
            if m.initial_position < 0.0 {
                return Err(DriveError::InvalidParameter {
                    name: "mechanics.initial_position",
                    value: m.initial_position,
                    requirement: "a position in m at or above the rest stop at 0 (and below the gap)",
                });
            }
            let forced = super::super::forced::Forced::new(m, force);
            let model = Relay {
                m,
                build,
                contact: stops.make,
                back: stops.back,
                rest: true,
                drive: &forced,
            };
            run(&model, settings, 0.0, horizon)
        }
    }
}
