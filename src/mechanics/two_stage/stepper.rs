//! The engine advanced a piece at a time, for a drive known only up to
//! the present: the lock-step coupling with ngspice
//! ([`crate::pipeline::lockstep`]) accepts a circuit time point, and only
//! then is the coil's pull known up to it.
//!
//! A [`Stepper`] is the engine's own propagation (the same event location,
//! stop modes and invariants as a whole run), stopped at the horizon of
//! each call and resumed from exactly where it stopped. A speculation
//! ([`Stepper::speculate`]) is a copy that runs ahead under an
//! extrapolated drive and is thrown away: the caller reads from it where
//! the armature will be and when the next event comes, and so plans the
//! circuit's next step.

use super::engine::{advance, describe};
use super::model::RelayModel;
use super::propagation::{Propagation, start};
use super::relay::validate_all;
use super::run::Horizon;
use super::span::state_at;
use crate::chatter::Interval;
use crate::mechanics::error::DriveError;
use crate::mechanics::forced::Forced;
use crate::mechanics::parameters::{Mechanics, Settings, Stops};
use crate::mechanics::two_stage::TwoStage;

/// The relay of a driven run, advanced by the caller.
pub(crate) struct Stepper<'a, F> {
    model: &'a RelayModel<'a, Forced<F>>,
    settings: Settings,
    p: Propagation,
    /// Keep the motion piece by piece (a speculation, read at any time
    /// of its span), or only the present state.
    keep: bool,
}

/// Runs `body` with a stepper of the relay `m` built as `build`, under
/// the force `force(t, x)` (N toward closing), from rest at t = 0 (the
/// driven cycle of [`super::driven_run`], one piece at a time).
pub(crate) fn with_stepper<F, R>(
    m: &Mechanics,
    build: &TwoStage,
    stops: &Stops,
    settings: &Settings,
    force: F,
    body: impl FnOnce(&mut Stepper<'_, F>) -> R,
) -> Result<R, DriveError>
where
    F: Fn(f64, f64) -> f64,
{
    validate_all(m, build, &stops.make, settings)?;
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
    let mut stepper = Stepper {
        model: &model,
        settings: *settings,
        p: start(&model, 0.0),
        keep: false,
    };
    Ok(body(&mut stepper))
}

impl<'a, F: Fn(f64, f64) -> f64> Stepper<'a, F> {
    /// s, how far the relay has been advanced.
    pub(crate) fn time(&self) -> f64 {
        self.p.t
    }

    /// Advances to `t` (nothing when already there): every event on the
    /// way is located and applied as in a whole run, and a broken
    /// invariant is an error.
    pub(crate) fn advance_to(&mut self, t: f64) -> Result<(), DriveError> {
        if t <= self.p.t {
            return Ok(());
        }
        if !self.keep {
            self.p.pieces.clear();
        }
        let settings = Settings {
            t_end: t,
            ..self.settings
        };
        advance(self.model, &settings, Horizon::Cycle, &mut self.p)?;
        if let Some((time, what)) = self.p.violation.clone() {
            return Err(DriveError::Impossible {
                time,
                what,
                relay: describe(self.model),
            });
        }
        Ok(())
    }

    /// A copy from the present state that keeps its motion piece by piece,
    /// to run ahead and be thrown away.
    pub(crate) fn speculate(&self) -> Stepper<'a, F> {
        Stepper {
            model: self.model,
            settings: self.settings,
            p: self.p.fork(),
            keep: true,
        }
    }

    /// m, the armature's position from its rest stop at `t` (the present
    /// state at or after the present; on a speculation, any time of its
    /// span).
    pub(crate) fn armature(&self, t: f64) -> f64 {
        let y = if t >= self.p.t || self.p.pieces.is_empty() {
            self.p.y
        } else {
            state_at(&self.p.pieces, t)
        };
        self.model.m.gap + y[0]
    }

    /// The normally-open contact's states so far.
    pub(crate) fn intervals(&self) -> &[Interval] {
        self.p.rec.intervals()
    }

    /// The rest stop's (the normally-closed contact's) states so far.
    pub(crate) fn back_intervals(&self) -> &[Interval] {
        self.p.rec.back_intervals()
    }

    /// s, the first event after `t` in the record: a contact or the rest
    /// stop changing state, an impact on or a release from the pole face.
    pub(crate) fn first_event_after(&self, t: f64) -> Option<f64> {
        self.p.rec.first_event_after(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mechanics::Surface;
    use crate::mechanics::two_stage::{Blade, driven_run};

    /// A relay with a blade pulled by a force that rises, holds and falls
    /// (a coil pulse): closing, bounces, release and the return onto the
    /// rest stop.
    fn relay() -> (Mechanics, TwoStage, Stops, Settings) {
        let m = Mechanics {
            mass: 2e-4,
            stiffness: 800.0,
            damping: 0.04,
            force: 0.0,
            gap: 4.5e-4,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.1,
        };
        let build = TwoStage {
            blade: Some(Blade {
                mass: 3e-5,
                stiffness: 3000.0,
                damping: 0.01,
            }),
            ..TwoStage::default()
        };
        let stops = Stops {
            make: Surface::KelvinVoigt {
                stiffness: 8e4,
                damping: 0.2,
            },
            back: Some(Surface::KelvinVoigt {
                stiffness: 5e4,
                damping: 0.2,
            }),
        };
        let settings = Settings {
            t_end: 0.03,
            ..Settings::default()
        };
        (m, build, stops, settings)
    }

    fn pull(t: f64, _x: f64) -> f64 {
        let rise = 1.0 - (-t / 2e-3).exp();
        if t < 0.012 {
            0.9 * rise
        } else {
            0.9 * (1.0 - (-0.012 / 2e-3_f64).exp()) * (-(t - 0.012) / 1e-3).exp()
        }
    }

    /// Advanced in uneven pieces, as ngspice's steps would, the stepper
    /// finds the events of the whole run to the integrator's precision.
    #[test]
    fn advancing_piece_by_piece_finds_the_whole_run_s_events() {
        let (m, build, stops, settings) = relay();
        let whole = driven_run(&m, &build, &stops, &settings, &pull).unwrap();
        let whole_changes: Vec<f64> = whole
            .chatter()
            .intervals
            .iter()
            .skip(1)
            .map(|iv| iv.start)
            .collect();
        assert!(whole_changes.len() >= 4, "{whole_changes:?}");
        let pieces = with_stepper(&m, &build, &stops, &settings, pull, |stepper| {
            // Steps from 0.1 µs to 40 µs, in a fixed irregular pattern.
            let mut t = 0.0;
            let mut k = 0u32;
            while t < settings.t_end {
                k = k.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                t = (t + 1e-7 + 4e-5 * f64::from(k % 1000) / 1000.0).min(settings.t_end);
                stepper.advance_to(t).unwrap();
                assert_eq!(stepper.time(), t);
            }
            stepper
                .intervals()
                .iter()
                .skip(1)
                .map(|iv| iv.start)
                .collect::<Vec<f64>>()
        })
        .unwrap();
        assert_eq!(
            pieces.len(),
            whole_changes.len(),
            "{pieces:?} vs {whole_changes:?}"
        );
        for (a, b) in pieces.iter().zip(&whole_changes) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
    }

    /// A speculation runs ahead and leaves the stepper where it was.
    #[test]
    fn a_speculation_leaves_the_stepper_alone() {
        let (m, build, stops, settings) = relay();
        with_stepper(&m, &build, &stops, &settings, pull, |stepper| {
            stepper.advance_to(2e-3).unwrap();
            let x = stepper.armature(2e-3);
            let mut plan = stepper.speculate();
            plan.advance_to(8e-3).unwrap();
            let first = plan.first_event_after(2e-3).expect("the contact makes");
            assert!(first > 2e-3 && first < 8e-3, "{first}");
            assert_eq!(stepper.time(), 2e-3);
            assert_eq!(stepper.armature(2e-3), x);
            // The stepper itself then finds the same event.
            stepper.advance_to(8e-3).unwrap();
            let found = stepper.first_event_after(2e-3).unwrap();
            assert!((found - first).abs() < 1e-12, "{found} vs {first}");
            assert_eq!(stepper.armature(8e-3), plan.armature(8e-3));
            assert_eq!(stepper.intervals(), plan.intervals());
        })
        .unwrap();
    }
}
