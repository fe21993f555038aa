//! The release of a coil-driven relay in its driver circuit: the two
//! example drivers, a plain flyback diode and a diode + zener clamp, run
//! coupled over the whole cycle.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use crate::common;

use std::path::Path;

use chatterspice::chatter::ContactState;
use chatterspice::coil::Operation;
use chatterspice::pipeline::{Coupled, CouplingOptions, run_coupled};
use chatterspice::scenario::Scenario;
use chatterspice::spice::Ngspice;

fn example(name: &str) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/scenarios")
        .join(name);
    Scenario::load(&path).unwrap()
}

fn coupled(ng: &Ngspice, name: &str) -> Coupled {
    run_coupled(&example(name), ng, &CouplingOptions::default())
        .unwrap_or_else(|e| panic!("{name}: {}", common::chain(&e)))
}

/// The one operation of a driver that pulses the coil once, with the
/// instants every operation of these drivers must show, in order.
fn operation(run: &Coupled) -> &Operation {
    let [op] = run.operations.as_slice() else {
        panic!("one pulse, one operation: {:?}", run.operations)
    };
    let s = &op.stroke;
    let on = op.coil_on.expect("switched on");
    let off = op.coil_off.expect("switched off");
    // The driver's pulse: on at 0.1 ms, off at 20 ms (edges of 1 µs).
    assert!((on - 0.1e-3).abs() < 5e-6, "{on}");
    assert!((off - 20e-3).abs() < 5e-6, "{off}");
    let order = [
        on,
        s.lift_off,
        s.first_make.unwrap(),
        s.last_make.unwrap(),
        off,
        s.break_time.unwrap(),
        s.back_make.unwrap(),
        s.back_last_make.unwrap(),
    ];
    assert!(order.windows(2).all(|w| w[0] <= w[1]), "{order:?}");
    op
}

#[test]
fn a_zener_clamp_releases_the_contact_several_times_sooner_than_a_plain_diode() {
    let ng = ngspice_or_skip!();
    let diode = coupled(&ng, "relay-driver.toml");
    let zener = coupled(&ng, "relay-driver-zener.toml");
    let (d, z) = (operation(&diode), operation(&zener));

    // The closing does not depend on the suppression: the same pull-in
    // (to the coupling's tolerance, and ngspice's).
    let make = |op: &Operation| op.stroke.first_make.unwrap();
    assert!((make(d) - make(z)).abs() < 1e-6, "{} {}", make(d), make(z));
    assert_eq!(d.stroke.bounces, z.stroke.bounces);

    // Datasheets: a plain diode makes the release ~3× slower than a
    // diode + zener; this coil, with its large L/R, more so.
    let (rd, rz) = (d.release_time.unwrap(), z.release_time.unwrap());
    assert!(rd > 3.0 * rz, "diode {rd} s, zener {rz} s");

    // The contact is broken when the pull no longer beats the spring and
    // preload at the closed position, p + s·g = 0.46 N: with the contact
    // closed (residual gap g_a − g + l_eq = 0.2 mm) that is a coil current
    // of √(0.46·2·(0.2 mm)²/(μ0 N² A)) = 12.8 mA, whatever the
    // suppression. Read off the circuit at the break, within the current's
    // change over the last few ngspice steps.
    for (name, run, op) in [("diode", &diode, d), ("zener", &zener, z)] {
        let current = run.current();
        let at_break = interpolate(&current, op.stroke.break_time.unwrap());
        assert!(
            (at_break / 12.76e-3 - 1.0).abs() < 0.02,
            "{name}: {at_break} A at the break"
        );
    }

    // The circuit saw the break: the contact's waveform is open after it.
    for run in [&diode, &zener] {
        let last = run.chatter.intervals.last().unwrap();
        assert_eq!(last.state, ContactState::Open);
        let op = &run.operations[0];
        assert!(last.start >= op.stroke.break_time.unwrap());
    }
}

/// Linear interpolation in (time, value) samples.
fn interpolate(samples: &[(f64, f64)], t: f64) -> f64 {
    let k = samples
        .partition_point(|&(s, _)| s <= t)
        .clamp(1, samples.len() - 1);
    let ((t0, v0), (t1, v1)) = (samples[k - 1], samples[k]);
    v0 + (v1 - v0) * (t - t0) / (t1 - t0)
}

#[test]
fn the_nc_contact_of_a_changeover_relay_switches_its_own_circuit() {
    let ng = ngspice_or_skip!();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/coil/changeover.toml");
    let scenario = Scenario::load(&path).unwrap();
    let run = chatterspice::pipeline::run(
        &scenario,
        &ng,
        &chatterspice::pipeline::RunOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{}", common::chain(&e)));
    let [op] = run.operations.as_slice() else {
        panic!("{:?}", run.operations)
    };
    let s = &op.stroke;
    assert!(op.coil_off.is_some() && s.back_make.is_some(), "{op:?}");
    let (no, nc) = (&run.probes[0].analysis, &run.probes[1].analysis);
    // Each contact pulls a bare 10 kΩ pull-up: every change of state is
    // an edge. NO: the make, its bounces, the break. NC: it opens at
    // lift-off, makes again on the return, and bounces.
    assert_eq!(no.edges, 2 + 2 * s.bounces, "{no:?}");
    assert_eq!(nc.edges, 2 + 2 * s.back_bounces, "{nc:?}");
    let close = |a: Option<f64>, b: f64| (a.unwrap() - b).abs() < 1e-6;
    assert!(
        close(nc.first_edge, s.lift_off),
        "{:?} {}",
        nc.first_edge,
        s.lift_off
    );
    assert!(close(nc.last_edge, s.back_last_make.unwrap()));
    assert!(close(no.last_edge, s.break_time.unwrap()));
    // The include written for the run carries both contacts.
    assert!(
        run.include.text.contains(".subckt CONTACT_NC"),
        "{}",
        run.include.text
    );
}
