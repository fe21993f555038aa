//! Every bundled part reproduces the datasheet figures it was fitted to,
//! carries the provenance of that fit, and `parts NAME -o FILE` writes a
//! scenario that loads back.

use assert_cmd::Command;
use chatterspice::calibrate::fit::{datasheet_figures, pick_up_of};
use chatterspice::calibrate::parts;
use chatterspice::scenario::Scenario;

#[test]
fn there_are_ten_parts_and_each_meets_its_datasheet() {
    assert!(parts::all().len() >= 10, "{}", parts::all().len());
    for part in parts::all() {
        let scenario = part.load().unwrap_or_else(|e| panic!("{}: {e}", part.name));
        // `base = "part:NAME"` starts from the same text.
        assert_eq!(
            chatterspice::scenario::bundled_part(part.name),
            Some(part.scenario),
            "{}",
            part.name
        );
        let d = scenario.datasheet.clone().expect("a [datasheet]");
        let provenance = scenario.provenance.clone().expect("a [provenance]");
        assert!(
            ["datasheet", "datasheet + dc_breaking"].contains(&provenance.fitted_to.as_str()),
            "{}: {}",
            part.name,
            provenance.fitted_to
        );
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
    // Each printed figure as printed: a number, or a table of its bounds.
    let im = listed
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == "te-axicom-im-5v")
        .expect("the Axicom IM is listed");
    assert_eq!(im["datasheet"]["bounce_time"]["typ"], 1.0e-3);
    assert_eq!(im["datasheet"]["bounce_time"]["max"], 5.0e-3);
    assert_eq!(im["datasheet"]["coil_voltage"], 5.0);
    assert_eq!(im["met"]["bounce_time"], true);
    assert!(im["envelope"]["source"].is_string());
}

/// Every part the library bundles works without a circuit: `bounce`,
/// `pwl` and `check` on its own scenario (the ideal DC step of its coil).
#[test]
fn every_part_bounces_writes_its_contact_and_checks_without_a_circuit() {
    let dir = tempfile::tempdir().unwrap();
    for part in parts::all() {
        let file = dir.path().join(format!("{}.toml", part.name));
        std::fs::write(&file, part.scenario).unwrap();
        for args in [vec!["bounce"], vec!["pwl"], vec!["check"]] {
            let out = Command::cargo_bin("chatterspice")
                .unwrap()
                .args(&args)
                .arg(&file)
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{} {args:?}: {}",
                part.name,
                String::from_utf8_lossy(&out.stderr)
            );
        }
    }
}

/// At least three parts print a bounce time, and their nominal relays
/// meet it; a bounce time the model misses is caught.
#[test]
fn three_parts_meet_a_printed_bounce_time_and_a_miss_is_caught() {
    let mut met = Vec::new();
    for part in parts::all() {
        let s = part.load().unwrap();
        let d = s.datasheet.clone().unwrap();
        let Some(printed) = d.bounce_time else {
            continue;
        };
        let model = datasheet_figures(&s, &d)
            .into_iter()
            .find(|(n, _)| *n == "bounce_time")
            .and_then(|(_, v)| v)
            .unwrap_or_else(|| panic!("{}: no bounce time", part.name));
        assert!(
            printed.met_by_nominal(model),
            "{}: {model} vs {printed}",
            part.name
        );
        // The same relay against a bounce time ten times shorter fails.
        let missed = chatterspice::scenario::PrintedFigure {
            typ: printed.typ.map(|t| t / 10.0),
            max: printed.max.map(|m| m / 10.0),
            ..printed
        };
        if model > printed.nominal() / 5.0 {
            assert!(!missed.met_by_nominal(model), "{}", part.name);
        }
        met.push(part.name);
    }
    assert!(met.len() >= 3, "{met:?}");
}

/// No part reports a σ finer than 1e-4 of its value: a σ from a zero
/// residual would claim a precision no datasheet has.
#[test]
fn no_part_claims_a_sigma_below_1e_4_relative() {
    for part in parts::all() {
        let provenance = part.load().unwrap().provenance.unwrap();
        for (key, p) in &provenance.parameters {
            if let Some(sigma) = p.sigma {
                assert!(
                    sigma >= 1e-4 * p.value.abs(),
                    "{}: {key} σ {sigma} on {}",
                    part.name,
                    p.value
                );
            }
        }
    }
}

/// Every part's envelope keeps relays and gives a real band (no ngspice:
/// the relay alone on its DC step).
#[test]
fn every_part_envelope_keeps_relays_and_gives_a_band() {
    use chatterspice::envelope::{EnvelopeOptions, run};
    for part in parts::all() {
        let s = part.load().unwrap();
        assert!(s.envelope.is_some(), "{}: no [envelope]", part.name);
        let options = EnvelopeOptions {
            samples: 12,
            jobs: std::num::NonZeroUsize::new(2).unwrap(),
            ..EnvelopeOptions::default()
        };
        let env = run(&s, None, &options).unwrap_or_else(|e| panic!("{}: {e}", part.name));
        assert!(env.report.kept >= 3, "{}: {:?}", part.name, env.report);
        let operate = env.report.quantities["operate_time"];
        assert!(operate.max > operate.min, "{}: {operate:?}", part.name);
        let bounces = env.report.quantities["bounce_count"];
        assert!(bounces.max > bounces.min, "{}: {bounces:?}", part.name);
    }
}

/// Every part's envelope can be simulated relay by relay: at 64 samples
/// `check --envelope` on `base = "part:NAME"` (no circuit) reports no relay
/// NOT EVALUATED (none whose armature reaches the magnet's pole, none the
/// engine refuses) and keeps relays.
#[test]
fn every_part_envelope_evaluates_every_relay_at_64_samples() {
    let dir = tempfile::tempdir().unwrap();
    let mut names = Vec::new();
    for part in parts::all() {
        let file = dir.path().join(format!("{}.toml", part.name));
        std::fs::write(&file, format!("base = \"part:{}\"\n", part.name)).unwrap();
        let out = Command::cargo_bin("chatterspice")
            .unwrap()
            .args(["check", "--envelope", "--samples", "64", "--jobs", "2"])
            .args(["--format", "json"])
            .arg(&file)
            .output()
            .unwrap();
        let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
            panic!(
                "{}: {e}: {}",
                part.name,
                String::from_utf8_lossy(&out.stderr)
            )
        });
        let envelope = &json["envelope"];
        assert_eq!(envelope["samples"], 64, "{}", part.name);
        let failed = envelope["failed"].as_u64().expect("a failed count");
        let failures = envelope["failures"].as_array().expect("a failures list");
        assert!(
            failed == 0 && failures.is_empty(),
            "{}: {failed} relays not evaluated: {failures:?}",
            part.name
        );
        let kept = envelope["kept"].as_u64().expect("a kept count");
        assert!(kept > 0, "{}: no relay kept", part.name);
        names.push(part.name);
    }
    assert_eq!(names.len(), parts::all().len());
    assert!(names.len() >= 11, "{names:?}");
}

/// Every power part that prints a DC breaking figure meets it at the
/// lowest printed voltage with its fitted arc (the model's largest
/// breakable current, at its full gap, within 1 %), and `fit` recovers the
/// arc constants from the figures alone, starting from the defaults.
#[test]
fn power_parts_break_what_their_datasheets_print() {
    let listed: serde_json::Value = serde_json::from_slice(
        &Command::cargo_bin("chatterspice")
            .unwrap()
            .args(["parts", "--format", "json"])
            .output()
            .unwrap()
            .stdout,
    )
    .unwrap();
    let with_figures: Vec<&serde_json::Value> = listed
        .as_array()
        .unwrap()
        .iter()
        .filter(|p| p["dc_breaking"].is_array())
        .collect();
    assert!(with_figures.len() >= 4, "{}", with_figures.len());
    for part in &with_figures {
        let first = &part["dc_breaking"][0];
        let (printed, model) = (
            first["printed"].as_f64().unwrap(),
            first["model"].as_f64().unwrap(),
        );
        assert!(
            (model / printed - 1.0).abs() < 0.01,
            "{}: {first}",
            part["name"]
        );
    }

    // The Finder's three figures, fitted from silver's defaults.
    let dir = tempfile::tempdir().unwrap();
    let part = parts::find("finder-40.52-12vdc").unwrap();
    let text = part
        .scenario
        .replace("field = ", "# field = ")
        .replace("low_current_gap = ", "# low_current_gap = ");
    assert!(text.contains("current = 0.3\n"));
    let prior = dir.path().join("prior.toml");
    std::fs::write(&prior, &text).unwrap();
    let defaults = Scenario::load(&prior).unwrap().arc.unwrap().model();
    assert_eq!(defaults.low_current, chatterspice::arc::DEFAULT_LOW_CURRENT);
    assert_eq!(
        defaults.low_current_gap,
        chatterspice::arc::DEFAULT_LOW_CURRENT_GAP
    );
    let fitted = dir.path().join("fitted.toml");
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["fit"])
        .arg(&prior)
        .args(["--free", "arc.field,arc.low_current_gap", "-o"])
        .arg(&fitted)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let model = Scenario::load(&fitted).unwrap().arc.unwrap().model();
    // The three figures lie on one tangent curve: a = 21.0 V, K = 5.40 V·A
    // at the 0.3 mm gap, read as D·gap (C stays 0).
    assert!(
        (model.arc_voltage(0.3e-3) / 21.0 - 1.0).abs() < 2e-3,
        "{model:?}"
    );
    assert!(
        (model.low_current_term(0.3e-3) / 5.40 - 1.0).abs() < 2e-3,
        "{model:?}"
    );
    assert_eq!(model.low_current, 0.0, "{model:?}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("dc_breaking") && stdout.contains("arc.field"),
        "{stdout}"
    );
    // The mechanics' provenance is kept, the arc's added.
    let written = std::fs::read_to_string(&fitted).unwrap();
    assert!(written.contains("mechanics.mass") && written.contains("\"arc.low_current_gap\""));

    // A figure that is not a number a datasheet prints names its key.
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, text.replace("current = 0.3\n", "current = -0.3\n")).unwrap();
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["fit"])
        .arg(&bad)
        .args(["--free", "arc.low_current_gap"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("bad.toml:")
            && stderr.contains("].current` = -0.3")
            && stderr.contains("must be > 0"),
        "{stderr}"
    );
    // Arc keys without a breaking curve: told what to add.
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args([
            "fit",
            "parts/coto-9104-05.toml",
            "--free",
            "arc.low_current",
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("dc_breaking"));
}
