//! A two-stage run in progress, as both propagators drive it from event
//! to event: where it is and in which modes ([`Propagation`]), what it has
//! recorded ([`Tally`]),
//! how an event changes the modes and the records ([`transition`]), when
//! a closing's ending is decided ([`check_closing`]), and the records it
//! returns.

use super::energy::{EnergyBound, force_reach, step_energy, widest_opening};
use super::model::{RelayModel, StopMode, StopModes, Which, Y};
use super::relay::Release;
use super::run::{Horizon, TwoStageRun};
use super::span::Span;
use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome};
use crate::mechanics::cycle::{Stroke, strokes, summary};
use crate::mechanics::dop853::Dense;
use crate::mechanics::driven::DriveModel;
use crate::mechanics::error::{DriveError, MAX_DRIVEN_STEPS, MAX_EVENTS};
use crate::mechanics::parameters::{Mechanics, Settings};
use crate::mechanics::surface::Surface;

/// The records a run builds.
#[derive(Clone)]
pub(crate) struct Tally {
    contact: Vec<Impact>,
    intervals: Vec<Interval>,
    pole: Vec<Impact>,
    back: Vec<Impact>,
    back_intervals: Vec<Interval>,
    lift_offs: Vec<f64>,
    /// m, the blade's farthest reach before its first touch.
    reach: f64,
    /// Whether the contact's present closure went through an opening
    /// below resolution (merged into it), or ended a rigid contact's
    /// bounces below resolution: closed for good, it is `resolved`.
    below_resolution: bool,
    /// s, where a rigid contact's bounces below resolution accumulate.
    accumulation: Option<f64>,
    /// The contact's changes of state so far (touches and releases,
    /// merged ones included).
    changes: usize,
}

impl Tally {
    /// Whether the contact has been touched.
    pub(crate) fn contact_is_empty(&self) -> bool {
        self.contact.is_empty()
    }

    /// The contact's impacts so far.
    pub(crate) fn contact_count(&self) -> usize {
        self.contact.len()
    }

    /// What the open contact's record holds so far: the widest opening
    /// since the last release (m, `Some`), or before the first touch the
    /// blade's farthest reach (m, `None` and `reach`).
    pub(crate) fn opening_so_far(&self) -> (Option<f64>, f64) {
        let opening = self.contact.last().map(|i| i.max_gap_after.unwrap_or(0.0));
        (opening, self.reach)
    }

    /// The engaged contact's largest and least force so far (N), or
    /// infinities before the first.
    pub(crate) fn force_so_far(&self) -> (f64, f64) {
        let last = self.contact.last();
        (
            last.and_then(|i| i.peak_force).unwrap_or(f64::NEG_INFINITY),
            last.and_then(|i| i.min_force).unwrap_or(f64::INFINITY),
        )
    }

    /// Each release's time and the widest opening after it (m).
    pub(crate) fn openings(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.contact
            .iter()
            .filter_map(|i| Some((i.release_time?, i.max_gap_after?)))
    }

    /// The contact's states so far, in time order (the last one open-ended).
    pub(crate) fn intervals(&self) -> &[Interval] {
        &self.intervals
    }

    /// The rest stop's (the normally-closed contact's) states so far.
    pub(crate) fn back_intervals(&self) -> &[Interval] {
        &self.back_intervals
    }

    /// s, the first event recorded after `t`: a change of the contact's
    /// or the rest stop's state, or an impact on or a release from the
    /// pole face.
    pub(crate) fn first_event_after(&self, t: f64) -> Option<f64> {
        let changes = self
            .intervals
            .iter()
            .chain(&self.back_intervals)
            .map(|iv| iv.start);
        let pole = self
            .pole
            .iter()
            .flat_map(|i| std::iter::once(i.impact_time).chain(i.release_time));
        changes.chain(pole).filter(|&e| e > t).reduce(f64::min)
    }

    /// Whether this record, taken on from `before`, has the same impacts
    /// and the contact still closed in the last one: whatever changed were
    /// openings below resolution, merged.
    pub(crate) fn same_closure(&self, before: &Tally) -> bool {
        self.contact.len() == before.contact.len()
            && self
                .contact
                .last()
                .is_some_and(|i| i.release_time.is_none())
    }

    /// Take on the closure's resolution from `later`, the record followed on.
    pub(crate) fn take_resolution(&mut self, later: &Tally) {
        self.below_resolution |= later.below_resolution;
        if self.accumulation.is_none() {
            self.accumulation = later.accumulation;
        }
    }

    /// The contact's changes of state so far, merged ones included.
    pub(crate) fn changes(&self) -> usize {
        self.changes
    }

    /// Take in the state `y` in `modes`: the engaged contact's force
    /// (`force(y)`), the opening after a release, the reach before the
    /// first touch.
    pub(crate) fn observe(&mut self, gap: f64, modes: StopModes, y: &Y, force: impl Fn(&Y) -> f64) {
        match modes.contact {
            StopMode::Engaged | StopMode::Pressed => self.observe_force(force(y)),
            StopMode::Open => self.observe_blade(gap, y[2]),
        }
    }

    /// Take in the engaged contact's force `f` (N).
    pub(crate) fn observe_force(&mut self, f: f64) {
        if let Some(last) = self.contact.last_mut() {
            last.peak_force = Some(last.peak_force.map_or(f, |p: f64| p.max(f)));
            last.min_force = Some(last.min_force.map_or(f, |p: f64| p.min(f)));
        }
    }

    /// Take in the open contact's blade at `u_b` (m, from the gap): the
    /// opening after a release, or the reach before the first touch.
    pub(crate) fn observe_blade(&mut self, gap: f64, u_b: f64) {
        match self.contact.last_mut() {
            Some(last) => {
                let opening = (-u_b).max(0.0);
                last.max_gap_after =
                    Some(last.max_gap_after.map_or(opening, |p: f64| p.max(opening)));
            }
            None => self.reach = self.reach.max(gap + u_b),
        }
    }

    /// At a touch at `t`: when the opening since the last release was
    /// below resolution (shorter than `min_open_time` or narrower than
    /// `min_gap`), take the contact as closed through it (the release
    /// undone, no new impact) and say so.
    fn merge_short_opening(&mut self, settings: &Settings, t: f64) -> bool {
        let Some(last) = self.contact.last_mut() else {
            return false;
        };
        let Some(released) = last.release_time else {
            return false;
        };
        let opening = last.max_gap_after.unwrap_or(0.0);
        if t - released >= settings.min_open_time && opening >= settings.min_gap {
            return false;
        }
        last.release_time = None;
        last.release_velocity = None;
        last.contact_time = None;
        last.restitution = None;
        last.max_gap_after = None;
        if self
            .intervals
            .last()
            .is_some_and(|iv| iv.state == ContactState::Open)
        {
            self.intervals.pop();
        }
        self.below_resolution = true;
        true
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
pub(crate) struct Propagation {
    pub t: f64,
    pub y: Y,
    pub modes: StopModes,
    pub rec: Tally,
    pub pieces: Vec<Span>,
    pub steps: usize,
    pub bound: EnergyBound,
    /// The contact's ending, when one was decided before the horizon.
    pub ending: Option<Outcome>,
    /// s, when the contact's ending was proven.
    pub proven_at: Option<f64>,
    /// Whether to run on past the contact's ending until the pole face
    /// can no longer change (its record complete) or the horizon: the
    /// run itself; a follow-on that only proves an ending does not.
    pub follow_pole: bool,
    /// Whether the pole face can no longer change (after the contact's
    /// ending).
    pub pole_settled: bool,
    /// Whether the contact's last opening can grow no wider (false only
    /// after an `ends_open` ending, until the energy shows it).
    pub opening_settled: bool,
    /// Whether the closed contact's force can reach no further than its
    /// record (false only after a `stuck` or `resolved` ending, until the
    /// energy shows it).
    pub force_settled: bool,
    /// J, the energy at the start, under a constant force with every stop
    /// released by position (when the energy can only fall).
    pub energy0: Option<f64>,
    /// The first broken invariant: (time, what).
    pub violation: Option<(f64, String)>,
    /// A follow-on that only proves an ending gives up once what it
    /// follows has changed for good: (impacts, changes), the most the
    /// contact may have and still be proven as it was.
    pub give_up_past: Option<(usize, usize)>,
    /// Whether it gave up: the contact's ending cannot be proven from here.
    pub gave_up: bool,
}

impl Propagation {
    /// A copy to follow on from here, without the motion so far.
    pub(crate) fn fork(&self) -> Propagation {
        Propagation {
            t: self.t,
            y: self.y,
            modes: self.modes,
            rec: self.rec.clone(),
            pieces: Vec::new(),
            steps: 0,
            bound: self.bound.fresh(),
            ending: None,
            proven_at: None,
            follow_pole: false,
            pole_settled: false,
            opening_settled: true,
            force_settled: true,
            energy0: self.energy0,
            violation: None,
            give_up_past: None,
            gave_up: false,
        }
    }

    /// Whether the run is over before its horizon: the event limit, or
    /// the contact's ending decided and (when followed) the pole face
    /// settled and an open contact's last opening at its widest.
    pub(crate) fn over(&self) -> bool {
        if self.gave_up {
            return true;
        }
        match self.ending {
            None => false,
            Some(Outcome::EventLimit) => true,
            Some(_) => {
                !self.follow_pole
                    || (self.pole_settled && self.opening_settled && self.force_settled)
            }
        }
    }

    /// Take in the contact's ending, proven at the present state.
    pub(crate) fn decide(&mut self, ending: Outcome) {
        self.ending = Some(ending);
        self.proven_at = Some(self.t);
        self.opening_settled = ending != Outcome::EndsOpen;
        self.force_settled = !matches!(ending, Outcome::Stuck | Outcome::Resolved);
    }

    /// After a `stuck` or `resolved` ending: whether the closed contact's
    /// force can reach no further than its peak and least so far, by more
    /// than 1e-9 of the larger ([`force_reach`]); recorded `by_force`, the
    /// law's negative values read as zero. Where there is no such bound
    /// the force is recorded to the proof.
    pub(crate) fn settle_force<D: DriveModel>(&mut self, model: &RelayModel<'_, D>) {
        if self.force_settled {
            return;
        }
        let Some((mut lo, mut hi)) = force_reach(model, &self.y) else {
            self.force_settled = true;
            return;
        };
        if model.build.release == Release::Force {
            (lo, hi) = (lo.max(0.0), hi.max(0.0));
        }
        let (peak, min) = self.rec.force_so_far();
        let tolerance = 1e-9 * peak.abs().max(min.abs());
        self.force_settled = hi <= peak + tolerance && lo >= min - tolerance;
    }

    /// After an `ends_open` ending: whether the last opening can grow no
    /// wider than its record, by more than 1e-9 of the gap. The energy
    /// only falls, so the blade stays where the least potential over the
    /// armature's positions is below it ([`widest_opening`]); under a
    /// drive that varies there is no such bound in closed form, and the
    /// opening is not followed.
    pub(crate) fn settle_opening<D: DriveModel>(&mut self, model: &RelayModel<'_, D>) {
        if self.opening_settled {
            return;
        }
        let widest = step_energy(model, &self.y).and_then(|j| widest_opening(model, j));
        self.opening_settled = match (widest, self.rec.opening_so_far().0) {
            (Some(widest), Some(record)) => widest <= record + 1e-9 * model.m.gap,
            _ => true,
        };
    }

    /// Apply the event of `which` at `t` (state `y` there, before it).
    pub(crate) fn event<D: DriveModel>(
        &mut self,
        model: &RelayModel<'_, D>,
        settings: &Settings,
        which: Which,
        t: f64,
        mut y: Y,
    ) {
        let (before, arriving) = (self.modes, y);
        self.modes = transition(model, settings, which, t, &mut y, self.modes, &mut self.rec);
        if self.violation.is_none() {
            self.violation = invariants(model, which, before, t, (&arriving, &y), self.energy0);
        }
        if let (Which::Contact, Some(ending), Some(proven)) = (which, self.ending, self.proven_at)
            && self.violation.is_none()
        {
            self.violation = Some((
                t,
                format!(
                    "the contact changed its state after its ending ({}) was proven at {proven:e} s",
                    ending.as_str()
                ),
            ));
        }
        if let Some(last) = self.pieces.last_mut() {
            last.y1 = y;
        }
        self.t = t;
        self.y = y;
        if let Some((impacts, changes)) = self.give_up_past
            && (self.rec.contact.len() > impacts || self.rec.changes > changes)
        {
            self.gave_up = true;
        }
        if self.rec.contact.len() >= MAX_EVENTS {
            self.ending = Some(Outcome::EventLimit);
            self.proven_at = None;
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

/// The state at t = 0: on the rest stop when the drive does not lift it.
pub(super) fn start<D: DriveModel>(model: &RelayModel<'_, D>, e0: f64) -> Propagation {
    let m = model.m;
    let g = m.gap;
    let x0 = m.initial_position;
    let mut y = Y::new(x0 - g, m.initial_velocity, x0 - g, m.initial_velocity, e0);
    let mut modes = StopModes {
        contact: StopMode::Open,
        pole: StopMode::Open,
        rest: StopMode::Open,
    };
    if model.rest
        && x0 == 0.0
        && m.initial_velocity <= 0.0
        && model.armature_push(0.0, &y, modes) <= 0.0
    {
        modes.rest = StopMode::Pressed;
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
            state: if modes.rest == StopMode::Pressed {
                ContactState::Closed
            } else {
                ContactState::Open
            },
            start: 0.0,
            end: 0.0,
        }],
        lift_offs: Vec::new(),
        reach: x0,
        below_resolution: false,
        accumulation: None,
        changes: 0,
    };
    if modes.rest == StopMode::Pressed {
        rec.back.push(Impact::touch(0.0, 0.0));
    } else if model.rest && x0 == 0.0 {
        rec.lift_offs.push(0.0);
    }
    let energy0 = by_position(model).then(|| step_energy(model, &y)).flatten();
    Propagation {
        t: 0.0,
        y,
        modes,
        rec,
        pieces: Vec::with_capacity(64),
        steps: 0,
        bound: EnergyBound::new(),
        ending: None,
        proven_at: None,
        follow_pole: true,
        pole_settled: false,
        opening_settled: true,
        force_settled: true,
        energy0,
        violation: None,
        give_up_past: None,
        gave_up: false,
    }
}

/// The run's records, with the motion held where it stopped to `t_end`.
pub(super) fn finish<D: DriveModel>(
    model: &RelayModel<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    mut p: Propagation,
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

/// The closing's chatter: its ending decided by the energy bound, or read
/// at the horizon.
pub(crate) fn closing_summary<D: DriveModel>(
    model: &RelayModel<'_, D>,
    bound: &mut EnergyBound,
    rec: &mut Tally,
    ending: Option<Outcome>,
    (t, y, modes): (f64, Y, StopModes),
    t_end: f64,
) -> Chatter {
    let impacts = std::mem::take(&mut rec.contact);
    let intervals = std::mem::take(&mut rec.intervals);
    let closed = modes.contact != StopMode::Open;
    let outcome = match ending {
        Some(o) => o,
        None if impacts.is_empty() => Outcome::NeverCloses,
        None if closed => {
            if modes.contact == StopMode::Pressed || bound.cannot_release(model, t, &y, modes) {
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
    // Closed for good after bounces below resolution.
    let outcome = if outcome == Outcome::Stuck && rec.below_resolution {
        Outcome::Resolved
    } else {
        outcome
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
        accumulation_time: rec.accumulation.filter(|_| outcome == Outcome::Resolved),
        t_end,
    }
}

/// Check a closing at the present state of `p` (every fourth accepted
/// step without an event): the contact's ending, once the energy bound
/// decides it (closed and unable to release, or open after touching and
/// unable to reach it again), then whether the pole face is settled.
pub(crate) fn check_closing<D: DriveModel>(model: &RelayModel<'_, D>, p: &mut Propagation) {
    if p.rec.contact.is_empty() || !p.bound.due() {
        return;
    }
    if p.ending.is_none() {
        let (t, y, modes) = (p.t, p.y, p.modes);
        let ending = match modes.contact {
            StopMode::Engaged if p.bound.cannot_release(model, t, &y, modes) => Outcome::Stuck,
            StopMode::Open if p.bound.cannot_reach(model, t, &y, modes) => Outcome::EndsOpen,
            _ => return,
        };
        p.decide(ending);
    }
    if p.follow_pole && !p.pole_settled {
        p.pole_settled = p.bound.pole_settled(model, p.t, &p.y);
    }
    p.settle_opening(model);
    p.settle_force(model);
}

/// Whether every stop of `model` is released by position (or rigid), so
/// that its energy can only fall.
pub(crate) fn by_position<D: DriveModel>(model: &RelayModel<'_, D>) -> bool {
    let position = |release: Release, s: &Surface| {
        release == Release::Position || matches!(s, Surface::Rigid { .. })
    };
    position(model.build.release, &model.contact)
        && model
            .build
            .pole_face
            .is_none_or(|p| position(p.release, &p.surface))
}

/// What physics guarantees at an event of `which` (the modes `before`
/// it, the state `arriving` before it and `y` after it): with the contact released by position an
/// impact approaches the surface; with a constant force and every stop
/// released by position the energy has not grown. The first broken one,
/// with its numbers.
pub(super) fn invariants<D: DriveModel>(
    model: &RelayModel<'_, D>,
    which: Which,
    before: StopModes,
    t: f64,
    (arriving, y): (&Y, &Y),
    energy0: Option<f64>,
) -> Option<(f64, String)> {
    let m = model.m;
    let speed =
        (m.force.abs() + m.preload.abs() + m.stiffness * m.gap) / (m.mass * m.stiffness).sqrt();
    if which == Which::Contact
        && before.contact == StopMode::Open
        && model.build.release == Release::Position
    {
        let v = if model.build.blade.is_some() {
            arriving[3]
        } else {
            arriving[1]
        };
        if v < -1e-9 * speed {
            return Some((
                t,
                format!("an impact approaches backwards (impact velocity {v:e} m/s)"),
            ));
        }
    }
    let (Some(j0), Some(j)) = (energy0, step_energy(model, y)) else {
        return None;
    };
    let scale = (m.force.abs() + m.preload.abs())
        * (m.gap + model.build.pole_face.map_or(0.0, |p| p.overtravel))
        + 0.5 * m.stiffness * m.gap * m.gap;
    if j > j0 + 1e-7 * (scale + j0.abs()) {
        return Some((
            t,
            format!("the energy has grown from {j0:e} J to {j:e} J with nothing to supply it"),
        ));
    }
    None
}

/// Apply the event of `which` at `t` to the state and the records; the
/// new modes.
pub(crate) fn transition<D: DriveModel>(
    model: &RelayModel<'_, D>,
    settings: &Settings,
    which: Which,
    t: f64,
    y: &mut Y,
    mut modes: StopModes,
    rec: &mut Tally,
) -> StopModes {
    let g = model.g();
    let no_blade = model.build.blade.is_none();
    if which == Which::Contact {
        rec.changes += 1;
    }
    match which {
        Which::Contact => match modes.contact {
            StopMode::Open => {
                if y[2] <= 0.0 {
                    y[2] = 0.0;
                    if no_blade {
                        y[0] = 0.0;
                    }
                }
                let v = y[3];
                let rigid_contact = matches!(model.contact, Surface::Rigid { .. });
                if !rigid_contact && rec.merge_short_opening(settings, t) {
                    modes.contact = StopMode::Engaged;
                    return modes;
                }
                rec.contact.push(Impact::touch(t, v));
                rec.below_resolution = false;
                rec.accumulation = None;
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
                    _ => StopMode::Engaged,
                };
            }
            StopMode::Engaged | StopMode::Pressed => {
                if modes.contact == StopMode::Engaged && y[2] <= 0.0 {
                    y[2] = 0.0;
                    if no_blade {
                        y[0] = 0.0;
                    }
                }
                if let Some(last) = rec.contact.last_mut() {
                    release(last, t, y[3]);
                }
                Tally::switch(&mut rec.intervals, t, ContactState::Open);
                modes.contact = StopMode::Open;
            }
        },
        Which::Pole => {
            let o = model.overtravel();
            match modes.pole {
                StopMode::Open => {
                    if y[0] <= o {
                        y[0] = o;
                    }
                    rec.pole.push(Impact::touch(t, y[1]));
                    let surface = model.build.pole_face.map(|p| p.surface);
                    modes.pole = match surface {
                        Some(Surface::Rigid { restitution }) => {
                            rigid(model, settings, Which::Pole, t, y, modes, restitution, rec)
                        }
                        _ => StopMode::Engaged,
                    };
                }
                StopMode::Engaged | StopMode::Pressed => {
                    if modes.pole == StopMode::Engaged && y[0] <= o {
                        y[0] = o;
                    }
                    if let Some(last) = rec.pole.last_mut() {
                        release(last, t, y[1]);
                    }
                    modes.pole = StopMode::Open;
                }
            }
        }
        Which::Rest => match modes.rest {
            StopMode::Open => {
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
                        StopMode::Pressed
                    }
                    Some(Surface::Rigid { restitution }) => {
                        rigid(model, settings, Which::Rest, t, y, modes, restitution, rec)
                    }
                    Some(_) => StopMode::Engaged,
                };
            }
            StopMode::Engaged | StopMode::Pressed => {
                y[0] = -g;
                if no_blade {
                    y[2] = -g;
                }
                if let Some(last) = rec.back.last_mut() {
                    release(last, t, -y[1]);
                }
                Tally::switch(&mut rec.back_intervals, t, ContactState::Open);
                rec.lift_offs.push(t);
                modes.rest = StopMode::Open;
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
fn rigid<D: DriveModel>(
    model: &RelayModel<'_, D>,
    settings: &Settings,
    which: Which,
    t: f64,
    y: &mut Y,
    modes: StopModes,
    e: f64,
    rec: &mut Tally,
) -> StopMode {
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
        Which::Contact => open.contact = StopMode::Open,
        Which::Pole => open.pole = StopMode::Open,
        Which::Rest => open.rest = StopMode::Open,
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
        if which == Which::Contact && resolved && w > 0.0 {
            // The rebounds left, each e times the last, sum to a
            // geometric series of flights 2w/a, 2ew/a, …
            rec.below_resolution = true;
            rec.accumulation = (e < 1.0).then(|| t + 2.0 * w / a / (1.0 - e));
        }
        StopMode::Pressed
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
        StopMode::Open
    }
}
