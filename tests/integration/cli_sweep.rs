//! `chatterspice sweep` and `chatterspice merge` end to end: the CSV is
//! the same for any `--jobs` (mechanics only, and a small sweep on real
//! ngspice), samples that never close are recorded, shards merged equal
//! one run byte for byte, and bad input is exit code 2 naming the key.
//!
//! Tests that need ngspice skip with a note when it is missing, and fail
//! when `REQUIRE_NGSPICE=1` (CI sets it).

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use predicates::prelude::*;

use crate::common::{has_words, word};

fn chatterspice() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

/// The built-in relay and circuit with `sweep` appended, written to
/// `dir/relay.toml` (its netlist named by absolute path).
fn scenario(dir: &Path, sweep: &str) -> PathBuf {
    let netlist = Path::new(env!("CARGO_MANIFEST_DIR")).join("netlists/mcu_input.cir");
    let text = chatterspice::scenario::DEFAULT_SCENARIO_TOML
        .replace("../netlists/mcu_input.cir", &netlist.to_string_lossy());
    let path = dir.join("relay.toml");
    std::fs::write(&path, format!("{text}\n{sweep}\n")).unwrap();
    path
}

const VARY: &str = "[sweep]\nsamples = 6\nseed = 11\n[sweep.vary]\n\"mechanics.mass\" = 0.1\n\
                    \"surface.damping\" = { normal = 0.1 }\n\"mechanics.force\" = 0.2";

/// Run `sweep` with `args` into `dir/name`, returning the CSV.
fn sweep_csv(scenario: &Path, dir: &Path, name: &str, args: &[&str]) -> Vec<u8> {
    let out = dir.join(name);
    chatterspice()
        .arg("sweep")
        .arg(scenario)
        .arg("--out")
        .arg(&out)
        .args(args)
        .assert()
        .success();
    std::fs::read(out.join("sweep.csv")).unwrap()
}

#[test]
fn mechanics_only_csv_is_the_same_for_one_and_two_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let args = ["--mechanics-only", "--samples", "2000"];
    let one = sweep_csv(
        &s,
        dir.path(),
        "j1",
        &[&args[..], &["--jobs", "1"]].concat(),
    );
    let two = sweep_csv(
        &s,
        dir.path(),
        "j2",
        &[&args[..], &["--jobs", "2"]].concat(),
    );
    assert_eq!(one, two);
    assert_eq!(String::from_utf8(one).unwrap().lines().count(), 2001);
    for file in ["summary.json", "sweep.svg", "sweep.png"] {
        assert_eq!(
            std::fs::read(dir.path().join("j1").join(file)).unwrap(),
            std::fs::read(dir.path().join("j2").join(file)).unwrap(),
            "{file}"
        );
    }
}

#[test]
fn ngspice_csv_is_the_same_for_one_and_two_jobs() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let one = sweep_csv(&s, dir.path(), "j1", &["--jobs", "1"]);
    let two = sweep_csv(&s, dir.path(), "j2", &["--jobs", "2"]);
    assert_eq!(one, two);
    let text = String::from_utf8(one).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "index,mechanics.force,mechanics.mass,surface.damping,outcome,bounce_count,\
         first_impact,settle_time,bounce_time,v(in).edges,v(in).peak,v(in).lockout,v(in).stable_for,verdict,failed_limits,error"
    );
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 6);
    for (i, row) in rows.iter().enumerate() {
        assert!(row.starts_with(&format!("{i},")), "{row}");
        assert!(row.ends_with(",pass,,"), "every sample ran: {row}");
        // The bounce makes extra edges at the MCU pin.
        let edges: usize = row.split(',').nth(9).unwrap().parse().unwrap();
        assert!(edges >= 1, "{row}");
    }
}

#[test]
fn an_ngspice_sweep_with_samples_that_never_close_completes_and_records_them() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    // Up to 0.3 N the armature cannot reach the gap; from 0.4 N it
    // touches but falls back open (ends_open) until, from 0.7 N, it stays.
    let s = scenario(
        dir.path(),
        "[sweep.grid]\n\"mechanics.force\" = { from = 0.1, to = 1.0, steps = 10 }",
    );
    let out = dir.path().join("out");
    chatterspice()
        .args(["sweep", "--jobs", "2", "--out"])
        .arg(&out)
        .arg(&s)
        .assert()
        // One sample could not run (below), so not every sample passed.
        .code(1)
        .stdout(predicate::str::contains("never_closes 3"))
        // The probe's peak in its unit.
        .stdout(predicate::function(|out: &str| {
            out.lines()
                .find(|l| l.starts_with("v(in) peak"))
                .is_some_and(|l| l.trim_end().ends_with(" V"))
        }));
    let text = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(rows.len(), 10, "{text}");
    for row in &rows[..3] {
        // Recorded: the outcome, no bounce, and a pin that never moved.
        assert!(row.contains(",never_closes,0,,,,0,"), "{row}");
        assert!(row.ends_with(",pass,,"), "{row}");
    }
    assert!(rows[3].contains(",ends_open,"), "{}", rows[3]);
    // At 0.7 N it chatters for 9.5 ms, past the netlist's 5 ms `.tran`:
    // that sample is an error row saying what to change, and the sweep
    // goes on.
    assert!(
        rows[6].contains(",resolved,19,")
            && rows[6].contains(",error,,")
            && rows[6].contains("`.tran 1e-7 1.2e-2 0 2e-6 uic`"),
        "{}",
        rows[6]
    );
    for row in &rows[7..] {
        assert!(
            row.contains(",stuck,") || row.contains(",resolved,"),
            "{row}"
        );
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["outcomes"]["never_closes"], 3);
    assert_eq!(summary["kind"], "grid");
}

#[test]
fn an_ngspice_failure_is_a_row_and_the_sweep_goes_on() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    // A probe of a node the circuit does not have fails every sample's
    // analysis, after ngspice ran.
    let s = scenario(dir.path(), VARY);
    let text = std::fs::read_to_string(&s)
        .unwrap()
        .replace("signal = \"v(in)\"", "signal = \"v(nowhere)\"");
    std::fs::write(&s, text).unwrap();
    let out = dir.path().join("out");
    chatterspice()
        .args(["sweep", "--samples", "2", "--out"])
        .arg(&out)
        .arg(&s)
        .assert()
        .code(1)
        .stdout(predicate::str::contains("errors: 2"));
    let text = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(rows.len(), 2);
    for row in rows {
        // The probe's cells are there, empty.
        assert!(
            row.contains(",stuck,") && row.contains(",,,error,,"),
            "{row}"
        );
        assert!(row.contains("v(nowhere)"), "{row}");
    }
    // Every row has the header's width: the file reads back.
    let mut reader = csv::Reader::from_path(out.join("sweep.csv")).unwrap();
    assert_eq!(reader.records().filter_map(Result::ok).count(), 2);
}

fn shards_then_merge(dir: &Path, s: &Path, extra: &[&str]) {
    let whole = sweep_csv(s, dir, "whole", extra);
    let shard_dir = dir.join("shards");
    for k in ["2/3", "1/3", "3/3"] {
        chatterspice()
            .arg("sweep")
            .arg(s)
            .args(["--shard", k, "--out"])
            .arg(&shard_dir)
            .args(extra)
            .assert()
            .success();
    }
    assert!(!shard_dir.join("summary.json").exists());
    let merged = dir.join("merged.csv");
    chatterspice()
        .arg("merge")
        .arg(&merged)
        .args(["3", "1", "2"].map(|k| shard_dir.join(format!("sweep.{k}-of-3.csv"))))
        .assert()
        .success();
    assert_eq!(std::fs::read(&merged).unwrap(), whole);
}

#[test]
fn shards_merged_equal_one_run_byte_for_byte() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    shards_then_merge(dir.path(), &s, &["--mechanics-only", "--samples", "1500"]);
}

#[test]
fn ngspice_shards_merged_equal_one_run_byte_for_byte() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    shards_then_merge(dir.path(), &s, &["--samples", "5"]);
}

#[test]
fn merge_reports_missing_samples_and_refuses_to_write() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let out = dir.path().join("shards");
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--shard", "1/2", "--out"])
        .arg(&out)
        .assert()
        .success();
    let merged = dir.path().join("merged.csv");
    chatterspice()
        .arg("merge")
        .arg(&merged)
        .arg(out.join("sweep.1-of-2.csv"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("missing: 1, 3"));
    assert!(!merged.exists());
    chatterspice()
        .arg("merge")
        .arg(&merged)
        .arg(out.join("sweep.1-of-2.csv"))
        .args(["--allow-missing", "--samples", "6"])
        .assert()
        .success()
        .stderr(predicate::str::contains("3 sample(s) missing: 1, 3, 5"));
}

#[test]
fn merge_refuses_shards_of_different_sweeps_naming_what_differs() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let shard = |k: &str, seed: &str, out: &str| {
        chatterspice()
            .arg("sweep")
            .arg(&s)
            .args([
                "--mechanics-only",
                "--samples",
                "40",
                "--seed",
                seed,
                "--shard",
                k,
                "--out",
            ])
            .arg(dir.path().join(out))
            .assert()
            .success();
        dir.path()
            .join(out)
            .join(format!("sweep.{}.csv", k.replace('/', "-of-")))
    };
    let a = shard("1/2", "7", "a");
    let b = shard("2/2", "8", "b");
    let merged = dir.path().join("merged.csv");
    chatterspice()
        .arg("merge")
        .arg(&merged)
        .args([&a, &b])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("different sweeps")
                .and(predicate::str::contains("seed"))
                .and(predicate::str::contains("7 against 8")),
        );
    assert!(!merged.exists());
    // The shards of one sweep merge; the sample count comes from their
    // identity files, so a missing shard is found without --samples.
    let b = shard("2/2", "7", "c");
    chatterspice()
        .arg("merge")
        .arg(&merged)
        .args([&a, &b])
        .assert()
        .success();
    let rows = std::fs::read_to_string(&merged).unwrap().lines().count();
    assert_eq!(rows, 41);
    // With a summary beside it, of all 40 samples.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["samples"], 40, "{summary}");
    assert_eq!(summary["seed"], 7);
    assert_eq!(summary["identity"], "verified");
    let whole = dir.path().join("whole");
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args([
            "--mechanics-only",
            "--samples",
            "40",
            "--seed",
            "7",
            "--out",
        ])
        .arg(&whole)
        .assert()
        .success();
    let one_run: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(whole.join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["bounce_count"], one_run["bounce_count"]);
    assert_eq!(summary["worst"], one_run["worst"]);
    std::fs::remove_file(dir.path().join("summary.json")).unwrap();
    let alone = dir.path().join("alone.csv");
    chatterspice()
        .arg("merge")
        .arg(&alone)
        .arg(&a)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("missing"));
}

#[test]
fn an_unknown_vary_key_is_exit_2_naming_the_key_and_listing_the_keys() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), "[sweep.vary]\n\"mechanics.mas\" = 0.1");
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .arg("--mechanics-only")
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("`mechanics.mas`")
                .and(predicate::str::contains("relay.toml:"))
                .and(predicate::str::contains(
                    "mechanics.mass, mechanics.stiffness",
                )),
        );
}

#[test]
fn bad_input_is_exit_2_with_what_to_change() {
    let dir = tempfile::tempdir().unwrap();
    let no_sweep = scenario(dir.path(), "");
    chatterspice()
        .arg("sweep")
        .arg(&no_sweep)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("[sweep.vary]"));
    let s = scenario(dir.path(), VARY);
    for (args, message) in [
        (&["--shard", "3/2"][..], "--shard"),
        (&["--shard", "x"][..], "K/N"),
        (&["--jobs", "0"][..], "--jobs"),
    ] {
        chatterspice()
            .arg("sweep")
            .arg(&s)
            .args(args)
            .assert()
            .code(2)
            .stderr(predicate::str::contains(message));
    }
    let grid = scenario(
        dir.path(),
        "[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 1.0, steps = 3 }",
    );
    chatterspice()
        .arg("sweep")
        .arg(&grid)
        .args(["--samples", "10", "--mechanics-only"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("grid"));
}

#[test]
fn existing_files_are_not_overwritten_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("summary.json"), "mine").unwrap();
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--out"])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--force"));
    assert_eq!(
        std::fs::read_to_string(out.join("summary.json")).unwrap(),
        "mine"
    );
    assert!(!out.join("sweep.csv").exists());
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--force", "--out"])
        .arg(&out)
        .assert()
        .success();
    assert_ne!(
        std::fs::read_to_string(out.join("summary.json")).unwrap(),
        "mine"
    );
}

#[test]
fn an_interrupted_sweep_leaves_the_header_and_whole_rows() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let out = dir.path().join("out");
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("chatterspice"))
        .arg("sweep")
        .arg(&s)
        .args([
            "--mechanics-only",
            "--jobs",
            "1",
            "--samples",
            "100000000",
            "--out",
        ])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // A running sweep writes here; SIGKILL leaves it for --resume.
    let csv = out.join("sweep.csv.partial");
    // Until some rows are on disk, then kill it as a scheduler would.
    let started = std::time::Instant::now();
    while std::fs::metadata(&csv).map_or(0, |m| m.len()) < 100_000 {
        assert!(started.elapsed().as_secs() < 60, "no rows written");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let text = std::fs::read_to_string(&csv).unwrap();
    // Whole lines only; a kill inside a write(2) could cut the last one,
    // which a reader then drops.
    let whole = &text[..=text.rfind('\n').unwrap()];
    let mut reader = csv::Reader::from_reader(whole.as_bytes());
    let width = reader.headers().unwrap().len();
    let mut rows = 0u64;
    for (i, row) in reader.records().enumerate() {
        let row = row.unwrap();
        assert_eq!(row.len(), width);
        assert_eq!(row[0].parse::<u64>().unwrap(), i as u64);
        rows += 1;
    }
    assert!(rows > 500, "{rows}");
    assert!(!out.join("summary.json").exists());
    assert!(!out.join("sweep.csv").exists());
    assert!(out.join("sweep.meta.json.partial").exists());
}

#[test]
fn samples_are_held_against_the_limits_and_a_failure_is_exit_1() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(
        dir.path(),
        &format!("[limits]\nmax_bounce_time = 1.2e-3\n\n{VARY}"),
    );
    let out = dir.path().join("out");
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--samples", "400", "--out"])
        .arg(&out)
        .assert()
        .code(1)
        .stdout(predicate::function(|out: &str| {
            let count = |w: &str| !w.is_empty() && w.bytes().all(|b| b.is_ascii_digit());
            let samples = |w: &str| w == "sample" || w == "samples";
            has_words(
                out,
                &[
                    &word("limits.max_bounce_time:"),
                    &count,
                    &samples,
                    &word("failed"),
                    &word("it"),
                ],
            )
        }));
    let mut reader = csv::Reader::from_path(out.join("sweep.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (time, verdict, failed) = (
        column("bounce_time"),
        column("verdict"),
        column("failed_limits"),
    );
    let mut failing = 0;
    for row in reader.records() {
        let row = row.unwrap();
        let long = row[time].parse::<f64>().is_ok_and(|t| t > 1.2e-3) || row[time].is_empty();
        assert_eq!(&row[verdict], if long { "fail" } else { "pass" }, "{row:?}");
        assert_eq!(
            &row[failed],
            if long { "limits.max_bounce_time" } else { "" }
        );
        failing += usize::from(long);
    }
    assert!(failing > 0 && failing < 400, "{failing}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["failing"], failing);
    assert_eq!(
        summary["limits"]["limits.max_bounce_time"]["failing"],
        failing
    );
    assert_eq!(summary["worst"]["verdict"], "fail");
}

#[test]
fn an_ngspice_sweep_holds_each_sample_against_the_probe_limits() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let text = std::fs::read_to_string(&s)
        .unwrap()
        .replace("high = 2.31 ", "high = 2.31\nmax_edges = 7\n#");
    std::fs::write(&s, text).unwrap();
    let out = dir.path().join("out");
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .arg("--out")
        .arg(&out)
        .assert()
        .code(1);
    let text = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let mut failing = 0;
    for row in text.lines().skip(1) {
        let cells: Vec<&str> = row.split(',').collect();
        let edges: u64 = cells[9].parse().unwrap();
        if edges > 7 {
            assert!(row.ends_with(",fail,probe[0].max_edges,"), "{row}");
            failing += 1;
        } else {
            assert!(row.ends_with(",pass,,"), "{row}");
        }
    }
    assert!(failing > 0, "{text}");
}

/// The coil-driven relay of examples/scenarios/relay-driver.toml with
/// `sweep` appended, written to `dir/coil.toml`.
fn coil_scenario(dir: &Path, sweep: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("examples/scenarios/relay-driver.toml"))
        .unwrap()
        .replace(
            "../../netlists/relay_driver_diode.cir",
            &root
                .join("netlists/relay_driver_diode.cir")
                .to_string_lossy(),
        );
    let path = dir.join("coil.toml");
    std::fs::write(&path, format!("{text}\n{sweep}\n")).unwrap();
    path
}

#[test]
fn a_coil_driven_relay_sweeps_its_release_through_the_circuit() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let s = coil_scenario(
        dir.path(),
        "[sweep]\nsamples = 2\nseed = 3\n[sweep.vary]\n\"coil.resistance\" = 0.05",
    );
    let csv = String::from_utf8(sweep_csv(&s, dir.path(), "out", &["--jobs", "2"])).unwrap();
    let mut rows = csv::Reader::from_reader(csv.as_bytes());
    let header = rows.headers().unwrap().clone();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (release, nc) = (column("release_time"), column("nc_bounce_time"));
    let records: Vec<csv::StringRecord> = rows.records().map(Result::unwrap).collect();
    assert_eq!(records.len(), 2);
    for r in &records {
        assert_eq!(&r[column("error")], "", "{r:?}");
        // The plain diode releases in some 15 ms (README).
        let t: f64 = r[release].parse().unwrap();
        assert!((5e-3..30e-3).contains(&t), "{r:?}");
        let b: f64 = r[nc].parse().unwrap();
        assert!(b > 0.0, "{r:?}");
    }
    // The relay moves only in its circuit.
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--out"])
        .arg(dir.path().join("mech"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--mechanics-only"));
}

/// `--jobs J` bounds the ngspice processes running at once, with and
/// without `--ideal`: a wrapper around ngspice records how many of its
/// kind are running each time one starts.
#[test]
fn jobs_bound_the_ngspice_processes_at_once() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    let running = dir.path().join("running");
    std::fs::create_dir(&running).unwrap();
    let log = dir.path().join("counts.log");
    let wrapper = dir.path().join("ngspice-counting.sh");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\ntouch '{r}'/$$\nls '{r}' | wc -l >> '{log}'\nsleep 0.05\n\
             ngspice \"$@\"\nrc=$?\nrm -f '{r}'/$$\nexit $rc\n",
            r = running.display(),
            log = log.display()
        ),
    )
    .unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&wrapper, std::fs::Permissions::from_mode(0o755)).unwrap();
    let s = scenario(dir.path(), VARY);
    for (jobs, ideal, most) in [("1", true, 1), ("2", false, 2), ("2", true, 2)] {
        std::fs::write(&log, "").unwrap();
        let out = dir.path().join(format!("out-{jobs}-{ideal}"));
        let mut cmd = chatterspice();
        cmd.arg("sweep")
            .arg(&s)
            .args(["--samples", "4", "--jobs", jobs, "--ngspice"])
            .arg(&wrapper)
            .arg("--out")
            .arg(&out);
        if ideal {
            cmd.arg("--ideal");
        }
        cmd.assert().success();
        let counts: Vec<usize> = std::fs::read_to_string(&log)
            .unwrap()
            .lines()
            .map(|l| l.trim().parse().unwrap())
            .collect();
        // The version check, then one run per sample (two with --ideal).
        let runs = if ideal { 8 } else { 4 };
        assert!(counts.len() > runs, "{counts:?}");
        let peak = counts.iter().copied().max().unwrap();
        assert!(
            peak <= most,
            "--jobs {jobs} --ideal {ideal}: {peak} at once"
        );
        let header = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
        let header = header.lines().next().unwrap().to_owned();
        assert_eq!(header.contains("v(in).ideal_edges"), ideal, "{header}");
    }
}

/// A sweep too big to finish is refused before it starts, naming what
/// made it so.
#[test]
fn a_sweep_of_a_billion_samples_is_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let grid = "[sweep.grid]\n\"mechanics.mass\" = { from = 1e-4, to = 3e-4, steps = 40000 }\n\
                \"surface.damping\" = { from = 1.0, to = 3.0, steps = 25000 }";
    let s = scenario(dir.path(), grid);
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--out"])
        .arg(dir.path().join("out"))
        .timeout(std::time::Duration::from_secs(10))
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("1000000000 samples")
                .and(predicate::str::contains("[sweep.grid]")),
        );
    let s = scenario(dir.path(), VARY);
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--samples", "1000000000", "--out"])
        .arg(dir.path().join("out2"))
        .timeout(std::time::Duration::from_secs(10))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--samples"));
}

/// The summary's worst sample is one that could not run when there is
/// one, columns stay aligned with long probe names.
#[test]
fn the_worst_sample_ranks_errors_first_and_columns_align() {
    let _ng = ngspice_or_skip!();
    let dir = tempfile::tempdir().unwrap();
    // At 0.7 N the relay chatters past the netlist's 5 ms `.tran`: that
    // sample cannot run; the others pass.
    let text = scenario(dir.path(), "")
        .to_str()
        .map(|p| std::fs::read_to_string(p).unwrap())
        .unwrap()
        .replace("signal = \"v(in)\"", "signal = \"v(in,      0)\"");
    let grid = "[sweep.grid]\n\"mechanics.force\" = { from = 0.7, to = 1.0, steps = 3 }\n";
    let path = dir.path().join("worst.toml");
    std::fs::write(&path, format!("{text}\n{grid}")).unwrap();
    let out = chatterspice()
        .arg("sweep")
        .arg(&path)
        .arg("--out")
        .arg(dir.path().join("o"))
        .assert()
        .code(1);
    let stdout = String::from_utf8(out.get_output().stdout.clone()).unwrap();
    let worst = stdout.lines().find(|l| l.starts_with("worst:")).unwrap();
    assert!(worst.starts_with("worst: sample 0 "), "{stdout}");
    assert!(stdout.contains("error in sample 0"), "{stdout}");
    // Every row of the distribution table has its numbers in the same
    // columns as the header's.
    let header = stdout
        .lines()
        .find(|l| l.trim_start().starts_with("min"))
        .unwrap();
    let end = header.len();
    let rows: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("v(in,      0)"))
        .collect();
    assert_eq!(rows.len(), 2, "{stdout}");
    for line in rows {
        assert_eq!(line.chars().count(), header.chars().count(), "{stdout}");
    }
    let _ = end;
}

/// The files of a sweep directory, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Starts a mechanics-only sweep of `samples` into `out`, waits until
/// `min_bytes` of rows are in its partial CSV, and stops it with `signal`.
fn interrupted_sweep(
    scenario: &Path,
    out: &Path,
    samples: &str,
    min_bytes: u64,
    signal: i32,
) -> std::process::ExitStatus {
    let mut child = std::process::Command::new(assert_cmd::cargo::cargo_bin("chatterspice"))
        .arg("sweep")
        .arg(scenario)
        .args([
            "--mechanics-only",
            "--jobs",
            "1",
            "--samples",
            samples,
            "--out",
        ])
        .arg(out)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let partial = out.join("sweep.csv.partial");
    let started = std::time::Instant::now();
    while std::fs::metadata(&partial).map_or(0, |m| m.len()) < min_bytes {
        assert!(started.elapsed().as_secs() < 60, "no rows written");
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the sweep ended ({status}) before it could be interrupted");
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    // SAFETY: kill(2) reads no memory of ours.
    unsafe { libc::kill(child.id() as i32, signal) };
    child.wait().unwrap()
}

/// SIGTERM and SIGKILL in the middle of a sweep, then `--resume`: the
/// same CSV, summary and identity file as an uninterrupted run, and no
/// lock, partial or temporary file left.
#[test]
fn an_interrupted_sweep_resumes_to_the_same_files() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let samples = "60000";
    let whole = dir.path().join("whole");
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--samples", samples, "--out"])
        .arg(&whole)
        .assert()
        .success();
    let expected = listing(&whole);
    assert_eq!(
        expected,
        [
            "summary.json",
            "sweep.csv",
            "sweep.meta.json",
            "sweep.png",
            "sweep.svg"
        ]
    );
    for (signal, code) in [(libc::SIGTERM, Some(143)), (libc::SIGKILL, None)] {
        let out = dir.path().join(format!("cut{signal}"));
        let status = interrupted_sweep(&s, &out, samples, 200_000, signal);
        assert_eq!(status.code(), code, "signal {signal}");
        if signal == libc::SIGTERM {
            // The finished rows in place, marked incomplete; nothing else.
            assert_eq!(listing(&out), ["sweep.csv", "sweep.meta.json"]);
            let meta: serde_json::Value =
                serde_json::from_slice(&std::fs::read(out.join("sweep.meta.json")).unwrap())
                    .unwrap();
            assert_eq!(meta["complete"], false);
            let rows = meta["rows"].as_u64().unwrap();
            assert!(rows > 1000, "{meta}");
            let text = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
            assert!(text.ends_with('\n'));
            assert_eq!(text.lines().count() as u64, rows + 1);
            // A fresh sweep into it is refused without --force.
            chatterspice()
                .arg("sweep")
                .arg(&s)
                .args(["--mechanics-only", "--samples", samples, "--out"])
                .arg(&out)
                .assert()
                .code(2)
                .stderr(predicate::str::contains("--resume"));
        }
        chatterspice()
            .arg("sweep")
            .arg(&s)
            .args([
                "--mechanics-only",
                "--jobs",
                "2",
                "--samples",
                samples,
                "--resume",
            ])
            .arg(&out)
            .assert()
            .success()
            .stderr(predicate::str::contains("resuming"));
        assert_eq!(listing(&out), expected, "signal {signal}");
        for name in ["sweep.csv", "summary.json", "sweep.meta.json"] {
            assert!(
                std::fs::read(out.join(name)).unwrap() == std::fs::read(whole.join(name)).unwrap(),
                "{name} differs after signal {signal} and --resume"
            );
        }
    }
}

/// `--resume` checks it is the same sweep: another seed is exit 2 naming
/// the seed, and a complete sweep has nothing to resume.
#[test]
fn resume_refuses_another_sweep() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let out = dir.path().join("out");
    let status = interrupted_sweep(&s, &out, "100000000", 50_000, libc::SIGINT);
    assert_eq!(status.code(), Some(130));
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args([
            "--mechanics-only",
            "--samples",
            "100000000",
            "--seed",
            "12",
            "--resume",
        ])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("seed is 11, this one's is 12"));
    let done = dir.path().join("done");
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--out"])
        .arg(&done)
        .assert()
        .success();
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--resume"])
        .arg(&done)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("nothing to resume"));
}

/// Two sweeps into one directory at once: the second is refused while
/// the first runs, and the first's CSV is whole.
#[test]
fn a_second_sweep_into_the_same_directory_is_refused_while_the_first_runs() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let out = dir.path().join("out");
    let mut first = std::process::Command::new(assert_cmd::cargo::cargo_bin("chatterspice"))
        .arg("sweep")
        .arg(&s)
        .args([
            "--mechanics-only",
            "--jobs",
            "1",
            "--samples",
            "100000",
            "--force",
            "--out",
        ])
        .arg(&out)
        .stdout(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    while !out.join("sweep.csv.partial").exists() {
        assert!(started.elapsed().as_secs() < 60);
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--samples", "50", "--force", "--out"])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("another chatterspice run"));
    assert!(first.wait().unwrap().success());
    let mut reader = csv::Reader::from_path(out.join("sweep.csv")).unwrap();
    let width = reader.headers().unwrap().len();
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 100_000);
    for (i, row) in rows.iter().enumerate() {
        assert_eq!((row.len(), row[0].parse::<usize>().unwrap()), (width, i));
    }
}

/// `--force` never writes through a link onto an input, nor over the
/// scenario itself.
#[cfg(unix)]
#[test]
fn a_sweep_never_overwrites_an_input() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let netlist = Path::new(env!("CARGO_MANIFEST_DIR")).join("netlists/mcu_input.cir");
    let before = std::fs::read(&netlist).unwrap();
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    std::os::unix::fs::symlink(&netlist, out.join("sweep.csv")).unwrap();
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--force", "--out"])
        .arg(&out)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("input of the run"));
    assert_eq!(std::fs::read(&netlist).unwrap(), before);
    // The scenario living at DIR/sweep.csv.
    let inside = dir.path().join("inside");
    std::fs::create_dir(&inside).unwrap();
    std::fs::copy(&s, inside.join("sweep.csv")).unwrap();
    let text = std::fs::read(inside.join("sweep.csv")).unwrap();
    chatterspice()
        .arg("sweep")
        .arg(inside.join("sweep.csv"))
        .args(["--mechanics-only", "--force", "--out"])
        .arg(&inside)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("input of the run"));
    assert_eq!(std::fs::read(inside.join("sweep.csv")).unwrap(), text);
    assert_eq!(listing(&inside), ["sweep.csv"]);
}

#[test]
fn merge_refuses_shards_without_their_identity_unless_told() {
    let dir = tempfile::tempdir().unwrap();
    let s = scenario(dir.path(), VARY);
    let shard = |k: &str, seed: &str, out: &str| {
        chatterspice()
            .arg("sweep")
            .arg(&s)
            .args([
                "--mechanics-only",
                "--samples",
                "20",
                "--seed",
                seed,
                "--shard",
                k,
                "--out",
            ])
            .arg(dir.path().join(out))
            .assert()
            .success();
        let name = format!("sweep.{}.csv", k.replace('/', "-of-"));
        // Copied the way `scp shards/*.csv` copies: without the .meta.json.
        let copied = dir.path().join("copied").join(&name);
        std::fs::create_dir_all(copied.parent().unwrap()).unwrap();
        std::fs::copy(dir.path().join(out).join(&name), &copied).unwrap();
        copied
    };
    // Two different seeds: nothing left to tell them apart.
    let a = shard("1/2", "7", "a");
    let b = shard("2/2", "8", "b");
    let merged = dir.path().join("merged.csv");
    chatterspice()
        .arg("merge")
        .arg(&merged)
        .args([&a, &b])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("sweep.1-of-2.meta.json")
                .and(predicate::str::contains("is missing"))
                .and(predicate::str::contains("--unverified")),
        );
    assert!(!merged.exists());
    assert!(!dir.path().join("summary.json").exists());
    chatterspice()
        .arg("merge")
        .arg(&merged)
        .args([&a, &b])
        .arg("--unverified")
        .assert()
        .success()
        .stderr(predicate::str::contains("unverified"));
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("summary.json")).unwrap())
            .unwrap();
    assert_eq!(summary["identity"], "unverified", "{summary}");
    assert_eq!(summary["seed"], serde_json::Value::Null);
}

/// `--mechanics-only` on a coil-driven part: each sample closes on the DC
/// step of its coil, as `bounce` simulates it (the same bounce count and
/// settle time, sample by sample).
#[test]
fn a_mechanics_only_sweep_runs_a_coil_part_on_its_dc_step() {
    let dir = tempfile::tempdir().unwrap();
    let s = dir.path().join("part.toml");
    std::fs::write(
        &s,
        "base = \"part:te-axicom-im-5v\"\n\n[sweep.grid]\n\
         \"coil.resistance\" = { from = 160.0, to = 200.0, steps = 3 }\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    chatterspice()
        .arg("sweep")
        .arg(&s)
        .args(["--mechanics-only", "--out"])
        .arg(&out)
        .assert()
        .success();
    let mut reader = csv::Reader::from_path(out.join("sweep.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let column = |name: &str| header.iter().position(|h| h == name).unwrap();
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 3);
    for row in &rows {
        assert_eq!(&row[column("error")], "", "{row:?}");
        let resistance: f64 = row[column("coil.resistance")].parse().unwrap();
        let one = dir.path().join("one.toml");
        std::fs::write(
            &one,
            format!("base = \"part:te-axicom-im-5v\"\n\n[coil]\nresistance = {resistance:e}\n"),
        )
        .unwrap();
        let bounce: serde_json::Value = serde_json::from_slice(
            &chatterspice()
                .args(["bounce", one.to_str().unwrap(), "--format", "json"])
                .output()
                .unwrap()
                .stdout,
        )
        .unwrap();
        assert_eq!(
            row[column("bounce_count")].parse::<u64>().unwrap(),
            bounce["bounce_count"].as_u64().unwrap(),
            "{row:?}"
        );
        let settle: f64 = row[column("settle_time")].parse().unwrap();
        assert!(
            (settle - bounce["settle_time"].as_f64().unwrap()).abs() < 1e-12,
            "{row:?}"
        );
    }
}
