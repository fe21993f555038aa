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
use super::energy::widest_opening;
use super::linear::{LinearSystem, propagate};
use super::model::{RelayModel, StopMode, StopModes, Which, Y, law};
use super::propagation::{Propagation, Tally, check_closing, finish, start};
use super::relay::{Release, TwoStage, validate_all};
pub use super::run::Horizon;
use super::run::TwoStageRun;
use super::span::Span;
use crate::chatter::Outcome;
use crate::mechanics::dop853::{Dense, Dop853};
use crate::mechanics::driven::{DriveModel, first_true};
use crate::mechanics::error::{DriveError, MechanicsError};
use crate::mechanics::forced::Forced;
use crate::mechanics::locate::{self, StepForm};
use crate::mechanics::parameters::{Mechanics, PROOF_SPAN, Settings, Stops};
use crate::mechanics::step_control::StepTolerance;
use crate::mechanics::surface::Surface;
use crate::mechanics::trajectory::{self, Trajectory, simulate_drive};

/// Relative tolerance of the integration: impact and release times of a
/// whole sequence agree with the exact one-mass engine to about 1e-9, and
/// the impacts of a long Hertz sequence (at 9–11 ms) with a brute-force
/// reference to well within 1e-6 (1e-11 left 2e-6 there).
pub(crate) const RTOL: f64 = 1e-12;

/// Sample points per step at which the event functions are checked.
const SAMPLES: usize = 4;

impl<D: DriveModel> RelayModel<'_, D> {
    /// The first event in `(t0, t1]` on `dense`: (time, which). Each stop
    /// whose event function is linear in the state (every one but a body
    /// pressed on a rigid stop by the drive) is searched by the one event
    /// locator on the dense output's polynomial, so no zero of it is
    /// stepped over; the others are sampled at [`SAMPLES`] points. The
    /// bracket found is bisected on the interpolant to adjacent floats.
    fn first_event(
        &self,
        dense: &Dense<5>,
        t1: f64,
        modes: StopModes,
        resolution: f64,
    ) -> Option<(f64, Which)> {
        const ALL: [Which; 3] = [Which::Contact, Which::Pole, Which::Rest];
        let t0 = dense.t0;
        let h = t1 - t0;
        let mut mono: Option<[Y; 8]> = None;
        let mut best: Option<(f64, Which)> = None;
        for which in ALL {
            let bracket = match self.linear_guard(which, modes) {
                Some(None) => None,
                Some(Some(guard)) => {
                    let mono = mono.get_or_insert_with(|| dense.monomial());
                    let forms: [StepForm; 2] = std::array::from_fn(|j| {
                        let f = &guard.forms[j];
                        let a: [f64; 8] = std::array::from_fn(|k| {
                            let c = &mono[k];
                            let v: f64 = (0..5).map(|i| f.c[i] * c[i]).sum();
                            if k == 0 { v + f.d } else { v }
                        });
                        StepForm::new(&a)
                    });
                    locate::first_zero(&forms[..guard.count], guard.combine, resolution / h)
                        .map(|(lo, hi)| (t0 + lo * h, t0 + hi * h))
                }
                None => self.sampled(which, dense, t1, modes),
            };
            let Some((lo, hi)) = bracket else { continue };
            let negative = |t: f64| self.event(which, t, &dense.at(t), modes) < 0.0;
            let t = if negative(hi) && !negative(lo) {
                first_true(negative, lo, hi)
            } else {
                hi
            };
            if best.is_none_or(|(tb, _)| t < tb) {
                best = Some((t, which));
            }
        }
        best
    }

    /// The first of [`SAMPLES`] points of the step at which `which`'s
    /// event function is negative, bracketed by the point before it.
    fn sampled(
        &self,
        which: Which,
        dense: &Dense<5>,
        t1: f64,
        modes: StopModes,
    ) -> Option<(f64, f64)> {
        let t0 = dense.t0;
        let mut lo = t0;
        for k in 1..=SAMPLES {
            let hi = if k == SAMPLES {
                t1
            } else {
                t0 + (t1 - t0) * k as f64 / SAMPLES as f64
            };
            if self.event(which, hi, &dense.at(hi), modes) < 0.0 {
                return Some((lo, hi));
            }
            lo = hi;
        }
        None
    }
}

/// Simulate the relay of `model` from the drive's state `e0` to
/// `horizon`. Parameters must have been validated.
pub(crate) fn run_relay<D: DriveModel>(
    model: &RelayModel<'_, D>,
    settings: &Settings,
    e0: f64,
    horizon: Horizon,
) -> Result<TwoStageRun, DriveError> {
    let mut progress = start(model, e0);
    advance(model, settings, horizon, &mut progress)?;
    if let Some((time, what)) = broken(model, &progress) {
        return Err(DriveError::Impossible {
            time,
            what,
            relay: describe(model),
        });
    }
    if horizon == Horizon::Closing {
        prove_ending(model, settings, &mut progress);
    }
    Ok(finish(model, settings, horizon, progress))
}

/// The first invariant `p` broke: one its events saw, or an opening wider
/// than the energy at the start allows (a constant force, every stop
/// released by position).
fn broken<D: DriveModel>(model: &RelayModel<'_, D>, p: &Propagation) -> Option<(f64, String)> {
    if p.violation.is_some() {
        return p.violation.clone();
    }
    let widest = widest_opening(model, p.energy0?)?;
    p.rec.openings().find_map(|(t, opening)| {
        (opening > widest * (1.0 + 1e-6) + 1e-12).then(|| {
            (
                t,
                format!(
                    "an opening of {opening:e} m after the release at {t:e} s, where the energy \
                     allows at most {widest:e} m"
                ),
            )
        })
    })
}

/// The relay's keys and values, for an error that must name them.
pub(super) fn describe<D: DriveModel>(model: &RelayModel<'_, D>) -> String {
    let m = model.m;
    let mut out = format!(
        "mechanics.mass = {:e} kg, mechanics.stiffness = {:e} N/m, mechanics.damping = {:e} N·s/m, \
         mechanics.force = {:e} N, mechanics.preload = {:e} N, mechanics.gap = {:e} m, surface = {:?}",
        m.mass, m.stiffness, m.damping, m.force, m.preload, m.gap, model.contact
    );
    if let Some(b) = &model.build.blade {
        out += &format!(
            ", blade.mass = {:e} kg, blade.stiffness = {:e} N/m, blade.damping = {:e} N·s/m",
            b.mass, b.stiffness, b.damping
        );
    }
    if let Some(p) = &model.build.pole_face {
        out += &format!(
            ", pole_face.overtravel = {:e} m, pole_face = {:?}",
            p.overtravel, p.surface
        );
    }
    out += &format!(", surface.release = {:?}", model.build.release);
    out
}

/// Propagate `p` to the horizon: exactly when every mode is linear, else
/// by DOP853.
pub(super) fn advance<D: DriveModel>(
    model: &RelayModel<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    p: &mut Propagation,
) -> Result<(), DriveError> {
    match LinearSystem::of(model) {
        Some(system) => propagate(&system, model, settings, horizon, p),
        None => integrate(model, settings, horizon, p),
    }
}

/// A closing whose contact's ending is not decided at `t_end` is followed
/// on, with the drive as it is, until the energy bound proves its ending
/// or the contact changes, up to [`PROOF_SPAN`]` × t_end`: closed there,
/// `stuck` (with its settle time, the last impact before `t_end`), open,
/// `ends_open`, each only when proven before the contact changes again.
/// What happens after `t_end` is not recorded.
fn prove_ending<D: DriveModel>(
    model: &RelayModel<'_, D>,
    settings: &Settings,
    p: &mut Propagation,
) {
    if p.ending.is_some()
        || p.modes.contact == StopMode::Pressed
        || p.rec.contact_is_empty()
        || p.t < settings.t_end
    {
        return;
    }
    // Proven where it stands (the run's summary will say so): nothing to
    // follow.
    let (t, y, modes) = (p.t, p.y, p.modes);
    let (proven, ending) = match modes.contact {
        StopMode::Open => (p.bound.cannot_reach(model, t, &y, modes), Outcome::EndsOpen),
        _ => (p.bound.cannot_release(model, t, &y, modes), Outcome::Stuck),
    };
    if proven {
        return;
    }
    let mut later = p.fork();
    // Past a new impact (or, open, any change) the ending followed can no
    // longer be proven: the follow-on stops there instead of running on
    // to its span for nothing.
    let impacts = p.rec.contact_count();
    later.give_up_past = Some(match ending {
        Outcome::EndsOpen => (impacts, p.rec.changes()),
        _ => (impacts, usize::MAX),
    });
    let span = Settings {
        t_end: settings.t_end * PROOF_SPAN,
        ..*settings
    };
    let followed = advance(model, &span, Horizon::Closing, &mut later);
    if followed.is_err() || later.ending != Some(ending) {
        return;
    }
    // Nothing happened to the contact on the way, but for openings below
    // resolution merged into a closed one (then it is resolved).
    if later.rec.changes() == p.rec.changes() {
        p.ending = Some(ending);
    } else if ending == Outcome::Stuck && later.rec.same_closure(&p.rec) {
        p.ending = Some(ending);
        p.rec.take_resolution(&later.rec);
    }
}

/// DOP853 from event to event, to the horizon.
fn integrate<D: DriveModel>(
    model: &RelayModel<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    p: &mut Propagation,
) -> Result<(), DriveError> {
    let tol = tolerance(model);
    let mut h = 0.05 / fastest(model);
    while p.t < settings.t_end && !p.over() {
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
            match model.first_event(&dense, step.t1, modes, settings.min_open_time) {
                None => {
                    sample(model, &dense, step.t1, modes, &mut p.rec);
                    p.pieces.push(Span::dense(dense, step.t1, step.y1, modes));
                    p.t = step.t1;
                    p.y = step.y1;
                    if horizon == Horizon::Closing {
                        check_closing(model, p);
                        if p.over() {
                            return Ok(());
                        }
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

/// The error when the armature has pressed through to the magnet's pole
/// (the drive's model ends there) at `time`.
fn pole_limit<D: DriveModel>(model: &RelayModel<'_, D>, y: &Y, time: f64) -> Option<DriveError> {
    let pole = model.drive.pole();
    let position = model.g() + y[0];
    (position >= pole).then_some(DriveError::ArmatureAtPole {
        time,
        position,
        pole,
    })
}

/// Peak and minimum contact forces and the largest opening after each
/// release over a step up to `t1`, on its dense output: at the step's
/// ends and at [`SAMPLES`] points, and where the watched quantity's rate
/// on the interpolant vanishes ([`interpolant_extremes`]).
fn sample<D: DriveModel>(
    model: &RelayModel<'_, D>,
    dense: &Dense<5>,
    t1: f64,
    modes: StopModes,
    rec: &mut Tally,
) {
    let force = |y: &Y| match modes.contact {
        // Pressed on a rigid contact: the blade's spring is the force.
        StopMode::Pressed => model.blade_force(y),
        // F_c = max(0, ·) released by force: zero, not a rounding
        // below it, where the contact lets go.
        _ if model.build.release == Release::Force => law(&model.contact, y[2], y[3]).max(0.0),
        _ => law(&model.contact, y[2], y[3]),
    };
    let t0 = dense.t0;
    for k in 0..=SAMPLES {
        let t = t0 + (t1 - t0) * k as f64 / SAMPLES as f64;
        rec.observe(model.g(), modes, &dense.at(t), force);
    }
    interpolant_extremes(model, dense, t1, modes, |t| {
        rec.observe(model.g(), modes, &dense.at(t), force);
    });
}

/// Every time in the step up to `t1` where the quantity the record
/// watches (the open blade's position, or the engaged contact's force)
/// turns on the step's interpolant, handed to `take`. The interpolant is
/// a polynomial of degree 7 in `θ = (t − t0)/h`, so the blade's position
/// and a Kelvin–Voigt or blade force are polynomials too, and a
/// Hunt–Crossley force `k δⁿ (1 + χ δ̇)` turns where
/// `n δ' (1 + χ δ̇) + χ δ δ̇'` vanishes (degree 13): their zeros are
/// isolated on the Bernstein form ([`locate::sign_changes`]) and bisected.
fn interpolant_extremes<D: DriveModel>(
    model: &RelayModel<'_, D>,
    dense: &Dense<5>,
    t1: f64,
    modes: StopModes,
    mut take: impl FnMut(f64),
) {
    let h = dense.t1 - dense.t0;
    if !(h > 0.0 && t1 > dense.t0) {
        return;
    }
    let end = ((t1 - dense.t0) / h).min(1.0);
    let m = dense.monomial();
    let poly = |i: usize| -> [f64; 8] { std::array::from_fn(|k| m[k][i]) };
    let slope = |p: &[f64; 8]| -> [f64; 7] { std::array::from_fn(|k| (k + 1) as f64 * p[k + 1]) };
    // The rate's coefficients in θ (up to 14).
    let mut rate = [0.0; 14];
    let linear = |rate: &mut [f64; 14], c: [f64; 4]| {
        let p: [[f64; 8]; 4] = std::array::from_fn(poly);
        for k in 0..7 {
            rate[k] = (0..4).map(|i| c[i] * (k + 1) as f64 * p[i][k + 1]).sum();
        }
        7
    };
    let n = match (modes.contact, &model.contact) {
        (StopMode::Open, _) => linear(&mut rate, [0.0, 0.0, 1.0, 0.0]),
        (StopMode::Pressed, _) => match &model.build.blade {
            Some(b) => linear(
                &mut rate,
                [b.stiffness, b.damping, -b.stiffness, -b.damping],
            ),
            None => return,
        },
        (_, Surface::KelvinVoigt { stiffness, damping }) => {
            linear(&mut rate, [0.0, 0.0, *stiffness, *damping])
        }
        (_, Surface::HuntCrossley { exponent, chi, .. }) => {
            let (p, v) = (poly(2), poly(3));
            let (dp, dv) = (slope(&p), slope(&v));
            // n P' (1 + χ V) + χ P V'
            for i in 0..7 {
                rate[i] += exponent * dp[i];
                for j in 0..8 {
                    rate[i + j] += exponent * chi * dp[i] * v[j] + chi * p[j] * dv[i];
                }
            }
            14
        }
        (_, Surface::Rigid { .. }) => return,
    };
    let rate = &rate[..n];
    let value = |theta: f64| rate.iter().rev().fold(0.0, |acc, &c| acc * theta + c);
    let form = StepForm::scaled(rate, end);
    let Some((brackets, count)) = locate::sign_changes::<8>(&form, 1e-6) else {
        // More turns than a step of an accurate integrator has: take the
        // interpolant at every 1/64 of the step.
        for k in 1..64 {
            take(dense.t0 + h * end * k as f64 / 64.0);
        }
        return;
    };
    for &(lo, hi) in &brackets[..count] {
        let (mut a, mut b) = (lo * end, hi * end);
        let (va, vb) = (value(a), value(b));
        if va != 0.0 && vb != 0.0 && (va > 0.0) != (vb > 0.0) {
            for _ in 0..60 {
                let mid = 0.5 * (a + b);
                if (value(mid) > 0.0) == (va > 0.0) {
                    a = mid;
                } else {
                    b = mid;
                }
            }
        }
        take(dense.t0 + h * 0.5 * (a + b));
    }
}

/// Tolerances for the state's components.
fn tolerance<D: DriveModel>(model: &RelayModel<'_, D>) -> StepTolerance<5> {
    let g = model.g();
    let omega = (model.m.stiffness / model.m.mass).sqrt();
    StepTolerance {
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
fn fastest<D: DriveModel>(model: &RelayModel<'_, D>) -> f64 {
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

/// A constant force (the step drive), as a [`DriveModel`].
pub(crate) struct Constant {
    force: f64,
    time_scale: f64,
}

impl DriveModel for Constant {
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
    stops: &Stops,
    settings: &Settings,
    drive: trajectory::Drive<'_>,
    horizon: Horizon,
) -> Result<TwoStageRun, DriveError> {
    validate_all(m, build, &stops.make, settings)?;
    match drive {
        trajectory::Drive::Step => {
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
            let model = RelayModel {
                m,
                build,
                contact: stops.make,
                back: None,
                rest: false,
                drive: &constant,
            };
            run_relay(&model, settings, 0.0, horizon)
        }
        trajectory::Drive::Force(force) => {
            if m.initial_position < 0.0 {
                return Err(DriveError::InvalidParameter {
                    name: "mechanics.initial_position",
                    value: m.initial_position,
                    requirement: "a position in m at or above the rest stop at 0 (and below the gap)",
                });
            }
            let forced = Forced::new(m, force);
            let model = RelayModel {
                m,
                build,
                contact: stops.make,
                back: stops.back,
                rest: true,
                drive: &forced,
            };
            run_relay(&model, settings, 0.0, horizon)
        }
    }
}

/// The closing of `m` under its step force onto `surface`, built as
/// `build`: the exact one-mass engine when `build` is the one-mass model
/// (the same numbers to the last digit), else the two-stage engine.
pub fn step_closing(
    m: &Mechanics,
    build: &TwoStage,
    surface: &Surface,
    settings: &Settings,
) -> Result<Trajectory, DriveError> {
    if build.is_one_mass() {
        return Ok(Trajectory::of_step(m, surface, settings)?);
    }
    let stops = Stops {
        make: *surface,
        back: None,
    };
    let run = simulate_two_stage(
        m,
        build,
        &stops,
        settings,
        trajectory::Drive::Step,
        Horizon::Closing,
    )?;
    Ok(Trajectory::of_two_stage(m, &stops, settings, run))
}

/// The whole run of `m` under a force `F(t, x)` (N toward closing at the
/// armature's position `x`), built as `build`: the one-mass cycle engine
/// when `build` is the one-mass model, else the two-stage engine to
/// `settings.t_end`.
pub fn driven_run(
    m: &Mechanics,
    build: &TwoStage,
    stops: &Stops,
    settings: &Settings,
    force: &dyn Fn(f64, f64) -> f64,
) -> Result<Trajectory, DriveError> {
    if build.is_one_mass() {
        return simulate_drive(m, stops, settings, trajectory::Drive::Force(force));
    }
    let run = simulate_two_stage(
        m,
        build,
        stops,
        settings,
        trajectory::Drive::Force(force),
        Horizon::Cycle,
    )?;
    Ok(Trajectory::of_two_stage(m, stops, settings, run))
}

#[cfg(test)]
mod invariant_tests {
    use super::*;
    use crate::mechanics::two_stage::energy::{force_reach, step_energy};
    use crate::mechanics::two_stage::propagation::invariants;
    use crate::mechanics::two_stage::{Blade, PoleFace};

    fn relay() -> (Mechanics, TwoStage) {
        let m = Mechanics {
            mass: 1e-4,
            stiffness: 5000.0,
            damping: 0.07,
            force: 1.0,
            gap: 1.4e-4,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        };
        let build = TwoStage {
            blade: Some(Blade {
                mass: 2e-5,
                stiffness: 3200.0,
                damping: 0.005,
            }),
            pole_face: Some(PoleFace {
                overtravel: 1e-4,
                release: Release::Position,
                surface: Surface::KelvinVoigt {
                    stiffness: 2e6,
                    damping: 2.0,
                },
            }),
            release: Release::Position,
        };
        (m, build)
    }

    fn with_model(check: impl Fn(&RelayModel<'_, Constant>)) {
        let (m, build) = relay();
        with_build(&m, &build, check);
    }

    /// The relay `m` built as `build`, on the test's contact and force.
    fn with_build(m: &Mechanics, build: &TwoStage, check: impl Fn(&RelayModel<'_, Constant>)) {
        let constant = Constant {
            force: m.force,
            time_scale: (m.mass / m.stiffness).sqrt(),
        };
        let model = RelayModel {
            m,
            build,
            contact: Surface::KelvinVoigt {
                stiffness: 5e5,
                damping: 0.3,
            },
            back: None,
            rest: false,
            drive: &constant,
        };
        check(&model);
    }

    const OPEN: StopModes = StopModes {
        contact: StopMode::Open,
        pole: StopMode::Open,
        rest: StopMode::Open,
    };

    #[test]
    fn an_impact_that_approaches_backwards_is_an_error() {
        with_model(|model| {
            let arriving = Y::new(-1e-5, 0.2, 0.0, -0.15, 0.0);
            let broken = invariants(
                model,
                Which::Contact,
                OPEN,
                1e-3,
                (&arriving, &arriving),
                None,
            );
            let (t, what) = broken.expect("a backward impact is caught");
            assert_eq!(t, 1e-3);
            assert!(what.contains("backwards"), "{what}");
            // Approaching, it holds.
            let arriving = Y::new(-1e-5, 0.2, 0.0, 0.15, 0.0);
            assert!(
                invariants(
                    model,
                    Which::Contact,
                    OPEN,
                    1e-3,
                    (&arriving, &arriving),
                    None
                )
                .is_none()
            );
        });
    }

    #[test]
    fn energy_from_nowhere_is_an_error() {
        with_model(|model| {
            let rest = Y::new(-1.4e-4, 0.0, -1.4e-4, 0.0, 0.0);
            let j0 = step_energy(model, &rest).unwrap();
            // The blade at the contact, moving at 5 m/s: more than the
            // force's work over the travel can give.
            let fast = Y::new(0.0, 0.0, 0.0, 5.0, 0.0);
            let broken = invariants(model, Which::Contact, OPEN, 2e-3, (&fast, &fast), Some(j0));
            assert!(broken.expect("caught").1.contains("energy has grown"));
            let slow = Y::new(0.0, 0.0, 0.0, 0.1, 0.0);
            assert!(
                invariants(model, Which::Contact, OPEN, 2e-3, (&slow, &slow), Some(j0)).is_none()
            );
        });
    }

    #[test]
    fn the_widest_opening_is_where_the_least_potential_meets_the_energy() {
        with_model(|model| {
            let (m, build) = relay();
            let sb = build.blade.unwrap().stiffness;
            let j = 1e-5;
            let opening = widest_opening(model, j).unwrap();
            let xb = m.gap - opening;
            // The least potential over the armature, found by brute force.
            let least = (0..200_001)
                .map(|i| -2e-3 + 4e-3 * i as f64 / 200_000.0)
                .map(|xa| {
                    0.5 * m.stiffness * xa * xa - m.force * xa + 0.5 * sb * (xa - xb) * (xa - xb)
                })
                .fold(f64::INFINITY, f64::min);
            assert!((least - j).abs() < 1e-9, "{least} against {j}");
            assert!(opening > m.gap);
        });
    }

    /// The force a closed contact can still reach from a state, against
    /// a brute-force search over every state of no more energy: the
    /// bound holds it, and is no wider than its two parts' own maxima.
    #[test]
    fn the_force_reach_holds_every_state_of_no_more_energy() {
        let check = |model: &RelayModel<'_, Constant>| {
            let (m, build) = (model.m, model.build);
            let blade = build.blade.unwrap();
            let Surface::KelvinVoigt {
                stiffness: s0,
                damping: r0,
            } = model.contact
            else {
                unreachable!()
            };
            // Near the closed contact's rest (pressed in by 0.23 µm, the
            // armature 37 µm past the gap) and moving: stuck.
            let y = Y::new(3.8e-5, 0.005, 3e-7, 0.001, 0.0);
            let j = step_energy(model, &y).unwrap();
            let (lo, hi) = force_reach(model, &y).expect("a bound");
            let potential = |xa: f64, delta: f64| {
                let xb = m.gap + delta;
                let mut v = 0.5 * m.stiffness * xa * xa - m.force * xa
                    + 0.5 * blade.stiffness * (xa - xb) * (xa - xb)
                    + 0.5 * s0 * delta.max(0.0).powi(2);
                if let Some(p) = &build.pole_face {
                    let d = xa - m.gap - p.overtravel;
                    if let Surface::KelvinVoigt { stiffness, .. } = p.surface {
                        v += 0.5 * stiffness * d.max(0.0).powi(2);
                    }
                }
                v
            };
            let (mut deepest, mut shallowest, mut slack) = (f64::MIN, f64::MAX, 0.0f64);
            let n = 800;
            for i in 0..=n {
                let delta = -1e-6 + 3e-6 * i as f64 / n as f64;
                for k in 0..=n {
                    let xa = 1e-4 + 1.5e-4 * k as f64 / n as f64;
                    let room = j - potential(xa, delta);
                    if room >= 0.0 {
                        deepest = deepest.max(delta);
                        shallowest = shallowest.min(delta);
                        slack = slack.max(room);
                    }
                }
            }
            let speed = (2.0 * slack / blade.mass).sqrt();
            let (brute_lo, brute_hi) = (s0 * shallowest - r0 * speed, s0 * deepest + r0 * speed);
            // Pressed in over the whole set, inside the grid, which then
            // stands for the whole plane.
            assert!(
                shallowest > 0.0 && deepest < 1.9e-6,
                "{shallowest} {deepest}"
            );
            // The grid's spacing (3.75 nm, and the energy between its
            // points) is what the brute force may miss.
            let grid = s0 * 4e-9 + r0 * speed * 0.02;
            assert!(
                hi >= brute_hi - grid && hi <= brute_hi + grid,
                "{hi} against {brute_hi}"
            );
            assert!(
                lo <= brute_lo + grid && lo >= brute_lo - grid,
                "{lo} against {brute_lo}"
            );
            // The force there now is inside.
            let now = s0 * y[2] + r0 * y[3];
            assert!(lo < now && now < hi, "{lo} {now} {hi}");
        };
        // With the pole face (the bracketed search) and without it (the
        // closed form).
        with_model(check);
        let (m, mut build) = relay();
        build.pole_face = None;
        with_build(&m, &build, check);
    }
}
