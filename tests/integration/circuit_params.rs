//! `[circuit.params]`: values for the netlist's own `.param` names, in a
//! run and as sweep keys, without editing the netlist.

use crate::common;

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;

fn chatterspice() -> Command {
    Command::cargo_bin("chatterspice").unwrap()
}

/// The default relay on a copy of the bundled MCU input (`.param cf=8.2n`)
/// in `dir`, with `params` as the body of `[circuit.params]` and `extra`
/// appended.
fn scenario(dir: &Path, params: &str, extra: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::copy(root.join("netlists/mcu_input.cir"), dir.join("mcu.cir")).unwrap();
    let text = chatterspice::scenario::DEFAULT_SCENARIO_TOML
        .replace("../netlists/mcu_input.cir", "mcu.cir")
        .replace(
            "subckt = \"CONTACT\"",
            &format!("subckt = \"CONTACT\"\n\n[circuit.params]\n{params}\n"),
        );
    let path = dir.join("relay.toml");
    std::fs::write(&path, format!("{text}\n{extra}\n")).unwrap();
    path
}

fn run_json(path: &Path) -> Value {
    let out = chatterspice()
        .args(["run", path.to_str().unwrap(), "--format", "json"])
        .assert()
        .success();
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

fn edges(v: &Value) -> u64 {
    v["probes"][0]["edges"].as_u64().unwrap()
}

#[test]
fn a_param_overrides_the_netlist_value_and_leaves_the_file_alone() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    // The netlist's own 8.2 nF lets the three long openings through.
    let nominal = run_json(&scenario(dir.path(), "cf = 8.2e-9", ""));
    let before = std::fs::read(dir.path().join("mcu.cir")).unwrap();
    // 47 nF: τ = 11 kΩ · 47 nF = 517 µs, longer than every opening.
    let path = scenario(dir.path(), "cf = 47e-9", "");
    let big = run_json(&path);
    assert!(edges(&nominal) > 1, "{}", edges(&nominal));
    assert_eq!(edges(&big), 1);
    assert_eq!(std::fs::read(dir.path().join("mcu.cir")).unwrap(), before);
    // The deck that ran sets it, after the netlist's own definition.
    let out = dir.path().join("out");
    chatterspice()
        .args(["run", path.to_str().unwrap(), "--out"])
        .arg(&out)
        .assert()
        .success();
    let deck = std::fs::read_to_string(out.join("netlist.cir")).unwrap();
    let own = deck.find(".param cf=8.2n").unwrap();
    let ours = deck
        .find(".param cf=4.7e-8")
        .unwrap_or_else(|| panic!("{deck}"));
    assert!(ours > own);
}

#[test]
fn a_param_the_netlist_does_not_define_is_an_error_naming_it() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    let path = scenario(dir.path(), "cx = 47e-9", "");
    chatterspice()
        .args(["run", path.to_str().unwrap()])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("circuit.params.cx")
                .and(predicate::str::contains("mcu.cir"))
                .and(predicate::str::contains("defines: cf")),
        );
}

#[test]
fn bad_param_names_and_values_are_refused_at_load() {
    let dir = tempfile::tempdir().unwrap();
    for (params, needle) in [
        ("\"c-f\" = 1e-9", "not a SPICE parameter name"),
        ("cf = nan", "finite"),
        ("cf = \"8.2n\"", "circuit.params.cf"),
    ] {
        let path = scenario(dir.path(), params, "");
        chatterspice()
            .args(["bounce", path.to_str().unwrap()])
            .assert()
            .code(2)
            .stderr(predicate::str::contains(needle));
    }
}

#[test]
fn a_grid_sweep_varies_the_filter_capacitor() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    let grid =
        "[sweep.grid]\n\"circuit.params.cf\" = { from = 1e-9, to = 100e-9, steps = 5, log = true }";
    let path = scenario(dir.path(), "", grid);
    let out = dir.path().join("sweep");
    chatterspice()
        .args(["sweep", path.to_str().unwrap(), "--out"])
        .arg(&out)
        .assert()
        .success();
    let text = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let mut rows = csv::Reader::from_reader(text.as_bytes());
    let header = rows.headers().unwrap().clone();
    let col = |name: &str| header.iter().position(|h| h == name).unwrap();
    let (cf, edges) = (col("circuit.params.cf"), col("v(in).edges"));
    let points: Vec<(f64, u64)> = rows
        .records()
        .map(|r| {
            let r = r.unwrap();
            (r[cf].parse().unwrap(), r[edges].parse().unwrap())
        })
        .collect();
    assert_eq!(points.len(), 5);
    assert!((points[0].0 - 1e-9).abs() < 1e-21 && (points[4].0 - 100e-9).abs() < 1e-19);
    // A bigger capacitor hides more openings, never fewer.
    for w in points.windows(2) {
        assert!(w[1].1 <= w[0].1, "{points:?}");
    }
    assert!(points[0].1 > points[4].1, "{points:?}");
    assert_eq!(points[4].1, 1);
}

#[test]
fn a_random_sweep_varies_around_the_netlist_s_own_value() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    // No [circuit.params] value: the nominal is the netlist's 8.2n.
    let vary = "[sweep]\nsamples = 4\n[sweep.vary]\n\"circuit.params.cf\" = 0.1";
    let path = scenario(dir.path(), "", vary);
    let out = dir.path().join("sweep");
    chatterspice()
        .args(["sweep", path.to_str().unwrap(), "--out"])
        .arg(&out)
        .assert()
        .success();
    let text = std::fs::read_to_string(out.join("sweep.csv")).unwrap();
    let mut rows = csv::Reader::from_reader(text.as_bytes());
    let col = rows
        .headers()
        .unwrap()
        .iter()
        .position(|h| h == "circuit.params.cf")
        .unwrap();
    let values: Vec<f64> = rows
        .records()
        .map(|r| r.unwrap()[col].parse().unwrap())
        .collect();
    assert_eq!(values.len(), 4);
    for v in &values {
        assert!((v / 8.2e-9 - 1.0).abs() <= 0.1 + 1e-12, "{values:?}");
    }
    assert!(values.windows(2).any(|w| w[0] != w[1]));
}
