//! `chatterspice capture`: scope captures generated from a known chatter
//! (the default relay's), in every instrument layout, with noise, ringing
//! at makes, RC recovery after breaks, 8-bit quantisation, a trigger
//! offset and pre-trigger samples. Every edge must come back within
//! max(2 samples, 0.5 µs) and the bounce count exactly.

use std::fmt::Write as _;
use std::path::Path;

use assert_cmd::Command;
use chatterspice::chatter::{ContactState, Interval};
use chatterspice::scenario::Scenario;
use predicates::prelude::*;
use serde_json::Value;

const OPEN: f64 = 5.0; // V, pulled up
const CLOSED: f64 = 0.02; // V
const DT: f64 = 0.2e-6; // s
const OFFSET: f64 = -1.2345e-4; // s, where the scope's t = 0 falls

/// The default relay's intervals, in scope time.
fn truth() -> Vec<Interval> {
    let s = Scenario::builtin_default();
    let c = chatterspice::simulate(&s.mechanics().unwrap(), &s.surface(), &s.settings()).unwrap();
    c.intervals
        .iter()
        .map(|i| Interval {
            state: i.state,
            start: i.start + OFFSET,
            end: i.end.min(2e-3) + OFFSET,
        })
        .filter(|i| i.end > i.start)
        .collect()
}

/// A cheap deterministic noise in [-1, 1].
fn noise(k: usize) -> f64 {
    let x = (k as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 11;
    2.0 * (x as f64 / (1u64 << 53) as f64) - 1.0
}

/// The scope trace of `intervals`: a make falls in ~0.1 µs and rings (a
/// damped 2 MHz sine of 0.9 V, never back past 30 %); a break jumps to
/// 80 % and recovers to the open level with τ = 20 µs; ±40 mV of noise;
/// 8 bits over −1…7 V. `closed_high` flips the polarity.
fn trace(intervals: &[Interval], closed_high: bool) -> (Vec<f64>, Vec<f64>) {
    trace_from(intervals, closed_high, intervals[0].start - 2e-4) // pre-trigger
}

/// [`trace`] from the first sample at `t0`, on the scope's axis.
fn trace_from(intervals: &[Interval], closed_high: bool, t0: f64) -> (Vec<f64>, Vec<f64>) {
    let t1 = intervals.last().unwrap().end;
    let n = ((t1 - t0) / DT) as usize;
    let (mut time, mut value) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for k in 0..n {
        let t = t0 + k as f64 * DT;
        let i = intervals.iter().rposition(|i| i.start <= t).unwrap_or(0);
        let since = t - intervals[i].start.max(t0);
        let first = intervals[i].start <= t0 + 1e-12;
        let v = match intervals[i].state {
            ContactState::Closed if first => CLOSED,
            ContactState::Closed => {
                let fall = (-since / 0.1e-6).exp();
                let ring =
                    0.9 * (-since / 1e-6).exp() * (2.0 * std::f64::consts::PI * 2e6 * since).sin();
                CLOSED + (OPEN - CLOSED) * fall * 0.999 + ring.abs() * (1.0 - fall)
            }
            ContactState::Open if first || i == 0 => OPEN,
            ContactState::Open => {
                if since < 0.0 {
                    CLOSED
                } else {
                    OPEN - 0.2 * (OPEN - CLOSED) * (-since / 20e-6).exp()
                }
            }
        };
        let v = v + 0.04 * noise(k);
        let v = if closed_high { OPEN + CLOSED - v } else { v };
        let lsb = 8.0 / 256.0;
        let q = ((v + 1.0) / lsb).round() * lsb - 1.0;
        time.push(t);
        value.push(q);
    }
    (time, value)
}

fn plain(t: &[f64], v: &[f64]) -> String {
    let mut s = String::from("time,value\n");
    for (t, v) in t.iter().zip(v) {
        let _ = writeln!(s, "{t:e},{v}");
    }
    s
}

fn plain_ms_crlf(t: &[f64], v: &[f64]) -> String {
    let mut s = String::from("\u{feff}Time (ms),CH1 (V)\r\n");
    for (t, v) in t.iter().zip(v) {
        let _ = write!(s, "{:.6},{v}\r\n", t * 1e3);
    }
    s
}

fn tds(t: &[f64], v: &[f64]) -> String {
    let settings = [
        ("Record Length", format!("{:e}", t.len() as f64)),
        ("Sample Interval", format!("{DT:e}")),
        ("Trigger Point", "1000".to_owned()),
        ("", String::new()),
        ("", String::new()),
        ("", String::new()),
        ("Source", "CH1".to_owned()),
        ("Vertical Units", "V".to_owned()),
        ("Vertical Scale", "1.0".to_owned()),
        ("Vertical Offset", "0.0".to_owned()),
        ("Horizontal Units", "s".to_owned()),
        ("Horizontal Scale", "1e-4".to_owned()),
        ("Pt Fmt", "Y".to_owned()),
        ("Yzero", "0".to_owned()),
        ("Probe Atten", "10".to_owned()),
    ];
    let mut s = String::new();
    for (k, (t, v)) in t.iter().zip(v).enumerate() {
        let (a, b) = settings.get(k).cloned().unwrap_or_default();
        let _ = writeln!(s, "{a},{b},,{t:.9e},{v:.5}");
    }
    s
}

fn mso(t: &[f64], v: &[f64]) -> String {
    let mut s = String::from(
        "Model,MSO54\nFirmware Version,1.30.4\n\nWaveform Type,ANALOG\nPoint Format,Y\n\
         Horizontal Units,s\nHorizontal Scale,0.0002\nHorizontal Delay,0\n",
    );
    let _ = writeln!(s, "Sample Interval,{DT:e}\nRecord Length,{}", t.len());
    s.push_str("Gating,0.0% to 100.0%\nProbe Attenuation,10\nVertical Units,V\nLabel,\nTIME,CH1\n");
    for (t, v) in t.iter().zip(v) {
        let _ = writeln!(s, "{t:e},{v}");
    }
    s
}

fn keysight(t: &[f64], v: &[f64], second: Option<&[f64]>) -> String {
    let mut s = String::from(if second.is_some() {
        "x-axis,1,2\nsecond,Volt,Volt\n"
    } else {
        "x-axis,1\nsecond,Volt\n"
    });
    for (k, (t, v)) in t.iter().zip(v).enumerate() {
        match second {
            Some(w) => writeln!(s, "{t:e},{:e},{v:e}", w[k]),
            None => writeln!(s, "{t:e},{v:e}"),
        }
        .unwrap();
    }
    s
}

fn rigol(t: &[f64], v: &[f64]) -> String {
    let mut s = format!("X,CH1,Start,Increment,\nSequence,Volt,{:e},{DT:e}\n", t[0]);
    for (k, v) in v.iter().enumerate() {
        let _ = writeln!(s, "{k},{v:e},");
    }
    s
}

fn siglent(t: &[f64], v: &[f64]) -> String {
    let mut s = format!(
        "Record Length,Analog:{}\nSample Interval,{DT:e}\nVertical Units,V\nHorizontal Units,s\n\
         Second,Value\n",
        t.len()
    );
    for (t, v) in t.iter().zip(v) {
        let _ = writeln!(s, "{t:E},{v:E}");
    }
    s
}

fn picoscope(t: &[f64], v: &[f64], second: Option<&[f64]>) -> String {
    let mut s = String::from(if second.is_some() {
        "Time,Channel A,Channel B\n(us),(V),(V)\n\n"
    } else {
        "Time,Channel A\n(us),(V)\n\n"
    });
    for (k, (t, v)) in t.iter().zip(v).enumerate() {
        match second {
            Some(w) => writeln!(s, "{:.5},{:.6},{v:.6}", t * 1e6, w[k]),
            None => writeln!(s, "{:.5},{v:.6}", t * 1e6),
        }
        .unwrap();
    }
    s
}

fn capture_json(path: &Path, args: &[&str]) -> Value {
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("capture")
        .arg(path)
        .args(["--format", "json"])
        .args(args)
        .assert()
        .success();
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

/// Every edge of the capture matches the truth's, and the count too.
fn assert_matches(v: &Value, truth: &[Interval], what: &str) {
    let tol = (2.0 * DT).max(0.5e-6);
    let want_makes: Vec<f64> = truth
        .iter()
        .skip(1)
        .filter(|i| i.state == ContactState::Closed)
        .map(|i| i.start)
        .collect();
    let want_breaks: Vec<f64> = truth
        .iter()
        .skip(1)
        .filter(|i| i.state == ContactState::Open)
        .map(|i| i.start)
        .collect();
    let got = |k: &str| -> Vec<f64> {
        v[k].as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect()
    };
    let (makes, breaks) = (got("makes"), got("breaks"));
    assert_eq!(
        makes.len(),
        want_makes.len(),
        "{what}: makes {makes:?} vs {want_makes:?}"
    );
    assert_eq!(
        breaks.len(),
        want_breaks.len(),
        "{what}: breaks {breaks:?} vs {want_breaks:?}"
    );
    for (g, w) in makes
        .iter()
        .zip(&want_makes)
        .chain(breaks.iter().zip(&want_breaks))
    {
        assert!((g - w).abs() <= tol, "{what}: edge at {g} vs {w}");
    }
    assert_eq!(v["bounce_count"], want_breaks.len(), "{what}");
    let first = v["first_make"].as_f64().unwrap();
    assert!((first - want_makes[0]).abs() <= tol, "{what}");
}

/// Exports from locales with a decimal comma (semicolon-separated), tab
/// separated files, and headers with units in parentheses or µs/mV.
#[test]
fn separators_decimal_commas_and_header_units() {
    let truth = truth();
    let (t, v) = trace(&truth, false);
    let dir = tempfile::tempdir().unwrap();
    let rows = |f: &dyn Fn(f64, f64) -> String| {
        t.iter().zip(&v).map(|(&t, &v)| f(t, v)).collect::<String>()
    };
    let files = [
        (
            "pico_eu.csv",
            format!(
                "Time;Channel A\n(us);(V)\n\n{}",
                rows(&|t, v| format!("{:.5};{v:.6}\n", t * 1e6).replace('.', ","))
            ),
        ),
        (
            "tabs.txt",
            format!("time\tvalue\n{}", rows(&|t, v| format!("{t:e}\t{v:.6}\n"))),
        ),
        (
            "units.csv",
            format!(
                "Time(s),CH1(V)\n{}",
                rows(&|t, v| format!("{t:e},{v:.6}\n"))
            ),
        ),
        (
            "micro.csv",
            format!(
                "t (us), v (mV)\n{}",
                rows(&|t, v| format!("{:.5}, {:.3}\n", t * 1e6, v * 1e3))
            ),
        ),
    ];
    for (name, text) in files {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        assert_matches(&capture_json(&path, &[]), &truth, name);
    }
}

#[test]
fn every_layout_gives_every_edge_and_the_bounce_count() {
    let truth = truth();
    let (t, v) = trace(&truth, false);
    let dir = tempfile::tempdir().unwrap();
    let layouts: Vec<(&str, String, &str)> = vec![
        ("plain.csv", plain(&t, &v), "plain"),
        ("plain_ms.csv", plain_ms_crlf(&t, &v), "plain"),
        ("tds.csv", tds(&t, &v), "tektronix-tds"),
        ("mso.csv", mso(&t, &v), "tektronix-mso"),
        ("keysight.csv", keysight(&t, &v, None), "keysight"),
        ("rigol.csv", rigol(&t, &v), "rigol"),
        ("siglent.csv", siglent(&t, &v), "siglent"),
        ("picoscope.csv", picoscope(&t, &v, None), "picoscope"),
    ];
    for (name, text, layout) in layouts {
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        let json = capture_json(&path, &[]);
        assert_eq!(json["layout"], layout, "{name}");
        assert_matches(&json, &truth, name);
        let open = json["levels"]["open"].as_f64().unwrap();
        assert!((open - OPEN).abs() < 0.1, "{name}: open level {open}");
        assert!(json["intervals"][0]["start"].as_f64().unwrap() < 0.0);
    }
}

#[test]
fn a_misread_layout_would_be_caught() {
    // Rigol's first column is a sample number: read as seconds, the edges
    // would land 1/DT times too late; the reader must use start + n·inc.
    let truth = truth();
    let (t, v) = trace(&truth, false);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rigol.csv");
    std::fs::write(&path, rigol(&t, &v)).unwrap();
    let json = capture_json(&path, &[]);
    let first = json["first_make"].as_f64().unwrap();
    assert!(first.abs() < 1e-2, "{first}");
}

#[test]
fn polarity_channels_and_thresholds() {
    let truth = truth();
    let (t, v) = trace(&truth, false);
    let (_, inverted) = trace(&truth, true);
    let dir = tempfile::tempdir().unwrap();
    // Closed high: found from where the trace ends.
    let path = dir.path().join("inverted.csv");
    std::fs::write(&path, plain(&t, &inverted)).unwrap();
    let json = capture_json(&path, &[]);
    assert_matches(&json, &truth, "inverted");
    assert!(json["levels"]["closed"].as_f64().unwrap() > 4.0);
    // Two channels: the contact on the second.
    let flat: Vec<f64> = (0..t.len()).map(|k| 3.3 + 0.01 * noise(k + 7)).collect();
    let mut flat2 = flat.clone();
    flat2[0] = 0.0; // not flat enough to fail, but not the contact
    let path = dir.path().join("two.csv");
    std::fs::write(&path, keysight(&t, &v, Some(&flat2))).unwrap();
    for channel in ["2", "CH2"] {
        let json = capture_json(&path, &["--channel", channel]);
        assert_eq!(json["channel"], "2");
        assert_matches(&json, &truth, channel);
    }
    let path = dir.path().join("pico2.csv");
    std::fs::write(&path, picoscope(&t, &v, Some(&flat2))).unwrap();
    let json = capture_json(&path, &["--channel", "B"]);
    assert_eq!(json["channel"], "Channel B");
    assert_matches(&json, &truth, "picoscope B");
    // Explicit thresholds are used as given.
    let path = dir.path().join("plain.csv");
    std::fs::write(&path, plain(&t, &v)).unwrap();
    let json = capture_json(&path, &["--low", "1.0", "--high", "4.0"]);
    assert_eq!(json["thresholds"]["low"], 1.0);
    assert_matches(&json, &truth, "thresholds");
    // --closed high on a closed-low trace swaps the states.
    let json = capture_json(&path, &["--closed", "high"]);
    assert!(json["levels"]["closed"].as_f64().unwrap() > 4.0);
}

#[test]
fn the_csv_reads_back_as_a_measured_record() {
    let truth = truth();
    let (t, v) = trace(&truth, false);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scope.csv");
    std::fs::write(&path, plain(&t, &v)).unwrap();
    let states = dir.path().join("states.csv");
    Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("capture")
        .arg(&path)
        .args(["--format", "csv", "-o"])
        .arg(&states)
        .assert()
        .success();
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["bounce", "--format", "json", "--measured"])
        .arg(&states)
        .assert()
        .success();
    let v: Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    let breaks = truth
        .iter()
        .skip(1)
        .filter(|i| i.state == ContactState::Open)
        .count();
    assert_eq!(v["bounce_count"], breaks);
    // The CSV starts at the first sample: the first make moves by it.
    let first = v["first_impact"].as_f64().unwrap();
    let want = truth
        .iter()
        .find(|i| i.state == ContactState::Closed)
        .unwrap()
        .start
        - t[0];
    assert!((first - want).abs() <= 0.5e-6, "{first} vs {want}");
}

#[test]
fn unreadable_captures_name_the_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "time,value\n0,1\n1e-6,1\n2e-6,oops\n3e-6,0\n").unwrap();
    Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("capture")
        .arg(&bad)
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("bad.csv:4: column 2").and(predicate::str::contains("oops")),
        );
    std::fs::write(&bad, "time,value\n0,1\n1e-6,1\n1e-6,0\n").unwrap();
    Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("capture")
        .arg(&bad)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("times must increase"));
    std::fs::write(&bad, "x-axis,1\nsecond,Volt\n0,1\n1e-6,1\n2e-6,1\n").unwrap();
    Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("capture")
        .arg(&bad)
        .args(["--channel", "3"])
        .assert()
        .code(2)
        .stderr(predicate::str::contains("no channel `3`"));
    Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("capture")
        .arg(&bad)
        .assert()
        .code(2)
        .stderr(predicate::str::contains("flat"));
}

/// `fit --capture`: a Rigol capture of a known relay, a prior off by up to
/// 2× in every free key; the fit must reproduce every captured event
/// within 10 µs and come back to the truth (not stay at its prior).
#[test]
fn fit_capture_recovers_a_known_relay() {
    let truth_text = "[mechanics]\nmass = 2.0e-4\nstiffness = 800.0\ndamping = 0.02\nforce = 0.5\n\
                      gap = 5.0e-4\n\n[surface]\nlaw = \"kelvin-voigt\"\nstiffness = 8.0e4\n\
                      damping = 0.5\n\n[simulation]\nt_end = 0.02\n";
    let truth = Scenario::parse(truth_text, Path::new("truth.toml")).unwrap();
    let c = chatterspice::simulate(
        &truth.mechanics().unwrap(),
        &truth.surface(),
        &truth.settings(),
    )
    .unwrap();
    let settle = c.settle_time.unwrap();
    let intervals: Vec<Interval> = c
        .intervals
        .iter()
        .map(|i| Interval {
            state: i.state,
            start: i.start + OFFSET,
            end: i.end.min(settle + 1e-3) + OFFSET,
        })
        .filter(|i| i.end > i.start)
        .collect();
    let (t, v) = trace(&intervals, false);
    let dir = tempfile::tempdir().unwrap();
    let scope = dir.path().join("scope.csv");
    std::fs::write(&scope, rigol(&t, &v)).unwrap();
    let prior = dir.path().join("prior.toml");
    std::fs::write(
        &prior,
        truth_text
            .replacen("stiffness = 800.0", "stiffness = 1600.0", 1)
            .replacen("force = 0.5", "force = 0.3", 1)
            .replacen("stiffness = 8.0e4", "stiffness = 4.0e4", 1)
            .replacen("damping = 0.5", "damping = 1.0", 1),
    )
    .unwrap();
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .arg("fit")
        .arg(&prior)
        .arg("--capture")
        .arg(&scope)
        .args([
            "--free",
            "mechanics.stiffness,mechanics.force,surface.stiffness,surface.damping",
            "--format",
            "json",
            "--report",
        ])
        .arg(dir.path().join("report"))
        .assert()
        .success();
    let report: Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    // The overlay draws the scope trace (grey) under the measured states.
    let svg = std::fs::read_to_string(dir.path().join("report/overlay.svg")).unwrap();
    assert!(
        svg.contains(r##"stroke="#999""##),
        "no trace in the overlay"
    );
    for e in report["events"].as_array().unwrap() {
        if e["dropped"] == true {
            continue;
        }
        let r = e["residual"].as_f64().unwrap();
        assert!(r.abs() < 10e-6, "{e}");
    }
    for (key, want, tol) in [
        ("mechanics.stiffness", 800.0, 0.05),
        ("mechanics.force", 0.5, 0.05),
        ("surface.stiffness", 8.0e4, 0.05),
        ("surface.damping", 0.5, 0.10),
    ] {
        let p = report["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["key"] == key)
            .unwrap();
        let got = p["value"].as_f64().unwrap();
        assert!((got / want - 1.0).abs() < tol, "{key}: {got} vs {want}");
    }
}

/// `fit --capture` gives its time offset from the scope's trigger (t = 0
/// of the file's time axis), not from the capture's first sample: the
/// same chatter recorded from 1 ms or from 50 µs before the trigger gives
/// the same offset, the model time of the trigger.
#[test]
fn fit_capture_offset_is_from_the_trigger_not_the_first_sample() {
    let truth_text = "[mechanics]\nmass = 2.0e-4\nstiffness = 800.0\ndamping = 0.02\nforce = 0.5\n\
                      gap = 5.0e-4\n\n[surface]\nlaw = \"kelvin-voigt\"\nstiffness = 8.0e4\n\
                      damping = 0.5\n\n[simulation]\nt_end = 0.02\n";
    let truth = Scenario::parse(truth_text, Path::new("truth.toml")).unwrap();
    let c = chatterspice::simulate(
        &truth.mechanics().unwrap(),
        &truth.surface(),
        &truth.settings(),
    )
    .unwrap();
    let settle = c.settle_time.unwrap();
    // Scope time = model time + OFFSET: the force came on -OFFSET before
    // the trigger.
    let intervals: Vec<Interval> = c
        .intervals
        .iter()
        .map(|i| Interval {
            state: i.state,
            start: i.start + OFFSET,
            end: i.end.min(settle + 1e-3) + OFFSET,
        })
        .filter(|i| i.end > i.start)
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let prior = dir.path().join("prior.toml");
    std::fs::write(&prior, truth_text).unwrap();
    let mut offsets = Vec::new();
    for (name, first_sample) in [("long.csv", -1.0e-3), ("short.csv", -0.05e-3)] {
        let (t, v) = trace_from(&intervals, false, first_sample);
        assert!((t[0] - first_sample).abs() < 1e-12);
        let scope = dir.path().join(name);
        std::fs::write(&scope, plain(&t, &v)).unwrap();
        let out = Command::cargo_bin("chatterspice")
            .unwrap()
            .arg("fit")
            .arg(&prior)
            .arg("--capture")
            .arg(&scope)
            .args(["--free", "surface.damping", "--format", "json"])
            .assert()
            .success();
        let report: Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
        let offset = report["time_offset"].as_f64().unwrap();
        assert!(
            (offset + OFFSET).abs() < 2e-6,
            "{name}: offset {offset}, the trigger is at model time {}",
            -OFFSET
        );
        // The events are reported on the scope's own axis.
        let first = report["events"][0]["measured"].as_f64().unwrap();
        let want = intervals[1].start;
        assert!((first - want).abs() < 1e-6, "{name}: {first} vs {want}");
        offsets.push(offset);
    }
    assert!(
        (offsets[0] - offsets[1]).abs() < 1e-6,
        "pre-trigger samples moved the offset: {offsets:?}"
    );
}

/// `capture --low/--high` on an RC-shaped trace (exponential edges, no
/// sharp step): each edge is where the trace crosses the far threshold,
/// in closed form τ·ln(ΔV₀/ΔV), so two pairs sharing a midpoint give
/// different edges.
#[test]
fn given_thresholds_move_the_edges_of_an_rc_trace() {
    let (open, closed, tau_fall, tau_rise): (f64, f64, f64, f64) = (3.3, 0.0, 8e-6, 30e-6);
    let (make, brk): (f64, f64) = (50e-6, 150e-6);
    let dt = 50e-9;
    let at_break = closed + (open - closed) * (-(brk - make) / tau_fall).exp();
    let v = |t: f64| {
        if t < make {
            open
        } else if t < brk {
            closed + (open - closed) * (-(t - make) / tau_fall).exp()
        } else {
            open - (open - at_break) * (-(t - brk) / tau_rise).exp()
        }
    };
    let t: Vec<f64> = (0..8000).map(|k| -20e-6 + k as f64 * dt).collect();
    let values: Vec<f64> = t.iter().map(|&t| v(t)).collect();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rc.csv");
    std::fs::write(&path, plain(&t, &values)).unwrap();
    let mut seen = Vec::new();
    for (low, high) in [(0.8, 2.5), (1.2, 2.1)] {
        let json = capture_json(
            &path,
            &[
                "--low",
                &low.to_string(),
                "--high",
                &high.to_string(),
                "--closed",
                "low",
            ],
        );
        let makes = json["makes"].as_array().unwrap();
        let breaks = json["breaks"].as_array().unwrap();
        assert_eq!((makes.len(), breaks.len()), (1, 1), "{json}");
        let want_make = make + tau_fall * ((open - closed) / (low - closed)).ln();
        let want_break = brk + tau_rise * ((open - at_break) / (open - high)).ln();
        let (m, b) = (makes[0].as_f64().unwrap(), breaks[0].as_f64().unwrap());
        assert!(
            (m - want_make).abs() < 1e-8,
            "{low}: make {m} vs {want_make}"
        );
        assert!(
            (b - want_break).abs() < 1e-8,
            "{high}: break {b} vs {want_break}"
        );
        seen.push((m, b));
    }
    assert!(
        (seen[0].0 - seen[1].0).abs() > 1e-6 && (seen[0].1 - seen[1].1).abs() > 1e-6,
        "{seen:?}"
    );
}
