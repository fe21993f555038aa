//! Every bundled part reproduces the datasheet figures it was fitted to,
//! carries the provenance of that fit, and `parts NAME -o FILE` writes a
//! scenario that loads back.

use assert_cmd::Command;
use chatterspice::calibrate::fit::{datasheet_figures, pick_up_of};
use chatterspice::calibrate::parts;
use chatterspice::scenario::Scenario;

#[test]
fn there_are_six_parts_and_each_meets_its_datasheet() {
    assert!(parts::all().len() >= 6);
    for part in parts::all() {
        let scenario = part.load().unwrap_or_else(|e| panic!("{}: {e}", part.name));
        let d = scenario.datasheet.clone().expect("a [datasheet]");
        let provenance = scenario.provenance.clone().expect("a [provenance]");
        assert_eq!(provenance.fitted_to, "datasheet", "{}", part.name);
        let model = datasheet_figures(&scenario, &d);
        let mut checked = 0;
        for (name, printed) in d.figures() {
            if name == "release_time" {
                continue;
            }
            let value = model
                .iter()
                .find(|(n, _)| *n == name)
                .and_then(|(_, v)| *v)
                .unwrap_or_else(|| panic!("{}: no model {name}", part.name));
            assert!(
                printed.met_by_nominal(value),
                "{}: {name} model {value}, datasheet {printed}",
                part.name
            );
            checked += 1;
        }
        assert!(checked >= 2, "{}: nothing checked", part.name);
        // The provenance says where the pick-up binds, as the scenario's
        // own load line has it.
        let (pu, line) = pick_up_of(&scenario).expect("a coil");
        assert_eq!(
            provenance.pick_up_binds.as_deref(),
            Some(pu.binding_text(&line).as_str()),
            "{}",
            part.name
        );
        let listed = parts::listing(part);
        assert_eq!(listed.pick_up_binds, provenance.pick_up_binds);
        // The fit moved the free keys away from the priors it started from.
        for (key, p) in &provenance.parameters {
            assert_eq!(
                scenario.number(key).unwrap(),
                Some(p.value),
                "{}: {key}",
                part.name
            );
        }
    }
}

#[test]
fn parts_writes_a_scenario_that_loads_and_never_overwrites() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("relay.toml");
    Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["parts", "panasonic-tq4-5v", "-o"])
        .arg(&file)
        .assert()
        .success();
    let scenario = Scenario::load(&file).expect("loads back");
    assert!(scenario.coil.is_some());
    Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["parts", "panasonic-tq4-5v", "-o"])
        .arg(&file)
        .assert()
        .code(2);
    let listed: serde_json::Value = serde_json::from_slice(
        &Command::cargo_bin("chatterspice")
            .unwrap()
            .args(["parts", "--format", "json"])
            .output()
            .unwrap()
            .stdout,
    )
    .unwrap();
    let first = &listed[0];
    assert!(first["name"].is_string() && first["source"].is_string());
    assert_eq!(first["datasheet"]["bounce_time"], "not given");
}
