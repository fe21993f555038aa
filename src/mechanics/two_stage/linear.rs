//! The two-stage relay under a constant force with Kelvin–Voigt surfaces:
//! every mode is linear, so the motion is exact.
//!
//! In each mode (the contact and the pole face each open or engaged) the
//! state `y = (u_a, v_a, u_b, v_b)` obeys `ẏ = A y + b`. With `y*` the
//! mode's equilibrium and the state scaled (`w = D⁻¹ (y − y*)`, `D`
//! diagonal, chosen so that `‖a‖∞` of `a = D⁻¹ A D` is least: see
//! [`balance`]), the motion is `w(τ) = exp(a τ) w(0)`. A mode is stepped
//! by `h = 3/‖a‖∞`, under half its fastest period; the propagator
//! `Φ = exp(a h)` comes from the Taylor series (28 terms, `a^k/k!` kept for
//! the mode), and a step costs one 4 × 4 product.
//!
//! Every event function is linear in the state (or the larger or smaller
//! of two linear functions, for a surface released by force). Each form a
//! mode watches (the blade's position, the contact's force, the
//! overtravel, the pole face's force) keeps its series `(aᵀ)^k q / k!`,
//! so its value and rate at the ends of a step cost two dot products, and
//! along a step it is a scalar polynomial in τ for 28 more, built only for
//! the steps that need one. An event is located on the exact solution: a
//! sign change over a step, or a minimum inside it below zero (found where
//! the function's rate changes sign), is polished by Newton's method from
//! the secant, safeguarded by bisection, until the value is lost in its
//! rounding. The contact force's peak and minimum and the widest opening
//! are taken at every step's ends, at the first state of every mode (a
//! damped contact's force can be largest at the touch), and at the zeros
//! of their rates inside a step: a step whose Bernstein coefficients show
//! that nothing inside it can beat the record so far, or that the form
//! is monotone, needs none; else the rate's exact Bernstein coefficients
//! count its turns (Descartes' rule of signs), and every one is found and
//! polished (see [`track`]). Two turns in one step (a blade ringing on its
//! slow swing) are not missed.
//!
//! The motion is kept in pieces of up to 16 steps, each a mode, a start
//! and its scaled state: a state inside one is had again by the same
//! steps and one series.
//!
//! A closing released by position is decided by the energy bound of
//! [`super::energy`] in closed form: with the force constant, the least
//! potential with the contact point at the gap is the minimum of a convex
//! quadratic in the armature's position, piecewise at the pole face.

use std::sync::Arc;

use crate::mechanics::linalg::{Matrix4, SMatrix, SVector, Vector4};

use super::linear_mode::{LinearMode, Poly, STEP_NORM, Series, StepBernstein, W};
use super::model::{RelayModel, StopMode, StopModes, Which, Y};
use super::propagation::{Propagation, check_closing};
use super::relay::Release;
use super::run::Horizon;
use super::span::{Interpolant, Span};
use crate::chatter::Outcome;
use crate::mechanics::driven::DriveModel;
use crate::mechanics::error::DriveError;
use crate::mechanics::locate::{self, Combine, StepForm};
use crate::mechanics::parameters::Settings;
use crate::mechanics::surface::Surface;

/// The forms a mode's steps read, by index into [`ModeKit::forms`].
const UB: usize = 0;
const FORCE: usize = 1;
const POLE_DELTA: usize = 2;
const POLE_PUSH: usize = 3;

/// A form of [`ModeKit::forms`], or its negative.
#[derive(Debug, Clone, Copy)]
struct Term {
    form: usize,
    negated: bool,
}

impl Term {
    #[inline(always)]
    fn plus(form: usize) -> Term {
        Term {
            form,
            negated: false,
        }
    }

    #[inline(always)]
    fn minus(form: usize) -> Term {
        Term {
            form,
            negated: true,
        }
    }

    #[inline(always)]
    fn sign(&self) -> f64 {
        if self.negated { -1.0 } else { 1.0 }
    }

    fn value(&self, at: &Reading) -> f64 {
        self.sign() * at.value[self.form]
    }

    #[inline(always)]
    fn rate(&self, at: &Reading) -> f64 {
        self.sign() * at.rate[self.form]
    }
}

/// An event function: one term, or the larger or smaller of two.
#[derive(Debug, Clone, Copy)]
enum Guard {
    One(Term),
    Max(Term, Term),
    Min(Term, Term),
}

impl Guard {
    fn terms(&self) -> impl Iterator<Item = Term> {
        let (a, b) = match *self {
            Guard::One(f) => (f, None),
            Guard::Max(a, b) | Guard::Min(a, b) => (a, Some(b)),
        };
        std::iter::once(a).chain(b)
    }
}

/// One mode with what its steps use: the forms they read (the blade's
/// position, the contact's force, and with a pole face the armature's
/// overtravel and the pole face's force) and the event functions.
struct ModeKit {
    mode: Arc<LinearMode>,
    forms: Vec<Series>,
    guards: Vec<(Which, Guard)>,
    readout: Readout,
}

/// The forms' values and rates as one affine map of `w`, so that a step
/// reads them in one product: a relay without a pole face has two forms
/// (four rows: the values, then the rates), one with a pole face four
/// (eight rows). `after` is `at · Φ`: the same read at the end of a full
/// step, from the state at its start (so that it need not wait for that
/// state).
// One per mode and run, read on every step: kept inline, not boxed.
#[allow(clippy::large_enum_variant)]
enum Readout {
    Two {
        at: Matrix4<f64>,
        after: Matrix4<f64>,
        offset: Vector4<f64>,
    },
    Four {
        at: SMatrix<f64, 8, 4>,
        after: SMatrix<f64, 8, 4>,
        offset: SVector<f64, 8>,
    },
}

impl ModeKit {
    fn new(mode: Arc<LinearMode>, forms: Vec<Series>, guards: Vec<(Which, Guard)>) -> ModeKit {
        let n = forms.len();
        let mut at = SMatrix::<f64, 8, 4>::zeros();
        let mut offset = SVector::<f64, 8>::zeros();
        for (i, form) in forms.iter().enumerate() {
            at.set_row(i, &form.r[0].transpose());
            at.set_row(n + i, &form.r[1].transpose());
            offset[i] = form.k;
        }
        let readout = if n <= 2 {
            let at: Matrix4<f64> = at.fixed_rows::<4>(0).into_owned();
            Readout::Two {
                after: at * mode.phi,
                at,
                offset: offset.fixed_rows::<4>(0).into_owned(),
            }
        } else {
            Readout::Four {
                after: at * mode.phi,
                at,
                offset,
            }
        };
        ModeKit {
            mode,
            forms,
            guards,
            readout,
        }
    }

    /// The forms' values and rates at `w` (zero for forms the mode has
    /// not).
    #[inline(always)]
    fn read(&self, w: &W) -> Reading {
        match &self.readout {
            Readout::Two { at, offset, .. } => Reading::two(&(at * w + offset)),
            Readout::Four { at, offset, .. } => Reading::four(&(at * w + offset)),
        }
    }

    /// The forms' values and rates after a full step of the mode from `w`.
    #[inline(always)]
    fn read_after_step(&self, w: &W) -> Reading {
        match &self.readout {
            Readout::Two { after, offset, .. } => Reading::two(&(after * w + offset)),
            Readout::Four { after, offset, .. } => Reading::four(&(after * w + offset)),
        }
    }
}

/// The values and rates of a mode's forms at one state.
#[derive(Debug, Clone, Copy)]
struct Reading {
    value: [f64; 4],
    rate: [f64; 4],
}

impl Reading {
    /// Two forms' values and rates (the others zero).
    #[inline(always)]
    fn two(v: &Vector4<f64>) -> Reading {
        Reading {
            value: [v[0], v[1], 0.0, 0.0],
            rate: [v[2], v[3], 0.0, 0.0],
        }
    }

    /// Four forms' values and rates.
    #[inline(always)]
    fn four(v: &SVector<f64, 8>) -> Reading {
        Reading {
            value: [v[0], v[1], v[2], v[3]],
            rate: [v[4], v[5], v[6], v[7]],
        }
    }
}

/// The forms' polynomials and Bernstein coefficients over one step, each
/// built when first needed.
struct StepPolys<'a> {
    kit: &'a ModeKit,
    w0: &'a W,
    y0: &'a Y,
    polys: [Option<Poly>; 4],
    bern: [Option<StepBernstein>; 4],
}

impl StepPolys<'_> {
    fn new<'a>(kit: &'a ModeKit, w0: &'a W, y0: &'a Y) -> StepPolys<'a> {
        StepPolys {
            kit,
            w0,
            y0,
            polys: [None; 4],
            bern: [None; 4],
        }
    }

    /// The polynomial of form `form` (not negated), built on first use.
    #[inline(always)]
    fn of(&mut self, form: usize) -> &Poly {
        let (kit, w0, y0) = (self.kit, self.w0, self.y0);
        // Not `get_or_insert_with`: its closure would be compiled apart,
        // outside the wide steps.
        let slot = &mut self.polys[form];
        if slot.is_none() {
            *slot = Some(kit.forms[form].poly(w0, y0));
        }
        slot.as_ref().expect("built just above")
    }

    /// The Bernstein coefficients of form `form` over the mode's full
    /// step, computed on first use.
    #[inline(always)]
    fn bernstein(&mut self, form: usize) -> &StepBernstein {
        let (kit, w0) = (self.kit, self.w0);
        let slot = &mut self.bern[form];
        if slot.is_none() {
            *slot = Some(kit.forms[form].step_bernstein(w0));
        }
        slot.as_ref().expect("computed just above")
    }

    /// Whether `term` stays positive over the step, read as `at0` at its
    /// start, as its series shows without a polynomial (see
    /// [`Series::shown_positive`]): most steps need no more.
    #[inline(always)]
    fn stays_positive(&mut self, term: Term, at0: &Reading) -> bool {
        let form = &self.kit.forms[term.form];
        form.shown_positive(
            term.value(at0),
            self.w0,
            term.negated,
            &mut self.bern[term.form],
        )
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
    /// J, [`LinearSystem::position_bound`], computed once.
    bound: f64,
    /// J, [`LinearSystem::pole_bound`], computed once (`None`: found by
    /// the general bound, for a pole face released by force).
    pole_bound: Option<f64>,
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
        let mut system = LinearSystem {
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
            bound: 0.0,
            pole_bound: None,
        };
        system.bound = system.position_bound();
        system.pole_bound = system.pole_bound();
        Some(system)
    }

    /// The mode with the contact and the pole face `engaged` or not.
    #[inline(always)]
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
        let d = balance(&a, omega);
        let scaled = Matrix4::from_fn(|i, j| a[(i, j)] * d[j] / d[i]);
        let norm = (0..4)
            .map(|i| (0..4).map(|j| scaled[(i, j)].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        LinearMode::new(scaled, eq, d, STEP_NORM / norm)
    }

    /// The mode with the contact and the pole face engaged as in `modes`,
    /// with its event functions, each positive while the mode lasts.
    #[inline(always)]
    fn kit(&self, modes: StopModes) -> ModeKit {
        let mode = self.mode(
            modes.contact != StopMode::Open,
            modes.pole != StopMode::Open,
        );
        let mut forms = vec![
            Series::new(&mode, [0.0, 0.0, 1.0, 0.0], 0.0),
            Series::new(&mode, [0.0, 0.0, self.s0, self.r0], 0.0),
        ];
        let (ub, force) = (Term::plus(UB), Term::plus(FORCE));
        let (not_ub, not_force) = (Term::minus(UB), Term::minus(FORCE));
        let mut guards = vec![(
            Which::Contact,
            match (modes.contact, self.by_force) {
                (StopMode::Open, false) => Guard::One(not_ub),
                (StopMode::Open, true) => Guard::Max(not_ub, not_force),
                (_, false) => Guard::One(ub),
                (_, true) => Guard::Min(ub, force),
            },
        )];
        if let Some((o, sp, rp, by_force)) = self.pole {
            forms.push(Series::new(&mode, [1.0, 0.0, 0.0, 0.0], -o));
            forms.push(Series::new(&mode, [sp, rp, 0.0, 0.0], -sp * o));
            let (delta, push) = (Term::plus(POLE_DELTA), Term::plus(POLE_PUSH));
            let (not_delta, not_push) = (Term::minus(POLE_DELTA), Term::minus(POLE_PUSH));
            guards.push((
                Which::Pole,
                match (modes.pole, by_force) {
                    (StopMode::Open, false) => Guard::One(not_delta),
                    (StopMode::Open, true) => Guard::Max(not_delta, not_push),
                    (_, false) => Guard::One(delta),
                    (_, true) => Guard::Min(delta, push),
                },
            ));
        }
        ModeKit::new(Arc::new(mode), forms, guards)
    }

    /// J, the energy of state `y` with the force frozen.
    #[inline(always)]
    fn energy(&self, y: &Y) -> f64 {
        let g = self.gap;
        let (xa, xb) = (g + y[0], g + y[2]);
        0.5 * self.m * y[1] * y[1] + 0.5 * self.mb * y[3] * y[3] + self.potential(xa, xb)
    }

    #[inline(always)]
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

    /// J, the least potential with the armature on a pole face released
    /// by position (`x_a = g + o`): the contact point then rests where the
    /// blade and the contact balance, `x_b − g = s_b o/(s_b + s0)`, and
    /// the two springs in series store `½ s_b s0/(s_b + s0) o²`. `None`
    /// without such a pole face.
    fn pole_bound(&self) -> Option<f64> {
        let (o, _, _, by_force) = self.pole?;
        if by_force {
            return None;
        }
        let xa = self.gap + o;
        let series = self.sb * self.s0 / (self.sb + self.s0);
        Some(0.5 * self.s * xa * xa - self.net * xa + 0.5 * series * o * o)
    }

    /// N, the contact's force as recorded from the law's value `f`: not
    /// below zero for a contact released by force.
    #[inline(always)]
    fn force(&self, f: f64) -> f64 {
        if self.by_force { f.max(0.0) } else { f }
    }

    #[inline(always)]
    fn below(&self, e: f64, bound: f64) -> bool {
        let margin = 1e-9 * (e.abs() + bound.abs() + self.s * self.gap * self.gap);
        e < bound - margin
    }

    /// The contact's ending, when the energy bound decides it at state
    /// `y` (a contact released by position).
    #[inline(always)]
    fn decided(&self, y: &Y, modes: StopModes) -> Option<Outcome> {
        if !self.below(self.energy(y), self.bound) {
            return None;
        }
        match modes.contact {
            StopMode::Open if y[2] < 0.0 => Some(Outcome::EndsOpen),
            StopMode::Open => None,
            _ => Some(Outcome::Stuck),
        }
    }

    /// Check the closing at the present state of `p` (every fourth step):
    /// in closed form for stops released by position, else by the
    /// general bound.
    #[inline(always)]
    fn check<D: DriveModel>(&self, model: &RelayModel<'_, D>, p: &mut Propagation) {
        let closed_form = !self.by_force && (self.pole.is_none() || self.pole_bound.is_some());
        if !closed_form {
            return check_closing(model, p);
        }
        if p.rec.contact_is_empty() || p.steps % 4 != 0 {
            return;
        }
        if p.ending.is_none() {
            match self.decided(&p.y, p.modes) {
                Some(ending) => p.decide(ending),
                None => return,
            }
        }
        if p.follow_pole && !p.pole_settled {
            p.pole_settled = self
                .pole_bound
                .is_none_or(|bound| self.below(self.energy(&p.y), bound));
        }
        p.settle_opening(model);
        p.settle_force(model);
    }
}

/// The diagonal scaling `d` that makes `‖D⁻¹ A D‖∞` least: the Perron
/// vector of `|A|`, for which every row of `D⁻¹ |A| D` sums to the
/// spectral radius of `|A|` (Perron–Frobenius). The step, `3/‖D⁻¹ A D‖∞`,
/// is then as long as the Taylor series' accuracy allows; on a blade as
/// stiff as the contact it is 1.4–1.9 times the step of one velocity scale
/// `ω` for both bodies. Found by power iteration on `|A₀| + σI`, where
/// `A₀` is `A` with the velocities scaled by `ω` (all its entries of
/// order ω, so that a few dozen iterations settle) and `|A₀|` irreducible,
/// the blade's spring coupling the two bodies.
#[inline(always)]
fn balance(a: &Matrix4<f64>, omega: f64) -> [f64; 4] {
    let d0 = [1.0, omega, 1.0, omega];
    let b = Matrix4::from_fn(|i, j| (a[(i, j)] * d0[j] / d0[i]).abs());
    let sigma = 0.25 * omega;
    let mut v = Vector4::repeat(1.0);
    for _ in 0..40 {
        let next = b * v + v * sigma;
        v = next / next.max();
    }
    let floor = 1e-6;
    std::array::from_fn(|i| d0[i] * v[i].max(floor))
}

/// Whether `term`'s rate changes sign inside the step from `at0` to `at1`.
#[inline(always)]
fn turns(term: Term, at0: &Reading, at1: &Reading) -> bool {
    let (r0, r1) = (term.rate(at0), term.rate(at1));
    r0 != 0.0 && r1 != 0.0 && (r0 > 0.0) != (r1 > 0.0)
}

/// The first event over `(0, h]` of a step from `w0` (read as `at0`):
/// (τ, which). Every guard is searched by the one event locator
/// ([`crate::mechanics::locate`]), which cannot step over a zero of the
/// exact polynomial, and the zero it brackets is polished on it. Most
/// steps end here, every guard shown positive over the step by its
/// Bernstein rows alone; the search itself is [`guard_event`].
#[inline(always)]
fn first_event<const WIDE: bool>(
    polys: &mut StepPolys<'_>,
    at0: &Reading,
    h: f64,
    resolution: f64,
) -> Option<(f64, Which)> {
    let mut best: Option<(f64, Which)> = None;
    let kit = polys.kit;
    for &(which, guard) in &kit.guards {
        let quick = match guard {
            Guard::One(t) => polys.stays_positive(t, at0),
            Guard::Max(a, b) => polys.stays_positive(a, at0) || polys.stays_positive(b, at0),
            Guard::Min(a, b) => polys.stays_positive(a, at0) && polys.stays_positive(b, at0),
        };
        if quick {
            continue;
        }
        // Elsewhere than on x86-64 there are no wide steps.
        #[cfg(target_arch = "x86_64")]
        let tau = if WIDE {
            // SAFETY: the wide steps run only where the processor has
            // AVX2 and FMA (see `propagate`).
            unsafe { guard_event_wide(polys, guard, h, resolution) }
        } else {
            guard_event(polys, guard, h, resolution)
        };
        #[cfg(not(target_arch = "x86_64"))]
        let tau = guard_event(polys, guard, h, resolution);
        let Some(tau) = tau else {
            continue;
        };
        if best.is_none_or(|(tb, _)| tau < tb) {
            best = Some((tau, which));
        }
    }
    best
}

/// The first zero of `guard` over `(0, h]` (τ), when the quick test of
/// [`first_event`] could not show it positive: bracketed by the locator
/// (or by the form's full Bernstein rows, for the common event) and
/// polished on the exact polynomial. Kept apart from the quick test, so
/// that what only this search needs is never computed for a step that
/// ends there.
#[inline(never)]
fn guard_event(polys: &mut StepPolys<'_>, guard: Guard, h: f64, resolution: f64) -> Option<f64> {
    search_guard(polys, guard, h, resolution)
}

/// [`guard_event`] compiled with AVX2 and FMA, for the wide steps.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[inline(never)]
fn guard_event_wide(
    polys: &mut StepPolys<'_>,
    guard: Guard,
    h: f64,
    resolution: f64,
) -> Option<f64> {
    search_guard(polys, guard, h, resolution)
}

/// [`guard_event`]'s search, inlined into each of its compilations.
#[inline(always)]
fn search_guard(polys: &mut StepPolys<'_>, guard: Guard, h: f64, resolution: f64) -> Option<f64> {
    let (kit, w0) = (polys.kit, polys.w0);
    let combine = match guard {
        Guard::One(_) => Combine::One,
        Guard::Max(..) => Combine::Max,
        Guard::Min(..) => Combine::Min,
    };
    for t in guard.terms() {
        polys.of(t.form);
    }
    // Each term's polynomial, by reference, with its sign: a negated
    // form has the same zeros and its values negated exactly.
    let built = &polys.polys;
    let mut terms = [None; 2];
    for (slot, t) in terms.iter_mut().zip(guard.terms()) {
        *slot = built[t.form].as_ref().map(|poly| (poly, t.sign()));
    }
    let step_polys = terms.iter().flatten().copied();
    // The common event: one form, one zero, nothing before it; the
    // locator would bracket the whole step.
    let isolated = match guard {
        Guard::One(t) if h == kit.mode.h => kit.forms[t.form].isolated_over_step(w0, t.negated),
        _ => false,
    };
    let bracket = if isolated {
        Some((0.0, 1.0))
    } else {
        let mut forms = [StepForm::new(&[0.0]); 2];
        let mut count = 0;
        for (form, (p, sign)) in forms.iter_mut().zip(step_polys.clone()) {
            *form = StepForm::scaled(&p.p.map(|c| sign * c), h);
            count += 1;
        }
        locate::first_zero(&forms[..count], combine, resolution / h)
    };
    let (lo, hi) = bracket?;
    let (lo, hi) = (lo * h, hi * h);
    // Polish on the exact polynomial: the zero of each form that
    // crosses in the bracket; for a max the last, else the first.
    // (A loop, not an iterator's closure, which would be compiled apart,
    // outside the wide steps.)
    let mut tau: Option<f64> = None;
    for (poly, sign) in step_polys {
        // The value at the bracket's end and the rounding of the form's
        // values over the bracket (0 ≤ lo < hi).
        let (f_hi, noise) = poly.value_and_noise(hi);
        let f_lo = poly.value(lo);
        let (v_lo, v_hi) = (sign * f_lo, sign * f_hi);
        if v_hi >= 0.0 || v_lo < 0.0 {
            continue;
        }
        // A form on its zero at the step's start is past that zero.
        let crossing = if lo == 0.0 && v_lo.abs() <= noise {
            hi
        } else {
            poly.root_within((lo, hi), (f_lo, f_hi), noise)
        };
        tau = Some(match (tau, combine) {
            (None, _) => crossing,
            (Some(t), Combine::Max) => t.max(crossing),
            (Some(t), _) => t.min(crossing),
        });
    }
    Some(tau.unwrap_or(hi))
}

/// Propagate `p` exactly from event to event, to the horizon.
///
/// The steps are compiled twice: for the baseline x86-64 (SSE2) and,
/// chosen at run time where the processor has them, with AVX2 and FMA
/// enabled, whose wider vectors and three-operand instructions take the
/// step's dot products in about two thirds of the instructions. The
/// arithmetic is the same operation for operation (Rust never fuses a
/// multiplication and an addition it is not asked to, and reorders no
/// floating-point sum), so both give the same records to the last bit:
/// the reference tests check it.
pub(crate) fn propagate<D: DriveModel>(
    system: &LinearSystem,
    model: &RelayModel<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    p: &mut Propagation,
) -> Result<(), DriveError> {
    #[cfg(target_arch = "x86_64")]
    if wide_steps() {
        // SAFETY: the processor has AVX2 and FMA, checked just above.
        return unsafe { propagate_wide(system, model, settings, horizon, p) };
    }
    propagate_steps::<false, _>(system, model, settings, horizon, p)
}

/// Whether this processor runs the wide steps (AVX2 and FMA), unless
/// the baseline ones are asked for ([`with_baseline_steps`]).
#[cfg(target_arch = "x86_64")]
fn wide_steps() -> bool {
    !BASELINE_ONLY.with(std::cell::Cell::get)
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
}

thread_local! {
    /// Set to run this thread's propagations on the baseline steps
    /// whatever the processor has.
    static BASELINE_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// `f` with this thread's linear propagations on the baseline steps, as
/// on a processor without AVX2: for checking that the wide steps give the
/// same runs.
pub fn with_baseline_steps<T>(f: impl FnOnce() -> T) -> T {
    /// Puts the flag back as it was, also when `f` panics.
    struct Restore(bool);
    impl Drop for Restore {
        fn drop(&mut self) {
            BASELINE_ONLY.with(|b| b.set(self.0));
        }
    }
    let _restore = Restore(BASELINE_ONLY.with(|b| b.replace(true)));
    f()
}

/// [`propagate_steps`] compiled with AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn propagate_wide<D: DriveModel>(
    system: &LinearSystem,
    model: &RelayModel<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    p: &mut Propagation,
) -> Result<(), DriveError> {
    propagate_steps::<true, _>(system, model, settings, horizon, p)
}

/// [`propagate`]'s steps, inlined into each of its two compilations
/// with everything a step calls (`WIDE`: the AVX2 one, which calls the
/// AVX2 compilation of the event search).
#[inline(always)]
fn propagate_steps<const WIDE: bool, D: DriveModel>(
    system: &LinearSystem,
    model: &RelayModel<'_, D>,
    settings: &Settings,
    horizon: Horizon,
    p: &mut Propagation,
) -> Result<(), DriveError> {
    let mut cache: [Option<Arc<ModeKit>>; 4] = [None, None, None, None];
    while p.t < settings.t_end && !p.over() {
        let key = usize::from(p.modes.contact != StopMode::Open)
            + 2 * usize::from(p.modes.pole != StopMode::Open);
        // Not `get_or_insert_with`: its closure would be compiled apart,
        // outside the wide steps.
        if cache[key].is_none() {
            cache[key] = Some(Arc::new(system.kit(p.modes)));
        }
        let kit = cache[key].clone().expect("built just above");
        let mode = &kit.mode;
        let mut w = mode.w_of(&p.y);
        let mut at0 = kit.read(&w);
        // The mode's first state is the record's too: a damped contact's
        // force can be largest at the touch itself (r0 times the impact
        // speed), before its spring takes over.
        observe(system, p, &at0);
        // The steps not yet in a piece: from `t0` and `w0`, each `mode.h`
        // long but the last.
        let (mut t0, mut w0, mut held) = (p.t, w, 0);
        let piece = |p: &mut Propagation, t0: f64, w0: W| Span {
            motion: Interpolant::Linear {
                w0,
                mode: mode.clone(),
            },
            t0,
            t1: p.t,
            y1: p.y,
            modes: p.modes,
        };
        loop {
            p.count_step(model.m, settings)?;
            let h = mode.h.min(settings.t_end - p.t);
            let (w1, at1) = if h == mode.h {
                (mode.phi * w, kit.read_after_step(&w))
            } else {
                let w1 = mode.at(&w, h);
                (w1, kit.read(&w1))
            };
            let y0 = p.y;
            let mut polys = StepPolys::new(&kit, &w, &y0);
            let event = first_event::<WIDE>(&mut polys, &at0, h, settings.min_open_time);
            let (tau, w_end, at_end) = match event {
                Some((tau, _)) => {
                    let w_end = mode.at(&w, tau);
                    (tau, w_end, kit.read(&w_end))
                }
                None => (h, w1, at1),
            };
            p.t += tau;
            p.y = mode.y_of(&w_end);
            track(system, p, &mut polys, (&at0, &at_end), tau);
            w = w_end;
            at0 = at_end;
            held += 1;
            if let Some((_, which)) = event {
                let last = piece(p, t0, w0);
                p.pieces.push(last);
                p.event(model, settings, which, p.t, p.y);
                break;
            }
            // The energy only falls within a mode, so the bound, once
            // met, stays met: every fourth step is enough to see it.
            if horizon == Horizon::Closing {
                system.check(model, p);
            }
            let over = p.over();
            if over || p.t >= settings.t_end || held == PIECE_STEPS {
                let last = piece(p, t0, w0);
                p.pieces.push(last);
                (t0, w0, held) = (p.t, w, 0);
            }
            if over {
                return Ok(());
            }
            if p.t >= settings.t_end {
                return Ok(());
            }
        }
    }
    Ok(())
}

/// Steps kept in one piece of the motion: a state on it is had from the
/// piece's start by at most this many step propagators and one series.
const PIECE_STEPS: usize = 16;

/// Take in the state read as `at`: the engaged contact's force, or the
/// open contact's blade.
#[inline(always)]
fn observe(system: &LinearSystem, p: &mut Propagation, at: &Reading) {
    if p.modes.contact == StopMode::Open {
        p.rec.observe_blade(system.gap, at.value[UB]);
    } else {
        p.rec.observe_force(system.force(at.value[FORCE]));
    }
}

/// The contact force's extremes and the openings over one step of `h`
/// read as `at0` and `at1` at its ends, `p.y` the state at its end.
#[inline(always)]
fn track(
    system: &LinearSystem,
    p: &mut Propagation,
    polys: &mut StepPolys<'_>,
    (at0, at1): (&Reading, &Reading),
    h: f64,
) {
    let open = p.modes.contact == StopMode::Open;
    observe(system, p, at1);
    // An opening's largest gap (or the reach before the first touch) and
    // a contact's peak and least force are at the step's ends, which are
    // taken in, or where the rate turns inside it. Most steps show by
    // their Bernstein coefficients that nothing inside can beat the
    // record, or that the form is monotone.
    let watched = if open { UB } else { FORCE };
    let b = polys.bernstein(watched);
    if b.monotone() {
        return;
    }
    // The bounds' tests are monotone, so that each is asked of every
    // coefficient (see `StepBernstein::least_is`).
    let cannot_beat = if open {
        match p.rec.opening_so_far() {
            (Some(opening), _) => b.least_is(|least| -least <= opening),
            (None, reach) => b.largest_is(|largest| system.gap + largest <= reach),
        }
    } else {
        let (peak, min) = p.rec.force_so_far();
        b.largest_is(|largest| system.force(largest) <= peak)
            && b.least_is(|least| system.force(least) >= min)
    };
    if cannot_beat {
        return;
    }
    // Near a turn: the rate's exact coefficients tell how often it turns.
    let (kit, w0) = (polys.kit, polys.w0);
    let rate = kit.forms[watched].rate_bernstein(w0);
    let turning = rate.turns();
    if turning == Some(0) {
        return;
    }
    let poly = polys.of(watched);
    let mut take = |v: f64| {
        if open {
            p.rec.observe_blade(system.gap, v);
        } else {
            p.rec.observe_force(system.force(v));
        }
    };
    match turning {
        Some(0) => {}
        // One zero of the rate over the full step: inside this one when
        // the rate's sign differs at its ends.
        Some(1) => {
            if turns(Term::plus(watched), at0, at1) {
                if let Some(tm) = poly.extremum(h) {
                    take(poly.value(tm));
                }
            }
        }
        _ => poly.every_extremum(&rate, (h, kit.mode.h), take),
    }
}
