//! The armature's trajectory under any drive: one entry point and one
//! result for the step force and for a force that varies in time and
//! position.
//!
//! [`simulate_drive`] runs the engine that fits the drive:
//!
//! - [`Drive::Step`], the constant force `mechanics.force` from t = 0: the
//!   exact event engine ([`simulate`]). Between its events the
//!   motion is rebuilt from the exact event states: closed-form flight and
//!   Kelvin–Voigt contact pieces, and each Hunt–Crossley contact integrated
//!   again by the very steps that found its release. The step model has no
//!   rest stop below the contact (a rebound may carry the armature past
//!   x = 0), as in the engine; `stops.back` is not used.
//! - [`Drive::Force`], a force `F(t, x)`: the whole operating cycle with
//!   event location ([`super::cycle`]): held on the rest stop, flight, the
//!   make contact, pressed on a rigid one, the back contact on the rest
//!   stop, for every pulse of the force.
//!
//! Either way the result is a [`Trajectory`]: position, velocity, contact
//! gap and contact forces at any time, the event list, and the contact
//! records (the chatter of the normally-open contact, and of the rest stop
//! as the normally-closed one).

use super::cycle::{Cycle, Stroke};
use super::driven::state_on;
use super::engine::{free_flight, kelvin_voigt_contact, simulate};
use super::error::{DriveError, MechanicsError};
use super::forced::simulate_cycle;
use super::hunt_crossley::HcContact;
use super::linear::LinearPiece;
use super::parameters::{Mechanics, Settings, Stops};
use super::segment::{Motion, Segment, Side, path_of};
use super::surface::{Surface, surface_force};
use super::two_stage::run::TwoStageRun;
use crate::chatter::{Chatter, ContactState, Impact};

/// What pushes the armature toward the fixed contact.
#[derive(Clone, Copy)]
pub enum Drive<'a> {
    /// `mechanics.force` (N), a step at t = 0.
    Step,
    /// A force (N, toward closing) at time t (s) and position x (m); it
    /// replaces `mechanics.force`. It must be finite, and smooth between
    /// the instants the caller knows of (the integrator samples it).
    Force(&'a dyn Fn(f64, f64) -> f64),
}

impl std::fmt::Debug for Drive<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Drive::Step => f.write_str("Step"),
            Drive::Force(_) => f.write_str("Force(..)"),
        }
    }
}

/// Simulate the armature under `drive` from t = 0 to `settings.t_end`.
/// Parameters are validated first; an invalid one is an error naming its
/// scenario key.
///
/// ```
/// use chatterspice::mechanics::cycle::Stops;
/// use chatterspice::mechanics::{Drive, TrajectoryEventKind, simulate_drive};
/// use chatterspice::{Mechanics, Settings, Surface};
///
/// let relay = Mechanics { mass: 1e-4, stiffness: 5000.0, damping: 0.07, force: 1.0,
///                         gap: 1.4e-4, initial_position: 0.0, initial_velocity: 0.0,
///                         preload: 0.0 };
/// let surface = Surface::KelvinVoigt { stiffness: 5e5, damping: 1.92 };
/// let stops = Stops { make: surface, back: None };
///
/// // A step force: the exact engine's closing, as a trajectory.
/// let closing = simulate_drive(&relay, &stops, &Settings::default(), Drive::Step)?;
/// assert_eq!(closing.chatter().bounce_count, 5);
/// let release = closing.chatter().impacts[1].release_time.unwrap();
/// assert_eq!(closing.gap(release - 1e-7), 0.0);
/// assert!(closing.gap(release + 1e-5) > 0.0 && closing.velocity(release + 1e-5) < 0.0);
///
/// // A 10 ms pulse against a 0.1 N preload: the whole cycle.
/// let pulse = |t: f64, _x: f64| if t < 0.01 { 1.0 } else { 0.0 };
/// let held = Mechanics { preload: 0.1, ..relay };
/// let settings = Settings { t_end: 0.03, ..Settings::default() };
/// let cycle = simulate_drive(&held, &stops, &settings, Drive::Force(&pulse))?;
/// let kinds: Vec<TrajectoryEventKind> = cycle.events().iter().map(|e| e.kind).collect();
/// assert_eq!(kinds.first(), Some(&TrajectoryEventKind::LiftOff));
/// assert!(kinds.contains(&TrajectoryEventKind::Settled));
/// assert!(kinds.contains(&TrajectoryEventKind::Release));
/// assert_eq!(kinds.last(), Some(&TrajectoryEventKind::Landing));
/// assert_eq!(cycle.gap(0.029), relay.gap);
/// # Ok::<(), chatterspice::mechanics::DriveError>(())
/// ```
pub fn simulate_drive(
    mechanics: &Mechanics,
    stops: &Stops,
    settings: &Settings,
    drive: Drive<'_>,
) -> Result<Trajectory, DriveError> {
    match drive {
        Drive::Step => Ok(Trajectory::of_step(mechanics, &stops.make, settings)?),
        Drive::Force(force) => {
            let cycle = simulate_cycle(mechanics, stops, settings, force)?;
            Ok(Trajectory::of_cycle(mechanics, stops, settings, cycle))
        }
    }
}

/// What happened at an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TrajectoryEventKind {
    /// The armature leaves its rest stop on its way to the contact.
    LiftOff,
    /// The moving contact touches the fixed one.
    Touch,
    /// It separates from it.
    Release,
    /// The contact is closed for good from here (to the next release by
    /// a weakening drive, if any): the last touch of a closing.
    Settled,
    /// The armature lands on its rest stop.
    Landing,
    /// It rebounds off the rest stop.
    Rebound,
    /// The armature hits the pole face (a relay with a contact blade).
    PoleFace,
    /// The armature leaves the pole face.
    PoleFaceRelease,
}

/// One event of a trajectory.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct TrajectoryEvent {
    /// s
    pub time: f64,
    /// What happened.
    pub kind: TrajectoryEventKind,
    /// m, the position (the gap for contact events, 0 on the rest stop).
    pub position: f64,
    /// m/s, the velocity just before the event for a touch or a landing,
    /// just after it for a release or a rebound, positive toward the
    /// contact; 0 for lift-off and settling.
    pub velocity: f64,
}

/// The old name of [`TrajectoryEventKind`].
#[deprecated(note = "renamed to `TrajectoryEventKind`")]
pub type EventKind = TrajectoryEventKind;

/// The old name of [`TrajectoryEvent`].
#[deprecated(note = "renamed to `TrajectoryEvent`")]
pub type Event = TrajectoryEvent;

/// The armature's motion from t = 0 to the horizon.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// m, the travel to the fixed contact.
    gap: f64,
    make_surface: Surface,
    back_surface: Option<Surface>,
    /// Tiling [0, t_end] in order.
    segments: Vec<Segment>,
    events: Vec<TrajectoryEvent>,
    make: Chatter,
    back: Option<Chatter>,
    strokes: Vec<Stroke>,
    pole_face: Vec<Impact>,
    t_end: f64,
}

impl Trajectory {
    /// s, the horizon.
    pub fn t_end(&self) -> f64 {
        self.t_end
    }

    /// (m, m/s): position and velocity at `t` (s), held at the ends of
    /// [0, t_end].
    pub fn state(&self, t: f64) -> (f64, f64) {
        let Some(seg) = self.segment(t) else {
            return (0.0, 0.0);
        };
        let t = t.clamp(seg.t0, seg.t1);
        match &seg.motion {
            Motion::Rest { x, .. } | Motion::Held { x, .. } => (*x, 0.0),
            Motion::Linear(piece) => piece.state(t - seg.t0),
            Motion::Integrated { step, y1 } => {
                let y = if t >= seg.t1 { *y1 } else { state_on(step, t) };
                (self.gap + y[0], y[1])
            }
            Motion::Contact { step, touch } => {
                let (delta, rate) = step.at(t - touch);
                (self.gap + delta, rate)
            }
            Motion::Staged(piece) => {
                let y = piece.at(t);
                (self.gap + y[2], y[3])
            }
        }
    }

    /// (m, m/s): the armature's position and velocity at `t` (s). The
    /// same as [`Trajectory::state`] for the one-mass model; with a
    /// contact blade, the armature that carries it.
    pub fn armature(&self, t: f64) -> (f64, f64) {
        let Some(seg) = self.segment(t) else {
            return (0.0, 0.0);
        };
        match &seg.motion {
            Motion::Staged(piece) => {
                let y = piece.at(t.clamp(seg.t0, seg.t1));
                (self.gap + y[0], y[1])
            }
            _ => self.state(t),
        }
    }

    /// The armature's impacts on the pole face (a relay with a pole face;
    /// empty otherwise).
    pub fn pole_face_impacts(&self) -> &[Impact] {
        &self.pole_face
    }

    /// m, the position at `t` (0 on the rest stop, the gap at the
    /// contact).
    pub fn position(&self, t: f64) -> f64 {
        self.state(t).0
    }

    /// m/s, the velocity at `t`, positive toward the contact.
    pub fn velocity(&self, t: f64) -> f64 {
        self.state(t).1
    }

    /// m, how far apart the contacts are at `t`: 0 while the contact is
    /// closed (a rebound below the resolution counts as closed), else the
    /// distance left to travel.
    pub fn gap(&self, t: f64) -> f64 {
        if self.closed_at(t) {
            0.0
        } else {
            (self.gap - self.position(t)).max(0.0)
        }
    }

    /// N, the force of the fixed contact on the moving one at `t`,
    /// positive pushing it back; 0 while open. A Kelvin–Voigt surface may
    /// pull just before a release (its force is not clamped).
    pub fn contact_force(&self, t: f64) -> f64 {
        self.force_of(t, Side::Make)
    }

    /// N, the force of the rest stop on the armature at `t`, positive
    /// pushing it toward the contact; 0 off the stop.
    pub fn back_force(&self, t: f64) -> f64 {
        self.force_of(t, Side::Back)
    }

    /// Every event in time order.
    pub fn events(&self) -> &[TrajectoryEvent] {
        &self.events
    }

    /// The normally-open contact's record.
    pub fn chatter(&self) -> &Chatter {
        &self.make
    }

    /// The rest stop as the normally-closed contact (a driven cycle only).
    pub fn back(&self) -> Option<&Chatter> {
        self.back.as_ref()
    }

    /// The strokes of a driven cycle (none for a step).
    pub fn strokes(&self) -> &[Stroke] {
        &self.strokes
    }

    /// The normally-open contact's record, taken out.
    pub fn into_chatter(self) -> Chatter {
        self.make
    }

    /// Both contacts' records, taken out: the normally-open contact and
    /// (a driven cycle only) the rest stop.
    pub fn into_contacts(self) -> (Chatter, Option<Chatter>) {
        (self.make, self.back)
    }

    /// (s, m): the position at t = 0 and at the end of every segment (every
    /// integrator step and event of a driven cycle; every event of a step
    /// drive), strictly increasing in time.
    pub fn path(&self) -> Vec<(f64, f64)> {
        path_of((0.0, self.position(0.0)), &self.segments, self.gap)
    }

    /// (s, m): the gap sampled `per_segment` times across every segment
    /// (at both ends and in between, denser toward the ends), for a
    /// profile that is linear between its samples.
    pub fn gap_samples(&self, per_segment: usize) -> Vec<(f64, f64)> {
        let n = per_segment.max(2);
        let mut out: Vec<(f64, f64)> = Vec::with_capacity(self.segments.len() * n);
        for seg in &self.segments {
            // Openings in full; a contact's gap is 0 throughout.
            let count = if seg.side == Side::Open && seg.t1 > seg.t0 {
                n
            } else {
                2
            };
            for k in 0..count {
                // Cosine spacing: dense where openings start and end.
                let theta = std::f64::consts::PI * k as f64 / (count - 1) as f64;
                let t = seg.t0 + (seg.t1 - seg.t0) * 0.5 * (1.0 - theta.cos());
                if out.last().is_none_or(|&(tp, _)| t > tp) {
                    out.push((t, self.gap(t)));
                }
            }
        }
        if out.is_empty() {
            out.push((0.0, self.gap(0.0)));
        }
        out
    }

    fn segment(&self, t: f64) -> Option<&Segment> {
        let k = self.segments.partition_point(|s| s.t1 < t);
        self.segments.get(k).or(self.segments.last())
    }

    fn closed_at(&self, t: f64) -> bool {
        let iv = &self.make.intervals;
        let k = iv.partition_point(|i| i.end < t);
        iv.get(k)
            .is_some_and(|i| i.state == ContactState::Closed && i.start <= t)
    }

    fn force_of(&self, t: f64, side: Side) -> f64 {
        let Some(seg) = self.segment(t) else {
            return 0.0;
        };
        if seg.side != side {
            return 0.0;
        }
        match &seg.motion {
            Motion::Rest { force, .. } => return *force,
            Motion::Held { forces, .. } if seg.t1 > seg.t0 => {
                let w = ((t - seg.t0) / (seg.t1 - seg.t0)).clamp(0.0, 1.0);
                return forces.0 + (forces.1 - forces.0) * w;
            }
            Motion::Held { forces, .. } => return forces.1,
            _ => {}
        }
        let (x, v) = self.state(t);
        match side {
            Side::Make => surface_force(&self.make_surface, x - self.gap, v),
            Side::Back => self.back_surface.map_or(0.0, |s| surface_force(&s, -x, -v)),
            Side::Open => 0.0,
        }
    }

    /// The trajectory of a driven cycle.
    pub(crate) fn of_cycle(
        m: &Mechanics,
        stops: &Stops,
        settings: &Settings,
        cycle: Cycle,
    ) -> Self {
        let mut events = contact_events(&cycle.make, m.gap);
        for b in &cycle.back.impacts {
            events.push(TrajectoryEvent {
                time: b.impact_time,
                kind: TrajectoryEventKind::Landing,
                position: 0.0,
                velocity: -b.impact_velocity,
            });
            if let (Some(t), Some(v)) = (b.release_time, b.release_velocity) {
                events.push(TrajectoryEvent {
                    time: t,
                    kind: TrajectoryEventKind::Rebound,
                    position: 0.0,
                    velocity: -v,
                });
            }
        }
        for s in &cycle.strokes {
            let rebound = events
                .iter()
                .any(|e| e.kind == TrajectoryEventKind::Rebound && e.time == s.lift_off);
            if !rebound {
                events.push(TrajectoryEvent {
                    time: s.lift_off,
                    kind: TrajectoryEventKind::LiftOff,
                    position: 0.0,
                    velocity: 0.0,
                });
            }
            if let Some(t) = s.last_make {
                events.push(settled(t, m.gap));
            }
        }
        sort(&mut events);
        Trajectory {
            gap: m.gap,
            make_surface: stops.make,
            back_surface: stops.back,
            segments: cycle.segments,
            events,
            make: cycle.make,
            back: Some(cycle.back),
            strokes: cycle.strokes,
            pole_face: Vec::new(),
            t_end: settings.t_end,
        }
    }
}

impl Trajectory {
    /// The trajectory of a two-stage run ([`TwoStageRun`]): the
    /// contact point is the blade's; [`Trajectory::armature`] and
    /// [`Trajectory::path`] follow the armature.
    pub fn of_two_stage(
        m: &Mechanics,
        stops: &Stops,
        settings: &Settings,
        run: TwoStageRun,
    ) -> Trajectory {
        let g = m.gap;
        let mut events = contact_events(&run.contact, g);
        for p in &run.pole_face {
            events.push(TrajectoryEvent {
                time: p.impact_time,
                kind: TrajectoryEventKind::PoleFace,
                position: run.state(p.impact_time, g).0,
                velocity: p.impact_velocity,
            });
            if let (Some(t), Some(v)) = (p.release_time, p.release_velocity) {
                events.push(TrajectoryEvent {
                    time: t,
                    kind: TrajectoryEventKind::PoleFaceRelease,
                    position: run.state(t, g).0,
                    velocity: v,
                });
            }
        }
        for &t in run.strokes.iter().map(|s| &s.lift_off) {
            events.push(TrajectoryEvent {
                time: t,
                kind: TrajectoryEventKind::LiftOff,
                position: 0.0,
                velocity: 0.0,
            });
        }
        for b in &run.back.impacts {
            events.push(TrajectoryEvent {
                time: b.impact_time,
                kind: TrajectoryEventKind::Landing,
                position: 0.0,
                velocity: -b.impact_velocity,
            });
        }
        if let Some(t) = run.contact.settle_time {
            events.push(settled(t, g));
        }
        sort(&mut events);
        let segments = run
            .pieces
            .into_iter()
            .map(|piece| Segment {
                t0: piece.t0,
                t1: piece.t1,
                side: if piece.contact_closed() {
                    Side::Make
                } else {
                    Side::Open
                },
                motion: Motion::Staged(Box::new(piece)),
            })
            .collect();
        let driven = !run.strokes.is_empty() || !run.back.impacts.is_empty();
        Trajectory {
            gap: g,
            make_surface: stops.make,
            back_surface: stops.back,
            segments,
            events,
            make: run.contact,
            back: driven.then_some(run.back),
            strokes: run.strokes,
            pole_face: run.pole_face,
            t_end: settings.t_end,
        }
    }

    /// The step-force closing of `m` onto `surface`: the exact engine's
    /// record ([`simulate`]), with the motion between its events
    /// rebuilt from the exact event states.
    pub fn of_step(
        m: &Mechanics,
        surface: &Surface,
        settings: &Settings,
    ) -> Result<Trajectory, MechanicsError> {
        let chatter = simulate(m, surface, settings)?;
        step_trajectory(m, surface, settings, chatter)
    }
}

/// The trajectory of `chatter`, the engine's record of `m` on `surface`.
fn step_trajectory(
    m: &Mechanics,
    surface: &Surface,
    settings: &Settings,
    chatter: Chatter,
) -> Result<Trajectory, MechanicsError> {
    let g = m.gap;
    let t_end = settings.t_end;
    let f_net = m.force - m.preload;
    let flight = free_flight(m);
    let at_rest = m.initial_position == 0.0 && m.initial_velocity == 0.0 && f_net <= 0.0;
    let mut segments = Vec::with_capacity(chatter.intervals.len());
    let mut events = contact_events(&chatter, g);
    if at_rest {
        let held = m.preload - m.force;
        segments.push(Segment::rest(0.0, t_end, 0.0, false, held));
    } else if m.initial_position == 0.0 && m.initial_velocity == 0.0 {
        events.push(TrajectoryEvent {
            time: 0.0,
            kind: TrajectoryEventKind::LiftOff,
            position: 0.0,
            velocity: 0.0,
        });
    }
    if let (Some(t), true) = (chatter.settle_time, chatter.outcome.is_closed()) {
        events.push(settled(t, g));
    }
    sort(&mut events);
    let impact_at = |t: f64| chatter.impacts.iter().find(|i| i.impact_time == t);
    let released_at = |t: f64| {
        chatter
            .impacts
            .iter()
            .find(|i| i.release_time == Some(t))
            .and_then(|i| i.release_velocity)
    };
    let last = chatter.intervals.len().saturating_sub(1);
    for (k, iv) in chatter.intervals.iter().enumerate() {
        if at_rest {
            break;
        }
        let end = if k == last { t_end } else { iv.end };
        match iv.state {
            ContactState::Open => {
                let (x0, v0) = if k == 0 {
                    (m.initial_position, m.initial_velocity)
                } else {
                    (g, released_at(iv.start).unwrap_or(0.0))
                };
                segments.push(Segment {
                    t0: iv.start,
                    t1: end,
                    side: Side::Open,
                    motion: Motion::Linear(LinearPiece::start(&flight, x0, v0)),
                });
            }
            ContactState::Closed if end > iv.start => {
                let v_hit = impact_at(iv.start).map_or(0.0, |i: &Impact| i.impact_velocity);
                contact_segments(&mut segments, m, surface, (iv.start, end), v_hit)?;
            }
            ContactState::Closed => {}
        }
    }
    Ok(Trajectory {
        gap: g,
        make_surface: *surface,
        back_surface: None,
        segments,
        events,
        make: chatter,
        back: None,
        strokes: Vec::new(),
        pole_face: Vec::new(),
        t_end,
    })
}

/// The segments of one contact of the step drive over `(t_hit, end)`,
/// touched at `v_hit`.
fn contact_segments(
    segments: &mut Vec<Segment>,
    m: &Mechanics,
    surface: &Surface,
    (t_hit, end): (f64, f64),
    v_hit: f64,
) -> Result<(), MechanicsError> {
    let g = m.gap;
    let f_net = m.force - m.preload;
    match *surface {
        Surface::Rigid { .. } => {
            // Held at the surface by the static overtravel force.
            let held = f_net - m.stiffness * g;
            segments.push(Segment::rest(t_hit, end, g, true, held));
        }
        Surface::KelvinVoigt { stiffness, damping } => {
            let contact = kelvin_voigt_contact(m, stiffness, damping);
            segments.push(Segment {
                t0: t_hit,
                t1: end,
                side: Side::Make,
                motion: Motion::Linear(LinearPiece::start(&contact, g, v_hit)),
            });
        }
        Surface::HuntCrossley {
            stiffness,
            exponent,
            chi,
        } => {
            let hc = HcContact::new(m, stiffness, exponent, chi);
            let mut reached = t_hit;
            for step in hc.trace(v_hit, end - t_hit)? {
                let (a, b) = step.span();
                let (t0, t1) = (t_hit + a, (t_hit + b).min(end));
                if t1 <= t0 {
                    continue;
                }
                segments.push(Segment {
                    t0,
                    t1,
                    side: Side::Make,
                    motion: Motion::Contact { step, touch: t_hit },
                });
                reached = t1;
            }
            if reached < end {
                // Past the traced steps (a rebound below the resolution,
                // or the step cap): at rest where the contact was left.
                let x = segments.last().map_or(g, |s| match &s.motion {
                    Motion::Contact { step, touch } => g + step.at(reached - touch).0,
                    _ => g,
                });
                let held = (f_net - m.stiffness * x).max(0.0);
                segments.push(Segment::rest(reached, end, x, true, held));
            }
        }
    }
    Ok(())
}

/// Touch and release events of a contact record at the gap `g`.
fn contact_events(chatter: &Chatter, g: f64) -> Vec<TrajectoryEvent> {
    let mut events = Vec::with_capacity(2 * chatter.impacts.len() + 2);
    for i in &chatter.impacts {
        events.push(TrajectoryEvent {
            time: i.impact_time,
            kind: TrajectoryEventKind::Touch,
            position: g,
            velocity: i.impact_velocity,
        });
        if let (Some(t), Some(v)) = (i.release_time, i.release_velocity) {
            events.push(TrajectoryEvent {
                time: t,
                kind: TrajectoryEventKind::Release,
                position: g,
                velocity: v,
            });
        }
    }
    events
}

fn settled(time: f64, g: f64) -> TrajectoryEvent {
    TrajectoryEvent {
        time,
        kind: TrajectoryEventKind::Settled,
        position: g,
        velocity: 0.0,
    }
}

/// In time order; at one instant, in the order things happen (a lift-off
/// before a touch, a touch before its release or its settling).
fn sort(events: &mut [TrajectoryEvent]) {
    let rank = |k: TrajectoryEventKind| match k {
        TrajectoryEventKind::Landing => 0,
        TrajectoryEventKind::Rebound | TrajectoryEventKind::LiftOff => 1,
        TrajectoryEventKind::Touch => 2,
        TrajectoryEventKind::Settled => 3,
        TrajectoryEventKind::Release => 4,
        TrajectoryEventKind::PoleFace => 5,
        TrajectoryEventKind::PoleFaceRelease => 6,
    };
    events.sort_by(|a, b| {
        a.time
            .total_cmp(&b.time)
            .then(rank(a.kind).cmp(&rank(b.kind)))
    });
}
