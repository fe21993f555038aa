//! The fit recovers known parameters: records and datasheet figures are
//! generated from a scenario with known ("true") values, the scenario
//! handed to the fit is put off by 1.5–2× in every free key, and the fit
//! must come back to the truth (a fit that returned its prior fails).

use std::path::Path;

use chatterspice::calibrate::fit::{FitRequest, Record, events_of, fit, model_events};
use chatterspice::scenario::Scenario;
use chatterspice::{ContactState, Interval};

const STEP: &str = r#"
[mechanics]
mass = 2.0e-4
stiffness = 800.0
damping = 0.02
force = 0.5
gap = 5.0e-4

[surface]
law = "kelvin-voigt"
stiffness = 8.0e4
damping = 0.5

[simulation]
t_end = 0.02
"#;

fn scenario(text: &str) -> Scenario {
    Scenario::parse(text, Path::new("truth.toml")).expect("valid scenario")
}

/// A record of the truth's events as a scope would show them: shifted
/// by the trigger `offset`, with a deterministic ±`jitter` on each edge,
/// and optionally one spurious glitch (a 3 µs opening) inside the last
/// closed interval.
fn record(truth: &Scenario, offset: f64, jitter: f64, glitch: bool) -> (Record, usize) {
    let events = model_events(truth, None).expect("truth simulates");
    let mut times: Vec<(ContactState, f64)> = events
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let sign = if i % 3 == 0 { 1.0 } else { -0.7 };
            let state = match e.kind {
                chatterspice::calibrate::fit::EventKind::Make => ContactState::Closed,
                chatterspice::calibrate::fit::EventKind::Break => ContactState::Open,
            };
            (state, e.time - offset + sign * jitter)
        })
        .collect();
    let last = times.last().unwrap().1;
    if glitch {
        times.push((ContactState::Open, last + 4e-4));
        times.push((ContactState::Closed, last + 4.03e-4));
    }
    let end = last + 2e-3;
    let mut intervals = vec![Interval {
        state: ContactState::Open,
        start: -offset,
        end: times[0].1,
    }];
    for (i, &(state, start)) in times.iter().enumerate() {
        let end = times.get(i + 1).map_or(end, |t| t.1);
        intervals.push(Interval { state, start, end });
    }
    (
        Record {
            name: "synthetic.csv".into(),
            intervals,
        },
        events.len(),
    )
}

fn off(text: &str, changes: &[(&str, &str)]) -> String {
    let mut t = text.to_owned();
    for (old, new) in changes {
        assert!(t.contains(old), "{old}");
        t = t.replacen(old, new, 1);
    }
    t
}

fn value(report: &chatterspice::calibrate::fit::FitReport, key: &str) -> (f64, f64, bool) {
    let p = report
        .parameters
        .iter()
        .find(|p| p.key == key)
        .unwrap_or_else(|| panic!("no {key}"));
    (p.prior, p.value, p.determined.is_determined())
}

fn assert_recovered(
    report: &chatterspice::calibrate::fit::FitReport,
    key: &str,
    truth: f64,
    tol: f64,
) {
    let (prior, v, determined) = value(report, key);
    let prior_off = (prior / truth).max(truth / prior);
    assert!(
        prior_off >= 1.5,
        "{key}: the prior {prior} is only {prior_off}× off {truth}"
    );
    assert!(
        ((v - truth) / truth).abs() <= tol,
        "{key}: fitted {v}, truth {truth} (prior {prior}); notes {:?}",
        report.notes
    );
    assert!(
        determined,
        "{key} should be determined: {:?}",
        report.parameters
    );
}

#[test]
fn a_step_force_capture_recovers_stiffness_force_and_surface_from_a_2x_prior() {
    let truth = scenario(STEP);
    let (record, n) = record(&truth, 5.14e-4, 0.3e-6, true);
    assert!(n >= 6, "the truth should bounce: {n} events");
    let prior = scenario(&off(
        STEP,
        &[
            ("stiffness = 800.0", "stiffness = 1600.0"),
            ("force = 0.5", "force = 0.3"),
            ("stiffness = 8.0e4", "stiffness = 4.0e4"),
            ("damping = 0.5", "damping = 1.0"),
        ],
    ));
    let request = FitRequest {
        record: Some(record),
        free: vec![
            "mechanics.stiffness".into(),
            "mechanics.force".into(),
            "surface.stiffness".into(),
            "surface.damping".into(),
        ],
    };
    let report = fit(&prior, &request).expect("fit runs");
    assert_recovered(&report, "mechanics.stiffness", 800.0, 0.05);
    assert_recovered(&report, "mechanics.force", 0.5, 0.05);
    assert_recovered(&report, "surface.stiffness", 8.0e4, 0.05);
    assert_recovered(&report, "surface.damping", 0.5, 0.10);
    let offset = report.time_offset.expect("an offset");
    assert!((offset - 5.14e-4).abs() < 2e-6, "offset {offset}");
    // Every kept event within 10 µs, and the glitch set aside.
    let dropped = report.events.iter().filter(|e| e.dropped).count();
    assert_eq!(dropped, 2, "{:?}", report.events);
    for e in report.events.iter().filter(|e| !e.dropped) {
        let r = e.residual.expect("matched");
        assert!(r.abs() < 10e-6, "{e:?}");
    }
    assert_eq!(
        report.bounce_count.unwrap().model,
        report.bounce_count.unwrap().measured
    );
}

#[test]
fn force_and_gap_together_are_not_determined_and_one_is_held() {
    let truth = scenario(STEP);
    let (record, _) = record(&truth, 2e-4, 0.0, false);
    let prior = scenario(&off(
        STEP,
        &[
            ("force = 0.5", "force = 1.0"),
            ("gap = 5.0e-4", "gap = 6.0e-4"),
        ],
    ));
    let request = FitRequest {
        record: Some(record),
        free: vec!["mechanics.force".into(), "mechanics.gap".into()],
    };
    let report = fit(&prior, &request).expect("fit runs");
    let (_, gap, gap_determined) = value(&report, "mechanics.gap");
    let (_, force, _) = value(&report, "mechanics.force");
    assert!(!gap_determined, "{:?}", report.parameters);
    assert_eq!(gap, 6.0e-4, "the held key stays at its prior");
    // What the capture does fix: the ratio force/gap.
    let ratio = force / gap;
    let truth_ratio = 0.5 / 5.0e-4;
    assert!(
        ((ratio - truth_ratio) / truth_ratio).abs() < 0.01,
        "{ratio} vs {truth_ratio}"
    );
    assert!(
        report.notes.iter().any(|n| n.contains("mechanics.gap")),
        "{:?}",
        report.notes
    );
}

const REFERENCE: &str = r#"
[mechanics]
mass = 2.0e-4
stiffness = 800.0
damping = 0.04
preload = 0.1
gap = 4.5e-4

[coil]
resistance = 70.0
turns = 3000
pole_area = 2.0e-5
air_gap = 6.0e-4
iron_gap = 5.0e-5

[surface]
law = "kelvin-voigt"
stiffness = 8.0e4
damping = 0.37536

[simulation]
t_end = 0.008

[datasheet]
coil_voltage = 5.0
pick_up_voltage = 1.54603
drop_out_voltage = 0.89285
operate_time = 3.8137e-3
bounce_time = 2.0589e-3

[fit]
free = ["mechanics.preload", "mechanics.stiffness"]
"#;

#[test]
fn a_datasheet_fit_of_the_reference_relay_recovers_preload_and_spring() {
    let prior = scenario(&off(
        REFERENCE,
        &[
            ("preload = 0.1", "preload = 0.2"),
            ("stiffness = 800.0", "stiffness = 400.0"),
        ],
    ));
    let report = fit(&prior, &FitRequest::default()).expect("fit runs");
    assert_recovered(&report, "mechanics.preload", 0.1, 0.01);
    assert_recovered(&report, "mechanics.stiffness", 800.0, 0.01);
    for row in &report.datasheet {
        let model = row.model.expect("modelled");
        let tol = if row.figure.ends_with("time") {
            0.02
        } else {
            0.01
        };
        assert!(((model - row.target) / row.target).abs() < tol, "{row:?}");
    }
    assert_eq!(report.datasheet.iter().filter(|r| r.binds).count(), 1);
    // The pick-up is set part-way along the travel, where the spring has
    // outgrown the pull, and the report says so.
    let pick = report
        .datasheet
        .iter()
        .find(|r| r.figure == "pick_up_voltage")
        .unwrap();
    let x = pick.position.expect("a binding position");
    assert!((x - 0.4e-3 / 3.0).abs() < 2e-6, "{pick:?}");
    let binds = report.pick_up_binds.as_deref().expect("where it binds");
    assert!(binds.starts_with("part-way, at x = 0.13"), "{binds}");
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("the pick-up binds part-way")),
        "{:?}",
        report.notes
    );
}

#[test]
fn a_datasheet_fit_from_below_the_truth_recovers_preload_and_spring() {
    // The prior low in both keys (the rest rule would have put the preload
    // at 0.131 N, above the truth): the fit must climb to both.
    let prior = scenario(&off(
        REFERENCE,
        &[
            ("preload = 0.1", "preload = 0.06"),
            ("stiffness = 800.0", "stiffness = 520.0"),
        ],
    ));
    let report = fit(&prior, &FitRequest::default()).expect("fit runs");
    assert_recovered(&report, "mechanics.preload", 0.1, 0.01);
    assert_recovered(&report, "mechanics.stiffness", 800.0, 0.01);
}

#[test]
fn the_fitted_scenario_reads_back_with_its_provenance() {
    let prior_text = off(REFERENCE, &[("preload = 0.1", "preload = 0.15")]);
    let prior = scenario(&prior_text);
    let report = fit(
        &prior,
        &FitRequest {
            record: None,
            free: vec!["mechanics.preload".into()],
        },
    )
    .expect("fit runs");
    let text = chatterspice::calibrate::fit::fitted_toml(&prior_text, &report, None).expect("toml");
    let back = Scenario::parse(&text, Path::new("fitted.toml")).expect("reads back");
    let p = back.provenance.expect("provenance");
    assert_eq!(p.fitted_to, "datasheet");
    let fitted = &p.parameters["mechanics.preload"];
    assert_eq!(fitted.value, back.mechanics.preload);
    assert!((fitted.value - 0.1).abs() < 1e-3, "{fitted:?}");
    let binds = p.pick_up_binds.as_deref().expect("where the pick-up binds");
    assert!(binds.contains("part-way"), "{binds}");
    let _ = events_of(&[]);
}

#[test]
fn the_fit_command_writes_json_a_scenario_and_a_report_and_never_overwrites() {
    use assert_cmd::Command;
    let dir = tempfile::tempdir().unwrap();
    let truth = scenario(STEP);
    let (record, _) = record(&truth, -1e-4, 0.0, false);
    let mut csv = String::from("time,state\n0,open\n");
    for i in record.intervals.iter().skip(1) {
        csv.push_str(&format!("{:.12e},{}\n", i.start, i.state.as_str()));
    }
    let last = record.intervals.last().unwrap();
    csv.push_str(&format!("{:.12e},{}\n", last.end, last.state.as_str()));
    let measured = dir.path().join("chatter.csv");
    std::fs::write(&measured, csv).unwrap();
    let prior = dir.path().join("prior.toml");
    let text = off(STEP, &[("damping = 0.5", "damping = 1.0")])
        + "\n[fit]\nfree = [\"surface.damping\"]\n";
    std::fs::write(&prior, text).unwrap();
    let fitted = dir.path().join("fitted.toml");
    let report = dir.path().join("report");
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("fit")
        .arg(&prior)
        .arg("--measured")
        .arg(&measured)
        .arg("-o")
        .arg(&fitted)
        .arg("--report")
        .arg(&report)
        .args(["--format", "json"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for field in [
        "parameters",
        "events",
        "bounce_count",
        "datasheet",
        "time_offset",
        "rms_residual",
        "evaluations",
        "elapsed",
    ] {
        assert!(json.get(field).is_some(), "no {field}: {json}");
    }
    let damping = json["parameters"][0]["value"].as_f64().unwrap();
    assert!((damping - 0.5).abs() < 0.005, "{damping}");
    assert!((json["time_offset"].as_f64().unwrap() + 1e-4).abs() < 1e-6);
    let back = Scenario::load(&fitted).expect("the fitted scenario loads");
    assert_eq!(back.surface.damping, Some(damping));
    assert!(report.join("overlay.svg").exists() && report.join("fit.json").exists());
    // The overlay's time axis reads in engineering units, not `0.0000e0 s`.
    let overlay = std::fs::read_to_string(report.join("overlay.svg")).unwrap();
    assert!(
        !overlay.contains("e0 s") && !overlay.contains("e-3 s"),
        "{overlay}"
    );
    assert!(
        overlay.contains(">0 s</text>")
            || overlay.contains(" µs</text>")
            || overlay.contains(" ms</text>"),
        "{overlay}"
    );
    // A second run refuses to overwrite without --force.
    Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("fit")
        .arg(&prior)
        .arg("--measured")
        .arg(&measured)
        .arg("-o")
        .arg(&fitted)
        .assert()
        .code(2);
    // Never over an input, even with --force: the prior itself, the
    // record, or a link to the record.
    let link = dir.path().join("link.toml");
    std::os::unix::fs::symlink(&measured, &link).unwrap();
    let before = (
        std::fs::read(&prior).unwrap(),
        std::fs::read(&measured).unwrap(),
    );
    for target in [&prior, &measured, &link] {
        Command::cargo_bin("chatterspice")
            .unwrap()
            .arg("fit")
            .arg(&prior)
            .arg("--measured")
            .arg(&measured)
            .arg("-o")
            .arg(target)
            .arg("--force")
            .assert()
            .code(2)
            .stderr(predicates::str::contains("input of the run"));
    }
    assert_eq!(
        (
            std::fs::read(&prior).unwrap(),
            std::fs::read(&measured).unwrap()
        ),
        before
    );
    // No free keys: exit 2 with a message naming what to add.
    Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("fit")
        .arg(dir.path().join("fitted.toml"))
        .arg("--measured")
        .arg(&measured)
        .arg("--free")
        .arg("surface.bogus")
        .assert()
        .code(2)
        .stderr(predicates::str::contains("surface.bogus"));
}

#[test]
fn a_record_that_missed_one_bounce_still_fits() {
    let truth = scenario(STEP);
    let (mut record, n) = record(&truth, 4e-4, 0.2e-6, false);
    assert!(n >= 8);
    // Merge the third bounce's opening into the closed time around it: the
    // scope missed that break and make.
    let k = 4; // intervals: open, closed, open, closed, open(k), closed(k+1)
    assert_eq!(record.intervals[k].state, ContactState::Open);
    let merged_end = record.intervals[k + 1].end;
    record.intervals[k - 1].end = merged_end;
    record.intervals.drain(k..=k + 1);
    let prior = scenario(&off(
        STEP,
        &[
            ("stiffness = 800.0", "stiffness = 1300.0"),
            ("damping = 0.5", "damping = 0.8"),
        ],
    ));
    let report = fit(
        &prior,
        &FitRequest {
            record: Some(record),
            free: vec!["mechanics.stiffness".into(), "surface.damping".into()],
        },
    )
    .expect("fit runs");
    assert_recovered(&report, "mechanics.stiffness", 800.0, 0.05);
    assert_recovered(&report, "surface.damping", 0.5, 0.10);
    assert!(
        report
            .notes
            .iter()
            .any(|n| n.contains("bounce the record lacks")),
        "{:?}",
        report.notes
    );
}

/// The reference relay with a contact blade stiff enough that its step in
/// the load line, not the return spring, sets the pick-up.
const BLADED: &str = r#"
[mechanics]
mass = 2.0e-4
stiffness = 800.0
damping = 0.04
preload = 0.1
gap = 4.5e-4

[blade]
mass = 3.0e-5
stiffness = 60000.0
damping = 0.01

[pole_face]
overtravel = 1.0e-4
law = "kelvin-voigt"
stiffness = 1.0e6
damping = 5.0

[coil]
resistance = 70.0
turns = 3000
pole_area = 2.0e-5
air_gap = 6.0e-4
iron_gap = 5.0e-5

[surface]
law = "kelvin-voigt"
stiffness = 8.0e4
damping = 0.37536

[simulation]
t_end = 0.008

[fit]
free = ["mechanics.preload", "mechanics.stiffness"]
"#;

/// V, the pick-up of `BLADED`'s magnet on the return spring alone (the
/// travel to the make), on a grid of the travel.
fn spring_only_pick_up(p: f64, s: f64) -> f64 {
    let k = 1.256_637_062_12e-6 * 3000.0 * 3000.0 * 2.0e-5;
    let volts = |x: f64| 70.0 * (2.0 * (p + s * x) * (6.5e-4 - x).powi(2) / k).sqrt();
    (0..=1000)
        .map(|i| volts(4.5e-4 * i as f64 / 1000.0))
        .fold(0.0, f64::max)
}

/// V, the pick-up and drop-out of `BLADED` with preload `p` and spring
/// `s`, by brute force: the largest holding voltage over a fine grid of
/// the travel (to the pole face), and the one at the pole face.
fn bladed_voltages(p: f64, s: f64) -> (f64, f64, f64) {
    let mu0 = 1.256_637_062_12e-6;
    let k = mu0 * 3000.0 * 3000.0 * 2.0e-5;
    let (a, g, o, sb, r) = (6.5e-4, 4.5e-4, 1.0e-4, 60000.0, 70.0);
    let load = |x: f64| p + s * x + if x > g { sb * (x - g) } else { 0.0 };
    let volts = |x: f64| r * (2.0 * load(x) * (a - x) * (a - x) / k).sqrt();
    let n = 200_000;
    let (mut best, mut at) = (0.0, 0.0);
    for i in 0..=n {
        let x = (g + o) * i as f64 / n as f64;
        if volts(x) > best {
            (best, at) = (volts(x), x);
        }
    }
    (best, volts(g + o), at)
}

#[test]
fn a_datasheet_fit_recovers_the_preload_where_the_blade_binds_the_load_line() {
    let (pick_up, drop_out, at) = bladed_voltages(0.1, 800.0);
    // The blade's step binds: the largest holding voltage lies past the make.
    assert!(at > 4.5e-4, "binding at {at:e} m");
    let truth = format!(
        "{BLADED}\n[datasheet]\ncoil_voltage = 5.0\npick_up_voltage = {pick_up:e}\n\
         drop_out_voltage = {drop_out:e}\n"
    );
    let prior = scenario(&off(
        &truth,
        &[
            ("preload = 0.1", "preload = 0.16"),
            ("stiffness = 800.0", "stiffness = 500.0"),
        ],
    ));
    let report = fit(&prior, &FitRequest::default()).expect("fit runs");
    assert_recovered(&report, "mechanics.preload", 0.1, 0.01);
    assert_recovered(&report, "mechanics.stiffness", 800.0, 0.01);
    // The rule that ignores the blade would need another preload: the
    // spring-only pick-up of the truth differs.
    let spring_only = spring_only_pick_up(0.1, 800.0);
    assert!(
        (pick_up - spring_only) / pick_up > 0.01,
        "{pick_up} vs {spring_only}"
    );
}
