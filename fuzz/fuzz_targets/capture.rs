//! Any text as a scope's CSV export: `parse_capture` returns a trace or an
//! error, never panics; a trace it returns is consistent, its chatter
//! (`Capture::of`) never panics, and the `time,state` CSV made of it reads
//! back (`read_state_csv`, what `--measured` uses).
#![no_main]

use std::path::Path;

use chatterspice::capture::{Capture, parse_capture};
use chatterspice::waveform::read_state_csv;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("capture.csv");
    let Ok(trace) = parse_capture(text, path, None) else {
        return;
    };
    assert_eq!(trace.time.len(), trace.value.len(), "one value per time");
    // Channels picked by 1-based number or by name.
    for n in 1..=trace.channels.len().min(4) {
        let _ = parse_capture(text, path, Some(&n.to_string()));
    }
    let _ = parse_capture(text, path, Some("CH2"));
    let Ok(capture) = Capture::of("capture.csv", &trace, None, None) else {
        return;
    };
    let _ = capture.shifted_intervals();
    let csv = capture.state_csv();
    let read_back = read_state_csv(&csv, Path::new("states.csv"));
    // A scope's times: within ±1 s of its trigger, samples more than 1 ps
    // apart. (Far outside that, e.g. a first sample at -1e20 s, `t - origin`
    // rounds two rows of the CSV to the same time, and it does not read
    // back.)
    let scope_like = trace.time.iter().all(|t| t.abs() < 1.0)
        && trace.time.windows(2).all(|w| w[1] - w[0] > 1e-12);
    if scope_like {
        if let Err(e) = read_back {
            panic!("the capture's time,state CSV does not read back: {e}\n{csv}");
        }
    }
});
