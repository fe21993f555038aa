//! `chatterspice check` end to end: exit 0 when every limit holds, 1 when
//! one fails, 2 on bad input; margins against values worked out here from
//! the chatter (a bare pull-up shows 1 + 2 × bounces edges).
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use predicates::prelude::*;

use crate::common::{has_words, word};
use serde_json::Value;

use chatterspice::scenario::DEFAULT_SCENARIO_TOML;

fn chatterspice() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

/// The default relay on a bare pull-up, with `probe_limits` added to its
/// probe and `limits` as its `[limits]` body (no section when empty).
fn scenario(dir: &Path, probe_limits: &str, limits: &str) -> PathBuf {
    std::fs::write(
        dir.join("pullup.cir"),
        "pull-up\nVDD vdd 0 DC 3.3\nR1 vdd sw 10k\nX1 sw 0 CONTACT\n.tran 100n 5m\n.end\n",
    )
    .unwrap();
    let cut = DEFAULT_SCENARIO_TOML.find("[circuit]").unwrap();
    let mut text = format!(
        "{}[circuit]\nnetlist = \"pullup.cir\"\n\n[[probe]]\nsignal = \"v(sw)\"\nlow = 0.99\nhigh = 2.31\n{probe_limits}\n",
        &DEFAULT_SCENARIO_TOML[..cut]
    );
    if !limits.is_empty() {
        text.push_str(&format!("\n[limits]\n{limits}\n"));
    }
    let path = dir.join("relay.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn check_json(path: &Path, code: i32) -> Value {
    let out = chatterspice()
        .args(["check", path.to_str().unwrap(), "--format", "json"])
        .assert()
        .code(code);
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

fn check_of<'a>(v: &'a Value, key: &str) -> &'a Value {
    v["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["key"] == key)
        .unwrap_or_else(|| panic!("no check {key} in {v}"))
}

#[test]
fn generous_limits_pass_with_their_margins() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let path = scenario(
        dir.path(),
        "max_edges = 20\nmax_value = 3.6\nmin_value = -0.3",
        "max_bounces = 8\nmax_bounce_time = 5e-3",
    );
    let v = check_json(&path, 0);
    assert_eq!(v["passed"], true);
    assert_eq!(v["failed"], 0);
    let bounces = v["bounce"]["bounce_count"].as_f64().unwrap();
    assert_eq!(check_of(&v, "limits.max_bounces")["margin"], 8.0 - bounces);
    // Unfiltered, every bounce is an edge pair.
    assert_eq!(
        check_of(&v, "probe[0].max_edges")["margin"],
        20.0 - (1.0 + 2.0 * bounces)
    );
    let bounce_time = v["bounce"]["settle_time"].as_f64().unwrap()
        - v["bounce"]["first_impact"].as_f64().unwrap();
    let margin = check_of(&v, "limits.max_bounce_time")["margin"]
        .as_f64()
        .unwrap();
    assert!((margin - (5e-3 - bounce_time)).abs() < 1e-15);
    // The pull-up's high level: 3.3 V through 10 kΩ into 1 GΩ open.
    let max = check_of(&v, "probe[0].max_value")["actual"]
        .as_f64()
        .unwrap();
    assert!((max - 3.3 * 1e9 / (1e9 + 1e4)).abs() < 1e-6, "{max}");
    assert!(v["run"]["probes"][0]["edges"].as_u64().is_some());
}

#[test]
fn a_failed_limit_exits_1_and_says_which_and_by_how_much() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let path = scenario(dir.path(), "max_edges = 1", "max_bounces = 8");
    let v = check_json(&path, 1);
    assert_eq!(v["passed"], false);
    assert_eq!(v["failed"], 1);
    let bounces = v["bounce"]["bounce_count"].as_f64().unwrap();
    let edges = check_of(&v, "probe[0].max_edges");
    assert_eq!(edges["passed"], false);
    assert_eq!(edges["margin"], 1.0 - (1.0 + 2.0 * bounces));
    assert_eq!(check_of(&v, "limits.max_bounces")["passed"], true);

    chatterspice()
        .args(["check", path.to_str().unwrap()])
        .assert()
        .code(1)
        .stdout(
            predicate::str::contains("FAIL: 1 of 2 limits failed")
                .and(predicate::function(|out: &str| {
                    has_words(out, &[&word("FAIL"), &word("probe[0].max_edges")])
                }))
                .and(predicate::str::contains(format!("-{}", 2.0 * bounces))),
        );
}

#[test]
fn relay_limits_alone_need_no_ngspice() {
    let dir = tempfile::tempdir().unwrap();
    let path = scenario(dir.path(), "", "max_bounces = 4\nmax_operate_time = 2e-3");
    let out = chatterspice()
        .args([
            "check",
            path.to_str().unwrap(),
            "--format",
            "json",
            "--ngspice",
            "/nonexistent/ngspice",
        ])
        .assert()
        .code(1);
    let v: Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    // The default relay bounces 5 times and settles at 1.23 ms.
    assert_eq!(check_of(&v, "limits.max_bounces")["passed"], false);
    assert_eq!(check_of(&v, "limits.max_operate_time")["passed"], true);
    assert_eq!(v["run"], Value::Null);
}

#[test]
fn a_check_without_limits_reports_the_figures_and_passes() {
    let dir = tempfile::tempdir().unwrap();
    let path = scenario(dir.path(), "", "");
    chatterspice()
        .args(["check", path.to_str().unwrap()])
        .assert()
        .code(0)
        .stdout(
            predicate::str::contains("no limits to hold").and(predicate::str::contains("bounces")),
        );
    let out = chatterspice()
        .args(["check", path.to_str().unwrap(), "--format", "json"])
        .assert()
        .code(0);
    let v: Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    assert_eq!(v["passed"], true, "{v}");
    assert_eq!(v["checks"].as_array().map(Vec::len), Some(0));
    assert!(v["bounce"]["bounce_count"].as_u64().unwrap() > 0, "{v}");
}

#[test]
fn a_bundled_part_is_checked_and_bounced_on_its_dc_step_without_ngspice() {
    let part = concat!(env!("CARGO_MANIFEST_DIR"), "/parts/omron-g5le-1-dc5.toml");
    for command in ["check", "bounce"] {
        let out = chatterspice()
            .args([command, part, "--format", "json"])
            .env("PATH", "/nonexistent")
            .assert()
            .code(0);
        let v: Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
        let bounce = if command == "check" { &v["bounce"] } else { &v };
        // The part's datasheet: operate 10 ms max. at 5 V; the nominal
        // relay makes at its coil voltage.
        let first = bounce["first_impact"].as_f64().expect("it makes");
        assert!(first > 0.0 && first <= 10.0e-3 * 1.001, "{v}");
    }
}

#[test]
fn a_coil_without_a_circuit_or_a_voltage_names_the_keys() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("coil.toml");
    std::fs::write(
        &path,
        "[mechanics]\nmass = 2e-4\nstiffness = 800.0\ndamping = 0.04\npreload = 0.1\ngap = 4.5e-4\n\
         [coil]\nresistance = 70.0\nturns = 3000\npole_area = 2e-5\nair_gap = 6e-4\niron_gap = 5e-5\n\
         [surface]\nlaw = \"kelvin-voigt\"\nstiffness = 8e4\ndamping = 0.37536\n",
    )
    .unwrap();
    for command in ["check", "bounce", "pwl"] {
        chatterspice()
            .args([command, path.to_str().unwrap()])
            .assert()
            .code(2)
            .stderr(
                predicate::str::contains("coil.drive_voltage")
                    .and(predicate::str::contains("datasheet.coil_voltage")),
            );
    }
}

#[test]
fn a_bad_limit_is_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let path = scenario(dir.path(), "", "max_bounce_time = -1.0");
    chatterspice()
        .args(["check", path.to_str().unwrap()])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("limits.max_bounce_time"));
    let path = scenario(dir.path(), "max_edge = 1", "");
    chatterspice()
        .args(["check", path.to_str().unwrap()])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("max_edge"));
}

#[test]
fn the_library_check_is_usable_from_a_user_s_own_tests() {
    let ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let path = scenario(dir.path(), "max_glitches = 0", "");
    let scenario = chatterspice::scenario::Scenario::load(&path).unwrap();
    let verdict = chatterspice::check::run(&scenario, &ng).unwrap();
    assert!(!verdict.passed);
    let failure = verdict.failures().next().unwrap();
    assert_eq!(failure.key, "probe[0].max_glitches");
    assert!(
        verdict.to_string().contains("FAIL probe[0].max_glitches"),
        "{verdict}"
    );
}

#[test]
fn a_coil_driven_relay_is_checked_through_its_driver() {
    let _ng = ngspice_or_skip!();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/relay-driver.toml");
    let v = check_json(&path, 0);
    let make = v["bounce"]["first_impact"].as_f64().unwrap();
    let coil_on = v["run"]["operations"][0]["coil_on"].as_f64().unwrap();
    let margin = check_of(&v, "limits.max_operate_time")["margin"]
        .as_f64()
        .unwrap();
    // Operate time as datasheets count it: from the coil being energized.
    let operate = make - coil_on;
    assert!(
        (margin - (5e-3 - operate)).abs() < 1e-15,
        "{margin} vs {operate}"
    );
    let timing = v["timing"]["operate_time"].as_f64().unwrap();
    assert!((timing - operate).abs() < 1e-15, "{timing} vs {operate}");
    // The coil's pull, not a step: the first make comes after the coil
    // current has built up, milliseconds in.
    assert!(make > 1e-3, "{make}");
    // One ngspice run, in lock-step through the shared library.
    let coupling = v["run"]["coupling"].as_array().unwrap();
    assert_eq!(coupling.len(), 1, "{coupling:?}");
    assert_eq!(coupling[0]["scheme"], "lock-step");
}

/// `check --measured`: the limits are held against the record, not the
/// model; a bare pull-up sees one edge per state change of the record.
#[test]
fn a_measured_record_is_checked_instead_of_the_mechanics() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    // The model bounces 5 times; the record only once.
    let path = scenario(dir.path(), "max_edges = 3", "max_bounces = 1");
    let csv = dir.path().join("scope.csv");
    std::fs::write(
        &csv,
        "time,state\n0,open\n1e-3,closed\n1.1e-3,open\n1.2e-3,closed\n5e-3,closed\n",
    )
    .unwrap();
    let with = |csv: &Path, code: i32| -> Value {
        let out = chatterspice()
            .args([
                "check",
                path.to_str().unwrap(),
                "--format",
                "json",
                "--measured",
            ])
            .arg(csv)
            .assert()
            .code(code);
        serde_json::from_slice(&out.get_output().stdout).unwrap()
    };
    let v = with(&csv, 0);
    assert_eq!(v["passed"], true, "{v}");
    // Without the record the model's 5 bounces fail both limits.
    let v = check_json(&path, 1);
    assert_eq!(v["passed"], false, "{v}");
    // A record with two openings fails them too.
    std::fs::write(
        &csv,
        "time,state\n0,open\n1e-3,closed\n1.1e-3,open\n1.2e-3,closed\n1.3e-3,open\n1.4e-3,closed\n5e-3,closed\n",
    )
    .unwrap();
    let v = with(&csv, 1);
    assert_eq!(v["passed"], false, "{v}");
}

/// A run that ends before the release a limit needs (the driver turns
/// the coil off at 20 ms, the scenario stops at 15 ms) fails that limit
/// as not evaluated: it never passes on a release that was not simulated.
#[test]
fn a_release_limit_past_the_end_of_the_run_fails_as_not_evaluated() {
    let Some(_) = crate::common::ngspice() else {
        return;
    };
    let root = env!("CARGO_MANIFEST_DIR");
    let text =
        std::fs::read_to_string(format!("{root}/examples/scenarios/relay-driver-zener.toml"))
            .unwrap()
            .replace("t_end = 0.05 ", "t_end = 0.015 ")
            .replace(
                "../../netlists/relay_driver_zener.cir",
                &format!("{root}/netlists/relay_driver_zener.cir"),
            );
    assert!(text.contains("t_end = 0.015"));
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("short.toml");
    std::fs::write(&file, text).unwrap();
    let out = assert_cmd::Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["check", file.to_str().unwrap(), "--format", "json"])
        .assert()
        .code(1);
    let doc: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    let release = doc["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["key"] == "limits.max_release_time")
        .expect("the release limit is reported");
    assert_eq!(release["passed"], false, "{release}");
    assert!(
        release["note"].as_str().unwrap().contains("not evaluated"),
        "{release}"
    );
}

/// The debounce limits: on a probe, its lockout (last edge − first edge)
/// and stable-for (longest gap between edges); in `[limits]`, the
/// contact's own, worked out here from the bounce record. Below the
/// value fails with exit 1 and the margin; above passes.
#[test]
fn debounce_limits_hold_lockout_and_stable_for() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let json = |path: &Path, code: i32| -> Value {
        let out = chatterspice()
            .args(["check", path.to_str().unwrap(), "--format", "json"])
            .assert()
            .code(code);
        serde_json::from_slice(&out.get_output().stdout).unwrap()
    };
    // The probe's figures from a run with a limit that cannot fail.
    let loose = scenario(dir.path(), "max_lockout = 1.0\nmax_stable_for = 1.0", "");
    let doc = json(&loose, 0);
    let debounce = &doc["run"]["probes"][0]["debounce"];
    let (lockout, stable) = (
        debounce["lockout"].as_f64().unwrap(),
        debounce["stable_for"].as_f64().unwrap(),
    );
    assert!(lockout > stable && stable > 0.0, "{debounce}");
    for (key, value) in [("max_lockout", lockout), ("max_stable_for", stable)] {
        let tight = scenario(dir.path(), &format!("{key} = {:e}", value * 0.99), "");
        let out = chatterspice()
            .args(["check", tight.to_str().unwrap()])
            .assert()
            .code(1);
        let text = String::from_utf8_lossy(&out.get_output().stdout).into_owned();
        assert!(
            text.contains(&format!("probe[0].{key}")) && text.contains("FAIL"),
            "{text}"
        );
        let doc = json(&tight, 1);
        let margin = doc["checks"][0]["margin"].as_f64().unwrap();
        assert!(
            (margin + value * 0.01).abs() < 1e-9 * value.max(1.0),
            "{margin}"
        );
        let above = scenario(dir.path(), &format!("{key} = {:e}", value * 1.01), "");
        json(&above, 0);
    }
    // The contact's own, from its transitions in the bounce record.
    let bounce: Value = serde_json::from_slice(
        &chatterspice()
            .args(["bounce", "--format", "json"])
            .output()
            .unwrap()
            .stdout,
    )
    .unwrap();
    let mut times: Vec<f64> = Vec::new();
    for i in bounce["impacts"].as_array().unwrap() {
        times.push(i["impact_time"].as_f64().unwrap());
        if let Some(r) = i["release_time"].as_f64() {
            times.push(r);
        }
    }
    let contact_lockout = times.last().unwrap() - times[0];
    let contact_stable = times.windows(2).map(|w| w[1] - w[0]).fold(0.0, f64::max);
    for (key, value) in [
        ("max_lockout", contact_lockout),
        ("max_stable_for", contact_stable),
    ] {
        let tight = scenario(dir.path(), "", &format!("{key} = {:e}", value * 0.99));
        let doc = json(&tight, 1);
        let actual = doc["checks"][0]["actual"].as_f64().unwrap();
        assert!(
            (actual - value).abs() < 1e-12,
            "{key}: {actual} against {value}"
        );
        let above = scenario(dir.path(), "", &format!("{key} = {:e}", value * 1.01));
        json(&above, 0);
    }
}
