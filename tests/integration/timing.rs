//! Datasheet timing (IEC 61810): every reported time of an operation counts
//! from the moment the coil is energized, so moving the driver's pulse in
//! the netlist moves the simulated instants but changes no reported time.

use crate::common;

use std::path::Path;

use assert_cmd::Command;
use serde_json::Value;

/// The zener-clamped relay driver with its drive pulse starting at
/// `delay_ms`, as a scenario in `dir`; limits set so that `check` reports
/// every closing time.
fn driver(dir: &Path, delay_ms: f64) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let netlist = std::fs::read_to_string(root.join("netlists/relay_driver_zener.cir")).unwrap();
    let pulse = "PULSE(0 5 0.1m 1u 1u 19.9m 100m)";
    assert!(
        netlist.contains(pulse),
        "the bundled driver's pulse changed"
    );
    let shifted = netlist.replace(pulse, &format!("PULSE(0 5 {delay_ms}m 1u 1u 19.9m 100m)"));
    std::fs::write(dir.join("driver.cir"), shifted).unwrap();
    let scenario =
        std::fs::read_to_string(root.join("examples/scenarios/relay-driver-zener.toml")).unwrap();
    let scenario = scenario.replace("../../netlists/relay_driver_zener.cir", "driver.cir");
    let (start, end) = (
        scenario.find("[limits]").unwrap(),
        scenario.find("[[probe]]").unwrap(),
    );
    let text = format!(
        "{}[limits]\nmax_operate_time = 1.0\nmax_first_make = 1.0\nmax_settle_time = 1.0\n\
         max_bounce_time = 1.0\nmax_release_time = 1.0\n\n{}",
        &scenario[..start],
        &scenario[end..]
    );
    let path = dir.join("relay.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn check_json(path: &Path) -> Value {
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["check", path.to_str().unwrap(), "--format", "json"])
        .assert()
        .code(0);
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

fn actual(v: &Value, key: &str) -> f64 {
    v["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["key"] == key)
        .unwrap_or_else(|| panic!("no check {key}"))["actual"]
        .as_f64()
        .unwrap()
}

#[test]
fn shifting_the_drive_pulse_changes_no_reported_time() {
    let Some(_) = common::ngspice() else { return };
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let early = check_json(&driver(a.path(), 0.1));
    let late = check_json(&driver(b.path(), 2.1));
    // The instants in simulation time moved with the pulse…
    let first = |v: &Value| v["bounce"]["first_impact"].as_f64().unwrap();
    let moved = first(&late) - first(&early);
    assert!((moved - 2e-3).abs() < 5e-6, "first impact moved {moved} s");
    // …the datasheet times did not: not in the check, the run's timing,
    // nor its operations.
    let tolerance = 2e-6;
    for key in [
        "limits.max_operate_time",
        "limits.max_first_make",
        "limits.max_settle_time",
        "limits.max_bounce_time",
        "limits.max_release_time",
    ] {
        let (x, y) = (actual(&early, key), actual(&late, key));
        assert!((x - y).abs() < tolerance, "{key}: {x} vs {y}");
    }
    for key in ["operate_time", "bounce_time", "settle_time"] {
        let (x, y) = (&early["timing"][key], &late["timing"][key]);
        assert!(
            (x.as_f64().unwrap() - y.as_f64().unwrap()).abs() < tolerance,
            "timing.{key}: {x} vs {y}"
        );
    }
    for key in [
        "operate_time",
        "first_make_time",
        "settle_time",
        "bounce_time",
        "release_time",
    ] {
        let (x, y) = (
            &early["run"]["operations"][0][key],
            &late["run"]["operations"][0][key],
        );
        assert!(
            (x.as_f64().unwrap() - y.as_f64().unwrap()).abs() < tolerance,
            "operations[0].{key}: {x} vs {y}"
        );
    }
    // Operate time is coil on → first make, bounce excluded.
    let op = &early["run"]["operations"][0];
    let expected = op["first_make"].as_f64().unwrap() - op["coil_on"].as_f64().unwrap();
    assert!((actual(&early, "limits.max_operate_time") - expected).abs() < 1e-12);
    assert!(actual(&early, "limits.max_settle_time") > expected + 1e-4);
}
