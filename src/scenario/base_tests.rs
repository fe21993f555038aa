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
