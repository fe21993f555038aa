//! A library of relay driver circuits around the example 5 V relay
//! (`examples/scenarios/relay-driver.toml`): suppressions, supplies that
//! dip, brown out or ramp, PWM holding, a rectified AC coil, two drives
//! in a row. For each, the test works out the operations it expects on
//! its own, from the circuit's designed drive (the instants its driver or
//! supply crosses the relay's drop-out level) and the contact's intervals
//! in the run, and holds both coupling schemes (lock-step and passes)
//! against it: the number of operations, each energisation and
//! de-energisation, each closing's first make and bounces, and every
//! re-closure with the coil off. (The passes do not converge on the
//! rectified AC coil within their 20 iterations: that one runs lock-step
//! only.)

use std::path::Path;

use chatterspice::chatter::{Chatter, ContactState};
use chatterspice::coil::Operation;
use chatterspice::pipeline::{Coupled, Coupling, CouplingOptions, run_coupled};
use chatterspice::scenario::Scenario;

use crate::common;

/// The base driver: an NPN low-side switch from 5 V; `drive` is the base
/// drive's source, `suppression` what is across the coil, `supply` the
/// VCC source.
fn netlist(supply: &str, drive: &str, suppression: &str, stop: f64) -> String {
    format!(
        "relay driver\n{supply}\n{drive}\nR_B drv base 2.2k\nQ1 col base 0 QSW\n\
         X_COIL vcc col COIL\n{suppression}\n\
         V33 v33 0 DC 3.3\nR_PU v33 in 10k\nX_RELAY in 0 CONTACT\n\
         .model QSW NPN(IS=1e-14 BF=200 VAF=100 CJE=25p CJC=8p TF=0.4n TR=50n RB=10 RC=1)\n\
         .model DFLY D(IS=2.5n RS=0.6 N=1.75 CJO=4p TT=6n BV=100)\n\
         .model DZ24 D(IS=1e-12 RS=2 N=1 BV=24 IBV=5m CJO=50p)\n\
         .model NM NMOS(LEVEL=1 VTO=2 KP=0.5)\n\
         .tran 1u {stop} 0 5u\n.end\n"
    )
}

const DIODE: &str = "D_FLY col vcc DFLY";
const PULSE_20MS: &str = "VDRV drv 0 PULSE(0 5 0.1m 1u 1u 19.9m 100m)";

/// One driver circuit and the energisations its design makes: each
/// (on, off) in s, `off` `None` when the drive stays on to the end.
struct Driver {
    name: &'static str,
    netlist: String,
    stop: f64,
    windows: Vec<(f64, Option<f64>)>,
}

fn drivers(drop_out: f64) -> Vec<Driver> {
    let vcc = "VCC vcc 0 DC 5";
    let d = |name, netlist, stop, windows| Driver {
        name,
        netlist,
        stop,
        windows,
    };
    // A supply ramped 0 → 5 V over 20 ms: the coil sees it less the
    // transistor's saturation (some 0.1 V) once the drive is on; it is
    // energised where that crosses drop-out.
    let ramp_on = (drop_out + 0.1) / 5.0 * 20e-3;
    vec![
        d(
            "npn_diode",
            netlist(vcc, PULSE_20MS, DIODE, 50e-3),
            50e-3,
            vec![(0.1e-3, Some(20e-3))],
        ),
        d(
            "mosfet_diode",
            netlist(vcc, PULSE_20MS, DIODE, 50e-3).replace(
                "R_B drv base 2.2k\nQ1 col base 0 QSW",
                "R_G drv gate 100\nM1 col gate 0 0 NM",
            ),
            50e-3,
            vec![(0.1e-3, Some(20e-3))],
        ),
        d(
            "zener_clamp",
            netlist(vcc, PULSE_20MS, "D_Z 0 col DZ24", 50e-3),
            50e-3,
            vec![(0.1e-3, Some(20e-3))],
        ),
        d(
            "diode_zener",
            netlist(
                vcc,
                PULSE_20MS,
                "D_FLY col clamp DFLY\nD_Z vcc clamp DZ24",
                50e-3,
            ),
            50e-3,
            vec![(0.1e-3, Some(20e-3))],
        ),
        d(
            "rc_snubber",
            netlist(vcc, PULSE_20MS, "R_SN vcc sn 100\nC_SN sn col 470n", 50e-3),
            50e-3,
            vec![(0.1e-3, Some(20e-3))],
        ),
        d(
            "tvs",
            netlist(vcc, PULSE_20MS, "D_T1 col tv DZ24\nD_T2 vcc tv DZ24", 50e-3),
            50e-3,
            vec![(0.1e-3, Some(20e-3))],
        ),
        d(
            "supply_dip_holds",
            netlist(
                "VCC vcc 0 PWL(0 5 12m 5 12.01m 1.5 14m 1.5 14.01m 5)",
                "VDRV drv 0 PULSE(0 5 0.1m 1u 1u 29.9m 100m)",
                DIODE,
                50e-3,
            ),
            50e-3,
            vec![(0.1e-3, Some(30e-3))],
        ),
        d(
            "brown_out_releases",
            netlist(
                "VCC vcc 0 PWL(0 5 12m 5 12.01m 0.2 27m 0.2 27.01m 5)",
                "VDRV drv 0 PULSE(0 5 0.1m 1u 1u 39.9m 100m)",
                DIODE,
                70e-3,
            ),
            70e-3,
            vec![(0.1e-3, Some(12e-3)), (27e-3, Some(40e-3))],
        ),
        d(
            "slow_ramp",
            netlist(
                "VCC vcc 0 PWL(0 0 20m 5)",
                "VDRV drv 0 PULSE(0 5 0.1m 1u 1u 29.9m 100m)",
                DIODE,
                50e-3,
            ),
            50e-3,
            vec![(ramp_on, Some(30e-3))],
        ),
        d(
            "pwm_hold",
            netlist(
                vcc,
                "BDRV drv 0 V = time < 10e-3 ? 5 : (time < 30e-3 ? (sin(6.2832 * 5e3 * time) > 0 ? 5 : 0) : 0)",
                DIODE,
                50e-3,
            ),
            50e-3,
            vec![(0.0, Some(30e-3))],
        ),
        d(
            "ac_bridge",
            "relay on a bridge-rectified AC supply\n\
             BAC ac1 ac2 V = time > 5e-3 ? (time < 45e-3 ? 7.5 * sin(6.2832 * 50 * time) : 0) : 0\n\
             R_AC ac2 0 1meg\n\
             D1 ac1 vcc DFLY\nD2 ac2 vcc DFLY\nD3 col ac1 DFLY\nD4 col ac2 DFLY\n\
             X_COIL vcc col COIL\nD_FLY col vcc DFLY\nR_REF col 0 1meg\n\
             V33 v33 0 DC 3.3\nR_PU v33 in 10k\nX_RELAY in 0 CONTACT\n\
             .model DFLY D(IS=2.5n RS=0.6 N=1.75 CJO=4p TT=6n BV=100)\n\
             .tran 1u 80m 0 5u\n.end\n"
                .to_owned(),
            80e-3,
            vec![(5e-3, Some(45e-3))],
        ),
        d(
            "two_drives",
            netlist(
                vcc,
                "VDRV drv 0 PULSE(0 5 0.1m 1u 1u 14.9m 40m)",
                DIODE,
                70e-3,
            ),
            70e-3,
            vec![(0.1e-3, Some(15e-3)), (40.1e-3, Some(55e-3))],
        ),
    ]
}

/// An operation as the test expects it: energised at `on` (`None` for a
/// re-closure with the coil off), the first make and the bounces.
#[derive(Debug)]
struct Expected {
    on: Option<f64>,
    off: Option<f64>,
    first_make: f64,
    bounces: usize,
}

/// The operations `windows` and the contact's closed intervals in
/// `chatter` make: a closing of each energisation (every make from its
/// start until the first release after its end), and a re-closure for
/// makes after that release while still de-energised.
fn expected(windows: &[(f64, Option<f64>)], chatter: &Chatter) -> Vec<Expected> {
    let closed: Vec<(f64, f64)> = chatter
        .intervals
        .iter()
        .filter(|i| i.state == ContactState::Closed)
        .map(|i| (i.start, i.end))
        .collect();
    let mut out = Vec::new();
    for (k, &(on, off)) in windows.iter().enumerate() {
        let until = windows.get(k + 1).map_or(f64::INFINITY, |w| w.0);
        let ours: Vec<(f64, f64)> = closed
            .iter()
            .copied()
            .filter(|&(start, _)| start >= on && start < until)
            .collect();
        let breaking = off.and_then(|off| ours.iter().position(|&(_, end)| end >= off));
        let (closing, again) = match breaking {
            Some(b) if b + 1 < ours.len() && ours[b].1 < chatter.t_end => ours.split_at(b + 1),
            _ => (&ours[..], &[][..]),
        };
        if let Some(&(first, _)) = closing.first() {
            out.push(Expected {
                on: Some(on),
                off,
                first_make: first,
                bounces: closing.len() - 1,
            });
        }
        if let Some(&(first, _)) = again.first() {
            out.push(Expected {
                on: None,
                off: None,
                first_make: first,
                bounces: again.len() - 1,
            });
        }
    }
    out
}

fn run(scenario: &Scenario, coupling: Coupling) -> Coupled {
    let ng = common::ngspice().expect("ngspice");
    run_coupled(
        scenario,
        &ng,
        &CouplingOptions {
            coupling: Some(coupling),
            ..CouplingOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{coupling:?}: {}", common::chain(&e)))
}

fn scenario(dir: &Path, driver: &Driver) -> Scenario {
    let base = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/relay-driver.toml"),
    )
    .unwrap();
    let cut = base.find("[simulation]").unwrap();
    let netlist = dir.join(format!("{}.cir", driver.name));
    std::fs::write(&netlist, &driver.netlist).unwrap();
    let text = format!(
        "{}[simulation]\nt_end = {}\n\n[circuit]\nnetlist = \"{}.cir\"\nsubckt = \"CONTACT\"\n\
         coil_subckt = \"COIL\"\n",
        &base[..cut],
        driver.stop,
        driver.name
    );
    let path = dir.join(format!("{}.toml", driver.name));
    std::fs::write(&path, &text).unwrap();
    Scenario::load(&path).unwrap_or_else(|e| panic!("{}: {}", driver.name, common::chain(&e)))
}

/// s: how close an energisation must come to the design's edge (the
/// transistor's switching and the diode drops move it by µs; the
/// ramp's crossing by the saturation voltage's spread).
const EDGE: f64 = 0.3e-3;

fn assert_matches(name: &str, scheme: Coupling, ops: &[Operation], want: &[Expected]) {
    let what = format!("{name} ({scheme:?})");
    assert_eq!(
        ops.len(),
        want.len(),
        "{what}: {ops:#?}\nexpected {want:#?}"
    );
    for (k, (op, w)) in ops.iter().zip(want).enumerate() {
        let at = format!("{what}, operation {}", k + 1);
        match w.on {
            Some(on) => {
                let got = op
                    .coil_on
                    .unwrap_or_else(|| panic!("{at}: no coil on: {op:?}"));
                assert!((got - on).abs() < EDGE, "{at}: on at {got}, designed {on}");
                assert!(!op.is_reclosure(), "{at}");
            }
            None => assert!(op.is_reclosure(), "{at}: a re-closure expected: {op:?}"),
        }
        match (w.off, op.coil_off) {
            (Some(off), Some(got)) => {
                assert!(
                    (got - off).abs() < EDGE,
                    "{at}: off at {got}, designed {off}"
                )
            }
            (None, None) => {}
            (a, b) => panic!("{at}: off {b:?}, designed {a:?}"),
        }
        let first = op.stroke.first_make.unwrap();
        assert!(
            (first - w.first_make).abs() < 1e-9,
            "{at}: first make {first}"
        );
        assert_eq!(op.stroke.bounces, w.bounces, "{at}: bounces");
    }
}

#[test]
fn every_driver_circuit_is_read_as_the_operations_it_makes() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let probe = scenario(dir.path(), &drivers(1.0)[0]);
    let levels = run(&probe, Coupling::LockStep).levels;
    // The reference relay drops out near 1 V (model: 0.89 V).
    assert!((0.5..1.5).contains(&levels.drop_out_voltage), "{levels:?}");
    assert!(
        levels.pick_up_voltage > levels.drop_out_voltage,
        "{levels:?}"
    );
    let all = drivers(levels.drop_out_voltage);
    assert!(all.len() >= 12);
    let mut reclosures = 0;
    for driver in &all {
        let scenario = scenario(dir.path(), driver);
        // Both couplings read operations the same way (the library does it
        // on the coupled result). The lock-step test compares the passes on
        // a plain pulse and on a ringing snubber that re-closes; here they
        // also run on a supply dip (1 s). The release checks
        // (`CHATTERSPICE_LOCKSTEP_ALL=1`) run them on every driver (the PWM
        // hold alone takes 13 s) but the rectified AC coil, whose ripple the
        // passes' waveform relaxation does not settle within their 20
        // iterations.
        let passes_too = if std::env::var_os("CHATTERSPICE_LOCKSTEP_ALL").is_some_and(|v| v == "1")
        {
            driver.name != "ac_bridge"
        } else {
            ["supply_dip_holds"].contains(&driver.name)
        };
        let schemes: &[Coupling] = if passes_too {
            &[Coupling::LockStep, Coupling::Passes]
        } else {
            &[Coupling::LockStep]
        };
        for &scheme in schemes {
            let coupled = run(&scenario, scheme);
            let want = expected(&driver.windows, &coupled.chatter);
            assert!(!want.is_empty(), "{}: the relay never closes", driver.name);
            assert_matches(driver.name, scheme, &coupled.operations, &want);
            reclosures += want.iter().filter(|w| w.on.is_none()).count();
        }
    }
    // The snubber's ringing pulls the armature in again.
    assert!(reclosures >= 1, "{reclosures}");
}
