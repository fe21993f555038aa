//! Arcs in real ngspice against closed forms worked out here from each
//! test's own circuit values (docs/arcs.md).
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use crate::common;

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

/// m, the widest gap below 1 mm at which `burns` still holds (bisection;
/// it must hold at 0 and not at 1 mm).
fn widest_burning_gap(burns: &dyn Fn(f64) -> bool) -> f64 {
    let (mut lo, mut hi) = (0.0, 1e-3);
    assert!(burns(lo) && !burns(hi));
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if burns(mid) { lo = mid } else { hi = mid }
    }
    lo
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
                 [arc]\nv_min = {v_a}\ni_min = {i_min}\nfield = 0.0\nlow_current = 0.0\nlow_current_gap = 0.0\n"
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
/// V_arc·I·t_open: with the arc voltage independent of the current
/// (C = D = 0) and with silver's defaults, whose low-current term grows
/// from 0 with the gap (at a few µm, (C + D·d)/6 A is some 0.05 V).
#[test]
fn a_24_v_12_a_resistive_load_arcs_at_every_bounce_near_v_min() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = "24 V resistive\nV1 vcc 0 24\nR1 vcc a 2\nX1 a 0 CONTACT\n\
                   .tran 0.1u 3m 0 1u\n.end\n";
    for (arc, tolerance) in [
        (
            "material = \"Ag\"\nlow_current = 0.0\nlow_current_gap = 0.0\n",
            0.02,
        ),
        ("material = \"Ag\"\n", 0.05),
    ] {
        let scenario = relay_on(
            dir.path(),
            netlist,
            &format!("[[probe]]\nsignal = \"i(V1)\"\nlow = -3\nhigh = -1\n\n[arc]\n{arc}"),
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
            let label = format!("{arc}: bounce {}", k + 1);
            let arcs = arcs_in(&result, &format!("bounce {}", k + 1));
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
                (arc.energy / want - 1.0).abs() < tolerance,
                "{label}: {} vs {want}",
                arc.energy
            );
            assert_eq!(arc.ends, "contact_closed");
        }
        // The ledger adds up: the source's energy went into the load,
        // the arcs and the closed contact (50 mΩ against 2 Ω: 2.4 %).
        let e = &result.energy;
        assert!(e.complete(), "{:?}", e.unaccounted);
        assert_eq!(e.arcs, report.totals.energy);
        let rest = e.elsewhere.unwrap();
        assert!(rest >= 0.0 && rest < 0.03 * e.delivered, "{e:?}");
        assert!(e.violation().is_none());
        // The load current never stops after the first make.
        let probe = &result.probes[0].analysis;
        assert!(probe.max > -5.9, "the current reached {} A", probe.max);
        assert!(report.breakdowns.is_empty(), "{:?}", report.breakdowns);
    }
}

/// 10 V through 10 Ω and 10 mH, broken at 1 A with a constant arc
/// voltage of 15 V: the arc takes the inductor's current down to I_min
/// and goes out. What the inductor still holds then, ½·L·I_min², is all
/// that any breakdown of the open gap can take afterwards: the gap rings
/// with the contact's own capacitance (1 pF by default), and the net
/// energy of its breakdowns stays within that bound.
#[test]
fn after_an_inductive_break_the_gap_takes_no_more_than_the_inductor_held() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = "RL break\nV1 vcc 0 10\nR1 vcc m 10\nL1 m a 10m\nX1 a 0 CONTACT\n\
                   .tran 0.1u 20m 0 1u\n.end\n";
    let (l, i_min) = (10e-3, 0.4);
    let scenario = relay_on(
        dir.path(),
        netlist,
        &format!(
            "[[probe]]\nsignal = \"v(a)\"\nlow = 1\nhigh = 2\n\n\
             [arc]\nv_min = 15.0\ni_min = {i_min}\nfield = 0.0\nlow_current = 0.0\n\
             low_current_gap = 0.0\n"
        ),
    );
    let result = run_measured(&ng, &scenario, make_and_break(1e-3, 10e-3, 20e-3));
    let arcs = arcs_in(&result, "break");
    assert_eq!(arcs.len(), 1, "{arcs:?}");
    assert_eq!(arcs[0].ends, "current_below_i_min");
    let out = arcs[0].start + arcs[0].duration;
    let report = result.arcs.as_ref().unwrap();
    let after: f64 = report
        .breakdowns
        .iter()
        .filter(|b| b.start >= out - 1e-9)
        .map(|b| b.energy)
        .sum();
    let held = 0.5 * l * i_min * i_min;
    assert!(
        after <= 1.05 * held,
        "breakdowns after the arc took {after} J; the inductor held {held} J: {:?}",
        report.breakdowns
    );
    for b in &report.breakdowns {
        assert!(b.energy >= -1e-9, "a breakdown that gives energy: {b:?}");
    }
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
        "[[probe]]\nsignal = \"v(a)\"\nlow = 100\nhigh = 200\n\n[arc]\nmaterial = \"Ag\"\n\
         low_current = 0.0\nlow_current_gap = 0.0\n",
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

fn cli() -> assert_cmd::Command {
    assert_cmd::Command::cargo_bin("chatterspice").unwrap()
}

/// `run SCENARIO --format json` with `extra` arguments; it must succeed.
fn run_json_with(scenario: &Path, extra: &[&str]) -> serde_json::Value {
    let out = cli()
        .args(["run", scenario.to_str().unwrap(), "--format", "json"])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn run_json(scenario: &Path) -> serde_json::Value {
    run_json_with(scenario, &[])
}

/// The lamp-arc example's text, its netlist path made absolute so that
/// the scenario can be written anywhere.
fn lamp_arc_text() -> String {
    std::fs::read_to_string(data("examples/scenarios/lamp-arc.toml"))
        .unwrap()
        .replace("../../netlists", data("netlists").to_str().unwrap())
}

/// The coil-driven examples: the solenoid's break arcs and, without a
/// freewheel diode, its gap then breaks down at hundreds of volts; with the diode
/// the contact never sees much more than the supply. The mains heater's
/// break arc goes out just before a current zero of its 50 Hz.
#[test]
fn the_coil_driven_power_examples() {
    let Some(_) = common::ngspice() else { return };
    let bare = run_json(&data("examples/scenarios/solenoid.toml"));
    let diode = run_json(&data("examples/scenarios/solenoid-diode.toml"));
    for doc in [&bare, &diode] {
        let breaks: Vec<_> = doc["arcs"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|a| a["opening"] == "break")
            .collect();
        assert_eq!(breaks.len(), 1, "{breaks:?}");
        assert_eq!(breaks[0]["ends"], "current_below_i_min");
    }
    let duration = |doc: &serde_json::Value| {
        doc["arcs"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["opening"] == "break")
            .unwrap()["duration"]
            .as_f64()
            .unwrap()
    };
    let gap_at_end = |doc: &serde_json::Value| {
        doc["arcs"]
            .as_array()
            .unwrap()
            .iter()
            .find(|a| a["opening"] == "break")
            .unwrap()["gap_at_end"]
            .as_f64()
            .unwrap()
    };
    // Without the diode, 1 A in 20 mH drives the arc while the gap opens
    // and its voltage V_min + E·d + D·d/i rises far past the 12 V supply.
    assert!(duration(&bare) > 1e-4, "{}", duration(&bare));
    // With it, the contact sees the supply plus a diode drop, 12.7 V: a
    // short arc burns near V_min = 12 V only until D·d/1 A takes the
    // 0.7 V left, some µm (D = 67 kV·A/m: 10 µm), then the diode carries
    // the current.
    assert!(gap_at_end(&diode) < 20e-6, "{}", gap_at_end(&diode));
    assert!(
        gap_at_end(&diode) < 0.5 * gap_at_end(&bare) && duration(&diode) < duration(&bare),
        "{} {}",
        duration(&diode),
        duration(&bare)
    );
    let peak = |doc: &serde_json::Value| {
        doc["probes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["signal"] == "v(v12,sol)")
            .map(|p| p["max"].as_f64().unwrap().max(-p["min"].as_f64().unwrap()))
            .unwrap()
    };
    // The arc goes out while the gap is some tens of µm: the returning
    // voltage then breaks it down at the Paschen minimum and above.
    assert!(peak(&bare) > 320.0, "{}", peak(&bare));
    assert!(peak(&diode) < 14.0, "{}", peak(&diode));
    assert!(
        bare["breakdowns"]
            .as_array()
            .unwrap()
            .iter()
            .any(|b| b["opening"] == "break" && b["peak_voltage"].as_f64().unwrap() > 320.0)
    );

    let mains = run_json(&data("examples/scenarios/mains-heater.toml"));
    let arcs = mains["arcs"].as_array().unwrap();
    let brk = arcs.iter().find(|a| a["opening"] == "break").unwrap();
    let end = brk["start"].as_f64().unwrap() + brk["duration"].as_f64().unwrap();
    // The next current zero: a multiple of 10 ms after the break began.
    let zero = (brk["start"].as_f64().unwrap() / 10e-3).ceil() * 10e-3;
    // The arc goes out where the falling supply's load line (52.9 Ω) no
    // longer meets the arc's characteristic: v = a + 2·√(K·R), with
    // a = V_min + E·gap and K = C + D·gap (silver's defaults).
    let gap = brk["gap_at_end"].as_f64().unwrap();
    let model = &mains["arc_model"];
    let a = model["v_min"].as_f64().unwrap() + model["field"].as_f64().unwrap() * gap;
    let k =
        model["low_current"].as_f64().unwrap() + model["low_current_gap"].as_f64().unwrap() * gap;
    let threshold = a + 2.0 * (k * 52.9).sqrt();
    let out = zero - (threshold / 325.27).asin() / (2.0 * std::f64::consts::PI * 50.0);
    assert!(
        end < zero && (end - out).abs() < 0.2e-3,
        "ended {end}, predicted {out}, zero {zero}"
    );
    assert!(
        arcs.iter()
            .all(|a| a["start"].as_f64().unwrap() <= brk["start"].as_f64().unwrap())
    );
    // Every bounce opening arcs: the source is far above V_arc.
    let bounces = mains["bounce"]["bounce_count"].as_u64().unwrap() as usize;
    assert_eq!(
        arcs.iter()
            .filter(|a| a["opening"].as_str().unwrap().starts_with("bounce"))
            .count(),
        bounces
    );
}

#[test]
fn without_arc_a_power_run_warns_and_a_signal_run_does_not() {
    let Some(_) = common::ngspice() else { return };
    let out = cli()
        .args([
            "run",
            data("examples/scenarios/lamp.toml").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("not physical") && stderr.contains("[arc]"),
        "{stderr}"
    );
    let out = cli().args(["run"]).output().unwrap();
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("not physical"), "{stderr}");
}

#[test]
fn arc_limits_pass_and_fail_in_check() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    let text = lamp_arc_text();
    for (limits, code) in [
        ("max_arc_energy = 1.0e-3\nmax_arc_count = 7\n", 0),
        ("max_arc_energy = 1.0e-4\n", 1),
        ("max_arc_count = 6\n", 1),
    ] {
        let path = dir.path().join("s.toml");
        std::fs::write(&path, format!("{text}\n[limits]\n{limits}")).unwrap();
        let out = cli()
            .args(["check", path.to_str().unwrap(), "--format", "json"])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(code), "{limits}");
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        let failed: Vec<_> = v["checks"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| c["passed"] == false)
            .map(|c| c["key"].as_str().unwrap().to_owned())
            .collect();
        assert_eq!(failed.len(), code as usize, "{failed:?}");
    }
}

#[test]
fn bad_arc_sections_name_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let cut = DEFAULT_SCENARIO_TOML.find("[circuit]").unwrap();
    let base = &DEFAULT_SCENARIO_TOML[..cut];
    for (section, needle) in [
        ("[arc]\nmaterial = \"Sn\"\n", "material"),
        ("[arc]\nvmin = 12.0\n", "vmin"),
        ("[arc]\nv_min = -1.0\n", "arc.v_min"),
        ("[arc]\ni_min = 0.0\n", "arc.i_min"),
        ("[arc]\nfield = 1e300\n", "arc.field"),
        ("[limits]\nmax_arc_count = 3\n", "[arc]"),
    ] {
        let path = dir.path().join("bad.toml");
        std::fs::write(&path, format!("{base}{section}")).unwrap();
        let out = cli()
            .args(["bounce", path.to_str().unwrap()])
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{section}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(needle), "{section}: {stderr}");
        assert!(stderr.contains("bad.toml:"), "{section}: {stderr}");
    }
}

/// A contact instantiated inside the user's own subcircuit: ngspice names
/// its vectors with the path (`i(v.x_board.x_relay.vsense)`), and the arcs are
/// found there.
#[test]
fn a_contact_inside_a_subcircuit_arcs_too() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = "Hierarchical\nV1 vcc 0 24\nX_BOARD vcc out BOARD\nR1 out 0 2\n\
                   .subckt BOARD in out\nX_RELAY in out CONTACT\n.ends\n\
                   .tran 0.1u 3m 0 1u\n.end\n";
    let scenario = relay_on(
        dir.path(),
        netlist,
        "[[probe]]\nsignal = \"v(out)\"\nlow = 1\nhigh = 5\n\n[arc]\nmaterial = \"Ag\"\n",
    );
    let result = run(&ng, &scenario);
    let arcs = &result.arcs.as_ref().unwrap().arcs;
    assert_eq!(
        arcs.iter()
            .filter(|a| a.opening.starts_with("bounce"))
            .count(),
        result.chatter.bounce_count
    );
}

/// `pwl` writes the include a user's own deck needs: with `[arc]`, the
/// arc element too.
#[test]
fn pwl_emits_the_arc_element_with_arc() {
    let with = cli()
        .args([
            "pwl",
            data("examples/scenarios/lamp-arc.toml").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(with.status.success());
    let text = String::from_utf8(with.stdout).unwrap();
    for needle in [
        ".subckt CONTACT a b",
        "Vsense a ai 0",
        "Xcore ai b CONTACT_core",
        "Barc ac b",
        ".subckt CONTACT_core a b",
    ] {
        assert!(text.contains(needle), "{needle}");
    }
    // The contact first, its helper after; nothing for the whole circuit.
    assert!(text.find(".subckt CONTACT a b").unwrap() < text.find(".subckt CONTACT_core").unwrap());
    assert!(
        !text
            .lines()
            .any(|l| l.trim_start().to_ascii_lowercase().starts_with(".option")),
        "{text}"
    );
    let without = cli()
        .args([
            "pwl",
            data("examples/scenarios/lamp.toml").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let text = String::from_utf8(without.stdout).unwrap();
    assert!(text.contains(".subckt CONTACT a b") && !text.contains("Barc"));
}

/// The arc element wraps whichever conductance element carries the
/// contact: each gives the lamp's seven bounce arcs and their energy.
#[test]
fn every_contact_element_carries_the_arc() {
    let Some(_) = common::ngspice() else { return };
    let mut energies = Vec::new();
    for element in ["pwl", "event-ramp", "switch"] {
        let v = run_json_with(
            &data("examples/scenarios/lamp-arc.toml"),
            &["--element", element],
        );
        let bounces = v["bounce"]["bounce_count"].as_u64().unwrap();
        assert_eq!(
            v["arc_totals"]["count"].as_u64(),
            Some(bounces),
            "{element}"
        );
        energies.push(v["arc_totals"]["energy"].as_f64().unwrap());
    }
    for e in &energies[1..] {
        assert!((e / energies[0] - 1.0).abs() < 0.05, "{energies:?}");
    }
}

/// The arc numbers are sweepable: below the lamp's 12 V supply an arc can
/// burn for the whole bounce opening, above it only while the wiring
/// inductance gives up its current.
#[test]
fn a_sweep_over_v_min_shows_where_the_supply_sustains_the_arc() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    // V_min alone sets where the supply sustains the arc.
    let text = lamp_arc_text().replace(
        "[arc]\n",
        "[arc]\nlow_current = 0.0\nlow_current_gap = 0.0\n",
    );
    assert!(text.contains("low_current_gap = 0.0"));
    let path = dir.path().join("s.toml");
    std::fs::write(
        &path,
        format!("{text}\n[sweep]\n[sweep.grid]\n\"arc.v_min\" = {{ from = 10.0, to = 14.0, steps = 2 }}\n"),
    )
    .unwrap();
    let out = dir.path().join("out");
    cli()
        .args([
            "sweep",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .assert()
        .success();
    let csv = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let mut rows = csv.lines();
    let header: Vec<&str> = rows.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let energy: Vec<f64> = rows
        .map(|r| {
            r.split(',')
                .nth(col("arc_energy"))
                .unwrap()
                .parse()
                .unwrap()
        })
        .collect();
    assert_eq!(energy.len(), 2);
    // 10 V: 2 V left across the lamp, and the arc burns the whole opening.
    assert!(energy[0] > 50.0 * energy[1], "{energy:?}");
}

/// Every arc of a bouncing RL load carries at most what the circuit
/// drives through the contact: the inductor's current, never above the
/// steady load current V/R (within 2 %), whatever the arc element's own
/// transient at the start of each arc.
#[test]
fn no_arc_peak_exceeds_what_the_circuit_drives() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let (v, r) = (24.0f64, 24.0f64);
    let netlist = format!(
        "RL bounce\nV1 vcc 0 {v}\nL1 vcc n1 2m\nR1 n1 a {r}\nX1 a 0 CONTACT\n\
         .tran 1u 5m 0 1u\n.end\n"
    );
    let scenario = relay_on(
        dir.path(),
        &netlist,
        "[[probe]]\nsignal = \"v(a)\"\nlow = 1\nhigh = 2\n\n[arc]\nmaterial = \"Ag\"\n",
    );
    let result = run(&ng, &scenario);
    let arcs = &result.arcs.as_ref().unwrap().arcs;
    assert!(!arcs.is_empty(), "the bounces of a 1 A inductive load arc");
    let load = v / r;
    for arc in arcs {
        assert!(
            arc.peak_current <= 1.02 * load,
            "{}: {} A from a {load} A load",
            arc.opening,
            arc.peak_current
        );
    }
}

/// A resistive DC break whose arc the opening gap puts out: with
/// V_arc = V_min + E·d + (C + D·d)/|i| the arc burns only while the load
/// line V − i·R meets that characteristic, so it goes out at the gap d*
/// where V = V_min + E·d* + 2·√((C + D·d*)·R), i.e. at d*/speed after
/// separation for a record opening at a known speed. Both the constant
/// and the gap-dependent low-current term.
#[test]
fn a_dc_break_goes_out_where_the_load_line_leaves_the_arc_characteristic() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = "30 V DC resistive\nV1 vcc 0 30\nR1 vcc a 3\nX1 a 0 CONTACT\n\
                   .tran 1u 20m 0 2u\n.end\n";
    let (v, r, v_min, field, speed) = (30.0, 3.0, 12.0, 2.0e4, 0.3);
    for (c, d) in [(20.0, 0.0), (15.0, 4.0e4)] {
        let scenario = relay_on(
            dir.path(),
            netlist,
            &format!(
                "[[probe]]\nsignal = \"i(V1)\"\nlow = -3\nhigh = -1\n\n[arc]\nv_min = {v_min}\n\
                 i_min = 0.4\nfield = {field}\nlow_current = {c}\nlow_current_gap = {d}\n\
                 opening_speed = {speed}\n"
            ),
        );
        let result = run_measured(&ng, &scenario, make_and_break(1e-3, 10e-3, 20e-3));
        let arcs = arcs_in(&result, "break");
        assert_eq!(arcs.len(), 1, "{arcs:?}");
        assert_eq!(arcs[0].ends, "current_below_i_min");
        // d* by bisection: below it the arc can burn, above it cannot.
        let burns = |g: f64| v_min + field * g + 2.0 * ((c + d * g) * r).sqrt() <= v;
        let lo = widest_burning_gap(&burns);
        let expected = lo / speed;
        let duration = arcs[0].duration;
        assert!(
            (duration / expected - 1.0).abs() < 0.02,
            "C = {c}, D = {d}: burned {duration} s, the load line leaves at {expected} s"
        );
        // The model's breaking current at that gap is the load's.
        let model = result.arcs.as_ref().unwrap().model;
        let at = model.breaking_current(v, lo).unwrap();
        assert!((at / (v / r) - 1.0).abs() < 1e-6, "{at}");
    }
}

/// 14 V through 2.8 Ω (5 A) with the silver–tin-oxide defaults: an
/// automotive load whose bounce openings and break arc, as measured on
/// AgSnO2 contacts opening at 20–200 mm/s (IEICE Trans. Electron.
/// E98-C(9), 923). A bounce gap of micrometres holds an arc near V_min,
/// so the 50 µs bounce opening arcs throughout; the break arc burns while
/// the gap opens and goes out where the model's breaking current at the
/// gap falls to the load's 5 A.
#[test]
fn a_14_v_5_a_automotive_load_arcs_at_its_bounce_and_its_break() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = "14 V automotive load\nV1 vcc 0 14\nR1 vcc a 2.8\nX1 a 0 CONTACT\n\
                   .tran 0.2u 8m 0 1u\n.end\n";
    let speed = 0.1;
    let scenario = relay_on(
        dir.path(),
        netlist,
        &format!(
            "[[probe]]\nsignal = \"i(V1)\"\nlow = -3\nhigh = -1\n\n[arc]\n\
             material = \"AgSnO2\"\nopening_speed = {speed}\n"
        ),
    );
    let iv = |state, start, end| Interval { state, start, end };
    let (bounce, t_break) = ((2e-3, 2.05e-3), 5e-3);
    let record = vec![
        iv(ContactState::Open, 0.0, 1e-3),
        iv(ContactState::Closed, 1e-3, bounce.0),
        iv(ContactState::Open, bounce.0, bounce.1),
        iv(ContactState::Closed, bounce.1, t_break),
        iv(ContactState::Open, t_break, 8e-3),
    ];
    let result = run_measured(&ng, &scenario, record);
    let report = result.arcs.as_ref().unwrap();
    let model = report.model;
    let all: Vec<(&str, f64, &str)> = report
        .arcs
        .iter()
        .map(|a| (a.opening.as_str(), a.duration, a.ends))
        .collect();
    // The bounce opening arcs until the contact closes again.
    let at_bounce: Vec<_> = all.iter().filter(|a| a.0 != "break").collect();
    assert_eq!(at_bounce.len(), 1, "{all:?}");
    assert!(
        (at_bounce[0].1 / (bounce.1 - bounce.0) - 1.0).abs() < 0.02,
        "{all:?}"
    );
    assert_eq!(at_bounce[0].2, "contact_closed", "{all:?}");
    // The break arc goes out at the gap where the load is the most the
    // contact breaks at 14 V.
    let arcs = arcs_in(&result, "break");
    assert_eq!(arcs.len(), 1, "{all:?}");
    let burns = |g: f64| {
        model
            .breaking_current(14.0, g)
            .is_some_and(|most| most < 5.0)
    };
    let lo = widest_burning_gap(&burns);
    let expected = lo / speed;
    let duration = arcs[0].duration;
    assert!(expected > 10e-6, "{expected}");
    assert!(
        (duration / expected - 1.0).abs() < 0.05,
        "burned {duration} s, the gap reaches {lo} m at {expected} s"
    );
}

/// The DC example breaks its 30 V, 5 A: every bounce opening arcs until
/// the contact closes again (a short arc burns near V_min), and the break
/// arc burns while the gap opens, from tens of µs to a few ms, going out
/// where the load line leaves the arc's characteristic. At 15 A the
/// contact cannot, and the run says so instead of failing: the arc still
/// burning, its duration so far, and `check` failing every arc limit on it.
#[test]
fn a_dc_load_the_contact_cannot_break_is_reported_as_still_burning() {
    let Some(_) = common::ngspice() else { return };
    let rated = run_json(&data("examples/scenarios/dc-break.toml"));
    assert!(rated["arc_totals"]["still_burning"].is_null());
    let arcs = rated["arcs"].as_array().unwrap();
    for arc in arcs.iter().filter(|a| a["opening"] != "break") {
        assert_eq!(arc["ends"], "contact_closed", "{arc}");
    }
    let brk: Vec<_> = arcs.iter().filter(|a| a["opening"] == "break").collect();
    assert_eq!(brk.len(), 1, "{arcs:?}");
    assert_eq!(brk[0]["ends"], "current_below_i_min");
    let duration = brk[0]["duration"].as_f64().unwrap();
    assert!((5e-5..5e-3).contains(&duration), "{}", brk[0]);
    // Out where 30 V = V_min + E·d + 2·√((C + D·d)·R) on the trajectory.
    let model = &rated["arc_model"];
    let (v_min, e, c, d) = (
        model["v_min"].as_f64().unwrap(),
        model["field"].as_f64().unwrap(),
        model["low_current"].as_f64().unwrap(),
        model["low_current_gap"].as_f64().unwrap(),
    );
    let gap = brk[0]["gap_at_end"].as_f64().unwrap();
    let r = 6.0; // the load; the open contact carries the arc
    let needed = v_min + e * gap + 2.0 * ((c + d * gap) * r).sqrt();
    assert!((needed / 30.0 - 1.0).abs() < 0.02, "{needed} V at {gap} m");
    let dir = tempfile::tempdir().unwrap();
    let netlist = std::fs::read_to_string(data("netlists/dc_break.cir"))
        .unwrap()
        .replace("R_LOAD load 0 6", "R_LOAD load 0 2");
    assert!(netlist.contains("R_LOAD load 0 2"));
    std::fs::write(dir.path().join("dc_break.cir"), netlist).unwrap();
    let text = std::fs::read_to_string(data("examples/scenarios/dc-break.toml"))
        .unwrap()
        .replace("../../netlists/dc_break.cir", "dc_break.cir");
    let path = dir.path().join("heavy.toml");
    std::fs::write(&path, text).unwrap();
    let heavy = run_json(&path);
    let burning = &heavy["arc_totals"]["still_burning"];
    assert_eq!(burning["opening"], "break", "{burning}");
    // From the release to the end of the run, 50 ms.
    let (start, duration) = (
        burning["start"].as_f64().unwrap(),
        burning["duration"].as_f64().unwrap(),
    );
    assert!((start + duration - 0.05).abs() < 1e-4, "{burning}");
    let out = cli()
        .args(["check", path.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("still burns when the run ends") && stdout.contains("max_arc_duration"),
        "{stdout}"
    );
}

/// Every make onto a capacitor is a new inrush: the peak current of each
/// closure is what the source drives into the capacitor's voltage at
/// that instant, (V − v_C)/(R + r_closed), and each carries the contact
/// force of the built-in (step-force) relay at its peak, from which the
/// spot's figures follow; `check` holds the worst make to the making
/// limits.
#[test]
fn every_make_onto_a_capacitor_is_a_new_inrush() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = "10 V onto 100 uF\nV1 vcc 0 10\nR1 vcc a 1\nX1 a c CONTACT\nC1 c 0 100u IC=0\n\
                   .tran 0.1u 10m 0 1u uic\n.end\n";
    let scenario = relay_on(dir.path(), netlist, "");
    let result = run(&ng, &scenario);
    let makes = &result.makes;
    assert_eq!(makes.len(), result.chatter.bounce_count + 1, "{makes:?}");
    let plot = &result.simulation.plot;
    let time = match plot.scale() {
        Some(chatterspice::rawfile::Vector::Real(t)) => t,
        _ => panic!("a transient"),
    };
    let vc = plot.real("v(c)").unwrap();
    for m in makes {
        let k = time.partition_point(|&t| t < m.time);
        let expected = (10.0 - vc[k]) / (1.0 + 0.05);
        assert!(
            (m.peak_current / expected - 1.0).abs() < 0.02,
            "make at {}: {} A, expected {expected} A",
            m.time,
            m.peak_current
        );
        let force = m.force.expect("a step-force relay knows its force");
        assert!(force > 0.0);
        let ag = chatterspice::arc::Material::Ag.spot();
        let a = (force / (std::f64::consts::PI * ag.hardness)).sqrt();
        let u = m.peak_current * ag.resistivity / (2.0 * a);
        assert!((m.spot_voltage.unwrap() / u - 1.0).abs() < 1e-9);
        assert!((m.weld_margin.unwrap() - ag.melting_voltage() / u).abs() < 1e-9 * u.recip());
    }
    // The first make carries the largest inrush.
    assert!(
        makes
            .iter()
            .all(|m| m.peak_current <= makes[0].peak_current)
    );

    // The limits, through the command line.
    let cir = dir.path().join("circuit.cir");
    let text = std::fs::read_to_string(&cir).unwrap();
    assert!(text.contains("100u"));
    let base = scenario_text_with(&cir);
    for (limits, code) in [
        ("max_making_current = 12.0\nmin_weld_margin = 1.0\n", 0),
        ("max_making_current = 5.0\n", 1),
        ("min_weld_margin = 1.0e6\n", 1),
    ] {
        let path = dir.path().join("limits.toml");
        std::fs::write(&path, format!("{base}\n[limits]\n{limits}")).unwrap();
        let out = cli()
            .args(["check", path.to_str().unwrap(), "--format", "json"])
            .output()
            .unwrap();
        assert_eq!(
            out.status.code(),
            Some(code),
            "{limits}: {}",
            String::from_utf8_lossy(&out.stdout)
        );
        let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert!(
            doc["run"]["makes"]
                .as_array()
                .is_some_and(|m| !m.is_empty()),
            "{doc}"
        );
    }
}

/// The built-in relay's scenario text with `netlist` as its circuit.
fn scenario_text_with(netlist: &Path) -> String {
    let cut = DEFAULT_SCENARIO_TOML.find("[circuit]").unwrap();
    format!(
        "{}[circuit]\nnetlist = {:?}\n",
        &DEFAULT_SCENARIO_TOML[..cut],
        netlist.display().to_string()
    )
}
