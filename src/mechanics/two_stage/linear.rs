//! The two-stage relay under a constant force with Kelvin–Voigt surfaces:
//! every mode is linear, so the motion is exact.
//!
//! In each mode (the contact and the pole face each open or engaged) the
//! state `y = (u_a, v_a, u_b, v_b)` obeys `ẏ = A y + b`. With `y*` the
//! mode's equilibrium and the velocities scaled by the mode's fastest
//! angular frequency ω (`w = D⁻¹ (y − y*)`, `D = diag(1, ω, 1, ω)`, so that
//! every entry of `a = D⁻¹ A D` is of order ω), the motion is
//! `w(τ) = exp(a τ) w(0)`. The propagator `Φ = exp(a h)` over a step
//! `h = 2.5/‖a‖∞` (under half the fastest period, so that no linear
//! function of the state turns twice in a step) is computed once per mode
//! from its Taylor series (40 terms), and each step costs one 4 × 4
//! product.
//!
//! Every event function is linear in the state (or the larger or smaller
//! of two linear functions, for a surface released by force), so an event
//! is located on the exact solution: a sign change over a step, or a
//! minimum inside it below zero (found where the function's rate changes
//! sign), is polished by Newton's method safeguarded by bisection on the
//! step's Taylor polynomial in τ (28 terms, built only for the steps that
//! need one), where any linear function of the state is a scalar
//! polynomial. The contact force's peak and minimum and the largest
//! opening are found the same way, at the zeros of their rates.
//!
//! A closing released by position is decided by the energy bound of
//! [`super::energy`] in closed form: with the force constant, the least
//! potential with the contact point at the gap is the minimum of a convex
//! quadratic in the armature's position, piecewise at the pole face.

use std::sync::Arc;

use nalgebra::{Matrix4, Vector4};

use super::linear_mode::{Form, LinearMode, Poly, Taylor, W};
use super::model::{RelayModel, StopMode, StopModes, Which, Y};
use super::propagation::{Propagation, decided};
use super::relay::Release;
use super::run::Horizon;
use super::span::{Interpolant, Span};
use crate::chatter::Outcome;
use crate::mechanics::driven::DriveModel;
use crate::mechanics::error::DriveError;
use crate::mechanics::parameters::Settings;
use crate::mechanics::surface::Surface;

/// An event function: one form, or the larger or smaller of two.
#[derive(Debug, Clone, Copy)]
enum Guard {
    One(Form),
    Max(Form, Form),
    Min(Form, Form),
}

impl Guard {
    fn value(&self, w: &W) -> f64 {
        match self {
            Guard::One(f) => f.value(w),
            Guard::Max(a, b) => a.value(w).max(b.value(w)),
            Guard::Min(a, b) => a.value(w).min(b.value(w)),
        }
    }

    fn forms(&self) -> impl Iterator<Item = &Form> {
        let (a, b) = match self {
            Guard::One(f) => (f, None),
            Guard::Max(a, b) | Guard::Min(a, b) => (a, Some(b)),
        };
        std::iter::once(a).chain(b)
    }
}

/// The relay's parameters in the linear case.
pub(crate) struct LinearSystem {
    /// N, the constant force less the preload and the spring at the gap.
    push: f64,
    m: f64,
    r: f64,
    s: f64,
    mb: f64,
    sb: f64,
    rb: f64,
    s0: f64,
    r0: f64,
    by_force: bool,
    /// (o, s_p, r_p, released by force)
    pole: Option<(f64, f64, f64, bool)>,
    /// N, the constant force less the preload.
    net: f64,
    gap: f64,
}

impl LinearSystem {
    /// The linear system of `model`, when it is one: a constant force (no
    /// rest stop), a blade, a Kelvin–Voigt contact, and a Kelvin–Voigt
    /// pole face or none.
    pub(crate) fn of<D: DriveModel>(model: &RelayModel<'_, D>) -> Option<LinearSystem> {
        let force = model.drive.constant()?;
        let blade = model.build.blade?;
        if model.rest {
            return None;
        }
        let Surface::KelvinVoigt {
            stiffness: s0,
            damping: r0,
        } = model.contact
        else {
            return None;
        };
        let pole = match &model.build.pole_face {
            None => None,
            Some(p) => match p.surface {
                Surface::KelvinVoigt { stiffness, damping } => Some((
                    p.overtravel,
                    stiffness,
                    damping,
                    p.release == Release::Force,
                )),
                _ => return None,
            },
        };
        let m = model.m;
        Some(LinearSystem {
            push: force - m.preload - m.stiffness * m.gap,
            m: m.mass,
            r: m.damping,
            s: m.stiffness,
            mb: blade.mass,
            sb: blade.stiffness,
            rb: blade.damping,
            s0,
            r0,
            by_force: model.build.release == Release::Force,
            pole,
            net: force - m.preload,
            gap: m.gap,
        })
    }

    /// The mode with the contact and the pole face `engaged` or not.
    fn mode(&self, contact: bool, pole: bool) -> LinearMode {
        let (o, sp, rp) = match (self.pole, pole) {
            (Some((o, sp, rp, _)), true) => (o, sp, rp),
            _ => (0.0, 0.0, 0.0),
        };
        let (s0, r0) = if contact {
            (self.s0, self.r0)
        } else {
            (0.0, 0.0)
        };
        let (m, mb) = (self.m, self.mb);
        let a = Matrix4::new(
            0.0,
            1.0,
            0.0,
            0.0,
            -(self.s + self.sb + sp) / m,
            -(self.r + self.rb + rp) / m,
            self.sb / m,
            self.rb / m,
            0.0,
            0.0,
            0.0,
            1.0,
            self.sb / mb,
            self.rb / mb,
            -(self.sb + s0) / mb,
            -(self.rb + r0) / mb,
        );
        let b = Vector4::new(0.0, (self.push + sp * o) / m, 0.0, 0.0);
        // A is invertible: its stiffness part has determinant s·s_b > 0.
        let eq = a.lu().solve(&(-b)).unwrap_or_else(Vector4::zeros);
        let omega = ((self.s + self.sb + sp) / m)
            .max((self.sb + s0) / mb)
            .sqrt();
        let d = [1.0, omega, 1.0, omega];
        let scaled = Matrix4::from_fn(|i, j| a[(i, j)] * d[j] / d[i]);
        let norm = (0..4)
            .map(|i| (0..4).map(|j| scaled[(i, j)].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        let h = 2.5 / norm;
        let mut phi = Matrix4::identity();
        let mut term = Matrix4::identity();
        for k in 1..=40 {
            term = term * scaled * (h / k as f64);
            phi += term;
        }
        LinearMode {
            a: scaled,
            eq,
            omega,
            phi,
            h,
        }
    }

    /// The event functions of `modes` in `mode`, each positive while the
    /// mode lasts.
    fn guards(&self, mode: &LinearMode, modes: StopModes) -> Vec<(Which, Guard)> {
        let ub = mode.form([0.0, 0.0, 1.0, 0.0], 0.0);
        let push = mode.form([0.0, 0.0, self.s0, self.r0], 0.0);
        let mut out = vec![(
            Which::Contact,
            match (modes.contact, self.by_force) {
                (StopMode::Open, false) => Guard::One(ub.negated()),
                (StopMode::Open, true) => Guard::Max(ub.negated(), push.negated()),
                (_, false) => Guard::One(ub),
                (_, true) => Guard::Min(ub, push),
            },
        )];
        if let Some((o, sp, rp, by_force)) = self.pole {
            let delta = mode.form([1.0, 0.0, 0.0, 0.0], -o);
            let push = mode.form([sp, rp, 0.0, 0.0], -sp * o);
            out.push((
                Which::Pole,
                match (modes.pole, by_force) {
                    (StopMode::Open, false) => Guard::One(delta.negated()),
                    (StopMode::Open, true) => Guard::Max(delta.negated(), push.negated()),
                    (_, false) => Guard::One(delta),
                    (_, true) => Guard::Min(delta, push),
                },
            ));
        }
        out
    }

    /// J, the energy of state `y` with the force frozen.
    fn energy(&self, y: &Y) -> f64 {
        let g = self.gap;
        let (xa, xb) = (g + y[0], g + y[2]);
        0.5 * self.m * y[1] * y[1] + 0.5 * self.mb * y[3] * y[3] + self.potential(xa, xb)
    }

    fn potential(&self, xa: f64, xb: f64) -> f64 {
        let g = self.gap;
        let mut v = 0.5 * self.s * xa * xa - self.net * xa + 0.5 * self.sb * (xa - xb).powi(2);
        let delta = xb - g;
        if delta > 0.0 {
            v += 0.5 * self.s0 * delta * delta;
        }
        if let Some((o, sp, _, _)) = self.pole {
            let d = xa - g - o;
            if d > 0.0 {
                v += 0.5 * sp * d * d;
            }
        }
        v
    }

    /// J, the least potential with the contact point at the gap: a convex
    /// quadratic in `x_a`, piecewise at the pole face.
    fn position_bound(&self) -> f64 {
        let g = self.gap;
        let free = (self.net + self.sb * g) / (self.s + self.sb);
        let xa = match self.pole {
            Some((o, sp, _, _)) if free > g + o => {
                (self.net + self.sb * g + sp * (g + o)) / (self.s + self.sb + sp)
            }
            _ => free,
        };
        self.potential(xa, g)
    }

    /// Whether the energy bound decides the closing at state `y`.
    fn decided(&self, y: &Y, modes: StopModes, touched: bool) -> Option<Outcome> {
        if !touched || self.by_force {
            return None;
        }
        let e = self.energy(y);
        let bound = self.position_bound();
        let margin = 1e-9 * (e.abs() + bound.abs() + self.s * self.gap * self.gap);
        if e >= bound - margin {
            return None;
        }
        match modes.contact {
            StopMode::Open if y[2] < 0.0 => Some(Outcome::EndsOpen),
            StopMode::Open => None,
            _ => Some(Outcome::Stuck),
        }
    }
}

/// Whether `form` has a minimum inside the step: its rate, from the
/// rates of the state at the ends (`aw0 = a w0`, `aw1 = a w1`), turns
/// from falling to rising.
fn dips(form: &Form, aw0: &W, aw1: &W) -> bool {
    form.q.dot(aw0) < 0.0 && form.q.dot(aw1) > 0.0
}

/// Whether `form`'s rate changes sign inside the step.
fn turns(form: &Form, aw0: &W, aw1: &W) -> bool {
    let (r0, r1) = (form.q.dot(aw0), form.q.dot(aw1));
    r0 != 0.0 && r1 != 0.0 && (r0 > 0.0) != (r1 > 0.0)
}

/// The first event over `(0, h]` from `w0` (ending at `w1`): (τ, which).
#[allow(clippy::too_many_arguments)]
fn first_event(
    mode: &LinearMode,
    guards: &[(Which, Guard)],
    w0: &W,
    w1: &W,
    (aw0, aw1): (&W, &W),
    h: f64,
    series: &mut Option<Taylor>,
) -> Option<(f64, Which)> {
    let mut best: Option<(f64, Which)> = None;
    for &(which, guard) in guards {
        let needs = guard.value(w1) < 0.0 || guard.forms().any(|f| dips(f, aw0, aw1));
        if !needs {
            continue;
        }
        let series = series.get_or_insert_with(|| Taylor::new(mode, w0));
        let polys: Vec<Poly> = guard.forms().map(|f| series.poly(f)).collect();
        let value = |tau: f64| match guard {
            Guard::One(_) => polys[0].value(tau),
            Guard::Max(..) => polys[0].value(tau).max(polys[1].value(tau)),
            Guard::Min(..) => polys[0].value(tau).min(polys[1].value(tau)),
        };
        // Where the guard turns negative: at the step's end, or at an
        // interior minimum of one of its forms.
        let mut end = (value(h) < 0.0).then_some(h);
        if end.is_none() {
            for poly in &polys {
                if let Some(tm) = poly.extremum(h)
                    && value(tm) < 0.0
                {
                    end = Some(end.map_or(tm, |e: f64| e.min(tm)));
                }
            }
        }
        let Some(hi) = end else { continue };
        // The first zero in (0, hi] of the guard: of its forms, those that
        // cross zero downward before `hi`; for a max the last of them, for
        // a min the first.
        let crossing = |poly: &Poly| {
            if poly.value(hi) > 0.0 {
                return None;
            }
            if poly.value(0.0) > 0.0 {
                return Some(poly.root(0.0, hi));
            }
            // Starting on its zero (the event that began this mode, set
            // exactly): the crossing is after the form's maximum.
            let top = poly.extremum(hi)?;
            (poly.value(top) > 0.0).then(|| poly.root(top, hi))
        };
        let found: Vec<f64> = polys.iter().filter_map(crossing).collect();
        let tau = match guard {
            Guard::Max(..) => found.iter().copied().reduce(f64::max),
            _ => found.iter().copied().reduce(f64::min),
        }
        .unwrap_or(hi);
        if best.is_none_or(|(tb, _)| tau < tb) {
            best = Some((tau, which));
        }
    }
    best
}

/// Propagate `p` exactly from event to event, to the horizon.
pub(crate) fn propagate<D: DriveModel>(
    system: &LinearSystem,
    model: &RelayModel<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    p: &mut Propagation,
) -> Result<(), DriveError> {
    let mut cache: [Option<Arc<LinearMode>>; 4] = [None, None, None, None];
    let force_form = |mode: &LinearMode| mode.form([0.0, 0.0, system.s0, system.r0], 0.0);
    while p.t < settings.t_end && p.ending.is_none() {
        let key = usize::from(p.modes.contact != StopMode::Open)
            + 2 * usize::from(p.modes.pole != StopMode::Open);
        let mode = cache[key]
            .get_or_insert_with(|| {
                Arc::new(system.mode(
                    p.modes.contact != StopMode::Open,
                    p.modes.pole != StopMode::Open,
                ))
            })
            .clone();
        let guards = system.guards(&mode, p.modes);
        let force = force_form(&mode);
        let ub = mode.form([0.0, 0.0, 1.0, 0.0], 0.0);
        let mut w = mode.w_of(&p.y);
        let mut aw = mode.a * w;
        loop {
            p.count_step(model.m, settings)?;
            let h = mode.h.min(settings.t_end - p.t);
            let w1 = if h == mode.h {
                mode.phi * w
            } else {
                mode.at(&w, h)
            };
            let mut series = None;
            let aw1 = mode.a * w1;
            let event = first_event(&mode, &guards, &w, &w1, (&aw, &aw1), h, &mut series);
            let tau = event.map_or(h, |(tau, _)| tau);
            let w_end = match (&series, event) {
                (Some(series), Some(_)) => series.at(tau),
                _ => w1,
            };
            let aw_end = if event.is_some() { mode.a * w_end } else { aw1 };
            track(
                system,
                p,
                &mode,
                (&w, &w_end),
                (&aw, &aw_end),
                tau,
                (&force, &ub),
                &mut series,
            );
            let y_end = mode.y_of(&w_end);
            p.pieces.push(Span {
                motion: Interpolant::Linear {
                    w0: w,
                    mode: mode.clone(),
                },
                t0: p.t,
                t1: p.t + tau,
                y1: y_end,
                modes: p.modes,
            });
            match event {
                Some((_, which)) => {
                    p.event(model, settings, which, p.t + tau, y_end);
                    break;
                }
                None => {
                    p.t += tau;
                    p.y = y_end;
                    w = w_end;
                    aw = aw_end;
                    if horizon == Horizon::Closing
                        && let Some(end) = system.decided(&p.y, p.modes, !p.rec.contact_is_empty())
                    {
                        p.ending = Some(end);
                        return Ok(());
                    }
                    if horizon == Horizon::Closing
                        && system.by_force
                        && p.steps % 16 == 0
                        && let Some(end) = decided(model, &mut p.bound, p.t, &p.y, p.modes, &p.rec)
                    {
                        p.ending = Some(end);
                        return Ok(());
                    }
                    if p.t >= settings.t_end {
                        return Ok(());
                    }
                }
            }
        }
    }
    Ok(())
}

/// The contact force's extremes and the openings over one step from
/// `w0` to `w1` (`aw0`, `aw1` their rates).
#[allow(clippy::too_many_arguments)] // one step's states, rates and forms, as the loop has them
fn track(
    system: &LinearSystem,
    p: &mut Propagation,
    mode: &LinearMode,
    (w0, w1): (&W, &W),
    (aw0, aw1): (&W, &W),
    h: f64,
    (force, ub): (&Form, &Form),
    series: &mut Option<Taylor>,
) {
    let mut at = |w: &W| {
        let y = mode.y_of(w);
        p.rec.observe(system.gap, p.modes, &y, |y| {
            let f = system.s0 * y[2] + system.r0 * y[3];
            if system.by_force { f.max(0.0) } else { f }
        });
    };
    at(w1);
    // An opening's largest gap (or the reach before the first touch) and
    // a contact's peak and least force are where their rates turn.
    let watched = if p.modes.contact == StopMode::Open {
        ub
    } else {
        force
    };
    let inside = turns(watched, aw0, aw1);
    if inside {
        let series = series.get_or_insert_with(|| Taylor::new(mode, w0));
        if let Some(tm) = series.poly(watched).extremum(h) {
            at(&series.at(tm));
        }
    }
}
