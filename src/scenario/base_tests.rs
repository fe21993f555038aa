//! `base =`: merging, paths, and errors that name the file a key came from.

use std::path::{Path, PathBuf};

use super::*;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    if let Some(parent) = path.parent() {
        std::fs::create_dir_all(parent).unwrap();
    }
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_scenario_on_the_default_overrides_key_by_key() {
    let default = Scenario::builtin_default();
    let s = Scenario::parse(
        "base = \"default\"\n[mechanics]\nmass = 3.0e-4\n",
        Path::new("mine.toml"),
    )
    .unwrap();
    assert_eq!(s.mechanics.mass, 3.0e-4);
    assert_ne!(default.mechanics.mass, 3.0e-4);
    // Everything else is the default's, the netlist included, and its
    // compiled-in text is still found.
    assert_eq!(s.mechanics.stiffness, default.mechanics.stiffness);
    assert_eq!(s.surface, default.surface);
    assert_eq!(s.probes, default.probes);
    assert!(s.netlist().unwrap().is_ok());
    assert_eq!(s.origin, Path::new("mine.toml"));
}

#[test]
fn a_part_as_base_brings_its_coil_and_datasheet() {
    let (name, _) = BUNDLED_PARTS[0];
    let s = Scenario::parse(
        &format!("base = \"part:{name}\"\n[simulation]\nt_end = 0.05\n"),
        Path::new("x.toml"),
    )
    .unwrap();
    assert!(s.coil.is_some() && s.datasheet.is_some());
    assert_eq!(s.simulation.t_end, 0.05);
    let err = Scenario::parse("base = \"part:no-such\"\n", Path::new("x.toml")).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("no-such") && text.contains(name), "{text}");
    assert!(text.starts_with("x.toml:1"), "{text}");
}

#[test]
fn arrays_are_replaced_and_a_changed_law_starts_afresh() {
    let s = Scenario::parse(
        "base = \"default\"\n[surface]\nlaw = \"rigid\"\nrestitution = 0.5\n\
         [[probe]]\nsignal = \"v(out)\"\nlow = 1.0\nhigh = 2.0\n",
        Path::new("x.toml"),
    )
    .unwrap();
    assert_eq!(s.probes.len(), 1);
    assert_eq!(s.probes[0].signal, "v(out)");
    assert_eq!(s.surface.law, SurfaceLaw::Rigid);
    assert_eq!(s.surface.stiffness, None);
}

#[test]
fn a_base_file_keeps_its_relative_netlist_and_its_errors_name_it() {
    let dir = tempfile::tempdir().unwrap();
    let base_text = DEFAULT_SCENARIO_TOML.replace(
        "netlist = \"../netlists/mcu_input.cir\"",
        "netlist = \"net/board.cir\"",
    );
    write(dir.path(), "lib/net/board.cir", DEFAULT_NETLIST);
    write(dir.path(), "lib/relay.toml", &base_text);
    let top = write(
        dir.path(),
        "work/top.toml",
        "base = \"../lib/relay.toml\"\n\n[mechanics]\nmass = 2.0e-4\n",
    );
    let s = Scenario::load(&top).unwrap();
    assert_eq!(s.mechanics.mass, 2.0e-4);
    let (path, text) = s.netlist().unwrap().unwrap();
    assert!(path.ends_with("lib/net/board.cir"), "{}", path.display());
    assert_eq!(text, DEFAULT_NETLIST);

    // A bad value in the file itself names the file and its line.
    write(
        dir.path(),
        "work/top.toml",
        "base = \"../lib/relay.toml\"\n\n[mechanics]\nmass = -1.0\n",
    );
    let err = Scenario::load(&top).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains("top.toml:4") && text.contains("mass"),
        "{text}"
    );

    // A bad value the base brings names the base file and its line.
    let line = base_text
        .lines()
        .position(|l| l.trim_start().starts_with("stiffness"))
        .unwrap()
        + 1;
    let broken = base_text.replacen("stiffness", "stiffness = -5.0 #", 1);
    write(dir.path(), "lib/relay.toml", &broken);
    write(
        dir.path(),
        "work/top.toml",
        "base = \"../lib/relay.toml\"\n[simulation]\nt_end = 0.02\n",
    );
    let err = Scenario::load(&top).unwrap_err();
    let text = err.to_string();
    assert!(
        text.contains(&format!("relay.toml:{line}")) && text.contains("stiffness"),
        "{text}"
    );
}

#[test]
fn a_loop_of_bases_and_an_unreadable_base_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let a = write(dir.path(), "a.toml", "base = \"b.toml\"\n");
    write(dir.path(), "b.toml", "base = \"a.toml\"\n");
    let text = Scenario::load(&a).unwrap_err().to_string();
    assert!(text.contains("comes back"), "{text}");
    let c = write(dir.path(), "c.toml", "base = \"missing.toml\"\n");
    let text = Scenario::load(&c).unwrap_err().to_string();
    assert!(
        text.contains("c.toml:1") && text.contains("missing.toml"),
        "{text}"
    );
    let d = write(dir.path(), "d.toml", "base = 3\n");
    let text = Scenario::load(&d).unwrap_err().to_string();
    assert!(text.contains("must be text"), "{text}");
}

#[test]
fn the_bundled_part_texts_are_the_parts() {
    for (name, text) in BUNDLED_PARTS {
        let s = Scenario::parse(text, Path::new(name)).unwrap();
        assert!(s.coil.is_some(), "{name}");
    }
}

#[test]
fn an_envelope_range_written_in_full_replaces_the_bases() {
    let base = Scenario::parse("base = \"part:te-axicom-im-5v\"\n", Path::new("x.toml")).unwrap();
    let range = |s: &Scenario| s.envelope.as_ref().unwrap().ranges["surface.stiffness"];
    assert!(
        range(&base).log,
        "the part samples its stiffness on a log scale"
    );
    // Written in full: the user's range, linear as written.
    let full = Scenario::parse(
        "base = \"part:te-axicom-im-5v\"\n[envelope.\"surface.stiffness\"]\nmin = 1.0e6\nmax = 2.0e6\n",
        Path::new("x.toml"),
    )
    .unwrap();
    let r = range(&full);
    assert_eq!((r.min, r.max, r.log), (1.0e6, 2.0e6, false));
    // One bound alone still amends the base's range, its scale kept.
    let partial = Scenario::parse(
        "base = \"part:te-axicom-im-5v\"\n[envelope.\"surface.stiffness\"]\nmax = 3.0e6\n",
        Path::new("x.toml"),
    )
    .unwrap();
    let r = range(&partial);
    assert_eq!((r.min, r.max, r.log), (range(&base).min, 3.0e6, true));
}

/// The coil of `examples/scenarios/relay-driver.toml`, with a DC step so
/// that it closes without its driver circuit.
const RELAY_DRIVER_COIL: &str = "[coil]\nresistance = 70.0\nturns = 3000\npole_area = 2.0e-5\n\
     air_gap = 6.0e-4\niron_gap = 5.0e-5\ndrive_voltage = 5.0\n";

#[test]
fn a_coil_over_the_defaults_step_force_replaces_it() {
    let default = Scenario::builtin_default();
    assert!(default.mechanics.force.is_some());
    let s = Scenario::parse(
        &format!("base = \"default\"\n\n{RELAY_DRIVER_COIL}"),
        Path::new("mine.toml"),
    )
    .unwrap();
    assert_eq!(
        s.mechanics.force, None,
        "a coil-driven relay has no step force"
    );
    assert_eq!(s.coil.as_ref().unwrap().turns, 3000);
    // The rest of the base's mechanics stays.
    assert_eq!(s.mechanics.mass, default.mechanics.mass);
    assert_eq!(s.mechanics.gap, default.mechanics.gap);
    assert_eq!(s.dc_step_voltage(), Some(5.0));
}

#[test]
fn a_file_that_gives_both_a_force_and_a_coil_is_told_to_remove_one() {
    let err = Scenario::parse(
        &format!("base = \"default\"\n\n[mechanics]\nforce = 0.8\n\n{RELAY_DRIVER_COIL}"),
        Path::new("mine.toml"),
    )
    .unwrap_err();
    assert!(matches!(err, ScenarioError::Conflict { .. }), "{err:?}");
    let text = err.to_string();
    assert!(text.starts_with("mine.toml:4:"), "{text}");
    assert!(
        text.contains("remove `mechanics.force` or the [coil] section"),
        "{text}"
    );
}

#[test]
fn a_force_over_a_parts_coil_names_both_files_and_the_way_out() {
    let name = "te-axicom-im-5v";
    let part_line = bundled_part(name)
        .unwrap()
        .lines()
        .position(|l| l == "[coil]")
        .unwrap()
        + 1;
    let mine = format!("base = \"part:{name}\"\n\n[mechanics]\nforce = 0.5\n");
    let err = Scenario::parse(&mine, Path::new("mine.toml")).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, ScenarioError::BaseConflict { .. }), "{text}");
    // The user's key at the user's line, the part's by the name the user
    // gave it, and what to write.
    assert!(text.starts_with("mine.toml:4:"), "{text}");
    assert!(text.contains("set in mine.toml line 4"), "{text}");
    assert!(
        text.contains(&format!("\"part:{name}\", line {part_line}")),
        "{text}"
    );
    assert!(
        text.contains("add `unset = [\"coil\"]` to mine.toml"),
        "{text}"
    );
    assert!(!text.contains("/parts/"), "no build-machine path: {text}");
    // The advice works: the part's mechanics on the step force.
    let s = Scenario::parse(
        &mine.replacen('\n', "\nunset = [\"coil\"]\n", 1),
        Path::new("mine.toml"),
    )
    .unwrap();
    assert_eq!((s.coil.is_none(), s.mechanics.force), (true, Some(0.5)));
}

#[test]
fn a_conflict_between_two_bases_names_the_chain() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "lib/a.toml",
        "base = \"default\"\n[limits]\nmax_release_time = 0.01\n",
    );
    let top = write(
        dir.path(),
        "top.toml",
        "base = \"lib/a.toml\"\n[simulation]\nt_end = 0.02\n",
    );
    let text = Scenario::load(&top).unwrap_err().to_string();
    let force_line = DEFAULT_SCENARIO_TOML
        .lines()
        .position(|l| l.starts_with("force"))
        .unwrap()
        + 1;
    assert!(text.contains("a.toml:3:"), "{text}");
    assert!(text.contains("base \"lib/a.toml\", line 3"), "{text}");
    assert!(
        text.contains(&format!("\"default\", line {force_line}, the base of")),
        "{text}"
    );
    assert!(
        text.contains("add `unset = [\"limits.max_release_time\"]` to")
            && text.contains("top.toml"),
        "{text}"
    );
}

#[test]
fn unset_removes_a_key_of_the_base() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "base.toml",
        "base = \"default\"\n[limits]\nmax_bounces = 1\nmax_settle_time = 0.01\n",
    );
    let top = write(
        dir.path(),
        "top.toml",
        "base = \"base.toml\"\nunset = [\"limits.max_bounces\"]\n",
    );
    let inherited = Scenario::load(&dir.path().join("base.toml")).unwrap();
    assert_eq!(inherited.limits.as_ref().unwrap().max_bounces, Some(1));
    let s = Scenario::load(&top).unwrap();
    let limits = s.limits.as_ref().unwrap();
    assert_eq!(limits.max_bounces, None);
    assert_eq!(limits.max_settle_time, Some(0.01));
    // Removing the last key removes the section.
    let s = Scenario::parse(
        "base = \"base.toml\"\nunset = [\"limits.max_bounces\", \"limits.max_settle_time\"]\n",
        &dir.path().join("top.toml"),
    )
    .unwrap();
    assert!(s.limits.is_none());
}

#[test]
fn unset_removes_an_envelope_range_and_a_section_starts_afresh() {
    let part = "base = \"part:te-axicom-im-5v\"\n";
    let base = Scenario::parse(part, Path::new("x.toml")).unwrap();
    let ranges = |s: &Scenario| s.envelope.as_ref().unwrap().ranges.clone();
    assert!(ranges(&base).contains_key("surface.stiffness"));
    let s = Scenario::parse(
        &format!("{part}unset = ['envelope.\"surface.stiffness\"']\n"),
        Path::new("x.toml"),
    )
    .unwrap();
    let left = ranges(&s);
    assert!(!left.contains_key("surface.stiffness"), "{left:?}");
    assert_eq!(left.len() + 1, ranges(&base).len());
    assert_eq!(left["surface.damping"], ranges(&base)["surface.damping"]);
    // A whole section removed and written again is this file's alone.
    let s = Scenario::parse(
        &format!(
            "{part}unset = [\"envelope\"]\n[envelope]\nsource = \"mine\"\n\
             [envelope.\"surface.stiffness\"]\nmax = 3.0e6\nmin = 1.0e6\n"
        ),
        Path::new("x.toml"),
    )
    .unwrap();
    let mine = ranges(&s);
    assert_eq!(mine.keys().collect::<Vec<_>>(), ["surface.stiffness"]);
}

#[test]
fn a_bad_unset_entry_names_the_file_and_its_line() {
    let case = |text: &str| {
        Scenario::parse(text, Path::new("mine.toml"))
            .unwrap_err()
            .to_string()
    };
    // Not set by the base: the entry's own line, and what the base sets.
    let text = case("base = \"default\"\nunset = [\n  \"limits\",\n  \"mechanics.forse\",\n]\n");
    assert!(text.starts_with("mine.toml:3:"), "{text}");
    assert!(
        text.contains("\"limits\"") && text.contains("does not set"),
        "{text}"
    );
    let text = case("base = \"default\"\nunset = [\n  \"mechanics.forse\",\n]\n");
    assert!(text.starts_with("mine.toml:3:"), "{text}");
    assert!(text.contains("force, gap"), "{text}");
    // No such section.
    let text = case("base = \"default\"\nunset = [\"mechanic.force\"]\n");
    assert!(
        text.starts_with("mine.toml:2:") && text.contains("not a section"),
        "{text}"
    );
    // Not a key path, or an element of an array.
    for entry in ["\"mechanics..force\"", "\"probe[0]\"", "\"\"", "3"] {
        let text = case(&format!("base = \"default\"\n\nunset = [{entry}]\n"));
        assert!(text.starts_with("mine.toml:3:"), "{entry}: {text}");
    }
    // Into a value.
    let text = case("base = \"default\"\nunset = [\"mechanics.force.x\"]\n");
    assert!(text.contains("not a table"), "{text}");
    // Without a base.
    let text = case("\nunset = [\"probe\"]\n[simulation]\nt_end = 0.02\n");
    assert!(
        text.starts_with("mine.toml:2:") && text.contains("no `base`"),
        "{text}"
    );
    // A required key removed is missing at the entry that removed it.
    let text =
        case("base = \"default\"\nunset = [\"mechanics.mass\"]\n[mechanics]\nstiffness = 4000.0\n");
    assert!(
        text.starts_with("mine.toml:2:") && text.contains("`mechanics.mass` is missing"),
        "{text}"
    );
}

#[test]
fn a_key_missing_from_what_the_user_wrote_is_named_at_the_users_line() {
    let case = |text: &str| {
        Scenario::parse(text, Path::new("mine.toml"))
            .unwrap_err()
            .to_string()
    };
    // The user's array replaces the base's: a key missing from it is the
    // user's to add, though the base's array had it.
    let text = case("base = \"default\"\n\n[[probe]]\nsignal = \"v(out)\"\nhigh = 3.0\n");
    assert!(
        text.starts_with("mine.toml:3:") && text.contains("`probe[0].low` is missing"),
        "{text}"
    );
    let text =
        case("base = \"part:finder-40.52-12vdc\"\n\n\n[[datasheet.dc_breaking]]\nvoltage = 30.0\n");
    assert!(
        text.starts_with("mine.toml:4:")
            && text.contains("`datasheet.dc_breaking[0].current` is missing"),
        "{text}"
    );
    // A table with another law starts afresh: its missing key is the
    // user's, at the user's table.
    let text = case("base = \"default\"\n\n[surface]\nlaw = \"hunt-crossley\"\n");
    assert!(text.starts_with("mine.toml:3:"), "{text}");
    // A key the base wrote is still named in the base.
    let text = case("base = \"default\"\n[mechanics]\nmass = -1.0\n");
    assert!(text.starts_with("mine.toml:3:"), "{text}");
}

#[test]
fn a_printed_figure_over_a_parts_replaces_it_whole() {
    let part = "base = \"part:finder-40.52-12vdc\"\n";
    let base = Scenario::parse(part, Path::new("x.toml")).unwrap();
    let printed = base.datasheet.as_ref().unwrap().making_current.unwrap();
    assert!(printed.max.is_some() || printed.typ.is_some());
    let s = Scenario::parse(
        &format!("{part}[datasheet]\nmaking_current = {{ typ = 10.0 }}\n"),
        Path::new("x.toml"),
    )
    .unwrap();
    let mine = s.datasheet.as_ref().unwrap().making_current.unwrap();
    assert_eq!((mine.min, mine.typ, mine.max), (None, Some(10.0), None));
}
