//! Scenarios on a base, end to end: a `[coil]` written over the default's
//! step force drives the relay, a step force written over a part's coil
//! is refused with both files named, and `unset` removes a key of the
//! base with its effect on `check`.
//!
//! The run needs ngspice: it skips with a note when ngspice is missing,
//! and fails when `REQUIRE_NGSPICE=1` (CI sets it).

use std::path::Path;

use assert_cmd::Command;
use serde_json::Value;

fn chatterspice() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

/// The coil of `examples/scenarios/relay-driver.toml`, on an ideal DC
/// step of `volts` (the default's circuit has no coil driver).
fn coil(volts: f64) -> String {
    format!(
        "[coil]\nresistance = 70.0\nturns = 3000\npole_area = 2.0e-5\nair_gap = 6.0e-4\n\
         iron_gap = 5.0e-5\ndrive_voltage = {volts:?}\n"
    )
}

fn json_of(args: &[&str], path: &Path) -> Value {
    let out = chatterspice()
        .args(args)
        .arg(path)
        .args(["--format", "json"])
        .assert()
        .success();
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

#[test]
fn a_coil_over_the_default_drives_the_relay() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, volts: f64| {
        let path = dir.path().join(name);
        std::fs::write(&path, format!("base = \"default\"\n\n{}", coil(volts))).unwrap();
        path
    };
    let (slow, fast) = (write("slow.toml", 12.0), write("fast.toml", 24.0));
    let plain = dir.path().join("plain.toml");
    std::fs::write(&plain, "base = \"default\"\n").unwrap();
    let default = json_of(&["bounce"], &plain);
    let (slow_b, fast_b) = (json_of(&["bounce"], &slow), json_of(&["bounce"], &fast));
    let make = |v: &Value| v["first_impact"].as_f64().unwrap();
    // The coil makes the force: more voltage, a sooner make; neither is
    // the default's step force.
    assert!(make(&fast_b) < make(&slow_b), "{fast_b} vs {slow_b}");
    assert!(
        (make(&slow_b) - make(&default)).abs() > 1e-4,
        "{slow_b} vs {default}"
    );

    let _ng = ngspice_or_skip!();
    let run = json_of(&["run"], &slow);
    let operate = run["timing"]["operate_time"].as_f64().unwrap();
    assert!(
        (operate - make(&slow_b)).abs() < 1e-6,
        "run {operate} vs bounce {}",
        make(&slow_b)
    );
    let edges = run["probes"][0]["edges"].as_u64().unwrap();
    assert!(edges >= 1, "{}", run["probes"][0]);
}

#[test]
fn a_force_over_a_parts_coil_names_both_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mine.toml");
    std::fs::write(
        &path,
        "base = \"part:te-axicom-im-5v\"\n\n[mechanics]\nforce = 0.5\n",
    )
    .unwrap();
    let out = chatterspice().arg("bounce").arg(&path).assert().code(2);
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(err.contains("mine.toml:4:"), "{err}");
    assert!(err.contains("\"part:te-axicom-im-5v\""), "{err}");
    assert!(err.contains("unset = [\"coil\"]"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // Followed, the advice gives a step-force relay.
    std::fs::write(
        &path,
        "base = \"part:te-axicom-im-5v\"\nunset = [\"coil\"]\n\n[mechanics]\nforce = 0.5\n",
    )
    .unwrap();
    let v = json_of(&["bounce"], &path);
    assert!(v["first_impact"].as_f64().unwrap() > 0.0, "{v}");
}

#[test]
fn unset_removes_a_limit_of_the_base() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("base.toml");
    std::fs::write(
        &base,
        "base = \"default\"\n[limits]\nmax_bounces = 1\nmax_settle_time = 0.01\n",
    )
    .unwrap();
    let top = dir.path().join("top.toml");
    std::fs::write(
        &top,
        "base = \"base.toml\"\nunset = [\"limits.max_bounces\"]\n",
    )
    .unwrap();
    let keys = |path: &Path, code: i32| -> Vec<String> {
        let out = chatterspice()
            .arg("check")
            .arg(path)
            .args(["--format", "json"])
            .assert()
            .code(code);
        let v: Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
        v["checks"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["key"].as_str().unwrap().to_owned())
            .collect()
    };
    // The default relay bounces 5 times: the base fails its limit...
    let with = keys(&base, 1);
    assert!(with.contains(&"limits.max_bounces".to_owned()), "{with:?}");
    // ... which the file on it removed, keeping the other.
    let without = keys(&top, 0);
    assert_eq!(without, ["limits.max_settle_time"]);
    // A key the base does not set is an error at the entry's line.
    std::fs::write(
        &top,
        "base = \"base.toml\"\nunset = [\n  \"limits.max_bounce\",\n]\n",
    )
    .unwrap();
    let out = chatterspice().arg("check").arg(&top).assert().code(2);
    let err = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(
        err.contains("top.toml:3:") && err.contains("limits.max_bounce"),
        "{err}"
    );
}
