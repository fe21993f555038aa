//! `chatterspice bounce` end to end: every format on the built-in default
//! and on the scenarios under tests/data/scenarios, and every kind of bad
//! input giving exit code 2 with a message that names the file and key.

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/scenarios");

fn data(name: &str) -> PathBuf {
    Path::new(DATA).join(name)
}

fn chatterspice() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

/// Run `bounce` with `args`, expect success, return stdout.
fn bounce_ok(args: &[&str]) -> String {
    let out = chatterspice().arg("bounce").args(args).assert().success();
    String::from_utf8(out.get_output().stdout.clone()).unwrap()
}

fn json(args: &[&str]) -> Value {
    let mut args = args.to_vec();
    args.extend(["--format", "json"]);
    serde_json::from_str(&bounce_ok(&args)).unwrap()
}

// Each format on the built-in default.

#[test]
fn default_table_is_the_default_format() {
    let text = bounce_ok(&[]);
    assert_eq!(text, bounce_ok(&["--format", "table"]));
    for label in [
        "outcome",
        "first impact",
        "settle time",
        "bounce time",
        "bounces",
    ] {
        assert!(text.contains(label), "no {label}:\n{text}");
    }
    assert!(text.contains("stuck") && text.contains(" ms"), "{text}");
}

#[test]
fn default_json_follows_the_contract() {
    let v = json(&[]);
    let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    for key in [
        "outcome",
        "first_impact",
        "settle_time",
        "bounce_count",
        "impacts",
        "intervals",
        "shortfall",
        "accumulation_time",
        "t_end",
        "dimensionless",
    ] {
        assert!(keys.contains(&key), "missing {key} in {keys:?}");
    }
    assert_eq!(v["outcome"], "stuck");
    let impacts = v["impacts"].as_array().unwrap();
    assert!(!impacts.is_empty());
    assert_eq!(v["first_impact"], impacts[0]["impact_time"]);
    assert_eq!(
        v["bounce_count"].as_u64().unwrap() as usize,
        impacts.len() - 1
    );
    assert_eq!(impacts.last().unwrap()["release_time"], Value::Null);
    let intervals = v["intervals"].as_array().unwrap();
    assert_eq!(intervals[0]["state"], "open");
    assert_eq!(intervals[0]["start"], 0.0);
    assert_eq!(intervals.last().unwrap()["state"], "closed");
    assert_eq!(intervals.last().unwrap()["end"], 0.02);
    // k0 = g/F = 1.4e-4 / (1.0/5000) = 0.7.
    let k0 = v["dimensionless"]["k0"].as_f64().unwrap();
    assert!((k0 - 0.7).abs() < 1e-12, "{k0}");
}

#[test]
fn default_csv_has_one_row_per_impact() {
    let text = bounce_ok(&["--format", "csv"]);
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "impact_time,impact_velocity,release_time,release_velocity,restitution,\
             contact_time,peak_force,min_force,max_gap_after"
        )
    );
    let impacts = json(&[])["impacts"].as_array().unwrap().len();
    assert_eq!(lines.count(), impacts);
}

#[test]
fn output_is_byte_identical_run_to_run() {
    for format in ["json", "csv", "table"] {
        assert_eq!(
            bounce_ok(&["--format", format]),
            bounce_ok(&["--format", format]),
            "{format}"
        );
    }
}

// Each format on files.

#[test]
fn every_data_scenario_renders_in_every_format() {
    for name in [
        "kelvin_voigt.toml",
        "rigid_zeno.toml",
        "hunt_crossley_chi.toml",
        "never_closes.toml",
    ] {
        let path = data(name);
        let path = path.to_str().unwrap();
        let v = json(&[path]);
        let impacts = v["impacts"].as_array().unwrap().len();
        let csv = bounce_ok(&[path, "--format", "csv"]);
        assert_eq!(csv.lines().count(), 1 + impacts, "{name}");
        let table = bounce_ok(&[path, "--format", "table"]);
        assert!(table.starts_with(&format!("outcome       {}", v["outcome"].as_str().unwrap())));
    }
}

#[test]
fn kelvin_voigt_file_reproduces_the_reference_sequence() {
    let v = json(&[data("kelvin_voigt.toml").to_str().unwrap()]);
    assert_eq!(v["outcome"], "stuck");
    assert_eq!(v["impacts"].as_array().unwrap().len(), 18);
    let first = v["first_impact"].as_f64().unwrap();
    assert!((first - 1.51477).abs() < 1e-5, "{first}");
}

#[test]
fn rigid_file_collapses_the_zeno_tail() {
    let v = json(&[data("rigid_zeno.toml").to_str().unwrap()]);
    assert_eq!(v["outcome"], "resolved");
    let settle = v["settle_time"].as_f64().unwrap();
    let accumulation = v["accumulation_time"].as_f64().unwrap();
    assert!(accumulation >= settle, "{accumulation} < {settle}");
}

#[test]
fn never_closes_reports_the_shortfall() {
    let path = data("never_closes.toml");
    let v = json(&[path.to_str().unwrap()]);
    assert_eq!(v["outcome"], "never_closes");
    assert_eq!(v["first_impact"], Value::Null);
    assert!(v["shortfall"].as_f64().unwrap() > 0.0);
    let csv = bounce_ok(&[path.to_str().unwrap(), "--format", "csv"]);
    assert_eq!(csv.lines().count(), 1, "header only");
}

#[test]
fn example_scenarios_run() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenarios");
    for law in ["rigid", "kelvin-voigt", "hunt-crossley"] {
        let path = format!("{dir}/{law}.toml");
        let v = json(&[&path]);
        assert!(v["first_impact"].is_f64(), "{law}");
    }
}

#[test]
fn scenario_can_come_from_stdin() {
    let path = data("rigid_zeno.toml");
    let from_file = bounce_ok(&[path.to_str().unwrap(), "--format", "json"]);
    let out = chatterspice()
        .args(["bounce", "-", "--format", "json"])
        .pipe_stdin(&path)
        .unwrap()
        .assert()
        .success();
    assert_eq!(String::from_utf8_lossy(&out.get_output().stdout), from_file);
}

// -o FILE

#[test]
fn output_file_is_written_and_stdout_stays_empty() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bounce.json");
    chatterspice()
        .args(["bounce", "--format", "json", "-o"])
        .arg(&out)
        .assert()
        .success()
        .stdout("");
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        bounce_ok(&["--format", "json"])
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary left"
    );
}

#[test]
fn output_file_is_not_overwritten_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("results.csv");
    std::fs::write(&out, "my measurements\n").unwrap();
    chatterspice()
        .args(["bounce", "--format", "csv", "-o"])
        .arg(&out)
        .assert()
        .code(2)
        .stdout("")
        .stderr(predicate::str::contains("results.csv").and(predicate::str::contains("--force")));
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "my measurements\n");

    chatterspice()
        .args(["bounce", "--format", "csv", "--force", "-o"])
        .arg(&out)
        .assert()
        .success();
    assert!(
        std::fs::read_to_string(&out)
            .unwrap()
            .starts_with("impact_time,")
    );
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary left"
    );
}

// Bad input: exit 2, a message naming the file and the key, never a panic.

const GOOD: &str = "\
[mechanics]
mass = 2.0e-4
stiffness = 800.0
damping = 0.04
force = 0.5
gap = 4.5e-4

[surface]
law = \"rigid\"
restitution = 0.7
";

/// Write GOOD with one edit to a file named `bad.toml`, run `bounce` on
/// it, expect exit 2 and stderr naming the file and each of `needles`.
#[track_caller]
fn rejects(old: &str, new: &str, needles: &[&str]) {
    assert!(GOOD.contains(old), "edit `{old}` not in GOOD");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, GOOD.replacen(old, new, 1)).unwrap();
    let out = chatterspice()
        .arg("bounce")
        .arg(&path)
        .assert()
        .code(2)
        .stdout("");
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(stderr.contains("bad.toml"), "file not named:\n{stderr}");
    for needle in needles {
        assert!(stderr.contains(needle), "`{needle}` not in:\n{stderr}");
    }
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn misspelt_key() {
    rejects(
        "mass = 2.0e-4",
        "mas = 2.0e-4",
        &["`mechanics.mas`", "bad.toml:2", "`mass`"],
    );
}

#[test]
fn negative_mass() {
    rejects(
        "mass = 2.0e-4",
        "mass = -2.0e-4",
        &["`mechanics.mass`", "> 0"],
    );
}

#[test]
fn nan_and_infinity() {
    rejects(
        "mass = 2.0e-4",
        "mass = nan",
        &["`mechanics.mass`", "finite"],
    );
    rejects("gap = 4.5e-4", "gap = inf", &["`mechanics.gap`", "finite"]);
    rejects(
        "force = 0.5",
        "force = -inf",
        &["`mechanics.force`", "finite"],
    );
}

#[test]
fn restitution_above_one() {
    rejects(
        "restitution = 0.7",
        "restitution = 1.5",
        &["`surface.restitution`", "[0, 1]"],
    );
}

#[test]
fn unknown_surface_law() {
    rejects(
        "law = \"rigid\"",
        "law = \"hertz\"",
        &["`surface.law`", "hunt-crossley"],
    );
}

#[test]
fn missing_required_key() {
    rejects(
        "stiffness = 800.0\n",
        "",
        &["`mechanics.stiffness`", "missing"],
    );
    rejects(
        "restitution = 0.7\n",
        "",
        &["`surface.restitution`", "missing"],
    );
}

#[test]
fn force_and_coil_together() {
    let coil = "\n[coil]\nresistance = 70.0\nturns = 3000\npole_area = 2.0e-5\n\
                air_gap = 6.0e-4\niron_gap = 5.0e-5\n";
    rejects(
        "restitution = 0.7\n",
        &format!("restitution = 0.7\n{coil}"),
        &["`mechanics.force`", "`coil`"],
    );
}

#[test]
fn toml_syntax_error_names_the_line() {
    rejects(
        "damping = 0.04",
        "damping = 0.04 0.05",
        &["bad.toml:4", "not valid TOML"],
    );
}

#[test]
fn key_of_another_surface_law() {
    rejects(
        "restitution = 0.7",
        "restitution = 0.7\nchi = 0.1",
        &["`surface.chi`", "rigid"],
    );
}

#[test]
fn missing_file() {
    chatterspice()
        .args(["bounce", "no/such/relay.toml"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("no/such/relay.toml"));
}

#[test]
fn usage_errors_exit_2_and_help_exits_0() {
    chatterspice()
        .args(["bounce", "--format", "xml"])
        .assert()
        .code(2);
    chatterspice().args(["bounce", "--force"]).assert().code(2);
    chatterspice().args(["bonce"]).assert().code(2);
    chatterspice().assert().code(2);
    chatterspice()
        .args(["bounce", "--help"])
        .assert()
        .success()
        .stdout(predicate::str::contains("--format"));
}

#[test]
fn bounce_reports_a_measured_chatter_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("scope.csv");
    // Two openings after the first make, then closed for good.
    let (make, settle) = (1.0e-3, 1.5e-3);
    std::fs::write(
        &csv,
        format!("time,state\n0,open\n{make},closed\n1.1e-3,open\n1.2e-3,closed\n1.3e-3,open\n{settle},closed\n5e-3,closed\n"),
    )
    .unwrap();
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["bounce", "--format", "json", "--measured"])
        .arg(&csv)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["bounce_count"], 2);
    assert_eq!(v["first_impact"].as_f64().unwrap(), make);
    assert_eq!(v["settle_time"].as_f64().unwrap(), settle);

    // A broken row is exit 2 naming the file and the line.
    std::fs::write(&csv, "time,state\n0,open\nnope,closed\n").unwrap();
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["bounce", "--measured"])
        .arg(&csv)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("scope.csv") && err.contains('3'), "{err}");
}
