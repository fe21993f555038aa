//! The two-stage relay as its engines see it: the state vector, the
//! modes of its three stops, and the relay with its drive ([`RelayModel`]):
//! the forces on the armature and the blade, the equations of motion in
//! each mode and the event function of each stop.

use crate::mechanics::linalg::SVector;

use super::relay::{Release, TwoStage};
use crate::mechanics::driven::DriveModel;
use crate::mechanics::locate::Combine;
use crate::mechanics::parameters::Mechanics;
use crate::mechanics::surface::Surface;

/// `(u_a, v_a, u_b, v_b, e)`.
pub(crate) type Y = SVector<f64, 5>;

/// What holds a body at a stop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum StopMode {
    Open,
    Engaged,
    Pressed,
}

/// The three stops' modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct StopModes {
    pub(crate) contact: StopMode,
    pub(crate) pole: StopMode,
    pub(crate) rest: StopMode,
}

/// Which stop an event belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Which {
    Contact,
    Pole,
    Rest,
}

/// The model: parameters and the drive.
pub(crate) struct RelayModel<'a, D> {
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
pub(super) fn law(surface: &Surface, delta: f64, rate: f64) -> f64 {
    match *surface {
        Surface::KelvinVoigt { stiffness, damping } => stiffness * delta + damping * rate,
        Surface::HuntCrossley { .. } => surface.force(delta.max(0.0), rate),
        Surface::Rigid { .. } => 0.0,
    }
}

/// A linear form of the state, `c·y + d`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinearForm {
    pub c: [f64; 5],
    pub d: f64,
}

impl LinearForm {
    fn of(c: [f64; 5], d: f64) -> LinearForm {
        LinearForm { c, d }
    }

    fn negated(self) -> LinearForm {
        LinearForm {
            c: self.c.map(|x| -x),
            d: -self.d,
        }
    }
}

/// An event function as linear forms with the same signs: one, or the
/// larger or smaller of two.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinearGuard {
    pub combine: Combine,
    pub forms: [LinearForm; 2],
    pub count: usize,
}

impl LinearGuard {
    fn one(f: LinearForm) -> LinearGuard {
        LinearGuard {
            combine: Combine::One,
            forms: [f, f],
            count: 1,
        }
    }

    fn two(combine: Combine, a: LinearForm, b: LinearForm) -> LinearGuard {
        LinearGuard {
            combine,
            forms: [a, b],
            count: 2,
        }
    }
}

/// The linear form with the sign of [`push`] on the penetration form
/// `delta` (with its rate in component `rate`).
fn push_form(surface: &Surface, delta: LinearForm, rate: usize) -> LinearForm {
    let mut f = LinearForm::of([0.0; 5], 0.0);
    match *surface {
        Surface::KelvinVoigt { stiffness, damping } => {
            for i in 0..5 {
                f.c[i] = stiffness * delta.c[i];
            }
            f.d = stiffness * delta.d;
            f.c[rate] += damping;
        }
        Surface::HuntCrossley { chi, .. } => {
            f.d = 1.0;
            f.c[rate] = chi;
        }
        Surface::Rigid { .. } => f = delta,
    }
    f
}

impl<D: DriveModel> RelayModel<'_, D> {
    pub(super) fn g(&self) -> f64 {
        self.m.gap
    }

    pub(super) fn overtravel(&self) -> f64 {
        self.build.pole_face.map_or(f64::INFINITY, |p| p.overtravel)
    }

    pub(super) fn blade_force(&self, y: &Y) -> f64 {
        match &self.build.blade {
            Some(b) => b.stiffness * (y[0] - y[2]) + b.damping * (y[1] - y[3]),
            None => 0.0,
        }
    }

    fn contact_force(&self, y: &Y, modes: StopModes) -> f64 {
        if modes.contact == StopMode::Engaged {
            law(&self.contact, y[2], y[3])
        } else {
            0.0
        }
    }

    fn pole_force(&self, y: &Y, modes: StopModes) -> f64 {
        match (&self.build.pole_face, modes.pole) {
            (Some(p), StopMode::Engaged) => law(&p.surface, y[0] - p.overtravel, y[1]),
            _ => 0.0,
        }
    }

    fn rest_force(&self, y: &Y, modes: StopModes) -> f64 {
        match (&self.back, modes.rest) {
            (Some(b), StopMode::Engaged) => law(b, -(self.g() + y[0]), -y[1]),
            _ => 0.0,
        }
    }

    /// N, the force toward closing on the armature from everything but
    /// its stops' constraints (and, without a blade, the contact).
    pub(super) fn armature_push(&self, t: f64, y: &Y, modes: StopModes) -> f64 {
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

    fn armature_held(&self, modes: StopModes) -> bool {
        modes.pole == StopMode::Pressed
            || modes.rest == StopMode::Pressed
            || (self.build.blade.is_none() && modes.contact == StopMode::Pressed)
    }

    pub(crate) fn rate(&self, t: f64, y: &Y, modes: StopModes) -> Y {
        let x = self.g() + y[0];
        let held = self.armature_held(modes);
        let (ua, aa) = if held {
            (0.0, 0.0)
        } else {
            (y[1], self.armature_push(t, y, modes) / self.m.mass)
        };
        let (ub, ab) = match &self.build.blade {
            None => (ua, aa),
            Some(_) if modes.contact == StopMode::Pressed => (0.0, 0.0),
            Some(b) => (
                y[3],
                (self.blade_force(y) - self.contact_force(y, modes)) / b.mass,
            ),
        };
        Y::new(ua, aa, ub, ab, self.drive.rate(t, x, y[4]))
    }

    /// The event function of `which` in `modes`: positive while the mode
    /// lasts.
    pub(super) fn event(&self, which: Which, t: f64, y: &Y, modes: StopModes) -> f64 {
        let force_rule = |release: Release, s: &Surface| {
            release == Release::Force && !matches!(s, Surface::Rigid { .. })
        };
        match which {
            Which::Contact => {
                let s = &self.contact;
                let by_force = force_rule(self.build.release, s);
                match modes.contact {
                    StopMode::Open if by_force => (-y[2]).max(-push(s, y[2], y[3])),
                    StopMode::Open => -y[2],
                    StopMode::Engaged if by_force => y[2].min(push(s, y[2], y[3])),
                    StopMode::Engaged => y[2],
                    StopMode::Pressed => match self.build.blade {
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
                    StopMode::Open if by_force => (-delta).max(-push(&p.surface, delta, y[1])),
                    StopMode::Open => -delta,
                    StopMode::Engaged if by_force => delta.min(push(&p.surface, delta, y[1])),
                    StopMode::Engaged => delta,
                    StopMode::Pressed => self.armature_push(t, y, modes),
                }
            }
            Which::Rest => {
                if !self.rest {
                    return 1.0;
                }
                let x = self.g() + y[0];
                match modes.rest {
                    StopMode::Open => x,
                    StopMode::Engaged => -x,
                    StopMode::Pressed => -self.armature_push(t, y, modes),
                }
            }
        }
    }

    /// The event function of `which` in `modes` as linear forms of the
    /// state with its sign: `Some(None)` when the stop has no event,
    /// `None` when the function depends on the drive (a body pressed on
    /// a rigid stop, held there by the drive's force).
    pub(super) fn linear_guard(
        &self,
        which: Which,
        modes: StopModes,
    ) -> Option<Option<LinearGuard>> {
        let force_rule = |release: Release, s: &Surface| {
            release == Release::Force && !matches!(s, Surface::Rigid { .. })
        };
        let guard = |mode: StopMode, surface: &Surface, by_force: bool, delta: LinearForm, rate| {
            let push = push_form(surface, delta, rate);
            Some(Some(match mode {
                StopMode::Open if by_force => {
                    LinearGuard::two(Combine::Max, delta.negated(), push.negated())
                }
                StopMode::Open => LinearGuard::one(delta.negated()),
                StopMode::Engaged if by_force => LinearGuard::two(Combine::Min, delta, push),
                StopMode::Engaged => LinearGuard::one(delta),
                StopMode::Pressed => return None,
            }))
        };
        match which {
            Which::Contact => {
                let s = &self.contact;
                if modes.contact == StopMode::Pressed {
                    let b = self.build.blade?;
                    return Some(Some(LinearGuard::one(LinearForm::of(
                        [b.stiffness, b.damping, -b.stiffness, -b.damping, 0.0],
                        0.0,
                    ))));
                }
                let delta = LinearForm::of([0.0, 0.0, 1.0, 0.0, 0.0], 0.0);
                guard(
                    modes.contact,
                    s,
                    force_rule(self.build.release, s),
                    delta,
                    3,
                )
            }
            Which::Pole => {
                let Some(p) = &self.build.pole_face else {
                    return Some(None);
                };
                let delta = LinearForm::of([1.0, 0.0, 0.0, 0.0, 0.0], -p.overtravel);
                guard(
                    modes.pole,
                    &p.surface,
                    force_rule(p.release, &p.surface),
                    delta,
                    1,
                )
            }
            Which::Rest => {
                if !self.rest {
                    return Some(None);
                }
                let x = LinearForm::of([1.0, 0.0, 0.0, 0.0, 0.0], self.g());
                match modes.rest {
                    StopMode::Open => Some(Some(LinearGuard::one(x))),
                    StopMode::Engaged => Some(Some(LinearGuard::one(x.negated()))),
                    StopMode::Pressed => None,
                }
            }
        }
    }

    /// The acceleration of `which`'s body toward its stop in `modes` (the
    /// stop open), m/s².
    pub(super) fn toward(&self, which: Which, t: f64, y: &Y, modes: StopModes) -> f64 {
        let r = self.rate(t, y, modes);
        match which {
            Which::Contact => r[3],
            Which::Pole => r[1],
            Which::Rest => -r[1],
        }
    }
}
