//! Free impacts: an armature thrown at the contact with no net closing
//! force (force at most the preload), as a restitution measurement does it.
//! The preload holds the armature only while it rests on its stop.

use assert_cmd::Command;
use predicates::prelude::*;
use serde_json::Value;

const MASS: f64 = 2e-4; // kg
const STIFFNESS: f64 = 800.0; // N/m
const GAP: f64 = 4.5e-4; // m

fn scenario(
    dir: &std::path::Path,
    force: f64,
    preload: f64,
    x0: f64,
    v0: f64,
) -> std::path::PathBuf {
    let text = format!(
        "[mechanics]\nmass = {MASS:e}\nstiffness = {STIFFNESS:e}\ndamping = 0.0\nforce = {force:e}\n\
         preload = {preload:e}\ngap = {GAP:e}\ninitial_position = {x0:e}\ninitial_velocity = {v0:e}\n\n\
         [surface]\nlaw = \"rigid\"\nrestitution = 0.6\n\n[simulation]\nt_end = 0.01\n"
    );
    let path = dir.join("free.toml");
    std::fs::write(&path, text).unwrap();
    path
}

fn bounce(path: &std::path::Path) -> Value {
    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["bounce", path.to_str().unwrap(), "--format", "json"])
        .assert()
        .success();
    serde_json::from_slice(&out.get_output().stdout).unwrap()
}

/// Undamped, force = preload (no net force): x(t) = (v0/ω)·sin ωt reaches
/// the gap at t1 = asin(gω/v0)/ω with speed v0·cos ωt1; the rigid surface
/// sends it back at 0.6 of that. With force 0 < preload the net force
/// −p pulls it back: x(t) = (v0/ω) sin ωt − (p/s)(1 − cos ωt).
#[test]
fn a_thrown_armature_hits_the_contact_as_the_closed_form_says() {
    let dir = tempfile::tempdir().unwrap();
    let omega = (STIFFNESS / MASS).sqrt();
    let v0 = 1.0; // m/s: reaches v0/ω = 0.5 mm > gap
    let v = bounce(&scenario(dir.path(), 0.05, 0.05, 0.0, v0));
    let t1 = (GAP * omega / v0).asin() / omega;
    let impact = &v["impacts"][0];
    let t = impact["impact_time"].as_f64().unwrap();
    assert!((t - t1).abs() < 1e-12 * t1.max(1.0) + 1e-15, "{t} vs {t1}");
    let vh = impact["impact_velocity"].as_f64().unwrap();
    let expected = v0 * (omega * t1).cos();
    assert!(
        (vh - expected).abs() < 1e-9 * expected,
        "{vh} vs {expected}"
    );
    let e = impact["restitution"].as_f64().unwrap();
    assert!((e - 0.6).abs() < 1e-12, "{e}");

    // Force 0 with a preload: the net force pulls back; solve for the
    // first crossing of the gap by bisection on the closed form.
    let p = 0.02;
    let x = |t: f64| v0 / omega * (omega * t).sin() - p / STIFFNESS * (1.0 - (omega * t).cos());
    let (mut lo, mut hi) = (0.0, std::f64::consts::FRAC_PI_2 / omega);
    assert!(x(hi) > GAP);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if x(mid) < GAP { lo = mid } else { hi = mid }
    }
    let v = bounce(&scenario(dir.path(), 0.0, p, 0.0, v0));
    let t = v["impacts"][0]["impact_time"].as_f64().unwrap();
    assert!((t - lo).abs() < 1e-12, "{t} vs {lo}");
}

#[test]
fn a_throw_too_weak_to_reach_the_contact_never_closes() {
    let dir = tempfile::tempdir().unwrap();
    // v0/ω = 0.25 mm < gap: turns back short of it.
    let v = bounce(&scenario(dir.path(), 0.0, 0.0, 1e-4, 0.5));
    assert_eq!(v["outcome"], "never_closes");
    assert_eq!(v["impacts"].as_array().unwrap().len(), 0);
}

#[test]
fn at_rest_on_the_stop_the_force_must_beat_the_preload() {
    let dir = tempfile::tempdir().unwrap();
    Command::cargo_bin("chatterspice")
        .unwrap()
        .args([
            "bounce",
            scenario(dir.path(), 0.05, 0.1, 0.0, 0.0).to_str().unwrap(),
        ])
        .assert()
        .code(2)
        .stderr(
            predicate::str::contains("mechanics.force")
                .and(predicate::str::contains("at rest on its stop"))
                .and(predicate::str::contains("initial_velocity")),
        );
}
