//! A relay-driver design check with the library: does the MCU input's RC
//! filter hide the bounce of this relay, and if not, how long must the
//! firmware debounce?
//!
//! `cargo run --example design_check` (needs ngspice)
//!
//! The stages are the ones `chatterspice run` chains: relay → chatter →
//! contact waveform → netlist → ngspice → analysis. Here the scenario is
//! the built-in default; `Scenario::load("my_relay.toml")` reads a file.

use std::process::ExitCode;

use chatterspice::pipeline::{self, RunOptions};
use chatterspice::scenario::Scenario;
use chatterspice::spice::Ngspice;

fn main() -> ExitCode {
    let scenario = Scenario::builtin_default();
    let result = Ngspice::find()
        .map_err(|e| e.to_string())
        .and_then(|ngspice| {
            pipeline::run(&scenario, &ngspice, &RunOptions::default()).map_err(|e| e.to_string())
        });
    let run = match result {
        Ok(run) => run,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };

    let chatter = &run.chatter;
    let pin = &run.probes[0];
    println!(
        "relay: {} bounces over {:.3} ms",
        chatter.bounce_count,
        1e3 * (chatter.settle_time.unwrap_or(f64::NAN) - chatter.first_impact.unwrap_or(f64::NAN)),
    );
    println!(
        "{}: {} edges ({} glitches) against 1 with an ideal contact",
        pin.analysis.signal, pin.analysis.edges, pin.analysis.glitches
    );

    // The design rule: the filter alone should leave one clean edge.
    if pin.analysis.glitches == 0 {
        println!("PASS: the RC filter hides the bounce");
        return ExitCode::SUCCESS;
    }
    // Otherwise the firmware must wait out the glitches: from the first
    // edge to the last, plus margin.
    let window = pin.analysis.last_edge.unwrap() - pin.analysis.first_edge.unwrap();
    println!(
        "FAIL: the filter lets {} glitches through; debounce for at least {:.2} ms \
         (first to last edge, ×1.5 margin), or raise the filter's time constant",
        pin.analysis.glitches,
        1.5e3 * window
    );
    ExitCode::from(1)
}
