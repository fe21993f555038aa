//! The mechanics under a drive force that varies in time and position.
//!
//! This is the mechanical half of the waveform-relaxation coupling with
//! ngspice: the circuit gives the coil current `i(t)`, the coil turns it
//! into its pull `F_m(i(t), x)`, and this integrates the armature under
//! it, with the same events, surface laws and endings as the step-force
//! engine, by the one integrated engine ([`super::cycle`]: the whole
//! cycle, or one closing stopped at its ending). With a constant force it
//! reproduces [`super::engine::simulate`].

use super::cycle::{self, Cycle};
use super::driven::DriveModel;
use super::error::DriveError;
use super::parameters::{self, Mechanics, Settings, Stops};
use super::segment::{Segment, path_of};
use super::surface::Surface;
use crate::chatter::Chatter;

/// Simulate one closing under `force(t, x)` (s, m → N, toward closing),
/// which replaces `mechanics.force`; the preload still holds the armature
/// on its rest stop at x = 0 until the force beats it.
///
/// The force must be finite and should be smooth between the instants the
/// caller knows of: the integrator samples it adaptively. A contact is
/// declared stuck on the understanding that the drive does not weaken
/// afterwards (a closing drive); at `t_end` the force is frozen at its last
/// value to tell whether the sequence would go on (`end_of_time`) or has
/// ended open. `mechanics.initial_position` must lie in `[0, gap)`: the
/// rest stop is at 0.
pub fn simulate_forced(
    mechanics: &Mechanics,
    surface: &Surface,
    settings: &Settings,
    force: impl Fn(f64, f64) -> f64,
) -> Result<Chatter, DriveError> {
    simulate_forced_path(mechanics, surface, settings, force).map(|(chatter, _)| chatter)
}

/// [`simulate_forced`], with the armature's path: (s, m) at every
/// accepted integration step and event, from t = 0 to where the run
/// stopped (the sticking decision, or `t_end`), strictly increasing in
/// time.
pub fn simulate_forced_path(
    mechanics: &Mechanics,
    surface: &Surface,
    settings: &Settings,
    force: impl Fn(f64, f64) -> f64,
) -> Result<(Chatter, Vec<(f64, f64)>), DriveError> {
    validate(mechanics, &[surface], settings)?;
    let drive = Forced::new(mechanics, force);
    let run = cycle::run_closing(mechanics, surface, settings, &drive, 0.0)?;
    let gap = mechanics.gap;
    let path = match run.steps.first().and_then(Segment::piece) {
        Some(first) => path_of((first.t0(), gap + first.y0()[0]), &run.steps, gap),
        None => Vec::new(),
    };
    Ok((run.chatter, path))
}

/// The whole cycle under `force(t, x)` (s, m → N, toward closing): the
/// closing, the contact held, its release when the force falls, and the
/// armature's return onto its rest stop (`stops.back`, the normally-closed
/// contact), for every pulse of the force up to `settings.t_end`. See
/// [`super::cycle`]. Unlike [`simulate_forced`], nothing is assumed of
/// the force after the contact sticks.
pub fn simulate_cycle(
    mechanics: &Mechanics,
    stops: &Stops,
    settings: &Settings,
    force: impl Fn(f64, f64) -> f64,
) -> Result<Cycle, DriveError> {
    let surfaces: Vec<&Surface> = std::iter::once(&stops.make).chain(&stops.back).collect();
    validate(mechanics, &surfaces, settings)?;
    let drive = Forced::new(mechanics, force);
    cycle::run_cycle(mechanics, stops, settings, &drive, 0.0)
}

/// The engine's checks of the relay (its `force` unused: the drive
/// replaces it) and of every surface, and a start on or above the rest
/// stop.
fn validate(
    mechanics: &Mechanics,
    surfaces: &[&Surface],
    settings: &Settings,
) -> Result<(), DriveError> {
    let unforced = Mechanics {
        force: 0.0,
        ..*mechanics
    };
    for surface in surfaces {
        parameters::validate(&unforced, surface, settings)?;
    }
    if mechanics.initial_position < 0.0 {
        return Err(DriveError::InvalidParameter {
            name: "mechanics.initial_position",
            value: mechanics.initial_position,
            requirement: "a position in m at or above the rest stop at 0 (and below the gap)",
        });
    }
    Ok(())
}

/// A drive given as a function. Its state `e` is the impulse `∫F dt`:
/// integrating it makes the step-size control follow the force while the
/// armature is held and nothing else moves.
pub(crate) struct Forced<F> {
    force: F,
    impulse_scale: f64,
    time_scale: f64,
}

/// Gauss–Legendre nodes and weights on [−1, 1], 3 points: exact for a
/// force polynomial of degree 5 in x over a penetration of a few µm.
const GL3: [(f64, f64); 3] = [
    (-0.774_596_669_241_483_4, 5.0 / 9.0),
    (0.0, 8.0 / 9.0),
    (0.774_596_669_241_483_4, 5.0 / 9.0),
];

impl<F: Fn(f64, f64) -> f64> Forced<F> {
    pub(crate) fn new(mechanics: &Mechanics, force: F) -> Self {
        let scale = [
            mechanics.preload,
            mechanics.stiffness * mechanics.gap,
            force(0.0, mechanics.initial_position).abs(),
        ]
        .into_iter()
        .fold(0.0, f64::max);
        let time_scale = (mechanics.mass / mechanics.stiffness).sqrt();
        Forced {
            force,
            // The impulse ∫F dt over the suspension's time scale.
            impulse_scale: scale * time_scale,
            time_scale,
        }
    }
}

impl<F: Fn(f64, f64) -> f64> DriveModel for Forced<F> {
    fn force(&self, t: f64, x: f64, _e: f64) -> f64 {
        (self.force)(t, x)
    }

    fn rate(&self, t: f64, x: f64, _e: f64) -> f64 {
        (self.force)(t, x)
    }

    fn frozen_work(&self, t: f64, _e: f64, from: f64, to: f64) -> f64 {
        let (mid, half) = (0.5 * (from + to), 0.5 * (to - from));
        half * GL3
            .iter()
            .map(|&(z, w)| w * (self.force)(t, mid + half * z))
            .sum::<f64>()
    }

    fn e_scale(&self) -> f64 {
        self.impulse_scale
    }

    fn time_scale(&self) -> f64 {
        self.time_scale
    }

    fn pole(&self) -> f64 {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::chatter::Outcome;

    fn relay() -> Mechanics {
        Mechanics {
            mass: 1.0,
            stiffness: 1.0,
            damping: 0.1,
            force: 1.0,
            gap: 0.9,
            initial_position: 0.0,
            initial_velocity: 0.0,
            preload: 0.0,
        }
    }

    #[test]
    fn a_drive_below_the_preload_never_lifts() {
        let m = Mechanics {
            preload: 2.0,
            ..relay()
        };
        let s = Surface::Rigid { restitution: 0.5 };
        let settings = Settings {
            t_end: 10.0,
            ..Settings::default()
        };
        let c = simulate_forced(&m, &s, &settings, |_, _| 1.0).unwrap();
        assert_eq!(c.outcome, Outcome::NeverCloses);
        assert_eq!(c.shortfall, Some(0.9));
    }

    #[test]
    fn a_late_drive_lifts_where_it_beats_the_preload() {
        // The force ramps from 0 to 1.5 N over [3, 3.001] s: it beats the
        // 0.5 N preload at 3 + 1e-3/3, between whatever steps the held
        // phase took; the flight then runs as from t = 0 under a step,
        // shifted by that time, up to the last 2/3 ms of the ramp.
        let m = Mechanics {
            preload: 0.5,
            ..relay()
        };
        let s = Surface::KelvinVoigt {
            stiffness: 100.0,
            damping: 0.5,
        };
        let settings = Settings {
            t_end: 20.0,
            ..Settings::default()
        };
        let ramp = |t: f64, _x: f64| 1.5 * ((t - 3.0) / 1e-3).clamp(0.0, 1.0);
        let late = simulate_forced(&m, &s, &settings, ramp).unwrap();
        let now = simulate_forced(&m, &s, &settings, |_, _| 1.5).unwrap();
        let shift = late.impacts[0].impact_time - now.impacts[0].impact_time;
        assert!(shift > 3.0 + 1e-3 / 3.0 && shift < 3.001, "{shift}");
    }

    #[test]
    fn a_closing_that_lands_and_lifts_again_starts_afresh() {
        // A rigid contact (e = 0.5) touched once under a short pulse: it
        // rebounds, the pulse ends, the armature lands on its rest stop.
        // A second pulse at 20 s lifts it again. With `min_open_time`
        // longer than the whole run, the touch after the landing must not
        // be judged against the first release (that would end the closing
        // as resolved at the first touch); the closing resolves after the
        // second touch, its first rebound being too short.
        let m = Mechanics {
            preload: 0.5,
            ..relay()
        };
        let s = Surface::Rigid { restitution: 0.5 };
        let settings = Settings {
            t_end: 60.0,
            min_open_time: 100.0,
            ..Settings::default()
        };
        let steady = simulate_forced(&m, &s, &settings, |_, _| 1.5).unwrap();
        let t1 = steady.impacts[0].impact_time;
        let (off, on) = (t1 + 0.05, 20.0);
        let pulses = move |t: f64, _x: f64| if t < off || t >= on { 1.5 } else { 0.0 };
        let c = simulate_forced(&m, &s, &settings, pulses).unwrap();
        assert_eq!(c.outcome, Outcome::Resolved);
        assert_eq!(c.impacts.len(), 2, "{:?}", c.impacts);
        assert!((c.impacts[0].impact_time - t1).abs() < 1e-9);
        // The second closing repeats the first, shifted by the pulse.
        let second = c.impacts[1].impact_time;
        assert!((second - (on + t1)).abs() < 1e-6, "{second}");
        assert_eq!(c.settle_time, Some(second));
        // The opening between the two reached the rest stop.
        assert_eq!(c.impacts[0].max_gap_after, Some(m.gap));
    }

    #[test]
    fn a_non_finite_drive_is_an_error() {
        let s = Surface::Rigid { restitution: 0.5 };
        let err = simulate_forced(&relay(), &s, &Settings::default(), |_, _| f64::NAN);
        assert!(
            matches!(err, Err(DriveError::DriveNotFinite { .. })),
            "{err:?}"
        );
    }
}
