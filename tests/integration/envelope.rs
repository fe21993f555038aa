//! `run --envelope` and `check --envelope`: every relay a part's datasheet
//! allows, as bands, with each limit held against the worst one.

use crate::common;

use assert_cmd::Command;
use serde_json::Value;

fn scenario() -> String {
    format!(
        "{}/tests/data/scenarios/im_mcu_envelope.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn check_envelope(path: &str, extra: &[&str], code: i32) -> Value {
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args([
            "check",
            path,
            "--envelope",
            "--samples",
            "32",
            "--jobs",
            "2",
        ])
        .args(["--format", "json"])
        .args(extra)
        .assert()
        .code(code);
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

#[test]
fn a_check_over_the_envelope_is_a_band_held_against_the_worst_relay() {
    let Some(_) = common::ngspice() else { return };
    let doc = check_envelope(&scenario(), &[], 0);
    let env = &doc["envelope"];
    assert_eq!(env["samples"], 32);
    let kept = env["kept"].as_u64().unwrap();
    assert!(kept >= 16, "{env}");
    let bounces = &env["quantities"]["bounce_count"];
    let (min, max) = (
        bounces["min"].as_f64().unwrap(),
        bounces["max"].as_f64().unwrap(),
    );
    assert!(max > min, "a band, not a point: {bounces}");
    let edges = &env["quantities"]["v(in).edges"];
    assert!(edges["max"].as_f64() > edges["min"].as_f64(), "{edges}");
    // The worst relay is the one with the most bounces, and its values
    // are the sampled keys.
    let worst = &env["worst"];
    assert_eq!(worst["limit"], "limits.max_bounces");
    assert!(worst["values"]["surface.damping"].is_number(), "{worst}");
    assert_eq!(doc["bounce"]["bounce_count"].as_f64(), Some(max));
    assert_eq!(doc["checks"][0]["actual"].as_f64(), Some(max));

    // A limit one below the worst relay's count fails, with exit 1, and
    // says which relay; at the worst relay's count it holds.
    let dir = tempfile::tempdir().unwrap();
    let tight = dir.path().join("tight.toml");
    let text = std::fs::read_to_string(scenario()).unwrap().replace(
        "netlist = \"../netlists/mcu_input_10ms.cir\"",
        &format!(
            "netlist = \"{}/tests/data/netlists/mcu_input_10ms.cir\"",
            env!("CARGO_MANIFEST_DIR")
        ),
    );
    for (limit, code) in [(max - 1.0, 1), (max, 0)] {
        std::fs::write(
            &tight,
            text.replace("max_bounces = 100", &format!("max_bounces = {limit}")),
        )
        .unwrap();
        let doc = check_envelope(tight.to_str().unwrap(), &[], code);
        let check = &doc["checks"][0];
        assert_eq!(check["passed"], code == 0, "{check}");
        let note = check["note"].as_str().unwrap();
        assert!(
            note.contains("worst of") && note.contains("relay"),
            "{note}"
        );
    }
}

#[test]
fn the_draw_is_reproducible_and_the_seed_moves_it() {
    let Some(_) = common::ngspice() else { return };
    let a = check_envelope(&scenario(), &["--seed", "7"], 0);
    let b = check_envelope(&scenario(), &["--seed", "7"], 0);
    let c = check_envelope(&scenario(), &["--seed", "8"], 0);
    assert_eq!(a["envelope"], b["envelope"]);
    assert_ne!(a["envelope"]["quantities"], c["envelope"]["quantities"]);
}

/// The message of `check --envelope` on `part:te-rel-5v` with the
/// envelope `range` (one TOML line), which must be refused with exit 2.
fn refused(dir: &std::path::Path, range: &str) -> String {
    let file = dir.join("point.toml");
    std::fs::write(
        &file,
        format!("base = \"part:te-rel-5v\"\n[envelope]\n{range}\n"),
    )
    .unwrap();
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["check", file.to_str().unwrap(), "--envelope"])
        .assert()
        .code(2);
    String::from_utf8_lossy(&out.get_output().stderr).into_owned()
}

#[test]
fn an_envelope_that_is_a_point_is_refused_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let err = refused(
        dir.path(),
        "\"surface.damping\" = { min = 20.0, max = 20.0 }",
    );
    assert!(err.contains("point.toml") && err.contains("max"), "{err}");
    // An unknown key is named too.
    let err = refused(dir.path(), "\"surface.dampnig\" = { min = 1.0, max = 2.0 }");
    assert!(err.contains("surface.dampnig"), "{err}");
}

/// A relay of the envelope that cannot be simulated is named, with its
/// reason, and counted apart from the datasheet's rejections; a check over
/// such an envelope cannot pass.
#[test]
fn relays_that_cannot_be_simulated_are_named_and_fail_the_check() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("soft.toml");
    // Pole faces set past the magnet's pole (gap + overtravel beyond
    // `coil.air_gap`): the magnet pulls those armatures through to its
    // pole, which the model cannot go past.
    std::fs::write(
        &path,
        "base = \"part:te-axicom-im-5v\"\n\n[limits]\nmax_bounces = 100\n\n\
         [envelope.\"pole_face.overtravel\"]\nmin = 1.0e-4\nmax = 1.6e-4\n",
    )
    .unwrap();
    let doc = check_envelope(path.to_str().unwrap(), &[], 1);
    let env = &doc["envelope"];
    let failed = env["failed"].as_u64().unwrap();
    assert!(failed > 0 && failed < 32, "{env}");
    assert_eq!(env["failures"].as_array().unwrap().len() as u64, failed);
    let first = &env["failures"][0];
    assert!(
        first["reason"].as_str().unwrap().contains("pole"),
        "{first}"
    );
    // Only armatures whose pole face lies near or past the magnet's pole
    // fail.
    let part: toml::Table = chatterspice::scenario::bundled_part_text("te-axicom-im-5v")
        .parse()
        .unwrap();
    let room =
        part["coil"]["air_gap"].as_float().unwrap() - part["mechanics"]["gap"].as_float().unwrap();
    for f in env["failures"].as_array().unwrap() {
        let o = f["values"]["pole_face.overtravel"].as_f64().unwrap();
        assert!(o > 0.9 * room, "{o} against {room}: {f}");
    }
    // Not rejections: the datasheet does not exclude them.
    let kept = env["kept"].as_u64().unwrap();
    let rejected = env["rejected_relays"].as_u64().unwrap();
    assert_eq!(kept + rejected + failed, 32, "{env}");
    assert!(env["rejected"].get("failed").is_none(), "{env}");
    let check = doc["checks"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["quantity"] == "relays not evaluated")
        .expect("the check says so");
    assert_eq!(check["passed"], false);
    assert_eq!(check["actual"].as_f64(), Some(failed as f64));
    // Its own envelope, where every relay simulates, passes.
    std::fs::write(
        &path,
        "base = \"part:te-axicom-im-5v\"\n\n[limits]\nmax_bounces = 100\n",
    )
    .unwrap();
    let doc = check_envelope(path.to_str().unwrap(), &[], 0);
    assert_eq!(doc["envelope"]["failed"], 0);
}
