//! The KiCad walkthrough of docs/kicad.md, as a user runs it: the netlist
//! in `examples/kicad/` is laid out as KiCad's SPICE export writes it (CRLF,
//! `/NET` names, `GND`, a `.include` of a contact model made by `pwl`), and
//! `run` must see through the filter exactly the openings that the RC
//! closed form says are long enough.

use std::path::{Path, PathBuf};

use assert_cmd::Command;
use chatterspice::chatter::ContactState;
use chatterspice::scenario::Scenario;
use serde_json::Value;

use crate::common::{Sexp, all, atom, head, parse_sexp};

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/kicad")
        .join(name)
}

/// R, C and the thresholds as the exported netlist and the scenario give
/// them: an opening shows at the pin when it lasts longer than the time the
/// pin needs to charge through R1 + R2 from 0 to the upper threshold.
fn visible_openings(scenario: &Scenario) -> (usize, usize) {
    let (r_pu, r_f, c_f, vdd) = (10e3, 1e3, 8.2e-9, 3.3);
    let tau = (r_pu + r_f) * c_f;
    let high = scenario.probes[0].high;
    let needed = tau * (vdd / (vdd - high)).ln();
    let chatter = chatterspice::simulate(
        &scenario.mechanics().unwrap(),
        &scenario.surface(),
        &scenario.settings(),
    )
    .unwrap();
    let first = chatter.first_impact.unwrap();
    let openings: Vec<f64> = chatter
        .intervals
        .iter()
        .filter(|iv| iv.state == ContactState::Open && iv.start > first)
        .map(|iv| iv.end - iv.start)
        .collect();
    // No opening so close to the threshold that ngspice's steps could
    // decide it: the test must not pass by luck.
    for d in &openings {
        assert!((d - needed).abs() > 0.05 * needed, "{d} vs {needed}");
    }
    let long = openings.iter().filter(|d| **d > needed).count();
    (long, openings.len())
}

#[test]
fn the_exported_netlist_runs_as_the_walkthrough_says() {
    let _ng = ngspice_or_skip!();
    let netlist = example("mcu_input.cir");
    let before = std::fs::read(&netlist).unwrap();
    assert!(before.windows(2).any(|w| w == b"\r\n"), "KiCad-style CRLF");
    let scenario_path = example("relay.toml");
    let scenario = Scenario::load(&scenario_path).unwrap();
    let (long, all) = visible_openings(&scenario);
    assert!(
        long > 0 && long < all,
        "{long} of {all}: the filter must matter"
    );

    let out = Command::cargo_bin("chatterspice")
        .unwrap()
        .args(["run", "--format", "json"])
        .arg(&scenario_path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let probe = &report["probes"][0];
    assert_eq!(probe["signal"], "v(/in)");
    // One edge for the first make, two for every opening the pin sees.
    assert_eq!(probe["edges"].as_u64().unwrap() as usize, 1 + 2 * long);
    // The exported file is never edited.
    assert_eq!(std::fs::read(&netlist).unwrap(), before);
}

#[test]
fn the_symbol_library_s_contact_matches_the_include_the_tool_writes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("kicad/chatterspice.kicad_sym")).unwrap();
    let lib = parse_sexp(&text);
    assert_eq!(head(&lib), Some("kicad_symbol_lib"));
    let Sexp::List(items) = &lib else {
        unreachable!()
    };
    let contact = items
        .iter()
        .find(|s| head(s) == Some("symbol") && atom(s, 1) == Some("RelayContact"))
        .expect("a RelayContact symbol");
    let mut props = Vec::new();
    all(contact, "property", &mut props);
    let field = |name: &str| {
        props
            .iter()
            .find(|p| atom(p, 1) == Some(name))
            .and_then(|p| atom(p, 2))
            .unwrap_or_else(|| panic!("no {name}"))
    };
    assert_eq!(field("Sim.Device"), "SUBCKT");
    assert_eq!(field("Sim.Name"), "CONTACT");
    assert_eq!(field("Sim.Library"), "contact.inc");
    assert_eq!(field("Sim.Pins"), "1=a 2=b");
    let mut pins = Vec::new();
    all(contact, "pin", &mut pins);
    let mut names: Vec<String> = pins
        .iter()
        .filter_map(|p| {
            let mut n = Vec::new();
            all(p, "name", &mut n);
            n.first().and_then(|n| atom(n, 1)).map(str::to_owned)
        })
        .collect();
    names.sort();
    assert_eq!(names, ["a", "b"]);
    // The include the tool writes (plain, and with an arc) defines that
    // subcircuit first, with those pins.
    for scenario in [
        "examples/kicad/relay.toml",
        "examples/scenarios/lamp-arc.toml",
    ] {
        let out = Command::cargo_bin("chatterspice")
            .unwrap()
            .args(["pwl", root.join(scenario).to_str().unwrap()])
            .output()
            .unwrap();
        assert!(out.status.success());
        let include = String::from_utf8(out.stdout).unwrap();
        let first = include
            .lines()
            .find(|l| l.to_ascii_lowercase().starts_with(".subckt"))
            .unwrap();
        assert_eq!(first, ".subckt CONTACT a b", "{scenario}");
    }
}
