//! Checks every deck a fuzz target gets from `prepare_deck`.

use std::path::Path;

use chatterspice::netlist::Deck;

/// A deck is consistent (one origin per line, every origin a file of the
/// deck's list, the netlist first, `.end` last) and runs no ngspice
/// commands: no line that ngspice reads as the start of a `.control` block
/// or as a `*#` command (prefixes, any case, after blanks) after the
/// title, and no `*ng_script` title.
pub fn check(deck: &Deck, netlist: &Path) {
    let text = &deck.text;
    let lines = text.lines().count();
    assert_eq!(deck.source_lines.len(), lines, "one origin per deck line");
    assert!(text.ends_with(".end\n"), "the deck ends with .end");
    assert_eq!(
        deck.files.first().map(|p| p.as_path()),
        Some(netlist),
        "the netlist is file 0"
    );
    for (i, origin) in deck.source_lines.iter().enumerate() {
        if let Some(o) = origin {
            assert!(
                o.file < deck.files.len(),
                "deck line {}: no file {}",
                i + 1,
                o.file
            );
            assert!(o.line >= 1, "deck line {}: source line 0", i + 1);
        }
    }
    for i in 0..=lines + 1 {
        let _ = deck.source_line(i);
    }
    let _ = deck.tran.effective_max_step();
    for w in &deck.warnings {
        let _ = w.to_string();
    }

    let prefixed = |line: &str, prefix: &str| {
        let t = line
            .trim_start_matches([' ', '\t', '\r', '\x0b', '\x0c'])
            .as_bytes();
        t.len() >= prefix.len() && t[..prefix.len()].eq_ignore_ascii_case(prefix.as_bytes())
    };
    // Line 1 is the title, which ngspice (39, `-b`) never reads as a
    // command: a `.control` or `*#` title runs nothing.
    for (i, line) in text.lines().enumerate().skip(1) {
        assert!(
            !prefixed(line, ".control") && !prefixed(line, "*#"),
            "deck line {} is an ngspice command: {line:?}\n{text}",
            i + 1
        );
    }
    let title = text.lines().next().unwrap_or("");
    assert!(!prefixed(title, "*ng_script"), "a script title: {title:?}");
}
