//! Arcs in real ngspice against closed forms worked out here from each
//! test's own circuit values (docs/arcs.md).
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

mod common;

use std::path::{Path, PathBuf};

use chatterspice::arc::ArcEvent;
use chatterspice::chatter::{ContactState, Interval};
use chatterspice::pipeline::{self, RunOptions, RunResult};
use chatterspice::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use chatterspice::spice::Ngspice;

fn data(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The built-in relay (5 bounces) on `netlist`, with `rest` appended.
fn relay_on(dir: &Path, netlist: &str, rest: &str) -> Scenario {
    let path = dir.join("circuit.cir");
    std::fs::write(&path, netlist).unwrap();
    let cut = DEFAULT_SCENARIO_TOML.find("[circuit]").unwrap();
    let text = format!(
        "{}[circuit]\nnetlist = {:?}\n\n{rest}",
        &DEFAULT_SCENARIO_TOML[..cut],
        path.display().to_string()
    );
    Scenario::parse(&text, &dir.join("scenario.toml")).unwrap_or_else(|e| panic!("{e}"))
}

fn run(ng: &Ngspice, scenario: &Scenario) -> RunResult {
    pipeline::run(scenario, ng, &RunOptions::default())
        .unwrap_or_else(|e| panic!("{}", common::chain(&e)))
}

fn run_measured(ng: &Ngspice, scenario: &Scenario, intervals: Vec<Interval>) -> RunResult {
    pipeline::run_measured(scenario, intervals, ng, &RunOptions::default())
        .unwrap_or_else(|e| panic!("{}", common::chain(&e)))
}

/// open → closed at `make` → open at `brk` → `end`.
fn make_and_break(make: f64, brk: f64, end: f64) -> Vec<Interval> {
    let iv = |state, start, end| Interval { state, start, end };
    vec![
        iv(ContactState::Open, 0.0, make),
        iv(ContactState::Closed, make, brk),
        iv(ContactState::Open, brk, end),
    ]
}

fn arcs_in<'a>(result: &'a RunResult, opening: &str) -> Vec<&'a ArcEvent> {
    result
        .arcs
        .as_ref()
        .expect("an [arc] run reports arcs")
        .arcs
        .iter()
        .filter(|a| a.opening == opening)
        .collect()
}

/// A DC source V, inductor L and resistor R broken by the contact after
/// the current has settled at I0; the arc burns at a constant V_a > V
/// (field 0) until the current falls to I_min:
///   t_arc = (L/R)·ln((I0 + a)/(I_min + a)),
///   E_arc = V_a·(L/R)·[(I0 − I_min) − a·ln((I0 + a)/(I_min + a))],
/// with a = (V_a − V)/R.
#[test]
fn an_rl_break_at_constant_arc_voltage_matches_the_closed_form() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    for (v, r, l, v_a, i_min) in [
        (10.0f64, 10.0f64, 10e-3f64, 15.0f64, 0.4f64),
        (24.0, 4.0, 4e-3, 36.0, 0.5),
        (48.0, 24.0, 2e-3, 55.0, 0.38),
    ] {
        let netlist = format!(
            "RL break\nV1 vcc 0 {v}\nL1 vcc n1 {l}\nR1 n1 a {r}\nX1 a 0 CONTACT\n\
             .tran 1u 40m 0 1u\n.end\n"
        );
        let scenario = relay_on(
            dir.path(),
            &netlist,
            &format!(
                "[[probe]]\nsignal = \"v(a)\"\nlow = 1\nhigh = 2\n\n\
                 [arc]\nv_min = {v_a}\ni_min = {i_min}\nfield = 0.0\n"
            ),
        );
        // Closed for 20 L/R or more: the current at the break is
        // V/(R + r_closed), the built-in relay's r_closed being 50 mΩ.
        let result = run_measured(&ng, &scenario, make_and_break(1e-3, 30e-3, 40e-3));
        let i0 = v / (r + scenario.contact.r_closed);
        let tau = l / r;
        let a = (v_a - v) / r;
        let log = ((i0 + a) / (i_min + a)).ln();
        let want_t = tau * log;
        let want_e = v_a * tau * ((i0 - i_min) - a * log);
        let arcs = arcs_in(&result, "break");
        assert_eq!(arcs.len(), 1, "{v} V: {arcs:?}");
        let arc = arcs[0];
        assert!(
            (arc.start - 30e-3).abs() < 1e-6,
            "{v} V: start {}",
            arc.start
        );
        assert_eq!(arc.ends, "current_below_i_min");
        assert!(
            (arc.duration / want_t - 1.0).abs() < 0.02,
            "{v} V: duration {} vs {want_t}",
            arc.duration
        );
        assert!(
            (arc.energy / want_e - 1.0).abs() < 0.01,
            "{v} V: energy {} vs {want_e}",
            arc.energy
        );
        assert!((arc.peak_current / i0 - 1.0).abs() < 0.01);
    }
}

#[test]
fn the_signal_circuit_never_arcs() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = std::fs::read_to_string(data("netlists/mcu_input.cir")).unwrap();
    let scenario = relay_on(
        dir.path(),
        &netlist,
        "[[probe]]\nsignal = \"v(in)\"\nlow = 0.99\nhigh = 2.31\n\n[arc]\nmaterial = \"Au\"\n",
    );
    let result = run(&ng, &scenario);
    assert_eq!(result.chatter.bounce_count, 5);
    let arcs = result.arcs.as_ref().unwrap();
    assert!(arcs.arcs.is_empty(), "{:?}", arcs.arcs);
    assert!(arcs.breakdowns.is_empty(), "{:?}", arcs.breakdowns);
    assert!(arcs.peak_voltage < 3.4);
}

/// 24 V across 2 Ω: 12 A closed. At each bounce opening the arc burns at
/// V_arc ≈ V_min (the gap is a few µm, E·gap ≪ 1 V), the load current
/// drops to (24 − V_arc)/2 and never stops, and the arc's energy is
/// V_arc·I·t_open.
#[test]
fn a_24_v_12_a_resistive_load_arcs_at_every_bounce_near_v_min() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = "24 V resistive\nV1 vcc 0 24\nR1 vcc a 2\nX1 a 0 CONTACT\n\
                   .tran 0.1u 3m 0 1u\n.end\n";
    let scenario = relay_on(
        dir.path(),
        netlist,
        "[[probe]]\nsignal = \"i(V1)\"\nlow = -3\nhigh = -1\n\n[arc]\nmaterial = \"Ag\"\n",
    );
    let result = run(&ng, &scenario);
    let chatter = &result.chatter;
    let first = chatter.first_impact.unwrap();
    let openings: Vec<&Interval> = chatter
        .intervals
        .iter()
        .filter(|iv| iv.state == ContactState::Open && iv.start > first)
        .collect();
    assert_eq!(openings.len(), 5);
    let report = result.arcs.as_ref().unwrap();
    for (k, opening) in openings.iter().enumerate() {
        let label = format!("bounce {}", k + 1);
        let arcs = arcs_in(&result, &label);
        assert_eq!(arcs.len(), 1, "{label}: {arcs:?}");
        let arc = arcs[0];
        let t_open = opening.end - opening.start;
        assert!(
            (arc.duration / t_open - 1.0).abs() < 0.02,
            "{label}: {} vs {t_open}",
            arc.duration
        );
        let v_arc = report.model.v_min;
        let want = v_arc * (24.0 - v_arc) / 2.0 * t_open;
        assert!(
            (arc.energy / want - 1.0).abs() < 0.02,
            "{label}: {} vs {want}",
            arc.energy
        );
        assert_eq!(arc.ends, "contact_closed");
    }
    // The load current never stops after the first make.
    let probe = &result.probes[0].analysis;
    assert!(probe.max > -5.9, "the current reached {} A", probe.max);
    assert!(report.breakdowns.is_empty(), "{:?}", report.breakdowns);
}

/// The lamp: every break of its ~5 A inrush arcs instead of ringing to
/// hundreds of volts.
#[test]
fn the_lamp_contact_stays_below_100_v() {
    let ng = ngspice_or_skip!();
    let text = std::fs::read_to_string(data("examples/scenarios/lamp.toml")).unwrap();
    let scenario = Scenario::parse(
        &format!("{text}\n[arc]\nmaterial = \"Ag\"\n"),
        &data("examples/scenarios/lamp-arc.toml"),
    )
    .unwrap();
    let result = run(&ng, &scenario);
    let contact = result
        .probes
        .iter()
        .find(|p| p.probe.signal == "v(c1,lamp)")
        .unwrap();
    assert!(
        contact.analysis.max < 100.0 && contact.analysis.min > -100.0,
        "{} .. {}",
        contact.analysis.min,
        contact.analysis.max
    );
    for k in 1..=result.chatter.bounce_count {
        assert!(
            !arcs_in(&result, &format!("bounce {k}")).is_empty(),
            "bounce {k} did not arc"
        );
    }
}

/// 230 V 50 Hz through 32.5 Ω (10 A peak), broken at a current peak: the
/// arc goes out just before the first current zero and does not restrike
/// across the widening gap.
#[test]
fn an_ac_arc_goes_out_at_its_first_current_zero() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = "230 V AC resistive\nV1 vcc 0 SIN(0 325.27 50)\nR1 vcc a 32.5\n\
                   X1 a 0 CONTACT\n.tran 1u 50m 0 2u\n.end\n";
    let scenario = relay_on(
        dir.path(),
        netlist,
        "[[probe]]\nsignal = \"v(a)\"\nlow = 100\nhigh = 200\n\n[arc]\nmaterial = \"Ag\"\n",
    );
    // Break at 25 ms, at the current's peak (sin = 1).
    let result = run_measured(&ng, &scenario, make_and_break(1e-3, 25e-3, 50e-3));
    let arcs = arcs_in(&result, "break");
    assert_eq!(arcs.len(), 1, "{arcs:?}");
    let arc = arcs[0];
    let end = arc.start + arc.duration;
    // Out when |i| < I_min: sin θ < (I_min·R + V_arc)/V_peak ≈ 0.08, i.e.
    // within 0.3 ms before the zero at 30 ms.
    assert!(end < 30e-3 && end > 29.6e-3, "ended at {end}");
    assert_eq!(arc.ends, "current_below_i_min");
    let report = result.arcs.as_ref().unwrap();
    assert!(
        report.breakdowns.iter().all(|b| b.start < 25e-3),
        "restruck: {:?}",
        report.breakdowns
    );
    // After the zero the open contact sees the whole source voltage.
    assert!(result.probes[0].analysis.min < -300.0);
}
