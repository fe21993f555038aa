//! The two-stage engine against the exact one-mass engine, and its own
//! properties.

use super::*;
use crate::chatter::Outcome;
use crate::mechanics::cycle::Stops;
use crate::mechanics::{Drive, Mechanics, Settings, Surface, simulate};

/// The reference sequence of docs/model.md (m = s = 1, ζ = 0.05, F = 1,
/// k0 = 0.9, β = 101, σ = 0.5192).
fn reference() -> (Mechanics, Surface, Settings) {
    let m = Mechanics {
        mass: 1.0,
        stiffness: 1.0,
        damping: 0.1,
        force: 1.0,
        gap: 0.9,
        initial_position: 0.0,
        initial_velocity: 0.0,
        preload: 0.0,
    };
    let s = Surface::KelvinVoigt {
        stiffness: 100.0,
        damping: 2.0 * (0.5192 - 0.05),
    };
    let settings = Settings {
        t_end: 60.0,
        ..Settings::default()
    };
    (m, s, settings)
}

#[test]
fn without_a_blade_it_is_the_exact_engine() {
    let (m, s, settings) = reference();
    let exact = simulate(&m, &s, &settings).unwrap();
    let stops = Stops {
        make: s,
        back: None,
    };
    let run = simulate_two_stage(
        &m,
        &TwoStage::default(),
        &stops,
        &settings,
        Drive::Step,
        Horizon::Closing,
    )
    .unwrap();
    let c = &run.contact;
    assert_eq!(c.outcome, Outcome::Stuck);
    assert_eq!(c.impacts.len(), exact.impacts.len());
    assert_eq!(c.bounce_count, exact.bounce_count);
    for (a, b) in c.impacts.iter().zip(&exact.impacts) {
        assert!((a.impact_time - b.impact_time).abs() < 1e-8, "{a:?} {b:?}");
        assert!((a.impact_velocity - b.impact_velocity).abs() < 1e-8);
        match (a.release_time, b.release_time) {
            (Some(x), Some(y)) => assert!((x - y).abs() < 1e-8, "{x} {y}"),
            (None, None) => {}
            other => panic!("{other:?}"),
        }
    }
    assert!((c.settle_time.unwrap() - exact.settle_time.unwrap()).abs() < 1e-8);
}
