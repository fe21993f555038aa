//! The whole pipeline on real ngspice: simulated waveforms against the
//! bounce counts the mechanics predicts, with the expected counts worked
//! out in each test from the chatter and the circuit's own values.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use crate::common;

use std::path::{Path, PathBuf};

use chatterspice::chatter::{Chatter, ContactState};
use chatterspice::pipeline::{self, RunOptions, RunResult};
use chatterspice::scenario::{DEFAULT_SCENARIO_TOML, Scenario};
use chatterspice::spice::Ngspice;

fn data(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The built-in relay with its `[circuit]` and `[[probe]]` replaced.
fn default_relay_on(netlist: &Path, probes: &str) -> Scenario {
    let cut = DEFAULT_SCENARIO_TOML
        .find("[circuit]")
        .expect("the default scenario has a [circuit]");
    let text = format!(
        "{}[circuit]\nnetlist = {:?}\n\n{probes}",
        &DEFAULT_SCENARIO_TOML[..cut],
        netlist.display().to_string()
    );
    Scenario::parse(&text, &data("tests/data/run/scenario.toml")).unwrap()
}

fn run(ng: &Ngspice, scenario: &Scenario) -> RunResult {
    pipeline::run(scenario, ng, &RunOptions::default())
        .unwrap_or_else(|e| panic!("{}", common::chain(&e)))
}

/// Durations of the openings between the first impact and settling, s.
fn bounce_openings(chatter: &Chatter) -> Vec<f64> {
    let first = chatter.first_impact.expect("the relay closes");
    chatter
        .intervals
        .iter()
        .filter(|iv| iv.state == ContactState::Open && iv.start > first)
        .map(|iv| iv.end - iv.start)
        .collect()
}

#[test]
fn with_no_filter_every_bounce_is_an_edge_pair() {
    let ng = ngspice_or_skip!();
    let scenario = default_relay_on(
        &data("tests/data/run/pullup.cir"),
        "[[probe]]\nsignal = \"v(sw)\"\nlow = 0.99\nhigh = 2.31\n",
    );
    let result = run(&ng, &scenario);
    let chatter = &result.chatter;
    assert_eq!(chatter.bounce_count, 5, "the default relay bounces 5 times");
    assert_eq!(result.waveform.merged_openings(), 0);
    let probe = &result.probes[0].analysis;
    assert_eq!(probe.edges, 1 + 2 * chatter.bounce_count);
    assert_eq!(probe.glitches, 2 * chatter.bounce_count);
    // The first edge is the first make, within the edge time and one step.
    let first = chatter.first_impact.unwrap();
    let edge_at = probe.first_edge.unwrap();
    assert!(
        edge_at >= first && edge_at - first < 2.0 * scenario.contact.edge_time,
        "first edge {edge_at} vs first impact {first}"
    );
    // The last edge is the final make.
    let settle = chatter.settle_time.unwrap();
    let last = probe.last_edge.unwrap();
    assert!(last >= settle && last - settle < 2.0 * scenario.contact.edge_time);

    // The ideal contact shows one edge, so the bounce added 2 per bounce.
    let cmp = result.probes[0].comparison.as_ref().unwrap();
    assert_eq!(result.probes[0].ideal.as_ref().unwrap().edges, 1);
    assert_eq!(cmp.extra_edges, 2 * chatter.bounce_count as i64);
    assert!((cmp.settle_delay.unwrap() - (settle - first)).abs() < 2.0 * 1e-8);

    // The debounce figures: a lockout from the first make to the last, and
    // the longest stable stretch inside the chatter, which with no filter
    // is the mechanics' longest interval between a make and a break, or a
    // break and the next make.
    let debounce = probe.debounce.expect("edges, so figures");
    let edge = 2.0 * scenario.contact.edge_time;
    assert!(
        (debounce.lockout - (settle - first)).abs() < edge,
        "{debounce:?}"
    );
    let longest = chatter
        .intervals
        .iter()
        .filter(|iv| iv.start >= first && iv.end <= settle)
        .map(|iv| iv.end - iv.start)
        .fold(0.0, f64::max);
    assert!(
        (debounce.stable_for - longest).abs() < edge,
        "{debounce:?} vs {longest}"
    );
}

#[test]
fn an_rc_filter_shows_exactly_the_openings_longer_than_its_threshold_time() {
    let ng = ngspice_or_skip!();
    let scenario = Scenario::builtin_default();
    let result = run(&ng, &scenario);

    // netlists/mcu_input.cir: while open, the pin charges through
    // R_PU + R_F into C_F from (almost) 0 V towards VDD; it reaches the
    // high threshold after tau·ln(VDD / (VDD − V_high)).
    let (r_pu, r_f, c_f, vdd) = (10e3, 1e3, 8.2e-9, 3.3);
    let high = scenario.probes[0].high;
    let threshold = (r_pu + r_f) * c_f * (vdd / (vdd - high)).ln();
    let openings = bounce_openings(&result.chatter);
    let shown = openings.iter().filter(|&&d| d > threshold).count();
    // Not a trivial case: some openings show and some do not, and none is
    // so close to the threshold that the edge time or a residual charge
    // could decide it.
    assert!(
        shown > 0 && shown < openings.len(),
        "{openings:?} vs {threshold}"
    );
    for d in &openings {
        assert!(
            (d / threshold - 1.0).abs() > 0.05,
            "{d} too close to {threshold}"
        );
    }
    let probe = &result.probes[0].analysis;
    assert_eq!(
        probe.edges,
        1 + 2 * shown,
        "openings {openings:?}, threshold {threshold}"
    );
    assert_eq!(probe.signal, "v(in)");
}

#[test]
fn the_lamp_draws_its_inrush_at_every_closure() {
    let ng = ngspice_or_skip!();
    let scenario = Scenario::load(&data("examples/scenarios/lamp.toml")).unwrap();
    let result = run(&ng, &scenario);
    let chatter = &result.chatter;
    assert!(chatter.bounce_count >= 3);

    let current = &result.probes[0];
    assert_eq!(current.probe.signal, "i(v_sense)");
    // Every closure is a pulse of inrush; each break also rings the
    // current through C_PAR at 16 MHz, past both thresholds, so the bounced
    // run shows more edges than two per bounce. The ideal contact's one
    // make shows exactly one.
    assert!(current.analysis.edges > 1 + 2 * chatter.bounce_count);
    assert_eq!(current.ideal.as_ref().unwrap().edges, 1);
    let rising: Vec<f64> = current
        .analysis
        .transitions
        .iter()
        .filter(|e| e.direction == chatterspice::analysis::Direction::Rising)
        .map(|e| e.time)
        .collect();
    for (start, end) in chatterspice::analysis::closures(chatter) {
        assert!(
            rising.iter().any(|&t| t >= start && t <= end),
            "no rising edge in the closure {start}..{end}"
        );
    }
    // netlists/lamp.cir: 12 V over R_SRC + R_LAMP + the contact's
    // r_closed; the wiring inductance's L/R = 0.4 µs is over long before
    // any closure ends.
    let inrush = 12.0 / (0.02 + 2.4 + scenario.contact.r_closed);
    let per_closure = &current.analysis.current.as_ref().unwrap().per_closure;
    assert_eq!(per_closure.len(), chatter.bounce_count + 1);
    for k in per_closure {
        // A break rings the current past the inrush; the closure's peak
        // is the inrush or more, never less.
        assert!(
            k.peak > 0.99 * inrush,
            "closure at {}: peak {} A",
            k.start,
            k.peak
        );
        // The charge is the inrush over the closure, to the edge and the
        // inductive rise.
        let expected = inrush * (k.end - k.start);
        if k.end < chatter.t_end.min(result.deck.tran.tstop) {
            assert!(
                (k.charge / expected - 1.0).abs() < 0.02,
                "{} vs {expected}",
                k.charge
            );
        }
    }
    // Each break interrupts ~5 A in the wiring inductance: the contact
    // voltage rings far above the supply.
    let across = &result.probes[1].analysis;
    assert!(across.max > 100.0, "break spike only {} V", across.max);
}

#[test]
fn the_capacitive_load_takes_its_charge_in_several_bites() {
    let ng = ngspice_or_skip!();
    let scenario = Scenario::load(&data("examples/scenarios/capacitive-load.toml")).unwrap();
    let result = run(&ng, &scenario);
    let current = result.probes[0].analysis.current.as_ref().unwrap();
    let bites = &current.per_closure;
    assert_eq!(bites.len(), result.chatter.bounce_count + 1);
    // Every closure charges the capacitor, each less than the one before
    // it while the capacitor fills.
    assert!(bites.iter().all(|k| k.charge > 0.0));
    assert!(bites[1].charge < bites[0].charge);

    // Charge balance, from netlists/capacitive_load.cir: what went through
    // the contact is what the capacitor holds at the end plus what the
    // 48 Ω load drew meanwhile.
    let plot = &result.simulation.plot;
    let time = match plot.scale() {
        Some(chatterspice::rawfile::Vector::Real(t)) => t,
        _ => panic!("no time scale"),
    };
    let v_load = plot.real("v(load)").unwrap();
    let v_esr = plot.real("v(esr)").unwrap();
    let end = time.len() - 1;
    let held = 470e-6 * (v_load[end] - v_esr[end]);
    let drawn: f64 = (1..time.len())
        .map(|i| 0.5 * (v_load[i] + v_load[i - 1]) / 48.0 * (time[i] - time[i - 1]))
        .sum();
    assert!(
        (current.charge / (held + drawn) - 1.0).abs() < 1e-3,
        "{} C through the contact vs {} C held + {} C drawn",
        current.charge,
        held,
        drawn
    );
    // The ideal contact delivers it in one closure.
    let ideal = result.probes[0].ideal.as_ref().unwrap();
    assert_eq!(ideal.current.as_ref().unwrap().per_closure.len(), 1);
    // The capacitor voltage itself crosses its thresholds once: the bounce
    // adds no edge there.
    let v = &result.probes[1];
    assert_eq!(v.analysis.edges, 1);
    assert_eq!(v.comparison.as_ref().unwrap().extra_edges, 0);
}

#[test]
fn a_holm_contact_settles_at_the_resistance_of_its_static_force() {
    let ng = ngspice_or_skip!();
    let base = default_relay_on(
        &data("tests/data/run/pullup.cir"),
        "[[probe]]\nsignal = \"v(sw)\"\nlow = 0.99\nhigh = 2.31\n",
    );
    // A poor contact, so that the force-dependent resistance shows
    // against the 10 kΩ pull-up: 100 Ω at 0.1 N, plastic spots.
    let mut scenario = base;
    scenario.contact.holm = Some(chatterspice::scenario::HolmSection {
        r_film: 1.0,
        r_ref: 100.0,
        f_ref: 0.1,
        exponent: 0.5,
    });
    let result = run(&ng, &scenario);
    let probe = &result.probes[0].analysis;
    assert_eq!(probe.edges, 1 + 2 * result.chatter.bounce_count);

    // Settled: spring and surface share the overtravel (default relay:
    // s = 5000 N/m, f = 1 N, g = 0.14 mm, s0 = 5e5 N/m), and the divider
    // with the pull-up gives the node voltage.
    let force: f64 = 5e5 * (1.0 - 5000.0 * 1.4e-4) / (5000.0 + 5e5);
    let r = 1.0 + 100.0 * (0.1 / force).sqrt();
    let expected = 3.3 * r / (r + 10e3);
    assert!(
        (probe.final_value / expected - 1.0).abs() < 1e-3,
        "{} V vs {expected} V",
        probe.final_value
    );
    // The ideal contact closes at that same settled resistance.
    let ideal = result.probes[0].ideal.as_ref().unwrap();
    assert!((ideal.final_value / expected - 1.0).abs() < 1e-3);
    // While bouncing, the force rises above its settled value, so the
    // node dips below its settled voltage.
    assert!(probe.min < 0.9 * expected, "{} vs {expected}", probe.min);
}
