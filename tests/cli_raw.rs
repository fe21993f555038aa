//! `chatterspice raw`: CSV of one plot, JSON summary, exit codes.

use std::path::PathBuf;

use assert_cmd::Command;
use chatterspice::rawfile::RawFile;
use predicates::prelude::*;

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
    assert!(csv.lines().nth(1).unwrap().starts_with("4e0,1e0,"), "{csv}");
}

#[test]
fn complex_vectors_become_re_and_im_columns() {
    let csv = stdout_of(&[data("rc_ac.raw").to_str().unwrap()]);
    assert_eq!(
        csv.lines().next(),
        Some("frequency,v(in).re,v(in).im,v(out).re,v(out).im,i(v1).re,i(v1).im")
    );
    assert!(csv.lines().nth(1).unwrap().starts_with("1e1,1e0,0e0,"));
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
fn output_is_byte_identical_across_runs() {
    for format in ["csv", "json"] {
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
