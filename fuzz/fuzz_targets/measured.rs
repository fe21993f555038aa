//! Any text as a measured `time,state` CSV (`--measured`):
//! `read_state_csv` returns intervals or an error, never panics; the
//! intervals it returns tile the record in order, and their summary
//! (`Chatter::from_intervals`) never panics.
#![no_main]

use std::path::Path;

use chatterspice::chatter::Chatter;
use chatterspice::waveform::read_state_csv;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(intervals) = read_state_csv(text, Path::new("measured.csv")) else {
        return;
    };
    for i in &intervals {
        assert!(i.start <= i.end, "interval ends before it starts: {i:?}");
    }
    for w in intervals.windows(2) {
        assert_eq!(w[0].end, w[1].start, "intervals tile the record");
    }
    let chatter = Chatter::from_intervals(intervals);
    // Each bounce is an open interval after a closed one.
    assert!(chatter.bounce_count < chatter.intervals.len().max(1));
});
