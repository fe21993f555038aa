//! Any text as the user's netlist: `prepare_deck` builds a deck or returns
//! an error, never panics, and a deck it builds is consistent and runs no
//! ngspice commands (common/deck.rs); the other readers of netlist text
//! (`param_value`, `instances_of`, `instance_nodes_of`, `save_names`,
//! `parse_number`) never panic either.
#![no_main]

#[path = "common/deck.rs"]
mod deck;

use std::path::PathBuf;
use std::sync::OnceLock;

use chatterspice::netlist::{
    DeckRequest, instance_nodes_of, instances_of, param_value, parse_number, prepare_deck,
    prepare_deck_with_params, save_names,
};
use libfuzzer_sys::fuzz_target;

/// The netlist's path: in an empty directory of its own, so that relative
/// `.include`s find nothing (the `include` target fuzzes included files).
fn netlist_path() -> &'static PathBuf {
    static PATH: OnceLock<PathBuf> = OnceLock::new();
    PATH.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("chatterspice-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        dir.join("circuit.cir")
    })
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let text: &str = &text;
    let req = DeckRequest {
        netlist_text: text,
        netlist_path: netlist_path(),
        include_file_name: "contact.inc",
        subckt: "CONTACT",
        coil: None,
        probes: &["v(in)"],
        chatter_end: 1e-3,
        stop_at_least: 2e-3,
        options: &[],
    };
    if let Ok(d) = prepare_deck(&req) {
        deck::check(&d, netlist_path());
    }
    if let Ok(d) = prepare_deck_with_params(&req, &[("r1", 1e3), ("cload", 1e-9)]) {
        deck::check(&d, netlist_path());
    }
    if let Ok(d) = prepare_deck(&DeckRequest {
        coil: Some(("coil.inc", "COIL")),
        ..req
    }) {
        deck::check(&d, netlist_path());
    }

    let first = text.lines().next().unwrap_or("");
    for name in ["r1", first.trim()] {
        let _ = param_value(text, name);
    }
    for subckt in ["CONTACT", first.trim()] {
        let _ = instances_of(text, subckt);
        let _ = instance_nodes_of(text, subckt);
    }
    let _ = save_names(first);
    for word in first.split_whitespace().take(8) {
        let _ = parse_number(word);
    }
});
