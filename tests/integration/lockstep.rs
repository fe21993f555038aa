//! The lock-step coupling through ngspice's shared library against the
//! passes it replaces: the same events on the bundled coil-driven
//! examples and coil parts switched onto their rated coil voltage (every
//! one of them with `CHATTERSPICE_LOCKSTEP_ALL=1`, before a release); one ngspice run; isolation from a simulator that crashes; and
//! the passes when the library is missing.

use std::path::{Path, PathBuf};

use chatterspice::chatter::Chatter;
use chatterspice::pipeline::{Coupled, Coupling, CouplingOptions, run_coupled};
use chatterspice::scenario::Scenario;

use crate::common;

/// Twice the passes' coupling tolerance: both runs are within one
/// tolerance of the coupled solution.
const AGREE: f64 = 2e-7;

fn run(scenario: &Scenario, coupling: Coupling) -> Coupled {
    let ng = common::ngspice().expect("ngspice");
    run_coupled(
        scenario,
        &ng,
        &CouplingOptions {
            coupling: Some(coupling),
            // The passes converged in their path too: the default path
            // leaves a bias of up to 0.2 µs on a long return flight.
            path_tolerance: chatterspice::pipeline::coupled::PATH_TOLERANCE / 100.0,
            ..CouplingOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("{coupling:?}: {}", common::chain(&e)))
}

/// Every impact and release time of `a` within [`AGREE`] of `b`'s, the
/// same number of each.
fn assert_same(what: &str, a: &Chatter, b: &Chatter) {
    assert_eq!(
        a.bounce_count, b.bounce_count,
        "{what}: bounces {a:?} vs {b:?}"
    );
    assert_eq!(a.impacts.len(), b.impacts.len(), "{what}: impacts");
    for (p, q) in a.impacts.iter().zip(&b.impacts) {
        let d = (p.impact_time - q.impact_time).abs();
        assert!(
            d <= AGREE,
            "{what}: impact {} vs {}",
            p.impact_time,
            q.impact_time
        );
        match (p.release_time, q.release_time) {
            (Some(r), Some(s)) => {
                assert!((r - s).abs() <= AGREE, "{what}: release {r} vs {s}");
            }
            (None, None) => {}
            other => panic!("{what}: releases {other:?}"),
        }
    }
}

fn compare(scenario: &Scenario, what: &str) {
    let lock = run(scenario, Coupling::LockStep);
    let passes = run(scenario, Coupling::Passes);
    assert_eq!(lock.iterations.len(), 1, "{what}: one ngspice run");
    assert_eq!(lock.iterations[0].scheme, Coupling::LockStep, "{what}");
    assert!(
        lock.iterations[0].change <= 1e-7,
        "{what}: {:?}",
        lock.iterations
    );
    assert!(passes.iterations.len() >= 2, "{what}");
    assert!(
        passes
            .iterations
            .iter()
            .all(|i| i.scheme == Coupling::Passes),
        "{what}"
    );
    assert!(
        !lock.chatter.impacts.is_empty(),
        "{what}: the relay must close for the comparison to mean anything"
    );
    assert_same(&format!("{what} (NO)"), &lock.chatter, &passes.chatter);
    assert_same(&format!("{what} (NC)"), &lock.back, &passes.back);
}

fn example(name: &str) -> Scenario {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/scenarios")
        .join(name);
    Scenario::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"))
}

macro_rules! examples {
    ($($test:ident: $file:literal,)*) => {$(
        #[test]
        fn $test() {
            let _ng = ngspice_or_skip!();
            compare(&example($file), $file);
        }
    )*};
}

// One example per kind of coupling: a diode-clamped driver, a ringing
// snubber that closes the relay again, an AC arc and a DC arc in the
// circuit. The driver circuits' own test runs both schemes on a dozen
// more drivers (dips, ramps, clamps).
examples! {
    lock_step_agrees_with_the_passes_on_relay_driver: "relay-driver.toml",
    lock_step_agrees_with_the_passes_on_relay_driver_snubber: "relay-driver-snubber.toml",
    lock_step_agrees_with_the_passes_on_mains_heater: "mains-heater.toml",
    lock_step_agrees_with_the_passes_on_dc_break: "dc-break.toml",
}

/// Coil examples that differ from a compared one only in a part the
/// comparison does not exercise: another suppression on a driver of the
/// same kind, another relay and load on the same coupling, or the same
/// arc element on another supply. Compared with every other coil example
/// by `CHATTERSPICE_LOCKSTEP_ALL=1` (scripts/release-checks).
const SAME_AS_COMPARED: [(&str, &str); 6] = [
    ("relay-driver-zener.toml", "relay-driver.toml"),
    ("solenoid.toml", "relay-driver.toml"),
    ("solenoid-diode.toml", "relay-driver.toml"),
    ("valve-24v.toml", "relay-driver.toml"),
    ("valve-24v-diode.toml", "relay-driver.toml"),
    ("life.toml", "dc-break.toml"),
];

/// Whether the release run (`CHATTERSPICE_LOCKSTEP_ALL=1`) compares every
/// coil example and every coil part, not only the ones that differ in kind.
fn compare_all() -> bool {
    std::env::var_os("CHATTERSPICE_LOCKSTEP_ALL").is_some_and(|v| v == "1")
}

#[test]
fn the_examples_like_a_compared_one_agree_in_a_release_run() {
    if !compare_all() {
        return;
    }
    let _ng = ngspice_or_skip!();
    for (name, _) in SAME_AS_COMPARED {
        compare(&example(name), name);
    }
}

/// Every bundled example with a `[coil]` has its test above, or is like
/// one that has.
#[test]
fn every_coil_example_is_compared() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios");
    let source = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/integration/lockstep.rs"),
    )
    .unwrap();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        if text.lines().any(|l| l.trim() == "[coil]") {
            let name = path.file_name().unwrap().to_str().unwrap();
            let like = SAME_AS_COMPARED.iter().find(|(n, _)| *n == name);
            let compared = |n: &str| source.contains(&format!("on_{}: \"{n}\"", test_name(n)));
            assert!(
                compared(name) || like.is_some_and(|(_, other)| compared(other)),
                "{name} has a [coil] and no lock-step comparison"
            );
        }
    }
}

/// The test name's tail for an example file: `valve-24v.toml` → `valve_24v`.
fn test_name(file: &str) -> String {
    file.trim_end_matches(".toml").replace('-', "_")
}

/// A part's coil switched onto its rated voltage by an ideal source, the
/// contact on a pull-up.
fn part_on_its_step(dir: &Path, name: &str, volts: f64) -> Scenario {
    let netlist = dir.join(format!("{name}.cir"));
    std::fs::write(
        &netlist,
        format!(
            "{name} on an ideal step of its rated coil voltage\n\
             V1 a 0 PWL(0 0 1n {volts})\n\
             X2 a 0 COIL\n\
             VDD vdd 0 DC 5\n\
             R_PU vdd in 10k\n\
             X1 in 0 CONTACT\n\
             .tran 1u 20m 0 2u\n\
             .end\n"
        ),
    )
    .unwrap();
    let origin: PathBuf = dir.join(format!("{name}.toml"));
    let text = format!(
        "base = \"part:{name}\"\n\n[simulation]\nt_end = 0.02\n\n[circuit]\nnetlist = \"{}\"\n\
         subckt = \"CONTACT\"\ncoil_subckt = \"COIL\"\n",
        netlist.file_name().unwrap().to_str().unwrap()
    );
    std::fs::write(&origin, &text).unwrap();
    Scenario::load(&origin).unwrap_or_else(|e| panic!("{name}: {}", common::chain(&e)))
}

/// The parts all share one structure (armature, blade, pole face,
/// Kelvin–Voigt surfaces) and differ in their numbers: the test suite
/// compares the one with the shortest time scales (a reed-sized signal
/// relay); `CHATTERSPICE_LOCKSTEP_ALL=1` compares all.
const PARTS_COMPARED: [&str; 1] = ["coto-9104-05"];

#[test]
fn lock_step_agrees_with_the_passes_on_coil_parts() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let mut compared = 0;
    let all = compare_all();
    for part in chatterspice::calibrate::parts::all() {
        if !all && !PARTS_COMPARED.contains(&part.name) {
            continue;
        }
        let scenario = part.load().unwrap();
        let Some(volts) = scenario
            .datasheet
            .as_ref()
            .and_then(|d| d.coil_voltage)
            .filter(|_| scenario.coil.is_some())
        else {
            continue;
        };
        let scenario = part_on_its_step(dir.path(), part.name, volts);
        compare(&scenario, part.name);
        compared += 1;
    }
    let expected = if all { 10 } else { PARTS_COMPARED.len() };
    assert!(compared >= expected, "{compared} coil parts compared");
}

/// A deck that crashes ngspice (a source written `dc 0 external`, which
/// ngspice 39 dies on) is an error of that run, not of the caller, which
/// goes on to run the next deck.
#[test]
fn a_simulator_that_crashes_takes_only_its_own_process() {
    let _ng = ngspice_or_skip!();
    let scenario = example("relay-driver.toml");
    let circuit = scenario.circuit.as_ref().unwrap();
    let text = std::fs::read_to_string(&circuit.netlist).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let netlist = dir.path().join("crash.cir");
    let crashing = text.replacen(".tran", "Vcrash crash 0 dc 0 external\n.tran", 1);
    assert_ne!(crashing, text);
    std::fs::write(&netlist, crashing).unwrap();
    let mut broken = scenario.clone();
    broken.circuit.as_mut().unwrap().netlist = netlist;
    let ng = common::ngspice().unwrap();
    let options = CouplingOptions {
        coupling: Some(Coupling::LockStep),
        ..CouplingOptions::default()
    };
    let err = run_coupled(&broken, &ng, &options).unwrap_err();
    let text = common::chain(&err);
    assert!(text.contains("died"), "{text}");
    // The caller is whole, and the next run works.
    let lock = run_coupled(&scenario, &ng, &options).unwrap();
    assert_eq!(lock.iterations.len(), 1);
}

/// Without the shared library every coupled run still works, by passes,
/// and says so once.
#[test]
fn without_the_shared_library_the_passes_run_and_say_so_once() {
    let _ng = ngspice_or_skip!();
    let scenario =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/relay-driver.toml");
    let out = assert_cmd::Command::cargo_bin("chatterspice")
        .unwrap()
        .env(
            chatterspice::spice::shared::LIBRARY_ENV,
            "/nonexistent/libngspice.so.0",
        )
        .args(["run", scenario.to_str().unwrap(), "--format", "json"])
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let runs = v["coupling"].as_array().unwrap();
    assert!(runs.len() >= 2, "{runs:?}");
    assert!(runs.iter().all(|r| r["scheme"] == "passes"));
    let warnings = v["warnings"].to_string();
    assert_eq!(
        warnings.matches("the coupling ran as passes").count(),
        1,
        "said once: {warnings}"
    );
    assert!(
        warnings.contains("apt-get install -y libngspice0"),
        "{warnings}"
    );
}
