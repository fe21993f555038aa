//! A seeded random sweep over valid relays and every surface law: the
//! engine never produces NaN, a negative interval, a non-increasing time
//! or an inconsistent summary, whatever the regime.

use chatterspice::{ContactState, Mechanics, Outcome, Settings, Surface, simulate};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    (lo.ln() + rng.random::<f64>() * (hi.ln() - lo.ln())).exp()
}

#[test]
fn random_relays_give_consistent_sequences() {
    let mut rng = ChaCha8Rng::seed_from_u64(0x5eed_c4a7);
    let mut outcomes = std::collections::BTreeMap::new();
    for case in 0..600 {
        let mass = log_uniform(&mut rng, 1e-5, 1e-2);
        let stiffness = log_uniform(&mut rng, 10.0, 1e5);
        let crit = 2.0 * (mass * stiffness).sqrt();
        // ζ from 0 to 3: under-, critically and over-damped.
        let zeta = if rng.random::<f64>() < 0.2 {
            0.0
        } else {
            3.0 * rng.random::<f64>()
        };
        let force = log_uniform(&mut rng, 1e-3, 10.0);
        let k0 = 0.05 + 2.2 * rng.random::<f64>();
        let gap = k0 * force / stiffness;
        let m = Mechanics {
            mass,
            stiffness,
            damping: zeta * crit,
            force,
            gap,
            initial_position: 0.0,
            initial_velocity: if rng.random::<f64>() < 0.2 {
                gap * (stiffness / mass).sqrt() * rng.random::<f64>()
            } else {
                0.0
            },
            preload: 0.0,
        };
        let surface = match case % 3 {
            0 => Surface::Rigid {
                restitution: rng.random::<f64>(),
            },
            1 => Surface::KelvinVoigt {
                stiffness: stiffness * log_uniform(&mut rng, 1.0, 1e4),
                damping: crit * log_uniform(&mut rng, 1e-3, 10.0),
            },
            _ => Surface::HuntCrossley {
                stiffness: stiffness * log_uniform(&mut rng, 10.0, 1e4) / gap.powf(0.5),
                exponent: if rng.random::<bool>() { 1.0 } else { 1.5 },
                chi: log_uniform(&mut rng, 1e-3, 10.0) / (gap * (stiffness / mass).sqrt()),
            },
        };
        let omega = (stiffness / mass).sqrt();
        let settings = Settings {
            t_end: 60.0 / omega,
            ..Settings::default()
        };
        let c = simulate(&m, &surface, &settings)
            .unwrap_or_else(|e| panic!("case {case}: {e} for {m:?} {surface:?}"));
        *outcomes.entry(c.outcome.as_str()).or_insert(0) += 1;
        let ctx = format!("case {case}: {m:?} {surface:?}");
        // Intervals tile [0, t_end] in order, alternate, never run backwards.
        assert!(!c.intervals.is_empty(), "{ctx}");
        assert_eq!(c.intervals[0].start, 0.0, "{ctx}");
        assert_eq!(c.intervals.last().unwrap().end, settings.t_end, "{ctx}");
        for w in c.intervals.windows(2) {
            assert_eq!(w[0].end, w[1].start, "{ctx}");
            assert_ne!(w[0].state, w[1].state, "{ctx}");
        }
        for i in &c.intervals {
            assert!(
                i.start.is_finite() && i.end.is_finite() && i.end >= i.start,
                "{ctx}: {i:?}"
            );
            if i.state == ContactState::Open && i.start > 0.0 && i.end < settings.t_end {
                assert!(i.end > i.start, "{ctx}: empty opening {i:?}");
            }
        }
        // Impacts in strictly increasing time, each after the last release.
        let mut t_prev = -1.0;
        for i in &c.impacts {
            assert!(i.impact_time > t_prev, "{ctx}");
            assert!(
                i.impact_velocity > 0.0 && i.impact_velocity.is_finite(),
                "{ctx}"
            );
            for v in [
                i.release_time,
                i.release_velocity,
                i.restitution,
                i.contact_time,
                i.peak_force,
                i.min_force,
                i.max_gap_after,
            ]
            .into_iter()
            .flatten()
            {
                assert!(v.is_finite(), "{ctx}: {i:?}");
            }
            if let Some(r) = i.release_time {
                assert!(r >= i.impact_time, "{ctx}");
                assert!(i.release_velocity.unwrap() <= 0.0, "{ctx}: {i:?}");
                t_prev = r;
            } else {
                t_prev = i.impact_time;
            }
        }
        match c.outcome {
            Outcome::NeverCloses => {
                assert!(c.impacts.is_empty() && c.shortfall.unwrap() >= 0.0, "{ctx}")
            }
            Outcome::Stuck | Outcome::Resolved => {
                assert_eq!(
                    c.intervals.last().unwrap().state,
                    ContactState::Closed,
                    "{ctx}"
                );
                assert!(c.settle_time.unwrap() >= c.first_impact.unwrap(), "{ctx}");
            }
            Outcome::EndsOpen => {
                assert_eq!(
                    c.intervals.last().unwrap().state,
                    ContactState::Open,
                    "{ctx}"
                )
            }
            Outcome::EndOfTime => assert!(c.settle_time.is_none(), "{ctx}"),
            Outcome::EventLimit => {
                assert!(c.settle_time.is_none(), "{ctx}");
                assert_eq!(
                    c.impacts.len(),
                    chatterspice::mechanics::MAX_EVENTS,
                    "{ctx}"
                );
            }
        }
        let openings = c
            .intervals
            .iter()
            .filter(|i| i.state == ContactState::Open)
            .count();
        assert_eq!(c.bounce_count, openings - 1, "{ctx}");
    }
    // The sweep really covers the endings, not one of them 600 times.
    for o in ["stuck", "never_closes", "ends_open", "resolved"] {
        assert!(outcomes.get(o).copied().unwrap_or(0) > 5, "{outcomes:?}");
    }
}
