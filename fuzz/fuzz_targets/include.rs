//! Any bytes as a file the user's netlist includes: `prepare_deck` inlines
//! it (`.include FILE`, and `.lib FILE typ` for a section) or returns an
//! error, never panics, and the deck is consistent and runs no ngspice
//! commands (common/deck.rs) whatever the included file holds.
#![no_main]

#[path = "common/deck.rs"]
mod deck;

use std::path::PathBuf;
use std::sync::OnceLock;

use chatterspice::netlist::{DeckRequest, prepare_deck};
use libfuzzer_sys::fuzz_target;

/// The directory of this process's netlist and of `lib.inc`, the input.
fn dir() -> &'static PathBuf {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir =
            std::env::temp_dir().join(format!("chatterspice-fuzz-include-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary directory");
        dir
    })
}

const WHOLE: &str = "* the input, included whole
V1 vdd 0 3.3
R1 vdd in 10k
X1 in 0 CONTACT
.include lib.inc
.tran 1u 5m
.end
";

const SECTION: &str = "* a section of the input
V1 vdd 0 3.3
R1 vdd in 10k
.lib \"lib.inc\" typ
.tran 1u 5m
.end
";

fuzz_target!(|data: &[u8]| {
    let dir = dir();
    std::fs::write(dir.join("lib.inc"), data).expect("the included file written");
    let netlist = dir.join("circuit.cir");
    for text in [WHOLE, SECTION] {
        let req = DeckRequest {
            netlist_text: text,
            netlist_path: &netlist,
            include_file_name: "contact.inc",
            subckt: "CONTACT",
            coil: None,
            probes: &["v(in)"],
            chatter_end: 1e-3,
            stop_at_least: 2e-3,
            options: &[],
        };
        if let Ok(d) = prepare_deck(&req) {
            deck::check(&d, &netlist);
        }
    }
});
