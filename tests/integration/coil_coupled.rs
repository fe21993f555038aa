//! The coil in an ngspice circuit, coupled to the mechanics by waveform
//! relaxation, against the direct solver of the same equations (no
//! ngspice) on docs/model.md §7's reference case.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use crate::common;

use std::path::Path;

use chatterspice::coil::{Coil, Source, simulate_direct};
use chatterspice::mechanics::Mechanics;
use chatterspice::pipeline::{Coupling, CouplingOptions, run_coupled};
use chatterspice::scenario::Scenario;

fn reference() -> Scenario {
    Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/coil/reference.toml"))
        .unwrap()
}

#[test]
fn the_coupled_run_agrees_with_the_direct_solver() {
    let ng = ngspice_or_skip!();
    let scenario = reference();
    let coupled = run_coupled(&scenario, &ng, &CouplingOptions::default())
        .unwrap_or_else(|e| panic!("{}", common::chain(&e)));

    let mechanics = Mechanics {
        force: 0.0,
        initial_position: 0.0,
        initial_velocity: 0.0,
        ..scenario.armature()
    };
    let direct = simulate_direct(
        &Coil::from(scenario.coil.as_ref().unwrap()),
        &Source {
            voltage: 5.0,
            series_resistance: 0.0,
        },
        &mechanics,
        &scenario.surface(),
        &scenario.settings(),
    )
    .unwrap();

    let (a, b) = (
        coupled.chatter.first_impact.unwrap(),
        direct.chatter.first_impact.unwrap(),
    );
    assert!((a / b - 1.0).abs() < 1e-3, "first impact {a} vs direct {b}");
    assert_eq!(coupled.chatter.bounce_count, direct.chatter.bounce_count);
    let (a, b) = (
        coupled.chatter.settle_time.unwrap(),
        direct.chatter.settle_time.unwrap(),
    );
    assert!((a / b - 1.0).abs() < 1e-3, "settle {a} vs direct {b}");
    let last = coupled.iterations.last().unwrap();
    assert!(last.change <= 1e-7, "{:?}", coupled.iterations);

    // The pull-in dip in ngspice's coil current: the back-EMF of the moving
    // armature pulls the current down from its peak (26 mA) to about half of
    // it by the first make (12.9 mA in the direct solver, where a held
    // armature would carry 38 mA), and ngspice agrees on the value.
    let current = coupled.current();
    let make = coupled.chatter.first_impact.unwrap();
    let at = |t: f64| current[current.partition_point(|&(s, _)| s < t)].1;
    let before = (0..current.len())
        .map(|k| current[k])
        .filter(|&(t, _)| t < make)
        .fold(
            (0.0, 0.0),
            |best, (t, i)| if i > best.1 { (t, i) } else { best },
        );
    assert!(
        at(make) < 0.6 * before.1,
        "no dip: peak {before:?}, at make {}",
        at(make)
    );
    let direct_make = direct.events.current_at_make.unwrap();
    assert!(
        (at(make) / direct_make - 1.0).abs() < 0.01,
        "{} vs {direct_make}",
        at(make)
    );
}

#[test]
fn a_coupling_that_cannot_converge_says_so_with_its_last_change() {
    let ng = ngspice_or_skip!();
    let options = CouplingOptions {
        tolerance: 0.0,
        max_iterations: 2,
        coupling: Some(Coupling::Passes),
        ..CouplingOptions::default()
    };
    let err = run_coupled(&reference(), &ng, &options).unwrap_err();
    let text = err.to_string();
    assert!(
        matches!(
            err,
            chatterspice::pipeline::CouplingError::NotConverged { iterations: 2, .. }
        ),
        "{text}"
    );
    assert!(text.contains("did not converge in 2 iterations"), "{text}");
    assert!(text.contains("ideal_step.cir"), "{text}");
}

#[test]
fn the_iterations_are_reported_and_shrink() {
    let ng = ngspice_or_skip!();
    let passes = CouplingOptions {
        coupling: Some(Coupling::Passes),
        ..CouplingOptions::default()
    };
    let coupled = run_coupled(&reference(), &ng, &passes).unwrap();
    let changes: Vec<f64> = coupled.iterations.iter().map(|i| i.change).collect();
    assert!(changes.len() >= 2);
    // Once the events are the same in number, each pass moves them less.
    let finite: Vec<f64> = changes.iter().copied().filter(|c| c.is_finite()).collect();
    assert!(finite.windows(2).all(|w| w[1] <= w[0]), "{changes:?}");
}

#[test]
fn a_two_stage_relay_coupled_to_its_coil_agrees_with_the_direct_solver() {
    use chatterspice::coil::direct::direct_closing;
    let ng = ngspice_or_skip!();
    // The reference relay with a contact blade and a pole face 0.1 mm past
    // the make (the magnet's pole is at 0.65 mm).
    let origin = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/coil/reference.toml");
    let text = std::fs::read_to_string(&origin).unwrap()
        + "\n[blade]\nmass = 3.0e-5\nstiffness = 3000.0\ndamping = 0.01\n\
           \n[pole_face]\novertravel = 1.0e-4\nlaw = \"kelvin-voigt\"\nstiffness = 5.0e6\ndamping = 20.0\n";
    let scenario = Scenario::parse(&text, &origin).unwrap();
    let coupled = run_coupled(&scenario, &ng, &CouplingOptions::default())
        .unwrap_or_else(|e| panic!("{}", common::chain(&e)));
    let mechanics = Mechanics {
        force: 0.0,
        initial_position: 0.0,
        initial_velocity: 0.0,
        ..scenario.armature()
    };
    let (direct, run) = direct_closing(
        &Coil::from(scenario.coil.as_ref().unwrap()),
        &Source {
            voltage: 5.0,
            series_resistance: 0.0,
        },
        &mechanics,
        &scenario.two_stage(),
        &scenario.surface(),
        &scenario.settings(),
    )
    .unwrap();
    let run = run.expect("a two-stage run");
    let close = |a: f64, b: f64, what: &str| {
        assert!(
            (a / b - 1.0).abs() < 1e-3,
            "{what}: coupled {a} vs direct {b}"
        )
    };
    close(
        coupled.chatter.first_impact.unwrap(),
        direct.first_impact.unwrap(),
        "first impact",
    );
    assert_eq!(coupled.chatter.bounce_count, direct.bounce_count);
    close(
        coupled.chatter.settle_time.unwrap(),
        direct.settle_time.unwrap(),
        "settle",
    );
    // The armature reaches the pole face after the make, in both.
    assert!(!run.pole_face.is_empty() && !coupled.pole_face.is_empty());
    close(
        coupled.pole_face[0].impact_time,
        run.pole_face[0].impact_time,
        "first pole-face impact",
    );
    assert!(run.pole_face[0].impact_time > direct.first_impact.unwrap());
}
