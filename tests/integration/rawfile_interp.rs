//! Raw files whose data disagree with their header's `No. Points:`, from
//! real ngspice: with `.options interp`, ngspice 39 writes more points than
//! it declares; a killed run, fewer. Every whole point is read, no vector
//! is misaligned, and a warning says what happened.

use crate::common;

use std::path::Path;

use assert_cmd::Command;
use chatterspice::rawfile::{RawFile, RawWarning};
use proptest::prelude::*;

/// An RC low-pass (1 kΩ, 1 nF) driven by a 1 V pulse, with
/// `.options interp`: run by real ngspice into `dir`, the raw file's bytes.
fn interp_raw(dir: &Path, ascii: bool) -> Vec<u8> {
    let deck = format!(
        "rc interp\nV1 a 0 PULSE(0 1 1u 1n 1n 10u 20u)\nR1 a b 1k\nC1 b 0 1n\n\
         .options interp{}\n.tran 0.1u 20u\n.end\n",
        if ascii { " filetype=ascii" } else { "" }
    );
    std::fs::write(dir.join("rc.cir"), deck).unwrap();
    let status = std::process::Command::new("ngspice")
        .current_dir(dir)
        .args(["-b", "-r", "rc.raw", "rc.cir"])
        .output()
        .unwrap();
    assert!(status.status.success(), "{status:?}");
    std::fs::read(dir.join("rc.raw")).unwrap()
}

/// The byte range of the declared point count, and the count.
fn declared_field(bytes: &[u8]) -> (std::ops::Range<usize>, usize) {
    let key = b"No. Points:";
    let at = bytes.windows(key.len()).position(|w| w == key).unwrap() + key.len();
    let end = at + bytes[at..].iter().position(|&b| b == b'\n').unwrap();
    let text = std::str::from_utf8(&bytes[at..end]).unwrap();
    (at..end, text.trim().parse().unwrap())
}

/// `bytes` with the declared point count rewritten to `n` (same width: the
/// field is padded, as ngspice pads it to patch it in place).
fn with_declared(bytes: &[u8], n: usize) -> Vec<u8> {
    let (range, _) = declared_field(bytes);
    let width = range.len();
    let mut out = bytes.to_vec();
    let text = format!(" {n:<w$}", w = width - 1);
    assert_eq!(text.len(), width);
    out[range].copy_from_slice(text.as_bytes());
    out
}

#[test]
fn interp_points_past_the_declared_count_are_read_and_aligned() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    let bytes = interp_raw(dir.path(), false);
    let (_, declared) = declared_field(&bytes);
    let data = bytes.windows(8).position(|w| w == b"Binary:\n").unwrap() + 8;
    let actual = (bytes.len() - data) / 32;
    assert!(
        actual > declared,
        "ngspice wrote {actual} points for {declared}"
    );
    let raw = RawFile::parse(&bytes).unwrap();
    assert_eq!(
        raw.warnings,
        [RawWarning::ExtraPoints {
            plot: 0,
            declared,
            read: actual
        }]
    );
    let plot = &raw.plots[0];
    assert_eq!(plot.points(), actual);
    let time = plot.real("time").unwrap();
    let (a, b) = (plot.real("v(a)").unwrap(), plot.real("v(b)").unwrap());
    let i = plot.real("i(v1)").unwrap();
    // Aligned: time never goes back, every value is in its range, and the
    // source current is −(v(a) − v(b))/R at every point. (ngspice 39's
    // interpolated time stamps run slow where its step exceeds the
    // `.tran` step, so the values cannot be held to a closed form in t.)
    assert!(time.windows(2).all(|w| w[1] >= w[0]));
    assert!((time[actual - 1] - 20e-6).abs() < 1e-12);
    for k in 0..actual {
        assert!((-1e-9..=1.0 + 1e-9).contains(&a[k]), "v(a) {}", a[k]);
        assert!((-1e-3..=1.0 + 1e-3).contains(&b[k]), "v(b) {}", b[k]);
        assert!(
            (i[k] + (a[k] - b[k]) / 1e3).abs() < 1e-9,
            "i(v1) at {}",
            time[k]
        );
    }
}

/// With UIC, ngspice 39 starts the interpolated data over several times,
/// re-declaring the variables and `Binary:` after an all-zero point; the
/// reader keeps the last start's points, all of them aligned.
#[test]
fn interp_restarts_keep_the_last_start_s_points() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    let deck = "rc uic interp\nV1 a 0 DC 3.3\nR1 a b 10k\nC1 b 0 8.2n IC=3.3\n.options interp\n\
                .tran 100n 5m 0 2u UIC\n.end\n";
    std::fs::write(dir.path().join("rc.cir"), deck).unwrap();
    let status = std::process::Command::new("ngspice")
        .current_dir(dir.path())
        .args(["-b", "-r", "rc.raw", "rc.cir"])
        .output()
        .unwrap();
    assert!(status.status.success());
    let bytes = std::fs::read(dir.path().join("rc.raw")).unwrap();
    let starts = bytes.windows(8).filter(|w| w == b"Binary:\n").count();
    assert!(starts > 1, "this ngspice does not restart: {starts}");
    let raw = RawFile::parse(&bytes).unwrap();
    assert!(
        raw.warnings.iter().any(
            |w| matches!(w, RawWarning::Restarted { restarts, .. } if *restarts == starts - 1)
        ),
        "{:?}",
        raw.warnings
    );
    let plot = &raw.plots[0];
    // v(a) is the 3.3 V source at every point kept: no zero point of an
    // abandoned start, no value shifted into another vector.
    assert!(
        plot.real("v(a)")
            .unwrap()
            .iter()
            .all(|&v| (v - 3.3).abs() < 1e-12)
    );
    let i = plot.real("i(v1)").unwrap();
    let b = plot.real("v(b)").unwrap();
    for (k, (&i, &b)) in i.iter().zip(b).enumerate() {
        assert!((i + (3.3 - b) / 1e4).abs() < 1e-12, "point {k}");
    }
    let time = plot.real("time").unwrap();
    assert!(time.windows(2).all(|w| w[1] >= w[0]));
}

#[test]
fn a_run_of_a_netlist_with_interp_succeeds_and_says_so() {
    let Some(_) = common::ngspice() else { return };
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let netlist = std::fs::read_to_string(root.join("netlists/mcu_input.cir")).unwrap();
    let netlist = netlist.replace(".tran", ".options interp\n.tran");
    std::fs::write(dir.path().join("mcu.cir"), netlist).unwrap();
    let scenario = chatterspice::scenario::DEFAULT_SCENARIO_TOML
        .replace("../netlists/mcu_input.cir", "mcu.cir");
    std::fs::write(dir.path().join("relay.toml"), scenario).unwrap();
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .current_dir(dir.path())
        .args(["run", "relay.toml", "--format", "json"])
        .assert()
        .success();
    let v: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    // The run leaves `interp` out, so the times are the true ones.
    assert_eq!(v["probes"][0]["edges"], 7);
    let first = v["probes"][0]["first_edge"].as_f64().unwrap();
    assert!((first - 1.933e-4).abs() < 1e-6, "{first}");
    let warnings = v["warnings"].to_string();
    assert!(warnings.contains("`interp` is left out"), "{warnings}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// Whatever the header declares, every whole point of real ngspice
    /// output is read with its values where they belong; a second plot
    /// after the first is found where its header starts.
    #[test]
    fn declared_counts_that_disagree_with_the_data(fraction in 0.0f64..1.3, second in any::<bool>()) {
        let Some(_) = common::ngspice() else { return Ok(()) };
        let dir = tempfile::tempdir().unwrap();
        let bytes = interp_raw(dir.path(), false);
        let reference = RawFile::parse(&bytes).unwrap();
        let actual = reference.plots[0].points();
        let declared = ((actual as f64 * fraction) as usize).max(1);
        if declared > actual && second {
            // The first plot's declared data would run into the second's
            // header: ngspice never writes that (only a killed run, the
            // last plot, declares more than it holds).
            return Ok(());
        }
        let mut file = with_declared(&bytes, declared);
        if second {
            // A whole second plot, as declared as ngspice declares it.
            file.extend_from_slice(&bytes);
        }
        let raw = RawFile::parse(&file).unwrap();
        prop_assert_eq!(raw.plots.len(), if second { 2 } else { 1 });
        let plot = &raw.plots[0];
        prop_assert_eq!(plot.points(), actual);
        for name in ["time", "v(a)", "v(b)", "i(v1)"] {
            prop_assert_eq!(plot.real(name).unwrap(), reference.plots[0].real(name).unwrap());
        }
        let warning = raw.warnings.first();
        match declared.cmp(&actual) {
            std::cmp::Ordering::Less => prop_assert!(
                matches!(warning, Some(RawWarning::ExtraPoints { read, .. }) if *read == actual),
                "{:?}", raw.warnings
            ),
            std::cmp::Ordering::Equal => prop_assert!(raw.warnings.is_empty() || second),
            std::cmp::Ordering::Greater => prop_assert!(
                matches!(warning, Some(RawWarning::Truncated { read, .. }) if *read == actual),
                "{:?}", raw.warnings
            ),
        }
        if second {
            prop_assert_eq!(raw.plots[1].points(), actual);
        }
    }
}
