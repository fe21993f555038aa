//! Relay timing as datasheets state it, from the strokes of a simulated
//! cycle and the instants the driver switched the coil on and off.
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
//! The coil counts as on while the voltage across it exceeds half the
//! largest it reaches: a driver that saturates puts nearly the supply
//! across it, and at turn-off the suppression makes it negative. Once the
//! suppression has let the current die, the coil rings with the circuit's
//! junction capacitances (tens of kHz, some volts): an "on" that carries
//! less than a tenth of the peak coil current is such ringing, not a
//! drive, and is dropped.

use serde::Serialize;

use crate::chatter::Chatter;
use crate::mechanics::cycle::Stroke;

/// The instants the coil was switched, in s.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Switching {
    /// Rising edges (0 when energised from the start).
    pub on: Vec<f64>,
    /// Falling edges.
    pub off: Vec<f64>,
}

impl Switching {
    /// The edges of the coil voltage `volts` sampled at `time`, the coil
    /// carrying `current`: crossings of half the largest voltage,
    /// interpolated, of the pulses that drive a current (see the module
    /// docs). Nothing when the coil never sees a positive voltage.
    pub fn from_coil(time: &[f64], volts: &[f64], current: &[f64]) -> Switching {
        let edges = Switching::from_voltage(time, volts);
        let peak = current.iter().copied().fold(0.0, f64::max);
        let mut out = Switching::default();
        for &on in &edges.on {
            let off = edges.off.iter().copied().find(|&t| t > on);
            let lo = time.partition_point(|&t| t < on);
            let hi = off.map_or(time.len(), |t| time.partition_point(|&s| s <= t));
            let drives = current[lo..hi.min(current.len())]
                .iter()
                .any(|&i| i >= 0.1 * peak);
            if drives && peak > 0.0 {
                out.on.push(on);
                if let Some(off) = off {
                    out.off.push(off);
                }
            }
        }
        out
    }

    /// The edges of the coil voltage alone: every crossing of half its
    /// largest value, interpolated.
    fn from_voltage(time: &[f64], volts: &[f64]) -> Switching {
        let peak = volts.iter().copied().fold(0.0, f64::max);
        let mut out = Switching::default();
        if peak <= 0.0 || time.is_empty() {
            return out;
        }
        let level = 0.5 * peak;
        let mut on = volts[0] > level;
        if on {
            out.on.push(time[0]);
        }
        for k in 1..time.len().min(volts.len()) {
            let now = volts[k] > level;
            if now != on {
                let (v0, v1) = (volts[k - 1], volts[k]);
                let frac = if v1 != v0 {
                    (level - v0) / (v1 - v0)
                } else {
                    1.0
                };
                let t = time[k - 1] + frac.clamp(0.0, 1.0) * (time[k] - time[k - 1]);
                if now {
                    out.on.push(t);
                } else {
                    out.off.push(t);
                }
                on = now;
            }
        }
        out
    }
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
    /// coil-on when there is one, else from t = 0.
    pub fn first(chatter: &Chatter, operations: &[Operation]) -> Closing {
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

/// Pair every stroke with the coil switching around it.
pub fn operations(strokes: &[Stroke], switching: &Switching) -> Vec<Operation> {
    strokes
        .iter()
        .enumerate()
        .map(|(k, stroke)| {
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
                stroke: stroke.clone(),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_coil_switches_where_its_voltage_crosses_half_its_peak() {
        let time = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0];
        // Off, on at 4.8 V, flyback to −0.7 V, on again.
        let volts = [0.0, 4.8, 4.8, -0.7, 4.8, 4.8];
        let s = Switching::from_voltage(&time, &volts);
        assert_eq!(s.on, vec![0.5, 3.0 + 3.1 / 5.5]);
        assert_eq!(s.off.len(), 1);
        assert!((s.off[0] - (2.0 + 2.4 / 5.5)).abs() < 1e-12);
        // Never energised: no edges.
        assert_eq!(
            Switching::from_voltage(&time, &[0.0; 6]),
            Switching::default()
        );
        // Energised from the start.
        assert_eq!(
            Switching::from_voltage(&[0.0, 1.0], &[5.0, 5.0]).on,
            vec![0.0]
        );
    }

    #[test]
    fn ringing_after_the_flyback_is_not_a_drive() {
        let time: Vec<f64> = (0..10).map(f64::from).collect();
        // A drive pulse 1..3, then ringing through ±5 V with no current.
        let volts = [0.0, 5.0, 5.0, -25.0, 5.5, -4.0, 5.0, -3.0, 0.0, 0.0];
        let current = [0.0, 0.02, 0.05, 0.01, 1e-5, -1e-5, 1e-5, 0.0, 0.0, 0.0];
        let s = Switching::from_coil(&time, &volts, &current);
        assert_eq!(s.on.len(), 1, "{s:?}");
        assert_eq!(s.off.len(), 1, "{s:?}");
        assert!(s.on[0] < 1.0 && s.off[0] > 2.0 && s.off[0] < 3.0, "{s:?}");
        // The voltage alone sees three pulses.
        assert_eq!(Switching::from_voltage(&time, &volts).on.len(), 3);
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
        let [op] = operations(std::slice::from_ref(&stroke), &switching)
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
        let op = &operations(&[stroke], &on_only)[0];
        assert_eq!(op.release_time, None);
        assert!(op.operate_time.is_some());
    }
}
