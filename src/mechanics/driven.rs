//! The event-driven chatter of an armature under a drive that varies in
//! time and position, and that may carry a state of its own (the coil's
//! flux). Shared by [`crate::coil::direct`] and [`super::forced`].
//!
//! The state is `(u, v, e)`: `u = x − g` (m, the position relative to the
//! fixed contact, so that the µm penetrations keep their precision), the
//! velocity `v` (m/s) and the drive's state `e`. A run is a chain of
//! phases, each integrated by [`Dopri5`] from the exact event state that
//! started it:
//!
//! - **held** on the rest stop at x = 0 while the drive does not beat the
//!   preload; lift-off is the first time `F(t, 0) > p`;
//! - **flight** `m ẍ + r ẋ + s x + p = F`; it ends at an impact (u
//!   crosses 0 upward) or by landing back on the rest stop (taken as
//!   inelastic: held again);
//! - **contact** by the surface law, as in the step-force engine: a rigid
//!   surface reverses the velocity (`ẋ ← −e ẋ`, no duration);
//!   Kelvin–Voigt `Fc = s0 δ + r0 δ̇` and Hunt–Crossley
//!   `Fc = k δⁿ(1 + χ δ̇)⁺` are integrated until the release (δ back to 0
//!   moving out, the paper's rule) or until the contact has stuck.
//!
//! Events are never read off samples. Each accepted step is split at the
//! velocity zero it may contain (x is monotonic on each part), a level
//! crossing is bracketed by the values at the ends of a monotonic part,
//! and located by bisection on the step's interpolant down to adjacent
//! floats; the state after an event is the interpolated state *at* the
//! event time with `u` set exactly to the level. Turning points and force
//! extrema are found the same way, as sign changes of the velocity and of
//! the force rate. Steps are far shorter than any oscillation (≈ 1000 a
//! period at the tolerance used), so a part holds at most one sign change.
//!
//! **Sticking.** With a constant drive the engine's energy argument is
//! exact: `M = ½mv² + W_s(δ) + (s g + p) δ + ½ s δ² − ∫_g^x F dξ`
//! (`W_s` the surface's stored energy) never increases in contact, and a
//! release needs `M = ½mv² ≥ 0` at δ = 0; so `M < 0` means stuck for good.
//! A drive that varies has no such invariant, so the test is quasi-static:
//! the drive is frozen where it stands (`Drive::frozen_work`) and the
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
//!
//! **The horizon.** At `t_end` the drive is frozen at its last value and
//! the remaining motion is a closed-form [`LinearPiece`]: in flight it
//! tells whether the contact would still be reached (`end_of_time`) or not
//! (`never_closes` / `ends_open`, with the reach for the shortfall); in a
//! Kelvin–Voigt contact whether it would release. For a constant drive
//! this is exact, which is what makes the results equal the engine's.

use nalgebra::Vector3;

use super::DriveError;
use super::integrate::{Dopri5, Step, Tolerance};
use super::linear::LinearPiece;
use super::surface::{surface_energy, surface_force};
use super::{Mechanics, Settings, Surface};
use crate::chatter::{Chatter, ContactState, Impact, Interval, Outcome, bounces};

/// `(u = x − g, v, e)`: m, m/s, and the drive's own state.
pub(crate) type State = Vector3<f64>;

/// Relative tolerance of the integration. At 1e-11 the impact times of a
/// whole sequence agree with the closed-form engine to ~1e-9.
pub(crate) const RTOL: f64 = 1e-11;

/// What pushes the armature toward the fixed contact.
pub(crate) trait Drive {
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
}

/// Which equations a step integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Phase {
    Held,
    Flight,
    Contact,
}

/// One accepted step, cut at the event that ended its phase: valid on
/// `[step.t0, t1]`, where the state is `y1` (the exact event state for
/// the last step of a phase).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Piece {
    pub phase: Phase,
    pub step: Step<3>,
    pub t1: f64,
    pub y1: State,
}

impl Piece {
    fn whole(phase: Phase, step: Step<3>) -> Self {
        Piece {
            phase,
            step,
            t1: step.t1,
            y1: step.y1,
        }
    }

    fn cut(phase: Phase, step: Step<3>, t1: f64, y1: State) -> Self {
        Piece {
            phase,
            step,
            t1,
            y1,
        }
    }

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
            state_on(&self.step, t)
        }
    }
}

/// A finished run.
pub(crate) struct Run {
    pub chatter: Chatter,
    /// s, the first lift-off from the rest stop (`None` if it never lifts
    /// or did not start on it).
    pub lift_off: Option<f64>,
    /// Every accepted step in time order, cut at events: they tile
    /// `[0, end]`.
    pub steps: Vec<Piece>,
    /// J, kinetic energy taken by rigid impacts and inelastic landings.
    pub jump_loss: f64,
    /// (s, state) where the run stopped.
    pub end: (f64, State),
}

/// The drive, the relay and its surface: everything the right-hand side
/// needs.
struct Model<'a, D> {
    m: Mechanics,
    surface: Surface,
    settings: Settings,
    drive: &'a D,
    tol: Tolerance<3>,
}

/// How a phase ended.
#[derive(Debug, Clone, Copy)]
enum End {
    /// Flight reached the contact at (t, state at the touch).
    Impact(f64, State),
    /// Flight came down onto the rest stop.
    Landed(f64, State),
    /// The held armature lifts off.
    Lift(f64, State),
    /// A contact released.
    Released(f64, State),
    /// A contact stuck for good.
    Stuck(f64, State),
    /// `t_end` reached.
    Horizon(State),
}

/// A flight cut by the horizon.
#[derive(Debug, Clone, Copy)]
struct Flight {
    /// m, the smallest x so far.
    lowest: f64,
    /// Whether it follows a release (rather than lift-off).
    after_release: bool,
}

/// The bookkeeping of one contact's force.
#[derive(Debug, Clone, Copy)]
struct ForceRange {
    peak: f64,
    min: f64,
}

impl ForceRange {
    fn new(f: f64) -> Self {
        ForceRange { peak: f, min: f }
    }

    fn see(&mut self, f: f64) {
        self.peak = self.peak.max(f);
        self.min = self.min.min(f);
    }
}

/// Simulate one closing under `drive`, from `e0` (the drive's initial
/// state). Parameters must have been validated.
pub(crate) fn run<D: Drive>(
    m: &Mechanics,
    surface: &Surface,
    settings: &Settings,
    drive: &D,
    e0: f64,
) -> Result<Run, DriveError> {
    let tol = start(m, drive, e0)?;
    let model = Model {
        m: *m,
        surface: *surface,
        settings: *settings,
        drive,
        tol,
    };
    let x0 = m.initial_position;
    let v0 = m.initial_velocity;
    Sequence {
        model,
        rec: Record {
            steps: Vec::new(),
            impacts: Vec::new(),
            intervals: Vec::new(),
            lift_off: None,
            reach: x0,
            jump_loss: 0.0,
        },
    }
    .run(State::new(x0 - m.gap, v0, e0))
}

/// The integration tolerance for `m` under `drive`, once the drive is
/// known to be finite where the run starts (drive state `e0`).
pub(crate) fn start<D: Drive>(
    m: &Mechanics,
    drive: &D,
    e0: f64,
) -> Result<Tolerance<3>, DriveError> {
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
    Ok(Tolerance {
        rtol: RTOL,
        atol: State::new(RTOL * m.gap, RTOL * m.gap * omega, RTOL * drive.e_scale()),
    })
}

impl<D: Drive> Model<'_, D> {
    fn g(&self) -> f64 {
        self.m.gap
    }

    /// N, the force of the fixed contact on the moving one.
    fn contact_force(&self, u: f64, v: f64) -> f64 {
        surface_force(&self.surface, u, v)
    }

    /// m/s², the acceleration in flight or in contact.
    fn accel(&self, t: f64, y: &State, contact: bool) -> f64 {
        let m = &self.m;
        let x = m.gap + y[0];
        let fc = if contact {
            self.contact_force(y[0], y[1])
        } else {
            0.0
        };
        (self.drive.force(t, x, y[2]) - m.preload - m.stiffness * x - m.damping * y[1] - fc)
            / m.mass
    }

    fn rhs(&self, phase: Phase, t: f64, y: &State) -> State {
        match phase {
            Phase::Held => State::new(0.0, 0.0, self.drive.rate(t, 0.0, y[2])),
            Phase::Flight | Phase::Contact => State::new(
                y[1],
                self.accel(t, y, phase == Phase::Contact),
                self.drive.rate(t, self.g() + y[0], y[2]),
            ),
        }
    }

    /// N/s, the rate of the contact force along the motion.
    fn contact_force_rate(&self, t: f64, y: &State) -> f64 {
        let (u, v) = (y[0], y[1]);
        match self.surface {
            Surface::Rigid { .. } => 0.0,
            Surface::KelvinVoigt { stiffness, damping } => {
                stiffness * v + damping * self.accel(t, y, true)
            }
            Surface::HuntCrossley {
                stiffness,
                exponent,
                chi,
            } => {
                if u <= 0.0 || 1.0 + chi * v <= 0.0 {
                    return 0.0;
                }
                let a = self.accel(t, y, true);
                stiffness
                    * (exponent * u.powf(exponent - 1.0) * v * (1.0 + chi * v)
                        + u.powf(exponent) * chi * a)
            }
        }
    }

    /// J, the sticking margin `M` of the module docs.
    fn margin(&self, t: f64, y: &State) -> f64 {
        let m = &self.m;
        let (u, v) = (y[0], y[1]);
        let g = m.gap;
        0.5 * m.mass * v * v
            + surface_energy(&self.surface, u)
            + (m.stiffness * g + m.preload) * u
            + 0.5 * m.stiffness * u * u
            - self.drive.frozen_work(t, y[2], g, g + u)
    }

    /// N, the drive net of preload with everything frozen at (t, y).
    fn frozen_net_force(&self, t: f64, y: &State) -> f64 {
        self.drive.force(t, self.g() + y[0], y[2]) - self.m.preload
    }

    fn solver(
        &self,
        phase: Phase,
        t: f64,
        y: State,
        v_hit: f64,
    ) -> Dopri5<3, impl Fn(f64, &State) -> State + '_> {
        let h0 = 1e-2 * self.scale(phase, v_hit);
        Dopri5::new(
            move |t, y: &State| self.rhs(phase, t, y),
            t,
            y,
            h0,
            self.tol,
        )
    }

    /// Force extrema inside `step` up to `until`: the zeros of the force
    /// rate, and the force at `until`.
    fn force_extrema(&self, step: &Step<3>, until: f64, range: &mut ForceRange) {
        let force = |y: &State| self.contact_force(y[0], y[1]);
        let rate = |t: f64| self.contact_force_rate(t, &state_on(step, t));
        if let Some(tz) = sign_change(rate, step.t0, until) {
            range.see(force(&step.at(tz)));
        }
        range.see(force(&state_on(step, until)));
    }

    /// The closed-form Kelvin–Voigt contact from (t, y) with the drive
    /// frozen there; `None` for another surface.
    fn frozen_kv_piece(&self, t: f64, y: &State) -> Option<(LinearPiece, f64, f64)> {
        let Surface::KelvinVoigt { stiffness, damping } = self.surface else {
            return None;
        };
        let m = &self.m;
        let g = m.gap;
        let piece = LinearPiece::new(
            m.mass,
            m.damping + damping,
            m.stiffness + stiffness,
            self.frozen_net_force(t, y) + stiffness * g,
            g + y[0],
            y[1],
        );
        Some((piece, stiffness, damping))
    }

    /// A Kelvin–Voigt contact that stuck at (t, y): its force keeps
    /// oscillating toward the static value; with the drive frozen the rest
    /// is a linear piece whose first two force extrema (a maximum and a
    /// minimum) bound all later ones, as in the engine.
    fn kv_tail(&self, t: f64, y: &State, range: &mut ForceRange) {
        let Some((piece, s0, r0)) = self.frozen_kv_piece(t, y) else {
            return;
        };
        let at_rest = s0 * (piece.x_eq - self.g());
        range.see(at_rest);
        let rate = piece.combo(-r0 * piece.omega2, s0 - 2.0 * piece.a * r0);
        for (_, varying) in piece.zeros(rate, piece.combo(s0, r0)).take(2) {
            range.see(at_rest + varying);
        }
    }

    /// In contact at the horizon: a Kelvin–Voigt contact that would not
    /// release under the frozen drive is stuck; otherwise it is still
    /// chattering.
    fn horizon_in_contact(&self, t: f64, y: State, range: &mut ForceRange) -> End {
        if let Some((piece, ..)) = self.frozen_kv_piece(t, &y) {
            if piece.crossing(self.g(), false).is_none() {
                self.kv_tail(t, &y, range);
                return End::Stuck(t, y);
            }
        }
        End::Horizon(y)
    }

    /// s, the time scale of a phase, for the first trial step.
    fn scale(&self, phase: Phase, v_hit: f64) -> f64 {
        let m = &self.m;
        match (phase, self.surface) {
            (Phase::Held, _) => self.drive.time_scale(),
            (Phase::Flight, _) | (Phase::Contact, Surface::Rigid { .. }) => {
                (m.mass / m.stiffness).sqrt()
            }
            (Phase::Contact, Surface::KelvinVoigt { stiffness, .. }) => {
                (m.mass / (m.stiffness + stiffness)).sqrt()
            }
            (
                Phase::Contact,
                Surface::HuntCrossley {
                    stiffness,
                    exponent,
                    ..
                },
            ) => {
                // The depth at which the surface alone stops the impact,
                // crossed at the impact speed (as the engine does).
                let depth = ((exponent + 1.0) * m.mass * v_hit * v_hit / (2.0 * stiffness))
                    .powf(1.0 / (exponent + 1.0));
                depth / v_hit
            }
        }
    }
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
pub(crate) struct Parts {
    bounds: [(f64, f64); 2],
    n: usize,
    /// (time, state) of the turning point, if any.
    pub turn: Option<(f64, State)>,
}

impl Parts {
    /// The one or two time spans on which x is monotonic, in order.
    pub fn spans(&self) -> &[(f64, f64)] {
        &self.bounds[..self.n]
    }
}

/// The step split at the velocity zero it may contain: up to two parts,
/// each with x monotonic, and the turning point if any.
pub(crate) fn monotone_parts(step: &Step<3>) -> Parts {
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
        Parts {
            bounds: [(step.t0, tz), (tz, step.t1)],
            n: 2,
            turn: Some((tz, yz)),
        }
    } else {
        Parts {
            bounds: [(step.t0, step.t1), (0.0, 0.0)],
            n: 1,
            turn: None,
        }
    }
}

/// The state on `step` at `t`, exact at its ends.
pub(crate) fn state_on(step: &Step<3>, t: f64) -> State {
    if t == step.t0 {
        step.y0
    } else if t == step.t1 {
        step.y1
    } else {
        step.at(t)
    }
}

struct Sequence<'a, D> {
    model: Model<'a, D>,
    rec: Record,
}

/// What a run has produced so far.
struct Record {
    steps: Vec<Piece>,
    impacts: Vec<Impact>,
    intervals: Vec<Interval>,
    lift_off: Option<f64>,
    /// m, the largest x reached so far.
    reach: f64,
    /// J, see [`Run::jump_loss`].
    jump_loss: f64,
}

impl<D: Drive> Sequence<'_, D> {
    fn run(mut self, y0: State) -> Result<Run, DriveError> {
        let g = self.model.g();
        let t_end = self.model.settings.t_end;
        let (mut t, mut y) = (0.0, y0);
        let mut open_since = 0.0;
        // Held on the rest stop when starting there at rest (or moving
        // into it).
        let mut held = y[0] == -g && y[1] <= 0.0;
        // The release that started the current flight: (time, velocity).
        let mut released: Option<f64> = None;
        loop {
            if held {
                y[1] = 0.0;
                match self.held(t, y)? {
                    End::Lift(tl, yl) => {
                        self.rec.lift_off.get_or_insert(tl);
                        (t, y) = (tl, yl);
                        held = false;
                    }
                    End::Horizon(yh) => {
                        return Ok(self.finish_open(open_since, t_end, yh, None));
                    }
                    _ => unreachable!("a held phase ends by lift-off or at the horizon"),
                }
            }
            // Flight from (t, y).
            let mut lowest = g + y[0];
            let flight = self.flight(t, y, &mut lowest)?;
            let (t_hit, y_hit) = match flight {
                End::Impact(th, yh) => (th, yh),
                End::Landed(tl, yl) => {
                    self.rec.jump_loss += 0.5 * self.model.m.mass * yl[1] * yl[1];
                    if let Some(last) = self.rec.impacts.last_mut() {
                        last.max_gap_after.get_or_insert(g - lowest);
                    }
                    (t, y) = (tl, yl);
                    released = None;
                    held = true;
                    continue;
                }
                End::Horizon(yh) => {
                    let flight = Flight {
                        lowest,
                        after_release: released.is_some(),
                    };
                    return Ok(self.finish_open(open_since, t_end, yh, Some(flight)));
                }
                _ => unreachable!("a flight ends by impact, landing or at the horizon"),
            };
            // The opening this flight made after a release: below
            // resolution, the contact is taken as closed from the last
            // contact on (docs/model.md §4).
            if let (Some(t_rel), Some(last)) = (released, self.rec.impacts.last_mut()) {
                let gap_opened = g - lowest;
                last.max_gap_after = Some(gap_opened);
                let dt = t_hit - t_rel;
                let x_eq = self.model.frozen_net_force(t_hit, &y_hit) / self.model.m.stiffness;
                let min_gap = self
                    .model
                    .settings
                    .min_gap
                    .max(1e3 * f64::EPSILON * x_eq.abs().max(g));
                let min_open = self
                    .model
                    .settings
                    .min_open_time
                    .max(1e3 * f64::EPSILON * t_hit);
                if dt < min_open || gap_opened < min_gap {
                    let tail = match self.model.surface {
                        Surface::Rigid { restitution } if restitution < 1.0 => {
                            Some(t_rel + dt / (1.0 - restitution))
                        }
                        _ => None,
                    };
                    return Ok(self.finish_resolved(tail, t_hit, y_hit));
                }
            }
            let v_hit = y_hit[1];
            if self.rec.impacts.len() >= crate::mechanics::MAX_EVENTS {
                return Err(crate::mechanics::MechanicsError::TooManyEvents {
                    time: t_hit,
                    events: self.rec.impacts.len(),
                }
                .into());
            }
            self.rec.intervals.push(Interval {
                state: ContactState::Open,
                start: open_since,
                end: t_hit,
            });
            self.rec.impacts.push(Impact::touch(t_hit, v_hit));
            match self.contact(t_hit, y_hit)? {
                End::Released(tr, yr) => {
                    let last = self.rec.impacts.last_mut().expect("impact pushed above");
                    last.release_time = Some(tr);
                    last.release_velocity = Some(yr[1]);
                    last.restitution = Some(-yr[1] / v_hit);
                    last.contact_time = Some(tr - t_hit);
                    self.rec.intervals.push(Interval {
                        state: ContactState::Closed,
                        start: t_hit,
                        end: tr,
                    });
                    (t, y) = (tr, yr);
                    open_since = tr;
                    released = Some(tr);
                }
                End::Stuck(ts, ys) => {
                    return Ok(self.finish_closed(Outcome::Stuck, t_hit, None, (ts, ys)));
                }
                End::Horizon(yh) => {
                    return Ok(self.finish_closed(Outcome::EndOfTime, t_hit, None, (t_end, yh)));
                }
                _ => unreachable!("a contact ends by release, sticking or at the horizon"),
            }
        }
    }

    /// Held at x = 0 until the drive beats the preload.
    fn held(&mut self, t0: f64, y0: State) -> Result<End, DriveError> {
        let model = &self.model;
        let t_end = model.settings.t_end;
        let lifts = |t: f64, y: &State| model.drive.force(t, 0.0, y[2]) > model.m.preload;
        if lifts(t0, &y0) {
            return Ok(End::Lift(t0, y0));
        }
        if t0 >= t_end {
            return Ok(End::Horizon(y0));
        }
        let mut solver = model.solver(Phase::Held, t0, y0, 0.0);
        loop {
            let step = solver.step(t_end)?;
            let end = if lifts(step.t1, &step.y1) {
                let tl = first_true(|t| lifts(t, &step.at(t)), step.t0, step.t1);
                let mut yl = state_on(&step, tl);
                (yl[0], yl[1]) = (-model.g(), 0.0);
                Some(End::Lift(tl, yl))
            } else if step.t1 >= t_end {
                Some(End::Horizon(step.y1))
            } else {
                None
            };
            self.rec.steps.push(match end {
                Some(End::Lift(tl, yl)) => Piece::cut(Phase::Held, step, tl, yl),
                _ => Piece::whole(Phase::Held, step),
            });
            if let Some(end) = end {
                return Ok(end);
            }
        }
    }

    /// Free flight from (t0, y0) to the next impact or landing; `lowest`
    /// tracks the smallest x on the way.
    fn flight(&mut self, t0: f64, y0: State, lowest: &mut f64) -> Result<End, DriveError> {
        let model = &self.model;
        let rec = &mut self.rec;
        let g = model.g();
        let t_end = model.settings.t_end;
        let mut solver = model.solver(Phase::Flight, t0, y0, 0.0);
        loop {
            let step = solver.step(t_end)?;
            let parts = monotone_parts(&step);
            if let Some((_, yz)) = parts.turn {
                let xz = g + yz[0];
                *lowest = lowest.min(xz);
                rec.reach = rec.reach.max(xz);
            }
            let mut event = None;
            for &(a, b) in parts.spans() {
                let (ua, ub) = (state_on(&step, a)[0], state_on(&step, b)[0]);
                if ua < 0.0 && ub >= 0.0 {
                    let th = first_true(|t| step.at(t)[0] >= 0.0, a, b);
                    let mut yh = state_on(&step, th);
                    yh[0] = 0.0;
                    rec.reach = rec.reach.max(g);
                    event = Some(End::Impact(th, yh));
                    break;
                }
                if ua > -g && ub <= -g {
                    let tl = first_true(|t| step.at(t)[0] <= -g, a, b);
                    let mut yl = state_on(&step, tl);
                    yl[0] = -g;
                    *lowest = 0.0;
                    event = Some(End::Landed(tl, yl));
                    break;
                }
            }
            if event.is_none() {
                let x1 = g + step.y1[0];
                *lowest = lowest.min(x1);
                rec.reach = rec.reach.max(x1);
                if step.t1 >= t_end {
                    event = Some(End::Horizon(step.y1));
                }
            }
            rec.steps.push(match event {
                Some(End::Impact(te, ye) | End::Landed(te, ye)) => {
                    Piece::cut(Phase::Flight, step, te, ye)
                }
                _ => Piece::whole(Phase::Flight, step),
            });
            if let Some(end) = event {
                return Ok(end);
            }
        }
    }

    /// One contact from the touch at (t_hit, y_hit); fills the force
    /// fields of the last impact.
    fn contact(&mut self, t_hit: f64, y_hit: State) -> Result<End, DriveError> {
        let model = &self.model;
        let rec = &mut self.rec;
        let last = rec.impacts.last_mut().expect("the impact was pushed");
        let m = model.m;
        let g = m.gap;
        let v_hit = y_hit[1];
        if let Surface::Rigid { restitution } = model.surface {
            let v_out = -restitution * v_hit;
            let held_by = model.frozen_net_force(t_hit, &y_hit) - m.stiffness * g;
            let mut y = y_hit;
            y[1] = v_out;
            rec.jump_loss += 0.5 * m.mass * (v_hit * v_hit - v_out * v_out);
            if v_out == 0.0 && held_by >= 0.0 {
                // Held against the surface by the static overtravel force.
                last.peak_force = Some(held_by);
                last.min_force = Some(held_by);
                return Ok(End::Stuck(t_hit, y));
            }
            return Ok(End::Released(t_hit, y));
        }
        let t_end = model.settings.t_end;
        let pole = model.drive.pole();
        // Sticking is tested with a margin so that rounding can never call
        // a contact stuck that will still release.
        let stick_margin = 1e-9 * 0.5 * m.mass * v_hit * v_hit;
        let mut range = ForceRange::new(model.contact_force(0.0, v_hit));
        let mut solver = model.solver(Phase::Contact, t_hit, y_hit, v_hit);
        let end = loop {
            let step = solver.step(t_end)?;
            let parts = monotone_parts(&step);
            let mut event = None;
            for &(a, b) in parts.spans() {
                let (ua, ub) = (state_on(&step, a)[0], state_on(&step, b)[0]);
                if ua > 0.0 && ub <= 0.0 {
                    let tr = first_true(|t| step.at(t)[0] <= 0.0, a, b);
                    let mut yr = state_on(&step, tr);
                    yr[0] = 0.0;
                    event = Some(End::Released(tr, yr));
                    break;
                }
            }
            if g + step.y1[0] >= pole {
                let tp = first_true(|t| g + step.at(t)[0] >= pole, step.t0, step.t1);
                return Err(DriveError::ArmatureAtPole {
                    time: tp,
                    position: g + state_on(&step, tp)[0],
                    pole,
                });
            }
            // The force over the part of the step still in contact.
            let until = match event {
                Some(End::Released(tr, _)) => tr,
                _ => step.t1,
            };
            model.force_extrema(&step, until, &mut range);
            if event.is_none() {
                let (t1, y1) = (step.t1, step.y1);
                let moving_out = y1[1] < 0.0;
                if moving_out && model.margin(t1, &y1) < -stick_margin {
                    model.kv_tail(t1, &y1, &mut range);
                    event = Some(End::Stuck(t1, y1));
                } else if t1 >= t_end {
                    event = Some(model.horizon_in_contact(t1, y1, &mut range));
                }
            }
            rec.steps.push(match event {
                Some(End::Released(te, ye)) => Piece::cut(Phase::Contact, step, te, ye),
                _ => Piece::whole(Phase::Contact, step),
            });
            if let Some(end) = event {
                break end;
            }
        };
        last.peak_force = Some(range.peak);
        last.min_force = Some(match model.surface {
            // The clamped force is 0 at the touch: nothing smaller is seen.
            Surface::HuntCrossley { .. } => 0.0,
            _ => range.min,
        });
        Ok(end)
    }

    /// The run ends with the contact open at `t_end`, in `flight` (or
    /// held on the rest stop if `None`).
    fn finish_open(mut self, open_since: f64, t_end: f64, y: State, flight: Option<Flight>) -> Run {
        let g = self.model.g();
        // Where the motion would go with the drive frozen: is the contact
        // still to be reached, and how far does the armature get?
        let (reaches, reach) = match flight {
            None => (false, self.rec.reach),
            Some(flight) => {
                let m = &self.model.m;
                let piece = LinearPiece::new(
                    m.mass,
                    m.damping,
                    m.stiffness,
                    self.model.frozen_net_force(t_end, &y),
                    g + y[0],
                    y[1],
                );
                let x = g + y[0];
                let tail = piece
                    .first_extremum(true)
                    .map_or(piece.x_eq.max(x), |(_, xm)| xm.max(x));
                let crossing = piece.crossing(g, true);
                // A flight after a release that will hit again: its largest
                // opening may still lie ahead.
                if let (Some(hit), true) = (crossing, flight.after_release) {
                    let lowest = match hit.turned_at {
                        Some((_, x_turn)) => flight.lowest.min(x_turn),
                        None => flight.lowest,
                    };
                    if let Some(last) = self.rec.impacts.last_mut() {
                        last.max_gap_after = Some(g - lowest);
                    }
                }
                (crossing.is_some(), self.rec.reach.max(tail))
            }
        };
        let (outcome, shortfall) = match (reaches, self.rec.impacts.is_empty()) {
            (true, _) => (Outcome::EndOfTime, None),
            (false, true) => (Outcome::NeverCloses, Some(g - reach)),
            (false, false) => (Outcome::EndsOpen, None),
        };
        self.rec.intervals.push(Interval {
            state: ContactState::Open,
            start: open_since.min(t_end),
            end: t_end,
        });
        let bounce_count = bounces(&self.rec.intervals);
        Run {
            chatter: Chatter {
                outcome,
                first_impact: self.rec.impacts.first().map(|i| i.impact_time),
                settle_time: None,
                bounce_count,
                impacts: self.rec.impacts,
                intervals: self.rec.intervals,
                shortfall,
                accumulation_time: None,
                t_end,
            },
            lift_off: self.rec.lift_off,
            steps: self.rec.steps,
            jump_loss: self.rec.jump_loss,
            end: (t_end, y),
        }
    }

    /// The run ends with the contact closed from `since` on.
    fn finish_closed(
        mut self,
        outcome: Outcome,
        since: f64,
        accumulation: Option<f64>,
        end: (f64, State),
    ) -> Run {
        let t_end = self.model.settings.t_end;
        self.rec.intervals.push(Interval {
            state: ContactState::Closed,
            start: since,
            end: t_end.max(since),
        });
        let bounce_count = bounces(&self.rec.intervals);
        Run {
            chatter: Chatter {
                outcome,
                first_impact: self.rec.impacts.first().map(|i| i.impact_time),
                settle_time: (outcome != Outcome::EndOfTime).then_some(since),
                bounce_count,
                impacts: self.rec.impacts,
                intervals: self.rec.intervals,
                shortfall: None,
                accumulation_time: accumulation,
                t_end,
            },
            lift_off: self.rec.lift_off,
            steps: self.rec.steps,
            jump_loss: self.rec.jump_loss,
            end,
        }
    }

    /// The opening after the last contact is below resolution: drop it
    /// and take the contact as closed from that contact's impact on. The
    /// run ends at the touch that was not kept.
    fn finish_resolved(mut self, accumulation: Option<f64>, t: f64, y: State) -> Run {
        let closed = self
            .rec
            .intervals
            .pop()
            .expect("a release pushed its closed interval");
        debug_assert_eq!(closed.state, ContactState::Closed);
        self.finish_closed(Outcome::Resolved, closed.start, accumulation, (t, y))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::surface::surface_loss;

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
