//! `chatterspice run` and `chatterspice pwl` end to end, on real ngspice:
//! the built-in default in both formats, `--out` and its refusal to
//! overwrite, and bad input of every kind giving exit code 2 with a
//! message that says what to fix.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use crate::common::{self, scenario_with_netlist, script};

use std::path::Path;

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;

fn chatterspice() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

fn stdout_of(args: &[&str]) -> String {
    let out = chatterspice().args(args).assert().success();
    String::from_utf8(out.get_output().stdout.clone()).unwrap()
}

const PULLUP: &str =
    "pull-up\nVDD vdd 0 DC 3.3\nR1 vdd sw 10k\nX1 sw 0 CONTACT\n.tran 100n 5m\n.end\n";

#[test]
fn run_with_no_scenario_reports_the_default_relay_on_the_mcu_input() {
    let _ng = ngspice_or_skip!();
    let text = stdout_of(&["run"]);
    for expected in [
        "5 bounces",
        "mcu_input.cir",
        "ngspice",
        "v(in)",
        "ideal contact",
        "the bounce adds",
    ] {
        assert!(
            text.contains(expected),
            "`{expected}` missing from:\n{text}"
        );
    }
}

#[test]
fn run_json_keeps_the_contract() {
    let _ng = ngspice_or_skip!();
    let text = stdout_of(&["run", "--format", "json"]);
    let top: Vec<&str> = text
        .lines()
        .filter(|l| l.starts_with("  \"") && !l.starts_with("   "))
        .map(|l| l.trim().split('"').nth(1).unwrap())
        .collect();
    assert_eq!(&top[..3], ["probes", "bounce", "ngspice"]);
    let v: Value = serde_json::from_str(&text).unwrap();
    let probe = &v["probes"][0];
    for key in [
        "signal",
        "edges",
        "glitches",
        "first_edge",
        "last_edge",
        "min",
        "max",
    ] {
        assert!(probe.get(key).is_some(), "probe lacks {key}");
    }
    let edges = probe["edges"].as_u64().unwrap();
    assert!(edges >= 1);
    assert_eq!(probe["glitches"].as_u64().unwrap(), edges - 1);
    assert_eq!(v["bounce"]["bounce_count"], 5);
    assert_eq!(v["bounce"]["outcome"], "stuck");
    assert!(v["ngspice"]["version"].is_string());
    assert!(v["ngspice"]["elapsed"].as_f64().unwrap() > 0.0);
    assert!(v["ngspice"]["points"].as_u64().unwrap() > 100);
    assert_eq!(probe["ideal"]["edges"], 1);
    assert_eq!(
        probe["bounce_added"]["extra_edges"].as_i64().unwrap(),
        edges as i64 - 1
    );
}

#[test]
fn out_writes_every_artefact_and_never_overwrites_without_force() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run1");
    let out_arg = out.to_str().unwrap();
    chatterspice()
        .args(["run", "--out", out_arg])
        .assert()
        .success();
    for file in [
        "report.json",
        "waveforms.csv",
        "waveforms_ideal.csv",
        "waveforms.raw",
        "waveforms_ideal.raw",
        "netlist.cir",
        "contact.inc",
        "plot.svg",
        "plot.png",
    ] {
        assert!(out.join(file).is_file(), "{file} not written");
    }
    let png = std::fs::read(out.join("plot.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "plot.png is a PNG");
    let deck = std::fs::read_to_string(out.join("netlist.cir")).unwrap();
    assert!(deck.contains(".include contact.inc"), "{deck}");
    let csv = std::fs::read_to_string(out.join("waveforms.csv")).unwrap();
    assert!(
        csv.starts_with("time,contact_resistance,v(in)\n"),
        "{}",
        &csv[..80]
    );
    let svg = std::fs::read_to_string(out.join("plot.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));

    // The netlist written is runnable by hand, as the bundle says.
    let ng = common::ngspice().unwrap();
    let rerun = std::process::Command::new(ng.program())
        .current_dir(&out)
        .args(["-b", "-r", "again.raw", "netlist.cir"])
        .output()
        .unwrap();
    assert!(rerun.status.success(), "{rerun:?}");
    assert!(out.join("again.raw").is_file());
    // The kept raw file is that run's plot, value for value.
    let kept = chatterspice::rawfile::RawFile::read(out.join("waveforms.raw")).unwrap();
    let again = chatterspice::rawfile::RawFile::read(out.join("again.raw")).unwrap();
    let tran = |f: &chatterspice::rawfile::RawFile| {
        f.plots
            .iter()
            .find(|p| p.name == "Transient Analysis")
            .cloned()
            .unwrap()
    };
    let (kept, again) = (tran(&kept), tran(&again));
    assert_eq!(kept.points(), again.points());
    assert_eq!(kept.real("v(in)"), again.real("v(in)"));

    // A second run refuses, names the file, and leaves everything as it was.
    std::fs::write(out.join("plot.svg"), "my edits").unwrap();
    let before = std::fs::read(out.join("report.json")).unwrap();
    chatterspice()
        .args(["run", "--out", out_arg])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("already exists").and(predicate::str::contains("--force")),
        );
    assert_eq!(
        std::fs::read_to_string(out.join("plot.svg")).unwrap(),
        "my edits"
    );
    assert_eq!(std::fs::read(out.join("report.json")).unwrap(), before);
    chatterspice()
        .args(["run", "--out", out_arg, "--force"])
        .assert()
        .success();
    assert_ne!(
        std::fs::read_to_string(out.join("plot.svg")).unwrap(),
        "my edits"
    );
}

#[test]
fn a_scenario_without_a_circuit_says_what_to_add() {
    let dir = tempfile::tempdir().unwrap();
    let relay = chatterspice::scenario::DEFAULT_SCENARIO_TOML;
    let path = dir.path().join("no_circuit.toml");
    std::fs::write(&path, &relay[..relay.find("[circuit]").unwrap()]).unwrap();
    chatterspice()
        .args(["run", path.to_str().unwrap()])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("no [circuit]").and(predicate::str::contains("netlist =")),
        );
}

#[test]
fn a_netlist_without_the_contact_names_the_file_and_the_line_to_add() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = scenario_with_netlist(
        dir.path(),
        "no contact\nVDD vdd 0 DC 3.3\nR1 vdd sw 10k\n.tran 100n 5m\n.end\n",
    );
    let original = std::fs::read(dir.path().join("circuit.cir")).unwrap();
    chatterspice()
        .args(["run", scenario.to_str().unwrap()])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("circuit.cir").and(predicate::str::contains("CONTACT")));
    assert_eq!(
        std::fs::read(dir.path().join("circuit.cir")).unwrap(),
        original
    );
}

#[test]
fn a_netlist_ngspice_rejects_gives_ngspice_s_own_words() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let scenario = scenario_with_netlist(
        dir.path(),
        "broken\nVDD vdd 0 DC 3.3\nR1 vdd sw 10kk!\nX1 sw 0 CONTACT\nQ1 a b c NOMODEL\n.tran 100n 5m\n.end\n",
    );
    chatterspice()
        .args(["run", scenario.to_str().unwrap()])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("ngspice failed")
                .and(predicate::str::contains("circuit.cir"))
                .and(predicate::str::contains("line 5 of that file")),
        );
}

#[test]
fn a_hanging_ngspice_is_killed_at_the_timeout() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    // A 1 fs maximum step over 5 ms: billions of steps.
    let scenario = scenario_with_netlist(
        dir.path(),
        "slow\nVDD vdd 0 DC 3.3\nR1 vdd sw 10k\nC1 sw 0 1n\nX1 sw 0 CONTACT\n.tran 1f 5m 0 1f\n.end\n",
    );
    let started = std::time::Instant::now();
    chatterspice()
        .args(["run", scenario.to_str().unwrap(), "--timeout", "1"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("timeout"));
    assert!(started.elapsed().as_secs() < 30, "{:?}", started.elapsed());
}

#[test]
fn a_missing_ngspice_says_how_to_install_it() {
    chatterspice()
        .args(["run", "--ngspice", "/nonexistent/ngspice"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("apt-get install"));
}

#[test]
fn a_bad_timeout_or_element_is_refused() {
    for bad in [
        ["--timeout", "0"],
        ["--timeout", "soon"],
        ["--element", "relay"],
    ] {
        chatterspice()
            .arg("run")
            .args(bad)
            .assert()
            .code(2)
            .stderr(predicate::str::contains(bad[1]));
    }
}

#[test]
fn pwl_prints_the_contact_include_the_same_every_time() {
    let text = stdout_of(&["pwl"]);
    assert!(text.contains(".subckt CONTACT a b"), "{text}");
    assert!(text.contains(".ends"), "{text}");
    assert_eq!(text, stdout_of(&["pwl"]));

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("contact.inc");
    let file_arg = file.to_str().unwrap();
    chatterspice()
        .args(["pwl", "-o", file_arg])
        .assert()
        .success();
    assert_eq!(std::fs::read_to_string(&file).unwrap(), text);
    chatterspice()
        .args(["pwl", "-o", file_arg])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("already exists"));
}

#[test]
fn pwl_takes_a_measured_chatter_sequence() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("scope.csv");
    std::fs::write(
        &csv,
        "time,state\n0,open\n1e-3,closed\n1.1e-3,open\n1.2e-3,closed\n5e-3,closed\n",
    )
    .unwrap();
    let text = stdout_of(&["pwl", "--measured", csv.to_str().unwrap()]);
    assert!(text.contains(".subckt CONTACT a b"), "{text}");
    assert!(
        text.contains("1.1e-3"),
        "the measured break is in the PWL:\n{text}"
    );

    std::fs::write(&csv, "time,state\n0,open\n1e-3,shut\n").unwrap();
    chatterspice()
        .args(["pwl", "--measured", csv.to_str().unwrap()])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("scope.csv").and(predicate::str::contains("shut")));
}

#[test]
fn a_pullup_run_from_a_file_counts_every_bounce() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let scenario = scenario_with_netlist(dir.path(), PULLUP);
    let v: Value = serde_json::from_str(&stdout_of(&[
        "run",
        scenario.to_str().unwrap(),
        "--format",
        "json",
    ]))
    .unwrap();
    let bounces = v["bounce"]["bounce_count"].as_u64().unwrap();
    assert_eq!(v["probes"][0]["edges"].as_u64().unwrap(), 1 + 2 * bounces);
}

#[test]
fn run_takes_a_measured_chatter_sequence() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let scenario = scenario_with_netlist(dir.path(), PULLUP);
    let csv = dir.path().join("scope.csv");
    // Two bounces of 50 µs, then closed to the end of the record.
    std::fs::write(
        &csv,
        "time,state\n0,open\n1e-3,closed\n1.1e-3,open\n1.15e-3,closed\n1.3e-3,open\n\
         1.35e-3,closed\n4e-3,closed\n",
    )
    .unwrap();
    let v: Value = serde_json::from_str(&stdout_of(&[
        "run",
        scenario.to_str().unwrap(),
        "--measured",
        csv.to_str().unwrap(),
        "--format",
        "json",
    ]))
    .unwrap();
    assert_eq!(v["bounce"]["bounce_count"], 2);
    assert_eq!(v["bounce"]["first_impact"], 1e-3);
    assert_eq!(v["bounce"]["settle_time"], 1.35e-3);
    assert_eq!(v["probes"][0]["edges"], 5);
    let first = v["probes"][0]["first_edge"].as_f64().unwrap();
    assert!((1e-3..1e-3 + 2e-8).contains(&first), "{first}");
}

#[test]
fn run_couples_a_coil_driven_relay_in_its_transistor_driver() {
    let _ng = ngspice_or_skip!();
    let scenario =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/relay-driver.toml");
    let v: Value = serde_json::from_str(&stdout_of(&[
        "run",
        scenario.to_str().unwrap(),
        "--format",
        "json",
    ]))
    .unwrap();
    let bounces = v["bounce"]["bounce_count"].as_u64().unwrap();
    assert!(bounces >= 1);
    // The contact pulls a bare pull-up: every bounce is an edge pair, and
    // the release at the end of the drive pulse one more edge.
    assert_eq!(v["probes"][0]["edges"].as_u64().unwrap(), 2 + 2 * bounces);
    let op = &v["operations"][0];
    assert_eq!(op["bounces"].as_u64(), Some(bounces));
    let break_time = op["break_time"].as_f64().unwrap();
    let last_edge = v["probes"][0]["last_edge"].as_f64().unwrap();
    assert!(
        (last_edge - break_time).abs() < 1e-6,
        "{last_edge} {break_time}"
    );
    let release = op["release_time"].as_f64().unwrap();
    let off = op["coil_off"].as_f64().unwrap();
    assert!((off + release - break_time).abs() < 1e-12);
    let runs = v["coupling"].as_array().unwrap();
    assert!(!runs.is_empty());
    assert!(runs.last().unwrap()["change"].as_f64().unwrap() <= 1e-7);
    // The coil current is integrated over the closures the coupling found.
    let make = v["bounce"]["first_impact"].as_f64().unwrap();
    let first_closure = &v["probes"][1]["current"]["per_closure"][0];
    assert_eq!(first_closure["start"].as_f64().unwrap(), make);
}

#[test]
fn a_coupling_that_does_not_converge_in_the_passes_allowed_is_exit_2() {
    let _ng = ngspice_or_skip!();
    let scenario =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/relay-driver.toml");
    chatterspice()
        .arg("run")
        .arg(&scenario)
        .args(["--max-iterations", "2", "--coupling", "passes"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("did not converge in 2 iterations"))
        .stderr(predicate::str::contains("--max-iterations"));
    chatterspice()
        .args(["run", "--coupling-tolerance=-1"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--coupling-tolerance"));
}

/// Warnings (here: a `.control` block left out) go to stderr in every
/// format, so that a table or JSON on stdout stays clean.
#[test]
fn warnings_go_to_stderr_not_into_the_table() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let netlist = dir.path().join("interactive.cir");
    std::fs::write(
        &netlist,
        "written for interactive use\nV1 vdd 0 DC 3.3\nR1 vdd in 10k\nX1 in 0 CONTACT\n.tran 1u 5m\n.control\nrun\nplot v(in)\n.endc\n.end\n",
    )
    .unwrap();
    let cut = chatterspice::scenario::DEFAULT_SCENARIO_TOML
        .find("[circuit]")
        .unwrap();
    let scenario = dir.path().join("relay.toml");
    std::fs::write(
        &scenario,
        format!(
            "{}[circuit]\nnetlist = {:?}\n\n[[probe]]\nsignal = \"v(in)\"\nlow = 0.99\nhigh = 2.31\n",
            &chatterspice::scenario::DEFAULT_SCENARIO_TOML[..cut],
            netlist.display().to_string()
        ),
    )
    .unwrap();
    for format in ["table", "json"] {
        let out = chatterspice()
            .args(["run", "--format", format])
            .arg(&scenario)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!stdout.contains("warning:"), "{format}: {stdout}");
        assert!(stderr.contains(".control"), "{format}: {stderr}");
    }
}

/// `--force` overwrites earlier outputs, never an input: not the scenario
/// (`pwl -o`), not a netlist kept in the output directory (`run --out`).
#[test]
fn force_never_overwrites_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::copy(
        root.join("netlists/mcu_input.cir"),
        dir.path().join("netlist.cir"),
    )
    .unwrap();
    let scenario = chatterspice::scenario::DEFAULT_SCENARIO_TOML
        .replace("../netlists/mcu_input.cir", "netlist.cir");
    let path = dir.path().join("relay.toml");
    std::fs::write(&path, &scenario).unwrap();
    let netlist = std::fs::read(dir.path().join("netlist.cir")).unwrap();
    Command::cargo_bin("chatterspice")
        .unwrap()
        .args([
            "pwl",
            path.to_str().unwrap(),
            "-o",
            path.to_str().unwrap(),
            "--force",
        ])
        .assert()
        .code(2)
        .stderr(predicates::str::contains("input"));
    // The same file by another name.
    let other = dir.path().join(".").join("relay.toml");
    Command::cargo_bin("chatterspice")
        .unwrap()
        .current_dir(dir.path())
        .args([
            "pwl",
            "relay.toml",
            "-o",
            other.to_str().unwrap(),
            "--force",
        ])
        .assert()
        .code(2);
    assert_eq!(std::fs::read_to_string(&path).unwrap(), scenario);
    Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["run", path.to_str().unwrap(), "--force", "--out"])
        .arg(dir.path())
        .assert()
        .code(2)
        .stderr(predicates::str::contains("netlist.cir"));
    assert_eq!(
        std::fs::read(dir.path().join("netlist.cir")).unwrap(),
        netlist
    );
}

/// `--timeout` covers the version check, and a wrapper that does not
/// `exec` ngspice is killed with everything it started.
#[test]
fn the_timeout_covers_the_version_check_and_kills_the_wrapper_s_children() {
    let dir = tempfile::tempdir().unwrap();
    let hangs = script(dir.path(), "hangs.sh", "sleep 30\n");
    let started = std::time::Instant::now();
    Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["run", "--timeout", "1", "--ngspice"])
        .arg(&hangs)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("did not finish within"));
    assert!(started.elapsed().as_secs() < 15, "{:?}", started.elapsed());

    // Answers the version check, then hangs in a child of its own.
    let _ng = ngspice_or_skip!();
    let pids = dir.path().join("pids");
    let body = format!(
        "if [ \"$1\" = -v ]; then exec ngspice -v; fi\nsleep 60 &\necho $! >> '{}'\nwait\n",
        pids.display()
    );
    let wrapper = script(dir.path(), "wrapper.sh", &body);
    Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["run", "--no-ideal", "--timeout", "2", "--ngspice"])
        .arg(&wrapper)
        .assert()
        .code(2);
    let pid = std::fs::read_to_string(&pids).unwrap();
    // Gone, or a zombie waiting for init to reap it: not running.
    let stat = std::fs::read_to_string(format!("/proc/{}/stat", pid.trim())).unwrap_or_default();
    let state = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .next();
    assert!(
        matches!(state, None | Some("Z") | Some("X")),
        "the wrapper's child {} outlived the timeout: {stat}",
        pid.trim()
    );
}

/// A relative `--ngspice ./x.sh` is the current directory's, not the work
/// directory's.
#[test]
fn a_relative_ngspice_path_is_the_current_directory_s() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    script(dir.path(), "my-ngspice.sh", "exec ngspice \"$@\"\n");
    Command::cargo_bin("chatterspice")
        .unwrap()
        .current_dir(dir.path())
        .args(["run", "--no-ideal", "--ngspice", "./my-ngspice.sh"])
        .assert()
        .success();
}

/// `--out` of a coil-driven relay holds everything its deck includes, the
/// coil too: the deck runs again by hand in ngspice.
#[test]
fn a_coil_driven_bundle_runs_again_by_hand() {
    let ng = ngspice_or_skip!();
    let scenario =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenarios/relay-driver-zener.toml");
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("bundle");
    chatterspice()
        .args([
            "run",
            scenario.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .assert()
        .success();
    let deck = std::fs::read_to_string(out.join("netlist.cir")).unwrap();
    for include in [".include contact.inc", ".include coil.inc"] {
        assert!(deck.contains(include), "{include}");
    }
    assert!(out.join("coil.inc").is_file());
    let status = std::process::Command::new(ng.program())
        .current_dir(&out)
        .args(["-b", "-r", "again.raw", "netlist.cir"])
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stdout)
    );
    assert!(out.join("again.raw").metadata().unwrap().len() > 1000);
}

/// A circuit with no `[[probe]]` runs: the relay, the contact and every
/// vector ngspice saved (in the CSV and the raw file), nothing measured.
#[test]
fn a_circuit_without_probes_runs_and_keeps_every_vector() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let default = chatterspice::scenario::DEFAULT_SCENARIO_TOML;
    let cut = default.find("[[probe]]").unwrap();
    let netlist = format!("{}/netlists/mcu_input.cir", env!("CARGO_MANIFEST_DIR"));
    let text = default[..cut].replace("../netlists/mcu_input.cir", &netlist);
    let path = dir.path().join("noprobe.toml");
    std::fs::write(&path, text).unwrap();
    let out = dir.path().join("out");
    let assert = chatterspice()
        .args([
            "run",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .assert()
        .success();
    let table = String::from_utf8_lossy(&assert.get_output().stdout).into_owned();
    assert!(table.contains("probes   none"), "{table}");
    let csv = std::fs::read_to_string(out.join("waveforms.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    // Every node of the MCU input, not only a probed one.
    for vector in ["v(vdd)", "v(sw)", "v(in)"] {
        assert!(header.split(',').any(|c| c == vector), "{header}");
    }
    let raw = chatterspice::rawfile::RawFile::read(out.join("waveforms.raw")).unwrap();
    let plot = raw.plots.last().unwrap();
    assert_eq!(plot.points(), csv.lines().count() - 1);
    let doc: serde_json::Value = serde_json::from_slice(
        &chatterspice()
            .args(["run", path.to_str().unwrap(), "--format", "json"])
            .output()
            .unwrap()
            .stdout,
    )
    .unwrap();
    assert_eq!(doc["probes"].as_array().unwrap().len(), 0);
    assert!(doc["bounce"]["bounce_count"].as_u64().unwrap() > 0);
}

/// An error in the user's own `[[probe]]` under `base = "default"` names
/// the user's file and its line there, and quotes no line of the merged
/// document nor any path of the machine the binary was built on.
#[test]
fn an_error_under_a_base_names_the_users_own_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("mine.toml");
    std::fs::write(
        &path,
        "base = \"default\"\n\n[[probe]]\nsignal = \"v(in)\"\nlow = 0.99\nhigh = 2.31\n\
         max_edgez = 3\n",
    )
    .unwrap();
    let out = chatterspice()
        .args(["run", path.to_str().unwrap()])
        .assert()
        .code(2);
    let stderr = String::from_utf8_lossy(&out.get_output().stderr).into_owned();
    assert!(stderr.contains("mine.toml:7:"), "{stderr}");
    assert!(stderr.contains("max_edgez"), "{stderr}");
    assert!(!stderr.contains(env!("CARGO_MANIFEST_DIR")), "{stderr}");
    // The file has 7 lines: no other line number may appear.
    assert!(!stderr.contains("line "), "{stderr}");
    assert!(!stderr.contains(" | "), "{stderr}");
}
