//! Any bytes: the reader returns a value or an error, never panics, and
//! what it returns is consistent.
#![no_main]

use chatterspice::rawfile::{RawFile, export};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(raw) = RawFile::parse(data) {
        for plot in &raw.plots {
            for i in 0..plot.variables.len() {
                let v = plot.vector(i).expect("one vector per variable");
                assert!(v.len() <= plot.points());
            }
            let mut sink = Vec::new();
            export::plot_csv(plot, &mut sink).expect("CSV into memory");
        }
        let _ = export::summary_json(&raw);
        let _ = export::stats_table(&raw);
    }
});
