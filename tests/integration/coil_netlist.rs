//! The coil subcircuit in real ngspice: with the armature held, the plain
//! RL step; with the armature moving, the back-EMF of a changing
//! inductance, against the closed form of a flux linkage held constant.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use crate::common;

use chatterspice::coil::MU0;
use chatterspice::netlist::coil::coil_include;
use chatterspice::rawfile::Vector;
use chatterspice::scenario::CoilSection;
use chatterspice::spice::{RunRequest, Runner};

/// The coil of docs/model.md §7's reference case.
const COIL: CoilSection = CoilSection {
    resistance: 70.0,
    turns: 3000,
    pole_area: 2e-5,
    air_gap: 6e-4,
    iron_gap: 5e-5,
    drive_voltage: None,
};

fn inductance(x: f64) -> f64 {
    MU0 * 9e6 * 2e-5 / (6e-4 - x + 5e-5)
}

/// (time, coil current) of `deck` with the coil following `trajectory`.
fn current(deck: &str, trajectory: &[(f64, f64)]) -> Option<(Vec<f64>, Vec<f64>)> {
    let ng = common::ngspice()?;
    let mut req = RunRequest::new(deck);
    req.includes.push((
        "coil.inc".into(),
        coil_include(&COIL, "COIL", trajectory).unwrap(),
    ));
    let out = ng.run(&req).unwrap();
    let plot = out.raw.plot_named("transient analysis").unwrap();
    let time = match plot.scale() {
        Some(Vector::Real(t)) => t.to_vec(),
        _ => panic!("no time"),
    };
    Some((time, plot.real("i(v.x2.vi)").unwrap().to_vec()))
}

#[test]
fn a_held_armature_is_the_plain_rl_step() {
    let deck = "coil held\n.include coil.inc\nV1 a 0 PWL(0 0 1n 5)\nX2 a 0 COIL\n\
                .tran 10u 20m 0 10u\n.end\n";
    let Some((t, i)) = current(deck, &[(0.0, 0.0), (1.0, 0.0)]) else {
        return;
    };
    let tau = inductance(0.0) / 70.0;
    let mut worst: f64 = 0.0;
    for (t, i) in t.iter().zip(&i) {
        let exact = 5.0 / 70.0 * (1.0 - (-(t - 1e-9).max(0.0) / tau).exp());
        worst = worst.max((i - exact).abs());
    }
    // ngspice's RELTOL (1e-3) of the 71 mA final current.
    assert!(worst < 1e-3 * 5.0 / 70.0, "worst error {worst} A");
}

#[test]
fn a_moving_armature_changes_the_current_at_constant_flux() {
    // Drive the coil to a steady current, then close the armature fast:
    // over a time much shorter than L/R the flux linkage ψ = L·i stays
    // put, so the current falls as the inductance rises (the pull-in dip).
    let deck = "coil closing\n.include coil.inc\nV1 a 0 DC 5\nX2 a 0 COIL\n\
                .tran 1u 20.2m 0 1u\n.end\n";
    // Held until 20 ms (five L/R: steady), then closed by 0.4 mm in 20 µs.
    let trajectory = [(0.0, 0.0), (20e-3, 0.0), (20.02e-3, 4e-4), (1.0, 4e-4)];
    let Some((t, i)) = current(deck, &trajectory) else {
        return;
    };
    let at = |time: f64| {
        let k = t.partition_point(|&x| x < time);
        i[k]
    };
    let before = at(19.999e-3);
    let after = at(20.021e-3);
    // Steady state: V/R (the DC operating point makes the coil a short).
    assert!((before - 5.0 / 70.0).abs() < 1e-6, "{before}");
    // Flux conserved over 20 µs ≪ L/R = 5 ms, to the decay in that time.
    let expected = before * inductance(0.0) / inductance(4e-4);
    assert!(
        (after / expected - 1.0).abs() < 0.01,
        "{after} vs {expected}"
    );
}

/// ms from the driver's turn-off (20 ms) until the coil current of
/// `netlist` (from netlists/) falls to half its on value, with the
/// armature held closed and the contact open.
fn decay_time(netlist: &str) -> Option<f64> {
    let ng = common::ngspice()?;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("netlists")
        .join(netlist);
    let text = std::fs::read_to_string(&path).unwrap();
    let open = chatterspice::waveform::Waveform::from_intervals(
        &[chatterspice::Interval {
            state: chatterspice::ContactState::Open,
            start: 0.0,
            end: 0.05,
        }],
        &chatterspice::waveform::ContactModel {
            r_closed: 0.05,
            r_open: 1e9,
            edge_time: 1e-8,
        },
    )
    .unwrap();
    let contact = chatterspice::netlist::contact_include(
        &open,
        "CONTACT",
        chatterspice::netlist::ContactElement::Pwl,
    )
    .unwrap();
    let deck = chatterspice::netlist::prepare_deck(&chatterspice::netlist::DeckRequest {
        netlist_text: &text,
        netlist_path: &path,
        include_file_name: "contact.inc",
        subckt: "CONTACT",
        coil: Some(("coil.inc", "COIL")),
        probes: &[],
        chatter_end: 0.0,
        stop_at_least: 0.0,
        options: &[],
    })
    .unwrap();
    let mut req = RunRequest::new(deck.text);
    req.includes.push(("contact.inc".into(), contact.text));
    // Held closed: the inductance of the closed armature (x = g).
    req.includes.push((
        "coil.inc".into(),
        coil_include(&COIL, "COIL", &[(0.0, 4.5e-4)]).unwrap(),
    ));
    let out = ng.run(&req).unwrap();
    let plot = out.raw.plot_named("transient analysis").unwrap();
    let t = match plot.scale() {
        Some(Vector::Real(t)) => t,
        _ => panic!("no time"),
    };
    let i = plot.real("i(v.x_coil.vi)").unwrap();
    let on = i[t.partition_point(|&x| x < 19.9e-3)];
    // Closed, L = 1.13 H: τ = L/R = 16 ms, so after 19.8 ms on the current
    // has reached 1 − e^(−1.24) of V/R.
    let expected = 5.0 / 70.0 * (1.0 - (-19.8e-3 / (1.131 / 70.0f64)).exp());
    assert!(
        (on / expected - 1.0).abs() < 0.05,
        "on current {on} vs {expected}"
    );
    let k = (0..t.len())
        .find(|&k| t[k] > 20e-3 && i[k] < 0.5 * on)
        .expect("the current decays");
    Some((t[k] - 20e-3) * 1e3)
}

#[test]
fn a_zener_clamp_lets_the_coil_current_die_much_faster_than_a_plain_diode() {
    let (Some(diode), Some(zener)) = (
        decay_time("relay_driver_diode.cir"),
        decay_time("relay_driver_zener.cir"),
    ) else {
        return;
    };
    // A plain diode: the coil's own L/R (L ≈ 0.5 H closed, R = 70 Ω plus
    // the diode): about ln(10)·τ ≈ 15 ms. The zener clamp: ≪ 1 ms.
    assert!(diode > 3.0 * zener, "diode {diode} ms, zener {zener} ms");
    assert!(
        diode > 5.0 && zener < 2.0,
        "diode {diode} ms, zener {zener} ms"
    );
}
