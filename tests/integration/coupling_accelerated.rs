//! The accelerated coupling (each ngspice run's coil voltage settled
//! against the coil and mechanics before the next run) against the plain
//! waveform relaxation run to a tolerance ten times tighter: both
//! must find the same events, within the default tolerance, and the
//! accelerated one with fewer ngspice runs.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use crate::common;

use std::path::Path;

use chatterspice::chatter::Chatter;
use chatterspice::pipeline::{Coupled, Coupling, CouplingOptions, run_coupled};
use chatterspice::scenario::Scenario;

fn load(name: &str) -> Scenario {
    Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(name)).unwrap()
}

/// Every impact and release time of a contact, in order.
fn events(chatter: &Chatter) -> Vec<f64> {
    chatter
        .impacts
        .iter()
        .flat_map(|i| std::iter::once(i.impact_time).chain(i.release_time))
        .collect()
}

fn assert_same_events(fast: &Coupled, plain: &Coupled, tolerance: f64) {
    for (a, b) in [(&fast.chatter, &plain.chatter), (&fast.back, &plain.back)] {
        let (a, b) = (events(a), events(b));
        assert_eq!(a.len(), b.len(), "{a:?} vs {b:?}");
        for (p, q) in a.iter().zip(&b) {
            assert!((p - q).abs() <= tolerance, "{p} vs {q}: {a:?} vs {b:?}");
        }
    }
}

fn compare(name: &str) {
    let ng = ngspice_or_skip!();
    let scenario = load(name);
    // The passes, which this compares with themselves.
    let defaults = CouplingOptions {
        coupling: Some(Coupling::Passes),
        ..CouplingOptions::default()
    };
    assert!(defaults.accelerate);
    let fast =
        run_coupled(&scenario, &ng, &defaults).unwrap_or_else(|e| panic!("{}", common::chain(&e)));
    let plain = run_coupled(
        &scenario,
        &ng,
        &CouplingOptions {
            accelerate: false,
            // Ten times tighter: the diode release settles no closer than a few
            // ns, the noise of ngspice's own time steps.
            tolerance: defaults.tolerance / 10.0,
            max_iterations: 40,
            ..defaults.clone()
        },
    )
    .unwrap_or_else(|e| panic!("{}", common::chain(&e)));
    assert_same_events(&fast, &plain, defaults.tolerance);
    assert!(
        fast.iterations.len() < plain.iterations.len(),
        "{} accelerated vs {} plain passes",
        fast.iterations.len(),
        plain.iterations.len()
    );
}

#[test]
fn the_accelerated_coupling_finds_the_plain_events_with_the_diode_clamp() {
    compare("examples/scenarios/relay-driver.toml");
}

#[test]
fn the_accelerated_coupling_finds_the_plain_events_with_the_zener_clamp() {
    compare("examples/scenarios/relay-driver-zener.toml");
}

#[test]
fn the_accelerated_coupling_finds_the_plain_events_on_an_ideal_step() {
    compare("tests/data/coil/reference.toml");
}
