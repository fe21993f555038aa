//! `chatterspice raw`: CSV of one plot, JSON summary, statistics, exit codes.

use std::path::PathBuf;

use assert_cmd::Command;
use chatterspice::rawfile::{RawFile, Vector};
use predicates::prelude::*;

use crate::common::{has_words, word};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/raw")
        .join(name)
}

fn raw_cmd() -> Command {
    let mut cmd = Command::cargo_bin("chatterspice").unwrap();
    cmd.arg("raw");
    cmd
}

fn stdout_of(args: &[&str]) -> String {
    let out = raw_cmd()
        .args(args)
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    String::from_utf8(out).unwrap()
}

#[test]
fn csv_of_the_last_plot_by_default_with_exact_values() {
    let path = data("divider_op_tran.raw");
    let csv = stdout_of(&[path.to_str().unwrap()]);
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("time,v(in),v(mid),i(v1)"));
    let raw = RawFile::read(&path).unwrap();
    let tran = &raw.plots[1];
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), tran.points());
    // Every value reads back to the identical f64.
    let vmid = tran.real("v(mid)").unwrap();
    for (row, &v) in rows.iter().zip(vmid) {
        let cell: f64 = row.split(',').nth(2).unwrap().parse().unwrap();
        assert_eq!(cell.to_bits(), v.to_bits());
    }
}

#[test]
fn plot_index_selects_the_operating_point() {
    let csv = stdout_of(&[data("divider_op_tran.raw").to_str().unwrap(), "--plot", "0"]);
    assert_eq!(csv.lines().count(), 2);
    assert!(csv.lines().nth(1).unwrap().starts_with("4.0,1.0,"), "{csv}");
}

#[test]
fn complex_vectors_become_re_and_im_columns() {
    let csv = stdout_of(&[data("rc_ac.raw").to_str().unwrap()]);
    assert_eq!(
        csv.lines().next(),
        Some("frequency,v(in).re,v(in).im,v(out).re,v(out).im,i(v1).re,i(v1).im")
    );
    assert!(csv.lines().nth(1).unwrap().starts_with("10.0,1.0,0.0,"));
}

#[test]
fn json_summarises_every_plot() {
    let out = stdout_of(&[
        data("divider_op_tran.raw").to_str().unwrap(),
        "--format",
        "json",
    ]);
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let plots = json["plots"].as_array().unwrap();
    assert_eq!(plots.len(), 2);
    assert_eq!(plots[0]["name"], "Operating Point");
    assert_eq!(plots[0]["points"], 1);
    assert_eq!(plots[1]["name"], "Transient Analysis");
    assert_eq!(plots[1]["variables"][2]["name"], "v(mid)");
    assert_eq!(plots[1]["flags"]["complex"], false);
}

#[test]
fn stats_give_every_vector_s_count_and_range_of_every_plot() {
    for name in ["divider_op_tran.raw", "rc_ac.raw", "killed_binary.raw"] {
        let path = data(name);
        let out = stdout_of(&[path.to_str().unwrap(), "--format", "stats"]);
        let raw = RawFile::read(&path).unwrap();
        let mut lines = out.lines();
        for (index, plot) in raw.plots.iter().enumerate() {
            let head = lines.next().unwrap();
            assert!(
                head.starts_with(&format!("plot {index}: {}, ", plot.name)),
                "{head}"
            );
            let s = if plot.points() == 1 { "" } else { "s" };
            assert!(
                head.ends_with(&format!(" {} point{s}", plot.points())),
                "{head}"
            );
            assert_eq!(
                lines.next().unwrap().split_whitespace().collect::<Vec<_>>(),
                ["vector", "type", "points", "min", "max"]
            );
            for (i, var) in plot.variables.iter().enumerate() {
                let values: Vec<f64> = match plot.vector(i).unwrap() {
                    Vector::Real(v) => v.to_vec(),
                    Vector::Complex(v) => v.iter().map(|c| c.norm()).collect(),
                };
                let min = values.iter().copied().fold(f64::INFINITY, f64::min);
                let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                let cells: Vec<&str> = lines.next().unwrap().split_whitespace().collect();
                assert_eq!(
                    cells[..3],
                    [&var.name, &var.kind, &values.len().to_string()]
                );
                assert_eq!(cells[3].parse::<f64>().unwrap(), min, "{name} {}", var.name);
                assert_eq!(cells[4].parse::<f64>().unwrap(), max, "{name} {}", var.name);
            }
        }
        assert_eq!(lines.next(), None);
    }
    raw_cmd()
        .arg(data("rc_tran.raw"))
        .args([
            "--format", "stats", "--signal", "v(out)", "--low", "0.3", "--high", "0.6",
        ])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("table or json"));
}

#[test]
fn output_is_byte_identical_across_runs() {
    for format in ["csv", "json", "stats"] {
        let args = [
            data("rc_ac.raw").to_str().unwrap().to_string(),
            "--format".into(),
            format.into(),
        ];
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_eq!(stdout_of(&args), stdout_of(&args));
    }
}

#[test]
fn killed_run_warns_on_stderr_and_succeeds() {
    raw_cmd()
        .arg(data("killed_binary.raw"))
        .assert()
        .success()
        .stderr(
            predicate::str::contains("warning").and(predicate::str::contains("40 whole points")),
        );
}

#[test]
fn bad_input_exits_2_with_a_clear_message() {
    raw_cmd().arg(data("no_such.raw")).assert().code(2).stderr(
        predicate::str::contains("no_such.raw").and(predicate::str::contains("No such file")),
    );
    raw_cmd()
        .arg(data("divider_op_tran.raw"))
        .args(["--plot", "7"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains(
            "there is no plot 7: the file has 2 plot(s)",
        ));
    raw_cmd()
        .arg(data("rc_tran.cir"))
        .assert()
        .code(2)
        .stderr(predicate::str::contains("rc_tran.cir").and(predicate::str::contains("line 1")));
    raw_cmd()
        .arg(data("rc_tran.raw"))
        .args(["--format", "xml"])
        .assert()
        .code(2);
}

/// Every plot of every stored ngspice file gives the same CSV through the
/// streaming path as through the whole-file reader.
#[test]
fn streamed_csv_equals_the_whole_file_csv() {
    for name in [
        "rc_tran.raw",
        "rc_tran_ascii.raw",
        "rc_tran_ngspice44.raw",
        "rc_ac.raw",
        "divider_op_tran.raw",
        "control_write_ac_binary.raw",
        "killed_binary.raw",
    ] {
        let raw = RawFile::read(data(name)).unwrap();
        for index in 0..raw.plots.len() {
            let mut expected = Vec::new();
            chatterspice::rawfile::export::plot_csv(&raw.plots[index], &mut expected).unwrap();
            let mut streamed = Vec::new();
            let result =
                chatterspice::rawfile::stream_csv(&data(name), Some(index), &mut streamed).unwrap();
            if result.is_some() {
                assert_eq!(
                    String::from_utf8(streamed).unwrap(),
                    String::from_utf8(expected.clone()).unwrap(),
                    "{name} plot {index}"
                );
            }
            let index = index.to_string();
            let cli = stdout_of(&[data(name).to_str().unwrap(), "--plot", &index]);
            assert_eq!(cli.as_bytes(), expected, "{name} plot {index}");
        }
    }
    // The batch files stream (the ASCII one falls back to the full reader).
    let mut sink = Vec::new();
    assert!(
        chatterspice::rawfile::stream_csv(&data("rc_tran.raw"), None, &mut sink)
            .unwrap()
            .is_some()
    );
    assert!(
        chatterspice::rawfile::stream_csv(&data("rc_tran_ascii.raw"), None, &mut sink)
            .unwrap()
            .is_none()
    );
}

#[test]
fn devices_and_pipes_are_refused_not_read_forever() {
    for device in ["/dev/zero", "/dev/urandom"] {
        for format in ["csv", "json"] {
            raw_cmd()
                .args([device, "--format", format])
                .timeout(std::time::Duration::from_secs(10))
                .assert()
                .code(2)
                .stderr(predicate::str::contains("not a regular file"));
        }
    }
    let dir = tempfile::tempdir().unwrap();
    raw_cmd()
        .arg(dir.path())
        .assert()
        .code(2)
        .stderr(predicate::str::contains("not a regular file"));
}

/// v(out) of the RC (1 kΩ, 1 µF) rises as 1 − e^(−t/τ): with thresholds
/// 0.3 / 0.7 it has one rising edge, where it crosses 0.7 at
/// τ·ln(1/0.3) (≈ 1.204 ms; the stored run samples every 50 µs, and the
/// crossing is interpolated between samples).
#[test]
fn signal_analysis_of_any_raw_file() {
    let file = data("rc_tran.raw");
    let out = raw_cmd()
        .arg(&file)
        .args(["--signal", "v(out)", "--signal", "v(in)", "--low", "0.3"])
        .args([
            "--low", "0.2", "--high", "0.7", "--high", "0.8", "--format", "json",
        ])
        .assert()
        .success();
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    let probes = v["probes"].as_array().unwrap();
    assert_eq!(probes.len(), 2);
    let out_probe = &probes[0];
    assert_eq!(out_probe["signal"], "v(out)");
    assert_eq!(out_probe["edges"], 1);
    assert_eq!(out_probe["glitches"], 0);
    let t = out_probe["first_edge"].as_f64().unwrap();
    let expected = 1e-3 * (1.0f64 / 0.3).ln();
    assert!((t - expected).abs() < 5e-6, "{t} vs {expected}");
    assert_eq!(out_probe["low"], 0.3);
    assert_eq!(probes[1]["signal"], "v(in)");
    assert_eq!(probes[1]["high"], 0.8);
    assert_eq!(probes[1]["edges"], 1);
    // The table names the probe and its edges.
    raw_cmd()
        .arg(&file)
        .args(["--signal", "v(out)", "--low", "0.3", "--high", "0.7"])
        .assert()
        .success()
        .stdout(predicate::function(|out: &str| {
            // `v(out)  1  0  1.20dd ms`
            let time = |w: &str| {
                w.len() == 6 && w.starts_with("1.20") && w[4..].bytes().all(|b| b.is_ascii_digit())
            };
            has_words(
                out,
                &[&word("v(out)"), &word("1"), &word("0"), &time, &word("ms")],
            )
        }));
}

#[test]
fn a_threshold_never_crossed_is_a_warning_with_the_range() {
    raw_cmd()
        .arg(data("rc_tran.raw"))
        .args(["--signal", "v(out)", "--low", "2", "--high", "3"])
        .assert()
        .success()
        .stderr(
            predicate::str::contains("v(out): no edge")
                .and(predicate::str::contains("range is"))
                .and(predicate::str::contains("high")),
        );
}

#[test]
fn signal_analysis_errors_exit_2_naming_what_to_fix() {
    let file = data("rc_tran.raw");
    raw_cmd()
        .arg(&file)
        .args(["--signal", "v(out)"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("--low and --high"));
    raw_cmd()
        .arg(&file)
        .args(["--signal", "v(nowhere)", "--low", "0.3", "--high", "0.7"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("v(nowhere)").and(predicate::str::contains("v(out)")));
    raw_cmd()
        .arg(&file)
        .args(["--signal", "v(out)", "--low", "0.7", "--high", "0.3"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("low < high"));
    raw_cmd()
        .arg(&file)
        .args([
            "--signal", "v(out)", "--signal", "v(in)", "--low", "1", "--low", "2",
        ])
        .args(["--low", "3", "--high", "4"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("3 values of --low for 2 --signal"));
}

/// A `Flags:` line that disagrees with the data is named as such, not
/// taken for a file cut short (or read as extra points).
#[test]
fn a_wrong_flags_line_is_named() {
    let dir = tempfile::tempdir().unwrap();
    for (name, from, to) in [
        ("rc_tran.raw", "Flags: real", "Flags: complex"),
        (
            "control_write_ac_binary.raw",
            "Flags: complex",
            "Flags: real   ",
        ),
    ] {
        let bytes = std::fs::read(data(name)).unwrap();
        let at = bytes
            .windows(from.len())
            .position(|w| w == from.as_bytes())
            .unwrap_or_else(|| panic!("{name} has no {from}"));
        let mut edited = bytes.clone();
        edited.splice(at..at + from.len(), to.bytes());
        let path = dir.path().join(name);
        std::fs::write(&path, edited).unwrap();
        raw_cmd()
            .arg(&path)
            .assert()
            .code(2)
            .stderr(predicate::str::contains("`Flags:`").and(predicate::str::contains("wrong")));
    }
}
