//! Relay timing as datasheets state it, from the strokes of a simulated
//! cycle and the instants the driver energised and de-energised the coil.
//!
//! - **operate time**: coil on → the NO contact's first make (bounce
//!   excluded, as IEC 61810-1 defines it); `first_make_time` is the same
//!   figure under its older name;
//! - **bounce time**: first make → last make (closed for good);
//! - **settle time**: coil on → closed for good, operate plus bounce;
//! - **release time**: coil off → the NO contact breaks for good;
//! - **NC make** and **NC bounce time**: coil off → the armature's first
//!   touch of its rest stop (the normally-closed contact), and from there
//!   to its last.
//!
//! # What an operation is
//!
//! An operation is what the relay did between an energisation of its coil
//! and the de-energisation after it. Both are read from the voltage across
//! the coil against the relay's own **drop-out level**: the coil voltage
//! whose steady current no longer holds the closed armature against its
//! springs and contact load (computed from the magnet and the load line,
//! [`crate::coil::pick_up::drop_out`], as the pick-up is). The coil is
//! energised when the drive rises above that level and de-energised when
//! it falls below it; a reversal through a flyback diode, a zener or a
//! snubber is below it.
//!
//! The decision has hysteresis in time and in level. In time: the drive
//! is the voltage as the coil's current sees it, low-passed over the
//! coil's time constant L/R (with the armature open, the shortest it
//! has): a supply dip shorter than the current's decay, the ringing of a
//! snubber that swings both ways, PWM holding at kHz and the ripple of a
//! rectified AC supply do not move it across the level, while a real
//! energisation or de-energisation does; an energisation also needs the
//! voltage itself above drop-out for [`HOLD_FRACTION`] of L/R without a
//! break. In level: it must rise above the drop-out level
//! by [`LEVEL_HYSTERESIS`] to count as energised and fall below it by as
//! much to count as de-energised. The instant reported is where the
//! voltage itself last crossed the drop-out level before that decision:
//! a ramped supply is energised where it crosses drop-out.
//!
//! A contact that closes again after its release while the coil is
//! de-energised (pulled in again by a snubber's ringing current, or an
//! armature that rebounds off its rest stop) is an operation of its own,
//! with its own bounces and figures, never more bounces of the closing
//! before it.

use serde::Serialize;

use crate::chatter::{Chatter, Impact};
use crate::mechanics::cycle::Stroke;

/// The instants the coil was energised and de-energised, in s.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Switching {
    /// Energisations (0 when energised from the start).
    pub on: Vec<f64>,
    /// De-energisations.
    pub off: Vec<f64>,
}

/// The fraction of the drop-out level by which the drive must rise above
/// it to count as energised, and fall below it to count as de-energised.
pub const LEVEL_HYSTERESIS: f64 = 0.1;

/// The fraction of the coil's L/R for which the voltage itself must have
/// stayed above drop-out to count as an energisation: the ringing of a
/// snubber, whose positive swings are shorter, never does.
pub const HOLD_FRACTION: f64 = 0.5;

/// The levels a coil's drive is read against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CoilLevels {
    /// V, the coil voltage whose steady current just holds the closed
    /// armature: below it the relay releases.
    pub drop_out_voltage: f64,
    /// V, the coil voltage whose steady current just pulls the armature
    /// in from rest (reported beside the drop-out level).
    pub pick_up_voltage: f64,
    /// s, the coil's L/R with the armature open: the time over which its
    /// current follows the drive.
    pub time_constant: f64,
}

impl Switching {
    /// The energisations and de-energisations of a coil whose terminal
    /// voltage is `volts` at `time`, read against `levels` (see the module
    /// overview). Nothing when the drive never rises above drop-out.
    pub fn from_coil(time: &[f64], volts: &[f64], levels: &CoilLevels) -> Switching {
        let n = time.len().min(volts.len());
        let mut out = Switching::default();
        let level = levels.drop_out_voltage;
        if n == 0 || level.is_nan() || level <= 0.0 {
            return out;
        }
        let (on_level, off_level) = (
            level * (1.0 + LEVEL_HYSTERESIS),
            level * (1.0 - LEVEL_HYSTERESIS),
        );
        let tau = levels.time_constant.max(0.0);
        let mut drive = volts[0];
        let mut on = drive > on_level;
        if on {
            out.on.push(time[0]);
        }
        // Since when the voltage itself has been above drop-out.
        let mut above_since = (volts[0] > level).then_some(time[0]);
        for k in 1..n {
            if volts[k] <= level {
                above_since = None;
            } else if above_since.is_none() {
                above_since = Some(time[k]);
            }
            let dt = time[k] - time[k - 1];
            let mean = 0.5 * (volts[k - 1] + volts[k]);
            let weight = if tau > 0.0 {
                1.0 - (-dt / tau).exp()
            } else {
                1.0
            };
            drive += weight * (mean - drive);
            let held = above_since.is_some_and(|t| time[k] - t >= HOLD_FRACTION * tau);
            if !on && drive > on_level && held {
                on = true;
                out.on
                    .push(last_crossing(&time[..=k], &volts[..=k], level, true));
            } else if on && drive < off_level {
                on = false;
                out.off
                    .push(last_crossing(&time[..=k], &volts[..=k], level, false));
            }
        }
        out
    }
}

/// s, where `volts` last crossed `level` rising (or falling) up to the end
/// of `time`, interpolated; the last sample when it never did.
fn last_crossing(time: &[f64], volts: &[f64], level: f64, rising: bool) -> f64 {
    for k in (1..time.len()).rev() {
        let (v0, v1) = (volts[k - 1], volts[k]);
        let crosses = if rising {
            v0 <= level && v1 > level
        } else {
            v0 >= level && v1 < level
        };
        if crosses {
            let frac = (level - v0) / (v1 - v0);
            return time[k - 1] + frac.clamp(0.0, 1.0) * (time[k] - time[k - 1]);
        }
    }
    time[time.len() - 1]
}

/// One operation of the relay: a stroke and the switching that made it.
/// Durations are `None` when an instant they need did not happen within
/// the run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Operation {
    /// s, the coil switched on before this stroke.
    pub coil_on: Option<f64>,
    /// s, the coil switched off after it closed.
    pub coil_off: Option<f64>,
    /// The stroke itself: its instants (s, from the run's t = 0) and
    /// bounce counts, flattened into the operation when serialized.
    #[serde(flatten)]
    pub stroke: Stroke,
    /// s, coil on → first make: the operate time.
    pub operate_time: Option<f64>,
    /// s, the same as `operate_time` (its older name).
    pub first_make_time: Option<f64>,
    /// s, first make → last make.
    pub bounce_time: Option<f64>,
    /// s, coil on → last make (closed for good).
    pub settle_time: Option<f64>,
    /// s, coil off → the NO contact's break.
    pub release_time: Option<f64>,
    /// s, coil off → the first touch of the rest stop (NC make).
    pub nc_make_time: Option<f64>,
    /// s, first → last touch of the rest stop.
    pub nc_bounce_time: Option<f64>,
    /// s, for a contact that closed again after its release with the coil
    /// de-energised (a re-pull, an armature rebound): the time from that
    /// release to this operation's first make. `None` for an operation
    /// the coil drove.
    pub recloses_after: Option<f64>,
}

impl Operation {
    /// How this operation's closing ended: never made; closed for good
    /// (stuck) when it stayed closed from its last make until the coil
    /// went off or it broke; otherwise what the run as a whole says
    /// (`whole`, e.g. still bouncing at the end of the run).
    pub fn outcome(&self, whole: crate::chatter::Outcome) -> crate::chatter::Outcome {
        use crate::chatter::Outcome;
        match (self.stroke.first_make, self.stroke.last_make) {
            (None, _) => Outcome::NeverCloses,
            (Some(_), Some(_)) if self.coil_off.is_some() || self.stroke.break_time.is_some() => {
                Outcome::Stuck
            }
            _ => whole,
        }
    }

    /// Whether this operation is a re-closure with the coil de-energised,
    /// not an energisation.
    pub fn is_reclosure(&self) -> bool {
        self.recloses_after.is_some()
    }

    /// The warning a re-closure carries: `the contact closes again 0.86 ms
    /// after its release, with the coil de-energised (...)`.
    pub fn reclosure_warning(&self) -> Option<String> {
        let after = self.recloses_after?;
        Some(format!(
            "the contact closes again {:.3} ms after its release, with the coil de-energised \
             (at {:.3} ms: a re-pull by the driver's ringing, or the armature rebounding), with \
             {} bounce{}: reported as an operation of its own",
            after * 1e3,
            self.stroke.first_make.unwrap_or(f64::NAN) * 1e3,
            self.stroke.bounces,
            if self.stroke.bounces == 1 { "" } else { "s" }
        ))
    }
}

/// A closing's times as datasheets define them, from t = 0 of the
/// operation: the moment the coil was energized or, without a coil, the
/// force step (t = 0 of the simulation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Closing {
    /// s, the operation's t = 0 in simulation time.
    pub origin: f64,
    /// s, t = 0 → first make (bounce excluded).
    pub operate_time: Option<f64>,
    /// s, first make → closed for good.
    pub bounce_time: Option<f64>,
    /// s, t = 0 → closed for good.
    pub settle_time: Option<f64>,
}

impl Closing {
    /// The first closing of `chatter`, timed from the first operation's
    /// coil-on when there is one (its closing, which ends when the coil
    /// goes off), else from t = 0.
    pub fn first(chatter: &Chatter, operations: &[Operation]) -> Closing {
        if let Some(op) = operations.first().filter(|op| op.coil_on.is_some()) {
            return Closing {
                origin: op.coil_on.unwrap_or(0.0),
                operate_time: op.operate_time,
                bounce_time: op.bounce_time,
                settle_time: op.settle_time,
            };
        }
        let origin = operations.first().and_then(|op| op.coil_on).unwrap_or(0.0);
        Closing {
            origin,
            operate_time: chatter.first_impact.map(|t| t - origin),
            bounce_time: chatter
                .first_impact
                .zip(chatter.settle_time)
                .map(|(first, settle)| settle - first),
            settle_time: chatter.settle_time.map(|t| t - origin),
        }
    }

    /// Every closing: one per operation of a coil-driven relay (each from
    /// its own coil-on), or the chatter's one from t = 0.
    pub fn all(chatter: &Chatter, operations: &[Operation]) -> Vec<Closing> {
        if operations.is_empty() {
            return vec![Closing::first(chatter, operations)];
        }
        operations
            .iter()
            .map(|op| Closing {
                origin: op.coil_on.unwrap_or(op.stroke.lift_off),
                operate_time: op.operate_time,
                bounce_time: op.bounce_time,
                settle_time: op.settle_time,
            })
            .collect()
    }
}

/// Pair every stroke with the coil switching around it, and split off
/// each re-closure: a make, after the coil went off and the contact
/// released, that comes before the armature is back on its rest stop and
/// before the coil is energised again. `make` are the NO contact's impacts
/// of the run, in order.
pub fn operations(strokes: &[Stroke], make: &[Impact], switching: &Switching) -> Vec<Operation> {
    let mut out = Vec::with_capacity(strokes.len());
    for (k, stroke) in strokes.iter().enumerate() {
        let next = strokes.get(k + 1).map_or(f64::INFINITY, |s| s.lift_off);
        // Lift-off may only lag the switch-on, by the flux build-up.
        let coil_on = switching
            .on
            .iter()
            .copied()
            .rev()
            .find(|&t| t <= stroke.lift_off);
        let from = coil_on.unwrap_or(stroke.lift_off);
        let coil_off = switching
            .off
            .iter()
            .copied()
            .find(|&t| t >= from && t < next);
        let next_on = switching
            .on
            .iter()
            .copied()
            .find(|&t| t > from)
            .unwrap_or(f64::INFINITY);
        match coil_off.and_then(|off| released(stroke, make, off, next.min(next_on))) {
            Some((before, Some((after, gap)))) => {
                out.push(operation(before, coil_on, coil_off, None));
                out.push(operation(after, None, None, Some(gap)));
            }
            Some((before, None)) => out.push(operation(before, coil_on, coil_off, None)),
            None => out.push(operation(stroke.clone(), coil_on, coil_off, None)),
        }
    }
    out
}

/// `stroke` read from its release after the coil went off at `off`: the
/// closing up to that release (closed for good from the make it released
/// from, whether or not the armature is back on its rest stop within the
/// run) and, when a make follows before `until`, the re-closure from that
/// make on with the time between the two. `None` when the contact never
/// released after `off`.
fn released(
    stroke: &Stroke,
    make: &[Impact],
    off: f64,
    until: f64,
) -> Option<(Stroke, Option<(Stroke, f64)>)> {
    let within: Vec<&Impact> = make
        .iter()
        .filter(|i| i.impact_time >= stroke.lift_off && i.impact_time < until)
        .collect();
    // The closure the coil-off found closed (or the first one after it)
    // and its release: the break.
    let breaking = within
        .iter()
        .position(|i| i.release_time.is_some_and(|r| r >= off))?;
    let release = within[breaking].release_time?;
    let first = &within[..=breaking];
    let rest = &within[breaking + 1..];
    let closing = Stroke {
        lift_off: stroke.lift_off,
        first_make: first.first().map(|i| i.impact_time),
        last_make: first.last().map(|i| i.impact_time),
        bounces: first.len().saturating_sub(1),
        break_time: Some(release),
        ..stroke.clone()
    };
    let Some(again) = rest.first() else {
        return Some((closing, None));
    };
    let before = Stroke {
        back_make: None,
        back_last_make: None,
        back_bounces: 0,
        ..closing
    };
    let after = Stroke {
        // The flight that ended in the re-closure starts at the release.
        lift_off: release,
        first_make: Some(again.impact_time),
        last_make: if stroke.last_make.is_some() {
            rest.last().map(|i| i.impact_time)
        } else {
            None
        },
        bounces: rest.len().saturating_sub(1),
        ..stroke.clone()
    };
    Some((before, Some((after, again.impact_time - release))))
}

/// One operation of `stroke`, timed from its switching.
fn operation(
    stroke: Stroke,
    coil_on: Option<f64>,
    coil_off: Option<f64>,
    recloses_after: Option<f64>,
) -> Operation {
    let since = |a: Option<f64>, b: Option<f64>| Some(b? - a?);
    Operation {
        coil_on,
        coil_off,
        operate_time: since(coil_on, stroke.first_make),
        first_make_time: since(coil_on, stroke.first_make),
        bounce_time: stroke.bounce_time(),
        settle_time: since(coil_on, stroke.last_make),
        release_time: since(coil_off, stroke.break_time),
        nc_make_time: since(coil_off, stroke.back_make),
        nc_bounce_time: stroke.back_bounce_time(),
        recloses_after,
        stroke,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference relay's levels: drop-out 1 V, τ = 5 ms.
    const LEVELS: CoilLevels = CoilLevels {
        drop_out_voltage: 1.0,
        pick_up_voltage: 3.0,
        time_constant: 5e-3,
    };

    /// `f` sampled every 10 µs over 60 ms.
    fn sampled(f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>) {
        let time: Vec<f64> = (0..6000).map(|k| k as f64 * 10e-6).collect();
        let volts = time.iter().map(|&t| f(t)).collect();
        (time, volts)
    }

    fn near(a: f64, b: f64) -> bool {
        (a - b).abs() < 20e-6
    }

    #[test]
    fn a_drive_pulse_is_one_operation_from_edge_to_edge() {
        // 5 V from 1 ms to 30 ms, then a diode's −0.7 V and 0.
        let (t, v) = sampled(|t| match t {
            t if t < 1e-3 => 0.0,
            t if t < 30e-3 => 5.0,
            t if t < 32e-3 => -0.7,
            _ => 0.0,
        });
        let s = Switching::from_coil(&t, &v, &LEVELS);
        assert_eq!((s.on.len(), s.off.len()), (1, 1), "{s:?}");
        assert!(near(s.on[0], 1e-3) && near(s.off[0], 30e-3), "{s:?}");
    }

    #[test]
    fn a_dip_that_holds_is_no_de_energisation_and_a_brown_out_is() {
        let dip = |low: f64| {
            move |t: f64| match t {
                t if t < 0.1e-3 => 0.0,
                t if (12e-3..14e-3).contains(&t) => low,
                t if t < 30e-3 => 5.0,
                _ => -0.7,
            }
        };
        let (t, v) = sampled(dip(1.5));
        let s = Switching::from_coil(&t, &v, &LEVELS);
        assert_eq!((s.on.len(), s.off.len()), (1, 1), "{s:?}");
        assert!(near(s.off[0], 30e-3), "{s:?}");
        // To 0.2 V for 15 ms: the current decays below drop-out (in some
        // 10 ms, with τ = 5 ms from 5 V): released, and energised again.
        let brown_out = |t: f64| match t {
            t if t < 0.1e-3 => 0.0,
            t if (12e-3..27e-3).contains(&t) => 0.2,
            t if t < 40e-3 => 5.0,
            _ => -0.7,
        };
        let (t, v) = sampled(brown_out);
        let s = Switching::from_coil(&t, &v, &LEVELS);
        assert_eq!((s.on.len(), s.off.len()), (2, 2), "{s:?}");
        assert!(near(s.off[0], 12e-3) && near(s.on[1], 27e-3), "{s:?}");
        assert!(near(s.off[1], 40e-3), "{s:?}");
    }

    #[test]
    fn ringing_pwm_ripple_and_ramps_read_as_the_drive_they_are() {
        // A snubber's ringing after turn-off at 20 ms: −60 V, then ±24 V
        // decaying, period 2.5 ms. One operation.
        let (t, v) = sampled(|t| match t {
            t if t < 1e-3 => 0.0,
            t if t < 20e-3 => 5.0,
            t => {
                let x = t - 20e-3;
                -60.0 * (-x / 4e-3).exp() * (2.0 * std::f64::consts::PI * x / 2.5e-3).cos()
            }
        });
        let s = Switching::from_coil(&t, &v, &LEVELS);
        assert_eq!((s.on.len(), s.off.len()), (1, 1), "snubber: {s:?}");
        assert!(near(s.off[0], 20e-3), "{s:?}");
        // Full voltage for 10 ms, then PWM at 5 kHz, 50 %: one operation.
        let (t, v) = sampled(|t| match t {
            t if t < 1e-3 => 0.0,
            t if t < 11e-3 => 5.0,
            t if t < 40e-3 && (t * 5e3).fract() < 0.5 => 5.0,
            _ => 0.0,
        });
        let s = Switching::from_coil(&t, &v, &LEVELS);
        assert_eq!((s.on.len(), s.off.len()), (1, 1), "PWM: {s:?}");
        // A bridge-rectified 50 Hz supply, 7 V peak, from 5 ms to 45 ms.
        let (t, v) = sampled(|t| {
            if (5e-3..45e-3).contains(&t) {
                (7.0 * (2.0 * std::f64::consts::PI * 50.0 * t).sin()).abs()
            } else {
                0.0
            }
        });
        let s = Switching::from_coil(&t, &v, &LEVELS);
        assert_eq!((s.on.len(), s.off.len()), (1, 1), "rectified AC: {s:?}");
        // A supply ramped 0 → 5 V over 20 ms: energised where it crosses
        // the drop-out level, 4 ms.
        let (t, v) = sampled(|t| (t / 20e-3).min(1.0) * 5.0);
        let s = Switching::from_coil(&t, &v, &LEVELS);
        assert_eq!(s.on.len(), 1, "{s:?}");
        assert!(near(s.on[0], 4e-3), "{s:?}");
        // Never above drop-out: nothing.
        let (t, v) = sampled(|_| 0.8);
        assert_eq!(Switching::from_coil(&t, &v, &LEVELS), Switching::default());
    }

    fn impact(at: f64, release: Option<f64>) -> Impact {
        Impact {
            release_time: release,
            ..Impact::touch(at, 0.1)
        }
    }

    #[test]
    fn a_re_closure_after_the_release_is_an_operation_of_its_own() {
        // Makes at 4 ms with 2 bounces, closed for good from 5 ms; coil
        // off at 20 ms, break at 21 ms; pulled in again at 21.86 ms with
        // one bounce; back on the rest stop at 30 ms.
        let make = vec![
            impact(4e-3, Some(4.3e-3)),
            impact(4.6e-3, Some(4.8e-3)),
            impact(5e-3, Some(21e-3)),
            impact(21.86e-3, Some(22e-3)),
            impact(22.3e-3, Some(25e-3)),
        ];
        let stroke = Stroke {
            lift_off: 1.5e-3,
            first_make: Some(4e-3),
            last_make: Some(22.3e-3),
            bounces: 4,
            break_time: Some(25e-3),
            back_make: Some(30e-3),
            back_last_make: Some(30e-3),
            back_bounces: 0,
        };
        let switching = Switching {
            on: vec![0.1e-3],
            off: vec![20e-3],
        };
        let ops = operations(&[stroke], &make, &switching);
        assert_eq!(ops.len(), 2, "{ops:#?}");
        let (closing, again) = (&ops[0], &ops[1]);
        assert_eq!(closing.stroke.bounces, 2);
        assert_eq!(closing.stroke.break_time, Some(21e-3));
        assert!((closing.release_time.unwrap() - 1e-3).abs() < 1e-12);
        assert!(!closing.is_reclosure());
        assert!(again.is_reclosure());
        assert_eq!(again.stroke.bounces, 1);
        assert_eq!(again.coil_on, None);
        assert_eq!(again.stroke.first_make, Some(21.86e-3));
        assert!((again.recloses_after.unwrap() - 0.86e-3).abs() < 1e-12);
        let warning = again.reclosure_warning().unwrap();
        assert!(
            warning.contains("closes again 0.860 ms after its release"),
            "{warning}"
        );
        // Without a make after the break: one operation.
        let ops = operations(&[ops[0].stroke.clone()], &make[..3], &switching);
        assert_eq!(ops.len(), 1);
    }

    #[test]
    fn durations_run_from_the_switching_that_caused_them() {
        let stroke = Stroke {
            lift_off: 1.5e-3,
            first_make: Some(4e-3),
            last_make: Some(5e-3),
            bounces: 3,
            break_time: Some(21e-3),
            back_make: Some(23e-3),
            back_last_make: Some(26e-3),
            back_bounces: 2,
        };
        let switching = Switching {
            on: vec![0.1e-3],
            off: vec![20e-3],
        };
        let [op] = operations(std::slice::from_ref(&stroke), &[], &switching)
            .try_into()
            .unwrap();
        let close = |a: Option<f64>, b: f64| (a.unwrap() - b).abs() < 1e-15;
        assert!(close(op.operate_time, 3.9e-3));
        assert!(close(op.first_make_time, 3.9e-3));
        assert!(close(op.settle_time, 4.9e-3));
        assert!(close(op.bounce_time, 1e-3));
        assert!(close(op.release_time, 1e-3));
        assert!(close(op.nc_make_time, 3e-3));
        assert!(close(op.nc_bounce_time, 3e-3));
        // Not switched off within the run: no release.
        let on_only = Switching {
            on: vec![0.1e-3],
            off: vec![],
        };
        let op = &operations(&[stroke], &[], &on_only)[0];
        assert_eq!(op.release_time, None);
        assert!(op.operate_time.is_some());
    }
}
