//! Unit tests of the scenario file.

use std::path::Path;

use super::base::lexically_normal;
use super::*;
use crate::mechanics::surface::hunt_crossley_chi;
use crate::mechanics::{Settings, Surface};

const ORIGIN: &str = "relays/test.toml";

const VALID: &str = r#"[mechanics]
mass = 2.0e-4
stiffness = 800.0
damping = 0.04
force = 0.5
gap = 4.5e-4

[surface]
law = "kelvin-voigt"
stiffness = 8.0e4
damping = 0.37536

[circuit]
netlist = "net/input.cir"

[[probe]]
signal = "v(in)"
low = 0.99
high = 2.31
"#;

const SURFACE: &str = "law = \"kelvin-voigt\"\nstiffness = 8.0e4\ndamping = 0.37536\n";

fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    Scenario::parse(text, Path::new(ORIGIN))
}

/// VALID with one piece of text replaced.
fn edit(old: &str, new: &str) -> String {
    assert!(VALID.contains(old), "test edit `{old}` not in VALID");
    VALID.replacen(old, new, 1)
}

/// VALID with the body of [surface] replaced.
fn with_surface(body: &str) -> String {
    edit(SURFACE, &format!("{body}\n"))
}

/// The text must fail on `key`, with a message naming the file and key.
#[track_caller]
fn fails_on(text: &str, key: &str) -> ScenarioError {
    let err = match parse(text) {
        Ok(_) => panic!("expected an error on `{key}`, but it parsed:\n{text}"),
        Err(e) => e,
    };
    let msg = err.to_string();
    assert_eq!(err.key(), Some(key), "wrong key in: {msg}");
    assert!(msg.contains(ORIGIN), "file not named in: {msg}");
    assert!(msg.contains(&format!("`{key}`")), "key not named in: {msg}");
    err
}

#[track_caller]
fn line_of(err: &ScenarioError) -> Option<usize> {
    err.location().and_then(|at| at.line)
}

#[test]
fn the_netlist_is_read_from_beside_the_scenario_or_named_when_missing() {
    let dir = tempfile::tempdir().unwrap();
    let origin = dir.path().join("relay.toml");
    let s = Scenario::parse(VALID, &origin).unwrap();
    let err = s.netlist().unwrap().unwrap_err();
    assert_eq!(err.key(), Some("circuit.netlist"));
    assert!(err.to_string().contains("net/input.cir"), "{err}");

    std::fs::create_dir(dir.path().join("net")).unwrap();
    std::fs::write(dir.path().join("net/input.cir"), "title\n.end\n").unwrap();
    let (path, text) = s.netlist().unwrap().unwrap();
    assert_eq!(path, dir.path().join("net/input.cir"));
    assert_eq!(text, "title\n.end\n");

    let no_circuit = edit("[circuit]\nnetlist = \"net/input.cir\"\n", "");
    assert!(parse(&no_circuit).unwrap().netlist().is_none());
}

#[test]
fn netlist_paths_are_folded_lexically() {
    for (given, folded) in [
        ("a/../b/c.cir", "b/c.cir"),
        ("./a/./c.cir", "a/c.cir"),
        ("../../c.cir", "../../c.cir"),
        ("a/../../c.cir", "../c.cir"),
        ("/x/../c.cir", "/c.cir"),
        ("/../c.cir", "/c.cir"),
    ] {
        assert_eq!(
            lexically_normal(Path::new(given)),
            Path::new(folded),
            "{given}"
        );
    }
}

#[test]
fn the_builtin_default_carries_its_netlist() {
    let (path, text) = Scenario::builtin_default().netlist().unwrap().unwrap();
    // Named as the user names the scenario, never by a path of the
    // checkout the binary was built in.
    assert_eq!(path, Path::new("default:netlists/mcu_input.cir"));
    assert!(!path.starts_with(env!("CARGO_MANIFEST_DIR")));
    // And a scenario on `base = "default"` carries the same circuit.
    let (on_base, text_on_base) =
        Scenario::parse("base = \"default\"\n", Path::new("/elsewhere/mine.toml"))
            .unwrap()
            .netlist()
            .unwrap()
            .unwrap();
    assert_eq!((on_base, text_on_base), (path.clone(), text.clone()));
    assert_eq!(text, DEFAULT_NETLIST);
    assert!(text.contains(" CONTACT"));
}

#[test]
fn valid_file_converts_to_library_types() {
    let s = parse(VALID).unwrap();
    let m = s.mechanics().unwrap();
    assert_eq!(m.mass, 2.0e-4);
    assert_eq!(m.force, 0.5);
    assert_eq!(m.gap, 4.5e-4);
    assert_eq!(
        s.surface(),
        Surface::KelvinVoigt {
            stiffness: 8.0e4,
            damping: 0.37536
        }
    );
    assert_eq!(s.probes.len(), 1);
    assert_eq!(s.probes[0].signal, "v(in)");
}

#[test]
fn optional_keys_take_their_documented_defaults() {
    let s = parse(VALID).unwrap();
    let m = s.mechanics().unwrap();
    assert_eq!(
        (m.initial_position, m.initial_velocity, m.preload),
        (0.0, 0.0, 0.0)
    );
    assert_eq!(s.contact, ContactSection::default());
    assert_eq!(
        (s.contact.r_closed, s.contact.r_open, s.contact.edge_time),
        (0.05, 1e9, 1e-8)
    );
    assert_eq!(s.settings(), Settings::default());
    assert_eq!(
        (
            s.simulation.t_end,
            s.simulation.min_open_time,
            s.simulation.min_gap
        ),
        (0.02, 1e-9, 1e-9)
    );
    let c = s.circuit.unwrap();
    assert_eq!(
        (c.subckt.as_str(), c.coil_subckt.as_str()),
        ("CONTACT", "COIL")
    );
}

#[test]
fn sections_other_than_mechanics_and_surface_are_optional() {
    let text = VALID.split("[circuit]").next().unwrap();
    let s = parse(text).unwrap();
    assert!(s.circuit.is_none());
    assert!(s.probes.is_empty());
}

#[test]
fn explicit_settings_are_used() {
    let text =
        format!("{VALID}\n[simulation]\nt_end = 0.005\nmin_open_time = 0.0\nmin_gap = 1e-12\n");
    let s = parse(&text).unwrap().settings();
    assert_eq!((s.t_end, s.min_open_time, s.min_gap), (0.005, 0.0, 1e-12));
}

#[test]
fn integers_are_accepted_where_numbers_are_expected() {
    let s = parse(&edit("stiffness = 800.0", "stiffness = 800")).unwrap();
    assert_eq!(s.mechanics.stiffness, 800.0);
}

#[test]
fn netlist_resolves_against_the_scenario_directory() {
    let s = parse(VALID).unwrap();
    assert_eq!(
        s.circuit.unwrap().netlist,
        Path::new("relays").join("net/input.cir")
    );
    let abs = edit("\"net/input.cir\"", "\"/opt/net.cir\"");
    assert_eq!(
        parse(&abs).unwrap().circuit.unwrap().netlist,
        Path::new("/opt/net.cir")
    );
}

#[test]
fn builtin_default_is_the_documented_relay() {
    let s = Scenario::builtin_default();
    let m = s.mechanics().unwrap();
    // What the file promises: a signal relay that bounces several
    // times for about a millisecond (datasheets: typ. 1 ms, ≤ 5 ms).
    assert!(matches!(s.surface(), Surface::KelvinVoigt { .. }));
    let c = crate::simulate(&m, &s.surface(), &s.settings()).unwrap();
    assert_eq!(c.outcome, crate::Outcome::Stuck);
    assert!((3..=8).contains(&c.bounce_count), "{}", c.bounce_count);
    let bounce_time = c.settle_time.unwrap() - c.first_impact.unwrap();
    assert!((0.5e-3..3e-3).contains(&bounce_time), "{bounce_time}");
    assert_eq!(s.settings().t_end, 0.02);
    // Its circuit is the checkout's netlists/mcu_input.cir, compiled in
    // and named as the built-in one.
    let (name, text) = s.netlist().unwrap().unwrap();
    assert_eq!(name, Path::new("default:netlists/mcu_input.cir"));
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("netlists/mcu_input.cir");
    assert_eq!(text, std::fs::read_to_string(&file).unwrap());
    assert_eq!(s.probes, vec![Probe::new("v(in)", 0.99, 2.31)]);
}

#[test]
fn example_scenarios_parse() {
    let examples = [
        ("rigid", include_str!("../../examples/scenarios/rigid.toml")),
        (
            "kelvin-voigt",
            include_str!("../../examples/scenarios/kelvin-voigt.toml"),
        ),
        (
            "hunt-crossley",
            include_str!("../../examples/scenarios/hunt-crossley.toml"),
        ),
    ];
    for (law, text) in examples {
        let s = Scenario::parse(text, Path::new("examples/scenarios/x.toml"))
            .unwrap_or_else(|e| panic!("{law}: {e}"));
        assert_eq!(s.surface.law.as_str(), law);
    }
}

// Shape errors: syntax, typos, missing keys, wrong kinds of value.

#[test]
fn syntax_error_names_the_line() {
    let err = parse(&edit("gap = 4.5e-4", "gap = = 4.5e-4")).unwrap_err();
    assert!(matches!(err, ScenarioError::Syntax { .. }), "{err:?}");
    assert_eq!(line_of(&err), Some(6));
    assert!(err.to_string().starts_with("relays/test.toml:6:"), "{err}");
}

#[test]
fn misspelt_key_is_an_error_naming_key_and_line() {
    let err = fails_on(&edit("mass = 2.0e-4", "mas = 2.0e-4"), "mechanics.mas");
    assert!(matches!(err, ScenarioError::UnknownKey { .. }));
    assert_eq!(line_of(&err), Some(2));
    assert!(
        err.to_string().contains("`mass`"),
        "suggests the valid keys: {err}"
    );
}

#[test]
fn unknown_section_and_unknown_probe_key_are_errors() {
    fails_on(&format!("{VALID}\n[mechancis]\nmass = 1.0\n"), "mechancis");
    let err = fails_on(
        &edit("high = 2.31", "high = 2.31\nhigh_v = 3"),
        "probe[0].high_v",
    );
    assert_eq!(line_of(&err), Some(20));
}

#[test]
fn missing_required_keys_are_named() {
    let err = fails_on(&edit("mass = 2.0e-4\n", ""), "mechanics.mass");
    assert!(matches!(err, ScenarioError::MissingKey { .. }));
    fails_on(&edit("damping = 0.04\n", ""), "mechanics.damping");
    fails_on(&edit("gap = 4.5e-4\n", ""), "mechanics.gap");
    fails_on(&edit("law = \"kelvin-voigt\"\n", ""), "surface.law");
    fails_on(&edit("low = 0.99\n", ""), "probe[0].low");
    fails_on(
        &edit("netlist = \"net/input.cir\"\n", ""),
        "circuit.netlist",
    );
    let no_surface = edit(&format!("[surface]\n{SURFACE}"), "");
    fails_on(&no_surface, "surface");
}

#[test]
fn wrong_kind_of_value_is_named() {
    let err = fails_on(&edit("mass = 2.0e-4", "mass = \"heavy\""), "mechanics.mass");
    assert!(matches!(err, ScenarioError::BadValue { .. }));
    assert_eq!(line_of(&err), Some(2));
}

#[test]
fn unknown_surface_law_lists_the_laws() {
    let err = fails_on(
        &with_surface("law = \"hertz\"\nstiffness = 1.0"),
        "surface.law",
    );
    let msg = err.to_string();
    assert!(
        msg.contains("hunt-crossley") && msg.contains("rigid"),
        "{msg}"
    );
}

// Physics: every rule.

#[test]
fn mechanics_rules() {
    let cases = [
        ("mass = 2.0e-4", "mass = -2.0e-4", "mechanics.mass"),
        ("mass = 2.0e-4", "mass = 0.0", "mechanics.mass"),
        ("mass = 2.0e-4", "mass = nan", "mechanics.mass"),
        ("mass = 2.0e-4", "mass = inf", "mechanics.mass"),
        (
            "stiffness = 800.0",
            "stiffness = 0.0",
            "mechanics.stiffness",
        ),
        (
            "stiffness = 800.0",
            "stiffness = -inf",
            "mechanics.stiffness",
        ),
        ("damping = 0.04", "damping = -0.01", "mechanics.damping"),
        ("gap = 4.5e-4", "gap = 0.0", "mechanics.gap"),
        ("force = 0.5", "force = nan", "mechanics.force"),
        ("force = 0.5", "force = 0.0", "mechanics.force"),
        (
            "gap = 4.5e-4",
            "gap = 4.5e-4\ninitial_position = 4.5e-4",
            "mechanics.initial_position",
        ),
        (
            "gap = 4.5e-4",
            "gap = 4.5e-4\ninitial_velocity = inf",
            "mechanics.initial_velocity",
        ),
        (
            "gap = 4.5e-4",
            "gap = 4.5e-4\npreload = -0.1",
            "mechanics.preload",
        ),
        (
            "gap = 4.5e-4",
            "gap = 4.5e-4\npreload = 0.5",
            "mechanics.force",
        ),
    ];
    for (old, new, key) in cases {
        fails_on(&edit(old, new), key);
    }
    let err = fails_on(&edit("mass = 2.0e-4", "mass = nan"), "mechanics.mass");
    assert!(err.to_string().contains("finite"), "{err}");
    assert_eq!(line_of(&err), Some(2));
}

#[test]
fn a_zero_damping_and_a_negative_start_are_allowed() {
    let text = edit("damping = 0.04", "damping = 0.0\ninitial_position = -1e-4");
    assert!(parse(&text).is_ok());
}

const COIL: &str = "\n[coil]\nresistance = 70.0\nturns = 3000\npole_area = 2.0e-5\nair_gap = 6.0e-4\niron_gap = 5.0e-5\n";

#[test]
fn force_and_coil_are_mutually_exclusive_and_one_is_required() {
    let err = fails_on(&format!("{VALID}{COIL}"), "mechanics.force");
    assert!(matches!(err, ScenarioError::Conflict { .. }), "{err:?}");
    let err = fails_on(&edit("force = 0.5\n", ""), "mechanics.force");
    assert!(matches!(err, ScenarioError::MissingKey { .. }), "{err:?}");
}

#[test]
fn coil_scenario_parses_but_is_not_simulated_yet() {
    let s = parse(&format!("{}{COIL}", edit("force = 0.5\n", ""))).unwrap();
    assert_eq!(s.coil.as_ref().unwrap().turns, 3000);
    let err = s.mechanics().unwrap_err();
    assert!(matches!(err, ScenarioError::CoilDriveUnsupported { .. }));
    assert!(err.to_string().contains("mechanics.force"), "{err}");
}

#[test]
fn a_back_stop_has_a_surface_law_of_its_own_and_needs_a_coil() {
    let coil = format!("{}{COIL}", edit("force = 0.5\n", ""));
    let back = "\n[back_stop]\nlaw = \"rigid\"\nrestitution = 0.4\n";
    let mut s = parse(&format!("{coil}{back}")).unwrap();
    assert_eq!(s.back_stop(), Some(Surface::Rigid { restitution: 0.4 }));
    assert_eq!(parse(&coil).unwrap().back_stop(), None);
    // Its keys are named as its own, and settable for sweeps.
    fails_on(
        &format!("{coil}{}", back.replace("0.4", "1.5")),
        "back_stop.restitution",
    );
    fails_on(&format!("{coil}{back}damping = 1.0\n"), "back_stop.damping");
    s.set_number("back_stop.restitution", 0.2).unwrap();
    assert_eq!(s.back_stop(), Some(Surface::Rigid { restitution: 0.2 }));
    assert!(s.set_number("back_stop.restitution", 2.0).is_err());
    assert_eq!(s.back_stop(), Some(Surface::Rigid { restitution: 0.2 }));
    // A step force never releases: a back stop or a release limit
    // without a coil is refused, naming what to change.
    let err = fails_on(&format!("{VALID}{back}"), "back_stop");
    assert!(err.to_string().contains("[coil]"), "{err}");
    fails_on(
        &format!("{VALID}\n[limits]\nmax_release_time = 1e-3\n"),
        "limits.max_release_time",
    );
    // So is a normally-closed contact in the circuit; with a coil it
    // needs a name of its own.
    let nc = "netlist = \"net/input.cir\"\nnc_subckt = \"CONTACT_NC\"\n";
    fails_on(
        &VALID.replace("netlist = \"net/input.cir\"\n", nc),
        "circuit.nc_subckt",
    );
    let with_nc = coil.replace("netlist = \"net/input.cir\"\n", nc);
    assert_eq!(
        parse(&with_nc)
            .unwrap()
            .circuit
            .unwrap()
            .nc_subckt
            .as_deref(),
        Some("CONTACT_NC")
    );
    fails_on(
        &with_nc.replace("\"CONTACT_NC\"", "\"contact\""),
        "circuit.nc_subckt",
    );
    let limits = "\n[limits]\nmax_release_time = 1e-3\nmax_nc_bounces = 3\n";
    let s = parse(&format!("{coil}{limits}")).unwrap();
    assert_eq!(s.limits.unwrap().max_nc_bounces, Some(3));
}

#[test]
fn coil_rules() {
    let base = format!("{}{COIL}", edit("force = 0.5\n", ""));
    let cases = [
        ("resistance = 70.0", "resistance = 0.0", "coil.resistance"),
        ("turns = 3000", "turns = 0", "coil.turns"),
        ("turns = 3000", "turns = -3", "coil.turns"),
        ("pole_area = 2.0e-5", "pole_area = nan", "coil.pole_area"),
        ("air_gap = 6.0e-4", "air_gap = 4.0e-4", "coil.air_gap"),
        ("iron_gap = 5.0e-5", "iron_gap = -1e-6", "coil.iron_gap"),
    ];
    for (old, new, key) in cases {
        assert!(base.contains(old));
        fails_on(&base.replacen(old, new, 1), key);
    }
}

#[test]
fn rigid_surface_rules() {
    let s = parse(&with_surface("law = \"rigid\"\nrestitution = 0.8")).unwrap();
    assert_eq!(s.surface(), Surface::Rigid { restitution: 0.8 });
    for e in ["0.0", "1.0"] {
        assert!(
            parse(&with_surface(&format!(
                "law = \"rigid\"\nrestitution = {e}"
            )))
            .is_ok()
        );
    }
    fails_on(
        &with_surface("law = \"rigid\"\nrestitution = 1.5"),
        "surface.restitution",
    );
    fails_on(
        &with_surface("law = \"rigid\"\nrestitution = -0.1"),
        "surface.restitution",
    );
    fails_on(&with_surface("law = \"rigid\""), "surface.restitution");
    let err = fails_on(
        &with_surface("law = \"rigid\"\nrestitution = 0.8\nstiffness = 1e5"),
        "surface.stiffness",
    );
    assert!(matches!(err, ScenarioError::NotForLaw { .. }), "{err:?}");
}

#[test]
fn kelvin_voigt_surface_rules() {
    let kv = |body: &str| with_surface(&format!("law = \"kelvin-voigt\"\n{body}"));
    assert!(parse(&kv("stiffness = 1e5\ndamping = 0.0")).is_ok());
    fails_on(&kv("stiffness = 0.0\ndamping = 0.3"), "surface.stiffness");
    fails_on(&kv("stiffness = 1e5\ndamping = -0.3"), "surface.damping");
    fails_on(&kv("damping = 0.3"), "surface.stiffness");
    fails_on(&kv("stiffness = 1e5"), "surface.damping");
    let err = fails_on(
        &kv("stiffness = 1e5\ndamping = 0.3\nrestitution = 0.8"),
        "surface.restitution",
    );
    assert!(err.to_string().contains("kelvin-voigt"), "{err}");
    fails_on(
        &kv("stiffness = 1e5\ndamping = 0.3\nchi = 0.1"),
        "surface.chi",
    );
}

#[test]
fn hunt_crossley_surface_rules() {
    let hc =
        |body: &str| with_surface(&format!("law = \"hunt-crossley\"\nstiffness = 1e6\n{body}"));
    let s = parse(&hc("chi = 0.2")).unwrap();
    assert_eq!(
        s.surface(),
        Surface::HuntCrossley {
            stiffness: 1e6,
            exponent: 1.0,
            chi: 0.2
        }
    );
    let s = parse(&hc(
        "exponent = 1.5\nrestitution = 0.85\nreference_velocity = 0.3",
    ))
    .unwrap();
    let expected_chi = hunt_crossley_chi(0.85, 0.3).unwrap();
    assert_eq!(
        s.surface(),
        Surface::HuntCrossley {
            stiffness: 1e6,
            exponent: 1.5,
            chi: expected_chi
        }
    );
    assert!(parse(&hc("chi = 0.0")).is_ok());
    assert!(parse(&hc("restitution = 1.0\nreference_velocity = 0.3")).is_ok());

    fails_on(
        &with_surface("law = \"hunt-crossley\"\nstiffness = -1.0\nchi = 0.2"),
        "surface.stiffness",
    );
    fails_on(
        &with_surface("law = \"hunt-crossley\"\nchi = 0.2"),
        "surface.stiffness",
    );
    fails_on(&hc("chi = 0.2\nexponent = 0.0"), "surface.exponent");
    fails_on(&hc("chi = -0.2"), "surface.chi");
    fails_on(&hc("chi = nan"), "surface.chi");
    let err = fails_on(&hc("chi = 0.2\nrestitution = 0.8"), "surface.chi");
    assert!(matches!(err, ScenarioError::Conflict { .. }), "{err:?}");
    fails_on(&hc("chi = 0.2\nreference_velocity = 0.3"), "surface.chi");
    fails_on(&hc("restitution = 0.8"), "surface.reference_velocity");
    fails_on(&hc("reference_velocity = 0.3"), "surface.restitution");
    fails_on(&hc(""), "surface.chi");
    fails_on(
        &hc("restitution = 0.0\nreference_velocity = 0.3"),
        "surface.restitution",
    );
    fails_on(
        &hc("restitution = 1.5\nreference_velocity = 0.3"),
        "surface.restitution",
    );
    fails_on(
        &hc("restitution = 0.8\nreference_velocity = 0.0"),
        "surface.reference_velocity",
    );
    fails_on(&hc("chi = 0.2\ndamping = 0.1"), "surface.damping");
}

#[test]
fn contact_rules() {
    let with = |body: &str| format!("{VALID}\n[contact]\n{body}\n");
    assert!(parse(&with("r_closed = 0.1")).is_ok());
    fails_on(&with("r_closed = 0.0"), "contact.r_closed");
    fails_on(&with("r_closed = 10.0\nr_open = 10.0"), "contact.r_open");
    fails_on(&with("r_open = inf"), "contact.r_open");
    fails_on(&with("edge_time = 0.0"), "contact.edge_time");

    let holm = |body: &str| format!("{VALID}\n[contact.holm]\n{body}\n");
    let s = parse(&holm("r_ref = 0.04\nf_ref = 1.0")).unwrap();
    assert_eq!(
        s.contact.holm,
        Some(HolmSection {
            r_film: 0.0,
            r_ref: 0.04,
            f_ref: 1.0,
            exponent: 0.5
        })
    );
    fails_on(&holm("r_ref = 0.0\nf_ref = 1.0"), "contact.holm.r_ref");
    fails_on(&holm("r_ref = 0.04\nf_ref = -1.0"), "contact.holm.f_ref");
    fails_on(
        &holm("r_ref = 0.04\nf_ref = 1.0\nr_film = -0.01"),
        "contact.holm.r_film",
    );
    fails_on(
        &holm("r_ref = 0.04\nf_ref = 1.0\nexponent = 2.0"),
        "contact.holm.exponent",
    );
    fails_on(
        &holm("r_ref = 0.04\nf_ref = 1.0\nfilm = 0.01"),
        "contact.holm.film",
    );
}

#[test]
fn simulation_rules() {
    let with = |body: &str| format!("{VALID}\n[simulation]\n{body}\n");
    fails_on(&with("t_end = 0.0"), "simulation.t_end");
    fails_on(&with("t_end = inf"), "simulation.t_end");
    fails_on(&with("min_open_time = -1e-9"), "simulation.min_open_time");
    fails_on(&with("min_gap = -1e-9"), "simulation.min_gap");
}

#[test]
fn circuit_and_probe_rules() {
    fails_on(
        &edit("netlist = \"net/input.cir\"", "netlist = \"\""),
        "circuit.netlist",
    );
    fails_on(
        &edit(
            "netlist = \"net/input.cir\"",
            "netlist = \"a.cir\"\nsubckt = \"\"",
        ),
        "circuit.subckt",
    );
    fails_on(
        &edit("signal = \"v(in)\"", "signal = \" \""),
        "probe[0].signal",
    );
    let err = fails_on(&edit("low = 0.99", "low = 2.31"), "probe[0].low");
    assert_eq!(line_of(&err), Some(18));
    fails_on(&edit("high = 2.31", "high = nan"), "probe[0].high");
    let second = format!("{VALID}\n[[probe]]\nsignal = \"v(out)\"\nlow = 3.0\nhigh = 1.0\n");
    let err = fails_on(&second, "probe[1].low");
    assert_eq!(line_of(&err), Some(23));
}

#[test]
fn missing_file_names_the_path() {
    let err = Scenario::load(Path::new("no/such/scenario.toml")).unwrap_err();
    assert!(matches!(err, ScenarioError::Read { .. }));
    assert!(err.to_string().contains("no/such/scenario.toml"), "{err}");
}
// [sweep] and set_number.

#[test]
fn set_number_sets_and_validates_by_the_loader_s_rules() {
    let mut s = parse(VALID).unwrap();
    s.set_number("mechanics.mass", 3.0e-4).unwrap();
    assert_eq!(s.mechanics().unwrap().mass, 3.0e-4);
    assert_eq!(s.number("mechanics.mass").unwrap(), Some(3.0e-4));
    s.set_number("surface.stiffness", 9.0e4).unwrap();
    assert!(matches!(s.surface(), Surface::KelvinVoigt { stiffness, .. } if stiffness == 9.0e4));
    s.set_number("probe[0].low", 1.2).unwrap();
    assert_eq!(s.probes[0].low, 1.2);

    let before = s.clone();
    let err = s.set_number("mechanics.mass", -1.0).unwrap_err();
    assert_eq!(err.key(), Some("mechanics.mass"));
    let err = s.set_number("probe[0].low", 5.0).unwrap_err();
    assert_eq!(err.key(), Some("probe[0].low"));
    let err = s.set_number("surface.restitution", 0.5).unwrap_err();
    assert!(matches!(err, ScenarioError::NotForLaw { .. }), "{err:?}");
    assert_eq!(s, before, "a failed set leaves the scenario as it was");

    // Together valid, one at a time not.
    s.set_numbers(&[("contact.r_open", 20.0), ("contact.r_closed", 10.0)])
        .unwrap();
    assert!(s.set_number("contact.r_closed", 30.0).is_err());
}

#[test]
fn set_number_converts_a_hunt_crossley_restitution_again() {
    let text = with_surface(
        "law = \"hunt-crossley\"\nstiffness = 1e6\nrestitution = 0.85\nreference_velocity = 0.3",
    );
    let mut s = parse(&text).unwrap();
    s.set_number("surface.restitution", 0.6).unwrap();
    let chi = hunt_crossley_chi(0.6, 0.3).unwrap();
    assert!(matches!(s.surface(), Surface::HuntCrossley { chi: c, .. } if c == chi));
}

#[test]
fn set_number_names_unknown_keys_and_missing_sections() {
    let mut s = parse(VALID).unwrap();
    let err = s.set_number("mechanics.mas", 1.0).unwrap_err();
    assert!(
        matches!(err, ScenarioError::UnknownNumber { .. }),
        "{err:?}"
    );
    let msg = err.to_string();
    assert!(
        msg.contains("`mechanics.mas`") && msg.contains("mechanics.mass"),
        "{msg}"
    );
    assert!(s.set_number("coil.resistance", 1.0).is_err());
    assert!(s.set_number("contact.holm.r_ref", 1.0).is_err());
    assert!(s.set_number("probe[3].low", 1.0).is_err());
    assert!(s.number("surface.restitution").unwrap().is_none());
}

#[test]
fn every_number_key_reads_back_what_was_set() {
    let text = format!("{VALID}\n[contact.holm]\nr_ref = 0.04\nf_ref = 1.0\n");
    let s = parse(&text).unwrap();
    for key in NUMBER_KEYS {
        let Ok(Some(value)) = s.number(key) else {
            continue;
        };
        let mut t = s.clone();
        let new = if value == 0.0 { 1e-12 } else { value * 1.001 };
        t.set_number(key, new)
            .unwrap_or_else(|e| panic!("{key}: {e}"));
        assert_eq!(t.number(key).unwrap(), Some(new), "{key}");
    }
}

#[test]
fn sweep_section_parses() {
    let text = format!(
        "{VALID}\n[sweep]\nsamples = 50\nseed = 7\n[sweep.vary]\n\"mechanics.mass\" = 0.1\n\
         \"surface.damping\" = {{ normal = 0.05 }}\n\"mechanics.force\" = {{ uniform = 0.2 }}\n"
    );
    let sweep = parse(&text).unwrap().sweep.unwrap();
    assert_eq!((sweep.samples, sweep.seed), (Some(50), Some(7)));
    let vary: Vec<_> = sweep.vary.iter().map(|(k, t)| (k.as_str(), *t)).collect();
    assert_eq!(
        vary,
        [
            ("mechanics.force", Tolerance::Uniform(0.2)),
            ("mechanics.mass", Tolerance::Uniform(0.1)),
            ("surface.damping", Tolerance::Normal(0.05)),
        ]
    );
    let grid = format!(
        "{VALID}\n[sweep.grid]\n\"mechanics.force\" = {{ from = 0.5, to = 2.0, steps = 4 }}\n"
    );
    let axis = parse(&grid).unwrap().sweep.unwrap().grid["mechanics.force"];
    let values: Vec<f64> = (0..4).map(|j| axis.value(j)).collect();
    assert_eq!(values, [0.5, 1.0, 1.5, 2.0]);
    let log = GridAxis {
        from: 1.0,
        to: 100.0,
        steps: 3,
        log: true,
    };
    assert!((log.value(1) - 10.0).abs() < 1e-12);
    assert_eq!(log.value(2), 100.0);
}

#[test]
fn sweep_rules() {
    let with = |body: &str| format!("{VALID}\n{body}\n");
    let err = fails_on(
        &with("[sweep.vary]\n\"mechanics.mas\" = 0.1"),
        "mechanics.mas",
    );
    assert!(
        matches!(err, ScenarioError::UnknownNumber { .. }),
        "{err:?}"
    );
    assert_eq!(line_of(&err), Some(22));
    let msg = err.to_string();
    assert!(
        msg.contains("[sweep.vary]") && msg.contains("surface.damping"),
        "{msg}"
    );
    fails_on(
        &with("[sweep.grid]\n\"bogus\" = { from = 1, to = 2, steps = 2 }"),
        "bogus",
    );
    fails_on(
        &with("[sweep.vary]\n\"mechanics.mass\" = 1.5"),
        "sweep.vary.\"mechanics.mass\"",
    );
    fails_on(
        &with("[sweep.vary]\n\"mechanics.mass\" = { normal = 0.3 }"),
        "sweep.vary.\"mechanics.mass\"",
    );
    fails_on(
        &with("[sweep.vary]\n\"mechanics.mass\" = { sigma = 0.3 }"),
        "sweep.vary.mechanics.mass",
    );
    fails_on(
        &with("[sweep.vary]\n\"mechanics.preload\" = 0.1"),
        "sweep.vary.\"mechanics.preload\"",
    );
    fails_on(
        &with("[sweep.vary]\n\"surface.restitution\" = 0.1"),
        "sweep.vary.\"surface.restitution\"",
    );
    fails_on(&with("[sweep]\nsamples = 0"), "sweep.samples");
    fails_on(
        &with(
            "[sweep.vary]\n\"mechanics.mass\" = 0.1\n[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 4 }",
        ),
        "sweep.grid",
    );
    fails_on(
        &with(
            "[sweep]\nsamples = 3\n[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 4 }",
        ),
        "sweep.samples",
    );
    fails_on(
        &with("[sweep.grid]\n\"mechanics.force\" = { from = -0.5, to = 2.0, steps = 4 }"),
        "sweep.grid.\"mechanics.force\".from",
    );
    fails_on(
        &with("[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 0 }"),
        "sweep.grid.\"mechanics.force\".steps",
    );
    fails_on(
        &with(
            "[sweep.grid]\n\"mechanics.force\" = { from = 0.5, to = 2.0, steps = 4 }\n\
             \"mechanics.mass\" = { from = 1e-4, to = 2e-4, steps = 2 }\n\
             \"mechanics.gap\" = { from = 1e-4, to = 2e-4, steps = 2 }",
        ),
        "sweep.grid",
    );
}
